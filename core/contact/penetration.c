/*
 * penetration.c - elements passing into one another (contract 6.2
 * "Warnings"): a body fast or stiff beyond what the penalty can stop goes
 * into or through another, and the run would otherwise end "finished" with
 * no word. The contact stage asks here about each pair that touched this
 * step (contact_pair_scatter, in pair order on one thread), never about
 * the pairs apart, so a model without contact, or whose contacts stay
 * shallow, runs no more than that one test per touching pair.
 *
 * The depth is the distance from the deepest node of either element to the
 * nearest face of the other it is inside (barycentric coordinates lambda_k
 * over their gradient's length), as a fraction of that element's inradius
 * (1 / the sum of the gradients' lengths): 0 at its faces, 1 at its
 * incentre, whatever its shape (a smallest height would never be reached
 * by a node inside a regular tetrahedron, whose inradius is a quarter of
 * it). Beyond FDEM_PENETRATION_WARN each pair is kept once (the first
 * FDEM_PENETRATIONS_MAX of them; later ones only counted) for the owner to
 * take with fdem_take_penetrations(). Nothing here changes the state: it
 * is an observation, not carried by checkpoints (the daemon keeps the
 * warnings it took in the case's status).
 */
#include <math.h>
#include <string.h>

#include "model/model.h"
#include "contact.h"

/* The barycentric gradients g[k] (rows of the inverse edge matrix, g[0]
 * minus their sum) of element e, and its first node; 0 when degenerate. */
static int element_gradients(const fdem_model *m, int e, double g[4][3], const double **p0)
{
    const int D = m->dim;
    const int32_t *n = element_nodes(m, e);
    const double *p = m->pos;
    double ed[3][3] = {{0}};
    for (int k = 0; k < D; k++)
        for (int d = 0; d < D; d++) ed[k][d] = p[D * n[k + 1] + d] - p[D * n[0] + d];
    memset(g, 0, sizeof(double) * 12);
    if (D == 2) {
        double det = ed[0][0] * ed[1][1] - ed[1][0] * ed[0][1];
        if (!(fabs(det) > 0)) return 0;
        g[1][0] = ed[1][1] / det, g[1][1] = -ed[1][0] / det;
        g[2][0] = -ed[0][1] / det, g[2][1] = ed[0][0] / det;
    } else {
        for (int k = 0; k < 3; k++) { /* g[k+1] = (e_{k+1} x e_{k+2}) / det */
            const double *u = ed[(k + 1) % 3], *v = ed[(k + 2) % 3];
            g[k + 1][0] = u[1] * v[2] - u[2] * v[1];
            g[k + 1][1] = u[2] * v[0] - u[0] * v[2];
            g[k + 1][2] = u[0] * v[1] - u[1] * v[0];
        }
        double det = ed[0][0] * g[1][0] + ed[0][1] * g[1][1] + ed[0][2] * g[1][2];
        if (!(fabs(det) > 0)) return 0;
        for (int k = 1; k <= 3; k++)
            for (int d = 0; d < 3; d++) g[k][d] /= det;
    }
    for (int k = 1; k <= D; k++)
        for (int d = 0; d < D; d++) g[0][d] -= g[k][d];
    *p0 = p + D * n[0];
    return 1;
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* How deep the deepest node of element a is inside element b, as a
 * fraction of b's inradius (1 / the sum of its gradients' lengths, the
 * deepest any point of b can be): 0 for none inside, 1 at b's incentre. */
static double nodes_depth(const fdem_model *m, int a, const double g[4][3], const double *p0)
{
    const int D = m->dim;
    const int32_t *n = element_nodes(m, a);
    double length[4], inradius = 0;
    for (int k = 0; k <= D; k++) inradius += length[k] = norm3(g[k]);
    inradius = 1 / inradius;
    double deepest = 0;
    for (int c = 0; c <= D; c++) {
        const double *x = m->pos + D * n[c];
        double lambda[4], sum = 0, depth = INFINITY;
        for (int k = 1; k <= D; k++) {
            lambda[k] = 0;
            for (int d = 0; d < D; d++) lambda[k] += g[k][d] * (x[d] - p0[d]);
            sum += lambda[k];
        }
        lambda[0] = 1 - sum;
        for (int k = 0; k <= D; k++) depth = fmin(depth, lambda[k] / length[k]);
        deepest = fmax(deepest, depth);
    }
    return deepest / inradius;
}

double contact_penetration(const fdem_model *m, int a, int b)
{
    double ga[4][3], gb[4][3];
    const double *pa, *pb;
    if (!element_gradients(m, a, ga, &pa) || !element_gradients(m, b, gb, &pb)) return 0;
    return fmax(nodes_depth(m, a, gb, pb), nodes_depth(m, b, ga, pa));
}

void contact_penetration_check(fdem_model *m, int a, int b)
{
    contact_penetration_record(m, a, b, contact_penetration(m, a, b));
}

void contact_penetration_record(fdem_model *m, int a, int b, double fraction)
{
    contact_state *cs = &m->contact;
    if (!(fraction > FDEM_PENETRATION_WARN)) return;
    int lo = a < b ? a : b, hi = a < b ? b : a;
    for (int i = 0; i < cs->pen_count; i++)
        if (cs->pen[i].a == lo && cs->pen[i].b == hi) return;
    if (cs->pen_count == FDEM_PENETRATIONS_MAX) {
        cs->pen_more++;
        return;
    }
    cs->pen[cs->pen_count++] = (fdem_penetration){m->step, m->time, lo, hi, fraction};
}

int fdem_take_penetrations(fdem_model *m, fdem_penetration *out, int max, long *more)
{
    contact_state *cs = &m->contact;
    int n = 0;
    while (cs->pen_taken < cs->pen_count && n < max) out[n++] = cs->pen[cs->pen_taken++];
    if (more) {
        *more = cs->pen_more;
        cs->pen_more = 0;
    }
    return n;
}
