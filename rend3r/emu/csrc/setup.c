/* A frame's set-up in one compiled call, its passes split over a team of threads
 * (team.h): the shape tables, the shape hierarchy, and each bundle of rays' bounds
 * (rend3r/emu/raytracer.py set_up, bvh.py, bounds.py; band.c fits the shadow rays'
 * bundles). Between the passes no Python runs, and passes of a few
 * tens of microseconds split over the cores, where a hand-off through a Python thread (its
 * wake-up, then the GIL) cost as much as it saved.
 *
 * Every pass computes each shape, item or node the same way whatever the split, so the
 * bits never depend on the thread count.
 */
#include <stdint.h>
#include <string.h>

#include "bvh.h"
#include "kernels.h"
#include "team.h"

/* Ranges a pass over shapes or items takes per thread. */
#define SHAPE_PARTS_PER_JOB 4

static int64_t shape_parts(int64_t n, int32_t jobs, int64_t smallest)
{
    int64_t parts = parts_of(n, jobs, smallest, SHAPE_PARTS_PER_JOB);
    return parts <= MAX_PARTS ? parts : MAX_PARTS - (jobs <= MAX_PARTS ? MAX_PARTS % jobs : 0);  /* still a multiple */
}

/* ---- per-shape passes (kernels.c, shape_bounds.inc) ---- */

#define SHAPE_PASSES(isa) \
    void primary_shapes_##isa(const int32_t *, const double *, const uint8_t *, int64_t, const double *, double, \
                              double, double, double, double, double *, double *, double *, float *); \
    void subtree_extremes_##isa(const int32_t *, int64_t, const double *, const double *, double *); \
    void subtree_bound_##isa(const double *, const double *, double, double, double, double, double, double *); \
    void shadow_shapes_##isa(const int32_t *, const double *, const uint8_t *, int64_t, const double *, double, \
                             double, double, double, double, double, double, const double *, double, double *, \
                             double *, double *, double *); \
    void flat_items_##isa(const int32_t *, int64_t, const double *, const double *, int32_t, const double *, \
                          double *); \
    void cone_items_##isa(const int32_t *, int64_t, const double *, const double *, int32_t, const double *, \
                          double *);
SHAPE_PASSES(base)
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
SHAPE_PASSES(avx2)
SHAPE_PASSES(avx512)
#define PICK(b, name) ((b)->isa == 2 ? name##_avx512 : (b)->isa == 1 ? name##_avx2 : name##_base)
#else
#define PICK(b, name) name##_base
#endif

int64_t bvh_build(const double *bnd, const uint8_t *bounded, int64_t rows, int32_t *items, int32_t *always,
                  int32_t *where, int32_t *node, int64_t *count_out, void *room, int32_t keep, TreeMemo *memo,
                  int32_t isa);
void bvh_refit(const Bvh *t, const double *floor, int32_t kind, double *box, const double *items, const double *keys,
               double *node_keys, int64_t lo, int64_t hi, int32_t isa);
void cone_node(double *b);

/* The primary rays' shape pass over shapes a..e. */
static void shape_range(const Bundle *b, int64_t a, int64_t e)
{
    PICK(b, primary_shapes)(NULL, b->bnd + B_COLUMNS * a, b->ok + a, e - a, b->apex, b->dmin, b->dmax, b->u, b->tiny,
                            b->overflow, b->radius + a, b->floor + a, b->pc + PC_COLUMNS * a,
                            b->pc32 + P32_COLUMNS * a);
}

/* The primary rays' shape pass over the n shapes of slots. */
static void shape_slots(const Bundle *b, const int32_t *slots, int64_t n)
{
    PICK(b, primary_shapes)(slots, b->bnd, b->ok, n, b->apex, b->dmin, b->dmax, b->u, b->tiny, b->overflow, b->radius,
                            b->floor, b->pc, b->pc32);
}

/* A light's shape pass over rows a..e of its bounds (kernels.h PASS_SHADOW): the shapes of
 * slots[0..e - a). */
static void shadow_rows(const Bundle *b, const int32_t *slots, int64_t a, int64_t e)
{
    PICK(b, shadow_shapes)(slots, b->bnd, b->ok, e - a, b->mid, b->half, b->magnitude, b->dmin, b->chord, b->u,
                           b->tiny, b->overflow, b->unit, b->l_len, b->radius + a,
                           b->behind != NULL ? b->behind + 3 * a : NULL, b->keys != NULL ? b->keys + 3 * a : NULL,
                           b->point != NULL ? b->point + SK_COLUMNS * a : NULL);
}

