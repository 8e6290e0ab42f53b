/* The raytracer's compiled kernels (rend3r/emu/native.py loads them with ctypes).
 *
 * Built with the float semantics the emulator needs: no contraction of a*b+c into fused
 * multiply-adds, no fast-math, IEEE subnormals (setup.py passes -ffp-contract=off).
 * The datapath is written once (datapath.inc) and instantiated per working precision
 * and instruction set in instances/: _f32 (fp32), _h16 (fp16, subnormals flushed), _h16i
 * (fp16, IEEE subnormals), _f64 (fp64), each _base and _avx2. This file holds the rest:
 * grid building and bounds, in double.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdint.h>

#include "bounds.h"
#include "colour.h"
#include "fround.h"
#include "grids.h"
#include "kernels.h"
#include "simd.h"
#include "cull.h"

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

/* ---- grids (rend3r/emu/grids.py) ---- */

/* Range of a/c over a in [x - r, x + r], c in [z - r, z + r] (0 not in the latter):
 * extreme at the corners. */
static void ratio_range(double x, double z, double r, double *lo, double *hi)
{
    double a[2] = {x - r, x + r}, c[2] = {z - r, z + r};
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            double q = a[i] / c[j];
            *lo = fmin(*lo, q);
            *hi = fmax(*hi, q);
        }
}

