/*
 * model.h - the engine's one model struct: the state every stage reads and
 * writes, in one place. Stages do not declare their functions here; each
 * folder's header does (element/element.h, contact/contact.h, ...), so a
 * stage sees another only through what that one publishes. Besides the
 * struct this header holds only what reads the state without computing
 * (element_nodes, model_time_after, ...) and the helpers every stage needs
 * (model_error, model_reserve, stage_clock: model.c).
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
#include <string.h>

#include "fdem.h"
#include "kernel/contact_pair.h"
#include "kernel/joint_law.h"
#include "nbs/nbs_classes.h"

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
    int fracture;        /* has joints: on every interior face, or only inside a region */
    int region;          /* fracture in a region (joint_region.c): its elements share the
                            nodes of every vertex no joint splits; 0 when every element
                            keeps its own nodes (a whole fracturing part) */
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

/* The stress of def at height h (y in 2D, z in 3D), in the layout of
 * fdem_element_stress (S components): value + gradient (h - reference).
 * The elements take it at their centroids (initial_stress.c), the joints
 * at their corners (joint_prestress.c). */
static inline void initial_stress_at(const initial_stress_def *def, int S, double h, double *out)
{
    double dh = h - def->reference;
    for (int k = 0; k < S; k++) out[k] = def->value[k] + def->gradient[k] * dh;
}

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
    double amplitude_now; /* that amplitude (1 without one, set at finalize): BOUNDARY_STRESS
                             scales its whole field by it */
    double *amplitude;   /* owned copy of def.amplitude (def.amplitude points here) */
    int facet_begin, facet_count; /* boundary loads (boundary_load.c): entries of
                                     model.bfacet_* */
} constraint;

/* A stage of the run (fdem_add_stage, step/stages.c): its end, its
 * excavation (a sorted copy of the element indices) and, once started, the
 * unloading ramp: the forces the removed elements exerted on the remaining
 * nodes at that moment (excavation.c), applied times 1 - s. */
typedef struct run_stage {
    double end, relax;
    int32_t *excavate;   /* sorted, without repeats */
    int excavate_count;
    double t_start;      /* the start time of its first step, once started */
    int ramp_count;      /* nodes with an unloading force */
    int32_t *ramp_node;  /* ascending */
    double *ramp_force;  /* dim per ramp node */
    double ramp_scale;   /* 1 - s of the current step (0 once the ramp is over) */
} run_stage;

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

/* Stick-spring history of one pair of elements lo < hi (contact_history.c):
 * the tangential springs of lo's contactor boundaries against hi, then of
 * hi's against lo, slots of them (contact_pair.h: 6 for triangles, 24 for
 * tetrahedra). A checkpoint stores lo, hi and the slots used, so a 2D record
 * there is 56 bytes as before 3D (contact_record_bytes). */
typedef struct contact_record {
    int32_t lo, hi;
    double slip[CONTACT_SLOTS_MAX];
} contact_record;

/* contact_state.need_detect: detection is due on the current positions
 * (ALL), or only joints broke since the last (BREAKS: the list is mended
 * on its circles, contact_breaks.c). A break never lowers a pending ALL. */
#define CONTACT_DETECT_ALL 1
#define CONTACT_DETECT_BREAKS 2