static void shape_task(void *ctx, int64_t k)
{
    const Bundle *b = ctx;
    int64_t parts = shape_parts(b->n, b->jobs, b->chunk);
    shape_range(b, edge(b->n, parts, k), edge(b->n, parts, k + 1));
}

/* Each shape's own cone or box, over the tree's items a..e (leaf order; a light's radii in
 * rows, the others' by slot). */
static void item_range(const Bundle *b, int64_t a, int64_t e)
{
    const int32_t *items = b->tree.items + a;
    int32_t by_row = b->pass == PASS_SHADOW;
    const double *radius = by_row ? b->radius + a : b->radius;
    if (b->kind == BVH_CONE)
        PICK(b, cone_items)(items, e - a, b->bnd, radius, by_row, b->tree.frame, b->own + CI_COLUMNS * a);
    else
        PICK(b, flat_items)(items, e - a, b->bnd, radius, by_row, b->tree.frame, b->own + BX_COLUMNS * a);
}

/* ---- refits: subtrees side by side, then the nodes above them ---- */

/* The subtree under node at: its items a..e and its nodes at..end (nodes are depth
 * first: its items run from its leftmost leaf's first, left children at + 1, to its
 * rightmost leaf's last, right children node[at][0], which is its last node). */
static void subtree_span(const int32_t *node, int64_t at, int64_t *a, int64_t *e, int64_t *end)
{
    int64_t left = at, right = at;
    while (node[2 * left + 1] == 0)
        left++;
    while (node[2 * right + 1] == 0)
        right = node[2 * right];
    *a = node[2 * left];
    *e = (int64_t)node[2 * right] + node[2 * right + 1];
    *end = right + 1;
}

typedef struct {
    const Bundle *b;
    int64_t below[MAX_PARTS][2];  /* node ranges of disjoint subtrees, largest first */
    int64_t count;
} Subtrees;

static void refit_range(const Bundle *b, int64_t lo, int64_t hi)
{
    const double *keys = b->kind == BVH_FLAT ? b->keys : b->point;
    bvh_refit(&b->tree, b->floor, b->kind, b->box, b->own, keys, b->node_keys, lo, hi, b->isa);
}

/* Subtree k's rows of a light's bounds (kernels.h PASS_SHADOW), its items, then its refit,
 * so that the thread that makes a subtree's rows and item bounds reads them: on two
 * threads whose cores had separate L3s, a light's shape pass of its own (in even ranges of
 * slots) took 38-95 us a thread at 4,096 spheres where it takes 20, each of its stores
 * waiting for the line to be taken from the other core, whose subtree tasks had read it
 * (docs/performance-history.md). Nodes are depth first and leaves hold ranges of items in
 * order: a subtree's items run from its leftmost leaf's first (left children: at + 1) to
 * its rightmost leaf's last (right children: node[at][0]). */
static void subtree_task(void *ctx, int64_t k)
{
    const Subtrees *s = ctx;
    int64_t lo = s->below[k][0], a, e, end;
    subtree_span(s->b->tree.node, lo, &a, &e, &end);
    if (s->b->pass == PASS_SHADOW)
        shadow_rows(s->b, s->b->tree.items + a, a, e);
    item_range(s->b, a, e);
    refit_range(s->b, lo, s->below[k][1]);
}

/* At least want disjoint subtrees (fewer when the tree has fewer leaves; the largest
 * subtree whose root is inner is split at each step) and the nodes above them, children
 * before parents. Nodes are
 * depth first: node at's left child is at + 1, its right child node[at][0] (inner: count
 * node[at][1] is 0). */
static void subtrees(const int32_t *node, int64_t nodes, int64_t want, Subtrees *s, int64_t *above, int64_t *n_above)
{
    s->count = 0;
    *n_above = 0;
    if (nodes <= 0)
        return;
    s->below[s->count][0] = 0;
    s->below[s->count++][1] = nodes;
    while (s->count < MIN(want, MAX_PARTS)) {
        int64_t pick = -1;
        for (int64_t i = 0; i < s->count; i++) {
            int64_t lo = s->below[i][0], hi = s->below[i][1];
            if (node[2 * lo + 1] == 0 && hi - lo > 1 &&
                (pick < 0 || hi - lo > s->below[pick][1] - s->below[pick][0]))
                pick = i;
        }
        if (pick < 0)
            break;
        int64_t lo = s->below[pick][0], hi = s->below[pick][1], right = node[2 * lo];
        s->below[pick][0] = lo + 1;
        s->below[pick][1] = right;
        s->below[s->count][0] = right;
        s->below[s->count++][1] = hi;
        above[(*n_above)++] = lo;
    }
    for (int64_t i = 1; i < s->count; i++) {  /* largest first (insertion sort: a few ranges) */
        int64_t lo = s->below[i][0], hi = s->below[i][1], j = i;
        for (; j > 0 && s->below[j - 1][1] - s->below[j - 1][0] < hi - lo; j--) {
            s->below[j][0] = s->below[j - 1][0];
            s->below[j][1] = s->below[j - 1][1];
        }
        s->below[j][0] = lo;
        s->below[j][1] = hi;
    }
}

