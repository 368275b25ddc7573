/*
 * rank_engine.c - the engine on N MPI ranks with the same bits as one
 * process: which rank computes what, and the two exchanges of a step.
 *
 * Why the bits match. One process forms each node's element force by
 * adding its elements colour by colour, block by block, each block in
 * element order (core/parallel/scatter_plan.c), and totals the blocks'
 * energy sums in block order. Here the blocks of that same plan are the
 * unit of ownership (rank_partition.c): a rank computes every element of
 * its blocks, so their block sums are whole, and it owns the nodes whose
 * first element (lowest index) lies in one of its blocks, but for the
 * border of two ranks, which they split (rank_borders.h). It also computes
 * every element touching an owned node (the halo), in the same plan order
 * (step_share.elem_mark, core/element/element.c), so an owned node's force
 * is the one process's sum, bit for bit. Two exchanges complete a step:
 *  - block sums: after the element blocks ran, each rank's blocks' partial
 *    sums go to every rank (MPI_Allgatherv, SCATTER_SUMS doubles a block,
 *    at most 64 blocks: under 4 KB), and every rank totals them in block
 *    order as one process does;
 *  - forces: once every force is added, each rank's owned nodes' forces go
 *    to every rank, so every rank holds the whole force. A rank's owned
 *    nodes are a few runs of consecutive indices (its blocks' elements'
 *    nodes), so the exchange is one MPI type a rank over m->force itself:
 *    MPI reads and writes the force rows where they are, and nothing is
 *    packed or unpacked here.
 * Everything after (the update, constraints, energies) and the joints,
 * contact detection and fluid run on every rank on the same numbers: the
 * whole state stays replicated, bit-identical on every rank, and nothing
 * of it needs moving when bodies travel. Exchanging the forces (dim
 * doubles a node) rather than positions and velocities (twice that) is
 * what lets the update run everywhere.
 *
 * The contact pair walk is split too (step_share.contact_gather,
 * core/contact/contact_walk.c): each rank evaluates a fixed share of the
 * near pairs and lists what they did; share_contact_gather hands every
 * rank every rank's lists (MPI_Allgather of their sizes, then one message
 * from each rank to each other), which every rank applies in rank order,
 * pair order.
 * The springs a pair keeps, updated in place by the rank walking it, go
 * through the same exchange only when something else is to read them
 * (core's contact_springs_sync: before a detection, a rebuild of the near
 * list, an excavation, and at rank_engine_gather).
 *
 * In a model where nothing after the forces reads nodes anywhere (no
 * contact, joints, fluid, stages: rank_halo_wanted) the update is split
 * too (rank_halo.c): a rank updates only the nodes it keeps (its own, its
 * computed elements', the constraints'), the force exchange sends only
 * border nodes to the neighbours that keep them, and one reduction a step
 * makes a non-finite value on one rank fail the step on all. Rank 0 gets
 * the nodes from their owners at rank_engine_gather.
 *
 * The elements' viscous history (elem_viscous) is kept only where an
 * element is computed; rank_engine_gather hands rank 0 the owners' values.
 */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "math/clock.h"
#include "contact/contact.h"
#include "element/element.h"
#include "rank_engine.h"
#include "rank_borders.h"
#include "rank_halo.h"

#define FORCE_TAG 3702   /* rank_halo.c's border forces are 3701 */
#define CONTACT_TAG 3703

