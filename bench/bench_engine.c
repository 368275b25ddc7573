/*
 * bench_engine.c - engine speed and memory, printed by `make bench`:
 *  1. an elastic block without contact, 1e4 .. 1e6 triangles: ns per
 *     element-step beside the memory-bandwidth bound of the bytes one
 *     element-step must move (measured with the STREAM-like triad here);
 *  2. a dense pile of discs in a box with contact: ns per element-step and
 *     the split over element forces, detection, contact and integration,
 *     and NBS against the all-pairs check on the same circles;
 *  3. a fracturing block (every triangle on its own nodes, a joint on every
 *     interior edge) vibrating at small strain: ns per element-step with
 *     the joints, beside the same block without fracture and the bandwidth
 *     bound of a private-node mesh;
 *  4. the elastic and fracturing blocks on 1 thread and on every core
 *     (fdem_set_threads): ns per element-step and the speed-up.
 * Figures, not pass/fail: nothing here is a test.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../tests/unit/build_model.h"
#include "model.h"
#include "stream.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void bench_elastic_block(double bandwidth_gbs)
{
    printf("\n## Elastic block, no contact (shared nodes, neo-Hookean CST, central difference)\n");
    printf("%10s %8s %14s %12s %14s %10s\n", "elements", "steps", "ns/elem-step", "bytes/elem",
           "bound ns/elem", "x bound");
    long sizes[] = {10000, 100000, 1000000};
    for (int k = 0; k < 3; k++) {
        int n = (int)(sqrt(sizes[k] / 2.0) + 0.5);
        fdem_model *m = fdem_model_create();
        int mat = build_material(m, 2700, 3e10, 0.25, 0, 0);
        int p = build_rectangle(m, mat, 0, 0, 1, 1, n, n);
        fdem_set_part_velocity(m, p, 0.1, -0.05, NULL);
        fdem_set_gravity(m, 0, -9.81);
        build_finalize(m, 0.5);
        int E = m->elem_count, N = m->node_count;
        int steps = (int)(3e7 / E);
        if (steps < 20) steps = 20;
        fdem_error err;
        for (int s = 0; s < 3; s++) fdem_step(m, &err); /* warm up caches and pages */
        double t0 = now();
        for (int s = 0; s < steps; s++) fdem_step(m, &err);
        double ns = (now() - t0) * 1e9 / ((double)steps * E);
        /* bytes per element-step that must cross memory once the mesh is
         * larger than cache: the 64-byte element record, and per node
         * force (memset + 3 read-modify-write passes amortised: 16 + 32),
         * position and velocity read/write (64), inverse mass and dof flag (9) */
        double bytes = 64 + (double)N / E * (16 + 32 + 64 + 9);
        double bound = bytes / bandwidth_gbs;
        printf("%10d %8d %14.1f %12.0f %14.1f %10.2f\n", E, steps, ns,
               (double)fdem_memory_bytes(m) / E, bound, ns / bound);
        fdem_model_destroy(m);
    }
}

