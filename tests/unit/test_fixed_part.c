/*
 * test_fixed_part.c - parts held still as a whole keep their element
 * forces (fixed_part.c), each test in both dimensions:
 *  - which parts qualify: fixed in every component by fix constraints and
 *    loaded by nothing else; a part fixed in some components, or held by a
 *    zero velocity, or under a pressure or a point force, or with joints,
 *    does not;
 *  - a block dropped on a fixed base that carries an in-situ stress steps
 *    as the same model that computes every element every step: the same
 *    positions and velocities to the bit, the base's reaction and the
 *    elastic and damping energies to 1e-12 (only the order of a sum
 *    changes). The base's in-situ stress holds most of the elastic energy
 *    and pushes on its supports, so a kept part that lost its forces or
 *    its energy fails here;
 *  - the kept figures are the same bits on 1 and 2 threads and after a
 *    restart from a checkpoint (they are computed again there).
 */
#include <stdlib.h>
#include <string.h>

#include "build_model.h"
#include "check.h"
#include "model/model.h"

enum { STEPS = 160, CHECKPOINT_AT = 70 };

static void fix(fdem_model *m, int p, int x, int y, int z)
{
    fdem_constraint_def c = {.select = FDEM_SELECT_PART, .part = p,
                             .kind = FDEM_CONSTRAINT_FIX, .fix_x = x, .fix_y = y, .fix_z = z};
    fdem_error err;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("fix", &err);
}

static void load(fdem_model *m, int p, fdem_constraint_kind kind)
{
    fdem_constraint_def c = {.select = FDEM_SELECT_PART, .part = p, .kind = kind};
    if (kind == FDEM_CONSTRAINT_PRESSURE) c.value[0] = 1e3;
    if (kind == FDEM_CONSTRAINT_FORCE) c.value[0] = 1;
    fdem_error err;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("load", &err);
}

/* Fixes the nodes of the base (those below 0.0502 m; the block's lowest
 * are at 0.0505) with x below `cut` (lower) or above it. */
static void fix_side(fdem_model *m, double cut, int lower)
{
    const int D = m->dim;
    fdem_constraint_def c = {.select = FDEM_SELECT_BOX, .kind = FDEM_CONSTRAINT_FIX,
                             .fix_x = 1, .fix_y = 1, .fix_z = D == 3};
    for (int d = 0; d < D; d++) {
        c.box[d] = -1;
        c.box[D + d] = 1;
    }
    c.box[2 * D - 1] = 0.0502;
    if (lower) c.box[D] = cut;
    else c.box[0] = cut;
    fdem_error err;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("fix", &err);
}

/* A base slab [0, 0.2] x [0, 0.05] (2D; 3D [0, 0.2] x [0, 0.2] x [0, 0.05])
 * under an in-situ compression, fixed in every component by two supports,
 * left of x = CUT and right of it; and a damped block just above it
 * falling at 1 m/s under gravity (the last axis is up). *base gets the
 * slab's part. */
#define CUT 0.09
#define SIGMA (-1e5)
static fdem_model *block_on_base(int dim, int *base)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_material(m, 1000, 1e7, 0.25, 0.2, 0); /* frictionless: see below */
    const double o[3] = {0, 0, 0};
    const double slab2[3] = {0.2, 0.05}, at2[3] = {0.05, 0.0505}, box2[3] = {0.1, 0.05};
    const double slab3[3] = {0.2, 0.2, 0.05}, at3[3] = {0.05, 0.05, 0.0505},
                 box3[3] = {0.1, 0.1, 0.05};
    const int slab_div[3] = {8, dim == 3 ? 8 : 2, 2}, box_div[3] = {4, dim == 3 ? 4 : 2, 2};
    *base = build_box_at(m, mat, dim, o, dim == 3 ? slab3 : slab2, slab_div, 0);
    int block = build_box_at(m, mat, dim, dim == 3 ? at3 : at2, dim == 3 ? box3 : box2, box_div, 0);
    double value[6] = {SIGMA, SIGMA, dim == 3 ? SIGMA : 0, 0, 0, 0}, gradient[6] = {0};
    if (fdem_set_part_initial_stress(m, *base, value, gradient, 0, &err))
        build_die("initial stress", &err);
    fix_side(m, CUT, 1);
    fix_side(m, CUT, 0);
    double v[3] = {0, 0, 0}, g[3] = {0, 0, 0};
    v[dim - 1] = -1;
    g[dim - 1] = -9.81;
    if (fdem_set_part_velocity_v(m, block, v, &err)) build_die("velocity", &err);
    fdem_set_gravity_v(m, g);
    build_finalize(m, 0.5);
    return m;
}

