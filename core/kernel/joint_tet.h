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
 *  - slip[3] is what the joint's three points keep from evaluation to
 *    evaluation (joint_law.h: plastic slide in the face frame, slip path);
 *    zero for an undamaged joint, updated while it is damaged.
 *  - e gets the stored energy, what damage growth and slip dissipated
 *    (fracture, friction: each >= 0) and, for a joint that broke shut, the
 *    compression energy contact takes over; e->broke the mode of a break
 *    in this call (joint_points_mode).
 */
#ifndef FDEM_JOINT_TET_H
#define FDEM_JOINT_TET_H

#include <stdint.h>

#include "joint_law.h"
#include "math/quad.h"
#include "math/vec3.h"

#include <math.h>
#include <stddef.h>

int joint_tet_forces(const joint_law *law, const double *pos, const int32_t node[6],
                     double *damage, joint_slip slip[3], double fa[9], joint_energy *e);

/* joint_tet_forces for a joint whose gaps d, normal N and |N| the caller
 * already has from joint_tet_gaps (or a lane of joint_tet_gaps_at_pair:
 * the same bits), so that a joint the fast path turned down does not
 * compute them again. */
int joint_tet_forces_of_gaps(const joint_law *law, const double *pos, const double d[3][3],
                             const double N[3], double N_len, const int32_t node[6],
                             double *damage, joint_slip slip[3], double fa[9], joint_energy *e);

/* The face's own frame (unit n given): t1 along the mean first edge
 * (a + d/2) projected into the face, t2 = n x t1; 0 for an edge of no
 * length. The slide's components and the in-situ offsets live in it. */
int joint_tet_face_frame(const double *pos, const int32_t node[6], const double d[3][3],
                         const double n[3], double t1[3], double t2[3]);

/* Adds a joint's in-situ gap to its corner gaps d (from joint_tet_gaps,
 * whose N and |N| it takes): offset[3 i .. 3 i + 2] is corner i's opening
 * and its slide along t1 and t2 of the face's frame, turned into the
 * current frame, so the offset turns with the face. Returns 0 (d left as
 * it was) for a degenerate face. */
int joint_tet_add_offsets(const double *pos, const int32_t node[6], const double N[3],
                          double N_len, const double offset[9], double d[3][3]);

/* ------------------------------------------------ the intact fast path
 * Nearly every joint in nearly every step is undamaged and far inside its
 * strengths. These pieces of joint_tet_forces are inline so the model's
 * joint loop can give such a joint its forces without the call, the
 * damage bookkeeping or the per-point law, one joint or two side by side
 * (joint_tet_fast_body.h, written once for both): joint_tet_gaps, then
 * joint_tet_surely_elastic, then joint_tet_elastic_forces give the very
 * bits joint_tet_forces gives (it is built from the same three). Forced
 * inline and unrolled, as element_tet_kernel.h's: gcc -O2 keeps the small
 * loops, and the gaps and forces then go through memory, where wide loads
 * of narrow stores stall on store forwarding. */
#if defined(__GNUC__)
#define JOINT_TET_INLINE static inline __attribute__((always_inline))
#define JOINT_TET_UNROLL _Pragma("GCC unroll 16")
#else
#define JOINT_TET_INLINE static inline
#define JOINT_TET_UNROLL
#endif

/* Far enough inside the strengths that rounding cannot matter
 * (joint_tet_surely_elastic). */
#define JOINT_TET_SURE (1 - 1e-6)

/* The smallest |N| the fast path takes: far above where the projections
 * of the point test could underflow. */
#define JOINT_TET_TINY_NORMAL 1e-100

/* Two joints side by side: lane k of every number is joint k's; a
 * comparison gives a lane of all bits set where it holds. */
typedef double joint_pair __attribute__((vector_size(16)));
typedef long long joint_pair_mask __attribute__((vector_size(16)));

/* IEEE 754 rounds a square root correctly, so the packed instruction gives
 * each lane the bits sqrt gives it alone; where the vector square root is
 * not at hand, lane by lane. */
