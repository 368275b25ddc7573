/*
 * test_boundary_load.c - pressures and absorbing boundaries (contract 5.3,
 * PHYSICS.md "Boundaries for rock engineering") and the amplitudes that ramp
 * loads, each against a closed form:
 *  - a uniform pressure on a closed surface sums to zero, on one face of a
 *    block to p times its area, along the inward normal (2D and 3D);
 *  - a thick ring under a slowly ramped internal pressure carries Lame's
 *    hoop stress at the bore, p (b^2 + a^2) / (b^2 - a^2), to 5 %;
 *  - a plane P pulse leaves a bar through an absorbing end (under 5 % of its
 *    energy stays) and comes back from a free end without it (over 80 %),
 *    and so does a plane S pulse; each puts in the energy its impedance
 *    takes;
 *  - a fracturing part's pressure loads its outline only;
 *  - a checkpoint carries ramped loads across a restore to the bit;
 *  - a velocity ramped from zero starts without the force step of an
 *    impedance rho c v;
 *  - the energy balance closes with pressures, dashpots and a ramped
 *    gravity.
 */
#include "build_model.h"
#include "check.h"
#include "mesh/mesh_3d.h"
#include "model/model.h"

static void add_constraint(fdem_model *m, const fdem_constraint_def *c)
{
    fdem_error err;
    if (fdem_add_constraint(m, c, &err) < 0) build_die("constraint", &err);
}

static fdem_constraint_def pressure_on_part(int body, double p)
{
    return (fdem_constraint_def){.select = FDEM_SELECT_PART, .part = body,
                                 .kind = FDEM_CONSTRAINT_PRESSURE, .value = {p}};
}

/* 21 (t, a) pairs: a ramp 0 -> 1 as (1 - cos)/2 over T, and a sin^2 pulse
 * lasting tau, smooth enough to excite little beyond their own time scale. */
static void ramp_table(double table[42], double T)
{
    for (int k = 0; k <= 20; k++) {
        table[2 * k] = T * k / 20;
        table[2 * k + 1] = 0.5 * (1 - cos(M_PI * k / 20));
    }
}

static void pulse_table(double table[42], double tau)
{
    for (int k = 0; k <= 20; k++) {
        table[2 * k] = tau * k / 20;
        table[2 * k + 1] = pow(sin(M_PI * k / 20), 2);
    }
}

/* The pressure's nodal forces after one step, as the constraint reports. */
static const double *forces_after_one_step(fdem_model *m)
{
    fdem_error err;
    if (fdem_step(m, &err)) build_die("step", &err);
    return fdem_constraint_forces(m);
}

static void pressure_totals_2d(void)
{
    const double p = 2e6, W = 0.3, H = 0.2;
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 2500, 1e10, 0.25, 0, 0);
    int body = build_rectangle(m, mat, 0, 0, W, H, 6, 4);
    fdem_constraint_def all = pressure_on_part(body, p);
    fdem_constraint_def left = {.select = FDEM_SELECT_BOX, .box = {-0.01, -0.01, 0.01, H + 0.01},
                                .kind = FDEM_CONSTRAINT_PRESSURE, .value = {p}};
    add_constraint(m, &all);
    add_constraint(m, &left);
    build_finalize(m, 0.5);
    CHECK(m->constraints[0].facet_count == 2 * (6 + 4), "%d boundary edges, want 20",
          m->constraints[0].facet_count);
    const double *f = forces_after_one_step(m);
    CHECK_NEAR(f[0], 0, 1e-9 * p * W);
    CHECK_NEAR(f[1], 0, 1e-9 * p * W);
    CHECK_REL(f[2], p * H, 1e-12); /* inward on the left edge: +x */
    CHECK_NEAR(f[3], 0, 1e-9 * p * H);
    fdem_model_destroy(m);
}

