/*
 * sizing_probe.c - the wall time of one step of a model on this machine
 * (sizing_probe.h), measured so that it means the run's steps and not the
 * first ones.
 *
 * The first steps of a fresh model are not like the rest: its arrays are
 * touched for the first time (page faults), the caches are cold, the first
 * contact detection runs, OpenMP starts its threads. One 50 ms sample of
 * them gave 115 s and 3,300 s for two dry runs of one document, and 12x
 * the measured run on a fracturing tunnel. So: a warm-up that is not timed,
 * then several short windows, each its own figure, and their median: a
 * window that a neighbour's process or a page fault slowed does not move
 * it, and neither does the one window with a detection in it (detection
 * reruns seldom, docs/physics.md).
 *
 * A window is timed in CPU seconds of the stepping thread, which the other
 * processes of a busy machine do not change (two dry runs at a load
 * average of 14 on two cores gave 9.4 and 1.0 ms of wall time a step for
 * one model). How much of the machine the run will get is a separate
 * factor: the median wall / CPU seconds of the stepping thread over this
 * daemon's last runs (sizing_note_run), what runs here really got. Before
 * any, the geometric mean of two guesses: the one-minute load average
 * (the run is one task more among those, on this many cores), which also
 * counts tasks waiting for the disk (at a load of 18 on two cores it said
 * 9.9), and the wall / CPU time of the windows themselves (5 to 8 then,
 * swinging from 4.8 to 12.4 between two dry runs a minute apart). Both
 * ran 2-3x above what the runs that followed got (wall / CPU 1.5-3).
 */
#include "sizing_probe.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "math/clock.h"
#include "common/sample_ring.h"

/* Untimed warm-up: chunks of 2, 4, 8... steps until they took this many
 * CPU seconds, at most PROBE_WARM_MAX_STEPS. */
#define PROBE_WARM_SECONDS 0.01
#define PROBE_WARM_MAX_STEPS 1024
/* Timed windows: each the same number of steps, the power of 2 (at most
 * PROBE_WINDOW_STEPS) that the warm-up's last chunk says takes about
 * PROBE_WINDOW_SECONDS. In steps, not until a clock runs out, so that two
 * dry runs time the same steps: a model whose pace changes in its first
 * steps (a sphere pile's from 2e-5 to 2e-4 s a step as its spheres land)
 * gave medians 2.6x apart when a loaded machine fitted fewer steps into
 * one dry run's windows than into the next one's. */
#define PROBE_WINDOWS 7
#define PROBE_WINDOW_SECONDS 0.008
#define PROBE_WINDOW_STEPS 64
/* Past PROBE_MIN_WINDOWS windows, no new one starts after this much of
 * the probe: a model whose step takes 0.1 s is timed in under a second. */
#define PROBE_MIN_WINDOWS 3
#define PROBE_BUDGET_SECONDS 0.3

int sizing_step(fdem_model *model)
{
    fdem_error err;
    memset(&err, 0, sizeof err);
    return fdem_step(model, &err);
}

/* Steps `steps` times: the steps taken, -1 when one failed; their wall
 * and CPU time into `load`. */
static int probe_run(fdem_model *model, int steps, sizing_load *load, double *cpu)
{
    double started = clock_wall_seconds(), cpu0 = clock_cpu_seconds();
    for (int taken = 0; taken < steps; taken++)
        if (sizing_step(model) != 0)
            return -1;
    *cpu = clock_cpu_seconds() - cpu0;
    load->wall += clock_wall_seconds() - started;
    load->cpu += *cpu;
    return steps;
}

/* The untimed warm-up: *taken steps (-1: one failed); returns the CPU
 * seconds a step of its last chunk took. */
static double probe_warm(fdem_model *model, int room, int *taken, sizing_load *warm_load)
{
    double spent = 0, cpu = 0;
    int chunk = 2, n = 0;
    *taken = 0;
    while (*taken < room && *taken < PROBE_WARM_MAX_STEPS && spent < PROBE_WARM_SECONDS) {
        int left = (room < PROBE_WARM_MAX_STEPS ? room : PROBE_WARM_MAX_STEPS) - *taken;
        int want = chunk < left ? chunk : left;
        n = probe_run(model, want, warm_load, &cpu);
        if (n < 0) {
            *taken = -1;
            return NAN;
        }
        *taken += n;
        spent += cpu;
        chunk *= 2;
    }
    return n > 0 ? cpu / n : NAN;
}

