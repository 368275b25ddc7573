/*
 * joint_tet.h - the 6-node joint (cohesive) element between two faces of
 * neighbouring tetrahedra, as a pure function over plain arrays (positions
 * and velocities as xyz triples, a joint as six node indices), so the model
 * can call it per joint as it calls tet_forces per element.
 *
 * Contract:
 *  - node[6] = a0, a1, a2 (face A, ordered so that (a1-a0) x (a2-a0) points
 *    out of A's tetrahedron, towards B), b0, b1, b2 (B's copies of them).
 *  - The gap d = x_b - x_a is linear over the triangle; the normal n is that
 *    of the current mean face (a + d/2), the opening d.n, the sliding the
 *    rest of d. The cohesive law is joint_law.h's, at three points.
 *  - An undamaged joint below its strengths is a penalty k on the whole gap,
 *    integrated exactly: f_a_i = k A/12 (2 d_i + d_j + d_k).
 *  - Compression (d.n < 0) is resisted by k d.n integrated exactly over the
 *    shut part of the face while the joint holds.
 *  - fa[9] gets the forces on a0, a1, a2; B's nodes feel -fa (action =
 *    reaction, so they sum to zero); a rigid motion of the pair gives none.
 *  - *damage never decreases; at 1 the joint is broken: fa is zero, nothing
 *    is stored, and the function returns 0 (1 while it holds).
 *  - e gets the stored energy, the dissipation of damage growth, the
 *    frictional work over the last step (vel may be NULL: none) and, for a
 *    joint that broke shut, the compression energy contact takes over;
 *    e->broke the mode of a break in this call (joint_points_mode).
 */
#ifndef FDEM_JOINT_TET_H
#define FDEM_JOINT_TET_H

#include <stdint.h>

#include "joint_law.h"
#include "vec3.h"

#include <math.h>
#include <stddef.h>

/* h_last: the last step, so that x - h_last v is where the nodes were. */
int joint_tet_forces(const joint_law *law, const double *pos, const double *vel, double h_last,
                     const int32_t node[6], double *damage, double fa[9], joint_energy *e);

/* ------------------------------------------------ the intact fast path
 * Nearly every joint in nearly every step is undamaged and far inside its
 * strengths. These pieces of joint_tet_forces are inline so the model's
 * joint loop can give such a joint its forces without the call, the
 * damage bookkeeping or the per-point law: joint_tet_gaps, then
 * joint_tet_surely_elastic, then joint_tet_elastic_forces give the very
 * bits joint_tet_forces gives (it is built from the same three). */

/* The gaps d_i = b_i - a_i at the corners and the unnormalised normal N of
 * the mean face (a + d/2); returns |N|, twice the face's area. */
static inline double joint_tet_gaps(const double *pos, const int32_t node[6], double d[3][3],
                                    double N[3])
{
    double mean[3][3];
    for (int i = 0; i < 3; i++) {
        const double *a = pos + 3 * (size_t)node[i], *b = pos + 3 * (size_t)node[3 + i];
        vec3_sub(b, a, d[i]);
        for (int c = 0; c < 3; c++) mean[i][c] = a[c] + 0.5 * d[i][c];
    }
    double e1[3], e2[3];
    vec3_sub(mean[1], mean[0], e1);
    vec3_sub(mean[2], mean[0], e2);
    vec3_cross(e1, e2, N);
    return sqrt(vec3_dot(N, N));
}

/* Far enough inside the strengths that rounding cannot matter (below). */
#define JOINT_TET_SURE (1 - 1e-6)

/* True when an undamaged joint's every point is surely elastic, decided
 * from the corner gaps alone: a point's gap g is a convex mix of them, so
 * |g| <= max |d_i|, and its opening and sliding are each at most |g|, while
 * the shear strength is at least the cohesion. So k max |d_i| below the
 * smaller of f_t and c passes joint_point_elastic at every point; the
 * margin JOINT_TET_SURE, far above the few roundings of that test, makes
 * it pass in floating point too. No sqrt, no normal; false (the point test
 * then decides) for anything else, NaN included. */
static inline int joint_tet_surely_elastic(const joint_law *law, const double d[3][3])
{
    double ft = law->tensile_strength * JOINT_TET_SURE, c = law->cohesion * JOINT_TET_SURE;
    if (!(ft >= 0 && c >= 0 && law->tan_phi >= 0)) return 0;
    double limit = ft < c ? ft * ft : c * c, kk = law->k * law->k;
    return kk * vec3_dot(d[0], d[0]) <= limit && kk * vec3_dot(d[1], d[1]) <= limit &&
           kk * vec3_dot(d[2], d[2]) <= limit;
}

/* The faces' elastic forces fa, k d integrated exactly against the linear
 * shape functions; returns the stored energy 1/2 integral k |d|^2. */
static inline double joint_tet_elastic_forces(double k, double area, const double d[3][3],
                                              double fa[9])
{
    double s = k * area / 12, stored = 0;
    for (int c = 0; c < 3; c++) {
        double sum = d[0][c] + d[1][c] + d[2][c];
        for (int i = 0; i < 3; i++) fa[3 * i + c] = s * (d[i][c] + sum);
    }
    for (int i = 0; i < 3; i++) stored += 0.5 * vec3_dot(fa + 3 * i, d[i]);
    return stored;
}

/* The smallest |N| the fast path takes: far above where the projections
 * of the point test could underflow. */
#define JOINT_TET_TINY_NORMAL 1e-100

#endif /* FDEM_JOINT_TET_H */