static void pressure_totals_3d(void)
{
    const double p = 1e6, size[3] = {0.3, 0.2, 0.1}, origin[3] = {0, 0, 0};
    const int div[3] = {3, 2, 2};
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_material(m, 2500, 1e10, 0.25, 0, 0);
    fdem_tet_mesh mesh;
    if (fdem_tet_mesh_box(origin, size, div, &mesh, &err)) build_die("box", &err);
    int body = fdem_add_part_3d(m, &mesh, mat, 0, &err);
    fdem_tet_mesh_free(&mesh);
    if (body < 0) build_die("part", &err);
    fdem_constraint_def all = pressure_on_part(body, p);
    fdem_constraint_def top = {.select = FDEM_SELECT_BOX, .box = {-1, -1, 0.099, 1, 1, 0.101},
                               .kind = FDEM_CONSTRAINT_PRESSURE, .value = {p}};
    add_constraint(m, &all);
    add_constraint(m, &top);
    build_finalize(m, 0.5);
    const double *f = forces_after_one_step(m);
    for (int d = 0; d < 3; d++) CHECK_NEAR(f[d], 0, 1e-9 * p * 0.06);
    CHECK_NEAR(f[3], 0, 1e-9 * p * 0.06);
    CHECK_NEAR(f[4], 0, 1e-9 * p * 0.06);
    CHECK_REL(f[5], -p * size[0] * size[1], 1e-12); /* inward on the top face: -z */
    fdem_model_destroy(m);
}

/* A ring a <= r <= b of nr x nt quadrilaterals, each split in two
 * triangles (alternating diagonals). */
static fdem_mesh ring_mesh(double a, double b, int nr, int nt)
{
    fdem_mesh mesh = {0};
    mesh.node_count = (nr + 1) * nt;
    mesh.triangle_count = 2 * nr * nt;
    mesh.xy = malloc(sizeof(double) * 2 * (size_t)mesh.node_count);
    mesh.tri = malloc(sizeof(int32_t) * 3 * (size_t)mesh.triangle_count);
    if (!mesh.xy || !mesh.tri) exit(2);
    for (int i = 0; i <= nr; i++)
        for (int j = 0; j < nt; j++) {
            double r = a + (b - a) * i / nr, th = 2 * M_PI * j / nt;
            mesh.xy[2 * (i * nt + j)] = r * cos(th);
            mesh.xy[2 * (i * nt + j) + 1] = r * sin(th);
        }
    int32_t *t = mesh.tri;
    for (int i = 0; i < nr; i++)
        for (int j = 0; j < nt; j++) {
            int32_t n00 = i * nt + j, n01 = i * nt + (j + 1) % nt;
            int32_t n10 = n00 + nt, n11 = n01 + nt;
            if ((i + j) % 2) {
                *t++ = n00; *t++ = n10; *t++ = n11;
                *t++ = n00; *t++ = n11; *t++ = n01;
            } else {
                *t++ = n00; *t++ = n10; *t++ = n01;
                *t++ = n01; *t++ = n10; *t++ = n11;
            }
        }
    return mesh;
}

/* The triangles extruded into a slice `thickness` thick: each prism split
 * into three tetrahedra by its sorted vertex numbers, which makes the
 * diagonals of neighbouring prisms' shared faces agree. */
static fdem_tet_mesh extrude(const fdem_mesh *tri, double thickness)
{
    const int N = tri->node_count;
    fdem_tet_mesh mesh = {0};
    mesh.node_count = 2 * N;
    mesh.tet_count = 3 * tri->triangle_count;
    mesh.xyz = malloc(sizeof(double) * 3 * (size_t)mesh.node_count);
    mesh.tet = malloc(sizeof(int32_t) * 4 * (size_t)mesh.tet_count);
    if (!mesh.xyz || !mesh.tet) exit(2);
    for (int layer = 0; layer < 2; layer++)
        for (int i = 0; i < N; i++) {
            double *x = mesh.xyz + 3 * (size_t)(layer * N + i);
            x[0] = tri->xy[2 * i];
            x[1] = tri->xy[2 * i + 1];
            x[2] = layer * thickness;
        }
    for (int e = 0; e < tri->triangle_count; e++) {
        int32_t v[3] = {tri->tri[3 * e], tri->tri[3 * e + 1], tri->tri[3 * e + 2]};
        for (int p = 0; p < 2; p++)
            for (int q = 0; q < 2 - p; q++)
                if (v[q] > v[q + 1]) {
                    int32_t tmp = v[q];
                    v[q] = v[q + 1];
                    v[q + 1] = tmp;
                }
        int32_t a = v[0], b = v[1], c = v[2], A = a + N, B = b + N, C = c + N;
        const int32_t tets[3][4] = {{a, b, c, C}, {a, b, B, C}, {a, A, B, C}};
        memcpy(mesh.tet + 12 * (size_t)e, tets, sizeof tets);
    }
    return mesh;
}

