/*
 * build.c - a model from nothing to ready for finalize: creating and
 * destroying it, the dimension, materials, parts (mesh nodes and
 * elements, part by part), velocities, gravity and constraints as given.
 * Nothing here computes: it checks what it is given, names the item at
 * fault, and copies it into the model's state (model/model.h).
 *
 * Both dimensions share this file: a part is node coordinates (dim a node)
 * and element node lists (elem_nodes an element) whatever its dimension;
 * only validating the mesh (mesh/) differs.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "math/amplitude.h"
#include "mesh/mesh.h"
#include "model/model.h"
#include "contact/contact.h"
#include "joint/joint.h"
#include "fluid/fluid.h"
#include "parallel/scatter_plan.h"
#include "step/step.h"
#include "build.h"

/* model_reserve for the build-phase arrays (materials, parts,
 * constraints), whose counts are int. */
static int grow(void **array, int *capacity, int need, size_t size)
{
    if (need <= *capacity) return 0;
    size_t cap = (size_t)*capacity;
    if (model_reserve(array, &cap, (size_t)need, size, 16)) return -1;
    *capacity = cap > INT32_MAX ? INT32_MAX : (int)cap;
    return 0;
}

fdem_model *fdem_model_create(void)
{
    fdem_model *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    m->dim = 2;
    m->elem_nodes = 3;
    nbs_grid_init(&m->contact.grid);
    nbs_classes_init(&m->contact.classes);
    nbs_pairs_init(&m->contact.pairs);
    return m;
}

void fdem_model_destroy(fdem_model *m)
{
    if (!m) return;
    free(m->pos); free(m->vel); free(m->force); free(m->inv_mass);
    free(m->pos0); free(m->mass); free(m->node_part); free(m->node_origin); free(m->dof_owned);
    free(m->elem); free(m->tet); free(m->elem_part); free(m->elem_node); free(m->elem_h);
    free(m->materials); free(m->parts); free(m->part_velocity);
    for (int k = 0; k < m->constraint_count; k++) {
        free(m->constraints[k].amplitude);
        free(m->constraints[k].vertices);
    }
    free(m->gravity_amplitude);
    boundary_load_free(m);
    free(m->constraints); free(m->cnode); free(m->cdof); free(m->constraint_force_out);
    free(m->joint_node); free(m->joint_damage); free(m->joint_offset); free(m->joint_elem); free(m->joint_h);
    free(m->joint_slip); free(m->joint_k); free(m->joint_strength_of); free(m->joint_strengths);
    joint_sets_free(m);
    free(m->elem_joint); free(m->elem_piece0); free(m->vertex_broken); free(m->vertex_root); free(m->elem_viscous); free(m->fixed_force);
    free(m->stress0_defs); free(m->elem_stress0);
    free(m->joint_fracture); free(m->joint_broke); free(m->events);
    stages_free(m);
    fluid_free(m);
    contact_free(&m->contact);
    scatter_plan_free(&m->elem_plan);
    joint_sweep_free(&m->joint_sweep);
    scatter_plan_free(&m->node_plan);
    free(m);
}

int fdem_set_dimension(fdem_model *m, int dimension, fdem_error *err)
{
    if (dimension != 2 && dimension != 3) {
        model_error(err, FDEM_ITEM_NONE, -1, "dimension must be 2 or 3, not %d", dimension);
        return -1;
    }
    if (m->part_count > 0 || m->finalized) {
        model_error(err, FDEM_ITEM_NONE, -1,
                    "the dimension is chosen before the first part is added");
        return -1;
    }
    m->dim = dimension;
    m->elem_nodes = dimension + 1;
    return 0;
}

int fdem_get_dimension(const fdem_model *m) { return m->dim; }

