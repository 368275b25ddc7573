/*
 * test_fracture.c - the fracture validation cases exactly as shipped in
 * examples/, built by case_build and stepped by the engine to their end:
 *
 *  - Brazilian disc (OpenFDEM's rock: E 30 GPa, nu 0.3, f_t 1 MPa, c 3 MPa,
 *    contact friction 0.3, G_I 10, G_II 50 J/m^2; joint friction angle 30
 *    degrees; between steel platens closing at 0.05 m/s): the peak platen force P
 *    per metre gives 2P/(pi D) within 15% of f_t; the damaged joints line
 *    the loaded diameter from platen to platen; the load falls after it.
 *  - The same rock as a 3D cylinder: between platens (coarse, fast; a wide
 *    band) and through loading arcs on a finer lattice, whose peak
 *    2P/(pi D t) is within 15 % of f_t; both split along the loaded plane.
 *  - Uniaxial compression of a 25 x 50 mm specimen of the same rock: peak
 *    stress within 25% of Mohr-Coulomb's 2c cos(phi)/(1 - sin(phi)) (the
 *    joints' own envelope); the broken joints mostly lie at 30-70 degrees to
 *    the load and their faces have slid more than they have opened (a shear
 *    failure); the load falls after the peak.
 *
 * The disc's mesh matters (docs/physics.md, "Known limitations and how to
 * mesh", measured by make limits). At the shipped 2 mm the first joints to
 * soften are under the flat platens, and the peak lands near f_t because
 * two errors cancel: crushing under the platens pulls it down, the
 * example's very ductile crack (E G_I / f_t^2 = 0.3 m, six disc diameters)
 * pushes it up; finer meshes crush first and peak below f_t. This test
 * holds the shipped example to its figure and its split along the loaded
 * diameter; a loading arc is the set-up that measures f_t itself.
 *
 * The platen force is averaged over 2 microsecond windows: when a joint
 * breaks, the freed faces ring for a few steps, and a one-step spike is
 * not the specimen's strength.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case/case.h"
#include "case_doc.h"
#include "check.h"
#include "joint_face_3d.h"
#include "model/model.h"
#include "read_file.h"

#define WINDOW 2e-6

/* The example at `path`, with the JSON at `pointer` replaced by `value`
 * when both are given (a coarser mesh for the sanitizer build). */
static fdem_model *load_example_edited(const char *path, const char *pointer, const char *value,
                                       case_info *info)
{
    size_t length = 0;
    char *text = read_text(path, &length);
    CHECK(text != NULL, "cannot read %s", path);
    if (!text) return NULL;
    if (pointer && value) {
        json_error_t error;
        json_t *doc = json_loads(text, 0, &error);
        CHECK(doc != NULL, "%s does not parse: %s", path, error.text);
        free(text);
        if (!doc) return NULL;
        edit(doc, pointer, load(value));
        text = json_dumps(doc, JSON_COMPACT);
        length = strlen(text);
        json_decref(doc);
    }
    problems p;
    problems_init(&p);
    fdem_model *m = case_build(text, length, (size_t)1 << 31, info, &p);
    CHECK(m != NULL, "%s was rejected", path);
    problems_free(&p);
    free(text);
    return m;
}

static fdem_model *load_example(const char *path, case_info *info)
{
    return load_example_edited(path, NULL, NULL, info);
}

typedef struct load_history {
    double peak, peak_time;   /* the first peak of the platen force (window means) */
    double drop_time;         /* when it first fell below 30% of that peak, or -1 */
    double last;              /* the last complete window's mean */
    double sum, span;         /* the window being filled */
    double residual_to_peak;  /* worst |energy residual| while the load rises to its peak */
    double residual_after;    /* worst |energy residual| after the peak */
    double peak_work;         /* the supports' work at the peak */
} load_history;

/* Steps until the case's end, or 0.1 ms after the load has fallen below 30%
 * of its first peak, recording the mean force of the two platens
 * (constraints 0 and 1) per window. Once the specimen has failed, its
 * pieces can be squeezed again and load the platens anew; that later
 * force is not the specimen's strength, so the peak is frozen at the drop. */
