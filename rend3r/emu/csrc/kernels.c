/* The raytracer's compiled kernels (rend3r/emu/native.py loads them with ctypes).
 *
 * Built with the float semantics the emulator needs: no contraction of a*b+c into fused
 * multiply-adds, no fast-math, IEEE subnormals (setup.py passes -ffp-contract=off).
 * The datapath is written once (datapath.inc) and instantiated per working precision
 * and instruction set in instances/: _f32 (fp32), _h16 (fp16, subnormals flushed), _h16i
 * (fp16, IEEE subnormals), _f64 (fp64), _nar and _fmt (other formats), each _base,
 * _avx2 and _avx512. This file holds the rest: the shape hierarchy, shadow grids and
 * bounds, in double (the shape passes in a _base, an _avx2 and an _avx512 copy,
 * shape_bounds.inc).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bounds.h"
#include "bvh.h"
#include "fround.h"
#include "kernels.h"
#include "simd.h"
#include "cull.h"
#include "team.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

/* Whether this processor runs the AVX2 build of the kernels (the _avx2 files of instances/,
 * which also use F16C's float16 conversions). */
int32_t have_avx2(void)
{
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0 && __builtin_cpu_supports("f16c") != 0;
#else
    return 0;
#endif
}

/* Whether this processor runs the AVX-512 build of the kernels (the _avx512 files of
 * instances/: the AVX2 build's code with AVX-512 F, VL, BW and DQ instructions; libgcc's
 * check also asks whether the system saves the AVX-512 registers). The shape passes
 * (shape_bounds.inc) have an AVX-512 copy of their own, eight lanes wide; the pairs'
 * decoding keeps its AVX2 copy. */
int32_t have_avx512(void)
{
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    return have_avx2() && __builtin_cpu_supports("avx512f") != 0 && __builtin_cpu_supports("avx512vl") != 0
           && __builtin_cpu_supports("avx512bw") != 0 && __builtin_cpu_supports("avx512dq") != 0;
#else
    return 0;
#endif
}

/* ---- the shape hierarchy (rend3r/emu/bvh.py, csrc/bvh.h) ---- */

/* A shape while the hierarchy is built: its centre in float (the tree's shape decides only
 * how fast rays find their shapes, never what they hit) and its slot, packed so that the
 * splits walk one small array instead of following slots into the bound table. */
typedef struct { float c[3]; int32_t slot; } BuildItem;
_Static_assert(2 * sizeof(BuildItem) + 2 * sizeof(uint64_t) == BUILD_BYTES, "bvh_build's room a shape");
_Static_assert(sizeof(BuildItem) == BUILD_ITEM_BYTES, "a tree memo's shape");

/* Reorders a[lo..hi) so that a[k] has the centre coordinate `axis` that sorting would give
 * it, none before it larger and none after it smaller (quickselect). */
static void select_nth(BuildItem *a, int64_t lo, int64_t hi, int64_t k, int axis)
{
    while (hi - lo > 1) {
        float pivot = a[lo + (hi - lo) / 2].c[axis];
        int64_t i = lo, j = hi - 1;
        while (i <= j) {
            while (a[i].c[axis] < pivot) i++;
            while (a[j].c[axis] > pivot) j--;
            if (i <= j) {
                BuildItem t = a[i]; a[i] = a[j]; a[j] = t;
                i++; j--;
            }
        }
        if (k <= j) hi = j + 1;
        else if (k >= i) lo = i;
        else return;
    }
}

/* Bits per axis of the Morton codes that order the shapes before the splits, and the
 * bits of a radix sort's digit (three passes; with 8-bit digits, four passes took 2.7
 * times as long: 256 runs 2 KB apart alias in the caches). */
#define MORTON_BITS 10
#define DIGIT_BITS 10

/* x's low MORTON_BITS bits (10) spread to every third bit, in 32-bit lanes. */
static inline uint32_t morton_spread(uint32_t x)
{
    x &= 0x3ffu;
    x = (x | x << 16) & 0x030000ffu;
    x = (x | x << 8) & 0x0300f00fu;
    x = (x | x << 4) & 0x030c30c3u;
    x = (x | x << 2) & 0x09249249u;
    return x;
}

/* keys[i]: the Morton code of a[i]'s centre in steps of 1/scale from lo3 (MORTON_BITS per
 * axis, the last step taking what lies beyond it) in bits 32 up, i below. The centres lie
 * at lo3 or above, so each q is in [0, 2**MORTON_BITS]. Written in 32-bit lanes with
 * shifts, the compiler makes vector code of it: at 65,536 shapes 0.105 ms under AVX-512,
 * 0.205 under AVX2 and 0.31 portable where two table lookups an axis took 0.40. */
static inline __attribute__((always_inline)) void morton_keys(const BuildItem *a, int64_t n, const float *lo3,
                                                              double scale, uint64_t *keys)
{
    enum { TOP = (1 << MORTON_BITS) - 1 };
    double lo0 = lo3[0], lo1 = lo3[1], lo2 = lo3[2];
    for (int64_t i = 0; i < n; i++) {
        double q0 = ((double)a[i].c[0] - lo0) * scale, q1 = ((double)a[i].c[1] - lo1) * scale,
               q2 = ((double)a[i].c[2] - lo2) * scale;
        int32_t s0 = q0 < TOP ? (int32_t)q0 : TOP, s1 = q1 < TOP ? (int32_t)q1 : TOP, s2 = q2 < TOP ? (int32_t)q2 : TOP;
        uint32_t code = morton_spread((uint32_t)s0) << 2 | morton_spread((uint32_t)s1) << 1 |
                        morton_spread((uint32_t)s2);
        keys[i] = (uint64_t)code << 32 | (uint64_t)i;
    }
}

#define MORTON_KEYS(isa, target)                                                                              \
    target static void morton_keys_##isa(const BuildItem *a, int64_t n, const float *lo3, double scale,    \
                                         uint64_t *keys)                                                    \
    {                                                                                                       \
        morton_keys(a, n, lo3, scale, keys);                                                                \
    }
MORTON_KEYS(base, )
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
MORTON_KEYS(avx2, __attribute__((target("avx2"))))
MORTON_KEYS(avx512, __attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))))
#define MORTON_KEYS_OF(isa) ((isa) == 2 ? morton_keys_avx512 : (isa) == 1 ? morton_keys_avx2 : morton_keys_base)
#else
#define MORTON_KEYS_OF(isa) morton_keys_base
#endif

/* Sorts key[0..n) by bits 32 and up (stable, least significant digit first; digits that
 * every key shares are skipped), with tmp of n as room; returns where the sorted keys are.
 * The keys' four quarters are counted and scattered side by side, each with its own
 * bucket counts: shapes listed in space order make long runs of one digit, and one
 * counter's chain of increments took twice the time. */
static uint64_t *radix_sort(uint64_t *key, uint64_t *tmp, int64_t n)
{
    enum { BUCKETS = 1 << DIGIT_BITS, MASK = BUCKETS - 1, Q = 4 };
    int64_t edge[Q + 1], len = n / Q;  /* the quarters, and the length they share (the rest after) */
    for (int q = 0; q <= Q; q++)
        edge[q] = n * q / Q;
    for (int shift = 32; shift < 32 + 3 * MORTON_BITS; shift += DIGIT_BITS) {
        int64_t at[Q][BUCKETS];
        memset(at, 0, sizeof at);
        for (int64_t i = 0; i < len; i++)
            for (int q = 0; q < Q; q++)
                at[q][key[edge[q] + i] >> shift & MASK]++;
        for (int q = 0; q < Q; q++)
            for (int64_t i = edge[q] + len; i < edge[q + 1]; i++)
                at[q][key[i] >> shift & MASK]++;
        int64_t sum = 0;
        int one = 0;
        for (int d = 0; d < BUCKETS; d++) {  /* each quarter's first place per digit */
            int64_t total = 0;
            for (int q = 0; q < Q; q++) {
                int64_t c = at[q][d];
                at[q][d] = sum + total;
                total += c;
            }
            one |= total == n;
            sum += total;
        }
        if (one)
            continue;
        for (int64_t i = 0; i < len; i++)
            for (int q = 0; q < Q; q++) {
                uint64_t k = key[edge[q] + i];
                tmp[at[q][k >> shift & MASK]++] = k;
            }
        for (int q = 0; q < Q; q++)
            for (int64_t i = edge[q] + len; i < edge[q + 1]; i++)
                tmp[at[q][key[i] >> shift & MASK]++] = key[i];
        uint64_t *t = key; key = tmp; tmp = t;
    }
    return key;
}

/* *at = v; with keep, written only where it differs. */
static inline void put(int32_t *at, int32_t v, int32_t keep)
{
    if (!keep || *at != v)
        *at = v;
}

