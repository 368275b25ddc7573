/*
 * rank_compare.c - steps a case on the ranks it is started on and prints,
 * every `every` steps, a hash of the whole state as rank 0 would write it
 * (the checkpoint bytes after rank_engine_gather: nodes, element history,
 * joints, contact history, energies) and of the energies, plus whether
 * every rank holds the same positions and velocities.
 * tests/integration/test_ranks.py runs it on 1, 2, 3, 4 and 8 ranks and
 * in one plain process (fdem_step, no rank engine) and compares the
 * lines: the same bits or a failure.
 *
 *   rank_compare STEPS EVERY [--plain] [--threads T] [--fault] [--figures]
 *                CASE.json...   (flags apply to the cases after them)
 *
 * --expect-failure: the cases after it must fail (a non-finite step):
 * the run then passes, and its lines say where they failed.
 *
 * --save-at K FILE writes the checkpoint after step K (one file: use it
 * with one case); --restore FILE starts every rank from one, so a run
 * saved on N ranks goes on on M.
 *
 * --fault turns on rank_engine_set_border_order_fault (each rank sums its
 * halo elements after its own blocks): its lines must differ from the
 * plain run's, which shows the comparison can fail. --contact-fault order
 * or rotate splits the contact walk wrongly (rank_engine_set_contact_fault:
 * the ranks' lists applied in reverse rank order, or each rank given
 * another share of the pairs every step): the same. --contact-fault fail
 * makes the last rank's walk fail at step 9 (with --expect-failure: every
 * rank must fail there). --contact-fault skip-sync (skip-gather-sync)
 * leaves out the hand-overs of the springs the walk updates in place
 * (contact_springs_sync) in the steps (at the gather): the lines must
 * differ.
 *
 * --split-threads-min N: a rank's share of the contact walk goes to its
 * threads from N pairs (contact.walk_threads_min; small cases' shares are
 * otherwise too few for threads).
 *
 * With the contact walk split, rank 0 prints to stderr how many near pairs
 * each rank evaluated and how many of its walks went to several threads
 * ("contact pairs walked N0 N1 ... (walks on threads T0 T1 ...): CASE").
 */
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "case/case.h"
#include "model/model.h"
#include "mpi/rank_engine.h"
#include "read_file.h"

static uint64_t fnv1a(const void *data, size_t size, uint64_t h)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < size; i++) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

/* The penetrations rank 0 has taken so far (fdem_take_penetrations): how
 * many and their hash. A split walk's looks are made by the rank walking
 * a pair and handed to all (core/contact/contact_walk_split.c); they are
 * an observation, not in the checkpoint, so they are compared here. */
static long deep_count;
static uint64_t deep_hash = 1469598103934665603ull;

static void take_penetrations(fdem_model *m)
{
    fdem_penetration p[64];
    long more;
    int n;
    do { /* `more` counts those past the kept list, once; a call that takes
          * nothing leaves the hash alone (lines are printed at other steps
          * on some runs: --save-at) */
        n = fdem_take_penetrations(m, p, 64, &more);
        if (!n && !more) break;
        deep_hash = fnv1a(p, sizeof *p * (size_t)n, deep_hash);
        deep_hash = fnv1a(&more, sizeof more, deep_hash);
        deep_count += n + more;
    } while (n == 64);
}

/* The hash of the checkpoint (rank 0) and of the energies. */
static void print_state(fdem_model *m, int step)
{
    size_t size = fdem_checkpoint_size(m);
    void *buf = malloc(size);
    if (!buf || fdem_checkpoint_write(m, buf, size)) {
        printf("step %d checkpoint failed\n", step);
        free(buf);
        return;
    }
    fdem_energy en = fdem_get_energy(m);
    fdem_counts c = fdem_get_counts(m);
    take_penetrations(m);
    printf("step %d state %016llx energy %016llx elastic %.17g kinetic %.17g broken %d "
           "contacts %d deep %ld %016llx\n", step,
           (unsigned long long)fnv1a(buf, size, 1469598103934665603ull),
           (unsigned long long)fnv1a(&en, sizeof en, 1469598103934665603ull), en.elastic,
           en.kinetic, c.broken_joints, c.contacts, deep_count, (unsigned long long)deep_hash);
    free(buf);
}

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* This process's peak resident memory, bytes (Linux; 0 elsewhere). */
static double peak_bytes(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    double kb = 0;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "VmHWM:", 6)) kb = atof(line + 6);
    if (f) fclose(f);
    return kb * 1024;
}

