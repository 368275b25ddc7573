/*
 * test_joint_prestress.c - fracturing parts under in-situ stress start in
 * equilibrium (contract 6.1, PHYSICS "Excavation under in-situ stress"),
 * each test in 2D and 3D:
 *  - a jointed block under a uniform in-situ stress, held by nothing but
 *    the matching boundary pressures, stays at rest as the continuous block
 *    does: kinetic energy below 1e-6 of the stored energy, no joint
 *    damaged, every element's stress within 1 %; its joints hold the
 *    stress's energy from t = 0 and the energy account closes;
 *  - the same with a stress that grows with depth as gravity asks (rollers
 *    at the sides and the base), and with a graded, sheared stress held by
 *    the matching boundary stress all round, at rest to round-off;
 *  - the strength test sees the in-situ traction: a tension 10 % above the
 *    tensile strength breaks the joints across it in tension within the
 *    first steps, 10 % below it breaks none;
 *  - one thread and two, and a run through a checkpoint, give the same bits.
 * Without the joints' in-situ gaps (measured by switching them off) the
 * jointed block's kinetic energy peaked at 0.37 (2D) and 0.999 (3D) of
 * its stored energy with the stresses 10 % and 19 % off, the column's at
 * 0.13 and 0.18 with 10 % and 39 %, and the tension damaged no joint at
 * the first step.
 */
#include <stdlib.h>

#include "build_model.h"
#include "check.h"
#include "model/model.h"
#include "element/element.h"
#include "stress_watch.h"

/* build_fracturing_rock's elastic constants and strengths */
#define RHO 2700.0
#define YOUNG 3e10
#define NU 0.25
#define TENSILE 1e6

static double wave_speed(void)
{
    return sqrt(YOUNG * (1 - NU) / ((1 + NU) * (1 - 2 * NU)) / RHO);
}

static fdem_model *jointed_block(int dim, const double size[3], const int div[3], int *part_out,
                                 double damping)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_fracturing_rock(m, damping);
    *part_out = build_box_part(m, mat, dim, size, div, 1);
    return m;
}

static void set_stress(fdem_model *m, int p, const double *value, const double *gradient,
                       double reference)
{
    fdem_error err;
    if (fdem_set_part_initial_stress(m, p, value, gradient, reference, &err))
        build_die("initial stress", &err);
}

/* A constraint of `kind` on the block's face at coordinate `at` of `axis`. */
static int add_face(fdem_model *m, const double size[3], int axis, double at,
                    fdem_constraint_kind kind, double pressure)
{
    const int D = m->dim;
    fdem_constraint_def c = {0};
    c.select = FDEM_SELECT_BOX;
    for (int d = 0; d < D; d++) {
        c.box[d] = d == axis ? at - 1e-6 : -1e-6;
        c.box[D + d] = d == axis ? at + 1e-6 : size[d] + 1e-6;
    }
    c.kind = kind;
    c.value[0] = pressure;
    c.fix_x = axis == 0;
    c.fix_y = axis == 1;
    c.fix_z = axis == 2;
    fdem_error err;
    int k = fdem_add_constraint(m, &c, &err);
    if (k < 0) build_die("constraint", &err);
    return k;
}


static double largest_damage(const fdem_model *m)
{
    double worst = 0;
    const double *D = fdem_joint_damage(m);
    for (int j = 0; j < fdem_get_counts(m).joints; j++) worst = fmax(worst, D[j]);
    return worst;
}


static const double UNIFORM2[3] = {-10e6, -6e6, 0}, UNIFORM3[6] = {-10e6, -6e6, -8e6, 0, 0, 0};

/* A jointed 2 x 1.5 (x 1) m block under the uniform stress, held by the
 * pressures it asks for: p = -sigma_aa on both faces normal to axis a. */
static fdem_model *pressed_block(int dim, const double size[3])
{
    const int div[3] = {8, 6, 4};
    int p;
    fdem_model *m = jointed_block(dim, size, div, &p, 0);
    const double *value = dim == 2 ? UNIFORM2 : UNIFORM3;
    set_stress(m, p, value, NULL, 0);
    for (int a = 0; a < dim; a++) {
        add_face(m, size, a, 0, FDEM_CONSTRAINT_PRESSURE, -value[a]);
        add_face(m, size, a, size[a], FDEM_CONSTRAINT_PRESSURE, -value[a]);
    }
    build_finalize(m, 0.5);
    return m;
}

