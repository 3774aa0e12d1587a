/*
 * mesh.c - loading (dispatch, file bytes, hashing, validation and
 * cleaning), welding, normals, appending, bounds and OBJ output for
 * vb_mesh. Reading a file's bytes into arrays is mesh_parse.cpp's and
 * its readers' (mesh_parse.h); refinement, the one part on OpenMesh, is
 * mesh_refine.cpp's; SHA-256 is nettle's.
 */
#include "mesh.h"
#include "mesh_parse.h"
#include "vdsh_math.h"
#include "vdsh_output.h"
#include "vdsh_det.h"

#include <nettle/sha2.h>

#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---------------------------------------------------------------------- */
/* Small helpers                                                          */
/* ---------------------------------------------------------------------- */

void vb_mesh_free(vb_mesh *m)
{
    if (!m)
        return;
    free(m->positions);
    free(m->normals);
    free(m->indices);
    memset(m, 0, sizeof *m);
}

void vb_mesh_bounds(const vb_mesh *m, float min[3], float max[3])
{
    for (int k = 0; k < 3; k++)
        min[k] = max[k] = 0.0f;
    if (!m || m->vertex_count == 0 || !m->positions)
        return;
    for (int k = 0; k < 3; k++)
        min[k] = max[k] = m->positions[k];
    for (uint32_t i = 1; i < m->vertex_count; i++) {
        const float *p = m->positions + 3 * (size_t)i;
        for (int k = 0; k < 3; k++) {
            if (p[k] < min[k])
                min[k] = p[k];
            if (p[k] > max[k])
                max[k] = p[k];
        }
    }
}

/* Receiver spacing: longest edges in log-spaced bins, 1% wide, from
 * 1e-6 of the diagonal up (anything longer than the diagonal in the last). */
#define SPACING_BINS 1400
#define SPACING_STEP 0.01 /* ln of a bin's width ratio */
#define SPACING_LOW 1e-6

/* 10^(n - 1) for the largest n with 10^n <= x, the step of x's second
 * digit (0.1 for x not positive and finite): by exact products and one
 * correctly rounded division, the same bits on every CPU (libm's log10
 * differs between CPUs, vdsh_det.h) */
static double second_digit_step(double x)
{
    double q = 1.0; /* 10^|n - 1| */
    if (!(x > 0.0 && x < 1e300))
        return 0.1;
    if (x >= 10.0) {
        while (q * 100.0 <= x)
            q *= 10.0;
        return q;
    }
    q = 10.0; /* x in [10^n, 10^(n+1)) with n <= 0: 1 / 10^(1 - n) */
    while (10.0 / q > x)
        q *= 10.0;
    return 1.0 / q;
}

void vb_mesh_spacing_of(const vb_mesh *m, float diagonal, vb_mesh_spacing *s)
{
    memset(s, 0, sizeof *s);
    if (!(diagonal > 0.0f)) {
        float lo[3], hi[3];
        vb_mesh_bounds(m, lo, hi);
        diagonal = sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                         (hi[2] - lo[2]) * (hi[2] - lo[2]));
    }
    s->diagonal = diagonal;
    if (!m || !m->positions || !m->indices || !(diagonal > 0.0f))
        return;
    double bin[SPACING_BINS] = {0}; /* area per bin */
    const double limit = (double)VB_SPACING_WARN_EDGE * diagonal;
    double area = 0.0, long_area = 0.0, longest = 0.0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *tri = m->indices + 3 * (size_t)t;
        const float *p[3] = {m->positions + 3 * (size_t)tri[0], m->positions + 3 * (size_t)tri[1],
                             m->positions + 3 * (size_t)tri[2]};
        double e[3][3], l2 = 0.0;
        for (int c = 0; c < 3; c++) {
            double q = 0.0;
            for (int k = 0; k < 3; k++) {
                e[c][k] = (double)p[(c + 1) % 3][k] - p[c][k];
                q += e[c][k] * e[c][k];
            }
            l2 = q > l2 ? q : l2;
        }
        const double cx = e[0][1] * e[2][2] - e[0][2] * e[2][1],
                     cy = e[0][2] * e[2][0] - e[0][0] * e[2][2],
                     cz = e[0][0] * e[2][1] - e[0][1] * e[2][0];
        const double a = 0.5 * sqrt(cx * cx + cy * cy + cz * cz), l = sqrt(l2);
        area += a;
        longest = l > longest ? l : longest;
        if (l > limit)
            long_area += a;
        double r = l / diagonal;
        int b = r > SPACING_LOW ? (int)(vdsh_det_log(r / SPACING_LOW) / SPACING_STEP) : 0;
        bin[b < SPACING_BINS ? b : SPACING_BINS - 1] += a;
    }
    s->area = area;
    s->max_edge = (float)longest;
    if (!(area > 0.0))
        return;
    s->long_area = long_area / area;
    s->far_apart = s->long_area > VB_SPACING_WARN_AREA;
    /* quantiles: a bin's geometric middle */
    double sum = 0.0;
    for (int b = 0; b < SPACING_BINS && !(s->p90_edge > 0.0f); b++) {
        sum += bin[b];
        double mid = SPACING_LOW * vdsh_det_exp((b + 0.5) * SPACING_STEP) * diagonal;
        if (mid > longest)
            mid = longest;
        if (!(s->median_edge > 0.0f) && sum >= 0.5 * area)
            s->median_edge = (float)mid;
        if (sum >= 0.9 * area)
            s->p90_edge = (float)mid;
    }
    double want = (double)VB_SPACING_SUGGEST * diagonal;
    double mag = second_digit_step(want);
    s->suggest_edge = (float)(round(want / mag) * mag);
}

void vb_sha256(const void *data, size_t size, uint8_t out[32])
{
    struct sha256_ctx ctx;
    sha256_init(&ctx);
    if (size)
        sha256_update(&ctx, size, (const uint8_t *)data);
    sha256_digest(&ctx, SHA256_DIGEST_SIZE, out);
}

/* "s" for a count other than 1. */
static const char *plural(uint32_t n)
{
    return n == 1 ? "" : "s";
}

/* The warning for n polygons fanned instead of ear-clipped, and why; the
 * fans cover 1 + excess times the area the polygons enclose (infinite when
 * they enclose none: a bowtie). */
static void warn_fanned(FILE *fp, const char *tool, const char *sep, const char *path, uint32_t n,
                        double excess, const char *why)
{
    if (!n)
        return;
    fprintf(fp,
            "%s%s%s: warning: %u polygon%s of 4 or more vertices %s, so not ear-clipped: fanned "
            "from the first vertex, ",
            tool, sep, path, n, plural(n), why);
    if (isfinite(excess))
        fprintf(fp, "the triangles cover %.3gx the area %s, part of it outside the face",
                1.0 + excess, n == 1 ? "it encloses" : "they enclose");
    else
        fprintf(fp, "the triangles cover area where %s none",
                n == 1 ? "it encloses" : "they enclose");
    fprintf(fp, "; triangulate %s in the exporter\n", n == 1 ? "it" : "them");
}

void vb_mesh_report_print(FILE *fp, const char *tool, const char *path, const vb_mesh_report *r)
{
    if (!fp || !r)
        return;
    const char *sep = tool ? ": " : "";
    tool = tool ? tool : "";
    path = path ? path : "(mesh)";
    if (r->dropped_triangles)
        fprintf(fp, "%s%s%s: %u triangle%s dropped (a repeated vertex index: no area)\n", tool, sep,
                path, r->dropped_triangles, plural(r->dropped_triangles));
    if (r->duplicate_triangles)
        fprintf(fp,
                "%s%s%s: %u duplicate triangle%s dropped (the same three positions as an earlier "
                "triangle, in any order)\n",
                tool, sep, path, r->duplicate_triangles, plural(r->duplicate_triangles));
    if (r->removed_vertices)
        fprintf(fp, "%s%s%s: %u vert%s removed (used by no remaining triangle)\n", tool, sep, path,
                r->removed_vertices, r->removed_vertices == 1 ? "ex" : "ices");
    if (r->split_vertices)
        fprintf(fp,
                "%s%s%s: %u vert%s split at creases (their face corners give normals more than %g "
                "degrees apart): %u vert%s added (in the count above)\n",
                tool, sep, path, r->split_vertices, r->split_vertices == 1 ? "ex" : "ices",
                VB_MESH_NORMAL_AGREE_DEG, r->split_added, r->split_added == 1 ? "ex" : "ices");
    if (r->missing_normals)
        fprintf(
            fp,
            "%s%s%s: %u used vert%s no normal in the file: every normal computed from the faces "
            "instead\n",
            tool, sep, path, r->missing_normals, r->missing_normals == 1 ? "ex has" : "ices have");
    if (r->zero_normals) {
        /* One line: what became of each of them. */
        char what[256] = "";
        size_t at = 0;
        if (r->zero_repaired)
            at += (size_t)snprintf(what + at, sizeof what - at,
                                   "%s%u given their own triangles' normal", at ? ", " : "",
                                   r->zero_repaired);
        if (r->zero_cancelled && at < sizeof what)
            at +=
                (size_t)snprintf(what + at, sizeof what - at,
                                 "%s%u their largest triangle's (their triangles' normals cancel: "
                                 "two-sided)",
                                 at ? ", " : "", r->zero_cancelled);
        if (r->zero_undefined && at < sizeof what)
            at +=
                (size_t)snprintf(what + at, sizeof what - at,
                                 "%s%u left without a normal (0,0,0: their triangles have no area)",
                                 at ? ", " : "", r->zero_undefined);
        fprintf(fp, "%s%s%s: %u vert%s a zero normal in the file: %s\n", tool, sep, path,
                r->zero_normals, r->zero_normals == 1 ? "ex has" : "ices have", what);
    }
    if (r->cancelled_normals)
        fprintf(
            fp,
            "%s%s%s: %u vert%s face normals cancel (two-sided triangles): each given the normal of "
            "its largest triangle\n",
            tool, sep, path, r->cancelled_normals, r->cancelled_normals == 1 ? "ex's" : "ices'");
    if (r->welded)
        fprintf(fp, "%s%s%s: %u vert%s merged by welding (normals then computed from the faces)\n",
                tool, sep, path, r->welded, r->welded == 1 ? "ex" : "ices");
    if (r->crease_vertices)
        fprintf(fp,
                "%s%s%s: %u vert%s split at creases of the computed normals (the crease "
                "angle): %u vert%s added\n",
                tool, sep, path, r->crease_vertices, r->crease_vertices == 1 ? "ex" : "ices",
                r->crease_added, r->crease_added == 1 ? "ex" : "ices");
    if (r->gltf_skipped_modes)
        fprintf(fp, "%s%s%s: %u glTF primitive%s of points or lines skipped (no surface)\n", tool,
                sep, path, r->gltf_skipped_modes, plural(r->gltf_skipped_modes));
    if (r->gltf_skipped_morph)
        fprintf(fp,
                "%s%s%s: %u glTF primitive%s with morph targets baked in the base pose (targets "
                "ignored)\n",
                tool, sep, path, r->gltf_skipped_morph, plural(r->gltf_skipped_morph));
    if (r->gltf_skipped_skin)
        fprintf(fp,
                "%s%s%s: %u glTF primitive%s of skinned nodes baked in the bind pose (skin and "
                "node transform ignored)\n",
                tool, sep, path, r->gltf_skipped_skin, plural(r->gltf_skipped_skin));
    warn_fanned(fp, tool, sep, path, r->nonconvex_polygons, r->nonconvex_excess,
                "not simple (or far from flat)");
    warn_fanned(fp, tool, sep, path, r->unclipped_polygons, r->unclipped_excess,
                "too large to clip (past the ear clipping's time bound)");
    if (r->gltf_ragged)
        fprintf(fp,
                "%s%s%s: %u glTF triangle list%s with a count not a multiple of 3 (invalid "
                "glTF): the last 1 or 2 indices ignored\n",
                tool, sep, path, r->gltf_ragged, r->gltf_ragged == 1 ? "" : "s");
    /* the zero file normals left undefined were said above */
    uint32_t undefined =
        r->undefined_normals -
        (r->zero_undefined < r->undefined_normals ? r->zero_undefined : r->undefined_normals);
    if (undefined)
        fprintf(fp,
                "%s%s%s: %u vert%s left without a normal (0,0,0): their triangles have no area\n",
                tool, sep, path, undefined, undefined == 1 ? "ex" : "ices");
}

