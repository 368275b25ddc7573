/*
 * test_fluid_kgd.c - a hydraulic fracture against its closed forms
 * (Detournay 2016, Annu. Rev. Fluid Mech. 48): the plane-strain KGD
 * fracture driven by a constant injection Q in its toughness-dominated
 * regime, where the viscous pressure drop is negligible (dimensionless
 * viscosity M = mu' Q E'^3 / K'^4 << 1) and the fracture is a Griffith
 * crack under a uniform pressure holding the injected volume V = Q t:
 *   K_I = p sqrt(pi l) = K_Ic,  V = 2 pi p l^2 / E',
 * so  l = (E' V / (2 sqrt(pi) K_Ic))^(2/3)  (= 0.9324 (E' Q t / K')^(2/3)),
 *     p = K_Ic / sqrt(pi l),  w(0) = 4 p l / E',
 * with K_Ic^2 = E' G_I, E' = E / (1 - nu^2): half-length growing as t^(2/3).
 *
 * The model: a 6 x 6 m plane-strain block, its outer boundary fixed, meshed
 * 120 x 120 (0.05 m); a fracture region two elements high around y = 0 whose joints on
 * the line y = 0 are a weak joint set (G_I, a tensile strength whose
 * cohesive length E' G_I / f_t^2 spans a few elements) and the rest far
 * stronger; fluid injected at the centre node. Measured at four times: the
 * half-length, the opening at the well (the aperture of the two joints
 * beside it) and the source pressure. The half-length of a cohesive crack
 * that LEFM's equals lies inside its process zone (Hillerborg): it is taken
 * as the middle of the zone, between the farthest broken joint and the
 * farthest damaged one (both printed; 0.15 m apart here, three joints).
 * Measured 2026-12-06: at t = 0.03 s half-length -0.8 %, opening at the
 * well -2.4 %, pressure +8.7 %; growth exponent 0.651 over t = 0.012-0.03 s
 * (2/3); at 0.012 s +0.2 %, -1.4 %, +3.0 % (the pressure drifts up as the
 * crack nears the fixed boundary: +14.7 % at 0.024 s in a 4 m block).
 * 34 s of CPU.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fdem.h"

#define KGD_E 1e10
#define KGD_NU 0.2
#define KGD_G 100.0
#define KGD_FT 3e6
#define KGD_HALF 3.0
#define KGD_N 120
#define KGD_Q 8e-3
#define KGD_MU 1e-5
#define KGD_K 1e8

typedef struct kgd_figures {
    double time, volume, length, opening, pressure;
    double broken, damaged; /* the farthest broken joint's end, and damaged one's */
    double wet;             /* the farthest end of a joint of the line holding fluid (p > 0) */
} kgd_figures;

static int on_line(const double *x0, int a)
{
    return fabs(x0[2 * a + 1]) < 1e-9;
}

/* Half-length: the farthest end of a broken joint on y = 0; opening at
 * the well: the mean aperture of the line's joints ending at x = 0. */
static kgd_figures kgd_measure(const fdem_model *m, double *aperture)
{
    kgd_figures k = {0};
    const fdem_fluid_status f = fdem_get_fluid(m);
    const fdem_counts c = fdem_get_counts(m);
    const int32_t *jn = fdem_joints(m);
    const double *x0 = fdem_initial_positions(m), *damage = fdem_joint_damage(m);
    const double *pressure = fdem_fluid_pressure(m);
    fdem_fluid_apertures(m, aperture);
    double opening = 0;
    int beside = 0;
    for (int j = 0; j < c.joints; j++) {
        int a0 = jn[4 * j], a1 = jn[4 * j + 1];
        if (!on_line(x0, a0) || !on_line(x0, a1)) continue;
        double xa = x0[2 * a0], xb = x0[2 * a1];
        double far = fmax(fabs(xa), fabs(xb));
        if (damage[j] >= 1) k.broken = fmax(k.broken, far);
        if (damage[j] > 0) k.damaged = fmax(k.damaged, far);
        if (pressure[j] > 0) k.wet = fmax(k.wet, far);
        if (fabs(xa) < 1e-9 || fabs(xb) < 1e-9) {
            opening += aperture[j];
            beside++;
        }
    }
    k.length = 0.5 * (k.broken + k.damaged);
    k.time = fdem_get_time(m);
    k.volume = f.injected_volume;
    k.opening = beside ? opening / beside : 0;
    k.pressure = f.source_pressure;
    return k;
}

