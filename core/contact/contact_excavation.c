/*
 * contact_excavation.c - what contact contributes to an excavation's
 * unloading forces (step/excavation.c): each candidate pair of the last
 * detection between an element removed now and one that stays is
 * evaluated on the positions now, with a copy of its stick springs, and
 * the forces on the remaining element's nodes are what the removed one
 * exerted through contact. The pairs themselves go at the next detection,
 * which the excavation asks for (contact_drop_excavated drops every pair
 * with an excavated element, then and at every later detection).
 *
 * The penalty energy those pairs hold leaves with them (excavated energy,
 * energy.c): the contact account is the work the contact forces did, so
 * without this it would keep showing energy no pair holds any more. A
 * pair's energy is the work its force does on the removed element as that
 * element is drawn straight out of the pair along that force: the distance
 * at which they part is found by doubling then halving, and the work summed
 * by the trapezoidal rule in CONTACT_ENERGY_STEPS steps over it; without
 * friction (a stick spring's share is not counted). Checked against the
 * account on a block resting on another (test_excavation.c): 2 % in 2D,
 * 4 % in 3D while the block rings.
 */
#include <math.h>
#include <string.h>

#include "model/model.h"
#include "contact.h"
#include "contact_internal.h"

#define CONTACT_ENERGY_STEPS 256 /* over the distance at which the pair parts */

/* Excavated elements touch nothing: their pairs leave the candidate list
 * (called at each detection of a model with excavations: elem_active). */
void contact_drop_excavated(fdem_model *m)
{
    contact_state *cs = &m->contact;
    size_t kept = 0;
    for (size_t k = 0; k < cs->pairs.count; k++) {
        int a = cs->pairs.a[k], b = cs->pairs.b[k];
        if (!m->elem_active[a] || !m->elem_active[b]) continue;
        cs->pairs.a[kept] = a;
        cs->pairs.b[kept] = b;
        kept++;
    }
    cs->pairs.count = kept;
}

int contact_excavation_forces(fdem_model *m, const uint8_t *removed, double *f)
{
    if (contact_springs_sync(m)) return -1; /* it reads every pair's springs */
    const contact_state *cs = &m->contact;
    const int D = m->dim, K = m->elem_nodes;
    double out[CONTACT_PAIR_OUT_MAX];
    for (size_t k = 0; k < cs->pairs.count; k++) {
        int a = cs->pairs.a[k], b = cs->pairs.b[k];
        if (removed[a] == removed[b] || !element_is_active(m, removed[a] ? b : a)) continue;
        if (!contact_pair_force_now(m, k, out)) continue;
        /* out: a's nodes, then b's */
        int stay = removed[a] ? 1 : 0;
        const int32_t *n = element_nodes(m, stay ? b : a);
        for (int c = 0; c < K; c++)
            for (int d = 0; d < D; d++)
                f[(size_t)D * (size_t)n[c] + (size_t)d] += out[D * (stay * K + c) + d];
    }
    return 0;
}

/* The element's nodes' positions into x (K * D) and its centroid into c;
 * its bounding radius about c is returned. */
static double element_copy(const fdem_model *m, int e, double *x, double c[3])
{
    const int D = m->dim, K = m->elem_nodes;
    const int32_t *n = element_nodes(m, e);
    c[0] = c[1] = c[2] = 0;
    for (int k = 0; k < K; k++)
        for (int d = 0; d < D; d++) {
            x[D * k + d] = m->pos[(size_t)D * (size_t)n[k] + (size_t)d];
            c[d] += x[D * k + d] / K;
        }
    double r2 = 0;
    for (int k = 0; k < K; k++) {
        double q = 0;
        for (int d = 0; d < D; d++) q += (x[D * k + d] - c[d]) * (x[D * k + d] - c[d]);
        r2 = fmax(r2, q);
    }
    return sqrt(r2);
}

/* The force of pair (gone, other) on gone's nodes along u with gone moved
 * by s u (x holds both elements' nodes, gone's first, at s = 0); 0 when
 * they do not touch there. */
