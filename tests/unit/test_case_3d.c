/*
 * test_case_3d.c - case documents with "dimension": 3 (contract 5.2): every
 * 3D shape builds the mesh its generator (or the gmsh reader) makes on its
 * own, vectors carry three components into the engine, and each class of
 * bad input is a 422 at the JSON Pointer of the thing at fault. The 2D
 * checks of the same kind are in test_case.c; both use case_doc.h.
 */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case/case.h"
#include "case_doc.h"
#include "check.h"
#include "gmsh/gmsh.h"
#include "mesh/mesh_3d.h"

/* One 0.1 x 0.2 x 0.3 m box of 2 x 3 x 4 cells, three constraints. */
static const char *base3d =
    "{'name': 'solid', 'dimension': 3,"
    " 'materials': {"
    "   'rock': {'density': 2700, 'young': 3e10, 'poisson': 0.25,"
    "            'fracture': {'tensile_strength': 5e6, 'cohesion': 2e7, 'friction_angle': 30,"
    "                         'energy_I': 20, 'energy_II': 100}}},"
    " 'parts': ["
    "   {'name': 'block', 'material': 'rock', 'velocity': [0.5, 0, -1],"
    "    'box': {'origin': [0, 0, 0], 'size': [0.1, 0.2, 0.3], 'divisions': [2, 3, 4]}}],"
    " 'constraints': ["
    "   {'part': 'block', 'velocity': [null, null, -1]},"
    "   {'box': [-1, -1, -0.001, 1, 1, 0.001], 'fix': ['x', 'y', 'z']},"
    "   {'box': [-1, -1, 0.299, 1, 1, 0.301], 'force': [0, 0, -1000]}],"
    " 'gravity': [0, 0, -9.81],"
    " 'time': {'end': 0.001},"
    " 'output': {'fields': ['position', 'velocity', 'stress']}}";

/* Two tetrahedra sharing the face (1, 2, 3), both of positive volume. */
static const char *two_tets =
    "{'nodes': [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]],"
    " 'tetrahedra': [[0, 1, 2, 3], [1, 2, 3, 4]]}";

static void expect_variant(const char *at, const char *value, const char *pointer,
                           const char *needle)
{
    expect_variant_of(base3d, at, value, pointer, needle);
}

/* base3d with part 0's box replaced by `key`: `shape` (NULL: no shape). */
static json_t *with_shape(const char *key, json_t *shape)
{
    json_t *doc = load(base3d);
    edit(doc, "/parts/0/box", NULL);
    edit(doc, "/constraints", load("[]"));
    if (shape) json_object_set_new(json_array_get(json_object_get(doc, "parts"), 0), key, shape);
    return doc;
}

/* One bad edit of a shape: `value` (NULL deletes) at `at` inside it. */
typedef struct shape_edit {
    const char *at, *value, *pointer, *needle;
} shape_edit;

/* Each edit of `shape` (single-quoted) as part 0's `key` must be a 422 at
 * its pointer mentioning its needle. */
static void expect_shape_edits(const char *key, const char *shape, const shape_edit *edits,
                               size_t count)
{
    for (size_t i = 0; i < count; i++) {
        json_t *value = load(shape);
        edit(value, edits[i].at, edits[i].value ? load(edits[i].value) : NULL);
        expect_doc(with_shape(key, value), GiB, 422, edits[i].pointer, edits[i].needle);
    }
}

/* The model holds exactly the generator's mesh: same counts, same nodes. */
static void check_same_mesh(const fdem_model *m, const fdem_tet_mesh *want)
{
    fdem_counts c = fdem_get_counts(m);
    CHECK(c.nodes == want->node_count && c.elements == want->tet_count,
          "model %d nodes %d tetrahedra, generator %d, %d", c.nodes, c.elements,
          want->node_count, want->tet_count);
    if (c.nodes != want->node_count) return;
    const double *x = fdem_initial_positions(m);
    double worst = 0;
    for (int i = 0; i < 3 * c.nodes; i++) worst = fmax(worst, fabs(x[i] - want->xyz[i]));
    CHECK(worst == 0, "node positions differ by up to %g", worst);
}

/* --------------------------------------------------------- valid cases */