typedef struct kgd_setup {
    double half;  /* the block's half-size (m) */
    int cells;    /* a side */
    double mu, G, ft, Q;
} kgd_setup;

static const kgd_setup TOUGH = {KGD_HALF, KGD_N, KGD_MU, KGD_G, KGD_FT, KGD_Q};

static fdem_model *kgd_model(const kgd_setup *k)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    fdem_material_def rock = {.density = 2500, .young = KGD_E, .poisson = KGD_NU,
                              .damping = 0.1, .has_fracture = 1};
    rock.fracture = (fdem_fracture_params){.tensile_strength = 1e9, .cohesion = 1e9,
                                           .friction_angle = 30, .energy_I = 1e6,
                                           .energy_II = 1e6, .aperture0 = 1e-5};
    int mat = fdem_add_material(m, &rock, &err);
    fdem_mesh mesh;
    fdem_mesh_rectangle(-k->half, -k->half, 2 * k->half, 2 * k->half, k->cells, k->cells, &mesh,
                        &err);
    const double h = 2 * k->half / k->cells;
    uint8_t *region = calloc((size_t)mesh.triangle_count, 1);
    for (int t = 0; t < mesh.triangle_count; t++) {
        double y = 0;
        for (int c = 0; c < 3; c++) y += mesh.xy[2 * mesh.tri[3 * t + c] + 1] / 3;
        region[t] = fabs(y) < h;
    }
    int part = fdem_add_part_region(m, &mesh, mat, region, &err);
    free(region);
    int32_t *faces = malloc(sizeof(int32_t) * 2 * (size_t)k->cells);
    int count = 0;
    for (int i = 0; i < mesh.node_count; i++)
        for (int k2 = 0; k2 < mesh.node_count; k2++) {
            const double *a = mesh.xy + 2 * i, *b = mesh.xy + 2 * (size_t)k2;
            if (fabs(a[1]) < 1e-9 && fabs(b[1]) < 1e-9 && b[0] > a[0] &&
                fabs(b[0] - a[0] - h) < 1e-9) {
                faces[2 * count] = i;
                faces[2 * count + 1] = k2;
                count++;
            }
        }
    fdem_fracture_params weak = {.tensile_strength = k->ft, .cohesion = 2 * k->ft,
                                 .friction_angle = 30, .energy_I = k->G, .energy_II = 10 * k->G,
                                 .aperture0 = 1e-5};
    if (fdem_add_joint_set(m, part, &weak, NULL, faces, count, &err) < 0)
        CHECK(0, "joint set: %s", err.message);
    free(faces);
    fdem_mesh_free(&mesh);
    fdem_fluid_def fluid = {.viscosity = k->mu, .bulk_modulus = KGD_K, .density = 0};
    fdem_set_fluid(m, &fluid, &err);
    const double L = k->half, e = 1e-6;
    const double boxes[4][4] = {{-L - e, -L - e, L + e, -L + e}, {-L - e, L - e, L + e, L + e},
                                {-L - e, -L - e, -L + e, L + e}, {L - e, -L - e, L + e, L + e}};
    for (int b = 0; b < 4; b++) {
        fdem_constraint_def fix = {.select = FDEM_SELECT_BOX, .kind = FDEM_CONSTRAINT_FIX,
                                   .fix_x = 1, .fix_y = 1};
        memcpy(fix.box, boxes[b], sizeof boxes[b]);
        fdem_add_constraint(m, &fix, &err);
    }
    fdem_constraint_def inject = {.select = FDEM_SELECT_BOX, .box = {-e, -e, e, e},
                                  .kind = FDEM_CONSTRAINT_INJECT, .value = {k->Q}};
    fdem_add_constraint(m, &inject, &err);
    if (fdem_model_finalize(m, &err)) {
        CHECK(0, "finalize: %s", err.message);
        fdem_model_destroy(m);
        return NULL;
    }
    return m;
}

