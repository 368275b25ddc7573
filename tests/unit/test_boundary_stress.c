/*
 * test_boundary_stress.c - the boundary stress and traction actions
 * (contract 6.1, core/step/boundary_load.c), each in 2D and 3D against a
 * closed form:
 *  - a uniform field -p I on a rotated block puts on every vertex the same
 *    bits as a pressure p; a uniform anisotropic field on one face of the
 *    rotated block sums to sigma . (R n) A;
 *  - a pure shear field gives the tangential resultant tau A and no normal
 *    one;
 *  - a field growing with height: the resultant on a side face is the
 *    integral of sigma . n, and so is its moment about the base, which is
 *    what tells consistent lumping from lumping p L / 2 (that one has the
 *    right resultant but a moment off by O(L^2));
 *  - a block whose elements hold an in-situ stress with a gradient balanced
 *    by gravity (a K0 field, sxx != syy) is at rest when held only by the
 *    matching boundary stress on its sides and top and a roller at its
 *    base, or by the boundary stress on all its faces with shears: kinetic
 *    energy below 1e-6 of the stored energy, stresses unchanged to 1 %
 *    (the contract's figures), and in fact to round-off (below 1e-15 and
 *    1e-9: lumping sigma(h_a) L / 2 instead gives 1e-8 and 5e-4, which
 *    passes the first figures and fails these);
 *  - a traction is a fixed vector times the current area, scaled by its
 *    amplitude, as is a boundary stress; their work closes the balance;
 *  - a checkpoint carries both across a restore to the bit, and a field
 *    that is not finite is refused at finalize;
 *  - a case document's "boundary_stress" and "traction" reach the engine
 *    as written, and a field that grows out of range over the model's
 *    heights is a 422 at its gradient.
 */
#include <stdlib.h>

#include "build_model.h"
#include "case_doc.h"
#include "check.h"
#include "math/voigt.h"
#include "mesh/mesh_3d.h"
#include "model/model.h"

#define RHO 2700.0
#define YOUNG 3e10
#define NU 0.25
#define GRAVITY 9.81

/* A block [0, size] of div cells a side (2D triangles, 3D tetrahedra). */
static fdem_model *block_model(int dim, const double size[3], const int div[3], int *body_out)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (fdem_set_dimension(m, dim, &err)) build_die("dimension", &err);
    int mat = build_material(m, RHO, YOUNG, NU, 0, 0);
    *body_out = build_box_part(m, mat, dim, size, div, 0);
    return m;
}

static int add_constraint(fdem_model *m, const fdem_constraint_def *c)
{
    fdem_error err;
    int k = fdem_add_constraint(m, c, &err);
    if (k < 0) build_die("constraint", &err);
    return k;
}

/* The nodes of the block's face at coordinate `at` of `axis` (initial positions). */
static fdem_constraint_def face(int dim, const double size[3], int axis, double at)
{
    fdem_constraint_def c = {.select = FDEM_SELECT_BOX};
    for (int d = 0; d < dim; d++) {
        c.box[d] = d == axis ? at - 1e-6 : -1e-6;
        c.box[dim + d] = d == axis ? at + 1e-6 : size[d] + 1e-6;
    }
    return c;
}

/* The field value + gradient (h - reference) on the selection c. */
static int add_stress(fdem_model *m, fdem_constraint_def c, const double *value,
                      const double *gradient, double reference)
{
    const int S = fdem_stress_components(m);
    c.kind = FDEM_CONSTRAINT_BOUNDARY_STRESS;
    for (int k = 0; k < S; k++) {
        c.stress_value[k] = value[k];
        c.stress_gradient[k] = gradient ? gradient[k] : 0;
    }
    c.stress_reference = reference;
    return add_constraint(m, &c);
}

static void step_once(fdem_model *m)
{
    fdem_error err;
    if (fdem_step(m, &err)) build_die("step", &err);
}

/* Rotates every current position by R (row-major 3x3; 2D its upper 2x2)
 * about the origin, as if the block had turned before the step. */
static void rotate_positions(fdem_model *m, const double R[9])
{
    const int D = m->dim;
    for (int i = 0; i < m->node_count; i++) {
        double y[3] = {0, 0, 0};
        for (int r = 0; r < D; r++)
            for (int c = 0; c < D; c++) y[r] += R[3 * r + c] * m->pos0[D * i + c];
        for (int d = 0; d < D; d++) m->pos[D * i + d] = y[d];
    }
}

