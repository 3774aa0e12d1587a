/* Ray origins and receiver orientation: origins.h says what and why. */
#include "origins.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "parallel.h"
#include "sampling.h"
#include "vdsh_det.h"

#define VB_PI 3.14159265358979323846

/* ---- subsets of receivers ----------------------------------------------- */

/* The receivers a pass works on: receiver idx[k] at slot k, idx ascending;
 * idx NULL: every receiver, slot = index. The bitmap (bit v: receiver v is
 * in) and the rank (members before each 64-bit word) give a receiver's
 * slot in constant time, for 1.5 bits per receiver of the mesh: a shard's
 * passes hold arrays of its own receivers only. */
typedef struct subset {
    uint32_t count;
    uint32_t *idx;
    uint64_t *bits;
    uint32_t *rank;
} subset;

static void subset_free(subset *S)
{
    free(S->idx);
    free(S->bits);
    free(S->rank);
    memset(S, 0, sizeof *S);
}

static inline uint32_t subset_vertex(const subset *S, uint32_t k)
{
    return S->idx ? S->idx[k] : k;
}

/* Receiver v's slot, or UINT32_MAX when it is not in S. */
static inline uint32_t subset_slot(const subset *S, uint32_t v)
{
    if (!S->idx)
        return v;
    uint64_t w = S->bits[v >> 6], bit = 1ull << (v & 63);
    if (!(w & bit))
        return UINT32_MAX;
    return S->rank[v >> 6] + (uint32_t)__builtin_popcountll(w & (bit - 1));
}

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

/* Receiver v's position with -0 folded into +0 (bit-identical positions
 * are equal positions). */
static void position_key(const vb_mesh *m, uint32_t v, float p[3])
{
    for (int c = 0; c < 3; c++)
        p[c] = m->positions[3 * (size_t)v + c] + 0.0f;
}

/* A position's bits (-0 folded into +0) as three words, compared inline:
 * the coincidence search below makes one binary search per receiver. */
typedef struct pos_bits {
    uint32_t w[3];
} pos_bits;

static pos_bits position_bits(const vb_mesh *m, uint32_t v)
{
    float p[3];
    pos_bits b;
    position_key(m, v, p);
    memcpy(b.w, p, sizeof b.w);
    return b;
}

static inline int cmp_bits_inline(const pos_bits *x, const pos_bits *y)
{
    for (int c = 0; c < 3; c++)
        if (x->w[c] != y->w[c])
            return x->w[c] < y->w[c] ? -1 : 1;
    return 0;
}

static int cmp_bits(const void *a, const void *b)
{
    return cmp_bits_inline(a, b);
}

/* E: the receivers at the bit-identical position of one of set[0..n) (set
 * itself among them), so that every group of coincident receivers is
 * either all in E or all out: their normals enter each other's ray-offset
 * normals. One sort of the set's positions, one search per receiver. */
static vb_result subset_coincident(const vb_mesh *m, const uint32_t *set, uint32_t n, subset *E)
{
    const uint32_t V = m->vertex_count;
    const size_t words = ((size_t)V + 63) / 64;
    memset(E, 0, sizeof *E);
    pos_bits *key = malloc((size_t)n * sizeof *key + 1);
    E->bits = calloc(words + 1, sizeof *E->bits);
    E->rank = malloc((words + 1) * sizeof *E->rank);
    if (!key || !E->bits || !E->rank) {
        free(key);
        subset_free(E);
        return VB_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < n; i++)
        key[i] = position_bits(m, set[i]);
    qsort(key, n, sizeof *key, cmp_bits);
    uint32_t count = 0;
    for (uint32_t v = 0; v < V; v++) {
        pos_bits p = position_bits(m, v);
        size_t a = 0, b = n; /* the first key >= p */
        while (a < b) {
            size_t mid = (a + b) / 2;
            if (cmp_bits_inline(&key[mid], &p) < 0)
                a = mid + 1;
            else
                b = mid;
        }
        if (a < n && cmp_bits_inline(&key[a], &p) == 0) {
            E->bits[v >> 6] |= 1ull << (v & 63);
            count++;
        }
    }
    free(key);
    E->idx = malloc((size_t)count * sizeof *E->idx + 1);
    if (!E->idx) {
        subset_free(E);
        return VB_ERR_OUT_OF_MEMORY;
    }
    uint32_t k = 0;
    for (size_t w = 0; w < words; w++) {
        E->rank[w] = k;
        for (uint64_t bits = E->bits[w]; bits; bits &= bits - 1)
            E->idx[k++] = (uint32_t)(w * 64 + (size_t)__builtin_ctzll(bits));
    }
    E->count = count;
    return VB_OK;
}

