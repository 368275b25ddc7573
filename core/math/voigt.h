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

#endif
