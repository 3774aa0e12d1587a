/*
 * test_runtime_errors.c - bad input ends in a clear error, never a crash:
 * missing, empty, truncated and corrupted .vdsh files, a cube_size no GL
 * holds, streams a mode needs but the file lacks, and bad arguments; and
 * no file beside the .vdsh is needed (the basis cubemaps are made). Every
 * failure must name the file (or the argument), leave the output
 * untouched, and leave nothing allocated (the sanitizer build checks
 * that).
 */
#include "test_runtime_util.h"
#include "vdsh_sdf.h"

#include <unistd.h>

static vr_scene *const SENTINEL = (vr_scene *)(uintptr_t)0x5e7;

static int spit(const char *path, const void *data, size_t size)
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return -1;
    int ok = fwrite(data, 1, size, fp) == size;
    return fclose(fp) == 0 && ok ? 0 : -1;
}

/* Create a scene from `path` and expect `want` with `needle` in the
 * message (the file it names) and *out untouched. */
static void expect_fail(const char *what, const vr_scene_desc *sd, vr_result want,
                        const char *needle)
{
    vr_scene *s = SENTINEL;
    vr_error err = {{0}};
    vr_result r = vr_scene_create(sd, &s, &err);
    CHECK(r == want, "%s: got %s (%s), want %s", what, vr_result_str(r), err.msg,
          vr_result_str(want));
    CHECK(s == SENTINEL, "%s: output changed on failure", what);
    CHECK(!needle || strstr(err.msg, needle), "%s: message '%s' does not name '%s'", what, err.msg,
          needle);
    if (r == VR_OK && s != SENTINEL)
        vr_scene_destroy(s);
    printf("%-28s -> %s: %s\n", what, vr_result_str(r), err.msg);
}

/* A small valid scene on disk: a quad with orders 3 and 5. */
static void small_file(rt_file *f, int with5)
{
    rt_file_unit_quad(f);
    float *c3 = calloc(4 * 9, sizeof(float));
    for (int i = 0; i < 4; i++)
        c3[9 * i] = 5.0f;
    rt_file_add_stream(f, 3, VDSH_ENCODING_F16, 0, c3, 0.01f);
    if (with5) {
        float *c5 = calloc(4 * 25, sizeof(float));
        for (int i = 0; i < 4; i++)
            c5[25 * i] = 5.0f;
        rt_file_add_stream(f, 5, VDSH_ENCODING_F32, 0, c5, 1.0f);
    }
}

