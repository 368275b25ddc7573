/*
 * case_internal.h - what the case_*.c files share while turning a case
 * document into an engine model. Not part of any public contract.
 *
 * case_build() works in three passes so that a user sees every problem at
 * once and nothing large is allocated for an invalid case:
 *   1. read: every section is checked and copied into a case_doc (explicit
 *      and gmsh meshes are parsed here; their size is bounded by the upload);
 *   2. estimate: node/element/joint counts from the shapes, checked against
 *      the memory limit before any generator runs;
 *   3. build: engine calls in contract order; an engine error is mapped back
 *      to the JSON Pointer of the thing it names.
 */
#ifndef FDEM_CASE_INTERNAL_H
#define FDEM_CASE_INTERNAL_H

#include <jansson.h>

#include "case.h"
#include "fdem.h"
#include "gmsh/gmsh.h"
#include "mesh/mesh_3d.h"
#include "json/problems.h"

#define CASE_POINTER 256 /* = sizeof problem.pointer */
#define CASE_NAME 128

typedef struct case_material {
    const char *name; /* key in "materials" (owned by the JSON tree) */
    fdem_material_def def;
} case_material;

typedef enum case_shape {
    CASE_SHAPE_NONE,
    CASE_SHAPE_RECTANGLE,
    CASE_SHAPE_DISC,
    CASE_SHAPE_MESH,
    CASE_SHAPE_GMSH,
    CASE_SHAPE_BOX,
    CASE_SHAPE_SPHERE,
    CASE_SHAPE_CYLINDER,
} case_shape;

/* The JSON key of each shape, indexed by case_shape - 1. */
extern const char *const case_shape_keys[];
#define CASE_SHAPE_KINDS 7

/* A stress field {"value", "gradient", "reference"}: the value at height
 * `reference` (y in 2D, z in 3D) and its change per metre of height, in
 * the layout of the `stress` output; Pa (case_initial_stress.c). */
typedef struct case_stress_field {
    double value[6], gradient[6], reference;
} case_stress_field;

/* A part's "fracture" given as a selector or a list of them (contract 6.1,
 * case_region.c): each a box of element centroids or a gmsh element group. */
#define CASE_MAX_REGION_SELECTORS 16

typedef struct case_region_selector {
    int group;               /* index into the part's groups, or -1: a box */
    double box[6];           /* lower bounds, then upper bounds (dimension each) */
} case_region_selector;

typedef struct case_region {
    int count;               /* 0: "fracture" is true or false */
    int listed;              /* given as a list: selector k is at /parts/i/fracture/k */
    case_region_selector selector[CASE_MAX_REGION_SELECTORS];
} case_region;

typedef struct case_part {
    char name[CASE_NAME];
    int material;            /* index into case_doc.materials, -1 if unknown */
    int fracture;
    int fracture_region;     /* "fracture" is a selector or a list (case_region.c) */
    int has_velocity;
    double velocity[3];      /* `dimension` components */
    case_shape shape;
    double at[3];            /* rectangle or box origin; disc, sphere or cylinder centre */
    double size[3];          /* rectangle, box */
    double radius;           /* disc, sphere, cylinder */
    double length;           /* cylinder */
    int axis;                /* cylinder: 0, 1, 2 for x, y, z */
    long divisions[3];       /* rectangle, box: per axis; disc, sphere: [0]; cylinder: 2 */
    fdem_mesh mesh;          /* 2D; MESH, GMSH: read in pass 1; others: pass 3 */
    fdem_tet_mesh tet_mesh;  /* 3D, the same */
    int has_stress0;         /* "initial_stress" read without a problem */
    case_stress_field stress0;
    double nodes, elements, joints; /* pass 2 estimates (doubles: no overflow) */
    gmsh_groups groups;      /* GMSH: its named physical groups */
    int32_t *element_material; /* "materials": the material of each element, else NULL */
    struct case_region region; /* "fracture" as selectors (case_region.c) */
    struct case_joint_set *joint_sets; /* "discontinuities" */
    int joint_set_count;
} case_part;

/* A "discontinuities" entry: the group (index into the part's groups) and
 * its parameters, the part material's where the entry leaves them out. */
