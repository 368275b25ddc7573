/*
 * http.c - libmicrohttpd setup and the per-request life cycle.
 *
 * libmicrohttpd calls http_access() several times per request: first with
 * only the headers (where we decide 401/404/405/411/413 without touching
 * the body, so a 100 MB upload is refused before it is sent), then once per
 * body chunk, then once more to answer. A small thread pool serves
 * connections so that one request waiting for the I/O thread (a result
 * download) or for a step boundary does not hold up the others.
 */
#include "http.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include "common/memory_budget.h"
#include "gate.h"
#include "heavy_work.h"
#include "http_frame.h"
#include "json/json_depth.h"
#include "routes.h"
#include "stream.h"
#include "web.h"

#define HTTP_THREADS 4
#define HTTP_CONNECTION_TIMEOUT 30 /* s of inactivity while a response is sent */
#define HTTP_CONNECTION_LIMIT 512
#define HTTP_CONNECTION_MEMORY (64 * 1024) /* request line and headers */

typedef struct http_request {
    route_match route;
    double deadline;  /* the whole request must have arrived by then */
    int answered;     /* a response was queued before the body */
    int later;        /* not its connection's first request (keep-alive) */
    int closing;      /* its connection closes after the answer (see http_completed) */
    int too_large;
    unsigned owed_status; /* an answer owed once the body is drained (see http_owe) */
    const char *owed_title;
    char *owed;           /* its detail */
    char *body;
    size_t size, capacity, limit;
    membudget_lease lease; /* the body and what parsing it costs */
    /* a request answered on a heavy-work thread (heavy_work.h): its
     * connection, method, and the answer kept for when it is resumed */
    struct MHD_Connection *conn;
    const char *method;
    int heavy_done;
    unsigned heavy_status;
    struct MHD_Response *heavy_answer;
} http_request;

/* What a heavy-work thread's routes answered: http_queue keeps it here
 * instead of queueing it, since a suspended connection takes its answer
 * only from its own access callback once resumed. */
typedef struct http_kept_answer {
    unsigned status;
    struct MHD_Response *resp;
} http_kept_answer;

static _Thread_local http_kept_answer *tl_kept;
static _Thread_local http_request *tl_request; /* the request being answered here */
static _Thread_local int tl_deferred; /* a route asked for a heavy-work thread */

static struct MHD_Daemon *http_daemon;
static const fdemd_config *http_cfg;

/* ------------------------------------------------------------ responses */

static enum MHD_Result http_queue(struct MHD_Connection *conn, unsigned status,
                                  struct MHD_Response *resp)
{
    if (!resp)
        return MHD_NO;
    /* An error closes its connection: its request may have a body left
     * unread, or be one no client should go on from; a success keeps it
     * alive for the next request (gate.h). */
    if (status >= 400) {
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, "close");
        if (tl_request)
            tl_request->closing = 1;
    }
    if (tl_kept) {
        if (tl_kept->resp) /* a second answer to one request: keep the first */
            MHD_destroy_response(resp);
        else
            *tl_kept = (http_kept_answer){status, resp};
        return MHD_YES;
    }
    enum MHD_Result rc = MHD_queue_response(conn, status, resp);
    MHD_destroy_response(resp);
    return rc;
}

static struct MHD_Response *http_text_response(char *text, const char *content_type)
{
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(strlen(text), text, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        free(text);
        return NULL;
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, content_type);
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    return resp;
}

enum MHD_Result http_reply_response(struct MHD_Connection *conn, unsigned status,
                                    struct MHD_Response *resp)
{
    return http_queue(conn, status, resp);
}

enum MHD_Result http_reply_json(struct MHD_Connection *conn, unsigned status, json_t *body,
                                const char *location)
{
    char *text = body ? json_dumps(body, JSON_COMPACT) : NULL;
    json_decref(body);
    if (!text)
        return http_reply_problem(conn, 500, "Internal error", "the response could not be encoded", NULL);
    struct MHD_Response *resp = http_text_response(text, "application/json");
    if (resp && location)
        MHD_add_response_header(resp, MHD_HTTP_HEADER_LOCATION, location);
    return http_queue(conn, status, resp);
}

