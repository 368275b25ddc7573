/*
 * model.h - the engine's one model struct and the internal contract between
 * its stages (mesh, element, contact, constraint, integrator, checkpoint).
 *
 * Layout follows the hot/cold split: what the per-step loops read and write
 * (positions, velocities, forces, inverse masses, the 64-byte element record)
 * sits in contiguous arrays of plain numbers; what only set-up, output and
 * checkpoints touch (initial positions, masses, part ids) lives beside them.
 * A step allocates only to grow the contact pair lists to a new high-water
 * mark.
 */
#ifndef FDEM_MODEL_H
#define FDEM_MODEL_H

#include <stdint.h>

#include "contact_pair.h"
#include "fdem.h"
#include "joint_law.h"
#include "nbs.h"

typedef struct material {
    fdem_material_def def;
    double lambda, mu;   /* Lame constants (plane strain uses the 3D ones) */
    double penalty;      /* resolved: def.penalty or 10 * young */
    double tan_phi;      /* joints: tan(fracture.friction_angle) */
} material;

/* Hot per-element record: exactly one cache line. */
typedef struct element_hot {
    int32_t node[3];     /* counter-clockwise */
    int32_t material;
    double xinv[4];      /* inverse of the initial edge matrix [X1-X0, X2-X0], row-major */
    double area0;        /* initial area */
    double eta;          /* viscous coefficient of damping (Pa s); 0 = none */
} element_hot;

/* Hot per-tetrahedron record (3D models): two cache lines less 16 bytes. */
typedef struct tet_hot {
    int32_t node[4];     /* positive volume */
    int32_t material;
    int32_t unused;
    double xinv[9];      /* inverse of the initial edge matrix [X1-X0, X2-X0, X3-X0], row-major */
    double volume0;      /* initial volume */
    double eta;          /* viscous coefficient of damping (Pa s); 0 = none */
} tet_hot;

/* The cohesive constants a joint reads in the hot loop (joint_strength.c):
 * one per material, one per joint set, one per joint whose strengths were
 * drawn (Weibull variation). A joint holds an index into this table, so
 * heterogeneity costs the joint loop nothing. */
typedef struct joint_strength {
    double tensile_strength, cohesion, tan_phi, energy_I, energy_II;
} joint_strength;

/* A pre-existing discontinuity of a fracturing part: the faces (mesh
 * vertices of the part, dim per face, each sorted, the list sorted) whose
 * joints take params. */
typedef struct joint_set {
    int part;
    fdem_fracture_params params;
    fdem_variation variation;
    int32_t *faces;
    int face_count;
} joint_set;

typedef struct part {
    int material;
    int fracture;
    int stressed;        /* has an in-situ stress (initial_stress.c) */
    int fixed;           /* held still as a whole: its element forces are kept (fixed_part.c) */
    int node_begin, node_count;
    int elem_begin, elem_count;
} part;

/* An in-situ stress as given for a part, until finalize evaluates it per
 * element (initial_stress.c). */
typedef struct initial_stress_def {
    int part;
    double value[6], gradient[6], reference;
} initial_stress_def;

/* One constraint after node selection. Its nodes are entries
 * [entry_begin, entry_begin + entry_count) of model.cnode / model.cdof. */
typedef struct constraint {
    fdem_constraint_def def;
    int entry_begin, entry_count;
    int32_t *vertices;   /* FDEM_SELECT_VERTICES: the owned, sorted copy def.vertices points to */
    double force[3];     /* reaction (fix, velocity), applied (force, pressure) or dashpot
                            (absorb) force of the last step */
    double value_now[3]; /* def.value times the amplitude at the instant this step uses
                            (constraint_set_time); def.value itself without an amplitude */
    double *amplitude;   /* owned copy of def.amplitude (def.amplitude points here) */
    int facet_begin, facet_count; /* PRESSURE, ABSORB: entries of model.bfacet_* */
} constraint;

/* Partial sums a scatter block hands back (see scatter_plan_run below). */
#define SCATTER_SUMS 7
#define SCATTER_MAX 5 /* sums[SCATTER_MAX] and on are maxima, not sums */