typedef struct contact_state {
    int enabled;             /* some pair of elements can ever touch */
    const struct contact_kernel *kernel; /* the dimension's pair kernel (contact.c) */
    int slots;               /* stick springs per pair */
    int pair_out;            /* numbers a pair evaluation hands back */
    double buffer;           /* the largest skin (0.4 of the largest radius): the near list's */
    double *skin;            /* per element its skin, added to its circle's diameter, on a
                                graded mesh; NULL: every element's is buffer (contact_travel.c) */
    double *travel_weight;   /* per node (smallest allowance / its allowance)^2; NULL with skin */
    double travel_limit2;    /* re-detect once a node's weighted squared travel passes this */
    double max_disp2;        /* bound of the weighted squared node displacement since detection,
                                exact once past the limit (contact_travel.c) */
    int need_detect;         /* CONTACT_DETECT_ALL, or _BREAKS: only joints broke (contact.h) */
    long detections;
    int touching;            /* pairs with non-zero force in the last step */
    fdem_penetration pen[FDEM_PENETRATIONS_MAX]; /* pairs found passing into one another,
                                each once (penetration.c); not checkpointed: an observation */
    int pen_count, pen_taken; /* found, handed out by fdem_take_penetrations */
    long pen_more;           /* found beyond pen[] since the last take */
    double *cx, *cy, *cz, *r; /* bounding circles (cz NULL) or spheres, one per element */
    double *pos_detect;      /* node positions at the last detection */
    double *force;           /* contact force per node (kept apart for its work) */
    int force_is_zero;       /* force holds only zeros: no pair was evaluated */
    int32_t *body;           /* body id per element: pairs of one body never touch */
    int32_t *piece;          /* scratch: piece label per element (fracturing models) */
    int32_t *detect_body;    /* scratch: the body ids a detection runs on (contact.c) */
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
    /* The near pairs whose elements share a mesh vertex but no broken
     * joint (SHUT_TOPO_VERTEX), kept apart: while both elements are shut
     * the walk leaves such a pair out, so it is walked only where an
     * element is not shut now or was not last step (contact_near.c);
     * vertex_start/vertex_pairs list each element's (CSR, a pair under
     * both elements), vertex_walk this step's, in pair order. */
    struct near_pair *near_vertex; /* the end of near's array */
    size_t near_vertex_count;
    int32_t *vertex_start, *vertex_pairs, *vertex_walk;
    size_t vertex_pairs_capacity, vertex_walk_capacity;
    uint8_t *vertex_due;     /* per near_vertex pair: listed this step (scratch) */
    size_t vertex_due_capacity;
    size_t vertex_walk_count;
    int vertex_walk_all;     /* the list was just rebuilt: every vertex pair this step */
    int vertex_skip_off;     /* tests: every vertex pair every step */
    int first_look_off;      /* tests: no first look (contact_walk.c, pair_first_met) */
    long first_looks;        /* a figure: pairs a first look found apart, or (3D) looked at
                                across their edges before clipping */
    double near_reach;       /* the list holds while no node is farther than this from */
    double *pos_near;        /* its place when the list was built */
    double near_disp2;       /* largest squared node displacement from pos_near since then
                                (tracked by the integrator with max_disp2) */
    double near_apart;       /* this step, a near_gap over this is still open */
    int32_t *near_active;    /* the elements in some near pair, once each: their boxes */
    int near_active_count;   /* are all a step needs while the list holds */
    double *elem_gap;        /* per element: the smallest gap of its near pairs of no
                                shut topology (those go by elem_topo) */
    int gaps_raised;         /* the walk raised some pair's gap since elem_gap was found */
    size_t near_dead;        /* near pairs raised past contact_near_dead since the list
                                was built or compacted */
    long near_compacted;     /* a figure: near pairs taken out that way, all steps */
    int near_stale;          /* a detection or a restore: the list is rebuilt next step */
    int clearance_off;       /* tests: never skip a pair on its kernel's clearance (contact.c) */
    /* after a break (contact_breaks.c): the list's spare and the pairs
     * found again, an element's count or mark, the pieces after the break,
     * each element's body in the search, the elements marked, what the
     * last detection saw of the joints (broken) and vertices (marks) */
    nbs_pairs spare, fresh;
    int32_t *break_scratch, *piece_next, *query_body;
    uint8_t *marked, *seen_joint, *seen_vertex;
    size_t breaks_bytes;     /* what these arrays hold */
    int breaks_off;          /* tests: a break reruns the whole detection */
    long break_mends;        /* breaks the list was mended for (of detections) */
    /* shut broken joints (contact_shut.c): per node its vertex's first copy,
     * per first copy the squared tolerance and whether it is shut this
     * step, per element whether all its vertices are; NULL without joints */
    int32_t *shut_first;
    int32_t *elem_first;     /* per element, its corners' first copies (elem_nodes each):
                                the marks read these, not the element records */
    double *shut_tol2;
    uint8_t *shut_vertex, *elem_shut;
    int shut_any;            /* this step: some broken joint, elem_shut is current */
    int shut_was_any;        /* last step's shut_any: elem_shut held last step's marks */
    int32_t *elem_due;       /* this step: the elements not shut now or last step */
    int elem_due_count;
    uint8_t *elem_topo;      /* per element: in a near pair of shut topology (bit 0, set
                                at the list's build), whose general kernel may read its
                                box this step (bit 1: contact_near.c) */
    int shut_off;            /* tests and benches: the general kernel on every pair */
    struct contact_touches *touches; /* threaded runs: one list per thread (contact_walk.c) */
    int touch_lists;         /* how many lists touches holds */
    double *walk_cut[2];     /* threaded runs, per walk (near list, vertex pairs): where
                                each thread's share starts, as a fraction of the walk
                                (walk_cuts + 1 numbers), set from last step's work */
    int walk_cuts[2];        /* the thread count walk_cut was made for (0: none) */
    int8_t *apply_owner;     /* threaded runs: per element, the thread whose nodes
                                all its nodes are, or -1 (contact_rows.c) */
    int apply_owner_threads; /* the thread count apply_owner was made for (0: none), */
    int apply_owner_elems;   /* the elements and nodes it was made for; */
    int apply_owner_nodes;
    size_t apply_owner_bytes; /* its size */
    unsigned char *wire;     /* a split walk (step_share.contact_gather): this process's lists */
    size_t wire_capacity;
    long pairs_walked;       /* near pairs in this process's share of the walks, all steps
                                (a figure: every pair on one process) */
    int walk_threads_min;    /* tests: the pairs a walk (or a process's share of a split
                                walk) needs to take threads (0: CONTACT_THREADED_PAIRS) */
    long split_threaded;     /* a figure: split walks whose share went to several threads */
    long near_builds;        /* a figure: rebuilds of the near list */
    int springs_behind;      /* a split walk updated springs in place since the last
                                contact_springs_sync: other processes' copies are behind */
    long springs_synced;     /* a figure: contact_springs_sync's exchanges */
    nbs_grid grid;           /* 2D detection */
    nbs_grid_3d grid3;       /* 3D detection */
    nbs_classes classes;     /* graded meshes: size classes on those grids (nbs_classes.h) */
    nbs_pairs pairs;
} contact_state;

