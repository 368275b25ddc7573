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
 *     (fdem_set_threads): ns per element-step and the speed-up;
 *  5. the same elastic block in 3D (tetrahedra of a box mesh, 1e4 .. 1e6)
 *     with its bandwidth bound, and on 1 thread and every core;
 *  6. a pile of tetrahedral spheres dropped into a box, with contact: ns
 *     per element-step split over the stages, against the 3D elastic block;
 *  7. the fracturing block in 3D (every tetrahedron on its own nodes, a
 *     joint on every interior face; 1e4, 1e5), as in 3, damped and
 *     undamped (goal: <= 4x the elastic block 3D, which is undamped; each
 *     row also beside its own twin without fracture);
 *  8. the fracturing blocks of 3 and 7 once broken (issue 34): every joint
 *     broken in place, so the pieces hold together by contact alone across
 *     faces that touch over their whole area, as after a split: ns per
 *     element-step split over the stages, the pairs and detections that
 *     drive it, against the same block intact (goal: <= 4x in 3D, <= 3x in
 *     2D).
 *  9. hydraulic fracturing (issue 36): the 2D fracturing block of 3, fed
 *     with fluid at its centre (until 20 joints broke, at most 3000
 *     steps), then timed: ns per element-step with the flow, beside the
 *     same block stepped from the same state with the flow switched off,
 *     and the flow's share of the step (its cost follows the open network:
 *     what remains is the scan of every joint for newly damaged ones).
 * Figures, not pass/fail: nothing here is a test.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../tests/unit/build_container_3d.h"
#include "../tests/unit/build_model.h"
#include "mesh/mesh_3d.h"
#include "model/model.h"
#include "pair_kinds.h"
#include "stream.h"
#include "fluid/fluid.h"
#include "math/clock.h"

/* The elastic block in either dimension: one builder and one bytes count,
 * so the 2D and 3D figures are measured the same way and printed alike. */
typedef struct block_kind {
    const char *title;
    int dim;
    double record_bytes;  /* hot element record */
} block_kind;

static const block_kind BLOCK_2D = {"Elastic block, no contact (shared nodes, neo-Hookean CST, "
                                    "central difference)", 2, sizeof(element_hot)};
static const block_kind BLOCK_3D = {"Elastic block 3D, no contact (shared nodes, neo-Hookean "
                                    "tetrahedra in a box mesh, central difference)", 3,
                                    sizeof(tet_hot)};

static fdem_model *elastic_block(const block_kind *k, long elements)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (k->dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_material(m, 2700, 3e10, 0.25, 0, 0);
    int p;
    if (k->dim == 2) {
        int n = (int)(sqrt(elements / 2.0) + 0.5); /* 2 triangles a cell */
        p = build_rectangle(m, mat, 0, 0, 1, 1, n, n);
    } else {
        int n = (int)(cbrt(elements / 6.0) + 0.5); /* 6 tetrahedra a cell */
        double origin[3] = {0, 0, 0}, size[3] = {1, 1, 1};
        int div[3] = {n, n, n};
        fdem_tet_mesh mesh = {0};
        if (fdem_tet_mesh_box(origin, size, div, &mesh, &err)) build_die("box mesh", &err);
        p = fdem_add_part_3d(m, &mesh, mat, 0, &err);
        fdem_tet_mesh_free(&mesh);
        if (p < 0) build_die("box part", &err);
    }
    const double v[3] = {0.1, -0.05, 0.02}, g[3] = {0, -9.81, 0};
    if (fdem_set_part_velocity_v(m, p, v, &err)) build_die("velocity", &err);
    fdem_set_gravity_v(m, g);
    build_finalize(m, 0.5);
    return m;
}

/* Bytes per element-step once the mesh is larger than cache: the element
 * record, and per node force (memset D x 8, then one read-modify-write of
 * the element pass amortised over the elements sharing it: 2 D x 8),
 * position and velocity read and written by the integrator (4 D x 8),
 * inverse mass and dof flag (9). */
static double block_bytes_moved(const block_kind *k, const fdem_model *m)
{
    double D = k->dim;
    return k->record_bytes + (double)m->node_count / m->elem_count * (8 * D * (1 + 2 + 4) + 9);
}

/* Wall and CPU ns per element-step of the best of three runs of `steps`
 * steps: a shared machine's neighbours only ever slow a run. */
typedef struct step_time {
    double wall, cpu;
} step_time;

