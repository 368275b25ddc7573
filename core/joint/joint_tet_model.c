/*
 * joint_tet_model.c - 6-node joints in a model of tetrahedra: one on every
 * face shared by two tetrahedra of a fracturing part (each tetrahedron
 * keeps its own nodes), their forces through joint_tet.c's kernel, and
 * their stable step. The dimension-free joint machinery (stiffness,
 * contact exclusion, fragments, breakage counting) stays in joint.c, which
 * calls in here where the geometry is a triangle and not an edge.
 */
#include <math.h>
#include <stdlib.h>

#include "kernel/element_tet.h"
#include "kernel/joint_tet.h"
#include "model/model.h"
#include "math/node_ids.h"
#include "math/vec3.h"
#include "joint.h"

typedef struct face_ref {
    int32_t key[3];   /* original node ids, ascending */
    int32_t tet;      /* tetrahedron within the part */
    int32_t face;     /* tet_face_nodes row */
} face_ref;

static int face_compare(const void *pa, const void *pb)
{
    const face_ref *a = pa, *b = pb;
    int c = node_ids_compare(a->key, b->key, 3);
    return c ? c : a->tet < b->tet ? -1 : a->tet > b->tet;
}

static int same_face(const face_ref *a, const face_ref *b)
{
    return node_ids_compare(a->key, b->key, 3) == 0;
}

/* Writes joint j between face f_a of element ea and the same face of eb:
 * a0, a1, a2 in ea's outward order, b_i eb's copy of a_i's original node. */
static void joint_set_3d(fdem_model *m, int j, const int32_t *tet, const face_ref *a,
                         const face_ref *b, int ea, int eb)
{
    int32_t *jn = m->joint_node + 6 * (size_t)j;
    for (int i = 0; i < 3; i++) {
        int corner = tet_face_nodes[a->face][i];
        int32_t orig = tet[4 * a->tet + corner];
        jn[i] = m->tet[ea].node[corner];
        for (int c = 0; c < 4; c++)
            if (tet[4 * b->tet + c] == orig) jn[3 + i] = m->tet[eb].node[c];
    }
    m->joint_elem[2 * j] = ea;
    m->joint_elem[2 * j + 1] = eb;
}

/* A joint to be: its two tetrahedra (a < b, face_compare's tie-break) and
 * where face A sits in the sorted faces (B follows it). */
typedef struct joint_pair_ref {
    int32_t tet_a, tet_b;
    size_t face;
} joint_pair_ref;

/* The joints in the order of their tetrahedra, (tet B, tet A) ascending:
 * the step's joint loop then walks B's private nodes in order, as the
 * element loop does, and each A (a lower tetrahedron: the cell before, the
 * row or the layer below) was met as a B a little earlier and is still in
 * cache. The faces' key order (original node ids) sent consecutive joints
 * to tetrahedra far apart; at 1e5 tetrahedra, beyond the caches, the loop
 * took about 36 ns a joint in that order, 39 in (A, B) order and 30 in
 * this one (interleaved runs). The contract fixes no joint order; this one
 * is fixed at build, so ids agree everywhere (events, checkpoints,
 * /mesh/joints). Two tetrahedra share at most one face: no two keys tie. */
static int pair_compare(const void *pa, const void *pb)
{
    const joint_pair_ref *a = pa, *b = pb;
    if (a->tet_b != b->tet_b) return a->tet_b < b->tet_b ? -1 : 1;
    return a->tet_a < b->tet_a ? -1 : a->tet_a > b->tet_a;
}

/* Adds a joint on every face shared by two tetrahedra of the fracturing
 * part part_index (both in the region, when in_region is given); tet holds
 * its original (validated, positively oriented) connectivity. */
