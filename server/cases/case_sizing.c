/*
 * case_sizing.c - sizing a case before it runs (case_sizing.h).
 *
 * The counts and the step come from the model the case builder made (the
 * same build POST /cases does), the memory from the builder's own estimate
 * (proto/case/case_memory.c, priced as the daemon's budget charges it), and the
 * wall time from stepping that model for a moment on this machine: a
 * formula of element counts would be wrong on every other machine and for
 * every contact-heavy case.
 */
#include "case_sizing.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "case_model.h"

/* Stepping the model to time it stops after whichever comes first. */
#define SIZING_PROBE_SECONDS 0.05
#define SIZING_PROBE_STEPS 200

int sizing_is_last_step(double t0, double dt, double end)
{
    return t0 + dt >= end - 1e-9 * dt; /* no sliver of a step left over */
}

double sizing_steps_to_end(double t0, double end, double dt)
{
    if (!(dt > 0) || !(end > t0))
        return 0;
    /* Step k (from 0) starts at t0 + k dt and is the last one when
     * sizing_is_last_step() holds: the first k >= (end - 1e-9 dt - t0)/dt - 1. */
    double k = ceil((end - 1e-9 * dt - t0) / dt - 1.0);
    return (k > 0 ? k : 0) + 1;
}

double sizing_output_interval(const case_info *info)
{
    double interval = info->output_interval;
    if (!(interval > 0))
        interval = info->end_time / 100.0;
    return interval > 0 ? interval : 1.0;
}

/* Snapshot 0, one at the first step at or after each output time (several
 * output times inside one step give one snapshot), and the one at the end.
 * An output time after the start of the last step, which is cut to land on
 * time.end, is the end's snapshot: only those up to that start count, with
 * the worker's tolerance of 1e-9 dt. */
static double sizing_snapshots(const case_info *info, double t0, double dt, double steps)
{
    double interval = sizing_output_interval(info);
    double last_start = t0 + (steps - 1) * dt + 1e-9 * dt;
    double done_before = floor(t0 / interval * (1 + 1e-12) + 1e-9);
    double inside = floor(last_start / interval * (1 + 1e-12)) - done_before;
    if (!(inside > 0))
        inside = 0;
    if (inside > steps - 1)
        inside = steps > 1 ? steps - 1 : 0;
    return 1 + inside + (steps > 0 ? 1 : 0);
}

/* result.h5 as proto/result/result_h5.c lays it out: /mesh once, then per
 * snapshot the requested node and element fields, damage when there are
 * joints, the fragment id of every element, the constraint forces, the
 * scalar series (step, time and the energy accounts) and, with stages, the
 * stage, every element's active flag and the excavated energy. HDF5's own metadata,
 * part-filled chunks and the case document with its names come on top. */
static double sizing_result_bytes(const fdem_model *model, const case_info *info, double snapshots)
{
    fdem_counts c = fdem_get_counts(model);
    double dim = fdem_get_dimension(model);
    double stress_width = dim == 3 ? 6 : 3;
    double nodes = c.nodes, elements = c.elements, joints = c.joints;
    double mesh = nodes * (dim * 8 + 8 + 4) + elements * ((dim + 1) * 4 + 4) + joints * 2 * dim * 4;
    double row = 2 * 8 + 9 * 8 + (double)c.constraints * dim * 8 + joints * 8 + elements * 4;
    if (info->fields & CASE_FIELD_POSITION)
        row += nodes * dim * 8;
    if (info->fields & CASE_FIELD_VELOCITY)
        row += nodes * dim * 8;
    if (info->fields & CASE_FIELD_STRESS)
        row += elements * stress_width * 8;
    if (info->fields & CASE_FIELD_STRAIN)
        row += elements * stress_width * 8;
    if (info->fields & CASE_FIELD_PRINCIPAL_STRESS)
        row += elements * dim * 8;
    if (info->fields & CASE_FIELD_DISPLACEMENT)
        row += nodes * dim * 8;
    if (info->stage_count > 0) /* /snapshots/stage, active and excavated_energy */
        row += 4 + elements + 8;
    if (fdem_get_fluid(model).enabled) /* /snapshots/fluid_pressure and aperture */
        row += joints * 2 * 8;
    return mesh + snapshots * row;
}

static double sizing_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Steps per second of this model here; 0 when a step fails (the run's
 * first steps will say why). */
