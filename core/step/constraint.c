/*
 * constraint.c - boundary conditions: node selection by part, box or mesh
 * vertices (a named group), fixed and prescribed-velocity components, forces
 * shared over a node set, their amplitudes in time, and the total reaction
 * of each constraint after every step (the loads on boundary facets:
 * pressures, boundary stresses, tractions and dashpots, boundary_load.c).
 *
 * A degree of freedom belongs to the last constraint (in case order) that
 * prescribes it, so overlapping selections are well defined and each
 * reaction is counted once. Prescribed dofs are integrated here, after the
 * free dofs: the reaction is what the support had to add to the step's
 * force to impose the prescribed velocity, m (v_prescribed - v_free) / h.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "math/amplitude.h"
#include "model/model.h"
#include "step.h"

void model_error(fdem_error *err, fdem_item_kind kind, int item, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static int vertex_compare(const void *pa, const void *pb)
{
    int32_t a = *(const int32_t *)pa, b = *(const int32_t *)pb;
    return (a > b) - (a < b);
}

/* A vertex selection's list is the caller's: keep a sorted copy, so
 * selecting a node is a binary search. */
int constraint_keep_vertices(constraint *c)
{
    if (c->def.select != FDEM_SELECT_VERTICES) {
        c->def.vertices = NULL;
        c->def.vertex_count = 0;
        return 0;
    }
    size_t n = (size_t)c->def.vertex_count;
    c->vertices = malloc(sizeof(int32_t) * n);
    if (!c->vertices) return -1;
    memcpy(c->vertices, c->def.vertices, sizeof(int32_t) * n);
    qsort(c->vertices, n, sizeof(int32_t), vertex_compare);
    c->def.vertices = c->vertices;
    return 0;
}

/* Box bounds: box[d] lower, box[D + d] upper, for D = m->dim. */
int constraint_selects(const fdem_model *m, const constraint *c, int node)
{
    if (c->def.select == FDEM_SELECT_PART) return m->node_part[node] == c->def.part;
    if (c->def.select == FDEM_SELECT_VERTICES) {
        if (m->node_part[node] != c->def.part) return 0;
        int32_t vertex = m->node_origin[node] - m->parts[c->def.part].node_begin;
        return bsearch(&vertex, c->vertices, (size_t)c->def.vertex_count, sizeof(int32_t),
                       vertex_compare) != NULL;
    }
    const double *b = c->def.box, *x = m->pos0 + (size_t)m->dim * (size_t)node;
    int inside = 1;
    for (int d = 0; d < m->dim; d++) inside &= x[d] >= b[d] && x[d] <= b[m->dim + d];
    return inside;
}

/* The dofs a constraint prescribes, bit d for component d (2D never z). */
static unsigned constraint_dofs(const fdem_model *m, const constraint *c)
{
    unsigned z = m->dim == 3 ? 4u : 0u;
    switch (c->def.kind) {
    case FDEM_CONSTRAINT_FIX:
        return (c->def.fix_x ? 1u : 0u) | (c->def.fix_y ? 2u : 0u) | (c->def.fix_z ? z : 0u);
    case FDEM_CONSTRAINT_VELOCITY:
        return (c->def.free_x ? 0u : 1u) | (c->def.free_y ? 0u : 2u) | (c->def.free_z ? 0u : z);
    default: return 0;
    }
}

/* The values this step uses: forces, pressures and gravity at t_n, where
 * the step evaluates forces, and prescribed velocities at velocity_time,
 * the half step t_n + h/2 they are the velocity of (0 at finalize, for the
 * velocity at t = 0). Without an amplitude the value is copied, not
 * multiplied, so such a case keeps its arithmetic to the bit. */
