/*
 * stream.c - GET /stream (stream.h): each open stream is a response whose
 * body libmicrohttpd asks for piece by piece (stream_read), taken from the
 * case feed from the last event it has sent on.
 *
 * Why suspend and resume rather than a callback that waits: the daemon
 * answers HTTP on HTTP_THREADS threads (http.c); 64 streams each blocking
 * one would leave none for ordinary requests. A stream with nothing to
 * send suspends its connection (libmicrohttpd then neither polls it nor
 * times it out) and returns 0; the wake thread resumes it when the feed
 * has an event for it or a keep-alive is due, and libmicrohttpd asks
 * again. The suspension and the check before it happen under the hub
 * lock, which the wake thread holds while it looks and resumes, so no
 * event slips between the two. The hub lock also keeps a stream's
 * connection valid while it is resumed: libmicrohttpd frees a connection
 * only after its response, whose free callback (stream_free) takes the
 * lock to unlink the stream.
 *
 * Why the wake thread also looks at suspended sockets: libmicrohttpd does
 * not poll a suspended connection, so a client that went away would hold
 * its place under --max-streams until the next keep-alive failed to send,
 * up to two keep-alives later. Once a second the thread polls them for a
 * hang-up and ends those streams.
 *
 * Lock order: the hub lock, then the feed's (a leaf), then
 * libmicrohttpd's own (suspend and resume take it; it calls none of ours
 * while holding it).
 */
#define _GNU_SOURCE /* POLLRDHUP */
#include "stream.h"

#include <errno.h>
#include <poll.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cases/case_feed.h"
#include "gate.h"
#include "http.h"
#include "math/clock.h"

#define STREAM_READ_BYTES (16 * 1024) /* feed text taken at a time */
#define STREAM_HANGUP_CHECK 1.0       /* s between looks for clients gone */

static const char STREAM_OPENING[] =
    ": fdemd case events: status, snapshot, deleted; a comment line every 15 s keeps "
    "the connection open\n\n";
static const char STREAM_KEEPALIVE[] = ": keep-alive\n\n";

typedef struct stream_client {
    struct stream_client *prev, *next;
    struct MHD_Connection *conn;
    int fd;                      /* its socket (libmicrohttpd's; only polled here) */
    uint64_t after;              /* the last feed id looked at */
    char only[CASE_ID_LEN + 1];  /* ?case=, "" for every case */
    char *out;                   /* text taken from the feed, not yet sent */
    size_t out_length, out_sent;
    int suspended;
    int keepalive_due;
    int hung_up;                 /* its client went away while it was suspended */
} stream_client;

static struct {
    pthread_mutex_t lock;
    pthread_cond_t gone;         /* a stream ended */
    stream_client *head;
    int count, max;
    int closing;
    int running;
    pthread_t thread;
} hub = {.lock = PTHREAD_MUTEX_INITIALIZER, .gone = PTHREAD_COND_INITIALIZER};

static const char *stream_only(const stream_client *s)
{
    return s->only[0] ? s->only : NULL;
}

/* ------------------------------------------------------------- the body */

/* Sets the text to send next (a copy of `text`); 0, or -1 without memory. */
static int stream_take_text(stream_client *s, const char *text)
{
    s->out = strdup(text);
    s->out_length = s->out ? strlen(text) : 0;
    s->out_sent = 0;
    return s->out ? 0 : -1;
}

/* The next piece of the body, 0 after suspending the connection, or the
 * end of the stream when the daemon stops. With the hub lock held. */
static ssize_t stream_next_locked(stream_client *s, char *buf, size_t max)
{
    for (;;) {
        if (s->out_sent < s->out_length) {
            size_t n = s->out_length - s->out_sent;
            if (n > max)
                n = max;
            memcpy(buf, s->out + s->out_sent, n);
            s->out_sent += n;
            return (ssize_t)n;
        }
        free(s->out);
        s->out = NULL;
        s->out_length = s->out_sent = 0;
        /* a client gone gets the end too: ending it "with error" would
         * log a line per client that went away */
        if (hub.closing || s->hung_up)
            return MHD_CONTENT_READER_END_OF_STREAM;
        s->out_length = case_feed_read(&s->after, stream_only(s), STREAM_READ_BYTES, &s->out);
        if (s->out_length)
            continue;
        if (s->keepalive_due) {
            s->keepalive_due = 0;
            if (stream_take_text(s, STREAM_KEEPALIVE) == 0)
                continue;
        }
        s->suspended = 1;
        MHD_suspend_connection(s->conn);
        return 0;
    }
}