/* The bundle's items and refit, after its radii are known: subtrees side by side, each
 * with its items (a pass of its own over the items, in even ranges, lost 25 us a frame at
 * 4,096 spheres when the two threads' cores had separate L3s: each thread then read item
 * bounds the other had made; docs/performance-history.md), then the nodes above them. */
static void bundle_tree(Bundle *b, Team *team)
{
    int64_t parts = shape_parts(b->items, b->jobs, b->chunk);
    Subtrees s = {.b = b};
    int64_t above[MAX_PARTS], n_above;
    subtrees(b->tree.node, b->tree.nodes, parts, &s, above, &n_above);
    team_phase(team, subtree_task, &s, s.count);
    for (int64_t i = n_above - 1; i >= 0; i--)  /* parents after their children */
        refit_range(b, above[i], above[i] + 1);
}

/* ---- a frame's primary bundle made in part: subtrees made when first entered ---- */

/* Subtree at's shapes' primary bounds, its items' cones and its nodes below at (at keeps
 * the bounds from its shapes' extremes, which another thread may be testing). */
static void refine(Bundle *b, int64_t at)
{
    int64_t a, e, end;
    subtree_span(b->tree.node, at, &a, &e, &end);
    shape_slots(b, b->tree.items + a, e - a);
    item_range(b, a, e);
    refit_range(b, at + 1, end);
}

/* Makes waiting subtree at (kernels.h LAZY_WAITING) as bundle_tree would have, once: the
 * thread that first claims it makes it, another that meets it meanwhile waits for it. */
void lazy_refine(Bundle *b, int64_t at)
{
    uint8_t *state = b->lazy + at, waiting = LAZY_WAITING;
    if (__atomic_compare_exchange_n(state, &waiting, LAZY_BUSY, 0, __ATOMIC_ACQUIRE, __ATOMIC_ACQUIRE)) {
        refine(b, at);
        __atomic_store_n(state, LAZY_READY, __ATOMIC_RELEASE);
        return;
    }
    for (int64_t spins = 1; __atomic_load_n(state, __ATOMIC_ACQUIRE) != LAZY_READY; spins++)
        team_relax(spins);
}

/* The primary bundle with its largest subtrees of at most b->lazy_items items waiting
 * (kernels.h LAZY_WAITING), each with bounds from its shapes' extremes (subtree_bound):
 * the shapes outside the tree and the leaves above those subtrees are made now, then the
 * nodes above, children before parents. A tree's items are all bounded with finite
 * centres (bvh_build). */
static void bundle_lazy(Bundle *b)
{
    const int32_t *node = b->tree.node;
    int64_t stack[BVH_STACK + 2], top;
    memset(b->lazy, LAZY_READY, (size_t)b->tree.nodes);
    shape_slots(b, b->tree.always, b->tree.nalways);
    stack[0] = 0;
    top = b->tree.nodes > 0 ? 0 : -1;  /* no shape bounded: every one outside the tree */
    while (top >= 0) {
        int64_t at = stack[top--], a, e, end;
        subtree_span(node, at, &a, &e, &end);
        if (node[2 * at + 1] > 0) {  /* a leaf */
            shape_slots(b, b->tree.items + a, e - a);
            item_range(b, a, e);
            refit_range(b, at, at + 1);
        } else if (e - a <= b->lazy_items) {
            double x[SX_COLUMNS], *box = b->box + BV_COLUMNS * at;
            PICK(b, subtree_extremes)(b->tree.items + a, e - a, b->bnd, b->apex, x);
            PICK(b, subtree_bound)(x, b->apex, b->dmin, b->dmax, b->u, b->tiny, b->overflow, box);
            cone_node(box);
            b->lazy[at] = LAZY_WAITING;
        } else {
            b->lazy[at] = LAZY_ABOVE;
            stack[++top] = node[2 * at];
            stack[++top] = at + 1;
        }
    }
    for (int64_t at = b->tree.nodes - 1; at >= 0; at--)
        if (b->lazy[at] == LAZY_ABOVE) {
            refit_range(b, at, at + 1);
            b->lazy[at] = LAZY_READY;
        }
}