static double pull_at(const fdem_model *m, contact_pair_in *in, const double *x, double *moved,
                      const double *u, double s, int *touched)
{
    const int D = m->dim, K = m->elem_nodes;
    double springs[CONTACT_SLOTS_MAX] = {0}, out[CONTACT_PAIR_OUT_MAX];
    memcpy(moved, x, sizeof(double) * (size_t)(2 * K * D));
    for (int k = 0; k < K; k++)
        for (int d = 0; d < D; d++) moved[D * k + d] += s * u[d];
    *touched = m->contact.kernel->pair_force(in, springs, out);
    if (!*touched) return 0;
    double f = 0;
    for (int k = 0; k < K; k++)
        for (int d = 0; d < D; d++) f += out[D * k + d] * u[d];
    return f;
}

/* The penalty energy of pair (gone, other) now (see the top of the file);
 * 0 for elements that share a node (glued: they hold none apart). */
static double pair_energy(const fdem_model *m, int gone, int other)
{
    const int D = m->dim, K = m->elem_nodes;
    const int32_t *na = element_nodes(m, gone), *nb = element_nodes(m, other);
    for (int i = 0; i < K; i++)
        for (int j = 0; j < K; j++)
            if (na[i] == nb[j]) return 0;
    double x[2 * 4 * 3], moved[2 * 4 * 3], vel[2 * 4 * 3] = {0}, ca[3], cb[3], u[3] = {0, 0, 0};
    double reach = element_copy(m, gone, x, ca) + element_copy(m, other, x + K * D, cb), len = 0;
    static const int32_t local[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    const material *ma = &m->materials[element_material(m, gone)];
    const material *mb = &m->materials[element_material(m, other)];
    contact_pair_in in = {moved, vel, local, local + K, fmin(ma->penalty, mb->penalty), 0,
                          m->dt_prev, NULL, 0, 0};
    /* drawn out along the pair's force on it */
    double springs[CONTACT_SLOTS_MAX] = {0}, out[CONTACT_PAIR_OUT_MAX];
    memcpy(moved, x, sizeof(double) * (size_t)(2 * K * D));
    if (!m->contact.kernel->pair_force(&in, springs, out)) return 0;
    for (int k = 0; k < K; k++)
        for (int d = 0; d < D; d++) u[d] += out[D * k + d];
    for (int d = 0; d < D; d++) len += u[d] * u[d];
    len = sqrt(len);
    if (!(len > 0) || !(reach > 0)) return 0;
    for (int d = 0; d < D; d++) u[d] /= len;

    /* where they part: doubled from a billionth of the reach, then halved */
    int touched = 1;
    double lo = 0, hi = 1e-9 * reach;
    while (hi < 2 * reach && (pull_at(m, &in, x, moved, u, hi, &touched), touched)) {
        lo = hi;
        hi *= 2;
    }
    for (int i = 0; i < 60; i++) {
        double mid = 0.5 * (lo + hi);
        pull_at(m, &in, x, moved, u, mid, &touched);
        if (touched) lo = mid;
        else hi = mid;
    }
    const double ds = hi / CONTACT_ENERGY_STEPS;
    double energy = 0, f_prev = pull_at(m, &in, x, moved, u, 0, &touched);
    for (int i = 1; i <= CONTACT_ENERGY_STEPS; i++) {
        double f = pull_at(m, &in, x, moved, u, i * ds, &touched);
        energy += 0.5 * (f_prev + f) * ds;
        f_prev = f;
    }
    return energy;
}

double contact_excavation_energy(const fdem_model *m, const uint8_t *removed)
{
    const contact_state *cs = &m->contact;
    double energy = 0;
    for (size_t k = 0; k < cs->pairs.count; k++) {
        int a = cs->pairs.a[k], b = cs->pairs.b[k];
        if (!(removed[a] || removed[b]) || !element_is_active(m, a) || !element_is_active(m, b))
            continue;
        double ba[6] = {0}, bb[6] = {0};
        element_box(m, a, ba);
        element_box(m, b, bb);
        if (!boxes_overlap(ba, bb, m->dim)) continue;
        energy += removed[a] ? pair_energy(m, a, b) : pair_energy(m, b, a);
    }
    return energy;
}
