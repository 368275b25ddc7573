/*
 * io_thread.h - the single thread that calls HDF5 (proto/result/result.h).
 *
 * Contract:
 *  - Jobs run strictly in the order they were queued, so a close queued
 *    after a case's last append sees every snapshot written, and a
 *    checkpoint queued with a snapshot lands on disk only after that
 *    snapshot is appended (checkpoint step <= last snapshot in result.h5,
 *    which is what result_reopen(keep_until_step) after a crash relies on).
 *  - A snapshot's row is counted in the status (`snapshots`) only once it
 *    and the checkpoint queued with it are fsynced: a restart cuts
 *    result.h5 back to checkpoint.bin, so an earlier count could turn back.
 *  - io_append() and io_checkpoint() take ownership of what they are given
 *    and return at once; the other calls wait for their job (they wait on
 *    file I/O, never on a simulation step).
 *  - Each job holds a reference on its case.
 *  - While a download copies a case's result.h5 (io_fetch_result with
 *    *held), that case's jobs wait aside and the others run on.
 */
#ifndef FDEMD_IO_THREAD_H
#define FDEMD_IO_THREAD_H

#include <stddef.h>
#include <stdint.h>
#include "registry.h"

int io_start(void);
void io_stop(void);

/* result_create + first snapshot + xdmf + checkpoint. */
int io_create(server_case *c, snapshot *first, void *ckpt, size_t ckpt_size,
              char *err, size_t errlen);
/* result_reopen keeping steps <= keep_until_step, then xdmf. */
int io_reopen(server_case *c, int64_t keep_until_step, int close_after,
              char *err, size_t errlen);
/* Appends the fracture events (may be NULL; malloc'd, taken over), then `s`
 * (may be NULL), then writes `ckpt` (may be NULL) as checkpoint.bin: the
 * events of the steps up to a snapshot are in result.h5 before it. */
void io_append(server_case *c, fdem_event *events, int event_count, snapshot *s, void *ckpt,
               size_t ckpt_size);
/* Rewrites result.xdmf of a case whose result.h5 is open if it lists
 * fewer rows than the file holds after the jobs queued before this call
 * (a running case's sidecar trails its file by up to ten times what a
 * rewrite takes, io_sidecar.c); waits for it. A case without a worker
 * has no open file: nothing is queued. For GET result.xdmf. */
void io_refresh_xdmf(server_case *c);
/* The case's fracture events with time > since from result.h5 (the open
 * file of a running case, else the file on disk; none when there is no
 * file yet): *out (free() it), *count, *dimension. -1 with the reason in
 * err when the file cannot be read. */
int io_read_events(server_case *c, double since, fdem_event **out, int *count, int *dimension,
                   char *err, size_t errlen);
/* Appends history rows (contract 6.2) to result.h5 after the jobs queued
 * before it; takes ownership of `rows` and each row, returns at once. The
 * worker queues a checkpoint's rows before it, so a restart that cuts
 * /history back to the checkpoint's step loses none it keeps. */
void io_append_history(server_case *c, history_row **rows, int count);
/* The case's history rows with time > since from result.h5 (as
 * io_read_events): *out (free with result_free_history), *count and the
 * point names the file holds. */
int io_read_history(server_case *c, double since, history_row ***out, int *count,
                    history_names *names, char *err, size_t errlen);
/* Snapshot q->snapshot of the case's result.h5 as the web page's binary
 * frame (result_read_frame): *out (free() it), *size. 0; 404 (no file, no
 * such snapshot), 503 (memory) or -1 (unreadable file) with err. */
int io_read_frame(server_case *c, const result_frame_request *q, unsigned char **out,
                  size_t *size, char *err, size_t errlen);
/* Writes the events (as io_append), then `ckpt` as DIR/ID/<name> (a string
 * literal), after the jobs queued before it; takes ownership, returns at once. */
void io_write_named_checkpoint(server_case *c, const char *name, fdem_event *events,
                               int event_count, void *ckpt, size_t ckpt_size);
/* Replaces the root attribute `case` of the closed result.h5 with `text`
 * (extend); waits. 0, or -1 with err. */
int io_replace_document(server_case *c, const char *text, size_t length, char *err,
                        size_t errlen);
void io_close(server_case *c);
/* An open descriptor of result.h5 and its size. A finished file is checked
 * and served as it is (*held = 0). A file still being written was flushed
 * and every later write of the case waits (*held = 1) until the caller has
 * copied the `size` bytes (result_image_copy_step, any thread) and called
 * io_release_hold(c). On failure *http_status is 404 (no file) or 500
 * (damaged or unreadable) with the reason in err. */
int io_fetch_result(server_case *c, int *fd, size_t *size, int *held, int *http_status,
                    char *err, size_t errlen);
void io_release_hold(server_case *c);
/* Wall seconds a snapshot of a model whose checkpoint is this large takes
 * to write (a result.h5 row with its checkpoint and status, fsynced):
 * the median wall seconds per snapshot of the last runs whose pace their
 * writes set (io_note_paced_run, from the worker as a run ends), else of
 * the last small snapshot jobs, else the seed given at start-up; the
 * size is not charged (io_thread.c says why). */
void io_note_paced_run(double wall, double waited, int snapshots);
double io_snapshot_seconds(double checkpoint_bytes);
void io_seed_snapshot_seconds(double seconds);
/* On the I/O thread only (io_sidecar.c): rewrites result.xdmf of a case
 * whose result.h5 is open, at once (force) or once ten times what its last
 * rewrite took has passed; io_sidecar_catch_up rewrites it if it lists
 * fewer rows than the file holds. */
void io_sidecar_write(server_case *c, int force);
void io_sidecar_catch_up(server_case *c);
/* The I/O thread's own timing of one snapshot job of `bytes` (the
 * checkpoint's size), io_snapshot_cost.c. */
void io_note_snapshot_cost(double seconds, double bytes);

#endif
