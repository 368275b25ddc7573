/*
 * power_iteration.h - the largest eigenvalue of M^-1 K for a lumped
 * (diagonal) mass matrix, by power iteration. The stable-step tests get an
 * element's omega_max^2 (or its largest damping rate, from the viscosity
 * matrix), or that of a small jointed model, this way from the engine's own
 * forces, independently of its closed forms and estimates. K is n x n
 * row-major, mass one per dof.
 */
#ifndef FDEM_POWER_ITERATION_H
#define FDEM_POWER_ITERATION_H

#include <assert.h>
#include <math.h>
#include <stdlib.h>

static inline double largest_eigenvalue_over_mass(int n, const double *K, const double *mass,
                                                  const double *start, int iterations)
{
    double *v = malloc(sizeof(double) * 2 * (size_t)n), *w = v + n, lambda = 0;
    assert(v);
    for (int i = 0; i < n; i++) v[i] = start[i];
    for (int it = 0; it < iterations; it++) {
        double norm = 0, vn = 0;
        for (int i = 0; i < n; i++) {
            w[i] = 0;
            for (int j = 0; j < n; j++) w[i] += K[(size_t)n * i + j] * v[j];
            w[i] /= mass[i];
            norm += w[i] * w[i];
            vn += v[i] * v[i];
        }
        norm = sqrt(norm);
        lambda = norm / sqrt(vn);
        for (int i = 0; i < n; i++) v[i] = w[i] / norm;
    }
    free(v);
    return lambda;
}

#endif /* FDEM_POWER_ITERATION_H */
