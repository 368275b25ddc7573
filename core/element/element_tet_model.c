/*
 * element_tet_model.c - the 3D element kernel on the model: tetrahedra from
 * the model's hot records, the counterpart of element_tri.c. The per-element
 * algebra is element_tet_kernel.h's (shared with element_tet.c, which also
 * has the set-up: geometry, stable step); this file owns the per-element
 * loop the scatter plan runs (groups of two or four elements in SIMD lanes:
 * element_tet_lanes.h), with the damping stress kept per element for the
 * damping account (element.c).
 *
 * Forces come from the face vectors c_k (twice the area vectors through
 * node 0), f_a = -sigma c_{a-1} / 6, node 0 taking minus the sum of the
 * other three so each element's forces sum to exactly zero.
 *
 * The damping stress 2 eta D takes D = sym([v][x_mid]^-1) on the mid-step
 * configuration x_mid = x - h_last v / 2 (v the half-step velocity, the
 * chord of the last step, h_last = dt_prev): for a rigid motion that chord
 * velocity is W x_mid with W skew (the Cayley transform of the step's
 * rotation), so a spin gives D = 0 to round-off, where on the current x it
 * gave D ~ h omega^2 / 2 and a free spin was damped, booked in proportion
 * to dt^2 (issue 29). Its forces are the loads of sigma_v / 6 on the
 * mid-step face vectors, added to the elastic ones before the one scatter
 * (tet_kernel_face_loads_add), so the power booked now, -(sigma_v : S) / 6
 * on the same faces, is exactly that of the forces applied; forces on the
 * current faces would not be (a relative h omega off for a spinning body).
 * The same forces' power with the velocities after the step is booked at
 * the next step from the stored stress on that step's mid-step faces, one
 * step's motion later than the faces it acted on (as before this change,
 * when it was the current faces): the account's one approximation, an
 * error of order h |L|^2 |sigma_v| V (L the velocity gradient, spin
 * included), small beside the power 2 eta D : D V unless an element spins
 * fast while hardly deforming (its sigma_v, and so the error, then vanish
 * with D: a free spin books nothing, test_damping.c).
 */
#include <math.h>
#include <string.h>

#include "kernel/element_tet_kernel.h"
#include "model/model.h"
#include "math/vec3.h"
#include "element.h"
#if FDEM_QUADS
#include <immintrin.h>
#endif

int tet_element_prepare(fdem_model *m, int e, fdem_error *err)
{
    tet_hot *t = &m->tet[e];
    /* the storing loop moves an element's four nodes as one block of
     * twelve numbers (tet_gather_own_quad): part_append numbers them so */
    if (model_part_stores_forces(m, &m->parts[m->elem_part[e]]))
        for (int c = 1; c < 4; c++)
            if (t->node[c] != t->node[0] + c) {
                model_error(err, FDEM_ITEM_ELEMENT, e,
                            "element %d of a fracturing part does not have consecutive nodes", e);
                return -1;
            }
    tet_geometry g;
    if (tet_prepare(m->pos0, t->node, &g)) {
        model_error(err, FDEM_ITEM_ELEMENT, e, "element %d has no positive volume", e);
        return -1;
    }
    memcpy(t->xinv, g.xinv, sizeof t->xinv);
    t->volume0 = g.volume0;
    m->elem_h[e] = g.height;
    const material *mat = &m->materials[t->material];
    t->eta = tet_viscosity(g.height, mat->lambda, mat->mu, mat->def.density, mat->def.damping);
    return 0;
}

double tet_element_stable_dt(const fdem_model *m, int e)
{
    const tet_hot *t = &m->tet[e];
    const material *mat = &m->materials[t->material];
    return tet_stable_dt_eigen(m->pos0, t->node, mat->lambda, mat->mu, mat->def.density, t->eta);
}

/* How far ahead the loop asks for element records (two cache lines each,
 * 112 bytes): see the measurement at tet_element_forces_range. */