static void bench_disc_pile(void)
{
    printf("\n## Dense disc pile in a box, with contact (discs of 16 rim nodes)\n");
    printf("%8s %9s %7s %13s %9s %9s %9s %9s %8s %8s\n", "discs", "elements", "steps",
           "ns/elem-step", "forces%", "detect%", "contact%", "integr%", "pairs/el", "touch/el");
    int dims[][2] = {{20, 20}, {60, 60}};
    for (int k = 0; k < 2; k++) {
        fdem_model *m = build_disc_pile(dims[k][0], dims[k][1]);
        fdem_error err;
        /* let the pile come into contact first: measure a loaded pile */
        int settle = 1000;
        for (int s = 0; s < settle; s++) fdem_step(m, &err);
        fdem_stage_times before = fdem_get_stage_times(m);
        int steps = (int)(2e7 / m->elem_count);
        if (steps < 100) steps = 100;
        double t0 = now();
        for (int s = 0; s < steps; s++) fdem_step(m, &err);
        double total = now() - t0;
        fdem_stage_times after = fdem_get_stage_times(m);
        double fe = after.elements - before.elements, de = after.detection - before.detection;
        double co = after.contact - before.contact, in = after.integration - before.integration;
        double sum = fe + de + co + in;
        fdem_counts c = fdem_get_counts(m);
        printf("%8d %9d %7d %13.1f %9.1f %9.1f %9.1f %9.1f %8.2f %8.3f\n", dims[k][0] * dims[k][1],
               c.elements, steps, total * 1e9 / ((double)steps * c.elements), 100 * fe / sum,
               100 * de / sum, 100 * co / sum, 100 * in / sum, (double)c.contact_pairs / c.elements,
               (double)c.contacts / c.elements);

        /* detection alone on this pile's circles: NBS against all pairs */
        contact_state *cs = &m->contact;
        nbs_pairs brute;
        nbs_pairs_init(&brute);
        int reps = 20;
        double tn = now();
        for (int s = 0; s < reps; s++)
            nbs_detect(&cs->grid, (size_t)m->elem_count, cs->cx, cs->cy, cs->r, cs->body, &cs->pairs);
        tn = (now() - tn) / reps;
        double tb = now();
        nbs_detect_brute((size_t)m->elem_count, cs->cx, cs->cy, cs->r, cs->body, &brute);
        tb = now() - tb;
        printf("         detection on these circles: NBS %.1f ns/element, all-pairs %.1f ns/element "
               "(%.0fx), same pairs: %s\n",
               tn * 1e9 / m->elem_count, tb * 1e9 / m->elem_count, tb / tn,
               brute.count == cs->pairs.count ? "yes" : "NO");
        nbs_pairs_free(&brute);
        fdem_model_destroy(m);
    }
}

/* A block vibrating at small strain (no joint breaks), fracturing or not. */
/* A bench that broke joints would time the wrong thing: say so loudly. */
#define CHECK_BROKEN(n) \
    do { \
        if (n) printf("           (!) %d joints broke: the figure above is not an intact block\n", n); \
    } while (0)

static fdem_model *vibrating_block(int n, int fracture)
{
    fdem_model *m = fdem_model_create();
    int mat = build_fracturing_rock(m, 0.1);
    build_rectangle_part(m, mat, 0, 0, 1, 1, n, n, fracture);
    /* a 0.1 mm/s shear of the initial velocity field: strains stay ~1e-9 */
    build_finalize(m, 0.5);
    for (int i = 0; i < m->node_count; i++) m->vel[2 * i] = 1e-4 * m->pos0[2 * i + 1];
    return m;
}

static void bench_fracturing_block(double bandwidth_gbs)
{
    printf("\n## Fracturing block: private nodes per triangle, a joint on every interior edge\n");
    printf("%10s %8s %8s %14s %13s %9s %9s %9s %12s %10s %14s\n", "elements", "joints", "steps",
           "ns/elem-step", "no-fracture", "forces%", "contact%", "integr%", "bytes/elem",
           "bound ns", "pairs/el");
    int sizes[] = {70, 224, 707}; /* 2 n^2 triangles: 1e4, 1e5, 1e6 */
    for (int k = 0; k < 3; k++) {
        double ns[2] = {0, 0};
        int steps = 0;
        fdem_stage_times before = {0};
        fdem_model *keep = NULL;
        for (int fracture = 0; fracture < 2; fracture++) {
            fdem_model *m = vibrating_block(sizes[k], fracture);
            fdem_error err;
            for (int s = 0; s < 3; s++) fdem_step(m, &err);
            if (fracture) before = fdem_get_stage_times(m);
            steps = (int)(2e7 / m->elem_count);
            if (steps < 10) steps = 10;
            double t0 = now();
            for (int s = 0; s < steps; s++) fdem_step(m, &err);
            ns[fracture] = (now() - t0) * 1e9 / ((double)steps * m->elem_count);
            if (fracture) keep = m;
            else fdem_model_destroy(m);
        }
        fdem_model *m = keep;
        fdem_stage_times t = fdem_get_stage_times(m);
        t.elements -= before.elements;
        t.detection -= before.detection;
        t.contact -= before.contact;
        t.integration -= before.integration;
        double sum = t.elements + t.detection + t.contact + t.integration;
        fdem_counts c = fdem_get_counts(m);
        /* per element-step once the mesh is larger than cache: the element
         * record (64), three private nodes' position, velocity and force
         * (3 x 64, force written twice: elements, joints), inverse mass and
         * dof flag (3 x 9), and 1.5 joints of 4 node ids + damage + size (40) */
        double bytes = 64 + 3 * (64 + 9) + 1.5 * 40;
        printf("%10d %8d %8d %14.1f %13.1f %9.1f %9.1f %9.1f %12.0f %10.1f %14.2f\n", c.elements,
               c.joints, steps, ns[1], ns[0], 100 * t.elements / sum,
               100 * (t.contact + t.detection) / sum, 100 * t.integration / sum,
               (double)fdem_memory_bytes(m) / c.elements, bytes / bandwidth_gbs,
               (double)c.contact_pairs / c.elements);
        CHECK_BROKEN(c.broken_joints);
        fdem_model_destroy(m);
    }
}