/* The ring as a 2D part, or in 3D a slice 0.05 m thick held in z (plane
 * strain, as the 2D model is). */
static void build_ring(fdem_model *m, int dim, int mat, double a, double b, int nr, int nt)
{
    fdem_mesh mesh = ring_mesh(a, b, nr, nt);
    fdem_error err;
    int body;
    if (dim == 2) {
        body = fdem_add_part(m, &mesh, mat, 0, &err);
    } else {
        fdem_tet_mesh slice = extrude(&mesh, 0.05);
        body = fdem_add_part_3d(m, &slice, mat, 0, &err);
        fdem_tet_mesh_free(&slice);
        fdem_constraint_def flat = {.select = FDEM_SELECT_PART, .part = body,
                                    .kind = FDEM_CONSTRAINT_FIX, .fix_z = 1};
        if (body >= 0) add_constraint(m, &flat);
    }
    fdem_mesh_free(&mesh);
    if (body < 0) build_die("ring", &err);
}

/* Mean hoop stress of the elements whose centroid radius is in [r0, r1). */
static double mean_hoop_stress(const fdem_model *m, double r0, double r1, double *r_mean)
{
    const int E = fdem_get_counts(m).elements, D = fdem_get_dimension(m);
    const int K = fdem_nodes_per_element(m), S = fdem_stress_components(m);
    const int xy = D == 3 ? 5 : 2; /* where sxy is in an element's stress */
    double *s = malloc(sizeof(double) * (size_t)S * (size_t)E);
    fdem_element_stress(m, s);
    const double *x = fdem_initial_positions(m);
    const int32_t *node = fdem_element_nodes(m);
    double sum = 0, rs = 0;
    int n = 0;
    for (int e = 0; e < E; e++) {
        double cx = 0, cy = 0;
        for (int k = 0; k < K; k++) {
            cx += x[D * node[K * e + k]] / K;
            cy += x[D * node[K * e + k] + 1] / K;
        }
        double r = hypot(cx, cy), c = cx / r, sn = cy / r;
        if (r < r0 || r >= r1) continue;
        const double *se = s + (size_t)S * (size_t)e;
        sum += se[0] * sn * sn - 2 * se[xy] * sn * c + se[1] * c * c;
        rs += r;
        n++;
    }
    free(s);
    *r_mean = rs / n;
    return sum / n;
}

/* Lame: a = 0.5 m, b = 1 m, p = 10 MPa ramped as 1 - cos over 10 periods
 * of the ring's breathing mode, then held; the hoop stress of the first two
 * rings of elements, averaged over the last breathing period and
 * extrapolated linearly to the bore. Returns its relative error. */
