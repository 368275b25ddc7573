/*
 * test_case_stages.c - the "stages" of a case document (contract 6.1) in
 * 2D and 3D: what a valid list gives (time.end from the last stage, the
 * names in case_info, stage constraints in the model after the top-level
 * ones), which elements each "excavate" selector hands the engine (seen in
 * fdem_element_active() after the stage's first step: a part, a gmsh
 * group, a box by centroid, an element two stages name), and every bad
 * input in one 422 at its JSON Pointer.
 *
 * Its own file rather than more of test_case.c / test_case_3d.c: those are
 * near the size a file should stay under, and stages are one section that
 * reads the same in both dimensions.
 */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case/case.h"
#include "case_doc.h"
#include "check.h"
#include "read_file.h"

/* A 2 x 1 block of 8 x 4 squares (64 triangles) over [0, 2] x [0, 1] and
 * a bar above it, in two stages. */
static const char *base_2d =
    "{'name': 'staged',"
    " 'materials': {'rock': {'density': 2500, 'young': 1e9, 'poisson': 0.25}},"
    " 'parts': ["
    "   {'name': 'block', 'material': 'rock',"
    "    'rectangle': {'origin': [0, 0], 'size': [2, 1], 'divisions': [8, 4]}},"
    "   {'name': 'lid', 'material': 'rock',"
    "    'rectangle': {'origin': [0, 2], 'size': [2, 0.5], 'divisions': [4, 1]}}],"
    " 'constraints': [{'box': [-0.1, -0.1, 2.1, 0.01], 'fix': ['x', 'y']}],"
    " 'stages': ["
    "   {'name': 'in-situ', 'end': 0.001},"
    "   {'name': 'dig', 'end': 0.002, 'relax': 0.0005,"
    "    'excavate': [{'box': [0.5, 0.5, 1.5, 1.0]}],"
    "    'constraints': [{'part': 'lid', 'fix': ['x', 'y']}]}],"
    " 'time': {'dt': 'auto'}}";

static fdem_model *build_text(const char *text, case_info *info)
{
    return expect_built(load(text), info);
}

/* The centroid of element e from the initial positions. */
static void centroid(const fdem_model *m, int e, double *c)
{
    int dim = fdem_get_dimension(m), k = fdem_nodes_per_element(m);
    const int32_t *nodes = fdem_element_nodes(m);
    const double *x0 = fdem_initial_positions(m);
    for (int d = 0; d < dim; d++) {
        c[d] = 0;
        for (int i = 0; i < k; i++) c[d] += x0[dim * nodes[k * e + i] + d];
        c[d] /= k;
    }
}

/* Steps until the model is in stage `stage`; 0, or -1 on an engine error. */
static int step_into_stage(fdem_model *m, int stage)
{
    fdem_error err;
    for (int s = 0; s < 100000 && fdem_stage_index(m) < stage; s++)
        if (fdem_step(m, &err) != 0) {
            CHECK(0, "step %d: %s", s, err.message);
            return -1;
        }
    CHECK(fdem_stage_index(m) == stage, "stage %d after stepping, want %d",
          fdem_stage_index(m), stage);
    return 0;
}

/* ------------------------------------------------------------ valid */

static void stages_build_without_time_end(void)
{
    case_info info;
    fdem_model *m = build_text(base_2d, &info);
    if (!m) return;
    CHECK(info.end_time == 0.002, "end %.17g, want the last stage's 0.002", info.end_time);
    CHECK(fabs(info.output_interval - 0.002 / CASE_DEFAULT_SNAPSHOTS) < 1e-18,
          "interval %g", info.output_interval);
    CHECK(info.stage_count == 2, "%d stages", info.stage_count);
    CHECK(strcmp(case_stage_name(&info, 0), "in-situ") == 0 &&
          strcmp(case_stage_name(&info, 1), "dig") == 0, "names %s, %s",
          case_stage_name(&info, 0), case_stage_name(&info, 1));
    CHECK(case_stage_name(&info, 2) == NULL && case_stage_name(&info, -1) == NULL,
          "a stage past the list has a name");
    CHECK(fdem_get_counts(m).constraints == 2, "%d constraints: the top-level one and the "
          "stage's own", fdem_get_counts(m).constraints);
    CHECK(fdem_stage_index(m) == 0, "stage %d before the first step", fdem_stage_index(m));
    CHECK(fdem_element_active(m) == NULL, "elements inactive before any stage removed one");
    fdem_model_destroy(m);
}

