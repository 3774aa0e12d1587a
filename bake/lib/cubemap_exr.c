/*
 * cubemap_exr.c - basis cubemaps as OpenEXR files, with OpenEXR's C API
 * (OpenEXRCore) only. See cubemap.h for the contract.
 *
 * OpenEXR does its I/O through our own read/write callbacks on a file
 * descriptor we opened. That is how we
 *  - decide where the temporary file goes and when it is renamed:
 *    OpenEXR's EXR_INTERMEDIATE_TEMP_FILE mode does rename, but it names
 *    the temporary "tmp.<pid><name>" (two threads writing the same
 *    destination collide), opens it without O_EXCL (it truncates a file
 *    that happens to have that name) and never fsyncs before renaming
 *    (after a crash the destination can be empty); ours is the project's
 *    one atomic output (vdsh_output.h), written at offsets through its fd;
 *  - get our own user data into OpenEXR's error handler, which receives
 *    only the context: the handler stores the message in that user data
 *    and it ends up in vb_error instead of on stderr;
 *  - tell an OS error (VB_ERR_IO) from a corrupt file (VB_ERR_FORMAT).
 * (What is said here about OpenEXR's internals is from reading its 3.1
 * sources and from the tests, not from its documentation.)
 *
 * Reading uses OpenEXR's chunk reader and decompressor but our own last
 * step, the conversion to float RGBA (unpack_to_float, for why).
 */
#include "cubemap.h"
#include "vdsh_cube.h"
#include "vdsh_output.h"

#include <openexr.h>

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ------------------------------------------------------------------ */
/* I/O callbacks and error capture                                      */

typedef struct exr_io {
    int fd;        /* -1: writes go to mem */
    int os_errno;  /* errno of the first failed read or write, or 0 */
    char msg[256]; /* first message OpenEXR reported since reset */
    uint8_t *mem;  /* a file written to memory: size bytes, cap allocated */
    size_t size, cap;
} exr_io;

static void io_reset_msg(exr_io *io)
{
    io->msg[0] = '\0';
}

static void on_exr_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    void *ud = NULL;
    /* A NULL context only happens when OpenEXR cannot allocate one; the
     * caller then reports the result code alone. */
    if (!ctxt || exr_get_user_data(ctxt, &ud) != EXR_ERR_SUCCESS || !ud)
        return;
    exr_io *io = ud;
    /* The first message of a failing step is the specific one; later
     * ones tend to be consequences ("failed to read chunk"). */
    if (io->msg[0] == '\0')
        snprintf(io->msg, sizeof io->msg, "%s", msg ? msg : exr_get_error_code_as_string(code));
}

/* Read into `to` or write from `from` the whole of [offset, offset +
 * size) of io's file, at most 1 GiB a call, through interruptions. The
 * bytes moved (fewer when a read meets the end of the file: OpenEXR
 * reports the short read), or -1 with the first errno kept in io. */
static int64_t io_transfer(exr_const_context_t ctxt, exr_io *io, uint8_t *to, const uint8_t *from,
                           uint64_t size, uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    uint64_t done = 0;
    while (done < size) {
        uint64_t want = size - done;
        if (want > (1u << 30))
            want = 1u << 30;
        ssize_t r = from ? pwrite(io->fd, from + done, (size_t)want, (off_t)(offset + done))
                         : pread(io->fd, to + done, (size_t)want, (off_t)(offset + done));
        if (r < 0) {
            if (errno == EINTR)
                continue;
            if (!io->os_errno)
                io->os_errno = errno;
            if (error_cb)
                error_cb(ctxt, from ? EXR_ERR_WRITE_IO : EXR_ERR_READ_IO, "%s failed: %s",
                         from ? "write" : "read", strerror(errno));
            return -1;
        }
        if (r == 0 && !from)
            break;
        done += (uint64_t)r;
    }
    return (int64_t)done;
}

static int64_t io_read(exr_const_context_t ctxt, void *ud, void *buffer, uint64_t size,
                       uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    exr_io *io = ud;
    uint8_t *p = buffer;
    if (offset > (uint64_t)INT64_MAX || size > (uint64_t)INT64_MAX - offset) {
        if (error_cb)
            error_cb(ctxt, EXR_ERR_READ_IO,
                     "read of %" PRIu64 " bytes at offset %" PRIu64 " out of range", size, offset);
        return -1;
    }
    return io_transfer(ctxt, io, p, NULL, size, offset, error_cb);
}

