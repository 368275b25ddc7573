/*
 * test_energy.c - the energy accounts close (contract 5.1, PHYSICS.md
 * "Energy accounting"): on a collision, a damped bar, a fracturing bar
 * pulled apart and a block sliding with friction, the residual
 *   kinetic + elastic + joint + contact + friction + fracture + damping
 *   - gravity_work - external_work - (kinetic + elastic at t = 0)
 * stays under 1 % of the energy that went through the model at every step,
 * and each account has the sign and size its physics gives it.
 *
 * "Energy that went through the model" is the largest of the initial
 * energy, the gravity work and the external work seen so far: the scale a
 * user compares the residual with.
 */
#include "build_model.h"
#include "check.h"
#include "model/model.h"

typedef struct balance {
    double worst;  /* largest |residual| / scale seen */
    double scale;  /* energy through the model */
    double at;     /* time of the worst */
} balance;

static void balance_watch(const fdem_model *m, balance *b)
{
    fdem_energy en = fdem_get_energy(m);
    double through = fmax(m->initial_energy, fmax(fabs(en.gravity_work), fabs(en.external_work)));
    if (through > b->scale) b->scale = through;
    if (b->scale > 0 && fabs(en.residual) / b->scale > b->worst) {
        b->worst = fabs(en.residual) / b->scale;
        b->at = fdem_get_time(m);
    }
}

static void run_watched(fdem_model *m, double t_end, balance *b)
{
    fdem_error err;
    while (fdem_get_time(m) < t_end) {
        if (fdem_step(m, &err)) build_die("step", &err);
        balance_watch(m, b);
    }
}

static void print_accounts(const char *name, const fdem_model *m, const balance *b)
{
    fdem_energy en = fdem_get_energy(m);
    fprintf(stderr,
            "  %s: kinetic %.6g elastic %.6g joint %.6g contact %.6g friction %.6g fracture %.6g "
            "damping %.6g gravity %.6g external %.6g; worst residual %.3g %% of %.6g J/m at "
            "t = %.3g s\n",
            name, en.kinetic, en.elastic, en.joint, en.contact, en.friction, en.fracture,
            en.damping, en.gravity_work, en.external_work, 100 * b->worst, b->scale, b->at);
}

/* Two undamped, frictionless blocks meet and part: everything kinetic goes
 * through the contact penalty and back. */
static void collision_closes_the_balance(void)
{
    int a, b;
    fdem_model *m = build_colliding_blocks(&a, &b);
    balance bal = {0};
    run_watched(m, 0.004, &bal);
    print_accounts("collision", m, &bal);
    CHECK(fdem_get_counts(m).detections > 0, "no detection");
    CHECK(bal.worst < 0.01, "residual %.3g %% of the energy", 100 * bal.worst);
    fdem_model_destroy(m);
}

/* A cantilevered bar swinging with 10 % damping: the damping account takes
 * what the oscillation loses. */
static void damped_bar_closes_the_balance(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 2000, 1e8, 0.25, 0.1, 0);
    int bar = build_rectangle(m, mat, 0, 0, 1.0, 0.1, 40, 4);
    fdem_constraint_def c = {.select = FDEM_SELECT_BOX, .box = {-0.001, -1, 0.001, 1},
                             .kind = FDEM_CONSTRAINT_FIX, .fix_x = 1, .fix_y = 1};
    fdem_error err;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("constraint", &err);
    fdem_set_part_velocity(m, bar, 0, 0.5, NULL);
    build_finalize(m, 0.5);
    balance bal = {0};
    run_watched(m, 0.05, &bal);
    print_accounts("damped bar", m, &bal);
    fdem_energy en = fdem_get_energy(m);
    CHECK(en.damping > 0.05 * m->initial_energy, "damping took only %g of %g J/m", en.damping,
          m->initial_energy);
    CHECK(bal.worst < 0.01, "residual %.3g %% of the energy", 100 * bal.worst);
    fdem_model_destroy(m);
}

/* Drives the nodes in the box [x0, x1] x [y0, y1] at velocity (vx, vy)
 * (a 2D box is lower x, y then upper x, y). */
static void drive_box(fdem_model *m, double x0, double y0, double x1, double y1, double vx,
                      double vy)
{
    fdem_constraint_def c = {.select = FDEM_SELECT_BOX, .box = {x0, y0, x1, y1},
                             .kind = FDEM_CONSTRAINT_VELOCITY, .value = {vx, vy}};
    fdem_error err;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("constraint", &err);
}

/* A fracturing bar whose ends are pulled apart: the work of the supports
 * goes into the joints, the crack (G_I per unit area at least once across
 * the bar) and the pieces' motion. */
static void fracturing_bar_closes_the_balance(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_fracturing_rock(m, 0);
    const double L = 0.1, H = 0.02;
    build_rectangle_part(m, mat, 0, 0, L, H, 20, 4, 1);
    drive_box(m, -0.001, -1, 0.0001, 1, -0.2, 0);
    drive_box(m, L - 0.0001, -1, L + 0.001, 1, 0.2, 0);
    build_finalize(m, 0.5);
    balance bal = {0};
    run_watched(m, 4e-4, &bal);
    print_accounts("fracturing bar", m, &bal);
    fdem_energy en = fdem_get_energy(m);
    CHECK(m->broken_joints > 0, "the bar did not break");
    CHECK(en.fracture >= 0.98 * 10 * H, "fracture %g J/m, a crack across is %g", en.fracture,
          10 * H);
    CHECK(bal.worst < 0.01, "residual %.3g %% of the energy", 100 * bal.worst);
    fdem_model_destroy(m);
}

