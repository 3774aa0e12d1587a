/* Ray origins and receiver orientation: origins.h says what and why. */
#include "origins.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "parallel.h"
#include "sampling.h"

#define VB_PI 3.14159265358979323846

/* ---- ray-offset normals ------------------------------------------------ */

typedef struct pos_key {
    float p[3];
    uint32_t index;
} pos_key;

static int cmp_pos(const void *a, const void *b)
{
    const pos_key *x = a, *y = b;
    int c = memcmp(x->p, y->p, sizeof x->p);
    if (c)
        return c;
    return (x->index > y->index) - (x->index < y->index);
}

/* m's vertices sorted by the bytes of their positions, which groups
 * bit-identical positions (+ 0.0f folds -0 into +0); ties are ordered by
 * index, so a group's sums run in a fixed order. NULL when out of memory. */
static pos_key *sorted_positions(const vb_mesh *m)
{
    uint32_t n = m->vertex_count;
    pos_key *key = malloc((size_t)n * sizeof *key + 1);
    if (!key)
        return NULL;
    for (uint32_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++)
            key[i].p[c] = m->positions[3 * (size_t)i + c] + 0.0f;
        key[i].index = i;
    }
    qsort(key, n, sizeof *key, cmp_pos);
    return key;
}

/* The end of the group of equal positions that starts at key[a]. */
static uint32_t group_end(const pos_key *key, uint32_t n, uint32_t a)
{
    uint32_t b = a + 1;
    while (b < n && memcmp(key[a].p, key[b].p, sizeof key[a].p) == 0)
        b++;
    return b;
}

vb_result vb_offset_normals(const vb_mesh *m, float *out, vb_error *err)
{
    uint32_t n = m->vertex_count;
    pos_key *key = sorted_positions(m);
    if (!key)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    for (uint32_t a = 0; a < n;) {
        uint32_t b = group_end(key, n, a);
        /* Each vertex of the group sums the normals that face its own side
         * (n_u . n_v >= 0, itself included): an unwelded room corner
         * (floor and walls at right angles) gets one diagonal normal for
         * all its vertices, while a floor vertex under the corner of a
         * crate does not average in the crate's bottom, which faces the
         * other way. Sums run in group (index) order. */
        for (uint32_t k = a; k < b; k++) {
            const float *nk = m->normals + 3 * (size_t)key[k].index;
            double s[3] = {0, 0, 0};
            for (uint32_t j = a; j < b; j++) {
                const float *nj = m->normals + 3 * (size_t)key[j].index;
                if (nj[0] * nk[0] + nj[1] * nk[1] + nj[2] * nk[2] < 0.0f)
                    continue;
                for (int c = 0; c < 3; c++)
                    s[c] += nj[c];
            }
            double len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
            for (int c = 0; c < 3; c++)
                out[3 * (size_t)key[k].index + c] = len > 1e-12 ? (float)(s[c] / len) : 0.0f;
        }
        a = b;
    }
    free(key);
    return VB_OK;
}

float vb_receiver_near(float diag, float mean_edge)
{
    float global = 1e-3f * diag, local = 0.1f * mean_edge;
    return mean_edge > 0.0f && local < global ? local : global;
}

vb_result vb_mean_edges(const vb_mesh *m, float *out, vb_error *err)
{
    uint32_t *count = calloc((size_t)m->vertex_count + 1, sizeof *count);
    double *sum = calloc((size_t)m->vertex_count + 1, sizeof *sum);
    if (!count || !sum) {
        free(count);
        free(sum);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for edge lengths");
    }
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *ix = m->indices + 3 * (size_t)t;
        for (int k = 0; k < 3; k++) {
            const float *a = m->positions + 3 * (size_t)ix[k];
            const float *b = m->positions + 3 * (size_t)ix[(k + 1) % 3];
            double dx = (double)a[0] - b[0], dy = (double)a[1] - b[1], dz = (double)a[2] - b[2];
            double len = sqrt(dx * dx + dy * dy + dz * dz);
            sum[ix[k]] += len, count[ix[k]]++;
            sum[ix[(k + 1) % 3]] += len, count[ix[(k + 1) % 3]]++;
        }
    }
    for (uint32_t v = 0; v < m->vertex_count; v++)
        out[v] = count[v] ? (float)(sum[v] / count[v]) : 0.0f;
    free(count);
    free(sum);
    return VB_OK;
}

