/*
 * vdsh.h - read and write .vdsh files (baked visibility-distance SH).
 *
 * Purpose: the one piece of code that knows the byte layout of a .vdsh file
 * (specified in formats/VDSH.md). Plain C11, POSIX libc (for the atomic
 * write: open, fsync, rename), libm and zlib (its CRC-32); nothing else.
 *
 * Does not: trace rays, fit SH, or touch GL. SH evaluation is vdsh_sh.h;
 * cubemap face conventions are vdsh_cube.h.
 *
 * Usage (tests/test_format.c is a compiled example):
 *
 *     vdsh_file *f = NULL;
 *     vdsh_error err;
 *     vdsh_result r = vdsh_read("room.vdsh", &f, &err);
 *     if (r != VDSH_OK) { fprintf(stderr, "%s\n", err.msg); return 1; }
 *     const vdsh_stream *s = vdsh_find_stream(f, 5, VDSH_QUANTITY_DISTANCE);
 *     float c[25];
 *     vdsh_stream_decode(s, 0, c);            (vertex 0's 25 coefficients)
 *     vdsh_free(f);
 *
 * Errors: every fallible function returns a vdsh_result (VDSH_OK = 0) and,
 * when `err` is not NULL, writes a message into err->msg that names the file
 * (or "memory") and what is wrong, e.g.
 * "room.vdsh: chunk 3 'COEF' at offset 1234: CRC mismatch". On failure the
 * outputs are left untouched. There is no global error state.
 *
 * Ownership: vdsh_read*() returns a vdsh_file owned by the caller and freed
 * with vdsh_free() (which accepts NULL). Every pointer inside it points into
 * memory it owns: the whole file is loaded into one 16-byte-aligned buffer
 * and positions, normals, indices and stream data point into it (so they
 * are 16-byte aligned). vdsh_write*() only borrows its argument.
 *
 * Writing: vdsh_write() writes through vdsh_output.h: `path.tmp.<pid>.<n>`
 * beside `path`, created with O_EXCL and mode 0666 (less the umask),
 * written, fsynced and renamed over `path`; a failure removes it and leaves
 * `path` as it was.
 *
 * Tools: vdsh_scan_chunks() lists the chunks of a file image with their
 * stored and computed CRCs, also for a damaged file (vdsh-info --verify).
 *
 * Threading: no shared state; any number of threads may read and write
 * different files at once.
 *
 * Byte order: the file is little-endian; this implementation supports
 * little-endian hosts only (checked at compile time).
 */
#ifndef VDSH_H
#define VDSH_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define VDSH_FORMAT_VERSION 1u
/* The largest SH order a stream stores: every size below, in the bake and
 * in the runtime, is derived from it. Orders 1..5 are the paper's (the
 * runtime draws them from vertex attributes and, at order 5, cubemaps);
 * orders 6..16 are for long shadows (issue 16), drawn from buffers. */
#define VDSH_MAX_ORDER 16
/* Coefficients of order n (bands 0..n-1). */
#define VDSH_COEFFS(n) ((n) * (n))
#define VDSH_MAX_COEFFS VDSH_COEFFS(VDSH_MAX_ORDER)
/* Arrays indexed by order 1..VDSH_MAX_ORDER ([0] unused). */
#define VDSH_ORDER_SLOTS (VDSH_MAX_ORDER + 1)
/* Functions in the highest band, 2l + 1 for l = VDSH_MAX_ORDER - 1. */
#define VDSH_MAX_BAND_WIDTH (2 * VDSH_MAX_ORDER - 1)
/* Coefficients of orders 1..n together: 1 + 4 + ... + n^2. */
#define VDSH_COEFFS_THROUGH(n) ((n) * ((n) + 1) * (2 * (n) + 1) / 6)
#define VDSH_MAX_STREAMS 16
#define VDSH_MAX_SOURCES 64
#define VDSH_MAX_NAME 4096
#define VDSH_MAX_VERTICES (1u << 28)
#define VDSH_MAX_TRIANGLES (1u << 28)

typedef enum vdsh_result {
    VDSH_OK = 0,
    VDSH_ERR_IO, /* could not open, read, write or rename (errno in msg) */
    VDSH_ERR_OUT_OF_MEMORY,
    VDSH_ERR_NOT_VDSH,  /* wrong magic: not a .vdsh file */
    VDSH_ERR_VERSION,   /* a version this reader does not support */
    VDSH_ERR_TRUNCATED, /* shorter than its header or a chunk says */
    VDSH_ERR_CRC,       /* header or chunk CRC mismatch */
    /* chunk structure: unknown critical id, missing, repeated or misplaced
     * chunk, bad size, padding */
    VDSH_ERR_CHUNK,
    VDSH_ERR_INVALID, /* a value out of range: count, enum, index, NaN */
    VDSH_ERR_ARGUMENT /* the caller passed an inconsistent vdsh_file */
} vdsh_result;

