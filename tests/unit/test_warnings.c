/*
 * test_warnings.c - contract 6.2 "Warnings": case_warnings() on a document
 * with units typed wrong (each value warned once, at its JSON Pointer; a
 * plausible document has none; neither is refused by case_build; the
 * build hands back the same list from its own parse), and the
 * engine's penetration depth (core/contact/penetration.c) against a depth
 * worked out by hand, then the case: a 3000 m/s block through a
 * 10 mm steel slab is found by fdem_take_penetrations, a 1 m/s touch is not.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "case/case.h"
#include "case_doc.h"
#include "check.h"
#include "contact/contact.h"
#include "model/model.h"

static const char *typos =
    "{'name': 'typos',"
    " 'materials': {'rock': {'density': 2.7, 'young': 40, 'poisson': 0.25, 'penalty': 10,"
    "   'friction': 30,"
    "   'fracture': {'tensile_strength': 5, 'cohesion': 2e7, 'friction_angle': 0.61,"
    "                'energy_I': 10, 'energy_II': 50}},"
    "   'steel': {'density': 7800, 'young': 2e11, 'poisson': 0.3,"
    "   'fracture': {'tensile_strength': 5e6, 'cohesion': 2e11, 'friction_angle': 0,"
    "                'energy_I': 10, 'energy_II': 50}}},"
    " 'parts': [{'name': 'block', 'material': 'rock',"
    "   'rectangle': {'origin': [0, 0], 'size': [0.1, 0.1], 'divisions': [2, 2]}}],"
    " 'gravity': [0, -981],"
    " 'time': {'end': 1e-3, 'dt': 1e-3}}";

static int warned_at(const problems *w, const char *pointer, const char *needle)
{
    int n = 0;
    for (int i = 0; i < w->count; i++)
        n += strcmp(w->items[i].pointer, pointer) == 0 && strstr(w->items[i].message, needle);
    return n;
}

static void test_typos_are_warned_at_their_pointers(void)
{
    char *text = quotes(typos);
    problems w;
    problems_init(&w);
    int n = case_warnings(text, strlen(text), &w);
    static const char *const want[][2] = {
        {"/materials/rock/young", "40"},
        {"/materials/rock/density", "2.7"},
        {"/materials/rock/penalty", "below young"},
        {"/materials/rock/friction", "degrees"},
        {"/materials/rock/fracture/tensile_strength", "far below"},
        {"/materials/rock/fracture/friction_angle", "radians"},
        {"/materials/steel/fracture/cohesion", "far above"},
        {"/gravity", "981"},
    };
    int count = (int)(sizeof want / sizeof want[0]);
    CHECK(n == count && w.count == count, "%d warnings, want %d", w.count, count);
    for (int i = 0; i < count; i++)
        CHECK(warned_at(&w, want[i][0], want[i][1]) == 1, "%s (%s) not warned once",
              want[i][0], want[i][1]);
    CHECK(w.status == 0, "warnings set a status %d", w.status);
    /* never a refusal: the same document builds */
    problems p;
    problems_init(&p);
    case_info info;
    fdem_model *m = case_build(text, strlen(text), GiB, &info, &p);
    CHECK(m != NULL, "a case with warnings was refused");
    if (!m) dump_problems(&p);
    fdem_model_destroy(m);
    problems_free(&p);
    problems_free(&w);
    free(text);
}

/* case_build_gated() hands back the warnings of the tree it parsed (one
 * parse per upload, issue 38): the same list as case_warnings(), in the
 * same order; a refused document gets none. */
static void test_build_gives_the_warnings_of_its_own_parse(void)
{
    char *text = quotes(typos);
    problems alone, built, p;
    problems_init(&alone);
    problems_init(&built);
    problems_init(&p);
    case_warnings(text, strlen(text), &alone);
    case_info info;
    fdem_model *m = case_build_gated(text, strlen(text), GiB, NULL, NULL, &info, &p, &built);
    CHECK(m != NULL && built.count == alone.count && built.status == 0,
          "built %d, %d warnings against %d", m != NULL, built.count, alone.count);
    for (int i = 0; i < built.count && i < alone.count; i++)
        CHECK(strcmp(built.items[i].pointer, alone.items[i].pointer) == 0 &&
                  strcmp(built.items[i].message, alone.items[i].message) == 0,
              "warning %d: %s against %s", i, built.items[i].pointer, alone.items[i].pointer);
    fdem_model_destroy(m);
    problems_free(&built);
    problems_free(&p);
    problems_init(&built);
    problems_init(&p);
    text[strlen(text) - 1] = ','; /* no longer JSON */
    m = case_build_gated(text, strlen(text), GiB, NULL, NULL, &info, &p, &built);
    CHECK(m == NULL && built.count == 0, "a refused document got %d warnings", built.count);
    problems_free(&alone);
    problems_free(&built);
    problems_free(&p);
    free(text);
}