int joint_build_part_3d(fdem_model *m, int part_index, const int32_t *tet, int tet_count,
                        const uint8_t *in_region, fdem_error *err)
{
    size_t nf = 4 * (size_t)tet_count;
    face_ref *faces = joint_build_scratch(sizeof *faces * nf, part_index, err);
    if (!faces) return -1;
    for (int t = 0; t < tet_count; t++)
        for (int f = 0; f < 4; f++) {
            face_ref *r = &faces[4 * (size_t)t + f];
            for (int i = 0; i < 3; i++) r->key[i] = tet[4 * t + tet_face_nodes[f][i]];
            node_ids_sort(r->key, 3);
            r->tet = t;
            r->face = f;
        }
    qsort(faces, nf, sizeof *faces, face_compare);
    int shared = 0;
    for (size_t k = 0; k + 1 < nf; k++) {
        if (!same_face(&faces[k], &faces[k + 1])) continue;
        if (k + 2 < nf && same_face(&faces[k], &faces[k + 2])) {
            int32_t n0 = faces[k].key[0], n1 = faces[k].key[1], n2 = faces[k].key[2];
            free(faces);
            model_error(err, FDEM_ITEM_PART, part_index,
                        "face %d-%d-%d of part %d is shared by more than two tetrahedra", n0, n1,
                        n2, part_index);
            return -1;
        }
        shared++;
        k++;
    }
    int J0 = m->joint_count, J = J0 + shared;
    if (joint_reserve(m, J, part_index, err)) {
        free(faces);
        return -1;
    }
    joint_pair_ref *pairs = joint_build_scratch(sizeof *pairs * (size_t)shared, part_index, err);
    if (!pairs) {
        free(faces);
        return -1;
    }
    int n_pairs = 0;
    for (size_t k = 0; k + 1 < nf; k++) {
        if (!same_face(&faces[k], &faces[k + 1])) continue;
        /* outside the region the two tetrahedra share nodes (joint_region.c) */
        if (!in_region || (in_region[faces[k].tet] && in_region[faces[k + 1].tet]))
            pairs[n_pairs++] = (joint_pair_ref){faces[k].tet, faces[k + 1].tet, k};
        k++;
    }
    qsort(pairs, (size_t)n_pairs, sizeof *pairs, pair_compare);
    int begin = m->parts[part_index].elem_begin;
    for (int i = 0; i < n_pairs; i++) {
        const face_ref *a = &faces[pairs[i].face];
        joint_set_3d(m, J0 + i, tet, a, a + 1, begin + a->tet, begin + a[1].tet);
    }
    m->joint_count = J0 + n_pairs;
    free(pairs);
    free(faces);
    return 0;
}

/* Initial area of joint j's face A. */
static double joint_face_area0(const fdem_model *m, int j)
{
    const int32_t *n = m->joint_node + 6 * (size_t)j;
    double e1[3], e2[3], c[3];
    vec3_sub(m->pos0 + 3 * (size_t)n[1], m->pos0 + 3 * (size_t)n[0], e1);
    vec3_sub(m->pos0 + 3 * (size_t)n[2], m->pos0 + 3 * (size_t)n[0], e2);
    vec3_cross(e1, e2, c);
    return 0.5 * sqrt(vec3_dot(c, c));
}

/* Joint springs in series with the element: a face node takes about
 * k A / 3 from each of its tetrahedron's three faces, k A in all, and both
 * faces move (2 k A), as a 2D node takes k L / 2 from each of two joints. */
double joint_stable_dt_3d(const fdem_model *m)
{
    double dt = INFINITY;
    for (int j = 0; j < m->joint_count; j++) {
        const int32_t *n = m->joint_node + 6 * (size_t)j;
        double mass = INFINITY;
        for (int i = 0; i < 6; i++) mass = fmin(mass, m->mass[n[i]]);
        dt = fmin(dt, joint_spring_dt(mass, 2 * m->joint_k[j] * joint_face_area0(m, j)));
    }
    return dt;
}

/* Adds fa to face A's nodes and -fa to face B's. */
JOINT_TET_INLINE void joint_tet_scatter(double *f, const int32_t n[6], const double fa[9])
{
    JOINT_TET_UNROLL
    for (int i = 0; i < 3; i++) {
        const double *load = fa + 3 * i;
        vec3_scatter(f, n[i], load[0], load[1], load[2], 1, 0);
        vec3_scatter(f, n[3 + i], load[0], load[1], load[2], 0, 0);
    }
}

