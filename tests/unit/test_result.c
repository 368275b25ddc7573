/*
 * test_result.c - result.h5 and result.xdmf checked by an independent
 * reader: tests/unit/result_check.py (h5py) compares the file with what the
 * engine reported, which this test writes as JSON (17-digit doubles, so the
 * comparison is exact). It reads while the writer still has the file open
 * (SWMR), races the writer and stops it mid-append, and checks the layout
 * of 2D, 3D, staged and minimal files and their sidecars. Reopening,
 * download copies and damaged files: test_result_recovery.c; what both
 * share: result_run.h.
 */
#include "result_run.h"

/* ----------------------------------------------------------------- tests */

static void test_result_layout_and_swmr_reads(void)
{
    run r;
    if (run_start(&r, 1, 1, 0, "layout.h5") == 0) {
        for (int i = 0; i < 3; i++) run_append(&r);
        expect_save(r.expect, "layout.json");
        /* Still open for SWMR writing. */
        CHECK(run_checker("layout.h5", "layout.json", "swmr", NULL) == 0, "3 snapshots, swmr");
        run_append(&r);
        run_append(&r);
        expect_save(r.expect, "layout.json");
        CHECK(run_checker("layout.h5", "layout.json", "swmr", NULL) == 0, "5 snapshots, swmr");
        CHECK(result_snapshot_count(r.file) == 5, "count %d", result_snapshot_count(r.file));
        CHECK(result_snapshot_time(r.file, 0) == 0.0, "first snapshot at t = 0");
        CHECK_NEAR(result_snapshot_time(r.file, 4), 4 * STEPS_BETWEEN * r.info.dt,
                   1e-9 * r.info.dt);
        CHECK(isnan(result_snapshot_time(r.file, 5)), "time past the end is NaN");
        CHECK(result_close(r.file) == 0, "result_close");
        r.file = NULL;
        CHECK(run_checker("layout.h5", "layout.json", "plain", NULL) == 0, "closed file");
    }
    run_end(&r);
}

static void test_result_reader_follows_writer(void)
{
    enum { SNAPSHOTS = 40 };
    run r;
    if (run_start(&r, 1, 1, 0, "follow.h5") != 0) {
        run_end(&r);
        return;
    }
    /* The follower needs every expected snapshot up front. */
    snapshot *snaps[SNAPSHOTS] = {0};
    for (int i = 0; i < SNAPSHOTS; i++) {
        snaps[i] = snapshot_take(r.model, r.info.fields);
        expect_snapshot(r.expect, snaps[i]);
        fixture_step(r.model, 1);
    }
    expect_save(r.expect, "follow.json");
    CHECK(result_append(r.file, snaps[0], r.err, sizeof r.err) == 0, "%s", r.err);

    char cmd[2048], h5[512], exp[512];
    tmp_path(h5, sizeof h5, "follow.h5");
    tmp_path(exp, sizeof exp, "follow.json");
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s '%s' '%s' follow 2>&1", checker_path(), h5,
             exp);
    FILE *p = popen(cmd, "r");
    char line[1024] = "";
    CHECK(p && fgets(line, sizeof line, p) && strncmp(line, "ready", 5) == 0,
          "follower did not start: %s", line);
    for (int i = 1; i < SNAPSHOTS; i++) {
        CHECK(result_append(r.file, snaps[i], r.err, sizeof r.err) == 0, "%s", r.err);
        usleep(1000);
    }
    int seen_ok = 0;
    while (p && fgets(line, sizeof line, p)) {
        fprintf(stderr, "    checker follow: %s", line);
        seen_ok |= strncmp(line, "ok", 2) == 0;
    }
    int status = p ? pclose(p) : -1;
    CHECK(seen_ok && WIFEXITED(status) && WEXITSTATUS(status) == 0, "follower failed");
    for (int i = 0; i < SNAPSHOTS; i++) snapshot_free(snaps[i]);
    run_end(&r);
}

/* A child process that creates `name`, appends snaps[0], reports ready on
 * a pipe, then appends the rest flat out. Returns its pid once ready, or -1. */