int fdem_add_material(fdem_model *m, const fdem_material_def *def, fdem_error *err)
{
    int k = m->material_count;
    if (m->finalized) {
        model_error(err, FDEM_ITEM_MATERIAL, k, "the model is already finalized");
        return -1;
    }
    if (!(def->density > 0) || !(def->young > 0) || !isfinite(def->density) || !isfinite(def->young)) {
        model_error(err, FDEM_ITEM_MATERIAL, k, "density and Young's modulus must be positive");
        return -1;
    }
    if (!(def->poisson > -1.0 && def->poisson < 0.5)) {
        model_error(err, FDEM_ITEM_MATERIAL, k,
                    "Poisson's ratio %g is outside (-1, 0.5); 0.5 (incompressible) is not supported",
                    def->poisson);
        return -1;
    }
    if (!(def->damping >= 0) || !(def->friction >= 0) || !isfinite(def->damping) ||
        !isfinite(def->friction) || !isfinite(def->penalty)) {
        model_error(err, FDEM_ITEM_MATERIAL, k, "damping and friction must be finite and >= 0");
        return -1;
    }
    if (grow((void **)&m->materials, &m->material_capacity, k + 1, sizeof *m->materials)) {
        model_error(err, FDEM_ITEM_MATERIAL, k, "out of memory");
        return -1;
    }
    material *mat = &m->materials[k];
    mat->def = *def;
    double E = def->young, nu = def->poisson;
    mat->mu = E / (2 * (1 + nu));
    mat->lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    mat->penalty = def->penalty > 0 ? def->penalty : 10 * E;
    mat->tan_phi = def->has_fracture ? tan(def->fracture.friction_angle * M_PI / 180) : 0;
    m->material_count++;
    return k;
}

static int reserve_nodes(fdem_model *m, int need)
{
    int cap = m->node_capacity;
    if (need <= cap) return 0;
    int newcap = cap ? cap : 64;
    while (newcap < need) newcap *= 2;
    double **d2[] = {&m->pos, &m->vel, &m->force, &m->pos0};
    for (size_t i = 0; i < sizeof d2 / sizeof d2[0]; i++) {
        void *p = realloc(*d2[i], sizeof(double) * (size_t)m->dim * (size_t)newcap);
        if (!p) return -1;
        *d2[i] = p;
    }
    double **d1[] = {&m->inv_mass, &m->mass};
    for (size_t i = 0; i < sizeof d1 / sizeof d1[0]; i++) {
        void *p = realloc(*d1[i], sizeof(double) * (size_t)newcap);
        if (!p) return -1;
        *d1[i] = p;
    }
    int32_t **i1[] = {&m->node_part, &m->node_origin};
    for (size_t i = 0; i < sizeof i1 / sizeof i1[0]; i++) {
        void *p = realloc(*i1[i], sizeof(int32_t) * (size_t)newcap);
        if (!p) return -1;
        *i1[i] = p;
    }
    m->node_capacity = newcap;
    return 0;
}

static int reserve_elements(fdem_model *m, int need)
{
    int cap = m->elem_capacity;
    if (need <= cap) return 0;
    int newcap = cap ? cap : 64;
    while (newcap < need) newcap *= 2;
    void *p;
    if (m->dim == 3) {
        if (!(p = realloc(m->tet, sizeof(tet_hot) * (size_t)newcap))) return -1;
        m->tet = p;
    } else {
        if (!(p = realloc(m->elem, sizeof(element_hot) * (size_t)newcap))) return -1;
        m->elem = p;
    }
    p = realloc(m->elem_part, sizeof(int32_t) * (size_t)newcap);
    if (!p) return -1;
    m->elem_part = p;
    p = realloc(m->elem_node, sizeof(int32_t) * (size_t)m->elem_nodes * (size_t)newcap);
    if (!p) return -1;
    m->elem_node = p;
    m->elem_capacity = newcap;
    return 0;
}

