/*
 * test_state_json.c - the JSON of GET /cases/ID/state: field selection,
 * shapes, exact round trip of doubles, and null for non-finite values.
 * Snapshots are built by hand so the expected numbers are known exactly.
 */
#include <jansson.h>
#include <math.h>
#include <stdlib.h>

#include "case/case.h"
#include "check.h"
#include "state/state_json.h"

static double position[4] = {0.1 + 0.2, -1.5, 1e-300, 2.5e17};
static double velocity[4] = {1.0, -2.0, 3.0, -4.0};
static double stress[3] = {-3e6, 1.25e5, 7.0};
static double damage[2] = {0.0, 0.75};
static double constraint_force[2] = {10.0, -20.0};
static double displacement[4] = {0.1 - 0.3, 0.0, -0.0, 5e-324};

static snapshot two_node_snapshot(unsigned fields)
{
    snapshot s = {0};
    s.step = 123456789012LL;
    s.time = 1.2345678901234567e-3;
    s.fields = fields;
    s.nodes = 2;
    s.elements = 1;
    s.joints = 2;
    s.constraints = 1;
    s.dimension = 2;
    s.stress_components = 3;
    s.position = position;
    s.velocity = velocity;
    s.stress = stress;
    s.damage = damage;
    s.constraint_force = constraint_force;
    s.displacement = displacement;
    return s;
}

static double number_at(const json_t *array, size_t row, size_t col)
{
    return json_number_value(json_array_get(json_array_get(array, row), col));
}

static void test_state_json_all_fields(void)
{
    unsigned all = CASE_FIELD_POSITION | CASE_FIELD_VELOCITY | CASE_FIELD_STRESS |
                   CASE_FIELD_DAMAGE;
    snapshot s = two_node_snapshot(all);
    json_t *j = state_to_json(&s);
    CHECK(j != NULL, "state_to_json returned NULL");
    if (!j) return;
    CHECK(json_integer_value(json_object_get(j, "step")) == 123456789012LL, "step");
    CHECK(json_real_value(json_object_get(j, "time")) == s.time, "time not exact");
    json_t *pos = json_object_get(j, "position");
    CHECK(json_array_size(pos) == 2, "position has %zu rows", json_array_size(pos));
    CHECK(json_array_size(json_array_get(pos, 1)) == 2, "position rows are pairs");
    CHECK(number_at(pos, 1, 1) == 2.5e17, "position[1][1] = %g", number_at(pos, 1, 1));
    json_t *vel = json_object_get(j, "velocity");
    CHECK(number_at(vel, 1, 0) == 3.0, "velocity[1][0] = %g", number_at(vel, 1, 0));
    json_t *str = json_object_get(j, "stress");
    CHECK(json_array_size(str) == 1 && json_array_size(json_array_get(str, 0)) == 3,
          "stress is [[sxx, syy, sxy]]");
    CHECK(number_at(str, 0, 2) == 7.0, "stress[0][2] = %g", number_at(str, 0, 2));
    json_t *dmg = json_object_get(j, "damage");
    CHECK(json_array_size(dmg) == 2, "damage has one number per joint");
    CHECK(json_real_value(json_array_get(dmg, 1)) == 0.75, "damage[1]");
    CHECK(json_object_size(j) == 6, "%zu keys, want step, time and 4 fields",
          json_object_size(j));
    json_decref(j);
}

static void test_state_json_only_requested_fields(void)
{
    /* Damage and velocity are in the snapshot but were not asked for. */
    snapshot s = two_node_snapshot(CASE_FIELD_POSITION);
    json_t *j = state_to_json(&s);
    CHECK(j != NULL, "state_to_json returned NULL");
    if (!j) return;
    CHECK(json_object_get(j, "position") != NULL, "position missing");
    CHECK(json_object_get(j, "velocity") == NULL, "velocity not requested");
    CHECK(json_object_get(j, "damage") == NULL, "damage not requested");
    CHECK(json_object_get(j, "stress") == NULL, "stress not requested");
    CHECK(json_object_size(j) == 3, "%zu keys, want 3", json_object_size(j));
    json_decref(j);
}

static void test_state_json_round_trip_is_exact(void)
{
    snapshot s = two_node_snapshot(CASE_FIELD_POSITION);
    json_t *j = state_to_json(&s);
    char *text = j ? json_dumps(j, JSON_COMPACT) : NULL;
    CHECK(text != NULL, "json_dumps failed");
    json_error_t e;
    json_t *back = text ? json_loads(text, 0, &e) : NULL;
    CHECK(back != NULL, "reparse failed");
    if (back) {
        json_t *pos = json_object_get(back, "position");
        for (int i = 0; i < 4; i++)
            CHECK(number_at(pos, (size_t)i / 2, (size_t)i % 2) == position[i],
                  "position[%d] %.17g != %.17g after dump/load", i,
                  number_at(pos, (size_t)i / 2, (size_t)i % 2), position[i]);
        CHECK(json_real_value(json_object_get(back, "time")) == s.time, "time not exact");
    }
    json_decref(back);
    free(text);
    json_decref(j);
}

