/*
 * fluid.h - fluid in the fractures (contract 6.4, docs/physics.md "Fluid in
 * fractures"): the flow network of a model's joints, both dimensions.
 *
 * Every joint is a cavity. A cavity is in the network (open) while its
 * joint is damaged or broken, carries a pore pressure, or is a source of
 * an "inject" constraint; an intact joint is sealed. A bore (an "inject"
 * with def.bore, fluid_bore.c) is one more cavity after the joints: its
 * wall is the constraint's boundary facets, its volume the space they
 * enclose, its pressure presses on them, and it is linked to the joints
 * that meet the wall, so fluid enters a wall joint once it opens. Neighbouring open
 * cavities (2D: joints sharing a mesh vertex; 3D: joints sharing an edge)
 * exchange fluid by the cubic law. What the cavity holds is a fluid
 * volume (its mass over the fluid's density): the pressure follows from it
 * and the cavity's volume, p = K_f (V_fluid / V_cavity - 1), never below
 * the cavity's floor (0, or a negative pore pressure), so mass is kept to
 * round-off whatever the cavity does. The pressure pushes both faces of
 * every open joint apart.
 *
 * Contract:
 *  - fluid_prepare (finalize, after the constraints are selected): the
 *    cavities' parameters (aperture0, pore pressure: the joint's set's
 *    fracture parameters, else its material's), the links, the sources;
 *    fails with the constraint named when an injection touches no joint.
 *  - fluid_step (each step, after the joint loop, before contact): books
 *    the fluid's work of the last step, evaluates each open cavity on the
 *    positions x_n, adds p S / dim to each node of face B and its negative
 *    to face A (equal and opposite: momentum to round-off), then moves the
 *    fluid over the step h by explicit flow, subcycled at the flow's own
 *    stable step where it is smaller than h.
 *  - Nothing here runs for a model without fluid (model.fluid NULL).
 *  - A single thread walks every loop in a fixed order: the same bits on
 *    any thread count.
 * The per-dimension geometry of a joint's face and a link's width lives in
 * fluid_face_2d.c and fluid_face_3d.c; the rest is shared.
 */
#ifndef FDEM_FLUID_H
#define FDEM_FLUID_H

#include <stddef.h>
#include <stdint.h>

#include "model/model.h"

/* Two cavities that exchange fluid; conductance = geometry a^3 / (12 mu),
 * geometry = w / l: the shared edge's width (1 in 2D) over the distance
 * between the two cavities' centres (initial positions). a < b; when b is
 * a bore, l runs from the joint's centre to the wall and a is the joint's
 * aperture (the bore is no constriction). */
typedef struct fluid_link {
    int32_t a, b;
    double geometry;
} fluid_link;

/* The geometry of a joint's mean face on the current positions: its area
 * vector (length: the area, per unit thickness in 2D; pointing out of
 * element A, towards B) and its mean normal opening. */
typedef struct fluid_face {
    double area[3];
    double opening;
} fluid_face;

typedef struct fluid_net {
    double viscosity, bulk_modulus, density;
    int joints;
    int bores, cavities;  /* cavities = joints, then the bores */
    /* per cavity (joints + bores) */
    double *fluid;       /* fluid volume (mass / density) */
    double *pressure;    /* of the last evaluation */
    double *volume;      /* cavity volume of the last evaluation: aperture times area */
    double *aperture;    /* hydraulic aperture of the last evaluation */
    double *aperture0;   /* of the joint's fracture parameters */
    double *floor;       /* lowest pressure: 0, or the pore pressure when it is negative */
    double *centre;      /* dim per cavity: the centre of face A at t = 0 */
    double *force;       /* dim per cavity: p S / dim, what each node of face B got */
    double *inflow;      /* scratch: fluid volume in per subcycle */
    double *conductance; /* scratch: per link */
    double *outgoing;    /* scratch: per cavity, the sum of its links' conductances */
    uint8_t *wet;        /* pore pressure or source: open from t = 0 */
    uint8_t *open;       /* in the network this step */
    int link_count;
    fluid_link *links;
    int32_t *link_begin;  /* joints + 1 offsets into link_of: each cavity's links */
    int32_t *link_of;     /* 2 per link, cavity by cavity */
    /* this step's network, so the flow costs what is open, not the model:
     * the open cavities in joint order and the links between two of them */
    int open_count, active_count;
    int32_t *open_list, *active;
    /* sources: joints touching an "inject" constraint's nodes */
    int source_count;
    int32_t *source_joint, *source_constraint;
    double *source_share; /* 1 / the number of joints the constraint touches */
    double *constraint_injected; /* per constraint: the volume it injected since t = 0 (history) */
    /* bores: the constraint whose boundary facets (model.bfacet_*) are its
     * wall, the point its volume is measured from, and per facet of the
     * model the force the bore's pressure put on each of its nodes */
    int32_t *bore_constraint;
    double *bore_origin;  /* dim per bore */
    double *bore_axis;    /* dim per bore: the axis a slab's wall is open along, else 0 */
    double *wall_force;   /* dim per boundary facet (bores' facets only) */
    /* the wall's corners: each wall vertex (node_origin) is one corner, at
     * the mean of the node copies on the wall there (a fracturing part
     * has a copy per element), so the wall stays closed when a wall joint
     * opens; wall_corner: per node of each boundary facet (bores' only) */
    int corner_count;
    int32_t *wall_corner, *corner_begin, *corner_node;
    double *corner_pos;   /* dim per corner, of the last evaluation */
    /* accounts */
    double injected;      /* volume injected since t = 0 */
    double work_booked;   /* the fluid's work on the solid up to the start of the last step */
    double power_old;     /* sum F . v_old of the last step's forces */
    double dissipation;   /* viscous */
    double restored_work; /* the work reported when the checkpoint read last was written */
    double flow_step;     /* the flow's stable step, last evaluation (INFINITY: no flow) */
    int subcycles;        /* flow steps in the last mechanical step */
} fluid_net;

