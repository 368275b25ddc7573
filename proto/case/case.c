/*
 * case.c - case_build(): a case document (contract section 3) in, a
 * finalized engine model (or the full list of problems) out.
 *
 * This file owns the order of things: parse, read every section (pass 1,
 * case_materials.c, case_parts.c, case_constraints.c and the small sections
 * here), estimate memory (pass 2, case_memory.c), check the boxes that
 * need generated meshes with the other problems (case_boxes.c), build and finalize the
 * model (pass 3), then choose the time step. Engine errors are mapped to
 * JSON Pointers (only the case knows which document item became which
 * engine index) in case_doc.c, which the sections share; no case file calls
 * back into this one.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"

#define CASE_DEFAULT_SAFETY FDEM_DEFAULT_SAFETY

static const char *const top_keys[] = {
    "name", "dimension", "materials", "parts", "constraints", "stages", "gravity",
    "gravity_amplitude", "time", "output", "history", "fluid", "parallel", NULL,
};
static const char *const time_keys[] = {"end", "dt", "safety", NULL};
static const char *const output_keys[] = {"interval", "fields", NULL};
static const char *const parallel_keys[] = {"ranks", NULL};
/* In CASE_FIELD_* bit order: names[k] is bit 1u << k. */
static const char *const field_names[] = {"position", "velocity", "stress", "damage",
                                          "strain", "principal_stress", "displacement"};
#define FIELD_NAME_COUNT (int)(sizeof field_names / sizeof field_names[0])
#define FIELD_NAME_LIST \
    "position, velocity, stress, damage, strain, principal_stress, displacement"

/* ------------------------------------------------------- small sections */

static void case_read_name(case_doc *doc, const json_t *root)
{
    json_t *name = json_object_get(root, "name");
    snprintf(doc->name, sizeof doc->name, "unnamed");
    if (!name) return;
    if (!json_is_string(name))
        case_problem(doc, "/name", "expected a string, got %s", case_type_word(name));
    else if (json_string_length(name) >= CASE_NAME ||
             strlen(json_string_value(name)) != json_string_length(name))
        case_problem(doc, "/name", "the name must be at most %d bytes, without NUL characters",
                     CASE_NAME - 1);
    else if (json_string_length(name) > 0 &&
             case_check_name_text(doc, json_string_value(name), "/name", "the name"))
        snprintf(doc->name, sizeof doc->name, "%s", json_string_value(name));
}

static void case_read_dt(case_doc *doc, const json_t *dt)
{
    doc->dt_auto = 1;
    if (!dt || (json_is_string(dt) && strcmp(json_string_value(dt), "auto") == 0)) return;
    if (json_is_string(dt)) {
        case_problem(doc, "/time/dt", "expected a number or \"auto\", got \"%.32s\"",
                     json_string_value(dt));
        return;
    }
    if (!json_is_number(dt)) {
        case_problem(doc, "/time/dt", "expected a number or \"auto\", got %s",
                     case_type_word(dt));
        return;
    }
    doc->dt_auto = 0;
    if (case_read_number(doc, dt, "/time/dt", &doc->dt) && !(doc->dt > 0))
        case_problem(doc, "/time/dt", "dt must be > 0, got %g", doc->dt);
}

/* With stages, time.end may be left out: the last stage's end is the end
 * (case_check_stage_end reconciles the two after this). */
static void case_read_time(case_doc *doc, const json_t *time)
{
    doc->safety = CASE_DEFAULT_SAFETY;
    doc->dt_auto = 1;
    int end_required = !doc->stages_given;
    if (!time) {
        if (end_required) case_problem(doc, "", "missing required \"time\" {\"end\": seconds}");
        return;
    }
    if (!case_expect_object(doc, time, "/time")) return;
    case_check_keys(doc, time, "/time", time_keys, "\"time\"");
    doc->end_given = json_object_get(time, "end") != NULL;
    double end = 0;
    if (case_number_member(doc, time, "/time", "end", end_required, &end) && doc->end_given) {
        if (!(end > 0)) case_problem(doc, "/time/end", "end must be > 0, got %g", end);
        else doc->end_time = end;
    }
    case_read_dt(doc, json_object_get(time, "dt"));
    if (case_number_member(doc, time, "/time", "safety", 0, &doc->safety) &&
        !(doc->safety > 0 && doc->safety <= 1))
        case_problem(doc, "/time/safety", "safety must be in (0, 1], got %g", doc->safety);
}

