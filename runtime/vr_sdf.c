/*
 * vr_sdf.c - mode sdf's data: the scene's distance volume as a 3D texture
 * (R16 unorm, the file's samples as stored), and its uniforms at draw
 * time. The trace itself is formats/vdsh_sdf.h's, in GLSL in
 * shaders/vr_sdf.glsl.
 */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "vr_internal.h"

vr_result vr_sdf_load(vr_scene *s, const vr_scene_desc *desc, uint32_t vertex_count,
                      uint32_t triangle_count, vr_error *err)
{
    char companion[4096];
    const char *path = desc->sdf_path;
    if (!path) {
        struct stat st;
        if (!desc->path || desc->file || vdsh_sdf_path(desc->path, companion, sizeof companion))
            return VR_OK; /* no volume: mode sdf is unsupported */
        if (stat(companion, &st) != 0) {
            /* Mode sdf names the file it looked for, this scene's own. */
            snprintf(s->sdf_why, sizeof s->sdf_why,
                     "none was loaded: no %s (bake it with vdsh-bake --sdf N, which writes it "
                     "beside %s)",
                     companion, desc->path);
            return VR_OK;
        }
        path = companion;
    }
    vdsh_sdf v;
    vdsh_error ve;
    vdsh_result vr = vdsh_sdf_read(path, &v, &ve);
    if (vr != VDSH_OK)
        return vr_fail(err, vr == VDSH_ERR_IO ? VR_ERR_IO : VR_ERR_FORMAT, "%s", ve.msg);
    if (vdsh_sdf_other_scene(&v, vertex_count, triangle_count)) {
        vdsh_sdf_free(&v);
        /* The companion, found by name: left by an earlier bake of the same
         * output with --sdf (a bake without --sdf leaves it). It is not
         * this scene's, but it must not stop the modes that do not use it:
         * skipped, and mode sdf says why. One named with sdf_path fails. */
        if (!desc->sdf_path) {
            snprintf(s->sdf_why, sizeof s->sdf_why,
                     "%s beside it was baked beside another bake (%u %s and %u %s, not "
                     "%u and %u): not loaded; bake again with vdsh-bake --sdf N",
                     path, v.vertex_count, vdsh_plural(v.vertex_count, "vertex", "vertices"),
                     v.triangle_count, vdsh_plural(v.triangle_count, "triangle", "triangles"),
                     vertex_count, triangle_count);
            return VR_OK;
        }
        return vr_fail(err, VR_ERR_FORMAT,
                       "%s: the distance volume was baked beside a scene "
                       "of %u %s and %u %s, not this one (%u, %u): bake it again",
                       path, v.vertex_count, vdsh_plural(v.vertex_count, "vertex", "vertices"),
                       v.triangle_count, vdsh_plural(v.triangle_count, "triangle", "triangles"),
                       vertex_count, triangle_count);
    }
    GLint max3d = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    if ((GLint)v.dim[0] > max3d || (GLint)v.dim[1] > max3d || (GLint)v.dim[2] > max3d) {
        vdsh_sdf_free(&v);
        return vr_fail(err, VR_ERR_GL,
                       "%s: a %u x %u x %u volume exceeds "
                       "GL_MAX_3D_TEXTURE_SIZE %d",
                       path, v.dim[0], v.dim[1], v.dim[2], max3d);
    }
    glGenTextures(1, &s->sdf_tex);
    glBindTexture(GL_TEXTURE_3D, s->sdf_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 2);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_R16, (GLsizei)v.dim[0], (GLsizei)v.dim[1], (GLsizei)v.dim[2],
                 0, GL_RED, GL_UNSIGNED_SHORT, v.samples);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAX_LEVEL, 0);
    glBindTexture(GL_TEXTURE_3D, 0);
    s->sdf_bytes = 2 * (size_t)v.dim[0] * v.dim[1] * v.dim[2];
    s->gpu_bytes += s->sdf_bytes;
    vdsh_sdf_free(&v);
    s->sdf = v; /* the header: samples NULL */
    return vr_check_gl(err, path);
}

void vr_sdf_bind(const vr_scene *s, GLuint prog, float k)
{
    glActiveTexture(GL_TEXTURE0 + VR_UNIT_SDF);
    glBindTexture(GL_TEXTURE_3D, s->sdf_tex);
    glUniform1i(glGetUniformLocation(prog, "u_sdf"), VR_UNIT_SDF);
    glUniform3fv(glGetUniformLocation(prog, "u_sdf_origin"), 1, s->sdf.origin);
    glUniform1f(glGetUniformLocation(prog, "u_sdf_cell"), s->sdf.cell);
    glUniform1f(glGetUniformLocation(prog, "u_sdf_max"), s->sdf.max_distance);
    glUniform3i(glGetUniformLocation(prog, "u_sdf_dim"), (GLint)s->sdf.dim[0], (GLint)s->sdf.dim[1],
                (GLint)s->sdf.dim[2]);
    glUniform1f(glGetUniformLocation(prog, "u_sdf_k"), k > 0.0f ? k : VDSH_SDF_DEFAULT_K);
}
