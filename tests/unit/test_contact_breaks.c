/*
 * test_contact_breaks.c - after joints break, the candidate list is mended
 * around what changed instead of detected again (contact_breaks.c). It
 * must be the list a whole detection on the same circles gives, in the
 * same order, since a restore runs one: a block squeezed until its joints
 * break one after another runs twice side by side, once mending and once
 * detecting whole at every break (contact.breaks_off), and the two lists
 * and states must agree bit for bit at every step, in 2D and 3D. So must
 * a run restored from a checkpoint taken with a cut's mending still due.
 * The test checks that lists were mended, that pieces split off and that
 * they touched, or it could not fail.
 */
#include "broken_block.h"
#include "check.h"
#include "contact/contact.h"
#include "fdem.h"
#include "model/model.h"

#include <stdlib.h>
#include <string.h>

static int same_list(const fdem_model *a, const fdem_model *b)
{
    const nbs_pairs *p = &a->contact.pairs, *q = &b->contact.pairs;
    if (p->count != q->count) return 0;
    return p->count == 0 || (!memcmp(p->a, q->a, p->count * sizeof(int32_t)) &&
                             !memcmp(p->b, q->b, p->count * sizeof(int32_t)));
}

/* Block of n cells a side squeezed hard enough that joints break step
 * after step. */
static void breaking_block_mends_to_the_whole_detections_list(int dim, int n, int steps)
{
    fdem_model *a = squeezed_block(dim, n, 5.0), *b = squeezed_block(dim, n, 5.0);
    b->contact.breaks_off = 1;
    fdem_error err = {0};
    int differ = -1, touched = 0;
    for (int s = 0; s < steps && differ < 0; s++) {
        CHECK(fdem_step(a, &err) == 0, "%s", err.message);
        CHECK(fdem_step(b, &err) == 0, "%s", err.message);
        if (!same_list(a, b) || memcmp(a->pos, b->pos, sizeof(double) * (size_t)dim * (size_t)a->node_count))
            differ = s;
        touched |= a->contact.touching > 0;
    }
    CHECK(differ < 0, "%dD: the mended list or the state differ from the whole detection's at "
          "step %d", dim, differ);
    same_state_bits(a, b, dim == 2 ? "2D" : "3D");
    CHECK(a->contact.break_mends >= 10, "%dD: %ld lists mended", dim, a->contact.break_mends);
    CHECK(b->contact.break_mends == 0, "%dD: breaks_off mended", dim);
    CHECK(a->fragments > 1, "%dD: no piece split off (%d fragments)", dim, a->fragments);
    CHECK(touched, "%dD: the pieces never touched", dim);
    printf("   %dD: %d broken of %d joints, %d fragments, %ld of %ld detections mended, %zu "
           "candidate pairs\n",
           dim, a->broken_joints, a->joint_count, a->fragments, a->contact.break_mends,
           a->contact.detections, a->contact.pairs.count);
    fdem_model_destroy(a);
    fdem_model_destroy(b);
}

static void mended_list_2d(void) { breaking_block_mends_to_the_whole_detections_list(2, 12, 400); }
static void mended_list_3d(void) { breaking_block_mends_to_the_whole_detections_list(3, 4, 200); }

/* A checkpoint written with a cut's mending due (the cut between steps)
 * restores to a model that steps on to the same bits. */
static void restored_with_a_mending_due(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        int n = dim == 3 ? 4 : 12;
        fdem_model *a = squeezed_block(dim, n, 5.0), *b = squeezed_block(dim, n, 5.0);
        fdem_error err = {0};
        for (int s = 0; s < 60; s++) CHECK(fdem_step(a, &err) == 0, "%s", err.message);
        const double normal[3] = {1, 0, 0};
        CHECK(fdem_break_joints_across(a, normal, 0.8) > 0, "%dD: cut", dim);
        CHECK(a->contact.need_detect == CONTACT_DETECT_BREAKS, "%dD: the cut asks a mending", dim);
        size_t size = fdem_checkpoint_size(a);
        void *buf = malloc(size);
        CHECK(buf && fdem_checkpoint_write(a, buf, size) == 0, "write");
        CHECK(buf && fdem_checkpoint_read(b, buf, size, &err) == 0, "%s", err.message);
        free(buf);
        long mends = a->contact.break_mends;
        for (int s = 0; s < 60; s++) {
            CHECK(fdem_step(a, &err) == 0, "%s", err.message);
            CHECK(fdem_step(b, &err) == 0, "%s", err.message);
        }
        CHECK(a->contact.break_mends > mends, "%dD: the cut's list was not mended", dim);
        CHECK(same_list(a, b), "%dD: candidate lists differ after the restore", dim);
        CHECK(a->contact.detections == b->contact.detections, "%dD: detections %ld and %ld", dim,
              a->contact.detections, b->contact.detections);
        same_state_bits(a, b, dim == 2 ? "2D after the restore" : "3D after the restore");
        fdem_model_destroy(a);
        fdem_model_destroy(b);
    }
}

CHECK_MAIN(T(mended_list_2d), T(mended_list_3d), T(restored_with_a_mending_due))
