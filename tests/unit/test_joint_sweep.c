/*
 * test_joint_sweep.c - the joint loop on several threads (joint_sweep.c)
 * adds every node's joint forces in joint order, as one thread does: the
 * same forces, damage and sums, bit for bit, on 1, 2 and 3 threads, in 2D
 * and 3D, with the faces set aside for another range's owner (slots)
 * actually taken.
 *
 * The models are fracturing blocks whose nodes are shaken at random so
 * that every joint carries a force (elastic, softening or breaking), and
 * whose force array starts from random values, as the element pass leaves
 * it: a node's sum then depends on the order its joints are added in, which
 * an impact's quiet regions would not show.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "build_model.h"
#include "check.h"
#include "model/model.h"
#include "joint/joint.h"

/* A fracturing block of some 3000 elements (three or more joint blocks):
 * 2D 40 x 40 squares of two triangles, 3D 8^3 cubes of six tetrahedra. */
static fdem_model *shaken_block(int dim)
{
    fdem_model *m = fdem_model_create();
    fdem_error err = {0};
    if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_fracturing_rock(m, 0.1);
    const double size_2d[3] = {0.4, 0.4, 0}, size_3d[3] = {0.08, 0.08, 0.08};
    const int div_2d[3] = {40, 40, 0}, div_3d[3] = {8, 8, 8};
    build_box_part(m, mat, dim, dim == 2 ? size_2d : size_3d, dim == 2 ? div_2d : div_3d, 1);
    build_finalize(m, 0.5);
    /* gaps around the tensile strength: most joints elastic, some past it,
     * a few (the nodes moved 2000 times as far) past the softening span */
    double limit = 1e6 / m->joint_k[0];
    uint64_t state = 2024;
    for (int i = 0; i < dim * m->node_count; i++) {
        m->pos[i] += (i % 149 == 0 ? 2000 : i % 5 == 0 ? 2 : 0.2) * limit * build_uniform(&state);
        m->vel[i] = 0.01 * build_uniform(&state);
        m->force[i] = 1e3 * build_uniform(&state);
    }
    for (int j = 0; j < m->joint_count; j += 11) m->joint_damage[j] = 0.4;
    return m;
}

static int slot_count(const joint_sweep *s)
{
    return s->slot_begin ? s->slot_begin[s->ranges] : 0;
}

static void joint_pass(fdem_model *m, double sums[SCATTER_SUMS])
{
    if (m->dim == 3) joint_sweep_run(m, joint_forces_range_3d, joint_forces_one_3d, sums);
    else joint_sweep_run(m, joint_forces_range_2d, joint_forces_one_2d, sums);
}

static void threads_give_the_bits_of_one(int dim)
{
    fdem_model *one = shaken_block(dim);
    double sums_one[SCATTER_SUMS] = {0};
    joint_pass(one, sums_one);
    int D = dim, broke = (int)sums_one[0], damaged = 0;
    for (int j = 0; j < one->joint_count; j++) damaged += one->joint_damage[j] > 0;
    CHECK(one->joint_sweep.block_count >= 3 && broke > 0 && damaged > broke,
          "%dD: the test needs 3 joint blocks and joints that soften and break: %d blocks, "
          "%d damaged, %d broke", dim, one->joint_sweep.block_count, damaged, broke);
    for (int threads = 2; threads <= 3; threads++) {
        fdem_model *many = shaken_block(dim);
        fdem_set_threads(many, threads);
        double sums[SCATTER_SUMS] = {0};
        joint_pass(many, sums);
        const joint_sweep *s = &many->joint_sweep;
        CHECK(s->ranges == threads && slot_count(s) > 0, "%dD, %d threads: %d ranges, %d slots",
              dim, threads, s->ranges, slot_count(s));
        size_t bytes = sizeof(double) * (size_t)D * (size_t)one->node_count;
        int differ = 0;
        for (size_t i = 0; i < bytes / sizeof(double); i++)
            differ += memcmp(&one->force[i], &many->force[i], sizeof(double)) != 0;
        CHECK(differ == 0, "%dD, %d threads: %d force components differ", dim, threads, differ);
        CHECK(memcmp(one->joint_damage, many->joint_damage,
                     sizeof(double) * (size_t)one->joint_count) == 0,
              "%dD, %d threads: damage differs", dim, threads);
        CHECK(memcmp(sums_one, sums, sizeof sums) == 0,
              "%dD, %d threads: sums differ (stored %.17g vs %.17g)", dim, threads, sums_one[1],
              sums[1]);
        fprintf(stderr, "  %dD, %d threads: %d joints in %d blocks, %d ranges, %d slots; %d broke, "
                "%d damaged\n", dim, threads, many->joint_count, s->block_count, s->ranges,
                slot_count(s), broke, damaged);
        fdem_model_destroy(many);
    }
    fdem_model_destroy(one);
}

