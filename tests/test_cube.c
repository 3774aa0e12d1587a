/*
 * test_cube.c - cube-face conventions (formats/vdsh_cube.c) and the basis
 * cubemap files (bake/lib/cubemap_exr.c).
 *
 *   test_cube conventions          pure math: GL table, EXR<->GL, basis
 *   test_cube files DIR            write/read round trips, header, bytes;
 *                                  the runtime's GL half texels
 *                                  (vdsh_cube_basis_face_gl_f16) against
 *                                  the files, bit for bit
 *   test_cube errors DIR           bad files and failing writes
 *   test_cube write PATH N         write one basis file (for exrheader)
 *
 * OpenEXR's own C++ implementation is checked in test_cube_openexr.cpp.
 */
#include "cubemap.h"
#include "test_dir.h"
#include "vdsh.h"
#include "vdsh_cube.h"
#include "vdsh_sh.h"

#include <openexr.h>

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int failures;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            failures++;                                                                            \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);               \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
        }                                                                                          \
    } while (0)

static const int sizes[] = {1, 2, 3, 8, 64};
#define NSIZES ((int)(sizeof sizes / sizeof sizes[0]))

/* ------------------------------------------------------------------ */
/* Half rounding. Files are compared with formats/vdsh.c's conversion;
 * this independent reference (IEEE binary16, round to nearest even)
 * checks that conversion first.                                        */

static uint16_t ref_f16(float f)
{
    uint32_t x;
    memcpy(&x, &f, 4);
    uint16_t sign = (uint16_t)((x >> 16) & 0x8000u);
    uint32_t ax = x & 0x7fffffffu;
    if (ax >= 0x7f800000u)
        return (uint16_t)(sign | 0x7c00u | (ax > 0x7f800000u ? 0x200u : 0u));
    if (ax >= 0x477ff000u) /* >= 65520 rounds to infinity */
        return (uint16_t)(sign | 0x7c00u);
    if (ax >= 0x38800000u) { /* normal half */
        uint32_t mant = ax & 0x7fffffu;
        uint32_t h = ((((ax >> 23) - 127u + 15u)) << 10) | (mant >> 13);
        uint32_t rem = mant & 0x1fffu;
        if (rem > 0x1000u || (rem == 0x1000u && (h & 1u)))
            h++; /* a carry into the exponent is still right */
        return (uint16_t)(sign | h);
    }
    float a;
    memcpy(&a, &ax, 4);
    /* Subnormal: units of 2^-24; exact in double, rint rounds to even. */
    return (uint16_t)(sign | (uint16_t)rint((double)a * 16777216.0));
}

static float ref_f32(uint16_t h)
{
    int e = (h >> 10) & 31, m = h & 1023;
    float v;
    if (e == 0)
        v = ldexpf((float)m, -24);
    else if (e == 31)
        v = m ? NAN : INFINITY;
    else
        v = ldexpf((float)(m | 1024), e - 25);
    return (h & 0x8000) ? -v : v;
}

/* What a value becomes after a trip through a half-float file. */
static float half_round(float f)
{
    return vdsh_f32_from_f16(vdsh_f16_from_f32(f));
}

static void test_reference_half(void)
{
    /* Known encodings, including the ties that tell RNE from others. */
    CHECK(ref_f16(1.0f) == 0x3c00, "1.0");
    CHECK(ref_f16(-2.0f) == 0xc000, "-2.0");
    CHECK(ref_f16(65504.0f) == 0x7bff, "max");
    CHECK(ref_f16(65519.0f) == 0x7bff, "65519 rounds down");
    CHECK(ref_f16(65520.0f) == 0x7c00, "65520 rounds to inf");
    CHECK(ref_f16(1.0f + ldexpf(1, -11)) == 0x3c00, "tie to even (down)");
    CHECK(ref_f16(1.0f + 3 * ldexpf(1, -11)) == 0x3c02, "tie to even (up)");
    CHECK(ref_f16(ldexpf(1, -24)) == 0x0001, "smallest subnormal");
    CHECK(ref_f16(ldexpf(1, -25)) == 0x0000, "tie to zero");
    CHECK(ref_f16(3 * ldexpf(1, -25)) == 0x0002, "subnormal tie up");
    CHECK(ref_f16(ldexpf(1, -14)) == 0x0400, "smallest normal");
    for (uint32_t h = 0; h < 0x7c00; h++)
        CHECK(ref_f16(ref_f32((uint16_t)h)) == h, "half %04x round trip", h);

    /* formats/vdsh.c agrees: every half back and forth, and a sweep of
     * about a million float bit patterns (NaN payloads aside). */
    for (uint32_t h = 0; h < 0x10000; h++) {
        float a = vdsh_f32_from_f16((uint16_t)h), b = ref_f32((uint16_t)h);
        CHECK(memcmp(&a, &b, 4) == 0 || (isnan(a) && isnan(b)),
              "vdsh_f32_from_f16(%04x) = %a, want %a", h, (double)a, (double)b);
    }
    int bad = 0;
    for (uint64_t x = 0; x < (1ull << 32); x += 4093) {
        uint32_t bits = (uint32_t)x;
        float f;
        memcpy(&f, &bits, 4);
        if (!isnan(f) && vdsh_f16_from_f32(f) != ref_f16(f) && bad++ < 5)
            fprintf(stderr, "vdsh_f16_from_f32(%a) = %04x, want %04x\n", (double)f,
                    vdsh_f16_from_f32(f), ref_f16(f));
    }
    CHECK(bad == 0, "vdsh_f16_from_f32 differs from the reference %d times", bad);
}

