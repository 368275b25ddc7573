/*
 * contact_walk.c - the contact stage's per-step pair walk (both
 * dimensions): each near pair (contact_near.c) whose boxes overlap goes to
 * its dimension's kernel, its forces are added to the contact force array
 * and its stick springs kept, adopted or let go, in pair order, on one
 * thread or several. It is kept apart from detection (contact.c) because it
 * is the stage's hot loop and the part that is shared out: each thread
 * takes a contiguous share of the pairs and lists the ones that touched
 * with their forces and what they ask of the spring pool, and the lists
 * are applied in thread order, which is pair order: every node's sum is
 * formed in the order the serial loop forms it, the same bits on any
 * thread count. Split between processes (step_share.contact_ranks), each
 * takes a fixed share and every process applies every process's lists:
 * contact_walk_split.c.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "kernel/contact_face.h"
#include "kernel/contact_pair.h"
#include "model/model.h"
#include "parallel/team.h"
#include "math/clock.h"
#include "contact.h"
#include "contact_internal.h"
#include "contact_rows.h"
#include "contact_walk.h"

/* Fewer candidate pairs than this are evaluated on one thread: below it the
 * threads' start-up costs more than they share. */
#define CONTACT_THREADED_PAIRS 2048

/* What a pair's evaluation asks of the spring pool (contact_history.c):
 * done at once on one thread, after the threads in pair order otherwise
 * (the pool is shared; each pair's own set is not). */
enum { SPRINGS_KEPT, SPRINGS_RELEASE, SPRINGS_ADOPT };

/* A pair's stick springs: its set in the pool (*set >= 0), else `fresh`,
 * zeroed. Both kernels of the walk read and write them the same way. */
static inline __attribute__((always_inline)) double *pair_springs(contact_state *cs,
                                                                  const near_pair *np,
                                                                  double *fresh, int slots,
                                                                  int32_t *set)
{
    *set = cs->spring_of[np->pair];
    if (*set >= 0) return cs->slip + (size_t)slots * (size_t)*set;
    contact_zero(fresh, (size_t)slots);
    return fresh;
}

/* After either kernel: a pair that did not touch has let every spring go
 * (contact_pair.h), so the springs are read only after a touch; a set
 * left holding nothing goes back to the pool, fresh springs holding a
 * force are adopted. Returns `touched`. */
static inline __attribute__((always_inline)) int pair_springs_held(near_pair *np, int32_t set,
                                                                   int any, int touched, int *pool)
{
    if (set >= 0 && !any) *pool = SPRINGS_RELEASE;
    if (set < 0 && any) *pool = SPRINGS_ADOPT;
    np->sprung = any;
    return touched;
}

static inline __attribute__((always_inline)) int pair_springs_settle(near_pair *np, int32_t set,
                                                                     const double *springs,
                                                                     int touched, int slots,
                                                                     int *pool)
{
    int any = 0;
    if (touched > 0)
        for (int s = 0; s < slots; s++) any |= springs[s] != 0;
    return pair_springs_held(np, set, any, touched, pool);
}

/* A pair found apart by clearance c (0: none) raised to the gap c -
 * near_apart (pair_evaluate says why that keeps the bits). */
static inline void pair_gap_raise(contact_state *cs, near_pair *np, double c)
{
    if (!(c > 0) || cs->clearance_off || !(c - cs->near_apart > np->gap)) return;
    np->gap = c - cs->near_apart;
    /* its elements' elem_gap may be lower than any of their pairs' gaps
     * now: found again before the next boxes (contact_near.c) */
#pragma omp atomic write
    cs->gaps_raised = 1;
    if (np->gap > contact_near_dead(cs)) {
#pragma omp atomic update
        cs->near_dead++;
    }
}

/* Broken rock: a pair across a crack whose boxes are a hair apart when the
 * list is built (1e-12 m in a block broken in place: corners of a mesh
 * square) keeps that box gap, is turned away by the box test every step,
 * and so stays in the near list and keeps both its elements computing
 * their boxes, where its kernel would find the two elements apart by
 * their size. Once its boxes have turned it away often enough
 * (pair_turned_away), it asks its kernel, once a list, for the clearance
 * of a face plane alone (no forces: the pair is apart this step as
 * before, springs and all), and a clearance skips it only where its
 * kernel would find it apart, the same bits. The whole kernel was
 * measured first: in 3D it cost more than the boxes it saved (broken 3D
 * block at 1e4, 96 steps from a restore: 968 -> 1036 ns an element-step),
 * where clipping a pair no face plane separates came first. */