static void box_case_builds(void)
{
    case_info info;
    fdem_model *m = expect_built(load(base3d), &info);
    if (!m) return;
    CHECK(fdem_get_dimension(m) == 3, "dimension %d", fdem_get_dimension(m));
    CHECK(fdem_nodes_per_element(m) == 4 && fdem_stress_components(m) == 6,
          "%d nodes per element, %d stress components", fdem_nodes_per_element(m),
          fdem_stress_components(m));
    fdem_tet_mesh box;
    fdem_error err;
    const double origin[3] = {0, 0, 0}, size[3] = {0.1, 0.2, 0.3};
    const int div[3] = {2, 3, 4};
    CHECK(fdem_tet_mesh_box(origin, size, div, &box, &err) == 0, "%s", err.message);
    check_same_mesh(m, &box);
    fdem_tet_mesh_free(&box);
    fdem_counts c = fdem_get_counts(m);
    CHECK(c.nodes == 3 * 4 * 5 && c.elements == 6 * 2 * 3 * 4, "nodes %d elements %d", c.nodes,
          c.elements);
    /* the bottom and top layers hold 3 x 4 nodes each */
    CHECK(fdem_constraint_node_count(m, 0) == c.nodes, "part constraint: %d nodes",
          fdem_constraint_node_count(m, 0));
    CHECK(fdem_constraint_node_count(m, 1) == 12, "bottom: %d nodes",
          fdem_constraint_node_count(m, 1));
    CHECK(fdem_constraint_node_count(m, 2) == 12, "top: %d nodes",
          fdem_constraint_node_count(m, 2));
    /* the part's velocity on every node above the fixed bottom layer */
    const double *v = fdem_velocities(m), *x = fdem_initial_positions(m);
    int moving = 0;
    for (int i = 0; i < c.nodes; i++)
        moving += x[3 * i + 2] > 0 && v[3 * i] == 0.5 && v[3 * i + 1] == 0 && v[3 * i + 2] == -1;
    CHECK(moving == c.nodes - 12, "%d of %d nodes have velocity (0.5, 0, -1)", moving,
          c.nodes - 12);
    CHECK_REL(info.dt, 0.5 * info.stable_dt, 1e-15);
    CHECK(info.part_count == 1 && info.constraint_count == 3, "parts %d constraints %d",
          info.part_count, info.constraint_count);
    fdem_model_destroy(m);
}

/* Gravity reaches the engine in three components: one free step from rest
 * moves every node by g dt^2 / 2, free fall (the first step of the central
 * difference starts from the initial velocity with half a step). */
static void gravity_has_three_components(void)
{
    json_t *doc = load(base3d);
    edit(doc, "/constraints", load("[]"));
    edit(doc, "/parts/0/velocity", NULL);
    edit(doc, "/gravity", load("[1, -2, -9.81]"));
    case_info info;
    fdem_model *m = expect_built(doc, &info);
    if (!m) return;
    fdem_error err;
    CHECK(fdem_step(m, &err) == 0, "%s", err.message);
    const double *x = fdem_positions(m), *x0 = fdem_initial_positions(m);
    const double g[3] = {1, -2, -9.81};
    double dt = fdem_get_dt(m);
    for (int a = 0; a < 3; a++)
        CHECK_REL(x[a] - x0[a], 0.5 * g[a] * dt * dt, 1e-9);
    fdem_model_destroy(m);
}

static void sphere_builds(void)
{
    case_info info;
    fdem_model *m = expect_built(with_shape("sphere", load("{'center': [1, 2, 3], 'radius': 0.05, "
                                                       "'divisions': 12}")),
                             &info);
    if (!m) return;
    fdem_tet_mesh want;
    fdem_error err;
    const double center[3] = {1, 2, 3};
    CHECK(fdem_tet_mesh_sphere(center, 0.05, 12, &want, &err) == 0, "%s", err.message);
    check_same_mesh(m, &want);
    fdem_tet_mesh_free(&want);
    fdem_model_destroy(m);
}