/* How many joints ahead the loop asks for face A's first node (position
 * and force). In (B, A) order the B faces come in node order, which the
 * hardware prefetcher follows, and A's tetrahedron sits a cell, a row or a
 * layer behind; one line of each of A's arrays is what it misses. At 1e5
 * tetrahedra (beyond the caches) this took the loop from ~30 to ~25 ns a
 * joint, as asking for all six nodes' lines did with a dozen prefetches
 * more (~50 instructions a joint); 8, 12, 16 or 32 ahead measured the same
 * within the noise. It changes no result. Forced inline: gcc finds a
 * function of prefetches alone free of effects and drops its calls. */
#define JOINT_PREFETCH_AHEAD 8

JOINT_TET_INLINE void joint_prefetch_face_a(const fdem_model *m, int j)
{
#if defined(__GNUC__)
    int32_t a0 = m->joint_node[6 * (size_t)j];
    __builtin_prefetch(m->pos + 3 * (size_t)a0);
    __builtin_prefetch(m->force + 3 * (size_t)a0, 1);
#else
    (void)m;
    (void)j;
#endif
}

/* Joint j (not broken) through joint_tet_forces, from the gaps the loop
 * already has: its damage, fracture account and break booked, its face A
 * forces in fa. Returns 0 when it broke (nothing to add). */
static int joint_through_kernel(fdem_model *m, int j, const double d[3][3], const double N[3],
                                double N_len, joint_totals *t, double fa[9])
{
    const int32_t *n = m->joint_node + 6 * (size_t)j;
    const joint_law law = joint_law_of(&m->joint_strengths[m->joint_strength_of[j]], m->joint_k[j]);
    double damage = m->joint_damage[j];
    /* this joint's own, for its fracture account and its event */
    joint_energy e = {0};
    int holds = joint_tet_forces_of_gaps(&law, m->pos, d, N, N_len, n, &damage,
                                         m->joint_slip + 3 * (size_t)j, fa, &e);
    m->joint_damage[j] = damage;
    t->stored += e.stored;
    t->dissipated += e.dissipated;
    t->handed += e.handed;
    t->friction += e.friction;
    if (e.dissipated != 0) m->joint_fracture[j] += e.dissipated;
    if (!holds) {
        m->joint_broke[j] = (uint8_t)e.broke;
        t->broke++;
        return 0;
    }
    return 1;
}

/* Joint j alone: the inline path when it is undamaged and surely elastic,
 * else the kernel; its face A forces in fa, 0 when it adds nothing
 * (broken). The joint sweep's joint_one_fn. */
int joint_forces_one_3d(fdem_model *m, int j, joint_totals *t, double fa[JOINT_FACE_VALUES])
{
    double damage = m->joint_damage[j];
    if (damage >= 1.0) return 0;
    const int32_t *n = m->joint_node + 6 * (size_t)j;
    const joint_strength *s = &m->joint_strengths[m->joint_strength_of[j]];
    double d[3][3], N[3], k = m->joint_k[j];
    double N_len = joint_tet_gaps(m->pos, n, d, N);
    if (m->joint_offset) joint_tet_add_offsets(m->pos, n, N, N_len, m->joint_offset + 9 * (size_t)j, d);
    if (damage == 0 && N_len > JOINT_TET_TINY_NORMAL &&
        (joint_tet_surely_elastic_of(k, s->tensile_strength, s->cohesion, s->tan_phi, d) ||
         joint_tet_elastic_points_of(k, s->tensile_strength, s->cohesion, s->tan_phi, d, N, N_len))) {
        t->stored += joint_tet_elastic_forces(k, 0.5 * N_len, d, fa);
        return 1;
    }
    return joint_through_kernel(m, j, d, N, N_len, t, fa);
}

static void joint_alone(fdem_model *m, int j, joint_totals *t)
{
    double fa[9];
    if (joint_forces_one_3d(m, j, t, fa))
        joint_tet_scatter(m->force, m->joint_node + 6 * (size_t)j, fa);
}

/* Joints j and j + 1, both undamaged, side by side: each lane surely
 * elastic gets its inline forces, any other goes to the kernel with the
 * gaps of its lane (the bits joint_tet_gaps gives), j's first. */
