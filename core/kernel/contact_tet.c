/*
 * contact_tet.c - potential contact between tetrahedra (contact_tet.h).
 *
 * Per contactor face the face triangle is clipped to the target and the
 * target's phi_t = 4 min_k lambda_k integrated over what is left, in the
 * face's own weights w (the face is the triangle (0,0), (1,0), (0,1)):
 * lambda is affine along the face, so every plane is an affine function of
 * w, a polygon vertex is two numbers, and the point of action comes out as
 * weights on the face's nodes. phi_t is linear only on a sub-tetrahedron
 * (lambda_k the smallest), so the clipped face is split where two
 * candidate lambdas are equal until one candidate is left on each piece;
 * on a piece the integral of the linear phi and its first moment are exact
 * fan sums: integral f = A (f_a + f_b + f_c)/3 and integral f w = A/12
 * (sum f_i w_i + sum f_i sum w_i) on each triangle. Most faces never get
 * that far: cheap separating planes (a face plane of either tetrahedron
 * with the other's corners all outside it, the face's own plane with the
 * target's corners all on one side) end them first.
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
#include "contact_spring.h"
#include "element_tet.h"

#include <math.h>
#include <string.h>

#include "math/vec3.h"

/* A cut adds at most one vertex: the face's triangle cut by the target's 4
 * face planes, then split by at most 3 sub-tetrahedron planes, has at most
 * 10. */
#define CLIP_MAX 12

/* A polygon on a contactor face, its vertices given by w, their weights on
 * the face's second and third corners (the first corner's is 1 - w[0] -
 * w[1]): the face is the triangle (0,0), (1,0), (0,1) in w. The target's
 * barycentric coordinates are affine along the face, so each clipping plane
 * is an affine function of w and x is never needed. */
typedef struct face_polygon {
    double w[CLIP_MAX][2];
    int count;
} face_polygon;

/* An affine function of w on a face: c[0] + c[1] w[0] + c[2] w[1]. */
typedef struct face_affine {
    double c[3];
} face_affine;

static inline double affine_at(const face_affine *f, const double w[2])
{
    return f->c[0] + f->c[1] * w[0] + f->c[2] * w[1];
}

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

/* Puts the vertex (x, y) at place k of w; returns the next place. The
 * clipping loops keep their counts in locals, not in the polygon: a count
 * read back from memory after every store was a fifth of their work. */
static inline int vertex_put(double (*w)[2], int k, double x, double y)
{
    w[k][0] = x;
    w[k][1] = y;
    return k + 1;
}

/* Keeps the part of the polygon inside a plane g >= 0 that cuts it (some
 * vertices in, some out) - Sutherland-Hodgman - in out. */
static void clip_keep(const face_polygon *poly, face_polygon *out, const face_affine *g)
{
    int n = poly->count, kept = 0;
    double depth[CLIP_MAX + 1];
    for (int a = 0; a < n; a++) depth[a] = affine_at(g, poly->w[a]);
    depth[n] = depth[0];
    for (int a = 0; a < n; a++) {
        const double *u = poly->w[a], *v = poly->w[a + 1 < n ? a + 1 : 0];
        if (depth[a] >= 0) kept = vertex_put(out->w, kept, u[0], u[1]);
        if ((depth[a] >= 0) != (depth[a + 1] >= 0)) {
            double t = depth[a] / (depth[a] - depth[a + 1]);
            kept = vertex_put(out->w, kept, u[0] + t * (v[0] - u[0]), u[1] + t * (v[1] - u[1]));
        }
    }
    out->count = kept;
}

/* Splits the polygon, with the depths of its vertices below a plane, into
 * the parts above (depth >= 0) and below (depth <= 0) it, in one pass. */
