/*
 * contact_tet.c - potential contact between tetrahedra (contact_tet.h).
 *
 * Per contactor face the face triangle is clipped, in the target's
 * barycentric coordinates, to each sub-tetrahedron k of the target: the
 * region lambda_k >= 0 and lambda_j >= lambda_k (j != k), where phi_t =
 * 4 lambda_k is linear. The clipping carries lambda with each polygon
 * vertex (lambda is affine, so it interpolates exactly along a clipped
 * edge), and the integral of the linear phi over the polygon and its first
 * moment are exact fan sums: integral f = A (f_a + f_b + f_c)/3 and
 * integral f x = A/12 (sum f_i x_i + sum f_i sum x_i) on each triangle.
 */
#include "contact_tet.h"

#include <math.h>
#include <string.h>

#include "vec3.h"

#define CLIP_MAX 12 /* a triangle clipped by 4 planes has at most 7 vertices */

typedef struct clip_vertex {
    double x[3];
    double lambda[4];
} clip_vertex;

typedef struct clip_polygon {
    clip_vertex v[CLIP_MAX];
    int count;
} clip_polygon;

/* The target's barycentric map: lambda_{1..3} = rows . (x - x0). */
typedef struct bary_map {
    double origin[3];
    double rows[3][3];
    int valid;
} bary_map;

static bary_map bary_of(const double *p[4])
{
    bary_map m;
    double e[3][3], c[3][3];
    for (int k = 0; k < 3; k++) vec3_sub(p[k + 1], p[0], e[k]);
    vec3_cross(e[1], e[2], c[0]);
    vec3_cross(e[2], e[0], c[1]);
    vec3_cross(e[0], e[1], c[2]);
    double det = vec3_dot(e[0], c[0]);
    m.valid = fabs(det) > 0 && isfinite(det);
    memcpy(m.origin, p[0], sizeof m.origin);
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) m.rows[k][i] = m.valid ? c[k][i] / det : 0.0;
    return m;
}

static void bary_at(const bary_map *m, const double x[3], double lambda[4])
{
    double d[3];
    vec3_sub(x, m->origin, d);
    lambda[1] = vec3_dot(m->rows[0], d);
    lambda[2] = vec3_dot(m->rows[1], d);
    lambda[3] = vec3_dot(m->rows[2], d);
    lambda[0] = 1.0 - lambda[1] - lambda[2] - lambda[3];
}

/* Keeps the part of the polygon where lambda_k - lambda_j >= 0 (j < 0:
 * lambda_k >= 0) - Sutherland-Hodgman on an affine function. */
static void clip_keep(clip_polygon *poly, int k, int j)
{
    clip_polygon out;
    out.count = 0;
    int n = poly->count;
    for (int a = 0; a < n; a++) {
        const clip_vertex *p = &poly->v[a], *q = &poly->v[(a + 1) % n];
        double gp = p->lambda[k] - (j >= 0 ? p->lambda[j] : 0.0);
        double gq = q->lambda[k] - (j >= 0 ? q->lambda[j] : 0.0);
        if (gp >= 0 && out.count < CLIP_MAX) out.v[out.count++] = *p;
        if ((gp >= 0) != (gq >= 0) && out.count < CLIP_MAX) {
            double t = gp / (gp - gq);
            clip_vertex *m = &out.v[out.count++];
            for (int i = 0; i < 3; i++) m->x[i] = p->x[i] + t * (q->x[i] - p->x[i]);
            for (int i = 0; i < 4; i++) m->lambda[i] = p->lambda[i] + t * (q->lambda[i] - p->lambda[i]);
        }
    }
    *poly = out;
}

/* Integral of phi = 4 lambda_k over the polygon (*i0) and its first moment
 * (i1), by a fan from vertex 0. */
static void polygon_integrals(const clip_polygon *poly, int k, double *i0, double i1[3])
{
    for (int a = 1; a + 1 < poly->count; a++) {
        const clip_vertex *v[3] = {&poly->v[0], &poly->v[a], &poly->v[a + 1]};
        double u[3], w[3], n[3];
        vec3_sub(v[1]->x, v[0]->x, u);
        vec3_sub(v[2]->x, v[0]->x, w);
        vec3_cross(u, w, n);
        double area = 0.5 * sqrt(vec3_dot(n, n));
        double phi[3] = {4 * v[0]->lambda[k], 4 * v[1]->lambda[k], 4 * v[2]->lambda[k]};
        double sum_phi = phi[0] + phi[1] + phi[2];
        *i0 += area * sum_phi / 3.0;
        for (int i = 0; i < 3; i++) {
            double sum_x = v[0]->x[i] + v[1]->x[i] + v[2]->x[i];
            double mixed = phi[0] * v[0]->x[i] + phi[1] * v[1]->x[i] + phi[2] * v[2]->x[i];
            i1[i] += area / 12.0 * (mixed + sum_phi * sum_x);
        }
    }
}