#define TET_PREFETCH 8
#if defined(__GNUC__)
#define TET_PREFETCH_READ(p) __builtin_prefetch(p)
#else
#define TET_PREFETCH_READ(p) ((void)(p))
#endif

/* The material constants the kernel wants, reloaded only when the material
 * changes (elements of a part are contiguous). */
typedef struct tet_constants {
    int32_t material;
    double smu, slambda; /* mu / 6, lambda / 6: the stress comes out as sigma / 6 */
    double hmu, hlambda; /* mu / 2, lambda / 2: the energy density */
} tet_constants;

static inline void tet_constants_load(tet_constants *k, const material *mats, int32_t which)
{
    if (which == k->material) return;
    k->material = which;
    k->smu = mats[which].mu * (1.0 / 6);
    k->slambda = mats[which].lambda * (1.0 / 6);
    k->hmu = 0.5 * mats[which].mu;
    k->hlambda = 0.5 * mats[which].lambda;
}

/* The damping stress 2 eta D of an element on its mid-step configuration
 * (edges e - hh [v], hh = h_last / 2; D = S / det, S = tet_kernel_rate_of)
 * into sv, full (the stored per-element value), with S, and the mid-step
 * face vectors in cm; a flat element gets none (returns 0, sv zero). */
static inline int tet_viscous(const double *vel, const int32_t node[4], const double e[3][3],
                              double hh, double eta, double cm[3][3], double S[6], double sv[6])
{
    double dv[3][3];
    tet_kernel_edges(vel + 3 * (size_t)node[0], vel + 3 * (size_t)node[1],
                     vel + 3 * (size_t)node[2], vel + 3 * (size_t)node[3], dv);
    double det = tet_kernel_mid_faces(e, dv, hh, cm);
    if (!(fabs(det) > 0)) {
        memset(sv, 0, 6 * sizeof(double));
        return 0;
    }
    tet_kernel_rate_of(dv, cm, S);
    double scale = 2 * eta / det;
    TET_UNROLL
    for (int k = 0; k < 6; k++) sv[k] = scale * S[k];
    return 1;
}

/* What a range of elements hands back (sums of element.c). */
typedef struct tet_sums {
    double energy, power_now, power_prev;
} tet_sums;

/* The damping of element t (eta > 0) with edges e and face loads g (of the
 * elastic sixth stress, tet_kernel_face_loads): stores the new viscous
 * stress, books both powers (-V sigma_v : D = -(sigma_v : S) / 6, S =
 * det D, the 1/6 applied to the totals) and adds the loads of sigma_v / 6
 * on the mid-step faces to g, so the power booked is that of the forces
 * applied. */
static inline void tet_damp(const fdem_model *m, const tet_hot *t, const double e[3][3],
                            double g[4][3], tet_sums *sum)
{
    double cm[3][3], S[6], sv[6], *prev = m->elem_viscous + 6 * (size_t)(t - m->tet);
    if (tet_viscous(m->vel, t->node, e, 0.5 * m->dt_prev, t->eta, cm, S, sv)) {
        sum->power_now -= tet_kernel_contract(sv, S);
        sum->power_prev -= tet_kernel_contract(prev, S);
        double sixth[6];
        TET_UNROLL
        for (int q = 0; q < 6; q++) sixth[q] = sv[q] * (1.0 / 6);
        tet_kernel_face_loads_add(sixth, cm, g);
    }
    TET_UNROLL
    for (int q = 0; q < 6; q++) prev[q] = sv[q];
}

static inline void tet_scatter(double *f, const int32_t node[4], const double g[4][3],
                               const int store)
{
    TET_UNROLL
    for (int a = 0; a < 4; a++)
        vec3_scatter(f, node[a], g[a][0], g[a][1], g[a][2], a == 0, store);
}

/* Element t's in-situ pre-stress (initial_stress.c). */
static inline const double *tet_stress0(const fdem_model *m, const tet_hot *t)
{
    return m->elem_stress0 + 6 * (size_t)(t - m->tet);
}

