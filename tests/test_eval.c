/*
 * test_eval.c - the evaluator (bake/eval/eval.h) against analytic truth and
 * against itself. Scenes are generated here or are builtin:room, with small
 * ray counts, so the test needs no files and runs in seconds.
 *
 *   sphere      inside a closed sphere the error is ~0 at every order with
 *               method full, and what the analytic zonal projection of
 *               R * step(w.n) predicts with method paper
 *   room        on the built-in room, order 5 beats 3 beats 2 in distance
 *               RMS; doubling the rays does not raise the error beyond
 *               noise
 *   oracle      the truth scored against itself: every error exactly 0, and
 *               the lights fall as designed (47% truly visible, 26% with
 *               s_ideal < 0.5)
 *   threads     1 and 2 threads give bit-identical results
 *   held-out    the evaluator's directions are never the bake's, even with
 *               the bake's seed, and lie above the horizon
 *   interpolate interior coefficients are the barycentric mix of the decoded
 *               vertex coefficients (f32 and f16); interior points are inside
 *               their triangles and area-weighted
 *   sources     a source whose hash differs is rejected, naming it
 *   lights      the light region (vdsh_light.h): a scene with room (the
 *               built-in room) keeps its bounds, and its lights are the
 *               candidates in the bounds that pass, as before the region
 *               (a copy of that loop here), by every rule; a closed box
 *               fills its bounds: the region is the bounds grown by a
 *               quarter of the diagonal, every rule places its lights
 *               there, outside the box, in free space, within a few
 *               thousand candidates, the same on 1 and 2 threads' bakes;
 *               the decision fit runs on the box (its lights > 0)
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "eval.h"
#include "mesh.h"
#include "sampling.h"
#include "scene.h"
#include "test_util.h"
#include "vdsh.h"
#include "vdsh_light.h"
#include "vdsh_sh.h"
#include "vdsh_shadow.h"

/* ---- fixtures ------------------------------------------------------------ */

static void mesh_alloc(vb_mesh *m, uint32_t nv, uint32_t nt)
{
    m->vertex_count = nv;
    m->triangle_count = nt;
    m->positions = calloc(3 * (size_t)nv + 1, sizeof(float));
    m->normals = calloc(3 * (size_t)nv + 1, sizeof(float));
    m->indices = calloc(3 * (size_t)nt + 1, sizeof(uint32_t));
}

/* UV sphere of radius r around c (chord error below 1e-3 r). */
static void make_sphere(vb_mesh *m, float r, const float c[3])
{
    enum { NT = 96, NP = 192 };
    mesh_alloc(m, (NT + 1) * NP, 2 * NT * NP);
    for (int i = 0; i <= NT; i++)
        for (int j = 0; j < NP; j++) {
            double th = M_PI * i / NT, ph = 2 * M_PI * j / NP;
            float d[3] = {(float)(sin(th) * cos(ph)), (float)(sin(th) * sin(ph)), (float)cos(th)};
            for (int k = 0; k < 3; k++) {
                m->positions[3 * (i * NP + j) + k] = c[k] + r * d[k];
                m->normals[3 * (i * NP + j) + k] = -d[k];
            }
        }
    uint32_t t = 0;
    for (int i = 0; i < NT; i++)
        for (int j = 0; j < NP; j++) {
            uint32_t a = i * NP + j, b = i * NP + (j + 1) % NP;
            uint32_t q[6] = {a, b, a + NP, b, b + NP, a + NP};
            memcpy(m->indices + 3 * t, q, sizeof q);
            t += 2;
        }
}

/* A tiny octahedron of radius s around c: six receivers with the six axis
 * normals, and eight triangles for interior points. */
