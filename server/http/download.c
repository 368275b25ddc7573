/*
 * download.c - consistent downloads of result.h5 that stall nobody.
 *
 * A file still open for SWMR writing changes in place at every append, so
 * a download needs a copy taken between two appends. The I/O thread only
 * flushes and holds that case's writes (io_fetch_result); a copier thread
 * then copies the bytes (copy_file_range, so a reflink where the file
 * system has one) into an unlinked file in the case directory, and
 * releases the hold as soon as the last byte is copied, not when the
 * client has read them. The response streams from that copy as it grows,
 * so a slow client costs disk space for its copy and nothing else.
 *
 * A copy is for a client that reads it: a HEAD gets the size without one,
 * and when the client goes away (libmicrohttpd drops the response) the
 * copier stops at its next piece, releasing the hold and the copy's disk
 * space at once. Otherwise a GET that hung up still held the case's writes
 * for a whole copy, and a HEAD started one: a case fell from 166 to 2
 * steps/s under them (issue 30). Nor may copies take the disk space the
 * running cases are about to write (download_headroom).
 */
#define _GNU_SOURCE /* fallocate */
#include "download.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "http.h"
#include "cases/io_thread.h"
#include "common/memory_budget.h"
#include "result/result.h"

#define DOWNLOAD_BLOCK (256 * 1024) /* bytes per response read */
#define DOWNLOAD_ROWS_AHEAD 8              /* snapshots of room kept per writing case */
#define DOWNLOAD_MIN_HEADROOM ((size_t)4 << 20) /* status.json, .reserve files, slack */

typedef struct download {
    server_case *c;
    int src, dst;
    size_t size;
    atomic_int refs;           /* the copier and the response */
    atomic_int abandoned;      /* the response is gone: nobody will read the copy */
    pthread_mutex_t lock;
    pthread_cond_t progress;
    size_t copied;             /* guarded by lock */
    int failed;                /* errno of a failed copy, guarded by lock */
} download;

static atomic_ulong download_counter;

static void download_unref(download *d)
{
    if (atomic_fetch_sub(&d->refs, 1) != 1)
        return;
    close(d->dst);
    pthread_mutex_destroy(&d->lock);
    pthread_cond_destroy(&d->progress);
    case_release(d->c);
    free(d);
}

static void *download_copier(void *arg)
{
    download *d = arg;
    size_t done = 0;
    int failed = 0;
    while (done < d->size && !atomic_load(&d->abandoned)) {
        ssize_t n = result_image_copy_step(d->src, d->dst, done, d->size);
        if (n <= 0) {
            failed = n < 0 ? errno : EIO;
            break;
        }
        done += (size_t)n;
        pthread_mutex_lock(&d->lock);
        d->copied = done;
        pthread_cond_broadcast(&d->progress);
        pthread_mutex_unlock(&d->lock);
    }
    close(d->src);
    io_release_hold(d->c);
    if (!failed && done < d->size)
        fprintf(stderr, "fdemd: case %s: a download of result.h5 was abandoned by its client; "
                "its copy was stopped after %zu of %zu bytes and released\n", d->c->id, done,
                d->size);
    if (failed) {
        fprintf(stderr, "fdemd: case %s: copying result.h5 for a download failed: %s\n", d->c->id,
                strerror(failed));
        pthread_mutex_lock(&d->lock);
        d->failed = failed;
        pthread_cond_broadcast(&d->progress);
        pthread_mutex_unlock(&d->lock);
    }
    download_unref(d);
    return NULL;
}

/* Waits only for the copier's next piece (disk speed, never the client). */
static ssize_t download_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    download *d = cls;
    pthread_mutex_lock(&d->lock);
    while (d->copied <= pos && !d->failed)
        pthread_cond_wait(&d->progress, &d->lock);
    size_t available = d->copied > pos ? d->copied - (size_t)pos : 0;
    pthread_mutex_unlock(&d->lock);
    if (available == 0)
        return MHD_CONTENT_READER_END_WITH_ERROR;
    ssize_t n;
    do
        n = pread(d->dst, buf, max < available ? max : available, (off_t)pos);
    while (n < 0 && errno == EINTR);
    return n > 0 ? n : MHD_CONTENT_READER_END_WITH_ERROR;
}

static void download_response_done(void *cls)
{
    download *d = cls;
    atomic_store(&d->abandoned, 1);
    download_unref(d);
}

static size_t download_file_size(const server_case *c, const char *name)
{
    char path[1200];
    struct stat st;
    snprintf(path, sizeof path, "%s/%s", c->dir, name);
    return stat(path, &st) == 0 ? (size_t)st.st_size : 0;
}

/* Room the cases that are writing will soon need in --data: for each
 * running or queued case, its next DOWNLOAD_ROWS_AHEAD snapshots (priced at
 * the mean row of its result.h5 so far, mesh included, so rather more) and
 * two checkpoints (one is written beside the other). A copy may not eat
 * into it: nine unread copies once filled a 200 MB disk and another user's
 * running case failed for good (issue 30). */
static size_t download_headroom(void)
{
    size_t need = DOWNLOAD_MIN_HEADROOM;
    int count = 0;
    server_case **all = registry_list(&count);
    for (int i = 0; all && i < count; i++) {
        server_case *c = all[i];
        pthread_mutex_lock(&c->lock);
        int writing = c->state == CASE_RUNNING || c->state == CASE_QUEUED;
        int rows = c->fig.snapshots > 0 ? c->fig.snapshots : 1;
        pthread_mutex_unlock(&c->lock);
        if (writing)
            need += download_file_size(c, "result.h5") / (size_t)rows * DOWNLOAD_ROWS_AHEAD +
                    2 * download_file_size(c, "checkpoint.bin");
    }
    registry_list_free(all, count);
    return need;
}