static void split_by(const face_polygon *poly, const double *depth, face_polygon *above,
                     face_polygon *below)
{
    int n = poly->count, up = 0, down = 0;
    for (int a = 0; a < n; a++) {
        int b = a + 1 < n ? a + 1 : 0;
        const double *u = poly->w[a], *v = poly->w[b];
        if (depth[a] >= 0) up = vertex_put(above->w, up, u[0], u[1]);
        if (depth[a] <= 0) down = vertex_put(below->w, down, u[0], u[1]);
        if ((depth[a] > 0 && depth[b] < 0) || (depth[a] < 0 && depth[b] > 0)) {
            double t = depth[a] / (depth[a] - depth[b]);
            double x = u[0] + t * (v[0] - u[0]), y = u[1] + t * (v[1] - u[1]);
            up = vertex_put(above->w, up, x, y);
            down = vertex_put(below->w, down, x, y);
        }
    }
    above->count = up;
    below->count = down;
}

/* The polygon cut by the planes in turn, in one of the two buffers (poly
 * itself when there is none). */
static const face_polygon *clip_all(const face_polygon *poly, const face_affine *const *planes,
                                    int count, face_polygon buffers[2])
{
    for (int c = 0; c < count && poly->count >= 3; c++) {
        face_polygon *out = poly == &buffers[0] ? &buffers[1] : &buffers[0];
        clip_keep(poly, out, planes[c]);
        poly = out;
    }
    return poly;
}

/* The integral over the polygon of phi (sums[0]), its first moment in w
 * (sums[1], sums[2]) and the polygon's area (sums[3]), in units of twice
 * the face's area (the face has area 1/2 in w), by a fan from vertex 0:
 * integral f = A (f_a + f_b + f_c)/3 and integral f w = A/12 (sum f_i w_i +
 * sum f_i sum w_i) on each triangle. A clipped triangle keeps its turn, so
 * the signed areas of the fan's triangles are their areas. */
static void polygon_integrals(const face_polygon *poly, const face_affine *phi_of,
                              double sums[4])
{
    const double *o = poly->w[0];
    double phi_o = affine_at(phi_of, o), phi_p = affine_at(phi_of, poly->w[1]);
    for (int a = 1; a + 1 < poly->count; a++) {
        const double *p = poly->w[a], *q = poly->w[a + 1];
        double phi_q = affine_at(phi_of, q);
        double area = 0.5 * ((p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0]));
        double sum_phi = phi_o + phi_p + phi_q;
        sums[0] += area * sum_phi / 3.0;
        for (int i = 0; i < 2; i++) {
            double sum_w = o[i] + p[i] + q[i];
            double mixed = phi_o * o[i] + phi_p * p[i] + phi_q * q[i];
            sums[1 + i] += area / 12.0 * (mixed + sum_phi * sum_w);
        }
        sums[3] += area;
        phi_p = phi_q;
    }
}

/* A list of up to four candidates (sub-tetrahedra, by the target face
 * they stand on), four bits each, the first in the lowest. */
typedef unsigned candidate_list;
#define CANDIDATES_ALL 0x3210u

static inline int candidate_first(candidate_list c) { return (int)(c & 15u); }
static inline int candidate_second(candidate_list c) { return (int)(c >> 4 & 15u); }
static inline candidate_list candidates_but_first(candidate_list c) { return c >> 4; }
static inline candidate_list candidates_but_second(candidate_list c)
{
    return (c & 15u) | (c >> 8) << 4;
}

/* Adds to sums the integrals (polygon_integrals) of phi_t = 4 min lambda_k
 * over the polygon, k among the count candidates. phi_t is linear only
 * where one lambda_k is the smallest (sub-tetrahedron k), so the polygon is
 * split where the first two, i and j, are equal: above lambda_i - lambda_j
 * = 0, i is never the smallest, below j is not. A polygon on one side
 * (most) is not cut: that candidate is dropped and the loop goes on with
 * the next two; a split recurses on both sides, which yields both in one
 * pass. */
