/* A band of rows rendered in one compiled call (rend3r/emu/raytracer.py _band), its
 * passes split over a team of threads (team.h): for a camera whose directions are
 * measured per pixel, those directions and the primary rays' bounds; the nearest hit of
 * every pixel; then per light its shadow rays' bounds (from the band's hit points) and
 * its pass, the last light's finishing the pixels. A frame of one shape casts no shadow:
 * the nearest-hit pass applies its lights as it goes and finishes the pixels, so the hit
 * points and normals never go to memory and no light pass runs (a 1-sphere 512x384
 * frame takes a third less). Between the passes no Python runs:
 * Python spent some 0.3 ms a frame building each pass's blocks and merging its reports,
 * a sixth of a 4,096-sphere frame on two threads.
 *
 * A pixel kernel runs in chunks, a few tens a thread (a thread takes the next chunk in a
 * microsecond, so many small chunks even out uneven ones), each adding to its own report
 * row; the rows are merged in chunk order. Every pixel is computed the same way whatever
 * the split, so the image never depends on it.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "kernels.h"
#include "team.h"

void bundle_bounds(Bundle *b, Team *team);  /* setup.c */

/* ---- chunks of a pixel kernel, each with its own report row ---- */

/* A report row takes two cache lines (16 doubles), as neighbouring lines may be fetched
 * together: rows that shared a line with another thread's made every kernel about a
 * quarter slower on two threads (false sharing). */
enum { ROW = 16, LINE = 64 };

typedef struct {
    ChunkFn fn;
    const void *block;
    int64_t n, parts;
    double *rows;
} Chunks;

/* Where part k of 0..n starts when the parts shrink from 1.75 times their mean size to a
 * quarter of it (n (x + 3/4 x (1 - x)) at x = k / parts): made for threads taking parts
 * in order, so that the last ones taken are short and the threads end a pass close
 * together, where equal parts left one waiting up to a part's time at the end of each
 * pass. Since the leader takes from the front and the members from the back (team.c
 * team_take), the parts met last are mid-sized; parts shrinking towards where the two
 * ends meet measured no faster (docs/performance-history.md, "The night of 2026-12-04"). */
static inline int64_t taper(int64_t n, int64_t parts, int64_t k)
{
    return (4 * n * k * parts + 3 * n * k * (parts - k)) / (4 * parts * parts);
}

static void chunk_task(void *ctx, int64_t k)
{
    const Chunks *c = ctx;
    c->fn(c->block, taper(c->n, c->parts, k), taper(c->n, c->parts, k + 1), c->rows + ROW * k);
}

/* Joins that keep NaN, as numpy's min and max do. */
static inline double join_min(double m, double x)
{
    return m != m || x != x ? m + x : x < m ? x : m;
}

static inline double join_max(double m, double x)
{
    return m != m || x != x ? m + x : x > m ? x : m;
}

/* A kernel's report (kernels.h OUT_*): counts summed, the hit points' boxes joined. */
static const double REPORT[OUT_COLUMNS] = {0, 0, 0, 0, INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY,
                                           0, 0};

static void merge_report(double *into, const double *row)
{
    for (int i = 0; i < OUT_COLUMNS; i++)
        if (i < OUT_LO || i >= OUT_HI + 3)
            into[i] += row[i];
    for (int i = 0; i < 3; i++) {
        into[OUT_LO + i] = join_min(into[OUT_LO + i], row[OUT_LO + i]);
        into[OUT_HI + i] = join_max(into[OUT_HI + i], row[OUT_HI + i]);
    }
}

/* directions' report: finite non-zero directions, the shortest and the longest length. */
static const double EXTENT[3] = {0, INFINITY, 0};

static void merge_extent(double *into, const double *row)
{
    into[0] += row[0];
    into[1] = join_min(into[1], row[1]);
    into[2] = join_max(into[2], row[2]);
}

/* shadow_origins' report: the points' box, largest magnitude, largest chord, the points
 * with a usable l and the shortest |l|. */
static const double ORIGINS[10] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY, 0, 0, 0, INFINITY};

static void merge_origins(double *into, const double *row)
{
    for (int i = 0; i < 3; i++) {
        into[i] = join_min(into[i], row[i]);
        into[3 + i] = join_max(into[3 + i], row[3 + i]);
    }
    into[6] = join_max(into[6], row[6]);
    into[7] = join_max(into[7], row[7]);
    into[8] += row[8];
    into[9] = join_min(into[9], row[9]);
}

/* ---- a band's working memory ---- */

typedef struct {
    double *rows;           /* report rows, capacity of them */
    int64_t capacity;
    double *radius, *behind, *keys, *point, *box, *own, *node_keys; /* a light's shadow bounds */
} Work;