/* One element alone: the last of an odd range, or a pair of two materials.
 * `stressed` (a constant at each call) adds the element's pre-stress;
 * `store`: see vec3_scatter. */
TET_KERNEL void tet_forces_one(fdem_model *m, const tet_hot *t, tet_constants *k, tet_sums *sum,
                               const int stressed, const int store)
{
    const double *pos = m->pos;
    const int32_t *n = t->node;
    double e[3][3], c[3][3], F[9], s[6], J, invJ;
    tet_kernel_edges(pos + 3 * (size_t)n[0], pos + 3 * (size_t)n[1], pos + 3 * (size_t)n[2],
                     pos + 3 * (size_t)n[3], e);
    tet_kernel_gradient(e, t->xinv, F);
    tet_constants_load(k, m->materials, t->material);
    double w = tet_kernel_stress(F, k->smu, k->slambda, k->hmu, k->hlambda, s, &J, &invJ);
    if (stressed) w += tet_kernel_prestress(F, invJ * (1.0 / 6), tet_stress0(m, t), s);
    sum->energy += w * t->volume0;
    tet_kernel_faces(e, c);
    double g[4][3];
    tet_kernel_face_loads(s, c, g);
    if (t->eta > 0) tet_damp(m, t, e, g, sum);
    tet_scatter(m->force, n, g, store);
}

#define TET_V tet_pair
#define TET_N 2
#define TET_VFN(name) name##_pair
#define TET_GATHER(p, i) ((tet_pair){(p)[0][i], (p)[1][i]})
#define TET_GATHER_OWN(xyz, t, x) tet_gather_nodes_pair(xyz, t, x)
#define TET_LOAD_SIX(rows, v)                                                                    \
    do {                                                                                         \
        for (int q_ = 0; q_ < 6; q_++) v[q_] = (tet_pair){(rows)[q_], (rows)[6 + q_]};          \
    } while (0)
#define TET_STORE_SIX(rows, v)                                                                   \
    do {                                                                                         \
        for (int q_ = 0; q_ < 6; q_++) {                                                         \
            (rows)[q_] = v[q_][0];                                                               \
            (rows)[6 + q_] = v[q_][1];                                                           \
        }                                                                                        \
    } while (0)
#define TET_STORE_OWN(f, t, g)                                                                   \
    do {                                                                                         \
        for (int l_ = 0; l_ < 2; l_++) tet_scatter_lane_pair(f, (t)[l_].node, g, l_, 1);        \
    } while (0)
#include "element_tet_lanes.h"

#if FDEM_QUADS
#pragma GCC push_options
#pragma GCC target("avx2")
#define TET_V fdem_quad
#define TET_N 4
#define TET_VFN(name) name##_quad
#define TET_GATHER(p, i) ((fdem_quad){(p)[0][i], (p)[1][i], (p)[2][i], (p)[3][i]})

/* Four rows of four numbers, one per lane, turned into four vectors over
 * the lanes (vector k holds number k of each row), and back: the same
 * transpose. */
TET_KERNEL void tet_transpose_quad(fdem_quad r[4])
{
    __m256d t0 = _mm256_unpacklo_pd((__m256d)r[0], (__m256d)r[1]);
    __m256d t1 = _mm256_unpackhi_pd((__m256d)r[0], (__m256d)r[1]);
    __m256d t2 = _mm256_unpacklo_pd((__m256d)r[2], (__m256d)r[3]);
    __m256d t3 = _mm256_unpackhi_pd((__m256d)r[2], (__m256d)r[3]);
    r[0] = (fdem_quad)_mm256_permute2f128_pd(t0, t2, 0x20);
    r[1] = (fdem_quad)_mm256_permute2f128_pd(t1, t3, 0x20);
    r[2] = (fdem_quad)_mm256_permute2f128_pd(t0, t2, 0x31);
    r[3] = (fdem_quad)_mm256_permute2f128_pd(t1, t3, 0x31);
}

