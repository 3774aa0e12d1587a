/*
 * vdsh_sdf.c - the distance volume's companion file and its trace
 * (vdsh_sdf.h; the byte layout is formats/VDSH.md's).
 */
#include "vdsh_sdf.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vdsh_failf.h"
#include "vdsh_output.h"

static const uint8_t MAGIC[8] = {'V', 'D', 'S', 'H', 'S', 'D', 'F', 0};
enum { SDF_VERSION = 1 };

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static float get_f32(const uint8_t *p)
{
    uint32_t u = get_u32(p);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

static void put_f32(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    put_u32(p, u);
}

int vdsh_sdf_path(const char *vdsh_path, char *out, size_t cap)
{
    size_t n = strlen(vdsh_path);
    if (n >= 5 && strcmp(vdsh_path + n - 5, ".vdsh") == 0)
        n -= 5;
    if (n + 5 > cap)
        return -1;
    memcpy(out, vdsh_path, n);
    memcpy(out + n, ".sdf", 5);
    return 0;
}

uint16_t vdsh_sdf_encode(float d, float max_distance)
{
    float x = d / max_distance;
    x = x < -1.0f ? -1.0f : x > 1.0f ? 1.0f : x;
    if (x != x)
        x = 1.0f;
    return (uint16_t)lrintf((x + 1.0f) * 0.5f * 65535.0f);
}

float vdsh_sdf_decode(uint16_t u, float max_distance)
{
    return ((float)u / 65535.0f * 2.0f - 1.0f) * max_distance;
}

static size_t sample_count(const vdsh_sdf *v)
{
    return (size_t)v->dim[0] * v->dim[1] * v->dim[2];
}

size_t vdsh_sdf_file_size(const vdsh_sdf *v)
{
    return VDSH_SDF_HEADER_SIZE + 2 * sample_count(v);
}

/* The header's value rules: one definition for reader and writer. */
static vdsh_result check_header(const vdsh_sdf *v, const char *name, vdsh_error *err)
{
    for (int a = 0; a < 3; a++)
        if (v->dim[a] < 2 || v->dim[a] > VDSH_SDF_MAX_DIM)
            return vdsh_failf_at(err, VDSH_ERR_INVALID, name,
                                 "distance volume: %u samples along axis "
                                 "%d, must be 2..%d",
                                 v->dim[a], a, VDSH_SDF_MAX_DIM);
    for (int a = 0; a < 3; a++)
        if (!isfinite(v->origin[a]))
            return vdsh_failf_at(err, VDSH_ERR_INVALID, name,
                                 "distance volume: origin is not finite");
    if (!(isfinite(v->cell) && v->cell > 0.0f))
        return vdsh_failf_at(err, VDSH_ERR_INVALID, name,
                             "distance volume: cell %g is not a finite "
                             "number > 0",
                             (double)v->cell);
    if (!(isfinite(v->max_distance) && v->max_distance > 0.0f))
        return vdsh_failf_at(err, VDSH_ERR_INVALID, name,
                             "distance volume: max_distance %g is not a "
                             "finite number > 0",
                             (double)v->max_distance);
    for (int a = 0; a < 3; a++)
        if (!isfinite(v->origin[a] + v->cell * (float)(v->dim[a] - 1)))
            return vdsh_failf_at(err, VDSH_ERR_INVALID, name,
                                 "distance volume: its box is not finite");
    return VDSH_OK;
}

vdsh_result vdsh_sdf_read_memory(const void *data, size_t size, const char *name, vdsh_sdf *out,
                                 vdsh_error *err)
{
    const uint8_t *d = data;
    if (!name)
        name = "(memory)";
    if (size < VDSH_SDF_HEADER_SIZE)
        return vdsh_failf_at(
            err, size >= 8 && memcmp(d, MAGIC, 8) == 0 ? VDSH_ERR_TRUNCATED : VDSH_ERR_NOT_VDSH,
            name, "%zu byte%s: shorter than the %d-byte distance volume header", size, vdsh_s(size),
            VDSH_SDF_HEADER_SIZE);
    if (memcmp(d, MAGIC, 8) != 0)
        return vdsh_failf_at(err, VDSH_ERR_NOT_VDSH, name, "not a VDSH distance volume (%s)",
                             memcmp(d, "VDSH\r\n\x1a\n", 8) == 0
                                 ? "a .vdsh file: vdsh-bake --sdf writes the volume beside it, "
                                   "as a .sdf"
                                 : "wrong magic");
    if (get_u32(d + 60) != vdsh_crc32(0, d, 60))
        return vdsh_failf_at(err, VDSH_ERR_CRC, name, "distance volume header: CRC mismatch");
    if (get_u32(d + 8) != SDF_VERSION)
        return vdsh_failf_at(err, VDSH_ERR_VERSION, name,
                             "distance volume version %u (this reader "
                             "reads %d)",
                             get_u32(d + 8), SDF_VERSION);
    vdsh_sdf v = {0};
    for (int a = 0; a < 3; a++) {
        v.dim[a] = get_u32(d + 12 + 4 * a);
        v.origin[a] = get_f32(d + 24 + 4 * a);
    }
    v.cell = get_f32(d + 36);
    v.max_distance = get_f32(d + 40);
    v.vertex_count = get_u32(d + 44);
    v.triangle_count = get_u32(d + 48);
    if (get_u32(d + 56) != 0)
        return vdsh_failf_at(err, VDSH_ERR_INVALID, name,
                             "distance volume: reserved bytes not zero");
    vdsh_result r = check_header(&v, name, err);
    if (r != VDSH_OK)
        return r;
    size_t n = sample_count(&v);
    if (n > (size - VDSH_SDF_HEADER_SIZE) / 2)
        return vdsh_failf_at(err, VDSH_ERR_TRUNCATED, name,
                             "distance volume: %zu byte%s of samples, "
                             "%u x %u x %u need %zu",
                             size - VDSH_SDF_HEADER_SIZE, vdsh_s(size - VDSH_SDF_HEADER_SIZE),
                             v.dim[0], v.dim[1], v.dim[2], 2 * n);
    if (size - VDSH_SDF_HEADER_SIZE != 2 * n)
        return vdsh_failf_at(err, VDSH_ERR_INVALID, name,
                             "distance volume: %zu bytes after the "
                             "samples",
                             size - VDSH_SDF_HEADER_SIZE - 2 * n);
    if (get_u32(d + 52) != vdsh_crc32(0, d + VDSH_SDF_HEADER_SIZE, 2 * n))
        return vdsh_failf_at(err, VDSH_ERR_CRC, name, "distance volume samples: CRC mismatch");
    v.samples = malloc(2 * n);
    if (!v.samples)
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, name, "out of memory for %zu samples", n);
    const uint8_t *s = d + VDSH_SDF_HEADER_SIZE;
    for (size_t i = 0; i < n; i++)
        v.samples[i] = (uint16_t)(s[2 * i] | s[2 * i + 1] << 8);
    *out = v;
    return VDSH_OK;
}