struct rank_engine {
    MPI_Comm comm;
    int rank, size, dim, elem_count;
    int blocks, block_size;          /* of m->elem_plan; blocks 1 when it has none */
    int32_t *block_owner;            /* per block */
    int32_t *block_order;            /* blocks rank by rank, each rank's ascending */
    int *block_counts, *block_displs; /* per rank, in doubles of block sums */
    int32_t *node_order;             /* nodes rank by rank (owned), ascending in each */
    int *node_counts, *node_displs;  /* per rank, in doubles (dim a node) */
    uint8_t *mark;                   /* elements this rank computes */
    uint8_t *halo;                   /* the border-order fault: halo elements only */
    double *send, *recv;             /* block-sum buffers */
    size_t send_len, recv_len;
    MPI_Datatype *force_type;        /* per rank: its flag and owned force rows (force_types) */
    const double *force_typed;       /* the m->force they point into; NULL: none made */
    double *flags;                   /* per rank: its flag in the force exchange */
    MPI_Request *requests;           /* the force and list exchanges', 2 (size - 1) */
    step_share share, halo_share;
    int border_fault;
    int exchanged;                   /* the force exchange ran in this step */
    int split;                       /* the update is split (rank_halo.c): border forces only */
    rank_halo border;                /* its nodes and lists */
    int agreed, local_bad, others_bad; /* this step's update verdicts (split) */
    int contact_split;               /* the contact walk is split (step_share.contact_gather) */
    int contact_gathered;            /* the walk's lists were exchanged in this step, or an
                                        exchange of springs before it told of a failure */
    int contact_fault;               /* rank_engine_set_contact_fault */
    int contact_turn;                /* the rotation fault: rank r takes share r + turn */
    int gathering;                   /* in rank_engine_gather (the skip-sync faults) */
    long long fault_step;            /* the step being made (the failure fault) */
    long long *contact_sizes;        /* per rank: the bytes of its lists, -1 failed */
    const unsigned char **contact_from; /* per share: its rank's lists (this rank's: the
                                        caller's own bytes) */
    size_t *contact_bytes;           /* per share: their size */
    unsigned char *contact_buf;      /* the other ranks' lists */
    size_t contact_cap, contact_agreed; /* its size here, and the size every rank has */
    rank_figures fig;
};

/* Wall and CPU time spent in exchanges (rank_figures): the CPU a rank
 * burns there is MPI polling for a partner, not work. */
typedef struct stopwatch {
    double wall, cpu;
} stopwatch;

static stopwatch stopwatch_now(void)
{
    return (stopwatch){MPI_Wtime(), clock_seconds_of(CLOCK_PROCESS_CPUTIME_ID)};
}

static void stopwatch_add(rank_engine *re, stopwatch since)
{
    stopwatch now = stopwatch_now();
    re->fig.exchange_seconds += now.wall - since.wall;
    re->fig.exchange_cpu_seconds += now.cpu - since.cpu;
}

/* Element block of element e, as scatter_plan.c cuts them. */
static inline int block_of(const rank_engine *re, int e) { return e / re->block_size; }

/* The blocks' sums of the other ranks into plan->block_sum: each rank's
 * own blocks packed in rank order, every rank the same lists. */
static void share_block_sums(void *ctx, fdem_model *m, scatter_plan *plan)
{
    rank_engine *re = ctx;
    if (plan != &m->elem_plan || plan->block_count != re->blocks) return;
    const int me = re->rank;
    double *out = re->send;
    const int32_t *mine = re->block_order + re->block_displs[me] / SCATTER_SUMS;
    const int count = re->block_counts[me] / SCATTER_SUMS;
    for (int k = 0; k < count; k++)
        memcpy(out + (size_t)k * SCATTER_SUMS, plan->block_sum + (size_t)mine[k] * SCATTER_SUMS,
               sizeof(double) * SCATTER_SUMS);
    stopwatch t0 = stopwatch_now();
    MPI_Allgatherv(out, re->block_counts[me], MPI_DOUBLE, re->recv, re->block_counts,
                   re->block_displs, MPI_DOUBLE, re->comm);
    stopwatch_add(re, t0);
    for (int k = 0; k < re->blocks; k++)
        memcpy(plan->block_sum + (size_t)re->block_order[k] * SCATTER_SUMS,
               re->recv + (size_t)k * SCATTER_SUMS, sizeof(double) * SCATTER_SUMS);
}

/* The border-order fault (rank_engine.h): the halo elements' forces added
 * after the owned blocks' whole pass; energies as they were. */
static void add_halo_after(rank_engine *re, fdem_model *m)
{
    double elastic = m->elastic_energy, damping = m->damping_work;
    m->share = &re->halo_share;
    element_forces(m);
    m->share = &re->share;
    m->elastic_energy = elastic;
    m->damping_work = damping;
}

/* Each rank's owned nodes' forces as one MPI type of absolute addresses
 * (used with MPI_BOTTOM): its flag (flags[r]), then each run of consecutive
 * owned nodes as one block of m->force. The exchange then sends and
 * receives the rows where they lie: packing them into a buffer and out of
 * it again, node by node, was as long as the transfer itself (2 ranks, a
 * contact pile of 55 k nodes: 0.13 ms a step of 2.6). Made again if
 * m->force ever moves; -1 when out of memory or MPI cannot make a type. */
