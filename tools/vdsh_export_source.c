/*
 * vdsh_export_source.c - the source glTF of vdsh-export --source: read it,
 * walk its scene as bake/lib/mesh_gltf.cpp does, map primitive vertices to
 * receivers (vdsh_export_source.h).
 */
#include "vdsh_export_source.h"
#include "vdsh_gltf_component.h"
#include "vdsh_gltf_uri.h"
#include "vdsh_math.h"

#include <errno.h>
#include <fcntl.h>
#include <nettle/sha2.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int fail(char *msg, size_t cap, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, cap, fmt, ap);
    va_end(ap);
    return -1;
}

/* The whole of a regular file; NULL with *why (errno's text, or "not a
 * regular file": a FIFO would block, /dev/zero never end) otherwise. */
static uint8_t *slurp(const char *path, size_t *size, const char **why)
{
    *why = "cannot read it";
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        *why = strerror(errno);
        return NULL;
    }
    struct stat st = {0};
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        *why = S_ISDIR(st.st_mode) ? "is a directory" : "not a regular file";
        close(fd);
        return NULL;
    }
    FILE *fp = fdopen(fd, "rb");
    if (!fp) {
        *why = strerror(errno);
        close(fd);
        return NULL;
    }
    uint8_t *d = NULL;
    if (fseek(fp, 0, SEEK_END) == 0) {
        long n = ftell(fp);
        if (n >= 0 && fseek(fp, 0, SEEK_SET) == 0 && (d = malloc((size_t)n + 1)) != NULL) {
            if (fread(d, 1, (size_t)n, fp) != (size_t)n) {
                free(d);
                d = NULL;
            } else {
                d[n] = 0;
                *size = (size_t)n;
            }
        }
    }
    fclose(fp);
    return d;
}

static int b64(int c)
{
    if (c >= 'A' && c <= 'Z')
        return c - 'A';
    if (c >= 'a' && c <= 'z')
        return c - 'a' + 26;
    if (c >= '0' && c <= '9')
        return c - '0' + 52;
    if (c == '+')
        return 62;
    if (c == '/')
        return 63;
    return -1;
}

/* A data: URI's base64 payload; NULL when it is not base64. */
static uint8_t *data_uri(const char *uri, size_t *size)
{
    const char *comma = strchr(uri, ',');
    if (!comma || comma - uri < 7 || strncmp(comma - 7, ";base64", 7) != 0)
        return NULL;
    const char *p = comma + 1;
    size_t n = strlen(p);
    uint8_t *d = malloc(n / 4 * 3 + 3);
    if (!d)
        return NULL;
    size_t o = 0;
    uint32_t acc = 0;
    int bits = 0;
    for (; *p && *p != '='; p++) {
        int v = b64((unsigned char)*p);
        if (v < 0) {
            free(d);
            return NULL;
        }
        acc = acc << 6 | (uint32_t)v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            d[o++] = (uint8_t)(acc >> bits);
        }
    }
    *size = o;
    return d;
}

char *vdsh_src_file(const vdsh_src *s, const char *uri, const char **why)
{
    size_t n = strlen(uri), d = strlen(s->dir);
    char *p = malloc(d + n + 1);
    if (!p) {
        *why = "out of memory";
        return NULL;
    }
    memcpy(p, s->dir, d);
    if (vdsh_gltf_uri_decode(uri, n, p + d) != strlen(p + d)) {
        *why = "its uri decodes to a NUL byte, which no file name holds";
        free(p);
        return NULL;
    }
    return p;
}

void vdsh_src_free(vdsh_src *s)
{
    cJSON_Delete(s->json);
    for (int i = 0; i < s->buffer_count; i++)
        free(s->buffers[i].data);
    free(s->buffers);
    free(s->dir);
    memset(s, 0, sizeof *s);
}

