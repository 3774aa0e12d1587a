/*
 * vdsh_check.c - the value checks of VDSH.md "Reading rules", on decoded
 * structs: the reader applies them to the file's bytes (VDSH_ERR_INVALID)
 * and the writer to the caller's vdsh_file (VDSH_ERR_ARGUMENT), so the
 * writer cannot produce a file that the reader rejects.
 */
#include "vdsh_internal.h"

#include <math.h>
#include <stdio.h>

/* ------------------------------------------------------------------ */
/* Value checks shared by the reader and the writer                   */
/* ------------------------------------------------------------------ */

/* Each returns 1 when the value is acceptable, else 0 with a description
 * in *w. The reader calls them on decoded fields, the writer on the
 * caller's struct: one set of rules, so a written file always reads. */

int vdsh_check_header(const vdsh_header *h, why *w)
{
    if (h->vertex_count < 1 || h->vertex_count > VDSH_MAX_VERTICES)
        return vdsh_bad(w, "HEAD: vertex_count %u out of range 1..%u", h->vertex_count,
                        VDSH_MAX_VERTICES);
    if (h->triangle_count > VDSH_MAX_TRIANGLES)
        return vdsh_bad(w, "HEAD: triangle_count %u out of range 0..%u", h->triangle_count,
                        VDSH_MAX_TRIANGLES);
    if (h->rays < 1)
        return vdsh_bad(w, "HEAD: rays is 0, must be at least 1");
    if (h->sampling > VDSH_SAMPLING_HEMISPHERE)
        return vdsh_bad(w, "HEAD: sampling %u unknown (0 sphere, 1 hemisphere)", h->sampling);
    if (!isfinite(h->max_distance) || !(h->max_distance > 0.0f))
        return vdsh_bad(w, "HEAD: max_distance %g must be finite and > 0", (double)h->max_distance);
    if (!isfinite(h->max_edge) || !(h->max_edge >= 0.0f))
        return vdsh_bad(w, "HEAD: max_edge %g must be finite and >= 0", (double)h->max_edge);
    if (h->offset_rule > VDSH_OFFSET_WB_AVG)
        return vdsh_bad(w, "HEAD: offset_rule %u unknown (0 none, 1 wb-avg)", h->offset_rule);
    if (h->load_flags & ~(uint32_t)(VDSH_LOAD_WELD | VDSH_LOAD_UP_MASK | VDSH_LOAD_CREASE_MASK))
        return vdsh_bad(w, "HEAD: load_flags 0x%x has unknown bits", h->load_flags);
    if ((h->load_flags & VDSH_LOAD_UP_MASK) >> VDSH_LOAD_UP_SHIFT >= VDSH_UP_AXES)
        return vdsh_bad(w, "HEAD: load_flags 0x%x: up axis %u unknown (0..%d)", h->load_flags,
                        (h->load_flags & VDSH_LOAD_UP_MASK) >> VDSH_LOAD_UP_SHIFT,
                        VDSH_UP_AXES - 1);
    if (VDSH_LOAD_CREASE(h->load_flags) >= 180)
        return vdsh_bad(w, "HEAD: load_flags 0x%x: crease angle %u degrees (1..179, or 0)",
                        h->load_flags, VDSH_LOAD_CREASE(h->load_flags));
    if (h->trace_flags & ~(uint32_t)VDSH_TRACE_ROBUST)
        return vdsh_bad(w, "HEAD: trace_flags 0x%x has unknown bits", h->trace_flags);
    for (int k = 0; k < 3; k++) {
        if (!isfinite(h->bounds_min[k]) || !isfinite(h->bounds_max[k]))
            return vdsh_bad(w, "HEAD: bounds axis %d (%g .. %g) not finite", k,
                            (double)h->bounds_min[k], (double)h->bounds_max[k]);
        if (h->bounds_min[k] > h->bounds_max[k])
            return vdsh_bad(w, "HEAD: bounds_min[%d] %g > bounds_max[%d] %g", k,
                            (double)h->bounds_min[k], k, (double)h->bounds_max[k]);
    }
    return 1;
}

/* Largest |x| bit pattern of n floats; >= 0x7f800000 means one is Inf or
 * NaN. One pass that vectorises, so the common all-good case is cheap; the
 * slow search for the culprit only runs to word a message. */
