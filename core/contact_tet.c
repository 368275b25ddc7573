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
 *
 * It is also the tetrahedron pair kernel of the contact stage
 * (contact_pair.h), with Coulomb friction the way contact_tri.c has it for
 * triangles: each contactor face of a pair carries a tangential spring
 * vector, loaded by the relative tangential velocity at the force's point of
 * action times h, kept in the face's current plane (the part along the new
 * normal is dropped each step) and capped at mu |Fn|, beyond which the
 * surfaces slide and the spring stays at the cap; what sliding dissipates,
 * cap x slip, is handed back. Its stiffness is 2/3 of the normal one:
 * phi_t = 4 lambda grows at up to 4 / h_t with depth (h_t the target's
 * smallest height), so a face of area A inside t is pressed back at
 * 4 p A / h_t per unit depth, and the spring gets (2/3) 4 p A / h_t: it
 * adds nothing to the stable step.
 */
#include "contact_tet.h"
#include "contact_pair.h"
#include "element_tet.h"

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
    double det;         /* 6 V, signed */
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
    m.det = det;
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
 * lambda_k >= 0) - Sutherland-Hodgman on an affine function. Returns the
 * clipped polygon: poly itself when the plane cuts nothing (most planes),
 * else spare, written (so the caller swaps buffers instead of copying). */
static clip_polygon *clip_keep(clip_polygon *poly, clip_polygon *spare, int k, int j)
{
    int n = poly->count, inside = 0;
    double g[CLIP_MAX];
    for (int a = 0; a < n; a++) {
        g[a] = poly->v[a].lambda[k] - (j >= 0 ? poly->v[a].lambda[j] : 0.0);
        inside += g[a] >= 0;
    }
    if (inside == n) return poly;
    clip_polygon *out = spare;
    out->count = 0;
    if (inside == 0) return out;
    for (int a = 0; a < n; a++) {
        const clip_vertex *p = &poly->v[a], *q = &poly->v[(a + 1) % n];
        double gp = g[a], gq = g[(a + 1) % n];
        if (gp >= 0 && out->count < CLIP_MAX) out->v[out->count++] = *p;
        if ((gp >= 0) != (gq >= 0) && out->count < CLIP_MAX) {
            double t = gp / (gp - gq);
            clip_vertex *m = &out->v[out->count++];
            for (int i = 0; i < 3; i++) m->x[i] = p->x[i] + t * (q->x[i] - p->x[i]);
            for (int i = 0; i < 4; i++) m->lambda[i] = p->lambda[i] + t * (q->lambda[i] - p->lambda[i]);
        }
    }
    return out;
}

/* Integral of phi = 4 lambda_k over the polygon (*i0), its first moment
 * (i1) and its area (*area), by a fan from vertex 0. */
