/*
 * test_contact_3d.c - contact between tetrahedral bodies through the public
 * API, against physics: two boxes colliding head-on and obliquely conserve
 * linear momentum (to 1e-12) and energy (kinetic + elastic + contact
 * [+ friction] to 5 %); flat impacts of shared-node and jointed cubes at
 * the default safety and at safety 1 keep their energy within 1 %; a box
 * on a slab with gravity tilted 30 degrees
 * slides at g (sin 30 - mu cos 30) (to 5 %) with mu = 0.3, and with
 * mu = 0.7 > tan 30 stays put; a pile of spheres dropped into a box of
 * fixed slabs settles with no sphere through another, and the near list
 * it walks leaves out no touching pair; two threads give the bits of one; a
 * checkpoint holding stick springs restores to the same bits.
 */
#include "build_container_3d.h"
#include "check.h"
#include "kernel/contact_tet.h"
#include "fdem.h"
#include "mesh/mesh_3d.h"
#include "model/model.h"
#include "contact/contact.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* penalty 0: the default, 10 x young. */
static fdem_material_def solid(double density, double young, double damping, double friction,
                               double penalty)
{
    fdem_material_def d = {0};
    d.density = density;
    d.young = young;
    d.penalty = penalty;
    d.poisson = 0.25;
    d.damping = damping;
    d.friction = friction;
    return d;
}

static int add_material(fdem_model *m, fdem_material_def def)
{
    fdem_error err = {0};
    int index = fdem_add_material(m, &def, &err);
    CHECK(index >= 0, "%s", err.message);
    return index;
}

/* A 3D model to add parts to. */
static fdem_model *model_3d(void)
{
    fdem_error err = {0};
    fdem_model *m = fdem_model_create();
    if (m && fdem_set_dimension(m, 3, &err) == 0) return m;
    fdem_model_destroy(m);
    return NULL;
}

/* Appends a tetrahedral mesh as a part; its nodes are [*first, *end). */
static int add_mesh(fdem_model *m, fdem_tet_mesh *mesh, int mat, int *first, int *end)
{
    fdem_error err = {0};
    int begin = fdem_get_counts(m).nodes;
    int index = fdem_add_part_3d(m, mesh, mat, 0, &err);
    fdem_tet_mesh_free(mesh);
    CHECK(index >= 0, "%s", err.message);
    if (first) *first = begin;
    if (end) *end = fdem_get_counts(m).nodes;
    return index;
}

static int add_box(fdem_model *m, int mat, const double origin[3], const double size[3],
                   const int div[3], int *first, int *end)
{
    fdem_error err = {0};
    fdem_tet_mesh mesh = {0};
    CHECK(fdem_tet_mesh_box(origin, size, div, &mesh, &err) == 0, "%s", err.message);
    return add_mesh(m, &mesh, mat, first, end);
}

static int add_sphere(fdem_model *m, int mat, const double centre[3], double radius,
                      int divisions, int *first, int *end)
{
    fdem_error err = {0};
    fdem_tet_mesh mesh = {0};
    CHECK(fdem_tet_mesh_sphere(centre, radius, divisions, &mesh, &err) == 0, "%s", err.message);
    return add_mesh(m, &mesh, mat, first, end);
}

static void fix_part(fdem_model *m, int index)
{
    fdem_error err = {0};
    fdem_constraint_def fix = {0};
    fix.select = FDEM_SELECT_PART;
    fix.part = index;
    fix.kind = FDEM_CONSTRAINT_FIX;
    fix.fix_x = fix.fix_y = fix.fix_z = 1;
    CHECK(fdem_add_constraint(m, &fix, &err) >= 0, "%s", err.message);
}

/* Finalizes and sets the step a case's "auto" would at this safety. */
static int finalize(fdem_model *m, double safety)
{
    fdem_error err = {0};
    if (fdem_model_finalize(m, &err)) {
        CHECK(0, "finalize: %s", err.message);
        return -1;
    }
    fdem_set_dt(m, fdem_auto_dt(m, safety));
    return 0;
}

static int step(fdem_model *m)
{
    fdem_error err = {0};
    if (fdem_step(m, &err) == 0) return 0;
    CHECK(0, "step failed: %s", err.message);
    return -1;
}

