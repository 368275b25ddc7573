/*
 * rank_borders.h - who owns the nodes on the border of two ranks: one rule,
 * used by the rank engine (rank_engine.c) and by the partition bench
 * (bench/mpi/bench_partition.c), which measures the halo this rule gives
 * on meshes too large to step. Pure C, no MPI: the bench builds without it.
 *
 * Contract: owner[] holds, on entry, each node's provisional owner (the
 * part of its first element). Each node touched by the elements of exactly
 * two parts a < b goes to a if it is in the first half of that pair's
 * border nodes in node order, else to b. The owner of a node computes the
 * other part's elements around it, so a border given whole to one side
 * puts the whole halo on that side (5 % more elements on one of two ranks
 * for a 384k-tetrahedron box); meshes numbered in space order make each
 * half one piece of the border, so the halo splits in two rather than
 * growing. Element e's part is part_of_block[e / block_size]. Up to 64
 * parts (a mask per node); nothing changes for fewer than 2 or more than
 * 64. Returns 0, or -1 when out of memory (owner unchanged).
 */
#ifndef FDEM_RANK_BORDERS_H
#define FDEM_RANK_BORDERS_H

#include <stdint.h>
#include <stdlib.h>

static inline int rank_split_borders(const int32_t *elem_node, int elem_count, int K,
                                     int node_count, const int32_t *part_of_block,
                                     int block_size, int parts, int32_t *owner)
{
    if (parts > 64 || parts < 2) return 0;
    uint64_t *touch = calloc((size_t)node_count + 1, sizeof *touch);
    int *pair_count = calloc((size_t)parts * parts * 2, sizeof(int));
    if (!touch || !pair_count) {
        free(touch), free(pair_count);
        return -1;
    }
    int *pair_seen = pair_count + parts * parts;
    for (int e = 0; e < elem_count; e++)
        for (int c = 0; c < K; c++)
            touch[elem_node[(size_t)K * e + c]] |= (uint64_t)1 << part_of_block[e / block_size];
    for (int pass = 0; pass < 2; pass++)
        for (int n = 0; n < node_count; n++) {
            uint64_t t = touch[n];
            if (__builtin_popcountll(t) != 2) continue;
            int a = __builtin_ctzll(t), b = 63 - __builtin_clzll(t), k = a * parts + b;
            if (pass == 0) pair_count[k]++;
            else owner[n] = pair_seen[k]++ < pair_count[k] / 2 ? a : b;
        }
    free(touch), free(pair_count);
    return 0;
}

#endif /* FDEM_RANK_BORDERS_H */