static void polygon_integrals(const clip_polygon *poly, int k, double *i0, double i1[3],
                              double *area_sum)
{
    for (int a = 1; a + 1 < poly->count; a++) {
        const clip_vertex *v[3] = {&poly->v[0], &poly->v[a], &poly->v[a + 1]};
        double u[3], w[3], n[3];
        vec3_sub(v[1]->x, v[0]->x, u);
        vec3_sub(v[2]->x, v[0]->x, w);
        vec3_cross(u, w, n);
        double area = 0.5 * sqrt(vec3_dot(n, n));
        *area_sum += area;
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

/* One contactor face inside the target's potential: where and how hard the
 * potential pushes it. */
typedef struct face_touch {
    double i0;          /* integral of phi_t over the face */
    double area;        /* area of the face inside t */
    double normal[3];   /* the face's outward unit normal */
    double wf[3];       /* the point of action's weights on the face's nodes */
    double lt[4];       /* and its barycentric coordinates in t */
} face_touch;

/* Some face plane of the target has all n points (their coordinates
 * lambda) outside: they miss it. Most candidate pairs end here. */
static int outside_one_face(const double (*lambda)[4], const int *which, int n)
{
    for (int j = 0; j < 4; j++) {
        int out = 1;
        for (int v = 0; v < n && out; v++) out = lambda[which[v]][j] < 0;
        if (out) return 1;
    }
    return 0;
}

/* Face m (opposite contactor node m, whose corners have the coordinates
 * lambda in the target) clipped to the target: 1 and *ft if the potential
 * acts on it, 0 if not. */
static int face_in_target(const double *const pc[4], const double (*lambda)[4], int m,
                          const bary_map *bt, face_touch *ft)
{
    const int *fn = tet_face_nodes[m];
    if (outside_one_face(lambda, fn, 3)) return 0;
    const double *a = pc[fn[0]], *b = pc[fn[1]], *c = pc[fn[2]];
    clip_polygon face;
    face.count = 3;
    for (int v = 0; v < 3; v++) {
        memcpy(face.v[v].x, pc[fn[v]], sizeof face.v[v].x);
        memcpy(face.v[v].lambda, lambda[fn[v]], sizeof face.v[v].lambda);
    }
    double i0 = 0, i1[3] = {0, 0, 0}, area = 0;
    clip_polygon buffers[2];
    for (int k = 0; k < 4; k++) {
        /* the face itself until some plane cuts it; then two buffers in turn */
        clip_polygon *poly = clip_keep(&face, &buffers[0], k, -1);
        for (int j = 0; j < 4 && poly->count >= 3; j++) {
            if (j == k) continue;
            clip_polygon *spare = poly == &buffers[0] ? &buffers[1] : &buffers[0];
            poly = clip_keep(poly, spare, j, k); /* lambda_j - lambda_k >= 0 */
        }
        if (poly->count >= 3) polygon_integrals(poly, k, &i0, i1, &area);
    }
    if (!(i0 > 0)) return 0;
    /* outward unit normal of the face: away from node m */
    double ab[3], ac[3], n[3], am[3];
    vec3_sub(b, a, ab);
    vec3_sub(c, a, ac);
    vec3_cross(ab, ac, n);
    vec3_sub(pc[m], a, am);
    double len = sqrt(vec3_dot(n, n));
    if (!(len > 0)) return 0;
    double sign = vec3_dot(n, am) > 0 ? -1.0 : 1.0;
    double point[3];
    for (int i = 0; i < 3; i++) {
        point[i] = i1[i] / i0;
        ft->normal[i] = sign * n[i] / len;
    }
    ft->i0 = i0;
    ft->area = area;
    face_weights(a, b, c, point, ft->wf);
    bary_at(bt, point, ft->lt);
    return 1;
}

/* Force on the face, shared by its nodes where it acts, and its reaction
 * on the target's nodes at the same point. */
static void face_force_apply(const face_touch *ft, int m, const double force[3], double f_c[12],
                             double f_t[12])
{
    const int *fn = tet_face_nodes[m];
    for (int v = 0; v < 3; v++)
        for (int i = 0; i < 3; i++) f_c[3 * fn[v] + i] += ft->wf[v] * force[i];
    for (int v = 0; v < 4; v++)
        for (int i = 0; i < 3; i++) f_t[3 * v + i] -= ft->lt[v] * force[i];
}

/* What friction needs beyond the normal force: velocities, the contactor's
 * and target's nodes, mu, the step, the contactor's four face springs
 * (3 each) and the dissipation so far. */
typedef struct tet_friction {
    const double *vel;
    const int32_t *contactor, *target;
    double mu, h;
    double *springs;
    double *dissipated;
} tet_friction;

/* The target's smallest height, det / (largest |face cross product|). */
static double tet_smallest_height_now(const double *const pt[4], double det)
{
    double largest = 0;
    for (int m = 0; m < 4; m++) {
        const int *fn = tet_face_nodes[m];
        double ab[3], ac[3], n[3];
        vec3_sub(pt[fn[1]], pt[fn[0]], ab);
        vec3_sub(pt[fn[2]], pt[fn[0]], ac);
        vec3_cross(ab, ac, n);
        largest = fmax(largest, vec3_dot(n, n));
    }
    return fabs(det) / sqrt(largest);
}

/* The tangential force on face m: its spring, turned into the face's
 * current plane, loaded by the relative tangential slip of the last step
 * at the point of action and capped at mu |Fn|; added to force. */
static void face_friction(const face_touch *ft, int m, double k_n, double f_n, tet_friction *fr,
                          double force[3])
{
    const int *fn = tet_face_nodes[m];
    const double *v = fr->vel, *n = ft->normal;
    double rel[3] = {0, 0, 0};
    for (int i = 0; i < 3; i++) {
        for (int c = 0; c < 3; c++) rel[i] += ft->wf[c] * v[3 * (size_t)fr->contactor[fn[c]] + i];
        for (int t = 0; t < 4; t++) rel[i] -= ft->lt[t] * v[3 * (size_t)fr->target[t] + i];
    }
    double *spring = fr->springs + 3 * m;
    double rel_n = vec3_dot(rel, n), spring_n = vec3_dot(spring, n);
    double k_t = (2.0 / 3.0) * k_n * ft->area, cap = fr->mu * f_n;
    double f[3];
    for (int i = 0; i < 3; i++)
        f[i] = (spring[i] - spring_n * n[i]) - k_t * (rel[i] - rel_n * n[i]) * fr->h;
    double size = sqrt(vec3_dot(f, f));
    if (size > cap) {
        *fr->dissipated += cap * (size - cap) / k_t;
        for (int i = 0; i < 3; i++) f[i] *= cap / size;
    }
    for (int i = 0; i < 3; i++) {
        spring[i] = f[i];
        force[i] += f[i];
    }
}

/* A tetrahedron's corner positions and barycentric map, worked out once
 * a pair and used in both roles. */
typedef struct tet_frame {
    const double *p[4];
    bary_map bary;
} tet_frame;

static void tet_frame_of(const double *pos, const int32_t n[4], tet_frame *t)
{
    for (int v = 0; v < 4; v++) t->p[v] = pos + 3 * (size_t)n[v];
    t->bary = bary_of(t->p);
}

/* One way, with friction when fr is not NULL (a face that does not touch
 * lets its spring go). */
static double contact_one_way(const tet_frame *contactor, const tet_frame *target,
                              double penalty, tet_friction *fr, double f_c[12], double f_t[12])
{
    const double *const *pc = contactor->p, *const *pt = target->p;
    const bary_map bt = target->bary;
    if (!bt.valid) return 0.0;
    double lambda[4][4];
    static const int all[4] = {0, 1, 2, 3};
    for (int v = 0; v < 4; v++) bary_at(&bt, pc[v], lambda[v]);
    if (outside_one_face((const double (*)[4])lambda, all, 4)) {
        if (fr) memset(fr->springs, 0, 12 * sizeof(double));
        return 0.0;
    }
    double total = 0, k_n = 0; /* 4 p / h_t, once some face needs it */
    for (int m = 0; m < 4; m++) {
        face_touch ft;
        if (!face_in_target(pc, (const double (*)[4])lambda, m, &bt, &ft)) {
            if (fr) memset(fr->springs + 3 * m, 0, 3 * sizeof(double));
            continue;
        }
        double f_n = penalty * ft.i0, force[3];
        for (int i = 0; i < 3; i++) force[i] = -f_n * ft.normal[i];
        if (fr && fr->mu > 0 && ft.area > 0) {
            if (k_n == 0) k_n = 4 * penalty / tet_smallest_height_now(pt, bt.det);
            face_friction(&ft, m, k_n, f_n, fr, force);
        } else if (fr) {
            memset(fr->springs + 3 * m, 0, 3 * sizeof(double));
        }
        face_force_apply(&ft, m, force, f_c, f_t);
        total += ft.i0;
    }
    return total;
}

double tet_contact_one_way(const double *pos, const int32_t contactor[4],
                           const int32_t target[4], double penalty, double f_c[12],
                           double f_t[12])
{
    tet_frame c, t;
    tet_frame_of(pos, contactor, &c);
    tet_frame_of(pos, target, &t);
    return contact_one_way(&c, &t, penalty, NULL, f_c, f_t);
}

double tet_contact_pair(const double *pos, const int32_t a[4], const int32_t b[4],
                        double penalty, double f_a[12], double f_b[12])
{
    memset(f_a, 0, 12 * sizeof *f_a);
    memset(f_b, 0, 12 * sizeof *f_b);
    return tet_contact_one_way(pos, a, b, penalty, f_a, f_b) +
           tet_contact_one_way(pos, b, a, penalty, f_b, f_a);
}

int tet_contact_pair_force(const contact_pair_in *in, double *springs, double *out)
{
    tet_frame a, b;
    tet_frame_of(in->pos, in->node_a, &a);
    tet_frame_of(in->pos, in->node_b, &b);
    if (!(a.bary.valid && a.bary.det > 0) || !(b.bary.valid && b.bary.det > 0)) {
        memset(springs, 0, sizeof(double) * TET_CONTACT_SLOTS); /* inverted: no potential */
        return 0;
    }
    for (int k = 0; k < TET_PAIR_OUT; k++) out[k] = 0;
    double *dissipated = &out[TET_PAIR_OUT - 1];
    tet_friction ab = {in->vel, in->node_a, in->node_b, in->friction, in->h, springs, dissipated};
    tet_friction ba = {in->vel, in->node_b, in->node_a, in->friction, in->h,
                       springs + TET_CONTACT_SLOTS / 2, dissipated};
    double touched = contact_one_way(&a, &b, in->penalty, &ab, out, out + 12);
    touched += contact_one_way(&b, &a, in->penalty, &ba, out + 12, out);
    return touched > 0;
}