/* 2D: 30 degrees about z; 3D: 50 degrees about (1, 2, 2)/3. */
static void test_rotation(int dim, double R[9])
{
    double a = dim == 2 ? M_PI / 6 : 50 * M_PI / 180, u[3] = {1 / 3.0, 2 / 3.0, 2 / 3.0};
    if (dim == 2) u[0] = u[1] = 0, u[2] = 1;
    double c = cos(a), s = sin(a);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double cross = 0; /* [u]x */
            if (i == 0 && j == 1) cross = -u[2];
            if (i == 0 && j == 2) cross = u[1];
            if (i == 1 && j == 0) cross = u[2];
            if (i == 1 && j == 2) cross = -u[0];
            if (i == 2 && j == 0) cross = -u[1];
            if (i == 2 && j == 1) cross = u[0];
            R[3 * i + j] = (i == j) * c + s * cross + (1 - c) * u[i] * u[j];
        }
}

/* ------------------------------------------------------- closed forms */

static const double blk_size[3] = {0.6, 0.8, 1.2};
static const int blk_div[3] = {3, 4, 6};

/* sigma = -p I on a turned block: the same bits as the pressure p on every
 * facet vertex; an anisotropic uniform field on the face x = Lx sums to
 * sigma . (R e_x) A, and on the whole outline to zero. */
static void uniform_field_on_a_rotated_block(void)
{
    const double p = 3e6;
    for (int dim = 2; dim <= 3; dim++) {
        double R[9];
        test_rotation(dim, R);
        int body;
        fdem_model *a = block_model(dim, blk_size, blk_div, &body);
        fdem_model *b = block_model(dim, blk_size, blk_div, &body);
        fdem_constraint_def all = {.select = FDEM_SELECT_PART, .part = body,
                                   .kind = FDEM_CONSTRAINT_PRESSURE, .value = {p}};
        add_constraint(a, &all);
        const double iso[6] = {-p, -p, -p, 0, 0, 0}, iso2[3] = {-p, -p, 0};
        add_stress(b, all, dim == 2 ? iso2 : iso, NULL, 0);
        const double v2[3] = {-4e6, 1e6, 2.5e6}, v3[6] = {-4e6, 1e6, -2e6, 0.7e6, -1.5e6, 2.5e6};
        const double *v = dim == 2 ? v2 : v3;
        int right = add_stress(b, face(dim, blk_size, 0, blk_size[0]), v, NULL, 0);
        int outline = add_stress(b, all, v, NULL, 0);
        build_finalize(a, 0.5);
        build_finalize(b, 0.5);
        fdem_set_dt(b, fdem_get_dt(a));
        rotate_positions(a, R);
        rotate_positions(b, R);
        step_once(a);
        step_once(b);
        int n = a->constraints[0].facet_count;
        CHECK(n == b->constraints[0].facet_count && n > 0, "%dD: %d facets", dim, n);
        CHECK(memcmp(a->bfacet_force, b->bfacet_force, sizeof(double) * dim * dim * n) == 0,
              "%dD: -p I differs from the pressure p", dim);
        /* sigma . (R e_x) A on the face x = Lx */
        double area = dim == 2 ? blk_size[1] : blk_size[1] * blk_size[2], want[3] = {0, 0, 0};
        for (int i = 0; i < dim; i++)
            for (int j = 0; j < dim; j++) want[i] += v[voigt_index(dim, i, j)] * R[3 * j] * area;
        const double *f = fdem_constraint_forces(b);
        double worst = 0, scale = 4e6 * area;
        for (int d = 0; d < dim; d++) {
            CHECK_NEAR(f[dim * right + d], want[d], 1e-12 * scale);
            CHECK_NEAR(f[dim * outline + d], 0, 1e-12 * scale);
            worst = fmax(worst, fabs(f[dim * right + d] - want[d]) / scale);
        }
        fprintf(stderr, "  %dD rotated block: -p I = pressure to the bit; face resultant off "
                        "sigma.(R n)A by %.2g of sigma A\n", dim, worst);
        fdem_model_destroy(a);
        fdem_model_destroy(b);
    }
}