static ssize_t stream_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    pthread_mutex_lock(&hub.lock);
    ssize_t n = stream_next_locked(cls, buf, max);
    pthread_mutex_unlock(&hub.lock);
    return n;
}

/* libmicrohttpd is done with the response: the stream has ended. */
static void stream_free(void *cls)
{
    stream_client *s = cls;
    pthread_mutex_lock(&hub.lock);
    if (s->prev)
        s->prev->next = s->next;
    else if (hub.head == s)
        hub.head = s->next;
    if (s->next)
        s->next->prev = s->prev;
    hub.count--;
    pthread_cond_broadcast(&hub.gone);
    pthread_mutex_unlock(&hub.lock);
    free(s->out);
    free(s);
}

/* ---------------------------------------------------------- wake thread */

/* Marks the suspended streams whose client has hung up. With the hub
 * lock held. */
static void stream_find_hangups_locked(void)
{
    struct pollfd fds[256];
    stream_client *of[256];
    int n = 0;
    for (stream_client *s = hub.head; s; s = s->next) {
        if (s->suspended && s->fd >= 0) {
            fds[n] = (struct pollfd){.fd = s->fd, .events = POLLRDHUP};
            of[n++] = s;
        }
        if (n == 256 || (!s->next && n > 0)) {
            if (poll(fds, (nfds_t)n, 0) > 0)
                for (int i = 0; i < n; i++)
                    if (fds[i].revents & (POLLRDHUP | POLLHUP | POLLERR | POLLNVAL))
                        of[i]->hung_up = 1;
            n = 0;
        }
    }
}

/* Resumes every suspended stream that has something to send or whose
 * client hung up (all of them when `all`). With the hub lock held. */
static void stream_resume_locked(int beat, int all)
{
    for (stream_client *s = hub.head; s; s = s->next) {
        if (beat)
            s->keepalive_due = 1;
        if (s->suspended && (all || s->keepalive_due || s->hung_up ||
                             case_feed_has(s->after, stream_only(s)))) {
            s->suspended = 0;
            MHD_resume_connection(s->conn);
        }
    }
}

static void *stream_main(void *unused)
{
    (void)unused;
    uint64_t seen = case_feed_last_id();
    double beat_at = clock_wall_seconds() + STREAM_KEEPALIVE_SECONDS;
    double look_at = clock_wall_seconds() + STREAM_HANGUP_CHECK;
    pthread_mutex_lock(&hub.lock);
    while (!hub.closing) {
        pthread_mutex_unlock(&hub.lock);
        double wait = (beat_at < look_at ? beat_at : look_at) - clock_wall_seconds();
        seen = case_feed_wait(seen, wait > 0 ? wait : 0);
        pthread_mutex_lock(&hub.lock);
        double now = clock_wall_seconds();
        int beat = now >= beat_at;
        if (beat)
            beat_at = now + STREAM_KEEPALIVE_SECONDS;
        if (now >= look_at) {
            look_at = now + STREAM_HANGUP_CHECK;
            stream_find_hangups_locked();
        }
        stream_resume_locked(beat, 0);
    }
    pthread_mutex_unlock(&hub.lock);
    return NULL;
}

int stream_start(int max_streams)
{
    hub.max = max_streams;
    hub.closing = 0;
    if (pthread_create(&hub.thread, NULL, stream_main, NULL) != 0) {
        fprintf(stderr, "fdemd: cannot start the event stream thread: %s\n", strerror(errno));
        return -1;
    }
    hub.running = 1;
    return 0;
}

