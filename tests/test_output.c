/*
 * test_output.c - formats/vdsh_output.h, the one way every program writes
 * a file: the target holds its old content or the whole new one, never a
 * part; a failure leaves no temporary file; writers never share or follow
 * a temporary name.
 *
 *   test_output WORK_DIR
 *
 * Failures are made deterministically, also for root (who may write into
 * a read-only directory): a file size limit (RLIMIT_FSIZE) for a write
 * that fails half way, /dev/full for a stream target, a directory planted
 * at the target between open and commit for a failing rename.
 */
#include "test_dir.h"
#include "test_util.h"
#include "vdsh_output.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static const char *work;

static char *in_work(const char *name)
{
    static char buf[8][4096];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 4096, "%s/%s", work, name);
    return p;
}

static int save(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    int ok = fputs(text, f) >= 0;
    return fclose(f) == 0 && ok;
}

/* The file's whole content equals text. */
static int holds(const char *path, const char *text)
{
    size_t n = 0;
    unsigned char *b = test_read_file(path, &n);
    int ok = b && n == strlen(text) && memcmp(b, text, n) == 0;
    free(b);
    return ok;
}

/* Names in dir that contain ".tmp." (temporaries, vdsh_output.h). */
static int temporaries(const char *dir)
{
    return test_count_names(dir, ".tmp.");
}

/* 1. A name taken under the temporary naming scheme is skipped, never
 * opened, truncated or followed (O_EXCL). Runs first: the process's
 * counter starts at 0, so the first names it tries are known. */
static void test_planted(void)
{
    const char *target = in_work("planted.txt"), *victim = in_work("victim.txt");
    char name[4200];
    CHECK(save(victim, "victim"), "write %s", victim);
    for (int n = 0; n < 40; n++) {
        snprintf(name, sizeof name, "%s.tmp.%ld.%d", target, (long)getpid(), n);
        if (n % 2)
            CHECK(symlink(victim, name) == 0, "symlink %s", name);
        else
            CHECK(save(name, "planted"), "write %s", name);
    }
    vdsh_output o;
    vdsh_error err;
    CHECK(vdsh_output_open(target, &o, &err) == VDSH_OK, "open: %s", err.msg);
    CHECK(o.tmp && strstr(o.tmp, ".tmp.") != NULL, "a temporary beside the target");
    fputs("new", o.fp);
    CHECK(vdsh_output_commit(&o, &err) == VDSH_OK, "commit: %s", err.msg);
    CHECK(holds(target, "new"), "target written");
    CHECK(holds(victim, "victim"), "a planted symbolic link was not followed");
    for (int n = 0; n < 40; n++) {
        snprintf(name, sizeof name, "%s.tmp.%ld.%d", target, (long)getpid(), n);
        if (n % 2 == 0)
            CHECK(holds(name, "planted"), "planted file %s untouched", name);
        unlink(name);
    }
    unlink(target);
    unlink(victim);
}

/* 2. Commit replaces; abort and an unfinished output leave the old
 * content; nothing is left behind. */
static void test_basic(void)
{
    const char *target = in_work("basic.txt");
    vdsh_output o;
    vdsh_error err;
    CHECK(vdsh_output_write(target, "one", 3, &err) == VDSH_OK, "%s", err.msg);
    CHECK(holds(target, "one"), "first write");

    CHECK(vdsh_output_open(target, &o, &err) == VDSH_OK, "%s", err.msg);
    fputs("two, half written", o.fp);
    fflush(o.fp);
    CHECK(holds(target, "one"), "the target unchanged while the new file is written");
    vdsh_output_abort(&o);
    vdsh_output_abort(&o); /* twice is fine */
    CHECK(holds(target, "one") && temporaries(work) == 0, "abort: old content, no temporary");

    CHECK(vdsh_output_open(target, &o, &err) == VDSH_OK, "%s", err.msg);
    fputs("three", o.fp);
    CHECK(vdsh_output_finish(&o, &err) == VDSH_OK, "%s", err.msg);
    CHECK(holds(target, "one"), "finished but not committed: old content");
    CHECK(vdsh_output_commit(&o, &err) == VDSH_OK, "%s", err.msg);
    CHECK(holds(target, "three") && temporaries(work) == 0, "commit: new content, no temporary");
    vdsh_output_abort(&o); /* after commit: nothing to do */
    CHECK(holds(target, "three"), "abort after commit changes nothing");

    int fd0_open = fcntl(0, F_GETFD) != -1;
    vdsh_output zero;
    memset(&zero, 0, sizeof zero);
    vdsh_output_abort(&zero); /* a zeroed output: nothing to close, fd 0 stays */
    vdsh_output_abort(NULL);
    CHECK((fcntl(0, F_GETFD) != -1) == fd0_open, "abort of a zeroed output closed fd 0");

    CHECK(vdsh_output_open(in_work("no/such/dir/x.txt"), &o, &err) == VDSH_ERR_IO &&
              strstr(err.msg, "no/such/dir/x.txt") && strstr(err.msg, strerror(ENOENT)),
          "missing directory named: %s", err.msg);
    CHECK(vdsh_output_open("", &o, &err) == VDSH_ERR_ARGUMENT, "empty path");
    vdsh_output_abort(&o);
    unlink(target);
}