static void test_files(const char *dir)
{
    char path[512], bad[700], exr[600];
    rt_file f;
    small_file(&f, 1);
    CHECK(rt_file_write(&f, dir, "good", path, sizeof path) == 0, "write");
    /* From memory the reader's checks do not run: a max distance (the
     * clamp of every reconstructed distance) that is not finite and > 0
     * is refused by the scene itself. */
    const float bad_md[3] = {0.0f, -1.0f, INFINITY};
    for (int i = 0; i < 4; i++) {
        f.f.header.max_distance = i < 3 ? bad_md[i] : NAN;
        vr_scene_desc md = {.file = &f.f, .skip_cubemaps = 1};
        expect_fail("bad max distance in memory", &md, VR_ERR_FORMAT, "max_distance");
    }
    rt_file_free(&f);
    vr_scene_desc sd = {.path = path};
    vr_scene *s = NULL;
    vr_error err;
    CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "the good file: %s", err.msg);
    vr_scene_destroy(s);

    /* The file itself. */
    snprintf(bad, sizeof bad, "%s/does-not-exist.vdsh", dir);
    sd.path = bad;
    expect_fail("missing file", &sd, VR_ERR_IO, "does-not-exist.vdsh");

    unsigned char *data = NULL;
    size_t size = 0;
    CHECK((data = test_read_file(path, &size)) != NULL, "read %s", path);
    snprintf(bad, sizeof bad, "%s/bad.vdsh", dir);
    sd.path = bad;
    spit(bad, data, 0);
    expect_fail("empty file", &sd, VR_ERR_FORMAT, "bad.vdsh");
    spit(bad, data, size / 2);
    expect_fail("truncated file", &sd, VR_ERR_FORMAT, "bad.vdsh");
    spit(bad, "\x89PNG\r\n\x1a\n0000000000000000000000000000000000", 40);
    expect_fail("not a .vdsh file", &sd, VR_ERR_FORMAT, "bad.vdsh");
    data[size / 2] ^= 0x40;
    spit(bad, data, size);
    expect_fail("one bit flipped", &sd, VR_ERR_FORMAT, "bad.vdsh");
    data[size / 2] ^= 0x40;

    /* Corruption anywhere: an error (or, for bytes nothing checks, a
     * scene), never a crash. */
    uint64_t rng = 77;
    int failed = 0, loaded = 0;
    for (int i = 0; i < 300; i++) {
        unsigned char *copy = malloc(size);
        memcpy(copy, data, size);
        int flips = 1 + (int)(test_rand(&rng) * 4);
        for (int k = 0; k < flips; k++)
            copy[(size_t)(test_rand(&rng) * (double)size)] ^=
                (unsigned char)(1 + test_rand(&rng) * 255);
        size_t n = test_rand(&rng) < 0.2 ? (size_t)(test_rand(&rng) * (double)size) : size;
        spit(bad, copy, n);
        free(copy);
        vr_scene *t = SENTINEL;
        vr_result r = vr_scene_create(&sd, &t, &err);
        if (r == VR_OK) {
            loaded++;
            vr_scene_destroy(t);
        } else {
            failed++;
            CHECK(t == SENTINEL && strstr(err.msg, "bad.vdsh"), "corruption %d: %s", i, err.msg);
        }
    }
    printf("random corruption: %d rejected, %d loaded\n", failed, loaded);
    free(data);

    /* The basis cubemaps: made by the runtime, no file read. The .vdsh
     * alone (rt_file_write writes nothing else) draws order 5 with them,
     * and so it does with garbage under the names of the bake's files
     * beside it. */
    sd.path = path;
    for (int pass = 0; pass < 2; pass++) {
        static const char *const names[4] = {"sh09-12", "sh13-16", "sh17-20", "sh21-24"};
        for (int k = 0; pass == 1 && k < 4; k++) {
            snprintf(exr, sizeof exr, "%s/good.%s.exr", dir, names[k]);
            spit(exr, "not an exr file at all", 22);
        }
        s = NULL;
        CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "the .vdsh alone, pass %d: %s", pass,
              err.msg);
        if (!s)
            continue;
        vr_scene_info info;
        vr_scene_get_info(s, &info);
        CHECK(info.has_cubemaps && info.cube_size == 64, "cubemaps %d of %d", info.has_cubemaps,
              info.cube_size);
        vr_renderer *r = NULL;
        vr_renderer_desc rd = {.width = 8, .height = 8};
        CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
        vr_light light = {.position = {0, 0, 1}};
        vr_draw_desc d = {.mode = VR_MODE_VDSH5, .lights = &light, .light_count = 1};
        CHECK(r && vr_draw(r, s, &d, &err) == VR_OK, "vdsh5 of the .vdsh alone: %s", err.msg);
        vr_renderer_destroy(r);
        vr_scene_destroy(s);
    }
    /* without cubemaps: order 5 only through the polynomials */
    sd.skip_cubemaps = 1;
    s = NULL;
    CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "skip_cubemaps: %s", err.msg);
    sd.skip_cubemaps = 0;
    if (s) {
        vr_renderer *r = NULL;
        vr_renderer_desc rd = {.width = 8, .height = 8};
        CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
        vr_light light = {.position = {0, 0, 1}};
        vr_draw_desc d = {.mode = VR_MODE_VDSH5, .lights = &light, .light_count = 1};
        vr_result res = vr_draw(r, s, &d, &err);
        CHECK(res == VR_ERR_MISSING && strstr(err.msg, "cubemap"), "vdsh5 without cubemaps: %s",
              err.msg);
        d.mode = VR_MODE_VDSH5_POLY;
        CHECK(vr_draw(r, s, &d, &err) == VR_OK, "vdsh5poly: %s", err.msg);
        CHECK(!vr_scene_supports(s, VR_MODE_VDSH5) && vr_scene_supports(s, VR_MODE_VDSH5_POLY),
              "supports");
        vr_scene_info info;
        vr_scene_get_info(s, &info);
        CHECK(!info.has_cubemaps && info.cube_size == 0, "skipped cubemaps reported");
        vr_renderer_destroy(r);
        vr_scene_destroy(s);
    }
    /* A companion distance volume (good.sdf beside good.vdsh) baked beside
     * another bake, as an earlier `vdsh-bake --sdf` of the same output
     * leaves it when the next bake has no --sdf: the scene loads (it
     * failed, and vdsh-view drew nothing in any mode), mode sdf says why;
     * the same file named with sdf_path fails the load. */
    {
        char sdf[600];
        snprintf(sdf, sizeof sdf, "%s/good.sdf", dir);
        uint16_t samples[8] = {40000, 40000, 40000, 40000, 40000, 40000, 40000, 40000};
        vdsh_sdf v = {.dim = {2, 2, 2},
                      .origin = {-1, -1, -1},
                      .cell = 2,
                      .max_distance = 4,
                      .vertex_count = 9999,
                      .triangle_count = 1,
                      .samples = samples};
        vdsh_error ve;
        CHECK(vdsh_sdf_write(sdf, &v, &ve) == VDSH_OK, "write %s: %s", sdf, ve.msg);
        sd.path = path;
        s = NULL;
        CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "stale companion volume: %s", err.msg);
        if (s) {
            CHECK(!vr_scene_supports(s, VR_MODE_SDF), "stale companion volume loaded");
            vr_renderer *r = NULL;
            vr_renderer_desc rd = {.width = 8, .height = 8};
            CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
            vr_light light = {.position = {0, 0, 1}};
            vr_draw_desc d = {.mode = VR_MODE_SDF, .lights = &light, .light_count = 1};
            vr_result res = r ? vr_draw(r, s, &d, &err) : VR_ERR_GL;
            CHECK(res == VR_ERR_MISSING && strstr(err.msg, "good.sdf") &&
                      strstr(err.msg, "another bake"),
                  "mode sdf with a stale companion: %s", err.msg);
            printf("%-28s -> %s: %s\n", "stale companion volume", vr_result_str(res), err.msg);
            d.mode = VR_MODE_VDSH3;
            CHECK(r && vr_draw(r, s, &d, &err) == VR_OK, "vdsh3 beside a stale volume: %s",
                  err.msg);
            vr_renderer_destroy(r);
            vr_scene_destroy(s);
        }
        vr_scene_desc named = {.path = path, .sdf_path = sdf};
        expect_fail("stale volume named", &named, VR_ERR_FORMAT, "good.sdf");
        unlink(sdf);
    }
    /* A light box from the caller, which no reader has checked, is
     * refused by the first axis that is not finite with min below max. */
    {
        vr_scene_desc lb = {
            .path = path, .light_region = VR_LIGHT_REGION_BOX, .light_box = {0, 0, 0, 1, NAN, 1}};
        expect_fail("light box y not finite", &lb, VR_ERR_ARGUMENT, "light region's y");
        lb.light_box[4] = 1;
        lb.light_box[2] = 2;
        expect_fail("light box z min above max", &lb, VR_ERR_ARGUMENT, "light region's z");
    }
    /* Where to decode and sum: an unknown choice is refused by name. */
    {
        vr_scene_desc w = {.path = path, .sums = 3};
        expect_fail("sums 3", &w, VR_ERR_ARGUMENT, "sums 3");
        w.sums = VR_SUMS_VERTEX;
        w.cpca_decode = -1;
        expect_fail("cpca_decode -1", &w, VR_ERR_ARGUMENT, "cpca_decode -1");
    }
    /* A cube_size no GL can hold is refused by name before anything is
     * allocated for it; cube_size 0 means none (vdsh5 unavailable). */
    {
        rt_file big;
        small_file(&big, 1);
        big.f.header.cube_size = 1u << 30;
        vr_scene_desc bd = {.file = &big.f};
        expect_fail("cube_size 2^30", &bd, VR_ERR_FORMAT, "cube_size");
        big.f.header.cube_size = 0;
        s = NULL;
        CHECK(vr_scene_create(&bd, &s, &err) == VR_OK, "cube_size 0: %s", err.msg);
        if (s)
            CHECK(!vr_scene_supports(s, VR_MODE_VDSH5) &&
                      vr_scene_supports(s, VR_MODE_VDSH5_POLY) &&
                      vr_scene_default_mode(s) == VR_MODE_VDSH5_POLY,
                  "cube_size 0: vdsh5 without cubemaps");
        vr_scene_destroy(s);
        rt_file_free(&big);
    }

    /* A log-distance file (vdsh-bake --log): drawn per vertex in every
     * VDSH mode, so its cubemaps are never needed: none on disk, or
     * corrupt ones beside it, and the default descriptor still loads it
     * and draws order 5 both ways. */
    rt_file lf;
    rt_file_unit_quad(&lf);
    static const int orders[3] = {2, 3, 5};
    for (int o = 0; o < 3; o++) {
        float *c = calloc(4 * 25, sizeof(float));
        for (int i = 0; i < 4; i++)
            c[orders[o] * orders[o] * i] = 3.0f;
        rt_file_add_stream(&lf, (uint32_t)orders[o], VDSH_ENCODING_F16, VDSH_QUANTITY_LOG_DISTANCE,
                           c, 0.01f);
    }
    char logpath[600];
    snprintf(logpath, sizeof logpath, "%s/log.vdsh", dir);
    vdsh_error ve;
    CHECK(vdsh_write(logpath, &lf.f, &ve) == VDSH_OK, "%s", ve.msg);
    rt_file_free(&lf);
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) /* garbage under the cubemaps' names beside it */
            for (int k = 0; k < 4; k++) {
                snprintf(exr, sizeof exr, "%s/log.sh%02d-%02d.exr", dir, 9 + 4 * k, 12 + 4 * k);
                spit(exr, "not an exr file at all", 22);
            }
        vr_scene_desc ld = {.path = logpath};
        s = NULL;
        CHECK(vr_scene_create(&ld, &s, &err) == VR_OK, "log-distance, pass %d: %s", pass, err.msg);
        if (!s)
            continue;
        vr_scene_info info;
        vr_scene_get_info(s, &info);
        CHECK(info.quantity == VDSH_QUANTITY_LOG_DISTANCE && !info.has_cubemaps &&
                  info.has_order[2] && info.has_order[3] && info.has_order[5],
              "log-distance info");
        vr_renderer *r = NULL;
        vr_renderer_desc rd = {.width = 8, .height = 8};
        CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
        vr_light light = {.position = {0, 0, 1}};
        for (int m = VR_MODE_VDSH2; m <= VR_MODE_VDSH5_POLY && r; m++) {
            vr_draw_desc d = {.mode = (uint32_t)m, .lights = &light, .light_count = 1};
            CHECK(vr_scene_supports(s, (vr_mode)m) &&
                      vr_scene_interp(s, (vr_mode)m) == VDSH_INTERP_DISTANCE,
                  "log-distance %s: supported, distance path", vr_mode_name((vr_mode)m));
            CHECK(vr_draw(r, s, &d, &err) == VR_OK, "log-distance %s: %s", vr_mode_name((vr_mode)m),
                  err.msg);
            CHECK(strstr(vr_scene_mode_label(s, (vr_mode)m), "log, per-vertex") != NULL, "label %s",
                  vr_scene_mode_label(s, (vr_mode)m));
        }
        CHECK(strcmp(vr_scene_mode_label(s, VR_MODE_VDSH5),
                     "VDSH order 5 (25 coeff., log, per-vertex)") == 0,
              "label");
        CHECK(vr_scene_interp(s, VR_MODE_CUBE) == -1, "cube has no path");
        vr_renderer_destroy(r);
        vr_scene_destroy(s);
    }
}