static void cylinder_builds(void)
{
    case_info info;
    fdem_model *m = expect_built(with_shape("cylinder", load("{'center': [0, 0, 0], 'axis': 'y', "
                                                         "'radius': 0.05, 'length': 0.2, "
                                                         "'divisions': [16, 5]}")),
                             &info);
    if (!m) return;
    fdem_tet_mesh want;
    fdem_error err;
    const double center[3] = {0, 0, 0};
    const int div[2] = {16, 5};
    CHECK(fdem_tet_mesh_cylinder(center, 1, 0.05, 0.2, div, &want, &err) == 0, "%s",
          err.message);
    check_same_mesh(m, &want);
    fdem_tet_mesh_free(&want);
    /* along y from 0 to the length */
    const double *x = fdem_initial_positions(m);
    double ymax = 0;
    for (int i = 0; i < fdem_get_counts(m).nodes; i++) ymax = fmax(ymax, x[3 * i + 1]);
    CHECK_NEAR(ymax, 0.2, 1e-15);
    fdem_model_destroy(m);
}

static void explicit_mesh_builds_in_either_orientation(void)
{
    case_info info;
    fdem_model *m = expect_built(with_shape("mesh", load(two_tets)), &info);
    if (m) {
        fdem_counts c = fdem_get_counts(m);
        CHECK(c.nodes == 5 && c.elements == 2, "nodes %d elements %d", c.nodes, c.elements);
        fdem_model_destroy(m);
    }
    /* the second tetrahedron given with negative volume is turned round */
    json_t *mesh = load(two_tets);
    edit(mesh, "/tetrahedra/1", load("[2, 1, 3, 4]"));
    m = expect_built(with_shape("mesh", mesh), &info);
    if (!m) return;
    const int32_t *tet = fdem_tetrahedra(m);
    const double *x = fdem_initial_positions(m);
    for (int t = 0; t < 2; t++) {
        const double *p[4];
        for (int k = 0; k < 4; k++) p[k] = x + 3 * tet[4 * t + k];
        double e[3][3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) e[k][a] = p[k + 1][a] - p[0][a];
        double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                     e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        CHECK(det > 0, "tetrahedron %d has volume %g", t, det / 6);
    }
    fdem_model_destroy(m);
}

/* The cube of tests/data/cube.geo: 45 nodes, 100 tetrahedra (test_gmsh.c),
 * from either file format. */
static void gmsh_tetrahedra_build(void)
{
    const char *files[2] = {"tests/data/cube_v22.msh", "tests/data/cube_v41.msh"};
    for (int f = 0; f < 2; f++) {
        size_t length = 0;
        char *text = read_file(files[f], &length);
        if (!text) continue;
        case_info info;
        fdem_model *m = expect_built(with_shape("gmsh", json_stringn(text, length)), &info);
        free(text);
        if (!m) continue;
        fdem_counts c = fdem_get_counts(m);
        CHECK(c.nodes == 45 && c.elements == 100, "%s: nodes %d elements %d", files[f], c.nodes,
              c.elements);
        fdem_model_destroy(m);
    }
}

/* Two parts in 3D need contact between tetrahedral parts; until the engine
 * has it, finalize says so at the top of the document (and nothing else is
 * wrong with the case). Once it lands the case builds with both parts. */
static void two_parts_build_or_wait_for_contact(void)
{
    json_t *doc = load(base3d);
    edit(doc, "/parts/1", load("{'name': 'lid', 'material': 'rock', 'box': {'origin': "
                               "[0, 0, 0.31], 'size': [0.1, 0.2, 0.1], 'divisions': [1, 1, 1]}}"));
    problems p;
    case_info info;
    fdem_model *m = build_json(doc, GiB, &info, &p);
    json_decref(doc);
    if (m) {
        fdem_counts c = fdem_get_counts(m);
        CHECK(c.parts == 2 && c.elements == 144 + 6, "parts %d elements %d", c.parts,
              c.elements);
        fdem_model_destroy(m);
    } else {
        CHECK(p.count == 1 && strstr(p.items[0].message, "contact between tetrahedral parts"),
              "%d problems", p.count);
        if (p.count != 1) dump_problems(&p);
    }
    problems_free(&p);
}

/* A second body placed into the block is refused at its part, whether it
 * reaches in partly or sits exactly on the block; one just touching it
 * builds (the lid above, flush on the top face). */
