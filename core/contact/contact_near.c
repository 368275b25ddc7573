/*
 * contact_near.c - the near-pair list of the contact stage (both
 * dimensions): which candidate pairs the per-step walk (contact.c) takes.
 *
 * Most candidate pairs are far from touching (coarse tetrahedra have loose
 * bounding spheres: a sphere pile has ~25 candidates per element and well
 * under one touching), so the per-step walk takes only the "near" pairs:
 * when the list is built every node's place is kept (pos_near), and two
 * boxes with a gap g then cannot overlap while no node is farther than r
 * from its kept place, if g > 2 r. The near list holds the other pairs,
 * in pair order, each with its gap and what the walk reads of it (its
 * elements, whether it holds springs: near_pair), so the walk streams one
 * array instead of looking each pair up in the candidate arrays, and is
 * rebuilt when some node passes r; a pair it leaves out has its boxes apart now and until then, exactly
 * what the box test would have found, so its springs go at the rebuild as
 * they would have gone that step: the same bits as walking every pair.
 * In the same way a near pair whose gap is over twice the farthest travel
 * so far is apart without a look at its boxes, and only elements with such
 * a pair closing get their box computed; a pair of shut topology (below)
 * reads boxes only where one of its elements is not shut, so its elements
 * get theirs only then (elem_topo).
 *
 * Broken rock: the pairs of elements that share a mesh vertex but no
 * broken joint are kept apart, at the end of the same array (the walk
 * leaves such a pair out while both elements are shut: contact_shut.c,
 * and in a block broken in place they are 41 of 66 near pairs an element
 * in 3D). Each element lists its own, and a step walks only those of the
 * elements not shut now or last step, after the rest of the list: a pair
 * both of whose elements were shut last step too was left out then, which
 * let its springs go, so walking it would change nothing. The step after a
 * rebuild (a detection, a restore) walks them all.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "contact_internal.h"

static int index_order(const void *x, const void *y)
{
    int32_t a = *(const int32_t *)x, b = *(const int32_t *)y;
    return (a > b) - (a < b);
}

static void sort_indices(int32_t *v, size_t n) { qsort(v, n, sizeof *v, index_order); }

/* The current box of each listed element: those in some candidate pair
 * when the near list is rebuilt, else those in some near pair. Most
 * candidate pairs do not touch (their bounding circles, inflated by the
 * buffer, overlap; their elements do not): the box test then reads two
 * boxes instead of two element records and their scattered nodes. */
static void contact_boxes(fdem_model *m, const int32_t *list, int count)
{
    double *box = m->contact.box;
    size_t width = 2 * (size_t)m->dim;
#pragma omp parallel for num_threads(m->threads) if (m->threads > 1 && count > 4096) \
    schedule(static)
    for (int k = 0; k < count; k++) element_box(m, list[k], box + width * (size_t)list[k]);
}

/* This step's TOPO_OPEN marks. A pair of shut topology reads its boxes
 * only on the general kernel, where one of its elements is not shut
 * (pair_evaluate): each element not shut now is marked, with its
 * neighbours across its joints (its face pairs' partners, and a few
 * more) and in its vertex pairs. Only the elements due (not shut now or
 * last step) can be unshut now. */
static void near_topology_open(fdem_model *m)
{
    contact_state *cs = &m->contact;
    uint8_t *topo = cs->elem_topo;
    const int faces = m->dim + 1;
    for (int e = 0; e < m->elem_count; e++) topo[e] &= TOPO_LISTED;
    for (int k = 0; k < cs->elem_due_count; k++) {
        int u = cs->elem_due[k];
        if (cs->elem_shut[u]) continue;
        topo[u] |= TOPO_OPEN;
        for (int c = 0; c < faces; c++) {
            int j = m->elem_joint[faces * u + c];
            if (j >= 0) topo[m->joint_elem[2 * j] + m->joint_elem[2 * j + 1] - u] |= TOPO_OPEN;
        }
        if (!cs->near_vertex_count) continue;
        for (int32_t i = cs->vertex_start[u]; i < cs->vertex_start[u + 1]; i++) {
            const near_pair *np = &cs->near_vertex[cs->vertex_pairs[i]];
            topo[np->a] |= TOPO_OPEN;
            topo[np->b] |= TOPO_OPEN;
        }
    }
}

