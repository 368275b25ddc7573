/*
 * routes.c - one function per API route (contract section 2).
 *
 * Routes translate between HTTP and the registry: they parse query
 * arguments, call one registry or I/O function and turn its answer into a
 * status code. Nothing here touches a model or an HDF5 handle directly.
 */
#include "routes.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cases/case_continue.h"
#include "download.h"
#include "fragment_query.h"
#include "mesh_frame.h"
#include "state/events_json.h"
#include "http.h"
#include "cases/io_thread.h"
#include "common/memory_budget.h"
#include "state/state_json.h"
#include "stream.h"
#include "web.h"

/* ------------------------------------------------------------- matching */

#define ROUTE_MAX_SEGMENTS 4

/* Splits "/a/b/c" into at most ROUTE_MAX_SEGMENTS segments; one trailing
 * slash is forgiven. Returns the count, or -1 for empty or excess segments. */
static int routes_split(const char *url, char seg[ROUTE_MAX_SEGMENTS][32])
{
    if (!url || url[0] != '/')
        return -1;
    const char *p = url + 1;
    int n = 0;
    while (*p) {
        const char *slash = strchr(p, '/');
        size_t len = slash ? (size_t)(slash - p) : strlen(p);
        if (len == 0 || len >= 32 || n == ROUTE_MAX_SEGMENTS)
            return -1;
        memcpy(seg[n], p, len);
        seg[n][len] = '\0';
        n++;
        if (!slash)
            break;
        p = slash + 1;
    }
    return n;
}

void routes_match(const char *url, route_match *out)
{
    static const struct { const char *name; route_kind kind; } sub[] = {
        {"start", ROUTE_CASE_START}, {"pause", ROUTE_CASE_PAUSE}, {"stop", ROUTE_CASE_STOP},
        {"case", ROUTE_CASE_DOCUMENT}, {"state", ROUTE_CASE_STATE},
        {"result.h5", ROUTE_CASE_RESULT_H5}, {"result.xdmf", ROUTE_CASE_RESULT_XDMF},
        {"fragments", ROUTE_CASE_FRAGMENTS}, {"extend", ROUTE_CASE_EXTEND},
        {"clone", ROUTE_CASE_CLONE}, {"events", ROUTE_CASE_EVENTS},
        {"history", ROUTE_CASE_HISTORY}, {"mesh.bin", ROUTE_CASE_MESH},
    };
    char seg[ROUTE_MAX_SEGMENTS][32];
    memset(out, 0, sizeof *out);
    if (web_path(url)) { /* the page's files: web.c checks the rest of the path */
        out->kind = ROUTE_WEB;
        out->url = url;
        return;
    }
    int n = routes_split(url, seg);
    if (n == 1 && strcmp(seg[0], "health") == 0)
        out->kind = ROUTE_HEALTH;
    if (n == 1 && strcmp(seg[0], "stream") == 0)
        out->kind = ROUTE_STREAM;
    if (n < 1 || strcmp(seg[0], "cases") != 0)
        return;
    if (n == 1) {
        out->kind = ROUTE_CASES;
        return;
    }
    if (!id_is_valid(seg[1])) {
        out->bad_id = 1;
        return;
    }
    if (n > 3)
        return;
    if (n == 2) {
        out->kind = ROUTE_CASE;
    } else {
        for (size_t i = 0; i < sizeof sub / sizeof *sub; i++)
            if (strcmp(seg[2], sub[i].name) == 0)
                out->kind = sub[i].kind;
        if (out->kind == ROUTE_NONE)
            return;
    }
    memcpy(out->id, seg[1], CASE_ID_LEN + 1);
}

const char *routes_allowed(route_kind kind)
{
    switch (kind) {
    case ROUTE_CASES: return "GET, HEAD, POST";
    case ROUTE_CASE: return "GET, HEAD, DELETE";
    case ROUTE_CASE_START: case ROUTE_CASE_PAUSE: case ROUTE_CASE_STOP:
    case ROUTE_CASE_EXTEND: case ROUTE_CASE_CLONE: return "POST";
    case ROUTE_STREAM: return "GET";
    default: return "GET, HEAD";
    }
}

