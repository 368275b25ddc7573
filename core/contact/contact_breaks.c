/*
 * contact_breaks.c - the candidate list after joints break, without a whole
 * detection, and the one order every list of a jointed model is kept in.
 *
 * Why: a break must let the freed faces meet through contact in the step
 * it happens, and it did so by rerunning the whole detection: tunnel-region
 * ran 479-486 detections per 1,000 steps once its wall broke, 46-63 % of
 * its CPU (issue 34). A break changes little: the circles are those of the
 * last detection (pos_detect; its list holds every pair that can touch
 * until a node passes its allowance, whatever the joints), and what a
 * joint's state decides of a pair (contact.c contact_drop_joined,
 * joint_contact_bodies) changes only for the pairs with an element that
 *  - holds a face of a joint broken since (joint_broken_between, the fan),
 *  - has a vertex whose mark changed (vertex_broken: 0, 1 or 2; the fan,
 *    element_on_crack), or
 *  - lies in a piece that split (piece equality; a piece's id as the body).
 * Of a piece that split, only the parts other than its largest are marked:
 * a pair inside one part keeps its fate. Every other pair keeps its fate:
 * the pieces it lies in are the same sets under new labels, and nothing
 * else it is judged by moved. An element's detection body may change
 * without a mark (a face of its own piece split off), but a body only
 * skips pairs the joint test would drop (joint_contact_bodies), so what
 * is kept is decided by the joint test alone. So the list
 * after the break is the old one without the marked elements' pairs, with
 * the marked elements' pairs found again on the old circles (one NBS run
 * in which only pairs with a marked element are listed: the rest share
 * one body id) and judged under the new joints. Marking more than that
 * costs time, never a pair; past a quarter of the elements (a split of
 * a large piece, a cut across the body) the whole detection runs, on the same
 * circles.
 *
 * The list must be the one a whole detection on those circles gives, in
 * the same order, since a restore runs one (contact_restore_detection):
 * so every jointed model's list is kept as (lo, hi) pairs in the order of
 * lo then hi (contact_pairs_order), which any two ways of finding the same
 * set agree on. tests/unit/test_contact_breaks.c runs both ways side by
 * side and compares the lists and the bits at every step.
 */
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "contact.h"
#include "contact_internal.h"
#include "joint/joint.h"

/* A whole detection runs instead once more elements than this share are
 * marked: the one-body run then costs about as much. */
#define BREAKS_MARKED_SHARE 4

/* The spare list becomes the list; the old one is let go (a list of a
 * fracturing body holds its raw detection's capacity, which is not kept
 * twice between detections). */
static void pairs_take_spare(contact_state *cs)
{
    nbs_pairs old = cs->pairs;
    cs->pairs = cs->spare;
    nbs_pairs_free(&old);
    nbs_pairs_init(&cs->spare);
}

/* `in` as (lo, hi) pairs into `out`, in the order of lo then hi: a
 * counting sort on lo (start: E + 1 counts), each lo's few pairs then put
 * in order of hi. */
static int pairs_sorted(const nbs_pairs *in, nbs_pairs *out, int32_t *start, size_t E)
{
    const size_t n = in->count;
    if (nbs_pairs_reserve(out, n ? n : 1)) return -1; /* a list is never NULL */
    memset(start, 0, sizeof(int32_t) * (E + 1));
    for (size_t k = 0; k < n; k++) {
        int32_t a = in->a[k], b = in->b[k];
        start[(a < b ? a : b) + 1]++;
    }
    for (size_t e = 0; e < E; e++) start[e + 1] += start[e];
    for (size_t k = 0; k < n; k++) {
        int32_t a = in->a[k], b = in->b[k];
        int32_t lo = a < b ? a : b, hi = a < b ? b : a;
        int32_t at = start[lo]++;
        out->a[at] = lo;
        out->b[at] = hi;
    }
    /* start[e] is now the end of e's run, the start of e + 1's */
    int32_t *hi = out->b;
    for (size_t e = 0, from = 0; e < E; from = (size_t)start[e++])
        for (size_t i = from + 1; i < (size_t)start[e]; i++) {
            int32_t v = hi[i];
            size_t j = i;
            for (; j > from && hi[j - 1] > v; j--) hi[j] = hi[j - 1];
            hi[j] = v;
        }
    out->count = n;
    return 0;
}