static void bodies_overlapping_at_start(void)
{
    const char *lid = "{'name': 'lid', 'material': 'rock', 'box': {'origin': [0, 0, 0.3], "
                      "'size': [0.1, 0.2, 0.1], 'divisions': [2, 3, 1]}}";
    json_t *doc = load(base3d);
    edit(doc, "/parts/1", load(lid));
    case_info info;
    fdem_model *m = expect_built(doc, &info);
    if (m) fdem_model_destroy(m);
    doc = load(base3d);
    edit(doc, "/parts/1", load(lid));
    edit(doc, "/parts/1/box/origin/2", json_real(0.25));
    expect_doc(doc, GiB, 422, "/parts/1", "part 1 overlaps part 0 at the start");
    doc = load(base3d);
    edit(doc, "/parts/1", load("{'name': 'twin', 'material': 'rock', 'box': {'origin': [0, 0, 0],"
                               " 'size': [0.1, 0.2, 0.3], 'divisions': [2, 3, 4]}}"));
    expect_doc(doc, GiB, 422, "/parts/1", "overlaps part 0");
}

/* ------------------------------------------------------------- problems */

/* Values each > 0 whose ratio has no finite wave speed leave no stable
 * step: named at the material, not at the document's root. */
static void material_without_a_wave_speed(void)
{
    expect_variant("/materials/rock/density", "5e-324", "/materials/rock", "wave speed");
    expect_variant("/materials/rock/young", "5e-324", "/materials/rock", "wave speed");
}

static void dimension_must_be_2_or_3(void)
{
    expect_variant("/dimension", "4", "/dimension", "2 or 3, got 4");
    expect_variant("/dimension", "2.5", "/dimension", "2 or 3");
    expect_variant("/dimension", "'3'", "/dimension", "expected 2 or 3, got a string");
    expect_variant("/dimensions", "3", "/dimensions", "did you mean \"dimension\"");
}

static void vectors_have_three_components(void)
{
    expect_variant("/gravity", "[0, -9.81]", "/gravity", "three numbers");
    expect_variant("/gravity", "[0, 0, 'down']", "/gravity/2", "expected a number");
    expect_variant("/parts/0/velocity", "[0, 0]", "/parts/0/velocity", "three numbers");
    expect_variant("/constraints/0/velocity", "[null, -1]", "/constraints/0/velocity",
                   "[vx, vy, vz]");
    expect_variant("/constraints/0/velocity", "[null, null, null]", "/constraints/0/velocity",
                   "constrains nothing");
    expect_variant("/constraints/0/velocity", "[null, null, 'a']", "/constraints/0/velocity/2",
                   "number or null");
    expect_variant("/constraints/2/force", "[0, -1000]", "/constraints/2/force",
                   "three numbers");
    expect_variant("/constraints/1/box", "[-1, -1, 1, 1]", "/constraints/1/box",
                   "[xmin, ymin, zmin, xmax, ymax, zmax]");
    expect_variant("/constraints/1/box", "[-1, -1, 1, 1, 1, 0]", "/constraints/1/box",
                   "zmin <= zmax");
    expect_variant("/constraints/1/box", "[-1, -1, 0, 1, 'a', 0]", "/constraints/1/box/4",
                   "expected a number");
    expect_variant("/constraints/1/fix", "['w']", "/constraints/1/fix/0",
                   "\"x\", \"y\" or \"z\"");
    expect_variant("/constraints/1/fix", "['x', 'y', 'z', 'x']", "/constraints/1/fix",
                   "components to fix");
    /* a selection with no node is found by the engine at finalize */
    expect_variant("/constraints/1/box", "[5, 5, 5, 6, 6, 6]", "/constraints/1", "no node");
}

static void shapes_of_the_other_dimension(void)
{
    json_t *doc = with_shape("rectangle", load("{'size': [1, 1], 'divisions': [1, 1]}"));
    expect_doc(doc, GiB, 422, "/parts/0/rectangle", "2D shape");
    doc = with_shape("disc", load("{'radius': 1, 'divisions': 8}"));
    expect_doc(doc, GiB, 422, "/parts/0/disc", "use a box, sphere, cylinder, mesh or gmsh");
    /* and 3D shapes in a 2D case */
    const char *shapes[3][2] = {
        {"box", "{'size': [1, 1, 1], 'divisions': [1, 1, 1]}"},
        {"sphere", "{'radius': 1, 'divisions': 8}"},
        {"cylinder", "{'axis': 'z', 'radius': 1, 'length': 1, 'divisions': [8, 1]}"},
    };
    for (int s = 0; s < 3; s++) {
        doc = with_shape(shapes[s][0], load(shapes[s][1]));
        edit(doc, "/dimension", NULL);
        edit(doc, "/gravity", NULL);
        edit(doc, "/parts/0/velocity", NULL);
        char at[64];
        snprintf(at, sizeof at, "/parts/0/%s", shapes[s][0]);
        expect_doc(doc, GiB, 422, at, "3D shape and this case is 2D");
    }
    /* a triangle mesh in a 3D case names what a 3D mesh needs */
    doc = with_shape("mesh", load("{'nodes': [[0, 0], [1, 0], [0, 1]], 'triangles': [[0, 1, 2]]}"));
    expect_doc(doc, GiB, 422, "/parts/0/mesh", "missing required \"tetrahedra\"");
    doc = with_shape(NULL, NULL);
    expect_doc(doc, GiB, 422, "/parts/0", "box, sphere, cylinder, mesh or gmsh");
}

