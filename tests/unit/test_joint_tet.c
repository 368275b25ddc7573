/*
 * test_joint_tet.c - the 6-node 3D joint kernel against the numbers its law
 * implies: an elastic joint in a rotated frame with a linearly varying gap
 * gives the face integral of k d (resultant and moment, 1e-6), a damaged
 * one z(D) k d; a rigid motion of the pair gives no force and turns the
 * forces of a gapped pair with it; the six forces sum to zero; the forces
 * of a partly shut damaged joint are the gradient of its stored energy
 * (the clipped compression integral); and a joint pulled apart in pure
 * mode I (sheared in pure mode II) absorbs energy_I (energy_II) times its
 * area, both as work of its forces and in the fracture account; sheared
 * while pressed shut, its work closes against stored + fracture + friction.
 */
#include "check.h"
#include "kernel/joint_law.h"
#include "kernel/joint_tet.h"
#include "rotation_3d.h"

#include <stdint.h>

/* material of test_joint.c: penalty 10 E over h = 1 cm */
static const double FT = 1e6, COHESION = 3e6, PHI_DEG = 30, GI = 10, GII = 50;

static joint_law law_of(void)
{
    joint_law L = joint_law_make(10 * 3e10 / 0.01, FT, COHESION, tan(PHI_DEG * M_PI / 180), GI, GII);
    return L;
}

/* Face A in its own frame: an irregular triangle in z = 0, counter-clockwise
 * seen from +z, so its normal +z points out of A (towards B). */
static const double face[9] = {0, 0, 0, 0.01, 0, 0, 0.003, 0.008, 0};
static const double face_area = 0.5 * 0.01 * 0.008;
static const int32_t six[6] = {0, 1, 2, 3, 4, 5};

