/*
 * log_near1.h - ln J for the neo-Hookean law of both element kernels
 * (element_tri.c, element_tet_model.c), where J = det F of a stressed solid
 * is almost always within a few per mille of 1. libm's log() was ~4 ns of a
 * ~23 ns 2D element-step, and more of the 3D one.
 *
 * Contract:
 *  - log_near1(J): within about one ulp of log(J) for every J > 0 (series
 *    for |J - 1| <= 2^-6, libm's log() beyond).
 *  - neo_hookean_log_inverse(J, j_min, &lnJ, &invJ): ln J and 1/J of the
 *    law; below j_min it continues along the tangent of ln J at j_min
 *    (invJ = 1/j_min), so a squashed element stays finite and is pushed open.
 *    The usual case (|J - 1| <= 2^-10) costs one test, the short series and
 *    the division.
 *
 * Near 1 the Taylor series of ln(1 + x), x = J - 1, is used:
 *   ln(1 + x) = x + x^2 q(x),  q(x) = sum_{k=2..K} (-1)^(k+1) x^(k-2) / k,
 * with K = 5 for |x| <= 2^-10 (volumetric strain below ~1e-3: the usual
 * case, 9 operations) and K = 9 for |x| <= 2^-6. x is exact there
 * (Sterbenz); the truncation error is below |x|^K / (K + 1) of the result,
 * < 2^-50 / 6 resp. 2^-54 / 10, i.e. < 1e-16; x^2 q is at most 1/128 of x,
 * so its rounding hardly reaches the sum: the result is within about one
 * ulp of log(J) (tested against log() in test_element.c; measured worst
 * 2.3e-16). q is evaluated in Estrin's form, a short dependency chain that
 * overlaps with the division 1/J.
 */
#ifndef FDEM_LOG_NEAR1_H
#define FDEM_LOG_NEAR1_H

#include <math.h>

#define LOG_SERIES_RANGE 0x1p-6
#define LOG_SHORT_RANGE 0x1p-10

static inline double log_short_series(double x)
{
    double x2 = x * x;
    double q = (-1.0 / 2 + x * (1.0 / 3)) + x2 * (-1.0 / 4 + x * (1.0 / 5));
    return x + x2 * q;
}

static inline double log_near1(double J)
{
    double x = J - 1.0;
    if (fabs(x) <= LOG_SHORT_RANGE) return log_short_series(x);
    if (!(fabs(x) <= LOG_SERIES_RANGE)) return log(J);
    double x2 = x * x;
    double x4 = x2 * x2;
    double p01 = -1.0 / 2 + x * (1.0 / 3), p23 = -1.0 / 4 + x * (1.0 / 5);
    double p45 = -1.0 / 6 + x * (1.0 / 7), p67 = -1.0 / 8 + x * (1.0 / 9);
    double q = (p01 + x2 * p23) + x4 * (p45 + x2 * p67);
    return x + x2 * q;
}

static inline void neo_hookean_log_inverse(double J, double j_min, double *lnJ, double *invJ)
{
    double x = J - 1.0;
    if (fabs(x) <= LOG_SHORT_RANGE) { /* the usual case first: one test */
        *lnJ = log_short_series(x);
        *invJ = 1.0 / J;
    } else if (J >= j_min) {
        *lnJ = log_near1(J);
        *invJ = 1.0 / J;
    } else {
        *lnJ = log(j_min) + (J - j_min) / j_min;
        *invJ = 1.0 / j_min;
    }
}

#endif /* FDEM_LOG_NEAR1_H */
