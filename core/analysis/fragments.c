/*
 * fragments.c - what a fragmentation engineer measures of a broken model:
 * its pieces (connected through shared nodes or intact joints), each
 * piece's mass, size, equivalent diameter, centroid and velocity, its part
 * and whether a constraint holds it (so a reader can leave the host body
 * out), and the sieve curve of the pieces' sizes (contract 5.4).
 *
 * Pieces come from joint_fragment_labels (union-find over intact joints;
 * an unbroken part is one piece), renumbered here in the order of each
 * piece's first element so that ids are stable whatever order the
 * union-find leaves them in. Both dimensions are one code: sizes are the
 * elements' initial areas or volumes, and the equivalent diameter is that
 * of the circle or sphere of the same size.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "analysis.h"
#include "joint/joint.h"

int fdem_fragment_labels(const fdem_model *m, int32_t *label)
{
    int E = m->elem_count;
    int32_t *root_id = malloc(sizeof(int32_t) * (size_t)(E ? E : 1));
    if (!root_id) return -1;
    joint_fragment_labels(m, label); /* label[e]: the root element of e's piece */
    for (int e = 0; e < E; e++) root_id[e] = -1;
    int count = 0;
    for (int e = 0; e < E; e++) {
        if (!element_is_active(m, e)) {
            label[e] = -1; /* excavated: in no fragment */
            continue;
        }
        int32_t root = label[e];
        if (root_id[root] < 0) root_id[root] = count++;
        label[e] = root_id[root];
    }
    free(root_id);
    return count;
}

/* Diameter of the circle (2D) or sphere (3D) of the given size. */
static double equivalent_diameter(int dim, double size)
{
    return dim == 3 ? cbrt(6.0 * size / M_PI) : sqrt(4.0 * size / M_PI);
}

int fdem_fragments(const fdem_model *m, fdem_fragment **out)
{
    *out = NULL;
    int E = m->elem_count, N = m->node_count, D = m->dim, K = m->elem_nodes;
    int32_t *label = malloc(sizeof(int32_t) * (size_t)(E ? E : 1));
    int32_t *node_piece = malloc(sizeof(int32_t) * (size_t)(N ? N : 1));
    if (!label || !node_piece) {
        free(label);
        free(node_piece);
        return -1;
    }
    int count = fdem_fragment_labels(m, label);
    fdem_fragment *f = count >= 0 ? calloc((size_t)(count ? count : 1), sizeof *f) : NULL;
    if (!f) {
        free(label);
        free(node_piece);
        return -1;
    }
    for (int i = 0; i < N; i++) node_piece[i] = -1;
    for (int e = 0; e < E; e++) {
        if (label[e] < 0) continue; /* excavated */
        fdem_fragment *p = &f[label[e]];
        double size = element_size0(m, e);
        if (p->elements == 0) p->part = m->elem_part[e];
        p->elements++;
        p->size += size;
        p->mass += m->materials[element_material(m, e)].def.density * size;
        for (int c = 0; c < K; c++) node_piece[m->elem_node[(size_t)K * (size_t)e + (size_t)c]] = label[e];
    }
    /* every node belongs to some element, and all of an element's nodes to
     * its piece; a node only excavated elements held belongs to none */
    double *node_mass = calloc((size_t)(count ? count : 1), sizeof(double));
    if (!node_mass) {
        free(f);
        free(label);
        free(node_piece);
        return -1;
    }
    for (int i = 0; i < N; i++) {
        if (node_piece[i] < 0) continue;
        fdem_fragment *p = &f[node_piece[i]];
        double mass = m->mass[i];
        node_mass[node_piece[i]] += mass;
        if (m->dof_owned && m->dof_owned[i]) p->held = 1; /* a fix or velocity owns a component */
        for (int d = 0; d < D; d++) {
            p->centroid[d] += mass * m->pos[(size_t)D * (size_t)i + (size_t)d];
            p->velocity[d] += mass * m->vel[(size_t)D * (size_t)i + (size_t)d];
        }
    }
    for (int k = 0; k < count; k++) {
        for (int d = 0; d < D; d++) {
            f[k].centroid[d] /= node_mass[k];
            f[k].velocity[d] /= node_mass[k];
        }
        f[k].diameter = equivalent_diameter(D, f[k].size);
    }
    free(node_mass);
    free(label);
    free(node_piece);
    *out = f;
    return count;
}

static int diameter_order(const void *pa, const void *pb)
{
    const fdem_fragment *a = *(const fdem_fragment *const *)pa, *b = *(const fdem_fragment *const *)pb;
    return a->diameter < b->diameter ? -1 : a->diameter > b->diameter;
}

int fdem_sieve_curve(const fdem_fragment *fragments, int count, double *diameter, double *passing)
{
    if (count <= 0) return 0;
    const fdem_fragment **sorted = malloc(sizeof *sorted * (size_t)count);
    if (!sorted) return -1;
    double total = 0;
    for (int k = 0; k < count; k++) {
        sorted[k] = &fragments[k];
        total += fragments[k].mass;
    }
    qsort(sorted, (size_t)count, sizeof *sorted, diameter_order);
    int points = 0;
    double below = 0;
    for (int k = 0; k < count; k++) {
        below += sorted[k]->mass;
        if (k + 1 < count && sorted[k + 1]->diameter == sorted[k]->diameter) continue;
        diameter[points] = sorted[k]->diameter;
        passing[points] = k + 1 == count ? 1.0 : below / total;
        points++;
    }
    free(sorted);
    return points;
}
