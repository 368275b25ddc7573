/*
 * case_warnings.c - values of a valid case that are far outside rock and
 * steel (contract 6.2 "Warnings"): almost surely a unit typed wrong, e.g.
 * `young` 40 (MPa meant as Pa) or a friction angle 0.61 (radians meant as
 * degrees). They never refuse a case: case_warnings() is asked only about
 * a document case_build() accepted and lists each finding once at its JSON
 * Pointer. It reads the JSON tree (not the case_doc) so that the readers
 * of case_build stay about what is valid, and this file alone about what
 * is plausible; case_build_gated() hands it the tree it parsed, so an
 * upload is parsed once (issue 38: a second parse had cost a document's
 * set-up as much again, and had been skipped above 2 MiB for its memory).
 *
 * The ranges (docs/case-format.md "Warnings") are wide on purpose: soft
 * soils to tungsten, foams excepted, so that a warning is worth reading.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <jansson.h>

#include "case.h"
#include "case_internal.h"

/* Pa: below a weak soil, above diamond */
#define WARN_YOUNG_MIN 1e6
#define WARN_YOUNG_MAX 1e13
/* kg/m3: below a foam, above osmium */
#define WARN_DENSITY_MIN 100
#define WARN_DENSITY_MAX 30000
/* Pa: tensile strength and cohesion, below a soft soil, above any steel */
#define WARN_STRENGTH_MIN 1e3
#define WARN_STRENGTH_MAX 1e10
/* degrees: a positive angle below it is almost surely in radians */
#define WARN_FRICTION_ANGLE_MIN 1
/* a friction coefficient above it is almost surely an angle in degrees */
#define WARN_FRICTION_MAX 5
/* m/s2: ten times the Earth's gravity */
#define WARN_GRAVITY_MAX 100

static int number_at(const json_t *object, const char *key, double *x)
{
    const json_t *v = json_object_get(object, key);
    if (!json_is_number(v)) return 0;
    *x = json_number_value(v);
    return 1;
}

static void warn(problems *out, const char *base, const char *key, const char *fmt, double x)
{
    char ptr[CASE_POINTER];
    pointer_join(ptr, sizeof ptr, base, key);
    problems_add(out, 200, ptr, fmt, x);
}

/* x outside [lo, hi]: one warning saying which side and what was meant. */
static void warn_range(problems *out, const json_t *object, const char *base, const char *key,
                       double lo, double hi, const char *unit)
{
    double x;
    if (!number_at(object, key, &x)) return;
    char fmt[200];
    if (x < lo)
        snprintf(fmt, sizeof fmt, "%s %%g %s is far below any rock or steel (%g %s): "
                 "check the unit", key, unit, lo, unit);
    else if (x > hi)
        snprintf(fmt, sizeof fmt, "%s %%g %s is far above any rock or steel (%g %s): "
                 "check the unit", key, unit, hi, unit);
    else
        return;
    warn(out, base, key, fmt, x);
}

/* A "fracture" block of a material or a joint set. */
static void warn_fracture(problems *out, const json_t *f, const char *base)
{
    if (!json_is_object(f)) return;
    warn_range(out, f, base, "tensile_strength", WARN_STRENGTH_MIN, WARN_STRENGTH_MAX, "Pa");
    warn_range(out, f, base, "cohesion", WARN_STRENGTH_MIN, WARN_STRENGTH_MAX, "Pa");
    double angle;
    if (number_at(f, "friction_angle", &angle) && angle > 0 && angle < WARN_FRICTION_ANGLE_MIN)
        warn(out, base, "friction_angle", "friction_angle %g is below 1 degree: it looks like "
             "radians, and the angle is in degrees", angle);
}

static void warn_material(problems *out, const json_t *m, const char *base)
{
    if (!json_is_object(m)) return;
    warn_range(out, m, base, "young", WARN_YOUNG_MIN, WARN_YOUNG_MAX, "Pa");
    warn_range(out, m, base, "density", WARN_DENSITY_MIN, WARN_DENSITY_MAX, "kg/m3");
    double young, penalty, friction;
    if (number_at(m, "penalty", &penalty) && number_at(m, "young", &young) && penalty < young)
        warn(out, base, "penalty", "penalty %g Pa is below young: bodies will sink into one "
             "another (10 x young is the default)", penalty);
    if (number_at(m, "friction", &friction) && friction > WARN_FRICTION_MAX)
        warn(out, base, "friction", "friction %g is a coefficient (tan of the angle): it "
             "looks like an angle in degrees", friction);
    char at[CASE_POINTER];
    pointer_join(at, sizeof at, base, "fracture");
    warn_fracture(out, json_object_get(m, "fracture"), at);
}

static void warn_parts(problems *out, const json_t *parts)
{
    size_t i, j;
    const json_t *part, *set;
    json_array_foreach(parts, i, part) {
        const json_t *sets = json_object_get(part, "discontinuities");
        json_array_foreach(sets, j, set) {
            char ptr[CASE_POINTER], base[CASE_POINTER];
            pointer_join_index(ptr, sizeof ptr, "/parts", (long)i);
            pointer_join(base, sizeof base, ptr, "discontinuities");
            pointer_join_index(ptr, sizeof ptr, base, (long)j);
            warn_fracture(out, set, ptr);
        }
    }
}

static void warn_gravity(problems *out, const json_t *gravity)
{
    double sum = 0;
    size_t i;
    const json_t *g;
    json_array_foreach(gravity, i, g)
        if (json_is_number(g)) sum += json_number_value(g) * json_number_value(g);
    if (sqrt(sum) > WARN_GRAVITY_MAX)
        problems_add(out, 200, "/gravity", "gravity of magnitude %g m/s2 is over ten times "
                     "the Earth's: check the unit", sqrt(sum));
}

int case_warnings_of(const json_t *root, problems *out)
{
    int before = out->count;
    const char *name;
    json_t *m_;
    json_object_foreach(json_object_get(root, "materials"), name, m_) {
        char base[CASE_POINTER];
        pointer_join(base, sizeof base, "/materials", name);
        warn_material(out, m_, base);
    }
    warn_parts(out, json_object_get(root, "parts"));
    warn_gravity(out, json_object_get(root, "gravity"));
    out->status = 0; /* warnings, not problems: nothing is refused */
    return out->count - before;
}

int case_warnings(const char *text, size_t length, problems *out)
{
    json_t *root = json_loadb(text, length, JSON_REJECT_DUPLICATES, NULL);
    if (!root) return 0;
    int n = case_warnings_of(root, out);
    json_decref(root);
    return n;
}