static double ring_under_internal_pressure(int dim, int nr, int nt)
{
    const double a = 0.5, b = 1.0, p = 1e7, E = 1e10, nu = 0.25, rho = 2500;
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (fdem_set_dimension(m, dim, &err)) build_die("dimension", &err);
    int mat = build_material(m, rho, E, nu, 0, 0);
    build_ring(m, dim, mat, a, b, nr, nt);
    double c_p = sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
    double period = 2 * M_PI * 0.75 / c_p * 1.6; /* about the breathing mode's, and longer */
    double T = 10 * period;
    double table[2 * 21];
    ramp_table(table, T);
    fdem_constraint_def bore = {.select = FDEM_SELECT_BOX, .kind = FDEM_CONSTRAINT_PRESSURE,
                                .value = {p}, .amplitude = table, .amplitude_count = 21};
    for (int d = 0; d < dim; d++) {
        bore.box[d] = d < 2 ? -a - 1e-3 : -1;
        bore.box[dim + d] = d < 2 ? a + 1e-3 : 1;
    }
    add_constraint(m, &bore);
    build_finalize(m, 0.5);
    /* the bore's facets: all their nodes at r = a (in 3D the box also
     * takes the slice's flat faces near the bore, which the z fixity holds) */
    const constraint *c = &m->constraints[m->constraint_count - 1];
    int on_bore = 0;
    for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++) {
        int all = 1;
        for (int k = 0; k < dim; k++) {
            const double *x = m->pos0 + dim * m->bfacet_node[dim * j + k];
            all &= fabs(hypot(x[0], x[1]) - a) < 1e-9;
        }
        on_bore += all;
    }
    int want = dim == 3 ? 2 * nt : nt; /* 3D: two triangles per bore quadrilateral */
    CHECK(on_bore == want, "%d bore facets, want %d", on_bore, want);
    CHECK(dim == 3 || c->facet_count == nt, "%d facets loaded in 2D, want %d", c->facet_count, nt);
    double dr = (b - a) / nr, s1 = 0, s2 = 0, r1 = 0, r2 = 0;
    int samples = 0;
    while (fdem_get_time(m) < T + 2 * period) {
        if (fdem_step(m, &err)) build_die("step", &err);
        if (fdem_get_time(m) > T + period && m->step % 10 == 0) {
            double ra, rb;
            s1 += mean_hoop_stress(m, a, a + dr, &ra);
            s2 += mean_hoop_stress(m, a + dr, a + 2 * dr, &rb);
            r1 = ra;
            r2 = rb;
            samples++;
        }
    }
    s1 /= samples;
    s2 /= samples;
    double at_bore = s1 + (s2 - s1) * (a - r1) / (r2 - r1);
    double lame = p * (b * b + a * a) / (b * b - a * a);
    fprintf(stderr, "  %dD ring %d x %d: hoop stress at r = %.4f: %.4g, at %.4f: %.4g, at the bore "
                    "%.4g Pa; Lame %.4g Pa (%+.2f %%)\n",
            dim, nr, nt, r1, s1, r2, s2, at_bore, lame, 100 * (at_bore / lame - 1));
    fdem_energy en = fdem_get_energy(m);
    CHECK(fabs(en.residual) < 1e-3 * en.external_work, "residual %g of external work %g",
          en.residual, en.external_work);
    fdem_model_destroy(m);
    return at_bore / lame - 1;
}

/* 2D: 16 x 128 quadrilaterals (4096 triangles). */
static void ring_under_internal_pressure_2d(void)
{
    CHECK(fabs(ring_under_internal_pressure(2, 16, 128)) < 0.05, "more than 5 %% off Lame");
}

/* 3D: a ring of 8 x 64 quadrilaterals extruded into one layer of 3072
 * tetrahedra, held in z. */
static void ring_under_internal_pressure_3d(void)
{
    CHECK(fabs(ring_under_internal_pressure(3, 8, 64)) < 0.05, "more than 5 %% off Lame");
}

/* A 1D-like bar: L x 0.1 m of 200 x 2 cells, every node held in y so the
 * wave is a plane P wave of speed c_p = sqrt((lambda + 2 mu) / rho). */
static const double bar_L = 10, bar_H = 0.1, bar_rho = 2500, bar_E = 1e10, bar_nu = 0.25;

static double bar_wave_speed(void)
{
    return sqrt(bar_E * (1 - bar_nu) / (bar_rho * (1 + bar_nu) * (1 - 2 * bar_nu)));
}

/* The bar in 2D (triangles) or 3D (a 200 x 2 x 2 box of tetrahedra, H x H
 * across), held in y and z for P waves, in x and z for S waves polarised
 * in y (shear != 0). */
static fdem_model *build_bar(int dim, int shear)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (fdem_set_dimension(m, dim, &err)) build_die("dimension", &err);
    int mat = build_material(m, bar_rho, bar_E, bar_nu, 0, 0);
    if (dim == 2) {
        build_rectangle(m, mat, 0, 0, bar_L, bar_H, 200, 2);
    } else {
        const double origin[3] = {0, 0, 0}, size[3] = {bar_L, bar_H, bar_H};
        const int div[3] = {200, 2, 2};
        fdem_tet_mesh mesh;
        if (fdem_tet_mesh_box(origin, size, div, &mesh, &err)) build_die("box", &err);
        int body = fdem_add_part_3d(m, &mesh, mat, 0, &err);
        fdem_tet_mesh_free(&mesh);
        if (body < 0) build_die("bar", &err);
    }
    fdem_constraint_def lateral = {.select = FDEM_SELECT_BOX, .kind = FDEM_CONSTRAINT_FIX,
                                   .fix_x = shear, .fix_y = !shear, .fix_z = 1};
    for (int d = 0; d < dim; d++) {
        lateral.box[d] = -1;
        lateral.box[dim + d] = bar_L + 1;
    }
    add_constraint(m, &lateral);
    return m;
}

