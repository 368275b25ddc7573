/*
 * test_element_tet.c - the tetrahedron kernel against closed forms: a rigid
 * rotation of 90 degrees about a skew axis is stress-free; small uniaxial
 * and shear strains give linear elasticity; nodal forces are minus the
 * derivative of the strain energy (central differences), sum to zero and
 * have no moment; a patch of tetrahedra around an interior node under a
 * homogeneous deformation has the homogeneous stress everywhere and no net
 * force on the interior node; the viscous stress is 2 eta D and a rigid
 * spin is not damped; the height and stable step of a regular tetrahedron.
 */
#include "check.h"
#include "kernel/element_tet.h"
#include "rotation_3d.h"

#include <stdint.h>
#include <stdlib.h>

static const double E = 10e9, NU = 0.25;

static tet_law law_of(double eta)
{
    tet_law L = {E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU)), eta};
    return L;
}

/* An irregular, positively oriented tetrahedron. */
static const double base[12] = {0.1, -0.2, 0.05, 1.3, 0.1, -0.1, 0.2, 1.1, 0.3, 0.4, 0.3, 0.9};
static const int32_t quad[4] = {0, 1, 2, 3};

/* x = A X + t at every node */
static void map_affine(const double *X, int nodes, const double A[9], const double t[3], double *x)
{
    for (int n = 0; n < nodes; n++)
        for (int i = 0; i < 3; i++)
            x[3 * n + i] = A[3 * i] * X[3 * n] + A[3 * i + 1] * X[3 * n + 1] +
                           A[3 * i + 2] * X[3 * n + 2] + t[i];
}

static void test_tet_prepare_geometry(void)
{
    tet_geometry g;
    CHECK(tet_prepare(base, quad, &g) == 0, "prepare failed");
    CHECK(g.volume0 > 0, "volume %g", g.volume0);
    /* [X]^-1 [X] = I */
    double X[3][3];
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) X[i][k] = base[3 * (k + 1) + i] - base[i];
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) {
            double v = 0;
            for (int i = 0; i < 3; i++) v += g.xinv[3 * k + i] * X[i][j];
            CHECK_NEAR(v, k == j ? 1.0 : 0.0, 1e-14);
        }
    /* inverted and flat elements are refused */
    int32_t swapped[4] = {0, 2, 1, 3};
    CHECK(tet_prepare(base, swapped, &g) != 0, "an inverted element was accepted");
    double flat[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    CHECK(tet_prepare(flat, quad, &g) != 0, "a flat element was accepted");
    /* regular tetrahedron of edge a: V = a^3/(6 sqrt 2), h = a sqrt(2/3) */
    double a = 2.0;
    double reg[12] = {0, 0, 0, a, 0, 0, a / 2, a * sqrt(3) / 2, 0,
                      a / 2, a * sqrt(3) / 6, a * sqrt(2.0 / 3.0)};
    CHECK(tet_prepare(reg, quad, &g) == 0, "regular: prepare failed");
    CHECK_REL(g.volume0, a * a * a / (6 * sqrt(2)), 1e-14);
    CHECK_REL(g.height, a * sqrt(2.0 / 3.0), 1e-14);
    tet_law L = law_of(0);
    double c = sqrt((L.lambda + 2 * L.mu) / 2700.0);
    CHECK_REL(tet_stable_dt(g.height, L.lambda, L.mu, 2700.0, 0), g.height / c, 1e-14);
    CHECK(tet_stable_dt(g.height, L.lambda, L.mu, 2700.0, 0.1) < g.height / c,
          "damping must shorten the step");
}

static void test_tet_rigid_rotation_stress_free(void)
{
    tet_geometry g;
    tet_prepare(base, quad, &g);
    double R[9], x[12], f[12], sigma[6], t[3] = {5.0, -3.0, 7.5};
    double axis[3] = {1.0, -2.0, 0.7};
    rotation(axis, M_PI / 2, R);
    map_affine(base, 4, R, t, x);
    tet_law L = law_of(0);
    double w = tet_forces(x, NULL, quad, &g, &L, f, sigma);
    for (int k = 0; k < 6; k++) CHECK(fabs(sigma[k]) <= 1e-9 * E, "sigma[%d] = %g", k, sigma[k]);
    CHECK(fabs(w) <= 1e-9 * E * g.volume0, "energy %g", w);
    for (int k = 0; k < 12; k++) CHECK(fabs(f[k]) <= 1e-9 * E, "f[%d] = %g", k, f[k]);
    /* and any other angle about any axis */
    double axis2[3] = {0.3, 0.9, -0.4};
    rotation(axis2, 2.5, R);
    map_affine(base, 4, R, t, x);
    tet_forces(x, NULL, quad, &g, &L, f, sigma);
    for (int k = 0; k < 6; k++) CHECK(fabs(sigma[k]) <= 1e-9 * E, "2.5 rad: sigma[%d] = %g", k, sigma[k]);
}