static uint32_t max_abs_bits_f32(const float *a, size_t n)
{
    uint32_t m = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, a + i, sizeof u);
        u &= 0x7fffffffu;
        m = u > m ? u : m;
    }
    return m;
}

static size_t first_nonfinite_f32(const float *a, size_t n)
{
    size_t i = 0;
    while (i < n && isfinite(a[i]))
        i++;
    return i;
}

int vdsh_check_positions(const float *p, uint32_t v, why *w)
{
    size_t n = (size_t)v * 3;
    if (max_abs_bits_f32(p, n) >= 0x7f800000u) {
        size_t i = first_nonfinite_f32(p, n);
        return vdsh_bad(w, "POSN: vertex %zu has a non-finite coordinate (%g)", i / 3,
                        (double)p[i]);
    }
    return 1;
}

int vdsh_check_normals(const float *nrm, uint32_t v, why *w)
{
    size_t n = (size_t)v * 3;
    if (max_abs_bits_f32(nrm, n) >= 0x7f800000u) {
        size_t i = first_nonfinite_f32(nrm, n);
        return vdsh_bad(w,
                        "NORM: normal of vertex %zu has a non-finite component "
                        "(%g)",
                        i / 3, (double)nrm[i]);
    }
    /* |len - 1| < 1e-3 without a square root: compare len^2 against the
     * squared bounds, in double so float rounding cannot move the edge. */
    const double lo = (1.0 - 1e-3) * (1.0 - 1e-3);
    const double hi = (1.0 + 1e-3) * (1.0 + 1e-3);
    for (size_t i = 0; i < v; i++) {
        const float *q = nrm + 3 * i;
        double l2 = (double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2];
        if (!(l2 > lo && l2 < hi) && !(q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f))
            return vdsh_bad(w,
                            "NORM: normal of vertex %zu (%g, %g, %g) has length "
                            "%g; must be 1 within 1e-3, or exactly (0, 0, 0)",
                            i, (double)q[0], (double)q[1], (double)q[2], sqrt(l2));
    }
    return 1;
}

int vdsh_check_indices(const uint32_t *idx, uint32_t t, uint32_t v, why *w)
{
    size_t n = (size_t)t * 3;
    uint32_t m = 0;
    for (size_t i = 0; i < n; i++)
        m = idx[i] > m ? idx[i] : m;
    if (n && m >= v) {
        size_t i = 0;
        while (idx[i] < v)
            i++;
        return vdsh_bad(w,
                        "TRIS: index %u out of range (%u vert%s) in "
                        "triangle %zu",
                        idx[i], v, v == 1 ? "ex" : "ices", i / 3);
    }
    return 1;
}

/* Offset of the first byte that breaks strict UTF-8 (no overlong forms,
 * no surrogates, nothing above U+10FFFF), or n when all is well. */
static size_t utf8_error_at(const uint8_t *s, size_t n)
{
    size_t i = 0;
    while (i < n) {
        uint32_t c = s[i], cp, min;
        size_t len;
        if (c < 0x80) {
            i++;
            continue;
        } else if ((c & 0xe0) == 0xc0) {
            len = 2, cp = c & 0x1f, min = 0x80;
        } else if ((c & 0xf0) == 0xe0) {
            len = 3, cp = c & 0x0f, min = 0x800;
        } else if ((c & 0xf8) == 0xf0) {
            len = 4, cp = c & 0x07, min = 0x10000;
        } else {
            return i;
        }
        if (len > n - i)
            return i;
        for (size_t k = 1; k < len; k++) {
            if ((s[i + k] & 0xc0) != 0x80)
                return i;
            cp = cp << 6 | (s[i + k] & 0x3fu);
        }
        if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
            return i;
        i += len;
    }
    return n;
}

int vdsh_check_name(const uint8_t *name, size_t len, uint32_t i, why *w)
{
    if (len < 1 || len > VDSH_MAX_NAME)
        return vdsh_bad(w, "SRCS: source %u: name length %zu out of range 1..%d", i, len,
                        VDSH_MAX_NAME);
    if (memchr(name, 0, len))
        return vdsh_bad(w, "SRCS: source %u: name contains a NUL byte", i);
    size_t at = utf8_error_at(name, len);
    if (at != len)
        return vdsh_bad(w, "SRCS: source %u: name is not valid UTF-8 (byte %zu)", i, at);
    return 1;
}

