/* A team of threads inside compiled calls (team.h): the protocol, and the pool of native
 * threads that join teams.
 *
 * The members are threads of this library, not Python threads: they never take the GIL,
 * so joining a team and leaving it costs the leader at most a wake-up call. They are
 * started the first time a team asks for them; between teams they wait spinning for a
 * while, then sleep.
 *
 * A team's memory is the library's: it goes when the leader has closed the team and every
 * member has left it (refs), so closing never waits for a member. A busy host may stop a
 * member's CPU for milliseconds; a close that waited for the member to see the end then
 * took 1.4 ms (median over a slow spell's runs at 4,096 spheres) where it takes 10 us.
 */
#if defined(__linux__) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE  /* sched_getcpu and CPU sets (team_apart) */
#endif
#define _POSIX_C_SOURCE 200809L  /* pthread_sigmask, sched_yield, clock_gettime under -std=c11 */

#include <stdint.h>
#include <stdlib.h>
#include <time.h>

#include "team.h"

#if TEAM_SOLO
Team *team_open(int32_t members)
{
    (void)members;
    return calloc(1, sizeof(Team));
}

void team_close(Team *t)
{
    free(t);
}

void team_phase(Team *t, TeamTask fn, void *ctx, int64_t tasks)
{
    for (int64_t k = 0; k < tasks; k++)
        fn(ctx, t->backwards ? tasks - 1 - k : k);
}
#else
#include <pthread.h>
#include <signal.h>

static inline void team_wait(int64_t *spins)
{
    team_relax(++*spins);
}

/* The CPU the calling thread runs on (-1: not known). */
static inline int32_t team_cpu(void)
{
#if defined(__linux__)
    return sched_getcpu();
#else
    return -1;
#endif
}

/* A member's CPUs: those its thread may run on when it started (Linux; elsewhere none is
 * kept). */
typedef struct {
#if defined(__linux__)
    cpu_set_t allowed;
#endif
    int32_t known;
} TeamCpus;

static void team_cpus(TeamCpus *c)
{
#if defined(__linux__)
    c->known = sched_getaffinity(0, sizeof c->allowed, &c->allowed) == 0;
#else
    c->known = 0;
#endif
}

/* Moves a member that runs on its leader's CPU to another of its CPUs (c, those it
 * started with), when the team (size threads) has no more threads than those CPUs: a
 * scheduler that packs threads onto few CPUs (a VM guest's, to let its other vCPUs
 * idle) may wake a member onto its leader's CPU and leave it there, where the two take
 * turns and each phase's end waits out a spin. The member's CPUs are narrowed, which
 * moves it, then given back at once: it is never left pinned, and the scheduler may
 * place it anywhere again (the next team's join or phase moves it again if need be). */
static void team_apart(const TeamCpus *c, int32_t leader_cpu, int32_t size)
{
#if defined(__linux__)
    if (!c->known || leader_cpu < 0 || leader_cpu >= CPU_SETSIZE || size > CPU_COUNT(&c->allowed)
        || team_cpu() != leader_cpu)
        return;
    cpu_set_t other = c->allowed;
    CPU_CLR(leader_cpu, &other);
    if (CPU_COUNT(&other) > 0 && sched_setaffinity(0, sizeof other, &other) == 0)
        sched_setaffinity(0, sizeof c->allowed, &c->allowed);
#else
    (void)c;
    (void)leader_cpu;
    (void)size;
#endif
}

/* A phase's claim word: its number << 32, the first task not taken from the front << 16,
 * and one past the last not taken from the back (at most TEAM_TASKS). */
#define TEAM_TASKS 0xFFFF
#define CLAIM_FRONT(v) ((int64_t)((v) >> 16 & TEAM_TASKS))
#define CLAIM_BACK(v) ((int64_t)((v) & TEAM_TASKS))

/* Takes tasks of phase p (its slot ph, read after p was seen released) until none is
 * left or the phase is over: the leader from the front, members from the back, so that a
 * team of two keeps each end of a pass's ranges on the same thread from pass to pass
 * (measured in a throwaway build over ten alternating pairs of runs: 1.82x against 1.77x
 * at 4,096 spheres with one counter for all). Lists ordered for one end (band.c's
 * tapering parts, setup.c's subtrees largest first) reach the members smallest first:
 * the measured gain is net of that. */