static void test_tet_small_strain_is_linear(void)
{
    tet_geometry g;
    tet_prepare(base, quad, &g);
    tet_law L = law_of(0);
    double eps = 1e-7, x[12], sigma[6], f[12], t[3] = {0, 0, 0};
    /* uniaxial strain along y: syy = (lambda + 2mu) eps, sxx = szz = lambda eps */
    double A[9] = {1, 0, 0, 0, 1 + eps, 0, 0, 0, 1};
    map_affine(base, 4, A, t, x);
    tet_forces(x, NULL, quad, &g, &L, f, sigma);
    CHECK_REL(sigma[1], (L.lambda + 2 * L.mu) * eps, 1e-6);
    CHECK_REL(sigma[0], L.lambda * eps, 1e-6);
    CHECK_REL(sigma[2], L.lambda * eps, 1e-6);
    for (int k = 3; k < 6; k++) CHECK(fabs(sigma[k]) <= 1e-6 * L.mu * eps, "shear %d = %g", k, sigma[k]);
    /* simple shear gamma in the xz plane: sxz = mu gamma, the rest ~0 */
    double S[9] = {1, 0, eps, 0, 1, 0, 0, 0, 1};
    map_affine(base, 4, S, t, x);
    tet_forces(x, NULL, quad, &g, &L, f, sigma);
    CHECK_REL(sigma[4], L.mu * eps, 1e-6);
    CHECK(fabs(sigma[3]) <= 1e-6 * L.mu * eps && fabs(sigma[5]) <= 1e-6 * L.mu * eps,
          "yz %g xy %g", sigma[3], sigma[5]);
    for (int k = 0; k < 3; k++) CHECK(fabs(sigma[k]) <= 1e-6 * L.mu * eps, "normal %d = %g", k, sigma[k]);
}

/* A finite, rotated deformation; every node moved. */
static void deformed(double *x)
{
    double R[9], A[9], M[9], t[3] = {0.2, -0.1, 0.4};
    double axis[3] = {0.5, 0.2, -1.0};
    rotation(axis, 0.7, R);
    double U[9] = {1.08, 0.03, -0.02, 0.03, 0.95, 0.04, -0.02, 0.04, 1.03};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            M[3 * i + j] = 0;
            for (int k = 0; k < 3; k++) M[3 * i + j] += R[3 * i + k] * U[3 * k + j];
        }
    memcpy(A, M, sizeof A);
    map_affine(base, 4, A, t, x);
    x[4] += 0.02; /* and non-affine: node 1 nudged */
    x[9] -= 0.015;
}

static void test_tet_forces_are_energy_gradient(void)
{
    tet_geometry g;
    tet_prepare(base, quad, &g);
    tet_law L = law_of(0);
    double x[12], f[12], fd[12];
    deformed(x);
    tet_forces(x, NULL, quad, &g, &L, f, NULL);
    double largest = 0;
    for (int k = 0; k < 12; k++) {
        double h = 1e-6, keep = x[k], tmp[12];
        x[k] = keep + h;
        double wp = tet_forces(x, NULL, quad, &g, &L, tmp, NULL);
        x[k] = keep - h;
        double wm = tet_forces(x, NULL, quad, &g, &L, tmp, NULL);
        x[k] = keep;
        fd[k] = -(wp - wm) / (2 * h);
        largest = fmax(largest, fabs(f[k]));
    }
    CHECK(largest > 1e7, "test deformation too small: |f| max %g", largest);
    for (int k = 0; k < 12; k++)
        CHECK(fabs(f[k] - fd[k]) <= 1e-6 * largest, "f[%d] = %.9g, -dW/dx = %.9g", k, f[k], fd[k]);
}

static void test_tet_forces_balance(void)
{
    tet_geometry g;
    tet_prepare(base, quad, &g);
    tet_law L = law_of(0.05 * sqrt(2700.0 * 18e9));
    double x[12], v[12], f[12];
    deformed(x);
    for (int k = 0; k < 12; k++) v[k] = sin(1.0 + 3.7 * k); /* any velocities */
    tet_forces(x, v, quad, &g, &L, f, NULL);
    double scale = 0, sum[3] = {0, 0, 0}, moment[3] = {0, 0, 0};
    for (int a = 0; a < 4; a++) {
        const double *p = x + 3 * a, *fa = f + 3 * a;
        for (int i = 0; i < 3; i++) sum[i] += fa[i], scale = fmax(scale, fabs(fa[i]));
        moment[0] += p[1] * fa[2] - p[2] * fa[1];
        moment[1] += p[2] * fa[0] - p[0] * fa[2];
        moment[2] += p[0] * fa[1] - p[1] * fa[0];
    }
    for (int i = 0; i < 3; i++) {
        CHECK(fabs(sum[i]) <= 1e-14 * scale, "force sum[%d] = %g of %g", i, sum[i], scale);
        CHECK(fabs(moment[i]) <= 1e-12 * scale, "moment[%d] = %g of %g", i, moment[i], scale);
    }
}

