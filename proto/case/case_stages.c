/*
 * case_stages.c - the "stages" of a case (contract 6.1 "Stages"): named
 * periods, in order, stage k running from the end of stage k - 1 (or 0) to
 * its "end". At a stage's start the elements its "excavate" selectors pick
 * are removed (the engine applies the forces they exerted on the rest and
 * ramps them to zero over "relax" seconds), and its own "constraints" act
 * during it only.
 *
 * Pass 1 reads every stage: names unique, ends increasing and agreeing
 * with time.end (which may be left out: the last end is the end), every
 * selector checked against the parts and their gmsh groups. Pass 3, once
 * the parts are in the model, turns each stage's selectors into model
 * element indices and hands the stage to the engine. A part's elements are
 * contiguous in the model, in the order of its mesh (build.c appends them
 * so), which is also the order gmsh groups count them in; a box picks the
 * elements whose centroid (the mean of their initial nodes) lies in it,
 * bounds included, as a constraint box picks nodes. An element already
 * excavated by an earlier stage is not handed over again. The engine never
 * sees a name: the names go to case_info, for the status.
 *
 * Named, like the other sections' files, after its key in the document;
 * extending and cloning a stored case (contract 5.3) is
 * server/cases/case_continue.c.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"

static const char *const stage_keys[] = {"name", "end", "excavate", "relax", "constraints",
                                         NULL};
static const char *const selector_keys[] = {"part", "group", "box", NULL};

/* ------------------------------------------------------------- pass 1 */

static void stage_read_name(case_doc *doc, case_stage *stage, int index, const json_t *value,
                            const char *ptr)
{
    char at[CASE_POINTER];
    json_t *name = case_member(value, ptr, "name", at);
    snprintf(stage->name, sizeof stage->name, "stage%d", index);
    if (!name) return;
    if (!json_is_string(name)) {
        case_problem(doc, at, "expected a string, got %s", case_type_word(name));
    } else if (json_string_length(name) == 0 || json_string_length(name) >= CASE_STAGE_NAME ||
               strlen(json_string_value(name)) != json_string_length(name)) {
        case_problem(doc, at, "a stage name must be 1 to %d bytes long", CASE_STAGE_NAME - 1);
    } else if (case_check_name_text(doc, json_string_value(name), at, "the stage name")) {
        snprintf(stage->name, sizeof stage->name, "%s", json_string_value(name));
    }
}

/* {"part": P}, {"part": P, "group": G} or {"box": [...]}; a selector that
 * does not read is left CASE_PICK_NONE (the document is refused anyway). */
static void selector_read(case_doc *doc, case_element_selector *sel, const json_t *value,
                          const char *ptr)
{
    sel->kind = CASE_PICK_NONE;
    if (!case_expect_object(doc, value, ptr)) return;
    case_check_keys(doc, value, ptr, selector_keys, "an element selector");
    char at[CASE_POINTER];
    json_t *part = json_object_get(value, "part"), *box = json_object_get(value, "box");
    json_t *group = case_member(value, ptr, "group", at);
    if ((part != NULL) == (box != NULL)) {
        case_problem(doc, ptr, "an element selector takes exactly one of \"part\" (a part name, "
                               "with \"group\" for a physical group of a gmsh part) or \"box\" "
                               "(by element centroid)");
        return;
    }
    if (box) {
        if (group)
            case_problem(doc, at, "\"group\" names a physical group of a part: give \"part\" "
                                  "instead of \"box\"");
        case_member(value, ptr, "box", at);
        if (case_read_box(doc, box, at, sel->box) && !group) sel->kind = CASE_PICK_BOX;
        return;
    }
    case_member(value, ptr, "part", at);
    sel->part = case_part_by_name(doc, part, at);
    if (sel->part < 0) return;
    if (!group) {
        sel->kind = CASE_PICK_PART;
        return;
    }
    case_member(value, ptr, "group", at);
    sel->group = case_group_with_elements(doc, sel->part, group, at);
    if (sel->group >= 0) sel->kind = CASE_PICK_GROUP;
}

static void stage_read_excavate(case_doc *doc, case_stage *stage, const json_t *list,
                                const char *ptr)
{
    if (!case_expect_array(doc, list, ptr)) return;
    size_t count = json_array_size(list);
    if (count == 0) return; /* a stage that removes nothing (an in-situ stage) */
    stage->excavate = calloc(count, sizeof *stage->excavate);
    if (!stage->excavate) {
        case_problem(doc, ptr, "out of memory");
        return;
    }
    stage->excavate_count = (int)count;
    for (size_t j = 0; j < count; j++) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, (long)j);
        selector_read(doc, &stage->excavate[j], json_array_get(list, j), at);
    }
}

