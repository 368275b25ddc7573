/*
 * limits.c - the measurements behind "Known limitations and how to mesh" in
 * docs/physics.md: it steps one case document through case_build and the
 * engine (the daemon's own path, without HTTP) and prints one JSON line of
 * what it measured. scripts/limits.py writes the cases (meshes of several
 * sizes) and turns the lines into the tables; `make limits` runs it all.
 *
 *   limits beam < CASE       cantilever under a tip force, no damping: the
 *                            static tip deflection is the mean over whole
 *                            periods of the free vibration about it, and the
 *                            period is read from the same record
 *   limits brazilian < CASE  peak platen force -> 2P/(pi D) (3D: 2P/(pi D t)); when and where
 *                            joints first soften and break (centre or under
 *                            the platens)
 *   limits uniaxial < CASE   peak platen stress P/W (3D: P/(W t)), the same crack record
 *   limits energy < CASE     the energy balance at every output time: the worst residual
 *                            against the work put in so far, the lowest friction and
 *                            fracture accounts, the largest kinetic energy against that work
 *   limits hydraulic < CASE  a hydraulic fracture on y = 0 (3D: z = 0) fed at the origin,
 *                            at every output time: the volume injected, how far the crack
 *                            has run, the opening and the fluid pressure at the well
 *
 * Both dimensions: a 3D case (tetrahedra, joints on faces) is measured the
 * same way, with the load along y and the thickness along z.
 *
 * Conventions shared with tests/unit/test_fracture.c: constraints 0 and 1
 * are the two platens, their force is averaged over 2 microsecond windows
 * (a joint that breaks makes the freed faces ring for a few steps; a
 * one-step spike is not the specimen's strength), and the peak is frozen
 * once the load has fallen below 30 % of it.
 *
 * Not a test: nothing here passes or fails, and a run takes minutes.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../tests/unit/joint_face_3d.h"
#include "case/case.h"
#include "model/model.h"

#define WINDOW 2e-6

/* CPU time of this process: on a shared machine it is what the run would
 * take alone (the driver steps on one thread). */
static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* The whole of a stream (the case document arrives on standard input). */
static char *read_stream(FILE *in, size_t *length)
{
    size_t cap = 1 << 16, n = 0;
    char *text = malloc(cap + 1);
    size_t got;
    while (text && (got = fread(text + n, 1, cap - n, in)) > 0) {
        n += got;
        if (n < cap) continue;
        cap *= 2;
        char *bigger = realloc(text, cap + 1);
        if (!bigger) free(text);
        text = bigger;
    }
    if (text) text[n] = 0;
    *length = n;
    return text;
}

static fdem_model *load_case(case_info *info)
{
    size_t length = 0;
    char *text = read_stream(stdin, &length);
    if (!text) {
        fprintf(stderr, "limits: cannot read the case from standard input\n");
        return NULL;
    }
    problems p;
    problems_init(&p);
    fdem_model *m = case_build(text, length, (size_t)1 << 32, info, &p);
    if (!m) fprintf(stderr, "limits: the case was rejected (%d problems)\n", p.count);
    problems_free(&p);
    free(text);
    return m;
}

static int step_or_report(fdem_model *m)
{
    fdem_error err;
    if (fdem_step(m, &err) == 0) return 0;
    fprintf(stderr, "limits: step failed: %s\n", err.message);
    return -1;
}

/* ------------------------------------------------------------------ beam */

/* The mean of y over [from, to) of the record, and the upward crossings of
 * y - mean in it: whole periods of the free vibration lie between the
 * first and the last crossing, so their mean is the static value. */
static int crossings(const double *t, const double *y, int n, double mean, double *first,
                     double *last, int *i_first, int *i_last)
{
    int count = 0;
    for (int i = 1; i < n; i++) {
        double a = y[i - 1] - mean, b = y[i] - mean;
        if (!(a < 0 && b >= 0)) continue;
        double tc = t[i - 1] + (t[i] - t[i - 1]) * (-a) / (b - a);
        if (count == 0) {
            *first = tc;
            *i_first = i;
        }
        *last = tc;
        *i_last = i;
        count++;
    }
    return count;
}

