/*
 * test_contact_3d.c - contact between tetrahedral bodies through the public
 * API, against physics: two boxes colliding head-on and obliquely conserve
 * linear momentum (to 1e-12) and energy (kinetic + elastic + contact
 * [+ friction] to 5 %); a box on a slab with gravity tilted 30 degrees
 * slides at g (sin 30 - mu cos 30) (to 5 %) with mu = 0.3, and with
 * mu = 0.7 > tan 30 stays put; a pile of spheres dropped into a box of
 * fixed slabs settles with no sphere through another; two threads give the
 * bits of one; a checkpoint holding stick springs restores to the same bits.
 */
#include "check.h"
#include "fdem.h"
#include "mesh_3d.h"
#include "model.h"

#include <stdint.h>
#include <stdlib.h>

/* penalty 0: the default, 10 x young. */
static fdem_material_def solid(double density, double young, double damping, double friction,
                               double penalty)
{
    fdem_material_def d = {0};
    d.density = density;
    d.young = young;
    d.penalty = penalty;
    d.poisson = 0.25;
    d.damping = damping;
    d.friction = friction;
    return d;
}

/* A 3D model to add parts to. */
static fdem_model *model_3d(void)
{
    fdem_error err = {0};
    fdem_model *m = fdem_model_create();
    if (m && fdem_set_dimension(m, 3, &err) == 0) return m;
    fdem_model_destroy(m);
    return NULL;
}

/* Appends a tetrahedral mesh as a part; its nodes are [*first, *end). */
static int add_mesh(fdem_model *m, fdem_tet_mesh *mesh, int mat, int *first, int *end)
{
    fdem_error err = {0};
    int begin = fdem_get_counts(m).nodes;
    int index = fdem_add_part_3d(m, mesh, mat, 0, &err);
    fdem_tet_mesh_free(mesh);
    CHECK(index >= 0, "%s", err.message);
    if (first) *first = begin;
    if (end) *end = fdem_get_counts(m).nodes;
    return index;
}

static int add_box(fdem_model *m, int mat, const double origin[3], const double size[3],
                   const int div[3], int *first, int *end)
{
    fdem_error err = {0};
    fdem_tet_mesh mesh = {0};
    CHECK(fdem_tet_mesh_box(origin, size, div, &mesh, &err) == 0, "%s", err.message);
    return add_mesh(m, &mesh, mat, first, end);
}

static int add_sphere(fdem_model *m, int mat, const double centre[3], double radius,
                      int divisions, int *first, int *end)
{
    fdem_error err = {0};
    fdem_tet_mesh mesh = {0};
    CHECK(fdem_tet_mesh_sphere(centre, radius, divisions, &mesh, &err) == 0, "%s", err.message);
    return add_mesh(m, &mesh, mat, first, end);
}

static void fix_part(fdem_model *m, int index)
{
    fdem_error err = {0};
    fdem_constraint_def fix = {0};
    fix.select = FDEM_SELECT_PART;
    fix.part = index;
    fix.kind = FDEM_CONSTRAINT_FIX;
    fix.fix_x = fix.fix_y = fix.fix_z = 1;
    CHECK(fdem_add_constraint(m, &fix, &err) >= 0, "%s", err.message);
}

/* Finalizes and sets the step to safety x the stable step. */
static int finalize(fdem_model *m, double safety)
{
    fdem_error err = {0};
    if (fdem_model_finalize(m, &err)) {
        CHECK(0, "finalize: %s", err.message);
        return -1;
    }
    fdem_set_dt(m, safety * fdem_stable_dt(m));
    return 0;
}

static int step(fdem_model *m)
{
    fdem_error err = {0};
    if (fdem_step(m, &err) == 0) return 0;
    CHECK(0, "step failed: %s", err.message);
    return -1;
}

static int run_until(fdem_model *m, double t_end)
{
    while (fdem_get_time(m) < t_end)
        if (step(m)) return -1;
    return 0;
}