int contact_pairs_order(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (pairs_sorted(&cs->pairs, &cs->spare, cs->break_scratch, (size_t)m->elem_count)) return -1;
    pairs_take_spare(cs);
    return 0;
}

/* What the detection that built the list saw of the joints: which were
 * broken and each vertex's mark (cs->piece holds its pieces). */
void contact_breaks_remember(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (!cs->seen_joint) return;
    for (int j = 0; j < m->joint_count; j++) cs->seen_joint[j] = m->joint_damage[j] >= 1.0;
    memcpy(cs->seen_vertex, m->vertex_broken, (size_t)m->node_count);
}

/* Split pieces (cs->piece before, cs->piece_next after): a pair within
 * one old piece changes only if its elements now lie in two of its parts,
 * one of which is then not the largest part. So the elements of every part
 * but the largest are marked: a fragment coming off the bulk
 * marks the fragment, not the bulk. first[old label] reads -1 (not seen),
 * the first new label met (no split so far), -2 (split), or -3 - the
 * largest part's label; count[new label] its elements. */
static void breaks_mark_splits(fdem_model *m, uint8_t *marked)
{
    contact_state *cs = &m->contact;
    const int E = m->elem_count;
    const int32_t *old = cs->piece, *now = cs->piece_next;
    int32_t *first = cs->break_scratch, *count = cs->query_body;
    int splits = 0;
    for (int e = 0; e < E; e++) first[e] = -1;
    for (int e = 0; e < E; e++) {
        int32_t *f = &first[old[e]];
        if (*f == -1) *f = now[e];
        else if (*f >= 0 && *f != now[e]) *f = -2, splits = 1;
    }
    if (!splits) return;
    for (int e = 0; e < E; e++) count[e] = 0;
    for (int e = 0; e < E; e++)
        if (first[old[e]] <= -2) count[now[e]]++;
    for (int e = 0; e < E; e++) {
        int32_t *f = &first[old[e]];
        if (*f == -2 || (*f <= -3 && count[now[e]] > count[-3 - *f])) *f = -3 - now[e];
    }
    for (int e = 0; e < E; e++)
        if (first[old[e]] <= -3 && now[e] != -3 - first[old[e]]) marked[e] = 1;
}

/* Marks (cs->marked) the elements whose pairs a break may have changed
 * (the top of this file), the new pieces in cs->piece_next. Returns how
 * many. */
static int breaks_mark(fdem_model *m)
{
    contact_state *cs = &m->contact;
    const int E = m->elem_count, K = m->elem_nodes;
    uint8_t *marked = cs->marked;
    memset(marked, 0, (size_t)E);
    for (int j = 0; j < m->joint_count; j++) {
        uint8_t broken = m->joint_damage[j] >= 1.0;
        if (broken == cs->seen_joint[j]) continue;
        marked[m->joint_elem[2 * j]] = marked[m->joint_elem[2 * j + 1]] = 1;
    }
    contact_mark_cracks(m, cs->piece_next);
    breaks_mark_splits(m, marked);
    int count = 0;
    for (int e = 0; e < E; e++) {
        const int32_t *n = m->elem_node + (size_t)K * (size_t)e;
        int mark = marked[e];
        for (int c = 0; c < K && !mark; c++) {
            int32_t v = m->node_origin[n[c]];
            mark = m->vertex_broken[v] != cs->seen_vertex[v];
        }
        marked[e] = (uint8_t)(mark != 0);
        count += mark != 0;
    }
    return count;
}

/* The marked elements' pairs on the last detection's circles, judged under
 * the joints now (the tests of contact_detect_at: bodies, excavation,
 * joined), as (lo, hi) in order, into cs->fresh. */
