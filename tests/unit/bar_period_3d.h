/*
 * bar_period_3d.h - the first period of a 3D fixed-free bar (fixed at
 * x = 0, free at x = L, set moving along x): the tip's mean displacement
 * and the first time it comes back through zero after swinging out and
 * in. Shared by the continuum test (test_dynamics_3d) and the fracturing
 * one (test_fracture_3d), so both measure the period the same way.
 */
#ifndef FDEM_TEST_BAR_PERIOD_3D_H
#define FDEM_TEST_BAR_PERIOD_3D_H

#include "fdem.h"

/* Mean x displacement of the nodes at x = L. */
static inline double bar_tip_displacement(const fdem_model *m, double L)
{
    const double *x0 = fdem_initial_positions(m), *x = fdem_positions(m);
    int nodes = fdem_get_counts(m).nodes, n = 0;
    double u = 0;
    for (int i = 0; i < nodes; i++)
        if (x0[3 * i] > L - 1e-9) {
            u += x[3 * i] - x0[3 * i];
            n++;
        }
    return n ? u / n : 0;
}

typedef struct bar_crossing {
    double prev_u, prev_t;
    double crossing; /* < 0 until found */
    int went_out, went_in;
} bar_crossing;

/* Feeds the tip displacement u at time t; u_max is the expected amplitude. */
static inline void bar_crossing_update(bar_crossing *b, double t, double u, double u_max)
{
    b->went_out |= u > 0.5 * u_max;
    b->went_in |= b->went_out && u < -0.5 * u_max;
    if (b->went_in && b->prev_u < 0 && u >= 0)
        b->crossing = b->prev_t + (t - b->prev_t) * b->prev_u / (b->prev_u - u);
    b->prev_u = u;
    b->prev_t = t;
}

#endif /* FDEM_TEST_BAR_PERIOD_3D_H */
