/*
 * fdem.h - the public C API of the fdemd engine (combined finite-discrete
 * element method, after Munjiza 2004) in two and three dimensions.
 *
 * Contract:
 *  - A model is built in two phases. Phase 1 (building): add materials, parts
 *    (explicit meshes or generated ones), per-part initial velocities,
 *    constraints and gravity. Phase 2 (running): fdem_model_finalize() lumps
 *    masses, precomputes element data and the stable step; from then on only
 *    fdem_step() and the read-only accessors are allowed.
 *  - Every function that can fail returns a negative value (or NULL) and fills
 *    an fdem_error that names the offending item (part, triangle, node,
 *    constraint) and says why in a sentence a user can act on.
 *  - The engine owns all its memory; accessors return pointers into it that
 *    stay valid until the next fdem_step() or fdem_model_destroy().
 *  - No global mutable state: two models may be stepped from two threads.
 *  - Units are SI; 2D is plane strain of unit thickness (forces per metre),
 *    3D has forces in N and energies in J.
 *  - A model has one dimension, 2 (triangles, the default) or 3
 *    (tetrahedra), chosen before its first part. Every node array holds
 *    `dimension` numbers per node, every vector (gravity, velocities,
 *    constraint values and reactions) `dimension` components.
 */
#ifndef FDEM_H
#define FDEM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define FDEM_VERSION "0.1.0"

typedef struct fdem_model fdem_model;

/* What went wrong, and with which item. `item` is the index of the offending
 * part/triangle/node/constraint (or -1); `kind` says which of those. */
typedef enum fdem_item_kind {
    FDEM_ITEM_NONE = 0,
    FDEM_ITEM_MATERIAL,
    FDEM_ITEM_PART,
    FDEM_ITEM_NODE,
    FDEM_ITEM_TRIANGLE,
    FDEM_ITEM_CONSTRAINT,
    FDEM_ITEM_ELEMENT, /* engine element index (after finalize) */
    FDEM_ITEM_TETRAHEDRON, /* tetrahedron of a 3D mesh (mesh_3d.h) */
} fdem_item_kind;

typedef struct fdem_error {
    fdem_item_kind kind;
    int item;
    char message[512];
} fdem_error;

/* ---------------------------------------------------------------- materials */

/* Heterogeneity (contract 5.3): each joint's tensile strength and cohesion
 * are the set's values times one factor drawn per joint from a Weibull law
 * of mean 1 and this modulus (scale 1/Gamma(1 + 1/modulus)), from a
 * counter-based generator keyed by the seed, the part and the joint's face
 * (its mesh vertices), so a run depends neither on the thread count nor on
 * the order of the mesh's elements or of the joints. modulus 0: no
 * variation. */
typedef struct fdem_variation {
    double weibull_modulus;
    uint64_t seed;
} fdem_variation;

typedef struct fdem_fracture_params {
    double tensile_strength; /* Pa (the mean when varied) */
    double cohesion;         /* Pa (the mean when varied) */
    double friction_angle;   /* degrees */
    double energy_I;         /* J/m^2 */
    double energy_II;        /* J/m^2 */
    /* Fluid in the fractures (contract 6.4; only with fdem_set_fluid):
     * the hydraulic aperture of a shut joint (m; <= 0: 1e-6), and a static
     * pore pressure that wets the joint from t = 0: value (Pa) + gradient
     * (Pa per metre of height: y in 2D, z in 3D) * (height of the joint's
     * centre at t = 0 - reference), when has_pore_pressure. */
    double aperture0;
    int has_pore_pressure;
    double pore_pressure[3]; /* value, gradient, reference */
} fdem_fracture_params;

typedef struct fdem_material_def {
    double density; /* kg/m^3 */
    double young;   /* Pa */
    double poisson; /* -, in (-1, 0.5) */
    double damping; /* fraction of critical damping of the element's stiffest mode */
    double penalty; /* normal contact penalty, Pa; <= 0 means 10 * young */
    double friction;/* Coulomb coefficient */
    int has_fracture;
    fdem_fracture_params fracture;
    fdem_variation variation; /* of fracture's strengths; zero: none */
} fdem_material_def;

/* ------------------------------------------------------------------- meshes */

/* A triangle mesh as plain arrays: nodes are (x, y) pairs, triangles are
 * 0-based node index triples. Generators allocate with malloc; free with
 * fdem_mesh_free(). */
typedef struct fdem_mesh {
    int node_count;
    int triangle_count;
    double *xy;    /* 2 * node_count */
    int32_t *tri;  /* 3 * triangle_count */
} fdem_mesh;

void fdem_mesh_free(fdem_mesh *mesh);