/* ------------------------------------------------------------------ */
/* conventions                                                          */

static float texel_centre(int i, int n)
{
    return (2.0f * (float)i + 1.0f) / (float)n - 1.0f;
}

static void test_gl_table(void)
{
    for (int si = 0; si < NSIZES; si++) {
        int n = sizes[si];
        for (int face = 0; face < 6; face++) {
            int axis = face / 2;
            float sign = (face & 1) ? -1.0f : 1.0f;
            for (int j = 0; j < n; j++) {
                for (int i = 0; i < n; i++) {
                    float g[3];
                    vdsh_cube_gl_dir(face, i, j, n, g);
                    /* Major axis: strictly the face's, with its sign. */
                    CHECK(g[axis] == sign, "n %d face %d (%d,%d): major %g", n, face, i, j,
                          (double)g[axis]);
                    for (int k = 0; k < 3; k++)
                        if (k != axis)
                            CHECK(fabsf(g[k]) < 1.0f, "n %d face %d minor", n, face);
                    /* GL 4.6 table 8.19: sc, tc, ma per major axis. */
                    float rx = g[0], ry = g[1], rz = g[2], sc, tc, ma;
                    switch (face) {
                    case 0:
                        sc = -rz;
                        tc = -ry;
                        ma = rx;
                        break;
                    case 1:
                        sc = rz;
                        tc = -ry;
                        ma = rx;
                        break;
                    case 2:
                        sc = rx;
                        tc = rz;
                        ma = ry;
                        break;
                    case 3:
                        sc = rx;
                        tc = -rz;
                        ma = ry;
                        break;
                    case 4:
                        sc = rx;
                        tc = -ry;
                        ma = rz;
                        break;
                    default:
                        sc = -rx;
                        tc = -ry;
                        ma = rz;
                        break;
                    }
                    float s = 0.5f * (sc / fabsf(ma) + 1.0f);
                    float t = 0.5f * (tc / fabsf(ma) + 1.0f);
                    /* Texel centre: s = (i + 0.5) / n. */
                    CHECK(fabsf(s * (float)n - 0.5f - (float)i) < 1e-4f,
                          "n %d face %d (%d,%d): s %g", n, face, i, j, (double)s);
                    CHECK(fabsf(t * (float)n - 0.5f - (float)j) < 1e-4f,
                          "n %d face %d (%d,%d): t %g", n, face, i, j, (double)t);
                }
            }
        }
    }
}

static void test_gl_exr_agree(void)
{
    for (int si = 0; si < NSIZES; si++) {
        int n = sizes[si];
        char *hit = calloc((size_t)n * (size_t)n, 1);
        for (int face = 0; face < 6; face++) {
            memset(hit, 0, (size_t)n * (size_t)n);
            for (int j = 0; j < n; j++) {
                for (int i = 0; i < n; i++) {
                    int ei = -1, ej = -1;
                    vdsh_cube_gl_to_exr(face, i, j, n, &ei, &ej);
                    CHECK(ei >= 0 && ei < n && ej >= 0 && ej < n, "n %d face %d (%d,%d) -> (%d,%d)",
                          n, face, i, j, ei, ej);
                    if (ei < 0 || ei >= n || ej < 0 || ej >= n)
                        continue;
                    hit[ej * n + ei]++;
                    float g[3], e[3];
                    vdsh_cube_gl_dir(face, i, j, n, g);
                    vdsh_cube_exr_dir(face, ei, ej, n, e);
                    /* Parallel (cross product zero), same direction... */
                    float cx = g[1] * e[2] - g[2] * e[1];
                    float cy = g[2] * e[0] - g[0] * e[2];
                    float cz = g[0] * e[1] - g[1] * e[0];
                    float dot = g[0] * e[0] + g[1] * e[1] + g[2] * e[2];
                    CHECK(fabsf(cx) + fabsf(cy) + fabsf(cz) < 1e-6f && dot > 0,
                          "n %d face %d GL (%d,%d) vs EXR (%d,%d) not parallel", n, face, i, j, ei,
                          ej);
                    /* ...and, as the mirrored centres are exact, equal. */
                    CHECK(g[0] == e[0] && g[1] == e[1] && g[2] == e[2],
                          "n %d face %d (%d,%d): (%g %g %g) vs (%g %g %g)", n, face, i, j,
                          (double)g[0], (double)g[1], (double)g[2], (double)e[0], (double)e[1],
                          (double)e[2]);
                    /* The EXR direction is the header's table. */
                    float u = texel_centre(ei, n), v = texel_centre(ej, n);
                    float want[6][3] = {{1, -v, u}, {-1, -v, -u}, {u, 1, -v},
                                        {u, -1, v}, {-u, -v, 1},  {u, -v, -1}};
                    for (int k = 0; k < 3; k++)
                        CHECK(fabsf(e[k] - want[face][k]) < 1e-6f,
                              "n %d face %d EXR (%d,%d) component %d", n, face, ei, ej, k);
                }
            }
            /* A bijection per face: every EXR texel is used exactly once. */
            for (int k = 0; k < n * n; k++)
                CHECK(hit[k] == 1, "n %d face %d EXR texel %d hit %d times", n, face, k, hit[k]);
        }
        free(hit);
    }
}