static pid_t spawn_writer(run *r, const char *name, snapshot **snaps, int count)
{
    char path[512];
    tmp_path(path, sizeof path, name);
    int ready[2];
    if (pipe(ready) != 0) return -1;
    fflush(NULL);
    pid_t child = fork();
    if (child == 0) {
        char e[512];
        result_file *f = result_create(path, r->model, &r->info, e, sizeof e);
        if (!f || result_append(f, snaps[0], e, sizeof e) < 0) _exit(1);
        if (write(ready[1], "1", 1) != 1) _exit(1);
        for (int i = 1; i < count; i++) {
            if (result_append(f, snaps[i], e, sizeof e) < 0) _exit(1);
            usleep(20);
        }
        _exit(result_close(f) == 0 ? 0 : 1);
    }
    close(ready[1]);
    char byte = 0;
    int started = child > 0 && read(ready[0], &byte, 1) == 1;
    close(ready[0]);
    return started ? child : -1;
}

/* result_check.py in a mode that answers one line per line it is sent. */
static pid_t spawn_checker(const char *h5_name, const char *expected, const char *mode,
                           FILE **ask, FILE **answer)
{
    int to[2], from[2];
    if (pipe(to) != 0 || pipe(from) != 0) return -1;
    char h5[512], exp[512];
    tmp_path(h5, sizeof h5, h5_name);
    tmp_path(exp, sizeof exp, expected);
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        dup2(to[0], 0);
        dup2(from[1], 1);
        dup2(from[1], 2);
        close(to[1]);
        close(from[0]);
        execl("/usr/bin/python3", "python3", checker_path(), h5, exp, mode, (char *)NULL);
        _exit(127);
    }
    close(to[0]);
    close(from[1]);
    *ask = fdopen(to[1], "w");
    *answer = fdopen(from[0], "r");
    return pid;
}

/* A writer process appending flat out is frozen with SIGSTOP at arbitrary
 * moments, usually in the middle of an append, and a SWMR reader checks
 * that every snapshot /snapshots/time admits is complete in every dataset.
 * This is the test that fails if time is not written last (checked by
 * moving the time write first: 3 to 15 of the 40 states were torn). */
static void test_result_writer_stopped_mid_append(void)
{
    enum { SNAPSHOTS = 800, FREEZES = 40 };
    run r;
    memset(&r, 0, sizeof r);
    r.model = fixture_model(1, 1, &r.info);
    CHECK(r.model != NULL, "fixture model");
    if (!r.model) return;
    r.expect = expect_new(r.model, &r.info);
    snapshot *snaps[SNAPSHOTS];
    for (int i = 0; i < SNAPSHOTS; i++) {
        snaps[i] = snapshot_take(r.model, r.info.fields);
        expect_snapshot(r.expect, snaps[i]);
        fixture_step(r.model, 1);
    }
    expect_save(r.expect, "frozen.json");

    pid_t writer = spawn_writer(&r, "frozen.h5", snaps, SNAPSHOTS);
    CHECK(writer > 0, "the writer process failed to start");
    FILE *ask = NULL, *answer = NULL;
    pid_t checker = writer > 0 ? spawn_checker("frozen.h5", "frozen.json", "frozen", &ask,
                                               &answer) : -1;
    char line[1024];
    int consistent = 0;
    for (int round = 0; round < FREEZES && checker > 0; round++) {
        usleep(200 + (unsigned)(rand() % 2000));
        int status;
        kill(writer, SIGSTOP);
        waitpid(writer, &status, WUNTRACED);
        fputs("check\n", ask);
        fflush(ask);
        if (fgets(line, sizeof line, answer)) {
            int ok = strncmp(line, "checked", 7) == 0;
            consistent += ok;
            if (!ok) fprintf(stderr, "    checker frozen: %s", line);
        }
        kill(writer, SIGCONT);
    }
    int checker_status = -1, writer_status = -1;
    if (checker > 0) {
        fclose(ask);
        while (fgets(line, sizeof line, answer)) fprintf(stderr, "    checker frozen: %s", line);
        fclose(answer);
        waitpid(checker, &checker_status, 0);
    }
    CHECK(consistent == FREEZES && WIFEXITED(checker_status) &&
              WEXITSTATUS(checker_status) == 0,
          "%d of %d frozen states consistent", consistent, FREEZES);
    if (writer > 0) waitpid(writer, &writer_status, 0);
    CHECK(WIFEXITED(writer_status) && WEXITSTATUS(writer_status) == 0, "writer process failed");
    CHECK(run_checker("frozen.h5", "frozen.json", "plain", NULL) == 0, "all snapshots");
    for (int i = 0; i < SNAPSHOTS; i++) snapshot_free(snaps[i]);
    run_end(&r);
}