int routes_method_allowed(route_kind kind, const char *method)
{
    const char *allowed = routes_allowed(kind);
    size_t len = strlen(method);
    for (const char *p = allowed; (p = strstr(p, method)) != NULL; p += len)
        if ((p == allowed || p[-1] == ' ') && (p[len] == ',' || p[len] == '\0'))
            return 1;
    return 0;
}

int routes_takes_body(route_kind kind, const char *method)
{
    return (kind == ROUTE_CASES || kind == ROUTE_CASE_EXTEND || kind == ROUTE_CASE_CLONE) &&
           strcmp(method, "POST") == 0;
}

/* ---------------------------------------------------------------- helpers */

static enum MHD_Result routes_no_case(struct MHD_Connection *conn, const char *id)
{
    char detail[64];
    snprintf(detail, sizeof detail, "no case with id %s", id);
    return http_reply_problem(conn, 404, "Not found", detail, NULL);
}

static enum MHD_Result routes_serve_file(struct MHD_Connection *conn, server_case *c,
                                         const char *name, const char *content_type)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", c->dir, name);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        if (fd >= 0)
            close(fd);
        char detail[128];
        snprintf(detail, sizeof detail, "the case has no %s (yet)", name);
        return http_reply_problem(conn, 404, "Not found", detail, NULL);
    }
    return http_reply_fd(conn, fd, (size_t)st.st_size, content_type, NULL);
}

/* "true"/"1"/"yes" -> 1, "false"/"0"/"no"/absent -> 0, else -1. */
static int routes_flag(struct MHD_Connection *conn, const char *name)
{
    const char *v = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, name);
    if (!v)
        return 0;
    if (!strcmp(v, "true") || !strcmp(v, "1") || !strcmp(v, "yes") || !*v)
        return 1;
    if (!strcmp(v, "false") || !strcmp(v, "0") || !strcmp(v, "no"))
        return 0;
    return -1;
}

/* --------------------------------------------------------- query arguments */

/* The query arguments each route and method takes; any other is a 400
 * naming it, so a misspelt "?strat=true" is not silently ignored. */
static const char *const *routes_query_names(route_kind kind, const char *method)
{
    static const char *const create[] = {"start", "dry_run", NULL};
    static const char *const list[] = {"state", NULL};
    static const char *const state[] = {"fields", NULL};
    static const char *const events[] = {"since", NULL};
    static const char *const fragments[] = {"parts", "exclude_host", NULL};
    static const char *const stream[] = {"case", NULL};
    static const char *const mesh[] = {"snapshot", "fields", "surface", "shape", NULL};
    static const char *const none[] = {NULL};
    if (kind == ROUTE_CASES)
        return strcmp(method, "POST") == 0 ? create : list;
    if (kind == ROUTE_CASE_CLONE)
        return create; /* a clone is made exactly as POST /cases makes a case */
    if (kind == ROUTE_STREAM)
        return stream;
    return kind == ROUTE_CASE_STATE ? state
         : kind == ROUTE_CASE_EVENTS || kind == ROUTE_CASE_HISTORY ? events
         : kind == ROUTE_CASE_FRAGMENTS ? fragments
         : kind == ROUTE_CASE_MESH ? mesh : none;
}

typedef struct routes_query_check {
    const char *const *allowed;
    char *detail;
    size_t detail_size;
    int seen;   /* bit i: allowed[i] given already */
    int bad;
} routes_query_check;