static int64_t io_size(exr_const_context_t ctxt, void *ud)
{
    exr_io *io = ud;
    struct stat st;
    (void)ctxt;
    if (fstat(io->fd, &st) != 0)
        return -1;
    return (int64_t)st.st_size;
}

static int64_t io_write(exr_const_context_t ctxt, void *ud, const void *buffer, uint64_t size,
                        uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    exr_io *io = ud;
    const uint8_t *p = buffer;
    if (offset > (uint64_t)INT64_MAX || size > (uint64_t)INT64_MAX - offset) {
        if (error_cb)
            error_cb(ctxt, EXR_ERR_WRITE_IO, "write out of range");
        return -1;
    }
    if (io->fd < 0) { /* OpenEXR writes at offsets, the offset table last */
        uint64_t end = offset + size;
        if (end > io->cap) {
            size_t cap = io->cap ? io->cap : 65536;
            while (cap < end && cap <= SIZE_MAX / 2)
                cap *= 2;
            uint8_t *mem = cap >= end ? realloc(io->mem, cap) : NULL;
            if (!mem) {
                if (error_cb)
                    error_cb(ctxt, EXR_ERR_OUT_OF_MEMORY, "out of memory");
                return -1;
            }
            io->mem = mem;
            io->cap = cap;
        }
        if (offset > io->size)
            memset(io->mem + io->size, 0, (size_t)(offset - io->size));
        memcpy(io->mem + offset, p, (size_t)size);
        if (end > io->size)
            io->size = (size_t)end;
        return (int64_t)size;
    }
    return io_transfer(ctxt, io, NULL, p, size, offset, error_cb);
}

/* Turn a failed OpenEXR call into a vb_result and a message:
 * "<path>: <what>: <OpenEXR's message>". `otherwise` is the code when
 * neither the OS nor memory is to blame (FORMAT when reading). */
static vb_result exr_fail(vb_error *err, const exr_io *io, exr_result_t rv, vb_result otherwise,
                          const char *path, const char *what)
{
    vb_result r = otherwise;
    if (rv == EXR_ERR_OUT_OF_MEMORY)
        r = VB_ERR_OUT_OF_MEMORY;
    else if (io->os_errno)
        r = VB_ERR_IO;
    const char *detail = io->msg[0] ? io->msg : exr_get_default_error_message(rv);
    return vb_fail(err, r, "%s: %s: %s", path, what, detail);
}

/* Channel name -> component index in our RGBA layout, -1 if not ours. */
static int channel_component(const char *name)
{
    static const char *const names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; c++)
        if (name && strcmp(name, names[c]) == 0)
            return c;
    return -1;
}

static size_t cube_floats(int n)
{
    return (size_t)n * 6u * (size_t)n * 4u;
}

/* ------------------------------------------------------------------ */
/* Writing                                                              */

/* A context's initializer: OpenEXR's messages go to io. */
static exr_context_initializer_t context_init(exr_io *io)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_exr_error;
    init.user_data = io;
    return init;
}

/* In encode_exr and decode_exr: run an OpenEXR call; when it fails, r is
 * its vb_result (the function's `otherwise` when neither the OS nor
 * memory is to blame) and the function goes to its clean-up. */
#define EXR_TRY(call, what)                                                                        \
    do {                                                                                           \
        io_reset_msg(io);                                                                          \
        rv = (call);                                                                               \
        if (rv != EXR_ERR_SUCCESS) {                                                               \
            r = exr_fail(err, io, rv, otherwise, path, (what));                                    \
            goto done;                                                                             \
        }                                                                                          \
    } while (0)

/* Encode the image through *io_out: into its open file descriptor, or
 * into memory when that is -1. `path` is only for messages. */
