/*
 * test_robust_load.c - vb_mesh_load_memory (the fuzz targets' way in) is
 * the same loader as vb_mesh_load: for every mesh file given, loading the
 * file and loading its bytes under the same name give the same result
 * code, the same message, the same mesh (bit for bit) and the same source
 * info, without and with welding. Also its own argument checks, and that
 * loading from memory writes no file (OFF's bytes once went through a
 * temporary copy in $TMPDIR: now no format needs one, even when $TMPDIR
 * cannot be written).
 *
 * Usage: test_robust_load TMP_DIR FILE_OR_DIR...   (directories: the files
 * in them whose names end in .obj/.ply/.off/.stl, any case)
 */
#include "mesh.h"
#include "test_util.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

static int is_mesh_name(const char *name)
{
    const char *dot = strrchr(name, '.');
    return dot &&
           (!strcasecmp(dot, ".obj") || !strcasecmp(dot, ".ply") || !strcasecmp(dot, ".off") ||
            !strcasecmp(dot, ".stl") || !strcasecmp(dot, ".gltf") || !strcasecmp(dot, ".glb"));
}

static int same_mesh(const vb_mesh *a, const vb_mesh *b)
{
    size_t nv = 3 * (size_t)a->vertex_count, nt = 3 * (size_t)a->triangle_count;
    return a->vertex_count == b->vertex_count && a->triangle_count == b->triangle_count &&
           !memcmp(a->positions, b->positions, nv * sizeof(float)) &&
           !memcmp(a->normals, b->normals, nv * sizeof(float)) &&
           !memcmp(a->indices, b->indices, nt * sizeof(uint32_t));
}

static unsigned files, accepted;

static void compare(const char *path)
{
    size_t size = 0;
    uint8_t *bytes = test_read_file(path, &size);
    CHECK(bytes != NULL, "cannot read %s", path);
    if (!bytes)
        return;
    files++;
    for (int weld = 0; weld < 2; weld++) {
        vb_load_desc desc = {.weld = weld};
        vb_mesh a = {0}, b = {0};
        vb_source_info ia, ib;
        vb_error ea, eb;
        memset(&ia, 0, sizeof ia);
        memset(&ib, 0, sizeof ib);
        vb_result ra = vb_mesh_load(path, &desc, &a, &ia, &ea);
        vb_result rb = vb_mesh_load_memory(bytes, size, path, &desc, &b, &ib, &eb);
        CHECK(ra == rb, "%s (weld %d): file gives %s, memory %s", path, weld, vb_result_str(ra),
              vb_result_str(rb));
        if (ra == VB_OK && rb == VB_OK) {
            accepted += weld == 0;
            CHECK(same_mesh(&a, &b), "%s (weld %d): different meshes", path, weld);
            /* The record (a glTF's covers its external buffers too) and
             * the file's own bytes, alike from the file and the memory. */
            CHECK(ia.size == ib.size && ia.size >= size && !memcmp(ia.sha256, ib.sha256, 32) &&
                      ia.file_size == size && ib.file_size == size &&
                      !memcmp(ia.file_sha256, ib.file_sha256, 32),
                  "%s: different source info", path);
        } else if (ra != VB_OK && rb != VB_OK) {
            CHECK(strcmp(ea.msg, eb.msg) == 0, "%s: messages differ:\n  file:   %s\n  memory: %s",
                  path, ea.msg, eb.msg);
        }
        vb_mesh_free(&a);
        vb_mesh_free(&b);
    }
    free(bytes);
}

static void compare_dir(const char *dir)
{
    DIR *d = opendir(dir);
    CHECK(d != NULL, "cannot open %s", dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.' || !is_mesh_name(e->d_name))
            continue;
        char path[4096 + sizeof e->d_name];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat st;
        if (stat(path, &st) == 0 && S_ISREG(st.st_mode))
            compare(path);
    }
    closedir(d);
}

