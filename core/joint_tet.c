/*
 * joint_tet.c - the 6-node joint between two tetrahedron faces: its
 * kinematics (gap, mean-face normal, opening and sliding vector), the
 * integration of joint_law.h's tractions over the triangle, and the
 * resistance to being pressed shut. It is the 3D twin in method, not in
 * code, of joint.c's 4-node edge joint: the law is shared, the geometry is
 * each dimension's own.
 *
 * Integration. The gap d is linear over the triangle, so while the joint is
 * undamaged and elastic the traction k d is integrated exactly in closed
 * form (the consistent "mass matrix" of the linear triangle, A/12 (1 + I)).
 * Beyond that the law is evaluated at the symmetric three-point rule
 * (barycentric 2/3, 1/6, 1/6, weight A/3; exact for quadratics, so it
 * gives the closed form back for an elastic open joint). Compression is
 * integrated exactly over the shut part of the face (the triangle clipped
 * by d.n = 0): at three points a joint that is open at one corner and
 * closed at another would let that corner sink into the neighbour
 * unresisted, as two Gauss points did in 2D (see joint_compression).
 *
 * Sliding. The sliding is a vector in the face; the law sees its length s
 * and returns a shear traction along its direction e. The step's
 * relative displacement projected on e gives the slide a step ago, through
 * which the frictional part of the shear strength works.
 */
#include "joint_tet.h"
#include "vec3.h"

#include <math.h>
#include <string.h>

/* The symmetric three-point rule on the triangle, barycentric. */
static const double rule[3][3] = {{2.0 / 3, 1.0 / 6, 1.0 / 6},
                                  {1.0 / 6, 2.0 / 3, 1.0 / 6},
                                  {1.0 / 6, 1.0 / 6, 2.0 / 3}};

static const double *node_at(const double *xyz, int32_t n) { return xyz + 3 * (size_t)n; }

/* The gap sum_i lambda_i d_i at barycentric point lambda. */
static void gap_at(const double d[3][3], const double lambda[3], double out[3])
{
    for (int c = 0; c < 3; c++)
        out[c] = lambda[0] * d[0][c] + lambda[1] * d[1][c] + lambda[2] * d[2][c];
}

/* ------------------------------------------------------------- elastic */

/* True when every point of an undamaged joint is within its strengths,
 * tested on projections against the unnormalised normal N (|N| = 2A). */
static int joint_tet_elastic(const joint_law *law, const double d[3][3], const double N[3],
                             double N_len)
{
    for (int p = 0; p < 3; p++) {
        double g[3], slide[3];
        gap_at(d, rule[p], g);
        vec3_cross(g, N, slide);
        if (!joint_point_elastic(law, N_len, vec3_dot(g, N), sqrt(vec3_dot(slide, slide))))
            return 0;
    }
    return 1;
}

/* ---------------------------------------------------------- compression */

/* Adds k delta n N_i integrated over the sub-triangle with barycentric
 * corners P (exact: delta N_i is quadratic there) to fa; returns the
 * integral of 1/2 k delta^2 over it. delta is linear, delta[i] at node i. */
static double shut_triangle(double k, double area, const double P[3][3], const double delta[3],
                            const double n[3], double fa[9])
{
    double fraction = fabs(P[0][0] * (P[1][1] * P[2][2] - P[1][2] * P[2][1]) -
                           P[0][1] * (P[1][0] * P[2][2] - P[1][2] * P[2][0]) +
                           P[0][2] * (P[1][0] * P[2][1] - P[1][1] * P[2][0]));
    double w = area * fraction / 3, energy = 0;
    for (int q = 0; q < 3; q++) {
        double lambda[3];
        for (int i = 0; i < 3; i++)
            lambda[i] = rule[q][0] * P[0][i] + rule[q][1] * P[1][i] + rule[q][2] * P[2][i];
        double dq = vec3_dot(lambda, delta);
        energy += w * 0.5 * k * dq * dq;
        for (int i = 0; i < 3; i++)
            for (int c = 0; c < 3; c++) fa[3 * i + c] += w * k * dq * lambda[i] * n[c];
    }
    return energy;
}

/* The barycentric point where delta crosses zero on the edge from corner i
 * to corner j (delta[i] < 0 <= delta[j]). */
static void zero_on_edge(const double delta[3], int i, int j, double out[3])
{
    double t = delta[i] / (delta[i] - delta[j]);
    out[0] = out[1] = out[2] = 0;
    out[i] = 1 - t;
    out[j] = t;
}

/* The joint's resistance to being pressed shut, k min(delta, 0) along n,
 * integrated exactly over the shut part of the face (the triangle clipped
 * by delta = 0, as one or two sub-triangles) and added to fa; returns its
 * stored energy. */
