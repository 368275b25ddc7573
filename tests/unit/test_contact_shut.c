/*
 * test_contact_shut.c - the contact stage on shut broken joints
 * (contact/contact_shut.c), 2D and 3D, on a block with every joint broken
 * in place and squeezed: the shut path engages (shut elements, face-kernel
 * pairs touching, the edge and corner pairs left out); a run on 2 threads
 * (the walk, its lists' application, the shut marks all threaded)
 * and a run restored from a mid-run checkpoint give the bits of the run on
 * 1 thread; the same block with every vertex copy moved 2 tolerances apart
 * never engages it and gives the bits of a run with it switched off (the
 * general path untouched); and the shut run stays close to the general
 * kernel's run (the kernels agree to O(s / h)); and a shut block
 * computes no element's box, from a restore too.
 */
#include "broken_block.h"
#include "check.h"
#include "contact/contact_internal.h"
#include "fdem.h"
#include "model/model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* broken_block.h's block broken in place; `apart` moves each vertex copy
 * but the first by that many tolerances. */
static fdem_model *broken_block(int dim, int n, double squeeze, double apart)
{
    fdem_model *m = broken_in_place_block(dim, n, squeeze);
    if (apart > 0) {
        const contact_state *cs = &m->contact;
        for (int i = 0; i < m->node_count; i++) {
            if (cs->shut_first[i] == i) continue;
            double step = apart * sqrt(cs->shut_tol2[cs->shut_first[i]]);
            /* a direction of its own per node, never along a face */
            m->pos[(size_t)dim * i] += step * (0.6 + 0.1 * (i % 3));
            m->pos[(size_t)dim * i + 1] += step * (0.8 - 0.1 * (i % 5));
        }
    }
    return m;
}

static int shut_elements(const fdem_model *m)
{
    const contact_state *cs = &m->contact;
    int n = 0;
    if (cs->shut_any)
        for (int e = 0; e < m->elem_count; e++) n += cs->elem_shut[e];
    return n;
}

static int step_both(fdem_model *a, fdem_model *b)
{
    fdem_error err = {0};
    int ok = fdem_step(a, &err) == 0;
    CHECK(ok, "%s", err.message);
    ok = ok && fdem_step(b, &err) == 0;
    CHECK(ok, "%s", err.message);
    return ok;
}

/* 1 thread against 2, and against a restore of a checkpoint taken at half
 * way: the same bits, with shut elements all along. */
static void shut_path_keeps_the_bits(int dim, int n, int steps)
{
    fdem_model *one = broken_block(dim, n, 2.0, 0), *two = broken_block(dim, n, 2.0, 0);
    fdem_model *restored = broken_block(dim, n, 2.0, 0);
    fdem_set_threads(two, 2);
    long shut = 0, touching = 0;
    for (int s = 0; s < steps; s++) {
        if (!step_both(one, two)) break;
        shut += shut_elements(one);
        touching += one->contact.touching;
        if (s == steps / 2) {
            size_t size = fdem_checkpoint_size(one);
            void *buf = malloc(size);
            fdem_error err = {0};
            CHECK(buf && fdem_checkpoint_write(one, buf, size) == 0, "write");
            CHECK(buf && fdem_checkpoint_read(restored, buf, size, &err) == 0, "%s", err.message);
            free(buf);
        } else if (s > steps / 2) {
            fdem_error err = {0};
            CHECK(fdem_step(restored, &err) == 0, "%s", err.message);
        }
    }
    /* both walks (the near list, the vertex pairs: contact.c) on threads,
     * their lists applied on threads (contact_rows.c), and the shut marks
     * and the force array's clearing on threads */
    CHECK(two->contact.near_count >= 2048 && two->contact.near_vertex_count >= 2048,
          "%dD: %zu near and %zu vertex pairs: the threaded walks need 2048", dim,
          two->contact.near_count, two->contact.near_vertex_count);
    CHECK(dim == 3 || (two->node_count > CONTACT_THREADED_NODES &&
                       two->contact.apply_owner_threads == 2),
          "%dD: %d nodes, lists applied on %d threads: the threaded marks need %d", dim,
          two->node_count, two->contact.apply_owner_threads, CONTACT_THREADED_NODES);
    CHECK(shut >= (long)steps * one->elem_count / 2, "%dD: %ld element-steps shut of %ld", dim,
          shut, (long)steps * one->elem_count);
    CHECK(touching > 0, "%dD: no pair touched", dim);
    fprintf(stderr, "  %dD: %ld of %ld element-steps shut, %ld pair-steps touching\n", dim, shut,
            (long)steps * one->elem_count, touching);
    same_state_bits(one, two, dim == 2 ? "2D, 2 threads" : "3D, 2 threads");
    same_state_bits(one, restored, dim == 2 ? "2D, restored" : "3D, restored");
    fdem_model_destroy(one);
    fdem_model_destroy(two);
    fdem_model_destroy(restored);
}

