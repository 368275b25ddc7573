/*
 * joint.h - the joints of fracturing parts, both dimensions: building them
 * between the elements of a part (joint.c in 2D, joint_tet_model.c in 3D),
 * their strengths (joint_strength.c: material, joint sets, Weibull
 * variation), the joint loop of a step over the shared law
 * (kernel/joint_law.h) in joint order on any thread count (joint_sweep.c),
 * the fracture events of the joints that broke (events.c), and what the
 * contact stage and fragment analysis ask of them (which pairs a joint
 * still holds, fragment labels). Calls only the model and the kernels.
 */
#ifndef FDEM_JOINT_H
#define FDEM_JOINT_H

#include "model/model.h"
#include "parallel/scatter_plan.h"

/* What a joint adds to one face's nodes: dim nodes of dim components. */
#define JOINT_FACE_VALUES 9

/* A joint loop's running sums, sums[0 .. 4] of its block: joints that
 * broke, energy stored, dissipated by damage, handed to contact by joints
 * that broke shut, and frictional work. A loop starts from what its block
 * holds and writes back what it reached (joint_sweep.c needs that). */
typedef struct joint_totals {
    int broke;
    double stored, dissipated, handed, friction;
} joint_totals;

static inline joint_totals joint_totals_load(const double sums[SCATTER_SUMS])
{
    return (joint_totals){(int)sums[0], sums[1], sums[2], sums[3], sums[4]};
}

static inline void joint_totals_store(const joint_totals *t, double sums[SCATTER_SUMS])
{
    sums[0] = t->broke;
    sums[1] = t->stored;
    sums[2] = t->dissipated;
    sums[3] = t->handed;
    sums[4] = t->friction;
}


/* Joint j is on an excavated element: it holds nothing (damage 1) but did
 * not break (step/excavation.c). */
static inline int joint_is_excavated(const fdem_model *m, int j)
{
    return !element_is_active(m, m->joint_elem[2 * j]) ||
           !element_is_active(m, m->joint_elem[2 * j + 1]);
}

/* joint.c (the cohesive law itself, joint_softening included: joint_law.h) */
/* The cohesive constants of a joint of strength s at stiffness k. */
static inline joint_law joint_law_of(const joint_strength *s, double k)
{
    return joint_law_make(k, s->tensile_strength, s->cohesion, s->tan_phi, s->energy_I,
                          s->energy_II);
}
/* The central-difference limit of a joint node of mass `mass` held by
 * stiffness k (all its joints, both faces), with a 0.9 margin. */
static inline double joint_spring_dt(double mass, double k)
{
    return 0.9 * 2 * sqrt(mass / (2 * k));
}
/* Adds a 2D joint's in-situ gap (offset: opening then slide at a0, then at
 * a1; joint_prestress.c) to its end gaps d0 and d1, turned into the frame
 * of the current mean face: tangent (tx, ty) of length L, normal (ty, -tx)
 * outward of A. */
static inline void joint_add_offsets_2d(const double offset[4], double tx, double ty, double L,
                                        double d0[2], double d1[2])
{
    double ux = tx / L, uy = ty / L; /* normal (uy, -ux) */
    d0[0] += offset[0] * uy + offset[1] * ux;
    d0[1] += -offset[0] * ux + offset[1] * uy;
    d1[0] += offset[2] * uy + offset[3] * ux;
    d1[1] += -offset[2] * ux + offset[3] * uy;
}
void *joint_build_scratch(size_t bytes, int part_index, fdem_error *err);
int joint_reserve(fdem_model *m, int J, int part_index, fdem_error *err);
/* in_region: NULL, or a flag per element (joints only between two set ones) */
int joint_build_part(fdem_model *m, int part_index, const int32_t *tri, int triangle_count,
                     const uint8_t *in_region, fdem_error *err);
int joint_prepare(fdem_model *m, fdem_error *err);
double joint_stable_dt(const fdem_model *m);
int joint_holds(const fdem_model *m, int a, int b);
void joint_mark_broken_vertices(fdem_model *m);
/* What contact needs to know of the cracks, at each detection: the broken
 * vertices, the copies intact joints join around each, the pieces (piece,
 * joint_fragment_labels) and the vertices of cracks inside one piece;
 * scratch holds 4 node_count int32 (its contents are left undefined). */
