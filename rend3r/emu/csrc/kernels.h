/* Argument blocks of the raytracer's kernels (mirrored by ctypes in rend3r/emu/native.py).
 *
 * Arrays are C-contiguous; "working" arrays hold float (fp16, fp32) or double (fp64)
 * values, the same type throughout one call. Every index a kernel follows (shape slots in
 * tree leaves, pixel ranges) was produced or checked by the Python side before the call.
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
/* Primary cull data per shape (double): centre minus camera, its squared length, the
 * squared cull radius with slack and the two terms of the behind test (bounds.h). */
enum { PC_V = 0, PC_VV = 3, PC_R2 = 4, PC_MEAN2 = 5, PC_BEHIND = 6, PC_COLUMNS = 7 };
/* What float lanes read of a shape instead (float, 32 bytes a shape: two to a cache line,
 * so that a pixel pass reads a quarter of the lines the double rows would take): the
 * depth floor rounded down (compared with sq_dist) and the float test's terms (cull.h
 * primary_culled_f: v rounded to floats, the widened threshold of the line distance, mean2
 * and the widened behind term; NaN where it must not cull). */
enum { P32_FLOOR = 0, P32_V = 1, P32_T = 4, P32_M = 5, P32_B = 6, P32_COLUMNS = 8 };
/* Values per shape and per light in a pixel trace. */
enum { TRACE_SHAPE_VALUES = 22, TRACE_LIGHT_VALUES = 12 };
/* What a kernel reports per chunk (double): tests, tests that met NaN or infinity, shadow
 * rays, hit pixels with a finite hit point and those points' bounding box; and once the
 * pixels are finished, those shown (not the background) and those whose rays met NaN or
 * infinity. */
enum { OUT_TESTS = 0, OUT_NAN_TESTS = 1, OUT_SHADOW_RAYS = 2, OUT_HITS = 3, OUT_LO = 4, OUT_HI = 7, OUT_SHOWN = 10,
       OUT_NAN_RAYS = 11, OUT_COLUMNS = 12 };

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

/* Shape hierarchy node columns (doubles, then floats; per bundle of rays; csrc/bvh.h): a
 * bundle through one apex (BVH_CONE) gets the double cone holding the lines that meet the balls below
 * (unit axis, the sine and cosine of its half-angle, its squared sine widened), parallel
 * lines (BVH_FLAT) the box of the balls' discs on two axes normal to them; then the least
 * depth floor below, and that
 * floor rounded down to a float; a cone also gets its axis rounded to floats and the
 * widened squared sine of the float test (bvh.h cone_missed_f), a box its bounds rounded
 * outwards to floats. */
enum { BVH_CONE = 0, BVH_FLAT = 1 };
/* Bytes a shape of bvh_build's working room (its Morton key twice, its centre and slot
 * twice), and of its centre and slot (kernels.c BuildItem). */
enum { BUILD_BYTES = 48, BUILD_ITEM_BYTES = 16 };
enum { BV_AXIS = 0, BV_SINE = 3, BV_COS = 4, BV_SIN2 = 5, BV_U0 = 0, BV_U1 = 1, BV_V0 = 2, BV_V1 = 3,
       BV_FLOOR = 6, BV_F32 = 7, BV_COLUMNS = 10 };
/* The float columns, six floats from double column BV_F32 on (node32): the floor, then a
 * cone's axis and squared sine or a box's u0, u1, v0, v1, and a zero. Read as floats where
 * they were doubles converted at each read, they take conversions off every node a packet
 * visits. */
enum { F32_FLOOR = 0, F32_AXIS = 1, F32_SIN2 = 4, F32_BOX = 1, F32_PAD = 5 };
/* Parallel lines also get each shape's own box (BV_U0..BV_V1), per item in leaf order;
 * boxes also come rounded outwards to floats (floats from double column BX_F32 of an item:
 * u0, u1, v0, v1; bvh.h flat_missed_f). */
enum { BX_F32 = 4, BX_COLUMNS = 6 };
/* A node's or an item's float columns, from double column `column` of its row on. */
static inline float *node32(double *row, int column) { return (float *)(row + column); }
static inline const float *node32c(const double *row, int column) { return (const float *)(row + column); }
/* A shape's own cone for lines through one apex (unit axis, the sine and cosine of its
 * half-angle: sine inf for every line), per item in leaf order, while the nodes' cones
 * are fitted (kernels.c bvh_refit). */
enum { CI_SINE = 3, CI_COS = 4, CI_COLUMNS = 5 };
/* A point light's behind test (cull.h point_behind4): per shape its centre, mean2, the
 * behind test's K (spread2 + 64 uu smax^2) and its cull radius (shape_bounds.inc
 * shadow_shapes), and per node the box of the centres below it, the least mean2 and the
 * largest K and radius (kernels.c refit_cones). */
