/*
 * rank_halo.h - the split update of the rank engine (rank_engine.c): which
 * nodes a rank updates and the point-to-point exchange of the forces its
 * neighbours need, in place of every force to every rank.
 *
 * Contract:
 *  - rank_halo_wanted says whether a model can take it: no contact, no
 *    joints or fracturing part, no fluid, stages, gravity amplitude or
 *    fixed part, at most 64 ranks. Those read or write nodes anywhere in the
 *    model after the forces (contact, the joint loop) or keep sums over all
 *    nodes (the gravity amplitude's momentum); they keep the replicated
 *    update.
 *  - rank_halo_setup (every rank, with the same owners) gives this rank's
 *    node marks: the nodes it owns, the nodes of every element it computes
 *    and the nodes every rank must hold (constraints' and boundary loads'),
 *    and the lists of border nodes each neighbour sends and receives, both
 *    ascending, so the two sides agree without talking.
 *  - rank_halo_exchange (collective over neighbours): each neighbour gets
 *    the forces of the nodes it keeps that this rank owns, led by a flag
 *    (0: this rank failed before; the receivers fail the step too).
 *    A node's force from its owner is whole (rank_engine.c), and a rank that
 *    keeps a node updates it from the same numbers as its owner: the same
 *    bits everywhere the node is kept.
 *  - rank_halo_gather (collective): rank 0 gets every node's position,
 *    velocity and force from its owner (what output and the energies read).
 */
#ifndef FDEM_RANK_HALO_H
#define FDEM_RANK_HALO_H

#include <mpi.h>
#include <stdint.h>
#include "model/model.h"

typedef struct rank_halo {
    MPI_Comm comm;
    int rank, size, dim;
    int neighbours;            /* ranks this one sends to or receives from */
    int *peer;                 /* per neighbour: its rank */
    int *send_begin, *recv_begin; /* neighbours + 1 offsets into send_node, recv_node */
    int32_t *send_node, *recv_node; /* border nodes, neighbour by neighbour, ascending */
    double *send_buf, *recv_buf; /* a flag and dim doubles a node, per neighbour */
    MPI_Request *requests;     /* 2 per neighbour */
    uint8_t *node_mark;        /* per node: this rank updates it */
    long kept_nodes;           /* nodes marked */
    double bytes_per_step;     /* what the force exchange sends */
} rank_halo;

int rank_halo_wanted(const fdem_model *m, int ranks);
int rank_halo_setup(rank_halo *h, const fdem_model *m, MPI_Comm comm, const int32_t *node_owner,
                    const int32_t *block_owner, int block_size);
int rank_halo_exchange(rank_halo *h, fdem_model *m, int ok);
int rank_halo_gather(const rank_halo *h, fdem_model *m, const int32_t *node_order,
                     const int *node_counts, const int *node_displs);
void rank_halo_free(rank_halo *h);

#endif