/* n * size bytes, or NULL when that overflows or malloc fails; never a
 * zero-byte request (so NULL always means failure). */
static void *alloc_array(size_t n, size_t size)
{
    if (size != 0 && n > SIZE_MAX / size)
        return NULL;
    size_t bytes = n * size;
    return malloc(bytes ? bytes : 1);
}

/* ---------------------------------------------------------------------- */
/* Normals                                                                */
/* ---------------------------------------------------------------------- */

/* Angle-weighted vertex normals (Thürmer and Wüthrich): each triangle adds
 * its unit normal times its angle at the corner. Unlike area weighting this
 * does not depend on how a flat region happens to be triangulated, and it
 * only ever sees the vertex's own triangles, so unwelded hard edges stay
 * hard. Arithmetic in double: coordinates of 1e5 with millimetre edges
 * would lose the cross product in float.
 *
 * A sum shorter than CANCEL times the sum of its weights has cancelled:
 * the vertex sits on a two-sided triangle (a triangle and its reverse, as
 * crude decimations leave) or a zero-width fold, and what is left of the
 * sum is rounding, pointing anywhere. Such a vertex takes the unit normal
 * of its largest triangle instead (the first of equal ones); `cancelled`
 * (may be NULL) marks them. */
#define CANCEL 1e-5

int vb_triangle_has_area(const float *positions, const uint32_t *ix)
{
    const float *a = positions + 3 * (size_t)ix[0];
    const float *b = positions + 3 * (size_t)ix[1];
    const float *c = positions + 3 * (size_t)ix[2];
    double e1[3], e2[3];
    for (int i = 0; i < 3; i++)
        e1[i] = (double)b[i] - a[i], e2[i] = (double)c[i] - a[i];
    double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2],
           z = e1[0] * e2[1] - e1[1] * e2[0];
    double len = sqrt(x * x + y * y + z * z);
    return len > 0.0 && isfinite(len);
}

uint32_t vb_drawn_receivers(const float *positions, uint32_t vertex_count, const uint32_t *indices,
                            uint32_t triangle_count, uint8_t *drawn)
{
    if (vertex_count)
        memset(drawn, 0, vertex_count);
    for (uint32_t t = 0; t < triangle_count; t++) {
        const uint32_t *ix = indices + 3 * (size_t)t;
        if (ix[0] >= vertex_count || ix[1] >= vertex_count || ix[2] >= vertex_count ||
            !vb_triangle_has_area(positions, ix))
            continue;
        drawn[ix[0]] = drawn[ix[1]] = drawn[ix[2]] = 1;
    }
    uint32_t n = 0;
    for (uint32_t v = 0; v < vertex_count; v++)
        n += drawn[v];
    if (n == 0 && vertex_count) {
        memset(drawn, 1, vertex_count);
        n = vertex_count;
    }
    return n;
}

/* Triangle t's corners (double) and unit normal; 0 when its indices are
 * out of range or it has no area, else twice its area. */
static double triangle_normal(const vb_mesh *m, uint32_t t, double p[3][3], double n[3])
{
    const uint32_t *tri = m->indices + 3 * (size_t)t;
    if (tri[0] >= m->vertex_count || tri[1] >= m->vertex_count || tri[2] >= m->vertex_count)
        return 0.0;
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 3; k++)
            p[c][k] = m->positions[3 * (size_t)tri[c] + (size_t)k];
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = p[1][k] - p[0][k];
        e2[k] = p[2][k] - p[0][k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0) || !isfinite(len))
        return 0.0;
    for (int k = 0; k < 3; k++)
        n[k] /= len;
    return len;
}

static void compute_normals(vb_mesh *m, uint8_t *cancelled)
{
    if (!m || !m->positions)
        return;
    if (!m->normals) {
        m->normals = alloc_array(3 * (size_t)m->vertex_count, sizeof(float));
        if (!m->normals)
            return;
    }
    memset(m->normals, 0, 3 * (size_t)m->vertex_count * sizeof(float));
    if (cancelled)
        memset(cancelled, 0, m->vertex_count);
    /* Each vertex's sum of weights (angles); without room for them,
     * cancellation goes undetected. */
    float *weight = calloc(m->vertex_count ? m->vertex_count : 1, sizeof(float));

    /* 1. Sum each triangle's unit normal times its angle at the corner. */
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        double p[3][3], n[3];
        if (triangle_normal(m, t, p, n) == 0.0)
            continue;
        const uint32_t *tri = m->indices + 3 * (size_t)t;
        for (int c = 0; c < 3; c++) {
            const double *a = p[c], *b = p[(c + 1) % 3], *d = p[(c + 2) % 3];
            double u[3], v[3];
            for (int k = 0; k < 3; k++) {
                u[k] = b[k] - a[k];
                v[k] = d[k] - a[k];
            }
            double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2],
                   cz = u[0] * v[1] - u[1] * v[0];
            double angle = vdsh_det_atan2(sqrt(cx * cx + cy * cy + cz * cz),
                                          u[0] * v[0] + u[1] * v[1] + u[2] * v[2]);
            float *out = m->normals + 3 * (size_t)tri[c];
            for (int k = 0; k < 3; k++)
                out[k] += (float)(n[k] * angle);
            if (weight)
                weight[tri[c]] += (float)angle;
        }
    }

    /* 2. Normalise; a sum that cancelled becomes (0,0,0) for now and its
     * weight -1. */
    uint32_t any = 0;
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        float *out = m->normals + 3 * (size_t)i;
        double len =
            sqrt((double)out[0] * out[0] + (double)out[1] * out[1] + (double)out[2] * out[2]);
        if (weight && weight[i] > 0.0f && !(len > CANCEL * weight[i])) {
            weight[i] = -1.0f;
            any++;
            len = 0.0;
        }
        for (int k = 0; k < 3; k++)
            out[k] = len > 1e-30 ? (float)(out[k] / len) : 0.0f;
    }

    /* 3. A cancelled vertex takes its largest triangle's normal. */
    double *best = any ? calloc(m->vertex_count, sizeof(double)) : NULL;
    for (uint32_t t = 0; best && t < m->triangle_count; t++) {
        const uint32_t *tri = m->indices + 3 * (size_t)t;
        if (tri[0] >= m->vertex_count || tri[1] >= m->vertex_count || tri[2] >= m->vertex_count ||
            (weight[tri[0]] >= 0.0f && weight[tri[1]] >= 0.0f && weight[tri[2]] >= 0.0f))
            continue;
        double p[3][3], n[3];
        double len = triangle_normal(m, t, p, n);
        for (int c = 0; c < 3; c++) {
            uint32_t v = tri[c];
            if (weight[v] < 0.0f && len > best[v]) {
                best[v] = len;
                for (int k = 0; k < 3; k++)
                    m->normals[3 * (size_t)v + (size_t)k] = (float)n[k];
                if (cancelled)
                    cancelled[v] = 1;
            }
        }
    }
    free(best);
    free(weight);
}

void vb_mesh_compute_normals(vb_mesh *m)
{
    compute_normals(m, NULL);
}

/* ---------------------------------------------------------------------- */
/* Creases of computed normals (vb_load_desc.crease)                      */
/* ---------------------------------------------------------------------- */

