/*
 * element_tet_lanes.h - a group of TET_N tetrahedra of one material side by
 * side in the lanes of the vector type TET_V, written once and included by
 * element_tet_model.c for pairs (tet_pair, SSE2) and quads (fdem_quad, the
 * AVX2 loop). Per element the same operations in the same order as
 * tet_forces_one, so the same bits whatever the group; the sums and the
 * scatter go element by element in element order. Not a header of its
 * own: it needs element_tet_model.c's helpers and these macros:
 *   TET_V, TET_N        the vector type and its lane count
 *   TET_VFN(name)       name with the kernel's suffix (_pair, _quad)
 *   TET_GATHER(p, i)    the vector of p[lane][i] over the lanes
 *   TET_GATHER_OWN(xyz, t, x), TET_STORE_OWN(f, t, g)
 *                       tet_gather_nodes and the storing scatter for a group
 *                       whose elements' nodes are their own and consecutive
 *                       (model_part_stores_forces): whole rows moved and
 *                       transposed, or the lane by lane way
 *   TET_LOAD_SIX(rows, v), TET_STORE_SIX(rows, v)
 *                       v[q] = the vector of rows[6 lane + q], q < 6, and
 *                       back (the group's stored viscous stresses)
 */
#if !defined(TET_V) || !defined(TET_N) || !defined(TET_VFN) || !defined(TET_GATHER) ||           \
    !defined(TET_GATHER_OWN) || !defined(TET_STORE_OWN) || !defined(TET_LOAD_SIX) ||        \
    !defined(TET_STORE_SIX)
#error "element_tet_lanes.h is included by element_tet_model.c only"
#endif

/* x[a][i] = component i of node a of each lane's element (xyz triples). */
TET_KERNEL void TET_VFN(tet_gather_nodes)(const double *xyz, const tet_hot *t, TET_V x[4][3])
{
    const double *p[TET_N];
    TET_UNROLL
    for (int a = 0; a < 4; a++) {
        TET_UNROLL
        for (int l = 0; l < TET_N; l++) p[l] = xyz + 3 * (size_t)t[l].node[a];
        TET_UNROLL
        for (int i = 0; i < 3; i++) x[a][i] = TET_GATHER(p, i);
    }
}

/* The forces of lane `lane` of g (tet_kernel_face_loads): f_0 = g_0 added,
 * f_a = -g_a subtracted (`store`: vec3_scatter). */
TET_KERNEL void TET_VFN(tet_scatter_lane)(double *f, const int32_t node[4], const TET_V g[4][3],
                                          int lane, const int store)
{
    TET_UNROLL
    for (int a = 0; a < 4; a++)
        vec3_scatter(f, node[a], g[a][0][lane], g[a][1][lane], g[a][2][lane], a == 0, store);
}

/* Lane `lane` of a group's edges and face loads as scalars, the damping
 * applied to it (tet_damp), and the loads put back. */
static inline void TET_VFN(tet_damp_lane)(const fdem_model *m, const tet_hot *t, int lane,
                                          const TET_V e[3][3], TET_V g[4][3], tet_sums *sum)
{
    double el[3][3], gl[4][3];
    TET_UNROLL
    for (int q = 0; q < 9; q++) el[q / 3][q % 3] = e[q / 3][q % 3][lane];
    TET_UNROLL
    for (int q = 0; q < 12; q++) gl[q / 3][q % 3] = g[q / 3][q % 3][lane];
    tet_damp(m, t, el, gl, sum);
    TET_UNROLL
    for (int q = 0; q < 12; q++) g[q / 3][q % 3][lane] = gl[q / 3][q % 3];
}

/* The damping of a group with edges e and face loads g (every eta > 0,
 * none flat at mid-step), lane by lane what tet_damp does to each element
 * alone, the powers booked in element order as one at a time would; else
 * each damped lane through tet_damp_lane. */
