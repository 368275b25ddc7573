/*
 * fluid_flow.c - one step of the fluid in the fractures, both dimensions
 * (the geometry of a face is the dimension's kernel: fluid_face_2d.c,
 * fluid_face_3d.c).
 *
 * Order within a mechanical step of h, on the positions x_n:
 *  1. the work of the last step's fluid forces is completed with the
 *     velocities it produced (F . (v_old + v_new)/2 havg, as every force's
 *     work is booked, energy.c);
 *  2. each open cavity is measured: hydraulic aperture a = max(opening,
 *     aperture0), volume V = a |S|, pressure p = K_f (V_fluid / V - 1), not
 *     below its floor; p S / dim goes to each node of face B and its
 *     negative to each node of face A; a bore (fluid_bore.c) is measured
 *     on its wall and presses on it;
 *  3. the fluid moves over h at fixed V: between open neighbours i, j the
 *     cubic law q = c (phi_i - phi_j), c = (w / l) a_m^3 / (12 mu), a_m
 *     the mean of their apertures, phi = p - rho_f g . x the potential
 *     (so a hydrostatic pore pressure is at rest), and the sources add
 *     their share of Q(t). Explicit (forward Euler) in the volumes, with
 *     the pressures updated after every subcycle; the subcycle is the
 *     flow's stable step min V_i / (K_f sum_j c_ij) (Gershgorin's bound
 *     for the pressures' equations), h cut into as many equal pieces as
 *     it takes. Each subcycle books the viscous dissipation q (phi_i -
 *     phi_j) dt >= 0.
 * Fluid volumes change only by flow between two cavities (equal and
 * opposite) and by the sources: the network keeps the injected volume to
 * round-off.
 */
#include <math.h>
#include <string.h>

#include "model/model.h"
#include "joint/joint.h"
#include "fluid.h"

static double face_size(const fluid_face *face)
{
    return sqrt(face->area[0] * face->area[0] + face->area[1] * face->area[1] +
                face->area[2] * face->area[2]);
}

/* Sum over open joints of F . (sum of B's velocities - sum of A's), and
 * the bores' walls' F . v. */
static double fluid_power(const fdem_model *m)
{
    const fluid_net *f = m->fluid;
    const int D = m->dim;
    double power = 0;
    for (int k = 0; k < f->open_count; k++) {
        const int j = f->open_list[k];
        if (j >= f->joints) break; /* the bores, listed last */
        const int32_t *n = m->joint_node + 2 * (size_t)D * (size_t)j;
        const double *F = f->force + (size_t)D * (size_t)j;
        double p = 0;
        for (int i = 0; i < D; i++)
            for (int d = 0; d < D; d++)
                p += F[d] * (m->vel[(size_t)D * n[D + i] + d] - m->vel[(size_t)D * n[i] + d]);
        power += p;
    }
    return f->bores ? power + fluid_bores_power(m, f) : power;
}

/* Step 2 without the forces: open flags, apertures, volumes, pressures;
 * the area vectors (times p / dim) in force. */
static void cavities_measure(fdem_model *m, int with_forces)
{
    fluid_net *f = m->fluid;
    const int D = m->dim;
    f->open_count = 0;
    for (int j = 0; j < f->joints; j++) {
        int open = (f->wet[j] || m->joint_damage[j] > 0) &&
                   !(m->elem_active && joint_is_excavated(m, j));
        f->open[j] = (uint8_t)open;
        double *F = f->force + (size_t)D * (size_t)j;
        if (!open) {
            f->pressure[j] = 0;
            continue;
        }
        f->open_list[f->open_count++] = j;
        fluid_face face;
        fluid_face_of(m, j, &face);
        f->aperture[j] = fmax(face.opening, f->aperture0[j]);
        f->volume[j] = f->aperture[j] * face_size(&face);
        if (!(f->volume[j] > 0)) f->volume[j] = f->aperture[j] * 1e-300; /* a degenerate face */
        double p = fluid_cavity_pressure(f, j);
        f->pressure[j] = p;
        if (!with_forces) continue;
        for (int d = 0; d < D; d++) F[d] = p * face.area[d] / D;
        const int32_t *n = m->joint_node + 2 * (size_t)D * (size_t)j;
        for (int i = 0; i < D; i++)
            for (int d = 0; d < D; d++) {
                m->force[(size_t)D * n[i] + d] -= F[d];
                m->force[(size_t)D * n[D + i] + d] += F[d];
            }
    }
    for (int b = 0; b < f->bores; b++) fluid_bore_measure(m, f, b, with_forces);
}

