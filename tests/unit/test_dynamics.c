/*
 * test_dynamics.c - the central difference scheme against closed forms:
 * free fall (exact for constant acceleration, also with a changing step),
 * the first longitudinal period of a fixed-free bar (4L/c), constraint
 * reactions in equilibrium, and a checkpoint round trip.
 */
#include <stddef.h>

#include "build_model.h"
#include "check.h"
#include "model/model.h"
#include "contact/contact.h"

static void free_fall_matches_half_g_t_squared(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 2700, 3e10, 0.25, 0, 0);
    int p = build_rectangle(m, mat, 0, 0, 0.1, 0.1, 4, 4);
    fdem_set_gravity(m, 0, -9.81);
    build_finalize(m, 0.5);
    double c0[2], c[2], v[2];
    part_centre(m, p, c0, NULL);
    run_until(m, 0.01);
    double t = fdem_get_time(m);
    part_centre(m, p, c, v);
    CHECK_REL(c0[1] - c[1], 0.5 * 9.81 * t * t, 1e-9);
    CHECK_NEAR(c[0], c0[0], 1e-12);
    /* energies belong to the start of the last step (energy.c) */
    fdem_energy en = fdem_get_energy(m);
    double drop = c0[1] - (c[1] - v[1] * fdem_get_dt(m));
    CHECK_REL(en.gravity_work, 2700 * 0.01 * 9.81 * drop, 1e-9);
    CHECK_REL(en.kinetic, en.gravity_work, 1e-6);
    fdem_model_destroy(m);
}

static void free_fall_with_changing_step(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 1000, 1e9, 0.2, 0, 0);
    int p = build_rectangle(m, mat, 0, 0, 1, 1, 2, 2);
    fdem_set_gravity(m, 0, -10);
    build_finalize(m, 0.5);
    double h = fdem_get_dt(m), c0[2], c[2];
    part_centre(m, p, c0, NULL);
    fdem_error err;
    for (int k = 0; k < 300; k++) {
        fdem_set_dt(m, h * (k % 3 == 0 ? 1.0 : k % 3 == 1 ? 0.5 : 0.8));
        CHECK(fdem_step(m, &err) == 0, "%s", err.message);
    }
    double t = fdem_get_time(m);
    part_centre(m, p, c, NULL);
    /* eq 5.9 with h_current != h_next keeps constant acceleration exact */
    CHECK_REL(c0[1] - c[1], 0.5 * 10 * t * t, 1e-9);
    fdem_model_destroy(m);
}

/* Fixed at x = 0, free at x = L, every node but the fixed ones moving at v0
 * at t = 0: the tip displacement is a triangle wave of period 4L/c. */
static void bar_period_is_4L_over_c(void)
{
    double L = 1.0, H = 0.05, E = 1e9, rho = 1000, v0 = 0.01;
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, rho, E, 0.0, 0, 0);
    int p = build_rectangle(m, mat, 0, 0, L, H, 80, 4);
    fdem_set_part_velocity(m, p, v0, 0, NULL);
    fdem_constraint_def fix = {.select = FDEM_SELECT_BOX, .box = {-1e-9, -1, 1e-9, 1},
                               .kind = FDEM_CONSTRAINT_FIX, .fix_x = 1, .fix_y = 0};
    fdem_error err;
    CHECK(fdem_add_constraint(m, &fix, &err) == 0, "%s", err.message);
    build_finalize(m, 0.5);
    double c = sqrt(E / rho), period = 4 * L / c;
    /* tip = mean x-displacement of the nodes at x = L */
    const double *x = fdem_positions(m), *x0 = fdem_initial_positions(m);
    int n = fdem_get_counts(m).nodes;
    double prev = 0, crossings[4];
    int found = 0;
    while (fdem_get_time(m) < 2.2 * period && found < 3) {
        double t_before = fdem_get_time(m);
        CHECK(fdem_step(m, &err) == 0, "%s", err.message);
        double tip = 0;
        int k = 0;
        for (int i = 0; i < n; i++)
            if (x0[2 * i] > L - 1e-9) { tip += x[2 * i] - x0[2 * i]; k++; }
        tip /= k;
        if (t_before > 0 && prev > 0 && tip <= 0) { /* downward zero crossing */
            double t_cross = t_before + fdem_get_dt(m) * prev / (prev - tip);
            crossings[found++] = t_cross;
        }
        prev = tip;
    }
    CHECK(found >= 2, "found %d crossings", found);
    if (found >= 2) {
        CHECK_REL(crossings[1] - crossings[0], period, 0.02);
        CHECK_REL(crossings[0], period / 2, 0.02);
    }
    fdem_model_destroy(m);
}