static void case_read_fields(case_doc *doc, const json_t *fields)
{
    if (!case_expect_array(doc, fields, "/output/fields")) return;
    doc->fields = 0;
    size_t i;
    json_t *f;
    json_array_foreach(fields, i, f) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, "/output/fields", (long)i);
        if (!json_is_string(f)) {
            case_problem(doc, at, "expected a field name, got %s", case_type_word(f));
            continue;
        }
        unsigned bit = 0;
        for (int k = 0; k < FIELD_NAME_COUNT; k++)
            if (strcmp(json_string_value(f), field_names[k]) == 0) bit = 1u << k;
        char hint[96];
        if (!bit)
            case_problem(doc, at, "unknown field \"%.64s\"%s (fields are " FIELD_NAME_LIST ")",
                         json_string_value(f),
                         case_did_you_mean(doc, hint, sizeof hint, json_string_value(f),
                                           field_names, FIELD_NAME_COUNT));
        doc->fields |= bit;
    }
}

/* Needs time.end, so it runs after case_read_time(). */
static void case_read_output(case_doc *doc, const json_t *output)
{
    doc->fields = CASE_FIELD_POSITION | CASE_FIELD_VELOCITY;
    doc->interval = doc->end_time / CASE_DEFAULT_SNAPSHOTS;
    if (!output) return;
    if (!case_expect_object(doc, output, "/output")) return;
    case_check_keys(doc, output, "/output", output_keys, "\"output\"");
    if (json_object_get(output, "interval") &&
        case_number_member(doc, output, "/output", "interval", 0, &doc->interval)) {
        if (!(doc->interval > 0))
            case_problem(doc, "/output/interval", "interval must be > 0, got %g", doc->interval);
        else if (doc->end_time > 0 && doc->end_time / doc->interval > CASE_MAX_SNAPSHOTS)
            case_problem(doc, "/output/interval",
                         "an interval of %g s over %g s would write %.3g snapshots; the limit "
                         "is %.0f", doc->interval, doc->end_time,
                         doc->end_time / doc->interval, CASE_MAX_SNAPSHOTS);
    }
    json_t *fields = json_object_get(output, "fields");
    if (fields) case_read_fields(doc, fields);
}

/* "parallel": {"ranks": N} (contract 6.5): how many MPI ranks run the
 * case, 1 (in the daemon's process) by default. Whether N is allowed here
 * (--max-ranks) is the daemon's to say: the document is the same case on
 * any machine. */
static void case_read_parallel(case_doc *doc, const json_t *parallel)
{
    doc->ranks = 1;
    if (!parallel) return;
    if (!case_expect_object(doc, parallel, "/parallel")) return;
    case_check_keys(doc, parallel, "/parallel", parallel_keys, "\"parallel\"");
    json_t *ranks = json_object_get(parallel, "ranks");
    long n = 1;
    if (ranks && case_read_integer(doc, ranks, "/parallel/ranks", 1, CASE_MAX_RANKS, &n))
        doc->ranks = (int)n;
}

/* 2 (the default) or 3. Everything with vectors or shapes depends on it,
 * so it is read first; an invalid value leaves 2 so the rest of the
 * document is still checked. */
static void case_read_dimension(case_doc *doc, const json_t *dimension)
{
    doc->dimension = 2;
    if (!dimension) return;
    double d = 0;
    if (!json_is_number(dimension))
        case_problem(doc, "/dimension", "expected 2 or 3, got %s", case_type_word(dimension));
    else if (case_read_number(doc, dimension, "/dimension", &d) && d != 2 && d != 3)
        case_problem(doc, "/dimension", "the dimension is 2 or 3, got %g", d);
    else if (d == 3)
        doc->dimension = 3;
}

static void case_read_gravity(case_doc *doc, const json_t *gravity)
{
    if (gravity) case_read_axes(doc, gravity, "/gravity", doc->gravity);
}

static void case_read_gravity_amplitude(case_doc *doc, const json_t *table)
{
    if (table)
        doc->gravity_amplitude = case_read_amplitude(doc, table, "/gravity_amplitude",
                                                     &doc->gravity_amplitude_count);
}

