/*
 * vdsh_compare A.vdsh B.vdsh [TOL [SHARE [LIMIT]]]: how far apart two bakes of the same
 * scene are. The geometry (positions, normals, indices) and the stream
 * list must match exactly; per stream it prints the vertices whose
 * coefficients differ and the largest difference in units of the stream's
 * largest |coefficient| (its f16 scale). Exit 0 when every difference is
 * at most TOL (default 0: identical) and at most a SHARE of the vertices
 * (default 1) differ by more than LIMIT (default 1e-3: beyond the f16
 * rounding of a stream whose scale moved), all in units of the first
 * file's largest |coefficient|; 1 otherwise; 2 on usage or read errors.
 * It prints the median and 99th percentile of the vertices' differences
 * too (cpca streams: the encoder's discrete choices spread them).
 * Used by the cross-ISA tests (tests/bake.cmake).
 * A variable-order stream's vertices whose orders differ count among
 * those beyond 1e-3 (and are printed); the others are compared as above.
 * With VDSH_COMPARE_LIST=1 in the environment it lists every vertex beyond
 * LIMIT too (index, position, difference): where two bakes part.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vdsh.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 3 || argc > 6) {
        fprintf(stderr, "usage: vdsh_compare A.vdsh B.vdsh [TOL [SHARE [LIMIT]]]\n");
        return 2;
    }
    double tol = argc >= 4 ? strtod(argv[3], NULL) : 0.0;
    double share = argc >= 5 ? strtod(argv[4], NULL) : 1.0;
    double limit = argc >= 6 ? strtod(argv[5], NULL) : 1e-3;
    vdsh_file *a = NULL, *b = NULL;
    vdsh_error err;
    if (vdsh_read(argv[1], &a, &err) != VDSH_OK || vdsh_read(argv[2], &b, &err) != VDSH_OK) {
        fprintf(stderr, "vdsh_compare: %s\n", err.msg);
        vdsh_free(a);
        return 2;
    }
    int status = 0;
    double *diffs = NULL;
    const char *list_env = getenv("VDSH_COMPARE_LIST");
    const int list = list_env && strcmp(list_env, "1") == 0;
    if (a->has_part || b->has_part) { /* streams of one range: compare merged files */
        fprintf(stderr, "vdsh_compare: a part of a sharded bake: merge it first\n");
        vdsh_free(a);
        vdsh_free(b);
        return 2;
    }
    uint32_t V = a->header.vertex_count, T = a->header.triangle_count;
    if (V != b->header.vertex_count || T != b->header.triangle_count ||
        memcmp(a->positions, b->positions, 3 * sizeof(float) * V) ||
        memcmp(a->normals, b->normals, 3 * sizeof(float) * V) ||
        memcmp(a->indices, b->indices, 3 * sizeof(uint32_t) * T) ||
        a->stream_count != b->stream_count) {
        printf("geometry or stream list differ\n");
        status = 1;
        goto out;
    }
    for (uint32_t s = 0; s < a->stream_count; s++) {
        const vdsh_stream *x = a->streams + s, *y = b->streams + s;
        if (x->order != y->order || x->quantity != y->quantity || x->flags != y->flags) {
            printf("stream %u: order or quantity differ\n", s);
            status = 1;
            continue;
        }
        uint32_t nc = x->order * x->order, differ = 0, above = 0, worst = 0, reordered = 0, nd = 0;
        free(diffs);
        if (!(diffs = malloc(((size_t)V + 1) * sizeof *diffs))) {
            fprintf(stderr, "vdsh_compare: out of memory\n");
            status = 2;
            goto out;
        }
        float cx[VDSH_MAX_COEFFS], cy[VDSH_MAX_COEFFS];
        double maxc = 0.0, maxd = 0.0;
        for (uint32_t v = 0; v < V; v++) {
            vdsh_stream_decode(x, v, cx);
            for (uint32_t i = 0; i < nc; i++)
                maxc = fmax(maxc, fabs(cx[i]));
        }
        for (uint32_t v = 0; v < V; v++) {
            if (vdsh_stream_vertex_order(x, v) != vdsh_stream_vertex_order(y, v)) {
                reordered++, differ++, above++; /* another order chosen */
                continue;
            }
            vdsh_stream_decode(x, v, cx);
            vdsh_stream_decode(y, v, cy);
            double dv = 0.0;
            for (uint32_t i = 0; i < nc; i++)
                dv = fmax(dv, fabs((double)cx[i] - cy[i]));
            differ += dv > 0.0;
            above += dv > limit * maxc; /* beyond the f16 rounding of a rescaled stream */
            if (list && dv > limit * maxc)
                printf("  order %u vertex %u at %g %g %g: %.3g\n", x->order, v,
                       (double)a->positions[3 * (size_t)v], (double)a->positions[3 * (size_t)v + 1],
                       (double)a->positions[3 * (size_t)v + 2], maxc > 0.0 ? dv / maxc : dv);
            diffs[nd++] = maxc > 0.0 ? dv / maxc : dv;
            if (dv > maxd)
                maxd = dv, worst = v;
        }
        double rel = maxc > 0.0 ? maxd / maxc : maxd;
        qsort(diffs, nd, sizeof *diffs, cmp_double);
        printf("order %u %s: %u of %u vertices differ (%u by more than %g), largest "
               "difference %.3g of the largest |coefficient|, median %.3g, 99th percentile %.3g",
               x->order, vdsh_quantity_name(x->quantity), differ, V, above, limit, rel,
               nd ? diffs[nd / 2] : 0.0, nd ? diffs[(size_t)(0.99 * (nd - 1))] : 0.0);
        if (differ)
            printf(" (vertex %u at %g %g %g)", worst, (double)a->positions[3 * (size_t)worst],
                   (double)a->positions[3 * (size_t)worst + 1],
                   (double)a->positions[3 * (size_t)worst + 2]);
        if (x->flags & VDSH_STREAM_VARIABLE)
            printf("; variable order: %u vertices with another order", reordered);
        printf("\n");
        if (rel > tol || above > share * V)
            status = 1;
    }
out:
    free(diffs);
    vdsh_free(a);
    vdsh_free(b);
    return status;
}
