/*
 * worker_ranked.c - a case on N MPI ranks, launched and followed by its
 * worker thread (worker_ranked.h).
 *
 * The ranks are bin/fdem-rank processes running runner/run_case.c's loop
 * on the case directory, so the files are written by the same proto/
 * writers as a one-process case's, and a ranked case's results routes read
 * them from disk as they read any case's. The daemon keeps no model and
 * no open result.h5 while they run; it reads their status.json for the
 * figures it shows.
 */
#include "worker_ranked.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "case_model.h"
#include "eta_window.h"
#include "files/persist.h"
#include "io_thread.h"
#include "launch.h"
#include "math/clock.h"
#include "registry_internal.h"

extern char **environ;

#define RANKED_POLL_SECONDS 0.05   /* between looks at the ranks and their status */
#define RANKED_LOG "ranks.log"
/* The process group of the ranks last launched for this case, while they
 * run: a daemon killed under them does not see them end (they checkpoint
 * and exit on the pipe's end of file), so the next launch waits for them. */
#define RANKED_PID "ranks.pid"
#define RANKED_EARLIER_WAIT_SECONDS 30

/* Exit statuses of bin/fdem-rank (runner/run_case.h: run_exit_status). */
enum { RANKED_FINISHED = 0, RANKED_FAILED = 1, RANKED_BAD_CASE = 2, RANKED_PAUSED = 3,
       RANKED_STOPPED = 4, RANKED_NOT_STARTED = 127 };

/* environ plus what mpirun needs to run as root (a container's daemon):
 * OpenMPI refuses root otherwise, and the refusal would fail every
 * ranked case. NULL without memory. */
static char **ranked_environment(void)
{
    static const char *const added[] = {"OMPI_ALLOW_RUN_AS_ROOT=1",
                                        "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1"};
    size_t n = 0;
    while (environ[n])
        n++;
    char **env = calloc(n + 4, sizeof *env);
    if (!env)
        return NULL;
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (strncmp(environ[i], "OMPI_ALLOW_RUN_AS_ROOT", 22) != 0 &&
            strncmp(environ[i], "ASAN_OPTIONS=", 13) != 0)
            env[k++] = environ[i];
    env[k++] = (char *)added[0];
    env[k++] = (char *)added[1];
    char *asan = launch_rank_asan_options(); /* freed with env (ranked_environment_free) */
    if (asan)
        env[k++] = asan;
    return env;
}

/* env of ranked_environment: only its last entry, the ASAN_OPTIONS it made,
 * is its own. */
static void ranked_environment_free(char **env)
{
    if (!env)
        return;
    size_t n = 0;
    while (env[n])
        n++;
    if (n > 0 && strncmp(env[n - 1], "ASAN_OPTIONS=", 13) == 0)
        free(env[n - 1]);
    free(env);
}

static void ranked_set_error(server_case *c, const char *message)
{
    pthread_mutex_lock(&c->lock);
    snprintf(c->error, sizeof c->error, "%s", message);
    pthread_mutex_unlock(&c->lock);
}

/* A pipe whose ends close on exec: no other child of the daemon keeps the
 * ranks' stdin open (their end of file is the daemon's death). */
static int ranked_pipe(int fds[2])
{
    if (pipe(fds) != 0)
        return -1;
    fcntl(fds[0], F_SETFD, FD_CLOEXEC);
    fcntl(fds[1], F_SETFD, FD_CLOEXEC);
    return 0;
}

/* Starts the launcher line with bin/fdem-rank in its own process group,
 * stdin the read end of a pipe whose write end goes to *control, output to
 * ranks.log. The pid, or -1 with c->error set. */
