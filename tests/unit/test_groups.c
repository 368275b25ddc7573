/*
 * test_groups.c - gmsh physical groups and what a case does with them
 * (contract 5.3): the groups read from both file formats in 2D and 3D, the
 * {"part", "group"} selector, a bonded body of two materials, joint sets on
 * a group, and Weibull-drawn joint strengths (their statistics, and
 * reproducibility by seed).
 *
 * The meshes are tests/data/bar_groups.geo (a 2 x 0.5 bar, "soft" x < 1,
 * "stiff" x > 1) and cube_groups.geo (two unit cubes the same way), as
 * written by the installed gmsh in formats 2.2 and 4.1.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_doc.h"
#include "check.h"
#include "gmsh/gmsh.h"
#include "mesh/mesh_3d.h"
#include "model/model.h"
#include "read_file.h"

static const char *const bar_files[] = {"tests/data/bar_groups_v22.msh",
                                        "tests/data/bar_groups_v41.msh"};
static const char *const cube_files[] = {"tests/data/cube_groups_v22.msh",
                                         "tests/data/cube_groups_v41.msh"};

static const gmsh_group *named(const gmsh_groups *g, const char *name, int dim)
{
    for (int k = 0; k < g->count; k++)
        if (g->group[k].dim == dim && strcmp(g->group[k].name, name) == 0) return &g->group[k];
    return NULL;
}

/* The nodes of `group` are exactly the mesh nodes with coordinate axis
 * equal to `at` (dim numbers per node). */
static void check_plane_group(const gmsh_group *group, const double *xyz, int nodes, int dim,
                              int axis, double at, const char *what)
{
    CHECK(group != NULL, "%s: no such group", what);
    if (!group) return;
    int on = 0, listed_on = 0;
    for (int i = 0; i < nodes; i++) on += fabs(xyz[dim * i + axis] - at) < 1e-9;
    for (int k = 0; k < group->node_count; k++)
        listed_on += fabs(xyz[dim * group->nodes[k] + axis] - at) < 1e-9;
    CHECK(group->node_count == on && listed_on == on, "%s: %d nodes listed, %d on the plane, %d "
          "listed on it", what, group->node_count, on, listed_on);
    for (int f = 0; f < dim * group->face_count; f++)
        CHECK(fabs(xyz[dim * group->faces[f] + axis] - at) < 1e-9, "%s: a face off the plane",
              what);
}

/* Reads a test mesh of dimension dim (into mesh or tets) with its groups;
 * 0, or -1 after a failed check. */
static int read_groups(const char *path, int dim, fdem_mesh *mesh, fdem_tet_mesh *tets,
                       gmsh_groups *g)
{
    size_t length = 0;
    char *text = read_file(path, &length);
    if (!text) return -1;
    char message[256];
    int rc = dim == 3 ? gmsh_read_tetrahedra_grouped(text, length, tets, g, message, sizeof message)
                      : gmsh_read_grouped(text, length, mesh, g, message, sizeof message);
    free(text);
    CHECK(rc == 0, "%s: %s", path, message);
    return rc;
}

/* Both formats, 2D: the surface groups partition the triangles (the
 * triangles 2.2 writes once per group are one each), "bar" holds them
 * all, the curve groups hold exactly the nodes on their lines and their
 * edges, the point group its one node. */
