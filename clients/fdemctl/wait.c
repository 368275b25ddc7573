/*
 * wait.c - `fdemctl wait ID`: polls a case until it ends, showing progress.
 *
 * On a terminal the progress is one line redrawn in place (bar, percent,
 * step, simulated time, steps/s, ETA); piped, it is one plain line per
 * change so logs stay readable. The exit code is the case's verdict, which
 * is what makes `fdemctl wait ID && fdemctl fetch ID` safe in scripts.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <jansson.h>
#include "fdemctl.h"

static const char USAGE_WAIT[] =
    "usage: fdemctl wait ID [--interval SECONDS]\n"
    "  Waits until the case is finished, failed or stopped, showing its progress\n"
    "  (a redrawn bar on a terminal, one line per update otherwise).\n"
    "  --interval S   seconds between polls (default 0.5)\n"
    "  Exit 0 when the case finished; 1 when it failed (its error is printed) or\n"
    "  was stopped, or the server refused; 2 for usage or connection errors.\n";

#define WAIT_BAR_WIDTH 30

typedef struct wait_progress {
    double progress, time, end_time, steps_per_second, dt;
    double eta;      /* the server's (contract 6.2), < 0 when it sent none */
    long long step;
    const char *state;
    char stage[112]; /* "  stage 1 \"excavate\"" for a case with stages, else "" */
} wait_progress;

static double wait_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void wait_sleep(double seconds)
{
    struct timespec ts = {(time_t)seconds, (long)((seconds - floor(seconds)) * 1e9)};
    while (nanosleep(&ts, &ts) != 0) {}
}

static wait_progress wait_read(json_t *s)
{
    wait_progress p;
    p.progress = json_number_value(json_object_get(s, "progress"));
    p.time = json_number_value(json_object_get(s, "time"));
    p.end_time = json_number_value(json_object_get(s, "end_time"));
    p.steps_per_second = json_number_value(json_object_get(s, "steps_per_second"));
    p.dt = json_number_value(json_object_get(s, "dt"));
    json_t *eta = json_object_get(s, "eta");
    p.eta = json_is_number(eta) ? json_number_value(eta) : -1;
    p.step = json_integer_value(json_object_get(s, "step"));
    p.state = json_string_value(json_object_get(s, "state"));
    if (!p.state) p.state = "?";
    char stage[96];
    ctl_stage_text(s, stage, sizeof stage);
    snprintf(p.stage, sizeof p.stage, "%s%s", stage[0] ? "  stage " : "", stage);
    if (!(p.progress >= 0)) p.progress = 0;
    if (p.progress > 1) p.progress = 1;
    /* 100 % is shown for a finished case only: one that has stepped to its
     * end but is still writing (or an older server's 1.0) shows 99.9 %. */
    if (strcmp(p.state, "finished") != 0 && p.progress > 0.999) p.progress = 0.999;
    return p;
}

/* Seconds left: the server's eta (over its last seconds, steadier than one
 * speed sample), else from its current speed (an older server); negative
 * when unknown. */
static double wait_eta(const wait_progress *p)
{
    if (strcmp(p->state, "running") != 0) return -1;
    if (p->eta >= 0) return p->eta;
    if (p->steps_per_second > 0 && p->dt > 0 && p->end_time > p->time)
        return (p->end_time - p->time) / p->dt / p->steps_per_second;
    return -1;
}

static void wait_format_eta(char *out, size_t size, double eta)
{
    if (eta < 0) snprintf(out, size, "--");
    else if (eta < 100) snprintf(out, size, "%.0f s", ceil(eta));
    else if (eta < 6000) snprintf(out, size, "%.0f min", ceil(eta / 60));
    else snprintf(out, size, "%.1f h", eta / 3600);
}

static void wait_draw_bar(FILE *tty, const wait_progress *p)
{
    char bar[WAIT_BAR_WIDTH + 1], eta[32];
    int filled = (int)(p->progress * WAIT_BAR_WIDTH + 0.5);
    for (int i = 0; i < WAIT_BAR_WIDTH; i++) bar[i] = i < filled ? '#' : '-';
    bar[WAIT_BAR_WIDTH] = '\0';
    wait_format_eta(eta, sizeof eta, wait_eta(p));
    /* \033[K clears what a longer previous line left behind. */
    fprintf(tty, "\r[%s] %5.1f%%  step %lld  t %.4g/%.4g s  %.3g steps/s  ETA %s  %s%s\033[K",
            bar, 100 * p->progress, p->step, p->time, p->end_time, p->steps_per_second,
            eta, p->state, p->stage);
    fflush(tty);
}

