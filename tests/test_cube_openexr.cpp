// test_cube_openexr.cpp - our cube-face convention (formats/vdsh_cube.h)
// and our files (bake/lib/cubemap_exr.c) against OpenEXR's own C++ library:
// Imf::CubeMap::faceAndPixelPosition / pixelPosition / direction
// (ImfEnvmap.cpp) and the C++ RGBA file reader and writer.
//
//   test_cube_openexr DIR
#include "cubemap.h"
#include "vdsh_cube.h"
#include "vdsh_sh.h"

#include <half.h>
#include <ImfArray.h>
#include <ImfEnvmap.h>
#include <ImfHeader.h>
#include <ImfRgbaFile.h>
#include <ImfStandardAttributes.h>
#include <ImfTiledRgbaFile.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include <sys/stat.h>

static int failures;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            failures++;                                                                            \
            std::fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);          \
            std::fprintf(stderr, __VA_ARGS__);                                                     \
            std::fputc('\n', stderr);                                                              \
        }                                                                                          \
    } while (0)

static Imath::Box2i cube_window(int n)
{
    return Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(n - 1, 6 * n - 1));
}

// For every texel centre of our convention, OpenEXR's own lookup lands in
// the same face and the same pixel (within half a pixel).
static void test_lookup_lands_in_texel(int n)
{
    Imath::Box2i dw = cube_window(n);
    int bad = 0;
    for (int face = 0; face < 6; face++) {
        for (int j = 0; j < n; j++) {
            for (int i = 0; i < n; i++) {
                float d[3];
                vdsh_cube_exr_dir(face, i, j, n, d);
                Imf::CubeMapFace f;
                Imath::V2f pif;
                Imf::CubeMap::faceAndPixelPosition(Imath::V3f(d[0], d[1], d[2]), dw, f, pif);
                Imath::V2f pos = Imf::CubeMap::pixelPosition(f, dw, pif);
                bool ok = int(f) == face && std::fabs(pos.x - float(i)) < 0.5f &&
                          std::fabs(pos.y - float(face * n + j)) < 0.5f;
                if (!ok && bad++ < 5)
                    std::fprintf(stderr,
                                 "n %d face %d texel (%d,%d): OpenEXR face %d "
                                 "pixel (%g,%g)\n",
                                 n, face, i, j, int(f), double(pos.x), double(pos.y));
            }
        }
    }
    CHECK(bad == 0, "n %d: %d texels looked up elsewhere by OpenEXR", n, bad);
}

// OpenEXR's CubeMap::direction samples pixel centres at the face edges
// (x / (n-1)); ours at texel centres ((2i+1-n)/n). Same table, so the
// minor components differ exactly by the factor (n-1)/n.
static void test_direction_table(int n)
{
    Imath::Box2i dw = cube_window(n);
    int bad = 0;
    for (int face = 0; face < 6; face++) {
        for (int b = 0; b < n; b++) {
            for (int a = 0; a < n; a++) {
                Imf::CubeMapFace f = Imf::CubeMapFace(face);
                Imath::V2f pif{float(a), float(b)};
                Imath::V3f theirs = Imf::CubeMap::direction(f, dw, pif);
                Imath::V2f pos = Imf::CubeMap::pixelPosition(f, dw, pif);
                int px = int(std::lround(pos.x));
                int py = int(std::lround(pos.y)) - face * n;
                if (px < 0 || px >= n || py < 0 || py >= n) {
                    bad++;
                    continue;
                }
                float ours[3];
                vdsh_cube_exr_dir(face, px, py, n, ours);
                int axis = face / 2;
                bool ok = theirs[axis] == ours[axis];
                for (int k = 0; k < 3; k++) {
                    if (k == axis)
                        continue;
                    float want = n == 1 ? 0.0f : theirs[k] * float(n - 1) / float(n);
                    ok = ok && std::fabs(ours[k] - want) < 1e-5f;
                }
                if (!ok && bad++ < 5)
                    std::fprintf(stderr,
                                 "n %d face %d pixel (%d,%d): OpenEXR (%g %g %g) "
                                 "ours (%g %g %g)\n",
                                 n, face, px, py, double(theirs.x), double(theirs.y),
                                 double(theirs.z), double(ours[0]), double(ours[1]),
                                 double(ours[2]));
            }
        }
    }
    CHECK(bad == 0, "n %d: %d pixels disagree with CubeMap::direction", n, bad);
}

