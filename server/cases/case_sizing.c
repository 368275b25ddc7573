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
#include "state/status_json.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_model.h"
#include "sizing_probe.h"
#include "state/snapshot.h"
#include "files/checkpoint_file.h"
#include "math/clock.h"
#include "common/sample_ring.h"


double sizing_steps_to_end(double t0, double end, double dt)
{
    if (!(dt > 0) || !(end > t0))
        return 0;
    /* Step k (from 0) starts at t0 + k dt and is the last one when
     * output_is_last_step() (proto/state/output_grid.h) holds: the first k >= (end - 1e-9 dt - t0)/dt - 1. */
    double k = ceil((end - 1e-9 * dt - t0) / dt - 1.0);
    return (k > 0 ? k : 0) + 1;
}

/* Snapshot 0, one at the first step at or after each output time (several
 * output times inside one step give one snapshot), and the one at the end.
 * An output time after the start of the last step, which is cut to land on
 * time.end, is the end's snapshot: only those up to that start count, with
 * the worker's tolerance of 1e-9 dt. */
static double sizing_snapshots(const case_info *info, double t0, double dt, double steps)
{
    double interval = output_snapshot_interval(info);
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

/* Broken joints cost a run twice (issue 34's figures). Through contact:
 * the faces of a crack, and in 3D every pair of tetrahedra around its
 * vertices, are pairs from then on, so a step costs about intact +
 * (broken joints) x (the cost of one), measured on the model with a crack
 * cut through it (sizing_cracked_step_seconds). And through the contact
 * list: every step in which a joint breaks mends it around the break
 * (core/contact/contact_breaks.c; it reran the whole detection until
 * stop 36, 82 % of a 2D tunnel's CPU after its wall split, 1,100 joints
 * broken at 8 ms a detection of 4,678 triangles): so each joint that
 * breaks is priced one mending, timed before the cut and on it
 * (sizing_detection_at).
 *
 * How many break by the end: a share of the joints, not known before the
 * run. The bundled examples break 0 to 23 % of their joints by the end
 * (the median 2 %), late in some runs and early in others: tunnel-region
 * 23 % (none until 80 % of the run, then 1,100 of 4,834), staged-tunnel
 * 7 %, kgd and hf-natural-joint 5 %, the arc-loaded 3D disc 4 % (27x a
 * step after its split), the 3D disc 3.6 %, drift-3d 2.7 %, the 2D disc
 * 1.2 %, jointed-block 1 %, borehole-breakdown 0.7 %, the 3D prism none
 * (it only softens). Priced at SIZING_BROKEN_SHARE, a run within a
 * factor of 2 breaks about 1 to 10 % (where breaks set the pace). When
 * the model's own steps up to the last look (below) broke more than that
 * share at their rate (a crack driven by injected fluid grows from the
 * first steps: the penny breaks its first joint at step 68 of 4,336),
 * as many at that rate. Held broken on average over the steps: half of
 * them (a count growing from none). */
#define SIZING_BROKEN_SHARE 0.03

/* Later looks: the model is stepped on, untimed, to SIZING_LOOKS evenly
 * spaced points up to this share of the run's steps and timed at each, so
 * that contact that starts soon after t = 0 (a pile whose lowest bodies
 * fall a few millimetres: a sphere pile's step costs 20 us at rest and
 * 1-3 ms once they touch, from about step 700) is priced from then on.
 * How far they go is set in steps from the first pace (as far as
 * SIZING_ADVANCE_CPU seconds of it reach, down to a power of 2, so that a
 * first pace 1.5x slower on a busier machine moves it seldom), not by a
 * clock, so that two dry runs look at the same steps; and the later pace
 * is the looks' median, so that one that lands in a short impact (a 3D
 * collision's contact: 30x a step for ~200 steps of 3,922) does not price
 * the whole run at it (their mean priced collision-3d at 5-10x its CPU,
 * 4.3 and 8.1 s for two dry runs of one document). */
#define SIZING_ADVANCE_SHARE 0.3
#define SIZING_ADVANCE_CPU 0.1
#define SIZING_LOOKS 3

/* The centre of the jointed rock: the mean of every joint's first face
 * node (joints lie where fracture can happen, so the crack of the probe
 * runs through the fracturing part or region, not through a platen). */
static void sizing_joint_centre(const fdem_model *model, double centre[3])
{
    int dim = fdem_get_dimension(model), J = fdem_get_counts(model).joints;
    const int32_t *joint = fdem_joints(model);
    const double *x = fdem_positions(model);
    centre[0] = centre[1] = centre[2] = 0;
    if (!joint || J <= 0) return;
    for (int j = 0; j < J; j++)
        for (int d = 0; d < dim; d++) centre[d] += x[dim * (size_t)joint[2 * dim * (size_t)j] + d];
    for (int d = 0; d < dim; d++) centre[d] /= J;
}

/* The plane of the probe's crack: through the joints' centre, normal to
 * the axis whose plane crosses the most joints (a disc's or a tunnel's
 * joints fill a region, which any axis cuts; a fluid-driven crack's lie
 * on its plane, which only the axis normal to it crosses). Returns how
 * many joints it crosses. */
static int sizing_crack_plane(const fdem_model *model, double normal[3], double *offset)
{
    double centre[3];
    sizing_joint_centre(model, centre);
    int dim = fdem_get_dimension(model), most = 0;
    for (int d = 0; d < dim; d++) {
        double axis[3] = {0, 0, 0};
        axis[d] = 1;
        int crossed = fdem_joints_across(model, axis, centre[d]);
        if (crossed > most) {
            most = crossed;
            memcpy(normal, axis, sizeof axis);
            *offset = centre[d];
        }
    }
    return most;
}

/* What a break costs the contact list, timed: up to SIZING_DETECTIONS
 * steps each with one more joint broken (fdem_break_one_joint, from the
 * middle of the joints on), whose list is mended for it
 * (core/contact/contact_breaks.c), as long as they take no more than
 * SIZING_DETECTION_CPU seconds in all; each counts its CPU seconds times
 * the detection stage's share of its wall time (the engine's stage clock
 * reads wall time). The median; NAN when a step fails. With no joint left
 * to break, the whole detection is timed instead. Before the cut, the
 * joints it will break are left to it (avoid_normal, avoid_offset: its
 * plane), so the cut's figures are those of the plane's joints. */
#define SIZING_DETECTIONS 5
#define SIZING_DETECTION_CPU 0.3

static double sizing_detection_seconds(fdem_model *model, double steps_left, int *taken,
                                       const double *avoid_normal, double avoid_offset)
{
    double seconds[SIZING_DETECTIONS], spent = 0;
    int n = 0, next = fdem_get_counts(model).joints / 2;
    while (n < SIZING_DETECTIONS && n < steps_left && (n == 0 || spent < SIZING_DETECTION_CPU)) {
        int broke = fdem_break_one_joint(model, next, avoid_normal, avoid_offset);
        if (broke < 0) fdem_force_detection(model);
        else next = broke + 1;
        double detected0 = fdem_get_stage_times(model).detection;
        double wall0 = clock_wall_seconds(), cpu0 = clock_cpu_seconds();
        if (sizing_step(model) != 0)
            return NAN;
        double cpu = clock_cpu_seconds() - cpu0, wall = clock_wall_seconds() - wall0;
        double share = wall > 0 ? (fdem_get_stage_times(model).detection - detected0) / wall : 1;
        seconds[n++] = cpu * (share < 0 ? 0 : share > 1 ? 1 : share);
        spent += cpu;
        (*taken)++;
    }
    if (n == 0) return NAN;
    return median_in_place(seconds, n);
}

/* The crack of the probe is the half of the plane's joints nearest the
 * joints' centre: a crack inside the body, as one that grows in the run.
 * Cut through the whole body, the crack parted it in two and only its
 * faces met (a face pair each, shut: the cheapest pair there is), while
 * the cracks of a run lie inside a piece and bring the elements around
 * their vertices into contact too: drift-3d and the arc-loaded 3D disc
 * ran 3.5-7x their estimate (100x the probe's price of a broken joint in
 * drift-3d). */
#define SIZING_CRACK_SHARE 0.5

/* A crack cut at rest is shut: its faces and the vertex pairs around it
 * take the cheap path of shut joints (docs/physics.md). A run's cracks
 * open, slide and wedge, and then every pair around them takes the
 * general kernel, in 3D ~25x the price (drift-3d: 0.8 and 22 us a broken
 * joint a step; its run paid ~60). How much of a run's cracks is open is
 * not known before it, so the probe's crack is priced open: priced shut,
 * drift-3d and the arc-loaded 3D disc ran 4.9x and 6.9x their estimates.
 *
 * But open at rest is more than a run's crack ever costs: every pair
 * around it is within reach of the contact list, its faces and vertex
 * copies in place, where a run's crack has moved (it is open because its
 * copies moved apart) and part of its pairs went out of reach. Near pairs
 * (within the list's reach) a broken joint brings, in the run against in
 * the probe's crack (bench_case at the end of each run; the probe's crack
 * cut and stepped as the dry run does), 2026-12-07: the arc-loaded 3D disc
 * 0.27 (42 against 157: its split opens), drift-3d 0.58 (97 against 168:
 * its cracks pressed in situ), the 3D disc 0.63, tunnel-region 0.60,
 * staged-tunnel 0.57, jointed-block 0.80, the 2D disc 0.84: about half,
 * SIZING_OPEN_CRACK_SHARE. Priced whole, the 3D discs and prism ran
 * 0.35-0.41x their estimates (every pair of the crack within reach is
 * their upper bound); priced at half, each of the seven is within 1.9x
 * of its own share. */
#define SIZING_OPEN_CRACK_SHARE 0.5

/* CPU seconds a step once the rock has broken: the model is cut by a
 * crack inside its joints (sizing_crack_plane, SIZING_CRACK_SHARE), its
 * cracks priced open (fdem_price_cracks_open), and timed again; then the
 * mending of the contact list a break sets off, on the cracked model
 * (*detection). NAN when no joint crosses the plane or a step fails. */
static double sizing_cracked_step_seconds(fdem_model *model, double steps_left,
                                          const double normal[3], double offset, int *broke,
                                          double *detection, sizing_load *load)
{
    *detection = NAN;
    *broke = 0;
    if (steps_left < 2) return NAN;
    double centre[3];
    sizing_joint_centre(model, centre);
    *broke = fdem_break_joints_near(model, normal, offset, centre, SIZING_CRACK_SHARE);
    if (*broke <= 0) return NAN;
    fdem_price_cracks_open(model, 1);
    int taken = 0;
    double pace = sizing_probe_step_seconds(model, steps_left, &taken, load);
    if (isfinite(pace))
        *detection = sizing_detection_seconds(model, steps_left - taken, &taken, NULL, 0);
    return pace;
}

/* A run whose remaining steps at the first pace fit in SIZING_ADVANCE_CPU
 * is stepped to its end, timed, and its mean pace is the run's: nothing is
 * extrapolated, so a short impact weighs what it weighs (collision-3d: 30x
 * a step for ~200 of 3,922 steps; the looks' median priced it at 2.0-2.2x
 * its run, and no pace sampled at points can know the contact ends). Its
 * CPU is capped at SIZING_WHOLE_CPU_CAP (a run far dearer than its first
 * pace said); the steps taken by then give the pace. NAN when a step
 * fails (the run will say why). */
#define SIZING_WHOLE_CPU_CAP 1.0

static double sizing_whole_run_seconds(fdem_model *model, double steps, int *taken,
                                       sizing_load *load)
{
    int from = *taken;
    double cpu0 = clock_cpu_seconds(), wall0 = clock_wall_seconds();
    while (*taken < steps) {
        if (sizing_step(model) != 0)
            return NAN;
        (*taken)++;
        if (((*taken - from) & 63) == 0 && clock_cpu_seconds() - cpu0 > SIZING_WHOLE_CPU_CAP)
            break;
    }
    double cpu = clock_cpu_seconds() - cpu0;
    load->wall += clock_wall_seconds() - wall0;
    load->cpu += cpu;
    return *taken > from ? cpu / (*taken - from) : NAN;
}

/* The pace of the run after the first probe (later_step_seconds): the
 * whole run's mean when it is cheap (above), else the median of the later
 * looks; the steps up to the last look go at the first pace, the rest at
 * the later one. */
static double sizing_later_step_seconds(fdem_model *model, case_sizing *out, int *taken,
                                        sizing_load *load)
{
    out->later_step_seconds = NAN;
    double first = out->step_seconds;
    if (!isfinite(first) || !(first > 0))
        return first;
    if (out->steps > *taken && first * (out->steps - *taken) <= SIZING_ADVANCE_CPU) {
        double from = *taken, whole = sizing_whole_run_seconds(model, out->steps, taken, load);
        if (!isfinite(whole))
            return first;
        out->later_step_seconds = whole;
        double done = from / out->steps;
        return done * first + (1 - done) * whole;
    }
    double reach = SIZING_ADVANCE_SHARE * out->steps;
    if (reach > SIZING_ADVANCE_CPU / first) /* down to a power of 2: two dry runs */
        reach = exp2(floor(log2(SIZING_ADVANCE_CPU / first))); /* look at the same steps */
    if (reach <= *taken || out->steps - reach < 16)
        return first;
    double pace_at[SIZING_LOOKS];
    int looks = 0;
    for (int k = 1; k <= SIZING_LOOKS; k++) {
        double target = reach * k / SIZING_LOOKS;
        while (*taken < target) {
            if (sizing_step(model) != 0)
                return first; /* the run will say why */
            (*taken)++;
        }
        int more = 0;
        double pace = sizing_probe_step_seconds(model, out->steps - *taken, &more, load);
        *taken += more;
        if (!isfinite(pace))
            return first;
        pace_at[looks++] = pace;
    }
    double later = out->later_step_seconds = median_in_place(pace_at, looks);
    double done = *taken / out->steps;
    return done * first + (1 - done) * later;
}

/* Wall seconds the worker spends on one snapshot besides writing it (the
 * I/O thread writes): copying the fields and the checkpoint that comes
 * with every snapshot (worker.c). */
static double sizing_snapshot_copy_seconds(const fdem_model *model, const case_info *info)
{
    double best = INFINITY;
    for (int k = 0; k < 2; k++) { /* the faster of two: one copy met a 12 ms stall */
        double started = clock_wall_seconds();
        snapshot *snap = snapshot_take(model, info->fields);
        size_t size = 0;
        void *ckpt = checkpoint_file_take(model, &size);
        double seconds = clock_wall_seconds() - started;
        snapshot_free(snap);
        free(ckpt);
        if (seconds < best) best = seconds;
    }
    return best;
}

/* How many joints the run breaks (out->breaks, each priced one
 * mending of the contact list) and how many it holds broken on average over its steps
 * (out->broken_joints, each priced its contact every step): the
 * SIZING_BROKEN_SHARE of them, or more when the `seen` that its first
 * `taken` steps broke go on at that rate. */
static void sizing_price_breaks(case_sizing *out, int joints, int seen, int taken)
{
    double by_end = SIZING_BROKEN_SHARE * joints;
    if (seen > 0 && taken > 0 && seen * (out->steps / taken) > by_end)
        by_end = seen * (out->steps / taken);
    if (by_end > joints) by_end = joints;
    if (by_end > out->steps) by_end = out->steps;
    out->breaks = by_end;
    out->broken_joints = 0.5 * by_end;
}

/* CPU seconds of one break's mending while the run holds
 * out->broken_joints broken: its work grows with the crack, so it is
 * interpolated between the one timed intact and the one timed on the cut
 * (drift-3d: 119 ms with 426 joints cut, 41 ms in its run with 143
 * broken). Either alone when the other was not timed; 0 when neither. */
static double sizing_detection_at(const case_sizing *out)
{
    double intact = out->intact_detection_seconds, cut = out->break_detection_seconds;
    if (!isfinite(intact)) return isfinite(cut) ? cut : 0;
    if (!isfinite(cut) || out->cracked_joints <= 0) return intact;
    double at = intact + (cut - intact) * (out->broken_joints / out->cracked_joints);
    return at > 0 ? at : 0;
}

/* The crack's figures (its step, its detections) are timed a second or
 * so after the run's pace (the first probe and the later looks), and a
 * shared machine's speed swings by 1.3-1.5x over seconds: the cracked
 * step's excess over that pace, a difference of two figures timed apart,
 * swung 3x between dry runs of tunnel-region (0.8e-4 to 2.5e-4 s). So each
 * is taken as a multiple of the intact step timed just before the cut
 * (`before`), which saw the same machine, and priced at the run's pace. */
static double sizing_relative(double seconds, double before, double pace)
{
    return seconds / before * pace;
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
    double copy = out->snapshot_copy_seconds = sizing_snapshot_copy_seconds(model, info);
    int taken = 0;
    sizing_load load = {0, 0};
    out->step_seconds = sizing_probe_step_seconds(model, out->steps, &taken, &load);
    double per_step = sizing_later_step_seconds(model, out, &taken, &load);
    /* joints the run's own steps broke so far (before the probe's crack) */
    int seen = fdem_get_counts(model).broken_joints, looked = taken;
    out->broken_seen = seen;
    double breaking = 0; /* CPU seconds of the mendings breaks set off */
    out->cracked_step_seconds = out->break_detection_seconds = NAN;
    out->intact_detection_seconds = out->adjacent_step_seconds = NAN;
    if (c.joints > 0 && isfinite(per_step) && out->steps > taken) {
        /* the intact step right before the cut, what the crack's figures
         * are taken against (sizing_relative) */
        int more = 0;
        double before = out->adjacent_step_seconds =
            sizing_probe_step_seconds(model, out->steps - taken, &more, &load);
        taken += more;
        /* a mending before the cut: what one costs with (nearly) none
         * broken, on joints off the cut's plane */
        double normal[3] = {1, 0, 0}, offset = 0;
        int planed = sizing_crack_plane(model, normal, &offset) > 0;
        out->intact_detection_seconds =
            sizing_detection_seconds(model, out->steps - taken, &taken, planed ? normal : NULL,
                                     offset);
        if (planed)
            out->cracked_step_seconds = sizing_cracked_step_seconds(
                model, out->steps - taken, normal, offset, &out->cracked_joints,
                &out->break_detection_seconds, &load);
        if (!(before > 0)) /* a step failed: the run will say why */
            before = per_step;
        if (isfinite(out->cracked_step_seconds) && out->cracked_joints > 0) {
            sizing_price_breaks(out, c.joints, seen, looked);
            double pace = per_step;
            double each = SIZING_OPEN_CRACK_SHARE *
                          sizing_relative(out->cracked_step_seconds - before, before, pace) /
                          out->cracked_joints;
            if (each > 0)
                per_step += out->broken_joints * each;
            breaking = out->breaks * sizing_relative(sizing_detection_at(out), before, pace);
        }
    }
    /* CPU seconds so far; the machine's present load turns them into wall
     * seconds (sizing_probe.h) */
    out->load_factor = sizing_load_factor(&load);
    out->probe_wall_over_cpu = load.cpu > 0 ? load.wall / load.cpu : NAN;
    per_step *= out->load_factor;
    out->steps_per_second = per_step > 0 ? 1.0 / per_step : 0.0;
    /* Snapshots are written on the I/O thread while the worker steps on:
     * the slower of the two sets the pace; the worker's copies add. */
    breaking *= out->load_factor;
    double stepping = per_step > 0 ? out->steps * per_step + breaking + out->snapshots * copy : NAN;
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

json_t *case_sizing_json(const case_sizing *s)
{
    json_t *o = json_object();
    json_object_set_new(o, "nodes", json_integer(s->nodes));
    json_object_set_new(o, "elements", json_integer(s->elements));
    json_object_set_new(o, "joints", json_integer(s->joints));
    json_object_set_new(o, "dt", status_number_or_null(s->dt));
    json_object_set_new(o, "steps", sizing_count_json(s->steps));
    json_object_set_new(o, "snapshots", sizing_count_json(s->snapshots));
    json_object_set_new(o, "memory_bytes", sizing_count_json(s->memory_bytes));
    json_object_set_new(o, "result_bytes", sizing_count_json(ceil(s->result_bytes)));
    json_object_set_new(o, "estimated_seconds", status_number_or_null(s->estimated_seconds));
    if (s->fluid) { /* the flow's step: null while no fluid can flow yet */
        json_object_set_new(o, "fluid_step", status_number_or_null(s->fluid_step));
        json_object_set_new(o, "fluid_subcycles", json_integer(s->fluid_subcycles));
    }
    /* what the estimate was made of (docs/api.md), to judge it by */
    json_t *parts = json_object();
    json_object_set_new(parts, "step_seconds", status_number_or_null(s->step_seconds));
    json_object_set_new(parts, "load_factor", status_number_or_null(s->load_factor));
    json_object_set_new(parts, "probe_wall_over_cpu", status_number_or_null(s->probe_wall_over_cpu));
    json_object_set_new(parts, "later_step_seconds", status_number_or_null(s->later_step_seconds));
    json_object_set_new(parts, "adjacent_step_seconds", status_number_or_null(s->adjacent_step_seconds));
    json_object_set_new(parts, "cracked_step_seconds", status_number_or_null(s->cracked_step_seconds));
    json_object_set_new(parts, "cracked_joints", json_integer(s->cracked_joints));
    json_object_set_new(parts, "broken_joints", status_number_or_null(s->broken_joints));
    json_object_set_new(parts, "broken_seen", json_integer(s->broken_seen));
    json_object_set_new(parts, "breaks", status_number_or_null(s->breaks));
    json_object_set_new(parts, "intact_detection_seconds",
                        status_number_or_null(s->intact_detection_seconds));
    json_object_set_new(parts, "break_detection_seconds",
                        status_number_or_null(s->break_detection_seconds));
    json_object_set_new(parts, "snapshot_seconds", status_number_or_null(s->snapshot_copy_seconds));
    json_object_set_new(o, "estimate", parts);
    char warning[400];
    if (case_sizing_warning(s, warning, sizeof warning))
        json_object_set_new(o, "warning", json_string(warning));
    return o;
}
