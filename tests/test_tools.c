/*
 * test_tools.c - tools/: the number rules every program's options follow
 * (vt_cli.h), the JSON every program writes and reads (vt_json.h), 16-bit
 * PNG frames (vt_image.h), view sets (vt_views.h) and the camera they use
 * (formats/vdsh_camera.h).
 *
 *   test_tools WORK_DIR
 */
#include "test_util.h"
#include "vt_cli.h"
#include "vt_json.h"
#include "vt_image.h"
#include "vt_views.h"
#include "vdsh_camera.h"

#include <float.h>
#include <math.h>
#include <png.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *work;

static void test_integers(void)
{
    uint64_t u = 7;
    CHECK(vt_parse_u64("010", 0, 100, &u) && u == 10, "010 is ten (decimal), got %llu",
          (unsigned long long)u);
    CHECK(vt_parse_u64("0", 0, 5, &u) && u == 0, "0");
    CHECK(vt_parse_u64("18446744073709551615", 0, UINT64_MAX, &u) && u == UINT64_MAX, "2^64 - 1");
    static const char *const bad[] = {"",
                                      "18446744073709551616",
                                      "99999999999999999999999",
                                      "0x10",
                                      "1e3",
                                      "12abc",
                                      " 12",
                                      "12 ",
                                      "+1",
                                      "-1",
                                      "1,2",
                                      "1.0",
                                      "\t1",
                                      "１"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        u = 7;
        CHECK(!vt_parse_u64(bad[i], 0, UINT64_MAX, &u) && u == 7, "'%s' refused, output untouched",
              bad[i]);
    }
    CHECK(!vt_parse_u64("0", 1, 10, &u) && !vt_parse_u64("11", 1, 10, &u) &&
              vt_parse_u64("10", 1, 10, &u),
          "range lo..hi, both included");
    uint32_t v = 3;
    CHECK(!vt_parse_u32("4294967296", 0, UINT32_MAX, &v) && v == 3 &&
              vt_parse_u32("4294967295", 0, UINT32_MAX, &v) && v == UINT32_MAX,
          "u32 range");
    int i = 5;
    CHECK(vt_parse_int("-12", -20, 20, &i) && i == -12, "negative int");
    CHECK(vt_parse_int("007", 0, 20, &i) && i == 7, "007");
    CHECK(!vt_parse_int("-", -5, 5, &i) && !vt_parse_int("--1", -5, 5, &i) &&
              !vt_parse_int("99999999999999999999", INT32_MIN, INT32_MAX, &i) &&
              !vt_parse_int("-9223372036854775809", INT32_MIN, INT32_MAX, &i) &&
              !vt_parse_int("21", -20, 20, &i) && i == 7,
          "bad ints refused");
}

static void test_reals(void)
{
    float f = 9.0f;
    static const struct {
        const char *s;
        float v;
    } good[] = {{"0", 0.0f},    {"1.5", 1.5f}, {"-2", -2.0f},   {"+3.25", 3.25f},
                {".5", 0.5f},   {"5.", 5.0f},  {"1e-4", 1e-4f}, {"2.5E+3", 2500.0f},
                {"010", 10.0f}, {"-0", -0.0f}};
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++)
        CHECK(vt_parse_float(good[i].s, &f) && f == good[i].v, "'%s' -> %g", good[i].s, (double)f);
    static const char *const bad[] = {"",      ".",   "-",   "e5",   "1e",    "1e+",
                                      "0x1p3", "inf", "nan", "1e39", "1e-50", "1.5x",
                                      " 1",    "1 ",  "1,5", "--1",  "1..2",  "1e5.5"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        f = 9.0f;
        CHECK(!vt_parse_float(bad[i], &f) && f == 9.0f, "'%s' refused", bad[i]);
    }
    float l[6];
    CHECK(vt_parse_floats("1,-2.5,3e1", l, 3, 6) == 3 && l[0] == 1 && l[1] == -2.5f &&
              l[2] == 30.0f,
          "a list");
    static const char *const bad_lists[] = {"1,2",   "1,2,3,",        ",1,2,3", "1,,2,3",
                                            "1,2,x", "1,2,3,4,5,6,7", "1;2;3",  "1, 2, 3"};
    for (size_t i = 0; i < sizeof bad_lists / sizeof bad_lists[0]; i++)
        CHECK(vt_parse_floats(bad_lists[i], l, 3, 6) == 0, "list '%s' refused", bad_lists[i]);
    uint64_t o[5];
    CHECK(vt_parse_u64_list("2,3,05", 1, 5, o, 1, 5) == 3 && o[2] == 5, "u64 list");
    CHECK(vt_parse_u64_list("2,6", 1, 5, o, 1, 5) == 0 &&
              vt_parse_u64_list("", 1, 5, o, 1, 5) == 0 &&
              vt_parse_u64_list("2,", 1, 5, o, 1, 5) == 0 &&
              vt_parse_u64_list("1,2,3,4,5,1", 1, 5, o, 1, 5) == 0,
          "bad u64 lists refused");
    int w = 0, h = 0;
    CHECK(vt_parse_size("640x480", 1, 16384, &w, &h) && w == 640 && h == 480, "WxH");
    CHECK(vt_parse_size("08X09", 1, 16384, &w, &h) && w == 8 && h == 9, "WXH, decimal");
    static const char *const bad_sizes[] = {"640",       "640x",    "x480",     "0x480",   "640x0",
                                            "640x480x2", "16385x2", "-640x480", "640 x480"};
    for (size_t i = 0; i < sizeof bad_sizes / sizeof bad_sizes[0]; i++)
        CHECK(!vt_parse_size(bad_sizes[i], 1, 16384, &w, &h), "size '%s' refused", bad_sizes[i]);
}