static vb_result encode_exr(const char *path, exr_io *io, int n, const float *rgba, vb_error *err)
{
    exr_context_t ctxt = NULL;
    exr_encode_pipeline_t enc;
    int enc_live = 0, part = 0;
    int32_t lines = 0;
    vb_result r = VB_OK;
    exr_result_t rv;
    const vb_result otherwise = VB_ERR_IO; /* EXR_TRY's */
    exr_context_initializer_t init = context_init(io);
    init.write_fn = io_write;

    memset(&enc, 0, sizeof enc);

    /* The header: exactly what cube maps need, nothing that varies from
     * run to run (no date, no software version), so the bytes depend on
     * the pixels only. */
    EXR_TRY(exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init), "cannot start writing");
    EXR_TRY(exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part), "cannot add image part");
    EXR_TRY(exr_initialize_required_attr_simple(ctxt, part, n, 6 * n, EXR_COMPRESSION_ZIP),
            "cannot set header");
    /* OpenEXR keeps the channel list sorted (A, B, G, R in the file). */
    static const char *const names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; c++)
        EXR_TRY(exr_add_channel(ctxt, part, names[c], EXR_PIXEL_HALF, EXR_PERCEPTUALLY_LOGARITHMIC,
                                1, 1),
                "cannot add channel");
    EXR_TRY(exr_attr_set_envmap(ctxt, part, "envmap", EXR_ENVMAP_CUBE),
            "cannot set envmap attribute");
    EXR_TRY(exr_write_header(ctxt), "cannot write header");
    EXR_TRY(exr_get_scanlines_per_chunk(ctxt, part, &lines), "cannot query chunk size");

    /* One chunk of `lines` scanlines at a time; OpenEXR converts our
     * floats to half (round to nearest even) while packing. Unlike its
     * unpacker (see unpack_to_float), OpenEXR 3.1's packer gets this
     * interleaved layout right: tests/test_cube_openexr.cpp reads our
     * files with OpenEXR's C++ reader and test_cube.c checks every value
     * against vdsh_f16_from_f32. */
    for (int y = 0; y < 6 * n; y += lines) {
        exr_chunk_info_t ci;
        EXR_TRY(exr_write_scanline_chunk_info(ctxt, part, y, &ci), "cannot prepare scanline chunk");
        if (!enc_live) {
            EXR_TRY(exr_encoding_initialize(ctxt, part, &ci, &enc), "cannot start encoder");
            enc_live = 1;
        } else {
            EXR_TRY(exr_encoding_update(ctxt, part, &ci, &enc), "cannot update encoder");
        }
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            int comp = channel_component(ch->channel_name);
            /* We declared exactly R, G, B, A. */
            if (comp < 0) {
                r = vb_fail(err, VB_ERR_IO, "%s: unexpected channel '%s'", path,
                            ch->channel_name ? ch->channel_name : "?");
                goto done;
            }
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 4 * (int32_t)sizeof(float);
            ch->user_line_stride = n * 4 * (int32_t)sizeof(float);
            ch->encode_from_ptr =
                (const uint8_t *)(rgba + (size_t)ci.start_y * (size_t)n * 4 + comp);
        }
        if (y == 0)
            EXR_TRY(exr_encoding_choose_default_routines(ctxt, part, &enc),
                    "cannot choose encoder");
        EXR_TRY(exr_encoding_run(ctxt, part, &enc), "cannot encode chunk");
    }

    if (enc_live) {
        enc_live = 0;
        EXR_TRY(exr_encoding_destroy(ctxt, &enc), "cannot finish encoder");
    }
    /* exr_finish writes the chunk offset table. */
    {
        exr_context_t c = ctxt;
        ctxt = NULL;
        EXR_TRY(exr_finish(&c), "cannot finish file");
    }

done:
    if (enc_live)
        exr_encoding_destroy(ctxt, &enc);
    if (ctxt)
        exr_finish(&ctxt);
    return r;
}

/* Write the image to a new temporary file beside `path` and flush it to
 * disk (vdsh_output.h): encoded from rgba, or, if `encoded` is not NULL,
 * the file already encoded in memory. On failure nothing is left behind. */
