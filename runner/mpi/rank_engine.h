/*
 * rank_engine.h - one model stepped by N MPI ranks with the same bits as
 * one process (contract 6.5, issue 37), as a driver of the unchanged engine.
 *
 * Contract:
 *  - Every rank builds the same whole model (replicated set-up) and calls
 *    rank_engine_create with it, collectively; then rank_engine_step in
 *    place of fdem_step, collectively, every rank the same number of times.
 *  - After each step every rank holds bit-identical to one process the
 *    joints, contact, energies and the nodes it keeps (rank_engine_node_mark:
 *    NULL when it keeps all); the elements' viscous history (elem_viscous)
 *    only where an element is computed. rank_engine_gather (collective)
 *    makes rank 0's model whole before it writes output or a checkpoint.
 *  - What is split: the element forces (the element blocks of the model's
 *    scatter plan are partitioned with METIS; a rank computes the elements
 *    of its blocks and every element touching a node it owns), the contact
 *    pair walk (a fixed share of the near pairs a rank; every rank applies
 *    every rank's lists in rank order: core/contact/contact_walk.c) and, in
 *    models without contact, joints, fluid, stages, fixed parts or a
 *    gravity amplitude (rank_halo.h), the update: a rank updates the nodes
 *    it keeps and receives only border forces. Otherwise joints, contact
 *    detection, fluid and the update run on every rank (see rank_engine.c).
 *  - Errors: -1 with err filled; an error on one rank fails the step on
 *    every rank (collective). MPI and METIS live only in runner/mpi.
 */
#ifndef FDEM_RANK_ENGINE_H
#define FDEM_RANK_ENGINE_H

#include <mpi.h>
#include <stddef.h>
#include "fdem.h"

typedef struct rank_engine rank_engine;

/* What a partition cost and gives, for the bench and the report. */
typedef struct rank_figures {
    int ranks, blocks;          /* element blocks of the plan: the unit of ownership */
    int owned_blocks;           /* this rank's */
    long owned_elements;        /* elements of this rank's blocks */
    long computed_elements;     /* owned plus halo (elements touching an owned node) */
    long owned_nodes;
    double partition_seconds;   /* METIS on the block graph, rank 0 */
    double bytes_sent_per_step; /* this rank's share of the exchanges */
    double exchange_seconds;    /* wall time in the step's exchanges, all steps */
    double exchange_cpu_seconds; /* CPU time there (MPI polling), all steps */
    int split_update;           /* 1: the update is split (rank_halo.h), 0: replicated */
    long kept_nodes;            /* nodes this rank updates (all when replicated) */
    int contact_split;          /* 1: the contact pair walk is split (rank_engine.c) */
    long contact_pairs_walked;  /* near pairs in this rank's share, all steps (every pair
                                   walked, on one rank) */
    double contact_bytes_sent;  /* the walk's lists sent to the other ranks, all steps */
    double contact_sync_bytes_sent; /* of which the springs handed over (contact_springs_sync) */
} rank_figures;

rank_engine *rank_engine_create(fdem_model *m, MPI_Comm comm, fdem_error *err);
int rank_engine_step(rank_engine *re, fdem_model *m, fdem_error *err);
int rank_engine_gather(rank_engine *re, fdem_model *m, fdem_error *err);
void rank_engine_free(rank_engine *re);
rank_figures rank_engine_figures(const rank_engine *re);
const uint8_t *rank_engine_node_mark(const rank_engine *re);

/* The engine as a batch loop's stepper (runner/run_case.h's
 * runner_stepper: ctx = a rank_engine_lazy, step = rank_engine_lazy_step,
 * gather = rank_engine_lazy_gather). The engine is made at the first step,
 * collectively, so a model restored from a checkpoint before it is split
 * as it is then; a different model (a rebuild) gets a new engine. Before
 * the first step every rank holds the whole state: gather has nothing to
 * do. */
typedef struct rank_engine_lazy {
    MPI_Comm comm;
    rank_engine *re;
    const fdem_model *model; /* the model re was made for */
} rank_engine_lazy;

int rank_engine_lazy_step(void *lazy, fdem_model *m, fdem_error *err);
int rank_engine_lazy_gather(void *lazy, fdem_model *m, fdem_error *err);
void rank_engine_lazy_free(rank_engine_lazy *lazy);

/* rank_partition.c: owner[b] in [0, parts) for each of `blocks` element
 * blocks of block_size consecutive elements (K nodes each), balanced by
 * element count and cut where the fewest nodes are shared; METIS k-way on
 * the block graph, consecutive runs of blocks if METIS fails. */
int rank_partition_blocks(const int32_t *elem_node, int elem_count, int K, int node_count,
                          int block_size, int blocks, int parts, int32_t *owner);

/* A test's knob (tests/mpi): nonzero makes each rank add its halo
 * elements' forces after its own blocks', the classic decomposition whose
 * node sums at the borders are formed in another order; the state then
 * must differ from one process, and the test shows that it does. */
void rank_engine_set_border_order_fault(rank_engine *re, int on);

/* Tests' knobs for the split contact walk (tests/mpi): ORDER hands the
 * ranks' lists over in the reverse rank order (border sums and the spring
 * pool's order change); ROTATE gives each rank another share of the pairs
 * every step (the hints the walk keeps in a near pair go stale). Either
 * must make the state differ from one process where pairs of two ranks
 * meet at a node. FAIL makes the last rank's walk fail at step
 * RANK_CONTACT_FAIL_STEP, as if its lists could not grow: every rank must
 * fail that step, none left waiting. SKIP_SYNC leaves out the hand-overs
 * of the springs the walk updated in place (contact_springs_sync) inside
 * the steps (before a detection, a break's mending, a near list's rebuild,
 * an excavation), SKIP_GATHER_SYNC the one at rank_engine_gather: each
 * rank then holds the other ranks' springs as they were. */
enum { RANK_CONTACT_FAULT_NONE, RANK_CONTACT_FAULT_ORDER, RANK_CONTACT_FAULT_ROTATE,
       RANK_CONTACT_FAULT_FAIL, RANK_CONTACT_FAULT_SKIP_SYNC,
       RANK_CONTACT_FAULT_SKIP_GATHER_SYNC };
#define RANK_CONTACT_FAIL_STEP 9
void rank_engine_set_contact_fault(rank_engine *re, int fault);

#endif