static void shut_broken_block_same_bits_on_threads_and_restore(void)
{
    /* 2D: 7,200 triangles, 21,600 nodes (past CONTACT_THREADED_NODES) */
    shut_path_keeps_the_bits(2, 60, 40);
    shut_path_keeps_the_bits(3, 5, 12);
}

/* Every stride-th vertex copy moved by 3 tolerances, or back: the
 * elements around it open, or shut again. */
static void nudge_copies(fdem_model *m, double sign, int stride)
{
    const contact_state *cs = &m->contact;
    for (int i = 0; i < m->node_count; i += stride)
        if (cs->shut_first[i] != i)
            m->pos[(size_t)m->dim * i] += sign * 3 * sqrt(cs->shut_tol2[cs->shut_first[i]]);
}

/* The vertex pairs walked only where an element is not shut now or was
 * not last step (contact_near.c) against every one of them every step, on
 * the block squeezed and sheared, with copies nudged open for a few steps
 * and back (so elements shut again and pairs that took springs meanwhile
 * come to be left out, and must let them go): the same bits and the same
 * checkpoint (which holds the springs), with steps that walked some of the
 * pairs but not all and elements due only for last step (or it could not
 * fail), 1 thread and 2. */
static void vertex_pairs_walked_where_due_give_the_same_bits(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        int n = dim == 2 ? 8 : 3, steps = dim == 2 ? 200 : 60;
        fdem_model *due = broken_block(dim, n, 2.0, 0), *every = broken_block(dim, n, 2.0, 0);
        fdem_model *two = broken_block(dim, n, 2.0, 0);
        every->contact.vertex_skip_off = 1;
        fdem_set_threads(two, 2);
        long walked = 0, held = 0, partial = 0, back = 0;
        for (int s = 0; s < steps; s++) {
            if (s == steps / 4 || s == steps / 4 + 3)
                for (int k = 0; k < 3; k++)
                    nudge_copies(k == 0 ? due : k == 1 ? every : two, s == steps / 4 ? 1 : -1,
                                 dim == 2 ? 7 : 61);
            if (!step_both(due, every)) break;
            fdem_error err = {0};
            CHECK(fdem_step(two, &err) == 0, "%s", err.message);
            const contact_state *cs = &due->contact;
            size_t w = cs->vertex_walk_count, h = cs->near_vertex_count;
            walked += (long)w;
            held += (long)h;
            partial += w > 0 && w < h;
            for (int k = 0; k < cs->elem_due_count; k++) back += cs->elem_shut[cs->elem_due[k]];
        }
        CHECK(walked < held, "%dD: %ld of %ld vertex pair-steps walked", dim, walked, held);
        CHECK(partial > 0, "%dD: no step walked some vertex pairs but not all", dim);
        CHECK(back > 0, "%dD: no element shut again", dim);
        fprintf(stderr, "  %dD: %ld of %ld vertex pair-steps walked, %ld steps in part, %ld elements "
                "shut again\n", dim, walked, held, partial, back);
        same_state_bits(due, every, dim == 2 ? "2D, vertex pairs where due" : "3D, where due");
        same_state_bits(due, two, dim == 2 ? "2D, where due, 2 threads" : "3D, 2 threads");
        size_t size = fdem_checkpoint_size(due);
        CHECK(size == fdem_checkpoint_size(every), "%dD: checkpoint sizes differ", dim);
        void *a = malloc(size), *b = malloc(size);
        CHECK(a && b && fdem_checkpoint_write(due, a, size) == 0 &&
                  fdem_checkpoint_write(every, b, size) == 0 && memcmp(a, b, size) == 0,
              "%dD: the checkpoints (springs) differ", dim);
        free(a);
        free(b);
        fdem_model_destroy(due);
        fdem_model_destroy(every);
        fdem_model_destroy(two);
    }
}

