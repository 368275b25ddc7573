/*
 * test_initial_stress.c - in-situ stress (contract 5.3, PHYSICS.md
 * "Boundaries for rock engineering"), each test in both dimensions:
 *  - at t = 0 every element's stress is value + gradient (h - reference) at
 *    its initial centroid;
 *  - a rigid rotation R turns the stress into R sigma0 R^T (it is carried
 *    by the element) and leaves the elastic energy alone;
 *  - a block on rollers (each face held in its normal direction) under a
 *    uniform in-situ stress stays still, keeps its stress, and the rollers
 *    carry sigma . n times the face area;
 *  - the same block held only by the matching boundary pressures stays
 *    still (kinetic energy below 1e-6 of the elastic energy) with its
 *    stress unchanged to 1 % (the test);
 *  - a block whose in-situ stress grows with depth as gravity asks, on
 *    rollers at the sides and the base, stays still;
 *  - a free block released from its in-situ stress springs open, and the
 *    energy account (the in-situ stress's energy booked as elastic) closes;
 *  - a part with a zero in-situ stress steps bit for bit as one without:
 *    the stressed loop is the plain loop plus the pre-stress.
 */
#include <stdlib.h>

#include "build_model.h"
#include "check.h"
#include "mesh/mesh_3d.h"
#include "model/model.h"
#include "element/element.h"
#include "stress_watch.h"

#define RHO 2700.0
#define YOUNG 3e10
#define NU 0.25

/* A block part origin + [0, size] of material 0 meshed with div cells a
 * side (2D: triangles, 3D: tetrahedra); returns the part. */
static int add_block(fdem_model *m, const double origin[3], const double size[3],
                     const int div[3])
{
    return build_box_at(m, 0, m->dim, origin, size, div, 0);
}

/* A model of one block [0, size]. */
static fdem_model *block_model(int dim, const double size[3], const int div[3], int *part_out)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    build_material(m, RHO, YOUNG, NU, 0, 0);
    const double origin[3] = {0, 0, 0};
    *part_out = add_block(m, origin, size, div);
    return m;
}

static void set_stress(fdem_model *m, int p, const double *value, const double *gradient,
                       double reference)
{
    fdem_error err;
    if (fdem_set_part_initial_stress(m, p, value, gradient, reference, &err))
        build_die("initial stress", &err);
}



/* ------------------------------------------------------------------ t = 0 */

static void stress_at_rest_is_the_given_field(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {2, dim == 2 ? 3 : 2, 3};
        const int div[3] = {4, dim == 2 ? 6 : 3, 4};
        int pi;
        fdem_model *m = block_model(dim, size, div, &pi);
        /* 2D: sxx, syy, sxy; 3D: xx, yy, zz, yz, xz, xy */
        const double v2[3] = {-12e6, -20e6, 3e6}, g2[3] = {0.5e6, 2.7e4 * 9.81, -1e5};
        const double v3[6] = {-12e6, -15e6, -20e6, 1e6, 2e6, 3e6},
                     g3[6] = {0.5e6, 0.6e6, 2.7e4 * 9.81, 0, -1e5, 2e5};
        const double *value = dim == 2 ? v2 : v3, *gradient = dim == 2 ? g2 : g3;
        const double reference = 1.25;
        set_stress(m, pi, value, gradient, reference);
        build_finalize(m, 0.5);
        const int S = fdem_stress_components(m), E = fdem_get_counts(m).elements;
        double *s = element_stresses(m), worst = 0;
        for (int e = 0; e < E; e++) {
            double dh = centroid_height(m, e) - reference;
            for (int k = 0; k < S; k++)
                worst = fmax(worst, fabs(s[S * e + k] - (value[k] + gradient[k] * dh)));
        }
        CHECK(worst <= 1e-9 * stress_scale(S, value), "%dD: stress off the field by %g Pa",
              dim, worst);
        free(s);
        fdem_model_destroy(m);
    }
}