/* sxy = tau (3D also syz, sxz): on the face x = Lx, t = (sxx, sxy, sxz) =
 * (0, tau_xy, tau_xz), on the face y = Ly, t = (sxy, 0, syz). */
static void shear_field_gives_the_tangential_resultant(void)
{
    const double t_xy = 2e6, t_xz = -1e6, t_yz = 0.5e6;
    for (int dim = 2; dim <= 3; dim++) {
        int body;
        fdem_model *m = block_model(dim, blk_size, blk_div, &body);
        const double v2[3] = {0, 0, t_xy}, v3[6] = {0, 0, 0, t_yz, t_xz, t_xy};
        const double *v = dim == 2 ? v2 : v3;
        int kx = add_stress(m, face(dim, blk_size, 0, blk_size[0]), v, NULL, 0);
        int ky = add_stress(m, face(dim, blk_size, 1, blk_size[1]), v, NULL, 0);
        build_finalize(m, 0.5);
        step_once(m);
        const double *f = fdem_constraint_forces(m);
        double ax = dim == 2 ? blk_size[1] : blk_size[1] * blk_size[2];
        double ay = dim == 2 ? blk_size[0] : blk_size[0] * blk_size[2];
        const double want_x[3] = {0, t_xy * ax, t_xz * ax}, want_y[3] = {t_xy * ay, 0, t_yz * ay};
        for (int d = 0; d < dim; d++) {
            CHECK_NEAR(f[dim * kx + d], want_x[d], 1e-12 * t_xy * ax);
            CHECK_NEAR(f[dim * ky + d], want_y[d], 1e-12 * t_xy * ay);
        }
        fprintf(stderr, "  %dD shear: face x resultant (%.6g, %.6g) N, want (0, %.6g)\n", dim,
                f[dim * kx], f[dim * kx + 1], want_x[1]);
        fdem_model_destroy(m);
    }
}

/* On the face x = Lx (n = e_x) of the block, t_i = s_ix(h) with s = v + g
 * (h - r), h = y (2D) or z (3D) from 0 to H: integral of t_i over the face
 * and its moment about the base, integral of h t_i. */
static void gradient_resultant_and_moment_are_the_integrals(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        int body;
        fdem_model *m = block_model(dim, blk_size, blk_div, &body);
        const double v2[3] = {-5e6, -2e6, 1e6}, g2[3] = {3e5, 1e5, -2e5};
        const double v3[6] = {-5e6, -3e6, -2e6, 0.4e6, 1e6, -0.6e6};
        const double g3[6] = {3e5, 2e5, 1e5, 0.5e5, -2e5, 0.7e5};
        const double *v = dim == 2 ? v2 : v3, *g = dim == 2 ? g2 : g3, r = 0.4;
        int k = add_stress(m, face(dim, blk_size, 0, blk_size[0]), v, g, r);
        build_finalize(m, 0.5);
        step_once(m);
        const double H = blk_size[dim - 1], W = dim == 2 ? 1 : blk_size[1]; /* width across */
        const double *f = fdem_constraint_forces(m);
        /* the moment from the facet forces each vertex got */
        const constraint *c = &m->constraints[k];
        double moment[3] = {0, 0, 0};
        for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++)
            for (int a = 0; a < dim; a++) {
                double h = m->pos0[dim * m->bfacet_node[dim * j + a] + dim - 1];
                for (int d = 0; d < dim; d++) moment[d] += h * m->bfacet_force[dim * (dim * j + a) + d];
            }
        double worst_f = 0, worst_m = 0;
        for (int d = 0; d < dim; d++) {
            int s = voigt_index(dim, d, 0);
            double F = W * (v[s] * H + g[s] * (H * H / 2 - r * H));
            double M = W * (v[s] * H * H / 2 + g[s] * (H * H * H / 3 - r * H * H / 2));
            double scale = 5e6 * W * H;
            CHECK_NEAR(f[dim * k + d], F, 1e-12 * scale);
            CHECK_NEAR(moment[d], M, 1e-12 * scale * H);
            worst_f = fmax(worst_f, fabs(f[dim * k + d] - F) / scale);
            worst_m = fmax(worst_m, fabs(moment[d] - M) / (scale * H));
        }
        fprintf(stderr, "  %dD gradient: resultant off the integral by %.2g, moment by %.2g (of "
                        "5 MPa x area)\n", dim, worst_f, worst_m);
        fdem_model_destroy(m);
    }
}

