/*
 * test_run.h - running a program from a C test: its stdout and stderr to
 * files, its exit code back; and whether a file holds a text.
 */
#ifndef VDSH_TEST_RUN_H
#define VDSH_TEST_RUN_H

#include <fcntl.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_util.h"

/* Run argv (NULL-terminated) with stdout to `out` and stderr to `err`;
 * its exit code, -1 when it could not be run or did not exit. */
static inline int test_run(char *const argv[], const char *out, const char *err)
{
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        int o = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int e = open(err, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (o < 0 || e < 0)
            _exit(127);
        dup2(o, 1);
        dup2(e, 2);
        execv(argv[0], argv);
        _exit(127);
    }
    int st;
    if (waitpid(pid, &st, 0) < 0)
        return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Whether the file at `path` can be read and holds `needle`. */
static inline int test_file_contains(const char *path, const char *needle)
{
    char *b = (char *)test_read_file(path, NULL);
    int ok = b && strstr(b, needle) != NULL;
    free(b);
    return ok;
}

#endif
