/*
 * test_element.c - the constant-strain triangle at finite strain: a rigid
 * rotation of any size gives zero stress, a small uniaxial strain gives the
 * plane-strain linear-elastic stress, internal forces sum to zero, and the
 * strain energy matches 1/2 sigma:eps V at small strain.
 */
#include "build_model.h"
#include "check.h"
#include "model/model.h"
#include "element/element.h"
#include "power_iteration.h"

static fdem_model *unit_block(double E, double nu)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 1000, E, nu, 0, 0);
    build_rectangle(m, mat, 0, 0, 1, 1, 4, 4);
    build_finalize(m, 0.5);
    return m;
}

/* Moves every node to x = F X + t. */
static void deform(fdem_model *m, double a, double b, double c, double d, double tx, double ty)
{
    for (int i = 0; i < m->node_count; i++) {
        double X = m->pos0[2 * i], Y = m->pos0[2 * i + 1];
        m->pos[2 * i] = a * X + b * Y + tx;
        m->pos[2 * i + 1] = c * X + d * Y + ty;
    }
}

static double max_abs_stress(fdem_model *m)
{
    double *s = malloc(sizeof(double) * 3 * (size_t)m->elem_count), mx = 0;
    fdem_element_stress(m, s);
    for (int k = 0; k < 3 * m->elem_count; k++) mx = fmax(mx, fabs(s[k]));
    free(s);
    return mx;
}

static void rigid_rotation_gives_zero_stress(void)
{
    double E = 3e10;
    fdem_model *m = unit_block(E, 0.25);
    double angles[] = {M_PI / 2, M_PI, 0.3, -2.0};
    for (int k = 0; k < 4; k++) {
        double co = cos(angles[k]), si = sin(angles[k]);
        deform(m, co, -si, si, co, 5.0, -3.0);
        /* round-off of a 30 GPa modulus times 1e-16 strain */
        CHECK(max_abs_stress(m) < 1e-5 * E * 1e-9, "rotation %.2f rad: stress %g Pa", angles[k],
              max_abs_stress(m));
    }
    fdem_model_destroy(m);
}

static void small_strain_is_linear_plane_strain(void)
{
    double E = 3e10, nu = 0.25, eps = 1e-6;
    fdem_model *m = unit_block(E, nu);
    deform(m, 1 + eps, 0, 0, 1, 0, 0);
    double *s = malloc(sizeof(double) * 3 * (size_t)m->elem_count);
    fdem_element_stress(m, s);
    double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    for (int e = 0; e < m->elem_count; e++) {
        CHECK_REL(s[3 * e], (lambda + 2 * mu) * eps, 1e-5);
        CHECK_REL(s[3 * e + 1], lambda * eps, 1e-5);
        CHECK_NEAR(s[3 * e + 2], 0, 1e-9 * E * eps);
    }
    /* simple shear gamma: sxy = mu gamma */
    deform(m, 1, eps, 0, 1, 0, 0);
    fdem_element_stress(m, s);
    for (int e = 0; e < m->elem_count; e++) CHECK_REL(s[3 * e + 2], mu * eps, 1e-5);
    free(s);
    fdem_model_destroy(m);
}

static void forces_balance_and_energy_matches(void)
{
    double E = 1e9, nu = 0.3, eps = 1e-5;
    fdem_model *m = unit_block(E, nu);
    deform(m, 1 + eps, 0, 0, 1 - 0.5 * eps, 0, 0);
    memset(m->force, 0, sizeof(double) * 2 * (size_t)m->node_count);
    element_forces(m);
    double fx = 0, fy = 0, fmax_ = 0;
    for (int i = 0; i < m->node_count; i++) {
        fx += m->force[2 * i];
        fy += m->force[2 * i + 1];
        fmax_ = fmax(fmax_, fabs(m->force[2 * i]));
    }
    CHECK(fabs(fx) < 1e-12 * fmax_ && fabs(fy) < 1e-12 * fmax_, "sum %g %g of max %g", fx, fy, fmax_);
    double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    double exx = eps, eyy = -0.5 * eps;
    double sxx = (lambda + 2 * mu) * exx + lambda * eyy, syy = lambda * exx + (lambda + 2 * mu) * eyy;
    double want = 0.5 * (sxx * exx + syy * eyy) * 1.0; /* unit area */
    CHECK_REL(m->elastic_energy, want, 1e-4);
    fdem_model_destroy(m);
}

static void stretched_block_pulls_nodes_inward(void)
{
    fdem_model *m = unit_block(1e9, 0.0);
    deform(m, 1.01, 0, 0, 1, 0, 0);
    memset(m->force, 0, sizeof(double) * 2 * (size_t)m->node_count);
    element_forces(m);
    /* right edge nodes (x = 1) must be pulled back in -x */
    int checked = 0;
    for (int i = 0; i < m->node_count; i++)
        if (m->pos0[2 * i] > 0.999) {
            CHECK(m->force[2 * i] < 0, "node %d force %g", i, m->force[2 * i]);
            checked++;
        }
    CHECK(checked == 5, "checked %d right-edge nodes", checked);
    fdem_model_destroy(m);
}