int vdsh_source_name_ok(const char *name, char *why_out, size_t n)
{
    why w = {{0}};
    if (vdsh_check_name((const uint8_t *)name, strlen(name), 0, &w))
        return 1;
    /* "SRCS: source 0: name is not ..." as "is not ..." */
    const char *m = strstr(w.msg, "name ");
    if (why_out && n)
        snprintf(why_out, n, "%s", m ? m + 5 : w.msg);
    return 0;
}

/* One fixed-order stream per (order, quantity), one variable-order
 * stream per quantity. */
int vdsh_same_slot(const vdsh_stream *a, const vdsh_stream *b)
{
    return a->quantity == b->quantity && a->flags == b->flags &&
           (vdsh_stream_variable(a) || a->order == b->order);
}

/* "order 5 distance", "variable-order log-distance": a stream's slot. */
const char *vdsh_slot_name(const vdsh_stream *s, char *buf, size_t n)
{
    if (vdsh_stream_variable(s))
        snprintf(buf, n, "variable-order %s", vdsh_quantity_name(s->quantity));
    else
        snprintf(buf, n, "order %u %s", s->order, vdsh_quantity_name(s->quantity));
    return buf;
}

/* "COEF order 5 distance": how messages name a stream. */
void vdsh_stream_label(const vdsh_stream *s, uint32_t i, char *buf, size_t n)
{
    snprintf(buf, n, "COEF stream %u (order %s%u, %s)", i, vdsh_stream_variable(s) ? "up to " : "",
             s->order, vdsh_quantity_name(s->quantity));
}

