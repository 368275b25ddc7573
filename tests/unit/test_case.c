/*
 * test_case.c - case_build() on a small valid document (counts checked
 * against independently generated meshes) and on one variant per class of
 * bad input, each checking the status, the JSON Pointer and a key word of
 * the message. Variants are made by editing the valid document at a JSON
 * Pointer, so each test states only what it breaks.
 *
 * Documents are written with single quotes (turned into double quotes
 * before parsing) to keep them readable in C.
 */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case/case.h"
#include "case_doc.h"
#include "check.h"

static const char *base_text =
    "{'name': 'small',"
    " 'materials': {"
    "   'rock': {'density': 2700, 'young': 3e10, 'poisson': 0.25, 'damping': 0.05,"
    "            'friction': 0.5,"
    "            'fracture': {'tensile_strength': 5e6, 'cohesion': 2e7, 'friction_angle': 30,"
    "                         'energy_I': 20, 'energy_II': 100}},"
    "   'steel': {'density': 7800, 'young': 2e11, 'poisson': 0.3, 'penalty': 2e12}},"
    " 'parts': ["
    "   {'name': 'disc', 'material': 'rock', 'fracture': true,"
    "    'disc': {'center': [0, 0], 'radius': 0.025, 'divisions': 24}},"
    "   {'name': 'top', 'material': 'steel', 'velocity': [0, -0.05],"
    "    'rectangle': {'origin': [-0.01, 0.026], 'size': [0.02, 0.005], 'divisions': [4, 1]}},"
    "   {'name': 'custom', 'material': 'rock',"
    "    'mesh': {'nodes': [[1, 0], [2, 0], [1, 1], [2, 1]],"
    "             'triangles': [[0, 1, 2], [1, 3, 2]]}}],"
    " 'constraints': ["
    "   {'part': 'top', 'velocity': [0, -0.05]},"
    "   {'box': [0.9, -0.1, 1.1, 1.1], 'fix': ['x', 'y']},"
    "   {'box': [1.9, 0.9, 2.1, 1.1], 'force': [1000, 0]}],"
    " 'gravity': [0, -9.81],"
    " 'time': {'end': 0.002, 'dt': 'auto', 'safety': 0.5},"
    " 'output': {'interval': 1e-5, 'fields': ['position', 'velocity', 'stress', 'damage']}}";

/* The valid document with `value` (single-quoted JSON, or NULL to delete)
 * at `at`, expected to fail with a 422 at `pointer` mentioning `needle`. */
static void expect_variant(const char *at, const char *value, const char *pointer,
                           const char *needle)
{
    expect_variant_of(base_text, at, value, pointer, needle);
}

/* Raw text expected to fail with `status` at `pointer` mentioning `needle`. */
static void expect_text(const char *text, size_t length, int status, const char *pointer,
                        const char *needle)
{
    problems p;
    problems_init(&p);
    fdem_model *m = case_build(text, length, GiB, NULL, &p);
    expect_refused(m, &p, status, pointer, needle);
}

/* --------------------------------------------------------- valid cases */

static int count_part_nodes(const fdem_model *m, int part)
{
    fdem_counts c = fdem_get_counts(m);
    const int32_t *node_part = fdem_node_parts(m);
    int n = 0;
    for (int i = 0; i < c.nodes; i++) n += node_part[i] == part;
    return n;
}

static int compare_edge(const void *a, const void *b)
{
    const long long *x = a, *y = b;
    return (*x > *y) - (*x < *y);
}

/* Edges shared by two triangles: where a fracturing part gets its joints. */
static int count_interior_edges(const fdem_mesh *m)
{
    long long *edges = malloc(sizeof *edges * 3 * (size_t)m->triangle_count);
    for (int t = 0; t < m->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            long long a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
            edges[3 * t + k] = a < b ? a * m->node_count + b : b * m->node_count + a;
        }
    qsort(edges, 3 * (size_t)m->triangle_count, sizeof *edges, compare_edge);
    int shared = 0;
    for (int i = 1; i < 3 * m->triangle_count; i++) shared += edges[i] == edges[i - 1];
    free(edges);
    return shared;
}

