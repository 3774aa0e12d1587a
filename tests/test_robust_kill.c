/*
 * test_robust_kill.c - a bake killed with SIGKILL at any moment leaves, at
 * each destination, either the previous complete file or the new complete
 * file (or nothing when there was none before): never a partial one
 * (issue 5, "Atomic output"). Interrupted with SIGTERM or SIGINT, it also
 * leaves no temporary file.
 *
 * Usage: test_robust_kill VDSH_BAKE WORK_DIR
 *
 * The bake: the built-in room refined to max edge 0.4 and exported as an
 * OBJ (1.6 MB, 15,869 vertices: loading it takes a noticeable part of the
 * bake), baked with 32 rays and 96-texel basis cubemaps. It writes five
 * files: scene.vdsh and scene.sh09-12/13-16/17-20/21-24.exr, the cubemaps
 * first. A calibration run measures its duration T and when the first
 * cubemap temporary and the .vdsh temporary appear; then the bake is
 * killed 20 times:
 *
 *   12 kills at delays spread over 0 .. 1.1 T (load, refinement, BVH,
 *      tracing, writing, and after the end);
 *    4 kills while the cubemaps are written (the moment a cubemap
 *      temporary file appears, plus 0 .. 2 ms);
 *    4 kills while the .vdsh is written (its temporary appears, plus
 *      0 .. 2 ms);
 *
 * then the same with 8 SIGTERM and SIGINT (alternately; 4 + 2 + 2), which
 * vdsh-bake defers while it writes: no temporary file may be left.
 *
 * Even trials start with the previous outputs in place (from a bake with
 * another seed and cube size, so every byte of every file differs), odd
 * ones with an empty folder. After each kill every destination must be
 * byte-identical to its previous content or to the complete new output
 * (the calibration run's; bakes are deterministic), or absent when it was
 * absent before; a new .vdsh implies four new cubemaps (they are renamed
 * first). Anything else in the folder must be a temporary file whose name
 * cannot be mistaken for an output ("<output>.tmp.<pid>.<n>", every
 * output's, formats/vdsh_output.h); they are counted and
 * removed. Test time: about 20 T.
 */
#include "test_util.h"
#include "vt_json.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

#define OUTPUTS 5
static const char *const output_names[OUTPUTS] = {"scene.vdsh", "scene.sh09-12.exr",
                                                  "scene.sh13-16.exr", "scene.sh17-20.exr",
                                                  "scene.sh21-24.exr"};

typedef struct blob {
    uint8_t *data;
    size_t size;
    int present;
} blob;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void sleep_s(double s)
{
    if (s <= 0)
        return;
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
}

/* The bake starts with default signal handling, whatever this test
 * inherited (a background shell job ignores SIGINT). */
static pid_t spawn(char *const argv[])
{
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t def, none;
    sigemptyset(&def);
    sigemptyset(&none);
    sigaddset(&def, SIGINT);
    sigaddset(&def, SIGTERM);
    sigaddset(&def, SIGHUP);
    posix_spawnattr_setsigdefault(&attr, &def);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    pid_t pid;
    int rc = posix_spawn(&pid, argv[0], &fa, &attr, argv, environ);
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) {
        fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(rc));
        return -1;
    }
    return pid;
}

/* Exit status, or 128 + signal. */
static int wait_for(pid_t pid)
{
    int status;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static int run(char *const argv[])
{
    pid_t pid = spawn(argv);
    return pid < 0 ? -1 : wait_for(pid);
}

static void load(const char *dir, const char *name, blob *b)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    memset(b, 0, sizeof *b);
    FILE *f = fopen(path, "rb");
    if (!f)
        return;
    struct stat st;
    if (fstat(fileno(f), &st) == 0) {
        b->size = (size_t)st.st_size;
        b->data = malloc(b->size ? b->size : 1);
        b->present = b->data && fread(b->data, 1, b->size, f) == b->size;
    }
    fclose(f);
}

static void store(const char *dir, const char *name, const blob *b)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(b->data, 1, b->size, f) == b->size;
    if (f)
        ok &= fclose(f) == 0;
    CHECK(ok, "cannot write %s", path);
}