static void make_octahedron(vb_mesh *m, float s, const float c[3])
{
    mesh_alloc(m, 6, 8);
    for (int i = 0; i < 6; i++) {
        float d[3] = {0, 0, 0};
        d[i / 2] = (i & 1) ? -1.0f : 1.0f;
        for (int k = 0; k < 3; k++) {
            m->positions[3 * i + k] = c[k] + s * d[k];
            m->normals[3 * i + k] = d[k];
        }
    }
    static const uint32_t t[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                     {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    memcpy(m->indices, t, sizeof t);
}

static void free_mesh(vb_mesh *m)
{
    vb_mesh_free(m);
}

/* A .vdsh in memory: receivers, one stream per order from the bake output
 * (in `encoding`), bounds from the scene. Pointers into rec and the owned
 * stream arrays; free with free_file. */
typedef struct memfile {
    vdsh_file f;
    vdsh_stream streams[VDSH_MAX_ORDER];
    void *data[VDSH_MAX_ORDER];
} memfile;

static void make_file(memfile *mf, const vb_mesh *rec, const vb_scene *s, const vb_bake_output *b,
                      vb_method method, uint32_t encoding, const int *orders, int norders)
{
    memset(mf, 0, sizeof *mf);
    vdsh_file *f = &mf->f;
    f->header.vertex_count = rec->vertex_count;
    f->header.triangle_count = rec->triangle_count;
    f->header.rays = b->rays;
    f->header.max_distance = b->max_distance;
    f->header.occluder_vertex_count = s->vertex_count;
    f->header.occluder_triangle_count = s->triangle_count;
    f->header.offset_rule = VDSH_OFFSET_WB_AVG;
    memcpy(f->header.bounds_min, s->bounds_min, sizeof f->header.bounds_min);
    memcpy(f->header.bounds_max, s->bounds_max, sizeof f->header.bounds_max);
    f->positions = rec->positions;
    f->normals = rec->normals;
    f->indices = rec->indices;
    /* The streams exactly as vdsh-bake writes them (vb_bake_stream). */
    for (int i = 0; i < norders; i++) {
        vb_error err;
        CHECK(vb_bake_stream(b, orders[i], encoding, &mf->streams[i], &mf->data[i], &err) == VB_OK,
              "stream of order %d: %s", orders[i], err.msg);
        mf->streams[i].method = vb_method_get(method)->stored;
    }
    f->stream_count = (uint32_t)norders;
    f->streams = mf->streams;
}

static void free_file(memfile *mf)
{
    for (int i = 0; i < VDSH_MAX_ORDER; i++)
        free(mf->data[i]);
    memset(mf, 0, sizeof *mf);
}

static int bake(const vb_mesh *rec, const vb_scene *s, vb_method method, uint32_t rays,
                uint64_t seed, vb_bake_output *out)
{
    vb_error err;
    vb_bake_desc d = {.keep_normals = 1,
                      .receivers = rec,
                      .scene = s,
                      .rays = rays,
                      .seed = seed,
                      .method = method,
                      .threads = 2,
                      .order_mask = (1u << 2) | (1u << 3) | (1u << 5)};
    vb_result r = vb_bake_run(&d, out, &err);
    if (r != VB_OK)
        fprintf(stderr, "bake: %s\n", err.msg);
    return r == VB_OK;
}

static int evaluate(const vdsh_file *f, const vb_scene *s, vb_eval_desc d, vb_eval_result *out)
{
    vb_error err;
    d.file = f;
    d.scene = s;
    if (d.threads == 0)
        d.threads = 2;
    vb_result r = vb_eval_run(&d, out, &err);
    if (r != VB_OK)
        fprintf(stderr, "eval: %s\n", err.msg);
    return r == VB_OK;
}

static int scene_from(const vb_mesh *occ, vb_scene **s)
{
    vb_error err;
    vb_scene_desc sd = {.robust = 1};
    if (vb_scene_create(occ, &sd, s, &err) != VB_OK) {
        fprintf(stderr, "scene: %s\n", err.msg);
        return 0;
    }
    return 1;
}

/* The built-in room, refined to `edge`: occluders and receivers. */
static int room(float edge, vb_mesh *occ, vb_mesh *rec)
{
    vb_error err;
    if (vb_mesh_load("builtin:room", NULL, occ, NULL, &err) != VB_OK ||
        vb_mesh_refine(occ, edge, rec, &err) != VB_OK) {
        fprintf(stderr, "room: %s\n", err.msg);
        return 0;
    }
    return 1;
}

/* room() and its scene; a failed check when either fails. */
static int room_scene(float edge, vb_mesh *occ, vb_mesh *rec, vb_scene **s)
{
    if (!room(edge, occ, rec) || !scene_from(occ, s)) {
        CHECK(0, "room fixture");
        return 0;
    }
    return 1;
}

/* Frees what room_scene (or a test's own scene) made. */
static void free_scene(vb_scene *s, vb_mesh *occ, vb_mesh *rec)
{
    vb_scene_destroy(s);
    free_mesh(occ);
    free_mesh(rec);
}

/* Frees n evaluations with their files and bakes. */
static void free_runs(int n, vb_eval_result *r, memfile *mf, vb_bake_output *b)
{
    for (int i = 0; i < n; i++) {
        vb_eval_result_free(&r[i]);
        free_file(&mf[i]);
        vb_bake_output_free(&b[i]);
    }
}

/* ---- analytic: the paper fit at the centre of a sphere ------------------- */

static float ramp(double x)
{
    return vdsh_ramp((float)x);
}

/* D(z) / R for the paper fit of R * step(z) at order n (zonal projection;
 * negative sums count as 0, like vdsh_stream_distance). */
static double paper_zonal(int n, double z)
{
    double c[5] = {0};
    const int N = 4000;
    for (int l = 0; l < n; l++) {
        double sum = 0.0;
        for (int i = 0; i <= N; i++) {
            double zz = (double)i / N, r = sqrt(fmax(0.0, 1 - zz * zz));
            float d[3] = {(float)r, 0.0f, (float)zz}, y[25];
            vdsh_sh_eval(5, d, y);
            sum += ((i == 0 || i == N) ? 1 : (i % 2 ? 4 : 2)) * y[l * (l + 1)];
        }
        c[l] = 2 * M_PI * sum / (3.0 * N);
    }
    double r = sqrt(fmax(0.0, 1 - z * z));
    float d[3] = {(float)r, 0.0f, (float)z}, y[25];
    vdsh_sh_eval(5, d, y);
    double f = 0.0;
    for (int l = 0; l < n; l++)
        f += c[l] * y[l * (l + 1)];
    return f > 0 ? f : 0.0;
}

/* Expected distance RMS and shadow MAE over the upper hemisphere (z
 * uniform in (0, 1]) and the lights (u uniform in (0.05, 1]). */
static void paper_expect(int n, double *rms, double *mae)
{
    const int NZ = 400, NU = 400;
    double se = 0.0, ae = 0.0;
    for (int i = 0; i < NZ; i++) {
        double z = (i + 0.5) / NZ, f = paper_zonal(n, z);
        se += (f - 1) * (f - 1);
        for (int j = 0; j < NU; j++) {
            double u = 0.05 + 0.95 * (j + 0.5) / NU;
            ae += fabs(ramp(f / (2 * u)) - ramp(1 / (2 * u)));
        }
    }
    *rms = sqrt(se / NZ);
    *mae = ae / ((double)NZ * NU);
}

static void test_sphere(void)
{
    const float R = 3.0f, c[3] = {0.5f, -1.0f, 2.0f};
    vb_mesh occ = {0}, rec = {0};
    vb_scene *s = NULL;
    make_sphere(&occ, R, c);
    make_octahedron(&rec, 1e-3f * R, c);
    if (!scene_from(&occ, &s))
        goto out;
    const int orders[3] = {2, 3, 5};
    static const vb_method sphere_methods[2] = {VB_METHOD_PAPER, VB_METHOD_FULL};
    for (int k_m = 0; k_m < 2; k_m++) {
        const vb_method method = sphere_methods[k_m];
        vb_bake_output b = {0};
        memfile mf;
        vb_eval_result r = {0};
        CHECK(bake(&rec, s, method, 2500, 3, &b), "bake");
        if (!b.coeffs[5])
            continue;
        make_file(&mf, &rec, s, &b, method, VDSH_ENCODING_F32, orders, 3);
        vb_eval_desc d = {.directions = 1024, .interior = 64};
        CHECK(evaluate(&mf.f, s, d, &r), "evaluate");
        if (!r.metrics[0])
            goto next;
        for (int k = 0; k < VB_EVAL_KINDS; k++) {
            CHECK(r.truth[k].escaped == 0, "%llu truth rays escaped a closed sphere",
                  (unsigned long long)r.truth[k].escaped);
            CHECK(r.truth[k].degenerate == 0, "degenerate receivers inside a sphere");
        }
        CHECK(r.truth[0].receivers == 6 && r.truth[1].receivers == 64, "receivers %u %u",
              r.truth[0].receivers, r.truth[1].receivers);
        for (int i = 0; i < 3; i++) {
            const vb_eval_metrics *mv = &r.metrics[VB_EVAL_VERTICES][i];
            const vb_eval_metrics *mi = &r.metrics[VB_EVAL_INTERIOR][i];
            if (method == VB_METHOD_FULL) {
                /* D = R everywhere: only the bake's sampling noise is left
                 * (it grows with the band: about 1% RMS at order 5). */
                const double bound[3] = {0.01, 0.01, 0.02};
                printf("sphere full order %d: distance RMS %.5f / %.5f, shadow MAE %.5f / %.5f\n",
                       orders[i], mv->distance_rms, mi->distance_rms, mv->shadow_mae,
                       mi->shadow_mae);
                CHECK(mv->distance_rms < bound[i] && mi->distance_rms < bound[i],
                      "full, order %d: distance RMS %g (vertices), %g (interior)", orders[i],
                      mv->distance_rms, mi->distance_rms);
                CHECK(mv->shadow_mae < 0.01 && mi->shadow_mae < 0.01,
                      "full, order %d: shadow MAE %g, %g", orders[i], mv->shadow_mae,
                      mi->shadow_mae);
                CHECK(mv->false_shadow < 0.02 && mv->light_leak < 0.02,
                      "full, order %d: false %g, leak %g", orders[i], mv->false_shadow,
                      mv->light_leak);
            } else {
                /* The paper fit of R * step(w.n): known in closed form. */
                double rms, mae;
                paper_expect(orders[i], &rms, &mae);
                printf("sphere paper order %d: distance RMS %.4f (analytic %.4f), shadow "
                       "MAE %.4f (analytic %.4f)\n",
                       orders[i], mv->distance_rms, rms, mv->shadow_mae, mae);
                CHECK(fabs(mv->distance_rms - rms) < 0.03 * rms + 0.003,
                      "paper, order %d: distance RMS %g, analytic %g", orders[i], mv->distance_rms,
                      rms);
                CHECK(fabs(mv->shadow_mae - mae) < 0.03 * mae + 0.003,
                      "paper, order %d: shadow MAE %g, analytic %g", orders[i], mv->shadow_mae,
                      mae);
            }
        }
    next:
        vb_eval_result_free(&r);
        free_file(&mf);
        vb_bake_output_free(&b);
    }
out:
    free_scene(s, &occ, &rec);
}

/* ---- the room ------------------------------------------------------------ */

static void test_room(void)
{
    vb_mesh occ = {0}, rec = {0};
    vb_scene *s = NULL;
    if (!room_scene(1.0f, &occ, &rec, &s))
        goto out;
    const int orders[3] = {2, 3, 5};
    vb_bake_output b[3] = {{0}};
    memfile mf[3];
    vb_eval_result r[3] = {{0}};
    const uint32_t rays[3] = {256, 512, 1024};
    /* Reconstruction quality: interior points from interpolated
     * coefficients (the renderer's per-vertex paths blend the vertices'
     * own views of the light, which is not a property of the fit). */
    vb_eval_desc d = {.interior = 4096, .interp = 1 + VDSH_INTERP_COEFFICIENTS};
    for (int i = 0; i < 3; i++) {
        CHECK(bake(&rec, s, VB_METHOD_PAPER, rays[i], 11, &b[i]), "bake %u", rays[i]);
        if (!b[i].coeffs[5]) {
            memset(&mf[i], 0, sizeof mf[i]);
            continue;
        }
        make_file(&mf[i], &rec, s, &b[i], VB_METHOD_PAPER, VDSH_ENCODING_F32, orders, 3);
        CHECK(evaluate(&mf[i].f, s, d, &r[i]), "evaluate %u rays", rays[i]);
    }
    if (!r[0].metrics[0] || !r[1].metrics[0] || !r[2].metrics[0])
        goto done;

    /* Order 5 < 3 < 2 in distance RMS, by more than the noise. */
    for (int k = 0; k < VB_EVAL_KINDS; k++) {
        const vb_eval_metrics *m = r[2].metrics[k];
        printf("room %s, 1024 rays: distance RMS order 2 %.4f, 3 %.4f, 5 %.4f (se %.4f)\n",
               k ? "interior" : "vertices", m[0].distance_rms, m[1].distance_rms, m[2].distance_rms,
               m[2].distance_rms_se);
        for (int i = 0; i < 2; i++)
            CHECK(m[i + 1].distance_rms + 2 * m[i + 1].distance_rms_se <
                      m[i].distance_rms - 2 * m[i].distance_rms_se,
                  "%s: order %d RMS %g (se %g) not below order %d's %g (se %g)",
                  k ? "interior" : "vertices", orders[i + 1], m[i + 1].distance_rms,
                  m[i + 1].distance_rms_se, orders[i], m[i].distance_rms, m[i].distance_rms_se);
    }
    /* Doubling the rays never raises the error beyond noise (3 combined
     * standard errors: the runs share receivers and lights, so this is
     * generous). */
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < VB_EVAL_KINDS; k++)
            for (int o = 0; o < 3; o++) {
                const vb_eval_metrics *a = &r[i].metrics[k][o], *c = &r[i + 1].metrics[k][o];
                double tol = 3 * hypot(a->distance_rms_se, c->distance_rms_se);
                CHECK(c->distance_rms <= a->distance_rms + tol,
                      "%u -> %u rays, %s order %d: distance RMS %g -> %g", rays[i], rays[i + 1],
                      k ? "interior" : "vertices", orders[o], a->distance_rms, c->distance_rms);
                tol = 3 * hypot(a->shadow_mae_se, c->shadow_mae_se);
                CHECK(c->shadow_mae <= a->shadow_mae + tol,
                      "%u -> %u rays, %s order %d: shadow MAE %g -> %g", rays[i], rays[i + 1],
                      k ? "interior" : "vertices", orders[o], a->shadow_mae, c->shadow_mae);
            }
    /* A closed room: the robust truth from interior points never escapes. */
    CHECK(r[0].truth[VB_EVAL_INTERIOR].escaped == 0, "%llu interior truth rays escaped",
          (unsigned long long)r[0].truth[VB_EVAL_INTERIOR].escaped);

    /* The interior worst list: positions are the barycentric mix. */
    for (uint32_t w = 0; w < r[0].metrics[VB_EVAL_INTERIOR][2].worst_count; w++) {
        const vb_eval_receiver *x = &r[0].metrics[VB_EVAL_INTERIOR][2].worst[w];
        const uint32_t *ix = rec.indices + 3 * (size_t)x->triangle;
        for (int c = 0; c < 3; c++) {
            float want = x->bary[0] * rec.positions[3 * ix[0] + c] +
                         x->bary[1] * rec.positions[3 * ix[1] + c] +
                         x->bary[2] * rec.positions[3 * ix[2] + c];
            CHECK(fabsf(want - x->position[c]) <= 1e-5f * (1 + fabsf(want)),
                  "worst point %u: position %g, mix %g", x->index, x->position[c], want);
        }
    }
done:
    free_runs(3, r, mf, b);
out:
    free_scene(s, &occ, &rec);
}

/* ---- the fits against each other ------------------------------------------ */

/* On the room, scored by the evaluator on the paths the runtime draws:
 * least squares of the log distance beats the paper's zero-filled
 * projection, and the shadow fit beats both, at every order, on vertices
 * and interior points, each by more than three combined standard errors.
 * (What the fits are for: a fit that regresses fails here.) */
static void test_methods(void)
{
    vb_mesh occ = {0}, rec = {0};
    vb_scene *s = NULL;
    if (!room_scene(0.7f, &occ, &rec, &s))
        goto out;
    const int orders[3] = {2, 3, 5};
    const vb_method methods[3] = {VB_METHOD_PAPER, VB_METHOD_LSQ, VB_METHOD_SHADOW};
    vb_bake_output b[3] = {{0}};
    memfile mf[3];
    vb_eval_result r[3] = {{0}};
    vb_eval_desc ed = {.interior = 8192};
    memset(mf, 0, sizeof mf);
    for (int i = 0; i < 3; i++) {
        vb_error err;
        vb_bake_desc d = {.keep_normals = 1,
                          .receivers = &rec,
                          .scene = s,
                          .rays = 1024,
                          .seed = 5,
                          .method = methods[i],
                          .threads = 2,
                          .quantity = i ? VB_QUANTITY_LOG : VB_QUANTITY_DISTANCE,
                          .order_mask = (1u << 2) | (1u << 3) | (1u << 5)};
        CHECK(vb_bake_run(&d, &b[i], &err) == VB_OK, "bake %s: %s", vb_method_name(methods[i]),
              err.msg);
        if (!b[i].coeffs[5])
            goto done;
        make_file(&mf[i], &rec, s, &b[i], methods[i], VDSH_ENCODING_F16, orders, 3);
        CHECK(evaluate(&mf[i].f, s, ed, &r[i]), "evaluate %s", vb_method_name(methods[i]));
        if (!r[i].metrics[0])
            goto done;
    }
    /* Scored with scene lights (the primary metric): lsq beats paper,
     * and shadow (lsq with the log offset) beats both on MAE and on false
     * shadows, at every order, on vertices and interior points. */
    for (int k = 0; k < VB_EVAL_KINDS; k++)
        for (int o = 0; o < 3; o++) {
            const vb_eval_scene_metrics *m[3] = {&r[0].scene[k][o], &r[1].scene[k][o],
                                                 &r[2].scene[k][o]};
            printf("room %s order %d scene-light MAE / false / recall: paper %.4f %.2f%% %.1f%%, "
                   "lsq+log %.4f %.2f%% %.1f%%, shadow %.4f %.2f%% %.1f%%\n",
                   k ? "interior" : "vertices", orders[o], m[0]->shadow_mae,
                   100 * m[0]->false_shadow, 100 * m[0]->recall, m[1]->shadow_mae,
                   100 * m[1]->false_shadow, 100 * m[1]->recall, m[2]->shadow_mae,
                   100 * m[2]->false_shadow, 100 * m[2]->recall);
            for (int i = 0; i < 2; i++)
                for (int j = i + 1; j < 3; j++) {
                    double tol = 3 * hypot(m[i]->shadow_mae_se, m[j]->shadow_mae_se);
                    CHECK(m[j]->shadow_mae < m[i]->shadow_mae - tol,
                          "%s order %d: %s %g not below %s %g by 3 se (%g)",
                          k ? "interior" : "vertices", orders[o], vb_method_name(methods[j]),
                          m[j]->shadow_mae, vb_method_name(methods[i]), m[i]->shadow_mae, tol);
                }
            /* The MAE's parts by pair class add up to it, and a fit that
             * draws false shadows has a false part. */
            for (int i = 0; i < 3; i++) {
                double sum = 0.0;
                for (int c = 0; c < VB_EVAL_MAE_PARTS; c++) {
                    CHECK(m[i]->mae_part[c] >= 0.0, "%s order %d: part %d is %g",
                          vb_method_name(methods[i]), orders[o], c, m[i]->mae_part[c]);
                    sum += m[i]->mae_part[c];
                }
                CHECK(fabs(sum - m[i]->shadow_mae) < 1e-9 * (1.0 + m[i]->shadow_mae),
                      "%s order %d: parts add up to %.9g, MAE %.9g", vb_method_name(methods[i]),
                      orders[o], sum, m[i]->shadow_mae);
                CHECK((m[i]->false_shadow > 0.0) == (m[i]->mae_part[VB_EVAL_PART_FALSE] > 0.0),
                      "%s order %d: false rate %g, false part %g", vb_method_name(methods[i]),
                      orders[o], m[i]->false_shadow, m[i]->mae_part[VB_EVAL_PART_FALSE]);
            }
            CHECK(m[2]->false_shadow < m[1]->false_shadow &&
                      m[2]->false_shadow < m[0]->false_shadow,
                  "%s order %d: shadow's false shadows %g not below lsq's %g and paper's %g",
                  k ? "interior" : "vertices", orders[o], m[2]->false_shadow, m[1]->false_shadow,
                  m[0]->false_shadow);
        }
done:
    free_runs(3, r, mf, b);
out:
    free_scene(s, &occ, &rec);
}

/* ---- oracle and threads --------------------------------------------------- */

static void test_oracle_and_threads(void)
{
    vb_mesh occ = {0}, rec = {0};
    vb_scene *s = NULL;
    if (!room_scene(1.0f, &occ, &rec, &s))
        goto out;
    const int orders[2] = {3, 5};
    vb_bake_output b = {0};
    memfile mf;
    vb_eval_result one = {0}, two = {0}, oracle = {0};
    CHECK(bake(&rec, s, VB_METHOD_PAPER, 256, 1, &b), "bake");
    if (!b.coeffs[5])
        goto out;
    make_file(&mf, &rec, s, &b, VB_METHOD_PAPER, VDSH_ENCODING_F16, orders, 2);

    vb_eval_desc d = {.interior = 3000, .points = 2000, .per_vertex = 1};
    d.oracle = 1;
    CHECK(evaluate(&mf.f, s, d, &oracle), "oracle");
    for (int k = 0; k < VB_EVAL_KINDS && oracle.metrics[0]; k++)
        for (int i = 0; i < 2; i++) {
            const vb_eval_metrics *m = &oracle.metrics[k][i];
            CHECK(m->distance_rms == 0 && m->distance_p99 == 0 && m->shadow_mae == 0 &&
                      m->false_shadow == 0 && m->light_leak == 0 && m->binary_mae == 0 &&
                      m->binary_false_shadow == 0 && m->binary_light_leak == 0,
                  "oracle %d/%d: errors %g %g %g %g %g %g %g", k, i, m->distance_rms, m->shadow_mae,
                  m->false_shadow, m->light_leak, m->binary_mae, m->binary_false_shadow,
                  m->binary_light_leak);
            /* Lights: P(d_T >= d_L) = P(u <= 1/2) = 0.45 / 0.95, and
             * P(s_ideal < 1/2) = P(u > 3/4) = 0.25 / 0.95. */
            double vis = (double)m->visible / m->samples, occ_ = (double)m->occluded / m->samples;
            CHECK(fabs(vis - 0.45 / 0.95) < 0.01, "visible fraction %g", vis);
            CHECK(fabs(occ_ - 0.25 / 0.95) < 0.01, "occluded fraction %g", occ_);
            CHECK(m->samples == (uint64_t)oracle.truth[k].receivers * 64, "samples %llu",
                  (unsigned long long)m->samples);
        }
    CHECK(oracle.truth[0].receivers == 2000, "vertex sample %u", oracle.truth[0].receivers);
    /* Scene lights: placed in the room's free space (inside the room, off
     * every surface by the clearance); the truth scores itself exactly. */
    CHECK(oracle.light_count == 32 && oracle.lights, "%u scene lights", oracle.light_count);
    for (uint32_t l = 0; l < oracle.light_count; l++) {
        const float *L = oracle.lights[l];
        const float cl = 0.01f * s->diagonal;
        int inside =
            !(L[1] > cl && L[1] < 6.0f - cl && fabsf(L[0]) < 9.5f - cl && fabsf(L[2]) < 9.5f - cl);
        /* Not inside builtin:room's pillars (0.4 m square at (+-5.5,
         * +-5.5), not at (-5.5, -5.5)) or its big crate (bake/lib/builtin.c).
         * (The clearance is checked along the 14 probes only: near a
         * pillar's corner a light may sit a little closer.) */
        const float pillar[3][2] = {{-5.5f, 5.5f}, {5.5f, 5.5f}, {5.5f, -5.5f}};
        for (int q = 0; q < 3; q++)
            inside |= fabsf(L[0] - pillar[q][0]) < 0.2f && fabsf(L[2] - pillar[q][1]) < 0.2f;
        inside |= fabsf(L[0] + 4.0f) < 0.79f && fabsf(L[2] + 3.0f) < 0.79f && L[1] < 1.58f;
        CHECK(!inside, "light %u at %g %g %g is not in the room's free space", l, L[0], L[1], L[2]);
    }
    for (int k = 0; k < VB_EVAL_KINDS && oracle.scene[0]; k++)
        for (int i = 0; i < 2; i++) {
            const vb_eval_scene_metrics *m = &oracle.scene[k][i];
            CHECK(m->pairs > 0 && m->shadow_mae == 0 && m->false_shadow == 0 &&
                      m->light_leak == 0 && m->binary_false_shadow == 0,
                  "oracle scene lights %d/%d: %llu pairs, errors %g %g %g", k, i,
                  (unsigned long long)m->pairs, m->shadow_mae, m->false_shadow, m->light_leak);
            CHECK(m->occluded == 0 || m->recall == 1.0, "oracle recall %g", m->recall);
            for (int c = 0; c < VB_EVAL_MAE_PARTS; c++)
                CHECK(m->mae_part[c] == 0.0, "oracle MAE part %d: %g", c, m->mae_part[c]);
        }

    d.oracle = 0;
    d.threads = 1;
    CHECK(evaluate(&mf.f, s, d, &one), "1 thread");
    d.threads = 2;
    CHECK(evaluate(&mf.f, s, d, &two), "2 threads");
    if (one.metrics[0] && two.metrics[0]) {
        for (int k = 0; k < VB_EVAL_KINDS; k++) {
            CHECK(memcmp(one.metrics[k], two.metrics[k], 2 * sizeof *one.metrics[k]) == 0,
                  "kind %d: 1 and 2 threads differ", k);
            CHECK(memcmp(one.scene[k], two.scene[k], 2 * sizeof *one.scene[k]) == 0,
                  "kind %d: scene lights, 1 and 2 threads differ", k);
            CHECK(memcmp(&one.truth[k], &two.truth[k], sizeof one.truth[k]) == 0,
                  "kind %d: truth differs with threads", k);
        }
        CHECK(memcmp(one.per_vertex, two.per_vertex,
                     (size_t)rec.vertex_count * one.per_vertex_fields * sizeof(float)) == 0,
              "per-vertex errors differ with threads");
        /* The sample: 2000 vertices have values, the rest NaN. */
        uint32_t with = 0;
        for (uint32_t v = 0; v < rec.vertex_count; v++)
            with += !isnan(one.per_vertex[(size_t)v * one.per_vertex_fields + 2]);
        CHECK(with == 2000, "%u vertices with per-vertex values", with);
        CHECK(one.per_vertex_fields == 2 + 5 * 2, "fields %u", one.per_vertex_fields);
        /* The sample is the same set whatever the thread count or stream. */
        CHECK(one.metrics[0][0].shadow_mae > 0.0, "real streams score above 0");
    }
    vb_eval_result_free(&one);
    vb_eval_result_free(&two);
    vb_eval_result_free(&oracle);
    free_file(&mf);
    vb_bake_output_free(&b);
out:
    free_scene(s, &occ, &rec);
}

/* ---- held-out directions --------------------------------------------------- */

static void test_heldout(void)
{
    vb_dirgrid g = {0};
    vb_error err;
    CHECK(vb_dirgrid_create(2500, 0, &g, &err) == VB_OK, "bake grid");
    float *bake_dirs = malloc(3 * 2500 * sizeof *bake_dirs);
    uint64_t rs = 3;
    double mean_nearest = 0.0;
    int count = 0;
    for (int trial = 0; trial < 40; trial++) {
        uint32_t v = (uint32_t)(test_rand(&rs) * 100000);
        float n[3];
        test_rand_dir(&rs, n);
        /* The bake's directions for this vertex (seed 1, the default). */
        uint32_t nb = 0;
        for (uint32_t pk = 0; pk < g.packet_count; pk++) {
            float x[16], y[16], z[16];
            int valid[16];
            vb_dirgrid_packet(&g, pk, 1, v, n, x, y, z, valid);
            for (int k = 0; k < 16; k++)
                if (valid[k]) {
                    bake_dirs[3 * nb] = x[k], bake_dirs[3 * nb + 1] = y[k];
                    bake_dirs[3 * nb + 2] = z[k];
                    nb++;
                }
        }
        /* The evaluator's: default seed, and the bake's own seed. */
        const uint64_t seeds[2] = {0, 1};
        for (int si = 0; si < 2; si++) {
            float e[3 * 64];
            uint32_t ne = vb_eval_directions(seeds[si], 64, v, n, e, 64);
            CHECK(ne == 64, "%u held-out directions", ne);
            for (uint32_t i = 0; i < ne && i < 64; i++) {
                const float *w = e + 3 * i;
                float len = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
                float up = w[0] * n[0] + w[1] * n[1] + w[2] * n[2];
                CHECK(fabsf(len - 1) < 1e-5f && up > -1e-6f, "direction %u: length %g, w.n %g", i,
                      len, up);
                double best = 4.0;
                for (uint32_t j = 0; j < nb; j++) {
                    const float *q = bake_dirs + 3 * j;
                    double dot = (double)w[0] * q[0] + (double)w[1] * q[1] + (double)w[2] * q[2];
                    double a = acos(fmin(1.0, fmax(-1.0, dot)));
                    best = a < best ? a : best;
                }
                CHECK(best > 1e-4, "held-out direction within %g rad of a bake direction", best);
                mean_nearest += best;
                count++;
            }
        }
    }
    /* Independent directions sit on average ~0.5 * sqrt(4 pi / N) from the
     * nearest of N stratified ones; copies would sit at 0. */
    mean_nearest /= count;
    double spacing = sqrt(4 * M_PI / 2500);
    printf("held-out directions: mean angle to the nearest bake direction %.4f rad "
           "(grid spacing %.4f)\n",
           mean_nearest, spacing);
    CHECK(mean_nearest > 0.25 * spacing, "held-out directions hug the bake's: %g", mean_nearest);
    /* Different receivers get different directions; interior ids are apart. */
    float a[3 * 64], b[3 * 64], n[3] = {0, 1, 0};
    vb_eval_directions(0, 64, 5, n, a, 64);
    vb_eval_directions(0, 64, VB_EVAL_INTERIOR_ID(5), n, b, 64);
    CHECK(memcmp(a, b, sizeof a) != 0, "vertex 5 and interior point 5 share directions");
    free(bake_dirs);
    vb_dirgrid_destroy(&g);
}

/* ---- interpolation and interior points ------------------------------------- */

static void test_interpolation(void)
{
    /* Two triangles, areas 1 and 3; random coefficients. */
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 2, 0, 3, 2, 0};
    static const float nrm[12] = {0, 0, 1, 0.6f, 0, 0.8f, 0, 0.6f, 0.8f, 0, 0, 1};
    static const uint32_t tri[6] = {0, 1, 2, 1, 3, 2};
    uint64_t rs = 9;
    float coef[4 * 25];
    for (int i = 0; i < 100; i++)
        coef[i] = (float)(20 * test_rand(&rs) - 5);
    uint16_t half[100];
    CHECK(vdsh_encode_f16(coef, 100, 8.0f, half) == VDSH_OK, "f16");
    vdsh_stream st[2] = {{.order = 5, .encoding = VDSH_ENCODING_F32, .scale = 1.0f, .data = coef},
                         {.order = 5, .encoding = VDSH_ENCODING_F16, .scale = 8.0f, .data = half}};
    vdsh_file f = {0};
    f.header.vertex_count = 4;
    f.header.triangle_count = 2;
    f.positions = pos;
    f.normals = nrm;
    f.indices = tri;
    f.stream_count = 2;
    f.streams = st;

    for (int trial = 0; trial < 200; trial++) {
        uint32_t t = trial & 1;
        double r1 = test_rand(&rs), r2 = test_rand(&rs);
        float bary[3] = {(float)(1 - sqrt(r1)), (float)(sqrt(r1) * (1 - r2)),
                         (float)(sqrt(r1) * r2)};
        for (int si = 0; si < 2; si++) {
            float got[25], p[3], nn[3], ca[25], cb[25], cc[25];
            vb_eval_interpolate(&f, &st[si], t, bary, p, nn, got);
            vdsh_stream_decode(&st[si], tri[3 * t], ca);
            vdsh_stream_decode(&st[si], tri[3 * t + 1], cb);
            vdsh_stream_decode(&st[si], tri[3 * t + 2], cc);
            for (int i = 0; i < 25; i++) {
                double want =
                    (double)bary[0] * ca[i] + (double)bary[1] * cb[i] + (double)bary[2] * cc[i];
                CHECK(fabs(got[i] - want) <= 1e-5 * (1 + fabs(want)),
                      "stream %d coefficient %d: %g, hand mix %g", si, i, got[i], want);
            }
            double nlen = 0.0;
            for (int c = 0; c < 3; c++) {
                double want = bary[0] * pos[3 * tri[3 * t] + c] +
                              bary[1] * pos[3 * tri[3 * t + 1] + c] +
                              bary[2] * pos[3 * tri[3 * t + 2] + c];
                CHECK(fabs(p[c] - want) < 1e-6, "position %g, mix %g", p[c], want);
                nlen += nn[c] * nn[c];
            }
            CHECK(fabs(nlen - 1) < 1e-5, "interpolated normal length^2 %g", nlen);
        }
    }
    /* f16 decodes to the same values the f32 stream holds, to f16 precision:
     * the evaluator sees what a GPU fetching halves sees. */
    float c16[25], c32[25];
    vdsh_stream_decode(&st[1], 3, c16);
    vdsh_stream_decode(&st[0], 3, c32);
    for (int i = 0; i < 25; i++)
        CHECK(fabsf(c16[i] - c32[i]) <= 8.0f * 4.0f / 2048.0f, "f16 %g vs %g", c16[i], c32[i]);

    /* Interior points: inside their triangle, area-weighted (1 : 3). */
    double total = 0.0;
    double *cdf = vb_eval_area_cdf(&f, &total);
    CHECK(cdf && fabs(total - 4.0) < 1e-9, "total area %g", total);
    int in_second = 0;
    const int N = 8000;
    for (int j = 0; j < N && cdf; j++) {
        uint32_t t;
        float b[3];
        CHECK(vb_eval_interior_point(cdf, 2, 77, (uint32_t)j, &t, b), "point %d", j);
        CHECK(b[0] > 0 && b[1] > 0 && b[2] > 0 && fabsf(b[0] + b[1] + b[2] - 1) < 1e-6f,
              "barycentrics %g %g %g", b[0], b[1], b[2]);
        in_second += t == 1;
    }
    double frac = (double)in_second / N;
    CHECK(fabs(frac - 0.75) < 0.02, "%.3f of points in the triangle with 3/4 of the area", frac);
    free(cdf);
}