static void test_plausible_case_has_none(void)
{
    char *text = quotes("{'materials': {'rock': {'density': 2700, 'young': 3e10, 'poisson': 0.25,"
                        " 'friction': 0.6, 'penalty': 3e11,"
                        " 'fracture': {'tensile_strength': 5e6, 'cohesion': 2e7,"
                        " 'friction_angle': 0, 'energy_I': 10, 'energy_II': 50}}},"
                        " 'parts': [{'discontinuities': [{'cohesion': 1e5}]}],"
                        " 'gravity': [0, 0, -9.81]}");
    problems w;
    problems_init(&w);
    CHECK(case_warnings(text, strlen(text), &w) == 0, "%d warnings, first at %s", w.count,
          w.count ? w.items[0].pointer : "");
    problems_free(&w);
    free(text);
}

/* A 0.06 x 0.01 m (3D: 0.04 x 0.04 x 0.01) steel slab, held at its ends,
 * and a 10 mm block `gap` above it moving down at `speed`, its mesh off
 * the slab's (nodes moving down the slab's edges are inside no element),
 * steel's contact penalty `penalty` (0: the default, 10 x young). */
static fdem_model *slab_hit(int dimension, double speed, double gap, double penalty)
{
    char extra[64] = "";
    if (penalty > 0) snprintf(extra, sizeof extra, ", 'penalty': %g", penalty);
    char text[2048];
    if (dimension == 2)
        snprintf(text, sizeof text,
            "{'materials': {'steel': {'density': 7800, 'young': 2e11, 'poisson': 0.3%s}},"
            " 'parts': [{'name': 'slab', 'material': 'steel', 'rectangle': {'origin': [0, 0],"
            "   'size': [0.06, 0.01], 'divisions': [12, 2]}},"
            "  {'name': 'bullet', 'material': 'steel', 'velocity': [0, %g], 'rectangle':"
            "   {'origin': [0.0263, %g], 'size': [0.01, 0.01], 'divisions': [2, 2]}}],"
            " 'constraints': [{'box': [-1, -1, 0.001, 1], 'fix': ['x', 'y']},"
            "   {'box': [0.059, -1, 1, 1], 'fix': ['x', 'y']}],"
            " 'time': {'end': 1e-5}}", extra, -speed, 0.01 + gap);
    else
        snprintf(text, sizeof text,
            "{'dimension': 3, 'materials': {'steel': {'density': 7800, 'young': 2e11,"
            "   'poisson': 0.3%s}},"
            " 'parts': [{'name': 'slab', 'material': 'steel', 'box': {'origin': [0, 0, 0],"
            "   'size': [0.04, 0.04, 0.01], 'divisions': [8, 8, 2]}},"
            "  {'name': 'bullet', 'material': 'steel', 'velocity': [0, 0, %g], 'box':"
            "   {'origin': [0.0163, 0.0171, %g], 'size': [0.01, 0.01, 0.01],"
            "    'divisions': [2, 2, 2]}}],"
            " 'constraints': [{'box': [-1, -1, -1, 0.001, 1, 1], 'fix': ['x', 'y', 'z']},"
            "   {'box': [0.039, -1, -1, 1, 1, 1], 'fix': ['x', 'y', 'z']}],"
            " 'time': {'end': 1e-5}}", extra, -speed, 0.01 + gap);
    char *doc = quotes(text);
    problems p;
    problems_init(&p);
    case_info info;
    fdem_model *m = case_build(doc, strlen(doc), GiB, &info, &p);
    if (!m) dump_problems(&p);
    problems_free(&p);
    free(doc);
    return m;
}

/* Moves node `node` of the model to x (the engine's arrays, a test only). */
static void place(fdem_model *m, int node, const double *x)
{
    for (int d = 0; d < m->dim; d++) m->pos[m->dim * node + d] = x[d];
}

/* Heights h[k] of element e (vertex k to the opposite face), from its size
 * and face sizes: 2 A / edge in 2D, 3 V / face area in 3D. */
static void heights(const fdem_model *m, int e, double h[4])
{
    const int D = m->dim;
    const int32_t *n = element_nodes(m, e);
    const double *p[4];
    for (int k = 0; k <= D; k++) p[k] = m->pos + D * n[k];
    if (D == 2) {
        double area2 = fabs((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) -
                            (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]));
        for (int k = 0; k < 3; k++) {
            const double *u = p[(k + 1) % 3], *v = p[(k + 2) % 3];
            h[k] = area2 / hypot(u[0] - v[0], u[1] - v[1]);
        }
        return;
    }
    double a[3], b[3], c[3];
    for (int d = 0; d < 3; d++) a[d] = p[1][d] - p[0][d], b[d] = p[2][d] - p[0][d],
                                c[d] = p[3][d] - p[0][d];
    double vol6 = fabs(a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                       a[2] * (b[0] * c[1] - b[1] * c[0]));
    for (int k = 0; k < 4; k++) {
        const double *q0 = p[(k + 1) % 4], *q1 = p[(k + 2) % 4], *q2 = p[(k + 3) % 4];
        double u[3], v[3];
        for (int d = 0; d < 3; d++) u[d] = q1[d] - q0[d], v[d] = q2[d] - q0[d];
        double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2],
               cz = u[0] * v[1] - u[1] * v[0];
        h[k] = vol6 / sqrt(cx * cx + cy * cy + cz * cz); /* 3V / area = 6V / |cross| */
    }
}

