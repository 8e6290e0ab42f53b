/* Narrow formats eEmM in float lanes: the working precision of the _nar kernels, for
 * M <= 10 and either E <= 7 or E = 8 with subnormals flushed (rend3r/emu/native.py
 * narrow() picks them; e6m9, bf16, tf32, e4m3, fp16 judging tininess before rounding).
 * Eight float lanes where the format kernels (fformat.h) have four double ones.
 *
 * An operation is computed in float32 and rounded once more to the format, nearest even,
 * as the fp16 kernels do: float32 carries 24 >= 2(M+1) + 2 significand bits, so the
 * double rounding is innocuous for + - * / and sqrt (Figueroa 1995). That theorem ignores
 * the exponent range, and here the range is safe too:
 * - E <= 7: the format's whole range, subnormals included (down to 2**-72), lies inside
 *   float32's normal range, and a float32 result below 2**-126 rounds to zero in the
 *   format either way; a result beyond float32's range overflows both.
 * - E = 8 with ftz: every operand is normal or zero, so a product (22 bits at most) and a
 *   sum (on the grid 2**(-126 - M)) near 2**-126 are exact in float32, and a quotient or
 *   square root of (M+1)-bit significands lies at least 2**-12 (relative) from a
 *   rounding boundary of the format, far beyond float32's error; below the boundary the
 *   result is flushed to its signed zero, whatever float32's subnormal kept. The same
 *   holds at the overflow threshold. (With ieee subnormals a float32 subnormal product
 *   can be rounded onto a midpoint of the format's subnormal grid: those formats stay on
 *   the double lanes of fformat.h.)
 * The same exactness makes tininess judged before rounding (Format.before) correct: no
 * exact result below 2**emin rounds up to it in float32.
 *
 * The format is the kernels' Format argument (one format: per-stage maps run in
 * fformat.h); each kernel derives the float32 constants at entry (NARROW_ENTER).
 */
#ifndef REND3R_FNARROW_H
#define REND3R_FNARROW_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "kernels.h"
#include "simd.h"

typedef struct {
    uint32_t drop;          /* 23 - M: the float fraction bits a rounding drops */
    uint32_t max_bits;      /* the largest finite value, as float bits */
    int32_t min_normal_bits; /* 2**emin, as float bits */
    float subnormal_magic;  /* 2**(emin - M + 23): adding and subtracting it rounds to the subnormal grid */
    int32_t ftz, before;
} Narrow;

static _Thread_local Narrow narrow_now;

/* The float32 form of a double-lane Format (kernels.h) of a narrow format. */
static inline Narrow narrow_of(const Format *f)
{
    Narrow n;
    double max, min_normal;
    memcpy(&max, &f->max_bits, 8);
    memcpy(&min_normal, &f->min_normal_bits, 8);
    float fmax = (float)max, fmin = (float)min_normal;  /* exact: the format's values are floats */
    memcpy(&n.max_bits, &fmax, 4);
    memcpy(&n.min_normal_bits, &fmin, 4);
    n.drop = (uint32_t)(f->drop - 29);
    n.subnormal_magic = (float)(f->subnormal_magic * 0x1p-29);
    n.ftz = f->ftz;
    n.before = f->before;
    return n;
}

#define NARROW_ENTER(f) (narrow_now = narrow_of(f))

/* Lanes in the format's subnormal range (0 < |x| < 2**emin): to its subnormal grid, then
 * (ftz) flushed where below 2**emin after rounding, or before (Format.before). Out of line:
 * the rare path of the hundreds of roundings of a kernel. */
static __attribute__((noinline)) u32x8 narrow_small8(u32x8 b, u32x8 r, i32x8 small)
{
    const Narrow *f = &narrow_now;
    u32x8 a = b & 0x7FFFFFFFu, sign = b & 0x80000000u;
    f32x8 magic = (f32x8){0} + f->subnormal_magic;
    u32x8 grid = (u32x8)(((f32x8)a + magic) - magic) | sign;
    if (f->ftz)
        grid = SEL_BITS((u32x8)((i32x8)(f->before ? a : grid & 0x7FFFFFFFu) < f->min_normal_bits), sign, grid);
    return SEL_BITS((u32x8)small, grid, r);
}

/* x rounded to the format (lane by lane): nearest even at M bits, overflow to infinity,
 * NaN kept; only packets with a lane in the subnormal range take narrow_small8. */
INLINE f32x8 round_narrow8(f32x8 x)
{
    const Narrow *f = &narrow_now;
    u32x8 b = (u32x8)x;
    i32x8 a = (i32x8)(b & 0x7FFFFFFFu);  /* |x|'s bits: signed comparisons order them */
    uint32_t drop = f->drop;
    u32x8 r = (b + ((1u << drop) >> 1) - 1u + ((b >> drop) & 1u)) & ~((1u << drop) - 1u);
    r = SEL_BITS((u32x8)((i32x8)(r & 0x7FFFFFFFu) > (int32_t)f->max_bits), (b & 0x80000000u) | 0x7F800000u, r);
    r = SEL_BITS((u32x8)(a > 0x7F800000), b, r);
    i32x8 small = (a > 0) & (a < f->min_normal_bits);
    if (mask_bits_32x8(small) != 0)
        r = narrow_small8(b, r, small);
    return (f32x8)r;
}

#endif
