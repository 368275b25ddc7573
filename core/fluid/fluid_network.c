/*
 * fluid_network.c - the fluid network's set-up: the fluid itself
 * (fdem_set_fluid), each cavity's parameters and initial fluid, the links
 * between neighbouring cavities, the sources of the "inject" constraints,
 * and what it all weighs. The step's work is fluid_flow.c's.
 *
 * Links are found once, by the keys the dimension's kernel hands out (2D:
 * a joint's vertices, 3D: its edges): every two joints with a key in
 * common are linked, whether they are open now or not, so a joint that
 * breaks during the run joins the network without any rebuilding. A link
 * carries flow only while both its cavities are open. A bore's wall
 * hands out the same keys (fluid_bore.c), which link it to the joints that
 * meet the wall.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "joint/joint.h"
#include "fluid.h"

#define FLUID_APERTURE0_DEFAULT 1e-6

int fdem_set_fluid(fdem_model *m, const fdem_fluid_def *def, fdem_error *err)
{
    if (m->finalized) {
        model_error(err, FDEM_ITEM_NONE, -1, "the model is already finalized");
        return -1;
    }
    if (!(def->viscosity > 0) || !(def->bulk_modulus > 0) || !(def->density >= 0) ||
        !isfinite(def->viscosity) || !isfinite(def->bulk_modulus) || !isfinite(def->density)) {
        model_error(err, FDEM_ITEM_NONE, -1,
                    "fluid: viscosity and bulk_modulus must be finite and > 0, density finite "
                    "and >= 0");
        return -1;
    }
    if (!m->fluid && !(m->fluid = calloc(1, sizeof *m->fluid))) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }
    m->fluid->viscosity = def->viscosity;
    m->fluid->bulk_modulus = def->bulk_modulus;
    m->fluid->density = def->density;
    return 0;
}

void fluid_free(fdem_model *m)
{
    fluid_net *f = m->fluid;
    if (!f) return;
    free(f->fluid); free(f->pressure); free(f->volume); free(f->aperture); free(f->aperture0);
    free(f->floor); free(f->centre); free(f->force); free(f->inflow); free(f->conductance);
    free(f->outgoing); free(f->wet); free(f->open); free(f->links);
    free(f->link_begin); free(f->link_of); free(f->open_list); free(f->active);
    free(f->source_joint); free(f->source_constraint); free(f->source_share);
    free(f->constraint_injected);
    free(f->bore_constraint); free(f->bore_origin); free(f->bore_axis); free(f->wall_force);
    free(f->wall_corner); free(f->corner_begin); free(f->corner_node); free(f->corner_pos);
    free(f);
    m->fluid = NULL;
}

size_t fluid_memory_bytes(const fdem_model *m)
{
    const fluid_net *f = m->fluid;
    if (!f) return 0;
    size_t D = (size_t)m->dim, J = (size_t)f->cavities, B = (size_t)f->bores;
    size_t facets = (size_t)m->bfacet_count + 1, corners = (size_t)f->corner_count + 1;
    size_t bores = B ? B * (sizeof(int32_t) + 2 * D * sizeof(double)) +
                           D * facets * (sizeof(double) + 2 * sizeof(int32_t)) +
                           corners * (sizeof(int32_t) + D * sizeof(double))
                     : 0;
    return sizeof *f + bores + J * ((7 + 2 * D) * sizeof(double) + 2 + 2 * sizeof(int32_t)) +
           (size_t)f->link_count * (sizeof(fluid_link) + sizeof(double) + 3 * sizeof(int32_t)) +
           (size_t)f->source_count * (2 * sizeof(int32_t) + sizeof(double)) +
           (size_t)m->constraint_count * sizeof(double);
}

/* Links per joint in the densest meshes measured: a 2D vertex joins about
 * six joints (15 links, a vertex per three joints: 5 a joint), a 3D edge
 * about five faces (10 links, 3/5 of an edge a joint: 6 a joint); priced
 * at 8. */
#define FLUID_LINKS_PER_JOINT 8

size_t fdem_fluid_memory_estimate(int dimension, long joints)
{
    size_t D = dimension == 3 ? 3 : 2, J = joints > 0 ? (size_t)joints : 0;
    size_t cavity = (7 + 2 * D) * sizeof(double) + 2 + 2 * sizeof(int32_t);
    size_t link = sizeof(fluid_link) + sizeof(double) + 3 * sizeof(int32_t);
    size_t sources = 2 * sizeof(int32_t) + sizeof(double);
    size_t scratch = 3 * sizeof(int32_t) * 3; /* key entries while the links are built */
    return sizeof(fluid_net) + J * (cavity + FLUID_LINKS_PER_JOINT * link + sources + scratch);
}

