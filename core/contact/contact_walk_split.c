/*
 * contact_walk_split.c - the contact stage's pair walk split between
 * processes (step_share.contact_ranks > 1: the rank engine, runner/mpi):
 * which pairs this process walks, the wire its lists and springs travel
 * on, and applying every process's lists in pair order. Kept apart from
 * the walk on one process (contact_walk.c), whose threads' walk it reuses
 * for its share (contact_walk.h), because it is the one part of the stage
 * that talks to other processes (through step_share.contact_gather; no
 * MPI here).
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "contact.h"
#include "contact_internal.h"
#include "contact_rows.h"
#include "contact_walk.h"

/*
 * The walk split between processes (step_share.contact_ranks > 1: the rank
 * engine, runner/mpi). Process r of R evaluates the near pairs at indices
 * [n r / R, n (r + 1) / R) of the near list and the vertex pairs whose index
 * in near_vertex lies in the same share of near_vertex (this step's
 * vertex_walk changes every step; its values, being ascending, give each
 * process one run of it), on its threads (walk_listed, contact_walk.c), and
 * lists what they did;
 * contact_gather hands every process every list, and each applies them,
 * the near list's in process order, then the vertex pairs' in process
 * order: pair order, so every node's sum is formed as the serial walk forms
 * it, and the spring pool ends holding the same springs for the same pairs
 * (which set of the pool holds them may differ, as with threads; nothing
 * reads that): the same bits on any process count.
 *
 * A process always evaluates the same pairs between two rebuilds of the
 * near list (the shares are fixed index ranges of arrays that change only
 * at a rebuild), so the hints the walk leaves in a near pair (gap raised by
 * a clearance, sprung, NEAR_EDGES_TRIED) are always its own; a rebuild
 * derives them from what every process holds alike (the boxes, the spring
 * pool, the shut marks).
 *
 * The springs a pair keeps are updated in place by its kernel, on the
 * process evaluating it only; the others' copies fall behind
 * (springs_behind). Only that process reads them until the near list is
 * rebuilt, so they are handed over (contact_springs_sync) only before
 * something else reads the pool: a detection or a break's mending (which
 * set it aside), a rebuild of the near list (which gives the pairs new
 * shares), an excavation (which evaluates pairs itself) and a gather
 * before output or a checkpoint (the rank engine's). Which set of the pool
 * holds a pair's springs is the same everywhere: adopting and letting go
 * are applied on every process in pair order.
 *
 * On the wire (8-byte items), for each of the two walks: the counts of
 * touched, released and adopted pairs (3 uint64), then the touched keys
 * (int64) and forces (pair_out doubles each), the released pairs (int64),
 * the adopted pairs (int64) and springs (slots doubles each), then the
 * touched pairs found deep (wire_put_deep: a count, then a key and a
 * depth each). A sync's
 * wire: the count of pairs (uint64), their pairs (int64), their springs
 * (slots doubles each).
 */

/* Room for `need` bytes on the wire; -1 when out of memory. */
static int wire_reserve(contact_state *cs, size_t need)
{
    if (need <= cs->wire_capacity) return 0;
    size_t cap = cs->wire_capacity ? 2 * cs->wire_capacity : 4096;
    while (cap < need) cap *= 2;
    unsigned char *w = realloc(cs->wire, cap);
    if (!w) return -1;
    cs->wire = w;
    cs->wire_capacity = cap;
    return 0;
}

static unsigned char *wire_put(unsigned char *at, const void *data, size_t bytes)
{
    if (bytes) memcpy(at, data, bytes);
    return at + bytes;
}

/* The keys and then the rows of one kind of list of threads [0, used), in
 * thread order. */
static unsigned char *wire_put_rows(unsigned char *at, const contact_touches *lists, int used,
                                    size_t kind, int width)
{
    for (int t = 0; t < used; t++) {
        const pair_rows *r = (const pair_rows *)((const char *)&lists[t] + kind);
        at = wire_put(at, r->pair, sizeof(long) * r->count);
    }
    for (int t = 0; t < used; t++) {
        const pair_rows *r = (const pair_rows *)((const char *)&lists[t] + kind);
        at = wire_put(at, r->row, sizeof(double) * (size_t)width * r->count);
    }
    return at;
}

