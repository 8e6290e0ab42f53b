/* Argument blocks of the raytracer's kernels (mirrored by ctypes in rend3r/emu/native.py).
 *
 * Arrays are C-contiguous; "working" arrays hold float (fp16, fp32) or double (fp64)
 * values, the same type throughout one call. Every index a kernel follows (shape slots in
 * grid lists, pixel ranges) was produced or checked by the Python side before the call.
 */
#ifndef REND3R_KERNELS_H
#define REND3R_KERNELS_H

#include <stdint.h>

/* Minimum and maximum of numbers known not to be NaN (fmin and fmax are library calls). */
#define MIN(a, b) ((a) < (b) ? (a) : (b))
#define MAX(a, b) ((a) > (b) ? (a) : (b))

/* Shape float table columns (working type): location, quaternion (r, i, j, k), inverse
 * scales, normal form (z sign, constant), the camera origin in normal space and its
 * origin term. Int table columns: rotation exactly (1, +0, +0, +0), RGB565 colour. */
enum { SF_LOC = 0, SF_ROT = 3, SF_INV = 7, SF_ZSIGN = 10, SF_ONE = 11, SF_SHAT = 12, SF_C2 = 15, SF_COLUMNS = 16 };
enum { SI_IDENT = 0, SI_COLOUR = 1, SI_COLUMNS = 2 };
/* Bound table columns (double): centre, smallest and largest singular value. */
enum { B_CENTER = 0, B_SMIN = 3, B_SMAX = 4, B_COLUMNS = 5 };
/* Camera table (working type): origin, tmin, tmax, z of the direction, rotation. */
enum { CAM_ORIGIN = 0, CAM_TMIN = 3, CAM_TMAX = 4, CAM_Z = 5, CAM_ROT = 6, CAM_COLUMNS = 10 };
/* Light table (working type): kind, location, l of a directional light, intensity. */
enum { LT_KIND = 0, LT_LOC = 1, LT_DIR = 4, LT_INTENSITY = 7, LT_COLUMNS = 8 };
enum { LIGHT_DIRECTIONAL = 1, LIGHT_POINT = 2 };
/* Grid face columns (double): the rays' u0, u1, v0, v1, then cells per unit of u, v;
 * face ints: cells along u, along v, first cell. */
/* cone_balls: unit axis, half-angle, its sine and cosine per shape. */
enum { CONE_COLUMNS = 6 };
enum { GF_U0 = 0, GF_U1 = 1, GF_V0 = 2, GF_V1 = 3, GF_SU = 4, GF_SV = 5, GF_COLUMNS = 6 };
enum { GS_NU = 0, GS_NV = 1, GS_FIRST = 2, GS_COLUMNS = 3 };
/* Per-face ray statistics: u0, u1, v0, v1, rays, shortest and longest direction. */
enum { BOX_COLUMNS = 7 };
/* Primary cull data per shape (double): centre minus camera, its squared length, the
 * squared cull radius with slack, and the two terms of the behind test (bounds.h). */
enum { PC_V = 0, PC_VV = 3, PC_R2 = 4, PC_MEAN2 = 5, PC_BEHIND = 6, PC_COLUMNS = 7 };
/* Values per shape and per light in a pixel trace. */
enum { TRACE_SHAPE_VALUES = 22, TRACE_LIGHT_VALUES = 12 };
/* What a kernel reports per chunk (double): tests, tests that met NaN or infinity, shadow
 * rays, hit pixels with a finite hit point and those points' bounding box. */
enum { OUT_TESTS = 0, OUT_NAN_TESTS = 1, OUT_SHADOW_RAYS = 2, OUT_HITS = 3, OUT_LO = 4, OUT_HI = 7, OUT_COLUMNS = 10 };

/* A working format eEmM of the _fmt kernels (csrc/fformat.h; native.py Format). */
typedef struct {
    int64_t drop;           /* 52 - M: the double fraction bits a rounding drops */
    uint64_t max_bits;      /* the largest finite value, as double bits */
    uint64_t min_normal_bits; /* 2**emin, as double bits */
    double subnormal_magic; /* 2**(emin - M + 52): adding and subtracting it rounds to the subnormal grid */
    int32_t ftz;            /* flush results below 2**emin to zero */
    int32_t wide;           /* M > 25: double rounding is not innocuous, round to odd first */
    int32_t before;         /* ftz judges a result tiny before rounding (a device quirk) */
    int32_t stages;         /* nonzero: the first of 1 + stages formats of a per-stage map (fformat.h) */
} Format;

