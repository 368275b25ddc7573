/*
 * rank_partition.c - which rank owns which element block (rank_engine.c).
 *
 * The unit is the block of the model's element scatter plan, not the
 * element: a block's energy sums are one sequential sum in element order,
 * so the rank that forms them must compute the whole block (rank_engine.c).
 * The plan has at most SCATTER_TARGET_BLOCKS (64) blocks, so this graph is
 * tiny: vertices are blocks weighted by their elements, edges join blocks
 * that share nodes, weighted by how many (each shared node is a halo
 * element or more to compute twice and a force to send). METIS k-way cuts
 * it; if METIS fails or there are no more blocks than parts, runs of
 * consecutive blocks (the generators and gmsh number elements in space
 * order, so a run is a slab) are the fallback.
 */
#include <metis.h>
#include <stdlib.h>
#include <string.h>

#include "rank_engine.h"

/* Consecutive runs of blocks, as even as whole blocks allow. */
static void partition_runs(int blocks, int parts, int32_t *owner)
{
    for (int b = 0; b < blocks; b++) owner[b] = (int32_t)((long)b * parts / blocks);
}

/* weight[a * blocks + b]: the nodes blocks a and b share (a != b), from a
 * mask per node of the blocks touching it (blocks <= 64). */
static int shared_nodes(const int32_t *elem_node, int elem_count, int K, int node_count,
                        int block_size, int blocks, idx_t *weight)
{
    uint64_t *touch = calloc((size_t)node_count + 1, sizeof *touch);
    if (!touch) return -1;
    for (int e = 0; e < elem_count; e++)
        for (int c = 0; c < K; c++) touch[elem_node[(size_t)K * e + c]] |= (uint64_t)1 << (e / block_size);
    memset(weight, 0, sizeof(idx_t) * (size_t)blocks * blocks);
    for (int n = 0; n < node_count; n++) {
        uint64_t t = touch[n];
        if (!(t & (t - 1))) continue; /* one block or none */
        for (uint64_t a = t; a; a &= a - 1)
            for (uint64_t b = t; b; b &= b - 1) {
                int i = __builtin_ctzll(a), j = __builtin_ctzll(b);
                if (i != j) weight[i * blocks + j]++;
            }
    }
    free(touch);
    return 0;
}

int rank_partition_blocks(const int32_t *elem_node, int elem_count, int K, int node_count,
                          int block_size, int blocks, int parts, int32_t *owner)
{
    if (parts <= 1 || blocks <= parts || blocks > 64) {
        if (parts <= 1) memset(owner, 0, sizeof(int32_t) * (size_t)blocks);
        else partition_runs(blocks, blocks < parts ? blocks : parts, owner);
        return 0;
    }
    idx_t n = blocks, ncon = 1, np = parts, cut = 0, options[METIS_NOPTIONS];
    idx_t *weight = malloc(sizeof(idx_t) * (size_t)blocks * blocks);
    idx_t *xadj = malloc(sizeof(idx_t) * ((size_t)blocks + 1));
    idx_t *adj = malloc(sizeof(idx_t) * (size_t)blocks * blocks);
    idx_t *adjw = malloc(sizeof(idx_t) * (size_t)blocks * blocks);
    idx_t *vw = malloc(sizeof(idx_t) * (size_t)blocks), *part = malloc(sizeof(idx_t) * (size_t)blocks);
    int rc = -1;
    if (!weight || !xadj || !adj || !adjw || !vw || !part ||
        shared_nodes(elem_node, elem_count, K, node_count, block_size, blocks, weight))
        goto done;
    idx_t edges = 0;
    for (int a = 0; a < blocks; a++) {
        xadj[a] = edges;
        int end = (a + 1) * block_size < elem_count ? (a + 1) * block_size : elem_count;
        vw[a] = end - a * block_size;
        for (int b = 0; b < blocks; b++)
            if (weight[a * blocks + b]) {
                adj[edges] = b;
                adjw[edges++] = weight[a * blocks + b];
            }
    }
    xadj[blocks] = edges;
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_CONTIG] = 0;
    if (METIS_PartGraphKway(&n, &ncon, xadj, adj, vw, NULL, adjw, &np, NULL, NULL, options, &cut,
                            part) == METIS_OK) {
        for (int b = 0; b < blocks; b++) owner[b] = (int32_t)part[b];
    } else {
        partition_runs(blocks, parts, owner);
    }
    rc = 0;
done:
    free(weight), free(xadj), free(adj), free(adjw), free(vw), free(part);
    return rc;
}