static bool read_rgba(const std::string &path, int &n, std::vector<float> &out, Imf::Envmap &envmap)
{
    Imf::RgbaInputFile in(path.c_str());
    Imath::Box2i dw = in.dataWindow();
    int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    if (h != 6 * w)
        return false;
    n = w;
    envmap = Imf::hasEnvmap(in.header()) ? Imf::envmap(in.header()) : Imf::NUM_ENVMAPTYPES;
    Imf::Array2D<Imf::Rgba> px(h, w);
    in.setFrameBuffer(&px[0][0] - dw.min.x - dw.min.y * w, 1, size_t(w));
    in.readPixels(dw.min.y, dw.max.y);
    out.resize(size_t(w) * size_t(h) * 4);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float *o = &out[(size_t(y) * size_t(w) + size_t(x)) * 4];
            o[0] = px[y][x].r;
            o[1] = px[y][x].g;
            o[2] = px[y][x].b;
            o[3] = px[y][x].a;
        }
    return true;
}

// Our files, read by OpenEXR's C++ reader: envmap = cube, the same values
// our reader gets, and OpenEXR's lookup of any direction d returns the
// texel whose centre is within one texel of d.
static void test_our_files(const std::string &dir)
{
    const int n = 16;
    vb_error err;
    CHECK(vb_cubemap_write_basis(dir.c_str(), "cpp", n, &err) == VB_OK, "%s", err.msg);
    for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++) {
        char path[1024];
        vb_cubemap_basis_path(dir.c_str(), "cpp", k, path, sizeof path, nullptr);
        int cn = 0;
        std::vector<float> cpp;
        Imf::Envmap em = Imf::NUM_ENVMAPTYPES;
        CHECK(read_rgba(path, cn, cpp, em) && cn == n, "%s: C++ read", path);
        CHECK(em == Imf::ENVMAP_CUBE, "%s: C++ sees envmap %d", path, int(em));
        vb_cubemap *m = nullptr;
        CHECK(vb_cubemap_read(path, &m, &err) == VB_OK, "%s", err.msg);
        if (!m || cn != n)
            continue;
        size_t differ = 0;
        for (size_t x = 0; x < cpp.size(); x++)
            differ += std::memcmp(&cpp[x], &m->rgba[x], sizeof(float)) != 0;
        CHECK(differ == 0, "%s: %zu values differ between C++ and our reader", path, differ);

        Imath::Box2i dw = cube_window(n);
        uint32_t state = 7u + uint32_t(k);
        int far = 0, wrong = 0;
        for (int trial = 0; trial < 20000; trial++) {
            float d[3];
            for (int c = 0; c < 3; c++) {
                state = state * 1664525u + 1013904223u;
                d[c] = float(state >> 8) / 8388608.0f - 1.0f;
            }
            Imf::CubeMapFace f;
            Imath::V2f pif;
            Imf::CubeMap::faceAndPixelPosition(Imath::V3f(d[0], d[1], d[2]), dw, f, pif);
            Imath::V2f pos = Imf::CubeMap::pixelPosition(f, dw, pif);
            int px = int(std::lround(pos.x)), py = int(std::lround(pos.y));
            int face = py / n, j = py % n;
            float c[3];
            vdsh_cube_exr_dir(face, px, j, n, c);
            // d projected onto the cube vs the texel centre: at most one
            // texel (2/n) apart per coordinate (edge vs centre sampling).
            int axis = face / 2;
            float scale = 1.0f / std::fabs(d[axis]);
            float dist = 0.0f;
            for (int q = 0; q < 3; q++)
                dist = std::fmax(dist, std::fabs(d[q] * scale - c[q]));
            if (!(dist <= 2.0f / float(n) + 1e-5f) && far++ < 5)
                std::fprintf(stderr,
                             "d (%g %g %g) -> face %d texel (%d,%d), "
                             "%g from its centre\n",
                             double(d[0]), double(d[1]), double(d[2]), face, px, j, double(dist));
            // The value OpenEXR returns there is the basis at that centre.
            float len = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
            float cu[3] = {c[0] / len, c[1] / len, c[2] / len}, y[25];
            vdsh_sh_eval(5, cu, y);
            const float *v = &cpp[(size_t(py) * size_t(n) + size_t(px)) * 4];
            for (int ch = 0; ch < 4; ch++)
                if (std::fabs(v[ch] - y[9 + 4 * k + ch]) > 2e-3f)
                    wrong++;
        }
        CHECK(far == 0, "%s: %d lookups far from the texel centre", path, far);
        CHECK(wrong == 0, "%s: %d looked-up values are not the basis", path, wrong);
        vb_cubemap_free(m);
    }
}