/* ---- scene reconstruction ---------------------------------------------------- */

static void test_sources(void)
{
    vb_mesh occ = {0};
    vb_source_info info;
    vb_error err;
    if (vb_mesh_load("builtin:room", NULL, &occ, &info, &err) != VB_OK) {
        CHECK(0, "room: %s", err.msg);
        return;
    }
    float lo[3], hi[3];
    vb_mesh_bounds(&occ, lo, hi);
    vdsh_source src = {.name = "builtin:room", .size = info.size};
    memcpy(src.sha256, info.sha256, 32);
    vdsh_file f = {0};
    f.header.occluder_vertex_count = occ.vertex_count;
    f.header.occluder_triangle_count = occ.triangle_count;
    memcpy(f.header.bounds_min, lo, sizeof lo);
    memcpy(f.header.bounds_max, hi, sizeof hi);
    f.source_count = 1;
    f.sources = &src;
    const char *paths[1] = {"builtin:room"};
    vb_scene *s = NULL;
    CHECK(vb_eval_scene_create(&f, paths, 1, NULL, &s, &err) == VB_OK, "matching source: %s",
          err.msg);
    CHECK(s && s->triangle_count == occ.triangle_count, "scene");
    vb_scene_destroy(s);
    s = NULL;

    src.sha256[7] ^= 1;
    vb_result r = vb_eval_scene_create(&f, paths, 1, NULL, &s, &err);
    CHECK(r == VB_ERR_INVALID && !s, "a changed source is accepted");
    CHECK(strstr(err.msg, "source 1 of 1") && strstr(err.msg, "builtin:room") &&
              strstr(err.msg, "SHA-256"),
          "message: %s", err.msg);
    vb_eval_scene_desc sd = {.allow_mismatch = 1};
    CHECK(vb_eval_scene_create(&f, paths, 1, &sd, &s, &err) == VB_OK, "allow_mismatch");
    vb_scene_destroy(s);
    s = NULL;
    src.sha256[7] ^= 1;

    f.header.occluder_triangle_count++;
    CHECK(vb_eval_scene_create(&f, paths, 1, NULL, &s, &err) == VB_ERR_INVALID &&
              strstr(err.msg, "triangles"),
          "count mismatch: %s", err.msg);
    f.header.occluder_triangle_count--;
    CHECK(vb_eval_scene_create(&f, paths, 2, NULL, &s, &err) == VB_ERR_ARGUMENT,
          "wrong number of paths");
    CHECK(!s, "output touched on failure");
    vb_mesh_free(&occ);
}

