/*
 * test_threads.c - the scatter plans that let threads share the per-step
 * loops: blocks of one colour never share a node, every block runs once, a
 * scattered mesh falls back to the serial loop, and a model stepped on two
 * threads ends in exactly the bits it reaches on one (elements, joints that
 * break, contact and friction, constraints).
 */
#include <stdint.h>
#include <string.h>

#include <stdlib.h>

#include "build_model.h"
#include "check.h"
#include "model/model.h"
#include "parallel/scatter_plan.h"

/* Every block appears once, and inside a colour no node is used by two
 * blocks. Returns the number of violations. */
static int plan_violations(const scatter_plan *plan, const int32_t *item_nodes, size_t stride,
                           int nodes_per_item, int node_count)
{
    int bad = 0;
    int32_t *owner = malloc(sizeof(int32_t) * (size_t)node_count);
    int32_t *seen = calloc((size_t)plan->block_count, sizeof(int32_t));
    for (int c = 0; c < plan->color_count; c++) {
        for (int i = 0; i < node_count; i++) owner[i] = -1;
        for (int k = plan->color_begin[c]; k < plan->color_begin[c + 1]; k++) {
            int b = plan->block_order[k];
            seen[b]++;
            int begin = b * plan->block_size;
            int end = begin + plan->block_size < plan->item_count ? begin + plan->block_size
                                                                  : plan->item_count;
            for (int it = begin; it < end; it++)
                for (int q = 0; q < nodes_per_item; q++) {
                    int32_t n = item_nodes[(size_t)it * stride + (size_t)q];
                    if (owner[n] >= 0 && owner[n] != b) bad++;
                    owner[n] = b;
                }
        }
    }
    for (int b = 0; b < plan->block_count; b++) bad += seen[b] != 1;
    free(owner);
    free(seen);
    return bad;
}

static void spatial_mesh_needs_few_colours(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 2700, 3e10, 0.25, 0, 0);
    build_rectangle(m, mat, 0, 0, 1, 1, 150, 100); /* 30000 elements, rows of 300 */
    build_finalize(m, 0.5);
    const scatter_plan *p = &m->elem_plan;
    CHECK(p->block_count == (30000 + SCATTER_BLOCK_ELEMENTS - 1) / SCATTER_BLOCK_ELEMENTS,
          "blocks %d", p->block_count);
    CHECK(p->color_count >= 2 && p->color_count <= 4, "colours %d", p->color_count);
    CHECK(plan_violations(p, m->elem[0].node, sizeof(element_hot) / sizeof(int32_t), 3,
                          m->node_count) == 0,
          "a colour has two blocks on one node");
    fdem_model_destroy(m);
}

/* Items in random order touch every block: the greedy colouring runs out
 * of its 64 colours, and the loop must then run serially (no plan). A
 * moderately scattered list still gets a valid plan. */
static void scattered_items_fall_back_or_stay_valid(void)
{
    enum { ITEMS = 200000, NODES = 3000 };
    int32_t *nodes = malloc(sizeof(int32_t) * 3 * ITEMS);
    uint64_t s = 88172645463325252ull;
    for (int i = 0; i < 3 * ITEMS; i++) {
        s ^= s << 13; s ^= s >> 7; s ^= s << 17;
        nodes[i] = (int32_t)(s % NODES);
    }
    scatter_plan plan = {0};
    CHECK(scatter_plan_build(&plan, ITEMS, 1024, nodes, 3, 3, NODES) == 0, "build");
    CHECK(plan.color_count == 0, "random items got %d colours", plan.color_count);
    /* the same items, but each block confined to its own band of nodes
     * except for a few shared with the next band */
    for (int i = 0; i < ITEMS; i++)
        for (int q = 0; q < 3; q++) {
            int band = i / 1024;
            nodes[3 * i + q] = (int32_t)((band * 10 + (nodes[3 * i + q] % 12)) % NODES);
        }
    CHECK(scatter_plan_build(&plan, ITEMS, 1024, nodes, 3, 3, NODES) == 0, "build");
    CHECK(plan.color_count > 0, "banded items got no plan");
    CHECK(plan_violations(&plan, nodes, 3, 3, NODES) == 0, "a colour has two blocks on one node");
    scatter_plan_free(&plan);
    free(nodes);
}

/* A block thrown at a fixed elastic wall: element forces, contact with
 * friction, a support and, when it fractures, joints that break. */
