/*
 * mesh.c - triangle meshes as plain arrays: the rectangle and disc
 * generators of the case format, and the validation every input mesh goes
 * through before it becomes part of a model.
 *
 * The disc is meshed in concentric rings whose spacing matches the rim
 * spacing, so its triangles are all close to equilateral; a fan from the
 * centre to the rim would produce slivers that force a tiny stable step.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "mesh.h"

void fdem_mesh_free(fdem_mesh *mesh)
{
    if (!mesh) return;
    free(mesh->xy);
    free(mesh->tri);
    mesh->xy = NULL;
    mesh->tri = NULL;
    mesh->node_count = mesh->triangle_count = 0;
}

static int mesh_alloc(fdem_mesh *out, long nodes, long triangles, fdem_error *err)
{
    memset(out, 0, sizeof *out);
    if (nodes <= 0 || triangles <= 0 || nodes > INT32_MAX / 2 || triangles > INT32_MAX / 3) {
        model_error(err, FDEM_ITEM_NONE, -1, "a mesh of %ld nodes and %ld triangles is out of range",
                   nodes, triangles);
        return -1;
    }
    out->xy = malloc(sizeof(double) * 2 * (size_t)nodes);
    out->tri = malloc(sizeof(int32_t) * 3 * (size_t)triangles);
    if (!out->xy || !out->tri) {
        fdem_mesh_free(out);
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for a mesh of %ld nodes", nodes);
        return -1;
    }
    out->node_count = (int)nodes;
    out->triangle_count = (int)triangles;
    return 0;
}

int fdem_mesh_rectangle(double ox, double oy, double width, double height, int nx, int ny,
                        fdem_mesh *out, fdem_error *err)
{
    if (!(width > 0) || !(height > 0) || !isfinite(width) || !isfinite(height) ||
        !isfinite(ox) || !isfinite(oy)) {
        model_error(err, FDEM_ITEM_NONE, -1, "rectangle size must be positive and finite");
        return -1;
    }
    if (nx < 1 || ny < 1) {
        model_error(err, FDEM_ITEM_NONE, -1, "rectangle divisions must be at least 1");
        return -1;
    }
    long nodes = (long)(nx + 1) * (ny + 1);
    if (mesh_alloc(out, nodes, 2L * nx * ny, err)) return -1;
    for (int j = 0; j <= ny; j++)
        for (int i = 0; i <= nx; i++) {
            long k = (long)j * (nx + 1) + i;
            out->xy[2 * k] = ox + width * i / nx;
            out->xy[2 * k + 1] = oy + height * j / ny;
        }
    int32_t *t = out->tri;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            int32_t a = j * (nx + 1) + i, b = a + 1, d = a + (nx + 1), c = d + 1;
            if ((i + j) % 2 == 0) { /* diagonal a-c */
                *t++ = a; *t++ = b; *t++ = c;
                *t++ = a; *t++ = c; *t++ = d;
            } else {                /* diagonal b-d */
                *t++ = a; *t++ = b; *t++ = d;
                *t++ = b; *t++ = c; *t++ = d;
            }
        }
    return 0;
}

/* Nodes on ring k of a disc with `rings` rings and `rim` nodes on the rim. */
static int disc_ring_nodes(int k, int rings, int rim)
{
    if (k == 0) return 1;
    int n = (int)lround((double)rim * k / rings);
    return n < 6 ? 6 : n;
}

/* Joins ring a (inner, na nodes from index ia) to ring b (outer): walk both
 * rings by angle and always close the triangle whose new node comes first,
 * which keeps every triangle spanning about one spacing of each ring. */
static int32_t *disc_join_rings(int32_t *t, int ia, int na, double phase_a, int ib, int nb,
                                double phase_b)
{
    int i = 0, j = 0;
    while (i < na || j < nb) {
        double next_a = phase_a + 2 * M_PI * (i + 1) / na;
        double next_b = phase_b + 2 * M_PI * (j + 1) / nb;
        int32_t a0 = ia + i % na, b0 = ib + j % nb;
        if (j < nb && (i >= na || next_b <= next_a)) {
            *t++ = a0; *t++ = b0; *t++ = ib + (j + 1) % nb;
            j++;
        } else {
            *t++ = a0; *t++ = b0; *t++ = ia + (i + 1) % na;
            i++;
        }
    }
    return t;
}