static vb_result stage(const char *path, int n, const float *rgba, const exr_io *encoded,
                       vdsh_output *out, vb_error *err)
{
    vdsh_error ve;
    vdsh_result vr = vdsh_output_open(path, out, &ve);
    if (vr != VDSH_OK)
        return vb_fail(err,
                       vr == VDSH_ERR_OUT_OF_MEMORY ? VB_ERR_OUT_OF_MEMORY
                       : vr == VDSH_ERR_ARGUMENT    ? VB_ERR_ARGUMENT
                                                    : VB_ERR_IO,
                       "%s", ve.msg);
    /* OpenEXR writes at offsets: straight to the descriptor, never
     * through the (unused) stream. */
    exr_io io = {.fd = out->fd};
    const char *tmp = out->tmp ? out->tmp : path;
    vb_result r = VB_OK;
    if (!encoded)
        r = encode_exr(path, &io, n, rgba, err);
    else if (io_write(NULL, &io, encoded->mem, encoded->size, 0, NULL) < 0)
        r = vb_fail(err, VB_ERR_IO, "%s: cannot write %s: %s", path, tmp, strerror(io.os_errno));
    if (r != VB_OK) {
        vdsh_output_abort(out);
        return r;
    }
    if (vdsh_output_finish(out, &ve) != VDSH_OK)
        return vb_fail(err, VB_ERR_IO, "%s", ve.msg);
    return VB_OK;
}

static vb_result commit(vdsh_output *s, vb_error *err)
{
    vdsh_error ve;
    if (vdsh_output_commit(s, &ve) != VDSH_OK)
        return vb_fail(err, VB_ERR_IO, "%s", ve.msg);
    return VB_OK;
}

static vb_result check_size(const char *what, int n, vb_error *err)
{
    if (n < 1 || n > VB_CUBEMAP_MAX_SIZE)
        return vb_fail(err, VB_ERR_ARGUMENT, "%s: cube map face size %d not in 1..%d", what, n,
                       VB_CUBEMAP_MAX_SIZE);
    return VB_OK;
}

vb_result vb_cubemap_write(const char *path, int n, const float *rgba, vb_error *err)
{
    if (!path || !path[0] || !rgba)
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_cubemap_write: %s is NULL",
                       !path || !path[0] ? "path" : "rgba");
    vb_result r = check_size(path, n, err);
    if (r != VB_OK)
        return r;

    /* Half's largest finite value is 65504; anything from 65520 up (or
     * NaN) would be stored as Inf/NaN and poison every lookup. */
    size_t count = cube_floats(n);
    for (size_t k = 0; k < count; k++) {
        if (!(fabsf(rgba[k]) < 65520.0f)) {
            size_t texel = k / 4, row = texel / (size_t)n;
            return vb_fail(err, VB_ERR_INVALID,
                           "%s: value %g at face %zu texel (%zu, %zu) channel "
                           "%c is not representable as a finite half",
                           path, (double)rgba[k], row / (size_t)n, texel % (size_t)n,
                           row % (size_t)n, "RGBA"[k % 4]);
        }
    }

    vdsh_output s;
    r = stage(path, n, rgba, NULL, &s, err);
    if (r == VB_OK)
        r = commit(&s, err);
    return r;
}

/* ------------------------------------------------------------------ */
/* Reading                                                              */

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "cubemap_exr.c unpacks little-endian EXR data in place: LE hosts only"
#endif