static fdem_model *impact_model(int threads, int fracture)
{
    fdem_model *m = fdem_model_create();
    int mr = build_fracturing_rock(m, 0.05);
    int mw = build_material(m, 7800, 2e11, 0.3, 0, 0.3);
    int block = build_rectangle_part(m, mr, 0, 0, 0.1, 0.1, 60, 60, fracture);
    int wall = build_rectangle(m, mw, -0.05, -0.021, 0.2, 0.02, 40, 4);
    build_fix_part(m, wall);
    fdem_set_part_velocity(m, block, 0.5, -40, NULL);
    fdem_set_gravity(m, 0, -9.81);
    build_finalize(m, 0.5);
    fdem_set_threads(m, threads);
    return m;
}

/* Steps the impact on one and on two threads side by side until it has
 * hit the wall (and broken joints, when it fractures). */
static void impact_on_one_and_two_threads(int fracture)
{
    fdem_model *one = impact_model(1, fracture), *two = impact_model(2, fracture);
    CHECK(fdem_get_threads(two) == 2, "threads %d", fdem_get_threads(two));
    /* private nodes: a fracturing part's element blocks share no node */
    CHECK(fracture ? one->elem_plan.color_count >= 1 && one->joint_sweep.block_count >= 2
                   : one->elem_plan.color_count >= 2,
          "the test needs planned loops: %d element colours, %d joint blocks",
          one->elem_plan.color_count, one->joint_sweep.block_count);
    fdem_error err;
    int steps = 0, touched = 0;
    while (steps < 600 || !touched || (fracture && fdem_get_counts(one).broken_joints == 0)) {
        if (fdem_step(one, &err) || fdem_step(two, &err)) build_die("step", &err);
        touched |= fdem_get_counts(one).contacts > 0;
        if (++steps > 20000) break;
    }
    fdem_counts c1 = fdem_get_counts(one), c2 = fdem_get_counts(two);
    CHECK(!fracture || c1.broken_joints > 0, "no joint broke in %d steps", steps);
    CHECK(touched, "never touched the wall in %d steps", steps);
    CHECK(c1.broken_joints == c2.broken_joints, "broken %d vs %d", c1.broken_joints,
          c2.broken_joints);
    size_t bytes = sizeof(double) * 2 * (size_t)one->node_count;
    CHECK(memcmp(one->pos, two->pos, bytes) == 0, "positions differ");
    CHECK(memcmp(one->vel, two->vel, bytes) == 0, "velocities differ");
    fdem_energy e1 = fdem_get_energy(one), e2 = fdem_get_energy(two);
    CHECK(memcmp(&e1, &e2, sizeof e1) == 0, "energies differ: kinetic %.17g vs %.17g",
          e1.kinetic, e2.kinetic);
    const joint_sweep *s2 = &two->joint_sweep;
    int slots = s2->slot_begin ? s2->slot_begin[s2->ranges] : 0;
    CHECK(!fracture || (s2->ranges == 2 && slots > 0), "joint ranges %d with %d slots",
          s2->ranges, slots);
    fprintf(stderr, "  %d steps, %d elements, %d joints (%d broken), %d element colours, %d joint "
            "ranges with %d slots\n", steps, c1.elements, c1.joints, c1.broken_joints,
            one->elem_plan.color_count, s2->ranges, slots);
    fdem_model_destroy(one);
    fdem_model_destroy(two);
}

static void two_threads_give_the_bits_of_one(void) { impact_on_one_and_two_threads(0); }
static void two_threads_give_the_bits_of_one_with_fracture(void)
{
    impact_on_one_and_two_threads(1);
}

/* Discs packed so that they touch from the first step, in a fixed box:
 * thousands of candidate pairs, so contact runs threaded too. */
static fdem_model *packed_discs(int threads)
{
    fdem_model *m = build_disc_pile(12, 10);
    fdem_set_threads(m, threads);
    return m;
}

/* Where two threads' shares of the near list meet, moved to a place of its
 * own each step (contact_walk.c balances them by the last step's CPU
 * seconds, so they fall anywhere): what a pair gives may not depend on it. */
static void shares_moved(fdem_model *m, int s)
{
    double *cut = m->contact.walk_cut[0];
    if (cut && m->contact.walk_cuts[0] == 2) cut[1] = 0.05 + 0.9 * (double)((s * 37) % 101) / 100;
}