static double joint_tet_compression(double k, double area, const double delta[3],
                                    const double n[3], double fa[9])
{
    int shut[3], open[3], ns = 0, no = 0;
    for (int i = 0; i < 3; i++) {
        if (delta[i] < 0) shut[ns++] = i;
        else open[no++] = i;
    }
    double P[3][3] = {{0}};
    if (ns == 0) return 0;
    if (ns == 3) {
        for (int i = 0; i < 3; i++) P[i][i] = 1;
        return shut_triangle(k, area, P, delta, n, fa);
    }
    if (ns == 1) { /* the corner shut[0] up to the zeros on its two edges */
        int i = shut[0];
        P[0][i] = 1;
        zero_on_edge(delta, i, open[0], P[1]);
        zero_on_edge(delta, i, open[1], P[2]);
        return shut_triangle(k, area, P, delta, n, fa);
    }
    /* two corners shut: the quadrilateral i, j, zero on j-o, zero on i-o */
    int i = shut[0], j = shut[1], o = open[0];
    double zi[3], zj[3];
    zero_on_edge(delta, i, o, zi);
    zero_on_edge(delta, j, o, zj);
    double Q[3][3] = {{0}};
    P[0][i] = 1;
    P[1][j] = 1;
    memcpy(P[2], zj, sizeof zj);
    Q[0][i] = 1;
    memcpy(Q[1], zj, sizeof zj);
    memcpy(Q[2], zi, sizeof zi);
    return shut_triangle(k, area, P, delta, n, fa) + shut_triangle(k, area, Q, delta, n, fa);
}

/* ------------------------------------------------------------- general */

/* Forces on face A from the law at the three points, for a joint that is
 * damaged or leaving its elastic range; updates *damage and books into e.
 * d: the gaps at the corners, step: how much they changed over the last
 * step, n the unit normal, area the face area. */
static void joint_tet_general(const joint_law *law, const double d[3][3],
                              const double step[3][3], const double n[3], double area,
                              double *damage, double fa[9], joint_energy *e)
{
    joint_point g[3];
    double slide_dir[3][3], slide_before[3];
    for (int p = 0; p < 3; p++) {
        double gap[3], was[3];
        gap_at(d, rule[p], gap);
        gap_at(step, rule[p], was);
        double delta = vec3_dot(gap, n), s = 0;
        for (int c = 0; c < 3; c++) {
            slide_dir[p][c] = gap[c] - delta * n[c];
            was[c] = gap[c] - was[c]; /* the gap a step ago */
        }
        s = sqrt(vec3_dot(slide_dir[p], slide_dir[p]));
        for (int c = 0; c < 3; c++) slide_dir[p][c] = s > 0 ? slide_dir[p][c] / s : 0;
        joint_point_measure(law, delta, s, &g[p]);
        slide_before[p] = vec3_dot(was, slide_dir[p]);
    }
    double D = joint_points_damage(g, 3, *damage);
    double z_old = joint_softening(*damage), z = joint_softening(D);
    *damage = D;
    if (D >= 1) e->broke = joint_points_mode(law, g, 3);
    double w = area / 3;
    memset(fa, 0, 9 * sizeof(double));
    for (int p = 0; p < 3; p++) {
        double sigma, tau;
        joint_point_respond(law, &g[p], w, z_old, z, slide_before[p], e, &sigma, &tau);
        for (int c = 0; c < 3; c++) {
            double T = w * (sigma * n[c] + tau * slide_dir[p][c]);
            for (int i = 0; i < 3; i++) fa[3 * i + c] += rule[p][i] * T;
        }
    }
    double delta[3] = {vec3_dot(d[0], n), vec3_dot(d[1], n), vec3_dot(d[2], n)};
    double squeezed = joint_tet_compression(law->k, area, delta, n, fa);
    e->stored += squeezed;
    if (D >= 1) e->handed += squeezed; /* broken shut: its overlap goes on as contact */
}

int joint_tet_forces(const joint_law *law, const double *pos, const double *vel, double h_last,
                     const int32_t node[6], double *damage, double fa[9], joint_energy *e)
{
    if (*damage >= 1.0) {
        memset(fa, 0, 9 * sizeof(double));
        return 0;
    }
    double d[3][3], N[3];
    double N_len = joint_tet_gaps(pos, node, d, N);
    return joint_tet_forces_of_gaps(law, d, N, N_len, vel, h_last, node, damage, fa, e);
}

int joint_tet_forces_of_gaps(const joint_law *law, const double d[3][3], const double N[3],
                             double N_len, const double *vel, double h_last,
                             const int32_t node[6], double *damage, double fa[9],
                             joint_energy *e)
{
    memset(fa, 0, 9 * sizeof(double));
    if (*damage >= 1.0) return 0;
    double area = 0.5 * N_len;
    if (!(N_len > 0)) return 1; /* a face squashed flat carries nothing this step */
    if (*damage == 0 && joint_tet_elastic(law, d, N, N_len)) {
        e->stored += joint_tet_elastic_forces(law->k, area, d, fa);
        return 1;
    }
    double step[3][3] = {{0}};
    if (vel)
        for (int i = 0; i < 3; i++)
            vec3_sub(node_at(vel, node[3 + i]), node_at(vel, node[i]), step[i]);
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++) step[i][c] *= h_last;
    double n[3] = {N[0] / N_len, N[1] / N_len, N[2] / N_len};
    joint_energy mine = {0};
    joint_tet_general(law, d, step, n, area, damage, fa, &mine);
    e->dissipated += mine.dissipated;
    e->friction += mine.friction;
    e->handed += mine.handed;
    e->broke = mine.broke;
    if (*damage >= 1.0) { /* broken within this call: it carries nothing from now on */
        memset(fa, 0, 9 * sizeof(double));
        return 0;
    }
    e->stored += mine.stored;
    return 1;
}
