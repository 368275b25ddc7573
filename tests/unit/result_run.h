/*
 * result_run.h - what the result.h5 tests share (test_result.c: the
 * layout, SWMR reads and the writer; test_result_recovery.c: reopening,
 * download images, damaged files and a full disk): a scratch folder, the
 * expected document the independent reader (tests/unit/result_check.py,
 * h5py) compares the file with, written as JSON with 17-digit doubles so
 * the comparison is exact, and a run that writes snapshots of the
 * fixture model (result_fixture.h) as it steps.
 */
#ifndef FDEM_TEST_RESULT_RUN_H
#define FDEM_TEST_RESULT_RUN_H

#include <hdf5.h>
#include <jansson.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "result/result.h"
#include "result_fixture.h"
#include "state/state_json.h"

#define STEPS_BETWEEN 5

static char tmpdir[256];

/* ------------------------------------------------------------- test paths */

/* The whole of a small text file, NUL-terminated (free() it); NULL if unreadable. */
static inline char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *text = NULL;
    long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (size >= 0 && fseek(f, 0, SEEK_SET) == 0 && (text = malloc((size_t)size + 1)) &&
        fread(text, 1, (size_t)size, f) == (size_t)size) {
        text[size] = '\0';
    } else {
        free(text);
        text = NULL;
    }
    fclose(f);
    return text;
}

static inline void tmp_path(char *out, size_t size, const char *name)
{
    snprintf(out, size, "%s/%s", tmpdir, name);
}

/* result_check.py sits next to this file; tests run from the repo root. */
static inline const char *checker_path(void)
{
    static char path[512];
    const char *here = __FILE__;
    const char *slash = strrchr(here, '/');
    int dir = slash ? (int)(slash - here) : 0;
    snprintf(path, sizeof path, "%.*s%sresult_check.py", dir, here, slash ? "/" : "");
    return path;
}

/* ------------------------------------------------- the expected document */

static inline json_t *doubles_rows(const double *v, int rows, int width)
{
    json_t *a = json_array();
    for (int i = 0; i < rows; i++) {
        if (width == 0) {
            json_array_append_new(a, json_real(v[i]));
            continue;
        }
        json_t *row = json_array();
        for (int k = 0; k < width; k++) json_array_append_new(row, json_real(v[i * width + k]));
        json_array_append_new(a, row);
    }
    return a;
}

static inline json_t *ints_rows(const int32_t *v, int rows, int width)
{
    json_t *a = json_array();
    for (int i = 0; i < rows; i++) {
        if (width == 0) {
            json_array_append_new(a, json_integer(v[i]));
            continue;
        }
        json_t *row = json_array();
        for (int k = 0; k < width; k++) json_array_append_new(row, json_integer(v[i * width + k]));
        json_array_append_new(a, row);
    }
    return a;
}

/* What result_check.py expects: root attributes, mesh, dataset list. */
static inline json_t *expect_new(const fdem_model *m, const case_info *info)
{
    fdem_counts c = fdem_get_counts(m);
    int dim = fdem_get_dimension(m);
    json_t *mesh = json_object();
    json_object_set_new(mesh, "position0", doubles_rows(fdem_initial_positions(m), c.nodes, dim));
    json_object_set_new(mesh, dim == 3 ? "tetrahedra" : "triangles",
                        ints_rows(fdem_element_nodes(m), c.elements, fdem_nodes_per_element(m)));
    json_object_set_new(mesh, "node_mass", doubles_rows(fdem_node_masses(m), c.nodes, 0));
    json_object_set_new(mesh, "node_part", ints_rows(fdem_node_parts(m), c.nodes, 0));
    json_object_set_new(mesh, "element_part", ints_rows(fdem_element_parts(m), c.elements, 0));
    if (c.joints > 0)
        json_object_set_new(mesh, "joints", ints_rows(fdem_joints(m), c.joints, 2 * dim));

    json_t *series = json_pack("[sssss]", "step", "time", "kinetic_energy", "elastic_energy",
                               "constraint_force");
    if (info->fields & CASE_FIELD_POSITION) json_array_append_new(series, json_string("position"));
    if (info->fields & CASE_FIELD_VELOCITY) json_array_append_new(series, json_string("velocity"));
    if (info->fields & CASE_FIELD_STRESS) json_array_append_new(series, json_string("stress"));
    if (c.joints > 0) json_array_append_new(series, json_string("damage"));
    json_array_append_new(series, json_string("fragment"));
    if (info->fields & CASE_FIELD_STRAIN) json_array_append_new(series, json_string("strain"));
    if (info->fields & CASE_FIELD_PRINCIPAL_STRESS)
        json_array_append_new(series, json_string("principal_stress"));
    if (info->fields & CASE_FIELD_DISPLACEMENT)
        json_array_append_new(series, json_string("displacement"));
    if (fdem_stage_index(m) >= 0) {
        json_array_append_new(series, json_string("stage"));
        json_array_append_new(series, json_string("active"));
        json_array_append_new(series, json_string("excavated_energy"));
    }

    return json_pack("{s:s, s:i, s:f, s:i, s:s, s:o, s:o, s:[]}", "name", info->name,
                     "dimension", dim, "dt", fdem_get_dt(m), "constraints", c.constraints,
                     "h5_name", "result.h5", "series", series, "mesh", mesh, "snapshots");
}

