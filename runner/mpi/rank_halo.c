/*
 * rank_halo.c - the split update (rank_halo.h): each rank integrates only
 * the nodes it keeps, and the forces cross only partition borders, point to
 * point.
 *
 * Why the bits stay the same. Every rank computes every element touching a
 * node it owns (rank_engine.c), so the owner's force of its node is the one
 * process's sum. A rank also computes halo elements whose other nodes it
 * does not own (ghosts): to compute them next step it needs the ghosts'
 * positions and velocities. Rather than receive those (2 dim doubles a
 * node), it receives the ghosts' whole forces from their owners (dim
 * doubles) and updates the ghosts itself: the central difference of a node
 * reads only that node's numbers, so it gives the owner's bits. Nodes every
 * rank reads after the forces (constraints' and boundary loads' nodes)
 * are kept by every rank the same way. What a rank neither owns nor keeps
 * goes stale on it; rank_halo_gather makes rank 0 whole before output.
 *
 * Which ranks keep a node: the ranks computing any element of the node
 * (the owner of the element's block and the owners of its nodes), its own
 * owner, and all ranks for a node every rank reads: a mask of up to 64
 * ranks per node, built alike on every rank from the same partition, so
 * the send list to a neighbour and that neighbour's receive list are the
 * same nodes in the same (ascending) order without any message.
 */
#include <stdlib.h>
#include <string.h>

#include "rank_halo.h"

#define HALO_TAG 3701

int rank_halo_wanted(const fdem_model *m, int ranks)
{
    if (ranks < 2 || ranks > 64 || m->elem_plan.color_count == 0) return 0;
    if (m->contact.enabled || m->joint_count || m->fluid || m->stage_count ||
        m->gravity_amplitude || m->fixed_parts || m->elem_active)
        return 0;
    for (int k = 0; k < m->part_count; k++)
        if (m->parts[k].fracture || m->parts[k].fixed) return 0;
    return 1;
}

/* keep[n]: bit r set when rank r keeps node n. */
static void ranks_keeping(const fdem_model *m, int size, const int32_t *node_owner,
                          const int32_t *block_owner, int block_size, uint64_t *keep)
{
    const int K = m->elem_nodes, D = m->dim;
    for (int n = 0; n < m->node_count; n++) keep[n] = (uint64_t)1 << node_owner[n];
    for (int e = 0; e < m->elem_count; e++) {
        const int32_t *node = m->elem_node + (size_t)K * e;
        uint64_t computing = (uint64_t)1 << block_owner[e / block_size];
        for (int c = 0; c < K; c++) computing |= (uint64_t)1 << node_owner[node[c]];
        for (int c = 0; c < K; c++) keep[node[c]] |= computing;
    }
    const uint64_t all = size == 64 ? ~(uint64_t)0 : ((uint64_t)1 << size) - 1;
    for (int i = 0; i < m->cnode_count; i++) keep[m->cnode[i]] = all;
    for (size_t i = 0; i < (size_t)D * (size_t)m->bfacet_count; i++) keep[m->bfacet_node[i]] = all;
}

/* The border lists: to each other rank the nodes this one owns and that
 * one keeps; from it the nodes it owns and this one keeps. */
