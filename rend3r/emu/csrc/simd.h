/* SIMD packets: GCC/Clang vector extensions, 32 bytes wide (8 floats or 4 doubles; a float
 * packet's colours in double, 64 bytes), or 16 floats in a unit that asks for them
 * (FLOAT_LANES).
 *
 * Without AVX the compiler splits each operation into SSE (or NEON) operations; the
 * kernels are also built for AVX2 and chosen at load time. Lane operations are IEEE
 * operations of the element type, so a lane computes exactly what a scalar would.
 * Comparisons give masks (all ones or zero per lane) of the same-width signed integers.
 */
#ifndef REND3R_SIMD_H
#define REND3R_SIMD_H

#include <math.h>
#include <stdint.h>
#include <string.h>

/* Helpers of the kernels are inlined whatever their size: they pass vectors and structs
 * of vectors, which a call would spill to memory. */
#define INLINE static inline __attribute__((always_inline))

/* A float packet's lanes: eight, or sixteen in a unit that defines FLOAT_LANES as 16
 * before its includes (instances/f32w_avx512.c). */
#ifndef FLOAT_LANES
#define FLOAT_LANES 8
#endif

typedef float f32x8 __attribute__((vector_size(32)));
typedef uint32_t u32x8 __attribute__((vector_size(32)));
typedef int32_t i32x8 __attribute__((vector_size(32)));
typedef double f64x4 __attribute__((vector_size(32)));
typedef double f64x8 __attribute__((vector_size(64)));
typedef int64_t i64x8 __attribute__((vector_size(64)));
typedef uint64_t u64x4 __attribute__((vector_size(32)));
typedef int64_t i64x4 __attribute__((vector_size(32)));
typedef int32_t i32x4 __attribute__((vector_size(16)));
typedef uint32_t u32x4 __attribute__((vector_size(16)));
typedef float f32x4 __attribute__((vector_size(16)));
typedef uint16_t u16x4 __attribute__((vector_size(8)));
typedef uint16_t u16x8 __attribute__((vector_size(16)));
typedef float f32xF __attribute__((vector_size(4 * FLOAT_LANES)));
typedef int32_t i32xF __attribute__((vector_size(4 * FLOAT_LANES)));
typedef uint32_t u32xF __attribute__((vector_size(4 * FLOAT_LANES)));
typedef uint16_t u16xF __attribute__((vector_size(2 * FLOAT_LANES)));
typedef double f64xF __attribute__((vector_size(8 * FLOAT_LANES)));
typedef int64_t i64xF __attribute__((vector_size(8 * FLOAT_LANES)));

/* Lanes 4h..4h+3 of a float packet, in double. */
#define F32_HALF(v, h) __builtin_convertvector(                                                    \
    (h) == 0 ? __builtin_shufflevector((v), (v), 0, 1, 2, 3) : __builtin_shufflevector((v), (v), 4, 5, 6, 7), f64x4)
/* Lanes 4h..4h+3 of an eight-lane float mask, as a four-lane double mask. */
#define I32_HALF(m, h) __builtin_convertvector(                                                    \
    (h) == 0 ? __builtin_shufflevector((m), (m), 0, 1, 2, 3) : __builtin_shufflevector((m), (m), 4, 5, 6, 7), i64x4)
/* Two four-lane double masks as one eight-lane float mask. */
#define MASK_8(lo, hi) __builtin_shufflevector(__builtin_convertvector((lo), i32x4),                \
                                               __builtin_convertvector((hi), i32x4), 0, 1, 2, 3, 4, 5, 6, 7)

/* Lanes of mask m: from a where set, else from b (integer vectors of one type). */
#define SEL_BITS(m, a, b) (((a) & (m)) | ((b) & ~(m)))

/* Lane by lane square roots (the compiler makes one vector instruction of them). */
INLINE f64x4 sqrt4(f64x4 x)
{
    f64x4 r;
    for (int i = 0; i < 4; i++)
        r[i] = sqrt(x[i]);
    return r;
}

/* Lane by lane the lesser and the greater of two vectors of numbers (not NaN), and the
 * least lane of one. */
INLINE f64x4 min4(f64x4 a, f64x4 b) { return (f64x4)SEL_BITS((i64x4)(a < b), (i64x4)a, (i64x4)b); }
INLINE f64x4 max4(f64x4 a, f64x4 b) { return (f64x4)SEL_BITS((i64x4)(a > b), (i64x4)a, (i64x4)b); }
INLINE double least4(f64x4 x)
{
    x = min4(x, __builtin_shufflevector(x, x, 2, 3, 0, 1));
    x = min4(x, __builtin_shufflevector(x, x, 1, 0, 3, 2));
    return x[0];
}