static void test_fill_basis(void)
{
    for (int si = 0; si < NSIZES; si++) {
        int n = sizes[si];
        size_t count = (size_t)n * 6 * (size_t)n * 4;
        float *rgba = malloc(count * sizeof(float));
        for (int first = 9; first <= 21; first += 4) {
            for (size_t k = 0; k < count; k++)
                rgba[k] = NAN;
            vdsh_cube_fill_basis(n, first, rgba);
            float maxdiff = 0.0f;
            for (int face = 0; face < 6; face++) {
                for (int j = 0; j < n; j++) {
                    for (int i = 0; i < n; i++) {
                        float d[3], y[25];
                        vdsh_cube_exr_dir(face, i, j, n, d);
                        double len =
                            sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
                        for (int k = 0; k < 3; k++)
                            d[k] = (float)(d[k] / len);
                        vdsh_sh_eval(5, d, y);
                        const float *o = rgba + (((size_t)face * n + j) * n + i) * 4;
                        for (int c = 0; c < 4; c++) {
                            float diff = fabsf(o[c] - y[first + c]);
                            if (!(diff <= maxdiff))
                                maxdiff = isnan(diff) ? INFINITY : diff;
                        }
                    }
                }
            }
            CHECK(maxdiff < 2e-6f, "n %d first %d: max |fill - eval| %g", n, first,
                  (double)maxdiff);
        }
        free(rgba);
    }

    /* Index sanity at n = 1, where every texel is a face centre: on +Z
     * (face 4) Y12 = 0.373176 z(5z^2-3) = 0.746353 (A of file 9..12) and
     * Y20 = 0.105786 (35-30+3) = 0.846284 (A of file 17..20); on +X
     * Y15 = -0.590044 x(x^2-3y^2) = -0.590044 (B of file 13..16). */
    float px[24];
    vdsh_cube_fill_basis(1, 9, px);
    CHECK(fabsf(px[4 * 4 + 3] - 0.746353f) < 1e-5f, "Y12(+Z) = %g", (double)px[19]);
    CHECK(fabsf(px[4 * 4 + 0]) < 1e-6f, "Y9(+Z) = %g", (double)px[16]);
    vdsh_cube_fill_basis(1, 17, px);
    CHECK(fabsf(px[4 * 4 + 3] - 0.846284f) < 1e-5f, "Y20(+Z) = %g", (double)px[19]);
    vdsh_cube_fill_basis(1, 13, px);
    CHECK(fabsf(px[0 * 4 + 2] + 0.590044f) < 1e-5f, "Y15(+X) = %g", (double)px[2]);
}

static int run_conventions(void)
{
    test_reference_half();
    test_gl_table();
    test_gl_exr_agree();
    test_fill_basis();
    return failures ? 1 : 0;
}

/* ------------------------------------------------------------------ */
/* File helpers                                                         */

static void rm_rf(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0)
        return;
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        struct dirent *e;
        while (d && (e = readdir(d)) != NULL) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
                continue;
            char sub[4096];
            snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
            rm_rf(sub);
        }
        if (d)
            closedir(d);
        rmdir(path);
    } else {
        unlink(path);
    }
}

static void mkdir_p(const char *path)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *p = buf + 1; *p; p++) {
        if (*p == '/') {
            *p = '\0';
            mkdir(buf, 0777);
            *p = '/';
        }
    }
    mkdir(buf, 0777);
}

static void fresh_dir(const char *path)
{
    rm_rf(path);
    mkdir_p(path);
}

static int count_entries(const char *dir)
{
    return test_count_names(dir, NULL);
}

/* No "*.tmp.*" leftovers in dir (vdsh_output.h names them NAME.tmp.PID.N). */
static int count_temp_files(const char *dir)
{
    return test_count_names(dir, ".tmp.");
}

static unsigned char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc(len > 0 ? (size_t)len : 1);
    if (buf && len > 0 && fread(buf, 1, (size_t)len, f) != (size_t)len) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    *size = (size_t)len;
    return buf;
}

static int write_all(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    int ok = fwrite(data, 1, size, f) == size;
    return fclose(f) == 0 && ok;
}

static void join(char *out, size_t size, const char *dir, const char *name)
{
    int len = snprintf(out, size, "%s/%s", dir, name);
    if (len < 0 || (size_t)len >= size) {
        fprintf(stderr, "test path too long: %s/%s\n", dir, name);
        exit(2);
    }
}

/* Write an arbitrary small scanline EXR with OpenEXRCore directly, for
 * files our writer refuses to make. envmap: -1 none, else the value.
 * Every value of every channel is `value`. */
static int write_odd_exr(const char *path, int w, int h, const char *channels,
                         exr_pixel_type_t type, int envmap, float value)
{
    exr_context_t ctxt = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    int part = 0, nch = (int)strlen(channels), ok = 0;
    float *row = malloc((size_t)w * sizeof(float));
    for (int x = 0; x < w; x++)
        row[x] = value;
    if (exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init) ||
        exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part) ||
        exr_initialize_required_attr_simple(ctxt, part, w, h, EXR_COMPRESSION_NONE))
        goto done;
    for (int c = 0; c < nch; c++) {
        char name[2] = {channels[c], 0};
        if (exr_add_channel(ctxt, part, name, type, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1))
            goto done;
    }
    if (envmap >= 0 && exr_attr_set_envmap(ctxt, part, "envmap", (exr_envmap_t)envmap))
        goto done;
    if (exr_write_header(ctxt))
        goto done;
    exr_encode_pipeline_t enc;
    memset(&enc, 0, sizeof enc);
    for (int y = 0; y < h; y++) {
        exr_chunk_info_t ci;
        if (exr_write_scanline_chunk_info(ctxt, part, y, &ci))
            goto done;
        if (y == 0 ? exr_encoding_initialize(ctxt, part, &ci, &enc)
                   : exr_encoding_update(ctxt, part, &ci, &enc))
            goto done;
        for (int c = 0; c < enc.channel_count; c++) {
            enc.channels[c].user_data_type = EXR_PIXEL_FLOAT;
            enc.channels[c].user_bytes_per_element = 4;
            enc.channels[c].user_pixel_stride = 4;
            enc.channels[c].user_line_stride = 4 * w;
            enc.channels[c].encode_from_ptr = (const uint8_t *)row;
        }
        if (y == 0 && exr_encoding_choose_default_routines(ctxt, part, &enc))
            goto done;
        if (exr_encoding_run(ctxt, part, &enc))
            goto done;
    }
    exr_encoding_destroy(ctxt, &enc);
    ok = exr_finish(&ctxt) == EXR_ERR_SUCCESS;
