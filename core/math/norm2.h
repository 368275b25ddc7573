/*
 * norm2.h - the length of a two-component vector for the hot kernels
 * (the joint law's slide return, the 2D general contact kernel's edges).
 *
 * glibc's hypot() is exact to the last bit at any scale, which costs a
 * call and a chain of fused operations: 5.6 % of the 3D arc-loaded
 * Brazilian disc's samples after its split (its damaged joints return
 * their slides every step) and 3.4-4.9 % of the 2D tunnels'. While the
 * sum of squares is a normal number far from overflow, sqrt(x^2 + y^2) is
 * within an ulp or so of it, and for y = 0 it is |x| exactly (the correctly
 * rounded root of a correctly rounded square, in base 2), so a slide along
 * one axis keeps the bits of a one-component return. Beyond that range
 * (lengths under 1e-150 or over 1e150 in any unit) hypot() is called, so
 * nothing underflows to 0 that was not 0.
 *
 * Contract: norm2(x, y) is hypot(x, y) to within about one ulp, exactly
 * |x| when y == 0, finite for finite x and y.
 */
#ifndef FDEM_NORM2_H
#define FDEM_NORM2_H

#include <math.h>

static inline double norm2(double x, double y)
{
    double s = x * x + y * y;
    if (s > 0x1p-1000 && s < 0x1p1000) return sqrt(s);
    return hypot(x, y);
}

#endif /* FDEM_NORM2_H */
