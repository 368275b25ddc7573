/*
 * case_memory.c - pass 2 of the case builder: how big would the model be?
 *
 * Counts are estimated from the shapes alone (in doubles, so absurd
 * divisions cannot overflow) and priced with fdem_memory_estimate() (or its
 * 3D form for tetrahedra) before any generator runs: an oversized case costs the daemon nothing but this
 * arithmetic, and the user learns how large the model would have been.
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>

#include "case_internal.h"

/* Beyond this many items fdem_memory_estimate() is asked about a scaled-down
 * model and the answer scaled back up: its size_t arithmetic stays exact and
 * the estimate is linear in the counts anyway. */
#define MEMORY_EXACT_COUNT 1e12

/* A disc with d rim nodes has about d/(2 pi) rings (equilateral triangles);
 * ring k holds about d k / rings nodes; a triangulation of n nodes has about
 * 2 n triangles. Rounded up so the estimate errs on the large side. */
static void memory_disc_counts(double divisions, double *nodes, double *elements)
{
    double rings = ceil(divisions / (2 * M_PI));
    if (rings < 1) rings = 1;
    *nodes = 1 + divisions * (rings + 1) / 2 + rings;
    *elements = 2 * *nodes;
}

/* The 3D generators map a lattice of cells, six tetrahedra each, onto the
 * shape. A sphere (cylinder cross-section) of d edges around the rim is a
 * cube (square) of n cells a side, n = d / 4 rounded up to even, as
 * cells_for_circle() in core/mesh/mesh_3d.c chooses it. */
static double memory_cells_for_circle(double divisions)
{
    double n = ceil(divisions / 4);
    return n + fmod(n, 2);
}

static void memory_lattice_counts(double nx, double ny, double nz, double *nodes,
                                  double *elements)
{
    *nodes = (nx + 1) * (ny + 1) * (nz + 1);
    *elements = 6 * nx * ny * nz;
}

static void memory_part_counts(case_part *part, int dimension)
{
    double nx = (double)part->divisions[0], ny = (double)part->divisions[1];
    double nz = (double)part->divisions[2], n = memory_cells_for_circle(nx);
    switch (part->shape) {
    case CASE_SHAPE_RECTANGLE:
        part->nodes = (nx + 1) * (ny + 1);
        part->elements = 2 * nx * ny;
        break;
    case CASE_SHAPE_DISC:
        memory_disc_counts(nx, &part->nodes, &part->elements);
        break;
    case CASE_SHAPE_BOX:
        memory_lattice_counts(nx, ny, nz, &part->nodes, &part->elements);
        break;
    case CASE_SHAPE_SPHERE:
        memory_lattice_counts(n, n, n, &part->nodes, &part->elements);
        break;
    case CASE_SHAPE_CYLINDER:
        memory_lattice_counts(n, n, ny, &part->nodes, &part->elements);
        break;
    case CASE_SHAPE_MESH:
    case CASE_SHAPE_GMSH:
        part->nodes = part->mesh.node_count + part->tet_mesh.node_count;
        part->elements = part->mesh.triangle_count + part->tet_mesh.tet_count;
        break;
    case CASE_SHAPE_NONE:
        break;
    }
    part->joints = 0;
    if (part->fracture) {
        /* every element gets its own nodes and a joint on each interior
         * side: an edge is shared by two of 3 per triangle, a face by two of
         * 4 per tetrahedron (rounded up: the hull sides have none) */
        int corners = dimension + 1;
        part->nodes = corners * part->elements;
        part->joints = corners / 2.0 * part->elements;
    }
}

static double memory_bytes(int dimension, double nodes, double elements, double joints,
                           int parts)
{
    double largest = fmax(nodes, fmax(elements, joints));
    double scale = largest > MEMORY_EXACT_COUNT ? largest / MEMORY_EXACT_COUNT : 1;
    long n = (long)(nodes / scale), e = (long)(elements / scale);
    long j = (long)(joints / scale);
    size_t bytes = dimension == 3 ? fdem_memory_estimate_3d(n, e, j, parts)
                                 : fdem_memory_estimate(n, e, j, parts);
    return (double)bytes * scale;
}

/* "12.3 GiB" */
static void memory_format(double bytes, char *out, size_t size)
{
    static const char *const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    int unit = 0;
    while (bytes >= 1024 && unit < 6) {
        bytes /= 1024;
        unit++;
    }
    if (unit == 0)
        snprintf(out, size, "%.0f bytes", bytes);
    else
        snprintf(out, size, "%.3g %s", bytes, units[unit]);
}

/* "about 9e+08 nodes, 1.8e+09 elements" (and joints when there are any) */
static void memory_describe(double nodes, double elements, double joints, char *out,
                            size_t size)
{
    int n = snprintf(out, size, "about %.3g nodes, %.3g elements", nodes, elements);
    if (joints > 0 && n > 0 && (size_t)n < size)
        snprintf(out + n, size - (size_t)n, ", %.3g joints", joints);
}

double case_part_bytes(const case_doc *doc, case_part *part)
{
    memory_part_counts(part, doc->dimension);
    return memory_bytes(doc->dimension, part->nodes, part->elements, part->joints, 1);
}

double case_check_memory(case_doc *doc, size_t memory_limit)
{
    double nodes = 0, elements = 0, joints = 0;
    for (int i = 0; i < doc->part_count; i++) {
        memory_part_counts(&doc->parts[i], doc->dimension);
        nodes += doc->parts[i].nodes;
        elements += doc->parts[i].elements;
        joints += doc->parts[i].joints;
    }
    double bytes = memory_bytes(doc->dimension, nodes, elements, joints, doc->part_count);
    if (doc->has_fluid) /* contract 6.4: the fluid network over the joints */
        bytes += (double)fdem_fluid_memory_estimate(doc->dimension, 1000) * (joints / 1000);
    char need[32], limit[32], counts[96];
    memory_format(bytes, need, sizeof need);
    memory_describe(nodes, elements, joints, counts, sizeof counts);
    if (bytes > (double)memory_limit) {
        memory_format((double)memory_limit, limit, sizeof limit);
        case_problem(doc, "/parts", "the model would need %s (%s), more than this daemon's "
                                    "limit of %s", need, counts, limit);
    } else if (nodes > INT_MAX || elements > INT_MAX || joints > INT_MAX) {
        case_problem(doc, "/parts", "the model would have %s (%s); the engine's limit is %d "
                                    "of each", counts, need, INT_MAX);
    }
    return bytes;
}
