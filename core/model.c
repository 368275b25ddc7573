/*
 * model.c - the model's life cycle: building (materials, parts, velocities,
 * constraints, gravity), finalizing (lumped mass, element preparation,
 * stable step), the read-only accessors and memory accounting.
 *
 * Lumped mass follows seed eqs 5.4-5.6: every triangle gives rho*A/3 to each
 * of its nodes (a tetrahedron rho*V/4); the mass matrix is diagonal and no
 * stiffness matrix exists.
 *
 * Both dimensions share this file: a part is node coordinates (dim a node)
 * and element node lists (elem_nodes an element) whatever its dimension;
 * only validating the mesh and preparing the element differ.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amplitude.h"
#include "mesh_3d.h"
#include "model.h"

void model_error(fdem_error *err, fdem_item_kind kind, int item, const char *fmt, ...)
{
    if (!err) return;
    err->kind = kind;
    err->item = item;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
}

int model_reserve(void **array, size_t *capacity, size_t need, size_t size, size_t first)
{
    if (need <= *capacity) return 0;
    size_t cap = *capacity ? *capacity : first;
    while (cap < need) cap *= 2;
    void *p = realloc(*array, cap * size);
    if (!p) return -1;
    *array = p;
    *capacity = cap;
    return 0;
}

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
    free(m->joint_node); free(m->joint_damage); free(m->joint_elem); free(m->joint_h);
    free(m->joint_slip); free(m->joint_k); free(m->joint_strength_of); free(m->joint_strengths);
    joint_sets_free(m);
    free(m->elem_joint); free(m->vertex_broken); free(m->elem_viscous); free(m->fixed_force);
    free(m->stress0_defs); free(m->elem_stress0);
    free(m->joint_fracture); free(m->joint_broke); free(m->events);
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

/* Appends a validated mesh as part k: node coordinates (dim a node) and
 * element node lists (elem_nodes an element). A fracturing part gives every
 * element its own nodes (joints join them). */
