/*
 * vt_json.c - JSON through cJSON, with exact numbers and any bytes as
 * strings (vt_json.h).
 */
#include "vt_json.h"

#include "vdsh_output.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Attach item to parent (member `key` of an object, or the next element
 * of an array); on any failure the item is freed and the document marked
 * failed. Returns the item or NULL. */
static cJSON *attach(vt_json *j, cJSON *parent, const char *key, cJSON *item)
{
    int ok = item && parent &&
             (key ? cJSON_IsObject(parent) && cJSON_AddItemToObject(parent, key, item)
                  : cJSON_IsArray(parent) && cJSON_AddItemToArray(parent, item));
    if (!ok) {
        cJSON_Delete(item);
        j->failed = 1;
        return NULL;
    }
    return item;
}

static cJSON *container(vt_json *j, cJSON *parent, const char *key, cJSON *item)
{
    if (!parent) {
        if (j->root || key) { /* one root, and it has no name */
            cJSON_Delete(item);
            j->failed = 1;
            return NULL;
        }
        if (!item)
            j->failed = 1;
        j->root = item;
        return item;
    }
    return attach(j, parent, key, item);
}

cJSON *vt_json_object(vt_json *j, cJSON *parent, const char *key)
{
    return container(j, parent, key, cJSON_CreateObject());
}

cJSON *vt_json_array(vt_json *j, cJSON *parent, const char *key)
{
    return container(j, parent, key, cJSON_CreateArray());
}

/* Length of the valid UTF-8 sequence at p (1..4), or 0 (RFC 3629: no
 * overlong forms, no surrogates, nothing past U+10FFFF). */
static size_t utf8_len(const unsigned char *p)
{
    unsigned c = p[0];
    if (c < 0x80)
        return 1;
    unsigned lo = 0x80, hi = 0xbf;
    size_t n;
    if (c >= 0xc2 && c <= 0xdf)
        n = 2;
    else if (c >= 0xe0 && c <= 0xef) {
        n = 3;
        if (c == 0xe0)
            lo = 0xa0;
        else if (c == 0xed)
            hi = 0x9f;
    } else if (c >= 0xf0 && c <= 0xf4) {
        n = 4;
        if (c == 0xf0)
            lo = 0x90;
        else if (c == 0xf4)
            hi = 0x8f;
    } else
        return 0;
    if (p[1] < lo || p[1] > hi)
        return 0;
    for (size_t k = 2; k < n; k++)
        if (p[k] < 0x80 || p[k] > 0xbf)
            return 0;
    return n;
}

void vt_json_string(vt_json *j, cJSON *parent, const char *key, const char *s)
{
    if (!s) {
        vt_json_null(j, parent, key);
        return;
    }
    /* Each invalid byte becomes U+FFFD (3 bytes): at most 3x as long. */
    size_t n = strlen(s);
    char *clean = n < SIZE_MAX / 3 ? malloc(3 * n + 1) : NULL;
    if (!clean) {
        j->failed = 1;
        return;
    }
    const unsigned char *p = (const unsigned char *)s;
    size_t o = 0;
    while (*p) {
        size_t k = utf8_len(p);
        if (k) {
            memcpy(clean + o, p, k);
            o += k;
            p += k;
        } else {
            memcpy(clean + o, "\xef\xbf\xbd", 3);
            o += 3;
            p++;
        }
    }
    clean[o] = '\0';
    attach(j, parent, key, cJSON_CreateString(clean));
    free(clean);
}

static void raw(vt_json *j, cJSON *parent, const char *key, const char *text)
{
    attach(j, parent, key, cJSON_CreateRaw(text));
}

void vt_json_f32(vt_json *j, cJSON *parent, const char *key, float v)
{
    if (!isfinite(v)) {
        vt_json_null(j, parent, key);
        return;
    }
    char buf[48];
    for (int digits = 6; digits <= 9; digits++) {
        snprintf(buf, sizeof buf, "%.*g", digits, (double)v);
        if (strtof(buf, NULL) == v)
            break;
    }
    raw(j, parent, key, buf);
}

void vt_json_f64(vt_json *j, cJSON *parent, const char *key, double v)
{
    if (!isfinite(v)) {
        vt_json_null(j, parent, key);
        return;
    }
    char buf[48];
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, sizeof buf, "%.*g", digits, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    raw(j, parent, key, buf);
}