void constraint_set_time(fdem_model *m, double velocity_time)
{
    if (m->gravity_amplitude) {
        double a = amplitude_at(m->gravity_amplitude, m->gravity_amplitude_count, m->time);
        for (int d = 0; d < m->dim; d++) m->gravity[d] = m->gravity_base[d] * a;
    }
    for (int k = 0; k < m->constraint_count; k++) {
        constraint *c = &m->constraints[k];
        if (!constraint_active(m, c)) { /* outside its stage: applies nothing */
            memset(c->value_now, 0, sizeof c->value_now);
            c->amplitude_now = 0; /* a boundary stress scales its field by it */
            continue;
        }
        if (!c->amplitude) {
            memcpy(c->value_now, c->def.value, sizeof c->value_now);
            c->amplitude_now = 1;
            continue;
        }
        double t = c->def.kind == FDEM_CONSTRAINT_VELOCITY ? velocity_time : m->time;
        double a = amplitude_at(c->amplitude, c->def.amplitude_count, t);
        for (int d = 0; d < 3; d++) c->value_now[d] = c->def.value[d] * a;
        c->amplitude_now = a;
    }
}

/* Each prescribed dof to the last constraint (in case order) that
 * prescribes it among those acting in the stage now (constraint_active);
 * a node only excavated elements held (node_frozen) has every dof owned,
 * by no constraint, so it stands still. Called at finalize and whenever
 * the stage or the excavated elements change (stages.c). */
int constraint_assign_dofs(fdem_model *m)
{
    const int D = m->dim;
    int32_t *owner = malloc(sizeof(int32_t) * (size_t)D * (size_t)(m->node_count ? m->node_count : 1));
    if (!owner) return -1;
    for (int i = 0; i < D * m->node_count; i++) owner[i] = -1;
    for (int k = 0; k < m->constraint_count; k++) {
        const constraint *c = &m->constraints[k];
        unsigned dofs = constraint_active(m, c) ? constraint_dofs(m, c) : 0;
        for (int e = c->entry_begin; e < c->entry_begin + c->entry_count; e++) {
            int i = m->cnode[e];
            if (m->node_frozen && m->node_frozen[i]) continue;
            for (int d = 0; d < D; d++)
                if (dofs & (1u << d)) owner[D * i + d] = k;
        }
    }
    memset(m->dof_owned, 0, (size_t)m->node_count);
    for (int k = 0; k < m->constraint_count; k++) {
        const constraint *c = &m->constraints[k];
        for (int e = c->entry_begin; e < c->entry_begin + c->entry_count; e++) {
            int i = m->cnode[e];
            unsigned own = 0;
            for (int d = 0; d < D; d++)
                if (owner[D * i + d] == k) own |= 1u << d;
            m->cdof[e] = (uint8_t)own;
            m->dof_owned[i] |= m->cdof[e];
        }
    }
    free(owner);
    if (m->node_frozen)
        for (int i = 0; i < m->node_count; i++)
            if (m->node_frozen[i]) m->dof_owned[i] = (uint8_t)((1u << D) - 1);
    return 0;
}

