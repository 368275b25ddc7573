/*
 * contact_face_tri.c - the triangle kernel of a shut broken joint
 * (contact_face.h: the physics, the tolerance is the contact stage's):
 * the joint's two edges pressed on each other by the depth of A's edge
 * into B's along their mean normal, per role at B's and then A's potential
 * stiffness 3 p / H, with the general kernel's friction springs.
 */
#include "contact_face.h"

#include <math.h>
#include <string.h>

/* A triangle now: corners and their velocities (copied once, so the
 * roles read no array the forces are written to), twice its area, its
 * edges' squared lengths (edge i from corner i to i + 1). Squares: a role
 * needs the length of one edge and of the longest, and glibc's hypot
 * (exact to the last bit at any scale, which an element's size never
 * needs) was a quarter of a broken 2D block's step. */
typedef struct tri_at {
    double x[3], y[3], vx[3], vy[3], area2, inv_area2, edge2[3];
} tri_at;

static int tri_at_of(const double *pos, const double *vel, const int32_t n[3], tri_at *t)
{
    for (int c = 0; c < 3; c++) {
        t->x[c] = pos[2 * n[c]], t->y[c] = pos[2 * n[c] + 1];
        t->vx[c] = vel[2 * n[c]], t->vy[c] = vel[2 * n[c] + 1];
    }
    t->area2 = (t->x[1] - t->x[0]) * (t->y[2] - t->y[0]) - (t->y[1] - t->y[0]) * (t->x[2] - t->x[0]);
    if (!(t->area2 > 0) || !isfinite(t->area2)) return 0;
    t->inv_area2 = 1.0 / t->area2; /* one division a triangle, not five a role */
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        double ex = t->x[j] - t->x[i], ey = t->y[j] - t->y[i];
        t->edge2[i] = ex * ex + ey * ey;
    }
    return 1;
}

/* The area coordinates of (px, py) in t, as three scalars: written into
 * an array here and read back as pairs by the vectorised role, each read
 * waited on two stores it could not be forwarded from (a fifth of the
 * role's time) */
static inline void area_coords(const tri_at *t, double px, double py, double *l0, double *l1,
                               double *l2)
{
    *l0 = ((t->x[1] - px) * (t->y[2] - py) - (t->y[1] - py) * (t->x[2] - px)) * t->inv_area2;
    *l1 = ((t->x[2] - px) * (t->y[0] - py) - (t->y[2] - py) * (t->x[0] - px)) * t->inv_area2;
    *l2 = ((t->x[0] - px) * (t->y[1] - py) - (t->y[0] - py) * (t->x[1] - px)) * t->inv_area2;
}

/* One role: the contactor's edge (local corners c0, c1 in the joint's
 * order) in the target's potential near its edge ft; n and tangent the
 * contactor's outward normal and edge direction, len the mean edge's. */
typedef struct edge_role {
    const tri_at *contactor, *target;
    int c[2];
    int ft;
    double n[2], tangent[2];
} edge_role;

/* i0_len: the overlap integral times the mean edge's length (the depth
 * integrated along the edge), so the normal force needs no division by
 * that length, which was on the pair's longest chain of dependent
 * divisions and roots */
static inline __attribute__((always_inline)) void role_force(const edge_role *r, double len, double i0_len, double w0, double w1,
                       double touch, const contact_pair_in *in, double *spring, double f_c[6],
                       double f_t[6], double *dissipated)
{
    const tri_at *c = r->contactor, *t = r->target;
    int c0 = r->c[0], c1 = r->c[1];
    double f_n = 3 * in->penalty * sqrt(t->edge2[r->ft]) * t->inv_area2 * i0_len; /* 3 p / H_t */
    double px = w0 * c->x[c0] + w1 * c->x[c1], py = w0 * c->y[c0] + w1 * c->y[c1];
    double l0, l1, l2;
    area_coords(t, px, py, &l0, &l1, &l2);
    double fx = -f_n * r->n[0], fy = -f_n * r->n[1];
    if (in->friction > 0) {
        double vx = w0 * c->vx[c0] + w1 * c->vx[c1], vy = w0 * c->vy[c0] + w1 * c->vy[c1];
        vx -= l0 * t->vx[0];
        vy -= l0 * t->vy[0];
        vx -= l1 * t->vx[1];
        vy -= l1 * t->vy[1];
        vx -= l2 * t->vx[2];
        vy -= l2 * t->vy[2];
        double longest = sqrt(max2(t->edge2[0], max2(t->edge2[1], t->edge2[2])));
        double k_t = (2.0 / 3.0) * (3 * in->penalty * longest * t->inv_area2) * touch * len;
        double cap = in->friction * f_n;
        double f = *spring - k_t * (vx * r->tangent[0] + vy * r->tangent[1]) * in->h;
        if (fabs(f) > cap) {
            *dissipated += cap * (fabs(f) - cap) / k_t;
            f = f > 0 ? cap : -cap;
        }
        *spring = f;
        fx += f * r->tangent[0];
        fy += f * r->tangent[1];
    } else {
        *spring = 0;
    }
    f_c[2 * c0] += w0 * fx;
    f_c[2 * c0 + 1] += w0 * fy;
    f_c[2 * c1] += w1 * fx;
    f_c[2 * c1 + 1] += w1 * fy;
    f_t[0] -= l0 * fx;
    f_t[1] -= l0 * fy;
    f_t[2] -= l1 * fx;
    f_t[3] -= l1 * fy;
    f_t[4] -= l2 * fx;
    f_t[5] -= l2 * fy;
}