static void test_streams_and_arguments(const char *dir)
{
    char path[512];
    rt_file f;
    small_file(&f, 0);
    CHECK(rt_file_write(&f, dir, "only3", path, sizeof path) == 0, "write");
    vr_scene *s = NULL;
    vr_renderer *r = NULL;
    vr_error err;
    vr_scene_desc sd = {.path = path};
    CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "%s", err.msg);
    vr_renderer_desc rd = {.width = 16, .height = 16};
    CHECK(vr_renderer_create(&rd, &r, &err) == VR_OK, "%s", err.msg);
    if (!s || !r)
        return;
    vr_light light = {.position = {0, 0, 1}};
    vr_draw_desc d = {.lights = &light, .light_count = 1};
    static const vr_mode missing[3] = {VR_MODE_VDSH2, VR_MODE_VDSH5, VR_MODE_VDSH5_POLY};
    for (int i = 0; i < 3; i++) {
        d.mode = missing[i];
        vr_result res = vr_draw(r, s, &d, &err);
        CHECK(res == VR_ERR_MISSING && strstr(err.msg, "stream"), "%s: %s",
              vr_mode_name(missing[i]), err.msg);
    }
    /* The default is the best mode the file has: here order 3. */
    CHECK(vr_scene_default_mode(s) == VR_MODE_VDSH3, "default mode %s",
          vr_mode_name(vr_scene_default_mode(s)));
    d.mode = VR_MODE_DEFAULT;
    CHECK(vr_draw(r, s, &d, &err) == VR_OK, "default mode: %s", err.msg);
    /* A file with no stream of orders 2, 3 or 5 (order 1 alone, which no
     * attribute mode draws): its stream is buffered and the default draws
     * it (it asked for order 5 and failed, where vdsh-view --mode buf1
     * and the web page drew it). */
    {
        rt_file f1;
        small_file(&f1, 0);
        f1.f.stream_count = 0;
        free(f1.coef[0]);
        free(f1.data[0]);
        f1.coef[0] = NULL;
        f1.data[0] = NULL;
        float *c1 = calloc(4, sizeof(float));
        for (int i = 0; i < 4; i++)
            c1[i] = 5.0f;
        rt_file_add_stream(&f1, 1, VDSH_ENCODING_F32, 0, c1, 1.0f);
        vr_scene *s1 = NULL;
        vr_scene_desc d1 = {.file = &f1.f};
        CHECK(vr_scene_create(&d1, &s1, &err) == VR_OK, "order 1 alone: %s", err.msg);
        if (s1) {
            CHECK(vr_scene_default_mode(s1) == VR_MODE_VDSH_BUFFER &&
                      vr_scene_supports(s1, VR_MODE_DEFAULT) && vr_scene_buffer_stream(s1, 0) == 1,
                  "order 1 alone: default %s", vr_mode_name(vr_scene_default_mode(s1)));
            d.mode = VR_MODE_DEFAULT;
            CHECK(vr_draw(r, s1, &d, &err) == VR_OK, "order 1 alone, default mode: %s", err.msg);
        }
        vr_scene_destroy(s1);
        rt_file_free(&f1);
    }
    d.mode = VR_MODE_VDSH3;
    CHECK(vr_draw(r, s, &d, &err) == VR_OK, "vdsh3: %s", err.msg);

    /* Arguments. */
    d.mode = 99;
    CHECK(vr_draw(r, s, &d, &err) == VR_ERR_ARGUMENT, "mode 99");
    d.mode = VR_MODE_VDSH3;
    d.compare = 7;
    CHECK(vr_draw(r, s, &d, &err) == VR_ERR_ARGUMENT, "compare 7");
    d.compare = 0;
    d.output = 5;
    CHECK(vr_draw(r, s, &d, &err) == VR_ERR_ARGUMENT, "output 5");
    d.output = 0;
    light.position[1] = NAN;
    CHECK(vr_draw(r, s, &d, &err) == VR_ERR_ARGUMENT && strstr(err.msg, "light 0"), "NaN light");
    light.position[1] = 0.0f;
    d.lights = NULL;
    CHECK(vr_draw(r, s, &d, &err) == VR_ERR_ARGUMENT, "lights NULL");
    d.lights = &light;
    CHECK(vr_draw(NULL, s, &d, &err) == VR_ERR_ARGUMENT, "NULL renderer");
    CHECK(vr_draw(r, NULL, &d, &err) == VR_ERR_ARGUMENT, "NULL scene");
    CHECK(vr_draw(r, s, NULL, &err) == VR_ERR_ARGUMENT, "NULL desc");
    /* a light count of zero is fine: ambient only */
    d.light_count = 0;
    CHECK(vr_draw(r, s, &d, &err) == VR_OK, "no lights: %s", err.msg);

    unsigned char small[16];
    memset(small, 0xab, sizeof small);
    CHECK(vr_read_pixels(r, small, sizeof small, &err) == VR_ERR_ARGUMENT, "small buffer");
    CHECK(small[0] == 0xab, "buffer changed on failure");
    CHECK(vr_renderer_resize(r, 0, 10, &err) == VR_ERR_ARGUMENT, "resize 0");
    int w, h;
    vr_renderer_size(r, &w, &h);
    CHECK(w == 16 && h == 16, "size changed on failure: %dx%d", w, h);
    CHECK(vr_renderer_resize(r, 40, 30, &err) == VR_OK, "resize: %s", err.msg);
    vr_renderer_size(r, &w, &h);
    CHECK(w == 40 && h == 30, "resize: %dx%d", w, h);

    vr_renderer *r2 = (vr_renderer *)(uintptr_t)0x5e7;
    vr_renderer_desc bad = {.width = -4, .height = 4};
    CHECK(vr_renderer_create(&bad, &r2, &err) == VR_ERR_ARGUMENT, "width -4");
    bad = (vr_renderer_desc){.max_lights_per_pass = 9};
    CHECK(vr_renderer_create(&bad, &r2, &err) == VR_ERR_ARGUMENT, "9 lights per pass");
    bad = (vr_renderer_desc){.shadow_map_size = -1};
    CHECK(vr_renderer_create(&bad, &r2, &err) == VR_ERR_ARGUMENT, "shadow size");
    CHECK(r2 == (vr_renderer *)(uintptr_t)0x5e7, "output changed on failure");
    CHECK(vr_draw_text(r, 2, 2, 1.0f, NULL, "text ok", &err) == VR_OK, "text: %s", err.msg);

    vr_scene_desc none = {0};
    vr_scene *s2 = SENTINEL;
    CHECK(vr_scene_create(&none, &s2, &err) == VR_ERR_ARGUMENT && s2 == SENTINEL, "no path");
    vr_scene_desc q = {.path = path, .quantity = 3};
    CHECK(vr_scene_create(&q, &s2, &err) == VR_ERR_ARGUMENT && s2 == SENTINEL, "quantity 3");
    /* a quantity the file does not have: its own quantity is drawn */
    q.quantity = VDSH_QUANTITY_LOG_DISTANCE;
    s2 = NULL;
    CHECK(vr_scene_create(&q, &s2, &err) == VR_OK, "%s", err.msg);
    vr_scene_info info;
    if (s2) {
        vr_scene_get_info(s2, &info);
        CHECK(info.quantity == VDSH_QUANTITY_DISTANCE && info.has_order[3], "fallback: %s",
              vdsh_quantity_name(info.quantity));
        d.light_count = 1;
        d.mode = VR_MODE_VDSH3;
        CHECK(vr_draw(r, s2, &d, &err) == VR_OK, "fallback vdsh3: %s", err.msg);
        d.mode = VR_MODE_VDSH5;
        CHECK(vr_draw(r, s2, &d, &err) == VR_ERR_MISSING && strstr(err.msg, "order-5 distance"),
              "no order 5: %s", err.msg);
        vr_scene_destroy(s2);
    }

    vr_scene_destroy(NULL);
    vr_renderer_destroy(NULL);
    vr_context_destroy(NULL);
    CHECK(strcmp(vr_result_str(VR_ERR_MISSING), "missing stream or file") == 0, "result str");
    CHECK(strcmp(vr_result_str((vr_result)99), "unknown result") == 0, "result str 99");
    vr_mode m = VR_MODE_NONE;
    CHECK(vr_mode_from_name("vdsh5poly", &m) == 0 && m == VR_MODE_VDSH5_POLY, "mode name");
    CHECK(vr_mode_from_name("bogus", &m) != 0 && m == VR_MODE_VDSH5_POLY, "bad mode name");
    vr_renderer_destroy(r);
    vr_scene_destroy(s);
    rt_file_free(&f);
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "runtime_errors";
    mkdir(dir, 0777);
    vr_context *ctx = rt_context_or_skip("test_runtime_errors");
    test_files(dir);
    test_streams_and_arguments(dir);
    vr_context_destroy(ctx);
    return test_report("test_runtime_errors");
}