static void contact_on_two_threads_gives_the_bits_of_one(void)
{
    fdem_model *one = packed_discs(1), *two = packed_discs(2), *moved = packed_discs(2);
    fdem_error err;
    for (int s = 0; s < 400; s++) {
        shares_moved(moved, s);
        if (fdem_step(one, &err) || fdem_step(two, &err) || fdem_step(moved, &err))
            build_die("step", &err);
    }
    fdem_counts c1 = fdem_get_counts(one), c2 = fdem_get_counts(two);
    /* contact.c evaluates pairs threaded from 2048 candidates on */
    CHECK(c1.contact_pairs >= 4096, "only %d candidate pairs", c1.contact_pairs);
    CHECK(c1.contacts > 100, "only %d pairs touching", c1.contacts);
    CHECK(c1.contacts == c2.contacts, "touching %d vs %d", c1.contacts, c2.contacts);
    /* the lists applied on the threads too, each to its own nodes
     * (contact_rows.c), on a mesh whose discs share nodes */
    CHECK(two->contact.apply_owner_threads == 2, "lists applied on %d threads",
          two->contact.apply_owner_threads);
    size_t bytes = sizeof(double) * 2 * (size_t)one->node_count;
    CHECK(memcmp(one->pos, two->pos, bytes) == 0, "positions differ");
    CHECK(memcmp(one->contact.force, two->contact.force, bytes) == 0, "contact forces differ");
    CHECK(moved->contact.walk_cuts[0] == 2, "the near list's shares were not cut");
    CHECK(memcmp(one->pos, moved->pos, bytes) == 0, "positions differ with the shares moved");
    CHECK(memcmp(one->vel, moved->vel, bytes) == 0, "velocities differ with the shares moved");
    fdem_energy e1 = fdem_get_energy(one), e2 = fdem_get_energy(two);
    CHECK(memcmp(&e1, &e2, sizeof e1) == 0, "energies differ: contact %.17g vs %.17g", e1.contact,
          e2.contact);
    fprintf(stderr, "  %d elements, %d candidate pairs, %d touching\n", c1.elements,
            c1.contact_pairs, c1.contacts);
    fdem_model_destroy(one);
    fdem_model_destroy(two);
    fdem_model_destroy(moved);
}

/* A pause, a restart or a memory-saving unload goes through a checkpoint:
 * the packed pile restored at step 300 (between two detections, with
 * thousands of candidate pairs and stick springs) reaches step 600 in the
 * bits of the run that never stopped, on two threads. */
static void restored_pile_gives_the_bits_of_one_run(void)
{
    fdem_model *run = packed_discs(2), *restored = packed_discs(2);
    fdem_error err;
    for (int s = 0; s < 300; s++)
        if (fdem_step(run, &err)) build_die("step", &err);
    size_t size = fdem_checkpoint_size(run);
    void *buf = malloc(size);
    CHECK(buf && fdem_checkpoint_write(run, buf, size) == 0, "checkpoint");
    CHECK(run->contact.max_disp2 > 0, "checkpoint right at a detection: nothing to test");
    if (buf && fdem_checkpoint_read(restored, buf, size, &err)) build_die("restore", &err);
    for (int s = 0; s < 300; s++)
        if (fdem_step(run, &err) || fdem_step(restored, &err)) build_die("step", &err);
    size_t bytes = sizeof(double) * 2 * (size_t)run->node_count;
    CHECK(memcmp(run->pos, restored->pos, bytes) == 0, "positions differ");
    CHECK(memcmp(run->vel, restored->vel, bytes) == 0, "velocities differ");
    fdem_energy e1 = fdem_get_energy(run), e2 = fdem_get_energy(restored);
    CHECK(memcmp(&e1, &e2, sizeof e1) == 0, "energies differ");
    CHECK(run->contact.detections == restored->contact.detections, "detections %ld vs %ld",
          run->contact.detections, restored->contact.detections);
    free(buf);
    fdem_model_destroy(run);
    fdem_model_destroy(restored);
}

CHECK_MAIN(T(spatial_mesh_needs_few_colours), T(scattered_items_fall_back_or_stay_valid),
           T(two_threads_give_the_bits_of_one), T(two_threads_give_the_bits_of_one_with_fracture),
           T(contact_on_two_threads_gives_the_bits_of_one),
           T(restored_pile_gives_the_bits_of_one_run))