/* One thread walks the joints in joint order: the plain loop over all of
 * them gives the same bits. */
static void one_thread_walks_in_joint_order(int dim)
{
    fdem_model *swept = shaken_block(dim), *plain = shaken_block(dim);
    double sums_swept[SCATTER_SUMS] = {0}, sums_plain[SCATTER_SUMS] = {0};
    joint_pass(swept, sums_swept);
    (dim == 3 ? joint_forces_range_3d : joint_forces_range_2d)(plain, 0, plain->joint_count,
                                                               sums_plain);
    size_t bytes = sizeof(double) * (size_t)dim * (size_t)swept->node_count;
    CHECK(memcmp(swept->force, plain->force, bytes) == 0, "%dD: forces differ", dim);
    /* the sums alone are formed per block, then totalled: the broken count
     * agrees exactly, the stored energy to rounding */
    CHECK(sums_swept[0] == sums_plain[0], "%dD: %g vs %g broke", dim, sums_swept[0],
          sums_plain[0]);
    fdem_model_destroy(swept);
    fdem_model_destroy(plain);
}

/* The thread count changed between passes (a case resumed with another
 * --threads): the sweep is cut again each time, and the forces stay those
 * of one thread pass after pass. */
static void changing_threads_between_passes_keeps_the_bits(int dim)
{
    fdem_model *one = shaken_block(dim), *varied = shaken_block(dim);
    const int threads[] = {2, 1, 3, 2};
    for (int pass = 0; pass < 4; pass++) {
        fdem_set_threads(varied, threads[pass]);
        double sums_one[SCATTER_SUMS] = {0}, sums[SCATTER_SUMS] = {0};
        joint_pass(one, sums_one);
        joint_pass(varied, sums);
        CHECK(varied->joint_sweep.ranges == threads[pass], "%dD pass %d: %d ranges for %d threads",
              dim, pass, varied->joint_sweep.ranges, threads[pass]);
        size_t bytes = sizeof(double) * (size_t)dim * (size_t)one->node_count;
        CHECK(memcmp(one->force, varied->force, bytes) == 0 &&
                  memcmp(sums_one, sums, sizeof sums) == 0,
              "%dD pass %d on %d threads: forces or sums differ", dim, pass, threads[pass]);
    }
    fdem_model_destroy(one);
    fdem_model_destroy(varied);
}

static void changing_threads_keeps_the_bits_2d(void) { changing_threads_between_passes_keeps_the_bits(2); }
static void changing_threads_keeps_the_bits_3d(void) { changing_threads_between_passes_keeps_the_bits(3); }

static void threads_give_the_bits_of_one_2d(void) { threads_give_the_bits_of_one(2); }
static void threads_give_the_bits_of_one_3d(void) { threads_give_the_bits_of_one(3); }
static void one_thread_walks_in_joint_order_2d(void) { one_thread_walks_in_joint_order(2); }
static void one_thread_walks_in_joint_order_3d(void) { one_thread_walks_in_joint_order(3); }

CHECK_MAIN(T(threads_give_the_bits_of_one_2d), T(threads_give_the_bits_of_one_3d),
           T(one_thread_walks_in_joint_order_2d), T(one_thread_walks_in_joint_order_3d),
           T(changing_threads_keeps_the_bits_2d), T(changing_threads_keeps_the_bits_3d))