/* A model's state at the start of a timed window, kept as a checkpoint so
 * that every run replays the same steps. Three windows run one after the
 * other would each time other states, and the best of them is the
 * cheapest phase, not the least disturbed run: a sphere pile still
 * bouncing costs 58 to 85 ns an element-step from one 246-step window to
 * the next, and took the 58. */
typedef struct window_start {
    void *state;
    size_t size;
} window_start;

static window_start window_mark(const fdem_model *m)
{
    window_start w = {NULL, fdem_checkpoint_size(m)};
    if (!(w.state = malloc(w.size)) || fdem_checkpoint_write(m, w.state, w.size)) {
        fprintf(stderr, "bench: no checkpoint of %zu bytes to replay a window from\n", w.size);
        exit(1);
    }
    return w;
}

static void window_rewind(fdem_model *m, const window_start *w)
{
    fdem_error err;
    if (fdem_checkpoint_read(m, w->state, w->size, &err)) {
        fprintf(stderr, "bench: %s\n", err.message);
        exit(1);
    }
}

static step_time timed_steps(fdem_model *m, int steps)
{
    fdem_error err;
    double t0 = clock_wall_seconds(), c0 = clock_cpu_seconds();
    for (int s = 0; s < steps; s++) fdem_step(m, &err);
    return (step_time){clock_wall_seconds() - t0, clock_cpu_seconds() - c0};
}

/* The best of three runs of the same `steps` steps from m's state (m is
 * left at the end of them), as wall and CPU ns per element-step of the
 * whole window; and, for a window whose first step rebuilds what a
 * restore left stale (the broken blocks' near list), CPU ns per element
 * of that first step and per element-step of the rest, each the best of
 * the three replays. */
typedef struct split_time {
    step_time whole;
    double first_cpu, rest_cpu;
} split_time;

static split_time best_of_three_split(fdem_model *m, int steps)
{
    window_start w = window_mark(m);
    split_time best = {{INFINITY, INFINITY}, INFINITY, INFINITY};
    for (int rep = 0; rep < 3; rep++) {
        window_rewind(m, &w);
        double t0 = clock_wall_seconds(), c0 = clock_cpu_seconds();
        step_time first = timed_steps(m, 1), rest = timed_steps(m, steps - 1);
        step_time t = {clock_wall_seconds() - t0, clock_cpu_seconds() - c0};
        best.whole = (step_time){fmin(best.whole.wall, t.wall), fmin(best.whole.cpu, t.cpu)};
        best.first_cpu = fmin(best.first_cpu, first.cpu);
        best.rest_cpu = fmin(best.rest_cpu, rest.cpu);
    }
    free(w.state);
    double E = m->elem_count, scale = 1e9 / ((double)steps * E);
    best.whole = (step_time){best.whole.wall * scale, best.whole.cpu * scale};
    best.first_cpu *= 1e9 / E;
    best.rest_cpu = steps > 1 ? best.rest_cpu * 1e9 / ((double)(steps - 1) * E) : 0;
    return best;
}

static step_time best_of_three(fdem_model *m, int steps)
{
    return best_of_three_split(m, steps).whole;
}

static void bench_elastic_block(const block_kind *k, double bandwidth_gbs)
{
    printf("\n## %s\n", k->title);
    printf("%10s %8s %14s %10s %12s %14s %14s %10s\n", "elements", "steps", "ns/elem-step",
           "cpu ns", "bytes/elem", "moved B/step", "bound ns/elem", "x bound");
    long sizes[] = {10000, 100000, 1000000};
    for (int s = 0; s < 3; s++) {
        fdem_model *m = elastic_block(k, sizes[s]);
        int E = m->elem_count;
        int steps = (int)(3e7 / E);
        if (steps < 20) steps = 20;
        fdem_error err;
        for (int w = 0; w < 3; w++) fdem_step(m, &err); /* warm up caches and pages */
        step_time t = best_of_three(m, steps);
        double ns = t.wall, cpu = t.cpu;
        double bytes = block_bytes_moved(k, m), bound = bytes / bandwidth_gbs;
        printf("%10d %8d %14.1f %10.1f %12.0f %14.0f %14.1f %10.2f\n", E, steps, ns, cpu,
               (double)fdem_memory_bytes(m) / E, bytes, bound, ns / bound);
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
        double t0 = clock_wall_seconds();
        for (int s = 0; s < steps; s++) fdem_step(m, &err);
        double total = clock_wall_seconds() - t0;
        fdem_stage_times after = fdem_get_stage_times(m);
        double fe = after.elements + after.joints - before.elements - before.joints;
        double de = after.detection - before.detection;
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
        double tn = clock_wall_seconds();
        for (int s = 0; s < reps; s++)
            nbs_detect(&cs->grid, (size_t)m->elem_count, cs->cx, cs->cy, cs->r, cs->body, &cs->pairs);
        tn = (clock_wall_seconds() - tn) / reps;
        double tb = clock_wall_seconds();
        nbs_detect_brute((size_t)m->elem_count, cs->cx, cs->cy, cs->r, cs->body, &brute);
        tb = clock_wall_seconds() - tb;
        printf("         detection on these circles: NBS %.1f ns/element, all-pairs %.1f ns/element "
               "(%.0fx), same pairs: %s\n",
               tn * 1e9 / m->elem_count, tb * 1e9 / m->elem_count, tb / tn,
               brute.count == cs->pairs.count ? "yes" : "NO");
        nbs_pairs_free(&brute);
        fdem_model_destroy(m);
    }
}