static double mean_of(const double *y, int from, int to)
{
    double s = 0;
    for (int i = from; i < to; i++) s += y[i];
    return s / (to - from);
}

static int run_beam(void)
{
    case_info info;
    fdem_model *m = load_case(&info);
    if (!m) return 1;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (int i = 0; i < m->node_count; i++) {
        xmin = fmin(xmin, m->pos0[2 * i]);
        xmax = fmax(xmax, m->pos0[2 * i]);
        ymin = fmin(ymin, m->pos0[2 * i + 1]);
        ymax = fmax(ymax, m->pos0[2 * i + 1]);
    }
    const double L = xmax - xmin, d = ymax - ymin;
    int tips = 0;
    for (int i = 0; i < m->node_count; i++) tips += m->pos0[2 * i] > xmax - 1e-9 * L;

    size_t cap = 1024, n = 0;
    double *t = malloc(cap * sizeof *t), *y = malloc(cap * sizeof *y);
    double start = cpu_seconds();
    while (fdem_get_time(m) < info.end_time) {
        if (step_or_report(m)) return 1;
        double w = 0;
        for (int i = 0; i < m->node_count; i++)
            if (m->pos0[2 * i] > xmax - 1e-9 * L) w += m->pos[2 * i + 1] - m->pos0[2 * i + 1];
        if (n == cap) {
            cap *= 2;
            t = realloc(t, cap * sizeof *t);
            y = realloc(y, cap * sizeof *y);
        }
        t[n] = fdem_get_time(m);
        y[n++] = w / tips;
    }
    double seconds = cpu_seconds() - start;

    /* refine the mean and the window of whole periods together */
    double mean = mean_of(y, 0, (int)n), first = 0, last = 0;
    int i_first = 0, i_last = (int)n, count = 0;
    for (int pass = 0; pass < 4; pass++) {
        count = crossings(t, y, (int)n, mean, &first, &last, &i_first, &i_last);
        if (count < 2) break;
        mean = mean_of(y, i_first, i_last);
    }
    double period = count >= 2 ? (last - first) / (count - 1) : NAN;
    printf("{\"case\": \"%s\", \"length\": %.6g, \"depth\": %.6g, \"elements\": %d, \"steps\": %lld, "
           "\"dt\": %.6g, \"periods\": %d, \"deflection\": %.10g, \"period\": %.10g, "
           "\"seconds\": %.3g}\n",
           info.name, L, d, m->elem_count, (long long)fdem_get_step(m), fdem_get_dt(m),
           count - 1, mean, period, seconds);
    free(t);
    free(y);
    fdem_model_destroy(m);
    return 0;
}

/* -------------------------------------------------------------- fracture */

/* Joints at or past a damage level counted by where they lie along the load
 * axis, |y| / half-height of the specimen: the central half, the outer
 * fifth (next to a platen) and the rest. */
typedef struct crack_zones {
    int centre, between, platen;
} crack_zones;

/* The midpoint of joint j's face A (2D: its edge; 3D: its triangle) in
 * the initial configuration, x and y (y: the load axis). */
static void joint_midpoint(const fdem_model *m, int j, double *x, double *y)
{
    const int D = m->dim, corners = D; /* an edge has 2 ends, a face 3 corners */
    const int32_t *nd = m->joint_node + 2 * D * (size_t)j;
    *x = *y = 0;
    for (int i = 0; i < corners; i++) {
        *x += m->pos0[D * nd[i]] / corners;
        *y += m->pos0[D * nd[i] + 1] / corners;
    }
}

/* D > 0 for level 0 (softening has begun), D >= level otherwise */
static int reached(const fdem_model *m, int j, double level)
{
    return level == 0 ? m->joint_damage[j] > 0 : m->joint_damage[j] >= level;
}

static crack_zones count_zones(const fdem_model *m, double half, double level)
{
    crack_zones z = {0, 0, 0};
    for (int j = 0; j < m->joint_count; j++) {
        if (!reached(m, j, level)) continue;
        double x, y;
        joint_midpoint(m, j, &x, &y);
        double r = fabs(y) / half;
        if (r < 0.5) z.centre++;
        else if (r > 0.8) z.platen++;
        else z.between++;
    }
    return z;
}

/* The first window in which some joint reached a damage level: when, how
 * many, and where the first few lie (|y| / half-height). */
