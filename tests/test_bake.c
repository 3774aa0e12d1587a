/*
 * Bake core against analytic truth: the centre of a closed sphere, points
 * on the floor of a closed box; the direction grid; thread determinism;
 * neighbours' decision fits. Scenes are generated here, so the test needs
 * no files.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "sampling.h"
#include "scene.h"
#include "test_scenes.h"
#include "test_util.h"
#include "vdsh.h"
#include "vdsh_sh.h"

/* ---- scene builders ----------------------------------------------------- */

/* UV sphere of radius r around c, fine enough that the chord error is
 * below 1e-3 r. */
static void make_sphere(vb_mesh *m, float r, const float c[3])
{
    enum { NT = 96, NP = 192 };
    test_mesh_alloc(m, (NT + 1) * NP, 2 * NT * NP);
    for (int i = 0; i <= NT; i++)
        for (int j = 0; j < NP; j++) {
            double th = M_PI * i / NT, ph = 2 * M_PI * j / NP;
            float *p = m->positions + 3 * (i * NP + j);
            float d[3] = {(float)(sin(th) * cos(ph)), (float)(sin(th) * sin(ph)), (float)cos(th)};
            for (int k = 0; k < 3; k++) {
                p[k] = c[k] + r * d[k];
                m->normals[3 * (i * NP + j) + k] = -d[k];
            }
        }
    uint32_t t = 0;
    for (int i = 0; i < NT; i++)
        for (int j = 0; j < NP; j++) {
            uint32_t a = i * NP + j, b = i * NP + (j + 1) % NP;
            uint32_t cc = a + NP, dd = b + NP;
            uint32_t q[6] = {a, b, cc, b, dd, cc};
            memcpy(m->indices + 3 * t, q, sizeof q);
            t += 2;
        }
}

static int bake_q(const vb_mesh *occ, const vb_mesh *rec, vb_method method, vb_quantity quantity,
                  uint32_t rays, unsigned threads, vb_bake_output *out)
{
    vb_error err;
    vb_scene *s = NULL;
    if (vb_scene_create(occ, NULL, &s, &err) != VB_OK) {
        fprintf(stderr, "scene: %s\n", err.msg);
        return 0;
    }
    vb_bake_desc d = {.keep_normals = 1,
                      .receivers = rec,
                      .scene = s,
                      .rays = rays,
                      .seed = 5,
                      .method = method,
                      .quantity = quantity,
                      .threads = threads};
    vb_result r = vb_bake_run(&d, out, &err);
    if (r != VB_OK)
        fprintf(stderr, "bake: %s\n", err.msg);
    vb_scene_destroy(s);
    return r == VB_OK;
}

static int bake(const vb_mesh *occ, const vb_mesh *rec, vb_method method, uint32_t rays,
                unsigned threads, vb_bake_output *out)
{
    return bake_q(occ, rec, method, VB_QUANTITY_AUTO, rays, threads, out);
}

/* ---- tests -------------------------------------------------------------- */

/* The centre of a closed sphere sees D = R everywhere: `full` (the
 * distance: its log, ln R, is a constant too, which the log fit also
 * reconstructs exactly, so auto may store either) reconstructs it at
 * every order; `paper` gives the projection of R * step(w.n), whose
 * zonal coefficients are known in closed form. */
static void test_sphere_centre(void)
{
    const float R = 3.0f, c[3] = {0.5f, -1.0f, 2.0f};
    vb_mesh occ = {0}, rec = {0};
    make_sphere(&occ, R, c);
    float n[3] = {0, 0, 1};
    test_make_points(&rec, 1, c, n);

    vb_bake_output full = {0}, paper = {0};
    CHECK(bake_q(&occ, &rec, VB_METHOD_FULL, VB_QUANTITY_DISTANCE, 2500, 2, &full), "full bake");
    CHECK(bake(&occ, &rec, VB_METHOD_PAPER, 2500, 2, &paper), "paper bake");
    if (!full.coeffs[5] || !paper.coeffs[5])
        goto out;
    CHECK(full.rays_missed == 0, "%llu rays escaped a closed sphere",
          (unsigned long long)full.rays_missed);
    CHECK(full.rays_traced == 2500, "full traced %llu rays", (unsigned long long)full.rays_traced);
    CHECK(paper.rays_traced > 1200 && paper.rays_traced < 1300,
          "paper should trace only the upper half: %llu", (unsigned long long)paper.rays_traced);

    /* Equal-weight sampling integrates a constant exactly: c_0 = R sqrt(4 pi),
     * less the tessellation's chord sag (at most 1.4e-4 R for this sphere).
     * The higher coefficients carry the jittered sampling's noise, which
     * grows with the band (measured: RMS 0.3% of R at order 3, 0.9% at
     * order 5 over many seeds), so the bound loosens with the order. */
    CHECK(fabs(full.coeffs[5][0] - R * sqrt(4 * M_PI)) < 2e-4 * R * sqrt(4 * M_PI),
          "c0 = %g, want %g", full.coeffs[5][0], R * sqrt(4 * M_PI));
    uint64_t s = 1;
    const double bound[6] = {0, 0, 0.002, 0.006, 0.012, 0.018};
    for (int order = 2; order <= 5; order++) {
        double se = 0.0;
        for (int k = 0; k < 2000; k++) {
            float d[3];
            test_rand_dir(&s, d);
            double e = vdsh_sh_reconstruct(order, full.coeffs[5], d) - R;
            se += e * e;
        }
        double rms = sqrt(se / 2000) / R;
        CHECK(rms < bound[order], "order %d: RMS |D - R| / R = %g", order, rms);
    }

    /* Zonal coefficients of R * step(z): c_l0 = R * 2 pi * int_0^1 Y_l0(z) dz
     * (Simpson's rule in double), all m != 0 coefficients zero. */
    for (int l = 0; l <= 4; l++) {
        double sum = 0.0;
        const int N = 2000;
        for (int i = 0; i <= N; i++) {
            double z = (double)i / N, r = sqrt(fmax(0.0, 1 - z * z));
            float d[3] = {(float)r, 0.0f, (float)z}, y[25];
            vdsh_sh_eval(5, d, y);
            double w = (i == 0 || i == N) ? 1 : (i % 2 ? 4 : 2);
            sum += w * y[l * (l + 1)];
        }
        double want = R * 2 * M_PI * sum / (3.0 * N);
        for (int m = -l; m <= l; m++) {
            double got = paper.coeffs[5][l * (l + 1) + m];
            double exp = m == 0 ? want : 0.0;
            CHECK(fabs(got - exp) < 0.02 * R, "paper c_%d,%d = %g, analytic %g", l, m, got, exp);
        }
    }
out:
    vb_bake_output_free(&full);
    vb_bake_output_free(&paper);
    test_mesh_free(&occ);
    test_mesh_free(&rec);
}