static void team_take(Team *t, int64_t p, TeamPhase *ph, int from_back)
{
    uint64_t v = atomic_load_explicit(&t->claim, memory_order_acquire);
    while ((uint32_t)(v >> 32) == (uint32_t)p && CLAIM_FRONT(v) < CLAIM_BACK(v)) {  /* phases past 2^32 too */
        uint64_t next = from_back ? v - 1 : v + (1u << 16);
        if (atomic_compare_exchange_weak_explicit(&t->claim, &v, next, memory_order_acq_rel,
                                                  memory_order_acquire)) {
            /* The slot is read only now: the swap acquired the leader's writes to it, and
             * the leader rewrites it only after this task has finished. */
            ph->fn(ph->ctx, from_back ? CLAIM_BACK(v) - 1 : CLAIM_FRONT(v));
            atomic_fetch_add_explicit(&ph->finished, 1, memory_order_release);
            v = atomic_load_explicit(&t->claim, memory_order_acquire);
        }
    }
}

/* A member (its CPUs c): takes tasks of each phase released until the team ends. */
static void team_member(Team *t, const TeamCpus *c)
{
    int64_t done = 0, spins = 0;
    team_apart(c, atomic_load_explicit(&t->leader_cpu, memory_order_relaxed), t->size);
    for (;;) {
        int64_t p = atomic_load_explicit(&t->released, memory_order_acquire);
        if (p == TEAM_ENDED)
            return;
        if (p != done) {
            team_apart(c, atomic_load_explicit(&t->leader_cpu, memory_order_relaxed), t->size);
            team_take(t, p, &t->ring[p % TEAM_RING], 1);
            done = p;
            spins = 0;
        } else {
            team_wait(&spins);
        }
    }
}

void team_phase(Team *t, TeamTask fn, void *ctx, int64_t tasks)
{
    if (tasks <= 1 || tasks > TEAM_TASKS || t->backwards) {  /* nothing to share, more than a claim counts
                                                                 (no pass asks), or a test's team */
        for (int64_t k = 0; k < tasks; k++)
            fn(ctx, t->backwards ? tasks - 1 - k : k);
        return;
    }
    int64_t p = ++t->phases;
    TeamPhase *ph = &t->ring[p % TEAM_RING];
    ph->fn = fn;
    ph->ctx = ctx;
    atomic_store_explicit(&ph->finished, 0, memory_order_relaxed);
    atomic_store_explicit(&t->leader_cpu, team_cpu(), memory_order_relaxed);
    atomic_store_explicit(&t->claim, (uint64_t)p << 32 | (uint64_t)tasks, memory_order_release);
    atomic_store_explicit(&t->released, p, memory_order_release);
    team_take(t, p, ph, 0);
    int64_t spins = 0;
    while (atomic_load_explicit(&ph->finished, memory_order_acquire) < tasks)
        team_wait(&spins);
}

/* The pool: one team at a time. Its threads wait until a team is opened for them (the
 * first `wanted` threads join it), and hold a reference to it while they are members.
 * A thread the last team wanted waits spinning for the next one for
 * POOL_LINGER_NS before it sleeps, as OpenMP runtimes do between parallel regions, and
 * again after each team it saw opened but could not join (it had ended): a team opened
 * meanwhile (a program's next run) is joined without a wake-up call, which cost
 * team_open some 8 us of the 10 it took (benchmarks/bench_team.py). */
#define POOL_LIMIT 256
#define POOL_LINGER_NS 200000
static pthread_mutex_t pool_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t pool_wake = PTHREAD_COND_INITIALIZER;
static struct {
    int32_t started;   /* threads started */
    int32_t wanted;    /* of them, members of the open team (or of the last, once it has ended) */
    int32_t sleeping;  /* of them, waiting on pool_wake */
    int64_t opened;    /* teams opened so far (a thread joins each at most once) */
    Team *team;        /* the open team, NULL: none */
    int32_t forks;     /* set up pthread_atfork once */
} pool;
static TEAM_ATOMIC(int64_t) pool_opened;  /* pool.opened, for threads that spin without the lock */