/* A 3D tetrahedral mesh appended to a model as one part (dies on failure). */
static int add_part_3d(fdem_model *m, int mat, fdem_tet_mesh *mesh, fdem_error *err)
{
    int p = fdem_add_part_3d(m, mesh, mat, 0, err);
    fdem_tet_mesh_free(mesh);
    if (p < 0) build_die("3D part", err);
    return p;
}

/* Spheres of radius r (8 divisions) on a cubic lattice of pitch 2.02 r,
 * nx x ny x nz of them, dropped into a box of fixed slabs (floor and four
 * walls, one part: build_container_mesh) meshed about as finely as the
 * spheres (NBS sizes its cells by the largest element). */
static fdem_model *sphere_pile(int nx, int ny, int nz)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int wall = build_material(m, 1000, 1e7, 0.25, 0.1, 0.3);
    int ball = build_material(m, 1000, 1e7, 0.25, 0.2, 0.3);
    const double r = 0.01, pitch = 2.02 * r, T = 0.01, e = 0.008;
    const double X = nx * pitch, Y = ny * pitch, H = nz * pitch + 2 * r;
    fdem_tet_mesh box = {0};
    if (build_container_mesh(X, Y, H, T, e, &box, &err)) build_die("container", &err);
    build_fix_part(m, add_part_3d(m, wall, &box, &err));
    for (int iz = 0; iz < nz; iz++)
        for (int iy = 0; iy < ny; iy++)
            for (int ix = 0; ix < nx; ix++) {
                /* a little off the lattice, so the pile does not stand as columns */
                double c[3] = {(ix + 0.5) * pitch + 0.0005 * (iz % 2), (iy + 0.5) * pitch,
                               r * 1.02 + iz * pitch};
                fdem_tet_mesh mesh = {0};
                if (fdem_tet_mesh_sphere(c, r, 8, &mesh, &err)) build_die("sphere", &err);
                add_part_3d(m, ball, &mesh, &err);
            }
    const double g[3] = {0, 0, -9.81};
    fdem_set_gravity_v(m, g);
    build_finalize(m, 0.5);
    return m;
}

/* CPU ns per element-step of the 3D elastic block of about E tetrahedra,
 * best of three runs: what the 3D goals (the sphere pile, the fracturing
 * block: 4x each) are measured against, in the same process. */
static double elastic_block_3d_cpu(int E)
{
    fdem_error err;
    fdem_model *block = elastic_block(&BLOCK_3D, E);
    for (int s = 0; s < 3; s++) fdem_step(block, &err);
    double elastic = best_of_three(block, (int)(1e7 / block->elem_count) + 20).cpu;
    fdem_model_destroy(block);
    return elastic;
}

/* The sphere pile with contact, its time split over the stages, beside the
 * 3D elastic block of about as many elements (goal: <= 4x that). */