static int run_until(fdem_model *m, double t_end)
{
    while (fdem_get_time(m) < t_end)
        if (step(m)) return -1;
    return 0;
}

/* Mass-weighted centre and velocity of nodes [first, end). */
static void nodes_centre(const fdem_model *m, int first, int end, double c[3], double v[3])
{
    const double *x = fdem_positions(m), *u = fdem_velocities(m), *mass = fdem_node_masses(m);
    double total = 0;
    for (int d = 0; d < 3; d++) c[d] = v ? (v[d] = 0) : 0;
    for (int i = first; i < end; i++) {
        total += mass[i];
        for (int d = 0; d < 3; d++) {
            c[d] += mass[i] * x[3 * i + d];
            if (v) v[d] += mass[i] * u[3 * i + d];
        }
    }
    for (int d = 0; d < 3; d++) {
        c[d] /= total;
        if (v) v[d] /= total;
    }
}

/* Total momentum, and sum of m |v| as its scale. */
static void momentum(const fdem_model *m, double p[3], double *scale)
{
    const double *v = fdem_velocities(m), *mass = fdem_node_masses(m);
    p[0] = p[1] = p[2] = 0;
    *scale = 0;
    for (int i = 0; i < fdem_get_counts(m).nodes; i++) {
        for (int d = 0; d < 3; d++) p[d] += mass[i] * v[3 * i + d];
        *scale += mass[i] * sqrt(v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] +
                                 v[3 * i + 2] * v[3 * i + 2]);
    }
}

/* Two undamped boxes, 0.1 m cubes of 3 x 3 x 3 cells, the first moving at
 * velocity v toward the second (0.2 mm away, offset by `offset` across the
 * impact direction), run until they have parted: momentum is kept to
 * round-off, kinetic + elastic + contact + friction to 5 %, and, with the
 * contact springs empty again, kinetic + elastic + friction to 5 %. */
static void boxes_collide(const double v[3], const double offset[2], double mu, const char *name)
{
    fdem_model *m = model_3d();
    fdem_error err = {0};
    int mat = add_material(m, solid(2700, 1e9, 0, mu, 0));
    const double size[3] = {0.1, 0.1, 0.1}, o1[3] = {0, 0, 0};
    const double o2[3] = {0.1002, offset[0], offset[1]};
    const int div[3] = {3, 3, 3};
    int a0, a1, b0, b1;
    int a = add_box(m, mat, o1, size, div, &a0, &a1);
    add_box(m, mat, o2, size, div, &b0, &b1);
    CHECK(fdem_set_part_velocity_v(m, a, v, &err) == 0, "%s", err.message);
    if (finalize(m, 0.5)) return;
    double p0[3], s0, p[3], s, c[3], va[3], vb[3];
    momentum(m, p0, &s0);
    double e0 = fdem_get_energy(m).kinetic;
    int touched = 0;
    while (fdem_get_time(m) < 0.01) {
        if (step(m)) break;
        int contacts = fdem_get_counts(m).contacts;
        touched |= contacts > 0;
        nodes_centre(m, a0, a1, c, va);
        nodes_centre(m, b0, b1, c, vb);
        if (touched && !contacts && vb[0] > va[0]) break;
    }
    CHECK(touched, "%s: the boxes never touched", name);
    CHECK(vb[0] > va[0], "%s: still approaching: %g %g", name, va[0], vb[0]);
    momentum(m, p, &s);
    double worst = 0;
    for (int d = 0; d < 3; d++) worst = fmax(worst, fabs(p[d] - p0[d]) / s0);
    CHECK(worst <= 1e-12, "%s: momentum changed by %.3g of sum m|v|", name, worst);
    fdem_energy en = fdem_get_energy(m);
    double total = en.kinetic + en.elastic + en.contact + en.friction;
    CHECK_REL(total, e0, 0.05);
    /* parted, the penalty springs hold nothing: what contact gave or took
     * is the discretisation's error */
    CHECK_REL(en.kinetic + en.elastic + en.friction, e0, 0.05);
    fprintf(stderr, "  %s: momentum error %.2g, energy %.4f of the initial (kinetic %.3f, "
            "elastic %.3f, contact %+.4f, friction %.3f), %lld steps\n", name, worst, total / e0,
            en.kinetic / e0, en.elastic / e0, en.contact / e0, en.friction / e0,
            (long long)fdem_get_step(m));
    fdem_model_destroy(m);
}