static void hanging_block_reaction_equals_weight(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 2000, 1e8, 0.3, 0.5, 0);
    build_rectangle(m, mat, 0, 0, 0.2, 0.4, 4, 8);
    fdem_constraint_def top = {.select = FDEM_SELECT_BOX, .box = {-1, 0.4 - 1e-9, 1, 1},
                               .kind = FDEM_CONSTRAINT_FIX, .fix_x = 1, .fix_y = 1};
    fdem_error err;
    fdem_add_constraint(m, &top, &err);
    fdem_set_gravity(m, 0, -9.81);
    build_finalize(m, 0.5);
    /* Damping is a fraction of the stiffest mode's, so the slow first mode
     * rings for long: compare the reaction averaged over ~10 of its periods. */
    run_until(m, 0.04);
    double rx = 0, ry = 0, t0 = fdem_get_time(m);
    fdem_error e2;
    while (fdem_get_time(m) < 0.1) {
        if (fdem_step(m, &e2)) build_die("step", &e2);
        const double *r = fdem_constraint_forces(m);
        rx += r[0] * fdem_get_dt(m);
        ry += r[1] * fdem_get_dt(m);
    }
    rx /= fdem_get_time(m) - t0;
    ry /= fdem_get_time(m) - t0;
    CHECK_REL(ry, 2000 * 0.2 * 0.4 * 9.81, 0.01);
    CHECK_NEAR(rx, 0, 1e-3 * ry);
    /* energy balance: kinetic + elastic + damping = gravity work + external work */
    fdem_energy en = fdem_get_energy(m);
    double lhs = en.kinetic + en.elastic + en.damping, rhs = en.gravity_work + en.external_work;
    CHECK_REL(lhs, rhs, 0.02);
    fdem_model_destroy(m);
}

/* The first fields of a checkpoint (checkpoint.c), to damage one on purpose. */
typedef struct checkpoint_probe {
    uint32_t magic, version;
    int32_t nodes, elements, joints, constraints;
    int64_t step;
} checkpoint_probe;

/* A block lands sliding on another, is checkpointed while its stick
 * springs hold history, and a model rebuilt from the checkpoint steps on to
 * the same bits as the one that wrote it: positions, velocities, every
 * energy account. */
static void checkpoint_round_trip_continues_identically(void)
{
    fdem_model *a = fdem_model_create(), *b = fdem_model_create();
    fdem_model *ms[2] = {a, b};
    for (int k = 0; k < 2; k++) {
        int mat = build_material(ms[k], 1000, 1e8, 0.3, 0.3, 0.2);
        build_fix_part(ms[k], build_rectangle(ms[k], mat, 0, 0, 0.3, 0.1, 9, 3));
        int q = build_rectangle(ms[k], mat, 0.0, 0.1, 0.1, 0.05, 3, 2);
        fdem_set_part_velocity(ms[k], q, 0.5, 0, NULL); /* slides on it: friction history */
        fdem_set_gravity(ms[k], 0, -9.81);
        build_finalize(ms[k], 0.5);
    }
    fdem_error err;
    for (int s = 0; s < 1500; s++) fdem_step(a, &err);
    CHECK(fdem_get_counts(a).contacts > 0, "no contact at the checkpoint");
    CHECK(contact_history_checkpoint_size(&a->contact) > 0, "no stick spring to carry");
    size_t size = fdem_checkpoint_size(a);
    void *buf = malloc(size);
    CHECK(fdem_checkpoint_write(a, buf, size) == 0, "write");
    CHECK(fdem_checkpoint_read(b, buf, size, &err) == 0, "%s", err.message);
    CHECK(fdem_checkpoint_read(b, buf, size - 8, &err) < 0, "truncated checkpoint accepted");
    fdem_energy ea = fdem_get_energy(a), eb = fdem_get_energy(b);
    CHECK(memcmp(&ea, &eb, sizeof ea) == 0, "energies differ right after restore");
    for (int s = 0; s < 1500; s++) { fdem_step(a, &err); fdem_step(b, &err); }
    int n = fdem_get_counts(a).nodes;
    size_t nb = sizeof(double) * 2 * (size_t)n;
    CHECK(memcmp(fdem_positions(a), fdem_positions(b), nb) == 0, "positions differ after restore");
    CHECK(memcmp(fdem_velocities(a), fdem_velocities(b), nb) == 0, "velocities differ after restore");
    ea = fdem_get_energy(a);
    eb = fdem_get_energy(b);
    CHECK(memcmp(&ea, &eb, sizeof ea) == 0, "energies differ after restore");
    CHECK(ea.friction > 0, "nothing slid");
    CHECK(fdem_get_step(b) == 3000, "step %lld", (long long)fdem_get_step(b));
    /* a checkpoint that claims an impossible state is refused */
    int64_t negative = -5;
    memcpy((char *)buf + offsetof(checkpoint_probe, step), &negative, sizeof negative);
    CHECK(fdem_checkpoint_read(b, buf, size, &err) < 0, "negative step accepted");
    free(buf);
    fdem_model_destroy(a);
    fdem_model_destroy(b);
}