/* Rotates every position by R (row-major 3x3; 2D uses the upper 2x2). */
static void rotate_positions(fdem_model *m, const double R[9])
{
    const int D = m->dim;
    for (int i = 0; i < m->node_count; i++) {
        double x[3] = {0, 0, 0}, y[3] = {0, 0, 0};
        for (int d = 0; d < D; d++) x[d] = m->pos0[D * i + d];
        for (int r = 0; r < D; r++)
            for (int c = 0; c < D; c++) y[r] += R[3 * r + c] * x[c];
        for (int d = 0; d < D; d++) m->pos[D * i + d] = y[d];
    }
}

/* Voigt (2D: xx, yy, xy; 3D: xx, yy, zz, yz, xz, xy) to a full 3x3 and back. */
static const int VOIGT_ROW[2][6] = {{0, 1, 0}, {0, 1, 2, 1, 0, 0}};
static const int VOIGT_COL[2][6] = {{0, 1, 1}, {0, 1, 2, 2, 2, 1}};

static void rotated_stress(int dim, const double R[9], const double *voigt, double *out)
{
    const int S = dim == 3 ? 6 : 3, *row = VOIGT_ROW[dim - 2], *col = VOIGT_COL[dim - 2];
    double s[3][3] = {{0}};
    for (int k = 0; k < S; k++) s[row[k]][col[k]] = s[col[k]][row[k]] = voigt[k];
    for (int k = 0; k < S; k++) {
        double sum = 0;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) sum += R[3 * row[k] + a] * s[a][b] * R[3 * col[k] + b];
        out[k] = sum;
    }
}

static void rotation_carries_the_stress(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {1, 1, 1};
        const int div[3] = {2, 2, 2};
        int pi;
        fdem_model *m = block_model(dim, size, div, &pi);
        const double v2[3] = {-10e6, -4e6, 2e6}, v3[6] = {-10e6, -4e6, -7e6, 1e6, -2e6, 2e6};
        const double *value = dim == 2 ? v2 : v3;
        set_stress(m, pi, value, NULL, 0);
        build_finalize(m, 0.5);
        const double elastic0 = fdem_get_energy(m).elastic;
        /* 2D: 40 degrees about z; 3D: 40 degrees about (1, 2, 2)/3 */
        double R[9], th = 40 * M_PI / 180, c = cos(th), s = sin(th);
        const double n2[3] = {0, 0, 1}, n3[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3};
        const double *n = dim == 2 ? n2 : n3;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double cross = (i == j) ? 0 : ((j == (i + 1) % 3) ? -n[(i + 2) % 3] : n[(i + 1) % 3]);
                R[3 * i + j] = (i == j ? c : 0) + s * cross + (1 - c) * n[i] * n[j];
            }
        rotate_positions(m, R);
        const int S = fdem_stress_components(m), E = fdem_get_counts(m).elements;
        double want[6], *got = element_stresses(m), worst = 0;
        rotated_stress(dim, R, value, want);
        for (int e = 0; e < E; e++)
            for (int k = 0; k < S; k++) worst = fmax(worst, fabs(got[S * e + k] - want[k]));
        CHECK(worst <= 1e-9 * stress_scale(S, value), "%dD: rotated stress off by %g Pa", dim,
              worst);
        /* the elastic energy of the rotated block, from one force pass */
        memset(m->force, 0, sizeof(double) * (size_t)dim * (size_t)m->node_count);
        element_forces(m);
        CHECK_REL(m->elastic_energy, elastic0, 1e-9);
        free(got);
        fdem_model_destroy(m);
    }
}

/* ------------------------------------------------------------ equilibrium */

/* A constraint selecting the face of the block at coordinate `at` of `axis`. */
static fdem_constraint_def face(const fdem_model *m, const double size[3], int axis, double at)
{
    const int D = m->dim;
    fdem_constraint_def c = {0};
    c.select = FDEM_SELECT_BOX;
    for (int d = 0; d < D; d++) {
        c.box[d] = d == axis ? at - 1e-6 : -1e-6;
        c.box[D + d] = d == axis ? at + 1e-6 : size[d] + 1e-6;
    }
    return c;
}