/* IEEE binary16 -> binary32, exact. */
static float half_bits_to_float(uint16_t h)
{
    uint32_t exp = (h >> 10) & 0x1fu, mant = h & 0x3ffu, bits;
    if (exp == 0) {
        float f = (float)mant * 0x1p-24f; /* zero or subnormal, exact */
        return (h & 0x8000u) ? -f : f;
    }
    bits = ((uint32_t)(h & 0x8000u) << 16) | (mant << 13) |
           (exp == 0x1f ? 0x7f800000u : (exp + 112u) << 23);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* Our own last stage of OpenEXR's decode pipeline. OpenEXR 3.1's
 * specialised unpackers pick a fast path from the output pointers, and
 * the one chosen for interleaved float RGBA from half A, B, G, R
 * ("4chan_interleave_rev") puts the channels back in the wrong order.
 * The decompressed chunk is simple: for each scanline, each channel's
 * samples in file (alphabetical) order, little-endian. */
static exr_result_t unpack_to_float(exr_decode_pipeline_t *d)
{
    const uint8_t *src = d->unpacked_buffer;
    uint64_t left = d->chunk.unpacked_size;
    for (int y = 0; y < d->chunk.height; y++) {
        for (int c = 0; c < d->channel_count; c++) {
            const exr_coding_channel_info_t *ch = &d->channels[c];
            if (ch->height == 0)
                continue;
            /* Subsampled (extra) channels have no samples on most lines. */
            if (ch->y_samples > 1 && ((d->chunk.start_y + y) % ch->y_samples) != 0)
                continue;
            uint64_t bytes = (uint64_t)ch->width * (uint64_t)ch->bytes_per_element;
            if (!src || bytes > left)
                return EXR_ERR_CORRUPT_CHUNK;
            if (ch->decode_to_ptr) {
                uint8_t *dst = ch->decode_to_ptr + (size_t)y * (size_t)ch->user_line_stride;
                for (int x = 0; x < ch->width; x++) {
                    float v;
                    if (ch->data_type == EXR_PIXEL_HALF) {
                        uint16_t h;
                        memcpy(&h, src + 2 * (size_t)x, 2);
                        v = half_bits_to_float(h);
                    } else {
                        memcpy(&v, src + 4 * (size_t)x, 4);
                    }
                    memcpy(dst + (size_t)x * (size_t)ch->user_pixel_stride, &v, 4);
                }
            }
            src += bytes;
            left -= bytes;
        }
    }
    return EXR_ERR_SUCCESS;
}

static vb_result decode_exr(const char *path, exr_io *io, vb_cubemap **out, vb_error *err)
{
    const vb_result otherwise = VB_ERR_FORMAT; /* EXR_TRY's */
    exr_context_t ctxt = NULL;
    exr_decode_pipeline_t dec;
    int dec_live = 0;
    vb_cubemap *map = NULL;
    vb_result r = VB_OK;
    exr_result_t rv;
    exr_context_initializer_t init = context_init(io);

    memset(&dec, 0, sizeof dec);
    init.read_fn = io_read;
    init.size_fn = io_size;
    /* A damaged offset table is an error, not something to guess around
     * by scanning the file for chunks. */
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;

#define BAD(...)                                                                                   \
    do {                                                                                           \
        r = vb_fail(err, VB_ERR_FORMAT, __VA_ARGS__);                                              \
        goto done;                                                                                 \
    } while (0)

    EXR_TRY(exr_start_read(&ctxt, path, &init), "not a readable OpenEXR file");

    exr_storage_t storage;
    EXR_TRY(exr_get_storage(ctxt, 0, &storage), "cannot read storage type");
    if (storage != EXR_STORAGE_SCANLINE)
        BAD("%s: %s OpenEXR images are not supported (cube maps are read "
            "from scanline images)",
            path, storage == EXR_STORAGE_TILED ? "tiled" : "deep");

    /* Is it a cube map at all? */
    const exr_attribute_t *attr = NULL;
    io_reset_msg(io);
    rv = exr_get_attribute_by_name(ctxt, 0, "envmap", &attr);
    if (rv == EXR_ERR_NO_ATTR_BY_NAME || (rv == EXR_ERR_SUCCESS && !attr))
        BAD("%s: not a cube environment map (no envmap attribute)", path);
    if (rv != EXR_ERR_SUCCESS) {
        r = exr_fail(err, io, rv, VB_ERR_FORMAT, path, "cannot read envmap attribute");
        goto done;
    }
    if (attr->type != EXR_ATTR_ENVMAP)
        BAD("%s: envmap attribute has type '%s', not 'envmap'", path,
            attr->type_name ? attr->type_name : "?");
    if (attr->uc != EXR_ENVMAP_CUBE) {
        if (attr->uc == EXR_ENVMAP_LATLONG)
            BAD("%s: not a cube environment map (envmap is latitude-longitude)", path);
        BAD("%s: not a cube environment map (envmap value %u)", path, (unsigned)attr->uc);
    }

    /* Shape: n wide, 6n tall. */
    exr_attr_box2i_t dw;
    EXR_TRY(exr_get_data_window(ctxt, 0, &dw), "cannot read data window");
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1;
    int64_t h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w < 1 || h < 1)
        BAD("%s: empty data window", path);
    if (h != 6 * w)
        BAD("%s: image is %" PRId64 " x %" PRId64 "; a cube map is n x 6n", path, w, h);
    if (w > VB_CUBEMAP_MAX_SIZE)
        BAD("%s: cube map face size %" PRId64 " not in 1..%d", path, w, VB_CUBEMAP_MAX_SIZE);
    int n = (int)w;

    /* Channels R, G, B, A, half or float, full resolution. */
    const exr_attr_chlist_t *chl = NULL;
    EXR_TRY(exr_get_channels(ctxt, 0, &chl), "cannot read channel list");
    int found[4] = {0, 0, 0, 0};
    for (int c = 0; chl && c < chl->num_channels; c++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[c];
        /* Any channel, used or not: OpenEXRCore 3.1's B44 decoder reads
         * past its buffer on subsampled channels (a fuzzer find,
         * tests/corpus/regressions/cubemap), and no basis map has one. */
        if (e->x_sampling != 1 || e->y_sampling != 1)
            BAD("%s: channel %s is subsampled", path, e->name.str);
        int comp = channel_component(e->name.str);
        if (comp < 0)
            continue;
        if (e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT)
            BAD("%s: channel %s is not half or float", path, e->name.str);
        found[comp] = 1;
    }
    for (int c = 0; c < 4; c++)
        if (!found[c])
            BAD("%s: channel %c missing (need R, G, B, A)", path, "RGBA"[c]);

    int32_t lines = 0;
    EXR_TRY(exr_get_scanlines_per_chunk(ctxt, 0, &lines), "cannot query chunk size");
    if (lines < 1)
        BAD("%s: invalid scanlines per chunk (%d)", path, (int)lines);

    map = calloc(1, sizeof *map);
    if (map)
        map->rgba = calloc(cube_floats(n), sizeof(float));
    if (!map || !map->rgba) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory for a %d x %d cube map", path, n,
                    6 * n);
        goto done;
    }
    map->size = n;

    for (int64_t y = dw.min.y; y <= dw.max.y; y += lines) {
        exr_chunk_info_t ci;
        EXR_TRY(exr_read_scanline_chunk_info(ctxt, 0, (int)y, &ci), "cannot read scanline chunk");
        /* The chunk must lie inside our buffer whatever the file says. */
        int64_t row = (int64_t)ci.start_y - dw.min.y;
        if (row < 0 || ci.height < 1 || row + ci.height > h || ci.width != w)
            BAD("%s: chunk for scanline %" PRId64 " has bad extent", path, y);
        if (!dec_live) {
            EXR_TRY(exr_decoding_initialize(ctxt, 0, &ci, &dec), "cannot start decoder");
            dec_live = 1;
        } else {
            EXR_TRY(exr_decoding_update(ctxt, 0, &ci, &dec), "cannot update decoder");
        }
        for (int c = 0; c < dec.channel_count; c++) {
            exr_coding_channel_info_t *ch = &dec.channels[c];
            int comp = channel_component(ch->channel_name);
            if (comp < 0 || ch->width != n || ch->height != ci.height) {
                ch->decode_to_ptr = NULL; /* skipped */
                continue;
            }
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 4 * (int32_t)sizeof(float);
            ch->user_line_stride = n * 4 * (int32_t)sizeof(float);
            ch->decode_to_ptr = (uint8_t *)(map->rgba + (size_t)row * (size_t)n * 4 + comp);
        }
        if (y == dw.min.y) {
            /* OpenEXR's reader and decompressor, our unpacker. */
            EXR_TRY(exr_decoding_choose_default_routines(ctxt, 0, &dec), "cannot choose decoder");
            dec.unpack_and_convert_fn = unpack_to_float;
        }
        EXR_TRY(exr_decoding_run(ctxt, 0, &dec), "cannot decode chunk");
    }

    /* NaN or Inf in a basis map would turn whole regions of shadow into
     * garbage on the GPU; a file holding them is damaged. */
    size_t count = cube_floats(n);
    for (size_t k = 0; k < count; k++) {
        if (!isfinite(map->rgba[k])) {
            size_t texel = k / 4, yrow = texel / (size_t)n;
            r = vb_fail(err, VB_ERR_INVALID,
                        "%s: value at face %zu texel (%zu, %zu) channel %c is "
                        "not finite",
                        path, yrow / (size_t)n, texel % (size_t)n, yrow % (size_t)n, "RGBA"[k % 4]);
            goto done;
        }
    }
