/*
 * io_sidecar.c - when the I/O thread rewrites result.xdmf (io_thread.h:
 * io_sidecar_write, io_sidecar_catch_up). Apart from io_thread.c because
 * it is a policy of its own, the sidecar's cost against its lag; called
 * on the I/O thread only, which owns c->result and these fields.
 *
 * Rewriting the XDMF costs O(snapshots) (about 30 us a snapshot it lists,
 * for a 2D bar): rewritten after every snapshot, the 161st snapshot of a
 * small case cost 7 ms where the first cost 2, its run's writes twice
 * what the first snapshots of any case said a snapshot costs (the run-time
 * estimate's price of a write, io_snapshot_seconds). So a rewrite waits
 * until SIDECAR_COST_RATIO times what the last one took has passed: the
 * sidecar costs the I/O thread at most a tenth of its time at any size,
 * and lags the file by at most that (a 161-entry sidecar: 40 ms). A case
 * whose snapshots come seldom still gets it after each; the close always
 * writes it, and GET result.xdmf catches it up first.
 */
#include "io_thread.h"

#include <stdio.h>

#include "math/clock.h"
#include "result/result.h"

#define SIDECAR_COST_RATIO 10.0

void io_sidecar_write(server_case *c, int force)
{
    if (!c->result || !c->model)
        return;
    double now = clock_wall_seconds();
    if (!force && now - c->xdmf_written_at < SIDECAR_COST_RATIO * c->xdmf_write_seconds)
        return;
    char path[1200], err[256] = "";
    snprintf(path, sizeof path, "%s/result.xdmf", c->dir);
    if (xdmf_write(path, "result.h5", c->model, &c->info, c->result, err, sizeof err) != 0)
        case_record_io_failure(c, "result.xdmf", err);
    c->xdmf_written_at = clock_wall_seconds();
    c->xdmf_write_seconds = c->xdmf_written_at - now;
    c->xdmf_listed = result_snapshot_count(c->result);
}

void io_sidecar_catch_up(server_case *c)
{
    if (c->result && c->xdmf_listed != result_snapshot_count(c->result))
        io_sidecar_write(c, 1);
}