static enum MHD_Result routes_query_visit(void *cls, enum MHD_ValueKind kind, const char *key,
                                          const char *value)
{
    (void)kind;
    (void)value;
    routes_query_check *q = cls;
    for (int i = 0; q->allowed[i]; i++) {
        if (strcmp(key, q->allowed[i]) != 0)
            continue;
        if (q->seen & (1 << i)) {
            snprintf(q->detail, q->detail_size, "the query parameter \"%.64s\" is given twice", key);
            q->bad = 1;
            return MHD_NO;
        }
        q->seen |= 1 << i;
        return MHD_YES;
    }
    char names[128] = "";
    for (int i = 0; q->allowed[i]; i++)
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s\"%s\"",
                 i ? ", " : "", q->allowed[i]);
    snprintf(q->detail, q->detail_size, "unknown query parameter \"%.64s\"; %s%s", key,
             names[0] ? "this route takes " : "this route takes none", names);
    q->bad = 1;
    return MHD_NO;
}

int routes_check_query(struct MHD_Connection *conn, route_kind kind, const char *method,
                       char *detail, size_t detail_size)
{
    routes_query_check q = {routes_query_names(kind, method), detail, detail_size, 0, 0};
    MHD_get_connection_values(conn, MHD_GET_ARGUMENT_KIND, routes_query_visit, &q);
    return q.bad ? -1 : 0;
}

/* ----------------------------------------------------------------- routes */

static enum MHD_Result route_health(struct MHD_Connection *conn)
{
    int cases = 0, running = 0;
    registry_counts(&cases, &running);
    return http_reply_json(conn, 200,
                           json_pack("{s:s, s:s, s:i, s:i}", "status", "ok", "version", FDEM_VERSION,
                                     "cases", cases, "running", running), NULL);
}

static enum MHD_Result route_list_cases(struct MHD_Connection *conn)
{
    const char *wanted = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "state");
    case_state only = CASE_CREATED;
    if (wanted && case_state_parse(wanted, &only) != 0) {
        char detail[200];
        snprintf(detail, sizeof detail, "?state= takes one of created, queued, running, paused, "
                 "finished, stopped, failed; not \"%.64s\"", wanted);
        return http_reply_problem(conn, 400, "Bad request", detail, NULL);
    }
    int count = 0;
    server_case **cases = registry_list(&count);
    json_t *arr = json_array();
    for (int i = 0; i < count; i++) {
        json_t *st = case_status_json(cases[i]);
        /* Filtered on the state in the object itself, so a case changing
         * state meanwhile is listed as it is shown. */
        if (wanted && strcmp(json_string_value(json_object_get(st, "state")), wanted) != 0)
            json_decref(st);
        else
            json_array_append_new(arr, st);
    }
    registry_list_free(cases, count);
    return http_reply_json(conn, 200, json_pack("{s:o}", "cases", arr), NULL);
}

/* 400 (malformed JSON) or 422 (the problems of `what`) with the list. */
static enum MHD_Result routes_reply_problems(struct MHD_Connection *conn, int status,
                                             const problems *p, const char *what)
{
    char detail[640];
    if (status == 400)
        snprintf(detail, sizeof detail, "%s", p->count ? p->items[0].message : "the body is not valid JSON");
    else if (p->dropped)
        snprintf(detail, sizeof detail, "%d problems in the %s; the first %d are listed",
                 p->count + p->dropped, what, p->count);
    else
        snprintf(detail, sizeof detail, "%d problem%s in the %s", p->count,
                 p->count == 1 ? "" : "s", what);
    const char *title = p->title[0] ? p->title : status == 400 ? "Malformed JSON" : "Invalid case";
    return http_reply_problem(conn, (unsigned)status, title, detail, p);
}

