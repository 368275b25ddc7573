/*
 * contact_walk.h - what the contact stage's pair walk on one process
 * (contact_walk.c) shares with the same walk split between processes
 * (contact_walk_split.c): a walk's pairs, and a range of them evaluated on
 * this process's threads into per-thread lists (contact_rows.h) that the
 * caller applies in thread order, which is pair order.
 */
#ifndef FDEM_CONTACT_WALK_H
#define FDEM_CONTACT_WALK_H

#include <stddef.h>
#include <stdint.h>

#include "model/model.h"
#include "contact_internal.h"

/* A list of near pairs the walk takes this step: the near list whole, or
 * this step's vertex pairs (index into near_vertex). */
typedef struct near_walk {
    near_pair *pairs;
    const int32_t *index; /* NULL: pairs[0 .. count) */
    size_t count;
} near_walk;

static inline near_pair *walk_pair(const near_walk *w, size_t i)
{
    return w->index ? &w->pairs[w->index[i]] : &w->pairs[i];
}

/* Pairs [begin, end) of walk w listed on this process's threads (the
 * lists in contact.touches); *used the lists filled, in thread order. 0,
 * or -1 when a list cannot grow. */
int walk_listed(fdem_model *m, double h, const near_walk *w, long begin, long end, int *used);

/* Both walks (the near list, this step's vertex pairs) split between the
 * step's processes (step_share.contact_ranks > 1): this process's shares
 * listed, every process's lists gathered and applied in pair order. The
 * pairs that touched, or -1 (out of memory, or a process failed). */
int contact_pairs_forces_split(fdem_model *m, double h, const near_walk walks[2]);

#endif /* FDEM_CONTACT_WALK_H */
