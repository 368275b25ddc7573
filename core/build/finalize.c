/*
 * finalize.c - from a built model to one that steps: fitted arrays, every
 * stage prepared in its order (elements and their in-situ stress, lumped
 * masses, joints, contact, the scatter plans), the stable step, the
 * constraints and loads selected, the initial energy booked. Each stage
 * prepares what it owns; this file only calls them in order.
 *
 * Lumped mass follows seed eqs 5.4-5.6: every triangle gives rho*A/3 to each
 * of its nodes (a tetrahedron rho*V/4); the mass matrix is diagonal and no
 * stiffness matrix exists.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact/contact.h"
#include "element/element.h"
#include "fluid/fluid.h"
#include "joint/joint.h"
#include "model/model.h"
#include "parallel/scatter_plan.h"
#include "step/step.h"
#include "build.h"

/* rho A / 3 to each node of a triangle, rho V / 4 to each of a tetrahedron. */
static void lump_masses(fdem_model *m)
{
    memset(m->mass, 0, sizeof(double) * (size_t)m->node_count);
    const int K = m->elem_nodes;
    for (int e = 0; e < m->elem_count; e++) {
        double share = m->materials[element_material(m, e)].def.density * element_size0(m, e) / K;
        const int32_t *n = m->elem_node + (size_t)K * (size_t)e;
        for (int c = 0; c < K; c++) m->mass[n[c]] += share;
    }
    for (int i = 0; i < m->node_count; i++) m->inv_mass[i] = 1.0 / m->mass[i];
}

/* Shrinks an array grown by doubling to what it holds: the node and
 * element arrays are built part by part, so up to half of them was never
 * used (a fracturing 3D block of 1e4 tetrahedra: 270 of 3086 bytes an
 * element). Keeps the block when the system will not move it. */
static void fit_array(void **array, size_t bytes)
{
    void *p = realloc(*array, bytes ? bytes : 1);
    if (p) *array = p;
}

static void fit_model_arrays(fdem_model *m)
{
    const size_t D = (size_t)m->dim, N = (size_t)m->node_count, E = (size_t)m->elem_count;
    void **by_dim[] = {(void **)&m->pos, (void **)&m->vel, (void **)&m->force, (void **)&m->pos0};
    for (size_t i = 0; i < sizeof by_dim / sizeof by_dim[0]; i++)
        fit_array(by_dim[i], sizeof(double) * D * N);
    fit_array((void **)&m->inv_mass, sizeof(double) * N);
    fit_array((void **)&m->mass, sizeof(double) * N);
    fit_array((void **)&m->node_part, sizeof(int32_t) * N);
    fit_array((void **)&m->node_origin, sizeof(int32_t) * N);
    m->node_capacity = m->node_count;
    if (m->dim == 3) fit_array((void **)&m->tet, sizeof(tet_hot) * E);
    else fit_array((void **)&m->elem, sizeof(element_hot) * E);
    fit_array((void **)&m->elem_part, sizeof(int32_t) * E);
    fit_array((void **)&m->elem_node, sizeof(int32_t) * (size_t)m->elem_nodes * E);
    m->elem_capacity = m->elem_count;
}

/* Element nodes sit at the start of each hot record (16 int32 apart for a
 * triangle, 28 for a tetrahedron). */
static int build_scatter_plans(fdem_model *m)
{
    _Static_assert(sizeof(element_hot) % sizeof(int32_t) == 0, "element records in int32 words");
    _Static_assert(sizeof(tet_hot) % sizeof(int32_t) == 0, "element records in int32 words");
    const int32_t *first = element_nodes(m, 0);
    size_t stride = (m->dim == 3 ? sizeof(tet_hot) : sizeof(element_hot)) / sizeof(int32_t);
    if (m->elem_count &&
        scatter_plan_build(&m->elem_plan, m->elem_count,
                           scatter_block_size(m->elem_count, SCATTER_BLOCK_ELEMENTS), first,
                           stride, m->elem_nodes, m->node_count))
        return -1;
    if (joint_sweep_init(&m->joint_sweep, m->joint_count)) return -1;
    return scatter_plan_build_disjoint(&m->node_plan, m->node_count,
                                       scatter_block_size(m->node_count, SCATTER_BLOCK_NODES));
}

