/* A bounding volume hierarchy over the shapes (rend3r/emu/bvh.py builds it once per frame;
 * kernels.c bvh_build, bvh_refit).
 *
 * The topology depends on the shapes' centres only. Each bundle of rays then gets its own
 * bounds (bvh_refit) around the balls (centre, cull radius) of the shapes below a node,
 * the radii being that bundle's (bounds.h): for lines through one apex (primary rays
 * from the camera; a point light's shadow rays, whose radii cover the rounding of l) the
 * double cone around the apex holding every line that meets one of the balls; for
 * parallel lines (a directional light's) the box holding the balls' discs on two axes
 * normal to them. A line outside a node's bound passes farther than the cull radius
 * from every centre below it, so each of those shapes is provably missed, as the
 * per-shape tests would find (parallel lines also get each shape's own box, a leaf of
 * one, which shadow packets test before a shape's own tests); and a node's floor is the least depth floor below it: a
 * node whose floor lies beyond every lane's nearest hit
 * holds no shape that can win or tie. Skipping such nodes changes which shapes are
 * tested, never the nearest hit (the tie rule orders by index, not by testing order).
 */
#ifndef REND3R_BVH_H
#define REND3R_BVH_H

#include <math.h>
#include <stdint.h>

#include "kernels.h"
#include "simd.h"

/* Shapes per leaf, at most, and the room of the traversal stacks: a tree of 2**19 shapes
 * is at most 30 levels of Morton bits deep plus ceil(log2(n / BVH_LEAF)) + 1 levels of
 * median splits below them (kernels.c bvh_build, which also ends a branch in a leaf
 * before it outgrows the stacks). */
#define BVH_LEAF 4
#define BVH_STACK 64

/* Lanes whose line through the apex along w (w: the lane's direction, ww = |w|^2) lies
 * outside a node's cone: |w x axis|^2 > ww sin^2, the squared sine of the angle between
 * them exactly where it is small (no cancellation, unlike the cosine); the cone's sine
 * is widened by 1e-9, far beyond these products' few ulps. NaN never lies outside. */
static inline i64x4 cone_missed4(const double *b, f64x4 w0, f64x4 w1, f64x4 w2, f64x4 ww)
{
    f64x4 c0 = w1 * b[BV_AXIS + 2] - w2 * b[BV_AXIS + 1];
    f64x4 c1 = w2 * b[BV_AXIS] - w0 * b[BV_AXIS + 2];
    f64x4 c2 = w0 * b[BV_AXIS + 1] - w1 * b[BV_AXIS];
    return c0 * c0 + c1 * c1 + c2 * c2 > ww * b[BV_SIN2];
}

/* cone_missed4 for a float packet's directions w (ww: w.w in float, in [2**-100, 2**100] on
 * every lane), in float: the axis rounded to floats (each component within u = 2**-24 of
 * its own), the products and sums rounded. Each computed component of w x axis is then
 * within 3u|w| of the exact one, the rounded axis adds at most u|w|, so the computed cross
 * product lies within 7u|w| of the exact one; the sum of its squares and ww x sin2 carry
 * relative errors of at most 3.1u and 4u. The node's squared sine is widened to
 * (sin + 8u)^2 (1 + 10u), rounded up (kernels.c bvh_refit), so a lane reported outside has
 * |w x axis| + 7u|w| > |w| (sin + 8u): outside the cone, as the double test would find.
 * Within that range no product overflows and none underflows by more than 2**-149, far
 * below u|w|. NaN never lies outside. */
static inline i32xF cone_missed_f(const double *b, f32xF w0, f32xF w1, f32xF w2, f32xF ww)
{
    const float *f = node32c(b, BV_F32);
    return cross2_f(f[F32_AXIS], f[F32_AXIS + 1], f[F32_AXIS + 2], w0, w1, w2) > ww * f[F32_SIN2];
}

/* flat_missed4 for a float packet's lanes: u and v rounded to floats, the box b32 (u0, u1,
 * v0, v1) rounded outwards (bounds.h round32). Rounding is monotonic, so u >= u0 gives
 * fl(u) >= fl(u0) >= b32[0], and likewise at the other sides: a lane inside the box is
 * never reported outside, whatever the magnitudes (overflow included). */
static inline i32xF flat_missed_f(const float *b32, f32xF u, f32xF v)
{
    return (u < b32[0]) | (u > b32[1]) | (v < b32[2]) | (v > b32[3]);
}

/* Lanes whose parallel line, at (u, v) on the axes normal to the lines, lies outside a
 * node's box. NaN never lies outside. */
static inline i64x4 flat_missed4(const double *b, f64x4 u, f64x4 v)
{
    return (u < b[BV_U0]) | (u > b[BV_U1]) | (v < b[BV_V0]) | (v > b[BV_V1]);
}

#endif