typedef struct {
    void *sf;               /* n x SF_COLUMNS, working */
    const int64_t *si;      /* n x SI_COLUMNS */
    const double *bnd;      /* n x B_COLUMNS */
    int64_t n;
    double u, tiny;         /* unit roundoff and smallest normal number of the precision */
    const Format *format;   /* the _fmt kernels' format (NULL for the others) */
} Shapes;

typedef struct {
    const double *faces;    /* 3 x GF_COLUMNS */
    const int64_t *shape;   /* 3 x GS_COLUMNS */
    const int64_t *start;   /* cells + 1 */
    int64_t start_count;    /* cells + 1 */
    const int32_t *entries; /* shape slots, per cell */
    const int32_t *glob;    /* shape slots every ray tests */
    int64_t nglob;
    /* A grid camera's pixel grid (face 2 only; u_at NULL otherwise): cells are blocks of
     * `block` columns by `block_rows` rows; u_at holds u_sign * u of every column and v_at
     * v_sign * v of every row of the band, both ascending. */
    const double *u_at, *v_at;
    int64_t n_u, n_v, block, block_rows;
    double u_sign, v_sign;
    /* A perspective grid's reach (or NULL), at every fourth entry: a double cone around
     * the apex (float axis x, y, z and cos of its half-angle, -2 for every line) holding
     * every line that may hit the entry's shape or a later one of its cell's list
     * (kernels.c cone_reach); entry i's is at reach + i, i a multiple of 4. */
    const float *reach;
} Grid;

typedef struct {            /* the primary rays of one band of rows */
    const Shapes *sh;
    const void *cam;        /* CAM_COLUMNS, working */
    const void *xs, *ys;    /* direction x per column, y per row, working */
    int32_t rotated;        /* turn (x, y, z) by the camera's rotation */
    int32_t lit;            /* keep hit points and normals */
    int64_t width, row0;
    uint64_t row_magic;     /* floor(2**40 / width) + 1: band_row without a division */
    void *dirs;             /* pixels x 4: direction and |d|^2, working (rotated camera; else NULL) */
    const double *pc;       /* per shape PC_COLUMNS: the primary rays' cull data (bounds.h) */
    const double *floor;    /* depth floor per shape */
    Grid grid;
    const int64_t *bucket_start; /* rotated camera: pixels by cell, cells + 2 starts (last: outside) */
    const int32_t *bucket_pixels;
    int32_t *slot;          /* nearest shape, -1 none */
    void *sqd;              /* its sq_dist, working */
    void *pt, *nm;          /* 3 x pixels (x row, y row, z row), working (lit only) */
    int64_t npix;           /* pixels of the band */
    uint8_t *bad;           /* hit point, or later a light, not finite */
    uint8_t *nan_px;        /* a ray of the pixel met NaN or infinity */
} Band;

typedef struct {            /* one light over one band */
    const Shapes *sh;
    const Band *band;
    const void *light;      /* LT_COLUMNS, working */
    double scale[3];        /* light channel / channel maximum */
    double frame[6];        /* parallel: two axes normal to l; point: the location */
    int32_t fixed;          /* the device's 13-bit intensity converter */
    int32_t shadows;        /* cast shadow rays (there are other shapes) */
    int32_t parallel;       /* directional light: parallel grid, per-shape terms in along */
    int32_t first;          /* the band's first light: it sets the colour sums instead of adding */
    const void *along;      /* n x 4: l in normal space and a2, working (directional) */
    const double *behind;   /* n x 3 (directional): centre . l/|l|, and the behind test's mean2
                               and (spread2 + 64 uu smax^2), NaN where no test applies */
    double l_hat[3], l_len; /* a directional light's l/|l| and |l| */
    const double *radius;   /* cull radius per shape, for these shadow rays */
    /* At every fourth entry of the grid's lists (directional light; else NULL): K0, K1,
     * K2, the largest over the entry's shape and every later one of its cell (kernels.c
     * behind_reach; entry i's at reach + 3 (i / 4)); a packet whose origins lie at depth
     * >= least along l within spread of their centre skips the rest of the list once
     * least >= max(K0 + K1 spread, K2 + 2 spread), as every shape left lies behind every
     * origin. */
    const double *reach;
    Grid grid;
    double *acc;            /* pixels x 3 colour sums */
} LightPass;

/* The row within its band of pixel p: (p * row_magic) >> 40 equals p / width exactly for
 * p < 2**20 and width <= 8192 (the error p * (row_magic - 2**40/width) / 2**40 < 2**-20
 * stays below the 1/width a fraction p/width keeps from the next integer). */
static inline int64_t band_row(const Band *b, int64_t p)
{
    return (int64_t)(((uint64_t)p * b->row_magic) >> 40);
}

#endif