/* Pass 1 over the whole document. */
static void case_read(case_doc *doc, const json_t *root)
{
    if (!json_is_object(root)) {
        case_problem(doc, "", "a case is a JSON object, got %s", case_type_word(root));
        return;
    }
    case_check_keys(doc, root, "", top_keys, "the case");
    case_read_dimension(doc, json_object_get(root, "dimension"));
    case_read_name(doc, root);
    case_read_fluid(doc, json_object_get(root, "fluid"));
    json_t *materials = json_object_get(root, "materials");
    if (materials) case_read_materials(doc, materials);
    else case_problem(doc, "", "missing required \"materials\" {name: {...}}");
    json_t *parts = json_object_get(root, "parts");
    if (parts) case_read_parts(doc, parts);
    else case_problem(doc, "", "missing required \"parts\" [...]");
    case_check_fluid(doc);
    json_t *constraints = json_object_get(root, "constraints");
    if (constraints) case_read_constraints(doc, constraints);
    json_t *stages = json_object_get(root, "stages");
    if (stages) case_read_stages(doc, stages);
    case_read_gravity(doc, json_object_get(root, "gravity"));
    case_read_gravity_amplitude(doc, json_object_get(root, "gravity_amplitude"));
    case_read_time(doc, json_object_get(root, "time"));
    case_check_stage_end(doc);
    case_read_output(doc, json_object_get(root, "output"));
    json_t *history = json_object_get(root, "history");
    if (history) case_read_history(doc, history);
    case_check_history_rows(doc);
    case_read_parallel(doc, json_object_get(root, "parallel"));
}

/* ---------------------------------------------------------------- pass 3 */

/* Belt and braces: a constraint that selected nothing is a user error even
 * if the engine accepted it. */
static int case_check_selections(case_doc *doc, const fdem_model *model)
{
    int ok = 1;
    for (int i = 0; i < doc->constraint_count; i++)
        if (fdem_constraint_node_count(model, i) <= 0) {
            case_problem(doc, doc->constraints[i].ptr, "the constraint selects no node");
            ok = 0;
        }
    return ok;
}

/* time.end / dt within CASE_MAX_STEPS; else a problem at whichever of the
 * two the user can fix: a given dt when "auto" would do, else the end. */
static int case_check_steps(case_doc *doc, double dt, double auto_dt)
{
    double steps = doc->end_time / dt;
    if (steps <= CASE_MAX_STEPS) return 0;
    if (!doc->dt_auto && doc->end_time / auto_dt <= CASE_MAX_STEPS)
        case_problem(doc, "/time/dt", "dt = %g s would take %.3g steps to reach time.end = %g s; "
                                      "a case may take at most %.0e steps: use a dt of at "
                                      "least %.4g s, or \"auto\" (%.4g s here)",
                     dt, steps, doc->end_time, CASE_MAX_STEPS, doc->end_time / CASE_MAX_STEPS,
                     auto_dt);
    else
        case_problem(doc, "/time/end", "end = %g s would take %.3g steps of %g s (the %s time "
                                       "step); a case may take at most %.0e steps: use an end of "
                                       "at most %.4g s",
                     doc->end_time, steps, dt, doc->dt_auto ? "stable" : "given",
                     CASE_MAX_STEPS, CASE_MAX_STEPS * dt);
    return -1;
}

/* "auto" is fdem_auto_dt (safety x the stability limits, at most the
 * contact step); a given dt must not exceed the stable step. */
static int case_choose_dt(case_doc *doc, fdem_model *model, case_info *info)
{
    double stable = fdem_stable_dt(model), auto_dt = fdem_auto_dt(model, doc->safety);
    if (!(stable > 0) || !isfinite(stable)) {
        case_problem(doc, "", "the model has no finite stable time step (%g s)", stable);
        return -1;
    }
    if (!doc->dt_auto && doc->dt > stable) {
        case_dt_problem(doc, stable, auto_dt, "");
        return -1;
    }
    double dt = doc->dt_auto ? auto_dt : doc->dt;
    if (case_check_steps(doc, dt, auto_dt) != 0) return -1;
    fdem_set_dt(model, dt);
    info->dt = dt;
    info->stable_dt = stable;
    return 0;
}

/* Parts placed inside each other would start with the penalty energy of
 * the whole overlap (start_overlap.c): named at the later part of the pair. */