/* The touched pairs of threads [0, used) found deep, as their count
 * (uint64) and each one's key (int64) and depth (double), in pair order,
 * written at `at`; returns the end. The process that walked a pair looks
 * (contact_penetration_looks), and every process keeps what it found
 * (contact_penetration_record, in pair order as one process keeps them):
 * every process looking at every touched pair was 2 % of a contact pile's
 * step on two. At most 8 + 16 bytes a touched pair. */
static unsigned char *wire_put_deep(fdem_model *m, unsigned char *at, const contact_touches *lists,
                                    int used)
{
    unsigned char *count_at = at;
    uint64_t n = 0;
    at += sizeof n;
    for (int t = 0; t < used && m->step % CONTACT_PENETRATION_EVERY == 0; t++) {
        const pair_rows *touched = &lists[t].touched;
        for (size_t i = 0; i < touched->count; i++) {
            long key = touched->pair[i];
            int a = touched_a(key), b = touched_b(key);
            if (!contact_penetration_looks(m, a, b)) continue;
            double depth = contact_penetration(m, a, b);
            if (!(depth > FDEM_PENETRATION_WARN)) continue;
            at = wire_put(at, &key, sizeof key);
            at = wire_put(at, &depth, sizeof depth);
            n++;
        }
    }
    memcpy(count_at, &n, sizeof n);
    return at;
}

/* The lists of threads [0, used) appended to the wire at *bytes; -1 when
 * out of memory. */
static int wire_append(fdem_model *m, const contact_touches *lists, int used, size_t *bytes)
{
    contact_state *cs = &m->contact;
    const size_t kinds[3] = {offsetof(contact_touches, touched),
                             offsetof(contact_touches, release), offsetof(contact_touches, adopt)};
    const int width[3] = {cs->pair_out, 0, cs->slots};
    uint64_t count[3] = {0, 0, 0};
    size_t need = sizeof count;
    for (int k = 0; k < 3; k++) {
        for (int t = 0; t < used; t++)
            count[k] += ((const pair_rows *)((const char *)&lists[t] + kinds[k]))->count;
        need += (size_t)count[k] * (sizeof(long) + sizeof(double) * (size_t)width[k]);
    }
    const size_t deep_most = sizeof(uint64_t) + (size_t)count[0] * (sizeof(long) + sizeof(double));
    if (wire_reserve(cs, *bytes + need + deep_most)) return -1;
    unsigned char *at = wire_put(cs->wire + *bytes, count, sizeof count);
    for (int k = 0; k < 3; k++) at = wire_put_rows(at, lists, used, kinds[k], width[k]);
    at = wire_put_deep(m, at, lists, used);
    *bytes = (size_t)(at - cs->wire);
    return 0;
}

/* The touched pairs of another process's lists arrive in pair order but
 * land on elements and nodes anywhere in the mesh: applying them, every
 * process over every pair, waited on the element records and the force
 * rows. Their keys are known ahead, so the records are asked for two
 * WIRE_AHEADs ahead and the force rows of their nodes one ahead. Same
 * bits: a prefetch changes no value. */
#define WIRE_AHEAD 8

static inline void wire_prefetch_records(const fdem_model *m, long key)
{
    int a = touched_a(key), b = touched_b(key);
    __builtin_prefetch(m->dim == 3 ? (const void *)&m->tet[a] : (const void *)&m->elem[a]);
    __builtin_prefetch(m->dim == 3 ? (const void *)&m->tet[b] : (const void *)&m->elem[b]);
}

static inline void wire_prefetch_nodes(const fdem_model *m, long key)
{
    const int D = m->dim;
    const int32_t *na = element_nodes(m, touched_a(key)), *nb = element_nodes(m, touched_b(key));
    for (int c = 0; c <= D; c++) {
        __builtin_prefetch(m->contact.force + D * (size_t)na[c], 1);
        __builtin_prefetch(m->contact.force + D * (size_t)nb[c], 1);
    }
}

/* One walk's lists of one process, as wire_append laid them out at p,
 * applied: the touched pairs' forces added, the released sets let go, the
 * adopted ones taken, the deep pairs kept (touching NULL: only stepped
 * over). Returns the pointer past them and adds the touched pairs
 * to *touching; NULL when the pool cannot grow or the bytes run past end. */
