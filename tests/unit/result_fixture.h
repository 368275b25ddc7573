/*
 * result_fixture.h - a small real model for the snapshot and result tests:
 * a fixed 4x2 rock block under gravity and, optionally, a fracturing 2x1
 * slab above it (so the model has joints) pushed by a force constraint; a
 * 3D box of tetrahedra for the 3D layout; and the block in two stages.
 * Small on purpose: the tests compare every number, and must stay fast.
 */
#ifndef RESULT_FIXTURE_H
#define RESULT_FIXTURE_H

#include <stdio.h>
#include <string.h>

#include "case/case.h"
#include "fdem.h"
#include "mesh/mesh_3d.h"

static inline int fixture_add_block(fdem_model *m, double ox, double oy, double w, double h, int nx,
                             int ny, int material, int fracture, fdem_error *err)
{
    fdem_mesh mesh = {0};
    if (fdem_mesh_rectangle(ox, oy, w, h, nx, ny, &mesh, err) < 0) return -1;
    int part = fdem_add_part(m, &mesh, material, fracture, err);
    fdem_mesh_free(&mesh);
    return part;
}

/* Sets dt = 0.5 x stable and fills `info` (when not NULL) as case_build
 * would: 1000 steps, a snapshot every 5, position, velocity, stress, strain,
 * principal_stress and displacement. */
static inline void fixture_info(fdem_model *m, case_info *info, const char *name, int parts,
                         int constraints, int fracture)
{
    fdem_set_dt(m, 0.5 * fdem_stable_dt(m));
    if (!info) return;
    memset(info, 0, sizeof *info);
    snprintf(info->name, sizeof info->name, "%s", name);
    info->dt = fdem_get_dt(m);
    info->stable_dt = fdem_stable_dt(m);
    info->end_time = 1000 * info->dt;
    info->safety = 0.5;
    info->output_interval = 5 * info->dt;
    info->fields = CASE_FIELD_POSITION | CASE_FIELD_VELOCITY | CASE_FIELD_STRESS |
                   CASE_FIELD_STRAIN | CASE_FIELD_PRINCIPAL_STRESS | CASE_FIELD_DISPLACEMENT;
    info->part_count = parts;
    info->constraint_count = constraints;
    info->fracture = fracture;
}

/* Returns a finalized model with dt = 0.5 x stable, or NULL (printing why).
 * `fracturing` adds the breakable slab, `constraints` the two constraints. */
static inline fdem_model *fixture_model(int fracturing, int constraints, case_info *info)
{
    fdem_error err = {0};
    fdem_model *m = fdem_model_create();
    fdem_material_def rock = {.density = 2700, .young = 3e10, .poisson = 0.25,
                              .damping = 0.0, .penalty = 3e11, .friction = 0.5,
                              .has_fracture = 1,
                              .fracture = {.tensile_strength = 5e6, .cohesion = 2e7,
                                           .friction_angle = 30, .energy_I = 20,
                                           .energy_II = 100}};
    int mat = m ? fdem_add_material(m, &rock, &err) : -1;
    int ok = mat >= 0 && fixture_add_block(m, 0, 0, 0.4, 0.2, 4, 2, mat, 0, &err) >= 0;
    if (ok && fracturing) ok = fixture_add_block(m, 0, 0.21, 0.4, 0.1, 2, 1, mat, 1, &err) >= 0;
    if (ok && constraints) {
        fdem_constraint_def fix = {.select = FDEM_SELECT_BOX, .box = {-1, -0.001, 1, 0.001},
                                   .kind = FDEM_CONSTRAINT_FIX, .fix_x = 1, .fix_y = 1};
        fdem_constraint_def push = {.select = FDEM_SELECT_PART, .part = 0,
                                    .kind = FDEM_CONSTRAINT_FORCE, .value = {1e5, -2e5}};
        ok = fdem_add_constraint(m, &fix, &err) >= 0 && fdem_add_constraint(m, &push, &err) >= 0;
    }
    if (ok) {
        fdem_set_gravity(m, 0, -9.81);
        ok = fdem_model_finalize(m, &err) >= 0;
    }
    if (!ok) {
        fprintf(stderr, "  fixture model: %s\n", err.message);
        fdem_model_destroy(m);
        return NULL;
    }
    fixture_info(m, info, "fixture \"block\" & <slab>", fracturing ? 2 : 1,
                 constraints ? 2 : 0, fracturing);
    if (info) info->fields |= CASE_FIELD_DAMAGE;
    return m;
}