static void box_errors(void)
{
    expect_variant("/parts/0/box/size", "[0.1, 0, 0.3]", "/parts/0/box/size", "> 0");
    expect_variant("/parts/0/box/size", "[0.1, 0.2]", "/parts/0/box/size", "three numbers");
    expect_variant("/parts/0/box/size", NULL, "/parts/0/box", "[sx, sy, sz]");
    expect_variant("/parts/0/box/origin", "[0, 0]", "/parts/0/box/origin", "three numbers");
    expect_variant("/parts/0/box/divisions", "[2, 3]", "/parts/0/box/divisions", "[nx, ny, nz]");
    expect_variant("/parts/0/box/divisions", "[2, 0, 4]", "/parts/0/box/divisions/1",
                   "at least 1");
    expect_variant("/parts/0/box/divisions", "[2, 3, 4.5]", "/parts/0/box/divisions/2",
                   "whole number");
    expect_variant("/parts/0/box/divisons", "[1, 1, 1]", "/parts/0/box/divisons", "divisions");
}

static void sphere_and_cylinder_errors(void)
{
    static const shape_edit bad_sphere[] = {
        {"/divisions", "7", "/parts/0/sphere/divisions", "at least 8"},
        {"/radius", "-1", "/parts/0/sphere/radius", "> 0"},
        {"/center", "[0, 0]", "/parts/0/sphere/center", "three numbers"},
        {"/divisions", NULL, "/parts/0/sphere", "great circle"},
    };
    expect_shape_edits("sphere", "{'radius': 1, 'divisions': 8}", bad_sphere,
                       sizeof bad_sphere / sizeof bad_sphere[0]);
    const char *cylinder = "{'axis': 'z', 'radius': 1, 'length': 2, 'divisions': [8, 2]}";
    static const shape_edit bad[] = {
        {"/axis", "'w'", "/parts/0/cylinder/axis", "\"x\", \"y\" or \"z\", got \"w\""},
        {"/axis", "2", "/parts/0/cylinder/axis", "got a number"},
        {"/axis", NULL, "/parts/0/cylinder", "missing required \"axis\""},
        {"/length", "0", "/parts/0/cylinder/length", "> 0"},
        {"/radius", NULL, "/parts/0/cylinder", "missing required \"radius\""},
        {"/divisions", "[7, 2]", "/parts/0/cylinder/divisions/0", "at least 8"},
        {"/divisions", "[8, 0]", "/parts/0/cylinder/divisions/1", "at least 1"},
        {"/divisions", "8", "/parts/0/cylinder/divisions", "[around the rim, along the axis]"},
        {"/center", "[0, 0, 0, 0]", "/parts/0/cylinder/center", "three numbers"},
    };
    expect_shape_edits("cylinder", cylinder, bad, sizeof bad / sizeof bad[0]);
}

