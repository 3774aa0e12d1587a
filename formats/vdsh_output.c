/*
 * vdsh_output.c - output files that appear only when complete (see
 * vdsh_output.h for the contract).
 */
#include "vdsh_output.h"
#include "vdsh_failf.h"

#include <errno.h>
#include <limits.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Temporary names tried before giving up: names taken by other writers
 * (or planted) are skipped, one attempt each. */
enum { MAX_ATTEMPTS = 1000 };

vdsh_result vdsh_failf(vdsh_error *err, vdsh_result r, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return r;
}

/* The temporary files that exist now (every open output's), for
 * vdsh_output_remove_temporaries: a growing array under one lock. The
 * lock is held while a temporary is created and listed, renamed or
 * removed and struck off, so that the list is always what is on disk. */
static pthread_mutex_t live_lock = PTHREAD_MUTEX_INITIALIZER;
static char **live;
static size_t live_count, live_cap;

static int live_add(char *tmp) /* under live_lock; 0, or -1 out of memory */
{
    if (live_count == live_cap) {
        size_t cap = live_cap ? 2 * live_cap : 16;
        char **grown = realloc(live, cap * sizeof *grown);
        if (!grown)
            return -1;
        live = grown, live_cap = cap;
    }
    live[live_count++] = tmp;
    return 0;
}

static void live_remove(const char *tmp) /* under live_lock */
{
    for (size_t i = 0; i < live_count; i++)
        if (live[i] == tmp) {
            live[i] = live[--live_count];
            return;
        }
}

void vdsh_output_remove_temporaries(void)
{
    pthread_mutex_lock(&live_lock);
    for (size_t i = 0; i < live_count; i++)
        unlink(live[i]);
    live_count = 0;
    /* The lock stays held: the caller ends the process, and no output may
     * create, rename or remove a temporary meanwhile. */
}

static void release(vdsh_output *o)
{
    if (o->fp)
        fclose(o->fp);
    else if (o->fd >= 0)
        close(o->fd);
    if (o->tmp) {
        pthread_mutex_lock(&live_lock);
        unlink(o->tmp);
        live_remove(o->tmp);
        pthread_mutex_unlock(&live_lock);
    }
    free(o->tmp);
    free(o->path);
    memset(o, 0, sizeof *o);
    o->fd = -1;
}

/* 1 when path leads through /proc/<pid>/fd (/dev/stdout, /dev/fd/N,
 * /proc/self/fd/N, or a link to one): a descriptor the process already has
 * open, whatever it is (a terminal, a pipe, or the regular file a shell
 * redirected it to). Such a target is written in place: a rename over it
 * would replace the link itself (/dev/stdout, for root) or fail. */
static int through_proc_fd(const char *path)
{
    char q[PATH_MAX], dir[PATH_MAX], real[PATH_MAX], link[PATH_MAX];
    if (snprintf(q, sizeof q, "%s", path) >= (int)sizeof q)
        return 0;
    for (int depth = 0; depth < 40; depth++) {
        char *slash = strrchr(q, '/');
        const char *base = slash ? slash + 1 : q;
        if (!slash)
            snprintf(dir, sizeof dir, ".");
        else if (slash == q)
            snprintf(dir, sizeof dir, "/");
        else
            snprintf(dir, sizeof dir, "%.*s", (int)(slash - q), q);
        if (!realpath(dir, real))
            return 0;
        if (strcmp(real, "/proc") == 0 || strncmp(real, "/proc/", 6) == 0)
            return 1;
        char full[PATH_MAX];
        if (snprintf(full, sizeof full, "%s/%s", strcmp(real, "/") ? real : "", base) >=
            (int)sizeof full)
            return 0;
        ssize_t n = readlink(full, link, sizeof link - 1);
        if (n < 0)
            return 0; /* not a link (or absent): the name is final */
        link[n] = 0;
        if (link[0] == '/')
            snprintf(q, sizeof q, "%s", link);
        else if (snprintf(q, sizeof q, "%s/%s", strcmp(real, "/") ? real : "", link) >=
                 (int)sizeof q)
            return 0;
    }
    return 0;
}