TET_KERNEL void TET_VFN(tet_damp_group)(const fdem_model *m, const tet_hot *t,
                                        const TET_V e[3][3], TET_V g[4][3], tet_sums *sum,
                                        const int store)
{
    TET_V v[4][3], dv[3][3], cm[3][3], S[6], sv[6], prev[6], eta2;
    if (store)
        TET_GATHER_OWN(m->vel, t, v);
    else
        TET_VFN(tet_gather_nodes)(m->vel, t, v);
    TET_VFN(tet_kernel_edges)(v[0], v[1], v[2], v[3], dv);
    TET_V det = TET_VFN(tet_kernel_mid_faces)(e, dv, 0.5 * m->dt_prev, cm);
    int all = 1;
    TET_UNROLL
    for (int l = 0; l < TET_N; l++) all &= t[l].eta > 0 && fabs(det[l]) > 0;
    if (!all) {
        for (int l = 0; l < TET_N; l++)
            if (t[l].eta > 0) TET_VFN(tet_damp_lane)(m, t + l, l, e, g, sum);
        return;
    }
    TET_VFN(tet_kernel_rate_of)(dv, cm, S);
    TET_UNROLL
    for (int l = 0; l < TET_N; l++) eta2[l] = 2 * t[l].eta;
    TET_V scale = eta2 / det;
    /* the group's stored stresses are adjacent, 6 numbers each */
    double *stored = m->elem_viscous + 6 * (size_t)(t - m->tet);
    TET_LOAD_SIX(stored, prev);
    TET_UNROLL
    for (int q = 0; q < 6; q++) sv[q] = scale * S[q];
    TET_V now = TET_VFN(tet_kernel_contract)(sv, S), before = TET_VFN(tet_kernel_contract)(prev, S);
    TET_UNROLL
    for (int l = 0; l < TET_N; l++) {
        sum->power_now -= now[l];
        sum->power_prev -= before[l];
    }
    TET_V sixth[6];
    TET_UNROLL
    for (int q = 0; q < 6; q++) sixth[q] = sv[q] * (1.0 / 6);
    TET_VFN(tet_kernel_face_loads_add)(sixth, cm, g);
    TET_STORE_SIX(stored, sv);
}

/* TET_N elements t[0 .. TET_N-1] of one material. */
TET_KERNEL void TET_VFN(tet_forces_group)(fdem_model *m, const tet_hot *t, tet_constants *k,
                                          tet_sums *sum, const int stressed, const int store)
{
    const double *p[TET_N];
    TET_V x[4][3], X[9];
    if (store)
        TET_GATHER_OWN(m->pos, t, x);
    else
        TET_VFN(tet_gather_nodes)(m->pos, t, x);
    TET_UNROLL
    for (int l = 0; l < TET_N; l++) p[l] = t[l].xinv;
    TET_UNROLL
    for (int q = 0; q < 9; q++) X[q] = TET_GATHER(p, q);
    TET_V e[3][3], c[3][3], F[9], s[6], J, invJ;
    TET_VFN(tet_kernel_edges)(x[0], x[1], x[2], x[3], e);
    TET_VFN(tet_kernel_gradient)(e, X, F);
    tet_constants_load(k, m->materials, t->material);
    TET_V w = TET_VFN(tet_kernel_stress)(F, k->smu, k->slambda, k->hmu, k->hlambda, s, &J, &invJ);
    if (stressed) {
        TET_UNROLL
        for (int l = 0; l < TET_N; l++) p[l] = tet_stress0(m, t + l);
        TET_V S0[6];
        TET_UNROLL
        for (int q = 0; q < 6; q++) S0[q] = TET_GATHER(p, q);
        w += TET_VFN(tet_kernel_prestress)(F, invJ * (1.0 / 6), S0, s);
    }
    TET_VFN(tet_kernel_faces)(e, c);
    TET_V g[4][3];
    TET_VFN(tet_kernel_face_loads)(s, c, g);
    int damped = 0;
    TET_UNROLL
    for (int l = 0; l < TET_N; l++) damped |= t[l].eta > 0;
    if (damped) TET_VFN(tet_damp_group)(m, t, e, g, sum, store);
    TET_UNROLL
    for (int l = 0; l < TET_N; l++) sum->energy += w[l] * t[l].volume0;
    if (store) {
        TET_STORE_OWN(m->force, t, g);
        return;
    }
    TET_UNROLL
    for (int l = 0; l < TET_N; l++) TET_VFN(tet_scatter_lane)(m->force, t[l].node, g, l, 0);
}

/* the parameters are this inclusion's alone: the next one defines its own */
#undef TET_V
#undef TET_N
#undef TET_VFN
#undef TET_GATHER
#undef TET_GATHER_OWN
#undef TET_STORE_OWN
#undef TET_LOAD_SIX
#undef TET_STORE_SIX