static pid_t ranked_spawn(server_case *c, int *control)
{
    const fdemd_config *cfg = registry_config();
    char rank_bin[4096], threads[16], ranks[16], case_path[1200], err[300];
    if (launch_rank_binary(rank_bin, sizeof rank_bin) != 0) {
        ranked_set_error(c, "this daemon has no bin/fdem-rank beside it: build it with `make "
                         "all` where mpicc is installed (Debian: openmpi-bin libopenmpi-dev), "
                         "or run the case with \"ranks\": 1");
        return -1;
    }
    snprintf(threads, sizeof threads, "%d", cfg->threads);
    snprintf(ranks, sizeof ranks, "%d", c->info.ranks);
    snprintf(case_path, sizeof case_path, "%s/case.json", c->dir);
    const char *extra[] = {rank_bin, case_path, "--out", c->dir, "--threads", threads,
                           "--ranks", ranks, "--control", "stdin", "--quiet", NULL};
    char **argv = launch_argv(cfg->launcher, c->info.ranks, extra, err, sizeof err);
    if (!argv) {
        char message[400];
        snprintf(message, sizeof message, "%s (fdemd --launcher)", err);
        ranked_set_error(c, message);
        return -1;
    }
    char log_path[1200];
    snprintf(log_path, sizeof log_path, "%s/%s", c->dir, RANKED_LOG);
    int fds[2] = {-1, -1};
    char **env = ranked_environment();
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t attr;
    posix_spawn_file_actions_init(&fa);
    posix_spawnattr_init(&attr);
    pid_t pid = -1;
    int rc = env && ranked_pipe(fds) == 0 ? 0 : errno ? errno : ENOMEM;
    if (rc == 0) {
        posix_spawn_file_actions_adddup2(&fa, fds[0], 0);
        posix_spawn_file_actions_addopen(&fa, 1, log_path, O_WRONLY | O_CREAT | O_APPEND, 0644);
        posix_spawn_file_actions_adddup2(&fa, 1, 2);
        /* its own group: a stop or delete signals the launcher and the
         * ranks it forked, and a terminal's ^C to the daemon does not */
        posix_spawnattr_setpgroup(&attr, 0);
        /* the daemon blocks SIGTERM and SIGINT (main.c waits for them) and
         * ignores SIGPIPE; a child would inherit both, and mpirun with
         * SIGTERM blocked never ends its ranks on a delete */
        sigset_t none, defaults;
        sigemptyset(&none);
        sigemptyset(&defaults);
        sigaddset(&defaults, SIGTERM);
        sigaddset(&defaults, SIGINT);
        sigaddset(&defaults, SIGPIPE);
        posix_spawnattr_setsigmask(&attr, &none);
        posix_spawnattr_setsigdefault(&attr, &defaults);
        posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK |
                                 POSIX_SPAWN_SETSIGDEF);
        rc = posix_spawnp(&pid, argv[0], &fa, &attr, argv, env);
    }
    if (rc != 0) {
        char message[600];
        if (rc == ENOENT)
            snprintf(message, sizeof message, "the launcher \"%.200s\" was not found: install "
                     "OpenMPI (Debian: openmpi-bin), give fdemd a --launcher line that works "
                     "on this machine, or run the case with \"ranks\": 1", argv[0]);
        else
            snprintf(message, sizeof message, "the launcher \"%.200s\" could not be started "
                     "(%s): check fdemd --launcher", argv[0], strerror(rc));
        ranked_set_error(c, message);
        pid = -1;
    }
    if (fds[0] >= 0)
        close(fds[0]);
    if (pid < 0 && fds[1] >= 0)
        close(fds[1]);
    *control = pid < 0 ? -1 : fds[1];
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&attr);
    ranked_environment_free(env);
    launch_argv_free(argv);
    return pid;
}

/* The ranks' status.json into the case's figures, when it changed; the
 * eta from the simulated time it shows, as the worker's (eta_window.h). */