static enum MHD_Result route_create_case(struct MHD_Connection *conn, const char *body, size_t size)
{
    if (!http_on_heavy_thread()) /* validating and sizing builds the model */
        return http_defer_heavy(conn);
    int start = routes_flag(conn, "start");
    if (start < 0)
        return http_reply_problem(conn, 400, "Bad request", "?start= takes true or false", NULL);
    int dry_run = routes_flag(conn, "dry_run");
    if (dry_run < 0)
        return http_reply_problem(conn, 400, "Bad request", "?dry_run= takes true or false", NULL);
    if (dry_run && start)
        return http_reply_problem(conn, 400, "Bad request", "?dry_run=true stores nothing, so it "
                                  "cannot be combined with ?start=true", NULL);
    problems p;
    problems_init(&p);
    int status = 0;
    char err[300] = "", warning[400] = "";
    server_case *c = NULL;
    json_t *sizing = NULL;
    if (dry_run)
        sizing = registry_dry_run(body, size, &p, &status);
    else
        c = registry_create(body, size, start, &p, &status, warning, sizeof warning, err, sizeof err);
    enum MHD_Result rc;
    if (sizing) {
        rc = http_reply_json(conn, 200, sizing, NULL);
    } else if (c) {
        char location[64];
        snprintf(location, sizeof location, "/cases/%s", c->id);
        json_t *st = case_status_json(c);
        if (warning[0])
            json_object_set_new(st, "warning", json_string(warning));
        rc = http_reply_json(conn, 201, st, location);
        case_release(c);
    } else if (status == 503) {
        rc = http_reply_unavailable(conn, p.count ? p.items[0].message : "short of memory", &p);
    } else if (status == 400 || status == 422) {
        rc = routes_reply_problems(conn, status, &p, "case");
    } else {
        fprintf(stderr, "fdemd: storing a new case failed: %s\n", err);
        rc = http_reply_problem(conn, 500, "Internal error", err, NULL);
    }
    problems_free(&p);
    return rc;
}

static enum MHD_Result route_command(struct MHD_Connection *conn, server_case *c, route_kind kind)
{
    char msg[256] = "";
    int status = kind == ROUTE_CASE_START ? registry_start(c, msg, sizeof msg)
               : kind == ROUTE_CASE_PAUSE ? registry_pause(c, msg, sizeof msg)
                                          : registry_stop(c, msg, sizeof msg);
    if (status == 0)
        return http_reply_json(conn, 200, case_status_json(c), NULL);
    if (status == 404)
        return routes_no_case(conn, c->id);
    if (status == 503)
        return http_reply_unavailable(conn, msg, NULL);
    if (status == 500)
        return http_reply_problem(conn, 500, "Internal error", msg, NULL);
    return http_reply_problem(conn, (unsigned)status, "Conflict", msg, NULL);
}

/* The state at one step boundary (taken between steps of a running case,
 * rebuilt from the checkpoint of a stopped one) turned into JSON by
 * to_json: GET /state and GET /fragments share the lock and the path. */