static void case_without_stages_has_none(void)
{
    json_t *doc = load(base_2d);
    edit(doc, "/stages", NULL);
    edit(doc, "/time/end", json_real(0.001));
    case_info info;
    fdem_model *m = expect_built(doc, &info);
    if (!m) return;
    CHECK(info.stage_count == 0 && case_stage_name(&info, 0) == NULL, "%d stages",
          info.stage_count);
    CHECK(fdem_stage_index(m) == -1, "stage %d", fdem_stage_index(m));
    fdem_model_destroy(m);
}

static void time_end_must_agree(void)
{
    json_t *doc = load(base_2d);
    edit(doc, "/time/end", json_real(0.002));
    case_info info;
    fdem_model *m = expect_built(doc, &info);
    if (m) fdem_model_destroy(m);
    expect_variant_of(base_2d, "/time/end", "0.003", "/time/end", "the last stage (\"dig\")");
}

/* The box [0.5, 1.5] x [0.5, 1] takes exactly the triangles whose
 * centroid lies in it, bounds included, and only at stage 1. */
static void box_excavates_by_centroid(void)
{
    fdem_model *m = build_text(base_2d, NULL);
    if (!m) return;
    step_into_stage(m, 0);
    CHECK(fdem_element_active(m) == NULL, "an element left during the in-situ stage");
    if (step_into_stage(m, 1) == 0) {
        const uint8_t *active = fdem_element_active(m);
        CHECK(active != NULL, "no element was excavated");
        int removed = 0, elements = fdem_get_counts(m).elements;
        for (int e = 0; active && e < elements; e++) {
            double c[2];
            centroid(m, e, c);
            int inside = c[0] >= 0.5 && c[0] <= 1.5 && c[1] >= 0.5 && c[1] <= 1.0;
            CHECK(active[e] == !inside, "element %d at (%g, %g): active %d", e, c[0], c[1],
                  active[e]);
            removed += !active[e];
        }
        /* 4 x 2 squares of the 8 x 4 lie in the box: 16 triangles */
        CHECK(removed == 16, "%d elements removed, want 16", removed);
    }
    fdem_model_destroy(m);
}

/* A gmsh part after a generated one: the group's elements are found at the
 * part's offset in the model. */
static void group_excavates_its_elements(void)
{
    size_t length = 0;
    char *text = read_file("tests/data/bar_groups_v41.msh", &length);
    if (!text) return;
    json_t *doc = load(base_2d);
    edit(doc, "/parts/1", load("{'name': 'bar', 'material': 'rock', 'gmsh': ''}"));
    edit(doc, "/parts/1/gmsh", json_stringn(text, length));
    free(text);
    /* the bar lies over [0, 2] x [0, 0.5]: the block goes below it */
    edit(doc, "/parts/0/rectangle/origin", load("[0, -2]"));
    edit(doc, "/constraints/0/box", load("[-0.1, -2.1, 2.1, -1.99]"));
    edit(doc, "/stages/1/excavate", load("[{'part': 'bar', 'group': 'soft'}]"));
    edit(doc, "/stages/1/constraints/0", load("{'part': 'block', 'fix': ['x']}"));
    fdem_model *m = expect_built(doc, NULL);
    if (!m) return;
    if (step_into_stage(m, 1) == 0) {
        const uint8_t *active = fdem_element_active(m);
        const int32_t *part = fdem_element_parts(m);
        int removed = 0, elements = fdem_get_counts(m).elements;
        for (int e = 0; active && e < elements; e++) {
            double c[2];
            centroid(m, e, c);
            int soft = part[e] == 1 && c[0] < 1;
            CHECK(active[e] == !soft, "element %d of part %d at (%g, %g): active %d", e,
                  part[e], c[0], c[1], active[e]);
            removed += !active[e];
        }
        CHECK(active && removed > 0, "%d elements removed", removed);
    }
    fdem_model_destroy(m);
}

/* A part named by two stages goes with the first; the second removes the
 * rest of what it names. */