/* The first index of ascending a[0..n) whose value is >= x (after = 0) or > x (after = 1). */
static int64_t search(const double *a, int64_t n, double x, int after)
{
    int64_t lo = 0, hi = n;
    while (lo < hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (after ? a[mid] <= x : a[mid] < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* The cells of a pixel grid whose rays' (u, v) lie in [ulo, uhi] x [vlo, vhi]. */
static int pixel_footprint(const Grid *g, double ulo, double uhi, double vlo, double vhi, int64_t *out)
{
    double a0 = g->u_sign > 0 ? ulo : -uhi, a1 = g->u_sign > 0 ? uhi : -ulo;
    double b0 = g->v_sign > 0 ? vlo : -vhi, b1 = g->v_sign > 0 ? vhi : -vlo;
    int64_t c0 = search(g->u_at, g->n_u, a0, 0), c1 = search(g->u_at, g->n_u, a1, 1) - 1;
    int64_t r0 = search(g->v_at, g->n_v, b0, 0), r1 = search(g->v_at, g->n_v, b1, 1) - 1;
    if (c0 > c1 || r0 > r1)
        return 0;
    out[0] = c0 / g->block; out[1] = c1 / g->block; out[2] = r0 / g->block_rows; out[3] = r1 / g->block_rows;
    return 1;
}

/* The cell rectangle a ball (centre c relative to the apex, or projected (u, v) for a
 * parallel grid; radius r) covers on a face: 0 when it covers none. Lines through the
 * ball have (u, v) in the ratio box of its bounding cube, widened for float64 rounding. */
static int footprint(const Grid *g, int parallel, int face, const double *c, double r, int64_t *out)
{
    const double *f = g->faces + GF_COLUMNS * face;
    const int64_t *s = g->shape + GS_COLUMNS * face;
    double ulo, uhi, vlo, vhi;
    if (s[GS_NU] == 0)
        return 0;
    if (parallel) {
        ulo = c[0] - r; uhi = c[0] + r; vlo = c[1] - r; vhi = c[1] + r;
    } else {
        double x = face == 0 ? c[1] : c[0], y = face == 2 ? c[1] : c[2], z = c[face];
        if (z - r <= 0.0 && 0.0 <= z + r) {  /* the ball meets the plane through the apex */
            ulo = f[GF_U0]; uhi = f[GF_U1]; vlo = f[GF_V0]; vhi = f[GF_V1];
        } else {
            ratio_range(x, z, r, &ulo, &uhi);
            ratio_range(y, z, r, &vlo, &vhi);
        }
    }
    ulo -= UV_SLACK * (1.0 + fabs(ulo)); vlo -= UV_SLACK * (1.0 + fabs(vlo));
    uhi += UV_SLACK * (1.0 + fabs(uhi)); vhi += UV_SLACK * (1.0 + fabs(vhi));
    if (face == 2 && g->u_at != NULL)
        return pixel_footprint(g, ulo, uhi, vlo, vhi, out);
    if (!(ulo <= f[GF_U1] && uhi >= f[GF_U0] && vlo <= f[GF_V1] && vhi >= f[GF_V0]))
        return 0;
    out[0] = (int64_t)((fmax(ulo, f[GF_U0]) - f[GF_U0]) * f[GF_SU]);
    out[1] = (int64_t)((fmin(uhi, f[GF_U1]) - f[GF_U0]) * f[GF_SU]);
    out[2] = (int64_t)((fmax(vlo, f[GF_V0]) - f[GF_V0]) * f[GF_SV]);
    out[3] = (int64_t)((fmin(vhi, f[GF_V1]) - f[GF_V0]) * f[GF_SV]);
    if (out[1] > s[GS_NU] - 1) out[1] = s[GS_NU] - 1;
    if (out[3] > s[GS_NV] - 1) out[3] = s[GS_NV] - 1;
    if (out[0] > out[1]) out[0] = out[1];
    if (out[2] > out[3]) out[2] = out[3];
    return 1;
}

/* Per shape and face, the cell rectangle its footprint covers (out: n x 3 x 4: iu0, iu1,
 * iv0, iv1; iu0 > iu1 where none, iu0 = -1 for a shape without a finite radius). */
void grid_footprints(const Grid *g, int32_t parallel, const double *centers, const double *radii, int64_t n,
                     int64_t *out)
{
    for (int64_t s = 0; s < n; s++) {
        for (int face = 0; face < 3; face++) {
            int64_t *box = out + 12 * s + 4 * face;
            if (!(radii[s] < INFINITY)) {
                box[0] = -1; box[1] = -2; box[2] = box[3] = 0;
            } else if ((parallel && face > 0) || !footprint(g, parallel, face, centers + 3 * s, radii[s], box)) {
                box[0] = 1; box[1] = box[2] = box[3] = 0;
            }
        }
    }
}

/* Count (fill == 0) or write (fill == 1; pos: each cell's next free entry) the listed
 * shapes of order into the cells of their rectangles (rects as grid_footprints gives
 * them; shape: per face cells along u, along v, first cell). */
void grid_fill(const int64_t *rects, const int64_t *shape, const int32_t *order, int64_t n, const uint8_t *listed,
               int64_t *pos, int32_t *entries, int32_t fill)
{
    for (int64_t k = 0; k < n; k++) {
        int32_t s = order[k];
        if (!listed[s])
            continue;
        for (int face = 0; face < 3; face++) {
            const int64_t *box = rects + 12 * (int64_t)s + 4 * face;
            const int64_t *gs = shape + GS_COLUMNS * face;
            for (int64_t iv = box[2]; iv <= box[3] && box[0] <= box[1]; iv++) {
                int64_t row = gs[GS_FIRST] + iv * gs[GS_NU];
                for (int64_t iu = box[0]; iu <= box[1]; iu++) {
                    if (fill)
                        entries[pos[row + iu]] = s;
                    pos[row + iu]++;
                }
            }
        }
    }
}

#define HALF_PI 1.5707963267948966  /* M_PI_2 is not C11 */

/* The double cone (unit axis a, half-angle t; t >= pi/2: every line) around the apex
 * holding cones 1 and 2 (lines: a2 flipped into a1's hemisphere). */
static void cone_union(double *a1, double *t1, const double *a2_, double t2)
{
    double a2[3] = {a2_[0], a2_[1], a2_[2]}, dot = a1[0] * a2[0] + a1[1] * a2[1] + a1[2] * a2[2];
    if (dot < 0) {
        a2[0] = -a2[0]; a2[1] = -a2[1]; a2[2] = -a2[2]; dot = -dot;
    }
    double w[3] = {a2[0] - dot * a1[0], a2[1] - dot * a1[1], a2[2] - dot * a1[2]};
    double sine = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), phi = atan2(sine, dot) * (1.0 + 1e-12) + 1e-15;
    if (*t1 >= HALF_PI || phi + t2 <= *t1)
        return;
    if (t2 >= HALF_PI || phi + *t1 <= t2 || !(sine > 1e-9)) {
        double keep = t2 >= *t1 ? t2 : *t1;
        if (t2 >= *t1)
            memcpy(a1, a2, sizeof a2);
        *t1 = sine > 1e-9 ? t2 : keep + phi;
        return;
    }
    double t = (phi + *t1 + t2) / 2, turn = t - *t1;
    for (int c = 0; c < 3; c++)
        a1[c] = cos(turn) * a1[c] + sin(turn) * w[c] / sine;
    double len = sqrt(a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2]);
    for (int c = 0; c < 3; c++)
        a1[c] /= len;
    *t1 = t * (1.0 + 1e-12) + 1e-12;
}

/* Per shape, what cone_reach needs of its ball seen from the apex (CONE_COLUMNS doubles):
 * the unit axis, the half-angle t (pi/2: every line), and sin t, cos t for the
 * containment test; centres relative to the apex, cull radii. */
void cone_balls(const double *centers, const double *radii, int64_t n, double *out)
{
    for (int64_t s = 0; s < n; s++) {
        const double *c = centers + 3 * s;
        double r = radii[s], dist = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), *o = out + CONE_COLUMNS * s;
        int ball = dist > r && r < INFINITY && dist < INFINITY;
        double sr = r / dist;
        o[0] = c[0] / dist; o[1] = c[1] / dist; o[2] = c[2] / dist;
        o[3] = ball ? asin(sr) * (1.0 + 1e-12) + 1e-12 : HALF_PI;
        o[4] = sr;
        o[5] = sqrt(fmax(0.0, 1.0 - sr * sr));
    }
}

