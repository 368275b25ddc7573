/*
 * element_tet_kernel_body.h - the tetrahedron's per-element expressions,
 * written once over a number type TET_T and included by
 * element_tet_kernel.h for double (one element), a pair of doubles (two
 * elements side by side in one SIMD register, TET_FN suffix _pair) and, in
 * AVX2 code, four (_quad).
 * Vector lanes round exactly as scalars do (IEEE, no contraction under
 * -std=c11), so a pair gives each element the bits it gets alone.
 * Not a header of its own: include element_tet_kernel.h.
 */
#if !defined(TET_T) || !defined(TET_FN) || !defined(TET_LOG_INVERSE)
#error "include element_tet_kernel.h, not this file"
#endif

TET_KERNEL void TET_FN(tet_kernel_edges)(const TET_T *p0, const TET_T *p1, const TET_T *p2,
                                         const TET_T *p3, TET_T e[3][3])
{
    TET_UNROLL
    for (int i = 0; i < 3; i++) {
        e[0][i] = p1[i] - p0[i];
        e[1][i] = p2[i] - p0[i];
        e[2][i] = p3[i] - p0[i];
    }
}

TET_KERNEL TET_T TET_FN(tet_kernel_faces)(const TET_T e[3][3], TET_T c[3][3])
{
    TET_UNROLL
    for (int k = 0; k < 3; k++) {
        const TET_T *a = e[(k + 1) % 3], *b = e[(k + 2) % 3];
        c[k][0] = a[1] * b[2] - a[2] * b[1];
        c[k][1] = a[2] * b[0] - a[0] * b[2];
        c[k][2] = a[0] * b[1] - a[1] * b[0];
    }
    return e[0][0] * c[0][0] + e[0][1] * c[0][1] + e[0][2] * c[0][2];
}

/* F_ij = sum_k (e_k)_i xinv_kj */
TET_KERNEL void TET_FN(tet_kernel_gradient)(const TET_T e[3][3], const TET_T xinv[9], TET_T F[9])
{
    TET_UNROLL
    for (int i = 0; i < 3; i++)
        TET_UNROLL
        for (int j = 0; j < 3; j++)
            F[3 * i + j] = e[0][i] * xinv[j] + e[1][i] * xinv[3 + j] + e[2][i] * xinv[6 + j];
}

TET_KERNEL TET_T TET_FN(tet_kernel_stress)(const TET_T F[9], double smu, double slambda,
                                           double hmu, double hlambda, TET_T s[6], TET_T *J_out,
                                           TET_T *invJ_out)
{
    TET_T J = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
              F[2] * (F[3] * F[7] - F[4] * F[6]);
    TET_T lnJ, invJ;
    TET_LOG_INVERSE(J, TET_J_MIN, &lnJ, &invJ);
    /* B = F F^T */
    TET_T B00 = F[0] * F[0] + F[1] * F[1] + F[2] * F[2];
    TET_T B11 = F[3] * F[3] + F[4] * F[4] + F[5] * F[5];
    TET_T B22 = F[6] * F[6] + F[7] * F[7] + F[8] * F[8];
    TET_T B12 = F[3] * F[6] + F[4] * F[7] + F[5] * F[8];
    TET_T B02 = F[0] * F[6] + F[1] * F[7] + F[2] * F[8];
    TET_T B01 = F[0] * F[3] + F[1] * F[4] + F[2] * F[5];
    TET_T muJ = smu * invJ, vol = slambda * lnJ * invJ;
    s[0] = muJ * (B00 - 1.0) + vol;
    s[1] = muJ * (B11 - 1.0) + vol;
    s[2] = muJ * (B22 - 1.0) + vol;
    s[3] = muJ * B12;
    s[4] = muJ * B02;
    s[5] = muJ * B01;
    *J_out = J;
    *invJ_out = invJ;
    return hmu * (B00 + B11 + B22 - 3.0 - 2.0 * lnJ) + hlambda * lnJ * lnJ;
}

/* g_a = s c_a (a = 1..3) and g_0 = g_1 + g_2 + g_3: the forces are f_a =
 * -g_a and f_0 = g_0, left unnegated so that a scatter subtracts instead
 * (x - g is x + (-g) exactly, and negation rounds symmetrically). */
TET_KERNEL void TET_FN(tet_kernel_face_loads)(const TET_T s[6], const TET_T c[3][3],
                                              TET_T g[4][3])
{
    TET_UNROLL
    for (int a = 1; a <= 3; a++) {
        const TET_T *ca = c[a - 1];
        g[a][0] = s[0] * ca[0] + s[5] * ca[1] + s[4] * ca[2];
        g[a][1] = s[5] * ca[0] + s[1] * ca[1] + s[3] * ca[2];
        g[a][2] = s[4] * ca[0] + s[3] * ca[1] + s[2] * ca[2];
    }
    TET_UNROLL
    for (int i = 0; i < 3; i++) g[0][i] = g[1][i] + g[2][i] + g[3][i];
}