static int part_append(fdem_model *m, const double *coords, int node_count, const int32_t *elems,
                       int elem_count, int material_index, int fracture, fdem_error *err)
{
    int k = m->part_count, D = m->dim, K = m->elem_nodes;
    int add_nodes = fracture ? K * elem_count : node_count;
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
    p->material = material_index;
    p->fracture = fracture;
    p->stressed = 0;
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
            int dst = fracture ? m->node_count + K * t + c : m->node_count + src;
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

int fdem_add_part(fdem_model *m, const fdem_mesh *mesh, int material_index, int fracture,
                  fdem_error *err)
{
    int k = m->part_count;
    fdem_mesh copy = {mesh->node_count, mesh->triangle_count, NULL, NULL};
    if (part_check(m, material_index, fracture, 2, err) ||
        part_copy_arrays(m, mesh->xy, mesh->node_count, mesh->tri, mesh->triangle_count, &copy.xy,
                         &copy.tri, err))
        return -1;
    int failed = fdem_mesh_validate(&copy, NULL, err) ||
                 part_append(m, copy.xy, copy.node_count, copy.tri, copy.triangle_count,
                             material_index, fracture, err) ||
                 (fracture && joint_build_part(m, k, copy.tri, copy.triangle_count, err));
    fdem_mesh_free(&copy);
    return failed ? -1 : k;
}

int fdem_add_part_3d(fdem_model *m, const fdem_tet_mesh *mesh, int material_index, int fracture,
                     fdem_error *err)
{
    int k = m->part_count;
    if (part_check(m, material_index, fracture, 3, err)) return -1;
    fdem_tet_mesh copy = {mesh->node_count, mesh->tet_count, NULL, NULL};
    if (part_copy_arrays(m, mesh->xyz, mesh->node_count, mesh->tet, mesh->tet_count, &copy.xyz,
                         &copy.tet, err))
        return -1;
    int failed = fdem_tet_mesh_validate(&copy, NULL, err) ||
                 part_append(m, copy.xyz, copy.node_count, copy.tet, copy.tet_count,
                             material_index, fracture, err) ||
                 (fracture && joint_build_part_3d(m, k, copy.tet, copy.tet_count, err));
    fdem_tet_mesh_free(&copy);
    return failed ? -1 : k;
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
    for (int t = 0; t < p->elem_count; t++) {
        int mat = material_of[t];
        if (mat < 0 || mat >= m->material_count) {
            model_error(err, FDEM_ITEM_PART, part_index,
                        "element %d of part %d refers to material %d, which does not exist", t,
                        part_index, mat);
            return -1;
        }
        if (p->fracture && !m->materials[mat].def.has_fracture) {
            model_error(err, FDEM_ITEM_MATERIAL, mat,
                        "part %d fractures, so material %d of its element %d needs fracture "
                        "parameters", part_index, mat, t);
            return -1;
        }
    }
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
    int has_amplitude = def->amplitude != NULL || def->amplitude_count != 0;
    if (has_amplitude && (def->kind == FDEM_CONSTRAINT_FIX || def->kind == FDEM_CONSTRAINT_ABSORB)) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k,
                    "constraint %d: an amplitude scales a velocity, force or pressure only", k);
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
    if (def->kind == FDEM_CONSTRAINT_PRESSURE || def->kind == FDEM_CONSTRAINT_ABSORB)
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

/* rho A / 3 to each node of a triangle, rho V / 4 to each of a tetrahedron. */
static void lump_masses(fdem_model *m)
{
    memset(m->mass, 0, sizeof(double) * (size_t)m->node_count);
    const int K = m->elem_nodes;
    for (int e = 0; e < m->elem_count; e++) {
        double share = m->materials[element_material(m, e)].def.density * element_size0(m, e) / K;
        const int32_t *n = m->elem_node + (size_t)K * (size_t)e;
        for (int c = 0; c < K; c++) m->mass[n[c]] += share;
    }
    for (int i = 0; i < m->node_count; i++) m->inv_mass[i] = 1.0 / m->mass[i];
}

/* Shrinks an array grown by doubling to what it holds: the node and
 * element arrays are built part by part, so up to half of them was never
 * used (a fracturing 3D block of 1e4 tetrahedra: 270 of 3086 bytes an
 * element). Keeps the block when the system will not move it. */
static void fit_array(void **array, size_t bytes)
{
    void *p = realloc(*array, bytes ? bytes : 1);
    if (p) *array = p;
}

static void fit_model_arrays(fdem_model *m)
{
    const size_t D = (size_t)m->dim, N = (size_t)m->node_count, E = (size_t)m->elem_count;
    void **by_dim[] = {(void **)&m->pos, (void **)&m->vel, (void **)&m->force, (void **)&m->pos0};
    for (size_t i = 0; i < sizeof by_dim / sizeof by_dim[0]; i++)
        fit_array(by_dim[i], sizeof(double) * D * N);
    fit_array((void **)&m->inv_mass, sizeof(double) * N);
    fit_array((void **)&m->mass, sizeof(double) * N);
    fit_array((void **)&m->node_part, sizeof(int32_t) * N);
    fit_array((void **)&m->node_origin, sizeof(int32_t) * N);
    m->node_capacity = m->node_count;
    if (m->dim == 3) fit_array((void **)&m->tet, sizeof(tet_hot) * E);
    else fit_array((void **)&m->elem, sizeof(element_hot) * E);
    fit_array((void **)&m->elem_part, sizeof(int32_t) * E);
    fit_array((void **)&m->elem_node, sizeof(int32_t) * (size_t)m->elem_nodes * E);
    m->elem_capacity = m->elem_count;
}

/* Element nodes sit at the start of each hot record (16 int32 apart for a
 * triangle, 28 for a tetrahedron). */
static int build_scatter_plans(fdem_model *m)
{
    _Static_assert(sizeof(element_hot) % sizeof(int32_t) == 0, "element records in int32 words");
    _Static_assert(sizeof(tet_hot) % sizeof(int32_t) == 0, "element records in int32 words");
    const int32_t *first = element_nodes(m, 0);
    size_t stride = (m->dim == 3 ? sizeof(tet_hot) : sizeof(element_hot)) / sizeof(int32_t);
    if (m->elem_count &&
        scatter_plan_build(&m->elem_plan, m->elem_count,
                           scatter_block_size(m->elem_count, SCATTER_BLOCK_ELEMENTS), first,
                           stride, m->elem_nodes, m->node_count))
        return -1;
    if (joint_sweep_init(&m->joint_sweep, m->joint_count)) return -1;
    return scatter_plan_build_disjoint(&m->node_plan, m->node_count,
                                       scatter_block_size(m->node_count, SCATTER_BLOCK_NODES));
}

int fdem_model_finalize(fdem_model *m, fdem_error *err)
{
    if (m->finalized) return 0;
    if (m->threads < 1) m->threads = 1;
    if (m->part_count == 0) {
        model_error(err, FDEM_ITEM_NONE, -1, "the model has no parts");
        return -1;
    }
    const size_t D = (size_t)m->dim;
    fit_model_arrays(m);
    memcpy(m->pos, m->pos0, sizeof(double) * D * (size_t)m->node_count);
    memset(m->force, 0, sizeof(double) * D * (size_t)m->node_count);
    for (int k = 0; k < m->part_count; k++) {
        const part *p = &m->parts[k];
        for (int i = p->node_begin; i < p->node_begin + p->node_count; i++)
            for (size_t d = 0; d < D; d++) m->vel[D * (size_t)i + d] = m->part_velocity[3 * k + (int)d];
    }
    m->elem_h = malloc(sizeof(double) * (size_t)m->elem_count);
    if (!m->elem_h) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }
    int damped = 0;
    for (int e = 0; e < m->elem_count; e++) {
        if (element_prepare(m, e, err)) return -1;
        damped |= element_eta(m, e) > 0;
    }
    if (initial_stress_prepare(m, err)) return -1;
    if (damped && !(m->elem_viscous = calloc((size_t)model_stress_comps(m) * (size_t)m->elem_count,
                                             sizeof(double)))) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }
    lump_masses(m);
    if (joint_prepare(m, err)) return -1;
    m->fragments = joint_fragment_count(m);
    if (contact_init(m, err)) return -1;
    if (build_scatter_plans(m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }

    double dt = INFINITY;
    for (int e = 0; e < m->elem_count; e++) {
        double de = element_stable_dt(m, e);
        if (de < dt) dt = de;
    }
    dt = fmin(dt, contact_stable_dt(m));
    m->stable_dt = fmin(dt, joint_stable_dt(m));
    /* After the stable step, so a case refused for its constraints can
     * still be told whether its dt would do (one answer, every problem). */
    constraint_set_time(m, 0);
    if (constraint_select(m, err)) return -1;
    if (boundary_load_select(m, err)) return -1;
    if (fixed_parts_prepare(m, err)) return -1;
    m->dt = m->stable_dt * 0.5;
    m->dt_prev = 0;
    m->finalized = 1;
    energy_initial(m);
    return 0;
}

