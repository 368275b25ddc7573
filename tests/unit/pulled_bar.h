/*
 * pulled_bar.h - a fracturing bar of the Brazilian-disc rock
 * (build_fracturing_rock, damping 0.1) whose two ends are pulled apart at
 * `speed` each, in either dimension: 0.1 x 0.01 m in 2D (20 x 2 cells), 0.1 x 0.01
 * x 0.01 m in 3D (10 x 1 x 1 boxes). The same bars test_fragments.c and
 * test_fracture_3d.c pull (at 5 m/s); tests of what a break leaves (events) share them.
 */
#ifndef FDEM_PULLED_BAR_H
#define FDEM_PULLED_BAR_H

#include "build_model.h"
#include "mesh/mesh_3d.h"

/* Prescribes vx (other components free) on the nodes at x. */
static inline void pulled_bar_end(fdem_model *m, double x, double vx)
{
    int D = fdem_get_dimension(m);
    fdem_constraint_def c = {0};
    c.select = FDEM_SELECT_BOX;
    for (int d = 0; d < D; d++) {
        c.box[d] = d ? -1 : x - 1e-9;
        c.box[D + d] = d ? 1 : x + 1e-9;
    }
    c.kind = FDEM_CONSTRAINT_VELOCITY;
    c.value[0] = vx;
    c.free_y = c.free_z = 1;
    fdem_error err;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("constraint", &err);
}

static inline fdem_model *pulled_bar(int dimension, int threads, double speed)
{
    fdem_model *m = fdem_model_create();
    fdem_error err = {0};
    if (!m || fdem_set_dimension(m, dimension, &err)) build_die("dimension", &err);
    int rock = build_fracturing_rock(m, 0.1);
    const double size[3] = {0.1, 0.01, 0.01};
    const int div_2d[3] = {20, 2, 0}, div_3d[3] = {10, 1, 1};
    build_box_part(m, rock, dimension, size, dimension == 2 ? div_2d : div_3d, 1);
    pulled_bar_end(m, 0, -speed);
    pulled_bar_end(m, 0.1, speed);
    fdem_set_threads(m, threads);
    build_finalize(m, 0.5);
    return m;
}

#endif