static void stage_read(case_doc *doc, int k, const json_t *value)
{
    case_stage *stage = &doc->stages[k];
    char ptr[CASE_POINTER], at[CASE_POINTER], what[32];
    pointer_join_index(ptr, sizeof ptr, "/stages", k);
    snprintf(stage->name, sizeof stage->name, "stage%d", k);
    if (!case_expect_object(doc, value, ptr)) return;
    snprintf(what, sizeof what, "stage %d", k);
    case_check_keys(doc, value, ptr, stage_keys, what);
    stage_read_name(doc, stage, k, value, ptr);
    double end = NAN;
    if (case_number_member(doc, value, ptr, "end", 1, &end)) {
        pointer_join(at, sizeof at, ptr, "end");
        if (end > 0) stage->end = end;
        else case_problem(doc, at, "end must be > 0, got %g", end);
    }
    if (case_number_member(doc, value, ptr, "relax", 0, &stage->relax) && !(stage->relax >= 0)) {
        pointer_join(at, sizeof at, ptr, "relax");
        case_problem(doc, at, "relax must be >= 0 s, got %g", stage->relax);
    }
    json_t *excavate = case_member(value, ptr, "excavate", at);
    if (excavate) stage_read_excavate(doc, stage, excavate, at);
    json_t *constraints = case_member(value, ptr, "constraints", at);
    if (constraints) case_read_constraint_list(doc, constraints, at, k + 1);
}

/* Each end after the one before it (stages run in the order given). */
static void stages_check_order(case_doc *doc)
{
    int last = -1;
    for (int k = 0; k < doc->stage_count; k++) {
        if (!(doc->stages[k].end > 0)) continue; /* reported where it was read */
        if (last >= 0 && !(doc->stages[k].end > doc->stages[last].end)) {
            char at[CASE_POINTER];
            pointer_join_index(at, sizeof at, "/stages", k);
            pointer_join(at, sizeof at, at, "end");
            case_problem(doc, at, "stage %d (\"%s\") ends at %g s, not after stage %d (\"%s\") "
                                  "at %g s: stages are listed in the order they run",
                         k, doc->stages[k].name, doc->stages[k].end, last,
                         doc->stages[last].name, doc->stages[last].end);
        }
        last = k;
    }
}

/* Names are unique: the status names the stage a case is in. */
static void stages_check_names(case_doc *doc)
{
    json_t *names = NULL;
    for (int k = 0; k < doc->stage_count; k++) {
        int first = case_names_add(doc, &names, doc->stages[k].name, k);
        if (first < 0) continue;
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, "/stages", k);
        case_problem(doc, at, "the stage name \"%s\" is already used by /stages/%d",
                     doc->stages[k].name, first);
    }
    json_decref(names);
}

void case_read_stages(case_doc *doc, const json_t *stages)
{
    doc->stages_given = 1;
    if (!case_expect_array(doc, stages, "/stages")) return;
    size_t count = json_array_size(stages);
    if (count == 0 || count > CASE_MAX_STAGES) {
        case_problem(doc, "/stages", "a case has 1 to %d stages (or no \"stages\"), got %zu",
                     CASE_MAX_STAGES, count);
        return;
    }
    doc->stages = calloc(count, sizeof *doc->stages);
    if (!doc->stages) {
        case_problem(doc, "/stages", "out of memory");
        return;
    }
    doc->stage_count = (int)count;
    for (int k = 0; k < doc->stage_count; k++) {
        doc->stages[k].end = NAN;
        stage_read(doc, k, json_array_get(stages, (size_t)k));
    }
    stages_check_order(doc);
    stages_check_names(doc);
}

void case_check_stage_end(case_doc *doc)
{
    if (doc->stage_count == 0) return;
    const case_stage *last = &doc->stages[doc->stage_count - 1];
    if (!(last->end > 0)) return; /* reported at the stage */
    if (!doc->end_given) {
        doc->end_time = last->end;
        return;
    }
    if (doc->end_time > 0 && doc->end_time != last->end)
        case_problem(doc, "/time/end", "time.end = %.17g s, but the last stage (\"%s\") ends at "
                                       "%.17g s: give the same end, or leave time.end out",
                     doc->end_time, last->name, last->end);
}

void case_stages_free(case_doc *doc)
{
    for (int k = 0; k < doc->stage_count; k++) free(doc->stages[k].excavate);
    free(doc->stages);
    doc->stages = NULL;
    doc->stage_count = 0;
}

/* ------------------------------------------------------------- pass 3 */

/* The model's elements as the selectors see them. */
typedef struct element_table {
    int count, corners, dimension;
    const int32_t *part;   /* model part of each element */
    const int32_t *nodes;  /* `corners` nodes each */
    const double *x0;      /* initial node positions */
    int *first;            /* first element of each document part (part_count + 1) */
    int32_t *mark;         /* stage + 1 that excavates the element, 0: none yet */
    int32_t *picked;       /* this stage's new elements */
} element_table;