/* 3. A write that fails half way (the file size limit: works for root):
 * the commit fails naming the target, the old content stays, no
 * temporary is left. */
static void test_write_fails(void)
{
    const char *target = in_work("big.bin");
    CHECK(save(target, "old"), "write %s", target);
    size_t n = 1 << 20;
    char *data = malloc(n);
    memset(data, 'x', n);
    struct rlimit saved, small;
    void (*old_handler)(int) = signal(SIGXFSZ, SIG_IGN);
    getrlimit(RLIMIT_FSIZE, &saved);
    small = saved;
    small.rlim_cur = 64 * 1024;
    CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0, "setrlimit");
    vdsh_error err;
    vdsh_result r = vdsh_output_write(target, data, n, &err);
    vdsh_output o;
    vdsh_result r2 = vdsh_output_open(target, &o, &err);
    if (r2 == VDSH_OK) {
        for (size_t k = 0; k < n; k += 4096)
            fwrite(data + k, 1, 4096, o.fp); /* fails part way; ferror remembers */
        r2 = vdsh_output_commit(&o, &err);
    }
    setrlimit(RLIMIT_FSIZE, &saved);
    signal(SIGXFSZ, old_handler);
    CHECK(r == VDSH_ERR_IO, "a write past the limit fails");
    CHECK(r2 == VDSH_ERR_IO && strstr(err.msg, target) && strstr(err.msg, strerror(EFBIG)),
          "commit after failed fwrites fails naming the file and why: %s", err.msg);
    CHECK(holds(target, "old"), "old content kept");
    CHECK(temporaries(work) == 0, "no temporary left");
    free(data);
    unlink(target);
}

/* 4. The rename fails (a non-empty directory took the target's name after
 * the output was opened): temporary removed, directory untouched. */
static void test_rename_fails(void)
{
    const char *target = in_work("dir.txt"), *inner = in_work("dir.txt/keep");
    vdsh_output o;
    vdsh_error err;
    CHECK(vdsh_output_open(target, &o, &err) == VDSH_OK, "%s", err.msg);
    fputs("data", o.fp);
    CHECK(mkdir(target, 0700) == 0 && save(inner, "keep"), "plant a directory");
    CHECK(vdsh_output_commit(&o, &err) == VDSH_ERR_IO && strstr(err.msg, "cannot rename") &&
              strstr(err.msg, target),
          "rename over a directory fails: %s", err.msg);
    CHECK(holds(inner, "keep") && temporaries(work) == 0, "directory kept, no temporary");
    /* And a directory already there is refused at open. */
    CHECK(vdsh_output_open(target, &o, &err) == VDSH_ERR_IO && strstr(err.msg, "is a directory"),
          "a directory target is refused: %s", err.msg);
    unlink(inner);
    rmdir(target);
}

/* 5. Stream targets: written in place, nothing created beside them. They
 * are reached through links in the work folder, so that a writer that
 * replaced its target would replace the link, never a device. */
