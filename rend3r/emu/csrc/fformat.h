/* Any binary format eEmM (E exponent bits 2..11, M fraction bits 1..51) held in double
 * lanes: the working precision of the _fmt kernels (rend3r/precision/formats.py names the
 * formats; fp16, fp32 and fp64 have kernels of their own).
 *
 * An operation of the format is computed in double and rounded once more to the format,
 * nearest even. For M <= 25 double has 53 >= 2(M+1) + 2 bits and the double rounding is
 * innocuous (Figueroa 1995). For wider M the double result is first made "round to odd"
 * from its exact error (TwoSum, Dekker's TwoProduct, the residual of a quotient or a
 * square root): an inexact result whose last bit is even moves one ulp towards the exact
 * value. Rounding a round-to-odd value to nearest at a precision at least two bits shorter
 * gives the correctly rounded result (Boldo and Melquiond 2008), so every M <= 50 rounds
 * correctly; M = 51 has one bit to spare and settles its midpoints from the error's sign
 * instead (to_side4). Results below the smallest normal number are rounded to
 * the subnormal grid by adding and subtracting a power of two; ftz then flushes what is
 * still below it (so values that round up to the smallest normal number keep it, as in
 * the fp16 kernels and rend3r/precision/rounding.py), or, judging tininess before
 * rounding (Format.before), what was below it before rounding.
 *
 * The format is a kernel argument (Shapes.format, shape_tables' last argument): each
 * kernel copies it to a thread-local at entry (FORMAT_ENTER), where R reads it.
 *
 * Per-stage formats (rend3r/precision/stages.py): the argument is then an array, the
 * load format (exact float16: scene values enter unrounded) with `stages` set, then one
 * format per stage in the order of the enum below; STAGE(k) in datapath.inc makes stage
 * k's format current, and every operation first rounds its operands to it (the converter
 * a value crosses between stages; a value already in the format is unchanged).
 */
#ifndef REND3R_FFORMAT_H
#define REND3R_FFORMAT_H

#include <math.h>
#include <stdint.h>

#include "kernels.h"
#include "simd.h"

/* The stages, in the order of rend3r/precision/stages.py STAGES (tests/precision/test_stages.py). */
enum { STAGE_CAMERA, STAGE_TRANSFORM, STAGE_QUADRATIC, STAGE_DISCRIMINANT, STAGE_SQRT, STAGE_DISTANCE, STAGE_HIT,
       STAGE_LIGHTING, STAGE_COLOUR, STAGE_COUNT };

static _Thread_local Format format_now;
static _Thread_local const Format *format_stages;  /* per-stage map (NULL: one format) */

#define FORMAT_ENTER(f) (format_now = *(f), format_stages = (f)->stages ? (f) : NULL)
#define FORMAT_STAGE(k) (format_stages != NULL ? (void)(format_now = format_stages[1 + (k)]) : (void)0)

#define F64_SIGN 0x8000000000000000ull
#define F64_INF 0x7FF0000000000000ull

/* x rounded to the format (lane by lane): NaN kept, overflow to infinity. */
static inline f64x4 round_format4(f64x4 x)
{
    const Format *f = &format_now;
    if (f->drop == 0)  /* e11m52 (a stage in fp64): double itself */
        return x;
    u64x4 b = (u64x4)x, a = b & ~F64_SIGN, sign = b & F64_SIGN;
    uint64_t drop = (uint64_t)f->drop, keep = ~((1ull << drop) - 1);
    u64x4 r = (b + ((1ull << drop) >> 1) - 1 + ((b >> drop) & 1)) & keep;  /* nearest even at M bits */
    r = SEL_BITS((u64x4)((i64x4)(r & ~F64_SIGN) > (int64_t)f->max_bits), sign | F64_INF, r);
    f64x4 m = (f64x4)a, magic = (f64x4){0} + f->subnormal_magic;  /* below 2**emin: the subnormal grid */
    r = SEL_BITS((u64x4)((i64x4)a < (int64_t)f->min_normal_bits), (u64x4)((m + magic) - magic) | sign, r);
    if (f->ftz)  /* what the grid left below 2**emin (before: what was below it unrounded) */
        r = SEL_BITS((u64x4)((i64x4)(f->before ? a : r & ~F64_SIGN) < (int64_t)f->min_normal_bits), sign, r);
    return (f64x4)SEL_BITS((u64x4)((i64x4)a > (int64_t)F64_INF), b, r);
}

