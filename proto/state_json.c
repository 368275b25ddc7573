/*
 * state_json.c - a snapshot as the JSON body of GET /cases/ID/state.
 *
 * Numbers go out as JSON reals (jansson prints them with 17 significant
 * digits, so a client reads back the exact double). JSON has no NaN or
 * infinity and jansson refuses to build them, so a non-finite value becomes
 * null: the client sees which entry is broken instead of getting no answer.
 */
#include "state_json.h"

#include <math.h>

#include "case.h"

static json_t *number_or_null(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

/* [[v0, v1, ...], ...]: `rows` rows of `width` numbers. */
static json_t *rows_to_json(const double *values, int rows, int width)
{
    json_t *array = json_array();
    if (!array) return NULL;
    for (int i = 0; i < rows; i++) {
        json_t *row = json_array();
        if (!row || json_array_append_new(array, row) < 0) {
            json_decref(array);
            return NULL;
        }
        for (int k = 0; k < width; k++)
            if (json_array_append_new(row, number_or_null(values[(size_t)i * width + k])) < 0) {
                json_decref(array);
                return NULL;
            }
    }
    return array;
}

static json_t *list_to_json(const double *values, int count)
{
    json_t *array = json_array();
    if (!array) return NULL;
    for (int i = 0; i < count; i++)
        if (json_array_append_new(array, number_or_null(values[i])) < 0) {
            json_decref(array);
            return NULL;
        }
    return array;
}

/* Sets obj[key] = value, taking ownership; a NULL value (allocation
 * failure upstream) counts as a failure. */
static int set_or_fail(json_t *obj, const char *key, json_t *value)
{
    if (!value) return -1;
    return json_object_set_new(obj, key, value);
}

json_t *state_to_json(const snapshot *s)
{
    if (!s) return NULL;
    json_t *obj = json_object();
    if (!obj) return NULL;
    int rc = 0;
    rc |= set_or_fail(obj, "step", json_integer((json_int_t)s->step));
    rc |= set_or_fail(obj, "time", number_or_null(s->time));
    if ((s->fields & CASE_FIELD_POSITION) && s->position)
        rc |= set_or_fail(obj, "position", rows_to_json(s->position, s->nodes, s->dimension));
    if ((s->fields & CASE_FIELD_VELOCITY) && s->velocity)
        rc |= set_or_fail(obj, "velocity", rows_to_json(s->velocity, s->nodes, s->dimension));
    if ((s->fields & CASE_FIELD_STRESS) && s->stress)
        rc |= set_or_fail(obj, "stress", rows_to_json(s->stress, s->elements, s->stress_components));
    if ((s->fields & CASE_FIELD_DAMAGE) && s->damage)
        rc |= set_or_fail(obj, "damage", list_to_json(s->damage, s->joints));
    if (rc != 0) {
        json_decref(obj);
        return NULL;
    }
    return obj;
}
