/* The frame's colour arithmetic, after the working-precision datapath (docs/emulator.md 5),
 * in double on a packet's LANES lanes at once: per RGB565 channel of a shape's colour, the
 * sum over unblocked lights of f * channel * light_channel / channel_max, rounded half up
 * and clamped; and the device's 13-bit intensity converter. Part of datapath.inc, whose
 * includer (instances.inc) names the packet's vectors: CV its lanes in double, CM their
 * masks, CI and CU its 32-bit integers, signed and not (eight doubles make one AVX-512
 * register, where a float packet's colours took two four-lane halves before). Lanes are
 * independent (a pixel trace reads lane 0). A translation unit builds one precision, so
 * the guard lets these types be the includer's. */
#ifndef REND3R_COLOUR_H
#define REND3R_COLOUR_H

static const int rgb_shift[3] = {11, 5, 0}, rgb_top[3] = {31, 63, 31};

/* Colour sums rounded half up (floor(x + 0.5)), clamped to each RGB565 channel, packed. */
INLINE CI pack_rgb(const CV acc[3])
{
    CI value = {0};
    for (int c = 0; c < 3; c++) {
        CV x = acc[c] + 0.5;  /* below 1 (or NaN): 0; from top + 1 on: top; between: truncation is floor */
        CV v = (CV)SEL_BITS(x >= 1.0, (CM)x, (CM)(CV){0});
        v = (CV)SEL_BITS(x >= rgb_top[c] + 1, (CM)((CV){0} + rgb_top[c]), (CM)v);
        value |= __builtin_convertvector(v, CI) << rgb_shift[c];
    }
    return value;
}

/* The channels of RGB565 colours, in double. */
INLINE void channels_of(CI base, CV channel[3])
{
    for (int c = 0; c < 3; c++)
        channel[c] = __builtin_convertvector((base >> rgb_shift[c]) & rgb_top[c], CV);
}

/* Lanes on: one light's share of shape colours (channels) added to the sums,
 * factor * channel * scale per channel, in double. */
INLINE void add_light(CV acc[3], CV factor, const CV channel[3], const double *scale, CM on)
{
    for (int c = 0; c < 3; c++) {
        CV sum = acc[c] + factor * channel[c] * scale[c];
        acc[c] = (CV)SEL_BITS(on, (CM)sum, (CM)acc[c]);
    }
}

/* The device's intensity converter: round(f * 16384) (nearest even) wrapped to a 13-bit
 * two's-complement integer; values beyond int64 convert as x86 does (to -2**63, which
 * wraps to 0). Packets within 2**31 convert to 32-bit integers (the same low 13 bits). */
INLINE CI fixed_intensity(CV f)
{
    CV x = f * 16384.0;
    for (int i = 0; i < LANES; i++)
        x[i] = rint(x[i]);
    CV a = (CV)((CM)x & 0x7FFFFFFFFFFFFFFFll);
    CI k;
    if (MASKBITS(__builtin_convertvector(a < 2147483648.0, M)) == (1 << LANES) - 1) {
        k = __builtin_convertvector(x, CI);
    } else {
        for (int i = 0; i < LANES; i++)
            k[i] = (int32_t)(a[i] < 9223372036854775808.0 ? (int64_t)x[i] : INT64_MIN);  /* the low 32 bits */
    }
    return (CI)(((CU)k + 4096u) & 8191u) - 4096;
}

/* n doubles from a (n <= LANES; the last repeated past n), and back. */
INLINE CV load_colours(const double *a, int n)
{
    CV v;
    if (n == LANES) {
        memcpy(&v, a, sizeof v);
        return v;
    }
    for (int i = 0; i < LANES; i++)
        v[i] = a[i < n ? i : n - 1];
    return v;
}

INLINE void store_colours(double *a, CV v, int n)
{
    if (n == LANES) {
        memcpy(a, &v, sizeof v);
        return;
    }
    for (int i = 0; i < n; i++)  /* a packet's last pixels of a row: rare */
        a[i] = v[i];
}

#endif