/* A tetrahedral mesh (mesh_3d.h has its generators and validation): nodes
 * are xyz triples, tetrahedra node index quadruples. */
typedef struct fdem_tet_mesh {
    int node_count, tet_count;
    double *xyz;   /* 3 * node_count */
    int32_t *tet;  /* 4 * tet_count */
} fdem_tet_mesh;

/* Structured rectangle, each of the nx*ny cells split into two triangles
 * (alternating diagonals, so the mesh has no preferred direction). */
int fdem_mesh_rectangle(double ox, double oy, double width, double height,
                        int nx, int ny, fdem_mesh *out, fdem_error *err);

/* Disc with `divisions` nodes on the rim: concentric rings of nodes, ring k
 * with about divisions*k/rings nodes, triangulated between rings so every
 * triangle is close to equilateral (no slivers, no fan at the centre). */
int fdem_mesh_disc(double cx, double cy, double radius, int divisions,
                   fdem_mesh *out, fdem_error *err);

/* Checks index range, finiteness, zero or negative area after orientation;
 * reorients clockwise triangles in place (counted in *reoriented). */
int fdem_mesh_validate(fdem_mesh *mesh, int *reoriented, fdem_error *err);

/* ------------------------------------------------------------------ building */

fdem_model *fdem_model_create(void);
void fdem_model_destroy(fdem_model *model);

/* 2 or 3; only before the first part is added (default 2). */
int fdem_set_dimension(fdem_model *model, int dimension, fdem_error *err);
int fdem_get_dimension(const fdem_model *model);

/* Returns the material index (>= 0) or -1. */
int fdem_add_material(fdem_model *model, const fdem_material_def *def, fdem_error *err);

/* Adds a part (a separate body) meshed by `mesh` (copied, validated and
 * reoriented). `fracture` != 0 makes it breakable along interior edges (the
 * material must then have fracture parameters). Returns part index or -1. */
int fdem_add_part(fdem_model *model, const fdem_mesh *mesh, int material,
                  int fracture, fdem_error *err);

/* The same for a 3D model and a tetrahedral mesh (copied, validated and
 * reoriented). fracture != 0 gives every tetrahedron its own nodes and a
 * 6-node joint on every face shared by two tetrahedra. */
int fdem_add_part_3d(fdem_model *model, const fdem_tet_mesh *mesh, int material,
                     int fracture, fdem_error *err);

/* Fracture in a region (contract 6.1): a fracturing part whose joints go
 * only on the interior edges (3D: faces) whose two elements both have
 * in_region[t] != 0 (one flag per triangle or tetrahedron of `mesh`, in
 * its order; the caller decides membership, e.g. by centroid). The rest
 * stays one continuous body, bonded to the region: a mesh vertex gets one
 * node per class of its elements joined around it through edges (faces)
 * that carry no joint, so elements outside the region share their nodes
 * as in a part that does not fracture, and a vertex inside it has a node
 * per element as in a whole fracturing part. The material needs fracture
 * parameters. Every flag set builds exactly the part fdem_add_part(...,
 * fracture 1) builds (the same nodes, joints and order); no flag set is an
 * error. Returns the part index or -1. */
int fdem_add_part_region(fdem_model *model, const fdem_mesh *mesh, int material,
                         const uint8_t *in_region, fdem_error *err);
int fdem_add_part_region_3d(fdem_model *model, const fdem_tet_mesh *mesh, int material,
                            const uint8_t *in_region, fdem_error *err);

/* Bonded materials (contract 5.3): material[t] becomes the material of
 * element t of the part (in the order of the mesh given to fdem_add_part*);
 * the part stays one body. Before finalize. In a fracturing part every
 * material needs fracture parameters (in a fracture region, those of the
 * elements some joint joins); a joint takes those of its first element's
 * material (unless a joint set says otherwise). */
int fdem_set_element_materials(fdem_model *model, int part, const int32_t *material,
                               fdem_error *err);

/* Pre-existing discontinuities (contract 5.3): the joints of fracturing
 * part `part` that lie on one of `face_count` faces (vertex pairs in 2D,
 * triples in 3D, indices of the part's mesh as given, any order) take
 * `params` (varied by `variation`, NULL: none) instead of their
 * material's. Before finalize; a later set wins where two overlap.
 * Finalize fails when a set lies on no joint. */
int fdem_add_joint_set(fdem_model *model, int part, const fdem_fracture_params *params,
                       const fdem_variation *variation, const int32_t *faces, int face_count,
                       fdem_error *err);

/* Initial velocity of every node of a part: `dimension` components in v
 * (the 2D form leaves vz out). */
