/*
 * rotation_3d.h - a rotation matrix for the 3D kernel tests (objectivity:
 * turn a configuration and check that the physics turns with it).
 */
#ifndef FDEM_TEST_ROTATION_3D_H
#define FDEM_TEST_ROTATION_3D_H

#include <math.h>

/* Rotation by angle about axis (any length), row-major (Rodrigues). */
static inline void rotation(const double axis[3], double angle, double R[9])
{
    double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    double u[3] = {axis[0] / n, axis[1] / n, axis[2] / n}, c = cos(angle), s = sin(angle);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) R[3 * i + j] = (i == j ? c : 0) + (1 - c) * u[i] * u[j];
    R[1] -= s * u[2], R[2] += s * u[1];
    R[3] += s * u[2], R[5] -= s * u[0];
    R[6] -= s * u[1], R[7] += s * u[0];
}

#endif /* FDEM_TEST_ROTATION_3D_H */