static json_t *http_problem_json(unsigned status, const char *title, const char *detail,
                                 const problems *p)
{
    json_t *errors = json_array();
    for (int i = 0; p && i < p->count; i++)
        json_array_append_new(errors, json_pack("{s:s, s:s}", "pointer", p->items[i].pointer,
                                                "message", p->items[i].message));
    return json_pack("{s:s, s:s, s:i, s:s, s:o}", "type", "about:blank", "title", title,
                     "status", (int)status, "detail", detail, "errors", errors);
}

static struct MHD_Response *http_problem_response(unsigned status, const char *title,
                                                  const char *detail, const problems *p)
{
    json_t *o = http_problem_json(status, title, detail, p);
    char *text = o ? json_dumps(o, JSON_COMPACT) : NULL;
    json_decref(o);
    if (!text)
        return NULL;
    return http_text_response(text, "application/problem+json");
}

enum MHD_Result http_reply_problem(struct MHD_Connection *conn, unsigned status, const char *title,
                                   const char *detail, const problems *p)
{
    return http_queue(conn, status, http_problem_response(status, title, detail, p));
}

enum MHD_Result http_reply_unavailable(struct MHD_Connection *conn, const char *detail,
                                       const problems *p)
{
    struct MHD_Response *resp = http_problem_response(503, "Service unavailable", detail, p);
    if (resp) {
        char seconds[16];
        snprintf(seconds, sizeof seconds, "%d", MEMBUDGET_RETRY_AFTER);
        MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, seconds);
    }
    return http_queue(conn, 503, resp);
}

enum MHD_Result http_reply_not_allowed(struct MHD_Connection *conn, const char *allow)
{
    char detail[128];
    snprintf(detail, sizeof detail, "this path allows %s", allow);
    struct MHD_Response *resp = http_problem_response(405, "Method not allowed", detail, NULL);
    if (resp)
        MHD_add_response_header(resp, MHD_HTTP_HEADER_ALLOW, allow);
    return http_queue(conn, 405, resp);
}

enum MHD_Result http_reply_empty(struct MHD_Connection *conn, unsigned status)
{
    struct MHD_Response *resp = MHD_create_response_from_buffer(0, "", MHD_RESPMEM_PERSISTENT);
    return http_queue(conn, status, resp);
}

enum MHD_Result http_reply_fd(struct MHD_Connection *conn, int fd, size_t size,
                              const char *content_type, const char *filename)
{
    struct MHD_Response *resp = MHD_create_response_from_fd(size, fd);
    if (!resp) {
        close(fd);
        return http_reply_problem(conn, 500, "Internal error", "the file could not be served", NULL);
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, content_type);
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    if (filename) {
        char disposition[128];
        snprintf(disposition, sizeof disposition, "attachment; filename=\"%s\"", filename);
        MHD_add_response_header(resp, "Content-Disposition", disposition);
    }
    return http_queue(conn, 200, resp);
}

enum MHD_Result http_reply_stream(struct MHD_Connection *conn, struct MHD_Response *resp,
                                  unsigned idle_timeout)
{
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, "text/event-stream");
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, "close");
    if (tl_request)
        tl_request->closing = 1;
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
    if (info)
        gate_stream_began(info->connect_fd);
    MHD_set_connection_option(conn, MHD_CONNECTION_OPTION_TIMEOUT, idle_timeout);
    return http_queue(conn, 200, resp);
}

enum MHD_Result http_defer_heavy(struct MHD_Connection *conn)
{
    (void)conn;
    tl_deferred = 1;
    return MHD_YES;
}

int http_on_heavy_thread(void)
{
    return tl_kept != NULL;
}

/* ------------------------------------------------------ authentication */

/* Compares in time that depends only on the expected token's length, so
 * the answer time leaks neither how much of a guess matched nor its length. */