/* g_a += s c_a (a = 1..3) and g_0 = g_1 + g_2 + g_3 again: the loads of a
 * second stress on other face vectors (the viscous stress on the mid-step
 * faces) added to those of tet_kernel_face_loads, the four still summing
 * to zero exactly. */
TET_KERNEL void TET_FN(tet_kernel_face_loads_add)(const TET_T s[6], const TET_T c[3][3],
                                                  TET_T g[4][3])
{
    TET_UNROLL
    for (int a = 1; a <= 3; a++) {
        const TET_T *ca = c[a - 1];
        g[a][0] += s[0] * ca[0] + s[5] * ca[1] + s[4] * ca[2];
        g[a][1] += s[5] * ca[0] + s[1] * ca[1] + s[3] * ca[2];
        g[a][2] += s[4] * ca[0] + s[3] * ca[1] + s[2] * ca[2];
    }
    TET_UNROLL
    for (int i = 0; i < 3; i++) g[0][i] = g[1][i] + g[2][i] + g[3][i];
}

/* s += scale F S0 F^T: the in-situ pre-stress S0 pushed forward (scale =
 * 1/J, or 1/(6J) for the sixth stress); returns its strain energy density
 * S0 : E = (tr(F S0 F^T) - tr S0) / 2 (initial_stress.c). */
TET_KERNEL TET_T TET_FN(tet_kernel_prestress)(const TET_T F[9], TET_T scale, const TET_T S0[6],
                                              TET_T s[6])
{
    const TET_T M[9] = {S0[0], S0[5], S0[4], S0[5], S0[1], S0[3], S0[4], S0[3], S0[2]};
    TET_T FS[9];
    TET_UNROLL
    for (int i = 0; i < 3; i++)
        TET_UNROLL
        for (int j = 0; j < 3; j++)
            FS[3 * i + j] = F[3 * i] * M[j] + F[3 * i + 1] * M[3 + j] + F[3 * i + 2] * M[6 + j];
    /* tau_ij = row i of F S0 . row j of F, in Voigt order */
    static const int row[6] = {0, 1, 2, 1, 0, 0}, col[6] = {0, 1, 2, 2, 2, 1};
    TET_T tau[6];
    TET_UNROLL
    for (int q = 0; q < 6; q++) {
        int i = row[q], j = col[q];
        tau[q] = FS[3 * i] * F[3 * j] + FS[3 * i + 1] * F[3 * j + 1] + FS[3 * i + 2] * F[3 * j + 2];
        s[q] += scale * tau[q];
    }
    return 0.5 * (tau[0] + tau[1] + tau[2] - S0[0] - S0[1] - S0[2]);
}

/* The face vectors c of the mid-step edges e - hh dv (e the edges, dv the
 * velocity differences v_k - v_0, hh = h_last / 2); returns their det. */
TET_KERNEL TET_T TET_FN(tet_kernel_mid_faces)(const TET_T e[3][3], const TET_T dv[3][3], double hh,
                                              TET_T c[3][3])
{
    TET_T em[3][3];
    TET_UNROLL
    for (int k = 0; k < 3; k++)
        TET_UNROLL
        for (int i = 0; i < 3; i++) em[k][i] = e[k][i] - hh * dv[k][i];
    return TET_FN(tet_kernel_faces)(em, c);
}

/* tet_kernel_rate from the velocity differences dv[k] = v_{k+1} - v_0. */
TET_KERNEL void TET_FN(tet_kernel_rate_of)(const TET_T dv[3][3], const TET_T c[3][3], TET_T S[6])
{
    TET_T L[3][3];
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

TET_KERNEL void TET_FN(tet_kernel_rate)(const TET_T *v0, const TET_T *v1, const TET_T *v2,
                                        const TET_T *v3, const TET_T c[3][3], TET_T S[6])
{
    TET_T dv[3][3];
    TET_FN(tet_kernel_edges)(v0, v1, v2, v3, dv);
    TET_FN(tet_kernel_rate_of)(dv, c, S);
}

/* s : S with the shear terms counted twice (symmetric tensors in Voigt order) */
TET_KERNEL TET_T TET_FN(tet_kernel_contract)(const TET_T s[6], const TET_T S[6])
{
    return s[0] * S[0] + s[1] * S[1] + s[2] * S[2] + 2 * (s[3] * S[3] + s[4] * S[4] + s[5] * S[5]);
}

/* the parameters are this inclusion's alone: the next one defines its own */
#undef TET_T
#undef TET_FN
#undef TET_LOG_INVERSE