/* ------------------------------------------------------------- at rest */

static double *element_stresses(const fdem_model *m)
{
    int S = fdem_stress_components(m);
    double *s = malloc(sizeof(double) * (size_t)S * (size_t)fdem_get_counts(m).elements);
    fdem_element_stress(m, s);
    return s;
}

/* Largest change of any element's stress, relative to its largest component. */
static double stress_change(const fdem_model *m, const double *before)
{
    const int S = fdem_stress_components(m), E = fdem_get_counts(m).elements;
    double *after = element_stresses(m), worst = 0;
    for (int e = 0; e < E; e++) {
        double scale = 0, diff = 0;
        for (int k = 0; k < S; k++) {
            scale = fmax(scale, fabs(before[S * e + k]));
            diff = fmax(diff, fabs(after[S * e + k] - before[S * e + k]));
        }
        worst = fmax(worst, diff / scale);
    }
    free(after);
    return worst;
}

/* A column 1 x 4 m (3D 1 x 1 x 4 m) whose elements hold value + gradient
 * (h - top), the gradient rho g vertically and K0 rho g horizontally, under
 * gravity: div sigma + rho g = 0. held_by_all: the matching boundary stress
 * on every face (with shears in value, which a uniform field may carry);
 * else on the sides and the top, and a roller at the base. Runs five
 * periods of the column's slowest compression mode; returns kinetic /
 * stored energy at the end, the stress change in *change. */
static double column_at_rest(int dim, int held_by_all, double *change)
{
    const double size[3] = {1, dim == 2 ? 4 : 1, 4};
    const int div[3] = {4, dim == 2 ? 16 : 4, 16};
    const double top = size[dim - 1], rg = RHO * GRAVITY;
    int body;
    fdem_model *m = block_model(dim, size, div, &body);
    double value[6] = {0}, gradient[6] = {0}, g[3] = {0, 0, 0};
    const double k0[3] = {0.5, dim == 2 ? 1 : 0.8, 1};
    for (int d = 0; d < dim; d++) {
        value[d] = -2e6 * k0[d];
        gradient[d] = rg * k0[d];
    }
    if (held_by_all) {
        value[dim] = 0.4e6;
        if (dim == 3) value[4] = -0.3e6, value[5] = 0.2e6;
    }
    g[dim - 1] = -GRAVITY;
    fdem_error err;
    if (fdem_set_part_initial_stress(m, body, value, gradient, top, &err))
        build_die("initial stress", &err);
    fdem_set_gravity_v(m, g);
    if (held_by_all) {
        fdem_constraint_def all = {.select = FDEM_SELECT_PART, .part = body};
        add_stress(m, all, value, gradient, top);
    } else {
        for (int a = 0; a < dim; a++) {
            if (a < dim - 1) add_stress(m, face(dim, size, a, 0), value, gradient, top);
            add_stress(m, face(dim, size, a, size[a]), value, gradient, top);
        }
        fdem_constraint_def base = face(dim, size, dim - 1, 0);
        base.kind = FDEM_CONSTRAINT_FIX;
        base.fix_y = dim == 2;
        base.fix_z = dim == 3;
        add_constraint(m, &base);
    }
    build_finalize(m, 0.5);
    double *before = element_stresses(m);
    double c = sqrt(YOUNG * (1 - NU) / ((1 + NU) * (1 - 2 * NU)) / RHO);
    double t_end = 5 * 4 * top / c, worst = 0;
    while (fdem_get_time(m) < t_end) {
        step_once(m);
        worst = fmax(worst, fabs(fdem_get_energy(m).residual));
    }
    fdem_energy en = fdem_get_energy(m);
    *change = stress_change(m, before);
    fprintf(stderr, "  %dD column held by %s: kinetic/stored %.3g, stress change %.3g %%, worst "
                    "residual %.3g J of %.6g J stored, %ld steps\n",
            dim, held_by_all ? "boundary stress all round" : "boundary stress + base roller",
            en.kinetic / en.elastic, 100 * *change, worst, en.elastic, (long)m->step);
    CHECK(worst < 1e-6 * en.elastic, "%dD: energy residual %g J", dim, worst);
    free(before);
    fdem_model_destroy(m);
    return en.kinetic / en.elastic;
}

