/*
 * element.c - constant-strain triangles at finite strain and finite
 * rotation: deformation gradient, Cauchy stress, nodal forces, strain
 * energy and the element's stable step.
 *
 * F = [x][X]^-1 with [X]^-1 stored per element. The stress law is the
 * compressible neo-Hookean solid sigma = (mu/J)(B - I) + (lambda/J) ln J I,
 * B = F F^T: objective (a rigid rotation R gives B = I, so no stress) and
 * equal to plane-strain linear elasticity at small strain. Viscous damping
 * adds 2 eta D with D = sym([v][x]^-1).
 *
 * Nodal forces come from edge tractions: the force on node a is
 * 1/2 sigma m_a, m_a the outward normal (scaled by length) of the edge
 * opposite a. This needs no division and sums to zero exactly.
 *
 * An element squashed to (or through) zero area would make ln J undefined;
 * below J_MIN the law continues along its tangent in J so the force stays
 * finite and keeps pushing the element open, instead of poisoning the run.
 */
#include <assert.h>
#include <math.h>
#include <string.h>

#include "model.h"

static_assert(sizeof(element_hot) == 64, "the hot element record is one cache line");

#define J_MIN 0.05

void element_prepare(fdem_model *m, int e)
{
    element_hot *el = &m->elem[e];
    const double *p = m->pos0;
    int a = el->node[0], b = el->node[1], c = el->node[2];
    double X1 = p[2 * b] - p[2 * a], Y1 = p[2 * b + 1] - p[2 * a + 1];
    double X2 = p[2 * c] - p[2 * a], Y2 = p[2 * c + 1] - p[2 * a + 1];
    double det = X1 * Y2 - X2 * Y1; /* > 0: validated and counter-clockwise */
    el->xinv[0] = Y2 / det;
    el->xinv[1] = -X2 / det;
    el->xinv[2] = -Y1 / det;
    el->xinv[3] = X1 / det;
    el->area0 = 0.5 * det;

    double l0 = hypot(X1, Y1), l1 = hypot(X2 - X1, Y2 - Y1), l2 = hypot(X2, Y2);
    double lmax = fmax(l0, fmax(l1, l2));
    m->elem_h[e] = det / lmax; /* smallest altitude */

    const material *mat = &m->materials[el->material];
    double modulus = mat->lambda + 2 * mat->mu;
    el->eta = mat->def.damping * m->elem_h[e] * sqrt(mat->def.density * modulus);
}

double element_stable_dt(const fdem_model *m, int e)
{
    const element_hot *el = &m->elem[e];
    const material *mat = &m->materials[el->material];
    double c = sqrt((mat->lambda + 2 * mat->mu) / mat->def.density);
    double xi = mat->def.damping;
    /* Damping of the stiffest mode shrinks the central-difference limit
     * from 2/omega to (2/omega)(sqrt(1 + xi^2) - xi). */
    return m->elem_h[e] / c * (sqrt(1 + xi * xi) - xi);
}

/* Stress of a deformation gradient (a b; c d), returns J; *w gets the
 * strain energy density per unit initial area. */
static inline double neo_hookean(double a, double b, double c, double d, double lambda,
                                 double mu, double s[3], double *w)
{
    double J = a * d - b * c;
    double lnJ, invJ;
    if (J >= J_MIN) {
        lnJ = log(J);
        invJ = 1.0 / J;
    } else {
        lnJ = log(J_MIN) + (J - J_MIN) / J_MIN;
        invJ = 1.0 / J_MIN;
    }
    double B11 = a * a + b * b, B22 = c * c + d * d, B12 = a * c + b * d;
    double muJ = mu * invJ, vol = lambda * lnJ * invJ;
    s[0] = muJ * (B11 - 1) + vol;
    s[1] = muJ * (B22 - 1) + vol;
    s[2] = muJ * B12;
    *w = 0.5 * mu * (B11 + B22 - 2 - 2 * lnJ) + 0.5 * lambda * lnJ * lnJ;
    return J;
}

/* Adds 2 eta D to s, returns the dissipated power per unit current area
 * (sigma_v : D). */