/* The links between two open cavities (each once, from its first end, in
 * the order of the open list), their conductances, and the flow's stable
 * step. */
static void links_conduct(fluid_net *f)
{
    const double inv = 1.0 / (12 * f->viscosity);
    f->active_count = 0;
    for (int k = 0; k < f->open_count; k++) f->outgoing[f->open_list[k]] = 0;
    for (int k = 0; k < f->open_count; k++) {
        const int i = f->open_list[k];
        for (int32_t e = f->link_begin[i]; e < f->link_begin[i + 1]; e++) {
            const int l = f->link_of[e];
            const fluid_link *link = &f->links[l];
            if (link->a != i || !f->open[link->b]) continue;
            /* a < b: only b can be a bore, which is no constriction */
            double a = link->b >= f->joints ? f->aperture[link->a]
                                            : 0.5 * (f->aperture[link->a] + f->aperture[link->b]);
            double c = link->geometry * a * a * a * inv;
            f->conductance[l] = c;
            f->outgoing[link->a] += c;
            f->outgoing[link->b] += c;
            f->active[f->active_count++] = l;
        }
    }
    double step = INFINITY;
    for (int k = 0; k < f->open_count; k++) {
        const int j = f->open_list[k];
        if (f->outgoing[j] > 0) step = fmin(step, f->volume[j] / (f->bulk_modulus * f->outgoing[j]));
    }
    f->flow_step = step;
}

/* The potential difference phi_a - phi_b of link k. */
static inline double link_drop(const fdem_model *m, const fluid_net *f, const fluid_link *k,
                               int gravity)
{
    double drop = f->pressure[k->a] - f->pressure[k->b];
    if (gravity) {
        const int D = m->dim;
        double g = 0;
        for (int d = 0; d < D; d++)
            g += m->gravity[d] * (f->centre[D * k->a + d] - f->centre[D * k->b + d]);
        drop -= f->density * g;
    }
    return drop;
}

/* One subcycle of dt: sources, flow, the pressures after it. */
static void flow_subcycle(fdem_model *m, fluid_net *f, double dt, int gravity)
{
    for (int k = 0; k < f->open_count; k++) f->inflow[f->open_list[k]] = 0;
    for (int s = 0; s < f->source_count; s++) {
        const constraint *c = &m->constraints[f->source_constraint[s]];
        if (!f->open[f->source_joint[s]]) continue; /* excavated: no cavity to feed */
        double v = c->value_now[0] * f->source_share[s] * dt;
        f->inflow[f->source_joint[s]] += v;
        f->injected += v;
        f->constraint_injected[f->source_constraint[s]] += v;
    }
    for (int a = 0; a < f->active_count; a++) {
        const int l = f->active[a];
        double c = f->conductance[l];
        const fluid_link *k = &f->links[l];
        double drop = link_drop(m, f, k, gravity), q = c * drop * dt;
        f->inflow[k->a] -= q;
        f->inflow[k->b] += q;
        f->dissipation += q * drop;
    }
    for (int k = 0; k < f->open_count; k++) {
        const int j = f->open_list[k];
        f->fluid[j] += f->inflow[j];
        f->pressure[j] = fluid_cavity_pressure(f, j);
    }
}