/* A perspective grid's reach (Grid.reach) for cells k0..k1: for each cell, backwards over
 * its list, the union of the lines' cones of the entry's ball (cone_balls) and every
 * later one, written at entries that are multiples of 4. The stored cone is widened by
 * 1e-6 rad for the float axis (its error is below 1e-7 rad) and its cosine rounded down. */
void cone_reach(const double *balls, const int64_t *start, int64_t k0, int64_t k1, const int32_t *entries,
                float *out)
{
    for (int64_t k = k0; k < k1; k++) {
        double axis[3] = {0, 0, 1}, angle = -1.0, cos_a = 1.0, written = -2.0;
        float stored[4] = {0};
        for (int64_t i = start[k + 1] - 1; i >= start[k]; i--) {
            const double *ball = balls + CONE_COLUMNS * (int64_t)entries[i], *a = ball, t = ball[3];
            int inside = 0;
            if (angle >= 0 && angle < HALF_PI && t < HALF_PI) {
                /* the ball inside the cone without trigonometry: the angle between the axis and
                 * the centre plus the ball's half-angle at most the cone's, with room for rounding */
                double dot = fabs(axis[0] * a[0] + axis[1] * a[1] + axis[2] * a[2]);
                double sine = sqrt(fmax(0.0, 1.0 - dot * dot));
                inside = dot * ball[5] - sine * ball[4] >= cos_a + 1e-9;  /* cos(angle to axis + half-angle) */
            }
            if (!inside) {
                double before = angle, was[3] = {axis[0], axis[1], axis[2]};
                if (angle < 0) {
                    memcpy(axis, a, sizeof axis);
                    angle = t;
                } else {
                    cone_union(axis, &angle, a, t);
                }
                if (angle != before)
                    cos_a = cos(angle);
                if (memcmp(was, axis, sizeof was) != 0)
                    written = -2.0;  /* the axis turned */
            }
            if (i % 4 == 0) {
                if (written != angle) {  /* else the same cone as the last one written */
                    int every = !(angle + 1e-6 < HALF_PI) || !(axis[0] == axis[0]);
                    for (int q = 0; q < 3; q++)
                        stored[q] = every ? 0.0f : (float)axis[q];
                    float cs = (float)cos(angle + 1e-6);
                    stored[3] = every ? -2.0f : ((double)cs > cos(angle + 1e-6) ? nextafterf(cs, -INFINITY) : cs);
                    written = angle;
                }
                memcpy(out + i, stored, sizeof stored);
            }
        }
    }
}

/* A directional light's stop keys per shape (BEHIND_COLUMNS; LightPass.reach), from the
 * behind terms and cull radii; diag: a cell's diagonal, l_len: |l|.
 *
 * blocked() skips shape c for a packet when ahead = least - bh0 > 0, mid - spread > r and
 * l_len (bh1 ahead - bh2 (mid + spread)) > 1/64, mid being the distance from the packet's
 * centre to c's. The centre lies within spread of every origin, so its depth along l is
 * at least least - spread (mid >= ahead - spread), and c's footprint meets the cell that
 * holds the origins, so the centres lie within r + diag + spread of each other across l
 * (mid <= ahead + 2 spread + r + diag). Hence least >= K2 + 2 spread, K2 = bh0 + r, gives
 * the first two conditions, and least >= K0 + K1 spread, K0 = bh0 + (b2 (r + diag) +
 * 1/(64 l_len)) / (bh1 - b2), K1 = 3 b2 / (bh1 - b2), the third (b2: bh2 widened by 1e-8
 * for the rounding of mid; r likewise). A shape without a test gets infinities. */
void behind_keys(const double *behind, const double *radius, int64_t n, double diag, double l_len, double *out)
{
    for (int64_t s = 0; s < n; s++) {
        const double *bh = behind + 3 * s;
        double r = radius[s] * (1.0 + 1e-8), b2 = bh[2] * (1.0 + 1e-8), a = bh[1] - b2;
        double pad = 1e-12 * (fabs(bh[0]) + r + diag);
        double key[3] = {bh[0] + (b2 * (r + diag) + 0.015625 / l_len) / a + pad, 3.0 * b2 / a, bh[0] + r + pad};
        int ok = bh[0] == bh[0] && a > 0 && r < INFINITY;
        for (int c = 0; c < 3; c++)
            ok &= key[c] == key[c] && key[c] < INFINITY;
        for (int c = 0; c < 3; c++)
            out[3 * s + c] = ok ? key[c] : INFINITY;
    }
}