static int border_lists(rank_halo *h, const fdem_model *m, const int32_t *node_owner,
                        const uint64_t *keep)
{
    const int N = m->node_count, me = h->rank, P = h->size;
    int *sends = calloc((size_t)P * 2, sizeof(int));
    if (!sends) return -1;
    int *recvs = sends + P;
    long sent = 0, received = 0;
    for (int n = 0; n < N; n++) {
        const int owner = node_owner[n];
        if (owner == me) {
            for (uint64_t k = keep[n] & ~((uint64_t)1 << me); k; k &= k - 1)
                sends[__builtin_ctzll(k)]++, sent++;
        } else if (keep[n] >> me & 1) {
            recvs[owner]++, received++;
        }
    }
    int neighbours = 0;
    for (int r = 0; r < P; r++) neighbours += sends[r] || recvs[r];
    h->neighbours = neighbours;
    h->peer = malloc(sizeof(int) * ((size_t)neighbours * 3 + 2));
    h->send_node = malloc(sizeof(int32_t) * ((size_t)sent + 1));
    h->recv_node = malloc(sizeof(int32_t) * ((size_t)received + 1));
    h->send_buf = malloc(sizeof(double) * ((size_t)h->dim * (size_t)sent + (size_t)neighbours + 1));
    h->recv_buf = malloc(sizeof(double) * ((size_t)h->dim * (size_t)received + (size_t)neighbours + 1));
    h->requests = malloc(sizeof(MPI_Request) * ((size_t)neighbours * 2 + 1));
    int rc = -1;
    if (!h->peer || !h->send_node || !h->recv_node || !h->send_buf || !h->recv_buf || !h->requests)
        goto done;
    h->send_begin = h->peer + neighbours;
    h->recv_begin = h->send_begin + neighbours + 1;
    int *slot = malloc(sizeof(int) * (size_t)P); /* rank -> neighbour index */
    if (!slot) goto done;
    int k = 0, s = 0, r = 0;
    for (int p = 0; p < P; p++) {
        slot[p] = -1;
        if (!sends[p] && !recvs[p]) continue;
        slot[p] = k;
        h->peer[k] = p;
        h->send_begin[k] = s;
        h->recv_begin[k] = r;
        s += sends[p];
        r += recvs[p];
        k++;
    }
    h->send_begin[neighbours] = s;
    h->recv_begin[neighbours] = r;
    for (int p = 0; p < P; p++) sends[p] = recvs[p] = 0; /* now: filled so far */
    for (int n = 0; n < N; n++) {
        const int owner = node_owner[n];
        if (owner == me) {
            for (uint64_t b = keep[n] & ~((uint64_t)1 << me); b; b &= b - 1) {
                int p = __builtin_ctzll(b);
                h->send_node[h->send_begin[slot[p]] + sends[p]++] = n;
            }
        } else if (keep[n] >> me & 1) {
            h->recv_node[h->recv_begin[slot[owner]] + recvs[owner]++] = n;
        }
    }
    free(slot);
    h->bytes_per_step = 8.0 * ((double)h->dim * (double)sent + neighbours);
    rc = 0;
done:
    free(sends);
    return rc;
}

int rank_halo_setup(rank_halo *h, const fdem_model *m, MPI_Comm comm, const int32_t *node_owner,
                    const int32_t *block_owner, int block_size)
{
    memset(h, 0, sizeof *h);
    h->comm = comm;
    MPI_Comm_rank(comm, &h->rank);
    MPI_Comm_size(comm, &h->size);
    h->dim = m->dim;
    const int N = m->node_count;
    uint64_t *keep = malloc(sizeof(uint64_t) * ((size_t)N + 1));
    h->node_mark = malloc((size_t)N + 1);
    int rc = -1;
    if (!keep || !h->node_mark) goto done;
    ranks_keeping(m, h->size, node_owner, block_owner, block_size, keep);
    for (int n = 0; n < N; n++) {
        h->node_mark[n] = (uint8_t)(keep[n] >> h->rank & 1);
        h->kept_nodes += h->node_mark[n];
    }
    rc = border_lists(h, m, node_owner, keep);
done:
    free(keep);
    return rc;
}

/* Offsets in the buffers: each neighbour's part is a flag, then its nodes. */
static inline size_t send_at(const rank_halo *h, int k)
{
    return (size_t)h->dim * (size_t)h->send_begin[k] + (size_t)k;
}

static inline size_t recv_at(const rank_halo *h, int k)
{
    return (size_t)h->dim * (size_t)h->recv_begin[k] + (size_t)k;
}