// Files written by OpenEXR's C++ writer: a scanline cube map reads back;
// a tiled one is refused with a clear message.
static void test_their_files(const std::string &dir)
{
    const int n = 4;
    std::vector<float> basis(size_t(n) * 6 * n * 4);
    vdsh_cube_fill_basis(n, 13, basis.data());
    Imf::Array2D<Imf::Rgba> px(6 * n, n);
    for (int y = 0; y < 6 * n; y++)
        for (int x = 0; x < n; x++) {
            const float *b = &basis[(size_t(y) * n + size_t(x)) * 4];
            px[y][x] = Imf::Rgba(b[0], b[1], b[2], b[3]);
        }
    Imf::Header header(n, 6 * n);
    Imf::addEnvmap(header, Imf::ENVMAP_CUBE);

    std::string scan = dir + "/cpp_scanline.exr";
    {
        Imf::RgbaOutputFile out(scan.c_str(), header, Imf::WRITE_RGBA);
        out.setFrameBuffer(&px[0][0], 1, size_t(n));
        out.writePixels(6 * n);
    }
    vb_cubemap *m = nullptr;
    vb_error err;
    CHECK(vb_cubemap_read(scan.c_str(), &m, &err) == VB_OK, "%s", err.msg);
    if (m) {
        size_t bad = 0;
        for (size_t x = 0; x < basis.size(); x++)
            bad += m->rgba[x] != float(half(basis[x]));
        CHECK(bad == 0, "%s: %zu values differ", scan.c_str(), bad);
        vb_cubemap_free(m);
    }

    std::string tiled = dir + "/cpp_tiled.exr";
    {
        Imf::TiledRgbaOutputFile out(tiled.c_str(), header, Imf::WRITE_RGBA, 4, 4, Imf::ONE_LEVEL);
        out.setFrameBuffer(&px[0][0], 1, size_t(n));
        out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
    }
    m = nullptr;
    vb_result r = vb_cubemap_read(tiled.c_str(), &m, &err);
    CHECK(r == VB_ERR_FORMAT && m == nullptr && std::strstr(err.msg, tiled.c_str()) &&
              std::strstr(err.msg, "tiled"),
          "tiled: %d %s", int(r), err.msg);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        std::fprintf(stderr, "usage: test_cube_openexr DIR\n");
        return 2;
    }
    std::string dir = argv[1];
    for (size_t at = 1; at <= dir.size(); at++)
        if (at == dir.size() || dir[at] == '/')
            mkdir(dir.substr(0, at).c_str(), 0777);
    try {
        const int sizes[] = {1, 2, 3, 8, 64};
        for (int n : sizes) {
            test_lookup_lands_in_texel(n);
            test_direction_table(n);
        }
        test_our_files(dir);
        test_their_files(dir);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "OpenEXR exception: %s\n", e.what());
        return 1;
    }
    if (failures)
        std::fprintf(stderr, "%d check(s) failed\n", failures);
    return failures ? 1 : 0;
}
