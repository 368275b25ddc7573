/*
 * power_iteration.h - the largest eigenvalue of M^-1 K for a lumped
 * (diagonal) mass matrix, by power iteration. The stable-step tests get an
 * element's omega_max^2 (or its largest damping rate, from the viscosity
 * matrix) this way from the element's own forces, independently of the
 * engine's closed forms. K is n x n row-major (n <= 12), mass one per dof.
 */
#ifndef FDEM_POWER_ITERATION_H
#define FDEM_POWER_ITERATION_H

#include <assert.h>
#include <math.h>

static inline double largest_eigenvalue_over_mass(int n, const double *K, const double *mass,
                                                  const double *start, int iterations)
{
    assert(n <= 12);
    double v[12], w[12], lambda = 0;
    for (int i = 0; i < n; i++) v[i] = start[i];
    for (int it = 0; it < iterations; it++) {
        double norm = 0, vn = 0;
        for (int i = 0; i < n; i++) {
            w[i] = 0;
            for (int j = 0; j < n; j++) w[i] += K[n * i + j] * v[j];
            w[i] /= mass[i];
            norm += w[i] * w[i];
            vn += v[i] * v[i];
        }
        norm = sqrt(norm);
        lambda = norm / sqrt(vn);
        for (int i = 0; i < n; i++) v[i] = w[i] / norm;
    }
    return lambda;
}

#endif /* FDEM_POWER_ITERATION_H */
