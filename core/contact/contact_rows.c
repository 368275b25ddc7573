/*
 * contact_rows.c - the lists a threaded contact walk fills (contact_rows.h)
 * and their application: each thread of the walk lists the pairs that
 * touched with their forces, and the lists are added to the contact force
 * array in thread order, which is pair order. Apart from the walk
 * (contact_walk.c, which evaluates the pairs) because applying is a job of
 * its own: on the threads too, each adding the forces on its own share of
 * the nodes, every node's sum still formed in pair order.
 */
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "parallel/team.h"
#include "contact.h"
#include "contact_internal.h"
#include "contact_rows.h"

/* Twice the room (pair_rows_room); -1 when out of memory. */
int pair_rows_grow(pair_rows *list, int width)
{
    size_t cap = list->capacity ? 2 * list->capacity : CONTACT_FIRST_ROWS;
    long *p = realloc(list->pair, cap * sizeof *p);
    if (!p) return -1;
    list->pair = p;
    if (width) {
        double *f = realloc(list->row, cap * (size_t)width * sizeof *f);
        if (!f) return -1;
        list->row = f;
        double *l = realloc(list->last, cap * sizeof *l);
        if (!l) return -1;
        list->last = l;
    }
    if (list->node_width) {
        int32_t *n = realloc(list->nodes, cap * (size_t)list->node_width * sizeof *n);
        if (!n) return -1;
        list->nodes = n;
    }
    list->capacity = cap;
    return 0;
}

int pair_rows_push(pair_rows *list, long pair, const double *row, int width)
{
    if (pair_rows_room(list, width)) return -1;
    list->pair[list->count] = pair;
    if (width) {
        memcpy(list->row + list->count * (size_t)width, row, sizeof(double) * (size_t)width);
        list->last[list->count] = row[width - 1];
    }
    list->count++;
    return 0;
}


size_t pair_rows_bytes(const pair_rows *list, int width)
{
    return list->capacity * (sizeof(long) + sizeof(double) * (size_t)(width ? width + 1 : 0) +
                             sizeof(int32_t) * (size_t)list->node_width);
}

void pair_rows_free(pair_rows *list)
{
    free(list->pair);
    free(list->row);
    free(list->last);
    free(list->nodes);
}

/* Adds a pair's forces (contact_pair_force) to the contact force array and
 * what its friction dissipated to the friction account; called in pair
 * order, so every sum is formed in the same order on any thread count. */
static inline __attribute__((always_inline)) void scatter_nodes(double *f, const int32_t *n1,
                                                                 const int32_t *n2, int D, int K,
                                                                 const double *out)
{
    /* unrolled whole (K, D are constants): the loops' own counting was a
     * fifth of this function's instructions */
#pragma GCC unroll 4
    for (int c = 0; c < K; c++)
#pragma GCC unroll 3
        for (int d = 0; d < D; d++) f[D * n1[c] + d] += out[D * c + d];
#pragma GCC unroll 4
    for (int c = 0; c < K; c++)
#pragma GCC unroll 3
        for (int d = 0; d < D; d++) f[D * n2[c] + d] += out[D * (K + c) + d];
}

static inline __attribute__((always_inline)) void pair_add(fdem_model *m, int e1, int e2,
                                                            const double *out)
{
    const int32_t *n1 = element_nodes(m, e1), *n2 = element_nodes(m, e2);
    if (m->dim == 3) scatter_nodes(m->contact.force, n1, n2, 3, 4, out);
    else scatter_nodes(m->contact.force, n1, n2, 2, 3, out);
    m->friction_energy += out[2 * m->dim * m->elem_nodes];
}

/* every 8th step: a body passing into another stays deep for several
 * steps, and every step would cost a dense 2D pile ~10 % */
static inline __attribute__((always_inline)) int pair_looks(const fdem_model *m, int e1, int e2)
{
    return m->step % CONTACT_PENETRATION_EVERY == 0 && !contact_shut_neighbours(m, e1, e2);
}

/* both inlined: the serial walk calls this for every touching pair (as one
 * function the 3D broken block stepped 5 % slower, 755 -> 790 ns) */
void contact_pair_scatter(fdem_model *m, int e1, int e2, const double *out)
{
    pair_add(m, e1, e2, out);
    if (pair_looks(m, e1, e2)) contact_penetration_check(m, e1, e2);
}

/* The lists of a threaded walk applied on its threads, each adding the
 * forces on the nodes it owns (a contiguous share of the node indices):
 * every node's sum is still formed in pair order, by one thread, as the
 * serial scatter forms it, so the same bits; applied on one thread, the
 * scatter was a fifth of a broken 2D block's step on two. An element
 * whose nodes all lie in one share is that thread's alone (apply_owner);
 * a thread passes over the pairs with no node of its own at the cost of
 * two bytes. The friction account and the penetration look stay in pair
 * order on one thread. */