int constraint_select(fdem_model *m, fdem_error *err)
{
    int total = 0, empty = 0, first_empty = -1;
    for (int k = 0; k < m->constraint_count; k++) {
        m->constraints[k].entry_count = -1; /* not counted */
        /* constraint_set_time keeps it for tables only: without one it stays 1 */
        if (!m->constraints[k].amplitude) m->constraints[k].amplitude_now = 1;
    }
    for (int k = 0; k < m->constraint_count; k++) {
        constraint *c = &m->constraints[k];
        if (c->def.select != FDEM_SELECT_BOX && (c->def.part < 0 || c->def.part >= m->part_count)) {
            model_error(err, FDEM_ITEM_CONSTRAINT, k, "constraint %d selects part %d, which does not exist",
                        k, c->def.part);
            return -1;
        }
        int n = 0;
        for (int i = 0; i < m->node_count; i++) n += constraint_selects(m, c, i);
        c->entry_begin = total;
        c->entry_count = n;
        total += n;
        if (n == 0 && empty++ == 0) first_empty = k;
    }
    /* every constraint counted first, so fdem_constraint_node_count()
     * names each empty one to the caller, not only the first */
    if (empty) {
        model_error(err, FDEM_ITEM_CONSTRAINT, first_empty,
                    "constraint %d selects no node (check the box against the initial positions)%s",
                    first_empty, empty > 1 ? "; other constraints select none either" : "");
        return -1;
    }
    m->cnode = malloc(sizeof(int32_t) * (size_t)(total ? total : 1));
    m->cdof = malloc((size_t)(total ? total : 1));
    m->dof_owned = calloc((size_t)m->node_count, 1);
    const int D = m->dim;
    m->constraint_force_out = calloc((size_t)D * (size_t)(m->constraint_count ? m->constraint_count : 1),
                                     sizeof(double));
    if (!m->cnode || !m->cdof || !m->dof_owned || !m->constraint_force_out) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for constraints");
        return -1;
    }
    m->cnode_count = total;
    for (int k = 0; k < m->constraint_count; k++) {
        constraint *c = &m->constraints[k];
        int at = c->entry_begin;
        for (int i = 0; i < m->node_count; i++)
            if (constraint_selects(m, c, i)) m->cnode[at++] = i;
    }
    if (constraint_assign_dofs(m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for constraints");
        return -1;
    }
    /* Prescribed velocities hold from t = 0 on. */
    for (int k = 0; k < m->constraint_count; k++) {
        const constraint *c = &m->constraints[k];
        if (c->def.kind != FDEM_CONSTRAINT_FIX && c->def.kind != FDEM_CONSTRAINT_VELOCITY) continue;
        for (int e = c->entry_begin; e < c->entry_begin + c->entry_count; e++) {
            int i = m->cnode[e];
            for (int d = 0; d < D; d++)
                if (m->cdof[e] & (1u << d))
                    m->vel[D * i + d] = c->def.kind == FDEM_CONSTRAINT_FIX ? 0.0 : c->value_now[d];
        }
    }
    return 0;
}

void constraint_apply_forces(fdem_model *m)
{
    const int D = m->dim;
    for (int k = 0; k < m->constraint_count; k++) {
        constraint *c = &m->constraints[k];
        if (c->def.kind != FDEM_CONSTRAINT_FORCE) continue;
        for (int d = 0; d < D; d++) {
            double share = c->value_now[d] / c->entry_count;
            for (int e = c->entry_begin; e < c->entry_begin + c->entry_count; e++)
                m->force[(size_t)D * (size_t)m->cnode[e] + (size_t)d] += share;
            c->force[d] = c->value_now[d];
        }
    }
}

/* What constraint_enforce accumulates over its entries, kept in locals:
 * through m, every store to a velocity or position (a double) could alias
 * the sums, so the compiler reloaded and stored them at every dof (67
 * instructions an element-step of the sphere pile, whose container is
 * fixed). The sums are formed in the same order as before: the same bits. */
typedef struct enforce_sums {
    double external_work, contact_work, max_disp2, near_disp2;
} enforce_sums;

/* fmax's result (the other when one is NaN) without its libm call */
static inline double enforce_max(double most, double v)
{
    return v > most || most != most ? v : most;
}

/* The prescribed dofs of one node (velocity `prescribed`, 0 when fixed)
 * into the support's reaction `reaction_sum`, with their work, and the
 * node's travel since the contact lists were built. D and with_contact
 * are constants at each call, so the loops unroll and fc's test goes. */
static inline __attribute__((always_inline)) void
enforce_node(fdem_model *m, size_t i, unsigned own, const double *prescribed, double h,
             double havg, const int D, const int with_contact, double *reaction_sum,
             enforce_sums *s)
{
    const size_t at = (size_t)D * i;
    const double *fc = m->contact.force;
    double *x = m->pos + at, *v = m->vel + at;
    const double mass = m->mass[i];
#pragma GCC unroll 3
    for (int d = 0; d < D; d++) {
        if (!(own & (1u << d))) continue;
        double f = m->force[at + d] + (with_contact ? fc[at + d] : 0) + mass * m->gravity[d];
        double v_old = v[d];
        double v_free = v_old + f / mass * havg;
        double reaction = mass * (prescribed[d] - v_free) / havg;
        reaction_sum[d] += reaction;
        v[d] = prescribed[d];
        x[d] += prescribed[d] * h;
        double v_mid = 0.5 * (v_old + prescribed[d]) * havg;
        s->external_work += reaction * v_mid;
        if (with_contact) s->contact_work += fc[at + d] * v_mid;
    }
    if (!with_contact) return;
    const double *xd = m->contact.pos_detect + at, *xn = m->contact.pos_near + at;
    double d2 = 0, n2 = 0;
#pragma GCC unroll 3
    for (int d = 0; d < D; d++) {
        double u = x[d] - xd[d];
        double w = x[d] - xn[d];
        d2 += u * u;
        n2 += w * w;
    }
    if (m->contact.travel_weight) d2 *= m->contact.travel_weight[i]; /* contact_travel.c */
    s->max_disp2 = enforce_max(s->max_disp2, d2);
    s->near_disp2 = enforce_max(s->near_disp2, n2);
}