/* 0 when a copy of `size` bytes leaves the headroom free (or cannot be
 * made at all), else -1 with a sentence in detail: a 503, as copies are
 * read off and released and cases end. */
static int download_check_room(server_case *c, size_t size, char *detail, size_t detail_size)
{
    struct statvfs fs;
    if (statvfs(c->dir, &fs) != 0)
        return 0; /* the copy's own fallocate then says what is wrong */
    size_t avail = (size_t)fs.f_bavail * (size_t)fs.f_frsize;
    size_t headroom = download_headroom();
    /* No room for the copy at all is the copy's own 507 (fallocate). */
    if (avail < size || avail - size >= headroom)
        return 0;
    char copy[32], free_now[32], keep[32];
    snprintf(detail, detail_size,
             "result.h5 of case %s is being written, and the consistent copy a download needs "
             "(%s) would leave less than the %s kept free for the running cases in the data "
             "directory (%s free now); try again later, or once the case has ended (its file "
             "is then sent without a copy)", c->id, membudget_describe(size, copy, sizeof copy),
             membudget_describe(headroom, keep, sizeof keep),
             membudget_describe(avail, free_now, sizeof free_now));
    return -1;
}

/* An unlinked file with room for `size` bytes, so a full disk is a 507
 * now rather than a cut-off transfer later. */
static int download_make_copy_file(server_case *c, size_t size)
{
    char path[1300];
    snprintf(path, sizeof path, "%s/.download-%lu.h5", c->dir, atomic_fetch_add(&download_counter, 1));
    int fd = open(path, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0)
        return -1;
    unlink(path);
    if (size > 0 && fallocate(fd, 0, 0, (off_t)size) != 0 && errno != EOPNOTSUPP) {
        int saved = errno;
        close(fd);
        errno = saved;
        return -1;
    }
    return fd;
}

static enum MHD_Result download_queue(struct MHD_Connection *conn, struct MHD_Response *resp)
{
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, "application/x-hdf5");
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    MHD_add_response_header(resp, "Content-Disposition", "attachment; filename=\"result.h5\"");
    enum MHD_Result rc = MHD_queue_response(conn, 200, resp);
    MHD_destroy_response(resp);
    return rc;
}

static enum MHD_Result download_refuse(struct MHD_Connection *conn, server_case *c, int err_no)
{
    char detail[1500];
    snprintf(detail, sizeof detail,
             "result.h5 of case %s is being written; the consistent copy a download needs could "
             "not be made in %s: %s", c->id, c->dir, strerror(err_no));
    fprintf(stderr, "fdemd: case %s: %s\n", c->id, detail);
    int full = err_no == ENOSPC || err_no == EDQUOT;
    return http_reply_problem(conn, full ? 507 : 500, full ? "Insufficient storage" : "Internal error",
                              detail, NULL);
}

/* Starts the copy of a held file and answers with its growing bytes. */
static enum MHD_Result download_copy_and_stream(struct MHD_Connection *conn, server_case *c,
                                                int src, size_t size)
{
    char detail[700];
    if (download_check_room(c, size, detail, sizeof detail) != 0) {
        close(src);
        io_release_hold(c);
        fprintf(stderr, "fdemd: case %s: download refused: %s\n", c->id, detail);
        return http_reply_unavailable(conn, detail, NULL);
    }
    download *d = calloc(1, sizeof *d);
    int dst = d ? download_make_copy_file(c, size) : -1;
    int saved = d ? errno : ENOMEM;
    if (!d || dst < 0) {
        free(d);
        close(src);
        io_release_hold(c);
        return download_refuse(conn, c, saved);
    }
    case_retain(c);
    d->c = c;
    d->src = src;
    d->dst = dst;
    d->size = size;
    atomic_init(&d->refs, 2);
    atomic_init(&d->abandoned, 0);
    pthread_mutex_init(&d->lock, NULL);
    pthread_cond_init(&d->progress, NULL);
    struct MHD_Response *resp =
        MHD_create_response_from_callback(size, DOWNLOAD_BLOCK, download_read, d, download_response_done);
    pthread_t t;
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    int started = resp && pthread_create(&t, &attr, download_copier, d) == 0;
    pthread_attr_destroy(&attr);
    if (!started) {
        /* Nobody else will copy or release: do it here, then refuse. */
        d->failed = EAGAIN;
        close(src);
        io_release_hold(c);
        if (resp)
            MHD_destroy_response(resp); /* drops the response's reference */
        else
            download_unref(d);
        download_unref(d);
        return http_reply_problem(conn, 500, "Internal error",
                                  "the daemon could not start a thread to copy result.h5", NULL);
    }
    return download_queue(conn, resp);
}

enum MHD_Result download_reply(struct MHD_Connection *conn, server_case *c, int head)
{
    int fd = -1, held = 0, status = 500;
    size_t size = 0;
    char err[600] = "";
    if (io_fetch_result(c, &fd, &size, &held, &status, err, sizeof err) != 0) {
        if (status != 404 && status != 409)
            fprintf(stderr, "fdemd: case %s: serving result.h5 failed: %s\n", c->id, err);
        return http_reply_problem(conn, (unsigned)status,
                                  status == 404 ? "Not found" : status == 409 ? "Conflict"
                                  : "Damaged result file", err, NULL);
    }
    /* HEAD: the size a GET would get now; the file is never read. */
    if (head && held)
        io_release_hold(c);
    if (!held || head)
        return http_reply_fd(conn, fd, size, "application/x-hdf5", "result.h5");
    return download_copy_and_stream(conn, c, fd, size);
}
