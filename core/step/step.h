/*
 * step.h - one step of the central-difference scheme and what it applies:
 * the integrator (integrator.c: the order of a step and fdem_step),
 * constraints (constraint.c: fixed, velocity, force and amplitude-driven
 * dofs), boundary pressures, stresses, tractions and absorbing dashpots
 * (boundary_load.c), and the energy accounts the step books (energy.c,
 * fdem_get_energy). Calls the element, contact and joint stages; finalize
 * (build/) and checkpoints call it.
 */
#ifndef FDEM_STEP_H
#define FDEM_STEP_H

#include "model/model.h"

/* constraint.c */
int constraint_selects(const fdem_model *m, const constraint *c, int node);
void constraint_set_time(fdem_model *m, double velocity_time);
int constraint_select(fdem_model *m, fdem_error *err);
void constraint_apply_forces(fdem_model *m);
void constraint_enforce(fdem_model *m, double h, double havg);


/* constraint.c: the owned copy of a vertex selection */
int constraint_keep_vertices(constraint *c);

/* boundary_load.c: pressures, boundary stresses, tractions and absorbing
 * dashpots on boundary facets */
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

#endif
