/*
 * element_tet_model.c - the 3D element kernel on the model: tetrahedra from
 * the model's hot records, the counterpart of element_tri.c. The algebra
 * (deformation gradient, neo-Hookean stress, stable step) is element_tet.c's;
 * this file owns the per-element loop the scatter plan runs, with the
 * damping stress kept per element for the damping account (element.c).
 *
 * Forces come from the face vectors c_k (twice the area vectors through
 * node 0), f_a = -sigma c_{a-1} / 6, node 0 taking minus the sum of the
 * other three so each element's forces sum to exactly zero.
 */
#include <math.h>
#include <string.h>

#include "element_tet.h"
#include "model.h"
#include "vec3.h"

int tet_element_prepare(fdem_model *m, int e, fdem_error *err)
{
    tet_hot *t = &m->tet[e];
    tet_geometry g;
    if (tet_prepare(m->pos0, t->node, &g)) {
        model_error(err, FDEM_ITEM_ELEMENT, e, "element %d has no positive volume", e);
        return -1;
    }
    memcpy(t->xinv, g.xinv, sizeof t->xinv);
    t->volume0 = g.volume0;
    m->elem_h[e] = g.height;
    const material *mat = &m->materials[t->material];
    t->eta = tet_viscosity(g.height, mat->lambda, mat->mu, mat->def.density, mat->def.damping);
    return 0;
}

double tet_element_stable_dt(const fdem_model *m, int e)
{
    const tet_hot *t = &m->tet[e];
    const material *mat = &m->materials[t->material];
    return tet_stable_dt_eigen(m->pos0, t->node, mat->lambda, mat->mu, mat->def.density, t->eta);
}

/* Current edges from node 0, their face vectors and det = 6V. */
static inline double tet_current(const double *pos, const int32_t node[4], double e[3][3],
                                 double c[3][3])
{
    const double *p0 = pos + 3 * (size_t)node[0];
    for (int k = 0; k < 3; k++) vec3_sub(pos + 3 * (size_t)node[k + 1], p0, e[k]);
    vec3_cross(e[1], e[2], c[0]);
    vec3_cross(e[2], e[0], c[1]);
    vec3_cross(e[0], e[1], c[2]);
    return vec3_dot(e[0], c[0]);
}

/* F = [x][X]^-1: F_ij = sum_k (e_k)_i xinv_kj */
static inline void tet_gradient(const double e[3][3], const double xinv[9], double F[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            F[3 * i + j] = e[0][i] * xinv[j] + e[1][i] * xinv[3 + j] + e[2][i] * xinv[6 + j];
}

/* The viscous stress 2 eta D (D = sym([v][x]^-1)) into sv, and the power
 * -V (s : D) of sv and of prev (the last step's viscous stress, may be
 * NULL) with these velocities. Order xx, yy, zz, yz, xz, xy. */
static inline void tet_viscous(const double *vel, const int32_t node[4], const double c[3][3],
                               double det, double eta, const double *prev, double sv[6],
                               double *power, double *power_prev)
{
    memset(sv, 0, 6 * sizeof(double));
    *power = *power_prev = 0;
    if (!(fabs(det) > 0)) return;
    const double *v0 = vel + 3 * (size_t)node[0];
    double L[3][3] = {{0}};
    for (int k = 0; k < 3; k++) {
        double dv[3];
        vec3_sub(vel + 3 * (size_t)node[k + 1], v0, dv);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) L[i][j] += dv[i] * c[k][j];
    }
    double inv = 1.0 / det;
    double D[6] = {L[0][0] * inv, L[1][1] * inv, L[2][2] * inv, 0.5 * (L[1][2] + L[2][1]) * inv,
                   0.5 * (L[0][2] + L[2][0]) * inv, 0.5 * (L[0][1] + L[1][0]) * inv};
    for (int k = 0; k < 6; k++) sv[k] = 2 * eta * D[k];
    double volume = det / 6.0;
    *power = -volume * (sv[0] * D[0] + sv[1] * D[1] + sv[2] * D[2] +
                        2 * (sv[3] * D[3] + sv[4] * D[4] + sv[5] * D[5]));
    if (prev)
        *power_prev = -volume * (prev[0] * D[0] + prev[1] * D[1] + prev[2] * D[2] +
                                 2 * (prev[3] * D[3] + prev[4] * D[4] + prev[5] * D[5]));
}

void tet_element_forces_range(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    const double *pos = m->pos, *vel = m->vel;
    double *f = m->force, *visc = m->elem_viscous;
    const material *mats = m->materials;
    double energy = 0, power_now = 0, power_prev = 0;
    for (int e = begin; e < end; e++) {
        const tet_hot *t = &m->tet[e];
        double ed[3][3], c[3][3], F[9], s[6], J;
        double det = tet_current(pos, t->node, ed, c);
        tet_gradient(ed, t->xinv, F);
        const material *mat = &mats[t->material];
        energy += tet_stress(F, mat->lambda, mat->mu, s, &J) * t->volume0;
        if (t->eta > 0) {
            double sv[6], now, before, *prev = visc + 6 * (size_t)e;
            tet_viscous(vel, t->node, c, det, t->eta, prev, sv, &now, &before);
            power_now += now;
            power_prev += before;
            for (int k = 0; k < 6; k++) {
                prev[k] = sv[k];
                s[k] += sv[k];
            }
        }
        /* f_a = -sigma c_{a-1} / 6 */
        const double S[3][3] = {{s[0], s[5], s[4]}, {s[5], s[1], s[3]}, {s[4], s[3], s[2]}};
        double sum[3] = {0, 0, 0};
        for (int a = 1; a <= 3; a++) {
            double *fa = f + 3 * (size_t)t->node[a];
            for (int i = 0; i < 3; i++) {
                double fi = -(S[i][0] * c[a - 1][0] + S[i][1] * c[a - 1][1] +
                              S[i][2] * c[a - 1][2]) * (1.0 / 6.0);
                fa[i] += fi;
                sum[i] += fi;
            }
        }
        double *f0 = f + 3 * (size_t)t->node[0];
        for (int i = 0; i < 3; i++) f0[i] -= sum[i];
    }
    sums[0] += energy;
    sums[1] += power_now;
    sums[2] += power_prev;
}

void tet_element_stress(const fdem_model *m, int e, double out[6])
{
    const tet_hot *t = &m->tet[e];
    double ed[3][3], c[3][3], F[9], J;
    double det = tet_current(m->pos, t->node, ed, c);
    tet_gradient(ed, t->xinv, F);
    const material *mat = &m->materials[t->material];
    tet_stress(F, mat->lambda, mat->mu, out, &J);
    if (t->eta > 0) {
        double sv[6], now, before;
        tet_viscous(m->vel, t->node, c, det, t->eta, NULL, sv, &now, &before);
        for (int k = 0; k < 6; k++) out[k] += sv[k];
    }
}
