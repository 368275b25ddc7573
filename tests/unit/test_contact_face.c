/*
 * test_contact_face.c - the shut broken joint's kernel (kernel/contact_face.h),
 * 2D and 3D: the closed-form normal force of a pair pressed together
 * uniformly, (D+1) p A d (1/H_a + 1/H_b); the exact clipped integral of a
 * depth that changes sign; momentum and angular momentum to round-off on
 * an irregular pair; the general kernel within O(d/h) of it; and Coulomb
 * friction: a stick spring that grows linearly below mu N without
 * dissipation, then slides at exactly mu N, dissipating cap x slip.
 */
#include "check.h"
#include "kernel/contact_face.h"
#include "kernel/contact_pair.h"

#include <stdint.h>
#include <string.h>

static const int32_t A3[4] = {0, 1, 2, 3}, B3[4] = {4, 5, 6, 7};
static const int32_t A2[3] = {0, 1, 2}, B2[3] = {3, 4, 5};

/* a below z = 0, b above, sharing the face (0,0,0), (1,0,0), (0,1,0); both
 * heights over it 1, its area 1/2. a's face 3 is tet_face_nodes {0, 2, 1}. */
static void pair_3d(double pos[24])
{
    static const double p[24] = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0.2, 0.2, -1,
                                 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 1};
    memcpy(pos, p, sizeof p);
}
static const face_match MATCH_3D = {3, 3, {0, 1, 2}};

/* a below y = 0, b above, sharing the edge (0,0)-(1,0): a's edge 2 (corner
 * 2 -> 0), b's edge 0; heights 1, length 1. */
static void pair_2d(double pos[12])
{
    static const double p[12] = {0, 0, 0.3, -1, 1, 0, 0, 0, 1, 0, 0.3, 1};
    memcpy(pos, p, sizeof p);
}
static const face_match MATCH_2D = {2, 0, {1, 0, 0}};

static void sums(const double *pos, const double *out, int D, int K, double F[3], double M[3])
{
    memset(F, 0, 3 * sizeof *F);
    memset(M, 0, 3 * sizeof *M);
    for (int v = 0; v < 2 * K; v++) {
        const double *x = pos + D * v, *f = out + D * v;
        double x3[3] = {x[0], x[1], D == 3 ? x[2] : 0}, f3[3] = {f[0], f[1], D == 3 ? f[2] : 0};
        for (int i = 0; i < 3; i++) F[i] += f3[i];
        M[0] += x3[1] * f3[2] - x3[2] * f3[1];
        M[1] += x3[2] * f3[0] - x3[0] * f3[2];
        M[2] += x3[0] * f3[1] - x3[1] * f3[0];
    }
}

static void test_face_overlap_integral_closed_form(void)
{
    double i0, w[3], touch, delta = 2e-4;
    /* whole face: mean depth, centroid weighted to the deeper corner */
    double all[3] = {1, 2, 3};
    CHECK(face_overlap_integral(3, all, &i0, w, &touch), "no overlap");
    CHECK_REL(i0, 2.0, 1e-15);
    CHECK_REL(touch, 1.0, 1e-15);
    for (int k = 0; k < 3; k++) CHECK_REL(w[k], (6.0 + all[k]) / 24.0, 1e-14);
    /* shut at one corner only: the corner triangle to the edges' middles,
     * a quarter of the face, depth delta at the corner: integral
     * delta / 12, centroid weights (3/4, 1/8, 1/8) */
    double corner[3] = {delta, -delta, -delta};
    CHECK(face_overlap_integral(3, corner, &i0, w, &touch), "no overlap");
    CHECK_REL(i0, delta / 12, 1e-14);
    CHECK_REL(touch, 0.25, 1e-14);
    CHECK_REL(w[0], 0.75, 1e-14);
    CHECK_REL(w[1], 0.125, 1e-13);
    /* open at one corner: the rest, a quadrilateral */
    double open[3] = {-delta, delta, delta};
    CHECK(face_overlap_integral(3, open, &i0, w, &touch), "no overlap");
    /* integral of d over the face (delta / 3) plus the corner's -d (delta / 12) */
    CHECK_REL(i0, 5 * delta / 12, 1e-13);
    CHECK_REL(touch, 0.75, 1e-14);
    /* segment shut over its first third: d = delta (1 - 3 s) */
    double seg[3] = {delta, -2 * delta, 0};
    CHECK(face_overlap_integral(2, seg, &i0, w, &touch), "no overlap");
    CHECK_REL(i0, delta / 6, 1e-14);
    CHECK_REL(touch, 1.0 / 3, 1e-14);
    CHECK_REL(w[1], 1.0 / 9, 1e-13);
    double apart[3] = {-1, -2, -3};
    CHECK(!face_overlap_integral(3, apart, &i0, w, &touch), "open face pressed");
}