/* A static string such as "CRC mismatch"; never NULL. */
const char *vdsh_result_str(vdsh_result r);

/* The library's version, "MAJOR.MINOR.PATCH" (the CMake project's; the
 * installed package's vdshConfigVersion.cmake and .pc files carry the
 * same). The file format's version is VDSH_FORMAT_VERSION's. */
const char *vdsh_library_version(void);

typedef struct vdsh_error {
    char msg[512];
} vdsh_error;

typedef enum vdsh_sampling { VDSH_SAMPLING_SPHERE = 0, VDSH_SAMPLING_HEMISPHERE = 1 } vdsh_sampling;

typedef enum vdsh_offset_rule { VDSH_OFFSET_NONE = 0, VDSH_OFFSET_WB_AVG = 1 } vdsh_offset_rule;

/* HEAD load_flags: bit 0 welded; bits 1..3 the sources' up axis, which
 * the baker turned into +y before anything else (vdsh-bake --up-axis;
 * readers that rebuild the scene from the sources turn them the same way):
 * 0 y (none: the default), 1 z, 2 -z, 3 x, 4 -x, 5 -y (vdsh_up_axis_name). */
enum { VDSH_LOAD_WELD = 1u, VDSH_LOAD_UP_SHIFT = 1, VDSH_LOAD_UP_MASK = 7u << 1, VDSH_UP_AXES = 6 };

/* "y", "z", "-z", "x", "-x", "-y" for up axis code 0..5; NULL otherwise. */
const char *vdsh_up_axis_name(uint32_t code);
/* load_flags bits 8..15: the crease angle of the computed normals, whole
 * degrees 1..179 (vb_load_desc.crease); 0: none */
enum { VDSH_LOAD_CREASE_SHIFT = 8, VDSH_LOAD_CREASE_MASK = 0xffu << 8 };
#define VDSH_LOAD_CREASE(flags) (((flags)&VDSH_LOAD_CREASE_MASK) >> VDSH_LOAD_CREASE_SHIFT)
enum { VDSH_TRACE_ROBUST = 1u };

typedef enum vdsh_encoding {
    VDSH_ENCODING_F32 = 0,
    VDSH_ENCODING_F16 = 1,
    VDSH_ENCODING_S8 = 2, /* signed 8-bit, a scale per coefficient index */
    /* bands 0-1 as s8, bands 2+ signed 6-bit, packed five to a u32 word;
     * scales as s8 */
    VDSH_ENCODING_S8S6 = 3,
    /* clustered PCA (issue 29): per cluster a mean and basis vectors (f16),
     * per vertex a cluster index and packed weights (vdsh_cpca below) */
    VDSH_ENCODING_CPCA = 4
} vdsh_encoding;
/* The largest encoding value this version reads and writes. */
#define VDSH_ENCODING_LAST VDSH_ENCODING_CPCA
/* s8s6: coefficients 0..3 as bytes; coefficient i >= 4 in bits
 * 6 * ((i - 4) % 5) .. + 5 of u32 word (i - 4) / 5 after them. */
#define VDSH_S8S6_BYTES 4
#define VDSH_S8S6_PER_WORD 5
#define VDSH_S8S6_BITS 6

typedef enum vdsh_method {
    VDSH_METHOD_PAPER = 0,
    VDSH_METHOD_FULL = 1,
    VDSH_METHOD_MIRROR = 2,
    VDSH_METHOD_LSQ = 3,
    VDSH_METHOD_SHADOW = 4,
    VDSH_METHOD_DECISION = 5
} vdsh_method;

typedef enum vdsh_quantity {
    VDSH_QUANTITY_DISTANCE = 0,
    VDSH_QUANTITY_DISTANCE2 = 1,
    VDSH_QUANTITY_LOG_DISTANCE = 2
} vdsh_quantity;

typedef enum vdsh_window {
    VDSH_WINDOW_NONE = 0,
    VDSH_WINDOW_HANN = 1,
    VDSH_WINDOW_LANCZOS = 2
} vdsh_window;

/* Names used on command lines and in reports ("paper", "f16", ...);
 * "?" for values this version does not know. */
const char *vdsh_method_name(uint32_t method);
const char *vdsh_encoding_name(uint32_t encoding);
const char *vdsh_quantity_name(uint32_t quantity);
const char *vdsh_window_name(uint32_t window);
const char *vdsh_sampling_name(uint32_t sampling);
const char *vdsh_offset_rule_name(uint32_t rule);