/* The first look at two shut elements that share no vertex (contact_walk.c,
 * pair_first_met: 2D an edge line's clearance before the kernel, 3D the
 * edge-edge planes before clipping) against the kernel alone, on the block
 * squeezed and sheared, restored half way (a restore rebuilds the list,
 * so the looks run again): the same bits, with looks that decided pairs
 * (or it could not fail). */
static void first_look_gives_the_kernels_bits(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        int n = dim == 2 ? 8 : 3, steps = dim == 2 ? 200 : 60;
        fdem_model *look = broken_block(dim, n, 2.0, 0), *whole = broken_block(dim, n, 2.0, 0);
        whole->contact.first_look_off = 1;
        for (int s = 0; s < steps && step_both(look, whole); s++) {
            if (s != steps / 2) continue;
            size_t size = fdem_checkpoint_size(look);
            void *buf = malloc(size);
            fdem_error err = {0};
            CHECK(buf && fdem_checkpoint_write(look, buf, size) == 0, "write");
            CHECK(buf && fdem_checkpoint_read(look, buf, size, &err) == 0, "%s", err.message);
            CHECK(buf && fdem_checkpoint_read(whole, buf, size, &err) == 0, "%s", err.message);
            free(buf);
        }
        CHECK(look->contact.first_looks > 0, "%dD: no first look decided a pair", dim);
        CHECK(whole->contact.first_looks == 0, "%dD: %ld looks with them off", dim,
              whole->contact.first_looks);
        fprintf(stderr, "  %dD: %ld first looks (2D: found apart; 3D: across edges first)\n", dim,
                look->contact.first_looks);
        same_state_bits(look, whole, dim == 2 ? "2D, first look" : "3D, first look");
        fdem_model_destroy(look);
        fdem_model_destroy(whole);
    }
}

/* Copies 2 tolerances apart: never shut, so every pair takes the general
 * kernel, bit for bit as with the shut path switched off. */
static void open_broken_block_is_the_general_kernel(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        int n = dim == 2 ? 8 : 3, steps = dim == 2 ? 40 : 12;
        fdem_model *on = broken_block(dim, n, 2.0, 2.0), *off = broken_block(dim, n, 2.0, 2.0);
        off->contact.shut_off = 1;
        long shut = 0, touching = 0;
        for (int s = 0; s < steps && step_both(on, off); s++) {
            shut += shut_elements(on);
            touching += on->contact.touching;
        }
        CHECK(shut == 0, "%dD: %ld element-steps shut with every copy apart", dim, shut);
        CHECK(touching > 0, "%dD: nothing touched", dim);
        same_state_bits(on, off, dim == 2 ? "2D open" : "3D open");
        fdem_model_destroy(on);
        fdem_model_destroy(off);
    }
}

/* The shut run against the general kernel's, squeezed and sheared for
 * longer: the nodes end within 1e-3 of how far they travelled (measured
 * 1.4e-4 in 2D, 5e-5 in 3D) and the elastic energy within 0.2 % (measured
 * 0.03 %, 0.006 %), with a fifth of the element-steps shut at least
 * (measured 24 % in 2D: the shear opens the copies past 1e-4 h; 59 % in 3D). At a tolerance of 1e-3 h
 * this failed in 2D: 2 % and 7.5 % (contact_shut.c). */
static void shut_run_close_to_the_general_kernel(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        int n = dim == 2 ? 8 : 3, steps = dim == 2 ? 200 : 60;
        fdem_model *on = broken_block(dim, n, 2.0, 0), *off = broken_block(dim, n, 2.0, 0);
        off->contact.shut_off = 1;
        long shut = 0;
        for (int s = 0; s < steps && step_both(on, off); s++) shut += shut_elements(on);
        double worst = 0, travel = 0;
        for (int i = 0; i < dim * on->node_count; i++) {
            worst = fmax(worst, fabs(on->pos[i] - off->pos[i]));
            travel = fmax(travel, fabs(off->pos[i] - off->pos0[i]));
        }
        fdem_energy ea = fdem_get_energy(on), eb = fdem_get_energy(off);
        fprintf(stderr, "  %dD: %ld of %ld element-steps shut; positions differ by %.3g of %.3g "
                "travelled; contact work %.6g (shut) %.6g (general), elastic %.6g %.6g\n", dim,
                shut, (long)steps * on->elem_count, worst, travel, ea.contact, eb.contact,
                ea.elastic, eb.elastic);
        CHECK(shut >= (long)steps * on->elem_count / 5, "%dD: %ld element-steps shut", dim, shut);
        CHECK(travel > 0 && worst <= 1e-3 * travel, "%dD: %g apart of %g", dim, worst, travel);
        CHECK_REL(ea.elastic, eb.elastic, 0.002);
        fdem_model_destroy(on);
        fdem_model_destroy(off);
    }
}