vdsh_result vdsh_sdf_read(const char *path, vdsh_sdf *out, vdsh_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return vdsh_failf_at(err, VDSH_ERR_IO, path, "cannot open the distance volume: %s",
                             strerror(errno));
    uint8_t *buf = NULL;
    size_t size = 0, cap = 0;
    for (;;) {
        if (size == cap) {
            size_t nc = cap ? 2 * cap : 1 << 16;
            uint8_t *nb = nc > cap ? realloc(buf, nc) : NULL;
            if (!nb) {
                free(buf);
                fclose(f);
                return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, path, "out of memory reading it");
            }
            buf = nb;
            cap = nc;
        }
        size_t got = fread(buf + size, 1, cap - size, f);
        size += got;
        if (got == 0)
            break;
    }
    int bad = ferror(f);
    fclose(f);
    vdsh_result r = bad ? vdsh_failf_at(err, VDSH_ERR_IO, path, "read error")
                        : vdsh_sdf_read_memory(buf, size, path, out, err);
    free(buf);
    return r;
}

vdsh_result vdsh_sdf_write_memory(const vdsh_sdf *v, void **out, size_t *size, vdsh_error *err)
{
    vdsh_result r = check_header(v, "distance volume", err);
    if (r != VDSH_OK)
        return r;
    if (!v->samples)
        return vdsh_failf_at(err, VDSH_ERR_ARGUMENT, "distance volume", "no samples");
    size_t n = sample_count(v), bytes = vdsh_sdf_file_size(v);
    uint8_t *d = calloc(1, bytes);
    if (!d)
        return vdsh_failf_at(err, VDSH_ERR_OUT_OF_MEMORY, "distance volume", "out of memory");
    memcpy(d, MAGIC, 8);
    put_u32(d + 8, SDF_VERSION);
    for (int a = 0; a < 3; a++) {
        put_u32(d + 12 + 4 * a, v->dim[a]);
        put_f32(d + 24 + 4 * a, v->origin[a]);
    }
    put_f32(d + 36, v->cell);
    put_f32(d + 40, v->max_distance);
    put_u32(d + 44, v->vertex_count);
    put_u32(d + 48, v->triangle_count);
    uint8_t *s = d + VDSH_SDF_HEADER_SIZE;
    for (size_t i = 0; i < n; i++) {
        s[2 * i] = (uint8_t)v->samples[i];
        s[2 * i + 1] = (uint8_t)(v->samples[i] >> 8);
    }
    put_u32(d + 52, vdsh_crc32(0, s, 2 * n));
    put_u32(d + 60, vdsh_crc32(0, d, 60));
    *out = d;
    *size = bytes;
    return VDSH_OK;
}