int vdsh_src_load(const char *path, vdsh_src *s, char *msg, size_t cap)
{
    memset(s, 0, sizeof *s);
    size_t size = 0;
    const char *why = NULL;
    uint8_t *d = slurp(path, &size, &why);
    if (!d)
        return fail(msg, cap, "%s: cannot read the source glTF: %s", path, why);
    const char *slash = strrchr(path, '/');
    s->dir = slash ? strndup(path, (size_t)(slash - path + 1)) : strdup("");
    uint8_t *bin = NULL;
    size_t bin_size = 0;
    int rc = -1;
    uint32_t h[5];
    if (size >= 20 && memcpy(h, d, 20) && h[0] == 0x46546C67u) {
        if (h[1] != 2 || h[2] > size || h[4] != 0x4E4F534Au || h[3] > size - 20) {
            fail(msg, cap, "%s: not a glTF 2.0 binary file (bad header or JSON chunk)", path);
            goto out;
        }
        s->json = cJSON_ParseWithLength((const char *)d + 20, h[3]);
        size_t at = 20 + (size_t)h[3];
        uint32_t bh[2];
        if (at + 8 <= h[2] && memcpy(bh, d + at, 8) && bh[1] == 0x004E4942u &&
            bh[0] <= h[2] - at - 8) {
            bin = d + at + 8;
            bin_size = bh[0];
        }
    } else {
        s->json = cJSON_ParseWithLength((const char *)d, size);
    }
    if (!cJSON_IsObject(s->json)) {
        fail(msg, cap, "%s: not a readable glTF 2.0 file (its JSON does not parse)", path);
        goto out;
    }
    cJSON *bufs = cJSON_GetObjectItemCaseSensitive(s->json, "buffers");
    s->buffer_count = cJSON_GetArraySize(bufs);
    s->buffers = calloc((size_t)s->buffer_count + 1, sizeof *s->buffers);
    if (!s->buffers) {
        fail(msg, cap, "%s: out of memory", path);
        goto out;
    }
    for (int i = 0; i < s->buffer_count; i++) {
        cJSON *b = cJSON_GetArrayItem(bufs, i);
        cJSON *uri = cJSON_GetObjectItemCaseSensitive(b, "uri");
        double want = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(b, "byteLength"));
        vdsh_src_buffer *sb = &s->buffers[i];
        const char *bwhy = "not decoded";
        char *file = NULL;
        if (!cJSON_IsString(uri)) {
            if (i != 0 || !bin) {
                fail(msg, cap, "%s: buffer %d has no uri and is not the glb's BIN chunk", path, i);
                goto out;
            }
            sb->data = malloc(bin_size + 1);
            if (sb->data)
                memcpy(sb->data, bin, bin_size), sb->size = bin_size;
        } else if (strncmp(uri->valuestring, "data:", 5) == 0) {
            sb->data = data_uri(uri->valuestring, &sb->size);
        } else {
            file = vdsh_src_file(s, uri->valuestring, &bwhy);
            if (file)
                sb->data = slurp(file, &sb->size, &bwhy);
        }
        if (!sb->data) {
            /* the file too, as the URI decodes to it ("a%20b+c.bin" is
             * "a b c.bin", tinygltf's rule) */
            if (file)
                fail(msg, cap, "%s: buffer %d (%s) cannot be read: %s: %s", path, i,
                     uri->valuestring, file, bwhy);
            else
                fail(msg, cap, "%s: buffer %d (%s) cannot be read: %s", path, i,
                     cJSON_IsString(uri) ? uri->valuestring : "BIN chunk", bwhy);
            free(file);
            goto out;
        }
        free(file);
        if (!(want >= 0) || want > (double)sb->size) {
            fail(msg, cap, "%s: buffer %d is %zu byte%s, shorter than its byteLength %.0f", path, i,
                 sb->size, sb->size == 1 ? "" : "s", want);
            goto out;
        }
    }
    /* The baker's hashes (bake/lib/mesh_gltf.cpp): the file's bytes alone,
     * and the file's bytes then each external buffer's (not data: URIs,
     * not the BIN chunk), in order; the two are one without an external
     * buffer. */
    struct sha256_ctx file, all;
    sha256_init(&file);
    sha256_update(&file, size, d);
    all = file;
    sha256_digest(&file, SHA256_DIGEST_SIZE, s->file_sha256);
    s->file_size = s->size = size;
    for (int i = 0; i < s->buffer_count; i++) {
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(bufs, i), "uri");
        if (cJSON_IsString(uri) && strncmp(uri->valuestring, "data:", 5) != 0) {
            sha256_update(&all, s->buffers[i].size, s->buffers[i].data);
            s->size += s->buffers[i].size;
        }
    }
    sha256_digest(&all, SHA256_DIGEST_SIZE, s->sha256);
    rc = 0;