/* Build a document, print it, parse it back with cJSON. */
static cJSON *round_trip(vt_json *j)
{
    char *text = vt_json_print(j);
    CHECK(text != NULL, "printed");
    cJSON *back = text ? cJSON_Parse(text) : NULL;
    CHECK(back != NULL, "parses: %s", text ? text : "");
    free(text);
    return back;
}

/* vt_list_item, the one splitter of every comma list (vt_parse_floats,
 * vdsh-view --frame-modes and --bench-modes, vdsh-frames --modes): each
 * item, empty ones too, for the caller to refuse. */
static void test_list_items(void)
{
    const struct {
        const char *s, *want;
    } cases[] = {{"a", "a|"},       {"", "|"},     {"ab,c", "ab|c|"},
                 {"a,,b", "a||b|"}, {"a,", "a||"}, {",", "||"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char got[64] = "";
        for (const char *p = cases[i].s, *next; p; p = next) {
            size_t len = vt_list_item(p, &next);
            strncat(got, p, len);
            strcat(got, "|");
        }
        CHECK(strcmp(got, cases[i].want) == 0, "'%s' split as %s, not %s", cases[i].s, got,
              cases[i].want);
    }
}

static void test_json_strings(void)
{
    static const char *const s[] = {"plain",
                                    "q\"uote",
                                    "back\\slash",
                                    "tab\tnew\nline",
                                    "ctl\x01\x1f",
                                    "caf\xc3\xa9",
                                    "bad \xff byte",
                                    "cut \xc3",
                                    "overlong \xc0\xaf",
                                    "surrogate \xed\xa0\x80",
                                    "emoji \xf0\x9f\x99\x82"};
    static const char *const want[] = {"plain",
                                       "q\"uote",
                                       "back\\slash",
                                       "tab\tnew\nline",
                                       "ctl\x01\x1f",
                                       "caf\xc3\xa9",
                                       "bad \xef\xbf\xbd byte",
                                       "cut \xef\xbf\xbd",
                                       "overlong \xef\xbf\xbd\xef\xbf\xbd",
                                       "surrogate \xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd",
                                       "emoji \xf0\x9f\x99\x82"};
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    cJSON *a = vt_json_array(&j, root, "s");
    for (size_t i = 0; i < sizeof s / sizeof s[0]; i++)
        vt_json_string(&j, a, NULL, s[i]);
    vt_json_string(&j, root, "null", NULL);
    vt_json_string(&j, root, "k\"ey", "v");
    char *text = vt_json_print(&j);
    CHECK(text && text[strlen(text) - 1] == '\n', "ends in a newline");
    CHECK(text && !strchr(text, '\x01') && !strstr(text, "\xff"),
          "no raw control character or invalid byte in the output");
    free(text);
    cJSON *back = round_trip(&j);
    cJSON *ba = cJSON_GetObjectItemCaseSensitive(back, "s");
    for (size_t i = 0; i < sizeof s / sizeof s[0]; i++) {
        const cJSON *it = cJSON_GetArrayItem(ba, (int)i);
        CHECK(cJSON_IsString(it) && strcmp(it->valuestring, want[i]) == 0, "string %zu", i);
    }
    CHECK(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(back, "null")), "NULL is null");
    CHECK(cJSON_IsString(cJSON_GetObjectItemCaseSensitive(back, "k\"ey")), "keys escaped");
    cJSON_Delete(back);
    vt_json_free(&j);
}