typedef struct first_event {
    double level;
    double time;
    int count;
    crack_zones zones;
    int listed;
    double y[6];
} first_event;

static void note_first(const fdem_model *m, double half, first_event *e)
{
    if (e->count > 0) return;
    for (int j = 0; j < m->joint_count; j++) {
        if (!reached(m, j, e->level)) continue;
        double x, y;
        joint_midpoint(m, j, &x, &y);
        if (e->listed < 6) e->y[e->listed++] = fabs(y) / half;
        e->count++;
    }
    if (e->count == 0) return;
    e->time = fdem_get_time(m);
    e->zones = count_zones(m, half, e->level);
}

typedef struct load_run {
    double peak, peak_time, drop_time;
    crack_zones softening_at_peak; /* D > 0 */
    crack_zones damaged_at_peak;   /* D >= 0.5 */
    crack_zones broken_at_peak;    /* D = 1 */
    first_event onset, broken;
    double centre_onset_time;      /* first window with a softening joint in the central half */
    double centre_onset_force;     /* the platen force (window mean) then */
    double seconds;
    long long steps;
} load_run;

/* Steps until the case's end, or 0.1 ms after the load has fallen below 30 %
 * of its first peak (later force is the pieces being squeezed again). A
 * fall counts only once the peak has passed a tenth of the expected force
 * `expect`: a platen settling onto a pad rings before the specimen loads. */
static int run_loaded(fdem_model *m, double end, double half, double expect, load_run *r)
{
    memset(r, 0, sizeof *r);
    r->drop_time = -1;
    r->onset.level = 0;
    r->broken.level = 1;
    double sum = 0, span = 0, start = cpu_seconds();
    while (fdem_get_time(m) < end && (r->drop_time < 0 || fdem_get_time(m) < r->drop_time + 1e-4)) {
        if (step_or_report(m)) return -1;
        const double *f = fdem_constraint_forces(m);
        double dt = fdem_get_dt(m);
        sum += 0.5 * (fabs(f[1]) + fabs(f[m->dim + 1])) * dt; /* y of constraints 0, 1 */
        span += dt;
        if (span < WINDOW) continue;
        double mean = sum / span;
        sum = span = 0;
        if (r->drop_time >= 0) continue;
        note_first(m, half, &r->onset);
        note_first(m, half, &r->broken);
        if (r->centre_onset_time == 0 && count_zones(m, half, 0).centre > 0) {
            r->centre_onset_time = fdem_get_time(m);
            r->centre_onset_force = mean;
        }
        if (mean > r->peak) {
            r->peak = mean;
            r->peak_time = fdem_get_time(m);
            r->softening_at_peak = count_zones(m, half, 0);
            r->damaged_at_peak = count_zones(m, half, 0.5);
            r->broken_at_peak = count_zones(m, half, 1);
        } else if (mean < 0.3 * r->peak && r->peak > 0.1 * expect) {
            r->drop_time = fdem_get_time(m);
        }
    }
    r->seconds = cpu_seconds() - start;
    r->steps = (long long)fdem_get_step(m);
    return 0;
}

static void print_zones(const char *name, crack_zones z)
{
    printf("\"%s\": [%d, %d, %d], ", name, z.centre, z.between, z.platen);
}

static void print_first(const char *name, const first_event *e)
{
    printf("\"%s\": {\"time\": %.6g, \"count\": %d, ", name, e->time, e->count);
    print_zones("zones", e->zones);
    printf("\"y\": [");
    for (int i = 0; i < e->listed; i++) printf("%s%.3f", i ? ", " : "", e->y[i]);
    printf("]}, ");
}