static int http_token_equal(const char *given, size_t given_len, const char *want)
{
    size_t want_len = strlen(want);
    unsigned char diff = given_len != want_len;
    for (size_t i = 0; i < want_len; i++) {
        unsigned char g = i < given_len ? (unsigned char)given[i] : 0;
        diff |= g ^ (unsigned char)want[i];
    }
    return diff == 0;
}

/* NULL when the request may pass, else why not: the detail of its 401,
 * which tells a user who sent no token from one who sent the wrong one. */
static const char *http_unauthorized_reason(struct MHD_Connection *conn)
{
    if (!http_cfg->token)
        return NULL;
    const char *h = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_AUTHORIZATION);
    if (!h || strncasecmp(h, "Bearer ", 7) != 0)
        return "this daemon needs an Authorization: Bearer <token> header "
               "(fdemctl and the Python client: set FDEMD_TOKEN)";
    h += 7;
    while (*h == ' ')
        h++;
    if (!http_token_equal(h, strlen(h), http_cfg->token))
        return "the bearer token does not match this daemon's --token";
    return NULL;
}

static enum MHD_Result http_reply_unauthorized(struct MHD_Connection *conn, const char *reason)
{
    struct MHD_Response *resp = http_problem_response(401, "Unauthorized", reason, NULL);
    if (resp)
        MHD_add_response_header(resp, MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"fdemd\"");
    return http_queue(conn, 401, resp);
}

/* ------------------------------------------------------ request phases */

/* A refusal decided from the headers (503 for the memory budget, 413 for a
 * body on a route that takes none) is owed, not sent, to a client that is
 * sending its body without waiting (no "Expect: 100-continue"): answering
 * at once makes libmicrohttpd close the socket with the body unread, the
 * kernel then resets the connection, and a client still writing its body
 * never reads the answer (of four concurrent 60 MB uploads over the budget,
 * two got their 503 and two a reset, issue 30). So the body is read and
 * dropped, never held (it costs no budget), and the answer follows it; the
 * whole request still has --request-timeout to arrive. A client that asked
 * for 100-continue waits for the answer, and gets it at once. Returns 1
 * when the answer is owed. */
static int http_owe(struct MHD_Connection *conn, http_request *r, unsigned status,
                    const char *title, const char *detail)
{
    const char *expect = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_EXPECT);
    if (r->limit == 0 || (expect && strcasecmp(expect, "100-continue") == 0))
        return 0;
    r->owed = strdup(detail);
    r->owed_status = status;
    r->owed_title = title;
    return r->owed != NULL;
}

static enum MHD_Result http_reply_owed(struct MHD_Connection *conn, const http_request *r)
{
    if (r->owed_status == 503)
        return http_reply_unavailable(conn, r->owed, NULL);
    return http_reply_problem(conn, r->owed_status, r->owed_title, r->owed, NULL);
}

/* Everything that can be decided from the request line and headers.
 * Returns 1 when a response was queued. */
