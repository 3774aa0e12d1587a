/*
 * test_runtime_glsl.c - the shaders agree with the C evaluation
 * (formats/vdsh_sh.h, formats/vdsh_shadow.h), proven by rendering into a
 * float target and reading back, never by reading the shader.
 *
 *   vertex    every texel-centre direction of all six GL cube faces (64^2
 *             each), one receiver per direction, drawn as points from a
 *             camera at the light: each pixel holds one receiver's d_V,
 *             d_L and s. Orders 2 and 3 (vertex stage), order 5 with the
 *             basis cubemaps and with polynomials, f16 and f32, smooth
 *             and binary, quantities distance, distance^2, log-distance.
 *             Because every direction is a texel centre, the cubemap path
 *             must match to the half-float precision of the basis values:
 *             a face uploaded mirrored or rotated fails by whole units.
 *   fragment  a triangulated grid drawn with triangles: each pixel against
 *             the C model of what the pipeline must do (vertex-stage
 *             values interpolated barycentrically, bands 3-4 per fragment
 *             toward the fragment's own light direction).
 *   at        a light exactly at a receiver: visibility 1 there in every
 *             mode (vdsh_shadow_compare), and no NaN anywhere else.
 */
#include "test_runtime_util.h"

#include "vdsh_cube.h"

/* Where the test writes its files (argv[1]). */
static const char *g_dir = "runtime_glsl";

enum { CUBE_N = 64 };

static const float LIGHT[3] = {0.3f, -0.2f, 0.1f};

/* The monotone map from an SH sum to a distance, per quantity. */
static float to_distance(uint32_t q, float sum)
{
    if (q == VDSH_QUANTITY_DISTANCE2)
        return sum > 0.0f ? sqrtf(sum) : 0.0f;
    if (q == VDSH_QUANTITY_LOG_DISTANCE)
        return expf(sum);
    return sum > 0.0f ? sum : 0.0f;
}

/* Random coefficients: c0 mostly positive (a mean distance), the rest
 * smaller; some vertices reconstruct negative (ringing) on purpose. */
static float *random_coefs(uint64_t *rng, uint32_t v, int order, float c0_lo, float c0_hi,
                           float rest)
{
    int nc = order * order;
    float *c = malloc((size_t)v * (size_t)nc * sizeof(float));
    for (uint32_t i = 0; i < v; i++) {
        c[(size_t)i * nc] = c0_lo + (c0_hi - c0_lo) * (float)test_rand(rng);
        for (int k = 1; k < nc; k++)
            c[(size_t)i * nc + k] = rest * (2.0f * (float)test_rand(rng) - 1.0f);
    }
    return c;
}

/* Add orders 2, 3, 5 for each quantity, coefficient ranges suited to it. */
static void add_all_streams(rt_file *f, uint64_t *rng, uint32_t enc)
{
    static const int orders[3] = {2, 3, 5};
    uint32_t v = f->f.header.vertex_count;
    for (uint32_t q = 0; q < 3; q++)
        for (int o = 0; o < 3; o++) {
            float *c;
            if (q == VDSH_QUANTITY_LOG_DISTANCE)
                c = random_coefs(rng, v, orders[o], -3.0f, 3.0f, 0.8f);
            else if (q == VDSH_QUANTITY_DISTANCE2)
                c = random_coefs(rng, v, orders[o], -2.0f, 20.0f, 3.0f);
            else
                c = random_coefs(rng, v, orders[o], -1.0f, 9.0f, 1.5f);
            rt_file_add_stream(f, (uint32_t)orders[o], enc, q, c,
                               enc == VDSH_ENCODING_F16 ? 0.01f : 0.5f);
        }
}

static const float *stream_coefs(const rt_file *f, int order, uint32_t q)
{
    for (uint32_t i = 0; i < f->f.stream_count; i++)
        if ((int)f->streams[i].order == order && f->streams[i].quantity == q)
            return f->coef[i];
    return NULL;
}

/* Sum of |c_i Y_i(d)| over i in [lo, hi): the scale of rounding errors. */
static float abs_terms(const float *c, const float d[3], int lo, int hi)
{
    float y[25], s = 0.0f;
    vdsh_sh_eval(5, d, y);
    for (int i = lo; i < hi; i++)
        s += fabsf(c[i] * y[i]);
    return s;
}

typedef struct tally {
    long checked, zero, partial, one, ambiguous, bad;
} tally;

