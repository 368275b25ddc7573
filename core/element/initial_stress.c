/*
 * initial_stress.c - in-situ stress (contract 5.3): a part's elements start
 * at t = 0 with a given Cauchy stress field, value + gradient (h - reference)
 * at the height h of each element's initial centroid.
 *
 * This file owns the definitions as given (per part, until finalize), their
 * evaluation into one pre-stress per element (elem_stress0, allocated only
 * when some part has one), the energy that stress holds at t = 0 and its
 * effect on the stable step. The element kernels (element_tri.c,
 * element_tet_model.c) carry the stored stress as a second Piola-Kirchhoff
 * pre-stress S0: sigma = sigma_elastic(F) + F S0 F^T / J, whose potential
 * is S0 : E (E the Green-Lagrange strain) per unit initial volume. At t = 0
 * F = I and sigma is the given field; a rigid rotation R turns it into
 * R S0 R^T (it rotates with the element); and because it derives from a
 * potential the energy account closes as for the elastic stress (see
 * docs/physics.md for why this form and not a rotated Cauchy stress).
 *
 * Only the elements of stressed parts pay for it: element.c runs them
 * through the kernels' *_stressed loops, all others through the plain ones.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "element.h"

int fdem_set_part_initial_stress(fdem_model *m, int part_index, const double *value,
                                 const double *gradient, double reference, fdem_error *err)
{
    if (m->finalized) {
        model_error(err, FDEM_ITEM_PART, part_index, "the model is already finalized");
        return -1;
    }
    if (part_index < 0 || part_index >= m->part_count) {
        model_error(err, FDEM_ITEM_PART, part_index, "part %d does not exist", part_index);
        return -1;
    }
    const int S = model_stress_comps(m);
    int finite = isfinite(reference);
    for (int k = 0; k < S; k++) finite &= isfinite(value[k]) && (!gradient || isfinite(gradient[k]));
    if (!finite) {
        model_error(err, FDEM_ITEM_PART, part_index,
                    "the initial stress of part %d is not finite", part_index);
        return -1;
    }
    int slot = 0;
    while (slot < m->stress0_def_count && m->stress0_defs[slot].part != part_index) slot++;
    if (slot == m->stress0_def_count) {
        void *p = realloc(m->stress0_defs, sizeof *m->stress0_defs * (size_t)(slot + 1));
        if (!p) {
            model_error(err, FDEM_ITEM_PART, part_index, "out of memory");
            return -1;
        }
        m->stress0_defs = p;
        m->stress0_def_count++;
    }
    initial_stress_def *def = &m->stress0_defs[slot];
    memset(def, 0, sizeof *def);
    def->part = part_index;
    def->reference = reference;
    for (int k = 0; k < S; k++) {
        def->value[k] = value[k];
        def->gradient[k] = gradient ? gradient[k] : 0;
    }
    return 0;
}

/* Height of element e's initial centroid: y in 2D, z in 3D. */
static double centroid_height(const fdem_model *m, int e)
{
    const int K = m->elem_nodes, D = m->dim;
    const int32_t *node = element_nodes(m, e);
    double h = 0;
    for (int c = 0; c < K; c++) h += m->pos0[(size_t)D * (size_t)node[c] + (size_t)(D - 1)];
    return h / K;
}

/* sigma : C^-1 : sigma / 2 of the linear elastic (plane strain in 2D)
 * compliance, for a stress in the layout of fdem_element_stress: the
 * normal block of the stiffness is 2 mu I + lambda 1 1^T on the n = dim
 * normal components, whose inverse is (I - lambda / (n lambda + 2 mu) 1 1^T)
 * / (2 mu); the shears are mu each. One formula for both dimensions. */
static double locked_energy_density(int dim, const double *s, double lambda, double mu)
{
    const int S = dim == 3 ? 6 : 3;
    double normal2 = 0, trace = 0, shear2 = 0;
    for (int k = 0; k < dim; k++) {
        normal2 += s[k] * s[k];
        trace += s[k];
    }
    for (int k = dim; k < S; k++) shear2 += s[k] * s[k];
    return (normal2 + 2 * shear2 - lambda / (dim * lambda + 2 * mu) * trace * trace) / (4 * mu);
}

static void prepare_part(fdem_model *m, const initial_stress_def *def)
{
    part *p = &m->parts[def->part];
    const int S = model_stress_comps(m);
    const material *mat = &m->materials[p->material];
    p->stressed = 1;
    for (int e = p->elem_begin; e < p->elem_begin + p->elem_count; e++) {
        double *s0 = m->elem_stress0 + (size_t)S * (size_t)e;
        initial_stress_at(def, S, centroid_height(m, e), s0);
        m->stress0_energy += element_size0(m, e) *
                             locked_energy_density(m->dim, s0, mat->lambda, mat->mu);
    }
}

int initial_stress_prepare(fdem_model *m, fdem_error *err)
{
    m->stress0_energy = 0;
    if (m->stress0_def_count == 0) return 0;
    const size_t S = (size_t)model_stress_comps(m);
    free(m->elem_stress0);
    m->elem_stress0 = calloc(S * (size_t)m->elem_count, sizeof(double));
    if (!m->elem_stress0) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the initial stresses");
        return -1;
    }
    for (int k = 0; k < m->stress0_def_count; k++) prepare_part(m, &m->stress0_defs[k]);
    return 0;
}

double initial_stress_energy(const fdem_model *m)
{
    const int S = model_stress_comps(m);
    double sum = 0;
    for (int k = 0; k < m->stress0_def_count; k++) {
        const part *p = &m->parts[m->stress0_defs[k].part];
        const material *mat = &m->materials[p->material];
        for (int e = p->elem_begin; e < p->elem_begin + p->elem_count; e++)
            if (element_is_active(m, e))
                sum += element_size0(m, e) *
                       locked_energy_density(m->dim, m->elem_stress0 + (size_t)S * (size_t)e,
                                             mat->lambda, mat->mu);
    }
    return sum;
}

/* A pre-stress sigma0 adds the geometric stiffness A grad(u) . sigma0 .
 * grad(u) (per unit size), at most sigma_1 |grad u|^2 for the largest
 * principal stress sigma_1 > 0; the elastic stiffness of the mode with the
 * largest |grad u|^2 is at least mu |grad u|^2. So omega^2 grows by at
 * most the factor 1 + sigma_1 / mu and the step shrinks by its root. A
 * compressive pre-stress only softens the element (factor 1). */
double initial_stress_dt_factor(const fdem_model *m, int e)
{
    if (!m->elem_stress0 || !m->parts[m->elem_part[e]].stressed) return 1;
    double principal[3];
    fdem_principal_values(m->dim, m->elem_stress0 + (size_t)model_stress_comps(m) * (size_t)e,
                          principal);
    double mu = m->materials[element_material(m, e)].mu;
    return principal[0] > 0 ? 1 / sqrt(1 + principal[0] / mu) : 1;
}