static void column_held_by_boundary_stress_and_roller_is_at_rest(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        double change, ratio = column_at_rest(dim, 0, &change);
        CHECK(ratio < 1e-6, "%dD: kinetic %.3g of the stored energy", dim, ratio);
        CHECK(change < 0.01, "%dD: stress changed by %.3g %%", dim, 100 * change);
        CHECK(ratio < 1e-15 && change < 1e-9, "%dD: not at rest to round-off (kinetic %.3g, "
              "stress change %.3g): the lumping is not consistent", dim, ratio, change);
    }
}

static void column_held_by_boundary_stress_all_round_is_at_rest(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        double change, ratio = column_at_rest(dim, 1, &change);
        CHECK(ratio < 1e-6, "%dD: kinetic %.3g of the stored energy", dim, ratio);
        CHECK(change < 0.01, "%dD: stress changed by %.3g %%", dim, 100 * change);
        CHECK(ratio < 1e-15 && change < 1e-9, "%dD: not at rest to round-off (kinetic %.3g, "
              "stress change %.3g): the lumping is not consistent", dim, ratio, change);
    }
}

/* ---------------------------------------------- traction, amplitude, work */

/* A traction t on the face y = Ly, times an amplitude of a constant 0.25
 * (and a boundary stress beside it under the same amplitude): the
 * resultant is 0.25 t A on the turned block too (a fixed direction, the
 * current area), and 0.25 sigma . n A for the stress. */
static void traction_and_amplitude(void)
{
    static const double quarter[2] = {0, 0.25};
    for (int dim = 2; dim <= 3; dim++) {
        double R[9];
        test_rotation(dim, R);
        int body;
        fdem_model *m = block_model(dim, blk_size, blk_div, &body);
        fdem_constraint_def t = face(dim, blk_size, 1, blk_size[1]);
        t.kind = FDEM_CONSTRAINT_TRACTION;
        t.value[0] = 1e6;
        t.value[1] = -2e5;
        t.value[2] = dim == 3 ? 3e5 : 0;
        t.amplitude = quarter;
        t.amplitude_count = 1;
        int kt = add_constraint(m, &t);
        fdem_constraint_def s = face(dim, blk_size, 0, 0);
        s.amplitude = quarter;
        s.amplitude_count = 1;
        const double v[6] = {-8e6, -1e6, -1e6, 0, 0, 4e6}, v2[3] = {-8e6, -1e6, 4e6};
        int ks = add_stress(m, s, dim == 2 ? v2 : v, NULL, 0);
        build_finalize(m, 0.5);
        rotate_positions(m, R);
        step_once(m);
        const double *f = fdem_constraint_forces(m), *sv = dim == 2 ? v2 : v;
        double area = dim == 2 ? blk_size[0] : blk_size[0] * blk_size[2];
        double area_x = dim == 2 ? blk_size[1] : blk_size[1] * blk_size[2];
        for (int d = 0; d < dim; d++) {
            double ts = 0; /* the left face's outward normal is -R e_x */
            for (int j = 0; j < dim; j++) ts -= sv[voigt_index(dim, d, j)] * R[3 * j];
            CHECK_NEAR(f[dim * kt + d], 0.25 * t.value[d] * area, 1e-12 * 1e6 * area);
            CHECK_NEAR(f[dim * ks + d], 0.25 * ts * area_x, 1e-12 * 8e6 * area_x);
        }
        fdem_model_destroy(m);
    }
}

/* A free block pushed by a traction on one face and pulled by a boundary
 * stress with a gradient on another, both ramped: their work is booked as
 * external work and the balance closes. */