out:
    free(d);
    if (rc)
        vdsh_src_free(s);
    return rc;
}

static double num(const cJSON *o, const char *k, double dflt)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, k);
    return cJSON_IsNumber(v) ? v->valuedouble : dflt;
}

/* Bytes [offset, offset + (count - 1) * stride + elem) of buffer view
 * `bv`, checked against the view and its buffer; NULL when they overrun. */
static const uint8_t *view_bytes(const vdsh_src *s, int bv, double offset, size_t count,
                                 size_t elem, size_t stride)
{
    cJSON *v = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(s->json, "bufferViews"), bv);
    int b = (int)num(v, "buffer", -1);
    double vo = num(v, "byteOffset", 0), len = num(v, "byteLength", 0);
    if (!v || bv < 0 || b < 0 || b >= s->buffer_count || !(vo >= 0) || !(len >= 0) ||
        !(offset >= 0) || vo + len > (double)s->buffers[b].size ||
        offset + (double)(count - 1) * (double)stride + (double)elem > len)
        return NULL;
    return s->buffers[b].data + (size_t)vo + (size_t)offset;
}

/* A VEC3 accessor as 3 * count doubles, its sparse values applied (as
 * mesh_gltf.cpp reads it). */
static double *read_vec3(const char *path, const vdsh_src *s, int ai, size_t *count, char *msg,
                         size_t cap)
{
    cJSON *a = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(s->json, "accessors"), ai);
    if (!a || ai < 0) {
        fail(msg, cap, "%s: accessor %d does not exist", path, ai);
        return NULL;
    }
    const cJSON *ty = cJSON_GetObjectItemCaseSensitive(a, "type");
    int ct = (int)num(a, "componentType", 0), bv = (int)num(a, "bufferView", -1);
    size_t n = (size_t)num(a, "count", 0), cs = vdsh_gltf_component_size(ct);
    if (!cJSON_IsString(ty) || strcmp(ty->valuestring, "VEC3") != 0 || !cs) {
        fail(msg, cap, "%s: accessor %d is not a VEC3 of a known component type", path, ai);
        return NULL;
    }
    int normalized = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(a, "normalized"));
    double *out = calloc(3 * n + 1, sizeof *out);
    if (!out) {
        fail(msg, cap, "%s: out of memory", path);
        return NULL;
    }
    const size_t elem = 3 * cs;
    if (bv >= 0 && n) {
        cJSON *v = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(s->json, "bufferViews"), bv);
        size_t stride = (size_t)num(v, "byteStride", 0);
        if (!stride)
            stride = elem;
        const uint8_t *p = view_bytes(s, bv, num(a, "byteOffset", 0), n, elem, stride);
        if (!p) {
            free(out);
            fail(msg, cap, "%s: accessor %d overruns its buffer view", path, ai);
            return NULL;
        }
        for (size_t i = 0; i < n; i++)
            for (size_t c = 0; c < 3; c++)
                out[3 * i + c] = vdsh_gltf_component(p + i * stride + c * cs, ct, normalized);
    }
    const cJSON *sp = cJSON_GetObjectItemCaseSensitive(a, "sparse");
    if (sp) {
        const cJSON *si = cJSON_GetObjectItemCaseSensitive(sp, "indices");
        const cJSON *sv = cJSON_GetObjectItemCaseSensitive(sp, "values");
        size_t sc = (size_t)num(sp, "count", 0);
        int ict = (int)num(si, "componentType", 0);
        size_t ics = vdsh_gltf_component_size(ict);
        const uint8_t *pi = NULL, *pv = NULL;
        if (sc >= 1 && sc <= n && (ict == 5121 || ict == 5123 || ict == 5125)) {
            pi = view_bytes(s, (int)num(si, "bufferView", -1), num(si, "byteOffset", 0), sc, ics,
                            ics);
            pv = view_bytes(s, (int)num(sv, "bufferView", -1), num(sv, "byteOffset", 0), sc, elem,
                            elem);
        }
        if (!pi || !pv) {
            free(out);
            fail(msg, cap, "%s: accessor %d: bad sparse indices or values", path, ai);
            return NULL;
        }
        for (size_t k = 0; k < sc; k++) {
            double di = vdsh_gltf_component(pi + k * ics, ict, 0);
            if (!(di < (double)n)) {
                free(out);
                fail(msg, cap, "%s: accessor %d: sparse index %.0f out of range (%zu)", path, ai,
                     di, n);
                return NULL;
            }
            for (size_t c = 0; c < 3; c++)
                out[3 * (size_t)di + c] =
                    vdsh_gltf_component(pv + k * elem + c * cs, ct, normalized);
        }
    }
    *count = n;
    return out;
}