static void groups_2d(void)
{
    int triangles[2] = {0, 0};
    for (int v = 0; v < 2; v++) {
        fdem_mesh mesh;
        gmsh_groups g;
        if (read_groups(bar_files[v], 2, &mesh, NULL, &g)) continue;
        triangles[v] = mesh.triangle_count;
        const gmsh_group *soft = named(&g, "soft", 2), *stiff = named(&g, "stiff", 2),
                         *bar = named(&g, "bar", 2);
        CHECK(soft && stiff && bar, "%s: surface groups missing", bar_files[v]);
        if (soft && stiff && bar) {
            CHECK(soft->element_count + stiff->element_count == mesh.triangle_count &&
                      bar->element_count == mesh.triangle_count,
                  "%s: %d + %d soft/stiff triangles, %d in bar, %d in the mesh", bar_files[v],
                  soft->element_count, stiff->element_count, bar->element_count,
                  mesh.triangle_count);
            for (int k = 0; k < soft->element_count; k++) {
                const int32_t *t = mesh.tri + 3 * soft->elements[k];
                double cx = (mesh.xy[2 * t[0]] + mesh.xy[2 * t[1]] + mesh.xy[2 * t[2]]) / 3;
                CHECK(cx < 1, "%s: a soft triangle at x = %g", bar_files[v], cx);
            }
        }
        check_plane_group(named(&g, "left", 1), mesh.xy, mesh.node_count, 2, 0, 0, "left");
        check_plane_group(named(&g, "interface", 1), mesh.xy, mesh.node_count, 2, 0, 1,
                          "interface");
        const gmsh_group *interface = named(&g, "interface", 1), *origin = named(&g, "origin", 0);
        CHECK(interface && interface->face_count == interface->node_count - 1,
              "the interface line is a chain of edges");
        CHECK(origin && origin->node_count == 1 && mesh.xy[2 * origin->nodes[0]] == 0 &&
                  mesh.xy[2 * origin->nodes[0] + 1] == 0,
              "the origin group is the node at (0, 0)");
        gmsh_groups_free(&g);
        fdem_mesh_free(&mesh);
    }
    CHECK(triangles[0] == triangles[1] && triangles[0] > 0, "2.2: %d triangles, 4.1: %d",
          triangles[0], triangles[1]);
}

/* The same in 3D: volume groups partition the tetrahedra; the surface
 * groups hold the nodes of their plane and its triangles. */
static void groups_3d(void)
{
    for (int v = 0; v < 2; v++) {
        fdem_tet_mesh mesh;
        gmsh_groups g;
        if (read_groups(cube_files[v], 3, NULL, &mesh, &g)) continue;
        const gmsh_group *soft = named(&g, "soft", 3), *stiff = named(&g, "stiff", 3);
        CHECK(soft && stiff && soft->element_count + stiff->element_count == mesh.tet_count,
              "%s: the volume groups partition the %d tetrahedra", cube_files[v], mesh.tet_count);
        check_plane_group(named(&g, "left", 2), mesh.xyz, mesh.node_count, 3, 0, 0, "left");
        check_plane_group(named(&g, "interface", 2), mesh.xyz, mesh.node_count, 3, 0, 1,
                          "interface");
        const gmsh_group *interface = named(&g, "interface", 2);
        CHECK(interface && interface->face_count > 0, "%s: interface triangles", cube_files[v]);
        gmsh_groups_free(&g);
        fdem_tet_mesh_free(&mesh);
    }
}

/* ------------------------------------------------------------ cases */

/* A case around one gmsh part `file` (materials "soft" and "stiff",
 * fracture blocks on both) with `part` edits applied by the caller. */
static json_t *bar_case(const char *file, int dimension)
{
    json_t *doc = load(
        "{'materials': {"
        " 'soft': {'density': 2000, 'young': 1e9, 'poisson': 0.25, 'damping': 1.0,"
        "          'fracture': {'tensile_strength': 1e8, 'cohesion': 1e8, 'friction_angle': 30,"
        "                       'energy_I': 1e4, 'energy_II': 1e4}},"
        " 'stiff': {'density': 2000, 'young': 4e9, 'poisson': 0.25, 'damping': 1.0,"
        "          'fracture': {'tensile_strength': 1e8, 'cohesion': 1e8, 'friction_angle': 30,"
        "                       'energy_I': 1e4, 'energy_II': 1e4}}},"
        " 'parts': [{'name': 'bar', 'material': 'soft', 'gmsh': ''}],"
        " 'time': {'end': 0.01}}");
    size_t length = 0;
    char *text = read_file(file, &length);
    edit(doc, "/parts/0/gmsh", json_stringn(text ? text : "", text ? length : 0));
    free(text);
    if (dimension == 3) edit(doc, "/dimension", json_integer(3));
    return doc;
}

