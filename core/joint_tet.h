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

/* h_last: the last step, so that x - h_last v is where the nodes were. */
int joint_tet_forces(const joint_law *law, const double *pos, const double *vel, double h_last,
                     const int32_t node[6], double *damage, double fa[9], joint_energy *e);

#endif /* FDEM_JOINT_TET_H */