static void boxes_colliding_conserve_momentum_and_energy(void)
{
    const double head_on[3] = {2, 0, 0}, centred[2] = {0, 0};
    boxes_collide(head_on, centred, 0, "head-on");
    const double oblique[3] = {2, 0.5, -0.3}, shifted[2] = {0.04, -0.03};
    boxes_collide(oblique, shifted, 0.3, "oblique, mu 0.3");
}

/* Two undamped, frictionless 0.1 m cubes of n x n x n cells, the first
 * moving at 2 m/s onto the second across a 1 mm gap (a flat impact), at
 * dt = scale x the step "auto" takes at `safety`. With fracture, both
 * have a joint on every interior face (too strong to break), so every
 * corner node carries one tetrahedron's mass. Returns the energy gained
 * once they have parted, (kinetic + elastic + joint) / initial - 1
 * (INFINITY if they never part); *dt gets the step taken, *contact the
 * contact step. */
static double boxes_flat_impact_gain(int n, int fracture, double safety, double scale,
                                     double *dt, double *contact)
{
    fdem_model *m = model_3d();
    fdem_material_def def = solid(2000, 1e8, 0, 0, 0);
    def.has_fracture = fracture;
    def.fracture = (fdem_fracture_params){.tensile_strength = 1e12, .cohesion = 3e12,
                                          .friction_angle = 30, .energy_I = 1e9,
                                          .energy_II = 1e9};
    int mat = add_material(m, def);
    const double size[3] = {0.1, 0.1, 0.1}, o1[3] = {-0.101, 0, 0}, o2[3] = {0, 0, 0};
    const int div[3] = {n, n, n};
    fdem_error err = {0};
    fdem_tet_mesh mesh = {0};
    int a0, a1, b0, b1;
    CHECK(fdem_tet_mesh_box(o1, size, div, &mesh, &err) == 0, "%s", err.message);
    a0 = fdem_get_counts(m).nodes;
    int a = fdem_add_part_3d(m, &mesh, mat, fracture, &err);
    fdem_tet_mesh_free(&mesh);
    a1 = b0 = fdem_get_counts(m).nodes;
    CHECK(fdem_tet_mesh_box(o2, size, div, &mesh, &err) == 0, "%s", err.message);
    CHECK(fdem_add_part_3d(m, &mesh, mat, fracture, &err) >= 0 && a >= 0, "%s", err.message);
    fdem_tet_mesh_free(&mesh);
    b1 = fdem_get_counts(m).nodes;
    const double v[3] = {2, 0, 0};
    CHECK(fdem_set_part_velocity_v(m, a, v, &err) == 0, "%s", err.message);
    if (finalize(m, safety)) return NAN;
    *contact = contact_stable_dt(m);
    fdem_set_dt(m, *dt = scale * fdem_get_dt(m));
    double e0 = fdem_get_energy(m).kinetic, c[3], va[3], vb[3];
    int touched = 0, parted = 0;
    while (!parted && fdem_get_time(m) < 0.01 && fdem_step(m, &err) == 0) {
        int contacts = fdem_get_counts(m).contacts;
        touched |= contacts > 0;
        nodes_centre(m, a0, a1, c, va);
        nodes_centre(m, b0, b1, c, vb);
        parted = touched && !contacts && vb[0] > va[0];
    }
    fdem_energy en = fdem_get_energy(m);
    fdem_model_destroy(m);
    return parted ? (en.kinetic + en.elastic + en.joint) / e0 - 1 : INFINITY;
}

/* The 3D contact step (0.153 h sqrt(rho / p)) is no larger than a flat
 * impact allows: it binds these cubes' step at safety 1 (checked), and at
 * the default safety too on the shared-node cubes (the jointed ones take
 * half the joints' limit, 0.85 x it); the cubes part with their energy
 * within 1 % at both safeties. 1.8 x and 2 x the step (the contact's
 * stability limit, which the safety scales) are printed, not held. */
