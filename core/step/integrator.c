/*
 * integrator.c - the central difference scheme of seed eqs 5.9-5.11 and the
 * order of one step: forces (elements, contact, gravity, applied), then the
 * explicit update of every free degree of freedom, then the prescribed ones.
 *
 *   v_next = v_current + a_current (h_current + h_next) / 2
 *   x_next = x_current + v_next h_next,        a = f / m
 *
 * Velocities live at half steps. h_current is the previous step size (0
 * before the first step, which makes the first update the usual half-step
 * start), so the step size may change from one step to the next.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "model/model.h"
#include "math/quad.h"
#include "step.h"
#include "contact/contact.h"
#include "element/element.h"
#include "fluid/fluid.h"
#include "joint/joint.h"
#include "parallel/scatter_plan.h"
#include "parallel/team.h"

/* The central difference update of nodes [begin, end), for every dof no
 * constraint owns, in D = 2 or 3 components (a constant at each call, so
 * the component loop unrolls). sums[0] gets a sum of the new positions and
 * velocities: non-finite if and only if some value is (cheaper than a test
 * per value in the hot loop); it is accumulated as one add per node, so
 * that its dependency chain does not pace the loop. sums[1] gets the work
 * of the contact forces (times 2 / havg). With contact on (with_contact)
 * sums[SCATTER_MAX] gets the largest squared step of a node, new minus old
 * position as computed (contact_travel_step makes a bound of it); with
 * candidate pairs (with_force: some contact force may be non-zero, and the
 * near list is in use) sums[SCATTER_MAX + 1] the largest squared
 * displacement since the near list was built (contact.c). Both flags are
 * constants at each call below, so the compiler emits each loop without
 * the loads and branches it does not need. A node with no prescribed dof
 * (nearly all) takes the branch-free path. */
static inline __attribute__((always_inline)) void
central_difference_node(double *x, double *v, const double *f, const double *fc,
                        const double *xn, double inv_mass, const double *g, double h,
                        double havg, unsigned own, const int D, int with_contact,
                        int with_force, double *check, double *work_sum, double *move2,
                        double *near2)
{
    double pos_sum = 0, vel_sum = 0, work = 0, s2 = 0, n2 = 0;
#pragma GCC unroll 3
    for (int d = 0; d < D; d++) {
        double fd = f[d], v_old = v[d];
        if (with_force) fd += fc[d];
        double vd = v_old, p_old = x[d], pd = p_old;
        if (!(own & (1u << d))) {
            vd += (fd * inv_mass + g[d]) * havg;
            pd += vd * h;
            v[d] = vd;
            x[d] = pd;
            /* f . (v_old + v_new)/2 * havg is exactly what a force adds
             * to the half-step kinetic energy, so the balance closes
             * (constrained dofs: constraint_enforce). */
            if (with_force) work += fc[d] * (v_old + vd);
        }
        pos_sum += pd;
        vel_sum += vd;
        if (with_contact) {
            double s = pd - p_old;
            s2 += s * s;
        }
        if (with_force) {
            double w = pd - xn[d];
            n2 += w * w;
        }
    }
    *check += pos_sum + vel_sum;
    if (with_force) *work_sum += work;
    if (with_contact && s2 > *move2) *move2 = s2;
    if (with_force && n2 > *near2) *near2 = n2;
}

/* The same update for a node with no prescribed dof (nearly every node),
 * x and y side by side in one 16-byte vector, z alone: per component the
 * operations of central_difference_node in its order, so the same bits;
 * the contact work and the near-list distance are added in its order too
 * (they are results), the finiteness check and the step bound in any. */
typedef double cd_pair __attribute__((vector_size(16)));

