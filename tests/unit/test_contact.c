/*
 * test_contact.c - the distributed potential contact force against physics:
 * one overlapping pair (equal and opposite, no net moment, pushing apart),
 * a head-on collision (momentum to 1e-12, energy within 5%), a block sliding
 * on a 30 degree incline with Coulomb friction (1/2 g (sin - mu cos) t^2
 * within 5%, friction dissipating mu N s within 10 %), a block on a slope
 * its friction holds staying put for a second at two step sizes,
 * a 100-disc pile in a box settling with no disc through another, flat
 * impacts of shared-node and jointed blocks at the default safety and at
 * safety 1 (one step: the contact step) keeping their energy within 1 %,
 * the contact step's closed form, and "auto" taking safety x the
 * contact's limit up to the contact step.
 */
#include "build_model.h"
#include "check.h"
#include "model/model.h"

int contact_potential_force(fdem_model *m, int e1, int e2, double havg);
double contact_stable_dt(const fdem_model *m);

static void overlapping_pair_forces_balance(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 1000, 1e9, 0.25, 0, 0);
    double xy1[] = {0, 0, 1, 0, 0.3, 1}, xy2[] = {0.2, 0.8, 1.2, 0.7, 0.9, 1.9};
    int32_t tri[] = {0, 1, 2};
    fdem_mesh a = {3, 1, xy1, tri}, b = {3, 1, xy2, tri};
    fdem_error err;
    fdem_add_part(m, &a, mat, 0, &err);
    fdem_add_part(m, &b, mat, 0, &err);
    build_finalize(m, 0.5);
    memset(m->contact.force, 0, sizeof(double) * 12);
    CHECK(contact_potential_force(m, 0, 1, 1e-6) == 1, "no contact found");
    const double *f = m->contact.force;
    double fx = 0, fy = 0, moment = 0, scale = 0;
    for (int i = 0; i < 6; i++) {
        fx += f[2 * i];
        fy += f[2 * i + 1];
        moment += m->pos[2 * i] * f[2 * i + 1] - m->pos[2 * i + 1] * f[2 * i];
        scale = fmax(scale, hypot(f[2 * i], f[2 * i + 1]));
    }
    CHECK(scale > 0, "no force");
    CHECK(fabs(fx) < 1e-12 * scale && fabs(fy) < 1e-12 * scale, "net force %g %g", fx, fy);
    CHECK(fabs(moment) < 1e-12 * scale, "net moment %g", moment);
    /* the upper triangle is pushed up, the lower one down */
    CHECK(f[7] + f[9] + f[11] > 0, "upper triangle pushed %g", f[7] + f[9] + f[11]);
    fdem_model_destroy(m);
}

static void separated_pair_has_no_force(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 1000, 1e9, 0.25, 0, 0);
    double xy1[] = {0, 0, 1, 0, 0, 1}, xy2[] = {0.6, 0.6, 1.6, 0.6, 0.6, 1.6};
    int32_t tri[] = {0, 1, 2};
    fdem_mesh a = {3, 1, xy1, tri}, b = {3, 1, xy2, tri};
    fdem_error err;
    fdem_add_part(m, &a, mat, 0, &err);
    fdem_add_part(m, &b, mat, 0, &err);
    build_finalize(m, 0.5);
    memset(m->contact.force, 0, sizeof(double) * 12);
    CHECK(contact_potential_force(m, 0, 1, 1e-6) == 0, "touching although apart");
    fdem_model_destroy(m);
}

static void momentum(const fdem_model *m, double p[2], double *scale)
{
    const double *v = fdem_velocities(m), *ms = fdem_node_masses(m);
    p[0] = p[1] = 0;
    *scale = 0;
    for (int i = 0; i < fdem_get_counts(m).nodes; i++) {
        p[0] += ms[i] * v[2 * i];
        p[1] += ms[i] * v[2 * i + 1];
        *scale += ms[i] * hypot(v[2 * i], v[2 * i + 1]);
    }
}