/* bvh_build's first pass: what it reads and writes (keep: as bvh_build's), and what it
 * finds: n items, outside shapes and the box lo3..hi3 of the items' centres. With last
 * (the memo's shapes of the last build, last_n of them; NULL: none) the AVX-512 pass
 * holds back the items while they equal last's: held counts them (then equal to n), -1
 * once they are written. */
typedef struct {
    const double *bnd;
    const uint8_t *bounded;
    BuildItem *a;     /* the bounded shapes with a finite centre, as given */
    int32_t *always;  /* the other shapes' slots */
    int32_t keep;
    const BuildItem *last;
    int64_t last_n, held;
    int64_t n, outside;
    float lo3[3], hi3[3];
} ShapesGiven;

/* Writes the items held back (equal to last's) to a; from here on every item is written. */
static inline void release(ShapesGiven *g)
{
    if (g->held > 0)
        memcpy(g->a, g->last, (size_t)g->held * sizeof *g->a);
    g->held = -1;
}

/* Shape s into a or always, its centre joined to the box. */
static inline void give_shape(ShapesGiven *g, int64_t s)
{
    release(g);
    const double *c = g->bnd + B_COLUMNS * s;
    if (!(g->bounded[s] && isfinite(c[0]) && isfinite(c[1]) && isfinite(c[2]))) {
        put(g->always + g->outside++, (int32_t)s, g->keep);
        return;
    }
    BuildItem *t = g->a + g->n++;
    *t = (BuildItem){{(float)c[0], (float)c[1], (float)c[2]}, (int32_t)s};
    for (int k = 0; k < 3; k++) { g->lo3[k] = MIN(g->lo3[k], t->c[k]); g->hi3[k] = MAX(g->hi3[k], t->c[k]); }
}

/* The first pass over rows shapes, one at a time. */
static void first_pass_base(ShapesGiven *g, int64_t rows)
{
    for (int64_t s = 0; s < rows; s++)
        give_shape(g, s);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
/* The first pass on AVX-512, eight shapes at a time where all eight are bounded with
 * finite centres (else one at a time): their centre columns gathered, converted to floats
 * in one instruction each, made into eight items by shuffles and joined to a box of eight
 * lanes. The same items and outside list as first_pass_base; the box the same but for
 * the sign of a zero at its edge, which the Morton codes do not see (x - +0 and x - -0
 * differ only for x = -0, and then both quantise to 0). While the items equal the last
 * build's they are compared as they are made and not written: a frame whose shapes did
 * not move writes none and compares none after (memo_holds' memcmp of both copies). A
 * 65,536-sphere fp32 frame whose tree is kept: 0.985x the time of the scalar pass, which
 * wrote every item, then compared 2 MiB (interleaved A/B, 40 rounds). */
__attribute__((target("avx2,avx512f,avx512vl,avx512dq"))) static void
first_pass_avx512(ShapesGiven *g, int64_t rows)
{
    const __m512i at = _mm512_setr_epi64(0, 5, 10, 15, 20, 25, 30, 35);
    _Static_assert(B_COLUMNS == 5 && B_CENTER == 0, "at follows the bound table's rows");
    f32x8 lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = (f32x8){0} + g->lo3[k];
        hi[k] = (f32x8){0} + g->hi3[k];
    }
    const i32x8 step = {0, 1, 2, 3, 4, 5, 6, 7};
    int64_t s = 0;
    for (; s + 8 <= rows; s += 8) {
        const double *c = g->bnd + B_COLUMNS * s;
        __m512d x = _mm512_i64gather_pd(at, c, 8), y = _mm512_i64gather_pd(at, c + 1, 8),
                z = _mm512_i64gather_pd(at, c + 2, 8);
        uint64_t flags;
        memcpy(&flags, g->bounded + s, sizeof flags);
        __mmask8 ok = _mm512_test_epi64_mask(_mm512_cvtepu8_epi64(_mm_cvtsi64_si128((long long)flags)),
                                             _mm512_set1_epi64(0xFF));
        ok &= ~(_mm512_fpclass_pd_mask(x, 0x99) | _mm512_fpclass_pd_mask(y, 0x99) | _mm512_fpclass_pd_mask(z, 0x99));
        if (ok != 0xFF) {  /* NaN, an infinity or a shape not bounded among them */
            for (int64_t k = s; k < s + 8; k++)
                give_shape(g, k);
            continue;
        }
        f32x8 f[3] = {(f32x8)_mm512_cvtpd_ps(x), (f32x8)_mm512_cvtpd_ps(y), (f32x8)_mm512_cvtpd_ps(z)};
        f32x8 slot = (f32x8)(step + (int32_t)s);
        for (int k = 0; k < 3; k++) {
            lo[k] = (f32x8)SEL_BITS((i32x8)(f[k] < lo[k]), (i32x8)f[k], (i32x8)lo[k]);
            hi[k] = (f32x8)SEL_BITS((i32x8)(f[k] > hi[k]), (i32x8)f[k], (i32x8)hi[k]);
        }
        f32x8 t0 = __builtin_shufflevector(f[0], f[1], 0, 8, 1, 9, 4, 12, 5, 13);
        f32x8 t1 = __builtin_shufflevector(f[0], f[1], 2, 10, 3, 11, 6, 14, 7, 15);
        f32x8 t2 = __builtin_shufflevector(f[2], slot, 0, 8, 1, 9, 4, 12, 5, 13);
        f32x8 t3 = __builtin_shufflevector(f[2], slot, 2, 10, 3, 11, 6, 14, 7, 15);
        f32x8 r0 = __builtin_shufflevector(t0, t2, 0, 1, 8, 9, 4, 5, 12, 13);  /* items 0 and 4 */
        f32x8 r1 = __builtin_shufflevector(t0, t2, 2, 3, 10, 11, 6, 7, 14, 15);  /* 1 and 5 */
        f32x8 r2 = __builtin_shufflevector(t1, t3, 0, 1, 8, 9, 4, 5, 12, 13);  /* 2 and 6 */
        f32x8 r3 = __builtin_shufflevector(t1, t3, 2, 3, 10, 11, 6, 7, 14, 15);  /* 3 and 7 */
        f32x8 out[4] = {__builtin_shufflevector(r0, r1, 0, 1, 2, 3, 8, 9, 10, 11),
                        __builtin_shufflevector(r2, r3, 0, 1, 2, 3, 8, 9, 10, 11),
                        __builtin_shufflevector(r0, r1, 4, 5, 6, 7, 12, 13, 14, 15),
                        __builtin_shufflevector(r2, r3, 4, 5, 6, 7, 12, 13, 14, 15)};
        _Static_assert(sizeof(BuildItem) == 16, "two items a vector");
        if (g->held >= 0 && g->n + 8 <= g->last_n) {  /* the last build's items so far: these too? */
            __m256i d = _mm256_setzero_si256();
            for (int k = 0; k < 4; k++)
                d |= _mm256_loadu_si256((const __m256i *)(g->last + g->n) + k) ^ (__m256i)out[k];
            if (_mm256_testz_si256(d, d)) {
                g->n += 8;
                g->held = g->n;
                continue;
            }
        }
        release(g);
        memcpy(g->a + g->n, out, sizeof out);
        g->n += 8;
    }
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 8; i++) {
            g->lo3[k] = MIN(g->lo3[k], lo[k][i]);
            g->hi3[k] = MAX(g->hi3[k], hi[k][i]);
        }
    for (; s < rows; s++)
        give_shape(g, s);
}
#define FIRST_PASS_OF(isa) ((isa) == 2 ? first_pass_avx512 : first_pass_base)
#else
#define FIRST_PASS_OF(isa) first_pass_base
#endif

/* Whether memo describes the tree of these inputs, written into these arrays: rows rows
 * and the n bounded shapes as given (a, or with held the memo's own, which the first pass
 * found them equal to; their slots, in order, make the outside ones the other rows, so
 * those need no comparison of their own). */
static int memo_holds(const TreeMemo *memo, int64_t rows, const BuildItem *a, int64_t n, int64_t outside,
                      const int32_t *items, const int32_t *always, const int32_t *where, const int32_t *node,
                      int held)
{
    return memo != NULL && memo->valid && memo->rows == rows && memo->counts[0] == n &&
           memo->counts[1] == outside && memo->items == items && memo->always == always && memo->where == where &&
           memo->node == node &&
           (held || memcmp((const BuildItem *)memo->given + memo->capacity * memo->last, a, (size_t)n * sizeof *a) == 0);
}

