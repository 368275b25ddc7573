/*
 * history.c - taking a history row (history.h) and turning rows into the
 * JSON of GET /cases/ID/history.
 *
 * A row is one malloc: the header and its four arrays after it, so the
 * worker hands the I/O thread one pointer and the cost of a row is a few
 * hundred bytes, not a snapshot's copy of every node.
 */
#include "history.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

const char *const history_energy_names[HISTORY_ENERGY_TERMS] = {
    "kinetic", "elastic", "joint", "contact", "friction", "fracture",
    "damping", "gravity_work", "external_work", "excavated", "residual",
};

const char *const history_fluid_energy_names[HISTORY_FLUID_ENERGY_TERMS] = {
    "fluid_work", "fluid_dissipation",
};

static void energy_terms(const fdem_energy *e, double *out)
{
    const double terms[HISTORY_ENERGY_TERMS] = {
        e->kinetic, e->elastic, e->joint, e->contact, e->friction, e->fracture,
        e->damping, e->gravity_work, e->external_work, e->excavated, e->residual,
    };
    memcpy(out, terms, sizeof terms);
}

history_row *history_alloc(int dimension, int points, int constraints, int fluid)
{
    size_t D = (size_t)dimension, P = (size_t)(points > 0 ? points : 0);
    size_t C = (size_t)(constraints > 0 ? constraints : 0);
    size_t doubles = 2 * D * P + 2 * D * C + (fluid ? 2 * C : 0);
    history_row *row = calloc(1, sizeof *row + doubles * sizeof(double));
    if (!row) return NULL;
    double *at = (double *)(row + 1);
    row->dimension = dimension;
    row->points = (int)P;
    row->constraints = (int)C;
    row->point_displacement = at;
    row->point_velocity = at + D * P;
    row->constraint_force = at + 2 * D * P;
    row->constraint_displacement = at + 2 * D * P + D * C;
    row->fluid = fluid != 0;
    if (fluid) {
        row->source_pressure = at + 2 * D * P + 2 * D * C;
        row->injected_volume = row->source_pressure + C;
    }
    return row;
}

void history_free(history_row *row) { free(row); }

history_row *history_take(const fdem_model *model, const int32_t *point_nodes, int points)
{
    int D = fdem_get_dimension(model);
    int C = fdem_get_counts(model).constraints;
    int fluid = fdem_has_fluid(model); /* O(1): fdem_get_fluid sums every joint */
    history_row *row = history_alloc(D, points, C, fluid);
    if (!row) return NULL;
    row->step = fdem_get_step(model);
    row->time = fdem_get_time(model);
    const double *x = fdem_positions(model), *x0 = fdem_initial_positions(model);
    const double *v = fdem_velocities(model);
    for (int p = 0; p < points; p++) {
        size_t at = (size_t)D * (size_t)point_nodes[p];
        for (int d = 0; d < D; d++) {
            row->point_displacement[D * p + d] = x[at + d] - x0[at + d];
            row->point_velocity[D * p + d] = v[at + d];
        }
    }
    const double *force = fdem_constraint_forces(model);
    if (C > 0) memcpy(row->constraint_force, force, sizeof(double) * (size_t)(D * C));
    for (int c = 0; c < C; c++) {
        int n = fdem_constraint_node_count(model, c);
        const int32_t *nodes = fdem_constraint_nodes(model, c);
        double sum[3] = {0, 0, 0};
        for (int k = 0; nodes && k < n; k++)
            for (int d = 0; d < D; d++)
                sum[d] += x[(size_t)D * nodes[k] + d] - x0[(size_t)D * nodes[k] + d];
        for (int d = 0; d < D; d++) row->constraint_displacement[D * c + d] = n > 0 ? sum[d] / n : 0;
    }
    fdem_energy e = fdem_get_energy(model);
    energy_terms(&e, row->energy);
    if (fluid) {
        fdem_fluid_sources(model, row->source_pressure, row->injected_volume);
        row->fluid_energy[0] = e.fluid_work;
        row->fluid_energy[1] = e.fluid_dissipation;
    }
    return row;
}

/* ----------------------------------------------------------------- JSON */

static json_t *number(double x) { return isfinite(x) ? json_real(x) : json_null(); }

/* rows of `count` vectors of `dimension`: [[x, y], ...] */
static json_t *vectors(const double *a, int count, int dimension)
{
    json_t *list = json_array();
    for (int i = 0; list && i < count; i++) {
        json_t *v = json_array();
        for (int d = 0; v && d < dimension; d++) json_array_append_new(v, number(a[dimension * i + d]));
        json_array_append_new(list, v);
    }
    return list;
}

/* [x, ...] of `count` scalars, null where not finite */
static json_t *scalars(const double *a, int count)
{
    json_t *list = json_array();
    for (int i = 0; list && i < count; i++) json_array_append_new(list, number(a[i]));
    return list;
}

static json_t *row_json(const history_row *r)
{
    json_t *energy = json_object();
    for (int k = 0; energy && k < HISTORY_ENERGY_TERMS; k++)
        json_object_set_new(energy, history_energy_names[k], number(r->energy[k]));
    for (int k = 0; energy && r->fluid && k < HISTORY_FLUID_ENERGY_TERMS; k++)
        json_object_set_new(energy, history_fluid_energy_names[k], number(r->fluid_energy[k]));
    json_t *o = json_pack("{s:o, s:I, s:{s:o, s:o}, s:o, s:o, s:o}", "time", number(r->time),
                     "step", (json_int_t)r->step, "points", "displacement",
                     vectors(r->point_displacement, r->points, r->dimension), "velocity",
                     vectors(r->point_velocity, r->points, r->dimension), "constraint_force",
                     vectors(r->constraint_force, r->constraints, r->dimension),
                     "constraint_displacement",
                     vectors(r->constraint_displacement, r->constraints, r->dimension),
                     "energy", energy);
    if (o && r->fluid)
        json_object_set_new(o, "fluid",
                            json_pack("{s:o, s:o}", "source_pressure",
                                      scalars(r->source_pressure, r->constraints),
                                      "injected_volume",
                                      scalars(r->injected_volume, r->constraints)));
    return o;
}

json_t *history_rows_json(history_row *const *rows, int count, const history_names *names)
{
    json_t *list = json_array(), *point_names = json_array();
    for (int p = 0; point_names && names && p < names->count; p++)
        json_array_append_new(point_names, json_string(names->name[p]));
    for (int i = 0; list && i < count; i++) json_array_append_new(list, row_json(rows[i]));
    return json_pack("{s:o, s:o}", "names", point_names, "rows", list);
}
