/*
 * wait.c - `fdemctl wait ID`: follows a case until it ends, showing progress.
 *
 * It follows the daemon's event stream (GET /stream?case=ID): each status
 * event is shown as it comes, so an end is seen at once and nothing is
 * polled. When the daemon has no stream (an older one: 404), refuses one
 * (503: --max-streams are open) or the stream is cut, it polls GET
 * /cases/ID every --interval instead, as it always did.
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
    "  (a redrawn bar on a terminal, one line per update otherwise). It follows\n"
    "  the daemon's event stream (GET /stream), else polls.\n"
    "  --interval S   seconds between polls, when polling (default 0.5)\n"
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

/* ------------------------------------------------------------- showing */

typedef struct wait_view {
    const ctl_options *o;
    const char *id;
    FILE *tty;
    long long last_step;
    char last_state[32];
    int code;          /* the exit code, once the wait is over */
} wait_view;

/* Shows one status; 1 when the case has ended (v->code is its verdict). */
static int wait_show(wait_view *v, json_t *s)
{
    wait_progress p = wait_read(s);
    if (strcmp(p.state, v->last_state) != 0)
        wait_hint_idle(v->tty, v->id, p.state, v->last_step >= 0);
    if (v->tty) {
        wait_draw_bar(v->tty, &p);
    } else if (p.step != v->last_step || strcmp(p.state, v->last_state) != 0) {
        wait_print_line(&p);
    }
    v->last_step = p.step;
    snprintf(v->last_state, sizeof v->last_state, "%s", p.state);
    if (!wait_is_terminal(p.state)) return 0;
    if (v->tty) fputc('\n', v->tty);
    v->code = wait_verdict(v->id, s, &p);
    return 1;
}

/* GET /cases/ID, shown; 1 when the wait is over (ended, or the request
 * failed: v->code says how). */
static int wait_poll_once(wait_view *v)
{
    int code;
    json_t *s = ctl_get_status(v->o, v->id, &code);
    if (!s) {
        if (v->tty && v->last_step >= 0) fputc('\n', v->tty);
        v->code = code;
        return 1;
    }
    int over = wait_show(v, s);
    json_decref(s);
    return over;
}

/* ----------------------------------------------------------- following */

#define WAIT_STREAM_QUIET 45.0 /* s without a byte: the stream is cut (keep-alives come every 15 s) */

/* The text/event-stream parser: lines are gathered until a blank one
 * ends an event; "event:" and "data:" are kept, comments skipped. */
typedef struct wait_stream {
    wait_view *v;
    int opened;
    char *buf;                     /* bytes not yet split into lines */
    size_t length, capacity;
    char event[32];
    char *data;
} wait_stream;

/* One whole event: a status is shown; a deletion ends the wait as GET
 * /cases/ID tells it (404). Returns 1 when the wait is over. */
static int wait_dispatch(wait_stream *w)
{
    int over = 0;
    if (strcmp(w->event, "status") == 0 && w->data) {
        json_t *s = json_loads(w->data, 0, NULL);
        if (json_is_object(s)) over = wait_show(w->v, s);
        json_decref(s);
    } else if (strcmp(w->event, "deleted") == 0) {
        over = wait_poll_once(w->v);
    }
    w->event[0] = '\0';
    free(w->data);
    w->data = NULL;
    return over;
}

static int wait_line(wait_stream *w, char *line, size_t length)
{
    if (length && line[length - 1] == '\r') line[--length] = '\0';
    if (length == 0) return wait_dispatch(w);
    if (line[0] == ':') return 0; /* a comment: the opening line, keep-alives, a gap note */
    char *colon = memchr(line, ':', length);
    const char *value = colon ? colon + 1 + (colon[1] == ' ') : "";
    if (colon) *colon = '\0';
    if (strcmp(line, "event") == 0) {
        snprintf(w->event, sizeof w->event, "%s", value);
    } else if (strcmp(line, "data") == 0) {
        size_t had = w->data ? strlen(w->data) : 0;
        char *grown = realloc(w->data, had + strlen(value) + 2);
        if (!grown) return 0;
        if (had) grown[had++] = '\n';
        strcpy(grown + had, value);
        w->data = grown;
    }
    return 0;
}

static int wait_take(void *arg, const char *data, size_t n)
{
    wait_stream *w = arg;
    if (!w->opened) {
        /* the stream is open: the state it may have changed from since
         * the first look is read now, so no change falls between them */
        w->opened = 1;
        if (wait_poll_once(w->v)) return 1;
    }
    if (w->length + n + 1 > w->capacity) {
        size_t capacity = w->capacity ? w->capacity : 4096;
        while (capacity < w->length + n + 1) capacity *= 2;
        char *grown = realloc(w->buf, capacity);
        if (!grown) return 0;
        w->buf = grown;
        w->capacity = capacity;
    }
    memcpy(w->buf + w->length, data, n);
    w->length += n;
    size_t at = 0;
    char *nl;
    while ((nl = memchr(w->buf + at, '\n', w->length - at)) != NULL) {
        *nl = '\0';
        if (wait_line(w, w->buf + at, (size_t)(nl - (w->buf + at)))) return 1;
        at = (size_t)(nl - w->buf) + 1;
    }
    memmove(w->buf, w->buf + at, w->length - at);
    w->length -= at;
    return 0;
}

/* Follows GET /stream?case=ID; 1 when the wait is over, 0 when there is
 * no stream to follow (the caller polls). */
static int wait_follow(wait_view *v)
{
    if (strspn(v->id, "0123456789abcdef") != strlen(v->id)) return 0;
    char path[128];
    snprintf(path, sizeof path, "/stream?case=%.64s", v->id);
    wait_stream w = {.v = v};
    http_response r;
    int rc = http_follow(v->o, path, WAIT_STREAM_QUIET, wait_take, &w, &r);
    http_response_free(&r);
    free(w.buf);
    free(w.data);
    return rc == 0;
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

    wait_view v = {o, id[0], NULL, -1, "", CTL_OK};
    v.tty = isatty(fileno(stderr)) ? stderr : isatty(fileno(stdout)) ? stdout : NULL;
    if (wait_poll_once(&v) || wait_follow(&v)) return v.code;
    for (;;) { /* no stream: poll */
        double polled_at = wait_now();
        if (wait_poll_once(&v)) return v.code;
        double left = interval - (wait_now() - polled_at);
        if (left > 0) wait_sleep(left);
    }
}