static void jointed_block_under_pressures_stays_still(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {2, 1.5, 1};
        fdem_model *m = pressed_block(dim, size);
        fdem_energy e0 = fdem_get_energy(m);
        double stored = e0.elastic + e0.joint;
        CHECK(e0.joint > 0, "%dD: the joints hold no energy at t = 0", dim);
        CHECK(fabs(e0.residual) < 1e-9 * stored, "%dD: residual %g J at t = 0", dim, e0.residual);
        double *before = element_stresses(m), kinetic_max;
        double worst = run_watched(m, 20 * size[0] / wave_speed(), stored, &kinetic_max);
        double change = stress_change(m, before);
        CHECK(kinetic_max < 1e-6 * stored, "%dD: kinetic reached %.3g of the stored energy", dim,
              kinetic_max / stored);
        CHECK(largest_damage(m) == 0, "%dD: a joint is damaged (%g)", dim, largest_damage(m));
        CHECK(change < 0.01, "%dD: stress changed by %.3g %%", dim, 100 * change);
        CHECK(worst < 1e-6, "%dD: energy residual %.3g of the stored energy", dim, worst);
        fprintf(stderr, "  %dD jointed block: %d joints hold %.4g of %.4g J; kinetic peak %.3g, "
                        "stress change %.3g %%, worst residual %.3g\n", dim,
                fdem_get_counts(m).joints, e0.joint, stored, kinetic_max / stored, 100 * change,
                worst);
        free(before);
        fdem_model_destroy(m);
    }
}

/* sigma_vv = rho g (h - top), the horizontal ones K0 times it, gravity on:
 * a jointed column on rollers stays still, node by node (each node's
 * element, joints and weight balance exactly for a linear field, see
 * joint_prestress.c), as the continuous column does. */
static void jointed_gravity_column_stays_still(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {1, dim == 2 ? 4 : 1, 4};
        const int div[3] = {3, dim == 2 ? 12 : 3, 12};
        int p;
        fdem_model *m = jointed_block(dim, size, div, &p, 0);
        const double g = 9.81, k0 = 0.5, top = size[dim - 1];
        double value[6] = {0}, gradient[6] = {0}, gv[3] = {0, 0, 0};
        for (int d = 0; d < dim; d++) gradient[d] = RHO * g * (d == dim - 1 ? 1 : k0);
        gv[dim - 1] = -g;
        set_stress(m, p, value, gradient, top);
        fdem_set_gravity_v(m, gv);
        for (int a = 0; a < dim; a++) {
            add_face(m, size, a, 0, FDEM_CONSTRAINT_FIX, 0);
            if (a < dim - 1) add_face(m, size, a, size[a], FDEM_CONSTRAINT_FIX, 0);
        }
        build_finalize(m, 0.5);
        fdem_energy e0 = fdem_get_energy(m);
        double stored = e0.elastic + e0.joint, *before = element_stresses(m), kinetic_max;
        run_watched(m, 20 * top / wave_speed(), stored, &kinetic_max);
        double change = stress_change_where(m, before, 1, top / 2);
        CHECK(kinetic_max < 1e-6 * stored, "%dD: kinetic reached %.3g of the stored energy", dim,
              kinetic_max / stored);
        CHECK(largest_damage(m) == 0, "%dD: a joint is damaged (%g)", dim, largest_damage(m));
        CHECK(change < 0.01, "%dD: stress in the lower half changed by %.3g %%", dim,
              100 * change);
        fprintf(stderr, "  %dD jointed column: kinetic peak %.3g of %.4g J, stress change %.3g %%\n",
                dim, kinetic_max / stored, stored, 100 * change);
        free(before);
        fdem_model_destroy(m);
    }
}

/* A jointed column under a graded, sheared in-situ stress balanced by
 * gravity, held by nothing but the boundary stress of the same field all
 * round (contract 6.1): every node's element, joints, weight and
 * consistently lumped boundary load balance exactly, so it is at rest to
 * round-off, as the continuous column of test_boundary_stress.c is. */