static inline __attribute__((always_inline)) void
central_difference_free_node(double *x, double *v, const double *f, const double *fc,
                             const double *xn, double inv_mass, cd_pair gxy, double gz,
                             double h, double havg, const int D, int with_contact,
                             int with_force, cd_pair *check, double *check_z, double *work_sum,
                             double *move2, double *near2)
{
    cd_pair fxy, vxy, xxy;
    memcpy(&fxy, f, sizeof fxy);
    memcpy(&vxy, v, sizeof vxy);
    memcpy(&xxy, x, sizeof xxy);
    cd_pair cxy = {0, 0};
    if (with_force) {
        memcpy(&cxy, fc, sizeof cxy);
        fxy += cxy;
    }
    cd_pair vn = vxy + (fxy * inv_mass + gxy) * havg;
    cd_pair pn = xxy + vn * h;
    memcpy(v, &vn, sizeof vn);
    memcpy(x, &pn, sizeof pn);
    *check += pn + vn;
    double vz = 0, pz = 0, z_old = 0, vz_old = 0;
    if (D == 3) {
        double fz = f[2];
        if (with_force) fz += fc[2];
        vz_old = v[2];
        z_old = x[2];
        vz = vz_old + (fz * inv_mass + gz) * havg;
        pz = z_old + vz * h;
        v[2] = vz;
        x[2] = pz;
        *check_z += pz + vz;
    }
    if (with_force) {
        cd_pair wv = cxy * (vxy + vn);
        double work = 0.0 + wv[0];
        work += wv[1];
        if (D == 3) work += fc[2] * (vz_old + vz);
        *work_sum += work;
    }
    if (with_contact) {
        cd_pair s = pn - xxy;
        s *= s;
        double s2 = s[0] + s[1];
        if (D == 3) s2 += (pz - z_old) * (pz - z_old);
        if (s2 > *move2) *move2 = s2;
    }
    if (with_force) {
        cd_pair w;
        memcpy(&w, xn, sizeof w);
        w = pn - w;
        w *= w;
        double n2 = w[0] + w[1];
        if (D == 3) n2 += (pz - xn[2]) * (pz - xn[2]);
        if (n2 > *near2) *near2 = n2;
    }
}

#if FDEM_QUADS
#include <immintrin.h>
#pragma GCC push_options
#pragma GCC target("avx2")

/* The free update of four consecutive 3D nodes with no prescribed dof and
 * no contact force, their twelve numbers as three vectors (x0 y0 z0 x1,
 * y1 z1 x2 y2, z2 x3 y3 z3), the inverse masses and gravity laid out
 * alike: per number the operations of central_difference_free_node in its
 * order (AVX2 without FMA rounds as the baseline does), so the same bits;
 * each node's squared step is summed (x + y) + z as there. */
static inline __attribute__((always_inline)) void
central_difference_quad(double *x, double *v, const double *f, const double *inv_mass,
                        const fdem_quad g[3], double h, double havg, const int with_contact,
                        fdem_quad *check, double *move2)
{
    fdem_quad xo[3], vn[3], pn[3];
    const fdem_quad im = (fdem_quad)_mm256_loadu_pd(inv_mass);
    const fdem_quad ims[3] = {__builtin_shuffle(im, (fdem_quad_mask){0, 0, 0, 1}),
                            __builtin_shuffle(im, (fdem_quad_mask){1, 1, 2, 2}),
                            __builtin_shuffle(im, (fdem_quad_mask){2, 3, 3, 3})};
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) {
        fdem_quad fk = (fdem_quad)_mm256_loadu_pd(f + 4 * k), vk = (fdem_quad)_mm256_loadu_pd(v + 4 * k);
        xo[k] = (fdem_quad)_mm256_loadu_pd(x + 4 * k);
        vn[k] = vk + (fk * ims[k] + g[k]) * havg;
        pn[k] = xo[k] + vn[k] * h;
        _mm256_storeu_pd(v + 4 * k, (__m256d)vn[k]);
        _mm256_storeu_pd(x + 4 * k, (__m256d)pn[k]);
        *check += pn[k] + vn[k];
    }
    if (!with_contact) return;
    fdem_quad q[3];
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) {
        q[k] = pn[k] - xo[k];
        q[k] *= q[k];
    }
    /* the squares by component: sx = q0[0] q0[3] q1[2] q2[1], sy, sz */
    fdem_quad a = __builtin_shuffle(q[0], q[1], (fdem_quad_mask){0, 3, 6, 1});
    fdem_quad b = __builtin_shuffle(q[0], q[1], (fdem_quad_mask){1, 4, 7, 2});
    fdem_quad sx = __builtin_shuffle(a, q[2], (fdem_quad_mask){0, 1, 2, 5});
    fdem_quad sy = __builtin_shuffle(b, q[2], (fdem_quad_mask){0, 1, 2, 6});
    fdem_quad sz = __builtin_shuffle(__builtin_shuffle(q[0], q[1], (fdem_quad_mask){2, 5, 0, 0}),
                                   q[2], (fdem_quad_mask){0, 1, 4, 7});
    fdem_quad s2 = (sx + sy) + sz;
#pragma GCC unroll 4
    for (int l = 0; l < 4; l++)
        if (s2[l] > *move2) *move2 = s2[l];
}

/* Nodes from `begin` on, four at a time while none of the four has a
 * prescribed dof and four remain before `end`; returns the first node not
 * done. A call of its own (per run of such nodes), so that the baseline
 * loop holds no AVX code. */
