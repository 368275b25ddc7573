/*
 * routes.h - the API's paths, which methods each allows, and one function
 * per route (contract section 2).
 *
 * Contract: routes_match() only looks at the path's shape; a segment that
 * is not a 16-hex-digit id never reaches the registry or the file system,
 * so "..", "%2F" and friends are plain 404s.
 */
#ifndef FDEMD_ROUTES_H
#define FDEMD_ROUTES_H

#include <stddef.h>
#include <microhttpd.h>

#include "cases/registry.h"

typedef enum route_kind {
    ROUTE_NONE, ROUTE_HEALTH, ROUTE_CASES, ROUTE_CASE, ROUTE_CASE_START, ROUTE_CASE_PAUSE,
    ROUTE_CASE_STOP, ROUTE_CASE_DOCUMENT, ROUTE_CASE_STATE, ROUTE_CASE_RESULT_H5,
    ROUTE_CASE_RESULT_XDMF, ROUTE_CASE_FRAGMENTS, ROUTE_CASE_EXTEND, ROUTE_CASE_CLONE,
    ROUTE_CASE_EVENTS, ROUTE_CASE_HISTORY, ROUTE_STREAM,
    ROUTE_CASE_MESH, ROUTE_WEB,
} route_kind;

typedef struct route_match {
    route_kind kind;
    char id[CASE_ID_LEN + 1]; /* "" unless the path names a valid id */
    int bad_id;               /* /cases/X... with an X that is not an id (its 404 says so) */
    const char *url;          /* ROUTE_WEB: the path (libmicrohttpd's, alive for the request) */
} route_match;

void routes_match(const char *url, route_match *out);
/* "GET, HEAD, POST" etc., for 405 and its Allow header. */
const char *routes_allowed(route_kind kind);
int routes_method_allowed(route_kind kind, const char *method);
int routes_takes_body(route_kind kind, const char *method);
/* 0 when every query argument is one the route takes, each at most once;
 * else -1 with a sentence naming the offending one (a 400). */
int routes_check_query(struct MHD_Connection *conn, route_kind kind, const char *method,
                       char *detail, size_t detail_size);

enum MHD_Result routes_handle(struct MHD_Connection *conn, const route_match *m,
                              const char *method, const char *body, size_t body_size);

#endif
