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
 * Sliding. The sliding is a vector in the face, given to the law as its
 * two components in the face's own frame (joint_tet_face_frame), where each point
 * keeps its plastic slide (joint_law.h's Coulomb return); the law returns
 * the shear traction in the same frame.
 */
#include "joint_tet.h"
#include "math/vec3.h"

#include <math.h>
#include <string.h>

static const double *node_at(const double *xyz, int32_t n) { return xyz + 3 * (size_t)n; }

/* The gap sum_i lambda_i d_i at barycentric point lambda. */
static void gap_at(const double d[3][3], const double lambda[3], double out[3])
{
    for (int c = 0; c < 3; c++)
        out[c] = lambda[0] * d[0][c] + lambda[1] * d[1][c] + lambda[2] * d[2][c];
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
            lambda[i] = joint_tet_rule[q][0] * P[0][i] + joint_tet_rule[q][1] * P[1][i] +
                        joint_tet_rule[q][2] * P[2][i];
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

/* The face's own frame: t1 along its first mean edge (a + d/2), t2 = n x t1
 * in the face. It turns with the face, so a rigid rotation of the pair
 * leaves the slide's components, and the plastic slide kept in them, as
 * they were. Returns 0 for an edge of no length. */
int joint_tet_face_frame(const double *pos, const int32_t node[6], const double d[3][3],
                         const double n[3], double t1[3], double t2[3])
{
    double e1[3];
    for (int c = 0; c < 3; c++)
        e1[c] = (node_at(pos, node[1])[c] - node_at(pos, node[0])[c]) + 0.5 * (d[1][c] - d[0][c]);
    double along = vec3_dot(e1, n);
    for (int c = 0; c < 3; c++) e1[c] -= along * n[c];
    double len = sqrt(vec3_dot(e1, e1));
    if (!(len > 0)) return 0;
    for (int c = 0; c < 3; c++) t1[c] = e1[c] / len;
    vec3_cross(n, t1, t2);
    return 1;
}

int joint_tet_add_offsets(const double *pos, const int32_t node[6], const double N[3],
                          double N_len, const double offset[9], double d[3][3])
{
    if (!(N_len > 0)) return 0;
    double n[3] = {N[0] / N_len, N[1] / N_len, N[2] / N_len}, t1[3], t2[3];
    if (!joint_tet_face_frame(pos, node, d, n, t1, t2)) return 0;
    for (int i = 0; i < 3; i++) {
        const double *o = offset + 3 * i;
        for (int c = 0; c < 3; c++) d[i][c] += o[0] * n[c] + o[1] * t1[c] + o[2] * t2[c];
    }
    return 1;
}

/* Forces on face A from the law at the three points, for a joint that is
 * damaged or leaving its elastic range; updates *damage and the slip each
 * point keeps (slip[3]) and books into e. d: the gaps at the corners, n
 * the unit normal, t1 and t2 the face frame, area the face area. */
static void joint_tet_general(const joint_law *law, const double d[3][3], const double n[3],
                              const double t1[3], const double t2[3], double area,
                              double *damage, joint_slip slip[3], double fa[9], joint_energy *e)
{
    joint_point g[3];
    for (int p = 0; p < 3; p++) {
        double gap[3];
        gap_at(d, joint_tet_rule[p], gap);
        const double slide[2] = {vec3_dot(gap, t1), vec3_dot(gap, t2)};
        joint_point_measure(law, vec3_dot(gap, n), slide, &slip[p], &g[p]);
    }
    double D = joint_points_damage(g, 3, *damage);
    double z_old, z;
    joint_softening_step(*damage, D, &z_old, &z);
    *damage = D;
    if (D >= 1) e->broke = joint_points_mode(law, g, 3);
    double w = area / 3;
    memset(fa, 0, 9 * sizeof(double));
    for (int p = 0; p < 3; p++) {
        double sigma, tau[2];
        joint_point_respond(law, &g[p], w, z_old, z, e, &sigma, tau);
        slip[p] = g[p].slip;
        for (int c = 0; c < 3; c++) {
            double T = w * (sigma * n[c] + tau[0] * t1[c] + tau[1] * t2[c]);
            for (int i = 0; i < 3; i++) fa[3 * i + c] += joint_tet_rule[p][i] * T;
        }
    }
    double delta[3] = {vec3_dot(d[0], n), vec3_dot(d[1], n), vec3_dot(d[2], n)};
    double squeezed = joint_tet_compression(law->k, area, delta, n, fa);
    e->stored += squeezed;
    if (D >= 1) e->handed += squeezed; /* broken shut: its overlap goes on as contact */
}

int joint_tet_forces(const joint_law *law, const double *pos, const int32_t node[6],
                     double *damage, joint_slip slip[3], double fa[9], joint_energy *e)
{
    if (*damage >= 1.0) {
        memset(fa, 0, 9 * sizeof(double));
        return 0;
    }
    double d[3][3], N[3];
    double N_len = joint_tet_gaps(pos, node, d, N);
    return joint_tet_forces_of_gaps(law, pos, d, N, N_len, node, damage, slip, fa, e);
}

int joint_tet_forces_of_gaps(const joint_law *law, const double *pos, const double d[3][3],
                             const double N[3], double N_len, const int32_t node[6],
                             double *damage, joint_slip slip[3], double fa[9], joint_energy *e)
{
    memset(fa, 0, 9 * sizeof(double));
    if (*damage >= 1.0) return 0;
    double area = 0.5 * N_len;
    if (!(N_len > 0)) return 1; /* a face squashed flat carries nothing this step */
    if (*damage == 0 && joint_tet_elastic_points_of(law->k, law->tensile_strength, law->cohesion,
                                                    law->tan_phi, d, N, N_len)) {
        e->stored += joint_tet_elastic_forces(law->k, area, d, fa);
        return 1;
    }
    double n[3] = {N[0] / N_len, N[1] / N_len, N[2] / N_len}, t1[3], t2[3];
    if (!joint_tet_face_frame(pos, node, d, n, t1, t2)) return 1; /* no edge to slide along */
    joint_energy mine = {0};
    joint_tet_general(law, d, n, t1, t2, area, damage, slip, fa, &mine);
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
