/*
 * contact_face_tet.c - the tetrahedron kernel of a shut broken joint
 * (contact_face.h: the physics, the tolerance is the contact stage's):
 * the joint's two triangular faces pressed on each other by the depth of
 * A's face into B's along their mean normal, per role at B's and then A's
 * potential stiffness 4 p / H, with the general kernel's friction springs.
 * A few hundred operations where clipping both tetrahedra's eight faces
 * against the other's sub-tetrahedra took thousands.
 */
#include "contact_face.h"
#include "contact_spring.h"
#include "element_tet.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "math/vec3.h"

/* A tetrahedron now: its corners' places and velocities (copied once: the
 * roles then read no array the forces are written to, so the compiler
 * keeps them in registers), its barycentric map (lambda_{1..3} = cof .
 * (x - p0) / det: one division, where a map of rows took nine and a role
 * uses it at one point), the inverse of 6 V, and the squared cross
 * products of its faces ((2 A)^2: a role takes the root of one face's and
 * of the largest). The map and the faces are TET_NOW_MAP numbers in a row,
 * as the walk's memo keeps them. */
typedef struct tet_now {
    double p[4][3], v[4][3];
    double cof[3][3], inv_det;
    double face_len2[4];
} tet_now;
#define TET_NOW_MAP 14

/* The map and face sizes from the corners: 0 when the tetrahedron is
 * inverted or flat (no potential). */
static int tet_now_map(tet_now *t)
{
    double e[3][3], (*c)[3] = t->cof;
    for (int k = 0; k < 3; k++) vec3_sub(t->p[k + 1], t->p[0], e[k]);
    vec3_cross(e[1], e[2], c[0]);
    vec3_cross(e[2], e[0], c[1]);
    vec3_cross(e[0], e[1], c[2]);
    double det = vec3_dot(e[0], c[0]);
    if (!(det > 0) || !isfinite(det)) return 0;
    t->inv_det = 1.0 / det;
    /* tet_face_nodes' faces: 0 (1,2,3) has cross (e1-e0) x (e2-e0) =
     * c0 + c1 + c2, faces 1, 2, 3 have -c0, -c1, -c2 */
    double s[3];
    for (int i = 0; i < 3; i++) s[i] = c[0][i] + c[1][i] + c[2][i];
    t->face_len2[0] = vec3_dot(s, s);
    for (int k = 0; k < 3; k++) t->face_len2[k + 1] = vec3_dot(c[k], c[k]);
    return 1;
}

/* Tetrahedron n now. An element is in about four shut faces, two of them
 * met as the pair's first element, so its map is kept in the walk's memo
 * (contact_pair.h; one slot per element, by a hash of its node list's
 * address) for the pairs after: the map and face sizes were a sixth of a
 * broken 3D block's step, worked out twice a face pair. What the memo gives
 * is what tet_now_map would work out again, bit for bit. */
static int tet_now_of(const double *pos, const double *vel, const int32_t n[4],
                      contact_pair_memo *memo, tet_now *t)
{
    _Static_assert(offsetof(tet_now, face_len2) - offsetof(tet_now, cof) ==
                       (TET_NOW_MAP - 4) * sizeof(double),
                   "the map and face sizes are TET_NOW_MAP numbers in a row");
    _Static_assert(TET_NOW_MAP <= sizeof memo->face_numbers[0] / sizeof(double),
                   "memo too small for a map");
    for (int c = 0; c < 4; c++)
        for (int i = 0; i < 3; i++) {
            t->p[c][i] = pos[3 * (size_t)n[c] + i];
            t->v[c][i] = vel[3 * (size_t)n[c] + i];
        }
    if (!memo) return tet_now_map(t);
    unsigned slot = contact_memo_slot(n);
    double *map = &t->cof[0][0];
    if (memo->face_node[slot] == n) {
        memcpy(map, memo->face_numbers[slot], TET_NOW_MAP * sizeof(double));
        return 1;
    }
    if (!tet_now_map(t)) return 0;
    memo->face_node[slot] = n;
    memcpy(memo->face_numbers[slot], map, TET_NOW_MAP * sizeof(double));
    return 1;
}

static void bary_in(const tet_now *t, const double x[3], double l[4])
{
    double d[3];
    vec3_sub(x, t->p[0], d);
    for (int k = 0; k < 3; k++) l[k + 1] = vec3_dot(t->cof[k], d) * t->inv_det;
    l[0] = 1.0 - l[1] - l[2] - l[3];
}

/* One role: the contactor's face (its local corners cf, in the joint's
 * order) in the target's potential near the target's face ft. n is the
 * contactor's outward unit normal, area the mean face's, i0 and w the
 * overlap integral (as a fraction of the area) and its centroid's weights,
 * touch the fraction that overlaps. */
