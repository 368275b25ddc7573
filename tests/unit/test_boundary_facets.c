/*
 * test_boundary_facets.c - the facets the web page's surface frame draws
 * (core/analysis/boundary_facets.h), against what a mesh must give by
 * counting: a 3x3x3 box of 162 tetrahedra shows its 6 x 9 x 2 = 108 outer
 * faces, each pointing out, whether its nodes are shared or each element
 * has its own held by intact joints; a broken joint adds its two faces
 * (marked with the joint), an excavated element opens its neighbours'
 * faces; and the same in 2D on a square of two triangles.
 */
#include "check.h"
#include "analysis/boundary_facets.h"
#include "mesh/mesh_3d.h"

#include <stdlib.h>

#include "math/node_ids.h"

/* ------------------------------------------------------------------ 2D */

static void square_2d(void)
{
    /* a unit square, triangles (0,1,2) and (0,2,3) sharing nodes 0 and 2 */
    const int32_t shared[] = {0, 1, 2, 0, 2, 3};
    facet_map m;
    int32_t out[6];
    CHECK(facet_map_build(&m, 2, 2, shared, 0, NULL) == 0, "build");
    int n = facet_map_boundary(&m, NULL, NULL, out);
    CHECK(n == 4, "%d edges of a square", n);
    for (int i = 0; i < n; i++) CHECK(out[i] != 2 && out[i] != 3, "the diagonal %d shows", out[i]);
    facet_map_free(&m);

    /* own nodes: (0,1,2) and (3,4,5) with 3 at 0 and 4 at 2; the joint
     * lies on edge (2,0) of the first and (3,4) of the second */
    const int32_t own[] = {0, 1, 2, 3, 4, 5}, joint[] = {0, 2, 3, 4};
    const unsigned char broken[] = {1}, holding[] = {0}, second_gone[] = {1, 0};
    CHECK(facet_map_build(&m, 2, 2, own, 1, joint) == 0, "build");
    CHECK(m.joint_facet[0] == 2 && m.joint_facet[1] == 3, "joint sides on %d, %d",
          m.joint_facet[0], m.joint_facet[1]);
    CHECK(facet_map_boundary(&m, holding, NULL, out) == 4, "an intact joint hides the diagonal");
    CHECK(facet_map_boundary(&m, NULL, NULL, out) == 4, "no damage field: intact");
    n = facet_map_boundary(&m, broken, NULL, out);
    CHECK(n == 6, "a broken joint shows both its edges: %d", n);
    n = facet_map_boundary(&m, holding, second_gone, out);
    CHECK(n == 3 && out[0] == 0 && out[1] == 1 && out[2] == 2,
          "the second excavated: the first's 3 edges, got %d", n);
    facet_map_free(&m);
}

/* ------------------------------------------------------------------ 3D */

typedef struct box_mesh {
    fdem_tet_mesh mesh;
    int32_t *own;    /* 4E: element e's own nodes 4e .. 4e+3 */
    int32_t *joints; /* J rows of 6 over own nodes */
    int joint_count;
} box_mesh;

/* Every interior face of the box becomes a joint between the two
 * elements' own nodes (a fracturing part). Brute force: a test mesh. */
static void box_joints(box_mesh *b)
{
    int E = b->mesh.tet_count, F = 4 * E;
    b->own = malloc(sizeof(int32_t) * 4 * (size_t)E);
    b->joints = malloc(sizeof(int32_t) * 6 * (size_t)F);
    b->joint_count = 0;
    for (int i = 0; i < 4 * E; i++) b->own[i] = i;
    for (int f = 0; f < F; f++)
        for (int g = f + 1; g < F; g++) {
            int32_t a[3], c[3];
            facet_nodes(3, b->mesh.tet, f, a);
            facet_nodes(3, b->mesh.tet, g, c);
            node_ids_sort(a, 3);
            node_ids_sort(c, 3);
            if (node_ids_compare(a, c, 3) != 0) continue;
            int32_t *row = b->joints + 6 * b->joint_count++;
            facet_nodes(3, b->own, f, row);
            facet_nodes(3, b->own, g, row + 3);
        }
}

/* Each facet shown lies on the box's surface (x, y or z at 0 or 1) and its
 * normal points out of its element, unless it is on a joint. */