static void integrate_min(const face_polygon *poly, const face_affine lambda[4],
                          candidate_list cand, int count, double sums[4])
{
    for (; count > 1; count--) {
        const face_affine *li = &lambda[candidate_first(cand)];
        const face_affine *lj = &lambda[candidate_second(cand)];
        face_affine g;
        for (int i = 0; i < 3; i++) g.c[i] = li->c[i] - lj->c[i];
        double depth[CLIP_MAX];
        int above = 0, below = 0;
        for (int a = 0; a < poly->count; a++) {
            depth[a] = affine_at(&g, poly->w[a]);
            above += depth[a] > 0;
            below += depth[a] < 0;
        }
        if (below == 0) { /* i is nowhere the smallest */
            cand = candidates_but_first(cand);
        } else if (above == 0) { /* nor is j */
            cand = candidates_but_second(cand);
        } else {
            face_polygon part_above, part_below;
            split_by(poly, depth, &part_above, &part_below);
            if (part_above.count >= 3)
                integrate_min(&part_above, lambda, candidates_but_first(cand), count - 1, sums);
            if (part_below.count >= 3)
                integrate_min(&part_below, lambda, candidates_but_second(cand), count - 1, sums);
            return;
        }
    }
    face_affine phi;
    for (int i = 0; i < 3; i++) phi.c[i] = 4 * lambda[candidate_first(cand)].c[i];
    polygon_integrals(poly, &phi, sums);
}

/* The face clipped to the target (lambda_f >= 0, given as affine functions
 * on the face), then the integrals of phi_t over it (integrate_min). The
 * planes that cut the face's triangle are those its corners' outside masks
 * (outside_mask) name: one corner outside is enough, all three never are
 * (face_in_target has let the face go then). */
static void face_clipped_integrals(const face_affine lambda[4], unsigned corners_outside,
                                   double sums[4])
{
    static const face_polygon face = {{{0, 0}, {1, 0}, {0, 1}}, 3};
    face_polygon inside[2];
    const face_affine *cut[4];
    int cuts = 0;
    for (int f = 0; f < 4; f++)
        if (corners_outside & 1u << f) cut[cuts++] = &lambda[f];
    const face_polygon *part = clip_all(&face, cut, cuts, inside);
    if (part->count >= 3) integrate_min(part, lambda, CANDIDATES_ALL, 4, sums);
}

/* The plane of a face (corners' coordinates la, lb, lc in the target)
 * has all four of the target's corners strictly on one side: the face
 * misses the target. In the coordinates (lambda_1, lambda_2, lambda_3) the
 * target's corners are 0 and the unit vectors, and the map from x is
 * affine, so the sides are the signs of c . (e_v - la), c = (lb - la) x
 * (lc - la). */
