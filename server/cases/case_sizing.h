/*
 * case_sizing.h - how long and how large a case will be before it runs:
 * POST /cases?dry_run=true, and the warning in the 201 of a case that will
 * run for hours (contract 5.4).
 *
 * Contract:
 *  - sizing_steps_to_end() counts steps under output_is_last_step()
 *    (proto/state/output_grid.h), the rule of the one step cut to land on
 *    time.end, so a dry run's `steps` is the number the run then takes;
 *    the snapshots are counted on output_snapshot_interval() likewise.
 *  - case_sizing_measure() sizes a model just built from a case document
 *    (model_bytes: the builder's own estimate, see case_model_build_upload):
 *    counts, dt, steps, snapshots, memory charged while it runs, result.h5
 *    bytes, and a wall time: the slower of stepping and writing the
 *    snapshots (snapshot_seconds each, see io_snapshot_seconds). Stepping
 *    is priced from the model's own steps timed here (sizing_probe.h: a
 *    warm-up, then the median of short windows) at t = 0 and at three points up to 30 %
 *    into the run when that is quickly reached; for a fracturing model,
 *    on a crack cut inside the model (fdem_break_joints_near, on the
 *    axis plane that crosses the most joints, the half of its joints
 *    nearest their centre): 3 % of its joints (or more,
 *    at the rate its own steps broke them) each breaking once, at the
 *    cost of a mending of the contact list (timed before the cut and on
 *    it, interpolated to the joints held broken), and half of them held broken through the whole run, each
 *    at half the cost a joint of the crack, priced open, adds to a step
 *    (SIZING_OPEN_CRACK_SHARE; the crack's figures as multiples of an intact step
 *    timed just before the cut, at the run's pace); plus the worker's
 *    copy of each snapshot and its checkpoint. Steps are timed in CPU seconds and turned into
 *    wall seconds by the machine's load (sizing_probe.h). It ADVANCES and CRACKS the model:
 *    call it only on a model that is thrown away.
 */
#ifndef FDEMD_CASE_SIZING_H
#define FDEMD_CASE_SIZING_H

#include <jansson.h>
#include <stdint.h>

#include "case/case.h"
#include "state/output_grid.h"
#include "fdem.h"

/* A case whose estimated run is at least this long gets a warning. */
#define SIZING_WARN_SECONDS 3600.0

typedef struct case_sizing {
    int nodes, elements, joints;
    double dt;
    double steps;             /* a double: absurd end times do not overflow */
    double snapshots;
    double memory_bytes, result_bytes;
    double steps_per_second;  /* the mean pace the estimate assumes */
    double step_seconds;      /* CPU seconds a step, measured on the model as built */
    double later_step_seconds; /* the same up to 30 % into the run (NAN: not timed) */
    double load_factor;       /* wall / CPU seconds the run will see (sizing_load_factor) */
    double probe_wall_over_cpu; /* the same, as the probe's own windows saw it */
    double adjacent_step_seconds; /* the same just before the cut (what the crack's are taken against) */
    double cracked_step_seconds; /* the same with a crack cut inside its joints, priced
                                    open (fdem_price_cracks_open); NAN: none */
    int cracked_joints;       /* joints the crack broke */
    double broken_joints;     /* joints priced as broken through the run */
    int broken_seen;          /* joints the probe's own steps broke (before its crack) */
    double breaks;            /* joints priced as breaking during the run */
    double intact_detection_seconds; /* CPU seconds of a detection before the crack (NAN: none) */
    double break_detection_seconds; /* the same on the crack (NAN: none) */
    double snapshot_copy_seconds; /* the worker's share of one snapshot */
    double estimated_seconds;
    int fluid;                /* the case has fluid (contract 6.4): then fluid_step and */
    double fluid_step;        /* fluid_subcycles, the flow's stable step and how many */
    int fluid_subcycles;      /* flow steps a mechanical step takes, at t = 0 */
} case_sizing;

double sizing_steps_to_end(double t0, double end, double dt);

void case_sizing_measure(fdem_model *model, const case_info *info, double model_bytes,
                         int threads, double snapshot_seconds, case_sizing *out);
/* The dry run's answer: {"nodes", "elements", "joints", "dt", "steps",
 * "snapshots", "memory_bytes", "result_bytes", "estimated_seconds"} (and
 * "warning" for a long run; "fluid_step" and "fluid_subcycles" for a case
 * with fluid). */
json_t *case_sizing_json(const case_sizing *s);
/* "this case will run for about 5.2 hours (...)" into out, or "" when it
 * is not long; returns whether there is a warning. */
int case_sizing_warning(const case_sizing *s, char *out, size_t size);

#endif
