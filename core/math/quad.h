/*
 * quad.h - the four-wide double vector of the AVX2 loops.
 *
 * The tetrahedron loop, the joint loop and the integrator's free update
 * each have a variant that carries four items in one 32-byte register,
 * compiled under
 * #pragma GCC target("avx2") and chosen at run time. Such vectors are
 * GCC's vector extension on x86-64 only: FDEM_QUADS is 1 where they exist
 * and 0 elsewhere, where only the baseline loops are built. Lane k of a
 * vector is item k's, so a lane gets the operations one item gets alone.
 */
#ifndef FDEM_QUAD_H
#define FDEM_QUAD_H

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FDEM_QUADS 1
typedef double fdem_quad __attribute__((vector_size(32)));
typedef long long fdem_quad_mask __attribute__((vector_size(32))); /* all-ones lanes: true */
#else
#define FDEM_QUADS 0
#endif

#endif /* FDEM_QUAD_H */
