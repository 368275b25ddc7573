/*
 * case_constraints.c - the "constraints" array of a case: each entry selects
 * nodes (a part by name, a named group of a gmsh part, or a box of initial
 * positions) and does one thing to them (fix components, prescribe a
 * velocity, apply a force; press on, load with the traction of a stress
 * field or a fixed traction, or absorb waves through the boundary they
 * span), every value but a fix and an absorb optionally scaled by an
 * "amplitude" table in time. An "inject" with "bore": true fills a bore
 * whose wall is the selected boundary (core/fluid/fluid_bore.c).
 *
 * The same reader serves the top-level list and each stage's own
 * (contract 6.1: those act during their stage only, def.only_stage); every
 * constraint keeps the pointer it was read at, so an engine error about
 * engine constraint i (top-level ones first, then each stage's in stage
 * order) is reported where the user wrote it.
 *
 * Parts are read first, so a part selector is resolved to its index here and
 * a misspelt part name is reported with a suggestion. Whether a box selects
 * any node is only known once the model exists; the engine reports that at
 * finalize with the constraint's index, which case_engine_problem() maps
 * back to /constraints/N.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"

static const char *const constraint_keys[] = {"part",     "group",    "box",
                                              "fix",      "velocity", "force",
                                              "pressure", "absorb",   "boundary_stress",
                                              "traction", "inject",   "amplitude",
                                              "bore",     NULL};

int case_part_by_name(case_doc *doc, const json_t *name, const char *ptr)
{
    if (!json_is_string(name)) {
        case_problem(doc, ptr, "expected the name of a part, got %s", case_type_word(name));
        return -1;
    }
    const char *wanted = json_string_value(name);
    int found = case_names_find(doc->part_names, wanted);
    if (found >= 0) return found;
    const char **names = malloc((size_t)(doc->part_count + 1) * sizeof *names);
    for (int i = 0; names && i < doc->part_count; i++) names[i] = doc->parts[i].name;
    char hint[96] = "";
    if (names) case_did_you_mean(doc, hint, sizeof hint, wanted, names, doc->part_count);
    free(names);
    case_problem(doc, ptr, "unknown part \"%.64s\"%s", wanted, hint);
    return -1;
}

static void constraint_read_part(case_doc *doc, fdem_constraint_def *def, const json_t *name,
                                 const char *ptr)
{
    def->select = FDEM_SELECT_PART;
    int found = case_part_by_name(doc, name, ptr);
    if (found >= 0) def->part = found;
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

int case_read_box(case_doc *doc, const json_t *box, const char *ptr, double *out)
{
    static const char *const axes = "xyz";
    int dim = doc->dimension;
    if (!json_is_array(box) || json_array_size(box) != (size_t)(2 * dim)) {
        char got[160];
        case_problem(doc, ptr, "expected %s, got %s", box_layout(dim),
                     case_wrong_tuple(doc, box, 2, got, sizeof got));
        return 0;
    }
    if (!case_read_vector(doc, box, ptr, 2 * dim, out)) return 0;
    for (int d = 0; d < dim; d++)
        if (out[d] > out[dim + d]) {
            case_problem(doc, ptr, "the box must be %s with %cmin <= %cmax, got %cmin = %g > "
                                   "%cmax = %g", box_layout(dim), axes[d], axes[d], axes[d],
                         out[d], axes[d], out[dim + d]);
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

/* "boundary_stress": {"value", "gradient", "reference"}, read as a part's
 * "initial_stress" is (case_initial_stress.c); its range over the model's
 * heights is checked once the model has its nodes (case_add_constraints). */
static void constraint_read_boundary_stress(case_doc *doc, fdem_constraint_def *def,
                                            const json_t *field, const char *ptr)
{
    def->kind = FDEM_CONSTRAINT_BOUNDARY_STRESS;
    case_stress_field f;
    case_read_stress_field(doc, field, ptr, "\"boundary_stress\"", &f);
    memcpy(def->stress_value, f.value, sizeof f.value);
    memcpy(def->stress_gradient, f.gradient, sizeof f.gradient);
    def->stress_reference = f.reference;
}

/* "inject": Q (contract 6.4), a rate of fluid volume; needs the top-level
 * "fluid" (read before the constraints). A negative Q would draw fluid
 * out of a cavity that may hold none: refused. */
static void constraint_read_inject(case_doc *doc, fdem_constraint_def *def, const json_t *q,
                                   const char *ptr)
{
    def->kind = FDEM_CONSTRAINT_INJECT;
    if (!case_read_number(doc, q, ptr, &def->value[0])) return;
    if (def->value[0] < 0)
        case_problem(doc, ptr, "must be >= 0 (a rate of injected volume, %s), got %g",
                     doc->dimension == 3 ? "m^3/s" : "m^2/s per unit thickness", def->value[0]);
    if (!doc->has_fluid)
        case_problem(doc, ptr, "injects fluid, but the case has no top-level \"fluid\": give "
                               "{\"viscosity\", \"bulk_modulus\", \"density\"}");
}

/* "bore": true with "inject": the fluid goes into a bore whose wall is the
 * boundary edges (faces) the selection spans (docs/case-format.md). */
static void constraint_read_bore(case_doc *doc, case_constraint *c, const json_t *value,
                                 const char *ptr)
{
    char at[CASE_POINTER];
    json_t *bore = case_member(value, ptr, "bore", at);
    if (!bore) return;
    int on = 0;
    if (!case_read_bool(doc, bore, at, &on)) return;
    if (c->def.kind != FDEM_CONSTRAINT_INJECT)
        case_problem(doc, at, "\"bore\" says where an \"inject\" puts its fluid: give it "
                              "with \"inject\" only");
    else
        c->def.bore = on;
}