/* The box lo..hi (three axes) widened to the lanes of q (x, y, z) that m sets. */
INLINE void box_join4(f64x4 lo[3], f64x4 hi[3], i64x4 m, const f64x4 q[3])
{
    const f64x4 inf = (f64x4){0} + INFINITY;
    for (int k = 0; k < 3; k++) {
        lo[k] = min4(lo[k], (f64x4)SEL_BITS(m, (i64x4)q[k], (i64x4)inf));
        hi[k] = max4(hi[k], (f64x4)SEL_BITS(m, (i64x4)q[k], (i64x4)-inf));
    }
}

/* |a x w|^2 for one vector a and a float packet's vectors w, in float (products and sums
 * rounded in this order; bvh.h cone_missed_f and cull.h primary_culled_f bound its error). */
INLINE f32xF cross2_f(float a0, float a1, float a2, f32xF w0, f32xF w1, f32xF w2)
{
    f32xF c0 = w1 * a2 - w2 * a1, c1 = w2 * a0 - w0 * a2, c2 = w0 * a1 - w1 * a0;
    return c0 * c0 + c1 * c1 + c2 * c2;
}

/* Flags (bytes that are 0 or 1) as the bits of an int, byte i giving bit i: one
 * multiplication gathers them into the top byte; and bits back to flags (each byte selects
 * its bit, and adding 0x7F carries a set bit into the byte's top bit). */
INLINE int flag_bits8(const uint8_t *a)
{
    uint64_t x;
    memcpy(&x, a, sizeof x);
    return (int)((x * 0x0102040810204080ull) >> 56);
}

INLINE int flag_bits4(const uint8_t *a)
{
    uint32_t x;
    memcpy(&x, a, sizeof x);
    return (int)((x * 0x01020408u) >> 24);
}

INLINE void put_flags8(uint8_t *a, int bits)
{
    uint64_t x = ((uint64_t)bits * 0x0101010101010101ull) & 0x8040201008040201ull;
    x = ((x + 0x7F7F7F7F7F7F7F7Full) >> 7) & 0x0101010101010101ull;
    memcpy(a, &x, sizeof x);
}

INLINE void put_flags4(uint8_t *a, int bits)
{
    uint32_t x = ((uint32_t)bits * 0x01010101u) & 0x08040201u;
    x = ((x + 0x7F7F7F7Fu) >> 7) & 0x01010101u;
    memcpy(a, &x, sizeof x);
}

/* A mask whose lane i is set where bit i of bits is. */
INLINE i32x8 bits_mask_32x8(int bits) { return ((i32x8){1, 2, 4, 8, 16, 32, 64, 128} & bits) != 0; }
INLINE i32x4 bits_mask_32x4(int bits) { return ((i32x4){1, 2, 4, 8} & bits) != 0; }
INLINE i64x4 bits_mask_64x4(int bits) { return ((i64x4){1, 2, 4, 8} & bits) != 0; }

/* The sign bits of a mask's lanes as an int (lane i: bit i); masks are all ones or zero
 * per lane. One instruction with AVX (the AVX2 kernels), two with SSE2. */
#if defined(__AVX__)
#include <immintrin.h>
INLINE int mask_bits_32x8(i32x8 m) { return _mm256_movemask_ps((__m256)m); }
INLINE int mask_bits_32x4(i32x4 m) { return _mm_movemask_ps((__m128)m); }
INLINE int mask_bits_64x4(i64x4 m) { return _mm256_movemask_pd((__m256d)m); }
#elif defined(__SSE2__)
#include <emmintrin.h>
typedef int64_t i64x2 __attribute__((vector_size(16)));
INLINE int mask_bits_32x4(i32x4 m) { return _mm_movemask_ps((__m128)m); }
INLINE int mask_bits_32x8(i32x8 m)
{
    return _mm_movemask_ps((__m128)__builtin_shufflevector(m, m, 0, 1, 2, 3))
         | _mm_movemask_ps((__m128)__builtin_shufflevector(m, m, 4, 5, 6, 7)) << 4;
}
INLINE int mask_bits_64x4(i64x4 m)
{
    return _mm_movemask_pd((__m128d)__builtin_shufflevector(m, m, 0, 1))
         | _mm_movemask_pd((__m128d)__builtin_shufflevector(m, m, 2, 3)) << 2;
}
#else
INLINE int mask_bits_32x4(i32x4 m)
{
    int r = 0;
    for (int i = 0; i < 4; i++)
        r |= (m[i] < 0) << i;
    return r;
}
INLINE int mask_bits_32x8(i32x8 m)
{
    int r = 0;
    for (int i = 0; i < 8; i++)
        r |= (m[i] < 0) << i;
    return r;
}
INLINE int mask_bits_64x4(i64x4 m)
{
    int r = 0;
    for (int i = 0; i < 4; i++)
        r |= (m[i] < 0) << i;
    return r;
}
#endif