/* ---- probes ------------------------------------------------------------- */

/* 16 directions above a receiver's horizon and their mirror images below,
 * on a staggered 4 x 4 grid in its normal's frame. */
#define PROBES 16
#define PROBE_UP_LIMIT 14   /* ~90% of the upper probes at ~0: squeezed or embedded */
#define PROBE_BACK_LIMIT 8  /* a quarter of all probes on a back face at ~0: behind a surface */
/* Faces this close along a ray coincide: a few ulps of the traced frame's
 * unit coordinates, and 1e-5 of the distance. Two faces in one plane
 * differ by an ulp or two; a ray passing near an edge where two faces
 * meet at an angle rarely comes this close to both. */
#define TIE_ABS 1e-6f
#define TIE_REL 1e-5f

typedef struct prober {
    const vb_scene *s;
    float local_dir[PROBES][3];
} prober;

static void prober_init(prober *P, const vb_scene *s)
{
    P->s = s;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double z = 1.0 - (i + 0.5) / 4.0, rr = sqrt(1.0 - z * z);
            double phi = 2.0 * VB_PI * (j + 0.5 + 0.25 * i) / 4.0;
            float *l = P->local_dir[4 * i + j];
            l[0] = (float)(rr * cos(phi)), l[1] = (float)(rr * sin(phi)), l[2] = (float)z;
        }
}

/* What a ray met first: nothing, a front face, a back face, or coincident
 * faces of both orientations. */
enum { FACE_NONE, FACE_FRONT, FACE_BACK, FACE_BOTH };

/* An intersect context whose filter records, per ray (by ray id), the
 * nearest front and back face of every candidate and rejects them all, so
 * that Embree visits every face in the ray's [tnear, tfar]: the answer is
 * the set of faces, not whichever the kernel reached first. */
typedef struct collect_ctx {
    struct RTCIntersectContext ctx; /* first: Embree hands it back */
    float tf[PROBES], tb[PROBES];
} collect_ctx;

static void collect_filter(const struct RTCFilterFunctionNArguments *a)
{
    collect_ctx *C = (collect_ctx *)a->context;
    const unsigned N = a->N;
    /* RTCRayN and RTCHitN as plain arrays (their C accessors are C++ only):
     * ray: org xyz, tnear, dir xyz, time, tfar, mask, id, flags; hit: Ng xyz. */
    const float *ray = (const float *)a->ray, *hit = (const float *)a->hit;
    const unsigned *id = (const unsigned *)a->ray + 10 * (size_t)N;
    for (unsigned i = 0; i < N; i++) {
        if (!a->valid[i])
            continue;
        unsigned k = id[i] % PROBES;
        float t = ray[8 * N + i];
        float facing = hit[i] * ray[4 * N + i] + hit[N + i] * ray[5 * N + i] +
                       hit[2 * N + i] * ray[6 * N + i];
        float *slot = facing > 0.0f ? &C->tb[k] : &C->tf[k];
        if (t < *slot)
            *slot = t;
        a->valid[i] = 0;
    }
}

static void collect_init(collect_ctx *C)
{
    rtcInitIntersectContext(&C->ctx);
    C->ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    C->ctx.filter = collect_filter;
    for (int k = 0; k < PROBES; k++)
        C->tf[k] = INFINITY, C->tb[k] = INFINITY;
}

static int classify(float tf, float tb)
{
    float t0 = fminf(tf, tb);
    if (!(t0 < INFINITY))
        return FACE_NONE;
    float lim = t0 + TIE_REL * t0 + TIE_ABS;
    int f = tf <= lim, b = tb <= lim;
    return f && b ? FACE_BOTH : b ? FACE_BACK : FACE_FRONT;
}

/* A packet of the 16 probe directions around unit normal n (sz = -1: the
 * mirror images below the horizon) from o, in [0, tfar]. */