/* zones are [centre, between, platen] counts */
static void print_loaded(const char *kind, const case_info *info, const fdem_model *m,
                         const load_run *r, double strength, double reference)
{
    printf("\"kind\": \"%s\", \"case\": \"%s\", \"elements\": %d, \"joints\": %d, \"dt\": %.6g, "
           "\"steps\": %lld, \"peak_force\": %.6g, \"strength\": %.6g, \"reference\": %.6g, "
           "\"peak_time\": %.6g, \"drop_time\": %.6g, ",
           kind, info->name, m->elem_count, m->joint_count, fdem_get_dt(m), r->steps, r->peak,
           strength, reference, r->peak_time, r->drop_time);
    print_zones("softening_at_peak", r->softening_at_peak);
    print_zones("damaged_at_peak", r->damaged_at_peak);
    print_zones("broken_at_peak", r->broken_at_peak);
    print_first("onset", &r->onset);
    print_first("first_broken", &r->broken);
    printf("\"centre_onset_time\": %.6g, \"centre_onset_force\": %.6g, ", r->centre_onset_time,
           r->centre_onset_force);
    printf("\"broken_end\": %d, \"seconds\": %.3g}\n", m->broken_joints, r->seconds);
}

/* How far joint j's crack would run from the load (y) axis, in degrees: in
 * 2D the angle of its edge to y; in 3D the angle of its face to y, or, for
 * a split along the loaded diameter (`split`), the angle of its normal to
 * x, so that faces lying across the disc's axis do not count. */
static double joint_angle(const fdem_model *m, int j, int split)
{
    const double *p = m->pos0;
    if (m->dim == 2) {
        const int32_t *nd = m->joint_node + 4 * (size_t)j;
        double dx = fabs(p[2 * nd[1]] - p[2 * nd[0]]), dy = fabs(p[2 * nd[1] + 1] - p[2 * nd[0] + 1]);
        return atan2(dx, dy) * 180 / M_PI;
    }
    double n[3], len = joint_face_normal(p, m->joint_node + 6 * (size_t)j, n);
    if (split) return acos(fmin(1, fabs(n[0]) / len)) * 180 / M_PI;
    return asin(fmin(1, fabs(n[1]) / len)) * 180 / M_PI;
}

/* The share of joints near the middle of the specimen (|x|, |y| within
 * `reach`) whose direction lies within 10 degrees of `angle` from the load
 * (y) axis: a crack can only run along element edges (faces in 3D), so a
 * mesh with none near the failure plane must be loaded further before it
 * fails. */
static double oriented_share(const fdem_model *m, double reach, double angle)
{
    int near = 0, oriented = 0;
    for (int j = 0; j < m->joint_count; j++) {
        double x, y;
        joint_midpoint(m, j, &x, &y);
        if (fabs(x) > reach || fabs(y) > reach) continue;
        near++;
        oriented += fabs(joint_angle(m, j, angle == 0) - angle) <= 10;
    }
    return near ? (double)oriented / near : 0;
}

/* The specimen is part 0; its extent gives D (disc) or W x H (block) and,
 * in 3D, its thickness along z. */
static void specimen_extent(const fdem_model *m, double *width, double *height, double *depth)
{
    const part *p = &m->parts[0];
    const int D = m->dim;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = p->node_begin; i < p->node_begin + p->node_count; i++)
        for (int c = 0; c < D; c++) {
            lo[c] = fmin(lo[c], m->pos0[D * i + c]);
            hi[c] = fmax(hi[c], m->pos0[D * i + c]);
        }
    *width = hi[0] - lo[0];
    *height = hi[1] - lo[1];
    *depth = D == 3 ? hi[2] - lo[2] : 1; /* 2D: per metre of thickness */
}

static int run_fracture(const char *kind)
{
    case_info info;
    fdem_model *m = load_case(&info);
    if (!m) return 1;
    double width, height, depth;
    specimen_extent(m, &width, &height, &depth);
    const material *rock = &m->materials[m->parts[0].material];
    double strength_per_force, reference, oriented;
    if (strcmp(kind, "brazilian") == 0) {
        /* sigma_t = 2P/(pi D t); the centre splits along the loaded diameter */
        strength_per_force = 2 / (M_PI * width * depth);
        reference = rock->def.fracture.tensile_strength;
        oriented = oriented_share(m, 0.25 * width, 0);
    } else {
        /* Mohr-Coulomb: failure planes at 45 - phi/2 degrees from the load */
        double c = rock->def.fracture.cohesion, phi_deg = rock->def.fracture.friction_angle;
        double phi = phi_deg * M_PI / 180;
        strength_per_force = 1 / (width * depth);
        reference = 2 * c * cos(phi) / (1 - sin(phi));
        oriented = oriented_share(m, 0.5 * width, 45 - 0.5 * phi_deg);
    }
    load_run r;
    if (run_loaded(m, info.end_time, 0.5 * height, reference / strength_per_force, &r)) return 1;
    double strength = r.peak * strength_per_force;
    printf("{\"oriented\": %.4f, ", oriented);
    print_loaded(kind, &info, m, &r, strength, reference);
    fdem_model_destroy(m);
    return 0;
}