static void test_json_numbers(void)
{
    enum { N = 2000 };
    static float f[N];
    static double d[N];
    uint64_t seed = 42;
    for (int i = 0; i < N; i++) {
        double r = test_rand(&seed);
        int e = (int)(test_rand(&seed) * 80.0) - 40;
        f[i] = (float)ldexp(r, e) * (i % 2 ? -1.0f : 1.0f);
        d[i] = ldexp(test_rand(&seed), (int)(test_rand(&seed) * 200.0) - 100);
    }
    f[0] = 0.1f, f[1] = FLT_MAX, f[2] = FLT_MIN, f[3] = -0.0f, f[4] = 16777217.0f;
    d[0] = 0.1 + 0.2, d[1] = DBL_MAX, d[2] = DBL_MIN, d[3] = 1.0 / 3.0, d[4] = 5e-324;
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    cJSON *fa = vt_json_array(&j, root, "f"), *da = vt_json_array(&j, root, "d");
    for (int i = 0; i < N; i++) {
        vt_json_f32(&j, fa, NULL, f[i]);
        vt_json_f64(&j, da, NULL, d[i]);
    }
    vt_json_u64(&j, root, "u", UINT64_MAX);
    vt_json_u64(&j, root, "u53", (1ull << 53) + 1);
    vt_json_i64(&j, root, "i", INT64_MIN);
    vt_json_f32(&j, root, "k1", NAN);
    vt_json_f64(&j, root, "k2", -INFINITY);
    vt_json_f32(&j, root, "tenth", 0.1f);
    vt_json_bool(&j, root, "yes", 7);
    char *text = vt_json_print(&j);
    CHECK(text && strstr(text, "\"u\":\t18446744073709551615") &&
              strstr(text, "\"u53\":\t9007199254740993") &&
              strstr(text, "\"i\":\t-9223372036854775808"),
          "whole numbers printed in full");
    CHECK(text && strstr(text, "\"tenth\":\t0.1,"), "the shortest float: 0.1, not 0.100000001");
    CHECK(text && strstr(text, "\"k1\":\tnull") && strstr(text, "\"k2\":\tnull") &&
              !strstr(text, "nan") && !strstr(text, "inf"),
          "NaN and Inf print as null, never as nan or inf");
    free(text);
    cJSON *back = round_trip(&j);
    cJSON *bf = cJSON_GetObjectItemCaseSensitive(back, "f"),
          *bd = cJSON_GetObjectItemCaseSensitive(back, "d");
    int exact_f = cJSON_GetArraySize(bf) == N, exact_d = cJSON_GetArraySize(bd) == N;
    for (int i = 0; i < N && exact_f && exact_d; i++) {
        float g = (float)cJSON_GetArrayItem(bf, i)->valuedouble;
        exact_f &= memcmp(&g, &f[i], sizeof g) == 0;
        exact_d &= cJSON_GetArrayItem(bd, i)->valuedouble == d[i];
        if (!exact_f || !exact_d)
            fprintf(stderr, "item %d: %.9g -> %.9g, %.17g -> %.17g\n", i, (double)f[i], (double)g,
                    d[i], cJSON_GetArrayItem(bd, i)->valuedouble);
    }
    CHECK(exact_f, "every float reads back as the same float");
    CHECK(exact_d, "every double reads back as the same double");
    CHECK(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(back, "k1")) &&
              cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(back, "k2")),
          "NaN and Inf are null");
    CHECK(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(back, "yes")), "bool");
    cJSON_Delete(back);
    vt_json_free(&j);

    /* Misuse marks the document failed: nothing half-built is printed. */
    vt_json bad = {0};
    cJSON *r = vt_json_object(&bad, NULL, NULL);
    vt_json_u64(&bad, r, NULL, 1); /* an object member needs a key */
    CHECK(bad.failed && vt_json_print(&bad) == NULL, "a failed document is not printed");
    vt_json_free(&bad);
}