static int run_loaded(fdem_model *m, double end, load_history *h)
{
    fdem_error err;
    memset(h, 0, sizeof *h);
    h->drop_time = -1;
    while (fdem_get_time(m) < end && (h->drop_time < 0 || fdem_get_time(m) < h->drop_time + 1e-4)) {
        if (fdem_step(m, &err)) {
            CHECK(0, "step failed: %s", err.message);
            return -1;
        }
        fdem_energy en = fdem_get_energy(m);
        if (h->peak_time == 0 || fdem_get_time(m) <= h->peak_time + WINDOW) {
            h->residual_to_peak = fmax(h->residual_to_peak, fabs(en.residual));
            h->peak_work = en.external_work;
        } else {
            h->residual_after = fmax(h->residual_after, fabs(en.residual));
        }
        const double *f = fdem_constraint_forces(m);
        double P = 0.5 * (fabs(f[1]) + fabs(f[m->dim + 1])); /* y of constraints 0 and 1 */
        double dt = fdem_get_dt(m);
        h->sum += P * dt;
        h->span += dt;
        if (h->span < WINDOW) continue;
        h->last = h->sum / h->span;
        h->sum = h->span = 0;
        if (h->drop_time >= 0) continue;
        if (h->last > h->peak) {
            h->peak = h->last;
            h->peak_time = fdem_get_time(m);
        } else if (h->last < 0.3 * h->peak) {
            h->drop_time = fdem_get_time(m);
        }
    }
    CHECK(h->drop_time >= 0, "the load never fell below 30%% of its peak %g N/m", h->peak);
    return 0;
}

/* The energy balance of a loaded specimen: up to the peak load, where the
 * supports' work goes into elastic, joint and contact energy and the first
 * cracks, the residual must stay under 1 % of that work. After the peak the
 * freed pieces ring and rub; what the residual does then is printed (see
 * docs/physics.md, "Energy accounting", for why it grows there). */
static void energy_report(const char *name, const fdem_model *m, const load_history *h)
{
    fdem_energy en = fdem_get_energy(m);
    printf("  %s: work in %.4g %s (%.4g at the peak): elastic %.4g, joint %.4g, fracture %.4g, "
           "contact %.4g, friction %.4g, damping %.4g, kinetic %.4g; worst residual %.3g %% of the "
           "work up to the peak, %.3g %% of all the work after it\n",
           name, en.external_work, m->dim == 2 ? "J/m" : "J", h->peak_work, en.elastic, en.joint, en.fracture, en.contact,
           en.friction, en.damping, en.kinetic, 100 * h->residual_to_peak / h->peak_work,
           100 * h->residual_after / en.external_work);
    CHECK(h->residual_to_peak < 0.01 * h->peak_work, "energy residual %.3g %% of the work done",
          100 * h->residual_to_peak / h->peak_work);
    /* Contact gives back at most what its overlaps were loaded with, which
     * the supports paid for. A damaged joint that let a corner sink into
     * its neighbour unresisted broke with an overlap nobody had paid for,
     * and the contact that took it over handed out 20 (disc) and 1.1
     * (uniaxial) times the supports' work (joint.c, joint_compression). */
    CHECK(-en.contact < en.external_work, "contact gave %.4g J/m, the supports put in %.4g J/m",
          -en.contact, en.external_work);
}

/* A joint's midpoint and direction in the initial configuration: the
 * angle of its edge (2D) or face (3D) to the horizontal (x, or the x-z
 * plane), 0 across the load, 90 along it. */
static void joint_geometry(const fdem_model *m, int j, double *x, double *y, double *angle_deg)
{
    const double *p = m->pos0;
    if (m->dim == 3) {
        const int32_t *n = m->joint_node + 6 * (size_t)j;
        double N[3], c[3], len = joint_face_normal(p, n, N);
        joint_face_centre(p, n, c);
        *x = c[0];
        *y = c[1];
        *angle_deg = acos(fmin(1, fabs(N[1]) / len)) * 180 / M_PI;
        return;
    }
    const int32_t *n = m->joint_node + 4 * j;
    *x = 0.5 * (p[2 * n[0]] + p[2 * n[1]]);
    *y = 0.5 * (p[2 * n[0] + 1] + p[2 * n[1] + 1]);
    double a = fabs(atan2(p[2 * n[1] + 1] - p[2 * n[0] + 1], p[2 * n[1]] - p[2 * n[0]])) * 180 / M_PI;
    *angle_deg = a > 90 ? 180 - a : a; /* 0 horizontal, 90 along the load */
}

/* How far face B of joint j has moved from face A (mean over its corners),
 * split into sliding along the joint and opening across it, in the initial
 * frame. */