static void ranked_follow_status(server_case *c, struct timespec *seen, eta_window *eta)
{
    char path[1200];
    struct stat st;
    snprintf(path, sizeof path, "%s/status.json", c->dir);
    if (stat(path, &st) != 0 || (st.st_mtim.tv_sec == seen->tv_sec &&
                                 st.st_mtim.tv_nsec == seen->tv_nsec))
        return;
    *seen = st.st_mtim;
    json_t *o = json_load_file(path, 0, NULL);
    if (!o)
        return; /* replaced while read: the next look finds it whole */
    case_figures f;
    memset(&f, 0, sizeof f);
    status_figures_from_json(&f, o);
    f.counts.dimension = f.counts.dimension ? f.counts.dimension : 2;
    const json_t *sps = json_object_get(o, "steps_per_second");
    f.steps_per_second = json_is_number(sps) ? json_number_value(sps) : 0.0;
    f.eta = eta_window_take(eta, clock_wall_seconds(), f.time, c->info.end_time);
    f.cpu_share = NAN;
    const char *error = json_string_value(json_object_get(o, "error"));
    if (error && error[0]) {
        pthread_mutex_lock(&c->lock);
        snprintf(c->error, sizeof c->error, "%s", error);
        pthread_mutex_unlock(&c->lock);
    }
    json_decref(o);
    case_publish(c, &f);
}

/* Whether a line of ranks.log says something (mpirun frames its messages
 * in lines of dashes). */
static int ranked_line_says_something(const char *line, size_t length)
{
    for (size_t i = 0; i < length; i++)
        if (line[i] != '-' && line[i] != ' ' && line[i] != '\t' && line[i] != '\r')
            return 1;
    return 0;
}

/* The last line of ranks.log that says something, for an error that names
 * what went wrong. */
