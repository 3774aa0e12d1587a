/*
 * test_runtime_buffer.c - VR_MODE_VDSH_BUFFER (runtime/vr_buffer.c,
 * shaders/vdsh_buffer.glsl) against the C evaluation, by rendering into a float
 * target and reading back:
 *
 *   vertex    a 64 x 48 lattice of receivers, one per pixel of an
 *             orthographic view, drawn as points with VR_OUTPUT_SHADOW:
 *             each pixel holds one vertex's d_V, d_L and s, checked
 *             against vdsh_stream_distance / vdsh_shadow_compare (the SH
 *             sum within float rounding of the coefficients' size, see
 *             SUM_TOL) for orders 1, 2, 3, 5 and, where the format
 *             holds them, 7, 9, 12, 16; f16, f32, s8, s8s6 and decoded
 *             floats; quantities distance and log-distance; three lights
 *             in a pass, in turn first (below, beside and far above the
 *             plane, so the directions cover the sphere). Then streams
 *             with an order per vertex (1..12, cap 12) in each encoding,
 *             each vertex against C at its own order.
 *   frames    the built-in room's log-distance bake (argv[2]): the buffer
 *             path at orders 2, 3, 5 draws what the attribute path's
 *             VR_MODE_VDSH2/3/5 draw (both are the distance path): the
 *             colour of 3 and of 9 lights (two passes) and the shadow
 *             output, pixel by pixel.
 *   errors    what a scene holds and says: buffers only where asked,
 *             vr_scene_buffer_stream, the bytes uploaded, VR_ERR_MISSING
 *             for a stream it does not have.
 *   derive    not a test: writes a file with orders 7, 9, 12 and an
 *             order per vertex for the frame test (tests/frames.cmake).
 * Exit 77 without a GL context.
 */
#include "test_runtime_util.h"

enum { W = 64, H = 48, NV = W * H };

/* The orders checked, those up to VDSH_MAX_ORDER. */
static const int ORDERS[] = {1, 2, 3, 5, 7, 9, 12, 16};
enum { NORDERS = sizeof ORDERS / sizeof ORDERS[0] };
static const uint32_t QUANT[2] = {VDSH_QUANTITY_DISTANCE, VDSH_QUANTITY_LOG_DISTANCE};

/* The GPU sum may differ from the C sum by this much times the sum of
 * |c_i| (every |Y_i| is below 1.2 up to band 15): float rounding of the
 * recurrence (every band here, closed forms below band 5 in C). */
static const float SUM_TOL = 2e-6f;

/* Lattice spacing, and the lights: below, beside and above the lattice,
 * so that its vertices see them in every direction. */
static const float STEP = 0.05f;
static const float LIGHTS[3][3] = {{0.5f, 0.3f, -1.0f}, {-2.5f, 1.5f, 0.8f}, {1.0f, -1.6f, 2.5f}};

static float to_distance(uint32_t q, float md, float sum)
{
    float d = q == VDSH_QUANTITY_LOG_DISTANCE ? expf(fminf(sum, VDSH_LOG_SUM_MAX))
                                              : (sum > 0.0f ? sum : 0.0f);
    return d > md ? md : d;
}

/* A lattice file: vertex (i, j) at the centre of pixel (i, j) of the
 * orthographic view below, normal +z; one triangle (unused). */
static void lattice_file_positions(rt_file *f)
{
    f->f.header.max_distance = 4.0f;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            float *p = f->pos + 3 * (j * W + i);
            p[0] = STEP * (-0.5f * W + (float)i + 0.5f);
            p[1] = STEP * (0.5f * H - (float)j - 0.5f);
            f->nrm[3 * (j * W + i) + 2] = 1.0f;
        }
    f->idx[0] = 0, f->idx[1] = 1, f->idx[2] = 2;
    rt_file_bounds(f);
}