static inline void contact_detect_after_breaks(contact_state *cs)
{
    if (!cs->need_detect) cs->need_detect = CONTACT_DETECT_BREAKS;
}

/* A step split between processes (runner/mpi/rank_engine.c: one MPI rank
 * each): the engine stays one process's code, and these hooks let a driver
 * decide which elements this process computes and complete what the others
 * computed. Absent (NULL), the process computes the whole step. No
 * communication happens here: the callbacks are the driver's.
 *  - elem_mark: per element, 1 if this process computes its forces. The
 *    driver marks every element of the element blocks it owns (so their
 *    block sums are whole) and every element touching a node it owns (so
 *    that node's force is summed over all its elements in plan order).
 *  - block_sums: called by scatter_plan_run after its blocks ran and before
 *    they are totalled in block order; fills in the sums of the blocks
 *    computed elsewhere. Called for every plan; the driver picks its own.
 *  - forces_done: called by fdem_step once every force of the step is
 *    added and before the update; makes the force of every node this
 *    process updates whole (each node's from its owner). Nonzero fails the
 *    step.
 *  - node_mark: NULL, or per node 1 if this process clears its force and
 *    updates it (its own nodes, those of the elements it computes and any
 *    a later stage reads, such as constraints'); the others' state is left
 *    as it was, for their owners to hand on.
 *  - update_done: called by fdem_step after the update with this
 *    process's verdict (nonzero: some value it updated is not finite);
 *    returns the verdict of all processes, so that they fail together.
 *  - contact_ranks, contact_rank: the contact pair walk is split between
 *    contact_ranks processes (under 2: not split), this one being
 *    contact_rank (core/contact/contact_walk.c): each evaluates a fixed
 *    share of the near pairs, lists what they did, and every process
 *    applies every list in process order.
 *  - contact_gather: called once a step by a split contact walk on every
 *    process (walk 1), and before the spring pool is read by anything but
 *    the walk (walk 0: contact_springs_sync, in a step or at a gather),
 *    with the bytes this process listed (ok 0: it failed, the bytes say
 *    nothing). Returns 0 with process p's bytes at (*from)[p], (*size)[p]
 *    of them, in process order (kept until the next call; this process's
 *    own may be `mine` itself, not a copy); nonzero when some process
 *    failed or the exchange did: the step then fails on every process. */
typedef struct step_share {
    void *ctx;
    const uint8_t *elem_mark;
    void (*block_sums)(void *ctx, fdem_model *m, scatter_plan *plan);
    int (*forces_done)(void *ctx, fdem_model *m);
    const uint8_t *node_mark;
    int (*update_done)(void *ctx, fdem_model *m, int bad);
    int contact_ranks, contact_rank;
    int (*contact_gather)(void *ctx, const void *mine, size_t bytes, int ok, int walk,
                          const unsigned char *const **from, const size_t **size);
} step_share;

/* The next run of marked items (mark[i] 1, others 0) in [from, end): its
 * first item, end when there is none, and in *stop the item past its last.
 * memchr finds the ends: a process's items come in long runs. */
