/* SIMD packets: GCC/Clang vector extensions, 32 bytes wide (8 floats or 4 doubles).
 *
 * Without AVX the compiler splits each operation into two SSE (or NEON) operations; the
 * kernels are also built for AVX2 and chosen at load time. Lane operations are IEEE
 * operations of the element type, so a lane computes exactly what a scalar would.
 * Comparisons give masks (all ones or zero per lane) of the same-width signed integers.
 */
#ifndef REND3R_SIMD_H
#define REND3R_SIMD_H

#include <stdint.h>

/* Helpers of the kernels are inlined whatever their size: they pass vectors and structs
 * of vectors, which a call would spill to memory. */
#define INLINE static inline __attribute__((always_inline))

typedef float f32x8 __attribute__((vector_size(32)));
typedef uint32_t u32x8 __attribute__((vector_size(32)));
typedef int32_t i32x8 __attribute__((vector_size(32)));
typedef double f64x4 __attribute__((vector_size(32)));
typedef uint64_t u64x4 __attribute__((vector_size(32)));
typedef int64_t i64x4 __attribute__((vector_size(32)));
typedef int32_t i32x4 __attribute__((vector_size(16)));

/* Lanes 4h..4h+3 of a float packet, in double. */
#define F32_HALF(v, h) __builtin_convertvector(                                                    \
    (h) == 0 ? __builtin_shufflevector((v), (v), 0, 1, 2, 3) : __builtin_shufflevector((v), (v), 4, 5, 6, 7), f64x4)
/* Two four-lane double masks as one eight-lane float mask. */
#define MASK_8(lo, hi) __builtin_shufflevector(__builtin_convertvector((lo), i32x4),                \
                                               __builtin_convertvector((hi), i32x4), 0, 1, 2, 3, 4, 5, 6, 7)

/* Lanes of mask m: from a where set, else from b (integer vectors of one type). */
#define SEL_BITS(m, a, b) (((a) & (m)) | ((b) & ~(m)))

/* float16 rounding of 8 float lanes (fround.h round16, lane by lane): normal results by
 * integer rounding of the significand; overflow to infinity; NaN kept; below 2**-14
 * flushed (ftz; 2**-14 - 2**-25 and up go to 2**-14) or rounded to the subnormal grid
 * (adding and subtracting 2**23 rounds to an integer, nearest even). */
static __attribute__((noinline)) f32x8 round16x8_rare(f32x8 x, int ftz);

INLINE f32x8 round16x8(f32x8 x, int ftz)
{
    u32x8 b = (u32x8)x, a = b & 0x7FFFFFFFu;
    u32x8 normal = (u32x8)((a >= 0x38800000u) & (a < 0x477FF000u));
    int all = 1;
    for (int i = 0; i < 8; i++)
        all &= normal[i] != 0;
    if (all)
        return (f32x8)((b + 0xFFFu + ((b >> 13) & 1u)) & 0xFFFFE000u);
    return round16x8_rare(x, ftz);
}

/* round16x8 for packets with a lane that is zero, subnormal, overflowing or not finite:
 * out of line, so that the hundreds of roundings of a kernel stay small to compile. */
static f32x8 round16x8_rare(f32x8 x, int ftz)
{
    u32x8 b = (u32x8)x, a = b & 0x7FFFFFFFu, sign = b & 0x80000000u;
    u32x8 normal = (u32x8)((a >= 0x38800000u) & (a < 0x477FF000u));
    u32x8 r = (b + 0xFFFu + ((b >> 13) & 1u)) & 0xFFFFE000u;
    u32x8 big = SEL_BITS((u32x8)(a > 0x7F800000u), b, sign | 0x7F800000u), small;
    if (ftz) {
        small = SEL_BITS((u32x8)(a < 0x387FE000u), sign, sign | 0x38800000u);
    } else {
        f32x8 y = (f32x8)a * 16777216.0f;
        y = (y + 8388608.0f) - 8388608.0f;
        small = (u32x8)(y * (1.0f / 16777216.0f)) | sign;
    }
    return (f32x8)SEL_BITS(normal, r, SEL_BITS((u32x8)(a >= 0x477FF000u), big, small));
}

#endif