/* Checks what a part of either dimension needs before its mesh is read. */
static int part_check(fdem_model *m, int material_index, int fracture, int dim, fdem_error *err)
{
    int k = m->part_count;
    if (m->finalized) {
        model_error(err, FDEM_ITEM_PART, k, "the model is already finalized");
        return -1;
    }
    if (m->dim != dim) {
        model_error(err, FDEM_ITEM_PART, k, "part %d is a %dD mesh in a %dD model", k, dim,
                    m->dim);
        return -1;
    }
    if (material_index < 0 || material_index >= m->material_count) {
        model_error(err, FDEM_ITEM_PART, k, "part %d refers to material %d, which does not exist",
                    k, material_index);
        return -1;
    }
    if (fracture && !m->materials[material_index].def.has_fracture) {
        model_error(err, FDEM_ITEM_PART, k,
                    "part %d fractures but its material has no fracture parameters", k);
        return -1;
    }
    return 0;
}

/* The nodes of a part: its mesh's own (corner NULL, a part that does not
 * fracture), or `count` nodes with corner[K t + c] the node (0-based in the
 * part) of corner c of element t (joint_region_nodes). */
typedef struct part_nodes {
    const int32_t *corner;
    int count;
    int region;
} part_nodes;

/* Appends a validated mesh as part k: node coordinates (dim a node) and
 * element node lists (elem_nodes an element). A fracturing part gives
 * each class of a vertex's corners its own node (joints join them). */
static int part_append(fdem_model *m, const double *coords, int node_count, const int32_t *elems,
                       int elem_count, int material_index, const part_nodes *nodes,
                       fdem_error *err)
{
    int k = m->part_count, D = m->dim, K = m->elem_nodes;
    int fracture = nodes->corner != NULL;
    int add_nodes = fracture ? nodes->count : node_count;
    if (grow((void **)&m->parts, &m->part_capacity, k + 1, sizeof *m->parts) ||
        reserve_nodes(m, m->node_count + add_nodes) ||
        reserve_elements(m, m->elem_count + elem_count)) {
        model_error(err, FDEM_ITEM_PART, k, "out of memory for part %d", k);
        return -1;
    }
    double *pv = realloc(m->part_velocity, sizeof(double) * 3 * (size_t)m->part_capacity);
    if (!pv) {
        model_error(err, FDEM_ITEM_PART, k, "out of memory for part %d", k);
        return -1;
    }
    m->part_velocity = pv;
    m->part_velocity[3 * k] = m->part_velocity[3 * k + 1] = m->part_velocity[3 * k + 2] = 0;

    part *p = &m->parts[k];
    memset(p, 0, sizeof *p);
    p->material = material_index;
    p->fracture = fracture;
    p->region = fracture && nodes->region;
    p->node_begin = m->node_count;
    p->node_count = add_nodes;
    p->elem_begin = m->elem_count;
    p->elem_count = elem_count;
    for (int t = 0; t < elem_count; t++) {
        int e = m->elem_count + t;
        int32_t *hot_node;
        if (D == 3) {
            memset(&m->tet[e], 0, sizeof m->tet[e]);
            m->tet[e].material = material_index;
            hot_node = m->tet[e].node;
        } else {
            memset(&m->elem[e], 0, sizeof m->elem[e]);
            m->elem[e].material = material_index;
            hot_node = m->elem[e].node;
        }
        for (int c = 0; c < K; c++) {
            int src = elems[K * t + c];
            int dst = m->node_count + (fracture ? nodes->corner[K * t + c] : src);
            hot_node[c] = dst;
            m->elem_node[(size_t)K * (size_t)e + (size_t)c] = dst;
            m->node_origin[dst] = m->node_count + src;
            if (fracture)
                for (int d = 0; d < D; d++)
                    m->pos0[(size_t)D * (size_t)dst + (size_t)d] = coords[(size_t)D * (size_t)src + (size_t)d];
        }
        m->elem_part[e] = k;
    }
    if (!fracture)
        memcpy(m->pos0 + (size_t)D * (size_t)m->node_count, coords,
               sizeof(double) * (size_t)D * (size_t)node_count);
    for (int i = 0; i < add_nodes; i++) m->node_part[m->node_count + i] = k;
    if (!fracture)
        for (int i = 0; i < add_nodes; i++) m->node_origin[m->node_count + i] = m->node_count + i;
    m->node_count += add_nodes;
    m->elem_count += elem_count;
    m->part_count++;
    return 0;
}

