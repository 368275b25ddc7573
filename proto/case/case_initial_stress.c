/*
 * case_initial_stress.c - stress fields of a case: {"value": [...],
 * "gradient": [...], "reference": h}, the shape of a part's
 * "initial_stress" (contract 5.3; the in-situ stress its elements start
 * with, read in pass 1 and handed to the engine with the part in pass 3)
 * and of a constraint's "boundary_stress" (contract 6.1; the traction of
 * such a field on the boundary, case_constraints.c). One reader and one
 * range check serve both, so the two say the same things about the same
 * mistakes.
 *
 * value and gradient hold the stress components in the layout of the
 * `stress` output (2D: sxx, syy, sxy; 3D: sxx, syy, szz, syz, sxz, sxy);
 * the gradient is per metre of height (y in 2D, z in 3D) and needs the
 * reference height where value holds, since a gradient from an unstated
 * height is a guess the user did not make.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "case_internal.h"

static const char *const stress_field_keys[] = {"value", "gradient", "reference", NULL};

static const char *stress_layout(int dimension)
{
    return dimension == 3 ? "[sxx, syy, szz, syz, sxz, sxy]" : "[sxx, syy, sxy]";
}

/* An array of the dimension's stress components, each a finite number; a
 * wrong length is told with the layout it should have. */
static int read_components(case_doc *doc, const json_t *value, const char *ptr, const char *unit,
                           double out[6])
{
    const int count = doc->dimension == 3 ? 6 : 3;
    if (!json_is_array(value) || json_array_size(value) != (size_t)count) {
        case_problem(doc, ptr, "expected an array of %s numbers %s (%s) for a %dD case, got %s%s",
                     case_count_word(count), stress_layout(doc->dimension), unit, doc->dimension,
                     case_type_word(value), json_is_array(value) ? " of another length" : "");
        return 0;
    }
    return case_read_vector(doc, value, ptr, count, out);
}

int case_read_stress_field(case_doc *doc, const json_t *block, const char *ptr, const char *what,
                           case_stress_field *field)
{
    memset(field, 0, sizeof *field);
    if (!case_expect_object(doc, block, ptr)) return 0;
    case_check_keys(doc, block, ptr, stress_field_keys, what);
    char at[CASE_POINTER];
    int ok = 1;
    json_t *value = case_member(block, ptr, "value", at);
    if (!value) {
        case_problem(doc, ptr, "missing required \"value\": the stress %s in Pa",
                     stress_layout(doc->dimension));
        ok = 0;
    } else {
        ok &= read_components(doc, value, at, "Pa", field->value);
    }
    json_t *gradient = case_member(block, ptr, "gradient", at);
    if (gradient) {
        ok &= read_components(doc, gradient, at, "Pa per metre of height", field->gradient);
        if (!json_object_get(block, "reference")) {
            case_problem(doc, at, "a \"gradient\" needs \"reference\": the height (%s) at which "
                                  "\"value\" holds", doc->dimension == 3 ? "z" : "y");
            ok = 0;
        }
    }
    ok &= case_number_member(doc, block, ptr, "reference", 0, &field->reference);
    return ok;
}

void case_read_initial_stress(case_doc *doc, case_part *part, const json_t *block,
                              const char *ptr)
{
    part->has_stress0 = case_read_stress_field(doc, block, ptr, "\"initial_stress\"",
                                               &part->stress0);
}

/* The field is linear in the height, so its extremes over a range of
 * heights are at its ends. A gradient of 1e308 made the stress there
 * infinite: the case was accepted and failed at once with an error that
 * blamed the time step. Here it is a 422 at the member to change. */
int case_check_stress_extent(case_doc *doc, const case_stress_field *field, const char *ptr,
                             const char *what, const char *body, const double height[2])
{
    const int count = doc->dimension == 3 ? 6 : 3;
    static const char *const names2[] = {"sxx", "syy", "sxy"};
    static const char *const names3[] = {"sxx", "syy", "szz", "syz", "sxz", "sxy"};
    const char *const *names = doc->dimension == 3 ? names3 : names2;
    for (int end = 0; end < 2; end++)
        for (int k = 0; k < count; k++) {
            double dh = height[end] - field->reference;
            double s = field->value[k] + field->gradient[k] * dh;
            if (isfinite(s) && fabs(s) <= CASE_MAX_INITIAL_STRESS) continue;
            char at[CASE_POINTER];
            pointer_join(at, sizeof at, ptr, field->gradient[k] != 0 ? "gradient" : "value");
            case_problem(doc, at, "the %s %s would be %g Pa at the %s node of %s (%s = %g m, "
                                  "reference %g m); it must be finite and at most %g Pa in "
                                  "size: check the units (Pa, and Pa per metre for the gradient)",
                         what, names[k], s, end ? "highest" : "lowest", body,
                         doc->dimension == 3 ? "z" : "y", height[end], field->reference,
                         CASE_MAX_INITIAL_STRESS);
            return -1;
        }
    return 0;
}

int case_add_initial_stress(case_doc *doc, fdem_model *model, int i, int index,
                            const double height[2])
{
    const case_part *part = &doc->parts[i];
    if (!part->has_stress0) return 0;
    char base[CASE_POINTER], ptr[CASE_POINTER], body[CASE_NAME + 16];
    pointer_join_index(base, sizeof base, "/parts", i);
    pointer_join(ptr, sizeof ptr, base, "initial_stress");
    snprintf(body, sizeof body, "part \"%s\"", part->name);
    if (case_check_stress_extent(doc, &part->stress0, ptr, "initial stress", body, height) != 0)
        return -1;
    fdem_error err = {0};
    if (fdem_set_part_initial_stress(model, index, part->stress0.value, part->stress0.gradient,
                                     part->stress0.reference, &err) == 0)
        return 0;
    case_problem(doc, ptr, "%s", err.message);
    return -1;
}