/* Blocks of consecutive items (elements, nodes) grouped by colour:
 * blocks of one colour share no node, so threads may run them side by side
 * and add into node arrays without races (scatter_plan.c). */
typedef struct scatter_plan {
    int item_count, block_size, block_count;
    int color_count;         /* 0: no blocks, scatter_plan_run runs the items serially */
    int32_t *color_begin;    /* color_count + 1 offsets into block_order */
    int32_t *block_order;    /* block indices, colour by colour */
    double *block_sum;       /* SCATTER_SUMS partials per block, totalled in block order */
} scatter_plan;

/* The joint loop's plan (joint_sweep.c). Every node's joint forces are
 * added in joint order on any thread count: one thread walks the joints in
 * order; T threads walk T contiguous ranges of them side by side, each
 * adding only into the elements it owns (those whose first joint is its
 * own) and setting aside the forces on the faces of elements an earlier
 * range owns (slots), which their owners add after a barrier. The energy
 * sums are formed per fixed block of joints, in joint order, and totalled
 * in block order, as scatter_plan_run does. */
typedef struct joint_sweep {
    int threads;          /* the thread count the ranges were cut for; 0: none yet */
    int block_size, block_count;
    double *block_sum;    /* SCATTER_SUMS per block */
    int ranges;           /* 1: the whole loop on one thread */
    int32_t *range_block; /* ranges + 1: each range's first block */
    int32_t *cross_begin; /* ranges + 1 offsets into cross_joint */
    int32_t *cross_joint; /* per range, in joint order: its joints with a slot */
    int32_t *cross_slot;  /* 2 per cross joint: the slot of face A's and B's forces, or -1 */
    int32_t *slot_begin;  /* ranges + 1: slots by the range owning their face */
    int32_t *slot_face;   /* per slot: 2 joint + face (0 A, 1 B); joint order within a range */
    double *slot_force;   /* JOINT_FACE_VALUES per slot */
    uint8_t *slot_live;   /* the joint held in this step: its forces are to be added */
} joint_sweep;

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

/* Stick-spring history of one pair of elements lo < hi (contact_history.c):
 * the tangential springs of lo's contactor boundaries against hi, then of
 * hi's against lo, slots of them (contact_pair.h: 6 for triangles, 24 for
 * tetrahedra). A checkpoint stores lo, hi and the slots used, so a 2D record
 * there is 56 bytes as before 3D (contact_record_bytes). */
typedef struct contact_record {
    int32_t lo, hi;
    double slip[CONTACT_SLOTS_MAX];
} contact_record;

/* First capacities of the contact lists that grow by doubling (pair and
 * touch rows, near pairs, spring indices; stick-spring sets and records):
 * a model with contact holds them however few its pairs, and the memory
 * estimate prices them (model.c, memory_fixed and fdem_memory_per_thread). */
#define CONTACT_FIRST_ROWS 1024
#define CONTACT_FIRST_SETS 256

