/*
 * contact_history.c - the stick springs of Coulomb friction: a tangential
 * force per contactor edge (2D) or face (3D, a vector) of every candidate
 * pair, kept across steps, detections and checkpoints.
 *
 * Friction with elastic stick needs to remember, per touching pair, how far
 * its surfaces have been sheared against each other (PHYSICS.md,
 * "Friction"): cs->slots values (2D the three edges of each element as
 * contactor, 3D the three components for each of four faces). Only pairs
 * that touch have springs that hold anything, and they are a few in a
 * hundred of the candidates (3D: 24 doubles a set against ~25 candidates
 * per element), so a candidate pair carries an index into a pool of sets
 * (-1 for none), and a set is handed out when a pair first holds a force
 * and taken back when all its springs are zero again. Detection rebuilds the pair list in an order
 * of its own, so before it runs the pairs that hold some history are set
 * aside as records keyed by their two elements, and afterwards every new
 * pair looks its record up in a small open-addressing table. A checkpoint
 * stores the same records, and a restore feeds them through the same path.
 * Nothing depends on the thread count or on the order of the records.
 */
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "contact.h"

/* Slots of a pair (a, b): the edges of a against b, then those of b against
 * a. Records store them for (lo, hi) = (min, max) of the two elements; this
 * turns one order into the other (either way: it swaps the halves or not). */
static void pair_slots_oriented(const double *slip, int a, int b, int slots, double *out)
{
    int half = slots / 2;
    for (int k = 0; k < half; k++) {
        out[k] = slip[a < b ? k : k + half];
        out[k + half] = slip[a < b ? k + half : k];
    }
}

/* Room for the set index of `pairs` candidate pairs. */
int contact_history_reserve(contact_state *cs, size_t pairs)
{
    return model_reserve((void **)&cs->spring_of, &cs->pair_capacity, pairs, sizeof *cs->spring_of,
                         CONTACT_FIRST_ROWS);
}

/* A set of zeros from the pool: its index, or -1 when out of memory. */
static int32_t springs_take(contact_state *cs)
{
    int32_t set;
    if (cs->free_count) {
        set = cs->slip_free[--cs->free_count];
    } else {
        if (cs->slip_count == cs->slip_capacity) {
            size_t cap = cs->slip_capacity ? 2 * cs->slip_capacity : CONTACT_FIRST_SETS;
            if (cap > INT32_MAX) return -1;
            double *s = realloc(cs->slip, sizeof(double) * (size_t)cs->slots * cap);
            if (!s) return -1;
            cs->slip = s;
            int32_t *f = realloc(cs->slip_free, sizeof *f * cap);
            if (!f) return -1;
            cs->slip_free = f;
            cs->slip_capacity = cap;
        }
        set = (int32_t)cs->slip_count++;
    }
    memset(cs->slip + (size_t)cs->slots * (size_t)set, 0, sizeof(double) * (size_t)cs->slots);
    return set;
}

/* Candidate pair `pair`, without a set so far, now holds these springs. */
int contact_springs_adopt(contact_state *cs, size_t pair, const double *springs)
{
    int32_t set = springs_take(cs);
    if (set < 0) return -1;
    memcpy(cs->slip + (size_t)cs->slots * (size_t)set, springs, sizeof(double) * (size_t)cs->slots);
    cs->spring_of[pair] = set;
    return 0;
}

/* Candidate pair `pair` lets its springs go (if it held any). */
void contact_springs_release(contact_state *cs, size_t pair)
{
    int32_t set = cs->spring_of[pair];
    if (set < 0) return;
    cs->slip_free[cs->free_count++] = set;
    cs->spring_of[pair] = -1;
}

static int records_reserve(contact_state *cs, size_t count)
{
    if (count <= cs->record_capacity) return 0;
    size_t cap = cs->record_capacity ? cs->record_capacity : CONTACT_FIRST_SETS;
    while (cap < count) cap *= 2;
    contact_record *r = realloc(cs->records, sizeof *r * cap);
    if (!r) return -1;
    cs->records = r;
    cs->record_capacity = cap;
    return 0;
}

/* Appends the pairs that hold history to the pending records (a restore
 * may have put some there already). */
int contact_history_set_aside(contact_state *cs)
{
    size_t n = cs->record_count;
    for (size_t k = 0; k < cs->pairs.count; k++)
        n += contact_pair_sprung(cs, k);
    if (records_reserve(cs, n)) return -1;
    n = cs->record_count;
    for (size_t k = 0; k < cs->pairs.count; k++) {
        if (!contact_pair_sprung(cs, k)) continue;
        const double *slip = cs->slip + (size_t)cs->slots * (size_t)cs->spring_of[k];
        int a = cs->pairs.a[k], b = cs->pairs.b[k];
        contact_record *r = &cs->records[n++];
        r->lo = a < b ? a : b;
        r->hi = a < b ? b : a;
        pair_slots_oriented(slip, a, b, cs->slots, r->slip);
    }
    cs->record_count = n;
    return 0;
}

