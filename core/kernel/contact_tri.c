/*
 * contact_tri.c - the triangle pair kernel of the contact stage
 * (contact_pair.h): the distributed potential contact force of Munjiza &
 * Andrews (2000) between two triangles, with Coulomb friction.
 *
 * Force. Each triangle carries the potential phi = 3 min_k lambda_k (lambda
 * the area coordinates): 1 at the centroid, 0 on the boundary. The force on
 * a contactor c from a target t is -p * integral over the overlap of
 * grad phi_t, which the divergence theorem turns into an integral along the
 * contactor's edges inside t:  F = -p * integral (phi_t n_c) ds. phi_t is
 * piecewise linear along an edge (it changes branch where two area
 * coordinates cross), so the integral and its first moment are exact sums.
 * The resultant acts at the potential's centroid s* along the edge: it is
 * shared by the edge's two nodes by lever rule, and the equal and opposite
 * force goes to the target's nodes by the area coordinates of that same
 * point. Action equals reaction at one point, so both linear and angular
 * momentum are conserved to round-off. Then the roles swap.
 *
 * Friction is Coulomb with elastic stick (PHYSICS.md, "Friction"): each
 * contactor edge of a pair carries a tangential spring, loaded by the
 * relative tangential displacement at the point of action and capped at
 * mu Fn, beyond which the surfaces slide and the spring stays at the cap.
 * The spring's stiffness is 2/3 of the normal one, p L / (h/3) for the
 * length L of the edge inside the target of smallest altitude h, so it adds
 * nothing to the stable step; its force is kept per pair across steps
 * (contact_history.c). A block on a slope below its friction angle then
 * stays put for as long as one runs it, whatever the step; the energy that
 * sliding dissipates, cap x slip, is booked in the friction account.
 */
#include <math.h>

#include "contact_pair.h"
#include "math/norm2.h"

static inline double min3(double a, double b, double c) { return min2(a, min2(b, c)); }
static inline double max3(double a, double b, double c) { return max2(a, max2(b, c)); }

/* The current geometry of one triangle, gathered once per pair. */
typedef struct tri_now {
    int node[3];
    double x[3], y[3];
    double area2;       /* twice the signed area (> 0 unless inverted) */
    double inv_area2;   /* 1 / area2, divided once a pair, not once a corner */
} tri_now;

/* The triangle's corners now, and twice its signed area. */
static inline void tri_gather(const double *pos, const int32_t node[3], tri_now *t)
{
    for (int c = 0; c < 3; c++) {
        t->node[c] = node[c];
        t->x[c] = pos[2 * node[c]];
        t->y[c] = pos[2 * node[c] + 1];
    }
    t->area2 = (t->x[1] - t->x[0]) * (t->y[2] - t->y[0]) - (t->y[1] - t->y[0]) * (t->x[2] - t->x[0]);
    t->inv_area2 = t->area2 > 0 ? 1.0 / t->area2 : 0.0; /* inverted: never used */
}

/* Area coordinates of (px, py) in t: lambda_k belongs to node k. */
static inline void area_coordinates(const tri_now *t, double px, double py, double l[3])
{
    double inv = t->inv_area2;
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3;
        l[k] = ((t->x[i] - px) * (t->y[j] - py) - (t->y[i] - py) * (t->x[j] - px)) * inv;
    }
}

/* Integral over s in [0,1] of phi(s) = 3 min_k lambda_k(s), clipped to where
 * all lambda_k >= 0, its first moment, and the fraction of the edge inside.
 * Returns 0 when the edge misses. */
static int edge_potential_integral(const double la[3], const double lb[3], double *i0, double *i1,
                                   double *inside)
{
    double smin = 0, smax = 1;
    for (int k = 0; k < 3; k++) {
        if (la[k] < 0 && lb[k] < 0) return 0;
        if (la[k] < 0) smin = max2(smin, la[k] / (la[k] - lb[k]));
        else if (lb[k] < 0) smax = min2(smax, la[k] / (la[k] - lb[k]));
    }
    if (!(smax > smin)) return 0;

    double s[5];
    int n = 0;
    s[n++] = smin;
    for (int k = 0; k < 3; k++) { /* where two coordinates cross, phi changes branch */
        int j = (k + 1) % 3;
        double denom = (lb[k] - la[k]) - (lb[j] - la[j]);
        if (fabs(denom) < 1e-300) continue;
        double sc = (la[j] - la[k]) / denom;
        if (sc > smin && sc < smax) s[n++] = sc;
    }
    s[n++] = smax;
    for (int a = 1; a < n; a++) /* insertion sort of at most 5 */
        for (int b = a; b > 0 && s[b] < s[b - 1]; b--) {
            double tmp = s[b]; s[b] = s[b - 1]; s[b - 1] = tmp;
        }
    double sum0 = 0, sum1 = 0, prev_s = s[0];
    double prev_phi = 3 * max2(0, min3(la[0] + prev_s * (lb[0] - la[0]), la[1] + prev_s * (lb[1] - la[1]),
                                       la[2] + prev_s * (lb[2] - la[2])));
    for (int a = 1; a < n; a++) {
        double sa = s[a];
        double phi = 3 * max2(0, min3(la[0] + sa * (lb[0] - la[0]), la[1] + sa * (lb[1] - la[1]),
                                      la[2] + sa * (lb[2] - la[2])));
        double ds = sa - prev_s;
        sum0 += 0.5 * ds * (prev_phi + phi);
        sum1 += ds / 6.0 * (prev_phi * (2 * prev_s + sa) + phi * (prev_s + 2 * sa));
        prev_s = sa;
        prev_phi = phi;
    }
    *i0 = sum0;
    *i1 = sum1;
    *inside = smax - smin;
    return sum0 > 0;
}