static void test_result_minimal_fields_without_constraints(void)
{
    run r;
    /* No constraints: /snapshots/constraint_force is (S, 0, 2). */
    if (run_start(&r, 0, 0, CASE_FIELD_VELOCITY, "minimal.h5") == 0) {
        for (int i = 0; i < 2; i++) run_append(&r);
        expect_save(r.expect, "minimal.json");
        CHECK(run_checker("minimal.h5", "minimal.json", "swmr", NULL) == 0, "minimal layout");
        char xdmf[512];
        tmp_path(xdmf, sizeof xdmf, "minimal.xdmf");
        CHECK(xdmf_write(xdmf, "result.h5", r.model, &r.info, r.file, r.err, sizeof r.err) == 0,
              "xdmf_write: %s", r.err);
    }
    run_end(&r);
}

static void test_xdmf_matches_file(void)
{
    run r;
    if (run_start(&r, 1, 1, 0, "result.h5") == 0) {
        for (int i = 0; i < 3; i++) run_append(&r);
        expect_save(r.expect, "result.json");
        run_check_xdmf(&r, "result.xdmf", "result.h5", "result.json", "xdmf with stress");
        run_finish(&r, "result.h5");
        run_check_xdmf(&r, "result.xdmf", "result.h5", "result.json", "xdmf with views");
    }
    run_end(&r);
    /* Without position the geometry is the initial mesh. */
    if (run_start(&r, 0, 0, CASE_FIELD_VELOCITY, "result.h5") == 0) {
        for (int i = 0; i < 2; i++) run_append(&r);
        expect_save(r.expect, "result.json");
        run_check_xdmf(&r, "result.xdmf", "result.h5", "result.json", "xdmf, position0");
    }
    run_end(&r);
}

/* The 3D layout of contract 5.2: dimension = 3, /mesh/tetrahedra (E, 4),
 * (S, N, 3) node series, (S, E, 6) stress, (S, C, 3) constraint forces,
 * read back by h5py under SWMR and as a closed file, and an XDMF with
 * Tetrahedron topology and XYZ geometry that matches the file. */
static void test_result_3d_layout_and_xdmf(void)
{
    run r;
    memset(&r, 0, sizeof r);
    if (run_start_with(&r, fixture_model_3d(1, &r.info), 0, "solid.h5") == 0) {
        for (int i = 0; i < 3; i++) run_append(&r);
        expect_save(r.expect, "solid.json");
        CHECK(run_checker("solid.h5", "solid.json", "swmr", NULL) == 0, "3D layout, swmr");
        run_check_xdmf(&r, "solid.xdmf", "solid.h5", "solid.json", "3D xdmf");
        run_finish(&r, "solid.h5");
        run_check_xdmf(&r, "solid.xdmf", "solid.h5", "solid.json", "3D xdmf with views");
        CHECK(result_close(r.file) == 0, "result_close");
        r.file = NULL;
        CHECK(run_checker("solid.h5", "solid.json", "plain", NULL) == 0, "3D, closed file");
    }
    run_end(&r);
}

/* A case in stages (contract 6.1): /snapshots/stage (S) i32 and
 * /snapshots/active (S, E) u8, the stage of each row and 0 for the two
 * triangles from the row after their removal on, read back by h5py under
 * SWMR and closed, and the sidecar's `active` Cell UChar (a HyperSlab
 * while open, a view once finished), the file reopened with them kept. */