JOINT_TET_INLINE void joint_pair_undamaged(fdem_model *m, int j, joint_totals *t)
{
    const int32_t *n0 = m->joint_node + 6 * (size_t)j, *n1 = n0 + 6;
    const joint_strength *s0 = &m->joint_strengths[m->joint_strength_of[j]];
    const joint_strength *s1 = &m->joint_strengths[m->joint_strength_of[j + 1]];
    joint_pair d[3][3], N[3];
    joint_pair N_len = joint_tet_gaps_at_pair(m->pos, n0, n1, d, N);
    joint_pair k = {m->joint_k[j], m->joint_k[j + 1]};
    joint_pair ft = {s0->tensile_strength, s1->tensile_strength};
    joint_pair c = {s0->cohesion, s1->cohesion}, tan_phi = {s0->tan_phi, s1->tan_phi};
    joint_pair_mask sized = N_len > JOINT_TET_TINY_NORMAL;
    joint_pair_mask sure = joint_tet_surely_elastic_of_pair(k, ft, c, tan_phi, d) & sized;
    if (!(sure[0] && sure[1])) /* pressed joints: the point test itself */
        sure |= joint_tet_elastic_points_of_pair(k, ft, c, tan_phi, d, N, N_len) & sized;
    joint_pair fa[9];
    joint_pair e = joint_tet_elastic_forces_of_pair(k, 0.5 * N_len, d, fa);
    JOINT_TET_UNROLL
    for (int lane = 0; lane < 2; lane++) {
        if (sure[lane]) {
            double f[9];
            JOINT_TET_UNROLL
            for (int q = 0; q < 9; q++) f[q] = fa[q][lane];
            joint_tet_scatter(m->force, lane ? n1 : n0, f);
            t->stored += e[lane];
            continue;
        }
        double dl[3][3], Nl[3], f[9];
        for (int q = 0; q < 9; q++) dl[q / 3][q % 3] = d[q / 3][q % 3][lane];
        for (int i = 0; i < 3; i++) Nl[i] = N[i][lane];
        if (joint_through_kernel(m, j + lane, dl, Nl, N_len[lane], t, f))
            joint_tet_scatter(m->force, lane ? n1 : n0, f);
    }
}

#if FDEM_QUADS
/* The point test for four joints, out of line: inlined, its code cost the
 * intact block's joint loop 4 % at 1e5 tetrahedra, where it never runs. */
__attribute__((target("avx2"), noinline)) static fdem_quad_mask
joint_quad_pressed(fdem_quad k, fdem_quad ft, fdem_quad c, fdem_quad tan_phi,
                   const fdem_quad d[3][3], const fdem_quad N[3], fdem_quad N_len)
{
    return joint_tet_elastic_points_of_quad(k, ft, c, tan_phi, d, N, N_len);
}

/* Joints j .. j + 3, all undamaged, when all four are surely elastic:
 * their forces added and their stored energy booked, joint by joint in
 * order; returns 0, having touched nothing, otherwise. A call of its own,
 * so that the baseline loop, which never takes it, holds no AVX code. */
__attribute__((target("avx2"))) static int joint_quad_elastic(fdem_model *m, int j,
                                                              joint_totals *t)
{
    const int32_t *n = m->joint_node + 6 * (size_t)j;
    fdem_quad k, ft, c, tan_phi;
    JOINT_TET_UNROLL
    for (int l = 0; l < 4; l++) {
        const joint_strength *s = &m->joint_strengths[m->joint_strength_of[j + l]];
        k[l] = m->joint_k[j + l];
        ft[l] = s->tensile_strength;
        c[l] = s->cohesion;
        tan_phi[l] = s->tan_phi;
    }
    fdem_quad d[3][3], N[3];
    fdem_quad N_len = joint_tet_gaps_at_quad(m->pos, n, n, d, N);
    fdem_quad_mask sized = N_len > JOINT_TET_TINY_NORMAL;
    fdem_quad_mask sure = joint_tet_surely_elastic_of_quad(k, ft, c, tan_phi, d) & sized;
    if (!(sure[0] && sure[1] && sure[2] && sure[3])) { /* pressed joints: the point test */
        sure |= joint_quad_pressed(k, ft, c, tan_phi, d, N, N_len) & sized;
        if (!(sure[0] && sure[1] && sure[2] && sure[3])) return 0;
    }
    fdem_quad fa[9];
    fdem_quad e = joint_tet_elastic_forces_of_quad(k, 0.5 * N_len, d, fa);
    JOINT_TET_UNROLL
    for (int l = 0; l < 4; l++) {
        double f[9];
        JOINT_TET_UNROLL
        for (int q = 0; q < 9; q++) f[q] = fa[q][l];
        joint_tet_scatter(m->force, n + 6 * l, f);
        t->stored += e[l];
    }
    return 1;
}
#endif