static void force_types_free(rank_engine *re)
{
    if (!re->force_typed) return;
    for (int r = 0; r < re->size; r++) MPI_Type_free(&re->force_type[r]);
    re->force_typed = NULL;
}

static int force_types(rank_engine *re, const fdem_model *m)
{
    const int D = re->dim;
    force_types_free(re);
    /* a rank's flag and its runs: at most one run a node */
    int *run_len = malloc(sizeof(int) * ((size_t)m->node_count + 1));
    MPI_Aint *run_at = malloc(sizeof(MPI_Aint) * ((size_t)m->node_count + 1));
    int made = 0;
    for (; run_len && run_at && made < re->size; made++) {
        const int32_t *nodes = re->node_order + re->node_displs[made] / D;
        const int count = re->node_counts[made] / D;
        int blocks = 1;
        MPI_Get_address(&re->flags[made], &run_at[0]);
        run_len[0] = 1;
        for (int k = 0; k < count; k++) {
            if (k > 0 && nodes[k] == nodes[k - 1] + 1) {
                run_len[blocks - 1] += D;
                continue;
            }
            MPI_Get_address(m->force + (size_t)D * nodes[k], &run_at[blocks]);
            run_len[blocks++] = D;
        }
        if (MPI_Type_create_hindexed(blocks, run_len, run_at, MPI_DOUBLE,
                                     &re->force_type[made]) != MPI_SUCCESS)
            break;
        if (MPI_Type_commit(&re->force_type[made]) != MPI_SUCCESS) {
            MPI_Type_free(&re->force_type[made]);
            break;
        }
    }
    free(run_len);
    free(run_at);
    if (made < re->size) {
        for (int q = 0; q < made; q++) MPI_Type_free(&re->force_type[q]);
        return -1;
    }
    re->force_typed = m->force;
    return 0;
}

/* Every rank's owned nodes' forces to every rank (one message to each
 * other rank: force_types), each led by one number saying whether its
 * rank got here in order (1) or failed before (0, sent by
 * rank_engine_step): a failure on one rank fails the step on all, in the
 * same exchange, and no rank waits for a partner that left. */
static int exchange_forces(rank_engine *re, fdem_model *m, int ok)
{
    const int P = re->size, me = re->rank;
    /* m->force never moves after set-up (an excavation swaps it only inside
     * its own pass), but if it did the rows must follow it */
    if (re->force_typed != m->force && force_types(re, m)) {
        fprintf(stderr, "rank %d: the force rows could not be described (out of memory or "
                "an MPI failure)\n", me);
        MPI_Abort(re->comm, 2); /* the others would wait for this rank's message */
    }
    re->flags[me] = ok;
    stopwatch t0 = stopwatch_now();
    int n = 0;
    for (int r = 0; r < P; r++)
        if (r != me)
            MPI_Irecv(MPI_BOTTOM, 1, re->force_type[r], r, FORCE_TAG, re->comm, &re->requests[n++]);
    for (int r = 0; r < P; r++)
        if (r != me)
            MPI_Isend(MPI_BOTTOM, 1, re->force_type[me], r, FORCE_TAG, re->comm,
                      &re->requests[n++]);
    int rc = MPI_Waitall(n, re->requests, MPI_STATUSES_IGNORE);
    stopwatch_add(re, t0);
    if (rc != MPI_SUCCESS) return -1;
    for (int r = 0; r < P; r++)
        if (re->flags[r] != 1) return -1;
    return 0;
}

/* The forces every rank needs: all of them (replicated update) or the
 * border nodes' to the neighbours that keep them (split update). */
static int share_forces_done(void *ctx, fdem_model *m)
{
    rank_engine *re = ctx;
    re->exchanged = 1;
    if (re->border_fault) add_halo_after(re, m);
    if (!re->split) return exchange_forces(re, m, 1);
    stopwatch t0 = stopwatch_now();
    int rc = rank_halo_exchange(&re->border, m, 1);
    stopwatch_add(re, t0);
    return rc;
}

