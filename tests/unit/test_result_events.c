/*
 * test_result_events.c - /events in result.h5 (contract 5.4): events
 * appended to a new file read back the same, from the open writer and from
 * the closed file, filtered by ?since's rule (time > since); a reopen
 * keeps the events of the joints the resumed model has broken and drops
 * those written after its checkpoint; a file written before events existed
 * reads as none and gets the group on reopen.
 */
#include <hdf5.h>
#include <stdint.h>
#include <stdlib.h>
#include <unistd.h>

#include "check.h"
#include "result/result.h"
#include "result_fixture.h"

static char tmpdir[] = "/tmp/fdem-result-events-XXXXXX";

static fdem_event event(double time, int joint, int mode, double energy)
{
    fdem_event e = {.time = time, .joint = joint, .mode = (int8_t)mode, .energy = energy};
    e.position[0] = 0.1 * joint;
    e.position[1] = 0.25 + joint;
    return e;
}

/* The `count` events read back from f (or path) after `since` equal want. */
static void check_read_d(result_file *f, const char *path, double since, const fdem_event *want,
                         int count, int want_dimension, const char *what)
{
    fdem_event *got = NULL;
    int n = -1, dimension = 0;
    char err[512] = "";
    CHECK(result_read_events(f, path, since, &got, &n, &dimension, err, sizeof err) == 0,
          "%s: %s", what, err);
    CHECK(n == count, "%s: %d events, want %d", what, n, count);
    CHECK(dimension == want_dimension, "%s: dimension %d", what, dimension);
    for (int i = 0; i < n && i < count; i++)
        CHECK(got[i].time == want[i].time && got[i].joint == want[i].joint &&
                  got[i].mode == want[i].mode && got[i].energy == want[i].energy &&
                  memcmp(got[i].position, want[i].position, sizeof(double) * (size_t)dimension) == 0,
              "%s: event %d differs", what, i);
    free(got);
}

static void check_read(result_file *f, const char *path, double since, const fdem_event *want,
                       int count, const char *what)
{
    check_read_d(f, path, since, want, count, 2, what);
}

static result_file *new_file(fdem_model **m, case_info *info, const char *path)
{
    char err[512] = "";
    *m = fixture_model(1, 1, info);
    CHECK(*m && fdem_get_counts(*m).joints >= 3, "a fixture with joints");
    if (!*m) return NULL;
    result_file *f = result_create(path, *m, info, err, sizeof err);
    CHECK(f != NULL, "result_create: %s", err);
    return f;
}

static void events_read_back(void)
{
    char path[512], err[512] = "";
    snprintf(path, sizeof path, "%s/read.h5", tmpdir);
    fdem_model *m = NULL;
    case_info info;
    result_file *f = new_file(&m, &info, path);
    if (!f) return;
    fdem_event ev[3] = {event(1e-6, 2, 1, 0.5), event(1e-6, 5, 3, 0.25), event(3e-6, 0, 2, 2)};
    check_read(f, NULL, -INFINITY, ev, 0, "a new file");
    CHECK(result_append_events(f, ev, 2, err, sizeof err) == 0, "%s", err);
    CHECK(result_append_events(f, ev + 2, 1, err, sizeof err) == 0, "%s", err);
    check_read(f, NULL, -INFINITY, ev, 3, "the open file");
    check_read(f, NULL, 1e-6, ev + 2, 1, "the open file after 1e-6 s");
    check_read(f, NULL, 3e-6, ev, 0, "the open file after the last");
    CHECK(result_close(f) == 0, "close");
    check_read(NULL, path, 0, ev, 3, "the closed file");
    check_read(NULL, path, 2e-6, ev + 2, 1, "the closed file after 2e-6 s");
    fdem_model_destroy(m);
}

/* The run resumes from a model in which joints 2 and 1 broke, not 0: the
 * event of joint 0, written after that checkpoint, is dropped (it will
 * break again), and the events appended next follow the kept ones. */