/* The fracture parameters joint j takes: its set's, else its material's. */
static const fdem_fracture_params *joint_params(const fdem_model *m, int j)
{
    int set = m->joint_set_count ? joint_set_index(m, j) : -1;
    if (set >= 0) return &m->joint_sets[set].params;
    return &m->materials[element_material(m, m->joint_elem[2 * j])].def.fracture;
}

/* One key of one joint, for sorting. */
typedef struct key_entry {
    int32_t key[2];
    int32_t joint;
} key_entry;

static int key_compare(const void *pa, const void *pb)
{
    const key_entry *a = pa, *b = pb;
    for (int i = 0; i < 2; i++)
        if (a->key[i] != b->key[i]) return a->key[i] < b->key[i] ? -1 : 1;
    return (a->joint > b->joint) - (a->joint < b->joint);
}

static double point_distance(int D, const double *x, const double *y)
{
    double s = 0;
    for (int d = 0; d < D; d++) {
        double u = x[d] - y[d];
        s += u * u;
    }
    return sqrt(s);
}

/* The keys of every joint and every bore's wall, sorted, each (key,
 * cavity) once: a bore's wall facets share their keys with each other. */
static key_entry *keys_sorted(const fdem_model *m, const fluid_net *f, size_t *count)
{
    const int D = m->dim, J = f->joints;
    const size_t walls = (size_t)fluid_bore_key_count(m, f);
    key_entry *keys = malloc(sizeof *keys * (3 * (size_t)J + walls + 1));
    int32_t(*wall)[2] = malloc(sizeof *wall * (walls + 1));
    int32_t *cavity = malloc(sizeof *cavity * (walls + 1));
    if (!keys || !wall || !cavity) {
        free(keys), free(wall), free(cavity);
        return NULL;
    }
    size_t n = 0;
    for (int j = 0; j < J; j++) {
        int32_t k[3][2];
        int got = D == 3 ? fluid_keys_3d(m, j, k) : fluid_keys_2d(m, j, k);
        for (int i = 0; i < got; i++) keys[n++] = (key_entry){{k[i][0], k[i][1]}, j};
    }
    int w = fluid_bore_keys(m, f, wall, cavity);
    for (int i = 0; i < w; i++) keys[n++] = (key_entry){{wall[i][0], wall[i][1]}, cavity[i]};
    free(wall), free(cavity);
    qsort(keys, n, sizeof *keys, key_compare);
    size_t kept = 0;
    for (size_t i = 0; i < n; i++)
        if (!kept || key_compare(&keys[kept - 1], &keys[i])) keys[kept++] = keys[i];
    *count = kept;
    return keys;
}

/* The length of link a - b through key: between the two cavities'
 * centres, or, to a bore (b), from the joint's centre to the wall. */
static double link_length(const fdem_model *m, const fluid_net *f, int a, int b,
                          const int32_t key[2])
{
    const int D = m->dim;
    if (b < f->joints) return point_distance(D, f->centre + D * a, f->centre + D * b);
    double x[3];
    fluid_key_point(m, key, x);
    return point_distance(D, f->centre + D * a, x);
}

/* Every two cavities with a key in common, in key order then cavity
 * order; never two bores. */
static int links_build(fdem_model *m, fluid_net *f)
{
    const int D = m->dim, J = f->joints, C = f->cavities;
    size_t n = 0;
    key_entry *keys = keys_sorted(m, f, &n);
    if (!keys) return -1;
    size_t links = 0;
    for (int pass = 0; pass < 2; pass++) {
        links = 0;
        for (size_t s = 0; s < n;) {
            size_t e = s + 1;
            while (e < n && keys[e].key[0] == keys[s].key[0] && keys[e].key[1] == keys[s].key[1]) e++;
            double width = D == 3 ? fluid_key_width_3d(m, keys[s].key) : fluid_key_width_2d(m, keys[s].key);
            for (size_t i = s; i < e && keys[i].joint < J; i++)
                for (size_t k = i + 1; k < e; k++) {
                    if (pass) {
                        int a = keys[i].joint, b = keys[k].joint;
                        double l = link_length(m, f, a, b, keys[s].key);
                        f->links[links] = (fluid_link){a, b, l > 0 ? width / l : 0};
                    }
                    links++;
                }
            s = e;
        }
        if (!pass && !(f->links = malloc(sizeof *f->links * (links ? links : 1)))) {
            free(keys);
            return -1;
        }
    }
    free(keys);
    f->link_count = (int)links;
    f->conductance = malloc(sizeof(double) * (links ? links : 1));
    f->active = malloc(sizeof(int32_t) * (links ? links : 1));
    f->link_begin = calloc((size_t)C + 1, sizeof(int32_t));
    f->link_of = malloc(sizeof(int32_t) * 2 * (links ? links : 1));
    if (!f->conductance || !f->active || !f->link_begin || !f->link_of) return -1;
    /* each cavity's links, in link order (counting sort) */
    for (size_t l = 0; l < links; l++) {
        f->link_begin[f->links[l].a + 1]++;
        f->link_begin[f->links[l].b + 1]++;
    }
    for (int j = 0; j < C; j++) f->link_begin[j + 1] += f->link_begin[j];
    int32_t *fill = malloc(sizeof(int32_t) * (size_t)(C ? C : 1));
    if (!fill) return -1;
    memcpy(fill, f->link_begin, sizeof(int32_t) * (size_t)C);
    for (size_t l = 0; l < links; l++) {
        f->link_of[fill[f->links[l].a]++] = (int32_t)l;
        f->link_of[fill[f->links[l].b]++] = (int32_t)l;
    }
    free(fill);
    return 0;
}