/* A float packet's masks as bits and back, and its flags (bytes) as bits and back. */
#if FLOAT_LANES == 16
INLINE int mask_bits_f(i32xF m) { return _mm512_movepi32_mask((__m512i)m); }
INLINE i32xF bits_mask_f(int bits) { return (i32xF)_mm512_movm_epi32((__mmask16)bits); }
INLINE int flag_bits_f(const uint8_t *a) { return flag_bits8(a) | flag_bits8(a + 8) << 8; }
INLINE void put_flags_f(uint8_t *a, int bits)
{
    put_flags8(a, bits & 255);
    put_flags8(a + 8, bits >> 8);
}
/* Lanes 4h..4h+3 of a float packet (a mask), in double (a four-lane double mask); four
 * four-lane double masks as one float packet mask. */
#define F32_PART(v, h) __builtin_convertvector(QUARTER((v), (h)), f64x4)
#define I32_PART(m, h) __builtin_convertvector(QUARTER((m), (h)), i64x4)
#define QUARTER(v, h) ((h) == 0 ? __builtin_shufflevector((v), (v), 0, 1, 2, 3)                      \
                      : (h) == 1 ? __builtin_shufflevector((v), (v), 4, 5, 6, 7)                     \
                      : (h) == 2 ? __builtin_shufflevector((v), (v), 8, 9, 10, 11)                   \
                                 : __builtin_shufflevector((v), (v), 12, 13, 14, 15))
#define MASK_F(c) __builtin_shufflevector(MASK_8((c)[0], (c)[1]), MASK_8((c)[2], (c)[3]), 0, 1, 2, 3, 4, 5, 6, 7, \
                                          8, 9, 10, 11, 12, 13, 14, 15)
#else
INLINE int mask_bits_f(i32xF m) { return mask_bits_32x8(m); }
INLINE i32xF bits_mask_f(int bits) { return bits_mask_32x8(bits); }
INLINE int flag_bits_f(const uint8_t *a) { return flag_bits8(a); }
INLINE void put_flags_f(uint8_t *a, int bits) { put_flags8(a, bits); }
#define F32_PART(v, h) F32_HALF(v, h)
#define I32_PART(m, h) I32_HALF(m, h)
#define MASK_F(c) MASK_8((c)[0], (c)[1])
#endif

/* float16 rounding of 8 float lanes (fround.h round16, lane by lane): normal results by
 * integer rounding of the significand; overflow to infinity; NaN kept; below 2**-14
 * flushed (ftz; 2**-14 - 2**-25 and up go to 2**-14) or rounded to the subnormal grid
 * (adding and subtracting 2**23 rounds to an integer, nearest even). The integer rounding
 * is also exact for zeros and infinities (their low bits are zero), so only packets with a
 * subnormal-range or overflowing lane take the rare path; NaN lanes are kept as they are. */
#if defined(__F16C__)
/* With F16C (every AVX2 processor), the conversion to float16 and back rounds as IEEE does,
 * nearest even, subnormals included; ftz then flushes what came out below 2**-14 (so
 * 2**-14 - 2**-25 and up still round to 2**-14, as round16 does). A NaN comes back as it
 * went in when its low 13 bits are zero and it is quiet, which every NaN the kernels round
 * is: they round results of operations, whose NaNs are the default NaN or a quieted
 * float16 operand. The same values as the integer rounding below, in fewer instructions. */
INLINE f32x8 round16x8(f32x8 x, int ftz)
{
    u32x8 b = (u32x8)_mm256_cvtph_ps(_mm256_cvtps_ph((__m256)x, _MM_FROUND_TO_NEAREST_INT));
    if (ftz)  /* below 2**-14: the sign alone */
        b &= (u32x8)((i32x8)(b & 0x7FFFFFFFu) >= 0x38800000) | 0x80000000u;
    return (f32x8)b;
}
#else
static __attribute__((noinline)) f32x8 round16x8_rare(f32x8 x, int ftz);

INLINE f32x8 round16x8(f32x8 x, int ftz)
{
    u32x8 b = (u32x8)x;
    i32x8 a = (i32x8)(b & 0x7FFFFFFFu);  /* |x|'s bits: signed comparisons order them */
    i32x8 rare = ((a > 0) & (a < 0x38800000)) | ((a >= 0x477FF000) & (a < 0x7F800000));
    if (mask_bits_32x8(rare) == 0)
        return (f32x8)SEL_BITS((u32x8)(a > 0x7F800000), b, (b + 0xFFFu + ((b >> 13) & 1u)) & 0xFFFFE000u);
    return round16x8_rare(x, ftz);
}
#endif

#if !defined(__F16C__)
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

#endif
