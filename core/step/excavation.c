/*
 * excavation.c - removing elements at the start of a stage (contract 6.1)
 * by the unloading method of tunnelling codes: at that moment the removed
 * elements exert nodal forces f_exc on the nodes they share with the
 * remaining body (their internal forces, with the in-situ pre-stress; the
 * weight of their share of those nodes' lumped mass; the forces of the
 * joints between a removed and a remaining element; those of contact pairs
 * between them); the elements go, and f_exc (1 - s) is
 * applied in their place as an external force, s ramping from 0 to 1 over
 * the stage's relax (stages.c). So the remaining body is in the state it
 * was, and the release of f_exc, slow or sudden, is what loads it.
 *
 * Why f_exc leaves the damping out: the viscous stress is a numerical
 * device (a fraction of critical damping to settle a model), and an
 * element that moved at the moment of excavation would freeze that
 * transient force into the load. Elastic and pre-stress forces are the
 * stress the ground held; damping is not.
 *
 * What the removed elements take with them, booked in excavated_energy so
 * the balance closes (energy.c): their strain energy at that moment (the
 * in-situ stress's share included), the energy of the joints on them, the
 * penalty energy of their contact pairs (out of the contact account:
 * contact_excavation.c), and the kinetic energy of the mass that leaves. That mass leaves the shared
 * nodes (the lumped masses are summed again over the active elements,
 * finalize's sum less the removed elements' terms), so gravity no longer
 * pulls it; a node that only removed elements held keeps no mass, is held
 * still (dof_owned, v = 0) and carries no force. The stable step needs no
 * change: each element's limit (element eigenvalue theorem) takes only its
 * own share of the lumped mass, which a remaining element keeps; a node
 * that lost mass is held by fewer elements, not stiffer ones.
 *
 * Everything but f_exc and the energies follows from which elements are
 * active, and is computed again from that alone after a checkpoint is read
 * (excavation_refresh): the same sums in the same order, the same bits.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact/contact.h"
#include "element/element.h"
#include "joint/joint.h"
#include "model/model.h"
#include "step.h"

/* Element e's damping coefficient, either dimension. */
static void element_set_eta(fdem_model *m, int e, double eta)
{
    if (m->dim == 3) m->tet[e].eta = eta;
    else m->elem[e].eta = eta;
}

/* The removed elements' kernel, run by run of consecutive removed elements
 * of one part, onto the force array f (swapped in for m->force); returns
 * the block sums (strain energy, viscous powers: element.c). */
static void removed_element_pass(fdem_model *m, const uint8_t *removed, double *f,
                                 double sums[SCATTER_SUMS])
{
    double *keep = m->force;
    m->force = f;
    for (int e = 0; e < m->elem_count;) {
        if (!removed[e]) {
            e++;
            continue;
        }
        const part *p = &m->parts[m->elem_part[e]];
        int stop = e + 1, part_end = p->elem_begin + p->elem_count;
        while (stop < part_end && removed[stop]) stop++;
        element_forces_loop_of(m, p)(m, e, stop, sums);
        e = stop;
    }
    m->force = keep;
}

/* The removed elements' forces without damping into f, their strain
 * energy into *energy. With damping, the power of their last viscous
 * forces with the velocities now (the half of the last step's damping that
 * the next element pass would have booked: element.c) goes to the damping
 * account first. 0, or -1 out of memory. */
static int removed_element_forces(fdem_model *m, const uint8_t *removed, int count, double *f,
                                  double *energy)
{
    const size_t DN = (size_t)m->dim * (size_t)m->node_count;
    double *eta = malloc(sizeof(double) * (size_t)count);
    if (!eta) return -1;
    if (m->elem_viscous) {
        double sums[SCATTER_SUMS] = {0};
        removed_element_pass(m, removed, f, sums);
        m->damping_work -= 0.5 * m->havg_last * sums[2];
        memset(f, 0, sizeof(double) * DN);
    }
    int r = 0;
    for (int e = 0; e < m->elem_count; e++)
        if (removed[e]) {
            eta[r++] = element_eta(m, e);
            element_set_eta(m, e, 0);
        }
    double sums[SCATTER_SUMS] = {0};
    removed_element_pass(m, removed, f, sums);
    const size_t S = (size_t)model_stress_comps(m);
    r = 0;
    for (int e = 0; e < m->elem_count; e++)
        if (removed[e]) {
            element_set_eta(m, e, eta[r++]);
            if (m->elem_viscous) memset(m->elem_viscous + S * (size_t)e, 0, sizeof(double) * S);
        }
    free(eta);
    *energy = sums[0];
    return 0;
}

/* Face nodes of joint j: face A's dim nodes, then face B's. */
static const int32_t *joint_face(const fdem_model *m, int j, int face)
{
    return m->joint_node + 2 * (size_t)m->dim * (size_t)j + (size_t)face * (size_t)m->dim;
}