/* Distance from p (inside the box) along unit d to the box's walls. */
static double box_exit(const float p[3], const float d[3], const float lo[3], const float hi[3])
{
    double t = INFINITY;
    for (int i = 0; i < 3; i++) {
        if (d[i] > 0)
            t = fmin(t, (hi[i] - p[i]) / d[i]);
        else if (d[i] < 0)
            t = fmin(t, (lo[i] - p[i]) / d[i]);
    }
    return t;
}

/* Points on the floor of a closed box: the reconstruction converges to the
 * analytic distance as the order grows (RMS over the upper hemisphere,
 * relative to the true distance), within bounds that tighten with order. */
static void test_box_floor(void)
{
    const float a = 4.0f, h = 3.0f, b = 2.5f;
    const float lo[3] = {-a, 0, -b}, hi[3] = {a, h, b};
    vb_mesh occ = {0}, rec = {0};
    test_make_box(&occ, a, h, b);
    enum { NP = 5 };
    float p[3 * NP] = {0, 0, 0, 1.5f, 0, 0.5f, -2.0f, 0, -1.0f, 3.0f, 0, 1.5f, -0.5f, 0, 1.8f};
    float n[3 * NP];
    for (int i = 0; i < NP; i++)
        n[3 * i] = 0, n[3 * i + 1] = 1, n[3 * i + 2] = 0;
    test_make_points(&rec, NP, p, n);
    vb_bake_output out = {0};
    CHECK(bake(&occ, &rec, VB_METHOD_PAPER, 10000, 2, &out), "box bake");
    if (!out.coeffs[5])
        goto done;
    CHECK(out.rays_missed == 0, "%llu rays escaped a closed box",
          (unsigned long long)out.rays_missed);

    const int orders[3] = {2, 3, 5};
    const double bound[3] = {0.40, 0.33, 0.25};
    double rms[3];
    for (int oi = 0; oi < 3; oi++) {
        double se = 0.0;
        int cnt = 0;
        uint64_t s = 99;
        for (int v = 0; v < NP; v++)
            for (int k = 0; k < 400; k++) {
                float d[3];
                test_rand_dir(&s, d);
                if (d[1] < 0.05f)
                    d[1] = -d[1];
                if (d[1] < 0.05f)
                    continue;
                double truth = box_exit(p + 3 * v, d, lo, hi);
                double got = vdsh_sh_reconstruct(orders[oi], out.coeffs[5] + 25 * v, d);
                se += (got - truth) * (got - truth) / (truth * truth);
                cnt++;
            }
        rms[oi] = sqrt(se / cnt);
        CHECK(rms[oi] < bound[oi], "order %d: relative RMS %g above %g", orders[oi], rms[oi],
              bound[oi]);
    }
    printf("box floor relative RMS: order 2 %.4f, order 3 %.4f, order 5 %.4f\n", rms[0], rms[1],
           rms[2]);
    CHECK(rms[2] < rms[1] && rms[1] < rms[0], "error must fall with order: %g %g %g", rms[0],
          rms[1], rms[2]);
done:
    vb_bake_output_free(&out);
    test_mesh_free(&occ);
    test_mesh_free(&rec);
}

/* The grid: unit directions, one per cell, packets of neighbouring cells,
 * per-vertex jitter, hemisphere directions above the horizon. */
static void test_grid(void)
{
    vb_dirgrid g = {0};
    vb_error err;
    CHECK(vb_dirgrid_create(2500, 0, &g, &err) == VB_OK, "grid");
    CHECK(g.nu == 50 && g.nv == 50 && g.count == 2500 && g.packet_count == 157,
          "grid %ux%u, %u packets", g.nu, g.nv, g.packet_count);
    char *seen = calloc(g.count, 1);
    int blocks_ok = 0, full_blocks = 0;
    for (uint32_t pk = 0; pk < g.packet_count; pk++) {
        float x[16], y[16], z[16];
        int valid[16];
        float n[3] = {0, 0, 1};
        vb_dirgrid_packet(&g, pk, 1, 7, n, x, y, z, valid);
        uint32_t rmin = UINT32_MAX, rmax = 0, cmin = UINT32_MAX, cmax = 0;
        for (int k = 0; k < 16; k++) {
            uint32_t cell = g.cells[pk * 16 + k];
            if (cell == UINT32_MAX) {
                CHECK(!valid[k], "empty lane marked valid");
                continue;
            }
            CHECK(valid[k] == -1, "lane not valid");
            CHECK(!seen[cell], "cell %u twice", cell);
            seen[cell] = 1;
            float len = sqrtf(x[k] * x[k] + y[k] * y[k] + z[k] * z[k]);
            CHECK(fabsf(len - 1) < 1e-5f, "direction length %g", len);
            uint32_t row = cell / g.nv, col = cell % g.nv;
            /* The direction lies inside its cell. */
            double w = (1.0 - z[k]) / 2.0 * g.nu;
            double phi = atan2(y[k], x[k]);
            if (phi < 0)
                phi += 2 * M_PI;
            double cc = phi / (2 * M_PI) * g.nv;
            CHECK(w >= row - 1e-3 && w <= row + 1 + 1e-3, "row %u: %g", row, w);
            CHECK(cc >= col - 1e-3 && cc <= col + 1 + 1e-3, "col %u: %g", col, cc);
            rmin = row < rmin ? row : rmin, rmax = row > rmax ? row : rmax;
            cmin = col < cmin ? col : cmin, cmax = col > cmax ? col : cmax;
        }
        blocks_ok += rmax - rmin <= 7 && cmax - cmin <= 7;
        full_blocks += rmax - rmin == 3 && cmax - cmin == 3;
    }
    for (uint32_t i = 0; i < g.count; i++)
        CHECK(seen[i], "cell %u never sampled", i);

    /* Horizon culling is conservative: no direction of a culled packet,
     * for any receiver's jitter, is above the horizon; and it culls about
     * half the packets, or it would be pointless. */
    uint64_t rs = 17;
    uint32_t culled = 0, considered = 0;
    for (int trial = 0; trial < 200; trial++) {
        float nn[3];
        test_rand_dir(&rs, nn);
        for (uint32_t pk = 0; pk < g.packet_count; pk++) {
            considered++;
            if (!vb_dirgrid_packet_below(&g, pk, nn))
                continue;
            culled++;
            for (uint32_t vtx = 0; vtx < 20; vtx++) {
                float x[16], y[16], z[16];
                int valid[16];
                vb_dirgrid_packet(&g, pk, 3, vtx * 7919u + (uint32_t)trial, nn, x, y, z, valid);
                for (int k = 0; k < 16; k++)
                    if (valid[k])
                        CHECK(x[k] * nn[0] + y[k] * nn[1] + z[k] * nn[2] < 0.0f,
                              "culled packet %u has a direction above the horizon", pk);
            }
        }
    }
    CHECK(culled > considered / 3, "culled only %u of %u packets", culled, considered);
    printf("horizon culling skips %.1f%% of packets\n", 100.0 * culled / considered);
    /* Morton order: 144 packets are exact 4x4 blocks, the rest compact. */
    CHECK(blocks_ok == (int)g.packet_count, "only %d of %u packets are compact", blocks_ok,
          g.packet_count);
    CHECK(full_blocks >= 144, "only %d packets are 4x4 blocks", full_blocks);

    /* Jitter differs between vertices, repeats for the same vertex. */
    float a[16], b[16], c[16], d2[16], e[16], f[16];
    int va[16];
    float n[3] = {0, 0, 1};
    vb_dirgrid_packet(&g, 3, 1, 7, n, a, b, c, va);
    vb_dirgrid_packet(&g, 3, 1, 8, n, d2, e, f, va);
    CHECK(memcmp(a, d2, sizeof a) != 0, "two vertices got the same jitter");
    vb_dirgrid_packet(&g, 3, 1, 7, n, d2, e, f, va);
    CHECK(memcmp(a, d2, sizeof a) == 0 && memcmp(c, f, sizeof c) == 0, "jitter not repeatable");
    free(seen);
    vb_dirgrid_destroy(&g);

    CHECK(vb_dirgrid_create(1000, 1, &g, &err) == VB_OK, "hemisphere grid");
    CHECK(g.count == 31 * 32, "1000 rays give %u", g.count);
    float nn[3] = {0.6f, -0.48f, 0.64f};
    for (uint32_t pk = 0; pk < g.packet_count; pk++) {
        float x[16], y[16], z[16];
        int valid[16];
        vb_dirgrid_packet(&g, pk, 2, 0, nn, x, y, z, valid);
        for (int k = 0; k < 16; k++)
            if (valid[k])
                CHECK(x[k] * nn[0] + y[k] * nn[1] + z[k] * nn[2] >= -1e-6f,
                      "hemisphere direction below the horizon");
    }
    vb_dirgrid_destroy(&g);
    CHECK(vb_dirgrid_create(0, 0, &g, &err) == VB_ERR_ARGUMENT, "0 rays accepted");
}

