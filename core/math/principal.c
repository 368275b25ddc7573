/*
 * principal.c - the principal values of one symmetric tensor given in Voigt
 * order (fdem_principal_values, fdem.h), largest first: the output fields
 * and the in-situ stress check both need them. 2D takes the in-plane
 * tensor's closed form; 3D a cyclic Jacobi rotation, which reaches the
 * eigenvalues to rounding whatever their spread (the closed cubic loses
 * digits near repeated roots).
 */
#include <math.h>

#include "fdem.h"
#include "jacobi.h"
#include "voigt.h"

static void sort_descending(double *v, int n)
{
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && v[j] > v[j - 1]; j--) {
            double t = v[j];
            v[j] = v[j - 1];
            v[j - 1] = t;
        }
}

void fdem_principal_values(int dim, const double *voigt, double *out)
{
    if (dim == 3) {
        double a[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) a[i][j] = voigt[voigt_index(3, i, j)];
        jacobi_eigenvalues(&a[0][0], 3, out);
    } else {
        double centre = 0.5 * (voigt[0] + voigt[1]);
        double radius = hypot(0.5 * (voigt[0] - voigt[1]), voigt[2]);
        out[0] = centre + radius;
        out[1] = centre - radius;
    }
    sort_descending(out, dim);
}