/* Split update: each rank checked only the nodes it updated; they fail
 * together (one small reduction a step). */
static int share_update_done(void *ctx, fdem_model *m, int bad)
{
    (void)m;
    rank_engine *re = ctx;
    re->agreed = 1;
    re->local_bad = bad != 0;
    int any = re->local_bad;
    stopwatch t0 = stopwatch_now();
    if (MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_MAX, re->comm) != MPI_SUCCESS) any = 1;
    stopwatch_add(re, t0);
    re->others_bad = any && !re->local_bad;
    return any;
}

/* The contact walk's lists or a hand-over of its springs
 * (step_share.contact_gather; walk 1 and 0): every rank's sizes, then
 * their bytes, one message from each rank to each other, into contact_buf
 * (a rank's own lists are handed back where they lie: copying them
 * there too was a sixth of the bytes a step moved in memory), in rank order
 * (or, for the order fault, in the reverse order). Every rank sees the
 * same sizes, so each takes the same path: a rank that failed (size -1)
 * fails the step on all, and the buffer grows on all at the same steps,
 * one reduction then telling whether it grew everywhere. A step's last
 * contact exchange is the walk's: a rank failing before it takes part in
 * it (fail_collectives) unless an exchange of springs before it told every
 * rank of a failure. */
static int share_contact_gather(void *ctx, const void *mine, size_t bytes, int ok, int walk,
                                const unsigned char *const **from, const size_t **size)
{
    rank_engine *re = ctx;
    const int P = re->size, me = re->rank;
    const int skip = re->gathering ? RANK_CONTACT_FAULT_SKIP_GATHER_SYNC
                                   : RANK_CONTACT_FAULT_SKIP_SYNC;
    *from = re->contact_from;
    *size = re->contact_bytes;
    if (!walk && re->contact_fault == skip && ok) {
        for (int k = 0; k < P; k++) { /* nothing handed over */
            re->contact_from[k] = re->contact_buf;
            re->contact_bytes[k] = 0;
        }
        return 0;
    }
    if (walk) re->contact_gathered = 1;
    if (walk && re->contact_fault == RANK_CONTACT_FAULT_FAIL && re->rank == P - 1 &&
        re->fault_step == RANK_CONTACT_FAIL_STEP)
        ok = 0; /* as if a list could not grow here */
    long long own = ok && bytes <= INT_MAX ? (long long)bytes : -1;
    stopwatch t0 = stopwatch_now();
    int rc = MPI_Allgather(&own, 1, MPI_LONG_LONG, re->contact_sizes, 1, MPI_LONG_LONG, re->comm);
    size_t total = 0; /* every rank's, own included: the same on every rank, so that all
                         take the same path through the growth's reduction */
    for (int r = 0; r < P && rc == MPI_SUCCESS; r++) {
        if (re->contact_sizes[r] < 0) rc = -1;
        else total += (size_t)re->contact_sizes[r];
    }
    if (rc == MPI_SUCCESS && total > re->contact_agreed) {
        size_t cap = total > 2 * re->contact_agreed ? total : 2 * re->contact_agreed;
        int grown = 1;
        if (cap > re->contact_cap) {
            unsigned char *b = realloc(re->contact_buf, cap);
            if (b) {
                re->contact_buf = b;
                re->contact_cap = cap;
            }
            grown = b != NULL;
        }
        MPI_Allreduce(MPI_IN_PLACE, &grown, 1, MPI_INT, MPI_MIN, re->comm);
        if (grown) re->contact_agreed = cap;
        else rc = -1;
    }
    if (rc != MPI_SUCCESS) {
        stopwatch_add(re, t0);
        re->contact_gathered = 1; /* every rank knows: none waits in another */
        return -1;
    }
    size_t at = 0;
    int n = 0;
    for (int k = 0; k < P; k++) {
        int r = k; /* the rank whose lists come k-th: the one with share k */
        if (re->contact_fault == RANK_CONTACT_FAULT_ORDER) r = P - 1 - k;
        if (re->contact_fault == RANK_CONTACT_FAULT_ROTATE)
            r = (int)(((k - re->contact_turn) % P + P) % P);
        re->contact_bytes[k] = (size_t)re->contact_sizes[r];
        if (r == me) {
            re->contact_from[k] = mine;
            continue;
        }
        re->contact_from[k] = re->contact_buf + at;
        MPI_Irecv(re->contact_buf + at, (int)re->contact_sizes[r], MPI_BYTE, r, CONTACT_TAG,
                  re->comm, &re->requests[n++]);
        at += (size_t)re->contact_sizes[r];
    }
    for (int r = 0; r < P; r++)
        if (r != me)
            MPI_Isend(mine, (int)own, MPI_BYTE, r, CONTACT_TAG, re->comm, &re->requests[n++]);
    rc = MPI_Waitall(n, re->requests, MPI_STATUSES_IGNORE);
    stopwatch_add(re, t0);
    re->fig.contact_bytes_sent += (double)bytes * (P - 1);
    if (!walk) re->fig.contact_sync_bytes_sent += (double)bytes * (P - 1);
    return rc == MPI_SUCCESS ? 0 : -1;
}