/* ------------------------------------------------------------ accessors */

double fdem_stable_dt(const fdem_model *m) { return m->stable_dt; }
void fdem_set_dt(fdem_model *m, double dt) { if (dt > 0 && isfinite(dt)) m->dt = dt; }
double fdem_get_dt(const fdem_model *m) { return m->dt; }
void fdem_set_threads(fdem_model *m, int threads) { m->threads = threads > 1 ? threads : 1; }
int fdem_get_threads(const fdem_model *m) { return m->threads > 1 ? m->threads : 1; }
int64_t fdem_get_step(const fdem_model *m) { return m->step; }
double fdem_get_time(const fdem_model *m) { return m->time; }

fdem_counts fdem_get_counts(const fdem_model *m)
{
    fdem_counts c = {0};
    c.dimension = m->dim;
    c.nodes = m->node_count;
    c.elements = m->elem_count;
    c.parts = m->part_count;
    c.materials = m->material_count;
    c.constraints = m->constraint_count;
    c.joints = m->joint_count;
    c.broken_joints = m->broken_joints;
    c.fragments = m->fragments;
    c.contacts = m->contact.touching;
    c.contact_pairs = (int)m->contact.pairs.count;
    c.detections = m->contact.detections;
    return c;
}

const double *fdem_positions(const fdem_model *m) { return m->pos; }
const double *fdem_initial_positions(const fdem_model *m) { return m->pos0; }
const double *fdem_velocities(const fdem_model *m) { return m->vel; }
const double *fdem_node_masses(const fdem_model *m) { return m->mass; }
const int32_t *fdem_node_parts(const fdem_model *m) { return m->node_part; }
const int32_t *fdem_element_parts(const fdem_model *m) { return m->elem_part; }
const int32_t *fdem_joints(const fdem_model *m) { return m->joint_count ? m->joint_node : NULL; }
const double *fdem_joint_damage(const fdem_model *m) { return m->joint_count ? m->joint_damage : NULL; }

int fdem_nodes_per_element(const fdem_model *m) { return m->elem_nodes; }
const int32_t *fdem_element_nodes(const fdem_model *m) { return m->elem_node; }
const int32_t *fdem_triangles(const fdem_model *m) { return m->dim == 2 ? m->elem_node : NULL; }
const int32_t *fdem_tetrahedra(const fdem_model *m) { return m->dim == 3 ? m->elem_node : NULL; }
int fdem_stress_components(const fdem_model *m) { return model_stress_comps(m); }