/* Drops a reference to t; the last one frees it. */
static void team_release(Team *t)
{
    if (atomic_fetch_sub_explicit(&t->refs, 1, memory_order_acq_rel) == 1)
        free(t);
}

static int64_t pool_now_ns(void)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (int64_t)now.tv_sec * 1000000000 + now.tv_nsec;
}

/* Waits spinning until a team is opened after the `seen`th, or POOL_LINGER_NS have
 * passed. */
static void pool_linger(int64_t seen)
{
    int64_t spins = 0, until = pool_now_ns() + POOL_LINGER_NS;
    while (atomic_load_explicit(&pool_opened, memory_order_relaxed) == seen) {
        team_wait(&spins);  /* yields the core after a while: a team may have more threads than cores */
        if ((spins % 64 == 0 || spins >= TEAM_SPINS) && pool_now_ns() > until)  /* a yield may take long */
            return;
    }
}

static void *pool_thread(void *arg)
{
    int32_t index = (int32_t)(intptr_t)arg;
    int64_t seen = 0;
    TeamCpus cpus;
    team_cpus(&cpus);
    pthread_mutex_lock(&pool_lock);
    for (;;) {
        while (!(pool.team != NULL && pool.opened != seen && index < pool.wanted)) {
            if (index < pool.wanted) {  /* wanted by the last team, which has ended (or is ending) */
                int64_t last = pool.opened;
                pthread_mutex_unlock(&pool_lock);
                pool_linger(last);
                pthread_mutex_lock(&pool_lock);
                if (pool.opened != last)  /* opened while it waited, or as the wait ran out (no wake-up
                                             comes then): join it; if it has ended, wait again; if it
                                             does not want this thread, sleep */
                    continue;
            }
            pool.sleeping++;
            pthread_cond_wait(&pool_wake, &pool_lock);
            pool.sleeping--;
        }
        Team *t = pool.team;
        seen = pool.opened;
        atomic_fetch_add_explicit(&t->refs, 1, memory_order_relaxed);  /* under the lock: t is open, its leader's */
        pthread_mutex_unlock(&pool_lock);
        team_member(t, &cpus);
        team_release(t);
        pthread_mutex_lock(&pool_lock);
    }
    return NULL;
}

/* A fork waits until no thread holds the pool's lock, so that the child's copy of the
 * pool is whole; in the child only the forking thread exists: the pool starts afresh. */
static void pool_before_fork(void)
{
    pthread_mutex_lock(&pool_lock);
}

static void pool_after_fork_parent(void)
{
    pthread_mutex_unlock(&pool_lock);
}

static void pool_after_fork_child(void)
{
    pthread_mutex_init(&pool_lock, NULL);
    pthread_cond_init(&pool_wake, NULL);
    pool.started = pool.wanted = pool.sleeping = 0;
    pool.team = NULL;
    atomic_store_explicit(&pool_opened, pool.opened, memory_order_relaxed);
}

/* Opens a team with up to `members` threads of the pool beside the caller, who leads it;
 * NULL when there is no memory for it. None joins when the pool is serving another team
 * or cannot start a thread. They join as they wake: the leader never waits for them. */