static void boxes_flat_impact_keeps_its_energy_at_every_safety(void)
{
    for (int fracture = 0; fracture < 2; fracture++) {
        double step, half, contact, wider = NAN, limit = NAN;
        double gain = boxes_flat_impact_gain(3, fracture, 1.0, 1.0, &step, &contact);
        CHECK_REL(step, contact, 1e-15);
        double gain_half = boxes_flat_impact_gain(3, fracture, FDEM_DEFAULT_SAFETY, 1.0, &half, &contact);
#ifndef FDEM_SAN /* figures, not checks: the sanitizer run spares them */
        double dt;
        wider = boxes_flat_impact_gain(3, fracture, 1.0, 1.8, &dt, &contact);
        limit = boxes_flat_impact_gain(3, fracture, 1.0, 2.0, &dt, &contact);
#endif
        fprintf(stderr, "  flat impact 3 x 3 x 3 %s: energy %+.2f %% at safety 1, %+.2f %% at "
                "safety 0.5 (%.2f x the step), %+.1f %% at 1.8 x, %+.1f %% at 2 x\n",
                fracture ? "jointed    " : "shared-node", 100 * gain, 100 * gain_half,
                half / step, 100 * wider, 100 * limit);
        CHECK(fabs(gain) < 0.01, "cubes (fracture %d): energy %+.2f %% at safety 1", fracture,
              100 * gain);
        CHECK(fabs(gain_half) < 0.01, "cubes (fracture %d): energy %+.2f %% at safety 0.5",
              fracture, 100 * gain_half);
    }
}

/* A 0.2 x 0.2 x 0.1 box of 2 x 2 x 1 cells resting on a fixed slab of
 * 0.1 m cells, gravity tilted by theta about y. The box is damped so its
 * settling on the slab does not ring. The penalty is the Young modulus, not
 * ten times it: under a load this light the overlap stays below 1e-5 of
 * the box either way, and the step is three times longer. Returns the
 * slide along x of the box's centre from t_settled to t_end; *settling gets
 * the slide before t_settled, *time the time between. */
static double slab_slide(double theta_deg, double mu, double t_settled, double t_end,
                         double *settling, double *time)
{
    double th = theta_deg * M_PI / 180, g = 9.81;
    fdem_model *m = model_3d();
    int slab_mat = add_material(m, solid(1000, 1e7, 0, mu, 1e7));
    int box_mat = add_material(m, solid(1000, 1e7, 0.2, mu, 1e7));
    const double slab_origin[3] = {0, -0.15, -0.1}, slab_dims[3] = {0.4, 0.3, 0.1};
    const int slab_div[3] = {4, 3, 1};
    const double box_origin[3] = {0.05, -0.1, 0}, box_dims[3] = {0.2, 0.2, 0.1};
    const int box_div[3] = {2, 2, 1};
    int slab = add_box(m, slab_mat, slab_origin, slab_dims, slab_div, NULL, NULL);
    int first, end;
    add_box(m, box_mat, box_origin, box_dims, box_div, &first, &end);
    fix_part(m, slab);
    const double gv[3] = {g * sin(th), 0, -g * cos(th)};
    fdem_set_gravity_v(m, gv);
    double c0[3], c[3];
    if (finalize(m, 0.5)) return NAN;
    nodes_centre(m, first, end, c0, NULL);
    run_until(m, t_settled);
    nodes_centre(m, first, end, c, NULL);
    *settling = c[0] - c0[0];
    double t0 = fdem_get_time(m);
    run_until(m, t_end);
    nodes_centre(m, first, end, c0, NULL);
    *time = fdem_get_time(m) - t0;
    fdem_model_destroy(m);
    return c0[0] - c[0];
}

/* Above its friction angle the box slides at g (sin 30 - mu cos 30). */
static void box_slides_down_tilted_slab_with_friction(void)
{
    double t, settling, th = M_PI / 6, mu = 0.3;
    double slide = slab_slide(30, mu, 0, 0.12, &settling, &t);
    double want = 9.81 * (sin(th) - mu * cos(th)), got = 2 * slide / (t * t);
    CHECK_REL(got, want, 0.05);
    fprintf(stderr, "  slab 30 deg, mu 0.3: acceleration %.5g m/s^2, g (sin - mu cos) %.5g "
            "(%+.2f%%), slid %.4g m in %.3g s\n", got, want, 100 * (got - want) / want, slide, t);
}

