/*
 * test_runtime_glsl.c - the shaders agree with the C evaluation
 * (formats/vdsh_sh.h, formats/vdsh_shadow.h), proven by rendering into a
 * float target and reading back, never by reading the shader.
 *
 *   vertex    every texel-centre direction of all six GL cube faces (64^2
 *             each), one receiver per direction, drawn as points from a
 *             camera at the light: each pixel holds one receiver's d_V,
 *             d_L and s. Orders 2 and 3 (vertex stage), order 5 with the
 *             basis cubemaps and with polynomials, f16, f32, s8 and s8s6, smooth
 *             and binary, quantities distance, distance^2, log-distance.
 *             Because every direction is a texel centre, the cubemap path
 *             must match to the half-float precision of the basis values:
 *             a face uploaded mirrored or rotated fails by whole units.
 *             Per vertex every path is vdsh_shadow().
 *   fragment  a triangulated grid drawn with triangles: each pixel against
 *             vdsh_shadow_interior() on the path vdsh_runtime_interp()
 *             gives (visibility, split or distance), the one definition
 *             vdsh-eval scores with; no model of the interpolation here.
 *             Three lights: in front of the grid, exactly at a vertex and
 *             exactly at a fragment.
 *   at        a light exactly at a receiver: visibility 1 there in every
 *             mode, quantity and encoding (vdsh_shadow_compare), and no
 *             NaN anywhere else.
 *   horizon   a light just below one vertex's horizon, toward which that
 *             vertex's log-distance stream runs away: every fragment
 *             against vdsh_shadow_interior, so the vertex's distance is
 *             clamped to the file's max distance as the definition says,
 *             and the light does not leak across the triangle.
 * The f32, s8 and s8s6 files of "vertex" and "fragment" have a max distance (2)
 * that clamps a good share of their distances, so every path is also
 * checked where the clamp acts; the f16 files keep 100, which clamps
 * almost none. The s8 and s8s6 files are drawn with the same tolerances:
 * their coefficients reach the shader as exact integers (s8s6's unpacked
 * there from its words) times the per-index step, the products
 * vdsh_stream_decode computes.
 */
#include "test_runtime_util.h"

#include "vdsh_cube.h"

/* Where the test writes its files (argv[1]). */
static const char *g_dir = "runtime_glsl";

enum { CUBE_N = 64 };

static const float LIGHT[3] = {0.3f, -0.2f, 0.1f};

/* The monotone map from an SH sum to a distance, per quantity, clamped
 * to max distance md. */
static float to_distance(uint32_t q, float md, float sum)
{
    float d;
    if (q == VDSH_QUANTITY_DISTANCE2)
        d = sum > 0.0f ? sqrtf(sum) : 0.0f;
    else if (q == VDSH_QUANTITY_LOG_DISTANCE)
        d = expf(sum);
    else
        d = sum > 0.0f ? sum : 0.0f;
    return d > md ? md : d;
}

/* The encodings every test draws, and their names in messages. */
enum { NENC = 4 };
static const uint32_t ENC[NENC] = {VDSH_ENCODING_F16, VDSH_ENCODING_F32, VDSH_ENCODING_S8,
                                   VDSH_ENCODING_S8S6};
static const char *const ENC_NAME[NENC] = {"f16", "f32", "s8", "s8s6"};

/* The max distance of the files of encoding enc (see the top). */
static float file_max_distance(uint32_t enc)
{
    return enc == VDSH_ENCODING_F16 ? 100.0f : 2.0f;
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
    long checked, zero, partial, one, ambiguous, bad, clamped;
} tally;

/* Check one receiver: GPU (s, dv, dl) against the C evaluation, with the
 * SH sum allowed to differ by tol_sum (float rounding; half-float basis
 * values on the cubemap path). */