/* np receivers at random in the box test_make_box(2, 2, 2) makes
 * (x, z in [-1.8, 1.8], y in [0, 2]), facing random directions. */
static void random_in_box(uint64_t seed, int np, float *p, float *n)
{
    uint64_t s = seed;
    for (int i = 0; i < np; i++) {
        p[3 * i] = (float)(3.6 * test_rand(&s) - 1.8);
        p[3 * i + 1] = (float)(2 * test_rand(&s));
        p[3 * i + 2] = (float)(3.6 * test_rand(&s) - 1.8);
        test_rand_dir(&s, n + 3 * i);
    }
}

/* 1 and 2 threads give bit-identical coefficients. */
static void test_threads(void)
{
    vb_mesh occ = {0}, rec = {0};
    test_make_box(&occ, 2, 2, 2);
    enum { NP = 200 };
    float p[3 * NP], n[3 * NP];
    random_in_box(5, NP, p, n);
    test_make_points(&rec, NP, p, n);
    vb_bake_output one = {0}, two = {0};
    CHECK(bake(&occ, &rec, VB_METHOD_PAPER, 400, 1, &one), "1 thread");
    CHECK(bake(&occ, &rec, VB_METHOD_PAPER, 400, 2, &two), "2 threads");
    if (one.coeffs[5] && two.coeffs[5])
        CHECK(memcmp(one.coeffs[5], two.coeffs[5], NP * 25 * sizeof(float)) == 0,
              "1 and 2 threads differ");
    CHECK(one.rays_traced == two.rays_traced, "ray counts differ");
    vb_bake_output_free(&one);
    vb_bake_output_free(&two);
    test_mesh_free(&occ);
    test_mesh_free(&rec);
}

/* Method shadow is lsq of the log distance with each order's log offset
 * added through c0 (Y00 = 1 / (2 sqrt(pi)), a constant): every stored
 * distance is e^offset times lsq's, exactly, in every direction; the
 * default offsets are positive (longer distances, fewer false shadows)
 * and an explicit one is used at every order. */
static void test_shadow_offset(void)
{
    vb_mesh occ = {0}, rec = {0};
    test_make_box(&occ, 2, 2, 2);
    enum { NP = 64 };
    float p[3 * NP], n[3 * NP];
    random_in_box(9, NP, p, n);
    test_make_points(&rec, NP, p, n);
    vb_error err;
    vb_scene *sc = NULL;
    CHECK(vb_scene_create(&occ, NULL, &sc, &err) == VB_OK, "scene");
    const float mine[VDSH_MAX_ORDER + 1] = {0, -0.3f, -0.3f, -0.3f, -0.3f, -0.3f};
    vb_bake_output b[3] = {{0}};
    for (int i = 0; i < 3 && sc; i++) {
        vb_bake_desc d = {.keep_normals = 1,
                          .receivers = &rec,
                          .scene = sc,
                          .rays = 400,
                          .seed = 5,
                          .method = i ? VB_METHOD_SHADOW : VB_METHOD_LSQ,
                          .quantity = VB_QUANTITY_LOG,
                          .log_offsets = i == 2 ? mine : NULL,
                          .order_mask = (1u << 2) | (1u << 3) | (1u << 5)};
        CHECK(vb_bake_run(&d, &b[i], &err) == VB_OK, "bake %d: %s", i, err.msg);
    }
    for (int o = 2; o <= 5 && b[2].coeffs[5]; o++) {
        if (!b[0].coeffs[o])
            continue;
        CHECK(vb_shadow_log_offset(o) > 0.0f, "order %d: default offset %g", o,
              (double)vb_shadow_log_offset(o));
        CHECK(b[1].log_offset[o] == vb_shadow_log_offset(o) && b[2].log_offset[o] == -0.3f,
              "order %d: offsets recorded %g %g", o, (double)b[1].log_offset[o],
              (double)b[2].log_offset[o]);
        int bad = 0;
        for (uint32_t v = 0; v < NP; v++) {
            const float *l = b[0].coeffs[o] + (size_t)v * o * o;
            for (int q = 1; q < 3; q++) {
                const float *c = b[q].coeffs[o] + (size_t)v * o * o;
                float off = q == 1 ? vb_shadow_log_offset(o) : -0.3f;
                bad += fabsf(c[0] - (l[0] + off / 0.28209479f)) > 1e-5f * (1 + fabsf(c[0]));
                for (int i = 1; i < o * o; i++)
                    bad += c[i] != l[i];
            }
        }
        CHECK(bad == 0, "order %d: %d coefficients are not lsq's with the offset", o, bad);
    }
    for (int i = 0; i < 3; i++)
        vb_bake_output_free(&b[i]);
    vb_scene_destroy(sc);
    test_mesh_free(&occ);
    test_mesh_free(&rec);
}

