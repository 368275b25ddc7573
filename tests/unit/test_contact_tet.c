/*
 * test_contact_tet.c - potential contact between tetrahedra: no force
 * without overlap; forces that sum to zero and have no net moment (to
 * round-off); a force that grows with the overlap; the closed-form
 * integral for a flat face pressed uniformly into a tetrahedron; and no
 * sideways force or torque in a configuration symmetric about the axis.
 */
#include "check.h"
#include "kernel/contact_tet.h"

#include <stdint.h>
#include <string.h>

static const int32_t A[4] = {0, 1, 2, 3}, B[4] = {4, 5, 6, 7};

/* A tetrahedron with its base (vertex on +x) in the plane z = z0 around the
 * z axis, base radius r, apex at z0 + h (h < 0: apex down). */
static void axial_tet(double *p, double r, double z0, double h)
{
    double base[3][2] = {{r, 0}, {-r / 2, r * sqrt(3) / 2}, {-r / 2, -r * sqrt(3) / 2}};
    for (int v = 0; v < 3; v++) p[3 * v] = base[v][0], p[3 * v + 1] = base[v][1], p[3 * v + 2] = z0;
    p[9] = 0, p[10] = 0, p[11] = z0 + h;
}

/* Sum of forces and moment about the origin, with the largest component. */
static void totals(const double *pos, const double fa[12], const double fb[12], double sum[3],
                   double moment[3], double *largest)
{
    memset(sum, 0, 3 * sizeof *sum);
    memset(moment, 0, 3 * sizeof *moment);
    *largest = 0;
    for (int n = 0; n < 8; n++) {
        const double *f = n < 4 ? fa + 3 * n : fb + 3 * (n - 4), *x = pos + 3 * n;
        for (int i = 0; i < 3; i++) sum[i] += f[i], *largest = fmax(*largest, fabs(f[i]));
        moment[0] += x[1] * f[2] - x[2] * f[1];
        moment[1] += x[2] * f[0] - x[0] * f[2];
        moment[2] += x[0] * f[1] - x[1] * f[0];
    }
}

static void test_contact_tet_apart(void)
{
    double pos[24], fa[12], fb[12];
    axial_tet(pos, 1.0, 0.0, 1.5);
    axial_tet(pos + 12, 1.0, 1.5 + 1e-9, 1.5); /* base just above the apex */
    CHECK(tet_contact_pair(pos, A, B, 1e9, fa, fb) == 0, "apart: contact found");
    for (int k = 0; k < 12; k++) CHECK(fa[k] == 0 && fb[k] == 0, "apart: force %d", k);
}

static void test_contact_tet_momentum(void)
{
    /* two irregular tetrahedra overlapping at a slant */
    double pos[24] = {0.1, -0.2, 0.05, 1.3, 0.1, -0.1, 0.2, 1.1, 0.3, 0.4, 0.3, 0.9,
                      0.5, 0.4, 0.2, 1.5, 0.9, 0.6, 0.3, 1.6, 0.1, 0.9, 0.2, 1.4};
    double fa[12], fb[12], sum[3], moment[3], largest;
    double got = tet_contact_pair(pos, A, B, 1e9, fa, fb);
    CHECK(got > 0, "no contact found in an overlapping pair");
    totals(pos, fa, fb, sum, moment, &largest);
    CHECK(largest > 1e6, "forces too small to test: %g", largest);
    for (int i = 0; i < 3; i++) {
        CHECK(fabs(sum[i]) <= 1e-13 * largest, "force sum[%d] = %g of %g", i, sum[i], largest);
        CHECK(fabs(moment[i]) <= 1e-12 * largest, "moment[%d] = %g of %g", i, moment[i], largest);
    }
    /* and the forces push the two apart: along the line between centroids */
    double ca[3] = {0}, cb[3] = {0}, fb_sum[3] = {0};
    for (int v = 0; v < 4; v++)
        for (int i = 0; i < 3; i++)
            ca[i] += pos[3 * v + i] / 4, cb[i] += pos[12 + 3 * v + i] / 4, fb_sum[i] += fb[3 * v + i];
    double along = 0;
    for (int i = 0; i < 3; i++) along += fb_sum[i] * (cb[i] - ca[i]);
    CHECK(along > 0, "the force on B points towards A (%g)", along);
}