/* 1 when `name` can name a source in SRCS (1..VDSH_MAX_NAME bytes of
 * valid UTF-8, no NUL: the rule the writer and reader apply); else 0 with
 * the reason ("is not valid UTF-8 (byte 3)") in why[0..n) when why is
 * not NULL. For a program to refuse a mesh path before baking it. */
int vdsh_source_name_ok(const char *name, char *why, size_t n);

/* The encodings, one row each, in the order command lines list them: the
 * one table that names, sizes and describes them (vdsh_encoding_name,
 * vdsh_encoding_bytes, vdsh_encoding_from_name, vdsh_encoding_names and
 * the programs' options read it). Adding an encoding: a row here, the enum
 * above, and its own code (encode, decode, check; the runtime's buffer). */
typedef struct vdsh_encoding_info {
    const char *name;  /* on command lines, in reports and JSON */
    uint32_t encoding; /* vdsh_encoding */
    /* bytes of one vertex at nc coefficients; 0 where the stream's own
     * model sizes the record (cpca: vdsh_cpca_record_words) */
    size_t (*bytes)(uint32_t nc);
    const char *description; /* one line */
} vdsh_encoding_info;

/* The table's rows, *count of them (count may be NULL). */
const vdsh_encoding_info *vdsh_encodings(size_t *count);
/* The row of an encoding value; NULL for values this version does not know. */
const vdsh_encoding_info *vdsh_encoding_info_of(uint32_t encoding);
/* The row named `name` (as vdsh_encoding_name spells it); NULL for none. */
const vdsh_encoding_info *vdsh_encoding_from_name(const char *name);
/* The names as a list for messages, "f16, f32, s8, s8s6 or cpca" (a
 * static string). */
const char *vdsh_encoding_names(void);

/* HEAD chunk: see VDSH.md for the meaning and range of every field. */
typedef struct vdsh_header {
    uint32_t vertex_count;
    uint32_t triangle_count;
    uint32_t rays;
    uint32_t sampling;
    uint64_t seed;
    float max_distance;
    float max_edge;
    uint32_t offset_rule;
    uint32_t load_flags;
    uint32_t cube_size;
    uint32_t occluder_vertex_count;
    uint32_t occluder_triangle_count;
    uint32_t trace_flags;
    float bounds_min[3];
    float bounds_max[3];
} vdsh_header;

typedef struct vdsh_source {
    char *name; /* NUL-terminated copy of the stored name */
    uint64_t size;
    uint8_t sha256[32];
} vdsh_source;

/* A `cpca` stream's model (VDSH.md "cpca streams"): K clusters, each a
 * mean and B basis vectors of order^2 coefficients (f16), per basis
 * vector a scale; per vertex row a record of record_words u32 words in
 * vdsh_stream.data: bits 0..7 of word 0 the cluster index, then B
 * two's-complement weight levels, weight j vdsh_cpca_width(m, j) bits
 * wide (`bits`, or with bits 0 the widths table's; vdsh_cpca_model_field
 * says where). Decoding (vdsh_stream_decode, to the bit): w_j = level_j *
 * vdsh_cpca_step(scales[c * B + j], width_j) in f32, coefficient i = mean
 * + sum over j = 0..B-1 in order of w_j * basis_j[i], each product and
 * sum rounded to f32. */
typedef struct vdsh_cpca {
    uint32_t clusters; /* K, 1..VDSH_CPCA_MAX_CLUSTERS */
    uint32_t basis;    /* B, 1..order^2 */
    uint32_t bits;     /* per weight, VDSH_CPCA_MIN_BITS..VDSH_CPCA_MAX_BITS, or 0:
                          a width per basis vector (widths) */
    /* 1: the bases are s8 (bases8, -127..127, the value the integer; the
     * header's bits word has VDSH_CPCA_BASES_S8 set), 0: f16 (bases) */
    uint32_t bases_s8;
    uint32_t record_words; /* W = vdsh_cpca_record_words(basis, bits), or with
                              bits 0 vdsh_cpca_widths_words(widths, basis) */
    const uint8_t *widths; /* bits 0: B widths, each 2..8; else NULL */
    const float *scales;   /* K * B: vector j of cluster c at c * B + j */
    const uint16_t *means; /* f16, K * order^2: cluster c's at c * order^2 */
    /* f16 (bases_s8 0) or s8 (bases_s8 1), K * B * order^2: vector j of
     * cluster c at (c * B + j) * order^2; the other NULL */
    const uint16_t *bases;
    const int8_t *bases8;
} vdsh_cpca;
/* In the cpca header's bits word: the bases are s8 (VDSH.md "cpca
 * streams"); in a part's cpca_bits, K,alloc:BYTES with s8 bases. */
