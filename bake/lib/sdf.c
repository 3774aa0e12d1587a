/*
 * sdf.c - the signed distance volume (sdf.h).
 */
#include "sdf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "parallel.h"
#include "vdsh_light.h"

static double dot3d(const double u[3], const double v[3])
{
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
}

/* The dot products of ab and of ac with p - x. */
static void dots_from(const double p[3], const double x[3], const double ab[3], const double ac[3],
                      double *with_ab, double *with_ac)
{
    double xp[3];
    for (int i = 0; i < 3; i++)
        xp[i] = p[i] - x[i];
    *with_ab = dot3d(ab, xp), *with_ac = dot3d(ac, xp);
}

/* |p - q|^2. */
static double dist2(const double p[3], const double q[3])
{
    double e[3];
    for (int i = 0; i < 3; i++)
        e[i] = p[i] - q[i];
    return dot3d(e, e);
}

/* |p - (x + t e)|^2. */
static double dist2_along(const double p[3], const double x[3], double t, const double e[3])
{
    double q[3];
    for (int i = 0; i < 3; i++)
        q[i] = x[i] + t * e[i];
    return dist2(p, q);
}

/* Squared distance from p to triangle abc (Ericson 5.1.5: the Voronoi
 * region of the closest feature, then the point on it). */
static double tri_dist2(const double p[3], const double a[3], const double b[3], const double c[3])
{
    double ab[3], ac[3], bc[3];
    for (int i = 0; i < 3; i++)
        ab[i] = b[i] - a[i], ac[i] = c[i] - a[i], bc[i] = c[i] - b[i];
    double d1, d2, d3, d4, d5, d6;
    dots_from(p, a, ab, ac, &d1, &d2);
    dots_from(p, b, ab, ac, &d3, &d4);
    dots_from(p, c, ab, ac, &d5, &d6);
    double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
    if (d1 <= 0.0 && d2 <= 0.0)
        return dist2(p, a);
    if (d3 >= 0.0 && d4 <= d3)
        return dist2(p, b);
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
        return dist2_along(p, a, d1 / (d1 - d3), ab);
    if (d6 >= 0.0 && d5 <= d6)
        return dist2(p, c);
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
        return dist2_along(p, a, d2 / (d2 - d6), ac);
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return dist2_along(p, b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), bc);
    double den = va + vb + vc;
    if (!(den > 0.0)) { /* no area: the nearest of the three corners */
        double da = dist2(p, a), db = dist2(p, b), dc = dist2(p, c);
        double best = da < INFINITY ? da : INFINITY;
        best = db < best ? db : best;
        return dc < best ? dc : best;
    }
    double v = vb / den, w = vc / den, q[3];
    for (int i = 0; i < 3; i++)
        q[i] = a[i] + ab[i] * v + ac[i] * w;
    return dist2(p, q);
}

typedef struct job {
    const vb_scene *s;
    const float *local; /* occluder vertices, traced frame */
    const uint32_t *indices;
    vdsh_sdf *v;
    float dirs[VDSH_FREE_PROBES][3];
} job;

typedef struct query {
    const job *J;
    double p[3];
    double best2;
} query;

static bool on_triangle(struct RTCPointQueryFunctionArguments *args)
{
    query *q = args->userPtr;
    const uint32_t *t = q->J->indices + 3 * (size_t)args->primID;
    double v[3][3];
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++)
            v[k][i] = q->J->local[3 * (size_t)t[k] + i];
    double d2 = tri_dist2(q->p, v[0], v[1], v[2]);
    if (!(d2 < q->best2))
        return false;
    q->best2 = d2;
    /* Rounded up, so no triangle nearer than the true minimum is pruned. */
    float r = nextafterf((float)sqrt(d2), INFINITY);
    if (r < args->query->radius) {
        args->query->radius = r;
        return true;
    }
    return false;
}

