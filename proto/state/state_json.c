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
#include <stdlib.h>

#include "case/case.h"

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

/* [0, 1, 1, ...]: one flag a element. */
static json_t *flags_to_json(const uint8_t *flags, int count)
{
    json_t *array = json_array();
    if (!array) return NULL;
    for (int i = 0; i < count; i++)
        if (json_array_append_new(array, json_integer(flags[i])) < 0) {
            json_decref(array);
            return NULL;
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

/* Appends value to array, taking ownership; NULL counts as a failure. */
static int set_or_fail_append(json_t *array, json_t *value)
{
    if (!value) return -1;
    return json_array_append_new(array, value);
}

/* The rock-mechanics name of each principal_stress column: the columns
 * are descending with tension positive, so the last, the most compressive,
 * is sigma1 (as the attribute rock_mechanics_names of result.h5 says). */
static json_t *principal_names_json(int dimension)
{
    return dimension == 3 ? json_pack("[sss]", "sigma3", "sigma2", "sigma1")
                          : json_pack("[ss]", "sigma3", "sigma1");
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
    if ((s->fields & CASE_FIELD_STRAIN) && s->strain)
        rc |= set_or_fail(obj, "strain", rows_to_json(s->strain, s->elements, s->stress_components));
    if ((s->fields & CASE_FIELD_PRINCIPAL_STRESS) && s->principal_stress) {
        rc |= set_or_fail(obj, "principal_stress",
                          rows_to_json(s->principal_stress, s->elements, s->dimension));
        rc |= set_or_fail(obj, "principal_stress_names", principal_names_json(s->dimension));
    }
    if ((s->fields & CASE_FIELD_DISPLACEMENT) && s->displacement)
        rc |= set_or_fail(obj, "displacement",
                          rows_to_json(s->displacement, s->nodes, s->dimension));
    if (s->active) /* a case with stages: which elements are still there */
        rc |= set_or_fail(obj, "active", flags_to_json(s->active, s->elements));
    if (rc != 0) {
        json_decref(obj);
        return NULL;
    }
    return obj;
}

/* {"id", "elements", "mass", "size", "diameter", "centroid", "velocity",
 * "part", "held"} */
static json_t *fragment_to_json(const fdem_fragment *f, int id, int dimension)
{
    json_t *o = json_object();
    if (!o) return NULL;
    int rc = 0;
    rc |= set_or_fail(o, "id", json_integer(id));
    rc |= set_or_fail(o, "elements", json_integer(f->elements));
    rc |= set_or_fail(o, "mass", number_or_null(f->mass));
    rc |= set_or_fail(o, "size", number_or_null(f->size));
    rc |= set_or_fail(o, "diameter", number_or_null(f->diameter));
    rc |= set_or_fail(o, "centroid", list_to_json(f->centroid, dimension));
    rc |= set_or_fail(o, "velocity", list_to_json(f->velocity, dimension));
    rc |= set_or_fail(o, "part", json_integer(f->part));
    rc |= set_or_fail(o, "held", json_boolean(f->held));
    if (rc != 0) {
        json_decref(o);
        return NULL;
    }
    return o;
}

/* The sieve curve as [{"diameter", "passing"}, ...]. */
static json_t *distribution_to_json(const fdem_fragment *f, int count)
{
    json_t *array = json_array();
    double *diameter = malloc(sizeof(double) * (size_t)(count ? count : 1));
    double *passing = malloc(sizeof(double) * (size_t)(count ? count : 1));
    int points = array && diameter && passing ? fdem_sieve_curve(f, count, diameter, passing) : -1;
    for (int k = 0; k < points; k++) {
        json_t *point = json_object();
        if (!point || json_array_append_new(array, point) < 0 ||
            set_or_fail(point, "diameter", number_or_null(diameter[k])) < 0 ||
            set_or_fail(point, "passing", number_or_null(passing[k])) < 0) {
            points = -1;
            break;
        }
    }
    free(diameter);
    free(passing);
    if (points < 0) {
        json_decref(array);
        return NULL;
    }
    return array;
}

static int fragment_of_wanted_part(const fdem_fragment *f, const fragment_selection *sel)
{
    return !sel || !sel->parts || (f->part >= 0 && f->part < sel->part_count && sel->parts[f->part]);
}

/* The host rule (state_json.h): held, or more than half the model's mass. */
static int fragment_is_host(const fdem_fragment *f, double model_mass)
{
    return f->held || f->mass > 0.5 * model_mass;
}

/* Which fragments are listed (1), left out as the host (-1) or by part
 * (0), into `listed`; returns how many are listed. */
static int fragments_select(const snapshot *s, const fragment_selection *sel, int *listed)
{
    double model_mass = 0;
    for (int k = 0; k < s->fragment_count; k++) model_mass += s->fragments[k].mass;
    int count = 0;
    for (int k = 0; k < s->fragment_count; k++) {
        const fdem_fragment *f = &s->fragments[k];
        listed[k] = !fragment_of_wanted_part(f, sel) ? 0
                  : sel && sel->exclude_host && fragment_is_host(f, model_mass) ? -1 : 1;
        count += listed[k] == 1;
    }
    return count;
}

json_t *fragments_to_json(const snapshot *s, const fragment_selection *sel)
{
    if (!s || !(s->fields & SNAPSHOT_FRAGMENTS)) return NULL;
    size_t n = (size_t)(s->fragment_count > 0 ? s->fragment_count : 1);
    int *listed = malloc(n * sizeof *listed);
    fdem_fragment *kept = malloc(n * sizeof *kept);
    json_t *obj = json_object(), *list = json_array();
    json_t *host = sel && sel->exclude_host ? json_array() : NULL;
    int rc = obj && list && listed && kept && (host || !(sel && sel->exclude_host)) ? 0 : -1;
    int count = rc == 0 ? fragments_select(s, sel, listed) : 0, at = 0;
    for (int k = 0; k < s->fragment_count && rc == 0; k++) {
        if (listed[k] == 1) {
            kept[at++] = s->fragments[k];
            rc = set_or_fail_append(list, fragment_to_json(&s->fragments[k], k, s->dimension));
        } else if (listed[k] < 0) {
            rc = set_or_fail_append(host, json_integer(k));
        }
    }
    if (rc == 0) {
        rc |= set_or_fail(obj, "step", json_integer((json_int_t)s->step));
        rc |= set_or_fail(obj, "time", number_or_null(s->time));
        rc |= set_or_fail(obj, "fragments", list);
        list = NULL;
        rc |= set_or_fail(obj, "distribution", distribution_to_json(kept, count));
        if (host) {
            rc |= set_or_fail(obj, "host", host);
            host = NULL;
        }
    }
    json_decref(list);
    json_decref(host);
    free(listed);
    free(kept);
    if (rc != 0) {
        json_decref(obj);
        return NULL;
    }
    return obj;
}
