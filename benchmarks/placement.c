/* Where the host put two CPUs of this machine, seen from inside: the time of a dependent
 * read, on one CPU, of cache lines the other has just written (placement.py compiles and
 * loads this file). On a VM the host may run the two vCPUs on one core's two hardware
 * threads (a shared L2: a few ns a line), on two cores sharing an L3 (some 20 ns on the
 * AMD EPYC host this project's VM first ran on; some 70 ns on an Intel Xeon's mesh), or on
 * cores with separate L3s (some 85 ns on that EPYC), and may move them between these every
 * few seconds to minutes. */
#define _GNU_SOURCE
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <time.h>

#define LINES 2048   /* 128 KiB: within the L2 of current x86 cores */
#define ROUNDS 63    /* the most rounds a call takes */
#define STRIDE 8     /* int64 words per 64-byte line */

typedef struct {
    int64_t *chain;              /* LINES lines, each holding the index of the next */
    int32_t order[LINES];        /* the lines' order in the chain (shuffle) */
    int32_t cpu[2];              /* the writer's, the reader's */
    int32_t rounds;
    _Atomic int32_t turn;        /* 2r + 1: round r written; 2r + 2: read */
    _Atomic int32_t failed;
    double own[ROUNDS], cross[ROUNDS];
} Probe;

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int pin(int32_t cpu)
{
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return sched_setaffinity(0, sizeof set, &set);
}

/* Seconds to follow the chain through every line once. */
static double follow(const int64_t *chain, volatile int64_t *sink)
{
    double start = now();
    int64_t at = 0;
    for (int32_t k = 0; k < LINES; k++)
        at = chain[at];
    *sink = at;
    return now() - start;
}

/* Waits a little in a spin: on one core's two hardware threads, the other thread's
 * timed read keeps the core's units. */
static inline void relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
}

/* A fixed shuffled order of the lines, so that no prefetcher guesses the next one. */
static void shuffle(int32_t *order)
{
    uint64_t seed = 0x9E3779B97F4A7C15u;
    for (int32_t i = 0; i < LINES; i++)
        order[i] = i;
    for (int32_t i = LINES - 1; i > 0; i--) {
        seed = seed * 6364136223846793005u + 1442695040888963407u;
        int32_t j = (int32_t)((seed >> 33) % (uint64_t)(i + 1)), t = order[i];
        order[i] = order[j];
        order[j] = t;
    }
}

/* Writes the chain: a cycle through every line in p's order. */
static void write_chain(Probe *p)
{
    for (int32_t i = 0; i < LINES; i++)
        p->chain[(int64_t)p->order[i] * STRIDE] = (int64_t)p->order[(i + 1) % LINES] * STRIDE;
}

/* Pins the calling thread to p's CPU `which` (0: the writer's, 1: the reader's); a
 * failure ends both threads. */
static void pin_or_fail(Probe *p, int which)
{
    if (pin(p->cpu[which]) != 0)
        atomic_store(&p->failed, 1);
}

/* Waits until p's turn is `turn`; 0 when the other thread failed instead. */
static int await_turn(Probe *p, int32_t turn)
{
    while (atomic_load(&p->turn) != turn)
        if (atomic_load(&p->failed))
            return 0;
        else
            relax();
    return 1;
}

static void *writer(void *arg)
{
    Probe *p = arg;
    volatile int64_t sink;
    pin_or_fail(p, 0);
    for (int32_t r = 0; r < p->rounds && !atomic_load(&p->failed); r++) {
        write_chain(p);
        p->own[r] = follow(p->chain, &sink);
        write_chain(p);  /* the lines modified in this CPU's cache again */
        atomic_store(&p->turn, 2 * r + 1);
        await_turn(p, 2 * r + 2);
    }
    return NULL;
}

static void *reader(void *arg)
{
    Probe *p = arg;
    volatile int64_t sink;
    pin_or_fail(p, 1);
    for (int32_t r = 0; r < p->rounds && await_turn(p, 2 * r + 1); r++) {
        p->cross[r] = follow(p->chain, &sink);
        atomic_store(&p->turn, 2 * r + 2);
    }
    return NULL;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Over `rounds` rounds (an odd number, 1..ROUNDS): the median ns per line of reading, on
 * CPU `to`, lines just written on CPU `from` (out[0]), and of reading them on `from`
 * itself (out[1]). Returns 0, or -1 when the arguments are not such or the threads could
 * not start or be pinned. The calling thread's CPUs are left as they were. */
int32_t cross_read_ns(int32_t from, int32_t to, int32_t rounds, double *out)
{
    if (rounds < 1 || rounds > ROUNDS || rounds % 2 == 0 || from < 0 || to < 0 || from >= CPU_SETSIZE
        || to >= CPU_SETSIZE || from == to)
        return -1;
    Probe *p = calloc(1, sizeof *p);
    int64_t *chain = aligned_alloc(64, (size_t)LINES * STRIDE * sizeof *chain);
    int32_t status = -1;
    if (p != NULL && chain != NULL) {
        p->chain = chain;
        p->cpu[0] = from;
        p->cpu[1] = to;
        p->rounds = rounds;
        shuffle(p->order);
        pthread_t w, r;
        if (pthread_create(&w, NULL, writer, p) == 0) {
            if (pthread_create(&r, NULL, reader, p) == 0)
                pthread_join(r, NULL);
            else
                atomic_store(&p->failed, 1);
            pthread_join(w, NULL);
            if (!atomic_load(&p->failed)) {
                qsort(p->cross, (size_t)rounds, sizeof(double), by_value);
                qsort(p->own, (size_t)rounds, sizeof(double), by_value);
                out[0] = 1e9 * p->cross[rounds / 2] / LINES;
                out[1] = 1e9 * p->own[rounds / 2] / LINES;
                status = 0;
            }
        }
    }
    free(chain);
    free(p);
    return status;
}
