/* Ray-space grids (double): which shapes each ray of a bundle must test (rend3r/emu/grids.py
 * explains the parameterisation). A perspective bundle's line along d through its apex
 * has face k = the axis of d's largest component and (u, v) = the other two components
 * over it, for d and -d alike; a parallel bundle's (u, v) is the origin projected on two
 * axes normal to its direction.
 */
#ifndef REND3R_GRIDS_H
#define REND3R_GRIDS_H

#include <math.h>
#include <stdint.h>

#include "kernels.h"

#define UV_SLACK 1e-12

/* The face and (u, v) of the line along d; returns -1 if d is zero or not finite. */
static inline int perspective_uv(double d0, double d1, double d2, double *u, double *v)
{
    double a0 = fabs(d0), a1 = fabs(d1), a2 = fabs(d2), sum = a0 + a1 + a2;
    *u = *v = 0.0;
    if (!(sum > 0.0 && sum < INFINITY))
        return -1;
    if (a0 >= a1 && a0 >= a2) { *u = d1 / d0; *v = d2 / d0; return 0; }
    if (a1 >= a2) { *u = d0 / d1; *v = d2 / d1; return 1; }
    *u = d0 / d2; *v = d1 / d2; return 2;
}

/* The cell holding (u, v) on a face, or -1 outside the grid. */
static inline int64_t cell_of(const Grid *g, int face, double u, double v)
{
    if (face < 0)
        return -1;
    const double *f = g->faces + GF_COLUMNS * face;
    const int64_t *s = g->shape + GS_COLUMNS * face;
    if (s[GS_NU] == 0 || !(f[GF_U0] <= u && u <= f[GF_U1] && f[GF_V0] <= v && v <= f[GF_V1]))
        return -1;
    int64_t iu = (int64_t)((u - f[GF_U0]) * f[GF_SU]), iv = (int64_t)((v - f[GF_V0]) * f[GF_SV]);
    if (iu > s[GS_NU] - 1) iu = s[GS_NU] - 1;
    if (iv > s[GS_NV] - 1) iv = s[GS_NV] - 1;
    return s[GS_FIRST] + iv * s[GS_NU] + iu;
}

#endif