static void apply(const double R[9], const double v[3], double out[3])
{
    for (int i = 0; i < 3; i++) out[i] = R[3 * i] * v[0] + R[3 * i + 1] * v[1] + R[3 * i + 2] * v[2];
}

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double norm3(const double a[3]) { return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

/* The pair in the world: x = R p + t for face A, and B = A + R gap_local. */
static void place_pair(const double R[9], const double t[3], const double gap_local[9],
                       double pos[18])
{
    for (int i = 0; i < 3; i++) {
        double a[3], g[3];
        apply(R, face + 3 * i, a);
        apply(R, gap_local + 3 * i, g);
        for (int c = 0; c < 3; c++) {
            pos[3 * i + c] = a[c] + t[c];
            pos[9 + 3 * i + c] = pos[3 * i + c] + g[c];
        }
    }
}

/* Resultant and moment (about the origin) of the traction scale * k d(x)
 * on face A, by the edge-midpoint rule: exact for the quadratic x x d, and
 * a rule the kernel does not use. */
static void face_integral(const double pos[18], double scale, double F[3], double M[3])
{
    static const double mid[3][3] = {{0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}};
    double k = law_of().k;
    for (int c = 0; c < 3; c++) F[c] = M[c] = 0;
    for (int q = 0; q < 3; q++) {
        double x[3] = {0, 0, 0}, d[3] = {0, 0, 0}, m[3];
        for (int i = 0; i < 3; i++)
            for (int c = 0; c < 3; c++) {
                x[c] += mid[q][i] * pos[3 * i + c];
                d[c] += mid[q][i] * (pos[9 + 3 * i + c] - pos[3 * i + c]);
            }
        double w = face_area / 3 * scale * k;
        for (int c = 0; c < 3; c++) d[c] *= w;
        cross(x, d, m);
        for (int c = 0; c < 3; c++) {
            F[c] += d[c];
            M[c] += m[c];
        }
    }
}

/* Resultant and moment of the kernel's forces on face A. */
static void kernel_resultant(const double pos[18], const double fa[9], double F[3], double M[3])
{
    for (int c = 0; c < 3; c++) F[c] = M[c] = 0;
    for (int i = 0; i < 3; i++) {
        double m[3];
        cross(pos + 3 * i, fa + 3 * i, m);
        for (int c = 0; c < 3; c++) {
            F[c] += fa[3 * i + c];
            M[c] += m[c];
        }
    }
}

/* joint_tet_forces for a joint whose points kept no slip, evaluated on its
 * own (the slip it would keep is dropped). */
static int forces_fresh(const joint_law *law, const double pos[18], double *damage, double fa[9],
                        joint_energy *e)
{
    joint_slip slip[3] = {{{0, 0}, 0}, {{0, 0}, 0}, {{0, 0}, 0}};
    return joint_tet_forces(law, pos, six, damage, slip, fa, e);
}

static void check_close3(const double got[3], const double want[3], double rel, const char *what)
{
    double diff[3] = {got[0] - want[0], got[1] - want[1], got[2] - want[2]};
    CHECK(norm3(diff) <= rel * norm3(want), "%s: |got - want| = %g, |want| = %g", what,
          norm3(diff), norm3(want));
}

static const double axis[3] = {1, 2, 3}, shift[3] = {0.2, -0.1, 0.05};

/* A linearly varying gap well inside the strengths (d_p = f_t / k = 33 nm):
 * opening at two corners, shut at the third, sliding everywhere. */
static const double gap_mixed[9] = {2e-9, -1e-9, 4e-9, -3e-9, 2e-9, 1e-9, 1e-9, 3e-9, -2e-9};
/* The same but open at every corner. */
static const double gap_open[9] = {2e-9, -1e-9, 4e-9, -3e-9, 2e-9, 1e-9, 1e-9, 3e-9, 2e-9};

static void elastic_joint_integrates_its_traction(void)
{
    joint_law law = law_of();
    double R[9], pos[18], fa[9], F[3], M[3], Fw[3], Mw[3];
    rotation(axis, 0.7, R);
    place_pair(R, shift, gap_mixed, pos);
    double damage = 0;
    joint_energy e = {0};
    CHECK(forces_fresh(&law, pos, &damage, fa, &e) == 1, "joint broke");
    CHECK(damage == 0, "an elastic joint was damaged: %g", damage);
    kernel_resultant(pos, fa, F, M);
    face_integral(pos, 1, Fw, Mw);
    check_close3(F, Fw, 1e-6, "resultant");
    check_close3(M, Mw, 1e-6, "moment");
    /* stored: 1/2 integral k |d|^2, exact by the midpoint rule; the gaps
     * as the positions hold them (a nanometre on 0.2 m keeps 8 digits) */
    double k = law.k, want = 0, gap[9];
    for (int i = 0; i < 9; i++) gap[i] = pos[9 + i] - pos[i];
    for (int q = 0; q < 3; q++) {
        double d[3];
        for (int c = 0; c < 3; c++) d[c] = 0.5 * (gap[3 * q + c] + gap[3 * ((q + 1) % 3) + c]);
        want += face_area / 3 * 0.5 * k * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
    /* the kernel integrates over the mean face a + d/2, whose area differs
     * from A's by |d| / size, 1e-7 here */
    CHECK_REL(e.stored, want, 1e-6);
    /* action = reaction: the six nodal forces (B's are -fa) sum to zero */
    double sum[3] = {0, 0, 0};
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++) sum[c] += fa[3 * i + c] + (-fa[3 * i + c]);
    CHECK(norm3(sum) == 0, "six forces sum to %g", norm3(sum));
    fprintf(stderr, "  elastic: |F| = %.6g N, |M| = %.6g N m, stored %.6g J\n", norm3(F),
            norm3(M), e.stored);
}

/* A damaged joint open everywhere and within its strengths goes through
 * the three-point law: its traction is z(D) k d, integrated exactly. */
static void damaged_open_joint_integrates_softened_traction(void)
{
    joint_law law = law_of();
    double R[9], pos[18], fa[9], F[3], M[3], Fw[3], Mw[3];
    rotation(axis, -1.1, R);
    place_pair(R, shift, gap_open, pos);
    double damage = 0.4;
    joint_energy e = {0};
    forces_fresh(&law, pos, &damage, fa, &e);
    CHECK(damage == 0.4, "damage moved to %g", damage);
    CHECK(e.dissipated == 0, "dissipated %g without damage growth", e.dissipated);
    kernel_resultant(pos, fa, F, M);
    face_integral(pos, joint_softening(0.4), Fw, Mw);
    check_close3(F, Fw, 1e-6, "softened resultant");
    check_close3(M, Mw, 1e-6, "softened moment");
}

/* A rigid motion of the pair (any rotation and translation) gives no force
 * to a pair that had none, and turns the forces of a gapped pair with it. */
static void rigid_motion_gives_no_force(void)
{
    joint_law law = law_of();
    double R[9], pos[18], fa[9];
    static const double none[9] = {0};
    rotation(axis, 2.3, R);
    place_pair(R, shift, none, pos);
    double damage = 0.3;
    joint_energy e = {0};
    forces_fresh(&law, pos, &damage, fa, &e);
    double largest = 0;
    for (int k = 0; k < 9; k++) largest = fmax(largest, fabs(fa[k]));
    CHECK(largest == 0, "rigid motion: force %g N", largest);
    CHECK(damage == 0.3, "damage moved to %g", damage);
    CHECK(e.stored == 0 && e.dissipated == 0 && e.friction == 0, "energies %g %g %g", e.stored,
          e.dissipated, e.friction);

    /* the gapped pair, then the same pair turned and moved: f' = R f */
    double ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, zero[3] = {0, 0, 0};
    double pos0[18], fa0[9], R2[9], pos1[18], fa1[9];
    place_pair(ident, zero, gap_mixed, pos0);
    damage = 0;
    forces_fresh(&law, pos0, &damage, fa0, &e);
    rotation(axis, 2.3, R2);
    place_pair(R2, shift, gap_mixed, pos1);
    damage = 0;
    forces_fresh(&law, pos1, &damage, fa1, &e);
    for (int i = 0; i < 3; i++) {
        double want[3];
        apply(R2, fa0 + 3 * i, want);
        /* to the gaps' rounding on positions of 0.2 m: 1e-8 */
        check_close3(fa1 + 3 * i, want, 1e-6, "turned force");
    }
}

/* With the damage held (every point inside its strengths), a partly shut
 * joint's forces are the gradient of its stored energy: the shut part's
 * clipped integral and the three-point law agree with one energy, up to
 * the turning of the normal (relative |d| / size, 1e-6 here). One and two
 * corners shut, by central differences on face B's nodes. */
static void shut_part_forces_are_energy_gradient(void)
{
    joint_law law = law_of();
    static const double shut_one[9] = {1e-9, 2e-9, -4e-9, -2e-9, 1e-9, 3e-9, 2e-9, -1e-9, 5e-9};
    static const double shut_two[9] = {1e-9, 2e-9, -4e-9, -2e-9, 1e-9, -2e-9, 2e-9, -1e-9, 5e-9};
    const double *gaps[2] = {shut_one, shut_two};
    double R[9];
    rotation(axis, 0.9, R);
    for (int which = 0; which < 2; which++) {
        double pos[18], fa[9], damage = 0.5;
        joint_energy e = {0};
        place_pair(R, shift, gaps[which], pos);
        forces_fresh(&law, pos, &damage, fa, &e);
        CHECK(damage == 0.5, "damage moved to %g", damage);
        double grad[9], h = 1e-12;
        for (int k = 0; k < 9; k++) {
            double keep = pos[9 + k], E[2], f_unused[9];
            for (int side = 0; side < 2; side++) {
                pos[9 + k] = keep + (side ? h : -h);
                double D = 0.5;
                joint_energy es = {0};
                forces_fresh(&law, pos, &D, f_unused, &es);
                E[side] = es.stored;
            }
            pos[9 + k] = keep;
            grad[k] = (E[1] - E[0]) / (2 * h); /* dE/db = -f_b = f_a */
        }
        for (int i = 0; i < 3; i++) check_close3(grad + 3 * i, fa + 3 * i, 1e-4, "gradient");
    }
}

/* Moves face B rigidly by total_local (in the face's frame) in `steps`
 * increments from where it touches A, integrating the work of the kernel's resisting force; returns
 * the work and the fracture account in *dissipated. */
static double pull_apart(const double R[9], const double total_local[3], int steps,
                         double *damage, double *dissipated, double *last_stored)
{
    joint_law law = law_of();
    double total[3], pos[18], fa[9], work = 0, prev = 0;
    apply(R, total_local, total);
    double len = norm3(total);
    joint_slip slip[3] = {{{0, 0}, 0}, {{0, 0}, 0}, {{0, 0}, 0}};
    *damage = 0;
    *dissipated = 0;
    for (int s = 1; s <= steps; s++) {
        double f = (double)s / steps, gap[9];
        for (int i = 0; i < 3; i++)
            for (int c = 0; c < 3; c++) gap[3 * i + c] = f * total_local[c];
        place_pair(R, shift, gap, pos);
        joint_energy e = {0};
        joint_tet_forces(&law, pos, six, damage, slip, fa, &e);
        *dissipated += e.dissipated;
        *last_stored = e.stored;
        double pull = 0; /* the force on A along the motion resists B's motion */
        for (int i = 0; i < 3; i++)
            for (int c = 0; c < 3; c++) pull += fa[3 * i + c] * total[c] / len;
        work += 0.5 * (pull + prev) * len / steps;
        prev = pull;
    }
    return work;
}

static void mode_I_dissipates_energy_I(void)
{
    joint_law law = law_of();
    double R[9], dp = FT / law.k;
    rotation(axis, 0.7, R);
    double dc = dp + softening_span(FT, dp, GI);
    double open[3] = {0, 0, 1.3 * dc}, damage, dissipated, stored;
    double work = pull_apart(R, open, 40000, &damage, &dissipated, &stored);
    CHECK(damage >= 1, "joint still holds at 1.3 critical openings: D = %g", damage);
    CHECK_REL(work / face_area, GI, 0.03);
    CHECK_REL(dissipated / face_area, GI, 0.03);
    CHECK(stored == 0, "a broken joint stores %g J", stored);
    fprintf(stderr, "  mode I: %.4f J/m^2 absorbed, fracture account %.4f, G_I %.4f\n",
            work / face_area, dissipated / face_area, GI);
}

static void mode_II_dissipates_energy_II(void)
{
    joint_law law = law_of();
    double R[9], sp = COHESION / law.k;
    rotation(axis, -0.4, R);
    double sc = sp + softening_span(COHESION, sp, GII);
    /* along no edge of the face */
    double slide[3] = {1.3 * sc * cos(0.4), 1.3 * sc * sin(0.4), 0}, damage, dissipated, stored;
    double work = pull_apart(R, slide, 40000, &damage, &dissipated, &stored);
    CHECK(damage >= 1, "joint still holds at 1.3 critical slides: D = %g", damage);
    CHECK_REL(work / face_area, GII, 0.03);
    CHECK_REL(dissipated / face_area, GII, 0.03);
    fprintf(stderr, "  mode II: %.4f J/m^2 absorbed, fracture account %.4f, G_II %.4f\n",
            work / face_area, dissipated / face_area, GII);
}

/* Sheared to breakage while pressed shut: the shear strength gains
 * sigma_c tan(phi), which is friction, booked as the joint slides. The
 * work of the sliding force is then what the joint stores (and, once
 * broken shut, hands to contact), dissipates by damage and by friction:
 * the balance closes to 1 % over the whole path. */
static void sheared_under_compression_closes_the_balance(void)
{
    joint_law law = law_of();
    double R[9], pos[18], fa[9];
    joint_slip slip[3] = {{{0, 0}, 0}, {{0, 0}, 0}, {{0, 0}, 0}};
    rotation(axis, 1.3, R);
    double shut = -0.5 * FT / law.k; /* sigma_c = f_t / 2 */
    double fs = COHESION + 0.5 * FT * law.tan_phi, sp = fs / law.k;
    double total = 1.5 * (sp + softening_span(fs, sp, GII)), dir[3] = {0.6, 0.8, 0}, world[3];
    apply(R, dir, world);
    int steps = 40000;
    double damage = 0, work = 0, prev = 0, stored0 = 0, stored = 0;
    joint_energy acc = {0};
    for (int s = 0; s <= steps; s++) {
        double f = total * s / steps, gap[9];
        for (int i = 0; i < 3; i++) {
            gap[3 * i] = f * dir[0];
            gap[3 * i + 1] = f * dir[1];
            gap[3 * i + 2] = shut;
        }
        place_pair(R, shift, gap, pos);
        joint_energy e = {0};
        joint_tet_forces(&law, pos, six, &damage, slip, fa, &e);
        acc.dissipated += e.dissipated;
        acc.friction += e.friction;
        acc.handed += e.handed;
        stored = e.stored;
        if (s == 0) stored0 = stored;
        double pull = 0;
        for (int i = 0; i < 3; i++)
            for (int c = 0; c < 3; c++) pull += fa[3 * i + c] * world[c];
        if (s) work += 0.5 * (pull + prev) * total / steps;
        prev = pull;
    }
    CHECK(damage >= 1, "joint still holds: D = %g", damage);
    double booked = stored + acc.handed - stored0 + acc.dissipated + acc.friction;
    CHECK(acc.friction > 0, "no friction booked");
    CHECK(acc.handed > 0, "a joint broken shut hands nothing to contact");
    CHECK_REL(booked, work, 0.01);
    fprintf(stderr, "  sheared shut: work %.6g J, fracture %.6g, friction %.6g, handed %.6g, "
            "residual %.3g %%\n", work, acc.dissipated, acc.friction, acc.handed - stored0,
            100 * fabs(booked - work) / work);
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        {"elastic_joint_integrates_its_traction", elastic_joint_integrates_its_traction},
        {"damaged_open_joint_integrates_softened_traction",
         damaged_open_joint_integrates_softened_traction},
        {"rigid_motion_gives_no_force", rigid_motion_gives_no_force},
        {"shut_part_forces_are_energy_gradient", shut_part_forces_are_energy_gradient},
        {"mode_I_dissipates_energy_I", mode_I_dissipates_energy_I},
        {"mode_II_dissipates_energy_II", mode_II_dissipates_energy_II},
        {"sheared_under_compression_closes_the_balance",
         sheared_under_compression_closes_the_balance},
    };
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