static void test_json_files(void)
{
    char path[4200], msg[4400];
    snprintf(path, sizeof path, "%s/doc.json", work);
    vt_json j = {0};
    cJSON *root = vt_json_object(&j, NULL, NULL);
    cJSON *sec = vt_json_object(&j, root, "seconds");
    vt_json_f64(&j, sec, "total", 1.25);
    CHECK(vt_json_write_file(&j, path, msg, sizeof msg) == 0, "%s", msg);
    vt_json_free(&j);
    cJSON *back = vt_json_read_file(path, msg, sizeof msg);
    CHECK(back &&
              vt_json_number(cJSON_GetObjectItemCaseSensitive(back, "seconds"), "total") == 1.25,
          "read back: %s", back ? "" : msg);
    CHECK(isnan(vt_json_number(back, "absent")) && isnan(vt_json_number(back, "seconds")),
          "absent or not a number: NaN");
    cJSON_Delete(back);

    static const char *const bad[] = {"{\"a\": 1} trailing", "{\"a\": }", "", "{\"a\": NaN}"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        FILE *f = fopen(path, "wb");
        fputs(bad[i], f);
        fclose(f);
        back = vt_json_read_file(path, msg, sizeof msg);
        CHECK(!back && strstr(msg, path) && strstr(msg, "not JSON"), "'%s' refused: %s", bad[i],
              msg);
        cJSON_Delete(back);
    }
    snprintf(path, sizeof path, "%s/none.json", work);
    back = vt_json_read_file(path, msg, sizeof msg);
    CHECK(!back && strstr(msg, path) && strstr(msg, "cannot open"), "missing file: %s", msg);
    back = vt_json_read_file(work, msg, sizeof msg);
    CHECK(!back && strstr(msg, "not a regular file"), "a directory: %s", msg);
}

/* The camera's pixel-centre ray and its GL projection agree: a point on
 * the ray through pixel (x, y) projects onto that pixel's centre. */
static void test_camera(void)
{
    uint64_t seed = 7;
    for (int trial = 0; trial < 200; trial++) {
        vdsh_camera c;
        memset(&c, 0, sizeof c);
        for (int i = 0; i < 3; i++) {
            c.eye[i] = (float)(test_rand(&seed) * 20 - 10);
            c.target[i] = (float)(test_rand(&seed) * 20 - 10);
        }
        c.fov_y = (float)(20 + 100 * test_rand(&seed));
        int w = 64 + (int)(test_rand(&seed) * 900), h = 48 + (int)(test_rand(&seed) * 700);
        int x = (int)(test_rand(&seed) * w), y = (int)(test_rand(&seed) * h);
        float o[3], d[3], view[16], proj[16];
        vdsh_camera_ray(&c, w, h, x, y, o, d);
        vdsh_camera_view(&c, view);
        vdsh_camera_projection(&c, (float)w / (float)h, 0.01f, 100.0f, proj);
        float t = 3.0f, p[4] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2], 1.0f}, e[4],
              q[4];
        for (int r = 0; r < 4; r++) {
            e[r] = 0.0f;
            for (int k = 0; k < 4; k++)
                e[r] += view[k * 4 + r] * p[k];
        }
        for (int r = 0; r < 4; r++) {
            q[r] = 0.0f;
            for (int k = 0; k < 4; k++)
                q[r] += proj[k * 4 + r] * e[k];
        }
        float px = (q[0] / q[3] * 0.5f + 0.5f) * (float)w,
              py = (0.5f - q[1] / q[3] * 0.5f) * (float)h;
        CHECK(fabsf(px - (x + 0.5f)) < 2e-3f && fabsf(py - (y + 0.5f)) < 2e-3f,
              "camera %d: pixel (%d, %d) of %dx%d projects to (%g, %g)", trial, x, y, w, h, px, py);
    }
}

