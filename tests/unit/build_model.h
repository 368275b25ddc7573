/*
 * build_model.h - short-hands for building engine models in tests: a
 * material from four numbers, a rectangle or disc part in one call. Every
 * failure aborts the test binary with the engine's message, so a test never
 * silently runs on half a model.
 */
#ifndef FDEM_BUILD_MODEL_H
#define FDEM_BUILD_MODEL_H

#include <stdio.h>
#include <stdlib.h>

#include "fdem.h"

static inline void build_die(const char *what, const fdem_error *err)
{
    fprintf(stderr, "model set-up failed in %s: %s\n", what, err->message);
    exit(2);
}

static inline int build_material(fdem_model *m, double rho, double E, double nu, double damping,
                                 double friction)
{
    fdem_material_def d = {0};
    d.density = rho;
    d.young = E;
    d.poisson = nu;
    d.damping = damping;
    d.friction = friction;
    fdem_error err;
    int k = fdem_add_material(m, &d, &err);
    if (k < 0) build_die("material", &err);
    return k;
}

/* A rectangle part; fracture != 0 makes it breakable along its interior
 * edges (the material needs fracture parameters then). */
static inline int build_rectangle_part(fdem_model *m, int mat, double x, double y, double w,
                                       double h, int nx, int ny, int fracture)
{
    fdem_mesh mesh;
    fdem_error err;
    if (fdem_mesh_rectangle(x, y, w, h, nx, ny, &mesh, &err)) build_die("rectangle", &err);
    int p = fdem_add_part(m, &mesh, mat, fracture, &err);
    fdem_mesh_free(&mesh);
    if (p < 0) build_die("rectangle part", &err);
    return p;
}

static inline int build_rectangle(fdem_model *m, int mat, double x, double y, double w, double h,
                                  int nx, int ny)
{
    return build_rectangle_part(m, mat, x, y, w, h, nx, ny, 0);
}

static inline int build_disc(fdem_model *m, int mat, double x, double y, double r, int divisions)
{
    fdem_mesh mesh;
    fdem_error err;
    if (fdem_mesh_disc(x, y, r, divisions, &mesh, &err)) build_die("disc", &err);
    int p = fdem_add_part(m, &mesh, mat, 0, &err);
    fdem_mesh_free(&mesh);
    if (p < 0) build_die("disc part", &err);
    return p;
}

static inline void build_fix_part(fdem_model *m, int part)
{
    fdem_constraint_def c = {0};
    c.select = FDEM_SELECT_PART;
    c.part = part;
    c.kind = FDEM_CONSTRAINT_FIX;
    c.fix_x = c.fix_y = 1;
    fdem_error err;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("constraint", &err);
}

static inline void build_finalize(fdem_model *m, double safety)
{
    fdem_error err;
    if (fdem_model_finalize(m, &err)) build_die("finalize", &err);
    fdem_set_dt(m, safety * fdem_stable_dt(m));
}

static inline void run_until(fdem_model *m, double t_end)
{
    fdem_error err;
    while (fdem_get_time(m) < t_end)
        if (fdem_step(m, &err)) build_die("step", &err);
}

/* Mass-weighted mean position (and velocity) of one part. */
static inline void part_centre(const fdem_model *m, int part, double c[2], double v[2])
{
    const double *x = fdem_positions(m), *u = fdem_velocities(m), *ms = fdem_node_masses(m);
    const int32_t *np = fdem_node_parts(m);
    double M = 0;
    c[0] = c[1] = 0;
    if (v) v[0] = v[1] = 0;
    for (int i = 0; i < fdem_get_counts(m).nodes; i++) {
        if (np[i] != part) continue;
        M += ms[i];
        c[0] += ms[i] * x[2 * i];
        c[1] += ms[i] * x[2 * i + 1];
        if (v) { v[0] += ms[i] * u[2 * i]; v[1] += ms[i] * u[2 * i + 1]; }
    }
    c[0] /= M; c[1] /= M;
    if (v) { v[0] /= M; v[1] /= M; }
}

#endif
