/*
 * test_element_fields.c - the derived output fields of contract 5.4
 * against closed forms: a block deformed by a uniform F (stretch, shear and
 * a translation) has the Green-Lagrange strain (F^T F - I)/2 in every
 * element, 2D and 3D, to 1e-6 (it is exact up to rounding: F of a linear
 * element reproduces a uniform map); the principal values of a uniaxial
 * stress rotated in the plane (2D) or by a general rotation (3D) are its
 * eigenvalues, descending, to 1e-9 relative; and the model's principal
 * stress field is that of its own stress field.
 */
#include "build_model.h"
#include "check.h"
#include "mesh/mesh_3d.h"
#include "model/model.h"

#include <stdlib.h>

/* x = F X + t on every node (F row-major, dim x dim). */
static void deform_uniformly(fdem_model *m, const double *F, const double *t)
{
    int D = m->dim;
    for (int i = 0; i < m->node_count; i++)
        for (int r = 0; r < D; r++) {
            double x = t[r];
            for (int c = 0; c < D; c++) x += F[D * r + c] * m->pos0[(size_t)D * (size_t)i + (size_t)c];
            m->pos[(size_t)D * (size_t)i + (size_t)r] = x;
        }
}

/* (F^T F - I)/2 in the Voigt order of fdem_element_stress. */
static void green_lagrange(int D, const double *F, double *voigt)
{
    static const int slot2[3][2] = {{0, 0}, {1, 1}, {0, 1}};
    static const int slot3[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
    int comps = D == 3 ? 6 : 3;
    for (int v = 0; v < comps; v++) {
        int i = D == 3 ? slot3[v][0] : slot2[v][0], j = D == 3 ? slot3[v][1] : slot2[v][1];
        double c = 0;
        for (int k = 0; k < D; k++) c += F[D * k + i] * F[D * k + j];
        voigt[v] = 0.5 * (c - (i == j));
    }
}

static void check_uniform_strain(fdem_model *m, const double *F, const double *t)
{
    int comps = fdem_stress_components(m);
    deform_uniformly(m, F, t);
    double want[6];
    green_lagrange(m->dim, F, want);
    double *E = malloc(sizeof(double) * (size_t)comps * (size_t)m->elem_count);
    fdem_element_strain(m, E);
    double worst = 0;
    for (int e = 0; e < m->elem_count; e++)
        for (int k = 0; k < comps; k++) worst = fmax(worst, fabs(E[comps * e + k] - want[k]));
    fprintf(stderr, "  %dD: largest strain error %.3g over %d elements (E_xx = %.6g)\n", m->dim,
            worst, m->elem_count, want[0]);
    CHECK(worst <= 1e-6, "strain off by %g", worst);
    free(E);
}

static void strain_of_uniform_stretch_2d(void)
{
    fdem_model *m = fdem_model_create();
    build_rectangle(m, build_material(m, 2700, 3e10, 0.25, 0, 0), 0, 0, 1, 0.5, 6, 3);
    build_finalize(m, 0.5);
    const double F[4] = {1.05, 0.02, -0.01, 0.97}, t[2] = {0.3, -0.2};
    check_uniform_strain(m, F, t);
    fdem_model_destroy(m);
}

static void strain_of_uniform_stretch_3d(void)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    CHECK(fdem_set_dimension(m, 3, &err) == 0, "%s", err.message);
    int rock = build_material(m, 2000, 1e9, 0.25, 0, 0);
    const double origin[3] = {0, 0, 0}, size[3] = {0.4, 0.2, 0.3};
    const int div[3] = {3, 2, 2};
    fdem_tet_mesh mesh;
    if (fdem_tet_mesh_box(origin, size, div, &mesh, &err)) build_die("box", &err);
    if (fdem_add_part_3d(m, &mesh, rock, 0, &err) < 0) build_die("part", &err);
    fdem_tet_mesh_free(&mesh);
    if (fdem_model_finalize(m, &err)) build_die("finalize", &err);
    const double F[9] = {1.04, 0.01, 0.02, -0.015, 0.98, 0.005, 0.01, 0.0, 1.02};
    const double t[3] = {0.1, 0.2, -0.3};
    check_uniform_strain(m, F, t);
    fdem_model_destroy(m);
}