int fdem_set_part_velocity(fdem_model *model, int part, double vx, double vy,
                           fdem_error *err);
int fdem_set_part_velocity_v(fdem_model *model, int part, const double *v, fdem_error *err);

/* In-situ stress of a part (contract 5.3): its elements start, at t = 0,
 * with the Cauchy stress value + gradient (h - reference), h the height of
 * each element's initial centroid (y in 2D, z in 3D). value and gradient
 * hold fdem_stress_components numbers in the layout of fdem_element_stress;
 * gradient may be NULL (a uniform stress). Before finalize; a second call
 * for the same part replaces the first. The stress is kept per element as a
 * second Piola-Kirchhoff pre-stress S0 that the element carries as it
 * deforms (sigma = F S0 F^T / J added to the elastic stress, docs/physics.md). */
int fdem_set_part_initial_stress(fdem_model *model, int part, const double *value,
                                 const double *gradient, double reference, fdem_error *err);

/* Gravity, `dimension` components in g (the 2D form leaves gz out). */
void fdem_set_gravity(fdem_model *model, double gx, double gy);
void fdem_set_gravity_v(fdem_model *model, const double *g);
/* Gravity times a(t), a table as a constraint's amplitude (copied); count 0
 * removes it. Returns 0, or -1 for a table that is not finite and
 * increasing in time. */
int fdem_set_gravity_amplitude(fdem_model *model, const double *pairs, int count,
                               fdem_error *err);

/* Node selection for a constraint: all nodes of a part, every node whose
 * initial position lies in the box (inclusive): box[d] is the lower and
 * box[dimension + d] the upper bound of axis d, so [xmin, ymin, xmax, ymax]
 * in 2D and [xmin, ymin, zmin, xmax, ymax, zmax] in 3D; or the nodes of
 * `part` that stand for the listed vertices of its mesh (0-based, as given
 * to fdem_add_part*; every copy of a vertex in a fracturing part), e.g. a
 * named group of a gmsh file. */
typedef enum fdem_select_kind {
    FDEM_SELECT_PART,
    FDEM_SELECT_BOX,
    FDEM_SELECT_VERTICES,
} fdem_select_kind;

typedef enum fdem_constraint_kind {
    FDEM_CONSTRAINT_FIX,      /* fix_x / fix_y / fix_z */
    FDEM_CONSTRAINT_VELOCITY, /* prescribed velocity; free_x/_y/_z leave a component free */
    FDEM_CONSTRAINT_FORCE,    /* total force shared equally by the selected nodes */
    FDEM_CONSTRAINT_PRESSURE, /* value[0] Pa on every boundary edge (face) whose nodes are all
                                 selected, along the current inward normal (boundary_load.c) */
    FDEM_CONSTRAINT_ABSORB,   /* Lysmer dashpots on the same boundary edges (faces) */
    FDEM_CONSTRAINT_BOUNDARY_STRESS, /* contract 6.1: the traction sigma . n of the stress field
                                        stress_value + stress_gradient (h - stress_reference) on
                                        the current outward normal n of the same boundary edges
                                        (faces), h the INITIAL height (y in 2D, z in 3D) of each
                                        point, so the field is fixed to the material; lumped
                                        consistently (linear along the facet), see boundary_load.c */
    FDEM_CONSTRAINT_TRACTION, /* value[0..dim) Pa: a fixed vector traction per unit current
                                 area of the same boundary edges (faces), |S|/dim per vertex */
    FDEM_CONSTRAINT_INJECT,   /* value[0]: fluid injected (m^3/s in 3D, m^2/s per unit thickness
                                 in 2D), shared equally by the joints touching a selected node
                                 (contract 6.4; needs fdem_set_fluid), or with def.bore into a
                                 bore */
} fdem_constraint_kind;

