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
 *    the law continues along its tangent.
 *  - tet_kernel_rate: the symmetric part of sum_k (v_k - v_0) (x) c_k, which
 *    is det times the rate of deformation D (no division here).
 *  - tet_kernel_forces: f_a = -s c_a for a stress s already scaled by 1/6
 *    (f_a = -V sigma grad N_a = -sigma c_a / 6), node 0 minus the sum of
 *    the other three: the four sum to zero exactly.
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

TET_KERNEL void tet_kernel_edges(const double *p0, const double *p1, const double *p2,
                                    const double *p3, double e[3][3])
{
    TET_UNROLL
    for (int i = 0; i < 3; i++) {
        e[0][i] = p1[i] - p0[i];
        e[1][i] = p2[i] - p0[i];
        e[2][i] = p3[i] - p0[i];
    }
}

TET_KERNEL double tet_kernel_faces(const double e[3][3], double c[3][3])
{
    TET_UNROLL
    for (int k = 0; k < 3; k++) {
        const double *a = e[(k + 1) % 3], *b = e[(k + 2) % 3];
        c[k][0] = a[1] * b[2] - a[2] * b[1];
        c[k][1] = a[2] * b[0] - a[0] * b[2];
        c[k][2] = a[0] * b[1] - a[1] * b[0];
    }
    return e[0][0] * c[0][0] + e[0][1] * c[0][1] + e[0][2] * c[0][2];
}

/* F_ij = sum_k (e_k)_i xinv_kj */
TET_KERNEL void tet_kernel_gradient(const double e[3][3], const double xinv[9], double F[9])
{
    TET_UNROLL
    for (int i = 0; i < 3; i++)
        TET_UNROLL
        for (int j = 0; j < 3; j++)
            F[3 * i + j] = e[0][i] * xinv[j] + e[1][i] * xinv[3 + j] + e[2][i] * xinv[6 + j];
}

TET_KERNEL double tet_kernel_stress(const double F[9], double smu, double slambda,
                                       double hmu, double hlambda, double s[6], double *J_out)
{
    double J = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
               F[2] * (F[3] * F[7] - F[4] * F[6]);
    double lnJ, invJ;
    neo_hookean_log_inverse(J, TET_J_MIN, &lnJ, &invJ);
    /* B = F F^T */
    double B00 = F[0] * F[0] + F[1] * F[1] + F[2] * F[2];
    double B11 = F[3] * F[3] + F[4] * F[4] + F[5] * F[5];
    double B22 = F[6] * F[6] + F[7] * F[7] + F[8] * F[8];
    double B12 = F[3] * F[6] + F[4] * F[7] + F[5] * F[8];
    double B02 = F[0] * F[6] + F[1] * F[7] + F[2] * F[8];
    double B01 = F[0] * F[3] + F[1] * F[4] + F[2] * F[5];
    double muJ = smu * invJ, vol = slambda * lnJ * invJ;
    s[0] = muJ * (B00 - 1.0) + vol;
    s[1] = muJ * (B11 - 1.0) + vol;
    s[2] = muJ * (B22 - 1.0) + vol;
    s[3] = muJ * B12;
    s[4] = muJ * B02;
    s[5] = muJ * B01;
    *J_out = J;
    return hmu * (B00 + B11 + B22 - 3.0 - 2.0 * lnJ) + hlambda * lnJ * lnJ;
}

TET_KERNEL void tet_kernel_rate(const double *v0, const double *v1, const double *v2,
                                   const double *v3, const double c[3][3], double S[6])
{
    double dv[3][3];
    tet_kernel_edges(v0, v1, v2, v3, dv);
    double L[3][3];
    TET_UNROLL
    for (int i = 0; i < 3; i++)
        TET_UNROLL
        for (int j = 0; j < 3; j++)
            L[i][j] = dv[0][i] * c[0][j] + dv[1][i] * c[1][j] + dv[2][i] * c[2][j];
    S[0] = L[0][0];
    S[1] = L[1][1];
    S[2] = L[2][2];
    S[3] = 0.5 * (L[1][2] + L[2][1]);
    S[4] = 0.5 * (L[0][2] + L[2][0]);
    S[5] = 0.5 * (L[0][1] + L[1][0]);
}

/* s : S with the shear terms counted twice (symmetric tensors in Voigt order) */
TET_KERNEL double tet_kernel_contract(const double s[6], const double S[6])
{
    return s[0] * S[0] + s[1] * S[1] + s[2] * S[2] + 2 * (s[3] * S[3] + s[4] * S[4] + s[5] * S[5]);
}

TET_KERNEL void tet_kernel_forces(const double s[6], const double c[3][3], double f[4][3])
{
    TET_UNROLL
    for (int a = 1; a <= 3; a++) {
        const double *ca = c[a - 1];
        f[a][0] = -(s[0] * ca[0] + s[5] * ca[1] + s[4] * ca[2]);
        f[a][1] = -(s[5] * ca[0] + s[1] * ca[1] + s[3] * ca[2]);
        f[a][2] = -(s[4] * ca[0] + s[3] * ca[1] + s[2] * ca[2]);
    }
    TET_UNROLL
    for (int i = 0; i < 3; i++) f[0][i] = -(f[1][i] + f[2][i] + f[3][i]);
}

#endif /* FDEM_ELEMENT_TET_KERNEL_H */