/* Mass-weighted centre and velocity of nodes [first, end). */
static void nodes_centre(const fdem_model *m, int first, int end, double c[3], double v[3])
{
    const double *x = fdem_positions(m), *u = fdem_velocities(m), *mass = fdem_node_masses(m);
    double total = 0;
    for (int d = 0; d < 3; d++) c[d] = v ? (v[d] = 0) : 0;
    for (int i = first; i < end; i++) {
        total += mass[i];
        for (int d = 0; d < 3; d++) {
            c[d] += mass[i] * x[3 * i + d];
            if (v) v[d] += mass[i] * u[3 * i + d];
        }
    }
    for (int d = 0; d < 3; d++) {
        c[d] /= total;
        if (v) v[d] /= total;
    }
}

/* Total momentum, and sum of m |v| as its scale. */
static void momentum(const fdem_model *m, double p[3], double *scale)
{
    const double *v = fdem_velocities(m), *mass = fdem_node_masses(m);
    p[0] = p[1] = p[2] = 0;
    *scale = 0;
    for (int i = 0; i < fdem_get_counts(m).nodes; i++) {
        for (int d = 0; d < 3; d++) p[d] += mass[i] * v[3 * i + d];
        *scale += mass[i] * sqrt(v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] +
                                 v[3 * i + 2] * v[3 * i + 2]);
    }
}

/* Two undamped boxes, 0.1 m cubes of 3 x 3 x 3 cells, the first moving at
 * velocity v toward the second (0.2 mm away, offset by `offset` across the
 * impact direction), run until they have parted: momentum is kept to
 * round-off, kinetic + elastic + contact + friction to 5 %, and, with the
 * contact springs empty again, kinetic + elastic + friction to 5 %. */
static void boxes_collide(const double v[3], const double offset[2], double mu, const char *name)
{
    fdem_model *m = model_3d();
    fdem_material_def rock = solid(2700, 1e9, 0, mu, 0);
    fdem_error err = {0};
    int mat = fdem_add_material(m, &rock, &err);
    const double size[3] = {0.1, 0.1, 0.1}, o1[3] = {0, 0, 0};
    const double o2[3] = {0.1002, offset[0], offset[1]};
    const int div[3] = {3, 3, 3};
    int a0, a1, b0, b1;
    int a = add_box(m, mat, o1, size, div, &a0, &a1);
    add_box(m, mat, o2, size, div, &b0, &b1);
    CHECK(fdem_set_part_velocity_v(m, a, v, &err) == 0, "%s", err.message);
    if (finalize(m, 0.5)) return;
    double p0[3], s0, p[3], s, c[3], va[3], vb[3];
    momentum(m, p0, &s0);
    double e0 = fdem_get_energy(m).kinetic;
    int touched = 0;
    while (fdem_get_time(m) < 0.01) {
        if (step(m)) break;
        int contacts = fdem_get_counts(m).contacts;
        touched |= contacts > 0;
        nodes_centre(m, a0, a1, c, va);
        nodes_centre(m, b0, b1, c, vb);
        if (touched && !contacts && vb[0] > va[0]) break;
    }
    CHECK(touched, "%s: the boxes never touched", name);
    CHECK(vb[0] > va[0], "%s: still approaching: %g %g", name, va[0], vb[0]);
    momentum(m, p, &s);
    double worst = 0;
    for (int d = 0; d < 3; d++) worst = fmax(worst, fabs(p[d] - p0[d]) / s0);
    CHECK(worst <= 1e-12, "%s: momentum changed by %.3g of sum m|v|", name, worst);
    fdem_energy en = fdem_get_energy(m);
    double total = en.kinetic + en.elastic + en.contact + en.friction;
    CHECK_REL(total, e0, 0.05);
    /* parted, the penalty springs hold nothing: what contact gave or took
     * is the discretisation's error */
    CHECK_REL(en.kinetic + en.elastic + en.friction, e0, 0.05);
    fprintf(stderr, "  %s: momentum error %.2g, energy %.4f of the initial (kinetic %.3f, "
            "elastic %.3f, contact %+.4f, friction %.3f), %lld steps\n", name, worst, total / e0,
            en.kinetic / e0, en.elastic / e0, en.contact / e0, en.friction / e0,
            (long long)fdem_get_step(m));
    fdem_model_destroy(m);
}