done:
    if (ctxt)
        exr_finish(&ctxt);
    free(row);
    return ok;
}

/* ------------------------------------------------------------------ */
/* files                                                                */

static void check_header(const char *path, int n)
{
    exr_context_t ctxt = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    CHECK(exr_start_read(&ctxt, path, &init) == EXR_ERR_SUCCESS, "%s: open", path);
    if (!ctxt)
        return;
    exr_envmap_t em = EXR_ENVMAP_LAST_TYPE;
    CHECK(exr_attr_get_envmap(ctxt, 0, "envmap", &em) == EXR_ERR_SUCCESS && em == EXR_ENVMAP_CUBE,
          "%s: envmap %d", path, (int)em);
    exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
    exr_get_storage(ctxt, 0, &storage);
    CHECK(storage == EXR_STORAGE_SCANLINE, "%s: storage %d", path, (int)storage);
    exr_attr_box2i_t dw;
    memset(&dw, 0, sizeof dw);
    exr_get_data_window(ctxt, 0, &dw);
    CHECK(dw.min.x == 0 && dw.min.y == 0 && dw.max.x == n - 1 && dw.max.y == 6 * n - 1,
          "%s: data window", path);
    const exr_attr_chlist_t *chl = NULL;
    exr_get_channels(ctxt, 0, &chl);
    CHECK(chl && chl->num_channels == 4, "%s: channel count", path);
    for (int c = 0; chl && c < chl->num_channels && c < 4; c++) {
        CHECK(strcmp(chl->entries[c].name.str, (const char *[]){"A", "B", "G", "R"}[c]) == 0,
              "%s: channel %d is %s", path, c, chl->entries[c].name.str);
        CHECK(chl->entries[c].pixel_type == EXR_PIXEL_HALF, "%s: not half", path);
    }
    exr_compression_t comp = EXR_COMPRESSION_LAST_TYPE;
    exr_get_compression(ctxt, 0, &comp);
    CHECK(comp == EXR_COMPRESSION_ZIP, "%s: compression %d", path, (int)comp);
    /* Only the attributes we mean to write: nothing that could carry a
     * date or a host name. */
    int32_t attrs = 0;
    exr_get_attribute_count(ctxt, 0, &attrs);
    for (int32_t a = 0; a < attrs; a++) {
        const exr_attribute_t *at = NULL;
        exr_get_attribute_by_index(ctxt, 0, EXR_ATTR_LIST_FILE_ORDER, a, &at);
        static const char *const allowed[] = {
            "channels",  "compression",      "dataWindow",         "displayWindow",     "envmap",
            "lineOrder", "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth", "type"};
        int ok = 0;
        for (size_t k = 0; at && k < sizeof allowed / sizeof allowed[0]; k++)
            ok |= strcmp(at->name, allowed[k]) == 0;
        CHECK(ok, "%s: unexpected attribute %s", path, at ? at->name : "?");
    }
    exr_finish(&ctxt);
}

static void test_basis_round_trip(const char *dir)
{
    const int ns[] = {1, 3, 8, 64};
    for (size_t si = 0; si < sizeof ns / sizeof ns[0]; si++) {
        int n = ns[si];
        vb_error err = {{0}};
        vb_result r = vb_cubemap_write_basis(dir, "room", n, &err);
        CHECK(r == VB_OK, "write_basis n %d: %s", n, err.msg);
        CHECK(count_entries(dir) == 4, "n %d: %d entries in %s", n, count_entries(dir), dir);
        vb_cubemap *maps[VB_CUBEMAP_BASIS_FILES] = {0};
        r = vb_cubemap_read_basis(dir, "room", n, maps, &err);
        CHECK(r == VB_OK, "read_basis n %d: %s", n, err.msg);
        if (r != VB_OK)
            continue;
        size_t count = (size_t)n * 6 * (size_t)n * 4;
        float *want = malloc(count * sizeof(float));
        for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++) {
            CHECK(maps[k]->size == n, "size %d", maps[k]->size);
            vdsh_cube_fill_basis(n, 9 + 4 * k, want);
            size_t bad = 0;
            for (size_t x = 0; x < count; x++)
                if (maps[k]->rgba[x] != half_round(want[x]))
                    bad++;
            CHECK(bad == 0, "n %d file %d: %zu values differ from half rounding", n, k, bad);
            /* What the runtime uploads instead of reading the file: the
             * file's half of every texel, bit for bit (signed zeros
             * too), at the texel vdsh_cube_gl_to_exr names. */
            size_t face_values = (size_t)n * (size_t)n * 4;
            uint16_t *gl = malloc(4 * face_values * sizeof *gl);
            uint16_t *const out[4] = {gl, gl + face_values, gl + 2 * face_values,
                                      gl + 3 * face_values};
            bad = 0;
            for (int f = 0; f < 6; f++) {
                vdsh_cube_basis_face_gl_f16(n, f, out);
                for (int j = 0; j < n; j++)
                    for (int i = 0; i < n; i++) {
                        int ei, ej;
                        vdsh_cube_gl_to_exr(f, i, j, n, &ei, &ej);
                        const float *file =
                            maps[k]->rgba +
                            (((size_t)f * (size_t)n + (size_t)ej) * (size_t)n + (size_t)ei) * 4;
                        for (int c = 0; c < 4; c++)
                            bad += out[k][((size_t)j * (size_t)n + (size_t)i) * 4 + (size_t)c] !=
                                   vdsh_f16_from_f32(file[c]);
                    }
            }
            CHECK(bad == 0, "n %d file %d: %zu GL half texels differ from the file's", n, k, bad);
            free(gl);
            char path[512];
            vb_cubemap_basis_path(dir, "room", k, path, sizeof path, NULL);
            check_header(path, n);
            if (n == 64) {
                struct stat st;
                stat(path, &st);
                printf("n = 64: %s is %lld bytes\n", path, (long long)st.st_size);
            }
            vb_cubemap_free(maps[k]);
        }
        free(want);
    }
}