static uint32_t uf_find(uint32_t *parent, uint32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* The lower root wins, so a fan's root is its first triangle in order. */
static void uf_join(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = uf_find(parent, a), b = uf_find(parent, b);
    if (a < b)
        parent[b] = a;
    else if (b < a)
        parent[a] = b;
}

/* (other vertex, slot) of one triangle around a vertex, sorted by other
 * vertex so that triangles sharing an edge through the vertex neighbour. */
typedef struct crease_edge {
    uint32_t other, slot;
} crease_edge;

static int crease_edge_cmp(const void *pa, const void *pb)
{
    const crease_edge *a = pa, *b = pb;
    if (a->other != b->other)
        return a->other < b->other ? -1 : 1;
    return a->slot < b->slot ? -1 : a->slot > b->slot;
}

/* Splits m's vertices at creases sharper than crease_deg (mesh.h,
 * vb_load_desc.crease) and recomputes its normals. Each vertex's triangles
 * (in triangle order) are joined across the edges through it whose two
 * face normals are at most crease_deg apart; triangles without area join
 * the vertex's first fan. A vertex with one fan keeps its place; one with
 * k fans becomes k vertices in a row, in the order of each fan's first
 * triangle. *split, *added: vertices split, vertices added. Nothing
 * changes when no vertex splits (the normals then are recomputed as they
 * were). */
static vb_result crease_split(vb_mesh *m, int crease_deg, uint8_t **cancelled, uint32_t *split,
                              uint32_t *added)
{
    *split = *added = 0;
    const uint32_t nv = m->vertex_count, nt = m->triangle_count;
    const size_t corners = 3 * (size_t)nt;
    const double agree = vdsh_det_cos(crease_deg * 3.14159265358979323846 / 180.0);
    double *fn = alloc_array(3 * (size_t)(nt ? nt : 1), sizeof *fn);
    uint8_t *area = calloc(nt ? nt : 1, 1);
    size_t *start = calloc((size_t)nv + 1, sizeof *start);
    size_t *list = alloc_array(corners ? corners : 1, sizeof *list);
    uint32_t *slot_group = alloc_array(corners ? corners : 1, sizeof *slot_group);
    uint32_t *groups = alloc_array(nv ? nv : 1, sizeof *groups);
    uint32_t *parent = NULL, *label = NULL;
    crease_edge *edges = NULL;
    size_t cap = 0;
    vb_result r = VB_ERR_OUT_OF_MEMORY;
    if (!fn || !area || !start || !list || !slot_group || !groups)
        goto done;
    for (uint32_t t = 0; t < nt; t++) {
        double p[3][3];
        area[t] = triangle_normal(m, t, p, fn + 3 * (size_t)t) != 0.0;
    }
    for (size_t c = 0; c < corners; c++)
        start[m->indices[c] + 1]++;
    for (uint32_t v = 0; v < nv; v++)
        start[v + 1] += start[v];
    {
        size_t *fill = alloc_array(nv ? nv : 1, sizeof *fill);
        if (!fill)
            goto done;
        memcpy(fill, start, nv * sizeof *fill);
        for (size_t c = 0; c < corners; c++)
            list[fill[m->indices[c]]++] = c;
        free(fill);
    }
    uint64_t total = 0;
    for (uint32_t v = 0; v < nv; v++) {
        const size_t s0 = start[v];
        const uint32_t k = (uint32_t)(start[v + 1] - s0);
        if (k > cap) {
            size_t nc = k > 2 * cap ? k : 2 * cap;
            uint32_t *np = realloc(parent, nc * sizeof *np), *nl = NULL;
            if (np)
                parent = np;
            nl = np ? realloc(label, nc * sizeof *nl) : NULL;
            if (nl)
                label = nl;
            crease_edge *ne = nl ? realloc(edges, 2 * nc * sizeof *ne) : NULL;
            if (!ne)
                goto done;
            edges = ne;
            cap = nc;
        }
        for (uint32_t i = 0; i < k; i++) {
            const size_t c = list[s0 + i];
            const uint32_t *tri = m->indices + c / 3 * 3;
            parent[i] = i;
            edges[2 * i] = (crease_edge){tri[(c + 1) % 3], i};
            edges[2 * i + 1] = (crease_edge){tri[(c + 2) % 3], i};
        }
        if (k > 1)
            qsort(edges, 2 * (size_t)k, sizeof *edges, crease_edge_cmp);
        for (size_t a = 0; a < 2 * (size_t)k;) {
            size_t b = a + 1;
            while (b < 2 * (size_t)k && edges[b].other == edges[a].other)
                b++;
            for (size_t i = a; i < b; i++)
                for (size_t j = i + 1; j < b; j++) {
                    const size_t ti = list[s0 + edges[i].slot] / 3,
                                 tj = list[s0 + edges[j].slot] / 3;
                    if (!area[ti] || !area[tj])
                        continue;
                    const double *x = fn + 3 * ti, *y = fn + 3 * tj;
                    if (x[0] * y[0] + x[1] * y[1] + x[2] * y[2] >= agree)
                        uf_join(parent, edges[i].slot, edges[j].slot);
                }
            a = b;
        }
        /* Triangles without area join the first fan (with area, if any). */
        uint32_t first = 0;
        while (first < k && !area[list[s0 + first] / 3])
            first++;
        if (first == k)
            first = 0;
        for (uint32_t i = 0; i < k; i++)
            if (!area[list[s0 + i] / 3])
                uf_join(parent, i, first);
        uint32_t ng = 0;
        for (uint32_t i = 0; i < k; i++) {
            uint32_t root = uf_find(parent, i);
            if (root == i)
                label[i] = ng++;
            slot_group[s0 + i] = label[root];
        }
        groups[v] = ng ? ng : 1;
        total += groups[v];
    }
    r = VB_OK;
    if (total == nv) {
        compute_normals(m, *cancelled);
        goto done;
    }
    if (total > 0x7fffffffu) {
        r = VB_ERR_INVALID;
        goto done;
    }
    {
        const uint32_t nn = (uint32_t)total;
        float *pos = alloc_array(3 * (size_t)nn, sizeof(float));
        float *nrm = alloc_array(3 * (size_t)nn, sizeof(float));
        uint8_t *canc = calloc(nn, 1);
        if (!pos || !nrm || !canc) {
            free(pos);
            free(nrm);
            free(canc);
            r = VB_ERR_OUT_OF_MEMORY;
            goto done;
        }
        uint32_t next = 0;
        for (uint32_t v = 0; v < nv; v++) {
            for (uint32_t g = 0; g < groups[v]; g++)
                memcpy(pos + 3 * (size_t)(next + g), m->positions + 3 * (size_t)v,
                       3 * sizeof(float));
            if (groups[v] > 1)
                (*split)++, *added += groups[v] - 1;
            for (size_t j = start[v]; j < start[v + 1]; j++)
                m->indices[list[j]] = next + slot_group[j];
            next += groups[v];
        }
        free(m->positions);
        free(m->normals);
        free(*cancelled);
        m->positions = pos, m->normals = nrm, *cancelled = canc;
        m->vertex_count = nn;
        compute_normals(m, *cancelled);
    }

done:
    free(fn);
    free(area);
    free(start);
    free(list);
    free(slot_group);
    free(groups);
    free(parent);
    free(label);
    free(edges);
    return r;
}

/* ---------------------------------------------------------------------- */
/* Compaction: drop triangles with a repeated index, then unused vertices  */
/* ---------------------------------------------------------------------- */

/* Renumbers vertices in their original order. `normals` may be NULL.
 * Writes *out only on success (its normals then are a copy or zeros). */
static vb_result compact(uint32_t vertex_count, const float *positions, const float *normals,
                         uint32_t triangle_count, const uint32_t *indices, vb_mesh *out,
                         uint32_t *dropped_triangles)
{
    vb_mesh res = {0};
    uint32_t *remap = alloc_array(vertex_count, sizeof(uint32_t));
    res.indices = alloc_array(3 * (size_t)triangle_count, sizeof(uint32_t));
    if (!remap || !res.indices) {
        free(remap);
        vb_mesh_free(&res);
        return VB_ERR_OUT_OF_MEMORY;
    }
    const uint32_t unused = UINT32_MAX;
    for (uint32_t i = 0; i < vertex_count; i++)
        remap[i] = unused;
    uint32_t kept = 0;
    for (uint32_t t = 0; t < triangle_count; t++) {
        const uint32_t *tri = indices + 3 * (size_t)t;
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
            continue;
        for (int k = 0; k < 3; k++) {
            remap[tri[k]] = 0;
            res.indices[3 * (size_t)kept + (size_t)k] = tri[k];
        }
        kept++;
    }
    uint32_t used = 0;
    for (uint32_t i = 0; i < vertex_count; i++)
        if (remap[i] != unused)
            remap[i] = used++;
    res.vertex_count = used;
    res.triangle_count = kept;
    res.positions = alloc_array(3 * (size_t)used, sizeof(float));
    res.normals = alloc_array(3 * (size_t)used, sizeof(float));
    if (!res.positions || !res.normals) {
        free(remap);
        vb_mesh_free(&res);
        return VB_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < vertex_count; i++) {
        if (remap[i] == unused)
            continue;
        memcpy(res.positions + 3 * (size_t)remap[i], positions + 3 * (size_t)i, 3 * sizeof(float));
        if (normals)
            memcpy(res.normals + 3 * (size_t)remap[i], normals + 3 * (size_t)i, 3 * sizeof(float));
        else
            memset(res.normals + 3 * (size_t)remap[i], 0, 3 * sizeof(float));
    }
    for (size_t j = 0; j < 3 * (size_t)kept; j++)
        res.indices[j] = remap[res.indices[j]];
    free(remap);
    if (dropped_triangles)
        *dropped_triangles = triangle_count - kept;
    *out = res;
    return VB_OK;
}

/* ---------------------------------------------------------------------- */
/* Welding                                                                */
/* ---------------------------------------------------------------------- */

static uint32_t position_key(const float *p, uint32_t bits[3])
{
    uint32_t h = 2166136261u;
    for (int k = 0; k < 3; k++) {
        float f = p[k] == 0.0f ? 0.0f : p[k]; /* -0 and +0 weld */
        memcpy(&bits[k], &f, sizeof f);
        h = (h ^ bits[k]) * 16777619u;
        h ^= h >> 15;
    }
    return h;
}

vb_result vb_mesh_weld(vb_mesh *m, vb_error *err)
{
    if (!m || (m->vertex_count && !m->positions) || (m->triangle_count && !m->indices))
        return vb_fail(err, VB_ERR_ARGUMENT, "weld: invalid mesh");
    for (size_t j = 0; j < 3 * (size_t)m->triangle_count; j++)
        if (m->indices[j] >= m->vertex_count)
            return vb_fail(err, VB_ERR_INVALID,
                           "weld: triangle %zu: index %u out of range (%u vertices)", j / 3,
                           m->indices[j], m->vertex_count);

    /* Open addressing keyed by position bits; the first vertex with a
     * position represents it, so the result does not depend on hashing. */
    size_t cap = 16;
    while (cap < 2 * (size_t)m->vertex_count)
        cap *= 2;
    uint32_t *slot = alloc_array(cap, sizeof(uint32_t));
    uint32_t *first = alloc_array(m->vertex_count, sizeof(uint32_t));
    uint32_t *idx = alloc_array(3 * (size_t)m->triangle_count, sizeof(uint32_t));
    if (!slot || !first || !idx) {
        free(slot);
        free(first);
        free(idx);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "weld: out of memory");
    }
    for (size_t s = 0; s < cap; s++)
        slot[s] = UINT32_MAX;
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        uint32_t bits[3];
        size_t s = position_key(m->positions + 3 * (size_t)i, bits) & (cap - 1);
        for (;;) {
            if (slot[s] == UINT32_MAX) {
                slot[s] = i;
                first[i] = i;
                break;
            }
            uint32_t other[3];
            position_key(m->positions + 3 * (size_t)slot[s], other);
            if (memcmp(bits, other, sizeof bits) == 0) {
                first[i] = slot[s];
                break;
            }
            s = (s + 1) & (cap - 1);
        }
    }
    free(slot);
    for (size_t j = 0; j < 3 * (size_t)m->triangle_count; j++)
        idx[j] = first[m->indices[j]];
    free(first);

    vb_mesh res;
    vb_result r = compact(m->vertex_count, m->positions, NULL, m->triangle_count, idx, &res, NULL);
    free(idx);
    if (r != VB_OK)
        return vb_fail(err, r, "weld: out of memory");
    vb_mesh_compute_normals(&res);
    vb_mesh_free(m);
    *m = res;
    return VB_OK;
}