/* The forces of the intact joints between a removed and a remaining
 * element on the remaining face, into f; returns the energy of every
 * intact joint on a removed element. Each is evaluated on the positions
 * now as the step would, and its history (damage, slip, fracture account)
 * is put back as it was: it is not going to be stepped. Then every joint
 * on an inactive element holds nothing from now on (damage at least 1:
 * the joint loop skips it), without being a fracture event or a broken
 * joint (joints_on_removed_let_go). */
static double removed_joint_forces(fdem_model *m, const uint8_t *removed, double *f)
{
    const int D = m->dim;
    double energy = 0;
    joint_one_fn one = D == 3 ? joint_forces_one_3d : joint_forces_one_2d;
    for (int j = 0; j < m->joint_count; j++) {
        int ea = m->joint_elem[2 * j], eb = m->joint_elem[2 * j + 1];
        int ra = removed[ea], rb = removed[eb];
        if (!(ra || rb) || m->joint_damage[j] >= 1.0) continue;
        joint_slip slip[3];
        memcpy(slip, m->joint_slip + (size_t)D * (size_t)j, sizeof(joint_slip) * (size_t)D);
        double damage = m->joint_damage[j], fracture = m->joint_fracture[j];
        joint_totals t = {0};
        double fa[JOINT_FACE_VALUES];
        int live = one(m, j, &t, fa);
        memcpy(m->joint_slip + (size_t)D * (size_t)j, slip, sizeof(joint_slip) * (size_t)D);
        m->joint_damage[j] = damage;
        m->joint_fracture[j] = fracture;
        m->joint_broke[j] = 0;
        if (!live) continue;
        energy += t.stored;
        if (ra && rb) continue;
        /* face A takes +fa, face B -fa */
        const int32_t *n = joint_face(m, j, ra ? 1 : 0);
        const double sign = ra ? -1.0 : 1.0;
        for (int c = 0; c < D; c++)
            for (int d = 0; d < D; d++) f[(size_t)D * (size_t)n[c] + (size_t)d] += sign * fa[D * c + d];
    }
    return energy;
}

/* Joints with an inactive element hold nothing: JOINT_DAMAGE_EXCAVATED
 * above the damage they had (model.h), which the joint loops skip as they
 * skip a broken joint, and which output shows as that damage. */
static void joints_on_removed_let_go(fdem_model *m)
{
    for (int j = 0; j < m->joint_count; j++)
        if (m->joint_damage[j] < 1.0 && joint_is_excavated(m, j))
            m->joint_damage[j] += JOINT_DAMAGE_EXCAVATED;
}

/* rho V / K of every active element to each of its nodes, in element
 * order as finalize lumps them (so with every element active, the same
 * bits); a node no active element holds gets no mass, no inverse mass and
 * is frozen. */
static void lump_active_masses(fdem_model *m)
{
    const int K = m->elem_nodes;
    memset(m->mass, 0, sizeof(double) * (size_t)m->node_count);
    for (int e = 0; e < m->elem_count; e++) {
        if (!element_is_active(m, e)) continue;
        double share = m->materials[element_material(m, e)].def.density * element_size0(m, e) / K;
        const int32_t *n = m->elem_node + (size_t)K * (size_t)e;
        for (int c = 0; c < K; c++) m->mass[n[c]] += share;
    }
    for (int i = 0; i < m->node_count; i++) {
        int frozen = !(m->mass[i] > 0);
        if (m->node_frozen) m->node_frozen[i] = (uint8_t)frozen;
        m->inv_mass[i] = frozen ? 0 : 1.0 / m->mass[i];
    }
}

/* Which elements are active (from the stages started), and what follows
 * from it alone: masses, frozen nodes, the in-situ stress's energy at
 * t = 0 of the elements left. 0, or -1 out of memory. */
int excavation_refresh(fdem_model *m)
{
    int any = 0;
    for (int k = 0; k < m->stages_started; k++) any |= m->stages[k].excavate_count > 0;
    if (!any && !m->elem_active) return 0;
    if (!any) { /* a checkpoint from before the first excavation: all back, as finalize left it */
        free(m->elem_active);
        free(m->node_frozen);
        m->elem_active = m->node_frozen = NULL;
        lump_active_masses(m);
        if (m->elem_stress0) m->stress0_energy = initial_stress_energy(m);
        return 0;
    }
    if (!m->elem_active) {
        m->elem_active = malloc((size_t)m->elem_count);
        m->node_frozen = calloc((size_t)m->node_count, 1);
        if (!m->elem_active || !m->node_frozen) return -1;
    }
    memset(m->elem_active, 1, (size_t)m->elem_count);
    for (int k = 0; k < m->stages_started; k++)
        for (int i = 0; i < m->stages[k].excavate_count; i++)
            m->elem_active[m->stages[k].excavate[i]] = 0;
    lump_active_masses(m);
    if (m->elem_stress0) m->stress0_energy = initial_stress_energy(m);
    return 0;
}

/* The unloading forces on nodes that stay (f at every node not frozen
 * whose force is not zero) as stage k's ramp. */