/* ---------------------------------------------------------------- energy */

/* The energy that went through the model by time t, the scale of its
 * residual (as tests/unit/test_energy.c takes it): the largest of the
 * energy it started with, the work of the loads and that of gravity. */
static double energy_through(const fdem_model *m, const fdem_energy *e)
{
    return fmax(m->initial_energy, fmax(fabs(e->external_work), fabs(e->gravity_work)));
}

/* What was put in by time t: the energy it started with and the work of
 * the loads and of gravity; no kinetic energy may exceed it. */
static double energy_put_in(const fdem_model *m, const fdem_energy *e)
{
    return m->initial_energy + e->external_work + e->gravity_work;
}

static int run_energy(void)
{
    case_info info;
    fdem_model *m = load_case(&info);
    if (!m) return 1;
    double t0 = cpu_seconds(), next = 0;
    fdem_energy e = fdem_get_energy(m);
    double worst = 0, worst_at = 0, least_friction = 0, least_fracture = 0, kinetic_ratio = 0;
    double kinetic_at = 0;
    long samples = 0;
    for (;;) {
        double t = fdem_get_time(m);
        if (t >= next || t >= info.end_time) {
            e = fdem_get_energy(m);
            double through = energy_through(m, &e), put_in = energy_put_in(m, &e);
            if (through > 0 && fabs(e.residual) / through > worst) {
                worst = fabs(e.residual) / through;
                worst_at = t;
            }
            if (put_in > 0 && e.kinetic / put_in > kinetic_ratio) {
                kinetic_ratio = e.kinetic / put_in;
                kinetic_at = t;
            }
            least_friction = fmin(least_friction, e.friction);
            least_fracture = fmin(least_fracture, e.fracture);
            samples++;
            while (next <= t) next += info.output_interval;
        }
        if (t >= info.end_time) break;
        if (step_or_report(m)) return 1;
    }
    printf("{\"samples\": %ld, \"worst_residual\": %.6g, \"worst_at\": %.6g, "
           "\"least_friction\": %.6g, \"least_fracture\": %.6g, \"kinetic_over_put_in\": %.6g, \"kinetic_at\": %.6g, "
           "\"work\": %.6g, \"kinetic\": %.6g, \"elastic\": %.6g, \"joint\": %.6g, "
           "\"contact\": %.6g, \"friction\": %.6g, \"fracture\": %.6g, \"damping\": %.6g, "
           "\"residual\": %.6g, \"broken\": %d, \"steps\": %lld, \"seconds\": %.3f}\n",
           samples, worst, worst_at, least_friction, least_fracture, kinetic_ratio, kinetic_at,
           energy_through(m, &e), e.kinetic, e.elastic, e.joint, e.contact, e.friction,
           e.fracture, e.damping, e.residual, fdem_get_counts(m).broken_joints,
           (long long)m->step, cpu_seconds() - t0);
    fdem_model_destroy(m);
    return 0;
}

/* ------------------------------------------------------------- hydraulic */

/* What a hydraulic fracture on the plane y = 0 (3D: z = 0) fed at the
 * origin has done by one output time. How far it runs: in 2D the
 * farthest end of a broken (D = 1) and of a damaged (D > 0) joint on the
 * line; in 3D the areas of the broken and of the damaged joints on the
 * plane (the radius follows from the area, whatever the mesh's symmetry).
 * At the well: the mean aperture and pressure of the plane's joints with
 * a corner at the origin. Broken joints off the plane are counted: a
 * crack that left it is not the one the closed form describes. */
typedef struct hydraulic_sample {
    double time, volume, broken, damaged, opening, pressure;
    int broken_off_plane;
} hydraulic_sample;