static void valid_document_builds(void)
{
    /* the disc as the engine's own generator meshes it, independently */
    fdem_mesh disc;
    fdem_error err;
    CHECK(fdem_mesh_disc(0, 0, 0.025, 24, &disc, &err) == 0, "%s", err.message);
    int disc_elements = disc.triangle_count;
    int disc_joints = count_interior_edges(&disc);
    fdem_mesh_free(&disc);

    json_t *doc = load(base_text);
    problems p;
    case_info info;
    fdem_model *m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    CHECK(m != NULL && p.count == 0, "%d problems", p.count);
    if (!m) {
        dump_problems(&p);
        problems_free(&p);
        return;
    }
    fdem_counts c = fdem_get_counts(m);
    /* fracturing disc: 3 own nodes per triangle; rectangle 5 x 2 nodes and
     * 2 x 4 x 1 triangles; explicit mesh 4 nodes, 2 triangles */
    CHECK(c.nodes == 3 * disc_elements + 10 + 4, "nodes %d", c.nodes);
    CHECK(c.elements == disc_elements + 8 + 2, "elements %d", c.elements);
    CHECK(c.joints == disc_joints, "joints %d, want %d (interior edges of the disc)", c.joints,
          disc_joints);
    CHECK(c.parts == 3 && c.materials == 2 && c.constraints == 3, "parts %d materials %d "
          "constraints %d", c.parts, c.materials, c.constraints);
    CHECK(count_part_nodes(m, 1) == 10, "part 1 has %d nodes", count_part_nodes(m, 1));
    CHECK(fdem_constraint_node_count(m, 0) == 10, "constraint 0: %d nodes",
          fdem_constraint_node_count(m, 0));
    CHECK(fdem_constraint_node_count(m, 1) == 2, "constraint 1: %d nodes",
          fdem_constraint_node_count(m, 1));
    CHECK(fdem_constraint_node_count(m, 2) == 1, "constraint 2: %d nodes",
          fdem_constraint_node_count(m, 2));
    /* the initial velocity of part "top" */
    const double *v = fdem_velocities(m);
    const int32_t *node_part = fdem_node_parts(m);
    int moving = 0;
    for (int i = 0; i < c.nodes; i++)
        if (node_part[i] == 1) moving += v[2 * i] == 0 && v[2 * i + 1] == -0.05;
    CHECK(moving == 10, "%d nodes of part 1 have velocity (0, -0.05)", moving);

    CHECK(strcmp(info.name, "small") == 0, "name %s", info.name);
    CHECK_NEAR(info.end_time, 0.002, 0);
    CHECK_NEAR(info.output_interval, 1e-5, 0);
    CHECK(info.fields == (CASE_FIELD_POSITION | CASE_FIELD_VELOCITY | CASE_FIELD_STRESS |
                          CASE_FIELD_DAMAGE), "fields %u", info.fields);
    CHECK(info.part_count == 3 && info.constraint_count == 3 && info.fracture == 1,
          "parts %d constraints %d fracture %d", info.part_count, info.constraint_count,
          info.fracture);
    CHECK_REL(info.stable_dt, fdem_stable_dt(m), 1e-15);
    /* contact binds this case's step: "auto" takes the contact step whole
     * at the default safety (fdem_auto_dt) */
    CHECK_REL(info.dt, fdem_auto_dt(m, info.safety), 1e-15);
    CHECK_REL(info.dt, info.stable_dt, 1e-15);
    CHECK_REL(fdem_get_dt(m), info.dt, 1e-15);
    fdem_model_destroy(m);
    problems_free(&p);
}

static void defaults_apply(void)
{
    json_t *doc = load("{'materials': {'m': {'density': 1000, 'young': 1e9, 'poisson': 0.2}},"
                       " 'parts': [{'material': 'm', 'rectangle': {'size': [1, 2], "
                       "'divisions': [2, 3]}}], 'time': {'end': 0.5, 'dt': 1e-9}}");
    problems p;
    case_info info;
    fdem_model *m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    CHECK(m != NULL, "%d problems", p.count);
    if (!m) {
        dump_problems(&p);
        problems_free(&p);
        return;
    }
    CHECK(strcmp(info.name, "unnamed") == 0, "name %s", info.name);
    CHECK_REL(info.output_interval, 0.5 / 100, 1e-15);
    CHECK(info.fields == (CASE_FIELD_POSITION | CASE_FIELD_VELOCITY), "fields %u", info.fields);
    CHECK_NEAR(info.safety, 0.5, 0);
    CHECK_NEAR(info.dt, 1e-9, 0); /* a given dt below the stable step is kept */
    CHECK(info.constraint_count == 0 && info.fracture == 0, "constraints %d",
          info.constraint_count);
    fdem_counts c = fdem_get_counts(m);
    CHECK(c.nodes == 12 && c.elements == 12, "nodes %d elements %d", c.nodes, c.elements);
    /* origin defaults to (0, 0): every node in [0, 1] x [0, 2] */
    const double *x = fdem_initial_positions(m);
    double xmin = 1e9, ymax = -1e9;
    for (int i = 0; i < c.nodes; i++) {
        xmin = fmin(xmin, x[2 * i]);
        ymax = fmax(ymax, x[2 * i + 1]);
    }
    CHECK_NEAR(xmin, 0, 1e-15);
    CHECK_NEAR(ymax, 2, 1e-15);
    fdem_model_destroy(m);
    problems_free(&p);
}

/* A gmsh file (as written by the installed gmsh) embedded as a string. */
static void gmsh_part_builds(void)
{
    FILE *f = fopen("tests/data/square_v41.msh", "rb");
    CHECK(f != NULL, "tests/data/square_v41.msh missing (run from the repository root)");
    if (!f) return;
    char text[4096];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    json_t *doc = load("{'materials': {'m': {'density': 1000, 'young': 1e9, 'poisson': 0.2}},"
                       " 'parts': [{'material': 'm', 'gmsh': ''}], 'time': {'end': 0.01}}");
    edit(doc, "/parts/0/gmsh", json_string(text));
    problems p;
    case_info info;
    fdem_model *m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    CHECK(m != NULL, "%d problems", p.count);
    if (m) {
        fdem_counts c = fdem_get_counts(m);
        CHECK(c.nodes == 12 && c.elements == 14, "nodes %d elements %d", c.nodes, c.elements);
        fdem_model_destroy(m);
    } else {
        dump_problems(&p);
    }
    problems_free(&p);
}