static void step_to(fdem_model *m, int step)
{
    fdem_error err;
    while (fdem_get_step(m) < step)
        if (fdem_step(m, &err)) build_die("step", &err);
}

static void which_parts_are_fixed(int dim)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    fdem_material_def d = {.density = 2700, .young = 3e10, .poisson = 0.25, .friction = 0.3,
                           .has_fracture = 1, .fracture = {1e6, 3e6, 30, 10, 50}};
    int mat = fdem_add_material(m, &d, &err);
    const double size[3] = {0.1, 0.1, 0.1};
    const int div[3] = {2, 2, 2};
    int p[7];
    for (int k = 0; k < 7; k++) {
        const double o[3] = {0.2 * k, 0, 0};
        p[k] = build_box_at(m, mat, dim, o, size, div, k == 6);
    }
    fix(m, p[0], 1, 1, 1);                             /* held still */
    fix(m, p[1], 1, dim == 3, 0);                      /* a component free */
    fdem_constraint_def zero = {.select = FDEM_SELECT_PART, .part = p[2],
                                .kind = FDEM_CONSTRAINT_VELOCITY};
    if (fdem_add_constraint(m, &zero, &err) < 0) build_die("velocity", &err);
    fix(m, p[3], 1, 1, 1);                             /* and pressed */
    load(m, p[3], FDEM_CONSTRAINT_PRESSURE);
    fix(m, p[4], 1, 1, 1);                             /* and pushed */
    load(m, p[4], FDEM_CONSTRAINT_FORCE);
    fix(m, p[5], 1, 0, 0);                             /* two fixes make it whole */
    fix(m, p[5], 0, 1, dim == 3);
    fix(m, p[6], 1, 1, 1);                             /* jointed */
    build_finalize(m, 0.5);
    const int want[7] = {1, 0, 0, 0, 0, 1, 0};
    for (int k = 0; k < 7; k++)
        CHECK(m->parts[p[k]].fixed == want[k], "%dD part %d: fixed %d, want %d", dim, k,
              m->parts[p[k]].fixed, want[k]);
    CHECK(m->fixed_parts == 2, "%dD: %d fixed parts, want 2", dim, m->fixed_parts);
    fdem_model_destroy(m);
}

/* What a comparison of two runs of block_on_base looks at: both supports'
 * reactions and the energy accounts. */
typedef struct run_figures {
    double reaction[2][3];
    fdem_energy energy;
} run_figures;

static run_figures figures_of(fdem_model *m)
{
    run_figures f = {{{0}}, fdem_get_energy(m)};
    const double *r = fdem_constraint_forces(m);
    for (int k = 0; k < 2; k++) memcpy(f.reaction[k], r + k * m->dim, sizeof(double) * (size_t)m->dim);
    return f;
}

static int same_state(const fdem_model *a, const fdem_model *b)
{
    size_t bytes = sizeof(double) * (size_t)a->dim * (size_t)a->node_count;
    return memcmp(a->pos, b->pos, bytes) == 0 && memcmp(a->vel, b->vel, bytes) == 0;
}

/* The in-situ stress pushes on each support with sigma_xx times the
 * slab's section (the divergence theorem on the supports' shape functions:
 * exact for linear elements), so the kept forces must be on the right
 * nodes: dropped, both reactions would be near zero. The block lands
 * without friction, so it adds nothing along x. */