static int add_constraint(fdem_model *m, const fdem_constraint_def *c)
{
    fdem_error err;
    int k = fdem_add_constraint(m, c, &err);
    if (k < 0) build_die("constraint", &err);
    return k;
}

/* A roller on a face: its nodes held along the axis. */
static int add_roller(fdem_model *m, const double size[3], int axis, double at)
{
    fdem_constraint_def c = face(m, size, axis, at);
    c.kind = FDEM_CONSTRAINT_FIX;
    c.fix_x = axis == 0;
    c.fix_y = axis == 1;
    c.fix_z = axis == 2;
    return add_constraint(m, &c);
}

/* A pressure p (> 0 pushes into the body) on a face. */
static int add_pressure(fdem_model *m, const double size[3], int axis, double at, double p)
{
    fdem_constraint_def c = face(m, size, axis, at);
    c.kind = FDEM_CONSTRAINT_PRESSURE;
    c.value[0] = p;
    return add_constraint(m, &c);
}

/* Steps for `periods` of the block's slowest compression mode (height / c). */
static void run_periods(fdem_model *m, double height, double periods)
{
    double c = sqrt(YOUNG * (1 - NU) / ((1 + NU) * (1 - 2 * NU)) / RHO);
    double t_end = periods * 4 * height / c;
    fdem_error err;
    while (fdem_get_time(m) < t_end)
        if (fdem_step(m, &err)) build_die("step", &err);
}


/* The 2 x 1.5 (x 1) m block of the equilibrium tests under the uniform
 * in-situ stress *value (principal along the axes). */
static fdem_model *uniform_block(int dim, const double size[3], const double **value)
{
    static const double v2[3] = {-10e6, -6e6, 0}, v3[6] = {-10e6, -6e6, -8e6, 0, 0, 0};
    const int div[3] = {8, 6, 4};
    int pi;
    fdem_model *m = block_model(dim, size, div, &pi);
    *value = dim == 2 ? v2 : v3;
    set_stress(m, pi, *value, NULL, 0);
    return m;
}


static void rollers_hold_a_stressed_block(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {2, 1.5, 1}, *value;
        fdem_model *m = uniform_block(dim, size, &value);
        int far[3];
        for (int a = 0; a < dim; a++) {
            add_roller(m, size, a, 0);
            far[a] = add_roller(m, size, a, size[a]);
        }
        build_finalize(m, 0.5);
        double *before = element_stresses(m);
        run_periods(m, size[1], 5);
        fdem_energy en = fdem_get_energy(m);
        CHECK(en.kinetic < 1e-6 * en.elastic, "%dD: kinetic %g J against elastic %g J", dim,
              en.kinetic, en.elastic);
        double change = stress_change(m, before);
        CHECK(change < 0.01, "%dD: stress changed by %.3g %%", dim, 100 * change);
        /* each far roller carries sigma_aa times the face's area */
        for (int a = 0; a < dim; a++) {
            double area = 1;
            for (int d = 0; d < dim; d++)
                if (d != a) area *= size[d];
            CHECK_REL(fdem_constraint_forces(m)[dim * far[a] + a], value[a] * area, 1e-6);
        }
        free(before);
        fdem_model_destroy(m);
    }
}

/* The same block held by nothing but the pressures its stress asks for:
 * p = -sigma_aa on both faces normal to axis a (contract 5.3 pressure). */