void fdem_element_stress(const fdem_model *m, double *out)
{
    size_t comps = (size_t)model_stress_comps(m);
    for (int e = 0; e < m->elem_count; e++) element_stress_one(m, e, out + comps * (size_t)e);
}

const double *fdem_constraint_forces(const fdem_model *m)
{
    for (int c = 0; c < m->constraint_count; c++)
        for (int d = 0; d < m->dim; d++)
            m->constraint_force_out[m->dim * c + d] = m->constraints[c].force[d];
    return m->constraint_force_out;
}

int fdem_constraint_node_count(const fdem_model *m, int c)
{
    if (c < 0 || c >= m->constraint_count) return 0;
    return m->constraints[c].entry_count;
}

/* ------------------------------------------------------- memory, priced
 *
 * fdem_memory_estimate*() must be an upper bound of a model's peak: what
 * fdem_memory_bytes() reports once it has stepped long enough for its
 * contacts to develop, and the scratch of finalize and of each detection
 * (measured with valgrind massif). The daemon admits a case on it, and a
 * low figure is an OOM kill on a loaded server. Counts are all it knows, so whatever a case may or may not have
 * (in-situ stress, damping, varied joint strengths, broken joints) is priced
 * as if it had it. The figures name the arrays they pay for; the contact
 * lists grow by doubling, so they are priced at the largest capacity per
 * element the bundled examples reach in 2000 steps, rounded up
 * (tests/unit/test_memory.c holds the estimate against the examples). */

/* What one dimension's records weigh, and its contact lists' capacities per
 * contact element: candidate pairs kept, the near pairs walked each step,
 * stick-spring sets and the records detection sets them aside in; and per
 * joint the raw NBS list's extra pairs of joined elements, held at each
 * detection until they are dropped (contact_drop_joined). */
typedef struct memory_figures {
    size_t D, elem_nodes, stress_comps, hot, slots, nbs_packed;
    double kept_pairs, near_pairs, spring_sets, records, joined_pairs;
} memory_figures;

/* Capacities measured (valgrind massif for the raw list, which is fitted
 * after each detection), per element: 2D kept 1.25 and near 1.25
 * (disc-pile), sets 0.2 (brazilian-disc); 3D kept 31.8, near 7.9, sets 2.0
 * (uniaxial-prism-3d), kept 30 and records 0.24 (sphere-pile); per joint,
 * the raw list: 2D 16.1 (uniaxial-compression; brazilian-disc 9.3,
 * jointed-block 5.5), 3D 62 (brazilian-disc-3d-arc; prism 58.7). Smaller
 * models sit on the first capacities (memory_fixed). */
static const memory_figures memory_2d = {2, 3, 3, sizeof(element_hot), TRI_CONTACT_SLOTS, 0,
                                         2, 2, 0.5, 0.25, 17};
static const memory_figures memory_3d = {3, 4, 6, sizeof(tet_hot), TET_CONTACT_SLOTS, 4,
                                         32, 8, 2, 0.5, 64};

/* pos, vel, force, pos0 (dim each), mass, inv_mass; node_part, node_origin;
 * a fixed part's kept force (dim; fixed_part.c); dof_owned and a constraint
 * entry (node, dofs); a quarter of a loaded
 * boundary facet (nodes, element, dim x dim forces; tunnel measures 0.15 a
 * node); with contact pos_detect, pos_near and the contact force (dim
 * each); with joints vertex_broken */
static size_t memory_node(const memory_figures *f, int contact, int joints)
{
    size_t facet = (f->D + 1) * sizeof(int32_t) + f->D * f->D * sizeof(double);
    return sizeof(double) * (5 * f->D + 2) + 2 * sizeof(int32_t) + 1 + sizeof(int32_t) + 1 +
           facet / 4 + (contact ? 3 * f->D * sizeof(double) : 0) + (joints ? 1 : 0);
}

/* hot record, elem_node, elem_part, elem_h, elem_viscous and elem_stress0
 * (stress_comps each); with joints elem_joint (a slot per face) and the
 * byte the joint sweep's cut needs while it finds each element's owner */
static size_t memory_element(const memory_figures *f, int joints)
{
    return f->hot + (f->elem_nodes + 1) * sizeof(int32_t) + sizeof(double) +
           2 * f->stress_comps * sizeof(double) + (joints ? (f->D + 1) * sizeof(int32_t) + 1 : 0);
}