JOINT_TET_INLINE joint_pair joint_pair_sqrt(joint_pair x)
{
#if FDEM_QUADS
    return __builtin_ia32_sqrtpd(x);
#else
    return (joint_pair){sqrt(x[0]), sqrt(x[1])};
#endif
}

/* Coordinate c of corner k (0-2 face A, 3-5 face B) of the joint(s). */
#define JOINT_TET_AT(pos, n, k, c) (pos)[3 * (size_t)(n)[k] + (c)]

/* The symmetric three-point rule on the triangle, barycentric: the points
 * of the law (joint_tet.c) and of the elastic test (joint_tet_fast_body.h). */
static const double joint_tet_rule[3][3] = {{2.0 / 3, 1.0 / 6, 1.0 / 6},
                                            {1.0 / 6, 2.0 / 3, 1.0 / 6},
                                            {1.0 / 6, 1.0 / 6, 2.0 / 3}};

#define JT_T double
#define JT_MASK int
#define JT_FN(name) name
#define JT_SQRT sqrt
#define JT_LOAD(pos, n0, n1, k, c) JOINT_TET_AT(pos, n0, k, c)
#define JT_IF(mask, x) ((mask) ? (x) : 0)
#include "joint_tet_fast_body.h"

#define JT_T joint_pair
#define JT_MASK joint_pair_mask
#define JT_FN(name) name##_pair
#define JT_SQRT joint_pair_sqrt
#define JT_LOAD(pos, n0, n1, k, c) \
    ((joint_pair){JOINT_TET_AT(pos, n0, k, c), JOINT_TET_AT(pos, n1, k, c)})
#define JT_IF(mask, x) ((joint_pair)((joint_pair_mask)(x) & (mask)))
#include "joint_tet_fast_body.h"

/* Four joints side by side exist only as AVX2 code (GCC on x86-64;
 * FDEM_QUADS says so, quad.h): 32-byte vectors are no baseline x86-64
 * argument. The four are consecutive, corners n0, n0 + 6, n0 + 12 and
 * n0 + 18 (n1 is not read). */
#if FDEM_QUADS
#pragma GCC push_options
#pragma GCC target("avx2")

/* One packed square root, not four (joint_pair_sqrt): the scalar four, with
 * the lane extractions they need, were about a seventh of the joint loop's
 * time (perf annotate, 1e4 tetrahedra). */
JOINT_TET_INLINE fdem_quad joint_quad_sqrt(fdem_quad x)
{
    return __builtin_ia32_sqrtpd256(x);
}

#define JT_T fdem_quad
#define JT_MASK fdem_quad_mask
#define JT_FN(name) name##_quad
#define JT_SQRT joint_quad_sqrt
#define JT_LOAD(pos, n0, n1, k, c)                                                               \
    ((fdem_quad){JOINT_TET_AT(pos, n0, k, c), JOINT_TET_AT(pos, (n0) + 6, k, c),               \
                  JOINT_TET_AT(pos, (n0) + 12, k, c), JOINT_TET_AT(pos, (n0) + 18, k, c)})
#define JT_IF(mask, x) ((fdem_quad)((fdem_quad_mask)(x) & (mask)))
#include "joint_tet_fast_body.h"
#pragma GCC pop_options
#endif

/* joint_tet_gaps_at for one joint, corners node[6]. */
JOINT_TET_INLINE double joint_tet_gaps(const double *pos, const int32_t node[6], double d[3][3],
                                       double N[3])
{
    return joint_tet_gaps_at(pos, node, node, d, N);
}

JOINT_TET_INLINE int joint_tet_surely_elastic(const joint_law *law, const double d[3][3])
{
    return joint_tet_surely_elastic_of(law->k, law->tensile_strength, law->cohesion, law->tan_phi,
                                       d);
}

JOINT_TET_INLINE double joint_tet_elastic_forces(double k, double area, const double d[3][3],
                                                 double fa[9])
{
    return joint_tet_elastic_forces_of(k, area, d, fa);
}

#endif /* FDEM_JOINT_TET_H */