static void test_result_stages_layout_and_xdmf(void)
{
    run r;
    memset(&r, 0, sizeof r);
    if (run_start_with(&r, fixture_model_staged(&r.info), 0, "staged.h5") == 0) {
        for (int i = 0; i < 3; i++) run_append(&r);
        expect_save(r.expect, "staged.json");
        json_t *rows = json_object_get(r.expect, "snapshots");
        CHECK(json_integer_value(json_object_get(json_array_get(rows, 0), "stage")) == 0 &&
              json_integer_value(json_object_get(json_array_get(rows, 2), "stage")) == 1,
              "the rows do not span both stages");
        json_t *last = json_object_get(json_array_get(rows, 2), "active");
        CHECK(json_integer_value(json_array_get(last, 15)) == 0 &&
              json_integer_value(json_array_get(last, 13)) == 1, "the last row's flags");
        CHECK(run_checker("staged.h5", "staged.json", "swmr", NULL) == 0, "stages, swmr");
        run_check_xdmf(&r, "staged.xdmf", "staged.h5", "staged.json", "stages xdmf");
        run_finish(&r, "staged.h5");
        run_check_xdmf(&r, "staged.xdmf", "staged.h5", "staged.json", "stages xdmf, views");
        CHECK(result_close(r.file) == 0, "result_close");
        char path[512];
        tmp_path(path, sizeof path, "staged.h5");
        r.file = result_reopen(path, r.model, &r.info, INT64_MAX, r.err, sizeof r.err);
        CHECK(r.file && result_snapshot_count(r.file) == 3, "reopened: %s", r.err);
        if (r.file) CHECK(result_close(r.file) == 0, "result_close");
        r.file = NULL;
        CHECK(run_checker("staged.h5", "staged.json", "plain", NULL) == 0, "stages, closed");
    }
    run_end(&r);
}

/* Displacement written without position, 2D and 3D: each snapshot's rows
 * are x - x0 as subtracted here from the engine's arrays (the file then
 * holds them, (S, N, dimension), checked by h5py), the sidecar names them
 * as a Node Vector over the initial geometry, a HyperSlab while the file
 * is open and a 3-component view once finished. The fixture's fields
 * (with position) have result_check.py compare displacement with
 * /snapshots/position - /mesh/position0 in every other test. */
static void test_result_displacement_without_position(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        char h5[32], xdmf[32], json[32];
        snprintf(h5, sizeof h5, "disp%d.h5", dim);
        snprintf(xdmf, sizeof xdmf, "disp%d.xdmf", dim);
        snprintf(json, sizeof json, "disp%d.json", dim);
        run r;
        memset(&r, 0, sizeof r);
        fdem_model *m = dim == 3 ? fixture_model_3d(1, &r.info) : fixture_model(1, 1, &r.info);
        if (run_start_with(&r, m, CASE_FIELD_VELOCITY | CASE_FIELD_DISPLACEMENT, h5) != 0) {
            run_end(&r);
            continue;
        }
        double moved = 0;
        for (int i = 0; i < 4; i++) {
            snapshot *s = snapshot_take(r.model, r.info.fields);
            size_t n = (size_t)dim * (size_t)(s ? s->nodes : 0);
            const double *x = fdem_positions(r.model), *x0 = fdem_initial_positions(r.model);
            int exact = s && s->displacement && !s->position;
            for (size_t k = 0; exact && k < n; k++) {
                double u = x[k] - x0[k];
                exact = memcmp(&u, &s->displacement[k], sizeof u) == 0;
                moved = fmax(moved, fabs(u));
            }
            CHECK(exact, "%dD snapshot %d: displacement is not position - position0", dim, i);
            CHECK(s && result_append(r.file, s, r.err, sizeof r.err) == 0, "append: %s", r.err);
            if (s) expect_snapshot(r.expect, s);
            snapshot_free(s);
            fixture_step(r.model, 4 * STEPS_BETWEEN);
        }
        CHECK(moved > 0, "%dD: the model did not move", dim);
        expect_save(r.expect, json);
        CHECK(run_checker(h5, json, "swmr", NULL) == 0, "%dD displacement, swmr", dim);
        run_check_xdmf(&r, xdmf, h5, json, "displacement xdmf, HyperSlabs");
        run_finish(&r, h5);
        run_check_xdmf(&r, xdmf, h5, json, "displacement xdmf, views");
        char path[512];
        tmp_path(path, sizeof path, xdmf);
        char *text = read_text(path);
        CHECK(text && strstr(text, "<Attribute Name=\"displacement\" AttributeType=\"Vector\" "
                                   "Center=\"Node\">"), "%dD: no displacement vector in %s",
              dim, xdmf);
        free(text);
        CHECK(result_close(r.file) == 0, "result_close");
        r.file = NULL;
        CHECK(run_checker(h5, json, "plain", NULL) == 0, "%dD displacement, closed file", dim);
        run_end(&r);
    }
}