static int same(const blob *a, const blob *b)
{
    return a->present && b->present && a->size == b->size && memcmp(a->data, b->data, a->size) == 0;
}

/* Is there a temporary file of the given kind (".vdsh.tmp" or
 * ".exr.tmp") in dir? */
static int has_temp(const char *dir, const char *kind)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    struct dirent *e;
    int found = 0;
    while (!found && (e = readdir(d)) != NULL)
        found = strstr(e->d_name, kind) != NULL;
    closedir(d);
    return found;
}

/* Removes everything in dir; counts and checks the names of temporaries. */
static int clean_dir(const char *dir, int *temps, char *example, size_t cap)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    struct dirent *e;
    int bad = 0;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        int output = 0, temp = 0;
        for (int k = 0; k < OUTPUTS; k++) {
            size_t n = strlen(output_names[k]);
            output |= strcmp(e->d_name, output_names[k]) == 0;
            temp |= strncmp(e->d_name, output_names[k], n) == 0 &&
                    strncmp(e->d_name + n, ".tmp.", 5) == 0;
        }
        if (temp) {
            ++*temps;
            if (!example[0])
                snprintf(example, cap, "%s", e->d_name);
        } else if (!output) {
            CHECK(0, "unexpected file %s/%s after a kill", dir, e->d_name);
            bad = 1;
        }
        char path[4096 + sizeof e->d_name];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        unlink(path);
    }
    closedir(d);
    return bad;
}

typedef struct kill_setup {
    const char *run_dir;
    char **run_args;
    const blob *old_files, *new_files;
    double T, t_load, t_cube, t_vdsh;
} kill_setup;

/* `timed` signals at delays spread over 0 .. 1.1 T, then `cubes` while
 * cubemaps are written and `vdsh` while the .vdsh is. With sig ==
 * SIGTERM, the trials alternate between SIGTERM and SIGINT. Returns the
 * number of temporary files left behind. */