/* A region flag per element, or NULL for the whole part (none given, or
 * every flag set: the same part as a whole fracturing one); *bad is set
 * when no flag is. */
static const uint8_t *region_or_whole(const uint8_t *in_region, int elem_count, int *bad)
{
    *bad = 0;
    if (!in_region) return NULL;
    int inside = 0;
    for (int t = 0; t < elem_count; t++) inside += in_region[t] != 0;
    *bad = inside == 0;
    return inside == elem_count ? NULL : in_region;
}

/* Appends a validated mesh of either dimension as a part: its nodes
 * (joint_region_nodes for a fracturing part), then its joints. */
static int part_add_mesh(fdem_model *m, const double *coords, int node_count,
                         const int32_t *elems, int elem_count, int material_index, int fracture,
                         const uint8_t *in_region, fdem_error *err)
{
    int k = m->part_count, K = m->elem_nodes, bad;
    const uint8_t *region = fracture ? region_or_whole(in_region, elem_count, &bad) : NULL;
    if (fracture && bad) {
        model_error(err, FDEM_ITEM_PART, k,
                    "part %d: its fracture region holds none of its %d %s (by centroid)", k,
                    elem_count, m->dim == 3 ? "tetrahedra" : "triangles");
        return -1;
    }
    part_nodes nodes = {NULL, 0, region != NULL};
    int32_t *corner = NULL;
    if (fracture) {
        corner = malloc(sizeof(int32_t) * (size_t)K * (size_t)elem_count);
        if (!corner) {
            model_error(err, FDEM_ITEM_PART, k, "out of memory for part %d", k);
            return -1;
        }
        if (joint_region_nodes(elems, elem_count, K, region, corner, &nodes.count, k, err)) {
            free(corner);
            return -1;
        }
        nodes.corner = corner;
    }
    int failed = part_append(m, coords, node_count, elems, elem_count, material_index, &nodes, err);
    free(corner);
    if (failed || !fracture) return failed ? -1 : 0;
    return m->dim == 3 ? joint_build_part_3d(m, k, elems, elem_count, region, err)
                       : joint_build_part(m, k, elems, elem_count, region, err);
}

/* A private copy of a mesh's arrays (dim numbers a node, m->elem_nodes
 * an element) to validate and reorient: the caller's mesh stays untouched.
 * Checks the counts first; returns 0, or -1 with err filled. */
static int part_copy_arrays(fdem_model *m, const double *coords, int node_count,
                            const int32_t *elems, int elem_count, double **coords_out,
                            int32_t **elems_out, fdem_error *err)
{
    int k = m->part_count, K = m->elem_nodes;
    *coords_out = NULL;
    *elems_out = NULL;
    if (node_count < K || elem_count < 1) {
        model_error(err, FDEM_ITEM_PART, k, "part %d needs at least %d nodes and 1 %s", k, K,
                    m->dim == 3 ? "tetrahedron" : "triangle");
        return -1;
    }
    size_t coord_bytes = sizeof(double) * (size_t)m->dim * (size_t)node_count;
    size_t elem_bytes = sizeof(int32_t) * (size_t)K * (size_t)elem_count;
    *coords_out = malloc(coord_bytes);
    *elems_out = malloc(elem_bytes);
    if (!*coords_out || !*elems_out) {
        free(*coords_out);
        free(*elems_out);
        *coords_out = NULL;
        *elems_out = NULL;
        model_error(err, FDEM_ITEM_PART, k, "out of memory for part %d", k);
        return -1;
    }
    memcpy(*coords_out, coords, coord_bytes);
    memcpy(*elems_out, elems, elem_bytes);
    return 0;
}

