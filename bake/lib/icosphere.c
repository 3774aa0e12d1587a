/* icosphere.c - the unit icosphere (icosphere.h). Compiled with
 * -ffp-contract=off, like builtin.c: its bytes are the built-in scenes'. */
#include "icosphere.h"

#include <assert.h>
#include <math.h>
#include <string.h>

enum {
    MAX_TRIANGLES = VB_ICOSPHERE_TRIANGLES(VB_ICOSPHERE_MAX_LEVELS),
    /* the edges of the last level's source triangles */
    MAX_EDGES = VB_ICOSPHERE_TRIANGLES(VB_ICOSPHERE_MAX_LEVELS - 1) * 3 / 2
};

void vb_icosphere(uint32_t levels, float pos[][3], uint32_t *nv, uint32_t tri[][3], uint32_t *nt)
{
    assert(levels <= VB_ICOSPHERE_MAX_LEVELS);
    const float t = 1.6180339887f;
    const float base[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                               {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                               {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    static const uint32_t faces[20][3] = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    float len = sqrtf(1.0f + t * t);
    for (int i = 0; i < 12; i++)
        for (int k = 0; k < 3; k++)
            pos[i][k] = base[i][k] / len;
    *nv = 12;
    memcpy(tri, faces, sizeof faces);
    *nt = 20;
    for (uint32_t level = 0; level < levels; level++) {
        /* edges met so far (lo, hi) and their midpoints: a linear search,
         * a few hundred edges */
        uint32_t edge_a[MAX_EDGES], edge_b[MAX_EDGES], edge_mid[MAX_EDGES];
        uint32_t next[MAX_TRIANGLES][3];
        uint32_t ne = 0, nn = 0;
        for (uint32_t f = 0; f < *nt; f++) {
            uint32_t mid[3];
            for (int e = 0; e < 3; e++) {
                uint32_t a = tri[f][e], c = tri[f][(e + 1) % 3];
                uint32_t lo = a < c ? a : c, hi = a < c ? c : a, found = UINT32_MAX;
                for (uint32_t q = 0; q < ne && found == UINT32_MAX; q++)
                    if (edge_a[q] == lo && edge_b[q] == hi)
                        found = edge_mid[q];
                if (found == UINT32_MAX) {
                    float m[3], l = 0.0f;
                    for (int k = 0; k < 3; k++) {
                        m[k] = 0.5f * (pos[a][k] + pos[c][k]);
                        l += m[k] * m[k];
                    }
                    l = sqrtf(l);
                    for (int k = 0; k < 3; k++)
                        pos[*nv][k] = m[k] / l;
                    found = (*nv)++;
                    edge_a[ne] = lo;
                    edge_b[ne] = hi;
                    edge_mid[ne++] = found;
                }
                mid[e] = found;
            }
            const uint32_t split[4][3] = {{tri[f][0], mid[0], mid[2]},
                                          {tri[f][1], mid[1], mid[0]},
                                          {tri[f][2], mid[2], mid[1]},
                                          {mid[0], mid[1], mid[2]}};
            memcpy(next[nn], split, sizeof split);
            nn += 4;
        }
        memcpy(tri, next, nn * sizeof next[0]);
        *nt = nn;
    }
}
