/*
 * test_hf_natural_joint.c - a hydraulic fracture meeting a natural joint at
 * right angles (issue 36 item 6): whether it crosses follows Renshaw &
 * Pollard's criterion (1995, Int. J. Rock Mech. 32, 237), which their
 * experiments bear out: it crosses a frictional interface when
 *     sigma_H / (T0 + sigma_h) > (0.35 + 0.35 / mu) / 1.06
 * (compression positive; sigma_H acts across the interface, along the
 * fracture; sigma_h across the fracture; T0 the rock's tensile strength,
 * mu the interface's friction coefficient). Below it the tip's stress
 * field makes the interface slip and open ahead of the tip, and the fluid
 * turns into it: the fracture is arrested.
 *
 * The model is examples/hf-natural-joint.json as committed (a 1 x 1 m
 * square, 20 x 20 cells, fluid injected at the centre, the fracture along
 * y = 0, a weak frictional joint set on x = 0.15 m; T0 = 3 MPa,
 * sigma_h = 1 MPa), with sigma_H and the joint's friction angle changed:
 *   sigma_H = 10 MPa, phi = 30 deg: 2.5 against 0.90: crosses;
 *   sigma_H =  2 MPa, phi = 30 deg: 0.5 against 0.90: arrested;
 *   sigma_H = 10 MPa, phi =  5 deg: 2.5 against 4.10: arrested.
 * Crossing: a joint of the line y = 0 beyond the natural joint breaks,
 * with the natural joint intact. Arrest: none does by the end (8 ms),
 * while the natural joint breaks and holds fluid. Measured 2026-12-06:
 * crossed at 5.55 ms (10 MPa), the natural joint intact; at 2 MPa, and at
 * 10 MPa with phi = 5 deg, not crossed by 8 ms, the fracture stopped at
 * the joint (x = 0.15 m), the joint's 20 joints slipped through (its
 * cohesion is 10 kPa) and 6 wet. 2.1 s of CPU for the three.
 * Where the model's threshold lies (daemon runs, phi = 30 deg): arrested at
 * sigma_H = 5 and 5.5 MPa (ratio 1.25, 1.38), crossed at 6, 7.5 and 10 MPa
 * (1.5 - 2.5); with 0.025 m cells arrested at 4, crossed at 5 MPa
 * (1.0 - 1.25); with 0.0125 m still arrested at 4.5 MPa (1.125): the
 * switch lies 1.1-1.7 times the criterion's 0.90, which is why these
 * cases sit far from it (docs/physics.md says what may move it).
 */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "case_doc.h"
#include "check.h"
#include "fdem.h"

#define EXAMPLE "examples/hf-natural-joint.json"
#define JOINT_X 0.15
#define CELL 0.05

typedef struct meeting {
    int crossed;       /* a joint of y = 0 beyond the natural joint broke */
    double reach;      /* the farthest broken joint's end on y = 0, x > 0 */
    int joint_broken;  /* joints of the natural joint broken */
    int joint_wet;     /* and holding fluid */
    double time;       /* when it was decided (crossing) or the end */
} meeting;

static int on(double a, double b) { return fabs(a - b) < 1e-9; }

static meeting measure(const fdem_model *m)
{
    meeting k = {0};
    const int32_t *jn = fdem_joints(m);
    const double *x0 = fdem_initial_positions(m), *damage = fdem_joint_damage(m);
    const double *pressure = fdem_fluid_pressure(m);
    for (int j = 0; j < fdem_get_counts(m).joints; j++) {
        const double *a = x0 + 2 * jn[4 * j], *b = x0 + 2 * jn[4 * j + 1];
        if (on(a[1], 0) && on(b[1], 0) && damage[j] >= 1) {
            double far = fmax(a[0], b[0]);
            k.reach = fmax(k.reach, far);
            k.crossed |= fmin(a[0], b[0]) > JOINT_X - 1e-9; /* on the far side */
        }
        if (on(a[0], JOINT_X) && on(b[0], JOINT_X)) {
            k.joint_broken += damage[j] >= 1;
            k.joint_wet += pressure[j] > 0;
        }
    }
    k.time = fdem_get_time(m);
    return k;
}

/* The example with sigma_H and the natural joint's friction angle set, run
 * until it crosses or ends. */
static meeting run_case(double sigma_H, double friction_angle)
{
    meeting k = {0};
    size_t length = 0;
    char *text = read_file(EXAMPLE, &length);
    json_error_t error;
    json_t *doc = text ? json_loadb(text, length, 0, &error) : NULL;
    free(text);
    CHECK(doc != NULL, "%s does not parse", EXAMPLE);
    if (!doc) return k;
    edit(doc, "/parts/0/initial_stress/value/0", json_real(-sigma_H));
    edit(doc, "/parts/0/discontinuities/natural joint/friction_angle", json_real(friction_angle));
    double end = json_number_value(json_object_get(json_object_get(doc, "time"), "end"));
    fdem_model *m = expect_built(doc, NULL);
    if (!m) return k;
    fdem_error err;
    int failed = 0;
    while (!failed && fdem_get_time(m) < end && !(k = measure(m)).crossed)
        failed = fdem_step(m, &err) != 0;
    CHECK(!failed, "step failed: %s", failed ? err.message : "");
    k = measure(m);
    double mu = tan(friction_angle * M_PI / 180);
    fprintf(stderr, "  sigma_H %4.1f MPa, phi %4.1f deg: ratio %.2f, criterion %.2f: %s at "
            "t = %.2f ms; the fracture reaches x = %.3f m, the natural joint has %d broken, "
            "%d wet\n", sigma_H / 1e6, friction_angle, sigma_H / (3e6 + 1e6),
            (0.35 + 0.35 / mu) / 1.06, k.crossed ? "crossed" : "not crossed", k.time * 1e3,
            k.reach, k.joint_broken, k.joint_wet);
    fdem_model_destroy(m);
    return k;
}

static void crosses_when_clamped(void)
{
    meeting k = run_case(10e6, 30);
    CHECK(k.crossed, "the fracture did not cross (reached x = %.3f)", k.reach);
    CHECK(k.joint_broken == 0, "%d joints of the natural joint broke", k.joint_broken);
}

static void arrested_under_low_stress(void)
{
    meeting k = run_case(2e6, 30);
    CHECK(!k.crossed, "the fracture crossed at t = %.4f", k.time);
    CHECK(k.reach > JOINT_X - 2 * CELL, "the fracture reached x = %.3f only: it never met the "
          "natural joint", k.reach);
    CHECK(k.joint_broken > 2 && k.joint_wet > 0, "the natural joint: %d broken, %d wet",
          k.joint_broken, k.joint_wet);
}

#ifndef FDEM_SAN
static void arrested_by_a_slippery_joint(void)
{
    meeting k = run_case(10e6, 5);
    CHECK(!k.crossed, "the fracture crossed at t = %.4f", k.time);
    CHECK(k.reach > JOINT_X - 2 * CELL, "the fracture reached x = %.3f only", k.reach);
    CHECK(k.joint_broken > 2 && k.joint_wet > 0, "the natural joint: %d broken, %d wet",
          k.joint_broken, k.joint_wet);
}
#endif

#ifdef FDEM_SAN
/* the friction case runs the same code with another number: the normal
 * build checks it */
CHECK_MAIN(T(crosses_when_clamped), T(arrested_under_low_stress))
#else
CHECK_MAIN(T(crosses_when_clamped), T(arrested_under_low_stress), T(arrested_by_a_slippery_joint))
#endif