/* fluid_network.c */
int fluid_prepare(fdem_model *m, fdem_error *err);
void fluid_free(fdem_model *m);
size_t fluid_memory_bytes(const fdem_model *m);
/* the flow step and cavity state on the current positions without
 * stepping (finalize, a restored checkpoint) */
void fluid_refresh(fdem_model *m);

/* fluid_flow.c */
void fluid_step(fdem_model *m, double h);
/* the pressures' forces on the positions at t = 0, added to m->force
 * (energy.c: the accelerations the energy reference needs) */
void fluid_forces_at_rest(fdem_model *m);
/* the fluid's work on the solid up to x_n (energy.c), and up to x_n+1 with
 * the last step completed on the current velocities (what the next step
 * books first: a checkpoint stores it) */
double fluid_work_reported(const fdem_model *m);
double fluid_work_completed(const fdem_model *m);

/* fluid_bore.c: the bores, cavities joints .. cavities - 1 */
int fluid_bores_count(fdem_model *m, fluid_net *f, fdem_error *err);
void fluid_bores_init(fdem_model *m, fluid_net *f);
void fluid_bore_measure(fdem_model *m, fluid_net *f, int b, int with_forces);
double fluid_bores_power(const fdem_model *m, const fluid_net *f);
double fluid_bores_stable_dt(const fdem_model *m, fluid_net *f);
/* The keys of every bore's wall facets, each with its bore's cavity
 * (fluid_bore_key_count of them at most), and the point a key stands for
 * at t = 0 (a vertex, an edge's middle): where a wall link starts. */
int fluid_bore_key_count(const fdem_model *m, const fluid_net *f);
int fluid_bore_keys(const fdem_model *m, const fluid_net *f, int32_t (*keys)[2], int32_t *cavity);
void fluid_key_point(const fdem_model *m, const int32_t key[2], double *x);

/* fluid_checkpoint.c: the fluid section of a checkpoint (version 9 on;
 * version 10 adds each constraint's injected volume, 11 each bore's fluid
 * volume), as written by a file of `version` */
size_t fluid_checkpoint_size(const fdem_model *m, unsigned version);
void fluid_checkpoint_write(const fdem_model *m, unsigned char *p);
void fluid_checkpoint_read(fdem_model *m, const unsigned char *p, unsigned version);

/* fluid_face_2d.c, fluid_face_3d.c: the dimension's kernel */
void fluid_face_2d(const fdem_model *m, int j, fluid_face *out);
void fluid_face_3d(const fdem_model *m, int j, fluid_face *out);
/* The keys a joint shares with its neighbours (2D: its two vertices, the
 * second of each pair -1; 3D: its three edges as sorted vertex pairs) and
 * their count. */
int fluid_keys_2d(const fdem_model *m, int j, int32_t keys[3][2]);
int fluid_keys_3d(const fdem_model *m, int j, int32_t keys[3][2]);
/* The same of a boundary facet of nodes n (a bore's wall). */
int fluid_facet_keys_2d(const fdem_model *m, const int32_t *n, int32_t keys[3][2]);
int fluid_facet_keys_3d(const fdem_model *m, const int32_t *n, int32_t keys[3][2]);
/* The width of a link through key (1 in 2D, the edge's initial length in
 * 3D). */
double fluid_key_width_2d(const fdem_model *m, const int32_t key[2]);
double fluid_key_width_3d(const fdem_model *m, const int32_t key[2]);

/* A cavity's pressure from its fluid and its volume of the last
 * evaluation, never below its floor. */
static inline double fluid_cavity_pressure(const fluid_net *f, int j)
{
    double p = f->bulk_modulus * (f->fluid[j] / f->volume[j] - 1);
    return p > f->floor[j] ? p : f->floor[j];
}

static inline void fluid_face_of(const fdem_model *m, int j, fluid_face *out)
{
    if (m->dim == 3) fluid_face_3d(m, j, out);
    else fluid_face_2d(m, j, out);
}

#endif