/* Below it (mu 0.7 > tan 30 = 0.577) the stick springs hold the box. Let
 * go touching the slab, it carries no normal force at first and slips a
 * little while it settles (tens of micrometres: the box's own shear under
 * the 490 Pa of m g sin 30 over its base is 6 um at the centre); then it
 * must not creep: less than 0.1 um over the next 0.25 s, in which it would
 * slide 0.15 m free. */
static void box_sticks_on_slab_below_friction_angle(void)
{
    double t, settling;
    double slide = slab_slide(30, 0.7, 0.05, 0.3, &settling, &t);
    CHECK(fabs(settling) < 5e-5, "slipped %g m while settling", settling);
    CHECK(fabs(slide) < 1e-7, "crept %g m in %g s", slide, t);
    fprintf(stderr, "  slab 30 deg, mu 0.7: moved %.3g m while settling, then %.3g m in %.3g s\n",
            settling, slide, t);
}

/* Five slabs (a floor and four walls) as one fixed part, so that they do
 * not contact each other: one mesh of five pieces. */
static void add_container(fdem_model *m, int mat, double X, double Y, double H, double T)
{
    fdem_tet_mesh all = {0};
    fdem_error err = {0};
    int ok = build_container_mesh(X, Y, H, T, 0.08, &all, &err) == 0;
    CHECK(ok, "%s", err.message);
    if (ok) fix_part(m, add_mesh(m, &all, mat, NULL, NULL));
}

/* The radius of the largest sphere inside the polyhedron the sphere
 * generator makes (divisions 8): the smallest distance from the centre to
 * a boundary face, a face that only one tetrahedron has. */
static double sphere_inscribed_radius(double R)
{
    fdem_tet_mesh mesh = {0};
    fdem_error err = {0};
    const double origin[3] = {0, 0, 0};
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    if (fdem_tet_mesh_sphere(origin, R, 8, &mesh, &err)) return NAN;
    double inscribed = INFINITY;
    for (int t = 0; t < mesh.tet_count; t++)
        for (int f = 0; f < 4; f++) {
            int32_t a[3], shared = 0;
            for (int v = 0; v < 3; v++) a[v] = mesh.tet[4 * t + face[f][v]];
            for (int u = 0; u < mesh.tet_count && !shared; u++) {
                int found = 0;
                for (int v = 0; v < 3; v++)
                    for (int w = 0; w < 4; w++) found += mesh.tet[4 * u + w] == a[v];
                shared = u != t && found == 3;
            }
            if (shared) continue;
            const double *p = mesh.xyz + 3 * a[0], *q = mesh.xyz + 3 * a[1], *r = mesh.xyz + 3 * a[2];
            double e1[3], e2[3], n[3];
            for (int d = 0; d < 3; d++) e1[d] = q[d] - p[d], e2[d] = r[d] - p[d];
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            inscribed = fmin(inscribed, fabs(n[0] * p[0] + n[1] * p[1] + n[2] * p[2]) / len);
        }
    fdem_tet_mesh_free(&mesh);
    return inscribed;
}

/* Eight spheres of radius R = 0.05 (8 divisions) over a 3 x 2 floor in a
 * box of fixed slabs (sphere_pile_settles_without_interpenetration says
 * where); their nodes are first[k] to end[k], X and Y the box. NULL if it
 * could not be built (the failure is checked). */
enum { PILE_SPHERES = 8 };
static fdem_model *sphere_pile(double R, int first[PILE_SPHERES], int end[PILE_SPHERES],
                               double *X, double *Y)
{
    fdem_model *m = model_3d();
    int wall = add_material(m, solid(1000, 3e5, 0.1, 0.3, 1e6));
    int ball = add_material(m, solid(1000, 3e5, 0.3, 0.3, 1e6));
    const double pitch = 2 * R + 0.002;
    *X = 3 * pitch;
    *Y = 2 * pitch;
    add_container(m, wall, *X, *Y, 0.25, 0.04);
    double rest = R + 0.002 + sqrt(4 * R * R - 0.5 * pitch * pitch); /* in a pocket */
    for (int k = 0; k < PILE_SPHERES; k++) {
        double c[3];
        if (k < 6) {
            c[0] = 0.5 * pitch + pitch * (k % 3);
            c[1] = 0.5 * pitch + pitch * (k / 3);
            c[2] = R + 0.002;
        } else {
            c[0] = pitch * (k - 5) + 0.003;
            c[1] = pitch - 0.002;
            c[2] = rest + 0.01;
        }
        add_sphere(m, ball, c, R, 8, &first[k], &end[k]);
    }
    const double g[3] = {0, 0, -9.81};
    fdem_set_gravity_v(m, g);
    if (finalize(m, 0.5)) return NULL;
    return m;
}