typedef struct contact_state {
    int enabled;             /* some pair of elements can ever touch */
    const struct contact_kernel *kernel; /* the dimension's pair kernel (contact.c) */
    int slots;               /* stick springs per pair */
    int pair_out;            /* numbers a pair evaluation hands back */
    double buffer;           /* added to circle diameters; re-detect after buffer/2 */
    double max_disp2;        /* bound of the squared node displacement since detection,
                                exact once past the limit (integrator.c) */
    int need_detect;
    long detections;
    int touching;            /* pairs with non-zero force in the last step */
    double *cx, *cy, *cz, *r; /* bounding circles (cz NULL) or spheres, one per element */
    double *pos_detect;      /* node positions at the last detection */
    double *force;           /* contact force per node (kept apart for its work) */
    int force_is_zero;       /* force holds only zeros: no pair was evaluated */
    int32_t *body;           /* body id per element: pairs of one body never touch */
    int32_t *piece;          /* scratch: piece label per element (fracturing models) */
    double *box;             /* 2 dim per element: lo, hi of each axis, each step, of the
                                elements in some candidate pair */
    int32_t *active;         /* the elements in some candidate pair, once each */
    int active_count;
    uint8_t *in_pair;        /* scratch per element for building active */
    /* Stick springs: a set of slots doubles only for the candidate pairs
     * whose springs hold something (pairs that touch: a few in a hundred
     * of the candidates), the rest share no memory (contact_history.c). */
    double *slip;            /* the sets, slots doubles each */
    int32_t *spring_of;      /* per candidate pair: its set, or -1 (all its springs zero) */
    size_t pair_capacity;    /* of spring_of */
    int32_t *slip_free;      /* sets let go, to be handed out again */
    size_t slip_count, slip_capacity, free_count; /* sets handed out or freed, allocated, free */
    contact_record *records; /* history set aside across a detection or a restore */
    size_t record_count, record_capacity;
    struct near_pair *near;  /* candidate pairs whose boxes can overlap before some node
                                moves near_reach from pos_near, in pair order, with what
                                the walk reads of them (contact.c) */
    size_t near_count, near_capacity;
    double near_reach;       /* the list holds while no node is farther than this from */
    double *pos_near;        /* its place when the list was built */
    double near_disp2;       /* largest squared node displacement from pos_near since then
                                (tracked by the integrator with max_disp2) */
    double near_apart;       /* this step, a near_gap over this is still open */
    int32_t *near_active;    /* the elements in some near pair, once each: their boxes */
    int near_active_count;   /* are all a step needs while the list holds */
    double *elem_gap;        /* per element: the smallest gap of its near pairs */
    int near_stale;          /* a detection or a restore: the list is rebuilt next step */
    struct contact_touches *touches; /* threaded runs: one list per thread (contact.c) */
    int touch_lists;         /* how many lists touches holds */
    nbs_grid grid;           /* 2D detection */
    nbs_grid_3d grid3;       /* 3D detection */
    nbs_pairs pairs;
} contact_state;

struct fdem_model {
    int finalized;
    int dim;                 /* 2 or 3: numbers per node in every node array */
    int elem_nodes;          /* 3 (triangles) or 4 (tetrahedra) */

    /* nodes: hot */
    int node_count, node_capacity;
    double *pos, *vel, *force, *inv_mass;
    /* nodes: cold */
    double *pos0, *mass;
    int32_t *node_part;
    int32_t *node_origin;    /* the mesh vertex a node stands for: copies in a fracturing
                                part share it; otherwise the node itself */
    uint8_t *dof_owned;      /* bit d: component d prescribed by some constraint */

    /* elements: triangles in elem (2D) or tetrahedra in tet (3D) */
    int elem_count, elem_capacity;
    element_hot *elem;
    tet_hot *tet;
    int32_t *elem_part;
    int32_t *elem_node;      /* elem_nodes per element, packed (cold copy for output) */
    double *elem_h;          /* smallest altitude (height) of the initial element */

    int material_count, material_capacity;
    material *materials;
    int part_count, part_capacity;
    part *parts;
    double *part_velocity;   /* 3 per part (2D uses 2), applied at finalize */
    initial_stress_def *stress0_defs; /* in-situ stresses as given, one per part that has one */
    int stress0_def_count;
    double *elem_stress0;    /* stress_comps per element: the 2nd Piola-Kirchhoff pre-stress
                                S0 (the in-situ Cauchy stress at t = 0); NULL when no part
                                has one, zeros in the elements of parts without */
    double stress0_energy;   /* sum of V0 S0 : C^-1 : S0 / 2: what the in-situ stress holds
                                at t = 0, linear elastic (a constant of the elastic energy) */
    int fixed_parts;         /* parts with part.fixed (fixed_part.c) */
    int fixed_valid;         /* fixed_force and fixed_energy are this model's */
    double *fixed_force;     /* dim per node of the fixed parts, part after part: their
                                elements' forces, the same every step from the second on */
    double fixed_energy;     /* those elements' strain energy */

    int constraint_count, constraint_capacity;
    constraint *constraints;
    int cnode_count;
    int32_t *cnode;          /* node of each constraint entry */
    uint8_t *cdof;           /* dofs this entry owns (bit d: component d) */
    double *constraint_force_out; /* dim per constraint, for fdem_constraint_forces */

