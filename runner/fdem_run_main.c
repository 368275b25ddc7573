/*
 * fdem_run_main.c - bin/fdem-run: a case run without a daemon (contract
 * 6.5), for batch jobs. One rank runs in this process (run_case.h); more
 * replace this process with the launcher line and bin/fdem-rank (launch.h),
 * which write the same directory.
 */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "launch.h"
#include "run_case.h"

static void usage(FILE *to)
{
    fprintf(to,
            "usage: fdem-run CASE.json --out DIR [--ranks N] [--threads T]\n"
            "                [--launcher LINE] [--control stdin] [--pause-at-step S] [--quiet]\n"
            "Runs CASE.json to its end and writes DIR as a daemon's case directory:\n"
            "case.json, result.h5, result.xdmf, checkpoint.bin, status.json.\n"
            "A DIR holding case.json and checkpoint.bin is resumed from its checkpoint.\n"
            "  --ranks N        N MPI ranks: runs LINE with bin/fdem-rank (default 1: this process)\n"
            "  --threads T      OpenMP threads per rank (default 1); results do not depend on it\n"
            "  --launcher LINE  the command that starts N ranks, {ranks} replaced by N\n"
            "                   (default: $FDEM_LAUNCHER, else \"%s\")\n"
            "  --control stdin  read \"pause\"/\"stop\" lines on stdin; its end pauses\n"
            "  --pause-at-step S  pause (checkpoint and exit 3) at step S; run again to go on\n"
            "SIGTERM or SIGINT pause at the next step with a checkpoint.\n"
            "Exit status: 0 finished, 3 paused, 4 stopped, 1 failed, 2 invalid case or usage.\n",
            LAUNCH_DEFAULT);
}

static int parse_positive(const char *s, int *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || !end || *end || v < 1 || v > 2147483647L)
        return -1;
    *out = (int)v;
    return 0;
}

/* Replaces this process with the launcher line running bin/fdem-rank. */
static int run_ranks(const run_options *o, const char *launcher, int control)
{
    char rank_bin[4096], threads[16], ranks[16], err[300];
    if (launch_rank_binary(rank_bin, sizeof rank_bin) != 0) {
        fprintf(stderr, "fdem-run: bin/fdem-rank is not beside fdem-run: build it with `make "
                "all` where mpicc is installed (Debian: openmpi-bin libopenmpi-dev)\n");
        return 1;
    }
    char pause[24];
    snprintf(threads, sizeof threads, "%d", o->threads);
    snprintf(ranks, sizeof ranks, "%d", o->ranks);
    snprintf(pause, sizeof pause, "%lld", o->pause_at_step);
    /* every option a rank's loop reads goes on to fdem-rank: --pause-at-step
     * was left behind, and ranked runs went on to their end */
    const char *extra[16] = {rank_bin, o->case_path, "--out", o->out_dir, "--threads", threads,
                             "--ranks", ranks};
    int k = 8;
    if (control)
        extra[k++] = "--control", extra[k++] = "stdin";
    if (o->pause_at_step > 0)
        extra[k++] = "--pause-at-step", extra[k++] = pause;
    if (o->quiet)
        extra[k++] = "--quiet";
    extra[k] = NULL;
    char **argv = launch_argv(launcher, o->ranks, extra, err, sizeof err);
    if (!argv) {
        fprintf(stderr, "fdem-run: %s\n", err);
        return 2;
    }
    char *asan = launch_rank_asan_options();
    if (asan)
        putenv(asan); /* kept: the environment owns it until exec */
    execvp(argv[0], argv);
    fprintf(stderr, "fdem-run: cannot start the launcher \"%s\": %s; install it (Debian: "
            "openmpi-bin) or name another with --launcher or FDEM_LAUNCHER\n", argv[0],
            strerror(errno));
    launch_argv_free(argv);
    return 127;
}

int main(int argc, char **argv)
{
    enum { OPT_LAUNCHER = 256, OPT_CONTROL, OPT_QUIET, OPT_PAUSE_AT };
    static const struct option longs[] = {
        {"out", required_argument, 0, 'o'}, {"ranks", required_argument, 0, 'n'},
        {"threads", required_argument, 0, 'j'}, {"launcher", required_argument, 0, OPT_LAUNCHER},
        {"control", required_argument, 0, OPT_CONTROL}, {"quiet", no_argument, 0, OPT_QUIET},
        {"pause-at-step", required_argument, 0, OPT_PAUSE_AT}, {"help", no_argument, 0, 'h'}, {0, 0, 0, 0},
    };
    run_options o = {.threads = 1, .ranks = 1, .control_fd = -1};
    const char *launcher = getenv("FDEM_LAUNCHER");
    int c;
    while ((c = getopt_long(argc, argv, "o:n:j:h", longs, NULL)) != -1) {
        switch (c) {
        case 'o': o.out_dir = optarg; break;
        case 'n':
            if (parse_positive(optarg, &o.ranks) != 0) {
                fprintf(stderr, "fdem-run: --ranks takes a positive integer\n");
                return 2;
            }
            break;
        case 'j':
            if (parse_positive(optarg, &o.threads) != 0) {
                fprintf(stderr, "fdem-run: --threads takes a positive integer\n");
                return 2;
            }
            break;
        case OPT_LAUNCHER: launcher = optarg; break;
        case OPT_CONTROL:
            if (strcmp(optarg, "stdin") != 0) {
                fprintf(stderr, "fdem-run: --control takes \"stdin\"\n");
                return 2;
            }
            o.control_fd = 0;
            break;
        case OPT_QUIET: o.quiet = 1; break;
        case OPT_PAUSE_AT: {
            int step = 0;
            if (parse_positive(optarg, &step) != 0) {
                fprintf(stderr, "fdem-run: --pause-at-step takes a positive step number\n");
                return 2;
            }
            o.pause_at_step = step;
            break;
        }
        case 'h': usage(stdout); return 0;
        default: usage(stderr); return 2;
        }
    }
    if (optind != argc - 1 || !o.out_dir) {
        usage(stderr);
        return 2;
    }
    o.case_path = argv[optind];
    if (o.ranks > 1)
        return run_ranks(&o, launcher && launcher[0] ? launcher : LAUNCH_DEFAULT,
                         o.control_fd == 0);
    return run_exit_status(run_case(&o, NULL));
}
