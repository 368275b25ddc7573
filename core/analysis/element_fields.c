/*
 * element_fields.c - per-element fields derived for output (contract 5.4):
 * the Green-Lagrange strain E = (F^T F - I) / 2 and the principal stresses.
 *
 * Why here and not in the element kernels: these fields never enter a step,
 * so they are computed only when a snapshot asks for them, from what the
 * kernels already keep (the inverse of each element's initial edge matrix).
 * One code for both dimensions: F = [x1-x0, x2-x0 (, x3-x0)] [X]^-1 with the
 * row-major xinv of the triangle (element_hot) or tetrahedron (tet_hot).
 * Principal stresses: math/principal.c.
 */
#include <math.h>
#include <string.h>

#include "element/element.h"
#include "math/voigt.h"
#include "model/model.h"
#include "analysis.h"

static const double *element_xinv(const fdem_model *m, int e)
{
    return m->dim == 3 ? m->tet[e].xinv : m->elem[e].xinv;
}

/* F (dim x dim, row-major) of element e at the current positions. */
static void deformation_gradient(const fdem_model *m, int e, double F[9])
{
    int D = m->dim;
    const int32_t *node = m->elem_node + (size_t)m->elem_nodes * (size_t)e;
    const double *x0 = m->pos + (size_t)D * (size_t)node[0];
    const double *xinv = element_xinv(m, e);
    double edge[3][3];
    for (int k = 0; k < D; k++)
        for (int i = 0; i < D; i++) edge[k][i] = m->pos[(size_t)D * (size_t)node[k + 1] + (size_t)i] - x0[i];
    for (int i = 0; i < D; i++)
        for (int j = 0; j < D; j++) {
            double f = 0;
            for (int k = 0; k < D; k++) f += edge[k][i] * xinv[D * k + j];
            F[D * i + j] = f;
        }
}

void fdem_element_strain(const fdem_model *m, double *out)
{
    int D = m->dim, comps = model_stress_comps(m);
    for (int e = 0; e < m->elem_count; e++) {
        double F[9];
        deformation_gradient(m, e, F);
        double *E = out + (size_t)comps * (size_t)e;
        for (int i = 0; i < D; i++)
            for (int j = i; j < D; j++) {
                double c = 0; /* (F^T F)_ij */
                for (int k = 0; k < D; k++) c += F[D * k + i] * F[D * k + j];
                E[voigt_index(D, i, j)] = 0.5 * (c - (i == j));
            }
    }
}

void fdem_element_principal_stress(const fdem_model *m, double *out)
{
    int D = m->dim;
    for (int e = 0; e < m->elem_count; e++) {
        double stress[6];
        element_stress_one(m, e, stress);
        fdem_principal_values(D, stress, out + (size_t)D * (size_t)e);
    }
}

void fdem_element_stress(const fdem_model *m, double *out)
{
    size_t comps = (size_t)model_stress_comps(m);
    for (int e = 0; e < m->elem_count; e++) element_stress_one(m, e, out + comps * (size_t)e);
}
