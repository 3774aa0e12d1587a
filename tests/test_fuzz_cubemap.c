/*
 * test_fuzz_cubemap.c - fuzz target for the basis cubemap reader
 * (vb_cubemap_read, bake/lib/cubemap.h): OpenEXR's header and chunk parsing
 * as we drive it, our checks on shape and channels, the decode into our
 * buffer, the finiteness check.
 *
 * vb_cubemap_read takes a path, so each input is written to one temporary
 * file (per process, in $TMPDIR or /tmp) and read from there. OpenEXR
 * itself is not instrumented for coverage in this build, so the fuzzer
 * mostly explores the paths our code takes; ASan still sees OpenEXR
 * writing past the buffers we hand it.
 *
 * Properties beyond "no crash, no leak": a rejection names the file; an
 * accepted map has a size in 1..VB_CUBEMAP_MAX_SIZE and finite values.
 */
#include "cubemap.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char path[4096];

static void remove_temp(void)
{
    unlink(path);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!path[0]) {
        const char *dir = getenv("TMPDIR");
        snprintf(path, sizeof path, "%s/vdsh-fuzz-cubemap-%ld.exr", dir && dir[0] ? dir : "/tmp",
                 (long)getpid());
        atexit(remove_temp);
    }
    FILE *fp = fopen(path, "wb");
    if (!fp || fwrite(data, 1, size, fp) != size || fclose(fp) != 0)
        abort();
    vb_cubemap *map = NULL;
    vb_error err;
    if (vb_cubemap_read(path, &map, &err) != VB_OK) {
        if (strncmp(err.msg, path, strlen(path)) != 0)
            abort();
        return 0;
    }
    if (map->size < 1 || map->size > VB_CUBEMAP_MAX_SIZE)
        abort();
    for (size_t k = 0; k < (size_t)map->size * (size_t)map->size * 24; k++)
        if (!isfinite(map->rgba[k]))
            abort();
    vb_cubemap_free(map);
    return 0;
}
