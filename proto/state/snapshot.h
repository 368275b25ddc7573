/*
 * snapshot.h - a plain copy of a model's state taken at one step boundary.
 *
 * Contract: snapshot_take() copies (never aliases) the requested fields, so
 * the copy can be handed to the I/O thread or turned into JSON while the
 * worker keeps stepping. constraint_force, energies, step and time are
 * always copied; damage only when the model has joints. Node rows and
 * constraint forces have `dimension` numbers, stress rows
 * `stress_components` (3 in 2D, 6 in 3D), and so do strain rows;
 * principal_stress rows have `dimension` numbers, and so do displacement
 * rows (one per node: position - initial position, computed at the copy).
 * The fragment id of every element is always copied (result.h5 stores it
 * with every snapshot, contract 5.4); the fragment records are computed only
 * when SNAPSHOT_FRAGMENTS is in `fields` (GET /cases/ID/fragments).
 * A model with stages (contract 6.1) always has its stage index and the
 * active flag of every element copied (result.h5 stores both with every
 * snapshot of such a case); a model without them gets stage -1 and no
 * flags, and costs nothing more.
 *
 * Folder proto/state/, a model's state on its way out of the engine: owns
 * this header (the copy, snapshot.c) and the JSON of GET /cases/ID/state
 * (state_json.h) and /cases/ID/events (events_json.h), the status
 * figures (status_json.h) and the steps outputs fall on (output_grid.h).
 * May call core/ and proto/case/ (the CASE_FIELD_* bits and case_info of
 * case.h). Called by proto/result/ (which writes snapshots), server/,
 * runner/ and the unit tests.
 */
#ifndef FDEM_SNAPSHOT_H
#define FDEM_SNAPSHOT_H

#include <stdint.h>
#include "fdem.h"

/* Not a case field (no name parses to it): asks snapshot_take for the
 * fragment records as well. */
#define SNAPSHOT_FRAGMENTS (1u << 16)

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
    double *strain;             /* stress_components * elements, or NULL */
    double *principal_stress;   /* dimension * elements, or NULL */
    double *displacement;       /* dimension * nodes (position - position0), or NULL */
    int32_t *fragment;          /* fragment id per element (always) */
    fdem_fragment *fragments;   /* fragment_count records, with SNAPSHOT_FRAGMENTS */
    int fragment_count;
    double *constraint_force;   /* dimension * constraints */
    fdem_energy energy;
    int stage;                  /* the stage the model is in, -1: the case has no stages */
    uint8_t *active;            /* with stages: elements flags, 1 active, 0 excavated; else NULL */
    double *fluid_pressure;     /* with fluid (contract 6.4): per joint; else NULL */
    double *aperture;           /* with fluid: hydraulic aperture per joint; else NULL */
} snapshot;

snapshot *snapshot_take(const fdem_model *model, unsigned fields);
void snapshot_free(snapshot *s);

#endif