static void jointed_column_in_a_boundary_stress_is_at_rest(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {1, dim == 2 ? 3 : 1, 3};
        const int div[3] = {3, dim == 2 ? 9 : 3, 9};
        int p;
        fdem_model *m = jointed_block(dim, size, div, &p, 0);
        const double g = 9.81, top = size[dim - 1];
        double value[6] = {0}, gradient[6] = {0}, gv[3] = {0, 0, 0};
        const double k0[3] = {0.5, dim == 2 ? 1 : 0.8, 1};
        for (int d = 0; d < dim; d++) {
            value[d] = -2e6 * k0[d];
            gradient[d] = RHO * g * k0[d];
        }
        value[dim] = 0.4e6; /* 2D sxy; 3D syz, and sxz, sxy below */
        if (dim == 3) value[4] = -0.3e6, value[5] = 0.2e6;
        gv[dim - 1] = -g;
        set_stress(m, p, value, gradient, top);
        fdem_set_gravity_v(m, gv);
        fdem_constraint_def all = {.select = FDEM_SELECT_PART, .part = p,
                                   .kind = FDEM_CONSTRAINT_BOUNDARY_STRESS,
                                   .stress_reference = top};
        for (int k = 0; k < 6; k++) {
            all.stress_value[k] = value[k];
            all.stress_gradient[k] = gradient[k];
        }
        fdem_error err;
        if (fdem_add_constraint(m, &all, &err) < 0) build_die("boundary stress", &err);
        build_finalize(m, 0.5);
        fdem_energy e0 = fdem_get_energy(m);
        double stored = e0.elastic + e0.joint, *before = element_stresses(m), kinetic_max;
        run_watched(m, 5 * 4 * top / wave_speed(), stored, &kinetic_max);
        double change = stress_change(m, before);
        CHECK(kinetic_max < 1e-15 * stored && change < 1e-9, "%dD: kinetic reached %.3g of the "
              "stored energy, stresses changed by %.3g", dim, kinetic_max / stored, change);
        CHECK(largest_damage(m) == 0, "%dD: a joint is damaged (%g)", dim, largest_damage(m));
        fprintf(stderr, "  %dD jointed column in a boundary stress: kinetic peak %.3g of %.4g J, "
                        "stress change %.3g %%\n", dim, kinetic_max / stored, stored,
                100 * change);
        free(before);
        fdem_model_destroy(m);
    }
}

/* n_x^2 of joint j's face at t = 0 (the squared x component of its unit
 * normal): the share of an in-situ sigma_xx its face carries as tension. */
static double normal_x2(const fdem_model *m, int j)
{
    const int D = m->dim;
    const int32_t *n = m->joint_node + 2 * D * j;
    const double *x = m->pos0;
    double N[3];
    if (D == 2) {
        N[0] = x[2 * n[1] + 1] - x[2 * n[0] + 1];
        N[1] = -(x[2 * n[1]] - x[2 * n[0]]);
        N[2] = 0;
    } else {
        double e1[3], e2[3];
        for (int c = 0; c < 3; c++) {
            e1[c] = x[3 * n[1] + c] - x[3 * n[0] + c];
            e2[c] = x[3 * n[2] + c] - x[3 * n[0] + c];
        }
        N[0] = e1[1] * e2[2] - e1[2] * e2[1];
        N[1] = e1[2] * e2[0] - e1[0] * e2[2];
        N[2] = e1[0] * e2[1] - e1[1] * e2[0];
    }
    return N[0] * N[0] / (N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
}

/* An in-situ tension sigma_xx = f f_t held by pulls (negative pressures)
 * on the faces normal to x. The joints carry sigma.n from t = 0, so the
 * first step damages exactly those whose normal traction n_x^2 sigma_xx
 * exceeds f_t (at f = 0.9, none; at 1.1, the faces across x; a diagonal
 * face carries half of it); run on, the first of them to break break in
 * tension. Returns the count damaged by the first step and sets *expected
 * and *tensile (the events of the first breaks that are tensile, of
 * *events). */
static int joints_damaged_by_tension(int dim, double f, int *expected, int *events,
                                     int *tensile)
{
    const double size[3] = {1, 1, 1};
    const int div[3] = {4, 4, 3};
    int p;
    fdem_model *m = jointed_block(dim, size, div, &p, 0);
    double value[6] = {0};
    value[0] = f * TENSILE;
    set_stress(m, p, value, NULL, 0);
    add_face(m, size, 0, 0, FDEM_CONSTRAINT_PRESSURE, -value[0]);
    add_face(m, size, 0, size[0], FDEM_CONSTRAINT_PRESSURE, -value[0]);
    build_finalize(m, 0.5);
    fdem_error err;
    if (fdem_step(m, &err)) build_die("step", &err);
    int damaged = 0;
    *expected = 0;
    const double *D = fdem_joint_damage(m);
    for (int j = 0; j < fdem_get_counts(m).joints; j++) {
        damaged += D[j] > 0;
        *expected += normal_x2(m, j) * value[0] > TENSILE;
    }
    for (int s = 0; s < 4000 && fdem_event_count(m) == 0; s++)
        if (fdem_step(m, &err)) build_die("step", &err);
    *events = fdem_event_count(m);
    fdem_event *ev = malloc(sizeof *ev * (size_t)(*events ? *events : 1));
    fdem_drain_events(m, ev, *events);
    *tensile = 0;
    for (int k = 0; k < *events; k++) *tensile += ev[k].mode == JOINT_MODE_TENSILE;
    free(ev);
    fdem_model_destroy(m);
    return damaged;
}

static void strength_sees_the_in_situ_traction(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        int expected, events, tensile;
        int over = joints_damaged_by_tension(dim, 1.1, &expected, &events, &tensile);
        CHECK(expected > 0 && over == expected, "%dD: 1.1 f_t damaged %d joints at once, %d "
              "carry more than f_t", dim, over, expected);
        CHECK(events > 0 && tensile == events, "%dD: %d first breaks, %d in tension", dim, events,
              tensile);
        fprintf(stderr, "  %dD: 1.1 f_t damaged the %d joints across x at once; first breaks %d, "
                        "all tensile\n", dim, over, events);
        int under = joints_damaged_by_tension(dim, 0.9, &expected, &events, &tensile);
        CHECK(under == 0 && expected == 0 && events == 0, "%dD: 0.9 f_t damaged %d joints and "
              "broke %d", dim, under, events);
    }
}

