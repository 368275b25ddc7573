/*
 * stages.c - the stages of a run (contract 6.1): their definitions, the
 * clock that says which stage a step belongs to, the start of each stage
 * (its excavation: excavation.c), the constraints that act during one
 * stage only, the unloading ramps of excavations with their work, and the
 * stage state a checkpoint carries.
 *
 * The clock. Stage k runs from end(k-1) (0 for the first) to end(k). A
 * step belongs to the stage of its start time t: the largest k with
 * start(k) <= t, the last stage taking every step after its end too (an
 * extended run). Stage k therefore starts at the first step whose start
 * time is >= start(k), and what it does at its start (excavation, the
 * switch of stage-only constraints) is done at the start of that step, on
 * the positions the step starts from. Steps are not cut to land on stage
 * ends: the step size is the caller's (the daemon cuts only the very last
 * step, to land on time.end), so a stage begins up to one step late, and
 * nothing depends on how the run was interrupted: time, the stage index and
 * every ramp are in the checkpoint, and the test t >= start(k) reads only
 * the step's start time, which is the same on any thread count.
 *
 * A model without stages pays one test of stage_count per step.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "step.h"

static int index_compare(const void *pa, const void *pb)
{
    int32_t a = *(const int32_t *)pa, b = *(const int32_t *)pb;
    return (a > b) - (a < b);
}

/* The start time of stage k: the end of the one before, or 0. */
static double stage_start(const fdem_model *m, int k)
{
    return k == 0 ? 0.0 : m->stages[k - 1].end;
}

/* What is wrong with a stage's numbers, or NULL. */
static const char *stage_def_problem(const fdem_model *m, const fdem_stage_def *def,
                                     double *bound)
{
    int k = m->stage_count;
    *bound = stage_start(m, k);
    if (!isfinite(def->end)) return "its end is not finite";
    if (!(def->end > *bound)) return k == 0 ? "its end is not after t = 0"
                                            : "its end is not after the end of the stage before";
    if (!isfinite(def->relax) || def->relax < 0) return "its relax is negative or not finite";
    if (def->excavate_count < 0 || (def->excavate_count > 0 && !def->excavate))
        return "its list of elements to excavate is missing";
    return NULL;
}

int fdem_add_stage(fdem_model *m, const fdem_stage_def *def, fdem_error *err)
{
    int k = m->stage_count;
    if (m->finalized) {
        model_error(err, FDEM_ITEM_NONE, -1, "stage %d: the model is already finalized", k);
        return -1;
    }
    double bound;
    const char *problem = stage_def_problem(m, def, &bound);
    if (problem) {
        model_error(err, FDEM_ITEM_NONE, -1, "stage %d: %s (end %g s, relax %g s, start %g s)", k,
                    problem, def->end, def->relax, bound);
        return -1;
    }
    for (int i = 0; i < def->excavate_count; i++)
        if (def->excavate[i] < 0 || def->excavate[i] >= m->elem_count) {
            model_error(err, FDEM_ITEM_ELEMENT, def->excavate[i],
                        "stage %d excavates element %d, which does not exist (the model has %d "
                        "elements)",
                        k, def->excavate[i], m->elem_count);
            return -1;
        }
    size_t cap = (size_t)m->stage_capacity;
    if (model_reserve((void **)&m->stages, &cap, (size_t)k + 1, sizeof *m->stages, 4)) {
        model_error(err, FDEM_ITEM_NONE, -1, "stage %d: out of memory", k);
        return -1;
    }
    m->stage_capacity = (int)cap;
    run_stage *s = &m->stages[k];
    memset(s, 0, sizeof *s);
    s->end = def->end;
    s->relax = def->relax;
    if (def->excavate_count > 0) {
        s->excavate = malloc(sizeof(int32_t) * (size_t)def->excavate_count);
        if (!s->excavate) {
            model_error(err, FDEM_ITEM_NONE, -1, "stage %d: out of memory", k);
            return -1;
        }
        memcpy(s->excavate, def->excavate, sizeof(int32_t) * (size_t)def->excavate_count);
        qsort(s->excavate, (size_t)def->excavate_count, sizeof(int32_t), index_compare);
        int n = 0;
        for (int i = 0; i < def->excavate_count; i++)
            if (n == 0 || s->excavate[i] != s->excavate[n - 1]) s->excavate[n++] = s->excavate[i];
        s->excavate_count = n;
    }
    m->stage_count++;
    return k;
}

