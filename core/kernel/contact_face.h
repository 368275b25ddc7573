/*
 * contact_face.h - the pair kernel of a SHUT broken joint: the two faces of
 * a joint that broke and stayed in place, pressed on each other over their
 * whole area, by the joint's own geometry instead of general clipping
 * (issue 34). Triangles: contact_face_tri.c; tetrahedra: contact_face_tet.c;
 * when the contact stage hands a pair to it: contact/contact_shut.c.
 *
 * Why. A block broken in place touches at every face, edge and corner
 * through copies of each vertex a hair apart; the general kernels
 * (contact_tri.c, contact_tet.c) clip every face of both elements against
 * the other's sub-simplices for what is, across a shut joint, two coincident
 * faces. 3D: 12.4 clipping calls an element-step, 40 % of the instructions
 * in integrate_min (s33 closing notes).
 *
 * Physics (the general kernel's limit, to first order in depth / size).
 * While the matched nodes of the joint (joint_node: a_i on A's face, b_i
 * its copy on B's) are within the shut tolerance of each other, the face of
 * A lies on B's face up to a gap field that is linear over the face: with n
 * the outward unit normal of A's face on the mean face x_m = (x_a + x_b)/2,
 *     d(w) = sum_i w_i (x_a_i - x_b_i) . n     (d > 0: the faces overlap).
 * The potential of a target t near its face f is phi_t = (D+1) lambda_f =
 * (D+1) d / H_t (H_t t's height over f), so the general kernel presses a
 * contactor face of area A at depth d back with (D+1) p A d / H_t: the
 * stiffness contact_tet.c's header states (4 p A / h_t per unit depth) and
 * contact_tri.c's 2D analogue (3 p L / h_t). This kernel does exactly that,
 * per role as the general kernel does (A's face in B's potential, then B's
 * face in A's):
 *     F_n = (D+1) p / H_t * integral max(d, 0) dA   along -n_c,
 * integrated exactly (d is linear; the face is clipped at d = 0, so a face
 * that hinges open at one end is pressed only where shut), acting at the
 * centroid of max(d, 0) on the contactor face, its reaction on the target's
 * nodes by the target's barycentric coordinates of that same point: linear
 * and angular momentum to round-off, as in the general kernels. What it
 * leaves out against the general kernel is O(d / h) and O(s / h) of the
 * force (s the tangential offset of the copies): the strips along the
 * face's rim where another barycentric coordinate is smaller than d / H_t,
 * and the edge and corner pairs through the hair-apart copies, whose forces
 * are second order (an area ~ s L at a potential ~ s / h).
 * Friction (PHYSICS.md "Friction"): per role, the contactor face's stick
 * spring in the same slot the general kernel keeps it in (contact_pair.h:
 * face f of a at 3 f, face f of b at 12 + 3 f; 2D: edge i of a at i, of b
 * at 3 + i), loaded by the relative tangential velocity at the point of
 * action times h, kept in the face's current plane, capped at mu F_n, with
 * stiffness (2/3)(D+1) p A_touch / h_t (h_t the target's smallest height),
 * as the general kernel: a pair that passes between the two kernels keeps
 * its springs, meaning the same, and the stable step is unchanged. Every
 * other slot is let go. Sliding dissipates cap x slip, handed back.
 *
 * Contract: the contact stage's kernel call (contact_pair.h) plus where the
 * joint lies in the two elements (face_match); the same out layout (forces
 * on a's nodes, then b's, then dissipation) and spring slots. Returns 1 if
 * some part of the face overlaps (d > 0), else 0 with every spring let go
 * and out[0] = 0 (no clearance: a shut pair is never apart by more than the
 * tolerance). An inverted element: no potential, 0.
 */
#ifndef FDEM_CONTACT_FACE_H
#define FDEM_CONTACT_FACE_H

#include <stdint.h>

#include "contact_pair.h"

/* Where a joint lies in its two elements: the local face (3D: the
 * tet_face_nodes row, face f opposite node f; 2D: edge i from corner i to
 * i+1) of a and of b, and for each corner of a's face (in that face's
 * order) the local corner of b holding its copy. */
typedef struct face_match {
    int face_a, face_b;
    int copy_in_b[3];
} face_match;

int tri_face_pair_force(const contact_pair_in *in, const face_match *fm, double *springs,
                        double *out);
int tet_face_pair_force(const contact_pair_in *in, const face_match *fm, double *springs,
                        double *out);

/* The overlap integral of a linear depth over a segment or triangle,
 * clipped at depth 0, in the face's own weights (shared by both kernels):
 * i0 = integral max(d, 0) over the reference simplex (length 1 or area 1/2
 * scaled to 1: multiply by the face's length or twice its area), w its
 * centroid's weights on the face's corners, touch the fraction of the face
 * where d > 0. Returns 0 where d <= 0 everywhere. */
int face_overlap_integral(int corners, const double depth[3], double *i0, double w[3],
                          double *touch);

/* The segment's case, inline: the 2D kernel's call to the function above
 * (a call and a branch on `corners`) was 8 % of a broken 2D block's step. */
static inline int face_segment_overlap(const double d[2], double *i0, double w[3], double *touch)
{
    if (d[0] > 0 && d[1] > 0) {
        /* pressed along the whole edge (most shut pairs): the sums below
         * with s0 = 0, s1 = 1, and one division for the centroid */
        double sum0 = 0.5 * (d[0] + d[1]);
        double s = (d[0] + 2 * d[1]) / (3 * (d[0] + d[1]));
        *i0 = sum0;
        w[0] = 1.0 - s;
        w[1] = s;
        w[2] = 0;
        *touch = 1;
        return 1;
    }
    double s0 = 0, s1 = 1;
    if (d[0] <= 0 && d[1] <= 0) return 0;
    if (d[0] <= 0) s0 = d[0] / (d[0] - d[1]);
    else if (d[1] <= 0) s1 = d[0] / (d[0] - d[1]);
    double e0 = d[0] + s0 * (d[1] - d[0]), e1 = d[0] + s1 * (d[1] - d[0]);
    double len = s1 - s0;
    double sum0 = 0.5 * len * (e0 + e1);
    double sum1 = len / 6.0 * (e0 * (2 * s0 + s1) + e1 * (s0 + 2 * s1));
    if (!(sum0 > 0)) return 0;
    double s = sum1 / sum0;
    *i0 = sum0;
    w[0] = 1.0 - s;
    w[1] = s;
    w[2] = 0;
    *touch = len;
    return 1;
}

/* The triangle's case, its whole-face part inline (a shut face pressed
 * over all of it: most shut pairs; as a call it was 7 % of a broken 3D
 * block's step), the cut face out of line (contact_face.c). The fan sum
 * of face_triangle_overlap_cut with one triangle, the weights' corners
 * and frac 1: the same sums in the same order. */
int face_triangle_overlap_cut(const double d[3], double *i0, double w[3], double *touch);
static inline int face_triangle_overlap(const double d[3], double *i0, double w[3], double *touch)
{
    if (!(d[0] > 0 && d[1] > 0 && d[2] > 0)) return face_triangle_overlap_cut(d, i0, w, touch);
    double fsum = d[0] + d[1] + d[2];
    double sum0 = fsum / 3.0;
    if (!(sum0 > 0)) return 0;
    *i0 = sum0;
    for (int i = 0; i < 3; i++) w[i] = 1.0 / 12.0 * (d[i] + fsum) / sum0;
    *touch = 1;
    return 1;
}

#endif /* FDEM_CONTACT_FACE_H */