/* The box {x <= x1} or {x >= x0} across the bar, in the model's layout. */
static void bar_end_box(int dim, double x0, double x1, double box[6])
{
    for (int d = 0; d < dim; d++) {
        box[d] = d == 0 ? x0 : -1;
        box[dim + d] = d == 0 ? x1 : 1;
    }
}

/* Sends a sin^2 pulse 1 m (20 cells) long into the bar at x = 0 and runs
 * until 1.5 transits after it: a P pulse of pressure (1 MPa) on a bar held
 * in y, or (shear) an S pulse of velocity (0.1 m/s in y, the end held still
 * after it) on a bar held in x. The far end is free or absorbing. Returns
 * the accounts at the end; *worst gets the largest |residual| on the way. */
static fdem_energy send_pulse(int dim, int shear, int absorb, double c, double *worst)
{
    fdem_model *m = build_bar(dim, shear);
    const double tau = 1.0 / c;
    double table[2 * 21];
    pulse_table(table, tau);
    fdem_constraint_def drive = {.select = FDEM_SELECT_BOX, .amplitude = table,
                                 .amplitude_count = 21};
    if (shear) {
        drive.kind = FDEM_CONSTRAINT_VELOCITY;
        drive.value[1] = 0.1;
        drive.free_x = drive.free_z = 1;
    } else {
        drive.kind = FDEM_CONSTRAINT_PRESSURE;
        drive.value[0] = 1e6;
    }
    fdem_constraint_def end = {.select = FDEM_SELECT_BOX, .kind = FDEM_CONSTRAINT_ABSORB};
    bar_end_box(dim, -1, 1e-6, drive.box);
    bar_end_box(dim, bar_L - 1e-6, bar_L + 1, end.box);
    add_constraint(m, &drive);
    if (absorb) add_constraint(m, &end);
    build_finalize(m, 0.5);
    fdem_error err;
    *worst = 0;
    while (fdem_get_time(m) < tau + 1.5 * bar_L / c) {
        if (fdem_step(m, &err)) build_die("step", &err);
        *worst = fmax(*worst, fabs(fdem_get_energy(m).residual));
    }
    fdem_energy en = fdem_get_energy(m);
    fprintf(stderr, "  %dD %s pulse, %s end: %.4g J/m in, %.4g %% left, %.4g J/m absorbed; worst "
                    "residual %.3g %% of the input\n",
            dim, shear ? "S" : "P", absorb ? "absorbing" : "free", en.external_work,
            100 * (en.kinetic + en.elastic) / en.external_work, en.damping,
            100 * *worst / en.external_work);
    CHECK(*worst < 0.01 * en.external_work, "residual %g J/m", *worst);
    fdem_model_destroy(m);
    return en;
}

/* P pulse: free end, all of the energy stays (R = 1); Lysmer dashpot, next
 * to nothing (R = 0 for a plane wave). What the pressure puts in a bar of
 * impedance rho c is the integral of p^2 A / (rho c), 3/8 p0^2 A tau /
 * (rho c) for a sin^2 pulse. Returns the fraction left. */
static double energy_left_after_pulse(int dim, int absorb)
{
    const double c = bar_wave_speed(), area = dim == 3 ? bar_H * bar_H : bar_H;
    double worst;
    fdem_energy en = send_pulse(dim, 0, absorb, c, &worst);
    CHECK_REL(en.external_work, 0.375 * 1e12 * area / (c * bar_rho * c), 0.03);
    return (en.kinetic + en.elastic) / en.external_work;
}

static void pulse_leaves_through_absorbing_end(void)
{
    CHECK(energy_left_after_pulse(2, 1) < 0.05, "more than 5 %% reflected");
    CHECK(energy_left_after_pulse(3, 1) < 0.05, "more than 5 %% reflected (3D)");
}