static inline double viscous_stress(const double *v, int n0, int n1, int n2, double x1, double y1,
                                    double x2, double y2, double eta, double s[3])
{
    double u1 = v[2 * n1] - v[2 * n0], w1 = v[2 * n1 + 1] - v[2 * n0 + 1];
    double u2 = v[2 * n2] - v[2 * n0], w2 = v[2 * n2 + 1] - v[2 * n0 + 1];
    double det = x1 * y2 - x2 * y1;
    if (!(fabs(det) > 0)) return 0;
    double inv = 1.0 / det;
    /* [x]^-1 = (1/det) (y2 -x2; -y1 x1); L = [v][x]^-1 */
    double L11 = (u1 * y2 - u2 * y1) * inv, L12 = (-u1 * x2 + u2 * x1) * inv;
    double L21 = (w1 * y2 - w2 * y1) * inv, L22 = (-w1 * x2 + w2 * x1) * inv;
    double D12 = 0.5 * (L12 + L21);
    s[0] += 2 * eta * L11;
    s[1] += 2 * eta * L22;
    s[2] += 2 * eta * D12;
    return 2 * eta * (L11 * L11 + L22 * L22 + 2 * D12 * D12);
}

void element_forces(fdem_model *m, double dt)
{
    const double *pos = m->pos, *vel = m->vel;
    double *f = m->force;
    const material *mats = m->materials;
    double energy = 0, dissipated = 0;
    for (int e = 0; e < m->elem_count; e++) {
        const element_hot *el = &m->elem[e];
        int n0 = el->node[0], n1 = el->node[1], n2 = el->node[2];
        double x0 = pos[2 * n0], y0 = pos[2 * n0 + 1];
        double x1 = pos[2 * n1] - x0, y1 = pos[2 * n1 + 1] - y0;
        double x2 = pos[2 * n2] - x0, y2 = pos[2 * n2 + 1] - y0;
        const double *Xi = el->xinv;
        double a = x1 * Xi[0] + x2 * Xi[2], b = x1 * Xi[1] + x2 * Xi[3];
        double c = y1 * Xi[0] + y2 * Xi[2], d = y1 * Xi[1] + y2 * Xi[3];
        const material *mat = &mats[el->material];
        double s[3], w;
        double J = neo_hookean(a, b, c, d, mat->lambda, mat->mu, s, &w);
        energy += w * el->area0;
        if (el->eta > 0)
            dissipated += viscous_stress(vel, n0, n1, n2, x1, y1, x2, y2, el->eta, s) *
                          fabs(J) * el->area0;
        /* edge normals (outward, length-scaled) opposite nodes 0, 1, 2 */
        double m0x = y2 - y1, m0y = -(x2 - x1);
        double m1x = -y2, m1y = x2;
        double m2x = y1, m2y = -x1;
        f[2 * n0] += 0.5 * (s[0] * m0x + s[2] * m0y);
        f[2 * n0 + 1] += 0.5 * (s[2] * m0x + s[1] * m0y);
        f[2 * n1] += 0.5 * (s[0] * m1x + s[2] * m1y);
        f[2 * n1 + 1] += 0.5 * (s[2] * m1x + s[1] * m1y);
        f[2 * n2] += 0.5 * (s[0] * m2x + s[2] * m2y);
        f[2 * n2 + 1] += 0.5 * (s[2] * m2x + s[1] * m2y);
    }
    m->elastic_energy = energy;
    m->damping_work += dissipated * dt;
}

void element_stress_one(const fdem_model *m, int e, double out[3])
{
    const element_hot *el = &m->elem[e];
    const double *pos = m->pos;
    int n0 = el->node[0], n1 = el->node[1], n2 = el->node[2];
    double x0 = pos[2 * n0], y0 = pos[2 * n0 + 1];
    double x1 = pos[2 * n1] - x0, y1 = pos[2 * n1 + 1] - y0;
    double x2 = pos[2 * n2] - x0, y2 = pos[2 * n2 + 1] - y0;
    const double *Xi = el->xinv;
    double a = x1 * Xi[0] + x2 * Xi[2], b = x1 * Xi[1] + x2 * Xi[3];
    double c = y1 * Xi[0] + y2 * Xi[2], d = y1 * Xi[1] + y2 * Xi[3];
    const material *mat = &m->materials[el->material];
    double w;
    neo_hookean(a, b, c, d, mat->lambda, mat->mu, out, &w);
    if (el->eta > 0) viscous_stress(m->vel, n0, n1, n2, x1, y1, x2, y2, el->eta, out);
}

int element_of_node(const fdem_model *m, int node)
{
    for (int e = 0; e < m->elem_count; e++)
        for (int c = 0; c < 3; c++)
            if (m->elem[e].node[c] == node) return e;
    return -1;
}