static void test_single_round_trip(const char *dir)
{
    /* Values that separate round-to-nearest-even from truncation and
     * from round-half-up, subnormals, signed zero, the largest half. */
    const float special[] = {1.0f + 0x1p-11f,    1.0f + 3 * 0x1p-11f,
                             -(1.0f + 0x1p-11f), 0x1p-24f,
                             0x1p-25f,           3 * 0x1p-25f,
                             0x1p-14f,           -0.0f,
                             65504.0f,           65519.0f,
                             -65519.0f,          0.1f,
                             1.0f / 3.0f,        2.0f - 0x1p-12f};
    const int n = 5;
    size_t count = (size_t)n * 6 * n * 4;
    float *rgba = malloc(count * sizeof(float));
    uint32_t state = 12345u;
    for (size_t k = 0; k < count; k++) {
        state = state * 1664525u + 1013904223u;
        if (k < sizeof special / sizeof special[0])
            rgba[k] = special[k];
        else
            rgba[k] = ((float)(state >> 8) / 16777216.0f - 0.5f) * 8.0f;
    }
    char path[512], path2[512];
    join(path, sizeof path, dir, "one.exr");
    join(path2, sizeof path2, dir, "two.exr");
    vb_error err = {{0}};
    CHECK(vb_cubemap_write(path, n, rgba, &err) == VB_OK, "%s", err.msg);
    vb_cubemap *m = NULL;
    CHECK(vb_cubemap_read(path, &m, &err) == VB_OK, "%s", err.msg);
    if (m) {
        CHECK(m->size == n, "size");
        size_t bad = 0;
        for (size_t k = 0; k < count; k++) {
            float want = half_round(rgba[k]);
            if (memcmp(&m->rgba[k], &want, 4) != 0) {
                if (bad++ < 5)
                    fprintf(stderr, "value %zu: wrote %a read %a want %a\n", k, (double)rgba[k],
                            (double)m->rgba[k], (double)want);
            }
        }
        CHECK(bad == 0, "%zu values not rounded to nearest even half", bad);
    }
    vb_cubemap_free(m);

    /* Determinism: the same pixels give the same bytes, whatever the
     * path and however often; overwriting works. */
    size_t s1 = 0, s2 = 0, s3 = 0;
    unsigned char *b1 = read_all(path, &s1);
    CHECK(vb_cubemap_write(path2, n, rgba, &err) == VB_OK, "%s", err.msg);
    CHECK(vb_cubemap_write(path, n, rgba, &err) == VB_OK, "overwrite: %s", err.msg);
    unsigned char *b2 = read_all(path2, &s2), *b3 = read_all(path, &s3);
    CHECK(b1 && b2 && b3 && s1 == s2 && s1 == s3 && !memcmp(b1, b2, s1) && !memcmp(b1, b3, s1),
          "writes differ (%zu %zu %zu bytes)", s1, s2, s3);
    free(b1);
    free(b2);
    free(b3);
    CHECK(count_temp_files(dir) == 0, "temporary files left in %s", dir);

    /* Float channels are read too (files from other tools). */
    char pf[512];
    join(pf, sizeof pf, dir, "float.exr");
    CHECK(write_odd_exr(pf, 4, 24, "RGBA", EXR_PIXEL_FLOAT, EXR_ENVMAP_CUBE, 0.1f),
          "write float cube");
    m = NULL;
    CHECK(vb_cubemap_read(pf, &m, &err) == VB_OK, "%s", err.msg);
    if (m) {
        CHECK(m->size == 4 && m->rgba[0] == 0.1f && m->rgba[4 * 4 * 24 - 1] == 0.1f,
              "float cube values");
        vb_cubemap_free(m);
    }
    /* Extra channels are ignored. */
    join(pf, sizeof pf, dir, "extra.exr");
    CHECK(write_odd_exr(pf, 2, 12, "RGBAZ", EXR_PIXEL_HALF, EXR_ENVMAP_CUBE, 0.5f),
          "write RGBAZ cube");
    m = NULL;
    CHECK(vb_cubemap_read(pf, &m, &err) == VB_OK, "%s", err.msg);
    if (m) {
        CHECK(m->size == 2 && m->rgba[5] == 0.5f, "RGBAZ values");
        vb_cubemap_free(m);
    }
    free(rgba);
}