static void test_result_bad_input_is_an_error(void)
{
    char err[512] = "";
    run r;
    if (run_start(&r, 1, 1, 0, "errors.h5") != 0) {
        run_end(&r);
        return;
    }
    CHECK(result_create("/nonexistent-dir/x.h5", r.model, &r.info, err, sizeof err) == NULL &&
              strstr(err, "/nonexistent-dir/x.h5"), "create in a missing folder: %s", err);

    /* A snapshot of another model, and one missing a stored field. */
    fdem_model *other = fixture_model(0, 1, NULL);
    snapshot *wrong = other ? snapshot_take(other, r.info.fields) : NULL;
    CHECK(wrong && result_append(r.file, wrong, err, sizeof err) < 0 && strstr(err, "nodes"),
          "snapshot of another model: %s", err);
    snapshot *partial = snapshot_take(r.model, CASE_FIELD_POSITION);
    CHECK(partial && result_append(r.file, partial, err, sizeof err) < 0 &&
              strstr(err, "velocity"), "snapshot without velocity: %s", err);
    CHECK(result_snapshot_count(r.file) == 0, "a rejected snapshot was counted");
    run_append(&r); /* the file is still usable */
    expect_save(r.expect, "errors.json");
    CHECK(run_checker("errors.h5", "errors.json", "swmr", NULL) == 0, "after rejections");

    char path[512];
    tmp_path(path, sizeof path, "missing.h5");
    CHECK(result_reopen(path, r.model, &r.info, 0, err, sizeof err) == NULL &&
              strstr(err, "missing.h5"), "reopen a missing file: %s", err);
    tmp_path(path, sizeof path, "foreign.h5");
    hid_t foreign = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    H5Fclose(foreign);
    CHECK(result_reopen(path, r.model, &r.info, 0, err, sizeof err) == NULL &&
              strstr(err, "not an fdem result"), "reopen a foreign file: %s", err);
    CHECK(result_close(r.file) == 0, "close");
    r.file = NULL;
    tmp_path(path, sizeof path, "errors.h5");
    CHECK(other && result_reopen(path, other, &r.info, 0, err, sizeof err) == NULL &&
              strstr(err, "does not match"), "reopen with another model: %s", err);
    snapshot_free(wrong);
    snapshot_free(partial);
    fdem_model_destroy(other);
    run_end(&r);
}