static void an_element_goes_once(void)
{
    json_t *doc = load(base_2d);
    edit(doc, "/stages/0/excavate", load("[{'box': [0.5, 0.5, 1.5, 1.0]}]"));
    edit(doc, "/stages/1/excavate", load("[{'box': [0.5, 0.5, 1.5, 1.0]}, {'part': 'lid'}]"));
    edit(doc, "/stages/1/constraints", NULL);
    fdem_model *m = expect_built(doc, NULL);
    if (!m) return;
    if (step_into_stage(m, 1) == 0) {
        const uint8_t *active = fdem_element_active(m);
        int removed = 0, elements = fdem_get_counts(m).elements;
        for (int e = 0; active && e < elements; e++) removed += !active[e];
        CHECK(removed == 16 + 8, "%d removed, want the 16 of the box and the lid's 8", removed);
    }
    fdem_model_destroy(m);
    /* a stage that would remove only what is gone already says so */
    doc = load(base_2d);
    edit(doc, "/stages/0/excavate", load("[{'part': 'lid'}]"));
    edit(doc, "/stages/1/excavate", load("[{'part': 'lid'}]"));
    edit(doc, "/stages/1/constraints", NULL);
    expect_doc(doc, GiB, 422, "/stages/1/excavate", "earlier stage");
}

/* A stage's pressure on the nodes around what it excavates (a box inside
 * the block, so none of its edges is boundary at the start) loads the
 * opening's wall from the excavation on: the middle of the opening's
 * floor goes down against a twin without it. It used to select no
 * boundary edge and be refused. */
static void stage_pressure_on_the_opening(void)
{
    double drop[2] = {0, 0};
    for (int k = 0; k < 2; k++) {
        json_t *doc = load(base_2d);
        edit(doc, "/stages/1/excavate/0/box", load("[0.5, 0.25, 1.5, 0.75]"));
        edit(doc, "/stages/1/constraints", load(k ? "[]" : "[{'box': [0.49, 0.24, 1.51, 0.76], "
                                                            "'pressure': 1e7}]"));
        case_info info;
        fdem_model *m = expect_built(doc, &info);
        if (!m) return;
        if (step_into_stage(m, 1) == 0)
            for (int s = 0; s < 20; s++) {
                fdem_error err;
                fdem_step(m, &err);
            }
        const double *x = fdem_positions(m), *x0 = fdem_initial_positions(m);
        for (int i = 0; i < fdem_get_counts(m).nodes; i++)
            if (fabs(x0[2 * i] - 1.0) < 1e-9 && fabs(x0[2 * i + 1] - 0.25) < 1e-9)
                drop[k] = x0[2 * i + 1] - x[2 * i + 1];
        fdem_model_destroy(m);
    }
    printf("  the floor of the opening went down %.3g m with the pressure, %.3g m without\n",
           drop[0], drop[1]);
    CHECK(drop[0] > drop[1] + 1e-7, "the pressure did not push the floor: %g m against %g m",
          drop[0], drop[1]);
}

/* ---------------------------------------------------------- refused */

static void every_stage_problem_in_one_answer(void)
{
    json_t *doc = load(base_2d);
    edit(doc, "/stages", load(
        "[{'name': 'a', 'end': 0.002, 'relx': 1},"
        " {'name': 'b', 'end': 0.001, 'relax': -1,"
        "  'excavate': [{'part': 'blok'}, {'part': 'block', 'group': 'g'},"
        "               {'box': [0, 0, 1]}, {'part': 'block', 'box': [0, 0, 1, 1]}, 7],"
        "  'constraints': [{'part': 'lidd', 'fix': ['x']}]},"
        " {'name': 'a'},"
        " {'name': 'd', 'end': 0.003, 'excavate': {'part': 'lid'}},"
        " {'name': '', 'end': -1}]"));
    edit(doc, "/time/end", json_real(0.004));
    problems p;
    build_refused(doc, GiB, &p);
    CHECK(p.status == 422, "status %d", p.status);
    struct { const char *pointer, *needle; } want[] = {
        {"/stages/0/relx", "did you mean \"relax\""},
        {"/stages/1/end", "not after stage 0"},
        {"/stages/1/relax", ">= 0"},
        {"/stages/1/excavate/0/part", "did you mean \"block\""},
        {"/stages/1/excavate/1/group", "not a \"gmsh\" mesh"},
        {"/stages/1/excavate/2/box", "[xmin, ymin, xmax, ymax]"},
        {"/stages/1/excavate/3", "exactly one of"},
        {"/stages/1/excavate/4", "expected an object"},
        {"/stages/1/constraints/0/part", "unknown part \"lidd\""},
        {"/stages/2", "missing required \"end\""},
        {"/stages/2", "already used by /stages/0"},
        {"/stages/3/excavate", "expected an array"},
        {"/stages/4/name", "1 to 63 bytes"},
        {"/stages/4/end", "> 0"},
    };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++)
        CHECK(has_problem(&p, want[i].pointer, want[i].needle), "no problem at %s with \"%s\"",
              want[i].pointer, want[i].needle);
    if (check_failures_in_test) dump_problems(&p);
    problems_free(&p);
}

