/*
 * model.c - the model's life cycle: building (materials, parts, velocities,
 * constraints, gravity), finalizing (lumped mass, element preparation,
 * stable step), the read-only accessors and memory accounting.
 *
 * Lumped mass follows seed eqs 5.4-5.6: every triangle gives rho*A/3 to each
 * of its nodes; the mass matrix is diagonal and no stiffness matrix exists.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* Grows *array (element size `size`) to hold at least `need` items. */
static int grow(void **array, int *capacity, int need, size_t size)
{
    if (need <= *capacity) return 0;
    int cap = *capacity ? *capacity : 16;
    while (cap < need) cap = cap > INT32_MAX / 2 ? need : cap * 2;
    void *p = realloc(*array, (size_t)cap * size);
    if (!p) return -1;
    *array = p;
    *capacity = cap;
    return 0;
}

fdem_model *fdem_model_create(void)
{
    fdem_model *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    nbs_grid_init(&m->contact.grid);
    nbs_pairs_init(&m->contact.pairs);
    return m;
}

void fdem_model_destroy(fdem_model *m)
{
    if (!m) return;
    free(m->pos); free(m->vel); free(m->force); free(m->inv_mass);
    free(m->pos0); free(m->mass); free(m->node_part); free(m->node_origin); free(m->dof_owned);
    free(m->elem); free(m->elem_part); free(m->tri); free(m->elem_h);
    free(m->materials); free(m->parts); free(m->part_velocity);
    free(m->constraints); free(m->cnode); free(m->cdof); free(m->constraint_force_out);
    free(m->joint_node); free(m->joint_damage); free(m->joint_elem); free(m->joint_h);
    free(m->joint_k); free(m->joint_material);
    free(m->elem_joint); free(m->vertex_broken); free(m->elem_viscous);
    contact_free(&m->contact);
    scatter_plan_free(&m->elem_plan);
    scatter_plan_free(&m->joint_plan);
    scatter_plan_free(&m->node_plan);
    free(m);
}

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
        void *p = realloc(*d2[i], sizeof(double) * 2 * (size_t)newcap);
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
    void *p = realloc(m->elem, sizeof(element_hot) * (size_t)newcap);
    if (!p) return -1;
    m->elem = p;
    p = realloc(m->elem_part, sizeof(int32_t) * (size_t)newcap);
    if (!p) return -1;
    m->elem_part = p;
    p = realloc(m->tri, sizeof(int32_t) * 3 * (size_t)newcap);
    if (!p) return -1;
    m->tri = p;
    m->elem_capacity = newcap;
    return 0;
}