/* The power of 2 of steps, 1 to PROBE_WINDOW_STEPS, that takes about
 * PROBE_WINDOW_SECONDS at `pace`. */
static int probe_window_steps(double pace)
{
    if (!(pace > 0)) return 1;
    double fit = PROBE_WINDOW_SECONDS / pace;
    if (fit >= PROBE_WINDOW_STEPS) return PROBE_WINDOW_STEPS;
    return fit >= 2 ? (int)exp2(floor(log2(fit))) : 1;
}

double sizing_probe_step_seconds(fdem_model *model, double steps_left, int *taken,
                                 sizing_load *load)
{
    *taken = 0;
    double cpu, window[PROBE_WINDOWS], started = clock_wall_seconds();
    sizing_load warm_load = {0, 0};
    int room = steps_left < 1e9 ? (int)steps_left : 1000000000, warm = 0;
    double warm_pace = probe_warm(model, room, &warm, &warm_load);
    if (warm < 0)
        return NAN;
    *taken += warm;
    room -= warm;
    if (room <= 0) { /* a run this short: its own steps are the figure */
        load->wall += warm_load.wall;
        load->cpu += warm_load.cpu;
        return warm > 0 ? warm_load.cpu / warm : NAN;
    }
    int each = probe_window_steps(warm_pace), windows = 0;
    while (windows < PROBE_WINDOWS && room > 0 &&
           (windows < PROBE_MIN_WINDOWS || clock_wall_seconds() - started < PROBE_BUDGET_SECONDS)) {
        int want = room < each ? room : each;
        int n = probe_run(model, want, load, &cpu);
        if (n < 0)
            return NAN;
        *taken += n;
        room -= n;
        window[windows++] = cpu / n;
    }
    return median_in_place(window, windows);
}

/* Wall over CPU seconds of the stepping thread in the daemon's recent
 * runs (sizing_note_run): the share of the machine a run really got. */
#define RUN_SHARE_MIN_SECONDS 0.2
static pthread_mutex_t run_share_lock = PTHREAD_MUTEX_INITIALIZER;
static sample_ring run_share;

void sizing_note_run(double wall, double cpu)
{
    if (!(wall >= RUN_SHARE_MIN_SECONDS) || !(cpu > 0))
        return;
    pthread_mutex_lock(&run_share_lock);
    sample_ring_add(&run_share, wall / cpu);
    pthread_mutex_unlock(&run_share_lock);
}

/* The median of the recent runs' wall / CPU, or 0 when none ran. */
static double recent_run_factor(void)
{
    pthread_mutex_lock(&run_share_lock);
    double median = sample_ring_median(&run_share, 0);
    pthread_mutex_unlock(&run_share_lock);
    return median;
}

/* The probes' own wall / CPU seconds swing 1x to 4x between two dry runs a
 * second apart on a busy machine (a neighbour's burst lands in one probe's
 * windows and not in the next's): before any run, the median of the last
 * SAMPLE_RING_SIZE probes' figures stands for them, so a repeated dry run
 * sees nearly the same machine. */
static sample_ring probe_share;

static double recent_probe_factor(double seen)
{
    pthread_mutex_lock(&run_share_lock);
    sample_ring_add(&probe_share, seen);
    double median = sample_ring_median(&probe_share, seen);
    pthread_mutex_unlock(&run_share_lock);
    return median;
}

double sizing_load_factor(const sizing_load *load)
{
    double recent = recent_run_factor();
    if (recent > 0)
        return recent > 1.0 ? recent : 1.0;
    double average[1];
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    double seen = load->cpu > 0 && load->wall > 0 ? load->wall / load->cpu : 1.0;
    if (seen < 1.0)
        seen = 1.0;
    seen = recent_probe_factor(seen);
    if (getloadavg(average, 1) != 1 || !(average[0] >= 0) || cores < 1)
        return seen;
    /* the run is one more task among those the load average counts */
    double counted = (average[0] + 1.0) / (double)cores;
    if (counted < 1.0)
        counted = 1.0;
    return sqrt(counted * seen);
}