/* ------------------------------------------------------ malformed JSON */

static void malformed_json_is_400(void)
{
    const char *text = "{\"name\": \"x\",\n \"parts\": [1, 2,]}";
    problems p;
    problems_init(&p);
    CHECK(case_build(text, strlen(text), GiB, NULL, &p) == NULL, "built");
    CHECK(p.status == 400 && p.count == 1, "status %d count %d", p.status, p.count);
    CHECK(strcmp(p.title, "Malformed JSON") == 0, "title %s", p.title);
    CHECK(p.count == 1 && strcmp(p.items[0].pointer, "") == 0 &&
          strstr(p.items[0].message, "line 2") != NULL, "message %s",
          p.count ? p.items[0].message : "");
    problems_free(&p);
    expect_text("", 0, 400, "", "line");
    expect_text("{\"a\": 1} trailing", 17, 400, "", "line 1");
    /* NUL inside strings would cut names short in C: jansson refuses it */
    const char *nul = "{\"name\": \"a\\u0000b\"}";
    expect_text(nul, strlen(nul), 400, "", "line 1");
    /* the length bounds the text: a valid prefix of a longer buffer */
    expect_text("{\"a\": 1}", 5, 400, "", "line 1");
}

static void deep_nesting_is_400(void)
{
    size_t n = 100000;
    char *text = malloc(2 * n);
    memset(text, '[', n);
    memset(text + n, ']', n);
    expect_text(text, 2 * n, 400, "", "depth");
    free(text);
}

static void duplicate_keys_are_400(void)
{
    const char *text = "{\"time\": {\"end\": 1, \"end\": 2}}";
    expect_text(text, strlen(text), 400, "", "duplicate");
}

static void overflowing_numbers_are_400(void)
{
    const char *text = "{\"time\": {\"end\": 1e999}}";
    expect_text(text, strlen(text), 400, "", "overflow");
    const char *big = "{\"time\": {\"end\": 123456789012345678901234567890}}";
    expect_text(big, strlen(big), 400, "", "line 1");
    const char *nan = "{\"time\": {\"end\": NaN}}";
    expect_text(nan, strlen(nan), 400, "", "line 1");
}

static void not_an_object(void)
{
    expect_text("[1, 2]", 6, 422, "", "a case is a JSON object");
}

/* ------------------------------------------------------- unknown keys */

static void unknown_keys_are_named(void)
{
    expect_variant("/materails", "{}", "/materails", "did you mean \"materials\"");
    expect_variant("/materials/rock/densty", "2700", "/materials/rock/densty",
                   "did you mean \"density\"");
    expect_variant("/materials/rock/fracture/energy_1", "20", "/materials/rock/fracture/energy_1",
                   "energy_I");
    expect_variant("/parts/0/velocty", "[0, 0]", "/parts/0/velocty", "did you mean \"velocity\"");
    expect_variant("/parts/1/rectangle/divisons", "[1, 1]", "/parts/1/rectangle/divisons",
                   "divisions");
    expect_variant("/parts/0/disc/centre", "[0, 0]", "/parts/0/disc/centre", "center");
    expect_variant("/parts/2/mesh/elements", "[]", "/parts/2/mesh/elements", "unknown key");
    expect_variant("/constraints/0/fixed", "['x']", "/constraints/0/fixed", "unknown key");
    expect_variant("/time/stop", "1", "/time/stop", "unknown key \"stop\"");
    expect_variant("/output/field", "[]", "/output/field", "did you mean \"fields\"");
}

/* ------------------------------------------------------- wrong types */

static void wrong_types_are_named(void)
{
    expect_variant("/materials/rock/density", "'2700'", "/materials/rock/density",
                   "expected a number, got a string");
    expect_variant("/materials/steel", "[]", "/materials/steel", "expected an object, got an array");
    expect_variant("/parts", "{}", "/parts", "expected an array, got an object");
    expect_variant("/parts/0/fracture", "'yes'", "/parts/0/fracture", "expected true or false");
    expect_variant("/parts/1/velocity", "[0]", "/parts/1/velocity", "two numbers");
    expect_variant("/parts/1/velocity", "[0, null]", "/parts/1/velocity/1",
                   "expected a number, got null");
    expect_variant("/gravity", "'down'", "/gravity", "two numbers");
    expect_variant("/time/end", "true", "/time/end", "expected a number, got a boolean");
    expect_variant("/name", "42", "/name", "expected a string");
    expect_variant("/parts/0/material", "3", "/parts/0/material", "name of a material");
}

/* "fracture" as a region (contract 6.1, case_region.c): each bad selector
 * at its pointer, and a good one builds fewer joints than the whole part. */