typedef struct case_joint_set {
    int group;
    fdem_fracture_params params;
    fdem_variation variation;
} case_joint_set;

typedef struct case_constraint {
    fdem_constraint_def def; /* def.only_stage: 0 top level, k + 1 in stage k's list */
    double *amplitude;       /* def.amplitude points here (case_amplitude.c) */
    int32_t *vertices;       /* {"part", "group"}: the group's nodes, owned */
    char ptr[CASE_POINTER];  /* "/constraints/3" or "/stages/1/constraints/0" */
} case_constraint;

/* An element selector of a stage's "excavate" (case_stages.c): read in
 * pass 1, turned into model element indices in pass 3. */
typedef enum case_pick { CASE_PICK_NONE, CASE_PICK_PART, CASE_PICK_GROUP, CASE_PICK_BOX } case_pick;

typedef struct case_element_selector {
    case_pick kind;
    int part;                /* PART, GROUP: index into case_doc.parts */
    int group;               /* GROUP: index into that part's groups */
    double box[6];           /* BOX: lower bounds, then upper bounds (element centroids) */
} case_element_selector;

typedef struct case_stage {
    char name[CASE_STAGE_NAME];
    double end, relax;
    case_element_selector *excavate;
    int excavate_count;
} case_stage;

/* A "history" point (case_history.c): read in pass 1, its nearest node
 * found in pass 3. */
typedef struct case_history_point {
    char name[CASE_HISTORY_NAME];
    double at[3];
    int node;                /* engine node nearest `at` at t = 0, -1 until located */
    int sound;               /* read without a problem */
    char ptr[CASE_POINTER];  /* "/history/points/2" */
} case_history_point;

typedef struct case_doc {
    problems *out;
    int dimension;           /* 2 or 3, read before everything that has vectors */
    char name[CASE_NAME];
    case_material *materials;
    int material_count;
    case_part *parts;
    int part_count;
    case_constraint *constraints;
    int constraint_count;
    double gravity[3];
    double *gravity_amplitude; /* (t, a) pairs or NULL */
    int gravity_amplitude_count;
    double end_time, dt, safety, interval;
    int dt_auto;
    unsigned fields;
    json_t *material_names;  /* name -> index into materials (case_names_add) */
    json_t *part_names;      /* name -> index into parts */
    case_stage *stages;      /* "stages", in order (case_stages.c) */
    int stage_count;
    int stages_given;        /* "stages" was in the document */
    int end_given;           /* time.end was in the document (stages may leave it out) */
    long typo_cells; /* edit-distance work spent on "did you mean" so far */
    int history_given;       /* "history" was in the document */
    double history_interval;
    case_history_point history_points[CASE_MAX_HISTORY_POINTS];
    int history_point_count;
    int has_fluid;           /* "fluid" was in the document (case_fluid.c) */
    fdem_fluid_def fluid;
    int ranks;               /* "parallel": {"ranks"}, 1 without it */
} case_doc;

/* case_fluid.c: the top-level "fluid" (read before the materials and
 * constraints, which ask whether there is one), the hydraulic members of
 * fracture parameters, and the cross-section checks after the parts. */
void case_read_fluid(case_doc *doc, const json_t *fluid);
void case_read_fracture_fluid(case_doc *doc, const json_t *value, const char *ptr,
                              fdem_fracture_params *f);
void case_check_fluid(case_doc *doc);

/* case_amplitude.c: an amplitude table [[t, a], ...] at ptr, finite with
 * strictly increasing times: the pairs (free() them) and their count, or
 * NULL after adding a problem at the entry at fault. */
double *case_read_amplitude(case_doc *doc, const json_t *value, const char *ptr, int *count);

/* ------------------------------------------------- case_read.c: JSON values */

/* "a string", "an array", ... for "expected X, got Y" messages. */
const char *case_type_word(const json_t *value);