/* Lays out size bytes at *at, aligned to a cache line; returns where they start. */
static void *carve(char *base, size_t *at, size_t size)
{
    size_t start = (*at + LINE - 1) / LINE * LINE;
    *at = start + size;
    return base == NULL ? NULL : base + start;
}

/* The band's arrays (Band: per pixel, for the light passes) and the call's scratch, in
 * one allocation; base NULL only measures. Returns the bytes it takes. */
static size_t lay_out(Bands *f, Work *w, char *base, int64_t npix)
{
    Band *b = f->band;
    int64_t n = b->sh->n, kept = f->lights > 0 && n != 1 ? npix : 0, item = f->item;  /* none: in_pass */
    size_t at = sizeof(double) * ROW;  /* a row's room before the report rows and after them: no other array on
                                           their lines or the lines fetched with them */
    w->capacity = f->chunks_per_job * (f->jobs > 1 ? f->jobs : 1);
    w->rows = carve(base, &at, sizeof(double) * ROW * (size_t)(w->capacity + 1));
    b->slot = carve(base, &at, sizeof(int32_t) * (size_t)kept);
    b->sqd = carve(base, &at, (size_t)(item * kept));
    b->pt = carve(base, &at, (size_t)(3 * item * kept));
    b->nm = carve(base, &at, (size_t)(3 * item * kept));
    b->bad = carve(base, &at, (size_t)kept);
    b->nan_px = carve(base, &at, (size_t)kept);
    b->acc = carve(base, &at, sizeof(double) * (size_t)(f->lights > 1 && kept ? 3 * npix : 0));
    b->dirs = f->primary != NULL ? carve(base, &at, (size_t)(4 * item * npix)) : NULL;
    int64_t shadows = f->lights > 0 && n > 1, nodes = shadows ? b->tree.nodes : 0, items = shadows ? f->items : 0;
    n = shadows ? n : 0;
    w->radius = carve(base, &at, sizeof(double) * (size_t)n);
    w->behind = carve(base, &at, sizeof(double) * (size_t)(3 * n));
    w->keys = carve(base, &at, sizeof(double) * (size_t)(3 * n));
    w->point = carve(base, &at, sizeof(double) * (size_t)(SK_COLUMNS * n));
    w->box = carve(base, &at, sizeof(double) * (size_t)(BV_COLUMNS * nodes));
    w->own = carve(base, &at, sizeof(double) * (size_t)(MAX((int)CI_COLUMNS, (int)BX_COLUMNS) * items));
    w->node_keys = carve(base, &at, sizeof(double) * (size_t)(MAX(3, (int)PK_COLUMNS) * nodes));
    return at;
}

/* Chunks a thread gets of a pixel pass at least, where the pass is long enough for chunks
 * averaging a quarter of the smallest: a lit band of few shapes (some 16,384 pixels) made
 * four chunks for two threads, and each of its passes ended with one thread waiting out
 * the other's last chunk (`--jobs 2` at 16 and 256 spheres 1.5x, 1.7x with chunks a
 * quarter as long; docs/performance.md). Longer passes keep their chunks. */
#define CHUNKS_LEAST 8

/* How many chunks a pixel pass over 0..n takes on f's team (team.h parts_of): up to
 * chunks_per_job a thread, averaging at least smallest; where that gives a thread fewer
 * than CHUNKS_LEAST, up to CHUNKS_LEAST a thread averaging at least a quarter of it
 * (chunk_task tapers them). */
static int64_t pixel_parts(const Bands *f, int64_t n, int64_t smallest)
{
    int64_t parts = parts_of(n, f->jobs, smallest, f->chunks_per_job), least = CHUNKS_LEAST * (int64_t)f->jobs;
    if (parts < least)  /* finer chunks are never fewer */
        parts = MIN(parts_of(n, f->jobs, smallest / 4, f->chunks_per_job), least);
    return parts;
}

/* fn over 0..n (block its argument) in chunks (pixel_parts), each adding to its own copy
 * of the report row init (width doubles); out gets the rows merged. */
static void run(const Bands *f, Team *team, Work *w, ChunkFn fn, const void *block, int64_t n, int64_t smallest,
                const double *init, int width, void (*merge)(double *, const double *), double *out)
{
    int64_t parts = pixel_parts(f, n, smallest);
    parts = parts < w->capacity ? parts : w->capacity;
    for (int64_t k = 0; k < parts; k++)
        memcpy(w->rows + ROW * k, init, sizeof(double) * (size_t)width);
    Chunks c = {fn, block, n, parts, w->rows};
    team_phase(team, chunk_task, &c, parts);
    memcpy(out, w->rows, sizeof(double) * (size_t)width);
    for (int64_t k = 1; k < parts; k++)
        merge(out, w->rows + ROW * k);
}

/* ---- a light's pass ---- */

/* Numbers light passes in the process (LightPass.serial: a thread keeps a pass's caches
 * across the chunks it takes of it, datapath.inc light_pass). */