static int case_check_start_overlap(case_doc *doc, const fdem_model *model)
{
    int inner = -1, outer = -1;
    double p[3] = {0, 0, 0};
    int found = fdem_find_start_overlap(model, &inner, &outer, p);
    if (found == 0) return 1;
    if (found < 0) {
        case_problem(doc, "/parts", "out of memory");
        return 0;
    }
    char at[CASE_POINTER], where[96];
    int later = inner > outer ? inner : outer; /* the pair's later part: one pointer per pair */
    pointer_join_index(at, sizeof at, "/parts", later);
    if (doc->dimension == 3)
        snprintf(where, sizeof where, "(%.6g, %.6g, %.6g)", p[0], p[1], p[2]);
    else
        snprintf(where, sizeof where, "(%.6g, %.6g)", p[0], p[1]);
    case_problem(doc, at, "part %d overlaps part %d at the start: the point %s of part %d "
                          "lies inside an element of part %d; bodies must start apart or just "
                          "touching", later, inner + outer - later, where, inner, outer);
    return 0;
}

static fdem_model *case_build_model(case_doc *doc, case_info *info)
{
    fdem_model *model = fdem_model_create();
    if (!model) {
        case_problem(doc, "", "out of memory");
        return NULL;
    }
    fdem_error err = {0};
    int ok = fdem_set_dimension(model, doc->dimension, &err) == 0;
    if (!ok) case_engine_problem(doc, &err, "/dimension");
    /* parts and constraints both, whatever the other finds (one answer);
     * stages select elements of the parts, and stage constraints name
     * their stage, so the stages go in between */
    ok = ok && case_add_materials(doc, model) == 0;
    if (ok) {
        int parts = case_add_parts(doc, model) == 0;
        int stages = parts && case_add_stages(doc, model) == 0;
        ok = parts & stages & (case_add_constraints(doc, model, stages) == 0);
    }
    if (ok) {
        fdem_set_gravity_v(model, doc->gravity);
        ok = fdem_set_gravity_amplitude(model, doc->gravity_amplitude,
                                        doc->gravity_amplitude_count, &err) == 0;
        if (!ok) case_engine_problem(doc, &err, "/gravity_amplitude");
        if (ok && doc->has_fluid && fdem_set_fluid(model, &doc->fluid, &err)) {
            case_engine_problem(doc, &err, "/fluid");
            ok = 0;
        }
        ok = ok && fdem_model_finalize(model, &err) == 0;
        /* a constraint that selects nothing: name every such one */
        if (!ok && err.kind == FDEM_ITEM_CONSTRAINT &&
            fdem_constraint_node_count(model, err.item) == 0)
            case_check_selections(doc, model);
        else if (!ok)
            case_engine_problem(doc, &err, "");
        if (!ok && err.kind == FDEM_ITEM_CONSTRAINT && fdem_stable_dt(model) > 0)
            case_choose_dt(doc, model, info);
    }
    /* Both checks, whatever the first finds: one answer names every problem. */
    if (ok)
        ok = case_check_selections(doc, model) & (case_choose_dt(doc, model, info) == 0) &
             case_check_start_overlap(doc, model) & case_locate_history(doc, model);
    if (!ok) {
        fdem_model_destroy(model);
        return NULL;
    }
    return model;
}

/* Appends a name and its NUL to info->names; 0, or -1 when it does not fit. */
static int case_pack_name(case_info *info, const char *name)
{
    size_t n = strlen(name) + 1;
    if (n > sizeof info->names - (size_t)info->names_bytes) return -1;
    memcpy(info->names + info->names_bytes, name, n);
    info->names_bytes += (int)n;
    return 0;
}

/* The part names (part_read_name made "part<i>" of an unnamed one) and the
 * material names, in the orders result_describe() reads them from the
 * document; none when they do not all fit. */
static void case_fill_names(const case_doc *doc, case_info *info)
{
    info->material_count = doc->material_count;
    info->names_bytes = 0;
    int fits = 1;
    for (int i = 0; fits && i < doc->part_count; i++)
        fits = case_pack_name(info, doc->parts[i].name) == 0;
    for (int i = 0; fits && i < doc->material_count; i++)
        fits = case_pack_name(info, doc->materials[i].name) == 0;
    if (!fits) info->names_bytes = 0;
}

static void case_fill_info(const case_doc *doc, case_info *info)
{
    snprintf(info->name, sizeof info->name, "%s", doc->name);
    info->end_time = doc->end_time;
    info->safety = doc->safety;
    info->output_interval = doc->interval;
    info->fields = doc->fields;
    info->part_count = doc->part_count;
    info->constraint_count = doc->constraint_count;
    info->ranks = doc->ranks;
    info->fracture = 0;
    for (int i = 0; i < doc->part_count; i++) info->fracture |= doc->parts[i].fracture;
    info->stage_count = doc->stage_count;
    for (int k = 0; k < doc->stage_count; k++)
        snprintf(info->stage_names[k], sizeof info->stage_names[k], "%s", doc->stages[k].name);
    case_fill_history_info(doc, info);
    case_fill_names(doc, info);
}

