/*
 * mesh_3d.c - tetrahedral meshes: the box, sphere and cylinder generators,
 * validation and quality measures (declared in mesh_3d.h).
 *
 * All three shapes are one structured lattice of hexahedral cells, each cut
 * into the six Kuhn tetrahedra around a main diagonal, mapped onto the
 * shape:
 *  - Each cell is the mirror image of its neighbours (the split of an odd
 *    cell is reflected on that axis), so the face diagonals of two cells
 *    sharing a face coincide (conforming) and the diagonals alternate
 *    through the mesh (no preferred direction). Every cell's main diagonal
 *    then runs through its corner whose lattice indices are all even.
 *  - Sphere: the cube [-1, 1]^3 with an even number of cells per side, each
 *    point pushed radially by |p|_inf / |p|_2, so each cube shell becomes a
 *    sphere. With the diagonals through the cube's corners (all even), the
 *    cells at the corners, where the map flattens most, are split along
 *    the direction it flattens, and no tetrahedron becomes a sliver.
 *  - Cylinder: the same map of a square onto a disc in the cross-section,
 *    extruded along the axis.
 * Tetrahedra are oriented by the validation that every generated mesh goes
 * through, as input meshes do.
 */
#include "mesh_3d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kernel/element_tet.h"
#include "model/model.h"
#include "math/vec3.h"
#include "mesh.h"

void fdem_tet_mesh_free(fdem_tet_mesh *mesh)
{
    if (!mesh) return;
    free(mesh->xyz);
    free(mesh->tet);
    memset(mesh, 0, sizeof *mesh);
}

/* ------------------------------------------------------ the Kuhn lattice */

/* Maps lattice indices (0 .. n[a]) to a point of the shape. */
typedef void (*lattice_map)(const void *shape, const int n[3], const int idx[3], double out[3]);