static int trials(const kill_setup *ks, int sig, int timed, int cubes, int vdsh)
{
    const int total = timed + cubes + vdsh;
    int outcome_old = 0, outcome_new = 0, outcome_absent = 0, mixed_cubes = 0, temps = 0;
    int phase_counts[5] = {0, 0, 0, 0, 0};
    char temp_example[256] = "";
    uint64_t seed = 12345 + (uint64_t)sig;
    for (int trial = 0; trial < total; trial++) {
        int with_old = trial % 2 == 0;
        int this_sig = sig == SIGTERM && trial % 2 ? SIGINT : sig;
        if (with_old)
            for (int k = 0; k < OUTPUTS; k++)
                store(ks->run_dir, output_names[k], &ks->old_files[k]);

        double start = now();
        pid_t pid = spawn(ks->run_args);
        int status = 0, exited = 0;
        if (trial < timed) {
            double delay = ks->T * 1.1 * ((double)trial + test_rand(&seed)) / timed;
            sleep_s(delay - (now() - start));
        } else {
            const char *kind = trial < timed + cubes ? ".exr.tmp" : ".vdsh.tmp";
            while (!has_temp(ks->run_dir, kind) &&
                   !(exited = waitpid(pid, &status, WNOHANG) == pid))
                sleep_s(50e-6);
            sleep_s(2e-3 * test_rand(&seed));
        }
        double killed_at = now() - start;
        if (!exited) {
            kill(pid, this_sig);
            status = wait_for(pid);
        } else {
            status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        }
        /* A signal that came while the bake was writing ends it once
         * the files are in place: the status still says so. */
        CHECK(status == 128 + this_sig || (status == 0 && (exited || killed_at > ks->T * 0.5)),
              "trial %d: bake ended with status %d", trial, status);
        if (exited)
            phase_counts[4]++;
        else if (trial >= timed)
            phase_counts[trial < timed + cubes ? 2 : 3]++;
        else
            phase_counts[killed_at < ks->t_load   ? 0
                         : killed_at < ks->t_cube ? 1
                         : killed_at < ks->t_vdsh ? 2
                         : killed_at < ks->T      ? 3
                                                  : 4]++;

        /* Every destination: previous, new or (if nothing before) absent. */
        int state[OUTPUTS]; /* 0 absent, 1 previous, 2 new */
        for (int k = 0; k < OUTPUTS; k++) {
            blob b;
            load(ks->run_dir, output_names[k], &b);
            state[k] = !b.present                    ? 0
                       : same(&b, &ks->new_files[k]) ? 2
                       : same(&b, &ks->old_files[k]) ? 1
                                                     : -1;
            CHECK(
                state[k] >= 0,
                "trial %d (signal at %.3f s): %s is neither the previous nor the new file (%zu bytes)",
                trial, killed_at, output_names[k], b.size);
            CHECK(state[k] != 1 || with_old, "trial %d: %s appeared with old content", trial,
                  output_names[k]);
            CHECK(state[k] != 0 || !with_old, "trial %d (signal at %.3f s): %s was removed", trial,
                  killed_at, output_names[k]);
            free(b.data);
        }
        CHECK(state[0] != 2 || (state[1] == 2 && state[2] == 2 && state[3] == 2 && state[4] == 2),
              "trial %d: new .vdsh without all four new cubemaps", trial);
        outcome_new += state[0] == 2;
        outcome_old += state[0] == 1;
        outcome_absent += state[0] == 0;
        int cubes_new = (state[1] == 2) + (state[2] == 2) + (state[3] == 2) + (state[4] == 2);
        mixed_cubes += cubes_new > 0 && cubes_new < 4;
        clean_dir(ks->run_dir, &temps, temp_example, sizeof temp_example);
    }
    const char *name = sig == SIGKILL ? "SIGKILL" : "SIGTERM/SIGINT";
    printf(
        "%s, %d times: %d while starting and loading, %d while refining, building and tracing, %d while "
        "writing cubemaps, %d while writing the .vdsh, %d at or after the end\n",
        name, total, phase_counts[0], phase_counts[1], phase_counts[2], phase_counts[3],
        phase_counts[4]);
    printf(
        "  .vdsh afterwards: %d previous, %d new, %d absent (none before); cubemap sets left mixed "
        "old/new: %d; temporary files left: %d%s%s%s\n",
        outcome_old, outcome_new, outcome_absent, mixed_cubes, temps, temps ? " (e.g. " : "",
        temp_example, temps ? ")" : "");
    CHECK(phase_counts[2] > 0 && phase_counts[3] > 0, "%s: no signal landed while writing", name);
    CHECK(sig != SIGKILL || phase_counts[0] + phase_counts[1] > 0,
          "SIGKILL: no kill landed before writing");
    return temps;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: test_robust_kill VDSH_BAKE WORK_DIR\n");
        return 2;
    }
    char *bake = argv[1];
    const char *work = argv[2];
    char obj[4096], old_dir[2048], new_dir[2048], run_dir[2048];
    char old_out[4096], new_out[4096], run_out[4096];
    mkdir(work, 0755);
    snprintf(obj, sizeof obj, "%s/room.obj", work);
    snprintf(old_dir, sizeof old_dir, "%s/old", work);
    snprintf(new_dir, sizeof new_dir, "%s/new", work);
    snprintf(run_dir, sizeof run_dir, "%s/run", work);
    snprintf(old_out, sizeof old_out, "%s/scene.vdsh", old_dir);
    snprintf(new_out, sizeof new_out, "%s/scene.vdsh", new_dir);
    snprintf(run_out, sizeof run_out, "%s/scene.vdsh", run_dir);
    mkdir(old_dir, 0755);
    mkdir(new_dir, 0755);
    mkdir(run_dir, 0755);
    int t0 = 0;
    char none[1] = "";
    clean_dir(run_dir, &t0, none, 0);

    /* The scene, the previous outputs, and the reference new outputs. */
    char *export_args[] = {bake, "builtin:room", "--max-edge", "0.4",
                           "-q", "--export-obj", obj,          NULL};
    char *old_args[] = {bake, obj,         "--rays", "16", "--seed", "2",     "--cube-size",
                        "64", "--threads", "2",      "-q", "-o",     old_out, NULL};
    char *new_args[] = {bake,        obj, "--rays", "32", "--cube-size", "96",
                        "--threads", "2", "-q",     "-o", new_out,       NULL};
    char *run_args[] = {bake,        obj, "--rays", "32", "--cube-size", "96",
                        "--threads", "2", "-q",     "-o", run_out,       NULL};
    CHECK(run(export_args) == 0, "export of the room failed");
    CHECK(run(old_args) == 0, "bake of the previous outputs failed");
    CHECK(run(new_args) == 0, "reference bake failed");
    blob old_files[OUTPUTS], new_files[OUTPUTS];
    for (int k = 0; k < OUTPUTS; k++) {
        load(old_dir, output_names[k], &old_files[k]);
        load(new_dir, output_names[k], &new_files[k]);
        CHECK(old_files[k].present && new_files[k].present && !same(&old_files[k], &new_files[k]),
              "%s: previous and new outputs missing or identical", output_names[k]);
    }
    if (test_failures)
        return test_report("robust_kill");

    /* Calibration: duration, load time (from --report) and the moments
     * the temporaries appear. */
    double t_cube = -1, t_vdsh = -1, T = 0, t_load = 0;
    {
        char report[4096];
        snprintf(report, sizeof report, "%s/calibration.json", work);
        char *calib_args[] = {bake, obj,  "--rays", "32",    "--cube-size", "96",   "--threads",
                              "2",  "-q", "-o",     run_out, "--report",    report, NULL};
        double start = now();
        pid_t pid = spawn(calib_args);
        int status;
        /* The start of the last stretch in which each temporary is there:
         * the checks before loading (every output writable) make and
         * remove one of each first. */
        int cube_on = 0, vdsh_on = 0;
        while (waitpid(pid, &status, WNOHANG) == 0) {
            int c = has_temp(run_dir, ".exr.tmp"), v = has_temp(run_dir, ".vdsh.tmp");
            if (c && !cube_on)
                t_cube = now() - start;
            if (v && !vdsh_on)
                t_vdsh = now() - start;
            cube_on = c, vdsh_on = v;
            sleep_s(50e-6);
        }
        T = now() - start;
        CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0, "calibration bake failed");
        /* Loading ends after process start-up and the load itself; the
         * report's clock starts after start-up. */
        char msg[4400];
        cJSON *r = vt_json_read_file(report, msg, sizeof msg);
        const cJSON *sec = cJSON_GetObjectItemCaseSensitive(r, "seconds");
        double load_s = vt_json_number(sec, "load"), total_s = vt_json_number(sec, "total");
        CHECK(isfinite(load_s) && isfinite(total_s), "no timings in %s: %s", report,
              r ? "no seconds.load, seconds.total" : msg);
        if (!isfinite(load_s) || !isfinite(total_s))
            load_s = total_s = 0;
        cJSON_Delete(r);
        t_load = T - total_s + load_s;
        for (int k = 0; k < OUTPUTS; k++) {
            blob b;
            load(run_dir, output_names[k], &b);
            CHECK(same(&b, &new_files[k]), "%s: bakes are not deterministic", output_names[k]);
            free(b.data);
        }
        clean_dir(run_dir, &t0, none, 0);
    }
    printf(
        "bake: %.3f s; loaded by %.3f s, first cubemap temporary at %.3f s, .vdsh temporary at %.3f s\n",
        T, t_load, t_cube, t_vdsh);

    /* The kills: SIGKILL, then the signals the bake defers while it
     * writes (SIGTERM and SIGINT alternately), which must leave no
     * temporary file. */
    kill_setup ks = {run_dir, run_args, old_files, new_files, T, t_load, t_cube, t_vdsh};
    int temps = trials(&ks, SIGKILL, 12, 4, 4);
    (void)temps;
    temps = trials(&ks, SIGTERM, 4, 2, 2);
    CHECK(temps == 0, "SIGTERM/SIGINT left %d temporary files", temps);
    for (int k = 0; k < OUTPUTS; k++) {
        free(old_files[k].data);
        free(new_files[k].data);
    }
    return test_report("robust_kill");
}
