/*
 * memory.c - memory, priced: the estimate a case is admitted on, and the
 * bytes a model holds.
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
 * (tests/unit/test_memory.c holds the estimate against the examples).
 */
#include <stddef.h>

#include "contact/contact.h"
#include "joint/joint.h"
#include "fluid/fluid.h"
#include "model/model.h"
#include "nbs/nbs.h"
#include "build.h"


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
 * each) and a graded mesh's travel weight; with joints vertex_broken and vertex_root, and with both the
 * shut tables (contact_shut.c: first copy, tolerance, shut flag) */
static size_t memory_node(const memory_figures *f, int contact, int joints)
{
    size_t facet = (f->D + 1) * sizeof(int32_t) + f->D * f->D * sizeof(double);
    return sizeof(double) * (5 * f->D + 2) + 2 * sizeof(int32_t) + 1 + sizeof(int32_t) + 1 +
           facet / 4 + (contact ? (3 * f->D + 1) * sizeof(double) : 0) +
           (joints ? 1 + sizeof(int32_t) : 0) +
           (joints && contact ? sizeof(int32_t) + sizeof(double) + 1 : 0);
}

/* hot record, elem_node, elem_part, elem_h, elem_viscous and elem_stress0
 * (stress_comps each); with joints elem_joint (a slot per face) and the
 * byte the joint sweep's cut needs while it finds each element's owner */
static size_t memory_element(const memory_figures *f, int joints)
{
    return f->hot + (f->elem_nodes + 1) * sizeof(int32_t) + sizeof(double) +
           2 * f->stress_comps * sizeof(double) + (joints ? (f->D + 1) * sizeof(int32_t) + 1 : 0);
}

/* Detection arrays (centre and radius, box, elem_gap, a graded mesh's
 * skin; body, piece,
 * detect_body, active, near_active; in_pair; the NBS grid's heads, 12 bytes measured in 3D, 40
 * in 2D, and in 3D its packed copy of the spheres, nbs_packed doubles) and
 * the pair lists at their capacities: a kept pair is two element
 * ids and its spring_of, a near_pair 24 bytes, a set slots doubles and a
 * free-list slot, a record a contact_record. A fracturing body's detection
 * takes the bulk path (nbs_classes.c): its member, next and body ids, a
 * gathered sphere (4 doubles) and about 4 cell heads and stamps. */