/* Offset normals average over bit-identical positions only, and only
 * normals facing the same side. */
static void test_offset_normals(void)
{
    vb_mesh m = {0};
    float p[12] = {1, 2, 3, 1, 2, 3, 1, 2, 3.0001f, 1, 2, 3};
    float n[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0};
    test_make_points(&m, 4, p, n);
    float out[12];
    vb_error err;
    CHECK(vb_offset_normals(&m, out, &err) == VB_OK, "offset normals");
    /* Vertices 0, 1, 3 share a position; each sums the normals not facing
     * away from its own: 0 takes (1,0,0) + (0,1,0) + (0,-1,0); 1 takes
     * (1,0,0) + (0,1,0); 3 takes (1,0,0) + (0,-1,0). Vertex 2 is alone. */
    float r = 1.0f / sqrtf(2.0f);
    CHECK(out[0] == 1 && out[1] == 0 && out[2] == 0, "vertex 0: (%g %g %g)", out[0], out[1],
          out[2]);
    CHECK(fabsf(out[3] - r) < 1e-6f && fabsf(out[4] - r) < 1e-6f && out[5] == 0,
          "vertex 1: (%g %g %g)", out[3], out[4], out[5]);
    CHECK(out[6] == 0 && out[7] == 0 && out[8] == 1, "distinct position changed");
    CHECK(fabsf(out[9] - r) < 1e-6f && fabsf(out[10] + r) < 1e-6f && out[11] == 0,
          "vertex 3: (%g %g %g)", out[9], out[10], out[11]);
    test_mesh_free(&m);
}

/* Adaptive rays' nested grid: a 1250-direction hemisphere gives 32 x 32
 * cells in 5 rounds (64, 128, ..., 1024 cells); for a receiver, every
 * prefix of rounds is a stratified sub-grid (one cell in each block of the
 * Morton code's free high bits), each contains the last, and the full
 * grid visits every cell once. */
static void test_nested_grid(void)
{
    vb_dirgrid g = {0};
    vb_error err;
    CHECK(vb_dirgrid_create_nested(1250, 1, &g, &err) == VB_OK, "nested grid: %s", err.msg);
    CHECK(g.nu == 32 && g.nv == 32 && g.count == 1024 && g.rounds == 5, "%ux%u, %u rounds", g.nu,
          g.nv, g.rounds);
    for (uint32_t r = 0; r < g.rounds && r < 5; r++)
        CHECK(g.round_end[r] == (64u << r) / 16, "round %u ends at packet %u", r, g.round_end[r]);
    const float n[3] = {0, 0, 1};
    for (uint32_t vertex = 0; vertex < 3; vertex++) {
        static unsigned char seen[1024];
        memset(seen, 0, sizeof seen);
        int bad = 0, twice = 0, pole = 0;
        for (uint32_t r = 0; r < g.rounds && r < 5; r++) {
            for (uint32_t pk = r ? g.round_end[r - 1] : 0; pk < g.round_end[r]; pk++) {
                float x[16], y[16], z[16];
                int valid[16];
                vb_dirgrid_packet_nested(&g, pk, 9, vertex, n, x, y, z, valid);
                for (int k = 0; k < 16; k++) {
                    double phi = atan2(y[k], x[k]);
                    if (phi < 0)
                        phi += 2 * M_PI;
                    uint32_t row = (uint32_t)((1.0 - z[k]) * 32),
                             col = (uint32_t)(phi / (2 * M_PI) * 32);
                    bad += valid[k] != -1 || row > 31 || col > 31;
                    if (x[k] * x[k] + y[k] * y[k] < 1e-8f) { /* at the pole: no column */
                        pole++;
                        continue;
                    }
                    if (row < 32 && col < 32) {
                        twice += seen[row * 32 + col] != 0;
                        seen[row * 32 + col] = 1;
                    }
                }
            }
            /* The prefix so far: 2^p cells, the low (10 - p) Morton bits
             * fixed: fr low row bits and fc low column bits. */
            int p = 6 + (int)r, fixed = 10 - p, fr = fixed / 2, fc = fixed - fr;
            static unsigned char block[1024];
            memset(block, 0, sizeof block);
            int cells = 0, strata_twice = 0;
            for (uint32_t c = 0; c < 1024; c++)
                if (seen[c]) {
                    uint32_t b = ((c / 32) >> fr) * (32u >> fc) + ((c % 32) >> fc);
                    strata_twice += block[b]++ != 0;
                    cells++;
                }
            cells += pole;
            CHECK(cells == (1 << p), "vertex %u round %u: %d cells, want %d", vertex, r, cells,
                  1 << p);
            CHECK(strata_twice == 0, "vertex %u round %u: %d strata sampled twice", vertex, r,
                  strata_twice);
        }
        CHECK(bad == 0 && twice == 0, "vertex %u: %d bad lanes, %d cells twice", vertex, bad,
              twice);
    }
    vb_dirgrid_destroy(&g);
    CHECK(vb_dirgrid_create_nested(100, 1, &g, &err) == VB_ERR_ARGUMENT, "cap 100 accepted");
}

/* Adaptive rays on receivers in a box: the same coefficients and ray
 * count on 1 and 3 threads; tolerance 0 traces every round (the whole
 * 32 x 32 grid), infinity stops at the first check (2/16 of it), the
 * default in between; every coefficient finite. */