static const unsigned char *wire_apply(fdem_model *m, const unsigned char *p,
                                       const unsigned char *end, int *touching)
{
    contact_state *cs = &m->contact;
    uint64_t count[3];
    if ((size_t)(end - p) < sizeof count) return NULL;
    memcpy(count, p, sizeof count);
    p += sizeof count;
    const size_t out = (size_t)cs->pair_out, slots = (size_t)cs->slots;
    const size_t row[3] = {out, 0, slots};
    size_t need = 0;
    for (int k = 0; k < 3; k++) {
        if (count[k] > (size_t)(end - p)) return NULL;
        need += (size_t)count[k] * (sizeof(long) + sizeof(double) * row[k]);
    }
    if (need > (size_t)(end - p)) return NULL;
    const unsigned char *deep = p + need;
    uint64_t deep_count;
    if ((size_t)(end - deep) < sizeof deep_count) return NULL;
    memcpy(&deep_count, deep, sizeof deep_count);
    deep += sizeof deep_count;
    const size_t deep_row = sizeof(long) + sizeof(double);
    if (deep_count > (size_t)(end - deep) / deep_row) return NULL;
    if (!touching) return deep + deep_count * deep_row;
    const long *key = (const long *)p;
    const double *rows = (const double *)(key + count[0]);
    for (size_t i = 0; i < count[0]; i++) {
        if (i + 2 * WIRE_AHEAD < count[0]) wire_prefetch_records(m, key[i + 2 * WIRE_AHEAD]);
        if (i + WIRE_AHEAD < count[0]) wire_prefetch_nodes(m, key[i + WIRE_AHEAD]);
        contact_pair_add(m, touched_a(key[i]), touched_b(key[i]), rows + i * out);
    }
    *touching += (int)count[0];
    const long *release = (const long *)(rows + count[0] * out);
    for (size_t i = 0; i < count[1]; i++) contact_springs_release(cs, (size_t)release[i]);
    const long *adopt = release + count[1];
    const double *springs = (const double *)(adopt + count[2]);
    for (size_t i = 0; i < count[2]; i++)
        if (contact_springs_adopt(cs, (size_t)adopt[i], springs + i * slots)) return NULL;
    for (uint64_t i = 0; i < deep_count; i++, deep += deep_row) {
        long pair;
        double depth;
        memcpy(&pair, deep, sizeof pair);
        memcpy(&depth, deep + sizeof pair, sizeof depth);
        contact_penetration_record(m, touched_a(pair), touched_b(pair), depth);
    }
    return deep;
}

/* The first position of an ascending index list at or past value v. */
static size_t lower_bound(const int32_t *v, size_t n, long x)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (v[mid] < x) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* This process's share [begin, end) of pairs [0, n) of the near array
 * (or of near_vertex, by index value, when w->index is set). */
static void walk_share(const near_walk *w, size_t n, const step_share *share, long *begin,
                       long *end)
{
    size_t lo, hi;
    contact_share(share, n, &lo, &hi);
    if (!w->index) {
        *begin = (long)lo;
        *end = (long)hi;
        return;
    }
    *begin = (long)lower_bound(w->index, w->count, (long)lo);
    *end = (long)lower_bound(w->index, w->count, (long)hi);
}

int contact_pairs_forces_split(fdem_model *m, double h, const near_walk walks[2])
{
    contact_state *cs = &m->contact;
    const step_share *share = m->share;
    const size_t totals[2] = {cs->near_count, cs->near_vertex_count};
    size_t bytes = 0;
    int ok = 1;
    for (int k = 0; k < 2 && ok; k++) {
        long begin, end;
        int used;
        walk_share(&walks[k], totals[k], share, &begin, &end);
        cs->pairs_walked += end - begin;
        ok = walk_listed(m, h, &walks[k], begin, end, &used) == 0 &&
             wire_append(m, cs->touches, used, &bytes) == 0;
        cs->split_threaded += ok && used > 1;
    }
    /* every process takes part, failed or not: none is left waiting */
    const unsigned char *const *from;
    const size_t *size;
    cs->springs_behind = 1; /* once gathered, failed or not (a failed step fails everywhere) */
    if (share->contact_gather(share->ctx, cs->wire, ok ? bytes : 0, ok, 1, &from, &size))
        return -1;
    int touching = 0;
    for (int k = 0; k < 2; k++)
        for (int r = 0; r < share->contact_ranks; r++) {
            const unsigned char *p = from[r], *end = from[r] + size[r];
            if (k == 1 && !(p = wire_apply(m, p, end, NULL))) return -1; /* past the near list's */
            if (!wire_apply(m, p, end, &touching)) return -1;
        }
    return touching;
}

