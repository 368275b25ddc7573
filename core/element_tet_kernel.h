/*
 * element_tet_kernel.h - the per-element arithmetic of the constant-strain
 * tetrahedron, inline, so that the plain-array functions of element_tet.c
 * (what the unit tests hold to closed forms) and the engine's hot loop in
 * element_tet_model.c are the same expressions, not two versions of them.
 *
 * Contract (positions and velocities are xyz triples; Voigt order xx, yy,
 * zz, yz, xz, xy as in contract 5.2):
 *  - tet_kernel_edges: e_k = x_{k+1} - x_0; tet_kernel_faces: the face
 *    vectors c_1 = e_2 x e_3, c_2 = e_3 x e_1, c_3 = e_1 x e_2 (twice the
 *    area vectors of the faces through node 0), returns det = e_1 . c_1 = 6V.
 *  - tet_kernel_gradient: F = [x][X]^-1 from the edges and the stored
 *    [X]^-1 (row-major).
 *  - tet_kernel_stress: the neo-Hookean Cauchy stress times a scale s,
 *    s sigma = (s mu / J)(B - I) + (s lambda / J) ln J I, for the constants
 *    already scaled (smu = s mu, slambda = s lambda); returns the strain
 *    energy density per initial volume from hmu = mu/2, hlambda = lambda/2.
 *    Scaling the constants instead of the stress is free in a loop that
 *    loads them once per material. ln J by log_near1.h; below TET_J_MIN
 *    the law continues along its tangent. J and the 1/J the law used come
 *    back through the pointers.
 *  - tet_kernel_prestress: adds scale F S0 F^T (an in-situ pre-stress S0
 *    pushed forward) to a stress, returns S0 : E.
 *  - tet_kernel_rate: the symmetric part of sum_k (v_k - v_0) (x) c_k, which
 *    is det times the rate of deformation D (no division here).
 *  - tet_kernel_face_loads: g_a = s c_a for a stress s already scaled by
 *    1/6 and g_0 = g_1 + g_2 + g_3; the nodal forces are f_a = -g_a
 *    (-V sigma grad N_a = -sigma c_a / 6) and f_0 = g_0: the four sum to
 *    zero exactly. Unnegated, so a scatter subtracts and saves the signs.
 *  - tet_kernel_contract: s : S of two symmetric tensors in Voigt order.
 *  - Each of edges, faces, gradient, stress, prestress, rate, contract and
 *    face_loads also exists as name_pair over tet_pair, two elements in the
 *    lanes of one SIMD register (element_tet_kernel_body.h is written once
 *    for both), with the same bits per element as the scalar one.
 */
#ifndef FDEM_ELEMENT_TET_KERNEL_H
#define FDEM_ELEMENT_TET_KERNEL_H

#include "element_tet.h"
#include "log_near1.h"

/* Forced inline, and the small loops fully unrolled (gcc -O2 keeps some as
 * loops): otherwise F, the stress and the forces go through memory, and
 * wide loads of narrow stores stall on store forwarding. */
#if defined(__GNUC__)
#define TET_KERNEL static inline __attribute__((always_inline))
#define TET_UNROLL _Pragma("GCC unroll 16")
#else
#define TET_KERNEL static inline
#define TET_UNROLL
#endif

/* Two elements side by side: lane k of every number is element k's. */
typedef double tet_pair __attribute__((vector_size(16)));

/* ln J and 1/J of a pair: the series on both lanes in the usual case
 * (lane by lane, bit for bit what one element gets), the division as one
 * vector; the rare lane outside it through the scalar path. */
static inline void tet_log_inverse_pair(tet_pair J, double j_min, tet_pair *lnJ, tet_pair *invJ)
{
    tet_pair x = J - 1.0;
    if (fabs(x[0]) <= LOG_SHORT_RANGE && fabs(x[1]) <= LOG_SHORT_RANGE) {
        *lnJ = (tet_pair){log_short_series(x[0]), log_short_series(x[1])};
        *invJ = 1.0 / J;
        return;
    }
    double l0, l1, i0, i1;
    neo_hookean_log_inverse(J[0], j_min, &l0, &i0);
    neo_hookean_log_inverse(J[1], j_min, &l1, &i1);
    *lnJ = (tet_pair){l0, l1};
    *invJ = (tet_pair){i0, i1};
}

#define TET_T double
#define TET_FN(name) name
#define TET_LOG_INVERSE neo_hookean_log_inverse
#include "element_tet_kernel_body.h"
#undef TET_T
#undef TET_FN
#undef TET_LOG_INVERSE

#define TET_T tet_pair
#define TET_FN(name) name##_pair
#define TET_LOG_INVERSE tet_log_inverse_pair
#include "element_tet_kernel_body.h"
#undef TET_T
#undef TET_FN
#undef TET_LOG_INVERSE

#endif /* FDEM_ELEMENT_TET_KERNEL_H */
