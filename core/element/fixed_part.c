/*
 * fixed_part.c - parts held still as a whole: a platen, a container, a
 * base block, each fixed in every component. Their elements' forces are
 * computed once and kept.
 *
 * A part is fixed here when every node of it is fixed in every component
 * by fix constraints and nothing else acts on those nodes: no velocity or
 * force constraint, no pressure or dashpot facet, no joint on its elements
 * (contact forces are kept apart, in contact.force). Its nodes then never
 * move: the central difference skips them and constraint_enforce sets
 * v = 0 and x += 0 h, which from the second step on leaves x as it was to
 * the bit (only a -0 coordinate becomes +0, in the first step). With the
 * same positions and zero velocities its elements give the same forces
 * and strain energy every step, and no damping. They still matter: the
 * reactions of the fix constraints are those forces (and contact's), and
 * the elastic energy holds their strain energy (an in-situ stress, say).
 *
 * So from the second step on (fixed_parts_kept) element.c leaves these
 * elements out of its blocks and fixed_parts_forces puts the kept forces
 * on their nodes; the first time, and after a checkpoint is restored, it
 * computes them: one walk over each part's elements in order, on one
 * thread, so the kept values are the same bits on any thread count and
 * after any restart. The elastic energy from the second step on is the
 * blocks' sum plus the kept figure, whether it was kept or just computed.
 * A container of 2760 of the 4056 elements of the bench's sphere pile
 * stops costing 2760 element evaluations a step.
 */
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "element.h"

/* Marks (1) every node some load other than a fix constraint acts on. */
static void mark_loaded_nodes(const fdem_model *m, uint8_t *loaded)
{
    const int D = m->dim;
    for (int k = 0; k < m->constraint_count; k++) {
        const constraint *c = &m->constraints[k];
        if (c->def.kind == FDEM_CONSTRAINT_FIX) continue;
        for (int e = c->entry_begin; e < c->entry_begin + c->entry_count; e++)
            loaded[m->cnode[e]] = 1;
        for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++)
            for (int a = 0; a < D; a++) loaded[m->bfacet_node[(size_t)D * (size_t)j + (size_t)a]] = 1;
    }
}

static int part_is_fixed(const fdem_model *m, const part *p, const uint8_t *loaded,
                         const uint8_t *jointed, int index)
{
    const unsigned all = (1u << m->dim) - 1;
    if (p->fracture || jointed[index] || p->elem_count == 0) return 0;
    for (int i = p->node_begin; i < p->node_begin + p->node_count; i++)
        if (loaded[i] || m->dof_owned[i] != all) return 0;
    return 1;
}

/* After the constraints and boundary loads have their nodes (finalize). */
int fixed_parts_prepare(fdem_model *m, fdem_error *err)
{
    uint8_t *loaded = calloc((size_t)m->node_count + 1, 1);
    uint8_t *jointed = calloc((size_t)m->part_count, 1);
    if (!loaded || !jointed) {
        free(loaded);
        free(jointed);
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }
    mark_loaded_nodes(m, loaded);
    for (int j = 0; j < m->joint_count; j++)
        for (int s = 0; s < 2; s++) jointed[m->elem_part[m->joint_elem[2 * j + s]]] = 1;
    size_t nodes = 0;
    m->fixed_parts = 0;
    for (int k = 0; k < m->part_count; k++) {
        part *p = &m->parts[k];
        p->fixed = part_is_fixed(m, p, loaded, jointed, k);
        if (!p->fixed) continue;
        m->fixed_parts++;
        nodes += (size_t)p->node_count;
    }
    free(loaded);
    free(jointed);
    m->fixed_valid = 0;
    if (!m->fixed_parts) return 0;
    if (!(m->fixed_force = malloc(sizeof(double) * (size_t)m->dim * nodes))) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }
    return 0;
}

/* Moves the forces of the fixed parts' nodes between m->force and the
 * kept copy, in either direction. */
static void fixed_forces_copy(fdem_model *m, int keep)
{
    const size_t D = (size_t)m->dim;
    double *kept = m->fixed_force;
    for (int k = 0; k < m->part_count; k++) {
        const part *p = &m->parts[k];
        if (!p->fixed) continue;
        double *f = m->force + D * (size_t)p->node_begin;
        size_t bytes = sizeof(double) * D * (size_t)p->node_count;
        if (keep) memcpy(kept, f, bytes);
        else memcpy(f, kept, bytes);
        kept += D * (size_t)p->node_count;
    }
}

/* Each fixed part's elements in order, on this thread, into their nodes
 * (zeroed first: nothing else adds to them). */
static void fixed_forces_compute(fdem_model *m)
{
    const size_t D = (size_t)m->dim;
    double sums[SCATTER_SUMS] = {0};
    for (int k = 0; k < m->part_count; k++) {
        const part *p = &m->parts[k];
        if (!p->fixed) continue;
        memset(m->force + D * (size_t)p->node_begin, 0, sizeof(double) * D * (size_t)p->node_count);
        element_forces_loop_of(m, p)(m, p->elem_begin, p->elem_begin + p->elem_count, sums);
    }
    fixed_forces_copy(m, 1);
    m->fixed_energy = sums[0];
    m->fixed_valid = 1;
}

/* The fixed parts' element forces on their nodes; returns their strain
 * energy. Only while fixed_parts_kept. */
double fixed_parts_forces(fdem_model *m)
{
    if (m->fixed_valid) fixed_forces_copy(m, 0);
    else fixed_forces_compute(m);
    return m->fixed_energy;
}
