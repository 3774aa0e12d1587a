/*
 * vdsh-raydump: for a deterministic sample of a scene's receivers, the
 * bake's own traced directions and distances and held-out directions with
 * their true distances, as a flat binary file, for studies of fits outside
 * the baker (scripts/fit_floor). Receivers, normals and ray origins are
 * the bake's (vb_mesh_refine, vb_orient_receivers, vb_ray_origins).
 *
 * Layout (little-endian): u32 receivers K, u32 traced N, u32 held-out H,
 * u32 scene receivers, f32 clamp distance; then per receiver: f32
 * position[3], f32 normal[3], u32 vertex index, then N + H records of f32
 * direction[3], f32 distance (scene units; misses get the clamp).
 *
 * Exit status: 0, 1 error, 2 usage.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "mesh.h"
#include "sampling.h"
#include "scene.h"
#include "vdsh_output.h"
#include "vt_cli.h"

static float trace(const vb_scene *s, const float o[3], const float d[3], float tmax)
{
    struct RTCRayHit rh;
    memset(&rh, 0, sizeof rh);
    rh.ray.org_x = o[0], rh.ray.org_y = o[1], rh.ray.org_z = o[2];
    rh.ray.dir_x = d[0], rh.ray.dir_y = d[1], rh.ray.dir_z = d[2];
    rh.ray.tfar = tmax, rh.ray.mask = 0xffffffffu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcIntersect1(s->scene, &ctx, &rh);
    return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? tmax : rh.ray.tfar;
}

#if defined(__GNUC__)
__attribute__((format(printf, 1, 2)))
#endif
static int bad_number(const char *fmt, ...)
{
    va_list ap;
    fputs("vdsh-raydump: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    return VT_EXIT_USAGE;
}

int main(int argc, char **argv)
{
    if (argc != 7) {
        fprintf(stderr, "usage: vdsh-raydump MESH MAX_EDGE RECEIVERS RAYS HELD_OUT OUT\n"
                        "  RAYS as vdsh-bake --rays (its hemisphere half is traced)\n");
        return 2;
    }
    /* Strict decimal numbers, as every vdsh program reads them (vt_cli.h). */
    float max_edge;
    uint64_t K, rays, H;
    if (!vt_parse_float(argv[2], &max_edge) || !(max_edge >= 0.0f))
        return bad_number("MAX_EDGE takes a number >= 0, not '%s'", argv[2]);
    if (!vt_parse_u64(argv[3], 1, VDSH_MAX_VERTICES, &K))
        return bad_number("RECEIVERS takes a whole number 1..%u, not '%s'",
                              VDSH_MAX_VERTICES, argv[3]);
    if (!vt_parse_u64(argv[4], 2, 100000, &rays))
        return bad_number("RAYS takes a whole number 2..100000, not '%s'",
                              argv[4]);
    if (!vt_parse_u64(argv[5], 0, 100000, &H))
        return bad_number("HELD_OUT takes a whole number 0..100000, not '%s'",
                              argv[5]);
    vb_error err;
    vb_mesh occ = {0}, rec = {0};
    vb_scene *s = NULL;
    vb_dirgrid g = {0};
    float *org = NULL, *buf = NULL;
    vdsh_output out = {.fd = -1};
    FILE *f = NULL;
    int status = 1;
    uint32_t flipped = 0;
    vb_origins_stats ost = {0};
    if (vb_mesh_load(argv[1], NULL, &occ, NULL, &err) != VB_OK ||
        vb_mesh_refine(&occ, max_edge, &rec, &err) != VB_OK ||
        vb_scene_create(&occ, NULL, &s, &err) != VB_OK ||
        vb_orient_receivers(&rec, s, 0, &flipped, &err) != VB_OK ||
        !(org = malloc((size_t)rec.vertex_count * 3 * sizeof *org)) ||
        vb_ray_origins(&rec, s, 0, org, NULL, &ost, &err) != VB_OK ||
        vb_dirgrid_create((uint32_t)(rays + 1) / 2, 1, &g, &err) != VB_OK) {
        fprintf(stderr, "vdsh-raydump: %s\n", org ? err.msg : "out of memory");
        goto out;
    }
    vdsh_error verr;
    if (!(buf = malloc(sizeof(float) * 4 * (g.count + (size_t)H)))) {
        fprintf(stderr, "vdsh-raydump: out of memory\n");
        goto out;
    }
    if (vdsh_output_open(argv[6], &out, &verr) != VDSH_OK) {
        fprintf(stderr, "vdsh-raydump: %s\n", verr.msg);
        goto out;
    }
    f = out.fp;
    float clamp = s->diagonal, tmax = clamp * s->scale, inv = 1.0f / s->scale;
    uint32_t hdr[4] = {(uint32_t)K, g.count, (uint32_t)H, rec.vertex_count};
    fwrite(hdr, 4, 4, f);
    fwrite(&clamp, 4, 1, f);
    for (uint64_t i = 0; i < K; i++) {
        uint32_t v = (uint32_t)(i * rec.vertex_count / K);
        const float *n = rec.normals + 3 * (size_t)v, *o = org + 3 * (size_t)v;
        size_t c = 0;
        fwrite(rec.positions + 3 * (size_t)v, 4, 3, f);
        fwrite(n, 4, 3, f);
        fwrite(&v, 4, 1, f);
        for (uint32_t pk = 0; pk < g.packet_count; pk++) { /* the bake's directions */
            float dx[16], dy[16], dz[16];
            int valid[16];
            vb_dirgrid_packet(&g, pk, 1, v, n, dx, dy, dz, valid);
            for (int k = 0; k < 16; k++)
                if (valid[k]) {
                    float d[3] = {dx[k], dy[k], dz[k]};
                    memcpy(buf + 4 * c, d, sizeof d);
                    buf[4 * c++ + 3] = trace(s, o, d, tmax) * inv;
                }
        }
        float t[3], b[3];
        vb_frame(n, t, b);
        for (uint64_t h = 0; h < H; h++) { /* held out: uniform over the hemisphere */
            float u1, u2, d[3];
            vb_hash2(0x686f6c64ull, v, (uint32_t)h, &u1, &u2);
            float r = sqrtf(fmaxf(0.0f, 1.0f - u1 * u1)), ph = 6.2831853f * u2;
            for (int q = 0; q < 3; q++)
                d[q] = r * cosf(ph) * t[q] + r * sinf(ph) * b[q] + u1 * n[q];
            memcpy(buf + 4 * c, d, sizeof d);
            buf[4 * c++ + 3] = trace(s, o, d, tmax) * inv;
        }
        fwrite(buf, 4, 4 * c, f);
    }
    f = NULL;
    if (vdsh_output_commit(&out, &verr) != VDSH_OK) {
        fprintf(stderr, "vdsh-raydump: %s\n", verr.msg);
        goto out;
    }
    fprintf(stderr, "vdsh-raydump: %llu of %u receivers, %u traced + %llu held-out directions "
                    "each (%u normals flipped, %u origins moved)\n",
            (unsigned long long)K, rec.vertex_count, g.count, (unsigned long long)H, flipped,
            ost.moved);
    status = 0;
out:
    vdsh_output_abort(&out);
    free(buf);
    free(org);
    vb_dirgrid_destroy(&g);
    vb_scene_destroy(s);
    vb_mesh_free(&occ);
    vb_mesh_free(&rec);
    return status;
}