int rank_halo_exchange(rank_halo *h, fdem_model *m, int ok)
{
    const int D = h->dim, nb = h->neighbours;
    for (int k = 0; k < nb; k++) {
        int count = 1 + D * (h->recv_begin[k + 1] - h->recv_begin[k]);
        MPI_Irecv(h->recv_buf + recv_at(h, k), count, MPI_DOUBLE, h->peer[k], HALO_TAG, h->comm,
                  &h->requests[k]);
    }
    for (int k = 0; k < nb; k++) {
        double *out = h->send_buf + send_at(h, k);
        const int begin = h->send_begin[k], end = h->send_begin[k + 1];
        out[0] = ok;
        if (ok)
            for (int i = begin; i < end; i++)
                memcpy(out + 1 + (size_t)D * (i - begin), m->force + (size_t)D * h->send_node[i],
                       sizeof(double) * D);
        else
            memset(out + 1, 0, sizeof(double) * D * (size_t)(end - begin));
        MPI_Isend(out, 1 + D * (end - begin), MPI_DOUBLE, h->peer[k], HALO_TAG, h->comm,
                  &h->requests[nb + k]);
    }
    int rc = MPI_Waitall(2 * nb, h->requests, MPI_STATUSES_IGNORE);
    if (rc != MPI_SUCCESS) return -1;
    for (int k = 0; k < nb; k++)
        if (h->recv_buf[recv_at(h, k)] != 1) return -1;
    for (int k = 0; k < nb; k++) {
        const double *in = h->recv_buf + recv_at(h, k) + 1;
        const int begin = h->recv_begin[k], end = h->recv_begin[k + 1];
        for (int i = begin; i < end; i++)
            memcpy(m->force + (size_t)D * h->recv_node[i], in + (size_t)D * (i - begin),
                   sizeof(double) * D);
    }
    return 0;
}

/* Each rank's owned nodes (node_order, counts and offsets in units of dim
 * doubles, rank by rank) as position, velocity and force, to rank 0. */
int rank_halo_gather(const rank_halo *h, fdem_model *m, const int32_t *node_order,
                     const int *node_counts, const int *node_displs)
{
    const int D = h->dim, me = h->rank, P = h->size, W = 3 * D;
    const int count = node_counts[me] / D;
    const int32_t *mine = node_order + node_displs[me] / D;
    double *out = malloc(sizeof(double) * ((size_t)W * (size_t)count + 1));
    double *all = me == 0 ? malloc(sizeof(double) * ((size_t)W * (size_t)m->node_count + 1)) : NULL;
    int *counts = malloc(sizeof(int) * 2 * (size_t)P);
    int ok = out && counts && (me != 0 || all);
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_MIN, h->comm);
    if (!ok) {
        free(out), free(all), free(counts);
        return -1;
    }
    int *displs = counts + P;
    for (int r = 0; r < P; r++) {
        counts[r] = 3 * node_counts[r];
        displs[r] = 3 * node_displs[r];
    }
    const double *from[3] = {m->pos, m->vel, m->force};
    for (int i = 0; i < count; i++)
        for (int a = 0; a < 3; a++)
            memcpy(out + (size_t)W * i + (size_t)D * a, from[a] + (size_t)D * mine[i],
                   sizeof(double) * D);
    MPI_Gatherv(out, counts[me], MPI_DOUBLE, all, counts, displs, MPI_DOUBLE, 0, h->comm);
    if (me == 0) {
        double *to[3] = {m->pos, m->vel, m->force};
        for (int i = 0; i < m->node_count; i++) {
            const int32_t n = node_order[i];
            for (int a = 0; a < 3; a++)
                memcpy(to[a] + (size_t)D * n, all + (size_t)W * i + (size_t)D * a,
                       sizeof(double) * D);
        }
    }
    free(out), free(all), free(counts);
    return 0;
}

void rank_halo_free(rank_halo *h)
{
    free(h->peer);
    free(h->send_node);
    free(h->recv_node);
    free(h->send_buf);
    free(h->recv_buf);
    free(h->requests);
    free(h->node_mark);
    memset(h, 0, sizeof *h);
}