static int apply_owners(fdem_model *m, int threads)
{
    contact_state *cs = &m->contact;
    if (cs->apply_owner_threads == threads && cs->apply_owner_elems == m->elem_count &&
        cs->apply_owner_nodes == m->node_count)
        return 0;
    if (cs->apply_owner_bytes < (size_t)m->elem_count) {
        int8_t *o = realloc(cs->apply_owner, (size_t)m->elem_count);
        if (!o) return -1;
        cs->apply_owner = o;
        cs->apply_owner_bytes = (size_t)m->elem_count;
    }
    const long N = m->node_count;
    for (int e = 0; e < m->elem_count; e++) {
        const int32_t *n = element_nodes(m, e);
        int owner = (int)((long)n[0] * threads / N);
        for (int c = 1; c < m->elem_nodes; c++)
            if ((int)((long)n[c] * threads / N) != owner) owner = -1;
        cs->apply_owner[e] = (int8_t)owner;
    }
    cs->apply_owner_threads = threads;
    cs->apply_owner_elems = m->elem_count;
    cs->apply_owner_nodes = m->node_count;
    return 0;
}

/* Element e's share of a pair's forces (out: its K nodes' rows) onto the
 * nodes of [lo, hi); all its nodes when mine. */
static inline __attribute__((always_inline)) void scatter_owned(double *f, const int32_t *n,
                                                                const double *out, int mine,
                                                                int32_t lo, int32_t hi, int D,
                                                                int K)
{
#pragma GCC unroll 4
    for (int c = 0; c < K; c++)
        if (mine || (n[c] >= lo && n[c] < hi))
#pragma GCC unroll 3
            for (int d = 0; d < D; d++) f[D * n[c] + d] += out[D * c + d];
}

static inline __attribute__((always_inline)) void
apply_share(fdem_model *m, const contact_touches *lists, int used, int t, int nt, int D)
{
    contact_state *cs = &m->contact;
    const int K = D + 1, width = cs->pair_out;
    const int32_t lo = (int32_t)((long)m->node_count * t / nt);
    const int32_t hi = (int32_t)((long)m->node_count * (t + 1) / nt);
    const int8_t *owner = cs->apply_owner;
    double *f = cs->force;
    for (int l = 0; l < used; l++) {
        const pair_rows *touched = &lists[l].touched;
        for (size_t i = 0; i < touched->count; i++) {
            long key = touched->pair[i];
            int32_t a = touched_a(key), b = touched_b(key);
            int oa = owner[a], ob = owner[b];
            if (oa != t && ob != t && oa >= 0 && ob >= 0) continue;
            const double *row = touched->row + i * (size_t)width;
            const int32_t *na = touched->nodes + 2 * (size_t)K * i, *nb = na + K;
            if (oa == t || oa < 0) scatter_owned(f, na, row, oa == t, lo, hi, D, K);
            if (ob == t || ob < 0) scatter_owned(f, nb, row + D * K, ob == t, lo, hi, D, K);
        }
    }
}

void touched_apply(fdem_model *m, const contact_touches *lists, int used)
{
    contact_state *cs = &m->contact;
    int shared = used > 1 && apply_owners(m, used) == 0;
    if (shared) {
#pragma omp parallel num_threads(used)
        {
            int t, nt;
            parallel_team(&t, &nt);
            /* the owners were made for `used` shares: a team given fewer
             * threads takes several each (the shares' nodes are apart) */
            for (int s = t; s < used; s += nt)
                if (m->dim == 3) apply_share(m, lists, used, s, used, 3);
                else apply_share(m, lists, used, s, used, 2);
        }
    }
    const int look = m->step % CONTACT_PENETRATION_EVERY == 0;
    for (int l = 0; l < used; l++) {
        const pair_rows *touched = &lists[l].touched;
        if (!shared) {
            for (size_t i = 0; i < touched->count; i++) {
                long key = touched->pair[i];
                contact_pair_scatter(m, touched_a(key), touched_b(key),
                                     touched->row + i * (size_t)cs->pair_out);
            }
            continue;
        }
        for (size_t i = 0; i < touched->count; i++) m->friction_energy += touched->last[i];
        for (size_t i = 0; look && i < touched->count; i++) {
            long key = touched->pair[i];
            if (pair_looks(m, touched_a(key), touched_b(key)))
                contact_penetration_check(m, touched_a(key), touched_b(key));
        }
    }
}

/* The two halves of contact_pair_scatter for the split walk's apply
 * (contact_walk_split.c), which looks where the pair was walked. */
void contact_pair_add(fdem_model *m, int e1, int e2, const double *out) { pair_add(m, e1, e2, out); }

int contact_penetration_looks(const fdem_model *m, int e1, int e2) { return pair_looks(m, e1, e2); }