static void test_adaptive_rays(void)
{
    vb_mesh occ = {0}, rec = {0};
    test_make_box(&occ, 2, 2, 2);
    enum { NP = 300 };
    float p[3 * NP], n[3 * NP];
    random_in_box(11, NP, p, n);
    /* A few on the floor, facing up into the box, and one in a corner. */
    for (int i = 0; i < 20; i++) {
        p[3 * i + 1] = 0.0f;
        n[3 * i] = 0, n[3 * i + 1] = 1, n[3 * i + 2] = 0;
    }
    p[0] = 1.999f, p[1] = 0.0f, p[2] = 1.999f;
    test_make_points(&rec, NP, p, n);
    vb_error err;
    vb_scene *sc = NULL;
    CHECK(vb_scene_create(&occ, NULL, &sc, &err) == VB_OK, "scene");
    const float tol[4] = {0.0f, 0.0f, -1.0f, INFINITY}; /* default x2, 0, inf */
    const unsigned threads[4] = {1, 3, 2, 2};
    vb_bake_output b[4] = {{0}};
    for (int i = 0; i < 4 && sc; i++) {
        vb_bake_desc d = {.receivers = &rec,
                          .scene = sc,
                          .rays = 2500,
                          .adaptive_rays = 1,
                          .ray_tolerance = tol[i],
                          .seed = 3,
                          .threads = threads[i],
                          .order_mask = (1u << 3) | (1u << 5)};
        CHECK(vb_bake_run(&d, &b[i], &err) == VB_OK, "adaptive bake %d: %s", i, err.msg);
    }
    if (b[0].coeffs[5] && b[1].coeffs[5] && b[2].coeffs[5] && b[3].coeffs[5]) {
        CHECK(memcmp(b[0].coeffs[5], b[1].coeffs[5], NP * 25 * sizeof(float)) == 0 &&
                  memcmp(b[0].coeffs[3], b[1].coeffs[3], NP * 9 * sizeof(float)) == 0,
              "1 and 3 threads differ");
        CHECK(b[0].rays_traced == b[1].rays_traced, "ray counts differ: %llu, %llu",
              (unsigned long long)b[0].rays_traced, (unsigned long long)b[1].rays_traced);
        CHECK(b[0].rays == 1024 && b[0].ray_tolerance == VB_DEFAULT_RAY_TOLERANCE,
              "cap %u, tolerance %g", b[0].rays, (double)b[0].ray_tolerance);
        CHECK(b[2].rays_traced == (uint64_t)NP * 1024, "tolerance 0 traced %llu",
              (unsigned long long)b[2].rays_traced);
        CHECK(b[3].rays_traced == (uint64_t)NP * 128, "tolerance inf traced %llu",
              (unsigned long long)b[3].rays_traced);
        CHECK(b[0].rays_traced > b[3].rays_traced && b[0].rays_traced < b[2].rays_traced,
              "default traced %llu, not between", (unsigned long long)b[0].rays_traced);
        int finite = 1;
        for (int i = 0; i < 4; i++)
            for (int k = 0; k < NP * 25; k++)
                finite &= isfinite(b[i].coeffs[5][k]) != 0;
        CHECK(finite, "a coefficient is not finite");
    }
    for (int i = 0; i < 4; i++)
        vb_bake_output_free(&b[i]);
    vb_scene_destroy(sc);
    test_mesh_free(&occ);
    test_mesh_free(&rec);
}

/* A receiver range (a shard) gets the whole bake's coefficients bit for
 * bit, with orientation on, for shadow (one quantity) and lsq (the
 * automatic quantity choice on a sample of 1024 of the 2501 receivers, most
 * outside any one range); receivers at one position straddle the cuts (their
 * normals enter each other's ray origins); and the ranges' ray counts add
 * up to the whole bake's. */
static void test_ranges(void)
{
    vb_mesh occ = {0}, rec = {0};
    test_make_box(&occ, 2, 2, 2);
    enum { NP = 2501 };
    static float p[3 * NP], n[3 * NP];
    uint64_t s = 17;
    for (int i = 0; i < NP; i++) {
        p[3 * i] = (float)(1.8 * test_rand(&s) - 0.9);
        p[3 * i + 1] = (float)(1.8 * test_rand(&s));
        p[3 * i + 2] = (float)(1.8 * test_rand(&s) - 0.9);
        test_rand_dir(&s, n + 3 * i);
    }
    /* Coincident receivers across the cuts: 1249..1251 at one position,
     * 0 and NP - 1 at another, their normals on one side of each other's
     * (so each one's ray-offset normal is their mean). */
    const int same[3][2] = {{1249, 1250}, {1251, 1250}, {NP - 1, 0}};
    for (int k = 0; k < 3; k++) {
        float *q = n + 3 * same[k][0];
        const float *r = n + 3 * same[k][1];
        memcpy(p + 3 * same[k][0], p + 3 * same[k][1], 3 * sizeof(float));
        q[0] = r[0], q[1] = r[1] + 0.5f, q[2] = r[2] + 0.25f * k;
        float len = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        for (int c = 0; c < 3; c++)
            q[c] /= len;
    }
    test_make_points(&rec, NP, p, n);
    vb_error err;
    vb_scene *sc = NULL;
    CHECK(vb_scene_create(&occ, NULL, &sc, &err) == VB_OK, "scene");
    const uint32_t cut[5] = {0, 1, 1250, 1251, NP};
    const vb_method methods[2] = {VB_METHOD_SHADOW, VB_METHOD_LSQ};
    for (int m = 0; m < 2 && sc; m++) {
        vb_bake_output whole = {0}, part[4] = {{0}};
        uint32_t mask = (1u << 3) | (1u << 5);
        for (int i = -1; i < 4; i++) {
            vb_bake_desc d = {.receivers = &rec,
                              .scene = sc,
                              .rays = 200,
                              .seed = 3,
                              .order_mask = mask,
                              .threads = 2,
                              .method = methods[m]};
            if (i >= 0)
                d.range_begin = cut[i], d.range_end = cut[i + 1];
            CHECK(vb_bake_run(&d, i < 0 ? &whole : &part[i], &err) == VB_OK, "bake %d: %s", i,
                  err.msg);
        }
        CHECK(m == 0 || whole.auto_receivers == 1024, "lsq: the quantity chosen on %u receivers",
              whole.auto_receivers);
        uint64_t traced = 0, missed = 0;
        for (int i = 0; i < 4 && whole.coeffs[5] && part[i].coeffs[5]; i++) {
            CHECK(part[i].range_begin == cut[i] && part[i].range_end == cut[i + 1] &&
                      part[i].vertex_count == NP,
                  "range %d: output range %u..%u of %u", i, part[i].range_begin, part[i].range_end,
                  part[i].vertex_count);
            traced += part[i].rays_traced;
            missed += part[i].rays_missed;
            /* Every range traces the choice's sample as the whole bake does. */
            CHECK(part[i].auto_receivers == whole.auto_receivers &&
                      memcmp(part[i].auto_error, whole.auto_error, sizeof whole.auto_error) == 0,
                  "method %d, range %d: the quantity choice's scores differ", m, i);
            for (int o = 3; o <= 5; o += 2) {
                /* A range holds its own rows only, the first receiver cut[i]'s. */
                size_t a = (size_t)cut[i] * o * o, b = (size_t)cut[i + 1] * o * o;
                CHECK(memcmp(part[i].coeffs[o], whole.coeffs[o] + a, (b - a) * sizeof(float)) == 0,
                      "method %d, range %u..%u order %d: coefficients differ", m, cut[i],
                      cut[i + 1], o);
                CHECK(part[i].quantity[o] == whole.quantity[o], "range %d order %d: quantity", i,
                      o);
            }
            /* And its own oriented normals only, as the whole bake's. */
            CHECK(memcmp(part[i].normals, whole.normals + 3 * (size_t)cut[i],
                         3 * (size_t)(cut[i + 1] - cut[i]) * sizeof(float)) == 0,
                  "method %d, range %d: oriented normals differ", m, i);
        }
        CHECK(traced == whole.rays_traced && missed == whole.rays_missed,
              "ranges traced %llu missed %llu, the whole bake %llu %llu",
              (unsigned long long)traced, (unsigned long long)missed,
              (unsigned long long)whole.rays_traced, (unsigned long long)whole.rays_missed);
        vb_bake_output_free(&whole);
        for (int i = 0; i < 4; i++)
            vb_bake_output_free(&part[i]);
    }
    vb_bake_desc bad = {.receivers = &rec, .scene = sc, .range_begin = 5, .range_end = NP + 1};
    vb_bake_output none = {0};
    CHECK(vb_bake_run(&bad, &none, &err) == VB_ERR_ARGUMENT, "a range past the end is refused");
    vb_bake_output_free(&none);
    vb_scene_destroy(sc);
    test_mesh_free(&occ);
    test_mesh_free(&rec);
}