static void test_frames(void)
{
    char path[4200], msg[4400];
    snprintf(path, sizeof path, "%s/frame.png", work);
    enum { W = 37, H = 23 };
    float v[W * H], *back = NULL;
    for (int i = 0; i < W * H; i++)
        v[i] = (float)i / (W * H - 1);
    v[5] = -1.0f, v[6] = 2.0f, v[7] = NAN;
    CHECK(vt_png16_write(path, W, H, v, msg, sizeof msg) == 0, "%s", msg);
    int w = 0, h = 0;
    CHECK(vt_png16_read(path, &w, &h, &back, msg, sizeof msg) == 0 && w == W && h == H, "%s", msg);
    if (back) {
        float worst = 0.0f;
        v[5] = 0.0f, v[6] = 1.0f, v[7] = 0.0f; /* clamped; NaN reads 0 */
        for (int i = 0; i < W * H; i++)
            worst = fmaxf(worst, fabsf(back[i] - v[i]));
        CHECK(worst <= 0.5f / 65535.0f + 1e-7f, "16-bit round trip: off by %g", worst);
        free(back);
    }
    /* 8-bit grey: the samples as values (/ 255), not decoded as sRGB; a
     * PNG with colour or alpha is no frame: refused, saying which. */
    {
        png_image im;
        memset(&im, 0, sizeof im);
        im.version = PNG_IMAGE_VERSION, im.width = 3, im.height = 1, im.format = PNG_FORMAT_GRAY;
        const uint8_t grey[3] = {0, 128, 255};
        snprintf(path, sizeof path, "%s/grey8.png", work);
        CHECK(png_image_write_to_file(&im, path, 0, grey, 0, NULL), "write %s", path);
        back = NULL;
        CHECK(vt_png16_read(path, &w, &h, &back, msg, sizeof msg) == 0 && w == 3 && h == 1, "%s",
              msg);
        if (back) {
            CHECK(back[0] == 0.0f && fabsf(back[1] - 128.0f / 255.0f) < 1e-6f && back[2] == 1.0f,
                  "8-bit grey 0, 128, 255 read as %g, %g, %g", back[0], back[1], back[2]);
            free(back);
        }
        const uint8_t rgba[3 * 4] = {128, 128, 128, 255, 0, 0, 0, 255, 255, 255, 255, 128};
        snprintf(path, sizeof path, "%s/rgba.png", work);
        CHECK(vt_png_rgba_write(path, 3, 1, rgba, msg, sizeof msg) == 0, "%s", msg);
        back = NULL;
        CHECK(vt_png16_read(path, &w, &h, &back, msg, sizeof msg) == -1 && !back &&
                  strstr(msg, "rgba.png: an RGBA PNG, not a frame"),
              "an RGBA PNG read as a frame: %s", msg);
        im.format = PNG_FORMAT_RGB;
        const uint8_t rgb[9] = {10, 20, 30, 0, 0, 0, 255, 255, 255};
        snprintf(path, sizeof path, "%s/rgb.png", work);
        CHECK(png_image_write_to_file(&im, path, 0, rgb, 0, NULL), "write %s", path);
        CHECK(vt_png16_read(path, &w, &h, &back, msg, sizeof msg) == -1 &&
                  strstr(msg, "rgb.png: an RGB PNG, not a frame"),
              "an RGB PNG read as a frame: %s", msg);
    }
    snprintf(path, sizeof path, "%s/views.json", work);
    vt_view one = {.name = "a-1",
                   .camera = {{1, 2, 3}, {0, 1, 0}, {0, 1, 0}, 50},
                   .set_count = 2,
                   .light_count = {1, 3},
                   .lights = {{{1, 1, 1}}, {{2, 2, 2}, {3, 3, 3}, {4, 4.5f, 4}}}};
    vt_views vs = {.width = 320, .height = 200, .count = 1, .views = &one}, in = {0};
    CHECK(vt_views_write(path, &vs, msg, sizeof msg) == 0, "%s", msg);
    CHECK(vt_views_read(path, &in, msg, sizeof msg) == 0 && in.count == 1 && in.width == 320 &&
              !strcmp(in.views[0].name, "a-1") && in.views[0].light_count[1] == 3 &&
              in.views[0].lights[1][2][1] == 4.5f && in.views[0].camera.fov_y == 50.0f,
          "views round trip: %s", msg);
    vt_views_free(&in);
    static const char *const bad[] = {
        "{\"width\": 10, \"height\": 10, \"views\": []}",
        "{\"width\": 10, \"height\": 10, \"views\": [{\"name\": \"a b\", \"eye\": [0,0,0], "
        "\"target\": [1,0,0], \"light_sets\": [[[0,1,0]]]}]}",
        "{\"width\": 10, \"height\": 10, \"views\": [{\"name\": \"a\", \"eye\": [0,0,0], "
        "\"target\": [0,0,0], \"light_sets\": [[[0,1,0]]]}]}",
        "{\"width\": 10, \"height\": 10, \"views\": [{\"name\": \"a\", \"eye\": [0,0,0], "
        "\"target\": [1,0,0], \"light_sets\": [[]]}]}",
        "{\"width\": 0.5, \"height\": 10, \"views\": [{\"name\": \"a\", \"eye\": [0,0,0], "
        "\"target\": [1,0,0], \"light_sets\": [[[0,1,0]]]}]}",
        /* beyond +-1e18 (VDSH_VIEW_MAX_COORD): vdsh-frames truth aborted in
         * Embree (SIGABRT) on a light at 1e39 (inf as a float) or an eye at
         * 3e38, leaving its DIR.tmp.* folder */
        "{\"width\": 10, \"height\": 10, \"views\": [{\"name\": \"a\", \"eye\": [0,0,0], "
        "\"target\": [1,0,0], \"light_sets\": [[[1e39,1,0]]]}]}",
        "{\"width\": 10, \"height\": 10, \"views\": [{\"name\": \"a\", \"eye\": [0,-3e38,0], "
        "\"target\": [1,0,0], \"light_sets\": [[[0,1,0]]]}]}"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        FILE *f = fopen(path, "wb");
        fputs(bad[i], f);
        fclose(f);
        CHECK(vt_views_read(path, &in, msg, sizeof msg) == -1 && strstr(msg, path),
              "bad view set %zu accepted", i);
    }
}