/* Whether every rank holds, of every node it keeps (mark; NULL: all),
 * the position and velocity rank 0 holds after the gather. */
static int ranks_agree(const fdem_model *m, const uint8_t *mark, MPI_Comm comm)
{
    fdem_counts c = fdem_get_counts(m);
    const size_t D = (size_t)c.dimension, n = D * (size_t)c.nodes;
    double *x = malloc(sizeof(double) * (2 * n + 1));
    int rank, same = x != NULL;
    MPI_Comm_rank(comm, &rank);
    MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_MIN, comm);
    if (!same) return free(x), 0;
    if (rank == 0) {
        memcpy(x, fdem_positions(m), sizeof(double) * n);
        memcpy(x + n, fdem_velocities(m), sizeof(double) * n);
    }
    MPI_Bcast(x, (int)(2 * n), MPI_DOUBLE, 0, comm);
    const double *pos = fdem_positions(m), *vel = fdem_velocities(m);
    for (int i = 0; i < c.nodes; i++)
        if (!mark || mark[i])
            same &= !memcmp(pos + D * i, x + D * i, sizeof(double) * D) &&
                    !memcmp(vel + D * i, x + n + D * i, sizeof(double) * D);
    free(x);
    MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_MIN, comm);
    return same;
}

typedef struct compare_options {
    int steps, every, plain, fault, threads, figures;
    int contact_fault;        /* RANK_CONTACT_FAULT_*: a wrong split of the contact walk */
    int split_threads_min;    /* contact.walk_threads_min: threads inside a rank's share */
    int expect_failure;       /* the cases must fail at some step (and then pass) */
    int save_at;              /* the step after which rank 0 writes save_path; 0: none */
    const char *save_path;
    const char *restore_path; /* a checkpoint every rank starts from; NULL: step 0 */
} compare_options;

/* Rank 0 writes the model's checkpoint (after rank_engine_gather). */
static int save_checkpoint(const fdem_model *m, const char *path)
{
    size_t size = fdem_checkpoint_size(m);
    void *buf = malloc(size);
    FILE *f = buf ? fopen(path, "wb") : NULL;
    int rc = !f || fdem_checkpoint_write(m, buf, size) || fwrite(buf, 1, size, f) != size;
    if (f && fclose(f)) rc = 1;
    free(buf);
    return rc;
}

/* Every rank reads the same checkpoint into its model. */
static int restore_checkpoint(fdem_model *m, const char *path, fdem_error *err)
{
    size_t size;
    char *buf = read_text(path, &size);
    int rc = !buf || fdem_checkpoint_read(m, buf, size, err);
    free(buf);
    return rc;
}