int vdsh_check_stream(const vdsh_stream *s, uint32_t i, why *w)
{
    char l[96];
    vdsh_stream_label(s, i, l, sizeof l);
    if (s->order < 1 || s->order > VDSH_MAX_ORDER)
        return vdsh_bad(w, "%s: order %u out of range 1..%d", l, s->order, VDSH_MAX_ORDER);
    if (s->encoding > VDSH_ENCODING_LAST)
        return vdsh_bad(w, "%s: encoding %u unknown (0 f32, 1 f16, 2 s8, 3 s8s6, 4 cpca)", l,
                        s->encoding);
    if (s->flags & ~VDSH_STREAM_VARIABLE)
        return vdsh_bad(w, "%s: flags 0x%x: unknown bits (bit 0: variable order)", l, s->flags);
    /* Any method value is allowed: later bakers add methods, and the
     * coefficients still reconstruct `quantity` (VDSH.md, "Methods"). */
    if (s->quantity > VDSH_QUANTITY_LOG_DISTANCE)
        return vdsh_bad(w,
                        "%s: quantity %u unknown (0 distance, 1 distance2, "
                        "2 log-distance)",
                        l, s->quantity);
    if (s->window > VDSH_WINDOW_LANCZOS)
        return vdsh_bad(w, "%s: window %u unknown (0 none, 1 hann, 2 lanczos)", l, s->window);
    if (!isfinite(s->window_param))
        return vdsh_bad(w, "%s: window_param %g not finite", l, (double)s->window_param);
    if (s->window == VDSH_WINDOW_NONE && s->window_param != 0.0f)
        return vdsh_bad(w, "%s: window_param %g must be 0 without a window", l,
                        (double)s->window_param);
    if (s->window != VDSH_WINDOW_NONE && !(s->window_param > 0.0f))
        return vdsh_bad(w, "%s: window_param %g must be > 0 with a window", l,
                        (double)s->window_param);
    if (!isfinite(s->method_param))
        return vdsh_bad(w, "%s: method_param %g not finite", l, (double)s->method_param);
    if (!isfinite(s->scale) || !(s->scale > 0.0f))
        return vdsh_bad(w, "%s: scale %g must be finite and > 0", l, (double)s->scale);
    if (vdsh_encoding_quantised(s->encoding) && s->scale != 1.0f)
        return vdsh_bad(w, "%s: scale %g must be 1 for %s (its scale table scales)", l,
                        (double)s->scale, vdsh_encoding_name(s->encoding));
    if (s->encoding == VDSH_ENCODING_CPCA) {
        const vdsh_cpca *m = &s->cpca;
        if (s->scale != 1.0f)
            return vdsh_bad(w, "%s: scale %g must be 1 for cpca", l, (double)s->scale);
        if (vdsh_stream_variable(s))
            return vdsh_bad(w, "%s: cpca streams cannot have variable order", l);
        if (m->clusters < 1 || m->clusters > VDSH_CPCA_MAX_CLUSTERS)
            return vdsh_bad(w, "%s: cpca clusters %u out of range 1..%d", l, m->clusters,
                            VDSH_CPCA_MAX_CLUSTERS);
        if (m->basis < 1 || m->basis > s->order * s->order)
            return vdsh_bad(w, "%s: cpca basis %u out of range 1..%u", l, m->basis,
                            s->order * s->order);
        if (m->bits && (m->bits < VDSH_CPCA_MIN_BITS || m->bits > VDSH_CPCA_MAX_BITS))
            return vdsh_bad(w, "%s: cpca bits %u out of range %d..%d (or 0: a width per vector)", l,
                            m->bits, VDSH_CPCA_MIN_BITS, VDSH_CPCA_MAX_BITS);
        if (!m->bits) {
            if (!m->widths)
                return vdsh_bad(w, "%s: cpca bits 0 without a widths table", l);
            for (uint32_t j = 0; j < m->basis; j++)
                if (m->widths[j] < VDSH_CPCA_MIN_BITS || m->widths[j] > VDSH_CPCA_MAX_BITS)
                    return vdsh_bad(w, "%s: cpca width of vector %u is %u, out of range %d..%d", l,
                                    j, m->widths[j], VDSH_CPCA_MIN_BITS, VDSH_CPCA_MAX_BITS);
            if (m->record_words != vdsh_cpca_widths_words(m->widths, m->basis))
                return vdsh_bad(w, "%s: cpca record_words %u, its widths need %u", l,
                                m->record_words, vdsh_cpca_widths_words(m->widths, m->basis));
        } else if (m->record_words != vdsh_cpca_record_words(m->basis, m->bits))
            return vdsh_bad(w, "%s: cpca record_words %u, %u weights of %u bits need %u", l,
                            m->record_words, m->basis, m->bits,
                            vdsh_cpca_record_words(m->basis, m->bits));
    }
    if (s->quantity == VDSH_QUANTITY_LOG_DISTANCE
            ? !(s->quantity_param > 0.0f) || !isfinite(s->quantity_param)
            : s->quantity_param != 0.0f)
        return vdsh_bad(w, "%s: quantity_param %g must be %s", l, (double)s->quantity_param,
                        s->quantity == VDSH_QUANTITY_LOG_DISTANCE ? "the log floor, finite and > 0"
                                                                  : "0 for this quantity");
    return 1;
}

/* A quantised record's stored values lie within +-levels, and s8s6's bits
 * that no coefficient uses (bits 30-31 of every word, the last word's
 * unused fields) are zero, so every file has one spelling. `rows` records
 * of nc coefficients at d, the first being vertex `first`. */
static int check_quant_data(const vdsh_stream *s, const char *l, const uint8_t *d, uint32_t nc,
                            size_t rows, size_t first, why *w)
{
    size_t bpv = vdsh_encoding_bytes(s->encoding, nc);
    uint32_t words = s->encoding == VDSH_ENCODING_S8S6 && nc > VDSH_S8S6_BYTES
                         ? (uint32_t)((bpv - VDSH_S8S6_BYTES) / 4)
                         : 0;
    for (size_t x = 0; x < rows; x++) {
        const uint8_t *p = d + x * bpv;
        for (uint32_t i = 0; i < nc; i++) {
            int levels = vdsh_quant_levels(s->encoding, i);
            int32_t q = vdsh_quant_stored(s->encoding, p, i);
            if (q < -levels)
                return vdsh_bad(w, "%s: vertex %zu coefficient %u is %d (%s stores %d..%d there)",
                                l, first + x, i, (int)q, vdsh_encoding_name(s->encoding), -levels,
                                levels);
        }
        for (uint32_t k = 0; k < words; k++) {
            uint32_t left = nc - VDSH_S8S6_BYTES - k * VDSH_S8S6_PER_WORD;
            uint32_t fields = left < VDSH_S8S6_PER_WORD ? left : VDSH_S8S6_PER_WORD;
            uint32_t used = (1u << (VDSH_S8S6_BITS * fields)) - 1u;
            if (get_u32(p + VDSH_S8S6_BYTES + 4 * k) & ~used)
                return vdsh_bad(w, "%s: vertex %zu: unused bits of packed word %u not zero", l,
                                first + x, k);
        }
    }
    return 1;
}