typedef struct fdem_constraint_def {
    fdem_select_kind select;
    int part;           /* FDEM_SELECT_PART, FDEM_SELECT_VERTICES */
    double box[6];      /* FDEM_SELECT_BOX: lower bounds, then upper bounds */
    const int32_t *vertices; /* FDEM_SELECT_VERTICES: copied by fdem_add_constraint */
    int vertex_count;
    fdem_constraint_kind kind;
    int fix_x, fix_y, fix_z;    /* FIX */
    double value[3];            /* VELOCITY: v; FORCE: f (2D: N per unit thickness);
                                   PRESSURE: p in value[0]; TRACTION: t (Pa) */
    int free_x, free_y, free_z; /* VELOCITY: component left free (JSON null) */
    int bore;                   /* INJECT: into a bore whose wall is the boundary edges (faces)
                                   the selection spans, its pressure on them (fluid_bore.c) */
    /* BOUNDARY_STRESS: the field, fdem_stress_components numbers each in the layout of
     * fdem_element_stress (2D: xx, yy, xy; 3D: xx, yy, zz, yz, xz, xy), as
     * fdem_set_part_initial_stress takes it; all finite (checked at finalize). */
    double stress_value[6], stress_gradient[6], stress_reference;
    /* VELOCITY, FORCE, PRESSURE, TRACTION, BOUNDARY_STRESS (the whole field): the
     * value times a(t), piecewise linear through amplitude_count (t, a) pairs
     * (times strictly increasing), held constant outside them; NULL (count 0)
     * is a(t) = 1. fdem_add_constraint copies it. */
    const double *amplitude;
    int amplitude_count;
    /* Stages (fdem_add_stage): 0 acts throughout; k + 1 acts only while
     * stage k runs (zero-initialised defs act throughout). Outside its stage
     * a constraint prescribes and applies nothing and reports a zero force.
     * Not for ABSORB (fdem_add_constraint refuses it). */
    int only_stage;
} fdem_constraint_def;

/* Returns the constraint index or -1 (e.g. a selection with no node).
 * Node selection happens at fdem_model_finalize(), so constraints may be
 * added before or after the parts they select. */
int fdem_add_constraint(fdem_model *model, const fdem_constraint_def *def, fdem_error *err);

/* A stage (contract 6.1): runs from the end of the stage before (or 0)
 * to `end`. At its start the elements listed in `excavate` (model element
 * indices, copied) are removed and the nodal forces they exerted on the
 * remaining body at that moment are applied and ramped linearly to zero
 * over `relax` seconds (0: removed at once).
 *
 * The clock: a step belongs to stage k when its start time t satisfies
 * end(k-1) <= t < end(k) (stage 0 from t = 0; the last stage also takes
 * every step after its end, e.g. after an extend). Stage k starts with the
 * first step whose start time is >= end(k-1): its excavation is done at
 * the start of that step, on the positions the step starts from, so it
 * happens on the same step on any thread count and across checkpoints
 * (steps are not cut to land on stage ends; the stage boundary is late by
 * less than one step). The unloading force is f_exc (1 - s), s = (t -
 * t_start) / relax clamped to [0, 1], t the start time of each step and
 * t_start that of the stage's first step (docs/physics.md "Excavation").
 * After the parts and before finalize, in stage order. Returns the stage
 * index or -1 (end not finite or not after the previous stage's, relax
 * negative or not finite, an element index out of range). */
typedef struct fdem_stage_def {
    double end;
    double relax;
    const int32_t *excavate;
    int excavate_count;
} fdem_stage_def;
int fdem_add_stage(fdem_model *model, const fdem_stage_def *def, fdem_error *err);

/* Fluid in the fractures (contract 6.4, core/fluid/fluid.h): viscosity
 * (Pa s, > 0), bulk modulus (Pa, > 0), density (kg/m^3, >= 0: the fluid's
 * weight under gravity, which makes a hydrostatic pore pressure rest).
 * Before finalize. Without it nothing of the fluid runs. */
typedef struct fdem_fluid_def {
    double viscosity, bulk_modulus, density;
} fdem_fluid_def;
int fdem_set_fluid(fdem_model *model, const fdem_fluid_def *def, fdem_error *err);

/* Lumps masses, builds element and contact data, selects constraint nodes,
 * computes the stable step. Returns 0 or -1. */
int fdem_model_finalize(fdem_model *model, fdem_error *err);

/* ------------------------------------------------------------------- running */

/* Largest step the finalized model accepts: the smallest of the elements'
 * fastest-mode limit (reduced for damping), the joints' and the fluid's,
 * and the contact step (only if some body can touch another). Also set
 * when finalize failed only at a constraint's node selection (so a caller
 * can judge its dt in the same answer); 0 after any earlier failure. */
double fdem_stable_dt(const fdem_model *model);

/* The step of time.dt "auto" for a safety in (0, 1]: safety x each
 * stability limit (the contact's is twice its step), never above the
 * contact step (build/finalize.c says why). At most fdem_stable_dt(); a
 * finalized model starts with the default safety's. */
#define FDEM_DEFAULT_SAFETY 0.5
double fdem_auto_dt(const fdem_model *model, double safety);

/* Step size of the next step; may change between steps (central difference
 * with h_current != h_next, seed eq. 5.9). Must be > 0. */
void fdem_set_dt(fdem_model *model, double dt);
double fdem_get_dt(const fdem_model *model);

