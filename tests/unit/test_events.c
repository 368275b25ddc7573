/*
 * test_events.c - fracture events (contract 5.4) in both dimensions: a bar
 * pulled apart gives one event per broken joint, in (step, joint) order,
 * whose energies add up to the fracture account of the broken joints and,
 * the bar's other joints having stayed almost undamaged, to energy.fracture
 * to 1 %; the joints across the crack break in tension, each dissipating
 * G_I times its face; 1 and 2 threads give the same
 * events; a checkpoint taken mid-crack with events not drained restores to
 * the same history; the mode rule on hand-made points.
 */
#include "pulled_bar.h" /* before model.h, whose `part` its helpers' parameters would shadow */
#include "check.h"
#include "kernel/joint_law.h"
#include "model/model.h"

#include <stdlib.h>
#include <string.h>

typedef struct history {
    fdem_event *ev;
    int count, capacity;
} history;

/* Slow enough that the crack localises before the other sections soften
 * much: the joints left damaged hold under 1 % of the fracture account
 * (at 5 m/s, 23 % in 2D), and a crack pulled open in pure mode I across
 * the bar dissipates its G_I times its area. */
#define SPEED 0.5

static void history_drain(fdem_model *m, history *h)
{
    int n = fdem_event_count(m);
    if (h->count + n > h->capacity) {
        h->capacity = 2 * (h->count + n) + 16;
        h->ev = realloc(h->ev, sizeof *h->ev * (size_t)h->capacity);
        if (!h->ev) abort();
    }
    h->count += fdem_drain_events(m, h->ev + h->count, n);
}

/* Steps until the bar is in two pieces and 200 steps on, draining every
 * `drain_every` steps; returns the steps taken. */
static int run_bar(fdem_model *m, history *h, int drain_every, int max_steps)
{
    fdem_error err;
    int s = 0, after = 0;
    while (s < max_steps && after < 200) {
        if (fdem_step(m, &err)) build_die("step", &err);
        s++;
        if (fdem_get_counts(m).fragments >= 2) after++;
        if (s % drain_every == 0) history_drain(m, h);
    }
    history_drain(m, h);
    return s;
}

static int joint_is_damaged_unbroken(const fdem_model *m, int j)
{
    return m->joint_damage[j] > 0 && m->joint_damage[j] < 1;
}