static void collision_conserves_momentum_and_energy(void)
{
    int a, b;
    fdem_model *m = build_colliding_blocks(&a, &b);
    double p0[2], s0, p[2], s;
    momentum(m, p0, &s0);
    double e0 = fdem_get_energy(m).kinetic;
    fdem_error err;
    double va[2] = {0, 0}, vb[2] = {0, 0}, c[2];
    int touched = 0;
    for (long k = 0; k < 200000 && fdem_get_time(m) < 0.01; k++) {
        CHECK(fdem_step(m, &err) == 0, "%s", err.message);
        if (fdem_get_counts(m).contacts) touched = 1;
        part_centre(m, a, c, va);
        part_centre(m, b, c, vb);
        if (touched && !fdem_get_counts(m).contacts && vb[0] > va[0]) break;
    }
    CHECK(touched, "the blocks never touched");
    momentum(m, p, &s);
    CHECK(fabs(p[0] - p0[0]) <= 1e-12 * s0, "x momentum %.17g -> %.17g", p0[0], p[0]);
    CHECK(fabs(p[1] - p0[1]) <= 1e-12 * s0, "y momentum %.17g -> %.17g", p0[1], p[1]);
    CHECK(vb[0] > va[0], "still approaching: %g %g", va[0], vb[0]);
    fdem_energy en = fdem_get_energy(m);
    CHECK_REL(en.kinetic + en.elastic + en.contact, e0, 0.05);
    CHECK_REL(en.kinetic + en.elastic, e0, 0.05);
    fdem_model_destroy(m);
}

/* Gravity tilted by theta on a horizontal fixed slab: the block's slide is
 * 1/2 g (sin theta - mu cos theta) t^2. Returns the slide of the block's
 * centre; *friction gets the friction account, *normal the block's weight
 * normal to the slab (N/m). The block is damped (damping_block) so that its
 * landing on the slab does not ring for the whole run. */
static double incline_slide(double theta_deg, double mu, double t_end, double safety,
                            double damping_block, int nx, double *expected, double *friction,
                            double *normal)
{
    double th = theta_deg * M_PI / 180, g = 9.81;
    fdem_model *m = fdem_model_create();
    int slab_mat = build_material(m, 1000, 1e8, 0.25, 0.0, mu);
    int block_mat = build_material(m, 1000, 1e8, 0.25, damping_block, mu);
    int slab = build_rectangle(m, slab_mat, 0, -0.05, 0.6, 0.05, 4 * nx, 2);
    int block = build_rectangle(m, block_mat, 0.05, 0, 0.1, 0.05, nx, nx / 2);
    build_fix_part(m, slab);
    fdem_set_gravity(m, g * sin(th), -g * cos(th));
    build_finalize(m, safety);
    double c0[2], c[2];
    part_centre(m, block, c0, NULL);
    run_until(m, t_end);
    part_centre(m, block, c, NULL);
    double t = fdem_get_time(m);
    *expected = fmax(0, 0.5 * g * (sin(th) - mu * cos(th)) * t * t);
    *friction = fdem_get_energy(m).friction;
    *normal = 1000 * 0.1 * 0.05 * g * cos(th);
    fdem_model_destroy(m);
    return c[0] - c0[0];
}

/* Above its friction angle the block slides at g (sin - mu cos), and the
 * friction account holds mu N times the distance slid. */
static void block_slides_down_incline_with_friction(void)
{
    double want, friction, normal;
    double got = incline_slide(30, 0.3, 0.15, 0.5, 0.2, 6, &want, &friction, &normal);
    CHECK_REL(got, want, 0.05);
    CHECK_REL(friction, 0.3 * normal * got, 0.10);
    fprintf(stderr, "  incline 30 deg, mu 0.3: slide %.6g m, expected %.6g m (%.2f%%); friction "
            "%.6g J/m, mu N s = %.6g J/m\n", got, want, 100 * (got - want) / want, friction,
            0.3 * normal * got);
}