/* Detection arrays (centre and radius, box, elem_gap; body, piece, active,
 * near_active; in_pair; the NBS grid's heads, 12 bytes measured in 3D, 40
 * in 2D, and in 3D its packed copy of the spheres, nbs_packed doubles) and
 * the pair lists at their capacities: a kept pair is two element
 * ids and its spring_of, a near_pair 24 bytes, a set slots doubles and a
 * free-list slot, a record a contact_record. */
static size_t memory_contact_element(const memory_figures *f)
{
    double set = (double)(f->slots * sizeof(double) + sizeof(int32_t));
    double lists = f->kept_pairs * 3 * sizeof(int32_t) +
                   f->near_pairs * (sizeof(double) + 4 * sizeof(int32_t)) + f->spring_sets * set +
                   f->records * (double)sizeof(contact_record);
    return (3 * f->D + 2 + f->nbs_packed) * sizeof(double) + 4 * sizeof(int32_t) + 1 +
           10 * sizeof(int32_t) + (size_t)lists;
}

/* joint_node (2 dim), joint_elem (2); damage, fracture, h, k; joint_broke;
 * the slip its dim points keep; joint_strength_of, a strength record of its own (varied strengths), its
 * fracture event (in a list that grows by doubling), the raw NBS list's
 * pairs of joined elements (two element ids each), and on several threads
 * the joint sweep's slots, at most one per 8 joints (a face's forces, its
 * joint and face, a flag; its joint's id and two slot ids) */
static size_t memory_joint(const memory_figures *f)
{
    size_t slot = JOINT_FACE_VALUES * sizeof(double) + 4 * sizeof(int32_t) + 1;
    return (2 * f->D + 2) * sizeof(int32_t) + 4 * sizeof(double) + 1 + sizeof(int32_t) +
           f->D * sizeof(joint_slip) + sizeof(joint_strength) + 2 * sizeof(fdem_event) +
           (size_t)(f->joined_pairs * 2 * sizeof(int32_t)) + (slot + 7) / 8;
}

/* The model record, parts, materials and constraints (a few KB), the event
 * list's first 64; with contact the first capacities of the lists that grow
 * by doubling (raw pairs, spring_of and near pairs; spring sets and
 * records), and the NBS grid's row and cell tables */
static size_t memory_fixed(const memory_figures *f, int contact)
{
    size_t b = sizeof(fdem_model) + 8192 + 64 * sizeof(fdem_event);
    if (contact)
        b += NBS_FIRST_PAIRS * 2 * sizeof(int32_t) +
             CONTACT_FIRST_ROWS * (sizeof(int32_t) + sizeof(double) + 4 * sizeof(int32_t)) +
             CONTACT_FIRST_SETS * (f->slots * sizeof(double) + sizeof(int32_t) + sizeof(contact_record)) +
             16384;
    return b;
}

/* Finalize's scratch, freed before the first step: the scatter plans'
 * colour mask (a uint64_t a node) and, with pressures or dashpots, every
 * element facet's sorted key (20 bytes) twice over (qsort's merge buffer):
 * tunnel's model peaks at 1.7 times what it holds after. A model with
 * contact builds them while its pair lists are still small, within what
 * memory_contact_element prices for those. */
static size_t memory_finalize(const memory_figures *f, long nodes, long elements)
{
    return (size_t)nodes * sizeof(uint64_t) + (size_t)elements * (f->D + 1) * 2 * 5 * sizeof(int32_t);
}

static size_t memory_estimate(const memory_figures *f, long nodes, long elements, long joints,
                              int parts)
{
    int contact = parts > 1 || joints > 0;
    size_t elem = memory_element(f, joints > 0) + (contact ? memory_contact_element(f) : 0);
    return memory_fixed(f, contact) + (size_t)nodes * memory_node(f, contact, joints > 0) +
           (size_t)elements * elem + (size_t)joints * memory_joint(f) +
           (contact ? 0 : memory_finalize(f, nodes, elements));
}

size_t fdem_memory_estimate(long nodes, long elements, long joints, int parts)
{
    return memory_estimate(&memory_2d, nodes, elements, joints, parts);
}

size_t fdem_memory_estimate_3d(long nodes, long elements, long joints, int parts)
{
    return memory_estimate(&memory_3d, nodes, elements, joints, parts);
}