static void probe_packet(const prober *J, const float o[3], const float n[3], float sz,
                         float tfar, struct RTCRayHit16 *rh, int valid[16])
{
    float t[3], b[3];
    vb_frame(n, t, b);
    for (int k = 0; k < PROBES; k++) {
        const float *l = J->local_dir[k];
        rh->ray.dir_x[k] = l[0] * t[0] + l[1] * b[0] + sz * l[2] * n[0];
        rh->ray.dir_y[k] = l[0] * t[1] + l[1] * b[1] + sz * l[2] * n[1];
        rh->ray.dir_z[k] = l[0] * t[2] + l[1] * b[2] + sz * l[2] * n[2];
        rh->ray.org_x[k] = o[0], rh->ray.org_y[k] = o[1], rh->ray.org_z[k] = o[2];
        rh->ray.tnear[k] = 0.0f, rh->ray.tfar[k] = tfar, rh->ray.time[k] = 0.0f;
        rh->ray.mask[k] = 0xffffffffu, rh->ray.id[k] = (unsigned)k, rh->ray.flags[k] = 0;
        rh->hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        rh->hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        valid[k] = -1;
    }
}

/* The short probe from o around n, each ray `near` long (traced frame):
 * upper probes that meet anything, and probes (upper and lower) whose
 * nearest faces are back faces only, or coincident faces of both kinds. */
typedef struct short_result {
    int up, back, tie;
} short_result;

static short_result short_probe(const prober *J, const float o[3], const float n[3],
                                float near, uint64_t *rays)
{
    short_result r = {0, 0, 0};
    for (int side = 0; side < 2; side++) {
        struct RTCRayHit16 rh __attribute__((aligned(64)));
        int valid[16] __attribute__((aligned(64)));
        collect_ctx C;
        collect_init(&C);
        probe_packet(J, o, n, side ? -1.0f : 1.0f, near, &rh, valid);
        rtcIntersect16(valid, J->s->scene, &C.ctx, &rh);
        for (int k = 0; k < PROBES; k++) {
            int c = classify(C.tf[k], C.tb[k]);
            r.up += !side && c != FACE_NONE;
            r.back += c == FACE_BACK;
            r.tie += c == FACE_BOTH;
        }
    }
    *rays += 2 * PROBES;
    return r;
}

/* How many of the 16 full-length upper probes from o escape the scene. */
static int escapes(const prober *J, const float o[3], const float n[3], uint64_t *rays)
{
    struct RTCRayHit16 rh __attribute__((aligned(64)));
    int valid[16] __attribute__((aligned(64)));
    probe_packet(J, o, n, 1.0f, INFINITY, &rh, valid);
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcOccluded16(valid, J->s->scene, &ctx, &rh.ray);
    int out = 0;
    for (int k = 0; k < PROBES; k++)
        out += rh.ray.tfar[k] >= 0.0f; /* occluded rays get tfar = -inf */
    *rays += PROBES;
    return out;
}

/* ---- receiver frames ---------------------------------------------------- */

/* What the origin rules need to know about each receiver: the normal
 * averaged over every receiver at its position, the inset vector into its
 * own triangles, the triangles around it and its near distance. Built once
 * per bake: the orientation flips normals, and then only the parts that
 * depend on them (navg, inset) are computed again (frames_normals). */
typedef struct frames {
    float *navg;                /* 3 per vertex */
    float *inset;               /* 3 per vertex */
    float *near;                /* per vertex, scene units */
    uint32_t *adj_start, *adj;  /* vertex -> its triangles, in triangle order */
    double *pull;               /* 4 per vertex: the centroids' pull x, y, z, weight */
} frames;

static void frames_free(frames *f)
{
    free(f->navg);
    free(f->inset);
    free(f->near);
    free(f->adj_start);
    free(f->adj);
    free(f->pull);
    memset(f, 0, sizeof *f);
}

/* The parts of f that depend on m's normals: the averaged normals, and the
 * inset (the centroids' pull in the tangent plane of the averaged normal). */
static vb_result frames_normals(const vb_mesh *m, frames *f, vb_error *err)
{
    vb_result r = vb_offset_normals(m, f->navg, err);
    if (r != VB_OK)
        return r;
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        const float *nv = f->navg + 3 * (size_t)v;
        const double *a = f->pull + 4 * (size_t)v;
        if (a[3] > 0.0) {
            double dot = a[0] * nv[0] + a[1] * nv[1] + a[2] * nv[2];
            for (int i = 0; i < 3; i++)
                f->inset[3 * (size_t)v + i] = (float)((a[i] - dot * nv[i]) / a[3]);
        }
    }
    return VB_OK;
}