/* The 3D counterpart of joint.c's joint_forces_range_2d, with the same sums.
 * Undamaged joints surely inside their strengths take joint_tet.h's inline
 * path, four (quads, in the AVX2 loop) or two at a time where they are
 * undamaged: the same bits as joint_tet_forces, without the call, the law
 * per point or the bookkeeping. Any other goes through joint_tet_forces'
 * kernel with the gaps already in hand. */
JOINT_TET_INLINE void joint_forces_loop(fdem_model *m, int begin, int end,
                                        double sums[SCATTER_SUMS], const int quads)
{
    const double *damage = m->joint_damage;
    joint_totals t = joint_totals_load(sums);
    int j = begin;
    for (; j + 1 < end; j += 2) {
        if (j + JOINT_PREFETCH_AHEAD + 1 < end) {
            joint_prefetch_face_a(m, j + JOINT_PREFETCH_AHEAD);
            joint_prefetch_face_a(m, j + JOINT_PREFETCH_AHEAD + 1);
        }
        if (damage[j] == 0 && damage[j + 1] == 0) {
#if FDEM_QUADS
            if (quads && j + 3 < end && damage[j + 2] == 0 && damage[j + 3] == 0 &&
                joint_quad_elastic(m, j, &t)) {
                if (j + JOINT_PREFETCH_AHEAD + 3 < end) {
                    joint_prefetch_face_a(m, j + JOINT_PREFETCH_AHEAD + 2);
                    joint_prefetch_face_a(m, j + JOINT_PREFETCH_AHEAD + 3);
                }
                j += 2;
                continue;
            }
#endif
            joint_pair_undamaged(m, j, &t);
        } else {
            joint_alone(m, j, &t);
            joint_alone(m, j + 1, &t);
        }
    }
    if (j < end) joint_alone(m, j, &t);
    joint_totals_store(&t, sums);
}

/* The loop is compiled twice, for the baseline x86-64 (pairs) and for AVX2
 * (quads where four undamaged joints in a row are all surely elastic, else
 * pairs), chosen by the CPU at run time as element_tet_model.c's: four
 * lanes halve the arithmetic per joint again, and the three-operand AVX
 * encoding drops the register copies two-operand SSE needs. AVX2 without
 * FMA, and no contraction under -std=c11: every operation rounds as in the
 * baseline, so both give the same bits. Measured on the loop alone
 * (callgrind; CPU ns per joint, interleaved runs on a busy 2-core machine):
 * pairs in AVX 252 -> 213 instructions, 21.8 -> 20.7 ns at 1e4 joints;
 * quads 20.3 -> 17.5 ns at 1e4, 25.4 -> 23.8 at 1e5. */
#if FDEM_QUADS
__attribute__((target("avx2"))) static void joint_forces_avx2(fdem_model *m, int begin, int end,
                                                               double sums[SCATTER_SUMS])
{
    joint_forces_loop(m, begin, end, sums, 1);
}
#endif

/* Joints that carry an in-situ gap (joint_prestress.c) one at a time: the
 * offsets turn with each face's frame, which the side-by-side lanes do not
 * compute. Only models with a stressed fracturing part come here. */
static void joint_forces_offset_loop(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    joint_totals t = joint_totals_load(sums);
    for (int j = begin; j < end; j++) joint_alone(m, j, &t);
    joint_totals_store(&t, sums);
}

void joint_forces_range_3d(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    if (m->joint_offset) {
        joint_forces_offset_loop(m, begin, end, sums);
        return;
    }
#if FDEM_QUADS
    if (__builtin_cpu_supports("avx2")) {
        joint_forces_avx2(m, begin, end, sums);
        return;
    }
#endif
    joint_forces_loop(m, begin, end, sums, 0);
}
