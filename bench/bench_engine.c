/*
 * bench_engine.c - engine speed and memory, printed by `make bench`:
 *  1. an elastic block without contact, 1e4 .. 1e6 triangles: ns per
 *     element-step beside the memory-bandwidth bound of the bytes one
 *     element-step must move (measured with the STREAM-like triad here);
 *  2. a dense pile of discs in a box with contact: ns per element-step and
 *     the split over element forces, detection, contact and integration,
 *     and NBS against the all-pairs check on the same circles.
 * Figures, not pass/fail: nothing here is a test.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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

static fdem_model *disc_pile(int columns, int rows)
{
    fdem_model *m = fdem_model_create();
    int wall = build_material(m, 1000, 1e7, 0.25, 0.1, 0.3);
    int disc = build_material(m, 1000, 1e7, 0.25, 0.2, 0.3);
    double r = 0.01, W = columns * 0.021 + 0.004;
    int fl = build_rectangle(m, wall, -0.02, -0.02, W + 0.04, 0.02, columns * 2, 2);
    int le = build_rectangle(m, wall, -0.02, 0, 0.02, rows * 0.021 + 0.05, 2, rows * 2);
    int ri = build_rectangle(m, wall, W, 0, 0.02, rows * 0.021 + 0.05, 2, rows * 2);
    build_fix_part(m, fl);
    build_fix_part(m, le);
    build_fix_part(m, ri);
    for (int row = 0; row < rows; row++)
        for (int col = 0; col < columns; col++)
            build_disc(m, disc, 0.0115 + col * 0.021 + (row % 2) * 0.002, 0.0105 + row * 0.0205,
                       r * (0.92 + 0.08 * ((row * 7 + col * 3) % 5) / 4.0), 16);
    fdem_set_gravity(m, 0, -9.81);
    build_finalize(m, 0.5);
    return m;
}

static void bench_disc_pile(void)
{
    printf("\n## Dense disc pile in a box, with contact (discs of 16 rim nodes)\n");
    printf("%8s %9s %7s %13s %9s %9s %9s %9s %8s %8s\n", "discs", "elements", "steps",
           "ns/elem-step", "forces%", "detect%", "contact%", "integr%", "pairs/el", "touch/el");
    int dims[][2] = {{20, 20}, {60, 60}};
    for (int k = 0; k < 2; k++) {
        fdem_model *m = disc_pile(dims[k][0], dims[k][1]);
        fdem_error err;
        /* let the pile come into contact first: measure a loaded pile */
        int settle = 3000;
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

int main(void)
{
    double bw = stream_bandwidth_gbs();
    printf("# fdemd engine bench (single core)\nsingle-core triad bandwidth: %.1f GB/s\n", bw);
    bench_elastic_block(bw);
    bench_disc_pile();
    return 0;
}