#define VDSH_CPCA_BASES_S8 0x100u
#define VDSH_CPCA_MAX_CLUSTERS 256
#define VDSH_CPCA_MIN_BITS 2
#define VDSH_CPCA_MAX_BITS 8
#define VDSH_CPCA_INDEX_BITS 8
/* The baker's default (vdsh-bake --encoding cpca without --cpca):
 * K,alloc:BYTES with K = VDSH_CPCA_DEFAULT_CLUSTERS and BYTES =
 * VDSH_CPCA_DEFAULT_BUDGET, 16,alloc:32 (docs/ACCURACY.md "The default
 * of --encoding cpca"); before, the fixed 8,54,4. */
#define VDSH_CPCA_DEFAULT_CLUSTERS 16
/* --cpca auto[:BYTES] and the default: bytes per vertex, the model included */
#define VDSH_CPCA_DEFAULT_BUDGET 32
#define VDSH_CPCA_MAX_BUDGET 4096

typedef struct vdsh_stream {
    uint32_t order;    /* bands n; n*n coefficients per vertex */
    uint32_t encoding; /* vdsh_encoding */
    uint32_t method;   /* vdsh_method */
    uint32_t quantity; /* vdsh_quantity */
    uint32_t window;   /* vdsh_window */
    float window_param;
    float method_param;
    /* coefficient = stored value * scale (f32, f16); s8: 1, the table below
     * scales */
    float scale;
    /* log-distance: the floor (distances below it were clamped to it before
     * the log); else 0 */
    float quantity_param;
    const void *data;         /* vertex_count * order^2 values of `encoding` */
    const float *coef_scales; /* s8, s8s6 only (else NULL): order^2 scales,
                                 one per coefficient index, each finite and
                                 >= 0; coefficient i = stored * vdsh_quant_step(
                                 coef_scales[i], vdsh_quant_levels(enc, i)) */
    uint32_t flags;           /* VDSH_STREAM_VARIABLE or 0 */
    /* Variable-order streams only (else NULL; VDSH.md "Variable-order
     * streams"): per vertex row its order k, 1..order (order is the cap);
     * `data` then holds one record of k^2 coefficients per row, each
     * padded to a multiple of 4 bytes, and row v's record starts at word
     * offsets[v] of data (offsets: rows + 1 entries). The reader sets
     * both; a writer's caller sets orders, and offsets when it decodes
     * its own stream (vdsh_stream_offsets); the writer ignores offsets. */
    const uint8_t *orders;
    const uint32_t *offsets;
    /* `cpca` streams only (else all zero): the model; `data` then holds
     * the rows' records, record_words u32 words each. */
    vdsh_cpca cpca;
} vdsh_stream;

/* vdsh_stream.flags: each vertex has its own order (issue 16). */
#define VDSH_STREAM_VARIABLE 1u

typedef struct vdsh_stats {
    uint64_t rays_traced;
    uint64_t rays_missed;
    uint32_t degenerate_receivers;
    uint32_t undefined_normals;
    uint32_t moved_origins;   /* receivers whose ray origin was repaired */
    uint32_t flipped_normals; /* receivers whose normal was turned to free space */
} vdsh_stats;

typedef struct vdsh_timings {
    double load, refine, build, trace, total;
    uint32_t threads;
} vdsh_timings;

/* A part of a sharded bake (`part` chunk, VDSH.md "Parts"): shard `index`
 * of `count`, which baked receivers [range_begin, range_end); its streams
 * hold those receivers' rows only; the merged file's streams use
 * `encoding`. */
typedef struct vdsh_part {
    uint32_t index, count;
    uint32_t range_begin, range_end;
    uint32_t encoding; /* vdsh_encoding of the merged file */
    /* encoding cpca: the settings the merge fits with (K, B as asked for,
     * capped there at V and order^2); else 0. */
    uint32_t cpca_clusters, cpca_basis, cpca_bits;
} vdsh_part;

/* Adaptive receivers (`adpt` chunk, VDSH.md): what refined the receivers
 * (vdsh-bake --adaptive) and what it did. */
typedef struct vdsh_adaptive {
    float tolerance;          /* expected shadow error; >= 0, may be +inf */
    float min_edge;           /* > 0, scene units */
    uint32_t max_receivers;   /* the budget; 0: none */
    uint32_t lights;          /* free-space lights scoring the error, >= 1 */
    uint32_t max_rounds;      /* >= 1 */
    uint32_t start_receivers; /* the uniform mesh it started from (max_edge) */
    uint32_t rounds;          /* rounds run */
    uint32_t candidates;      /* midpoints baked, split or not */
} vdsh_adaptive;

