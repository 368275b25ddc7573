/*
 * test_dynamics_3d.c - the engine with tetrahedra, through the public API,
 * against closed forms: the stable step is 2/omega_max of the fastest
 * element mode (power iteration on a finite-difference stiffness); free
 * fall follows 1/2 g t^2; a fixed-free bar (nu = 0) has the first period
 * 4L/c; a column on a fixed base carries its weight in the reaction; two
 * threads give the same bits as one; a model restored from a checkpoint
 * steps on to the same bits; an undamped bar closes its energy balance.
 */
#include "check.h"
#include "kernel/element_tet.h"
#include "fdem.h"
#include "mesh/mesh_3d.h"
#include "power_iteration.h"
#include "bar_period_3d.h"

#include <stdint.h>
#include <stdlib.h>

static fdem_material_def rock(double young, double poisson, double damping)
{
    fdem_material_def d = {0};
    d.density = 2500;
    d.young = young;
    d.poisson = poisson;
    d.damping = damping;
    return d;
}

/* A 3D model of one box part; NULL (and a message) on failure. */
static fdem_model *box_model(const double origin[3], const double size[3], const int div[3],
                             fdem_material_def mat)
{
    fdem_error err = {0};
    fdem_tet_mesh mesh = {0};
    fdem_model *m = fdem_model_create();
    int ok = m && fdem_set_dimension(m, 3, &err) == 0 &&
             fdem_tet_mesh_box(origin, size, div, &mesh, &err) == 0 &&
             fdem_add_material(m, &mat, &err) == 0 && fdem_add_part_3d(m, &mesh, 0, 0, &err) == 0;
    fdem_tet_mesh_free(&mesh);
    if (!ok) {
        fprintf(stderr, "  building the box failed: %s\n", err.message);
        fdem_model_destroy(m);
        return NULL;
    }
    return m;
}

static int finalize(fdem_model *m)
{
    fdem_error err = {0};
    if (fdem_model_finalize(m, &err) == 0) return 0;
    fprintf(stderr, "  finalize failed: %s\n", err.message);
    return -1;
}

static int run_steps(fdem_model *m, int steps)
{
    fdem_error err = {0};
    for (int s = 0; s < steps; s++)
        if (fdem_step(m, &err)) {
            fprintf(stderr, "  step failed: %s\n", err.message);
            return -1;
        }
    return 0;
}

/* omega_max^2 of one tetrahedron with masses rho V / 4, by power iteration
 * on M^-1 K, K from central differences of the nodal forces. */
static double tet_omega2_by_power_iteration(const double X[12], double lambda, double mu,
                                            double density)
{
    const int32_t quad[4] = {0, 1, 2, 3};
    tet_geometry g;
    tet_prepare(X, quad, &g);
    tet_law law = {lambda, mu, 0};
    double K[12][12], x[12], fp[12], fm[12];
    double step = 1e-7 * g.height;
    for (int j = 0; j < 12; j++) {
        for (int k = 0; k < 12; k++) x[k] = X[k];
        x[j] = X[j] + step;
        tet_forces(x, NULL, quad, &g, &law, fp, NULL);
        x[j] = X[j] - step;
        tet_forces(x, NULL, quad, &g, &law, fm, NULL);
        for (int i = 0; i < 12; i++) K[i][j] = -(fp[i] - fm[i]) / (2 * step);
    }
    double mass[12], start[12];
    for (int i = 0; i < 12; i++) {
        mass[i] = density * g.volume0 / 4;
        start[i] = 1.0 + 0.1 * i * (i % 3 == 1 ? -1 : 1);
    }
    return largest_eigenvalue_over_mass(12, &K[0][0], mass, start, 5000);
}

/* The model's stable step is 2/omega_max of its one element, to 1e-4, for
 * a regular-ish and a flat, irregular tetrahedron at three Poisson ratios;
 * the old estimate h/c is printed beside it. */