typedef double mat4[16];

/* mesh_gltf.cpp's node_matrix, the same operations in the same order. */
static void node_matrix(const cJSON *n, double *m)
{
    static const double id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    memcpy(m, id, sizeof id);
    const cJSON *mx = cJSON_GetObjectItemCaseSensitive(n, "matrix");
    if (cJSON_GetArraySize(mx) == 16) {
        for (int i = 0; i < 16; i++)
            m[i] = cJSON_GetNumberValue(cJSON_GetArrayItem(mx, i));
        return;
    }
    double t[3], q[4], s[3];
    const cJSON *tr = cJSON_GetObjectItemCaseSensitive(n, "translation");
    const cJSON *ro = cJSON_GetObjectItemCaseSensitive(n, "rotation");
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(n, "scale");
    for (int k = 0; k < 3; k++) {
        t[k] = cJSON_GetNumberValue(cJSON_GetArrayItem(tr, k));
        s[k] = cJSON_GetNumberValue(cJSON_GetArrayItem(sc, k));
    }
    for (int k = 0; k < 4; k++)
        q[k] = cJSON_GetNumberValue(cJSON_GetArrayItem(ro, k));
    vdsh_mat4d_trs(cJSON_GetArraySize(tr) == 3 ? t : NULL, cJSON_GetArraySize(ro) == 4 ? q : NULL,
                   cJSON_GetArraySize(sc) == 3 ? s : NULL, m);
}

typedef struct walk {
    const char *path;
    vdsh_src *s;
    const float *pos, *nrm;
    uint32_t nv, *head, *next, hash_mask;
    uint8_t *used;
    vdsh_src_prim *prims;
    int count, cap;
    char *msg;
    size_t cap_msg;
} walk;

static uint32_t pos_hash(const float *p)
{
    uint32_t h = 2166136261u, b[3];
    for (int k = 0; k < 3; k++) {
        float v = p[k] == 0 ? 0.0f : p[k]; /* -0 and +0 alike */
        memcpy(&b[k], &v, 4);
        h = (h ^ b[k]) * 16777619u;
        h ^= h >> 15;
    }
    return h;
}