/* ---------------------------------------------------------------------- */
/* Append                                                                 */
/* ---------------------------------------------------------------------- */

vb_result vb_mesh_append(vb_mesh *dst, const vb_mesh *src, vb_error *err)
{
    if (!dst || !src || (src->vertex_count && !src->positions) ||
        (src->triangle_count && !src->indices) || (dst->vertex_count && !dst->positions) ||
        (dst->triangle_count && !dst->indices))
        return vb_fail(err, VB_ERR_ARGUMENT, "append: invalid mesh");
    if (src->vertex_count > UINT32_MAX - dst->vertex_count ||
        src->triangle_count > UINT32_MAX / 3 - dst->triangle_count ||
        dst->triangle_count > UINT32_MAX / 3)
        return vb_fail(
            err, VB_ERR_ARGUMENT, "append: too many vertices or triangles (%u + %u, %u + %u)",
            dst->vertex_count, src->vertex_count, dst->triangle_count, src->triangle_count);
    uint32_t nv = dst->vertex_count + src->vertex_count;
    uint32_t nt = dst->triangle_count + src->triangle_count;
    vb_mesh res = {0};
    res.positions = alloc_array(3 * (size_t)nv, sizeof(float));
    res.normals = alloc_array(3 * (size_t)nv, sizeof(float));
    res.indices = alloc_array(3 * (size_t)nt, sizeof(uint32_t));
    if (!res.positions || !res.normals || !res.indices) {
        vb_mesh_free(&res);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "append: out of memory");
    }
    res.vertex_count = nv;
    res.triangle_count = nt;
    size_t dv = 3 * (size_t)dst->vertex_count, sv = 3 * (size_t)src->vertex_count;
    if (dv)
        memcpy(res.positions, dst->positions, dv * sizeof(float));
    if (sv)
        memcpy(res.positions + dv, src->positions, sv * sizeof(float));
    if (dv && dst->normals)
        memcpy(res.normals, dst->normals, dv * sizeof(float));
    else
        memset(res.normals, 0, dv * sizeof(float));
    if (sv && src->normals)
        memcpy(res.normals + dv, src->normals, sv * sizeof(float));
    else
        memset(res.normals + dv, 0, sv * sizeof(float));
    size_t di = 3 * (size_t)dst->triangle_count;
    if (di)
        memcpy(res.indices, dst->indices, di * sizeof(uint32_t));
    for (size_t j = 0; j < 3 * (size_t)src->triangle_count; j++)
        res.indices[di + j] = src->indices[j] + dst->vertex_count;
    vb_mesh_free(dst);
    *dst = res;
    return VB_OK;
}

/* ---------------------------------------------------------------------- */
/* OBJ output                                                             */
/* ---------------------------------------------------------------------- */

/* What both writers do first: check m (normals too with need_normals) and
 * open the project's atomic output (vdsh_output.h: a temporary file beside
 * the target, renamed over it once complete and on disk). */
static vb_result write_begin(const vb_mesh *m, const char *path, const char *what, int need_normals,
                             vdsh_output *out, vb_error *err)
{
    *out = (vdsh_output){.fd = -1};
    if (!m || !path || !path[0] || (m->vertex_count && !m->positions) ||
        (m->vertex_count && need_normals && !m->normals) || (m->triangle_count && !m->indices))
        return vb_fail(err, VB_ERR_ARGUMENT, "%s: invalid argument", what);
    for (size_t j = 0; j < 3 * (size_t)m->triangle_count; j++)
        if (m->indices[j] >= m->vertex_count)
            return vb_fail(err, VB_ERR_INVALID, "%s: triangle %zu: index %u out of range (%u %s)",
                           path, j / 3, m->indices[j], m->vertex_count,
                           vdsh_plural(m->vertex_count, "vertex", "vertices"));
    vdsh_error ve;
    vdsh_result vr = vdsh_output_open(path, out, &ve);
    if (vr != VDSH_OK)
        return vb_fail(err, vr == VDSH_ERR_OUT_OF_MEMORY ? VB_ERR_OUT_OF_MEMORY : VB_ERR_IO, "%s",
                       ve.msg);
    setvbuf(out->fp, NULL, _IOFBF, 1 << 16);
    return VB_OK;
}

/* Finish what write_begin opened: complete and on disk, not yet renamed
 * (or removed, on failure). */
static vb_result write_end(vdsh_output *out, vb_error *err)
{
    vdsh_error ve;
    if (vdsh_output_finish(out, &ve) != VDSH_OK)
        return vb_fail(err, VB_ERR_IO, "%s", ve.msg);
    return VB_OK;
}

/* A staged file renamed into place (or removed, on failure). */
static vb_result commit_staged(vb_result staged, vdsh_output *out, vb_error *err)
{
    vdsh_error ve;
    if (staged != VB_OK)
        return staged;
    if (vdsh_output_commit(out, &ve) != VDSH_OK)
        return vb_fail(err, VB_ERR_IO, "%s", ve.msg);
    return VB_OK;
}

vb_result vb_mesh_write_obj(const vb_mesh *m, const char *path, vb_error *err)
{
    vdsh_output out;
    return commit_staged(vb_mesh_stage_obj(m, path, &out, err), &out, err);
}

vb_result vb_mesh_write_ply(const vb_mesh *m, const char *path, vb_error *err)
{
    vdsh_output out;
    return commit_staged(vb_mesh_stage_ply(m, path, &out, err), &out, err);
}

vb_result vb_mesh_stage_obj(const vb_mesh *m, const char *path, vdsh_output *out, vb_error *err)
{
    vb_result r = write_begin(m, path, "write_obj", 0, out, err);
    if (r != VB_OK)
        return r;
    FILE *f = out->fp;

    /* %.9g: 9 significant digits read back as the same float. */
    fprintf(f, "# vdsh mesh: %u vertices, %u triangles\n", m->vertex_count, m->triangle_count);
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        const float *p = m->positions + 3 * (size_t)i;
        fprintf(f, "v %.9g %.9g %.9g\n", (double)p[0], (double)p[1], (double)p[2]);
    }
    if (m->normals)
        for (uint32_t i = 0; i < m->vertex_count; i++) {
            const float *n = m->normals + 3 * (size_t)i;
            fprintf(f, "vn %.9g %.9g %.9g\n", (double)n[0], (double)n[1], (double)n[2]);
        }
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *tri = m->indices + 3 * (size_t)t;
        if (m->normals)
            fprintf(f, "f %u//%u %u//%u %u//%u\n", tri[0] + 1, tri[0] + 1, tri[1] + 1, tri[1] + 1,
                    tri[2] + 1, tri[2] + 1);
        else
            fprintf(f, "f %u %u %u\n", tri[0] + 1, tri[1] + 1, tri[2] + 1);
    }
    return write_end(out, err);
}

/* vb_mesh_write_ply's header for v vertices and t triangles (the plan
 * reader compares a file's header with it): its length. */
static int ply_header(char *buf, size_t cap, uint32_t v, uint32_t t)
{
    return snprintf(buf, cap,
                    "ply\nformat binary_little_endian 1.0\ncomment vdsh mesh\n"
                    "element vertex %u\nproperty float x\nproperty float y\nproperty float z\n"
                    "property float nx\nproperty float ny\nproperty float nz\n"
                    "element face %u\nproperty list uchar uint vertex_indices\nend_header\n",
                    v, t);
}

#define PLY_HEADER_MAX 512
#define PLY_VERTEX_BYTES 24 /* x y z nx ny nz, f32 */
#define PLY_FACE_BYTES 13   /* uchar 3, 3 x u32 */