void vt_json_u64(vt_json *j, cJSON *parent, const char *key, uint64_t v)
{
    char buf[32];
    snprintf(buf, sizeof buf, "%" PRIu64, v);
    raw(j, parent, key, buf);
}

void vt_json_i64(vt_json *j, cJSON *parent, const char *key, int64_t v)
{
    char buf[32];
    snprintf(buf, sizeof buf, "%" PRId64, v);
    raw(j, parent, key, buf);
}

void vt_json_bool(vt_json *j, cJSON *parent, const char *key, int v)
{
    attach(j, parent, key, cJSON_CreateBool(v != 0));
}

void vt_json_null(vt_json *j, cJSON *parent, const char *key)
{
    attach(j, parent, key, cJSON_CreateNull());
}

char *vt_json_print(vt_json *j)
{
    if (j->failed || !j->root)
        return NULL;
    char *text = cJSON_Print(j->root);
    if (!text)
        return NULL;
    size_t n = strlen(text);
    char *out = malloc(n + 2);
    if (out) {
        memcpy(out, text, n);
        out[n] = '\n';
        out[n + 1] = '\0';
    }
    cJSON_free(text);
    return out;
}

int vt_json_write_file(vt_json *j, const char *path, char *msg, size_t cap)
{
    if (path && strcmp(path, "-") == 0)
        return vt_json_write_stream(j, stdout, "stdout", msg, cap);
    char *text = vt_json_print(j);
    if (!text) {
        snprintf(msg, cap, "%s: not written: out of memory", path);
        return -1;
    }
    vdsh_error err;
    vdsh_result r = vdsh_output_write(path, text, strlen(text), &err);
    free(text);
    if (r != VDSH_OK) {
        snprintf(msg, cap, "%s", err.msg);
        return -1;
    }
    return 0;
}

int vt_json_write_stream(vt_json *j, FILE *fp, const char *name, char *msg, size_t cap)
{
    char *text = vt_json_print(j);
    if (!text) {
        snprintf(msg, cap, "%s: not written: out of memory", name);
        return -1;
    }
    errno = 0;
    int bad = fputs(text, fp) < 0 || fflush(fp) != 0;
    int e = errno ? errno : EIO;
    free(text);
    if (bad) {
        snprintf(msg, cap, "%s: cannot write: %s", name, strerror(e));
        return -1;
    }
    return 0;
}

void vt_json_free(vt_json *j)
{
    if (!j)
        return;
    cJSON_Delete(j->root);
    j->root = NULL;
    j->failed = 0;
}

cJSON *vt_json_read_file(const char *path, char *msg, size_t cap)
{
    enum { MAX_BYTES = 64 << 20 };
    /* Only regular files (a FIFO would wait for a writer: O_NONBLOCK,
     * which regular files ignore). */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        snprintf(msg, cap, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    struct stat st;
    int e = fstat(fd, &st) != 0 ? errno : 0;
    if (e || !S_ISREG(st.st_mode) || st.st_size > MAX_BYTES) {
        snprintf(msg, cap, "%s: %s", path,
                 e                      ? strerror(e)
                 : !S_ISREG(st.st_mode) ? "not a regular file"
                                        : "larger than 64 MiB");
        close(fd);
        return NULL;
    }
    size_t size = (size_t)st.st_size, got = 0;
    char *buf = malloc(size + 1);
    while (buf && got < size) {
        ssize_t k = read(fd, buf + got, size - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            snprintf(msg, cap, "%s: cannot read: %s", path,
                     k < 0 ? strerror(errno) : "shorter than its size");
            free(buf);
            close(fd);
            return NULL;
        }
        got += (size_t)k;
    }
    close(fd);
    if (!buf) {
        snprintf(msg, cap, "%s: out of memory", path);
        return NULL;
    }
    buf[size] = '\0';
    const char *end = NULL;
    /* The terminating NUL is part of the length: cJSON checks that
     * nothing but white space follows the value by finding it. */
    cJSON *root = cJSON_ParseWithLengthOpts(buf, size + 1, &end, 1);
    if (!root)
        snprintf(msg, cap, "%s: not JSON (at byte %zu)", path,
                 end && end >= buf && end <= buf + size ? (size_t)(end - buf) : (size_t)0);
    free(buf);
    return root;
}

double vt_json_number(const cJSON *object, const char *key)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, key);
    return cJSON_IsNumber(item) ? item->valuedouble : NAN;
}