/* A quantised stream's scales: finite and >= 0 (0: the index is 0 at
 * every vertex), and `levels` steps finite, so |coefficient| <= about its
 * scale, finite. */
static int check_scales(const vdsh_stream *s, const char *l, why *w)
{
    for (uint32_t k = 0; k < s->order * s->order; k++) {
        float sc = s->coef_scales[k];
        int levels = vdsh_quant_levels(s->encoding, k);
        if (!isfinite(sc) || !(sc >= 0.0f))
            return vdsh_bad(w, "%s: scale of coefficient %zu is %g, not finite and >= 0", l,
                            (size_t)k, (double)sc);
        if (!isfinite((float)levels * vdsh_quant_step(sc, levels)))
            return vdsh_bad(w, "%s: scale of coefficient %zu, %g: %d steps overflow a float", l,
                            (size_t)k, (double)sc, levels);
    }
    return 1;
}

/* `rows` records of nc coefficients at d, the first being vertex `first`:
 * stored values finite, and so must stored * scale be, which is what
 * vdsh_stream_decode() hands out (a huge scale could overflow it);
 * quantised ones within +-levels (-128, or -32 in 6 bits, would make the
 * range lopsided, and GL's normalisation rules disagree on -128). */
static int check_rows(const vdsh_stream *s, const char *l, const void *data, uint32_t nc,
                      size_t rows, size_t first, why *w)
{
    size_t n = rows * nc;
    float maxabs;
    if (vdsh_encoding_quantised(s->encoding))
        return check_quant_data(s, l, (const uint8_t *)data, nc, rows, first, w);
    if (s->encoding == VDSH_ENCODING_F16) {
        const uint16_t *d = (const uint16_t *)data;
        uint16_t m = 0;
        for (size_t k = 0; k < n; k++) {
            uint16_t a = (uint16_t)(d[k] & 0x7fffu);
            m = a > m ? a : m;
        }
        if (m >= 0x7c00u) {
            size_t k = 0;
            while ((d[k] & 0x7c00u) != 0x7c00u)
                k++;
            return vdsh_bad(w,
                            "%s: vertex %zu coefficient %zu is not finite "
                            "(f16 0x%04x)",
                            l, first + k / nc, k % nc, d[k]);
        }
        maxabs = vdsh_f32_from_f16(m);
    } else {
        const float *d = (const float *)data;
        uint32_t m = max_abs_bits_f32(d, n);
        if (m >= 0x7f800000u) {
            size_t k = first_nonfinite_f32(d, n);
            return vdsh_bad(w, "%s: vertex %zu coefficient %zu is not finite (%g)", l,
                            first + k / nc, k % nc, (double)d[k]);
        }
        maxabs = f32_from_bits(m);
    }
    if (!isfinite(maxabs * s->scale))
        return vdsh_bad(w,
                        "%s: a stored value of %g times scale %g overflows a "
                        "float",
                        l, (double)maxabs, (double)s->scale);
    return 1;
}

/* A variable-order stream's orders (1..order) and records, each as a
 * fixed stream's one vertex, their padding zero. */
static int check_variable_rows(const vdsh_stream *s, const char *l, uint32_t v, why *w)
{
    const uint32_t *words = (const uint32_t *)s->data;
    size_t at = 0;
    for (uint32_t x = 0; x < v; x++) {
        uint32_t k = s->orders[x];
        if (k < 1 || k > s->order)
            return vdsh_bad(w, "%s: vertex %u has order %u (1..%u)", l, x, k, s->order);
        uint32_t nc = k * k;
        if (!check_rows(s, l, words + at, nc, 1, x, w))
            return 0;
        size_t used = vdsh_encoding_bytes(s->encoding, nc);
        uint32_t rec = vdsh_record_words(s->encoding, k);
        if (!all_zero((const uint8_t *)(words + at) + used, 4 * (size_t)rec - used))
            return vdsh_bad(w, "%s: vertex %u: padding after its record not zero", l, x);
        at += rec;
    }
    return 1;
}