/* elem_gap found again from the near pairs' gaps, after the walk raised
 * some by a clearance its kernel found: the boxes' gaps at the list's
 * build are lower, and kept every element of a block broken in place
 * computing its box (the pairs across each square's diagonal, apart by
 * their clearance, but not by their boxes). This process's share of the
 * list, as the walk takes it; a step without a raise pays nothing. */
static void near_gaps_refresh(fdem_model *m)
{
    contact_state *cs = &m->contact;
    double *elem_gap = cs->elem_gap;
    for (int k = 0; k < cs->near_active_count; k++) elem_gap[cs->near_active[k]] = INFINITY;
    size_t lo, hi;
    contact_share(m->share, cs->near_count, &lo, &hi);
    for (size_t i = lo; i < hi; i++) {
        const near_pair *np = &cs->near[i];
        if (np->topology) continue;
        elem_gap[np->a] = min2(elem_gap[np->a], np->gap);
        elem_gap[np->b] = min2(elem_gap[np->b], np->gap);
    }
    cs->gaps_raised = 0;
}

/* The near pairs found apart past contact_near_dead by a clearance taken
 * out of the list, the rest kept in pair order: a block broken in place
 * walked 25 near pairs an element in 3D, 22 of them found apart by the
 * size of an element, which stay skipped until the next rebuild anyway
 * (the rebuild would have left them out had it known). A pair that holds
 * springs stays (the walk has let a dead pair's go). Not while the walk is
 * split between processes: their shares are fixed index ranges of the
 * list between rebuilds (contact_walk.c). */
void contact_near_compact(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (m->share && m->share->contact_ranks > 1) return;
    const double dead = contact_near_dead(cs);
    size_t kept = 0;
    for (size_t i = 0; i < cs->near_count; i++)
        if (!(cs->near[i].gap > dead) || cs->near[i].sprung) cs->near[kept++] = cs->near[i];
    cs->near_compacted += (long)(cs->near_count - kept);
    cs->near_count = kept;
    cs->near_dead = 0;
}

/* The same for the near pairs' elements whose boxes can touch another's:
 * an element whose every near pair had a gap over near_apart keeps its
 * box from before, which no pair reads (pair_evaluate). So does one whose
 * only pairs that close are of shut topology between shut elements (the
 * face kernel, or left out): in a block broken in place that is every
 * element, whose boxes were 5 % of a step at 1e5 triangles. */
static void contact_near_boxes(fdem_model *m)
{
    const contact_state *cs = &m->contact;
    const int32_t *list = cs->near_active;
    const double *elem_gap = cs->elem_gap;
    double *box = cs->box, apart = cs->near_apart;
    size_t width = 2 * (size_t)m->dim;
    int count = cs->near_active_count;
    const uint8_t *topo = cs->elem_topo;
    const uint8_t open = cs->shut_any ? TOPO_OPEN : TOPO_LISTED;
    if (topo && cs->shut_any) near_topology_open(m);
    if (cs->gaps_raised) near_gaps_refresh(m);
#pragma omp parallel for num_threads(m->threads) if (m->threads > 1 && count > 4096) \
    schedule(static)
    for (int k = 0; k < count; k++) {
        int e = list[k];
        if (elem_gap[e] <= apart || (topo && (topo[e] & open)))
            element_box(m, e, box + width * (size_t)e);
    }
}

/* The elements of the near pairs (of every candidate pair when near is
 * NULL), once each and in element order (so that contact_boxes walks the
 * mesh forwards), into list; returns how many. */
int contact_collect_elements(contact_state *cs, int elem_count, const near_pair *near,
                             size_t count, const near_pair *more, size_t more_count,
                             int32_t *list)
{
    memset(cs->in_pair, 0, (size_t)elem_count);
    for (size_t i = 0; i < count; i++) {
        cs->in_pair[near ? near[i].a : cs->pairs.a[i]] = 1;
        cs->in_pair[near ? near[i].b : cs->pairs.b[i]] = 1;
    }
    for (size_t i = 0; i < more_count; i++) cs->in_pair[more[i].a] = cs->in_pair[more[i].b] = 1;
    return contact_listed_elements(cs, elem_count, list);
}

int contact_listed_elements(const contact_state *cs, int elem_count, int32_t *list)
{
    int listed = 0;
    for (int e = 0; e < elem_count; e++)
        if (cs->in_pair[e]) list[listed++] = e;
    return listed;
}

