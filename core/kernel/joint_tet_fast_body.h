/*
 * joint_tet_fast_body.h - the intact, elastic 3D joint's expressions (the
 * fast path of joint_tet.h), written once over a number type JT_T and
 * included by joint_tet.h for double (one joint), a pair of doubles (two
 * joints side by side in one SIMD register, JT_FN suffix _pair) and, in
 * AVX2 code, four (_quad). Lanes round exactly as scalars do (IEEE, no
 * contraction under -std=c11), so a pair or a quad gives each joint the
 * bits it gets alone, as element_tet_kernel_body.h does for tetrahedra.
 * Not a header of its own: include joint_tet.h.
 */
#if !defined(JT_T) || !defined(JT_FN) || !defined(JT_SQRT) || !defined(JT_LOAD) || !defined(JT_IF)
#error "include joint_tet.h, not this file"
#endif

/* The gaps d_i = b_i - a_i at the corners and the unnormalised normal N of
 * the mean face (a + d/2) of joint n0 (and n1 in lane 1 of a pair; a
 * single joint reads only n0); returns |N|, twice the face's area. */
JOINT_TET_INLINE JT_T JT_FN(joint_tet_gaps_at)(const double *pos, const int32_t n0[6],
                                               const int32_t n1[6], JT_T d[3][3], JT_T N[3])
{
    JT_T mean[3][3];
    JOINT_TET_UNROLL
    for (int i = 0; i < 3; i++)
        JOINT_TET_UNROLL
        for (int c = 0; c < 3; c++) {
            JT_T a = JT_LOAD(pos, n0, n1, i, c), b = JT_LOAD(pos, n0, n1, 3 + i, c);
            d[i][c] = b - a;
            mean[i][c] = a + 0.5 * d[i][c];
        }
    JT_T e1[3], e2[3];
    JOINT_TET_UNROLL
    for (int c = 0; c < 3; c++) {
        e1[c] = mean[1][c] - mean[0][c];
        e2[c] = mean[2][c] - mean[0][c];
    }
    N[0] = e1[1] * e2[2] - e1[2] * e2[1];
    N[1] = e1[2] * e2[0] - e1[0] * e2[2];
    N[2] = e1[0] * e2[1] - e1[1] * e2[0];
    return JT_SQRT(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
}

/* True (all bits of a lane set, for a pair) when an undamaged joint of
 * penalty k, strengths ft and c and friction tan_phi is surely elastic at
 * every point, decided from the corner gaps alone: a point's gap g is a
 * convex mix of them, so |g| <= max |d_i|, and its opening and sliding are
 * each at most |g|, while the shear strength is at least the cohesion. So
 * k max |d_i| below the smaller of f_t and c passes joint_point_elastic at
 * every point; the margin JOINT_TET_SURE, far above the few roundings of
 * that test, makes it pass in floating point too. No sqrt, no normal; false
 * (the point test then decides) for anything else, NaN included. */
JOINT_TET_INLINE JT_MASK JT_FN(joint_tet_surely_elastic_of)(JT_T k, JT_T ft, JT_T c, JT_T tan_phi,
                                                            const JT_T d[3][3])
{
    JT_T ft2 = (ft * JOINT_TET_SURE) * (ft * JOINT_TET_SURE);
    JT_T c2 = (c * JOINT_TET_SURE) * (c * JOINT_TET_SURE), kk = k * k;
    JT_MASK sure = (ft >= 0) & (c >= 0) & (tan_phi >= 0);
    JOINT_TET_UNROLL
    for (int i = 0; i < 3; i++) {
        JT_T kd2 = kk * (d[i][0] * d[i][0] + d[i][1] * d[i][1] + d[i][2] * d[i][2]);
        sure &= (kd2 <= ft2) & (kd2 <= c2);
    }
    return sure;
}

/* The elastic test of an undamaged joint, the kernel's own (joint_tet.c
 * calls the one-joint form) and, lane by lane with the same operations,
 * the side-by-side paths': every point of the three-point rule within
 * joint_point_elastic's strengths, projected on the unnormalised normal N
 * (|N| = N_len). For what the test above cannot pass: a pressed joint. Its gaps are as large as its compression makes
 * them, far over f_t / k, while its shear strength grows with the
 * pressure; each such joint went through the kernel's call and point law,
 * which made a loaded 3D disc's joints 3.5x dearer a step before any
 * broke. Needs k >= 0 (then |k sl| is k sl). */
JOINT_TET_INLINE JT_MASK JT_FN(joint_tet_elastic_points_of)(JT_T k, JT_T ft, JT_T c, JT_T tan_phi,
                                                           const JT_T d[3][3], const JT_T N[3],
                                                           JT_T N_len)
{
    JT_MASK elastic = k >= 0;
    JOINT_TET_UNROLL
    for (int p = 0; p < 3; p++) {
        JT_T g[3], slide[3];
        JOINT_TET_UNROLL
        for (int i = 0; i < 3; i++)
            g[i] = joint_tet_rule[p][0] * d[0][i] + joint_tet_rule[p][1] * d[1][i] +
                   joint_tet_rule[p][2] * d[2][i];
        slide[0] = g[1] * N[2] - g[2] * N[1];
        slide[1] = g[2] * N[0] - g[0] * N[2];
        slide[2] = g[0] * N[1] - g[1] * N[0];
        JT_T on = g[0] * N[0] + g[1] * N[1] + g[2] * N[2];
        JT_T sl = JT_SQRT(slide[0] * slide[0] + slide[1] * slide[1] + slide[2] * slide[2]);
        JT_T ksig = k * on;
        JT_T shear_limit = c * N_len + JT_IF(on < 0, -ksig * tan_phi);
        elastic &= (ksig <= ft * N_len) & (k * sl <= shear_limit);
    }
    return elastic;
}

/* The faces' elastic forces fa, k d integrated exactly against the linear
 * shape functions (f_a_i = k A/12 (2 d_i + d_j + d_k)); returns the stored
 * energy 1/2 integral k |d|^2. */
JOINT_TET_INLINE JT_T JT_FN(joint_tet_elastic_forces_of)(JT_T k, JT_T area, const JT_T d[3][3],
                                                         JT_T fa[9])
{
    JT_T s = k * area / 12, stored = {0};
    JOINT_TET_UNROLL
    for (int c = 0; c < 3; c++) {
        JT_T sum = d[0][c] + d[1][c] + d[2][c];
        JOINT_TET_UNROLL
        for (int i = 0; i < 3; i++) fa[3 * i + c] = s * (d[i][c] + sum);
    }
    JOINT_TET_UNROLL
    for (int i = 0; i < 3; i++)
        stored += 0.5 * (fa[3 * i] * d[i][0] + fa[3 * i + 1] * d[i][1] + fa[3 * i + 2] * d[i][2]);
    return stored;
}

/* the parameters are this inclusion's alone: the next one defines its own */
#undef JT_T
#undef JT_MASK
#undef JT_FN
#undef JT_SQRT
#undef JT_LOAD
#undef JT_IF
