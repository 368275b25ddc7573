/*
 * contact_spring.h - the Coulomb stick spring of a 3D contact (PHYSICS.md,
 * "Friction"), shared by the general tetrahedron kernel (contact_tet.c)
 * and the shut-joint kernel (contact_face_tet.c), so that a pair passing
 * from one to the other keeps the same friction law and the same bits.
 *
 * Contract: the spring is turned into the plane of unit normal n (its part
 * along n dropped), loaded by the relative tangential velocity rel over the
 * step h at stiffness k_t and capped at `cap` (mu |Fn|); beyond the cap the
 * surfaces slide, the spring stays at the cap and cap x slip is added to
 * *dissipated. The spring is stored back and added to force.
 */
#ifndef FDEM_CONTACT_SPRING_H
#define FDEM_CONTACT_SPRING_H

#include <math.h>

#include "math/vec3.h"

static inline void contact_spring_load(double spring[3], const double n[3], const double rel[3],
                                       double k_t, double h, double cap, double *dissipated,
                                       double force[3])
{
    double rel_n = vec3_dot(rel, n), spring_n = vec3_dot(spring, n), f[3];
    for (int i = 0; i < 3; i++)
        f[i] = (spring[i] - spring_n * n[i]) - k_t * (rel[i] - rel_n * n[i]) * h;
    double size = sqrt(vec3_dot(f, f));
    if (size > cap) {
        *dissipated += cap * (size - cap) / k_t;
        for (int i = 0; i < 3; i++) f[i] *= cap / size;
    }
    for (int i = 0; i < 3; i++) {
        spring[i] = f[i];
        force[i] += f[i];
    }
}

#endif