/* The near list is to be rebuilt: a detection or a restore made it stale,
 * or some node has gone past its reach since it was built. */
static int contact_near_due(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (cs->near_stale) return 1;
    double moved2 = cs->near_disp2; /* the integrator's (central_difference_pass) */
    if (moved2 > cs->near_reach * cs->near_reach) return 1;
    /* boxes move by no more than their nodes: a gap over twice the
     * farthest travel since the list was built is still open (a hair over
     * it, for rounding) */
    cs->near_apart = 2.0 * sqrt(moved2) * (1 + 1e-9);
    return 0;
}

/* The near array doubled (the first time CONTACT_FIRST_ROWS), its last
 * `vertex` rows (the vertex pairs so far) moved to its new end. */
static int near_grow(contact_state *cs, size_t vertex)
{
    size_t old = cs->near_capacity, cap = old ? 2 * old : CONTACT_FIRST_ROWS;
    near_pair *p = realloc(cs->near, cap * sizeof *p);
    if (!p) return -1;
    memmove(p + cap - vertex, p + old - vertex, vertex * sizeof *p);
    cs->near = p;
    cs->near_capacity = cap;
    return 0;
}

/* Room for exactly `need` items (a rebuild fills them whole): the index
 * arrays of the vertex pairs cost no doubling's slack. */
static int fit_array(void **array, size_t *capacity, size_t need, size_t size)
{
    if (need <= *capacity && need >= *capacity / 2) return 0;
    void *p = realloc(*array, (need ? need : 1) * size);
    if (!p) return -1;
    *array = p;
    *capacity = need;
    return 0;
}

/* Each element's vertex pairs (CSR over near_vertex, a pair under both of
 * its elements), and every vertex pair due at the first step of the list:
 * last step's shut marks say nothing of pairs the list did not hold. The
 * pairs arrive from near_list_pairs in reverse pair order, each element's
 * count in vertex_start[e + 1] already (only a model with shut marks has
 * vertex pairs, and its rebuild counts them as it lists them), and are
 * turned to pair order as they are indexed, in one pass (an element's
 * pairs are then not in ascending order in vertex_pairs:
 * contact_vertex_due sorts what it takes). Returns 0, or -1 when out of
 * memory. */
static int near_vertex_index(fdem_model *m)
{
    contact_state *cs = &m->contact;
    size_t n = cs->near_vertex_count, E = (size_t)m->elem_count;
    cs->vertex_walk_all = 1;
    if (!n) return 0;
    if (fit_array((void **)&cs->vertex_pairs, &cs->vertex_pairs_capacity, 2 * n,
                  sizeof *cs->vertex_pairs) ||
        fit_array((void **)&cs->vertex_walk, &cs->vertex_walk_capacity, n, sizeof *cs->vertex_walk) ||
        fit_array((void **)&cs->vertex_due, &cs->vertex_due_capacity, n, sizeof *cs->vertex_due))
        return -1;
    int32_t *start = cs->vertex_start, *index = cs->vertex_pairs;
    near_pair *v = cs->near_vertex;
    for (size_t e = 0; e < E; e++) start[e + 1] += start[e];
    /* start[e] runs to e's end, then is set back; v[i] and v[n - 1 - i]
     * swap places, each indexed at its new one */
    for (size_t i = 0, j = n - 1; i <= j && j < n; i++, j--) {
        near_pair p = v[i], q = v[j];
        index[start[q.a]++] = (int32_t)i;
        index[start[q.b]++] = (int32_t)i;
        if (i == j) break;
        index[start[p.a]++] = (int32_t)j;
        index[start[p.b]++] = (int32_t)j;
        v[i] = q;
        v[j] = p;
    }
    for (size_t e = E; e > 0; e--) start[e] = start[e - 1];
    start[0] = 0;
    memset(cs->vertex_due, 0, n);
    return 0;
}

/* This step's vertex pairs to walk, in pair order (vertex_walk): every one
 * the step after a rebuild or while shut marks are off; else those of an
 * element not shut now or last step (elem_due). A pair of two elements
 * shut now and last step is left out by the walk now and was last step,
 * which let its springs go: walking it would do nothing. */
