/* Conservative bounds, in double: when a ray provably cannot hit a shape, or cannot hit it
 * nearer than some distance, *as the working-precision raycaster computes it*
 * (docs/emulator.md section 7 derives each).
 *
 * cull_radius: a world radius around the centre; a ray whose line stays farther gets a
 *   negative computed discriminant.
 * misses: the line is farther than that, or the shape lies behind the ray's origin (then
 *   the computed b = 2 D.S and c2 are positive, sqrt(fl(b*b - a2*c2)) <= b and neither
 *   root is positive).
 * depth_floor: a lower bound of any computed sq_dist of a ray from one apex.
 * (cull_radius and depth_floor are computed lane by lane in the per-shape passes,
 * shape_bounds.inc.)
 */
#ifndef REND3R_BOUNDS_H
#define REND3R_BOUNDS_H

#include <math.h>

#include "kernels.h"
#include "simd.h"

#define BOUND_SLACK 1e-9

/* fmin and fmax (the other number when one is NaN), inline: without -ffinite-math-only
 * they are library calls. */
static inline double min_num(double a, double b)
{
    return a <= b || b != b ? a : b;
}

/* Four double lanes (cull.h, datapath.inc; the per-shape passes have their own lanes,
 * shape_bounds.inc). Lane operations are the scalar IEEE operations. */
INLINE f64x4 splat4(double x) { return (f64x4){x, x, x, x}; }
INLINE f64x4 abs4(f64x4 x) { return (f64x4)((i64x4)x & INT64_MAX); }

/* The bits of the float next to w (bits b, not NaN) towards -infinity (down) or
 * +infinity, w not at that end: they step away from zero on the side w moves to, towards
 * zero on the other, and a zero becomes the smallest subnormal of that sign (nextafterf,
 * without a call). Integer selects: the rounding's direction is random from shape to
 * shape, and mispredicted branches cost more than both candidates. */
static inline uint32_t step32(uint32_t b, int down)
{
    uint32_t away = -(uint32_t)((b >> 31) == (uint32_t)down);  /* all ones: moving away from zero */
    uint32_t zero = -(uint32_t)((b & 0x7fffffffu) == 0), next = b - 1 + (away & 2u);
    return ((down ? 0x80000001u : 1u) & zero) | (next & ~zero);
}

/* x rounded to a float, then to its neighbour towards -infinity (down) or +infinity when
 * the rounding went the other way; as a double (NaN stays NaN). */
static inline double round32(double x, int down)
{
    float w = (float)x;
    uint32_t b;
    memcpy(&b, &w, sizeof b);
    uint32_t step = -(uint32_t)(down ? (double)w > x : (double)w < x);  /* masks, not a branch */
    uint32_t pick = (step32(b, down) & step) | (b & ~step);
    memcpy(&w, &pick, sizeof w);
    return (double)w;
}

/* The largest float at most x, as a double (NaN stays NaN): a depth floor that float
 * lanes compare with their sq_dist stays a lower bound. */
static inline double floor32(double x)
{
    return round32(x, 1);
}

/* The least float at least x, as a double. */
static inline double ceil32(double x)
{
    return round32(x, 0);
}

/* The largest effective unit roundoff (u plus an underflow's absolute error over the
 * squared direction length in normal space, tiny / min(1, |D|^2)) the bounds are claimed
 * for: 2**-6, where the first-order error terms they sum still dominate. For float16
 * this asks |D| >= 2**-4, as before; fp32 and fp64 allow any direction that is not
 * near their own underflow. */
#define MAX_UU 0.015625
/* A finite a2*c2 is below the format's overflow threshold T (65520 for float16); with the
 * coefficients' rounding error allowed for, |D|^2 (|S|^2 - 1) stays below
 * T/4 * 1.02 / (1 - 2**-6)**2 for float16's u = 2**-11: that slack of 5.3% is about a
 * hundred roundings of 2**-11, and a coarser format takes it to the power u / 2**-11
 * (as many roundings of its own u). T infinite: no limit. */
static inline double product_limit(double overflow, double u)
{
    double slack = 1.02 / ((1.0 - 0.015625) * (1.0 - 0.015625));
    return overflow / 4.0 * (u > 0x1p-11 ? pow(slack, u * 0x1p11) : slack);
}

static inline int misses(const double *b, double r, double o0, double o1, double o2, double d0, double d1,
                         double d2, double u, double tiny)
{
    if (!(r < INFINITY))
        return 0;
    double v0 = b[B_CENTER] - o0, v1 = b[B_CENTER + 1] - o1, v2 = b[B_CENTER + 2] - o2;
    double vv = v0 * v0 + v1 * v1 + v2 * v2, vd = v0 * d0 + v1 * d1 + v2 * d2, dd = d0 * d0 + d1 * d1 + d2 * d2;
    if (vv - vd * vd / dd > r * r * (1.0 + BOUND_SLACK) + 1e-12 * vv)
        return 1;  /* off the line */
    double dist = sqrt(vv);
    if (!(dist > r))
        return 0;
    double smin = b[B_SMIN], smax = b[B_SMAX], dlen = sqrt(dd);
    double uu = u + tiny / min_num(1.0, (smin * dlen) * (smin * dlen));
    double mean2 = (smax * smax + smin * smin) / 2.0, spread2 = (smax * smax - smin * smin) / 2.0;
    double ahead = -vd / dlen;  /* (origin - centre) . d / |d| */
    return dlen * (mean2 * ahead - (spread2 + 64.0 * uu * smax * smax) * dist) > 0.015625;  /* behind */
}

/* A primary ray in double, with what the cull tests need of it (len: sqrt(dd) once the
 * behind test needs it, else -1). */
typedef struct { double d0, d1, d2, dd, len; } Ray;

static inline Ray ray_of(double d0, double d1, double d2)
{
    Ray r = {d0, d1, d2, d0 * d0 + d1 * d1 + d2 * d2, -1.0};
    return r;
}

/* misses() for rays from the camera, with the per-shape parts computed once per band
 * (rend3r/emu/raytracer.py primary_cull_table): pc holds v = centre - camera, |v|^2,
 * r^2 (1 + slack) + 1e-12 |v|^2, and mean2 and (spread2 + 64 uu smax^2) |v| of the
 * behind test (NaN when the camera lies within r, where the test does not apply), with uu
 * taken at the band's shortest direction, which only makes the test stricter. */
static inline int primary_cull(const double *pc, Ray *ray)
{
    double vd = pc[PC_V] * ray->d0 + pc[PC_V + 1] * ray->d1 + pc[PC_V + 2] * ray->d2;
    if (pc[PC_VV] * ray->dd - vd * vd > pc[PC_R2] * ray->dd)  /* |v|^2 - (v.d)^2/|d|^2 > r^2, times |d|^2 */
        return 1;
    if (!(pc[PC_BEHIND] == pc[PC_BEHIND]))
        return 0;
    if (ray->len < 0)
        ray->len = sqrt(ray->dd);
    return -pc[PC_MEAN2] * vd - ray->len * pc[PC_BEHIND] > 0.015625;
}

#endif