/* At finalize: every stage-only constraint names a stage that exists. */
int stages_validate(const fdem_model *m, fdem_error *err)
{
    for (int c = 0; c < m->constraint_count; c++) {
        int only = m->constraints[c].def.only_stage;
        if (only > m->stage_count) {
            model_error(err, FDEM_ITEM_CONSTRAINT, c,
                        "constraint %d acts only during stage %d, but the model has %d stage%s", c,
                        only - 1, m->stage_count, m->stage_count == 1 ? "" : "s");
            return -1;
        }
    }
    return 0;
}

void stages_free(fdem_model *m)
{
    for (int k = 0; k < m->stage_count; k++) {
        free(m->stages[k].excavate);
        free(m->stages[k].ramp_node);
        free(m->stages[k].ramp_force);
    }
    free(m->stages);
    free(m->elem_active);
    free(m->node_frozen);
    m->stages = NULL;
    m->elem_active = m->node_frozen = NULL;
    m->stage_count = m->stage_capacity = 0;
}

int fdem_stage_index(const fdem_model *m) { return m->stage_count ? m->stage_now : -1; }

const uint8_t *fdem_element_active(const fdem_model *m) { return m->elem_active; }

/* 1 - s of stage k's ramp at time t (0 when it is over or has none). */
static double ramp_scale_at(const run_stage *s, double t)
{
    if (!s->ramp_count || !(s->relax > 0)) return 0;
    double r = (t - s->t_start) / s->relax;
    return r >= 1 ? 0 : r <= 0 ? 1 : 1 - r;
}

/* At the start of a step: starts every stage whose start time has come
 * (its excavation), sets the stage of this step and, when it changed or
 * elements left, which constraint owns which dof; then each ramp's scale
 * for this step. Returns 0, or -1 (out of memory, err filled). */
int stages_advance(fdem_model *m, fdem_error *err)
{
    int changed = 0;
    while (m->stages_started < m->stage_count &&
           m->time >= stage_start(m, m->stages_started)) {
        int k = m->stages_started;
        m->stages[k].t_start = m->time;
        if (excavation_start(m, k, err)) return -1;
        m->stages_started++;
        changed = 1;
    }
    int now = m->stages_started > 0 ? m->stages_started - 1 : 0;
    if (now != m->stage_now) {
        m->stage_now = now;
        changed = 1;
    }
    if (changed && constraint_assign_dofs(m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory starting stage %d at step %lld",
                    m->stage_now, (long long)m->step + 1);
        return -1;
    }
    for (int k = 0; k < m->stages_started; k++)
        m->stages[k].ramp_scale = ramp_scale_at(&m->stages[k], m->time);
    return 0;
}

/* The unloading forces of this step (f_exc times 1 - s) added to the
 * nodes, and their power with the velocities before the step. */
void stages_ramp_apply(fdem_model *m)
{
    const int D = m->dim;
    double power = 0;
    for (int k = 0; k < m->stages_started; k++) {
        const run_stage *s = &m->stages[k];
        if (s->ramp_scale == 0) continue;
        for (int r = 0; r < s->ramp_count; r++) {
            size_t at = (size_t)D * (size_t)s->ramp_node[r];
            for (int d = 0; d < D; d++) {
                double f = s->ramp_scale * s->ramp_force[(size_t)D * (size_t)r + (size_t)d];
                m->force[at + d] += f;
                power += f * m->vel[at + d];
            }
        }
    }
    m->ramp_power_old = power;
}

/* After the update: their work with the step-averaged velocity, as every
 * applied force's (energy.c drops the last half step). */
void stages_ramp_account(fdem_model *m, double havg)
{
    const int D = m->dim;
    double power = 0;
    for (int k = 0; k < m->stages_started; k++) {
        const run_stage *s = &m->stages[k];
        if (s->ramp_scale == 0) continue;
        for (int r = 0; r < s->ramp_count; r++) {
            size_t at = (size_t)D * (size_t)s->ramp_node[r];
            for (int d = 0; d < D; d++)
                power += s->ramp_scale * s->ramp_force[(size_t)D * (size_t)r + (size_t)d] *
                         m->vel[at + d];
        }
    }
    m->external_work += 0.5 * (m->ramp_power_old + power) * havg;
    m->ramp_power_new = power;
}

/* ------------------------------------------------------------ checkpoints */

/* The stage section (version 8, only for a model with stages): stages
 * started and the stage now (int32 each), the excavated energy and the
 * gravity work of removed mass, then per started stage its start time, its
 * ramp's node count (int32), nodes (int32) and forces (dim doubles each).
 * The rest of an excavation's state (which elements are active, the
 * masses, the frozen nodes, the in-situ stress energy left) follows from
 * the stages started and is computed again (excavation_refresh). */