static vb_result frames_create(const vb_mesh *m, const vb_scene *s, frames *f, vb_error *err)
{
    uint32_t n = m->vertex_count;
    memset(f, 0, sizeof *f);
    f->navg = malloc((size_t)n * 3 * sizeof *f->navg + 1);
    f->inset = calloc((size_t)n * 3 + 1, sizeof *f->inset);
    f->near = malloc((size_t)n * sizeof *f->near + 1);
    f->adj_start = calloc((size_t)n + 1, sizeof *f->adj_start);
    f->adj = malloc((size_t)m->triangle_count * 3 * sizeof *f->adj + 1);
    double *acc = f->pull = calloc((size_t)n * 4 + 1, sizeof *acc); /* x, y, z, weight */
    uint32_t *fill = malloc((size_t)n * sizeof *fill + 1);
    vb_result r = VB_OK;
    if (!f->navg || !f->inset || !f->near || !f->adj_start || !f->adj || !acc || !fill) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for ray origins");
        goto done;
    }
    if ((r = vb_mean_edges(m, f->near, err)) != VB_OK)
        goto done;
    for (uint32_t v = 0; v < n; v++)
        f->near[v] = vb_receiver_near(s->diagonal, f->near[v]);
    /* Inset: the mean direction from a vertex to the centroids of its own
     * triangles, weighted by their distance, in the tangent plane.
     * Interior vertices' pulls cancel (length ~0); a vertex on a boundary
     * or crease gets a vector of length up to 1 into its own surface. */
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *ix = m->indices + 3 * (size_t)t;
        double c[3] = {0, 0, 0};
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 3; i++)
                c[i] += m->positions[3 * (size_t)ix[k] + i] / 3.0;
        for (int k = 0; k < 3; k++) {
            const float *p = m->positions + 3 * (size_t)ix[k];
            double d[3] = {c[0] - p[0], c[1] - p[1], c[2] - p[2]};
            double *a = acc + 4 * (size_t)ix[k];
            for (int i = 0; i < 3; i++)
                a[i] += d[i];
            a[3] += sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            f->adj_start[ix[k] + 1]++;
        }
    }
    for (uint32_t v = 0; v < n; v++)
        f->adj_start[v + 1] += f->adj_start[v];
    memcpy(fill, f->adj_start, (size_t)n * sizeof *fill);
    for (uint32_t t = 0; t < m->triangle_count; t++)
        for (int k = 0; k < 3; k++)
            f->adj[fill[m->indices[3 * (size_t)t + k]]++] = t;
    r = frames_normals(m, f, err);
done:
    free(fill);
    if (r != VB_OK)
        frames_free(f);
    return r;
}

/* The standard origin of receiver v on side `sign` of its surface (+1:
 * the side its normal points to), in the traced frame: offset along the
 * averaged normal, then along the inset. */
static void standard_origin(const vb_scene *s, const vb_mesh *m, const frames *f, uint32_t v,
                            float sign, float out[3])
{
    const float *nv = f->navg + 3 * (size_t)v;
    float p[3], o[3], ns[3] = {sign * nv[0], sign * nv[1], sign * nv[2]};
    vb_scene_to_local(s, m->positions + 3 * (size_t)v, p);
    vb_offset_origin(p, ns, o);
    vb_offset_origin(o, f->inset + 3 * (size_t)v, out);
}

/* What the first probe says of an origin. */
enum { ORIGIN_FREE, ORIGIN_REPAIR, ORIGIN_PRESSED };

static int mostly_facing(const prober *J, const float o[3], const float n[3], int back,
                         uint64_t *rays);

/* Whether the origin of receiver v at o must be repaired: squeezed (upper
 * probes at ~0) or behind a surface (back faces at ~0) - or pressed: only
 * coincident faces make the back count, and the receiver's own surface is
 * the skin of a solid (from just behind it, the full-length probes toward
 * -n meet back faces): a box's bottom on a floor, whose origin would look
 * through the floor, where a double-sided sheet's sides are free. */
