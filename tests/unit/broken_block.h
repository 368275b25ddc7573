/*
 * broken_block.h - the broken rock the contact tests run on: a unit
 * fracturing block (bench_engine.c's), n cells a side, moving as squeezed
 * along x at `squeeze` (1/s) and sheared, so that once broken its pieces
 * press on and slide along each other, and the check that two runs of it
 * agree bit for bit. One header, so that the clearance, shut-joint and
 * detection tests run the same block.
 */
#ifndef FDEM_TEST_BROKEN_BLOCK_H
#define FDEM_TEST_BROKEN_BLOCK_H

#include <string.h>

#include "build_model.h"
#include "check.h"
#include "model/model.h"

static inline fdem_model *squeezed_block(int dim, int n, double squeeze)
{
    fdem_model *m = fdem_model_create();
    fdem_error err = {0};
    if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_fracturing_rock(m, 0.0);
    const double size[3] = {1, 1, 1};
    const int div[3] = {n, n, n};
    build_box_part(m, mat, dim, size, div, 1);
    build_finalize(m, 0.5);
    for (int i = 0; i < m->node_count; i++) {
        double *v = m->vel + (size_t)dim * i, *x = m->pos0 + (size_t)dim * i;
        v[0] = -squeeze * (x[0] - 0.5) + 0.3 * squeeze * x[1];
        v[1] = 0.2 * squeeze * (x[0] - 0.5);
    }
    return m;
}

/* The same with every joint broken where it stands. */
static inline fdem_model *broken_in_place_block(int dim, int n, double squeeze)
{
    fdem_model *m = squeezed_block(dim, n, squeeze);
    for (int j = 0; j < m->joint_count; j++) m->joint_damage[j] = 1;
    m->broken_joints = m->joint_count;
    m->contact.need_detect = 1;
    return m;
}

/* Two runs at the same step hold the same positions, velocities and
 * energy accounts, bit for bit. */
static inline void same_state_bits(const fdem_model *a, const fdem_model *b, const char *what)
{
    size_t n = sizeof(double) * (size_t)a->dim * (size_t)a->node_count;
    CHECK(memcmp(a->pos, b->pos, n) == 0, "%s: positions differ", what);
    CHECK(memcmp(a->vel, b->vel, n) == 0, "%s: velocities differ", what);
    fdem_energy ea = fdem_get_energy(a), eb = fdem_get_energy(b);
    CHECK(memcmp(&ea, &eb, sizeof ea) == 0, "%s: energies differ", what);
}

#endif