/* Lists of owned items rank by rank (owner[i] of n items), with the
 * counts and offsets in units of `width` doubles. */
static int list_by_owner(const int32_t *owner, int n, int size, int width, int32_t *order,
                         int *counts, int *displs)
{
    for (int r = 0; r < size; r++) counts[r] = 0;
    for (int i = 0; i < n; i++) counts[owner[i]]++;
    int at = 0;
    for (int r = 0; r < size; r++) {
        displs[r] = at;
        at += counts[r];
    }
    for (int r = 0; r < size; r++) counts[r] = 0;
    for (int i = 0; i < n; i++) order[displs[owner[i]] + counts[owner[i]]++] = i;
    for (int r = 0; r < size; r++) {
        counts[r] *= width;
        displs[r] *= width;
    }
    return 0;
}

/* Node owners (the owner of the block of each node's first element, the
 * border of two ranks split between them, rank 0 for a node of no
 * element) and the marks of the elements this rank computes: its blocks'
 * and those touching a node it owns. */
static int assign_nodes_and_marks(rank_engine *re, const fdem_model *m, int32_t *node_owner)
{
    const int K = m->elem_nodes, E = m->elem_count;
    for (int i = 0; i < m->node_count; i++) node_owner[i] = -1;
    for (int e = 0; e < E; e++)
        for (int c = 0; c < K; c++) {
            int32_t n = m->elem_node[(size_t)K * e + c];
            if (node_owner[n] < 0) node_owner[n] = re->block_owner[block_of(re, e)];
        }
    if (rank_split_borders(m->elem_node, E, K, m->node_count, re->block_owner, re->block_size,
                           re->size, node_owner))
        return -1;
    long owned_nodes = 0;
    for (int i = 0; i < m->node_count; i++) {
        if (node_owner[i] < 0) node_owner[i] = 0;
        owned_nodes += node_owner[i] == re->rank;
    }
    long owned = 0, computed = 0;
    for (int e = 0; e < E; e++) {
        int own = re->block_owner[block_of(re, e)] == re->rank, touch = own;
        for (int c = 0; c < K && !touch; c++)
            touch = node_owner[m->elem_node[(size_t)K * e + c]] == re->rank;
        re->mark[e] = (uint8_t)touch;
        re->halo[e] = (uint8_t)(touch && !own);
        owned += own;
        computed += touch;
    }
    re->fig.owned_elements = owned;
    re->fig.computed_elements = computed;
    re->fig.owned_nodes = owned_nodes;
    return 0;
}

/* Rank 0 partitions the blocks and tells the others (one partition even if
 * METIS were to differ between machines). */
static int partition(rank_engine *re, const fdem_model *m)
{
    double t0 = MPI_Wtime();
    int rc = 0;
    if (re->rank == 0) {
        if (m->elem_plan.color_count == 0 || re->size == 1)
            memset(re->block_owner, 0, sizeof(int32_t) * (size_t)re->blocks);
        else
            rc = rank_partition_blocks(m->elem_node, m->elem_count, m->elem_nodes, m->node_count,
                                       re->block_size, re->blocks, re->size, re->block_owner);
    }
    MPI_Bcast(&rc, 1, MPI_INT, 0, re->comm);
    MPI_Bcast(re->block_owner, re->blocks, MPI_INT32_T, 0, re->comm);
    re->fig.partition_seconds = MPI_Wtime() - t0;
    return rc;
}