static int origin_state(const prober *J, const vb_mesh *m, const frames *F, uint32_t v,
                        const float o[3], const float n[3], float near, short_result *sr,
                        int *tie_seen, uint64_t *rays)
{
    *sr = short_probe(J, o, n, near, rays);
    *tie_seen |= sr->tie > 0;
    if (sr->up >= PROBE_UP_LIMIT || sr->back >= PROBE_BACK_LIMIT)
        return ORIGIN_REPAIR;
    if (sr->back + sr->tie < PROBE_BACK_LIMIT)
        return ORIGIN_FREE;
    float behind[3], mn[3] = {-n[0], -n[1], -n[2]};
    standard_origin(J->s, m, F, v, -1.0f, behind);
    int res = mostly_facing(J, behind, mn, 1, rays);
    return res ? ORIGIN_PRESSED : ORIGIN_FREE;
}

/* ---- the repair --------------------------------------------------------- */

/* How bad an origin that is not in free space is, worst first: looking
 * into the void (full-length upper probes that hit nothing: an origin
 * pushed through the floor it rests on sees only the outside of the room,
 * and would store the clamp distance where the truth is ~0); on the back
 * of a surface (coincident faces count as back here); squeezed. */
typedef struct badness {
    int escape, back, up;
} badness;

static int worse_short(short_result a, short_result b)
{
    if (a.back + a.tie != b.back + b.tie)
        return a.back + a.tie > b.back + b.tie;
    return a.up > b.up;
}

static int worse(badness a, badness b)
{
    if (a.escape != b.escape)
        return a.escape > b.escape;
    if (a.back != b.back)
        return a.back > b.back;
    return a.up > b.up;
}

static badness full_badness(const prober *J, const float o[3], const float n[3],
                            short_result sr, uint64_t *rays)
{
    badness b = {escapes(J, o, n, rays), sr.back + sr.tie, sr.up};
    return b;
}

typedef struct origin_job {
    const vb_mesh *m;
    const frames *F;
    float *out;
    const uint8_t *need;        /* vb_receivers_prepare's; NULL: all */
    prober P;
    _Atomic uint32_t moved, flagged, ties;
    _Atomic uint64_t rays;
} origin_job;

/* What repairing one receiver did (bits). */
enum { REPAIR_MOVED = 1, REPAIR_FLAGGED = 2, REPAIR_TIE = 4 };

/* Probe receiver v's origin J->out[v] and repair it if it must be. */
static unsigned repair_one(origin_job *J, uint32_t v, uint64_t *rays)
{
    const vb_mesh *m = J->m;
    const frames *F = J->F;
    const float scale = J->P.s->scale;
    /* Steps toward the centroids of its own triangles, nearest first; up
     * to 95% of the way, since a fan mostly buried in other geometry may
     * show only near its far edge. At most 4 triangles of the fan, evenly
     * spread over it: the cost stays bounded at any valence. */
    static const float steps[6] = {0.05f, 0.15f, 0.35f, 0.6f, 0.8f, 0.95f};
    enum { FAN = VB_REPAIR_CANDIDATES / 6 };
    const float *n = m->normals + 3 * (size_t)v;
    if (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f)
        return 0;
    float *o = J->out + 3 * (size_t)v;
    const float near = F->near[v] * scale;
    short_result sr, csr, best_sr = {0, 0, 0};
    int tie_seen = 0;
    int state = origin_state(&J->P, m, F, v, o, n, near, &sr, &tie_seen, rays);
    if (state == ORIGIN_FREE)
        return tie_seen ? REPAIR_TIE : 0;
    if (state == ORIGIN_PRESSED) {
        /* Pressed flat against a surface it faces: no point of its own
         * surface is free, and the true distances are ~0. The origin
         * just behind its own surface gives exactly that, instead of
         * one pushed through the other surface. */
        standard_origin(J->P.s, m, F, v, -1.0f, o);
        return REPAIR_FLAGGED | REPAIR_TIE | REPAIR_MOVED;
    }
    const float *p = m->positions + 3 * (size_t)v;
    float best[3] = {o[0], o[1], o[2]}, cand[3], first[3] = {0, 0, 0};
    int found = 0, have = 0;
    uint32_t a0 = F->adj_start[v], fan = F->adj_start[v + 1] - a0;
    uint32_t picks = fan < FAN ? fan : FAN;
    for (int st = 0; st < 6 && !found; st++)
        for (uint32_t i = 0; i < picks && !found; i++) {
            uint32_t a = a0 + (uint32_t)((uint64_t)i * fan / picks);
            const uint32_t *ix = m->indices + 3 * (size_t)F->adj[a];
            float q[3], ql[3];
            for (int c = 0; c < 3; c++) {
                double ctr = ((double)m->positions[3 * (size_t)ix[0] + c] +
                              m->positions[3 * (size_t)ix[1] + c] +
                              m->positions[3 * (size_t)ix[2] + c]) / 3.0;
                q[c] = (float)(p[c] + steps[st] * (ctr - p[c]));
            }
            vb_scene_to_local(J->P.s, q, ql);
            vb_offset_origin(ql, F->navg + 3 * (size_t)v, cand);
            int cs = origin_state(&J->P, m, F, v, cand, n, near, &csr, &tie_seen, rays);
            found = cs != ORIGIN_REPAIR;
            if (cs == ORIGIN_PRESSED) /* its face lies on another: see above */
                standard_origin(J->P.s, m, F, v, -1.0f, cand);
            if (found) { /* in free space, or pressed: take it */
                memcpy(best, cand, sizeof best);
            } else if (!have || worse_short(best_sr, csr)) {
                memcpy(first, cand, sizeof first);
                best_sr = csr;
                have = 1;
            }
        }
    if (!found) {
        /* The least bad of: where it is, the best candidate, and the
         * origin just behind its own surface (a face pressed against
         * another without coincident faces, one buried in a solid).
         * Ties keep the earlier. */
        badness bb = full_badness(&J->P, o, n, sr, rays), c;
        if (have && (c = full_badness(&J->P, first, n, best_sr, rays), worse(bb, c))) {
            memcpy(best, first, sizeof best);
            bb = c;
        }
        standard_origin(J->P.s, m, F, v, -1.0f, cand);
        csr = short_probe(&J->P, cand, n, near, rays);
        c = full_badness(&J->P, cand, n, csr, rays);
        if (worse(bb, c))
            memcpy(best, cand, sizeof best);
    }
    unsigned res = REPAIR_FLAGGED | (tie_seen ? REPAIR_TIE : 0);
    if (memcmp(best, o, sizeof best) != 0) {
        memcpy(o, best, sizeof best);
        res |= REPAIR_MOVED;
    }
    return res;
}