void case_problem(case_doc *doc, const char *pointer, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* The member `key` of `object` (NULL if absent) with its pointer in `ptr`. */
json_t *case_member(const json_t *object, const char *base, const char *key, char *ptr);

/* Each returns 1 when the value is acceptable, 0 after adding a problem. */
int case_expect_object(case_doc *doc, const json_t *value, const char *ptr);
int case_expect_array(case_doc *doc, const json_t *value, const char *ptr);
int case_read_number(case_doc *doc, const json_t *value, const char *ptr, double *out);
/* An array of exactly `count` finite numbers (a vector of the case's
 * dimension, a box selector, ...); the message says how many. */
int case_read_vector(case_doc *doc, const json_t *value, const char *ptr, int count,
                     double *out);
/* A vector of the case's dimension: its `dimension` numbers, or a problem
 * that names the dimension when the length is the other one's. */
int case_read_axes(case_doc *doc, const json_t *value, const char *ptr, double *out);
/* What a value that is not the expected tuple is, for "got ...": its type,
 * an array's length and, when that is `per_axis` times the other
 * dimension (per_axis > 0), a note naming "dimension". Returns buf. */
const char *case_wrong_tuple(const case_doc *doc, const json_t *value, int per_axis, char *buf,
                             size_t size);
/* Names (of the case, a part, a material) go into result.xdmf (XML 1.0
 * has no form for U+0001 and its kin, not even escaped) and the daemon's
 * log (a newline would forge a log line), so a control character in one
 * (C0, DEL or C1) is refused: 1 when `name` is acceptable, else 0 after a
 * problem at ptr naming the character, its byte offset and `what`. */
int case_check_name_text(case_doc *doc, const char *name, const char *ptr, const char *what);

/* "two", "three", ... for "expected an array of three numbers". */
const char *case_count_word(int count);
/* An integer-valued number (2 or 2.0 or 1e3) in [lo, hi]. */
int case_read_integer(case_doc *doc, const json_t *value, const char *ptr, long lo, long hi,
                      long *out);
/* An array of `count` such integers, entry k in [lo[k], hi]; `layout` names
 * them for the message ("[nx, ny]"). */
int case_read_integers(case_doc *doc, const json_t *value, const char *ptr, int count,
                       const long *lo, long hi, const char *layout, long *out);
int case_read_bool(case_doc *doc, const json_t *value, const char *ptr, int *out);

/* Optional number member: 1 read (or absent, leaving *out), 0 on a problem.
 * With `required`, absence is a problem naming the key. */
int case_number_member(case_doc *doc, const json_t *object, const char *base,
                       const char *key, int required, double *out);

/* Every key of `object` must be in the NULL-terminated `allowed` list; an
 * unknown one is reported with the closest allowed name, if any. `what`
 * names the object in the message ("material \"rock\""). */
int case_check_keys(case_doc *doc, const json_t *object, const char *ptr,
                    const char *const *allowed, const char *what);

/* Name -> index tables, so lookups by name are O(1). case_names_add()
 * returns the index already stored under `name` (and stores nothing), or -1
 * after storing `index` (or adding an out-of-memory problem). */
int case_names_add(case_doc *doc, json_t **names, const char *name, int index);
int case_names_find(const json_t *names, const char *name); /* -1: unknown */

/* The candidate closest to `word` if it is a plausible typo, else NULL.
 * Spends at most *cells_left cells of edit-distance table (and subtracts
 * what it spent): the search stops, keeping the best so far, when a
 * comparison would not fit. */
const char *case_closest(const char *word, const char *const *candidates, int count,
                         long *cells_left);

/* "; did you mean \"x\"?" or "" written into `buf`. The work is charged to
 * the document's bounded budget, and skipped once the problem list is full
 * (the message would be dropped anyway), so validation stays linear in the
 * size of the document however many names are unknown. */
const char *case_did_you_mean(case_doc *doc, char *buf, size_t size, const char *word,
                              const char *const *candidates, int count);

/* --------------------------------------- case_doc.c: problems and freeing */

/* Turns an engine error into a problem at the pointer of the item it names;
 * `fallback` is used when the error names nothing more precise. */
void case_engine_problem(case_doc *doc, const fdem_error *err, const char *fallback);

/* The problem at /time/dt of a dt above `stable`, naming "auto"'s step
 * `auto_dt`; `whose` qualifies the model ("" or "'s valid parts"). */
void case_dt_problem(case_doc *doc, double stable, double auto_dt, const char *whose);

void case_doc_free(case_doc *doc);

/* -------------------------------------------------- the sections, pass 1 */
void case_read_materials(case_doc *doc, const json_t *materials);
int case_material_index(const case_doc *doc, const char *name);
void case_read_parts(case_doc *doc, const json_t *parts);
/* case_shapes.c: the generated shapes of both dimensions (pass 1 reads,
 * pass 3 meshes after the memory check). */
void case_read_block(case_doc *doc, case_part *part, const json_t *block, const char *ptr);
void case_read_round(case_doc *doc, case_part *part, const json_t *round, const char *ptr);
void case_read_cylinder(case_doc *doc, case_part *part, const json_t *cylinder,
                        const char *ptr);
/* Meshes a generated shape into part->mesh or part->tet_mesh (0, or -1 with err). */
int case_generate_shape(case_part *part, fdem_error *err);
/* case_mesh.c: explicit meshes and gmsh text of the case's dimension. */
void case_read_mesh(case_doc *doc, case_part *part, const json_t *mesh, const char *ptr);
void case_read_gmsh(case_doc *doc, case_part *part, const json_t *text, const char *ptr);
/* An engine error about a node or element of part i's mesh, at the pointer
 * of that item when the mesh was given explicitly ("/parts/2/mesh/nodes/4"),
 * else at `fallback`. */
void case_mesh_problem(case_doc *doc, int part, const fdem_error *err, const char *fallback);
void case_read_constraints(case_doc *doc, const json_t *constraints);
/* The index of the part named by `name` (a string), or -1 after a problem
 * at ptr (with the closest part name, if any). */
int case_part_by_name(case_doc *doc, const json_t *name, const char *ptr);
/* A box [xmin, ymin, (zmin,) xmax, ymax, (zmax)] of the case's dimension
 * with min <= max into out: 1, or 0 after a problem at ptr. */
int case_read_box(case_doc *doc, const json_t *box, const char *ptr, double *out);
/* The constraints array at `ptr` appended to doc->constraints with
 * def.only_stage = only_stage (0: top level; k + 1: stage k's own). */
void case_read_constraint_list(case_doc *doc, const json_t *list, const char *ptr,
                               int only_stage);
/* case_stages.c: "stages" (pass 1, after parts and constraints, before
 * time); reconciling time.end with the last stage's end (after time);
 * the stages handed to the engine (pass 3, after the parts; 0 or -1 after
 * a problem); freeing them. */
void case_read_stages(case_doc *doc, const json_t *stages);
void case_check_stage_end(case_doc *doc);
int case_add_stages(case_doc *doc, fdem_model *model);
void case_stages_free(case_doc *doc);
/* case_region.c: a part's "fracture" when it is a selector or a list of
 * them (after its shape and groups; `value` is the part's object; a mesh
 * read in pass 1 is checked against the region when mesh_sound, i.e. it
 * read without a problem), and the flag per element of part i's mesh (NULL
 * while "fracture" is not a region): 0, or -1 after a problem at the
 * selector that selects nothing. */
void case_read_region(case_doc *doc, case_part *part, const json_t *value, const char *ptr,
                      int mesh_sound);
int case_region_mask(case_doc *doc, int i, uint8_t **mask);
/* case_groups.c: the group of elements (of the mesh's dimension) named by
 * `name` at ptr, or -1 after a problem there. */
int case_element_group(case_doc *doc, const case_part *part, const json_t *name,
                       const char *ptr);
/* case_initial_stress.c: a stress field block at ptr ("initial_stress",
 * "boundary_stress"; `what` names it in the message about an unknown key):
 * 1 when read, 0 after a problem at each member at fault. */
int case_read_stress_field(case_doc *doc, const json_t *block, const char *ptr, const char *what,
                           case_stress_field *field);
/* A field not finite, or above CASE_MAX_INITIAL_STRESS, anywhere between the
 * heights height[0] and height[1] (the lowest and highest node of `body`,
 * which the message names, as it names the field `what`) is a problem at
 * ptr's "value" or "gradient", whichever makes it so: -1, else 0. */
int case_check_stress_extent(case_doc *doc, const case_stress_field *field, const char *ptr,
                             const char *what, const char *body, const double height[2]);
/* A part's "initial_stress" (pass 1), and handing document part i's to the
 * engine once it is model part `index` (pass 3; 0, or -1 after a problem);
 * height: the lowest and highest node of the part (y in 2D, z in 3D). */
void case_read_initial_stress(case_doc *doc, case_part *part, const json_t *block,
                              const char *ptr);
int case_add_initial_stress(case_doc *doc, fdem_model *model, int i, int index,
                            const double height[2]);
/* case_materials.c: a fracture block and its variation (zero when it has
 * none); required = 0 lets keys be absent (f keeps what it held) but wants
 * at least one. */
void case_read_fracture(case_doc *doc, const json_t *value, const char *ptr, const char *what,
                        int required, fdem_fracture_params *f, fdem_variation *v);
/* case_groups.c: a gmsh part's "materials" and "discontinuities" (after its
 * shape, material and fracture flag), a {"part", "group"} selector's nodes
 * (0 and a list the caller frees, or -1 after a problem at ptr), and the
 * groups' materials and joint sets given to the engine (pass 3). */
void case_read_part_groups(case_doc *doc, case_part *part, const json_t *value,
                           const char *ptr);
int case_group_vertices(case_doc *doc, int part, const json_t *group, const char *ptr,
                        int32_t **vertices, int *count);
/* The index (into the part's groups) of the group named `group` of part
 * `part` that has elements of the mesh's dimension, for an element
 * selector; -1 after a problem at ptr. */
int case_group_with_elements(case_doc *doc, int part, const json_t *group, const char *ptr);
/* The groups' materials and joint sets of document part i, which is model
 * part `index` (i unless an earlier part was refused). */
int case_add_part_groups(case_doc *doc, fdem_model *model, int i, int index);
void case_part_groups_free(case_part *part);

/* ----------------------------------------------------- pass 2 and pass 3 */
/* Adds a problem when the model would pass memory_limit; returns the estimate. */
double case_check_memory(case_doc *doc, size_t memory_limit);
int case_add_materials(case_doc *doc, fdem_model *model);
int case_add_parts(case_doc *doc, fdem_model *model);
/* stages_added: the stages are in the model, so stage constraints can go
 * too (without them they are left out: the stages' problem is reported). */
int case_add_constraints(case_doc *doc, fdem_model *model, int stages_added);

/* case_probe.c: after pass 1 found problems, adds the /time/dt one a build
 * would find too, from a scratch model of the parts without problems;
 * whether a problem from index `from` on is at `base` or below it; whether
 * part i (its shape, material and all) read without one. */
void case_probe_dt(case_doc *doc, int from, size_t memory_limit, case_memory_gate gate,
                   void *gate_ctx);
int case_problem_under(const problems *p, int from, const char *base);
int case_part_sound(const case_doc *doc, int i, int from);

/* case_boxes.c: after pass 1, whatever it found (and before case_probe_dt,
 * which takes the meshes), the region and excavation boxes that hold no
 * element centroid, each a problem at its selector; meshes the generated
 * shapes a box needs within memory_limit. */
void case_check_boxes(case_doc *doc, int from, size_t memory_limit);
/* case_memory.c: the estimated bytes of one part as a model of its own. */
double case_part_bytes(const case_doc *doc, case_part *part);
/* case_region.c: the centroid of element t of the part's mesh (dim numbers). */
void case_element_centroid(const case_doc *doc, const case_part *part, int t, double *c);

/* case_history.c: "history" (pass 1), its row count against time.end
 * (after time), its points located in the built model (pass 3: 1, or 0
 * after a problem at each point outside every body) and copied to info. */
void case_read_history(case_doc *doc, const json_t *history);
void case_check_history_rows(case_doc *doc);
int case_locate_history(case_doc *doc, const fdem_model *model);
void case_fill_history_info(const case_doc *doc, case_info *info);
/* case_warnings.c: case_warnings() on a tree already parsed. */
int case_warnings_of(const json_t *root, problems *out);

/* The pointer of part i's mesh source ("/parts/3/mesh" or "/parts/3/gmsh"). */
void case_part_mesh_pointer(const case_doc *doc, int part, char *ptr);

#endif
