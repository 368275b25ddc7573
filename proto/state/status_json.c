/*
 * status_json.c - a run's figures as the members of its status object and
 * back (status_json.h). One copy for the daemon's status routes and
 * status.json and for fdem-run's status.json: a listing of either reads
 * the same members.
 */
#include "status_json.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

json_t *status_number_or_null(double x)
{
    return isfinite(x) ? json_real(x) : json_null();
}

void status_figures_stage(run_figures *f, const fdem_model *model, const case_info *info)
{
    f->stage = fdem_stage_index(model);
    const char *name = case_stage_name(info, f->stage);
    snprintf(f->stage_name, sizeof f->stage_name, "%s", name ? name : "");
}

void status_figures_of_model(run_figures *f, const fdem_model *m, const case_info *info)
{
    memset(f, 0, sizeof *f);
    f->step = fdem_get_step(m);
    f->time = fdem_get_time(m);
    f->dt = fdem_get_dt(m);
    f->counts = fdem_get_counts(m);
    f->energy = fdem_get_energy(m);
    f->fluid = fdem_get_fluid(m);
    f->snapshots = -1;
    f->elapsed = -1;
    f->eta = NAN;
    f->cpu_share = NAN;
    status_figures_stage(f, m, info);
}

double status_progress(int finished, double time, double end)
{
    if (finished)
        return 1.0;
    double progress = end > 0 ? time / end : 0.0;
    if (!(progress >= 0))
        progress = 0;
    return progress > STATUS_PROGRESS_UNFINISHED_MAX ? STATUS_PROGRESS_UNFINISHED_MAX : progress;
}

double status_steps_per_second(int running, const run_figures *f)
{
    if (running)
        return f->steps_per_second;
    return f->elapsed > 0 ? (double)f->step / f->elapsed : 0.0;
}

/* The status' energy object, member by member (contract 5.1). */
static const struct { const char *key; size_t offset; } energy_accounts[] = {
    {"kinetic", offsetof(fdem_energy, kinetic)}, {"elastic", offsetof(fdem_energy, elastic)},
    {"joint", offsetof(fdem_energy, joint)}, {"contact", offsetof(fdem_energy, contact)},
    {"friction", offsetof(fdem_energy, friction)}, {"fracture", offsetof(fdem_energy, fracture)},
    {"damping", offsetof(fdem_energy, damping)},
    {"gravity_work", offsetof(fdem_energy, gravity_work)},
    {"external_work", offsetof(fdem_energy, external_work)},
    {"excavated", offsetof(fdem_energy, excavated)},
    {"residual", offsetof(fdem_energy, residual)},
};
#define ENERGY_ACCOUNT_COUNT (sizeof energy_accounts / sizeof energy_accounts[0])

void status_energy_from_json(fdem_energy *energy, const json_t *o)
{
    for (size_t i = 0; i < ENERGY_ACCOUNT_COUNT; i++) {
        const json_t *v = json_object_get(o, energy_accounts[i].key);
        /* a status.json from before stages has no "excavated": nothing was */
        double missing = strcmp(energy_accounts[i].key, "excavated") == 0 && o && !v ? 0.0 : NAN;
        *(double *)((char *)energy + energy_accounts[i].offset) =
            json_is_number(v) ? json_number_value(v) : missing;
    }
}

static json_t *status_energy_json(const run_figures *f)
{
    json_t *energy = json_object();
    if (!energy)
        return NULL;
    for (size_t i = 0; i < ENERGY_ACCOUNT_COUNT; i++)
        json_object_set_new(energy, energy_accounts[i].key,
                            status_number_or_null(*(const double *)((const char *)&f->energy +
                                                                    energy_accounts[i].offset)));
    if (f->fluid.enabled) {
        json_object_set_new(energy, "fluid_work", status_number_or_null(f->energy.fluid_work));
        json_object_set_new(energy, "fluid_dissipation",
                            status_number_or_null(f->energy.fluid_dissipation));
    }
    return energy;
}

/* "stage": {"index", "name"} of a case with stages (contract 6.1), null
 * without them. Written to status.json too: a case loaded from it shows
 * its last stage without a model (status_stage_from_json). */
static json_t *status_stage_json(const run_figures *f)
{
    if (f->stage < 0) return json_null();
    json_t *o = json_object();
    if (!o) return NULL;
    json_object_set_new(o, "index", json_integer(f->stage));
    json_object_set_new(o, "name", json_string(f->stage_name));
    return o;
}