static void boxes_colliding_conserve_momentum_and_energy(void)
{
    const double head_on[3] = {2, 0, 0}, centred[2] = {0, 0};
    boxes_collide(head_on, centred, 0, "head-on");
    const double oblique[3] = {2, 0.5, -0.3}, shifted[2] = {0.04, -0.03};
    boxes_collide(oblique, shifted, 0.3, "oblique, mu 0.3");
}

/* A 0.2 x 0.2 x 0.1 box of 2 x 2 x 1 cells resting on a fixed slab of
 * 0.1 m cells, gravity tilted by theta about y. The box is damped so its
 * settling on the slab does not ring. The penalty is the Young modulus, not
 * ten times it: under a load this light the overlap stays below 1e-5 of
 * the box either way, and the step is three times longer. Returns the
 * slide along x of the box's centre from t_settled to t_end; *settling gets
 * the slide before t_settled, *time the time between. */
static double slab_slide(double theta_deg, double mu, double t_settled, double t_end,
                         double *settling, double *time)
{
    double th = theta_deg * M_PI / 180, g = 9.81;
    fdem_model *m = model_3d();
    fdem_material_def slab_def = solid(1000, 1e7, 0, mu, 1e7);
    fdem_material_def box_def = solid(1000, 1e7, 0.2, mu, 1e7);
    fdem_error err = {0};
    int slab_mat = fdem_add_material(m, &slab_def, &err);
    int box_mat = fdem_add_material(m, &box_def, &err);
    const double slab_origin[3] = {0, -0.15, -0.1}, slab_dims[3] = {0.4, 0.3, 0.1};
    const int slab_div[3] = {4, 3, 1};
    const double box_origin[3] = {0.05, -0.1, 0}, box_dims[3] = {0.2, 0.2, 0.1};
    const int box_div[3] = {2, 2, 1};
    int slab = add_box(m, slab_mat, slab_origin, slab_dims, slab_div, NULL, NULL);
    int first, end;
    add_box(m, box_mat, box_origin, box_dims, box_div, &first, &end);
    fix_part(m, slab);
    const double gv[3] = {g * sin(th), 0, -g * cos(th)};
    fdem_set_gravity_v(m, gv);
    double c0[3], c[3];
    if (finalize(m, 0.5)) return NAN;
    nodes_centre(m, first, end, c0, NULL);
    run_until(m, t_settled);
    nodes_centre(m, first, end, c, NULL);
    *settling = c[0] - c0[0];
    double t0 = fdem_get_time(m);
    run_until(m, t_end);
    nodes_centre(m, first, end, c0, NULL);
    *time = fdem_get_time(m) - t0;
    fdem_model_destroy(m);
    return c0[0] - c[0];
}

/* Above its friction angle the box slides at g (sin 30 - mu cos 30). */
static void box_slides_down_tilted_slab_with_friction(void)
{
    double t, settling, th = M_PI / 6, mu = 0.3;
    double slide = slab_slide(30, mu, 0, 0.12, &settling, &t);
    double want = 9.81 * (sin(th) - mu * cos(th)), got = 2 * slide / (t * t);
    CHECK_REL(got, want, 0.05);
    fprintf(stderr, "  slab 30 deg, mu 0.3: acceleration %.5g m/s^2, g (sin - mu cos) %.5g "
            "(%+.2f%%), slid %.4g m in %.3g s\n", got, want, 100 * (got - want) / want, slide, t);
}