static void test_basis_determinism(const char *dir)
{
    char d1[512], d2[512];
    join(d1, sizeof d1, dir, "a");
    join(d2, sizeof d2, dir, "b");
    mkdir_p(d1);
    mkdir_p(d2);
    vb_error err = {{0}};
    CHECK(vb_cubemap_write_basis(d1, "s", 16, &err) == VB_OK, "%s", err.msg);
    CHECK(vb_cubemap_write_basis(d2, "s", 16, &err) == VB_OK, "%s", err.msg);
    for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++) {
        char p1[512], p2[512];
        vb_cubemap_basis_path(d1, "s", k, p1, sizeof p1, NULL);
        vb_cubemap_basis_path(d2, "s", k, p2, sizeof p2, NULL);
        size_t s1 = 0, s2 = 0;
        unsigned char *b1 = read_all(p1, &s1), *b2 = read_all(p2, &s2);
        CHECK(b1 && b2 && s1 == s2 && !memcmp(b1, b2, s1), "%s and %s differ", p1, p2);
        free(b1);
        free(b2);
    }
}

static void test_paths(void)
{
    char buf[64];
    vb_error err = {{0}};
    CHECK(vb_cubemap_basis_path("out", "room", 0, buf, sizeof buf, &err) == VB_OK &&
              !strcmp(buf, "out/room.sh09-12.exr"),
          "%s", buf);
    CHECK(vb_cubemap_basis_path("out/", "room", 1, buf, sizeof buf, &err) == VB_OK &&
              !strcmp(buf, "out/room.sh13-16.exr"),
          "%s", buf);
    CHECK(vb_cubemap_basis_path(NULL, "room", 2, buf, sizeof buf, &err) == VB_OK &&
              !strcmp(buf, "room.sh17-20.exr"),
          "%s", buf);
    CHECK(vb_cubemap_basis_path("", "a.b", 3, buf, sizeof buf, &err) == VB_OK &&
              !strcmp(buf, "a.b.sh21-24.exr"),
          "%s", buf);
    CHECK(vb_cubemap_basis_path("/", "r", 3, buf, sizeof buf, &err) == VB_OK &&
              !strcmp(buf, "/r.sh21-24.exr"),
          "%s", buf);
    /* Too small: exactly one byte short; buf untouched. */
    strcpy(buf, "untouched");
    CHECK(vb_cubemap_basis_path("out", "room", 0, buf, strlen("out/room.sh09-12.exr"), &err) ==
                  VB_ERR_ARGUMENT &&
              !strcmp(buf, "untouched"),
          "short buffer");
    CHECK(vb_cubemap_basis_path("out", "room", 4, buf, sizeof buf, &err) == VB_ERR_ARGUMENT,
          "k = 4");
    CHECK(vb_cubemap_basis_path("out", "", 0, buf, sizeof buf, &err) == VB_ERR_ARGUMENT,
          "empty stem");
}

/* Runs test(dir/name) in a new folder dir/name. */
static void in_sub(const char *dir, const char *name, void (*test)(const char *))
{
    char sub[512];
    join(sub, sizeof sub, dir, name);
    mkdir_p(sub);
    test(sub);
}

static int run_files(const char *dir)
{
    fresh_dir(dir);
    in_sub(dir, "basis", test_basis_round_trip);
    in_sub(dir, "single", test_single_round_trip);
    in_sub(dir, "determinism", test_basis_determinism);
    test_paths();
    return failures ? 1 : 0;
}

/* ------------------------------------------------------------------ */
/* errors                                                               */

/* Read must fail with `want` (or any error if want == VB_OK), name the
 * file, contain `needle` (if not NULL) and leave the output alone. */
static void expect_read_fails(const char *path, vb_result want, const char *needle)
{
    vb_cubemap *sentinel = (vb_cubemap *)&failures, *m = sentinel;
    vb_error err = {{0}};
    vb_result r = vb_cubemap_read(path, &m, &err);
    printf("rejected (%s): %s\n", vb_result_str(r), err.msg);
    CHECK(r != VB_OK && (want == VB_OK || r == want), "%s: result %d (%s), want %d: %s", path,
          (int)r, vb_result_str(r), (int)want, err.msg);
    CHECK(m == sentinel, "%s: output changed on failure", path);
    CHECK(strstr(err.msg, path) != NULL, "%s: message does not name the file: %s", path, err.msg);
    if (needle)
        CHECK(strstr(err.msg, needle) != NULL, "%s: message lacks '%s': %s", path, needle, err.msg);
}

/* Patch the first int32 after "<name>\0<type>\0<size>" in an EXR header. */
static int patch_box2i(unsigned char *buf, size_t size, const char *name, const int32_t box[4])
{
    size_t nl = strlen(name) + 1;
    for (size_t k = 0; k + nl + 6 + 4 + 16 <= size; k++) {
        if (!memcmp(buf + k, name, nl) && !memcmp(buf + k + nl, "box2i", 6)) {
            memcpy(buf + k + nl + 6 + 4, box, 16); /* little-endian host */
            return 1;
        }
    }
    return 0;
}