/* ---- the light region ---------------------------------------------------- */

/* The unit cube [0,1]^3, its faces wound outward: a closed object. */
static void make_cube(vb_mesh *m)
{
    static const uint32_t tri[36] = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                                     2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};
    mesh_alloc(m, 8, 12);
    for (uint32_t i = 0; i < 8; i++)
        for (int a = 0; a < 3; a++) {
            m->positions[3 * i + a] = (float)((i >> a) & 1u);
            m->normals[3 * i + a] = ((i >> a) & 1u ? 1.0f : -1.0f) * 0.57735027f;
        }
    memcpy(m->indices, tri, sizeof tri);
}

/* The placement before the light region: candidates in the bounds, kept
 * when free, 1000 per light; the ceiling rule lifts them to the top fifth. */
static uint32_t place_in_bounds(const vb_scene *s, uint64_t seed, uint32_t count, int ceiling,
                                float (*out)[3])
{
    const float *lo = s->bounds_min, *hi = s->bounds_max;
    uint32_t n = 0, k = 0;
    while (n < count && k < 1000u * count) {
        float p[3];
        vdsh_light_candidate(lo, hi, seed, k++, p);
        if (ceiling) {
            float u = hi[1] > lo[1] ? (p[1] - lo[1]) / (hi[1] - lo[1]) : 0.5f;
            p[1] = lo[1] + (0.8f + 0.2f * u) * (hi[1] - lo[1]);
        }
        if (vb_scene_free_space(s, p))
            memcpy(out[n++], p, sizeof out[0]);
    }
    return n;
}