static int routes_all_finite(const double *v, size_t n)
{
    for (size_t i = 0; v && i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

static int routes_state_is_finite(const snapshot *s)
{
    size_t nodes = (size_t)s->dimension * (size_t)s->nodes;
    size_t tensors = (size_t)s->stress_components * (size_t)s->elements;
    return isfinite(s->time) && routes_all_finite(s->position, nodes) &&
           routes_all_finite(s->velocity, nodes) && routes_all_finite(s->stress, tensors) &&
           routes_all_finite(s->strain, tensors) && routes_all_finite(s->damage, (size_t)s->joints) &&
           routes_all_finite(s->principal_stress, (size_t)s->dimension * (size_t)s->elements) &&
           routes_all_finite(s->displacement, nodes);
}

/* A failed case has no state to show: the one it failed in may be
 * non-finite (a 200 full of nulls looked like data), and the one it could
 * be rebuilt from is its last checkpoint, from before whatever went wrong.
 * So it is a 409 carrying the case's own error, which says where and why;
 * result.h5 keeps what was written. A state with non-finite numbers that
 * is caught between two steps, before the worker marks the case failed,
 * gets the same answer. Returns 0 when the state may be served. */
static int routes_no_state(struct MHD_Connection *conn, server_case *c, const snapshot *s,
                           enum MHD_Result *rc)
{
    char detail[sizeof c->error + 160];
    pthread_mutex_lock(&c->lock);
    int failed = c->state == CASE_FAILED;
    if (failed)
        snprintf(detail, sizeof detail, "the case failed, so it has no state to show (result.h5 "
                 "keeps the snapshots written before): %s", c->error);
    else
        snprintf(detail, sizeof detail, "the state holds non-finite numbers, which JSON cannot "
                 "carry (the solution became non-finite)");
    pthread_mutex_unlock(&c->lock);
    if (!failed && (!s || routes_state_is_finite(s)))
        return 0;
    *rc = http_reply_problem(conn, 409, failed ? "Case failed" : "State not finite", detail, NULL);
    return 1;
}

/* "stage": {"index", "name"} of the state of a case with stages (contract
 * 6.1 names it in the status; GET /state says it too). A case without
 * stages gets no "stage" here (its state stays as it was). */
static int routes_set_stage(json_t *o, int stage, const char *name)
{
    if (stage < 0) return 0;
    json_t *v = json_pack("{s:i, s:s}", "index", stage, "name", name);
    return v ? json_object_set_new(o, "stage", v) : -1;
}

/* with_stage: the answer names the state's stage (GET /state). */
static enum MHD_Result route_snapshot_json(struct MHD_Connection *conn, server_case *c,
                                           unsigned fields,
                                           json_t *(*to_json)(const snapshot *, const void *),
                                           const void *how, int with_stage)
{
    int status = 0;
    enum MHD_Result rc;
    if (routes_no_state(conn, c, NULL, &rc))
        return rc;
    /* a case that holds no model rebuilds one from its checkpoint to be read */
    if (!http_on_heavy_thread() && !case_holds_model(c))
        return http_defer_heavy(conn);
    char stage_name[CASE_STAGE_NAME] = "";
    snapshot *s = case_take_state(c, fields, &status, stage_name, sizeof stage_name);
    if (!s && status == 503)
        return http_reply_unavailable(conn, "the state of a case that is not running is rebuilt "
                                      "from its checkpoint, and that would take the daemon past "
                                      "its memory budget (--max-memory) now", NULL);
    if (!s)
        return http_reply_problem(conn, 409, "Conflict",
                                  "the stored case could not be rebuilt to read its state", NULL);
    if (routes_no_state(conn, c, s, &rc)) {
        snapshot_free(s);
        return rc;
    }
    /* The JSON tree of a state is ~100 bytes per number: it is charged to
     * the budget, and its pages go back to the OS once it is sent off. */
    membudget_lease lease = {0};
    membudget_meter_begin(&lease, 0);
    json_t *o = to_json(s, how);
    if (o && with_stage && routes_set_stage(o, s->stage, stage_name) != 0) {
        json_decref(o);
        o = NULL;
    }
    membudget_meter_end();
    snapshot_free(s);
    if (!o && membudget_meter_refused())
        rc = http_reply_unavailable(conn, "the JSON form of this state would take the daemon past "
                                    "its memory budget (--max-memory) now", NULL);
    else if (!o)
        rc = http_reply_problem(conn, 409, "Conflict",
                                "the state holds non-finite numbers (the case failed) and has no JSON form", NULL);
    else
        rc = http_reply_json(conn, 200, o, NULL);
    membudget_release(&lease);
    return rc;
}

static json_t *routes_state_json(const snapshot *s, const void *unused)
{
    (void)unused;
    return state_to_json(s);
}

static json_t *routes_fragments_json(const snapshot *s, const void *selection)
{
    return fragments_to_json(s, selection);
}

static enum MHD_Result route_state(struct MHD_Connection *conn, server_case *c)
{
    const char *csv = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "fields");
    unsigned fields = CASE_FIELD_POSITION | CASE_FIELD_VELOCITY;
    if (csv && *csv) {
        problems p;
        problems_init(&p);
        fields = case_parse_fields(csv, &p);
        if (p.count) {
            enum MHD_Result rc = http_reply_problem(conn, 400, "Bad request",
                                                    "unknown field in ?fields=", &p);
            problems_free(&p);
            return rc;
        }
        problems_free(&p);
    }
    return route_snapshot_json(conn, c, fields, routes_state_json, NULL, 1);
}

/* GET /cases/ID/fragments[?parts=a,b][&exclude_host=true] (contract 5.4,
 * issue 33 item 6): the names of ?parts= are read from the case's
 * document, which is heavy work. */
static enum MHD_Result route_fragments(struct MHD_Connection *conn, server_case *c)
{
    fragment_selection sel = {0};
    sel.exclude_host = routes_flag(conn, "exclude_host");
    if (sel.exclude_host < 0)
        return http_reply_problem(conn, 400, "Bad request", "?exclude_host= takes true or false",
                                  NULL);
    const char *parts = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "parts");
    if (parts && !http_on_heavy_thread())
        return http_defer_heavy(conn);
    char detail[700];
    int status = parts ? fragment_query_parts(c, parts, &sel, detail, sizeof detail) : 0;
    if (status == 503)
        return http_reply_unavailable(conn, detail, NULL);
    if (status != 0)
        return http_reply_problem(conn, (unsigned)status, status == 400 ? "Bad request"
                                  : "Internal error", detail, NULL);
    enum MHD_Result rc = route_snapshot_json(conn, c, SNAPSHOT_FRAGMENTS, routes_fragments_json,
                                             &sel, 0);
    fragment_query_free(&sel);
    return rc;
}

