/*
 * case_amplitude.c - amplitude tables of a case (contract 5.3): the
 * "amplitude" of a velocity, force or pressure constraint and the top-level
 * "gravity_amplitude", both [[t0, a0], [t1, a1], ...] with finite numbers
 * and strictly increasing times. Each bad entry is reported at its own JSON
 * Pointer, so a long table with one slip names the slip.
 */
#include <stdlib.h>

#include "case_internal.h"

/* One [t, a] pair at ptr into pair[2]; 1 when it is acceptable. */
static int amplitude_read_pair(case_doc *doc, const json_t *value, const char *ptr, double pair[2])
{
    if (!json_is_array(value) || json_array_size(value) != 2) {
        case_problem(doc, ptr, "expected a [time, factor] pair of numbers, got %s%s",
                     case_type_word(value), json_is_array(value) ? " of another length" : "");
        return 0;
    }
    return case_read_vector(doc, value, ptr, 2, pair);
}

double *case_read_amplitude(case_doc *doc, const json_t *value, const char *ptr, int *count)
{
    *count = 0;
    if (!json_is_array(value) || json_array_size(value) == 0) {
        case_problem(doc, ptr, "expected a table [[t0, a0], [t1, a1], ...] of at least one "
                               "[time, factor] pair, got %s%s",
                     case_type_word(value), json_is_array(value) ? " that is empty" : "");
        return NULL;
    }
    size_t n = json_array_size(value);
    double *pairs = malloc(sizeof(double) * 2 * n);
    if (!pairs) {
        case_problem(doc, ptr, "out of memory");
        return NULL;
    }
    int ok = 1;
    for (size_t k = 0; k < n; k++) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, (long)k);
        if (!amplitude_read_pair(doc, json_array_get(value, k), at, pairs + 2 * k)) {
            ok = 0;
            continue;
        }
        if (k > 0 && ok && !(pairs[2 * k] > pairs[2 * k - 2])) {
            char t_at[CASE_POINTER];
            pointer_join_index(t_at, sizeof t_at, at, 0);
            case_problem(doc, t_at, "amplitude times must increase strictly: %g follows %g",
                         pairs[2 * k], pairs[2 * k - 2]);
            ok = 0;
        }
    }
    if (!ok) {
        free(pairs);
        return NULL;
    }
    *count = (int)n;
    return pairs;
}