/* Threads (OpenMP) for the per-step loops: element, joint and contact
 * forces, the central difference update. Any time, default 1. The result does not
 * depend on it: every node's force is summed in an order fixed when the
 * model is finalized, so one thread and eight give the same bits. */
void fdem_set_threads(fdem_model *model, int threads);
int fdem_get_threads(const fdem_model *model);

/* Advances one step. Returns 0, or -1 if the state became non-finite; then
 * err names the element (FDEM_ITEM_ELEMENT) or node and the step. The model
 * is left as it was after the failing step (do not step it again). */
int fdem_step(fdem_model *model, fdem_error *err);

/* ----------------------------------------------------------------- accessors */

/* The energy accounts, in J per metre of thickness, all since t = 0 and all
 * at the start of the last step, where the elastic energy is evaluated (see
 * energy.c for why that instant). residual is their balance:
 *   kinetic + elastic + joint + contact + friction + fracture + damping
 *   + excavated - gravity_work - external_work - (kinetic + elastic at t = 0),
 * zero but for the time discretisation of non-linear forces. */
typedef struct fdem_energy {
    double kinetic;       /* 1/2 sum m v(t - h/2) . v(t + h/2): the central-difference kinetic
                             energy, which with the elastic energy the scheme conserves exactly
                             for a linear solid */
    double elastic;       /* strain energy of all elements; with an in-situ stress S0 that
                             of the total stress: the energy S0 holds at t = 0 (linear
                             elastic) plus what it and the material gained since (S0 : E) */
    double joint;         /* elastic energy stored in intact joints */
    double contact;       /* minus the work of the contact forces, less what friction
                             dissipated: what the penalty (normal and stick) springs hold;
                             negative means the contact discretisation gave energy */
    double friction;      /* dissipated by Coulomb sliding of contacts and by the sigma_c tan(phi)
                             part of intact joints' shear strength (>= 0) */
    double fracture;      /* dissipated by joint softening and breaking (>= 0, never decreases) */
    double damping;       /* dissipated by viscous damping of elements and by absorbing
                             boundaries' dashpots (>= 0) */
    double gravity_work;  /* work done by gravity */
    double external_work; /* work of applied forces, pressures and constraint reactions,
                             and of the unloading forces of excavations */
    double residual;      /* the balance above */
    double excavated;     /* what excavated elements took with them when removed: their
                             strain energy (in-situ stress included), the kinetic energy
                             of the mass that left with them and the energy of the joints
                             they were on; added to the balance like a dissipation, and
                             the work gravity did on the removed mass stays in
                             gravity_work */
    double fluid_work;    /* work of the fluid's pressure on the solid (in the balance, as
                             a work done on it) */
    double fluid_dissipation; /* dissipated by the fluid's viscous flow (the fluid's own
                             budget: what injection delivers goes to fluid_work, this, and
                             the fluid's compression; not a term of residual) */
} fdem_energy;

typedef struct fdem_counts {
    int dimension;     /* 2 or 3 */
    int nodes, elements, parts, materials, constraints;
    int joints, broken_joints;
    int fragments;     /* connected pieces through intact joints (parts count as one each) */
    int contacts;      /* candidate pairs currently in contact (non-zero force) */
    int contact_pairs; /* candidate pairs from the last detection */
    long detections;   /* how many times detection ran */
} fdem_counts;

/* Elements passing into one another (contract 6.2 "Warnings"): a pair
 * that touched with a node of one inside the other deeper than
 * FDEM_PENETRATION_WARN of that element's inradius (the deepest any point
 * of it can be: 1 at its incentre), looked for every 8 steps (so its cost
 * stays a small fraction of a contact step), each pair once, the first
 * FDEM_PENETRATIONS_MAX of a run (core/contact/penetration.c). Contact at
 * the default penalty keeps a touch of rock or steel far below it (a
 * 10 m/s touch: 0); a 3000 m/s steel block stopped by a 10 mm slab goes
 * 0.36 deep in 2D, and through it at penalty young / 100, 0.93.
 * fdem_take_penetrations() hands out up to `max` found since the last
 * call, and in *more (may be NULL) how many more were seen past the list
 * since then. The check never changes the state. */
#define FDEM_PENETRATION_WARN 0.25
#define FDEM_PENETRATIONS_MAX 16
typedef struct fdem_penetration {
    int64_t step;    /* the step whose start found it */
    double time;
    int a, b;        /* element indices, a < b */
    double depth;    /* of the node inside, as a fraction of the inradius of the element entered */
} fdem_penetration;
int fdem_take_penetrations(fdem_model *model, fdem_penetration *out, int max, long *more);

