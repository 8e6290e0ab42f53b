/* A team of threads inside compiled calls (team.c; setup.c runs a frame's passes on one),
 * so that passes of a few tens of microseconds split over the cores: a hand-off through
 * a Python thread (its wake-up, then the GIL) costs about as much as such a pass.
 *
 * The thread that opens a team leads it (team_open, team_close; threads.py team keeps
 * one open while a program runs): it releases phases one after another, each a list of
 * tasks, takes tasks itself and waits until every task of the phase has finished. The
 * members are native threads of a pool (team.c), which wait spinning for the next phase
 * and take tasks of the phase released last: the leader from the front of its list, the
 * members from the back, each the next one not yet taken. A member may join
 * late or never: the leader never waits for one to arrive, only for the tasks taken to
 * finish. Tasks write disjoint outputs, so results never depend on which thread ran which
 * task.
 *
 * A task is claimed by one compare-and-swap on claim, which holds the phase number with
 * the first and last tasks not yet taken (the leader takes from the front, the members
 * from the back): a member that read a phase's slot late (the leader has moved on and may
 * be rewriting it) fails that swap, as the phase number in claim has changed, and never
 * runs a task of a phase that is over. A phase's slot is rewritten TEAM_RING phases
 * later, when every task of it has finished (the leader waited for them).
 */
#ifndef REND3R_TEAM_H
#define REND3R_TEAM_H

#include <stdint.h>

#if defined(__STDC_NO_ATOMICS__) || defined(_WIN32)
#define TEAM_SOLO 1  /* no C11 atomics or POSIX threads: the leader does every task */
#else
#define TEAM_SOLO 0
#include <sched.h>
#include <stdatomic.h>
#endif

/* A phase's description lives in a ring slot until the phase TEAM_RING later reuses it. */
#define TEAM_RING 4
#define TEAM_ENDED INT64_MAX

typedef void (*TeamTask)(void *ctx, int64_t k);

/* A waiting thread's spins-th wait: a little (the other threads run on other cores), then,
 * from TEAM_SPINS on, the core yielded at each: a team of more threads than cores must not
 * spin against its own leader. */
#define TEAM_SPINS 2048
static inline void team_relax(int64_t spins)
{
#if !TEAM_SOLO
    if (spins >= TEAM_SPINS) {
        sched_yield();
        return;
    }
#endif
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
    (void)spins;
}

#if TEAM_SOLO
#define TEAM_ATOMIC(t) t
#else
#define TEAM_ATOMIC(t) _Atomic t
#endif

typedef struct {
    TeamTask fn;
    void *ctx;
    TEAM_ATOMIC(int64_t) finished;
} TeamPhase;

typedef struct {
    TEAM_ATOMIC(int64_t) released;  /* the phase released last (1, 2, ...; 0: none yet), TEAM_ENDED once ended */
    TEAM_ATOMIC(uint64_t) claim;    /* that phase << 32 | its first task not taken << 16 | one past its last (team.c) */
    int64_t phases;                 /* the leader's count of phases */
    TEAM_ATOMIC(int32_t) refs;      /* the leader until it closes the team, and each member inside it */
    TEAM_ATOMIC(int32_t) leader_cpu;  /* the CPU the leader released its last phase on (-1: not known) */
    int32_t size;                   /* the leader and the members it was opened for */
    int32_t backwards;              /* tests: the leader alone runs each phase's tasks, last first (team.c) */
    TeamPhase ring[TEAM_RING];
} Team;

/* Runs tasks 0..tasks of fn on team t (the caller leads it); returns once every one has
 * finished (team.c). */
void team_phase(Team *t, TeamTask fn, void *ctx, int64_t tasks);

/* ---- ranges of work (threads.py parts) ---- */

/* The most ranges a pass over shapes splits into. */
#define MAX_PARTS 256

/* How many ranges 0..n splits into on jobs threads: up to per_job a thread, so that uneven
 * work evens out, none shorter than smallest unless there is only one, and a multiple of
 * jobs when there are at least jobs. Equal ranges then split evenly between the threads
 * when each takes its share (the leader from the front, the members from the back), and
 * passes over the same rows split them at the same places, so a thread that takes the
 * same ranges from pass to pass finds its rows in its own cache: the pairs' passes at
 * 4,096 spheres split into 5 ranges, the leader wrote 3 of them, rows the member read
 * in the shape tables' 4, and on two threads whose cores had separate L3s its writes
 * took twice the member's (docs/performance-history.md, "Ranges a multiple of the
 * thread count"). */
static inline int64_t parts_of(int64_t n, int32_t jobs, int64_t smallest, int64_t per_job)
{
    if (jobs <= 1 || n <= 0)
        return 1;
    int64_t parts = n / (smallest > 0 ? smallest : 1), most = per_job * (int64_t)jobs;
    parts = parts < most ? parts : most;
    parts -= parts >= jobs ? parts % jobs : 0;
    return parts < 1 ? 1 : parts;
}

/* Range k of 0..n split into parts: edge(k) .. edge(k + 1). */
static inline int64_t edge(int64_t n, int64_t parts, int64_t k)
{
    return n * k / parts;
}

#endif