static void bench_sphere_pile(void)
{
    printf("\n## Sphere pile in a box, 3D with contact (spheres of 8 divisions, fixed slabs)\n");
    printf("%8s %9s %7s %13s %8s %9s %9s %9s %9s %8s %8s %10s %9s\n", "spheres", "elements",
           "steps", "ns/elem-step", "cpu ns", "forces%", "detect%", "contact%", "integr%",
           "pairs/el", "touch/el", "elastic cpu", "x elastic");
    int dims[][3] = {{3, 3, 3}, {6, 6, 4}}; /* contact is slow yet: keep make bench short */
    for (int k = 0; k < 2; k++) {
        fdem_model *m = sphere_pile(dims[k][0], dims[k][1], dims[k][2]);
        fdem_error err;
        /* let the spheres fall into contact: measure a loaded pile */
        for (int s = 0; s < 400; s++) fdem_step(m, &err);
        int E = m->elem_count;
        /* the spheres still bounce: a window of 1000 steps (about 2 ms)
         * spans several rebounds, so its figure is not one phase's */
        int steps = 1000;
        fdem_stage_times before = fdem_get_stage_times(m);
        step_time t = best_of_three(m, steps);
        fdem_stage_times after = fdem_get_stage_times(m);
        double fe = after.elements + after.joints - before.elements - before.joints;
        double de = after.detection - before.detection;
        double co = after.contact - before.contact, in = after.integration - before.integration;
        double sum = fe + de + co + in, ns = t.wall, cpu = t.cpu;
        fdem_counts c = fdem_get_counts(m);

        double elastic = elastic_block_3d_cpu(E);
        printf("%8d %9d %7d %13.1f %8.1f %9.1f %9.1f %9.1f %9.1f %8.2f %8.3f %10.1f %9.2f\n",
               dims[k][0] * dims[k][1] * dims[k][2], E, steps, ns, cpu, 100 * fe / sum,
               100 * de / sum, 100 * co / sum, 100 * in / sum, (double)c.contact_pairs / E,
               (double)c.contacts / E, elastic, cpu / elastic);
        fdem_model_destroy(m);
    }
    printf("goal: the pile within 4x the elastic block per element-step (CPU time of both)\n");
}

/* A bench that broke joints would time the wrong thing: say so loudly. */
#define CHECK_BROKEN(n) \
    do { \
        if (n) printf("           (!) %d joints broke: the figure above is not an intact block\n", n); \
    } while (0)

/* The fracturing block in either dimension: one builder and one table, so
 * the 2D and 3D figures are measured the same way and printed alike. */
typedef struct fracture_kind {
    const char *title;
    int dim;
    int sizes[3];         /* cells a side; 0: no such row */
    double record_bytes;  /* hot element record */
    double damping;       /* the rock's damping ratio (both blocks of a row) */
} fracture_kind;

static const fracture_kind FRACTURE_2D = {
    "Fracturing block: private nodes per triangle, a joint on every interior edge", 2,
    {70, 224, 707}, sizeof(element_hot), 0.1}; /* 2 n^2 triangles: 1e4, 1e5, 1e6 */
static const fracture_kind FRACTURE_3D = {
    "Fracturing block 3D: private nodes per tetrahedron, a joint on every interior face "
    "(damping ratio 0.1)", 3, {12, 26, 0}, sizeof(tet_hot), 0.1}; /* 6 n^3 tetrahedra: 1e4, 1e5 */
/* The same without damping, like the elastic block 3D the goal compares
 * with: the viscous stress costs both blocks of a row the same ~5 ns an
 * element-step (1e5: 48 against 43 with fracture, 16 against 11 without),
 * which the damped row's ratio to the undamped elastic block counts as
 * joint cost. */
static const fracture_kind FRACTURE_3D_UNDAMPED = {
    "Fracturing block 3D, undamped (as the elastic block 3D)", 3, {12, 26, 0}, sizeof(tet_hot),
    0.0};

/* A unit block of n cells a side vibrating at small strain (no joint
 * breaks), fracturing or not: rock damped as the kind says, a 0.1 mm/s
 * shear of the initial velocity field, so strains stay ~1e-9. */
static fdem_model *vibrating_block(const fracture_kind *k, int n, int fracture)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (k->dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_fracturing_rock(m, k->damping);
    if (k->dim == 2) {
        build_rectangle_part(m, mat, 0, 0, 1, 1, n, n, fracture);
    } else {
        double origin[3] = {0, 0, 0}, size[3] = {1, 1, 1};
        int div[3] = {n, n, n};
        fdem_tet_mesh mesh = {0};
        if (fdem_tet_mesh_box(origin, size, div, &mesh, &err)) build_die("box mesh", &err);
        int p = fdem_add_part_3d(m, &mesh, mat, fracture, &err);
        fdem_tet_mesh_free(&mesh);
        if (p < 0) build_die("box part", &err);
    }
    build_finalize(m, 0.5);
    for (int i = 0; i < m->node_count; i++)
        m->vel[(size_t)k->dim * i] = 1e-4 * m->pos0[(size_t)k->dim * i + 1];
    return m;
}

