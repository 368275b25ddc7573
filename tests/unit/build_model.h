/*
 * build_model.h - short-hands for building engine models in tests: a
 * material from four numbers, a rectangle or disc part in one call. Every
 * failure aborts the test binary with the engine's message, so a test never
 * silently runs on half a model.
 */
#ifndef FDEM_BUILD_MODEL_H
#define FDEM_BUILD_MODEL_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "fdem.h"
#include "mesh/mesh_3d.h"

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

/* A rock that can fracture: 2700 kg/m^3, E = 30 GPa, nu = 0.25, friction
 * 0.3, tensile strength 1 MPa, cohesion 3 MPa, friction angle 30 degrees,
 * G_I = 10 and G_II = 50 J/m^2 (the strengths and energies of the
 * Brazilian disc example). */
static inline int build_fracturing_rock(fdem_model *m, double damping)
{
    fdem_material_def d = {.density = 2700, .young = 3e10, .poisson = 0.25, .damping = damping,
                           .friction = 0.3, .has_fracture = 1,
                           .fracture = {1e6, 3e6, 30, 10, 50}};
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

/* A box part origin + [0, size] in the model's dimension: 2D size[0] x
 * size[1] in div[0] x div[1] squares of two triangles, 3D size in div
 * cubes of six tetrahedra; fracture != 0 puts a joint on every interior
 * edge or face. */
static inline int build_box_at(fdem_model *m, int mat, int dim, const double origin[3],
                               const double size[3], const int div[3], int fracture)
{
    if (dim == 2)
        return build_rectangle_part(m, mat, origin[0], origin[1], size[0], size[1], div[0], div[1],
                                    fracture);
    fdem_tet_mesh mesh = {0};
    fdem_error err = {0};
    if (fdem_tet_mesh_box(origin, size, div, &mesh, &err)) build_die("box mesh", &err);
    int p = fdem_add_part_3d(m, &mesh, mat, fracture, &err);
    fdem_tet_mesh_free(&mesh);
    if (p < 0) build_die("box part", &err);
    return p;
}

/* The same box from the origin. */
static inline int build_box_part(fdem_model *m, int mat, int dim, const double size[3],
                                 const int div[3], int fracture)
{
    const double origin[3] = {0, 0, 0};
    return build_box_at(m, mat, dim, origin, size, div, fracture);
}

/* Reproducible noise for tests: the next number of a 64-bit linear
 * congruential state (Knuth's MMIX constants), uniform in [-1, 1). */
static inline double build_uniform(uint64_t *state)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*state >> 11) * 0x1.0p-53 * 2 - 1;
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
    c.fix_z = fdem_get_dimension(m) == 3;
    fdem_error err;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("constraint", &err);
}

static inline void build_finalize(fdem_model *m, double safety)
{
    fdem_error err;
    if (fdem_model_finalize(m, &err)) build_die("finalize", &err);
    fdem_set_dt(m, fdem_auto_dt(m, safety)); /* a case's "auto" */
}

/* Discs of radius r in hexagonal packing at a spacing of 1.97 r: the
 * 16-gon's flats sit at 0.981 r, so neighbours start touching and the pile
 * is loaded by gravity from the first step (timed as a packed pile, not a
 * falling cloud). Walls are meshed as finely as the discs: NBS sizes its
 * cells by the largest element, and coarse walls would crowd many disc
 * elements into each cell. Used by the bench and the thread tests. */
static inline fdem_model *build_disc_pile(int columns, int rows)
{
    fdem_model *m = fdem_model_create();
    int wall = build_material(m, 1000, 1e7, 0.25, 0.1, 0.3);
    int disc = build_material(m, 1000, 1e7, 0.25, 0.2, 0.3);
    double r = 0.01, d = 1.97 * r, W = columns * d + 0.5 * d + 0.001;
    double H = rows * d * 0.8660254 + 0.05;
    int fl = build_rectangle(m, wall, -0.02, -0.02, W + 0.04, 0.02, (int)((W + 0.04) / 0.004), 5);
    int le = build_rectangle(m, wall, -0.02, 0, 0.02, H, 5, (int)(H / 0.004));
    int ri = build_rectangle(m, wall, W, 0, 0.02, H, 5, (int)(H / 0.004));
    build_fix_part(m, fl);
    build_fix_part(m, le);
    build_fix_part(m, ri);
    for (int row = 0; row < rows; row++)
        for (int col = 0; col < columns; col++)
            build_disc(m, disc, 0.0005 + r + col * d + (row % 2) * 0.5 * d,
                       0.981 * r + row * d * 0.8660254, r, 16);
    fdem_set_gravity(m, 0, -9.81);
    build_finalize(m, 0.5);
    return m;
}

/* Two undamped, frictionless blocks, 8x4 and 5x4 cells, about to meet at
 * 5 m/s (the first also drifting up at 0.1 m/s): the collision test case of
 * the contact and the energy tests. */
static inline fdem_model *build_colliding_blocks(int *a, int *b)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 2700, 1e9, 0.25, 0, 0);
    *a = build_rectangle(m, mat, 0, 0, 0.1, 0.05, 8, 4);
    *b = build_rectangle(m, mat, 0.1002, 0.01, 0.06, 0.05, 5, 4);
    fdem_set_part_velocity(m, *a, 2.0, 0.1, NULL);
    fdem_set_part_velocity(m, *b, -3.0, 0, NULL);
    build_finalize(m, 0.5);
    return m;
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