/* A bore injection's one source: its bore, which must meet a joint. */
static int bore_source(fdem_model *m, fluid_net *f, int k, fdem_error *err)
{
    int b = 0;
    while (f->bore_constraint[b] != k) b++;
    const int cav = f->joints + b;
    if (f->link_begin[cav + 1] == f->link_begin[cav]) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k,
                    "constraint %d injects into a bore whose wall no joint meets (the wall must "
                    "bound a fracturing part)", k);
        return -1;
    }
    f->source_joint[f->source_count] = cav;
    f->source_share[f->source_count] = 1;
    f->source_constraint[f->source_count++] = k;
    return 0;
}

/* The joints touching each "inject" constraint's nodes, each its share
 * (a bore's injection: the bore). */
static int sources_build(fdem_model *m, fluid_net *f, fdem_error *err)
{
    const int D = m->dim, J = f->joints;
    uint8_t *selected = calloc((size_t)(m->node_count ? m->node_count : 1), 1);
    size_t room = 0;
    for (int k = 0; k < m->constraint_count; k++)
        if (m->constraints[k].def.kind == FDEM_CONSTRAINT_INJECT) room += (size_t)J + 1;
    f->source_joint = malloc(sizeof(int32_t) * (room ? room : 1));
    f->source_constraint = malloc(sizeof(int32_t) * (room ? room : 1));
    f->source_share = malloc(sizeof(double) * (room ? room : 1));
    f->constraint_injected = calloc((size_t)(m->constraint_count ? m->constraint_count : 1),
                                    sizeof(double));
    if (!selected || !f->source_joint || !f->source_constraint || !f->source_share ||
        !f->constraint_injected) {
        free(selected);
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the fluid network");
        return -1;
    }
    for (int k = 0; k < m->constraint_count; k++) {
        const constraint *c = &m->constraints[k];
        if (c->def.kind != FDEM_CONSTRAINT_INJECT) continue;
        if (c->def.bore) {
            if (bore_source(m, f, k, err)) {
                free(selected);
                return -1;
            }
            continue;
        }
        for (int e = c->entry_begin; e < c->entry_begin + c->entry_count; e++) selected[m->cnode[e]] = 1;
        int first = f->source_count;
        for (int j = 0; j < J; j++) {
            const int32_t *n = m->joint_node + 2 * (size_t)D * (size_t)j;
            int touches = 0;
            for (int i = 0; i < 2 * D; i++) touches |= selected[n[i]];
            if (!touches) continue;
            f->source_joint[f->source_count] = j;
            f->source_constraint[f->source_count++] = k;
            f->wet[j] = 1;
        }
        for (int e = c->entry_begin; e < c->entry_begin + c->entry_count; e++) selected[m->cnode[e]] = 0;
        int count = f->source_count - first;
        if (!count) {
            free(selected);
            model_error(err, FDEM_ITEM_CONSTRAINT, k,
                        "constraint %d injects fluid, but none of the nodes it selects lies on a "
                        "joint (select nodes of a fracturing part's interior)", k);
            return -1;
        }
        for (int s = first; s < f->source_count; s++) f->source_share[s] = 1.0 / count;
    }
    free(selected);
    return 0;
}

/* Each cavity's aperture0, pore pressure (its floor and initial fluid) and
 * centre; the wet flag of those with a pore pressure. */