/* ---- ray-offset normals ------------------------------------------------ */

/* E's receivers sorted by the bytes of their positions, which groups
 * bit-identical positions; ties are ordered by slot (= by index), so a
 * group's sums run in a fixed order. NULL when out of memory. */
static pos_key *sorted_positions(const vb_mesh *m, const subset *E)
{
    uint32_t n = E->count;
    pos_key *key = malloc((size_t)n * sizeof *key + 1);
    if (!key)
        return NULL;
    for (uint32_t k = 0; k < n; k++) {
        position_key(m, subset_vertex(E, k), key[k].p);
        key[k].index = k;
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

/* vb_offset_normals for the receivers of E (closed under coincidence):
 * normals and out per slot. */
static vb_result offset_normals_in(const vb_mesh *m, const subset *E, const float *normals,
                                   float *out, uint8_t *corner)
{
    uint32_t n = E->count;
    pos_key *key = sorted_positions(m, E);
    if (!key)
        return VB_ERR_OUT_OF_MEMORY;
    for (uint32_t a = 0; a < n;) {
        uint32_t b = group_end(key, n, a);
        /* Each vertex of the group sums the normals that face its own side
         * (n_u . n_v >= 0, itself included): an unwelded room corner
         * (floor and walls at right angles) gets one diagonal normal for
         * all its vertices, while a floor vertex under the corner of a
         * crate does not average in the crate's bottom, which faces the
         * other way. Sums run in group (index) order. */
        for (uint32_t k = a; k < b; k++) {
            const float *nk = normals + 3 * (size_t)key[k].index;
            double s[3] = {0, 0, 0};
            for (uint32_t j = a; j < b; j++) {
                const float *nj = normals + 3 * (size_t)key[j].index;
                if (nj[0] * nk[0] + nj[1] * nk[1] + nj[2] * nk[2] < 0.0f)
                    continue;
                for (int c = 0; c < 3; c++)
                    s[c] += nj[c];
            }
            double len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
            for (int c = 0; c < 3; c++)
                out[3 * (size_t)key[k].index + c] = len > 1e-12 ? (float)(s[c] / len) : 0.0f;
            /* A corner: another normal at its position (its bits differ). */
            if (corner) {
                uint8_t any = 0;
                for (uint32_t j = a; j < b && !any; j++)
                    any = memcmp(normals + 3 * (size_t)key[j].index, nk, 3 * sizeof *nk) != 0;
                corner[key[k].index] = any;
            }
        }
        a = b;
    }
    free(key);
    return VB_OK;
}

vb_result vb_offset_normals(const vb_mesh *m, float *out, vb_error *err)
{
    subset all = {.count = m->vertex_count};
    if (offset_normals_in(m, &all, m->normals, out, NULL) != VB_OK)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    return VB_OK;
}

float vb_receiver_near(float diag, float mean_edge)
{
    float global = 1e-3f * diag, local = 0.1f * mean_edge;
    return mean_edge > 0.0f && local < global ? local : global;
}

/* ---- probes ------------------------------------------------------------- */

/* 16 directions above a receiver's horizon and their mirror images below,
 * on a staggered 4 x 4 grid in its normal's frame. */
#define PROBES 16
#define PROBE_UP_LIMIT 14  /* ~90% of the upper probes at ~0: squeezed or embedded */
#define PROBE_BACK_LIMIT 8 /* a quarter of all probes on a back face at ~0: behind a surface */
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
            l[0] = (float)(rr * vdsh_det_cos(phi)), l[1] = (float)(rr * vdsh_det_sin(phi)),
            l[2] = (float)z;
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
        float facing =
            hit[i] * ray[4 * N + i] + hit[N + i] * ray[5 * N + i] + hit[2 * N + i] * ray[6 * N + i];
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
static void probe_packet(const prober *J, const float o[3], const float n[3], float sz, float tfar,
                         struct RTCRayHit16 *rh, int valid[16])
{
    float t[3], b[3];
    vb_frame(n, t, b);
    for (int k = 0; k < PROBES; k++) {
        const float *l = J->local_dir[k];
        rh->ray.dir_x[k] = l[0] * t[0] + l[1] * b[0] + sz * l[2] * n[0];
        rh->ray.dir_y[k] = l[0] * t[1] + l[1] * b[1] + sz * l[2] * n[1];
        rh->ray.dir_z[k] = l[0] * t[2] + l[1] * b[2] + sz * l[2] * n[2];
        vb_ray16_init(rh, k, o, tfar);
        valid[k] = -1;
    }
}

/* The short probe from o around n, each ray `near` long (traced frame):
 * upper probes that meet anything, and probes (upper and lower) whose
 * nearest faces are back faces only, or coincident faces of both kinds. */
typedef struct short_result {
    int up, back, tie;
} short_result;

/* The probe rays one at a time (upper first), each with the collecting
 * context: the 16 directions of a packet spread over a hemisphere, so a
 * 16-wide packet visits the union of their BVH nodes, which long thin
 * triangles (boxes that overlap at every origin) make dear: on a
 * generated interior of such triangles (scripts/gen_long_interior) single
 * rays took 0.4-0.6x the packets' time, with the same faces found (the
 * collecting filter sees every face in the window either way; the bakes
 * are byte-identical). */
static short_result short_probe(const prober *J, const float o[3], const float n[3], float near,
                                uint64_t *rays)
{
    short_result r = {0, 0, 0};
    for (int side = 0; side < 2; side++) {
        struct RTCRayHit16 rh __attribute__((aligned(64)));
        int valid[16] __attribute__((aligned(64)));
        collect_ctx C;
        collect_init(&C);
        probe_packet(J, o, n, side ? -1.0f : 1.0f, near, &rh, valid);
        for (int k = 0; k < PROBES; k++) {
            const float d[3] = {rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]};
            struct RTCRayHit r1;
            vb_ray_init(&r1, o, d, near, (unsigned)k);
            rtcIntersect1(J->s->scene, &C.ctx, &r1);
            (*rays)++;
            int c = classify(C.tf[k], C.tb[k]);
            r.up += !side && c != FACE_NONE;
            r.back += c == FACE_BACK;
            r.tie += c == FACE_BOTH;
        }
    }
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

/* What the origin rules need to know about the receivers of a subset E
 * (closed under coincidence; per slot): their normals, the normal averaged
 * over every receiver at the same position, the inset vector into their own
 * triangles, the triangles around them and their near distance. Built once
 * per bake: the orientation flips normals, and then only the parts that
 * depend on them (navg, inset) are computed again (frames_normals). */
typedef struct frames {
    const subset *E;
    float *normals; /* 3 per slot: borrowed, or own_normals */
    float *own_normals;
    float *navg;               /* 3 per slot */
    float *inset;              /* 3 per slot */
    float *near;               /* per slot, scene units */
    uint32_t *adj_start, *adj; /* slot -> its triangles, in triangle order */
    double *pull;              /* 4 per slot: the centroids' pull x, y, z, weight */
    uint8_t *area;             /* per slot: 1 when one of its triangles has area */
    uint8_t *corner;           /* per slot: 1 for a corner (origins.h, "Corners"); only with
                        vb_scene.corner_lift, else NULL */
} frames;

static void frames_free(frames *f)
{
    free(f->own_normals);
    free(f->navg);
    free(f->inset);
    free(f->near);
    free(f->adj_start);
    free(f->adj);
    free(f->pull);
    free(f->area);
    free(f->corner);
    memset(f, 0, sizeof *f);
}

/* The parts of f that depend on the normals: the averaged normals, and the
 * inset (the centroids' pull in the tangent plane of the averaged normal). */
static vb_result frames_normals(const vb_mesh *m, frames *f, vb_error *err)
{
    if (offset_normals_in(m, f->E, f->normals, f->navg, f->corner) != VB_OK)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory");
    for (uint32_t k = 0; k < f->E->count; k++) {
        const float *nv = f->navg + 3 * (size_t)k;
        const double *a = f->pull + 4 * (size_t)k;
        if (a[3] > 0.0) {
            double dot = a[0] * nv[0] + a[1] * nv[1] + a[2] * nv[2];
            for (int i = 0; i < 3; i++)
                f->inset[3 * (size_t)k + i] = (float)((a[i] - dot * nv[i]) / a[3]);
        }
    }
    return VB_OK;
}

/* The frames of E's receivers. normals: E's normals per slot, borrowed (to
 * be oriented in place), or NULL: a copy of m's. Every per-receiver sum
 * (edge lengths, the centroids' pull) runs over the triangles in order, as
 * over the whole mesh, so a receiver's frame does not depend on E. */
static vb_result frames_create(const vb_mesh *m, const vb_scene *s, const subset *E, float *normals,
                               frames *f, vb_error *err)
{
    uint32_t n = E->count;
    memset(f, 0, sizeof *f);
    f->E = E;
    if (!normals && (normals = f->own_normals = malloc((size_t)n * 3 * sizeof *normals + 1)))
        for (uint32_t k = 0; k < n; k++)
            memcpy(normals + 3 * (size_t)k, m->normals + 3 * (size_t)subset_vertex(E, k),
                   3 * sizeof *normals);
    f->normals = normals;
    f->navg = malloc((size_t)n * 3 * sizeof *f->navg + 1);
    f->inset = calloc((size_t)n * 3 + 1, sizeof *f->inset);
    f->near = malloc((size_t)n * sizeof *f->near + 1);
    f->adj_start = calloc((size_t)n + 1, sizeof *f->adj_start);
    f->area = calloc((size_t)n + 1, 1);
    f->corner = s->corner_lift ? calloc((size_t)n + 1, 1) : NULL;
    double *acc = f->pull = calloc((size_t)n * 4 + 1, sizeof *acc); /* x, y, z, weight */
    uint32_t *count = calloc((size_t)n + 1, sizeof *count);
    double *sum = calloc((size_t)n + 1, sizeof *sum);
    vb_result r = VB_OK;
    if (!f->normals || !f->navg || !f->inset || !f->near || !f->adj_start || !f->area ||
        (s->corner_lift && !f->corner) || !acc || !count || !sum) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for ray origins");
        goto done;
    }
    /* Per triangle with a corner in E: the mean edge length around each
     * corner and the inset's pull - the mean direction from
     * a vertex to the centroids of its own triangles, weighted by their
     * distance, in the tangent plane. Interior vertices' pulls cancel
     * (length ~0); a vertex on a boundary or crease gets a vector of length
     * up to 1 into its own surface. */
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *ix = m->indices + 3 * (size_t)t;
        uint32_t sl[3] = {subset_slot(E, ix[0]), subset_slot(E, ix[1]), subset_slot(E, ix[2])};
        if (sl[0] == UINT32_MAX && sl[1] == UINT32_MAX && sl[2] == UINT32_MAX)
            continue;
        for (int k = 0; k < 3; k++) {
            const float *a = m->positions + 3 * (size_t)ix[k];
            const float *b = m->positions + 3 * (size_t)ix[(k + 1) % 3];
            double dx = (double)a[0] - b[0], dy = (double)a[1] - b[1], dz = (double)a[2] - b[2];
            double len = sqrt(dx * dx + dy * dy + dz * dz);
            if (sl[k] != UINT32_MAX)
                sum[sl[k]] += len, count[sl[k]]++;
            if (sl[(k + 1) % 3] != UINT32_MAX)
                sum[sl[(k + 1) % 3]] += len, count[sl[(k + 1) % 3]]++;
        }
        if (vb_triangle_has_area(m->positions, ix)) /* drawn: vb_drawn_receivers */
            for (int k = 0; k < 3; k++)
                if (sl[k] != UINT32_MAX)
                    f->area[sl[k]] = 1;
        double c[3] = {0, 0, 0};
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 3; i++)
                c[i] += m->positions[3 * (size_t)ix[k] + i] / 3.0;
        for (int k = 0; k < 3; k++) {
            if (sl[k] == UINT32_MAX)
                continue;
            const float *p = m->positions + 3 * (size_t)ix[k];
            double d[3] = {c[0] - p[0], c[1] - p[1], c[2] - p[2]};
            double *a = acc + 4 * (size_t)sl[k];
            for (int i = 0; i < 3; i++)
                a[i] += d[i];
            a[3] += sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            f->adj_start[sl[k] + 1]++;
        }
    }
    for (uint32_t k = 0; k < n; k++) {
        f->near[k] = vb_receiver_near(s->diagonal, count[k] ? (float)(sum[k] / count[k]) : 0.0f);
        f->adj_start[k + 1] += f->adj_start[k];
    }
    /* The triangles around each receiver, in triangle order (count reused
     * as the fill pointer). */
    if (!(f->adj = malloc((size_t)f->adj_start[n] * sizeof *f->adj + 1))) {
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for ray origins");
        goto done;
    }
    memcpy(count, f->adj_start, (size_t)n * sizeof *count);
    for (uint32_t t = 0; t < m->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t sk = subset_slot(E, m->indices[3 * (size_t)t + k]);
            if (sk != UINT32_MAX)
                f->adj[count[sk]++] = t;
        }
    r = frames_normals(m, f, err);