/* Where the lights go (`lreg` chunk, VDSH.md), when the bake was told
 * (vdsh-bake --light-region grown or a box): the decision fit trained, and
 * its offsets were calibrated, on lights in this box (in free space), and
 * readers place their default lights there. Absent: the scene's own rule
 * (vdsh_light.h, vdsh_light_region). */
enum { VDSH_LIGHT_REGION_GROWN = 1, VDSH_LIGHT_REGION_BOX = 2 };
typedef struct vdsh_light_box {
    /* VDSH_LIGHT_REGION_GROWN (the bounds grown by VDSH_REGION_GROW of their
     * diagonal) or _BOX (given) */
    uint32_t rule;
    float min[3]; /* scene units (the space of POSN), finite */
    float max[3]; /* finite, > min on every axis */
} vdsh_light_box;

/* The first axis (0 x, 1 y, 2 z) on which min..max is not a light box's
 * (both finite, min below max), else -1: the `lreg` chunk's rule, which
 * the reader and writer apply, and every light box given (vdsh-bake,
 * vdsh-eval, vdsh-frames and vdsh-view --light-region; the runtime's
 * vr_scene_desc.light_box). */
int vdsh_light_box_bad_axis(const float min[3], const float max[3]);

/* A part's cpca light pool (`lpol` chunk, VDSH.md "Parts"): the light mix
 * and the pool of the cpca encoder's light-density metric (vdsh_cpca.h),
 * which vdsh-merge passes to the encoder. Only in parts whose `part`
 * encoding is cpca, and only with a mix > 0. */
#define VDSH_MAX_POOL_LIGHTS 65536
#define VDSH_CPCA_MAX_MARGIN 1e6f /* --cpca margin:S, 0 < S <= this */
#define VDSH_CPCA_MAX_STARTS 16   /* --cpca starts:N, 1 <= N <= this */
typedef struct vdsh_light_pool {
    float mix;           /* 0 < mix <= 1 */
    uint32_t count;      /* 1..VDSH_MAX_POOL_LIGHTS */
    const float *lights; /* 3 * count, finite */
    float margin;        /* --cpca margin:S: 0 (none) or 0 < S <= VDSH_CPCA_MAX_MARGIN */
    uint32_t starts;     /* --cpca starts:N: 0 (one fit), 1..VDSH_CPCA_MAX_STARTS */
} vdsh_light_pool;

typedef struct vdsh_file {
    vdsh_header header;
    uint32_t source_count;
    vdsh_source *sources;
    const float *positions;  /* 3 * vertex_count */
    const float *normals;    /* 3 * vertex_count */
    const uint32_t *indices; /* 3 * triangle_count */
    uint32_t stream_count;
    vdsh_stream *streams;
    int has_stats; /* `stat` chunk present */
    vdsh_stats stats;
    int has_timings; /* `time` chunk present */
    vdsh_timings timings;
    int has_part; /* `part` chunk present: a shard's part */
    vdsh_part part;
    int has_adaptive; /* `adpt` chunk present: adaptive receivers */
    vdsh_adaptive adaptive;
    int has_light_pool; /* `lpol` chunk present: a cpca part's light pool */
    vdsh_light_pool light_pool;
    int has_light_box; /* `lreg` chunk present: where the bake's lights went */
    vdsh_light_box light_box;
    void *storage_; /* owned memory; do not touch */
} vdsh_file;

/* Receivers each COEF stream holds: a part's range (range_end -
 * range_begin; its first row is receiver range_begin), else vertex_count.
 * A tool that indexes streams by receiver should refuse parts (has_part). */
uint32_t vdsh_file_stream_vertices(const vdsh_file *f);

/* Read and validate a whole file (every rule in VDSH.md, all CRCs).
 * On success *out owns everything; on failure *out is untouched. */
vdsh_result vdsh_read(const char *path, vdsh_file **out, vdsh_error *err);

/* The same from memory (the bytes are copied; `name` is used in messages
 * and may be NULL). This is what the fuzz target calls. */
vdsh_result vdsh_read_memory(const void *data, size_t size, const char *name, vdsh_file **out,
                             vdsh_error *err);

void vdsh_free(vdsh_file *f);

/* Write `f` atomically: to a temporary file in the same directory, flushed,
 * then renamed over `path`; on any failure the temporary file is removed
 * and `path` is left as it was. `f` is validated first with the same rules
 * as the reader (VDSH_ERR_ARGUMENT names the offending field). Pointers in
 * `f` are borrowed; storage_ is ignored. */
