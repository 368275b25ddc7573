/*
 * test_contact_clearance.c - the contact stage skips a pair its kernel
 * found apart by a clearance (contact.c, pair_evaluate; contact_pair.h)
 * until the nodes' travel could close it. That is allowed only where the
 * kernel would have returned exactly what it returned then (no force,
 * every spring let go), so a run with the skips gives the bits of the same
 * run without them (contact.clearance_off), in both dimensions: a block
 * with every joint broken in place, squeezed so that its pieces press on
 * each other, and two blocks colliding. Each test also checks that the
 * skips happened (kernel calls saved), or it could not fail. A checkpoint
 * taken mid-run restores to the same bits (the clearances start afresh),
 * and the 3D broken block's run with the skips is on two threads. The
 * kernels' clearance alone (no forces) is their own figure.
 */
#include "broken_block.h"
#include "check.h"
#include "contact/contact_internal.h"
#include "fdem.h"
#include "model/model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Two blocks about to meet (the 2D pair of build_model.h, or its 3D like). */
static fdem_model *colliding_blocks(int dim)
{
    if (dim == 2) {
        int a, b;
        return build_colliding_blocks(&a, &b);
    }
    fdem_model *m = fdem_model_create();
    fdem_error err = {0};
    if (fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_material(m, 2700, 1e9, 0.25, 0, 0.3);
    const double oa[3] = {0, 0, 0}, sa[3] = {0.1, 0.05, 0.05}, ob[3] = {0.1002, 0.01, 0.01},
                 sb[3] = {0.06, 0.05, 0.05};
    const int da[3] = {4, 2, 2}, db[3] = {3, 2, 2};
    int a = build_box_at(m, mat, 3, oa, sa, da, 0), b = build_box_at(m, mat, 3, ob, sb, db, 0);
    const double va[3] = {2.0, 0.1, 0.05}, vb[3] = {-3.0, 0, 0};
    if (fdem_set_part_velocity_v(m, a, va, &err) || fdem_set_part_velocity_v(m, b, vb, &err))
        build_die("velocity", &err);
    build_finalize(m, 0.5);
    return m;
}

/* Near pairs the walk of the coming step skips on a clearance alone: their
 * boxes, as of now, overlap, so without the clearance the kernel would run. */
static int skipped_on_clearance(const fdem_model *m)
{
    const contact_state *cs = &m->contact;
    double apart = 2.0 * sqrt(cs->near_disp2) * (1 + 1e-9);
    int skipped = 0;
    for (size_t i = 0; i < cs->near_count; i++) {
        const near_pair *np = &cs->near[i];
        double ba[6] = {0}, bb[6] = {0};
        element_box(m, np->a, ba);
        element_box(m, np->b, bb);
        skipped += np->gap > apart && boxes_overlap(ba, bb, m->dim);
    }
    return skipped;
}

/* The model built twice, stepped `steps` times with the clearance skips
 * and without them (the first on 2 threads, its walks threaded from 64
 * pairs, when `threaded`): the same bits, contact made, and some kernel
 * calls skipped along the way: on a clearance, or by the pair's leaving
 * the near list once its clearance put it past the list's reach
 * (contact_near_compact). */
static void same_bits_with_and_without(fdem_model *(*build)(int), int dim, int steps,
                                       int threaded, const char *what)
{
    fdem_model *on = build(dim), *off = build(dim);
    off->contact.clearance_off = 1;
    if (threaded) {
        fdem_set_threads(on, 2);
        on->contact.walk_threads_min = 64;
    }
    fdem_error err = {0};
    long skipped = 0, touching = 0;
    for (int s = 0; s < steps; s++) {
        CHECK(fdem_step(on, &err) == 0 && fdem_step(off, &err) == 0, "step %d: %s", s, err.message);
        skipped += skipped_on_clearance(on);
        touching += on->contact.touching;
    }
    same_state_bits(on, off, what);
    CHECK(!threaded || on->contact.touch_lists >= 2, "%s: the walk never took threads", what);
    CHECK(touching > 0, "%s: no pair touched", what);
    long compacted = on->contact.near_compacted;
    CHECK(skipped + compacted > 0, "%s: no kernel call skipped on a clearance", what);
    CHECK(off->contact.near_compacted == 0, "%s: compacted without clearances", what);
    fprintf(stderr, "  %s: %ld pair-steps touching, %ld skipped on a clearance, %ld pairs "
            "compacted away\n", what, touching, skipped, compacted);
    fdem_model_destroy(on);
    fdem_model_destroy(off);
}

static fdem_model *broken_block_2d(int dim) { return broken_in_place_block(dim, 6, 20.0); }
static fdem_model *broken_block_3d(int dim) { return broken_in_place_block(dim, 4, 20.0); }

static void broken_block_2d_gives_the_same_bits(void)
{
    same_bits_with_and_without(broken_block_2d, 2, 200, 0, "2D broken block");
}

static void broken_block_3d_gives_the_same_bits(void)
{
    same_bits_with_and_without(broken_block_3d, 3, 40, 1, "3D broken block");
}

static void colliding_blocks_give_the_same_bits(void)
{
    same_bits_with_and_without(colliding_blocks, 2, 600, 0, "2D blocks colliding");
    same_bits_with_and_without(colliding_blocks, 3, 300, 0, "3D blocks colliding");
}

/* A checkpoint mid-run, while pairs are being skipped: the restored model
 * starts its near list (and so its clearances) afresh, and steps on to the
 * bits of the run that went on. */
static void restored_broken_block_steps_on_to_the_same_bits(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *a = dim == 2 ? broken_block_2d(2) : broken_block_3d(3);
        fdem_model *b = dim == 2 ? broken_block_2d(2) : broken_block_3d(3);
        fdem_error err = {0};
        for (int s = 0; s < 30; s++) CHECK(fdem_step(a, &err) == 0, "%s", err.message);
        CHECK(skipped_on_clearance(a) + a->contact.near_compacted > 0,
              "%dD: nothing skipped at the checkpoint", dim);
        size_t size = fdem_checkpoint_size(a);
        void *buf = malloc(size);
        CHECK(buf && fdem_checkpoint_write(a, buf, size) == 0, "write");
        CHECK(buf && fdem_checkpoint_read(b, buf, size, &err) == 0, "%s", err.message);
        free(buf);
        for (int s = 0; s < 30; s++) {
            CHECK(fdem_step(a, &err) == 0, "%s", err.message);
            CHECK(fdem_step(b, &err) == 0, "%s", err.message);
        }
        same_state_bits(a, b, dim == 2 ? "2D restored" : "3D restored");
        fdem_model_destroy(a);
        fdem_model_destroy(b);
    }
}