static void cavities_init(fdem_model *m, fluid_net *f)
{
    const int D = m->dim;
    for (int j = 0; j < f->joints; j++) {
        const fdem_fracture_params *p = joint_params(m, j);
        const int32_t *n = m->joint_node + 2 * (size_t)D * (size_t)j;
        for (int d = 0; d < D; d++) {
            double s = 0;
            for (int i = 0; i < D; i++) s += m->pos0[(size_t)D * n[i] + d];
            f->centre[D * j + d] = s / D;
        }
        f->aperture0[j] = p->aperture0 > 0 ? p->aperture0 : FLUID_APERTURE0_DEFAULT;
        f->floor[j] = 0;
        f->pressure[j] = 0;
        if (!p->has_pore_pressure) continue;
        double h = f->centre[D * j + D - 1];
        double p0 = p->pore_pressure[0] + p->pore_pressure[1] * (h - p->pore_pressure[2]);
        f->pressure[j] = p0; /* the initial fluid is set from it below */
        f->floor[j] = p0 < 0 ? p0 : 0;
        f->wet[j] = 1;
    }
}

/* The stiffness the fluid adds to a joint's nodes: a filled cavity
 * squeezed by u at one corner loses A u / dim of its volume (the opening is
 * the mean of dim corner gaps), so its pressure rises by K u / (dim a);
 * the corner gets A / dim of that, and a corner lies on about dim faces
 * of its element: K A / (dim a) per node, at its stiffest (a = aperture0).
 * It acts beside the joint's own spring, so it is added to whichever limit
 * binds: 1 / dt^2 of springs in parallel add up. */
static double fluid_stable_dt(const fdem_model *m, fluid_net *f, double dt)
{
    const int D = m->dim;
    double fluid_dt = INFINITY;
    for (int j = 0; j < f->joints; j++) {
        const int32_t *n = m->joint_node + 2 * (size_t)D * (size_t)j;
        double mass = INFINITY;
        for (int i = 0; i < 2 * D; i++) mass = fmin(mass, m->mass[n[i]]);
        fluid_face face;
        fluid_face_of(m, j, &face);
        double area = sqrt(face.area[0] * face.area[0] + face.area[1] * face.area[1] +
                           face.area[2] * face.area[2]);
        double k = f->bulk_modulus * area / (D * f->aperture0[j]);
        if (k > 0) fluid_dt = fmin(fluid_dt, joint_spring_dt(mass, k));
    }
    if (f->bores) fluid_dt = fmin(fluid_dt, fluid_bores_stable_dt(m, f));
    if (!isfinite(fluid_dt)) return dt;
    if (!isfinite(dt)) return fluid_dt;
    return 1 / sqrt(1 / (dt * dt) + 1 / (fluid_dt * fluid_dt));
}

int fluid_prepare(fdem_model *m, fdem_error *err)
{
    fluid_net *f = m->fluid;
    for (int k = 0; !f && k < m->constraint_count; k++)
        if (m->constraints[k].def.kind == FDEM_CONSTRAINT_INJECT) {
            model_error(err, FDEM_ITEM_CONSTRAINT, k,
                        "constraint %d injects fluid, but the model has no fluid", k);
            return -1;
        }
    if (!f) return 0;
    f->joints = m->joint_count;
    if (fluid_bores_count(m, f, err)) return -1;
    const size_t C = (size_t)f->cavities, D = (size_t)m->dim, room = C ? C : 1;
    double **arrays[] = {&f->fluid, &f->pressure, &f->volume, &f->aperture, &f->aperture0,
                         &f->floor, &f->inflow, &f->outgoing};
    int ok = 1;
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
        ok &= (*arrays[i] = calloc(room, sizeof(double))) != NULL;
    f->centre = calloc(room * D, sizeof(double));
    f->force = calloc(room * D, sizeof(double));
    f->wet = calloc(room, 1);
    f->open = calloc(room, 1);
    f->open_list = malloc(sizeof(int32_t) * room);
    if (!ok || !f->centre || !f->force || !f->wet || !f->open || !f->open_list) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the fluid network");
        return -1;
    }
    cavities_init(m, f);
    fluid_bores_init(m, f);
    if (links_build(m, f)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the fluid network");
        return -1;
    }
    if (sources_build(m, f, err)) return -1;
    /* the initial fluid: a wet cavity full at its pore pressure (0 for a
     * source), on the geometry at t = 0 */
    for (int j = 0; j < f->joints; j++) {
        if (!f->wet[j]) continue;
        fluid_face face;
        fluid_face_of(m, j, &face);
        double area = sqrt(face.area[0] * face.area[0] + face.area[1] * face.area[1] +
                           face.area[2] * face.area[2]);
        double V = fmax(face.opening, f->aperture0[j]) * area;
        f->fluid[j] = V * (1 + f->pressure[j] / f->bulk_modulus);
    }
    /* both limits, so stable_dt is what one limit of their smaller would be */
    m->eigen_dt = fluid_stable_dt(m, f, m->eigen_dt);
    if (isfinite(m->contact_dt)) m->contact_dt = fluid_stable_dt(m, f, m->contact_dt);
    m->stable_dt = fmin(m->eigen_dt, m->contact_dt);
    fluid_refresh(m);
    return 0;
}
