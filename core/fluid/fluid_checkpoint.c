/*
 * fluid_checkpoint.c - the fluid's part of a checkpoint (version 9 on):
 * the injected volume, the fluid's work on the solid (complete through the
 * last step, and as reported at x_n), the viscous dissipation and every
 * cavity's fluid volume; from version 10 each constraint's injected volume
 * (the history series); from version 11 each bore's fluid volume after
 * the joints' (fluid_bore.c; older files had no bores, so their layout is
 * version 11's without bores). Pressures, apertures and the
 * flow step follow from these and the positions (fluid_refresh).
 *
 * A version 9 file kept only the total: restored, it goes to the one
 * injection there is, or is shared evenly among several (documented).
 *
 * The work is stored complete through the last step (its forces' work with
 * the velocities they produced: fluid_work_completed), and the restored
 * model starts with no forces pending, so the first step after a restart
 * books nothing more for the step before: the same sum, to the bit, as the
 * run that wrote it.
 */
#include <string.h>

#include "model/model.h"
#include "fluid.h"

#define FLUID_SECTION_SCALARS 4

/* The cavities whose fluid a file of `version` holds: the joints, and
 * from version 11 the bores. */
static int stored_cavities(const fdem_model *m, unsigned version)
{
    return version >= 11 ? m->fluid->cavities : m->fluid->joints;
}

size_t fluid_checkpoint_size(const fdem_model *m, unsigned version)
{
    if (!m->fluid) return 0;
    size_t per_constraint = version >= 10 ? (size_t)m->constraint_count : 0;
    return sizeof(double) * (FLUID_SECTION_SCALARS + (size_t)stored_cavities(m, version) +
                             per_constraint);
}

/* A version 9 file's total, shared among the injections. */
static void injected_from_total(fdem_model *m, double total)
{
    int injections = 0;
    for (int k = 0; k < m->constraint_count; k++)
        injections += m->constraints[k].def.kind == FDEM_CONSTRAINT_INJECT;
    for (int k = 0; k < m->constraint_count; k++)
        m->fluid->constraint_injected[k] =
            m->constraints[k].def.kind == FDEM_CONSTRAINT_INJECT ? total / injections : 0;
}

void fluid_checkpoint_write(const fdem_model *m, unsigned char *p)
{
    const fluid_net *f = m->fluid;
    if (!f) return;
    double head[FLUID_SECTION_SCALARS] = {f->injected, fluid_work_completed(m), f->dissipation,
                                         fluid_work_reported(m)};
    memcpy(p, head, sizeof head);
    p += sizeof head;
    if (f->cavities) memcpy(p, f->fluid, sizeof(double) * (size_t)f->cavities);
    p += sizeof(double) * (size_t)f->cavities;
    if (m->constraint_count)
        memcpy(p, f->constraint_injected, sizeof(double) * (size_t)m->constraint_count);
}

void fluid_checkpoint_read(fdem_model *m, const unsigned char *p, unsigned version)
{
    fluid_net *f = m->fluid;
    if (!f) return;
    double head[FLUID_SECTION_SCALARS];
    memcpy(head, p, sizeof head);
    f->injected = head[0];
    f->work_booked = head[1];
    f->dissipation = head[2];
    f->restored_work = head[3];
    f->power_old = 0;
    p += sizeof head;
    const size_t stored = (size_t)stored_cavities(m, version);
    if (stored) memcpy(f->fluid, p, sizeof(double) * stored);
    if (f->joints) memset(f->force, 0, sizeof(double) * (size_t)m->dim * (size_t)f->joints);
    if (f->bores) memset(f->wall_force, 0, sizeof(double) * (size_t)m->dim * (size_t)m->bfacet_count);
    p += sizeof(double) * stored;
    if (version >= 10 && m->constraint_count)
        memcpy(f->constraint_injected, p, sizeof(double) * (size_t)m->constraint_count);
    else if (version < 10)
        injected_from_total(m, f->injected);
    fluid_refresh(m);
}