/* Check one receiver: GPU (s, dv, dl) against the C evaluation, with the
 * SH sum allowed to differ by tol_sum (float rounding; half-float basis
 * values on the cubemap path). */
static void check_receiver(tally *t, const char *what, uint32_t q, uint32_t cmp, int order,
                           const float *c, const float p[3], const float l[3],
                           const float *gpu, float tol_sum)
{
    float v[3] = {l[0] - p[0], l[1] - p[1], l[2] - p[2]};
    float dl = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    float d[3] = {v[0] / dl, v[1] / dl, v[2] / dl};
    float sum = vdsh_sh_reconstruct(order, c, d);
    float dv = vdsh_stream_distance((uint32_t)order, q, c, d);
    float s = vdsh_shadow((uint32_t)order, q, c, p, l, cmp);
    /* The interval of distances and visibilities the tolerance allows. */
    float dv_lo = to_distance(q, sum - tol_sum), dv_hi = to_distance(q, sum + tol_sum);
    float dl_tol = 2e-6f * dl + 1e-7f;
    float s_lo = vdsh_shadow_compare(dv_lo, dl + dl_tol, cmp);
    float s_hi = vdsh_shadow_compare(dv_hi, dl - dl_tol, cmp);
    float eps_dv = 2e-6f * fabsf(dv) + 1e-6f;
    t->checked++;
    if (s == 0.0f)
        t->zero++;
    else if (s == 1.0f)
        t->one++;
    else
        t->partial++;
    int ok = fabsf(gpu[2] - dl) <= dl_tol && gpu[1] >= dv_lo - eps_dv && gpu[1] <= dv_hi + eps_dv;
    if (cmp == VDSH_COMPARE_BINARY && s_lo != s_hi)
        t->ambiguous++; /* d_V within rounding of d_L: either answer is right */
    else
        ok = ok && gpu[0] >= s_lo - 2e-5f && gpu[0] <= s_hi + 2e-5f;
    if (!ok) {
        if (t->bad++ < 5)
            fprintf(stderr, "%s: receiver (%g %g %g): GPU s %.7g dv %.7g dl %.7g; C s %.7g "
                    "[%.7g, %.7g] dv %.7g [%.7g, %.7g] dl %.7g\n", what, p[0], p[1], p[2],
                    gpu[0], gpu[1], gpu[2], s, s_lo, s_hi, dv, dv_lo, dv_hi, dl);
    }
}

/* GL face coordinates (s, t) of a direction whose major axis is face f
 * (the inverse of vdsh_cube_gl_dir). */
static void gl_face_st(int f, const float d[3], float *s, float *t)
{
    float ax = fabsf(d[0]), ay = fabsf(d[1]), az = fabsf(d[2]);
    switch (f) {
    case 0: *s = -d[2] / ax; *t = -d[1] / ax; break;
    case 1: *s = d[2] / ax; *t = -d[1] / ax; break;
    case 2: *s = d[0] / ay; *t = d[2] / ay; break;
    case 3: *s = d[0] / ay; *t = -d[2] / ay; break;
    case 4: *s = d[0] / az; *t = -d[1] / az; break;
    default: *s = -d[0] / az; *t = -d[1] / az; break;
    }
}

/* ------------------------------------------------------------------ */