static int central_difference_quads(fdem_model *m, int begin, int end, int with_contact,
                                    double *check, double *move2)
{
    const double h = m->dt, havg = 0.5 * (m->dt_prev + m->dt);
    const double *g = m->gravity, *f = m->force, *inv_mass = m->inv_mass;
    const fdem_quad gq[3] = {{g[0], g[1], g[2], g[0]}, {g[1], g[2], g[0], g[1]},
                           {g[2], g[0], g[1], g[2]}};
    double *x = m->pos, *v = m->vel;
    const uint8_t *owned = m->dof_owned;
    fdem_quad sum = {0, 0, 0, 0};
    double most = *move2; /* in a register, not re-read past the stores */
    int i = begin;
    for (; end - i >= 4; i += 4) {
        uint32_t own4;
        memcpy(&own4, owned + i, sizeof own4);
        if (own4) break;
        const size_t at = 3 * (size_t)i;
        if (with_contact)
            central_difference_quad(x + at, v + at, f + at, inv_mass + i, gq, h, havg, 1, &sum,
                                    &most);
        else
            central_difference_quad(x + at, v + at, f + at, inv_mass + i, gq, h, havg, 0, &sum,
                                    &most);
    }
    *check += (sum[0] + sum[1]) + (sum[2] + sum[3]);
    *move2 = most;
    return i;
}
#pragma GCC pop_options
#endif

static inline __attribute__((always_inline)) void
central_difference_pass(fdem_model *m, int begin, int end, const int D, int with_contact,
                        int with_force, double sums[SCATTER_SUMS])
{
    const double h = m->dt, havg = 0.5 * (m->dt_prev + m->dt);
    const double *g = m->gravity;
    double *x = m->pos, *v = m->vel;
    const double *f = m->force, *inv_mass = m->inv_mass;
    const uint8_t *owned = m->dof_owned;
    const double *fc = m->contact.force, *xn = m->contact.pos_near;
    const cd_pair gxy = {g[0], g[1]};
    const double gz = D == 3 ? g[2] : 0;
    cd_pair check_xy = {0, 0};
    double check = 0, move2 = 0, near2 = 0, contact_work = 0;
#if FDEM_QUADS
    const int quads = D == 3 && !with_force && __builtin_cpu_supports("avx2");
#endif
    for (int i = begin; i < end; i++) {
#if FDEM_QUADS
        if (quads && end - i >= 4) {
            int stop = central_difference_quads(m, i, end, with_contact, &check, &move2);
            if (stop > i) {
                i = stop - 1;
                continue;
            }
        }
#endif
        const size_t at = (size_t)D * (size_t)i;
        unsigned own = owned[i];
        if (own == 0)
            central_difference_free_node(x + at, v + at, f + at, with_force ? fc + at : NULL,
                                         with_force ? xn + at : NULL, inv_mass[i], gxy, gz, h,
                                         havg, D, with_contact, with_force, &check_xy, &check,
                                         &contact_work, &move2, &near2);
        else
            central_difference_node(x + at, v + at, f + at, with_force ? fc + at : NULL,
                                    with_force ? xn + at : NULL, inv_mass[i], g, h, havg, own, D,
                                    with_contact, with_force, &check, &contact_work, &move2,
                                    &near2);
    }
    sums[0] += check + check_xy[0] + check_xy[1];
    sums[1] += contact_work;
    if (move2 > sums[SCATTER_MAX]) sums[SCATTER_MAX] = move2;
    if (near2 > sums[SCATTER_MAX + 1]) sums[SCATTER_MAX + 1] = near2;
}

#define CENTRAL_DIFFERENCE_PASSES(D)                                                              \
    static void central_difference_nodes_##D(fdem_model *m, int begin, int end,                  \
                                             double sums[SCATTER_SUMS])                           \
    {                                                                                             \
        central_difference_pass(m, begin, end, D, 0, 0, sums);                                    \
    }                                                                                             \
    static void central_difference_tracked_##D(fdem_model *m, int begin, int end,                \
                                               double sums[SCATTER_SUMS])                         \
    {                                                                                             \
        central_difference_pass(m, begin, end, D, 1, 0, sums);                                    \
    }                                                                                             \
    static void central_difference_contact_##D(fdem_model *m, int begin, int end,                \
                                               double sums[SCATTER_SUMS])                         \
    {                                                                                             \
        central_difference_pass(m, begin, end, D, 1, 1, sums);                                    \
    }
CENTRAL_DIFFERENCE_PASSES(2)
CENTRAL_DIFFERENCE_PASSES(3)