/* A node of the bullet put at slab element 0's centroid is 1/(D+1) of the
 * smallest height from its nearest face; the inradius is 1 / sum(1/h_k):
 * the fraction is min(h) / (D+1) * sum(1/h_k) (2D right isosceles:
 * (2 + sqrt 2) / (3 sqrt 2) = 0.8047,
 * 3D: the box's tetrahedra). At element 0's incentre it is 1; far away 0. */
static void test_depth_by_hand(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *m = slab_hit(dim, 1.0, 0.0025, 0);
        CHECK(m != NULL, "the slab case did not build");
        if (!m) continue;
        const int32_t *ns = element_nodes(m, 0);
        int bullet = -1;
        for (int e = 0; e < m->elem_count && bullet < 0; e++)
            if (m->elem_part[e] == 1) bullet = e;
        double h[4], c[3] = {0, 0, 0}, in[3] = {0, 0, 0}, hmin = INFINITY, inverse = 0;
        heights(m, 0, h);
        for (int k = 0; k <= dim; k++) hmin = fmin(hmin, h[k]), inverse += 1 / h[k];
        /* incentre: vertices weighted by their opposite faces, i.e. by 1/h_k */
        for (int k = 0; k <= dim; k++)
            for (int d = 0; d < dim; d++) {
                c[d] += m->pos[dim * ns[k] + d] / (dim + 1);
                in[d] += m->pos[dim * ns[k] + d] / h[k] / inverse;
            }
        int node = element_nodes(m, bullet)[0];
        place(m, node, c);
        double want = hmin / (dim + 1) * inverse;
        printf("  %dD centroid: %.15f, want %.15f\n", dim, contact_penetration(m, 0, bullet), want);
        CHECK_NEAR(contact_penetration(m, 0, bullet), want, 1e-12);
        place(m, node, in);
        CHECK_NEAR(contact_penetration(m, 0, bullet), 1.0, 1e-12);
        double far[3] = {1, 1, 1};
        place(m, node, far);
        CHECK(contact_penetration(m, 0, bullet) == 0, "a node far away is inside");
        fdem_model_destroy(m);
    }
}

static int run_and_take(fdem_model *m, fdem_penetration *pen, int max, double *deepest,
                        int *touched)
{
    int n = 0;
    *deepest = 0;
    *touched = 0;
    fdem_error err;
    while (fdem_get_time(m) < 1e-5) {
        memset(&err, 0, sizeof err);
        if (fdem_step(m, &err) != 0) break;
        n += fdem_take_penetrations(m, pen + n, max - n, NULL);
        *touched |= fdem_get_counts(m).contacts > 0;
    }
    for (int i = 0; i < n; i++) *deepest = fmax(*deepest, pen[i].depth);
    return n;
}

/* The case: 3000 m/s through a 10 mm slab (penalty young / 100:
 * it goes right through), found; the same block set on the slab at 10 m/s
 * touches it (contacts) and is not. */
static void test_fast_body_through_a_slab(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_penetration pen[FDEM_PENETRATIONS_MAX];
        double deepest;
        int touched;
        fdem_model *fast = slab_hit(dim, 3000, 0.0025, 2e9);
        int n = fast ? run_and_take(fast, pen, FDEM_PENETRATIONS_MAX, &deepest, &touched) : 0;
        printf("  %dD 3000 m/s: %d pairs, deepest %.3f, first at step %lld (%d, %d)\n", dim, n,
               deepest, n ? (long long)pen[0].step : -1LL, n ? pen[0].a : -1,
               n ? pen[0].b : -1);
        CHECK(n > 0, "%dD: no pair passing into another at 3000 m/s", dim);
        for (int i = 0; i < n; i++) {
            CHECK(pen[i].depth > FDEM_PENETRATION_WARN && pen[i].depth <= 1 + 1e-12 &&
                  pen[i].a < pen[i].b, "pair %d", i);
            CHECK(fast->elem_part[pen[i].a] != fast->elem_part[pen[i].b], "pair %d in one part", i);
            for (int j = 0; j < i; j++)
                CHECK(pen[i].a != pen[j].a || pen[i].b != pen[j].b, "pair %d twice", i);
        }
        fdem_model_destroy(fast);
        fdem_model *slow = slab_hit(dim, 10, 2e-5, 0);
        n = slow ? run_and_take(slow, pen, FDEM_PENETRATIONS_MAX, &deepest, &touched) : 0;
        CHECK(touched, "%dD: the slow block never touched the slab", dim);
        CHECK(n == 0, "%dD: %d pairs at 10 m/s", dim, n);
        fdem_model_destroy(slow);
    }
}

CHECK_MAIN(T(test_typos_are_warned_at_their_pointers),
           T(test_build_gives_the_warnings_of_its_own_parse), T(test_plausible_case_has_none),
           T(test_depth_by_hand), T(test_fast_body_through_a_slab))
