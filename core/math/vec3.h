/*
 * vec3.h - the few 3-vector operations the 3D kernels share (element_tet.c,
 * mesh_3d.c, contact_tet.c, the tetrahedron and joint loops): differences,
 * cross and dot products on plain double[3], and the scatter of one node's
 * force, inline so the hot loops keep them in registers.
 */
#ifndef FDEM_VEC3_H
#define FDEM_VEC3_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* force[n] += or -= one node's load (x, y, z): x and y as one 16-byte
 * vector, z alone, each lane rounding as the scalar sum does. Every scatter
 * writes the nodes this same way, so the next load of a node just stored
 * forwards from the store. `store` (a constant at each call: the element's
 * part has nodes of its own, so this element is the first and only one to
 * write them this step) starts from zero instead of reading the force:
 * 0 + x and 0 - x are what the zeroed array gave, to the bit (signed zeros
 * included), without the step having to zero it first or the loop reading
 * it. */
static inline void vec3_scatter(double *f, int32_t n, double x, double y, double z, const int add,
                                const int store)
{
    typedef double xy_pair __attribute__((vector_size(16)));
    double *fn = f + 3 * (size_t)n;
    xy_pair old = {0.0, 0.0}, xy = {x, y};
    double old_z = 0.0;
    if (!store) {
        memcpy(&old, fn, sizeof old);
        old_z = fn[2];
    }
    old = add ? old + xy : old - xy;
    memcpy(fn, &old, sizeof old);
    fn[2] = add ? old_z + z : old_z - z;
}

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
