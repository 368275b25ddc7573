/*
 * test_detect_bulk.c - a fracturing block broken along a plane near one
 * side keeps one piece of most of its elements: detection then takes the
 * bulk path (nbs_classes.h: the piece never tested against itself). That
 * path must leave a run's bits alone across a checkpoint: a restore
 * rebuilds the list the run had (contact_restore_detection), and a break
 * after it (a detection the break forces) gives both runs the same list
 * again. 2D and 3D; the test also checks that the bulk path ran and that
 * the pieces touched, or it could not fail.
 */
#include "broken_block.h"
#include "check.h"
#include "fdem.h"
#include "model/model.h"

#include <stdlib.h>
#include <string.h>

/* A unit block of n cells a side, squeezed along x and sheared, broken
 * across x = 0.2: the elements beside the crack are bodies of their own,
 * the rest (about 2/3) one piece. */
static fdem_model *cut_block(int dim, int n)
{
    fdem_model *m = squeezed_block(dim, n, 5.0);
    fdem_error err = {0};
    const double normal[3] = {1, 0, 0};
    if (fdem_break_joints_across(m, normal, 0.2) <= 0) build_die("cut", &err);
    return m;
}

static void same_bits(const fdem_model *a, const fdem_model *b, const char *what)
{
    size_t n = sizeof(double) * (size_t)a->dim * (size_t)a->node_count;
    CHECK(memcmp(a->pos, b->pos, n) == 0, "%s: positions differ", what);
    CHECK(memcmp(a->vel, b->vel, n) == 0, "%s: velocities differ", what);
    CHECK(a->contact.pairs.count == b->contact.pairs.count &&
              !memcmp(a->contact.pairs.a, b->contact.pairs.a,
                      a->contact.pairs.count * sizeof(int32_t)) &&
              !memcmp(a->contact.pairs.b, b->contact.pairs.b,
                      a->contact.pairs.count * sizeof(int32_t)),
          "%s: candidate lists differ", what);
}

static void restored_cut_block_steps_on_to_the_same_bits(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *a = cut_block(dim, dim == 3 ? 4 : 8), *b = cut_block(dim, dim == 3 ? 4 : 8);
        fdem_error err = {0};
        int touched = 0, bulk = 0;
        for (int s = 0; s < 30; s++) {
            CHECK(fdem_step(a, &err) == 0, "%s", err.message);
            touched |= a->contact.touching > 0;
            bulk |= a->contact.classes.used == 2;
        }
        CHECK(bulk, "%dD: detection never took the bulk path", dim);
        size_t size = fdem_checkpoint_size(a);
        void *buf = malloc(size);
        CHECK(buf && fdem_checkpoint_write(a, buf, size) == 0, "write");
        CHECK(buf && fdem_checkpoint_read(b, buf, size, &err) == 0, "%s", err.message);
        free(buf);
        same_bits(a, b, dim == 2 ? "2D at the restore" : "3D at the restore");
        const double normal[3] = {0, 1, 0};
        for (int s = 0; s < 40; s++) {
            if (s == 10) /* a break: both detect at once */
                CHECK(fdem_break_joints_across(a, normal, 0.5) > 0 &&
                          fdem_break_joints_across(b, normal, 0.5) > 0,
                      "%dD: second cut", dim);
            CHECK(fdem_step(a, &err) == 0, "%s", err.message);
            CHECK(fdem_step(b, &err) == 0, "%s", err.message);
            touched |= a->contact.touching > 0;
            bulk |= (a->contact.classes.used == 2) << 1;
        }
        CHECK(bulk == 3, "%dD: no bulk path after the restore", dim);
        CHECK(touched, "%dD: the pieces never touched", dim);
        CHECK(a->contact.detections >= 2, "%dD: %ld detections", dim, a->contact.detections);
        same_bits(a, b, dim == 2 ? "2D after the restore" : "3D after the restore");
        fdem_model_destroy(a);
        fdem_model_destroy(b);
    }
}

CHECK_MAIN(T(restored_cut_block_steps_on_to_the_same_bits))