static void stable_step_is_that_of_the_fastest_element_mode(void)
{
    const double shapes[2][12] = {
        {0, 0, 0, 1, 0, 0, 0.5, 0.866, 0, 0.5, 0.289, 0.816},
        {0.1, -0.2, 0.05, 1.3, 0.1, -0.1, 0.2, 1.1, 0.3, 0.4, 0.3, 0.35},
    };
    const double nus[3] = {0, 0.3, 0.45};
    for (int s = 0; s < 2; s++)
        for (int t = 0; t < 3; t++) {
            fdem_material_def mat = rock(10e9, nus[t], 0);
            fdem_error err = {0};
            fdem_model *m = fdem_model_create();
            int32_t tet[4] = {0, 1, 2, 3};
            double xyz[12];
            for (int k = 0; k < 12; k++) xyz[k] = shapes[s][k];
            fdem_tet_mesh mesh = {4, 1, xyz, tet};
            CHECK(fdem_set_dimension(m, 3, &err) == 0 && fdem_add_material(m, &mat, &err) == 0 &&
                      fdem_add_part_3d(m, &mesh, 0, 0, &err) == 0 && finalize(m) == 0,
                  "%s", err.message);
            double E = mat.young, nu = nus[t];
            double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
            double want = 2 / sqrt(tet_omega2_by_power_iteration(shapes[s], lambda, mu, mat.density));
            CHECK_REL(fdem_stable_dt(m), want, 1e-4);
            double h = tet_smallest_height(shapes[s], shapes[s] + 3, shapes[s] + 6, shapes[s] + 9);
            fprintf(stderr, "  shape %d nu %.2f: stable step %.6g s, 2/omega_max %.6g s, h/c %.6g s\n",
                    s, nu, fdem_stable_dt(m), want,
                    tet_stable_dt(h, lambda, mu, mat.density, 0));
            fdem_model_destroy(m);
        }
}

/* Mass-weighted mean of one component of the node positions. */
static double centre_of_mass(const fdem_model *m, int component)
{
    fdem_counts c = fdem_get_counts(m);
    const double *x = fdem_positions(m), *mass = fdem_node_masses(m);
    double sum = 0, total = 0;
    for (int i = 0; i < c.nodes; i++) {
        sum += mass[i] * x[3 * i + component];
        total += mass[i];
    }
    return sum / total;
}

/* A box let go under gravity (0, 0, -9.81) falls 1/2 g t^2 (to 1 %), keeps
 * its mass rho V (lumped rho V / 4), and is not strained. */
static void free_fall_is_half_g_t_squared(void)
{
    const double origin[3] = {0, 0, 10}, size[3] = {1, 0.5, 0.4};
    const int div[3] = {4, 2, 2};
    fdem_model *m = box_model(origin, size, div, rock(10e9, 0.25, 0));
    if (!m) { CHECK(0, "no model"); return; }
    const double g[3] = {0, 0, -9.81};
    fdem_set_gravity_v(m, g);
    if (finalize(m)) { CHECK(0, "finalize"); fdem_model_destroy(m); return; }
    fdem_counts c = fdem_get_counts(m);
    double mass = 0;
    for (int i = 0; i < c.nodes; i++) mass += fdem_node_masses(m)[i];
    CHECK_REL(mass, 2500 * 1 * 0.5 * 0.4, 1e-12);
    double z0 = centre_of_mass(m, 2);
    fdem_set_dt(m, 0.9 * fdem_stable_dt(m));
    int steps = (int)ceil(0.05 / fdem_get_dt(m));
    CHECK(run_steps(m, steps) == 0, "run");
    double t = fdem_get_time(m);
    CHECK_REL(z0 - centre_of_mass(m, 2), 0.5 * 9.81 * t * t, 0.01);
    CHECK_NEAR(centre_of_mass(m, 0), 0.5, 1e-12);
    double *stress = malloc(sizeof(double) * 6 * (size_t)c.elements), worst = 0;
    fdem_element_stress(m, stress);
    for (int k = 0; k < 6 * c.elements; k++) worst = fmax(worst, fabs(stress[k]));
    CHECK(worst < 1e-3, "a falling body is not strained: |stress| up to %g Pa", worst);
    free(stress);
    fdem_model_destroy(m);
}