static void bench_fracturing_block(const fracture_kind *k, double bandwidth_gbs)
{
    printf("\n## %s\n", k->title);
    printf("%10s %8s %7s %8s %14s %10s %13s %7s %9s %9s %9s %12s %10s %9s\n", "elements",
           "joints", "j/elem", "steps", "ns/elem-step", "cpu ns", "no-frac cpu", "x cpu",
           "forces%", "contact%", "integr%", "bytes/elem", "bound ns", "pairs/el");
    char goal[256] = "";
    for (int s = 0; s < 3 && k->sizes[s]; s++) {
        double ns[2] = {0, 0}, cpu[2] = {0, 0};
        int steps = 0;
        fdem_stage_times before = {0};
        fdem_model *keep = NULL;
        for (int fracture = 0; fracture < 2; fracture++) {
            fdem_model *m = vibrating_block(k, k->sizes[s], fracture);
            fdem_error err;
            for (int w = 0; w < 3; w++) fdem_step(m, &err);
            if (fracture) before = fdem_get_stage_times(m);
            steps = (int)(2e7 / m->elem_count);
            if (steps < 10) steps = 10;
            /* best of three, as the other tables (one run of the 1e5 block
             * read 65 to 74 ns within minutes) */
            step_time t = best_of_three(m, steps);
            ns[fracture] = t.wall;
            cpu[fracture] = t.cpu;
            if (fracture) keep = m;
            else fdem_model_destroy(m);
        }
        fdem_model *m = keep;
        fdem_stage_times t = fdem_get_stage_times(m);
        t.elements += t.joints - before.elements - before.joints;
        t.detection -= before.detection;
        t.contact -= before.contact;
        t.integration -= before.integration;
        double sum = t.elements + t.detection + t.contact + t.integration;
        fdem_counts c = fdem_get_counts(m);
        /* per element-step once the mesh is larger than cache: the element
         * record, D + 1 private nodes' position, velocity and force (force
         * written twice: elements, joints; 8 D x 4), inverse mass and dof
         * flag (9), and the joints of 2 D node ids + damage + size + k */
        double D = k->dim, joints = (double)c.joints / c.elements;
        double bytes = k->record_bytes + (D + 1) * (8 * D * 4 + 9) + joints * (8 * D + 24);
        printf("%10d %8d %7.2f %8d %14.1f %10.1f %13.1f %7.2f %9.1f %9.1f %9.1f %12.0f %10.1f "
               "%9.2f\n", c.elements, c.joints, joints, steps, ns[1], cpu[1], cpu[0],
               cpu[1] / cpu[0], 100 * t.elements / sum,
               100 * (t.contact + t.detection) / sum, 100 * t.integration / sum,
               (double)fdem_memory_bytes(m) / c.elements, bytes / bandwidth_gbs,
               (double)c.contact_pairs / c.elements);
        CHECK_BROKEN(c.broken_joints);
        if (k->dim == 3) {
            double elastic = elastic_block_3d_cpu(c.elements);
            snprintf(goal + strlen(goal), sizeof goal - strlen(goal), "%s %d: %.1f / %.1f = %.2fx",
                     s ? ";" : "", c.elements, cpu[1], elastic, cpu[1] / elastic);
        }
        fdem_model_destroy(m);
    }
    if (k->dim == 3)
        printf("goal: within 4x the elastic block 3D of as many tetrahedra (CPU ns, best of 3):%s\n",
               goal);
}

/* Every joint of m broken where it stands: damage 1, so the joint loop
 * skips it, and a detection due, so the contact stage takes the pairs the
 * joints held apart (joint_contact_excluded) from the next step on. The
 * state a block reaches once it has split everywhere, without the minutes
 * of loading that would take. */
static void break_every_joint(fdem_model *m)
{
    for (int j = 0; j < m->joint_count; j++) m->joint_damage[j] = 1;
    m->broken_joints = m->joint_count;
    m->contact.need_detect = 1;
}

/* The fracturing block after fracture against the same block intact, CPU
 * ns per element-step (best of three replays of the same window), with the
 * split over the stages (elements, joints, detection, contact) and what
 * drives the cost: candidate pairs kept, near pairs walked and pairs
 * touching per element, detections per 1000 steps; then the candidate
 * pairs by what their elements share (pair_kinds.h: the two sides of a
 * broken joint, an edge, a corner, nothing) with the pair kernel's time on
 * each kind (every pair of it once, ns per element) and the share of it
 * touching. The window's first step rebuilds the near list a restore left
 * stale (and evaluates every pair within reach once more, its clearance
 * gone with the list), which a run pays after each detection or break,
 * not every 49 steps: "1st-step" is that step (CPU ns per element), "rest"
 * the window's other steps, beside the window as a whole (the goal's
 * figure). */
