/*
 * test_snapshot.c - snapshot_take() copies exactly what the engine reports
 * at that step, only the requested fields, and never aliases engine memory.
 */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "result_fixture.h"
#include "state/snapshot.h"

static int equal_doubles(const double *a, const double *b, size_t n)
{
    return a && b && memcmp(a, b, n * sizeof *a) == 0;
}

static void test_snapshot_copies_requested_fields(void)
{
    fdem_model *m = fixture_model(1, 1, NULL);
    CHECK(m != NULL, "fixture model");
    if (!m) return;
    CHECK(fixture_step(m, 10) == 0, "stepping");
    snapshot *s = snapshot_take(m, CASE_FIELD_POSITION | CASE_FIELD_VELOCITY);
    CHECK(s != NULL, "snapshot_take");
    if (s) {
        fdem_counts c = fdem_get_counts(m);
        CHECK(s->step == 10 && s->step == fdem_get_step(m), "step %lld", (long long)s->step);
        CHECK(s->time == fdem_get_time(m), "time %g vs %g", s->time, fdem_get_time(m));
        CHECK(s->nodes == c.nodes && s->elements == c.elements && s->joints == c.joints &&
              s->constraints == 2, "counts");
        CHECK(s->fields == (CASE_FIELD_POSITION | CASE_FIELD_VELOCITY), "fields %#x", s->fields);
        CHECK(equal_doubles(s->position, fdem_positions(m), 2 * (size_t)c.nodes), "position");
        CHECK(equal_doubles(s->velocity, fdem_velocities(m), 2 * (size_t)c.nodes), "velocity");
        CHECK(s->stress == NULL, "stress was not requested");
        CHECK(equal_doubles(s->constraint_force, fdem_constraint_forces(m), 4),
              "constraint forces");
        fdem_energy e = fdem_get_energy(m);
        CHECK(s->energy.kinetic == e.kinetic && s->energy.elastic == e.elastic, "energies");
        CHECK(s->energy.kinetic > 0, "gravity made the model move: kinetic %g", s->energy.kinetic);
    }
    snapshot_free(s);
    fdem_model_destroy(m);
}

static void test_snapshot_is_a_copy(void)
{
    fdem_model *m = fixture_model(0, 0, NULL);
    CHECK(m != NULL, "fixture model");
    if (!m) return;
    CHECK(fixture_step(m, 3) == 0, "stepping");
    snapshot *s = snapshot_take(m, CASE_FIELD_POSITION);
    CHECK(s != NULL, "snapshot_take");
    if (s) {
        size_t n = 2 * (size_t)s->nodes;
        double *saved = malloc(n * sizeof *saved);
        memcpy(saved, s->position, n * sizeof *saved);
        CHECK(s->position != fdem_positions(m), "position aliases engine memory");
        CHECK(fixture_step(m, 50) == 0, "stepping on");
        /* The free-falling block has moved, the snapshot has not. */
        CHECK(!equal_doubles(s->position, fdem_positions(m), n), "the model did not move");
        CHECK(equal_doubles(s->position, saved, n), "the snapshot changed with the model");
        free(saved);
    }
    snapshot_free(s);
    fdem_model_destroy(m);
}

static void test_snapshot_stress_matches_engine(void)
{
    fdem_model *m = fixture_model(1, 1, NULL);
    CHECK(m != NULL, "fixture model");
    if (!m) return;
    CHECK(fixture_step(m, 20) == 0, "stepping");
    snapshot *s = snapshot_take(m, CASE_FIELD_STRESS | CASE_FIELD_DAMAGE);
    CHECK(s != NULL, "snapshot_take");
    if (s) {
        size_t n = 3 * (size_t)s->elements;
        double *want = malloc(n * sizeof *want);
        fdem_element_stress(m, want);
        CHECK(equal_doubles(s->stress, want, n), "stress differs from fdem_element_stress");
        double largest = 0;
        for (size_t i = 0; i < n; i++) largest = fmax(largest, fabs(want[i]));
        CHECK(largest > 0, "the fixed block under gravity and load carries stress");
        CHECK(s->position == NULL && s->velocity == NULL, "position/velocity not requested");
        free(want);
    }
    snapshot_free(s);
    fdem_model_destroy(m);
}