done:
    free(count);
    free(sum);
    if (r != VB_OK)
        frames_free(f);
    return r;
}

/* The standard origin of receiver v (slot k of f) on side `sign` of its
 * surface (+1: the side its normal points to), in the traced frame: offset
 * along the averaged normal, then along the inset. */
static void standard_origin(const vb_scene *s, const vb_mesh *m, const frames *f, uint32_t v,
                            uint32_t k, float sign, float out[3])
{
    const float *nv = f->navg + 3 * (size_t)k, *in = f->inset + 3 * (size_t)k;
    const float lift = s->corner_lift && f->corner[k] ? VB_CORNER_LIFT : 1.0f;
    float p[3], o[3], ns[3] = {lift * sign * nv[0], lift * sign * nv[1], lift * sign * nv[2]};
    float is[3] = {lift * in[0], lift * in[1], lift * in[2]};
    vb_scene_to_local(s, m->positions + 3 * (size_t)v, p);
    vb_offset_origin(p, ns, o);
    vb_offset_origin(o, is, out);
}

/* What the first probe says of an origin. */
enum { ORIGIN_FREE, ORIGIN_REPAIR, ORIGIN_PRESSED };

static int mostly_facing(const prober *J, const float o[3], const float n[3], int back,
                         uint64_t *rays);

