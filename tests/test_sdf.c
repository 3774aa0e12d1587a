/*
 * test_sdf.c - the distance volume: formats/vdsh_sdf.h (round trip, every
 * truncation, every single-byte corruption and bad header values end in an
 * error, never a crash or a volume that reads differently) and
 * bake/lib/sdf.h (exact distances and the sign in a closed object and an
 * open room; the same bytes for 1 and 4 threads). With file arguments it
 * replays them through the reader instead (a fuzz replay).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"
#include "sdf.h"
#include "vdsh_sdf.h"

static int failures;
#define CHECK(c)                                                                                   \
    do {                                                                                           \
        if (!(c)) {                                                                                \
            fprintf(stderr, "%s:%d: FAIL: %s\n", __FILE__, __LINE__, #c);                          \
            failures++;                                                                            \
        }                                                                                          \
    } while (0)

/* A cube [-1,1]^3: 8 corners, 12 triangles wound counter-clockwise seen
 * from outside (sign = +1) or from inside (sign = -1); `skip` a face
 * (0..5) to leave out, -1 none: an open box. */
static void make_box(int inward, int skip, vb_mesh *m)
{
    static const float c[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                  {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    /* outward CCW quads: -z, +z, -y, +y, -x, +x */
    static const int q[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};
    m->vertex_count = 8;
    m->positions = malloc(sizeof c);
    memcpy(m->positions, c, sizeof c);
    m->normals = calloc(24, sizeof(float));
    m->indices = malloc(36 * sizeof(uint32_t));
    m->triangle_count = 0;
    for (int f = 0; f < 6; f++) {
        if (f == skip)
            continue;
        int t[2][3] = {{q[f][0], q[f][1], q[f][2]}, {q[f][0], q[f][2], q[f][3]}};
        for (int k = 0; k < 2; k++) {
            uint32_t *o = m->indices + 3 * m->triangle_count++;
            o[0] = (uint32_t)t[k][0];
            o[1] = (uint32_t)(inward ? t[k][2] : t[k][1]);
            o[2] = (uint32_t)(inward ? t[k][1] : t[k][2]);
        }
    }
}

static void free_mesh(vb_mesh *m)
{
    free(m->positions);
    free(m->normals);
    free(m->indices);
}

/* The stored distance at the sample nearest p. */
static float nearest(const vdsh_sdf *v, const float p[3], float at[3])
{
    size_t idx = 0, stride = 1;
    for (int a = 0; a < 3; a++) {
        long i = lrintf((p[a] - v->origin[a]) / v->cell);
        i = i < 0 ? 0 : i >= (long)v->dim[a] ? (long)v->dim[a] - 1 : i;
        at[a] = v->origin[a] + v->cell * (float)i;
        idx += (size_t)i * stride;
        stride *= v->dim[a];
    }
    return vdsh_sdf_decode(v->samples[idx], v->max_distance);
}

static void bake(const vb_mesh *m, int res, unsigned threads, vdsh_sdf *out)
{
    vb_scene *s = NULL;
    vb_error err;
    vb_scene_desc sd = {.robust = 1, .threads = 1};
    if (vb_scene_create(m, &sd, &s, &err) != VB_OK) {
        fprintf(stderr, "scene: %s\n", err.msg);
        exit(1);
    }
    if (vb_sdf_bake(s, m, res, threads, out, &err) != VB_OK) {
        fprintf(stderr, "sdf: %s\n", err.msg);
        exit(1);
    }
    vb_scene_destroy(s);
}

static void test_bake(void)
{
    /* A closed cube seen from outside: negative inside, positive out,
     * every sample within the encoding's step of the exact distance. */
    vb_mesh m;
    make_box(0, -1, &m);
    vdsh_sdf v, v4;
    bake(&m, 16, 1, &v);
    bake(&m, 16, 4, &v4);
    size_t n = (size_t)v.dim[0] * v.dim[1] * v.dim[2];
    CHECK(memcmp(v.samples, v4.samples, 2 * n) == 0);
    const float step = 2.0f * v.max_distance / 65535.0f;
    int wrong_sign = 0, wrong_dist = 0;
    for (uint32_t k = 0; k < v.dim[2]; k++)
        for (uint32_t j = 0; j < v.dim[1]; j++)
            for (uint32_t i = 0; i < v.dim[0]; i++) {
                float p[3] = {v.origin[0] + v.cell * (float)i, v.origin[1] + v.cell * (float)j,
                              v.origin[2] + v.cell * (float)k};
                float d = vdsh_sdf_decode(v.samples[i + v.dim[0] * (j + (size_t)v.dim[1] * k)],
                                          v.max_distance);
                /* exact distance to the cube's surface */
                float out2 = 0.0f, in = INFINITY;
                for (int a = 0; a < 3; a++) {
                    float e = fabsf(p[a]) - 1.0f;
                    out2 += e > 0.0f ? e * e : 0.0f;
                    in = fminf(in, -e);
                }
                int inside = in > 0.0f;
                float exact = inside ? in : sqrtf(out2);
                if (fabsf(exact) > 1e-4f && (d < 0.0f) != inside)
                    wrong_sign++;
                if (fabsf(fabsf(d) - exact) > step + 1e-5f)
                    wrong_dist++;
            }
    CHECK(wrong_sign == 0);
    CHECK(wrong_dist == 0);
    if (wrong_sign || wrong_dist)
        fprintf(stderr, "closed cube: %d wrong signs, %d wrong distances\n", wrong_sign,
                wrong_dist);
    CHECK(v.dim[0] == 19 && v.dim[1] == 19 && v.dim[2] == 19); /* 16 + 3 */
    vdsh_sdf_free(&v);
    vdsh_sdf_free(&v4);
    free_mesh(&m);

    /* An open room (the cube's faces turned inward, its +x wall missing):
     * free space inside, solid behind the walls, free beyond the opening. */
    make_box(1, 5, &m);
    bake(&m, 16, 2, &v);
    float at[3];
    const float centre[3] = {0, 0, 0}, behind[3] = {0, 0, -1.15f}, below[3] = {0, -1.15f, 0};
    CHECK(nearest(&v, centre, at) > 0.5f);
    CHECK(nearest(&v, behind, at) < 0.0f);
    CHECK(nearest(&v, below, at) < 0.0f);
    const float beyond[3] = {1.15f, 0, 0};
    CHECK(nearest(&v, beyond, at) > 0.0f);
    /* A trace in the room: a light in the middle lights the floor's
     * middle; the same light behind a wall does not. */
    const float floor_p[3] = {0, -1, 0}, up[3] = {0, 1, 0}, light[3] = {0, 0.5f, 0};
    const float hidden[3] = {0, 0.5f, -1.5f};
    CHECK(vdsh_sdf_shadow(&v, floor_p, up, light, VDSH_SDF_DEFAULT_K) > 0.9f);
    CHECK(vdsh_sdf_shadow(&v, floor_p, up, hidden, VDSH_SDF_DEFAULT_K) < 0.1f);
    vdsh_sdf_free(&v);
    free_mesh(&m);
}

/* The reader on arbitrary bytes: an error, or a volume that writes back
 * to the same bytes. */
static void replay(const uint8_t *d, size_t size)
{
    vdsh_sdf v;
    vdsh_error err;
    if (vdsh_sdf_read_memory(d, size, "input", &v, &err) != VDSH_OK)
        return;
    void *back;
    size_t bs;
    CHECK(vdsh_sdf_write_memory(&v, &back, &bs, &err) == VDSH_OK);
    CHECK(bs == size && memcmp(back, d, size) == 0);
    free(back);
    vdsh_sdf_free(&v);
}

static void test_format(const char *dir)
{
    vdsh_sdf v = {.dim = {3, 4, 5},
                  .origin = {-1, 2, 3},
                  .cell = 0.5f,
                  .max_distance = 4.0f,
                  .vertex_count = 10,
                  .triangle_count = 7};
    v.samples = malloc(60 * sizeof *v.samples);
    for (int i = 0; i < 60; i++)
        v.samples[i] = vdsh_sdf_encode((float)(i - 30) * 0.1f, v.max_distance);
    void *data;
    size_t size;
    vdsh_error err;
    CHECK(vdsh_sdf_write_memory(&v, &data, &size, &err) == VDSH_OK);
    CHECK(size == vdsh_sdf_file_size(&v) && size == 64 + 120);
    vdsh_sdf r;
    CHECK(vdsh_sdf_read_memory(data, size, "x", &r, &err) == VDSH_OK);
    CHECK(memcmp(r.dim, v.dim, sizeof v.dim) == 0 && r.cell == v.cell &&
          r.max_distance == v.max_distance && r.vertex_count == 10 && r.triangle_count == 7);
    CHECK(memcmp(r.samples, v.samples, 120) == 0);
    vdsh_sdf_free(&r);
    /* the file on disk, atomically */
    char path[4096];
    snprintf(path, sizeof path, "%s/t.sdf", dir);
    CHECK(vdsh_sdf_write(path, &v, &err) == VDSH_OK);
    CHECK(vdsh_sdf_read(path, &r, &err) == VDSH_OK);
    vdsh_sdf_free(&r);
    snprintf(path, sizeof path, "%s/missing.sdf", dir);
    CHECK(vdsh_sdf_read(path, &r, &err) == VDSH_ERR_IO && strstr(err.msg, "missing.sdf"));

    /* encoding: clamped, exact at 0 within a step, NaN never stored */
    CHECK(vdsh_sdf_encode(100.0f, 4.0f) == 65535 && vdsh_sdf_encode(-100.0f, 4.0f) == 0);
    CHECK(fabsf(vdsh_sdf_decode(vdsh_sdf_encode(0.0f, 4.0f), 4.0f)) < 1e-4f);
    CHECK(vdsh_sdf_encode(NAN, 4.0f) == 65535);

    /* every truncation fails, as truncated (or not a volume when short) */
    uint8_t *d = data;
    for (size_t n = 0; n < size; n++) {
        vdsh_result res = vdsh_sdf_read_memory(d, n, "x", &r, &err);
        CHECK(res != VDSH_OK);
        if (n >= 64)
            CHECK(res == VDSH_ERR_TRUNCATED);
    }
    /* one extra byte */
    uint8_t *longer = malloc(size + 1);
    memcpy(longer, d, size);
    longer[size] = 0;
    CHECK(vdsh_sdf_read_memory(longer, size + 1, "x", &r, &err) == VDSH_ERR_INVALID);
    free(longer);
    /* every byte changed fails its CRC or the magic */
    for (size_t i = 0; i < size; i++)
        for (int bit = 0; bit < 8; bit++) {
            d[i] ^= (uint8_t)(1 << bit);
            CHECK(vdsh_sdf_read_memory(d, size, "x", &r, &err) != VDSH_OK);
            replay(d, size);
            d[i] ^= (uint8_t)(1 << bit);
        }
    /* bad header values are refused by the writer (the reader's rules) */
    vdsh_sdf b = v;
    b.dim[1] = 1;
    CHECK(vdsh_sdf_write_memory(&b, &data, &size, &err) == VDSH_ERR_INVALID);
    b = v;
    b.cell = 0.0f;
    CHECK(vdsh_sdf_write_memory(&b, &data, &size, &err) == VDSH_ERR_INVALID);
    b = v;
    b.max_distance = INFINITY;
    CHECK(vdsh_sdf_write_memory(&b, &data, &size, &err) == VDSH_ERR_INVALID);
    b = v;
    b.origin[2] = NAN;
    CHECK(vdsh_sdf_write_memory(&b, &data, &size, &err) == VDSH_ERR_INVALID);
    b = v;
    b.dim[0] = VDSH_SDF_MAX_DIM + 1;
    CHECK(vdsh_sdf_write_memory(&b, &data, &size, &err) == VDSH_ERR_INVALID);
    free(d);
    vdsh_sdf_free(&v);

    /* companion paths */
    char p[64];
    CHECK(vdsh_sdf_path("a/room.vdsh", p, sizeof p) == 0 && strcmp(p, "a/room.sdf") == 0);
    CHECK(vdsh_sdf_path("room", p, sizeof p) == 0 && strcmp(p, "room.sdf") == 0);
    CHECK(vdsh_sdf_path("room.vdsh", p, 8) == -1);
}

int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "replay") == 0) {
        for (int i = 2; i < argc; i++) {
            FILE *f = fopen(argv[i], "rb");
            if (!f)
                return 1;
            uint8_t *buf = malloc(1 << 24);
            size_t n = fread(buf, 1, 1 << 24, f);
            fclose(f);
            replay(buf, n);
            free(buf);
        }
        return failures != 0;
    }
    test_format(argc > 1 ? argv[1] : ".");
    test_bake();
    if (failures)
        fprintf(stderr, "%d failures\n", failures);
    else
        printf("test_sdf: ok\n");
    return failures != 0;
}