const char *case_stage_name(const case_info *info, int index)
{
    if (!info || index < 0 || index >= info->stage_count) return NULL;
    return info->stage_names[index];
}

static json_t *case_parse(const char *text, size_t length, problems *out)
{
    json_error_t error;
    json_t *root = json_loadb(text ? text : "", text ? length : 0, JSON_REJECT_DUPLICATES, &error);
    if (root) return root;
    if (!out->title[0]) snprintf(out->title, sizeof out->title, "Malformed JSON");
    problems_add(out, 400, "", "line %d, column %d: %s", error.line, error.column, error.text);
    return NULL;
}

/* Material names are keys of the JSON tree; copies let the tree go before
 * pass 3. Returns the copies (free with case_free_names), NULL when out of
 * memory. */
static char **case_copy_names(case_doc *doc)
{
    char **names = calloc((size_t)doc->material_count + 1, sizeof *names);
    for (int i = 0; names && i < doc->material_count; i++) {
        names[i] = strdup(doc->materials[i].name);
        if (!names[i]) {
            for (int k = 0; k < i; k++) free(names[k]);
            free(names);
            return NULL;
        }
        doc->materials[i].name = names[i];
    }
    return names;
}

static void case_free_names(char **names)
{
    for (int i = 0; names && names[i]; i++) free(names[i]);
    free(names);
}

fdem_model *case_build_gated(const char *text, size_t length, size_t memory_limit,
                             case_memory_gate gate, void *gate_ctx,
                             case_info *info, problems *out, problems *warnings)
{
    case_info scratch;
    if (!info) info = &scratch;
    memset(info, 0, sizeof *info);
    json_t *root = case_parse(text, length, out);
    if (!root) return NULL;
    case_doc doc = {0};
    doc.out = out;
    int before = out->count + out->dropped;
    case_read(&doc, root);
    double bytes = 0;
    if (out->count + out->dropped == before) bytes = case_check_memory(&doc, memory_limit);
    if (warnings && out->count + out->dropped == before) case_warnings_of(root, warnings);
    /* The tree of an explicit mesh is ten or more times its text; the model
     * must not come on top of it. */
    char **names = case_copy_names(&doc);
    json_decref(root);
    if (!names) case_problem(&doc, "", "out of memory");
    if (out->count + out->dropped != before) {
        case_check_boxes(&doc, before, memory_limit);
        case_probe_dt(&doc, before, memory_limit, gate, gate_ctx);
    } else if (gate && gate(gate_ctx, bytes) != 0) {
        snprintf(out->title, sizeof out->title, "Service unavailable");
        problems_add(out, 503, "", "the daemon has no memory to spare for this model now "
                                   "(--max-memory); try again later");
    } else {
        case_check_boxes(&doc, before, memory_limit); /* the boxes of the shapes meshed now */
    }
    fdem_model *model = NULL;
    if (out->count + out->dropped == before) model = case_build_model(&doc, info);
    if (model) case_fill_info(&doc, info);
    case_doc_free(&doc);
    case_free_names(names);
    return model;
}

fdem_model *case_build(const char *text, size_t length, size_t memory_limit,
                       case_info *info, problems *out)
{
    return case_build_gated(text, length, memory_limit, NULL, NULL, info, out, NULL);
}

unsigned case_parse_fields(const char *csv, problems *out)
{
    unsigned fields = 0;
    const char *p = csv ? csv : "";
    while (*p) {
        const char *comma = strchr(p, ',');
        size_t n = comma ? (size_t)(comma - p) : strlen(p);
        unsigned bit = 0;
        for (int k = 0; k < FIELD_NAME_COUNT; k++)
            if (strlen(field_names[k]) == n && strncmp(p, field_names[k], n) == 0)
                bit = 1u << k;
        if (!bit && n > 0) {
            if (!out->title[0]) snprintf(out->title, sizeof out->title, "Unknown field");
            problems_add(out, 400, "", "unknown field \"%.*s\"; fields are " FIELD_NAME_LIST, (int)(n < 64 ? n : 64), p);
        }
        fields |= bit;
        p += n;
        if (*p == ',') p++;
    }
    return fields;
}