static void check_outward(const box_mesh *b, const int32_t *facet, int n, const char *what)
{
    const double *x = b->mesh.xyz;
    for (int i = 0; i < n; i++) {
        int32_t v[3];
        facet_nodes(3, b->mesh.tet, facet[i], v);
        const int32_t *t = b->mesh.tet + 4 * (facet[i] / 4);
        double u[3], w[3], c[3] = {0, 0, 0}, normal[3], dot = 0;
        for (int k = 0; k < 3; k++) {
            u[k] = x[3 * v[1] + k] - x[3 * v[0] + k];
            w[k] = x[3 * v[2] + k] - x[3 * v[0] + k];
            for (int q = 0; q < 4; q++) c[k] += x[3 * t[q] + k] / 4;
        }
        normal[0] = u[1] * w[2] - u[2] * w[1];
        normal[1] = u[2] * w[0] - u[0] * w[2];
        normal[2] = u[0] * w[1] - u[1] * w[0];
        for (int k = 0; k < 3; k++) dot += normal[k] * (x[3 * v[0] + k] - c[k]);
        CHECK(dot > 0, "%s: facet %d points into its element", what, facet[i]);
    }
}

static int on_box_surface(const box_mesh *b, int32_t f)
{
    int32_t v[3];
    facet_nodes(3, b->mesh.tet, f, v);
    for (int k = 0; k < 3; k++) {
        int low = 1, high = 1;
        for (int q = 0; q < 3; q++) {
            double x = b->mesh.xyz[3 * v[q] + k];
            low &= fabs(x) < 1e-12;
            high &= fabs(x - 1) < 1e-12;
        }
        if (low || high) return 1;
    }
    return 0;
}

static void box_3d(void)
{
    box_mesh b;
    fdem_error err;
    const double origin[3] = {0, 0, 0}, size[3] = {1, 1, 1};
    const int div[3] = {3, 3, 3};
    CHECK(fdem_tet_mesh_box(origin, size, div, &b.mesh, &err) == 0, "box: %s", err.message);
    int E = b.mesh.tet_count;
    int32_t *out = malloc(sizeof(int32_t) * 4 * (size_t)E);
    facet_map m;

    CHECK(facet_map_build(&m, 3, E, b.mesh.tet, 0, NULL) == 0, "build shared");
    int n = facet_map_boundary(&m, NULL, NULL, out);
    CHECK(n == 108, "shared nodes: %d faces, want 108", n);
    check_outward(&b, out, n, "shared");
    for (int i = 0; i < n; i++) CHECK(on_box_surface(&b, out[i]), "facet %d is inside", out[i]);
    facet_map_free(&m);

    box_joints(&b);
    int J = b.joint_count;
    CHECK(J == (4 * E - 108) / 2, "%d joints, want %d", J, (4 * E - 108) / 2);
    unsigned char *broken = calloc((size_t)J, 1), *active = malloc((size_t)E);
    CHECK(facet_map_build(&m, 3, E, b.own, J, b.joints) == 0, "build own");
    n = facet_map_boundary(&m, broken, NULL, out);
    CHECK(n == 108, "intact joints: %d faces, want 108", n);
    for (int i = 0; i < n; i++)
        CHECK(on_box_surface(&b, out[i]) && m.joint[out[i]] < 0, "facet %d", out[i]);

    broken[7] = 1; /* one crack: both its faces show, each on joint 7 */
    n = facet_map_boundary(&m, broken, NULL, out);
    CHECK(n == 110, "one broken joint: %d faces, want 110", n);
    int on_joint = 0;
    for (int i = 0; i < n; i++) on_joint += m.joint[out[i]] == 7;
    CHECK(on_joint == 2, "%d faces on the broken joint", on_joint);
    check_outward(&b, out, n, "cracked");
    broken[7] = 0;

    /* the element behind joint 7's side b goes: its inner faces, held by
     * joints to it, open on the neighbours, and its own faces go */
    for (int e = 0; e < E; e++) active[e] = 1;
    int gone = m.joint_facet[2 * 7 + 1] / 4, outer = 0, inner = 0;
    for (int k = 0; k < 4; k++) {
        int32_t f = 4 * gone + k;
        if (m.joint[f] >= 0) inner++; else outer++;
    }
    active[gone] = 0;
    n = facet_map_boundary(&m, broken, active, out);
    CHECK(n == 108 - outer + inner, "one element excavated: %d faces, want %d", n,
          108 - outer + inner);
    for (int i = 0; i < n; i++) CHECK(out[i] / 4 != gone, "a face of the excavated element");
    check_outward(&b, out, n, "excavated");
    facet_map_free(&m);

    CHECK(facet_map_build(&m, 3, E, b.own, J, b.joints) == 0 &&
              facet_map_bytes(3, E, J) >= sizeof(int32_t) * (8 * (size_t)E + 2 * (size_t)J),
          "the bytes priced cover the map");
    facet_map_free(&m);
    int32_t bad[4] = {0, 1, -2, 3};
    CHECK(facet_map_build(&m, 3, 1, bad, 0, NULL) == -1 && !m.twin, "a negative node id");
    free(out);
    free(broken);
    free(active);
    free(b.own);
    free(b.joints);
    fdem_tet_mesh_free(&b.mesh);
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        {"square_2d", square_2d},
        {"box_3d", box_3d},
    };
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