/* Below it (mu 0.7 > tan 30 = 0.577) the stick springs hold the box. Let
 * go touching the slab, it carries no normal force at first and slips a
 * little while it settles (tens of micrometres: the box's own shear under
 * the 490 Pa of m g sin 30 over its base is 6 um at the centre); then it
 * must not creep: less than 0.1 um over the next 0.25 s, in which it would
 * slide 0.15 m free. */
static void box_sticks_on_slab_below_friction_angle(void)
{
    double t, settling;
    double slide = slab_slide(30, 0.7, 0.05, 0.3, &settling, &t);
    CHECK(fabs(settling) < 5e-5, "slipped %g m while settling", settling);
    CHECK(fabs(slide) < 1e-7, "crept %g m in %g s", slide, t);
    fprintf(stderr, "  slab 30 deg, mu 0.7: moved %.3g m while settling, then %.3g m in %.3g s\n",
            settling, slide, t);
}

/* Five slabs (a floor and four walls) as one fixed part, so that they do
 * not contact each other: one mesh of five pieces. */
static void add_container(fdem_model *m, int mat, double W, double H, double T)
{
    const double slabs[5][2][3] = {
        {{-T, -T, -T}, {W + 2 * T, W + 2 * T, T}}, /* floor */
        {{-T, 0, 0}, {T, W, H}},                   /* walls */
        {{W, 0, 0}, {T, W, H}},
        {{-T, -T, 0}, {W + 2 * T, T, H}},
        {{-T, W, 0}, {W + 2 * T, T, H}},
    };
    fdem_tet_mesh all = {0};
    fdem_error err = {0};
    for (int k = 0; k < 5; k++) {
        int div[3];
        for (int d = 0; d < 3; d++) div[d] = (int)fmax(1, lround(slabs[k][1][d] / 0.08));
        fdem_tet_mesh one = {0};
        CHECK(fdem_tet_mesh_box(slabs[k][0], slabs[k][1], div, &one, &err) == 0, "%s", err.message);
        double *xyz = realloc(all.xyz, sizeof(double) * 3 * (size_t)(all.node_count + one.node_count));
        if (xyz) all.xyz = xyz;
        int32_t *tet = realloc(all.tet, sizeof(int32_t) * 4 * (size_t)(all.tet_count + one.tet_count));
        if (tet) all.tet = tet;
        if (!xyz || !tet) {
            CHECK(0, "out of memory");
            fdem_tet_mesh_free(&one);
            fdem_tet_mesh_free(&all);
            return;
        }
        memcpy(all.xyz + 3 * all.node_count, one.xyz, sizeof(double) * 3 * (size_t)one.node_count);
        for (int i = 0; i < 4 * one.tet_count; i++)
            all.tet[4 * all.tet_count + i] = one.tet[i] + all.node_count;
        all.node_count += one.node_count;
        all.tet_count += one.tet_count;
        fdem_tet_mesh_free(&one);
    }
    fix_part(m, add_mesh(m, &all, mat, NULL, NULL));
}

/* Eight spheres of radius 0.05 (two layers of four, slightly jittered)
 * dropped into a box of fixed slabs: after 0.5 s their kinetic energy is
 * below 5 % of gravity's work, no two centres are closer than 0.9 x 2R
 * (the coarse spheres are polyhedra whose faces lie at 0.87 R and beyond)
 * and no node of one sphere lies deeper than 0.2 R inside another. Soft
 * (E = p = 1 MPa) for long steps: a sphere landing at 1.5 m/s presses in
 * about 1 mm, 0.02 R. */