static int add_part_2d(fdem_model *m, const fdem_mesh *mesh, int material_index, int fracture,
                       const uint8_t *in_region, fdem_error *err)
{
    int k = m->part_count;
    fdem_mesh copy = {mesh->node_count, mesh->triangle_count, NULL, NULL};
    if (part_check(m, material_index, fracture, 2, err) ||
        part_copy_arrays(m, mesh->xy, mesh->node_count, mesh->tri, mesh->triangle_count, &copy.xy,
                         &copy.tri, err))
        return -1;
    int failed = fdem_mesh_validate(&copy, NULL, err) ||
                 part_add_mesh(m, copy.xy, copy.node_count, copy.tri, copy.triangle_count,
                               material_index, fracture, in_region, err);
    fdem_mesh_free(&copy);
    return failed ? -1 : k;
}

static int add_part_3d(fdem_model *m, const fdem_tet_mesh *mesh, int material_index, int fracture,
                       const uint8_t *in_region, fdem_error *err)
{
    int k = m->part_count;
    if (part_check(m, material_index, fracture, 3, err)) return -1;
    fdem_tet_mesh copy = {mesh->node_count, mesh->tet_count, NULL, NULL};
    if (part_copy_arrays(m, mesh->xyz, mesh->node_count, mesh->tet, mesh->tet_count, &copy.xyz,
                         &copy.tet, err))
        return -1;
    int failed = fdem_tet_mesh_validate(&copy, NULL, err) ||
                 part_add_mesh(m, copy.xyz, copy.node_count, copy.tet, copy.tet_count,
                               material_index, fracture, in_region, err);
    fdem_tet_mesh_free(&copy);
    return failed ? -1 : k;
}

int fdem_add_part(fdem_model *m, const fdem_mesh *mesh, int material_index, int fracture,
                  fdem_error *err)
{
    return add_part_2d(m, mesh, material_index, fracture, NULL, err);
}

int fdem_add_part_3d(fdem_model *m, const fdem_tet_mesh *mesh, int material_index, int fracture,
                     fdem_error *err)
{
    return add_part_3d(m, mesh, material_index, fracture, NULL, err);
}

int fdem_add_part_region(fdem_model *m, const fdem_mesh *mesh, int material_index,
                         const uint8_t *in_region, fdem_error *err)
{
    if (!in_region) {
        model_error(err, FDEM_ITEM_PART, m->part_count, "part %d: no fracture region given",
                    m->part_count);
        return -1;
    }
    return add_part_2d(m, mesh, material_index, 1, in_region, err);
}

int fdem_add_part_region_3d(fdem_model *m, const fdem_tet_mesh *mesh, int material_index,
                            const uint8_t *in_region, fdem_error *err)
{
    if (!in_region) {
        model_error(err, FDEM_ITEM_PART, m->part_count, "part %d: no fracture region given",
                    m->part_count);
        return -1;
    }
    return add_part_3d(m, mesh, material_index, 1, in_region, err);
}

/* A flag per element of part p: some joint joins it (NULL without memory). */
static uint8_t *part_jointed_elements(const fdem_model *m, const part *p)
{
    uint8_t *jointed = calloc((size_t)(p->elem_count ? p->elem_count : 1), 1);
    if (!jointed) return NULL;
    for (int j = 0; j < m->joint_count; j++)
        for (int s = 0; s < 2; s++) {
            int e = m->joint_elem[2 * j + s] - p->elem_begin;
            if (e >= 0 && e < p->elem_count) jointed[e] = 1;
        }
    return jointed;
}

