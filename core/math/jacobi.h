/*
 * jacobi.h - eigenvalues of a small symmetric matrix by cyclic Jacobi
 * rotations, for the few places that need them (the tetrahedron's stable
 * step, 6x6 in strain space; principal stresses, 2x2 or 3x3). Quadratically
 * convergent: a few sweeps reach round-off, and no branch depends on the
 * matrix's shape, so it is robust for repeated and zero eigenvalues.
 *
 * Contract: a is n x n, row-major, symmetric, n <= JACOBI_MAX; it is
 * destroyed (left diagonal). out[n] gets the eigenvalues, unordered.
 */
#ifndef FDEM_JACOBI_H
#define FDEM_JACOBI_H

#include <math.h>

#define JACOBI_MAX 6

static inline void jacobi_eigenvalues(double *a, int n, double *out)
{
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = 0, diag = 0;
        for (int i = 0; i < n; i++) {
            diag += a[n * i + i] * a[n * i + i];
            for (int j = i + 1; j < n; j++) off += a[n * i + j] * a[n * i + j];
        }
        if (!(off > 1e-30 * diag)) break;
        for (int p = 0; p < n - 1; p++)
            for (int q = p + 1; q < n; q++) {
                if (a[n * p + q] == 0) continue;
                double theta = (a[n * q + q] - a[n * p + p]) / (2 * a[n * p + q]);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < n; k++) { /* columns p, q */
                    double akp = a[n * k + p], akq = a[n * k + q];
                    a[n * k + p] = c * akp - s * akq;
                    a[n * k + q] = s * akp + c * akq;
                }
                for (int k = 0; k < n; k++) { /* rows p, q */
                    double apk = a[n * p + k], aqk = a[n * q + k];
                    a[n * p + k] = c * apk - s * aqk;
                    a[n * q + k] = s * apk + c * aqk;
                }
                a[n * p + q] = a[n * q + p] = 0;
            }
    }
    for (int k = 0; k < n; k++) out[k] = a[n * k + k];
}

#endif /* FDEM_JACOBI_H */