/* One snapshot as the file must hold it: the state JSON (which the daemon
 * serves) plus what only the file stores. */
static inline void expect_snapshot(json_t *doc, const snapshot *s)
{
    snapshot all = *s;
    all.fields |= s->damage ? CASE_FIELD_DAMAGE : 0;
    json_t *j = state_to_json(&all);
    json_object_set_new(j, "constraint_force", doubles_rows(s->constraint_force, s->constraints,
                                                                s->dimension));
    json_object_set_new(j, "kinetic_energy", json_real(s->energy.kinetic));
    json_object_set_new(j, "fragment", ints_rows(s->fragment, s->elements, 0));
    json_object_set_new(j, "elastic_energy", json_real(s->energy.elastic));
    if (s->active) { /* a model with stages ("active" is in the state JSON) */
        json_object_set_new(j, "stage", json_integer(s->stage));
        json_object_set_new(j, "excavated_energy", json_real(s->energy.excavated));
    }
    json_array_append_new(json_object_get(doc, "snapshots"), j);
}

static inline void expect_save(json_t *doc, const char *name)
{
    char path[512];
    tmp_path(path, sizeof path, name);
    CHECK(json_dump_file(doc, path, JSON_COMPACT) == 0, "cannot write %s", path);
}

/* ------------------------------------------------------- running checks */

/* Runs result_check.py; its report goes to stderr. Returns its exit code. */
static inline int run_checker(const char *h5_name, const char *expected, const char *mode,
                       const char *extra)
{
    char cmd[4096], h5[512], exp[512];
    tmp_path(h5, sizeof h5, h5_name);
    tmp_path(exp, sizeof exp, expected);
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s '%s' '%s' %s %s 2>&1", checker_path(), h5,
             exp, mode, extra ? extra : "");
    FILE *p = popen(cmd, "r");
    if (!p) return -1;
    char line[1024];
    while (fgets(line, sizeof line, p)) fprintf(stderr, "    checker %s: %s", mode, line);
    int status = pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* -------------------------------------------------------------- fixtures */

typedef struct run {
    fdem_model *model;
    case_info info;
    json_t *expect;
    result_file *file;
    char err[512];
} run;

/* Takes `model` (from a fixture, filling r->info) and creates the file. */
static inline int run_start_with(run *r, fdem_model *model, unsigned fields, const char *name)
{
    r->model = model;
    if (!r->model) return -1;
    if (fields) r->info.fields = fields;
    r->expect = expect_new(r->model, &r->info);
    char path[512];
    tmp_path(path, sizeof path, name);
    r->file = result_create(path, r->model, &r->info, r->err, sizeof r->err);
    CHECK(r->file != NULL, "result_create: %s", r->err);
    return r->file ? 0 : -1;
}

static inline int run_start(run *r, int fracturing, int constraints, unsigned fields, const char *name)
{
    memset(r, 0, sizeof *r);
    return run_start_with(r, fixture_model(fracturing, constraints, &r->info), fields, name);
}

/* Takes a snapshot now, appends it and records it as expected; then steps. */
static inline int run_append(run *r)
{
    snapshot *s = snapshot_take(r->model, r->info.fields);
    int rc = s ? result_append(r->file, s, r->err, sizeof r->err) : -1;
    CHECK(rc == 0, "result_append: %s", r->err);
    if (rc == 0) expect_snapshot(r->expect, s);
    snapshot_free(s);
    return rc == 0 ? fixture_step(r->model, STEPS_BETWEEN) : -1;
}

static inline void run_end(run *r)
{
    if (r->file) CHECK(result_close(r->file) == 0, "result_close");
    json_decref(r->expect);
    fdem_model_destroy(r->model);
}

/* Writes r's sidecar as `xdmf_name` and has result_check.py compare it
 * with `h5_name` and the expected `json_name`; `what` labels a failure. */
static inline void run_check_xdmf(run *r, const char *xdmf_name, const char *h5_name,
                           const char *json_name, const char *what)
{
    char xdmf[512], extra[600];
    tmp_path(xdmf, sizeof xdmf, xdmf_name);
    CHECK(xdmf_write(xdmf, "result.h5", r->model, &r->info, r->file, r->err, sizeof r->err) == 0,
          "xdmf_write: %s", r->err);
    snprintf(extra, sizeof extra, "'%s'", xdmf);
    CHECK(run_checker(h5_name, json_name, "xdmf", extra) == 0, "%s", what);
}

/* Ends SWMR writing and adds the /xdmf views: every snapshot gets them. */
static inline void run_finish(run *r, const char *h5_name)
{
    char h5[512];
    tmp_path(h5, sizeof h5, h5_name);
    CHECK(result_finish(r->file, h5, fdem_get_dimension(r->model), r->err, sizeof r->err) == 0,
          "result_finish: %s", r->err);
    CHECK(result_view_count(r->file) == result_snapshot_count(r->file), "views %d of %d",
          result_view_count(r->file), result_snapshot_count(r->file));
}

static inline void setup(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/fdem-test-result-XXXXXX");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        exit(2);
    }
}

static inline void teardown(void)
{
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmpdir);
}

/* CHECK_MAIN plus a scratch folder for the files, removed afterwards. */
static inline int result_tests_main(const check_test *tests, int count, int argc, char **argv)
{
    setup();
    int rc = check_run(tests, count, argc, argv);
    teardown();
    return rc;
}

#endif