static void test_bad_files(const char *dir)
{
    char path[512], good[512];
    vb_error err = {{0}};

    join(path, sizeof path, dir, "missing.exr");
    expect_read_fails(path, VB_ERR_IO, "cannot open");
    expect_read_fails(dir, VB_ERR_IO, "not a regular file");

    join(path, sizeof path, dir, "text.exr");
    const char *text = "this is not an OpenEXR file at all, just some text\n";
    write_all(path, text, strlen(text));
    expect_read_fails(path, VB_ERR_FORMAT, NULL);

    join(path, sizeof path, dir, "empty.exr");
    write_all(path, "", 0);
    expect_read_fails(path, VB_ERR_FORMAT, NULL);

    /* Not cube maps. */
    join(path, sizeof path, dir, "plain.exr");
    CHECK(write_odd_exr(path, 4, 24, "RGBA", EXR_PIXEL_HALF, -1, 0), "plain");
    expect_read_fails(path, VB_ERR_FORMAT, "no envmap attribute");
    join(path, sizeof path, dir, "latlong.exr");
    CHECK(write_odd_exr(path, 8, 4, "RGBA", EXR_PIXEL_HALF, EXR_ENVMAP_LATLONG, 0), "latlong");
    expect_read_fails(path, VB_ERR_FORMAT, "latitude-longitude");
    join(path, sizeof path, dir, "aspect.exr");
    CHECK(write_odd_exr(path, 4, 20, "RGBA", EXR_PIXEL_HALF, EXR_ENVMAP_CUBE, 0), "aspect");
    expect_read_fails(path, VB_ERR_FORMAT, "n x 6n");
    join(path, sizeof path, dir, "rgb.exr");
    CHECK(write_odd_exr(path, 4, 24, "RGB", EXR_PIXEL_HALF, EXR_ENVMAP_CUBE, 0), "rgb");
    expect_read_fails(path, VB_ERR_FORMAT, "channel A missing");
    join(path, sizeof path, dir, "uint.exr");
    CHECK(write_odd_exr(path, 4, 24, "RGBA", EXR_PIXEL_UINT, EXR_ENVMAP_CUBE, 0), "uint");
    expect_read_fails(path, VB_ERR_FORMAT, "not half or float");
    join(path, sizeof path, dir, "nan.exr");
    CHECK(write_odd_exr(path, 4, 24, "RGBA", EXR_PIXEL_FLOAT, EXR_ENVMAP_CUBE, NAN), "nan");
    expect_read_fails(path, VB_ERR_INVALID, "not finite");

    /* A good file, then damaged copies of it. */
    join(good, sizeof good, dir, "good.sh09-12.exr");
    CHECK(vb_cubemap_write_basis(dir, "good", 8, &err) == VB_OK, "%s", err.msg);
    size_t size = 0;
    unsigned char *bytes = read_all(good, &size);
    CHECK(bytes && size > 100, "read back %s", good);
    if (!bytes)
        return;

    /* Face size over the limit: only the header is needed to refuse it. */
    join(path, sizeof path, dir, "huge.exr");
    unsigned char *copy = malloc(size);
    memcpy(copy, bytes, size);
    const int32_t huge[4] = {0, 0, 4096, 6 * 4097 - 1};
    CHECK(patch_box2i(copy, size, "dataWindow", huge) &&
              patch_box2i(copy, size, "displayWindow", huge),
          "patch windows");
    write_all(path, copy, size);
    expect_read_fails(path, VB_ERR_FORMAT, NULL);

    /* Truncated at every length: always a clean failure naming the file. */
    join(path, sizeof path, dir, "truncated.exr");
    size_t ok_count = 0;
    for (size_t len = 0; len < size; len++) {
        write_all(path, bytes, len);
        vb_cubemap *m = NULL;
        err.msg[0] = '\0';
        vb_result r = vb_cubemap_read(path, &m, &err);
        if (r == VB_OK) {
            ok_count++;
            vb_cubemap_free(m);
        } else {
            CHECK(strstr(err.msg, path) && m == NULL, "truncated to %zu: message %s", len, err.msg);
        }
    }
    CHECK(ok_count == 0, "%zu truncated files were accepted", ok_count);

    /* Corrupted bytes (deterministic): never a crash; an error names the
     * file. Some flips (e.g. in displayWindow) are harmless. */
    join(path, sizeof path, dir, "corrupt.exr");
    uint32_t state = 99u;
    int errors = 0, accepted = 0;
    for (int trial = 0; trial < 600; trial++) {
        memcpy(copy, bytes, size);
        int flips = 1 + trial % 4;
        for (int f = 0; f < flips; f++) {
            state = state * 1664525u + 1013904223u;
            size_t at = (size_t)(state >> 8) % size;
            state = state * 1664525u + 1013904223u;
            copy[at] ^= (unsigned char)(1u + (state >> 24) % 255u);
        }
        write_all(path, copy, size);
        vb_cubemap *m = NULL;
        err.msg[0] = '\0';
        vb_result r = vb_cubemap_read(path, &m, &err);
        if (r == VB_OK) {
            accepted++;
            CHECK(m && m->size >= 1 && m->size <= VB_CUBEMAP_MAX_SIZE, "size");
            vb_cubemap_free(m);
        } else {
            errors++;
            CHECK(strstr(err.msg, path) != NULL, "corrupt trial %d: %s", trial, err.msg);
        }
    }
    printf("corrupted files: %d rejected, %d accepted\n", errors, accepted);
    free(copy);
    free(bytes);

    /* A missing member of the set; a set of mixed sizes. */
    vb_cubemap *sentinel = (vb_cubemap *)&failures;
    vb_cubemap *maps[VB_CUBEMAP_BASIS_FILES] = {sentinel, sentinel, sentinel, sentinel};
    char p2[512];
    vb_cubemap_basis_path(dir, "good", 2, p2, sizeof p2, NULL);
    unlink(p2);
    CHECK(vb_cubemap_read_basis(dir, "good", 8, maps, &err) == VB_ERR_IO && strstr(err.msg, p2),
          "missing third file: %s", err.msg);
    CHECK(maps[0] == sentinel && maps[3] == sentinel, "outputs changed");
    float *small = malloc(4 * 6 * 4 * 4 * sizeof(float));
    vdsh_cube_fill_basis(4, 17, small);
    CHECK(vb_cubemap_write(p2, 4, small, &err) == VB_OK, "%s", err.msg);
    free(small);
    CHECK(vb_cubemap_read_basis(dir, "good", 0, maps, &err) == VB_ERR_FORMAT &&
              strstr(err.msg, p2) && strstr(err.msg, "face size 4"),
          "mixed sizes: %s", err.msg);
    CHECK(vb_cubemap_read_basis(dir, "good", 16, maps, &err) == VB_ERR_FORMAT &&
              strstr(err.msg, "expected 16"),
          "expected size: %s", err.msg);
    CHECK(maps[0] == sentinel && maps[3] == sentinel, "outputs changed");
}