static void joint_slide_open(const fdem_model *m, int j, double *slid, double *opened)
{
    const int D = m->dim;
    const int32_t *n = m->joint_node + 2 * D * (size_t)j;
    const double *p = m->pos, *p0 = m->pos0;
    double d[3] = {0, 0, 0}, N[3] = {0, 0, 0};
    for (int i = 0; i < D; i++)
        for (int c = 0; c < D; c++) d[c] += (p[D * n[D + i] + c] - p[D * n[i] + c]) / D;
    if (D == 2) {
        N[0] = -(p0[2 * n[1] + 1] - p0[2 * n[0] + 1]);
        N[1] = p0[2 * n[1]] - p0[2 * n[0]];
    } else {
        joint_face_normal(p0, n, N);
    }
    double len = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    double normal = (d[0] * N[0] + d[1] * N[1] + d[2] * N[2]) / len;
    *opened += fabs(normal);
    *slid += sqrt(fmax(0, d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - normal * normal));
}

/* The specimen's (part 0's) thickness: its extent along z in 3D; 1 in 2D,
 * where forces are per metre. */
static double specimen_thickness(const fdem_model *m)
{
    if (m->dim == 2) return 1;
    const part *p = &m->parts[0];
    double lo = INFINITY, hi = -INFINITY;
    for (int i = p->node_begin; i < p->node_begin + p->node_count; i++) {
        lo = fmin(lo, m->pos0[3 * i + 2]);
        hi = fmax(hi, m->pos0[3 * i + 2]);
    }
    return hi - lo;
}

/* A disc of radius 25 mm (a cylinder along z in 3D) split between platens:
 * 2P/(pi D t) at the peak between low and high times f_t, the damaged
 * joints lining the loaded diameter from platen to platen. */
static void brazilian_disc_model(fdem_model *m, const case_info *info, double low, double high)
{
    const double R = 0.025, ft = 1e6, t = specimen_thickness(m);
    load_history h;
    /* results are the same bits on any number of threads; CI has two cores */
    fdem_set_threads(m, 2);
    if (run_loaded(m, info->end_time, &h)) {
        fdem_model_destroy(m);
        return;
    }
    double sigma = 2 * h.peak / (M_PI * 2 * R * t);
    printf("  brazilian %dD: peak P %.4g N%s at %.3g ms -> 2P/(pi D%s) = %.4g MPa (%+.1f%% of f_t), "
           "fell below 30%% at %.3g ms, broken %d of %d joints, %d fragments\n",
           m->dim, h.peak, m->dim == 2 ? "/m" : "", 1e3 * h.peak_time, m->dim == 2 ? "" : " t",
           sigma / 1e6, 100 * (sigma / ft - 1), 1e3 * h.drop_time, m->broken_joints,
           m->joint_count, m->fragments);
    CHECK(sigma >= low * ft && sigma <= high * ft, "2P/(pi D t) = %.4g f_t, not in [%g, %g]",
          sigma / ft, low, high);
    energy_report("brazilian", m, &h);

    /* the crack: damaged joints within 0.2 R of the loaded (vertical)
     * diameter, counted per tenth of the height */
    int bins[10] = {0}, near = 0, damaged = 0;
    for (int j = 0; j < m->joint_count; j++) {
        if (m->joint_damage[j] < 0.5) continue;
        double x, y, angle;
        joint_geometry(m, j, &x, &y, &angle);
        damaged++;
        if (fabs(x) > 0.2 * R) continue;
        near++;
        int b = (int)((y + R) / (0.2 * R));
        if (b >= 0 && b < 10) bins[b]++;
    }
    int reached = 0;
    for (int b = 0; b < 10; b++) reached += bins[b] > 0;
    printf("  brazilian %dD: %d damaged joints, %d near the loaded diameter, in %d of its 10 tenths:",
           m->dim, damaged, near, reached);
    for (int b = 0; b < 10; b++) printf(" %d", bins[b]);
    printf("\n");
    CHECK(reached >= 8, "the crack covers only %d tenths of the loaded diameter", reached);
    CHECK(near >= damaged / 2, "only %d of %d damaged joints are near the loaded diameter", near,
          damaged);
    fdem_model_destroy(m);
}

static void brazilian_disc(const char *path, double low, double high)
{
    case_info info;
    fdem_model *m = load_example(path, &info);
    if (m) brazilian_disc_model(m, &info, low, high);
}

/* A block 25 mm wide (and deep, in 3D) crushed between platens: the peak
 * stress P/(W t) within `tolerance` of Mohr-Coulomb, a shear failure. */