static void inverted_element_stays_finite(void)
{
    fdem_model *m = unit_block(1e9, 0.3);
    deform(m, -0.2, 0, 0, 1, 0, 0); /* turned inside out */
    memset(m->force, 0, sizeof(double) * 2 * (size_t)m->node_count);
    element_forces(m);
    for (int i = 0; i < 2 * m->node_count; i++) CHECK(isfinite(m->force[i]), "force %d", i);
    fdem_model_destroy(m);
}

/* element.c's ln J: series near 1, log() elsewhere (not in model.h: it is
 * the kernel's private approximation, exported for this test only). */
double element_log_near1(double J);

/* The series must stay within a few ulps of log() over both of its ranges
 * (|J - 1| <= 2^-10 and <= 2^-6), at their edges, and be exact elsewhere. */
static void log_series_matches_log(void)
{
    double worst = 0;
    int n = 200000;
    for (int k = -n; k <= n; k++) {
        double x = 0x1p-6 * (double)k / n * 1.001; /* a little past the edge */
        for (int s = 0; s < 2; s++) {
            double J = 1.0 + (s ? x * 0x1p-4 : x); /* also sweep |x| <= 2^-10 finely */
            double want = log(J), got = element_log_near1(J);
            double err = want == 0 ? fabs(got) : fabs(got - want) / fabs(want);
            if (err > worst) worst = err;
        }
    }
    CHECK(worst < 1e-15, "series ln J: worst relative error %.3g", worst);
    double edges[] = {1 + 0x1p-10, 1 - 0x1p-10, 1 + 0x1p-6, 1 - 0x1p-6, 1 + 1e-300, 1, 0.5, 2, 0.05, 7};
    for (int k = 0; k < (int)(sizeof edges / sizeof edges[0]); k++) {
        double J = edges[k], want = log(J), got = element_log_near1(J);
        CHECK(want == 0 ? got == 0 : fabs(got - want) <= 1e-15 * fabs(want), "ln %.17g: %.17g vs %.17g",
              J, got, want);
    }
    CHECK(element_log_near1(1.5) == log(1.5) && element_log_near1(0.9) == log(0.9),
          "outside the series' range ln J must be log()");
}

/* Node 0 of each element takes exactly minus the (rounded) sum of the other
 * two forces, so (f1 + f2) + f0 == 0 in floating point, under any
 * deformation. */
static void element_forces_sum_to_zero_exactly(void)
{
    fdem_model *m = unit_block(3e10, 0.25);
    deform(m, 1.003, 0.02, -0.01, 0.995, 0.3, 0.1);
    element_hot *all = m->elem;
    int count = m->elem_count;
    scatter_plan plan = m->elem_plan; /* covers the whole mesh: run one element instead */
    m->elem_plan = (scatter_plan){.item_count = 1};
    for (int e = 0; e < count; e++) {
        memset(m->force, 0, sizeof(double) * 2 * (size_t)m->node_count);
        m->elem = all + e; /* this element on its own */
        m->elem_count = 1;
        element_forces(m);
        const int32_t *nd = all[e].node;
        for (int d = 0; d < 2; d++) {
            double f0 = m->force[2 * nd[0] + d], f1 = m->force[2 * nd[1] + d];
            double f2 = m->force[2 * nd[2] + d];
            CHECK((f1 + f2) + f0 == 0 && f0 != 0, "element %d dof %d: %g %g %g", e, d, f0, f1, f2);
        }
    }
    m->elem = all;
    m->elem_count = count;
    m->elem_plan = plan;
    fdem_model_destroy(m);
}

/* One scalene triangle of material (rho 2000, E 1 GPa, nu, damping xi). */
static fdem_model *scalene_element(double nu, double xi)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 2000, 1e9, nu, xi, 0);
    fdem_mesh mesh = {3, 1, (double[]){0, 0, 0.1, 0, 0.03, 0.05}, (int32_t[]){0, 1, 2}};
    fdem_error err;
    if (fdem_add_part(m, &mesh, mat, 0, &err) < 0) build_die("part", &err);
    build_finalize(m, 1.0);
    return m;
}

/* The element's stiffness (velocity = 0) or viscosity (positions = pos0)
 * matrix by central differences of element_forces: -d f / d x or -d f / d v. */
static void element_matrix(fdem_model *m, double *wrt, double K[6][6])
{
    double h = 1e-9;
    memcpy(m->pos, m->pos0, sizeof(double) * 6);
    memset(m->vel, 0, sizeof(double) * 6);
    for (int j = 0; j < 6; j++) {
        double f[2][6], keep = wrt[j];
        for (int sgn = 0; sgn < 2; sgn++) {
            wrt[j] = keep + (sgn ? -h : h);
            memset(m->force, 0, sizeof(double) * 6);
            element_forces(m);
            memcpy(f[sgn], m->force, sizeof(double) * 6);
        }
        wrt[j] = keep;
        for (int i = 0; i < 6; i++) K[i][j] = -(f[0][i] - f[1][i]) / (2 * h);
    }
}

