/* A team of threads inside one compiled call (setup.c), so that passes of a few tens of
 * microseconds split over the cores: a hand-off through Python (a helper's wake-up, then
 * the GIL) costs about as much as such a pass.
 *
 * The calling thread leads: it releases phases one after another, each a list of tasks,
 * takes tasks itself and waits until every task of the phase has finished. Members are
 * threads that the Python side starts beside the call (threads.team: its helpers call
 * team_member); each takes the next task not yet taken of every phase released, and
 * returns when the leader ends the team (team_end). A member may join late or never: the
 * leader never waits for one to arrive, only for the tasks taken to finish. Tasks write
 * disjoint outputs, so results never depend on which thread ran which task.
 */
#ifndef REND3R_TEAM_H
#define REND3R_TEAM_H

#include <stdint.h>

#if defined(__STDC_NO_ATOMICS__) || defined(_WIN32)
#define TEAM_SOLO 1  /* no C11 atomics (or no sched_yield): members return at once, the leader does every task */
#else
#define TEAM_SOLO 0
#include <sched.h>
#include <stdatomic.h>
#endif

/* Phases a team may release; a leader that would need more runs the rest itself. */
#define TEAM_PHASES 16
#define TEAM_ENDED INT64_MAX

typedef void (*TeamTask)(void *ctx, int64_t k);

typedef struct {
    TeamTask fn;
    void *ctx;
    int64_t tasks;
#if TEAM_SOLO
    int64_t next, finished;
#else
    _Atomic int64_t next, finished;
#endif
} TeamPhase;

typedef struct {
#if TEAM_SOLO
    int64_t released;
#else
    _Atomic int64_t released;  /* phases released so far; TEAM_ENDED once the team has ended */
#endif
    TeamPhase at[TEAM_PHASES];
} Team;

#endif
