/* The cull tests of bounds.h for four rays at once (double lanes).
 *
 * primary_cull4: rays from the camera, against one shape's primary cull data (pc, see
 *   primary_shapes in kernels.c): off the line, or behind the camera.
 * misses4: rays with their own origins (shadow rays), against one shape's centre and cull
 *   radius: off the line, or the shape behind the origin.
 * A set lane means "provably no hit"; NaN anywhere leaves the lane clear.
 */
#ifndef REND3R_CULL_H
#define REND3R_CULL_H

#include <math.h>

#include "bounds.h"
#include "kernels.h"
#include "simd.h"

/* Off the line: |v|^2 - (v.d)^2/|d|^2 > r^2, tested times |d|^2 (no division). */
INLINE i64x4 primary_off4(const double *pc, f64x4 d0, f64x4 d1, f64x4 d2, f64x4 dd)
{
    f64x4 vd = pc[PC_V] * d0 + pc[PC_V + 1] * d1 + pc[PC_V + 2] * d2;
    return pc[PC_VV] * dd - vd * vd > pc[PC_R2] * dd;
}

/* Off the line, or behind the camera. */
INLINE i64x4 primary_cull4(const double *pc, f64x4 d0, f64x4 d1, f64x4 d2, f64x4 dd, f64x4 len)
{
    f64x4 vd = pc[PC_V] * d0 + pc[PC_V + 1] * d1 + pc[PC_V + 2] * d2;
    i64x4 off = pc[PC_VV] * dd - vd * vd > pc[PC_R2] * dd;
    return off | (-pc[PC_MEAN2] * vd - len * pc[PC_BEHIND] > 0.015625);
}

/* primary_cull4 for eight float directions d (ww = d.d and len = sqrt(ww), computed in
 * float, ww in [2**-40, 2**40]) against a shape whose |v| lies in [2**-20, 2**40]
 * (kernels.c primary_shapes; else its terms are NaN and nothing is culled), in float.
 * Off the line: as bvh.h cone_missed8, with |v| for the axis's unit length, the computed
 * v x d lies within 7u|v||d| of the exact one (u = 2**-24), so against the threshold
 * (sqrt(r2) + 8u|v|)^2 (1 + 10u) a lane reported off has |v x d| > |d| sqrt(r2).
 * Behind: v.d is computed within 4u|v||d|, mean2 within u, len within 2.5u of |d|; the
 * behind term widened to (B + 7u mean2 |v|)(1 + 4u) and the bound 2**-6 to
 * 2**-6 (1 + 2**-22) leave -mean2 v.d - |d| B > 2**-6 whenever the float test holds.
 * No product overflows in these ranges, and an underflow's error (2**-149) is far below
 * the margins. NaN never culls. */
static inline i32x8 primary_culled8(const double *pc, f32x8 d0, f32x8 d1, f32x8 d2, f32x8 ww, f32x8 len)
{
    float v0 = (float)pc[PC_V32], v1 = (float)pc[PC_V32 + 1], v2 = (float)pc[PC_V32 + 2];
    f32x8 vd = v0 * d0 + v1 * d1 + v2 * d2;
    i32x8 off = cross2_8(v0, v1, v2, d0, d1, d2) > ww * (float)pc[PC_T32];
    return off | (-(float)pc[PC_M32] * vd - len * (float)pc[PC_B32] > 0x1.000004p-6f);
}

INLINE i64x4 misses4(const double *b, double r, f64x4 o0, f64x4 o1, f64x4 o2, f64x4 d0, f64x4 d1, f64x4 d2,
                            double u, double tiny)
{
    i64x4 none = {0, 0, 0, 0};
    if (!(r < INFINITY))
        return none;
    f64x4 v0 = b[B_CENTER] - o0, v1 = b[B_CENTER + 1] - o1, v2 = b[B_CENTER + 2] - o2;
    f64x4 vv = v0 * v0 + v1 * v1 + v2 * v2, vd = v0 * d0 + v1 * d1 + v2 * d2, dd = d0 * d0 + d1 * d1 + d2 * d2;
    i64x4 off = vv * dd - vd * vd > (r * r * (1.0 + BOUND_SLACK) + 1e-12 * vv) * dd;
    double smin = b[B_SMIN], smax = b[B_SMAX];
    f64x4 dist = sqrt4(vv), dlen = sqrt4(dd), m = smin * smin * dd;
    const f64x4 one = {1.0, 1.0, 1.0, 1.0};
    m = (f64x4)SEL_BITS((u64x4)(m < 1.0), (u64x4)m, (u64x4)one);
    f64x4 uu = u + tiny / m;
    f64x4 k = ((smax * smax - smin * smin) / 2.0 + 64.0 * uu * smax * smax) * dist;
    i64x4 behind = (dist > r) & (-((smax * smax + smin * smin) / 2.0) * vd - dlen * k > 0.015625);
    return off | behind;
}

#endif