static void kept_forces_step_as_computed_ones(int dim)
{
    int base;
    fdem_model *kept = block_on_base(dim, &base), *computed = block_on_base(dim, &base);
    CHECK(kept->parts[base].fixed && kept->fixed_parts == 1, "%dD: the base is not fixed", dim);
    computed->fixed_parts = 0; /* every element every step, as before fixed_part.c */
    step_to(kept, STEPS);
    step_to(computed, STEPS);
    CHECK(same_state(kept, computed), "%dD: positions or velocities differ at step %d", dim, STEPS);
    run_figures k = figures_of(kept), c = figures_of(computed);
    double section = dim == 3 ? 0.2 * 0.05 : 0.05, push = SIGMA * section;
    for (int s = 0; s < 2; s++) {
        CHECK_NEAR(k.reaction[s][0], s ? push : -push, 1e-3 * fabs(push));
        for (int d = 0; d < dim; d++) CHECK_NEAR(k.reaction[s][d], c.reaction[s][d], 1e-12 * fabs(push));
    }
    /* the block rests on the base by now: the supports carry it */
    CHECK(c.reaction[0][dim - 1] + c.reaction[1][dim - 1] > 1, "%dD: the block is not on the base", dim);
    CHECK_REL(k.energy.elastic, c.energy.elastic, 1e-12);
    CHECK_REL(k.energy.damping, c.energy.damping, 1e-12);
    CHECK(c.energy.damping > 0, "%dD: no damping to compare", dim);
    fdem_model_destroy(kept);
    fdem_model_destroy(computed);
}

static void kept_forces_are_the_bits_of_any_thread_count_and_restart(int dim)
{
    int base;
    fdem_model *one = block_on_base(dim, &base), *two = block_on_base(dim, &base),
               *restored = block_on_base(dim, &base);
    fdem_set_threads(two, 2);
    step_to(one, CHECKPOINT_AT);
    size_t size = fdem_checkpoint_size(one);
    void *state = malloc(size);
    fdem_error err;
    if (!state || fdem_checkpoint_write(one, state, size)) build_die("checkpoint", &err);
    if (fdem_checkpoint_read(restored, state, size, &err)) build_die("restore", &err);
    free(state);
    step_to(one, STEPS);
    step_to(two, STEPS);
    step_to(restored, STEPS);
    run_figures a = figures_of(one), b = figures_of(two), r = figures_of(restored);
    CHECK(same_state(one, two) && memcmp(&a, &b, sizeof a) == 0,
          "%dD: 2 threads differ from 1 (elastic %.17g / %.17g)", dim, b.energy.elastic,
          a.energy.elastic);
    CHECK(same_state(one, restored) && memcmp(&a, &r, sizeof a) == 0,
          "%dD: the restored run differs (elastic %.17g / %.17g, reaction %.17g / %.17g)", dim,
          r.energy.elastic, a.energy.elastic, r.reaction[0][0], a.reaction[0][0]);
    fdem_model_destroy(one);
    fdem_model_destroy(two);
    fdem_model_destroy(restored);
}

static void which_parts_are_fixed_2d(void) { which_parts_are_fixed(2); }
static void which_parts_are_fixed_3d(void) { which_parts_are_fixed(3); }
static void kept_forces_step_as_computed_2d(void) { kept_forces_step_as_computed_ones(2); }
static void kept_forces_step_as_computed_3d(void) { kept_forces_step_as_computed_ones(3); }
static void kept_bits_threads_restart_2d(void)
{
    kept_forces_are_the_bits_of_any_thread_count_and_restart(2);
}
static void kept_bits_threads_restart_3d(void)
{
    kept_forces_are_the_bits_of_any_thread_count_and_restart(3);
}

CHECK_MAIN(T(which_parts_are_fixed_2d), T(which_parts_are_fixed_3d),
           T(kept_forces_step_as_computed_2d), T(kept_forces_step_as_computed_3d),
           T(kept_bits_threads_restart_2d), T(kept_bits_threads_restart_3d))