static int http_check_headers(struct MHD_Connection *conn, const char *url, const char *method,
                              http_request *r, enum MHD_Result *rc)
{
    /* /health and the page's own files need no token: the page must load
     * to ask for it, and its files hold no data (web.h). */
    int open_route = r->route.kind == ROUTE_HEALTH || r->route.kind == ROUTE_WEB;
    const char *unauthorized = !open_route ? http_unauthorized_reason(conn) : NULL;
    if (unauthorized) {
        *rc = http_reply_unauthorized(conn, unauthorized);
        return 1;
    }
    if (r->route.kind == ROUTE_NONE) {
        *rc = http_reply_problem(conn, 404, "Not found",
                                 r->route.bad_id ? "no such path: a case id is 16 lowercase "
                                                   "hexadecimal digits (GET /cases lists them)"
                                                 : "no such path", NULL);
        return 1;
    }
    if (!routes_method_allowed(r->route.kind, method)) {
        *rc = http_reply_not_allowed(conn, routes_allowed(r->route.kind));
        return 1;
    }
    char query_problem[300];
    if (routes_check_query(conn, r->route.kind, method, query_problem, sizeof query_problem) != 0) {
        *rc = http_reply_problem(conn, 400, "Bad request", query_problem, NULL);
        return 1;
    }
    /* Transfer-Encoding and malformed lengths were refused by the gate. */
    const char *cl = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
    if (!cl) {
        if (routes_takes_body(r->route.kind, method)) {
            *rc = http_reply_problem(conn, 411, "Length required",
                                     "a POST with a body needs a Content-Length header", NULL);
            return 1;
        }
        return 0;
    }
    errno = 0;
    char *end = NULL;
    unsigned long long length = strtoull(cl, &end, 10);
    if (errno || end == cl || *end != '\0' || length > http_cfg->max_upload) {
        char detail[160];
        snprintf(detail, sizeof detail, "the body is %s bytes; this daemon accepts at most %zu (--max-upload)",
                 cl, http_cfg->max_upload);
        *rc = http_reply_problem(conn, 413, "Payload too large", detail, NULL);
        return 1;
    }
    r->limit = (size_t)length;
    /* A route that takes no body never buffers one: up to --max-upload of it
     * per connection would be held outside the memory budget (48 GET
     * /health with 64 MiB bodies took the RSS to 3 GB, issue 30). */
    if (length > 0 && !routes_takes_body(r->route.kind, method)) {
        char detail[400];
        snprintf(detail, sizeof detail, "%.16s %.200s takes no request body; this one has %s "
                 "bytes (send it without one)", method, url, cl);
        if (http_owe(conn, r, 413, "Payload too large", detail))
            return 0;
        *rc = http_reply_problem(conn, 413, "Payload too large", detail, NULL);
        return 1;
    }
    if (routes_takes_body(r->route.kind, method) &&
        membudget_grow(&r->lease, membudget_upload_cost(r->limit)) != 0) {
        char detail[240], need[32], limit[32];
        if (membudget_upload_cost(r->limit) > membudget_limit())
            snprintf(detail, sizeof detail, "parsing a body of %s bytes takes about %s, more than "
                     "this daemon's whole memory budget (--max-memory, %s)", cl,
                     membudget_describe(membudget_upload_cost(r->limit), need, sizeof need),
                     membudget_describe(membudget_limit(), limit, sizeof limit));
        else
            snprintf(detail, sizeof detail, "parsing a body of %s bytes would take this daemon past "
                     "its memory budget (--max-memory) now; try again later", cl);
        if (http_owe(conn, r, 503, "Service unavailable", detail))
            return 0;
        *rc = http_reply_unavailable(conn, detail, NULL);
        return 1;
    }
    return 0;
}

static int http_collect(http_request *r, const char *data, size_t size)
{
    if (r->size + size > r->limit || r->size + size > http_cfg->max_upload) {
        r->too_large = 1;
        return 0;
    }
    if (r->size + size + 1 > r->capacity) {
        size_t cap = r->capacity ? r->capacity : 4096;
        while (cap < r->size + size + 1)
            cap *= 2;
        if (cap > r->limit + 1)
            cap = r->limit + 1;
        char *grown = realloc(r->body, cap);
        if (!grown)
            return -1;
        r->body = grown;
        r->capacity = cap;
    }
    memcpy(r->body + r->size, data, size);
    r->size += size;
    r->body[r->size] = '\0';
    return 0;
}

/* ------------------------------------------------------------ deadline */

/* A request must arrive whole within --request-timeout of its connection
 * being accepted. The gate enforces that until the headers are in; from
 * then on libmicrohttpd's inactivity timeout is narrowed to the time left,
 * so a body that stalls is cut at the deadline and one that trickles is cut
 * at its first chunk after it. */
static double http_request_deadline(struct MHD_Connection *conn, int *later)
{
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
    *later = 0;
    double began = info ? gate_request_began(info->connect_fd, later) : 0;
    return (began > 0 ? began : gate_now()) + http_cfg->request_timeout;
}