vdsh_result vdsh_write(const char *path, const vdsh_file *f, vdsh_error *err);

/* vdsh_write, and on success the file's size in bytes in *size (may be
 * NULL; untouched on failure): a caller need not open the file again. */
vdsh_result vdsh_write_sized(const char *path, const vdsh_file *f, uint64_t *size, vdsh_error *err);

/* Serialise to memory. On success *out_data is a malloc'd buffer the
 * caller frees with free(). */
vdsh_result vdsh_write_memory(const vdsh_file *f, void **out_data, size_t *out_size,
                              vdsh_error *err);

/* The fixed-order stream for (order, quantity), or NULL. */
const vdsh_stream *vdsh_find_stream(const vdsh_file *f, uint32_t order, uint32_t quantity);

/* The variable-order stream of `quantity`, or NULL. */
const vdsh_stream *vdsh_find_variable_stream(const vdsh_file *f, uint32_t quantity);

/* Vertex row v's order: s->order, or its own in a variable-order stream. */
uint32_t vdsh_stream_vertex_order(const vdsh_stream *s, uint32_t v);

/* Decode vertex v's coefficients of `s` to floats (scale applied): its
 * own order's k^2, then zeros up to s->order^2, so that out always holds
 * order^2 values. v must be < the stream's rows (vdsh_file_stream_vertices).
 * cpca streams decode mean + weights x basis as vdsh_cpca says. */
void vdsh_stream_decode(const vdsh_stream *s, uint32_t v, float *out);

/* cpca (VDSH.md "cpca streams"). Words of one record: the 8-bit cluster
 * index, then `basis` fields of `bits` bits, none straddling a word. */
uint32_t vdsh_cpca_record_words(uint32_t basis, uint32_t bits);
/* Where weight j's field lies in a record: word *word, bits *shift ..
 * *shift + bits - 1. */
void vdsh_cpca_field(uint32_t bits, uint32_t j, uint32_t *word, uint32_t *shift);
/* Words of a record whose weight j is widths[j] bits wide (0: no field),
 * none straddling a word. */
uint32_t vdsh_cpca_widths_words(const uint8_t *widths, uint32_t basis);
/* Weight j's width in bits: `bits`, or with bits 0 widths[j]. */
static inline uint32_t vdsh_cpca_width(const vdsh_cpca *m, uint32_t j)
{
    return m->bits ? m->bits : m->widths[j];
}
/* Where weight j's field lies in a record of model m (either form). */
void vdsh_cpca_model_field(const vdsh_cpca *m, uint32_t j, uint32_t *word, uint32_t *shift);
/* Levels each side of 0: 2^(bits-1) - 1 (4 bits: 7). */
static inline int vdsh_cpca_levels(uint32_t bits)
{
    return (1 << (bits - 1)) - 1;
}
/* Weight = level * step, the step scale / levels rounded to f32. */
static inline float vdsh_cpca_step(float scale, uint32_t bits)
{
    return scale / (float)vdsh_cpca_levels(bits);
}
/* Bytes between the 48-byte stream header and the records: the 16-byte
 * cpca header, the scales, means and bases (f16, or s8 with bases_s8),
 * each padded to 16. */
uint64_t vdsh_cpca_model_bytes(uint32_t order, uint32_t clusters, uint32_t basis,
                               uint32_t bases_s8);
/* The same for model m (either form: with bits 0 the widths table, B
 * bytes padded to 16, too). */
uint64_t vdsh_cpca_stream_model_bytes(const vdsh_cpca *m, uint32_t order);
/* Vertex row v's cluster index (< clusters) of a cpca stream. */
uint32_t vdsh_cpca_cluster(const vdsh_stream *s, uint32_t v);
/* Vertex row v's B stored weight levels (-L..L) and weights (level *
 * step, f32) of a cpca stream; either output may be NULL. */
void vdsh_cpca_weights(const vdsh_stream *s, uint32_t v, int32_t *levels, float *weights);

/* Bytes of coefficient data per vertex of a fixed-order stream: order^2 *
 * 4 (f32), * 2 (f16) or * 1 (s8); s8s6: min(n^2, 4) + 4 * ceil((n^2 -
 * 4) / 5) (orders 1..5: 1, 4, 8, 16, 24); cpca: 4 * record_words (the
 * model not counted); 0 for an unknown encoding and for a variable-order
 * stream (vdsh_stream_data_bytes). */
size_t vdsh_stream_bytes_per_vertex(const vdsh_stream *s);