static int ramp_from(fdem_model *m, int k, const double *f)
{
    const int D = m->dim;
    run_stage *s = &m->stages[k];
    int count = 0;
    for (int i = 0; i < m->node_count; i++) {
        if (m->node_frozen[i]) continue;
        int nonzero = 0;
        for (int d = 0; d < D; d++) nonzero |= f[(size_t)D * (size_t)i + (size_t)d] != 0;
        count += nonzero;
    }
    s->ramp_count = 0;
    if (!count) return 0;
    s->ramp_node = malloc(sizeof(int32_t) * (size_t)count);
    s->ramp_force = malloc(sizeof(double) * (size_t)D * (size_t)count);
    if (!s->ramp_node || !s->ramp_force) return -1;
    for (int i = 0; i < m->node_count; i++) {
        if (m->node_frozen[i]) continue;
        const double *fi = f + (size_t)D * (size_t)i;
        int nonzero = 0;
        for (int d = 0; d < D; d++) nonzero |= fi[d] != 0;
        if (!nonzero) continue;
        s->ramp_node[s->ramp_count] = i;
        memcpy(s->ramp_force + (size_t)D * (size_t)s->ramp_count, fi, sizeof(double) * (size_t)D);
        s->ramp_count++;
    }
    return 0;
}

/* The weight of the mass that left a node that stays (old - new, times
 * this step's gravity) is part of what the removed elements put on it:
 * added to f, it is released with the rest. */
static void removed_weight(const fdem_model *m, const double *old_mass, double *f)
{
    const int D = m->dim;
    for (int i = 0; i < m->node_count; i++) {
        double gone = old_mass[i] - m->mass[i];
        if (gone == 0 || m->node_frozen[i]) continue;
        for (int d = 0; d < D; d++) f[(size_t)D * (size_t)i + (size_t)d] += gone * m->gravity[d];
    }
}

/* The mass that left each node (old - new) takes its kinetic energy
 * (returned) and the work gravity did on it so far (energy.c); frozen
 * nodes stop. */
static double mass_left(fdem_model *m, const double *old_mass)
{
    const int D = m->dim;
    double kinetic = 0;
    for (int i = 0; i < m->node_count; i++) {
        double gone = old_mass[i] - m->mass[i];
        if (gone == 0) continue;
        double *v = m->vel + (size_t)D * (size_t)i, v2 = 0;
        for (int d = 0; d < D; d++) v2 += v[d] * v[d];
        kinetic += 0.5 * gone * v2;
    }
    energy_mass_removed(m, old_mass);
    for (int i = 0; i < m->node_count; i++) {
        if (!m->node_frozen[i]) continue;
        for (int d = 0; d < D; d++) {
            m->vel[(size_t)D * (size_t)i + (size_t)d] = 0;
            m->force[(size_t)D * (size_t)i + (size_t)d] = 0;
        }
    }
    return kinetic;
}

/* Stage k's excavation at the start of the step (stages.c): unloading
 * forces, energies, then the elements go. 0, or -1 (err filled). */
int excavation_start(fdem_model *m, int k, fdem_error *err)
{
    const run_stage *s = &m->stages[k];
    if (!s->excavate_count) return 0;
    const size_t N = (size_t)m->node_count, D = (size_t)m->dim;
    uint8_t *removed = calloc((size_t)m->elem_count, 1);
    double *f = calloc(D * N, sizeof(double));
    double *old_mass = malloc(sizeof(double) * N);
    int count = 0;
    if (removed && f && old_mass) {
        for (int i = 0; i < s->excavate_count; i++) {
            int e = s->excavate[i];
            if (!element_is_active(m, e)) continue; /* an earlier stage took it */
            removed[e] = 1;
            count++;
        }
    }
    int failed = !removed || !f || !old_mass;
    double energy = 0;
    if (!failed && count) failed = removed_element_forces(m, removed, count, f, &energy);
    if (!failed && count) {
        energy += removed_joint_forces(m, removed, f);
        if (m->contact.enabled && contact_excavation_forces(m, removed, f)) failed = 1;
        if (m->contact.enabled) { /* the pairs' penalty energy leaves the contact account */
            double held = contact_excavation_energy(m, removed);
            energy += held;
            m->contact_work += held;
        }
        memcpy(old_mass, m->mass, sizeof(double) * N);
        double locked = m->elem_stress0 ? m->stress0_energy : 0;
        /* stages_started counts stage k from here: refresh sees its list */
        m->stages_started++;
        failed |= excavation_refresh(m);
        m->stages_started--;
        if (!failed) {
            removed_weight(m, old_mass, f);
            if (m->elem_stress0) energy += locked - m->stress0_energy;
            energy += mass_left(m, old_mass);
            joints_on_removed_let_go(m);
            m->fragments = joint_fragment_count(m); /* the pieces left */
            m->contact.need_detect = m->contact.enabled;
            m->excavated_energy += energy;
            failed = ramp_from(m, k, f);
        }
    }
    free(removed);
    free(f);
    free(old_mass);
    if (failed) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory excavating stage %d at step %lld", k,
                    (long long)m->step + 1);
        return -1;
    }
    return 0;
}