static int http_in_time(struct MHD_Connection *conn, const http_request *r)
{
    double left = r->deadline - gate_now();
    if (left <= 0)
        return 0;
    MHD_set_connection_option(conn, MHD_CONNECTION_OPTION_TIMEOUT, (unsigned)ceil(left));
    return 1;
}

static enum MHD_Result http_reply_timeout(struct MHD_Connection *conn)
{
    char detail[128];
    snprintf(detail, sizeof detail, "the request did not arrive whole within %g s (--request-timeout)",
             http_cfg->request_timeout);
    return http_reply_problem(conn, 408, "Request timeout", detail, NULL);
}

/* Only routes that take a JSON body have one by now (http_check_headers).
 * Returns 1 when it nests too deeply, with its 400 queued in *rc. */
static int http_refuse_deep_json(struct MHD_Connection *conn, const http_request *r,
                                 enum MHD_Result *rc)
{
    int line = 0, column = 0;
    if (!json_depth_exceeds(r->body, r->size, JSON_MAX_DEPTH, &line, &column))
        return 0;
    problems p;
    problems_init(&p);
    problems_add(&p, 400, "", "line %d, column %d: arrays and objects nest deeper than %d "
                 "levels, the most this daemon reads (a case needs fewer than 10)",
                 line, column, JSON_MAX_DEPTH);
    char detail[160];
    snprintf(detail, sizeof detail, "the JSON body nests deeper than %d levels", JSON_MAX_DEPTH);
    *rc = http_reply_problem(conn, 400, "JSON nested too deeply", detail, &p);
    problems_free(&p);
    return 1;
}

/* A deferred request on a heavy-work thread: the same route, its answer
 * kept, then the connection resumed so that its callback sends it. */
static void http_heavy_run(void *arg)
{
    http_request *r = arg;
    http_kept_answer kept = {0, NULL};
    tl_kept = &kept;
    tl_request = r;
    membudget_request_enter(&r->lease);
    routes_handle(r->conn, &r->route, r->method, r->body ? r->body : "", r->size);
    membudget_request_leave();
    tl_kept = NULL;
    tl_request = NULL;
    r->heavy_status = kept.status;
    r->heavy_answer = kept.resp;
    r->heavy_done = 1;
    MHD_resume_connection(r->conn);
}

/* Runs the route; one that asks for a heavy-work thread (a model build)
 * gets one, its connection suspended meanwhile, or a 503 at once when the
 * queue is full. */
static enum MHD_Result http_route(struct MHD_Connection *conn, http_request *r, const char *method)
{
    tl_deferred = 0;
    membudget_request_enter(&r->lease);
    enum MHD_Result rc = routes_handle(conn, &r->route, method, r->body ? r->body : "", r->size);
    membudget_request_leave();
    if (!tl_deferred)
        return rc;
    tl_deferred = 0;
    if (heavy_work_reserve() != 0)
        return http_reply_unavailable(conn, "the daemon is building as many models as it takes "
                                      "at once for other requests; try again shortly", NULL);
    r->conn = conn;
    r->method = method;
    MHD_suspend_connection(conn);
    heavy_work_submit(http_heavy_run, r);
    return MHD_YES;
}