static void test_state_json_non_finite_becomes_null(void)
{
    double bad_position[4] = {NAN, 1.0, INFINITY, -INFINITY};
    snapshot s = two_node_snapshot(CASE_FIELD_POSITION);
    s.position = bad_position;
    s.time = NAN;
    json_t *j = state_to_json(&s);
    CHECK(j != NULL, "a NaN must not make the whole state fail");
    if (!j) return;
    json_t *pos = json_object_get(j, "position");
    CHECK(json_is_null(json_array_get(json_array_get(pos, 0), 0)), "NaN -> null");
    CHECK(number_at(pos, 0, 1) == 1.0, "finite neighbour kept");
    CHECK(json_is_null(json_array_get(json_array_get(pos, 1), 0)), "+inf -> null");
    CHECK(json_is_null(json_array_get(json_array_get(pos, 1), 1)), "-inf -> null");
    CHECK(json_is_null(json_object_get(j, "time")), "NaN time -> null");
    char *text = json_dumps(j, JSON_COMPACT);
    CHECK(text != NULL && strstr(text, "[[null,1.0],[null,null]]") != NULL,
          "dumped as %s", text ? text : "(null)");
    free(text);
    json_decref(j);
}

/* 3D: three numbers per node, six stress components per element, each
 * row in the engine's order (xx, yy, zz, yz, xz, xy). */
static void test_state_json_three_dimensions(void)
{
    double position3[6] = {0, 1, 2, 3, 4, 5};
    double stress6[6] = {1, 2, 3, 4, 5, 6};
    snapshot s = two_node_snapshot(CASE_FIELD_POSITION | CASE_FIELD_VELOCITY |
                                   CASE_FIELD_STRESS);
    s.dimension = 3;
    s.stress_components = 6;
    s.position = s.velocity = position3;
    s.stress = stress6;
    json_t *j = state_to_json(&s);
    CHECK(j != NULL, "no JSON");
    if (!j) return;
    json_t *pos = json_object_get(j, "position"), *str = json_object_get(j, "stress");
    CHECK(json_array_size(pos) == 2 && json_array_size(json_array_get(pos, 0)) == 3,
          "position rows %zu of %zu", json_array_size(pos),
          json_array_size(json_array_get(pos, 0)));
    CHECK(number_at(pos, 1, 2) == 5, "z of node 1: %g", number_at(pos, 1, 2));
    CHECK(json_array_size(json_object_get(j, "velocity")) == 2, "velocity rows");
    CHECK(json_array_size(str) == 1 && json_array_size(json_array_get(str, 0)) == 6,
          "stress row of %zu", json_array_size(json_array_get(str, 0)));
    for (int k = 0; k < 6; k++)
        CHECK(number_at(str, 0, (size_t)k) == stress6[k], "stress[%d] %g", k,
              number_at(str, 0, (size_t)k));
    json_decref(j);
}

/* displacement: a [dx, dy] row per node, exact, only when asked for. */
static void test_state_json_displacement(void)
{
    snapshot s = two_node_snapshot(CASE_FIELD_DISPLACEMENT);
    json_t *j = state_to_json(&s);
    CHECK(j != NULL, "state_to_json returned NULL");
    if (!j) return;
    json_t *u = json_object_get(j, "displacement");
    CHECK(json_array_size(u) == 2 && json_array_size(json_array_get(u, 0)) == 2,
          "displacement is [[dx, dy], [dx, dy]]");
    for (int i = 0; i < 4; i++)
        CHECK(number_at(u, (size_t)(i / 2), (size_t)(i % 2)) == displacement[i] &&
                  signbit(number_at(u, (size_t)(i / 2), (size_t)(i % 2))) ==
                      signbit(displacement[i]),
              "displacement[%d][%d] = %.17g, want %.17g", i / 2, i % 2,
              number_at(u, (size_t)(i / 2), (size_t)(i % 2)), displacement[i]);
    CHECK(json_object_get(j, "position") == NULL, "position not requested");
    CHECK(json_object_size(j) == 3, "%zu keys, want step, time, displacement",
          json_object_size(j));
    json_decref(j);
    s = two_node_snapshot(CASE_FIELD_POSITION | CASE_FIELD_VELOCITY);
    j = state_to_json(&s);
    CHECK(j && json_object_get(j, "displacement") == NULL, "displacement not requested");
    json_decref(j);
}

CHECK_MAIN(T(test_state_json_all_fields), T(test_state_json_only_requested_fields),
           T(test_state_json_round_trip_is_exact), T(test_state_json_non_finite_becomes_null),
           T(test_state_json_three_dimensions), T(test_state_json_displacement))