static void test_snapshot_damage_of_fracturing_model(void)
{
    fdem_model *m = fixture_model(1, 1, NULL);
    CHECK(m != NULL, "fixture model");
    if (!m) return;
    fdem_counts c = fdem_get_counts(m);
    CHECK(c.joints > 0, "a fracturing part must have joints, the model has %d", c.joints);
    /* The result file needs damage of every fracturing model, so it is
     * copied even when not requested; only the field bit says "asked for". */
    snapshot *plain = snapshot_take(m, CASE_FIELD_POSITION);
    snapshot *asked = snapshot_take(m, CASE_FIELD_DAMAGE);
    CHECK(plain && asked, "snapshot_take");
    if (plain && asked && c.joints > 0) {
        CHECK(equal_doubles(plain->damage, fdem_joint_damage(m), (size_t)c.joints),
              "damage copied though not requested");
        CHECK(!(plain->fields & CASE_FIELD_DAMAGE), "damage bit set though not requested");
        CHECK(equal_doubles(asked->damage, fdem_joint_damage(m), (size_t)c.joints), "damage");
        CHECK(asked->fields == CASE_FIELD_DAMAGE, "fields %#x", asked->fields);
        CHECK(asked->joints == c.joints, "joints %d", asked->joints);
    }
    snapshot_free(plain);
    snapshot_free(asked);
    fdem_model_destroy(m);
}

static void test_snapshot_without_joints_has_no_damage(void)
{
    fdem_model *m = fixture_model(0, 0, NULL);
    CHECK(m != NULL, "fixture model");
    if (!m) return;
    snapshot *s = snapshot_take(m, CASE_FIELD_POSITION | CASE_FIELD_DAMAGE);
    CHECK(s != NULL, "snapshot_take");
    if (s) {
        CHECK(s->joints == 0 && s->damage == NULL, "damage without joints");
        CHECK(s->fields == CASE_FIELD_POSITION, "fields %#x claims damage", s->fields);
        CHECK(s->constraints == 0 && s->constraint_force == NULL, "no constraints");
        CHECK(s->step == 0 && s->time == 0, "first snapshot at t = 0");
    }
    snapshot_free(s);
    CHECK(snapshot_take(NULL, CASE_FIELD_POSITION) == NULL, "NULL model");
    snapshot_free(NULL);
    fdem_model_destroy(m);
}

/* 3D: three numbers per node and per constraint, six stress components
 * per element, exactly the engine's. */
static void test_snapshot_of_a_3d_model(void)
{
    fdem_model *m = fixture_model_3d(1, NULL);
    CHECK(m != NULL, "3D fixture model");
    if (!m) return;
    CHECK(fixture_step(m, 20) == 0, "stepping");
    snapshot *s = snapshot_take(m, CASE_FIELD_POSITION | CASE_FIELD_VELOCITY | CASE_FIELD_STRESS);
    CHECK(s != NULL, "snapshot_take");
    if (s) {
        size_t nodes = (size_t)s->nodes, n = 6 * (size_t)s->elements;
        CHECK(s->dimension == 3 && s->stress_components == 6, "dimension %d, %d components",
              s->dimension, s->stress_components);
        CHECK(equal_doubles(s->position, fdem_positions(m), 3 * nodes), "position");
        CHECK(equal_doubles(s->velocity, fdem_velocities(m), 3 * nodes), "velocity");
        CHECK(equal_doubles(s->constraint_force, fdem_constraint_forces(m), 6),
              "constraint forces");
        double *want = malloc(n * sizeof *want);
        fdem_element_stress(m, want);
        CHECK(equal_doubles(s->stress, want, n), "stress differs from fdem_element_stress");
        free(want);
    }
    snapshot_free(s);
    fdem_model_destroy(m);
}

/* x - x0 per number, computed here as a reader of result.h5 would. */
static int is_position_minus_position0(const fdem_model *m, const double *u, size_t n)
{
    const double *x = fdem_positions(m), *x0 = fdem_initial_positions(m);
    double *want = malloc(n * sizeof *want);
    for (size_t i = 0; want && i < n; i++) want[i] = x[i] - x0[i];
    int same = equal_doubles(u, want, n);
    free(want);
    return same;
}

/* Displacement alone, in 2D and 3D: position - initial position to the
 * bit, without position being asked for; nonzero once the model moved. */
