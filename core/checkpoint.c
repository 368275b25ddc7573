/*
 * checkpoint.c - the dynamic state of a model as one flat byte buffer.
 *
 * Only what stepping changes is stored (step, time, step sizes, positions,
 * velocities, joint damage, energy accumulators): the static model is
 * rebuilt from the case document, so a checkpoint stays small and a model
 * of another shape is detected by its counts and refused.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model.h"

#define CHECKPOINT_MAGIC 0x31434446u /* "FDC1" */

typedef struct checkpoint_header {
    uint32_t magic, version;
    int32_t nodes, elements, joints, constraints;
    int64_t step;
    double time, dt, dt_prev;
    double contact_work, damping_work, external_work;
} checkpoint_header;

size_t fdem_checkpoint_size(const fdem_model *m)
{
    return sizeof(checkpoint_header) + sizeof(double) * 4 * (size_t)m->node_count +
           sizeof(double) * (size_t)m->joint_count;
}

int fdem_checkpoint_write(const fdem_model *m, void *buf, size_t size)
{
    if (size < fdem_checkpoint_size(m)) return -1;
    checkpoint_header h = {CHECKPOINT_MAGIC, 1, m->node_count, m->elem_count, m->joint_count,
                           m->constraint_count, m->step, m->time, m->dt, m->dt_prev,
                           m->contact_work, m->damping_work, m->external_work};
    unsigned char *p = buf;
    memcpy(p, &h, sizeof h);
    p += sizeof h;
    size_t nb = sizeof(double) * 2 * (size_t)m->node_count;
    memcpy(p, m->pos, nb);
    p += nb;
    memcpy(p, m->vel, nb);
    p += nb;
    if (m->joint_count) memcpy(p, m->joint_damage, sizeof(double) * (size_t)m->joint_count);
    return 0;
}

/* A damaged or hand-made header must not be restored: a negative step
 * would, for one, make the daemon drop every stored snapshot. */
static int checkpoint_header_valid(const checkpoint_header *h, fdem_error *err)
{
    const char *bad = NULL;
    if (h->step < 0) bad = "a negative step";
    else if (!isfinite(h->time) || h->time < 0) bad = "a time that is negative or not finite";
    else if (!isfinite(h->dt) || h->dt <= 0) bad = "a time step that is not positive and finite";
    else if (!isfinite(h->dt_prev) || h->dt_prev < 0) bad = "a previous time step that is negative or not finite";
    else if (!isfinite(h->contact_work) || !isfinite(h->damping_work) || !isfinite(h->external_work))
        bad = "energy totals that are not finite";
    if (!bad) return 0;
    model_error(err, FDEM_ITEM_NONE, -1,
                "checkpoint has %s (step %lld, t = %g s, dt = %g s); it is damaged",
                bad, (long long)h->step, h->time, h->dt);
    return -1;
}

int fdem_checkpoint_read(fdem_model *m, const void *buf, size_t size, fdem_error *err)
{
    checkpoint_header h;
    if (size < sizeof h) {
        model_error(err, FDEM_ITEM_NONE, -1, "checkpoint is truncated (%zu bytes)", size);
        return -1;
    }
    memcpy(&h, buf, sizeof h);
    if (h.magic != CHECKPOINT_MAGIC || h.version != 1) {
        model_error(err, FDEM_ITEM_NONE, -1, "not an fdemd checkpoint (or of another version)");
        return -1;
    }
    if (h.nodes != m->node_count || h.elements != m->elem_count || h.joints != m->joint_count ||
        h.constraints != m->constraint_count) {
        model_error(err, FDEM_ITEM_NONE, -1,
                    "checkpoint is of a model with %d nodes, %d elements, %d joints; this one has "
                    "%d, %d, %d",
                    h.nodes, h.elements, h.joints, m->node_count, m->elem_count, m->joint_count);
        return -1;
    }
    if (size != fdem_checkpoint_size(m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "checkpoint has %zu bytes, expected %zu", size,
                    fdem_checkpoint_size(m));
        return -1;
    }
    if (checkpoint_header_valid(&h, err) != 0) return -1;
    const unsigned char *p = (const unsigned char *)buf + sizeof h;
    size_t nb = sizeof(double) * 2 * (size_t)m->node_count;
    memcpy(m->pos, p, nb);
    p += nb;
    memcpy(m->vel, p, nb);
    p += nb;
    if (m->joint_count) memcpy(m->joint_damage, p, sizeof(double) * (size_t)m->joint_count);
    m->step = h.step;
    m->time = h.time;
    m->dt = h.dt;
    m->dt_prev = h.dt_prev;
    m->contact_work = h.contact_work;
    m->damping_work = h.damping_work;
    m->external_work = h.external_work;
    m->contact.need_detect = 1;
    m->broken_joints = 0;
    for (int j = 0; j < m->joint_count; j++) m->broken_joints += m->joint_damage[j] >= 1.0;
    if (m->joint_count) m->fragments = joint_fragment_count(m);
    /* Forces and elastic energy are those of the restored positions. */
    memset(m->force, 0, sizeof(double) * 2 * (size_t)m->node_count);
    element_forces(m, 0);
    memset(m->force, 0, sizeof(double) * 2 * (size_t)m->node_count);
    return 0;
}