static void lattice_file(rt_file *f, uint32_t enc, uint64_t *rng)
{
    rt_file_init(f, NV, 1);
    lattice_file_positions(f);
    for (int q = 0; q < 2; q++)
        for (int o = 0; o < NORDERS && ORDERS[o] <= VDSH_MAX_ORDER; o++) {
            int n = ORDERS[o], nc = n * n;
            float *c = malloc((size_t)NV * (size_t)nc * sizeof(float));
            /* c0 a mean distance; the rest shrinking with the order so
             * that sums stay in a range where the clamp is not all. */
            float lo = q ? -3.0f : 0.0f, hi = q ? 5.5f : 16.0f, rest = (q ? 3.0f : 8.0f) / (float)n;
            for (size_t v = 0; v < NV; v++) {
                c[v * (size_t)nc] = lo + (hi - lo) * (float)test_rand(rng);
                for (int k = 1; k < nc; k++)
                    c[v * (size_t)nc + (size_t)k] = rest * (2.0f * (float)test_rand(rng) - 1.0f);
            }
            rt_file_add_stream(f, (uint32_t)n, enc, QUANT[q], c,
                               enc == VDSH_ENCODING_F16 ? 0.01f : 0.5f);
        }
}

static vr_draw_desc lattice_view(void)
{
    vr_draw_desc d = {.mode = VR_MODE_VDSH_BUFFER, .points = 1, .output = VR_OUTPUT_SHADOW};
    d.camera.eye[2] = 5.0f;
    d.camera.up[1] = 1.0f;
    d.camera.ortho_height = STEP * (float)H;
    d.camera.znear = 1.0f;
    d.camera.zfar = 10.0f;
    return d;
}

typedef struct tally {
    long checked, bad, clamped, zero, one;
    double worst; /* max |sum_gpu - sum_c| / max(1, sum |c_i|) where measurable */
} tally;

/* One vertex: GPU (s, dv, dl) for light l against C. */
static void check_vertex(tally *t, const char *what, uint32_t q, float md, int order,
                         const float *c, const float p[3], const float l[3], const float *gpu)
{
    float v[3] = {l[0] - p[0], l[1] - p[1], l[2] - p[2]};
    float dl = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    float d[3] = {v[0] / dl, v[1] / dl, v[2] / dl};
    float sum = vdsh_sh_reconstruct(order, c, d), size = 0.0f;
    for (int i = 0; i < order * order; i++)
        size += fabsf(c[i]);
    float tol = SUM_TOL * size + 1e-6f;
    float dv_lo = to_distance(q, md, sum - tol), dv_hi = to_distance(q, md, sum + tol);
    float eps = 2e-6f * dv_hi + 1e-6f, dl_tol = 2e-6f * dl + 1e-7f;
    float s_lo = vdsh_shadow_compare(dv_lo, dl + dl_tol, VDSH_COMPARE_SMOOTH);
    float s_hi = vdsh_shadow_compare(dv_hi, dl - dl_tol, VDSH_COMPARE_SMOOTH);
    t->checked++;
    t->clamped += to_distance(q, INFINITY, sum) > md;
    t->zero += s_hi == 0.0f;
    t->one += s_lo == 1.0f;
    int ok = fabsf(gpu[2] - dl) <= dl_tol && gpu[1] >= dv_lo - eps && gpu[1] <= dv_hi + eps &&
             gpu[0] >= s_lo - 2e-5f && gpu[0] <= s_hi + 2e-5f;
    float g = gpu[1];
    if (g > 0.0f && g < md * 0.999f && to_distance(q, INFINITY, sum) < md * 0.999f) {
        double gs = q == VDSH_QUANTITY_LOG_DISTANCE ? log((double)g) : (double)g;
        double e = fabs(gs - (double)sum) / fmax(1.0, (double)size);
        if (e > t->worst)
            t->worst = e;
    }
    if (!ok && t->bad++ < 5)
        fprintf(stderr,
                "%s: vertex (%g %g): GPU s %.7g dv %.7g dl %.7g; C s [%.7g, %.7g] "
                "dv [%.7g, %.7g] (sum %.7g) dl %.7g\n",
                what, p[0], p[1], gpu[0], gpu[1], gpu[2], s_lo, s_hi, dv_lo, dv_hi, sum, dl);
}

static const float *coefs_of(const rt_file *f, int order, uint32_t q)
{
    for (uint32_t i = 0; i < f->f.stream_count; i++)
        if ((int)f->streams[i].order == order && f->streams[i].quantity == q)
            return f->coef[i];
    return NULL;
}

