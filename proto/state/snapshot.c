/*
 * snapshot.c - copies a model's state at one step boundary into plain
 * buffers the caller owns.
 *
 * Why a copy: the worker thread keeps stepping while the I/O thread writes
 * the copy to HDF5 or an HTTP thread turns it into JSON, and the engine's
 * accessors only stay valid until the next fdem_step().
 *
 * Damage is copied whenever the model has joints, requested or not, because
 * the result file stores it for every fracturing model (contract section 4);
 * the CASE_FIELD_DAMAGE bit in `fields` says whether the caller asked for it
 * (state_to_json shows only what was asked for).
 *
 * Displacement is not engine state: it is position - initial position,
 * computed here per number, so it is exactly what a reader of result.h5
 * gets by subtracting /mesh/position0 from /snapshots/position, and asking
 * for it reads the model without changing it.
 */
#include "snapshot.h"

#include <stdlib.h>
#include <string.h>

#include "case/case.h"

/* malloc + memcpy of `count` doubles; a zero count gives NULL, not an error. */
static double *copy_doubles(const double *src, size_t count, int *failed)
{
    if (count == 0 || !src) return NULL;
    double *dst = malloc(count * sizeof *dst);
    if (!dst) {
        *failed = 1;
        return NULL;
    }
    memcpy(dst, src, count * sizeof *dst);
    return dst;
}

/* A per-element field the engine computes into a buffer of `values`. */
static double *copy_element_field(const fdem_model *model, size_t values,
                                  void (*compute)(const fdem_model *, double *), int *failed)
{
    if (values == 0) return NULL;
    double *dst = malloc(values * sizeof *dst);
    if (!dst) {
        *failed = 1;
        return NULL;
    }
    compute(model, dst);
    return dst;
}

/* position - initial position of every node, one subtraction per number
 * (the bits a reader gets from /snapshots/position - /mesh/position0). */
static double *node_displacements(const fdem_model *model, size_t count, int *failed)
{
    const double *x = fdem_positions(model), *x0 = fdem_initial_positions(model);
    if (count == 0 || !x || !x0) return NULL;
    double *u = malloc(count * sizeof *u);
    if (!u) {
        *failed = 1;
        return NULL;
    }
    for (size_t i = 0; i < count; i++) u[i] = x[i] - x0[i];
    return u;
}

static int32_t *copy_fragment_labels(const fdem_model *model, size_t elements, int *failed)
{
    int32_t *label = malloc((elements ? elements : 1) * sizeof *label);
    if (!label || fdem_fragment_labels(model, label) < 0) {
        free(label);
        *failed = 1;
        return NULL;
    }
    return label;
}

/* Every element's flag: the engine's, or all 1 while it keeps none (no
 * element excavated yet). */
static uint8_t *copy_active(const fdem_model *model, size_t elements, int *failed)
{
    uint8_t *active = malloc(elements ? elements : 1);
    if (!active) {
        *failed = 1;
        return NULL;
    }
    const uint8_t *flags = fdem_element_active(model);
    if (flags) memcpy(active, flags, elements);
    else memset(active, 1, elements);
    return active;
}

snapshot *snapshot_take(const fdem_model *model, unsigned fields)
{
    if (!model) return NULL;
    snapshot *s = calloc(1, sizeof *s);
    if (!s) return NULL;

    fdem_counts counts = fdem_get_counts(model);
    s->step = fdem_get_step(model);
    s->time = fdem_get_time(model);
    s->nodes = counts.nodes;
    s->elements = counts.elements;
    s->joints = counts.joints;
    s->constraints = counts.constraints;
    s->dimension = fdem_get_dimension(model);
    s->stress_components = fdem_stress_components(model);
    s->energy = fdem_get_energy(model);

    int failed = 0;
    size_t dim = (size_t)s->dimension;
    size_t nodes = (size_t)counts.nodes, elements = (size_t)counts.elements;
    if (fields & CASE_FIELD_POSITION) {
        s->position = copy_doubles(fdem_positions(model), dim * nodes, &failed);
        if (s->position) s->fields |= CASE_FIELD_POSITION;
    }
    if (fields & CASE_FIELD_VELOCITY) {
        s->velocity = copy_doubles(fdem_velocities(model), dim * nodes, &failed);
        if (s->velocity) s->fields |= CASE_FIELD_VELOCITY;
    }
    if (fields & CASE_FIELD_STRESS) {
        s->stress = copy_element_field(model, (size_t)s->stress_components * elements,
                                       fdem_element_stress, &failed);
        if (s->stress) s->fields |= CASE_FIELD_STRESS;
    }
    if (fields & CASE_FIELD_STRAIN) {
        s->strain = copy_element_field(model, (size_t)s->stress_components * elements,
                                       fdem_element_strain, &failed);
        if (s->strain) s->fields |= CASE_FIELD_STRAIN;
    }
    if (fields & CASE_FIELD_PRINCIPAL_STRESS) {
        s->principal_stress = copy_element_field(model, dim * elements,
                                                 fdem_element_principal_stress, &failed);
        if (s->principal_stress) s->fields |= CASE_FIELD_PRINCIPAL_STRESS;
    }
    if (fields & CASE_FIELD_DISPLACEMENT) {
        s->displacement = node_displacements(model, dim * nodes, &failed);
        if (s->displacement) s->fields |= CASE_FIELD_DISPLACEMENT;
    }
    s->fragment = copy_fragment_labels(model, elements, &failed);
    if (fields & SNAPSHOT_FRAGMENTS) {
        s->fragment_count = fdem_fragments(model, &s->fragments);
        if (s->fragment_count < 0) failed = 1;
        else s->fields |= SNAPSHOT_FRAGMENTS;
    }
    if (counts.joints > 0) {
        /* an excavated joint shows the damage it had then (not 1: it did
         * not break); /snapshots/active says it is gone */
        s->damage = malloc((size_t)counts.joints * sizeof *s->damage);
        if (s->damage) fdem_copy_joint_damage(model, s->damage);
        else failed = 1;
        if (s->damage && (fields & CASE_FIELD_DAMAGE)) s->fields |= CASE_FIELD_DAMAGE;
    }
    if (counts.joints > 0 && fdem_get_fluid(model).enabled) {
        s->fluid_pressure = copy_doubles(fdem_fluid_pressure(model), (size_t)counts.joints,
                                         &failed);
        s->aperture = malloc(sizeof(double) * (size_t)counts.joints);
        if (s->aperture) fdem_fluid_apertures(model, s->aperture);
        else failed = 1;
    }
    s->constraint_force = copy_doubles(fdem_constraint_forces(model),
                                       dim * (size_t)counts.constraints, &failed);
    s->stage = fdem_stage_index(model);
    if (s->stage >= 0) s->active = copy_active(model, elements, &failed);
    if (failed) {
        snapshot_free(s);
        return NULL;
    }
    return s;
}

void snapshot_free(snapshot *s)
{
    if (!s) return;
    free(s->position);
    free(s->velocity);
    free(s->stress);
    free(s->damage);
    free(s->fluid_pressure);
    free(s->aperture);
    free(s->strain);
    free(s->principal_stress);
    free(s->displacement);
    free(s->fragment);
    free(s->fragments);
    free(s->constraint_force);
    free(s->active);
    free(s);
}