void contact_vertex_due(fdem_model *m)
{
    contact_state *cs = &m->contact;
    size_t n = cs->near_vertex_count, listed = 0;
    if (!n) {
        cs->vertex_walk_count = 0;
        return;
    }
    if (cs->vertex_walk_all || !cs->shut_any || cs->vertex_skip_off) {
        for (size_t i = 0; i < n; i++) cs->vertex_walk[i] = (int32_t)i;
        cs->vertex_walk_count = n;
        cs->vertex_walk_all = 0;
        return;
    }
    uint8_t *due = cs->vertex_due;
    for (int k = 0; k < cs->elem_due_count; k++) {
        int e = cs->elem_due[k];
        for (int32_t j = cs->vertex_start[e]; j < cs->vertex_start[e + 1]; j++)
            due[cs->vertex_pairs[j]] = 1;
    }
    /* a few elements due: their pairs, sorted; many: one pass over the marks */
    if ((size_t)cs->elem_due_count * 64 < n) {
        for (int k = 0; k < cs->elem_due_count; k++) {
            int e = cs->elem_due[k];
            for (int32_t j = cs->vertex_start[e]; j < cs->vertex_start[e + 1]; j++) {
                int32_t i = cs->vertex_pairs[j];
                if (due[i]) {
                    due[i] = 0;
                    cs->vertex_walk[listed++] = i;
                }
            }
        }
        sort_indices(cs->vertex_walk, listed);
    } else {
        for (size_t i = 0; i < n; i++)
            if (due[i]) {
                due[i] = 0;
                cs->vertex_walk[listed++] = (int32_t)i;
            }
    }
    cs->vertex_walk_count = listed;
}

/* The widest gap between two boxes along an axis (negative: they overlap
 * on every axis); D a constant where it is called (the rebuild's loop,
 * unrolled). */
static inline __attribute__((always_inline)) double boxes_gap_of(const double *a, const double *b,
                                                                  const int D)
{
    double gap = max2(b[0] - a[1], a[0] - b[1]);
    for (int d = 1; d < D; d++) gap = max2(gap, max2(b[2 * d] - a[2 * d + 1], a[2 * d] - b[2 * d + 1]));
    return gap;
}

/* The rebuild's pass over the candidate pairs: each within reach listed
 * with its gap and topology, the others' springs let go (apart now and
 * until the next rebuild). D and K are constants where it is called, so
 * the boxes' gap and the shared-vertex count are unrolled. Each vertex
 * pair is counted under both its elements (vertex_count[e + 1], zeroed:
 * near_vertex_index), and with in_pair each listed pair's elements are
 * marked (contact_collect_elements' marks, without a pass over the list).
 * Returns 0, or -1 when out of memory; *count and *vertex the pairs
 * listed. */
static inline __attribute__((always_inline)) int
near_list_pairs(fdem_model *m, double limit, uint8_t *in_pair, int32_t *vertex_count,
                size_t *count_out, size_t *vertex_out, const int D, const int K)
{
    contact_state *cs = &m->contact;
    const size_t width = 2 * (size_t)D, n = cs->pairs.count;
    const int32_t *pa = cs->pairs.a, *pb = cs->pairs.b, *spring_of = cs->spring_of;
    const double *box = cs->box;
    /* topology only where some joint is broken (without one, every pair
     * is "nothing") */
    const int32_t *elem_first = cs->elem_shut && m->broken_joints ? cs->elem_first : NULL;
    uint8_t *topo = cs->elem_topo;
    double *elem_gap = cs->elem_gap;
    size_t count = 0, vertex = 0;
    for (size_t k = 0; k < n; k++) {
        int32_t ea = pa[k], eb = pb[k];
        double gap = boxes_gap_of(box + width * (size_t)ea, box + width * (size_t)eb, D);
        if (gap > limit) {
            if (spring_of[k] >= 0) contact_springs_release(cs, k);
            continue;
        }
        uint16_t face = 0;
        uint8_t topology =
            elem_first ? (uint8_t)contact_shut_topology(m, elem_first, ea, eb, &face, D, K) : 0;
        near_pair np = {gap, (uint32_t)k, ea, eb, (uint8_t)(spring_of[k] >= 0), topology, face};
        /* one array, the vertex pairs filling it from the end (two lists
         * would each keep their own doubling's room); it grows as it
         * fills: it holds a tenth or so of the candidates */
        if (count + vertex == cs->near_capacity && near_grow(cs, vertex)) return -1;
        if (topology == SHUT_TOPO_VERTEX) {
            cs->near[cs->near_capacity - ++vertex] = np;
            vertex_count[ea + 1]++;
            vertex_count[eb + 1]++;
        } else {
            cs->near[count++] = np;
        }
        if (in_pair) in_pair[ea] = in_pair[eb] = 1;
        if (topology) { /* its boxes by the marks (contact_near_boxes) */
            topo[ea] = topo[eb] = TOPO_LISTED;
            continue;
        }
        elem_gap[ea] = min2(elem_gap[ea], gap);
        elem_gap[eb] = min2(elem_gap[eb], gap);
    }
    *count_out = count;
    *vertex_out = vertex;
    return 0;
}