vb_result vb_mesh_stage_ply(const vb_mesh *m, const char *path, vdsh_output *out, vb_error *err)
{
    vb_result r = write_begin(m, path, "write_ply", 1, out, err);
    if (r != VB_OK)
        return r;
    FILE *f = out->fp;
    char header[PLY_HEADER_MAX];
    ply_header(header, sizeof header, m->vertex_count, m->triangle_count);
    fputs(header, f);
    /* Little-endian host (vdsh.h checks it): the floats and indices as they are. */
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        fwrite(m->positions + 3 * (size_t)i, sizeof(float), 3, f);
        fwrite(m->normals + 3 * (size_t)i, sizeof(float), 3, f);
    }
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        unsigned char three = 3;
        fwrite(&three, 1, 1, f);
        fwrite(m->indices + 3 * (size_t)t, sizeof(uint32_t), 3, f);
    }
    return write_end(out, err);
}

/* ---------------------------------------------------------------------- */
/* Loading                                                                */
/* ---------------------------------------------------------------------- */

vb_result vb_mesh_read_file(const char *path, uint8_t **bytes, size_t *size, vb_error *err)
{
    /* O_NONBLOCK: opening a FIFO must not wait for a writer (it is refused
     * below, as anything but a regular file); regular files ignore it. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    FILE *f = fd >= 0 ? fdopen(fd, "rb") : NULL;
    if (!f) {
        int e = errno;
        if (fd >= 0)
            close(fd);
        return vb_fail(err, VB_ERR_IO, "%s: cannot open: %s", path, strerror(e));
    }
    struct stat st;
    if (fstat(fileno(f), &st) != 0) {
        int e = errno;
        fclose(f);
        return vb_fail(err, VB_ERR_IO, "%s: cannot stat: %s", path, strerror(e));
    }
    if (!S_ISREG(st.st_mode)) {
        fclose(f);
        return vb_fail(err, VB_ERR_IO, "%s: not a regular file", path);
    }
    if ((uint64_t)st.st_size > (uint64_t)SIZE_MAX - 1) {
        fclose(f);
        return vb_fail(err, VB_ERR_IO, "%s: file too large", path);
    }
    size_t n = (size_t)st.st_size;
    uint8_t *buf = malloc(n ? n : 1);
    if (!buf) {
        fclose(f);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu bytes", path, n);
    }
    size_t got = n ? fread(buf, 1, n, f) : 0;
    int bad = ferror(f);
    fclose(f);
    if (bad || got != n) {
        free(buf);
        return vb_fail(err, VB_ERR_IO, "%s: read error (%zu of %zu bytes)", path, got, n);
    }
    *bytes = buf;
    *size = n;
    return VB_OK;
}

/* ---------------------------------------------------------------------- */
/* Creases: a vertex whose face corners give disagreeing normals is split  */
/* ---------------------------------------------------------------------- */

/* n scaled to unit length in double, (0,0,0) when it has no length. */
static void unit_double(const float *n, double u[3])
{
    double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    for (int k = 0; k < 3; k++)
        u[k] = len > 0.0 && isfinite(len) ? n[k] / len : 0.0;
}

/* As mesh_parse.cpp keeps a single given normal: as it is when it is
 * unit to float precision, else scaled to unit length. */
static void unit_float(const float *n, float out[3])
{
    memcpy(out, n, 3 * sizeof(float));
    vdsh_unit3f_keep(out);
}

#define MAX_GROUPS 256

/* The split mesh's vertices, when some vertex splits (mesh.h, "Normals
 * per face corner"); all NULL / 0 when none does. */
typedef struct split_vertices {
    uint32_t vertex_count;
    float *positions;
    float *normals;
    uint8_t *has_normal;
    uint32_t split, added;
} split_vertices;

static void split_free(split_vertices *sv)
{
    free(sv->positions);
    free(sv->normals);
    free(sv->has_normal);
    memset(sv, 0, sizeof *sv);
}

/* Groups the corners of every vertex by normal and, when any vertex has
 * more than one group, fills *sv and renumbers idx (3 * triangle_count,
 * already range-checked) to the split vertices. Triangles that repeat an
 * index take no part (they are dropped next) and stay repeated. */
static vb_result split_creases(const vb_mesh_raw *raw, uint32_t *idx, split_vertices *sv)
{
    memset(sv, 0, sizeof *sv);
    if (!raw->corner_normals || !raw->corner_given || raw->vertex_count == 0)
        return VB_OK;
    const uint32_t nv = raw->vertex_count;
    const size_t corners = 3 * (size_t)raw->triangle_count;
    const double agree = vdsh_det_cos(VB_MESH_NORMAL_AGREE_DEG * 3.14159265358979323846 / 180.0);

    /* Every vertex's corners, in triangle order (counting sort). */
    size_t *start = calloc((size_t)nv + 1, sizeof *start);
    size_t *list = alloc_array(corners, sizeof *list);
    uint16_t *group = alloc_array(corners, sizeof *group);
    uint32_t *groups = alloc_array(nv, sizeof *groups);
    double *rep = alloc_array(3 * MAX_GROUPS, sizeof *rep);
    vb_result r = VB_ERR_OUT_OF_MEMORY;
    if (!start || !list || !group || !groups || !rep)
        goto done;
    for (size_t c = 0; c < corners; c++) {
        const uint32_t *tri = idx + c / 3 * 3;
        group[c] = 0;
        if (tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2])
            start[idx[c] + 1]++;
    }
    for (uint32_t v = 0; v < nv; v++)
        start[v + 1] += start[v];
    {
        size_t *fill = alloc_array(nv, sizeof *fill);
        if (!fill)
            goto done;
        memcpy(fill, start, nv * sizeof *fill);
        for (size_t c = 0; c < corners; c++) {
            const uint32_t *tri = idx + c / 3 * 3;
            if (tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2])
                list[fill[idx[c]]++] = c;
        }
        free(fill);
    }

    /* Group each vertex's corners: the first group whose first normal
     * agrees, else a new group (the closest once there are MAX_GROUPS).
     * Corners without a normal, or with a zero one, join group 0. */
    uint64_t total = 0;
    for (uint32_t v = 0; v < nv; v++) {
        uint32_t ng = 0;
        for (size_t j = start[v]; j < start[v + 1]; j++) {
            size_t c = list[j];
            double u[3];
            unit_double(raw->corner_normals + 3 * c, u);
            if (!raw->corner_given[c] || (u[0] == 0.0 && u[1] == 0.0 && u[2] == 0.0))
                continue;
            uint32_t best = 0;
            double best_dot = -2.0;
            for (uint32_t g = 0; g < ng; g++) {
                double d = u[0] * rep[3 * g] + u[1] * rep[3 * g + 1] + u[2] * rep[3 * g + 2];
                if (d >= agree) {
                    best = g;
                    best_dot = 2.0;
                    break;
                }
                if (d > best_dot) {
                    best = g;
                    best_dot = d;
                }
            }
            if (best_dot < 2.0 && ng < MAX_GROUPS) {
                best = ng++;
                memcpy(rep + 3 * best, u, sizeof u);
            }
            group[c] = (uint16_t)best;
        }
        groups[v] = ng ? ng : 1;
        total += groups[v];
    }
    r = VB_OK;
    if (total == nv)
        goto done; /* nothing to split */
    if (total > 0x7fffffffu) {
        r = VB_ERR_INVALID;
        goto done;
    }

    /* The split vertices, each vertex's groups in a row. A vertex that is
     * not split keeps the reader's per-vertex normal; a group takes its first
     * given normal. */
    sv->vertex_count = (uint32_t)total;
    sv->positions = alloc_array(3 * (size_t)total, sizeof(float));
    sv->normals = calloc(3 * (size_t)total, sizeof(float));
    sv->has_normal = calloc((size_t)total, 1);
    uint32_t *base = alloc_array(nv, sizeof *base);
    if (!sv->positions || !sv->normals || !sv->has_normal || !base) {
        free(base);
        split_free(sv);
        r = VB_ERR_OUT_OF_MEMORY;
        goto done;
    }
    uint32_t next = 0;
    for (uint32_t v = 0; v < nv; v++) {
        base[v] = next;
        for (uint32_t g = 0; g < groups[v]; g++)
            memcpy(sv->positions + 3 * (size_t)(next + g), raw->positions + 3 * (size_t)v,
                   3 * sizeof(float));
        if (groups[v] == 1) {
            if (raw->normals && raw->has_normal) {
                memcpy(sv->normals + 3 * (size_t)next, raw->normals + 3 * (size_t)v,
                       3 * sizeof(float));
                sv->has_normal[next] = raw->has_normal[v];
            }
        } else {
            sv->split++;
            sv->added += groups[v] - 1;
            for (size_t j = start[v]; j < start[v + 1]; j++) {
                size_t c = list[j];
                uint32_t w = next + group[c];
                if (raw->corner_given[c] && !sv->has_normal[w]) {
                    sv->has_normal[w] = 1;
                    unit_float(raw->corner_normals + 3 * c, sv->normals + 3 * (size_t)w);
                } else if (raw->corner_given[c] && sv->normals[3 * (size_t)w] == 0.0f &&
                           sv->normals[3 * (size_t)w + 1] == 0.0f &&
                           sv->normals[3 * (size_t)w + 2] == 0.0f) {
                    /* group 0 may have met a zero normal before its first */
                    unit_float(raw->corner_normals + 3 * c, sv->normals + 3 * (size_t)w);
                }
            }
        }
        next += groups[v];
    }
    for (size_t c = 0; c < corners; c++)
        idx[c] = base[idx[c]] + group[c];
    free(base);

done:
    free(start);
    free(list);
    free(group);
    free(groups);
    free(rep);
    return r;
}

/* ---------------------------------------------------------------------- */
/* Duplicate triangles                                                    */
/* ---------------------------------------------------------------------- */