/* The 3D counterpart: one 0.4 x 0.2 x 0.2 m box of 4 x 2 x 2 cells (six
 * tetrahedra each) under gravity along -z, fixed at z = 0 and, with
 * `constraints`, pushed by a force; one part, so no contact is needed. */
static inline fdem_model *fixture_model_3d(int constraints, case_info *info)
{
    fdem_error err = {0};
    fdem_model *m = fdem_model_create();
    fdem_material_def rock = {.density = 2700, .young = 3e10, .poisson = 0.25};
    fdem_tet_mesh box = {0};
    const double origin[3] = {0, 0, 0}, size[3] = {0.4, 0.2, 0.2};
    const int div[3] = {4, 2, 2};
    int ok = m && fdem_set_dimension(m, 3, &err) == 0;
    int mat = ok ? fdem_add_material(m, &rock, &err) : -1;
    ok = mat >= 0 && fdem_tet_mesh_box(origin, size, div, &box, &err) == 0 &&
         fdem_add_part_3d(m, &box, mat, 0, &err) >= 0;
    fdem_tet_mesh_free(&box);
    if (ok && constraints) {
        fdem_constraint_def fix = {.select = FDEM_SELECT_BOX, .box = {-1, -1, -0.001, 1, 1, 0.001},
                                   .kind = FDEM_CONSTRAINT_FIX, .fix_x = 1, .fix_y = 1,
                                   .fix_z = 1};
        fdem_constraint_def push = {.select = FDEM_SELECT_PART, .part = 0,
                                    .kind = FDEM_CONSTRAINT_FORCE, .value = {1e5, -2e5, 3e5}};
        ok = fdem_add_constraint(m, &fix, &err) >= 0 && fdem_add_constraint(m, &push, &err) >= 0;
    }
    if (ok) {
        const double g[3] = {0, 0, -9.81};
        fdem_set_gravity_v(m, g);
        ok = fdem_model_finalize(m, &err) >= 0;
    }
    if (!ok) {
        fprintf(stderr, "  3D fixture model: %s\n", err.message);
        fdem_model_destroy(m);
        return NULL;
    }
    fixture_info(m, info, "fixture box", 1, constraints ? 2 : 0, 0);
    return m;
}

/* The 4x2 block of fixture_model, fixed at its base, in two stages
 * (contract 6.1): "in-situ" ends at 1e-7 s, within the first step, and
 * "dig" removes its two last triangles at the start of the second. */
static inline fdem_model *fixture_model_staged(case_info *info)
{
    fdem_error err = {0};
    fdem_model *m = fdem_model_create();
    fdem_material_def rock = {.density = 2700, .young = 3e10, .poisson = 0.25};
    int mat = m ? fdem_add_material(m, &rock, &err) : -1;
    int ok = mat >= 0 && fixture_add_block(m, 0, 0, 0.4, 0.2, 4, 2, mat, 0, &err) >= 0;
    const int32_t dig[2] = {14, 15};
    fdem_stage_def first = {.end = 1e-7}, second = {.end = 1.0, .excavate = dig,
                                                    .excavate_count = 2};
    fdem_constraint_def fix = {.select = FDEM_SELECT_BOX, .box = {-1, -0.001, 1, 0.001},
                               .kind = FDEM_CONSTRAINT_FIX, .fix_x = 1, .fix_y = 1};
    ok = ok && fdem_add_stage(m, &first, &err) == 0 && fdem_add_stage(m, &second, &err) == 1 &&
         fdem_add_constraint(m, &fix, &err) >= 0 && fdem_model_finalize(m, &err) >= 0;
    if (!ok) {
        fprintf(stderr, "  staged fixture model: %s\n", err.message);
        fdem_model_destroy(m);
        return NULL;
    }
    fixture_info(m, info, "staged", 1, 1, 0);
    if (info) {
        info->stage_count = 2;
        snprintf(info->stage_names[0], sizeof info->stage_names[0], "in-situ");
        snprintf(info->stage_names[1], sizeof info->stage_names[1], "dig");
    }
    return m;
}

/* Steps n times; returns 0 or -1 (printing the engine's error). */
static inline int fixture_step(fdem_model *m, int n)
{
    fdem_error err = {0};
    for (int i = 0; i < n; i++)
        if (fdem_step(m, &err) < 0) {
            fprintf(stderr, "  fixture step: %s\n", err.message);
            return -1;
        }
    return 0;
}

#endif