/* The springs of the pairs of pairs[lo, hi) that hold a set, appended to
 * the wire at *bytes as one run: their count (uint64), their pairs (int64),
 * their springs (slots doubles each). -1 when out of memory. */
static int sync_append(contact_state *cs, const near_pair *pairs, size_t lo, size_t hi,
                       size_t *bytes)
{
    const size_t slots = (size_t)cs->slots;
    uint64_t n = 0;
    for (size_t i = lo; i < hi; i++) n += cs->spring_of[pairs[i].pair] >= 0;
    size_t need = sizeof n + (size_t)n * (sizeof(long) + sizeof(double) * slots);
    if (wire_reserve(cs, *bytes + need)) return -1;
    unsigned char *at = wire_put(cs->wire + *bytes, &n, sizeof n);
    long *key = (long *)at;
    double *springs = (double *)(key + n);
    size_t j = 0;
    for (size_t i = lo; i < hi; i++) {
        int32_t set = cs->spring_of[pairs[i].pair];
        if (set < 0) continue;
        key[j] = (long)pairs[i].pair;
        memcpy(springs + j * slots, cs->slip + slots * (size_t)set, sizeof(double) * slots);
        j++;
    }
    *bytes += need;
    return 0;
}

/* One process's runs (sync_append) written into the pool; -1 when the
 * bytes do not hold whole runs of pairs that hold a set. */
static int sync_apply(contact_state *cs, const unsigned char *p, const unsigned char *end)
{
    const size_t slots = (size_t)cs->slots, row = sizeof(long) + sizeof(double) * slots;
    while (p < end) {
        uint64_t n;
        if ((size_t)(end - p) < sizeof n) return -1;
        memcpy(&n, p, sizeof n);
        p += sizeof n;
        if (n > (size_t)(end - p) / row) return -1;
        const long *key = (const long *)p;
        const double *springs = (const double *)(key + n);
        for (size_t i = 0; i < n; i++) {
            if (key[i] < 0 || (size_t)key[i] >= cs->pairs.count) return -1;
            int32_t set = cs->spring_of[key[i]];
            if (set < 0) return -1;
            memcpy(cs->slip + slots * (size_t)set, springs + i * slots, sizeof(double) * slots);
        }
        p += (size_t)n * row;
    }
    return 0;
}

int contact_springs_sync(fdem_model *m)
{
    contact_state *cs = &m->contact;
    const step_share *share = m->share;
    if (!cs->springs_behind || !share || share->contact_ranks < 2) return 0;
    if (cs->slip_count == cs->free_count) { /* no pair holds a set (every process alike) */
        cs->springs_behind = 0;
        return 0;
    }
    /* this process's shares as walk_share cut them: the near list's by
     * index, the vertex pairs' by index into near_vertex */
    const size_t totals[2] = {cs->near_count, cs->near_vertex_count};
    const near_pair *arrays[2] = {cs->near, cs->near_vertex};
    size_t bytes = 0;
    int ok = 1;
    for (int k = 0; k < 2 && ok; k++) {
        size_t lo, hi;
        contact_share(share, totals[k], &lo, &hi);
        ok = sync_append(cs, arrays[k], lo, hi, &bytes) == 0;
    }
    const unsigned char *const *from;
    const size_t *size;
    if (share->contact_gather(share->ctx, cs->wire, ok ? bytes : 0, ok, 0, &from, &size))
        return -1;
    cs->springs_behind = 0;
    cs->springs_synced++;
    for (int p = 0; p < share->contact_ranks; p++) /* its own too: they are what it holds */
        if (sync_apply(cs, from[p], from[p] + size[p])) return -1;
    return 0;
}
