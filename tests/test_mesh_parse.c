/*
 * test_mesh_parse.c - the strict readers (bake/lib/mesh_parse.h) on bytes in
 * memory: the values they produce where bakes depend on them (numbers as
 * std::istream reads them, OBJ corner normals, STL vertex merging, PLY
 * property layouts), and the files OpenMesh's readers misread that the
 * baker accepted before issue 13 (a face of an ascii PLY replaced by a
 * copy of the previous one, binary PLY coordinates read shifted) and now
 * refuses.
 *
 * Usage: test_mesh_parse [ASSIMP_MODELS]  (no data needed; with assimp's
 * test models, their concave polygon is checked too)
 */
#include "mesh.h"
#include "mesh_parse.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static vb_result parse(const char *name, vb_mesh_format f, const void *bytes, size_t size,
                       vb_mesh_raw *raw, vb_error *err)
{
    memset(raw, 0, sizeof *raw);
    err->msg[0] = 0;
    return vb_mesh_parse(name, f, (const uint8_t *)bytes, size, raw, err);
}

static vb_result parse_text(const char *name, vb_mesh_format f, const char *text, vb_mesh_raw *raw,
                            vb_error *err)
{
    return parse(name, f, text, strlen(text), raw, err);
}

static uint32_t bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

/* Refused, naming the input, with `needle` in the message. */
static void expect_refused(const char *name, vb_mesh_format f, const void *bytes, size_t size,
                           const char *needle)
{
    vb_mesh_raw raw;
    vb_error err;
    vb_result r = parse(name, f, bytes, size, &raw, &err);
    CHECK(r != VB_OK, "%s: accepted", name);
    CHECK(strncmp(err.msg, name, strlen(name)) == 0, "%s: message does not name it: %s", name,
          err.msg);
    CHECK(strstr(err.msg, needle) != NULL, "%s: message lacks '%s': %s", name, needle, err.msg);
    vb_mesh_raw_free(&raw);
}

/* Numbers: correctly rounded like strtof, down to signed zeros and
 * subnormals; a leading '+' and leading zeros are fine. */
static void test_numbers(void)
{
    vb_mesh_raw raw;
    vb_error err;
    const char *obj = "v 1e-50 -1e-50 1e-40\nv 3.4028235e38 0.1 -0\nv +5 007 1e+05\nf 1 2 3\n";
    CHECK(parse_text("n.obj", VB_MESH_OBJ, obj, &raw, &err) == VB_OK, "%s", err.msg);
    static const uint32_t want[9] = {0x00000000u, 0x80000000u, 0x000116c2u,
                                     0x7f7fffffu, 0x3dcccccdu, 0x80000000u,
                                     0x40a00000u, 0x40e00000u, 0x47c35000u};
    for (int i = 0; i < 9 && raw.vertex_count == 3; i++)
        CHECK(bits(raw.positions[i]) == want[i], "n.obj: coordinate %d: bits %08x, want %08x", i,
              bits(raw.positions[i]), want[i]);
    vb_mesh_raw_free(&raw);
    const char *big = "v 0 0 3.40282357e38\n", *hex = "v 0 0 0x10\n";
    expect_refused("r.obj", VB_MESH_OBJ, big, strlen(big), "out of float range");
    expect_refused("x.obj", VB_MESH_OBJ, hex, strlen(hex), "'0x10' is not a number");
}

/* OBJ normals: named per corner, forward or backward (negative); a
 * vertex given two normals keeps one per corner and their average per
 * vertex. "//0", a number past the "vn" lines and a negative one past those
 * so far are refused (before: they named no normal, silently). */