/* Below it the stick springs hold the block: over a whole second, at two
 * step sizes, it moves less than 10 micrometres (the viscous stick this
 * replaced crept at 0.07-1 mm/s, in proportion to the step). */
static void block_sticks_below_friction_angle(void)
{
    const double safety[2] = {0.5, 0.25};
    for (int k = 0; k < 2; k++) {
        double want, friction, normal;
        double got = incline_slide(20, 0.5, 1.0, safety[k], 0.2, 4, &want, &friction, &normal);
        CHECK(want == 0, "expected %g", want); /* tan 20 = 0.36 < 0.5 */
        CHECK(fabs(got) < 1e-5, "crept %g m in 1 s at safety %g", got, safety[k]);
        fprintf(stderr, "  incline 20 deg, mu 0.5, safety %.2f: moved %.3g m in 1 s\n", safety[k],
                got);
    }
}

static void disc_pile_settles_without_interpenetration(void)
{
    fdem_model *m = fdem_model_create();
    int wall = build_material(m, 1000, 1e6, 0.25, 0.1, 0.3);
    int disc = build_material(m, 1000, 1e6, 0.25, 0.3, 0.3);
    double r = 0.01, W = 0.22;
    int floor_p = build_rectangle(m, wall, -0.02, -0.02, W + 0.04, 0.02, 24, 2);
    int left = build_rectangle(m, wall, -0.02, 0, 0.02, 0.3, 2, 24);
    int right = build_rectangle(m, wall, W, 0, 0.02, 0.3, 2, 24);
    build_fix_part(m, floor_p);
    build_fix_part(m, left);
    build_fix_part(m, right);
    int first = -1, count = 0;
    for (int row = 0; row < 10; row++)
        for (int col = 0; col < 10; col++) {
            double x = 0.012 + col * 0.0215 + (row % 2) * 0.003, y = 0.0105 + row * 0.0205;
            int p = build_disc(m, disc, x, y, r * (0.9 + 0.1 * ((row * 7 + col * 3) % 5) / 4.0), 12);
            if (first < 0) first = p;
            count++;
        }
    fdem_set_gravity(m, 0, -9.81);
    build_finalize(m, 0.5);
    run_until(m, 0.25);
    fdem_energy en = fdem_get_energy(m);
    CHECK(en.kinetic < 0.02 * en.gravity_work, "still moving: kinetic %g of gravity work %g",
          en.kinetic, en.gravity_work);
    double centre[100][2];
    for (int k = 0; k < count; k++) part_centre(m, first + k, centre[k], NULL);
    double worst = 1;
    for (int i = 0; i < count; i++)
        for (int j = i + 1; j < count; j++) {
            double d = hypot(centre[i][0] - centre[j][0], centre[i][1] - centre[j][1]);
            worst = fmin(worst, d / (2 * r));
        }
    /* radii are 0.9r..r, so touching discs sit at >= 1.8 r; anything well
     * below means one disc went into another */
    CHECK(worst > 0.85, "two discs' centres only %.3f diameters apart", worst);
    for (int i = 0; i < count; i++)
        CHECK(centre[i][1] > 0 && centre[i][0] > 0 && centre[i][0] < W, "disc %d left the box: %g %g",
              i, centre[i][0], centre[i][1]);
    fprintf(stderr, "  pile: closest centres %.3f diameters, kinetic/gravity work %.2g, %ld detections\n",
            worst, en.kinetic / en.gravity_work, fdem_get_counts(m).detections);
    fdem_model_destroy(m);
}

/* Two undamped, frictionless 0.1 m square blocks of n x n cells, the left
 * one (*a) moving at 2 m/s onto the right one (*b) across a 5 mm gap (a
 * flat impact), finalized. With fracture, both are meshed with a joint on
 * every interior edge (strengths far above the impact's stresses, so none
 * breaks): every corner node then carries one element's mass, the lightest
 * a contact spring meets. */