/* Position p, -0 as +0 (so that equal coordinates compare and hash equal). */
static void pos_of(const float *positions, uint32_t v, float out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = positions[3 * (size_t)v + (size_t)k] + 0.0f;
}

static int pos_cmp(const float *a, const float *b)
{
    for (int k = 0; k < 3; k++)
        if (a[k] != b[k])
            return a[k] < b[k] ? -1 : 1;
    return 0;
}

/* Triangle tri's three positions, sorted: its key whatever the corner
 * order. */
static void tri_key(const float *positions, const uint32_t *tri, float key[9])
{
    float p[3][3];
    for (int c = 0; c < 3; c++)
        pos_of(positions, tri[c], p[c]);
    int o[3] = {0, 1, 2};
    for (int i = 1; i < 3; i++)
        for (int j = i; j > 0 && pos_cmp(p[o[j - 1]], p[o[j]]) > 0; j--) {
            int s = o[j];
            o[j] = o[j - 1];
            o[j - 1] = s;
        }
    for (int c = 0; c < 3; c++)
        memcpy(key + 3 * c, p[o[c]], 3 * sizeof(float));
}

static uint64_t key_hash(const float key[9])
{
    /* Each word mixed in whole (integer coordinates leave a float's low
     * bits zero), then murmur3's finaliser: every bit depends on all. */
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (int i = 0; i < 9; i++) {
        uint32_t u;
        memcpy(&u, &key[i], 4);
        h = (h ^ u) * 0xff51afd7ed558ccdull;
        h ^= h >> 32;
    }
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    h ^= h >> 33;
    return h;
}

/* 1 when triangles a and b (the same three distinct positions) go round
 * them the same way. */
static int same_winding(const float *positions, const uint32_t *a, const uint32_t *b)
{
    float pa0[3], pa1[3], q[3];
    pos_of(positions, a[0], pa0);
    pos_of(positions, a[1], pa1);
    for (int j = 0; j < 3; j++) {
        pos_of(positions, b[j], q);
        if (pos_cmp(q, pa0) == 0) {
            pos_of(positions, b[(j + 1) % 3], q);
            return pos_cmp(q, pa1) == 0;
        }
    }
    return 1;
}

static int share_index(const uint32_t *a, const uint32_t *b)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (a[i] == b[j])
                return 1;
    return 0;
}

/* Drop every triangle whose three positions (any corner order, either
 * winding) an earlier kept triangle has, keeping the order of the rest in
 * idx; *count becomes the number kept, *dropped the number dropped.
 * Exception: the first reversed copy that shares no vertex index with the
 * kept one is the back of a two-sided sheet (each side its own vertices,
 * so its own receivers) and is kept. Triangles that repeat an index are
 * left for compact() to drop. 0 when out of memory.
 *
 * The triangles are radix-sorted by a 32-bit hash of their sorted
 * positions (stable: equal hashes stay in triangle order), and only runs
 * of equal hashes are compared, position by position: streaming passes,
 * where a hash table costs a cache miss a triangle (Lost Empire's 225k
 * triangles: ~5 ms against ~25 ms). */
static int drop_duplicates(const float *positions, uint32_t *idx, uint32_t *count,
                           uint32_t *dropped)
{
    const uint32_t n = *count;
    *dropped = 0;
    if (n < 2)
        return 1;
    uint64_t *a = alloc_array(n, sizeof *a), *b = alloc_array(n, sizeof *b);
    uint32_t *hist = calloc(65536, sizeof *hist);
    uint8_t *drop = calloc(n, 1);
    uint32_t *keep = NULL; /* the kept triangles of one run */
    size_t keep_cap = 0;
    int ok = a && b && hist && drop;
    uint32_t m = 0; /* triangles with three distinct indices */
    for (uint32_t t = 0; ok && t < n; t++) {
        const uint32_t *tri = idx + 3 * (size_t)t;
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
            continue;
        float key[9];
        tri_key(positions, tri, key);
        a[m++] = (uint64_t)(uint32_t)(key_hash(key) >> 32) << 32 | t;
    }
    /* LSD radix sort on the hash, 16 bits a pass. */
    for (int shift = 32; ok && shift < 64; shift += 16) {
        memset(hist, 0, 65536 * sizeof *hist);
        for (uint32_t i = 0; i < m; i++)
            hist[(a[i] >> shift) & 0xffff]++;
        uint32_t sum = 0;
        for (uint32_t d = 0; d < 65536; d++) {
            uint32_t c = hist[d];
            hist[d] = sum;
            sum += c;
        }
        for (uint32_t i = 0; i < m; i++)
            b[hist[(a[i] >> shift) & 0xffff]++] = a[i];
        uint64_t *s = a;
        a = b;
        b = s;
    }
    for (uint32_t i = 0; ok && i < m;) {
        uint32_t j = i + 1;
        while (j < m && a[j] >> 32 == a[i] >> 32)
            j++;
        if (j - i > 1) { /* a run of equal hashes, in triangle order */
            size_t kept = 0;
            for (uint32_t r = i; r < j; r++) {
                const uint32_t t = (uint32_t)a[r];
                const uint32_t *tri = idx + 3 * (size_t)t;
                float key[9], other[9];
                tri_key(positions, tri, key);
                int same = 0, reversed = 0, shares = 0;
                for (size_t q = 0; q < kept && !same; q++) {
                    const uint32_t *u = idx + 3 * (size_t)keep[q];
                    tri_key(positions, u, other);
                    if (memcmp(key, other, sizeof key) != 0)
                        continue;
                    if (same_winding(positions, u, tri)) {
                        same = 1;
                    } else {
                        reversed = 1;
                        shares |= share_index(u, tri);
                    }
                }
                if (same || (reversed && shares)) {
                    drop[t] = 1;
                    continue;
                }
                if (kept == keep_cap) {
                    size_t cap = keep_cap ? 2 * keep_cap : 8;
                    uint32_t *k = realloc(keep, cap * sizeof *k);
                    if (!k) {
                        ok = 0;
                        break;
                    }
                    keep = k;
                    keep_cap = cap;
                }
                keep[kept++] = t;
            }
        }
        i = j;
    }
    uint32_t kept = 0;
    for (uint32_t t = 0; ok && t < n; t++)
        if (!drop[t]) {
            memmove(idx + 3 * (size_t)kept, idx + 3 * (size_t)t, 3 * sizeof *idx);
            kept++;
        }
    free(a);
    free(b);
    free(hist);
    free(drop);
    free(keep);
    if (!ok)
        return 0;
    *dropped = n - kept;
    *count = kept;
    return 1;
}

/* Polygons of 4+ vertices (consecutive triangles of one file face) whose
 * triangles cover more than 1% beyond the area the polygon encloses (the
 * length of its vector area, which the triangles' vector areas sum to).
 * The readers ear-clip concave polygons (mesh_read.h,
 * triangulate_polygon), whose triangles then cover the face exactly; what
 * is left here is what they fanned from the first vertex instead: polygons
 * that are not simple (crossing themselves, no area) or far from flat,
 * and, counted apart (raw->unclipped_faces), those past the file's ear
 * clipping time bound, not tried. Another reader may take them
 * differently: counted and said, not refused. */
static void nonconvex_polygons(const vb_mesh_raw *raw, vb_mesh_report *rp)
{
    double fan_sum[2] = {0.0, 0.0}, own_sum[2] = {0.0, 0.0};
    uint32_t count[2] = {0, 0}, next_unclipped = 0;
    for (uint32_t t = 0; raw->faces && t < raw->triangle_count;) {
        uint32_t e = t + 1;
        while (e < raw->triangle_count && raw->faces[e] == raw->faces[t])
            e++;
        if (e - t >= 2) {
            double fan = 0.0, vec[3] = {0.0, 0.0, 0.0};
            for (uint32_t k = t; k < e; k++) {
                const int64_t *ix = raw->indices + 3 * (size_t)k;
                const float *a = raw->positions + 3 * ix[0], *b = raw->positions + 3 * ix[1],
                            *c = raw->positions + 3 * ix[2];
                double u[3], v[3], x[3];
                for (int d = 0; d < 3; d++)
                    u[d] = (double)b[d] - a[d], v[d] = (double)c[d] - a[d];
                x[0] = u[1] * v[2] - u[2] * v[1];
                x[1] = u[2] * v[0] - u[0] * v[2];
                x[2] = u[0] * v[1] - u[1] * v[0];
                fan += sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
                for (int d = 0; d < 3; d++)
                    vec[d] += x[d];
            }
            const double own = sqrt(vec[0] * vec[0] + vec[1] * vec[1] + vec[2] * vec[2]);
            if (fan > 1.01 * own) {
                /* unclipped_faces ascends, as the faces do */
                while (next_unclipped < raw->unclipped_count &&
                       raw->unclipped_faces[next_unclipped] < raw->faces[t])
                    next_unclipped++;
                const int timed_out = next_unclipped < raw->unclipped_count &&
                                      raw->unclipped_faces[next_unclipped] == raw->faces[t];
                count[timed_out]++;
                fan_sum[timed_out] += fan, own_sum[timed_out] += own;
            }
        }
        t = e;
    }
    double excess[2];
    for (int k = 0; k < 2; k++)
        excess[k] = count[k] ? (own_sum[k] > 0.0 ? fan_sum[k] / own_sum[k] - 1.0 : INFINITY) : 0.0;
    rp->nonconvex_polygons = count[0], rp->nonconvex_excess = excess[0];
    rp->unclipped_polygons = count[1], rp->unclipped_excess = excess[1];
}