static double sizing_probe(fdem_model *model, double steps)
{
    double started = sizing_now(), now = started;
    int taken = 0;
    while (taken < SIZING_PROBE_STEPS && taken < steps &&
           (taken < 2 || now - started < SIZING_PROBE_SECONDS)) {
        fdem_error err;
        memset(&err, 0, sizeof err);
        if (fdem_step(model, &err) != 0)
            break;
        taken++;
        now = sizing_now();
    }
    return taken > 0 && now > started ? taken / (now - started) : 0.0;
}

void case_sizing_measure(fdem_model *model, const case_info *info, double model_bytes,
                         int threads, double snapshot_seconds, case_sizing *out)
{
    memset(out, 0, sizeof *out);
    fdem_counts c = fdem_get_counts(model);
    out->nodes = c.nodes;
    out->elements = c.elements;
    out->joints = c.joints;
    out->dt = fdem_get_dt(model);
    out->steps = sizing_steps_to_end(fdem_get_time(model), info->end_time, out->dt);
    out->snapshots = sizing_snapshots(info, fdem_get_time(model), out->dt, out->steps);
    out->memory_bytes = (double)case_model_cost(model_bytes);
    out->result_bytes = sizing_result_bytes(model, info, out->snapshots);
    fdem_fluid_status fluid = fdem_get_fluid(model);
    out->fluid = fluid.enabled;
    out->fluid_step = fluid.flow_step;
    out->fluid_subcycles = fluid.subcycles;
    fdem_set_threads(model, threads);
    out->steps_per_second = sizing_probe(model, out->steps);
    /* Snapshots are written on the I/O thread while the worker steps on:
     * the slower of the two sets the pace. */
    double stepping = out->steps_per_second > 0 ? out->steps / out->steps_per_second : NAN;
    double writing = out->snapshots * snapshot_seconds;
    out->estimated_seconds = writing > stepping ? writing : stepping;
}

/* "3.2 hours", "5.1 days" */
static void sizing_describe_duration(double seconds, char *out, size_t size)
{
    if (seconds < 2 * 86400.0)
        snprintf(out, size, "%.1f hours", seconds / 3600.0);
    else if (seconds < 730 * 86400.0)
        snprintf(out, size, "%.1f days", seconds / 86400.0);
    else
        snprintf(out, size, "%.3g years", seconds / (365.25 * 86400.0));
}

int case_sizing_warning(const case_sizing *s, char *out, size_t size)
{
    out[0] = '\0';
    if (!(s->estimated_seconds >= SIZING_WARN_SECONDS))
        return 0;
    char duration[48];
    sizing_describe_duration(s->estimated_seconds, duration, sizeof duration);
    snprintf(out, size, "this case will run for about %s: %.4g steps of %.3g s at about %.3g steps "
             "per second (measured on its model here); POST /cases?dry_run=true sizes a case "
             "without storing it", duration, s->steps, s->dt, s->steps_per_second);
    return 1;
}

/* Counts above 2^53 are no longer exact integers: they go out as numbers. */
static json_t *sizing_count_json(double n)
{
    return n < 9007199254740992.0 ? json_integer((json_int_t)n) : json_real(n);
}

static json_t *sizing_number_json(double x)
{
    return isfinite(x) ? json_real(x) : json_null();
}

json_t *case_sizing_json(const case_sizing *s)
{
    json_t *o = json_object();
    json_object_set_new(o, "nodes", json_integer(s->nodes));
    json_object_set_new(o, "elements", json_integer(s->elements));
    json_object_set_new(o, "joints", json_integer(s->joints));
    json_object_set_new(o, "dt", sizing_number_json(s->dt));
    json_object_set_new(o, "steps", sizing_count_json(s->steps));
    json_object_set_new(o, "snapshots", sizing_count_json(s->snapshots));
    json_object_set_new(o, "memory_bytes", sizing_count_json(s->memory_bytes));
    json_object_set_new(o, "result_bytes", sizing_count_json(ceil(s->result_bytes)));
    json_object_set_new(o, "estimated_seconds", sizing_number_json(s->estimated_seconds));
    if (s->fluid) { /* the flow's step: null while no fluid can flow yet */
        json_object_set_new(o, "fluid_step", sizing_number_json(s->fluid_step));
        json_object_set_new(o, "fluid_subcycles", json_integer(s->fluid_subcycles));
    }
    char warning[400];
    if (case_sizing_warning(s, warning, sizeof warning))
        json_object_set_new(o, "warning", json_string(warning));
    return o;
}