static void repair_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    origin_job *J = ctx;
    (void)worker;
    uint64_t rays = 0;
    uint32_t moved = 0, flagged = 0, ties = 0;
    for (uint32_t v = begin; v < end; v++) {
        if (J->need && !J->need[v])
            continue;
        unsigned did = repair_one(J, v, &rays);
        if (J->need && J->need[v] != VB_NEED_COUNT)
            continue; /* prepared, not counted */
        moved += (did & REPAIR_MOVED) != 0;
        flagged += (did & REPAIR_FLAGGED) != 0;
        ties += (did & REPAIR_TIE) != 0;
    }
    atomic_fetch_add(&J->moved, moved);
    atomic_fetch_add(&J->flagged, flagged);
    atomic_fetch_add(&J->ties, ties);
    atomic_fetch_add(&J->rays, rays);
}

static vb_result place_origins(const vb_mesh *m, const vb_scene *s, const frames *Fp,
                               unsigned threads, const uint8_t *need, float *out,
                               float *near_out, vb_origins_stats *stats, double t0,
                               vb_error *err)
{
    const frames F = *Fp;
    vb_result r = VB_OK;
    /* 1. The standard rule. */
    for (uint32_t v = 0; v < m->vertex_count; v++)
        standard_origin(s, m, &F, v, 1.0f, out + 3 * (size_t)v);
    /* 2. Repair: probe every receiver, move those left inside or behind
     * other geometry. */
    origin_job *J = calloc(1, sizeof *J);
    if (!J)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for ray origins");
    J->m = m, J->F = &F, J->out = out, J->need = need;
    prober_init(&J->P, s);
    if (vb_parallel_for(threads, m->vertex_count, 256, repair_block, J, NULL, NULL) == 0)
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    if (r == VB_OK && near_out)
        memcpy(near_out, F.near, (size_t)m->vertex_count * sizeof *near_out);
    if (r == VB_OK && stats) {
        stats->moved = atomic_load(&J->moved);
        stats->flagged = atomic_load(&J->flagged);
        stats->ties = atomic_load(&J->ties);
        stats->probe_rays = atomic_load(&J->rays);
        stats->seconds = vb_now() - t0;
    }
    free(J);
    return r;
}