/* Raw file mesh -> clean vb_mesh (see mesh.h for what clean means). */
static vb_result clean_raw(const char *path, vb_mesh_format format, const vb_mesh_raw *raw,
                           vb_mesh *out, vb_mesh_report *rep, vb_error *err)
{
    /* Vertex numbers in messages as the format counts them. */
    unsigned base = format == VB_MESH_OBJ ? 1 : 0;
    for (uint32_t i = 0; i < raw->vertex_count; i++) {
        const float *p = raw->positions + 3 * (size_t)i;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
            return vb_fail(err, VB_ERR_INVALID,
                           "%s: vertex %llu has a non-finite coordinate (%g, %g, %g)", path,
                           (unsigned long long)i + base, (double)p[0], (double)p[1], (double)p[2]);
    }
    uint32_t *idx = alloc_array(3 * (size_t)raw->triangle_count, sizeof(uint32_t));
    if (!idx)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    for (size_t j = 0; j < 3 * (size_t)raw->triangle_count; j++) {
        int64_t v = raw->indices[j];
        if (v < 0 || v >= (int64_t)raw->vertex_count) {
            free(idx);
            return vb_fail(err, VB_ERR_INVALID,
                           "%s: face %llu: vertex index %lld out of range (%u %s)", path,
                           (unsigned long long)raw->faces[j / 3] + base, (long long)v + base,
                           raw->vertex_count, vdsh_plural(raw->vertex_count, "vertex", "vertices"));
        }
        idx[j] = (uint32_t)v;
    }

    /* Creases first: from here on the vertices are the split ones (the
     * file's own when nothing splits). */
    split_vertices sv;
    vb_result r = split_creases(raw, idx, &sv);
    if (r != VB_OK) {
        free(idx);
        return r == VB_ERR_OUT_OF_MEMORY
                   ? vb_fail(err, r, "%s: out of memory", path)
                   : vb_fail(err, r, "%s: too many vertices after splitting at creases", path);
    }
    const int split = sv.positions != NULL;
    const uint32_t vertex_count = split ? sv.vertex_count : raw->vertex_count;
    const float *positions = split ? sv.positions : raw->positions;
    const float *normals = split ? sv.normals : raw->normals;
    const uint8_t *has_normal = split ? sv.has_normal : raw->has_normal;

    /* Duplicate triangles (the same three positions as an earlier one):
     * scans and merged exports repeat faces, and a receiver on a copy sees
     * the other at distance ~0. */
    uint32_t tri_count = raw->triangle_count, duplicates = 0;
    if (!drop_duplicates(positions, idx, &tri_count, &duplicates)) {
        free(idx);
        split_free(&sv);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    }

    vb_mesh m;
    uint32_t degenerate = 0;
    r = compact(vertex_count, positions, NULL, tri_count, idx, &m, &degenerate);
    if (r != VB_OK) {
        free(idx);
        split_free(&sv);
        return vb_fail(err, r, "%s: out of memory", path);
    }
    if (m.triangle_count == 0) {
        free(idx);
        split_free(&sv);
        vb_mesh_free(&m);
        if (degenerate)
            return vb_fail(err, VB_ERR_INVALID, "%s: empty mesh (%s %u %s a vertex)", path,
                           degenerate == 1 ? "its" : "all", degenerate,
                           degenerate == 1 ? "triangle repeats" : "triangles repeat");
        return vb_fail(err, VB_ERR_INVALID, "%s: empty mesh (no faces)", path);
    }
    vb_mesh_report rp;
    memset(&rp, 0, sizeof rp);
    rp.dropped_triangles = degenerate + raw->dropped_triangles;
    rp.duplicate_triangles = duplicates;
    rp.gltf_skipped_modes = raw->gltf_skipped_modes;
    rp.gltf_skipped_morph = raw->gltf_skipped_morph;
    rp.gltf_skipped_skin = raw->gltf_skipped_skin;
    rp.gltf_ragged = raw->gltf_ragged;
    rp.split_vertices = sv.split;
    rp.split_added = sv.added;
    nonconvex_polygons(raw, &rp);
    rp.removed_vertices = vertex_count - m.vertex_count;

    /* File normals only when every vertex kept has one: a mix of given and
     * computed normals would be inconsistent across the mesh. */
    int use_file = normals != NULL && has_normal != NULL;
    if (use_file) {
        uint8_t *seen = calloc(vertex_count ? vertex_count : 1, 1);
        if (!seen) {
            free(idx);
            split_free(&sv);
            vb_mesh_free(&m);
            return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
        }
        for (uint32_t t = 0; t < tri_count; t++) {
            const uint32_t *tri = idx + 3 * (size_t)t;
            if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
                continue;
            for (int k = 0; k < 3; k++)
                seen[tri[k]] = 1;
        }
        for (uint32_t i = 0; i < vertex_count; i++)
            rp.missing_normals += seen[i] && !has_normal[i];
        use_file = rp.missing_normals == 0;
        /* compact() numbers kept vertices in their original order */
        uint32_t next = 0;
        for (uint32_t i = 0; i < vertex_count && use_file; i++)
            if (seen[i])
                memcpy(m.normals + 3 * (size_t)next++, normals + 3 * (size_t)i, 3 * sizeof(float));
        free(seen);
    }
    free(idx);
    split_free(&sv);
    uint8_t *cancelled = calloc(m.vertex_count, 1);
    if (!cancelled) {
        vb_mesh_free(&m);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    if (!use_file) {
        rp.normals_computed = 1;
        compute_normals(&m, cancelled);
        for (uint32_t i = 0; i < m.vertex_count; i++)
            rp.cancelled_normals += cancelled[i];
    } else {
        /* A zero file normal says nothing: such vertices get the computed
         * normal of their own triangles (itself zero only where those all
         * have no area, or cancel). */
        size_t zeros = 0;
        for (uint32_t i = 0; i < m.vertex_count; i++) {
            const float *n = m.normals + 3 * (size_t)i;
            zeros += n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f;
        }
        if (zeros) {
            float *given = alloc_array(3 * (size_t)m.vertex_count, sizeof(float));
            if (!given) {
                free(cancelled);
                vb_mesh_free(&m);
                return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
            }
            memcpy(given, m.normals, 3 * (size_t)m.vertex_count * sizeof(float));
            compute_normals(&m, cancelled);
            for (uint32_t i = 0; i < m.vertex_count; i++) {
                const float *n = given + 3 * (size_t)i;
                if (n[0] != 0.0f || n[1] != 0.0f || n[2] != 0.0f) {
                    memcpy(m.normals + 3 * (size_t)i, n, 3 * sizeof(float));
                } else {
                    const float *c = m.normals + 3 * (size_t)i;
                    rp.zero_normals++;
                    if (cancelled[i])
                        rp.zero_cancelled++;
                    else if (c[0] != 0.0f || c[1] != 0.0f || c[2] != 0.0f)
                        rp.zero_repaired++;
                    else
                        rp.zero_undefined++;
                }
            }
            free(given);
        }
    }
    free(cancelled);
    *out = m;
    *rep = rp;
    return VB_OK;
}

/* The built-in scene's source description: its positions and indices as
 * little-endian 32-bit words, the same bytes on every machine. */
static vb_result builtin_info(const vb_mesh *m, vb_source_info *info, vb_error *err)
{
    size_t words = 3 * (size_t)m->vertex_count + 3 * (size_t)m->triangle_count;
    uint8_t *buf = alloc_array(words, 4);
    if (!buf)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "builtin: out of memory");
    size_t w = 0;
    for (size_t j = 0; j < 3 * (size_t)m->vertex_count; j++, w++) {
        uint32_t u;
        memcpy(&u, &m->positions[j], 4);
        for (int b = 0; b < 4; b++)
            buf[4 * w + (size_t)b] = (uint8_t)(u >> (8 * b));
    }
    for (size_t j = 0; j < 3 * (size_t)m->triangle_count; j++, w++)
        for (int b = 0; b < 4; b++)
            buf[4 * w + (size_t)b] = (uint8_t)(m->indices[j] >> (8 * b));
    info->size = (uint64_t)words * 4;
    vb_sha256(buf, words * 4, info->sha256);
    info->file_size = info->size;
    memcpy(info->file_sha256, info->sha256, 32);
    free(buf);
    return VB_OK;
}

static int has_extension(const char *path, const char *ext)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash))
        return 0;
    return strcasecmp(dot + 1, ext) == 0;
}

static vb_result format_of(const char *name, vb_mesh_format *format, vb_error *err)
{
    if (has_extension(name, "obj"))
        *format = VB_MESH_OBJ;
    else if (has_extension(name, "ply"))
        *format = VB_MESH_PLY;
    else if (has_extension(name, "off"))
        *format = VB_MESH_OFF;
    else if (has_extension(name, "stl"))
        *format = VB_MESH_STL;
    else if (has_extension(name, "gltf"))
        *format = VB_MESH_GLTF;
    else if (has_extension(name, "glb"))
        *format = VB_MESH_GLB;
    else
        return vb_fail(err, VB_ERR_FORMAT,
                       "%s: unsupported file type (expected .obj, .ply, .off, .stl, .gltf or .glb)",
                       name);
    return VB_OK;
}

/* A file's bytes -> clean mesh and source info. */
static vb_result load_bytes(const char *name, vb_mesh_format format, int gltf_scene,
                            const uint8_t *bytes, size_t size, vb_mesh *m, vb_source_info *si,
                            vb_error *err)
{
    if (size == 0)
        return vb_fail(err, VB_ERR_FORMAT, "%s: empty file", name);
    si->size = size;
    vb_sha256(bytes, size, si->sha256);
    si->file_size = si->size;
    memcpy(si->file_sha256, si->sha256, 32);
    vb_mesh_raw raw;
    memset(&raw, 0, sizeof raw);
    vb_result r = format == VB_MESH_GLTF || format == VB_MESH_GLB
                      ? vb_mesh_parse_gltf(name, format == VB_MESH_GLB, gltf_scene - 1, bytes, size,
                                           &raw, err)
                      : vb_mesh_parse(name, format, bytes, size, &raw, err);
    if (r == VB_OK && raw.gltf_hashed) {
        si->size = raw.gltf_size;
        memcpy(si->sha256, raw.gltf_sha256, 32);
    }
    if (r == VB_OK)
        r = clean_raw(name, format, &raw, m, &si->report, err);
    vb_mesh_raw_free(&raw);
    return r;
}