static void test_vertex(void)
{
    static const uint32_t enc[5] = {VDSH_ENCODING_F16, VDSH_ENCODING_F32, VDSH_ENCODING_S8,
                                    VDSH_ENCODING_S8S6, VDSH_ENCODING_F16};
    static const char *const enc_name[5] = {"f16", "f32", "s8", "s8s6", "f16 as floats"};
    vr_renderer *r = rt_float_renderer(W, H);
    vr_error err;
    if (!r)
        return;
    uint64_t rng = 0xb0ff;
    tally all[NORDERS];
    memset(all, 0, sizeof all);
    for (int e = 0; e < 5; e++) {
        rt_file f;
        lattice_file(&f, enc[e], &rng);
        for (int q = 0; q < 2; q++) {
            vr_scene *s = NULL;
            vr_scene_desc sd = {
                .file = &f.f, .quantity = QUANT[q], .buffers = 1, .buffer_floats = e == 4};
            CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "%s", err.msg);
            if (!s)
                continue;
            /* Which vertex each pixel shows (the upload reorders them). */
            vr_draw_desc d = lattice_view();
            d.mode = VR_MODE_NONE;
            d.output = VR_OUTPUT_POSITION;
            rt_draw_or_die(r, s, &d);
            float *pos = rt_read(r, W, H);
            int found = 0;
            for (int k = 0; k < NV; k++)
                found +=
                    pos[4 * k + 3] == 1.0f &&
                    fabsf(pos[4 * k] - f.pos[3 * k]) + fabsf(pos[4 * k + 1] - f.pos[3 * k + 1]) <
                        1e-5f;
            free(pos);
            CHECK(found == NV, "%s: %d of %d vertices at their pixels", enc_name[e], found, NV);
            for (int o = 0; o < NORDERS && ORDERS[o] <= VDSH_MAX_ORDER; o++) {
                const float *c = coefs_of(&f, ORDERS[o], QUANT[q]);
                CHECK(vr_scene_buffer_stream(s, ORDERS[o]) == ORDERS[o], "order %d not buffered",
                      ORDERS[o]);
                for (int first = 0; first < 3; first++) {
                    vr_light lights[3];
                    memset(lights, 0, sizeof lights);
                    for (int i = 0; i < 3; i++)
                        memcpy(lights[i].position, LIGHTS[(first + i) % 3], sizeof LIGHTS[0]);
                    d = lattice_view();
                    d.stream = ORDERS[o];
                    d.lights = lights;
                    d.light_count = 3;
                    rt_draw_or_die(r, s, &d);
                    float *px = rt_read(r, W, H);
                    char what[96];
                    snprintf(what, sizeof what, "order %d, %s, %s, light %d", ORDERS[o],
                             enc_name[e], vdsh_quantity_name(QUANT[q]), first);
                    int nc = ORDERS[o] * ORDERS[o];
                    for (int k = 0; k < NV; k++)
                        check_vertex(&all[o], what, QUANT[q], f.f.header.max_distance, ORDERS[o],
                                     c + (size_t)k * (size_t)nc, f.pos + 3 * k, LIGHTS[first],
                                     px + 4 * k);
                    free(px);
                }
            }
            vr_scene_destroy(s);
        }
        rt_file_free(&f);
    }
    for (int o = 0; o < NORDERS && ORDERS[o] <= VDSH_MAX_ORDER; o++) {
        tally *t = &all[o];
        printf("vertex order %2d: %ld receivers checked (s = 0: %ld, s = 1: %ld, clamped: %ld), "
               "%ld wrong; largest |GPU - C| sum / max(1, sum |c_i|): %.2g\n",
               ORDERS[o], t->checked, t->zero, t->one, t->clamped, t->bad, t->worst);
        CHECK(t->bad == 0, "order %d: %ld receivers disagree", ORDERS[o], t->bad);
        CHECK(t->checked == 5L * 2 * 3 * NV, "order %d: %ld checked", ORDERS[o], t->checked);
        CHECK(t->zero > t->checked / 50 && t->one > t->checked / 50 &&
                  t->clamped > t->checked / 100,
              "order %d: the data do not cover shadow, light and the clamp", ORDERS[o]);
    }
    vr_renderer_destroy(r);
}

/* A variable-order stream of `quantity` added to f: orders 1..cap drawn
 * per vertex, coefficients as lattice_file's; *coef gets the decoded
 * coefficients (cap^2 per vertex, zeros past a vertex's own k^2) and
 * *ord the orders. The storage goes to f->data / f->coef and `extra`. */