static void check_receiver(tally *t, const char *what, uint32_t q, float md, uint32_t cmp,
                           int order, const float *c, const float p[3], const float l[3],
                           const float *gpu, float tol_sum)
{
    float v[3] = {l[0] - p[0], l[1] - p[1], l[2] - p[2]};
    float dl = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    float d[3] = {v[0] / dl, v[1] / dl, v[2] / dl};
    float sum = vdsh_sh_reconstruct(order, c, d);
    float dv = vdsh_stream_distance((uint32_t)order, q, md, c, d);
    float s = vdsh_shadow((uint32_t)order, q, md, c, p, l, cmp);
    /* The interval of distances and visibilities the tolerance allows. */
    float dv_lo = to_distance(q, md, sum - tol_sum), dv_hi = to_distance(q, md, sum + tol_sum);
    float dl_tol = 2e-6f * dl + 1e-7f;
    float s_lo = vdsh_shadow_compare(dv_lo, dl + dl_tol, cmp);
    float s_hi = vdsh_shadow_compare(dv_hi, dl - dl_tol, cmp);
    float eps_dv = 2e-6f * fabsf(dv) + 1e-6f;
    t->checked++;
    t->clamped += to_distance(q, INFINITY, sum) > md;
    if (s == 0.0f)
        t->zero++;
    else if (s == 1.0f)
        t->one++;
    else
        t->partial++;
    int ok = fabsf(gpu[2] - dl) <= dl_tol && gpu[1] >= dv_lo - eps_dv && gpu[1] <= dv_hi + eps_dv &&
             gpu[1] <= md;
    if (cmp == VDSH_COMPARE_BINARY && s_lo != s_hi)
        t->ambiguous++; /* d_V within rounding of d_L: either answer is right */
    else
        ok = ok && gpu[0] >= s_lo - 2e-5f && gpu[0] <= s_hi + 2e-5f;
    if (!ok) {
        if (t->bad++ < 5)
            fprintf(stderr,
                    "%s: receiver (%g %g %g): GPU s %.7g dv %.7g dl %.7g; C s %.7g "
                    "[%.7g, %.7g] dv %.7g [%.7g, %.7g] dl %.7g\n",
                    what, p[0], p[1], p[2], gpu[0], gpu[1], gpu[2], s, s_lo, s_hi, dv, dv_lo, dv_hi,
                    dl);
    }
}

/* GL face coordinates (s, t) of a direction whose major axis is face f
 * (the inverse of vdsh_cube_gl_dir). */
static void gl_face_st(int f, const float d[3], float *s, float *t)
{
    float ax = fabsf(d[0]), ay = fabsf(d[1]), az = fabsf(d[2]);
    switch (f) {
    case 0:
        *s = -d[2] / ax;
        *t = -d[1] / ax;
        break;
    case 1:
        *s = d[2] / ax;
        *t = -d[1] / ax;
        break;
    case 2:
        *s = d[0] / ay;
        *t = d[2] / ay;
        break;
    case 3:
        *s = d[0] / ay;
        *t = -d[2] / ay;
        break;
    case 4:
        *s = d[0] / az;
        *t = -d[1] / az;
        break;
    default:
        *s = -d[0] / az;
        *t = -d[1] / az;
        break;
    }
}

/* ------------------------------------------------------------------ */