/* {"part", "group"} selects exactly the nodes on the group: every copy of
 * them in a fracturing part, whatever the group's dimension. */
static void group_selector(void)
{
    for (int dim = 2; dim <= 3; dim++)
        for (int v = 0; v < 2; v++)
            for (int fracture = 0; fracture < 2; fracture++) {
                json_t *doc = bar_case(dim == 3 ? cube_files[v] : bar_files[v], dim);
                edit(doc, "/parts/0/fracture", json_boolean(fracture));
                edit(doc, "/constraints",
                     load("[{'part': 'bar', 'group': 'left', 'fix': ['x']},"
                          " {'part': 'bar', 'group': 'interface', 'fix': ['x']},"
                          " {'part': 'bar', 'group': 'origin', 'fix': ['y']},"
                          " {'part': 'bar', 'group': 'soft', 'fix': ['y']}]"));
                fdem_model *m = expect_built(doc, NULL);
                if (!m) continue;
                const double *x = fdem_initial_positions(m);
                fdem_counts c = fdem_get_counts(m);
                int left = 0, interface = 0, origin = 0, soft = 0;
                for (int i = 0; i < c.nodes; i++) {
                    const double *p = x + dim * i;
                    left += fabs(p[0]) < 1e-9;
                    interface += fabs(p[0] - 1) < 1e-9;
                    origin += fabs(p[0]) + fabs(p[1]) + (dim == 3 ? fabs(p[2]) : 0) < 1e-9;
                    soft += p[0] < 1 + 1e-9;
                }
                int want[4] = {left, interface, origin, soft};
                for (int k = 0; k < 4; k++)
                    CHECK(fdem_constraint_node_count(m, k) == want[k],
                          "%dD %s fracture %d: constraint %d selects %d nodes, %d lie on its "
                          "group", dim, v ? "4.1" : "2.2", fracture, k,
                          fdem_constraint_node_count(m, k), want[k]);
                fdem_model_destroy(m);
            }
}

/* The text of `file` with one more physical name: "ghost", of dimension
 * dim, whose tag no element carries (gmsh writes such a name when a
 * physical group's entities were deleted or never meshed). */
static json_t *with_ghost_group(const char *file, int dim)
{
    size_t length = 0;
    char *raw = read_file(file, &length);
    char *text = raw ? malloc(length + 1) : NULL; /* read_file's bytes have no NUL */
    if (text) memcpy(text, raw, length), text[length] = 0;
    free(raw);
    const char *head = text ? strstr(text, "$PhysicalNames\n") : NULL;
    const char *end = text ? strstr(text, "$EndPhysicalNames") : NULL;
    if (!head || !end) {
        free(text);
        return json_string("");
    }
    const char *names = head + strlen("$PhysicalNames\n");
    char *after_count = NULL;
    long count = strtol(names, &after_count, 10);
    size_t size = length + 64;
    char *out = malloc(size);
    snprintf(out, size, "%.*s%ld%.*s%d 99 \"ghost\"\n%s", (int)(names - text), text, count + 1,
             (int)(end - after_count), after_count, dim, end);
    json_t *string = json_string(out);
    free(out);
    free(text);
    return string;
}

/* A named group with no element of the mesh is refused where a case names
 * it, for each use: a material on it would silently apply to nothing. */