/* tet_gather_nodes for four elements whose four nodes are consecutive:
 * each element's twelve numbers are three rows of four, so three loads
 * and a transpose per block of four numbers instead of 48 single ones. */
TET_KERNEL void tet_gather_own_quad(const double *xyz, const tet_hot *t, fdem_quad x[4][3])
{
    fdem_quad col[12];
    TET_UNROLL
    for (int k = 0; k < 3; k++) {
        fdem_quad *r = col + 4 * k;
        TET_UNROLL
        for (int l = 0; l < 4; l++)
            memcpy(&r[l], xyz + 3 * (size_t)t[l].node[0] + 4 * k, sizeof r[l]);
        tet_transpose_quad(r);
    }
    TET_UNROLL
    for (int q = 0; q < 12; q++) x[q / 3][q % 3] = col[q];
}

/* The storing scatter (vec3_scatter with store) of four such elements:
 * 0 + g_0 and 0 - g_a as vectors, lane by lane what the scalar store
 * gives, transposed back to rows and stored whole. */
TET_KERNEL void tet_store_own_quad(double *f, const tet_hot *t, const fdem_quad g[4][3])
{
    const fdem_quad zero = {0.0, 0.0, 0.0, 0.0};
    fdem_quad row[12];
    TET_UNROLL
    for (int q = 0; q < 12; q++) row[q] = q < 3 ? zero + g[0][q] : zero - g[q / 3][q % 3];
    TET_UNROLL
    for (int k = 0; k < 3; k++) {
        fdem_quad *r = row + 4 * k;
        tet_transpose_quad(r);
        TET_UNROLL
        for (int l = 0; l < 4; l++)
            memcpy(f + 3 * (size_t)t[l].node[0] + 4 * k, &r[l], sizeof r[l]);
    }
}

/* Six numbers a lane in four adjacent rows of six (24 numbers) as six
 * vectors over the lanes, and back: a transpose of the first four of each
 * row, and the last two of the rows paired across the lanes. */
TET_KERNEL void tet_load_six_quad(const double *rows, fdem_quad v[6])
{
    TET_UNROLL
    for (int l = 0; l < 4; l++) memcpy(&v[l], rows + 6 * l, sizeof v[l]);
    tet_transpose_quad(v);
    __m256d p = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(rows + 4)),
                                     _mm_loadu_pd(rows + 16), 1); /* rows 0, 2 */
    __m256d q = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(rows + 10)),
                                     _mm_loadu_pd(rows + 22), 1); /* rows 1, 3 */
    v[4] = (fdem_quad)_mm256_unpacklo_pd(p, q);
    v[5] = (fdem_quad)_mm256_unpackhi_pd(p, q);
}

TET_KERNEL void tet_store_six_quad(double *rows, const fdem_quad v[6])
{
    fdem_quad r[4] = {v[0], v[1], v[2], v[3]};
    tet_transpose_quad(r);
    TET_UNROLL
    for (int l = 0; l < 4; l++) memcpy(rows + 6 * l, &r[l], sizeof r[l]);
    __m256d p = _mm256_unpacklo_pd((__m256d)v[4], (__m256d)v[5]); /* rows 0, 2 */
    __m256d q = _mm256_unpackhi_pd((__m256d)v[4], (__m256d)v[5]); /* rows 1, 3 */
    _mm_storeu_pd(rows + 4, _mm256_castpd256_pd128(p));
    _mm_storeu_pd(rows + 16, _mm256_extractf128_pd(p, 1));
    _mm_storeu_pd(rows + 10, _mm256_castpd256_pd128(q));
    _mm_storeu_pd(rows + 22, _mm256_extractf128_pd(q, 1));
}

#define TET_GATHER_OWN(xyz, t, x) tet_gather_own_quad(xyz, t, x)
#define TET_STORE_OWN(f, t, g) tet_store_own_quad(f, t, g)
#define TET_LOAD_SIX(rows, v) tet_load_six_quad(rows, v)
#define TET_STORE_SIX(rows, v) tet_store_six_quad(rows, v)
#include "element_tet_lanes.h"