vdsh_result vdsh_sdf_stage(const char *path, const vdsh_sdf *v, vdsh_output *out, vdsh_error *err)
{
    void *data;
    size_t size;
    *out = (vdsh_output){.fd = -1};
    vdsh_result r = vdsh_sdf_write_memory(v, &data, &size, err);
    if (r != VDSH_OK) {
        if (err) {
            char m[sizeof err->msg];
            memcpy(m, err->msg, sizeof m);
            vdsh_failf_at(err, r, path, "%.300s", m);
        }
        return r;
    }
    r = vdsh_output_open(path, out, err);
    if (r == VDSH_OK) {
        vdsh_output_put(out, data, size);
        r = vdsh_output_finish(out, err);
    }
    free(data);
    return r;
}

vdsh_result vdsh_sdf_write(const char *path, const vdsh_sdf *v, vdsh_error *err)
{
    vdsh_output out;
    vdsh_result r = vdsh_sdf_stage(path, v, &out, err);
    return r == VDSH_OK ? vdsh_output_commit(&out, err) : r;
}

void vdsh_sdf_free(vdsh_sdf *v)
{
    if (v) {
        free(v->samples);
        v->samples = NULL;
    }
}

int vdsh_sdf_other_scene(const vdsh_sdf *v, uint32_t vertex_count, uint32_t triangle_count)
{
    return (v->vertex_count || v->triangle_count) &&
           (v->vertex_count != vertex_count || v->triangle_count != triangle_count);
}

/* ---- the trace: runtime/vr_glsl_sdf.c repeats it operation for operation ---- */

float vdsh_sdf_sample(const vdsh_sdf *v, const float p[3])
{
    int i0[3];
    float f[3];
    for (int a = 0; a < 3; a++) {
        float g = (p[a] - v->origin[a]) / v->cell;
        float hi = (float)(v->dim[a] - 1);
        g = g < 0.0f ? 0.0f : g > hi ? hi : g;
        if (g != g)
            g = 0.0f;
        float fl = floorf(g);
        fl = fl > hi - 1.0f ? hi - 1.0f : fl;
        i0[a] = (int)fl;
        f[a] = g - fl;
    }
    const size_t sx = 1, sy = v->dim[0], sz = (size_t)v->dim[0] * v->dim[1];
    const uint16_t *b = v->samples + (size_t)i0[0] + (size_t)i0[1] * sy + (size_t)i0[2] * sz;
    float c[8];
    for (int k = 0; k < 8; k++)
        c[k] = vdsh_sdf_decode(b[(k & 1 ? sx : 0) + (k & 2 ? sy : 0) + (k & 4 ? sz : 0)],
                               v->max_distance);
    float x00 = c[0] + (c[1] - c[0]) * f[0], x10 = c[2] + (c[3] - c[2]) * f[0];
    float x01 = c[4] + (c[5] - c[4]) * f[0], x11 = c[6] + (c[7] - c[6]) * f[0];
    float y0 = x00 + (x10 - x00) * f[1], y1 = x01 + (x11 - x01) * f[1];
    return y0 + (y1 - y0) * f[2];
}

float vdsh_sdf_shadow(const vdsh_sdf *v, const float p[3], const float n[3], const float light[3],
                      float k)
{
    float o[3], dir[3];
    for (int a = 0; a < 3; a++) {
        o[a] = p[a] + n[a] * (1.5f * v->cell);
        dir[a] = light[a] - o[a];
    }
    float tmax = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (!(tmax > 0.0f))
        return 1.0f;
    for (int a = 0; a < 3; a++)
        dir[a] /= tmax;
    /* Quilez's k is for a light at infinity; a point light at distance
     * tmax of radius diag / k is a cone of k * tmax / diag (Unreal's
     * source radius). A constant k darkens every receiver of a light
     * near a wall: the trace ends within its clearance of the wall. */
    const float kk = k * tmax / v->max_distance;
    float res = 1.0f, t = 0.5f * v->cell;
    const float min_step = v->cell * 0.125f, hit = v->cell * (1.0f / 64.0f);
    for (int i = 0; i < VDSH_SDF_MAX_STEPS && t < tmax; i++) {
        float q[3] = {o[0] + dir[0] * t, o[1] + dir[1] * t, o[2] + dir[2] * t};
        /* Surfaces thickened by half a spacing: a sheet of no thickness
         * between two samples interpolates to up to cell / 2, and would
         * let every trace through. */
        float h = vdsh_sdf_sample(v, q) - 0.35f * v->cell;
        if (h < hit)
            return 0.0f;
        float s = kk * h / t;
        res = s < res ? s : res;
        t += h > min_step ? h : min_step;
    }
    return res < 0.0f ? 0.0f : res;
}