int fdem_mesh_disc(double cx, double cy, double radius, int divisions, fdem_mesh *out,
                   fdem_error *err)
{
    if (!(radius > 0) || !isfinite(radius) || !isfinite(cx) || !isfinite(cy)) {
        model_error(err, FDEM_ITEM_NONE, -1, "disc radius must be positive and finite");
        return -1;
    }
    if (divisions < 6) {
        model_error(err, FDEM_ITEM_NONE, -1, "a disc needs at least 6 divisions around the rim");
        return -1;
    }
    int rings = (int)lround(divisions / (2 * M_PI));
    if (rings < 1) rings = 1;
    long nodes = 0, triangles = 0;
    for (int k = 0; k <= rings; k++) {
        nodes += disc_ring_nodes(k, rings, divisions);
        if (k > 0) triangles += disc_ring_nodes(k, rings, divisions) +
                                (k > 1 ? disc_ring_nodes(k - 1, rings, divisions) : 0);
    }
    if (mesh_alloc(out, nodes, triangles, err)) return -1;

    int32_t *t = out->tri;
    int first = 0, prev_first = 0, prev_n = 1;
    double prev_phase = 0;
    for (int k = 0; k <= rings; k++) {
        int n = disc_ring_nodes(k, rings, divisions);
        double r = radius * k / rings;
        double phase = (k % 2) ? 0.0 : M_PI / n; /* stagger rings: no aligned spokes */
        for (int i = 0; i < n; i++) {
            double a = phase + 2 * M_PI * i / n;
            out->xy[2 * (first + i)] = k ? cx + r * cos(a) : cx;
            out->xy[2 * (first + i) + 1] = k ? cy + r * sin(a) : cy;
        }
        if (k == 1) {
            for (int i = 0; i < n; i++) {
                *t++ = 0; *t++ = first + i; *t++ = first + (i + 1) % n;
            }
        } else if (k > 1) {
            t = disc_join_rings(t, prev_first, prev_n, prev_phase, first, n, phase);
        }
        prev_first = first;
        prev_n = n;
        prev_phase = phase;
        first += n;
    }
    out->triangle_count = (int)((t - out->tri) / 3);
    return fdem_mesh_validate(out, NULL, err);
}

static double triangle_signed_area2(const double *xy, const int32_t *t)
{
    double x0 = xy[2 * t[0]], y0 = xy[2 * t[0] + 1];
    return (xy[2 * t[1]] - x0) * (xy[2 * t[2] + 1] - y0) -
           (xy[2 * t[1] + 1] - y0) * (xy[2 * t[2]] - x0);
}

int fdem_mesh_validate(fdem_mesh *mesh, int *reoriented, fdem_error *err)
{
    if (reoriented) *reoriented = 0;
    if (mesh->node_count < 3 || mesh->triangle_count < 1) {
        model_error(err, FDEM_ITEM_NONE, -1, "a mesh needs at least 3 nodes and 1 triangle");
        return -1;
    }
    for (int i = 0; i < 2 * mesh->node_count; i++)
        if (!isfinite(mesh->xy[i])) {
            model_error(err, FDEM_ITEM_NODE, i / 2, "node %d has a non-finite coordinate", i / 2);
            return -1;
        }
    for (int k = 0; k < mesh->triangle_count; k++) {
        int32_t *t = mesh->tri + 3 * k;
        for (int c = 0; c < 3; c++)
            if (t[c] < 0 || t[c] >= mesh->node_count) {
                model_error(err, FDEM_ITEM_TRIANGLE, k,
                           "triangle %d refers to node %d, but nodes are numbered 0 to %d", k,
                           (int)t[c], mesh->node_count - 1);
                return -1;
            }
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
            model_error(err, FDEM_ITEM_TRIANGLE, k, "triangle %d uses node %d twice", k,
                       (int)(t[0] == t[1] || t[0] == t[2] ? t[0] : t[1]));
            return -1;
        }
        double a2 = triangle_signed_area2(mesh->xy, t);
        double ex = fabs(mesh->xy[2 * t[1]] - mesh->xy[2 * t[0]]) +
                    fabs(mesh->xy[2 * t[2]] - mesh->xy[2 * t[0]]);
        double ey = fabs(mesh->xy[2 * t[1] + 1] - mesh->xy[2 * t[0] + 1]) +
                    fabs(mesh->xy[2 * t[2] + 1] - mesh->xy[2 * t[0] + 1]);
        double scale = (ex + ey) * (ex + ey);
        if (ex + ey > 0 && !(isfinite(scale) && scale > MESH_SMALLEST_CUBE)) {
            model_error(err, FDEM_ITEM_TRIANGLE, k,
                       "triangle %d is %.3g m across: an area of that scale cannot be computed "
                       "in double precision; give the coordinates in metres", k, ex + ey);
            return -1;
        }
        if (!(fabs(a2) > 1e-12 * scale)) {
            model_error(err, FDEM_ITEM_TRIANGLE, k,
                       "triangle %d has zero area (nodes %d, %d, %d are collinear or coincide)",
                       k, (int)t[0], (int)t[1], (int)t[2]);
            return -1;
        }
        if (a2 < 0) {
            int32_t s = t[1];
            t[1] = t[2];
            t[2] = s;
            if (reoriented) (*reoriented)++;
        }
    }
    /* A node no triangle uses would have no mass and could never move. */
    unsigned char *used = calloc((size_t)mesh->node_count, 1);
    if (!used) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory validating a mesh");
        return -1;
    }
    for (int k = 0; k < 3 * mesh->triangle_count; k++) used[mesh->tri[k]] = 1;
    int unused = -1;
    for (int i = 0; i < mesh->node_count && unused < 0; i++)
        if (!used[i]) unused = i;
    free(used);
    if (unused >= 0) {
        model_error(err, FDEM_ITEM_NODE, unused, "node %d is not used by any triangle", unused);
        return -1;
    }
    return 0;
}
