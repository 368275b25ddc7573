/*
 * test_case_history.c - the "history" block of a case document (contract
 * 6.2) in 2D and 3D: a valid block gives its interval, the point names and
 * the node nearest each point at t = 0 in case_info; a case without one
 * has interval 0 (rows at every snapshot); every bad input is one 422 at
 * its JSON Pointer (a point outside every body, a duplicate name, an
 * interval <= 0, a point of the other dimension).
 */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case/case.h"
#include "case_doc.h"
#include "check.h"

/* A 1 x 0.1 bar of 10 x 1 squares over [0, 1] x [0, 0.1]. */
static const char *bar_2d =
    "{'name': 'bar',"
    " 'materials': {'steel': {'density': 7800, 'young': 2e11, 'poisson': 0.3}},"
    " 'parts': [{'name': 'bar', 'material': 'steel',"
    "   'rectangle': {'origin': [0, 0], 'size': [1, 0.1], 'divisions': [10, 1]}}],"
    " 'constraints': [{'box': [-0.01, -1, 0.01, 1], 'fix': ['x', 'y']}],"
    " 'time': {'end': 0.001},"
    " 'history': {'interval': 1e-5, 'points': ["
    "   {'name': 'tip', 'at': [0.99, 0.01]}, {'name': 'middle', 'at': [0.5, 0.04]}]}}";

/* The same bar as a 1 x 0.1 x 0.1 box of 10 x 1 x 1 cells. */
static const char *bar_3d =
    "{'name': 'bar', 'dimension': 3,"
    " 'materials': {'steel': {'density': 7800, 'young': 2e11, 'poisson': 0.3}},"
    " 'parts': [{'name': 'bar', 'material': 'steel',"
    "   'box': {'origin': [0, 0, 0], 'size': [1, 0.1, 0.1], 'divisions': [10, 1, 1]}}],"
    " 'constraints': [{'box': [-0.01, -1, -1, 0.01, 1, 1], 'fix': ['x', 'y', 'z']}],"
    " 'time': {'end': 0.001},"
    " 'history': {'interval': 1e-5, 'points': ["
    "   {'name': 'tip', 'at': [0.99, 0.01, 0.09]}, {'name': 'middle', 'at': [0.5, 0.04, 0.01]}]}}";

/* The node of `m` at t = 0 that is nearest p, by brute force. */
static void check_node_at(const fdem_model *m, int node, const double *want)
{
    int dim = fdem_get_dimension(m);
    const double *x0 = fdem_initial_positions(m) + (size_t)dim * node;
    for (int d = 0; d < dim; d++) CHECK_NEAR(x0[d], want[d], 1e-12);
}

static void valid_history(const char *base, const double *tip, const double *middle)
{
    case_info info;
    fdem_model *m = expect_built(load(base), &info);
    if (!m) return;
    CHECK(info.history_interval == 1e-5, "interval %g", info.history_interval);
    CHECK(info.history_point_count == 2, "%d points", info.history_point_count);
    CHECK(strcmp(info.history_names[0], "tip") == 0, "name 0 \"%s\"", info.history_names[0]);
    CHECK(strcmp(info.history_names[1], "middle") == 0, "name 1 \"%s\"", info.history_names[1]);
    check_node_at(m, info.history_nodes[0], tip);
    check_node_at(m, info.history_nodes[1], middle);
    fdem_model_destroy(m);
}

static void history_2d_points_find_nearest_nodes(void)
{
    double tip[2] = {1, 0}, middle[2] = {0.5, 0};
    valid_history(bar_2d, tip, middle);
}

static void history_3d_points_find_nearest_nodes(void)
{
    double tip[3] = {1, 0, 0.1}, middle[3] = {0.5, 0, 0};
    valid_history(bar_3d, tip, middle);
}

static void no_history_means_at_snapshots(void)
{
    json_t *doc = load(bar_2d);
    edit(doc, "/history", NULL);
    case_info info;
    fdem_model *m = expect_built(doc, &info);
    CHECK(info.history_interval == 0 && info.history_point_count == 0, "interval %g, %d points",
          info.history_interval, info.history_point_count);
    if (m) fdem_model_destroy(m);
}

/* Every problem of the block in one answer, each at its pointer. */
static void bad_history(const char *base, const char *outside, const char *wrong_dimension)
{
    json_t *doc = load(base);
    edit(doc, "/history/interval", json_real(0));
    edit(doc, "/history/points/1/name", json_string("tip"));
    edit(doc, "/history/points/2", load(outside));
    edit(doc, "/history/points/3", load(wrong_dimension));
    edit(doc, "/history/points/4", load("{'name': 'p', 'at': [0.5, 0.05, 0], 'colour': 1}"));
    problems p;
    build_refused(doc, GiB, &p);
    CHECK(p.status == 422, "status %d", p.status);
    CHECK(has_problem(&p, "/history/interval", "interval must be > 0"), "interval 0");
    CHECK(has_problem(&p, "/history/points/1/name", "already the name of /history/points/0"),
          "duplicate name");
    CHECK(has_problem(&p, "/history/points/3/at", "dimension"), "a point of the other dimension");
    CHECK(has_problem(&p, "/history/points/4/colour", "unknown key"), "an unknown key");
    if (check_failures_in_test) dump_problems(&p);
    problems_free(&p);
    /* outside every body: found only in a model that builds */
    doc = load(base);
    edit(doc, "/history/points/2", load(outside));
    build_refused(doc, GiB, &p);
    CHECK(p.status == 422, "status %d", p.status);
    CHECK(has_problem(&p, "/history/points/2/at", "lies outside every body"), "outside");
    CHECK(p.count == 1, "%d problems, want 1", p.count);
    if (check_failures_in_test) dump_problems(&p);
    problems_free(&p);
}

static void bad_history_2d(void)
{
    bad_history(bar_2d, "{'name': 'far', 'at': [2, 0.05]}", "{'name': 'q', 'at': [0.5, 0, 0]}");
}

static void bad_history_3d(void)
{
    bad_history(bar_3d, "{'name': 'far', 'at': [0.5, 0.05, 0.2]}",
                "{'name': 'q', 'at': [0.5, 0.05]}");
}

CHECK_MAIN(T(history_2d_points_find_nearest_nodes), T(history_3d_points_find_nearest_nodes),
           T(no_history_means_at_snapshots), T(bad_history_2d), T(bad_history_3d))
