/*
 * contact_face.c - what the shut-joint kernels of both dimensions share
 * (contact_face.h): the integral of a linear depth over a segment or a
 * triangle, clipped where the depth is positive, and its centroid. Exact:
 * the clipped simplex is a segment, a triangle or a quadrilateral, and on a
 * triangle the integral of a linear f and its first moment in barycentric
 * weights are fan sums, integral f = A (f_a + f_b + f_c)/3 and integral
 * f w = A/12 (sum f_j w_j + sum f_j sum w_j), as contact_tet.c has them.
 */
#include "contact_face.h"

#include <math.h>

const double contact_zeros[CONTACT_PAIR_OUT_MAX] = {0};

/* The triangle's part where d > 0 in barycentric weights (at most 4
 * corners: one line cuts a triangle), then fan sums; the whole face's
 * case is face_triangle_overlap's (contact_face.h). */
int face_triangle_overlap_cut(const double d[3], double *i0, double w[3], double *touch)
{
    if (d[0] <= 0 && d[1] <= 0 && d[2] <= 0) return 0;
    double poly[4][3], depth[4];
    int n = 0;
    for (int a = 0; a < 3; a++) {
        int b = (a + 1) % 3;
        if (d[a] > 0) {
            for (int i = 0; i < 3; i++) poly[n][i] = i == a;
            depth[n++] = d[a];
        }
        if ((d[a] > 0) != (d[b] > 0)) { /* the edge crosses d = 0 */
            double t = d[a] / (d[a] - d[b]);
            for (int i = 0; i < 3; i++) poly[n][i] = (i == a) * (1 - t) + (i == b) * t;
            depth[n++] = 0;
        }
    }
    if (n < 3) return 0;
    double sum0 = 0, area = 0, moment[3] = {0, 0, 0};
    for (int k = 1; k + 1 < n; k++) {
        const double *p = poly[0], *q = poly[k], *r = poly[k + 1];
        double frac = fabs(p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) +
                           p[2] * (q[0] * r[1] - q[1] * r[0]));
        double fsum = depth[0] + depth[k] + depth[k + 1];
        sum0 += frac * fsum / 3.0;
        area += frac;
        for (int i = 0; i < 3; i++)
            moment[i] += frac / 12.0 *
                         (depth[0] * p[i] + depth[k] * q[i] + depth[k + 1] * r[i] +
                          fsum * (p[i] + q[i] + r[i]));
    }
    if (!(sum0 > 0)) return 0;
    *i0 = sum0;
    for (int i = 0; i < 3; i++) w[i] = moment[i] / sum0;
    *touch = area;
    return 1;
}

int face_overlap_integral(int corners, const double depth[3], double *i0, double w[3],
                          double *touch)
{
    return corners == 2 ? face_segment_overlap(depth, i0, w, touch)
                        : face_triangle_overlap(depth, i0, w, touch);
}