/* The friction force on edge (na, nb) of a contactor, acting at sbar along
 * it and lbar in the target t: the edge's stick spring `spring` is loaded
 * by the relative tangential displacement of the last step (velocity times
 * h, the last step's size), capped at mu Fn; *dissipated gets cap x slip. */
static double friction_force(const double *v, const tri_now *t, int na, int nb, double sbar,
                             const double lbar[3], double tx, double ty, double k_t, double cap,
                             double h, double *spring, double *dissipated)
{
    double vcx = (1 - sbar) * v[2 * na] + sbar * v[2 * nb];
    double vcy = (1 - sbar) * v[2 * na + 1] + sbar * v[2 * nb + 1];
    double vtx = 0, vty = 0;
    for (int k = 0; k < 3; k++) {
        vtx += lbar[k] * v[2 * t->node[k]];
        vty += lbar[k] * v[2 * t->node[k] + 1];
    }
    double slide = ((vcx - vtx) * tx + (vcy - vty) * ty) * h;
    double f = *spring - k_t * slide;
    if (fabs(f) > cap) {
        *dissipated += cap * (fabs(f) - cap) / k_t;
        f = f > 0 ? cap : -cap;
    }
    *spring = f;
    return f;
}

/* Forces of target t's potential on contactor c's edges, added to fc (two
 * per corner of c), and their reactions on t, added to ft; springs holds the
 * stick springs of c's three edges against t (updated; an edge that does not
 * touch lets its spring go) and *dissipated gets what friction dissipated.
 * Returns 1 if any force acted. */
static void corners_in(const tri_now *c, const tri_now *t, double lam[3][3])
{
    for (int i = 0; i < 3; i++) area_coordinates(t, c->x[i], c->y[i], lam[i]);
}

static int contactor_against_target(const double *vel, const tri_now *c, const tri_now *t,
                                    const double lam[3][3], double penalty, double friction,
                                    double h, double springs[3], double fc[6], double ft[6],
                                    double *dissipated)
{
    double stiffness = 0; /* p / (h_t / 3), h_t the target's smallest altitude */
    int acted = 0;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        double i0, i1, inside;
        if (!edge_potential_integral(lam[i], lam[j], &i0, &i1, &inside)) {
            springs[i] = 0;
            continue;
        }
        acted = 1;
        double ex = c->x[j] - c->x[i], ey = c->y[j] - c->y[i];
        double len = norm2(ex, ey);
        double sbar = i1 / i0;
        /* normal: -p * i0 * (length-scaled outward normal) */
        double fx = -penalty * i0 * ey, fy = penalty * i0 * ex;
        double lbar[3];
        for (int k = 0; k < 3; k++) lbar[k] = lam[i][k] + sbar * (lam[j][k] - lam[i][k]);
        int na = c->node[i], nb = c->node[j];
        if (friction > 0 && len > 0) {
            if (stiffness == 0) {
                double dx0 = t->x[1] - t->x[0], dy0 = t->y[1] - t->y[0];
                double dx1 = t->x[2] - t->x[1], dy1 = t->y[2] - t->y[1];
                double dx2 = t->x[0] - t->x[2], dy2 = t->y[0] - t->y[2];
                double longest2 = max3(dx0 * dx0 + dy0 * dy0, dx1 * dx1 + dy1 * dy1,
                                       dx2 * dx2 + dy2 * dy2);
                stiffness = 3 * penalty * sqrt(longest2) / t->area2;
            }
            double tx = ex / len, ty = ey / len;
            double k_t = (2.0 / 3.0) * stiffness * inside * len;
            double f_t = friction_force(vel, t, na, nb, sbar, lbar, tx, ty, k_t,
                                        friction * penalty * i0 * len, h, &springs[i], dissipated);
            fx += f_t * tx;
            fy += f_t * ty;
        } else {
            springs[i] = 0;
        }
        fc[2 * i] += (1 - sbar) * fx;
        fc[2 * i + 1] += (1 - sbar) * fy;
        fc[2 * j] += sbar * fx;
        fc[2 * j + 1] += sbar * fy;
        for (int k = 0; k < 3; k++) {
            ft[2 * k] -= lbar[k] * fx;
            ft[2 * k + 1] -= lbar[k] * fy;
        }
    }
    return acted;
}