void fluid_step(fdem_model *m, double h)
{
    fluid_net *f = m->fluid;
    f->work_booked += 0.5 * m->havg_last * (f->power_old + fluid_power(m));
    cavities_measure(m, 1);
    f->power_old = fluid_power(m);
    links_conduct(f);
    int n = 1;
    if (f->flow_step < h) {
        double pieces = ceil(h / f->flow_step);
        n = pieces < 1e9 ? (int)pieces : 1000000000;
    }
    f->subcycles = n;
    const int gravity = f->density > 0 &&
                        (m->gravity[0] != 0 || m->gravity[1] != 0 || m->gravity[2] != 0);
    const double dt = h / n;
    for (int s = 0; s < n; s++) flow_subcycle(m, f, dt, gravity);
}

void fluid_forces_at_rest(fdem_model *m) { cavities_measure(m, 1); }

void fluid_refresh(fdem_model *m)
{
    fluid_net *f = m->fluid;
    if (!f) return;
    cavities_measure(m, 0);
    links_conduct(f);
    f->subcycles = f->flow_step < m->dt ? (int)fmin(ceil(m->dt / f->flow_step), 1e9) : 1;
}

double fluid_work_completed(const fdem_model *m)
{
    const fluid_net *f = m->fluid;
    return f->work_booked + 0.5 * m->havg_last * (f->power_old + fluid_power(m));
}

double fluid_work_reported(const fdem_model *m)
{
    const fluid_net *f = m->fluid;
    return f->work_booked + 0.5 * m->havg_last * f->power_old;
}

/* ----------------------------------------------------------- the API */

int fdem_has_fluid(const fdem_model *m) { return m->fluid != NULL; }

fdem_fluid_status fdem_get_fluid(const fdem_model *m)
{
    fdem_fluid_status s = {0};
    const fluid_net *f = m->fluid;
    if (!f) return s;
    s.enabled = 1;
    s.injected_volume = f->injected;
    for (int j = 0; j < f->cavities; j++) s.stored_volume += f->fluid[j];
    double p = 0;
    for (int k = 0; k < f->source_count; k++) p += f->pressure[f->source_joint[k]];
    s.source_pressure = f->source_count ? p / f->source_count : 0;
    s.flow_step = f->flow_step;
    /* before the first step: what the step chosen now will take */
    s.subcycles = m->step == 0 && f->flow_step < m->dt ? (int)fmin(ceil(m->dt / f->flow_step), 1e9)
                                                        : f->subcycles;
    s.open_joints = f->open_count - f->bores; /* the bores are always open */
    return s;
}

void fdem_fluid_sources(const fdem_model *m, double *pressure, double *injected)
{
    const fluid_net *f = m->fluid;
    if (!f) return;
    for (int k = 0; k < m->constraint_count; k++) {
        int inject = m->constraints[k].def.kind == FDEM_CONSTRAINT_INJECT;
        pressure[k] = inject ? 0 : NAN;
        injected[k] = inject ? f->constraint_injected[k] : NAN;
    }
    /* the mean over each constraint's joints (fdem_get_fluid's, one
     * constraint at a time): sources are listed constraint by constraint */
    for (int s = 0, count = 0; s < f->source_count; s++) {
        const int k = f->source_constraint[s];
        pressure[k] += f->pressure[f->source_joint[s]];
        count++;
        if (s + 1 == f->source_count || f->source_constraint[s + 1] != k) {
            pressure[k] /= count;
            count = 0;
        }
    }
}

const double *fdem_fluid_pressure(const fdem_model *m)
{
    return m->fluid && m->fluid->joints ? m->fluid->pressure : NULL;
}

void fdem_fluid_apertures(const fdem_model *m, double *out)
{
    const fluid_net *f = m->fluid;
    for (int j = 0; j < m->joint_count; j++) {
        fluid_face face;
        fluid_face_of(m, j, &face);
        double a0 = f ? f->aperture0[j] : 0;
        out[j] = fmax(face.opening, a0);
    }
}
