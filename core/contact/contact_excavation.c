/*
 * contact_excavation.c - what contact contributes to an excavation's
 * unloading forces (step/excavation.c): each candidate pair of the last
 * detection between an element removed now and one that stays is
 * evaluated on the positions now, with a copy of its stick springs, and
 * the forces on the remaining element's nodes are what the removed one
 * exerted through contact. The pairs themselves go at the next detection,
 * which the excavation asks for (contact_drop_excavated drops every pair
 * with an excavated element, then and at every later detection).
 */
#include "model/model.h"
#include "contact.h"

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
