/*
 * contact.h - the contact stage of both dimensions: when to detect
 * (travel since the last detection), NBS detection into candidate pairs,
 * pairs the joints exclude, the near-pair list walked each step, the pair
 * kernels (kernel/contact_tri.c, kernel/contact_tet.c) on one or several
 * threads, the friction stick springs' history, and the overlap check of a
 * model's start. Reads the joints (joint/joint.h) to skip joined pairs;
 * the step (step/), finalize (build/) and checkpoints call it.
 */
#ifndef FDEM_CONTACT_H
#define FDEM_CONTACT_H

#include "model/model.h"

/* First capacities of the contact lists that grow by doubling (pair and
 * touch rows, near pairs, spring indices; stick-spring sets and records):
 * a model with contact holds them however few its pairs, and the memory
 * estimate prices them (build/memory.c, memory_fixed and fdem_memory_per_thread). */
#define CONTACT_FIRST_ROWS 1024
#define CONTACT_FIRST_SETS 256


/* contact.c: the contact stage of both dimensions over the pair kernels of
 * contact_tri.c and contact_tet.c (contact_pair.h) */
int contact_init(fdem_model *m, fdem_error *err);
void contact_free(contact_state *c);
double contact_stable_dt(const fdem_model *m);
/* The contact's stability limit (omega dt = 2 on its stiffest estimate)
 * over its step (omega dt = 1, where flat impacts keep their energy):
 * fdem_auto_dt scales the limit by the safety and caps it at the step. */
#define CONTACT_STABLE_OVER_STEP 2.0
int contact_forces(fdem_model *m);
/* penetration.c: how deep a node of either element is inside the other,
 * as a fraction of that element's inradius; a touching pair beyond
 * FDEM_PENETRATION_WARN is kept once for fdem_take_penetrations(). */
#define CONTACT_PENETRATION_EVERY 8 /* steps between two looks (contact_pair_scatter) */
double contact_penetration(const fdem_model *m, int a, int b);
void contact_penetration_check(fdem_model *m, int a, int b);
/* check's second half, for a depth found elsewhere (a split walk's
 * process that walked the pair: contact_walk_split.c); kept when past
 * FDEM_PENETRATION_WARN */
void contact_penetration_record(fdem_model *m, int a, int b, double fraction);
int contact_restore_detection(fdem_model *m);
/* contact_walk.c: a split walk's springs updated in place handed to every
 * process (collective on the processes of m->share; nothing to do on one
 * process or when none fell behind). 0, or -1 when some process failed. */
int contact_springs_sync(fdem_model *m);
size_t contact_memory_bytes(const contact_state *c); /* touch lists and stick springs */
int contact_pair_force_now(const fdem_model *m, size_t k, double *out);

/* contact_excavation.c: the forces of the candidate pairs between removed
 * and remaining elements on the remaining ones, added to f (dim per node;
 * returns 0); the candidate pairs of excavated elements dropped; */
int contact_excavation_forces(fdem_model *m, const uint8_t *removed, double *f);
void contact_drop_excavated(fdem_model *m);
/* The penalty energy of the touching pairs with an element removed now
 * (removed[e]), before any is dropped. */
double contact_excavation_energy(const fdem_model *m, const uint8_t *removed);

/* contact_history.c */
int contact_history_reserve(contact_state *cs, size_t pairs);
int contact_springs_adopt(contact_state *cs, size_t pair, const double *springs);
void contact_springs_release(contact_state *cs, size_t pair);
/* Some stick spring of candidate pair k holds a force. */
static inline int contact_pair_sprung(const contact_state *cs, size_t k)
{
    return cs->spring_of[k] >= 0;
}
int contact_history_set_aside(contact_state *cs);
int contact_history_take_back(contact_state *cs);
size_t contact_history_checkpoint_size(const contact_state *cs);
void contact_history_checkpoint_write(const contact_state *cs, unsigned char *p);
int contact_history_checkpoint_read(contact_state *cs, const unsigned char *p, size_t count,
                                    int elements);
size_t contact_record_bytes(const contact_state *cs); /* one record in a checkpoint */


/* contact_breaks.c: the list after joints broke (0, or -1 out of memory),
 * a jointed model's list in the order of (lo, hi), what a detection saw of
 * the joints, and the arrays these need */
int contact_detect_breaks(fdem_model *m);
int contact_pairs_order(fdem_model *m);
void contact_breaks_remember(fdem_model *m);
int contact_breaks_init(fdem_model *m);
void contact_breaks_free(contact_state *cs);
/* the whole detection again on the last detection's circles (contact.c) */
int contact_detect_again(fdem_model *m);

/* the travel since detection (contact.max_disp2, a bound; contact_travel.c):
 * grown by a step's largest squared node step, and whether some node is now
 * farther than sqrt(limit2) from pos_detect (exact, read when the bound says
 * it may be) */
void contact_travel_step(fdem_model *m, double step2);
int contact_travel_past(fdem_model *m, double limit2);
/* each element's skin from its radius (cs->r, unwidened) and the largest:
 * buffer, and on a graded mesh skin, travel_weight and travel_limit2
 * (contact_travel.c); 0, or -1 out of memory */
int contact_skin_init(fdem_model *m, double rmax);
double contact_skin(const contact_state *cs, int e);

#endif