static void empty_group_is_refused(void)
{
    for (int dim = 2; dim <= 3; dim++)
        for (int v = 0; v < 2; v++) {
            const char *file = dim == 3 ? cube_files[v] : bar_files[v];
            json_t *doc = bar_case(file, dim);
            edit(doc, "/parts/0/gmsh", with_ghost_group(file, dim));
            edit(doc, "/parts/0/materials", load("{'ghost': 'stiff'}"));
            expect_doc(doc, GiB, 422, "/parts/0/materials/ghost", "has no element of the mesh");
            doc = bar_case(file, dim);
            edit(doc, "/parts/0/gmsh", with_ghost_group(file, dim - 1));
            edit(doc, "/constraints", load("[{'part': 'bar', 'group': 'ghost', 'fix': ['x']}]"));
            expect_doc(doc, GiB, 422, "/constraints/0/group", "has no node of the mesh");
        }
}

/* Mean of `component` of the element strain over elements whose centroid
 * x lies in (lo, hi). */
static double mean_strain(const fdem_model *m, const double *strain, double lo, double hi)
{
    int K = fdem_nodes_per_element(m), D = fdem_get_dimension(m), S = fdem_stress_components(m);
    const int32_t *en = fdem_element_nodes(m);
    const double *x = fdem_initial_positions(m);
    double sum = 0, size = 0;
    fdem_counts c = fdem_get_counts(m);
    for (int e = 0; e < c.elements; e++) {
        double cx = 0;
        for (int k = 0; k < K; k++) cx += x[D * en[K * e + k]] / K;
        if (cx <= lo || cx >= hi) continue;
        sum += strain[S * e];
        size += 1;
    }
    return size > 0 ? sum / size : NAN;
}

/* One bonded, fracturing body of two materials (E 1 and 4 GPa) pulled by
 * a force on its right end until still: no joint breaks (the interface
 * holds) and each material carries its own strain, sigma/E' with
 * E' = E/(1 - nu^2) in plane strain (2D) and sigma/E in 3D (a uniaxial
 * bar, free sides), so the strains are in the ratio 4 : 1. Measured away
 * from the ends and the interface, where the load and the bond disturb the
 * uniform field; 2 % on each strain and on the ratio. */
static void two_materials_bonded(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        double area = dim == 3 ? 1.0 : 0.5, sigma = 1e6, nu = 0.25;
        json_t *doc = bar_case(dim == 3 ? cube_files[1] : bar_files[1], dim);
        edit(doc, "/parts/0/fracture", json_true());
        edit(doc, "/parts/0/materials", load("{'stiff': 'stiff'}"));
        edit(doc, "/constraints",
             load(dim == 3 ? "[{'part': 'bar', 'group': 'left', 'fix': ['x']},"
                             " {'part': 'bar', 'group': 'origin', 'fix': ['y', 'z']},"
                             " {'box': [-0.01, -0.01, 0.99, 0.01, 0.01, 1.01], 'fix': ['y']},"
                             " {'box': [-0.01, 0.99, -0.01, 0.01, 1.01, 0.01], 'fix': ['z']},"
                             " {'part': 'bar', 'group': 'right', 'force': [0, 0, 0]}]"
                           : "[{'part': 'bar', 'group': 'left', 'fix': ['x']},"
                             " {'part': 'bar', 'group': 'origin', 'fix': ['y']},"
                             " {'part': 'bar', 'group': 'right', 'force': [0, 0]}]"));
        edit(doc, dim == 3 ? "/constraints/4/force/0" : "/constraints/2/force/0",
             json_real(sigma * area));
        fdem_model *m = expect_built(doc, NULL);
        if (!m) continue;
        fdem_counts c = fdem_get_counts(m);
        double *strain = malloc(sizeof(double) * (size_t)fdem_stress_components(m) *
                                (size_t)c.elements);
        /* dynamic relaxation by kinetic damping: the viscous damping is
         * tuned to the fastest mode and would take long to still the
         * slowest, so every kinetic energy peak the velocities are zeroed */
        double kinetic_before = 0, zero[3] = {0, 0, 0};
        for (int s = 0; s < 20000; s++) {
            if (fdem_step(m, NULL)) break;
            double kinetic = fdem_get_energy(m).kinetic;
            if (kinetic < kinetic_before) {
                fdem_set_part_velocity_v(m, 0, zero, NULL);
                kinetic = 0;
            }
            kinetic_before = kinetic;
        }
        fdem_element_strain(m, strain);
        double soft = mean_strain(m, strain, 0.3, 0.7), stiff = mean_strain(m, strain, 1.3, 1.7);
        c = fdem_get_counts(m);
        double factor = dim == 3 ? 1 : 1 - nu * nu;
        CHECK(c.broken_joints == 0, "%dD: %d joints broke", dim, c.broken_joints);
        CHECK_REL(soft, sigma * factor / 1e9, 0.02);
        CHECK_REL(stiff, sigma * factor / 4e9, 0.02);
        CHECK_REL(soft / stiff, 4.0, 0.02);
        printf("  %dD bonded bar: strain soft %.4g (want %.4g), stiff %.4g (want %.4g), ratio "
               "%.4f\n", dim, soft, sigma * factor / 1e9, stiff, sigma * factor / 4e9,
               soft / stiff);
        free(strain);
        fdem_model_destroy(m);
    }
}

