/*
 * facet_area.h - the area vector of a boundary facet, the one formula a
 * boundary load (step/boundary_load.c) and a bore's wall
 * (fluid/fluid_bore.c) press on.
 *
 * Contract: facet_area_vector_of(dim, x, s) for the facet through corners
 * x[0..dim) in the order that makes it point out of its element: in 2D
 * the edge x0 -> x1 turned to (t_y, -t_x), its length times the outward
 * unit normal (per unit thickness); in 3D half the cross product of its
 * edges from x0, its area times the unit normal. s[2] is 0 in 2D.
 */
#ifndef FDEM_MATH_FACET_AREA_H
#define FDEM_MATH_FACET_AREA_H

#include "vec3.h"

static inline void facet_area_vector_of(int dim, const double *const x[3], double s[3])
{
    if (dim == 2) {
        s[0] = x[1][1] - x[0][1];
        s[1] = -(x[1][0] - x[0][0]);
        s[2] = 0;
        return;
    }
    double a[3], b[3];
    vec3_sub(x[1], x[0], a);
    vec3_sub(x[2], x[0], b);
    vec3_cross(a, b, s);
    for (int d = 0; d < 3; d++) s[d] *= 0.5;
}

#endif