/* The fluid (contract 6.4): volumes since t = 0 (2D: per unit
 * thickness), the mean pressure of the joints an injection feeds (0
 * without one), the flow's stable step and how many flow steps the last
 * mechanical step took (fluid_flow.c), the joints in the flow network.
 * enabled 0 (and the rest 0) without fluid. */
typedef struct fdem_fluid_status {
    int enabled;
    double injected_volume, stored_volume, source_pressure;
    double flow_step; /* INFINITY while no two open cavities are linked */
    int subcycles, open_joints;
} fdem_fluid_status;
fdem_fluid_status fdem_get_fluid(const fdem_model *model);
/* 1 when the model has fluid (fdem_get_fluid's `enabled`, without its sum
 * over every joint). */
int fdem_has_fluid(const fdem_model *model);
/* Per joint: the fluid pressure of the last evaluation (0 in a sealed
 * joint; NULL without fluid or joints), and the hydraulic aperture
 * max(opening, aperture0) on the current positions into out[joints]
 * (the opening itself without fluid). */
const double *fdem_fluid_pressure(const fdem_model *model);
void fdem_fluid_apertures(const fdem_model *model, double *out);
/* Per constraint, in case order (the history series, contract 6.2/6.4):
 * the mean fluid pressure of the joints an "inject" constraint feeds into
 * pressure[k] and the volume it injected since t = 0 into injected[k]; NAN
 * for a constraint that does not inject. Writes nothing without fluid. */
void fdem_fluid_sources(const fdem_model *model, double *pressure, double *injected);
/* For run-time estimates only, on a model that is thrown away afterwards
 * (core/joint/joint_crack.c): breaks every intact joint between two active
 * elements whose centroids lie on either side of the plane
 * normal . x = offset (normal: `dimension` numbers), as a crack along it
 * would, with no fracture event and no energy booked. Returns how many
 * broke, or -1 out of memory. */
int fdem_break_joints_across(fdem_model *model, const double *normal, double offset);
/* The same crack held inside the body: of the joints
 * fdem_break_joints_across would break, the `share` whose midpoints (the
 * mean of their two elements' centroids) lie nearest `centre`. A cut
 * through the whole body parts it in two, and only the faces meet; a
 * crack inside it, as a growing crack is, also brings the elements
 * around its vertices into contact. Returns how many broke, or -1 out of
 * memory. */
int fdem_break_joints_near(fdem_model *model, const double *normal, double offset,
                           const double *centre, double share);
/* For run-time estimates: treats every broken joint's faces and vertex
 * copies as open (1) or as they are (0). A crack cut at rest is shut, and
 * its pairs take the cheap path of shut joints; a run's cracks open,
 * slide and wedge, and their pairs take the general kernel. */
void fdem_price_cracks_open(fdem_model *model, int open);
/* How many joints fdem_break_joints_across would break, breaking none. */
int fdem_joints_across(const fdem_model *model, const double *normal, double offset);
/* The next step reruns the whole contact detection (for timing it). */
void fdem_force_detection(fdem_model *model);
/* For run-time estimates too: breaks the first intact joint between two
 * active elements at or after `from` (wrapping round) that
 * fdem_break_joints_across(model, avoid_normal, avoid_offset) would not
 * break (any, when avoid_normal is NULL), as the fracture law would, with
 * no event and no energy booked; the next step mends the contact list for
 * it, as a step in which a joint breaks does. Returns the joint, or -1
 * when none is left (or out of memory). */
int fdem_break_one_joint(fdem_model *model, int from, const double *avoid_normal,
                         double avoid_offset);

int64_t fdem_get_step(const fdem_model *model);
double fdem_get_time(const fdem_model *model);
fdem_counts fdem_get_counts(const fdem_model *model);
fdem_energy fdem_get_energy(const fdem_model *model);

/* The stage the last step belonged to (0 before the first step), or -1
 * for a model without stages. */
int fdem_stage_index(const fdem_model *model);
/* elem_count flags, 1 active and 0 excavated, or NULL while every element
 * is active (no stage has removed any yet). Excavated elements exert no
 * force, take part in no contact, their joints hold nothing (damage reads
 * 1, but they are no fracture events and not counted as broken), and the
 * nodes only they held stand still with no mass. */
const uint8_t *fdem_element_active(const fdem_model *model);

/* Node arrays, `dimension` doubles per node, engine order. */
const double *fdem_positions(const fdem_model *model);
const double *fdem_initial_positions(const fdem_model *model);
const double *fdem_velocities(const fdem_model *model);
const double *fdem_node_masses(const fdem_model *model);
const int32_t *fdem_node_parts(const fdem_model *model);
/* Element arrays: node indices per element (3, counter-clockwise, in 2D;
 * 4, positive volume, in 3D), part index. fdem_triangles is NULL in 3D and
 * fdem_tetrahedra NULL in 2D; fdem_element_nodes is whichever there is. */