int fdem_set_element_materials(fdem_model *m, int part_index, const int32_t *material_of,
                               fdem_error *err)
{
    if (m->finalized || part_index < 0 || part_index >= m->part_count) {
        model_error(err, FDEM_ITEM_PART, part_index,
                    m->finalized ? "the model is already finalized" : "part %d does not exist",
                    part_index);
        return -1;
    }
    const part *p = &m->parts[part_index];
    uint8_t *jointed = p->region ? part_jointed_elements(m, p) : NULL;
    if (p->region && !jointed) {
        model_error(err, FDEM_ITEM_PART, part_index, "out of memory");
        return -1;
    }
    for (int t = 0; t < p->elem_count; t++) {
        int mat = material_of[t];
        if (mat < 0 || mat >= m->material_count) {
            model_error(err, FDEM_ITEM_PART, part_index,
                        "element %d of part %d refers to material %d, which does not exist", t,
                        part_index, mat);
            free(jointed);
            return -1;
        }
        /* a joint takes its strengths from its elements' materials: in a
         * fracture region only the elements with a joint need them */
        if (p->fracture && !m->materials[mat].def.has_fracture && (!jointed || jointed[t])) {
            model_error(err, FDEM_ITEM_MATERIAL, mat,
                        "part %d fractures, so material %d of its element %d needs fracture "
                        "parameters%s", part_index, mat, t,
                        jointed ? " (the element lies in the fracture region)" : "");
            free(jointed);
            return -1;
        }
    }
    free(jointed);
    for (int t = 0; t < p->elem_count; t++) {
        int e = p->elem_begin + t;
        if (m->dim == 3) m->tet[e].material = material_of[t];
        else m->elem[e].material = material_of[t];
    }
    return 0;
}

int fdem_set_part_velocity_v(fdem_model *m, int part_index, const double *v, fdem_error *err)
{
    if (part_index < 0 || part_index >= m->part_count) {
        model_error(err, FDEM_ITEM_PART, part_index, "part %d does not exist", part_index);
        return -1;
    }
    for (int d = 0; d < m->dim; d++)
        if (!isfinite(v[d])) {
            model_error(err, FDEM_ITEM_PART, part_index, "the velocity of part %d is not finite",
                        part_index);
            return -1;
        }
    for (int d = 0; d < m->dim; d++) m->part_velocity[3 * part_index + d] = v[d];
    if (m->finalized) {
        const part *p = &m->parts[part_index];
        for (int i = p->node_begin; i < p->node_begin + p->node_count; i++)
            for (int d = 0; d < m->dim; d++) m->vel[(size_t)m->dim * (size_t)i + (size_t)d] = v[d];
    }
    return 0;
}

int fdem_set_part_velocity(fdem_model *m, int part_index, double vx, double vy, fdem_error *err)
{
    const double v[3] = {vx, vy, 0};
    return fdem_set_part_velocity_v(m, part_index, v, err);
}

void fdem_set_gravity_v(fdem_model *m, const double *g)
{
    m->gravity[2] = 0;
    for (int d = 0; d < m->dim; d++) m->gravity[d] = g[d];
    memcpy(m->gravity_base, m->gravity, sizeof m->gravity_base);
}

/* A copy of an amplitude table, or NULL (with err filled) if it is bad. */
static double *amplitude_copy(const double *pairs, int count, fdem_item_kind kind, int item,
                              const char *what, fdem_error *err)
{
    int bad = count < 1 || !pairs ? -1 : amplitude_bad_pair(pairs, count);
    if (bad) {
        if (bad < 0)
            model_error(err, kind, item, "%s: an amplitude needs at least one (t, a) pair", what);
        else
            model_error(err, kind, item,
                        "%s: amplitude pair %d is not finite or its time does not exceed the "
                        "time before it", what, bad - 1);
        return NULL;
    }
    double *copy = malloc(sizeof(double) * 2 * (size_t)count);
    if (!copy) model_error(err, kind, item, "%s: out of memory", what);
    else memcpy(copy, pairs, sizeof(double) * 2 * (size_t)count);
    return copy;
}

int fdem_set_gravity_amplitude(fdem_model *m, const double *pairs, int count, fdem_error *err)
{
    double *copy = NULL;
    if (count > 0 && !(copy = amplitude_copy(pairs, count, FDEM_ITEM_NONE, -1, "gravity", err)))
        return -1;
    free(m->gravity_amplitude);
    m->gravity_amplitude = copy;
    m->gravity_amplitude_count = copy ? count : 0;
    return 0;
}

void fdem_set_gravity(fdem_model *m, double gx, double gy)
{
    const double g[3] = {gx, gy, 0};
    fdem_set_gravity_v(m, g);
}