static fdem_model *flat_impact_blocks(int n, int fracture, int *a, int *b)
{
    fdem_model *m = fdem_model_create();
    fdem_material_def d = {.density = 2000, .young = 1e8, .poisson = 0.25, .friction = 0,
                           .has_fracture = fracture, .fracture = {1e12, 3e12, 30, 1e9, 1e9}};
    fdem_error err;
    int mat = fdem_add_material(m, &d, &err);
    if (mat < 0) build_die("material", &err);
    *a = build_rectangle_part(m, mat, -0.105, 0, 0.1, 0.1, n, n, fracture);
    *b = build_rectangle_part(m, mat, 0.005, 0, 0.1, 0.1, n, n, fracture);
    fdem_set_part_velocity(m, *a, 2.0, 0, NULL);
    build_finalize(m, FDEM_DEFAULT_SAFETY);
    return m;
}

/* Runs the blocks at dt until they have parted and destroys the model.
 * Returns the energy gained, (kinetic + elastic + joint) / initial - 1, or
 * INFINITY if they never parted (or the run diverged). */
static double flat_impact_gain(fdem_model *m, int a, int b, double dt)
{
    fdem_error err;
    fdem_set_dt(m, dt);
    double e0 = fdem_get_energy(m).kinetic, c[2], va[2], vb[2];
    int touched = 0, parted = 0;
    while (!parted && fdem_get_time(m) < 0.03 && fdem_step(m, &err) == 0) {
        if (fdem_get_counts(m).contacts) touched = 1;
        part_centre(m, a, c, va);
        part_centre(m, b, c, vb);
        parted = touched && !fdem_get_counts(m).contacts && vb[0] > va[0];
    }
    fdem_energy en = fdem_get_energy(m);
    fdem_model_destroy(m);
    return parted ? (en.kinetic + en.elastic + en.joint) / e0 - 1 : INFINITY;
}

/* The contact step (contact_stable_dt, 0.25 h sqrt(rho / p)) is no larger
 * than a flat impact allows. It binds these blocks' step at safety 1
 * (checked); at the default safety "auto" takes it whole too on the
 * shared-node blocks (one run then stands for both safeties) and half the
 * joints' limit, 0.73 x it, on the jointed ones. The blocks part with their
 * energy within 1 % at both safeties (+0.78 % at most, the 5 x 5 jointed
 * blocks at safety 1). The factor 0.45 of 7f53400 (1.8 x the step) gained
 * 8.0 % on the 10 x 10 shared-node blocks and 15 % and 21 % on the jointed
 * ones, and 2 x (the contact's stability limit, which the safety scales)
 * 56-77 % (printed, not held). So neither the contact step nor "auto" at
 * any safety can grow past what impacts allow unnoticed, and
 * contact_step_is_its_closed_form keeps the step from shrinking
 * unnoticed. */
static void flat_impact_keeps_its_energy_at_every_safety(void)
{
    const int cells[2] = {5, 10};
    for (int fracture = 0; fracture < 2; fracture++)
        for (int k = 0; k < 2; k++) {
            int a, b, n = cells[k];
            fdem_model *m = flat_impact_blocks(n, fracture, &a, &b);
            double step = fdem_auto_dt(m, 1.0), half = fdem_auto_dt(m, FDEM_DEFAULT_SAFETY);
            double wider = NAN, limit = NAN;
            CHECK_REL(contact_stable_dt(m), step, 1e-15);
            double gain = flat_impact_gain(m, a, b, step), gain_half = gain;
            if (half != step) gain_half = flat_impact_gain(flat_impact_blocks(n, fracture, &a, &b), a, b, half);
#ifndef FDEM_SAN /* figures, not checks: the sanitizer run spares them */
            wider = flat_impact_gain(flat_impact_blocks(n, fracture, &a, &b), a, b, 1.8 * step);
            limit = flat_impact_gain(flat_impact_blocks(n, fracture, &a, &b), a, b, 2.0 * step);
#endif
            fprintf(stderr, "  flat impact %2d x %-2d %s: energy %+.2f %% at safety 1, %+.2f %% at "
                    "safety 0.5 (%.2f x the step), %+.1f %% at 1.8 x (the old factor 0.45), "
                    "%+.1f %% at 2 x\n", n, n, fracture ? "jointed    " : "shared-node",
                    100 * gain, 100 * gain_half, half / step, 100 * wider, 100 * limit);
            CHECK(fabs(gain) < 0.01, "%d x %d blocks (fracture %d): energy %+.2f %% at safety 1",
                  n, n, fracture, 100 * gain);
            CHECK(fabs(gain_half) < 0.01, "%d x %d blocks (fracture %d): energy %+.2f %% at safety "
                  "0.5", n, n, fracture, 100 * gain_half);
        }
}