static void pair_clearance_look(fdem_model *m, near_pair *np, contact_pair_memo *memo)
{
    contact_state *cs = &m->contact;
    contact_pair_in in = contact_pair_input(m, np->a, np->b, 0, memo);
    pair_gap_raise(cs, np, cs->kernel->pair_clearance(&in));
}

/* How often the pair's boxes have turned it away since the list was
 * built, or NEAR_TURNED_LOOKED once it has had its one look. */
static inline unsigned pair_turned(const near_pair *np)
{
    return (np->face & NEAR_TURNED_MASK) >> NEAR_TURNED_SHIFT;
}

static inline void pair_mark_looked(near_pair *np)
{
    np->face = (uint16_t)(np->face | NEAR_TURNED_LOOKED << NEAR_TURNED_SHIFT);
}

/* Such a pair turned away by its boxes once more: it looks only once the
 * list has lived long enough to pay for the look, about half the steps it
 * takes (4 in 2D, 14 in 3D). A look costs what 8 steps of boxes save in
 * 2D and 20 in 3D (the broken blocks, harness), and a rock that is
 * breaking rebuilds its list at every break: looked at on the first turn
 * away, the broken 3D block at 1e5 read 1,511 -> 1,589 ns an element-step
 * over the bench's 9 steps from a restore, where 96 steps at 1e4 gained. */
static void pair_turned_away(fdem_model *m, near_pair *np, contact_pair_memo *memo)
{
    const unsigned after = m->dim == 3 ? NEAR_LOOK_AFTER_3D : NEAR_LOOK_AFTER_2D;
    unsigned turned = pair_turned(np);
    if (turned == NEAR_TURNED_LOOKED) return;
    if (turned + 1 < after) {
        np->face = (uint16_t)(np->face + (1u << NEAR_TURNED_SHIFT));
        return;
    }
    /* looked, once: not NEAR_EDGES_TRIED, which the look did not try, so
     * the kernel still looks across edges when the boxes meet */
    pair_mark_looked(np);
    pair_clearance_look(m, np, memo);
}

/* Broken rock: two shut elements that share no vertex and whose boxes
 * meet, met for the first time since the list was built (a rebuild after
 * every detection, break and restore): 1 once a list, and the pair is
 * marked looked (as pair_turned_away marks it). Such a pair is more likely
 * apart than not, so it gets a first look before the whole kernel (the
 * same bits: a clearance c > 0 is what the kernel would find, apart):
 *  - 2D (pair_first_look): an edge line's clearance. Two triangles apart
 *    are always parted by the line of one of their edges, so the look
 *    finds nearly every such pair's clearance (a pair within the rounding
 *    margin takes the kernel after it): the broken block's restore step
 *    went 470 -> 452 ns an element;
 *  - 3D (contact_pair_in.edges_first): the kernel tries the planes across
 *    an edge of each before it clips (contact_tet.c), where the face
 *    planes' look alone read 3,990 -> 4,380, tetrahedra being often apart
 *    only across such a plane: restore step 4,000 -> 3,870 ns an element
 *    at 1e4 tetrahedra, 4,760 -> 4,570 at 1e5. */
static inline int pair_first_met(const contact_state *cs, near_pair *np, int32_t a, int32_t b)
{
    if (!cs->shut_any || cs->first_look_off || np->topology != SHUT_TOPO_NONE ||
        !cs->elem_shut[a] || !cs->elem_shut[b] || pair_turned(np) == NEAR_TURNED_LOOKED)
        return 0;
    pair_mark_looked(np);
    return 1;
}

/* The 2D first look: 1 if an edge line's clearance found the pair apart
 * (its gap raised by it). */
static int pair_first_look(fdem_model *m, near_pair *np, contact_pair_memo *memo)
{
    contact_state *cs = &m->contact;
    contact_pair_in in = contact_pair_input(m, np->a, np->b, 0, memo);
    double c = cs->kernel->pair_clearance(&in);
    pair_gap_raise(cs, np, c);
    if (c > 0) {
#pragma omp atomic update
        cs->first_looks++;
    }
    return c > 0;
}