/* Barycentric coordinates of x (in the plane) on the triangle a, b, c. */
static void face_weights(const double *a, const double *b, const double *c, const double x[3],
                         double w[3])
{
    double ab[3], ac[3], ax[3], n[3], t[3];
    vec3_sub(b, a, ab);
    vec3_sub(c, a, ac);
    vec3_sub(x, a, ax);
    vec3_cross(ab, ac, n);
    double n2 = vec3_dot(n, n);
    vec3_cross(ax, ac, t);
    w[1] = vec3_dot(t, n) / n2;
    vec3_cross(ab, ax, t);
    w[2] = vec3_dot(t, n) / n2;
    w[0] = 1.0 - w[1] - w[2];
}

static const int face_nodes[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

/* One contactor face (opposite contactor node m) in the target's potential. */
static double face_in_target(const double *pc[4], int m, const bary_map *bt, double penalty,
                             double f_c[12], double f_t[12])
{
    const int *fn = face_nodes[m];
    const double *a = pc[fn[0]], *b = pc[fn[1]], *c = pc[fn[2]];
    clip_polygon face;
    face.count = 3;
    for (int v = 0; v < 3; v++) {
        memcpy(face.v[v].x, pc[fn[v]], sizeof face.v[v].x);
        bary_at(bt, face.v[v].x, face.v[v].lambda);
    }
    double i0 = 0, i1[3] = {0, 0, 0};
    for (int k = 0; k < 4; k++) {
        clip_polygon poly = face;
        clip_keep(&poly, k, -1);
        for (int j = 0; j < 4 && poly.count >= 3; j++)
            if (j != k) clip_keep(&poly, j, k); /* lambda_j - lambda_k >= 0 */
        if (poly.count >= 3) polygon_integrals(&poly, k, &i0, i1);
    }
    if (!(i0 > 0)) return 0.0;
    /* outward unit normal of the face: away from node m */
    double ab[3], ac[3], n[3], am[3];
    vec3_sub(b, a, ab);
    vec3_sub(c, a, ac);
    vec3_cross(ab, ac, n);
    vec3_sub(pc[m], a, am);
    double len = sqrt(vec3_dot(n, n));
    if (!(len > 0)) return 0.0;
    double sign = vec3_dot(n, am) > 0 ? -1.0 : 1.0;
    double point[3], force[3], wf[3], lt[4];
    for (int i = 0; i < 3; i++) {
        point[i] = i1[i] / i0;
        force[i] = -penalty * i0 * sign * n[i] / len;
    }
    face_weights(a, b, c, point, wf);
    bary_at(bt, point, lt);
    for (int v = 0; v < 3; v++)
        for (int i = 0; i < 3; i++) f_c[3 * fn[v] + i] += wf[v] * force[i];
    for (int v = 0; v < 4; v++)
        for (int i = 0; i < 3; i++) f_t[3 * v + i] -= lt[v] * force[i];
    return i0;
}

double tet_contact_one_way(const double *pos, const int32_t contactor[4],
                           const int32_t target[4], double penalty, double f_c[12],
                           double f_t[12])
{
    const double *pc[4], *pt[4];
    for (int v = 0; v < 4; v++) {
        pc[v] = pos + 3 * (size_t)contactor[v];
        pt[v] = pos + 3 * (size_t)target[v];
    }
    bary_map bt = bary_of(pt);
    if (!bt.valid) return 0.0;
    double total = 0;
    for (int m = 0; m < 4; m++) total += face_in_target(pc, m, &bt, penalty, f_c, f_t);
    return total;
}

double tet_contact_pair(const double *pos, const int32_t a[4], const int32_t b[4],
                        double penalty, double f_a[12], double f_b[12])
{
    memset(f_a, 0, 12 * sizeof *f_a);
    memset(f_b, 0, 12 * sizeof *f_b);
    return tet_contact_one_way(pos, a, b, penalty, f_a, f_b) +
           tet_contact_one_way(pos, b, a, penalty, f_b, f_a);
}