static void test_obj_normals(void)
{
    vb_mesh_raw raw;
    vb_error err;
    const char *obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\n"
                      "f 1//2 2//-1 3\n" /* 2: forward; -1: the last so far (1) */
                      "vn 1 0 0\n"
                      "f 2//2 4 3//-2\n"; /* -2: normal 1 */
    CHECK(parse_text("c.obj", VB_MESH_OBJ, obj, &raw, &err) == VB_OK, "%s", err.msg);
    if (raw.triangle_count == 2 && raw.corner_given && raw.has_normal) {
        static const uint8_t given[6] = {1, 1, 0, 1, 0, 1};
        for (int c = 0; c < 6; c++)
            CHECK(raw.corner_given[c] == given[c], "c.obj: corner %d given %u", c,
                  raw.corner_given[c]);
        CHECK(raw.corner_normals[0] == 1.0f, "c.obj: corner 0 takes normal 2 (forward)");
        CHECK(raw.corner_normals[5] == 1.0f && raw.corner_normals[9] == 1.0f &&
                  raw.corner_normals[17] == 1.0f,
              "c.obj: corner 1 normal -1 = 1, corner 3 normal 2, corner 5 normal -2 = 1");
        /* vertex 2 (index 1): normal 1 and normal 2, averaged */
        CHECK(raw.has_normal[0] && raw.has_normal[1] && raw.has_normal[2] && !raw.has_normal[3],
              "c.obj: has_normal %u %u %u %u", raw.has_normal[0], raw.has_normal[1],
              raw.has_normal[2], raw.has_normal[3]);
        CHECK(raw.normals[0] == 1.0f && raw.normals[8] == 1.0f && raw.normals[3] > 0.7f &&
                  raw.normals[3] == raw.normals[5],
              "c.obj: per-vertex normals");
    } else {
        CHECK(0, "c.obj: %u triangles, corner normals %p", raw.triangle_count,
              (void *)raw.corner_given);
    }
    vb_mesh_raw_free(&raw);
    static const char zero[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//0 3\n";
    static const char past[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2 3//9\n";
    static const char back[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//-1 2 3\nvn 0 0 1\n";
    expect_refused("z.obj", VB_MESH_OBJ, zero, strlen(zero), "normal index 0 out of range");
    expect_refused("p.obj", VB_MESH_OBJ, past, strlen(past),
                   "line 5: face corner '3//9': normal index 9 out of range");
    expect_refused("b.obj", VB_MESH_OBJ, back, strlen(back),
                   "line 4: face corner '1//-1': normal index -1 out of range");
    vb_mesh_raw_free(&raw);

    /* A line that starts with a vertical tab (after blanks) is skipped; a
     * vertex or face skipped that way is refused. */
    CHECK(parse_text("vt.obj", VB_MESH_OBJ, "v 0 0 0\nv 1 0 0\nv 0 1 0\n\vvn 0 0 1\nf 1//1 2 3\n",
                     &raw, &err) == VB_OK &&
              raw.normals == NULL,
          "vt.obj: %s", err.msg);
    vb_mesh_raw_free(&raw);
    const char *vline = "v 0 0 0\nv 1 0 0\n \vv 0 1 0\nf 1 2 3\n";
    expect_refused("vl.obj", VB_MESH_OBJ, vline, strlen(vline),
                   "line 3: a vertex line starting with a vertical tab");
    /* A UTF-8 byte order mark before the first line is not part of it:
     * the first vertex is read, not skipped with every index shifted
     * (this file was the triangle of vertices 2, 3, 4). */
    const char *bom = "\xef\xbb\xbfv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n";
    CHECK(parse_text("bom.obj", VB_MESH_OBJ, bom, &raw, &err) == VB_OK && raw.vertex_count == 4 &&
              raw.triangle_count == 1 && raw.indices[0] == 0 && raw.positions[0] == 0.0f &&
              raw.positions[3] == 1.0f,
          "bom.obj: %u vertices, %u triangles, %s", raw.vertex_count, raw.triangle_count, err.msg);
    vb_mesh_raw_free(&raw);
    /* Text after '#' on a face line that names another vertex. */
    const char *hash = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 # 4\n";
    expect_refused("h.obj", VB_MESH_OBJ, hash, strlen(hash),
                   "line 5: the text after '#' reads as further");
}

static void put_f32(uint8_t *p, float f)
{
    memcpy(p, &f, 4); /* little-endian hosts only, as the tests run */
}

/* STL: corners within FLT_MIN of each other (+0 and -0, 0 and 1e-40) are
 * one vertex; a triangle that then repeats one is dropped. */
static void test_stl_merge(void)
{
    static const float tri[4][9] = {
        {0, 0, 0, 1, 0, 0, 0, 1, 0},
        {1e-40f, 0, 0, 1, 0, 0, 0, 0, 1},
        {-0.0f, 1, 0, 2, 0, 0, 0, 0, 2},
        {0, 0, 1e-40f, -0.0f, 0, 0, 3, 3, 3},
    };
    uint8_t b[84 + 4 * 50];
    memset(b, 0, sizeof b);
    b[80] = 4;
    for (int t = 0; t < 4; t++)
        for (int k = 0; k < 9; k++)
            put_f32(b + 84 + 50 * t + 12 + 4 * k, tri[t][k]);
    vb_mesh_raw raw;
    vb_error err;
    CHECK(parse("m.stl", VB_MESH_STL, b, sizeof b, &raw, &err) == VB_OK, "%s", err.msg);
    CHECK(raw.vertex_count == 7 && raw.triangle_count == 3,
          "m.stl: %u vertices, %u triangles (want 7, 3)", raw.vertex_count, raw.triangle_count);
    CHECK(raw.triangle_count == 3 && raw.indices[3] == 0 && raw.indices[6] == 2,
          "m.stl: 1e-40 and -0 merged with earlier vertices");
    vb_mesh_raw_free(&raw);
}

/* A binary PLY as a byte string: header, then `body`. */
static size_t ply_bytes(uint8_t *out, const char *props, const uint8_t *body, size_t n)
{
    int h = sprintf((char *)out,
                    "ply\nformat binary_little_endian 1.0\nelement vertex 3\n%selement face 1\n"
                    "property list uchar int vertex_indices\nend_header\n",
                    props);
    memcpy(out + h, body, n);
    return (size_t)h + n;
}

static size_t put_face(uint8_t *p)
{
    p[0] = 3;
    for (int k = 0; k < 3; k++) {
        uint32_t v = (uint32_t)k;
        memcpy(p + 1 + 4 * k, &v, 4);
    }
    return 13;
}

/* PLY layouts: double coordinates are rounded to float; a property named
 * after a type of the same size reads as declared. Binary coordinates of
 * an integer type and properties named after a type of another size were
 * read shifted by OpenMesh, and the baker accepted such a file when the
 * counts still fitted (y read from the wrong bytes): now refused. */
static void test_ply_layouts(void)
{
    uint8_t body[256], file[1024];
    vb_mesh_raw raw;
    vb_error err;

    /* double x, y, z */
    size_t n = 0;
    const double xyz[9] = {0.1, 0, 0, 1, 0, 0, 0, 1, 1e-300};
    for (int i = 0; i < 9; i++, n += 8)
        memcpy(body + n, &xyz[i], 8);
    n += put_face(body + n);
    size_t size =
        ply_bytes(file, "property double x\nproperty double y\nproperty double z\n", body, n);
    CHECK(parse("d.ply", VB_MESH_PLY, file, size, &raw, &err) == VB_OK, "%s", err.msg);
    CHECK(raw.vertex_count == 3 && raw.positions[0] == 0.1f && bits(raw.positions[8]) == 0,
          "d.ply: doubles not rounded to float");
    vb_mesh_raw_free(&raw);

    /* "property int float": 4 bytes either way */
    n = 0;
    for (int v = 0; v < 3; v++) {
        float p[3] = {(float)(v == 1), (float)(v == 2), 0};
        for (int k = 0; k < 3; k++, n += 4)
            put_f32(body + n, p[k]);
        int32_t extra = 7;
        memcpy(body + n, &extra, 4);
        n += 4;
    }
    n += put_face(body + n);
    size = ply_bytes(file,
                     "property float x\nproperty float y\nproperty float z\nproperty int float\n",
                     body, n);
    CHECK(parse("f.ply", VB_MESH_PLY, file, size, &raw, &err) == VB_OK, "%s", err.msg);
    CHECK(raw.vertex_count == 3 && raw.positions[3] == 1.0f && raw.positions[7] == 1.0f,
          "f.ply: misread");
    vb_mesh_raw_free(&raw);

    /* x, "uint16 int" (read as 4 bytes), y, "ushort s" (a texture
     * coordinate of an integer type: read as nothing), z */
    n = 0;
    for (int v = 0; v < 3; v++) {
        float p[3] = {0.5f * (float)v, 0.25f, -1.0f};
        uint16_t pad = 7;
        put_f32(body + n, p[0]);
        memcpy(body + n + 4, &pad, 2);
        put_f32(body + n + 6, p[1]);
        memcpy(body + n + 10, &pad, 2);
        put_f32(body + n + 12, p[2]);
        n += 16;
    }
    n += put_face(body + n);
    size = ply_bytes(file,
                     "property float x\nproperty uint16 int\nproperty float y\nproperty ushort s\n"
                     "property float z\n",
                     body, n);
    expect_refused("shifted.ply", VB_MESH_PLY, file, size, "binary property 'int' of type uint16");

    /* an integer z */
    n = 0;
    for (int v = 0; v < 3; v++) {
        put_f32(body + n, (float)(v == 1));
        put_f32(body + n + 4, (float)(v == 2));
        uint16_t z = 2;
        memcpy(body + n + 8, &z, 2);
        n += 10;
    }
    n += put_face(body + n);
    size = ply_bytes(file, "property float x\nproperty float y\nproperty uint16 z\n", body, n);
    expect_refused("intz.ply", VB_MESH_PLY, file, size, "binary property 'z' of type uint16");
}

/* ascii PLY colours not of type float were read as an int: a value that
 * is not one (a fraction, or beyond int range) failed or shifted the rest
 * of the reading. In a face followed by another face, OpenMesh kept the
 * previous face's vertices for the next, and the baker accepted the copy:
 * now refused. In the last face nothing used follows: read as before. */
static void test_ply_colours(void)
{
    static const char head[] =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
        "property %s red\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2 %s\n3 1 3 2 %s\n";
    char text[1024];
    vb_mesh_raw raw;
    vb_error err;
    snprintf(text, sizeof text, head, "uint", "4294967295", "5");
    expect_refused("copy.ply", VB_MESH_PLY, text, strlen(text),
                   "line 15: face 0: red '4294967295'");
    snprintf(text, sizeof text, head, "double", "0.5", "5");
    expect_refused("half.ply", VB_MESH_PLY, text, strlen(text), "line 15: face 0: red '0.5'");

    snprintf(text, sizeof text, head, "uint", "5", "4294967295");
    CHECK(parse_text("last.ply", VB_MESH_PLY, text, &raw, &err) == VB_OK, "last.ply: %s", err.msg);
    CHECK(raw.triangle_count == 2 && raw.indices[3] == 1 && raw.indices[4] == 3,
          "last.ply: faces misread");
    vb_mesh_raw_free(&raw);
    snprintf(text, sizeof text, head, "double", "255", "-7");
    CHECK(parse_text("whole.ply", VB_MESH_PLY, text, &raw, &err) == VB_OK, "whole.ply: %s",
          err.msg);
    vb_mesh_raw_free(&raw);
}

/* OFF: the unused edge count must still be a count (a larger one failed
 * OpenMesh's stream: the rest read as uninitialised memory). */
static void test_off(void)
{
    const char *off = "OFF\n3 1 4294967296\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    expect_refused("e.off", VB_MESH_OFF, off, strlen(off), "edge count 4294967296 is too large");
    vb_mesh_raw raw;
    vb_error err;
    CHECK(parse_text("ok.off", VB_MESH_OFF, "OFF\n3 1 4294967295\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                     &raw, &err) == VB_OK,
          "ok.off: %s", err.msg);
    vb_mesh_raw_free(&raw);
    /* Counts on the OFF line itself ("OFF 3 1 0", ModelNet40's "OFF3 1 0"):
     * read there (the first vertex was taken for the counts: "empty
     * mesh"); "OFF BINARY" stays binary. */
    static const char *const one_line[] = {"OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                                           "OFF3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                                           "COFF 3 1 0 \r\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n"
                                           "0 1 0 1 1 1 1\n3 0 1 2\n"};
    for (int i = 0; i < 3; i++) {
        vb_result r = parse_text("line.off", VB_MESH_OFF, one_line[i], &raw, &err);
        CHECK(r == VB_OK && raw.vertex_count == 3 && raw.triangle_count == 1,
              "counts on the OFF line %d: %s", i, r == VB_OK ? "wrong mesh" : err.msg);
        if (r == VB_OK)
            vb_mesh_raw_free(&raw);
    }
}

/* ====================================================================== */
/* Polygons: the fan where it lies inside, ear clipping where it does not  */
/* ====================================================================== */

/* Twice the vector area of raw's triangle t (its corners' cross product). */
static void raw_cross(const vb_mesh_raw *raw, uint32_t t, double x[3])
{
    const float *a = raw->positions + 3 * raw->indices[3 * (size_t)t],
                *b = raw->positions + 3 * raw->indices[3 * (size_t)t + 1],
                *c = raw->positions + 3 * raw->indices[3 * (size_t)t + 2];
    double u[3], v[3];
    for (int d = 0; d < 3; d++)
        u[d] = (double)b[d] - a[d], v[d] = (double)c[d] - a[d];
    x[0] = u[1] * v[2] - u[2] * v[1];
    x[1] = u[2] * v[0] - u[0] * v[2];
    x[2] = u[0] * v[1] - u[1] * v[0];
}

/* Over every polygon of raw (a run of triangles of one file face): the
 * largest ratio of its triangles' total area to the area it encloses (the
 * length of their summed vector areas, the same for any triangulation of
 * the polygon: 1 when the triangles tile it, more when part lies outside
 * and overlaps). *total: all triangles' area. */
static double worst_cover(const vb_mesh_raw *raw, double *total)
{
    double worst = 1.0;
    *total = 0.0;
    for (uint32_t t = 0; t < raw->triangle_count;) {
        uint32_t e = t;
        double sum = 0.0, vec[3] = {0.0, 0.0, 0.0};
        for (; e < raw->triangle_count && raw->faces[e] == raw->faces[t]; e++) {
            double x[3];
            raw_cross(raw, e, x);
            sum += sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            for (int d = 0; d < 3; d++)
                vec[d] += x[d];
        }
        const double own = sqrt(vec[0] * vec[0] + vec[1] * vec[1] + vec[2] * vec[2]);
        if (sum > worst * own)
            worst = own > 0.0 ? sum / own : INFINITY;
        *total += 0.5 * sum;
        t = e;
    }
    return worst;
}

/* Whether raw's triangles are polygon v[0..n-1] fanned from v[0]. */
static int is_fan(const vb_mesh_raw *raw, const int64_t *v, uint32_t n)
{
    if (raw->triangle_count != n - 2)
        return 0;
    for (uint32_t i = 1; i + 1 < n; i++) {
        const int64_t *t = raw->indices + 3 * (size_t)(i - 1);
        if (t[0] != v[0] || t[1] != v[i] || t[2] != v[i + 1])
            return 0;
    }
    return 1;
}

/* An L of area 3 listed from a corner that does not see all of it: its
 * fan covered 4 (a triangle outside the face, overlapping another). Every
 * reader that takes polygons ear-clips it: 4 triangles tiling the L, in
 * its winding (+z). The same L listed from its inner corner, which sees
 * all of it, keeps the fan, as do a convex quad and pentagon (one with a
 * corner on an edge: its degenerate triangle included). */
static void test_concave(void)
{
    static const char obj[] = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n"
                              "f 3 4 5 6 1 2\n";
    static const char off[] = "OFF\n6 1 0\n0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n"
                              "6 2 3 4 5 0 1\n";
    static const char ply[] = "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\n"
                              "property float y\nproperty float z\nelement face 1\n"
                              "property list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n6 2 3 4 5 0 1\n";
    const struct {
        const char *name;
        vb_mesh_format f;
        const char *text;
    } ells[] = {{"ell.obj", VB_MESH_OBJ, obj},
                {"ell.off", VB_MESH_OFF, off},
                {"ell.ply", VB_MESH_PLY, ply}};
    static const int64_t ell[6] = {2, 3, 4, 5, 0, 1};
    for (size_t i = 0; i < sizeof ells / sizeof ells[0]; i++) {
        vb_mesh_raw raw;
        vb_error err;
        vb_result r = parse_text(ells[i].name, ells[i].f, ells[i].text, &raw, &err);
        CHECK(r == VB_OK && raw.triangle_count == 4, "%s: %s, %u triangles", ells[i].name,
              r == VB_OK ? "read" : err.msg, raw.triangle_count);
        if (r != VB_OK)
            continue;
        double total = 0.0;
        const double worst = worst_cover(&raw, &total);
        CHECK(worst <= 1.0 + 1e-12 && fabs(total - 3.0) <= 1e-12,
              "%s: triangles cover %.6gx the L, area %.9g (its own: 3)", ells[i].name, worst,
              total);
        CHECK(!is_fan(&raw, ell, 6), "%s: still fanned", ells[i].name);
        for (uint32_t t = 0; t < raw.triangle_count; t++) {
            double x[3];
            raw_cross(&raw, t, x);
            CHECK(x[2] > 0.0, "%s: triangle %u not in the L's winding (%g)", ells[i].name, t, x[2]);
            CHECK(raw.faces[t] == 0, "%s: triangle %u of face %u", ells[i].name, t, raw.faces[t]);
        }
        vb_mesh_raw_free(&raw);
    }

    /* Fans kept, index for index. */
    const struct {
        const char *text;
        int64_t v[6];
        uint32_t n;
    } fans[] = {
        {"v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 4 5 6 1 2 3\n",
         {3, 4, 5, 0, 1, 2},
         6},
        {"v 0 0 0\nv 2 0 0\nv 2 1 0.01\nv 0 1 0\nf 1 2 3 4\n", {0, 1, 2, 3}, 4},
        {"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 2 3 4 5 1\n", {1, 2, 3, 4, 0}, 5},
        {"v 0 0 0\nv 2 0 0\nv 3 1 1\nv 1 2 2\nv -1 1 1\nf 1 2 3 4 5\n", {0, 1, 2, 3, 4}, 5},
    };
    for (size_t i = 0; i < sizeof fans / sizeof fans[0]; i++) {
        vb_mesh_raw raw;
        vb_error err;
        vb_result r = parse_text("fan.obj", VB_MESH_OBJ, fans[i].text, &raw, &err);
        CHECK(r == VB_OK && is_fan(&raw, fans[i].v, fans[i].n), "fan %zu: %s", i,
              r == VB_OK ? "not the fan" : err.msg);
        if (r == VB_OK)
            vb_mesh_raw_free(&raw);
    }

    /* Not simple (a crossing: no ear; the fan covers more than the
     * vector area) or far from flat (the L's inner corner raised 3 above
     * it: clipped triangles would cover far more than it encloses): fanned
     * as before (mesh.c warns). */
    static const char *const fallback[] = {
        "v 0 0 0\nv 3 0 0\nv 3 2 0\nv 1 -1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n",
        "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 3\nv 1 2 0\nv 0 2 0\nf 3 4 5 6 1 2\n",
    };
    for (size_t i = 0; i < sizeof fallback / sizeof fallback[0]; i++) {
        vb_mesh_raw raw;
        vb_error err;
        vb_result r = parse_text("odd.obj", VB_MESH_OBJ, fallback[i], &raw, &err);
        const int64_t v0[6] = {0, 1, 2, 3, 4, 5}, v1[6] = {2, 3, 4, 5, 0, 1};
        double total = 0.0;
        CHECK(r == VB_OK && is_fan(&raw, i == 0 ? v0 : v1, 6) && worst_cover(&raw, &total) > 1.01,
              "fallback %zu: %s", i, r == VB_OK ? "not the fan, or no excess" : err.msg);
        if (r == VB_OK)
            vb_mesh_raw_free(&raw);
    }
}

/* OBJ corner normals follow the corners into the clipped triangles: each
 * corner of each triangle keeps the normal its vertex was given there. */
static void test_concave_normals(void)
{
    static const char obj[] = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n"
                              "vn 1 0 0\nvn 0 1 0\nvn 0 0 1\nvn -1 0 0\nvn 0 -1 0\n"
                              "f 3//3 4//4 5 6//1 1//5 2//2\n";
    vb_mesh_raw raw;
    vb_error err;
    vb_result r = parse_text("ell_n.obj", VB_MESH_OBJ, obj, &raw, &err);
    CHECK(r == VB_OK && raw.triangle_count == 4 && raw.corner_given && raw.corner_normals,
          "ell_n.obj: %s", r == VB_OK ? "no corner normals" : err.msg);
    if (r != VB_OK)
        return;
    /* vertex (0-based) -> normal number (1-based), 0: none */
    static const int given[6] = {5, 2, 3, 4, 0, 1};
    static const float vn[5][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}};
    for (uint32_t c = 0; raw.corner_given && c < 3 * raw.triangle_count; c++) {
        const int g = given[raw.indices[c]];
        CHECK(raw.corner_given[c] == (g != 0), "ell_n.obj: corner %u (vertex %lld) given %u", c,
              (long long)raw.indices[c], raw.corner_given[c]);
        if (g)
            CHECK(memcmp(raw.corner_normals + 3 * c, vn[g - 1], sizeof vn[0]) == 0,
                  "ell_n.obj: corner %u (vertex %lld) has another vertex's normal", c,
                  (long long)raw.indices[c]);
    }
    double total = 0.0;
    CHECK(worst_cover(&raw, &total) <= 1.0 + 1e-12, "ell_n.obj: not clipped");
    vb_mesh_raw_free(&raw);
}

/* assimp's concave_polygon.obj: one flat polygon of 64 vertices, which
 * the fan covered 13.5x over; clipped, its triangles tile it. */
static void test_assimp_concave(const char *models)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/OBJ/concave_polygon.obj", models);
    uint8_t *bytes = NULL;
    size_t size = 0;
    vb_error err;
    if (vb_mesh_read_file(path, &bytes, &size, &err) != VB_OK) {
        printf("skipped: %s\n", err.msg);
        return;
    }
    vb_mesh_raw raw;
    vb_result r = parse(path, VB_MESH_OBJ, bytes, size, &raw, &err);
    free(bytes);
    CHECK(r == VB_OK, "%s", err.msg);
    if (r != VB_OK)
        return;
    double total = 0.0;
    const double worst = worst_cover(&raw, &total);
    printf("concave_polygon.obj: %u triangles cover %.9gx the area the polygon encloses\n",
           raw.triangle_count, worst);
    CHECK(raw.triangle_count > 2 && worst <= 1.0 + 1e-9, "%s: triangles cover %.6gx its area", path,
          worst);
    vb_mesh_raw_free(&raw);
}

static void test_arguments(void)
{
    vb_mesh_raw raw;
    vb_error err;
    memset(&raw, 0, sizeof raw);
    CHECK(vb_mesh_parse(NULL, VB_MESH_OBJ, (const uint8_t *)"v", 1, &raw, &err) == VB_ERR_ARGUMENT,
          "NULL name");
    CHECK(vb_mesh_parse("a.obj", VB_MESH_OBJ, NULL, 1, &raw, &err) == VB_ERR_ARGUMENT,
          "NULL bytes");
    CHECK(vb_mesh_parse("a.obj", (vb_mesh_format)9, (const uint8_t *)"v", 1, &raw, &err) ==
              VB_ERR_ARGUMENT,
          "unknown format");
    vb_mesh_raw_free(&raw);
    vb_mesh_raw_free(NULL);
}

int main(int argc, char **argv)
{
    test_numbers();
    test_obj_normals();
    test_stl_merge();
    test_ply_layouts();
    test_ply_colours();
    test_off();
    test_arguments();
    test_concave();
    test_concave_normals();
    if (argc > 1)
        test_assimp_concave(argv[1]);
    return test_report("mesh_parse");
}
