#include "vdsh_cube.h"
#include "vdsh.h"
#include "vdsh_sh.h"

#include <assert.h>
#include <math.h>

/* Texel-centre coordinate in (-1, 1). The numerator is an exact integer
 * and there is a single rounding, so the coordinate of texel n-1-i is
 * exactly the negation of texel i's: mirroring a face is exact. */
static float centre(int i, int n)
{
    return (float)(2 * i + 1 - n) / (float)n;
}

static void check_texel(int face, int i, int j, int n)
{
    (void)face, (void)i, (void)j, (void)n;
    assert(n >= 1);
    assert(face >= 0 && face < 6);
    assert(i >= 0 && i < n && j >= 0 && j < n);
}

void vdsh_cube_exr_dir(int face, int i, int j, int n, float dir[3])
{
    check_texel(face, i, j, n);
    float u = centre(i, n), v = centre(j, n);
    /* The rows of the table in vdsh_cube.h, in face order. */
    switch (face) {
    case 0:
        dir[0] = 1.0f;
        dir[1] = -v;
        dir[2] = u;
        break;
    case 1:
        dir[0] = -1.0f;
        dir[1] = -v;
        dir[2] = -u;
        break;
    case 2:
        dir[0] = u;
        dir[1] = 1.0f;
        dir[2] = -v;
        break;
    case 3:
        dir[0] = u;
        dir[1] = -1.0f;
        dir[2] = v;
        break;
    case 4:
        dir[0] = -u;
        dir[1] = -v;
        dir[2] = 1.0f;
        break;
    default:
        dir[0] = u;
        dir[1] = -v;
        dir[2] = -1.0f;
        break;
    }
}

void vdsh_cube_gl_dir(int face, int i, int j, int n, float dir[3])
{
    check_texel(face, i, j, n);
    float s = centre(i, n), t = centre(j, n);
    switch (face) {
    case 0:
        dir[0] = 1.0f;
        dir[1] = -t;
        dir[2] = -s;
        break;
    case 1:
        dir[0] = -1.0f;
        dir[1] = -t;
        dir[2] = s;
        break;
    case 2:
        dir[0] = s;
        dir[1] = 1.0f;
        dir[2] = t;
        break;
    case 3:
        dir[0] = s;
        dir[1] = -1.0f;
        dir[2] = -t;
        break;
    case 4:
        dir[0] = s;
        dir[1] = -t;
        dir[2] = 1.0f;
        break;
    default:
        dir[0] = -s;
        dir[1] = -t;
        dir[2] = -1.0f;
        break;
    }
}

void vdsh_cube_gl_to_exr(int face, int i, int j, int n, int *ei, int *ej)
{
    check_texel(face, i, j, n);
    /* X and Z faces are mirrored left-right, Y faces top-bottom. */
    if (face == 2 || face == 3) {
        *ei = i;
        *ej = n - 1 - j;
    } else {
        *ei = n - 1 - i;
        *ej = j;
    }
}

/* The 25 basis functions of order 5 at the centre of OpenEXR texel (i, j) of
 * `face`: the one computation behind both fills below, so the runtime's
 * textures and the bake's files hold the same values. */
static void exr_texel_basis(int face, int i, int j, int n, float y[VDSH_MAX_COEFFS])
{
    float d[3];
    vdsh_cube_exr_dir(face, i, j, n, d);
    float inv = 1.0f / sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    d[0] *= inv;
    d[1] *= inv;
    d[2] *= inv;
    vdsh_sh_eval(5, d, y); /* the cubemaps hold functions 9..24 */
}

void vdsh_cube_fill_basis(int n, int first, float *rgba)
{
    assert(n >= 1);
    assert(first == 9 || first == 13 || first == 17 || first == 21);
    for (int face = 0; face < 6; face++) {
        for (int j = 0; j < n; j++) {
            for (int i = 0; i < n; i++) {
                float y[VDSH_MAX_COEFFS];
                exr_texel_basis(face, i, j, n, y);
                float *o =
                    rgba + (((size_t)face * (size_t)n + (size_t)j) * (size_t)n + (size_t)i) * 4;
                o[0] = y[first];
                o[1] = y[first + 1];
                o[2] = y[first + 2];
                o[3] = y[first + 3];
            }
        }
    }
}

void vdsh_cube_basis_face_gl_f16(int n, int face, uint16_t *const out[4])
{
    assert(n >= 1);
    for (int j = 0; j < n; j++) {
        for (int i = 0; i < n; i++) {
            int ei, ej;
            float y[VDSH_MAX_COEFFS];
            vdsh_cube_gl_to_exr(face, i, j, n, &ei, &ej);
            exr_texel_basis(face, ei, ej, n, y);
            size_t t = ((size_t)j * (size_t)n + (size_t)i) * 4;
            for (int k = 0; k < 4; k++)
                for (int c = 0; c < 4; c++)
                    out[k][t + (size_t)c] = vdsh_f16_from_f32(y[9 + 4 * k + c]);
        }
    }
}