static void bench_broken_block(const fracture_kind *k, double goal, double work)
{
    printf("\n## %s, every joint broken in place (after fracture)\n", k->title);
    printf("%10s %7s %10s %10s %7s %7s %7s %8s %9s %8s %8s %8s %9s %9s %10s %9s %7s\n",
           "elements", "steps", "broken ns", "intact ns", "x", "elem%", "joint%", "detect%",
           "contact%", "integr%", "pairs/el", "near/el", "touch/el", "det/1000", "1st-step", "rest ns",
           "rest x");
    char line[256] = "";
    for (int s = 0; s < 2 && k->sizes[s]; s++) {
        fdem_error err;
        fdem_model *intact = vibrating_block(k, k->sizes[s], 1);
        for (int w = 0; w < 3; w++) fdem_step(intact, &err);
        /* work: element-steps a window; broken 3D rock costs about a
         * microsecond an element-step, so its windows are shorter (and
         * the first step of each rebuilds the near list a restore left
         * stale: 19-step windows read 1,222 ns where 200 steps ran at
         * ~900) */
        int E = intact->elem_count, steps = (int)(work / E);
        if (steps < 5) steps = 5;
        double intact_cpu = best_of_three(intact, steps).cpu;
        fdem_model_destroy(intact);

        fdem_model *m = vibrating_block(k, k->sizes[s], 1);
        break_every_joint(m);
        for (int w = 0; w < 3; w++) fdem_step(m, &err);
        fdem_stage_times before = fdem_get_stage_times(m);
        long det0 = fdem_get_counts(m).detections;
        split_time split = best_of_three_split(m, steps);
        step_time t = split.whole;
        fdem_stage_times after = fdem_get_stage_times(m);
        fdem_counts c = fdem_get_counts(m);
        double fe = after.elements - before.elements, jo = after.joints - before.joints;
        double de = after.detection - before.detection;
        double co = after.contact - before.contact, in = after.integration - before.integration;
        double sum = fe + jo + de + co + in;
        /* three replays of the window ran: a third of the detections each */
        double det = (double)(c.detections - det0) / 3 * 1000 / steps;
        printf("%10d %7d %10.1f %10.1f %7.2f %7.1f %7.1f %8.1f %9.1f %8.1f %8.2f %8.2f %9.3f "
               "%9.1f %10.1f %9.1f %7.2f\n", E, steps, t.cpu, intact_cpu, t.cpu / intact_cpu,
               100 * fe / sum, 100 * jo / sum, 100 * de / sum, 100 * co / sum, 100 * in / sum,
               (double)c.contact_pairs / E, (double)(m->contact.near_count + m->contact.near_vertex_count) / E,
               (double)c.contacts / E, det, split.first_cpu, split.rest_cpu,
               split.rest_cpu / intact_cpu);
        double count[PAIR_KINDS], seconds[PAIR_KINDS], touching[PAIR_KINDS];
        pair_kind_counts(m, count);
        pair_kind_kernel(m, seconds, touching);
        printf("%10s pairs by kind (per element; kernel ns per element over them once; "
               "touching %%):", "");
        for (int kind = PAIR_KINDS - 1; kind >= 0; kind--)
            printf(" %s %.2f / %.0f ns / %.0f%%", pair_kind_name[kind], count[kind] / E,
                   seconds[kind] * 1e9 / E, count[kind] ? 100 * touching[kind] / count[kind] : 0);
        printf("\n");
        snprintf(line + strlen(line), sizeof line - strlen(line), "%s %d: %.2fx", s ? ";" : "", E,
                 t.cpu / intact_cpu);
        fdem_model_destroy(m);
    }
    printf("goal: after fracture within %.0fx the intact fracturing block (CPU ns):%s\n", goal,
           line);
}

/* One model on 1 thread and its twin (built and stepped alike, so their
 * states are the same bits) on `cores`: ns per element-step, the best of
 * three runs each, every run the same steps from the same checkpoint
 * (window_start), the runs interleaved. Two models, not one switched
 * between thread counts: a change of count re-cuts the joint sweep in the
 * first step after it, which would be timed. Destroys both. */