static void fracture_regions_are_read(void)
{
    expect_variant("/parts/0/fracture", "{'box': [5, 5, 6, 6]}", "/parts/0/fracture",
                   "outside the part"); /* a generated disc: checked in pass 3 */
    expect_variant("/parts/2/fracture", "{'box': [5, 5, 6, 6]}", "/parts/2/fracture",
                   "outside the part"); /* a given mesh: in pass 1 */
    expect_variant("/parts/2/fracture", "[{'box': [0, 0, 3, 3]}, {'group': 'g'}]",
                   "/parts/2/fracture/1", "gmsh");
    expect_variant("/parts/0/fracture", "{'box': [1, 0, 0, 1]}", "/parts/0/fracture/box",
                   "xmin <= xmax");
    expect_variant("/parts/0/fracture", "{'box': [0, 0, 1]}", "/parts/0/fracture/box",
                   "[xmin, ymin, xmax, ymax]");
    expect_variant("/parts/0/fracture", "{}", "/parts/0/fracture", "exactly one");
    expect_variant("/parts/0/fracture", "[]", "/parts/0/fracture", "1 to 16");
    expect_variant("/parts/0/fracture", "[3]", "/parts/0/fracture/0", "selector");
    expect_variant("/parts/1/fracture", "{'box': [-1, -1, 1, 1]}", "/parts/1/fracture",
                   "\"fracture\" block in material \"steel\"");
    json_t *doc = load(base_text);
    edit(doc, "/parts/0/fracture", load("{'box': [-0.015, -0.015, 0.015, 0.015]}"));
    fdem_model *region = expect_built(doc, NULL);
    fdem_model *whole = expect_built(load(base_text), NULL);
    if (region && whole) {
        fdem_counts r = fdem_get_counts(region), w = fdem_get_counts(whole);
        CHECK(r.joints > 0 && r.joints < w.joints, "region %d joints, whole %d", r.joints,
              w.joints);
        CHECK(r.nodes < w.nodes, "region %d nodes, whole %d", r.nodes, w.nodes);
    }
    fdem_model_destroy(region);
    fdem_model_destroy(whole);
}

/* ---------------------------------------------------- material ranges */

static void material_ranges(void)
{
    expect_variant("/materials/rock/density", "0", "/materials/rock/density", "> 0");
    expect_variant("/materials/rock/young", "-1e9", "/materials/rock/young", "> 0");
    expect_variant("/materials/rock/young", "1e308", "/materials/rock/young", "too large");
    expect_variant("/materials/rock/poisson", "0.5", "/materials/rock/poisson", "incompressible");
    expect_variant("/materials/rock/poisson", "-1", "/materials/rock/poisson", "(-1, 0.5)");
    expect_variant("/materials/rock/poisson", "0.7", "/materials/rock/poisson", "(-1, 0.5)");
    expect_variant("/materials/rock/poisson", NULL, "/materials/rock", "missing required \"poisson\"");
    expect_variant("/materials/rock/damping", "-0.1", "/materials/rock/damping", ">= 0");
    expect_variant("/materials/steel/penalty", "0", "/materials/steel/penalty", "> 0");
    expect_variant("/materials/rock/friction", "-0.5", "/materials/rock/friction", ">= 0");
    expect_variant("/materials/rock/fracture/tensile_strength", "0",
                   "/materials/rock/fracture/tensile_strength", "> 0");
    expect_variant("/materials/rock/fracture/energy_II", "-5",
                   "/materials/rock/fracture/energy_II", "> 0");
    expect_variant("/materials/rock/fracture/friction_angle", "90",
                   "/materials/rock/fracture/friction_angle", "[0, 90)");
    expect_variant("/materials/rock/fracture/cohesion", NULL, "/materials/rock/fracture",
                   "missing required \"cohesion\"");
    expect_variant("/materials", "{}", "/materials", "at least one material");
}

/* The names other codes and textbooks use are pointed at ours, and a key
 * put in the wrong section is pointed at its own: none of these is a typo
 * of the right name, so they used to come without a hint. */