/* A small elastic square of side `side` in `cells` x `cells` cells (two
 * triangles each), built and finalized: the tests below need a model, not
 * particular physics. */
static fdem_model *small_square(double side, int cells)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 1000, 1e8, 0.3, 0, 0.2);
    build_rectangle(m, mat, 0, 0, side, side, cells, cells);
    build_finalize(m, 0.5);
    return m;
}

/* The checkpoint of a run restored halfway and stepped on is the same
 * bytes as that of the run that never stopped, with contact and without:
 * a restart leaves nothing behind, not even a flag. Without contact the
 * restore used to set need_detect where a fresh model has none, so the two
 * files differed in one header byte though every number was the same. */
static void checkpoint_after_a_restart_is_the_same_bytes(void)
{
    for (int contact = 0; contact < 2; contact++) {
        fdem_model *ms[3];
        for (int k = 0; k < 3; k++) {
            fdem_model *m = ms[k] = fdem_model_create();
            int mat = build_material(m, 1000, 1e8, 0.3, 0.3, 0.2);
            int q = build_rectangle(m, mat, 0.0, 0.1, 0.1, 0.05, 3, 2);
            if (contact) build_fix_part(m, build_rectangle(m, mat, 0, 0, 0.3, 0.1, 9, 3));
            fdem_set_part_velocity(m, q, 0.5, -0.1, NULL);
            fdem_set_gravity(m, 0, -9.81);
            build_finalize(m, 0.5);
        }
        fdem_model *whole = ms[0], *first = ms[1], *second = ms[2];
        fdem_error err;
        for (int s = 0; s < 800; s++) fdem_step(whole, &err);
        for (int s = 0; s < 400; s++) fdem_step(first, &err);
        size_t half = fdem_checkpoint_size(first);
        void *hb = malloc(half);
        CHECK(fdem_checkpoint_write(first, hb, half) == 0, "write at step 400");
        CHECK(fdem_checkpoint_read(second, hb, half, &err) == 0, "%s", err.message);
        for (int s = 0; s < 400; s++) fdem_step(second, &err);
        size_t na = fdem_checkpoint_size(whole), nb = fdem_checkpoint_size(second);
        CHECK(na == nb, "%s: checkpoint sizes %zu and %zu", contact ? "contact" : "no contact",
              na, nb);
        unsigned char *a = malloc(na), *b = malloc(nb);
        CHECK(fdem_checkpoint_write(whole, a, na) == 0 && fdem_checkpoint_write(second, b, nb) == 0,
              "write at step 800");
        size_t first_diff = na;
        for (size_t i = 0; i < na && first_diff == na; i++)
            if (a[i] != b[i]) first_diff = i;
        CHECK(first_diff == na, "%s: the restarted run's checkpoint differs from byte %zu on",
              contact ? "contact" : "no contact", first_diff);
        CHECK(!contact || fdem_get_energy(whole).friction > 0, "the block never slid on the slab");
        free(a);
        free(b);
        free(hb);
        for (int k = 0; k < 3; k++) fdem_model_destroy(ms[k]);
    }
}

/* A checkpoint whose header was damaged (negative step, NaN time) is
 * refused and leaves the model as it was. */