static float sample_at(const job *J, uint32_t i, uint32_t j, uint32_t k)
{
    const vdsh_sdf *v = J->v;
    float p[3] = {v->origin[0] + v->cell * (float)i, v->origin[1] + v->cell * (float)j,
                  v->origin[2] + v->cell * (float)k};
    float o[3];
    vb_scene_to_local(J->s, p, o);
    query q = {.J = J, .p = {o[0], o[1], o[2]}, .best2 = INFINITY};
    struct RTCPointQuery pq = {.x = o[0], .y = o[1], .z = o[2], .time = 0.0f, .radius = INFINITY};
    struct RTCPointQueryContext ctx;
    rtcInitPointQueryContext(&ctx);
    rtcPointQuery(J->s->scene, &pq, &ctx, on_triangle, &q);
    float d = (float)(sqrt(q.best2) / (double)J->s->scale);

    /* The sign: the probes' first hits, front against back. */
    int front = 0, back = 0;
    struct RTCIntersectContext ic;
    rtcInitIntersectContext(&ic);
    for (int r = 0; r < VDSH_FREE_PROBES; r++) {
        struct RTCRayHit rh;
        vb_ray_init(&rh, o, J->dirs[r], INFINITY, 0);
        rtcIntersect1(J->s->scene, &ic, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
            continue;
        if (rh.hit.Ng_x * J->dirs[r][0] + rh.hit.Ng_y * J->dirs[r][1] +
                rh.hit.Ng_z * J->dirs[r][2] >
            0.0f)
            back++;
        else
            front++;
    }
    return back > front ? -d : d;
}

static void bake_rows(void *ctx, uint32_t begin, uint32_t end, unsigned worker)
{
    (void)worker;
    const job *J = ctx;
    vdsh_sdf *v = J->v;
    for (uint32_t row = begin; row < end; row++) { /* row = j + k * ny */
        uint32_t j = row % v->dim[1], k = row / v->dim[1];
        uint16_t *out = v->samples + (size_t)row * v->dim[0];
        for (uint32_t i = 0; i < v->dim[0]; i++)
            out[i] = vdsh_sdf_encode(sample_at(J, i, j, k), v->max_distance);
    }
}

vb_result vb_sdf_bake(const vb_scene *s, const vb_mesh *occluders, int resolution, unsigned threads,
                      vdsh_sdf *out, vb_error *err)
{
    if (resolution < VB_SDF_MIN_RESOLUTION || resolution > VB_SDF_MAX_RESOLUTION)
        return vb_fail(err, VB_ERR_ARGUMENT, "distance volume resolution %d is not %d..%d",
                       resolution, VB_SDF_MIN_RESOLUTION, VB_SDF_MAX_RESOLUTION);
    if (!occluders->triangle_count)
        return vb_fail(err, VB_ERR_ARGUMENT, "no occluder triangles for a distance volume");
    vdsh_sdf v = {0};
    float ext[3], longest = 0.0f, d2 = 0.0f;
    for (int a = 0; a < 3; a++) {
        ext[a] = s->bounds_max[a] - s->bounds_min[a];
        longest = ext[a] > longest ? ext[a] : longest;
        d2 += ext[a] * ext[a];
    }
    if (!(longest > 0.0f))
        return vb_fail(err, VB_ERR_ARGUMENT, "the occluders have no extent");
    v.cell = longest / (float)resolution;
    v.max_distance = sqrtf(d2);
    for (int a = 0; a < 3; a++) {
        /* Samples over the bounds and one spacing beyond each side. */
        float n = ceilf(ext[a] / v.cell) + 3.0f;
        v.dim[a] = n > VDSH_SDF_MAX_DIM ? VDSH_SDF_MAX_DIM : (uint32_t)n;
        float centre = 0.5f * (s->bounds_min[a] + s->bounds_max[a]);
        v.origin[a] = centre - 0.5f * v.cell * (float)(v.dim[a] - 1);
    }
    size_t n = (size_t)v.dim[0] * v.dim[1] * v.dim[2];
    v.samples = malloc(n * sizeof *v.samples);
    float *local = malloc((size_t)occluders->vertex_count * 3 * sizeof *local);
    if (!v.samples || !local) {
        free(v.samples);
        free(local);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "out of memory for a %u x %u x %u volume",
                       v.dim[0], v.dim[1], v.dim[2]);
    }
    for (uint32_t i = 0; i < occluders->vertex_count; i++)
        vb_scene_to_local(s, occluders->positions + 3 * (size_t)i, local + 3 * (size_t)i);
    job J = {.s = s, .local = local, .indices = occluders->indices, .v = &v};
    vdsh_free_probe_dirs(J.dirs);
    /* Turned by a fixed rotation of no special angle (the unit quaternion
     * (0.5, 0.3, 0.5, 0.7) / |.|, plain float arithmetic): the probes'
     * own axes and diagonals would run along the walls and through the
     * corners of axis-aligned scenes from the grid's samples, where a ray
     * that grazes an edge is met or missed by one Embree kernel and not
     * another. */
    {
        float w = 0.5f, x = 0.3f, y = 0.5f, z = 0.7f;
        float q = 1.0f / sqrtf(w * w + x * x + y * y + z * z);
        w *= q, x *= q, y *= q, z *= q;
        const float R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                               {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                               {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
        for (int r = 0; r < VDSH_FREE_PROBES; r++) {
            float d[3];
            for (int a = 0; a < 3; a++)
                d[a] = R[a][0] * J.dirs[r][0] + R[a][1] * J.dirs[r][1] + R[a][2] * J.dirs[r][2];
            memcpy(J.dirs[r], d, sizeof d);
        }
    }
    unsigned ran = vb_parallel_for(threads, v.dim[1] * v.dim[2], 4, bake_rows, &J, NULL, NULL);
    free(local);
    if (!ran) {
        free(v.samples);
        return vb_fail(err, VB_ERR_OUT_OF_MEMORY, "cannot start worker threads");
    }
    *out = v;
    return VB_OK;
}
