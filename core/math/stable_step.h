/*
 * stable_step.h - the central-difference limit of one damped mode, shared
 * by the triangle and tetrahedron kernels (each finds its own omega_max
 * and c_max by the element eigenvalue theorem; the limit is the same).
 *
 * Contract: with the damping force taken at the lagged (half-step)
 * velocity, x'' = -omega^2 x - c x' is stable for
 *   h <= 2 / (sqrt(omega^2 + c^2 / 4) + c / 2)  =  (2/omega)(sqrt(1 + xi^2) - xi),
 * c = 2 xi omega. For a whole element, omega_max^2 (largest eigenvalue of
 * M^-1 K) and c_max (of M^-1 C) taken separately keep 4M - h^2 K - 2h C
 * positive semi-definite, so the bound holds for every mode even when K
 * and C do not share their eigenvectors. With c = 0 the result is
 * 2 / omega exactly (no rounding beyond the square root and division).
 */
#ifndef FDEM_STABLE_STEP_H
#define FDEM_STABLE_STEP_H

#include <math.h>

static inline double damped_mode_stable_dt(double omega2, double rate)
{
    return 2 / (sqrt(omega2 + 0.25 * rate * rate) + 0.5 * rate);
}

#endif /* FDEM_STABLE_STEP_H */