static int breaks_find(fdem_model *m)
{
    contact_state *cs = &m->contact;
    const int E = m->elem_count;
    int32_t *query = cs->query_body;
    for (int e = 0; e < E; e++) query[e] = cs->marked[e] ? -1 : 0; /* -1 never skips */
    size_t n = (size_t)E;
    int failed = m->dim == 3 ? nbs_detect_classes_3d(&cs->classes, &cs->grid3, n, cs->cx, cs->cy,
                                                     cs->cz, cs->r, query, &cs->fresh)
                             : nbs_detect_classes(&cs->classes, &cs->grid, n, cs->cx, cs->cy,
                                                  cs->r, query, &cs->fresh);
    if (failed) return -1;
    joint_contact_bodies(m, cs->piece_next, cs->body, cs->detect_body);
    const int32_t *body = cs->detect_body;
    size_t kept = 0;
    for (size_t k = 0; k < cs->fresh.count; k++) {
        int32_t a = cs->fresh.a[k], b = cs->fresh.b[k];
        if (body[a] >= 0 && body[a] == body[b]) continue;
        if (m->elem_active && (!m->elem_active[a] || !m->elem_active[b])) continue;
        if (contact_pair_joined(m, cs->piece_next, a, b)) continue;
        cs->fresh.a[kept] = a;
        cs->fresh.b[kept] = b;
        kept++;
    }
    cs->fresh.count = kept;
    /* in order through the spare list, which the merge then fills */
    if (pairs_sorted(&cs->fresh, &cs->spare, cs->break_scratch, (size_t)E)) return -1;
    nbs_pairs t = cs->fresh;
    cs->fresh = cs->spare;
    cs->spare = t;
    return 0;
}

/* The old list without the marked elements' pairs, merged with fresh. */
static int breaks_merge(fdem_model *m)
{
    contact_state *cs = &m->contact;
    const uint8_t *marked = cs->marked;
    if (nbs_pairs_reserve(&cs->spare, cs->pairs.count + cs->fresh.count + 1)) return -1;
    size_t i = 0, f = 0, out = 0;
    const nbs_pairs *old = &cs->pairs, *fresh = &cs->fresh;
    for (;;) {
        while (i < old->count && (marked[old->a[i]] || marked[old->b[i]])) i++;
        int take_old;
        if (i < old->count && f < fresh->count)
            take_old = old->a[i] < fresh->a[f] || (old->a[i] == fresh->a[f] && old->b[i] < fresh->b[f]);
        else if (i < old->count) take_old = 1;
        else if (f < fresh->count) take_old = 0;
        else break;
        cs->spare.a[out] = take_old ? old->a[i] : fresh->a[f];
        cs->spare.b[out] = take_old ? old->b[i] : fresh->b[f];
        out++;
        if (take_old) i++;
        else f++;
    }
    cs->spare.count = out;
    pairs_take_spare(cs);
    return 0;
}

int contact_detect_breaks(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (contact_springs_sync(m)) return -1; /* set aside below, or by a detection */
    int marked = breaks_mark(m);
    if (cs->breaks_off || marked > m->elem_count / BREAKS_MARKED_SHARE)
        return contact_detect_again(m);
    if (marked) {
        if (contact_history_set_aside(cs) || breaks_find(m) || breaks_merge(m) ||
            contact_history_take_back(cs))
            return -1;
        cs->active_count = contact_collect_elements(cs, m->elem_count, NULL, cs->pairs.count,
                                                    NULL, 0, cs->active);
        cs->near_stale = 1;
    }
    int32_t *t = cs->piece; /* the pieces now are the list's */
    cs->piece = cs->piece_next;
    cs->piece_next = t;
    contact_breaks_remember(m);
    cs->need_detect = 0;
    cs->detections++;
    cs->break_mends++;
    return 0;
}

int contact_breaks_init(fdem_model *m)
{
    contact_state *cs = &m->contact;
    size_t E = (size_t)m->elem_count, J = (size_t)m->joint_count, N = (size_t)m->node_count;
    if (!J) return 0; /* no break, and the list stays in detection's order */
    cs->breaks_bytes = (3 * E + 1) * sizeof(int32_t) + E + J + N;
    cs->break_scratch = malloc(sizeof(int32_t) * (E + 1));
    cs->piece_next = malloc(sizeof(int32_t) * E);
    cs->query_body = malloc(sizeof(int32_t) * E);
    cs->marked = malloc(E);
    cs->seen_joint = calloc((size_t)m->joint_count, 1);
    cs->seen_vertex = calloc((size_t)m->node_count, 1);
    return cs->break_scratch && cs->piece_next && cs->query_body && cs->marked &&
                   cs->seen_joint && cs->seen_vertex
               ? 0
               : -1;
}

void contact_breaks_free(contact_state *cs)
{
    free(cs->break_scratch);
    free(cs->piece_next);
    free(cs->query_body);
    free(cs->marked);
    free(cs->seen_joint);
    free(cs->seen_vertex);
    nbs_pairs_free(&cs->fresh);
    nbs_pairs_free(&cs->spare);
}