static void test_contact_tet_grows_with_overlap(void)
{
    double previous = 0;
    for (int step = 1; step <= 8; step++) {
        double pos[24], fa[12], fb[12];
        double depth = 0.05 * step;
        axial_tet(pos, 1.0, 0.0, 1.5);                 /* apex up at 1.5 */
        axial_tet(pos + 12, 1.2, 1.5 - depth, 1.0);    /* base pressed onto the apex */
        tet_contact_pair(pos, A, B, 1e9, fa, fb);
        double fz = fb[2] + fb[5] + fb[8] + fb[11];
        CHECK(fz > previous, "depth %g: upward force %g not above %g", depth, fz, previous);
        previous = fz;
    }
}

/* A target of height H over a base of area A0 in z = 0; the contactor's top
 * face is a huge triangle at z = d, so the part inside the target is the
 * slice at t = d / H: lambda_base = t there and the other coordinates are
 * (1 - t) mu (mu the slice's own). With s = min mu, whose level sets bound
 * areas (1 - 3s)^2 A_s, integral 4 min(t, (1 - t) s) dA is
 *   4 A_s [6 (1 - t)(s*^2/2 - s*^3) + t (1 - 3 s*)^2],  s* = t / (1 - t),
 * A_s = (1 - t)^2 A0, for t <= 1/4 (s* <= 1/3). */
static void test_contact_tet_flat_face_closed_form(void)
{
    double H = 2.0, r = 1.0, A0 = 3 * sqrt(3) / 4 * r * r, p = 1e9;
    for (int k = 1; k <= 4; k++) {
        double d = 0.1 * k, t = d / H, pos[24], fa[12], fb[12];
        axial_tet(pos, r, 0.0, H); /* target: A */
        axial_tet(pos + 12, 100.0, d, -60.0); /* contactor: B, top face at z = d */
        memset(fa, 0, sizeof fa);
        memset(fb, 0, sizeof fb);
        double integral = tet_contact_one_way(pos, B, A, p, fb, fa);
        double s = t / (1 - t), As = (1 - t) * (1 - t) * A0;
        double want = 4 * As * (6 * (1 - t) * (s * s / 2 - s * s * s) + t * (1 - 3 * s) * (1 - 3 * s));
        CHECK_REL(integral, want, 1e-12);
        double fz = fb[2] + fb[5] + fb[8] + fb[11], fx = fb[0] + fb[3] + fb[6] + fb[9];
        CHECK_REL(fz, -p * want, 1e-12); /* pushed down, out of the target */
        CHECK(fabs(fx) <= 1e-12 * p * want, "sideways force %g", fx);
    }
}

/* Apex to apex along z, each symmetric about the z axis (3-fold) and the
 * plane y = 0: the force is along z and has no moment about the axis. */
static void test_contact_tet_symmetric_torque_free(void)
{
    double pos[24], fa[12], fb[12];
    axial_tet(pos, 1.0, 0.0, 1.5);
    axial_tet(pos + 12, 1.0, 2.8, -1.5); /* apex down at 1.3: 0.2 overlap */
    CHECK(tet_contact_pair(pos, A, B, 1e9, fa, fb) > 0, "no contact");
    double F[3] = {0, 0, 0}, M[3] = {0, 0, 0};
    for (int v = 0; v < 4; v++) {
        const double *x = pos + 12 + 3 * v, *f = fb + 3 * v;
        for (int i = 0; i < 3; i++) F[i] += f[i];
        M[0] += x[1] * f[2] - x[2] * f[1];
        M[1] += x[2] * f[0] - x[0] * f[2];
        M[2] += x[0] * f[1] - x[1] * f[0];
    }
    CHECK(F[2] > 0, "B not pushed up: %g", F[2]);
    CHECK(fabs(F[0]) <= 1e-12 * F[2] && fabs(F[1]) <= 1e-12 * F[2], "sideways %g %g of %g", F[0], F[1], F[2]);
    /* about the origin (on the axis): no moment */
    for (int i = 0; i < 3; i++) CHECK(fabs(M[i]) <= 1e-12 * F[2], "moment[%d] = %g", i, M[i]);
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        {"test_contact_tet_apart", test_contact_tet_apart},
        {"test_contact_tet_momentum", test_contact_tet_momentum},
        {"test_contact_tet_grows_with_overlap", test_contact_tet_grows_with_overlap},
        {"test_contact_tet_flat_face_closed_form", test_contact_tet_flat_face_closed_form},
        {"test_contact_tet_symmetric_torque_free", test_contact_tet_symmetric_torque_free},
    };
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
