#include "vb.h"

#include <stdio.h>
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

vb_result vb_fail(vb_error *err, vb_result r, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return r;
}

double vb_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
