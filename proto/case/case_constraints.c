/*
 * case_constraints.c - the "constraints" array of a case: each entry selects
 * nodes (a part by name, a named group of a gmsh part, or a box of initial
 * positions) and does one thing to them (fix components, prescribe a
 * velocity, apply a force, press on or absorb waves through the boundary
 * they span), a velocity, force or
 * pressure optionally scaled by an "amplitude" table in time.
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

static const char *const constraint_keys[] = {"part",     "group",  "box",    "fix",
                                              "velocity", "force",  "pressure", "absorb",
                                              "amplitude",
                                              NULL};

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

/* {"part": P, "group": G}: the nodes of physical group G of gmsh part P. */
static void constraint_read_group(case_doc *doc, case_constraint *c, const json_t *group,
                                  const char *ptr)
{
    int count = 0;
    if (case_group_vertices(doc, c->def.part, group, ptr, &c->vertices, &count) < 0) return;
    c->def.select = FDEM_SELECT_VERTICES;
    c->def.vertices = c->vertices;
    c->def.vertex_count = count;
}

/* "[xmin, ymin, xmax, ymax]" or the 3D six. */
static const char *box_layout(int dimension)
{
    return dimension == 3 ? "[xmin, ymin, zmin, xmax, ymax, zmax]" : "[xmin, ymin, xmax, ymax]";
}

int case_read_box(case_doc *doc, const json_t *value, const char *ptr, double box[6])
{
    static const char *const axes = "xyz";
    int dim = doc->dimension;
    if (!json_is_array(value) || json_array_size(value) != (size_t)(2 * dim)) {
        char got[160];
        case_problem(doc, ptr, "expected %s, got %s", box_layout(dim),
                     case_wrong_tuple(doc, value, 2, got, sizeof got));
        return 0;
    }
    if (!case_read_vector(doc, value, ptr, 2 * dim, box)) return 0;
    for (int d = 0; d < dim; d++)
        if (box[d] > box[dim + d]) {
            case_problem(doc, ptr, "the box must be %s with %cmin <= %cmax, got %cmin = %g > "
                                   "%cmax = %g", box_layout(dim), axes[d], axes[d], axes[d],
                         box[d], axes[d], box[dim + d]);
            return 0;
        }
    return 1;
}

/* Lower bounds, then upper bounds: the engine's layout of def->box. */
static void constraint_read_box(case_doc *doc, fdem_constraint_def *def, const json_t *box,
                                const char *ptr)
{
    def->select = FDEM_SELECT_BOX;
    case_read_box(doc, box, ptr, def->box);
}

/* "\"x\" or \"y\"" / "\"x\", \"y\" or \"z\"" */
static const char *axis_names(int dimension)
{
    return dimension == 3 ? "\"x\", \"y\" or \"z\"" : "\"x\" or \"y\"";
}

static void constraint_read_fix(case_doc *doc, fdem_constraint_def *def, const json_t *fix,
                                const char *ptr)
{
    static const char *const axes[] = {"x", "y", "z"};
    int *flags[3] = {&def->fix_x, &def->fix_y, &def->fix_z};
    int dim = doc->dimension;
    def->kind = FDEM_CONSTRAINT_FIX;
    if (!json_is_array(fix) || json_array_size(fix) == 0 ||
        json_array_size(fix) > (size_t)dim) {
        char got[160];
        case_problem(doc, ptr, "expected a list of the components to fix (some of %s), got %s",
                     axis_names(dim), case_wrong_tuple(doc, fix, 1, got, sizeof got));
        return;
    }
    size_t i;
    json_t *c;
    json_array_foreach(fix, i, c) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, (long)i);
        const char *s = json_is_string(c) ? json_string_value(c) : NULL;
        int axis = -1;
        for (int d = 0; s && d < dim; d++)
            if (strcmp(s, axes[d]) == 0) axis = d;
        if (axis >= 0)
            *flags[axis] = 1;
        else if (s)
            case_problem(doc, at, "expected %s, got \"%.32s\"%s", axis_names(dim), s,
                         dim == 2 && strcmp(s, "z") == 0
                             ? " (this case is 2D: set \"dimension\": 3 at the top of the case "
                               "for a 3D one)"
                             : "");
        else
            case_problem(doc, at, "expected %s, got %s", axis_names(dim), case_type_word(c));
    }
}

/* [vx, vy(, vz)] where null leaves that component free. */
static void constraint_read_velocity(case_doc *doc, fdem_constraint_def *def, const json_t *v,
                                     const char *ptr)
{
    int dim = doc->dimension;
    const char *layout = dim == 3 ? "[vx, vy, vz]" : "[vx, vy]";
    def->kind = FDEM_CONSTRAINT_VELOCITY;
    if (!json_is_array(v) || json_array_size(v) != (size_t)dim) {
        char got[160];
        case_problem(doc, ptr, "expected %s (null leaves a component free), got %s", layout,
                     case_wrong_tuple(doc, v, 1, got, sizeof got));
        return;
    }
    int *free_flag[3] = {&def->free_x, &def->free_y, &def->free_z};
    int free_count = 0;
    for (int k = 0; k < dim; k++) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, k);
        json_t *c = json_array_get(v, (size_t)k);
        if (json_is_null(c)) {
            *free_flag[k] = 1;
            free_count++;
        } else if (!json_is_number(c)) {
            case_problem(doc, at, "expected a number or null, got %s", case_type_word(c));
        } else {
            case_read_number(doc, c, at, &def->value[k]);
        }
    }
    if (free_count == dim)
        case_problem(doc, ptr, "all null constrains nothing; give at least one component of %s",
                     layout);
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