void status_stage_from_json(run_figures *f, const json_t *stage)
{
    const json_t *given = json_object_get(stage, "index");
    json_int_t index = json_integer_value(given);
    const char *name = json_string_value(json_object_get(stage, "name"));
    f->stage = json_is_integer(given) && index >= 0 && index < CASE_MAX_STAGES ? (int)index : -1;
    snprintf(f->stage_name, sizeof f->stage_name, "%s", f->stage >= 0 && name ? name : "");
}

/* "fluid" (contract 6.4): null without fluid; the flow's step and subcycle
 * count beside the contract's three (docs/api.md). */
/* The fluid's figures that are numbers, written and read back by the same
 * table (as the energy accounts are). */
static const struct { const char *key; size_t offset; } fluid_figures[] = {
    {"injected_volume", offsetof(fdem_fluid_status, injected_volume)},
    {"stored_volume", offsetof(fdem_fluid_status, stored_volume)},
    {"source_pressure", offsetof(fdem_fluid_status, source_pressure)},
    {"fluid_step", offsetof(fdem_fluid_status, flow_step)},
};
#define FLUID_FIGURE_COUNT (sizeof fluid_figures / sizeof fluid_figures[0])

static json_t *status_fluid_json(const fdem_fluid_status *f)
{
    if (!f->enabled) return json_null();
    json_t *o = json_object();
    if (!o) return NULL;
    for (size_t i = 0; i < FLUID_FIGURE_COUNT; i++)
        json_object_set_new(o, fluid_figures[i].key,
                            status_number_or_null(*(const double *)((const char *)f +
                                                                    fluid_figures[i].offset)));
    json_object_set_new(o, "fluid_subcycles", json_integer(f->subcycles));
    json_object_set_new(o, "open_joints", json_integer(f->open_joints));
    return o;
}

/* Read back by status_figures_from_json: a case loaded from status.json
 * shows its fluid (and writes it again) without a model. */
static void status_fluid_from_json(run_figures *f, const json_t *fluid, const json_t *energy)
{
    memset(&f->fluid, 0, sizeof f->fluid);
    if (!json_is_object(fluid)) return;
    f->fluid.enabled = 1;
    for (size_t i = 0; i < FLUID_FIGURE_COUNT; i++) {
        const json_t *v = json_object_get(fluid, fluid_figures[i].key);
        *(double *)((char *)&f->fluid + fluid_figures[i].offset) =
            json_is_number(v) ? json_number_value(v) : NAN;
    }
    f->fluid.subcycles = (int)json_integer_value(json_object_get(fluid, "fluid_subcycles"));
    f->fluid.open_joints = (int)json_integer_value(json_object_get(fluid, "open_joints"));
    const json_t *work = json_object_get(energy, "fluid_work");
    const json_t *dissipation = json_object_get(energy, "fluid_dissipation");
    f->energy.fluid_work = json_is_number(work) ? json_number_value(work) : NAN;
    f->energy.fluid_dissipation =
        json_is_number(dissipation) ? json_number_value(dissipation) : NAN;
}

void status_put_figures(json_t *o, const run_figures *f, double end_time, double progress,
                        double steps_per_second)
{
    json_object_set_new(o, "step", json_integer((json_int_t)f->step));
    json_object_set_new(o, "time", status_number_or_null(f->time));
    json_object_set_new(o, "end_time", status_number_or_null(end_time));
    json_object_set_new(o, "progress", status_number_or_null(progress));
    json_object_set_new(o, "dt", status_number_or_null(f->dt));
    json_object_set_new(o, "dimension", json_integer(f->counts.dimension ? f->counts.dimension : 2));
    json_object_set_new(o, "nodes", json_integer(f->counts.nodes));
    json_object_set_new(o, "elements", json_integer(f->counts.elements));
    json_object_set_new(o, "joints", json_integer(f->counts.joints));
    json_object_set_new(o, "broken_joints", json_integer(f->counts.broken_joints));
    json_object_set_new(o, "fragments", json_integer(f->counts.fragments));
    json_object_set_new(o, "contacts", json_integer(f->counts.contacts));
    json_object_set_new(o, "stage", status_stage_json(f));
    json_object_set_new(o, "fluid", status_fluid_json(&f->fluid));
    json_object_set_new(o, "snapshots", json_integer(f->snapshots));
    json_t *energy = status_energy_json(f);
    json_object_set_new(o, "energy", energy ? energy : json_null());
    json_object_set_new(o, "steps_per_second", status_number_or_null(steps_per_second));
}