    /* joints (fracture); joint_count == 0 when no part fractures */
    int joint_count;
    int32_t *joint_node;     /* 2 dim per joint: a0, a1 (, a2) on face A (outward of A),
                                b0, b1 (, b2) their copies in B */
    int32_t *joint_elem;     /* 2 per joint: elements A and B */
    double *joint_h;         /* smaller size of the two elements: sets the stiffness */
    double *joint_k;         /* penalty / joint_h: traction per unit opening or sliding */
    int32_t *joint_strength_of; /* index into joint_strengths */
    joint_strength *joint_strengths;
    int joint_strength_count;
    joint_set *joint_sets;   /* fdem_add_joint_set, resolved at finalize */
    int joint_set_count;
    double *joint_damage;    /* 0 intact .. 1 broken, never decreases */
    joint_slip *joint_slip;  /* dim per joint, one per integration point: the plastic slide
                                and slip path each keeps (joint_law.h); zero while undamaged */
    int32_t *elem_joint;     /* dim + 1 per element: its joints, -1 where none */
    uint8_t *vertex_broken;  /* per mesh vertex (node_origin): some joint on it is broken;
                                refreshed at each contact detection */
    double *joint_fracture;  /* per joint: what its damage growth dissipated so far (the
                                fracture account joint by joint; its event's energy) */
    uint8_t *joint_broke;    /* per joint: the mode of a break in this step's joint loop,
                                0 otherwise; cleared as events_collect records it */
    int broken_joints;
    int fragments;
    fdem_event *events;      /* fracture events not drained yet, in (step, joint) order */
    int event_count, event_capacity;

    double gravity[3];       /* this step's gravity: gravity_base times its amplitude */
    double gravity_base[3];
    double *gravity_amplitude; /* (t, a) pairs, NULL for a constant gravity */
    int gravity_amplitude_count;
    double gravity_work_sum; /* with a gravity amplitude: its work booked step by step */
    double momentum[3];      /* with a gravity amplitude: sum m v after the last step */

    /* boundary facets loaded by PRESSURE and ABSORB constraints
     * (boundary_load.c): dim nodes per entry, ordered so that their area
     * vector points out of the body, the element behind, and the force the
     * last step put on each of its nodes (dim * dim per entry) */
    int bfacet_count;
    int32_t *bfacet_node;
    int32_t *bfacet_elem;
    double *bfacet_force;
    double boundary_power_old[2]; /* this step's sum f . v_old: pressures, dashpots */
    double dt, dt_prev;      /* h_next and h_current of seed eq. 5.9 */
    int64_t step;
    double time;
    double time_carry;       /* what rounding took off time, added back next step (model_time_after) */
    double stable_dt;

    /* energy accounts (see fdem_energy and energy.c). Work is booked with
     * the step-averaged velocity (v_old + v_new)/2 * havg, which is exactly
     * what a force adds to the half-step kinetic energy; fdem_get_energy
     * turns the sums into values at the start of the last step, where the
     * elastic and joint energies are evaluated. */
    double elastic_energy;   /* of the last force evaluation */
    double joint_energy;     /* stored in intact joints, last force evaluation */
    double contact_work;     /* work of all contact forces (normal and friction) */
    double friction_energy;  /* dissipated by Coulomb sliding of contacts (>= 0) */
    double joint_friction_energy; /* by the sigma_c tan(phi) part of intact joints' shear
                                     strength as they slide (joint.c) */
    double fracture_energy;  /* dissipated by joint softening and breaking (>= 0) */
    double damping_work;     /* energy dissipated by viscous damping */
    double external_work;
    double initial_energy;   /* kinetic + elastic at t = 0 */
    double initial_acceleration2; /* sum of m a.a at t = 0 over free dofs (energy.c) */
    double first_dt;         /* the first step's size, 0 before it or after a restore */
    double havg_last;        /* (h_current + h_next)/2 of the last step, 0 before it */
    double *elem_viscous;    /* stress_comps per element: the viscous half stress of the last step, whose
                                work with the new velocities the next step books
                                (element.c); NULL when no element is damped */
    fdem_energy restored_energy; /* the accounts a checkpoint held, reported until the next
                                    step (the last step's forces they need are not stored) */
    int restored_energy_valid;

    contact_state contact;
    fdem_stage_times times;