/* Near pair np this step: boxes apart, it lets its springs go (-1);
 * otherwise its force into out (pair_out numbers), 1 if it touched. A pair
 * without a set of springs is evaluated on fresh (zeros); *pool says
 * whether fresh is to be adopted or the pair's set let go (np->sprung
 * says so at once). D is a constant where it is called, so each
 * dimension's walk is compiled on its own with the box and spring loops
 * unrolled. */
static inline __attribute__((always_inline)) int pair_evaluate(fdem_model *m, near_pair *np,
                                                               double h, double *out,
                                                               double *fresh, int *pool,
                                                               contact_pair_memo *memo, int D)
{
    contact_state *cs = &m->contact;
    const int slots = D == 3 ? TET_CONTACT_SLOTS : TRI_CONTACT_SLOTS;
    const size_t width = 2 * (size_t)D;
    int32_t a = np->a, b = np->b;
    *pool = SPRINGS_KEPT;
    /* shut broken rock first: its kernel ignores the gap the general one
     * found (a clearance says what the general kernel would do) */
    if (cs->shut_any && np->topology && cs->elem_shut[a] && cs->elem_shut[b]) {
        if (np->topology == SHUT_TOPO_VERTEX) { /* left out: as a pair apart */
            if (np->sprung) {
                *pool = SPRINGS_RELEASE;
                np->sprung = 0;
            }
            return -1;
        }
        /* the two sides of a shut broken joint */
        int32_t set;
        double *springs = pair_springs(cs, np, fresh, slots, &set);
        face_match fm = shut_face_unpack(np->face);
        contact_pair_in in = contact_pair_input(m, a, b, h, memo);
        int touched = D == 3 ? tet_face_pair_force(&in, &fm, springs, out)
                             : tri_face_pair_force(&in, &fm, springs, out);
        /* the face kernel keeps only the two faces' slots (contact_face.h:
         * per face 1 in 2D, 3 in 3D) */
        const int per = slots / (2 * (D + 1));
        int any = 0;
        if (touched > 0)
            for (int k = 0; k < per; k++)
                any |= (springs[per * fm.face_a + k] != 0) |
                       (springs[slots / 2 + per * fm.face_b + k] != 0);
        return pair_springs_held(np, set, any, touched, pool);
    }
    /* a gap over near_apart: apart, boxes not even computed this step */
    int apart = np->gap > cs->near_apart;
    if (!apart && !boxes_overlap(cs->box + width * (size_t)a, cs->box + width * (size_t)b, D)) {
        apart = 1;
        if (cs->elem_topo && cs->elem_topo[a] && cs->elem_topo[b]) pair_turned_away(m, np, memo);
    }
    const int first_met = !apart && pair_first_met(cs, np, a, b);
    if (D == 2 && first_met) apart = pair_first_look(m, np, memo);
    if (apart) {
        if (np->sprung) {
            *pool = SPRINGS_RELEASE;
            np->sprung = 0;
        }
        return -1;
    }
    int32_t set;
    double *springs = pair_springs(cs, np, fresh, slots, &set);
    contact_pair_in in = contact_pair_input(m, a, b, h, memo);
    in.edge_clearance = !(np->face & NEAR_EDGES_TRIED);
    if (D == 3 && first_met) { /* the 3D first look (pair_first_met) */
        in.edges_first = in.edge_clearance;
#pragma omp atomic update
        cs->first_looks++;
    }
    int touched = cs->kernel->pair_force(&in, springs, out);
    if (!touched) np->face |= NEAR_EDGES_TRIED;
    /* Apart with a clearance c (contact_pair.h): the kernel keeps returning
     * 0, every spring let go, while the two elements' nodes travel less
     * than c together. Each node is within sqrt(near_disp2) of its place at
     * the list's build, now and later, so between now and a later step it
     * moves less than the two figures' sum, and a node of either element
     * less than near_apart / 2 now plus near_apart / 2 then (near_apart is
     * twice the figure, a hair over). As the gap c - near_apart_now the
     * pair then passes the walk's test above (gap > near_apart) exactly
     * while c > near_apart_now + near_apart_then: skipped only where the
     * kernel would have found what it found now, the same bits. The list's
     * rebuild (and a restore, which rebuilds it) starts from box gaps. */
    if (!touched) pair_gap_raise(cs, np, out[0]);
    return pair_springs_settle(np, set, springs, touched, slots, pool);
}