/* Pressed uniformly by d: (D+1) p A d (1/H_a + 1/H_b) along the normal. */
static void test_contact_face_pressed_closed_form(void)
{
    double p = 1e10, d = 1e-5;
    /* 3D: 4 p (1/2) d (1 + 1) = 4 p d */
    double pos[24], vel[24] = {0}, springs[TET_CONTACT_SLOTS] = {0}, out[TET_PAIR_OUT], F[3], M[3];
    pair_3d(pos);
    for (int v = 4; v < 8; v++) pos[3 * v + 2] -= d;
    contact_pair_in in = {pos, vel, A3, B3, p, 0.0, 1e-6, NULL, 0, 0};
    CHECK(tet_face_pair_force(&in, &MATCH_3D, springs, out) == 1, "3D: not touching");
    double fb = out[14] + out[17] + out[20] + out[23];
    CHECK_REL(fb, 4 * p * d, 1e-12);
    sums(pos, out, 3, 4, F, M);
    for (int i = 0; i < 3; i++) {
        CHECK(fabs(F[i]) <= 1e-13 * fb, "3D: net force %d %g", i, F[i]);
        CHECK(fabs(M[i]) <= 1e-13 * fb, "3D: net moment %d %g", i, M[i]);
    }
    /* the general kernel on the same pair: within O(d / h) */
    double general[TET_PAIR_OUT], gs[TET_CONTACT_SLOTS] = {0};
    CHECK(tet_contact_pair_force(&in, gs, general) == 1, "3D general: not touching");
    double gb = general[14] + general[17] + general[20] + general[23];
    fprintf(stderr, "  3D: face %.9g, general %.9g, closed form %.9g (d/h %g)\n", fb, gb,
            4 * p * d, d);
    CHECK_REL(gb, fb, 20 * d);
    /* opened by d: nothing, springs let go */
    pair_3d(pos);
    for (int v = 4; v < 8; v++) pos[3 * v + 2] += d;
    springs[9] = 1;
    CHECK(tet_face_pair_force(&in, &MATCH_3D, springs, out) == 0, "3D: open pair touched");
    CHECK(springs[9] == 0 && out[0] == 0, "3D: open pair kept a spring");

    /* 2D: 3 p 1 d (1 + 1) = 6 p d */
    double p2[12], v2[12] = {0}, s2[TRI_CONTACT_SLOTS] = {0}, o2[TRI_PAIR_OUT], g2[TRI_PAIR_OUT];
    pair_2d(p2);
    for (int v = 3; v < 6; v++) p2[2 * v + 1] -= d;
    contact_pair_in in2 = {p2, v2, A2, B2, p, 0.0, 1e-6, NULL, 0, 0};
    CHECK(tri_face_pair_force(&in2, &MATCH_2D, s2, o2) == 1, "2D: not touching");
    double fb2 = o2[7] + o2[9] + o2[11];
    CHECK_REL(fb2, 6 * p * d, 1e-12);
    sums(p2, o2, 2, 3, F, M);
    CHECK(fabs(F[0]) <= 1e-13 * fb2 && fabs(F[1]) <= 1e-13 * fb2, "2D: net force %g %g", F[0], F[1]);
    CHECK(fabs(M[2]) <= 1e-13 * fb2, "2D: net moment %g", M[2]);
    double gs2[TRI_CONTACT_SLOTS] = {0};
    CHECK(tri_contact_pair_force(&in2, gs2, g2) == 1, "2D general: not touching");
    double gb2 = g2[7] + g2[9] + g2[11];
    fprintf(stderr, "  2D: face %.9g, general %.9g, closed form %.9g\n", fb2, gb2, 6 * p * d);
    CHECK_REL(gb2, fb2, 20 * d);
}

/* An irregular pair: copies off by a few 1e-5 every way, a spin and a
 * slide: forces and moments of both kernels' kinds balance to round-off. */