    /* threads for the per-step loops; the plans fix the summation order so
     * that the result does not depend on the thread count */
    int threads;
    scatter_plan elem_plan, node_plan;
    joint_sweep joint_sweep;
};

double stage_clock(void);

/* model.c: fills *err (when not NULL) with a kind, an item and a message */
void model_error(fdem_error *err, fdem_item_kind kind, int item, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Grows *array (items of `size` bytes) to hold at least `need`, doubling
 * from `first`: 0, or -1 when out of memory (*array is then unchanged). */
int model_reserve(void **array, size_t *capacity, size_t need, size_t size, size_t first);

/* Stress components per element: 3 in 2D, 6 in 3D. */
static inline int model_stress_comps(const fdem_model *m) { return m->dim == 3 ? 6 : 3; }

/* What every element's hot record holds, whichever its dimension. */
static inline int element_material(const fdem_model *m, int e)
{
    return m->dim == 3 ? m->tet[e].material : m->elem[e].material;
}

static inline const int32_t *element_nodes(const fdem_model *m, int e)
{
    return m->dim == 3 ? m->tet[e].node : m->elem[e].node;
}

/* The time after a step of h. Time is a running sum of steps, and summed
 * plainly its rounding grew with the step count: the 160000 steps of
 * examples/incline.json ended 7e-13 s short of time.end, so the daemon took
 * one more step of 7e-13 s, and each snapshot time was off by as much.
 * Compensated (Kahan) summation keeps it within a rounding of the exact sum
 * however many steps; *carry gets the compensation for the next step (the
 * checkpoint keeps it, so a restart continues with the same bits). */
static inline double model_time_after(const fdem_model *m, double h, double *carry)
{
    double y = h - m->time_carry, t = m->time + y;
    *carry = (t - m->time) - y;
    return t;
}

/* A part whose elements' forces are stored, not added, at each step: a
 * fracturing part in 3D, where every element has nodes of its own, so the
 * step need not zero their forces first (element_tet_model.c; the triangle
 * kernel adds everywhere). */
static inline int model_part_stores_forces(const fdem_model *m, const part *p)
{
    return m->dim == 3 && p->fracture;
}

/* The mesh checks (mesh.c, mesh_3d.c) take an element only when its size
 * squared (2D) or cubed (3D) is above this and finite: the 1e-12 tolerance
 * on its area or volume is then still a normal double. Edges from about
 * 1e-93 m (3D; 1e-140 m in 2D) up to 5e102 m (1e154 m) pass. */
#define MESH_SMALLEST_CUBE 1e-280

/* Initial area (2D) or volume (3D), set by element_prepare. */
static inline double element_size0(const fdem_model *m, int e)
{
    return m->dim == 3 ? m->tet[e].volume0 : m->elem[e].area0;
}

static inline double element_eta(const fdem_model *m, int e)
{
    return m->dim == 3 ? m->tet[e].eta : m->elem[e].eta;
}

/* initial_stress.c: evaluates each stressed part's field at its elements'
 * initial centroids into elem_stress0 and stress0_energy, marks the parts
 * (0, or -1 out of memory); the stable step's factor for the geometric
 * stiffness of a tensile pre-stress (1 for elements without) */
int initial_stress_prepare(fdem_model *m, fdem_error *err);
double initial_stress_dt_factor(const fdem_model *m, int e);

/* element.c: the element stage of either dimension (prepare, stable step,
 * forces through the scatter plan, stress), calling the kernels below */
int element_prepare(fdem_model *m, int e, fdem_error *err);
double element_stable_dt(const fdem_model *m, int e);
void element_forces(fdem_model *m);
void element_stress_one(const fdem_model *m, int e, double *out);
int element_of_node(const fdem_model *m, int node);

/* fixed_part.c: parts held still as a whole, whose element forces are
 * computed once and kept (element.c skips their elements from the second
 * step on: fixed_parts_kept) */
int fixed_parts_prepare(fdem_model *m, fdem_error *err);
static inline int fixed_parts_kept(const fdem_model *m) { return m->fixed_parts && m->step >= 1; }
double fixed_parts_forces(fdem_model *m);

/* element_tri.c: the triangle kernel */
void tri_element_prepare(fdem_model *m, int e);
double tri_element_stable_dt(const fdem_model *m, int e);
void tri_element_forces_range(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS]);
void tri_element_forces_range_stressed(fdem_model *m, int begin, int end,
                                       double sums[SCATTER_SUMS]); /* with elem_stress0 */