static void checkpoint_with_a_bad_header_is_refused(void)
{
    fdem_model *m = small_square(0.1, 3);
    fdem_error err;
    for (int s = 0; s < 10; s++) fdem_step(m, &err);
    size_t size = fdem_checkpoint_size(m);
    unsigned char *buf = malloc(size);
    CHECK(fdem_checkpoint_write(m, buf, size) == 0, "write");
    const size_t step_at = 6 * sizeof(int32_t), time_at = step_at + sizeof(int64_t);
    int64_t negative = -5;
    memcpy(buf + step_at, &negative, sizeof negative);
    CHECK(fdem_checkpoint_read(m, buf, size, &err) < 0, "a negative step was accepted");
    CHECK(strstr(err.message, "negative step") != NULL, "message: %s", err.message);
    CHECK(fdem_get_step(m) == 10, "the model changed: step %lld", (long long)fdem_get_step(m));
    int64_t ten = 10;
    double nan_time = NAN;
    memcpy(buf + step_at, &ten, sizeof ten);
    memcpy(buf + time_at, &nan_time, sizeof nan_time);
    CHECK(fdem_checkpoint_read(m, buf, size, &err) < 0, "a NaN time was accepted");
    free(buf);
    fdem_model_destroy(m);
}

/* Two nodes moving at 1e308 m/s keep a finite position and velocity, but
 * the finiteness check sums them and overflows: the step fails, and the
 * error names one of them and its element. It said "element -1 (node -1)"
 * when it looked only for a non-finite node. */
static void overflow_of_finite_values_names_a_node(void)
{
    fdem_model *m = small_square(0.1, 3);
    fdem_error err;
    CHECK(fdem_step(m, &err) == 0, "%s", err.message);
    m->vel[0] = m->vel[2] = 1e308;
    CHECK(fdem_step(m, &err) < 0, "a step whose sums overflow passed");
    int e = -1, node = -1;
    const char *at = strstr(err.message, "node ");
    CHECK(at && sscanf(at, "node %d of element %d", &node, &e) == 2, "message: %s", err.message);
    CHECK((node == 0 || node == 1) && e >= 0 && e < m->elem_count, "node %d, element %d: %s",
          node, e, err.message);
    CHECK(err.kind == FDEM_ITEM_ELEMENT && err.item == e, "kind %d item %d", (int)err.kind,
          err.item);
    fdem_model_destroy(m);
}

/* examples/incline.json takes 160000 steps of 3.125e-6 s to its end at
 * 0.5 s. Time summed plainly ended 7e-13 s short (the daemon then took a
 * 160001st step of 7e-13 s, and every snapshot time was off by as much);
 * compensated, it is the sum to within a rounding. A checkpoint carries
 * the compensation: a restored model goes on to the same time bits. */
static void time_after_many_steps_is_their_sum(void)
{
    fdem_model *m = small_square(1, 1);
    fdem_error err;
    const double dt = 3.125e-6;
    fdem_set_dt(m, dt);
    size_t size = 0;
    unsigned char *buf = NULL;
    for (int s = 1; s <= 160000; s++) {
        CHECK(fdem_step(m, &err) == 0, "%s", err.message);
        if (s == 100001) { /* a checkpoint partway */
            size = fdem_checkpoint_size(m);
            buf = malloc(size);
            CHECK(buf && fdem_checkpoint_write(m, buf, size) == 0, "write");
        }
    }
    double t = fdem_get_time(m);
    CHECK(fabs(t - 0.5) <= 0x1p-53, "t = %.17g after 160000 steps of %g s (off by %.3g s)", t, dt,
          t - 0.5);
    fdem_model *r = small_square(1, 1);
    fdem_set_dt(r, dt);
    CHECK(fdem_checkpoint_read(r, buf, size, &err) == 0, "%s", err.message);
    for (int s = 100001; s < 160000; s++) fdem_step(r, &err);
    CHECK(memcmp(&t, &(double){fdem_get_time(r)}, sizeof t) == 0, "restored: t = %.17g, not %.17g",
          fdem_get_time(r), t);
    free(buf);
    fdem_model_destroy(r);
    fdem_model_destroy(m);
}

CHECK_MAIN(T(free_fall_matches_half_g_t_squared), T(free_fall_with_changing_step),
           T(bar_period_is_4L_over_c), T(hanging_block_reaction_equals_weight),
           T(checkpoint_round_trip_continues_identically),
           T(checkpoint_after_a_restart_is_the_same_bytes), T(checkpoint_with_a_bad_header_is_refused),
           T(overflow_of_finite_values_names_a_node),
           T(time_after_many_steps_is_their_sum))