static void test_contact_face_momentum(void)
{
    static const double jiggle[24] = {3, -1, 2, 0, 1, -2, -1, 2, 1, 0, 0, 0,
                                      -2, 1, -4, 1, -3, -2, 2, -1, -3, 0, 0, 0};
    double pos[24], vel[24], springs[TET_CONTACT_SLOTS] = {0}, out[TET_PAIR_OUT], F[3], M[3];
    pair_3d(pos);
    for (int k = 0; k < 24; k++) {
        pos[k] += 1e-5 * jiggle[k];
        vel[k] = 0.1 * jiggle[(k * 7) % 24] + (k >= 12 ? 0.5 : 0);
    }
    contact_pair_in in = {pos, vel, A3, B3, 1e10, 0.6, 1e-6, NULL, 0, 0};
    for (int step = 0; step < 3; step++) {
        CHECK(tet_face_pair_force(&in, &MATCH_3D, springs, out) == 1, "3D: not touching");
        double largest = 0;
        for (int k = 0; k < 24; k++) largest = fmax(largest, fabs(out[k]));
        sums(pos, out, 3, 4, F, M);
        for (int i = 0; i < 3; i++) {
            CHECK(fabs(F[i]) <= 1e-13 * largest, "3D: net force %d %g of %g", i, F[i], largest);
            CHECK(fabs(M[i]) <= 1e-13 * largest, "3D: net moment %d %g of %g", i, M[i], largest);
        }
    }
    static const double j2[12] = {3, -1, 2, 0, -1, 2, -2, 1, -4, 1, -3, -2};
    double p2[12], v2[12], s2[TRI_CONTACT_SLOTS] = {0}, o2[TRI_PAIR_OUT];
    pair_2d(p2);
    for (int k = 0; k < 12; k++) p2[k] += 1e-5 * j2[k], v2[k] = 0.1 * j2[(k * 5) % 12] + (k >= 6);
    contact_pair_in in2 = {p2, v2, A2, B2, 1e10, 0.6, 1e-6, NULL, 0, 0};
    for (int step = 0; step < 3; step++) {
        CHECK(tri_face_pair_force(&in2, &MATCH_2D, s2, o2) == 1, "2D: not touching");
        double largest = 0;
        for (int k = 0; k < 12; k++) largest = fmax(largest, fabs(o2[k]));
        sums(p2, o2, 2, 3, F, M);
        CHECK(fabs(F[0]) <= 1e-13 * largest && fabs(F[1]) <= 1e-13 * largest, "2D: net force");
        CHECK(fabs(M[2]) <= 1e-13 * largest, "2D: net moment %g of %g", M[2], largest);
    }
}

/* b slides along x over a pressed at N: the tangential force on b grows by
 * the same amount each step (stick, nothing dissipated) up to mu N, then
 * stays at mu N exactly while each step dissipates mu N x the slip the
 * springs could not take. Returns the steps it stuck. */
static int coulomb_steps(int D, double mu, double *force_stuck, double *force_slid,
                         double *dissipated, double *normal)
{
    double p = 1e10, d = 1e-5, h = 1e-6, v = 0.5;
    double pos[24], vel[24] = {0}, springs[CONTACT_SLOTS_MAX] = {0}, out[CONTACT_PAIR_OUT_MAX];
    int K = D + 1, outs = D == 3 ? TET_PAIR_OUT : TRI_PAIR_OUT;
    if (D == 3) pair_3d(pos);
    else pair_2d(pos);
    for (int c = K; c < 2 * K; c++) pos[D * c + D - 1] -= d, vel[D * c] = v;
    contact_pair_in in = {pos, vel, D == 3 ? A3 : A2, D == 3 ? B3 : B2, p, mu, h, NULL, 0, 0};
    int stuck = 0;
    double last = 0, first = 0;
    *dissipated = 0;
    for (int step = 0; step < 40; step++) {
        int touched = D == 3 ? tet_face_pair_force(&in, &MATCH_3D, springs, out)
                             : tri_face_pair_force(&in, &MATCH_2D, springs, out);
        CHECK(touched, "%dD: not touching", D);
        double fx = 0, fn = 0;
        for (int c = K; c < 2 * K; c++) fx += out[D * c], fn += out[D * c + D - 1];
        *normal = fn;
        if (step == 0) first = fx;
        if (out[outs - 1] == 0) {
            stuck++;
            CHECK_REL(fx, (step + 1) * first, 1e-9);
            *force_stuck = fx;
        } else {
            *dissipated += out[outs - 1];
            *force_slid = fx;
        }
        last = fx;
    }
    (void)last;
    return stuck;
}

static void test_contact_face_coulomb(void)
{
    for (int D = 2; D <= 3; D++) {
        double stuck_f = 0, slid_f = 0, diss = 0, N = 0, mu = 0.5;
        int stuck = coulomb_steps(D, mu, &stuck_f, &slid_f, &diss, &N);
        fprintf(stderr, "  %dD: stuck %d steps at up to %.6g, slides at %.9g, mu N %.9g\n", D,
                stuck, -stuck_f, -slid_f, mu * N);
        CHECK(stuck >= 2 && stuck < 40, "%dD: stuck %d of 40 steps", D, stuck);
        CHECK(-stuck_f < mu * N, "%dD: stuck above mu N", D);
        CHECK_REL(-slid_f, mu * N, 1e-12);
        CHECK(diss > 0, "%dD: sliding dissipated nothing", D);
        /* below mu for the whole run: never slides */
        double s2 = 0, f2 = 0, d2 = 0, N2 = 0;
        CHECK(coulomb_steps(D, 50.0, &s2, &f2, &d2, &N2) == 40 && d2 == 0,
              "%dD: slid below mu N", D);
    }
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        {"test_face_overlap_integral_closed_form", test_face_overlap_integral_closed_form},
        {"test_contact_face_pressed_closed_form", test_contact_face_pressed_closed_form},
        {"test_contact_face_momentum", test_contact_face_momentum},
        {"test_contact_face_coulomb", test_contact_face_coulomb},
    };
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