/* "amplitude" only scales a value: not a fix or an absorbing boundary. */
static void constraint_read_amplitude(case_doc *doc, case_constraint *c, const json_t *value,
                                      const char *ptr)
{
    char at[CASE_POINTER];
    json_t *table = case_member(value, ptr, "amplitude", at);
    if (!table) return;
    if (c->def.kind == FDEM_CONSTRAINT_FIX || c->def.kind == FDEM_CONSTRAINT_ABSORB) {
        case_problem(doc, at, "an amplitude scales a \"velocity\", \"force\", \"pressure\", "
                              "\"boundary_stress\", \"traction\" or \"inject\", not %s",
                     c->def.kind == FDEM_CONSTRAINT_FIX ? "\"fix\"" : "\"absorb\"");
        return;
    }
    c->amplitude = case_read_amplitude(doc, table, at, &c->def.amplitude_count);
    c->def.amplitude = c->amplitude;
}

/* The entry at c->ptr (index `index` of its list). */
static void constraint_read(case_doc *doc, case_constraint *c, int index, const json_t *value)
{
    static const char *const selectors[] = {"part", "box"};
    static const char *const actions[] = {"fix",    "velocity",        "force",    "pressure",
                                          "absorb", "boundary_stress", "traction", "inject"};
    const char *ptr = c->ptr;
    char at[CASE_POINTER], what[32];
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
    int action = constraint_pick(doc, value, ptr, actions, 8,
                                 "an action: \"fix\", \"velocity\", \"force\", \"pressure\", "
                                 "\"absorb\", \"boundary_stress\", \"traction\" or \"inject\"");
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
    } else if (action == 4) {
        constraint_read_absorb(doc, &c->def, a, at);
        if (c->def.only_stage)
            case_problem(doc, at, "an absorbing boundary acts throughout the run: give it in "
                                  "the top-level \"constraints\", not in a stage's");
    } else if (action == 5) {
        constraint_read_boundary_stress(doc, &c->def, a, at);
    } else if (action == 7) {
        constraint_read_inject(doc, &c->def, a, at);
    } else {
        c->def.kind = FDEM_CONSTRAINT_TRACTION;
        case_read_axes(doc, a, at, c->def.value);
    }
    constraint_read_amplitude(doc, c, value, ptr);
    constraint_read_bore(doc, c, value, ptr);
}

void case_read_constraint_list(case_doc *doc, const json_t *list, const char *ptr,
                               int only_stage)
{
    if (!case_expect_array(doc, list, ptr)) return;
    size_t count = json_array_size(list);
    if (count == 0) return;
    size_t total = (size_t)doc->constraint_count + count;
    case_constraint *grown = total <= (size_t)INT32_MAX
                                 ? realloc(doc->constraints, total * sizeof *grown)
                                 : NULL;
    if (!grown) {
        case_problem(doc, ptr, "out of memory");
        return;
    }
    doc->constraints = grown;
    for (size_t i = 0; i < count; i++) {
        case_constraint *c = &doc->constraints[doc->constraint_count++];
        memset(c, 0, sizeof *c);
        c->def.only_stage = only_stage;
        pointer_join_index(c->ptr, sizeof c->ptr, ptr, (long)i);
        constraint_read(doc, c, (int)i, json_array_get(list, i));
    }
}

void case_read_constraints(case_doc *doc, const json_t *constraints)
{
    case_read_constraint_list(doc, constraints, "/constraints", 0);
}

/* Lowest and highest initial node of the model (y in 2D, z in 3D), over
 * the parts added so far. */
static void model_height_range(const fdem_model *model, double height[2])
{
    const int dim = fdem_get_dimension(model), count = fdem_get_counts(model).nodes;
    const double *x = fdem_initial_positions(model);
    height[0] = height[1] = 0;
    for (int n = 0; x && n < count; n++) {
        double h = x[(size_t)dim * (size_t)n + (size_t)(dim - 1)];
        if (n == 0 || h < height[0]) height[0] = h;
        if (n == 0 || h > height[1]) height[1] = h;
    }
}

/* A boundary stress must stay finite and plausible over the model's
 * heights, as a part's initial stress over the part's. */
static int check_boundary_stress(case_doc *doc, const fdem_model *model, int i)
{
    const fdem_constraint_def *def = &doc->constraints[i].def;
    if (def->kind != FDEM_CONSTRAINT_BOUNDARY_STRESS) return 0;
    case_stress_field f;
    memcpy(f.value, def->stress_value, sizeof f.value);
    memcpy(f.gradient, def->stress_gradient, sizeof f.gradient);
    f.reference = def->stress_reference;
    double height[2];
    model_height_range(model, height);
    char ptr[CASE_POINTER];
    pointer_join(ptr, sizeof ptr, doc->constraints[i].ptr, "boundary_stress");
    return case_check_stress_extent(doc, &f, ptr, "boundary stress", "the model", height);
}

/* Every constraint is checked even after one is refused (one answer names
 * each); such a model is never finalized. */
int case_add_constraints(case_doc *doc, fdem_model *model, int stages_added)
{
    int rc = 0;
    for (int i = 0; i < doc->constraint_count; i++) {
        const case_constraint *c = &doc->constraints[i];
        if (c->def.only_stage && !stages_added) {
            rc = -1;
            continue;
        }
        fdem_error err = {0};
        if (check_boundary_stress(doc, model, i) < 0) {
            rc = -1;
            continue;
        }
        if (fdem_add_constraint(model, &c->def, &err) < 0) {
            if (err.kind == FDEM_ITEM_CONSTRAINT) err.item = i; /* not shifted by a refusal */
            case_engine_problem(doc, &err, c->ptr);
            rc = -1;
        }
    }
    return rc;
}