/* Two tetrahedra whose nearest parts are an edge of each, crossed: A's top
 * edge along x at z = 0, B's bottom edge along y at z = g. No face plane of
 * either separates them (each face through a crossing edge leans over the
 * other's), only the axis across the two edges does, g apart. The kernel
 * gives a clearance of g less its margin (before the edge axes, 0: a
 * broken block's pairs an element apart were clipped every step), and
 * pressed together (g < 0) it touches. */
static void orient(double *pos, int32_t *n)
{
    double e[3][3];
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) e[k][i] = pos[3 * n[k + 1] + i] - pos[3 * n[0] + i];
    double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                 e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                 e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    if (det < 0) {
        int32_t t = n[2];
        n[2] = n[3];
        n[3] = t;
    }
}

static void crossed_edges_give_a_clearance(void)
{
    const double gaps[] = {0.05, 1e-3, -0.01};
    for (int g = 0; g < 3; g++) {
        double z = gaps[g];
        double pos[24] = {-1, 0, 0,  1, 0, 0,  0, -1, -1,  0, 1, -1,
                          0, -1, z,  0, 1, z,  -1, 0, 1 + z,  1, 0, 1 + z};
        double vel[24] = {0};
        int32_t na[4] = {0, 1, 2, 3}, nb[4] = {4, 5, 6, 7};
        orient(pos, na);
        orient(pos, nb);
        contact_pair_in in = {pos, vel, na, nb, 1e9, 0.5, 1e-6, NULL, 1, 0};
        double springs[TET_CONTACT_SLOTS] = {0}, out[TET_PAIR_OUT];
        int touched = tet_contact_pair_force(&in, springs, out);
        if (z < 0) {
            CHECK(touched == 1, "pressed by %g: no touch", -z);
            continue;
        }
        double margin = 1e-8 * 2 + 1e-7 * sqrt(6); /* size 1 + z, longest edge sqrt(6) */
        CHECK(!touched, "%g apart: touched", z);
        CHECK(out[0] > z - 1.01 * margin && out[0] <= z, "%g apart: clearance %.17g, margin %g", z,
              out[0], margin);
    }
}

/* The kernels' clearance alone (contact_pair.h: a face or edge plane
 * that separates the pair, no forces) against the kernel's own answer
 * without the edge axes: the same figure for every pair apart, 0 for every
 * pair that touches. On the colliding blocks, mid-impact, every candidate
 * pair; some of each kind, or it could not fail. */
static void clearance_alone_is_the_kernels(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *m = colliding_blocks(dim);
        fdem_error err = {0};
        int apart = 0, touching = 0;
        for (int s = 0; s < (dim == 2 ? 600 : 300); s++) {
            CHECK(fdem_step(m, &err) == 0, "%s", err.message);
            if (s % 50) continue;
            const contact_state *cs = &m->contact;
            for (size_t k = 0; k < cs->pairs.count; k++) {
                contact_pair_in in = contact_pair_input(m, cs->pairs.a[k], cs->pairs.b[k],
                                                        m->dt, NULL);
                double springs[CONTACT_SLOTS_MAX] = {0}, out[CONTACT_PAIR_OUT_MAX];
                int touched = cs->kernel->pair_force(&in, springs, out);
                double alone = cs->kernel->pair_clearance(&in);
                CHECK(touched ? alone == 0 : alone == out[0],
                      "%dD pair %zu: touched %d, kernel %.17g, alone %.17g", dim, k, touched,
                      touched ? 0.0 : out[0], alone);
                apart += !touched && alone > 0;
                touching += touched;
            }
        }
        CHECK(apart > 0 && touching > 0, "%dD: %d apart with a clearance, %d touching", dim,
              apart, touching);
        fprintf(stderr, "  %dD: %d pair-looks apart with a clearance, %d touching\n", dim, apart,
                touching);
        fdem_model_destroy(m);
    }
}

CHECK_MAIN(T(clearance_alone_is_the_kernels), T(crossed_edges_give_a_clearance), T(broken_block_2d_gives_the_same_bits), T(broken_block_3d_gives_the_same_bits),
           T(colliding_blocks_give_the_same_bits),
           T(restored_broken_block_steps_on_to_the_same_bits))