static void pressures_hold_a_stressed_block(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {2, 1.5, 1}, *value;
        fdem_model *m = uniform_block(dim, size, &value);
        for (int a = 0; a < dim; a++) {
            add_pressure(m, size, a, 0, -value[a]);
            add_pressure(m, size, a, size[a], -value[a]);
        }
        build_finalize(m, 0.5);
        double *before = element_stresses(m), e0 = fdem_get_energy(m).elastic;
        double c = sqrt(YOUNG * (1 - NU) / ((1 + NU) * (1 - 2 * NU)) / RHO);
        double worst = run_watched(m, 20 * size[0] / c, e0, NULL);
        fdem_energy en = fdem_get_energy(m);
        CHECK(en.kinetic < 1e-6 * en.elastic, "%dD: kinetic %g J against elastic %g J", dim,
              en.kinetic, en.elastic);
        double change = stress_change(m, before);
        CHECK(change < 0.01, "%dD: stress changed by %.3g %%", dim, 100 * change);
        CHECK(worst < 1e-6, "%dD: energy residual %.3g of the elastic energy", dim, worst);
        fprintf(stderr, "  %dD pressures: kinetic/elastic %.3g, stress change %.3g %%, worst "
                        "residual %.3g of %.6g J\n", dim, en.kinetic / en.elastic, 100 * change,
                worst, e0);
        free(before);
        fdem_model_destroy(m);
    }
}

/* sigma_vv = rho g (h - top), the horizontal ones K0 times it: the
 * in-situ stress a column of rock under gravity holds, balanced by the
 * lumped weight of its nodes up to the discretisation of a stress that is
 * constant per element. */
static void gravity_column_stays_still(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {1, dim == 2 ? 4 : 1, 4};
        const int div[3] = {4, dim == 2 ? 16 : 4, 16};
        int pi;
        fdem_model *m = block_model(dim, size, div, &pi);
        const double g = 9.81, k0 = 0.5, top = size[dim - 1];
        double value[6] = {0}, gradient[6] = {0}, gv[3] = {0, 0, 0};
        for (int d = 0; d < dim; d++) gradient[d] = RHO * g * (d == dim - 1 ? 1 : k0);
        gv[dim - 1] = -g;
        set_stress(m, pi, value, gradient, top);
        fdem_set_gravity_v(m, gv);
        for (int a = 0; a < dim; a++) {
            add_roller(m, size, a, 0);
            if (a < dim - 1) add_roller(m, size, a, size[a]);
        }
        build_finalize(m, 0.5);
        double *before = element_stresses(m);
        run_periods(m, top, 5);
        fdem_energy en = fdem_get_energy(m);
        CHECK(en.kinetic < 1e-6 * en.elastic, "%dD: kinetic %g J against elastic %g J", dim,
              en.kinetic, en.elastic);
        /* the stress near the base, where it is large: within 1 % */
        const int S = fdem_stress_components(m), E = fdem_get_counts(m).elements;
        double *after = element_stresses(m), worst = 0;
        for (int e = 0; e < E; e++) {
            if (centroid_height(m, e) > top / 2) continue;
            worst = fmax(worst, fabs(after[S * e + dim - 1] - before[S * e + dim - 1]) /
                                    fabs(before[S * e + dim - 1]));
        }
        CHECK(worst < 0.01, "%dD: vertical stress changed by %.3g %%", dim, 100 * worst);
        fprintf(stderr, "  %dD column: kinetic/elastic %.3g, vertical stress change %.3g %%\n",
                dim, en.kinetic / en.elastic, 100 * worst);
        free(before);
        free(after);
        fdem_model_destroy(m);
    }
}

/* ----------------------------------------------------------------- energy */

static void released_block_closes_the_balance(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {1, 1, 1};
        const int div[3] = {6, 6, 6};
        int pi;
        fdem_model *m = block_model(dim, size, div, &pi);
        const double v2[3] = {-20e6, -10e6, 4e6}, g2[3] = {0, -5e6, 0};
        const double v3[6] = {-20e6, -10e6, -15e6, 2e6, 0, 4e6}, g3[6] = {0, 0, -5e6, 0, 1e6, 0};
        set_stress(m, pi, dim == 2 ? v2 : v3, dim == 2 ? g2 : g3, 0.5);
        build_finalize(m, 0.5);
        const double e0 = m->initial_energy;
        CHECK_REL(e0, m->stress0_energy, 1e-9); /* at rest all is the in-situ stress's */
        double kinetic_max, c = sqrt(YOUNG * (1 - NU) / ((1 + NU) * (1 - 2 * NU)) / RHO);
        double worst = run_watched(m, 4 / c, e0, &kinetic_max);
        /* the stress is released: most of its energy becomes motion */
        CHECK(kinetic_max > 0.5 * e0, "%dD: kinetic peaked at %g of %g J", dim, kinetic_max, e0);
        CHECK(worst < 1e-3, "%dD: residual %.3g of the in-situ energy", dim, worst);
        fprintf(stderr, "  %dD release: in-situ energy %.6g J, kinetic peak %.3g of it, worst "
                        "residual %.3g of it\n", dim, e0, kinetic_max / e0, worst);
        fdem_model_destroy(m);
    }
}

