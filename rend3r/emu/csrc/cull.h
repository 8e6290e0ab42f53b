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

/* primary_cull4 for a float packet's directions d (ww = d.d and len = sqrt(ww), computed in
 * float, ww in [2**-40, 2**40]) against a shape's float terms p (P32_COLUMNS) whose |v| lies in [2**-20, 2**40]
 * (kernels.c primary_shapes; else its terms are NaN and nothing is culled), in float.
 * Off the line: as bvh.h cone_missed_f, with |v| for the axis's unit length, the computed
 * v x d lies within 7u|v||d| of the exact one (u = 2**-24), so against the threshold
 * (sqrt(r2) + 8u|v|)^2 (1 + 10u) a lane reported off has |v x d| > |d| sqrt(r2).
 * Behind: v.d is computed within 4u|v||d|, mean2 within u, len within 2.5u of |d|; the
 * behind term widened to (B + 7u mean2 |v|)(1 + 4u) and the bound 2**-6 to
 * 2**-6 (1 + 2**-22) leave -mean2 v.d - |d| B > 2**-6 whenever the float test holds.
 * No product overflows in these ranges, and an underflow's error (2**-149) is far below
 * the margins. NaN never culls. */
static inline i32xF primary_culled_f(const float *p, f32xF d0, f32xF d1, f32xF d2, f32xF ww, f32xF len)
{
    float v0 = p[P32_V], v1 = p[P32_V + 1], v2 = p[P32_V + 2];
    f32xF vd = v0 * d0 + v1 * d1 + v2 * d2;
    i32xF off = cross2_f(v0, v1, v2, d0, d1, d2) > ww * p[P32_T];
    return off | (-p[P32_M] * vd - len * p[P32_B] > 0x1.000004p-6f);
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

/* Shadow rays P + t l towards a point light against every shape below a node, from the
 * node's terms pk (PK_COLUMNS, kernels.c refit_cones): the lanes for which misses4's
 * behind test holds for each of them, so none can block them. For a centre c in the box
 * (lo, hi): (P - c).l >= P.l - max over the box of c.l =: x, and |P - c| lies between the
 * box's distance from P, n, and its farthest corner's, f; so with the node's least mean2
 * m, largest K and largest radius R, mean2_c (P - c).l - K_c |l| |P - c| >=
 * m x - K |l| f (once x >= 0), and P lies outside c's cull radius when n > R
 * (docs/emulator.md 7.1). In double, x is lowered by 1e-12 of its terms' magnitudes, f
 * raised and n lowered by 1e-12, and the two products moved by 1e-12 the safe way, far
 * beyond double rounding; the box's NaN, mean2 0 or an infinite K or R claim nothing,
 * nor does a lane with NaN or infinity (pl = P.l in double). */
INLINE i64x4 point_behind4(const double *pk, f64x4 p0, f64x4 p1, f64x4 p2, f64x4 l0, f64x4 l1, f64x4 l2, f64x4 pl)
{
    const double *lo = pk + PK_LO, *hi = pk + PK_HI;
    i64x4 none = {0, 0, 0, 0};
    if (!(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2] && pk[PK_MEAN2] > 0 && pk[PK_K] < INFINITY
          && pk[PK_R] < INFINITY))
        return none;
    f64x4 cl = max4(l0 * lo[0], l0 * hi[0]) + max4(l1 * lo[1], l1 * hi[1]) + max4(l2 * lo[2], l2 * hi[2]);
    if (!mask_bits_64x4(pl - cl > 0))  /* no lane ahead of the box: the usual case, settled early */
        return none;
    f64x4 mag = abs4(p0 * l0) + abs4(p1 * l1) + abs4(p2 * l2) + abs4(l0) * MAX(fabs(lo[0]), fabs(hi[0]))
                + abs4(l1) * MAX(fabs(lo[1]), fabs(hi[1])) + abs4(l2) * MAX(fabs(lo[2]), fabs(hi[2]));
    f64x4 x = pl - cl - 1e-12 * mag;
    f64x4 f0 = max4(abs4(p0 - lo[0]), abs4(p0 - hi[0])), f1 = max4(abs4(p1 - lo[1]), abs4(p1 - hi[1]));
    f64x4 f2 = max4(abs4(p2 - lo[2]), abs4(p2 - hi[2]));
    f64x4 zero = {0, 0, 0, 0};
    f64x4 n0 = max4(max4(lo[0] - p0, p0 - hi[0]), zero), n1 = max4(max4(lo[1] - p1, p1 - hi[1]), zero);
    f64x4 n2 = max4(max4(lo[2] - p2, p2 - hi[2]), zero);
    f64x4 far = sqrt4(f0 * f0 + f1 * f1 + f2 * f2) * (1.0 + 1e-12);
    f64x4 near = sqrt4(n0 * n0 + n1 * n1 + n2 * n2) * (1.0 - 1e-12);
    f64x4 ll = sqrt4(l0 * l0 + l1 * l1 + l2 * l2);
    f64x4 ahead = pk[PK_MEAN2] * x * (1.0 - 1e-12) - pk[PK_K] * ll * far * (1.0 + 1e-12);
    return (near > pk[PK_R]) & (ahead > 0.015625 * (1.0 + 1e-9)) & (x > 0);
}

#endif
