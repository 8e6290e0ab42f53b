/* The frame's colour arithmetic, after the working-precision datapath (docs/emulator.md 5),
 * on four double lanes: per RGB565 channel of a shape's colour, the sum over unblocked
 * lights of f * channel * light_channel / channel_max in double, rounded half up and
 * clamped; and the device's 13-bit intensity converter. Lanes are independent (a pixel
 * trace reads lane 0). */
#ifndef REND3R_COLOUR_H
#define REND3R_COLOUR_H

#include <math.h>
#include <stdint.h>

#include "simd.h"

static const int rgb_shift[3] = {11, 5, 0}, rgb_top[3] = {31, 63, 31};

/* Colour sums rounded half up (floor(x + 0.5)), clamped to each RGB565 channel, packed. */
static inline i32x4 pack_rgb4(const f64x4 acc[3])
{
    i32x4 value = {0};
    for (int c = 0; c < 3; c++) {
        f64x4 x = acc[c] + 0.5;  /* below 1 (or NaN): 0; from top + 1 on: top; between: truncation is floor */
        f64x4 v = (f64x4)SEL_BITS(x >= 1.0, (i64x4)x, (i64x4)(f64x4){0});
        v = (f64x4)SEL_BITS(x >= rgb_top[c] + 1, (i64x4)((f64x4){0} + rgb_top[c]), (i64x4)v);
        value |= __builtin_convertvector(v, i32x4) << rgb_shift[c];
    }
    return value;
}

/* The channels of RGB565 colours, in double. */
static inline void channels4(i32x4 base, f64x4 channel[3])
{
    for (int c = 0; c < 3; c++)
        channel[c] = __builtin_convertvector((base >> rgb_shift[c]) & rgb_top[c], f64x4);
}

/* Lanes on: one light's share of shape colours (channels) added to the sums,
 * factor * channel * scale per channel, in double. */
static inline void add_light4(f64x4 acc[3], f64x4 factor, const f64x4 channel[3], const double *scale, i64x4 on)
{
    for (int c = 0; c < 3; c++) {
        f64x4 sum = acc[c] + factor * channel[c] * scale[c];
        acc[c] = (f64x4)SEL_BITS(on, (i64x4)sum, (i64x4)acc[c]);
    }
}

/* The device's intensity converter: round(f * 16384) (nearest even) wrapped to a 13-bit
 * two's-complement integer; values beyond int64 convert as x86 does (to -2**63, which
 * wraps to 0). Packets within 2**31 convert to 32-bit integers (the same low 13 bits). */
static inline i32x4 fixed_intensity4(f64x4 f)
{
    f64x4 x = f * 16384.0;
    for (int i = 0; i < 4; i++)
        x[i] = rint(x[i]);
    f64x4 a = (f64x4)((i64x4)x & 0x7FFFFFFFFFFFFFFFll);
    i32x4 k;
    if (mask_bits_64x4(a < 2147483648.0) == 15) {
        k = __builtin_convertvector(x, i32x4);
    } else {
        for (int i = 0; i < 4; i++)
            k[i] = (int32_t)(a[i] < 9223372036854775808.0 ? (int64_t)x[i] : INT64_MIN);  /* the low 32 bits */
    }
    return (i32x4)(((u32x4)k + 4096u) & 8191u) - 4096;
}

#endif