static int map_prim(walk *w, int node, int mesh, int pi, const cJSON *prim, const double *m)
{
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    const cJSON *pa = cJSON_GetObjectItemCaseSensitive(attrs, "POSITION");
    const cJSON *na = cJSON_GetObjectItemCaseSensitive(attrs, "NORMAL");
    if (!cJSON_IsNumber(pa))
        return fail(w->msg, w->cap_msg, "%s: a triangle primitive has no POSITION", w->path);
    size_t n = 0, nn = 0;
    double *pos = read_vec3(w->path, w->s, (int)pa->valuedouble, &n, w->msg, w->cap_msg),
           *nrm = NULL;
    if (!pos)
        return -1;
    if (cJSON_IsNumber(na) &&
        !(nrm = read_vec3(w->path, w->s, (int)na->valuedouble, &nn, w->msg, w->cap_msg))) {
        free(pos);
        return -1;
    }
    if (nrm && nn != n) {
        free(nrm);
        nrm = NULL;
    }
    if (w->count == w->cap) {
        int c = w->cap ? 2 * w->cap : 16;
        vdsh_src_prim *p = realloc(w->prims, (size_t)c * sizeof *p);
        if (!p) {
            free(pos), free(nrm);
            return fail(w->msg, w->cap_msg, "%s: out of memory", w->path);
        }
        w->prims = p, w->cap = c;
    }
    vdsh_src_prim *sp = &w->prims[w->count++];
    *sp = (vdsh_src_prim){node, mesh, pi, (uint32_t)n, 0, malloc(n * sizeof(uint32_t) + 4)};
    if (!sp->map) {
        free(pos), free(nrm);
        return fail(w->msg, w->cap_msg, "%s: out of memory", w->path);
    }
    /* mesh_gltf.cpp's world position and normal (cofactor matrix) */
    const double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6],
                 k = m[10];
    const double cof[9] = {e * k - f * h,    -(d * k - f * g), d * h - e * g,
                           -(b * k - c * h), a * k - c * g,    -(a * h - b * g),
                           b * f - c * e,    -(a * f - c * d), a * e - b * d};
    for (size_t i = 0; i < n; i++) {
        const double *q = &pos[3 * i];
        float p[3], nv[3] = {0, 0, 0};
        for (int r = 0; r < 3; r++)
            p[r] = (float)(m[r] * q[0] + m[4 + r] * q[1] + m[8 + r] * q[2] + m[12 + r]);
        if (nrm) {
            const double *nq = &nrm[3 * i];
            double t[3];
            for (int r = 0; r < 3; r++)
                t[r] = cof[3 * r] * nq[0] + cof[3 * r + 1] * nq[1] + cof[3 * r + 2] * nq[2];
            vdsh_unit3d_to_f(t, nv);
        }
        /* the receivers at this exact position: the closest normal, an
         * unused one first among equals (duplicated vertices in order) */
        uint32_t best = UINT32_MAX;
        double best_dot = -INFINITY;
        for (uint32_t r = w->head[pos_hash(p) & w->hash_mask]; r != UINT32_MAX; r = w->next[r]) {
            const float *rp = w->pos + 3 * (size_t)r;
            if (rp[0] != p[0] || rp[1] != p[1] || rp[2] != p[2])
                continue;
            const float *rn = w->nrm + 3 * (size_t)r;
            double dot = (double)rn[0] * nv[0] + (double)rn[1] * nv[1] + (double)rn[2] * nv[2];
            dot -= w->used[r] ? 1e-3 : 0;
            if (dot > best_dot)
                best_dot = dot, best = r;
        }
        sp->map[i] = best;
        if (best != UINT32_MAX) {
            w->used[best] = 1;
            sp->matched++;
        }
    }
    free(pos), free(nrm);
    return 0;
}

