/*
 * boundary_load.c - loads that act on a body's boundary rather than on its
 * nodes (contracts 5.3 and 6.1): a pressure along the current inward normal
 * of every selected boundary edge (3D: face), the traction sigma . n of a
 * given stress field on its current outward normal (boundary stress), a
 * fixed vector traction, and Lysmer-Kuhlemeyer dashpots that let waves
 * leave through it. Both dimensions share every loop; only the area vector
 * of a facet (an edge's rotated tangent, a face's half cross product)
 * depends on the dimension.
 *
 * A boundary facet is an element edge (face) that no other element of the
 * same body has: facets are keyed by their mesh vertices (node_origin), so
 * the faces joined by joints inside a fracturing part are interior, and a
 * crack opening during the run does not become loaded. A constraint loads
 * the boundary facets whose nodes it all selects; the facets are found once
 * at finalize, their forces are recomputed on the deformed geometry at
 * every step. Nothing here runs for a model without such constraints.
 * An injection into a bore (fluid/fluid_bore.c) has its wall's facets
 * found here too; the fluid network presses on them, not this file.
 *
 * Excavation (stages.c) changes the boundary: a facet between an element
 * that stays and one a stage removes becomes boundary when that stage
 * starts (the opening), and the facets of a removed element stop being
 * boundary. So in a model whose stages excavate, finalize also keeps the
 * facets that open later, each with the number of stages that must have
 * started before it is loaded (bfacet_open), and a facet loads only while
 * its element is active: a pressure, boundary stress, traction or dashpot
 * on nodes of the opening acts on its wall (a support pressure in a
 * staged tunnel). Which facets are live follows from the stages started
 * and the active elements alone, so a checkpoint needs nothing more.
 *
 * Lumping: a load uniform over a facet puts |S|/dim of it on each vertex.
 * A boundary stress varies linearly with the height, so its traction is
 * linear along the facet and is lumped consistently (int N_a t dA): 2D
 * L (2 t_a + t_b) / 6, 3D A (2 t_a + t_b + t_c) / 12. Both are the traction
 * at the vertex's weighted height (h_a + sum of the facet's h) / (dim + 1)
 * times |S| / dim, so one formula serves both dimensions, and a uniform
 * field gives exactly what a pressure gives. Consistent lumping is what
 * makes a block whose elements hold the same linear field (constant strain,
 * stress at the centroid, lumped gravity balancing its divergence) be at
 * rest to round-off: by the divergence theorem each node's internal force is
 * then exactly the sum of these loads and its weight.
 *
 * Energy: each facet force's work is booked as every force's, with the
 * step-averaged velocity f . (v_old + v_new)/2 havg, as external work for
 * the applied loads and as dissipated (damping) for a dashpot; energy.c
 * drops the last half step, as for the other accounts.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "math/facet_area.h"
#include "math/node_ids.h"
#include "math/voigt.h"
#include "step.h"

static int is_boundary_load(const constraint *c)
{
    switch (c->def.kind) {
    case FDEM_CONSTRAINT_PRESSURE:
    case FDEM_CONSTRAINT_ABSORB:
    case FDEM_CONSTRAINT_BOUNDARY_STRESS:
    case FDEM_CONSTRAINT_TRACTION: return 1;
    default: return 0;
    }
}

/* A constraint that needs its boundary facets: a boundary load, or a
 * fluid injection into a bore, whose wall they are (fluid/fluid_bore.c
 * presses on them; the loops below that apply and book loads skip it). */
static int has_facets(const constraint *c)
{
    return is_boundary_load(c) || (c->def.kind == FDEM_CONSTRAINT_INJECT && c->def.bore);
}

/* "a pressure", ... for messages that name what a constraint does. */
static const char *load_name(const constraint *c)
{
    switch (c->def.kind) {
    case FDEM_CONSTRAINT_INJECT: return "a bore's injection";
    case FDEM_CONSTRAINT_PRESSURE: return "a pressure";
    case FDEM_CONSTRAINT_BOUNDARY_STRESS: return "a boundary stress";
    case FDEM_CONSTRAINT_TRACTION: return "a traction";
    default: return "an absorbing boundary";
    }
}

