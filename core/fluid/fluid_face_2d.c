/*
 * fluid_face_2d.c - the 2D kernel of the fluid network: a joint's mean
 * edge as the fluid sees it, and which joints are neighbours (those that
 * share a mesh vertex), and the keys of a bore's wall edge. Everything else is shared
 * with 3D (fluid_flow.c, fluid_network.c, fluid_bore.c).
 *
 * The mean face is the one the joint law uses (joint.c): A's edge a0 -> a1
 * plus half the gap change, tangent t of length L, normal (t_y, -t_x)
 * pointing out of A. Its area vector per unit thickness is that normal
 * unnormalised (length L), and the opening the mean of the two end gaps
 * along the unit normal: the physical gap, without the in-situ offsets a
 * stressed joint's law adds (those are a stress, not a void).
 */
#include <math.h>

#include "model/model.h"
#include "fluid.h"

void fluid_face_2d(const fdem_model *m, int j, fluid_face *out)
{
    const int32_t *n = m->joint_node + 4 * (size_t)j;
    const double *x = m->pos;
    const double *a0 = x + 2 * (size_t)n[0], *a1 = x + 2 * (size_t)n[1];
    const double *b0 = x + 2 * (size_t)n[2], *b1 = x + 2 * (size_t)n[3];
    double d0x = b0[0] - a0[0], d0y = b0[1] - a0[1], d1x = b1[0] - a1[0], d1y = b1[1] - a1[1];
    double tx = (a1[0] - a0[0]) + 0.5 * (d1x - d0x), ty = (a1[1] - a0[1]) + 0.5 * (d1y - d0y);
    double L = sqrt(tx * tx + ty * ty);
    out->area[0] = ty;
    out->area[1] = -tx;
    out->area[2] = 0;
    out->opening = L > 0 ? 0.5 * ((d0x + d1x) * ty - (d0y + d1y) * tx) / L : 0;
}

int fluid_keys_2d(const fdem_model *m, int j, int32_t keys[3][2])
{
    return fluid_facet_keys_2d(m, m->joint_node + 4 * (size_t)j, keys);
}

int fluid_facet_keys_2d(const fdem_model *m, const int32_t *n, int32_t keys[3][2])
{
    for (int i = 0; i < 2; i++) {
        keys[i][0] = m->node_origin[n[i]];
        keys[i][1] = -1;
    }
    return 2;
}

double fluid_key_width_2d(const fdem_model *m, const int32_t key[2]) { return 1.0; }
