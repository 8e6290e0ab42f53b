/* Argument blocks of the raytracer's kernels (mirrored by ctypes in rend3r/emu/native.py).
 *
 * Arrays are C-contiguous; "working" arrays hold float (fp16, fp32) or double (fp64)
 * values, the same type throughout one call. Every index a kernel follows (shape slots in
 * grid lists, pixel ranges) was produced or checked by the Python side before the call.
 */
#ifndef REND3R_KERNELS_H
#define REND3R_KERNELS_H

#include <stdint.h>

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
enum { GF_U0 = 0, GF_U1 = 1, GF_V0 = 2, GF_V1 = 3, GF_SU = 4, GF_SV = 5, GF_COLUMNS = 6 };
enum { GS_NU = 0, GS_NV = 1, GS_FIRST = 2, GS_COLUMNS = 3 };
/* Per-face ray statistics: u0, u1, v0, v1, rays, shortest and longest direction. */
enum { BOX_COLUMNS = 7 };
/* Primary cull data per shape (double): centre minus camera, its squared length, the
 * squared cull radius with slack, and the two terms of the behind test (bounds.h). */
enum { PC_V = 0, PC_VV = 3, PC_R2 = 4, PC_MEAN2 = 5, PC_BEHIND = 6, PC_COLUMNS = 7 };
/* Values per shape and per light in a pixel trace. */
enum { TRACE_SHAPE_VALUES = 22, TRACE_LIGHT_VALUES = 12 };
/* Counters: tests, tests that met NaN or infinity, shadow rays. */
enum { C_TESTS = 0, C_NAN_TESTS = 1, C_SHADOW_RAYS = 2 };

typedef struct {
    void *sf;               /* n x SF_COLUMNS, working */
    const int64_t *si;      /* n x SI_COLUMNS */
    const double *bnd;      /* n x B_COLUMNS */
    int64_t n;
    double u, tiny;         /* unit roundoff and smallest normal number of the precision */
} Shapes;

typedef struct {
    const double *faces;    /* 3 x GF_COLUMNS */
    const int64_t *shape;   /* 3 x GS_COLUMNS */
    const int64_t *start;   /* cells + 1 */
    const int32_t *entries; /* shape slots, per cell */
    const int32_t *glob;    /* shape slots every ray tests */
    int64_t nglob;
} Grid;

typedef struct {            /* the primary rays of one band of rows */
    const Shapes *sh;
    const void *cam;        /* CAM_COLUMNS, working */
    const void *xs, *ys;    /* direction x per column, y per row, working */
    int32_t rotated;        /* turn (x, y, z) by the camera's rotation */
    int32_t lit;            /* keep hit points and normals */
    int64_t width, row0;
    void *dirs;             /* pixels x 4: direction and |d|^2, working (rotated camera) */
    const int64_t *col_cell;/* grid camera: per column its cell's u part, per row (of the band) */
    const int64_t *row_cell;/* its v part; -1 outside the grid. NULL: a rotated camera */
    const double *pc;       /* per shape PC_COLUMNS: the primary rays' cull data (bounds.h) */
    const double *floor;    /* depth floor per shape */
    Grid grid;
    int32_t *slot;          /* nearest shape, -1 none */
    void *sqd;              /* its sq_dist, working */
    void *pt, *nm;          /* pixels x 3, working (lit only) */
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
    const void *along;      /* n x 4: l in normal space and a2, working (directional) */
    const double *radius;   /* cull radius per shape, for these shadow rays */
    Grid grid;
    double *acc;            /* pixels x 3 colour sums */
} LightPass;

#endif