/* A cpca stream's model (finite scales, means and bases, decoded values
 * bounded) and records (index < K, levels within +-L, unused bits 0). */
static int check_cpca_data(const vdsh_stream *s, const char *l, uint32_t v, why *w)
{
    const vdsh_cpca *m = &s->cpca;
    uint32_t n = s->order * s->order, b = m->basis;
    for (size_t k = 0; k < (size_t)m->clusters * b; k++) {
        float sc = m->scales[k];
        if (!isfinite(sc) || !(sc >= 0.0f))
            return vdsh_bad(w,
                            "%s: cpca scale %zu (cluster %zu vector %zu) is %g, not finite and "
                            ">= 0",
                            l, k, k / b, k % b, (double)sc);
    }
    for (size_t k = 0; k < (size_t)m->clusters * n; k++)
        if ((m->means[k] & 0x7c00u) == 0x7c00u)
            return vdsh_bad(w, "%s: cpca mean of cluster %zu coefficient %zu is not finite", l,
                            k / n, k % n);
    for (size_t k = 0; k < (size_t)m->clusters * b * n; k++)
        if (m->bases_s8 ? m->bases8[k] == -128 : (m->bases[k] & 0x7c00u) == 0x7c00u)
            return vdsh_bad(w,
                            m->bases_s8 ? "%s: cpca basis vector %zu of cluster %zu, coefficient "
                                          "%zu, is -128 (s8 bases: -127..127)"
                                        : "%s: cpca basis vector %zu of cluster %zu, coefficient "
                                          "%zu, is not finite",
                            l, (k / n) % b, k / n / b, k % n);
    for (uint32_t c = 0; c < m->clusters; c++)
        for (uint32_t i = 0; i < n; i++) {
            double bound = fabs((double)vdsh_f32_from_f16(m->means[(size_t)c * n + i]));
            for (uint32_t j = 0; j < b; j++)
                bound +=
                    (double)vdsh_cpca_levels(vdsh_cpca_width(m, j)) *
                    (double)vdsh_cpca_step(m->scales[(size_t)c * b + j], vdsh_cpca_width(m, j)) *
                    fabs((double)vdsh_cpca_basis_value(m, ((size_t)c * b + j) * n + i));
            if (!(bound <= 1e38))
                return vdsh_bad(w, "%s: cpca cluster %u coefficient %u can reach %g, beyond 1e38",
                                l, c, i, bound);
        }
    /* the bits the fields use, per word */
    uint32_t used[VDSH_MAX_COEFFS + 1];
    for (uint32_t k = 0; k < m->record_words; k++)
        used[k] = 0;
    used[0] = (1u << VDSH_CPCA_INDEX_BITS) - 1u;
    uint32_t fword[VDSH_MAX_COEFFS], fshift[VDSH_MAX_COEFFS];
    for (uint32_t j = 0; j < b; j++) {
        vdsh_cpca_model_field(m, j, &fword[j], &fshift[j]);
        used[fword[j]] |= (uint32_t)(((1ull << vdsh_cpca_width(m, j)) - 1u) << fshift[j]);
    }
    for (uint32_t x = 0; x < v; x++) {
        const uint32_t *r = (const uint32_t *)s->data + (size_t)x * m->record_words;
        if ((r[0] & 0xffu) >= m->clusters)
            return vdsh_bad(w, "%s: vertex %u has cluster %u (0..%u)", l, x, r[0] & 0xffu,
                            m->clusters - 1);
        for (uint32_t k = 0; k < m->record_words; k++)
            if (r[k] & ~used[k])
                return vdsh_bad(w, "%s: vertex %u: unused bits of record word %u not zero", l, x,
                                k);
        for (uint32_t j = 0; j < b; j++) {
            uint32_t bits = vdsh_cpca_width(m, j);
            int L = vdsh_cpca_levels(bits), q = vdsh_cpca_field_level(r, fword[j], fshift[j], bits);
            if (q < -L)
                return vdsh_bad(w, "%s: vertex %u weight %u is %d (%u bits store %d..%d)", l, x, j,
                                q, bits, -L, L);
        }
    }
    return 1;
}