size_t fdem_memory_estimate_of(const fdem_counts *n)
{
    return n->dimension == 3
               ? fdem_memory_estimate_3d(n->nodes, n->elements, n->joints, n->parts)
               : fdem_memory_estimate(n->nodes, n->elements, n->joints, n->parts);
}

/* A thread's touch lists hold at least CONTACT_FIRST_ROWS rows of each kind
 * once the pairs run threaded (contact.c pair_rows_push): pairs touched with
 * their forces, springs adopted, springs released. */
size_t fdem_memory_per_thread(int dimension)
{
    size_t out = dimension == 3 ? TET_PAIR_OUT : TRI_PAIR_OUT;
    size_t slots = dimension == 3 ? TET_CONTACT_SLOTS : TRI_CONTACT_SLOTS;
    return CONTACT_FIRST_ROWS * (3 * sizeof(long) + (out + slots) * sizeof(double));
}

static size_t scatter_plan_bytes(const scatter_plan *p)
{
    if (!p->color_count) return 0;
    return ((size_t)p->color_count + 1 + (size_t)p->block_count) * sizeof(int32_t) +
           SCATTER_SUMS * (size_t)p->block_count * sizeof(double);
}

size_t fdem_memory_bytes(const fdem_model *m)
{
    size_t b = sizeof *m, D = (size_t)m->dim;
    /* pos, vel, force, pos0, mass, inv_mass; node_part, node_origin */
    b += (size_t)m->node_capacity * (sizeof(double) * (D * 4 + 2) + 2 * sizeof(int32_t));
    /* dof_owned; vertex_broken with joints; the contact's pos_detect, pos_near, force */
    b += (size_t)m->node_count * (1 + (m->joint_count ? 1 : 0) +
                                  (m->contact.enabled ? 3 * D * sizeof(double) : 0));
    b += (size_t)m->elem_capacity * ((m->dim == 3 ? sizeof(tet_hot) : sizeof(element_hot)) +
                                     ((size_t)m->elem_nodes + 1) * sizeof(int32_t));
    b += (size_t)m->elem_count * sizeof(double);
    for (int k = 0; k < m->part_count && m->fixed_force; k++) /* fixed_part.c */
        if (m->parts[k].fixed) b += sizeof(double) * D * (size_t)m->parts[k].node_count;
    size_t stress = (size_t)m->elem_count * (size_t)model_stress_comps(m) * sizeof(double);
    if (m->elem_stress0) b += stress;
    if (m->elem_viscous) b += stress;
    /* spheres (centre, radius), boxes (2 dim), elem_gap; body, piece,
     * active, near_active; in_pair */
    if (m->contact.enabled)
        b += (size_t)m->elem_count * ((3 * D + 2) * sizeof(double) + 4 * sizeof(int32_t) + 1) +
             (m->dim == 3 ? nbs_memory_bytes_3d(&m->contact.grid3, &m->contact.pairs)
                          : nbs_memory_bytes(&m->contact.grid, &m->contact.pairs));
    /* joints: 2 dim nodes and 2 elements; damage, fracture, h, k; broke;
     * the slip of its dim points; strength_of; elem_joint */
    b += (size_t)m->joint_count * ((2 * (size_t)D + 2) * sizeof(int32_t) + 4 * sizeof(double) + 1 +
                                   D * sizeof(joint_slip));
    if (m->joint_strength_of) b += (size_t)m->joint_count * sizeof(int32_t);
    b += (size_t)m->event_capacity * sizeof(fdem_event);
    if (m->joint_count) b += (size_t)m->elem_count * ((size_t)D + 1) * sizeof(int32_t);
    b += (size_t)m->joint_strength_count * sizeof(joint_strength);
    /* constraint entries (node, dofs), their records and forces out */
    b += (size_t)m->cnode_count * (sizeof(int32_t) + 1);
    b += (size_t)m->constraint_capacity * sizeof(constraint) +
         (size_t)m->constraint_count * D * sizeof(double);
    b += (size_t)m->part_capacity * (sizeof(part) + 3 * sizeof(double)) +
         (size_t)m->material_capacity * sizeof(material);
    /* boundary facets of pressures and dashpots: nodes, element, forces */
    b += (size_t)m->bfacet_count * ((D + 1) * sizeof(int32_t) + D * D * sizeof(double));
    b += scatter_plan_bytes(&m->elem_plan) + joint_sweep_bytes(&m->joint_sweep) +
         scatter_plan_bytes(&m->node_plan);
    b += contact_memory_bytes(&m->contact);
    return b;
}