/* Adaptive order (bake.h, order_tolerance): receivers on the ground
 * around a box. Every receiver's variable-order coefficients are, bit for
 * bit, the fixed stream's of its chosen order (one projection serves
 * both); chosen orders are candidates; a tolerance of +inf gives order 1
 * everywhere and a tiny one the order of least error, which is not order
 * 1 everywhere next to a box; 1 and 2 threads, and a range, agree bit for
 * bit; a method without a log distance is refused. Method decision's
 * stream is its own: chosen and refitted by the decision loss (below). */
static void test_adaptive_order(void)
{
    vb_mesh occ = {0}, rec = {0};
    test_make_box(&occ, 1, 2, 1);
    enum { NP = 160, CAP = 9 };
    float p[3 * NP], n[3 * NP];
    uint64_t s = 17;
    for (int i = 0; i < NP; i++) {
        double r = 1.2 + 10.0 * test_rand(&s), a = 6.283185307 * test_rand(&s);
        p[3 * i] = (float)(r * cos(a)), p[3 * i + 1] = 0.0f, p[3 * i + 2] = (float)(r * sin(a));
        n[3 * i] = 0.0f, n[3 * i + 1] = 1.0f, n[3 * i + 2] = 0.0f;
    }
    test_make_points(&rec, NP, p, n);
    vb_error err;
    vb_scene *sc = NULL;
    CHECK(vb_scene_create(&occ, NULL, &sc, &err) == VB_OK, "scene");
    const float tols[3] = {0.01f, INFINITY, 1e-30f};
    vb_bake_output b[3] = {{0}}, two = {0}, part = {0};
    uint32_t mask = 0;
    for (int k = 1; k <= CAP; k++)
        if (vb_order_candidate(k, CAP))
            mask |= 1u << k;
    for (int i = 0; i < 3 && sc; i++) {
        /* Method shadow: its fixed orders are the lsq fits the adaptive
         * order chooses among (method decision refits its fixed orders). */
        vb_bake_desc d = {.keep_normals = 1,
                          .receivers = &rec,
                          .scene = sc,
                          .rays = 400,
                          .seed = 5,
                          .threads = 1,
                          .order_mask = mask,
                          .method = VB_METHOD_SHADOW,
                          .order_tolerance = tols[i],
                          .variable_cap = CAP};
        CHECK(vb_bake_run(&d, &b[i], &err) == VB_OK, "bake %d: %s", i, err.msg);
        if (i == 0) {
            d.threads = 2;
            CHECK(vb_bake_run(&d, &two, &err) == VB_OK, "2 threads: %s", err.msg);
            d.range_begin = 37, d.range_end = 101;
            CHECK(vb_bake_run(&d, &part, &err) == VB_OK, "range: %s", err.msg);
            d.range_begin = d.range_end = 0;
            d.method = VB_METHOD_PAPER;
            vb_bake_output x = {0};
            CHECK(vb_bake_run(&d, &x, &err) == VB_ERR_ARGUMENT &&
                      strstr(err.msg, "adaptive order fits the log distance"),
                  "paper: %s", err.msg);
        }
        if (i == 2) {
            /* Method decision (issue 25): the variable-order stream is the
             * decision's. Each receiver's order is chosen by the decision
             * loss of the lsq candidates, not shadow's error, and the chosen
             * order is refitted to the decision: its coefficients (past c0,
             * where the offsets go) lie nearer the fixed decision fit of
             * that order than the lsq fit it started from. At the least
             * loss (tolerance 1e-30: orders above 1). 2 and 1 threads,
             * and a range, give the same rows. */
            vb_bake_output dw = {0}, dr = {0}, d1 = {0};
            d.method = VB_METHOD_DECISION;
            CHECK(vb_bake_run(&d, &d1, &err) == VB_OK, "decision, 1 thread: %s", err.msg);
            d.threads = 2;
            CHECK(vb_bake_run(&d, &dw, &err) == VB_OK, "decision: %s", err.msg);
            d.range_begin = 37, d.range_end = 101;
            CHECK(vb_bake_run(&d, &dr, &err) == VB_OK, "decision, range: %s", err.msg);
            d.range_begin = d.range_end = 0;
            if (dw.variable_orders && dr.variable_orders && d1.variable_orders) {
                CHECK(dw.variable_method == VDSH_METHOD_DECISION &&
                          dw.method == VDSH_METHOD_DECISION,
                      "decision: variable stream %s", vdsh_method_name(dw.variable_method));
                int differ = 0, fitted = 0, nearer = 0;
                for (uint32_t v = 0; v < NP; v++) {
                    int k = dw.variable_orders[v];
                    differ += b[2].variable_orders && k != b[2].variable_orders[v];
                    if (k < 2 || !dw.coeffs[k] || !b[0].coeffs[k])
                        continue;
                    const float *c = dw.variable_coeffs + (size_t)v * CAP * CAP;
                    const float *dec = dw.coeffs[k] + (size_t)v * k * k;
                    const float *lsq = b[0].coeffs[k] + (size_t)v * k * k;
                    double to_dec = 0.0, to_lsq = 0.0;
                    for (int j = 1; j < k * k; j++) {
                        to_dec += ((double)c[j] - dec[j]) * ((double)c[j] - dec[j]);
                        to_lsq += ((double)c[j] - lsq[j]) * ((double)c[j] - lsq[j]);
                    }
                    fitted++;
                    nearer += to_dec < to_lsq;
                }
                printf("decision adaptive order: %d of %d receivers at another order than "
                       "shadow's; %d of %d fits nearer the decision fit\n",
                       differ, NP, nearer, fitted);
                CHECK(differ > 0, "decision: the adaptive order is shadow's everywhere");
                CHECK(fitted > 0 && nearer * 10 >= fitted * 9,
                      "decision: %d of %d adaptive fits nearer the decision fit than the lsq fit",
                      nearer, fitted);
                CHECK(memcmp(dw.variable_orders, d1.variable_orders, NP) == 0 &&
                          memcmp(dw.variable_coeffs, d1.variable_coeffs,
                                 (size_t)NP * CAP * CAP * 4) == 0,
                      "decision: 1 and 2 threads differ");
                CHECK(memcmp(dw.variable_orders + 37, dr.variable_orders, 64) == 0 &&
                          memcmp(dw.variable_coeffs + (size_t)37 * CAP * CAP, dr.variable_coeffs,
                                 (size_t)64 * CAP * CAP * 4) == 0 &&
                          memcmp(dw.coeffs[CAP] + (size_t)37 * CAP * CAP, dr.coeffs[CAP],
                                 (size_t)64 * CAP * CAP * 4) == 0,
                      "decision: a range's rows differ from the whole bake's");
            }
            vb_bake_output_free(&d1);
            vb_bake_output_free(&dw);
            vb_bake_output_free(&dr);
        }
    }
    int hist[3][VDSH_ORDER_SLOTS] = {{0}}, bad = 0;
    for (int i = 0; i < 3; i++) {
        if (!b[i].variable_orders)
            continue;
        CHECK(b[i].variable_cap == CAP && b[i].order_tolerance == tols[i], "recorded");
        for (uint32_t v = 0; v < NP; v++) {
            int k = b[i].variable_orders[v];
            hist[i][k]++;
            bad += !vb_order_candidate(k, CAP) || !b[i].coeffs[k];
            if (b[i].coeffs[k]) {
                const float *c = b[i].variable_coeffs + (size_t)v * CAP * CAP;
                bad += memcmp(c, b[i].coeffs[k] + (size_t)v * k * k, (size_t)k * k * 4) != 0;
                for (int j = k * k; j < CAP * CAP; j++)
                    bad += c[j] != 0.0f;
            }
        }
    }
    CHECK(bad == 0, "%d receivers: not a candidate order or not its fixed fit", bad);
    CHECK(hist[1][1] == NP, "tolerance inf: %d of %d at order 1", hist[1][1], NP);
    long coef[3] = {0, 0, 0}; /* a larger tolerance never buys more coefficients */
    for (int i = 0; i < 3; i++)
        for (int k = 1; k <= CAP; k++)
            coef[i] += (long)hist[i][k] * k * k;
    CHECK(coef[2] >= coef[0] && coef[0] > coef[1] && hist[2][CAP] > 0,
          "coefficients: %ld at least error, %ld at 0.01, %ld at inf", coef[2], coef[0], coef[1]);
    int low = 0, high = 0; /* the tolerance spends coefficients where they help */
    for (int k = 1; k <= CAP; k++) {
        if (k <= 3)
            low += hist[0][k];
        else
            high += hist[0][k];
    }
    CHECK(low > 0 && high > 0, "tolerance 0.01: %d receivers at orders 1-3, %d above", low, high);
    if (b[0].variable_orders && two.variable_orders && part.variable_orders) {
        CHECK(memcmp(b[0].variable_orders, two.variable_orders, NP) == 0 &&
                  memcmp(b[0].variable_coeffs, two.variable_coeffs, (size_t)NP * CAP * CAP * 4) ==
                      0,
              "1 and 2 threads differ");
        CHECK(memcmp(b[0].variable_orders + 37, part.variable_orders, 64) == 0 &&
                  memcmp(b[0].variable_coeffs + (size_t)37 * CAP * CAP, part.variable_coeffs,
                         (size_t)64 * CAP * CAP * 4) == 0,
              "a range's rows differ from the whole bake's");
    }
    for (int i = 0; i < 3; i++)
        vb_bake_output_free(&b[i]);
    vb_bake_output_free(&two);
    vb_bake_output_free(&part);
    vb_scene_destroy(sc);
    test_mesh_free(&occ);
    test_mesh_free(&rec);
}