enum { SK_CENTER = 0, SK_MEAN2 = 3, SK_K = 4, SK_R = 5, SK_COLUMNS = 6 };
enum { PK_LO = 0, PK_HI = 3, PK_MEAN2 = 6, PK_K = 7, PK_R = 8, PK_COLUMNS = 9 };

typedef struct {
    const int32_t *node;    /* per node: right child (inner) or first item (leaf), item count (0: inner);
                               an inner node's left child is the next node */
    const int32_t *items;   /* shape slots, leaf by leaf */
    const double *box;      /* nodes x BV_COLUMNS, for one bundle of rays (bvh_refit) */
    double frame[6];        /* that bundle's apex (BVH_CONE) or two unit axes normal to its lines (BVH_FLAT) */
    int64_t nodes;
    const int32_t *always;  /* shape slots outside the tree (no finite bound): every ray tests them */
    int64_t nalways;
    const double *item_box; /* parallel lines: items x BX_COLUMNS, each shape's own box (else NULL) */
    const int32_t *where;   /* per shape slot, its row in a light's bounds (bvh_build; PASS_SHADOW) */
} Bvh;

typedef struct {            /* the primary rays of one band of rows */
    const Shapes *sh;
    const void *cam;        /* CAM_COLUMNS, working */
    const void *xs, *ys;    /* direction x per column, y per row, working */
    int32_t rotated;        /* turn (x, y, z) by the camera's rotation */
    int32_t lit;            /* the frame has lights: keep hit points and normals for the light passes (unless
                               in_pass) */
    int64_t width, row0;
    uint64_t row_magic;     /* floor(2**40 / width) + 1: band_row without a division */
    void *dirs;             /* pixels x 4: direction and |d|^2, working (rotated camera; else NULL) */
    const double *pc;       /* per shape PC_COLUMNS: the primary rays' cull data (bounds.h) */
    const float *pc32;      /* per shape P32_COLUMNS: what float lanes read of it */
    const double *floor;    /* depth floor per shape */
    Bvh tree;               /* the shapes, with the primary rays' boxes */
    /* per pixel, for the light passes (lit only; without lights, or with them applied in
     * it, the nearest-hit pass finishes the pixels itself): */
    int32_t *slot;          /* nearest shape, -1 none */
    void *sqd;              /* its sq_dist, working */
    void *pt, *nm;          /* 3 x pixels (x row, y row, z row), working */
    int64_t npix;           /* pixels of the band (lit or not) */
    uint8_t *bad;           /* hit point, or later a light, not finite */
    uint8_t *nan_px;        /* a ray of the pixel met NaN or infinity */
    double *acc;            /* 3 x pixels colour sums (red row, green row, blue row) between lights
                               (two lights or more) */
    const int32_t *index;   /* program index per shape slot (provenance) */
    int32_t background;     /* RGB565 of pixels that show no shape */
    uint16_t *rgb;          /* the band's pixels: RGB565, depth, provenance */
    float *depth;
    int32_t *prov;
    const struct Bands *in_pass; /* a frame of one shape with lights: its lights, which the nearest-hit pass
                                    applies (band.c render_band; else NULL) */
    struct Bundle *lazy;    /* the frame's primary bundle, whose subtrees may wait to be refined (setup.c
                               lazy_refine; NULL: none) */
} Band;

typedef struct {            /* one light over one band */
    const Shapes *sh;
    const Band *band;
    const void *light;      /* LT_COLUMNS, working */
    double scale[3];        /* light channel / channel maximum */
    int32_t fixed;          /* the device's 13-bit intensity converter */
    int32_t shadows;        /* cast shadow rays (there are other shapes) */
    int32_t parallel;       /* directional light */
    int32_t first;          /* the band's first light: it sets the colour sums instead of adding */
    int32_t last;           /* the band's last light: its pass also finishes the pixels */
    const double *behind;   /* rows x 3 (directional): centre . l/|l|, and the behind test's mean2
                               and (spread2 + 64 uu smax^2), NaN where no test applies */
    double l_hat[3], l_len; /* a directional light's l/|l| and |l| */
    const double *radius;   /* cull radius per row, for these shadow rays */
    Bvh tree;               /* the shapes, with these shadow rays' boxes */
    const double *keys;     /* directional light (else NULL): per node the largest stop keys below it
                               (shape_bounds.inc shadow_shapes, kernels.c bvh_refit) */
    const double *point_keys; /* point light (else NULL): per node PK_COLUMNS, its shapes' behind
                                 test's terms (cull.h point_behind4) */
    int64_t serial;         /* this light pass's number in the process, its chunks' caches kept
                               per thread (datapath.inc light_pass); 0: none kept */
} LightPass;