static void add_variable(rt_file *f, uint32_t enc, uint32_t q, int cap, uint64_t *rng, void **extra,
                         const float **coef, const uint8_t **ord)
{
    uint32_t nv = f->f.header.vertex_count, nc = (uint32_t)(cap * cap);
    uint8_t *orders = malloc(nv);
    uint32_t *offsets = malloc(((size_t)nv + 1) * sizeof *offsets);
    float *c = calloc((size_t)nv * nc, sizeof(float));
    float lo = q ? -3.0f : 0.0f, hi = q ? 5.5f : 16.0f;
    for (uint32_t v = 0; v < nv; v++) {
        orders[v] = (uint8_t)(1 + (int)(test_rand(rng) * cap) % cap);
        float rest = (q ? 3.0f : 8.0f) / (float)orders[v];
        c[(size_t)v * nc] = lo + (hi - lo) * (float)test_rand(rng);
        for (uint32_t k = 1; k < (uint32_t)orders[v] * orders[v]; k++)
            c[(size_t)v * nc + k] = rest * (2.0f * (float)test_rand(rng) - 1.0f);
    }
    vdsh_stream_offsets(orders, nv, enc, offsets);
    float *scales = calloc(nc, sizeof(float));
    void *data = calloc(4 * (size_t)offsets[nv] + 4, 1);
    float scale = vdsh_encoding_quantised(enc) ? 1.0f : enc == VDSH_ENCODING_F16 ? 0.01f : 0.5f;
    if (vdsh_encode_variable(enc, c, nc, orders, nv, (uint32_t)cap, scale, offsets, scales, data) !=
        VDSH_OK)
        abort();
    uint32_t i = f->f.stream_count++;
    vdsh_stream *st = &f->streams[i];
    memset(st, 0, sizeof *st);
    st->order = (uint32_t)cap;
    st->encoding = enc;
    st->quantity = q;
    st->scale = scale;
    st->quantity_param = q == VDSH_QUANTITY_LOG_DISTANCE ? 0.01f : 0.0f;
    st->data = data;
    st->coef_scales = vdsh_encoding_quantised(enc) ? scales : NULL;
    st->flags = VDSH_STREAM_VARIABLE;
    st->orders = orders;
    st->offsets = offsets;
    for (uint32_t v = 0; v < nv; v++)
        vdsh_stream_decode(st, v, c + (size_t)v * nc);
    f->data[i] = data;
    f->coef[i] = c;
    extra[0] = orders;
    extra[1] = offsets;
    extra[2] = scales;
    *coef = c;
    *ord = orders;
}

/* Streams with an order per vertex (cap 12), each vertex against C at
 * its own order, in every encoding and as decoded floats. */
