/*
 * history.h - one row of history output (contract 6.2): the few numbers a
 * load-displacement curve or an energy balance needs, taken at one step
 * boundary without copying the model's arrays.
 *
 * Contract: history_take() copies (never aliases): the displacement and
 * velocity of each monitored node (`dimension` numbers per point), each
 * constraint's force (fdem_constraint_forces) and the mean displacement of
 * its nodes (`dimension` numbers per constraint), every energy account
 * (in history_energy_names order) and the step and time; with fluid
 * (contract 6.4) also each constraint's source pressure and injected
 * volume (fdem_fluid_sources: NaN for a constraint that does not inject)
 * and the fluid's two energy accounts. Its cost is
 * O(points + nodes held by constraints), never O(model). The rows of
 * GET /cases/ID/history are history_rows_json() of what result.h5 holds.
 *
 * Folder proto/state/ (see snapshot.h). May call core/. Called by
 * proto/result/ (which appends rows to /history), server/ and the tests.
 */
#ifndef FDEM_HISTORY_H
#define FDEM_HISTORY_H

#include <jansson.h>
#include <stdint.h>
#include "case/case.h"
#include "fdem.h"

/* The energy accounts of a row, by name (the status' names, contract 5.1). */
#define HISTORY_ENERGY_TERMS 11
extern const char *const history_energy_names[HISTORY_ENERGY_TERMS];
/* The fluid's accounts (contract 6.4), in rows of a model with fluid only. */
#define HISTORY_FLUID_ENERGY_TERMS 2
extern const char *const history_fluid_energy_names[HISTORY_FLUID_ENERGY_TERMS];

typedef struct history_row {
    int64_t step;
    double time;
    int dimension, points, constraints;
    double *point_displacement;      /* dimension * points */
    double *point_velocity;          /* dimension * points */
    double *constraint_force;        /* dimension * constraints */
    double *constraint_displacement; /* dimension * constraints: mean over its nodes */
    double energy[HISTORY_ENERGY_TERMS];
    int fluid;                       /* the model has fluid: the figures below are set */
    double *source_pressure;         /* constraints: of an "inject" one, else NaN */
    double *injected_volume;         /* constraints: since t = 0, of an "inject" one, else NaN */
    double fluid_energy[HISTORY_FLUID_ENERGY_TERMS];
} history_row;

/* The monitoring points' names, as /history/points stores them. */
typedef struct history_names {
    int count;
    char name[CASE_MAX_HISTORY_POINTS][CASE_HISTORY_NAME];
} history_names;

/* A row of `model` now, following the nodes `point_nodes[points]`; NULL when
 * out of memory. One allocation: free with history_free(). */
history_row *history_take(const fdem_model *model, const int32_t *point_nodes, int points);
/* An empty row with room for the given counts (its arrays zeroed); fluid
 * gives it the fluid's members. */
history_row *history_alloc(int dimension, int points, int constraints, int fluid);
void history_free(history_row *row);

/* {"names": [names->name...], "rows": [{"time", "step", "points": {"displacement",
 * "velocity"}, "constraint_force", "constraint_displacement", "energy":
 * {term: J}}]} of rows[0..count), a row with fluid also "fluid":
 * {"source_pressure": [per constraint], "injected_volume": [...]} (null for
 * a constraint that does not inject) and energy's fluid_work and
 * fluid_dissipation; NULL when out of memory. */
json_t *history_rows_json(history_row *const *rows, int count, const history_names *names);

#endif