/* Steps m until its time reaches t; non-zero (err says why) if a step fails. */
static int kgd_step_to(fdem_model *m, double t, fdem_error *err)
{
    while (fdem_get_time(m) < t)
        if (fdem_step(m, err)) return -1;
    return 0;
}

static void kgd_toughness_dominated(void)
{
    fdem_model *m = kgd_model(&TOUGH);
    if (!m) return;
    const double Ep = KGD_E / (1 - KGD_NU * KGD_NU), Kic = sqrt(Ep * KGD_G);
    const double Kp = 4 * sqrt(2 / M_PI) * Kic;
    fprintf(stderr, "  M = mu' Q E'^3 / K'^4 = %.3g; dt %.3g s\n",
            12 * KGD_MU * KGD_Q * Ep * Ep * Ep / pow(Kp, 4), fdem_get_dt(m));
    /* the half-length moves by whole joints (0.05 m): its growth exponent
     * is fitted over four times, after the start (the initial flaw, the
     * source joints, takes a pressure above the crack's to break) */
#ifdef FDEM_SAN
    /* under the sanitizers (minutes at full length): the first sample
     * only, held to the same band (measured +0.2 / -1.4 / +3.0 %); the
     * later ones and the growth exponent are checked by the normal build */
    enum { SAMPLES = 1 };
    const double times[SAMPLES] = {0.012};
#else
    enum { SAMPLES = 4 };
    const double times[SAMPLES] = {0.012, 0.018, 0.024, 0.030};
#endif
    kgd_figures k[SAMPLES];
    double *aperture = malloc(sizeof(double) * (size_t)fdem_get_counts(m).joints);
    fdem_error err;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int s = 0; s < SAMPLES; s++) {
        if (kgd_step_to(m, times[s], &err)) {
            CHECK(0, "step: %s", err.message);
            free(aperture);
            fdem_model_destroy(m);
            return;
        }
        k[s] = kgd_measure(m, aperture);
        double l = pow(Ep * k[s].volume / (2 * sqrt(M_PI) * Kic), 2.0 / 3);
        double p = Kic / sqrt(M_PI * l), w = 4 * p * l / Ep;
        fdem_fluid_status f = fdem_get_fluid(m);
        fprintf(stderr, "  t = %.4g s: broken to %.3g m, damaged to %.3g m\n", k[s].time,
                k[s].broken, k[s].damaged);
        fprintf(stderr, "  t = %.4g s: V = %.4g m^2; half-length %.4g m (LEFM %.4g, %+.1f %%), "
                        "opening at the well %.4g m (%.4g, %+.1f %%), pressure %.4g Pa (%.4g, "
                        "%+.1f %%); flow step %.3g s x %d\n",
                k[s].time, k[s].volume, k[s].length, l, 100 * (k[s].length / l - 1), k[s].opening,
                w, 100 * (k[s].opening / w - 1), k[s].pressure, p, 100 * (k[s].pressure / p - 1),
                f.flow_step, f.subcycles);
        if (s == SAMPLES - 1) {
            CHECK_REL(k[s].length, l, 0.15);
            CHECK_REL(k[s].opening, w, 0.15);
            CHECK_REL(k[s].pressure, p, 0.15);
        }
        double x = log(k[s].volume), y = log(fmax(k[s].length, 1e-9));
        sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    if (SAMPLES > 1) {
        double exponent = (SAMPLES * sxy - sx * sy) / (SAMPLES * sxx - sx * sx);
        fprintf(stderr, "  growth exponent %.3f (2/3), least squares of log l on log V\n",
                exponent);
        CHECK_REL(exponent, 2.0 / 3, 0.15);
    }
    free(aperture);
    fdem_model_destroy(m);
}

