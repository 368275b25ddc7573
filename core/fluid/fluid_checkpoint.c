/*
 * fluid_checkpoint.c - the fluid's part of a checkpoint (version 9 on):
 * the injected volume, the fluid's work on the solid (complete through the
 * last step, and as reported at x_n), the viscous dissipation and every
 * cavity's fluid volume. Pressures, apertures and the
 * flow step follow from these and the positions (fluid_refresh).
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

size_t fluid_checkpoint_size(const fdem_model *m)
{
    if (!m->fluid) return 0;
    return sizeof(double) * (FLUID_SECTION_SCALARS + (size_t)m->fluid->joints);
}

void fluid_checkpoint_write(const fdem_model *m, unsigned char *p)
{
    const fluid_net *f = m->fluid;
    if (!f) return;
    double head[FLUID_SECTION_SCALARS] = {f->injected, fluid_work_completed(m), f->dissipation,
                                         fluid_work_reported(m)};
    memcpy(p, head, sizeof head);
    if (f->joints) memcpy(p + sizeof head, f->fluid, sizeof(double) * (size_t)f->joints);
}

void fluid_checkpoint_read(fdem_model *m, const unsigned char *p)
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
    if (f->joints) {
        memcpy(f->fluid, p + sizeof head, sizeof(double) * (size_t)f->joints);
        memset(f->force, 0, sizeof(double) * (size_t)m->dim * (size_t)f->joints);
    }
    fluid_refresh(m);
}