/* d moved to round-to-odd from its exact error e (the exact value is d + e; NaN e: none). */
static inline f64x4 to_odd4(f64x4 d, f64x4 e)
{
    u64x4 b = (u64x4)d, a = b & ~F64_SIGN;
    i64x4 move = ((e < 0) | (e > 0)) & ((b & 1) == 0) & ((i64x4)a < (int64_t)F64_INF);
    i64x4 away = (i64x4)(((u64x4)e ^ b) & F64_SIGN) == 0;  /* e has d's sign: magnitude up */
    u64x4 stepped = SEL_BITS((u64x4)away, b + 1, b - 1);
    stepped = SEL_BITS((u64x4)(a == 0), ((u64x4)e & F64_SIGN) | 1, stepped);  /* d = 0: the least subnormal */
    return (f64x4)SEL_BITS((u64x4)move, stepped, b);
}

/* For M = 51 double keeps one bit more than the format, too few for round to odd in the
 * normal range: there an inexact d whose last bit is set lies on a midpoint of the format,
 * and one ulp towards the exact value (d + e) settles the rounding; below 2**emin the
 * format keeps fewer bits and round to odd applies. */
static inline f64x4 to_side4(f64x4 d, f64x4 e)
{
    if (format_now.drop == 0)
        return d;
    if (format_now.drop > 1)
        return to_odd4(d, e);
    u64x4 b = (u64x4)d, a = b & ~F64_SIGN;
    i64x4 move = ((e < 0) | (e > 0)) & ((b & 1) == 1) & ((i64x4)a < (int64_t)F64_INF);
    i64x4 away = (i64x4)(((u64x4)e ^ b) & F64_SIGN) == 0;
    u64x4 normal = SEL_BITS((u64x4)move, SEL_BITS((u64x4)away, b + 1, b - 1), b);
    return (f64x4)SEL_BITS((u64x4)((i64x4)a < (int64_t)format_now.min_normal_bits), (u64x4)to_odd4(d, e), normal);
}

/* Dekker's TwoProduct without a fused multiply-add: x*y = p + e exactly (no overflow). */
static inline f64x4 product_error4(f64x4 x, f64x4 y, f64x4 p)
{
    const double split = 134217729.0;  /* 2**27 + 1 */
    f64x4 cx = split * x, cy = split * y;
    f64x4 xh = cx - (cx - x), xl = x - xh, yh = cy - (cy - y), yl = y - yh;
    return ((xh * yh - p) + xh * yl + xl * yh) + xl * yl;
}

/* Operands into the current stage's format (per-stage maps only). */
#define CONVERT(x) (format_stages != NULL ? round_format4(x) : (x))

static inline f64x4 format_add4(f64x4 a, f64x4 b)
{
    a = CONVERT(a);
    b = CONVERT(b);
    f64x4 d = a + b;
    if (format_now.wide) {
        f64x4 bv = d - a;
        d = to_side4(d, (a - (d - bv)) + (b - bv));
    }
    return round_format4(d);
}

static inline f64x4 format_mul4(f64x4 a, f64x4 b)
{
    a = CONVERT(a);
    b = CONVERT(b);
    f64x4 d = a * b;
    if (format_now.wide)
        d = to_side4(d, product_error4(a, b, d));
    return round_format4(d);
}

/* a/b = d + r/b with r = a - d*b exact: the error has the sign of r*b. */
static inline f64x4 format_div4(f64x4 a, f64x4 b)
{
    a = CONVERT(a);
    b = CONVERT(b);
    f64x4 d = a / b;
    if (format_now.wide) {
        f64x4 p = d * b, r = (a - p) - product_error4(d, b, p);
        d = to_side4(d, (f64x4)((u64x4)r ^ ((u64x4)b & F64_SIGN)));
    }
    return round_format4(d);
}

/* sqrt(a) = d + e with e of the sign of a - d*d. */
static inline f64x4 format_sqrt4(f64x4 a)
{
    a = CONVERT(a);
    f64x4 d;
    for (int i = 0; i < 4; i++)
        d[i] = sqrt(a[i]);
    if (format_now.wide) {
        f64x4 p = d * d;
        d = to_side4(d, (a - p) - product_error4(d, d, p));
    }
    return round_format4(d);
}

#endif