/* GET /cases/ID/events?since=T (contract 5.4): the events in result.h5
 * with time > T (all without ?since), so a client that passes the last
 * time it saw gets only what broke after; a step's events are written
 * together, so none of that step is missed. A case without fracture, or
 * not started, has none. */
/* strtod() also reads hexadecimal ("0x10" is 16), "inf" and "nan"; a time
 * in a URL is a decimal number, so anything else is refused before it. */
static int routes_is_decimal(const char *text)
{
    return *text && strspn(text, "0123456789+-.eE") == strlen(text);
}

/* ?since=T of /events and /history: 0 with *since (-inf without it), or -1
 * after the 400 is queued in *rc. */
static int routes_since(struct MHD_Connection *conn, double *since, const char **text,
                        enum MHD_Result *rc)
{
    *text = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "since");
    *since = -INFINITY;
    if (!*text) return 0;
    char *end = NULL;
    errno = 0;
    *since = routes_is_decimal(*text) ? strtod(*text, &end) : NAN;
    if (end && !*end && errno != ERANGE && isfinite(*since)) return 0;
    char detail[160];
    snprintf(detail, sizeof detail, "?since= takes a finite decimal time in seconds "
             "(e.g. 0.0015 or 1.5e-3); not \"%.64s\"", *text);
    *rc = http_reply_problem(conn, 400, "Bad request", detail, NULL);
    return -1;
}

/* The tail of a JSON answer built under the memory meter (the tree o
 * charged to the budget through lease): 200 with it, else 503 when the
 * budget refused it (`what` names the items, "these events"), else 500;
 * the lease is released either way. */
static enum MHD_Result routes_reply_metered(struct MHD_Connection *conn, json_t *o,
                                            membudget_lease *lease, const char *what)
{
    enum MHD_Result rc;
    if (!o && membudget_meter_refused()) {
        char detail[200];
        snprintf(detail, sizeof detail, "the JSON form of %s would take the daemon past its "
                 "memory budget (--max-memory) now; ask for fewer with ?since=", what);
        rc = http_reply_unavailable(conn, detail, NULL);
    } else if (!o) {
        rc = http_reply_problem(conn, 500, "Internal error", "out of memory", NULL);
    } else {
        rc = http_reply_json(conn, 200, o, NULL);
    }
    membudget_release(lease);
    return rc;
}

