/*
 * voigt.h - where tensor slot (i, j) sits in a symmetric tensor stored as a
 * Voigt vector, in the order fdem_element_stress uses (2D: xx, yy, xy;
 * 3D: xx, yy, zz, yz, xz, xy).
 */
#ifndef FDEM_VOIGT_H
#define FDEM_VOIGT_H

/* Tensor slot (i, j) -> Voigt index, in the order of fdem_element_stress. */
static inline int voigt_index(int dim, int i, int j)
{
    static const int v2[2][2] = {{0, 2}, {2, 1}};
    static const int v3[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};
    return dim == 3 ? v3[i][j] : v2[i][j];
}

/* out = sigma . n for a symmetric tensor sigma in Voigt layout: the
 * traction on a plane of normal n (or, for an area vector n, the force). */
static inline void voigt_dot(int dim, const double *sigma, const double *n, double *out)
{
    for (int i = 0; i < dim; i++) {
        double t = 0;
        for (int j = 0; j < dim; j++) t += sigma[voigt_index(dim, i, j)] * n[j];
        out[i] = t;
    }
}

#endif