static void wait_print_line(const wait_progress *p)
{
    char eta[32];
    wait_format_eta(eta, sizeof eta, wait_eta(p));
    printf("%-8s %5.1f%%  step %lld  t %.6g/%.6g s  %.3g steps/s  ETA %s%s\n", p->state,
           100 * p->progress, p->step, p->time, p->end_time, p->steps_per_second, eta, p->stage);
    fflush(stdout);
}

/* Prints the verdict of a case that reached a terminal state. */
static int wait_verdict(const char *id, json_t *s, const wait_progress *p)
{
    if (strcmp(p->state, "finished") == 0) {
        printf("%s finished: %lld steps, t = %.6g s, %lld snapshots\n", id, p->step, p->time,
               json_integer_value(json_object_get(s, "snapshots")));
        return CTL_OK;
    }
    if (strcmp(p->state, "failed") == 0) {
        const char *error = json_string_value(json_object_get(s, "error"));
        fprintf(stderr, "fdemctl: case %s failed: %s\n", id, error ? error : "(no reason given)");
        return CTL_FAIL;
    }
    fprintf(stderr, "fdemctl: case %s was stopped at step %lld, t = %.6g s\n", id, p->step,
            p->time);
    return CTL_FAIL;
}

/* A created or paused case does not move until someone starts it; wait
 * keeps waiting (another client may), but says so once per such state, so
 * a user who forgot --start is not left watching 0.0 % in silence. */
static void wait_hint_idle(FILE *tty, const char *id, const char *state, int drawn)
{
    if (strcmp(state, "created") != 0 && strcmp(state, "paused") != 0) return;
    if (tty == stderr && drawn) fputc('\n', stderr);
    fprintf(stderr, "fdemctl: case %s is %s: it does not run until it is started "
                    "(fdemctl start %s); waiting\n", id, state, id);
}

static int wait_is_terminal(const char *state)
{
    return strcmp(state, "finished") == 0 || strcmp(state, "failed") == 0 ||
           strcmp(state, "stopped") == 0;
}

static int wait_parse_interval(const char *text, double *interval)
{
    char *end;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || !isfinite(v) || v <= 0 || v > 3600) {
        fprintf(stderr, "fdemctl wait: --interval wants seconds between 0 and 3600, not '%s'\n",
                text);
        return -1;
    }
    *interval = v < 0.05 ? 0.05 : v;
    return 0;
}

int cmd_wait(const ctl_options *o, int argc, char **argv)
{
    const char *id[1], *interval_text = NULL;
    ctl_option_spec specs[] = {{"--interval", "-i", &interval_text, NULL}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_WAIT, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    double interval = 0.5;
    if (interval_text && wait_parse_interval(interval_text, &interval) != 0) return CTL_USAGE;

    FILE *tty = isatty(fileno(stderr)) ? stderr : isatty(fileno(stdout)) ? stdout : NULL;
    long long last_step = -1;
    char last_state[32] = "";
    for (;;) {
        double polled_at = wait_now();
        int code;
        json_t *s = ctl_get_status(o, id[0], &code);
        if (!s) {
            if (tty) fputc('\n', tty);
            return code;
        }
        wait_progress p = wait_read(s);
        if (strcmp(p.state, last_state) != 0)
            wait_hint_idle(tty, id[0], p.state, last_step >= 0);
        if (tty) {
            wait_draw_bar(tty, &p);
        } else if (p.step != last_step || strcmp(p.state, last_state) != 0) {
            wait_print_line(&p);
        }
        last_step = p.step;
        snprintf(last_state, sizeof last_state, "%s", p.state);
        if (wait_is_terminal(p.state)) {
            if (tty) fputc('\n', tty);
            code = wait_verdict(id[0], s, &p);
            json_decref(s);
            return code;
        }
        json_decref(s);
        double left = interval - (wait_now() - polled_at);
        if (left > 0) wait_sleep(left);
    }
}
