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
 *    is det times the rate of deformation D (no division here);
 *    tet_kernel_rate_of the same from the differences v_k - v_0.
 *  - tet_kernel_mid_faces: the face vectors and det of the mid-step edges
 *    e_k - (h/2)(v_k - v_0), where the damping's D is taken (a rigid
 *    motion's chord velocity is skew on them: element_tet_model.c).
 *  - tet_kernel_face_loads: g_a = s c_a for a stress s already scaled by
 *    1/6 and g_0 = g_1 + g_2 + g_3; the nodal forces are f_a = -g_a
 *    (-V sigma grad N_a = -sigma c_a / 6) and f_0 = g_0: the four sum to
 *    zero exactly. Unnegated, so a scatter subtracts and saves the signs.
 *    tet_kernel_face_loads_add adds a second stress's loads on other face
 *    vectors (g_1..g_3) and sums g_0 again.
 *  - tet_kernel_contract: s : S of two symmetric tensors in Voigt order.
 *  - Each of edges, faces, mid_faces, gradient, stress, prestress, rate,
 *    rate_of, contract, face_loads and face_loads_add also exists as
 *    name_pair over tet_pair, two elements in the lanes of one SIMD
 *    register (element_tet_kernel_body.h is written once for both), with
 *    the same bits per element as the scalar one.
 */
#ifndef FDEM_ELEMENT_TET_KERNEL_H
#define FDEM_ELEMENT_TET_KERNEL_H

#include "element_tet.h"
#include "math/log_near1.h"
#include "math/quad.h"

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

/* Two (four: quad.h's fdem_quad, for the AVX2 loop only) elements side by
 * side: lane k of every number is element k's. */
typedef double tet_pair __attribute__((vector_size(16)));

/* ln J and 1/J of a group of N lanes: log_short_series of log_near1.h on
 * every lane as vector operations when all are in its range (the same
 * operations per lane, so bit for bit what one element gets: keep the
 * expression that of log_short_series), the division as one vector; else
 * lane by lane through the scalar path. */
#define TET_LOG_INVERSE_LANES(T, N)                                                              \
    TET_KERNEL void tet_log_inverse_##T(T J, double j_min, T *lnJ, T *invJ)                      \
    {                                                                                           \
        T x = J - 1.0;                                                                          \
        int near = 1;                                                                           \
        for (int l = 0; l < N; l++) near &= fabs(x[l]) <= LOG_SHORT_RANGE;                      \
        if (near) {                                                                             \
            T x2 = x * x;                                                                       \
            T q = (-1.0 / 2 + x * (1.0 / 3)) + x2 * (-1.0 / 4 + x * (1.0 / 5));                 \
            *lnJ = x + x2 * q;                                                                  \
            *invJ = 1.0 / J;                                                                    \
            return;                                                                             \
        }                                                                                       \
        for (int l = 0; l < N; l++) {                                                           \
            double ln, inv;                                                                     \
            neo_hookean_log_inverse(J[l], j_min, &ln, &inv);                                    \
            (*lnJ)[l] = ln;                                                                     \
            (*invJ)[l] = inv;                                                                   \
        }                                                                                       \
    }
TET_LOG_INVERSE_LANES(tet_pair, 2)

#define TET_T double
#define TET_FN(name) name
#define TET_LOG_INVERSE neo_hookean_log_inverse
#include "element_tet_kernel_body.h"

#define TET_T tet_pair
#define TET_FN(name) name##_pair
#define TET_LOG_INVERSE tet_log_inverse_tet_pair
#include "element_tet_kernel_body.h"

/* The quads exist only as AVX2 code (GCC on x86-64; FDEM_QUADS says so,
 * quad.h): 32-byte vectors are no baseline x86-64 argument. */
#if FDEM_QUADS
#pragma GCC push_options
#pragma GCC target("avx2")
TET_LOG_INVERSE_LANES(fdem_quad, 4)
#define TET_T fdem_quad
#define TET_FN(name) name##_quad
#define TET_LOG_INVERSE tet_log_inverse_fdem_quad
#include "element_tet_kernel_body.h"
#pragma GCC pop_options
#endif

#endif /* FDEM_ELEMENT_TET_KERNEL_H */