int fdem_add_constraint(fdem_model *m, const fdem_constraint_def *def, fdem_error *err)
{
    int k = m->constraint_count;
    if (m->finalized) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k, "the model is already finalized");
        return -1;
    }
    int D = m->dim, box_ok = 1, value_ok = 1;
    for (int d = 0; d < D; d++) {
        box_ok &= isfinite(def->box[d]) && isfinite(def->box[D + d]) && def->box[d] <= def->box[D + d];
        value_ok &= isfinite(def->value[d]) != 0;
    }
    if (def->select == FDEM_SELECT_BOX && !box_ok) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k,
                    D == 3 ? "constraint %d: box must be [xmin, ymin, zmin, xmax, ymax, zmax] with min <= max"
                           : "constraint %d: box must be [xmin, ymin, xmax, ymax] with min <= max",
                    k);
        return -1;
    }
    if (!value_ok) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k, "constraint %d: value is not finite", k);
        return -1;
    }
    if (def->kind == FDEM_CONSTRAINT_FIX && !def->fix_x && !def->fix_y && !(D == 3 && def->fix_z)) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k,
                    D == 3 ? "constraint %d fixes none of x, y, z" : "constraint %d fixes neither x nor y", k);
        return -1;
    }
    if (def->select == FDEM_SELECT_VERTICES && (def->vertex_count < 1 || !def->vertices)) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k, "constraint %d selects an empty list of vertices", k);
        return -1;
    }
    if (def->only_stage < 0) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k,
                    "constraint %d: only_stage is %d; 0 acts throughout, k + 1 during stage k only",
                    k, def->only_stage);
        return -1;
    }
    if (def->only_stage && def->kind == FDEM_CONSTRAINT_ABSORB) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k,
                    "constraint %d: an absorbing boundary acts throughout, not during one stage", k);
        return -1;
    }
    if (def->bore && def->kind != FDEM_CONSTRAINT_INJECT) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k,
                    "constraint %d: only an injection goes into a bore", k);
        return -1;
    }
    int has_amplitude = def->amplitude != NULL || def->amplitude_count != 0;
    if (has_amplitude && (def->kind == FDEM_CONSTRAINT_FIX || def->kind == FDEM_CONSTRAINT_ABSORB)) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k,
                    "constraint %d: an amplitude scales a velocity, force, pressure, boundary "
                    "stress, traction or injection only", k);
        return -1;
    }
    double *amplitude = NULL;
    char what[32];
    snprintf(what, sizeof what, "constraint %d", k);
    if (has_amplitude &&
        !(amplitude = amplitude_copy(def->amplitude, def->amplitude_count, FDEM_ITEM_CONSTRAINT,
                                     k, what, err)))
        return -1;
    if (grow((void **)&m->constraints, &m->constraint_capacity, k + 1, sizeof *m->constraints)) {
        free(amplitude);
        model_error(err, FDEM_ITEM_CONSTRAINT, k, "out of memory");
        return -1;
    }
    memset(&m->constraints[k], 0, sizeof m->constraints[k]);
    m->constraints[k].def = *def;
    m->constraints[k].amplitude = amplitude;
    m->constraints[k].def.amplitude = amplitude;
    m->constraints[k].def.amplitude_count = amplitude ? def->amplitude_count : 0;
    if (def->kind == FDEM_CONSTRAINT_PRESSURE || def->kind == FDEM_CONSTRAINT_ABSORB ||
        def->kind == FDEM_CONSTRAINT_INJECT)
        m->constraints[k].def.value[1] = m->constraints[k].def.value[2] = 0;
    if (constraint_keep_vertices(&m->constraints[k])) {
        free(amplitude);
        model_error(err, FDEM_ITEM_CONSTRAINT, k, "out of memory");
        return -1;
    }
    if (D == 2) { /* what a 2D caller left in the third component means nothing */
        constraint *c = &m->constraints[k];
        c->def.fix_z = 0;
        c->def.free_z = 1;
        c->def.value[2] = 0;
    }
    m->constraint_count++;
    return k;
}
