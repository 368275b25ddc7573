/*
 * test_result_recovery.c - result.h5 after something went wrong, checked by
 * the independent reader (tests/unit/result_check.py, h5py): reopened after
 * a crash (the rows past the last complete snapshot dropped, older files
 * gaining the series they lack), the HDF5-free download image opened
 * plainly with a checksum HDF5 agrees with, a damaged file refused, and a
 * full disk that leaves what was written readable. The layout and SWMR
 * reads: test_result.c; what both share: result_run.h.
 */
#include "result_run.h"

/* ----------------------------------------------------------------- tests */

static void test_result_reopen_after_crash(void)
{
    run r;
    memset(&r, 0, sizeof r);
    r.model = fixture_model(1, 1, &r.info);
    CHECK(r.model != NULL, "fixture model");
    if (!r.model) return;
    snapshot *snaps[5];
    for (int i = 0; i < 5; i++) {
        snaps[i] = snapshot_take(r.model, r.info.fields);
        fixture_step(r.model, STEPS_BETWEEN);
    }
    char path[512];
    tmp_path(path, sizeof path, "crash.h5");

    /* A writer that dies without closing the file. */
    fflush(NULL);
    pid_t child = fork();
    if (child == 0) {
        char e[512];
        result_file *f = result_create(path, r.model, &r.info, e, sizeof e);
        for (int i = 0; f && i < 3; i++) result_append(f, snaps[i], e, sizeof e);
        _exit(f ? 0 : 1);
    }
    int status = -1;
    waitpid(child, &status, 0);
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0, "crashing writer failed early");
    CHECK(run_checker("crash.h5", "-", "openfails", NULL) == 0,
          "a crashed SWMR file should refuse a plain open (else this test proves nothing)");

    r.file = result_reopen(path, r.model, &r.info, snaps[1]->step, r.err, sizeof r.err);
    CHECK(r.file != NULL, "result_reopen: %s", r.err);
    if (r.file) {
        CHECK(result_snapshot_count(r.file) == 2, "kept %d snapshots, want 2",
              result_snapshot_count(r.file));
        CHECK(result_snapshot_time(r.file, 1) == snaps[1]->time, "time of the kept snapshot");
        for (int i = 3; i < 5; i++)
            CHECK(result_append(r.file, snaps[i], r.err, sizeof r.err) == 0, "%s", r.err);
        CHECK(result_snapshot_count(r.file) == 4, "count %d", result_snapshot_count(r.file));
        CHECK(result_close(r.file) == 0, "result_close");
        r.file = NULL;
    }
    r.expect = expect_new(r.model, &r.info);
    int kept[4] = {0, 1, 3, 4};
    for (int i = 0; i < 4; i++) expect_snapshot(r.expect, snaps[kept[i]]);
    expect_save(r.expect, "crash.json");
    CHECK(run_checker("crash.h5", "crash.json", "plain", NULL) == 0, "reopened file");
    for (int i = 0; i < 5; i++) snapshot_free(snaps[i]);
    run_end(&r);
}

/* The highest address of a chunk holding row `row` of a /snapshots
 * series of more than one dimension (0 if none). */
static uint64_t last_row_chunk_address(const char *path, hsize_t row)
{
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t group = file >= 0 ? H5Gopen2(file, "snapshots", H5P_DEFAULT) : -1;
    uint64_t highest = 0;
    hsize_t count = 0;
    if (group >= 0) H5Gget_num_objs(group, &count);
    for (hsize_t i = 0; i < count; i++) {
        char name[128];
        if (H5Gget_objname_by_idx(group, i, name, sizeof name) < 0) continue;
        hid_t ds = H5Dopen2(group, name, H5P_DEFAULT);
        hid_t space = ds >= 0 ? H5Dget_space(ds) : -1;
        int rank = space >= 0 ? H5Sget_simple_extent_ndims(space) : 0;
        hsize_t at[3] = {row, 0, 0};
        unsigned filter = 0;
        haddr_t addr = HADDR_UNDEF;
        hsize_t size = 0;
        if (rank >= 2 && H5Dget_chunk_info_by_coord(ds, at, &filter, &addr, &size) >= 0 &&
            addr != HADDR_UNDEF && addr > highest)
            highest = addr;
        if (space >= 0) H5Sclose(space);
        if (ds >= 0) H5Dclose(ds);
    }
    if (group >= 0) H5Gclose(group);
    if (file >= 0) H5Fclose(file);
    return highest;
}