static void reopen_keeps_the_events_of_broken_joints(void)
{
    char path[512], err[512] = "";
    snprintf(path, sizeof path, "%s/reopen.h5", tmpdir);
    fdem_model *m = NULL;
    case_info info;
    result_file *f = new_file(&m, &info, path);
    if (!f) return;
    fdem_event ev[3] = {event(1e-6, 1, 1, 0.5), event(1e-6, 2, 3, 0.25), event(3e-6, 0, 2, 2)};
    CHECK(result_append_events(f, ev, 3, err, sizeof err) == 0, "%s", err);
    CHECK(result_close(f) == 0, "close");
    double *damage = (double *)fdem_joint_damage(m); /* the checkpoint's state, by hand */
    damage[1] = damage[2] = 1.0;
    damage[0] = 0.5;
    f = result_reopen(path, m, &info, INT64_MAX, err, sizeof err);
    CHECK(f != NULL, "result_reopen: %s", err);
    if (!f) return;
    check_read(f, NULL, -INFINITY, ev, 2, "the reopened file");
    fdem_event later = event(4e-6, 0, 1, 1);
    CHECK(result_append_events(f, &later, 1, err, sizeof err) == 0, "%s", err);
    fdem_event want[3] = {ev[0], ev[1], later};
    CHECK(result_close(f) == 0, "close");
    check_read(NULL, path, -INFINITY, want, 3, "appended after the reopen");
    fdem_model_destroy(m);
}

static void file_without_events(void)
{
    char path[512], err[512] = "";
    snprintf(path, sizeof path, "%s/older.h5", tmpdir);
    fdem_model *m = NULL;
    case_info info;
    result_file *f = new_file(&m, &info, path);
    if (!f) return;
    CHECK(result_close(f) == 0, "close");
    hid_t file = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    CHECK(file >= 0 && H5Ldelete(file, "/events", H5P_DEFAULT) >= 0, "making the older file");
    if (file >= 0) H5Fclose(file);
    check_read_d(NULL, path, -INFINITY, NULL, 0, 0, "a file written before events");
    f = result_reopen(path, m, &info, INT64_MAX, err, sizeof err);
    CHECK(f != NULL, "result_reopen of an older file: %s", err);
    if (!f) return;
    fdem_event ev = event(1e-6, 1, 1, 0.5);
    CHECK(result_append_events(f, &ev, 1, err, sizeof err) == 0, "%s", err);
    check_read(f, NULL, -INFINITY, &ev, 1, "the older file, reopened");
    CHECK(result_close(f) == 0, "close");
    fdem_model_destroy(m);
}

/* A 3D file has (K, 3) positions, and the group even without joints. */
static void events_in_3d(void)
{
    char path[512], err[512] = "";
    snprintf(path, sizeof path, "%s/box.h5", tmpdir);
    case_info info;
    fdem_model *m = fixture_model_3d(1, &info);
    CHECK(m && fixture_step(m, 2) == 0, "the 3D fixture");
    if (!m) return;
    result_file *f = result_create(path, m, &info, err, sizeof err);
    CHECK(f != NULL, "result_create: %s", err);
    if (!f) return;
    check_read_d(f, NULL, -INFINITY, NULL, 0, 3, "a new 3D file");
    fdem_event ev = event(2e-6, 7, 2, 0.125);
    ev.position[2] = -0.5;
    CHECK(result_append_events(f, &ev, 1, err, sizeof err) == 0, "%s", err);
    CHECK(result_close(f) == 0, "close");
    check_read_d(NULL, path, 0, &ev, 1, 3, "the closed 3D file");
    fdem_model_destroy(m);
}

int main(int argc, char **argv)
{
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 2;
    }
    static const check_test tests[] = {T(events_read_back),
                                       T(reopen_keeps_the_events_of_broken_joints),
                                       T(file_without_events), T(events_in_3d)};
    int rc = check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
    char command[600];
    snprintf(command, sizeof command, "rm -rf %s", tmpdir);
    if (system(command) != 0) rc = rc ? rc : 1;
    return rc;
}
