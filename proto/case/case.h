/*
 * case.h - the case document (contract section 3) turned into a finalized
 * engine model.
 *
 * Contract:
 *  - case_build() parses with JSON_REJECT_DUPLICATES; malformed JSON is one
 *    400 problem; otherwise every problem in the document is collected (not
 *    only the first) with its JSON Pointer and the model is not built (422).
 *  - A case whose model would exceed memory_limit bytes (estimated before
 *    building) is rejected with 422 saying how large it would be.
 *  - time.dt "auto" = fdem_auto_dt(safety); a number above the stable
 *    step is rejected with 422 naming the stable value.
 *  - On success the model is finalized, its dt set, and `info` filled.
 *  - "stages" (contract 6.1, case_stages.c): the engine gets each stage's
 *    end, relax and excavated element indices (fdem_add_stage) and every
 *    stage constraint with def.only_stage = k + 1, after the top-level
 *    ones; info gets the stage names (the engine has none) and, when
 *    time.end is left out, the last stage's end as end_time.
 *
 * Folder proto/case/, the case document -> engine model: owns this header
 * (case_build(), case_info, the CASE_FIELD_* bits, case_parse_fields()) and
 * the passes behind it, case*.c sharing case_internal.h, with case.c on top
 * (no case file calls back into it). May call core/ (the engine),
 * proto/json/ (problem lists, JSON Pointers) and proto/gmsh/ (gmsh parts and
 * their named groups). Called by proto/result/ and proto/state/ (case_info,
 * CASE_FIELD_*), server/, the unit tests, the fuzzers and scripts/limits.c.
 */
#ifndef FDEM_CASE_H
#define FDEM_CASE_H

#include <stddef.h>
#include <stdint.h>
#include "fdem.h"
#include "json/problems.h"

enum case_field {
    CASE_FIELD_POSITION = 1u << 0,
    CASE_FIELD_VELOCITY = 1u << 1,
    CASE_FIELD_STRESS   = 1u << 2,
    CASE_FIELD_DAMAGE   = 1u << 3,
    CASE_FIELD_STRAIN   = 1u << 4,
    CASE_FIELD_PRINCIPAL_STRESS = 1u << 5,
    /* position - initial position per node, computed when a snapshot is
     * taken (snapshot.c), never stored in the engine */
    CASE_FIELD_DISPLACEMENT = 1u << 6,
};

#define CASE_MAX_PARTS 1024
/* Snapshots a case may ask for, and how many an output.interval left out
 * gives (interval = time.end / CASE_DEFAULT_SNAPSHOTS). */
#define CASE_MAX_SNAPSHOTS 1e6
/* Steps a case may take (time.end / dt). At a million steps a second this
 * is twelve days of one core; beyond it a run is a typo (time.end 1e308,
 * time.dt 5e-324), and a step below the rounding of the time (about 1e-16
 * of it) would never advance it at all. */
#define CASE_MAX_STEPS 1e12
/* Largest initial stress accepted, Pa: a million times the strength of any
 * rock or steel. Above it the stress is a typo, and its square (the energy
 * it stores) or its effect on the stable step is not finite. */
#define CASE_MAX_INITIAL_STRESS 1e15
#define CASE_DEFAULT_SNAPSHOTS 100
/* Stages a case may have (contract 6.1 "Stages"), and the room for a
 * stage's name with its NUL. The names live in case_info (the status and
 * GET /state name the current stage), so both are bounded. */
#define CASE_MAX_STAGES 256
#define CASE_STAGE_NAME 64
/* History output (contract 6.2, case_history.c): monitoring points a case
 * may have, the room for a point's name with its NUL, and the rows an
 * interval may ask for (as many as snapshots: each row is a few numbers
 * per point and constraint). */
#define CASE_MAX_HISTORY_POINTS 64
#define CASE_HISTORY_NAME 64
/* The most ranks a case may ask for in "parallel" (the daemon's --max-ranks
 * is usually far lower). */
#define CASE_MAX_RANKS 65536
/* Room in case_info for the part and material names: 64 names of 127
 * bytes, or many more short ones. */
#define CASE_NAMES_BYTES 8192
#define CASE_MAX_HISTORY_ROWS 1e6

typedef struct case_info {
    char name[128];
    double end_time;        /* time.end */
    double dt;              /* the step in use */
    double stable_dt;       /* fdem_stable_dt() of the model */
    double safety;          /* time.safety (default 0.5) */
    double output_interval; /* simulated seconds between snapshots */
    unsigned fields;        /* CASE_FIELD_* written to snapshots */
    int part_count;
    int constraint_count;
    int ranks;              /* "parallel": {"ranks"} (contract 6.5), 1 without it */
    int fracture;           /* some part fractures */
    int stage_count;        /* entries of "stages" (0: the case has none) */
    char stage_names[CASE_MAX_STAGES][CASE_STAGE_NAME]; /* each stage's "name" */
    /* "history": seconds between rows, 0 when the case has no "history"
     * (rows are then taken at every snapshot); each point's name and the
     * engine node nearest it at t = 0. */
    double history_interval;
    int history_point_count;
    char history_names[CASE_MAX_HISTORY_POINTS][CASE_HISTORY_NAME];
    int32_t history_nodes[CASE_MAX_HISTORY_POINTS];
    /* The names behind result.h5's part and material indices (its
     * /mesh/part_names and /mesh/material_names, result_describe.c), read
     * by the builder so that nobody parses the document again for them:
     * part_count part names in "parts" order (an unnamed part is
     * "part<i>"), then material_count material names in the order of
     * "materials", each ending in a NUL. names_bytes is 0 when they do not
     * fit (result_describe() then reads them from the document). */
    int material_count;
    int names_bytes;
    char names[CASE_NAMES_BYTES];
} case_info;

/* The name of stage `index` of the case, or NULL when it has no such stage
 * (index -1: the case has no stages). */
const char *case_stage_name(const case_info *info, int index);

fdem_model *case_build(const char *text, size_t length, size_t memory_limit,
                       case_info *info, problems *out);

/* Asked, once the document is read and before anything is built, whether
 * `bytes` (the model's estimated size) may be allocated now; nonzero means
 * no: case_build_gated() then builds nothing and reports one problem with
 * status 503 (the daemon is short of memory at the moment, the case itself
 * is fine). */
typedef int (*case_memory_gate)(void *ctx, double bytes);

/* case_build() with a gate; the JSON tree is freed before the model is built
 * (never both at once). `warnings` (may be NULL) gets the document's
 * warnings (case_warnings) from the same tree, when the document reads
 * without a problem: one parse for both. */
fdem_model *case_build_gated(const char *text, size_t length, size_t memory_limit,
                             case_memory_gate gate, void *gate_ctx,
                             case_info *info, problems *out, problems *warnings);

/* Adds to `out` (status left 0) the values of an accepted case document
 * far outside rock and steel, each once at its JSON Pointer (contract 6.2
 * "Warnings", case_warnings.c); returns how many. Never a refusal. It
 * parses the text; case_build_gated() gives the same list without a second
 * parse. */
int case_warnings(const char *text, size_t length, problems *out);

/* Parses "position,velocity,..." (the ?fields= of GET /state) into
 * CASE_FIELD_* bits; unknown names are added to `out` (400). */
unsigned case_parse_fields(const char *csv, problems *out);

#endif
