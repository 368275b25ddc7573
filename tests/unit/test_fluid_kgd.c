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

static fdem_model *kgd_model(void)
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
    fdem_mesh_rectangle(-KGD_HALF, -KGD_HALF, 2 * KGD_HALF, 2 * KGD_HALF, KGD_N, KGD_N, &mesh,
                        &err);
    const double h = 2 * KGD_HALF / KGD_N;
    uint8_t *region = calloc((size_t)mesh.triangle_count, 1);
    for (int t = 0; t < mesh.triangle_count; t++) {
        double y = 0;
        for (int c = 0; c < 3; c++) y += mesh.xy[2 * mesh.tri[3 * t + c] + 1] / 3;
        region[t] = fabs(y) < h;
    }
    int part = fdem_add_part_region(m, &mesh, mat, region, &err);
    free(region);
    int32_t *faces = malloc(sizeof(int32_t) * 2 * KGD_N);
    int count = 0;
    for (int i = 0; i < mesh.node_count; i++)
        for (int k = 0; k < mesh.node_count; k++) {
            const double *a = mesh.xy + 2 * i, *b = mesh.xy + 2 * k;
            if (fabs(a[1]) < 1e-9 && fabs(b[1]) < 1e-9 && b[0] > a[0] &&
                fabs(b[0] - a[0] - h) < 1e-9) {
                faces[2 * count] = i;
                faces[2 * count + 1] = k;
                count++;
            }
        }
    fdem_fracture_params weak = {.tensile_strength = KGD_FT, .cohesion = 2 * KGD_FT,
                                 .friction_angle = 30, .energy_I = KGD_G, .energy_II = 10 * KGD_G,
                                 .aperture0 = 1e-5};
    if (fdem_add_joint_set(m, part, &weak, NULL, faces, count, &err) < 0)
        CHECK(0, "joint set: %s", err.message);
    free(faces);
    fdem_mesh_free(&mesh);
    fdem_fluid_def fluid = {.viscosity = KGD_MU, .bulk_modulus = KGD_K, .density = 0};
    fdem_set_fluid(m, &fluid, &err);
    const double L = KGD_HALF, e = 1e-6;
    const double boxes[4][4] = {{-L - e, -L - e, L + e, -L + e}, {-L - e, L - e, L + e, L + e},
                                {-L - e, -L - e, -L + e, L + e}, {L - e, -L - e, L + e, L + e}};
    for (int b = 0; b < 4; b++) {
        fdem_constraint_def fix = {.select = FDEM_SELECT_BOX, .kind = FDEM_CONSTRAINT_FIX,
                                   .fix_x = 1, .fix_y = 1};
        memcpy(fix.box, boxes[b], sizeof boxes[b]);
        fdem_add_constraint(m, &fix, &err);
    }
    fdem_constraint_def inject = {.select = FDEM_SELECT_BOX, .box = {-e, -e, e, e},
                                  .kind = FDEM_CONSTRAINT_INJECT, .value = {KGD_Q}};
    fdem_add_constraint(m, &inject, &err);
    if (fdem_model_finalize(m, &err)) {
        CHECK(0, "finalize: %s", err.message);
        fdem_model_destroy(m);
        return NULL;
    }
    return m;
}

static void kgd_toughness_dominated(void)
{
    fdem_model *m = kgd_model();
    if (!m) return;
    const double Ep = KGD_E / (1 - KGD_NU * KGD_NU), Kic = sqrt(Ep * KGD_G);
    const double Kp = 4 * sqrt(2 / M_PI) * Kic;
    fprintf(stderr, "  M = mu' Q E'^3 / K'^4 = %.3g; dt %.3g s\n",
            12 * KGD_MU * KGD_Q * Ep * Ep * Ep / pow(Kp, 4), fdem_get_dt(m));
    /* the half-length moves by whole joints (0.05 m): its growth exponent
     * is fitted over four times, after the start (the initial flaw, the
     * source joints, takes a pressure above the crack's to break) */
    enum { SAMPLES = 4 };
    const double times[SAMPLES] = {0.012, 0.018, 0.024, 0.030};
    kgd_figures k[SAMPLES];
    double *aperture = malloc(sizeof(double) * (size_t)fdem_get_counts(m).joints);
    fdem_error err;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int s = 0; s < SAMPLES; s++) {
        while (fdem_get_time(m) < times[s])
            if (fdem_step(m, &err)) {
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
    double exponent = (SAMPLES * sxy - sx * sy) / (SAMPLES * sxx - sx * sx);
    fprintf(stderr, "  growth exponent %.3f (2/3), least squares of log l on log V\n", exponent);
    CHECK_REL(exponent, 2.0 / 3, 0.15);
    free(aperture);
    fdem_model_destroy(m);
}

CHECK_MAIN(T(kgd_toughness_dominated))