static enum MHD_Result http_access(void *cls, struct MHD_Connection *conn, const char *url,
                                   const char *method, const char *version, const char *upload_data,
                                   size_t *upload_data_size, void **req_cls)
{
    (void)cls;
    (void)version;
    http_request *r = *req_cls;
    tl_request = r;
    if (!r) {
        r = calloc(1, sizeof *r);
        if (!r)
            return MHD_NO;
        *req_cls = r;
        tl_request = r;
        r->deadline = http_request_deadline(conn, &r->later);
        r->closing = http_client_closes(conn, version);
        routes_match(url, &r->route);
        enum MHD_Result rc = MHD_YES;
        if (!http_in_time(conn, r)) {
            r->answered = 1;
            return http_reply_timeout(conn);
        }
        if ((r->later && http_refuse_bad_framing(conn, method, version, &rc)) ||
            http_check_headers(conn, url, method, r, &rc)) {
            r->answered = 1;
            return rc;
        }
        return MHD_YES;
    }
    if (r->heavy_done) { /* resumed: the heavy-work thread's answer */
        r->heavy_done = 0;
        struct MHD_Response *resp = r->heavy_answer;
        r->heavy_answer = NULL;
        if (!resp)
            return MHD_NO;
        enum MHD_Result rc = MHD_queue_response(conn, r->heavy_status, resp);
        MHD_destroy_response(resp);
        return rc;
    }
    if (r->answered) {
        *upload_data_size = 0;
        return MHD_YES;
    }
    if (*upload_data_size > 0) {
        if (!http_in_time(conn, r))
            return MHD_NO; /* nothing can be answered in the middle of a body */
        if (!r->too_large && !r->owed && http_collect(r, upload_data, *upload_data_size) != 0)
            return MHD_NO;
        *upload_data_size = 0;
        return MHD_YES;
    }
    r->answered = 1;
    MHD_set_connection_option(conn, MHD_CONNECTION_OPTION_TIMEOUT, (unsigned)HTTP_CONNECTION_TIMEOUT);
    if (gate_now() > r->deadline)
        return http_reply_timeout(conn);
    if (r->too_large)
        return http_reply_problem(conn, 413, "Payload too large",
                                  "the body is longer than its Content-Length or --max-upload", NULL);
    if (r->owed)
        return http_reply_owed(conn, r);
    enum MHD_Result rc;
    if (r->size > 0 && http_refuse_deep_json(conn, r, &rc))
        return rc;
    return http_route(conn, r, method);
}

static void http_completed(void *cls, struct MHD_Connection *conn, void **req_cls,
                           enum MHD_RequestTerminationCode toe)
{
    (void)cls;
    /* A connection that closes after this answer stops counting against
     * its address now, not at libmicrohttpd's next clean-up pass: the
     * client has its whole answer and may already be opening its next
     * connection (gate.c). One kept alive waits for its next request, under
     * the gate's watchdog. */
    http_request *r = *req_cls;
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
    if (info) {
        if (!r || r->closing || toe != MHD_REQUEST_TERMINATED_COMPLETED_OK)
            gate_closed(info->connect_fd);
        else
            gate_request_done(info->connect_fd);
    }
    tl_request = NULL;
    if (r) {
        if (r->heavy_answer)
            MHD_destroy_response(r->heavy_answer);
        free(r->body);
        free(r->owed);
        membudget_release(&r->lease);
        free(r);
        *req_cls = NULL;
    }
}

/* Percent-decodes in place like libmicrohttpd's default, except that
 * "%00" stays as it is: a decoded NUL would silently cut the path short
 * ("/cases/ID%00/x" would become "/cases/ID"). */
static size_t http_unescape(void *cls, struct MHD_Connection *conn, char *s)
{
    (void)cls;
    (void)conn;
    char *out = s;
    for (const char *in = s; *in; ) {
        unsigned hi, lo;
        if (in[0] == '%' && sscanf(in + 1, "%1x%1x", &hi, &lo) == 2 && (hi | lo) != 0) {
            *out++ = (char)(hi << 4 | lo);
            in += 3;
        } else {
            *out++ = *in++;
        }
    }
    *out = '\0';
    return (size_t)(out - s);
}

/* ---------------------------------------------------------------- start */

/* The gate counts connections per address; it must hear of every close. */
static void http_connection_event(void *cls, struct MHD_Connection *conn, void **socket_context,
                                  enum MHD_ConnectionNotificationCode code)
{
    (void)cls;
    (void)socket_context;
    if (code != MHD_CONNECTION_NOTIFY_CLOSED)
        return;
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
    if (info)
        gate_closed(info->connect_fd);
}

