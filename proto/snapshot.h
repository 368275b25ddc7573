/*
 * snapshot.h - a plain copy of a model's state taken at one step boundary.
 *
 * Contract: snapshot_take() copies (never aliases) the requested fields, so
 * the copy can be handed to the I/O thread or turned into JSON while the
 * worker keeps stepping. constraint_force, energies, step and time are
 * always copied; damage only when the model has joints. Node rows and
 * constraint forces have `dimension` numbers, stress rows
 * `stress_components` (3 in 2D, 6 in 3D).
 */
#ifndef FDEM_SNAPSHOT_H
#define FDEM_SNAPSHOT_H

#include <stdint.h>
#include "fdem.h"

typedef struct snapshot {
    int64_t step;
    double time;
    unsigned fields;            /* CASE_FIELD_* actually present */
    int nodes, elements, joints, constraints;
    int dimension;              /* 2 or 3 */
    int stress_components;      /* 3 or 6 */
    double *position;           /* dimension * nodes, or NULL */
    double *velocity;           /* dimension * nodes, or NULL */
    double *stress;             /* stress_components * elements, or NULL */
    double *damage;             /* joints, or NULL */
    double *constraint_force;   /* dimension * constraints */
    fdem_energy energy;
} snapshot;

snapshot *snapshot_take(const fdem_model *model, unsigned fields);
void snapshot_free(snapshot *s);

#endif
