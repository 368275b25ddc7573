/*
 * start_overlap.c - bodies that overlap at t = 0 (fdem_find_start_overlap,
 * declared in fdem.h), in either dimension.
 *
 * Contact is a penalty on overlap, so two parts placed inside each other
 * start with the penalty energy of the whole overlap and fly apart at
 * absurd speeds (two 0.1 m rock boxes overlapping by half a side left at
 * about 2.8 km/s), or the step turns non-finite: nonsense a user should
 * hear about when the case is submitted, not read in the results. The
 * candidates are the pairs of elements of different parts whose bounding
 * circles (spheres) touch, from the engine's own NBS detection (linear in
 * the element count); a pair overlaps when a vertex or the centroid of
 * one lies inside the other by more than a tenth of its depth
 * (barycentric coordinates): bodies placed touching pass, and so do the
 * shallow overlaps of curved boundaries meshed apart (a disc's 16-gon in
 * a hole's 16-gon: a vertex up to a chord's sagitta, about 6 % of an
 * element's depth, inside), which contact pushes apart at once. Two
 * simplices can cross without either holding a vertex or the centroid of
 * the other; bodies sunk into each other by more than about a tenth of an
 * element always have some pair where one holds a vertex or the centroid of
 * the other (the deepest ones).
 *
 * Memory: the spheres (4 doubles an element), the NBS grid (in 3D with
 * its packed copy of them, 4 more) and the pair list live only during this
 * check, at build time, while the model's own contact lists are still at
 * their first capacities; fdem_memory_estimate prices those lists grown
 * (3D: 32 kept pairs an element, 384 bytes), far above this check's 64
 * bytes an element and its pairs.
 */
#include <math.h>
#include <stdlib.h>

#include "fdem.h"
#include "model/model.h"
#include "nbs/nbs.h"
#include "contact.h"

/* Barycentric margin: a point is inside when every coordinate exceeds it. */
#define START_OVERLAP_MARGIN 0.1

static const double *corner_of(const fdem_model *m, int e, int k)
{
    return m->pos0 + (size_t)m->dim * (size_t)m->elem_node[(size_t)m->elem_nodes * (size_t)e + (size_t)k];
}

/* dim! times the signed measure of the simplex c[0 .. dim]. */
static double simplex_measure(int dim, const double *const c[4])
{
    double e[3][3];
    for (int i = 0; i < dim; i++)
        for (int k = 0; k < dim; k++) e[i][k] = c[i + 1][k] - c[0][k];
    if (dim == 2) return e[0][0] * e[1][1] - e[0][1] * e[1][0];
    return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
           e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
           e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
}

/* Is p inside element e by more than the margin of each face? */
static int inside_element(const fdem_model *m, int e, const double *p)
{
    const double *c[4];
    for (int k = 0; k < m->elem_nodes; k++) c[k] = corner_of(m, e, k);
    double whole = simplex_measure(m->dim, c);
    for (int k = 0; k < m->elem_nodes; k++) {
        const double *ck = c[k];
        c[k] = p;
        int deep = simplex_measure(m->dim, c) > START_OVERLAP_MARGIN * whole;
        c[k] = ck;
        if (!deep) return 0;
    }
    return 1;
}

static void centroid_of(const fdem_model *m, int e, double out[3])
{
    out[0] = out[1] = out[2] = 0;
    for (int k = 0; k < m->elem_nodes; k++)
        for (int d = 0; d < m->dim; d++) out[d] += corner_of(m, e, k)[d] / m->elem_nodes;
}

/* A vertex or the centroid of element a inside element b: 1 and the
 * point, else 0. */
static int element_reaches_into(const fdem_model *m, int a, int b, double point[3])
{
    for (int k = 0; k <= m->elem_nodes; k++) {
        double p[3] = {0, 0, 0};
        if (k < m->elem_nodes)
            for (int d = 0; d < m->dim; d++) p[d] = corner_of(m, a, k)[d];
        else
            centroid_of(m, a, p);
        if (inside_element(m, b, p)) {
            for (int d = 0; d < 3; d++) point[d] = p[d];
            return 1;
        }
    }
    return 0;
}

/* Bounding circles (spheres) of every element at t = 0, into cx, cy, cz, r. */
static void bounding_spheres(const fdem_model *m, double *cx, double *cy, double *cz, double *r)
{
    for (int e = 0; e < m->elem_count; e++) {
        double c[3];
        centroid_of(m, e, c);
        double r2 = 0;
        for (int k = 0; k < m->elem_nodes; k++) {
            double s = 0;
            for (int d = 0; d < m->dim; d++) {
                double dx = corner_of(m, e, k)[d] - c[d];
                s += dx * dx;
            }
            r2 = fmax(r2, s);
        }
        cx[e] = c[0];
        cy[e] = c[1];
        cz[e] = c[2];
        r[e] = sqrt(r2);
    }
}

/* The candidate pairs: elements of different parts whose spheres touch. */
static int candidate_pairs(const fdem_model *m, const double *s, nbs_pairs *pairs)
{
    size_t n = (size_t)m->elem_count;
    const double *cx = s, *cy = s + n, *cz = s + 2 * n, *r = s + 3 * n;
    if (m->dim == 3) {
        nbs_grid_3d grid;
        nbs_grid_3d_init(&grid);
        int rc = nbs_detect_3d(&grid, n, cx, cy, cz, r, m->elem_part, pairs);
        nbs_grid_3d_free(&grid);
        return rc;
    }
    nbs_grid grid;
    nbs_grid_init(&grid);
    int rc = nbs_detect(&grid, n, cx, cy, r, m->elem_part, pairs);
    nbs_grid_free(&grid);
    return rc;
}

int fdem_find_start_overlap(const fdem_model *m, int *inner, int *outer, double point[3])
{
    if (m->part_count < 2 || m->elem_count < 2) return 0;
    size_t n = (size_t)m->elem_count;
    double *spheres = malloc(4 * n * sizeof *spheres);
    if (!spheres) return -1;
    bounding_spheres(m, spheres, spheres + n, spheres + 2 * n, spheres + 3 * n);
    nbs_pairs pairs;
    nbs_pairs_init(&pairs);
    int found = candidate_pairs(m, spheres, &pairs) != 0 ? -1 : 0;
    for (size_t k = 0; found == 0 && k < pairs.count; k++) {
        int a = pairs.a[k], b = pairs.b[k];
        if (element_reaches_into(m, a, b, point)) {
            *inner = m->elem_part[a], *outer = m->elem_part[b], found = 1;
        } else if (element_reaches_into(m, b, a, point)) {
            *inner = m->elem_part[b], *outer = m->elem_part[a], found = 1;
        }
    }
    nbs_pairs_free(&pairs);
    free(spheres);
    return found;
}