/* Sets the end of allocation of a version 2/3 superblock (8-byte
 * addresses: base, extension, end, root) short, as a crashed SWMR writer
 * can leave it; result_image_mark_closed redoes its checksum. 0 or -1. */
static int superblock_set_stale_end(const char *path, uint64_t end)
{
    unsigned char sb[48];
    int fd = open(path, O_RDWR);
    int ok = fd >= 0 && pread(fd, sb, sizeof sb, 0) == (ssize_t)sizeof sb && sb[9] == 8;
    if (ok) {
        for (int i = 0; i < 8; i++) sb[28 + i] = (unsigned char)(end >> (8 * i));
        ok = result_image_mark_closed(sb, sizeof sb) == 0 &&
             pwrite(fd, sb, sizeof sb, 0) == (ssize_t)sizeof sb;
    }
    if (fd >= 0) close(fd);
    return ok ? 0 : -1;
}

/* An SWMR writer writes the superblock's end of allocation (EOA) only now
 * and then: a SIGKILLed daemon left bytes past it in 1 kill of 4, and
 * once a chunk of a kept row there, so the reopened file's next append
 * failed ("addr overflow, addr = eoa"; the case failed after a few hundred
 * kills of test_crash_consistency) or, had it been allocated there, would
 * have written over that row. The file here is left so on purpose: the
 * EOA is set to the last row's last chunk. Every row must read back and
 * the next ones append. */
static void test_result_reopen_keeps_rows_past_a_stale_end_of_allocation(void)
{
    enum { FIRST = 5, MORE = 3 };
    run r;
    memset(&r, 0, sizeof r);
    if (run_start(&r, 0, 1, 0, "stale-eoa.h5") != 0) {
        run_end(&r);
        return;
    }
    for (int i = 0; i < FIRST; i++) run_append(&r);
    CHECK(result_close(r.file) == 0, "result_close");
    r.file = NULL;
    char path[512];
    tmp_path(path, sizeof path, "stale-eoa.h5");
    uint64_t chunk = last_row_chunk_address(path, FIRST - 1);
    CHECK(chunk > 0, "no chunk of the last row found");
    CHECK(superblock_set_stale_end(path, chunk) == 0, "cannot set the superblock of %s", path);
    r.file = result_reopen(path, r.model, &r.info, INT64_MAX, r.err, sizeof r.err);
    CHECK(r.file != NULL, "result_reopen: %s", r.err);
    if (r.file) {
        CHECK(result_snapshot_count(r.file) == FIRST, "kept %d snapshots, want %d",
              result_snapshot_count(r.file), FIRST);
        for (int i = 0; i < MORE; i++)
            CHECK(run_append(&r) == 0, "append %d after the reopen: %s", i, r.err);
        CHECK(result_close(r.file) == 0, "result_close");
        r.file = NULL;
        expect_save(r.expect, "stale-eoa.json");
        CHECK(run_checker("stale-eoa.h5", "stale-eoa.json", "plain", NULL) == 0,
              "the rows past the stale end and the ones appended read back");
    }
    run_end(&r);
}

static void test_result_reopen_clean_file_keeps_all(void)
{
    run r;
    if (run_start(&r, 0, 1, 0, "clean.h5") == 0) {
        for (int i = 0; i < 3; i++) run_append(&r);
        CHECK(result_close(r.file) == 0, "result_close");
        char path[512];
        tmp_path(path, sizeof path, "clean.h5");
        r.file = result_reopen(path, r.model, &r.info, INT64_MAX, r.err, sizeof r.err);
        CHECK(r.file != NULL, "result_reopen: %s", r.err);
        if (r.file) {
            CHECK(result_snapshot_count(r.file) == 3, "count %d", result_snapshot_count(r.file));
            run_append(&r);
            expect_save(r.expect, "clean.json");
            CHECK(run_checker("clean.h5", "clean.json", "swmr", NULL) == 0, "reopened, swmr");
        }
    }
    run_end(&r);
}

/* A file from before fragments were recorded (no /snapshots/fragment): a
 * paused case must go on. The series is added with its earlier rows -1
 * (not recorded), and the rows appended after carry the ids. */