/* The update a block of this model's nodes runs. */
static scatter_block_fn central_difference_pass_of(const fdem_model *m)
{
    const int three = m->dim == 3;
    return !m->contact.enabled
               ? (three ? central_difference_nodes_3 : central_difference_nodes_2)
           : m->contact.force_is_zero
               ? (three ? central_difference_tracked_3 : central_difference_tracked_2)
               : (three ? central_difference_contact_3 : central_difference_contact_2);
}

/* A step shared between processes that split the update (step_share.
 * node_mark): the runs of the nodes this process updates, each as a block
 * runs them. The sums serve this process's finiteness check; the driver
 * splits the update only where no other of them is read (no contact). */
static void central_difference_marked_runs(fdem_model *m, int begin, int end,
                                           double sums[SCATTER_SUMS])
{
    scatter_marked_runs(m, m->share->node_mark, begin, end, central_difference_pass_of(m), sums);
}

/* Advances every free dof by m->dt (h_next) after a step of m->dt_prev
 * (h_current). Returns -1 if some new value is not finite. */
int central_difference_step(fdem_model *m)
{
    double havg = 0.5 * (m->dt_prev + m->dt);
    double sums[SCATTER_SUMS] = {0};
    sums[SCATTER_MAX + 1] = m->contact.near_disp2;
    scatter_block_fn pass = m->share && m->share->node_mark ? central_difference_marked_runs
                                                            : central_difference_pass_of(m);
    scatter_plan_run(&m->node_plan, m, m->threads, pass, sums);
    if (m->contact.enabled) contact_travel_step(m, sums[SCATTER_MAX]);
    m->contact.near_disp2 = sums[SCATTER_MAX + 1];
    m->contact_work += sums[1] * 0.5 * havg;
    return isfinite(sums[0]) ? 0 : -1;
}

fdem_stage_times fdem_get_stage_times(const fdem_model *m) { return m->times; }

/* The most stressed element (the first whose stress is not finite, else
 * the largest stress component) and its first node; -1 without elements. */
static int element_most_stressed(const fdem_model *m, int *node)
{
    double s[6], most = -1;
    const int comps = model_stress_comps(m);
    int found = -1;
    for (int e = 0; e < m->elem_count && most < INFINITY; e++) {
        element_stress_one(m, e, s);
        for (int q = 0; q < comps; q++) {
            double size = isfinite(s[q]) ? fabs(s[q]) : INFINITY;
            if (size > most) most = size, found = e;
        }
    }
    if (found >= 0) *node = m->elem_node[(size_t)m->elem_nodes * (size_t)found];
    return found;
}

/* The node with the largest position or velocity component. */
static int node_farthest(const fdem_model *m, double *x_out, double *v_out)
{
    const size_t D = (size_t)m->dim;
    int found = 0;
    double most = -1;
    for (int i = 0; i < m->node_count; i++)
        for (size_t d = 0; d < D; d++) {
            double size = fmax(fabs(m->pos[D * (size_t)i + d]), fabs(m->vel[D * (size_t)i + d]));
            if (size > most) most = size, found = i;
        }
    double x = 0, v = 0;
    for (size_t d = 0; d < D; d++) {
        x = fmax(x, fabs(m->pos[D * (size_t)found + d]));
        v = fmax(v, fabs(m->vel[D * (size_t)found + d]));
    }
    *x_out = x, *v_out = v;
    return found;
}

/* Says where the step failed: at the first node whose state is not finite;
 * when every node is finite, either the elastic energy overflowed (the most
 * stressed element) or positions and velocities grew past what their sums
 * can hold in double precision (the farthest node). */
static void report_non_finite(fdem_model *m, double h, fdem_error *err)
{
    int node = -1;
    const size_t D = (size_t)m->dim;
    const long long step = (long long)m->step + 1;
    for (int i = 0; i < m->node_count && node < 0; i++)
        for (size_t d = 0; d < D; d++)
            if (!isfinite(m->pos[D * (size_t)i + d]) || !isfinite(m->vel[D * (size_t)i + d]))
                node = i;
    if (node >= 0 || !isfinite(m->elastic_energy)) {
        int elem = node >= 0 ? element_of_node(m, node) : element_most_stressed(m, &node);
        model_error(err, elem >= 0 ? FDEM_ITEM_ELEMENT : FDEM_ITEM_NONE, elem,
                    "the solution became non-finite at step %lld (t = %.6g s) in element %d "
                    "(node %d) with dt = %.6g s; the stable step is %.6g s: reduce time.safety "
                    "or check the material stiffness, penalty and applied loads",
                    step, m->time + h, elem, node, h, m->stable_dt);
        return;
    }
    double x, v;
    node = node_farthest(m, &x, &v);
    int elem = element_of_node(m, node);
    model_error(err, elem >= 0 ? FDEM_ITEM_ELEMENT : FDEM_ITEM_NONE, elem,
                "the solution grew past what double precision can carry at step %lld "
                "(t = %.6g s): node %d of element %d is %.3g m out and moves at %.3g m/s; check "
                "the coordinates, initial velocities and applied loads",
                step, m->time + h, node, elem, x, v);
}