static void stage_list_shapes(void)
{
    expect_variant_of(base_2d, "/stages", "{}", "/stages", "expected an array");
    expect_variant_of(base_2d, "/stages", "[]", "/stages", "1 to 256 stages");
    expect_variant_of(base_2d, "/stages/0", "3", "/stages/0", "expected an object");
    expect_variant_of(base_2d, "/stages/1/name", "'in-situ'", "/stages/1", "already used");
    expect_variant_of(base_2d, "/stages/1/excavate/0/box", "[1.5, 0.5, 0.5, 1.0]",
                      "/stages/1/excavate/0/box", "xmin <= xmax");
    expect_variant_of(base_2d, "/stages/1/excavate/0", "{'box': [0.5, 0.5, 1.5, 1.0], "
                      "'group': 'g'}", "/stages/1/excavate/0/group", "give \"part\"");
    /* a stage constraint refused by the engine is named where it was written */
    expect_variant_of(base_2d, "/stages/1/constraints/0", "{'part': 'lid', 'absorb': true}",
                      "/stages/1/constraints/0/absorb", "throughout");
}

/* Which elements a box holds is known once the shapes are meshed (pass 3). */
static void box_selecting_nothing(void)
{
    expect_variant_of(base_2d, "/stages/1/excavate/0/box", "[5, 5, 6, 6]",
                      "/stages/1/excavate/0", "selects no element");
}

/* A box that selects nothing, of an excavation or of a fracture region of
 * a generated shape, is named in the same answer as the document's other
 * problems (here a safety out of range), in 2D and 3D: the shapes are
 * meshed for the check. They were named only once the rest was valid. */
static void empty_boxes_with_the_other_problems(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        json_t *doc = load(
            "{'materials': {'rock': {'density': 2500, 'young': 1e9, 'poisson': 0.25,"
            "   'fracture': {'tensile_strength': 5e6, 'cohesion': 2e7, 'friction_angle': 30,"
            "                'energy_I': 20, 'energy_II': 100}}},"
            " 'parts': [{'name': 'block', 'material': 'rock',"
            "            'rectangle': {'origin': [0, 0], 'size': [2, 1], 'divisions': [8, 4]}},"
            "           {'name': 'lid', 'material': 'rock', 'fracture': {'box': [7, 7, 8, 8]},"
            "            'rectangle': {'origin': [0, 2], 'size': [2, 0.5], 'divisions': [4, 1]}}],"
            " 'stages': [{'end': 0.001},"
            "            {'end': 0.002, 'excavate': [{'box': [0.5, 0.5, 1.5, 1.0]},"
            "                                        {'box': [5, 5, 6, 6]}]}],"
            " 'time': {'safety': 2}}");
        if (dim == 3) {
            edit(doc, "/dimension", json_integer(3));
            for (int i = 0; i < 2; i++) {
                char at[64];
                json_object_del(json_array_get(json_object_get(doc, "parts"), (size_t)i),
                                "rectangle");
                snprintf(at, sizeof at, "/parts/%d/box", i);
                edit(doc, at, load(i ? "{'origin': [0, 0, 2], 'size': [2, 1, 0.5], "
                                       "'divisions': [4, 2, 1]}"
                                     : "{'origin': [0, 0, 0], 'size': [2, 1, 1], "
                                       "'divisions': [4, 2, 2]}"));
            }
            edit(doc, "/parts/1/fracture/box", load("[7, 7, 7, 8, 8, 8]"));
            edit(doc, "/stages/1/excavate", load("[{'box': [0.5, 0, 0, 1.5, 1, 1]},"
                                                 " {'box': [5, 5, 5, 6, 6, 6]}]"));
        }
        problems p;
        build_refused(doc, GiB, &p);
        CHECK(p.status == 422, "%dD: status %d", dim, p.status);
        CHECK(has_problem(&p, "/time/safety", "(0, 1]"), "%dD: the safety", dim);
        CHECK(has_problem(&p, "/stages/1/excavate/1", "selects no element"),
              "%dD: the empty excavation box", dim);
        CHECK(has_problem(&p, "/parts/1/fracture", "outside the part"),
              "%dD: the empty region box", dim);
        CHECK(p.count == 3, "%dD: %d problems, want 3", dim, p.count);
        if (check_failures_in_test) dump_problems(&p);
        problems_free(&p);
    }
}

