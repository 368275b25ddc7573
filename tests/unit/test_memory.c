/*
 * test_memory.c - the admission estimate against what models really hold.
 *
 * The daemon admits a case when fdem_memory_estimate_of() of its counts fits
 * the budget, so the estimate must not be below what the model comes to
 * hold once its contacts develop (else a loaded server is OOM-killed), and
 * fdem_memory_bytes() - the figure users read as the case's memory and the
 * one the estimate is held against here - must count what the model
 * allocated. Bundled examples, 2D and 3D, with and without contact and
 * fracture, are built as the daemon builds them and stepped. Peaks inside
 * a step (the raw pair list at detection) and finalize's scratch are not
 * seen here; valgrind massif measured them (core/build/memory.c).
 */
#include <stdio.h>
#include <stdlib.h>

#include "case/case.h"
#include "check.h"
#include "model/model.h"
#include "fdem.h"
#include "heap_count.h"
#include "json/problems.h"
#include "read_file.h"

/* An example and how long to step it: long enough for its contacts (or
 * fractures) to reach the densest the estimate prices them at. */
typedef struct memory_case {
    const char *path;
    int steps;
} memory_case;

static const memory_case memory_cases[] = {
    {"examples/incline.json", 2000},              /* sliding block: sprung pairs */
    {"examples/collision.json", 2000},            /* two bodies, first capacities */
    {"examples/disc-pile.json", 2000},            /* 2D pile */
    {"examples/tunnel.json", 200},                /* no contact, loaded facets */
    {"examples/jointed-block.json", 2000},        /* 2D fracture */
    {"examples/uniaxial-compression.json", 2000}, /* 2D fracture under platens */
    {"examples/collision-3d.json", 2000},         /* 3D contact */
    {"examples/sphere-pile.json", 500},           /* 3D pile */
    {"examples/uniaxial-prism-3d.json", 1000},    /* 3D fracture: densest pair lists */
};

/* Not absurdly high: between steps the examples here hold 1/1.5 to 1/2.5
 * of it, collision-3d (two bodies that barely touch) 1/3.8; a small model
 * sits on fixed first capacities of the contact lists (~100-200 KB). */
#define MEMORY_ESTIMATE_MAX_RATIO 4.5

static double gated_estimate;

static int memory_gate(void *ctx, double bytes)
{
    (void)ctx;
    gated_estimate = bytes;
    return 0;
}

static fdem_model *memory_build(const char *path)
{
    size_t length;
    char *text = read_file(path, &length);
    if (!text) return NULL;
    problems p;
    problems_init(&p);
    case_info info;
    gated_estimate = -1;
    fdem_model *m = case_build_gated(text, length, (size_t)1 << 32, memory_gate, NULL, &info, &p, NULL);
    CHECK(m != NULL, "%s was rejected", path);
    problems_free(&p);
    free(text);
    return m;
}

/* The largest fdem_memory_bytes() between steps. */
static size_t memory_peak(fdem_model *m, int steps)
{
    size_t peak = fdem_memory_bytes(m);
    fdem_error err;
    for (int s = 0; s < steps; s++) {
        CHECK(fdem_step(m, &err) == 0, "step %d: %s", s, err.message);
        size_t now = fdem_memory_bytes(m);
        if (now > peak) peak = now;
    }
    return peak;
}

/* The estimate the builder gated on, and that of the built model's counts
 * (what the daemon charges a stored case), both above the peak. */
static void estimate_holds_each_example(void)
{
    for (size_t i = 0; i < sizeof memory_cases / sizeof memory_cases[0]; i++) {
        const memory_case *c = &memory_cases[i];
        fdem_model *m = memory_build(c->path);
        if (!m) continue;
        fdem_counts n = fdem_get_counts(m);
        double counted = (double)fdem_memory_estimate_of(&n);
        double peak = (double)memory_peak(m, c->steps);
        printf("  %-38s estimate %9.0f (counts %9.0f) peak %9.0f ratio %.2f\n", c->path,
               gated_estimate, counted, peak, gated_estimate / peak);
        CHECK(gated_estimate >= peak, "%s: estimated %.0f bytes, holds %.0f after %d steps",
              c->path, gated_estimate, peak, c->steps);
        CHECK(counted >= peak, "%s: its counts price at %.0f bytes, it holds %.0f", c->path,
              counted, peak);
        CHECK(gated_estimate <= MEMORY_ESTIMATE_MAX_RATIO * peak,
              "%s: estimated %.0f bytes, more than %.0f times the %.0f it holds", c->path,
              gated_estimate, MEMORY_ESTIMATE_MAX_RATIO, peak);
        fdem_model_destroy(m);
    }
}

/* On two threads a 3D fracturing model also holds each thread's touch
 * lists: the estimate plus fdem_memory_per_thread() a thread, what the
 * daemon charges, covers it. */
static void threads_add_their_touch_lists(void)
{
    fdem_model *m = memory_build("examples/uniaxial-prism-3d.json");
    if (!m) return;
    fdem_set_threads(m, 2);
    /* its walk, 654 near pairs once the pairs apart leave the list, takes
     * threads from 64 pairs here, so that the lists are exercised */
    m->contact.walk_threads_min = 64;
    double peak = (double)memory_peak(m, 300);
    double priced = gated_estimate + 2.0 * (double)fdem_memory_per_thread(3);
    printf("  two threads: estimate %.0f + threads %.0f, peak %.0f\n", gated_estimate,
           priced - gated_estimate, peak);
    CHECK(priced >= peak, "estimated %.0f bytes with two threads, holds %.0f", priced, peak);
    CHECK(gated_estimate < peak, "the two threads' lists (peak %.0f) were not exercised", peak);
    fdem_model_destroy(m);
}

/* fdem_memory_bytes() against the allocator's own count (heap_count.h:
 * only the plain build checks it). What the model holds once built and stepped: within 3% and
 * 8 KB of what was allocated for it (the builder's leftovers, case_info),
 * and not above it by more than the few KB of part, material and
 * constraint tables counted at their capacities. */
static void memory_bytes_counts_the_heap(void)
{
#if HEAP_COUNTED
    const memory_case cases[] = {{"examples/jointed-block.json", 300},
                                 {"examples/uniaxial-prism-3d.json", 100},
                                 {"examples/tunnel.json", 50}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double before = heap_in_use();
        fdem_model *m = memory_build(cases[i].path);
        if (!m) continue;
        memory_peak(m, cases[i].steps);
        double counted = (double)fdem_memory_bytes(m);
        double heap = heap_in_use() - before;
        printf("  %-38s fdem_memory_bytes %9.0f heap %9.0f\n", cases[i].path, counted, heap);
        CHECK(counted <= heap + 4096, "%s: counts %.0f bytes, the heap grew by %.0f", cases[i].path,
              counted, heap);
        CHECK(heap <= 1.03 * counted + 8192, "%s: counts %.0f bytes, the heap grew by %.0f",
              cases[i].path, counted, heap);
        fdem_model_destroy(m);
    }
#endif
}

CHECK_MAIN(T(estimate_holds_each_example), T(threads_add_their_touch_lists),
           T(memory_bytes_counts_the_heap))