/* What vdsh_output_open makes of a target (stat into *st): TARGET_FILE, a
 * regular file or none (the temporary-file path); TARGET_PROC_FD, a path
 * through /proc/<pid>/fd, whatever it leads to (written in place,
 * appended to); TARGET_DEVICE, a character device or FIFO (written in
 * place); TARGET_REFUSED, a directory, block device or socket. */
enum { TARGET_REFUSED = -1, TARGET_FILE, TARGET_PROC_FD, TARGET_DEVICE };

static int target_kind(const char *path, struct stat *st)
{
    if (stat(path, st) != 0)
        return TARGET_FILE;
    if (!S_ISDIR(st->st_mode) && through_proc_fd(path))
        return TARGET_PROC_FD;
    if (S_ISREG(st->st_mode))
        return TARGET_FILE;
    return S_ISCHR(st->st_mode) || S_ISFIFO(st->st_mode) ? TARGET_DEVICE : TARGET_REFUSED;
}

/* A stream target (target_kind) opened in place: 1 when it is one and
 * opened, 0 when the temporary-file path follows, -1 on an error (already
 * reported). */
static int open_stream(const char *path, vdsh_output *o, vdsh_error *err, vdsh_result *res)
{
    struct stat st;
    const int kind = target_kind(path, &st);
    if (kind == TARGET_FILE)
        return 0;
    if (kind == TARGET_REFUSED) {
        *res = vdsh_failf(err, VDSH_ERR_IO, "%s: cannot write: %s", path,
                          S_ISDIR(st.st_mode) ? "is a directory" : "not a regular file");
        return -1;
    }
    int fd = open(path, O_WRONLY | O_NOCTTY | O_CLOEXEC | (kind == TARGET_PROC_FD ? O_APPEND : 0));
    if (fd < 0) {
        *res = vdsh_failf(err, VDSH_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    /* What was opened, not what stat saw a moment ago, decides. */
    if (kind == TARGET_DEVICE &&
        (fstat(fd, &st) != 0 || (!S_ISCHR(st.st_mode) && !S_ISFIFO(st.st_mode)))) {
        close(fd);
        *res = vdsh_failf(err, VDSH_ERR_IO,
                          "%s: cannot write: not a regular file "
                          "(it changed while being opened)",
                          path);
        return -1;
    }
    o->fd = fd;
    return 1;
}

int vdsh_output_is_stream(const char *path)
{
    struct stat st;
    return path && *path && target_kind(path, &st) > TARGET_FILE;
}

vdsh_result vdsh_output_open(const char *path, vdsh_output *out, vdsh_error *err)
{
    static atomic_uint counter;
    vdsh_output o = {.fd = -1};
    if (out)
        *out = o;
    if (!out || !path || !path[0])
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "%s: cannot write: no file name given",
                          path ? path : "(null)");
    vdsh_result res = VDSH_OK;
    size_t len = strlen(path);
    o.path = malloc(len + 1);
    if (!o.path)
        return vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    memcpy(o.path, path, len + 1);

    int stream = open_stream(path, &o, err, &res);
    if (stream < 0) {
        release(&o);
        return res;
    }
    if (!stream) {
        size_t cap = len + 64;
        o.tmp = malloc(cap);
        if (!o.tmp) {
            release(&o);
            return vdsh_failf(err, VDSH_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
        }
        int e = 0;
        pthread_mutex_lock(&live_lock);
        for (int attempt = 0; attempt < MAX_ATTEMPTS; attempt++) {
            snprintf(o.tmp, cap, "%s.tmp.%ld.%u", path, (long)getpid(),
                     atomic_fetch_add(&counter, 1u));
            o.fd = open(o.tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOCTTY | O_CLOEXEC, 0666);
            e = errno;
            if (o.fd >= 0 || e != EEXIST)
                break;
        }
        if (o.fd >= 0 && live_add(o.tmp) != 0) {
            unlink(o.tmp);
            close(o.fd);
            o.fd = -1;
            e = ENOMEM;
        }
        pthread_mutex_unlock(&live_lock);
        if (o.fd < 0) {
            res = vdsh_failf(err, VDSH_ERR_IO,
                             "%s: cannot create a temporary file beside it "
                             "(%s): %s",
                             path, o.tmp, e == EEXIST ? "every name taken" : strerror(e));
            free(o.tmp); /* not ours: never unlink it */
            o.tmp = NULL;
            release(&o);
            return res;
        }
    }
    o.fp = fdopen(o.fd, "wb");
    if (!o.fp) {
        int e = errno;
        release(&o);
        return vdsh_failf(err, VDSH_ERR_IO, "%s: cannot write: %s", path, strerror(e));
    }
    *out = o;
    return VDSH_OK;
}

size_t vdsh_output_put(vdsh_output *o, const void *data, size_t n)
{
    if (!o || !o->fp)
        return 0;
    errno = 0;
    size_t k = fwrite(data, 1, n, o->fp);
    if (k != n && !o->error)
        o->error = errno ? errno : EIO;
    return k;
}

vdsh_result vdsh_output_finish(vdsh_output *o, vdsh_error *err)
{
    if (!o || !o->path)
        return vdsh_failf(err, VDSH_ERR_ARGUMENT, "vdsh_output_finish: no open output");
    if (o->finished)
        return VDSH_OK;
    /* errno of the first step that failed; a write error that stdio only
     * remembers (ferror), from a write not made through vdsh_output_put,
     * reports EIO. */
    int e = o->error;
    const char *step = "write";
    if (o->fp && !e) {
        errno = 0;
        if (fflush(o->fp) != 0)
            e = errno ? errno : EIO;
        else if (ferror(o->fp))
            e = EIO;
    }
    if (!e && o->tmp && fsync(o->fd) != 0) {
        e = errno;
        step = "sync";
    }
    int closed = o->fp ? fclose(o->fp) : close(o->fd);
    if (closed != 0 && !e) {
        e = errno;
        step = "close";
    }
    o->fp = NULL;
    o->fd = -1;
    if (e) {
        vdsh_result r;
        if (o->tmp)
            r = vdsh_failf(err, VDSH_ERR_IO, "%s: cannot %s (temporary file %s): %s", o->path, step,
                           o->tmp, strerror(e));
        else
            r = vdsh_failf(err, VDSH_ERR_IO, "%s: cannot %s: %s", o->path, step, strerror(e));
        release(o);
        return r;
    }
    o->finished = 1;
    return VDSH_OK;
}

/* Make the rename itself durable; best effort (some file systems refuse
 * to fsync a directory, and the data is already safe). */
static void sync_parent_dir(const char *path)
{
    const char *slash = strrchr(path, '/');
    char *dir;
    if (!slash) {
        dir = strdup(".");
    } else {
        size_t n = slash == path ? 1 : (size_t)(slash - path);
        dir = malloc(n + 1);
        if (dir) {
            memcpy(dir, path, n);
            dir[n] = 0;
        }
    }
    if (!dir)
        return;
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        (void)fsync(fd);
        close(fd);
    }
    free(dir);
}

vdsh_result vdsh_output_commit(vdsh_output *o, vdsh_error *err)
{
    vdsh_result r = vdsh_output_finish(o, err);
    if (r != VDSH_OK)
        return r;
    if (o->tmp) {
        pthread_mutex_lock(&live_lock);
        if (rename(o->tmp, o->path) != 0) {
            int e = errno;
            pthread_mutex_unlock(&live_lock);
            r = vdsh_failf(err, VDSH_ERR_IO, "%s: cannot rename %s to it: %s", o->path, o->tmp,
                           strerror(e));
            release(o);
            return r;
        }
        live_remove(o->tmp);
        pthread_mutex_unlock(&live_lock);
        sync_parent_dir(o->path);
        free(o->tmp);
        o->tmp = NULL;
    }
    release(o);
    return VDSH_OK;
}

void vdsh_output_abort(vdsh_output *o)
{
    if (o && o->path)
        release(o);
    else if (o)
        o->fd = -1;
}

vdsh_result vdsh_output_write(const char *path, const void *data, size_t size, vdsh_error *err)
{
    vdsh_output o;
    vdsh_result r = vdsh_output_open(path, &o, err);
    if (r != VDSH_OK)
        return r;
    vdsh_output_put(&o, data, size);
    return vdsh_output_commit(&o, err);
}
