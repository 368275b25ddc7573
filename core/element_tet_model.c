/*
 * element_tet_model.c - the 3D element kernel on the model: tetrahedra from
 * the model's hot records, the counterpart of element_tri.c. The per-element
 * algebra is element_tet_kernel.h's (shared with element_tet.c, which also
 * has the set-up: geometry, stable step); this file owns the per-element loop the scatter plan runs, with the
 * damping stress kept per element for the damping account (element.c).
 *
 * Forces come from the face vectors c_k (twice the area vectors through
 * node 0), f_a = -sigma c_{a-1} / 6, node 0 taking minus the sum of the
 * other three so each element's forces sum to exactly zero.
 */
#include <math.h>
#include <string.h>

#include "element_tet_kernel.h"
#include "model.h"

int tet_element_prepare(fdem_model *m, int e, fdem_error *err)
{
    tet_hot *t = &m->tet[e];
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

/* The damping stress 2 eta D (D = S / det, S = tet_kernel_rate) into sv,
 * full (the stored per-element value); a flat element gets none (returns 0,
 * sv zero). */
static inline int tet_viscous(const double *vel, const int32_t node[4], const double c[3][3],
                              double det, double eta, double S[6], double sv[6])
{
    if (!(fabs(det) > 0)) {
        memset(sv, 0, 6 * sizeof(double));
        return 0;
    }
    tet_kernel_rate(vel + 3 * (size_t)node[0], vel + 3 * (size_t)node[1],
                    vel + 3 * (size_t)node[2], vel + 3 * (size_t)node[3], c, S);
    double scale = 2 * eta / det;
    TET_UNROLL
    for (int k = 0; k < 6; k++) sv[k] = scale * S[k];
    return 1;
}

/* The hot loop: one pass over the tetrahedron records, gathering four
 * nodes and scattering four forces each (~140 floating-point operations
 * and one division per undamped element). What makes it fast, as in
 * element_tri.c:
 *  - the stress comes out as sigma / 6 (constants scaled once per
 *    material), so f_a = -sigma c_a / 6 costs no division or extra scale;
 *  - ln J by the series of log_near1.h instead of libm;
 *  - everything inline, no per-element call or table lookup;
 *  - records prefetched ahead;
 *  - damping: one division, and its power from s : S directly, since
 *    -V sigma_v : D = -(sigma_v : S) / 6 with S = det D. */
void tet_element_forces_range(fdem_model *m, int begin, int end_index, double sums[SCATTER_SUMS])
{
    const double *pos = m->pos, *vel = m->vel;
    double *f = m->force, *visc = m->elem_viscous;
    double energy = 0, power_now = 0, power_prev = 0;
    tet_constants k = {.material = -1};
    const tet_hot *t = m->tet + begin, *end = m->tet + end_index;
    for (; t < end; t++) {
        const tet_hot *ahead = end - t > TET_PREFETCH ? t + TET_PREFETCH : t;
        TET_PREFETCH_READ(ahead);
        TET_PREFETCH_READ((const char *)ahead + 64);
        const int32_t *n = t->node;
        double *fn[4];
        TET_UNROLL
        for (int a = 0; a < 4; a++) fn[a] = f + 3 * (size_t)n[a];
        double e[3][3], c[3][3], F[9], s[6], J;
        tet_kernel_edges(pos + 3 * (size_t)n[0], pos + 3 * (size_t)n[1], pos + 3 * (size_t)n[2],
                         pos + 3 * (size_t)n[3], e);
        tet_kernel_gradient(e, t->xinv, F);
        tet_constants_load(&k, m->materials, t->material);
        energy += tet_kernel_stress(F, k.smu, k.slambda, k.hmu, k.hlambda, s, &J) * t->volume0;
        double det = tet_kernel_faces(e, c);
        if (t->eta > 0) {
            double S[6], sv[6], *prev = visc + 6 * (size_t)(t - m->tet);
            if (tet_viscous(vel, n, c, det, t->eta, S, sv)) {
                power_now -= tet_kernel_contract(sv, S);
                power_prev -= tet_kernel_contract(prev, S);
                TET_UNROLL
                for (int q = 0; q < 6; q++) s[q] += sv[q] * (1.0 / 6);
            }
            TET_UNROLL
            for (int q = 0; q < 6; q++) prev[q] = sv[q];
        }
        double fa[4][3];
        tet_kernel_forces(s, c, fa);
        TET_UNROLL
        for (int a = 0; a < 4; a++)
            TET_UNROLL
            for (int i = 0; i < 3; i++) fn[a][i] += fa[a][i];
    }
    sums[0] += energy;
    sums[1] += power_now * (1.0 / 6);
    sums[2] += power_prev * (1.0 / 6);
}

void tet_element_stress(const fdem_model *m, int e, double out[6])
{
    const tet_hot *t = &m->tet[e];
    const double *pos = m->pos;
    const material *mat = &m->materials[t->material];
    double ed[3][3], c[3][3], F[9], J;
    tet_kernel_edges(pos + 3 * (size_t)t->node[0], pos + 3 * (size_t)t->node[1],
                     pos + 3 * (size_t)t->node[2], pos + 3 * (size_t)t->node[3], ed);
    tet_kernel_gradient(ed, t->xinv, F);
    tet_kernel_stress(F, mat->mu, mat->lambda, 0.5 * mat->mu, 0.5 * mat->lambda, out, &J);
    double S[6], sv[6], det = tet_kernel_faces(ed, c);
    if (t->eta > 0 && tet_viscous(m->vel, t->node, c, det, t->eta, S, sv))
        for (int q = 0; q < 6; q++) out[q] += sv[q];
}