/* The pairs a walk needs to take threads. */
static inline long walk_threads_least(const contact_state *cs)
{
    return cs->walk_threads_min > 0 ? cs->walk_threads_min : CONTACT_THREADED_PAIRS;
}

/* One list per thread, its touched rows with room for the two elements'
 * nodes; 0, or -1 if they cannot be had. */
static int contact_touch_lists(fdem_model *m, int threads)
{
    contact_state *cs = &m->contact;
    if (threads <= cs->touch_lists) return 0;
    contact_touches *t = realloc(cs->touches, sizeof *t * (size_t)threads);
    if (!t) return -1;
    memset(t + cs->touch_lists, 0, sizeof *t * (size_t)(threads - cs->touch_lists));
    for (int k = cs->touch_lists; k < threads; k++) t[k].touched.node_width = 2 * m->elem_nodes;
    cs->touches = t;
    cs->touch_lists = threads;
    return 0;
}

/* The walk's indirect loads asked for ahead of the pair that needs them:
 * the pool index of pair i + 2 WALK_AHEAD (spring_of, one int in a
 * candidate array of ~100 an element in broken 3D rock, so a cache miss a
 * near pair: a quarter of that walk's own samples), and for pair
 * i + WALK_AHEAD, whose index is in cache by then, its springs' row.
 * 3D only: a broken 2D block's candidates are ~9 an element, its indices
 * close together, and there the prefetches cost more than they saved
 * (harness, 49 steps at 1e5 triangles: 188-190 -> 192 ns an element-step,
 * where the broken 3D block at 1e4 went 822-865 -> 808-850). */
#define WALK_AHEAD 4
static inline void walk_prefetch(const contact_state *cs, const near_walk *w, size_t i, size_t end,
                                 int slots)
{
    if (i + 2 * WALK_AHEAD < end) __builtin_prefetch(&cs->spring_of[walk_pair(w, i + 2 * WALK_AHEAD)->pair]);
    if (i + WALK_AHEAD < end) {
        int32_t set = cs->spring_of[walk_pair(w, i + WALK_AHEAD)->pair];
        if (set >= 0) __builtin_prefetch(cs->slip + (size_t)slots * (size_t)set);
    }
}

/* Past this many bytes of element records and node places and velocities,
 * the walk asks for each pair's second element ahead (below). */
#define WALK_FAR_BYTES (8u << 20)

/* Whether the elements a walk reads are far: more of them than a core's
 * caches keep between one step and the next. */
static inline int walk_elements_far(const fdem_model *m)
{
    const size_t D = (size_t)m->dim, record = D == 3 ? sizeof m->tet[0] : sizeof m->elem[0];
    return (size_t)m->elem_count * record + (size_t)m->node_count * 2 * D * sizeof(double) >
           WALK_FAR_BYTES;
}

/* The pair WALK_AHEAD * 3 on: its second element's record; and two
 * WALK_AHEAD on, if it is the two sides of a broken joint (the pairs whose
 * kernel runs every step), that element's node places and velocities. The
 * near list runs in the first element's order, so the first's come in
 * order and the memory system streams them; the second is a neighbour up
 * to a row of the mesh ahead, a cache miss a pair when the model is large:
 * waiting for its material was a quarter of the broken 2D block's walk at
 * 1e5 triangles. Measured (harness, alternating rounds, broken blocks from
 * the break): 2D 1e5 triangles 189-193 -> 186-189 ns an element-step, 3D
 * 1e5 tetrahedra 778-799 -> 757-765; at 1e4 (the elements near in cache)
 * the prefetches cost 1-2 % and saved no miss, hence only for far
 * elements. The nodes only for joints' sides: reading the node ids of
 * every pair's record, most of them skipped by their gap, stalled the 3D
 * walk on records not yet in (restore step at 1e5 tetrahedra 4,540 ->
 * 4,400 ns an element without it). Same bits: a prefetch changes no
 * value. */