static int dir_is_empty(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    struct dirent *e;
    int n = 0;
    while ((e = readdir(d)) != NULL)
        n += e->d_name[0] != '.';
    closedir(d);
    return n == 0;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_robust_load TMP_DIR FILE_OR_DIR...\n");
        return 2;
    }
    /* A private $TMPDIR: loading must leave nothing in it. */
    const char *tmp = argv[1];
    mkdir(tmp, 0755);
    setenv("TMPDIR", tmp, 1);
    for (int i = 2; i < argc; i++) {
        struct stat st;
        if (stat(argv[i], &st) == 0 && S_ISDIR(st.st_mode))
            compare_dir(argv[i]);
        else
            compare(argv[i]);
    }
    CHECK(dir_is_empty(tmp), "temporary files left in %s", tmp);

    /* Arguments and names. */
    vb_mesh m = {0};
    vb_error err;
    static const char tri[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    CHECK(vb_mesh_load_memory(NULL, 4, "x.obj", NULL, &m, NULL, &err) == VB_ERR_ARGUMENT,
          "NULL data");
    CHECK(vb_mesh_load_memory(tri, sizeof tri - 1, NULL, NULL, &m, NULL, &err) == VB_ERR_ARGUMENT,
          "NULL name");
    CHECK(vb_mesh_load_memory(tri, sizeof tri - 1, "x.obj", NULL, NULL, NULL, &err) ==
              VB_ERR_ARGUMENT,
          "NULL output");
    CHECK(vb_mesh_load_memory(NULL, 0, "x.obj", NULL, &m, NULL, &err) == VB_ERR_FORMAT &&
              strcmp(err.msg, "x.obj: empty file") == 0,
          "no bytes: %s", err.msg);
    CHECK(vb_mesh_load_memory(tri, sizeof tri - 1, "builtin:room", NULL, &m, NULL, &err) ==
                  VB_ERR_FORMAT &&
              strstr(err.msg, "unsupported file type") != NULL,
          "builtin name: %s", err.msg);
    CHECK(vb_mesh_load_memory(tri, sizeof tri - 1, "dir.obj/mesh", NULL, &m, NULL, &err) ==
              VB_ERR_FORMAT,
          "extension of a folder, not of the name");
    CHECK(vb_mesh_load_memory(tri, sizeof tri - 1, "A.OBJ", NULL, &m, NULL, &err) == VB_OK &&
              m.triangle_count == 1,
          "upper-case extension: %s", err.msg);
    vb_mesh_free(&m);

    /* OFF from memory needs no temporary file: with a $TMPDIR that does
     * not exist, ascii and binary OFF load as they do with a usable one. */
    static const char off[] = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    static const unsigned char off_bin[] = "OFF BINARY\n\3\0\0\0\1\0\0\0\0\0\0\0"
                                           "\0\0\0\0\0\0\0\0\0\0\0\0"
                                           "\0\0\200\77\0\0\0\0\0\0\0\0"
                                           "\0\0\0\0\0\0\200\77\0\0\0\0"
                                           "\3\0\0\0\0\0\0\0\1\0\0\0\2\0\0\0";
    char missing[4200];
    snprintf(missing, sizeof missing, "%s/no/such/dir", tmp);
    setenv("TMPDIR", missing, 1);
    vb_result r = vb_mesh_load_memory(off, sizeof off - 1, "m.off", NULL, &m, NULL, &err);
    CHECK(r == VB_OK && m.vertex_count == 3 && m.triangle_count == 1 && m.positions[3] == 1.0f,
          "ascii OFF from memory without a usable TMPDIR: %s: %s", vb_result_str(r), err.msg);
    vb_mesh_free(&m);
    r = vb_mesh_load_memory(off_bin, sizeof off_bin - 1, "b.off", NULL, &m, NULL, &err);
    CHECK(r == VB_OK && m.vertex_count == 3 && m.triangle_count == 1 && m.positions[3] == 1.0f &&
              m.positions[7] == 1.0f,
          "binary OFF from memory without a usable TMPDIR: %s: %s", vb_result_str(r), err.msg);
    vb_mesh_free(&m);
    setenv("TMPDIR", tmp, 1);
    CHECK(dir_is_empty(tmp), "files left in %s", tmp);

    printf(
        "%u files: loading the bytes gives what loading the file gives (%u accepted, %u refused, each "
        "without and with welding)\n",
        files, accepted, files - accepted);
    CHECK(files >= 100 && accepted >= 30, "too few inputs (%u files, %u accepted)", files,
          accepted);
    return test_report("robust_load");
}