static size_t memory_contact_element(const memory_figures *f)
{
    double set = (double)(f->slots * sizeof(double) + sizeof(int32_t));
    double lists = f->kept_pairs * 3 * sizeof(int32_t) +
                   f->near_pairs * (sizeof(double) + 4 * sizeof(int32_t)) + f->spring_sets * set +
                   f->records * (double)sizeof(contact_record);
    /* + 1: on threads, the owner of each element's nodes (contact_rows.c) */
    return (3 * f->D + 3 + f->nbs_packed + 4) * sizeof(double) + 5 * sizeof(int32_t) + 1 + 1 +
           (10 + 3 + 4) * sizeof(int32_t) + (size_t)lists;
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
    size_t elem = memory_element(f, joints > 0) + (contact ? memory_contact_element(f) : 0) +
                  /* elem_shut, elem_topo, elem_due, vertex_start, elem_first;
                   * contact_breaks.c: a count, the next pieces, a search body, a mark */
                  (contact && joints > 0 ? 2 + (2 + f->elem_nodes) * sizeof(int32_t) +
                                               3 * sizeof(int32_t) + 1
                                         : 0);
    /* contact_breaks.c: what the last detection saw of each joint and vertex */
    size_t seen = contact && joints > 0 ? (size_t)joints + (size_t)nodes : 0;
    return memory_fixed(f, contact) + (size_t)nodes * memory_node(f, contact, joints > 0) +
           (size_t)elements * elem + (size_t)joints * memory_joint(f) + seen +
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
 * once the pairs run threaded (contact_rows.c pair_rows_grow): pairs touched
 * with their forces, springs adopted, springs released; a row of numbers
 * keeps its last number again. */
size_t fdem_memory_per_thread(int dimension)
{
    size_t out = dimension == 3 ? TET_PAIR_OUT : TRI_PAIR_OUT;
    size_t slots = dimension == 3 ? TET_CONTACT_SLOTS : TRI_CONTACT_SLOTS;
    return CONTACT_FIRST_ROWS * (3 * sizeof(long) + (out + slots + 2) * sizeof(double));
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
    /* dof_owned; vertex_broken and vertex_root with joints; the contact's
     * pos_detect, pos_near, force */
    b += (size_t)m->node_count * (1 + (m->joint_count ? 1 + sizeof(int32_t) : 0) +
                                  (m->contact.enabled ? 3 * D * sizeof(double) : 0));
    /* contact_shut.c: first copy, tolerance, shut; per element shut and due;
     * contact_near.c: per element the start of its vertex pairs (from the
     * first rebuild of a jointed model's near list) */
    if (m->contact.shut_first)
        b += (size_t)m->node_count * (sizeof(int32_t) + sizeof(double) + 1) +
             (size_t)m->elem_count * (1 + sizeof(int32_t));
    if (m->contact.vertex_start) b += ((size_t)m->elem_count + 1) * sizeof(int32_t);
    /* contact_travel.c: a graded mesh's skins and travel weights */
    if (m->contact.skin)
        b += ((size_t)m->elem_count + (size_t)m->node_count) * sizeof(double);
    b += (size_t)m->elem_capacity * ((m->dim == 3 ? sizeof(tet_hot) : sizeof(element_hot)) +
                                     ((size_t)m->elem_nodes + 1) * sizeof(int32_t));
    b += (size_t)m->elem_count * sizeof(double);
    for (int k = 0; k < m->part_count && m->fixed_force; k++) /* fixed_part.c */
        if (m->parts[k].fixed) b += sizeof(double) * D * (size_t)m->parts[k].node_count;
    size_t stress = (size_t)m->elem_count * (size_t)model_stress_comps(m) * sizeof(double);
    if (m->elem_stress0) b += stress;
    if (m->elem_viscous) b += stress;
    /* spheres (centre, radius), boxes (2 dim), elem_gap; body, piece,
     * detect_body, active, near_active; in_pair */
    if (m->contact.enabled)
        b += (size_t)m->elem_count * ((3 * D + 2) * sizeof(double) + 5 * sizeof(int32_t) + 1) +
             (m->dim == 3 ? nbs_memory_bytes_3d(&m->contact.grid3, &m->contact.pairs)
                          : nbs_memory_bytes(&m->contact.grid, &m->contact.pairs)) +
             nbs_classes_memory_bytes(&m->contact.classes);
    /* joints: 2 dim nodes and 2 elements; damage, fracture, h, k; broke;
     * the slip of its dim points; strength_of; elem_joint */
    b += (size_t)m->joint_count * ((2 * (size_t)D + 2) * sizeof(int32_t) + 4 * sizeof(double) + 1 +
                                   D * sizeof(joint_slip));
    if (m->joint_strength_of) b += (size_t)m->joint_count * sizeof(int32_t);
    b += (size_t)m->event_capacity * sizeof(fdem_event);
    if (m->joint_count) b += (size_t)m->elem_count * ((size_t)D + 1) * sizeof(int32_t);
    if (m->elem_piece0) b += (size_t)m->elem_count * sizeof(int32_t);
    b += (size_t)m->joint_strength_count * sizeof(joint_strength);
    /* constraint entries (node, dofs), their records and forces out */
    b += (size_t)m->cnode_count * (sizeof(int32_t) + 1);
    b += (size_t)m->constraint_capacity * sizeof(constraint) +
         (size_t)m->constraint_count * D * sizeof(double);
    b += (size_t)m->part_capacity * (sizeof(part) + 3 * sizeof(double)) +
         (size_t)m->material_capacity * sizeof(material);
    /* boundary facets of pressures and dashpots: nodes, element, forces (and
     * with excavations when each opens) */
    b += (size_t)m->bfacet_count * ((D + 1 + (m->bfacet_open != NULL)) * sizeof(int32_t) +
                                    D * D * sizeof(double));
    b += scatter_plan_bytes(&m->elem_plan) + joint_sweep_bytes(&m->joint_sweep) +
         scatter_plan_bytes(&m->node_plan);
    b += contact_memory_bytes(&m->contact);
    /* stages: their lists to excavate and ramps; elem_active, node_frozen */
    b += (size_t)m->stage_capacity * sizeof(run_stage);
    for (int k = 0; k < m->stage_count; k++)
        b += (size_t)m->stages[k].excavate_count * sizeof(int32_t) +
             (size_t)m->stages[k].ramp_count * (sizeof(int32_t) + D * sizeof(double));
    if (m->elem_active) b += (size_t)m->elem_count + (size_t)m->node_count;
    b += fluid_memory_bytes(m);
    return b;
}