static inline void walk_prefetch_elements(const fdem_model *m, const near_walk *w, size_t i,
                                          size_t end, int D)
{
    if (i + 3 * WALK_AHEAD < end) {
        int b = walk_pair(w, i + 3 * WALK_AHEAD)->b;
        __builtin_prefetch(D == 3 ? (const void *)&m->tet[b] : (const void *)&m->elem[b]);
    }
    if (i + 2 * WALK_AHEAD >= end) return;
    const near_pair *np = walk_pair(w, i + 2 * WALK_AHEAD);
    if (np->topology != SHUT_TOPO_FACE) return;
    const int32_t *n = element_nodes(m, np->b);
    __builtin_prefetch(m->pos + D * (size_t)n[0]);
    __builtin_prefetch(m->vel + D * (size_t)n[0]);
    if (D == 3) { /* four private corners span two lines */
        __builtin_prefetch(m->pos + D * (size_t)n[3]);
        __builtin_prefetch(m->vel + D * (size_t)n[3]);
    }
}

/* Every pair of a walk's force, added to the contact force array in its
 * order, one pair at a time. Returns the number of pairs that touched. */
static inline __attribute__((always_inline)) int pairs_forces_serial(fdem_model *m, double h,
                                                                     const near_walk *w, int D)
{
    contact_state *cs = &m->contact;
    contact_pair_memo memo;
    contact_pair_memo_clear(&memo);
    const int far = walk_elements_far(m);
    int touching = 0;
    for (size_t i = 0; i < w->count; i++) {
        if (D == 3) walk_prefetch(cs, w, i, w->count, cs->slots);
        if (far) walk_prefetch_elements(m, w, i, w->count, D);
        near_pair *np = walk_pair(w, i);
        double out[CONTACT_PAIR_OUT_MAX], fresh[CONTACT_SLOTS_MAX];
        int pool, touched = pair_evaluate(m, np, h, out, fresh, &pool, &memo, D);
        if (pool == SPRINGS_RELEASE) contact_springs_release(cs, np->pair);
        else if (pool == SPRINGS_ADOPT && contact_springs_adopt(cs, np->pair, fresh)) return -1;
        if (touched <= 0) continue;
        contact_pair_scatter(m, np->a, np->b, out);
        touching++;
    }
    return touching;
}

static int contact_pairs_forces_serial(fdem_model *m, double h, const near_walk *w)
{
    return m->dim == 3 ? pairs_forces_serial(m, h, w, 3) : pairs_forces_serial(m, h, w, 2);
}

/* The same on several threads: each takes a contiguous share of the near
 * pairs and lists the ones that touched with their forces; the lists are then
 * added in thread order, which is pair order. Every node's sum is formed in
 * the order the serial loop forms it: the same bits on any thread count.
 * Returns the number of pairs that touched, or -1 if a list could not grow
 * (nothing has been added then). */
static inline __attribute__((always_inline)) int pairs_forces_listed(fdem_model *m, double h,
                                                                     const near_walk *w,
                                                                     long begin, long end,
                                                                     contact_touches *list, int D)
{
    const contact_state *cs = &m->contact;
    contact_pair_memo memo;
    contact_pair_memo_clear(&memo);
    int touching = 0;
    pair_rows *rows = &list->touched;
    const int width = cs->pair_out, K = D + 1, far = walk_elements_far(m);
    for (long i = begin; i < end; i++) {
        if (D == 3) walk_prefetch(cs, w, (size_t)i, (size_t)end, cs->slots);
        if (far) walk_prefetch_elements(m, w, (size_t)i, (size_t)end, D);
        near_pair *np = walk_pair(w, (size_t)i);
        long k = (long)np->pair;
        /* the kernel writes the forces into the list's next row itself,
         * kept if the pair touched: copying them after was 5 % of a
         * broken 2D block's step on two threads */
        if (pair_rows_room(rows, width)) return -1;
        double *force = rows->row + rows->count * (size_t)width, fresh[CONTACT_SLOTS_MAX];
        int pool, touched = pair_evaluate(m, np, h, force, fresh, &pool, &memo, D);
        if (pool == SPRINGS_RELEASE && pair_rows_push(&list->release, k, NULL, 0)) return -1;
        if (pool == SPRINGS_ADOPT && pair_rows_push(&list->adopt, k, fresh, cs->slots)) return -1;
        if (touched <= 0) continue;
        touching++;
        rows->pair[rows->count] = touched_key(np->a, np->b);
        rows->last[rows->count] = force[width - 1];
        int32_t *nodes = rows->nodes + 2 * (size_t)K * rows->count;
        memcpy(nodes, element_nodes(m, np->a), sizeof(int32_t) * (size_t)K);
        memcpy(nodes + K, element_nodes(m, np->b), sizeof(int32_t) * (size_t)K);
        rows->count++;
    }
    return touching;
}

