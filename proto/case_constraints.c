/*
 * case_constraints.c - the "constraints" array of a case: each entry selects
 * nodes (a part by name, or a box of initial positions) and does one thing
 * to them (fix components, prescribe a velocity, apply a force).
 *
 * Parts are read first, so a part selector is resolved to its index here and
 * a misspelt part name is reported with a suggestion. Whether a box selects
 * any node is only known once the model exists; the engine reports that at
 * finalize with the constraint's index, which case_engine_problem() maps
 * back to /constraints/N.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"

static const char *const constraint_keys[] = {"part", "box", "fix", "velocity", "force", NULL};

static void constraint_read_part(case_doc *doc, fdem_constraint_def *def, const json_t *name,
                                 const char *ptr)
{
    def->select = FDEM_SELECT_PART;
    if (!json_is_string(name)) {
        case_problem(doc, ptr, "expected the name of a part, got %s", case_type_word(name));
        return;
    }
    const char *wanted = json_string_value(name);
    int found = case_names_find(doc->part_names, wanted);
    if (found >= 0) {
        def->part = found;
        return;
    }
    const char **names = malloc((size_t)(doc->part_count + 1) * sizeof *names);
    for (int i = 0; names && i < doc->part_count; i++) names[i] = doc->parts[i].name;
    char hint[96] = "";
    if (names) case_did_you_mean(doc, hint, sizeof hint, wanted, names, doc->part_count);
    free(names);
    case_problem(doc, ptr, "unknown part \"%.64s\"%s", wanted, hint);
}

static void constraint_read_box(case_doc *doc, fdem_constraint_def *def, const json_t *box,
                                const char *ptr)
{
    def->select = FDEM_SELECT_BOX;
    if (!json_is_array(box) || json_array_size(box) != 4) {
        case_problem(doc, ptr, "expected [xmin, ymin, xmax, ymax], got %s%s",
                     case_type_word(box), json_is_array(box) ? " of another length" : "");
        return;
    }
    int ok = 1;
    for (int k = 0; k < 4; k++) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, k);
        ok &= case_read_number(doc, json_array_get(box, (size_t)k), at, &def->box[k]);
    }
    if (ok && (def->box[0] > def->box[2] || def->box[1] > def->box[3]))
        case_problem(doc, ptr, "the box must be [xmin, ymin, xmax, ymax] with xmin <= xmax and "
                               "ymin <= ymax, got [%g, %g, %g, %g]",
                     def->box[0], def->box[1], def->box[2], def->box[3]);
}

static void constraint_read_fix(case_doc *doc, fdem_constraint_def *def, const json_t *fix,
                                const char *ptr)
{
    def->kind = FDEM_CONSTRAINT_FIX;
    if (!json_is_array(fix) || json_array_size(fix) == 0 || json_array_size(fix) > 2) {
        case_problem(doc, ptr, "expected a list of the components to fix, [\"x\"], [\"y\"] or "
                               "[\"x\", \"y\"], got %s", case_type_word(fix));
        return;
    }
    size_t i;
    json_t *c;
    json_array_foreach(fix, i, c) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, (long)i);
        const char *s = json_is_string(c) ? json_string_value(c) : NULL;
        if (s && strcmp(s, "x") == 0)
            def->fix_x = 1;
        else if (s && strcmp(s, "y") == 0)
            def->fix_y = 1;
        else if (s)
            case_problem(doc, at, "expected \"x\" or \"y\", got \"%.32s\"", s);
        else
            case_problem(doc, at, "expected \"x\" or \"y\", got %s", case_type_word(c));
    }
}

/* [vx, vy] where null leaves that component free. */
static void constraint_read_velocity(case_doc *doc, fdem_constraint_def *def, const json_t *v,
                                     const char *ptr)
{
    def->kind = FDEM_CONSTRAINT_VELOCITY;
    if (!json_is_array(v) || json_array_size(v) != 2) {
        case_problem(doc, ptr, "expected [vx, vy] (null leaves a component free), got %s%s",
                     case_type_word(v), json_is_array(v) ? " of another length" : "");
        return;
    }
    int *free_flag[2] = {&def->free_x, &def->free_y};
    for (int k = 0; k < 2; k++) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, k);
        json_t *c = json_array_get(v, (size_t)k);
        if (json_is_null(c))
            *free_flag[k] = 1;
        else if (!json_is_number(c))
            case_problem(doc, at, "expected a number or null, got %s", case_type_word(c));
        else
            case_read_number(doc, c, at, &def->value[k]);
    }
    if (def->free_x && def->free_y)
        case_problem(doc, ptr, "[null, null] constrains nothing; give vx, vy or both");
}

