/*
 * server/http/ - the daemon's front end: everything between a client's
 * socket and the case lifecycle.
 *  - Owns: accepting and holding connections (gate.c) and the framing
 *    checks on a raw header block (http_frame.c); libmicrohttpd, request
 *    bodies, authentication and the reply helpers (this header, http.c),
 *    a kept-alive connection's later requests (http_keepalive.c);
 *    one function per API route (routes.c); result.h5 downloads
 *    (download.c); the web page's files (web.c) and its binary snapshot
 *    frames (mesh_frame.c); the threads for requests that build a model
 *    (heavy_work.c); GET /stream's event streams (stream.c).
 *  - May call: cases/ (registry.h, case_continue.h, io_thread.h), common/
 *    (config.h, memory_budget.h), proto/ and core/.
 *  - Called by: main.c only (http_start, http_stop). Nothing in cases/,
 *    store/ or common/ calls back into this folder.
 */
/*
 * http.h - the libmicrohttpd daemon: connection handling, request bodies,
 * authentication, and the response helpers the routes use.
 *
 * Contract:
 *  - http_start() binds cfg->listen_host:listen_port and returns the port
 *    actually bound (useful for port 0), or -1 with a message on stderr.
 *  - Connections come through the gate (gate.h): per-address cap, header
 *    deadline, framing checks. Each response closes its connection, so
 *    every request passes the gate.
 *  - Requests are checked before their body is read: 401 (token), 404/405
 *    (route), 411 (POST /cases without Content-Length), 413 (Content-Length
 *    above --max-upload, or any body on a route that takes none: such a
 *    body is never held). Only then is the body collected, against the
 *    memory budget, and the route called; a request not whole by
 *    --request-timeout gets 408 or is cut.
 *  - Every error body is RFC 9457 problem+json with an "errors" list.
 */
#ifndef FDEMD_HTTP_H
#define FDEMD_HTTP_H

#include <stddef.h>
#include <jansson.h>
#include <microhttpd.h>

#include "common/config.h"
#include "json/problems.h"

int http_start(const fdemd_config *cfg);
void http_stop(void);

/* The json is consumed. */
enum MHD_Result http_reply_json(struct MHD_Connection *conn, unsigned status, json_t *body,
                                const char *location);
enum MHD_Result http_reply_problem(struct MHD_Connection *conn, unsigned status, const char *title,
                                   const char *detail, const problems *p);
/* 503 with Retry-After: MEMBUDGET_RETRY_AFTER (the daemon is short of memory). */
enum MHD_Result http_reply_unavailable(struct MHD_Connection *conn, const char *detail,
                                       const problems *p);
enum MHD_Result http_reply_not_allowed(struct MHD_Connection *conn, const char *allow);
enum MHD_Result http_reply_empty(struct MHD_Connection *conn, unsigned status);
/* A route whose work is a model build calls http_defer_heavy() (and returns
 * what it returns) unless http_on_heavy_thread(): the request is then run
 * again, whole, on a heavy-work thread (heavy_work.h) while its connection
 * waits suspended, so the threads that answer HTTP never build models. */
enum MHD_Result http_defer_heavy(struct MHD_Connection *conn);
int http_on_heavy_thread(void);
/* Queues an event stream (stream.c), text/event-stream: its connection
 * leaves the per-address count and the request deadline (gate.h), is cut
 * after `idle_timeout` s in which its client reads nothing, and closes
 * when the stream ends. */
enum MHD_Result http_reply_stream(struct MHD_Connection *conn, struct MHD_Response *resp,
                                  unsigned idle_timeout);
/* Queues a response a route built itself (consumed; NULL answers nothing). */
enum MHD_Result http_reply_response(struct MHD_Connection *conn, unsigned status,
                                    struct MHD_Response *resp);
/* Serves `size` bytes of an open descriptor (closed by libmicrohttpd). */
enum MHD_Result http_reply_fd(struct MHD_Connection *conn, int fd, size_t size,
                              const char *content_type, const char *filename);

/* http_keepalive.c, for http.c's request phases: does the client want its
 * connection closed after this request ("Connection: close", or HTTP/1.0
 * without keep-alive); and the gate's framing checks on a later request of
 * a kept-alive connection (1 with its answer queued in *rc). */
int http_client_closes(struct MHD_Connection *conn, const char *version);
int http_refuse_bad_framing(struct MHD_Connection *conn, const char *method,
                            const char *version, enum MHD_Result *rc);

#endif