/* Largest eigenvalue of M^-1 K (lumped M) by power iteration. */
static double largest_mode(const fdem_model *m, double K[6][6])
{
    const double start[6] = {1, -0.3, 0.2, 0.7, -0.5, 0.1};
    double mass[6];
    for (int i = 0; i < 6; i++) mass[i] = m->mass[i / 2];
    return largest_eigenvalue_over_mass(6, &K[0][0], mass, start, 2000);
}

/* The stable step is 2 / omega_max of the element with its lumped masses:
 * here omega_max comes from the element's own forces (a stiffness matrix by
 * central differences of element_forces at small strain, then power
 * iteration on M^-1 K), for one scalene triangle at three Poisson ratios. */
static void stable_step_is_that_of_the_fastest_element_mode(void)
{
    const double nus[3] = {0.0, 0.3, 0.45};
    for (int t = 0; t < 3; t++) {
        fdem_model *m = scalene_element(nus[t], 0);
        double K[6][6];
        element_matrix(m, m->pos, K);
        double want = 2 / sqrt(largest_mode(m, K));
        CHECK_REL(fdem_stable_dt(m), want, 1e-4);
        fprintf(stderr, "  nu %.2f: stable step %.6g s, 2/omega_max %.6g s, h_min/c %.6g s\n",
                nus[t], fdem_stable_dt(m), want,
                m->elem_h[0] / sqrt((m->materials[0].lambda + 2 * m->materials[0].mu) / 2000));
        fdem_model_destroy(m);
    }
}

/* With damping, the limit of the lagged-velocity central difference is
 * 2 / (sqrt(omega^2 + c^2/4) + c/2) with omega^2 the largest eigenvalue of
 * M^-1 K and c that of M^-1 C, both by power iteration on the element's own
 * forces. The material's damping fraction is not the fastest mode's
 * damping ratio (eta is set from the smallest altitude), so the older
 * (2/omega)(sqrt(1 + xi^2) - xi) was too large here. */
static void damped_stable_step_is_that_of_the_fastest_damped_mode(void)
{
    const double xis[3] = {0.1, 0.5, 0.9};
    for (int t = 0; t < 3; t++) {
        fdem_model *m = scalene_element(0.3, xis[t]);
        double K[6][6], C[6][6];
        element_matrix(m, m->pos, K);
        element_matrix(m, m->vel, C);
        double omega2 = largest_mode(m, K), rate = largest_mode(m, C);
        double want = 2 / (sqrt(omega2 + 0.25 * rate * rate) + 0.5 * rate);
        double by_xi = 2 / sqrt(omega2) * (sqrt(1 + xis[t] * xis[t]) - xis[t]);
        CHECK_REL(fdem_stable_dt(m), want, 1e-4);
        fprintf(stderr, "  xi %.1f: stable step %.6g s, power iteration %.6g s, by xi %.6g s "
                "(fastest mode's damping ratio %.3f)\n",
                xis[t], fdem_stable_dt(m), want, by_xi, rate / (2 * sqrt(omega2)));
        fdem_model_destroy(m);
    }
}

/* A strongly damped element at safety 1 must not grow: the scheme is run
 * from a velocity in every mode, and its elastic plus kinetic energy, which
 * damping can only take away, must stay at or below the start's (plus
 * round-off) for 2000 steps. At the older step it grows without bound. */
static void strongly_damped_element_at_safety_one_stays_bounded(void)
{
    const double xis[2] = {0.5, 0.9};
    for (int t = 0; t < 2; t++) {
        fdem_model *m = scalene_element(0.3, xis[t]);
        const double v0[6] = {0.01, -0.02, -0.015, 0.005, 0.003, 0.012};
        memcpy(m->vel, v0, sizeof v0);
        double start = 0, worst = 0;
        for (int i = 0; i < 6; i++) start += 0.5 * m->mass[i / 2] * v0[i] * v0[i];
        fdem_error err;
        for (int s = 0; s < 2000; s++) {
            if (fdem_step(m, &err)) break;
            fdem_energy e = fdem_get_energy(m);
            double now = e.kinetic + e.elastic;
            if (!(now <= worst)) worst = isfinite(now) ? now : INFINITY;
        }
        CHECK(worst <= start * (1 + 1e-9), "xi %.1f: energy rose to %.6g of %.6g", xis[t],
              worst, start);
        fdem_model_destroy(m);
    }
}

CHECK_MAIN(T(stable_step_is_that_of_the_fastest_element_mode),
           T(damped_stable_step_is_that_of_the_fastest_damped_mode),
           T(strongly_damped_element_at_safety_one_stays_bounded), T(rigid_rotation_gives_zero_stress), T(small_strain_is_linear_plane_strain),
           T(forces_balance_and_energy_matches), T(stretched_block_pulls_nodes_inward),
           T(inverted_element_stays_finite), T(log_series_matches_log),
           T(element_forces_sum_to_zero_exactly))