static void test_snapshot_displacement_is_position_minus_position0(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *m = dim == 3 ? fixture_model_3d(1, NULL) : fixture_model(1, 1, NULL);
        CHECK(m != NULL, "%dD fixture model", dim);
        if (!m) continue;
        snapshot *s0 = snapshot_take(m, CASE_FIELD_DISPLACEMENT);
        CHECK(fixture_step(m, 30) == 0, "stepping");
        snapshot *s = snapshot_take(m, CASE_FIELD_DISPLACEMENT);
        CHECK(s0 && s && s0->displacement && s->displacement, "snapshot_take");
        if (s0 && s && s0->displacement && s->displacement) {
            size_t n = (size_t)dim * (size_t)s->nodes;
            CHECK(s->fields == CASE_FIELD_DISPLACEMENT, "%dD fields %#x", dim, s->fields);
            CHECK(s->position == NULL && s->velocity == NULL, "%dD: only displacement", dim);
            CHECK(s->displacement != fdem_positions(m), "displacement aliases engine memory");
            CHECK(is_position_minus_position0(m, s->displacement, n),
                  "%dD displacement is not position - position0", dim);
            double moved = 0;
            for (size_t i = 0; i < n; i++) moved = fmax(moved, fabs(s->displacement[i]));
            CHECK(moved > 0, "%dD: the model did not move", dim);
            size_t nonzero = 0;
            for (size_t i = 0; i < n; i++) nonzero += s0->displacement[i] != 0;
            CHECK(nonzero == 0, "%dD: %zu displacements nonzero at step 0", dim, nonzero);
        }
        snapshot_free(s0);
        snapshot_free(s);
        fdem_model_destroy(m);
    }
}

/* Taking displacement every step changes nothing in the model: two
 * copies, one watched and one not, step to the same bits. */
static void test_snapshot_displacement_leaves_the_run_alone(void)
{
    fdem_model *watched = fixture_model(1, 1, NULL), *alone = fixture_model(1, 1, NULL);
    CHECK(watched && alone, "fixture models");
    for (int i = 0; watched && alone && i < 40; i++) {
        snapshot *s = snapshot_take(watched, CASE_FIELD_DISPLACEMENT | CASE_FIELD_POSITION);
        CHECK(s != NULL, "snapshot_take");
        snapshot_free(s);
        CHECK(fixture_step(watched, 1) == 0 && fixture_step(alone, 1) == 0, "stepping");
    }
    if (watched && alone) {
        size_t n = 2 * (size_t)fdem_get_counts(alone).nodes;
        CHECK(equal_doubles(fdem_positions(watched), fdem_positions(alone), n), "positions");
        CHECK(equal_doubles(fdem_velocities(watched), fdem_velocities(alone), n), "velocities");
        fdem_energy a = fdem_get_energy(watched), b = fdem_get_energy(alone);
        CHECK(memcmp(&a, &b, sizeof a) == 0, "energies");
    }
    fdem_model_destroy(watched);
    fdem_model_destroy(alone);
}

/* A model with stages: its stage and every element's flag, a copy (all 1
 * while the engine keeps no flags, the engine's once it does); a model
 * without stages: stage -1 and no flags. */
static void test_snapshot_stage_and_active(void)
{
    fdem_model *m = fixture_model_staged(NULL), *plain = fixture_model(0, 1, NULL);
    CHECK(m && plain, "fixture models");
    if (m && plain) {
        int elements = fdem_get_counts(m).elements;
        snapshot *s = snapshot_take(m, 0), *p = snapshot_take(plain, CASE_FIELD_POSITION);
        CHECK(s && s->stage == 0 && s->active, "stage %d at t = 0", s ? s->stage : -2);
        for (int e = 0; s && s->active && e < elements; e++)
            CHECK(s->active[e] == 1, "element %d inactive at t = 0", e);
        CHECK(p && p->stage == -1 && p->active == NULL, "a model without stages has a stage");
        snapshot_free(s);
        snapshot_free(p);
        CHECK(fixture_step(m, 2) == 0, "stepping");
        s = snapshot_take(m, 0);
        const uint8_t *flags = fdem_element_active(m);
        CHECK(s && s->stage == 1 && flags && s->active != flags, "stage %d after 2 steps",
              s ? s->stage : -2);
        for (int e = 0; s && flags && e < elements; e++)
            CHECK(s->active[e] == flags[e] && flags[e] == (e < 14), "element %d: %d, engine %d",
                  e, s->active[e], flags[e]);
        snapshot_free(s);
    }
    fdem_model_destroy(m);
    fdem_model_destroy(plain);
}

CHECK_MAIN(T(test_snapshot_copies_requested_fields), T(test_snapshot_is_a_copy),
           T(test_snapshot_stress_matches_engine), T(test_snapshot_damage_of_fracturing_model),
           T(test_snapshot_without_joints_has_no_damage), T(test_snapshot_of_a_3d_model),
           T(test_snapshot_displacement_is_position_minus_position0),
           T(test_snapshot_displacement_leaves_the_run_alone), T(test_snapshot_stage_and_active))