void tri_element_stress(const fdem_model *m, int e, double out[3]);

/* element_tet_model.c: the tetrahedron kernel (element_tet.h) on the model */
int tet_element_prepare(fdem_model *m, int e, fdem_error *err);
double tet_element_stable_dt(const fdem_model *m, int e);
void tet_element_forces_range(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS]);
void tet_element_forces_range_stressed(fdem_model *m, int begin, int end,
                                       double sums[SCATTER_SUMS]);
void tet_element_stress(const fdem_model *m, int e, double out[6]);

/* contact.c: the contact stage of both dimensions over the pair kernels of
 * contact_tri.c and contact_tet.c (contact_pair.h) */
int contact_init(fdem_model *m, fdem_error *err);
void contact_free(contact_state *c);
double contact_stable_dt(const fdem_model *m);
int contact_forces(fdem_model *m);
int contact_restore_detection(fdem_model *m);
size_t contact_memory_bytes(const contact_state *c); /* touch lists and stick springs */

/* contact_history.c */
int contact_history_reserve(contact_state *cs, size_t pairs);
int contact_springs_adopt(contact_state *cs, size_t pair, const double *springs);
void contact_springs_release(contact_state *cs, size_t pair);
/* Some stick spring of candidate pair k holds a force. */
static inline int contact_pair_sprung(const contact_state *cs, size_t k)
{
    return cs->spring_of[k] >= 0;
}
int contact_history_set_aside(contact_state *cs);
int contact_history_take_back(contact_state *cs);
size_t contact_history_checkpoint_size(const contact_state *cs);
void contact_history_checkpoint_write(const contact_state *cs, unsigned char *p);
int contact_history_checkpoint_read(contact_state *cs, const unsigned char *p, size_t count,
                                    int elements);
size_t contact_record_bytes(const contact_state *cs); /* one record in a checkpoint */

/* constraint.c */
int constraint_selects(const fdem_model *m, const constraint *c, int node);
void constraint_set_time(fdem_model *m, double velocity_time);
int constraint_select(fdem_model *m, fdem_error *err);
void constraint_apply_forces(fdem_model *m);
void constraint_enforce(fdem_model *m, double h, double havg);

/* joint.c (the cohesive law itself, joint_softening included: joint_law.h) */
/* The cohesive constants of a joint of strength s at stiffness k. */
static inline joint_law joint_law_of(const joint_strength *s, double k)
{
    return (joint_law){k, s->tensile_strength, s->cohesion, s->tan_phi, s->energy_I,
                       s->energy_II};
}
/* The central-difference limit of a joint node of mass `mass` held by
 * stiffness k (all its joints, both faces), with a 0.9 margin. */
static inline double joint_spring_dt(double mass, double k)
{
    return 0.9 * 2 * sqrt(mass / (2 * k));
}
void *joint_build_scratch(size_t bytes, int part_index, fdem_error *err);
int joint_reserve(fdem_model *m, int J, int part_index, fdem_error *err);
int joint_build_part(fdem_model *m, int part_index, const int32_t *tri, int triangle_count,
                     fdem_error *err);
int joint_prepare(fdem_model *m, fdem_error *err);
double joint_stable_dt(const fdem_model *m);
int joint_holds(const fdem_model *m, int a, int b);
void joint_mark_broken_vertices(fdem_model *m);
int joint_fan_holds(const fdem_model *m, int a, int b);
int joint_contact_excluded(const fdem_model *m, const int32_t *piece, int a, int b);
int joint_fragment_labels(const fdem_model *m, int32_t *label);
int joint_forces(fdem_model *m);
void joint_forces_range_2d(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS]);
int joint_forces_one_2d(fdem_model *m, int j, joint_totals *t, double fa[JOINT_FACE_VALUES]);
int joint_fragment_count(const fdem_model *m);
/* events.c: the fracture events of the joints that broke in this step's
 * joint loop (joint_broke), appended in joint order; -1 without memory */