#undef BAD
#undef EXR_TRY

    *out = map;
    map = NULL;

done:
    if (dec_live)
        exr_decoding_destroy(ctxt, &dec);
    if (ctxt)
        exr_finish(&ctxt);
    vb_cubemap_free(map);
    return r;
}

vb_result vb_cubemap_read(const char *path, vb_cubemap **out, vb_error *err)
{
    if (!path || !path[0] || !out)
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_cubemap_read: %s is NULL", !out ? "out" : "path");
    exr_io io = {.fd = -1};
    /* O_NONBLOCK: opening a FIFO must not wait for a writer (it is refused
     * below); regular files ignore the flag. */
    io.fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (io.fd < 0)
        return vb_fail(err, VB_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(io.fd, &st) == 0 && !S_ISREG(st.st_mode)) {
        close(io.fd);
        return vb_fail(err, VB_ERR_IO, "%s: not a regular file", path);
    }
    vb_result r = decode_exr(path, &io, out, err);
    close(io.fd);
    return r;
}

void vb_cubemap_free(vb_cubemap *map)
{
    if (map) {
        free(map->rgba);
        free(map);
    }
}

/* ------------------------------------------------------------------ */
/* The set of four basis files                                          */

vb_result vb_cubemap_basis_path(const char *dir, const char *stem, int k, char *buf, size_t size,
                                vb_error *err)
{
    if (!stem || !stem[0] || !buf)
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_cubemap_basis_path: %s is NULL or empty",
                       !buf ? "buf" : "stem");
    if (k < 0 || k >= VB_CUBEMAP_BASIS_FILES)
        return vb_fail(err, VB_ERR_ARGUMENT, "vb_cubemap_basis_path: file index %d not in 0..%d", k,
                       VB_CUBEMAP_BASIS_FILES - 1);
    const char *d = dir ? dir : "";
    size_t dl = strlen(d);
    const char *sep = (dl > 0 && d[dl - 1] != '/') ? "/" : "";
    int first = 9 + 4 * k;
    /* Measure first: buf must stay untouched on failure. */
    int len = snprintf(NULL, 0, "%s%s%s.sh%02d-%02d.exr", d, sep, stem, first, first + 3);
    if (len < 0 || (size_t)len >= size)
        return vb_fail(err, VB_ERR_ARGUMENT,
                       "%s%s%s: basis cubemap path too long (%d bytes, buffer %zu)", d, sep, stem,
                       len, size);
    snprintf(buf, size, "%s%s%s.sh%02d-%02d.exr", d, sep, stem, first, first + 3);
    return VB_OK;
}