static void other_names_and_places_are_suggested(void)
{
    static const struct { const char *at, *meant; } names[] = {
        {"/materials/rock/youngs_modulus", "did you mean \"young\""},
        {"/materials/rock/E", "did you mean \"young\""},
        {"/materials/rock/poisson_ratio", "did you mean \"poisson\""},
        {"/materials/rock/nu", "did you mean \"poisson\""},
        {"/materials/rock/rho", "did you mean \"density\""},
        {"/materials/rock/fracture/G_I", "did you mean \"energy_I\""},
        {"/time/interval", "\"interval\" belongs in \"output\""},
        {"/output/dt", "\"dt\" belongs in \"time\""},
        {"/time/gravity", "\"gravity\" belongs at the top of the case"}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        expect_variant(names[i].at, "1", names[i].at, names[i].meant);
}

static void unknown_material_is_suggested(void)
{
    expect_variant("/parts/0/material", "'granit'", "/parts/0/material",
                   "unknown material \"granit\"");
    json_t *doc = load(base_text);
    edit(doc, "/materials/granite", load("{'density': 2700, 'young': 3e10, 'poisson': 0.25}"));
    edit(doc, "/parts/1/material", json_string("granit"));
    expect_doc(doc, GiB, 422, "/parts/1/material", "did you mean \"granite\"");
    /* far from every name: the ones the case has are listed */
    expect_variant("/parts/0/material", "'sandstone'", "/parts/0/material",
                   "the case's materials are \"rock\", \"steel\"");
}

/* ----------------------------------------------------------- parts */

static void part_shapes(void)
{
    expect_variant("/parts/1/rectangle", NULL, "/parts/1", "needs a shape");
    expect_variant("/parts/1/disc", "{'radius': 1, 'divisions': 6}", "/parts/1",
                   "rectangle and disc");
    expect_variant("/parts/1/rectangle/size", "[0, 1]", "/parts/1/rectangle/size", "> 0");
    expect_variant("/parts/1/rectangle/size", NULL, "/parts/1/rectangle", "\"size\"");
    expect_variant("/parts/1/rectangle/divisions", "[0, 2]", "/parts/1/rectangle/divisions/0",
                   "at least 1");
    expect_variant("/parts/1/rectangle/divisions", "[1.5, 2]", "/parts/1/rectangle/divisions/0",
                   "whole number");
    expect_variant("/parts/1/rectangle/divisions", "[2, 2, 2]", "/parts/1/rectangle/divisions",
                   "[nx, ny]");
    expect_variant("/parts/0/disc/radius", "-1", "/parts/0/disc/radius", "> 0");
    expect_variant("/parts/0/disc/divisions", "5", "/parts/0/disc/divisions", "at least 6");
    expect_variant("/parts", "[]", "/parts", "1 to 1024 parts");
}

static void explicit_mesh_errors(void)
{
    expect_variant("/parts/2/mesh/triangles/1", "[1, 3, 7]", "/parts/2/mesh/triangles/1",
                   "node index 7 is out of range");
    expect_variant("/parts/2/mesh/triangles/1", "[1, 3, -1]", "/parts/2/mesh/triangles/1/2",
                   "at least 0");
    expect_variant("/parts/2/mesh/triangles/0", "[0, 1, 1]", "/parts/2/mesh/triangles/0",
                   "twice");
    expect_variant("/parts/2/mesh/nodes/2", "[3, 0]", "/parts/2/mesh/triangles/0", "zero area");
    expect_variant("/parts/2/mesh/nodes/1", "[2, 'x']", "/parts/2/mesh/nodes/1/1",
                   "expected a number");
    expect_variant("/parts/2/mesh/triangles/1", "[1, 3]", "/parts/2/mesh/triangles/1",
                   "three node indices");
    expect_variant("/parts/2/mesh/nodes/4", "[5, 5]", "/parts/2/mesh/nodes/4",
                   "not used by any triangle");
    expect_variant("/parts/2/mesh/triangles", NULL, "/parts/2/mesh", "\"triangles\"");
    /* a repeated triangle (in any order) would double its mass and stiffness */
    expect_variant("/parts/2/mesh/triangles/2", "[2, 1, 3]", "/parts/2/mesh/triangles/2",
                   "same nodes as triangle 1");
}

/* The platen lowered into the disc is refused at its part; lowered until
 * it rests on the disc's top vertex it builds. */
static void bodies_overlapping_at_start(void)
{
    expect_variant("/parts/1/rectangle/origin", "[-0.01, 0.02]", "/parts/1",
                   "part 1 overlaps part 0 at the start");
    json_t *doc = load(base_text); /* resting on the disc */
    edit(doc, "/parts/1/rectangle/origin", load("[-0.01, 0.025]"));
    fdem_model_destroy(expect_built(doc, NULL));
}

static void gmsh_errors(void)
{
    expect_variant("/parts/2/gmsh", "'not a mesh'", "/parts/2", "mesh and gmsh"); /* two shapes */
    json_t *doc = load(base_text);
    edit(doc, "/parts/2/mesh", NULL);
    edit(doc, "/parts/2/gmsh", json_string("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n"));
    expect_doc(doc, GiB, 422, "/parts/2/gmsh", "binary");
    doc = load(base_text);
    edit(doc, "/parts/2/mesh", NULL);
    edit(doc, "/parts/2/gmsh", json_string("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n"));
    expect_doc(doc, GiB, 422, "/parts/2/gmsh", "line 5");
    doc = load(base_text);
    edit(doc, "/parts/2/mesh", NULL);
    edit(doc, "/parts/2/gmsh", json_integer(1));
    expect_doc(doc, GiB, 422, "/parts/2/gmsh", "text of a .msh file");
}

static void part_flags_and_names(void)
{
    expect_variant("/parts/1/fracture", "true", "/parts/1/fracture",
                   "needs a \"fracture\" block in material \"steel\"");
    expect_variant("/parts/1/name", "'disc'", "/parts/1", "already used");
    expect_variant("/parts/1/name", "''", "/parts/1/name", "1 to 127 bytes");
    /* control characters would break result.xdmf and the log (issue 30) */
    expect_variant("/name", "'a\\u0001b'", "/name", "control character U+0001 at byte 1");
    expect_variant("/parts/1/name", "'top\\n'", "/parts/1/name", "U+000A at byte 3");
    expect_variant("/name", "'next\\u0085line'", "/name", "U+0085");
    /* a default name ("part1") may collide with a given one */
    json_t *doc = load(base_text);
    edit(doc, "/parts/0/name", json_string("part1"));
    edit(doc, "/parts/1/name", NULL);
    edit(doc, "/constraints/0/part", json_string("part1"));
    expect_doc(doc, GiB, 422, "/parts/1", "\"part1\" is already used");
}

/* ------------------------------------------------------- constraints */

static void constraint_errors(void)
{
    expect_variant("/constraints/0/part", NULL, "/constraints/0", "needs a selector");
    expect_variant("/constraints/1/part", "'top'", "/constraints/1", "exactly one of a selector");
    expect_variant("/constraints/0/velocity", NULL, "/constraints/0", "needs an action");
    expect_variant("/constraints/0/force", "[1, 2]", "/constraints/0", "exactly one of an action");
    expect_variant("/constraints/0/part", "'tpo'", "/constraints/0/part",
                   "unknown part \"tpo\"; did you mean \"top\"?");
    expect_variant("/constraints/1/box", "[1, 0, 0, 1]", "/constraints/1/box", "xmin <= xmax");
    expect_variant("/constraints/1/box", "[1, 0, 2]", "/constraints/1/box", "[xmin, ymin");
    expect_variant("/constraints/1/fix", "['z']", "/constraints/1/fix/0", "\"x\" or \"y\"");
    expect_variant("/constraints/1/fix", "[]", "/constraints/1/fix", "components to fix");
    expect_variant("/constraints/0/velocity", "[null, null]", "/constraints/0/velocity",
                   "constrains nothing");
    expect_variant("/constraints/0/velocity", "[null, 'a']", "/constraints/0/velocity/1",
                   "number or null");
    expect_variant("/constraints/2/force", "[1]", "/constraints/2/force", "two numbers");
    expect_variant("/constraints", "{}", "/constraints", "expected an array");
    /* a box that selects no node is found by the engine at finalize */
    expect_variant("/constraints/2/box", "[5, 5, 6, 6]", "/constraints/2", "no node");
}

static void velocity_constraint_may_leave_a_component_free(void)
{
    json_t *doc = load(base_text);
    edit(doc, "/constraints/0/velocity", load("[null, -0.05]"));
    fdem_model_destroy(expect_built(doc, NULL));
}

/* ------------------------------------------------------ time, output */

static void time_errors(void)
{
    expect_variant("/time", NULL, "", "missing required \"time\"");
    expect_variant("/time/end", "0", "/time/end", "> 0");
    expect_variant("/time/end", NULL, "/time", "missing required \"end\"");
    expect_variant("/time/dt", "'fast'", "/time/dt", "a number or \"auto\", got \"fast\"");
    expect_variant("/time/dt", "[1]", "/time/dt", "a number or \"auto\", got an array");
    expect_variant("/time/dt", "-1e-6", "/time/dt", "> 0");
    expect_variant("/time/safety", "1.5", "/time/safety", "(0, 1]");
    expect_variant("/time/safety", "0", "/time/safety", "(0, 1]");
}

/* More than CASE_MAX_STEPS steps: at the member that makes them so. */
static void absurd_step_counts(void)
{
    expect_variant("/time/dt", "5e-324", "/time/dt", "a dt of at least 2e-15 s");
    json_t *doc = load(base_text);
    edit(doc, "/time/end", json_real(1e308));
    edit(doc, "/output/interval", json_real(1e306));
    expect_doc(doc, GiB, 422, "/time/end", "use an end of at most");
}

/* dt above the stable step: rejected with the stable value in the message. */
static void dt_above_stable_step(void)
{
    json_t *doc = load(base_text);
    problems p;
    case_info info;
    fdem_model *m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    CHECK(m != NULL, "the base document must build");
    if (!m) return;
    double stable = info.stable_dt;
    fdem_model_destroy(m);
    problems_free(&p);
    char value[64], stable_text[64];
    snprintf(value, sizeof value, "%.17g", 1.01 * stable);
    snprintf(stable_text, sizeof stable_text, "%.4g s", stable);
    expect_variant("/time/dt", value, "/time/dt", stable_text);
    /* just below it is accepted */
    doc = load(base_text);
    edit(doc, "/time/dt", json_real(0.99 * stable));
    m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    CHECK(m != NULL && info.dt == 0.99 * stable, "dt below the stable step refused");
    if (m) fdem_model_destroy(m);
    problems_free(&p);
}

static void output_errors(void)
{
    expect_variant("/output/interval", "0", "/output/interval", "> 0");
    expect_variant("/output/interval", "1e-12", "/output/interval", "snapshots");
    expect_variant("/output/fields", "['position', 'pressure']", "/output/fields/1",
                   "unknown field \"pressure\"");
    expect_variant("/output/fields", "['positon']", "/output/fields/0",
                   "did you mean \"position\"");
    expect_variant("/output/fields", "'position'", "/output/fields", "expected an array");
    expect_variant("/output/fields", "['position', 'displacment']", "/output/fields/1",
                   "did you mean \"displacement\"");
}

/* "displacement" is an output field of its own: asked alone, it is the
 * only node field the case writes. */
static void displacement_field_is_read(void)
{
    json_t *doc = load(base_text);
    edit(doc, "/output/fields", load("['displacement', 'stress']"));
    problems p;
    case_info info;
    fdem_model *m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    CHECK(m != NULL, "%d problems", p.count);
    if (m) CHECK(info.fields == (CASE_FIELD_DISPLACEMENT | CASE_FIELD_STRESS), "fields %#x",
                 info.fields);
    fdem_model_destroy(m);
    problems_free(&p);
}

/* ------------------------------------------------------------ memory */

static void absurd_divisions_are_refused_by_size(void)
{
    json_t *doc = load(base_text);
    edit(doc, "/parts/1/rectangle/divisions", load("[1e9, 1e9]"));
    expect_doc(doc, 4 * GiB, 422, "/parts", "more than this daemon's limit of 4 GiB");
    doc = load(base_text);
    edit(doc, "/parts/1/rectangle/divisions", load("[20000, 20000]"));
    expect_doc(doc, 4 * GiB, 422, "/parts", "GiB (about 4e+08 nodes, 8e+08 elements");
    doc = load(base_text);
    edit(doc, "/parts/0/disc/divisions", load("3e5"));
    expect_doc(doc, 4 * GiB, 422, "/parts", "TiB");
    /* without a memory limit the engine's int counts still bound the model */
    doc = load(base_text);
    edit(doc, "/parts/1/rectangle/divisions", load("[1e5, 1e5]"));
    expect_doc(doc, (size_t)-1, 422, "/parts", "the engine's limit is 2147483647");
}

/* The counts estimated from the shapes must not be below the real counts:
 * the case's estimate is at least the engine's price of the real model. */
static void memory_estimate_is_not_low(void)
{
    json_t *doc = load(base_text);
    edit(doc, "/parts/0/disc/divisions", json_integer(200));
    edit(doc, "/parts/1/rectangle/divisions", load("[40, 10]"));
    problems p;
    case_info info;
    fdem_model *m = build_json(doc, GiB, &info, &p);
    CHECK(m != NULL, "%d problems", p.count);
    problems_free(&p);
    if (m) {
        fdem_counts c = fdem_get_counts(m);
        /* joints: one per interior edge of the fracturing disc, at most 1.5 per triangle */
        size_t priced = fdem_memory_estimate_of(&c);
        size_t limit = smallest_accepted_limit(doc);
        CHECK(limit >= priced, "accepted at %zu bytes, the real counts price at %zu", limit,
              priced);
        /* and not absurdly high: within a factor 3 */
        CHECK(limit <= 3 * priced, "accepted only at %zu bytes, real counts price at %zu",
              limit, priced);
        fdem_model_destroy(m);
    }
    json_decref(doc);
}

/* ------------------------------------------------ collection and misc */

static void all_problems_are_collected(void)
{
    json_t *doc = load(base_text);
    edit(doc, "/materials/rock/densty", json_integer(1));
    edit(doc, "/materials/steel/poisson", json_real(0.5));
    edit(doc, "/parts/2/material", json_string("granit"));
    edit(doc, "/constraints/1/fix", load("['z']"));
    edit(doc, "/time/end", json_string("1"));
    problems p;
    build_refused(doc, GiB, &p);
    CHECK(p.count == 5, "%d problems, want 5", p.count);
    if (p.count != 5) dump_problems(&p);
    CHECK(strcmp(p.title, "Invalid case") == 0, "title %s", p.title);
    problems_free(&p);
}

/* Problems of independent sections come in one answer: a dt above the
 * stable step (found only by building a model) beside a bad constraint,
 * material and part (found while reading), and beside a constraint that
 * selects nothing (found while building). */
static void independent_problems_in_one_pass(void)
{
    json_t *doc = load(base_text);
    edit(doc, "/time/dt", json_real(1e-3));
    edit(doc, "/constraints/1/fix", load("['z']"));
    edit(doc, "/materials/steel/poisson", json_real(0.5));
    edit(doc, "/parts/2/material", json_string("granit"));
    problems p;
    case_info info;
    fdem_model *m = build_json(doc, GiB, &info, &p);
    CHECK(p.count == 4, "%d problems, want 4", p.count);
    CHECK(has_problem(&p, "/time/dt", "stable time step of this model's valid parts"),
          "no dt problem");
    CHECK(has_problem(&p, "/constraints/1/fix/0", "\"x\" or \"y\""), "no constraint problem");
    CHECK(has_problem(&p, "/materials/steel/poisson", "0.5"), "no material problem");
    CHECK(has_problem(&p, "/parts/2/material", "granit"), "no part problem");
    if (p.count != 4) dump_problems(&p);
    if (m) fdem_model_destroy(m);
    problems_free(&p);

    /* a dt the valid parts allow is not called too large */
    edit(doc, "/time/dt", json_real(1e-9));
    m = build_json(doc, GiB, &info, &p);
    CHECK(p.count == 3 && !has_problem(&p, "/time/dt", ""), "%d problems, want 3", p.count);
    if (m) fdem_model_destroy(m);
    problems_free(&p);
    json_decref(doc);

    /* the engine refuses two meshes: both are named */
    doc = load(base_text);
    edit(doc, "/parts/2/mesh/nodes", load("[[1, 0], [2, 0], [3, 0], [2, 1]]"));
    edit(doc, "/parts/3", load("{'name': 'flat', 'material': 'rock', 'mesh': {'nodes': "
                               "[[5, 5], [6, 6], [7, 7]], 'triangles': [[0, 1, 2]]}}"));
    m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    CHECK(p.count == 2 && has_problem(&p, "/parts/2/mesh/triangles/0", "") &&
          has_problem(&p, "/parts/3/mesh/triangles/0", ""), "%d problems, want both meshes",
          p.count);
    if (p.count != 2) dump_problems(&p);
    if (m) fdem_model_destroy(m);
    problems_free(&p);

    doc = load(base_text);
    edit(doc, "/time/dt", json_real(1e-3));
    edit(doc, "/constraints/1/box", load("[10, 10, 11, 11]"));
    m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    CHECK(p.count == 2 && has_problem(&p, "/constraints/1", "selects no node") &&
          has_problem(&p, "/time/dt", "stable time step of this model,"),
          "%d problems, want the selection and dt", p.count);
    if (p.count != 2) dump_problems(&p);
    if (m) fdem_model_destroy(m);
    problems_free(&p);

    /* two constraints selecting nothing: both named in one answer */
    doc = load(base_text);
    edit(doc, "/constraints/1/box", load("[10, 10, 11, 11]"));
    edit(doc, "/constraints/2/box", load("[20, 20, 21, 21]"));
    m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    CHECK(!m && p.count == 2 && has_problem(&p, "/constraints/1", "selects no node") &&
              has_problem(&p, "/constraints/2", "selects no node"),
          "%d problems, want /constraints/1 and /constraints/2", p.count);
    if (p.count != 2) dump_problems(&p);
    if (m) fdem_model_destroy(m);
    problems_free(&p);
}

static void pointer_escaping(void)
{
    json_t *doc = load(base_text);
    edit(doc, "/materials/rock", NULL);
    json_object_set_new(json_object_get(doc, "materials"), "a/b~c",
                        load("{'density': -1, 'young': 1e9, 'poisson': 0.2}"));
    expect_doc(doc, GiB, 422, "/materials/a~1b~0c/density", "> 0");
}

static void many_problems_are_capped(void)
{
    json_t *doc = load(base_text);
    json_t *nodes = json_array(), *tris = json_array();
    for (int i = 0; i < 1000; i++) json_array_append_new(nodes, load("[0, 'x']"));
    json_array_append_new(tris, load("[0, 1, 2]"));
    edit(doc, "/parts/2/mesh/nodes", nodes);
    edit(doc, "/parts/2/mesh/triangles", tris);
    problems p;
    build_refused(doc, GiB, &p);
    CHECK(p.count == PROBLEMS_MAX && p.count + p.dropped == 1000, "count %d dropped %d", p.count,
          p.dropped);
    problems_free(&p);
}

static void parse_fields(void)
{
    problems p;
    problems_init(&p);
    CHECK(case_parse_fields("position,stress", &p) == (CASE_FIELD_POSITION | CASE_FIELD_STRESS),
          "position,stress");
    CHECK(case_parse_fields("velocity,damage", &p) == (CASE_FIELD_VELOCITY | CASE_FIELD_DAMAGE),
          "velocity,damage");
    CHECK(case_parse_fields("", &p) == 0 && p.count == 0, "empty");
    CHECK(case_parse_fields("displacement", &p) == CASE_FIELD_DISPLACEMENT && p.count == 0,
          "displacement");
    case_parse_fields("position,presure", &p);
    CHECK(p.status == 400 && p.count == 1 && strstr(p.items[0].message, "\"presure\""),
          "status %d count %d", p.status, p.count);
    problems_free(&p);
}

CHECK_MAIN(T(valid_document_builds), T(defaults_apply), T(gmsh_part_builds),
           T(malformed_json_is_400), T(deep_nesting_is_400), T(duplicate_keys_are_400),
           T(overflowing_numbers_are_400), T(not_an_object), T(unknown_keys_are_named),
           T(wrong_types_are_named), T(fracture_regions_are_read), T(material_ranges), T(unknown_material_is_suggested),
           T(other_names_and_places_are_suggested),
           T(part_shapes), T(explicit_mesh_errors),
           T(bodies_overlapping_at_start), T(gmsh_errors), T(part_flags_and_names),
           T(constraint_errors), T(velocity_constraint_may_leave_a_component_free),
           T(time_errors), T(absurd_step_counts), T(dt_above_stable_step), T(output_errors),
           T(displacement_field_is_read),
           T(absurd_divisions_are_refused_by_size), T(memory_estimate_is_not_low),
           T(all_problems_are_collected), T(independent_problems_in_one_pass),
           T(pointer_escaping), T(many_problems_are_capped),
           T(parse_fields))
