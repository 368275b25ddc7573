/*
 * test_damping.c - viscous damping (sigma_v = 2 eta D, D = sym([v][x]^-1))
 * on the mid-step configuration x_mid = x - h_last v / 2 (issue 29):
 *  - a damped body spinning freely about its centre of mass, 2D (a square
 *    of triangles) and 3D (a cube of tetrahedra about its diagonal), starts
 *    in its centrifugal equilibrium (so no vibration is there to damp) and
 *    turns 5 times: the damping account stays at round-off (under 1e-12 of
 *    the kinetic energy) and the kinetic energy changes no more than the
 *    undamped spin's. With D on the current positions the spin was damped
 *    by ~h omega^2 / 2;
 *  - a damped body in pure stretching (v = G x_mid, G symmetric) books the
 *    power 2 eta G : G per unit mid-step volume, that power is the one of
 *    the forces applied (sum f . v), and the reported stress has 2 eta G;
 *  - the 3D loop's element groups (pairs, AVX2 quads) give a damped run the
 *    bits of one element at a time, also when an element of the group is
 *    flat at mid-step (it takes no damping).
 */
#include "build_model.h"
#include "check.h"
#include "model/model.h"
#include "element/element.h"
#include "step/step.h"

static const double RHO = 2700, YOUNG = 3e10, NU = 0.25;

/* A unit square (4 x 4 squares of two triangles) or cube (2 x 2 x 2 cubes
 * of six tetrahedra) centred on the origin, at safety 0.5. The cube's
 * lattice is symmetric under the turn by a third about its diagonal
 * (1, 1, 1), so that is a principal axis of its lumped masses and a spin
 * about it is steady. */
static fdem_model *damped_box(int dim, double damping)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_material(m, RHO, YOUNG, NU, damping, 0);
    const double origin[3] = {-0.5, -0.5, -0.5}, size[3] = {1, 1, 1};
    const int div[3] = {dim == 3 ? 2 : 4, dim == 3 ? 2 : 4, 2};
    build_box_at(m, mat, dim, origin, size, div, 0);
    build_finalize(m, 0.5);
    return m;
}

static void centre_of_mass(const fdem_model *m, double c[3])
{
    const int D = m->dim;
    double total = 0;
    c[0] = c[1] = c[2] = 0;
    for (int i = 0; i < m->node_count; i++) {
        total += m->mass[i];
        for (int d = 0; d < D; d++) c[d] += m->mass[i] * m->pos[(size_t)D * (size_t)i + (size_t)d];
    }
    for (int d = 0; d < D; d++) c[d] /= total;
}

/* Node i's distance vector from the axis n through c (2D: n is z). */
static void from_axis(const fdem_model *m, int i, const double n[3], const double c[3], double r[3])
{
    const int D = m->dim;
    double nr = 0;
    r[2] = 0;
    for (int d = 0; d < D; d++) r[d] = m->pos[(size_t)D * (size_t)i + (size_t)d] - c[d];
    if (D == 2) return;
    for (int d = 0; d < 3; d++) nr += n[d] * r[d];
    for (int d = 0; d < 3; d++) r[d] -= nr * n[d];
}

/* Moves the nodes to the body's equilibrium spinning at omega about n
 * through its centre of mass (internal forces balancing the centrifugal
 * m omega^2 r) by dynamic relaxation, and returns the largest remaining
 * force over the largest centrifugal one. */
static double centrifugal_equilibrium(fdem_model *m, const double n[3], double omega)
{
    const int D = m->dim;
    const size_t count = (size_t)D * (size_t)m->node_count;
    double *v = calloc(count, sizeof(double)), c[3], worst = 0, scale = 0;
    for (int it = 0; it < 80000; it++) {
        centre_of_mass(m, c);
        memset(m->force, 0, sizeof(double) * count);
        memset(m->vel, 0, sizeof(double) * count); /* elastic forces only */
        element_forces(m);
        worst = scale = 0;
        for (int i = 0; i < m->node_count; i++) {
            double r[3];
            from_axis(m, i, n, c, r);
            for (int d = 0; d < D; d++) {
                size_t k = (size_t)D * (size_t)i + (size_t)d;
                double fc = m->mass[i] * omega * omega * r[d], f = m->force[k] + fc;
                worst = fmax(worst, fabs(f));
                scale = fmax(scale, fabs(fc));
                v[k] = 0.98 * v[k] + m->dt * f / m->mass[i];
                m->pos[k] += m->dt * v[k];
            }
        }
    }
    free(v);
    return worst / scale;
}

typedef struct spin_result {
    double kinetic0;      /* J (J/m in 2D) */
    double worst_damping; /* largest |damping account| over the run */
    double worst_kinetic; /* largest |kinetic - kinetic0| over the run */
    double residual;      /* largest |energy residual| over the run */
} spin_result;