/* A sheared, graded in-situ stress in a jointed block on rollers, set
 * moving: 1 thread, 2 threads and a run restored from a checkpoint taken
 * half-way agree to the bit. */
static fdem_model *moving_block(int dim, int threads)
{
    const double size[3] = {1, 1, 1};
    const int div[3] = {dim == 2 ? 16 : 5, dim == 2 ? 16 : 5, 5};
    int p;
    fdem_model *m = jointed_block(dim, size, div, &p, 0.05);
    const double value[6] = {-5e6, -3e6, -4e6, 0.5e6, 0.3e6, 0.4e6}, gradient[6] = {0, 1e6, 0.5e6};
    set_stress(m, p, value, gradient, 0.5);
    const double v[3] = {0.5, -0.2, 0.1};
    fdem_error err;
    fdem_set_part_velocity_v(m, p, v, &err);
    add_face(m, size, 0, 0, FDEM_CONSTRAINT_FIX, 0);
    fdem_set_threads(m, threads);
    build_finalize(m, 0.5);
    return m;
}

static void threads_and_checkpoints_give_the_same_bits(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *one = moving_block(dim, 1), *two = moving_block(dim, 2);
        fdem_model *restored = moving_block(dim, 1);
        fdem_error err;
        for (int s = 0; s < 60; s++) {
            fdem_step(one, &err);
            fdem_step(two, &err);
        }
        size_t size = fdem_checkpoint_size(one);
        void *buf = malloc(size);
        CHECK(fdem_checkpoint_write(one, buf, size) == 0, "%dD: checkpoint write", dim);
        CHECK(fdem_checkpoint_read(restored, buf, size, &err) == 0, "%dD: checkpoint read: %s",
              dim, err.message);
        free(buf);
        for (int s = 0; s < 60; s++) {
            fdem_step(one, &err);
            fdem_step(two, &err);
            fdem_step(restored, &err);
        }
        size_t bytes = sizeof(double) * (size_t)dim * (size_t)one->node_count;
        fdem_energy e1 = fdem_get_energy(one), e2 = fdem_get_energy(two);
        fdem_energy e3 = fdem_get_energy(restored);
        CHECK(memcmp(one->pos, two->pos, bytes) == 0, "%dD: 2 threads moved otherwise", dim);
        CHECK(memcmp(one->pos, restored->pos, bytes) == 0, "%dD: the restored run moved otherwise",
              dim);
        CHECK(memcmp(&e1, &e2, sizeof e1) == 0 && memcmp(&e1, &e3, sizeof e1) == 0,
              "%dD: energies differ", dim);
        fdem_model_destroy(one);
        fdem_model_destroy(two);
        fdem_model_destroy(restored);
    }
}

CHECK_MAIN(T(jointed_block_under_pressures_stays_still), T(jointed_gravity_column_stays_still),
           T(jointed_column_in_a_boundary_stress_is_at_rest),
           T(strength_sees_the_in_situ_traction), T(threads_and_checkpoints_give_the_same_bits))