static void test_result_reopen_adds_fragment_series_to_older_file(void)
{
    run r;
    if (run_start(&r, 0, 1, 0, "older.h5") == 0) {
        for (int i = 0; i < 3; i++) run_append(&r);
        CHECK(result_close(r.file) == 0, "result_close");
        char path[512];
        tmp_path(path, sizeof path, "older.h5");
        hid_t file = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
        CHECK(file >= 0 && H5Ldelete(file, "/snapshots/fragment", H5P_DEFAULT) >= 0,
              "making the older file");
        if (file >= 0) H5Fclose(file);
        r.file = result_reopen(path, r.model, &r.info, INT64_MAX, r.err, sizeof r.err);
        CHECK(r.file != NULL, "result_reopen of an older file: %s", r.err);
        if (r.file) {
            CHECK(result_snapshot_count(r.file) == 3, "count %d", result_snapshot_count(r.file));
            run_append(&r);
            CHECK(result_close(r.file) == 0, "result_close");
            r.file = NULL;
            file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
            hid_t ds = file >= 0 ? H5Dopen2(file, "/snapshots/fragment", H5P_DEFAULT) : -1;
            hid_t space = ds >= 0 ? H5Dget_space(ds) : -1;
            hsize_t dims[2] = {0, 0};
            if (space >= 0) H5Sget_simple_extent_dims(space, dims, NULL);
            CHECK(dims[0] == 4, "fragment rows %llu", (unsigned long long)dims[0]);
            int32_t *ids = dims[0] == 4 ? malloc(sizeof(int32_t) * 4 * dims[1]) : NULL;
            if (ids && H5Dread(ds, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, ids) >= 0) {
                int unrecorded = 0, recorded = 0;
                for (hsize_t e = 0; e < 3 * dims[1]; e++) unrecorded += ids[e] == -1;
                for (hsize_t e = 3 * dims[1]; e < 4 * dims[1]; e++) recorded += ids[e] >= 0;
                CHECK(unrecorded == (int)(3 * dims[1]), "earlier rows: %d of %d are -1",
                      unrecorded, (int)(3 * dims[1]));
                CHECK(recorded == (int)dims[1], "new row: %d of %d ids", recorded, (int)dims[1]);
            }
            free(ids);
            if (space >= 0) H5Sclose(space);
            if (ds >= 0) H5Dclose(ds);
            if (file >= 0) H5Fclose(file);
        }
    }
    run_end(&r);
}

/* What a download does: flush on the I/O thread, then a byte copy taken by
 * any thread with the superblock's open-for-writing flags cleared. */
