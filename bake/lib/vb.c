#include "vb.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

const char *vb_result_str(vb_result r)
{
    switch (r) {
    case VB_OK: return "ok";
    case VB_ERR_IO: return "I/O error";
    case VB_ERR_OUT_OF_MEMORY: return "out of memory";
    case VB_ERR_FORMAT: return "unreadable or unsupported file content";
    case VB_ERR_INVALID: return "invalid data";
    case VB_ERR_EMBREE: return "Embree error";
    case VB_ERR_ARGUMENT: return "invalid argument";
    }
    return "unknown error";
}

/* Format into err->msg from byte `at` on (err not NULL). */
static void vformat(vb_error *err, size_t at, const char *fmt, va_list ap)
{
    vsnprintf(err->msg + at, sizeof err->msg - at, fmt, ap);
}

vb_result vb_fail(vb_error *err, vb_result r, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (err)
        vformat(err, 0, fmt, ap);
    va_end(ap);
    return r;
}

void vb_append(vb_error *err, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (err)
        vformat(err, strlen(err->msg), fmt, ap);
    va_end(ap);
}

int vb_ranked_cmp(const void *a, const void *b)
{
    const vb_ranked *x = a, *y = b;
    if (x->key == y->key)
        return (x->index > y->index) - (x->index < y->index);
    return x->key < y->key ? 1 : -1;
}

double vb_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