static int table_make(const case_doc *doc, const fdem_model *model, element_table *t)
{
    fdem_counts c = fdem_get_counts(model);
    t->count = c.elements;
    t->corners = fdem_nodes_per_element(model);
    t->dimension = fdem_get_dimension(model);
    t->part = fdem_element_parts(model);
    t->nodes = fdem_element_nodes(model);
    t->x0 = fdem_initial_positions(model);
    size_t n = (size_t)(t->count > 0 ? t->count : 1);
    t->first = calloc((size_t)doc->part_count + 1, sizeof *t->first);
    t->mark = calloc(n, sizeof *t->mark);
    t->picked = malloc(n * sizeof *t->picked);
    if (!t->first || !t->mark || !t->picked || !t->part || !t->nodes || !t->x0) return -1;
    /* every part is in the model (pass 3 got here), in document order */
    for (int p = 0, e = 0; p <= doc->part_count; p++) {
        while (e < t->count && t->part[e] < p) e++;
        t->first[p] = e;
    }
    return 0;
}

static void table_free(element_table *t)
{
    free(t->first);
    free(t->mark);
    free(t->picked);
}

static int centroid_in_box(const element_table *t, int e, const double *box)
{
    int dim = t->dimension;
    for (int d = 0; d < dim; d++) {
        double sum = 0;
        for (int c = 0; c < t->corners; c++)
            sum += t->x0[(size_t)dim * (size_t)t->nodes[(size_t)t->corners * (size_t)e + c] + d];
        double x = sum / t->corners;
        if (!(x >= box[d] && x <= box[dim + d])) return 0;
    }
    return 1;
}

/* Adds element e to stage k's list unless a stage already has it. */
static void pick(element_table *t, int k, int e, int *count)
{
    if (t->mark[e]) return;
    t->mark[e] = k + 1;
    t->picked[(*count)++] = e;
}

/* Selector j of stage k: adds its elements; returns how many it selects
 * (those excavated before included). */
static int selector_apply(const case_doc *doc, element_table *t, int k,
                          const case_element_selector *sel, int *count)
{
    int selected = 0;
    if (sel->kind == CASE_PICK_PART) {
        for (int e = t->first[sel->part]; e < t->first[sel->part + 1]; e++, selected++)
            pick(t, k, e, count);
    } else if (sel->kind == CASE_PICK_GROUP) {
        const gmsh_group *g = &doc->parts[sel->part].groups.group[sel->group];
        int begin = t->first[sel->part], size = t->first[sel->part + 1] - begin;
        for (int i = 0; i < g->element_count; i++)
            if (g->elements[i] >= 0 && g->elements[i] < size) {
                pick(t, k, begin + g->elements[i], count);
                selected++;
            }
    } else if (sel->kind == CASE_PICK_BOX) {
        for (int e = 0; e < t->count; e++)
            if (centroid_in_box(t, e, sel->box)) {
                pick(t, k, e, count);
                selected++;
            }
    }
    return selected;
}

/* Stage k's elements into t->picked; -1 after a problem. */
static int stage_resolve(case_doc *doc, element_table *t, int k, int *count)
{
    const case_stage *stage = &doc->stages[k];
    char ptr[CASE_POINTER], at[CASE_POINTER];
    pointer_join_index(ptr, sizeof ptr, "/stages", k);
    pointer_join(ptr, sizeof ptr, ptr, "excavate");
    int rc = 0;
    *count = 0;
    for (int j = 0; j < stage->excavate_count; j++) {
        if (selector_apply(doc, t, k, &stage->excavate[j], count) > 0) continue;
        pointer_join_index(at, sizeof at, ptr, j);
        case_problem(doc, at, "the selector selects no element: no element's centroid lies in "
                              "the box");
        rc = -1;
    }
    if (rc == 0 && stage->excavate_count > 0 && *count == 0) {
        case_problem(doc, ptr, "every element this stage excavates was excavated by an earlier "
                               "stage already");
        rc = -1;
    }
    return rc;
}

int case_add_stages(case_doc *doc, fdem_model *model)
{
    if (doc->stage_count == 0) return 0;
    element_table t = {0};
    if (table_make(doc, model, &t) < 0) {
        table_free(&t);
        case_problem(doc, "/stages", "out of memory");
        return -1;
    }
    int rc = 0;
    for (int k = 0; k < doc->stage_count; k++) {
        int count = 0;
        if (stage_resolve(doc, &t, k, &count) < 0) {
            rc = -1;
            continue;
        }
        if (rc < 0) continue; /* the later stages are still checked */
        fdem_stage_def def = {0};
        def.end = doc->stages[k].end;
        def.relax = doc->stages[k].relax;
        def.excavate = t.picked;
        def.excavate_count = count;
        fdem_error err = {0};
        if (fdem_add_stage(model, &def, &err) < 0) {
            char ptr[CASE_POINTER];
            pointer_join_index(ptr, sizeof ptr, "/stages", k);
            case_engine_problem(doc, &err, ptr);
            rc = -1;
        }
    }
    table_free(&t);
    return rc;
}
