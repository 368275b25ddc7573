/*
 * io_snapshot_cost.c - what a snapshot write costs on this machine's disk,
 * for the estimate of a case's run time (io_thread.h: io_snapshot_seconds).
 *
 * The I/O thread times each snapshot job it runs (io_note_snapshot_cost)
 * and a worker reports each run whose pace its writes set
 * (io_note_paced_run); a dry run asks for the price of one more. Apart from
 * io_thread.c because it is the estimate's bookkeeping, not the writing:
 * one lock, a few rings of samples, no HDF5.
 */
#include "io_thread.h"

#include "common/sample_ring.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* Wall seconds a snapshot takes to become durable here (result.h5 row,
 * checkpoint.bin and status.json, fsynced): what a dry run charges per
 * snapshot, as latency + bytes x seconds per byte (the checkpoint's bytes
 * stand for the job's size: the row grows with the same model), both from
 * recent snapshot jobs: the latency from the small ones (where the fsyncs
 * are all of it), the seconds per byte from the
 * large ones, less the latency: each the median of the last
 * SAMPLE_RING_SIZE. One moving average of every job priced a 2D collision's
 * 3 KB snapshots at the 0.1 s the large 3D jobs before it took, five times
 * its run, and one write the disk held up for seconds priced a small 3D
 * case's 76 snapshots at 68 s. */
#define IO_SMALL_JOB_BYTES 262144.0
static pthread_mutex_t io_cost_lock = PTHREAD_MUTEX_INITIALIZER;
static sample_ring io_latency_samples, io_rate_samples, io_paced_samples;
static double io_latency_seed;

void io_note_snapshot_cost(double seconds, double bytes)
{
    pthread_mutex_lock(&io_cost_lock);
    if (bytes < IO_SMALL_JOB_BYTES) {
        sample_ring_add(&io_latency_samples, seconds);
    } else {
        double latency = sample_ring_median(&io_latency_samples, io_latency_seed);
        sample_ring_add(&io_rate_samples, (seconds > latency ? seconds - latency : 0.0) / bytes);
    }
    pthread_mutex_unlock(&io_cost_lock);
}

void io_seed_snapshot_seconds(double seconds)
{
    pthread_mutex_lock(&io_cost_lock);
    io_latency_seed = seconds;
    pthread_mutex_unlock(&io_cost_lock);
}

/* Runs whose pace the snapshot writes set (the worker waited for them
 * over a third of its wall time): wall seconds per snapshot, all the I/O
 * thread did for each included (the XDMF sidecar, the status, the history
 * rows besides the snapshot job). Timing the snapshot job alone priced
 * such runs at a fifth of what they took. */
#define IO_PACED_SHARE 0.33
#define IO_PACED_MIN_SNAPSHOTS 10

void io_note_paced_run(double wall, double waited, int snapshots)
{
    if (snapshots < IO_PACED_MIN_SNAPSHOTS || !(waited > IO_PACED_SHARE * wall))
        return;
    pthread_mutex_lock(&io_cost_lock);
    sample_ring_add(&io_paced_samples, wall / snapshots);
    pthread_mutex_unlock(&io_cost_lock);
}

double io_snapshot_seconds(double bytes)
{
    pthread_mutex_lock(&io_cost_lock);
    double seconds = sample_ring_median(&io_latency_samples, io_latency_seed);
    if (io_paced_samples.count > 0)
        seconds = sample_ring_median(&io_paced_samples, seconds);
    /* the rate is kept but not charged: on a disk other processes keep
     * busy, large writes stalled for seconds at random and priced a 3D
     * collision's 76 snapshots of 300 KB at 20 to 36 s, which took 2.5 s;
     * a model whose snapshots are that large steps for longer anyway */
    (void)bytes;
    pthread_mutex_unlock(&io_cost_lock);
    return seconds;
}