size_t stages_checkpoint_size(const fdem_model *m)
{
    if (!m->stage_count) return 0;
    size_t b = 2 * sizeof(int32_t) + 2 * sizeof(double);
    for (int k = 0; k < m->stages_started; k++)
        b += sizeof(double) + sizeof(int32_t) +
             (size_t)m->stages[k].ramp_count * (sizeof(int32_t) + sizeof(double) * (size_t)m->dim);
    return b;
}

static unsigned char *put(unsigned char *p, const void *v, size_t n)
{
    if (n) memcpy(p, v, n);
    return p + n;
}

void stages_checkpoint_write(const fdem_model *m, unsigned char *p)
{
    if (!m->stage_count) return;
    int32_t started = m->stages_started, now = m->stage_now;
    p = put(p, &started, sizeof started);
    p = put(p, &now, sizeof now);
    p = put(p, &m->excavated_energy, sizeof(double));
    p = put(p, &m->gravity_work_removed, sizeof(double));
    for (int k = 0; k < m->stages_started; k++) {
        const run_stage *s = &m->stages[k];
        int32_t count = s->ramp_count;
        p = put(p, &s->t_start, sizeof(double));
        p = put(p, &count, sizeof count);
        p = put(p, s->ramp_node, sizeof(int32_t) * (size_t)count);
        p = put(p, s->ramp_force, sizeof(double) * (size_t)m->dim * (size_t)count);
    }
}

/* Reads the section at p (at most `size` bytes); sets *used to its size.
 * Returns 0, or -1 with err filled. */
int stages_checkpoint_read(fdem_model *m, const unsigned char *p, size_t size, size_t *used,
                           fdem_error *err)
{
    *used = 0;
    if (!m->stage_count) return 0;
    const unsigned char *start = p, *end = p + size;
    int32_t started, now;
    if (size < 2 * sizeof(int32_t) + 2 * sizeof(double)) goto truncated;
    memcpy(&started, p, sizeof started);
    memcpy(&now, p + sizeof started, sizeof now);
    p += 2 * sizeof(int32_t);
    if (started < 0 || started > m->stage_count || now < 0 || now >= m->stage_count) {
        model_error(err, FDEM_ITEM_NONE, -1, "checkpoint's stages do not fit this model (%d of %d "
                    "started)", (int)started, m->stage_count);
        return -1;
    }
    memcpy(&m->excavated_energy, p, sizeof(double));
    memcpy(&m->gravity_work_removed, p + sizeof(double), sizeof(double));
    p += 2 * sizeof(double);
    for (int k = 0; k < m->stage_count; k++) {
        run_stage *s = &m->stages[k];
        free(s->ramp_node);
        free(s->ramp_force);
        s->ramp_node = NULL;
        s->ramp_force = NULL;
        s->ramp_count = 0;
        s->ramp_scale = 0;
    }
    for (int k = 0; k < started; k++) {
        run_stage *s = &m->stages[k];
        int32_t count;
        if ((size_t)(end - p) < sizeof(double) + sizeof count) goto truncated;
        memcpy(&s->t_start, p, sizeof(double));
        memcpy(&count, p + sizeof(double), sizeof count);
        p += sizeof(double) + sizeof count;
        size_t bytes = (size_t)count * (sizeof(int32_t) + sizeof(double) * (size_t)m->dim);
        if (count < 0 || count > m->node_count || (size_t)(end - p) < bytes) goto truncated;
        if (count) {
            s->ramp_node = malloc(sizeof(int32_t) * (size_t)count);
            s->ramp_force = malloc(sizeof(double) * (size_t)m->dim * (size_t)count);
            if (!s->ramp_node || !s->ramp_force) {
                model_error(err, FDEM_ITEM_NONE, -1, "out of memory restoring stage %d", k);
                return -1;
            }
            memcpy(s->ramp_node, p, sizeof(int32_t) * (size_t)count);
            memcpy(s->ramp_force, p + sizeof(int32_t) * (size_t)count,
                   sizeof(double) * (size_t)m->dim * (size_t)count);
            for (int r = 0; r < count; r++)
                if (s->ramp_node[r] < 0 || s->ramp_node[r] >= m->node_count) goto truncated;
        }
        s->ramp_count = count;
        p += bytes;
    }
    m->stages_started = started;
    m->stage_now = now;
    if (excavation_refresh(m) || constraint_assign_dofs(m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory restoring the excavations");
        return -1;
    }
    *used = (size_t)(p - start);
    return 0;
truncated:
    model_error(err, FDEM_ITEM_NONE, -1, "checkpoint's stage section is damaged");
    return -1;
}