#ifndef FDEM_SAN /* the normal build only: see CHECK_MAIN */
/* The viscosity-dominated KGD (M >> 1: the same block with a fluid 25
 * times as viscous and a joint line of G_I = 1 J/m^2), against Adachi &
 * Detournay (2002) / Detournay (2016), zero fluid lag:
 *   l = 0.6152 (E' Q^3 / mu')^(1/6) t^(2/3),  w(0)^2 = 2.1 (mu' Q / E')^(1/2) l,
 *   w(0) p(0) = 0.62 (mu' Q E')^(1/2),  mu' = 12 mu;
 * the half-length (the fluid front: the solution has no lag), the opening
 * and the pressure at the well each within 20 %. Measured 2026-12-06 at
 * t = 0.02 s (M = 2410): fluid front 0.45 m against 0.499 (-9.8 %), opening
 * -11.0 %, pressure -13.7 %; the front grows as t^0.593 over 0.01-0.02 s
 * (2/3). Without a confining stress the crack itself runs far ahead of
 * the fluid (broken to 1.35 m): the zero-lag solution holds under a
 * confining stress large against the cohesive one (Garagash 2019), which
 * this block does not have; the fluid front is what it describes. */
static const kgd_setup VISCOUS = {2.0, 80, 2.5e-4, 1.0, 2e5, 8e-3};

static void kgd_viscosity_dominated(void)
{
    fdem_model *m = kgd_model(&VISCOUS);
    if (!m) return;
    const double Ep = KGD_E / (1 - KGD_NU * KGD_NU), Kic = sqrt(Ep * VISCOUS.G);
    const double Kp = 4 * sqrt(2 / M_PI) * Kic, mup = 12 * VISCOUS.mu, Q = VISCOUS.Q;
    fprintf(stderr, "  M = mu' Q E'^3 / K'^4 = %.3g; dt %.3g s\n",
            mup * Q * Ep * Ep * Ep / pow(Kp, 4), fdem_get_dt(m));
    enum { SAMPLES = 3 };
    const double times[SAMPLES] = {0.01, 0.015, 0.02};
    double *aperture = malloc(sizeof(double) * (size_t)fdem_get_counts(m).joints);
    fdem_error err;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int s = 0; s < SAMPLES; s++) {
        if (kgd_step_to(m, times[s], &err)) {
            CHECK(0, "step: %s", err.message);
            free(aperture);
            fdem_model_destroy(m);
            return;
        }
        kgd_figures k = kgd_measure(m, aperture);
        double t = k.time, l = 0.6152 * pow(Ep * Q * Q * Q / mup, 1.0 / 6) * pow(t, 2.0 / 3);
        double w = sqrt(2.1 * sqrt(mup * Q / Ep) * l), p = 0.62 * sqrt(mup * Q * Ep) / w;
        fdem_fluid_status f = fdem_get_fluid(m);
        k.length = k.wet; /* zero lag: the fluid front is the tip */
        fprintf(stderr, "  t = %.4g s: broken to %.3g m, damaged to %.3g m; fluid front %.4g m "
                        "(%.4g, %+.1f %%), opening at the well %.4g m (%.4g, %+.1f %%), pressure "
                        "%.4g Pa (%.4g, %+.1f %%); flow step %.3g s x %d\n",
                t, k.broken, k.damaged, k.length, l, 100 * (k.length / l - 1), k.opening, w,
                100 * (k.opening / w - 1), k.pressure, p, 100 * (k.pressure / p - 1), f.flow_step,
                f.subcycles);
        if (s == SAMPLES - 1) {
            CHECK_REL(k.length, l, 0.20);
            CHECK_REL(k.opening, w, 0.20);
            CHECK_REL(k.pressure, p, 0.20);
        }
        double x = log(t), y = log(fmax(k.length, 1e-9));
        sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    double exponent = (SAMPLES * sxy - sx * sy) / (SAMPLES * sxx - sx * sx);
    fprintf(stderr, "  growth exponent in t %.3f (2/3)\n", exponent);
    free(aperture);
    fdem_model_destroy(m);
}
#endif

#ifdef FDEM_SAN
/* the viscous regime runs the same code with other numbers: the normal
 * build checks it; under the sanitizers it would add minutes to CI */
CHECK_MAIN(T(kgd_toughness_dominated))
#else
CHECK_MAIN(T(kgd_toughness_dominated), T(kgd_viscosity_dominated))
#endif