static int setup(rank_engine *re, fdem_model *m)
{
    const int N = m->node_count, D = re->dim;
    const scatter_plan *plan = &m->elem_plan;
    re->blocks = plan->color_count ? plan->block_count : 1;
    re->block_size = plan->color_count ? plan->block_size : (m->elem_count > 0 ? m->elem_count : 1);
    re->block_owner = malloc(sizeof(int32_t) * (size_t)re->blocks);
    re->block_order = malloc(sizeof(int32_t) * (size_t)re->blocks);
    re->block_counts = malloc(sizeof(int) * (size_t)re->size * 4);
    re->node_order = malloc(sizeof(int32_t) * ((size_t)N + 1));
    re->mark = malloc((size_t)m->elem_count + 1);
    re->halo = malloc((size_t)m->elem_count + 1);
    int32_t *node_owner = malloc(sizeof(int32_t) * ((size_t)N + 1));
    re->split = plan->color_count && rank_halo_wanted(m, re->size);
    /* block sums (the forces go where they lie: force_types) */
    re->send_len = re->recv_len = (size_t)SCATTER_SUMS * re->blocks + (size_t)re->size;
    re->send = malloc(sizeof(double) * re->send_len);
    re->recv = malloc(sizeof(double) * re->recv_len);
    re->force_type = malloc(sizeof(MPI_Datatype) * (size_t)re->size);
    re->flags = malloc(sizeof(double) * (size_t)re->size);
    re->requests = malloc(sizeof(MPI_Request) * 2 * (size_t)re->size);
    int rc = -1;
    if (!re->block_owner || !re->block_order || !re->block_counts || !re->node_order ||
        !re->mark || !re->halo || !node_owner || !re->send || !re->recv || !re->force_type ||
        !re->flags || !re->requests)
        goto done;
    re->block_displs = re->block_counts + re->size;
    re->node_counts = re->block_counts + 2 * re->size;
    re->node_displs = re->block_counts + 3 * re->size;
    if (partition(re, m)) goto done;
    if (m->elem_plan.color_count == 0) { /* no blocks: every rank computes every element */
        memset(re->mark, 1, (size_t)m->elem_count + 1);
        memset(re->halo, 0, (size_t)m->elem_count + 1);
        for (int i = 0; i < N; i++) node_owner[i] = 0;
        re->fig.owned_elements = re->rank == 0 ? m->elem_count : 0;
        re->fig.computed_elements = m->elem_count;
        re->fig.owned_nodes = re->rank == 0 ? N : 0;
    } else {
        if (assign_nodes_and_marks(re, m, node_owner)) goto done;
        if (re->split && rank_halo_setup(&re->border, m, re->comm, node_owner, re->block_owner,
                                         re->block_size))
            goto done;
    }
    list_by_owner(re->block_owner, re->blocks, re->size, SCATTER_SUMS, re->block_order,
                  re->block_counts, re->block_displs);
    list_by_owner(node_owner, N, re->size, D, re->node_order, re->node_counts, re->node_displs);
    if (!re->split && force_types(re, m)) goto done;
    re->fig.ranks = re->size;
    re->fig.blocks = re->blocks;
    re->fig.owned_blocks = re->block_counts[re->rank] / SCATTER_SUMS;
    const double others = re->size - 1;
    const double sums = m->elem_plan.color_count ? re->block_counts[re->rank] : 0;
    re->fig.bytes_sent_per_step = re->split ? re->border.bytes_per_step + others * 8.0 * sums
                                            : others * 8.0 * (re->node_counts[re->rank] + sums);
    re->fig.split_update = re->split;
    re->contact_split = m->contact.enabled && re->size > 1;
    if (re->contact_split) {
        re->contact_sizes = malloc(sizeof(long long) * (size_t)re->size);
        re->contact_from = malloc(sizeof(*re->contact_from) * (size_t)re->size);
        re->contact_bytes = malloc(sizeof(size_t) * (size_t)re->size);
        if (!re->contact_sizes || !re->contact_from || !re->contact_bytes) goto done;
    }
    re->fig.contact_split = re->contact_split;
    re->fig.kept_nodes = re->split ? re->border.kept_nodes : N;
    rc = 0;
done:
    free(node_owner);
    return rc;
}