/* The vt_opt_* checks (parse_args): the value, or the usage error naming
 * the option and its range, with *out untouched. */
static void test_options(void)
{
    char path[4096], text[2048] = "";
    snprintf(path, sizeof path, "%s/options.err", work);
    fflush(stderr);
    int saved = dup(2);
    CHECK(saved >= 0 && freopen(path, "w", stderr) != NULL, "stderr to %s", path);
    uint32_t u = 7;
    uint64_t s = 9;
    int i = 3, v = 5, want[17] = {0};
    float f = 2.0f;
    double t = 1.0;
    static const vt_choice names[] = {{"a", 1}, {"bb", 2}, {"c", 3}, {NULL, 0}};
    const int ok[] = {
        vt_opt_u32("--n", NULL, "256", 1, 256, &u) && u == 256,
        !vt_opt_u32("--n", NULL, "257", 1, 256, &u) && u == 256,
        !vt_opt_u32("--d", "", "0", 1, 1024, &u) && u == 256,
        !vt_opt_u64("--seed", NULL, "x", 0, UINT64_MAX, &s) && s == 9,
        !vt_opt_u64("--m", NULL, "0", 1, UINT64_MAX, &s) && s == 9,
        !vt_opt_int("--k", "an order", "-0", 0, 16, &i) && i == 3,
        vt_opt_int("--k", NULL, "-2", -5, 5, &i) && i == -2,
        !vt_opt_positive("--p", "0", &f) && f == 2.0f,
        vt_opt_nonnegative("--q", "-0", &f) && f == 0.0f,
        !vt_opt_nonnegative("--q", "-1", &f) && f == 0.0f,
        vt_opt_tolerance("--t", NULL, "inf", 0, &t) && isinf(t),
        !vt_opt_tolerance("--t", "a number", "0", 0, &t) && isinf(t),
        vt_opt_orders("--orders", "2,3,5", "5,2", 16, want) && want[2] && want[5] && !want[3],
        !vt_opt_orders("--orders", "2,3,5", "2,2", 16, want) && want[5],
        vt_opt_choice("--c", "bb", names, &v) && v == 2,
        !vt_opt_choice("--c", "d", names, &v) && v == 2,
    };
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; k++)
        CHECK(ok[k], "option check %zu", k);
    FILE *in = fopen(path, "rb");
    size_t n = in ? fread(text, 1, sizeof text - 1, in) : 0;
    text[n] = 0;
    if (in)
        fclose(in);
    static const char *const said[] = {
        "--n takes a whole number 1..256, not '257'",
        "--d takes 1..1024, not '0'",
        "--seed takes a whole number, not 'x'",
        "--m takes a whole number >= 1, not '0'",
        "--k takes an order 0..16, not '-0'",
        "--p takes a positive number, not '0'",
        "--q takes a number >= 0, not '-1'",
        "--t takes a number > 0 (or inf), not '0'",
        "--orders takes distinct orders 1..16 such as 2,3,5, not '2,2'",
        "--c takes a, bb or c, not 'd'"};
    char want_text[2048] = "";
    for (size_t k = 0; k < sizeof said / sizeof said[0]; k++)
        snprintf(want_text + strlen(want_text), sizeof want_text - strlen(want_text),
                 "%s: %s\nTry '%s --help'.\n", vt_cli_prog(), said[k], vt_cli_prog());
    CHECK(strcmp(text, want_text) == 0, "option messages:\n%s\nwanted:\n%s", text, want_text);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_tools WORK_DIR\n");
        return 2;
    }
    work = argv[1];
    mkdir(work, 0755);
    test_integers();
    test_reals();
    test_list_items();
    test_json_strings();
    test_json_numbers();
    test_json_files();
    test_camera();
    test_frames();
    test_options();
    return test_report("test_tools");
}
