/*
 * fdem_rank_main.c - bin/fdem-rank: one MPI rank of a case run on N ranks
 * (contract 6.5), started by a launcher line (launch.h) from bin/fdem-run
 * or the daemon, with fdem-run's arguments (--out, --threads, --ranks,
 * --control stdin). Every rank runs the same batch loop (run_case.h);
 * rank 0 writes the files.
 *
 * The stepper below is the seam to the rank engine (runner/mpi/,
 * rank_engine.h): built with it (the Makefile defines FDEM_RANK_ENGINE
 * when runner/mpi/ has sources), every rank steps its share of the model;
 * built without it, every rank steps the whole model (fdem_step: the same
 * bits on every rank, N times the work). Either way every rank runs the
 * loop, rank 0 writes, and the ranks agree on commands and failures, so
 * the launcher, the daemon's process handling, the files and the
 * collective control flow are the ones the engine runs under.
 */
#include <errno.h>
#include <getopt.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "run_case.h"
#ifdef FDEM_RANK_ENGINE
#include "mpi/rank_engine.h"
#endif

#if defined(__SANITIZE_ADDRESS__)
/* OpenMPI keeps what MPI_Init allocated past MPI_Finalize, in components
 * it has unloaded by then: LeakSanitizer reports it from "<unknown
 * module>" frames no suppression can name, and would fail every sanitizer
 * run of a ranked case. Leak checks stay on for bin/fdem-run, which runs
 * the same loop (run_case.c) without MPI. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "detect_leaks=0";
}
#endif

typedef struct rank_stepper_ctx {
    MPI_Comm comm;
    int rank, size;
#ifdef FDEM_RANK_ENGINE
    rank_engine_lazy engine; /* made at the first step of each model run_case builds */
#endif
} rank_stepper_ctx;

#ifdef FDEM_RANK_ENGINE
static int rank_stepper_step(void *ctx, fdem_model *m, fdem_error *err)
{
    return rank_engine_lazy_step(&((rank_stepper_ctx *)ctx)->engine, m, err);
}

static int rank_stepper_gather(void *ctx, fdem_model *m, fdem_error *err)
{
    return rank_engine_lazy_gather(&((rank_stepper_ctx *)ctx)->engine, m, err);
}
#else
static int rank_stepper_step(void *ctx, fdem_model *m, fdem_error *err)
{
    (void)ctx;
    return fdem_step(m, err);
}

static int rank_stepper_gather(void *ctx, fdem_model *m, fdem_error *err)
{
    (void)ctx;
    (void)m;
    (void)err;
    return 0;
}
#endif

static int rank_stepper_agree(void *ctx, int local)
{
    rank_stepper_ctx *s = ctx;
    int all = local;
    MPI_Allreduce(&local, &all, 1, MPI_INT, MPI_MAX, s->comm);
    return all;
}

/* The other ranks wait for rank 0's last writes in a barrier polled every
 * 20 ms (OpenMPI's blocking calls spin, taking a core from rank 0). */
static void rank_wait_for_writer(MPI_Comm comm)
{
    MPI_Request req;
    int done = 0;
    MPI_Ibarrier(comm, &req);
    while (!done) {
        MPI_Test(&req, &done, MPI_STATUS_IGNORE);
        struct timespec ts = {0, 20 * 1000 * 1000};
        if (!done)
            nanosleep(&ts, NULL);
    }
}

int main(int argc, char **argv)
{
    enum { OPT_CONTROL = 256, OPT_QUIET, OPT_PAUSE_AT };
    static const struct option longs[] = {
        {"out", required_argument, 0, 'o'}, {"ranks", required_argument, 0, 'n'},
        {"threads", required_argument, 0, 'j'}, {"control", required_argument, 0, OPT_CONTROL},
        {"quiet", no_argument, 0, OPT_QUIET}, {"pause-at-step", required_argument, 0, OPT_PAUSE_AT},
        {0, 0, 0, 0},
    };
    run_options o = {.threads = 1, .ranks = 1, .control_fd = -1};
    int c;
    while ((c = getopt_long(argc, argv, "o:n:j:", longs, NULL)) != -1) {
        switch (c) {
        case 'o': o.out_dir = optarg; break;
        case 'n': o.ranks = atoi(optarg); break;
        case 'j': o.threads = atoi(optarg); break;
        case OPT_CONTROL: o.control_fd = strcmp(optarg, "stdin") == 0 ? 0 : -1; break;
        case OPT_QUIET: o.quiet = 1; break;
        case OPT_PAUSE_AT: o.pause_at_step = atoll(optarg); break; /* checked by fdem-run */
        default: return 2;
        }
    }
    if (optind != argc - 1 || !o.out_dir) {
        fprintf(stderr, "usage: fdem-rank CASE.json --out DIR [--threads T] [--ranks N] "
                "[--control stdin] [--pause-at-step S] [--quiet] (started by fdem-run --ranks N or the "
                "daemon)\n");
        return 2;
    }
    o.case_path = argv[optind];
    MPI_Init(&argc, &argv);
    rank_stepper_ctx ctx = {.comm = MPI_COMM_WORLD};
#ifdef FDEM_RANK_ENGINE
    ctx.engine.comm = ctx.comm;
#endif
    MPI_Comm_rank(ctx.comm, &ctx.rank);
    MPI_Comm_size(ctx.comm, &ctx.size);
    o.ranks = ctx.size;
    if (ctx.rank != 0)
        o.control_fd = -1; /* the launcher gives stdin to rank 0 */
    runner_stepper st = {.ctx = &ctx, .step = rank_stepper_step, .gather = rank_stepper_gather,
                         .is_writer = ctx.rank == 0, .agree = rank_stepper_agree};
    int status = run_exit_status(run_case(&o, &st));
#ifdef FDEM_RANK_ENGINE
    rank_engine_lazy_free(&ctx.engine);
#endif
    rank_wait_for_writer(ctx.comm);
    /* every rank ends with rank 0's outcome, which the launcher reports */
    MPI_Bcast(&status, 1, MPI_INT, 0, ctx.comm);
    MPI_Finalize();
    return status;
}
