/*
 * element.c - the element stage of a model of either dimension: preparing
 * each element, its stable step, the forces of every element through the
 * scatter plan (so the sum at every node is formed in one order on any
 * thread count) and the damping account, the stress for output.
 *
 * The work per element is its dimension's kernel: element_tri.c for
 * triangles, element_tet_model.c for tetrahedra. What the two share (the
 * walk, the sums, how damping is booked) lives here, once.
 */
#include <string.h>

#include "model/model.h"
#include "element.h"

int element_prepare(fdem_model *m, int e, fdem_error *err)
{
    if (m->dim == 3) return tet_element_prepare(m, e, err);
    tri_element_prepare(m, e);
    return 0;
}

double element_stable_dt(const fdem_model *m, int e)
{
    double dt = m->dim == 3 ? tet_element_stable_dt(m, e) : tri_element_stable_dt(m, e);
    return dt * initial_stress_dt_factor(m, e);
}

scatter_block_fn element_forces_loop_of(const fdem_model *m, const part *p)
{
    if (m->dim == 3) return p->stressed ? tet_element_forces_range_stressed : tet_element_forces_range;
    return p->stressed ? tri_element_forces_range_stressed : tri_element_forces_range;
}

/* A block part run by part run (elements of a part are contiguous): each
 * run through its part's loop (element_forces_loop_of), a fixed part whose
 * forces are kept (fixed_part.c) not at all, so a model without in-situ
 * stress or fixed parts pays nothing for them. */
static void forces_by_part_runs(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    const int kept = fixed_parts_kept(m);
    for (int e = begin; e < end;) {
        const part *p = &m->parts[m->elem_part[e]];
        int stop = p->elem_begin + p->elem_count < end ? p->elem_begin + p->elem_count : end;
        if (!(kept && p->fixed)) element_forces_loop_of(m, p)(m, e, stop, sums);
        e = stop;
    }
}

/* With excavated elements (elem_active): the runs of active elements of
 * a block, each as forces_by_part_runs does a block; the excavated ones
 * are skipped (step/excavation.c). Only such models take this path. */
static void forces_of_active_runs(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    const uint8_t *active = m->elem_active;
    for (int e = begin; e < end;) {
        if (!active[e]) {
            e++;
            continue;
        }
        int stop = e + 1;
        while (stop < end && active[stop]) stop++;
        forces_by_part_runs(m, e, stop, sums);
        e = stop;
    }
}

/* The loop a block of this model runs: the one function per model kind
 * that every path below ends in. */
static scatter_block_fn element_forces_loop(const fdem_model *m)
{
    return m->elem_active                        ? forces_of_active_runs
           : m->elem_stress0 || fixed_parts_kept(m) ? forces_by_part_runs
           : m->dim == 3                         ? tet_element_forces_range
                                                 : tri_element_forces_range;
}

/* A step shared between processes (step_share, model/model.h): the runs of
 * the elements this process computes, each as its model's loop runs a
 * block. A block whose elements are all marked is one run, the block
 * exactly as one process runs it (its sums too); the sums of a block
 * partly marked are another process's to give (step_share.block_sums). */
static void forces_of_marked_runs(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    scatter_marked_runs(m, m->share->elem_mark, begin, end, element_forces_loop(m), sums);
}

/* Runs the element blocks through the model's scatter plan (threads side
 * by side within a colour). A block hands back the strain energy (sums[0])
 * and the power of the viscous stresses with the velocities before this
 * step (sums[1]) and of the last step's viscous stresses with the same
 * velocities (sums[2]); the elastic energy adds what the fixed parts'
 * elements hold (fixed_part.c) and what an in-situ stress held at t = 0
 * (initial_stress.c); damping is booked with the step-averaged velocity
 * like every work: this step's first half and the last step's second half
 * (energy.c). */
void element_forces(fdem_model *m)
{
    double sums[SCATTER_SUMS] = {0};
    const int kept = fixed_parts_kept(m);
    scatter_block_fn run = m->share && m->share->elem_mark ? forces_of_marked_runs
                                                           : element_forces_loop(m);
    scatter_plan_run(&m->elem_plan, m, m->threads, run, sums);
    double elastic = kept ? sums[0] + fixed_parts_forces(m) : sums[0];
    m->elastic_energy = m->elem_stress0 ? elastic + m->stress0_energy : elastic;
    m->damping_work -= 0.5 * (m->dt_prev + m->dt) * 0.5 * sums[1] + 0.5 * m->havg_last * sums[2];
}

/* An excavated element carries no stress. */
void element_stress_one(const fdem_model *m, int e, double *out)
{
    if (!element_is_active(m, e)) {
        memset(out, 0, sizeof(double) * (size_t)model_stress_comps(m));
        return;
    }
    if (m->dim == 3) tet_element_stress(m, e, out);
    else tri_element_stress(m, e, out);
}

int element_of_node(const fdem_model *m, int node)
{
    const int K = m->elem_nodes;
    for (int e = 0; e < m->elem_count; e++)
        for (int c = 0; c < K; c++)
            if (m->elem_node[(size_t)K * (size_t)e + (size_t)c] == node) return e;
    return -1;
}