int events_collect(fdem_model *m, int broke);
size_t events_checkpoint_size(const fdem_model *m);
void events_checkpoint_write(const fdem_model *m, unsigned char *p);
int events_checkpoint_read(fdem_model *m, const unsigned char *p, int64_t count);
/* joint_strength.c: every joint's strength (material, joint set, variation) */
int joint_strengths_assign(fdem_model *m, fdem_error *err);
void joint_sets_free(fdem_model *m);
double weibull_factor(uint64_t seed, uint64_t index, double modulus);
/* constraint.c: the owned copy of a vertex selection */
int constraint_keep_vertices(constraint *c);
/* joint_tet_model.c: the 3D geometry of joints (6 nodes, a face each) */
int joint_build_part_3d(fdem_model *m, int part_index, const int32_t *tet, int tet_count,
                        fdem_error *err);
double joint_stable_dt_3d(const fdem_model *m);
void joint_forces_range_3d(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS]);
int joint_forces_one_3d(fdem_model *m, int j, joint_totals *t, double fa[JOINT_FACE_VALUES]);

/* scatter_plan.c: fn runs items [begin, end) of one block and may add into
 * node arrays. It starts from sums zeroed and leaves its block's partial
 * results there: sums[0 .. SCATTER_MAX - 1] are added, block by block in
 * block order, to the same totals; each totals[i] from SCATTER_MAX on
 * becomes the largest sums[i] (and what it held before, if larger). */
typedef void (*scatter_block_fn)(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS]);
/* The element loop of part p's elements: its dimension's kernel, with the
 * pre-stress where the part has one (element.c, fixed_part.c). */
scatter_block_fn element_forces_loop_of(const fdem_model *m, const part *p);

/* Smallest blocks, and the block count aimed at above that: a node on the
 * border of two colours is loaded once per colour, so large meshes get
 * blocks many rows deep (few border nodes), while 64 blocks still spread
 * over any core count this daemon meets. */
#define SCATTER_BLOCK_ELEMENTS 1024
#define SCATTER_BLOCK_JOINTS 2048
#define SCATTER_BLOCK_NODES 4096
#define SCATTER_TARGET_BLOCKS 64
int scatter_block_size(int item_count, int smallest);
int scatter_plan_build(scatter_plan *plan, int item_count, int block_size,
                       const int32_t *item_nodes, size_t stride, int nodes_per_item,
                       int node_count);
int scatter_plan_build_disjoint(scatter_plan *plan, int item_count, int block_size);
void scatter_plan_run(scatter_plan *plan, fdem_model *m, int threads, scatter_block_fn fn,
                      double totals[SCATTER_SUMS]);
void scatter_plan_free(scatter_plan *plan);
/* One block's partial results into the totals, as the comment on
 * scatter_block_fn says. */
static inline void scatter_sums_add(double totals[SCATTER_SUMS], const double sum[SCATTER_SUMS])
{
    for (int i = 0; i < SCATTER_MAX; i++) totals[i] += sum[i];
    for (int i = SCATTER_MAX; i < SCATTER_SUMS; i++)
        if (sum[i] > totals[i]) totals[i] = sum[i];
}

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

/* boundary_load.c: pressures and absorbing dashpots on boundary facets */
int boundary_load_select(fdem_model *m, fdem_error *err);
void boundary_load_apply(fdem_model *m);
void boundary_load_account(fdem_model *m, double havg);
double boundary_load_last_half_step(const fdem_model *m, int absorb);
void boundary_load_free(fdem_model *m);

/* energy.c */
void energy_initial(fdem_model *m);
void energy_gravity_step(fdem_model *m, double havg);
void energy_gravity_restored(fdem_model *m, double gravity_work);

/* integrator.c */
int central_difference_step(fdem_model *m);
/* the travel since detection (contact.max_disp2, a bound; see integrator.c):
 * grown by a step's largest squared node step, and whether some node is now
 * farther than sqrt(limit2) from pos_detect (exact, read when the bound says
 * it may be) */
void contact_travel_step(fdem_model *m, double step2);
int contact_travel_past(fdem_model *m, double limit2);

#endif
