/*
 * scatter_plan.h - the per-step loops over elements and nodes on any
 * thread count with the same bits: items cut into blocks, blocks coloured
 * so that no two of one colour share a node (threads run a colour's blocks
 * side by side and add into node arrays without races), and each block's
 * sums totalled in block order. Reads the model only to hand it to the
 * block function; the plan itself lives in the model (model/model.h).
 */
#ifndef FDEM_SCATTER_PLAN_H
#define FDEM_SCATTER_PLAN_H

#include "model/model.h"

/* scatter_plan.c: fn runs items [begin, end) of one block and may add into
 * node arrays. It starts from sums zeroed and leaves its block's partial
 * results there: sums[0 .. SCATTER_MAX - 1] are added, block by block in
 * block order, to the same totals; each totals[i] from SCATTER_MAX on
 * becomes the largest sums[i] (and what it held before, if larger). */
typedef void (*scatter_block_fn)(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS]);
/* Smallest blocks, and the block count aimed at above that: a node on the
 * border of two colours is loaded once per colour, so large meshes get
 * blocks many rows deep (few border nodes), while 64 blocks still spread
 * over any core count this daemon meets. */
#define SCATTER_BLOCK_ELEMENTS 1024
#define SCATTER_BLOCK_JOINTS 2048
#define SCATTER_BLOCK_NODES 4096
#define SCATTER_TARGET_BLOCKS 64
int scatter_block_size(int item_count, int smallest);
int scatter_plan_build(scatter_plan *plan, int item_count, int block_size,
                       const int32_t *item_nodes, size_t stride, int nodes_per_item,
                       int node_count);
int scatter_plan_build_disjoint(scatter_plan *plan, int item_count, int block_size);
void scatter_plan_run(scatter_plan *plan, fdem_model *m, int threads, scatter_block_fn fn,
                      double totals[SCATTER_SUMS]);
void scatter_plan_free(scatter_plan *plan);
/* One block's partial results into the totals, as the comment on
 * scatter_block_fn says. */
static inline void scatter_sums_add(double totals[SCATTER_SUMS], const double sum[SCATTER_SUMS])
{
    for (int i = 0; i < SCATTER_MAX; i++) totals[i] += sum[i];
    for (int i = SCATTER_MAX; i < SCATTER_SUMS; i++)
        if (sum[i] > totals[i]) totals[i] = sum[i];
}

/* A block of a step shared between processes (model.h, step_share): fn
 * over each run of the items in [begin, end) this process marks, in item
 * order, into the block's sums. */
static inline void scatter_marked_runs(fdem_model *m, const uint8_t *mark, int begin, int end,
                                       scatter_block_fn fn, double sums[SCATTER_SUMS])
{
    int stop;
    for (int i = share_next_run(mark, begin, end, &stop); i < end;
         i = share_next_run(mark, stop, end, &stop))
        fn(m, i, stop, sums);
}

#endif