static void thread_row(const char *name, fdem_model *one, fdem_model *many, int colours,
                       int cores, double work)
{
    int steps = (int)(work / one->elem_count);
    if (steps < 10) steps = 10;
    fdem_error err;
    fdem_set_threads(one, 1);
    fdem_set_threads(many, cores);
    for (int s = 0; s < 3; s++) {
        fdem_step(one, &err);
        fdem_step(many, &err);
    }
    window_start w = window_mark(one);
    double best_one = INFINITY, best_many = INFINITY;
    for (int rep = 0; rep < 3; rep++) {
        window_rewind(one, &w);
        window_rewind(many, &w);
        best_one = fmin(best_one, timed_steps(one, steps).wall);
        best_many = fmin(best_many, timed_steps(many, steps).wall);
    }
    free(w.state);
    double scale = 1e9 / ((double)steps * one->elem_count);
    printf("%-28s %10d %8d %12.1f %12.1f %9.2f\n", name, one->elem_count, colours,
           best_one * scale, best_many * scale, best_one / best_many);
    fdem_model_destroy(one);
    fdem_model_destroy(many);
}

/* Steps a model `steps` steps (into contact) and returns it. */
static fdem_model *stepped(fdem_model *m, int steps)
{
    fdem_error err;
    for (int s = 0; s < steps; s++) fdem_step(m, &err);
    return m;
}

/* After fracture (issue 34: 2 threads >= 1.7x one): the block of
 * bench_broken_block, every joint broken in place; 1e5 triangles, 1e4
 * tetrahedra. */
static void broken_thread_row(int dim, int cores)
{
    const fracture_kind *k = dim == 3 ? &FRACTURE_3D_UNDAMPED : &FRACTURE_2D;
    int n = k->sizes[dim == 3 ? 0 : 1];
    fdem_model *one = vibrating_block(k, n, 1), *many = vibrating_block(k, n, 1);
    break_every_joint(one);
    break_every_joint(many);
    thread_row(dim == 3 ? "broken block 3D (contact)" : "broken block 2D (contact)", one, many,
               one->elem_plan.color_count, cores, dim == 3 ? 2e6 : 5e6);
}

static void bench_threads(int rows_2d, int rows_3d)
{
    int cores = (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (cores < 2) cores = 2;
    printf("\n## Threads: the same models on 1 and %d threads (results are bit-identical)\n", cores);
    printf("%-28s %10s %8s %12s %12s %9s\n", "model", "elements", "colours", "1 thread ns",
           "threads ns", "speed-up");
    for (int fracture = 0; fracture < 2 && rows_2d; fracture++)
        for (int k = 0; k < 2; k++) {
            fdem_model *one = vibrating_block(&FRACTURE_2D, k ? 707 : 224, fracture);
            fdem_model *many = vibrating_block(&FRACTURE_2D, k ? 707 : 224, fracture);
            thread_row(fracture ? "fracturing block (joints)" : "elastic block (shared nodes)", one,
                       many, one->elem_plan.color_count, cores, 1e7);
        }
    int dims[][2] = {{20, 20}, {60, 60}};
    for (int k = 0; k < 2 && rows_2d; k++) { /* into contact, as above */
        fdem_model *one = stepped(build_disc_pile(dims[k][0], dims[k][1]), 300);
        fdem_model *many = stepped(build_disc_pile(dims[k][0], dims[k][1]), 300);
        thread_row("disc pile (contact)", one, many, one->elem_plan.color_count, cores, 5e6);
    }
    if (rows_2d) broken_thread_row(2, cores);
    long sizes_3d[] = {100000, 1000000};
    for (int k = 0; k < 2 && rows_3d; k++) {
        fdem_model *one = elastic_block(&BLOCK_3D, sizes_3d[k]);
        fdem_model *many = elastic_block(&BLOCK_3D, sizes_3d[k]);
        thread_row("elastic block 3D (tets)", one, many, one->elem_plan.color_count, cores, 1e7);
    }
    if (!rows_3d) return;
    fdem_model *one = vibrating_block(&FRACTURE_3D, FRACTURE_3D.sizes[1], 1);
    fdem_model *many = vibrating_block(&FRACTURE_3D, FRACTURE_3D.sizes[1], 1);
    thread_row("fracturing block 3D (joints)", one, many, one->elem_plan.color_count, cores, 1e7);
    one = stepped(sphere_pile(6, 6, 4), 400); /* into contact, as above */
    many = stepped(sphere_pile(6, 6, 4), 400);
    thread_row("sphere pile 3D (contact)", one, many, one->elem_plan.color_count, cores, 5e6);
    broken_thread_row(3, cores);
}

/* The fracturing block of n cells a side (unit square) with water-like
 * fluid (K_f scaled down to 1e8 Pa, the practice of hydraulic-fracturing
 * FDEM codes, so the fluid's stiffness leaves the step of the rock), fed
 * at its centre node. */
static fdem_model *fed_block(int n, double inject)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    fdem_material_def rock = {.density = 2500, .young = 1e10, .poisson = 0.2, .damping = 0.1,
                              .has_fracture = 1};
    rock.fracture = (fdem_fracture_params){.tensile_strength = 1e6, .cohesion = 3e6,
                                           .friction_angle = 30, .energy_I = 20,
                                           .energy_II = 100, .aperture0 = 1e-4};
    int mat = fdem_add_material(m, &rock, &err);
    if (mat < 0) build_die("material", &err);
    build_rectangle_part(m, mat, -0.5, -0.5, 1, 1, n, n, 1);
    fdem_fluid_def water = {.viscosity = 1e-3, .bulk_modulus = 1e8, .density = 1000};
    if (fdem_set_fluid(m, &water, &err)) build_die("fluid", &err);
    const double e = 1e-9;
    fdem_constraint_def feed = {.select = FDEM_SELECT_BOX, .box = {-e, -e, e, e},
                                .kind = FDEM_CONSTRAINT_INJECT, .value = {inject}};
    if (fdem_add_constraint(m, &feed, &err) < 0) build_die("inject", &err);
    build_finalize(m, 0.5);
    return m;
}