int fdem_nodes_per_element(const fdem_model *model);
const int32_t *fdem_element_nodes(const fdem_model *model);
const int32_t *fdem_triangles(const fdem_model *model);
const int32_t *fdem_tetrahedra(const fdem_model *model);
const int32_t *fdem_element_parts(const fdem_model *model);
/* Joint arrays (2 dim node indices per joint: a0, a1 (, a2) on one face,
 * b0, b1 (, b2) the matching nodes of the other, a_i opposite b_i), and
 * the engine's damage per joint: 0..1, but above 1 for a joint a stage
 * excavated (it holds nothing). NULL when no joints. fdem_copy_joint_damage
 * writes the damage to show, 0..1, into out[joints]: an excavated joint's
 * as it was when excavated (fdem_element_active says which are gone). */
const int32_t *fdem_joints(const fdem_model *model);
const double *fdem_joint_damage(const fdem_model *model);
void fdem_copy_joint_damage(const fdem_model *model, double *out);

/* Fragments (contract 5.4): pieces connected through shared nodes or
 * intact joints. fdem_fragment_labels writes each element's fragment id
 * into label[elements]: ids 0 .. count-1, numbered in the order of each
 * fragment's first element, so they do not depend on how the pieces were
 * found (an excavated element is in no fragment: label -1); returns
 * count, or -1 when out of memory. fdem_fragments returns the same count
 * and sets *out (free() it) to one record per id: size is the initial
 * area (2D) or volume (3D) of its elements, mass their density times that
 * (exactly the lumped node masses they hold), diameter the circle
 * (sphere) of that size, centroid and velocity the mass-weighted means
 * over its nodes at the current step, part the part of its elements (a
 * fragment never spans two parts: they share no node and no joint) and
 * held 1 when a fix or velocity constraint prescribes some component of
 * the motion of one of its nodes (a fixed slope, a supported rock mass, a
 * driven platen: a body the model holds, not a piece it broke off). */
typedef struct fdem_fragment {
    int elements;
    double mass, size, diameter;
    double centroid[3], velocity[3]; /* dimension components used */
    int part, held;
} fdem_fragment;

int fdem_fragment_labels(const fdem_model *model, int32_t *label);
int fdem_fragments(const fdem_model *model, fdem_fragment **out);

/* The sieve curve of fragments: for each distinct diameter d, in
 * increasing order, the mass fraction of fragments no larger than d.
 * Writes up to count points into diameter[] and passing[] and returns how
 * many it wrote (count distinct diameters). */
int fdem_sieve_curve(const fdem_fragment *fragments, int count, double *diameter,
                     double *passing);

/* Fracture events (contract 5.4): every joint that breaks is one event,
 * kept by the model until drained. time is the end of the step it broke
 * in (the first snapshot time that shows it broken), position its
 * midpoint (the mean of its 2 dim nodes) at the start of that step, mode
 * 1 tensile, 2 shear, 3 mixed (the opening's and the sliding's share of
 * the damage at the point that broke it, docs/physics.md), energy what its
 * damage growth dissipated from its first damage to the break: the events'
 * energies sum to the fracture account of the broken joints. Events come
 * in (step, joint) order whatever the thread count, and a checkpoint keeps
 * those not drained. fdem_drain_events copies the oldest up to max into
 * out, forgets them and returns how many; fdem_event_count says how many
 * wait. fdem_joint_fracture_energy: each joint's fracture account so far
 * (NULL when no joints); its sum is fdem_energy.fracture. */
typedef struct fdem_event {
    double time;
    double position[3]; /* dimension components used */
    double energy;
    int32_t joint;
    int8_t mode;
} fdem_event;

int fdem_event_count(const fdem_model *model);
int fdem_drain_events(fdem_model *model, fdem_event *out, int max);
const double *fdem_joint_fracture_energy(const fdem_model *model);

/* Cauchy stress of every element into out[fdem_stress_components * elements]:
 * (sxx, syy, sxy) in 2D, (sxx, syy, szz, syz, sxz, sxy) in 3D. */
int fdem_stress_components(const fdem_model *model);
void fdem_element_stress(const fdem_model *model, double *out);

/* Derived element fields for output (contract 5.4), element_fields.c.
 * fdem_element_strain: Green-Lagrange strain E = (F^T F - I)/2 in the
 * layout of fdem_element_stress (tensor components, so E_xy is half the
 * engineering shear). fdem_element_principal_stress: the principal values
 * of each element's Cauchy stress, `dimension` per element, descending (2D:
 * of the in-plane tensor). fdem_principal_values does one stress given in
 * that Voigt layout. */
