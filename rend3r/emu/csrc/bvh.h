/* A bounding volume hierarchy over the shapes (rend3r/emu/bvh.py builds it once per frame;
 * kernels.c bvh_build, bvh_refit).
 *
 * The topology depends on the shapes' centres only. Each bundle of rays then gets its own
 * boxes (bvh_refit): a node's box holds the balls (centre, cull radius) of its shapes, the
 * radii being those of that bundle (bounds.h), padded outwards, and a node's floor is the
 * least depth floor below it. A line that misses a node's box passes farther than the
 * cull radius from every centre below it, so each of those shapes is provably missed, as
 * the per-shape tests would find; a node whose floor lies beyond every lane's nearest hit
 * holds no shape that can win or tie. Skipping such nodes changes which shapes are
 * tested, never the nearest hit (the tie rule orders by index, not by testing order).
 */
#ifndef REND3R_BVH_H
#define REND3R_BVH_H

#include <math.h>
#include <stdint.h>

#include "kernels.h"
#include "simd.h"

/* Shapes per leaf, at most, and the deepest a tree of 2**19 shapes gets (median splits:
 * ceil(log2(n / BVH_LEAF)) + 1 levels), with room to spare for traversal stacks. */
#define BVH_LEAF 4
#define BVH_STACK 64

/* A line's parameter interval within one slab, [near, far], from (lo - o) * inv and
 * (hi - o) * inv: NaN (a line in the slab's plane, or NaN operands) gives every t. */
static inline void slab4(f64x4 t1, f64x4 t2, f64x4 *near, f64x4 *far)
{
    i64x4 nan = (t1 != t1) | (t2 != t2);
    const f64x4 inf = {INFINITY, INFINITY, INFINITY, INFINITY};
    f64x4 lo = (f64x4)SEL_BITS((u64x4)(t1 < t2), (u64x4)t1, (u64x4)t2);
    f64x4 hi = (f64x4)SEL_BITS((u64x4)(t1 < t2), (u64x4)t2, (u64x4)t1);
    lo = (f64x4)SEL_BITS((u64x4)nan, (u64x4)-inf, (u64x4)lo);
    hi = (f64x4)SEL_BITS((u64x4)nan, (u64x4)inf, (u64x4)hi);
    *near = (f64x4)SEL_BITS((u64x4)(lo > *near), (u64x4)lo, (u64x4)*near);
    *far = (f64x4)SEL_BITS((u64x4)(hi < *far), (u64x4)hi, (u64x4)*far);
}

/* Lanes whose line o + t inv^-1 (any t) provably misses the box: the slabs' intervals do
 * not meet, by more than their rounding (each t carries a relative error of a few ulps:
 * a subtraction and a product of exact doubles). NaN never misses. */
static inline i64x4 box_missed4(const double *bx, f64x4 o0, f64x4 o1, f64x4 o2, f64x4 i0, f64x4 i1, f64x4 i2)
{
    const f64x4 inf = {INFINITY, INFINITY, INFINITY, INFINITY};
    f64x4 near = -inf, far = inf;
    slab4((bx[BV_LO] - o0) * i0, (bx[BV_HI] - o0) * i0, &near, &far);
    slab4((bx[BV_LO + 1] - o1) * i1, (bx[BV_HI + 1] - o1) * i1, &near, &far);
    slab4((bx[BV_LO + 2] - o2) * i2, (bx[BV_HI + 2] - o2) * i2, &near, &far);
    const f64x4 shrink = {1.0 - 1e-12, 1.0 - 1e-12, 1.0 - 1e-12, 1.0 - 1e-12};
    const f64x4 grow = {1.0 + 1e-12, 1.0 + 1e-12, 1.0 + 1e-12, 1.0 + 1e-12};
    f64x4 a = near * (f64x4)SEL_BITS((u64x4)(near > 0), (u64x4)shrink, (u64x4)grow);
    f64x4 b = far * (f64x4)SEL_BITS((u64x4)(far > 0), (u64x4)grow, (u64x4)shrink);
    return a > b;
}

#endif