/* A number of status.json; null (a non-finite figure) reads as NaN. */
static double status_number(const json_t *o, const char *key)
{
    const json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

static int status_count(const json_t *o, const char *key)
{
    json_int_t v = json_integer_value(json_object_get(o, key));
    return v >= 0 && v <= INT32_MAX ? (int)v : 0;
}

void status_figures_from_json(run_figures *f, const json_t *st)
{
    static const struct { const char *key; size_t offset; } counts[] = {
        {"dimension", offsetof(fdem_counts, dimension)}, {"nodes", offsetof(fdem_counts, nodes)},
        {"elements", offsetof(fdem_counts, elements)}, {"joints", offsetof(fdem_counts, joints)},
        {"broken_joints", offsetof(fdem_counts, broken_joints)},
        {"fragments", offsetof(fdem_counts, fragments)},
        {"contacts", offsetof(fdem_counts, contacts)},
    };
    for (size_t i = 0; i < sizeof counts / sizeof *counts; i++)
        *(int *)((char *)&f->counts + counts[i].offset) = status_count(st, counts[i].key);
    status_energy_from_json(&f->energy, json_object_get(st, "energy"));
    status_stage_from_json(f, json_object_get(st, "stage"));
    status_fluid_from_json(f, json_object_get(st, "fluid"), json_object_get(st, "energy"));
    f->step = (int64_t)json_integer_value(json_object_get(st, "step"));
    f->time = status_number(st, "time");
    f->dt = status_number(st, "dt");
    f->snapshots = status_count(st, "snapshots");
    f->elapsed = status_number(st, "elapsed");
    if (!(f->elapsed >= 0))
        f->elapsed = 0; /* written by an fdemd from before `elapsed` */
}

void status_time_now(char *out, size_t size)
{
    struct timespec ts;
    struct tm tm;
    clock_gettime(CLOCK_REALTIME, &ts);
    gmtime_r(&ts.tv_sec, &tm);
    char base[24];
    strftime(base, sizeof base, "%Y-%m-%dT%H:%M:%S", &tm);
    snprintf(out, size, "%.19s.%03dZ", base, (int)(ts.tv_nsec / 1000000L));
}

static int status_warning_known(const json_t *list, const char *pointer, const char *message)
{
    size_t i;
    const json_t *w;
    json_array_foreach(list, i, w)
        if (strcmp(json_string_value(json_object_get(w, "pointer")), pointer) == 0 &&
            strcmp(json_string_value(json_object_get(w, "message")), message) == 0)
            return 1;
    return 0;
}

void status_warning_add(json_t *list, const char *pointer, const char *message)
{
    if (!list || json_array_size(list) >= STATUS_WARNINGS_MAX ||
        status_warning_known(list, pointer, message))
        return;
    json_t *w = json_object();
    json_object_set_new(w, "pointer", json_string(pointer));
    json_object_set_new(w, "message", json_string(message));
    json_array_append_new(list, w);
}

static int status_warning_starting(const json_t *list, const char *start)
{
    size_t i, n = strlen(start);
    const json_t *w;
    json_array_foreach(list, i, w)
        if (strncmp(json_string_value(json_object_get(w, "message")), start, n) == 0)
            return 1;
    return 0;
}

/* At the part of the first element, each pair once; their step is in the
 * message. */
void status_take_penetrations(json_t *list, fdem_model *model)
{
    fdem_penetration pen[FDEM_PENETRATIONS_MAX];
    long more = 0;
    int n = fdem_take_penetrations(model, pen, FDEM_PENETRATIONS_MAX, &more);
    const int32_t *part = fdem_element_parts(model);
    for (int i = 0; i < n; i++) {
        char ptr[32], msg[300], pair[64];
        /* the engine lists each pair once a run; a run resumed from a
         * checkpoint may find a pair it had found before the restart */
        snprintf(pair, sizeof pair, "elements %d and %d passed", pen[i].a, pen[i].b);
        if (status_warning_starting(list, pair)) continue;
        snprintf(ptr, sizeof ptr, "/parts/%d", part ? (int)part[pen[i].a] : 0);
        snprintf(msg, sizeof msg, "%s into one another at step %lld (t = %.6g s): a node "
                 "%.2f of the other's inradius deep (warned beyond %.2f); a body too fast or a "
                 "penalty too soft for contact to hold it", pair, (long long)pen[i].step,
                 pen[i].time, pen[i].depth, FDEM_PENETRATION_WARN);
        status_warning_add(list, ptr, msg);
    }
    if (more > 0)
        status_warning_add(list, "", "more element pairs passed into one another than are listed");
}