/* Where the threads' shares of walk `which` start this step, as fractions
 * of it (cut[0] = 0 .. cut[threads] = 1): even the first time, then each
 * step from the last one's work (each share's CPU seconds), so that each
 * share holds as much of it as the work was spread over the shares (evenly
 * within each). A sphere pile's costly pairs sit in a few runs of its near
 * list: split by count, one thread had nearly all of them, and 2 threads
 * were no faster than one (kernel calls counted instead of seconds
 * balanced it less: 83 -> 69 ns an element-step on 2 threads, against 65:
 * calls differ in cost, a pair ended by a face plane against one clipped).
 * Which thread walks a pair changes nothing in what it gives (the lists
 * are applied in pair order, every hint a pair keeps is in the pair, and a
 * kernel's memo gives what it would work out again): the same bits however
 * the shares fall, which test_threads checks with shares moved at random.
 * NULL when out of memory. */
static double *walk_cuts(contact_state *cs, int which, int threads)
{
    if (cs->walk_cuts[which] == threads) return cs->walk_cut[which];
    double *cut = realloc(cs->walk_cut[which], sizeof *cut * 2 * (size_t)(threads + 1));
    if (!cut) return NULL;
    for (int t = 0; t <= threads; t++) cut[t] = (double)t / threads;
    cs->walk_cut[which] = cut;
    cs->walk_cuts[which] = threads;
    return cut;
}

/* The next step's cuts from this step's work per share (cut's second half,
 * threads + 1 numbers, is the scratch). */
static void walk_cuts_balance(double *cut, const contact_touches *lists, int threads)
{
    double total = 0, *next = cut + threads + 1;
    for (int t = 0; t < threads; t++) total += lists[t].work;
    if (!(total > 0)) return;
    int s = 0;
    double before = 0; /* the work of the shares before s */
    for (int t = 1; t < threads; t++) {
        double want = total * t / threads;
        while (s < threads - 1 && before + lists[s].work < want) before += lists[s++].work;
        double inside = lists[s].work > 0 ? (want - before) / lists[s].work : 0;
        next[t] = cut[s] + (cut[s + 1] - cut[s]) * (inside < 0 ? 0 : inside > 1 ? 1 : inside);
    }
    for (int t = 1; t < threads; t++) cut[t] = next[t] > cut[t - 1] ? next[t] : cut[t - 1];
}

/* Pairs [begin, end) of walk w listed on this process's threads; *used the
 * lists filled (thread order). 0, or -1 when a list cannot grow. */
int walk_listed(fdem_model *m, double h, const near_walk *w, long begin, long end, int *used)
{
    contact_state *cs = &m->contact;
    long least = walk_threads_least(cs);
    int threads = m->threads > 1 && end - begin >= least ? m->threads : 1;
    if (contact_touch_lists(m, threads)) return -1;
    const int which = w->index != NULL;
    double *cut = threads > 1 ? walk_cuts(cs, which, threads) : NULL;
    if (threads > 1 && !cut) return -1;
    contact_touches *lists = cs->touches;
    int failed = 0, nt_used = 1;
#pragma omp parallel num_threads(threads) if (threads > 1)
    {
        int t, nt;
        parallel_team(&t, &nt);
        if (t == 0) nt_used = nt;
        contact_touches *list = &lists[t];
        list->touched.count = list->adopt.count = list->release.count = 0;
        long n = end - begin, b = begin + n * t / nt, e = begin + n * (t + 1) / nt;
        if (cut && nt == threads) { /* the shares as last step's work spread */
            b = t ? begin + (long)(n * cut[t]) : begin;
            e = t + 1 < nt ? begin + (long)(n * cut[t + 1]) : end;
        }
        double started = clock_cpu_seconds();
        int mine = m->dim == 3 ? pairs_forces_listed(m, h, w, b, e, list, 3)
                               : pairs_forces_listed(m, h, w, b, e, list, 2);
        list->work = clock_cpu_seconds() - started;
        if (mine < 0) {
#pragma omp atomic write
            failed = 1;
        }
    }
    *used = nt_used;
    if (cut && nt_used == threads && !failed) walk_cuts_balance(cut, lists, threads);
    return failed ? -1 : 0;
}