vb_result vb_ray_origins(const vb_mesh *m, const vb_scene *s, unsigned threads, float *out,
                         float *near_out, vb_origins_stats *stats, vb_error *err)
{
    double t0 = vb_now();
    frames F;
    vb_result r = frames_create(m, s, &F, err);
    if (r != VB_OK)
        return r;
    r = place_origins(m, s, &F, threads, NULL, out, near_out, stats, t0, err);
    frames_free(&F);
    return r;
}

/* ---- orientation -------------------------------------------------------- */

typedef struct orient_job {
    const vb_mesh *m;
    const frames *F;
    const uint8_t *need;        /* NULL: all */
    prober P;
    uint8_t *flip;
} orient_job;

/* What the ray from o along d meets first: one query for the nearest
 * face, then every face that coincides with it. */
static int first_face(const prober *J, const float o[3], const float d[3], uint64_t *rays)
{
    (*rays)++;
    struct RTCRayHit rh;
    rh.ray.dir_x = d[0], rh.ray.dir_y = d[1], rh.ray.dir_z = d[2];
    rh.ray.org_x = o[0], rh.ray.org_y = o[1], rh.ray.org_z = o[2];
    rh.ray.tnear = 0.0f, rh.ray.tfar = INFINITY, rh.ray.time = 0.0f;
    rh.ray.mask = 0xffffffffu, rh.ray.id = 0, rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcIntersect1(J->s->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return FACE_NONE;
    /* The second query spans [0, a little past t], never a narrow window
     * around t: Embree's box tests cull a window of a few ulps unreliably. */
    float t = rh.ray.tfar;
    collect_ctx C;
    collect_init(&C);
    (*rays)++;
    rh.ray.tnear = 0.0f, rh.ray.tfar = t + 1e-3f * t + 4.0f * TIE_ABS;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(J->s->scene, &C.ctx, &rh);
    return classify(C.tf[0], C.tb[0]);
}

/* Whether at least PROBE_UP_LIMIT of the 16 full-length upper probes from o
 * around unit normal n meet back faces (back = 1: faces turned away from
 * the ray) or front faces (back = 0; coincident faces of both kinds count
 * as front: a double-sided sheet can be seen); rays that escape count as
 * neither. One ray at a time, stopping as soon as the answer is known:
 * almost every receiver has its answer (no) after 3 probes, and the probes
 * point too far apart for a 16-wide packet to share any work. */
static int mostly_facing(const prober *J, const float o[3], const float n[3], int back,
                         uint64_t *rays)
{
    float t[3], b[3];
    vb_frame(n, t, b);
    int yes = 0, no = 0;
    for (int k = 0; k < PROBES && yes < PROBE_UP_LIMIT && no <= PROBES - PROBE_UP_LIMIT; k++) {
        const float *l = J->local_dir[k];
        float d[3];
        for (int i = 0; i < 3; i++)
            d[i] = l[0] * t[i] + l[1] * b[i] + l[2] * n[i];
        int c = first_face(J, o, d, rays);
        if (back ? c == FACE_BACK : c == FACE_FRONT || c == FACE_BOTH)
            yes++;
        else
            no++;
    }
    return yes >= PROBE_UP_LIMIT;
}

static void orient_block(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    orient_job *J = ctx;
    (void)worker;
    for (uint32_t v = begin; v < end; v++) {
        const float *n = J->m->normals + 3 * (size_t)v;
        if ((J->need && !J->need[v]) || (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f))
            continue;
        /* Full-length probes from the standard origins on both sides:
         * toward +n mostly the backs of faces (inside a solid); toward -n
         * mostly the fronts of faces (a scene seen from the outside).
         * Escaping rays do not count as seen: a floor covered by a crate
         * resting on it has a solid above it and the void outside the room
         * below, and its normal is right. */
        float o[3], m[3] = {-n[0], -n[1], -n[2]};
        uint64_t rays = 0;
        standard_origin(J->P.s, J->m, J->F, v, 1.0f, o);
        if (!mostly_facing(&J->P, o, n, 1, &rays))
            continue;
        standard_origin(J->P.s, J->m, J->F, v, -1.0f, o);
        J->flip[v] = (uint8_t)mostly_facing(&J->P, o, m, 0, &rays);
    }
}

/* Orient m's receivers with frames F of m: flip, in `normals` (m's or a
 * copy of them), those pointing into geometry. */
static vb_result orient(const vb_mesh *m, const vb_scene *s, const frames *F, unsigned threads,
                        const uint8_t *need, float *normals, uint32_t *flipped, uint32_t *any,
                        vb_error *err)
{
    vb_result r = VB_OK;
    orient_job J = {.m = m, .F = F, .need = need};
    J.flip = calloc((size_t)m->vertex_count + 1, 1);
    if (!J.flip)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for receiver normals");
    prober_init(&J.P, s);
    if (vb_parallel_for(threads, m->vertex_count, 256, orient_block, &J, NULL, NULL) == 0)
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    uint32_t count = 0, all = 0;
    for (uint32_t v = 0; v < m->vertex_count && r == VB_OK; v++)
        if (J.flip[v]) {
            for (int i = 0; i < 3; i++)
                normals[3 * (size_t)v + i] = -normals[3 * (size_t)v + i];
            count += !need || need[v] == VB_NEED_COUNT;
            all++;
        }
    free(J.flip);
    if (r == VB_OK) {
        *flipped = count; /* the counted ones */
        *any = all;       /* every flip: the frames depend on them all */
    }
    return r;
}

vb_result vb_orient_receivers(vb_mesh *m, const vb_scene *s, unsigned threads,
                              uint32_t *flipped, vb_error *err)
{
    frames F;
    vb_result r = frames_create(m, s, &F, err);
    if (r != VB_OK)
        return r;
    uint32_t count = 0;
    uint32_t any = 0;
    r = orient(m, s, &F, threads, NULL, m->normals, &count, &any, err);
    frames_free(&F);
    if (r == VB_OK && flipped)
        *flipped = count;
    return r;
}

/* need expanded to the receivers at the bit-identical position of a needed
 * one (marked VB_NEED_ONLY): their oriented normals enter the needed
 * ones' ray-offset normals. A new array, or NULL when out of memory. */
static uint8_t *need_with_coincident(const vb_mesh *m, const uint8_t *need)
{
    uint32_t n = m->vertex_count;
    uint8_t *out = malloc((size_t)n + 1);
    pos_key *key = sorted_positions(m);
    if (!out || !key) {
        free(out);
        free(key);
        return NULL;
    }
    memcpy(out, need, n);
    for (uint32_t a = 0; a < n;) {
        uint32_t b = group_end(key, n, a);
        int any = 0;
        for (uint32_t k = a; k < b; k++)
            any |= need[key[k].index] != 0;
        for (uint32_t k = a; k < b && any && b - a > 1; k++)
            if (!out[key[k].index])
                out[key[k].index] = VB_NEED_ONLY;
        a = b;
    }
    free(key);
    return out;
}

vb_result vb_receivers_prepare(const vb_mesh *m, const vb_scene *s, unsigned threads,
                               const uint8_t *need, float *normals, uint32_t *flipped,
                               float *out, float *near_out, vb_origins_stats *stats,
                               vb_error *err)
{
    double t0 = vb_now();
    frames F;
    vb_result r = frames_create(m, s, &F, err);
    if (r != VB_OK)
        return r;
    vb_mesh oriented = *m;
    uint32_t count = 0, any = 0;
    uint8_t *orient_need = NULL;
    if (need && normals && !(orient_need = need_with_coincident(m, need))) {
        frames_free(&F);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for receiver normals");
    }
    if (normals) {
        memcpy(normals, m->normals, (size_t)m->vertex_count * 3 * sizeof *normals);
        oriented.normals = normals;
        r = orient(m, s, &F, threads, orient_need, normals, &count, &any, err);
        /* The frames again where they depend on the normals: after any flip,
         * also one of a receiver that is not counted (a shard's neighbour at
         * the same position). */
        if (r == VB_OK && any > 0)
            r = frames_normals(&oriented, &F, err);
        t0 = vb_now(); /* the origins' time, as before: not the orientation's */
    }
    if (r == VB_OK)
        r = place_origins(&oriented, s, &F, threads, need, out, near_out, stats, t0, err);
    frames_free(&F);
    free(orient_need);
    if (r == VB_OK && flipped)
        *flipped = count;
    return r;
}
