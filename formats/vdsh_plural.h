/*
 * vdsh_plural.h - plurals in messages, the one helper of every module
 * (formats, bake, tools, runtime; not installed): "%u byte%s", n,
 * vdsh_s(n) says "1 byte", "2 bytes"; vdsh_plural(n, "vertex",
 * "vertices") the irregular ones. (Each module had its own copy: vdsh_s,
 * vb_s and vb_plural, vt_s and vt_plural, vr_plural.)
 */
#ifndef VDSH_PLURAL_H
#define VDSH_PLURAL_H

static inline const char *vdsh_s(unsigned long long n)
{
    return n == 1 ? "" : "s";
}

static inline const char *vdsh_plural(unsigned long long n, const char *one, const char *many)
{
    return n == 1 ? one : many;
}

#endif