static int http_hand_over(int fd, const struct sockaddr_in *addr)
{
    return MHD_add_connection(http_daemon, fd, (const struct sockaddr *)addr, sizeof *addr) == MHD_YES;
}

/* Returns the listening socket and the port it got, or -1. */
static int http_listen(const fdemd_config *cfg, int *port)
{
    struct sockaddr_in addr;
    memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_port = htons((uint16_t)cfg->listen_port);
    if (inet_pton(AF_INET, cfg->listen_host, &addr.sin_addr) != 1) {
        fprintf(stderr, "fdemd: --listen: \"%s\" is not an IPv4 address\n", cfg->listen_host);
        return -1;
    }
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    int one = 1;
    socklen_t len = sizeof addr;
    if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0 ||
        bind(fd, (struct sockaddr *)&addr, sizeof addr) != 0 || listen(fd, 128) != 0 ||
        getsockname(fd, (struct sockaddr *)&addr, &len) != 0) {
        fprintf(stderr, "fdemd: cannot listen on %s:%d (%s)\n", cfg->listen_host, cfg->listen_port,
                strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    *port = ntohs(addr.sin_port);
    return fd;
}

int http_start(const fdemd_config *cfg)
{
    http_cfg = cfg;
    int port = 0;
    if (web_init(cfg->web_dir) != 0)
        fprintf(stderr, "fdemd: no web page: %s is not a folder (--web DIR); GET / answers 404\n",
                cfg->web_dir[0] ? cfg->web_dir : "web/ beside bin/");
    if (heavy_work_start() != 0)
        return -1;
    if (stream_start(cfg->max_streams) != 0) {
        heavy_work_stop();
        return -1;
    }
    int listen_fd = http_listen(cfg, &port);
    if (listen_fd < 0) {
        stream_stop();
        heavy_work_stop();
        return -1;
    }
    /* Connections arrive through the gate (MHD_add_connection), so
     * libmicrohttpd has no listening socket of its own and no limits of its
     * own: the gate's counts are the ones that hold. */
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG |
                     MHD_USE_NO_LISTEN_SOCKET | MHD_USE_ITC;
    flags |= MHD_is_feature_supported(MHD_FEATURE_EPOLL) == MHD_YES ? MHD_USE_EPOLL : MHD_USE_POLL;
    http_daemon = MHD_start_daemon(
        flags, 0, NULL, NULL, http_access, NULL,
        MHD_OPTION_THREAD_POOL_SIZE, (unsigned)HTTP_THREADS,
        MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)HTTP_CONNECTION_TIMEOUT,
        MHD_OPTION_CONNECTION_LIMIT, (unsigned)(2 * HTTP_CONNECTION_LIMIT),
        MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)HTTP_CONNECTION_MEMORY,
        MHD_OPTION_NOTIFY_COMPLETED, http_completed, NULL,
        MHD_OPTION_NOTIFY_CONNECTION, http_connection_event, NULL,
        MHD_OPTION_UNESCAPE_CALLBACK, http_unescape, NULL,
        MHD_OPTION_END);
    gate_limits limits = {cfg->max_connections_per_ip, HTTP_CONNECTION_LIMIT, cfg->request_timeout,
                          cfg->token != NULL};
    if (!http_daemon || gate_start(listen_fd, &limits, http_hand_over) != 0) {
        fprintf(stderr, "fdemd: cannot start the HTTP server\n");
        if (http_daemon)
            MHD_stop_daemon(http_daemon);
        else
            close(listen_fd);
        http_daemon = NULL;
        stream_stop();
        heavy_work_stop();
        return -1;
    }
    return port;
}

void http_stop(void)
{
    gate_stop(); /* no new connections while the open ones are closed */
    stream_stop(); /* ends every stream: none may be left suspended */
    heavy_work_stop(); /* answers and resumes every suspended request first */
    if (http_daemon) {
        MHD_stop_daemon(http_daemon);
        http_daemon = NULL;
    }
}