#if TEAM_SOLO
static int64_t next_serial(void)
{
    return 0;  /* no atomics: frames on several threads could take the same number, so none keeps */
}
#else
static _Atomic int64_t passes;

static int64_t next_serial(void)
{
    return atomic_fetch_add(&passes, 1) + 1;
}
#endif

/* A light's shadow rays' bounds over the band (shape_bounds.inc shadow_shapes, bvh.h): from the box of
 * the band's hit points (hits, the nearest-hit pass's report) and, for a point light,
 * what shadow_origins finds of the points' l; a directional light's also get the behind
 * terms and stop keys, so a packet skips whole subtrees behind its origins. Where nothing
 * bounds the rays (no hit point, no usable l, a light of no finite direction), every
 * radius is infinite and every shadow ray tests every shape. */
static void shadow_bounds(const Bands *f, Team *team, Work *w, LightPass *lp, const double *lf, const double *hits)
{
    const Band *b = f->band;
    Bundle bd = {.bnd = b->sh->bnd, .ok = f->bounded, .n = b->sh->n, .pass = PASS_SHADOW, .chord = NAN,
                 .u = b->sh->u, .tiny = b->sh->tiny, .overflow = f->overflow, .radius = w->radius, .tree = b->tree,
                 .items = f->items, .box = w->box, .own = w->own, .jobs = f->jobs, .isa = f->isa,
                 .chunk = f->chunk};
    bd.tree.box = w->box;
    bd.tree.item_box = NULL;
    memset(bd.tree.frame, 0, sizeof bd.tree.frame);
    int bounded = hits[OUT_HITS] != 0;
    if (bounded && !lp->parallel) {  /* a point light: the rounding of l turns each ray off the line to it */
        double o[10];
        run(f, team, w, f->shadow_origins, lp, b->npix, f->min_chunk, ORIGINS, 10, merge_origins, o);
        bounded = o[8] != 0;  /* none when the light is not finite: then no l is */
        bd.kind = BVH_CONE;
        memcpy(bd.tree.frame, lf + LF_APEX, 3 * sizeof(double));
        bd.dmin = o[9];
        bd.chord = o[7];
        if (bd.chord == bd.chord)  /* the terms of its per-node behind test */
            bd.point = w->point, bd.node_keys = w->node_keys, lp->point_keys = w->node_keys;
    } else if (bounded) {  /* a directional light: boxes on the plane normal to l */
        double length = lf[LF_LENGTH];
        bounded = 0 < length && length < INFINITY;  /* else cos is not finite at any point: no shadow ray */
        bd.kind = BVH_FLAT;
        memcpy(bd.tree.frame, lf + LF_AXES, 6 * sizeof(double));
        bd.tree.item_box = w->own;
        bd.dmin = bd.l_len = lp->l_len = length;
        bd.unit = lf + LF_UNIT;
        memcpy(lp->l_hat, lf + LF_UNIT, sizeof lp->l_hat);
        bd.behind = w->behind;
        lp->behind = w->behind;
        bd.keys = w->keys;
        bd.node_keys = w->node_keys;
        lp->keys = w->node_keys;
    }
    if (bounded) {  /* the origins' box */
        const double *lo = hits + OUT_LO, *hi = hits + OUT_HI;
        double span = 0, magnitude = fabs(lo[0]);
        for (int c = 0; c < 3; c++) {
            bd.mid[c] = (lo[c] + hi[c]) / 2;
            span += (hi[c] - lo[c]) * (hi[c] - lo[c]);
            magnitude = fabs(lo[c]) > magnitude ? fabs(lo[c]) : magnitude;
        }
        for (int c = 0; c < 3; c++)
            magnitude = fabs(hi[c]) > magnitude ? fabs(hi[c]) : magnitude;
        bd.half = sqrt(span) / 2;
        bd.magnitude = magnitude;
    } else {  /* infinite radii: every node holds every line */
        Bundle none = {.bnd = bd.bnd, .n = bd.n, .pass = PASS_NONE, .kind = lp->parallel ? BVH_FLAT : BVH_CONE,
                       .radius = w->radius, .tree = bd.tree, .items = bd.items, .box = w->box, .own = w->own,
                       .jobs = bd.jobs, .isa = bd.isa, .chunk = bd.chunk};
        memset(none.tree.frame, 0, sizeof none.tree.frame);
        none.tree.item_box = NULL;
        if (lp->parallel) {  /* the x and y axes */
            none.tree.frame[0] = none.tree.frame[4] = 1;
            none.tree.item_box = w->own;
        }
        for (int64_t i = 0; i < bd.n; i++)
            w->radius[i] = INFINITY;
        lp->behind = lp->keys = lp->point_keys = NULL;
        lp->l_len = 0;
        memset(lp->l_hat, 0, sizeof lp->l_hat);
        bd = none;
    }
    bundle_bounds(&bd, team);
    lp->tree = bd.tree;
    lp->radius = w->radius;
}