/* The vertices of each facet of an element, ordered so that the facet's
 * area vector points out of it: counter-clockwise edges of a triangle (the
 * outward normal of edge a -> b is its tangent turned clockwise) and the
 * faces of a positive tetrahedron seen from outside. */
static const int tri_facets[3][3] = {{0, 1, -1}, {1, 2, -1}, {2, 0, -1}};
static const int tet_facets[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

static const int *facet_vertices(const fdem_model *m, int f)
{
    return m->dim == 3 ? tet_facets[f] : tri_facets[f];
}

/* Outward area vector of the facet through nodes n (dim of them) at the
 * current positions: length times the unit normal in 2D (per unit
 * thickness), area times it in 3D. */
static void facet_area_vector(const fdem_model *m, const int32_t *n, double s[3])
{
    const size_t D = (size_t)m->dim;
    const double *x[3] = {m->pos + D * (size_t)n[0], m->pos + D * (size_t)n[1],
                          D == 3 ? m->pos + D * (size_t)n[2] : NULL};
    facet_area_vector_of(m->dim, x, s);
}

/* One element facet, keyed by its sorted mesh vertices. */
typedef struct facet_key {
    int32_t vertex[3];
    int32_t elem, facet;
} facet_key;

static int facet_key_compare(const void *pa, const void *pb)
{
    const facet_key *a = pa, *b = pb;
    int c = node_ids_compare(a->vertex, b->vertex, 3);
    return c ? c : (a->elem > b->elem) - (a->elem < b->elem);
}

/* Every element facet, sorted so that the two sides of an interior facet
 * are neighbours. Returns the array (count in *out_count) or NULL. */
static facet_key *facets_sorted(const fdem_model *m, int *out_count)
{
    const int D = m->dim, per = m->elem_nodes;
    size_t count = (size_t)per * (size_t)m->elem_count;
    facet_key *keys = malloc(sizeof *keys * (count ? count : 1));
    if (!keys) return NULL;
    size_t at = 0;
    for (int e = 0; e < m->elem_count; e++) {
        const int32_t *n = element_nodes(m, e);
        for (int f = 0; f < per; f++) {
            facet_key *k = &keys[at++];
            const int *v = facet_vertices(m, f);
            k->vertex[2] = -1; /* 2D: a sorted edge has it first */
            for (int j = 0; j < D; j++) k->vertex[j] = m->node_origin[n[v[j]]];
            node_ids_sort(k->vertex, 3);
            k->elem = e;
            k->facet = f;
        }
    }
    qsort(keys, count, sizeof *keys, facet_key_compare);
    *out_count = (int)count;
    return keys;
}

static int same_facet(const facet_key *a, const facet_key *b)
{
    return memcmp(a->vertex, b->vertex, sizeof a->vertex) == 0;
}

/* When facet i of keys is on the boundary of its element's body: 0 from
 * the start, k once k stages have started (the stage k - 1 that removes
 * the last element on its other side), -1 never (an element that stays is
 * on its other side, or its own element goes no later than that). removed_by
 * (NULL without excavations) holds per element the number of stages started
 * once it is gone, 0 if it stays. */
static int facet_opens_at(const facet_key *keys, int count, int i, const int32_t *removed_by)
{
    int lo = i, hi = i + 1;
    while (lo > 0 && same_facet(&keys[lo - 1], &keys[i])) lo--;
    while (hi < count && same_facet(&keys[hi], &keys[i])) hi++;
    if (hi - lo == 1) return 0;
    if (!removed_by) return -1;
    int opens = 0;
    for (int o = lo; o < hi; o++) {
        if (o == i) continue;
        int gone = removed_by[keys[o].elem];
        if (!gone) return -1;
        if (gone > opens) opens = gone;
    }
    int own = removed_by[keys[i].elem];
    return own && own <= opens ? -1 : opens;
}

/* Per element, 1 + the first stage that excavates it (the number of stages
 * started once it is gone), 0 for one that stays; NULL when no stage
 * excavates (*failed set when out of memory). */
static int32_t *elements_removed_by(const fdem_model *m, int *failed)
{
    int any = 0;
    for (int k = 0; k < m->stage_count; k++) any |= m->stages[k].excavate_count > 0;
    *failed = 0;
    if (!any) return NULL;
    int32_t *by = calloc((size_t)(m->elem_count ? m->elem_count : 1), sizeof *by);
    if (!by) {
        *failed = 1;
        return NULL;
    }
    for (int k = m->stage_count - 1; k >= 0; k--)
        for (int i = 0; i < m->stages[k].excavate_count; i++) by[m->stages[k].excavate[i]] = k + 1;
    return by;
}

/* Boundary facet i of keys, when constraint c selects all its nodes: its
 * nodes into n (outward order). */
static int facet_selected(const fdem_model *m, const constraint *c, const facet_key *k,
                          int32_t n[3])
{
    const int32_t *en = element_nodes(m, k->elem);
    const int *v = facet_vertices(m, k->facet);
    for (int j = 0; j < m->dim; j++) {
        n[j] = en[v[j]];
        if (!constraint_selects(m, c, n[j])) return 0;
    }
    return 1;
}

/* Pass 0 counts the entries of every boundary-load constraint, pass 1 fills
 * them in. */
static void facets_assign(fdem_model *m, const facet_key *keys, int count,
                          const int32_t *removed_by, int pass)
{
    const int D = m->dim;
    int at = 0;
    for (int k = 0; k < m->constraint_count; k++) {
        constraint *c = &m->constraints[k];
        if (!has_facets(c)) continue;
        c->facet_begin = at;
        for (int i = 0; i < count; i++) {
            int32_t n[3];
            int opens = facet_opens_at(keys, count, i, removed_by);
            if (opens < 0 || !facet_selected(m, c, &keys[i], n)) continue;
            if (pass) {
                memcpy(m->bfacet_node + (size_t)D * (size_t)at, n, sizeof(int32_t) * (size_t)D);
                m->bfacet_elem[at] = keys[i].elem;
                if (m->bfacet_open) m->bfacet_open[at] = opens;
            }
            at++;
        }
        c->facet_count = at - c->facet_begin;
    }
    m->bfacet_count = at;
}

/* A boundary stress field must be finite (fdem_add_constraint checks only
 * the value vector the other kinds use). */
static int stress_fields_finite(const fdem_model *m, fdem_error *err)
{
    const int S = model_stress_comps(m);
    for (int k = 0; k < m->constraint_count; k++) {
        const fdem_constraint_def *def = &m->constraints[k].def;
        if (def->kind != FDEM_CONSTRAINT_BOUNDARY_STRESS) continue;
        int finite = isfinite(def->stress_reference);
        for (int i = 0; i < S; i++)
            finite &= isfinite(def->stress_value[i]) && isfinite(def->stress_gradient[i]);
        if (!finite) {
            model_error(err, FDEM_ITEM_CONSTRAINT, k,
                        "constraint %d: the boundary stress is not finite", k);
            return 0;
        }
    }
    return 1;
}

int boundary_load_select(fdem_model *m, fdem_error *err)
{
    int wanted = 0;
    for (int k = 0; k < m->constraint_count; k++) wanted |= has_facets(&m->constraints[k]);
    if (!wanted) return 0;
    if (!stress_fields_finite(m, err)) return -1;
    int count = 0, failed = 0;
    int32_t *removed_by = elements_removed_by(m, &failed);
    facet_key *keys = failed ? NULL : facets_sorted(m, &count);
    if (!keys) {
        free(removed_by);
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the boundary facets");
        return -1;
    }
    facets_assign(m, keys, count, removed_by, 0);
    const size_t D = (size_t)m->dim, n = (size_t)(m->bfacet_count ? m->bfacet_count : 1);
    m->bfacet_node = malloc(sizeof(int32_t) * D * n);
    m->bfacet_elem = malloc(sizeof(int32_t) * n);
    m->bfacet_force = calloc(D * D * n, sizeof(double));
    if (removed_by) m->bfacet_open = malloc(sizeof(int32_t) * n);
    if (!m->bfacet_node || !m->bfacet_elem || !m->bfacet_force || (removed_by && !m->bfacet_open)) {
        free(keys);
        free(removed_by);
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the boundary facets");
        return -1;
    }
    facets_assign(m, keys, count, removed_by, 1);
    free(keys);
    free(removed_by);
    for (int k = 0; k < m->constraint_count; k++) {
        const constraint *c = &m->constraints[k];
        if (has_facets(c) && c->facet_count == 0) {
            model_error(err, FDEM_ITEM_CONSTRAINT, k,
                        "constraint %d selects no boundary %s: %s acts on the %s of a body "
                        "whose nodes are all selected",
                        k, m->dim == 3 ? "face" : "edge", load_name(c),
                        m->dim == 3 ? "faces" : "edges");
            return -1;
        }
    }
    return 0;
}

/* The dashpot force on a facet vertex of velocity v, for the facet's
 * outward area vector s: the impedances z_p (normal) and z_s (tangential)
 * of the element behind, over the vertex's share of the area. */
static void dashpot_force(const fdem_model *m, int elem, const double s[3], const double *v,
                          double f[3])
{
    const int D = m->dim;
    const material *mat = &m->materials[element_material(m, elem)];
    double rho = mat->def.density;
    double z_p = sqrt(rho * (mat->lambda + 2 * mat->mu)), z_s = sqrt(rho * mat->mu);
    double area = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    double vn = 0;
    for (int d = 0; d < D; d++) vn += v[d] * s[d] / area;
    for (int d = 0; d < D; d++)
        f[d] = -(area / D) * (z_s * v[d] + (z_p - z_s) * vn * s[d] / area);
}

/* Initial height (y in 2D, z in 3D) of node n: where the material point
 * stood when the stress field was given. */
static double initial_height(const fdem_model *m, int32_t n)
{
    return m->pos0[(size_t)m->dim * (size_t)n + (size_t)(m->dim - 1)];
}

/* Vertex a's consistent share of the linear traction sigma(h) . s over the
 * facet of nodes n: the traction at the weighted height (h_a + sum h) /
 * (dim + 1), times 1/dim (see the top of the file), times the amplitude. */
static void boundary_stress_force(const fdem_model *m, const constraint *c, const int32_t *n,
                                  int a, const double s[3], double f[3])
{
    const int D = m->dim, S = model_stress_comps(m);
    const fdem_constraint_def *def = &c->def;
    double h = initial_height(m, n[a]);
    for (int b = 0; b < D; b++) h += initial_height(m, n[b]);
    double dh = h / (D + 1) - def->stress_reference, sigma[6];
    for (int k = 0; k < S; k++)
        sigma[k] = c->amplitude_now * (def->stress_value[k] + def->stress_gradient[k] * dh);
    double t[3];
    voigt_dot(D, sigma, s, t);
    for (int i = 0; i < D; i++) f[i] = t[i] / D;
}

/* The force on vertex a of facet j (nodes n, outward area vector s) from
 * constraint c; dashpots use the vertex's velocity v. */
static void vertex_force(const fdem_model *m, const constraint *c, int j, const int32_t *n, int a,
                         const double s[3], const double *v, double f[3])
{
    const int D = m->dim;
    switch (c->def.kind) {
    case FDEM_CONSTRAINT_PRESSURE:
        for (int d = 0; d < D; d++) f[d] = -c->value_now[0] * s[d] / D;
        return;
    case FDEM_CONSTRAINT_BOUNDARY_STRESS:
        boundary_stress_force(m, c, n, a, s, f);
        return;
    case FDEM_CONSTRAINT_TRACTION: {
        double area = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        for (int d = 0; d < D; d++) f[d] = c->value_now[d] * area / D;
        return;
    }
    default:
        dashpot_force(m, m->bfacet_elem[j], s, v, f);
        return;
    }
}

/* Facet j is boundary now: opened by the stages started, its element not
 * excavated (always, in a model whose stages excavate nothing). */
static int facet_live(const fdem_model *m, int j)
{
    return !m->bfacet_open || (m->stages_started >= m->bfacet_open[j] &&
                               element_is_active(m, m->bfacet_elem[j]));
}

/* The facet forces of this step, at the positions of t_n and (dashpots) the
 * velocities v(t_n - h/2): added to the node forces, totalled per
 * constraint, and their power with those velocities kept for the work. */

void boundary_load_apply(fdem_model *m)
{
    if (!m->bfacet_count) return;
    const int D = m->dim;
    m->boundary_power_old[0] = m->boundary_power_old[1] = 0;
    for (int k = 0; k < m->constraint_count; k++) {
        constraint *c = &m->constraints[k];
        if (!is_boundary_load(c)) continue;
        int absorb = c->def.kind == FDEM_CONSTRAINT_ABSORB;
        c->force[0] = c->force[1] = c->force[2] = 0;
        for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++) {
            if (!facet_live(m, j)) { /* no force, so no work (boundary_power) */
                memset(m->bfacet_force + (size_t)D * (size_t)D * (size_t)j, 0,
                       sizeof(double) * (size_t)D * (size_t)D);
                continue;
            }
            const int32_t *n = m->bfacet_node + (size_t)D * (size_t)j;
            double s[3];
            facet_area_vector(m, n, s);
            for (int a = 0; a < D; a++) {
                size_t at = (size_t)D * (size_t)n[a];
                double *f = m->bfacet_force + (size_t)D * ((size_t)D * (size_t)j + (size_t)a);
                double fv[3] = {0, 0, 0};
                vertex_force(m, c, j, n, a, s, m->vel + at, fv);
                for (int d = 0; d < D; d++) {
                    f[d] = fv[d];
                    m->force[at + d] += fv[d];
                    c->force[d] += fv[d];
                    m->boundary_power_old[absorb] += fv[d] * m->vel[at + d];
                }
            }
        }
    }
}