/* Exactly one of the keys in `keys[0..count)`; returns its index or -1. */
static int constraint_pick(case_doc *doc, const json_t *value, const char *ptr,
                           const char *const *keys, int count, const char *what)
{
    int found = -1, n = 0;
    for (int i = 0; i < count; i++)
        if (json_object_get(value, keys[i])) {
            if (n++ == 0) found = i;
        }
    if (n == 1) return found;
    if (n == 0)
        case_problem(doc, ptr, "a constraint needs %s", what);
    else
        case_problem(doc, ptr, "a constraint takes exactly one of %s, this one has %d", what, n);
    return -1;
}

static void constraint_read(case_doc *doc, case_constraint *c, int index, const json_t *value)
{
    static const char *const selectors[] = {"part", "box"};
    static const char *const actions[] = {"fix", "velocity", "force"};
    char ptr[CASE_POINTER], at[CASE_POINTER], what[32];
    pointer_join_index(ptr, sizeof ptr, "/constraints", index);
    if (!case_expect_object(doc, value, ptr)) return;
    snprintf(what, sizeof what, "constraint %d", index);
    case_check_keys(doc, value, ptr, constraint_keys, what);

    int selector = constraint_pick(doc, value, ptr, selectors, 2,
                                   "a selector: \"part\" (a part name) or \"box\" "
                                   "[xmin, ymin, xmax, ymax]");
    if (selector >= 0) {
        json_t *s = case_member(value, ptr, selectors[selector], at);
        if (selector == 0) constraint_read_part(doc, &c->def, s, at);
        else constraint_read_box(doc, &c->def, s, at);
    }
    int action = constraint_pick(doc, value, ptr, actions, 3,
                                 "an action: \"fix\", \"velocity\" or \"force\"");
    if (action < 0) return;
    json_t *a = case_member(value, ptr, actions[action], at);
    if (action == 0) {
        constraint_read_fix(doc, &c->def, a, at);
    } else if (action == 1) {
        constraint_read_velocity(doc, &c->def, a, at);
    } else {
        c->def.kind = FDEM_CONSTRAINT_FORCE;
        case_read_vec2(doc, a, at, c->def.value);
    }
}

void case_read_constraints(case_doc *doc, const json_t *constraints)
{
    if (!case_expect_array(doc, constraints, "/constraints")) return;
    size_t count = json_array_size(constraints);
    if (count == 0) return;
    doc->constraints = calloc(count, sizeof *doc->constraints);
    if (!doc->constraints) {
        case_problem(doc, "/constraints", "out of memory");
        return;
    }
    doc->constraint_count = (int)count;
    for (int i = 0; i < doc->constraint_count; i++)
        constraint_read(doc, &doc->constraints[i], i, json_array_get(constraints, (size_t)i));
}

int case_add_constraints(case_doc *doc, fdem_model *model)
{
    for (int i = 0; i < doc->constraint_count; i++) {
        fdem_error err = {0};
        if (fdem_add_constraint(model, &doc->constraints[i].def, &err) != i) {
            char ptr[CASE_POINTER];
            pointer_join_index(ptr, sizeof ptr, "/constraints", i);
            case_engine_problem(doc, &err, ptr);
            return -1;
        }
    }
    return 0;
}