/* malloc'd path of basis file k. */
static vb_result basis_path_alloc(const char *dir, const char *stem, int k, char **out,
                                  vb_error *err)
{
    size_t size = (dir ? strlen(dir) : 0) + (stem ? strlen(stem) : 0) + 32;
    char *p = malloc(size);
    if (!p)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory", stem ? stem : "basis path");
    vb_result r = vb_cubemap_basis_path(dir, stem, k, p, size, err);
    if (r != VB_OK) {
        free(p);
        return r;
    }
    *out = p;
    return VB_OK;
}

vb_result vb_cubemap_basis_encode(int n, vb_cubemap_basis *out, vb_error *err)
{
    vb_cubemap_basis b = {.size = n};
    float *rgba = NULL;
    vb_result r = check_size("vb_cubemap_basis_encode", n, err);
    if (r == VB_OK && !(rgba = malloc(cube_floats(n) * sizeof(float))))
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for a %d x %d cube map", n, 6 * n);
    for (int k = 0; r == VB_OK && k < VB_CUBEMAP_BASIS_FILES; k++) {
        char name[32];
        snprintf(name, sizeof name, "basis cubemap sh%02d-%02d", 9 + 4 * k, 12 + 4 * k);
        exr_io io = {.fd = -1};
        vdsh_cube_fill_basis(n, 9 + 4 * k, rgba);
        r = encode_exr(name, &io, n, rgba, err);
        b.bytes[k] = io.mem;
        b.length[k] = io.size;
    }
    free(rgba);
    if (r != VB_OK)
        vb_cubemap_basis_free(&b);
    else
        *out = b;
    return r;
}

