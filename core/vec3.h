/*
 * vec3.h - the few 3-vector operations the 3D kernels share (element_tet.c,
 * mesh_3d.c, contact_tet.c): differences, cross and dot products on plain
 * double[3], inline so the hot loops keep them in registers.
 */
#ifndef FDEM_VEC3_H
#define FDEM_VEC3_H

static inline void vec3_sub(const double *a, const double *b, double out[3])
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}

static inline void vec3_cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double vec3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

#endif /* FDEM_VEC3_H */