/* Light k added to the band's colour sums, with its shadow rays (hits: the nearest-hit
 * pass's report); c gets its pass's report (the last light's finishes the pixels). */
static void light(Bands *f, Team *team, Work *w, int64_t k, const double *hits, double *c)
{
    const Band *b = f->band;
    const double *lf = f->light_frames + LF_COLUMNS * k;
    int64_t n = b->sh->n;
    LightPass lp = {.sh = b->sh, .band = b, .light = f->light_rows + f->light_row * k, .fixed = f->fixed,
                    .shadows = n > 1, .parallel = lf[LF_PARALLEL] != 0, .first = k == 0, .last = k == f->lights - 1,
                    .serial = next_serial()};
    memcpy(lp.scale, f->scales + 3 * k, sizeof lp.scale);
    if (lp.shadows)
        shadow_bounds(f, team, w, &lp, lf, hits);
    run(f, team, w, f->light_pass, &lp, b->npix, f->min_chunk, REPORT, OUT_COLUMNS, merge_report, c);
    int64_t rays = (int64_t)c[OUT_SHADOW_RAYS], tests = (int64_t)c[OUT_TESTS];
    f->counts[BC_SHADOW_RAYS] += rays;
    f->counts[BC_TESTS] += tests;
    f->counts[BC_NAN_TESTS] += (int64_t)c[OUT_NAN_TESTS];
    if (lp.shadows)
        f->counts[BC_SKIPPED] += rays * (n - 1) - tests;
}

/* ---- the band ---- */

/* The working memory render_band takes for a band of npix pixels of the frame f. */
int64_t band_bytes(Bands *f, int64_t npix)
{
    Work w;
    return (int64_t)lay_out(f, &w, NULL, npix) + LINE;
}

/* Rows row0..row1 of the frame f (at most 2**20 pixels: band_row) rendered into rgb,
 * depth and prov (the band's pixels) with f->memory, adding the band's counts to
 * f->counts. Returns 0, or -1 when f->memory_bytes is less than band_bytes (nothing is
 * then drawn). */
int64_t render_band(Bands *f, int64_t row0, int64_t row1, uint16_t *rgb, float *depth, int32_t *prov, Team *team)
{
    Band *b = f->band;
    int64_t npix = (row1 - row0) * b->width;
    if (f->memory == NULL || f->memory_bytes < band_bytes(f, npix))
        return -1;
    int64_t n = b->sh->n;
    b->in_pass = f->lights > 0 && n == 1 ? f : NULL;  /* one shape casts no shadow: its lights need no pass */
    Work w;
    lay_out(f, &w, f->memory + (LINE - (uintptr_t)f->memory % LINE) % LINE, npix);
    b->row0 = row0;
    b->npix = npix;
    b->rgb = rgb;
    b->depth = depth;
    b->prov = prov;
    if (f->primary != NULL) {  /* directions per pixel, kept for the nearest-hit pass; then the bounds */
        double e[3];
        run(f, team, &w, f->directions, b, npix, f->min_chunk, EXTENT, 3, merge_extent, e);
        f->primary->dmin = e[0] != 0 ? e[1] : 0.0;
        f->primary->dmax = e[0] != 0 ? e[2] : 0.0;
        bundle_bounds(f->primary, team);
    }
    double c[OUT_COLUMNS], last[OUT_COLUMNS];
    int64_t rows = row1 - row0, smallest = f->min_chunk / b->width;
    run(f, team, &w, f->nearest, b, rows, smallest > 1 ? smallest : 1, REPORT, OUT_COLUMNS, merge_report, c);
    f->counts[BC_TESTS] += (int64_t)c[OUT_TESTS];
    f->counts[BC_NAN_TESTS] += (int64_t)c[OUT_NAN_TESTS];
    f->counts[BC_SKIPPED] += npix * n - (int64_t)c[OUT_TESTS];
    const double *done = c;  /* the pixels are finished by the nearest-hit pass without lights or with them in it,
                                 else by the last light's */
    f->counts[BC_SHADOW_RAYS] += (int64_t)c[OUT_SHADOW_RAYS];
    for (int64_t k = 0; b->in_pass == NULL && k < f->lights; k++) {
        light(f, team, &w, k, c, last);
        done = last;
    }
    f->counts[BC_HITS] += (int64_t)done[OUT_SHOWN];
    f->counts[BC_NAN_RAYS] += (int64_t)done[OUT_NAN_RAYS];
    b->slot = NULL;  /* the band's arrays are the next band's */
    b->sqd = b->pt = b->nm = b->dirs = NULL;
    b->bad = b->nan_px = NULL;
    b->acc = NULL;
    b->in_pass = NULL;
    return 0;
}