static void pulse_reflects_from_free_end(void)
{
    CHECK(energy_left_after_pulse(2, 0) > 0.80, "less than 80 %% reflected");
    CHECK(energy_left_after_pulse(3, 0) > 0.80, "less than 80 %% reflected (3D)");
}

/* S pulse: the far end's tangential dashpot rho c_s takes it out. A
 * velocity v(t) drives rho c_s A v^2: 3/8 rho c_s A v0^2 tau for sin^2. */
static double energy_left_after_shear_pulse(int dim, int absorb)
{
    const double c_s = sqrt(bar_E / (2 * (1 + bar_nu) * bar_rho));
    const double area = dim == 3 ? bar_H * bar_H : bar_H;
    double worst;
    fdem_energy en = send_pulse(dim, 1, absorb, c_s, &worst);
    CHECK_REL(en.external_work, 0.375 * bar_rho * c_s * area * 0.01 / c_s, 0.03);
    return (en.kinetic + en.elastic) / en.external_work;
}

static void shear_pulse_leaves_through_absorbing_end(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        CHECK(energy_left_after_shear_pulse(dim, 1) < 0.05, "%dD: more than 5 %% reflected", dim);
        CHECK(energy_left_after_shear_pulse(dim, 0) > 0.80, "%dD: less than 80 %% reflected", dim);
    }
}

/* The reaction of a velocity v0 on the bar's end over its first steps: a
 * plane wave needs a stress rho c v, so a step in velocity is a step to
 * F = rho c v0 H at once, and a velocity ramped over T a force rising as
 * rho c v0 H t / T. Returns the largest |reaction| of the first `steps`
 * steps and, via at_half, the reaction at T / 2. */
static double end_reaction(int ramped, int steps, double T, double *at_half)
{
    fdem_model *m = build_bar(2, 0);
    double table[4] = {0, 0, T, 1};
    fdem_constraint_def drive = {.select = FDEM_SELECT_BOX, .box = {-1, -1, 1e-6, 1},
                                 .kind = FDEM_CONSTRAINT_VELOCITY, .value = {0.1, 0},
                                 .free_y = 1, .amplitude = ramped ? table : NULL,
                                 .amplitude_count = ramped ? 2 : 0};
    add_constraint(m, &drive);
    build_finalize(m, 0.5);
    fdem_error err;
    double largest = 0;
    *at_half = 0;
    while (fdem_get_time(m) < T / 2) {
        if (fdem_step(m, &err)) build_die("step", &err);
        double f = fdem_constraint_forces(m)[2];
        if (m->step <= steps) largest = fmax(largest, fabs(f));
        *at_half = f;
    }
    fdem_model_destroy(m);
    return largest;
}

static void ramped_velocity_has_no_force_step(void)
{
    const double c = bar_wave_speed(), F = bar_rho * c * 0.1 * bar_H;
    const double T = 2 / c; /* 40 cells of travel */
    double half_step, half_ramp;
    double step = end_reaction(0, 5, T, &half_step);
    double ramp = end_reaction(1, 5, T, &half_ramp);
    fprintf(stderr, "  velocity 0.1 m/s: first 5 steps' largest reaction %.4g N/m as a step, %.4g "
                    "N/m ramped; at T/2 %.4g and %.4g N/m; rho c v H = %.4g N/m\n",
            step, ramp, half_step, half_ramp, F);
    CHECK(step > 0.5 * F, "the step gave only %g N/m", step);
    CHECK(ramp < 0.05 * F, "the ramp gave %g N/m at once", ramp);
    CHECK_REL(fabs(half_step), F, 0.1);
    CHECK_REL(fabs(half_ramp), 0.5 * F, 0.1);
}

/* A block standing on a fixed base under gravity ramped as 1 - cos over
 * ten of its vertical periods: the accounts close (the ramped gravity's
 * work is booked step by step) and it ends nearly at rest, where the same
 * gravity switched on at once rings with a kinetic energy up to the static
 * elastic energy U_s (one mode: W = 2 U_s at the static position, U_s of it
 * elastic). Returns the largest kinetic energy after the ramp time, and in
 * *elastic the elastic energy at the end. */