static void test_tet_viscous_stress(void)
{
    tet_geometry g;
    tet_prepare(base, quad, &g);
    double eta = 1e6, v[12], x[12], f[12], sigma[6], zero[3] = {0, 0, 0};
    tet_law L = law_of(eta);
    memcpy(x, base, sizeof x);
    /* v = G x with G symmetric: sigma = 2 eta G */
    double G[9] = {0.3, 0.1, -0.2, 0.1, -0.5, 0.05, -0.2, 0.05, 0.2};
    map_affine(base, 4, G, zero, v);
    tet_forces(x, v, quad, &g, &L, f, sigma);
    const int ij[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
    for (int k = 0; k < 6; k++)
        CHECK_NEAR(sigma[k], 2 * eta * G[3 * ij[k][0] + ij[k][1]], 1e-9 * eta);
    /* a rigid spin v = w x X is not damped */
    double W[9] = {0, -0.4, 0.3, 0.4, 0, -0.8, -0.3, 0.8, 0};
    map_affine(base, 4, W, zero, v);
    tet_forces(x, v, quad, &g, &L, f, sigma);
    for (int k = 0; k < 6; k++) CHECK(fabs(sigma[k]) <= 1e-9 * eta, "spin: sigma[%d] = %g", k, sigma[k]);
}

/* A unit cube of 12 tetrahedra, each a face triangle of the cube joined to
 * the centre node 8: under x = A X + t every element has the stress of A,
 * and the forces on the interior node cancel. */
static void test_tet_patch_homogeneous(void)
{
    double X[27];
    for (int n = 0; n < 8; n++) X[3 * n] = n & 1, X[3 * n + 1] = (n >> 1) & 1, X[3 * n + 2] = (n >> 2) & 1;
    X[24] = X[25] = X[26] = 0.5;
    static const int faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                    {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
    int32_t tets[12][4];
    for (int k = 0; k < 6; k++)
        for (int h = 0; h < 2; h++) {
            int32_t *t = tets[2 * k + h];
            t[0] = 8, t[1] = faces[k][0], t[2] = faces[k][1 + h], t[3] = faces[k][2 + h];
            if (tet_volume(X + 3 * t[0], X + 3 * t[1], X + 3 * t[2], X + 3 * t[3]) < 0) {
                int32_t s = t[2]; t[2] = t[3]; t[3] = s;
            }
        }
    double A[9] = {1.01, 0.002, -0.003, 0.001, 0.995, 0.004, 0.0, -0.002, 1.006}, t[3] = {1, 2, 3};
    double x[27], F[9] = {0}, want[6];
    map_affine(X, 9, A, t, x);
    memcpy(F, A, sizeof F);
    tet_law L = law_of(0);
    tet_stress(F, L.lambda, L.mu, want, NULL);
    double centre[3] = {0, 0, 0}, volume = 0, energy = 0;
    for (int e = 0; e < 12; e++) {
        tet_geometry g;
        CHECK(tet_prepare(X, tets[e], &g) == 0, "patch element %d not prepared", e);
        double f[12], sigma[6];
        energy += tet_forces(x, NULL, tets[e], &g, &L, f, sigma);
        volume += g.volume0;
        for (int k = 0; k < 6; k++) CHECK_NEAR(sigma[k], want[k], 1e-9 * fabs(want[0]));
        for (int i = 0; i < 3; i++) centre[i] += f[i]; /* node 8 is node 0 of each */
    }
    CHECK_REL(volume, 1.0, 1e-14);
    double w = tet_stress(F, L.lambda, L.mu, want, NULL);
    CHECK_REL(energy, w, 1e-12);
    for (int i = 0; i < 3; i++)
        CHECK(fabs(centre[i]) <= 1e-9 * fabs(want[0]), "interior node force[%d] = %g", i, centre[i]);
}

static void test_tet_squashed_stays_finite(void)
{
    tet_geometry g;
    tet_prepare(base, quad, &g);
    tet_law L = law_of(0);
    double x[12], f[12], sigma[6], t[3] = {0, 0, 0};
    double A[9] = {1, 0, 0, 0, 1, 0, 0, 0, -0.2}; /* inverted through zero volume */
    map_affine(base, 4, A, t, x);
    tet_forces(x, NULL, quad, &g, &L, f, sigma);
    for (int k = 0; k < 12; k++) CHECK(isfinite(f[k]), "f[%d] not finite", k);
    CHECK(sigma[2] < 0, "a squashed element must push open: szz = %g", sigma[2]);
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        {"test_tet_prepare_geometry", test_tet_prepare_geometry},
        {"test_tet_rigid_rotation_stress_free", test_tet_rigid_rotation_stress_free},
        {"test_tet_small_strain_is_linear", test_tet_small_strain_is_linear},
        {"test_tet_forces_are_energy_gradient", test_tet_forces_are_energy_gradient},
        {"test_tet_forces_balance", test_tet_forces_balance},
        {"test_tet_viscous_stress", test_tet_viscous_stress},
        {"test_tet_patch_homogeneous", test_tet_patch_homogeneous},
        {"test_tet_squashed_stays_finite", test_tet_squashed_stays_finite},
    };
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
