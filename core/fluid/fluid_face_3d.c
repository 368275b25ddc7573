/*
 * fluid_face_3d.c - the 3D kernel of the fluid network: a joint's mean
 * triangle as the fluid sees it, and which joints are neighbours (those
 * that share an edge of the mesh, through which the fluid passes with the
 * edge's length as its width), and the keys of a bore's wall triangle. Everything
 * else is shared with 2D (fluid_flow.c, fluid_network.c, fluid_bore.c).
 *
 * The mean face is the joint law's (joint_tet.h): corners a_i + d_i / 2,
 * d_i = b_i - a_i; its area vector is half the cross product of its edges,
 * pointing out of A towards B, and the opening the mean corner gap along
 * the unit normal (the physical gap, without in-situ offsets).
 */
#include <math.h>

#include "model/model.h"
#include "math/vec3.h"
#include "fluid.h"

void fluid_face_3d(const fdem_model *m, int j, fluid_face *out)
{
    const int32_t *n = m->joint_node + 6 * (size_t)j;
    const double *x = m->pos;
    double c[3][3], dsum[3] = {0, 0, 0};
    for (int i = 0; i < 3; i++) {
        const double *a = x + 3 * (size_t)n[i], *b = x + 3 * (size_t)n[3 + i];
        for (int k = 0; k < 3; k++) {
            double d = b[k] - a[k];
            c[i][k] = a[k] + 0.5 * d;
            dsum[k] += d;
        }
    }
    double e1[3], e2[3], N[3];
    vec3_sub(c[1], c[0], e1);
    vec3_sub(c[2], c[0], e2);
    vec3_cross(e1, e2, N);
    double len = sqrt(vec3_dot(N, N));
    for (int k = 0; k < 3; k++) out->area[k] = 0.5 * N[k];
    out->opening = len > 0 ? vec3_dot(dsum, N) / (3 * len) : 0;
}

int fluid_keys_3d(const fdem_model *m, int j, int32_t keys[3][2])
{
    return fluid_facet_keys_3d(m, m->joint_node + 6 * (size_t)j, keys);
}

int fluid_facet_keys_3d(const fdem_model *m, const int32_t *n, int32_t keys[3][2])
{
    for (int i = 0; i < 3; i++) {
        int32_t p = m->node_origin[n[i]], q = m->node_origin[n[(i + 1) % 3]];
        keys[i][0] = p < q ? p : q;
        keys[i][1] = p < q ? q : p;
    }
    return 3;
}

double fluid_key_width_3d(const fdem_model *m, const int32_t key[2])
{
    const double *p = m->pos0 + 3 * (size_t)key[0], *q = m->pos0 + 3 * (size_t)key[1];
    double d[3];
    vec3_sub(q, p, d);
    return sqrt(vec3_dot(d, d));
}