/* The six paths from corner 000 to 111 of a cell, one axis at a time. */
static const int kuhn_paths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                     {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

static int32_t lattice_node(const int n[3], int i, int j, int k)
{
    return (int32_t)(((long)k * (n[1] + 1) + j) * (n[0] + 1) + i);
}

static int lattice_mesh(const int n[3], lattice_map map, const void *shape, fdem_tet_mesh *out,
                        fdem_error *err)
{
    memset(out, 0, sizeof *out);
    long nodes = (long)(n[0] + 1) * (n[1] + 1) * (n[2] + 1);
    long tets = 6L * n[0] * n[1] * n[2];
    if (n[0] < 1 || n[1] < 1 || n[2] < 1 || nodes > INT32_MAX / 3 || tets > INT32_MAX / 4) {
        model_error(err, FDEM_ITEM_NONE, -1, "a lattice of %d x %d x %d cells is out of range",
                    n[0], n[1], n[2]);
        return -1;
    }
    out->xyz = malloc(sizeof(double) * 3 * (size_t)nodes);
    out->tet = malloc(sizeof(int32_t) * 4 * (size_t)tets);
    if (!out->xyz || !out->tet) {
        fdem_tet_mesh_free(out);
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for a mesh of %ld tetrahedra", tets);
        return -1;
    }
    out->node_count = (int)nodes;
    out->tet_count = (int)tets;
    for (int k = 0; k <= n[2]; k++)
        for (int j = 0; j <= n[1]; j++)
            for (int i = 0; i <= n[0]; i++) {
                int idx[3] = {i, j, k};
                map(shape, n, idx, out->xyz + 3 * (size_t)lattice_node(n, i, j, k));
            }
    int32_t *t = out->tet;
    for (int k = 0; k < n[2]; k++)
        for (int j = 0; j < n[1]; j++)
            for (int i = 0; i < n[0]; i++) {
                int cell[3] = {i, j, k};
                for (int p = 0; p < 6; p++) {
                    int bits[3] = {0, 0, 0};
                    for (int v = 0; v < 4; v++) {
                        if (v > 0) bits[kuhn_paths[p][v - 1]] = 1;
                        int at[3];
                        for (int a = 0; a < 3; a++) /* odd cells mirrored */
                            at[a] = cell[a] + (cell[a] % 2 ? 1 - bits[a] : bits[a]);
                        *t++ = lattice_node(n, at[0], at[1], at[2]);
                    }
                }
            }
    if (fdem_tet_mesh_validate(out, NULL, err) != 0) {
        fdem_tet_mesh_free(out);
        return -1;
    }
    return 0;
}

/* --------------------------------------------------------------- shapes */

typedef struct box_shape {
    double origin[3], size[3];
} box_shape;

static void box_map(const void *shape, const int n[3], const int idx[3], double out[3])
{
    const box_shape *b = shape;
    for (int a = 0; a < 3; a++) out[a] = b->origin[a] + b->size[a] * idx[a] / n[a];
}

/* p scaled by |p|_inf / |p|_2 over its first `dims` components: squares
 * and cubes onto discs and balls, shell by shell. */
static void square_to_round(double *p, int dims)
{
    double inf = 0, two = 0;
    for (int a = 0; a < dims; a++) inf = fmax(inf, fabs(p[a])), two += p[a] * p[a];
    if (two <= 0) return;
    double scale = inf / sqrt(two);
    for (int a = 0; a < dims; a++) p[a] *= scale;
}

typedef struct round_shape {
    double center[3], radius, length;
    int axis; /* cylinder: 0, 1, 2; the sphere ignores it */
} round_shape;

static void sphere_map(const void *shape, const int n[3], const int idx[3], double out[3])
{
    const round_shape *s = shape;
    double p[3];
    for (int a = 0; a < 3; a++) p[a] = 2.0 * idx[a] / n[a] - 1.0;
    square_to_round(p, 3);
    for (int a = 0; a < 3; a++) out[a] = s->center[a] + s->radius * p[a];
}

/* Lattice axes 0, 1 span the cross-section, 2 runs along the cylinder. */
static void cylinder_map(const void *shape, const int n[3], const int idx[3], double out[3])
{
    const round_shape *s = shape;
    double p[3] = {2.0 * idx[0] / n[0] - 1.0, 2.0 * idx[1] / n[1] - 1.0, 0};
    square_to_round(p, 2);
    int along = s->axis, u = (along + 1) % 3, v = (along + 2) % 3;
    out[along] = s->center[along] + s->length * idx[2] / n[2];
    out[u] = s->center[u] + s->radius * p[0];
    out[v] = s->center[v] + s->radius * p[1];
}

static int finite3(const double v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

int fdem_tet_mesh_box(const double origin[3], const double size[3], const int div[3],
                      fdem_tet_mesh *out, fdem_error *err)
{
    memset(out, 0, sizeof *out);
    if (!finite3(origin) || !finite3(size) || !(size[0] > 0 && size[1] > 0 && size[2] > 0)) {
        model_error(err, FDEM_ITEM_NONE, -1, "box size must be positive and finite");
        return -1;
    }
    if (div[0] < 1 || div[1] < 1 || div[2] < 1) {
        model_error(err, FDEM_ITEM_NONE, -1, "box divisions must be at least 1");
        return -1;
    }
    box_shape b;
    memcpy(b.origin, origin, sizeof b.origin);
    memcpy(b.size, size, sizeof b.size);
    return lattice_mesh(div, box_map, &b, out, err);
}

/* Cells per side of the square (cube) whose boundary of 4 sides carries
 * `around` edges: even, so the corners are lattice points of even index. */
static int cells_for_circle(int around)
{
    int n = (around + 3) / 4;
    return n + (n % 2);
}

int fdem_tet_mesh_sphere(const double center[3], double radius, int divisions,
                         fdem_tet_mesh *out, fdem_error *err)
{
    memset(out, 0, sizeof *out);
    if (!finite3(center) || !(radius > 0) || !isfinite(radius)) {
        model_error(err, FDEM_ITEM_NONE, -1, "sphere radius must be positive and finite");
        return -1;
    }
    if (divisions < 8) {
        model_error(err, FDEM_ITEM_NONE, -1, "sphere divisions must be at least 8");
        return -1;
    }
    round_shape s = {.radius = radius};
    memcpy(s.center, center, sizeof s.center);
    int n = cells_for_circle(divisions);
    int cells[3] = {n, n, n};
    return lattice_mesh(cells, sphere_map, &s, out, err);
}

int fdem_tet_mesh_cylinder(const double center[3], int axis, double radius, double length,
                           const int divisions[2], fdem_tet_mesh *out, fdem_error *err)
{
    memset(out, 0, sizeof *out);
    if (!finite3(center) || !(radius > 0) || !isfinite(radius) || !(length > 0) ||
        !isfinite(length)) {
        model_error(err, FDEM_ITEM_NONE, -1, "cylinder radius and length must be positive and finite");
        return -1;
    }
    if (axis < 0 || axis > 2) {
        model_error(err, FDEM_ITEM_NONE, -1, "cylinder axis must be x, y or z");
        return -1;
    }
    if (divisions[0] < 8 || divisions[1] < 1) {
        model_error(err, FDEM_ITEM_NONE, -1,
                    "cylinder divisions must be at least 8 around the rim and 1 along the axis");
        return -1;
    }
    round_shape s = {.radius = radius, .length = length, .axis = axis};
    memcpy(s.center, center, sizeof s.center);
    int n = cells_for_circle(divisions[0]);
    int cells[3] = {n, n, divisions[1]};
    return lattice_mesh(cells, cylinder_map, &s, out, err);
}

/* ------------------------------------------------------------ validation */

static const double *node_xyz(const fdem_tet_mesh *m, int32_t n) { return m->xyz + 3 * (size_t)n; }

static double tet_volume_of(const fdem_tet_mesh *m, const int32_t *t)
{
    return tet_volume(node_xyz(m, t[0]), node_xyz(m, t[1]), node_xyz(m, t[2]), node_xyz(m, t[3]));
}

/* Largest edge from node 0: cubed, the scale a zero volume is judged at. */
static double tet_size(const fdem_tet_mesh *m, const int32_t *t)
{
    double l = 0;
    for (int a = 1; a < 4; a++) {
        const double *p = node_xyz(m, t[a]), *o = node_xyz(m, t[0]);
        /* hypot: the squares of edges beyond 1e154 m or below 1e-154 m
         * would overflow or underflow */
        l = fmax(l, hypot(hypot(p[0] - o[0], p[1] - o[1]), p[2] - o[2]));
    }
    return l;
}

static int tet_check_nodes(const fdem_tet_mesh *m, int k, fdem_error *err)
{
    const int32_t *t = m->tet + 4 * (size_t)k;
    for (int c = 0; c < 4; c++)
        if (t[c] < 0 || t[c] >= m->node_count) {
            model_error(err, FDEM_ITEM_TETRAHEDRON, k,
                        "tetrahedron %d refers to node %d, but nodes are numbered 0 to %d", k,
                        (int)t[c], m->node_count - 1);
            return -1;
        }
    for (int a = 0; a < 4; a++)
        for (int b = a + 1; b < 4; b++)
            if (t[a] == t[b]) {
                model_error(err, FDEM_ITEM_TETRAHEDRON, k, "tetrahedron %d uses node %d twice",
                            k, (int)t[a]);
                return -1;
            }
    return 0;
}

static int tet_first_unused_node(const fdem_tet_mesh *m, fdem_error *err)
{
    unsigned char *used = calloc((size_t)m->node_count, 1);
    if (!used) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory validating a mesh");
        return -2;
    }
    for (size_t k = 0; k < 4 * (size_t)m->tet_count; k++) used[m->tet[k]] = 1;
    int unused = -1;
    for (int i = 0; i < m->node_count && unused < 0; i++)
        if (!used[i]) unused = i;
    free(used);
    return unused;
}

int fdem_tet_mesh_validate(fdem_tet_mesh *mesh, int *reoriented, fdem_error *err)
{
    if (reoriented) *reoriented = 0;
    if (mesh->node_count < 4 || mesh->tet_count < 1) {
        model_error(err, FDEM_ITEM_NONE, -1, "a mesh needs at least 4 nodes and 1 tetrahedron");
        return -1;
    }
    for (size_t i = 0; i < 3 * (size_t)mesh->node_count; i++)
        if (!isfinite(mesh->xyz[i])) {
            model_error(err, FDEM_ITEM_NODE, (int)(i / 3), "node %d has a non-finite coordinate",
                        (int)(i / 3));
            return -1;
        }
    for (int k = 0; k < mesh->tet_count; k++) {
        if (tet_check_nodes(mesh, k, err) != 0) return -1;
        int32_t *t = mesh->tet + 4 * (size_t)k;
        double v = tet_volume_of(mesh, t), size = tet_size(mesh, t), size3 = size * size * size;
        if (size > 0 && !(isfinite(size3) && size3 > MESH_SMALLEST_CUBE)) {
            model_error(err, FDEM_ITEM_TETRAHEDRON, k,
                        "tetrahedron %d is %.3g m across: a volume of that scale cannot be "
                        "computed in double precision; give the coordinates in metres", k, size);
            return -1;
        }
        if (!(fabs(v) > 1e-12 * size3)) {
            model_error(err, FDEM_ITEM_TETRAHEDRON, k,
                        "tetrahedron %d has zero volume (nodes %d, %d, %d, %d are coplanar or coincide)",
                        k, (int)t[0], (int)t[1], (int)t[2], (int)t[3]);
            return -1;
        }
        if (v < 0) {
            int32_t s = t[1];
            t[1] = t[2];
            t[2] = s;
            if (reoriented) (*reoriented)++;
        }
    }
    /* a node no tetrahedron uses would have no mass and could never move */
    int unused = tet_first_unused_node(mesh, err);
    if (unused == -2) return -1;
    if (unused >= 0) {
        model_error(err, FDEM_ITEM_NODE, unused, "node %d is not used by any tetrahedron", unused);
        return -1;
    }
    return 0;
}

/* --------------------------------------------------------------- quality */

/* The dihedral angle at edge (a, b) between faces (a, b, c) and (a, b, d):
 * the angle between e x (c - a) and e x (d - a), e = b - a. */
static double dihedral(const double *pa, const double *pb, const double *pc, const double *pd)
{
    double e[3], u[3], w[3], nu[3], nw[3];
    vec3_sub(pb, pa, e);
    vec3_sub(pc, pa, u);
    vec3_sub(pd, pa, w);
    vec3_cross(e, u, nu);
    vec3_cross(e, w, nw);
    double c = vec3_dot(nu, nw) / sqrt(vec3_dot(nu, nu) * vec3_dot(nw, nw));
    return acos(fmax(-1.0, fmin(1.0, c)));
}

/* 3 r_in / r_circ: r_in = 3V / area, r_circ = |a^2 (b x c) + b^2 (c x a) +
 * c^2 (a x b)| / (12 V) with a, b, c the edges from node 0. */
static double radius_ratio(const double *p[4])
{
    double e[3][3], c[3][3], area = 0;
    for (int k = 0; k < 3; k++) vec3_sub(p[k + 1], p[0], e[k]);
    vec3_cross(e[1], e[2], c[0]);
    vec3_cross(e[2], e[0], c[1]);
    vec3_cross(e[0], e[1], c[2]);
    double six_v = vec3_dot(e[0], c[0]);
    double opposite[3], u[3], w[3];
    vec3_sub(p[2], p[1], u);
    vec3_sub(p[3], p[1], w);
    vec3_cross(u, w, opposite);
    area = 0.5 * (sqrt(vec3_dot(c[0], c[0])) + sqrt(vec3_dot(c[1], c[1])) + sqrt(vec3_dot(c[2], c[2])) +
                  sqrt(vec3_dot(opposite, opposite)));
    double s[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) s[i] += vec3_dot(e[k], e[k]) * c[k][i];
    double r_in = 0.5 * fabs(six_v) / area, r_circ = sqrt(vec3_dot(s, s)) / (2 * fabs(six_v));
    return 3 * r_in / r_circ;
}

void fdem_tet_mesh_quality(const fdem_tet_mesh *mesh, double *min_dihedral_deg,
                           double *min_radius_ratio)
{
    static const int edges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2},
                                    {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
    double worst_angle = M_PI, worst_ratio = 1.0;
    for (int k = 0; k < mesh->tet_count; k++) {
        const int32_t *t = mesh->tet + 4 * (size_t)k;
        const double *p[4];
        for (int a = 0; a < 4; a++) p[a] = node_xyz(mesh, t[a]);
        for (int e = 0; e < 6; e++) {
            const int *q = edges[e];
            worst_angle = fmin(worst_angle, dihedral(p[q[0]], p[q[1]], p[q[2]], p[q[3]]));
        }
        worst_ratio = fmin(worst_ratio, radius_ratio(p));
    }
    if (min_dihedral_deg) *min_dihedral_deg = worst_angle * 180.0 / M_PI;
    if (min_radius_ratio) *min_radius_ratio = worst_ratio;
}

double fdem_tet_mesh_volume(const fdem_tet_mesh *mesh)
{
    double v = 0;
    for (int k = 0; k < mesh->tet_count; k++) v += tet_volume_of(mesh, mesh->tet + 4 * (size_t)k);
    return v;
}
