/* kill_at_rename.c - an LD_PRELOAD shim for tests/test_signal_temporaries.sh:
 * the first rename() whose target contains $VDSH_KILL_AT_RENAME sends the
 * process SIGTERM (process-directed, as kill(1) or Ctrl-C send it) just
 * before renaming: a program interrupted with its temporary files written
 * and not yet renamed, deterministically. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int rename(const char *from, const char *to)
{
    static atomic_int fired;
    static int (*real)(const char *, const char *);
    if (!real)
        real = (int (*)(const char *, const char *))dlsym(RTLD_NEXT, "rename");
    const char *want = getenv("VDSH_KILL_AT_RENAME");
    if (want && *want && to && strstr(to, want) && !atomic_exchange(&fired, 1)) {
        kill(getpid(), SIGTERM);
        usleep(200000); /* the signal is taken before the rename, if it is not deferred */
    }
    return real(from, to);
}