/* The hierarchy over the shapes of bnd (n rows) that are bounded with a finite centre;
 * their slots go to items (count[0] of them), the others' to always (count[1]). The
 * shapes are ordered along a Morton curve of their centres, quantised to 2**MORTON_BITS
 * steps per axis on the cube around them (an O(n) radix sort), and a node's shapes are
 * split where the highest bit their codes differ in changes: halves of the cube's cell
 * holding them, the longest side first. Shapes that share a code (closer than a step)
 * are split across the longest side of their centres' box (quickselect) at the median
 * rounded up to whole leaves.
 * Leaves hold at most BVH_LEAF shapes. items is ordered leaf by leaf; node (2 ints per
 * node, room for 2n nodes) gets the nodes depth first; room (rows x BUILD_BYTES, 8-byte
 * aligned) holds the working copies; where gets each shape's row in a light's bounds
 * (kernels.h PASS_SHADOW): its place in items, or count[0] plus its place in always.
 * With keep (other threads read the tree), items, always, where and node are written
 * only where they differ: the tree depends on the centres alone, and a frame whose shapes
 * did not move then leaves the last frame's in the other threads' caches
 * (docs/performance-history.md, "Rows left alone"). memo (NULL: none; ignored past its
 * capacity) holds the shapes as given, and says whether items, always, where and node
 * hold the tree of the same shapes already, written by the last build: then nothing is
 * built. isa picks the Morton codes' copy (0 portable, 1 AVX2, 2 AVX-512: the same codes).
 * Returns the node count. */
