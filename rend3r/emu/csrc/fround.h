/* float16 rounding of float32 values, and the rounding modes of the working precision.
 *
 * A float16 operation is computed in float32 and rounded once more to float16, nearest
 * even: float32 carries 24 >= 2*11 + 2 significand bits, so the double rounding is
 * innocuous for + - * / and sqrt (Figueroa 1995) and the result is the correctly rounded
 * float16 operation. round16 works on the float32 bit pattern as rend3r/emu/arith.py's
 * _round16_f32 does (tests/emu/test_native.py compares them on every exponent).
 */
#ifndef REND3R_FROUND_H
#define REND3R_FROUND_H

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#error "the kernels need float and double arithmetic evaluated in their own format (FLT_EVAL_METHOD 0)"
#endif

static inline uint32_t f32_bits(float x) { uint32_t b; memcpy(&b, &x, 4); return b; }
static inline float bits_f32(uint32_t b) { float x; memcpy(&x, &b, 4); return x; }

/* x rounded to the nearest-even float16 value, held in a float. */
static inline float round16(float x, int ftz)
{
    uint32_t b = f32_bits(x), a = b & 0x7FFFFFFFu, sign = b & 0x80000000u;
    if (a >= 0x38800000u && a < 0x477FF000u)         /* 2**-14 <= |x| < 65520: normal */
        return bits_f32((b + 0xFFFu + ((b >> 13) & 1u)) & 0xFFFFE000u);
    if (a >= 0x477FF000u)                             /* overflow, infinity, NaN */
        return a > 0x7F800000u ? x : bits_f32(sign | 0x7F800000u);
    if (ftz)                                          /* 2**-14 - 2**-25 and up round to 2**-14 */
        return bits_f32(a < 0x387FE000u ? sign : (sign | 0x38800000u));
    return bits_f32(f32_bits(rintf(fabsf(x) * 16777216.0f) * (1.0f / 16777216.0f)) | sign);
}

#endif