int fdem_add_part(fdem_model *m, const fdem_mesh *mesh, int material_index, int fracture,
                  fdem_error *err)
{
    int k = m->part_count;
    if (m->finalized) {
        model_error(err, FDEM_ITEM_PART, k, "the model is already finalized");
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
    /* Validate a private copy: the caller's mesh stays untouched. */
    fdem_mesh copy = {mesh->node_count, mesh->triangle_count, NULL, NULL};
    if (mesh->node_count < 3 || mesh->triangle_count < 1) {
        model_error(err, FDEM_ITEM_PART, k, "part %d needs at least 3 nodes and 1 triangle", k);
        return -1;
    }
    copy.xy = malloc(sizeof(double) * 2 * (size_t)mesh->node_count);
    copy.tri = malloc(sizeof(int32_t) * 3 * (size_t)mesh->triangle_count);
    if (!copy.xy || !copy.tri) {
        fdem_mesh_free(&copy);
        model_error(err, FDEM_ITEM_PART, k, "out of memory for part %d", k);
        return -1;
    }
    memcpy(copy.xy, mesh->xy, sizeof(double) * 2 * (size_t)mesh->node_count);
    memcpy(copy.tri, mesh->tri, sizeof(int32_t) * 3 * (size_t)mesh->triangle_count);
    if (fdem_mesh_validate(&copy, NULL, err)) {
        fdem_mesh_free(&copy);
        return -1;
    }
    /* A fracturing part gives every triangle its own nodes (joints join them). */
    int add_nodes = fracture ? 3 * copy.triangle_count : copy.node_count;
    if (grow((void **)&m->parts, &m->part_capacity, k + 1, sizeof *m->parts) ||
        reserve_nodes(m, m->node_count + add_nodes) ||
        reserve_elements(m, m->elem_count + copy.triangle_count)) {
        fdem_mesh_free(&copy);
        model_error(err, FDEM_ITEM_PART, k, "out of memory for part %d", k);
        return -1;
    }
    double *pv = realloc(m->part_velocity, sizeof(double) * 2 * (size_t)m->part_capacity);
    if (!pv) {
        fdem_mesh_free(&copy);
        model_error(err, FDEM_ITEM_PART, k, "out of memory for part %d", k);
        return -1;
    }
    m->part_velocity = pv;
    m->part_velocity[2 * k] = m->part_velocity[2 * k + 1] = 0;

    part *p = &m->parts[k];
    p->material = material_index;
    p->fracture = fracture;
    p->node_begin = m->node_count;
    p->node_count = add_nodes;
    p->elem_begin = m->elem_count;
    p->elem_count = copy.triangle_count;
    for (int t = 0; t < copy.triangle_count; t++) {
        element_hot *e = &m->elem[m->elem_count + t];
        memset(e, 0, sizeof *e);
        e->material = material_index;
        for (int c = 0; c < 3; c++) {
            int src = copy.tri[3 * t + c];
            int dst = fracture ? m->node_count + 3 * t + c : m->node_count + src;
            e->node[c] = dst;
            m->tri[3 * (m->elem_count + t) + c] = dst;
            m->node_origin[dst] = m->node_count + src;
            if (fracture) {
                m->pos0[2 * dst] = copy.xy[2 * src];
                m->pos0[2 * dst + 1] = copy.xy[2 * src + 1];
            }
        }
        m->elem_part[m->elem_count + t] = k;
    }
    if (!fracture)
        memcpy(m->pos0 + 2 * m->node_count, copy.xy, sizeof(double) * 2 * (size_t)copy.node_count);
    for (int i = 0; i < add_nodes; i++) m->node_part[m->node_count + i] = k;
    if (!fracture)
        for (int i = 0; i < add_nodes; i++) m->node_origin[m->node_count + i] = m->node_count + i;
    m->node_count += add_nodes;
    m->elem_count += copy.triangle_count;
    m->part_count++;
    int failed = fracture && joint_build_part(m, k, copy.tri, copy.triangle_count, err);
    fdem_mesh_free(&copy);
    return failed ? -1 : k;
}

int fdem_set_part_velocity(fdem_model *m, int part_index, double vx, double vy, fdem_error *err)
{
    if (part_index < 0 || part_index >= m->part_count) {
        model_error(err, FDEM_ITEM_PART, part_index, "part %d does not exist", part_index);
        return -1;
    }
    if (!isfinite(vx) || !isfinite(vy)) {
        model_error(err, FDEM_ITEM_PART, part_index, "the velocity of part %d is not finite",
                    part_index);
        return -1;
    }
    m->part_velocity[2 * part_index] = vx;
    m->part_velocity[2 * part_index + 1] = vy;
    if (m->finalized) {
        const part *p = &m->parts[part_index];
        for (int i = p->node_begin; i < p->node_begin + p->node_count; i++) {
            m->vel[2 * i] = vx;
            m->vel[2 * i + 1] = vy;
        }
    }
    return 0;
}

void fdem_set_gravity(fdem_model *m, double gx, double gy)
{
    m->gravity[0] = gx;
    m->gravity[1] = gy;
}

int fdem_add_constraint(fdem_model *m, const fdem_constraint_def *def, fdem_error *err)
{
    int k = m->constraint_count;
    if (m->finalized) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k, "the model is already finalized");
        return -1;
    }
    if (def->select == FDEM_SELECT_BOX &&
        (!isfinite(def->box[0]) || !isfinite(def->box[1]) || !isfinite(def->box[2]) ||
         !isfinite(def->box[3]) || def->box[0] > def->box[2] || def->box[1] > def->box[3])) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k,
                    "constraint %d: box must be [xmin, ymin, xmax, ymax] with min <= max", k);
        return -1;
    }
    if (!isfinite(def->value[0]) || !isfinite(def->value[1])) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k, "constraint %d: value is not finite", k);
        return -1;
    }
    if (def->kind == FDEM_CONSTRAINT_FIX && !def->fix_x && !def->fix_y) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k, "constraint %d fixes neither x nor y", k);
        return -1;
    }
    if (grow((void **)&m->constraints, &m->constraint_capacity, k + 1, sizeof *m->constraints)) {
        model_error(err, FDEM_ITEM_CONSTRAINT, k, "out of memory");
        return -1;
    }
    memset(&m->constraints[k], 0, sizeof m->constraints[k]);
    m->constraints[k].def = *def;
    m->constraint_count++;
    return k;
}

static void lump_masses(fdem_model *m)
{
    memset(m->mass, 0, sizeof(double) * (size_t)m->node_count);
    for (int e = 0; e < m->elem_count; e++) {
        const element_hot *el = &m->elem[e];
        double third = m->materials[el->material].def.density * el->area0 / 3.0;
        for (int c = 0; c < 3; c++) m->mass[el->node[c]] += third;
    }
    for (int i = 0; i < m->node_count; i++) m->inv_mass[i] = 1.0 / m->mass[i];
}