/* The initial length (2D) or area (3D) of joint j's face A. */
static double joint_face_size(const fdem_model *m, int j)
{
    int D = m->dim;
    const int32_t *n = m->joint_node + 2 * (size_t)D * (size_t)j;
    double e[2][3] = {{0}};
    for (int i = 1; i < D; i++)
        for (int d = 0; d < D; d++) e[i - 1][d] = m->pos0[D * n[i] + d] - m->pos0[D * n[0] + d];
    if (D == 2) return hypot(e[0][0], e[0][1]);
    double c[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                   e[0][0] * e[1][1] - e[0][1] * e[1][0]};
    return 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

/* What every run of either bar must show. */
static void check_bar_events(int dimension)
{
    fdem_model *m = pulled_bar(dimension, 1, SPEED);
    history h = {0};
    run_bar(m, &h, 7, 40000);
    fdem_counts c = fdem_get_counts(m);
    fdem_energy e = fdem_get_energy(m);
    CHECK(c.fragments >= 2, "%dD bar did not break", dimension);
    CHECK(h.count == c.broken_joints, "%d events, %d broken joints", h.count, c.broken_joints);
    double events = 0, broken = 0, all = 0, damaged = 0, worst_g = 0;
    int ordered = 1, unique = 1, tensile_across = 0, across = 0;
    const double G_I = 10; /* build_fracturing_rock */
    uint8_t *seen = calloc((size_t)c.joints, 1);
    for (int k = 0; k < h.count; k++) {
        const fdem_event *v = &h.ev[k];
        events += v->energy;
        if (k && (v->time < h.ev[k - 1].time ||
                  (v->time == h.ev[k - 1].time && v->joint <= h.ev[k - 1].joint)))
            ordered = 0;
        if (v->joint < 0 || v->joint >= c.joints || seen[v->joint]++) unique = 0;
        else CHECK(m->joint_damage[v->joint] >= 1, "event of joint %d, not broken", v->joint);
        CHECK(v->mode >= 1 && v->mode <= 3, "mode %d", v->mode);
        CHECK(v->position[0] > -0.01 && v->position[0] < 0.11 && v->position[1] > -0.001 &&
                  v->position[1] < 0.011, "event %d at (%g, %g) outside the bar", k,
              v->position[0], v->position[1]);
        CHECK(v->time > 0 && v->time <= fdem_get_time(m), "event time %g", v->time);
        /* a joint whose face is normal to the bar (all its nodes at one x)
         * is pulled straight open */
        const int32_t *n = m->joint_node + 2 * (size_t)dimension * (size_t)v->joint;
        int normal = 1;
        for (int i = 1; i < dimension; i++)
            normal &= fabs(m->pos0[dimension * n[i]] - m->pos0[dimension * n[0]]) < 1e-12;
        across += normal;
        tensile_across += normal && v->mode == JOINT_MODE_TENSILE;
        if (normal) {
            double face = joint_face_size(m, v->joint);
            worst_g = fmax(worst_g, fabs(v->energy / (G_I * face) - 1));
        }
    }
    for (int j = 0; j < c.joints; j++) {
        all += m->joint_fracture[j];
        if (m->joint_damage[j] >= 1) broken += m->joint_fracture[j];
        else if (joint_is_damaged_unbroken(m, j)) damaged += m->joint_fracture[j];
    }
    CHECK(ordered, "events not in (time, joint) order");
    CHECK(unique, "a joint has two events or an index out of range");
    CHECK_REL(events, broken, 1e-12);
    CHECK_REL(all, e.fracture, 1e-9);
    /* the joints left damaged but whole hold under 1 % of the account */
    CHECK(damaged <= 0.01 * e.fracture, "damaged, unbroken joints hold %g of %g J", damaged,
          e.fracture);
    CHECK_REL(events, e.fracture, 0.01);
    CHECK(across > 0 && tensile_across == across, "%d of %d joints across the bar broke tensile",
          tensile_across, across);
    CHECK(worst_g <= 0.05, "a joint across the bar dissipated G_I A %+.2g %%", 100 * worst_g);
    int modes[4] = {0};
    for (int k = 0; k < h.count; k++) modes[h.ev[k].mode]++;
    fprintf(stderr, "  %dD bar: %d events (%d tensile, %d shear, %d mixed), sum %.6g J, "
            "fracture %.6g J, damaged unbroken %.3g J; across the bar each within %.2g %% of "
            "G_I A\n", dimension, h.count, modes[1], modes[2], modes[3], events, e.fracture,
            damaged, 100 * worst_g);
    free(seen);
    free(h.ev);
    fdem_model_destroy(m);
}

static void pulled_bar_events_2d(void) { check_bar_events(2); }
static void pulled_bar_events_3d(void) { check_bar_events(3); }

static void same_events_on_two_threads(int dimension)
{
    fdem_model *a = pulled_bar(dimension, 1, SPEED), *b = pulled_bar(dimension, 2, SPEED);
    history ha = {0}, hb = {0};
    run_bar(a, &ha, 1, 40000);
    run_bar(b, &hb, 13, 40000);
    CHECK(ha.count > 0 && ha.count == hb.count, "%d events on 1 thread, %d on 2", ha.count,
          hb.count);
    CHECK(ha.count == hb.count && memcmp(ha.ev, hb.ev, sizeof *ha.ev * (size_t)ha.count) == 0,
          "the events differ");
    free(ha.ev);
    free(hb.ev);
    fdem_model_destroy(a);
    fdem_model_destroy(b);
}

static void two_threads_same_events(void)
{
    same_events_on_two_threads(2);
    same_events_on_two_threads(3);
}

/* Steps a new bar to `at`, checkpoints it (events not drained), restores
 * the checkpoint into another new bar and steps that on to `steps`:
 * returns its events. *softening gets how many of the joints that break
 * later were damaged at the checkpoint. */
static history restored_run(int dimension, int at, int steps, int *waiting, int *softening)
{
    fdem_model *m = pulled_bar(dimension, 1, SPEED);
    fdem_error err;
    for (int s = 0; s < at; s++)
        if (fdem_step(m, &err)) build_die("step", &err);
    size_t size = fdem_checkpoint_size(m);
    void *buf = malloc(size);
    CHECK(buf && fdem_checkpoint_write(m, buf, size) == 0, "checkpoint");
    fdem_model *back = pulled_bar(dimension, 1, SPEED);
    CHECK(fdem_checkpoint_read(back, buf, size, &err) == 0, "restore: %s", err.message);
    *waiting = fdem_event_count(back);
    CHECK(*waiting == fdem_event_count(m), "%d events waiting, %d restored", fdem_event_count(m),
          *waiting);
    history h = {0};
    history_drain(back, &h);
    for (int s = at; s < steps; s++) {
        if (fdem_step(back, &err)) build_die("step", &err);
        history_drain(back, &h);
    }
    *softening = 0;
    for (int j = 0; j < m->joint_count; j++)
        *softening += joint_is_damaged_unbroken(m, j) && back->joint_damage[j] >= 1;
    free(buf);
    fdem_model_destroy(back);
    fdem_model_destroy(m);
    return h;
}

/* Checkpoints taken while the joints that break are softening, and at the
 * step they break with their events not drained: the restored model
 * reports the same history, energies included, to the bit. */
static void checkpoint_keeps_events(void)
{
    for (int dimension = 2; dimension <= 3; dimension++) {
        fdem_model *ref = pulled_bar(dimension, 1, SPEED);
        history whole = {0};
        fdem_error err;
        int first = 0, steps = 0;
        for (int after = 0; steps < 40000 && after < 200; steps++) {
            if (fdem_step(ref, &err)) build_die("step", &err);
            after += fdem_get_counts(ref).fragments >= 2;
            if (!first && fdem_event_count(ref)) first = steps + 1;
            history_drain(ref, &whole);
        }
        CHECK(whole.count > 1 && first > 0, "%dD: %d events", dimension, whole.count);
        int at[2] = {first - 20, first};
        for (int k = 0; k < 2; k++) {
            int waiting = 0, softening = 0;
            history h = restored_run(dimension, at[k], steps, &waiting, &softening);
            CHECK(h.count == whole.count &&
                      memcmp(h.ev, whole.ev, sizeof *h.ev * (size_t)h.count) == 0,
                  "%dD: %d events after a restore at step %d, %d without", dimension, h.count,
                  at[k], whole.count);
            CHECK(k == 0 ? softening > 0 : waiting > 0,
                  "%dD step %d: %d joints softening, %d events waiting", dimension, at[k],
                  softening, waiting);
            fprintf(stderr, "  %dD: restored at step %d with %d events waiting and %d of the "
                    "joints that break softening: the same %d events\n", dimension, at[k],
                    waiting, softening, h.count);
            free(h.ev);
        }
        free(whole.ev);
        fdem_model_destroy(ref);
    }
}

/* The rule of docs/physics.md on points of a joint with G_I = 10,
 * G_II = 50 J/m^2: each point's opening and sliding beyond the elastic
 * limits, over the softening spans. */
static void mode_rule(void)
{
    joint_law law = joint_law_make(1e12, 1e6, 3e6, tan(30 * M_PI / 180), 10, 50);
    double dp = 1e6 / 1e12, sp = 3e6 / 1e12;
    double span_n = softening_span(1e6, dp, 10), span_s = softening_span(3e6, sp, 50);
    struct { double dn, ds; int mode; } cases[] = {
        {1.0, 0.0, JOINT_MODE_TENSILE}, {1.0, 0.3, JOINT_MODE_TENSILE},
        {0.0, 1.0, JOINT_MODE_SHEAR},   {0.3, 1.0, JOINT_MODE_SHEAR},
        {0.8, 0.8, JOINT_MODE_MIXED},   {1.0, 0.4, JOINT_MODE_MIXED},
    };
    const joint_slip none = {{0, 0}, 0};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        joint_point g[2];
        const double still[2] = {0, 0}, slid[2] = {sp + cases[k].ds * span_s, 0};
        joint_point_measure(&law, 0, still, &none, &g[0]); /* an unstrained point beside it */
        joint_point_measure(&law, dp + cases[k].dn * span_n, slid, &none, &g[1]);
        CHECK(joint_points_mode(&law, g, 2) == cases[k].mode, "Dn %g Ds %g: mode %d, want %d",
              cases[k].dn, cases[k].ds, joint_points_mode(&law, g, 2), cases[k].mode);
    }
}

CHECK_MAIN(T(pulled_bar_events_2d), T(pulled_bar_events_3d), T(two_threads_same_events),
           T(checkpoint_keeps_events), T(mode_rule))