int fdem_model_finalize(fdem_model *m, fdem_error *err)
{
    if (m->finalized) return 0;
    if (m->threads < 1) m->threads = 1;
    if (m->part_count == 0) {
        model_error(err, FDEM_ITEM_NONE, -1, "the model has no parts");
        return -1;
    }
    const size_t D = (size_t)m->dim;
    fit_model_arrays(m);
    memcpy(m->pos, m->pos0, sizeof(double) * D * (size_t)m->node_count);
    memset(m->force, 0, sizeof(double) * D * (size_t)m->node_count);
    for (int k = 0; k < m->part_count; k++) {
        const part *p = &m->parts[k];
        for (int i = p->node_begin; i < p->node_begin + p->node_count; i++)
            for (size_t d = 0; d < D; d++) m->vel[D * (size_t)i + d] = m->part_velocity[3 * k + (int)d];
    }
    m->elem_h = malloc(sizeof(double) * (size_t)m->elem_count);
    if (!m->elem_h) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }
    int damped = 0;
    for (int e = 0; e < m->elem_count; e++) {
        if (element_prepare(m, e, err)) return -1;
        damped |= element_eta(m, e) > 0;
    }
    if (initial_stress_prepare(m, err)) return -1;
    if (damped && !(m->elem_viscous = calloc((size_t)model_stress_comps(m) * (size_t)m->elem_count,
                                             sizeof(double)))) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }
    lump_masses(m);
    if (joint_prepare(m, err) || joint_prestress_prepare(m, err)) return -1;
    m->fragments = joint_fragment_count(m);
    if (contact_init(m, err)) return -1;
    if (build_scatter_plans(m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }

    double dt = INFINITY;
    for (int e = 0; e < m->elem_count; e++) {
        double de = element_stable_dt(m, e);
        if (de < dt) dt = de;
    }
    m->eigen_dt = fmin(dt, joint_stable_dt(m));
    m->contact_dt = contact_stable_dt(m);
    m->stable_dt = fmin(m->eigen_dt, m->contact_dt);
    m->stage_now = 0; /* the stage of the first step: stage-only constraints of stage 0 hold */
    if (stages_validate(m, err)) return -1;
    /* After the stable step, so a case refused for its constraints can
     * still be told whether its dt would do (one answer, every problem). */
    constraint_set_time(m, 0);
    if (constraint_select(m, err)) return -1;
    if (boundary_load_select(m, err)) return -1;
    if (fixed_parts_prepare(m, err)) return -1;
    if (fluid_prepare(m, err)) return -1; /* tightens stable_dt by the fluid's stiffness */
    m->dt = fdem_auto_dt(m, FDEM_DEFAULT_SAFETY);
    m->dt_prev = 0;
    m->finalized = 1;
    energy_initial(m);
    return 0;
}

/* The stability limits (elements, joints, fluid) are bounds on the fastest
 * mode, omega dt <= 2: safety x them keeps a margin. The contact step is
 * not such a bound: a penalty that switches on within a step adds energy
 * long before the step goes unstable, so contact_stable_dt is where flat
 * impacts keep their energy (omega dt about 1), half the contact's own
 * stability limit. "auto" takes safety x every stability limit, the
 * contact's too, and never more than the contact step: from the default
 * safety up, contact runs at its step; below it, at safety x its limit. */
double fdem_auto_dt(const fdem_model *m, double safety)
{
    double contact = fmin(1, safety * CONTACT_STABLE_OVER_STEP) * m->contact_dt;
    return fmin(safety * m->eigen_dt, contact);
}