/* Property words per object table row (isa PROP_LIMIT). */
enum { PROP_WORDS = 32 };

/* A precision's shape_tables (datapath.inc). */
typedef int64_t (*ShapeTablesFn)(const uint16_t *values, const int64_t *index, int64_t rows, const int32_t *props,
                                 const int32_t *kinds, const void *cam, double tiny, void *sf, int64_t *si,
                                 double *bnd, uint8_t *bounded, int32_t *index_out, const Format *format,
                                 int32_t keep);

/* What a thread's bvh_build keeps from frame to frame (bvh.py tree_room): the tree depends
 * on the bounded shapes' float centres and slots and on the shapes outside it alone, so a
 * frame whose shapes did not move, given the arrays the last build wrote its tree into,
 * finds that tree there and builds nothing, as a renderer keeps a scene's hierarchy
 * between frames. */
typedef struct {
    int64_t capacity;       /* shapes the room below holds */
    int64_t valid;          /* 1: the fields below describe the last build */
    int64_t rows, counts[2], nodes;
    int64_t kept;           /* the builds that found their tree so, since it was made */
    int64_t last;           /* the half of given holding the last build's shapes */
    void *given;            /* 2 x capacity x BUILD_ITEM_BYTES: the bounded shapes as given
                               (kernels.c BuildItem), the last build's and the next's */
    const int32_t *items, *always, *where, *node; /* where the last build wrote its tree */
} TreeMemo;

typedef struct {            /* a frame's set-up (setup.c frame_setup) */
    ShapeTablesFn tables;
    const uint16_t *values; /* the object table: rows x PROP_WORDS, and each row's program index */
    const int64_t *index;
    int64_t rows;
    const int32_t *props, *kinds; /* shape_tables' columns and type codes */
    const void *cam;        /* CAM_COLUMNS, working */
    double tiny;
    const Format *format;
    char *sf;               /* out, room for rows: the shape tables (sf_row bytes a float row) */
    int64_t sf_row;
    int64_t *si;
    double *bnd;
    uint8_t *bounded;
    int32_t *index_out;
    int32_t *items, *always, *node; /* out, room for rows, rows and max(1, 2 rows) nodes: the tree */
    int32_t *where;         /* out, room for rows: per shape its row in a light's bounds (bvh_build) */
    void *room;             /* rows x BUILD_BYTES, 8-byte aligned: the build's working copies */
    TreeMemo *memo;         /* the calling thread's last tree, NULL: none kept */
    int64_t counts[2];      /* out: the tree's items and the shapes outside it */
    int64_t nodes;          /* out: its nodes */
    int64_t shapes;         /* out: the shapes on */
    int32_t jobs;           /* threads the passes split over */
    int32_t isa;            /* the tree's Morton codes' copy (kernels.c bvh_build) */
    int64_t chunk;          /* rows a range takes at least */
} Setup;

/* A bundle's shape pass: none (radii given), the primary rays' (shape_bounds.inc
 * primary_shapes) or a light's shadow rays' (shadow_shapes). A light's per-shape bounds
 * (radius, behind, keys, point) go in rows in the tree's order: the items' in leaf order,
 * then the shapes outside the tree (bvh_build's where maps a slot to its row), so that
 * each subtree's rows are made by the thread that refits the subtree (setup.c
 * subtree_task); the other passes' rows are by slot. */
enum { PASS_NONE = 0, PASS_PRIMARY = 1, PASS_SHADOW = 2 };

typedef struct Bundle {     /* one bundle of rays' bounds (setup.c bundle_bounds) */
    const double *bnd;      /* n x B_COLUMNS */
    const uint8_t *ok;      /* per shape: bounded */
    int64_t n;
    int32_t pass;
    int32_t kind;           /* BVH_CONE (lines through tree.frame[0..3)) or BVH_FLAT (normal to two axes) */
    double apex[3], dmin, dmax; /* primary_shapes' rays (dmin also shadow_shapes') */
    double mid[3], half, magnitude, chord, l_len; /* shadow_shapes' */
    const double *unit;
    double u, tiny, overflow;
    double *radius;         /* n: out of the shape pass, else given (a light's: rows, PASS_SHADOW) */
    double *floor, *pc;     /* primary: out, n and n x PC_COLUMNS (floor NULL for shadow rays) */
    float *pc32;            /* primary: out, n x P32_COLUMNS */
    double *behind, *keys;  /* directional shadow rays: out, n rows x 3 each (else NULL) */
    double *point;          /* point-light shadow rays: out, n rows x SK_COLUMNS (else NULL) */
    Bvh tree;               /* node, items, frame, nodes of the tree */
    int64_t items;          /* the tree's items */
    double *box, *own;      /* out: nodes x BV_COLUMNS, items x CI_COLUMNS (cone) or BX_COLUMNS (flat) */
    double *node_keys;      /* out where keys or point is given: nodes x 3 or PK_COLUMNS */
    int32_t jobs, isa;      /* threads the passes split over; the shape passes' copy (native.py shape_isa) */
    int64_t chunk;          /* shapes or items a range takes at least */
    uint8_t *lazy;          /* primary rays, in the frame's set-up: per node (room for 2 n), LAZY_* (NULL: the
                               bundle is made whole, as every other) */
    int64_t lazy_items;     /* the most items a waiting subtree holds */
} Bundle;