/* sigma = s n n^T, written in Voigt order for the dimension. */
static void principal_of_rotated_uniaxial_2d(void)
{
    const double s = -7.5e6, angle = 0.61;
    double c = cos(angle), n = sin(angle);
    const double voigt[3] = {s * c * c, s * n * n, s * c * n};
    double p[2];
    fdem_principal_values(2, voigt, p);
    CHECK_NEAR(p[0], 0, 1e-9 * fabs(s));
    CHECK_REL(p[1], s, 1e-9);
    const double tension[3] = {-s * c * c, -s * n * n, -s * c * n};
    fdem_principal_values(2, tension, p);
    CHECK_REL(p[0], -s, 1e-9);
    CHECK_NEAR(p[1], 0, 1e-9 * fabs(s));
}

/* R diag(l) R^T with R a rotation about a skew axis. */
static void principal_of_rotated_stress_3d(void)
{
    const double l[3] = {-3e6, 12e6, 5e5}; /* unsorted on purpose */
    double axis[3] = {0.3, -0.5, 0.8}, norm = sqrt(0.09 + 0.25 + 0.64), a = 1.1;
    for (int k = 0; k < 3; k++) axis[k] /= norm;
    double K[3][3] = {{0, -axis[2], axis[1]}, {axis[2], 0, -axis[0]}, {-axis[1], axis[0], 0}};
    double R[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double kk = 0;
            for (int k = 0; k < 3; k++) kk += K[i][k] * K[k][j];
            R[i][j] = (i == j) + sin(a) * K[i][j] + (1 - cos(a)) * kk;
        }
    double S[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            S[i][j] = 0;
            for (int k = 0; k < 3; k++) S[i][j] += R[i][k] * l[k] * R[j][k];
        }
    const double voigt[6] = {S[0][0], S[1][1], S[2][2], S[1][2], S[0][2], S[0][1]};
    double p[3];
    fdem_principal_values(3, voigt, p);
    const double want[3] = {12e6, 5e5, -3e6};
    for (int k = 0; k < 3; k++) CHECK_REL(p[k], want[k], 1e-9);
    /* uniaxial along the same axis: one non-zero value */
    double U[6];
    const double s = 4e6, n[3] = {axis[0], axis[1], axis[2]};
    const int ij[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
    for (int v = 0; v < 6; v++) U[v] = s * n[ij[v][0]] * n[ij[v][1]];
    fdem_principal_values(3, U, p);
    CHECK_REL(p[0], s, 1e-9);
    CHECK_NEAR(p[1], 0, 1e-9 * s);
    CHECK_NEAR(p[2], 0, 1e-9 * s);
}

/* The model's field is the principal values of its own stress field. */
static void principal_field_matches_stress(void)
{
    fdem_model *m = fdem_model_create();
    build_rectangle(m, build_material(m, 2700, 3e10, 0.25, 0, 0), 0, 0, 1, 1, 3, 3);
    build_finalize(m, 0.5);
    const double F[4] = {1.001, 0.0004, 0.0002, 0.9985}, t[2] = {0, 0};
    deform_uniformly(m, F, t);
    int E = m->elem_count;
    double *stress = malloc(sizeof(double) * 3 * (size_t)E), *p = malloc(sizeof(double) * 2 * (size_t)E);
    fdem_element_stress(m, stress);
    fdem_element_principal_stress(m, p);
    for (int e = 0; e < E; e++) {
        double want[2];
        fdem_principal_values(2, stress + 3 * e, want);
        CHECK_REL(p[2 * e], want[0], 1e-15);
        CHECK_REL(p[2 * e + 1], want[1], 1e-15);
        CHECK(p[2 * e] >= p[2 * e + 1], "element %d not descending", e);
        /* invariants: trace and determinant of the in-plane tensor */
        double s = stress[3 * e], y = stress[3 * e + 1], xy = stress[3 * e + 2];
        CHECK_REL(p[2 * e] + p[2 * e + 1], s + y, 1e-9);
        CHECK_REL(p[2 * e] * p[2 * e + 1], s * y - xy * xy, 1e-9);
    }
    free(stress);
    free(p);
    fdem_model_destroy(m);
}

CHECK_MAIN(T(strain_of_uniform_stretch_2d), T(strain_of_uniform_stretch_3d),
           T(principal_of_rotated_uniaxial_2d), T(principal_of_rotated_stress_3d),
           T(principal_field_matches_stress))