int vdsh_check_stream_data(const vdsh_stream *s, uint32_t i, uint32_t v, why *w)
{
    char l[96];
    vdsh_stream_label(s, i, l, sizeof l);
    if (s->encoding == VDSH_ENCODING_CPCA)
        return check_cpca_data(s, l, v, w);
    if (vdsh_encoding_quantised(s->encoding) && !check_scales(s, l, w))
        return 0;
    if (vdsh_stream_variable(s))
        return check_variable_rows(s, l, v, w);
    return check_rows(s, l, s->data, s->order * s->order, v, 0, w);
}

/* The statistics must describe a bake of vertex_count receivers. */
int vdsh_check_stats(const vdsh_stats *t, uint32_t vertex_count, why *w)
{
    if (t->rays_missed > t->rays_traced)
        return vdsh_bad(w, "stat: %llu rays missed of %llu traced",
                        (unsigned long long)t->rays_missed, (unsigned long long)t->rays_traced);
    const uint32_t v[4] = {t->degenerate_receivers, t->undefined_normals, t->moved_origins,
                           t->flipped_normals};
    static const char *const n[4] = {"degenerate_receivers", "undefined_normals", "moved_origins",
                                     "flipped_normals"};
    for (int k = 0; k < 4; k++)
        if (v[k] > vertex_count)
            return vdsh_bad(w, "stat: %s %u exceeds the %u receivers", n[k], v[k], vertex_count);
    return 1;
}

int vdsh_check_part(const vdsh_part *t, uint32_t vertex_count, why *w)
{
    if (t->count < 1 || t->index >= t->count)
        return vdsh_bad(w, "part: shard %u of %u", t->index, t->count);
    if (t->range_begin >= t->range_end || t->range_end > vertex_count)
        return vdsh_bad(w, "part: receivers %u..%u not within 0..%u", t->range_begin, t->range_end,
                        vertex_count);
    if (t->encoding > VDSH_ENCODING_LAST)
        return vdsh_bad(w, "part: unknown encoding %u", t->encoding);
    if (t->encoding != VDSH_ENCODING_CPCA) {
        if (t->cpca_clusters || t->cpca_basis || t->cpca_bits)
            return vdsh_bad(w, "part: cpca settings %u,%u,%u with encoding %s (must be 0)",
                            t->cpca_clusters, t->cpca_basis, t->cpca_bits,
                            vdsh_encoding_name(t->encoding));
    } else if (!t->cpca_clusters || !t->cpca_bits || t->cpca_bits == VDSH_CPCA_BASES_S8) {
        /* auto: 0, budget, 0; alloc: K, budget, 0 or VDSH_CPCA_BASES_S8 (s8 bases) */
        if (t->cpca_basis < 1 || t->cpca_basis > VDSH_CPCA_MAX_BUDGET ||
            (t->cpca_bits && !t->cpca_clusters) || t->cpca_clusters > VDSH_CPCA_MAX_CLUSTERS)
            return vdsh_bad(w,
                            "part: cpca auto settings %u,%u,%u out of range (K 0..%d, budget "
                            "1..%d, 0, or 256 with K: s8 bases)",
                            t->cpca_clusters, t->cpca_basis, t->cpca_bits, VDSH_CPCA_MAX_CLUSTERS,
                            VDSH_CPCA_MAX_BUDGET);
    } else if (t->cpca_clusters > VDSH_CPCA_MAX_CLUSTERS || t->cpca_basis < 1 ||
               t->cpca_basis > VDSH_MAX_COEFFS || t->cpca_bits < VDSH_CPCA_MIN_BITS ||
               t->cpca_bits > VDSH_CPCA_MAX_BITS) {
        return vdsh_bad(w, "part: cpca settings %u,%u,%u out of range (1..%d, 1..%d, %d..%d)",
                        t->cpca_clusters, t->cpca_basis, t->cpca_bits, VDSH_CPCA_MAX_CLUSTERS,
                        VDSH_MAX_COEFFS, VDSH_CPCA_MIN_BITS, VDSH_CPCA_MAX_BITS);
    }
    return 1;
}