/* Steps one case; prints its lines (rank 0). Returns nonzero on failure. */
static int run_case(const char *path, const compare_options *o, int rank, int size)
{
    const int steps = o->steps, every = o->every, plain = o->plain, figures = o->figures;
    size_t length;
    char *text = read_text(path, &length);
    problems out;
    problems_init(&out);
    case_info info;
    double t0 = MPI_Wtime();
    fdem_model *m = text ? case_build(text, length, (size_t)1 << 36, &info, &out) : NULL;
    free(text);
    if (!m) {
        fprintf(stderr, "rank %d: %s does not build: %s\n", rank, path,
                out.count ? out.items[0].message : "unreadable");
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    problems_free(&out);
    fdem_set_threads(m, o->threads);
    m->contact.walk_threads_min = o->split_threads_min;
    double t_build = MPI_Wtime() - t0;
    fdem_error err = {0};
    if (o->restore_path && restore_checkpoint(m, o->restore_path, &err)) {
        fprintf(stderr, "rank %d: %s does not restore: %s\n", rank, o->restore_path, err.message);
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    const int first = (int)fdem_get_step(m) + 1; /* after a restore, the step it holds */
    const int stepped = steps - first + 1; /* the figures are per step stepped */
    /* the batch loop's way (made at the first step), but for the fault,
     * which is set before it, and the figures, which time steps only */
    rank_engine_lazy lazy = {MPI_COMM_WORLD, NULL, NULL};
    double t_setup = MPI_Wtime();
    if (!plain && (o->fault || o->contact_fault || figures)) {
        if (!(lazy.re = rank_engine_create(m, MPI_COMM_WORLD, &err))) {
            fprintf(stderr, "rank %d: %s\n", rank, err.message);
            MPI_Abort(MPI_COMM_WORLD, 2);
        }
        lazy.model = m;
        if (o->fault) rank_engine_set_border_order_fault(lazy.re, 1);
        if (o->contact_fault) rank_engine_set_contact_fault(lazy.re, o->contact_fault);
    }
    t_setup = MPI_Wtime() - t_setup;
    if (rank == 0) printf("case %s\n", path);
    deep_count = 0;
    deep_hash = 1469598103934665603ull;
    int status = 0;
    double t_step = 0, c_step = 0;
    int told = 0;
    for (int s = first; s <= steps && !status; s++) {
        double ts = MPI_Wtime(), cs = cpu_seconds();
        int rc = plain ? fdem_step(m, &err) : rank_engine_lazy_step(&lazy, m, &err);
        t_step += MPI_Wtime() - ts;
        c_step += cpu_seconds() - cs;
        if (rc) {
            if (rank == 0) printf("step %d failed: %s\n", s, err.message);
            status = 1;
            break;
        }
        if (s % every && s != steps && s != o->save_at) continue;
        if (!plain && rank_engine_lazy_gather(&lazy, m, &err)) status = 1;
        int agree = plain || ranks_agree(m, lazy.re ? rank_engine_node_mark(lazy.re) : NULL,
                                         MPI_COMM_WORLD);
        if (!plain && !told++ && rank == 0) /* which update ran, for the test */
            fprintf(stderr, "update %s: %s\n",
                    lazy.re && rank_engine_figures(lazy.re).split_update ? "split" : "replicated",
                    path);
        if (rank == 0) {
            if (!agree) printf("step %d ranks disagree\n", s);
            print_state(m, s);
            if (s == o->save_at && save_checkpoint(m, o->save_path)) status = 1;
        }
    }
    if (lazy.re && rank_engine_figures(lazy.re).contact_split) {
        /* how many near pairs each rank evaluated, for the test: each
         * rank's share of the split walk */
        long walked[2] = {rank_engine_figures(lazy.re).contact_pairs_walked,
                          m->contact.split_threaded};
        long *each = rank == 0 ? malloc(sizeof(long) * 2 * (size_t)size) : NULL;
        MPI_Gather(walked, 2, MPI_LONG, each, 2, MPI_LONG, 0, MPI_COMM_WORLD);
        if (rank == 0 && each) {
            fprintf(stderr, "contact pairs walked");
            for (int r = 0; r < size; r++) fprintf(stderr, " %ld", each[2 * r]);
            fprintf(stderr, " (walks on threads");
            for (int r = 0; r < size; r++) fprintf(stderr, " %ld", each[2 * r + 1]);
            fprintf(stderr, "): %s\n", path);
        }
        free(each);
    }
    if (figures && lazy.re) {
        rank_figures f = rank_engine_figures(lazy.re);
        double most = f.bytes_sent_per_step, step_s = t_step / stepped;
        MPI_Allreduce(MPI_IN_PLACE, &most, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        MPI_Allreduce(MPI_IN_PLACE, &step_s, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        /* work: the CPU outside the exchanges, where MPI polls for a
         * partner (load-independent where the CPU a step is not) */
        fprintf(stderr, "rank %d: blocks %d of %d, elements owned %ld computed %ld (halo %.3f), "
                "nodes owned %ld kept %ld (update %s), bytes sent/step %.0f, "
                "partition %.4f s, engine set-up %.2f s, build %.2f s, step %.6f s (cpu %.6f s, "
                "exchanges %.6f s, cpu there %.6f s: work %.6f s), peak %.0f bytes/element, "
                "contact pairs walked/step %.0f, contact bytes sent/step %.0f "
                "(springs handed over %.0f)\n",
                rank, f.owned_blocks, f.blocks, f.owned_elements, f.computed_elements,
                f.owned_elements ? (double)(f.computed_elements - f.owned_elements) /
                                       (double)f.owned_elements : 0.0,
                f.owned_nodes, f.kept_nodes, f.split_update ? "split" : "replicated",
                f.bytes_sent_per_step, f.partition_seconds, t_setup, t_build, t_step / stepped,
                c_step / stepped, f.exchange_seconds / stepped, f.exchange_cpu_seconds / stepped,
                (c_step - f.exchange_cpu_seconds) / stepped,
                peak_bytes() / fdem_get_counts(m).elements,
                (double)f.contact_pairs_walked / stepped,
                f.contact_bytes_sent / stepped, f.contact_sync_bytes_sent / stepped);
        if (rank == 0)
            printf("figures ranks %d step_s %.6f max_bytes_sent_per_step %.0f\n", size, step_s,
                   most);
    }
    if (figures && rank == 0) {
        fdem_stage_times st = fdem_get_stage_times(m);
        printf("stages per step (s): elements %.6f joints %.6f detection %.6f contact %.6f "
               "integration %.6f, all %.6f (cpu %.6f)\n", st.elements / stepped,
               st.joints / stepped, st.detection / stepped, st.contact / stepped,
               st.integration / stepped, t_step / stepped, c_step / stepped);
    if (figures && rank == 0 && m->contact.enabled)
        printf("contact: %ld detections, %ld near-list builds, %ld hand-overs of springs in "
               "all\n", m->contact.detections, m->contact.near_builds, m->contact.springs_synced);
    }
    rank_engine_lazy_free(&lazy);
    fdem_model_destroy(m);
    return status;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int rank, size;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (argc < 4) {
        if (rank == 0) fprintf(stderr, "usage: rank_compare STEPS EVERY [--plain] [--threads T] "
                                       "[--fault] [--contact-fault order|rotate|fail|skip-sync|skip-gather-sync] [--figures] "
                                       "[--split-threads-min N] "
                                       "[--save-at K FILE] [--restore FILE] "
                                       "CASE.json...\n");
        MPI_Finalize();
        return 2;
    }
    compare_options o = {.steps = atoi(argv[1]), .every = atoi(argv[2]), .threads = 1};
    int status = 0;
    if (o.steps < 1 || o.every < 1) MPI_Abort(MPI_COMM_WORLD, 2);
    for (int i = 3; i < argc; i++) {
        if (!strcmp(argv[i], "--plain")) o.plain = 1;
        else if (!strcmp(argv[i], "--fault")) o.fault = 1;
        else if (!strcmp(argv[i], "--split-threads-min") && i + 1 < argc)
            o.split_threads_min = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--contact-fault") && i + 1 < argc) {
            const char *kind = argv[++i];
            o.contact_fault = !strcmp(kind, "order")    ? RANK_CONTACT_FAULT_ORDER
                              : !strcmp(kind, "rotate") ? RANK_CONTACT_FAULT_ROTATE
                              : !strcmp(kind, "fail")   ? RANK_CONTACT_FAULT_FAIL
                              : !strcmp(kind, "skip-sync") ? RANK_CONTACT_FAULT_SKIP_SYNC
                              : !strcmp(kind, "skip-gather-sync")
                                  ? RANK_CONTACT_FAULT_SKIP_GATHER_SYNC
                                  : -1;
            if (o.contact_fault < 0) MPI_Abort(MPI_COMM_WORLD, 2);
        }
        else if (!strcmp(argv[i], "--expect-failure")) o.expect_failure = 1;
        else if (!strcmp(argv[i], "--figures")) o.figures = 1;
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc) o.threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--save-at") && i + 2 < argc) {
            o.save_at = atoi(argv[++i]);
            o.save_path = argv[++i];
        } else if (!strcmp(argv[i], "--restore") && i + 1 < argc) o.restore_path = argv[++i];
        else if (o.expect_failure) { /* its lines say where it failed; not failing fails */
            int failed = run_case(argv[i], &o, rank, size);
            if (!failed && rank == 0) printf("no step failed\n");
            status |= !failed;
        } else status |= run_case(argv[i], &o, rank, size);
    }
    MPI_Finalize();
    return status;
}