/* A fracturing block pressed (0.5 m/s) and sheared (0.2 m/s) between two
 * driven edges fails in shear, and its joints slide under a compression
 * that keeps changing. The frictional part of their shear strength,
 * sigma_c tan(phi), is booked as friction where they slide. When the joints'
 * stored energy followed that strength instead (so it changed with the
 * compression, which does no such work), 13.8 % of the work went to no
 * account (docs/physics.md, "Energy accounting"). Damage is still booked
 * alone in `fracture`, which never decreases, and friction never goes
 * below zero. */
static fdem_model *sheared_block(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_fracturing_rock(m, 0.6);
    const double W = 0.01, H = 0.02;
    build_rectangle_part(m, mat, 0, 0, W, H, 4, 8, 1);
    drive_box(m, -1, -0.001, 1, 0.0001, 0, 0);
    drive_box(m, -1, H - 0.0001, 1, H + 0.001, 0.2, -0.5);
    build_finalize(m, 0.5);
    return m;
}

static void sheared_block_under_compression_closes_the_balance(void)
{
    fdem_model *m = sheared_block();
    fdem_error err;
    balance bal = {0};
    double fracture = 0, least_friction = 0;
    int fracture_fell = 0;
    while (fdem_get_time(m) < 2e-4) {
        if (fdem_step(m, &err)) build_die("step", &err);
        balance_watch(m, &bal);
        fdem_energy en = fdem_get_energy(m);
        fracture_fell += en.fracture < fracture;
        fracture = en.fracture;
        least_friction = fmin(least_friction, en.friction);
    }
    print_accounts("sheared block", m, &bal);
    CHECK(m->broken_joints > 0, "the block did not break");
    CHECK(m->joint_friction_energy > 0.05 * fdem_get_energy(m).external_work,
          "the joints' friction took only %g J/m", m->joint_friction_energy);
    CHECK(fracture_fell == 0, "the fracture account fell in %d steps", fracture_fell);
    CHECK(least_friction >= 0, "the friction account went down to %g J/m", least_friction);
    CHECK(bal.worst < 0.01, "residual %.3g %% of the energy", 100 * bal.worst);
    fdem_model_destroy(m);
}

/* The joints' friction is carried by a checkpoint (version 3): a model
 * restored mid-failure books on to the same bits. A version 2 file (its
 * header without that total) is still read, the total restarting at 0. */
static void checkpoint_carries_the_joints_friction(void)
{
    fdem_model *a = sheared_block(), *b = sheared_block();
    fdem_error err;
    while (fdem_get_time(a) < 4e-5)
        if (fdem_step(a, &err)) build_die("step", &err);
    CHECK(a->joint_friction_energy > 0, "no joint slid yet");
    size_t size = fdem_checkpoint_size(a);
    unsigned char *buf = malloc(size);
    CHECK(fdem_checkpoint_write(a, buf, size) == 0, "write");
    CHECK(fdem_checkpoint_read(b, buf, size, &err) == 0, "%s", err.message);
    for (int s = 0; s < 500; s++) {
        fdem_step(a, &err);
        fdem_step(b, &err);
    }
    fdem_energy ea = fdem_get_energy(a), eb = fdem_get_energy(b);
    CHECK(memcmp(&ea, &eb, sizeof ea) == 0, "energies differ after restore: friction %.17g %.17g",
          ea.friction, eb.friction);
    /* version 2: the same bytes less the header's last three numbers (joint
     * friction, version 3; pending events, version 4; time's carry,
     * version 6) and the sections after the springs (version 4: each
     * joint's fracture account, the events not drained; version 7: the
     * slip its points keep) */
    size_t v2_header = sizeof(uint32_t) * 2 + 4 * sizeof(int32_t) + sizeof(int64_t) +
                       10 * sizeof(double) + sizeof(int64_t) + 2 * sizeof(int32_t) +
                       sizeof(int64_t) + 2 * sizeof(int32_t) +
                       10 * sizeof(double); /* the accounts as fdem_energy had them to version 7 */
    size_t cut = 2 * sizeof(double) + sizeof(int64_t);
    size_t tail = sizeof(double) * (size_t)a->joint_count +
                  sizeof(fdem_event) * (size_t)a->event_count +
                  sizeof(joint_slip) * 2 * (size_t)a->joint_count;
    size_t old_size = size - cut - tail;
    unsigned char *old = malloc(old_size);
    memcpy(old, buf, v2_header);
    memcpy(old + v2_header, buf + v2_header + cut, old_size - v2_header);
    uint32_t two = 2;
    memcpy(old + sizeof(uint32_t), &two, sizeof two);
    CHECK(fdem_checkpoint_read(b, old, old_size, &err) == 0, "version 2: %s", err.message);
    CHECK(b->joint_friction_energy == 0, "version 2 restored %g J/m of joint friction",
          b->joint_friction_energy);
    free(old);
    free(buf);
    fdem_model_destroy(a);
    fdem_model_destroy(b);
}

CHECK_MAIN(T(collision_closes_the_balance), T(damped_bar_closes_the_balance),
           T(fracturing_bar_closes_the_balance),
           T(sheared_block_under_compression_closes_the_balance),
           T(checkpoint_carries_the_joints_friction))