int vdsh_check_light_pool(const vdsh_light_pool *l, int has_part, const vdsh_part *part, why *w)
{
    if (!has_part || part->encoding != VDSH_ENCODING_CPCA)
        return vdsh_bad(w, "lpol: a light pool outside a cpca part (only parts of --encoding "
                           "cpca bakes carry one)");
    if (!(l->mix > 0.0f && l->mix <= 1.0f))
        return vdsh_bad(w, "lpol: light mix %g out of range (0, 1]", (double)l->mix);
    if (!(l->margin == 0.0f || (l->margin > 0.0f && l->margin <= VDSH_CPCA_MAX_MARGIN)))
        return vdsh_bad(w, "lpol: margin %g out of range (0 or (0, %g])", (double)l->margin,
                        (double)VDSH_CPCA_MAX_MARGIN);
    if (l->starts > VDSH_CPCA_MAX_STARTS)
        return vdsh_bad(w, "lpol: %u starts, out of range 0..%d", l->starts, VDSH_CPCA_MAX_STARTS);
    if ((l->margin > 0.0f || l->starts) &&
        (!part->cpca_clusters || (part->cpca_bits & ~VDSH_CPCA_BASES_S8)))
        return vdsh_bad(w, "lpol: a margin or starts with cpca settings other than "
                           "K,alloc:BYTES");
    if (l->count < 1 || l->count > VDSH_MAX_POOL_LIGHTS)
        return vdsh_bad(w, "lpol: %u lights, out of range 1..%d", l->count, VDSH_MAX_POOL_LIGHTS);
    if (!l->lights)
        return vdsh_bad(w, "lpol: lights is NULL");
    for (size_t x = 0; x < 3 * (size_t)l->count; x++)
        if (!isfinite(l->lights[x]))
            return vdsh_bad(w, "lpol: light %zu is not finite", x / 3);
    return 1;
}

int vdsh_check_adaptive(const vdsh_adaptive *a, uint32_t vertex_count, why *w)
{
    if (!(a->tolerance >= 0.0f))
        return vdsh_bad(w, "adpt: tolerance %g is not a number >= 0", (double)a->tolerance);
    if (!(a->min_edge > 0.0f) || !isfinite(a->min_edge))
        return vdsh_bad(w, "adpt: min_edge %g is not a finite number > 0", (double)a->min_edge);
    if (a->lights < 1 || a->max_rounds < 1 || a->rounds > a->max_rounds)
        return vdsh_bad(w, "adpt: %u lights, %u of at most %u rounds", a->lights, a->rounds,
                        a->max_rounds);
    if (a->start_receivers > vertex_count || a->start_receivers < 1)
        return vdsh_bad(w, "adpt: started from %u receivers of %u", a->start_receivers,
                        vertex_count);
    if (a->max_receivers && vertex_count > a->max_receivers)
        return vdsh_bad(w, "adpt: %u receivers over the budget of %u", vertex_count,
                        a->max_receivers);
    if ((uint64_t)a->start_receivers + a->candidates < vertex_count)
        return vdsh_bad(w, "adpt: %u receivers from %u and %u midpoints", vertex_count,
                        a->start_receivers, a->candidates);
    return 1;
}

int vdsh_light_box_bad_axis(const float min[3], const float max[3])
{
    for (int a = 0; a < 3; a++)
        if (!isfinite(min[a]) || !isfinite(max[a]) || !(min[a] < max[a]))
            return a;
    return -1;
}

int vdsh_check_light_box(const vdsh_light_box *b, why *w)
{
    if (b->rule != VDSH_LIGHT_REGION_GROWN && b->rule != VDSH_LIGHT_REGION_BOX)
        return vdsh_bad(w, "lreg: rule %u out of range (1 grown, 2 box)", b->rule);
    int a = vdsh_light_box_bad_axis(b->min, b->max);
    if (a >= 0)
        return vdsh_bad(w, "lreg: axis %d is %g..%g, not finite with min < max", a,
                        (double)b->min[a], (double)b->max[a]);
    return 1;
}

int vdsh_check_timings(const vdsh_timings *t, why *w)
{
    const double v[5] = {t->load, t->refine, t->build, t->trace, t->total};
    static const char *const n[5] = {"load", "refine", "build", "trace", "total"};
    for (int k = 0; k < 5; k++)
        if (!isfinite(v[k]) || !(v[k] >= 0.0))
            return vdsh_bad(w, "time: %s %g must be finite and >= 0", n[k], v[k]);
    return 1;
}