/* The clearance (contact_pair.h) of two triangles that did not touch:
 * how far the corners of `other` (their area coordinates lam in t) are
 * outside an edge line of t that has them all outside, less a margin for
 * rounding; 0 if there is none or either triangle is too flat to trust
 * the figure. As in 3D (contact_tet.c, pair_clearance): the distance is
 * -lambda_k times t's altitude over edge k; rounding puts it within some
 * hundred ulps relative to the coordinates' size S, amplified by the shape
 * (L^2 / 2A at most, L the longest edge): with 2A >= 1e-6 L^2 under
 * 1e-10 (S + L), against a margin of 1e-8 S + 1e-7 L; and two triangles
 * further apart than that give this kernel no edge with a positive
 * integral (each clipped interval is within such rounding of the target),
 * so it returns 0 with every spring let go, exactly. */
static double tri_longest_edge(const tri_now *t)
{
    double most = 0;
    for (int k = 0; k < 3; k++) {
        int j = (k + 1) % 3;
        double dx = t->x[j] - t->x[k], dy = t->y[j] - t->y[k];
        most = max2(most, dx * dx + dy * dy);
    }
    return sqrt(most);
}

static double tri_clearance(const tri_now *t, const tri_now *other, const double lam[3][3])
{
    double best = 0;
    for (int k = 0; k < 3; k++) {
        double nearest = max3(lam[0][k], lam[1][k], lam[2][k]);
        if (!(nearest < 0)) continue;
        int i = (k + 1) % 3, j = (k + 2) % 3;
        double dx = t->x[j] - t->x[i], dy = t->y[j] - t->y[i], edge2 = dx * dx + dy * dy;
        /* the distance, -nearest area2 / |edge|, under 1e-7 |edge| (never
         * over the margin): let go without a root - broken rock's pairs
         * apart are mostly a hair apart across a crack */
        if (!(-nearest * t->area2 > 1e-7 * edge2)) continue;
        best = max2(best, -nearest * t->area2 / sqrt(edge2));
    }
    if (!(best > 0)) return 0;
    double lt = tri_longest_edge(t), lo = tri_longest_edge(other);
    if (!(t->area2 >= CONTACT_CLEARANCE_QUALITY * lt * lt) ||
        !(other->area2 >= CONTACT_CLEARANCE_QUALITY * lo * lo))
        return 0;
    double size = 0;
    for (int v = 0; v < 3; v++)
        size = max2(size, max2(max2(fabs(t->x[v]), fabs(t->y[v])),
                               max2(fabs(other->x[v]), fabs(other->y[v]))));
    return contact_clearance_less_margin(best, size, max2(lt, lo));
}

/* Both triangles now and each one's corners in the other's area
 * coordinates; 0 if either is inverted (no potential defined). */
static int tri_pair_frames(const contact_pair_in *in, tri_now *a, tri_now *b,
                           double a_in_b[3][3], double b_in_a[3][3])
{
    tri_gather(in->pos, in->node_a, a);
    tri_gather(in->pos, in->node_b, b);
    if (!(a->area2 > 0) || !(b->area2 > 0)) return 0;
    corners_in(a, b, a_in_b);
    corners_in(b, a, b_in_a);
    return 1;
}

/* The pair's clearance by an edge line of either (tri_clearance), 0 if
 * none separates them. */
static double tri_pair_clearance(const tri_now *a, const tri_now *b, double a_in_b[3][3],
                                 double b_in_a[3][3])
{
    return max2(tri_clearance(a, b, (const double(*)[3])b_in_a),
                tri_clearance(b, a, (const double(*)[3])a_in_b));
}

double tri_contact_pair_clearance(const contact_pair_in *in)
{
    tri_now a, b;
    double a_in_b[3][3], b_in_a[3][3];
    return tri_pair_frames(in, &a, &b, a_in_b, b_in_a) ? tri_pair_clearance(&a, &b, a_in_b, b_in_a)
                                                        : 0;
}

int tri_contact_pair_force(const contact_pair_in *in, double *springs, double *out)
{
    tri_now a, b;
    double a_in_b[3][3], b_in_a[3][3];
    if (!tri_pair_frames(in, &a, &b, a_in_b, b_in_a)) {
        contact_zero(springs, TRI_CONTACT_SLOTS);
        out[0] = 0;
        return 0;
    }
    contact_zero(out, TRI_PAIR_OUT);
    double *dissipated = &out[TRI_PAIR_OUT - 1];
    int touched = contactor_against_target(in->vel, &a, &b, (const double(*)[3])a_in_b,
                                           in->penalty, in->friction, in->h, springs, out,
                                           out + 6, dissipated);
    touched |= contactor_against_target(in->vel, &b, &a, (const double(*)[3])b_in_a,
                                        in->penalty, in->friction, in->h, springs + 3, out + 6,
                                        out, dissipated);
    /* untouched, nothing was added: out[0] is 0 unless a clearance is found */
    if (!touched) out[0] = tri_pair_clearance(&a, &b, a_in_b, b_in_a);
    return touched;
}