/* Joint j's face A lies on the plane (height 0), and its extent there. */
static int plane_joint(const fdem_model *m, int j, double *reach, double *area, int *at_origin)
{
    const int D = m->dim;
    const int32_t *nd = m->joint_node + 2 * D * (size_t)j;
    *reach = 0;
    *at_origin = 0;
    for (int i = 0; i < D; i++) {
        const double *x = m->pos0 + D * (size_t)nd[i];
        if (fabs(x[D - 1]) > 1e-9) return 0;
        double r = D == 3 ? hypot(x[0], x[1]) : fabs(x[0]);
        *reach = fmax(*reach, r);
        *at_origin |= r < 1e-9;
    }
    if (D == 3) {
        const double *a = m->pos0 + 3 * (size_t)nd[0], *b = m->pos0 + 3 * (size_t)nd[1],
                     *c = m->pos0 + 3 * (size_t)nd[2];
        *area = 0.5 * fabs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    } else {
        *area = 0;
    }
    return 1;
}

static hydraulic_sample hydraulic_measure(const fdem_model *m, double *aperture)
{
    hydraulic_sample s = {0};
    const double *pressure = fdem_fluid_pressure(m);
    fdem_fluid_apertures(m, aperture);
    int beside = 0;
    for (int j = 0; j < m->joint_count; j++) {
        double reach, area;
        int origin;
        const double damage = m->joint_damage[j];
        if (!plane_joint(m, j, &reach, &area, &origin)) {
            s.broken_off_plane += damage >= 1;
            continue;
        }
        double extent = m->dim == 3 ? area : reach;
        if (damage >= 1) s.broken = m->dim == 3 ? s.broken + extent : fmax(s.broken, extent);
        if (damage > 0) s.damaged = m->dim == 3 ? s.damaged + extent : fmax(s.damaged, extent);
        if (!origin) continue;
        s.opening += aperture[j];
        s.pressure += pressure[j];
        beside++;
    }
    s.time = fdem_get_time(m);
    s.volume = fdem_get_fluid(m).injected_volume;
    if (beside) s.opening /= beside, s.pressure /= beside;
    return s;
}

static int run_hydraulic(void)
{
    case_info info;
    fdem_model *m = load_case(&info);
    if (!m) return 1;
    if (!m->fluid) {
        fprintf(stderr, "limits: the case has no fluid\n");
        return 1;
    }
    double *aperture = malloc(sizeof(double) * (size_t)(m->joint_count ? m->joint_count : 1));
    double t0 = cpu_seconds(), next = info.output_interval;
    printf("{\"case\": \"%s\", \"dimension\": %d, \"elements\": %d, \"joints\": %d, \"dt\": %.6g, "
           "\"samples\": [", info.name, m->dim, m->elem_count, m->joint_count, fdem_get_dt(m));
    int first = 1;
    for (;;) {
        double t = fdem_get_time(m);
        if (t >= next || t >= info.end_time) {
            hydraulic_sample s = hydraulic_measure(m, aperture);
            printf("%s{\"time\": %.6g, \"volume\": %.8g, \"broken\": %.8g, \"damaged\": %.8g, "
                   "\"opening\": %.8g, \"pressure\": %.8g, \"broken_off_plane\": %d, "
                   "\"subcycles\": %d}", first ? "" : ", ", s.time, s.volume, s.broken,
                   s.damaged, s.opening, s.pressure, s.broken_off_plane,
                   fdem_get_fluid(m).subcycles);
            first = 0;
            while (next <= t) next += info.output_interval;
        }
        if (t >= info.end_time) break;
        if (step_or_report(m)) return 1;
    }
    printf("], \"steps\": %lld, \"seconds\": %.3f}\n", (long long)m->step, cpu_seconds() - t0);
    free(aperture);
    fdem_model_destroy(m);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: limits beam|brazilian|uniaxial|energy|hydraulic < CASE.json\n");
        return 2;
    }
    if (strcmp(argv[1], "energy") == 0) return run_energy();
    if (strcmp(argv[1], "hydraulic") == 0) return run_hydraulic();
    if (strcmp(argv[1], "beam") == 0) return run_beam();
    if (strcmp(argv[1], "brazilian") == 0 || strcmp(argv[1], "uniaxial") == 0)
        return run_fracture(argv[1]);
    fprintf(stderr, "limits: unknown measurement '%s'\n", argv[1]);
    return 2;
}