static void test_vertex(const char *dir)
{
    uint64_t rng = 0x5eed;
    uint32_t per_face = CUBE_N * CUBE_N, nv = 6 * per_face;
    rt_file files[NENC];
    vr_scene *scenes[NENC][3] = {{0}};
    for (int e = 0; e < NENC; e++) {
        rt_file *f = &files[e];
        rt_file_init(f, nv, 1);
        f->f.header.max_distance = file_max_distance(ENC[e]);
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
        add_all_streams(f, &rng, ENC[e]);
        char path[512];
        if (rt_file_write(f, dir, (const char *const[]){"star16", "star32", "star8", "star86"}[e],
                          path, sizeof path)) {
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
        static const float axis[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                         {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
        vr_draw_desc d = {.mode = VR_MODE_NONE,
                          .output = VR_OUTPUT_POSITION,
                          .points = 1,
                          .lights = &light,
                          .light_count = 1};
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
            int i = (int)floorf((s + 1.0f) * 0.5f * CUBE_N),
                j = (int)floorf((t + 1.0f) * 0.5f * CUBE_N);
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
        CHECK(found == (int)per_face, "face %d: %d of %u receivers found in the image", face, found,
              per_face);

        for (int e = 0; e < NENC; e++)
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
                        uint32_t interp = vdsh_runtime_interp((uint32_t)mode_order[m], q);
                        CHECK(vr_scene_interp(scenes[e][q], modes[m]) == (int)interp,
                              "%s %s: path %d, not %s", vr_mode_name(modes[m]),
                              vdsh_quantity_name(q), vr_scene_interp(scenes[e][q], modes[m]),
                              vdsh_interp_name(interp));
                        char what[128];
                        snprintf(what, sizeof what, "face %d, %s, %s, %s, %s", face,
                                 vr_mode_name(modes[m]), ENC_NAME[e], vdsh_quantity_name(q),
                                 cmp ? "binary" : "smooth");
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
                            if (modes[m] == VR_MODE_VDSH5 && interp == VDSH_INTERP_SPLIT)
                                tol += 6e-4f * abs_terms(c, dd, 9, 25);
                            check_receiver(&total[m][cmp], what, q, file_max_distance(ENC[e]), cmp,
                                           mode_order[m], c, p, LIGHT, px + 4 * k, tol);
                        }
                        free(px);
                    }
    }
    for (int m = 0; m < 4; m++)
        for (int cmp = 0; cmp < 2; cmp++) {
            tally *t = &total[m][cmp];
            printf("vertex %-9s %-6s: %ld receivers checked (s = 0: %ld, 0 < s < 1: %ld, "
                   "s = 1: %ld, binary ties skipped: %ld, clamped: %ld), %ld wrong\n",
                   vr_mode_name(modes[m]), cmp ? "binary" : "smooth", t->checked, t->zero,
                   t->partial, t->one, t->ambiguous, t->clamped, t->bad);
            CHECK(t->bad == 0, "%s %s: %ld receivers disagree", vr_mode_name(modes[m]),
                  cmp ? "binary" : "smooth", t->bad);
            CHECK(t->checked == (long)NENC * 3 * 6 * CUBE_N * CUBE_N, "%ld checked", t->checked);
            /* the data must exercise every branch */
            CHECK(t->zero > t->checked / 50 && t->one > t->checked / 50, "coverage");
            CHECK(t->clamped > t->checked / 50, "coverage of the clamp: %ld", t->clamped);
            if (cmp == 0)
                CHECK(t->partial > t->checked / 50, "coverage of the ramp");
            CHECK(t->ambiguous < t->checked / 1000, "too many ties: %ld", t->ambiguous);
        }
    vr_renderer_destroy(r);
    for (int e = 0; e < NENC; e++) {
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
    f->f.header.max_distance = file_max_distance(enc);
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
    } else { /* triangle a, c, d */
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

/* The distances that SH sums within delta of the one behind distance d
 * give (d = 0 on a linear quantity: any sum <= 0). */
static void distance_interval(uint32_t q, float md, float d, float delta, float *lo, float *hi)
{
    if (!(d > 0.0f)) {
        *lo = 0.0f;
        *hi = q == VDSH_QUANTITY_LOG_DISTANCE ? 0.0f : to_distance(q, md, delta);
        return;
    }
    float sum = q == VDSH_QUANTITY_DISTANCE2      ? d * d
                : q == VDSH_QUANTITY_LOG_DISTANCE ? logf(d)
                                                  : d;
    *lo = to_distance(q, md, sum - delta);
    *hi = to_distance(q, md, sum + delta);
}

/* The visibility path's interval without a model of it: [s_lo, s_hi] and
 * [d_lo, d_hi] are vdsh_shadow_interior with every vertex's SH sums
 * moved down and up by delta. Coefficient 0's basis function is the
 * constant C00 in every direction, so moving it moves every sum by the
 * same amount, and the interpolated result monotonically. */
typedef struct bracket {
    float s_lo, s_hi, d_lo, d_hi;
} bracket;

static bracket interior_bracket(uint32_t order, uint32_t q, float md, uint32_t interp,
                                const float *const c[3], const float *const pv[3], const float b[3],
                                const float l[3], uint32_t cmp, float delta)
{
    const float c00 = 0.28209479177387814f;
    int nc = (int)(order * order);
    float lo[3][25], hi[3][25];
    const float *cl[3], *ch[3];
    for (int k = 0; k < 3; k++) {
        memcpy(lo[k], c[k], (size_t)nc * sizeof(float));
        memcpy(hi[k], c[k], (size_t)nc * sizeof(float));
        lo[k][0] -= delta / c00;
        hi[k][0] += delta / c00;
        cl[k] = lo[k];
        ch[k] = hi[k];
    }
    bracket r;
    r.s_lo = vdsh_shadow_interior(order, q, md, interp, cl, pv, b, l, cmp, &r.d_lo);
    r.s_hi = vdsh_shadow_interior(order, q, md, interp, ch, pv, b, l, cmp, &r.d_hi);
    return r;
}

typedef struct frag_tally {
    long checked, ramp, ties, bad, differ, clamped;
} frag_tally;

/* One fragment: GPU (s, d_V, d_L) in g against the definition on the
 * runtime's path. p: the fragment's position (read back), v, w: its
 * triangle and barycentrics. */
static void check_fragment(frag_tally *t, const char *what, const rt_file *f, int order, uint32_t q,
                           vr_mode mode, uint32_t cmp, const float *coefs, const float p[3],
                           const uint32_t v[3], const float w[3], const float l[3], const float *g,
                           int at_light)
{
    int nc = order * order;
    uint32_t interp = vdsh_runtime_interp((uint32_t)order, q);
    const float md = f->f.header.max_distance;
    const float *c[3], *pv[3];
    float mag = 0.0f, mag16 = 0.0f;
    for (int k = 0; k < 3; k++) {
        c[k] = coefs + (size_t)v[k] * (size_t)nc;
        pv[k] = f->pos + 3 * v[k];
        float m = 0.0f, m16 = 0.0f;
        for (int i = 0; i < nc; i++) {
            m += fabsf(c[k][i]);
            m16 += i >= 9 ? fabsf(c[k][i]) : 0.0f;
        }
        mag = fmaxf(mag, m), mag16 = fmaxf(mag16, m16);
    }
    float lv[3] = {l[0] - p[0], l[1] - p[1], l[2] - p[2]};
    float dl = sqrtf(lv[0] * lv[0] + lv[1] * lv[1] + lv[2] * lv[2]);
    /* Rounding of the sums (|Y_i| < 1 for every basis function up to band
     * 4, so mag bounds sum |c_i Y_i|) and of the vertex stage's light
     * distances. On the split path also: with cubemaps the half-float,
     * bilinearly filtered basis; and the fragment's direction toward the
     * light, which the rounding of p (1e-6 here) turns by 1e-6 / d_L, where
     * bands 3-4 change by at most 5 per radian. */
    float delta = 2e-5f * mag + 4e-6f * (mag + 1.0f) + 1e-6f;
    if (interp == VDSH_INTERP_SPLIT) {
        if (mode == VR_MODE_VDSH5)
            delta += 5e-3f * mag16;
        delta += 5.0f * mag16 * 1e-6f / fmaxf(dl, 1e-6f);
    }
    float d_ref;
    float s_ref = vdsh_shadow_interior((uint32_t)order, q, md, interp, c, pv, w, l, cmp, &d_ref);
    /* The barycentrics come from a read-back position, not from the
     * rasteriser: allow their rounding times the vertices' values. */
    float span = 0.0f;
    for (int k = 0; k < 3; k++) {
        float e[3] = {k == 0, k == 1, k == 2}, dk;
        vdsh_shadow_interior((uint32_t)order, q, md, interp, c, pv, e, l, cmp, &dk);
        span += fabsf(dk);
    }
    float tol_b = 2e-5f * span + 1e-6f;
    float d_lo, d_hi, s_lo, s_hi;
    if (interp == VDSH_INTERP_VISIBILITY) {
        /* compared per vertex: the visibilities are interpolated */
        bracket r = interior_bracket((uint32_t)order, q, md, interp, c, pv, w, l, cmp, delta);
        d_lo = r.d_lo - tol_b, d_hi = r.d_hi + tol_b;
        s_lo = r.s_lo - 1e-5f;
        s_hi = r.s_hi + 1e-5f;
    } else {
        /* one distance, compared here with this fragment's own d_L */
        distance_interval(q, md, d_ref, delta, &d_lo, &d_hi);
        d_lo -= tol_b, d_hi += tol_b;
        float dl_lo = fmaxf(0.0f, dl * (1.0f - 4e-6f) - 1e-7f), dl_hi = dl * (1.0f + 4e-6f) + 1e-7f;
        s_lo = vdsh_shadow_compare(d_lo, dl_hi, cmp) - 2e-5f;
        s_hi = vdsh_shadow_compare(d_hi, dl_lo, cmp) + 2e-5f;
    }
    t->checked++;
    float d_wild;
    vdsh_shadow_interior((uint32_t)order, q, INFINITY, interp, c, pv, w, l, cmp, &d_wild);
    t->clamped += d_wild > d_ref;
    if (s_ref > 0.05f && s_ref < 0.95f)
        t->ramp++;
    if (s_hi - s_lo > 0.5f)
        t->ties++; /* binary, d_V within rounding of d_L: either answer */
    if (q == VDSH_QUANTITY_LOG_DISTANCE) {
        float sc = vdsh_shadow_interior((uint32_t)order, q, md, VDSH_INTERP_COEFFICIENTS, c, pv, w,
                                        l, cmp, NULL);
        t->differ += fabsf(sc - s_ref) > 0.1f;
    }
    int ok = g[0] >= s_lo && g[0] <= s_hi && g[1] >= d_lo - 1e-6f * fabsf(d_lo) &&
             g[1] <= d_hi + 1e-6f * fabsf(d_hi) &&
             /* per vertex at most md; the debug output's d_V is then
              * interpolated on the visibility path, which rounds */
             g[1] <= md * (interp == VDSH_INTERP_VISIBILITY ? 1.000001f : 1.0f);
    if (interp != VDSH_INTERP_VISIBILITY)
        ok = ok && fabsf(g[2] - dl) <= 4e-6f * dl + 2e-7f;
    if (at_light && interp != VDSH_INTERP_VISIBILITY) {
        /* The fragment whose position is the light: its d_L is exactly 0
         * on the GPU, but p rebuilt from barycentrics is off by rounding,
         * and the split path reports d_V = 0 for d_L = 0. The definition
         * there: visible. */
        ok = g[0] == 1.0f && g[2] == 0.0f &&
             (interp == VDSH_INTERP_SPLIT
                  ? g[1] == 0.0f
                  : g[1] >= d_lo - 1e-6f * fabsf(d_lo) && g[1] <= d_hi + 1e-6f * fabsf(d_hi));
    }
    if (!ok && t->bad++ < 5)
        fprintf(stderr,
                "fragment %s at (%g, %g, %g), path %s: GPU s %.7g dv %.7g dl %.7g; C s "
                "%.7g [%.7g, %.7g] dv %.7g [%.7g, %.7g] dl %.7g\n",
                what, p[0], p[1], p[2], vdsh_interp_name(interp), g[0], g[1], g[2], s_ref, s_lo,
                s_hi, d_ref, d_lo, d_hi, dl);
}

static void test_fragment(void)
{
    uint64_t rng = 0xf4a9;
    rt_file files[NENC];
    vr_scene *scenes[NENC][3] = {{0}};
    vr_error err;
    for (int e = 0; e < NENC; e++) {
        grid_file(&files[e], &rng, ENC[e]);
        for (uint32_t q = 0; q < 3; q++) {
            /* from memory, the basis cubemaps made at the file's cube_size */
            vr_scene_desc sd = {.file = &files[e].f, .quantity = q};
            CHECK(vr_scene_create(&sd, &scenes[e][q], &err) == VR_OK, "%s", err.msg);
            if (!scenes[e][q])
                return;
        }
    }
    vr_renderer *r = NULL;
    vr_renderer_desc rd = {.width = GRID_PX, .height = GRID_PX, .color_format = VR_COLOR_RGBA32F};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    if (!r)
        return;
    vr_light light = {0};
    vr_draw_desc d = grid_view(&light);
    d.mode = VR_MODE_NONE;
    d.output = VR_OUTPUT_POSITION;
    rt_draw_or_die(r, scenes[0][0], &d);
    float *pos = rt_read(r, GRID_PX, GRID_PX);

    /* Lights: in front of the grid (triangles of a third of their
     * distance to it: the paths differ); exactly at grid vertex (4, 2);
     * exactly at the position one fragment reads back, inside a triangle
     * (pixel (41, 58): barycentrics all between 0.1 and 0.9). */
    int light_pixel = 58 * GRID_PX + 41;
    uint32_t at_vertex = 2 * (GRID_Q + 1) + 4;
    float lights[3][3] = {{0.2f, 0.1f, 0.8f}};
    memcpy(lights[1], files[0].pos + 3 * at_vertex, sizeof lights[1]);
    memcpy(lights[2], pos + 4 * light_pixel, sizeof lights[2]);
    {
        uint32_t v[3];
        float w[3];
        grid_locate(lights[2][0], lights[2][1], v, w);
        CHECK(pos[4 * light_pixel + 3] == 1.0f && fminf(w[0], fminf(w[1], w[2])) > 0.1f,
              "the light pixel is not inside a triangle: %g %g %g", w[0], w[1], w[2]);
    }
    static const char *const light_names[3] = {"in front", "at a vertex", "at a fragment"};

    static const vr_mode modes[4] = {VR_MODE_VDSH2, VR_MODE_VDSH3, VR_MODE_VDSH5,
                                     VR_MODE_VDSH5_POLY};
    static const int mode_order[4] = {2, 3, 5, 5};
    frag_tally paths[4], lt[3];
    memset(paths, 0, sizeof paths);
    memset(lt, 0, sizeof lt);
    for (int li = 0; li < 3; li++)
        for (int e = 0; e < NENC; e++)
            for (uint32_t q = 0; q < 3; q++)
                for (int m = 0; m < 4; m++)
                    for (uint32_t cmp = 0; cmp < 2; cmp++) {
                        memcpy(light.position, lights[li], sizeof light.position);
                        vr_draw_desc ds = grid_view(&light);
                        ds.mode = modes[m];
                        ds.compare = cmp;
                        ds.output = VR_OUTPUT_SHADOW;
                        rt_draw_or_die(r, scenes[e][q], &ds);
                        float *px = rt_read(r, GRID_PX, GRID_PX);
                        int order = mode_order[m];
                        uint32_t interp = vdsh_runtime_interp((uint32_t)order, q);
                        const float *coefs = stream_coefs(&files[e], order, q);
                        char what[160];
                        snprintf(what, sizeof what, "%s %s %s %s, light %s", vr_mode_name(modes[m]),
                                 ENC_NAME[e], vdsh_quantity_name(q), cmp ? "binary" : "smooth",
                                 light_names[li]);
                        frag_tally t;
                        memset(&t, 0, sizeof t);
                        for (int k = 0; k < GRID_PX * GRID_PX; k++) {
                            const float *p = pos + 4 * k;
                            if (p[3] != 1.0f)
                                continue;
                            uint32_t v[3];
                            float w[3];
                            grid_locate(p[0], p[1], v, w);
                            check_fragment(&t, what, &files[e], order, q, modes[m], cmp, coefs, p,
                                           v, w, lights[li], px + 4 * k,
                                           li == 2 && k == light_pixel);
                        }
                        free(px);
                        frag_tally *sum[2] = {&paths[interp], &lt[li]};
                        for (int a = 0; a < 2; a++) {
                            sum[a]->checked += t.checked;
                            sum[a]->ramp += t.ramp;
                            sum[a]->ties += t.ties;
                            sum[a]->bad += t.bad;
                            sum[a]->differ += t.differ;
                            sum[a]->clamped += t.clamped;
                        }
                    }
    for (uint32_t i = 0; i < 4; i++) {
        frag_tally *t = &paths[i];
        if (!t->checked)
            continue;
        printf("fragment, path %-10s: %ld pixels checked (%ld in the ramp, %ld binary ties, "
               "%ld clamped), %ld wrong\n",
               vdsh_interp_name(i), t->checked, t->ramp, t->ties, t->clamped, t->bad);
        CHECK(t->bad == 0, "path %s: %ld fragments disagree", vdsh_interp_name(i), t->bad);
        CHECK(t->ramp > t->checked / 50, "path %s: ramp coverage %ld", vdsh_interp_name(i),
              t->ramp);
        CHECK(t->clamped > t->checked / 50, "path %s: clamp coverage %ld", vdsh_interp_name(i),
              t->clamped);
        /* the cubemaps' half-float, filtered basis widens the split
         * path's interval: more binary answers are left open there */
        CHECK(t->ties < t->checked / (i == VDSH_INTERP_SPLIT ? 20 : 200), "path %s: %ld ties",
              vdsh_interp_name(i), t->ties);
    }
    CHECK(paths[VDSH_INTERP_VISIBILITY].checked && paths[VDSH_INTERP_SPLIT].checked &&
              paths[VDSH_INTERP_DISTANCE].checked,
          "a path was not drawn");
    for (int li = 0; li < 3; li++) {
        printf("fragment, light %-13s: %ld pixels checked, %ld wrong; log-distance: %ld where "
               "interpolating coefficients would differ by > 0.1\n",
               light_names[li], lt[li].checked, lt[li].bad, lt[li].differ);
        CHECK(lt[li].checked > 20L * GRID_PX * GRID_PX, "only %ld fragments checked",
              lt[li].checked);
    }
    /* The grid must be able to tell the distance path from coefficient
     * interpolation, or matching it proves little. */
    CHECK(lt[0].differ > lt[0].checked / 100, "log-distance paths barely differ: %ld",
          lt[0].differ);
    free(pos);
    vr_renderer_destroy(r);
    for (int e = 0; e < NENC; e++) {
        for (int q = 0; q < 3; q++)
            vr_scene_destroy(scenes[e][q]);
        rt_file_free(&files[e]);
    }
}

/* ------------------------------------------------------------------ */

static void test_light_at_receiver(void)
{
    uint64_t rng = 0xa7;
    vr_renderer *r = NULL;
    vr_error err;
    vr_renderer_desc rd = {.width = GRID_PX, .height = GRID_PX, .color_format = VR_COLOR_RGBA32F};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    if (!r)
        return;
    long draws = 0;
    for (int e = 0; e < NENC; e++) {
        rt_file f;
        grid_file(&f, &rng, ENC[e]);
        /* The light exactly at a grid vertex: (1/3, -1/3, 0) is vertex (4, 2). */
        uint32_t at = 2 * (GRID_Q + 1) + 4;
        const float *L = f.pos + 3 * at;
        vr_light light = {.position = {L[0], L[1], L[2]}};
        for (uint32_t q = 0; q < 3; q++) {
            /* The C definition first. */
            const float *c5 = stream_coefs(&f, 5, q) + 25 * at;
            float md = f.f.header.max_distance;
            CHECK(vdsh_shadow(5, q, md, c5, L, L, VDSH_COMPARE_SMOOTH) == 1.0f, "C");
            CHECK(vdsh_shadow(5, q, md, c5, L, L, VDSH_COMPARE_BINARY) == 1.0f, "C");

            vr_scene *s = NULL;
            /* buffers: VR_MODE_VDSH_BUFFER draws order 5 too */
            vr_scene_desc sd = {.file = &f.f, .quantity = q, .buffers = 1};
            CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "%s", err.msg);
            if (!s)
                break;
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

            /* (VR_MODE_SDF needs a distance volume, which these files have
             * not: its trace is checked by test_sdf and frames_gl_vs_c.) */
            for (int m = VR_MODE_NONE; m < VR_MODE_COUNT_; m++)
                for (uint32_t cmp = 0; cmp < 2 && m != VR_MODE_SDF; cmp++)
                    for (int points = 1; points >= 0; points--) {
                        vr_draw_desc ds = grid_view(&light);
                        ds.mode = (uint32_t)m;
                        ds.compare = cmp;
                        ds.points = points;
                        for (int out = VR_OUTPUT_COLOR; out <= VR_OUTPUT_SHADOW; out++) {
                            ds.output = (uint32_t)out;
                            rt_draw_or_die(r, s, &ds);
                            draws++;
                            float *px = rt_read(r, GRID_PX, GRID_PX);
                            long nan = 0;
                            for (int k = 0; k < 4 * GRID_PX * GRID_PX; k++)
                                nan += !isfinite(px[k]);
                            CHECK(nan == 0,
                                  "%s %s %s %s points %d output %d: %ld values not "
                                  "finite",
                                  vr_mode_name((vr_mode)m), ENC_NAME[e], vdsh_quantity_name(q),
                                  cmp ? "binary" : "smooth", points, out, nan);
                            if (points && out == VR_OUTPUT_SHADOW && pixel >= 0) {
                                CHECK(px[4 * pixel] == 1.0f,
                                      "%s %s %s: light at the receiver: "
                                      "s = %g",
                                      vr_mode_name((vr_mode)m), vdsh_quantity_name(q),
                                      cmp ? "binary" : "smooth", px[4 * pixel]);
                                CHECK(px[4 * pixel + 2] == 0.0f, "d_L = %g", px[4 * pixel + 2]);
                            }
                            free(px);
                        }
                    }
            vr_scene_destroy(s);
        }
        rt_file_free(&f);
    }
    printf("light at a receiver: %ld draws (every mode, quantity, encoding, comparison, "
           "points and triangles), no NaN, s = 1 there\n",
           draws);
    vr_renderer_destroy(r);
}

/* ------------------------------------------------------------------ */

/* One triangle a, b, c in z = 0 seen from +z, lit from in front. The
 * light is 3 degrees below a's horizon (a's smooth normal is turned away
 * from it, as at a terminator) and above b's and c's. b and c see an
 * occluder 0.3 away in every direction: ln D = ln 0.3. a's stream runs
 * away toward the light, as fits do where nothing constrains them:
 * ln D(w) = ln 0.3 + 14 (u . w), u the direction from a to the light, so
 * that D toward it is 3.6e5 while the file's max distance is 4.
 * Unclamped, a's distance interpolated over the triangle lit all of it;
 * clamped, the side near b-c stays dark. (tests/test_sh.c checks the
 * same case in C.) */
static void test_horizon(void)
{
    static const float A[3] = {-1, -1, 0}, B[3] = {1, -1, 0}, C[3] = {-1, 1, 0};
    static const float L[3] = {0.5f, 0.5f, 1.5f};
    const float md = 4.0f, beta = 14.0f, eps = 3.0f * 3.14159265f / 180.0f;
    const float c00 = 0.28209479177387814f, c1 = 0.4886025119029199f;
    float u[3], len = 0.0f;
    for (int k = 0; k < 3; k++) {
        u[k] = L[k] - A[k];
        len += u[k] * u[k];
    }
    for (int k = 0; k < 3; k++)
        u[k] /= sqrtf(len);

    rt_file f;
    rt_file_init(&f, 3, 1);
    f.f.header.max_distance = md;
    memcpy(f.pos, A, sizeof A);
    memcpy(f.pos + 3, B, sizeof B);
    memcpy(f.pos + 6, C, sizeof C);
    /* a's normal: w (+z made perpendicular to u) turned 3 degrees past u */
    float w[3] = {-u[2] * u[0], -u[2] * u[1], 1.0f - u[2] * u[2]};
    float wl = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int k = 0; k < 3; k++)
        f.nrm[k] = -sinf(eps) * u[k] + cosf(eps) * w[k] / wl;
    f.nrm[5] = f.nrm[8] = 1.0f;
    f.idx[0] = 0, f.idx[1] = 1, f.idx[2] = 2;
    rt_file_bounds(&f);
    static const int orders[3] = {2, 3, 5};
    for (int o = 0; o < 3; o++) {
        int nc = orders[o] * orders[o];
        float *c = calloc(3 * (size_t)nc, sizeof(float));
        for (int v = 0; v < 3; v++)
            c[v * nc] = logf(0.3f) / c00;
        c[1] = -beta * u[1] / c1; /* Y_1-1 = -C1 y, Y_10 = C1 z, Y_11 = -C1 x */
        c[2] = beta * u[2] / c1;
        c[3] = -beta * u[0] / c1;
        rt_file_add_stream(&f, (uint32_t)orders[o], VDSH_ENCODING_F32, VDSH_QUANTITY_LOG_DISTANCE,
                           c, 1.0f);
    }
    float cosn = 0.0f;
    for (int k = 0; k < 3; k++)
        cosn += f.nrm[k] * u[k];
    const float *c2 = stream_coefs(&f, 2, VDSH_QUANTITY_LOG_DISTANCE);
    CHECK(cosn < -0.05f && cosn > -0.06f &&
              vdsh_stream_distance(2, VDSH_QUANTITY_LOG_DISTANCE, INFINITY, c2, u) > 1e5f,
          "the case: the light at %g below a's horizon", cosn);

    vr_scene *s = NULL;
    vr_renderer *r = NULL;
    vr_error err;
    vr_scene_desc sd = {.file = &f.f};
    CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "%s", err.msg);
    vr_renderer_desc rd = {.width = GRID_PX, .height = GRID_PX, .color_format = VR_COLOR_RGBA32F};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    if (!s || !r) {
        vr_scene_destroy(s);
        vr_renderer_destroy(r);
        rt_file_free(&f);
        return;
    }
    vr_scene_info info;
    vr_scene_get_info(s, &info);
    CHECK(info.max_distance == md, "scene info: max distance %g", info.max_distance);
    vr_light light = {.position = {L[0], L[1], L[2]}};
    vr_draw_desc d = grid_view(&light);
    d.mode = VR_MODE_NONE;
    d.output = VR_OUTPUT_POSITION;
    rt_draw_or_die(r, s, &d);
    float *pos = rt_read(r, GRID_PX, GRID_PX);

    static const vr_mode modes[4] = {VR_MODE_VDSH2, VR_MODE_VDSH3, VR_MODE_VDSH5,
                                     VR_MODE_VDSH5_POLY};
    static const int mode_order[4] = {2, 3, 5, 5};
    const uint32_t q = VDSH_QUANTITY_LOG_DISTANCE, tri[3] = {0, 1, 2};
    for (int m = 0; m < 4; m++)
        for (uint32_t cmp = 0; cmp < 2; cmp++) {
            vr_draw_desc ds = grid_view(&light);
            ds.mode = modes[m];
            ds.compare = cmp;
            ds.output = VR_OUTPUT_SHADOW;
            rt_draw_or_die(r, s, &ds);
            float *px = rt_read(r, GRID_PX, GRID_PX);
            const float *coefs = stream_coefs(&f, mode_order[m], q);
            const float *cv[3], *pv[3] = {A, B, C};
            for (int k = 0; k < 3; k++)
                cv[k] = coefs + (size_t)k * (size_t)(mode_order[m] * mode_order[m]);
            char what[96];
            snprintf(what, sizeof what, "horizon %s %s", vr_mode_name(modes[m]),
                     cmp ? "binary" : "smooth");
            frag_tally t;
            memset(&t, 0, sizeof t);
            long dark = 0, leak_stopped = 0;
            float worst = 0.0f;
            for (int k = 0; k < GRID_PX * GRID_PX; k++) {
                const float *p = pos + 4 * k, *g = px + 4 * k;
                if (p[3] != 1.0f)
                    continue;
                /* barycentrics in the right triangle a, b, c */
                float b[3] = {0.0f, 0.5f * (p[0] + 1.0f), 0.5f * (p[1] + 1.0f)};
                b[0] = 1.0f - b[1] - b[2];
                check_fragment(&t, what, &f, mode_order[m], q, modes[m], cmp, coefs, p, tri, b, L,
                               g, 0);
                worst = fmaxf(worst, g[1]);
                float s_wild = vdsh_shadow_interior((uint32_t)mode_order[m], q, INFINITY,
                                                    VDSH_INTERP_DISTANCE, cv, pv, b, L, cmp, NULL);
                dark += g[0] < 0.5f;
                leak_stopped += g[0] < 0.5f && s_wild > 0.5f;
            }
            free(px);
            printf("horizon %-9s %s: %ld fragments checked, %ld wrong, %ld dark, %ld of them "
                   "lit without the clamp; largest distance %g (max %g)\n",
                   vr_mode_name(modes[m]), cmp ? "binary" : "smooth", t.checked, t.bad, dark,
                   leak_stopped, worst, md);
            CHECK(t.bad == 0, "%s: %ld fragments disagree with vdsh_shadow_interior", what, t.bad);
            CHECK(t.checked > GRID_PX * GRID_PX / 4, "%s: only %ld fragments", what, t.checked);
            CHECK(worst <= md, "%s: a distance of %g past the max distance", what, worst);
            /* the side near b-c, where a's weight is small (about half
             * the triangle), is dark, and was lit unclamped */
            CHECK(leak_stopped > t.checked / 5 && leak_stopped == dark,
                  "%s: %ld of %ld fragments dark, %ld of them lit unclamped", what, dark, t.checked,
                  leak_stopped);
        }
    free(pos);
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
    test_horizon();
    vr_context_destroy(ctx);
    return test_report("test_runtime_glsl");
}