/* Eight spheres of radius R = 0.05 dropped into a box of fixed slabs, six
 * on the floor (3 x 2, 2 mm above it, 2 mm apart) and two above the
 * pockets between them, 1 cm higher than where they rest. By 0.25 s their
 * kinetic energy is below 5 % of gravity's work and less than half what it
 * was at 0.15 s; no two centres are closer than 0.9 x 2R, and no node of
 * one sphere is more than 0.05 R inside the sphere inscribed in another
 * (the coarse spheres are polyhedra whose faces come as close as 0.8 R to
 * the centre; a node resting on a face sits on that sphere). Soft (E =
 * 0.3 MPa, p = 1 MPa) for long steps; the penalty sets how far a vertex
 * of an upper sphere presses into a face under its weight, which grows as
 * p^(-1/3): measured 0.04 R inside the inscribed sphere at p = 0.3 MPa,
 * 0.01 R at 1 MPa, none at 3 MPa. */
static void sphere_pile_settles_without_interpenetration(void)
{
    enum { SPHERES = PILE_SPHERES };
    const double R = 0.05;
    int first[SPHERES], end[SPHERES];
    double X, Y;
    fdem_model *m = sphere_pile(R, first, end, &X, &Y);
    if (!m) return;
    run_until(m, 0.15);
    double kinetic_before = fdem_get_energy(m).kinetic;
    run_until(m, 0.25);
    fdem_energy en = fdem_get_energy(m);
    CHECK(en.kinetic < 0.05 * en.gravity_work, "still moving: kinetic %g of gravity work %g",
          en.kinetic, en.gravity_work);
    CHECK(en.kinetic < 0.5 * kinetic_before, "kinetic %g at 0.25 s, %g at 0.15 s", en.kinetic,
          kinetic_before);
    double centre[SPHERES][3];
    for (int k = 0; k < SPHERES; k++) nodes_centre(m, first[k], end[k], centre[k], NULL);
    double closest = INFINITY, deepest = -INFINITY, inscribed = sphere_inscribed_radius(R);
    const double *x = fdem_positions(m);
    for (int i = 0; i < SPHERES; i++)
        for (int j = 0; j < SPHERES; j++) {
            if (i == j) continue;
            double d = sqrt(pow(centre[i][0] - centre[j][0], 2) + pow(centre[i][1] - centre[j][1], 2) +
                            pow(centre[i][2] - centre[j][2], 2));
            closest = fmin(closest, d / (2 * R));
            for (int n = first[j]; n < end[j]; n++) { /* j's nodes inside i's inscribed sphere */
                double r = sqrt(pow(x[3 * n] - centre[i][0], 2) + pow(x[3 * n + 1] - centre[i][1], 2) +
                                pow(x[3 * n + 2] - centre[i][2], 2));
                deepest = fmax(deepest, (inscribed - r) / R);
            }
        }
    CHECK(closest > 0.9, "two spheres' centres only %.3f diameters apart", closest);
    CHECK(deepest < 0.05, "a node %.3f R inside another sphere's inscribed sphere", deepest);
    for (int k = 0; k < SPHERES; k++)
        CHECK(centre[k][2] > 0 && centre[k][0] > 0 && centre[k][0] < X && centre[k][1] > 0 &&
                  centre[k][1] < Y,
              "sphere %d left the box: %g %g %g", k, centre[k][0], centre[k][1], centre[k][2]);
    fprintf(stderr, "  pile: closest centres %.3f diameters, deepest node %+.3f R inside another's "
            "inscribed sphere (%.3f R), kinetic/gravity work %.2g (at 0.15 s %.2g), %lld steps, "
            "%d candidate pairs\n", closest, deepest, inscribed / R, en.kinetic / en.gravity_work,
            kinetic_before / en.gravity_work, (long long)fdem_get_step(m),
            fdem_get_counts(m).contact_pairs);
    fdem_model_destroy(m);
}