/* A joint set on the interface: exactly its joints (one per interface
 * edge, 3D face) take the set's parameters; the others keep the
 * material's. */
static void joint_set_on_group(void)
{
    for (int dim = 2; dim <= 3; dim++)
        for (int v = 0; v < 2; v++) {
            const char *file = dim == 3 ? cube_files[v] : bar_files[v];
            json_t *doc = bar_case(file, dim);
            edit(doc, "/parts/0/fracture", json_true());
            edit(doc, "/parts/0/discontinuities",
                 load("{'interface': {'tensile_strength': 1e5, 'cohesion': 2e5}}"));
            fdem_model *m = expect_built(doc, NULL);
            if (!m) continue;
            gmsh_groups g = {0};
            fdem_mesh mesh = {0};
            fdem_tet_mesh tets = {0};
            read_groups(file, dim, &mesh, &tets, &g);
            const gmsh_group *interface = named(&g, "interface", dim - 1);
            int on_set = 0, weak_off_plane = 0;
            for (int j = 0; j < m->joint_count; j++) {
                const joint_strength *s = &m->joint_strengths[m->joint_strength_of[j]];
                if (s->tensile_strength != 1e5) {
                    CHECK(s->tensile_strength == 1e8 && s->cohesion == 1e8, "material strength");
                    continue;
                }
                on_set++;
                CHECK(s->cohesion == 2e5 && s->energy_I == 1e4, "the set's own and inherited");
                for (int i = 0; i < dim; i++)
                    weak_off_plane += fabs(m->pos0[dim * m->joint_node[2 * dim * j + i]] - 1) > 1e-9;
            }
            CHECK(interface && on_set == interface->face_count && weak_off_plane == 0,
                  "%dD %s: %d joints on the set, %d interface faces, %d off the plane", dim,
                  file, on_set, interface ? interface->face_count : -1, weak_off_plane);
            gmsh_groups_free(&g);
            fdem_mesh_free(&mesh);
            fdem_tet_mesh_free(&tets);
            fdem_model_destroy(m);
        }
}

/* ---------------------------------------------------------- Weibull */

static const char *const weibull_plate =
    "{'materials': {'rock': {'density': 2600, 'young': 2e10, 'poisson': 0.2,"
    "  'fracture': {'tensile_strength': 5e6, 'cohesion': 1.5e7, 'friction_angle': 30,"
    "   'energy_I': 20, 'energy_II': 100,"
    "   'variation': {'distribution': 'weibull', 'modulus': 5, 'seed': 7}}}},"
    " 'parts': [{'name': 'plate', 'material': 'rock', 'fracture': true,"
    "            'rectangle': {'origin': [0, 0], 'size': [0.1, 0.1], 'divisions': [20, 20]}}],"
    " 'constraints': [{'box': [-1, -1, 1, 0.0001], 'velocity': [0, -1]},"
    "                 {'box': [-1, 0.0999, 1, 1], 'velocity': [0, 1]}],"
    " 'time': {'end': 1e-4}}";

