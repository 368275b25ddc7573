/*
 * element.h - the element stage of both dimensions: preparing each element
 * (inverse edge matrix, size, damping), its stable step, the element
 * forces of a step through the scatter plan (with the in-situ pre-stress
 * and the kept forces of fixed parts), and each element's stress. The
 * shared stage (element.c) calls each dimension's kernel on the model:
 * element_tri.c for triangles, element_tet_model.c for tetrahedra over the
 * pure kernel in kernel/element_tet.h. Calls nothing above it; the step
 * (step/), finalize (build/) and analysis/ call it.
 */
#ifndef FDEM_ELEMENT_H
#define FDEM_ELEMENT_H

#include "model/model.h"
#include "parallel/scatter_plan.h"

/* initial_stress.c: evaluates each stressed part's field at its elements'
 * initial centroids into elem_stress0 and stress0_energy, marks the parts
 * (0, or -1 out of memory); the stable step's factor for the geometric
 * stiffness of a tensile pre-stress (1 for elements without) */
int initial_stress_prepare(fdem_model *m, fdem_error *err);
double initial_stress_dt_factor(const fdem_model *m, int e);
/* the energy the in-situ stress holds at t = 0 in the active elements
 * (stress0_energy, summed as initial_stress_prepare sums it) */
double initial_stress_energy(const fdem_model *m);

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


/* The element loop of part p's elements: its dimension's kernel, with the
 * pre-stress where the part has one (element.c, fixed_part.c). */
scatter_block_fn element_forces_loop_of(const fdem_model *m, const part *p);

#endif