/* ns per element-step on `threads` threads: the best of three runs of
 * `steps` steps (a shared machine's neighbours only ever slow a run). */
static double time_steps(fdem_model *m, int threads, int steps)
{
    fdem_error err;
    fdem_set_threads(m, threads);
    for (int s = 0; s < 3; s++) fdem_step(m, &err);
    double best = INFINITY;
    for (int rep = 0; rep < 3; rep++) {
        double t0 = now();
        for (int s = 0; s < steps; s++) fdem_step(m, &err);
        best = fmin(best, now() - t0);
    }
    return best * 1e9 / ((double)steps * m->elem_count);
}

static void bench_threads(void)
{
    int cores = (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (cores < 2) cores = 2;
    printf("\n## Threads: the same models on 1 and %d threads (results are bit-identical)\n", cores);
    printf("%-28s %10s %8s %12s %12s %9s\n", "model", "elements", "colours", "1 thread ns",
           "threads ns", "speed-up");
    for (int fracture = 0; fracture < 2; fracture++)
        for (int k = 0; k < 2; k++) {
            int n = k ? 707 : 224;
            fdem_model *m = vibrating_block(n, fracture);
            int steps = (int)(1e7 / m->elem_count);
            if (steps < 10) steps = 10;
            double one = time_steps(m, 1, steps), many = time_steps(m, cores, steps);
            printf("%-28s %10d %8d %12.1f %12.1f %9.2f\n",
                   fracture ? "fracturing block (joints)" : "elastic block (shared nodes)",
                   m->elem_count, fracture ? m->joint_plan.color_count : m->elem_plan.color_count,
                   one, many, one / many);
            fdem_model_destroy(m);
        }
    int dims[][2] = {{20, 20}, {60, 60}};
    for (int k = 0; k < 2; k++) {
        fdem_model *m = build_disc_pile(dims[k][0], dims[k][1]);
        fdem_error err;
        for (int s = 0; s < 300; s++) fdem_step(m, &err); /* into contact, as above */
        int steps = (int)(5e6 / m->elem_count);
        if (steps < 25) steps = 25;
        double one = time_steps(m, 1, steps), many = time_steps(m, cores, steps);
        printf("%-28s %10d %8d %12.1f %12.1f %9.2f\n", "disc pile (contact)", m->elem_count,
               m->elem_plan.color_count, one, many, one / many);
        fdem_model_destroy(m);
    }
}

/* With no argument every section runs; otherwise only those named
 * (block, pile, fracture, threads), to iterate on one kernel. */
static int wanted(int argc, char **argv, const char *name)
{
    if (argc < 2) return 1;
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], name) == 0) return 1;
    return 0;
}

int main(int argc, char **argv)
{
    double bw = stream_bandwidth_gbs();
    printf("# fdemd engine bench (single core)\nsingle-core triad bandwidth: %.1f GB/s\n", bw);
    if (wanted(argc, argv, "block")) bench_elastic_block(bw);
    if (wanted(argc, argv, "pile")) bench_disc_pile();
    if (wanted(argc, argv, "fracture")) bench_fracturing_block(bw);
    if (wanted(argc, argv, "threads")) bench_threads();
    return 0;
}
