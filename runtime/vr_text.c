/*
 * vr_text.c - text on top of the framebuffer, for the viewer's overlay and
 * the labels of comparison images: stb_easy_font turns a string into
 * axis-aligned quads of a 7-pixel-high font, drawn here as triangles in one
 * colour on a translucent dark box. Going through GL rather than writing
 * into read-back pixels keeps one path for the window and for PNGs.
 */
#include "vr_internal.h"

#include <stb/stb_easy_font.h>

#include <stdlib.h>
#include <string.h>

static const char text_vs[] =
    "#version 330 core\n"
    "layout(location = 0) in vec2 a_pos;\n"
    "uniform vec2 u_viewport;\n"
    "void main()\n"
    "{\n"
    "    /* pixels from the top-left to clip space */\n"
    "    gl_Position = vec4(2.0 * a_pos.x / u_viewport.x - 1.0,\n"
    "                       1.0 - 2.0 * a_pos.y / u_viewport.y, 0.0, 1.0);\n"
    "}\n";

static const char text_fs[] = "#version 330 core\n"
                              "uniform vec4 u_color;\n"
                              "out vec4 o_color;\n"
                              "void main()\n"
                              "{\n"
                              "    o_color = u_color;\n"
                              "}\n";

void vr_text_destroy(vr_text_state *t)
{
    if (t->prog)
        glDeleteProgram(t->prog);
    glDeleteVertexArrays(1, &t->vao);
    glDeleteBuffers(1, &t->vbo);
    memset(t, 0, sizeof *t);
}

static vr_result text_init(vr_text_state *t, vr_error *err)
{
    if (t->prog)
        return VR_OK;
    GLuint prog = 0;
    vr_result r = vr_link("text program", text_vs, text_fs, &prog, err);
    if (r != VR_OK)
        return r;
    t->prog = prog;
    t->u_viewport = glGetUniformLocation(prog, "u_viewport");
    t->u_color = glGetUniformLocation(prog, "u_color");
    glGenVertexArrays(1, &t->vao);
    glGenBuffers(1, &t->vbo);
    glBindVertexArray(t->vao);
    glBindBuffer(GL_ARRAY_BUFFER, t->vbo);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), NULL);
    glEnableVertexAttribArray(0);
    glBindVertexArray(0);
    return vr_check_gl(err, "text");
}

/* stb_easy_font's vertex: x, y, z and 4 colour bytes. */
typedef struct easy_vertex {
    float x, y, z;
    unsigned char rgba[4];
} easy_vertex;

vr_result vr_text_draw_impl(vr_text_state *t, GLuint fbo, int w, int h, int x, int y, float scale,
                            const float color[4], const char *text, vr_error *err)
{
    vr_result r = text_init(t, err);
    if (r != VR_OK)
        return r;
    if (!(scale > 0.0f))
        scale = 1.0f;
    size_t len = strlen(text);
    /* stb_easy_font takes a mutable string, and needs at most about 270
     * bytes of vertices per character. */
    char *copy = malloc(len + 1);
    size_t vsize = 300 * (len + 1);
    easy_vertex *quads = malloc(vsize);
    /* 6 vertices of 2 floats per quad, plus the box. */
    size_t max_quads = vsize / (4 * sizeof(easy_vertex));
    float *tri = malloc((max_quads + 1) * 12 * sizeof(float));
    if (!copy || !quads || !tri) {
        free(copy);
        free(quads);
        free(tri);
        return vr_fail(err, VR_ERR_OUT_OF_MEMORY, "text: out of memory");
    }
    memcpy(copy, text, len + 1);
    int nq = stb_easy_font_print(0.0f, 0.0f, copy, NULL, quads, (int)vsize);
    float bw = (float)stb_easy_font_width(copy) * scale;
    float bh = (float)stb_easy_font_height(copy) * scale;
    float pad = 3.0f * scale;

    /* The box first, then each quad (a, b, c, d) as (a, b, c) (a, c, d). */
    float x0 = (float)x, y0 = (float)y;
    const float box[12] = {x0,
                           y0,
                           x0 + bw + 2 * pad,
                           y0,
                           x0 + bw + 2 * pad,
                           y0 + bh + 2 * pad,
                           x0,
                           y0,
                           x0 + bw + 2 * pad,
                           y0 + bh + 2 * pad,
                           x0,
                           y0 + bh + 2 * pad};
    memcpy(tri, box, sizeof box);
    for (int q = 0; q < nq; q++) {
        static const int order[6] = {0, 1, 2, 0, 2, 3};
        for (int k = 0; k < 6; k++) {
            const easy_vertex *v = &quads[4 * q + order[k]];
            tri[12 + 12 * q + 2 * k] = x0 + pad + v->x * scale;
            tri[12 + 12 * q + 2 * k + 1] = y0 + pad + v->y * scale;
        }
    }

    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, w, h);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(t->prog);
    glUniform2f(t->u_viewport, (float)w, (float)h);
    glBindVertexArray(t->vao);
    glBindBuffer(GL_ARRAY_BUFFER, t->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)((size_t)(nq + 1) * 12 * sizeof(float)), tri,
                 GL_STREAM_DRAW);
    glUniform4f(t->u_color, 0.0f, 0.0f, 0.0f, 0.6f);
    glDrawArrays(GL_TRIANGLES, 0, 6);
    const float white[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    glUniform4fv(t->u_color, 1, color ? color : white);
    glDrawArrays(GL_TRIANGLES, 6, 6 * nq);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    free(copy);
    free(quads);
    free(tri);
    return vr_check_gl(err, "text");
}
