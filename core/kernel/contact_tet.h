/*
 * contact_tet.h - the potential contact force between two tetrahedra
 * (Munjiza & Andrews 2000, in 3D), as functions over plain arrays.
 *
 * Contract:
 *  - Each tetrahedron carries phi(P) = 4 min_i V_i(P) / V = 4 min_i lambda_i
 *    (lambda the barycentric coordinates): 1 at the centroid, 0 on the
 *    boundary, linear inside each sub-tetrahedron (centroid + one face).
 *  - The force on a contactor c from a target t is -p * (integral over the
 *    overlap of grad phi_t), turned by the divergence theorem into integrals
 *    of phi_t over the contactor's faces clipped to t's sub-tetrahedra (phi_t
 *    vanishes on t's own faces): per contactor face, F = -p n_f * integral
 *    phi_t dA along the face's outward unit normal n_f, acting at the
 *    potential's centroid on the face; it is shared by the face's 3 nodes by
 *    the barycentric coordinates of that point, and the equal and opposite
 *    force goes to t's 4 nodes by t's barycentric coordinates of the same
 *    point. Then the roles swap. Linear and angular momentum are conserved
 *    to round-off by construction.
 *  - The contactor face normal (not the target sub-tetrahedron's base face)
 *    carries the force, exactly as the triangle contact (contact_tri.c) uses the
 *    contactor edge normal: the two dimensions are the same method.
 *  - tet_contact_one_way / tet_contact_pair give the normal force alone;
 *    the contact stage's kernel, tet_contact_pair_force (contact_pair.h),
 *    adds Coulomb friction with elastic stick.
 */
#ifndef FDEM_CONTACT_TET_H
#define FDEM_CONTACT_TET_H

#include <stdint.h>

/* One way: adds the forces of contactor faces in the target's potential to
 * f_c (12 numbers, the contactor's 4 nodes) and f_t (the target's). Returns
 * the integral of phi_t over the contactor's faces (0: no contact). */
double tet_contact_one_way(const double *pos, const int32_t contactor[4],
                           const int32_t target[4], double penalty, double f_c[12],
                           double f_t[12]);

/* Both ways: f_a and f_b are set (not added) to the forces on a's and b's
 * nodes. Returns the summed integrals (0: no contact). */
double tet_contact_pair(const double *pos, const int32_t a[4], const int32_t b[4],
                        double penalty, double f_a[12], double f_b[12]);

#endif /* FDEM_CONTACT_TET_H */