/* A walk of one process on its threads: listed (walk_listed), then the
 * lists applied in thread order, which is pair order. Returns the number
 * of pairs that touched, or -1 if a list could not grow (nothing has been
 * added then). */
static int contact_pairs_forces_threaded(fdem_model *m, double h, const near_walk *w)
{
    contact_state *cs = &m->contact;
    int used, touching = 0;
    if (walk_listed(m, h, w, 0, (long)w->count, &used)) return -1;
    const contact_touches *lists = cs->touches;
    touched_apply(m, lists, used);
    for (int t = 0; t < used; t++) {
        touching += (int)lists[t].touched.count;
        for (size_t i = 0; i < lists[t].release.count; i++)
            contact_springs_release(cs, (size_t)lists[t].release.pair[i]);
        const pair_rows *adopt = &lists[t].adopt;
        for (size_t i = 0; i < adopt->count; i++)
            if (contact_springs_adopt(cs, (size_t)adopt->pair[i], adopt->row + i * (size_t)cs->slots))
                return -1;
    }
    return touching;
}

/* The near list, then this step's vertex pairs (contact_near.c), each in
 * pair order: the same sums in the same order on any thread count. Threads
 * only pay off with enough pairs; without room for their lists a walk
 * stays on one thread. Returns the number of pairs that touched, or -1
 * when out of memory. */
int contact_pairs_forces(fdem_model *m, double h)
{
    contact_state *cs = &m->contact;
    const near_walk walks[2] = {{cs->near, NULL, cs->near_count},
                                {cs->near_vertex, cs->vertex_walk, cs->vertex_walk_count}};
    if (m->share && m->share->contact_ranks > 1) return contact_pairs_forces_split(m, h, walks);
    cs->pairs_walked += (long)(walks[0].count + walks[1].count);
    int touching = 0;
    for (int k = 0; k < 2; k++) {
        int t;
        if (m->threads > 1 && (long)walks[k].count >= walk_threads_least(cs) &&
            contact_touch_lists(m, m->threads) == 0)
            /* a list that cannot grow has already moved some stick springs:
             * the step fails rather than run the pairs twice */
            t = contact_pairs_forces_threaded(m, h, &walks[k]);
        else
            t = contact_pairs_forces_serial(m, h, &walks[k]);
        if (t < 0) return -1;
        touching += t;
    }
    if (cs->near_dead > cs->near_count / 8) contact_near_compact(m);
    return touching;
}


/* What the lists hold (contact_memory_bytes). */
size_t contact_walk_bytes(const contact_state *cs)
{
    size_t b = (size_t)cs->touch_lists * sizeof(contact_touches) + cs->apply_owner_bytes;
    for (int k = 0; k < 2; k++)
        if (cs->walk_cut[k]) b += sizeof(double) * 2 * (size_t)(cs->walk_cuts[k] + 1);
    for (int t = 0; t < cs->touch_lists; t++) {
        b += pair_rows_bytes(&cs->touches[t].touched, cs->pair_out);
        b += pair_rows_bytes(&cs->touches[t].adopt, cs->slots);
        b += pair_rows_bytes(&cs->touches[t].release, 0);
    }
    return b + cs->wire_capacity;
}

void contact_walk_free(contact_state *cs)
{
    free(cs->walk_cut[0]);
    free(cs->walk_cut[1]);
    free(cs->apply_owner);
    for (int t = 0; t < cs->touch_lists; t++) {
        pair_rows_free(&cs->touches[t].touched);
        pair_rows_free(&cs->touches[t].adopt);
        pair_rows_free(&cs->touches[t].release);
    }
    free(cs->touches);
    free(cs->wire);
}