/* v (x, y, z) turned so that the up axis `up` (vb_load_desc.up_axis)
 * becomes +y: a proper rotation (determinant 1, windings kept), exact. */
static void turn_up(int up, float *v)
{
    const float x = v[0], y = v[1], z = v[2];
    switch (up) {
    case 1: v[0] = x, v[1] = z, v[2] = -y; break;  /* z up: -90 degrees about x */
    case 2: v[0] = x, v[1] = -z, v[2] = y; break;  /* -z up: +90 degrees about x */
    case 3: v[0] = -y, v[1] = x, v[2] = z; break;  /* x up: +90 degrees about z */
    case 4: v[0] = y, v[1] = -x, v[2] = z; break;  /* -x up: -90 degrees about z */
    case 5: v[0] = x, v[1] = -y, v[2] = -z; break; /* -y up: 180 degrees about x */
    default: break;
    }
}

/* The common tail of both loaders: turn the up axis into +y, weld if
 * asked, split computed normals at creases, count what is left without a
 * normal, then hand over. */
static vb_result finish_load(vb_result r, vb_mesh *m, vb_source_info *si, const vb_load_desc *desc,
                             const char *path, vb_mesh *out, vb_source_info *info, vb_error *err)
{
    const int weld = desc ? desc->weld : 0, up = desc ? desc->up_axis : 0;
    const int crease = desc ? desc->crease : 0;
    if (r == VB_OK && (up < 0 || up >= VDSH_UP_AXES))
        r = vb_fail(err, VB_ERR_ARGUMENT, "load: up axis %d unknown (0..%d)", up, VDSH_UP_AXES - 1);
    for (uint32_t i = 0; r == VB_OK && up && i < m->vertex_count; i++) {
        turn_up(up, m->positions + 3 * (size_t)i);
        turn_up(up, m->normals + 3 * (size_t)i);
    }
    uint32_t before = m->vertex_count;
    if (r == VB_OK && weld) {
        r = vb_mesh_weld(m, err);
        si->report.welded = before - m->vertex_count;
        si->report.normals_computed = 1;
    }
    if (r == VB_OK && crease > 0 && crease < 180 && si->report.normals_computed) {
        uint8_t *cancelled = calloc(m->vertex_count ? m->vertex_count : 1, 1);
        r = cancelled ? crease_split(m, crease, &cancelled, &si->report.crease_vertices,
                                     &si->report.crease_added)
                      : VB_ERR_OUT_OF_MEMORY;
        if (r == VB_OK) {
            si->report.cancelled_normals = 0;
            for (uint32_t i = 0; i < m->vertex_count; i++)
                si->report.cancelled_normals += cancelled[i];
        } else {
            r = r == VB_ERR_OUT_OF_MEMORY
                    ? vb_fail(err, r, "%s: out of memory", path)
                    : vb_fail(err, r, "%s: too many vertices after splitting at creases", path);
        }
        free(cancelled);
    }
    if (r != VB_OK) {
        vb_mesh_free(m);
        return r;
    }
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        const float *n = m->normals + 3 * (size_t)i;
        si->report.undefined_normals += n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f;
    }
    *out = *m;
    if (info)
        *info = *si;
    return VB_OK;
}

vb_result vb_mesh_load(const char *path, const vb_load_desc *desc, vb_mesh *out,
                       vb_source_info *info, vb_error *err)
{
    if (!path || !out)
        return vb_fail(err, VB_ERR_ARGUMENT, "load: NULL path or output");
    vb_mesh m = {0};
    vb_source_info si;
    memset(&si, 0, sizeof si);
    vb_result r;

    if (strncmp(path, "builtin:", 8) == 0) {
        r = vb_builtin_load(path, &m, err);
        if (r != VB_OK)
            return r;
        r = builtin_info(&m, &si, err);
    } else {
        vb_mesh_format format = VB_MESH_OBJ;
        r = format_of(path, &format, err);
        if (r != VB_OK)
            return r;
        uint8_t *bytes = NULL;
        size_t size = 0;
        r = vb_mesh_read_file(path, &bytes, &size, err);
        if (r != VB_OK)
            return r;
        r = load_bytes(path, format, desc ? desc->gltf_scene : 0, bytes, size, &m, &si, err);
        free(bytes);
    }
    return finish_load(r, &m, &si, desc, path, out, info, err);
}

/* ---------------------------------------------------------------------- */
/* Plans: vb_mesh_write_ply's files, read in one streaming pass            */
/* ---------------------------------------------------------------------- */

/* Read a file vb_mesh_write_ply wrote (its header byte for byte, its size)
 * whose mesh the cleaning would leave as it is: every position finite,
 * every normal finite and not zero (stored as unit_float gives it, as the
 * PLY reader does), every face a triangle of three distinct vertices, every
 * vertex in one. Then *out is vb_mesh_load's mesh, read in blocks into its
 * final arrays: no file buffer, no parser arrays. 0 when the file is not
 * such a plan, or cannot be read (vb_mesh_load then reads it, or says why
 * it cannot); *out untouched. */
static int read_plan(const char *path, vb_mesh *out)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    struct stat st;
    char head[PLY_HEADER_MAX], want[PLY_HEADER_MAX];
    size_t got =
        fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) ? fread(head, 1, sizeof head - 1, f) : 0;
    head[got] = '\0';
    const char *ve = strstr(head, "element vertex "), *fe = strstr(head, "element face ");
    unsigned long long V = ve ? strtoull(ve + 15, NULL, 10) : 0;
    unsigned long long T = fe ? strtoull(fe + 13, NULL, 10) : 0;
    int hlen = V && T && V <= UINT32_MAX && T <= UINT32_MAX / 3
                   ? ply_header(want, sizeof want, (uint32_t)V, (uint32_t)T)
                   : 0;
    vb_mesh m = {0};
    uint8_t *used = NULL, *buf = NULL;
    enum { BLOCK = 1 << 16 }; /* records per read */
    int ok = hlen > 0 && (size_t)hlen <= got && memcmp(head, want, (size_t)hlen) == 0 &&
             (uint64_t)st.st_size == (uint64_t)hlen + V * PLY_VERTEX_BYTES + T * PLY_FACE_BYTES &&
             fseek(f, hlen, SEEK_SET) == 0;
    if (ok) {
        m.vertex_count = (uint32_t)V, m.triangle_count = (uint32_t)T;
        m.positions = alloc_array(3 * (size_t)V, sizeof(float));
        m.normals = alloc_array(3 * (size_t)V, sizeof(float));
        m.indices = alloc_array(3 * (size_t)T, sizeof(uint32_t));
        used = calloc((size_t)V, 1);
        buf = malloc((size_t)BLOCK * PLY_VERTEX_BYTES);
        ok = m.positions && m.normals && m.indices && used && buf;
    }
    /* Little-endian host (vdsh.h checks it): the floats and indices as they are. */
    for (uint64_t a = 0; ok && a < V; a += BLOCK) {
        size_t n = V - a < BLOCK ? (size_t)(V - a) : BLOCK;
        ok = fread(buf, PLY_VERTEX_BYTES, n, f) == n;
        for (size_t i = 0; ok && i < n; i++) {
            float rec[6];
            memcpy(rec, buf + i * PLY_VERTEX_BYTES, sizeof rec);
            float *p = m.positions + 3 * (a + i), *nv = m.normals + 3 * (a + i);
            memcpy(p, rec, 3 * sizeof(float));
            ok = isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]) && isfinite(rec[3]) &&
                 isfinite(rec[4]) && isfinite(rec[5]);
            if (ok)
                unit_float(rec + 3, nv);
            ok = ok && (nv[0] != 0.0f || nv[1] != 0.0f || nv[2] != 0.0f);
        }
    }
    for (uint64_t a = 0; ok && a < T; a += BLOCK) {
        size_t n = T - a < BLOCK ? (size_t)(T - a) : BLOCK;
        ok = fread(buf, PLY_FACE_BYTES, n, f) == n;
        for (size_t i = 0; ok && i < n; i++) {
            const uint8_t *rec = buf + i * PLY_FACE_BYTES;
            uint32_t *tri = m.indices + 3 * (a + i);
            memcpy(tri, rec + 1, 3 * sizeof(uint32_t));
            ok = rec[0] == 3 && tri[0] < V && tri[1] < V && tri[2] < V && tri[0] != tri[1] &&
                 tri[1] != tri[2] && tri[0] != tri[2];
            if (ok)
                used[tri[0]] = used[tri[1]] = used[tri[2]] = 1;
        }
    }
    for (uint64_t i = 0; ok && i < V; i++)
        ok = used[i];
    fclose(f);
    free(used);
    free(buf);
    if (!ok) {
        vb_mesh_free(&m);
        return 0;
    }
    *out = m;
    return 1;
}

vb_result vb_mesh_load_plan(const char *path, vb_mesh *out, vb_error *err)
{
    if (!path || !out)
        return vb_fail(err, VB_ERR_ARGUMENT, "load: NULL path or output");
    if (has_extension(path, "ply") && read_plan(path, out))
        return VB_OK;
    vb_load_desc ld = {0};
    return vb_mesh_load(path, &ld, out, NULL, err);
}

vb_result vb_mesh_load_memory(const void *data, size_t size, const char *name,
                              const vb_load_desc *desc, vb_mesh *out, vb_source_info *info,
                              vb_error *err)
{
    if (!name || !out || (!data && size))
        return vb_fail(err, VB_ERR_ARGUMENT, "load_memory: NULL name, data or output");
    vb_mesh_format format = VB_MESH_OBJ;
    vb_result r = format_of(name, &format, err);
    if (r != VB_OK)
        return r;
    vb_mesh m = {0};
    vb_source_info si;
    memset(&si, 0, sizeof si);
    r = load_bytes(name, format, desc ? desc->gltf_scene : 0, (const uint8_t *)data, size, &m, &si,
                   err);
    return finish_load(r, &m, &si, desc, name, out, info, err);
}