static int image_copy(run *r, const char *name)
{
    char src[512], dst[512];
    tmp_path(src, sizeof src, "live.h5");
    tmp_path(dst, sizeof dst, name);
    if (result_flush(r->file, r->err, sizeof r->err) != 0) return -1;
    int in = open(src, O_RDONLY), out = open(dst, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    struct stat st;
    int rc = in >= 0 && out >= 0 && fstat(in, &st) == 0 ? 0 : -1;
    for (size_t done = 0; rc == 0 && done < (size_t)st.st_size;) {
        ssize_t n = result_image_copy_step(in, out, done, (size_t)st.st_size);
        if (n <= 0) rc = -1;
        else done += (size_t)n;
    }
    if (in >= 0) close(in);
    if (out >= 0) close(out);
    return rc;
}

static void test_result_image_opens_plainly(void)
{
    run r;
    if (run_start(&r, 1, 1, 0, "live.h5") == 0) {
        for (int i = 0; i < 3; i++) run_append(&r);
        expect_save(r.expect, "live.json");
        CHECK(image_copy(&r, "copy.h5") == 0, "image copy: %s", strerror(errno));
        CHECK(run_checker("copy.h5", "live.json", "plain", NULL) == 0, "copy, plain open");
        /* The copy is a snapshot of the file, not a view of it. */
        run_append(&r);
        expect_save(r.expect, "live.json");
        CHECK(run_checker("copy.h5", "live.json", "plain", "--count 3") == 0, "copy unchanged");
        CHECK(image_copy(&r, "copy.h5") == 0, "image copy: %s", strerror(errno));
        CHECK(run_checker("copy.h5", "live.json", "plain", NULL) == 0, "second copy");
    }
    run_end(&r);
}

/* The checksum we write is the one HDF5 writes: a closed file's superblock
 * recomputed leaves every byte as it was. */
static void test_result_image_checksum_matches_hdf5(void)
{
    run r;
    if (run_start(&r, 0, 0, 0, "closed.h5") == 0) {
        run_append(&r);
        CHECK(result_close(r.file) == 0, "close");
        r.file = NULL;
        char path[512];
        tmp_path(path, sizeof path, "closed.h5");
        unsigned char head[64], again[64];
        FILE *f = fopen(path, "rb");
        CHECK(f && fread(head, 1, sizeof head, f) == sizeof head, "read superblock");
        if (f) fclose(f);
        memcpy(again, head, sizeof head);
        CHECK(result_image_mark_closed(again, sizeof again) == 0, "superblock not recognised");
        CHECK(memcmp(head, again, sizeof head) == 0, "checksum differs from HDF5's");
        again[0] = 'X';
        CHECK(result_image_mark_closed(again, sizeof again) < 0, "a non-HDF5 head was accepted");
    }
    run_end(&r);
}

static void test_result_check_file_refuses_damage(void)
{
    run r;
    if (run_start(&r, 0, 0, 0, "whole.h5") == 0) {
        run_append(&r);
        CHECK(result_close(r.file) == 0, "close");
        r.file = NULL;
        char path[512], err[512] = "";
        tmp_path(path, sizeof path, "whole.h5");
        CHECK(result_check_file(path, err, sizeof err) == 0, "whole file refused: %s", err);
        struct stat st;
        CHECK(stat(path, &st) == 0 && truncate(path, st.st_size / 2) == 0, "truncate");
        CHECK(result_check_file(path, err, sizeof err) < 0, "a truncated file was accepted");
        tmp_path(path, sizeof path, "");
        CHECK(result_check_file(path, err, sizeof err) < 0, "a directory was accepted");
        CHECK(strstr(err, "not a regular file") != NULL, "message: %s", err);
    }
    run_end(&r);
}

/* A disk that fills while result_finish adds the views must not leave the
 * file flagged as open for writing (h5py and the other readers then refuse
 * it): the views go only into room reserved on disk first, else nowhere.
 * RLIMIT_FSIZE plays the full disk: a write past it fails with EFBIG as
 * one past a full disk fails with ENOSPC. */
static void test_result_finish_on_a_full_disk_keeps_the_file_readable(void)
{
    run r;
    if (run_start(&r, 1, 1, 0, "fullfinish.h5") == 0) {
        for (int i = 0; i < 40; i++) run_append(&r);
        char path[512], err[512] = "";
        tmp_path(path, sizeof path, "fullfinish.h5");
        CHECK(result_flush(r.file, err, sizeof err) == 0, "flush: %s", err);
        struct stat st;
        CHECK(stat(path, &st) == 0, "stat");
        struct rlimit old, tight;
        CHECK(getrlimit(RLIMIT_FSIZE, &old) == 0, "getrlimit");
        void (*was)(int) = signal(SIGXFSZ, SIG_IGN);
        tight = old;
        tight.rlim_cur = (rlim_t)st.st_size + 512;
        CHECK(setrlimit(RLIMIT_FSIZE, &tight) == 0, "setrlimit");
        int finished = result_finish(r.file, path, fdem_get_dimension(r.model), err, sizeof err);
        int views = result_view_count(r.file);
        int closed = result_close(r.file);
        r.file = NULL;
        CHECK(setrlimit(RLIMIT_FSIZE, &old) == 0, "setrlimit back");
        signal(SIGXFSZ, was);
        fprintf(stderr, "DBG finish %d err %s closed %d\n", finished, err, closed);
        CHECK(finished < 0, "views added past the file size limit");
        CHECK(strstr(err, "fullfinish.h5") && strstr(err, "/xdmf views"), "message: %s", err);
        CHECK(views == 0, "views %d", views);
        CHECK(closed == 0, "close after the refused views failed");
        expect_save(r.expect, "fullfinish.json");
        CHECK(run_checker("fullfinish.h5", "fullfinish.json", "plain", NULL) == 0,
              "40 snapshots readable after a full disk");
    }
    run_end(&r);
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        T(test_result_reopen_after_crash),
        T(test_result_reopen_keeps_rows_past_a_stale_end_of_allocation),
        T(test_result_reopen_clean_file_keeps_all),
        T(test_result_reopen_adds_fragment_series_to_older_file),
        T(test_result_image_opens_plainly), T(test_result_image_checksum_matches_hdf5),
        T(test_result_check_file_refuses_damage),
        T(test_result_finish_on_a_full_disk_keeps_the_file_readable),
    };
    return result_tests_main(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
