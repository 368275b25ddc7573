/*
 * joint_face_3d.h - the initial geometry of a 6-node joint's face A (its
 * three corners a0, a1, a2 in pos0), which the 3D fracture tests and
 * scripts/limits.c read to sort joints by where they lie and which way
 * they face.
 *
 * Contract: joint_face_normal writes (a1 - a0) x (a2 - a0), pointing out
 * of A's tetrahedron, into N and returns its length (twice the area);
 * joint_face_centre writes the centroid of the three corners.
 */
#ifndef FDEM_JOINT_FACE_3D_H
#define FDEM_JOINT_FACE_3D_H

#include <math.h>
#include <stdint.h>

#include "math/vec3.h"

static inline double joint_face_normal(const double *pos0, const int32_t *node, double N[3])
{
    double e1[3], e2[3];
    vec3_sub(pos0 + 3 * (size_t)node[1], pos0 + 3 * (size_t)node[0], e1);
    vec3_sub(pos0 + 3 * (size_t)node[2], pos0 + 3 * (size_t)node[0], e2);
    vec3_cross(e1, e2, N);
    return sqrt(vec3_dot(N, N));
}

static inline void joint_face_centre(const double *pos0, const int32_t *node, double c[3])
{
    for (int k = 0; k < 3; k++)
        c[k] = (pos0[3 * (size_t)node[0] + k] + pos0[3 * (size_t)node[1] + k] +
                pos0[3 * (size_t)node[2] + k]) / 3;
}

#endif /* FDEM_JOINT_FACE_3D_H */