static int face_plane_separates(const double la[4], const double lb[4], const double lc[4])
{
    double u[3], v[3], c[3];
    vec3_sub(lb + 1, la + 1, u);
    vec3_sub(lc + 1, la + 1, v);
    vec3_cross(u, v, c);
    double s = vec3_dot(c, la + 1);
    double side[4] = {-s, c[0] - s, c[1] - s, c[2] - s};
    int above = 0, below = 0;
    for (int v_ = 0; v_ < 4; v_++) {
        above += side[v_] > 0;
        below += side[v_] < 0;
    }
    return above == 4 || below == 4;
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

/* Which face planes of the target a point (its coordinates lambda) is
 * outside of: bit j for lambda_j < 0. Points whose masks share a bit all
 * miss the target on that side - most candidate pairs end there - and the
 * test is an AND, without a branch per coordinate. */
static inline unsigned outside_mask(const double lambda[4])
{
    return (unsigned)(lambda[0] < 0) | (unsigned)(lambda[1] < 0) << 1 |
           (unsigned)(lambda[2] < 0) << 2 | (unsigned)(lambda[3] < 0) << 3;
}

/* Face m (opposite contactor node m, whose corners have the coordinates
 * lambda in the target) clipped to the target: 1 and *ft if the potential
 * acts on it, 0 if not. */
static int face_in_target(const double *const pc[4], const double (*lambda)[4],
                          const unsigned outside[4], int m, face_touch *ft)
{
    const int *fn = tet_face_nodes[m];
    if (outside[fn[0]] & outside[fn[1]] & outside[fn[2]]) return 0;
    const double *la = lambda[fn[0]], *lb = lambda[fn[1]], *lc = lambda[fn[2]];
    if (face_plane_separates(la, lb, lc)) return 0;
    face_affine along[4]; /* the target's lambda_i along the face */
    for (int i = 0; i < 4; i++) {
        along[i].c[0] = la[i];
        along[i].c[1] = lb[i] - la[i];
        along[i].c[2] = lc[i] - la[i];
    }
    double sums[4] = {0, 0, 0, 0};
    face_clipped_integrals(along, outside[fn[0]] | outside[fn[1]] | outside[fn[2]], sums);
    if (!(sums[0] > 0)) return 0;
    /* outward normal of the face, away from node m; |n| is twice its area */
    const double *a = pc[fn[0]], *b = pc[fn[1]], *c = pc[fn[2]];
    double ab[3], ac[3], n[3], am[3];
    vec3_sub(b, a, ab);
    vec3_sub(c, a, ac);
    vec3_cross(ab, ac, n);
    vec3_sub(pc[m], a, am);
    double len = sqrt(vec3_dot(n, n));
    if (!(len > 0)) return 0;
    double sign = vec3_dot(n, am) > 0 ? -1.0 : 1.0;
    for (int i = 0; i < 3; i++) ft->normal[i] = sign * n[i] / len;
    ft->i0 = len * sums[0];
    ft->area = len * sums[3];
    /* the point of action: its weights on the face, and in t (affine in w) */
    double w1 = sums[1] / sums[0], w2 = sums[2] / sums[0];
    ft->wf[0] = 1.0 - w1 - w2;
    ft->wf[1] = w1;
    ft->wf[2] = w2;
    for (int i = 1; i < 4; i++) ft->lt[i] = ft->wf[0] * la[i] + w1 * lb[i] + w2 * lc[i];
    ft->lt[0] = 1.0 - ft->lt[1] - ft->lt[2] - ft->lt[3];
    return 1;
}

/* Force on the face, shared by its nodes where it acts, and its reaction
 * on the target's nodes at the same point. */
static void face_force_apply(const face_touch *ft, int m, const double force[3], double f_c[12],
                             double f_t[12])
{
    /* in locals: the stores to f_c and f_t could alias them otherwise */
    const int *fn = tet_face_nodes[m];
    const double f[3] = {force[0], force[1], force[2]};
    const double wf[3] = {ft->wf[0], ft->wf[1], ft->wf[2]};
    const double lt[4] = {ft->lt[0], ft->lt[1], ft->lt[2], ft->lt[3]};
    for (int v = 0; v < 3; v++)
        for (int i = 0; i < 3; i++) f_c[3 * fn[v] + i] += wf[v] * f[i];
    for (int v = 0; v < 4; v++)
        for (int i = 0; i < 3; i++) f_t[3 * v + i] -= lt[v] * f[i];
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
    const double *n = ft->normal, *vc[3], *vt[4];
    for (int c = 0; c < 3; c++) vc[c] = fr->vel + 3 * (size_t)fr->contactor[fn[c]];
    for (int t = 0; t < 4; t++) vt[t] = fr->vel + 3 * (size_t)fr->target[t];
    double rel[3] = {0, 0, 0};
    for (int i = 0; i < 3; i++) {
        for (int c = 0; c < 3; c++) rel[i] += ft->wf[c] * vc[c][i];
        for (int t = 0; t < 4; t++) rel[i] -= ft->lt[t] * vt[t][i];
    }
    double k_t = (2.0 / 3.0) * k_n * ft->area;
    contact_spring_load(fr->springs + 3 * m, n, rel, k_t, fr->h, fr->mu * f_n, fr->dissipated,
                        force);
}

/* A tetrahedron's corner positions and barycentric map, worked out once
 * a pair and used in both roles. */
typedef struct tet_frame {
    const double *p[4];
    bary_map bary;
} tet_frame;

static void tet_corners_of(const double *pos, const int32_t n[4], tet_frame *t)
{
    for (int v = 0; v < 4; v++) t->p[v] = pos + 3 * (size_t)n[v];
}

static void tet_frame_of(const double *pos, const int32_t n[4], tet_frame *t)
{
    tet_corners_of(pos, n, t);
    t->bary = bary_of(t->p);
}

/* A contactor's corners in the target: their barycentric coordinates and
 * outside masks (outside_mask). */
typedef struct corners_in {
    double lambda[4][4];
    unsigned outside[4];
} corners_in;

/* The contactor's corners in the target; 1 if they are all outside one of
 * its face planes: that plane separates the two, no face of either touches
 * the other, both ways. */
static int corners_in_target(const tet_frame *contactor, const tet_frame *target, corners_in *ci)
{
    for (int v = 0; v < 4; v++) {
        bary_at(&target->bary, contactor->p[v], ci->lambda[v]);
        ci->outside[v] = outside_mask(ci->lambda[v]);
    }
    return (ci->outside[0] & ci->outside[1] & ci->outside[2] & ci->outside[3]) != 0;
}

/* One way, the contactor's corners in the target given, with friction when
 * fr is not NULL (a face that does not touch lets its spring go). */
static double contact_one_way(const tet_frame *contactor, const tet_frame *target,
                              const corners_in *ci, double penalty, tet_friction *fr,
                              double f_c[12], double f_t[12])
{
    const double *const *pc = contactor->p, *const *pt = target->p;
    double total = 0, k_n = 0; /* 4 p / h_t, once some face needs it */
    for (int m = 0; m < 4; m++) {
        face_touch ft;
        if (!face_in_target(pc, (const double (*)[4])ci->lambda, ci->outside, m, &ft)) {
            if (fr) memset(fr->springs + 3 * m, 0, 3 * sizeof(double));
            continue;
        }
        double f_n = penalty * ft.i0, force[3];
        for (int i = 0; i < 3; i++) force[i] = -f_n * ft.normal[i];
        if (fr && fr->mu > 0 && ft.area > 0) {
            if (k_n == 0) k_n = 4 * penalty / tet_smallest_height_now(pt, target->bary.det);
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
    corners_in ci;
    if (!t.bary.valid || corners_in_target(&c, &t, &ci)) return 0.0;
    return contact_one_way(&c, &t, &ci, penalty, NULL, f_c, f_t);
}

double tet_contact_pair(const double *pos, const int32_t a[4], const int32_t b[4],
                        double penalty, double f_a[12], double f_b[12])
{
    memset(f_a, 0, 12 * sizeof *f_a);
    memset(f_b, 0, 12 * sizeof *f_b);
    return tet_contact_one_way(pos, a, b, penalty, f_a, f_b) +
           tet_contact_one_way(pos, b, a, penalty, f_b, f_a);
}

/* A tetrahedron's frame, its map kept in memo (contact_pair.h) for the
 * next pairs it is in this walk: one slot per element, picked by a hash of
 * its node list's address, which stands for the element. */
static void tet_frame_memo(const double *pos, const int32_t n[4], contact_pair_memo *memo,
                           tet_frame *t)
{
    _Static_assert(sizeof(bary_map) <= sizeof memo->numbers[0], "memo too small for a bary_map");
    tet_corners_of(pos, n, t);
    if (!memo) {
        t->bary = bary_of(t->p);
        return;
    }
    unsigned slot = contact_memo_slot(n);
    if (memo->node[slot] == n) {
        memcpy(&t->bary, memo->numbers[slot], sizeof t->bary);
        return;
    }
    t->bary = bary_of(t->p);
    memo->node[slot] = n;
    memcpy(memo->numbers[slot], &t->bary, sizeof t->bary);
}

static double tet_longest_edge2(const double *const p[4])
{
    double most = 0;
    for (int i = 0; i < 4; i++)
        for (int k = i + 1; k < 4; k++) {
            double d[3];
            vec3_sub(p[k], p[i], d);
            most = max2(most, vec3_dot(d, d));
        }
    return most;
}

static double tet_six_volume(const double *const p[4])
{
    double e[3][3], c[3];
    for (int k = 0; k < 3; k++) vec3_sub(p[k + 1], p[0], e[k]);
    vec3_cross(e[1], e[2], c);
    return vec3_dot(e[0], c);
}

/* A gap `apart` between a and b as a clearance: less the margin, or 0 when
 * there is none or either element is too flat for the figure to be
 * trusted (six_a: a's 6 V, which a caller with a's map already has). */
static double trusted_clearance(const tet_frame *a, const tet_frame *b, double six_a,
                                double apart)
{
    if (!(apart > 0)) return 0;
    double la2 = tet_longest_edge2(a->p), lb2 = tet_longest_edge2(b->p);
    double la = sqrt(la2), lb = sqrt(lb2);
    if (!(six_a >= CONTACT_CLEARANCE_QUALITY * la2 * la) ||
        !(tet_six_volume(b->p) >= CONTACT_CLEARANCE_QUALITY * lb2 * lb))
        return 0;
    double size = 0;
    for (int v = 0; v < 4; v++)
        for (int i = 0; i < 3; i++) size = max2(size, max2(fabs(a->p[v][i]), fabs(b->p[v][i])));
    return contact_clearance_less_margin(apart, size, max2(la, lb));
}

/* The clearance of a pair found apart by a face plane of t (the corners
 * of `other` all outside it, their coordinates in t's map ci): how far
 * they are from that plane, less a margin for rounding, or 0 when either
 * element is too flat for the figure to be trusted. What the contact
 * stage does with it (contact_pair.h) is exact only if, while the two
 * elements stay further apart than the margin, this kernel cannot find
 * them touching, whatever path it takes:
 *  - the distance is -lambda_f / |grad lambda_f|, from the map's rows;
 *    rounding puts the corners' lambdas and the rows within some hundred
 *    ulps of their values, relative to the coordinates' size S (x - x0
 *    is formed from them) and amplified by the shape, L^3 / (6 V) at most
 *    (L the longest edge): with 6 V >= 1e-6 L^3 (QUALITY) that is under
 *    1e-10 (S + L) of distance, against a margin of 1e-8 S + 1e-7 L;
 *  - two elements apart by more than that margin can never give this
 *    kernel a clipped polygon of 3 vertices: every vertex it forms lies
 *    within such rounding of the face and of the target's planes it kept
 *    it by, so the integral is exactly 0 and every spring let go, as the
 *    early-outs do; the elements stay that shape (the stage skips only
 *    while no node has moved a hundredth of an element).
 * An inverted element has no potential (apart in any case). */
static double pair_clearance(const tet_frame *t, const tet_frame *other, const corners_in *ci)
{
    unsigned common = ci->outside[0] & ci->outside[1] & ci->outside[2] & ci->outside[3];
    const double(*r)[3] = t->bary.rows;
    /* most pairs found apart are far apart or all but touching (broken
     * rock: a hair apart across a crack); these last are let go before the
     * square roots, on one edge of t, never longer than L */
    double e01[3];
    vec3_sub(t->p[1], t->p[0], e01);
    double floor2 = 1e-14 * vec3_dot(e01, e01), best = 0;
    for (int f = 0; f < 4; f++) {
        if (!(common & 1u << f)) continue;
        double g[3];
        for (int i = 0; i < 3; i++) g[i] = f ? r[f - 1][i] : -(r[0][i] + r[1][i] + r[2][i]);
        double nearest = -INFINITY, g2 = vec3_dot(g, g);
        for (int v = 0; v < 4; v++) nearest = max2(nearest, ci->lambda[v][f]);
        if (nearest * nearest > floor2 * g2) best = max2(best, -nearest / sqrt(g2));
    }
    return trusted_clearance(t, other, t->bary.det, best);
}

/* The clearance of a pair that no face plane of either separates and the
 * kernel found untouched: the widest gap between the two along an axis
 * across an edge of each (the rest of the separating-axis test of two
 * convex solids), less the margin, or 0. Any axis's gap is at most their
 * distance, so pair_clearance's argument holds as it stands: apart by
 * more than the margin, the kernel cannot find them touching. Why: a
 * broken 3D block's pairs an element apart with overlapping boxes are
 * mostly separated only so (1.3 an element-step in bench_engine broken3d,
 * each clipped in full every step for nothing; now once a near list).
 * Axes of nearly parallel edges (|ea x eb|^2 < 1e-6 |ea|^2 |eb|^2) are
 * skipped: their direction is too rounded to trust. */
static double edge_pair_clearance(const tet_frame *a, const tet_frame *b)
{
    static const int edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    double ea[6][3], eb[6][3], la[6], lb[6], best = 0;
    for (int e = 0; e < 6; e++) {
        vec3_sub(a->p[edge[e][1]], a->p[edge[e][0]], ea[e]);
        vec3_sub(b->p[edge[e][1]], b->p[edge[e][0]], eb[e]);
        la[e] = vec3_dot(ea[e], ea[e]);
        lb[e] = vec3_dot(eb[e], eb[e]);
    }
    for (int i = 0; i < 6; i++)
        for (int k = 0; k < 6; k++) {
            double c[3];
            vec3_cross(ea[i], eb[k], c);
            double c2 = vec3_dot(c, c);
            if (!(c2 >= 1e-6 * la[i] * lb[k])) continue;
            double a_lo = INFINITY, a_hi = -INFINITY, b_lo = INFINITY, b_hi = -INFINITY;
            for (int v = 0; v < 4; v++) {
                double x = vec3_dot(a->p[v], c), y = vec3_dot(b->p[v], c);
                a_lo = min2(a_lo, x), a_hi = max2(a_hi, x);
                b_lo = min2(b_lo, y), b_hi = max2(b_hi, y);
            }
            double gap = max2(b_lo - a_hi, a_lo - b_hi);
            if (gap > 0 && gap * gap > best * best * c2) best = gap / sqrt(c2);
        }
    return trusted_clearance(a, b, tet_six_volume(a->p), best);
}

/* Inverted: no potential; a face plane of either apart: no touch, and
 * *clear its clearance. a's map first, most often kept from the last pair,
 * so that most pairs, apart by one of a's faces, never look at b's.
 * Otherwise both maps and the corners in them, for the clipping. */
static int tet_pair_apart(const contact_pair_in *in, tet_frame *a, tet_frame *b,
                          corners_in *a_in_b, corners_in *b_in_a, double *clear)
{
    *clear = 0;
    tet_frame_memo(in->pos, in->node_a, in->memo, a);
    if (!(a->bary.valid && a->bary.det > 0)) return 1;
    tet_corners_of(in->pos, in->node_b, b);
    if (corners_in_target(b, a, b_in_a)) {
        *clear = pair_clearance(a, b, b_in_a);
        return 1;
    }
    tet_frame_memo(in->pos, in->node_b, in->memo, b);
    if (!(b->bary.valid && b->bary.det > 0)) return 1;
    if (corners_in_target(a, b, a_in_b)) {
        *clear = pair_clearance(b, a, a_in_b);
        return 1;
    }
    return 0;
}

double tet_contact_pair_clearance(const contact_pair_in *in)
{
    tet_frame a, b;
    corners_in a_in_b, b_in_a;
    double clear;
    tet_pair_apart(in, &a, &b, &a_in_b, &b_in_a, &clear);
    return clear;
}

int tet_contact_pair_force(const contact_pair_in *in, double *springs, double *out)
{
    tet_frame a, b;
    corners_in a_in_b, b_in_a;
    double clear;
    int apart = tet_pair_apart(in, &a, &b, &a_in_b, &b_in_a, &clear);
    /* apart across an edge of each by more than the margin: what the
     * clipping below would find, untouched, and the clearance after it */
    if (!apart && in->edges_first) {
        clear = edge_pair_clearance(&a, &b);
        apart = clear > 0;
    }
    if (apart) {
        contact_zero(springs, TET_CONTACT_SLOTS);
        out[0] = clear;
        return 0;
    }
    contact_zero(out, TET_PAIR_OUT);
    double *dissipated = &out[TET_PAIR_OUT - 1];
    tet_friction ab = {in->vel, in->node_a, in->node_b, in->friction, in->h, springs, dissipated};
    tet_friction ba = {in->vel, in->node_b, in->node_a, in->friction, in->h,
                       springs + TET_CONTACT_SLOTS / 2, dissipated};
    double touched = contact_one_way(&a, &b, &a_in_b, in->penalty, &ab, out, out + 12);
    touched += contact_one_way(&b, &a, &b_in_a, in->penalty, &ba, out + 12, out);
    /* untouched, no face has added anything: out[0] is 0 until a clearance
     * (none across the edges if edges_first found none above) */
    if (!(touched > 0) && in->edge_clearance && !in->edges_first)
        out[0] = edge_pair_clearance(&a, &b);
    return touched > 0;
}
