/* The frame's colour arithmetic, after the working-precision datapath (docs/emulator.md 5):
 * per RGB565 channel of a shape's colour, the sum over unblocked lights of
 * f * channel * light_channel / channel_max in double, rounded half up and clamped. */
#ifndef REND3R_COLOUR_H
#define REND3R_COLOUR_H

#include <math.h>
#include <stdint.h>

static const int rgb_shift[3] = {11, 5, 0}, rgb_top[3] = {31, 63, 31};

/* Colour sums rounded half up (floor(x + 0.5)), clamped to each RGB565 channel, packed. */
static inline int64_t pack_rgb(const double *acc)
{
    int64_t value = 0;
    for (int c = 0; c < 3; c++) {
        double x = acc[c] + 0.5;  /* below 1: 0; from top + 1 on: top; between: truncation is floor */
        value |= (int64_t)(!(x >= 1.0) ? 0 : x >= rgb_top[c] + 1 ? rgb_top[c] : (int)x) << rgb_shift[c];
    }
    return value;
}

/* One light's share of a shape colour's channels: factor * channel * scale, in double. */
static inline void add_light(double *acc, double factor, int64_t base, const double *scale)
{
    for (int c = 0; c < 3; c++)
        acc[c] += factor * (double)((base >> rgb_shift[c]) & rgb_top[c]) * scale[c];
}

#endif