rank_engine *rank_engine_create(fdem_model *m, MPI_Comm comm, fdem_error *err)
{
    rank_engine *re = calloc(1, sizeof *re);
    if (!re) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the rank engine");
        return NULL;
    }
    re->comm = comm;
    MPI_Comm_rank(comm, &re->rank);
    MPI_Comm_size(comm, &re->size);
    re->dim = m->dim;
    re->elem_count = m->elem_count;
    int ok = m->finalized && setup(re, m) == 0;
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_MIN, comm);
    if (!ok) {
        model_error(err, FDEM_ITEM_NONE, -1, "the rank engine could not be set up on %d ranks "
                    "(a model not finalized, or out of memory on some rank)", re->size);
        rank_engine_free(re);
        return NULL;
    }
    re->share = (step_share){.ctx = re, .elem_mark = re->mark, .block_sums = share_block_sums,
                             .forces_done = share_forces_done,
                             .node_mark = re->split ? re->border.node_mark : NULL,
                             .update_done = re->split ? share_update_done : NULL};
    re->halo_share = (step_share){.ctx = re, .elem_mark = re->halo};
    if (m->elem_plan.color_count == 0) re->share.block_sums = NULL;
    if (re->contact_split) {
        re->share.contact_ranks = re->size;
        re->share.contact_rank = re->rank;
        re->share.contact_gather = share_contact_gather;
    }
    return re;
}

/* A step that failed on this rank before the others' collectives of the
 * step: it takes part in them saying so, so that none waits for it. */
static void fail_collectives(rank_engine *re, fdem_model *m)
{
    if (re->contact_split && !re->contact_gathered) {
        const unsigned char *const *from;
        const size_t *size;
        share_contact_gather(re, NULL, 0, 0, 1, &from, &size);
    }
    if (!re->exchanged) {
        if (re->split) rank_halo_exchange(&re->border, m, 0);
        else exchange_forces(re, m, 0);
    }
    if (re->split && !re->agreed) {
        int any = 1;
        MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_MAX, re->comm);
    }
}

int rank_engine_step(rank_engine *re, fdem_model *m, fdem_error *err)
{
    re->exchanged = re->agreed = re->local_bad = re->others_bad = re->contact_gathered = 0;
    if (re->size == 1) return fdem_step(m, err); /* nothing to share */
    re->fault_step = m->step + 1;
    /* the rotation fault: each step another share of the pairs */
    if (re->contact_fault == RANK_CONTACT_FAULT_ROTATE) {
        re->contact_turn = (int)(m->step % re->size);
        re->share.contact_rank = (re->rank + re->contact_turn) % re->size;
    }
    m->share = &re->share; /* only while stepping: outside a step nothing is collective */
    int rc = fdem_step(m, err);
    m->share = NULL;
    re->fig.contact_pairs_walked = m->contact.pairs_walked;
    if (rc) fail_collectives(re, m);
    if (rc && re->others_bad) /* this rank's nodes are finite: say whose are not */
        model_error(err, FDEM_ITEM_NONE, -1, "the solution became non-finite at step %lld on "
                    "another rank (t = %.6g s, dt = %.6g s; the stable step is %.6g s): reduce "
                    "time.safety or check the material stiffness, penalty and applied loads",
                    (long long)m->step + 1, m->time + m->dt, m->dt, m->stable_dt);
    return rc;
}