static void uniaxial_compression(const char *path, double tolerance)
{
    case_info info;
    fdem_model *m = load_example(path, &info);
    if (!m) return;
    const double W = 0.025, c = 3e6, phi = 30 * M_PI / 180, t = specimen_thickness(m);
    double mohr_coulomb = 2 * c * cos(phi) / (1 - sin(phi));
    load_history h;
    if (run_loaded(m, info.end_time, &h)) {
        fdem_model_destroy(m);
        return;
    }
    double ucs = h.peak / (W * t);
    int inclined = 0, broken = 0;
    double slid = 0, opened = 0;
    for (int j = 0; j < m->joint_count; j++) {
        if (m->joint_damage[j] < 1.0) continue;
        double x, y, angle;
        joint_geometry(m, j, &x, &y, &angle);
        broken++;
        inclined += angle >= 30 && angle <= 70;
        joint_slide_open(m, j, &slid, &opened);
    }
    printf("  uniaxial %dD: peak %.4g MPa at %.3g ms (Mohr-Coulomb %.4g MPa, %+.1f%%), fell below 30%% at %.3g ms; "
           "%d broken joints, %d at 30-70 deg; faces slid %.3g mm, opened %.3g mm in all\n",
           m->dim, ucs / 1e6, 1e3 * h.peak_time, mohr_coulomb / 1e6, 100 * (ucs / mohr_coulomb - 1),
           1e3 * h.drop_time, broken, inclined, 1e3 * slid, 1e3 * opened);
    CHECK_REL(ucs, mohr_coulomb, tolerance);
    CHECK(broken >= 10, "only %d joints broke", broken);
    CHECK(inclined >= 0.6 * broken, "only %d of %d broken joints are inclined", inclined, broken);
    CHECK(slid > opened, "faces opened (%g) more than they slid (%g)", opened, slid);
    energy_report("uniaxial", m, &h);
    fdem_model_destroy(m);
}

static void brazilian_disc_splits_at_its_tensile_strength(void)
{
    brazilian_disc("examples/brazilian-disc.json", 0.85, 1.15);
}

static void uniaxial_compression_fails_in_shear(void)
{
    uniaxial_compression("examples/uniaxial-compression.json", 0.25);
}

/* The 3D disc as shipped (24 edges round the rim, one layer, platens at
 * 0.1 m/s each: a coarse, fast set-up a test can afford). Its peak is not
 * f_t and must not be: the example's crack is very ductile (E G_I / f_t^2
 * = 0.3 m, six diameters), so the load goes on rising after the centre has
 * begun to soften (at 0.64 f_t here), and a fast platen adds inertia. make
 * limits measured 1.49 f_t for this set-up, 1.30 at 0.025 m/s and 0.86
 * with a tenth of G_I (docs/physics.md, "3D Brazilian disc"); the test
 * holds the peak above f_t and below 1.6 f_t, with the split from platen
 * to platen. */
static void brazilian_disc_3d_splits_along_the_loaded_plane(void)
{
    brazilian_disc("examples/brazilian-disc-3d.json", 1.0, 1.6);
}

/* The 3D disc that measures f_t (examples/brazilian-disc-3d-arc.json): 40
 * edges round the rim (a 10 x 10 lattice across, two layers: 1200
 * tetrahedra), loaded without platens through the rim nodes within a 15
 * degree arc of each end of the loaded diameter, moved at 0.025 m/s and
 * free sideways and along the axis. On this lattice the arc holds one row
 * of nodes along the axis, so the load is the diametral line load that
 * 2P/(pi D t) is the solution for. make limits measured 1.087 f_t here and
 * 1.130 at 48 edges (docs/physics.md, "3D Brazilian disc"): within 15 %.
 * The run takes minutes under ASan, so the sanitizer build (FDEM_SAN, set
 * by the Makefile) runs the same set-up on the 24-edge, one-layer lattice
 * and holds it to that mesh's band, [1.0, 1.6] f_t (measured 1.365), with
 * the same split; the 15 % figure is checked by the normal build. */
static void brazilian_disc_3d_through_arcs_peaks_at_its_tensile_strength(void)
{
    const char *path = "examples/brazilian-disc-3d-arc.json";
    case_info info;
#ifdef FDEM_SAN
    fdem_model *m = load_example_edited(path, "/parts/0/cylinder/divisions", "[24, 1]", &info);
    if (m) brazilian_disc_model(m, &info, 1.0, 1.6);
#else
    fdem_model *m = load_example(path, &info);
    if (m) brazilian_disc_model(m, &info, 0.85, 1.15);
#endif
}

CHECK_MAIN(T(brazilian_disc_splits_at_its_tensile_strength), T(uniaxial_compression_fails_in_shear),
           T(brazilian_disc_3d_splits_along_the_loaded_plane),
           T(brazilian_disc_3d_through_arcs_peaks_at_its_tensile_strength))