static void explicit_mesh_errors(void)
{
    static const shape_edit bad[] = {
        {"/tetrahedra/1", "[1, 2, 3, 9]", "/parts/0/mesh/tetrahedra/1",
         "node index 9 is out of range"},
        {"/tetrahedra/1", "[1, 2, 3, -1]", "/parts/0/mesh/tetrahedra/1/3", "at least 0"},
        {"/tetrahedra/1", "[1, 2, 3]", "/parts/0/mesh/tetrahedra/1", "four node indices"},
        {"/tetrahedra/0", "[0, 1, 1, 3]", "/parts/0/mesh/tetrahedra/0", "twice"},
        {"/nodes/3", "[1, 1, 0]", "/parts/0/mesh/tetrahedra/0", "zero volume"},
        {"/nodes/1", "[1, 0, 'x']", "/parts/0/mesh/nodes/1/2", "expected a number"},
        {"/nodes/1", "[1, 0]", "/parts/0/mesh/nodes/1", "three numbers"},
        {"/nodes/5", "[2, 2, 2]", "/parts/0/mesh/nodes/5", "not used by any tetrahedron"},
        {"/tetrahedra", "[]", "/parts/0/mesh/tetrahedra", "at least one tetrahedron"},
        {"/nodes", "[[0, 0, 0], [1, 0, 0], [0, 1, 0]]", "/parts/0/mesh/nodes",
         "at least 4 nodes"},
        {"/tetrahedra", NULL, "/parts/0/mesh", "missing required \"tetrahedra\""},
        {"/triangles", "[[0, 1, 2]]", "/parts/0/mesh/triangles", "unknown key \"triangles\""},
        /* a repeated tetrahedron (in any order) would double its mass and stiffness */
        {"/tetrahedra/2", "[3, 2, 1, 0]", "/parts/0/mesh/tetrahedra/2",
         "same nodes as tetrahedron 0"},
    };
    expect_shape_edits("mesh", two_tets, bad, sizeof bad / sizeof bad[0]);
}

static void gmsh_errors(void)
{
    /* a 2D file has no tetrahedra */
    size_t length = 0;
    char *square = read_file("tests/data/square_v41.msh", &length);
    if (square) {
        expect_doc(with_shape("gmsh", json_stringn(square, length)), GiB, 422, "/parts/0/gmsh",
                   "no 4-node tetrahedra");
        free(square);
    }
    expect_doc(with_shape("gmsh", json_string("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n")),
               GiB, 422, "/parts/0/gmsh", "line 5");
    expect_doc(with_shape("gmsh", json_integer(1)), GiB, 422, "/parts/0/gmsh",
               "text of a .msh file");
}

/* A fracturing box gets its own four nodes per tetrahedron and a joint on
 * every interior face: 2 x 3 x 4 cells of 6 tetrahedra have 4 x 144 faces,
 * 2 x 52 of them on the hull, the rest paired. */
static void fracture_builds_a_joint_on_every_interior_face(void)
{
    json_t *doc = load(base3d);
    edit(doc, "/parts/0/fracture", json_true());
    case_info info;
    fdem_model *m = expect_built(doc, &info);
    if (m) {
        fdem_counts c = fdem_get_counts(m);
        CHECK(c.elements == 144 && c.nodes == 4 * 144, "%d elements, %d nodes", c.elements,
              c.nodes);
        CHECK(c.joints == (4 * 144 - 2 * 52) / 2 && c.broken_joints == 0, "%d joints, %d broken",
              c.joints, c.broken_joints);
        fdem_model_destroy(m);
    }
    /* the material must say how it breaks */
    doc = load(base3d);
    edit(doc, "/parts/0/fracture", json_true());
    edit(doc, "/materials/rock/fracture", NULL);
    expect_doc(doc, GiB, 422, "/parts/0/fracture", "needs a \"fracture\" block");
}

/* ------------------------------------------------------------- memory */

static void absurd_3d_divisions_are_refused_by_size(void)
{
    expect_variant("/parts/0/box/divisions", "[1e4, 1e4, 1e4]", "/parts",
                   "more than this daemon's limit of 1 GiB");
    json_t *doc = with_shape("sphere", load("{'radius': 1, 'divisions': 1e5}"));
    expect_doc(doc, GiB, 422, "/parts", "PiB");
    doc = with_shape("cylinder", load("{'axis': 'x', 'radius': 1, 'length': 1, "
                                      "'divisions': [1e4, 1e6]}"));
    expect_doc(doc, GiB, 422, "/parts", "more than this daemon's limit");
    expect_variant("/parts/0/box/divisions", "[1e4, 1e4, 1e4]", "/parts", "6e+12 elements");
}

/* The estimate from the shapes is at least the engine's price of the
 * model it builds, and not absurdly more (the 2D check, for each 3D shape). */