static void test_streams(void)
{
    vdsh_output o;
    vdsh_error err;
    const char *null = in_work("null"), *full = in_work("full");
    CHECK(symlink("/dev/null", null) == 0 && symlink("/dev/full", full) == 0, "links");
    CHECK(vdsh_output_write(null, "x", 1, &err) == VDSH_OK, "/dev/null: %s", err.msg);
    CHECK(vdsh_output_open(full, &o, &err) == VDSH_OK && o.tmp == NULL,
          "/dev/full opens in place: %s", err.msg);
    fputs("x", o.fp);
    CHECK(vdsh_output_commit(&o, &err) == VDSH_ERR_IO && strstr(err.msg, full) &&
              strstr(err.msg, strerror(ENOSPC)),
          "/dev/full fails naming it: %s", err.msg);
    struct stat st;
    CHECK(lstat(null, &st) == 0 && S_ISLNK(st.st_mode) && lstat(full, &st) == 0 &&
              S_ISLNK(st.st_mode),
          "the links are still links");
    CHECK(temporaries(work) == 0, "nothing created beside them");
    unlink(null);
    unlink(full);
    int p[2];
    CHECK(pipe(p) == 0, "pipe");
    char fifo[64];
    snprintf(fifo, sizeof fifo, "/dev/fd/%d", p[1]);
    vdsh_output po;
    CHECK(vdsh_output_open(fifo, &po, &err) == VDSH_OK && po.tmp == NULL,
          "a pipe opens in place: %s", err.msg);
    if (po.tmp == NULL) {
        fputs("piped", po.fp);
        CHECK(vdsh_output_commit(&po, &err) == VDSH_OK, "a pipe: %s", err.msg);
    } else {
        vdsh_output_abort(&po);
    }
    char got[8] = {0};
    CHECK(read(p[0], got, sizeof got) == 5 && memcmp(got, "piped", 5) == 0, "pipe content");
    close(p[0]);
    close(p[1]);

    /* A link to /proc/self/fd/N whose descriptor is a regular file (what
     * /dev/stdout is under "> out.json"): written in place, appended after
     * what the descriptor already wrote, the link left a link (a rename
     * would have replaced /dev/stdout itself). */
    const char *redirected = in_work("redirected"), *fdlink = in_work("fdlink");
    int fd = open(redirected, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    CHECK(fd >= 0 && write(fd, "before,", 7) == 7, "the redirected file");
    char target[64];
    snprintf(target, sizeof target, "/proc/self/fd/%d", fd);
    CHECK(symlink(target, fdlink) == 0, "link to %s", target);
    vdsh_output ro;
    CHECK(vdsh_output_open(fdlink, &ro, &err) == VDSH_OK && ro.tmp == NULL,
          "a link to a descriptor opens in place: %s", err.msg);
    if (ro.tmp == NULL) {
        fputs("json", ro.fp);
        CHECK(vdsh_output_commit(&ro, &err) == VDSH_OK, "a descriptor: %s", err.msg);
    } else {
        vdsh_output_abort(&ro);
    }
    CHECK(lstat(fdlink, &st) == 0 && S_ISLNK(st.st_mode), "the link is still a link");
    CHECK(holds(redirected, "before,json"), "the descriptor's file got the text after its own");
    CHECK(temporaries(work) == 0, "nothing created beside the link");
    close(fd);
    unlink(fdlink);
    unlink(redirected);
}

/* 6. Many writers to one target at once, threads and processes: every
 * commit succeeds, the target ends as one writer's complete file, no
 * temporary is shared or left. */
enum { WRITERS = 4, ROUNDS = 50, SIZE = 20000 };

static void *writer(void *arg)
{
    long id = (long)arg;
    static const char letters[] = "ABCDEFGH";
    char *buf = malloc(SIZE);
    memset(buf, letters[id % 8], SIZE);
    intptr_t failures = 0;
    for (int r = 0; r < ROUNDS; r++) {
        vdsh_error err;
        failures += vdsh_output_write(in_work("shared.bin"), buf, SIZE, &err) != VDSH_OK;
    }
    free(buf);
    return (void *)failures;
}

static int uniform_file(const char *path)
{
    size_t n = 0;
    unsigned char *b = test_read_file(path, &n);
    int ok = b && n == SIZE;
    for (size_t i = 1; ok && i < n; i++)
        ok = b[i] == b[0];
    free(b);
    return ok;
}

static void test_concurrent(void)
{
    /* Two open at once in one thread: different temporaries. */
    vdsh_output a, b;
    vdsh_error err;
    CHECK(vdsh_output_open(in_work("two.txt"), &a, &err) == VDSH_OK &&
              vdsh_output_open(in_work("two.txt"), &b, &err) == VDSH_OK,
          "two outputs to one target");
    CHECK(a.tmp && b.tmp && strcmp(a.tmp, b.tmp) != 0, "distinct temporaries");
    fputs("first", a.fp);
    fputs("second", b.fp);
    CHECK(vdsh_output_commit(&a, &err) == VDSH_OK && vdsh_output_commit(&b, &err) == VDSH_OK,
          "both commit");
    CHECK(holds(in_work("two.txt"), "second"), "the last commit wins, whole");
    unlink(in_work("two.txt"));

    pthread_t t[WRITERS];
    pid_t pid[2];
    for (int p = 0; p < 2; p++) {
        pid[p] = fork();
        if (pid[p] == 0) {
            intptr_t f = (intptr_t)writer((void *)(long)(WRITERS + p));
            _exit(f ? 1 : 0);
        }
    }
    for (long i = 0; i < WRITERS; i++)
        pthread_create(&t[i], NULL, writer, (void *)i);
    intptr_t failures = 0;
    for (int i = 0; i < WRITERS; i++) {
        void *r;
        pthread_join(t[i], &r);
        failures += (intptr_t)r;
    }
    for (int p = 0; p < 2; p++) {
        int st;
        waitpid(pid[p], &st, 0);
        failures += !(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    }
    CHECK(failures == 0, "%ld writes failed", (long)failures);
    CHECK(uniform_file(in_work("shared.bin")), "the target is one writer's whole file");
    CHECK(temporaries(work) == 0, "no temporary left");
    unlink(in_work("shared.bin"));
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_output WORK_DIR\n");
        return 2;
    }
    work = argv[1];
    mkdir(work, 0755);
    test_planted();
    test_basic();
    test_write_fails();
    test_rename_fails();
    test_streams();
    test_concurrent();
    return test_report("test_output");
}