/* A 4 x 3 x 2.5 room with a 0.6 x 0.6 pillar at its centre, 3 high: four
 * quads facing out (the decision fit's neighbour and offset-cap tests). */
static void test_make_pillar_room(vb_mesh *occ)
{
    test_make_room(occ, 4, 3, 2.5f);
    const float w = 0.3f, h = 3.0f;
    const float px0[4][3] = {{-w, 0, -w}, {-w, 0, w}, {-w, h, w}, {-w, h, -w}};
    const float px1[4][3] = {{w, 0, -w}, {w, h, -w}, {w, h, w}, {w, 0, w}};
    const float pz0[4][3] = {{-w, 0, -w}, {-w, h, -w}, {w, h, -w}, {w, 0, -w}};
    const float pz1[4][3] = {{-w, 0, w}, {w, 0, w}, {w, h, w}, {-w, h, w}};
    const float nx[3] = {-1, 0, 0}, pxn[3] = {1, 0, 0}, nz[3] = {0, 0, -1}, pzn[3] = {0, 0, 1};
    test_add_quad(occ, px0, nx);
    test_add_quad(occ, px1, pxn);
    test_add_quad(occ, pz0, nz);
    test_add_quad(occ, pz1, pzn);
}

/* Method decision: receivers a millimetre apart on a floor, lit by the
 * same free space, get nearly the same fit. The fit of ln D to the shadow
 * decision must not add noise of its own between neighbours beyond the
 * least-squares fit's ray noise (method shadow: the same rays, the same
 * offset for every receiver): a pool start per receiver gave each its own
 * training lights, and drew order 12 mottled on lit walls
 * (docs/ACCURACY.md, "Order 12 mottling"). */
static void test_decision_neighbours(void)
{
    vb_mesh occ = {0}, rec = {0};
    test_make_pillar_room(&occ);
    enum { NP = 24, O = 7 };
    float p[3 * 2 * NP], n[3 * 2 * NP];
    uint64_t s = 23;
    for (int i = 0; i < NP; i++) {
        float x, z;
        do {
            x = (float)(7.0 * test_rand(&s) - 3.5), z = (float)(4.0 * test_rand(&s) - 2.0);
        } while (fabsf(x) < 0.6f && fabsf(z) < 0.6f);
        for (int k = 0; k < 2; k++) {
            float *q = p + 3 * (2 * i + k), *m = n + 3 * (2 * i + k);
            q[0] = x + 0.001f * (float)k, q[1] = 0.0f, q[2] = z;
            m[0] = 0.0f, m[1] = 1.0f, m[2] = 0.0f;
        }
    }
    test_make_points(&rec, 2 * NP, p, n);
    vb_error err;
    vb_scene *sc = NULL;
    CHECK(vb_scene_create(&occ, NULL, &sc, &err) == VB_OK, "scene: %s", err.msg);
    /* RMS over the pairs and directions above the horizon of the
     * difference of the two fits' ln D. */
    double diff[2] = {0, 0};
    const vb_method methods[2] = {VB_METHOD_SHADOW, VB_METHOD_DECISION};
    for (int mi = 0; mi < 2 && sc; mi++) {
        vb_bake_desc d = {.keep_normals = 1,
                          .receivers = &rec,
                          .scene = sc,
                          .rays = 2500,
                          .seed = 5,
                          .threads = 2,
                          .order_mask = 1u << O,
                          .method = methods[mi]};
        vb_bake_output out = {0};
        CHECK(vb_bake_run(&d, &out, &err) == VB_OK, "%s: %s", mi ? "decision" : "shadow", err.msg);
        if (out.coeffs[O]) {
            if (mi)
                CHECK(out.decision_fitted > 0, "decision: no receiver fitted");
            double se = 0.0;
            int cnt = 0;
            uint64_t r = 41;
            for (int i = 0; i < NP; i++)
                for (int k = 0; k < 200; k++) {
                    float dir[3];
                    test_rand_dir(&r, dir);
                    if (dir[1] < 0.0f)
                        dir[1] = -dir[1];
                    double a = vdsh_sh_reconstruct(O, out.coeffs[O] + O * O * (2 * i), dir);
                    double b = vdsh_sh_reconstruct(O, out.coeffs[O] + O * O * (2 * i + 1), dir);
                    se += (a - b) * (a - b);
                    cnt++;
                }
            diff[mi] = sqrt(se / cnt);
        }
        vb_bake_output_free(&out);
    }
    printf("neighbours' ln D, RMS difference at order %d: shadow %.4f, decision %.4f\n", O, diff[0],
           diff[1]);
    CHECK(diff[0] > 0.0, "shadow: neighbours' fits are equal (no ray noise to compare with)");
    CHECK(diff[1] <= 2.0 * diff[0],
          "decision: neighbours' fits differ by %.4f, more than twice the lsq fit's %.4f", diff[1],
          diff[0]);
    vb_scene_destroy(sc);
    test_mesh_free(&occ);
    test_mesh_free(&rec);
}

