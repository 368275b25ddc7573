/*
 * model.c - what every stage needs of the model's state and nothing more:
 * errors that name the item at fault, arrays that grow by doubling, the
 * stage clock, and the public accessors that only read the state (fdem.h).
 * Anything that asks a stage to compute (stresses, energies, fragments)
 * lives with that stage or in analysis/.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "model.h"
#include "math/clock.h"

void model_error(fdem_error *err, fdem_item_kind kind, int item, const char *fmt, ...)
{
    if (!err) return;
    err->kind = kind;
    err->item = item;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
}

int model_reserve(void **array, size_t *capacity, size_t need, size_t size, size_t first)
{
    if (need <= *capacity) return 0;
    size_t cap = *capacity ? *capacity : first;
    while (cap < need) cap *= 2;
    void *p = realloc(*array, cap * size);
    if (!p) return -1;
    *array = p;
    *capacity = cap;
    return 0;
}

double stage_clock(void) { return clock_wall_seconds(); }

/* ------------------------------------------------------------ accessors */

double fdem_stable_dt(const fdem_model *m) { return m->stable_dt; }
void fdem_set_dt(fdem_model *m, double dt) { if (dt > 0 && isfinite(dt)) m->dt = dt; }
double fdem_get_dt(const fdem_model *m) { return m->dt; }
void fdem_set_threads(fdem_model *m, int threads) { m->threads = threads > 1 ? threads : 1; }
int fdem_get_threads(const fdem_model *m) { return m->threads > 1 ? m->threads : 1; }
int64_t fdem_get_step(const fdem_model *m) { return m->step; }
double fdem_get_time(const fdem_model *m) { return m->time; }

fdem_counts fdem_get_counts(const fdem_model *m)
{
    fdem_counts c = {0};
    c.dimension = m->dim;
    c.nodes = m->node_count;
    c.elements = m->elem_count;
    c.parts = m->part_count;
    c.materials = m->material_count;
    c.constraints = m->constraint_count;
    c.joints = m->joint_count;
    c.broken_joints = m->broken_joints;
    c.fragments = m->fragments;
    c.contacts = m->contact.touching;
    c.contact_pairs = (int)m->contact.pairs.count;
    c.detections = m->contact.detections;
    return c;
}

const double *fdem_positions(const fdem_model *m) { return m->pos; }
const double *fdem_initial_positions(const fdem_model *m) { return m->pos0; }
const double *fdem_velocities(const fdem_model *m) { return m->vel; }
const double *fdem_node_masses(const fdem_model *m) { return m->mass; }
const int32_t *fdem_node_parts(const fdem_model *m) { return m->node_part; }
const int32_t *fdem_element_parts(const fdem_model *m) { return m->elem_part; }
const int32_t *fdem_joints(const fdem_model *m) { return m->joint_count ? m->joint_node : NULL; }
const double *fdem_joint_damage(const fdem_model *m) { return m->joint_count ? m->joint_damage : NULL; }

void fdem_copy_joint_damage(const fdem_model *m, double *out)
{
    for (int j = 0; j < m->joint_count; j++) out[j] = joint_damage_shown(m, j);
}

int fdem_nodes_per_element(const fdem_model *m) { return m->elem_nodes; }
const int32_t *fdem_element_nodes(const fdem_model *m) { return m->elem_node; }
const int32_t *fdem_triangles(const fdem_model *m) { return m->dim == 2 ? m->elem_node : NULL; }
const int32_t *fdem_tetrahedra(const fdem_model *m) { return m->dim == 3 ? m->elem_node : NULL; }
int fdem_stress_components(const fdem_model *m) { return model_stress_comps(m); }

const double *fdem_constraint_forces(const fdem_model *m)
{
    for (int c = 0; c < m->constraint_count; c++)
        for (int d = 0; d < m->dim; d++)
            m->constraint_force_out[m->dim * c + d] = m->constraints[c].force[d];
    return m->constraint_force_out;
}

int fdem_constraint_node_count(const fdem_model *m, int c)
{
    if (c < 0 || c >= m->constraint_count) return 0;
    return m->constraints[c].entry_count;
}

const int32_t *fdem_constraint_nodes(const fdem_model *m, int c)
{
    if (c < 0 || c >= m->constraint_count || m->constraints[c].entry_count <= 0 || !m->cnode)
        return NULL;
    return m->cnode + m->constraints[c].entry_begin;
}