/* Touching pairs among every candidate pair at the positions pos, each put
 * to the kernel (tet_contact_pair) when the two boxes overlap. */
static int touching_candidates(const fdem_model *m, const double *pos)
{
    const contact_state *cs = &m->contact;
    int touching = 0;
    for (size_t k = 0; k < cs->pairs.count; k++) {
        const int32_t *na = m->tet[cs->pairs.a[k]].node, *nb = m->tet[cs->pairs.b[k]].node;
        int apart = 0;
        for (int d = 0; d < 3 && !apart; d++) {
            double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
            for (int v = 0; v < 4; v++) {
                lo[0] = fmin(lo[0], pos[3 * na[v] + d]), hi[0] = fmax(hi[0], pos[3 * na[v] + d]);
                lo[1] = fmin(lo[1], pos[3 * nb[v] + d]), hi[1] = fmax(hi[1], pos[3 * nb[v] + d]);
            }
            apart = hi[0] < lo[1] || hi[1] < lo[0];
        }
        double fa[12], fb[12];
        if (!apart && tet_contact_pair(pos, na, nb, 1.0, fa, fb) > 0) touching++;
    }
    return touching;
}

/* The walk takes only the near list (contact.c): candidate pairs whose boxes
 * can overlap before some node travels the list's reach, a shorter reach in
 * 3D, so the list is rebuilt often as the pile falls. What it leaves out
 * must never touch: every 50th step of the settling pile (every 400th under
 * the sanitizers) the pairs the step found touching are counted against
 * every candidate pair at the positions the step starts from. A step that
 * detects again (a new candidate list) is not compared. */
static void near_list_misses_no_touching_pair(void)
{
    int first[PILE_SPHERES], end[PILE_SPHERES];
    double X, Y;
    fdem_model *m = sphere_pile(0.05, first, end, &X, &Y);
    if (!m) return;
#ifdef FDEM_SAN
    const int every = 400;
#else
    const int every = 50;
#endif
    size_t bytes = sizeof(double) * 3 * (size_t)m->node_count;
    double *start = malloc(bytes), *kept = calloc(1, bytes); /* kept: the list's pos_near */
    fdem_error err = {0};
    int compared = 0, busiest = 0, rebuilds = 0;
    for (int s = 0; s < 2500 && start && kept; s++) {
        long detections = m->contact.detections;
        int check = s % every == 0 && m->contact.pairs.count > 0;
        if (check) memcpy(start, m->pos, bytes);
        if (fdem_step(m, &err)) {
            CHECK(0, "step %d: %s", s, err.message);
            break;
        }
        if (memcmp(kept, m->contact.pos_near, bytes)) {
            memcpy(kept, m->contact.pos_near, bytes);
            rebuilds++;
        }
        if (!check || m->contact.detections != detections) continue;
        int expected = touching_candidates(m, start);
        CHECK(m->contact.touching == expected, "step %d: %d pairs touched, %d candidates touch", s,
              m->contact.touching, expected);
        busiest = expected > busiest ? expected : busiest;
        compared++;
    }
    CHECK(compared >= 2500 / every / 2, "only %d steps compared", compared);
    CHECK(busiest > 20, "at most %d touching pairs: nothing to miss", busiest);
    CHECK(rebuilds > 2500 / every, "the near list was rebuilt %d times only", rebuilds);
    fprintf(stderr, "  near list: %d steps compared, up to %d touching pairs, %d rebuilds\n",
            compared, busiest, rebuilds);
    free(start);
    free(kept);
    fdem_model_destroy(m);
}

/* A 4 x 4 x 2-cell box sliding with friction on a slab: enough candidate
 * pairs for the threaded pair loop. */