/* Words of one record of order k in a variable-order stream of
 * `encoding`: vdsh_encoding_bytes(encoding, k^2) rounded up to 4 bytes. */
uint32_t vdsh_record_words(uint32_t encoding, uint32_t order);

/* Fill offsets[0..rows] of a variable-order stream from its orders (each
 * 1..VDSH_MAX_ORDER): offsets[v] = words of the records before row v. */
void vdsh_stream_offsets(const uint8_t *orders, uint32_t rows, uint32_t encoding,
                         uint32_t *offsets);

/* What a stream's rows cost: rows per order ([k]: of order k; a fixed
 * stream's all at its order), bytes per row on average (a variable-order
 * stream's order table included; a cpca stream's model spread over the
 * rows) and the largest row's record. */
typedef struct vdsh_stream_size {
    uint32_t rows_per_order[VDSH_ORDER_SLOTS];
    double mean_bytes;
    uint32_t max_bytes;
} vdsh_stream_size;
vdsh_stream_size vdsh_stream_size_of(const vdsh_stream *s, uint32_t rows);

/* Bytes of a stream's data for `rows` vertex rows, the scale table (and
 * a cpca stream's model) not counted: rows * bytes per vertex, or for a
 * variable-order stream its order table (rows, padded to 16) and records
 * (from s->orders). */
uint64_t vdsh_stream_data_bytes(const vdsh_stream *s, uint32_t rows);

/* IEEE binary16 conversion, round to nearest even; overflow gives +-Inf
 * (the caller checks), NaN stays NaN. */
uint16_t vdsh_f16_from_f32(float f);
float vdsh_f32_from_f16(uint16_t h);
/* Basis value i (index (c * B + j) * order^2 + coefficient) of model m as
 * f32: the f16 widened, or the s8 integer. */
static inline float vdsh_cpca_basis_value(const vdsh_cpca *m, size_t i)
{
    return m->bases_s8 ? (float)m->bases8[i] : vdsh_f32_from_f16(m->bases[i]);
}

/* Encode n floats to f16 as value / scale. Returns VDSH_ERR_INVALID if an
 * input is not finite or a result overflows f16; dst is then unspecified. */
vdsh_result vdsh_encode_f16(const float *src, size_t n, float scale, uint16_t *dst);

/* s8 (VDSH.md, COEF): the step of coefficient index i, scale_i / 127 in
 * f32, so that coefficient = stored * step, stored in -127..127. Every
 * decoder (vdsh_stream_decode, the GL runtime's uniforms, the Python
 * reader) computes it this way, so they agree to the bit. */
static inline float vdsh_s8_step(float scale)
{
    return scale / 127.0f;
}

/* The quantised encodings (s8, s8s6), which carry a scale table. */
static inline int vdsh_encoding_quantised(uint32_t e)
{
    return e == VDSH_ENCODING_S8 || e == VDSH_ENCODING_S8S6;
}
/* The largest stored magnitude of coefficient index i in quantised
 * encoding e: 127 (8 bits), or 31 for s8s6's 6-bit bands 2+. */
static inline int vdsh_quant_levels(uint32_t e, uint32_t i)
{
    return e == VDSH_ENCODING_S8S6 && i >= VDSH_S8S6_BYTES ? 31 : 127;
}
/* Coefficient = stored * vdsh_quant_step(scale_i, levels_i), the step
 * rounded to f32 first (vdsh_s8_step is levels 127). */
static inline float vdsh_quant_step(float scale, int levels)
{
    return scale / (float)levels;
}

/* vdsh_encode_s8 for any quantised encoding (s8, s8s6): dst receives
 * vertices * (bytes per vertex of encoding at nc coefficients), unused
 * bits zero. VDSH_ERR_ARGUMENT also for an encoding that is not one. */
vdsh_result vdsh_encode_quantised(uint32_t encoding, const float *src, size_t vertices, uint32_t nc,
                                  float *scales, void *dst);
/* vdsh_encode_quantised with the scales taken over the drawn vertices only
 * (drawn[v] != 0; NULL: every vertex): the others (receivers no triangle
 * with area touches, never drawn, whose coefficients may be extreme) are
 * stored clamped to their index's range, so they do not coarsen every
 * receiver's steps. vdsh-bake and vdsh-merge both pass the mask of
 * vb_drawn_receivers (bake/lib/mesh.h). Every value is still checked
 * finite. */
vdsh_result vdsh_encode_quantised_drawn(uint32_t encoding, const float *src, size_t vertices,
                                        uint32_t nc, const uint8_t *drawn, float *scales,
                                        void *dst);