void joint_mark_cracks(fdem_model *m, int32_t *piece, int32_t *scratch);
int joint_fan_holds(const fdem_model *m, int a, int b);
int joint_contact_excluded(const fdem_model *m, const int32_t *piece, int a, int b);
/* Body ids for detection (nbs.h: pairs of one body are never listed):
 * body's, but an element of a fracturing part that is not on a crack takes
 * its piece's id, so the pairs joint_contact_excluded would drop for being
 * of one piece off the cracks are never listed. Valid after
 * joint_mark_broken_vertices and joint_fragment_labels (piece). */
void joint_contact_bodies(const fdem_model *m, const int32_t *piece, const int32_t *body,
                          int32_t *out);
int joint_fragment_labels(const fdem_model *m, int32_t *label);
int joint_forces(fdem_model *m);
void joint_forces_range_2d(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS]);
int joint_forces_one_2d(fdem_model *m, int j, joint_totals *t, double fa[JOINT_FACE_VALUES]);
int joint_fragment_count(const fdem_model *m);
/* joint_prestress.c: the in-situ gaps of the joints of stressed fracturing
 * parts (joint_offset), and their forces and energy at rest for the
 * energy reference at t = 0 */
int joint_prestress_prepare(fdem_model *m, fdem_error *err);
double joint_prestress_rest_forces(fdem_model *m);
/* events.c: the fracture events of the joints that broke in this step's
 * joint loop (joint_broke), appended in joint order; -1 without memory */
int events_collect(fdem_model *m, int broke);
size_t events_checkpoint_size(const fdem_model *m);
void events_checkpoint_write(const fdem_model *m, unsigned char *p);
int events_checkpoint_read(fdem_model *m, const unsigned char *p, int64_t count);
/* joint_strength.c: every joint's strength (material, joint set, variation) */
int joint_strengths_assign(fdem_model *m, fdem_error *err);
/* the joint set joint j lies on (the last that names its face), or -1 */
int joint_set_index(const fdem_model *m, int j);
void joint_sets_free(fdem_model *m);
double weibull_factor(uint64_t seed, uint64_t index, double modulus);
/* joint_region.c: fracture in a region. The node (0-based within the part)
 * of each of the K elem_count corners of a part's elements: one per class
 * of a vertex's corners joined through faces without a joint (in_region
 * NULL: every element keeps its own, node K t + c); *node_count their
 * number. 0, or -1 with err filled. */
int joint_region_nodes(const int32_t *elems, int elem_count, int K, const uint8_t *in_region,
                       int32_t *corner_node, int *node_count, int part_index, fdem_error *err);
/* model.elem_piece0 when some part fractures in a region (at finalize). */
int joint_region_pieces(fdem_model *m, fdem_error *err);
/* Contact detection's body per element (contact.c set a fracturing part's
 * to part_count + e): a region's elements with no vertex on a joint get
 * their part's number. 0, or -1 without memory. */
int joint_region_bodies(const fdem_model *m, int32_t *body);
/* joint_tet_model.c: the 3D geometry of joints (6 nodes, a face each) */
int joint_build_part_3d(fdem_model *m, int part_index, const int32_t *tet, int tet_count,
                        const uint8_t *in_region, fdem_error *err);
double joint_stable_dt_3d(const fdem_model *m);
void joint_forces_range_3d(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS]);
int joint_forces_one_3d(fdem_model *m, int j, joint_totals *t, double fa[JOINT_FACE_VALUES]);


/* joint_sweep.c. A joint loop (range_fn) continues the running sums it is
 * handed, so that a block walked in several pieces sums as if in one;
 * one_fn computes joint j alike, continuing the running sums t, but hands
 * back face A's share fa (face A gets +fa, face B -fa) instead of adding
 * it, returning 0 when nothing is to be added (the joint is broken or
 * degenerate). */
typedef int (*joint_one_fn)(fdem_model *m, int j, joint_totals *t,
                            double fa[JOINT_FACE_VALUES]);
int joint_sweep_init(joint_sweep *s, int joint_count);
void joint_sweep_free(joint_sweep *s);
void joint_sweep_run(fdem_model *m, scatter_block_fn range_fn, joint_one_fn one_fn,
                     double totals[SCATTER_SUMS]);
size_t joint_sweep_bytes(const joint_sweep *s);

#endif