/* The drawn strengths of a big plate's joints: their mean is the
 * requested mean, their Weibull modulus the requested modulus, and each
 * joint's cohesion scales with its tensile strength. The modulus is read
 * from the spread of ln(f): a Weibull variate's logarithm is a Gumbel with
 * standard deviation pi / (m sqrt 6). With N joints the mean has a
 * relative standard error of CV/sqrt(N) (CV 0.229 at m = 5) and the
 * modulus about 1.05/sqrt(N): tolerances of five of them. */
static void weibull_statistics(void)
{
    json_t *doc = load(weibull_plate);
    edit(doc, "/parts/0/rectangle/divisions", load("[100, 100]"));
    fdem_model *m = expect_built(doc, NULL);
    if (!m) return;
    int N = m->joint_count;
    double sum = 0, sum_log = 0, sum_log2 = 0;
    int same_ratio = 1;
    for (int j = 0; j < N; j++) {
        const joint_strength *s = &m->joint_strengths[m->joint_strength_of[j]];
        double f = s->tensile_strength / 5e6;
        sum += f;
        sum_log += log(f);
        sum_log2 += log(f) * log(f);
        same_ratio &= fabs(s->cohesion / s->tensile_strength - 3) < 1e-12;
    }
    double mean = sum / N, var_log = sum_log2 / N - (sum_log / N) * (sum_log / N);
    double modulus = M_PI / (sqrt(6 * var_log));
    printf("  %d joints: mean strength %.4f of the requested, modulus %.3f (requested 5)\n", N,
           mean, modulus);
    CHECK(N > 25000, "only %d joints", N);
    CHECK_NEAR(mean, 1.0, 5 * 0.229 / sqrt(N));
    CHECK_NEAR(modulus, 5.0, 5 * 5.0 * 1.05 / sqrt(N));
    CHECK(same_ratio, "cohesion / tensile strength stays 3 joint by joint");
    fdem_model_destroy(m);
}

/* Steps a plate pulled apart until it has cracked; returns the model. */
static fdem_model *pulled_plate(int seed, int threads)
{
    json_t *doc = load(weibull_plate);
    edit(doc, "/materials/rock/fracture/variation/seed", json_integer(seed));
    fdem_model *m = expect_built(doc, NULL);
    if (!m) return NULL;
    fdem_set_threads(m, threads);
    while (fdem_get_time(m) < 4e-5)
        if (fdem_step(m, NULL)) break;
    return m;
}

/* The same seed gives the same bits (also on two threads); another seed
 * another crack pattern. */
static void weibull_reproducible(void)
{
    fdem_model *a = pulled_plate(7, 1), *b = pulled_plate(7, 2), *c = pulled_plate(8, 1);
    if (a && b && c) {
        fdem_counts ca = fdem_get_counts(a);
        size_t J = (size_t)ca.joints, N = (size_t)ca.nodes * 2;
        CHECK(ca.broken_joints > 0, "the plate did not crack");
        CHECK(memcmp(fdem_positions(a), fdem_positions(b), N * sizeof(double)) == 0 &&
                  memcmp(fdem_joint_damage(a), fdem_joint_damage(b), J * sizeof(double)) == 0,
              "seed 7 on one and two threads differ");
        int differ = 0;
        const double *da = fdem_joint_damage(a), *dc = fdem_joint_damage(c);
        for (size_t j = 0; j < J; j++) differ += (da[j] >= 1) != (dc[j] >= 1);
        printf("  seed 7: %d broken joints, seed 8: %d, %d joints broken in one and not the "
               "other\n", ca.broken_joints, fdem_get_counts(c).broken_joints, differ);
        CHECK(differ > 0, "seeds 7 and 8 broke the same joints");
    }
    fdem_model_destroy(a);
    fdem_model_destroy(b);
    fdem_model_destroy(c);
}

