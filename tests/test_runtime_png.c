/*
 * test_runtime_png.c - checks on PNG files for the vdsh-view tests:
 *   test_runtime_png info FILE W H     FILE is W x H and not a flat image
 *   test_runtime_png same A B MAXDIFF  A and B have the same size and at
 *                                      least 99.9% of their values differ
 *                                      by at most MAXDIFF
 *   test_runtime_png coverage FILE MIN MAX
 *                                      the share of pixels that are not
 *                                      black (the background: something
 *                                      was drawn there) is in MIN..MAX
 */
#include <stb/stb_image.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned char *load(const char *path, int *w, int *h)
{
    int n = 0;
    unsigned char *px = stbi_load(path, w, h, &n, 4);
    if (!px)
        fprintf(stderr, "%s: cannot read PNG\n", path);
    return px;
}

int main(int argc, char **argv)
{
    if (argc == 5 && !strcmp(argv[1], "info")) {
        int w, h;
        unsigned char *px = load(argv[2], &w, &h);
        if (!px)
            return 1;
        int want_w = atoi(argv[3]), want_h = atoi(argv[4]);
        long n = (long)w * h, lo = 255, hi = 0;
        double sum = 0;
        for (long i = 0; i < n; i++) {
            int g = px[4 * i + 1];
            sum += g;
            lo = g < lo ? g : lo;
            hi = g > hi ? g : hi;
        }
        stbi_image_free(px);
        printf("%s: %dx%d, green %ld..%ld, mean %.1f\n", argv[2], w, h, lo, hi, sum / n);
        if (w != want_w || h != want_h) {
            fprintf(stderr, "%s: %dx%d, expected %dx%d\n", argv[2], w, h, want_w, want_h);
            return 1;
        }
        if (hi - lo < 32) {
            fprintf(stderr, "%s: a flat image (green %ld..%ld)\n", argv[2], lo, hi);
            return 1;
        }
        return 0;
    }
    if (argc == 5 && !strcmp(argv[1], "same")) {
        int w, h, w2, h2;
        unsigned char *a = load(argv[2], &w, &h), *b = load(argv[3], &w2, &h2);
        if (!a || !b || w != w2 || h != h2) {
            fprintf(stderr, "images missing or of different sizes\n");
            return 1;
        }
        int maxdiff = atoi(argv[4]);
        long n = 4L * w * h, off = 0;
        for (long i = 0; i < n; i++)
            off += abs(a[i] - b[i]) > maxdiff;
        stbi_image_free(a);
        stbi_image_free(b);
        printf("%ld of %ld values differ by more than %d\n", off, n, maxdiff);
        return off * 1000 <= n ? 0 : 1;
    }
    if (argc == 5 && !strcmp(argv[1], "coverage")) {
        int w, h;
        unsigned char *px = load(argv[2], &w, &h);
        if (!px)
            return 1;
        long n = (long)w * h, drawn = 0;
        for (long i = 0; i < n; i++)
            drawn += px[4 * i] || px[4 * i + 1] || px[4 * i + 2];
        stbi_image_free(px);
        double share = (double)drawn / (double)n, lo = atof(argv[3]), hi = atof(argv[4]);
        printf("%s: %.1f%% of the pixels drawn (want %.1f%%..%.1f%%)\n", argv[2], 100.0 * share,
               100.0 * lo, 100.0 * hi);
        return share >= lo && share <= hi ? 0 : 1;
    }
    fprintf(stderr, "usage: test_runtime_png info FILE W H | same A B MAXDIFF | "
                    "coverage FILE MIN MAX\n");
    return 2;
}