/* ------------------------------------------------------------------ 3D */

static const char *base_3d =
    "{'dimension': 3,"
    " 'materials': {'rock': {'density': 2500, 'young': 1e9, 'poisson': 0.25}},"
    " 'parts': [{'name': 'cube', 'material': 'rock', 'gmsh': ''}],"
    " 'constraints': [{'box': [-0.1, -0.1, -0.1, 0.01, 1.1, 1.1], 'fix': ['x', 'y', 'z']}],"
    " 'stages': ["
    "   {'name': 'in-situ', 'end': 0.0002},"
    "   {'name': 'dig', 'end': 0.0004, 'excavate': [{'part': 'cube', 'group': 'stiff'}]}],"
    " 'time': {'end': 0.0004}}";

static json_t *cube_doc(void)
{
    size_t length = 0;
    char *text = read_file("tests/data/cube_groups_v41.msh", &length);
    if (!text) return NULL;
    json_t *doc = load(base_3d);
    edit(doc, "/parts/0/gmsh", json_stringn(text, length));
    free(text);
    return doc;
}

static void stages_in_3d(void)
{
    json_t *doc = cube_doc();
    if (!doc) return;
    case_info info;
    fdem_model *m = expect_built(doc, &info);
    if (!m) return;
    CHECK(info.stage_count == 2 && info.end_time == 0.0004, "%d stages, end %g",
          info.stage_count, info.end_time);
    if (step_into_stage(m, 1) == 0) {
        const uint8_t *active = fdem_element_active(m);
        int removed = 0, elements = fdem_get_counts(m).elements;
        for (int e = 0; active && e < elements; e++) {
            double c[3];
            centroid(m, e, c);
            CHECK(active[e] == !(c[0] > 1), "tetrahedron %d at x = %g: active %d", e, c[0],
                  active[e]);
            removed += !active[e];
        }
        CHECK(active && removed > 0 && removed < elements, "%d of %d removed", removed,
              elements);
    }
    fdem_model_destroy(m);
}

static void bad_stages_in_3d(void)
{
    json_t *doc = cube_doc();
    if (!doc) return;
    edit(doc, "/stages/1/excavate", load("[{'box': [0, 0, 1, 1]}, {'part': 'cube', 'group': "
                                         "'left'}, {'box': [0, 0, 0, 1, 1, 1]}]"));
    edit(doc, "/time/end", json_real(0.0005));
    problems p;
    build_refused(doc, GiB, &p);
    CHECK(has_problem(&p, "/stages/1/excavate/0/box", "[xmin, ymin, zmin, xmax, ymax, zmax]"),
          "a 2D box in a 3D case");
    CHECK(has_problem(&p, "/stages/1/excavate/1/group", "\"left\" is a surface group"),
          "a group of faces");
    CHECK(has_problem(&p, "/time/end", "ends at 0.0004"), "time.end");
    CHECK(p.count == 3, "%d problems, want 3", p.count);
    if (check_failures_in_test) dump_problems(&p);
    problems_free(&p);
}

CHECK_MAIN(T(stages_build_without_time_end), T(case_without_stages_has_none),
           T(time_end_must_agree), T(box_excavates_by_centroid),
           T(group_excavates_its_elements), T(an_element_goes_once),
           T(stage_pressure_on_the_opening), T(every_stage_problem_in_one_answer),
           T(stage_list_shapes),
           T(box_selecting_nothing), T(empty_boxes_with_the_other_problems), T(stages_in_3d),
           T(bad_stages_in_3d))