int64_t bvh_build(const double *bnd, const uint8_t *bounded, int64_t rows, int32_t *items, int32_t *always,
                  int32_t *where, int32_t *node, int64_t *count_out, void *room, int32_t keep, TreeMemo *memo,
                  int32_t isa)
{
    int64_t stack[4 * BVH_STACK], top = 1, count = 0;
    count_out[0] = count_out[1] = 0;
    if (rows <= 0)
        return 0;
    uint64_t *keys = room;  /* 2 rows keys, then the shapes twice: as given (with a memo, in its
                               half instead), then in Morton order */
    if (memo != NULL && rows > memo->capacity) {  /* too small: it keeps nothing */
        memo->valid = 0;
        memo = NULL;
    }
    BuildItem *a = memo != NULL ? (BuildItem *)memo->given + memo->capacity * (1 - memo->last)
                                : (BuildItem *)(keys + 2 * rows), *sorted = (BuildItem *)(keys + 2 * rows) + rows;
    int last = memo != NULL && memo->valid;
    ShapesGiven g = {bnd, bounded, a, always, keep,
                     last ? (const BuildItem *)memo->given + memo->capacity * memo->last : NULL,
                     last ? memo->counts[0] : 0, last ? 0 : -1, 0, 0,
                     {INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    FIRST_PASS_OF(isa)(&g, rows);
    int64_t n = g.n, outside = g.outside;
    const float *lo3 = g.lo3, *hi3 = g.hi3;
    count_out[0] = n;
    count_out[1] = outside;
    if (memo_holds(memo, rows, a, n, outside, items, always, where, node, g.held == n)) {
        memo->kept++;
        return memo->nodes;
    }
    release(&g);
    if (memo != NULL)
        memo->valid = 0;
    for (int64_t k = 0; k < outside; k++)
        put(where + always[k], (int32_t)(n + k), keep);
    if (n == 0)
        return 0;
    double side = MAX(MAX((double)hi3[0] - lo3[0], (double)hi3[1] - lo3[1]), (double)hi3[2] - lo3[2]);
    double scale = side > 0 && side < INFINITY ? (double)(1 << MORTON_BITS) / side : 0.0;  /* else one code */
    MORTON_KEYS_OF(isa)(a, n, lo3, scale, keys);
    uint64_t *key = radix_sort(keys, keys + n, n);
    for (int64_t i = 0; i < n; i++) {
        sorted[i] = a[key[i] & 0xFFFFFFFFu];
        key[i] >>= 32;
    }
    const BuildItem *given = a;
    a = sorted;
    /* pending ranges: lo, hi, the parent whose right child it is (-1: none), depth */
    stack[0] = 0; stack[1] = n; stack[2] = -1; stack[3] = 0;
    while (top > 0) {
        top--;
        int64_t lo = stack[4 * top], hi = stack[4 * top + 1], parent = stack[4 * top + 2], depth = stack[4 * top + 3];
        int64_t at = count++;
        if (parent >= 0)
            put(node + 2 * parent, (int32_t)at, keep);
        if (hi - lo <= BVH_LEAF || depth + 2 >= BVH_STACK) {  /* traversal stacks hold depth + 2 nodes */
            put(node + 2 * at, (int32_t)lo, keep);
            put(node + 2 * at + 1, (int32_t)(hi - lo), keep);
            continue;
        }
        int64_t mid;
        uint64_t differ = key[lo] ^ key[hi - 1];  /* sorted: the range shares the bits above */
        if (differ) {  /* the first shape with the highest differing bit set */
            uint64_t bit = (uint64_t)1 << (63 - __builtin_clzll(differ));
            int64_t l = lo, h = hi - 1;
            while (l < h) {
                int64_t m = l + (h - l) / 2;
                if (key[m] & bit) h = m;
                else l = m + 1;
            }
            mid = l;
        } else {
            float bl[3] = {INFINITY, INFINITY, INFINITY}, bh[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (int64_t i = lo; i < hi; i++)
                for (int k = 0; k < 3; k++) { bl[k] = MIN(bl[k], a[i].c[k]); bh[k] = MAX(bh[k], a[i].c[k]); }
            int axis = 0;
            for (int k = 1; k < 3; k++)
                if (bh[k] - bl[k] > bh[axis] - bl[axis])
                    axis = k;
            mid = lo + ((hi - lo) / 2 + BVH_LEAF - 1) / BVH_LEAF * BVH_LEAF;  /* full leaves: fewer nodes */
            if (bh[axis] > bl[axis])  /* else every centre is the same */
                select_nth(a, lo, hi, mid, axis);
        }
        put(node + 2 * at + 1, 0, keep);
        int64_t right[4] = {mid, hi, at, depth + 1}, left[4] = {lo, mid, -1, depth + 1};
        memcpy(stack + 4 * top++, right, sizeof right);  /* after the left subtree */
        memcpy(stack + 4 * top++, left, sizeof left);    /* the next node */
    }
    for (int64_t i = 0; i < n; i++) {
        put(items + i, a[i].slot, keep);
        put(where + a[i].slot, (int32_t)i, keep);
    }
    if (memo != NULL)
        *memo = (TreeMemo){.capacity = memo->capacity, .valid = 1, .rows = rows, .counts = {n, outside},
                           .nodes = count, .kept = memo->kept, .last = given != (BuildItem *)memo->given,
                           .given = memo->given, .items = items, .always = always, .where = where, .node = node};
    return count;
}

/* A cone's half-angle t is kept as its sine and cosine; from CONE_EVERY on (t within
 * 0.9 degree of pi/2, a cosine below 1/64) the cone holds every line, and its sine is
 * inf. */
#define CONE_EVERY 0.99987792197

/* The sine s and cosine of a half-angle widened by 1e-12 of s and 1e-13 (inf: every line),
 * into cs. */
#define CONE_WIDENED(s) ((s) * (1.0 + 1e-12) + 1e-13)
#define CONE_COS2(s) ((1.0 - (s)) * (1.0 + (s)))  /* the squared cosine of sine s */
static inline void cone_widen(double s, double *cs)
{
    s = CONE_WIDENED(s);
    cs[0] = s < CONE_EVERY ? s : INFINITY;  /* NaN: every line */
    cs[1] = s < CONE_EVERY ? sqrt(CONE_COS2(s)) : 0.0;
}

/* The double cone (unit axis a1, sine and cosine cs1 of its half-angle t1) around the
 * apex made to hold cones 1 and 2 (lines: a2 counts as -a2 too), the smallest such cone,
 * found with the addition and half-angle formulas rather than trigonometry. With phi the
 * angle between the axes (cosine cp = |a1.a2|, sine sp = |a2 - cp a1|): cone 1 holds
 * cone 2 when phi + t2 <= t1, cone 2 holds cone 1 when phi + t1 <= t2; otherwise the axis
 * is a1 turned towards a2 by turn = (phi + t2 - t1) / 2, whose cosine and sine come from
 * those of 2 turn, and the half-angle is t1 + turn. Every sine and cosine computed here
 * is a sum of products of unit-bounded terms and at most two square roots away from the
 * inputs, so it carries an absolute error of a few tens of ulps (2**-52) and the axis
 * turns by as little; the result is widened by 1e-13 (cone_widen), over a hundred times
 * that. */
static void cone_union(double *a1, double *cs1, const double *a2_, const double *cs2)
{
    double s1 = cs1[0], c1 = cs1[1], s2 = cs2[0], c2 = cs2[1];
    if (s1 >= CONE_EVERY)
        return;
    if (s2 >= CONE_EVERY) {
        cs1[0] = INFINITY;
        return;
    }
    double a2[3] = {a2_[0], a2_[1], a2_[2]}, cp = a1[0] * a2[0] + a1[1] * a2[1] + a1[2] * a2[2];
    if (cp < 0) {
        a2[0] = -a2[0]; a2[1] = -a2[1]; a2[2] = -a2[2]; cp = -cp;
    }
    double w[3] = {a2[0] - cp * a1[0], a2[1] - cp * a1[1], a2[2] - cp * a1[2]};
    double sp = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    double cq = cp * c2 - sp * s2, sq = sp * c2 + cp * s2;  /* phi + t2 */
    double su = sq * c1 - cq * s1, cu = cq * c1 + sq * s1;  /* 2 turn = phi + t2 - t1, in (-pi/2, pi) */
    if (!(su > 0)) {  /* cone 1 holds cone 2 */
        cone_widen(s1, cs1);
        return;
    }
    double cr = cp * c1 - sp * s1, sr = sp * c1 + cp * s1;  /* phi + t1 */
    if (s2 * cr - c2 * sr >= 0) {  /* sin(t2 - phi - t1) >= 0: cone 2 holds cone 1 */
        memcpy(a1, a2, sizeof a2);
        cone_widen(s2, cs1);
        return;
    }
    double ct, st;  /* turn in (0, phi), stably from 2 turn */
    if (cu >= 0) {
        ct = sqrt((1.0 + cu) / 2);
        st = su / (2 * ct);
    } else {
        st = sqrt((1.0 - cu) / 2);
        ct = su / (2 * st);
    }
    double axis[3], len = 0;
    for (int c = 0; c < 3; c++) {
        axis[c] = ct * a1[c] + st * w[c] / sp;
        len += axis[c] * axis[c];
    }
    len = sqrt(len);
    for (int c = 0; c < 3; c++)
        a1[c] = axis[c] / len;
    double ct1 = ct * c1 - st * s1;  /* cos(t1 + turn) */
    cone_widen(ct1 < 1.0 / 64 ? INFINITY : st * c1 + ct * s1, cs1);
}

/* A float's unit roundoff, 2**-24. */
#define U32 5.9604644775390625e-08

/* Refits visit leaves last to first: the floor of the shape of item i - REFIT_AHEAD is
 * fetched while item i's is joined (leaf order jumps about the slots, and at tens of
 * thousands of shapes these rows lie in the last-level cache). Keys are a light's, in rows
 * in leaf order (kernels.h PASS_SHADOW). */
#define REFIT_AHEAD 16
static inline void fetch_behind(const Bvh *t, int32_t i, const double *floor)
{
    if (i >= REFIT_AHEAD && floor != NULL)
        __builtin_prefetch(floor + t->items[i - REFIT_AHEAD]);
}

/* A node's float columns: a double rounded to a float towards -infinity (down) or
 * +infinity (up). bounds.h floor32 and ceil32 round to nearest, then step; AVX-512 makes
 * one conversion in the rounding it names (the same float: both are IEEE's directed
 * roundings, NaN kept), where the refits' scalar selects took 2-2.5% of a 65,536-sphere frame. */
typedef float (*Round32)(double);
static inline float down32_base(double x) { return (float)floor32(x); }
static inline float up32_base(double x) { return (float)ceil32(x); }
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
__attribute__((target("avx512f"))) static inline float down32_avx512(double x)
{
    return _mm_cvtss_f32(_mm_cvt_roundsd_ss(_mm_setzero_ps(), _mm_set_sd(x), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC));
}
__attribute__((target("avx512f"))) static inline float up32_avx512(double x)
{
    return _mm_cvtss_f32(_mm_cvt_roundsd_ss(_mm_setzero_ps(), _mm_set_sd(x), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC));
}
#endif

/* bvh_refit for parallel lines: per node the box holding its shapes' boxes, its least
 * floor, both rounded outwards to floats, and where keys is not NULL the largest of each
 * of its shapes' stop keys (3 per shape, shape_bounds.inc shadow_shapes; 3 per node into
 * node_keys): a packet for which the keys' test holds has every shape below the node
 * behind every origin (K1 multiplies spread >= 0, so the test only gets harder as keys
 * grow). The bounds are joined in locals (reading back the stores as a vector stalled on
 * store forwarding). */
static inline __attribute__((always_inline)) void refit_flat(const Bvh *t, const double *floor, double *box,
                                                              const double *items, const double *keys,
                                                              double *node_keys, int64_t lo, int64_t hi,
                                                              Round32 down, Round32 up)
{
    for (int64_t at = hi - 1; at >= lo; at--) {
        double *b = box + BV_COLUMNS * at;
        int32_t first = t->node[2 * at], count = t->node[2 * at + 1];
        double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY, fl = INFINITY;
        double k[3] = {-INFINITY, -INFINITY, -INFINITY};
        if (count == 0) {
            const double *l = box + BV_COLUMNS * (at + 1), *r = box + BV_COLUMNS * (int64_t)first;
            u0 = MIN(l[BV_U0], r[BV_U0]); u1 = MAX(l[BV_U1], r[BV_U1]);
            v0 = MIN(l[BV_V0], r[BV_V0]); v1 = MAX(l[BV_V1], r[BV_V1]);
            fl = MIN(l[BV_FLOOR], r[BV_FLOOR]);
            for (int c = 0; keys != NULL && c < 3; c++)
                k[c] = MAX(node_keys[3 * (at + 1) + c], node_keys[3 * (int64_t)first + c]);
        }
        for (int32_t i = first; count > 0 && i < first + count; i++) {
            const double *o = items + BX_COLUMNS * (int64_t)i;  /* the shape's own box (flat_items) */
            fetch_behind(t, i, floor);
            fl = MIN(fl, floor != NULL ? floor[t->items[i]] : -INFINITY);
            u0 = MIN(u0, o[BV_U0]); u1 = MAX(u1, o[BV_U1]);
            v0 = MIN(v0, o[BV_V0]); v1 = MAX(v1, o[BV_V1]);
            for (int c = 0; keys != NULL && c < 3; c++)
                k[c] = MAX(k[c], keys[3 * (int64_t)i + c]);
        }
        if (keys != NULL)
            memcpy(node_keys + 3 * at, k, sizeof k);
        b[BV_U0] = u0; b[BV_U1] = u1; b[BV_V0] = v0; b[BV_V1] = v1;
        b[BV_FLOOR] = fl;
        float *f = node32(b, BV_F32);
        f[F32_FLOOR] = down(fl);
        f[F32_BOX] = down(u0); f[F32_BOX + 1] = up(u1);
        f[F32_BOX + 2] = down(v0); f[F32_BOX + 3] = up(v1);
        f[F32_PAD] = 0.0f;
    }
}

/* A point light's behind-test terms of a node (PK_COLUMNS) joined with those of a shape
 * (SK_COLUMNS, shape) or of a child node: the box of the centres, the least mean2, the
 * largest K and radius. A NaN makes the node's terms claim nothing: the box stays NaN,
 * mean2 becomes 0, K and the radius inf. */
static inline void point_join(double *pk, const double *e, int shape)
{
    const double *c = e + (shape ? SK_CENTER : PK_LO), *h = e + (shape ? SK_CENTER : PK_HI);
    for (int k = 0; k < 3; k++) {  /* a NaN stays */
        double a = pk[PK_LO + k], z = pk[PK_HI + k];
        pk[PK_LO + k] = a != a || c[k] != c[k] ? NAN : MIN(a, c[k]);
        pk[PK_HI + k] = z != z || h[k] != h[k] ? NAN : MAX(z, h[k]);
    }
    double m = e[shape ? SK_MEAN2 : PK_MEAN2], kk = e[shape ? SK_K : PK_K], r = e[shape ? SK_R : PK_R];
    pk[PK_MEAN2] = m >= pk[PK_MEAN2] ? pk[PK_MEAN2] : m == m ? m : 0.0;
    pk[PK_K] = kk <= pk[PK_K] ? pk[PK_K] : kk == kk ? kk : INFINITY;
    pk[PK_R] = r <= pk[PK_R] ? pk[PK_R] : r == r ? r : INFINITY;
}

/* What the kernels' tests read of a cone node b from its axis, sine and floor: the squared
 * sine widened (inf from CONE_EVERY on: every line), and the float columns (bvh.h
 * cone_missed8): the floor rounded down, the axis rounded, the float test's squared sine
 * rounded up. */
static inline __attribute__((always_inline)) void cone_tests(double *b, Round32 down, Round32 up)
{
    float *f = node32(b, BV_F32);
    f[F32_FLOOR] = down(b[BV_FLOOR]);
    double sine = b[BV_SINE];
    int cone = sine < CONE_EVERY && b[BV_AXIS] == b[BV_AXIS];
    b[BV_SIN2] = cone ? sine * sine * (1.0 + 1e-9) : INFINITY;
    for (int c = 0; c < 3; c++)
        f[F32_AXIS + c] = (float)b[BV_AXIS + c];
    f[F32_SIN2] = cone ? up((sine * (1.0 + 1e-9) + 8 * U32) * (sine * (1.0 + 1e-9) + 8 * U32) * (1.0 + 10 * U32))
                       : INFINITY;
    f[F32_PAD] = 0.0f;
}

/* cone_tests for a node whose bounds are set otherwise (setup.c bundle_lazy). */
void cone_node(double *b)
{
    cone_tests(b, down32_base, up32_base);
}

/* bvh_refit for lines through an apex: per node the double cone holding its shapes'
 * cones, its least floor, the cone's squared sine for the tests, and where keys is not
 * NULL (a point light's shadow rays: SK_COLUMNS per shape) its behind-test terms
 * (PK_COLUMNS per node into node_keys). */
static inline __attribute__((always_inline)) void refit_cones(const Bvh *t, const double *floor, double *box,
                                                               const double *items, const double *keys,
                                                               double *node_keys, int64_t lo, int64_t hi,
                                                               Round32 down, Round32 up)
{
    for (int64_t at = hi - 1; at >= lo; at--) {
        double *b = box + BV_COLUMNS * at;
        int32_t first = t->node[2 * at], count = t->node[2 * at + 1];
        double fl = INFINITY;
        double pk[PK_COLUMNS] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY, INFINITY, 0.0, 0.0};
        if (count == 0) {
            const double *l = box + BV_COLUMNS * (at + 1), *r = box + BV_COLUMNS * (int64_t)first;
            memcpy(b + BV_AXIS, l + BV_AXIS, 3 * sizeof(double));
            b[BV_SINE] = l[BV_SINE];
            b[BV_COS] = l[BV_COS];
            cone_union(b + BV_AXIS, b + BV_SINE, r + BV_AXIS, r + BV_SINE);
            fl = MIN(l[BV_FLOOR], r[BV_FLOOR]);
            if (keys != NULL) {
                point_join(pk, node_keys + PK_COLUMNS * (at + 1), 0);
                point_join(pk, node_keys + PK_COLUMNS * (int64_t)first, 0);
            }
        }
        for (int32_t i = first; count > 0 && i < first + count; i++) {
            const double *o = items + CI_COLUMNS * (int64_t)i;  /* the shape's own cone (cone_items) */
            fetch_behind(t, i, floor);
            fl = MIN(fl, floor != NULL ? floor[t->items[i]] : -INFINITY);
            if (keys != NULL)
                point_join(pk, keys + SK_COLUMNS * (int64_t)i, 1);
            if (i == first) {
                memcpy(b + BV_AXIS, o, 3 * sizeof(double));
                b[BV_SINE] = o[CI_SINE];
                b[BV_COS] = o[CI_COS];
            } else {
                cone_union(b + BV_AXIS, b + BV_SINE, o, o + CI_SINE);
            }
        }
        b[BV_FLOOR] = fl;
        cone_tests(b, down, up);
        if (keys != NULL)
            memcpy(node_keys + PK_COLUMNS * at, pk, sizeof pk);
    }
}

/* One bundle's bounds of nodes lo..hi (BV_COLUMNS each into box) from its shapes' own
 * bounds (items, in leaf order): for BVH_CONE the double cones around the apex holding the
 * shapes' cones (CI_COLUMNS per item, from cone_items), for parallel lines (BVH_FLAT) the
 * boxes holding the shapes' boxes (BX_COLUMNS per item, from flat_items); and each node's
 * least floor (NULL: -inf, by slot); boxes also the stop keys of a directional light's
 * shadow rays (keys NULL: none; refit_flat), cones a point light's behind-test terms
 * (refit_cones), both in rows in leaf order (kernels.h PASS_SHADOW).
 * Children follow their parent, so nodes go last to
 * first, and lo..hi must hold the subtrees of the nodes it holds (bvh.py refits subtrees
 * on several threads, then the nodes above them); a cone gets the squared sine of its
 * half-angle (inf from CONE_EVERY on: every line) for the kernels' test, a box its bounds
 * rounded outwards to floats; isa 2: the AVX-512 copy (the same bounds, bit for bit). */
#define REFITS(isa, target)                                                                                   \
    target static void refit_##isa(const Bvh *t, const double *floor, int32_t kind, double *box,              \
                                   const double *items, const double *keys, double *node_keys, int64_t lo,    \
                                   int64_t hi)                                                                \
    {                                                                                                         \
        if (kind == BVH_FLAT)                                                                                 \
            refit_flat(t, floor, box, items, keys, node_keys, lo, hi, down32_##isa, up32_##isa);              \
        else                                                                                                  \
            refit_cones(t, floor, box, items, keys, node_keys, lo, hi, down32_##isa, up32_##isa);             \
    }
REFITS(base, )
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
REFITS(avx512, __attribute__((target("avx512f"))))
#define REFIT_OF(isa) ((isa) == 2 ? refit_avx512 : refit_base)
#else
#define REFIT_OF(isa) refit_base
#endif

void bvh_refit(const Bvh *t, const double *floor, int32_t kind, double *box, const double *items, const double *keys,
               double *node_keys, int64_t lo, int64_t hi, int32_t isa)
{
    if (lo < 0 || hi > t->nodes)
        return;
    REFIT_OF(isa)(t, floor, kind, box, items, keys, node_keys, lo, hi);
}

/* ---- bounds per shape (rend3r/emu/bounds.py) ---- */

#define LANES 4
#define SB(name) name##_base
#include "shape_bounds.inc"
#undef SB
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#pragma GCC push_options
#pragma GCC target("avx2")
#define SB(name) name##_avx2
#include "shape_bounds.inc"
#undef SB
#pragma GCC pop_options
#undef LANES
#define LANES 8
#pragma GCC push_options
#pragma GCC target("avx2,avx512f,avx512vl,avx512bw,avx512dq")
#define SB(name) name##_avx512
#define SB_DIRECTED
#include "shape_bounds.inc"
#undef SB_DIRECTED
#undef SB
#pragma GCC pop_options
#endif
#undef LANES

/* ---- the instruction processor (rend3r/emu/processor.py) ---- */

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#pragma GCC push_options
#pragma GCC target("avx2")
/* stream_scan's runs of pairs on AVX2, from word i on: whole blocks of eight pairs (16
 * words below n) whose SE words all have the opcode se_op, their addresses into pair.
 * Returns where it stopped. The addresses are built as vectors and stored two at a time;
 * the portable loop in stream_scan (without AVX2), compiled for baseline x86-64, put the
 * SE words' vector together a word at a time and stored each address. */
static int64_t scan_pairs8(const uint32_t *words, int64_t i, int64_t n, int32_t op_lo, uint32_t mask, uint32_t se_op,
                           int64_t *pair)
{
    const i64x4 step = {0, 2, 4, 6};
    for (; i + 16 <= n; i += 16, pair += 8) {
        u32x8 lo, hi;
        memcpy(&lo, words + i, sizeof lo);
        memcpy(&hi, words + i + 8, sizeof hi);
        u32x8 se = __builtin_shufflevector(lo, hi, 0, 2, 4, 6, 8, 10, 12, 14);
        if (mask_bits_32x8((i32x8)(((se >> op_lo) & mask) == se_op)) != 255)
            break;
        i64x4 a0 = step + i, a1 = step + (i + 8);
        memcpy(pair, &a0, sizeof a0);
        memcpy(pair + 4, &a1, sizeof a1);
    }
    return i;
}
#pragma GCC pop_options
#define SCAN8 1
#else
#define SCAN8 0
#endif

/* The instructions met reading words linearly from address start (_Stream): an SE word
 * takes the next word as its SD whatever that word is (an SE in the last word has none),
 * any other word is one instruction. Each instruction's address goes to a list, in address
 * order: list kind[opcode] (0 unknown opcodes, 1 C, 2 L, 3 SE), and for the frame-control
 * opcode (its kind is 4) list 4 + the word's two-bit function field (ER, NR, NF, LR).
 * List k is lists + k * room (room: at least n - start); count[k] is how many it got. The counts stay
 * in locals (an array indexed by the kind put a store and a load on each word's path).
 * Runs of pairs are read eight pairs at a time (a 65,536-sphere program's 655,373 words
 * took 0.3 ms a word or a pair at a time), with avx2 by scan_pairs8. */
void stream_scan(const uint32_t *words, int64_t n, int64_t start, int32_t op_lo, int32_t op_width, int32_t func_lo,
                 const uint8_t *kind, int64_t *lists, int64_t room, int64_t *count, int32_t avx2)
{
    uint32_t mask = (1u << op_width) - 1u;
    int64_t *unknown = lists, *camera = lists + room, *light = lists + 2 * room, *pair = lists + 3 * room;
    int64_t *er = lists + 4 * room, *nr = lists + 5 * room, *nf = lists + 6 * room, *lr = lists + 7 * room;
    int64_t c0 = 0, c1 = 0, c2 = 0, c3 = 0, c4 = 0, c5 = 0, c6 = 0, c7 = 0;
    int64_t se_op = -1;  /* the one opcode of list 3, else negative */
    for (uint32_t op = 0; op <= mask; op++)
        if (kind[op] == 3)
            se_op = se_op == -1 ? (int64_t)op : -2;
    for (int64_t i = start; i < n;) {  /* by how often each comes: pairs, then C and L words */
        uint32_t w = words[i];
        int k = kind[(w >> op_lo) & mask];
        if (k == 3) {
            pair[c3++] = i;
            i += 2;
#if SCAN8
            if (avx2 && se_op >= 0) {  /* a run of pairs (a program's shapes): eight at a time */
                int64_t end = scan_pairs8(words, i, n, op_lo, mask, (uint32_t)se_op, pair + c3);
                c3 += (end - i) / 2;
                i = end;  /* the loop below stops at the same block */
            }
#endif
            while (se_op >= 0 && i + 16 <= n) {
                u32x8 lo, hi;
                memcpy(&lo, words + i, sizeof lo);
                memcpy(&hi, words + i + 8, sizeof hi);
                u32x8 se = __builtin_shufflevector(lo, hi, 0, 2, 4, 6, 8, 10, 12, 14);
                if (mask_bits_32x8((i32x8)(((se >> op_lo) & mask) == (uint32_t)se_op)) != 255)
                    break;
                for (int j = 0; j < 8; j++)
                    pair[c3 + j] = i + 2 * j;
                c3 += 8;
                i += 16;
            }
        } else if (k == 1) {
            camera[c1++] = i++;
        } else if (k == 2) {
            light[c2++] = i++;
        } else if (k == 4) {
            uint32_t f = (w >> func_lo) & 3u;
            if (f == 0)
                er[c4++] = i++;
            else if (f == 1)
                nr[c5++] = i++;
            else if (f == 2)
                nf[c6++] = i++;
            else
                lr[c7++] = i++;
        } else {
            unknown[c0++] = i++;
        }
    }
    int64_t c[8] = {c0, c1, c2, c3, c4, c5, c6, c7};
    memcpy(count, c, sizeof c);
}

/* The C or L words at addresses at[0..n) (_Stream camera, lights) as writes: those whose
 * property (fields[0], [1]: its lo bit and width) is not null (null: a flag per value
 * of that field) go, in the order of at, to out_at, out_index (fields[2], [3]; width 0: 0,
 * at most 31), out_prop and out_bits (fields[4], [5]: the data, at most 16 bits).
 * Returns how many. */
int64_t word_writes(const uint32_t *words, const int64_t *at, int64_t n, const int32_t *fields, const uint8_t *null,
                    int64_t *out_at, uint32_t *out_index, uint32_t *out_prop, uint16_t *out_bits)
{
    uint32_t prop_mask = (1u << fields[1]) - 1u, index_mask = (1u << fields[3]) - 1u;
    uint32_t data_mask = (1u << fields[5]) - 1u;
    int64_t kept = 0;
    for (int64_t k = 0; k < n; k++) {
        uint32_t w = words[at[k]], prop = (w >> fields[0]) & prop_mask;
        if (null[prop])
            continue;
        out_at[kept] = at[k];
        out_index[kept] = (w >> fields[2]) & index_mask;
        out_prop[kept] = prop;
        out_bits[kept++] = (uint16_t)((w >> fields[4]) & data_mask);
    }
    return kept;
}

/* The SE/SD pairs whose SE words are at at[0..n) (_apply), each writing (index, prop, data)
 * then (index, prop2, data2) to the table of its table code t (tables[k], or entry where
 * tables is NULL or tables[k] is 0); only pairs with wanted[t] are taken, and a write to a
 * null property of the pair's table (null[32 (t - 1) + prop]) stores nothing. fields holds
 * (lo, width) of SE_INDEX_HI, SE_INDEX_LO, PROP, SE_PROP2, SD_DATA, SD_DATA2 from
 * rend3r/isa/tables.py. pair_marks decodes each pair into records[k] for pair_apply. */
typedef struct {
    const uint32_t *words;
    int64_t n_words;
    const int64_t *at;
    int64_t n;
    const int64_t *fields;
    const uint8_t *tables;
    int32_t entry;
    const uint8_t *wanted;
    const uint8_t *null;
    uint64_t *records;
    int32_t avx2;  /* decode eight pairs at a time where they lie back to back (marks8) */
} Pairs;

/* A pair decoded (processor.py checks the fields fit): which of its two writes store a
 * word (bits 0-1, 0: none), prop2 (bits 2-6), prop (7-11) and the index (12-31); data2
 * (32-47) and data (48-63). pair_apply then reads 8 bytes a pair in order, where it read
 * and decoded both words again after pair_marks: a 65,536-sphere program executes in
 * 3.33 ms on one thread where it took 3.50 (processor.py execute). */
static inline uint64_t pair_record(unsigned stores, uint32_t prop, uint32_t prop2, int64_t index, uint32_t data,
                                   uint32_t data2)
{
    return (uint64_t)stores | (uint64_t)prop2 << 2 | (uint64_t)prop << 7 | (uint64_t)index << 12
           | (uint64_t)data2 << 32 | (uint64_t)data << 48;
}

/* The pair fields' shifts and masks, in locals (the kernels' stores to bytes may alias
 * anything, so fields read through p would be read again after each). */
typedef struct {
    uint32_t lo[6], mask[6], hi_shift;
} PairFields;

static inline PairFields pair_fields(const Pairs *p)
{
    PairFields f;
    for (int k = 0; k < 6; k++) {
        f.lo[k] = (uint32_t)p->fields[2 * k];
        f.mask[k] = (uint32_t)((1ull << p->fields[2 * k + 1]) - 1ull);
    }
    f.hi_shift = (uint32_t)p->fields[3];
    return f;
}

#define FIELD(f, w, k) (((w) >> (f).lo[k]) & (f).mask[k])

static inline int32_t pair_table(const uint8_t *tables, int32_t entry, int64_t k)
{
    return tables != NULL && tables[k] ? tables[k] : entry;
}

/* Which of pair k's two writes store a word (bit 0: prop, bit 1: prop2; 0 when the pair
 * is not taken), and its table code. */
static inline unsigned pair_stores(const uint8_t *wanted, const uint8_t *null, const uint8_t *tables, int32_t entry,
                                   const PairFields *f, int64_t k, uint32_t se, int32_t *table)
{
    *table = pair_table(tables, entry, k);
    const uint8_t *nulls = null + 32 * (*table - 1);
    return wanted[*table] ? (unsigned)!nulls[FIELD(*f, se, 2)] | (unsigned)!nulls[FIELD(*f, se, 3)] << 1 : 0u;
}

/* What marks carries from pair to pair: the largest index marked + 1, and the previous
 * pair's index and whether it stored a word (a pair that stores to the index the previous
 * pair stored to need not mark it again: pairs of a shape mostly come together). */
typedef struct {
    int64_t top, index;
    unsigned stores;
} MarkState;

/* Pair k of marks (its arrays in the caller's locals: the byte stores to mark may alias
 * anything reached through p): decoded into records[k], its index marked (one table:
 * null_bits has bit p set where property p is null). Returns 0, or -1 - k when its SD lies
 * outside the words. */
static inline __attribute__((always_inline)) int64_t mark_one(const Pairs *p, const uint32_t *words,
                                                              const int64_t *at, int64_t n_words, uint64_t *records,
                                                              const PairFields *f, uint32_t null_bits,
                                                              int one_table, int take, uint8_t *mark, int64_t k,
                                                              MarkState *m)
{
    if (at[k] < 0 || at[k] + 1 >= n_words)
        return -1 - k;
    uint32_t se = words[at[k]], sd = words[at[k] + 1];
    int32_t table;
    unsigned stores = !one_table ? pair_stores(p->wanted, p->null, p->tables, p->entry, f, k, se, &table)
                      : take ? (~null_bits >> FIELD(*f, se, 2) & 1u) | (~null_bits >> FIELD(*f, se, 3) & 1u) << 1 : 0u;
    int64_t index = ((int64_t)FIELD(*f, se, 0) << f->hi_shift) | FIELD(*f, se, 1);
    records[k] = pair_record(stores, FIELD(*f, se, 2), FIELD(*f, se, 3), index, FIELD(*f, sd, 4), FIELD(*f, sd, 5));
    if (stores && !(m->stores && m->index == index)) {
        __atomic_store_n(mark + index, 1, __ATOMIC_RELAXED);  /* ranges of pairs on several threads */
        m->top = index >= m->top ? index + 1 : m->top;
    }
    m->index = index;
    m->stores = stores;
    return 0;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MARKS8 1
#pragma GCC push_options
#pragma GCC target("avx2")
/* mark_one for one table over whole blocks of eight pairs from k on whose words lie back
 * to back inside the words (the pairs of a program's shapes mostly do), on AVX2: each
 * lane computes what mark_one computes for its pair, and the lanes that mark follow its
 * rule (null_bits: bit p set where property p is null). Returns where it stopped: the end
 * of the last whole block, or the first block that is not back to back. */
static int64_t marks8(const uint32_t *words, const int64_t *at, int64_t n, int64_t n_words, uint64_t *records,
                      const PairFields *f, uint32_t null_bits, int take, uint8_t *mark, int64_t k, MarkState *m)
{
    u32x8 top = {0}, prev_index = (u32x8){0} + (uint32_t)m->index, prev_stores = (u32x8){0} + m->stores;
    int64_t start = k;
    for (; k + 8 <= n; k += 8) {
        i64x4 a0, a1, first = (i64x4){0, 2, 4, 6} + at[k];
        memcpy(&a0, at + k, sizeof a0);
        memcpy(&a1, at + k + 4, sizeof a1);
        if (at[k] < 0 || at[k] + 15 >= n_words || mask_bits_64x4((a0 == first) & (a1 == first + 8)) != 15)
            break;
        u32x8 lo, hi;
        memcpy(&lo, words + at[k], sizeof lo);
        memcpy(&hi, words + at[k] + 8, sizeof hi);
        u32x8 se = __builtin_shufflevector(lo, hi, 0, 2, 4, 6, 8, 10, 12, 14);
        u32x8 sd = __builtin_shufflevector(lo, hi, 1, 3, 5, 7, 9, 11, 13, 15);
        u32x8 prop = (se >> f->lo[2]) & f->mask[2], prop2 = (se >> f->lo[3]) & f->mask[3];
        u32x8 index = ((se >> f->lo[0]) & f->mask[0]) << f->hi_shift | ((se >> f->lo[1]) & f->mask[1]);
        u32x8 nulls = (u32x8){0} + null_bits;
        u32x8 stores = take ? ((~(nulls >> prop) & 1u) | (~(nulls >> prop2) & 1u) << 1) : (u32x8){0};
        u32x8 low = stores | prop2 << 2 | prop << 7 | index << 12;
        u32x8 high = ((sd >> f->lo[5]) & f->mask[5]) | ((sd >> f->lo[4]) & f->mask[4]) << 16;
        u32x8 r0 = __builtin_shufflevector(low, high, 0, 8, 1, 9, 2, 10, 3, 11);
        u32x8 r1 = __builtin_shufflevector(low, high, 4, 12, 5, 13, 6, 14, 7, 15);
        memcpy(records + k, &r0, sizeof r0);
        memcpy(records + k + 4, &r1, sizeof r1);
        u32x8 before = __builtin_shufflevector(prev_index, index, 7, 8, 9, 10, 11, 12, 13, 14);
        u32x8 stored = __builtin_shufflevector(prev_stores, stores, 7, 8, 9, 10, 11, 12, 13, 14);
        i32x8 storing = (i32x8)(stores != 0);
        int marks = mask_bits_32x8(storing & ~((i32x8)(stored != 0) & (i32x8)(before == index)));
        for (; marks; marks &= marks - 1)
            __atomic_store_n(mark + index[__builtin_ctz(marks)], 1, __ATOMIC_RELAXED);
        u32x8 next = (index + 1) & (u32x8)storing;
        top = (u32x8)((i32x8)(next > top) & (i32x8)next) | (u32x8)(~(i32x8)(next > top) & (i32x8)top);
        prev_index = index;
        prev_stores = stores;
    }
    if (k == start)
        return k;
    for (int i = 0; i < 8; i++)
        m->top = top[i] > m->top ? top[i] : m->top;
    m->index = prev_index[7];
    m->stores = prev_stores[7];
    return k;
}
#pragma GCC pop_options
#else
#define MARKS8 0
#endif

/* Marks the index of every pair taken that stores a word: mark[index] = 1 (mark holds
 * 2^19 bytes, every index; threads may mark ranges of pairs at once), and decodes every
 * pair into its record (pair_record). Returns the largest
 * index marked + 1 (0 for none), or -1 - k for the first pair k whose SD lies outside the
 * words (then nothing may be written). With AVX2 and one table, blocks of eight pairs
 * back to back are decoded at once (marks8): a 65,536-sphere program's 327,680 pairs took
 * 1.29 ms one at a time. */
static inline __attribute__((always_inline)) int64_t marks(const Pairs *p, uint8_t *mark, int one_table)
{
    const uint32_t *words = p->words;
    const int64_t *at = p->at;
    int64_t n = p->n, n_words = p->n_words;
    PairFields f = pair_fields(p);
    uint64_t *records = p->records;
    /* one table: its null row as bits and whether it is taken, read once (the byte stores may alias) */
    int take = one_table && p->wanted[p->entry], eight = MARKS8 && one_table && p->avx2;
    uint32_t null_bits = 0;
    for (int i = 0; one_table && i < 32; i++)
        null_bits |= (uint32_t)(p->null[32 * (p->entry - 1) + i] != 0) << i;
    MarkState m = {0, -1, 0};
    for (int64_t k = 0; k < n;) {
#if MARKS8
        if (eight && k + 8 <= n && at[k + 7] == at[k] + 14)  /* else scattered pairs would try each block */
            k = marks8(words, at, n, n_words, records, &f, null_bits, take, mark, k, &m);
#endif
        for (int64_t end = k + 8 < n ? k + 8 : n; k < end; k++)  /* a block not back to back, or the last pairs */
            if (mark_one(p, words, at, n_words, records, &f, null_bits, one_table, take, mark, k, &m) < 0)
                return -1 - k;
    }
    (void)eight;
    return m.top;
}

static int64_t pair_marks(const Pairs *p, uint8_t *mark)
{
    return p->tables == NULL ? marks(p, mark, 1) : marks(p, mark, 0);  /* NULL: no TS word, one table */
}

/* Range k of the pairs p split into parts (team.h edge). */
static Pairs pair_part(const Pairs *p, int64_t parts, int64_t k)
{
    int64_t a = edge(p->n, parts, k), b = edge(p->n, parts, k + 1);
    Pairs part = *p;
    part.at += a;
    part.n = b - a;
    part.tables = part.tables != NULL ? part.tables + a : NULL;
    part.records += a;
    return part;
}

typedef struct {
    const Pairs *p;
    int64_t parts;
    uint8_t *mark;
    int64_t *tops;
} PairRanges;

static void pair_range(void *ctx, int64_t k)
{
    const PairRanges *r = ctx;
    Pairs part = pair_part(r->p, r->parts, k);
    r->tops[k] = pair_marks(&part, r->mark);
}

/* pair_marks over `parts` ranges of the pairs on a team (team.h), range k's result into
 * tops[k]. */
static void pair_marks_team(Team *team, const Pairs *p, int64_t parts, uint8_t *mark, int64_t *tops)
{
    PairRanges r = {p, parts < 1 ? 1 : parts, mark, tops};
    team_phase(team, pair_range, &r, r.parts);
}

/* A range of pairs' writes to the largest index the ranges before it marked (index; -1:
 * none), kept aside to be made after theirs: the words (row, undefined where not
 * written), and which were written (zero before the range writes). */
typedef struct {
    int64_t index;
    uint32_t written;
    uint16_t row[PROP_WORDS];
} PairShadow;

/* Writes the pairs taken, in order, to a table of 32 property words per row (the last
 * write to a word wins), row row_of[index], from the records pair_marks decoded. The row
 * of the last index is kept: a shape's pairs mostly come together, and a store whose
 * address waits on a row_of load each time ran at half the speed. A row whose index is
 * fresh (fresh[index] != 0; NULL: none) is zeroed as it is first written, and its flag
 * cleared: a pass of its own over a new table's rows took a tenth of the processor's time
 * at 65,536 spheres. With a shadow (NULL: none), the writes to shadow->index go to it
 * instead (shadow->written set when there were any), and a pair whose index is below that
 * one stops the writes: returns 0 then, 1 when every pair was written. */
static inline __attribute__((always_inline)) int pair_apply(const Pairs *p, const int32_t *row_of, uint16_t *values,
                                                            uint8_t *fresh, PairShadow *shadow)
{
    const uint64_t *records = p->records;
    int64_t n = p->n, last = -1, shared = shadow != NULL ? shadow->index : -1;
    uint16_t *row = values;
    uint32_t written = 0;
    for (int64_t k = 0; k < n; k++) {
        uint64_t r = records[k];
        if (!(r & 3u))
            continue;
        int64_t index = (int64_t)(r >> 12 & 0xFFFFFu);
        if (index != last) {
            last = index;
            if (index <= shared) {
                if (index < shared)
                    return 0;
                row = shadow->row;
            } else {
                row = values + 32 * (int64_t)row_of[index];
                if (fresh != NULL && fresh[index]) {
                    memset(row, 0, 32 * sizeof *row);
                    fresh[index] = 0;
                }
            }
        }
        if (shadow != NULL && index == shared)
            written |= (r & 1u ? 1u << (r >> 7 & 31u) : 0u) | (r & 2u ? 1u << (r >> 2 & 31u) : 0u);
        if (r & 1u)
            row[r >> 7 & 31u] = (uint16_t)(r >> 48);
        if (r & 2u)
            row[r >> 2 & 31u] = (uint16_t)(r >> 32);
    }
    if (written)
        shadow->written = written;
    return 1;
}
#undef FIELD

typedef struct {
    const Pairs *p;
    int64_t parts;
    const int32_t *row_of;
    uint16_t *values;
    uint8_t *fresh;
    int32_t disorder;  /* a range met an index below its shadow's */
    PairShadow shadow[];  /* one a range */
} PairWrites;

static void pair_apply_range(void *ctx, int64_t k)
{
    PairWrites *w = ctx;
    Pairs part = pair_part(w->p, w->parts, k);
    if (!__atomic_load_n(&w->disorder, __ATOMIC_RELAXED)
        && !pair_apply(&part, w->row_of, w->values, w->fresh, &w->shadow[k]))
        __atomic_store_n(&w->disorder, 1, __ATOMIC_RELAXED);
}

/* pair_apply over the pairs p that pair_marks_team decoded in `parts` ranges (tops[k]:
 * range k's largest index marked + 1). Programs set their shapes up one after another, so
 * each range's indices mostly lie at or above the largest the ranges before it marked:
 * then the ranges write on the team, each most likely on the thread that decoded it
 * (team.h: each thread keeps its end of a pass's ranges), so its records and rows stay in
 * that thread's cache. The leader writing them all took 145 us at 4,096 spheres when the
 * two threads' cores had separate L3s, 33 on a shared L3 (docs/performance-history.md). A range's
 * writes to that largest index wait in its shadow and are made after the phase, range by
 * range, so the last write to a word still wins. A range that meets a lower index stops,
 * and the leader then writes every pair again, in order, over what the ranges wrote: the
 * last write to each word is the same, and a fresh row was zeroed before its first write.
 * The leader writes them all at once, in order, when there is one range, when a range's
 * indices all lie below the ones before it, or when the shadows' memory is refused. */
static void pair_apply_team(Team *team, const Pairs *p, int64_t parts, const int64_t *tops, const int32_t *row_of,
                            uint16_t *values, uint8_t *fresh)
{
    PairWrites *w = parts > 1 ? malloc(sizeof *w + (size_t)parts * sizeof w->shadow[0]) : NULL;
    int64_t before = 0;  /* the largest index the ranges before marked + 1 */
    for (int64_t k = 0; w != NULL && k < parts; k++) {
        if (tops[k] > 0 && tops[k] < before) {
            free(w);
            w = NULL;
        } else {
            w->shadow[k].index = before - 1;
            w->shadow[k].written = 0;
            before = tops[k] > before ? tops[k] : before;
        }
    }
    if (w != NULL) {
        w->p = p;
        w->parts = parts;
        w->row_of = row_of;
        w->values = values;
        w->fresh = fresh;
        w->disorder = 0;
        team_phase(team, pair_apply_range, w, parts);
    }
    if (w == NULL || w->disorder) {
        pair_apply(p, row_of, values, fresh, NULL);
        free(w);
        return;
    }
    for (int64_t k = 0; k < parts; k++) {
        const PairShadow *sh = &w->shadow[k];
        for (uint32_t bits = sh->written; bits; bits &= bits - 1)
            values[PROP_WORDS * (int64_t)row_of[sh->index] + __builtin_ctz(bits)] = sh->row[__builtin_ctz(bits)];
    }
    free(w);
}

/* The rows of the indices marked below top (mark[i] != 0), in index order: row_of[i] of
 * each marked i (the others' are left undefined), and the marked indices into index
 * (room for top). Returns how many are marked. */
static int64_t mark_rows(const uint8_t *mark, int64_t top, int32_t *row_of, int64_t *index)
{
    int64_t r = 0;
    for (int64_t i = 0; i < top; i++) {
        row_of[i] = (int32_t)r;
        index[r] = i;
        r += mark[i] != 0;
    }
    return r;
}

/* The pairs p to be written to an object table of `had` rows (index: sorted, each below
 * 2^19; values: PROP_WORDS words a row), the first of two calls (processor.py
 * _write_pairs): pair_marks over `parts` ranges of the pairs on a team, range k's result
 * into tops[k]; then the rows of the indices written merged with the table's
 * (mark_rows: row_of[i] the row of index i, merged the indices in order). When no index is
 * new, the writes (pair_apply_team) go to values in place here. mark (an index's flag, all
 * zero), row_of and merged are the caller's, 2^19 entries each. Returns the merged table's
 * rows: more than had when an index is new (then pairs_grow writes), mark being zero again
 * otherwise; -1 when a range holds a pair without its SD (tops[k] < 0 tells which), -2
 * when index is not strictly increasing: nothing written, the marks left to the caller. */
int64_t pairs_rows(Team *team, const Pairs *p, int64_t parts, uint8_t *mark, int64_t *tops, int32_t *row_of,
                   int64_t *merged, const int64_t *index, int64_t had, uint16_t *values)
{
    pair_marks_team(team, p, parts, mark, tops);
    int64_t top = 0;
    for (int64_t k = 0; k < parts; k++) {
        if (tops[k] < 0)
            return -1;
        top = tops[k] > top ? tops[k] : top;
    }
    if (top == 0)  /* no pair stores a word */
        return had;
    for (int64_t i = 0; i < had; i++) {
        if (i && index[i] <= index[i - 1])
            return -2;
        mark[index[i]] = 1;
    }
    top = had && index[had - 1] >= top ? index[had - 1] + 1 : top;
    int64_t rows = mark_rows(mark, top, row_of, merged);
    if (rows == had) {  /* no index is new */
        memset(mark, 0, (size_t)top);
        pair_apply_team(team, p, parts, tops, row_of, values, NULL);
    }
    return rows;
}

/* The second call when pairs_rows found a new index, on the same team with the same
 * ranges and their tops: the merged table of `rows` rows into index_out and
 * values_out, the old rows moved there and each new one zeroed as pair_apply first writes
 * it (every new index was marked by a pair that stores a word), then the writes
 * (pair_apply_team). mark is zero again on return. */
void pairs_grow(Team *team, const Pairs *p, int64_t parts, const int64_t *tops, uint8_t *mark, const int32_t *row_of,
                const int64_t *merged, int64_t rows, const int64_t *index, int64_t had, const uint16_t *values,
                int64_t *index_out, uint16_t *values_out)
{
    memcpy(index_out, merged, (size_t)rows * sizeof *merged);
    for (int64_t i = 0; i < had; i++) {  /* the old rows move; the marks left are the new indices' */
        memcpy(values_out + PROP_WORDS * (int64_t)row_of[index[i]], values + PROP_WORDS * i,
               PROP_WORDS * sizeof *values);
        mark[index[i]] = 0;
    }
    pair_apply_team(team, p, parts, tops, row_of, values_out, mark);
}

/* ---- rounding, for tests ---- */

void round16_array(const float *in, float *out, int64_t n, int32_t ftz)
{
    for (int64_t i = 0; i < n; i++)
        out[i] = round16(in[i], ftz);
}

/* The address of an object's C-contiguous buffer (a numpy array's data), for the ctypes
 * calls: what ndarray.ctypes.data gives without building a ctypes object, in a tenth of
 * its 1.6 us (a frame passes over a hundred addresses). A buffer that is not C-contiguous
 * is refused (numpy raises ValueError). */
static PyObject *address(PyObject *self, PyObject *obj)
{
    (void)self;
    Py_buffer view;
    if (PyObject_GetBuffer(obj, &view, PyBUF_C_CONTIGUOUS) < 0)
        return NULL;
    PyObject *at = PyLong_FromVoidPtr(view.buf);
    PyBuffer_Release(&view);
    return at;
}

static PyMethodDef methods[] = {
    {"address", address, METH_O, "The address of a C-contiguous buffer's first byte."},
    {NULL, NULL, 0, NULL},
};

/* The kernels are called through ctypes; the module itself only offers address(). */
static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_kernels", "rend3r's compiled raytracer kernels", -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__kernels(void) { return PyModule_Create(&module); }