/* One bundle of rays' bounds: its shape pass (none: radius given; a light's in its subtree
 * tasks, and for the shapes outside the tree here), each shape's own cone or box, and the
 * nodes' bounds (bvh.py Tree.refit, bounds.py). */
void bundle_bounds(Bundle *b, Team *team)
{
    if (b->pass == PASS_PRIMARY)
        team_phase(team, shape_task, b, shape_parts(b->n, b->jobs, b->chunk));
    else if (b->pass == PASS_SHADOW && b->tree.nalways > 0)
        shadow_rows(b, b->tree.always, b->items, b->items + b->tree.nalways);
    bundle_tree(b, team);
}

/* ---- the frame's set-up ---- */

typedef struct {
    Setup *s;
    Bundle *primary;
    int64_t parts;
    int64_t on[MAX_PARTS];  /* shapes on per range of rows */
} Tables;

static void tables_task(void *ctx, int64_t k)
{
    Tables *t = ctx;
    Setup *s = t->s;
    int64_t a = edge(s->rows, t->parts, k), e = edge(s->rows, t->parts, k + 1);
    t->on[k] = s->tables(s->values + PROP_WORDS * a, s->index + a, e - a, s->props, s->kinds, s->cam, s->tiny,
                         s->sf + s->sf_row * a, s->si + SI_COLUMNS * a, s->bnd + B_COLUMNS * a, s->bounded + a,
                         s->index_out + a, s->format, s->jobs > 1);
}

/* Task 0 builds the tree, the others run the primary bundle's shape pass. */
static void build_task(void *ctx, int64_t k)
{
    Tables *t = ctx;
    Setup *s = t->s;
    if (k == 0)
        s->nodes = bvh_build(s->bnd, s->bounded, s->shapes, s->items, s->always, s->where, s->node, s->counts,
                             s->room, s->jobs > 1, s->memo, s->isa);
    else
        shape_task(t->primary, k - 1);
}

/* The shape tables of the object table's rows (datapath.inc shape_tables, in ranges of
 * rows, each range's shapes then moved up behind the previous range's), the tree over
 * them (kernels.c bvh_build) and, when primary is not NULL, the primary rays' bounds
 * (its shape pass beside the build, then bundle_tree). Returns the shapes on. */
int64_t frame_setup(Setup *s, Bundle *primary, Team *team)
{
    Tables t = {.s = s, .primary = primary, .parts = shape_parts(s->rows, s->jobs, s->chunk)};
    team_phase(team, tables_task, &t, t.parts);
    int64_t n = 0;
    for (int64_t k = 0; k < t.parts; k++) {
        int64_t a = edge(s->rows, t.parts, k), m = t.on[k];
        if (a != n && m > 0) {  /* rows before a were off */
            memmove(s->sf + s->sf_row * n, s->sf + s->sf_row * a, (size_t)(s->sf_row * m));
            memmove(s->si + SI_COLUMNS * n, s->si + SI_COLUMNS * a, (size_t)m * SI_COLUMNS * sizeof *s->si);
            memmove(s->bnd + B_COLUMNS * n, s->bnd + B_COLUMNS * a, (size_t)m * B_COLUMNS * sizeof *s->bnd);
            memmove(s->bounded + n, s->bounded + a, (size_t)m);
            memmove(s->index_out + n, s->index_out + a, (size_t)m * sizeof *s->index_out);
        }
        n += m;
    }
    s->shapes = n;
    if (primary != NULL) {
        primary->n = n;
        if (!(primary->lazy_items > 0 && n > primary->lazy_items))  /* made whole */
            primary->lazy = NULL;
    }
    int64_t passes = primary != NULL && primary->lazy == NULL ? shape_parts(n, primary->jobs, primary->chunk) : 0;
    team_phase(team, build_task, &t, 1 + passes);
    if (primary != NULL) {
        primary->items = s->counts[0];
        primary->tree.nodes = s->nodes;
        primary->tree.nalways = s->counts[1];
        if (primary->lazy != NULL)
            bundle_lazy(primary);
        else
            bundle_tree(primary, team);
    }
    return n;
}
