/*
 * stress_watch.h - what the in-situ stress tests watch while a model that
 * should stay at rest runs: each element's stress, its largest relative
 * change against a reference stress per element, and the worst energy
 * residual and largest kinetic energy over a run. Shared by
 * test_initial_stress.c and test_joint_prestress.c, which ask the same
 * questions of a block without and with joints.
 */
#ifndef FDEM_TEST_STRESS_WATCH_H
#define FDEM_TEST_STRESS_WATCH_H

#include <math.h>
#include <stdlib.h>

#include "build_model.h"
#include "model/model.h"

/* Every element's stress (Voigt, S per element); free() it. */
static inline double *element_stresses(const fdem_model *m)
{
    int S = fdem_stress_components(m);
    double *s = malloc(sizeof(double) * (size_t)S * (size_t)fdem_get_counts(m).elements);
    fdem_element_stress(m, s);
    return s;
}

/* The largest |component| of a stress in Voigt layout. */
static inline double stress_scale(int S, const double *s)
{
    double big = 0;
    for (int k = 0; k < S; k++) big = fmax(big, fabs(s[k]));
    return big;
}

/* The initial height (y in 2D, z in 3D) of element e's centroid. */
static inline double centroid_height(const fdem_model *m, int e)
{
    const int K = fdem_nodes_per_element(m), D = fdem_get_dimension(m);
    const int32_t *node = fdem_element_nodes(m) + (size_t)K * (size_t)e;
    double h = 0;
    for (int c = 0; c < K; c++) h += fdem_initial_positions(m)[D * node[c] + D - 1];
    return h / K;
}

/* The largest change of any element's stress component from `want` (S per
 * element), over the largest component of that element's `want`; with
 * only_below, only elements whose centroid starts at or below height. */
static inline double stress_change_where(const fdem_model *m, const double *want, int only_below,
                                         double height)
{
    const int S = fdem_stress_components(m), E = fdem_get_counts(m).elements;
    double *s = element_stresses(m), worst = 0;
    for (int e = 0; e < E; e++) {
        if (only_below && centroid_height(m, e) > height) continue;
        double scale = stress_scale(S, want + S * e);
        for (int k = 0; k < S; k++) worst = fmax(worst, fabs(s[S * e + k] - want[S * e + k]) / scale);
    }
    free(s);
    return worst;
}

static inline double stress_change(const fdem_model *m, const double *want)
{
    return stress_change_where(m, want, 0, 0);
}

/* Steps to t_end; returns the worst |energy residual| / scale and sets
 * *kinetic_max (when not NULL) to the largest kinetic energy seen. */
static inline double run_watched(fdem_model *m, double t_end, double scale, double *kinetic_max)
{
    double worst = 0, kinetic = 0;
    fdem_error err;
    while (fdem_get_time(m) < t_end) {
        if (fdem_step(m, &err)) build_die("step", &err);
        fdem_energy en = fdem_get_energy(m);
        worst = fmax(worst, fabs(en.residual) / scale);
        kinetic = fmax(kinetic, en.kinetic);
    }
    if (kinetic_max) *kinetic_max = kinetic;
    return worst;
}

#endif