static void memory_estimate_3d_is_not_low(void)
{
    const char *shapes[4][2] = {
        {"box", "{'size': [1, 1, 1], 'divisions': [5, 7, 3]}"},
        {"sphere", "{'radius': 1, 'divisions': 30}"},
        {"cylinder", "{'axis': 'x', 'radius': 1, 'length': 3, 'divisions': [22, 9]}"},
        {"box", "{'size': [1, 1, 1], 'divisions': [5, 7, 3]}"}, /* fracturing */
    };
    for (int s = 0; s < 4; s++) {
        json_t *doc = with_shape(shapes[s][0], load(shapes[s][1]));
        if (s == 3) edit(doc, "/parts/0/fracture", json_true());
        problems p;
        case_info info;
        fdem_model *m = build_json(doc, GiB, &info, &p);
        CHECK(m != NULL, "%s: %d problems", shapes[s][0], p.count);
        problems_free(&p);
        if (m) {
            fdem_counts c = fdem_get_counts(m);
            size_t priced = fdem_memory_estimate_of(&c);
            size_t limit = smallest_accepted_limit(doc);
            CHECK(limit >= priced, "%s accepted at %zu bytes, the real counts price at %zu",
                  shapes[s][0], limit, priced);
            CHECK(limit <= 3 * priced, "%s accepted only at %zu bytes, real counts price at %zu",
                  shapes[s][0], limit, priced);
            fdem_model_destroy(m);
        }
        json_decref(doc);
    }
}

/* Every problem at once, the dimension's first. */
static void all_problems_are_collected(void)
{
    json_t *doc = load(base3d);
    edit(doc, "/dimension", json_integer(5));
    edit(doc, "/parts/0/box/size", load("[0, 1, 1]"));
    edit(doc, "/time/end", json_integer(-1));
    problems p;
    build_refused(doc, GiB, &p);
    CHECK(p.count >= 3 && strcmp(p.items[0].pointer, "/dimension") == 0, "%d problems, first %s",
          p.count, p.count ? p.items[0].pointer : "-");
    CHECK(has_problem(&p, "/time/end", "> 0"), "time.end not reported");
    problems_free(&p);
}

/* A case written for one dimension and read as the other (the usual cause:
 * "dimension": 3 left out, or left in) says so at every vector and fix,
 * not only at the shape: these messages used to end "got an array of
 * another length". */
static void vectors_of_the_other_dimension_name_it(void)
{
    json_t *doc = load(base3d);
    edit(doc, "/dimension", NULL);
    problems p;
    build_refused(doc, GiB, &p);
    static const char *const as_2d[] = {"/gravity", "/parts/0/velocity", "/constraints/0/velocity",
                                        "/constraints/1/box", "/constraints/1/fix",
                                        "/constraints/2/box", "/constraints/2/force",
                                        "/parts/0/box"};
    for (int i = 0; i < 8; i++)
        CHECK(has_problem(&p, as_2d[i], "\"dimension\": 3"), "%s does not name the dimension",
              as_2d[i]);
    problems_free(&p);
    static const struct { const char *at, *value; } as_3d[] = {
        {"/gravity", "[0, -9.81]"}, {"/parts/0/velocity", "[1, 0]"},
        {"/constraints/0/velocity", "[null, -1]"}, {"/constraints/1/box", "[-1, -1, 1, 1]"},
        {"/constraints/2/force", "[0, -1000]"}, {"/parts/0/box/size", "[0.1, 0.2]"}};
    for (int i = 0; i < 6; i++)
        expect_variant(as_3d[i].at, as_3d[i].value, as_3d[i].at, "this case has \"dimension\": 3");
}

CHECK_MAIN(T(box_case_builds), T(gravity_has_three_components), T(sphere_builds),
           T(cylinder_builds), T(explicit_mesh_builds_in_either_orientation),
           T(gmsh_tetrahedra_build), T(two_parts_build_or_wait_for_contact), T(bodies_overlapping_at_start),
           T(material_without_a_wave_speed), T(dimension_must_be_2_or_3), T(vectors_have_three_components),
           T(shapes_of_the_other_dimension), T(box_errors), T(sphere_and_cylinder_errors),
           T(explicit_mesh_errors), T(gmsh_errors), T(fracture_builds_a_joint_on_every_interior_face),
           T(absurd_3d_divisions_are_refused_by_size), T(memory_estimate_3d_is_not_low),
           T(all_problems_are_collected), T(vectors_of_the_other_dimension_name_it))