static void sphere_pile_settles_without_interpenetration(void)
{
    fdem_model *m = model_3d();
    fdem_material_def wall_def = solid(1000, 1e6, 0.1, 0.3, 1e6);
    fdem_material_def ball_def = solid(1000, 1e6, 0.3, 0.3, 1e6);
    fdem_error err = {0};
    int wall = fdem_add_material(m, &wall_def, &err);
    int ball = fdem_add_material(m, &ball_def, &err);
    const double W = 0.24;
    add_container(m, wall, W, 0.3, 0.04);
    enum { SPHERES = 8 };
    const double R = 0.05;
    int first[SPHERES], end[SPHERES];
    for (int k = 0; k < SPHERES; k++) {
        int layer = k / 4, i = k % 4;
        double c[3] = {0.062 + 0.115 * (i % 2) + 0.004 * layer, 0.062 + 0.115 * (i / 2) - 0.003 * layer,
                       R + 0.002 + layer * 0.11};
        add_sphere(m, ball, c, R, 8, &first[k], &end[k]);
    }
    const double g[3] = {0, 0, -9.81};
    fdem_set_gravity_v(m, g);
    if (finalize(m, 0.5)) return;
    run_until(m, 0.5);
    fdem_energy en = fdem_get_energy(m);
    CHECK(en.kinetic < 0.05 * en.gravity_work, "still moving: kinetic %g of gravity work %g",
          en.kinetic, en.gravity_work);
    double centre[SPHERES][3];
    for (int k = 0; k < SPHERES; k++) nodes_centre(m, first[k], end[k], centre[k], NULL);
    double closest = INFINITY, deepest = 0;
    const double *x = fdem_positions(m);
    for (int i = 0; i < SPHERES; i++)
        for (int j = 0; j < SPHERES; j++) {
            if (i == j) continue;
            double d = sqrt(pow(centre[i][0] - centre[j][0], 2) + pow(centre[i][1] - centre[j][1], 2) +
                            pow(centre[i][2] - centre[j][2], 2));
            closest = fmin(closest, d / (2 * R));
            for (int n = first[j]; n < end[j]; n++) { /* j's nodes inside i's sphere */
                double r = sqrt(pow(x[3 * n] - centre[i][0], 2) + pow(x[3 * n + 1] - centre[i][1], 2) +
                                pow(x[3 * n + 2] - centre[i][2], 2));
                deepest = fmax(deepest, (R - r) / R);
            }
        }
    CHECK(closest > 0.9, "two spheres' centres only %.3f diameters apart", closest);
    CHECK(deepest < 0.2, "a node %.3f R deep inside another sphere", deepest);
    for (int k = 0; k < SPHERES; k++)
        CHECK(centre[k][2] > 0 && centre[k][0] > 0 && centre[k][0] < W && centre[k][1] > 0 &&
                  centre[k][1] < W,
              "sphere %d left the box: %g %g %g", k, centre[k][0], centre[k][1], centre[k][2]);
    fprintf(stderr, "  pile: closest centres %.3f diameters, deepest node %.3f R, kinetic/gravity "
            "work %.2g, %lld steps, %ld detections\n", closest, deepest,
            en.kinetic / en.gravity_work, (long long)fdem_get_step(m), fdem_get_counts(m).detections);
    fdem_model_destroy(m);
}

/* A 4 x 4 x 2-cell box sliding with friction on a slab: enough candidate
 * pairs for the threaded pair loop. */
static fdem_model *sliding_box(int threads)
{
    fdem_model *m = model_3d();
    fdem_material_def slab_def = solid(1000, 1e7, 0.1, 0.4, 0);
    fdem_material_def box_def = solid(1000, 1e7, 0.1, 0.4, 0);
    fdem_error err = {0};
    int slab_mat = fdem_add_material(m, &slab_def, &err);
    int box_mat = fdem_add_material(m, &box_def, &err);
    const double slab_origin[3] = {0, 0, -0.05}, slab_dims[3] = {0.4, 0.3, 0.05};
    const int slab_div[3] = {8, 6, 1};
    const double box_origin[3] = {0.05, 0.05, 0.0}, box_dims[3] = {0.2, 0.2, 0.1};
    const int box_div[3] = {4, 4, 2};
    fix_part(m, add_box(m, slab_mat, slab_origin, slab_dims, slab_div, NULL, NULL));
    int box = add_box(m, box_mat, box_origin, box_dims, box_div, NULL, NULL);
    const double v[3] = {0.5, 0.2, -0.05}, g[3] = {2, 0, -9.81};
    CHECK(fdem_set_part_velocity_v(m, box, v, &err) == 0, "%s", err.message);
    fdem_set_gravity_v(m, g);
    fdem_set_threads(m, threads);
    if (finalize(m, 0.5)) {
        fdem_model_destroy(m);
        return NULL;
    }
    return m;
}

