/*
 * vdsh_output.h - output files that appear only when complete.
 *
 * Purpose: the one way every program of the project writes a file (.vdsh,
 * basis cubemaps, OBJ export, bake and evaluation reports, per-vertex
 * errors, PNG images): a reader of the target sees either its old
 * content or the whole new one, never a part, and a failure (a full disk,
 * a killed process, an error of the caller's) leaves the target as it
 * was. Plain C11 and POSIX libc (open, fsync, rename); nothing else.
 *
 * How: vdsh_output_open creates a temporary file beside the target (rename
 * is atomic within one file system), named "<path>.tmp.<pid>.<n>" with a
 * counter n shared by every thread of the process, with O_EXCL (so two
 * writers, threads or processes, never share a temporary, and a file or
 * symbolic link already there under that name is never followed or
 * truncated: the next n is tried) and mode 0666 less the umask (the
 * permissions any new file gets). The caller writes through `fp`
 * (vdsh_output_put, or any stdio call; a library with a write callback,
 * such as stb_image_write's, writes through it too), or through `fd` with
 * write()/pwrite() (OpenEXR's callbacks do), not both. vdsh_output_finish flushes,
 * fsyncs and closes it: the data is on disk. vdsh_output_commit (which
 * finishes first if needed) renames the temporary over the target and
 * fsyncs the directory, best effort (some file systems refuse to sync a
 * directory; the data is safe by then). Several files that must change
 * together (the four basis cubemaps) are all finished before the first is
 * committed. A SIGKILL can leave a temporary file behind, never a partial
 * target; a program that ends on SIGINT or SIGTERM removes them first
 * with vdsh_output_remove_temporaries.
 *
 * Targets that are not regular files: an existing character device or
 * FIFO (/dev/stdout, /dev/null, a pipe) is written in place as a stream
 * (tmp is NULL; nothing to rename, nothing to fsync), so that
 * "--json /dev/stdout" works and nothing under /dev is ever replaced; so is
 * any path that leads through /proc/<pid>/fd (/dev/stdout, /dev/fd/N, a link
 * to one), whatever the descriptor is, a regular file the shell redirected
 * it to included (appended to, O_APPEND: "--json /dev/stdout > out.json"
 * puts the JSON in out.json and leaves the link /dev/stdout alone). An
 * existing directory, block device or socket is refused. A symbolic link
 * to a regular file is replaced by the new file, as rename does.
 *
 * Does not: lock the target (two writers committing at once both succeed
 * and the target holds one of the two complete files) or keep the old
 * file's permissions or owner.
 *
 * Usage (tests/test_output.c is a compiled example):
 *
 *     vdsh_output o;
 *     vdsh_error err;
 *     if (vdsh_output_open("r.json", &o, &err) != VDSH_OK) { print err.msg }
 *     fputs(text, o.fp);
 *     if (vdsh_output_commit(&o, &err) != VDSH_OK) { print err.msg }
 *
 * Errors: VDSH_ERR_IO (errno's text in the message, which names the target
 * and, where one exists, the temporary file), VDSH_ERR_OUT_OF_MEMORY,
 * VDSH_ERR_ARGUMENT (NULL or empty path). A failed open leaves *out as a
 * closed output that vdsh_output_abort accepts; a failed finish or commit
 * removes the temporary file and releases everything, as abort does.
 *
 * Ownership: a vdsh_output owns its copies of the paths, its descriptor and
 * its stream until commit or abort; abort accepts NULL, a zeroed, a failed,
 * a committed or an aborted output, any number of times.
 *
 * Threading: one output belongs to one thread; different outputs, also to
 * the same target, may be used by different threads at once.
 */
#ifndef VDSH_OUTPUT_H
#define VDSH_OUTPUT_H

#include <stddef.h>
#include <stdio.h>

#include "vdsh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vdsh_output {
    char *path;   /* the target (a copy) */
    char *tmp;    /* the temporary file; NULL for a stream target */
    int fd;       /* open for writing until finished; -1 after */
    FILE *fp;     /* a buffered stream on fd; NULL after finishing */
    int error;    /* errno of the first failed vdsh_output_put, or 0 */
    int finished; /* data flushed, synced and closed */
} vdsh_output;

/* Create the temporary file beside `path` (or open a stream target).
 * A directory, block device or socket at `path` is VDSH_ERR_IO. */
vdsh_result vdsh_output_open(const char *path, vdsh_output *out, vdsh_error *err);

/* 1 when vdsh_output_open would write `path` in place, as a stream (an
 * existing character device or FIFO such as /dev/null, or a path through
 * /proc/<pid>/fd such as /dev/stdout), else 0. Files named after such a
 * target ("OUT.sh09-12.exr" beside it) would land in /dev or /proc. */
int vdsh_output_is_stream(const char *path);

/* fwrite to fp, remembering why the first failed write failed (the
 * commit reports it: a stream's error flag alone does not say why).
 * Returns the count written, as fwrite. */
size_t vdsh_output_put(vdsh_output *o, const void *data, size_t n);

/* Flush, check for write errors (ferror on fp too), fsync (regular files)
 * and close. On failure the temporary is removed and the output released. */
vdsh_result vdsh_output_finish(vdsh_output *o, vdsh_error *err);

/* Finish if not yet finished, then rename the temporary over the target
 * and fsync its directory. On failure the temporary is removed and the
 * target is as it was. Releases the output either way. */
vdsh_result vdsh_output_commit(vdsh_output *o, vdsh_error *err);

/* Close and remove the temporary file; the target is as it was. */
void vdsh_output_abort(vdsh_output *o);

/* The whole file from memory: open, write `size` bytes, commit. */
vdsh_result vdsh_output_write(const char *path, const void *data, size_t size, vdsh_error *err);

/* Remove every temporary file of every output now open, in any thread,
 * and keep any output from creating, renaming or removing one after:
 * for a program that is about to end on a signal (SIGINT, SIGTERM), so
 * that it leaves no "<path>.tmp..." behind; each target stays as it was
 * or is whole. Not async-signal-safe: call it from a thread that took the
 * signal with sigwait() (tools/vt_cli.h: vt_cli_clean_exit_on_signals),
 * then end the process. */
void vdsh_output_remove_temporaries(void);

#ifdef __cplusplus
}
#endif

#endif