static void zero_stress_steps_as_none(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        const double size[3] = {1, 1, 1};
        const int div[3] = {5, 4, 3};
        int pa, pb;
        fdem_model *a = block_model(dim, size, div, &pa), *b = block_model(dim, size, div, &pb);
        const double zero[6] = {0}, v[3] = {3, -2, 1};
        set_stress(b, pb, zero, zero, 0);
        fdem_error err;
        fdem_set_part_velocity_v(a, pa, v, &err);
        fdem_set_part_velocity_v(b, pb, v, &err);
        add_roller(a, size, 0, 0);
        add_roller(b, size, 0, 0);
        build_finalize(a, 0.5);
        build_finalize(b, 0.5);
        for (int s = 0; s < 300; s++) {
            fdem_step(a, &err);
            fdem_step(b, &err);
        }
        size_t bytes = sizeof(double) * (size_t)dim * (size_t)a->node_count;
        CHECK(memcmp(a->pos, b->pos, bytes) == 0 && memcmp(a->vel, b->vel, bytes) == 0,
              "%dD: a zero in-situ stress changed the motion", dim);
        fdem_model_destroy(a);
        fdem_model_destroy(b);
    }
}

/* Two parts, one stressed and one not, split across the scatter plan's
 * blocks: one thread and two give the same bits (the stressed runs are
 * summed in block order like the rest). */
static void threads_give_the_same_bits(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *m[2];
        for (int k = 0; k < 2; k++) {
            const double size[3] = {1, 1, 1};
            const int div[3] = {dim == 2 ? 40 : 10, dim == 2 ? 40 : 10, 10};
            int pi;
            const double beside[3] = {2, 0, 0};
            m[k] = block_model(dim, size, div, &pi);
            add_block(m[k], beside, size, div); /* unstressed */
            const double value[6] = {-10e6, -6e6, -8e6, 1e6, 2e6, 3e6}, gradient[6] = {1e6};
            set_stress(m[k], pi, value, gradient, 0.5);
            fdem_set_threads(m[k], k + 1);
            build_finalize(m[k], 0.5);
        }
        fdem_error err;
        for (int s = 0; s < 50; s++)
            for (int k = 0; k < 2; k++) fdem_step(m[k], &err);
        size_t bytes = sizeof(double) * (size_t)dim * (size_t)m[0]->node_count;
        fdem_energy e0 = fdem_get_energy(m[0]), e1 = fdem_get_energy(m[1]);
        CHECK(memcmp(m[0]->pos, m[1]->pos, bytes) == 0, "%dD: positions differ", dim);
        CHECK(memcmp(&e0, &e1, sizeof e0) == 0, "%dD: energies differ", dim);
        CHECK(m[0]->elem_plan.color_count > 0, "%dD: the model fits one block", dim);
        fdem_model_destroy(m[0]);
        fdem_model_destroy(m[1]);
    }
}

CHECK_MAIN(T(stress_at_rest_is_the_given_field), T(rotation_carries_the_stress),
           T(rollers_hold_a_stressed_block), T(pressures_hold_a_stressed_block),
           T(gravity_column_stays_still),
           T(released_block_closes_the_balance), T(zero_stress_steps_as_none),
           T(threads_give_the_same_bits))