/* Nodes past which the force array is zeroed on the step's threads: below
 * it a team costs more than the memset (as CONTACT_THREADED_NODES). */
#define FORCES_THREADED_NODES 8192

/* force[D from, D to) zeroed, on the step's threads when there are many
 * (parallel_zero). */
static void forces_zero(fdem_model *m, size_t from, size_t to)
{
    const int threads = m->threads > 1 && to - from > FORCES_THREADED_NODES ? m->threads : 1;
    parallel_zero(m->force + (size_t)m->dim * from, (size_t)m->dim * (to - from), threads);
}

/* Zeroes the force of every node the element pass adds to; the nodes of
 * parts whose elements store their forces (model_part_stores_forces) are
 * left as they are, the pass overwrites them. Parts hold consecutive
 * nodes, so this is a memset per run of such parts. */
static void forces_clear(fdem_model *m)
{
    const size_t D = (size_t)m->dim;
    if (m->share && m->share->node_mark) { /* only the nodes this process updates */
        int stop, N = m->node_count;
        for (int i = share_next_run(m->share->node_mark, 0, N, &stop); i < N;
             i = share_next_run(m->share->node_mark, stop, N, &stop))
            memset(m->force + D * (size_t)i, 0, sizeof(double) * D * (size_t)(stop - i));
        return;
    }
    int from = 0; /* the first node not zeroed yet */
    for (int k = 0; k < m->part_count; k++) {
        const part *p = &m->parts[k];
        if (!model_part_stores_forces(m, p)) continue;
        if (p->node_begin > from) forces_zero(m, (size_t)from, (size_t)p->node_begin);
        from = p->node_begin + p->node_count;
    }
    if (m->node_count > from) forces_zero(m, (size_t)from, (size_t)m->node_count);
}

int fdem_step(fdem_model *m, fdem_error *err)
{
    if (!m->finalized) {
        model_error(err, FDEM_ITEM_NONE, -1, "the model is not finalized");
        return -1;
    }
    double h = m->dt, havg = 0.5 * (m->dt_prev + h);
    double t0 = stage_clock();
    if (m->stage_count && stages_advance(m, err)) return -1;
    constraint_set_time(m, m->time + 0.5 * h);
    forces_clear(m);
    element_forces(m);
    double tj = stage_clock();
    m->times.elements += tj - t0;
    if (m->joint_count) {
        int broke = joint_forces(m);
        if (broke < 0) {
            model_error(err, FDEM_ITEM_NONE, -1, "out of memory recording fracture events at "
                        "step %lld", (long long)m->step + 1);
            return -1;
        }
        if (broke) {
            m->broken_joints += broke;
            m->fragments = joint_fragment_count(m);
            contact_detect_after_breaks(&m->contact); /* the freed faces must meet */
        }
    }
    if (m->fluid) fluid_step(m, h);
    double t1 = stage_clock();
    m->times.joints += t1 - tj;
    if (contact_forces(m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory in contact detection at step %lld",
                    (long long)m->step + 1);
        return -1;
    }
    if (m->share && m->share->forces_done && m->share->forces_done(m->share->ctx, m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "exchanging the forces between processes failed "
                    "at step %lld", (long long)m->step + 1);
        return -1;
    }
    double t2 = stage_clock();
    constraint_apply_forces(m);
    boundary_load_apply(m);
    if (m->stages_started) stages_ramp_apply(m);
    int bad = central_difference_step(m);
    if (m->share && m->share->update_done) bad = m->share->update_done(m->share->ctx, m, bad);
    constraint_enforce(m, h, havg);
    if (m->stages_started) stages_ramp_account(m, havg);
    boundary_load_account(m, havg);
    energy_gravity_step(m, havg);
    m->times.integration += stage_clock() - t2;
    m->times.contact += t2 - t1; /* detection time is moved out in contact_forces */
    if (bad || !isfinite(m->elastic_energy)) {
        report_non_finite(m, h, err);
        return -1;
    }
    if (m->step == 0) m->first_dt = h;
    m->dt_prev = h;
    m->havg_last = havg;
    m->restored_energy_valid = 0;
    double carry;
    m->time = model_time_after(m, h, &carry);
    m->time_carry = carry;
    m->step++;
    return 0;
}