/* The box spinning freely at omega (tip speed 1 % of the P-wave speed)
 * about n for `turns` revolutions from its centrifugal equilibrium. */
static spin_result spin(int dim, double damping, const double n[3], double turns)
{
    fdem_model *m = damped_box(dim, damping);
    const double c_p = sqrt((m->materials[0].lambda + 2 * m->materials[0].mu) / RHO);
    const double omega = 0.01 * c_p / sqrt(0.5 * dim);
    double equilibrium = centrifugal_equilibrium(m, n, omega);
    CHECK(equilibrium < 1e-9, "relaxed to %.3g of the centrifugal force only", equilibrium);
    double c[3];
    centre_of_mass(m, c);
    const int D = dim;
    for (int i = 0; i < m->node_count; i++) {
        double r[3], w[3];
        from_axis(m, i, n, c, r);
        w[0] = n[1] * r[2] - n[2] * r[1];
        w[1] = n[2] * r[0] - n[0] * r[2];
        w[2] = n[0] * r[1] - n[1] * r[0];
        for (int d = 0; d < D; d++) m->vel[(size_t)D * (size_t)i + (size_t)d] = omega * w[d];
    }
    energy_initial(m);
    spin_result out = {0};
    for (int i = 0; i < m->node_count; i++)
        for (int d = 0; d < D; d++) {
            double vk = m->vel[(size_t)D * (size_t)i + (size_t)d];
            out.kinetic0 += 0.5 * m->mass[i] * vk * vk;
        }
    long steps = lround(turns * 2 * M_PI / omega / m->dt);
    fdem_error err;
    for (long s = 0; s < steps; s++) {
        if (fdem_step(m, &err)) build_die("step", &err);
        fdem_energy en = fdem_get_energy(m);
        out.worst_damping = fmax(out.worst_damping, fabs(en.damping));
        out.worst_kinetic = fmax(out.worst_kinetic, fabs(en.kinetic - out.kinetic0));
        out.residual = fmax(out.residual, fabs(en.residual));
    }
    fdem_model_destroy(m);
    return out;
}

static void spin_is_not_damped(int dim)
{
    const double s = 1 / sqrt(3.0);
    const double n[3] = {dim == 3 ? s : 0, dim == 3 ? s : 0, dim == 3 ? s : 1};
    spin_result free_spin = spin(dim, 0, n, 5);
    const double dampings[2] = {0.1, 0.6};
    for (int k = 0; k < 2; k++) {
        spin_result r = spin(dim, dampings[k], n, 5);
        fprintf(stderr,
                "  %dD spin, damping %.1f: kinetic %.6g, damping account %.3g (%.3g of it), "
                "kinetic drift %.3g (undamped %.3g), residual %.3g\n",
                dim, dampings[k], r.kinetic0, r.worst_damping, r.worst_damping / r.kinetic0,
                r.worst_kinetic / r.kinetic0, free_spin.worst_kinetic / free_spin.kinetic0,
                r.residual / r.kinetic0);
        CHECK(r.worst_damping <= 1e-12 * r.kinetic0, "%dD: a spin dissipated %.3g of %.6g J",
              dim, r.worst_damping, r.kinetic0);
        CHECK(r.worst_kinetic <= 2 * free_spin.worst_kinetic + 1e-12 * r.kinetic0,
              "%dD: kinetic energy drifted %.3g, undamped %.3g", dim, r.worst_kinetic,
              free_spin.worst_kinetic);
        CHECK(r.residual <= 1e-9 * r.kinetic0, "%dD: energy residual %.3g of %.6g J", dim,
              r.residual, r.kinetic0);
    }
}

static void spinning_square_is_not_damped(void) { spin_is_not_damped(2); }
static void spinning_cube_is_not_damped(void) { spin_is_not_damped(3); }

/* Every node at v = G X and x = X + (h/2) v, so the mid-step configuration
 * is the reference (stress-free, volume V0) and D = G there; one force
 * evaluation after a step of h. The power booked (the damping account of
 * this evaluation alone) must be -2 eta V0 G : G summed over the elements,
 * which is also sum f . v of the viscous forces applied (the forces less
 * those at v = 0), and the reported stress must be 2 eta G beyond the
 * elastic one. On the current positions D was G (I + h G / 2)^-1. */
