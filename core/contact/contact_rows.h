/*
 * contact_rows.h - what a threaded or split contact walk lists per thread
 * (contact_walk.c) and how the lists are applied (contact_rows.c): rows
 * of numbers keyed by a pair, in pair order; a thread's touched pairs with
 * their forces, and the pairs whose springs the pool adopts or lets go.
 * Internal to core/contact.
 *
 * Contract: a list grows by pair_rows_room (then the caller fills the row
 * at count) or pair_rows_push; touched_apply adds `used` lists' forces to
 * the contact force array, the friction account and the penetration look
 * in list order, row order: the serial walk's order, the same bits.
 */
#ifndef FDEM_CONTACT_ROWS_H
#define FDEM_CONTACT_ROWS_H

#include <stddef.h>
#include <stdint.h>

#include "model/model.h"

/* Rows of numbers keyed by a candidate pair, in pair order. */
typedef struct pair_rows {
    long *pair;
    double *row;
    double *last; /* touched rows: each row's last number (the dissipation) again, so
                     the account summed in pair order on one thread reads 8 bytes a
                     pair, not the row's cache lines */
    int32_t *nodes; /* touched rows: the two elements' nodes (node_width ids a row),
                       so the threads applying the rows read no element record: they
                       were a cache miss a pair and element, half of the apply's time
                       on a broken 2D block on two threads */
    int node_width;
    size_t count, capacity;
} pair_rows;

/* A thread's share of the pairs: those that touched with their forces
 * (pair_out numbers each; keyed by their two elements, touched_key, not
 * by pair: the scatter after the threads would otherwise look each up in
 * the candidate arrays, a cache miss a pair, a tenth of a broken 3D
 * block's 2-thread step on one thread) and those whose springs the pool is
 * to adopt (slots each) or let go. The springs a pair keeps, updated in
 * place, are not listed: in a split walk contact_springs_sync hands them
 * to the other processes when something other than the walk reads them. */
typedef struct contact_touches {
    pair_rows touched, adopt, release;
    double work; /* what the share cost, CPU seconds of its thread (contact_walk.c
                    balances the next step's shares by it) */
} contact_touches;

static inline long touched_key(int32_t a, int32_t b)
{
    return (long)((uint64_t)(uint32_t)a << 32 | (uint32_t)b);
}
static inline int32_t touched_a(long key) { return (int32_t)((uint64_t)key >> 32); }
static inline int32_t touched_b(long key) { return (int32_t)(uint32_t)key; }

int pair_rows_grow(pair_rows *list, int width);
/* Room for one more row (a walk asks before each pair); -1 when out of
 * memory. */
static inline int pair_rows_room(pair_rows *list, int width)
{
    return list->count < list->capacity ? 0 : pair_rows_grow(list, width);
}
int pair_rows_push(pair_rows *list, long pair, const double *row, int width);
size_t pair_rows_bytes(const pair_rows *list, int width);
void pair_rows_free(pair_rows *list);
void touched_apply(fdem_model *m, const contact_touches *lists, int used);

#endif /* FDEM_CONTACT_ROWS_H */
