/*
 * test_runtime_png.c - checks on PNG files for the vdsh-view tests:
 *   test_runtime_png info FILE W H     FILE is W x H and not a flat image
 *   test_runtime_png same A B MAXDIFF  A and B have the same size and at
 *                                      least 99.9% of their values differ
 *                                      by at most MAXDIFF
 *   test_runtime_png shadow IMG NONE EX,EY,EZ,TX,TY,TZ FOV DARK LIT
 *                                      IMG (a shadow mode) and NONE (the
 *                                      same view and light, mode none)
 *                                      were rendered by vdsh-view --camera
 *                                      EX,..,TZ --fov FOV; DARK and LIT
 *                                      (X,Y,Z) are scene points that the
 *                                      light is hidden from and seen from.
 *                                      Each is projected with that camera;
 *                                      around DARK, IMG must be at most
 *                                      half as bright as NONE, around LIT
 *                                      at least 0.8 times. With IMG = NONE
 *                                      the first check fails: the control.
 *   test_runtime_png coverage FILE MIN MAX
 *                                      the share of pixels that are not
 *                                      black (the background: something
 *                                      was drawn there) is in MIN..MAX
 */
#include <stb/stb_image.h>

#include <math.h>
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

static int parse3(const char *s, double *v, int n)
{
    int got = 0;
    char *end;
    while (got < n) {
        v[got++] = strtod(s, &end);
        if (end == s || (*end != ',' && *end != '\0'))
            return -1;
        s = *end ? end + 1 : end;
        if (!*end)
            break;
    }
    return got == n && !*s ? 0 : -1;
}

/* Where point p lands in a w x h image seen from eye toward target (up
 * +y, vertical field of view fov degrees), the way vr_draw projects:
 * pixel column x, row y from the top. Returns -1 behind the eye. */
static int project(const double eye[3], const double target[3], double fov, int w, int h,
                   const double p[3], double *x, double *y)
{
    double f[3], s[3], u[3], d[3], n;
    for (int k = 0; k < 3; k++)
        f[k] = target[k] - eye[k], d[k] = p[k] - eye[k];
    n = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; k++)
        f[k] /= n;
    s[0] = -f[2], s[1] = 0.0, s[2] = f[0]; /* f x (0, 1, 0) */
    n = sqrt(s[0] * s[0] + s[2] * s[2]);
    s[0] /= n, s[2] /= n;
    u[0] = s[1] * f[2] - s[2] * f[1];
    u[1] = s[2] * f[0] - s[0] * f[2];
    u[2] = s[0] * f[1] - s[1] * f[0];
    double depth = d[0] * f[0] + d[1] * f[1] + d[2] * f[2];
    if (!(depth > 0.0))
        return -1;
    double t = 1.0 / tan(0.5 * fov * M_PI / 180.0), aspect = (double)w / h;
    double nx = (d[0] * s[0] + d[1] * s[1] + d[2] * s[2]) * t / aspect / depth;
    double ny = (d[0] * u[0] + d[1] * u[1] + d[2] * u[2]) * t / depth;
    *x = 0.5 * (nx + 1.0) * w;
    *y = 0.5 * (1.0 - ny) * h;
    return 0;
}

/* Mean of R, G, B over the (2 r + 1)^2 pixels around (x, y). */
static double window_mean(const unsigned char *px, int w, int x, int y, int r)
{
    double sum = 0.0;
    for (int j = y - r; j <= y + r; j++)
        for (int i = x - r; i <= x + r; i++)
            for (int c = 0; c < 3; c++)
                sum += px[4 * ((long)j * w + i) + c];
    return sum / (3.0 * (2 * r + 1) * (2 * r + 1));
}

static int shadow_check(char **argv)
{
    double cam[6], fov, pts[2][3];
    if (parse3(argv[4], cam, 6) || parse3(argv[6], pts[0], 3) || parse3(argv[7], pts[1], 3) ||
        !((fov = atof(argv[5])) > 1.0 && fov < 179.0)) {
        fprintf(stderr, "shadow: bad camera, field of view or point\n");
        return 2;
    }
    int w, h, w2, h2;
    unsigned char *img = load(argv[2], &w, &h), *none = load(argv[3], &w2, &h2);
    int rc = 0;
    if (!img || !none || w != w2 || h != h2) {
        fprintf(stderr, "images missing or of different sizes\n");
        rc = 1;
    }
    /* a window of about 1/25 of the image height around each point */
    int r = h / 50 > 1 ? h / 50 : 1;
    static const char *const name[2] = {"shadowed", "lit"};
    for (int k = 0; k < 2 && rc == 0; k++) {
        double x, y;
        if (project(cam, cam + 3, fov, w, h, pts[k], &x, &y) || x < r + 1 || y < r + 1 ||
            x > w - r - 2 || y > h - r - 2) {
            fprintf(stderr, "%s point (%g, %g, %g) is not in the view\n", name[k], pts[k][0],
                    pts[k][1], pts[k][2]);
            rc = 1;
            break;
        }
        double a = window_mean(img, w, (int)x, (int)y, r);
        double b = window_mean(none, w, (int)x, (int)y, r);
        printf("%s: %s point (%g, %g, %g) at pixel (%d, %d): %.1f, without shadows %.1f\n", argv[2],
               name[k], pts[k][0], pts[k][1], pts[k][2], (int)x, (int)y, a, b);
        if (b < 40.0) {
            fprintf(stderr,
                    "%s point: only %.1f without shadows: the light does not reach "
                    "it, the check would prove nothing\n",
                    name[k], b);
            rc = 1;
        } else if (k == 0 && !(a <= 0.5 * b)) {
            fprintf(stderr, "%s: the shadowed point is not darkened (%.1f of %.1f)\n", argv[2], a,
                    b);
            rc = 1;
        } else if (k == 1 && !(a >= 0.8 * b)) {
            fprintf(stderr, "%s: the lit point is darkened (%.1f of %.1f)\n", argv[2], a, b);
            rc = 1;
        }
    }
    stbi_image_free(img);
    stbi_image_free(none);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc == 8 && !strcmp(argv[1], "shadow"))
        return shadow_check(argv);
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
    fprintf(stderr, "usage: test_runtime_png info FILE W H | same A B MAXDIFF |\n"
                    "       shadow IMG NONE EX,EY,EZ,TX,TY,TZ FOV DX,DY,DZ LX,LY,LZ |\n"
                    "       coverage FILE MIN MAX\n");
    return 2;
}