static void work_is_external(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        int body;
        fdem_model *m = block_model(dim, blk_size, blk_div, &body);
        static const double ramp[4] = {0, 0, 2e-4, 1};
        fdem_constraint_def t = face(dim, blk_size, 0, blk_size[0]);
        t.kind = FDEM_CONSTRAINT_TRACTION;
        t.value[0] = 1e6;
        t.value[1] = 3e5;
        t.amplitude = ramp;
        t.amplitude_count = 2;
        add_constraint(m, &t);
        fdem_constraint_def s = face(dim, blk_size, dim - 1, blk_size[dim - 1]);
        s.amplitude = ramp;
        s.amplitude_count = 2;
        const double v[6] = {1e6, 2e6, 3e6, 0.5e6, 0.2e6, 0.1e6}, g[6] = {1e6, 1e6, 1e6, 0, 0, 1e6};
        add_stress(m, s, v, g, 0);
        build_finalize(m, 0.5);
        double worst = 0;
        while (fdem_get_time(m) < 4e-4) {
            step_once(m);
            worst = fmax(worst, fabs(fdem_get_energy(m).residual));
        }
        fdem_energy en = fdem_get_energy(m);
        fprintf(stderr, "  %dD work: external %.6g J, kinetic %.6g J, elastic %.6g J, worst "
                        "residual %.3g of the external work\n",
                dim, en.external_work, en.kinetic, en.elastic, worst / en.external_work);
        CHECK(en.external_work > 0, "%dD: no external work", dim);
        CHECK(worst < 1e-3 * en.external_work, "%dD: residual %g J", dim, worst);
        fdem_model_destroy(m);
    }
}

/* ----------------------------------------------- checkpoint, bad input */

static fdem_model *loaded_column(int dim)
{
    const double size[3] = {0.2, 0.3, 1};
    const int div[3] = {2, 2, 8};
    int body;
    fdem_model *m = block_model(dim, size, div, &body);
    static const double ramp[4] = {0, 0, 2e-3, 1};
    const double v[6] = {-1e5, -2e5, -3e5, 1e4, 2e4, 3e4}, g[6] = {1e4, 2e4, 3e4, 0, 0, 0};
    fdem_constraint_def s = face(dim, size, 0, size[0]);
    s.amplitude = ramp;
    s.amplitude_count = 2;
    add_stress(m, s, v, g, 0.5);
    fdem_constraint_def t = face(dim, size, dim - 1, size[dim - 1]);
    t.kind = FDEM_CONSTRAINT_TRACTION;
    t.value[0] = 1e5;
    t.value[dim - 1] = -1e5;
    t.amplitude = ramp;
    t.amplitude_count = 2;
    add_constraint(m, &t);
    fdem_constraint_def base = face(dim, size, dim - 1, 0);
    base.kind = FDEM_CONSTRAINT_FIX;
    base.fix_x = base.fix_y = base.fix_z = 1;
    add_constraint(m, &base);
    build_finalize(m, 0.5);
    return m;
}

static void checkpoint_carries_the_loads(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *straight = loaded_column(dim), *first = loaded_column(dim);
        for (int k = 0; k < 400; k++) step_once(straight);
        for (int k = 0; k < 200; k++) step_once(first);
        size_t size = fdem_checkpoint_size(first);
        void *buf = malloc(size);
        fdem_error err;
        if (!buf || fdem_checkpoint_write(first, buf, size)) build_die("checkpoint", &err);
        fdem_model *second = loaded_column(dim);
        if (fdem_checkpoint_read(second, buf, size, &err)) build_die("restore", &err);
        for (int k = 0; k < 200; k++) step_once(second);
        size_t bytes = sizeof(double) * (size_t)dim * (size_t)straight->node_count;
        CHECK(memcmp(straight->pos, second->pos, bytes) == 0, "%dD: positions differ", dim);
        fdem_energy a = fdem_get_energy(straight), b = fdem_get_energy(second);
        CHECK(a.external_work != 0 && memcmp(&a, &b, sizeof a) == 0, "%dD: accounts differ", dim);
        free(buf);
        fdem_model_destroy(straight);
        fdem_model_destroy(first);
        fdem_model_destroy(second);
    }
}

static void field_not_finite_is_refused(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        int body;
        fdem_model *m = block_model(dim, blk_size, blk_div, &body);
        fdem_constraint_def all = {.select = FDEM_SELECT_PART, .part = body};
        const double v[6] = {0, 0, 0, 0, 0, 0}, g[6] = {0, 0, NAN, 0, 0, NAN};
        add_stress(m, all, v, NULL, 0);
        int k = add_stress(m, all, v, g, 0);
        fdem_error err = {0};
        CHECK(fdem_model_finalize(m, &err) != 0, "%dD: a NaN gradient was accepted", dim);
        CHECK(err.kind == FDEM_ITEM_CONSTRAINT && err.item == k, "%dD: error names item %d: %s",
              dim, err.item, err.message);
        fdem_model_destroy(m);
    }
}