static void test_variable(void)
{
    enum { CAP = 12 };
    static const uint32_t enc[5] = {VDSH_ENCODING_F16, VDSH_ENCODING_F32, VDSH_ENCODING_S8,
                                    VDSH_ENCODING_S8S6, VDSH_ENCODING_S8S6};
    static const char *const enc_name[5] = {"f16", "f32", "s8", "s8s6", "s8s6 as floats"};
    vr_renderer *r = rt_float_renderer(W, H);
    vr_error err;
    if (!r)
        return;
    uint64_t rng = 0x7a71;
    tally t;
    memset(&t, 0, sizeof t);
    long per_order[CAP + 1] = {0};
    for (int e = 0; e < 5; e++)
        for (int q = 0; q < 2; q++) {
            rt_file f;
            rt_file_init(&f, NV, 1);
            lattice_file_positions(&f);
            void *extra[3];
            const float *c;
            const uint8_t *ord;
            add_variable(&f, enc[e], QUANT[q], CAP, &rng, extra, &c, &ord);
            vr_scene *s = NULL;
            vr_scene_desc sd = {.file = &f.f, .quantity = QUANT[q], .buffer_floats = e == 4};
            CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "%s", err.msg);
            if (s) {
                vr_scene_info info;
                vr_scene_get_info(s, &info);
                double mean = 0.0;
                for (int v = 0; v < NV; v++)
                    mean += ord[v];
                mean /= NV;
                CHECK(info.variable_order == CAP && fabs(info.variable_mean_order - mean) < 1e-4,
                      "info: order %d mean %g, not %d %g", info.variable_order,
                      (double)info.variable_mean_order, CAP, mean);
                CHECK(vr_scene_buffer_stream(s, 0) == VR_STREAM_VARIABLE, "default stream");
                /* records padded to whole texels, plus 5 bytes of attributes */
                size_t want = 5 * (size_t)NV;
                for (int v = 0; v < NV; v++) {
                    size_t nc = (size_t)ord[v] * ord[v], t4 = (nc + 3) / 4;
                    want += e == 4 ? 16 * t4
                            : enc[e] == VDSH_ENCODING_S8S6
                                ? 4 * ((vdsh_encoding_bytes(enc[e], (uint32_t)nc) + 3) / 4)
                                : t4 * vdsh_encoding_bytes(enc[e], 4);
                }
                CHECK(vr_scene_buffer_bytes(s, VR_STREAM_VARIABLE) == want &&
                          info.buffer_bytes == want,
                      "%s: %zu buffer bytes, not %zu", enc_name[e],
                      vr_scene_buffer_bytes(s, VR_STREAM_VARIABLE), want);
                for (int first = 0; first < 3; first++) {
                    vr_light lights[3];
                    memset(lights, 0, sizeof lights);
                    for (int i = 0; i < 3; i++)
                        memcpy(lights[i].position, LIGHTS[(first + i) % 3], sizeof LIGHTS[0]);
                    vr_draw_desc d = lattice_view();
                    d.stream = VR_STREAM_VARIABLE;
                    d.lights = lights;
                    d.light_count = 3;
                    rt_draw_or_die(r, s, &d);
                    float *px = rt_read(r, W, H);
                    char what[96];
                    snprintf(what, sizeof what, "variable, %s, %s, light %d", enc_name[e],
                             vdsh_quantity_name(QUANT[q]), first);
                    for (int k = 0; k < NV; k++) {
                        check_vertex(&t, what, QUANT[q], f.f.header.max_distance, ord[k],
                                     c + (size_t)k * CAP * CAP, f.pos + 3 * k, LIGHTS[first],
                                     px + 4 * k);
                        per_order[ord[k]]++;
                    }
                    free(px);
                }
                vr_scene_destroy(s);
            }
            for (int i = 0; i < 3; i++)
                free(extra[i]);
            rt_file_free(&f);
        }
    printf("variable (cap %d): %ld receivers checked (s = 0: %ld, s = 1: %ld, clamped: %ld), "
           "%ld wrong; largest |GPU - C| sum / max(1, sum |c_i|): %.2g\n",
           CAP, t.checked, t.zero, t.one, t.clamped, t.bad, t.worst);
    CHECK(t.bad == 0, "variable: %ld receivers disagree", t.bad);
    CHECK(t.zero > t.checked / 50 && t.one > t.checked / 50 && t.clamped > t.checked / 100,
          "variable: the data do not cover shadow, light and the clamp");
    for (int k = 1; k <= CAP; k++)
        CHECK(per_order[k] > 1000, "variable: order %d: %ld vertices", k, per_order[k]);
    vr_renderer_destroy(r);
}

/* The buffer path against the attribute path on a baked scene. */
static void test_frames(const char *path)
{
    enum { FW = 160, FH = 120 };
    vr_error err;
    vr_scene *s = NULL;
    CHECK(vr_scene_create(&(vr_scene_desc){.path = path, .buffers = 1}, &s, &err) == VR_OK, "%s",
          err.msg);
    vr_renderer *r = NULL;
    vr_renderer_desc rd = {.width = FW, .height = FH, .color_format = VR_COLOR_RGBA32F};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    if (!s || !r) {
        vr_scene_destroy(s);
        vr_renderer_destroy(r);
        return;
    }
    vr_light lights[9];
    int n = vr_scene_default_lights(s, lights, 4);
    /* light 0 in front of the room's crate (bake/lib/builtin.c): its
     * shadow is in the default view */
    lights[0].position[0] = -4.0f;
    lights[0].position[1] = 3.5f;
    lights[0].position[2] = 1.0f;
    for (int i = n; i < 9; i++) {
        lights[i] = lights[i % n];
        lights[i].position[1] += 0.1f * (float)i;
    }
    static const vr_mode modes[3] = {VR_MODE_VDSH2, VR_MODE_VDSH3, VR_MODE_VDSH5};
    static const int orders[3] = {2, 3, 5};
    for (int m = 0; m < 3; m++)
        for (int v = 0; v < 3; v++) {
            vr_draw_desc d = {.mode = modes[m],
                              .lights = lights,
                              .light_count = v == 2 ? 9 : 3,
                              .output = v == 0 ? VR_OUTPUT_SHADOW : VR_OUTPUT_COLOR,
                              .ambient = {0.05f, 0.05f, 0.05f}};
            rt_draw_or_die(r, s, &d);
            float *a = rt_read(r, FW, FH);
            d.mode = VR_MODE_VDSH_BUFFER;
            d.stream = orders[m];
            rt_draw_or_die(r, s, &d);
            float *b = rt_read(r, FW, FH);
            double worst = 0.0, sum = 0.0;
            long lit = 0, dark = 0;
            for (int k = 0; k < FW * FH * 4; k++) {
                double e = fabs((double)a[k] - (double)b[k]);
                /* d_V and d_L: relative */
                if (v == 0 && (k & 3) != 0 && (k & 3) != 3)
                    e /= fmax(1.0, fabs((double)a[k]));
                worst = fmax(worst, e);
                sum += e;
                if (v == 0 && (k & 3) == 0 && a[k + 3] == 1.0f) {
                    lit += a[k] == 1.0f;
                    dark += a[k] < 0.5f;
                }
            }
            printf("frames order %d, %s: largest difference %.3g, mean %.3g\n", orders[m],
                   v == 0   ? "shadow of light 0"
                   : v == 1 ? "colour, 3 lights"
                            : "colour, 9 lights",
                   worst, sum / (FW * FH * 4));
            CHECK(worst <= 5e-4, "order %d view %d: buffer and attribute paths differ by %g",
                  orders[m], v, worst);
            if (v == 0)
                CHECK(lit > 100 && dark > 100, "the view shows too little: %ld lit, %ld dark", lit,
                      dark);
            free(a);
            free(b);
        }
    vr_renderer_destroy(r);
    vr_scene_destroy(s);
}

