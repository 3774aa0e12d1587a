/* kill_at_rename.c - an LD_PRELOAD shim for tests/test_signal_temporaries.sh:
 * the first rename() whose target contains $VDSH_KILL_AT_RENAME sends the
 * process SIGTERM (process-directed, as kill(1) or Ctrl-C send it) just
 * before renaming: a program interrupted with its temporary files written
 * and not yet renamed, deterministically. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <sched.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* VDSH_KILL_ONE_CPU=1: every thread on one CPU (set before main, so the
 * signal thread inherits it): with VDSH_KILL_SLEEP_US=0 the program runs
 * on past the kill before its signal thread is scheduled, as on a loaded
 * machine. */
__attribute__((constructor)) static void one_cpu(void)
{
    const char *one = getenv("VDSH_KILL_ONE_CPU");
    if (one && *one == '1') {
        cpu_set_t set;
        CPU_ZERO(&set);
        if (sched_getaffinity(0, sizeof set, &set) == 0)
            for (int c = 0; c < CPU_SETSIZE; c++)
                if (CPU_ISSET(c, &set)) {
                    CPU_ZERO(&set);
                    CPU_SET(c, &set);
                    sched_setaffinity(0, sizeof set, &set);
                    break;
                }
    }
}

int rename(const char *from, const char *to)
{
    static atomic_int fired;
    static int (*real)(const char *, const char *);
    if (!real)
        real = (int (*)(const char *, const char *))dlsym(RTLD_NEXT, "rename");
    const char *want = getenv("VDSH_KILL_AT_RENAME");
    if (want && *want && to && strstr(to, want) && !atomic_exchange(&fired, 1)) {
        kill(getpid(), SIGTERM);
        /* the signal is taken before the rename, if it is not deferred;
         * VDSH_KILL_SLEEP_US=0: no wait, as a loaded machine may schedule
         * the signal thread after the program has returned from main */
        const char *us = getenv("VDSH_KILL_SLEEP_US");
        usleep(us && *us ? (useconds_t)atol(us) : 200000);
    }
    return real(from, to);
}