/* ------------------------------------------------------ case documents */

static const char *const case_2d =
    "{'materials': {'rock': {'density': 2700, 'young': 3e10, 'poisson': 0.25}},"
    " 'parts': [{'name': 'b', 'material': 'rock',"
    "            'rectangle': {'origin': [0, 0], 'size': [1, 2], 'divisions': [2, 4]}}],"
    " 'constraints': [{'part': 'b', 'boundary_stress': {'value': [-1e6, -2e6, 3e5],"
    "                  'gradient': [1e4, 2e4, 0], 'reference': 2}, 'amplitude': [[0, 0], [1, 1]]},"
    "                 {'box': [-1, 1.99, 2, 3], 'traction': [5e5, -1e6]}],"
    " 'time': {'end': 1e-4}}";

static const char *const case_3d =
    "{'dimension': 3, 'materials': {'rock': {'density': 2700, 'young': 3e10, 'poisson': 0.25}},"
    " 'parts': [{'name': 'b', 'material': 'rock',"
    "            'box': {'origin': [0, 0, 0], 'size': [1, 1, 2], 'divisions': [1, 1, 2]}}],"
    " 'constraints': [{'part': 'b', 'boundary_stress': {'value': [-1e6, -2e6, -3e6, 1, 2, 3]}},"
    "                 {'box': [-1, -1, 1.99, 2, 2, 3], 'traction': [5e5, -1e6, 2e5],"
    "                  'amplitude': [[0, 1]]}],"
    " 'time': {'end': 1e-4}}";

static void case_document_reaches_the_engine(void)
{
    fdem_model *m = expect_built(load(case_2d), NULL);
    if (m) {
        const fdem_constraint_def *b = &m->constraints[0].def, *t = &m->constraints[1].def;
        CHECK(b->kind == FDEM_CONSTRAINT_BOUNDARY_STRESS && t->kind == FDEM_CONSTRAINT_TRACTION,
              "kinds %d, %d", b->kind, t->kind);
        CHECK(b->stress_value[2] == 3e5 && b->stress_gradient[1] == 2e4 &&
                  b->stress_reference == 2 && b->amplitude_count == 2,
              "2D field not as written");
        CHECK(t->value[0] == 5e5 && t->value[1] == -1e6, "2D traction not as written");
        CHECK(m->constraints[1].facet_count == 2, "%d top edges", m->constraints[1].facet_count);
        fdem_model_destroy(m);
    }
    m = expect_built(load(case_3d), NULL);
    if (m) {
        const fdem_constraint_def *b = &m->constraints[0].def, *t = &m->constraints[1].def;
        CHECK(b->stress_value[5] == 3 && b->stress_gradient[2] == 0 && b->stress_reference == 0,
              "3D field not as written");
        CHECK(t->value[2] == 2e5 && t->amplitude_count == 1, "3D traction not as written");
        CHECK(m->constraints[1].facet_count == 2, "%d top faces", m->constraints[1].facet_count);
        fdem_model_destroy(m);
    }
    /* 1e300 Pa/m over the model's 2 m: infinite at its lowest node */
    json_t *doc = load(case_2d);
    edit(doc, "/constraints/0/boundary_stress/gradient", load("[0, 1e300, 0]"));
    edit(doc, "/constraints/0/boundary_stress/reference", load("1e10"));
    expect_doc(doc, GiB, 422, "/constraints/0/boundary_stress/gradient", "syy would be");
    doc = load(case_3d);
    edit(doc, "/constraints/0/boundary_stress/value", load("[1, 2, 3]"));
    expect_doc(doc, GiB, 422, "/constraints/0/boundary_stress/value",
               "[sxx, syy, szz, syz, sxz, sxy]");
}

CHECK_MAIN(T(uniform_field_on_a_rotated_block), T(shear_field_gives_the_tangential_resultant),
           T(gradient_resultant_and_moment_are_the_integrals),
           T(column_held_by_boundary_stress_and_roller_is_at_rest),
           T(column_held_by_boundary_stress_all_round_is_at_rest), T(traction_and_amplitude),
           T(work_is_external), T(checkpoint_carries_the_loads), T(field_not_finite_is_refused),
           T(case_document_reaches_the_engine))
