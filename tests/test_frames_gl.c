/*
 * test_frames_gl.c - the GL frame is the one that counts (issue 14): the
 * runtime's shadow-only frames (vdsh-view --views --frames) against the
 * same streams computed in C on the runtime's path (vdsh-frames truth,
 * c-vdshN), pixel by pixel over the truth's mask (the pixels that see a
 * surface facing the light).
 *
 *   test_frames_gl VIEWS.json TRUTH_DIR GL_DIR MEAN MAXSHARE GLMODE=CMODE...
 *
 * For every view, light set and light of VIEWS and every pair: the mean
 * |GL - C| over the mask must be at most MEAN, and the share of mask
 * pixels differing by more than 0.1 at most MAXSHARE (rasterisation and
 * the GPU's float arithmetic move a few pixels along shadow edges and
 * silhouettes; a wrong path, order or sign moves whole regions). Prints
 * the measured figures. Exit 0 pass, 1 fail, 2 usage or unreadable input.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vt_image.h"
#include "vt_views.h"

static float *load(const char *dir, const char *view, int set, int light, const char *mode, int w,
                   int h)
{
    char path[4096], msg[4400];
    int fw, fh;
    float *v = NULL;
    if (vt_frame_path(path, sizeof path, dir, view, set, light, mode) != 0 ||
        vt_png16_read(path, &fw, &fh, &v, msg, sizeof msg) != 0) {
        fprintf(stderr, "test_frames_gl: %s\n", msg);
        return NULL;
    }
    if (fw != w || fh != h) {
        fprintf(stderr, "test_frames_gl: %s is %dx%d, not %dx%d\n", path, fw, fh, w, h);
        free(v);
        return NULL;
    }
    return v;
}

int main(int argc, char **argv)
{
    if (argc < 7) {
        fprintf(stderr, "usage: test_frames_gl VIEWS TRUTH GL MEAN MAXSHARE GLMODE=CMODE...\n");
        return 2;
    }
    vt_views vs = {0};
    char msg[4400];
    if (vt_views_read(argv[1], &vs, msg, sizeof msg) != 0) {
        fprintf(stderr, "test_frames_gl: %s\n", msg);
        return 2;
    }
    const double mean_max = atof(argv[4]), share_max = atof(argv[5]);
    int fail = 0;
    for (int a = 6; a < argc; a++) {
        char gl[64], cm[64];
        if (sscanf(argv[a], "%63[^=]=%63s", gl, cm) != 2) {
            fprintf(stderr, "test_frames_gl: '%s' is not GLMODE=CMODE\n", argv[a]);
            return 2;
        }
        double sum = 0.0, worst_mean = 0.0, worst_share = 0.0;
        size_t n = 0, off = 0;
        for (int i = 0; i < vs.count; i++)
            for (int k = 0; k < vs.views[i].set_count; k++)
                for (int l = 0; l < vs.views[i].light_count[k]; l++) {
                    const char *name = vs.views[i].name;
                    float *m = load(argv[2], name, k, l, "mask", vs.width, vs.height);
                    float *c = load(argv[2], name, k, l, cm, vs.width, vs.height);
                    float *g = load(argv[3], name, k, l, gl, vs.width, vs.height);
                    if (!m || !c || !g) {
                        free(m), free(c), free(g);
                        return 2;
                    }
                    double fs = 0.0;
                    size_t fn = 0, fo = 0;
                    for (size_t p = 0; p < (size_t)vs.width * vs.height; p++) {
                        if (m[p] < 0.5f)
                            continue;
                        double d = fabs((double)g[p] - c[p]);
                        fs += d, fn++, fo += d > 0.1;
                    }
                    sum += fs, n += fn, off += fo;
                    if (fn) {
                        worst_mean = fmax(worst_mean, fs / fn);
                        worst_share = fmax(worst_share, (double)fo / fn);
                    }
                    free(m), free(c), free(g);
                }
        double mean = n ? sum / n : NAN, share = n ? (double)off / n : NAN;
        int ok = n > 0 && worst_mean <= mean_max && worst_share <= share_max;
        printf("%-10s vs %-8s: %zu mask pixels, mean |GL - C| %.5f (worst frame %.5f), "
               "differing by > 0.1: %.3f%% (worst frame %.3f%%)%s\n",
               gl, cm, n, mean, worst_mean, 100.0 * share, 100.0 * worst_share, ok ? "" : "  FAIL");
        fail |= !ok;
    }
    vt_views_free(&vs);
    return fail;
}