/* A joint's face and drawn tensile strength, for comparing two models
 * whose joints are numbered differently. */
typedef struct face_strength {
    int32_t vertex[3]; /* the part's mesh vertices of side A, sorted (2D: third -1) */
    double strength;
} face_strength;

static int face_strength_compare(const void *pa, const void *pb)
{
    const face_strength *a = pa, *b = pb;
    for (int i = 0; i < 3; i++)
        if (a->vertex[i] != b->vertex[i]) return a->vertex[i] < b->vertex[i] ? -1 : 1;
    return 0;
}

/* Every joint of a one-part model as (face, strength), sorted by face. */
static face_strength *faces_and_strengths(const fdem_model *m)
{
    face_strength *out = calloc((size_t)m->joint_count, sizeof *out);
    int D = m->dim;
    for (int j = 0; out && j < m->joint_count; j++) {
        int32_t *v = out[j].vertex;
        v[2] = -1;
        for (int i = 0; i < D; i++) v[i] = m->node_origin[m->joint_node[2 * D * j + i]];
        for (int i = 1; i < D; i++)
            for (int k = i; k > 0 && v[k - 1] > v[k]; k--) {
                int32_t t = v[k];
                v[k] = v[k - 1];
                v[k - 1] = t;
            }
        out[j].strength = m->joint_strengths[m->joint_strength_of[j]].tensile_strength;
    }
    if (out) qsort(out, (size_t)m->joint_count, sizeof *out, face_strength_compare);
    return out;
}

/* Lists `count` elements of `per` nodes in reverse order, each with its
 * first three nodes rotated (an even permutation: a tetrahedron keeps the
 * sign of its volume). */
static void reverse_elements(int32_t *nodes, int count, int per)
{
    for (int t = 0; t < count / 2; t++) {
        int32_t *a = nodes + per * t, *b = nodes + per * (count - 1 - t);
        for (int i = 0; i < per; i++) {
            int32_t x = a[i];
            a[i] = b[i];
            b[i] = x;
        }
    }
    for (int t = 0; t < count; t++) {
        int32_t *n = nodes + per * t, first = n[0];
        n[0] = n[1], n[1] = n[2], n[2] = first;
    }
}

/* One fracturing part of Weibull-varied rock (modulus 5, seed 7) on a mesh
 * whose elements are listed in reverse order when `reversed`, each with its
 * nodes rotated, in 2D (a rectangle) or 3D (a box). */
static fdem_model *varied_part(int dim, int reversed)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    fdem_material_def d = {.density = 2700, .young = 3e10, .poisson = 0.25, .has_fracture = 1,
                           .fracture = {1e6, 3e6, 30, 10, 50}, .variation = {5, 7}};
    int ok = fdem_set_dimension(m, dim, &err) == 0;
    int mat = ok ? fdem_add_material(m, &d, &err) : -1;
    ok = mat >= 0;
    if (ok && dim == 2) {
        fdem_mesh mesh;
        ok = fdem_mesh_rectangle(0, 0, 1, 1, 6, 6, &mesh, &err) == 0;
        if (ok && reversed) reverse_elements(mesh.tri, mesh.triangle_count, 3);
        ok = ok && fdem_add_part(m, &mesh, mat, 1, &err) >= 0;
        if (ok) fdem_mesh_free(&mesh);
    } else if (ok) {
        fdem_tet_mesh mesh;
        const double origin[3] = {0, 0, 0}, size[3] = {1, 1, 1};
        const int div[3] = {3, 3, 3};
        ok = fdem_tet_mesh_box(origin, size, div, &mesh, &err) == 0;
        if (ok && reversed) reverse_elements(mesh.tet, mesh.tet_count, 4);
        ok = ok && fdem_add_part_3d(m, &mesh, mat, 1, &err) >= 0;
        if (ok) fdem_tet_mesh_free(&mesh);
    }
    if (!ok || fdem_model_finalize(m, &err)) {
        CHECK(0, "varied part (%dD): %s", dim, err.message);
        fdem_model_destroy(m);
        return NULL;
    }
    return m;
}