static void enforce_entries(fdem_model *m, const constraint *c, const double *prescribed,
                            double h, double havg, double *reaction_sum, enforce_sums *s)
{
    const int end = c->entry_begin + c->entry_count, with_contact = m->contact.enabled;
    for (int e = c->entry_begin; e < end; e++) {
        size_t i = (size_t)m->cnode[e];
        unsigned own = m->cdof[e];
        if (m->dim == 3)
            with_contact ? enforce_node(m, i, own, prescribed, h, havg, 3, 1, reaction_sum, s)
                         : enforce_node(m, i, own, prescribed, h, havg, 3, 0, reaction_sum, s);
        else
            with_contact ? enforce_node(m, i, own, prescribed, h, havg, 2, 1, reaction_sum, s)
                         : enforce_node(m, i, own, prescribed, h, havg, 2, 0, reaction_sum, s);
    }
}

/* Integrates the prescribed dofs (skipped by the free update) and the work
 * of every constraint during this step. total_force(i, d) is the step's
 * force on dof d of node i from every source except the support. */
void constraint_enforce(fdem_model *m, double h, double havg)
{
    const double *fc = m->contact.enabled ? m->contact.force : NULL;
    const int D = m->dim;
    enforce_sums s = {m->external_work, m->contact_work, m->contact.max_disp2,
                      m->contact.near_disp2};
    for (int k = 0; k < m->constraint_count; k++) {
        constraint *c = &m->constraints[k];
        if (c->def.kind == FDEM_CONSTRAINT_FORCE) {
            for (int e = c->entry_begin; e < c->entry_begin + c->entry_count; e++) {
                size_t i = (size_t)m->cnode[e], at = (size_t)D * i;
                double power = 0;
                for (int d = 0; d < D; d++) {
                    double share = c->value_now[d] / c->entry_count;
                    /* a prescribed dof moves at its prescribed velocity (0
                     * when fixed): the support takes the force, and the
                     * free update's acceleration is not its own (booking
                     * it gave a fixed node work at rest) */
                    if (m->dof_owned[i] & (1u << d)) {
                        power += share * m->vel[at + d];
                        continue;
                    }
                    /* velocities were already advanced: v_old = v_new - a havg */
                    double a = (m->force[at + d] + (fc ? fc[at + d] : 0)) / m->mass[i] + m->gravity[d];
                    power += share * (m->vel[at + d] - 0.5 * a * havg);
                }
                s.external_work += power * havg;
            }
            continue;
        }
        if (c->def.kind != FDEM_CONSTRAINT_FIX && c->def.kind != FDEM_CONSTRAINT_VELOCITY)
            continue; /* boundary loads: boundary_load.c */
        static const double fixed[3] = {0, 0, 0};
        double reaction[3] = {0, 0, 0};
        enforce_entries(m, c, c->def.kind == FDEM_CONSTRAINT_FIX ? fixed : c->value_now, h, havg,
                        reaction, &s);
        for (int d = 0; d < 3; d++) c->force[d] = reaction[d];
    }
    m->external_work = s.external_work;
    m->contact_work = s.contact_work;
    m->contact.max_disp2 = s.max_disp2;
    m->contact.near_disp2 = s.near_disp2;
}