void stream_stop(void)
{
    pthread_mutex_lock(&hub.lock);
    hub.closing = 1;
    stream_resume_locked(0, 1); /* each then ends its body */
    pthread_mutex_unlock(&hub.lock);
    case_feed_wake();
    if (hub.running)
        pthread_join(hub.thread, NULL);
    hub.running = 0;
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += (time_t)STREAM_STOP_WAIT;
    pthread_mutex_lock(&hub.lock);
    while (hub.count > 0 && pthread_cond_timedwait(&hub.gone, &hub.lock, &until) == 0)
        ;
    pthread_mutex_unlock(&hub.lock);
}

/* -------------------------------------------------------------- opening */

/* Last-Event-ID: a decimal id, as this daemon sends them. 0 with *id
 * (none: 0 and *given 0), -1 when malformed. */
static int stream_last_event_id(struct MHD_Connection *conn, uint64_t *id, int *given)
{
    const char *text = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Last-Event-ID");
    *given = text && *text;
    *id = 0;
    if (!*given)
        return 0;
    if (strspn(text, "0123456789") != strlen(text) || strlen(text) > 19)
        return -1;
    *id = strtoull(text, NULL, 10);
    return 0;
}

/* 0, or an HTTP status with its answer queued in *rc. */
static int stream_check_request(struct MHD_Connection *conn, const char *only, int resuming,
                                enum MHD_Result *rc)
{
    char detail[160];
    if (only && !id_is_valid(only)) {
        snprintf(detail, sizeof detail, "?case= takes a case id (16 lowercase hexadecimal "
                 "digits), not \"%.32s\"", only);
        *rc = http_reply_problem(conn, 400, "Bad request", detail, NULL);
        return 400;
    }
    server_case *c = only ? registry_find(only) : NULL;
    if (only && !c && !resuming) {
        snprintf(detail, sizeof detail, "no case with id %s", only);
        *rc = http_reply_problem(conn, 404, "Not found", detail, NULL);
        return 404;
    }
    if (c)
        case_release(c);
    return 0;
}

/* Lists a new stream; 0, or -1 with its 503 queued in *rc. */
static int stream_admit(struct MHD_Connection *conn, stream_client *s, enum MHD_Result *rc)
{
    char detail[200] = "";
    pthread_mutex_lock(&hub.lock);
    if (hub.closing)
        snprintf(detail, sizeof detail, "the daemon is shutting down");
    else if (hub.count >= hub.max)
        snprintf(detail, sizeof detail, "this daemon serves at most %d event streams at once "
                 "(--max-streams); close one, or try again later", hub.max);
    if (!detail[0]) {
        s->next = hub.head;
        if (hub.head)
            hub.head->prev = s;
        hub.head = s;
        hub.count++;
    }
    pthread_mutex_unlock(&hub.lock);
    if (!detail[0])
        return 0;
    *rc = http_reply_unavailable(conn, detail, NULL);
    return -1;
}

enum MHD_Result stream_open(struct MHD_Connection *conn)
{
    const char *only = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "case");
    uint64_t last = 0;
    int resuming = 0;
    if (stream_last_event_id(conn, &last, &resuming) != 0)
        return http_reply_problem(conn, 400, "Bad request", "Last-Event-ID takes the id of an "
                                  "event this daemon sent (a decimal number)", NULL);
    enum MHD_Result rc;
    if (stream_check_request(conn, only, resuming, &rc) != 0)
        return rc;
    stream_client *s = calloc(1, sizeof *s);
    if (!s || stream_take_text(s, STREAM_OPENING) != 0) {
        free(s);
        return http_reply_problem(conn, 500, "Internal error", "out of memory", NULL);
    }
    s->conn = conn;
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
    s->fd = info ? info->connect_fd : -1;
    s->after = resuming ? last : case_feed_last_id();
    if (only)
        snprintf(s->only, sizeof s->only, "%s", only);
    if (stream_admit(conn, s, &rc) != 0) {
        free(s->out);
        free(s);
        return rc;
    }
    struct MHD_Response *resp =
        MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 4096, stream_read, s, stream_free);
    if (!resp) {
        stream_free(s);
        return http_reply_problem(conn, 500, "Internal error", "out of memory", NULL);
    }
    return http_reply_stream(conn, resp, STREAM_IDLE_TIMEOUT);
}