/* "absorb": true; false is refused rather than ignored, since the constraint
 * would then do nothing. */
static void constraint_read_absorb(case_doc *doc, fdem_constraint_def *def, const json_t *a,
                                   const char *ptr)
{
    def->kind = FDEM_CONSTRAINT_ABSORB;
    int on = 0;
    if (case_read_bool(doc, a, ptr, &on) && !on)
        case_problem(doc, ptr, "\"absorb\": false does nothing; use true or leave the "
                               "constraint out");
}

/* "amplitude" only scales a value: a velocity, force or pressure. */
static void constraint_read_amplitude(case_doc *doc, case_constraint *c, const json_t *value,
                                      const char *ptr)
{
    char at[CASE_POINTER];
    json_t *table = case_member(value, ptr, "amplitude", at);
    if (!table) return;
    if (c->def.kind == FDEM_CONSTRAINT_FIX || c->def.kind == FDEM_CONSTRAINT_ABSORB) {
        case_problem(doc, at, "an amplitude scales a \"velocity\", \"force\" or \"pressure\", "
                              "not %s", c->def.kind == FDEM_CONSTRAINT_FIX ? "\"fix\"" : "\"absorb\"");
        return;
    }
    c->amplitude = case_read_amplitude(doc, table, at, &c->def.amplitude_count);
    c->def.amplitude = c->amplitude;
}

static void constraint_read(case_doc *doc, case_constraint *c, int index, const json_t *value)
{
    static const char *const selectors[] = {"part", "box"};
    static const char *const actions[] = {"fix", "velocity", "force", "pressure", "absorb"};
    char ptr[CASE_POINTER], at[CASE_POINTER], what[32];
    pointer_join_index(ptr, sizeof ptr, "/constraints", index);
    if (!case_expect_object(doc, value, ptr)) return;
    snprintf(what, sizeof what, "constraint %d", index);
    case_check_keys(doc, value, ptr, constraint_keys, what);

    char selector_what[96];
    snprintf(selector_what, sizeof selector_what,
             "a selector: \"part\" (a part name) or \"box\" %s", box_layout(doc->dimension));
    int selector = constraint_pick(doc, value, ptr, selectors, 2, selector_what);
    if (selector >= 0) {
        json_t *s = case_member(value, ptr, selectors[selector], at);
        if (selector == 0) constraint_read_part(doc, &c->def, s, at);
        else constraint_read_box(doc, &c->def, s, at);
    }
    json_t *group = case_member(value, ptr, "group", at);
    json_t *part = json_object_get(value, "part");
    if (group && selector != 0)
        case_problem(doc, at, "\"group\" names a physical group of a part: give \"part\" too");
    else if (group && json_is_string(part) &&
             case_names_find(doc->part_names, json_string_value(part)) >= 0)
        constraint_read_group(doc, c, group, at); /* an unknown part is reported at "part" */
    int action = constraint_pick(doc, value, ptr, actions, 5,
                                 "an action: \"fix\", \"velocity\", \"force\", \"pressure\" "
                                 "or \"absorb\"");
    if (action < 0) return;
    json_t *a = case_member(value, ptr, actions[action], at);
    if (action == 0) {
        constraint_read_fix(doc, &c->def, a, at);
    } else if (action == 1) {
        constraint_read_velocity(doc, &c->def, a, at);
    } else if (action == 2) {
        c->def.kind = FDEM_CONSTRAINT_FORCE;
        case_read_axes(doc, a, at, c->def.value);
    } else if (action == 3) {
        c->def.kind = FDEM_CONSTRAINT_PRESSURE;
        case_read_number(doc, a, at, &c->def.value[0]);
    } else {
        constraint_read_absorb(doc, &c->def, a, at);
    }
    constraint_read_amplitude(doc, c, value, ptr);
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

/* Every constraint is checked even after one is refused (one answer names
 * each); such a model is never finalized. */
int case_add_constraints(case_doc *doc, fdem_model *model)
{
    int rc = 0;
    for (int i = 0; i < doc->constraint_count; i++) {
        fdem_error err = {0};
        if (fdem_add_constraint(model, &doc->constraints[i].def, &err) < 0) {
            char ptr[CASE_POINTER];
            pointer_join_index(ptr, sizeof ptr, "/constraints", i);
            if (err.kind == FDEM_ITEM_CONSTRAINT) err.item = i; /* not shifted by a refusal */
            case_engine_problem(doc, &err, ptr);
            rc = -1;
        }
    }
    return rc;
}
