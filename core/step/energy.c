/*
 * energy.c - the energy accounts of a model and their balance.
 *
 * Central difference keeps velocities at half steps (v(t - h/2), v(t + h/2))
 * and evaluates forces, elastic and joint energy at whole steps. Booking
 * each force's work with the step-averaged velocity, f (v_old + v_new)/2
 * havg, gives exactly what that force adds to 1/2 m v^2 at the half step,
 * but compared with the elastic energy U(x_n) that leaves an offset of half
 * a step, 1/2 f . v h, which for a stiff contact or a coarse bar is several
 * per cent of the energy in play. So the accounts are reported at x_n, the
 * start of the last step:
 *  - kinetic is 1/2 sum m v_old . v_new, the kinetic part of the energy the
 *    scheme conserves exactly for a linear solid (1/2 v_old M v_new +
 *    1/2 x K x), so a linear elastic model closes to round-off;
 *  - each work sum drops its last half step, 1/2 f . v_new havg, which
 *    turns the sum into the trapezoidal rule along the positions up to x_n
 *    (damping is booked that way in element.c, element by element);
 *  - gravity's work is exact: M g . (centre of mass at x_n - at x_0).
 * Friction and fracture are booked where they dissipate (contact.c,
 * joint.c). The friction of contacts is part of their work, so `contact`
 * leaves it out; the friction of intact joints (joint_friction_energy) is
 * not. What remains in `residual` is the time discretisation of the
 * non-linear forces: finite strain, the contact potential's changing
 * overlap, joint softening and sliding, and the stick springs.
 */
#include <math.h>
#include <string.h>

#include "math/amplitude.h"
#include "model/model.h"
#include "step.h"
#include "element/element.h"
#include "fluid/fluid.h"
#include "joint/joint.h"

static void total_momentum(const fdem_model *m, double p[3]);

/* Sum of m a . a over the free dofs at t = 0 for the forces in m->force
 * (and gravity): see energy_initial. */
static double initial_acceleration2(const fdem_model *m)
{
    const int D = m->dim;
    double sum = 0;
    for (int i = 0; i < m->node_count; i++)
        for (int d = 0; d < D; d++) {
            if (m->dof_owned[i] & (1u << d)) continue;
            double a = m->force[(size_t)D * (size_t)i + (size_t)d] * m->inv_mass[i] + m->gravity[d];
            sum += m->mass[i] * a * a;
        }
    return sum;
}

/* Kinetic and elastic energy at t = 0: the reference of the balance.
 * Central difference starts with half a step, v(h/2) = v0 + a0 h/2, and
 * what it conserves for a linear solid is 1/2 m v(t - h/2) . v(t + h/2) +
 * U: at t = 0 that is the kinetic energy of v0 less m a0 . a0 h^2 / 8
 * (v(-h/2) = v0 - a0 h/2). For a model that starts in equilibrium this is
 * nothing; one that starts out of it (an in-situ stress without the
 * matching boundary tractions) would otherwise carry it as a constant
 * residual from the first step on. The first step's h is only known when
 * it is taken (fdem_step records it); a model restored from a checkpoint
 * takes its current dt. The forces at t = 0 are the elements' and the
 * applied ones, pressures included, and those of joints that carry an
 * in-situ gap (joint_prestress.c; other joints hold none; bodies start
 * apart, so no contact). */
void energy_initial(fdem_model *m)
{
    double kinetic = 0;
    const size_t D = (size_t)m->dim;
    for (int i = 0; i < m->node_count; i++) {
        double v2 = 0;
        for (size_t d = 0; d < D; d++) v2 += m->vel[D * (size_t)i + d] * m->vel[D * (size_t)i + d];
        kinetic += 0.5 * m->mass[i] * v2;
    }
    memset(m->force, 0, sizeof(double) * D * (size_t)m->node_count);
    element_forces(m);
    m->joint_energy = joint_prestress_rest_forces(m);
    constraint_apply_forces(m);
    boundary_load_apply(m);
    if (m->fluid) fluid_forces_at_rest(m);
    m->initial_acceleration2 = initial_acceleration2(m);
    memset(m->force, 0, sizeof(double) * D * (size_t)m->node_count);
    if (m->elem_viscous)
        memset(m->elem_viscous, 0,
               sizeof(double) * (size_t)model_stress_comps(m) * (size_t)m->elem_count);
    m->damping_work = 0;
    m->initial_energy = kinetic + m->elastic_energy + m->joint_energy;
    if (m->gravity_amplitude) total_momentum(m, m->momentum);
}

/* Half the last step's power of the applied forces and reactions, times
 * havg: what external_work holds beyond x_n. */
static double constraints_last_half_step(const fdem_model *m)
{
    double power = 0;
    const int D = m->dim;
    for (int k = 0; k < m->constraint_count; k++) {
        const constraint *c = &m->constraints[k];
        if (c->def.kind == FDEM_CONSTRAINT_FORCE) {
            for (int e = c->entry_begin; e < c->entry_begin + c->entry_count; e++) {
                const double *v = m->vel + (size_t)D * (size_t)m->cnode[e];
                double p = 0;
                for (int d = 0; d < D; d++) p += c->value_now[d] / c->entry_count * v[d];
                power += p;
            }
        } else if (c->def.kind == FDEM_CONSTRAINT_VELOCITY) {
            for (int d = 0; d < D; d++) power += c->force[d] * c->value_now[d];
        }
    }
    power += m->ramp_power_new; /* excavations' unloading forces (stages.c) */
    return 0.5 * m->havg_last * power + boundary_load_last_half_step(m, 0);
}