/* Encode a variable-order stream (VDSH.md "Variable-order streams"):
 * row v's first orders[v]^2 of its `stride` values in src (stride >=
 * cap^2) into its record at word offsets[v] of dst (offsets from
 * vdsh_stream_offsets; dst holds 4 * offsets[rows] bytes and is zeroed
 * here, so padding is zero). f32 and f16 store c / scale; s8 and s8s6
 * write scales[cap^2], per index the largest |c| over the rows that
 * store it, and quantise as vdsh_encode_quantised. VDSH_ERR_INVALID for
 * a value that is not finite or does not fit; VDSH_ERR_ARGUMENT for an
 * order outside 1..cap or other bad arguments. */
vdsh_result vdsh_encode_variable(uint32_t encoding, const float *src, size_t stride,
                                 const uint8_t *orders, uint32_t rows, uint32_t cap, float scale,
                                 const uint32_t *offsets, float *scales, void *dst);
/* vdsh_encode_variable whose s8, s8s6 scales are over the drawn rows only
 * (drawn[v] != 0; NULL: every row), as vdsh_encode_quantised_drawn. */
vdsh_result vdsh_encode_variable_drawn(uint32_t encoding, const float *src, size_t stride,
                                       const uint8_t *orders, uint32_t rows, uint32_t cap,
                                       float scale, const uint32_t *offsets, const uint8_t *drawn,
                                       float *scales, void *dst);

/* Bytes per vertex of encoding e at nc coefficients (0 if unknown). */
size_t vdsh_encoding_bytes(uint32_t e, uint32_t nc);

/* Encode an s8 stream: `vertices` vertices of `nc` coefficients (src,
 * vertex-major) to scales[nc] (per index: the largest |coefficient| over
 * the vertices, 0 when all are 0) and dst[vertices * nc]: each value
 * rounded to the nearest multiple of its index's step, ties away from 0,
 * clamped to -127..127 (an index with scale 0 stores 0). vdsh-bake and
 * vdsh-merge both call this, so their bytes agree. Returns
 * VDSH_ERR_INVALID if an input is not finite or an index's largest |c| is
 * so near FLT_MAX that 127 steps overflow (outputs then unspecified),
 * VDSH_ERR_ARGUMENT if nc is not 1..VDSH_MAX_COEFFS. */
vdsh_result vdsh_encode_s8(const float *src, size_t vertices, uint32_t nc, float *scales,
                           int8_t *dst);

/* The scale every writer of an f16 stream uses (VDSH.md, COEF): the
 * stream's largest |coefficient| `amax`, or 1 for an all-zero stream, so
 * stored values lie in [-1, 1]. vdsh-bake and vdsh-merge must agree on it
 * to the bit (merged files are byte-identical to whole bakes). */
static inline float vdsh_f16_scale(float amax)
{
    return amax > 0.0f ? amax : 1.0f;
}

/* CRC-32 (zlib/PNG), continuing from `crc` (start with 0). */
uint32_t vdsh_crc32(uint32_t crc, const void *data, size_t size);

/* One chunk as it lies in a file image, for tools that list and check
 * chunks (vdsh-info --verify). */
typedef struct vdsh_chunk_info {
    char id[5]; /* the 4 id bytes + NUL; non-letters read as '?' */
    /* payload and padding lie inside the data; if 0, crc_computed is 0 and
     * this is the last entry */
    int complete;
    uint64_t offset; /* of the 16-byte chunk header */
    uint64_t size;   /* payload bytes the header states (no padding) */
    uint32_t crc_stored;
    uint32_t crc_computed; /* over id, size, payload and padding */
} vdsh_chunk_info;

/* List the chunks of a file image without judging it: walk chunk headers
 * back to back from offset 32 to the end of the data, ignoring the file
 * header's chunk_count and CRC so that a damaged file still lists, and
 * compute every chunk's CRC. The walk stops at the end of the data, where
 * fewer than 16 bytes remain, or after a chunk that is not complete.
 * Writes the first `max` entries to `out` (NULL is fine when max is 0) and
 * the number found to *count, which may exceed max.
 * Returns VDSH_ERR_NOT_VDSH or VDSH_ERR_TRUNCATED (outputs untouched) when
 * the data does not start with the magic and a 32-byte header, else
 * VDSH_OK: CRC mismatches and incomplete chunks are in the entries for the
 * caller to report. Whether the file is valid is vdsh_read_memory's call. */
vdsh_result vdsh_scan_chunks(const void *data, size_t size, const char *name, vdsh_chunk_info *out,
                             uint32_t max, uint32_t *count, vdsh_error *err);

#ifdef __cplusplus
}
#endif

#endif /* VDSH_H */