static void test_lights(void)
{
    enum { N = 256 };
    float(*a)[3] = malloc(N * sizeof *a), (*b)[3] = malloc(N * sizeof *b);
    vb_mesh occ = {0}, rec = {0}, cube = {0};
    vb_scene *s = NULL, *c = NULL;
    vb_error err;
    uint32_t tried = 0;
    if (!a || !b || !room_scene(1.0f, &occ, &rec, &s))
        goto out;
    float lo[3], hi[3];
    CHECK(vb_scene_light_region(s, lo, hi, NULL) == 0, "the room's region is grown");
    CHECK(!memcmp(lo, s->bounds_min, sizeof lo) && !memcmp(hi, s->bounds_max, sizeof hi),
          "the room's region is not its bounds");
    for (int ceiling = 0; ceiling <= 1; ceiling++) {
        const uint64_t seed = 0x5eed + (uint64_t)ceiling;
        CHECK(place_in_bounds(s, seed, N, ceiling, a) == N, "reference placement");
        CHECK(vb_scene_place_lights_rule(s, seed, N,
                                         ceiling ? VB_LIGHTS_CEILING : VB_LIGHTS_UNIFORM, b, NULL,
                                         &err) == VB_OK,
              "room rule %d: %s", ceiling, err.msg);
        CHECK(!memcmp(a, b, N * sizeof *a), "room rule %d: other lights than before", ceiling);
    }
    /* The shell and around rules outside a closed room: no room. Every
     * side of its bounds is closed (vdsh_light_grown_box: a point just
     * outside a wall sees its back), and the rules do not reach past a
     * closed side; they found lights before, far out where no probe
     * met the room, lighting nothing inside it. */
    CHECK(vb_scene_grown_box(s, lo, hi) == 63, "the room's sides are not all closed");
    for (int rule = VB_LIGHTS_AROUND; rule <= VB_LIGHTS_SHELL; rule++) {
        vb_result r = vb_scene_place_lights_rule(s, 0x5e11, N, (vb_light_rule)rule, b, NULL, &err);
        CHECK(r == VB_ERR_INVALID && strstr(err.msg, "no room"), "room %s: %d %s",
              vb_light_rule_name((vb_light_rule)rule), (int)r, err.msg);
    }
    /* A pool's first lights are a smaller pool's (vb_scene_place_pool:
     * the decision fit's and the cpca metric's one placement). */
    float(*big)[3] = malloc(2 * N * sizeof *big);
    int first_ok = 0;
    CHECK(big && vb_scene_place_pool(s, 0x77, 2 * N, big, N, &first_ok, &err) == VB_OK && first_ok,
          "room pool of %d: %s", 2 * N, err.msg);
    CHECK(big && vb_scene_place_lights(s, 0x77, N, a, NULL, &err) == VB_OK &&
              !memcmp(a, big, N * sizeof *a),
          "the pool's first %d lights are not a pool of %d", N, N);
    free(big);
    /* The decision fit's pool placed by the bake, or given (bake desc
     * pool, as vdsh-bake's job places it once): the same fit; another
     * seed's pool given: another fit (the pool is used). */
    float(*pool)[3] = malloc(VB_DECISION_POOL * sizeof *pool);
    vb_bake_output fit[3] = {{0}};
    for (int i = 0; i < 3 && pool; i++) {
        vb_bake_desc d = {.receivers = &rec,
                          .scene = s,
                          .rays = 64,
                          .seed = 3,
                          .threads = 1,
                          .method = VB_METHOD_DECISION,
                          .order_mask = 1u << 3};
        if (i) {
            CHECK(vb_scene_place_pool(s, (i == 1 ? 3 : 4) ^ VB_POOL_SEED, VB_DECISION_POOL, pool, 1,
                                      NULL, &err) == VB_OK,
                  "room pool: %s", err.msg);
            d.pool = &pool[0][0];
            d.pool_count = VB_DECISION_POOL;
        }
        CHECK(vb_bake_run(&d, &fit[i], &err) == VB_OK && fit[i].coeffs[3], "room bake %d: %s", i,
              err.msg);
    }
    const size_t fit_bytes = 9 * (size_t)rec.vertex_count * sizeof(float);
    CHECK(pool && fit[2].coeffs[3] && !memcmp(fit[0].coeffs[3], fit[1].coeffs[3], fit_bytes) &&
              memcmp(fit[0].coeffs[3], fit[2].coeffs[3], fit_bytes),
          "the decision fit with its pool given differs, or another pool changes nothing");
    for (int i = 0; i < 3; i++)
        vb_bake_output_free(&fit[i]);
    free(pool);

    make_cube(&cube);
    if (!scene_from(&cube, &c)) {
        CHECK(0, "cube scene");
        goto out;
    }
    CHECK(place_in_bounds(c, 7, 1, 0, a) == 0, "the cube's bounds hold free space");
    CHECK(vb_scene_light_region(c, lo, hi, NULL) == 1, "the cube's region is its bounds");
    const float g = VDSH_REGION_GROW * c->diagonal;
    for (int k = 0; k < 3; k++)
        CHECK(fabsf(lo[k] - (c->bounds_min[k] - g)) < 1e-5f &&
                  fabsf(hi[k] - (c->bounds_max[k] + g)) < 1e-5f,
              "grown region axis %d: %g..%g", k, (double)lo[k], (double)hi[k]);
    /* ... and the shell (the bounds grown by VDSH_REGION_GROW, outside
     * them): the same box here, the rule's own bounds test. */
    for (int rule = VB_LIGHTS_UNIFORM; rule <= VB_LIGHTS_SHELL; rule++) {
        if (rule > VB_LIGHTS_PATH && rule != VB_LIGHTS_SHELL)
            continue;
        vb_result r = vb_scene_place_lights_rule(c, 0x11 + (uint64_t)rule, N, (vb_light_rule)rule,
                                                 b, &tried, &err);
        CHECK(r == VB_OK, "cube rule %s: %s", vb_light_rule_name((vb_light_rule)rule), err.msg);
        if (r != VB_OK)
            continue;
        CHECK(tried <= VDSH_REGION_TRIES + 4u * N, "cube rule %d: %u candidates", rule, tried);
        for (int l = 0; l < N; l++) {
            int outside = 0, within = 1;
            for (int k = 0; k < 3; k++) {
                outside |= b[l][k] < 0.0f || b[l][k] > 1.0f;
                within &= b[l][k] >= lo[k] && b[l][k] <= hi[k];
            }
            CHECK(outside && within && vb_scene_free_space(c, b[l]),
                  "cube rule %d light %d at (%g, %g, %g)", rule, l, (double)b[l][0],
                  (double)b[l][1], (double)b[l][2]);
        }
    }

    /* A lone triangle (in z = 0, over half its bounds): its region is its
     * plane, where no point is near it along a probe (the probes in the
     * plane pass it edge-on), and the near rule gives up after the first
     * light's candidates find none, not a thousand per light (the bake's
     * 2048 near lights spent 2M candidates, seconds, on one triangle). */
    {
        vb_mesh tri = {0};
        vb_scene *ts = NULL;
        mesh_alloc(&tri, 3, 1);
        static const float tp[9] = {0, 0, 0, 1, 0, 0, 1, 1, 0};
        memcpy(tri.positions, tp, sizeof tp);
        for (int i = 0; i < 3; i++)
            tri.normals[3 * i + 2] = 1.0f, tri.indices[i] = (uint32_t)i;
        if (scene_from(&tri, &ts)) {
            const int grown = vb_scene_light_region(ts, lo, hi, NULL);
            vb_result r = vb_scene_place_lights_rule(ts, 0x3ea, N, VB_LIGHTS_NEAR, b, &tried, &err);
            CHECK(r == VB_ERR_INVALID && strstr(err.msg, "no room"),
                  "lone triangle, near rule: %d %s", (int)r, err.msg);
            CHECK(tried == vdsh_light_tries(1, grown),
                  "lone triangle, near rule: %u candidates tried, not the first light's %llu",
                  tried, (unsigned long long)vdsh_light_tries(1, grown));
        } else
            CHECK(0, "triangle scene");
        vb_scene_destroy(ts);
        vb_mesh_free(&tri);
    }

    /* The decision fit runs on the closed box, the same on 1 and 2 threads. */
    vb_bake_output o[2] = {{0}};
    for (int t = 0; t < 2; t++) {
        vb_bake_desc d = {.receivers = &cube,
                          .scene = c,
                          .rays = 256,
                          .seed = 3,
                          .threads = 1 + (uint32_t)t,
                          .method = VB_METHOD_DECISION,
                          .order_mask = (1u << 2) | (1u << 3)};
        vb_result r = vb_bake_run(&d, &o[t], &err);
        CHECK(r == VB_OK, "decision bake of the cube: %s", err.msg);
        if (r != VB_OK)
            goto out;
        CHECK(o[t].decision_lights > 0 && o[t].decision_fitted == cube.vertex_count,
              "the cube's decision fit: %u lights, %u of %u fitted", o[t].decision_lights,
              o[t].decision_fitted, cube.vertex_count);
    }
    CHECK(!memcmp(o[0].coeffs[3], o[1].coeffs[3], 9 * cube.vertex_count * sizeof(float)),
          "1 and 2 threads differ on the cube");
    for (int t = 0; t < 2; t++)
        vb_bake_output_free(&o[t]);
out:
    free(a);
    free(b);
    vb_scene_destroy(s);
    vb_scene_destroy(c);
    vb_mesh_free(&occ);
    vb_mesh_free(&rec);
    vb_mesh_free(&cube);
}

int main(int argc, char **argv)
{
    const char *only = argc > 1 ? argv[1] : NULL;
#define RUN(name, fn)                                                                              \
    if (!only || strcmp(only, name) == 0)                                                          \
    fn()
    RUN("heldout", test_heldout);
    RUN("interpolate", test_interpolation);
    RUN("sources", test_sources);
    RUN("sphere", test_sphere);
    RUN("room", test_room);
    RUN("methods", test_methods);
    RUN("oracle", test_oracle_and_threads);
    RUN("lights", test_lights);
    return test_report("test_eval");
}