/* Gravity times an amplitude is not a constant force, so its work is not
 * M g . (centre of mass displacement): it is booked every step as any
 * other force's, g . (P_old + P_new)/2 havg with P = sum m v over all nodes
 * (prescribed ones too, as for a constant gravity). Only with an
 * amplitude: the plain case keeps its exact formula. */
static void total_momentum(const fdem_model *m, double p[3])
{
    const int D = m->dim;
    p[0] = p[1] = p[2] = 0;
    for (int i = 0; i < m->node_count; i++)
        for (int d = 0; d < D; d++) p[d] += m->mass[i] * m->vel[(size_t)D * (size_t)i + (size_t)d];
}

void energy_gravity_step(fdem_model *m, double havg)
{
    if (!m->gravity_amplitude) return;
    double p[3];
    total_momentum(m, p);
    for (int d = 0; d < m->dim; d++)
        m->gravity_work_sum += m->gravity[d] * 0.5 * (m->momentum[d] + p[d]) * havg;
    memcpy(m->momentum, p, sizeof p);
}

/* Excavation took mass off the nodes (old_mass: before; m->mass: after),
 * at the start of a step, where positions are x_n. Gravity's work on that
 * mass up to now stays in the account: with a constant gravity the work is
 * M g . (x_n - x_0) over the masses left, plus what it did on the mass
 * that left (gravity_work_removed); with an amplitude the sum booked step
 * by step already holds it, and the momentum it goes on from is that of
 * the masses left. */
void energy_mass_removed(fdem_model *m, const double *old_mass)
{
    const int D = m->dim;
    if (m->gravity_amplitude) {
        total_momentum(m, m->momentum);
        return;
    }
    double work = 0;
    for (int i = 0; i < m->node_count; i++) {
        double gone = old_mass[i] - m->mass[i];
        if (gone == 0) continue;
        for (int d = 0; d < D; d++) {
            size_t k = (size_t)D * (size_t)i + (size_t)d;
            work += gone * m->gravity[d] * (m->pos[k] - m->pos0[k]);
        }
    }
    m->gravity_work_removed += work;
}

/* After a checkpoint is read: the sum that reports the stored gravity work. */
void energy_gravity_restored(fdem_model *m, double gravity_work)
{
    if (!m->gravity_amplitude) return;
    double a = amplitude_at(m->gravity_amplitude, m->gravity_amplitude_count, m->time - m->dt_prev);
    for (int d = 0; d < m->dim; d++) m->gravity[d] = m->gravity_base[d] * a;
    total_momentum(m, m->momentum);
    double half = 0;
    for (int d = 0; d < m->dim; d++) half += m->gravity[d] * m->momentum[d];
    m->gravity_work_sum = gravity_work + 0.5 * m->havg_last * half;
}

static double gravity_work_of_amplitude(const fdem_model *m)
{
    double half = 0;
    for (int d = 0; d < m->dim; d++) half += m->gravity[d] * m->momentum[d];
    return m->gravity_work_sum - 0.5 * m->havg_last * half;
}

fdem_energy fdem_get_energy(const fdem_model *m)
{
    if (m->restored_energy_valid) return m->restored_energy;
    fdem_energy en = {0};
    const double havg = m->havg_last, h = m->dt_prev;
    /* v(t - h/2) from v(t + h/2): after the first (half) step, v(-h/2) of
     * the scheme, as energy_initial takes it */
    const double back = m->step == 1 ? h : havg;
    const double h_first = m->first_dt > 0 ? m->first_dt : m->dt;
    const double initial = m->initial_energy - 0.125 * h_first * h_first * m->initial_acceleration2;
    const double *fc = m->contact.enabled && !m->contact.force_is_zero ? m->contact.force : NULL;
    double contact_power = 0, gravity_work = 0;
    const int D = m->dim;
    for (int i = 0; i < m->node_count; i++) {
        for (int d = 0; d < D; d++) {
            size_t k = (size_t)D * (size_t)i + (size_t)d;
            double v = m->vel[k], v_old = v;
            if (!(m->dof_owned[i] & (1u << d))) {
                double f = m->force[k] + (fc ? fc[k] : 0);
                v_old = v - (f * m->inv_mass[i] + m->gravity[d]) * back;
            }
            en.kinetic += 0.5 * m->mass[i] * v * v_old;
            gravity_work += m->mass[i] * m->gravity[d] * (m->pos[k] - v * h - m->pos0[k]);
            if (fc) contact_power += fc[k] * v;
        }
    }
    en.elastic = m->elastic_energy;
    en.joint = m->joint_energy;
    en.friction = m->friction_energy + m->joint_friction_energy;
    en.fracture = m->fracture_energy;
    /* b - a, not -(a - b): the same bits but for zero, which this way is
     * +0 (a model without contacts showed "contact -0") */
    en.contact = (0.5 * havg * contact_power - m->contact_work) - m->friction_energy;
    en.damping = m->damping_work + boundary_load_last_half_step(m, 1);
    en.gravity_work = m->gravity_amplitude ? gravity_work_of_amplitude(m)
                                           : gravity_work + m->gravity_work_removed;
    en.external_work = m->external_work - constraints_last_half_step(m);
    en.excavated = m->excavated_energy;
    if (m->fluid) {
        en.fluid_work = fluid_work_reported(m);
        en.fluid_dissipation = m->fluid->dissipation;
    }
    en.residual = en.kinetic + en.elastic + en.joint + en.contact + en.friction + en.fracture +
                  en.damping + en.excavated - en.gravity_work - en.external_work - initial;
    if (m->fluid) en.residual -= en.fluid_work;
    return en;
}
