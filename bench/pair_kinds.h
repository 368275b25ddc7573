/*
 * pair_kinds.h - the candidate pairs of a model's contact stage sorted by
 * what their two elements share of the mesh (bench_engine.c, bench_case.c):
 * the mesh vertices two elements hold copies of (node_origin), so 3 in 3D
 * (2 in 2D) are the two sides of a broken joint, one fewer an edge (3D) and
 * 1 a corner. What drives the cost of a body after fracture (issue 34).
 */
#ifndef FDEM_BENCH_PAIR_KINDS_H
#define FDEM_BENCH_PAIR_KINDS_H

#include <stdlib.h>

#include "contact/contact.h"
#include "kernel/contact_pair.h"
#include "math/clock.h"
#include "model/model.h"

enum { PAIR_APART_MESH, PAIR_CORNER, PAIR_EDGE, PAIR_FACE, PAIR_KINDS };
static const char *const pair_kind_name[PAIR_KINDS] = {"none", "corner", "edge", "face"};

/* Mesh vertices elements a and b both hold, as a kind: in 2D two shared
 * vertices are a face (an edge of the triangles). */
static inline int pair_kind(const fdem_model *m, int a, int b)
{
    int K = m->elem_nodes, shared = 0;
    const int32_t *na = m->elem_node + (size_t)K * (size_t)a;
    const int32_t *nb = m->elem_node + (size_t)K * (size_t)b;
    for (int i = 0; i < K; i++)
        for (int k = 0; k < K; k++) shared += m->node_origin[na[i]] == m->node_origin[nb[k]];
    if (m->dim == 2 && shared == 2) return PAIR_FACE;
    return shared >= 3 ? PAIR_FACE : shared;
}

/* Candidate pairs of each kind. */
static inline void pair_kind_counts(const fdem_model *m, double count[PAIR_KINDS])
{
    for (int k = 0; k < PAIR_KINDS; k++) count[k] = 0;
    for (size_t k = 0; k < m->contact.pairs.count; k++)
        count[pair_kind(m, m->contact.pairs.a[k], m->contact.pairs.b[k])]++;
}

/* Seconds the pair kernel takes over every candidate pair of each kind once
 * (the force now, springs untouched: contact_pair_force_now; one timed pass
 * per kind), and how many of them touch. */
static inline void pair_kind_kernel(const fdem_model *m, double seconds[PAIR_KINDS],
                                    double touching[PAIR_KINDS])
{
    size_t n = m->contact.pairs.count;
    unsigned char *kind = malloc(n ? n : 1);
    for (size_t k = 0; k < n; k++) kind[k] = (unsigned char)pair_kind(m, m->contact.pairs.a[k], m->contact.pairs.b[k]);
    double out[CONTACT_PAIR_OUT_MAX];
    for (int c = 0; c < PAIR_KINDS; c++) {
        int touched = 0;
        double t0 = clock_cpu_seconds();
        for (size_t k = 0; k < n; k++)
            if (kind[k] == c) touched += contact_pair_force_now(m, k, out);
        seconds[c] = clock_cpu_seconds() - t0;
        touching[c] = touched;
    }
    free(kind);
}

#endif