vb_result vb_cubemap_basis_stage(const vb_cubemap_basis *b, const char *dir, const char *stem,
                                 vdsh_output staged[VB_CUBEMAP_BASIS_FILES], vb_error *err)
{
    char *paths[VB_CUBEMAP_BASIS_FILES] = {0};
    vb_result r = VB_OK;
    for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
        staged[k] = (vdsh_output){.fd = -1};
    for (int k = 0; r == VB_OK && k < VB_CUBEMAP_BASIS_FILES; k++)
        r = basis_path_alloc(dir, stem, k, &paths[k], err);
    for (int k = 0; r == VB_OK && k < VB_CUBEMAP_BASIS_FILES; k++) {
        exr_io encoded = {.fd = -1, .mem = b->bytes[k], .size = b->length[k]};
        r = stage(paths[k], b->size, NULL, &encoded, &staged[k], err);
    }
    for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++) {
        if (r != VB_OK)
            vdsh_output_abort(&staged[k]);
        free(paths[k]);
    }
    return r;
}

vb_result vb_cubemap_basis_write(const vb_cubemap_basis *b, const char *dir, const char *stem,
                                 vb_error *err)
{
    vdsh_output st[VB_CUBEMAP_BASIS_FILES];
    /* Stage all four, then rename: a failure while writing leaves every
     * destination as it was, never a mix of two bakes. */
    vb_result r = vb_cubemap_basis_stage(b, dir, stem, st, err);
    for (int k = 0; r == VB_OK && k < VB_CUBEMAP_BASIS_FILES; k++) {
        r = commit(&st[k], err);
        if (r != VB_OK && k > 0)
            vb_append(err, " (the first %d basis files were already replaced)", k);
    }

    for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
        vdsh_output_abort(&st[k]);
    return r;
}

void vb_cubemap_basis_free(vb_cubemap_basis *b)
{
    if (!b)
        return;
    for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
        free(b->bytes[k]);
    memset(b, 0, sizeof *b);
}

vb_result vb_cubemap_write_basis(const char *dir, const char *stem, int n, vb_error *err)
{
    /* The arguments first, so that a bad one costs no encoding. */
    char *path = NULL;
    vb_result r = check_size(stem ? stem : "vb_cubemap_write_basis", n, err);
    if (r == VB_OK)
        r = basis_path_alloc(dir, stem, 0, &path, err);
    free(path);
    vb_cubemap_basis b = {0};
    if (r == VB_OK)
        r = vb_cubemap_basis_encode(n, &b, err);
    if (r == VB_OK)
        r = vb_cubemap_basis_write(&b, dir, stem, err);
    vb_cubemap_basis_free(&b);
    return r;
}

vb_result vb_cubemap_read_basis(const char *dir, const char *stem, int expected_size,
                                vb_cubemap *out[VB_CUBEMAP_BASIS_FILES], vb_error *err)
{
    vb_cubemap *maps[VB_CUBEMAP_BASIS_FILES] = {0};
    vb_result r = VB_OK;
    if (!out)
        r = vb_fail(err, VB_ERR_ARGUMENT, "vb_cubemap_read_basis: out is NULL");
    else if (expected_size != 0)
        r = check_size(stem ? stem : "vb_cubemap_read_basis", expected_size, err);

    for (int k = 0; r == VB_OK && k < VB_CUBEMAP_BASIS_FILES; k++) {
        char *path = NULL;
        r = basis_path_alloc(dir, stem, k, &path, err);
        if (r == VB_OK)
            r = vb_cubemap_read(path, &maps[k], err);
        if (r == VB_OK) {
            int want = expected_size ? expected_size : maps[0]->size;
            if (maps[k]->size != want)
                r = vb_fail(err, VB_ERR_FORMAT, "%s: face size %d, expected %d%s", path,
                            maps[k]->size, want,
                            expected_size ? " (cube_size of the bake)"
                                          : " (as the first basis file)");
        }
        free(path);
    }

    if (r == VB_OK) {
        for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
            out[k] = maps[k];
    } else {
        for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
            vb_cubemap_free(maps[k]);
    }
    return r;
}
