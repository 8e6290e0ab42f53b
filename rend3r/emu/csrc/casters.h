/* A directional light's shadow casters per receiving shape (datapath.inc light_pass).
 *
 * The shadow rays of a packet whose lanes all show one shape s start on s: in a ball
 * around s's centre, of radius rho = (1 + 1/16) / smin (the shape lies within 1/smin of
 * its centre; the sixteenth is room for the rounding of the hit points, and every lane's
 * point is checked to lie inside). The shapes that could block a line from some point of
 * that ball are found once per shape and light pass, with the tests blocked() applies to a
 * packet's ball of origins (its stop keys, node and item boxes, and behind test) and the
 * per-shape line test widened by the ball's radius; the packets of s then test those
 * shapes only. Every test here holds for each point of the ball whenever it holds for the
 * ball, so a shape left out is one that blocked() would have skipped or found missed for
 * every lane: the blocked lanes are the same, only the tests counted differ (docs/emulator.md
 * section 7).
 */
#ifndef REND3R_CASTERS_H
#define REND3R_CASTERS_H

#include <math.h>
#include <stdint.h>

#include "bounds.h"
#include "kernels.h"

/* Shapes a receiver's list holds at most (more: its packets traverse the tree), and the
 * receivers a light pass keeps (direct-mapped by slot). */
#define CASTER_MAX 8
#define CASTER_BITS 5
#define CASTER_SETS (1 << CASTER_BITS)
/* The shapes whose normal-space l a light pass keeps (datapath.inc test_shadow). */
#define ALONG_BITS 6

/* A shape's place in a direct-mapped cache of 2**bits sets (Fibonacci hashing: slots a
 * power of two apart, as in a grid of shapes, spread over the sets). */
static inline int64_t slot_hash(int64_t s, int bits)
{
    return (int64_t)(((uint64_t)s * 0x9E3779B97F4A7C15ull) >> (64 - bits));
}

typedef struct {
    int64_t owner;              /* the receiving shape's slot, -1: none */
    int32_t count;              /* casters, -1: none listed (the packets traverse the tree) */
    int32_t item[CASTER_MAX];   /* their slots, the shapes outside the tree first, then tree order */
    double centre[3], inside2;  /* the ball; a point is inside when its squared distance is <= inside2 */
} Casters;

/* Shape c (row: its row of the light's bounds, kernels.h PASS_SHADOW) lies behind every
 * origin within spread of centre whose depth along l is at least least (shape_bounds.inc
 * shadow_shapes states the test). */
static inline int shadow_behind(const LightPass *lp, int64_t c, int64_t row, const double *centre, double spread,
                                double least)
{
    const double *bh = lp->behind + 3 * row, *bc = lp->sh->bnd + B_COLUMNS * c;
    double ahead = least - bh[0];
    if (!(ahead > 0))
        return 0;
    double e0 = bc[B_CENTER] - centre[0], e1 = bc[B_CENTER + 1] - centre[1], e2 = bc[B_CENTER + 2] - centre[2];
    double mid = sqrt(e0 * e0 + e1 * e1 + e2 * e2) * (1.0 + BOUND_SLACK);
    return mid - spread > lp->radius[row] && lp->l_len * (bh[1] * ahead - bh[2] * (mid + spread)) > 0.015625;
}

/* The box (u0, u1, v0, v1) lies farther than reach from (u, v) on one axis. */
static inline int box_beyond(const double *b, double u, double v, double reach)
{
    return u + reach < b[BV_U0] || u - reach > b[BV_U1] || v + reach < b[BV_V0] || v - reach > b[BV_V1];
}

/* Shape c (not s; row: its row) may block a line along l from some point of the ball. */
static inline int may_block(const LightPass *lp, int64_t c, int64_t row, const double *centre, double spread,
                            double least, double reach)
{
    if (shadow_behind(lp, c, row, centre, spread, least))
        return 0;
    double r = lp->radius[row];
    if (!(r < INFINITY))
        return 1;
    const double *bc = lp->sh->bnd + B_COLUMNS * c;
    double v0 = bc[B_CENTER] - centre[0], v1 = bc[B_CENTER + 1] - centre[1], v2 = bc[B_CENTER + 2] - centre[2];
    double vv = v0 * v0 + v1 * v1 + v2 * v2, vd = v0 * lp->l_hat[0] + v1 * lp->l_hat[1] + v2 * lp->l_hat[2];
    double far = r + reach;  /* each point's line lies within reach of the centre's */
    return !(vv - vd * vd > far * far * (1.0 + BOUND_SLACK) + 1e-12 * vv);
}

/* Fill e with the casters of receiver s (count -1 when s has no ball, or more than
 * CASTER_MAX casters). */
static inline void casters_fill(const LightPass *lp, int64_t s, Casters *e)
{
    const Bvh *t = &lp->tree;
    const double *bs = lp->sh->bnd + B_COLUMNS * s;
    double rho = (1.0 + 0.0625) / bs[B_SMIN];
    e->owner = s;
    e->count = -1;
    e->centre[0] = bs[B_CENTER]; e->centre[1] = bs[B_CENTER + 1]; e->centre[2] = bs[B_CENTER + 2];
    double mag = fabs(e->centre[0]) + fabs(e->centre[1]) + fabs(e->centre[2]);
    if (!(rho < INFINITY) || !(mag < INFINITY) || !(lp->radius[lp->tree.where[s]] < INFINITY))
        return;
    e->inside2 = rho * rho * (1.0 - BOUND_SLACK);  /* a computed squared distance within 4 ulps */
    const double *c = e->centre, *f = t->frame, *l = lp->l_hat;
    double spread = rho * (1.0 + BOUND_SLACK), slack = 1e-12 * (mag + spread);
    double least = c[0] * l[0] + c[1] * l[1] + c[2] * l[2] - spread - slack, reach = spread + slack;
    double u = c[0] * f[0] + c[1] * f[1] + c[2] * f[2], v = c[0] * f[3] + c[1] * f[4] + c[2] * f[5];
    int32_t n = 0;
    for (int64_t k = 0; k < t->nalways; k++) {
        int64_t a = t->always[k];
        if (a != s && may_block(lp, a, lp->tree.where[a], c, spread, least, reach)) {
            if (n == CASTER_MAX)
                return;
            e->item[n++] = (int32_t)a;
        }
    }
    int32_t stack[BVH_STACK];
    int top = t->nodes > 0 ? 0 : -1;
    stack[0] = 0;
    while (top >= 0) {
        int32_t at = stack[top--];
        const double *key = lp->keys + 3 * at;
        if (least >= MAX(key[0] + key[1] * spread, key[2] + 2.0 * spread) ||
            box_beyond(t->box + BV_COLUMNS * at, u, v, reach))
            continue;
        int32_t first = t->node[2 * at], count = t->node[2 * at + 1];
        if (count == 0) {
            stack[++top] = first;
            stack[++top] = at + 1;
            continue;
        }
        for (int32_t i = first; i < first + count; i++) {
            int64_t a = t->items[i];
            if (a == s || (t->item_box != NULL && box_beyond(t->item_box + BX_COLUMNS * i, u, v, reach)) ||
                !may_block(lp, a, i, c, spread, least, reach))
                continue;
            if (n == CASTER_MAX)
                return;
            e->item[n++] = (int32_t)a;
        }
    }
    e->count = n;
}

#endif