static double block_under_gravity(int ramped, double *worst, double *elastic)
{
    fdem_model *m = fdem_model_create();
    const double H = 1, rho = 2500, E = 1e9, nu = 0.25;
    int mat = build_material(m, rho, E, nu, 0, 0);
    build_rectangle(m, mat, 0, 0, 1, H, 8, 8);
    fdem_constraint_def base = {.select = FDEM_SELECT_BOX, .box = {-1, -1e-6, 2, 1e-6},
                                .kind = FDEM_CONSTRAINT_FIX, .fix_x = 1, .fix_y = 1};
    add_constraint(m, &base);
    fdem_set_gravity(m, 0, -9.81);
    double c = sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu))), period = 4 * H / c;
    double T = 10 * period, table[2 * 21];
    ramp_table(table, T);
    fdem_error err;
    if (ramped && fdem_set_gravity_amplitude(m, table, 21, &err)) build_die("amplitude", &err);
    build_finalize(m, 0.5);
    *worst = 0;
    double kinetic_max = 0, residual = 0;
    while (fdem_get_time(m) < T + 2 * period) {
        if (fdem_step(m, &err)) build_die("step", &err);
        fdem_energy en = fdem_get_energy(m);
        residual = fmax(residual, fabs(en.residual));
        *worst = residual / fabs(en.gravity_work);
        if (fdem_get_time(m) > T) kinetic_max = fmax(kinetic_max, en.kinetic);
        *elastic = en.elastic;
    }
    fdem_model_destroy(m);
    return kinetic_max;
}

static void ramped_gravity_settles_and_balances(void)
{
    double worst_ramp, worst_step, u_static, u_end;
    double ramp = block_under_gravity(1, &worst_ramp, &u_static);
    double step = block_under_gravity(0, &worst_step, &u_end);
    fprintf(stderr, "  block under gravity: static elastic energy %.4g J/m; largest kinetic after "
                    "the ramp %.3g J/m, switched on at once %.3g J/m; worst residual %.3g %% (at "
                    "once %.3g %%) of the gravity work\n",
            u_static, ramp, step, 100 * worst_ramp, 100 * worst_step);
    CHECK(worst_ramp < 0.01, "residual %.3g of the gravity work", worst_ramp);
    CHECK(ramp < 0.01 * u_static, "kinetic %.3g J/m after the ramp", ramp);
    CHECK(step > 0.5 * u_static, "gravity at once should ring, kinetic %.3g J/m", step);
}

/* A column under ramped gravity with a pressure on its top and an absorbing
 * base, stepped 400 times straight through, or 200 times, checkpointed into
 * a freshly built model and stepped 200 more: the two end in the same state
 * and report the same accounts (the ramped gravity's work is carried across
 * the checkpoint by the accounts it stores). */
static fdem_model *build_loaded_column(void)
{
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, 2500, 1e9, 0.25, 0, 0);
    build_rectangle(m, mat, 0, 0, 0.2, 1, 2, 10);
    static const double ramp[] = {0, 0, 2e-3, 1};
    fdem_constraint_def top = {.select = FDEM_SELECT_BOX, .box = {-1, 0.999, 1, 2},
                               .kind = FDEM_CONSTRAINT_PRESSURE, .value = {1e5},
                               .amplitude = ramp, .amplitude_count = 2};
    fdem_constraint_def base = {.select = FDEM_SELECT_BOX, .box = {-1, -1, 1, 1e-6},
                                .kind = FDEM_CONSTRAINT_ABSORB};
    add_constraint(m, &top);
    add_constraint(m, &base);
    fdem_set_gravity(m, 0, -9.81);
    fdem_error err;
    if (fdem_set_gravity_amplitude(m, ramp, 2, &err)) build_die("amplitude", &err);
    build_finalize(m, 0.5);
    return m;
}

static void step_n(fdem_model *m, int n)
{
    fdem_error err;
    for (int k = 0; k < n; k++)
        if (fdem_step(m, &err)) build_die("step", &err);
}