/* sum f . v over the facet forces of the last step (absorb: of the
 * dashpots, else of the applied loads), with the velocities now held. */
static double boundary_power(const fdem_model *m, int absorb)
{
    const int D = m->dim;
    double power = 0;
    for (int k = 0; k < m->constraint_count; k++) {
        const constraint *c = &m->constraints[k];
        if (!is_boundary_load(c) || (c->def.kind == FDEM_CONSTRAINT_ABSORB) != absorb) continue;
        for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++)
            for (int a = 0; a < D; a++) {
                const double *f = m->bfacet_force + (size_t)D * ((size_t)D * (size_t)j + (size_t)a);
                const double *v = m->vel + (size_t)D * (size_t)m->bfacet_node[(size_t)D * (size_t)j + (size_t)a];
                for (int d = 0; d < D; d++) power += f[d] * v[d];
            }
    }
    return power;
}

/* After every dof has its new velocity: the step's work of the facet forces. */
void boundary_load_account(fdem_model *m, double havg)
{
    if (!m->bfacet_count) return;
    m->external_work += 0.5 * havg * (m->boundary_power_old[0] + boundary_power(m, 0));
    m->damping_work -= 0.5 * havg * (m->boundary_power_old[1] + boundary_power(m, 1));
}

/* Half the last step's work with the new velocities: what the sum above
 * holds beyond x_n (added back for the dashpots, whose account counts
 * dissipation, i.e. minus their work). */
double boundary_load_last_half_step(const fdem_model *m, int absorb)
{
    if (!m->bfacet_count) return 0;
    return 0.5 * m->havg_last * boundary_power(m, absorb);
}

void boundary_load_free(fdem_model *m)
{
    free(m->bfacet_node);
    free(m->bfacet_elem);
    free(m->bfacet_force);
    free(m->bfacet_open);
}