static void pure_stretching_dissipates_2_eta_D_D(int dim)
{
    fdem_model *m = damped_box(dim, 0.3);
    const int D = dim, comps = model_stress_comps(m);
    const size_t count = (size_t)D * (size_t)m->node_count;
    const double h = m->dt, rate = 100; /* h G / 2 ~ 1e-3 */
    const double G[3][3] = {{0.3 * rate, 0.1 * rate, -0.05 * rate},
                            {0.1 * rate, -0.2 * rate, 0.07 * rate},
                            {-0.05 * rate, 0.07 * rate, 0.1 * rate}};
    for (int i = 0; i < m->node_count; i++)
        for (int a = 0; a < D; a++) {
            double va = 0;
            for (int b = 0; b < D; b++) va += G[a][b] * m->pos0[(size_t)D * (size_t)i + (size_t)b];
            m->vel[(size_t)D * (size_t)i + (size_t)a] = va;
            m->pos[(size_t)D * (size_t)i + (size_t)a] =
                m->pos0[(size_t)D * (size_t)i + (size_t)a] + 0.5 * h * va;
        }
    m->dt_prev = h;
    m->havg_last = 0;
    double *v = malloc(sizeof(double) * count), *f_elastic = malloc(sizeof(double) * count);
    double *s_elastic = malloc(sizeof(double) * (size_t)comps * (size_t)m->elem_count);
    double *s_all = malloc(sizeof(double) * (size_t)comps * (size_t)m->elem_count);
    memcpy(v, m->vel, sizeof(double) * count);
    /* the elastic forces and stress alone (v = 0) */
    memset(m->vel, 0, sizeof(double) * count);
    memset(m->force, 0, sizeof(double) * count);
    element_forces(m);
    memcpy(f_elastic, m->force, sizeof(double) * count);
    fdem_element_stress(m, s_elastic);
    /* and with the stretching */
    memcpy(m->vel, v, sizeof(double) * count);
    memset(m->force, 0, sizeof(double) * count);
    memset(m->elem_viscous, 0, sizeof(double) * (size_t)comps * (size_t)m->elem_count);
    m->damping_work = 0;
    element_forces(m);
    fdem_element_stress(m, s_all);
    /* element.c books -(h_prev + h) / 4 of the power now */
    double booked = -m->damping_work / (0.5 * (m->dt_prev + m->dt) * 0.5);
    double applied = 0, want = 0, GG = 0, stress_error = 0, stress_scale = 0;
    for (int a = 0; a < D; a++)
        for (int b = 0; b < D; b++) GG += G[a][b] * G[a][b];
    for (size_t k = 0; k < count; k++) applied += (m->force[k] - f_elastic[k]) * v[k];
    for (int e = 0; e < m->elem_count; e++) {
        double eta = element_eta(m, e), V0 = dim == 3 ? m->tet[e].volume0 : m->elem[e].area0;
        want -= 2 * eta * V0 * GG;
        static const int ij2[3][2] = {{0, 0}, {1, 1}, {0, 1}};
        static const int ij3[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
        for (int q = 0; q < comps; q++) {
            const int *ij = dim == 3 ? ij3[q] : ij2[q];
            size_t k = (size_t)comps * (size_t)e + (size_t)q;
            double viscous = 2 * eta * G[ij[0]][ij[1]];
            stress_error = fmax(stress_error, fabs(s_all[k] - s_elastic[k] - viscous));
            stress_scale = fmax(stress_scale, fabs(viscous));
        }
    }
    CHECK(stress_error <= 1e-10 * stress_scale, "%dD: reported viscous stress off by %.3g of %.3g",
          dim, stress_error, stress_scale);
    fprintf(stderr, "  %dD stretching: power booked %.12g, of the forces %.12g, 2 eta G:G V0 %.12g\n",
            dim, booked, applied, want);
    CHECK_REL(booked, want, 1e-10);
    CHECK_REL(applied, want, 1e-10);
    free(v);
    free(f_elastic);
    free(s_elastic);
    free(s_all);
    fdem_model_destroy(m);
}

static void stretched_square_dissipates_2_eta_D_D(void) { pure_stretching_dissipates_2_eta_D_D(2); }
static void stretched_cube_dissipates_2_eta_D_D(void) { pure_stretching_dissipates_2_eta_D_D(3); }

/* 11 separate tetrahedra (4 + 4 + 2 + 1: a quad, another, a pair and one
 * alone), damped, as one part (the loop groups them) or as 11 parts of one
 * element (one at a time), fracturing (the storing loop) or not: after 40
 * steps from the same deformed state, the same bits. */
static fdem_model *separate_tets(int one_part, int fracture)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    if (fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_fracturing_rock(m, 0.4);
    enum { K = 11 };
    static const double corner[4][3] = {{0, 0, 0}, {1, 0.1, 0}, {0.2, 0.9, 0.1}, {0.1, 0.2, 1.1}};
    double xyz[K * 12];
    int32_t tets[K * 4];
    for (int e = 0; e < K; e++)
        for (int a = 0; a < 4; a++) {
            tets[4 * e + a] = 4 * e + a;
            for (int d = 0; d < 3; d++)
                xyz[12 * e + 3 * a + d] = corner[a][d] * (1 + 0.03 * e) + (d == 0 ? 3.0 * e : 0);
        }
    for (int e = 0; e < (one_part ? 1 : K); e++) {
        fdem_tet_mesh mesh = {0};
        mesh.node_count = one_part ? 4 * K : 4;
        mesh.tet_count = one_part ? K : 1;
        mesh.xyz = xyz + 12 * e;
        int32_t local[4] = {0, 1, 2, 3};
        mesh.tet = one_part ? tets : local;
        if (fdem_add_part_3d(m, &mesh, mat, fracture, &err) < 0) build_die("part", &err);
    }
    build_finalize(m, 0.5);
    fdem_set_dt(m, 5e-6); /* separate parts take the contact penalty's step */
    /* a state that is a function of the node's initial place, so the same
     * whatever the order the parts number the nodes in */
    for (int k = 0; k < 3 * m->node_count; k++) {
        const double *X = m->pos0 + 3 * (k / 3);
        double phase = 12.9898 * X[0] + 78.233 * X[1] + 37.719 * X[2] + 1.7 * (k % 3);
        m->pos[k] += 0.002 * sin(phase);
        m->vel[k] = 0.5 * cos(1.3 * phase);
    }
    energy_initial(m);
    fdem_error e2;
    for (int s = 0; s < 40; s++)
        if (fdem_step(m, &e2)) build_die("step", &e2);
    return m;
}

/* The node of b at a's node i's initial place. */
static int same_node(const fdem_model *a, const fdem_model *b, int i)
{
    for (int j = 0; j < b->node_count; j++)
        if (memcmp(a->pos0 + 3 * (size_t)i, b->pos0 + 3 * (size_t)j, 3 * sizeof(double)) == 0)
            return j;
    return -1;
}

static void element_groups_give_the_bits_of_one_at_a_time(void)
{
    for (int fracture = 0; fracture < 2; fracture++) {
        fdem_model *a = separate_tets(1, fracture), *b = separate_tets(0, fracture);
        CHECK(a->node_count == b->node_count && a->elem_count == b->elem_count, "models differ");
        int differ = 0;
        for (int i = 0; i < a->node_count; i++) {
            int j = same_node(a, b, i);
            differ += j < 0 || memcmp(a->pos + 3 * (size_t)i, b->pos + 3 * (size_t)j, 24) != 0 ||
                      memcmp(a->vel + 3 * (size_t)i, b->vel + 3 * (size_t)j, 24) != 0;
        }
        CHECK(differ == 0, "fracture %d: %d of %d nodes differ", fracture, differ, a->node_count);
        CHECK(a->damping_work > 0, "fracture %d: no damping", fracture);
        CHECK_REL(b->damping_work, a->damping_work, 1e-14);
        /* element 5 (in a group of four or a pair) flat at mid-step: the
         * group's lanes go one by one, and it alone takes no damping */
        fdem_model *ab[2] = {a, b};
        for (int k = 0; k < 2; k++) {
            fdem_model *m = ab[k];
            m->dt_prev = 1.0; /* x_mid = x - v / 2, exact for these numbers */
            for (int c = 0; c < 4; c++) {
                double *x = m->pos + 3 * (size_t)m->tet[5].node[c];
                double *v = m->vel + 3 * (size_t)m->tet[5].node[c];
                x[0] = 15 + (c & 1), x[1] = c >> 1, x[2] = c == 3 ? 1 : 0;
                v[0] = v[1] = 0, v[2] = 2 * x[2]; /* x_mid: the square c -> (c & 1, c >> 1, 0) */
            }
            memset(m->force, 0, sizeof(double) * 3 * (size_t)m->node_count);
            element_forces(m);
            double *sv = m->elem_viscous + 6 * 5;
            CHECK(sv[0] == 0 && sv[1] == 0 && sv[2] == 0 && sv[5] == 0,
                  "a flat element was damped: %g %g %g", sv[0], sv[1], sv[2]);
        }
        differ = 0;
        for (int i = 0; i < a->node_count; i++) {
            int j = same_node(a, b, i);
            differ += j < 0 || memcmp(a->force + 3 * (size_t)i, b->force + 3 * (size_t)j, 24) != 0;
        }
        CHECK(differ == 0, "fracture %d, flat element: %d of %d forces differ", fracture, differ,
              a->node_count);
        fdem_model_destroy(a);
        fdem_model_destroy(b);
    }
}

CHECK_MAIN(T(spinning_square_is_not_damped), T(spinning_cube_is_not_damped),
           T(stretched_square_dissipates_2_eta_D_D), T(stretched_cube_dissipates_2_eta_D_D),
           T(element_groups_give_the_bits_of_one_at_a_time))