static void checkpoint_carries_ramped_loads(void)
{
    fdem_model *straight = build_loaded_column();
    step_n(straight, 400);
    fdem_model *first = build_loaded_column();
    step_n(first, 200);
    size_t size = fdem_checkpoint_size(first);
    void *buf = malloc(size);
    fdem_error err;
    if (!buf || fdem_checkpoint_write(first, buf, size)) build_die("checkpoint", &err);
    fdem_model *second = build_loaded_column();
    if (fdem_checkpoint_read(second, buf, size, &err)) build_die("restore", &err);
    step_n(second, 200);
    fdem_energy a = fdem_get_energy(straight), b = fdem_get_energy(second);
    int n = fdem_get_counts(straight).nodes;
    CHECK(memcmp(fdem_positions(straight), fdem_positions(second), sizeof(double) * 2 * (size_t)n) == 0,
          "positions differ after the restore");
    CHECK_REL(b.gravity_work, a.gravity_work, 1e-9);
    CHECK_REL(b.external_work, a.external_work, 1e-9);
    CHECK_REL(b.damping, a.damping, 1e-9);
    CHECK(fabs(b.residual) < 1e-6 * a.gravity_work + 1e-6 * a.external_work, "residual %g", b.residual);
    fprintf(stderr, "  column: gravity work %.6g / %.6g, external %.6g / %.6g, dashpots %.6g / %.6g "
                    "J/m (straight / restored), residual %.3g J/m\n",
            a.gravity_work, b.gravity_work, a.external_work, b.external_work, a.damping, b.damping,
            b.residual);
    free(buf);
    fdem_model_destroy(straight);
    fdem_model_destroy(first);
    fdem_model_destroy(second);
}

/* A fracturing part has its own nodes in every element, joined by joints:
 * its boundary is still only the outline (facets are matched by mesh
 * vertex), so a pressure on the part loads 2 (nx + ny) edges in 2D and the
 * 2 x 2 (nx ny + ny nz + nz nx) outer triangles of a box in 3D, and sums
 * to zero. */
static void fracturing_part_boundary_is_its_outline(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *m = fdem_model_create();
        fdem_error err;
        if (fdem_set_dimension(m, dim, &err)) build_die("dimension", &err);
        int mat = build_fracturing_rock(m, 0);
        int body, want;
        if (dim == 2) {
            body = build_rectangle_part(m, mat, 0, 0, 0.3, 0.2, 6, 4, 1);
            want = 2 * (6 + 4);
        } else {
            const double origin[3] = {0, 0, 0}, size[3] = {0.3, 0.2, 0.1};
            const int div[3] = {3, 2, 2};
            fdem_tet_mesh mesh;
            if (fdem_tet_mesh_box(origin, size, div, &mesh, &err)) build_die("box", &err);
            body = fdem_add_part_3d(m, &mesh, mat, 1, &err);
            fdem_tet_mesh_free(&mesh);
            if (body < 0) build_die("part", &err);
            want = 2 * 2 * (3 * 2 + 2 * 2 + 2 * 3);
        }
        fdem_constraint_def all = pressure_on_part(body, 1e6);
        add_constraint(m, &all);
        build_finalize(m, 0.5);
        CHECK(fdem_get_counts(m).joints > 0, "%dD: no joints", dim);
        CHECK(m->constraints[0].facet_count == want, "%dD: %d facets loaded, want %d", dim,
              m->constraints[0].facet_count, want);
        const double *f = forces_after_one_step(m);
        for (int d = 0; d < dim; d++) CHECK_NEAR(f[d], 0, 1e-9 * 1e6 * 0.1);
        fdem_model_destroy(m);
    }
}

static const check_test tests[] = {
    {"fracturing_part_boundary_is_its_outline", fracturing_part_boundary_is_its_outline},
    {"checkpoint_carries_ramped_loads", checkpoint_carries_ramped_loads},
    {"pulse_leaves_through_absorbing_end", pulse_leaves_through_absorbing_end},
    {"pulse_reflects_from_free_end", pulse_reflects_from_free_end},
    {"shear_pulse_leaves_through_absorbing_end", shear_pulse_leaves_through_absorbing_end},
    {"ramped_velocity_has_no_force_step", ramped_velocity_has_no_force_step},
    {"ramped_gravity_settles_and_balances", ramped_gravity_settles_and_balances},
    {"pressure_totals_2d", pressure_totals_2d},
    {"pressure_totals_3d", pressure_totals_3d},
    {"ring_under_internal_pressure_2d", ring_under_internal_pressure_2d},
    {"ring_under_internal_pressure_3d", ring_under_internal_pressure_3d},
};

int main(int argc, char **argv)
{
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