static void test_vertex(const char *dir)
{
    uint64_t rng = 0x5eed;
    uint32_t per_face = CUBE_N * CUBE_N, nv = 6 * per_face;
    rt_file files[2];
    vr_scene *scenes[2][3] = {{0}};
    for (int e = 0; e < 2; e++) {
        rt_file *f = &files[e];
        rt_file_init(f, nv, 1);
        /* Receiver (f, i, j) at distance t from the light, opposite the GL
         * texel centre direction of (f, i, j): seen from it, the light is
         * exactly in that direction. */
        for (int face = 0; face < 6; face++)
            for (int j = 0; j < CUBE_N; j++)
                for (int i = 0; i < CUBE_N; i++) {
                    uint32_t v = (uint32_t)face * per_face + (uint32_t)(j * CUBE_N + i);
                    float d[3];
                    vdsh_cube_gl_dir(face, i, j, CUBE_N, d);
                    float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    float t = 0.3f + 2.7f * (float)test_rand(&rng);
                    for (int k = 0; k < 3; k++) {
                        f->pos[3 * v + k] = LIGHT[k] - t * d[k] / len;
                        f->nrm[3 * v + k] = d[k] / len;
                    }
                }
        f->idx[0] = 0, f->idx[1] = 1, f->idx[2] = 2;
        rt_file_bounds(f);
        add_all_streams(f, &rng, e ? VDSH_ENCODING_F32 : VDSH_ENCODING_F16);
        char path[512];
        if (rt_file_write(f, dir, e ? "star32" : "star16", path, sizeof path)) {
            CHECK(0, "cannot write %s", path);
            return;
        }
        for (uint32_t q = 0; q < 3; q++) {
            vr_error err;
            vr_scene_desc sd = {.path = path, .quantity = q};
            vr_result r = vr_scene_create(&sd, &scenes[e][q], &err);
            CHECK(r == VR_OK, "%s", err.msg);
            if (r != VR_OK)
                return;
        }
    }

    vr_renderer *r = NULL;
    vr_error err;
    vr_renderer_desc rd = {.width = CUBE_N, .height = CUBE_N, .color_format = VR_COLOR_RGBA32F};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    if (!r)
        return;

    static const vr_mode modes[4] = {VR_MODE_VDSH2, VR_MODE_VDSH3, VR_MODE_VDSH5,
                                     VR_MODE_VDSH5_POLY};
    static const int mode_order[4] = {2, 3, 5, 5};
    tally total[4][2];
    memset(total, 0, sizeof total);
    vr_light light = {.position = {LIGHT[0], LIGHT[1], LIGHT[2]}};
    for (int face = 0; face < 6; face++) {
        /* A 90-degree camera at the light looking away from face's texel
         * directions: the receivers of this face, one per pixel. */
        static const float axis[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                         {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        vr_draw_desc d = {.mode = VR_MODE_NONE, .output = VR_OUTPUT_POSITION, .points = 1,
                          .lights = &light, .light_count = 1};
        for (int k = 0; k < 3; k++) {
            d.camera.eye[k] = LIGHT[k];
            d.camera.target[k] = LIGHT[k] - axis[face][k];
        }
        d.camera.up[face == 2 || face == 3 ? 2 : 1] = 1.0f;
        d.camera.fov_y = 90.0f;
        d.camera.znear = 0.05f;
        d.camera.zfar = 10.0f;
        rt_draw_or_die(r, scenes[0][0], &d);
        float *pos = rt_read(r, CUBE_N, CUBE_N);
        /* Which receiver each pixel shows: from its position's direction. */
        int vert[CUBE_N * CUBE_N];
        int found = 0;
        for (int px = 0; px < CUBE_N * CUBE_N; px++) {
            vert[px] = -1;
            const float *p = pos + 4 * px;
            if (p[3] != 1.0f)
                continue;
            float dd[3] = {LIGHT[0] - p[0], LIGHT[1] - p[1], LIGHT[2] - p[2]}, s, t;
            gl_face_st(face, dd, &s, &t);
            int i = (int)floorf((s + 1.0f) * 0.5f * CUBE_N), j = (int)floorf((t + 1.0f) * 0.5f * CUBE_N);
            if (i < 0 || j < 0 || i >= CUBE_N || j >= CUBE_N)
                continue;
            int v = face * (int)per_face + j * CUBE_N + i;
            const float *q = files[0].pos + 3 * v;
            if (fabsf(p[0] - q[0]) + fabsf(p[1] - q[1]) + fabsf(p[2] - q[2]) < 1e-5f) {
                vert[px] = v;
                found++;
            }
        }
        free(pos);
        CHECK(found == (int)per_face, "face %d: %d of %u receivers found in the image", face,
              found, per_face);

        for (int e = 0; e < 2; e++)
            for (uint32_t q = 0; q < 3; q++)
                for (int m = 0; m < 4; m++)
                    for (uint32_t cmp = 0; cmp < 2; cmp++) {
                        vr_draw_desc ds = d;
                        ds.mode = modes[m];
                        ds.compare = cmp;
                        ds.output = VR_OUTPUT_SHADOW;
                        rt_draw_or_die(r, scenes[e][q], &ds);
                        float *px = rt_read(r, CUBE_N, CUBE_N);
                        const float *coefs = stream_coefs(&files[e], mode_order[m], q);
                        char what[128];
                        snprintf(what, sizeof what, "face %d, %s, %s, %s, %s", face,
                                 vr_mode_name(modes[m]), e ? "f32" : "f16",
                                 vdsh_quantity_name(q), cmp ? "binary" : "smooth");
                        int nc = mode_order[m] * mode_order[m];
                        for (int k = 0; k < CUBE_N * CUBE_N; k++) {
                            int v = vert[k];
                            if (v < 0)
                                continue;
                            const float *c = coefs + (size_t)v * (size_t)nc;
                            const float *p = files[e].pos + 3 * v;
                            float dd[3] = {LIGHT[0] - p[0], LIGHT[1] - p[1], LIGHT[2] - p[2]};
                            float len = sqrtf(dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
                            for (int a = 0; a < 3; a++)
                                dd[a] /= len;
                            /* float rounding; plus half-float basis values
                             * (relative 2^-11) for bands 3-4 from cubemaps */
                            float tol = 3e-6f * abs_terms(c, dd, 0, nc) + 1e-6f;
                            if (modes[m] == VR_MODE_VDSH5)
                                tol += 6e-4f * abs_terms(c, dd, 9, 25);
                            check_receiver(&total[m][cmp], what, q, cmp, mode_order[m], c, p,
                                           LIGHT, px + 4 * k, tol);
                        }
                        free(px);
                    }
    }
    for (int m = 0; m < 4; m++)
        for (int cmp = 0; cmp < 2; cmp++) {
            tally *t = &total[m][cmp];
            printf("vertex %-9s %-6s: %ld receivers checked (s = 0: %ld, 0 < s < 1: %ld, "
                   "s = 1: %ld, binary ties skipped: %ld), %ld wrong\n",
                   vr_mode_name(modes[m]), cmp ? "binary" : "smooth", t->checked, t->zero,
                   t->partial, t->one, t->ambiguous, t->bad);
            CHECK(t->bad == 0, "%s %s: %ld receivers disagree", vr_mode_name(modes[m]),
                  cmp ? "binary" : "smooth", t->bad);
            CHECK(t->checked == 2L * 3 * 6 * CUBE_N * CUBE_N, "%ld checked", t->checked);
            /* the data must exercise every branch */
            CHECK(t->zero > t->checked / 50 && t->one > t->checked / 50, "coverage");
            if (cmp == 0)
                CHECK(t->partial > t->checked / 50, "coverage of the ramp");
            CHECK(t->ambiguous < t->checked / 1000, "too many ties: %ld", t->ambiguous);
        }
    vr_renderer_destroy(r);
    for (int e = 0; e < 2; e++) {
        for (int q = 0; q < 3; q++)
            vr_scene_destroy(scenes[e][q]);
        rt_file_free(&files[e]);
    }
}

/* ------------------------------------------------------------------ */

enum { GRID_Q = 6, GRID_PX = 96 };

/* A (Q+1)^2 lattice over [-1, 1]^2 in z = 0, facing +z, two triangles
 * per cell split along the (i, j)-(i+1, j+1) diagonal. */
static void grid_file(rt_file *f, uint64_t *rng, uint32_t enc)
{
    uint32_t n = GRID_Q + 1;
    rt_file_init(f, n * n, 2 * GRID_Q * GRID_Q);
    for (uint32_t j = 0; j < n; j++)
        for (uint32_t i = 0; i < n; i++) {
            uint32_t v = j * n + i;
            f->pos[3 * v] = -1.0f + 2.0f * (float)i / GRID_Q;
            f->pos[3 * v + 1] = -1.0f + 2.0f * (float)j / GRID_Q;
            f->nrm[3 * v + 2] = 1.0f;
        }
    uint32_t t = 0;
    for (uint32_t j = 0; j < GRID_Q; j++)
        for (uint32_t i = 0; i < GRID_Q; i++) {
            uint32_t a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
            uint32_t tri[6] = {a, b, c, a, c, d};
            memcpy(f->idx + 3 * t, tri, sizeof tri);
            t += 2;
        }
    rt_file_bounds(f);
    add_all_streams(f, rng, enc);
}

/* Barycentric coordinates of (x, y) in the grid: vertex indices and
 * weights. */
static void grid_locate(float x, float y, uint32_t v[3], float w[3])
{
    float gx = (x + 1.0f) * 0.5f * GRID_Q, gy = (y + 1.0f) * 0.5f * GRID_Q;
    int i = (int)floorf(gx), j = (int)floorf(gy);
    i = i < 0 ? 0 : i >= GRID_Q ? GRID_Q - 1 : i;
    j = j < 0 ? 0 : j >= GRID_Q ? GRID_Q - 1 : j;
    float u = gx - (float)i, t = gy - (float)j;
    uint32_t n = GRID_Q + 1, a = (uint32_t)(j * (int)n + i);
    if (u >= t) { /* triangle a, b, c */
        v[0] = a, v[1] = a + 1, v[2] = a + n + 1;
        w[0] = 1.0f - u, w[1] = u - t, w[2] = t;
    } else {      /* triangle a, c, d */
        v[0] = a, v[1] = a + n + 1, v[2] = a + n;
        w[0] = 1.0f - t, w[1] = u, w[2] = t - u;
    }
}

static vr_draw_desc grid_view(const vr_light *light)
{
    vr_draw_desc d = {.lights = light, .light_count = 1};
    d.camera.eye[2] = 5.0f;
    d.camera.up[1] = 1.0f;
    d.camera.ortho_height = 2.2f;
    return d;
}

static void test_fragment(void)
{
    uint64_t rng = 0xf4a9;
    rt_file files[2];
    vr_scene *scenes[2][3] = {{0}};
    vr_error err;
    for (int e = 0; e < 2; e++) {
        grid_file(&files[e], &rng, e ? VDSH_ENCODING_F32 : VDSH_ENCODING_F16);
        for (uint32_t q = 0; q < 3; q++) {
            vr_scene_desc sd = {.file = &files[e].f, .quantity = q, .skip_cubemaps = 0,
                                .path = NULL};
            /* from memory; cubemaps from the star test's files */
            sd.cubemap_dir = g_dir;
            sd.cubemap_stem = "star16";
            CHECK(vr_scene_create(&sd, &scenes[e][q], &err) == VR_OK, "%s", err.msg);
            if (!scenes[e][q])
                return;
        }
    }
    vr_renderer *r = NULL;
    vr_renderer_desc rd = {.width = GRID_PX, .height = GRID_PX,
                           .color_format = VR_COLOR_RGBA32F};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    if (!r)
        return;
    const float L[3] = {0.2f, 0.1f, 0.8f};
    vr_light light = {.position = {L[0], L[1], L[2]}};
    vr_draw_desc d = grid_view(&light);
    d.mode = VR_MODE_NONE;
    d.output = VR_OUTPUT_POSITION;
    rt_draw_or_die(r, scenes[0][0], &d);
    float *pos = rt_read(r, GRID_PX, GRID_PX);

    static const vr_mode modes[4] = {VR_MODE_VDSH2, VR_MODE_VDSH3, VR_MODE_VDSH5,
                                     VR_MODE_VDSH5_POLY};
    static const int mode_order[4] = {2, 3, 5, 5};
    long checked = 0, bad = 0, covered = 0;
    for (int e = 0; e < 2; e++)
        for (uint32_t q = 0; q < 3; q++)
            for (int m = 0; m < 4; m++)
                for (uint32_t cmp = 0; cmp < 2; cmp++) {
                    vr_draw_desc ds = grid_view(&light);
                    ds.mode = modes[m];
                    ds.compare = cmp;
                    ds.output = VR_OUTPUT_SHADOW;
                    rt_draw_or_die(r, scenes[e][q], &ds);
                    float *px = rt_read(r, GRID_PX, GRID_PX);
                    int order = mode_order[m], nc = order * order;
                    const float *coefs = stream_coefs(&files[e], order, q);
                    for (int k = 0; k < GRID_PX * GRID_PX; k++) {
                        const float *p = pos + 4 * k, *g = px + 4 * k;
                        if (p[3] != 1.0f)
                            continue;
                        uint32_t v[3];
                        float w[3];
                        grid_locate(p[0], p[1], v, w);
                        float ref_s, ref_dv, tol_s, tol_dv;
                        int skip = 0;
                        if (order < 5) {
                            /* per-vertex values, interpolated */
                            ref_s = ref_dv = 0.0f;
                            float span = 0.0f;
                            for (int a = 0; a < 3; a++) {
                                const float *vp = files[e].pos + 3 * v[a];
                                const float *c = coefs + (size_t)v[a] * (size_t)nc;
                                float dd[3] = {L[0] - vp[0], L[1] - vp[1], L[2] - vp[2]};
                                float dl = sqrtf(dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
                                for (int b = 0; b < 3; b++)
                                    dd[b] /= dl;
                                float dv = vdsh_stream_distance((uint32_t)order, q, c, dd);
                                if (cmp == VDSH_COMPARE_BINARY && fabsf(dv - dl) < 1e-4f * dl)
                                    skip = 1;
                                ref_s += w[a] * vdsh_shadow_compare(dv, dl, cmp);
                                ref_dv += w[a] * dv;
                                span += dv;
                            }
                            tol_s = 1e-4f;
                            tol_dv = 1e-4f * span + 1e-5f;
                        } else {
                            /* bands 0-2 at the vertices toward their own
                             * light direction, interpolated; bands 3-4
                             * interpolated and evaluated toward the
                             * fragment's light direction */
                            float sum = 0.0f, mag = 0.0f, c16[25] = {0};
                            for (int a = 0; a < 3; a++) {
                                const float *vp = files[e].pos + 3 * v[a];
                                const float *c = coefs + (size_t)v[a] * 25;
                                float dd[3] = {L[0] - vp[0], L[1] - vp[1], L[2] - vp[2]};
                                float dl = sqrtf(dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
                                for (int b = 0; b < 3; b++)
                                    dd[b] /= dl;
                                sum += w[a] * vdsh_sh_reconstruct(3, c, dd);
                                mag += abs_terms(c, dd, 0, 9);
                                for (int i = 9; i < 25; i++)
                                    c16[i] += w[a] * c[i];
                            }
                            float fd[3] = {L[0] - p[0], L[1] - p[1], L[2] - p[2]};
                            float dl = sqrtf(fd[0] * fd[0] + fd[1] * fd[1] + fd[2] * fd[2]);
                            for (int b = 0; b < 3; b++)
                                fd[b] /= dl;
                            float y[25];
                            vdsh_sh_eval(5, fd, y);
                            float hi = 0.0f;
                            for (int i = 9; i < 25; i++) {
                                sum += c16[i] * y[i];
                                hi += fabsf(c16[i] * y[i]) + fabsf(c16[i]);
                            }
                            /* barycentrics from a read-back position;
                             * with cubemaps, bilinear filtering of the
                             * basis between texel centres */
                            float tol_sum = 2e-5f * (mag + hi) + 1e-6f;
                            if (modes[m] == VR_MODE_VDSH5)
                                tol_sum += 4e-3f * hi;
                            float lo_dv = to_distance(q, sum - tol_sum);
                            float hi_dv = to_distance(q, sum + tol_sum);
                            ref_dv = 0.5f * (lo_dv + hi_dv);
                            tol_dv = 0.5f * (hi_dv - lo_dv) + 1e-5f * ref_dv + 1e-6f;
                            float s_lo = vdsh_shadow_compare(lo_dv, dl * (1 + 2e-6f), cmp);
                            float s_hi = vdsh_shadow_compare(hi_dv, dl * (1 - 2e-6f), cmp);
                            if (cmp == VDSH_COMPARE_BINARY && s_lo != s_hi)
                                skip = 1;
                            ref_s = 0.5f * (s_lo + s_hi);
                            tol_s = 0.5f * (s_hi - s_lo) + 2e-5f;
                        }
                        if (skip)
                            continue;
                        checked++;
                        if (ref_s > 0.05f && ref_s < 0.95f)
                            covered++;
                        if (!(fabsf(g[0] - ref_s) <= tol_s && fabsf(g[1] - ref_dv) <= tol_dv)) {
                            if (bad++ < 5)
                                fprintf(stderr, "fragment %s %s %s %s at (%g, %g): GPU s %.6g "
                                        "dv %.6g, expected s %.6g +- %.2g, dv %.6g +- %.2g\n",
                                        vr_mode_name(modes[m]), e ? "f32" : "f16",
                                        vdsh_quantity_name(q), cmp ? "binary" : "smooth",
                                        p[0], p[1], g[0], g[1], ref_s, tol_s, ref_dv, tol_dv);
                        }
                    }
                    free(px);
                }
    printf("fragment: %ld pixels checked (%ld in the ramp), %ld wrong\n", checked, covered, bad);
    CHECK(bad == 0, "%ld fragments disagree", bad);
    CHECK(checked > 40L * GRID_PX * GRID_PX, "only %ld fragments checked", checked);
    CHECK(covered > checked / 50, "ramp coverage %ld", covered);
    free(pos);
    vr_renderer_destroy(r);
    for (int e = 0; e < 2; e++) {
        for (int q = 0; q < 3; q++)
            vr_scene_destroy(scenes[e][q]);
        rt_file_free(&files[e]);
    }
}

/* ------------------------------------------------------------------ */

static void test_light_at_receiver(void)
{
    uint64_t rng = 0xa7;
    rt_file f;
    grid_file(&f, &rng, VDSH_ENCODING_F16);
    vr_scene *s = NULL;
    vr_renderer *r = NULL;
    vr_error err;
    vr_scene_desc sd = {.file = &f.f, .cubemap_dir = g_dir, .cubemap_stem = "star16"};
    CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "%s", err.msg);
    vr_renderer_desc rd = {.width = GRID_PX, .height = GRID_PX,
                           .color_format = VR_COLOR_RGBA32F};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    if (!s || !r)
        return;
    /* The light exactly at a grid vertex: (1/3, -1/3, 0) is vertex (4, 2). */
    uint32_t at = 2 * (GRID_Q + 1) + 4;
    const float *L = f.pos + 3 * at;
    vr_light light = {.position = {L[0], L[1], L[2]}};

    /* The C definition first. */
    const float *c5 = stream_coefs(&f, 5, VDSH_QUANTITY_DISTANCE) + 25 * at;
    CHECK(vdsh_shadow(5, VDSH_QUANTITY_DISTANCE, c5, L, L, VDSH_COMPARE_SMOOTH) == 1.0f, "C");
    CHECK(vdsh_shadow(5, VDSH_QUANTITY_DISTANCE, c5, L, L, VDSH_COMPARE_BINARY) == 1.0f, "C");

    vr_draw_desc d = grid_view(&light);
    d.mode = VR_MODE_NONE;
    d.output = VR_OUTPUT_POSITION;
    d.points = 1;
    rt_draw_or_die(r, s, &d);
    float *pos = rt_read(r, GRID_PX, GRID_PX);
    int pixel = -1;
    for (int k = 0; k < GRID_PX * GRID_PX; k++)
        if (pos[4 * k + 3] == 1.0f && memcmp(pos + 4 * k, L, 3 * sizeof(float)) == 0)
            pixel = k;
    free(pos);
    CHECK(pixel >= 0, "the receiver under the light is not in the image");

    for (int m = VR_MODE_NONE; m < VR_MODE_COUNT_; m++)
        for (uint32_t cmp = 0; cmp < 2; cmp++)
            for (int points = 1; points >= 0; points--) {
                vr_draw_desc ds = grid_view(&light);
                ds.mode = (uint32_t)m;
                ds.compare = cmp;
                ds.points = points;
                for (int out = VR_OUTPUT_COLOR; out <= VR_OUTPUT_SHADOW; out++) {
                    ds.output = (uint32_t)out;
                    rt_draw_or_die(r, s, &ds);
                    float *px = rt_read(r, GRID_PX, GRID_PX);
                    long nan = 0;
                    for (int k = 0; k < 4 * GRID_PX * GRID_PX; k++)
                        nan += !isfinite(px[k]);
                    CHECK(nan == 0, "%s %s points %d output %d: %ld values not finite",
                          vr_mode_name((vr_mode)m), cmp ? "binary" : "smooth", points, out, nan);
                    if (points && out == VR_OUTPUT_SHADOW && pixel >= 0) {
                        CHECK(px[4 * pixel] == 1.0f, "%s %s: light at the receiver: s = %g",
                              vr_mode_name((vr_mode)m), cmp ? "binary" : "smooth",
                              px[4 * pixel]);
                        CHECK(px[4 * pixel + 2] == 0.0f, "d_L = %g", px[4 * pixel + 2]);
                    }
                    free(px);
                }
            }
    vr_renderer_destroy(r);
    vr_scene_destroy(s);
    rt_file_free(&f);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        g_dir = argv[1];
    vr_context *ctx = rt_context_or_skip("test_runtime_glsl");
    printf("GL_RENDERER: %s (%s)\n", vr_gl_renderer(), vr_context_description(ctx));
    test_vertex(g_dir);
    test_fragment();
    test_light_at_receiver();
    vr_context_destroy(ctx);
    return test_report("test_runtime_glsl");
}