/* A face keeps its strength whatever order the mesh lists its elements in
 * (and so whatever order the engine numbers its joints in): the draws are
 * keyed by the face, not by the joint's index. Keyed by the index, 268 of
 * the 270 faces of the reversed 3D mesh drew another strength (3D joints
 * are numbered by their tetrahedra); the 2D joints, numbered by their
 * edges' vertices, kept theirs either way. */
static void weibull_follows_faces(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *a = varied_part(dim, 0), *b = varied_part(dim, 1);
        if (!a || !b) {
            fdem_model_destroy(a);
            fdem_model_destroy(b);
            return;
        }
        int J = a->joint_count, moved = 0, varied = 0;
        face_strength *fa = faces_and_strengths(a), *fb = faces_and_strengths(b);
        CHECK(J == b->joint_count && J > 50, "%d and %d joints", J, b->joint_count);
        for (int j = 0; fa && fb && j < J && J == b->joint_count; j++) {
            CHECK(face_strength_compare(&fa[j], &fb[j]) == 0, "%dD: the two meshes' faces differ",
                  dim);
            moved += fa[j].strength != fb[j].strength;
            varied += fa[j].strength != 1e6;
        }
        printf("  %dD: %d joints, %d varied, %d with another strength after the elements were "
               "reversed\n", dim, J, varied, moved);
        CHECK(varied == J, "%d of %d joints drew no factor", J - varied, J);
        CHECK(moved == 0, "%d of %d faces changed strength", moved, J);
        free(fa);
        free(fb);
        fdem_model_destroy(a);
        fdem_model_destroy(b);
    }
}

/* examples/jointed-block.json to just past its peak: pulled across a set
 * of joints at beta = 30 degrees, the block fails along the set when the
 * normal stress on it, sigma cos^2(beta), reaches the set's tensile
 * strength, 1 MPa (the shear on it, sigma sin cos, stays under the
 * cohesion): peak sigma = 1.333 MPa to 3 %, far below the rock's 5 MPa, and
 * every joint that broke is on the set. */
static void jointed_block_example(void)
{
    size_t length = 0;
    char *text = read_file("examples/jointed-block.json", &length);
    if (!text) return;
    json_error_t error;
    json_t *doc = json_loadb(text, length, 0, &error);
    free(text);
    edit(doc, "/time/end", json_real(1.6e-3));
    fdem_model *m = expect_built(doc, NULL);
    if (!m) return;
    double peak = 0, width = 0.05, beta = M_PI / 6;
    while (fdem_get_time(m) < 1.6e-3 && fdem_step(m, NULL) == 0)
        peak = fmax(peak, fdem_constraint_forces(m)[2 * 2 + 1] / width);
    int broken = 0, on_set = 0;
    for (int j = 0; j < m->joint_count; j++) {
        if (m->joint_damage[j] < 1) continue;
        broken++;
        on_set += m->joint_strengths[m->joint_strength_of[j]].tensile_strength == 1e6;
    }
    printf("  jointed block: peak %.4g MPa (f_t / cos^2 30 = %.4g MPa), %d broken joints, %d on "
           "the set\n", peak / 1e6, 1e6 / (cos(beta) * cos(beta)) / 1e6, broken, on_set);
    CHECK_REL(peak, 1e6 / (cos(beta) * cos(beta)), 0.03);
    CHECK(broken > 0 && on_set == broken, "%d broken, %d on the set", broken, on_set);
    fdem_model_destroy(m);
}

CHECK_MAIN(T(groups_2d), T(groups_3d), T(group_selector), T(empty_group_is_refused),
           T(two_materials_bonded),
           T(joint_set_on_group), T(weibull_statistics), T(weibull_reproducible),
           T(weibull_follows_faces), T(jointed_block_example))
