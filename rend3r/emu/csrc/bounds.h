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

/* Four lanes at a time, for the per-shape passes (kernels.c primary_shapes and
 * shadow_shapes compute four shapes at once: their square roots and divisions are
 * independent from shape to shape). Lane operations are the scalar IEEE operations. */
INLINE f64x4 splat4(double x) { return (f64x4){x, x, x, x}; }
INLINE f64x4 sel4(i64x4 m, f64x4 a, f64x4 b) { return (f64x4)SEL_BITS(m, (i64x4)a, (i64x4)b); }
INLINE f64x4 min_num4(f64x4 a, f64x4 b) { return sel4((a <= b) | (b != b), a, b); }
INLINE f64x4 max_num4(f64x4 a, f64x4 b) { return sel4((a >= b) | (b != b), a, b); }
INLINE i64x4 finite4(f64x4 x) { return (x == x) & (x < INFINITY) & (x > -INFINITY); }
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

/* round32 on four lanes. */
INLINE f64x4 round32_4(f64x4 x, int down)
{
    f32x4 w = __builtin_convertvector(x, f32x4);
    f64x4 back = __builtin_convertvector(w, f64x4);
    u32x4 step = (u32x4)__builtin_convertvector(down ? back > x : back < x, i32x4);
    u32x4 bits = (u32x4)w, side = {0u, 0u, 0u, 0u};
    u32x4 away = (u32x4)((bits >> 31) == side + (uint32_t)down), zero = (u32x4)((bits & 0x7fffffffu) == 0);
    u32x4 next = bits - 1u + (away & 2u), stepped = ((down ? 0x80000001u : 1u) & zero) | (next & ~zero);
    return __builtin_convertvector((f32x4)((stepped & step) | (bits & ~step)), f64x4);
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

/* dist bounds the distance from the rays' origins to the centre, dmin the rays' direction
 * lengths from below, limit is product_limit(); INFINITY: no bound. Four shapes. */
INLINE f64x4 cull_radius4(f64x4 smin, f64x4 smax, f64x4 dist, double dmin, double u, double tiny, double limit)
{
    f64x4 dhat = smin * dmin;  /* |D| in normal space, at least */
    f64x4 uu = u + tiny / min_num4(splat4(1.0), dhat * dhat);
    f64x4 mm = smax * dist;
    f64x4 cap = sqrt4(1.0 + limit / (dhat * dhat));  /* a larger |S| overflows a2*c2 */
    mm = sel4(mm < cap, mm, cap);
    f64x4 h = sqrt4(1.0 + 24.0 * uu * (1.0 + mm * mm)) + 16.0 * uu * mm * (1.0 + smax / smin);
    f64x4 r = h / smin * (1.0 + BOUND_SLACK) + BOUND_SLACK;
    return sel4((uu <= MAX_UU) & finite4(r), r, splat4(INFINITY));
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

/* dist: from the apex to the centre; directions between dmin and dmax long; 0: no claim.
 * Four shapes. */
INLINE f64x4 depth_floor4(f64x4 smin, f64x4 smax, f64x4 dist, double dmin, double dmax, double u, double tiny)
{
    const f64x4 zero = splat4(0.0);
    f64x4 dlo = smin * dmin;
    f64x4 uu = u + tiny / min_num4(splat4(1.0), min_num4(dlo * dlo, splat4(dmin * dmin)));
    f64x4 e = 32.0 * uu * (1.0 + smax / smin);  /* transform error, relative */
    f64x4 s_lo = smin * dist * (1.0 - BOUND_SLACK) * (1.0 - e), s_hi = smax * dist * (1.0 + BOUND_SLACK) * (1.0 + e);
    f64x4 b_max = 2.0 * s_hi * (1.0 + 4.0 * uu), a_hi = 2.0 * (1.0 + 4.0 * uu);
    f64x4 c_lo = 2.0 * (s_lo * s_lo - 1.0) - 8.0 * uu * (s_hi * s_hi + 1.0);
    f64x4 up2 = (1.0 + uu) * (1.0 + uu), down2 = (1.0 - uu) * (1.0 - uu);  /* products, not pow(): the */
    f64x4 alpha = up2 * up2, beta = down2 * down2, ac = 2.0 * (1.0 - 4.0 * uu) * c_lo;  /* slack covers their ulps */
    f64x4 d_lo = dlo * (1.0 - e);
    f64x4 b_min = sqrt4(max_num4(zero, ((1.0 - uu) * ac - tiny / (d_lo * d_lo)) / (1.0 + uu)));
    f64x4 g_min = b_min - sqrt4(max_num4(zero, alpha * b_min * b_min - beta * ac));
    f64x4 g_max = b_max - sqrt4(max_num4(zero, alpha * b_max * b_max - beta * ac));
    f64x4 t_lo = (1.0 - uu) * (1.0 - uu) * min_num4(g_min, g_max) / a_hi / (smax * (1.0 + e));
    f64x4 floor = beta * down2 * (1.0 - 4.0 * uu) * t_lo * t_lo * (1.0 - BOUND_SLACK);
    i64x4 ok = (uu <= MAX_UU) & (e < 0.25) & (c_lo > 0) & (b_min > 0) & (t_lo >= 2.0 * sqrt(tiny) * dmax);
    return sel4(ok & finite4(floor), floor, zero);
}

#endif