static inline int share_next_run(const uint8_t *mark, int from, int end, int *stop)
{
    const uint8_t *first = from < end ? memchr(mark + from, 1, (size_t)(end - from)) : NULL;
    if (!first) {
        *stop = end;
        return end;
    }
    const int begin = (int)(first - mark);
    const uint8_t *past = memchr(first, 0, (size_t)(end - begin));
    *stop = past ? (int)(past - mark) : end;
    return begin;
}

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
    double *joint_offset;    /* dim x dim per joint, NULL when no fracturing part is stressed:
                                the in-situ gap at each corner, its opening and then its
                                slide, in the face's own frame, so that the joint carries
                                sigma.n from t = 0 (joint_prestress.c) */
    double *joint_damage;    /* 0 intact .. 1 broken, never decreases; an excavated joint
                                holds JOINT_DAMAGE_EXCAVATED + its damage then (see there) */
    joint_slip *joint_slip;  /* dim per joint, one per integration point: the plastic slide
                                and slip path each keeps (joint_law.h); zero while undamaged */
    int32_t *elem_joint;     /* dim + 1 per element: its joints, -1 where none */
    int32_t *elem_piece0;    /* with a fracture region: per element, the first element of
                                those it is joined to through shared nodes (the pieces before
                                any joint counts; joint_region.c); NULL without one */
    uint8_t *vertex_broken;  /* per mesh vertex (node_origin): some joint on it is broken;
                                refreshed at each contact detection */
    int32_t *vertex_root;    /* per node: the first copy of its vertex joined to it around the
                                vertex by intact joints; refreshed with vertex_broken */
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

    /* boundary facets loaded by PRESSURE, ABSORB, BOUNDARY_STRESS and TRACTION constraints
     * (boundary_load.c): dim nodes per entry, ordered so that their area
     * vector points out of the body, the element behind, and the force the
     * last step put on each of its nodes (dim * dim per entry) */
    int bfacet_count;
    int32_t *bfacet_node;
    int32_t *bfacet_elem;
    double *bfacet_force;
    int32_t *bfacet_open;    /* with excavations: stages started before each entry is boundary
                                (0: from the start), NULL without */
    double boundary_power_old[2]; /* this step's sum f . v_old: applied loads, dashpots */
    double dt, dt_prev;      /* h_next and h_current of seed eq. 5.9 */
    int64_t step;
    double time;
    double time_carry;       /* what rounding took off time, added back next step (model_time_after) */
    double stable_dt;        /* the largest step accepted: min(eigen_dt, contact_dt) */
    double eigen_dt;         /* the elements', joints' and fluid's stability limits */
    double contact_dt;       /* the contact step (contact_stable_dt), INFINITY without contact */

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

    /* stages (step/stages.c, step/excavation.c); stage_count == 0 without */
    int stage_count, stage_capacity;
    run_stage *stages;
    int stages_started;      /* stages whose start (excavation) is done */
    int stage_now;           /* the stage of the last step (0 before the first) */
    uint8_t *elem_active;    /* per element, 1 active, 0 excavated; NULL until the first
                                excavation */
    uint8_t *node_frozen;    /* per node: only excavated elements held it (with elem_active) */
    double excavated_energy; /* fdem_energy.excavated */
    double gravity_work_removed; /* gravity's work on mass that left, up to its removal */
    double ramp_power_old, ramp_power_new; /* the unloading forces' power, v before/after */

    contact_state contact;
    fdem_stage_times times;
    struct fluid_net *fluid; /* fluid in the fractures (fluid/fluid.h); NULL without */

    /* threads for the per-step loops; the plans fix the summation order so
     * that the result does not depend on the thread count */
    int threads;
    scatter_plan elem_plan, node_plan;
    joint_sweep joint_sweep;
    const step_share *share; /* NULL: one process computes the whole step */
};

/* model.c: the stage clock (seconds, monotonic) the stage times are read on */
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
 * kernel adds everywhere). A fracture region shares nodes: it adds. */
static inline int model_part_stores_forces(const fdem_model *m, const part *p)
{
    return m->dim == 3 && p->fracture && !p->region;
}

/* Initial area (2D) or volume (3D), set by element_prepare. */
static inline double element_size0(const fdem_model *m, int e)
{
    return m->dim == 3 ? m->tet[e].volume0 : m->elem[e].area0;
}

/* Element e has not been excavated. */
static inline int element_is_active(const fdem_model *m, int e)
{
    return !m->elem_active || m->elem_active[e];
}

/* A joint on an excavated element holds nothing from then on, yet its
 * damage is not 1: it did not break (contract 5.4: 1 is broken). It keeps
 * the damage it had as JOINT_DAMAGE_EXCAVATED + d: at least 1, so every
 * joint loop leaves it alone as it does a broken joint, and d kept (to
 * 2 ulp) for the output (fdem_copy_joint_damage) and in checkpoints. A
 * joint broken before the excavation stays at 1. */
#define JOINT_DAMAGE_EXCAVATED 2.0

/* The damage joint j shows: what it had when excavated, if it was. */
static inline double joint_damage_shown(const fdem_model *m, int j)
{
    double d = m->joint_damage[j];
    return d >= JOINT_DAMAGE_EXCAVATED ? d - JOINT_DAMAGE_EXCAVATED : d;
}

static inline double element_eta(const fdem_model *m, int e)
{
    return m->dim == 3 ? m->tet[e].eta : m->elem[e].eta;
}

#endif