static void test_failed_writes(const char *dir)
{
    vb_error err = {{0}};
    float rgba[2 * 12 * 4];
    vdsh_cube_fill_basis(2, 9, rgba);
    char path[512], missing[512];

    /* Into a missing directory: clear error, nothing created. */
    join(missing, sizeof missing, dir, "no/such/dir");
    join(path, sizeof path, missing, "x.exr");
    int before = count_entries(dir);
    CHECK(vb_cubemap_write(path, 2, rgba, &err) == VB_ERR_IO && strstr(err.msg, path) &&
              strstr(err.msg, "No such file or directory"),
          "missing dir: %s", err.msg);
    printf("missing directory: %s\n", err.msg);
    CHECK(vb_cubemap_write_basis(missing, "room", 8, &err) == VB_ERR_IO && strstr(err.msg, missing),
          "basis into missing dir: %s", err.msg);
    CHECK(count_entries(dir) == before && count_entries(missing) < 0, "something was created");

    /* Destination is a directory: the rename fails, the temporary file
     * is removed. */
    join(path, sizeof path, dir, "isdir.exr");
    mkdir(path, 0777);
    before = count_entries(dir);
    CHECK(vb_cubemap_write(path, 2, rgba, &err) == VB_ERR_IO && strstr(err.msg, path),
          "rename over a directory: %s", err.msg);
    CHECK(count_entries(dir) == before && count_temp_files(dir) == 0, "temporary file left behind");

    /* Set: the first destination is a directory, so its rename fails
     * after all four were staged; the three other temporary files must
     * go too, and no destination may appear. */
    char p0[512];
    vb_cubemap_basis_path(dir, "set", 0, p0, sizeof p0, NULL);
    mkdir(p0, 0777);
    before = count_entries(dir);
    CHECK(vb_cubemap_write_basis(dir, "set", 2, &err) == VB_ERR_IO && strstr(err.msg, p0),
          "set with a directory in the way: %s", err.msg);
    CHECK(count_entries(dir) == before && count_temp_files(dir) == 0,
          "set left files behind (%d entries, %d before)", count_entries(dir), before);

    /* Values a half cannot hold; bad arguments. Nothing written. */
    join(path, sizeof path, dir, "inf.exr");
    rgba[13] = 70000.0f;
    CHECK(vb_cubemap_write(path, 2, rgba, &err) == VB_ERR_INVALID &&
              strstr(err.msg, "face 0 texel (1, 1) channel G"),
          "%s", err.msg);
    rgba[13] = NAN;
    CHECK(vb_cubemap_write(path, 2, rgba, &err) == VB_ERR_INVALID, "%s", err.msg);
    rgba[13] = 0.0f;
    CHECK(vb_cubemap_write(path, 0, rgba, &err) == VB_ERR_ARGUMENT, "n 0");
    CHECK(vb_cubemap_write(path, 4097, rgba, &err) == VB_ERR_ARGUMENT, "n 4097");
    CHECK(vb_cubemap_write(path, 2, NULL, &err) == VB_ERR_ARGUMENT, "NULL");
    CHECK(vb_cubemap_write_basis(dir, "x", 0, &err) == VB_ERR_ARGUMENT, "basis n 0");
    CHECK(vb_cubemap_write_basis(dir, NULL, 2, &err) == VB_ERR_ARGUMENT, "NULL stem");
    CHECK(access(path, F_OK) != 0, "%s exists", path);
    CHECK(vb_cubemap_read(NULL, NULL, NULL) == VB_ERR_ARGUMENT, "NULL read");
}

static int run_errors(const char *dir)
{
    fresh_dir(dir);
    in_sub(dir, "bad", test_bad_files);
    in_sub(dir, "writes", test_failed_writes);
    return failures ? 1 : 0;
}

static int run_write(const char *path, int n)
{
    size_t count = (size_t)n * 6 * (size_t)n * 4;
    float *rgba = malloc(count * sizeof(float));
    vdsh_cube_fill_basis(n, 9, rgba);
    vb_error err;
    vb_result r = vb_cubemap_write(path, n, rgba, &err);
    free(rgba);
    if (r != VB_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    int rc = 2;
    if (argc == 2 && !strcmp(argv[1], "conventions"))
        rc = run_conventions();
    else if (argc == 3 && !strcmp(argv[1], "files"))
        rc = run_files(argv[2]);
    else if (argc == 3 && !strcmp(argv[1], "errors"))
        rc = run_errors(argv[2]);
    else if (argc == 4 && !strcmp(argv[1], "write"))
        rc = run_write(argv[2], atoi(argv[3]));
    else
        fprintf(stderr, "usage: test_cube conventions | files DIR | errors DIR | "
                        "write PATH N\n");
    if (rc == 1)
        fprintf(stderr, "%d check(s) failed\n", failures);
    return rc;
}