/* The viscous history of each block from its owner to rank 0. */
int rank_engine_gather(rank_engine *re, fdem_model *m, fdem_error *err)
{
    if (re->contact_split) { /* the springs the walk updated in place, for rank 0's output */
        m->share = &re->share;
        re->gathering = 1;
        int rc = contact_springs_sync(m);
        re->gathering = 0;
        m->share = NULL;
        if (rc) {
            model_error(err, FDEM_ITEM_NONE, -1, "out of memory handing the ranks' contact "
                        "springs over");
            return -1;
        }
    }
    if (re->split &&
        rank_halo_gather(&re->border, m, re->node_order, re->node_counts, re->node_displs)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory gathering the ranks' nodes");
        return -1;
    }
    if (!m->elem_viscous || m->elem_plan.color_count == 0 || re->size == 1) return 0;
    const int C = model_stress_comps(m), me = re->rank;
    const size_t per_block = (size_t)C * re->block_size;
    int *counts = malloc(sizeof(int) * 2 * (size_t)re->size);
    double *all = me == 0 ? malloc(sizeof(double) * (size_t)C * m->elem_count + 1) : NULL;
    double *mine = malloc(sizeof(double) * (per_block * re->fig.owned_blocks + 1));
    int ok = counts && mine && (me != 0 || all);
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_MIN, re->comm);
    if (!ok) {
        free(counts), free(all), free(mine);
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory gathering the ranks' element state");
        return -1;
    }
    int *displs = counts + re->size, at = 0;
    for (int r = 0; r < re->size; r++) { /* each rank's blocks' elements, in block order */
        int n = 0;
        for (int k = re->block_displs[r] / SCATTER_SUMS;
             k < (re->block_displs[r] + re->block_counts[r]) / SCATTER_SUMS; k++) {
            int b = re->block_order[k], begin = b * re->block_size;
            int end = begin + re->block_size < m->elem_count ? begin + re->block_size
                                                             : m->elem_count;
            if (r == me)
                memcpy(mine + n, m->elem_viscous + (size_t)C * begin,
                       sizeof(double) * (size_t)C * (end - begin));
            n += C * (end - begin);
        }
        counts[r] = n;
        displs[r] = at;
        at += n;
    }
    MPI_Gatherv(mine, counts[me], MPI_DOUBLE, all, counts, displs, MPI_DOUBLE, 0, re->comm);
    if (me == 0) {
        size_t from = 0;
        for (int k = 0; k < re->blocks; k++) {
            int b = re->block_order[k], begin = b * re->block_size;
            int end = begin + re->block_size < m->elem_count ? begin + re->block_size
                                                             : m->elem_count;
            memcpy(m->elem_viscous + (size_t)C * begin, all + from,
                   sizeof(double) * (size_t)C * (end - begin));
            from += (size_t)C * (end - begin);
        }
    }
    free(counts), free(all), free(mine);
    return 0;
}

int rank_engine_lazy_step(void *ctx, fdem_model *m, fdem_error *err)
{
    rank_engine_lazy *lazy = ctx;
    if (lazy->re && lazy->model != m) rank_engine_lazy_free(lazy);
    if (!lazy->re) {
        if (!(lazy->re = rank_engine_create(m, lazy->comm, err))) return -1;
        lazy->model = m;
    }
    return rank_engine_step(lazy->re, m, err);
}

int rank_engine_lazy_gather(void *ctx, fdem_model *m, fdem_error *err)
{
    rank_engine_lazy *lazy = ctx;
    return lazy->re && lazy->model == m ? rank_engine_gather(lazy->re, m, err) : 0;
}

void rank_engine_lazy_free(rank_engine_lazy *lazy)
{
    rank_engine_free(lazy->re);
    lazy->re = NULL;
    lazy->model = NULL;
}

rank_figures rank_engine_figures(const rank_engine *re) { return re->fig; }

const uint8_t *rank_engine_node_mark(const rank_engine *re)
{
    return re->split ? re->border.node_mark : NULL;
}

/* Turning the fault on keeps only the owned blocks' marks in the pass
 * (the halo comes after, add_halo_after); it is never turned off. */
void rank_engine_set_border_order_fault(rank_engine *re, int on)
{
    if (!on || re->border_fault) return;
    re->border_fault = 1;
    for (int e = 0; e < re->elem_count; e++)
        if (re->halo[e]) re->mark[e] = 0;
}

void rank_engine_set_contact_fault(rank_engine *re, int fault) { re->contact_fault = fault; }

void rank_engine_free(rank_engine *re)
{
    if (!re) return;
    free(re->contact_sizes);
    free(re->contact_from);
    free(re->contact_bytes);
    free(re->contact_buf);
    free(re->block_owner);
    free(re->block_order);
    free(re->block_counts);
    free(re->node_order);
    free(re->mark);
    free(re->halo);
    free(re->send);
    free(re->recv);
    force_types_free(re);
    free(re->force_type);
    free(re->flags);
    free(re->requests);
    if (re->split) rank_halo_free(&re->border);
    free(re);
}