static int run_steps(fdem_model *m, int steps)
{
    for (int s = 0; s < steps; s++)
        if (step(m)) return -1;
    return 0;
}

static void same_bits(const fdem_model *a, const fdem_model *b, const char *what)
{
    fdem_counts c = fdem_get_counts(a);
    size_t nb = sizeof(double) * 3 * (size_t)c.nodes;
    CHECK(memcmp(fdem_positions(a), fdem_positions(b), nb) == 0, "%s: positions differ", what);
    CHECK(memcmp(fdem_velocities(a), fdem_velocities(b), nb) == 0, "%s: velocities differ", what);
    fdem_energy ea = fdem_get_energy(a), eb = fdem_get_energy(b);
    CHECK(memcmp(&ea, &eb, sizeof ea) == 0, "%s: energies differ", what);
}

static void two_threads_give_the_same_bits_with_contact(void)
{
    fdem_model *m[2] = {sliding_box(1), sliding_box(2)};
    if (!m[0] || !m[1]) return;
    for (int k = 0; k < 2; k++) run_steps(m[k], 300);
    fdem_counts c = fdem_get_counts(m[0]);
    CHECK(c.contact_pairs >= 2048, "only %d candidate pairs: the threaded loop is not run",
          c.contact_pairs);
    CHECK(c.contacts > 0, "no contact");
    CHECK(fdem_get_energy(m[0]).friction > 0, "no sliding");
    same_bits(m[0], m[1], "1 and 2 threads");
    fprintf(stderr, "  threads: %d candidate pairs, %d touching\n", c.contact_pairs, c.contacts);
    fdem_model_destroy(m[0]);
    fdem_model_destroy(m[1]);
}

/* Pairs holding stick springs in a model (engine internals). */
static long sprung_pairs(const fdem_model *m)
{
    long n = 0;
    for (size_t k = 0; k < m->contact.pairs.count; k++) n += m->contact.sprung[k];
    return n;
}

static void restored_model_steps_on_to_the_same_bits_with_springs(void)
{
    fdem_model *a = sliding_box(1), *b = sliding_box(1);
    if (!a || !b) return;
    run_steps(a, 300);
    CHECK(sprung_pairs(a) > 0, "no stick spring held at the checkpoint");
    size_t size = fdem_checkpoint_size(a);
    void *buf = malloc(size);
    fdem_error err = {0};
    CHECK(fdem_checkpoint_write(a, buf, size) == 0, "write");
    CHECK(fdem_checkpoint_read(b, buf, size, &err) == 0, "%s", err.message);
    free(buf);
    CHECK(sprung_pairs(b) == sprung_pairs(a), "springs %ld restored of %ld", sprung_pairs(b),
          sprung_pairs(a));
    run_steps(a, 300);
    run_steps(b, 300);
    same_bits(a, b, "restored");
    fdem_model_destroy(a);
    fdem_model_destroy(b);
}

CHECK_MAIN(T(boxes_colliding_conserve_momentum_and_energy),
           T(box_slides_down_tilted_slab_with_friction),
           T(box_sticks_on_slab_below_friction_angle),
           T(sphere_pile_settles_without_interpenetration),
           T(two_threads_give_the_same_bits_with_contact),
           T(restored_model_steps_on_to_the_same_bits_with_springs))