static void bench_hydraulic_fracture(void)
{
    printf("\n## Hydraulic fracturing (2D fracturing block fed at its centre, issue 36)\n");
    printf("%10s %8s %8s %8s %10s %14s %14s %9s\n", "elements", "joints", "open", "broken",
           "subcycles", "ns/elem-step", "no-flow ns", "flow %");
    const int sizes[] = {100, 224};
    for (int s = 0; s < 2; s++) {
        fdem_model *m = fed_block(sizes[s], 2e-2);
        fdem_error err;
        /* until some joints broke and the network holds the fluid, or long enough */
        for (int k = 0; k < 3000 && fdem_get_counts(m).broken_joints < 20; k++)
            if (fdem_step(m, &err)) build_die("step", &err);
        int steps = (int)(1e7 / m->elem_count);
        if (steps < 10) steps = 10;
        step_time with = best_of_three(m, steps);
        struct fluid_net *keep = m->fluid;
        m->fluid = NULL; /* the same state, stepped without the flow */
        step_time without = best_of_three(m, steps);
        m->fluid = keep;
        fdem_counts c = fdem_get_counts(m);
        fdem_fluid_status f = fdem_get_fluid(m);
        printf("%10d %8d %8d %8d %10d %14.1f %14.1f %9.1f\n", c.elements, c.joints, f.open_joints,
               c.broken_joints, f.subcycles, with.cpu, without.cpu,
               100 * (1 - without.cpu / with.cpu));
        fdem_model_destroy(m);
    }
}

/* With no argument every section runs; otherwise only those named
 * (block, block3d, pile, pile3d, fracture, fracture3d, broken, broken3d, hydraulic, threads,
 * threads3d),
 * to iterate on one kernel. */
static int wanted(int argc, char **argv, const char *name)
{
    if (argc < 2) return 1;
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], name) == 0) return 1;
    return 0;
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* a bench cut short still shows its rows */
    double bw = stream_bandwidth_gbs();
    printf("# fdemd engine bench (single core)\nsingle-core triad bandwidth: %.1f GB/s\n", bw);
    if (wanted(argc, argv, "block")) bench_elastic_block(&BLOCK_2D, bw);
    if (wanted(argc, argv, "block3d")) bench_elastic_block(&BLOCK_3D, bw);
    if (wanted(argc, argv, "pile3d")) bench_sphere_pile();
    if (wanted(argc, argv, "pile")) bench_disc_pile();
    if (wanted(argc, argv, "fracture")) bench_fracturing_block(&FRACTURE_2D, bw);
    if (wanted(argc, argv, "fracture3d")) {
        bench_fracturing_block(&FRACTURE_3D, bw);
        bench_fracturing_block(&FRACTURE_3D_UNDAMPED, bw);
    }
    if (wanted(argc, argv, "broken")) bench_broken_block(&FRACTURE_2D, 3, 5e6);
    if (wanted(argc, argv, "broken3d")) bench_broken_block(&FRACTURE_3D_UNDAMPED, 4, 1e6);
    if (wanted(argc, argv, "hydraulic")) bench_hydraulic_fracture();
    if (wanted(argc, argv, "threads") || wanted(argc, argv, "threads3d"))
        bench_threads(wanted(argc, argv, "threads"), wanted(argc, argv, "threads3d"));
    return 0;
}