static fdem_model *sliding_box(int threads)
{
    fdem_model *m = model_3d();
    fdem_error err = {0};
    int mat = add_material(m, solid(1000, 1e7, 0.1, 0.4, 0));
    const double slab_origin[3] = {0, 0, -0.05}, slab_dims[3] = {0.4, 0.3, 0.05};
    const int slab_div[3] = {8, 6, 1};
    const double box_origin[3] = {0.05, 0.05, 0.0}, box_dims[3] = {0.2, 0.2, 0.1};
    const int box_div[3] = {4, 4, 2};
    fix_part(m, add_box(m, mat, slab_origin, slab_dims, slab_div, NULL, NULL));
    int box = add_box(m, mat, box_origin, box_dims, box_div, NULL, NULL);
    const double v[3] = {0.5, 0.2, -0.05}, g[3] = {2, 0, -9.81};
    CHECK(fdem_set_part_velocity_v(m, box, v, &err) == 0, "%s", err.message);
    fdem_set_gravity_v(m, g);
    fdem_set_threads(m, threads);
    if (finalize(m, 0.5)) {
        fdem_model_destroy(m);
        return NULL;
    }
    return m;
}

static int run_steps(fdem_model *m, int steps)
{
    for (int s = 0; s < steps; s++)
        if (step(m)) return -1;
    return 0;
}

static void same_bits(const fdem_model *a, const fdem_model *b, const char *what)
{
    fdem_counts c = fdem_get_counts(a);
    size_t nb = sizeof(double) * 3 * (size_t)c.nodes;
    CHECK(memcmp(fdem_positions(a), fdem_positions(b), nb) == 0, "%s: positions differ", what);
    CHECK(memcmp(fdem_velocities(a), fdem_velocities(b), nb) == 0, "%s: velocities differ", what);
    fdem_energy ea = fdem_get_energy(a), eb = fdem_get_energy(b);
    CHECK(memcmp(&ea, &eb, sizeof ea) == 0, "%s: energies differ", what);
}

static void two_threads_give_the_same_bits_with_contact(void)
{
    fdem_model *m[2] = {sliding_box(1), sliding_box(2)};
    if (!m[0] || !m[1]) return;
    for (int k = 0; k < 2; k++) run_steps(m[k], 200);
    fdem_counts c = fdem_get_counts(m[0]);
    CHECK(c.contact_pairs >= 2048, "only %d candidate pairs: the threaded loop is not run",
          c.contact_pairs);
    CHECK(c.contacts > 0, "no contact");
    CHECK(fdem_get_energy(m[0]).friction > 0, "no sliding");
    same_bits(m[0], m[1], "1 and 2 threads");
    fprintf(stderr, "  threads: %d candidate pairs, %d touching\n", c.contact_pairs, c.contacts);
    fdem_model_destroy(m[0]);
    fdem_model_destroy(m[1]);
}

/* Pairs holding stick springs in a model (engine internals). */
static long sprung_pairs(const fdem_model *m)
{
    long n = 0;
    for (size_t k = 0; k < m->contact.pairs.count; k++) n += contact_pair_sprung(&m->contact, k);
    return n;
}

static void restored_model_steps_on_to_the_same_bits_with_springs(void)
{
    fdem_model *a = sliding_box(1), *b = sliding_box(1);
    if (!a || !b) return;
    run_steps(a, 200);
    CHECK(sprung_pairs(a) > 0, "no stick spring held at the checkpoint");
    size_t size = fdem_checkpoint_size(a);
    void *buf = malloc(size);
    fdem_error err = {0};
    CHECK(fdem_checkpoint_write(a, buf, size) == 0, "write");
    CHECK(fdem_checkpoint_read(b, buf, size, &err) == 0, "%s", err.message);
    free(buf);
    CHECK(sprung_pairs(b) == sprung_pairs(a), "springs %ld restored of %ld", sprung_pairs(b),
          sprung_pairs(a));
    run_steps(a, 200);
    run_steps(b, 200);
    same_bits(a, b, "restored");
    fdem_model_destroy(a);
    fdem_model_destroy(b);
}

CHECK_MAIN(T(boxes_colliding_conserve_momentum_and_energy),
           T(boxes_flat_impact_keeps_its_energy_at_every_safety),
           T(box_slides_down_tilted_slab_with_friction),
           T(box_sticks_on_slab_below_friction_angle),
           T(sphere_pile_settles_without_interpenetration),
           T(near_list_misses_no_touching_pair),
           T(two_threads_give_the_same_bits_with_contact),
           T(restored_model_steps_on_to_the_same_bits_with_springs))