static inline uint64_t pair_hash(int32_t lo, int32_t hi)
{
    uint64_t key = ((uint64_t)(uint32_t)lo << 32) | (uint32_t)hi;
    key ^= key >> 33;
    key *= 0xff51afd7ed558ccdULL;
    key ^= key >> 33;
    return key;
}

/* Gives every pair of the new list its pending record, if it has one, and
 * empties the records. */
int contact_history_take_back(contact_state *cs)
{
    if (contact_history_reserve(cs, cs->pairs.count)) return -1;
    /* every set was set aside: the pool starts empty */
    cs->slip_count = cs->free_count = 0;
    for (size_t k = 0; k < cs->pairs.count; k++) cs->spring_of[k] = -1;
    size_t n = cs->record_count;
    if (n == 0) return 0;
    size_t size = 16;
    while (size < 2 * n) size *= 2;
    int32_t *table = malloc(sizeof(int32_t) * size);
    if (!table) return -1;
    for (size_t i = 0; i < size; i++) table[i] = -1;
    for (size_t r = 0; r < n; r++) {
        size_t i = pair_hash(cs->records[r].lo, cs->records[r].hi) & (size - 1);
        while (table[i] >= 0) i = (i + 1) & (size - 1);
        table[i] = (int32_t)r;
    }
    for (size_t k = 0; k < cs->pairs.count; k++) {
        int a = cs->pairs.a[k], b = cs->pairs.b[k];
        int32_t lo = a < b ? a : b, hi = a < b ? b : a;
        size_t i = pair_hash(lo, hi) & (size - 1);
        for (; table[i] >= 0; i = (i + 1) & (size - 1)) {
            const contact_record *r = &cs->records[table[i]];
            if (r->lo != lo || r->hi != hi) continue;
            double oriented[CONTACT_SLOTS_MAX];
            pair_slots_oriented(r->slip, a, b, cs->slots, oriented);
            if (contact_springs_adopt(cs, k, oriented)) {
                free(table);
                return -1;
            }
            break;
        }
    }
    free(table);
    cs->record_count = 0;
    return 0;
}

/* In a checkpoint a record is lo, hi and the slots in use: 56 bytes in 2D,
 * as sizeof(contact_record) was before 3D, so 2D checkpoints read as they
 * were written. */
size_t contact_record_bytes(const contact_state *cs)
{
    return 2 * sizeof(int32_t) + sizeof(double) * (size_t)cs->slots;
}

size_t contact_history_checkpoint_size(const contact_state *cs)
{
    size_t n = 0;
    for (size_t k = 0; k < cs->pairs.count; k++)
        n += contact_pair_sprung(cs, k);
    return n * contact_record_bytes(cs);
}

void contact_history_checkpoint_write(const contact_state *cs, unsigned char *p)
{
    size_t springs = sizeof(double) * (size_t)cs->slots;
    for (size_t k = 0; k < cs->pairs.count; k++) {
        if (!contact_pair_sprung(cs, k)) continue;
        const double *slip = cs->slip + (size_t)cs->slots * (size_t)cs->spring_of[k];
        int a = cs->pairs.a[k], b = cs->pairs.b[k];
        int32_t key[2] = {a < b ? a : b, a < b ? b : a};
        double oriented[CONTACT_SLOTS_MAX];
        pair_slots_oriented(slip, a, b, cs->slots, oriented);
        memcpy(p, key, sizeof key);
        memcpy(p + sizeof key, oriented, springs);
        p += sizeof key + springs;
    }
}

int contact_history_checkpoint_read(contact_state *cs, const unsigned char *p, size_t count,
                                    int elements)
{
    if (records_reserve(cs, count)) return -1;
    size_t bytes = contact_record_bytes(cs);
    for (size_t k = 0; k < count; k++) {
        contact_record *r = &cs->records[k];
        memset(r, 0, sizeof *r);
        memcpy(&r->lo, p + k * bytes, sizeof r->lo);
        memcpy(&r->hi, p + k * bytes + sizeof r->lo, sizeof r->hi);
        memcpy(r->slip, p + k * bytes + 2 * sizeof(int32_t), bytes - 2 * sizeof(int32_t));
        if (r->lo < 0 || r->hi <= r->lo || r->hi >= elements) return -1;
    }
    cs->record_count = count;
    return 0;
}
