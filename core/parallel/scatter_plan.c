/*
 * scatter_plan.c - lets several threads run a loop that adds into node
 * arrays (element forces) with no locks and no atomics. (The joint loop
 * has a plan of its own, joint_sweep.c, that keeps joint order.)
 *
 * Items (elements, nodes) are cut into blocks of consecutive items. Blocks
 * that share no node get the same colour, greedily in block order, using a
 * 64-bit mask per node of the colours already touching it. A step then runs
 * the colours one after another and the blocks of one colour side by side:
 * inside a colour no two blocks write the same node, and a barrier separates
 * colours. Inside a block the items keep their mesh order, so each thread
 * streams through memory as the serial loop does. Meshes in spatial order
 * (the generators, gmsh) need two to four colours; a mesh so scattered that
 * 64 colours do not suffice gets no blocks (color_count 0), and
 * scatter_plan_run then runs its items serially.
 *
 * The plan, not the thread count, fixes the order in which each node's sum
 * is formed (colour by colour, each block in item order), and per-block
 * partial sums are added in block order: a run gives the same bits on one
 * thread or on eight. When several processes share a step (step_share in
 * model/model.h), each runs the blocks it is given and a driver fills in
 * the others' block sums before the same totalling.
 */
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "scatter_plan.h"

void scatter_plan_free(scatter_plan *plan)
{
    free(plan->color_begin);
    free(plan->block_order);
    free(plan->block_sum);
    memset(plan, 0, sizeof *plan);
}

int scatter_block_size(int item_count, int smallest)
{
    int size = (item_count + SCATTER_TARGET_BLOCKS - 1) / SCATTER_TARGET_BLOCKS;
    return size > smallest ? size : smallest;
}

/* Greedy colouring of blocks; returns the number of colours, or 0 when some
 * block would need a 65th. color[b] gets each block's colour. */
static int scatter_color_blocks(int item_count, int block_size, const int32_t *item_nodes,
                                size_t stride, int nodes_per_item, int node_count,
                                uint64_t *node_mask, uint8_t *color)
{
    int block_count = (item_count + block_size - 1) / block_size, colors = 0;
    for (int b = 0; b < block_count; b++) {
        int begin = b * block_size, end = begin + block_size < item_count ? begin + block_size
                                                                          : item_count;
        uint64_t taken = 0;
        for (int i = begin; i < end; i++)
            for (int k = 0; k < nodes_per_item; k++) {
                int32_t n = item_nodes[(size_t)i * stride + (size_t)k];
                if (n >= 0 && n < node_count) taken |= node_mask[n];
            }
        if (taken == ~(uint64_t)0) return 0;
        int c = __builtin_ctzll(~taken);
        color[b] = (uint8_t)c;
        if (c + 1 > colors) colors = c + 1;
        uint64_t bit = (uint64_t)1 << c;
        for (int i = begin; i < end; i++)
            for (int k = 0; k < nodes_per_item; k++) {
                int32_t n = item_nodes[(size_t)i * stride + (size_t)k];
                if (n >= 0 && n < node_count) node_mask[n] |= bit;
            }
    }
    return colors;
}

/* Allocates the block order and sums for `colors` colours and sets the
 * sizes; block_order is filled by the caller. */
static int scatter_plan_alloc(scatter_plan *plan, int item_count, int block_size, int colors)
{
    int block_count = (item_count + block_size - 1) / block_size;
    plan->color_begin = calloc((size_t)colors + 1, sizeof *plan->color_begin);
    plan->block_order = malloc(sizeof *plan->block_order * (size_t)block_count);
    plan->block_sum = calloc(SCATTER_SUMS * (size_t)block_count, sizeof *plan->block_sum);
    if (!plan->color_begin || !plan->block_order || !plan->block_sum) {
        scatter_plan_free(plan);
        return -1;
    }
    plan->item_count = item_count;
    plan->block_size = block_size;
    plan->block_count = block_count;
    plan->color_count = colors;
    return 0;
}

int scatter_plan_build(scatter_plan *plan, int item_count, int block_size,
                       const int32_t *item_nodes, size_t stride, int nodes_per_item,
                       int node_count)
{
    scatter_plan_free(plan);
    if (item_count <= 0) return 0;
    int block_count = (item_count + block_size - 1) / block_size;
    uint64_t *mask = calloc((size_t)node_count + 1, sizeof *mask);
    uint8_t *color = malloc((size_t)block_count);
    int rc = -1;
    if (!mask || !color) goto done;
    int colors = scatter_color_blocks(item_count, block_size, item_nodes, stride, nodes_per_item,
                                      node_count, mask, color);
    rc = 0;
    if (colors == 0) { /* too scattered: no blocks, scatter_plan_run runs it serially */
        plan->item_count = item_count;
        goto done;
    }
    if ((rc = scatter_plan_alloc(plan, item_count, block_size, colors)) != 0) goto done;
    int32_t fill[64];
    for (int b = 0; b < block_count; b++) plan->color_begin[color[b] + 1]++;
    for (int c = 0; c < colors; c++) {
        plan->color_begin[c + 1] += plan->color_begin[c];
        fill[c] = plan->color_begin[c];
    }
    for (int b = 0; b < block_count; b++) plan->block_order[fill[color[b]]++] = b;
done:
    free(mask);
    free(color);
    return rc;
}

int scatter_plan_build_disjoint(scatter_plan *plan, int item_count, int block_size)
{
    scatter_plan_free(plan);
    if (item_count <= 0) return 0;
    if (scatter_plan_alloc(plan, item_count, block_size, 1)) return -1;
    plan->color_begin[1] = plan->block_count;
    for (int b = 0; b < plan->block_count; b++) plan->block_order[b] = b;
    return 0;
}

/* Runs block k of the colour-ordered list, leaving its partial sums in
 * block_sum. */
static inline void scatter_run_block(scatter_plan *plan, fdem_model *m, scatter_block_fn fn,
                                     int k)
{
    const int bs = plan->block_size, items = plan->item_count;
    int b = plan->block_order[k];
    int begin = b * bs, end = items - begin > bs ? begin + bs : items;
    double *sum = &plan->block_sum[SCATTER_SUMS * (size_t)b];
    for (int i = 0; i < SCATTER_SUMS; i++) sum[i] = 0;
    fn(m, begin, end, sum);
}

void scatter_plan_run(scatter_plan *plan, fdem_model *m, int threads, scatter_block_fn fn,
                      double totals[SCATTER_SUMS])
{
    if (plan->color_count == 0) { /* unplanned: every item, in order, on this thread */
        double sum[SCATTER_SUMS] = {0};
        if (plan->item_count > 0) fn(m, 0, plan->item_count, sum);
        scatter_sums_add(totals, sum);
        return;
    }
    if (threads > 1 && plan->block_count > 1) {
#pragma omp parallel num_threads(threads)
        for (int c = 0; c < plan->color_count; c++) {
#pragma omp for schedule(dynamic, 1)
            for (int k = plan->color_begin[c]; k < plan->color_begin[c + 1]; k++)
                scatter_run_block(plan, m, fn, k);
        }
    } else { /* the same blocks in the same order, without a thread team's start-up */
        for (int k = 0; k < plan->block_count; k++) scatter_run_block(plan, m, fn, k);
    }
    if (m->share && m->share->block_sums) /* blocks another process ran (model.h) */
        m->share->block_sums(m->share->ctx, m, plan);
    for (int b = 0; b < plan->block_count; b++) { /* block order: the same bits for any T */
        scatter_sums_add(totals, &plan->block_sum[SCATTER_SUMS * (size_t)b]);
    }
}