static enum MHD_Result route_events(struct MHD_Connection *conn, server_case *c)
{
    const char *text = NULL;
    double since = -INFINITY;
    enum MHD_Result bad;
    if (routes_since(conn, &since, &text, &bad) != 0) return bad;
    fdem_event *events = NULL;
    int count = 0, dimension = 0;
    char err[700] = "";
    if (io_read_events(c, since, &events, &count, &dimension, err, sizeof err) != 0)
        return http_reply_problem(conn, 500, "Internal error", err, NULL);
    if (!dimension) {
        pthread_mutex_lock(&c->lock);
        dimension = c->fig.counts.dimension ? c->fig.counts.dimension : 2;
        pthread_mutex_unlock(&c->lock);
    }
    /* about 150 bytes of JSON tree per event, charged to the budget */
    membudget_lease lease = {0};
    membudget_meter_begin(&lease, 0);
    json_t *o = events_to_json(events, count, dimension, text ? &since : NULL);
    membudget_meter_end();
    free(events);
    return routes_reply_metered(conn, o, &lease, "these events");
}

/* GET /cases/ID/history?since=T (contract 6.2): the history rows in
 * result.h5 with time > T (all without ?since), with the point names. */
static enum MHD_Result route_history(struct MHD_Connection *conn, server_case *c)
{
    const char *text = NULL;
    double since = -INFINITY;
    enum MHD_Result rc;
    if (routes_since(conn, &since, &text, &rc) != 0) return rc;
    history_row **rows = NULL;
    int count = 0;
    char err[700] = "";
    history_names names;
    if (io_read_history(c, since, &rows, &count, &names, err, sizeof err) != 0)
        return http_reply_problem(conn, 500, "Internal error", err, NULL);
    /* about 100 bytes of JSON tree per number, charged to the budget */
    membudget_lease lease = {0};
    membudget_meter_begin(&lease, 0);
    json_t *o = history_rows_json(rows, count, &names);
    membudget_meter_end();
    result_free_history(rows, count);
    return routes_reply_metered(conn, o, &lease, "these history rows");
}

static enum MHD_Result route_delete(struct MHD_Connection *conn, server_case *c)
{
    char msg[1400] = "";
    int status = registry_delete(c, msg, sizeof msg);
    if (status == 0)
        return http_reply_empty(conn, 204);
    if (status == 404)
        return routes_no_case(conn, c->id);
    return http_reply_problem(conn, 500, "Not deleted", msg, NULL);
}

static enum MHD_Result route_extend(struct MHD_Connection *conn, server_case *c, const char *body,
                                    size_t size)
{
    problems p;
    problems_init(&p);
    char msg[640] = "";
    int status = registry_extend(c, body, size, &p, msg, sizeof msg);
    enum MHD_Result rc;
    if (status == 0)
        rc = http_reply_json(conn, 200, case_status_json(c), NULL);
    else if (status == 404)
        rc = routes_no_case(conn, c->id);
    else if (status == 400 || status == 422)
        rc = routes_reply_problems(conn, status, &p, "request");
    else if (status == 409)
        rc = http_reply_problem(conn, 409, "Conflict", msg, NULL);
    else
        rc = http_reply_problem(conn, 500, "Internal error", msg, NULL);
    problems_free(&p);
    return rc;
}

/* 1 when the body says it is a JSON Patch (RFC 6902): Content-Type
 * application/json-patch+json, parameters and case aside. Any other type,
 * or none, is a JSON Merge Patch, as before JSON Patch was taken (curl's
 * --data sends application/x-www-form-urlencoded). */
static int routes_is_json_patch(struct MHD_Connection *conn)
{
    static const char json_patch[] = "application/json-patch+json";
    const char *type = MHD_lookup_connection_value(conn, MHD_HEADER_KIND,
                                                   MHD_HTTP_HEADER_CONTENT_TYPE);
    if (!type)
        return 0;
    type += strspn(type, " \t");
    size_t n = strcspn(type, "; \t");
    return n == strlen(json_patch) && strncasecmp(type, json_patch, n) == 0;
}