int tri_face_pair_force(const contact_pair_in *in, const face_match *fm, double *springs,
                        double *out)
{
    tri_at a, b;
    int ca[2] = {fm->face_a, (fm->face_a + 1) % 3}, cb[2] = {fm->copy_in_b[0], fm->copy_in_b[1]};
    double d[3] = {0, 0, 0}, i0_len = 0, w[3], touch = 0, ex = 0, ey = 0;
    int touched = tri_at_of(in->pos, in->vel, in->node_a, &a) &&
                  tri_at_of(in->pos, in->vel, in->node_b, &b);
    if (touched) {
        double mx[2], my[2];
        for (int k = 0; k < 2; k++) {
            mx[k] = 0.5 * (a.x[ca[k]] + b.x[cb[k]]);
            my[k] = 0.5 * (a.y[ca[k]] + b.y[cb[k]]);
        }
        ex = mx[1] - mx[0], ey = my[1] - my[0];
        /* the depths along the unnormalised normal (ey, -ex), out of a
         * counter-clockwise triangle: len times the depth, whose integral
         * and centroid face_segment_overlap takes as they come (its
         * weights are ratios of depths); a zero edge gives no depth */
        for (int k = 0; k < 2; k++)
            d[k] = (a.x[ca[k]] - b.x[cb[k]]) * ey - (a.y[ca[k]] - b.y[cb[k]]) * ex;
        touched = face_segment_overlap(d, &i0_len, w, &touch);
    }
    if (!touched) {
        for (int k = 0; k < TRI_CONTACT_SLOTS; k++) springs[k] = 0;
        out[0] = 0;
        return 0;
    }
    double len = sqrt(ex * ex + ey * ey), inv_len = 1.0 / len;
    double tan[2] = {ex * inv_len, ey * inv_len}, n[2] = {tan[1], -tan[0]};
    double keep_a = springs[fm->face_a], keep_b = springs[3 + fm->face_b];
    memset(springs, 0, sizeof(double) * TRI_CONTACT_SLOTS);
    /* element by element: as a loop or a memset, GCC emits `rep stos`,
     * whose start-up was 6 % of this function */
    _Static_assert(TRI_PAIR_OUT == 13, "forces on 2 x 3 nodes, then the dissipation");
    out[0] = out[1] = out[2] = out[3] = out[4] = out[5] = out[6] = 0;
    out[7] = out[8] = out[9] = out[10] = out[11] = out[12] = 0;
    double *dissipated = &out[TRI_PAIR_OUT - 1];
    /* b's edge runs the other way round (both counter-clockwise) */
    edge_role ra = {&a, &b, {ca[0], ca[1]}, fm->face_b, {n[0], n[1]}, {tan[0], tan[1]}};
    edge_role rb = {&b, &a, {cb[0], cb[1]}, fm->face_a, {-n[0], -n[1]}, {-tan[0], -tan[1]}};
    role_force(&ra, len, i0_len, w[0], w[1], touch, in, &keep_a, out, out + 6, dissipated);
    role_force(&rb, len, i0_len, w[0], w[1], touch, in, &keep_b, out + 6, out, dissipated);
    springs[fm->face_a] = keep_a;
    springs[3 + fm->face_b] = keep_b;
    return 1;
}