static void test_errors(const char *path)
{
    vr_error err;
    vr_scene *plain = NULL, *buffered = NULL, *floats = NULL;
    CHECK(vr_scene_create(&(vr_scene_desc){.path = path}, &plain, &err) == VR_OK, "%s", err.msg);
    CHECK(vr_scene_create(&(vr_scene_desc){.path = path, .buffers = 1}, &buffered, &err) == VR_OK,
          "%s", err.msg);
    CHECK(vr_scene_create(&(vr_scene_desc){.path = path, .buffers = 1, .buffer_floats = 1}, &floats,
                          &err) == VR_OK,
          "%s", err.msg);
    vdsh_file *f = NULL;
    vdsh_error ve;
    CHECK(vdsh_read(path, &f, &ve) == VDSH_OK, "%s", ve.msg);
    if (!plain || !buffered || !floats || !f)
        goto done;
    vr_scene_info pi, bi, fi;
    vr_scene_get_info(plain, &pi);
    vr_scene_get_info(buffered, &bi);
    vr_scene_get_info(floats, &fi);
    /* Orders 1-5 only as attributes by default: nothing buffered. */
    int any = 0;
    for (int o = 1; o <= VDSH_MAX_ORDER; o++)
        any |= pi.has_buffer[o];
    CHECK(!any && pi.buffer_bytes == 0 && !vr_scene_supports(plain, VR_MODE_VDSH_BUFFER),
          "a default load buffers orders 1-5");
    CHECK(vr_scene_buffer_stream(plain, 0) == 0, "a default load has a buffer stream");
    size_t want = 0, want_f = 0;
    int top = 0;
    for (uint32_t i = 0; i < f->stream_count; i++) {
        const vdsh_stream *st = &f->streams[i];
        if (st->quantity != bi.quantity)
            continue;
        /* the file's bytes, each record padded to whole texels: 4
         * coefficients (f32, f16, s8; s8s6 words need none) */
        size_t nc = (size_t)st->order * st->order, texels = (nc + 3) / 4;
        size_t bpv = vdsh_stream_bytes_per_vertex(st);
        size_t rec = st->encoding == VDSH_ENCODING_S8S6
                         ? (bpv + 3) / 4 * 4
                         : texels * vdsh_encoding_bytes(st->encoding, 4);
        want += (size_t)f->header.vertex_count * rec;
        want_f += (size_t)f->header.vertex_count * 16 * texels;
        CHECK(bi.has_buffer[st->order], "order %u not buffered", st->order);
        top = (int)st->order > top ? (int)st->order : top;
    }
    CHECK(bi.buffer_bytes == want, "buffer bytes %zu, not %zu", bi.buffer_bytes, want);
    size_t each = 0;
    for (int o = 1; o <= VDSH_MAX_ORDER; o++)
        each += vr_scene_buffer_bytes(buffered, o);
    CHECK(each == want && vr_scene_buffer_bytes(plain, top) == 0 &&
              vr_scene_buffer_bytes(buffered, VR_STREAM_VARIABLE) == 0,
          "vr_scene_buffer_bytes: %zu in all, not %zu", each, want);
    CHECK(fi.buffer_bytes == want_f, "float buffer bytes %zu, not %zu", fi.buffer_bytes, want_f);
    CHECK(bi.gpu_bytes == pi.gpu_bytes + want, "gpu bytes %zu, not %zu + %zu", bi.gpu_bytes,
          pi.gpu_bytes, want);
    printf("errors: buffers of %zu bytes as stored (padded to texels), %zu as floats\n", want,
           want_f);
    CHECK(vr_scene_buffer_stream(buffered, 0) == top, "default stream %d, not %d",
          vr_scene_buffer_stream(buffered, 0), top);
    CHECK(vr_scene_buffer_stream(buffered, VR_STREAM_VARIABLE) == 0, "a variable stream");
    CHECK(vr_scene_interp(buffered, VR_MODE_VDSH_BUFFER) == VDSH_INTERP_DISTANCE, "path");

    vr_renderer *r = NULL;
    CHECK(vr_renderer_create(&(vr_renderer_desc){.width = 32, .height = 24}, &r, &err) == VR_OK,
          "%s", err.msg);
    vr_light light = {.position = {0, 2, 0}};
    vr_draw_desc d = {.mode = VR_MODE_VDSH_BUFFER, .lights = &light, .light_count = 1};
    vr_result res = vr_draw(r, plain, &d, &err);
    CHECK(res == VR_ERR_MISSING && strstr(err.msg, "buffer"), "no buffers: %d %s", res, err.msg);
    d.stream = 3;
    res = vr_draw(r, plain, &d, &err);
    CHECK(res == VR_ERR_MISSING && strstr(err.msg, "vr_scene_desc.buffers"),
          "order 3 unbuffered: %d %s", res, err.msg);
    d.stream = VR_STREAM_VARIABLE;
    res = vr_draw(r, buffered, &d, &err);
    CHECK(res == VR_ERR_MISSING && strstr(err.msg, "order per vertex"), "variable: %d %s", res,
          err.msg);
    d.stream = 0;
    CHECK(vr_draw(r, buffered, &d, &err) == VR_OK, "%s", err.msg);
    vr_renderer_destroy(r);
done:
    vdsh_free(f);
    vr_scene_destroy(plain);
    vr_scene_destroy(buffered);
    vr_scene_destroy(floats);
}