/* The patched document then goes the way of any POST /cases body. */
static enum MHD_Result route_clone(struct MHD_Connection *conn, server_case *c, const char *body,
                                   size_t size)
{
    if (!http_on_heavy_thread())
        return http_defer_heavy(conn);
    problems p;
    problems_init(&p);
    int status = 0;
    char err[640] = "";
    size_t length = 0;
    char *doc = registry_clone_document(c, body, size, routes_is_json_patch(conn), &length, &p,
                                        &status, err, sizeof err);
    membudget_lease *lease = membudget_request_lease();
    enum MHD_Result rc;
    if (!doc && (status == 400 || status == 422))
        rc = routes_reply_problems(conn, status, &p, "patch");
    else if (!doc && status == 404)
        rc = routes_no_case(conn, c->id);
    else if (!doc && status == 503)
        rc = http_reply_unavailable(conn, err, NULL);
    else if (!doc)
        rc = http_reply_problem(conn, 500, "Internal error", err, NULL);
    else if (lease && membudget_grow(lease, membudget_upload_cost(length)) != 0)
        rc = http_reply_unavailable(conn, "parsing the patched case would take the daemon past "
                                    "its memory budget (--max-memory) now; try again later", NULL);
    else
        rc = route_create_case(conn, doc, length);
    free(doc);
    problems_free(&p);
    return rc;
}

static enum MHD_Result route_case(struct MHD_Connection *conn, server_case *c, route_kind kind,
                                  const char *method, const char *body, size_t body_size)
{
    switch (kind) {
    case ROUTE_CASE:
        if (strcmp(method, "DELETE") == 0)
            return route_delete(conn, c);
        return http_reply_json(conn, 200, case_status_json(c), NULL);
    case ROUTE_CASE_START: case ROUTE_CASE_PAUSE: case ROUTE_CASE_STOP:
        return route_command(conn, c, kind);
    case ROUTE_CASE_DOCUMENT:
        return routes_serve_file(conn, c, "case.json", "application/json");
    case ROUTE_CASE_STATE:
        return route_state(conn, c);
    case ROUTE_CASE_FRAGMENTS:
        return route_fragments(conn, c);
    case ROUTE_CASE_EVENTS:
        return route_events(conn, c);
    case ROUTE_CASE_HISTORY:
        return route_history(conn, c);
    case ROUTE_CASE_MESH:
        return mesh_frame_reply(conn, c);
    case ROUTE_CASE_RESULT_H5:
        return download_reply(conn, c, strcmp(method, "HEAD") == 0);
    case ROUTE_CASE_RESULT_XDMF:
        io_refresh_xdmf(c);
        return routes_serve_file(conn, c, "result.xdmf", "application/xml");
    case ROUTE_CASE_EXTEND:
        return route_extend(conn, c, body, body_size);
    case ROUTE_CASE_CLONE:
        return route_clone(conn, c, body, body_size);
    default:
        return http_reply_problem(conn, 404, "Not found", "no such path", NULL);
    }
}

enum MHD_Result routes_handle(struct MHD_Connection *conn, const route_match *m,
                              const char *method, const char *body, size_t body_size)
{
    if (m->kind == ROUTE_HEALTH)
        return route_health(conn);
    if (m->kind == ROUTE_STREAM)
        return stream_open(conn);
    if (m->kind == ROUTE_WEB)
        return web_reply(conn, m->url);
    if (m->kind == ROUTE_CASES)
        return strcmp(method, "POST") == 0 ? route_create_case(conn, body, body_size)
                                           : route_list_cases(conn);
    server_case *c = registry_find(m->id);
    if (!c)
        return routes_no_case(conn, m->id);
    registry_ensure_checked(c);
    enum MHD_Result rc = route_case(conn, c, m->kind, method, body, body_size);
    case_release(c);
    return rc;
}
