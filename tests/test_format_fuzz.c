/*
 * test_format_fuzz.c - fuzz target for the .vdsh reader.
 *
 * With libFuzzer:
 *     clang -g -O1 -fsanitize=fuzzer,address,undefined -DVDSH_LIBFUZZER \
 *         -Iformats tests/test_format_fuzz.c formats/vdsh*.c -lz -lm -o fuzz_vdsh
 *     ./fuzz_vdsh corpus/     (seed it with the files test_format_tool makes)
 * Without it, main() replays the files named on the command line (ctest
 * runs it on the vdsh-info fixtures), so every crash input can become a
 * regression test.
 *
 * Property checked beyond "no crash": whatever the reader accepts, the
 * writer accepts too and writes back to bytes that read the same; a
 * part's `part` and `lpol` chunks read back as they were (the corpus has
 * parts: box-s8s6-part1of2.vdsh, box-cpca-part0of2-lpol6.vdsh, and
 * box-cpca-part0of2-lpol6-margin-starts2.vdsh with a margin and starts), and an
 * lreg chunk the same (cubefloor-f16-lreg-grown.vdsh).
 *
 * Random bytes almost never pass the CRCs, so the value rules behind them
 * are reached by a second pass over a copy whose CRCs have been recomputed
 * (the test knows the layout for that on purpose).
 */
#include "vdsh.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void wr32(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

/* Recompute the chunk CRCs as far as the stored sizes allow, then the
 * header CRC. */
static void fix_crcs(uint8_t *d, size_t size)
{
    if (size < 32)
        return;
    size_t off = 32;
    while (size - off >= 16) {
        uint64_t n = rd32(d + off + 8) | (uint64_t)rd32(d + off + 12) << 32;
        uint64_t room = size - off - 16;
        if (n > room || ((16 - (n & 15)) & 15) > room - n)
            break;
        size_t padded = (size_t)((n + 15) & ~(uint64_t)15);
        uint32_t crc = vdsh_crc32(0, d + off, 4);
        crc = vdsh_crc32(crc, d + off + 8, 8);
        wr32(d + off + 4, vdsh_crc32(crc, d + off + 16, padded));
        off += 16 + padded;
    }
    wr32(d + 28, vdsh_crc32(0, d, 28));
}

static void one_input(const uint8_t *data, size_t size)
{
    vdsh_file *f = NULL, *g = NULL;
    vdsh_error err;
    vdsh_chunk_info info[8];
    uint32_t count;
    void *mem = NULL, *mem2 = NULL;
    size_t n = 0, n2 = 0;

    (void)vdsh_scan_chunks(data, size, "fuzz", info, 8, &count, &err);
    if (vdsh_read_memory(data, size, "fuzz", &f, &err) != VDSH_OK)
        return;
    float c[VDSH_MAX_COEFFS];
    /* The last row: a part's streams hold its range's rows only (row
     * vertex_count - 1 of one read past the file, ASan: the first part
     * seed) */
    const uint32_t rows = vdsh_file_stream_vertices(f);
    for (uint32_t i = 0; rows && i < f->stream_count; i++)
        vdsh_stream_decode(&f->streams[i], rows - 1, c);
    if (vdsh_write_memory(f, &mem, &n, &err) != VDSH_OK ||
        vdsh_read_memory(mem, n, "fuzz-rewritten", &g, &err) != VDSH_OK ||
        vdsh_write_memory(g, &mem2, &n2, &err) != VDSH_OK || n != n2 || memcmp(mem, mem2, n) != 0) {
        fprintf(stderr, "accepted input does not survive a rewrite: %s\n", err.msg);
        abort();
    }
    /* A part (`part`, and `lpol` for a cpca part with a light mix) reads
     * back as it was: shard, range, merge settings, margin, starts, pool
     * bit for bit. */
    if (g->has_part != f->has_part || g->has_light_pool != f->has_light_pool ||
        (f->has_part && memcmp(&f->part, &g->part, sizeof f->part) != 0) ||
        (f->has_light_pool &&
         (memcmp(&f->light_pool.mix, &g->light_pool.mix, sizeof f->light_pool.mix) != 0 ||
          memcmp(&f->light_pool.margin, &g->light_pool.margin, sizeof f->light_pool.margin) != 0 ||
          f->light_pool.starts != g->light_pool.starts ||
          f->light_pool.count != g->light_pool.count ||
          memcmp(f->light_pool.lights, g->light_pool.lights,
                 3 * sizeof(float) * f->light_pool.count) != 0))) {
        fprintf(stderr, "a part's part or lpol chunk does not survive a rewrite\n");
        abort();
    }
    /* The light region (`lreg`, vdsh-bake --light-region) too, bit for bit. */
    if (g->has_light_box != f->has_light_box ||
        (f->has_light_box && memcmp(&f->light_box, &g->light_box, sizeof f->light_box) != 0)) {
        fprintf(stderr, "an lreg chunk does not survive a rewrite\n");
        abort();
    }
    free(mem);
    free(mem2);
    vdsh_free(g);
    vdsh_free(f);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    one_input(data, size);
    uint8_t *copy = malloc(size ? size : 1);
    if (!copy)
        return 0;
    memcpy(copy, data, size);
    fix_crcs(copy, size);
    one_input(copy, size);
    free(copy);
    return 0;
}

#ifndef VDSH_LIBFUZZER
int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        FILE *fp = fopen(argv[i], "rb");
        if (!fp) {
            perror(argv[i]);
            return 1;
        }
        size_t cap = 1 << 16, n = 0;
        uint8_t *buf = malloc(cap);
        size_t k;
        while ((k = fread(buf + n, 1, cap - n, fp)) > 0) {
            n += k;
            if (n == cap)
                buf = realloc(buf, cap *= 2);
        }
        fclose(fp);
        /* An exact-size copy, so ASan sees any read past the end. */
        uint8_t *exact = malloc(n ? n : 1);
        memcpy(exact, buf, n);
        free(buf);
        LLVMFuzzerTestOneInput(exact, n);
        free(exact);
        printf("%s: %zu bytes replayed\n", argv[i], n);
    }
    return 0;
}
#endif