/* Element nodes sit at the start of each 64-byte record, 16 int32 apart. */
static int build_scatter_plans(fdem_model *m)
{
    _Static_assert(sizeof(element_hot) % sizeof(int32_t) == 0, "element records in int32 words");
    if (m->elem_count &&
        scatter_plan_build(&m->elem_plan, m->elem_count,
                           scatter_block_size(m->elem_count, SCATTER_BLOCK_ELEMENTS),
                           m->elem[0].node, sizeof(element_hot) / sizeof(int32_t), 3,
                           m->node_count))
        return -1;
    if (m->joint_count &&
        scatter_plan_build(&m->joint_plan, m->joint_count,
                           scatter_block_size(m->joint_count, SCATTER_BLOCK_JOINTS),
                           m->joint_node, 4, 4, m->node_count))
        return -1;
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
    memcpy(m->pos, m->pos0, sizeof(double) * 2 * (size_t)m->node_count);
    memset(m->force, 0, sizeof(double) * 2 * (size_t)m->node_count);
    for (int k = 0; k < m->part_count; k++) {
        const part *p = &m->parts[k];
        for (int i = p->node_begin; i < p->node_begin + p->node_count; i++) {
            m->vel[2 * i] = m->part_velocity[2 * k];
            m->vel[2 * i + 1] = m->part_velocity[2 * k + 1];
        }
    }
    m->elem_h = malloc(sizeof(double) * (size_t)m->elem_count);
    if (!m->elem_h) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }
    int damped = 0;
    for (int e = 0; e < m->elem_count; e++) {
        element_prepare(m, e);
        damped |= m->elem[e].eta > 0;
    }
    if (damped && !(m->elem_viscous = calloc(3 * (size_t)m->elem_count, sizeof(double)))) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory");
        return -1;
    }
    lump_masses(m);
    if (joint_prepare(m, err)) return -1;
    m->fragments = joint_fragment_count(m);
    if (constraint_select(m, err)) return -1;
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

const int32_t *fdem_triangles(const fdem_model *m) { return m->tri; }

void fdem_element_stress(const fdem_model *m, double *out)
{
    for (int e = 0; e < m->elem_count; e++) element_stress_one(m, e, out + 3 * e);
}

const double *fdem_constraint_forces(const fdem_model *m)
{
    for (int c = 0; c < m->constraint_count; c++) {
        m->constraint_force_out[2 * c] = m->constraints[c].force[0];
        m->constraint_force_out[2 * c + 1] = m->constraints[c].force[1];
    }
    return m->constraint_force_out;
}

int fdem_constraint_node_count(const fdem_model *m, int c)
{
    if (c < 0 || c >= m->constraint_count) return 0;
    return m->constraints[c].entry_count;
}

size_t fdem_memory_estimate(long nodes, long elements, long joints)
{
    size_t per_node = sizeof(double) * (2 * 5 + 2) + sizeof(int32_t) + 1;
    size_t per_elem = sizeof(element_hot) + sizeof(int32_t) * 3 + sizeof(double) * 8 + 1 +
                      2 * 2 * sizeof(int32_t) * 4; /* circles, boxes, body, NBS lists, ~4 pairs */
    size_t per_joint = sizeof(int32_t) * 4 + sizeof(double) * 8;
    return (size_t)nodes * per_node + (size_t)elements * per_elem + (size_t)joints * per_joint;
}

size_t fdem_memory_bytes(const fdem_model *m)
{
    size_t b = sizeof *m;
    b += (size_t)m->node_capacity * (sizeof(double) * (2 * 4 + 2) + sizeof(int32_t));
    b += (size_t)m->node_count * (1 + (m->contact.enabled ? 4 * sizeof(double) : 0));
    b += (size_t)m->elem_capacity * (sizeof(element_hot) + 4 * sizeof(int32_t));
    b += (size_t)m->elem_count * sizeof(double);
    if (m->contact.enabled)
        b += (size_t)m->elem_count * (7 * sizeof(double) + 2 * sizeof(int32_t) + 1) +
             nbs_memory_bytes(&m->contact.grid, &m->contact.pairs);
    b += (size_t)m->joint_count * (6 * sizeof(int32_t) + 2 * sizeof(double));
    if (m->joint_count) b += (size_t)m->elem_count * 3 * sizeof(int32_t);
    b += (size_t)m->cnode_count * (sizeof(int32_t) + 1);
    b += contact_memory_bytes(&m->contact);
    return b;
}
