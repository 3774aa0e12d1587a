/*
 * test_runtime_basis.c - the runtime's basis cubemaps, made at load
 * (runtime/vr_scene.c, formats/vdsh_cube.h), hold in GL exactly what the
 * runtime used to upload from the bake's OpenEXR files:
 *
 *   for face sizes 1, 3, 16 and 64 (vdsh-bake's default), the four files
 *   are written by bake/lib/cubemap_exr.c and read back (the EXR reader is a
 *   test aid now, linked here only); each file's floats go into an RGBA16F
 *   cube texture the way the runtime did before (glTexImage2D from
 *   GL_FLOAT, every GL texel fetched from the EXR texel
 *   vdsh_cube_gl_to_exr names); a scene of a file with that cube_size is
 *   created; every texel of every face of the scene's four textures reads
 *   back (GL_HALF_FLOAT) with the same 16 bits as the reference texture.
 *
 * Any renderer that samples the two gets the same values, so renders in
 * mode vdsh5 are unchanged by the runtime no longer reading the files.
 */
#include "test_runtime_util.h"

#include "cubemap.h"
#include "vdsh_cube.h"
#include "vr_internal.h"

/* The pre-change upload of one basis file, kept here as the reference. */
static GLuint upload_from_file(const vb_cubemap *m)
{
    int n = m->size;
    float *face = malloc((size_t)n * (size_t)n * 4 * sizeof(float));
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_CUBE_MAP, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    for (int f = 0; f < 6; f++) {
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                int ei, ej;
                vdsh_cube_gl_to_exr(f, i, j, n, &ei, &ej);
                const float *src =
                    m->rgba + (((size_t)f * (size_t)n + (size_t)ej) * (size_t)n + (size_t)ei) * 4;
                memcpy(face + ((size_t)j * (size_t)n + (size_t)i) * 4, src, 4 * sizeof(float));
            }
        glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, 0, GL_RGBA16F, n, n, 0, GL_RGBA,
                     GL_FLOAT, face);
    }
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAX_LEVEL, 0);
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
    free(face);
    return tex;
}

/* Face f of a cube texture as half-float bits. */
static void read_face(GLuint tex, int f, int n, uint16_t *out)
{
    glBindTexture(GL_TEXTURE_CUBE_MAP, tex);
    glPixelStorei(GL_PACK_ALIGNMENT, 2);
    glGetTexImage(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, 0, GL_RGBA, GL_HALF_FLOAT, out);
    (void)n;
    glBindTexture(GL_TEXTURE_CUBE_MAP, 0);
}

/* A quad with a distance stream of order 5 and the given cube_size. */
static void quad_file(rt_file *f, uint32_t cube_size)
{
    rt_file_unit_quad(f);
    f->f.header.cube_size = cube_size;
    float *c5 = calloc(4 * 25, sizeof(float));
    for (int i = 0; i < 4; i++)
        c5[25 * i] = 5.0f;
    rt_file_add_stream(f, 5, VDSH_ENCODING_F16, 0, c5, 0.01f);
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "runtime_basis";
    vr_context *ctx = rt_context_or_skip("test_runtime_basis");
    mkdir(dir, 0777);
    static const int sizes[] = {1, 3, 16, 64};
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++) {
        int n = sizes[si];
        vb_error be;
        vb_cubemap *maps[VB_CUBEMAP_BASIS_FILES] = {0};
        CHECK(vb_cubemap_write_basis(dir, "basis", n, &be) == VB_OK, "%s", be.msg);
        CHECK(vb_cubemap_read_basis(dir, "basis", n, maps, &be) == VB_OK, "%s", be.msg);
        if (!maps[0])
            continue;

        rt_file f;
        quad_file(&f, (uint32_t)n);
        vr_scene *s = NULL;
        vr_error err;
        vr_scene_desc sd = {.file = &f.f};
        CHECK(vr_scene_create(&sd, &s, &err) == VR_OK, "n %d: %s", n, err.msg);
        size_t count = (size_t)n * (size_t)n * 4;
        uint16_t *want = malloc(count * sizeof *want), *got = malloc(count * sizeof *got);
        long texels = 0, differ = 0, zeros = 0;
        for (int k = 0; s && k < VB_CUBEMAP_BASIS_FILES; k++) {
            CHECK(s->basis[k] != 0 && s->cube_size == n, "n %d: texture %d missing", n, k);
            GLuint ref = upload_from_file(maps[k]);
            for (int face = 0; face < 6; face++) {
                memset(want, 0x55, count * sizeof *want);
                memset(got, 0xaa, count * sizeof *got);
                read_face(ref, face, n, want);
                read_face(s->basis[k], face, n, got);
                for (size_t x = 0; x < count; x++) {
                    differ += want[x] != got[x];
                    zeros += (want[x] & 0x7fffu) == 0;
                }
                texels += (long)n * n;
            }
            glDeleteTextures(1, &ref);
        }
        CHECK(vr_check_gl(&err, "read back") == VR_OK, "%s", err.msg);
        CHECK(differ == 0, "n %d: %ld of %ld half values differ from the files' upload", n, differ,
              4 * texels);
        printf("n = %2d: %ld texels x 4 functions, every half identical to the upload from "
               "the .exr files (%ld zeros of either sign among them), %ld differ\n",
               n, texels, zeros, differ);
        free(want);
        free(got);
        vr_scene_destroy(s);
        rt_file_free(&f);
        for (int k = 0; k < VB_CUBEMAP_BASIS_FILES; k++)
            vb_cubemap_free(maps[k]);
    }
    vr_context_destroy(ctx);
    return test_report("test_runtime_basis");
}