/* A deterministic value in [-1, 1] for (vertex, index). */
static float hash_unit(uint32_t v, uint32_t i)
{
    uint64_t x = ((uint64_t)v << 32 | i) * 0x9e3779b97f4a7c15ull;
    x ^= x >> 29;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 32;
    return (float)(x & 0xffffff) / (float)0x7fffff - 1.0f;
}

/* derive IN OUT: IN's streams and, from its log-distance order-5 stream,
 * fixed streams of orders 7 (f16), 9 (s8s6) and 12 (s8) and one with an
 * order per vertex up to 11 (s8s6; k = 1 + (7v mod 11)): each keeps the
 * order-5 coefficients and adds small deterministic ones above band 4
 * (1 / l), so that every band changes the frames. Frames of these (vdsh-frames
 * truth against vdsh-view's buffer modes) check the GL path at orders the
 * baker has not made yet. Exit 0, or 1 naming the file. */
static int derive(const char *in, const char *out)
{
    vdsh_file *f = NULL;
    vdsh_error ve;
    if (vdsh_read(in, &f, &ve) != VDSH_OK) {
        fprintf(stderr, "derive: %s\n", ve.msg);
        return 1;
    }
    const vdsh_stream *base = vdsh_find_stream(f, 5, VDSH_QUANTITY_LOG_DISTANCE);
    if (!base || f->stream_count + 4 > VDSH_MAX_STREAMS) {
        fprintf(stderr, "derive: %s: no log-distance order-5 stream, or no room\n", in);
        vdsh_free(f);
        return 1;
    }
    enum { NEW = 4 };
    static const uint32_t orders[NEW] = {7, 9, 12, 11};
    static const uint32_t encs[NEW] = {VDSH_ENCODING_F16, VDSH_ENCODING_S8S6, VDSH_ENCODING_S8,
                                       VDSH_ENCODING_S8S6};
    uint32_t nv = f->header.vertex_count, cap2 = 12 * 12;
    vdsh_stream streams[VDSH_MAX_STREAMS];
    memcpy(streams, f->streams, f->stream_count * sizeof *streams);
    float *c = malloc((size_t)nv * cap2 * sizeof(float));
    void *mem[NEW][4] = {{0}};
    int rc = c ? 0 : 1;
    for (int n = 0; n < NEW && !rc; n++) {
        uint32_t k = orders[n], nc = k * k;
        for (uint32_t v = 0; v < nv; v++) {
            float c5[VDSH_MAX_COEFFS];
            vdsh_stream_decode(base, v, c5);
            for (uint32_t i = 0; i < nc; i++) {
                int l = (int)sqrtf((float)i);
                c[(size_t)v * nc + i] = i < 25 ? c5[i] : 1.0f / (float)l * hash_unit(v, i);
            }
        }
        vdsh_stream *st = &streams[f->stream_count + (uint32_t)n];
        *st = *base;
        st->order = k;
        st->encoding = encs[n];
        float *scales = calloc(nc, sizeof(float));
        mem[n][0] = scales;
        if (n < 3) {
            size_t bytes = (size_t)nv * vdsh_encoding_bytes(encs[n], nc);
            void *data = calloc(bytes + 4, 1);
            mem[n][1] = data;
            float mx = 0.0f;
            for (size_t i = 0; i < (size_t)nv * nc; i++)
                mx = fmaxf(mx, fabsf(c[i]));
            st->scale = encs[n] == VDSH_ENCODING_F16 ? mx : 1.0f;
            vdsh_result r = encs[n] == VDSH_ENCODING_F16
                                ? vdsh_encode_f16(c, (size_t)nv * nc, mx, data)
                                : vdsh_encode_quantised(encs[n], c, nv, nc, scales, data);
            rc = r != VDSH_OK;
            st->data = data;
            st->coef_scales = encs[n] == VDSH_ENCODING_F16 ? NULL : scales;
        } else {
            uint8_t *ko = malloc(nv);
            uint32_t *off = malloc(((size_t)nv + 1) * sizeof *off);
            mem[n][2] = ko;
            mem[n][3] = off;
            for (uint32_t v = 0; v < nv; v++)
                ko[v] = (uint8_t)(1 + (7 * v) % k);
            vdsh_stream_offsets(ko, nv, encs[n], off);
            void *data = calloc(4 * (size_t)off[nv] + 4, 1);
            mem[n][1] = data;
            rc =
                vdsh_encode_variable(encs[n], c, nc, ko, nv, k, 1.0f, off, scales, data) != VDSH_OK;
            st->scale = 1.0f;
            st->data = data;
            st->coef_scales = scales;
            st->flags = VDSH_STREAM_VARIABLE;
            st->orders = ko;
            st->offsets = off;
        }
    }
    if (!rc) {
        vdsh_file g = *f;
        g.streams = streams;
        g.stream_count = f->stream_count + NEW;
        if (vdsh_write(out, &g, &ve) != VDSH_OK) {
            fprintf(stderr, "derive: %s\n", ve.msg);
            rc = 1;
        }
    } else
        fprintf(stderr, "derive: %s: cannot encode the derived streams\n", out);
    for (int n = 0; n < NEW; n++)
        for (int k = 0; k < 4; k++)
            free(mem[n][k]);
    free(c);
    vdsh_free(f);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc == 4 && !strcmp(argv[1], "derive"))
        return derive(argv[2], argv[3]);
    if (argc != 3 ||
        (strcmp(argv[1], "vertex") && strcmp(argv[1], "frames") && strcmp(argv[1], "errors"))) {
        fprintf(stderr, "usage: test_runtime_buffer vertex|frames|errors SCENE.vdsh\n"
                        "       test_runtime_buffer derive IN.vdsh OUT.vdsh\n");
        return 2;
    }
    vr_context *ctx = rt_context_or_skip(argv[1]);
    if (!strcmp(argv[1], "vertex")) {
        test_vertex();
        test_variable();
    } else if (!strcmp(argv[1], "frames"))
        test_frames(argv[2]);
    else
        test_errors(argv[2]);
    vr_context_destroy(ctx);
    return test_report(argv[1]);
}