/* The fixed-length strings of /mesh/<name> joined by '|' into out. */
static void read_mesh_names(const char *path, const char *name, char *out, size_t size)
{
    out[0] = '\0';
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    char where[64];
    snprintf(where, sizeof where, "/mesh/%s", name);
    hid_t ds = file >= 0 ? H5Dopen2(file, where, H5P_DEFAULT) : H5I_INVALID_HID;
    hid_t type = ds >= 0 ? H5Dget_type(ds) : H5I_INVALID_HID;
    hid_t space = ds >= 0 ? H5Dget_space(ds) : H5I_INVALID_HID;
    if (type >= 0 && space >= 0) {
        size_t width = H5Tget_size(type);
        hssize_t count = H5Sget_simple_extent_npoints(space);
        char *all = calloc((size_t)(count > 0 ? count : 1), width);
        if (all && (count == 0 || H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, all) >= 0))
            for (hssize_t i = 0; i < count; i++) {
                size_t used = strlen(out);
                snprintf(out + used, size - used, "%s%.*s", i ? "|" : "", (int)width,
                         all + (size_t)i * width);
            }
        free(all);
    }
    if (space >= 0) H5Sclose(space);
    if (type >= 0) H5Tclose(type);
    if (ds >= 0) H5Dclose(ds);
    if (file >= 0) H5Fclose(file);
}

/* /mesh/part_names and material_names come from the builder's case_info
 * (issue 38: the I/O thread parsed a 4 MB document a second time only for
 * them, as much CPU as building its model): with the names kept, the
 * stored text is not read for them (a text that is not JSON still
 * describes the file); parts in "parts" order, an unnamed one "part<i>",
 * materials in the document's order. Without kept names (too many to keep)
 * the document is read as before. */
static void test_result_names_come_from_the_builder(void)
{
    const char *doc =
        "{\"materials\": {\"soft\": {\"density\": 2000, \"young\": 1e8, \"poisson\": 0.25},"
        " \"hard\": {\"density\": 2700, \"young\": 3e10, \"poisson\": 0.25}},"
        " \"parts\": [{\"material\": \"hard\", \"rectangle\": {\"origin\": [0, 0],"
        " \"size\": [1, 1], \"divisions\": [2, 2]}}, {\"name\": \"top\", \"material\": \"soft\","
        " \"rectangle\": {\"origin\": [0, 1.5], \"size\": [1, 1], \"divisions\": [2, 2]}}],"
        " \"time\": {\"end\": 1e-4}}";
    problems p;
    problems_init(&p);
    case_info info;
    fdem_model *m = case_build(doc, strlen(doc), (size_t)1 << 30, &info, &p);
    CHECK(m && info.names_bytes > 0 && info.part_count == 2 && info.material_count == 2,
          "built %d, names %d bytes", m != NULL, m ? info.names_bytes : 0);
    if (!m) return;
    char path[512], err[512] = "", names[256];
    tmp_path(path, sizeof path, "names.h5");
    const char text[] = "not JSON: the names are the builder's";
    result_file *f = result_create_described(path, m, &info, text, sizeof text - 1, err,
                                             sizeof err);
    CHECK(f && result_close(f) == 0, "described with kept names: %s", err);
    read_mesh_names(path, "part_names", names, sizeof names);
    CHECK(strcmp(names, "part0|top") == 0, "part names %s", names);
    read_mesh_names(path, "material_names", names, sizeof names);
    CHECK(strcmp(names, "soft|hard") == 0, "material names %s", names);
    info.names_bytes = 0; /* as when they did not fit: the document is read */
    f = result_create_described(path, m, &info, doc, strlen(doc), err, sizeof err);
    CHECK(f && result_close(f) == 0, "described from the document: %s", err);
    read_mesh_names(path, "part_names", names, sizeof names);
    CHECK(strcmp(names, "part0|top") == 0, "part names read from the document %s", names);
    read_mesh_names(path, "material_names", names, sizeof names);
    CHECK(strcmp(names, "soft|hard") == 0, "material names read from the document %s", names);
    fdem_model_destroy(m);
    problems_free(&p);
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        T(test_result_layout_and_swmr_reads), T(test_result_reader_follows_writer),
        T(test_result_writer_stopped_mid_append), T(test_result_minimal_fields_without_constraints),
        T(test_xdmf_matches_file), T(test_result_3d_layout_and_xdmf),
        T(test_result_displacement_without_position), T(test_result_stages_layout_and_xdmf),
        T(test_result_bad_input_is_an_error), T(test_result_names_come_from_the_builder),
    };
    return result_tests_main(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