/* The elements whose boxes this step computed (contact_near_boxes' test). */
static int boxes_computed(const fdem_model *m)
{
    const contact_state *cs = &m->contact;
    int n = 0;
    for (int k = 0; k < cs->near_active_count; k++) {
        int e = cs->near_active[k];
        n += cs->elem_gap[e] <= cs->near_apart || (cs->elem_topo[e] & TOPO_OPEN);
    }
    return n;
}

/* A shut broken block computes no element's box: its face pairs and vertex
 * pairs read none between shut elements, and the pairs across its
 * squares' diagonals, their boxes a hair apart (1e-12 m) when the near
 * list is built, are found apart by their clearance (the first step after
 * a rebuild that turns one away on its boxes often enough asks its kernel
 * for it),
 * which elem_gap then follows. Once copies are nudged open, the open
 * elements and their neighbours get boxes again. From a restore too
 * (which rebuilds the near list), in 2D. */
static void shut_block_computes_no_boxes(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *m = broken_block(dim, dim == 2 ? 8 : 3, 2.0, 0);
        fdem_error err = {0};
        for (int s = 0; s < 5; s++) CHECK(fdem_step(m, &err) == 0, "%s", err.message);
        CHECK(shut_elements(m) == m->elem_count, "%dD: %d of %d shut", dim, shut_elements(m),
              m->elem_count);
        CHECK(boxes_computed(m) == 0, "%dD: %d of %d elements computed their boxes", dim,
              boxes_computed(m), m->elem_count);
        size_t size = fdem_checkpoint_size(m);
        void *state = malloc(size);
        CHECK(state && fdem_checkpoint_write(m, state, size) == 0, "checkpoint");
        CHECK(fdem_checkpoint_read(m, state, size, &err) == 0, "%s", err.message);
        /* the looks come once a pair has been turned away by its boxes
         * NEAR_LOOK_AFTER_* times (contact_walk.c) */
        int after[3], steps = NEAR_LOOK_AFTER_3D + 6;
        for (int s = 0; s < steps; s++) {
            CHECK(fdem_step(m, &err) == 0, "%s", err.message);
            if (s < 2) after[s] = boxes_computed(m);
        }
        after[2] = boxes_computed(m);
        /* 3D: from the restore's state some pairs across a diagonal are
         * apart only along an oblique axis that the kernel's clearance
         * cannot certify there (every separating face plane passes
         * through a corner of both), so their elements keep their boxes
         * (126 of 162 here): only fewer than before the looks */
        CHECK(dim == 3 ? after[2] < after[0] : after[2] == 0,
              "%dD, restored: %d, %d, %d elements computed their boxes", dim, after[0], after[1],
              after[2]);
        nudge_copies(m, 1, dim == 2 ? 7 : 61);
        CHECK(fdem_step(m, &err) == 0, "%s", err.message);
        int open = m->elem_count - shut_elements(m), boxes = boxes_computed(m);
        CHECK(open > 0 && boxes >= open, "%dD, nudged: %d elements open, %d boxes", dim, open,
              boxes);
        fprintf(stderr, "  %dD: after a restore %d, %d, then %d boxes; nudged open %d elements, "
                "%d boxes\n", dim, after[0], after[1], after[2], open, boxes);
        free(state);
        fdem_model_destroy(m);
    }
}

CHECK_MAIN(T(shut_block_computes_no_boxes), T(vertex_pairs_walked_where_due_give_the_same_bits), T(shut_broken_block_same_bits_on_threads_and_restore),
           T(first_look_gives_the_kernels_bits), T(open_broken_block_is_the_general_kernel),
           T(shut_run_close_to_the_general_kernel))