/* The near list (see the top of this file) and its elements from this
 * step's boxes. Returns 0, or -1 when out of memory (or past 2^32
 * candidate pairs, which near_pair cannot name: 32 GB of pair lists). */
static int contact_near_rebuild(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (cs->pairs.count > UINT32_MAX) return -1;
    double reach = cs->kernel->near_step * cs->buffer;
    /* a hair over 2 reach, so rounding in the gap never leaves out a pair
     * that could touch */
    double limit = 2.0 * reach * (1 + 1e-9);
    int dim = m->dim;
    size_t count = 0, vertex = 0, E = (size_t)m->elem_count;
    for (size_t e = 0; e < E; e++) cs->elem_gap[e] = INFINITY;
    if (cs->elem_topo) memset(cs->elem_topo, 0, E);
    /* the vertex pairs' counts (only broken rock has any) */
    if (cs->elem_topo && !cs->vertex_start &&
        !(cs->vertex_start = malloc(sizeof(int32_t) * (E + 1))))
        return -1;
    int32_t *vertex_count = cs->elem_topo ? cs->vertex_start : NULL;
    if (vertex_count) memset(vertex_count, 0, sizeof(int32_t) * (E + 1));
    /* one process takes the whole list: its elements marked as listed */
    uint8_t *in_pair = m->share ? NULL : cs->in_pair;
    if (in_pair) memset(in_pair, 0, E);
    if (dim == 3 ? near_list_pairs(m, limit, in_pair, vertex_count, &count, &vertex, 3, 4)
                 : near_list_pairs(m, limit, in_pair, vertex_count, &count, &vertex, 2, 3))
        return -1;
    memcpy(cs->pos_near, m->pos, sizeof(double) * (size_t)dim * (size_t)m->node_count);
    cs->near_disp2 = 0;
    /* the vertex pairs, from the end in reverse (near_vertex_index turns
     * them to pair order) */
    cs->near_vertex = cs->near + (cs->near_capacity - vertex);
    cs->near_count = count;
    cs->near_vertex_count = vertex;
    cs->near_reach = reach;
    cs->near_apart = 0;
    cs->near_stale = 0;
    cs->gaps_raised = 0;
    cs->near_dead = 0;
    cs->near_builds++;
    /* A process of a split walk (contact_walk.c) reads the boxes of its
     * shares' pairs only, until the next rebuild (which computes every
     * candidate's first): it keeps only those up to date. */
    if (near_vertex_index(m)) return -1;
    if (in_pair) {
        cs->near_active_count = contact_listed_elements(cs, m->elem_count, cs->near_active);
        return 0;
    }
    size_t lo, hi, vlo, vhi;
    contact_share(m->share, count, &lo, &hi);
    contact_share(m->share, vertex, &vlo, &vhi);
    cs->near_active_count = contact_collect_elements(cs, m->elem_count, cs->near + lo, hi - lo,
                                                     cs->near_vertex + vlo, vhi - vlo,
                                                     cs->near_active);
    return 0;
}

/* This step's boxes of the elements the near list needs, the list rebuilt
 * first when due (from the boxes of every candidate pair's elements).
 * Returns 0, or -1 when out of memory. */
int contact_near_refresh(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (cs->pairs.count == 0) { /* nothing to walk: the next pairs come with a detection */
        cs->near_count = cs->near_vertex_count = 0;
        return 0;
    }
    if (!contact_near_due(m)) {
        contact_near_boxes(m);
        return 0;
    }
    /* new shares of a split walk: each process's springs handed over first */
    if (contact_springs_sync(m)) return -1;
    contact_boxes(m, cs->active, cs->active_count);
    return contact_near_rebuild(m);
}