static void ranked_log_tail(server_case *c, char *out, size_t size)
{
    char path[1200], buf[4096];
    snprintf(path, sizeof path, "%s/%s", c->dir, RANKED_LOG);
    out[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    if (fseek(f, -(long)(sizeof buf - 1), SEEK_END) != 0)
        rewind(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    size_t end = n;
    while (end > 0) {
        size_t start = end;
        while (start > 0 && buf[start - 1] != '\n')
            start--;
        if (ranked_line_says_something(buf + start, end - start)) {
            size_t keep = end - start < size ? end - start : size - 1;
            memcpy(out, buf + start, keep);
            out[keep] = '\0';
            return;
        }
        end = start > 0 ? start - 1 : 0;
    }
}

static void ranked_send(int control, const char *line)
{
    if (control >= 0 && write(control, line, strlen(line)) < 0)
        fprintf(stderr, "fdemd: a ranked case's control pipe: %s\n", strerror(errno));
}

/* The state the ranks' exit status means; a failure gets a sentence. */
static case_state ranked_outcome(server_case *c, int status)
{
    if (WIFEXITED(status)) {
        switch (WEXITSTATUS(status)) {
        case RANKED_FINISHED: return CASE_FINISHED;
        case RANKED_PAUSED: return CASE_PAUSED;
        case RANKED_STOPPED: return CASE_STOPPED;
        default: break;
        }
    }
    pthread_mutex_lock(&c->lock);
    int explained = c->error[0] != '\0';
    pthread_mutex_unlock(&c->lock);
    if (explained)
        return CASE_FAILED;
    char tail[300];
    ranked_log_tail(c, tail, sizeof tail);
    const fdemd_config *cfg = registry_config();
    char how[64];
    if (WIFEXITED(status))
        snprintf(how, sizeof how, "exit status %d", WEXITSTATUS(status));
    else
        snprintf(how, sizeof how, "signal %d", WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    pthread_mutex_lock(&c->lock);
    snprintf(c->error, sizeof c->error, "the %d ranks ended with %s before the case ended "
             "(launcher \"%.200s\"); ranks.log in the case directory says: %.300s",
             c->info.ranks, how, cfg->launcher, tail[0] ? tail : "(nothing)");
    pthread_mutex_unlock(&c->lock);
    return CASE_FAILED;
}

static void ranked_sleep(double seconds)
{
    struct timespec ts = {0, (long)(seconds * 1e9)};
    nanosleep(&ts, NULL);
}

static void ranked_pid_path(const server_case *c, char *out, size_t size)
{
    snprintf(out, size, "%s/%s", c->dir, RANKED_PID);
}

/* Ranks of an earlier daemon may still be writing their checkpoint and
 * closing result.h5 after status.json said "paused" (the pipe's end of
 * file reached them when that daemon died): new ranks started then would
 * find the file locked. Wait (bounded) until their process group is gone;
 * a group id reused by something else is only waited for, never
 * signalled. */
static void ranked_wait_for_earlier(server_case *c)
{
    char path[1200];
    ranked_pid_path(c, path, sizeof path);
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    long group = 0;
    int read = fscanf(f, "%ld", &group);
    fclose(f);
    if (read != 1 || group <= 1)
        return;
    double waited = 0;
    while (kill(-(pid_t)group, 0) == 0 && waited < RANKED_EARLIER_WAIT_SECONDS) {
        ranked_sleep(RANKED_POLL_SECONDS);
        waited += RANKED_POLL_SECONDS;
    }
    if (waited > 0)
        case_log(c, "waited %.1f s for the ranks of an earlier run (process group %ld) to end%s",
                 waited, group, kill(-(pid_t)group, 0) == 0 ? ": they still run" : "");
}

static void ranked_note_group(server_case *c, pid_t pid)
{
    char text[32];
    int n = snprintf(text, sizeof text, "%ld\n", (long)pid);
    if (persist_write_atomic(c->dir, RANKED_PID, text, (size_t)n) != 0)
        case_log(c, "could not write %s/%s: a later launch will not wait for these ranks",
                 c->dir, RANKED_PID);
}

case_state worker_ranked_run(server_case *c)
{
    /* the start's checks are done: the ranks own the files from here */
    case_model_free(c);
    pthread_mutex_lock(&c->lock);
    c->error[0] = '\0';
    pthread_mutex_unlock(&c->lock);
    int control = -1;
    ranked_wait_for_earlier(c);
    pid_t pid = ranked_spawn(c, &control);
    if (pid < 0) {
        case_log(c, "its ranks could not be started: %s", c->error);
        return CASE_FAILED;
    }
    ranked_note_group(c, pid);
    atomic_store(&c->ranks_running, 1);
    case_log(c, "started on %d ranks (process group %d)", c->info.ranks, (int)pid);
    struct timespec seen = {0, 0};
    eta_window eta;
    memset(&eta, 0, sizeof eta);
    int sent = WORKER_GO, status = 0;
    for (;;) {
        pid_t done = waitpid(pid, &status, WNOHANG);
        if (done == pid || (done < 0 && errno != EINTR))
            break;
        ranked_follow_status(c, &seen, &eta);
        int cmd = atomic_load(&c->command);
        if (cmd != sent && cmd == WORKER_PAUSE)
            ranked_send(control, "pause\n");
        else if (cmd != sent && cmd == WORKER_STOP)
            ranked_send(control, "stop\n");
        else if (cmd != sent && cmd == WORKER_ABANDON)
            kill(-pid, SIGTERM); /* deleted: mpirun ends its ranks, then itself */
        sent = cmd;
        ranked_sleep(RANKED_POLL_SECONDS);
    }
    close(control);
    char pid_path[1200];
    ranked_pid_path(c, pid_path, sizeof pid_path);
    unlink(pid_path); /* they are gone: nothing for a later launch to wait for */
    atomic_store(&c->ranks_running, 0);
    seen.tv_sec = seen.tv_nsec = 0;
    ranked_follow_status(c, &seen, &eta);
    if (atomic_load(&c->command) == WORKER_ABANDON)
        return CASE_STOPPED;
    return ranked_outcome(c, status);
}
