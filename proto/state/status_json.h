/*
 * status_json.h - the figures of a case's status object (contract 5.1):
 * what the daemon's status routes and status.json show of a run, and what
 * the batch runner (runner/run_case.c) writes to its status.json, from
 * one copy, so that the two files agree member by member.
 *
 * Contract:
 *  - status_put_figures() adds, in this order, "step", "time", "end_time",
 *    "progress", "dt", "dimension", "nodes", "elements", "joints",
 *    "broken_joints", "fragments", "contacts", "stage", "fluid",
 *    "snapshots", "energy" and "steps_per_second" to `o`; the writer of
 *    the status adds who and when (id, state, times, warnings).
 *    Non-finite numbers are written as null (JSON has none).
 *  - status_figures_from_json() reads those members back (a status.json
 *    written by the daemon or by fdem-run): what a listing shows without
 *    building the model. Missing or null numbers read as NaN (counts as 0).
 *  - "warnings" (contract 6.2): a JSON array of {"pointer", "message"},
 *    each kept once, at most STATUS_WARNINGS_MAX; status_take_penetrations()
 *    moves the engine's pairs of elements found passing into one another
 *    into it, each pair once across restarts (the message names it).
 *  - status_progress(): 1 only when finished; otherwise at most
 *    STATUS_PROGRESS_UNFINISHED_MAX, so no client prints "running 100 %".
 *
 * Folder: proto/state/ (its contract: snapshot.h).
 */
#ifndef FDEM_STATUS_JSON_H
#define FDEM_STATUS_JSON_H

#include <jansson.h>
#include <stdint.h>
#include "case/case.h"
#include "fdem.h"

#define STATUS_PROGRESS_UNFINISHED_MAX 0.999
/* A status stays small whatever a document or a run does. */
#define STATUS_WARNINGS_MAX 100

/* Figures of one step of a run (the status object's). */
typedef struct run_figures {
    int64_t step;
    double time, dt;
    fdem_counts counts;
    fdem_energy energy;
    double steps_per_second;
    int snapshots;
    double elapsed;            /* wall seconds spent stepping, all runs; < 0: keep */
    double eta;                /* wall seconds left at the recent speed; NAN: unknown */
    double cpu_share;          /* CPU seconds of the stepping thread a wall second; NAN: unknown */
    int stage;                 /* the stage the case is in (contract 6.1), -1: no stages */
    char stage_name[CASE_STAGE_NAME];
    fdem_fluid_status fluid;   /* contract 6.4; enabled 0 without fluid */
} run_figures;

/* The model's figures now (snapshots and elapsed -1: unknown here, eta NaN). */
void status_figures_of_model(run_figures *f, const fdem_model *m, const case_info *info);
/* f->stage and f->stage_name of `model`, the names from `info`. */
void status_figures_stage(run_figures *f, const fdem_model *model, const case_info *info);

double status_progress(int finished, double time, double end);
/* A running case's current speed, any other's mean over every step it took. */
double status_steps_per_second(int running, const run_figures *f);

void status_put_figures(json_t *o, const run_figures *f, double end_time, double progress,
                        double steps_per_second);
void status_figures_from_json(run_figures *f, const json_t *status);
/* The status' "stage" back into f->stage and f->stage_name (null: -1). */
void status_stage_from_json(run_figures *f, const json_t *stage);
/* The status' energy object back into an fdem_energy (missing: NaN). */
void status_energy_from_json(fdem_energy *energy, const json_t *o);
json_t *status_number_or_null(double x);
/* Appends {"pointer", "message"} to `list` unless it is there or the list is full. */
void status_warning_add(json_t *list, const char *pointer, const char *message);
/* Takes the model's penetrations (fdem_take_penetrations) into `list`. */
void status_take_penetrations(json_t *list, fdem_model *model);
/* Now as ISO 8601 UTC with milliseconds ("2026-12-06T18:00:00.123Z"): the
 * status' created, started and finished_at; sorts like time. */
void status_time_now(char *out, size_t size);

#endif