static int visit(walk *w, int node, const double *parent, uint8_t *on_path, int depth)
{
    cJSON *nodes = cJSON_GetObjectItemCaseSensitive(w->s->json, "nodes");
    cJSON *n = cJSON_GetArrayItem(nodes, node);
    if (!n || node < 0)
        return fail(w->msg, w->cap_msg, "%s: node %d does not exist", w->path, node);
    if (on_path[node])
        return fail(w->msg, w->cap_msg, "%s: node %d is its own ancestor", w->path, node);
    if (depth > 1000)
        return fail(w->msg, w->cap_msg, "%s: node %d: the node tree is deeper than 1000 levels",
                    w->path, node);
    on_path[node] = 1;
    double local[16], m[16];
    node_matrix(n, local);
    vdsh_mat4d_mul(parent, local, m);
    int mesh = (int)num(n, "mesh", -1);
    if (mesh >= 0 &&
        cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(n, "extensions"),
                                         "EXT_mesh_gpu_instancing"))
        return fail(w->msg, w->cap_msg,
                    "%s: node %d draws its mesh as instances (EXT_mesh_gpu_instancing), which "
                    "share their VDSH attributes: --source cannot give each its own shadows "
                    "(export without --source)",
                    w->path, node);
    if (mesh >= 0) {
        /* a skinned node's mesh in its bind pose, as the baker reads it
         * (bake/lib/mesh_gltf.cpp): POSITION as stored, the node's own
         * transform ignored (glTF spec) */
        static const double bind[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        const double *pm = cJSON_GetObjectItemCaseSensitive(n, "skin") ? bind : m;
        cJSON *me =
            cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(w->s->json, "meshes"), mesh);
        if (!me)
            return fail(w->msg, w->cap_msg, "%s: node %d: mesh %d does not exist", w->path, node,
                        mesh);
        cJSON *prims = cJSON_GetObjectItemCaseSensitive(me, "primitives");
        for (int pi = 0; pi < cJSON_GetArraySize(prims); pi++) {
            cJSON *p = cJSON_GetArrayItem(prims, pi);
            int mode = (int)num(p, "mode", 4);
            if (mode < 4 || mode > 6)
                continue; /* skipped by the baker too; morph targets: the base pose */
            if (map_prim(w, node, mesh, pi, p, pm))
                return -1;
        }
    }
    cJSON *ch;
    cJSON_ArrayForEach(ch, cJSON_GetObjectItemCaseSensitive(
                               n, "children")) if (visit(w, (int)cJSON_GetNumberValue(ch), m,
                                                         on_path, depth + 1)) return -1;
    on_path[node] = 0;
    return 0;
}

int vdsh_src_map(const char *path, vdsh_src *s, const float *positions, const float *normals,
                 uint32_t nv, vdsh_src_prim **prims, int *prim_count, char *msg, size_t cap)
{
    walk w = {path, s, positions, normals, nv, NULL, NULL, 0, NULL, NULL, 0, 0, msg, cap};
    uint32_t hs = 1;
    while (hs < 2 * nv)
        hs *= 2;
    w.hash_mask = hs - 1;
    int nn = cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(s->json, "nodes"));
    w.head = malloc(hs * sizeof(uint32_t));
    w.next = malloc((size_t)nv * sizeof(uint32_t) + 4);
    w.used = calloc((size_t)nv + 1, 1);
    uint8_t *on_path = calloc((size_t)nn + 1, 1);
    int rc = -1;
    if (!w.head || !w.next || !w.used || !on_path) {
        fail(msg, cap, "%s: out of memory", path);
        goto out;
    }
    memset(w.head, 0xff, hs * sizeof(uint32_t));
    for (uint32_t r = nv; r-- > 0;) { /* lists in receiver order */
        uint32_t h = pos_hash(positions + 3 * (size_t)r) & w.hash_mask;
        w.next[r] = w.head[h];
        w.head[h] = r;
    }
    cJSON *scenes = cJSON_GetObjectItemCaseSensitive(s->json, "scenes");
    int sc = (int)num(s->json, "scene", 0);
    cJSON *scene = cJSON_GetArrayItem(scenes, sc);
    if (!scene) {
        fail(msg, cap, "%s: no scene", path);
        goto out;
    }
    static const double id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    cJSON *ni;
    cJSON_ArrayForEach(ni, cJSON_GetObjectItemCaseSensitive(
                               scene, "nodes")) if (visit(&w, (int)cJSON_GetNumberValue(ni), id,
                                                          on_path, 0)) goto out;
    rc = 0;
out:
    free(w.head), free(w.next), free(w.used), free(on_path);
    if (rc) {
        for (int i = 0; i < w.count; i++)
            free(w.prims[i].map);
        free(w.prims);
    } else {
        *prims = w.prims;
        *prim_count = w.count;
    }
    return rc;
}