Team *team_open(int32_t members)
{
    Team *t = calloc(1, sizeof *t);
    if (t == NULL)
        return NULL;
    atomic_init(&t->refs, 1);
    atomic_init(&t->leader_cpu, team_cpu());
    members = members < 0 ? 0 : members > POOL_LIMIT ? POOL_LIMIT : members;
    pthread_mutex_lock(&pool_lock);
    if (!pool.forks) {
        pthread_atfork(pool_before_fork, pool_after_fork_parent, pool_after_fork_child);
        pool.forks = 1;
    }
    if (pool.team != NULL || members == 0) {
        pthread_mutex_unlock(&pool_lock);
        return t;
    }
    if (pool.started < members) {
        sigset_t all, before;  /* the pool's threads block every signal: the process's threads take them */
        sigfillset(&all);
        pthread_sigmask(SIG_SETMASK, &all, &before);
        while (pool.started < members) {
            pthread_t thread;
            pthread_attr_t attr;
            pthread_attr_init(&attr);
            pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
            int failed = pthread_create(&thread, &attr, pool_thread, (void *)(intptr_t)pool.started);
            pthread_attr_destroy(&attr);
            if (failed)
                break;
            pool.started++;
        }
        pthread_sigmask(SIG_SETMASK, &before, NULL);
    }
    pool.wanted = members < pool.started ? members : pool.started;
    t->size = 1 + pool.wanted;  /* read by the members after the lock below */
    pool.team = t;
    atomic_store_explicit(&pool_opened, ++pool.opened, memory_order_relaxed);
    if (pool.sleeping > 0)  /* the others see pool_opened, or pool.opened once they hold the lock */
        pthread_cond_broadcast(&pool_wake);
    pthread_mutex_unlock(&pool_lock);
    return t;
}

/* Ends team t without waiting for its members: each leaves when it sees the end, and the
 * last reference frees it. */
void team_close(Team *t)
{
    atomic_store_explicit(&t->released, TEAM_ENDED, memory_order_release);
    pthread_mutex_lock(&pool_lock);
    if (pool.team == t)
        pool.team = NULL;  /* no thread joins it from now on */
    pthread_mutex_unlock(&pool_lock);
    team_release(t);
}
#endif

/* ---- for tests ---- */

/* A team without members whose leader runs each phase's tasks last first, as if members
 * had taken them all from the back before the leader took one: a pass whose result must
 * not depend on which thread ran which task, or when, gets the order threads make least
 * often (tests/emu/test_processor_vectorized.py). Closed with team_close. */
Team *team_open_backwards(void)
{
    Team *t = team_open(0);
    if (t != NULL)
        t->backwards = 1;
    return t;
}

/* The split the passes take (team.h parts_of), for the passes that Python splits
 * (threads.py parts: the pairs' ranges), so that they split the rows alike. */
int64_t team_parts(int64_t n, int32_t jobs, int64_t smallest, int64_t per_job)
{
    return parts_of(n, jobs, smallest, per_job);
}

/* A check of the protocol (tests/emu/test_threads.py). */

static _Thread_local char team_here;  /* its address tells the threads apart */

typedef struct {
    TEAM_ATOMIC(int32_t) *runs;   /* one count per task of this phase */
    const char *leader;           /* the leader's team_here */
} TeamCheck;

/* Adds 1 to the task's count, and TEAM_BY_MEMBER more when a member runs it. */
#define TEAM_BY_MEMBER 256

static void team_check_task(void *ctx, int64_t k)
{
    TeamCheck *c = ctx;
    for (volatile int32_t spin = 0; spin < 200; spin++)  /* a little work, so that members get some */
        ;
    int32_t add = &team_here == c->leader ? 1 : 1 + TEAM_BY_MEMBER;
#if TEAM_SOLO
    c->runs[k] += add;
#else
    atomic_fetch_add_explicit(&c->runs[k], add, memory_order_relaxed);
#endif
}

/* Runs phases of tasks[0], tasks[1], ... tasks on team t, each task adding to its count
 * in runs (the phases' counts one after another) 1 when the leader runs it and 257 when a
 * member does. Each phase has a context of its own (one of TEAM_RING + 1, in turn), so
 * that a task run with another phase's slot counts in the wrong place. */
void team_check_runs(Team *t, const int64_t *tasks, int64_t phases, int32_t *runs)
{
    TeamCheck c[TEAM_RING + 1];
    for (int64_t p = 0, at = 0; p < phases; at += tasks[p++]) {
        TeamCheck *mine = &c[p % (TEAM_RING + 1)];
        mine->runs = (TEAM_ATOMIC(int32_t) *)(runs + at);
        mine->leader = &team_here;
        team_phase(t, team_check_task, mine, tasks[p]);
    }
}