/* The contact step's closed form on meshes of right triangles (legs s,
 * smallest altitude s / sqrt 2): 0.25 h sqrt(rho / p) with the default
 * penalty p = 10 E, the smallest over the materials and element sizes. */
static void contact_step_is_its_closed_form(void)
{
    fdem_model *m = fdem_model_create();
    int soft = build_material(m, 2000, 1e8, 0.25, 0, 0);
    int stiff = build_material(m, 2700, 3e9, 0.25, 0, 0);
    build_rectangle(m, soft, 0, 0, 0.1, 0.1, 5, 5);  /* 0.25 (0.02 / sqrt 2) sqrt(2000 / 1e9) */
    build_rectangle(m, stiff, 0.2, 0, 0.1, 0.1, 4, 4); /* 0.25 (0.025 / sqrt 2) sqrt(2700 / 3e10) */
    build_finalize(m, 0.5);
    double soft_dt = 0.25 * 0.02 / sqrt(2.0) * sqrt(2000 / 1e9);
    double stiff_dt = 0.25 * 0.025 / sqrt(2.0) * sqrt(2700 / 3e10);
    CHECK_REL(contact_stable_dt(m), fmin(soft_dt, stiff_dt), 1e-14);
    CHECK_REL(contact_stable_dt(m), 1.3258252147e-6, 1e-10); /* figure as of 2026-12-06 */
    fdem_model_destroy(m);
}

/* "auto" on a model whose step contact binds: the contact step whole from
 * the default safety up (the stable step: a given dt may be as large), and
 * safety x the contact's stability limit, twice the step, below it. */
static void auto_step_scales_the_contact_limit_up_to_the_step(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 2000, 1e8, 0.25, 0, 0);
    build_rectangle(m, mat, 0, 0, 0.1, 0.1, 5, 5);
    build_rectangle(m, mat, 0.2, 0, 0.1, 0.1, 5, 5);
    build_finalize(m, FDEM_DEFAULT_SAFETY);
    double step = contact_stable_dt(m); /* 0.25 (0.02 / sqrt 2) sqrt(2000 / 1e9) */
    CHECK_REL(step, 0.25 * 0.02 / sqrt(2.0) * sqrt(2000 / 1e9), 1e-14);
    CHECK_REL(fdem_stable_dt(m), step, 1e-15);
    CHECK_REL(fdem_get_dt(m), step, 1e-15);
    CHECK_REL(fdem_auto_dt(m, 1.0), step, 1e-15);
    CHECK_REL(fdem_auto_dt(m, 0.5), step, 1e-15);
    CHECK_REL(fdem_auto_dt(m, 0.25), 0.5 * step, 1e-15);
    CHECK_REL(fdem_auto_dt(m, 0.1), 0.2 * step, 1e-15);
    fdem_model_destroy(m);
}

CHECK_MAIN(T(overlapping_pair_forces_balance), T(separated_pair_has_no_force),
           T(collision_conserves_momentum_and_energy), T(block_slides_down_incline_with_friction),
           T(block_sticks_below_friction_angle), T(disc_pile_settles_without_interpenetration),
           T(flat_impact_keeps_its_energy_at_every_safety), T(contact_step_is_its_closed_form),
           T(auto_step_scales_the_contact_limit_up_to_the_step))