/* Whether the origin of receiver v (slot k) at o must be repaired:
 * squeezed (upper probes at ~0) or behind a surface (back faces at ~0) -
 * or pressed: only coincident faces make the back count, and the
 * receiver's own surface is the skin of a solid (from just behind it, the
 * full-length probes toward -n meet back faces): a box's bottom on a
 * floor, whose origin would look through the floor, where a double-sided
 * sheet's sides are free. */
static int origin_state(const prober *J, const vb_mesh *m, const frames *F, uint32_t v, uint32_t k,
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
    standard_origin(J->s, m, F, v, k, -1.0f, behind);
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

static badness full_badness(const prober *J, const float o[3], const float n[3], short_result sr,
                            uint64_t *rays)
{
    badness b = {escapes(J, o, n, rays), sr.back + sr.tie, sr.up};
    return b;
}

/* The receivers given origins: set[j] at slot j of out (set NULL: every
 * receiver); those in [count_begin, count_end) counted. */
typedef struct origin_job {
    const vb_mesh *m;
    const frames *F;
    const uint32_t *set;
    uint32_t count_begin, count_end;
    float *out;
    prober P;
    _Atomic uint32_t moved, flagged, ties, no_area;
    _Atomic uint64_t rays;
} origin_job;

/* What repairing one receiver did (bits). */
enum { REPAIR_MOVED = 1, REPAIR_FLAGGED = 2, REPAIR_TIE = 4, REPAIR_NO_AREA = 8 };

/* Probe receiver v's (slot k of the frames) origin o and repair it if it
 * must be. */
static unsigned repair_one(origin_job *J, uint32_t v, uint32_t k, float *o, uint64_t *rays)
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
    const float *n = F->normals + 3 * (size_t)k;
    if (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f)
        return 0;
    /* Its triangles have no area (a fan's triangles along its corner's
     * own edges; the normal came from the file): it is drawn nowhere, so
     * its origin decides nothing a viewer sees. The standard rule's origin
     * stays, unprobed: such receivers could never be freed (every
     * candidate lies on their line) and took half the probe rays of a CAD
     * interior (docs/BENCHMARKS.md). */
    if (!F->area[k])
        return REPAIR_NO_AREA;
    const float near = F->near[k] * scale;
    short_result sr, csr, best_sr = {0, 0, 0};
    int tie_seen = 0;
    int state = origin_state(&J->P, m, F, v, k, o, n, near, &sr, &tie_seen, rays);
    if (state == ORIGIN_FREE)
        return tie_seen ? REPAIR_TIE : 0;
    if (state == ORIGIN_PRESSED) {
        /* Pressed flat against a surface it faces: no point of its own
         * surface is free, and the true distances are ~0. The origin
         * just behind its own surface gives exactly that, instead of
         * one pushed through the other surface. */
        standard_origin(J->P.s, m, F, v, k, -1.0f, o);
        return REPAIR_FLAGGED | REPAIR_TIE | REPAIR_MOVED;
    }
    const float *p = m->positions + 3 * (size_t)v;
    float best[3] = {o[0], o[1], o[2]}, cand[3], first[3] = {0, 0, 0};
    int found = 0, have = 0;
    uint32_t a0 = F->adj_start[k], fan = F->adj_start[k + 1] - a0;
    uint32_t picks = fan < FAN ? fan : FAN;
    for (int st = 0; st < 6 && !found; st++)
        for (uint32_t i = 0; i < picks && !found; i++) {
            uint32_t a = a0 + (uint32_t)((uint64_t)i * fan / picks);
            const uint32_t *ix = m->indices + 3 * (size_t)F->adj[a];
            float q[3], ql[3];
            for (int c = 0; c < 3; c++) {
                double ctr =
                    ((double)m->positions[3 * (size_t)ix[0] + c] +
                     m->positions[3 * (size_t)ix[1] + c] + m->positions[3 * (size_t)ix[2] + c]) /
                    3.0;
                q[c] = (float)(p[c] + steps[st] * (ctr - p[c]));
            }
            vb_scene_to_local(J->P.s, q, ql);
            vb_offset_origin(ql, F->navg + 3 * (size_t)k, cand);
            int cs = origin_state(&J->P, m, F, v, k, cand, n, near, &csr, &tie_seen, rays);
            found = cs != ORIGIN_REPAIR;
            if (cs == ORIGIN_PRESSED) /* its face lies on another: see above */
                standard_origin(J->P.s, m, F, v, k, -1.0f, cand);
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
        standard_origin(J->P.s, m, F, v, k, -1.0f, cand);
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
    uint32_t moved = 0, flagged = 0, ties = 0, no_area = 0;
    for (uint32_t j = begin; j < end; j++) {
        uint32_t v = J->set ? J->set[j] : j;
        unsigned did = repair_one(J, v, subset_slot(J->F->E, v), J->out + 3 * (size_t)j, &rays);
        if (v < J->count_begin || v >= J->count_end)
            continue; /* prepared, not counted */
        moved += (did & REPAIR_MOVED) != 0;
        flagged += (did & REPAIR_FLAGGED) != 0;
        ties += (did & REPAIR_TIE) != 0;
        no_area += (did & REPAIR_NO_AREA) != 0;
    }
    atomic_fetch_add(&J->moved, moved);
    atomic_fetch_add(&J->flagged, flagged);
    atomic_fetch_add(&J->ties, ties);
    atomic_fetch_add(&J->no_area, no_area);
    atomic_fetch_add(&J->rays, rays);
}

/* Origins and near distances of set[0..set_count) (NULL: every receiver)
 * at their slots of out and near_out, by the standard rule, then the
 * repair. */
static vb_result place_origins(const vb_mesh *m, const vb_scene *s, const frames *F,
                               unsigned threads, const uint32_t *set, uint32_t set_count,
                               uint32_t count_begin, uint32_t count_end, float *out,
                               float *near_out, vb_origins_stats *stats, double t0, vb_error *err)
{
    vb_result r = VB_OK;
    /* 1. The standard rule. */
    for (uint32_t j = 0; j < set_count; j++) {
        uint32_t v = set ? set[j] : j, k = subset_slot(F->E, v);
        standard_origin(s, m, F, v, k, 1.0f, out + 3 * (size_t)j);
        if (near_out)
            near_out[j] = F->near[k];
    }
    /* 2. Repair: probe every receiver, move those left inside or behind
     * other geometry. */
    origin_job *J = calloc(1, sizeof *J);
    if (!J)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for ray origins");
    J->m = m, J->F = F, J->set = set, J->out = out;
    J->count_begin = count_begin, J->count_end = count_end;
    prober_init(&J->P, s);
    if (vb_parallel_for(threads, set_count, 256, repair_block, J, NULL, NULL) == 0)
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    if (r == VB_OK && stats) {
        stats->moved = atomic_load(&J->moved);
        stats->flagged = atomic_load(&J->flagged);
        stats->ties = atomic_load(&J->ties);
        stats->skipped_zero_area = atomic_load(&J->no_area);
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
    subset all = {.count = m->vertex_count};
    frames F;
    vb_result r = frames_create(m, s, &all, NULL, &F, err);
    if (r != VB_OK)
        return r;
    r = place_origins(m, s, &F, threads, NULL, m->vertex_count, 0, m->vertex_count, out, near_out,
                      stats, t0, err);
    frames_free(&F);
    return r;
}

/* ---- orientation -------------------------------------------------------- */

typedef struct orient_job {
    const vb_mesh *m;
    const frames *F;
    prober P;
    uint8_t *flip; /* per slot of F */
} orient_job;

/* What the ray from o along d meets first: one query for the nearest
 * face, then every face that coincides with it. */
static int first_face(const prober *J, const float o[3], const float d[3], uint64_t *rays)
{
    (*rays)++;
    struct RTCRayHit rh;
    vb_ray_init(&rh, o, d, INFINITY, 0);
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
    for (uint32_t k = begin; k < end; k++) {
        uint32_t v = subset_vertex(J->F->E, k);
        const float *n = J->F->normals + 3 * (size_t)k;
        if (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f)
            continue;
        /* Full-length probes from the standard origins on both sides:
         * toward +n mostly the backs of faces (inside a solid); toward -n
         * mostly the fronts of faces (a scene seen from the outside).
         * Escaping rays do not count as seen: a floor covered by a crate
         * resting on it has a solid above it and the void outside the room
         * below, and its normal is right. */
        float o[3], m[3] = {-n[0], -n[1], -n[2]};
        uint64_t rays = 0;
        standard_origin(J->P.s, J->m, J->F, v, k, 1.0f, o);
        if (!mostly_facing(&J->P, o, n, 1, &rays))
            continue;
        standard_origin(J->P.s, J->m, J->F, v, k, -1.0f, o);
        J->flip[k] = (uint8_t)mostly_facing(&J->P, o, m, 0, &rays);
    }
}

/* Orient the receivers of F (all of its subset): flip, in F's normals,
 * those pointing into geometry. `flipped` counts those in
 * [count_begin, count_end), `any` every flip. */
static vb_result orient(const vb_mesh *m, const vb_scene *s, frames *F, unsigned threads,
                        uint32_t count_begin, uint32_t count_end, uint32_t *flipped, uint32_t *any,
                        vb_error *err)
{
    vb_result r = VB_OK;
    const uint32_t n = F->E->count;
    orient_job J = {.m = m, .F = F};
    J.flip = calloc((size_t)n + 1, 1);
    if (!J.flip)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for receiver normals");
    prober_init(&J.P, s);
    if (vb_parallel_for(threads, n, 256, orient_block, &J, NULL, NULL) == 0)
        r = vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    uint32_t count = 0, all = 0;
    for (uint32_t k = 0; k < n && r == VB_OK; k++)
        if (J.flip[k]) {
            uint32_t v = subset_vertex(F->E, k);
            for (int i = 0; i < 3; i++)
                F->normals[3 * (size_t)k + i] = -F->normals[3 * (size_t)k + i];
            count += v >= count_begin && v < count_end;
            all++;
        }
    free(J.flip);
    if (r == VB_OK) {
        *flipped = count; /* the counted ones */
        *any = all;       /* every flip: the frames depend on them all */
    }
    return r;
}

vb_result vb_orient_receivers(vb_mesh *m, const vb_scene *s, unsigned threads, uint32_t *flipped,
                              vb_error *err)
{
    subset all = {.count = m->vertex_count};
    frames F;
    vb_result r = frames_create(m, s, &all, m->normals, &F, err);
    if (r != VB_OK)
        return r;
    uint32_t count = 0;
    uint32_t any = 0;
    r = orient(m, s, &F, threads, 0, m->vertex_count, &count, &any, err);
    frames_free(&F);
    if (r == VB_OK && flipped)
        *flipped = count;
    return r;
}

vb_result vb_receivers_prepare(const vb_mesh *m, const vb_scene *s, unsigned threads,
                               const uint32_t *set, uint32_t set_count, uint32_t count_begin,
                               uint32_t count_end, float *normals, uint32_t *flipped, float *out,
                               float *near_out, vb_origins_stats *stats, vb_error *err)
{
    double t0 = vb_now();
    const uint32_t V = m->vertex_count;
    if (!set)
        set_count = V, count_begin = 0, count_end = V;
    /* The frames of the set and of the receivers at its positions. */
    subset E = {.count = V};
    if (set && subset_coincident(m, set, set_count, &E) != VB_OK)
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for receiver frames");
    /* Every receiver: the caller's copy of the normals is oriented in place. */
    float *in_place = normals && !set ? normals : NULL;
    if (in_place)
        memcpy(in_place, m->normals, (size_t)V * 3 * sizeof *in_place);
    frames F;
    vb_result r = frames_create(m, s, &E, in_place, &F, err);
    if (r != VB_OK) {
        subset_free(&E);
        return r;
    }
    uint32_t count = 0, any = 0;
    if (normals) {
        r = orient(m, s, &F, threads, count_begin, count_end, &count, &any, err);
        /* The frames again where they depend on the normals: after any flip,
         * also one of a receiver that is not counted (a shard's neighbour at
         * the same position). */
        if (r == VB_OK && any > 0)
            r = frames_normals(m, &F, err);
        for (uint32_t j = 0; j < set_count && set && r == VB_OK; j++)
            memcpy(normals + 3 * (size_t)j, F.normals + 3 * (size_t)subset_slot(&E, set[j]),
                   3 * sizeof *normals);
        t0 = vb_now(); /* the origins' time, as before: not the orientation's */
    }
    if (r == VB_OK)
        r = place_origins(m, s, &F, threads, set, set_count, count_begin, count_end, out, near_out,
                          stats, t0, err);
    frames_free(&F);
    subset_free(&E);
    if (r == VB_OK && flipped)
        *flipped = count;
    return r;
}