/* The reach of cells k0..k1 of a directional light's shadow grid at entries i that are
 * multiples of 4 (out + 3 (i / 4)): per key, the largest over the entry and every later
 * one of its list (behind_keys). */
void behind_reach(const int64_t *start, int64_t k0, int64_t k1, const int32_t *entries, const double *keys,
                  double *out)
{
    for (int64_t k = k0; k < k1; k++) {
        double m[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int64_t i = start[k + 1] - 1; i >= start[k]; i--) {
            const double *key = keys + 3 * (int64_t)entries[i];
            for (int c = 0; c < 3; c++)
                m[c] = MAX(m[c], key[c]);
            if (i % 4 == 0)
                memcpy(out + 3 * (i / 4), m, sizeof m);
        }
    }
}

/* ---- bounds per shape (rend3r/emu/bounds.py) ---- */

void bound_radii(const double *bnd, const uint8_t *ok, const double *dist, int64_t n, double dmin, double u,
                 double tiny, int32_t fp16, double *out)
{
    for (int64_t s = 0; s < n; s++) {
        const double *b = bnd + B_COLUMNS * s;
        out[s] = ok[s] ? cull_radius(b[B_SMIN], b[B_SMAX], dist[s], dmin, u, tiny, fp16) : INFINITY;
    }
}

void bound_floors(const double *bnd, const uint8_t *ok, const double *dist, int64_t n, double dmin, double dmax,
                  double u, double tiny, double *out)
{
    for (int64_t s = 0; s < n; s++) {
        const double *b = bnd + B_COLUMNS * s;
        out[s] = ok[s] ? depth_floor(b[B_SMIN], b[B_SMAX], dist[s], dmin, dmax, u, tiny) : 0.0;
    }
}

/* The primary rays' cull data per shape (PC_COLUMNS, see primary_cull in bounds.h), for a
 * camera at apex whose rays are at least dmin long; radius: the cull radii. */
void bound_primary(const double *bnd, const double *radius, int64_t n, const double *apex, double dmin, double u,
                   double tiny, double *out)
{
    for (int64_t s = 0; s < n; s++) {
        const double *b = bnd + B_COLUMNS * s;
        double *pc = out + PC_COLUMNS * s, r = radius[s], smin = b[B_SMIN], smax = b[B_SMAX];
        double v0 = b[B_CENTER] - apex[0], v1 = b[B_CENTER + 1] - apex[1], v2 = b[B_CENTER + 2] - apex[2];
        double vv = v0 * v0 + v1 * v1 + v2 * v2, dist = sqrt(vv);
        double uu = u + tiny / fmin(1.0, (smin * dmin) * (smin * dmin));
        pc[PC_V] = v0; pc[PC_V + 1] = v1; pc[PC_V + 2] = v2; pc[PC_VV] = vv;
        pc[PC_R2] = r < INFINITY ? r * r * (1.0 + BOUND_SLACK) + 1e-12 * vv : INFINITY;
        pc[PC_MEAN2] = (smax * smax + smin * smin) / 2.0;
        pc[PC_BEHIND] = r < INFINITY && dist > r ? ((smax * smax - smin * smin) / 2.0 + 64.0 * uu * smax * smax) * dist
                                                 : NAN;
    }
}

/* Counting sort: the items (0..n) by their bucket (0..nbuckets; negative: left out), in
 * order within a bucket. start gets nbuckets + 1 entries. */
void bucket_sort(const int32_t *bucket, int64_t n, int64_t nbuckets, int64_t *start, int32_t *items)
{
    for (int64_t k = 0; k <= nbuckets; k++)
        start[k] = 0;
    for (int64_t i = 0; i < n; i++)
        if (bucket[i] >= 0)
            start[bucket[i] + 1]++;
    for (int64_t k = 0; k < nbuckets; k++)
        start[k + 1] += start[k];
    for (int64_t i = 0; i < n; i++)
        if (bucket[i] >= 0)
            items[start[bucket[i]]++] = (int32_t)i;
    for (int64_t k = nbuckets; k > 0; k--)
        start[k] = start[k - 1];
    start[0] = 0;
}

/* ---- rounding, for tests ---- */

void round16_array(const float *in, float *out, int64_t n, int32_t ftz)
{
    for (int64_t i = 0; i < n; i++)
        out[i] = round16(in[i], ftz);
}

/* The library is loaded with ctypes; the module object only makes it importable. */
static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_kernels", "rend3r's compiled raytracer kernels", -1, NULL, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__kernels(void) { return PyModule_Create(&module); }