/* A fixed-free bar with nu = 0 (a 1D bar: no lateral coupling), all of it
 * moving at v0 along its axis at t = 0 but the fixed end: its free end
 * goes out to v0 L/c at L/c, back through zero at 2L/c, in to -v0 L/c and
 * back to zero at the first period 4L/c (to 3 %). The undamped run closes its energy
 * balance to 1e-3 of the kinetic energy it started with. */
static void fixed_free_bar_period_is_4L_over_c(void)
{
    const double L = 1.0, origin[3] = {0, 0, 0}, size[3] = {L, 0.1, 0.1};
    const int div[3] = {40, 2, 2};
    fdem_material_def mat = rock(10e9, 0, 0);
    fdem_model *m = box_model(origin, size, div, mat);
    if (!m) { CHECK(0, "no model"); return; }
    fdem_error err = {0};
    fdem_constraint_def fix = {0};
    fix.select = FDEM_SELECT_BOX;
    const double box[6] = {-1e-9, -1, -1, 1e-9, 1, 1};
    for (int k = 0; k < 6; k++) fix.box[k] = box[k];
    fix.kind = FDEM_CONSTRAINT_FIX;
    fix.fix_x = fix.fix_y = fix.fix_z = 1;
    CHECK(fdem_add_constraint(m, &fix, &err) == 0, "%s", err.message);
    const double v0[3] = {0.1, 0, 0};
    CHECK(fdem_set_part_velocity_v(m, 0, v0, &err) == 0, "%s", err.message);
    if (finalize(m)) { CHECK(0, "finalize"); fdem_model_destroy(m); return; }
    double c = sqrt(mat.young / mat.density), period = 4 * L / c;
    fdem_energy e0 = fdem_get_energy(m);
    (void)e0;
    fdem_counts counts = fdem_get_counts(m);
    double kinetic0 = 0;
    for (int i = 0; i < counts.nodes; i++) {
        const double *v = fdem_velocities(m) + 3 * i;
        kinetic0 += 0.5 * fdem_node_masses(m)[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    fdem_set_dt(m, 0.5 * fdem_stable_dt(m));
    /* tip displacement: mean over the nodes at x = L */
    bar_crossing bar = {0, 0, -1, 0, 0};
    double worst_residual = 0;
    double u_max = 0.1 * L / c;
    while (fdem_get_time(m) < 1.5 * period && bar.crossing < 0) {
        if (run_steps(m, 1)) { CHECK(0, "run"); break; }
        double u = bar_tip_displacement(m, L), t = fdem_get_time(m);
        if (getenv("BAR_TRACE")) fprintf(stderr, "%g %g\n", t, u);
        bar_crossing_update(&bar, t, u, u_max);
        worst_residual = fmax(worst_residual, fabs(fdem_get_energy(m).residual));
    }
    CHECK(bar.crossing > 0, "the tip never came back");
    CHECK_REL(bar.crossing, period, 0.03);
    CHECK(worst_residual <= 1e-3 * kinetic0, "energy residual %g J of %g J", worst_residual,
          kinetic0);
    fprintf(stderr, "  first period %.6g s, 4L/c %.6g s (%+.2f %%); worst residual %.3g of %.3g J\n",
            bar.crossing, period, 100 * (bar.crossing / period - 1), worst_residual, kinetic0);
    fdem_model_destroy(m);
}

/* A damped column standing on a fixed base under gravity comes to rest
 * carrying its weight: the base's reaction is (0, 0, m g) to 1 %, and the
 * velocity constraint's free component (a roller) leaves that axis alone. */
static void column_reaction_carries_the_weight(void)
{
    const double origin[3] = {0, 0, 0}, size[3] = {0.2, 0.2, 1};
    const int div[3] = {2, 2, 8};
    fdem_model *m = box_model(origin, size, div, rock(1e9, 0.25, 0.5));
    if (!m) { CHECK(0, "no model"); return; }
    fdem_error err = {0};
    fdem_constraint_def base = {0};
    base.select = FDEM_SELECT_BOX;
    const double box[6] = {-1, -1, -1e-9, 1, 1, 1e-9};
    for (int k = 0; k < 6; k++) base.box[k] = box[k];
    base.kind = FDEM_CONSTRAINT_VELOCITY; /* z held, x and y free: a roller */
    base.free_x = base.free_y = 1;
    CHECK(fdem_add_constraint(m, &base, &err) == 0, "%s", err.message);
    const double g[3] = {0, 0, -9.81};
    fdem_set_gravity_v(m, g);
    if (finalize(m)) { CHECK(0, "finalize"); fdem_model_destroy(m); return; }
    fdem_set_dt(m, 0.9 * fdem_stable_dt(m));
    double weight = 2500 * 0.2 * 0.2 * 1 * 9.81;
    CHECK(run_steps(m, 4000) == 0, "run");
    const double *r = fdem_constraint_forces(m);
    CHECK_REL(r[2], weight, 0.01);
    CHECK_NEAR(r[0], 0, 1e-9 * weight);
    CHECK_NEAR(r[1], 0, 1e-9 * weight);
    CHECK(fdem_constraint_node_count(m, 0) == 9, "base nodes: %d", fdem_constraint_node_count(m, 0));
    fdem_model_destroy(m);
}

/* A damped box large enough for several scatter blocks, under gravity with
 * a roller base, run on 1 and on 2 threads: the same bits. */
static void two_threads_give_the_same_bits(void)
{
    const double origin[3] = {0, 0, 0}, size[3] = {1, 1, 1};
    const int div[3] = {12, 12, 12};
    fdem_model *m[2];
    for (int k = 0; k < 2; k++) {
        m[k] = box_model(origin, size, div, rock(1e9, 0.3, 0.1));
        if (!m[k]) { CHECK(0, "no model"); return; }
        fdem_error err = {0};
        fdem_constraint_def base = {0};
        base.select = FDEM_SELECT_BOX;
        const double box[6] = {-1, -1, -1e-9, 2, 2, 1e-9};
        for (int j = 0; j < 6; j++) base.box[j] = box[j];
        base.kind = FDEM_CONSTRAINT_VELOCITY;
        base.value[0] = 0.01;
        base.free_y = 1;
        CHECK(fdem_add_constraint(m[k], &base, &err) == 0, "%s", err.message);
        const double g[3] = {1, 2, -9.81};
        fdem_set_gravity_v(m[k], g);
        fdem_set_threads(m[k], k + 1);
        CHECK(finalize(m[k]) == 0, "finalize");
        CHECK(run_steps(m[k], 100) == 0, "run");
    }
    fdem_counts c = fdem_get_counts(m[0]);
    CHECK(c.elements == 12 * 12 * 12 * 6, "elements %d", c.elements);
    size_t nb = sizeof(double) * 3 * (size_t)c.nodes;
    CHECK(memcmp(fdem_positions(m[0]), fdem_positions(m[1]), nb) == 0, "positions differ");
    CHECK(memcmp(fdem_velocities(m[0]), fdem_velocities(m[1]), nb) == 0, "velocities differ");
    fdem_energy e0 = fdem_get_energy(m[0]), e1 = fdem_get_energy(m[1]);
    CHECK(memcmp(&e0, &e1, sizeof e0) == 0, "energies differ");
    fdem_model_destroy(m[0]);
    fdem_model_destroy(m[1]);
}

/* Checkpoint after 50 steps, restore into a fresh model of the same case,
 * run both 50 more: the same bits (damped, so the viscous stresses count). */
static void restored_model_steps_on_to_the_same_bits(void)
{
    const double origin[3] = {0, 0, 0}, size[3] = {1, 0.3, 0.3};
    const int div[3] = {6, 2, 2};
    fdem_model *a = box_model(origin, size, div, rock(1e9, 0.3, 0.2));
    fdem_model *b = box_model(origin, size, div, rock(1e9, 0.3, 0.2));
    if (!a || !b) { CHECK(0, "no model"); return; }
    const double v[3] = {0.3, -0.1, 0.2}, g[3] = {0, 0, -9.81};
    fdem_error err = {0};
    for (int k = 0; k < 2; k++) {
        fdem_model *m = k ? b : a;
        fdem_constraint_def fix = {0};
        fix.select = FDEM_SELECT_BOX;
        const double box[6] = {-1, -1, -1, 1e-9, 1, 1};
        for (int j = 0; j < 6; j++) fix.box[j] = box[j];
        fix.kind = FDEM_CONSTRAINT_FIX;
        fix.fix_z = 1;
        CHECK(fdem_add_constraint(m, &fix, &err) == 0, "%s", err.message);
        CHECK(fdem_set_part_velocity_v(m, 0, v, &err) == 0, "%s", err.message);
        fdem_set_gravity_v(m, g);
        CHECK(finalize(m) == 0, "finalize");
    }
    CHECK(run_steps(a, 50) == 0, "run");
    size_t size_cp = fdem_checkpoint_size(a);
    void *buf = malloc(size_cp);
    CHECK(fdem_checkpoint_write(a, buf, size_cp) == 0, "write");
    CHECK(fdem_checkpoint_read(b, buf, size_cp, &err) == 0, "%s", err.message);
    free(buf);
    CHECK(run_steps(a, 50) == 0 && run_steps(b, 50) == 0, "run");
    fdem_counts c = fdem_get_counts(a);
    size_t nb = sizeof(double) * 3 * (size_t)c.nodes;
    CHECK(memcmp(fdem_positions(a), fdem_positions(b), nb) == 0, "positions differ");
    CHECK(memcmp(fdem_velocities(a), fdem_velocities(b), nb) == 0, "velocities differ");
    fdem_energy ea = fdem_get_energy(a), eb = fdem_get_energy(b);
    CHECK(memcmp(&ea, &eb, sizeof ea) == 0, "energies differ");
    fdem_model_destroy(a);
    fdem_model_destroy(b);
}

/* A 2D checkpoint is refused by a 3D model of the same counts, by name. */
static void dimension_is_chosen_before_parts(void)
{
    const double origin[3] = {0, 0, 0}, size[3] = {1, 1, 1};
    const int div[3] = {1, 1, 1};
    fdem_model *m = box_model(origin, size, div, rock(1e9, 0.3, 0));
    if (!m) { CHECK(0, "no model"); return; }
    fdem_error err = {0};
    CHECK(fdem_set_dimension(m, 2, &err) < 0, "changed the dimension after a part");
    CHECK(strstr(err.message, "before the first part") != NULL, "%s", err.message);
    CHECK(fdem_set_dimension(m, 4, &err) < 0 && strstr(err.message, "2 or 3"), "%s", err.message);
    fdem_mesh tri = {0};
    CHECK(fdem_mesh_rectangle(0, 0, 1, 1, 1, 1, &tri, &err) == 0, "%s", err.message);
    CHECK(fdem_add_part(m, &tri, 0, 0, &err) < 0 && strstr(err.message, "2D mesh in a 3D model"),
          "%s", err.message);
    fdem_mesh_free(&tri);
    CHECK(finalize(m) == 0, "finalize");
    CHECK(fdem_get_dimension(m) == 3 && fdem_nodes_per_element(m) == 4 &&
              fdem_stress_components(m) == 6 && fdem_triangles(m) == NULL &&
              fdem_tetrahedra(m) != NULL,
          "accessors");
    fdem_model_destroy(m);
}

CHECK_MAIN(T(stable_step_is_that_of_the_fastest_element_mode), T(free_fall_is_half_g_t_squared),
           T(fixed_free_bar_period_is_4L_over_c), T(column_reaction_carries_the_weight),
           T(two_threads_give_the_same_bits), T(restored_model_steps_on_to_the_same_bits),
           T(dimension_is_chosen_before_parts))