/* A frame's primary bundle over more than lazy_items shapes is made in part (setup.c
 * bundle_lazy): the roots of the largest subtrees of at most lazy_items items get bounds
 * from their shapes' extremes and wait (LAZY_WAITING); their shapes' bounds, their items'
 * cones and the nodes below them are made when a packet first enters one (lazy_refine:
 * LAZY_BUSY, then LAZY_READY), so that subtrees no packet enters cost only their
 * extremes (docs/performance.md, "Decision: subtrees made when first entered"). */
enum { LAZY_READY = 0, LAZY_WAITING = 1, LAZY_BUSY = 2, LAZY_ABOVE = 3 };
/* A waiting subtree's extremes (shape_bounds.inc subtree_extremes): the box of its
 * centres, its least smallest singular value and largest largest, and the least and
 * largest |S| bounds, smin dist and smax dist. */
enum { SX_LO = 0, SX_HI = 3, SX_SMIN = 6, SX_SMAX = 7, SX_NEAR = 8, SX_FAR = 9, SX_COLUMNS = 10 };
void lazy_refine(Bundle *b, int64_t at);

/* A pixel kernel of datapath.inc (directions, nearest, light_pass, shadow_origins): its
 * block, pixels (rows for nearest) a..b, and the report row it adds to. */
typedef void (*ChunkFn)(const void *block, int64_t a, int64_t b, double *out);

/* Per light, what its shadow rays' bounds need (double; raytracer.py _light_frames): a
 * directional light (1) or not, a point light's location, a directional light's l / |l|
 * and |l|, and two unit axes normal to l. */
enum { LF_PARALLEL = 0, LF_APEX = 1, LF_UNIT = 4, LF_LENGTH = 7, LF_AXES = 8, LF_COLUMNS = 14 };

/* What render_band counts, summed over the bands (raytracer.py _BAND_COUNTS). */
enum { BC_TESTS = 0, BC_SKIPPED = 1, BC_NAN_TESTS = 2, BC_NAN_RAYS = 3, BC_HITS = 4, BC_SHADOW_RAYS = 5,
       BC_COLUMNS = 6 };

typedef struct Bands {      /* a frame's bands, each rendered in one call (band.c render_band) */
    Band *band;             /* the frame's fields (render_band sets a band's rows, arrays and pixels) */
    ChunkFn directions, nearest, light_pass, shadow_origins; /* the precision's pixel kernels */
    Bundle *primary;        /* a camera whose directions are measured per pixel: its primary bundle, fitted
                               to each band's directions (band->tree holds its bounds); else NULL (band->tree
                               holds the frame's primary bounds) */
    const char *light_rows; /* lights x LT_COLUMNS, working, light_row bytes a row */
    int64_t light_row, lights;
    const double *light_frames; /* lights x LF_COLUMNS */
    const double *scales;   /* lights x 3: the light colour's channels over their maximum */
    int32_t fixed;          /* the device's 13-bit intensity converter */
    int32_t item;           /* bytes of a working value */
    const uint8_t *bounded; /* per shape */
    int64_t items;          /* the tree's items */
    double overflow;        /* the precision's overflow threshold */
    int32_t jobs, isa;      /* threads the passes split over; the shape passes' copy (native.py shape_isa) */
    int64_t chunk;          /* shapes or items a range takes at least */
    int64_t min_chunk, chunks_per_job; /* pixels a chunk takes at least; the most chunks a thread takes */
    int64_t counts[BC_COLUMNS]; /* out: summed over the bands */
    char *memory;           /* the bands' working memory (band_bytes for the largest band) */
    int64_t memory_bytes;
} Bands;

/* The row within its band of pixel p: (p * row_magic) >> 40 equals p / width exactly for
 * p < 2**20 and width <= 8192 (the error p * (row_magic - 2**40/width) / 2**40 < 2**-20
 * stays below the 1/width a fraction p/width keeps from the next integer). */
static inline int64_t band_row(const Band *b, int64_t p)
{
    return (int64_t)(((uint64_t)p * b->row_magic) >> 40);
}

#endif