void fdem_element_strain(const fdem_model *model, double *out);
void fdem_element_principal_stress(const fdem_model *model, double *out);
void fdem_principal_values(int dimension, const double *voigt, double *out);

/* Total reaction (fix, velocity), applied (force, pressure, boundary stress, traction) or dashpot
 * (absorb) force of each constraint during the last step, `dimension`
 * doubles per constraint. */
const double *fdem_constraint_forces(const fdem_model *model);

/* Number of nodes selected by constraint c: valid after finalize, and
 * after a finalize that failed on a constraint selecting no node (then 0
 * for each such one); -1 for a constraint finalize did not count. */
int fdem_constraint_node_count(const fdem_model *model, int c);
/* The fdem_constraint_node_count() nodes of constraint c, ascending (valid
 * after finalize; NULL for an unknown c or one that selected none): what
 * its mean displacement is taken over (history output, contract 6.2). */
const int32_t *fdem_constraint_nodes(const fdem_model *model, int c);

/* Parts placed inside each other at t = 0 (after finalize; see
 * start_overlap.c): 1 with a point (dimension numbers) of part *inner that
 * lies inside an element of part *outer, 0 when no two parts do more than
 * touch, -1 when out of memory. */
int fdem_find_start_overlap(const fdem_model *model, int *inner, int *outer, double point[3]);

/* ------------------------------------------------------------- checkpoints */

/* The dynamic state (step, time, dt, positions, velocities, joint and
 * friction history, energy accumulators) as one flat byte buffer, so a
 * daemon can persist a case as {case document, checkpoint} and rebuild it by
 * re-running the case through the same builder and restoring the state.
 * fdem_checkpoint_size() is the exact size fdem_checkpoint_write() needs. */
size_t fdem_checkpoint_size(const fdem_model *model);
int fdem_checkpoint_write(const fdem_model *model, void *buf, size_t size);
/* Fails (with a message) if the buffer does not belong to a model of the
 * same shape (node/element/joint counts). */
int fdem_checkpoint_read(fdem_model *model, const void *buf, size_t size, fdem_error *err);
/* The format version a checkpoint buffer says it is in (1 to the current
 * one, FDEM_CHECKPOINT_VERSION), or -1 when it does not start like one. */
#define FDEM_CHECKPOINT_VERSION 11
int fdem_checkpoint_version(const void *buf, size_t size);

/* Seconds spent in each stage of fdem_step() since the model was built
 * (wall clock, for benchmarks and the status' figures). */
typedef struct fdem_stage_times {
    double elements;    /* internal forces, stress, damping */
    double joints;      /* the joint loop (fracture) and what a break sets off */
    double detection;   /* NBS runs */
    double contact;     /* pair forces */
    double integration; /* central difference update and constraints */
} fdem_stage_times;

fdem_stage_times fdem_get_stage_times(const fdem_model *model);

/* Bytes the engine holds for this model now: every array it allocated,
 * at its capacity (for memory limits, the status and bench). */
size_t fdem_memory_bytes(const fdem_model *model);

/* An upper bound of fdem_memory_bytes() of a model with this many nodes,
 * elements, joints and parts once it has stepped (contacts developed), on
 * one thread: to reject oversized cases before building them. What the
 * counts cannot tell (in-situ stress, damping, varied joint strengths,
 * every joint broken) is priced as present; contact when parts > 1 or
 * joints > 0; finalize's scratch too. The bundled examples' real peaks
 * (valgrind massif, 2000 steps) are 0.26-0.98 of it: 0.5-0.7 for the large
 * 2D and 3D fracturing ones, less for small or sparse-contact ones. */
size_t fdem_memory_estimate(long nodes, long elements, long joints, int parts);
size_t fdem_memory_estimate_3d(long nodes, long elements, long joints, int parts);
/* The estimate of the counts' dimension (a dimension of 0, as in counts
 * stored before 3D, is 2). */
size_t fdem_memory_estimate_of(const fdem_counts *counts);
/* What each thread of a case run on more than one may add (its contact
 * touch lists, one per thread, the first's included). */
size_t fdem_memory_per_thread(int dimension);
/* What fluid in the fractures adds to a model with this many joints (an
 * upper bound: every joint's cavity, links of the densest meshes, one
 * injection's sources, finalize's scratch; core/fluid/fluid_network.c). */
size_t fdem_fluid_memory_estimate(int dimension, long joints);

#ifdef __cplusplus
}
#endif

#endif /* FDEM_H */
