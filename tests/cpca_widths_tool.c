/*
 * cpca_widths_tool.c - the cpca encoder with a bit width per basis vector,
 * for scripts/cpca_study's `K.B.wTe` settings (issue 29; measurement only,
 * no file format: vdsh_cpca_study.h).
 *
 *   cpca_widths_tool IN.vdsh ORDER K B FIT_BASIS BUDGET OUT.f32
 *
 * IN: a whole file with a fixed-order f32 stream of ORDER (scale 1);
 * BUDGET: bytes per vertex (the model included), `u` for the bytes of the
 * uniform 4-bit record of B vectors (vdsh-bake --cpca K,B,4's file), or
 * `=BITS` for every one of the first B vectors BITS bits (the others 0:
 * the same coefficients as vdsh-bake --cpca K,B,BITS). Writes the decoded
 * coefficients (rows x ORDER^2 little-endian f32) to OUT.f32 and one JSON
 * line to stdout: clusters, basis (vectors stored), words,
 * bytes_per_vertex, rms_error, widths. Exit 1 for a bad file or fit, 2
 * for bad usage.
 */
#include "cpca_tool.h"
#include "vdsh.h"
#include "vdsh_cpca_study.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc != 8) {
        fprintf(stderr, "usage: cpca_widths_tool IN.vdsh ORDER K B FIT_BASIS BUDGET|u|=BITS "
                        "OUT.f32\n");
        return 2;
    }
    unsigned order = (unsigned)atoi(argv[2]);
    vdsh_cpca_settings st = {.clusters = (uint32_t)atoi(argv[3]),
                             .basis = (uint32_t)atoi(argv[4]),
                             .bits = 4,
                             .budget = 0};
    uint32_t fit_basis = (uint32_t)atoi(argv[5]);
    vdsh_error err;
    vdsh_file *f;
    if (vdsh_read(argv[1], &f, &err) != VDSH_OK) {
        fprintf(stderr, "cpca_widths_tool: %s\n", err.msg);
        return 1;
    }
    const vdsh_stream *s = cpca_tool_stream(f, order);
    uint32_t rows = vdsh_file_stream_vertices(f), n = order * order;
    if (!s) {
        fprintf(stderr, "cpca_widths_tool: %s: no f32 stream of order %u (or a part)\n", argv[1],
                order);
        vdsh_free(f);
        return 1;
    }
    double budget = 0.0;
    uint8_t widths[VDSH_MAX_COEFFS] = {0};
    if (argv[6][0] == 'u') {
        budget = ((double)rows * 4.0 * vdsh_cpca_record_words(st.basis, 4) +
                  (double)vdsh_cpca_model_bytes(order, st.clusters < rows ? st.clusters : rows,
                                                st.basis, 0)) /
                 rows;
    } else if (argv[6][0] == '=') {
        for (uint32_t j = 0; j < st.basis && j < VDSH_MAX_COEFFS; j++)
            widths[j] = (uint8_t)atoi(argv[6] + 1);
    } else {
        budget = atof(argv[6]);
        if (!(budget > 0.0)) {
            fprintf(stderr, "cpca_widths_tool: budget '%s' is not a positive number\n", argv[6]);
            vdsh_free(f);
            return 2;
        }
    }
    float *dec = malloc(sizeof(float) * rows * n);
    vdsh_cpca_widths_fit wf;
    if (!dec || vdsh_cpca_encode_widths((const float *)s->data, f->normals, rows, order, &st,
                                        fit_basis, budget, widths, dec, &wf, &err) != VDSH_OK) {
        fprintf(stderr, "cpca_widths_tool: %s: %s\n", argv[1], dec ? err.msg : "out of memory");
        free(dec);
        vdsh_free(f);
        return 1;
    }
    FILE *o = fopen(argv[7], "wb");
    int ok = o && fwrite(dec, sizeof(float), (size_t)rows * n, o) == (size_t)rows * n;
    ok = (o && fclose(o) == 0) && ok;
    free(dec);
    vdsh_free(f);
    if (!ok) {
        fprintf(stderr, "cpca_widths_tool: cannot write %s\n", argv[7]);
        remove(argv[7]);
        return 1;
    }
    printf("{\"clusters\": %u, \"basis\": %u, \"words\": %u, \"bytes_per_vertex\": %.6f, "
           "\"rms_error\": %.9g, \"budget\": %.6f, \"widths\": [",
           wf.clusters, wf.basis, wf.words, wf.bytes_per_vertex, wf.rms_error, budget);
    for (uint32_t j = 0; j < wf.basis; j++)
        printf("%s%u", j ? ", " : "", wf.widths[j]);
    printf("]}\n");
    return 0;
}
