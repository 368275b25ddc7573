/*
 * test_element.c - the constant-strain triangle at finite strain: a rigid
 * rotation of any size gives zero stress, a small uniaxial strain gives the
 * plane-strain linear-elastic stress, internal forces sum to zero, and the
 * strain energy matches 1/2 sigma:eps V at small strain.
 */
#include "build_model.h"
#include "check.h"
#include "model.h"

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
    element_forces(m, 0);
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
    element_forces(m, 0);
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
    element_forces(m, 0);
    for (int i = 0; i < 2 * m->node_count; i++) CHECK(isfinite(m->force[i]), "force %d", i);
    fdem_model_destroy(m);
}

CHECK_MAIN(T(rigid_rotation_gives_zero_stress), T(small_strain_is_linear_plane_strain),
           T(forces_balance_and_energy_matches), T(stretched_block_pulls_nodes_inward),
           T(inverted_element_stays_finite))
