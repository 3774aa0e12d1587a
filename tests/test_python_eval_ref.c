/*
 * test_python_eval_ref - the C library's values for tests/test_python_reader.py
 * to compare the Python evaluator (python/vdsh/evaluate.py) with.
 *
 *   test_python_eval_ref lights FILE.vdsh STREAM OFFSET IN OUT
 *       IN: records of u32 vertex, f32 light x, y, z; OUT: per record f32
 *       vdsh_vertex_distance (the vertex's own order for a variable-order
 *       stream), vdsh_shadow smooth, vdsh_shadow binary. OFFSET: a log
 *       offset added as vdsh-eval --offsets adds it.
 *   test_python_eval_ref dirs FILE.vdsh STREAM OFFSET IN OUT
 *       IN: records of u32 vertex, f32 direction x, y, z; OUT: per record
 *       f32 vdsh_stream_distance.
 *   test_python_eval_ref sh IN OUT
 *       IN: records of u32 order, f32 direction x, y, z; OUT: per record
 *       256 f32, vdsh_sh_eval's order^2 values then zeros.
 *
 * Little-endian files of whole records; exit 1 naming the problem.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vdsh.h"
#include "vdsh_sh.h"
#include "vdsh_shadow.h"

typedef struct rec {
    uint32_t id;
    float v[3];
} rec;

static rec *read_records(const char *path, size_t *n)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        fprintf(stderr, "test_python_eval_ref: %s: cannot open\n", path);
        return NULL;
    }
    fseek(fp, 0, SEEK_END);
    long size = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    if (size < 0 || size % 16 != 0) {
        fprintf(stderr, "test_python_eval_ref: %s: not whole 16-byte records\n", path);
        fclose(fp);
        return NULL;
    }
    *n = (size_t)size / 16;
    rec *r = malloc((size_t)size + 16);
    if (!r || fread(r, 16, *n, fp) != *n) {
        fprintf(stderr, "test_python_eval_ref: %s: cannot read\n", path);
        free(r);
        fclose(fp);
        return NULL;
    }
    fclose(fp);
    return r;
}

static int write_floats(const char *path, const float *v, size_t n)
{
    FILE *fp = fopen(path, "wb");
    int ok = fp && fwrite(v, sizeof *v, n, fp) == n;
    if (fp && fclose(fp) != 0)
        ok = 0;
    if (!ok)
        fprintf(stderr, "test_python_eval_ref: %s: cannot write\n", path);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc == 4 && strcmp(argv[1], "sh") == 0) {
        size_t n = 0;
        rec *r = read_records(argv[2], &n);
        if (!r)
            return 1;
        float *out = calloc(n * VDSH_MAX_COEFFS + 1, sizeof *out);
        if (!out)
            return 1;
        for (size_t k = 0; k < n; k++) {
            if (r[k].id < 1 || r[k].id > VDSH_MAX_ORDER) {
                fprintf(stderr, "test_python_eval_ref: record %zu: order %u\n", k, r[k].id);
                return 1;
            }
            vdsh_sh_eval((int)r[k].id, r[k].v, out + k * VDSH_MAX_COEFFS);
        }
        int ok = write_floats(argv[3], out, n * VDSH_MAX_COEFFS);
        free(out);
        free(r);
        return ok ? 0 : 1;
    }
    if (argc != 7 || (strcmp(argv[1], "lights") != 0 && strcmp(argv[1], "dirs") != 0)) {
        fprintf(stderr, "usage: test_python_eval_ref lights|dirs FILE STREAM OFFSET IN OUT\n"
                        "       test_python_eval_ref sh IN OUT\n");
        return 2;
    }
    int lights = strcmp(argv[1], "lights") == 0;
    vdsh_file *f = NULL;
    vdsh_error err;
    if (vdsh_read(argv[2], &f, &err) != VDSH_OK) {
        fprintf(stderr, "test_python_eval_ref: %s\n", err.msg);
        return 1;
    }
    uint32_t si = (uint32_t)strtoul(argv[3], NULL, 10);
    float offset = strtof(argv[4], NULL);
    if (si >= f->stream_count || f->has_part) {
        fprintf(stderr, "test_python_eval_ref: %s: no stream %u (or a part)\n", argv[2], si);
        vdsh_free(f);
        return 1;
    }
    const vdsh_stream *s = &f->streams[si];
    size_t n = 0;
    rec *r = read_records(argv[5], &n);
    float *out = calloc(3 * n + 1, sizeof *out);
    if (!r || !out) {
        vdsh_free(f);
        return 1;
    }
    const float maxd = f->header.max_distance;
    for (size_t k = 0; k < n; k++) {
        uint32_t v = r[k].id;
        if (v >= f->header.vertex_count) {
            fprintf(stderr, "test_python_eval_ref: record %zu: vertex %u\n", k, v);
            return 1;
        }
        float c[VDSH_MAX_COEFFS];
        vdsh_stream_decode(s, v, c);
        /* vdsh-eval --offsets, bake/tools/vdsh_eval.c */
        if (offset != 0.0f) {
            uint32_t nc = s->order * s->order;
            if (s->quantity == VDSH_QUANTITY_LOG_DISTANCE)
                c[0] += offset / 0.28209479177387814f; /* Y00 */
            else
                for (uint32_t i = 0; i < nc; i++)
                    c[i] *=
                        s->quantity == VDSH_QUANTITY_DISTANCE2 ? expf(2.0f * offset) : expf(offset);
        }
        uint32_t order = vdsh_stream_vertex_order(s, v);
        const float *p = f->positions + 3 * (size_t)v;
        if (lights) {
            out[3 * k] = vdsh_vertex_distance(order, s->quantity, maxd, c, p, r[k].v);
            out[3 * k + 1] =
                vdsh_shadow(order, s->quantity, maxd, c, p, r[k].v, VDSH_COMPARE_SMOOTH);
            out[3 * k + 2] =
                vdsh_shadow(order, s->quantity, maxd, c, p, r[k].v, VDSH_COMPARE_BINARY);
        } else {
            out[k] = vdsh_stream_distance(order, s->quantity, maxd, c, r[k].v);
        }
    }
    int ok = write_floats(argv[6], out, lights ? 3 * n : n);
    free(out);
    free(r);
    vdsh_free(f);
    return ok ? 0 : 1;
}
