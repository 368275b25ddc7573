/*
 * case_initial_stress.c - a part's "initial_stress" (contract 5.3): the
 * in-situ stress its elements start with, {"value": [...], "gradient":
 * [...], "reference": h}, read in pass 1 and handed to the engine with the
 * part in pass 3.
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

static const char *const initial_stress_keys[] = {"value", "gradient", "reference", NULL};

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

void case_read_initial_stress(case_doc *doc, case_part *part, const json_t *block,
                              const char *ptr)
{
    if (!case_expect_object(doc, block, ptr)) return;
    case_check_keys(doc, block, ptr, initial_stress_keys, "\"initial_stress\"");
    char at[CASE_POINTER];
    int ok = 1;
    json_t *value = case_member(block, ptr, "value", at);
    if (!value) {
        case_problem(doc, ptr, "missing required \"value\": the stress %s in Pa",
                     stress_layout(doc->dimension));
        ok = 0;
    } else {
        ok &= read_components(doc, value, at, "Pa", part->stress0_value);
    }
    json_t *gradient = case_member(block, ptr, "gradient", at);
    if (gradient) {
        ok &= read_components(doc, gradient, at, "Pa per metre of height",
                              part->stress0_gradient);
        if (!json_object_get(block, "reference")) {
            case_problem(doc, at, "a \"gradient\" needs \"reference\": the height (%s) at which "
                                  "\"value\" holds", doc->dimension == 3 ? "z" : "y");
            ok = 0;
        }
    }
    ok &= case_number_member(doc, block, ptr, "reference", 0, &part->stress0_reference);
    part->has_stress0 = ok;
}

/* The field is linear in the height, so its extremes over the part are at
 * its lowest and highest nodes. A gradient of 1e308 made the stress there
 * infinite: the case was accepted and failed at once with an error that
 * blamed the time step. Here it is a 422 at the member to change. */
static int check_extent(case_doc *doc, const case_part *part, int i, const double height[2])
{
    const int count = doc->dimension == 3 ? 6 : 3;
    static const char *const names2[] = {"sxx", "syy", "sxy"};
    static const char *const names3[] = {"sxx", "syy", "szz", "syz", "sxz", "sxy"};
    const char *const *names = doc->dimension == 3 ? names3 : names2;
    for (int end = 0; end < 2; end++)
        for (int k = 0; k < count; k++) {
            double dh = height[end] - part->stress0_reference;
            double s = part->stress0_value[k] + part->stress0_gradient[k] * dh;
            if (isfinite(s) && fabs(s) <= CASE_MAX_INITIAL_STRESS) continue;
            char ptr[CASE_POINTER];
            snprintf(ptr, sizeof ptr, "/parts/%d/initial_stress/%s", i,
                     part->stress0_gradient[k] != 0 ? "gradient" : "value");
            case_problem(doc, ptr, "the initial stress %s of part \"%s\" would be %g Pa at its "
                                   "%s node (%s = %g m, reference %g m); it must be finite and "
                                   "at most %g Pa in size: check the units (Pa, and Pa per metre "
                                   "for the gradient)",
                         names[k], part->name, s, end ? "highest" : "lowest",
                         doc->dimension == 3 ? "z" : "y", height[end],
                         part->stress0_reference, CASE_MAX_INITIAL_STRESS);
            return -1;
        }
    return 0;
}

int case_add_initial_stress(case_doc *doc, fdem_model *model, int i, int index,
                            const double height[2])
{
    const case_part *part = &doc->parts[i];
    if (!part->has_stress0) return 0;
    if (check_extent(doc, part, i, height) != 0) return -1;
    fdem_error err = {0};
    if (fdem_set_part_initial_stress(model, index, part->stress0_value, part->stress0_gradient,
                                     part->stress0_reference, &err) == 0)
        return 0;
    char base[CASE_POINTER], ptr[CASE_POINTER];
    pointer_join_index(base, sizeof base, "/parts", i);
    pointer_join(ptr, sizeof ptr, base, "initial_stress");
    case_problem(doc, ptr, "%s", err.message);
    return -1;
}