/* Four elements of one material: a call of its own, so that the baseline
 * loop, which never takes it, holds no AVX code. */
static void tet_forces_quad(fdem_model *m, const tet_hot *t, tet_constants *k, tet_sums *sum,
                            int stressed, int store)
{
    if (stressed)
        tet_forces_group_quad(m, t, k, sum, 1, store);
    else if (store)
        tet_forces_group_quad(m, t, k, sum, 0, 1);
    else
        tet_forces_group_quad(m, t, k, sum, 0, 0);
}
#pragma GCC pop_options
#endif

/* The hot loop: one pass over the tetrahedron records, gathering four
 * nodes and scattering four forces each (~200 floating-point operations
 * and one division per undamped element: bound by the FP ports, not by
 * memory). What makes it fast, as in element_tri.c:
 *  - four (AVX2) or two elements at a time in the lanes of one SIMD
 *    register (groups of one material; the bits are those of one at a
 *    time; element_tet_lanes.h);
 *  - the stress comes out as sigma / 6 (constants scaled once per
 *    material), so f_a = -sigma c_a / 6 costs no division or extra scale;
 *  - ln J by the series of log_near1.h instead of libm;
 *  - everything inline and unrolled, no per-element call or table lookup;
 *  - records prefetched ahead;
 *  - damping: one division, and its power from s : S directly (the mid-step
 *    faces cost one more cross product per face). */
TET_KERNEL void tet_forces_run(fdem_model *m, int begin, int end_index, const int stressed,
                               const int store, const int quads, tet_constants *constants,
                               tet_sums *sums)
{
    tet_sums sum = *sums;
    tet_constants k = *constants;
    const tet_hot *t = m->tet + begin, *end = m->tet + end_index;
    while (end - t >= 2) {
        const tet_hot *ahead = end - t > TET_PREFETCH + 3 ? t + TET_PREFETCH : t;
        TET_PREFETCH_READ(ahead);
        TET_PREFETCH_READ((const char *)ahead + 64);
        TET_PREFETCH_READ((const char *)ahead + 128);
        TET_PREFETCH_READ((const char *)ahead + 192);
#if FDEM_QUADS
        if (quads && end - t >= 4 && t[0].material == t[1].material &&
            t[0].material == t[2].material && t[0].material == t[3].material) {
            TET_PREFETCH_READ((const char *)ahead + 256);
            TET_PREFETCH_READ((const char *)ahead + 320);
            TET_PREFETCH_READ((const char *)ahead + 384);
            TET_PREFETCH_READ((const char *)ahead + 448);
            tet_forces_quad(m, t, &k, &sum, stressed, store);
            t += 4;
            continue;
        }
#endif
        if (t[0].material == t[1].material) {
            tet_forces_group_pair(m, t, &k, &sum, stressed, store);
        } else {
            tet_forces_one(m, t, &k, &sum, stressed, store);
            tet_forces_one(m, t + 1, &k, &sum, stressed, store);
        }
        t += 2;
    }
    if (t < end) tet_forces_one(m, t, &k, &sum, stressed, store);
    *sums = sum;
    *constants = k;
}

/* The loop is compiled twice, for the baseline x86-64 (pairs in SSE2) and
 * for AVX2 (quads), chosen by the CPU at run time: four lanes halve the
 * vector arithmetic per element, and the three-operand AVX encoding drops
 * the register copies two-operand SSE needs. AVX2 without FMA: every
 * operation rounds as in the baseline (no contraction under -std=c11
 * either), so both give the same bits. Measured on the 3D block of 1e5
 * elements (callgrind instructions per element-step; CPU ns, busy 2-core
 * machine): undamped 291 -> 205 (23.4 -> 18.7 ns), damped (xi = 0.1)
 * 300 instructions, 34.4 -> 27.4 ns. */