/* The per-receiver offset cap (issue 25, vb_bake_desc.offset_cap):
 * receivers on the floor of a room with a pillar, more than the
 * calibration sample. Without the cap the calibrated offset turns some receivers' lit
 * training pairs false; with it (strict, and with a tolerance) none
 * beyond the tolerance, some receivers' offsets raised, and the global
 * offset recalibrated through the caps no higher than without them;
 * 1 and 2 threads give the same coefficients; a cap on another method
 * is refused. */
static void test_offset_cap(void)
{
    vb_mesh occ = {0}, rec = {0};
    test_make_pillar_room(&occ);
    enum { NP = 1200, O = 5 };
    float *p = malloc(sizeof(float) * 3 * NP), *n = malloc(sizeof(float) * 3 * NP);
    uint64_t s = 29;
    for (int i = 0; p && n && i < NP; i++) {
        float x, z;
        do {
            x = (float)(7.0 * test_rand(&s) - 3.5), z = (float)(4.0 * test_rand(&s) - 2.0);
        } while (fabsf(x) < 0.4f && fabsf(z) < 0.4f);
        p[3 * i] = x, p[3 * i + 1] = 0.0f, p[3 * i + 2] = z;
        n[3 * i] = 0.0f, n[3 * i + 1] = 1.0f, n[3 * i + 2] = 0.0f;
    }
    CHECK(p && n, "out of memory");
    if (!p || !n)
        return;
    test_make_points(&rec, NP, p, n);
    vb_error err;
    vb_scene *sc = NULL;
    CHECK(vb_scene_create(&occ, NULL, &sc, &err) == VB_OK, "scene: %s", err.msg);
    /* none, strict, tolerance 0.2, strict on 1 thread */
    vb_bake_output b[4] = {{0}};
    const float tol[4] = {0.0f, 0.0f, 0.2f, 0.0f};
    for (int i = 0; i < 4 && sc; i++) {
        vb_bake_desc d = {.keep_normals = 1,
                          .receivers = &rec,
                          .scene = sc,
                          .rays = 400,
                          .seed = 7,
                          .threads = i == 3 ? 1 : 2,
                          .order_mask = 1u << O,
                          .method = VB_METHOD_DECISION,
                          .offset_cap = i > 0,
                          .offset_cap_tol = tol[i]};
        CHECK(vb_bake_run(&d, &b[i], &err) == VB_OK, "bake %d: %s", i, err.msg);
    }
    if (b[0].coeffs[O] && b[1].coeffs[O] && b[2].coeffs[O] && b[3].coeffs[O]) {
        printf("offset cap: offsets %+.3f / %+.3f / %+.3f; lit training pairs turned false "
               "%llu / %llu / %llu of %llu; offsets raised %llu / %llu\n",
               (double)b[0].log_offset[O], (double)b[1].log_offset[O], (double)b[2].log_offset[O],
               (unsigned long long)b[0].lit_training_false,
               (unsigned long long)b[1].lit_training_false,
               (unsigned long long)b[2].lit_training_false, (unsigned long long)b[0].lit_training,
               (unsigned long long)b[1].cap_bound, (unsigned long long)b[2].cap_bound);
        CHECK(b[0].log_offset[O] < 0.0f && b[0].lit_training > 0 && b[0].lit_training_false > 0 &&
                  b[0].cap_bound == 0,
              "without the cap the offset (%g) turns no lit training pair false",
              (double)b[0].log_offset[O]);
        for (int i = 1; i <= 2; i++) {
            CHECK(b[i].lit_training == b[0].lit_training, "cap %d: other training pairs", i);
            CHECK(b[i].lit_training_false == 0,
                  "cap %d: %llu lit training pairs in shadow by more than %g", i,
                  (unsigned long long)b[i].lit_training_false, (double)tol[i]);
            CHECK(b[i].cap_bound > 0, "cap %d: no receiver's offset raised", i);
            CHECK(b[i].log_offset[O] <= b[0].log_offset[O],
                  "cap %d: the recalibrated offset %g is above the uncapped %g", i,
                  (double)b[i].log_offset[O], (double)b[0].log_offset[O]);
        }
        CHECK(memcmp(b[1].coeffs[O], b[3].coeffs[O], sizeof(float) * NP * O * O) == 0 &&
                  b[1].log_offset[O] == b[3].log_offset[O],
              "cap: 1 and 2 threads differ");
        CHECK(memcmp(b[0].coeffs[O], b[1].coeffs[O], sizeof(float) * NP * O * O) != 0,
              "cap: the coefficients are the uncapped ones");
    }
    vb_bake_desc bad = {
        .receivers = &rec, .scene = sc, .method = VB_METHOD_SHADOW, .offset_cap = 1};
    vb_bake_output none = {0};
    CHECK(sc && vb_bake_run(&bad, &none, &err) == VB_ERR_ARGUMENT && strstr(err.msg, "offset cap"),
          "a cap on method shadow is refused");
    for (int i = 0; i < 4; i++)
        vb_bake_output_free(&b[i]);
    vb_scene_destroy(sc);
    test_mesh_free(&occ);
    test_mesh_free(&rec);
    free(p);
    free(n);
}

int main(void)
{
    test_grid();
    test_offset_normals();
    test_sphere_centre();
    test_box_floor();
    test_threads();
    test_shadow_offset();
    test_nested_grid();
    test_adaptive_rays();
    test_ranges();
    test_adaptive_order();
    test_decision_neighbours();
    test_offset_cap();
    return test_report("test_bake");
}
