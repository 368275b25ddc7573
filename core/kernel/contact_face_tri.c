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

/* A target triangle now: corners, twice its area, its edges' squared
 * lengths (edge i from corner i to i + 1). Squares: a role needs the
 * length of one edge and of the longest, and glibc's hypot (exact to the
 * last bit at any scale, which an element's size never needs) was a
 * quarter of a broken 2D block's step. */
typedef struct tri_at {
    double x[3], y[3], area2, inv_area2, edge2[3];
} tri_at;

static int tri_at_of(const double *pos, const int32_t n[3], tri_at *t)
{
    for (int c = 0; c < 3; c++) t->x[c] = pos[2 * n[c]], t->y[c] = pos[2 * n[c] + 1];
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

static void area_coords(const tri_at *t, double px, double py, double l[3])
{
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3;
        l[k] = ((t->x[i] - px) * (t->y[j] - py) - (t->y[i] - py) * (t->x[j] - px)) * t->inv_area2;
    }
}

/* One role: the contactor's edge (local corners c0, c1 in the joint's
 * order) in the target's potential near its edge ft; n and tangent the
 * contactor's outward normal and edge direction, len the mean edge's. */
typedef struct edge_role {
    const double *pos, *vel;
    const int32_t *cn, *tn;
    int c[2];
    const tri_at *target;
    int ft;
    double n[2], tangent[2];
} edge_role;

static void role_force(const edge_role *r, double len, double i0, const double w[3], double touch,
                       const contact_pair_in *in, double *spring, double f_c[6], double f_t[6],
                       double *dissipated)
{
    const tri_at *t = r->target;
    double f_n = 3 * in->penalty * sqrt(t->edge2[r->ft]) * t->inv_area2 * i0 * len; /* 3 p / H_t */
    double px = 0, py = 0, lt[3];
    for (int k = 0; k < 2; k++) {
        px += w[k] * r->pos[2 * r->cn[r->c[k]]];
        py += w[k] * r->pos[2 * r->cn[r->c[k]] + 1];
    }
    area_coords(t, px, py, lt);
    double fx = -f_n * r->n[0], fy = -f_n * r->n[1];
    if (in->friction > 0) {
        double vx = 0, vy = 0;
        for (int k = 0; k < 2; k++) {
            vx += w[k] * r->vel[2 * r->cn[r->c[k]]];
            vy += w[k] * r->vel[2 * r->cn[r->c[k]] + 1];
        }
        for (int v = 0; v < 3; v++) {
            vx -= lt[v] * r->vel[2 * r->tn[v]];
            vy -= lt[v] * r->vel[2 * r->tn[v] + 1];
        }
        double longest = sqrt(fmax(t->edge2[0], fmax(t->edge2[1], t->edge2[2])));
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
    for (int k = 0; k < 2; k++) {
        f_c[2 * r->c[k]] += w[k] * fx;
        f_c[2 * r->c[k] + 1] += w[k] * fy;
    }
    for (int v = 0; v < 3; v++) {
        f_t[2 * v] -= lt[v] * fx;
        f_t[2 * v + 1] -= lt[v] * fy;
    }
}

int tri_face_pair_force(const contact_pair_in *in, const face_match *fm, double *springs,
                        double *out)
{
    tri_at a, b;
    int ca[2] = {fm->face_a, (fm->face_a + 1) % 3}, cb[2] = {fm->copy_in_b[0], fm->copy_in_b[1]};
    double d[3] = {0, 0, 0}, i0 = 0, w[3], touch = 0, len = 0, n[2] = {0, 0}, tan[2] = {0, 0};
    int touched = tri_at_of(in->pos, in->node_a, &a) && tri_at_of(in->pos, in->node_b, &b);
    if (touched) {
        double mx[2], my[2];
        for (int k = 0; k < 2; k++) {
            mx[k] = 0.5 * (a.x[ca[k]] + b.x[cb[k]]);
            my[k] = 0.5 * (a.y[ca[k]] + b.y[cb[k]]);
        }
        double ex = mx[1] - mx[0], ey = my[1] - my[0];
        len = sqrt(ex * ex + ey * ey);
        touched = len > 0;
        if (touched) {
            tan[0] = ex / len, tan[1] = ey / len;
            n[0] = tan[1], n[1] = -tan[0]; /* out of a counter-clockwise triangle */
            for (int k = 0; k < 2; k++)
                d[k] = (a.x[ca[k]] - b.x[cb[k]]) * n[0] + (a.y[ca[k]] - b.y[cb[k]]) * n[1];
            touched = face_overlap_integral(2, d, &i0, w, &touch);
        }
    }
    if (!touched) {
        for (int k = 0; k < TRI_CONTACT_SLOTS; k++) springs[k] = 0;
        out[0] = 0;
        return 0;
    }
    double keep_a = springs[fm->face_a], keep_b = springs[3 + fm->face_b];
    for (int k = 0; k < TRI_CONTACT_SLOTS; k++) springs[k] = 0;
    for (int k = 0; k < TRI_PAIR_OUT; k++) out[k] = 0;
    double *dissipated = &out[TRI_PAIR_OUT - 1];
    /* b's edge runs the other way round (both counter-clockwise) */
    edge_role ra = {in->pos, in->vel, in->node_a, in->node_b, {ca[0], ca[1]}, &b, fm->face_b,
                    {n[0], n[1]}, {tan[0], tan[1]}};
    edge_role rb = {in->pos, in->vel, in->node_b, in->node_a, {cb[0], cb[1]}, &a, fm->face_a,
                    {-n[0], -n[1]}, {-tan[0], -tan[1]}};
    role_force(&ra, len, i0, w, touch, in, &keep_a, out, out + 6, dissipated);
    role_force(&rb, len, i0, w, touch, in, &keep_b, out + 6, out, dissipated);
    springs[fm->face_a] = keep_a;
    springs[3 + fm->face_b] = keep_b;
    return 1;
}