typedef struct face_role {
    const tet_now *contactor, *target;
    const int *cf;
    int ft;
    double n[3];
} face_role;

static inline __attribute__((always_inline)) void
role_force(const face_role *r, double area, double i0, const double w[3], double touch,
           const contact_pair_in *in, double spring[3], double f_c[12], double f_t[12],
           double *dissipated)
{
    const tet_now *c = r->contactor, *t = r->target;
    double k_face = 4 * in->penalty * sqrt(t->face_len2[r->ft]) * t->inv_det; /* 4 p / H_t */
    double f_n = k_face * i0 * area, x[3] = {0, 0, 0}, lt[4], force[3];
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) x[i] += w[k] * c->p[r->cf[k]][i];
    bary_in(t, x, lt);
    for (int i = 0; i < 3; i++) force[i] = -f_n * r->n[i];
    if (in->friction > 0) {
        double rel[3] = {0, 0, 0};
        for (int i = 0; i < 3; i++) {
            for (int k = 0; k < 3; k++) rel[i] += w[k] * c->v[r->cf[k]][i];
            for (int v = 0; v < 4; v++) rel[i] -= lt[v] * t->v[v][i];
        }
        double largest2 = 0;
        for (int f = 0; f < 4; f++) largest2 = largest2 > t->face_len2[f] ? largest2 : t->face_len2[f];
        double largest = sqrt(largest2);
        double k_t = (2.0 / 3.0) * (4 * in->penalty * largest * t->inv_det) * touch * area;
        contact_spring_load(spring, r->n, rel, k_t, in->h, in->friction * f_n, dissipated, force);
    } else {
        memset(spring, 0, 3 * sizeof(double));
    }
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) f_c[3 * r->cf[k] + i] += w[k] * force[i];
    for (int v = 0; v < 4; v++)
        for (int i = 0; i < 3; i++) f_t[3 * v + i] -= lt[v] * force[i];
}

int tet_face_pair_force(const contact_pair_in *in, const face_match *fm, double *springs,
                        double *out)
{
    tet_now a, b;
    int fa[3], fb[3];
    for (int k = 0; k < 3; k++) {
        fa[k] = tet_face_nodes[fm->face_a][k];
        fb[k] = fm->copy_in_b[k];
    }
    double d[3], i0 = 0, w[3], touch = 0, n[3] = {0, 0, 0}, area = 0;
    int touched = tet_now_of(in->pos, in->vel, in->node_a, in->memo, &a) &&
                  tet_now_of(in->pos, in->vel, in->node_b, in->memo, &b);
    if (touched) {
        double m[3][3], e1[3], e2[3];
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 3; i++) m[k][i] = 0.5 * (a.p[fa[k]][i] + b.p[fb[k]][i]);
        vec3_sub(m[1], m[0], e1);
        vec3_sub(m[2], m[0], e2);
        vec3_cross(e1, e2, n); /* out of a: tet_face_nodes' order */
        double len = sqrt(vec3_dot(n, n));
        touched = len > 0;
        if (touched) {
            area = 0.5 * len;
            for (int i = 0; i < 3; i++) n[i] /= len;
            for (int k = 0; k < 3; k++) {
                double gap[3];
                vec3_sub(a.p[fa[k]], b.p[fb[k]], gap);
                d[k] = vec3_dot(gap, n);
            }
            touched = face_triangle_overlap(d, &i0, w, &touch);
        }
    }
    if (!touched) {
        contact_zero(springs, TET_CONTACT_SLOTS);
        out[0] = 0;
        return 0;
    }
    /* every slot but the two faces' is let go: nothing else touches */
    double keep_a[3], keep_b[3];
    memcpy(keep_a, springs + 3 * fm->face_a, sizeof keep_a);
    memcpy(keep_b, springs + TET_CONTACT_SLOTS / 2 + 3 * fm->face_b, sizeof keep_b);
    contact_zero(springs, TET_CONTACT_SLOTS);
    contact_zero(out, TET_PAIR_OUT);
    double *dissipated = &out[TET_PAIR_OUT - 1];
    face_role ra = {&a, &b, fa, fm->face_b, {n[0], n[1], n[2]}};
    face_role rb = {&b, &a, fb, fm->face_a, {-n[0], -n[1], -n[2]}};
    role_force(&ra, area, i0, w, touch, in, keep_a, out, out + 12, dissipated);
    role_force(&rb, area, i0, w, touch, in, keep_b, out + 12, out, dissipated);
    memcpy(springs + 3 * fm->face_a, keep_a, sizeof keep_a);
    memcpy(springs + TET_CONTACT_SLOTS / 2 + 3 * fm->face_b, keep_b, sizeof keep_b);
    return 1;
}