/* The loop's variants, each with its constants: a part with an in-situ
 * stress is rare, so its loop takes `store` as a variable (one variant
 * fewer). */
TET_KERNEL void tet_forces_variant(fdem_model *m, int begin, int end, int stressed, int store,
                                   const int quads, tet_constants *k, tet_sums *sum)
{
    if (stressed)
        tet_forces_run(m, begin, end, 1, store, quads, k, sum);
    else if (store)
        tet_forces_run(m, begin, end, 0, 1, quads, k, sum);
    else
        tet_forces_run(m, begin, end, 0, 0, quads, k, sum);
}

#if FDEM_QUADS
__attribute__((target("avx2"))) static void tet_forces_avx2(fdem_model *m, int begin, int end,
                                                             int stressed, int store,
                                                             tet_constants *k, tet_sums *sum)
{
    tet_forces_variant(m, begin, end, stressed, store, 1, k, sum);
}
#endif

static void tet_forces_dispatch(fdem_model *m, int begin, int end, int stressed, int store,
                                tet_constants *k, tet_sums *sum)
{
#if FDEM_QUADS
    if (__builtin_cpu_supports("avx2")) {
        tet_forces_avx2(m, begin, end, stressed, store, k, sum);
        return;
    }
#endif
    tet_forces_variant(m, begin, end, stressed, store, 0, k, sum);
}

/* Elements [begin, end) run by run of one part: a part whose nodes are its
 * elements' own (model_part_stores_forces) stores their forces, the others
 * add to what the zeroed array holds (elements of a part are contiguous).
 * One running sum over the whole range, whatever its runs, so the energy
 * is added in the order it always was. */
static void tet_forces_by_part(fdem_model *m, int begin, int end, int stressed,
                               double sums[SCATTER_SUMS])
{
    tet_sums sum = {0, 0, 0};
    tet_constants k = {.material = -1};
    for (int e = begin; e < end;) {
        const part *p = &m->parts[m->elem_part[e]];
        int stop = p->elem_begin + p->elem_count < end ? p->elem_begin + p->elem_count : end;
        tet_forces_dispatch(m, e, stop, stressed, model_part_stores_forces(m, p), &k, &sum);
        e = stop;
    }
    sums[0] += sum.energy;
    sums[1] += sum.power_now * (1.0 / 6);
    sums[2] += sum.power_prev * (1.0 / 6);
}

void tet_element_forces_range(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    tet_forces_by_part(m, begin, end, 0, sums);
}

/* The same loop for the elements of a part with an in-situ stress. */
void tet_element_forces_range_stressed(fdem_model *m, int begin, int end,
                                       double sums[SCATTER_SUMS])
{
    tet_forces_by_part(m, begin, end, 1, sums);
}

void tet_element_stress(const fdem_model *m, int e, double out[6])
{
    const tet_hot *t = &m->tet[e];
    const double *pos = m->pos;
    const material *mat = &m->materials[t->material];
    double ed[3][3], c[3][3], F[9], J, invJ;
    tet_kernel_edges(pos + 3 * (size_t)t->node[0], pos + 3 * (size_t)t->node[1],
                     pos + 3 * (size_t)t->node[2], pos + 3 * (size_t)t->node[3], ed);
    tet_kernel_gradient(ed, t->xinv, F);
    tet_kernel_stress(F, mat->mu, mat->lambda, 0.5 * mat->mu, 0.5 * mat->lambda, out, &J, &invJ);
    if (m->elem_stress0 && m->parts[m->elem_part[e]].stressed)
        tet_kernel_prestress(F, invJ, tet_stress0(m, t), out);
    /* the viscous stress of the forces: on the mid-step configuration */
    double S[6], sv[6];
    if (t->eta > 0 && tet_viscous(m->vel, t->node, ed, 0.5 * m->dt_prev, t->eta, c, S, sv))
        for (int q = 0; q < 6; q++) out[q] += sv[q];
}
