/*
 * test_fuzz_main.c - the plain main() that replays fuzzer inputs without
 * libFuzzer (as stb does): linked with one fuzz target's
 * LLVMFuzzerTestOneInput, it feeds every file named on the command line to
 * it, and every regular file in every directory named (sorted by name, not
 * recursive). ctest runs it on the committed corpus and the regression
 * inputs of each target (tests/robust.cmake); a crash, sanitizer report or
 * abort() in the target fails the test.
 *
 * Each input is copied into a buffer of exactly its size, so ASan (in the
 * VDSH_SANITIZE build) sees any read past the end as libFuzzer would.
 *
 * Exit status: 0 when every input ran; 1 when a path cannot be read, a
 * directory is missing, or nothing was replayed at all (an empty corpus is
 * a mistake in the test set-up, not a pass).
 */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Replays one file; 0 on success. */
static int replay_file(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        perror(path);
        return 1;
    }
    struct stat st;
    if (fstat(fileno(fp), &st) != 0 || st.st_size < 0) {
        perror(path);
        fclose(fp);
        return 1;
    }
    size_t n = (size_t)st.st_size;
    uint8_t *buf = malloc(n ? n : 1);
    if (!buf || (n && fread(buf, 1, n, fp) != n)) {
        fprintf(stderr, "%s: cannot read %zu bytes\n", path, n);
        free(buf);
        fclose(fp);
        return 1;
    }
    fclose(fp);
    LLVMFuzzerTestOneInput(buf, n);
    free(buf);
    return 0;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Replays every regular file in `dir`, in name order; counts them. */
static int replay_dir(const char *dir, size_t *count)
{
    DIR *d = opendir(dir);
    if (!d) {
        perror(dir);
        return 1;
    }
    char **names = NULL;
    size_t n = 0, cap = 0;
    int bad = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 64;
            char **grown = realloc(names, cap * sizeof *names);
            if (!grown) {
                bad = 1;
                break;
            }
            names = grown;
        }
        size_t len = strlen(dir) + strlen(e->d_name) + 2;
        names[n] = malloc(len);
        if (!names[n]) {
            bad = 1;
            break;
        }
        snprintf(names[n], len, "%s/%s", dir, e->d_name);
        n++;
    }
    closedir(d);
    if (names)
        qsort(names, n, sizeof *names, by_name);
    for (size_t i = 0; i < n; i++) {
        struct stat st;
        if (!bad && stat(names[i], &st) == 0 && S_ISREG(st.st_mode)) {
            bad |= replay_file(names[i]);
            (*count)++;
        }
        free(names[i]);
    }
    free(names);
    return bad;
}

int main(int argc, char **argv)
{
    size_t count = 0;
    int bad = 0;
    for (int i = 1; i < argc && !bad; i++) {
        struct stat st;
        if (stat(argv[i], &st) != 0) {
            perror(argv[i]);
            bad = 1;
        } else if (S_ISDIR(st.st_mode)) {
            size_t before = count;
            bad = replay_dir(argv[i], &count);
            printf("%s: %zu inputs replayed\n", argv[i], count - before);
        } else {
            bad = replay_file(argv[i]);
            count++;
        }
    }
    if (!bad && count == 0) {
        fprintf(stderr, "no inputs to replay\n");
        bad = 1;
    }
    printf("%zu inputs replayed%s\n", count, bad ? ", with errors" : "");
    return bad;
}
