/*
 * mesh_frame.c - the route of the web page's binary snapshot frames
 * (mesh_frame.h). The bytes are built by proto/result/result_frame.c on
 * the I/O thread, where every HDF5 call is made; this file only reads the
 * query and turns the answer into HTTP.
 */
#include "mesh_frame.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cases/io_thread.h"
#include "common/memory_budget.h"
#include "http.h"

/* ?snapshot=K: -1 without it, else K (0 or more); -2 when it is not one. */
static int mesh_frame_snapshot(struct MHD_Connection *conn)
{
    const char *v = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "snapshot");
    if (!v)
        return -1;
    if (!*v || strspn(v, "0123456789") != strlen(v) || strlen(v) > 9)
        return -2;
    return atoi(v);
}

/* ?fields=a,b: the bits of result_frame_field_names; every name without
 * it. -1 with the 400's detail for an unknown name. */
static int mesh_frame_fields(struct MHD_Connection *conn, unsigned *bits, char *detail,
                             size_t size)
{
    const char *csv = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "fields");
    *bits = csv ? 0u : (1u << RESULT_FRAME_FIELDS) - 1;
    for (const char *p = csv; p && *p; ) {
        size_t n = strcspn(p, ",");
        int found = -1;
        for (int k = 0; k < RESULT_FRAME_FIELDS; k++)
            if (strlen(result_frame_field_names[k]) == n &&
                strncmp(p, result_frame_field_names[k], n) == 0)
                found = k;
        if (found < 0 && n > 0) {
            char names[200] = "";
            for (int k = 0; k < RESULT_FRAME_FIELDS; k++)
                snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s",
                         k ? ", " : "", result_frame_field_names[k]);
            snprintf(detail, size, "unknown field \"%.*s\" in ?fields=; a frame carries %s",
                     (int)(n > 64 ? 64 : n), p, names);
            return -1;
        }
        if (found >= 0)
            *bits |= 1u << found;
        p += n;
        if (*p == ',')
            p++;
    }
    return 0;
}

/* ?surface=true|false (also 1/0, yes/no, empty for true): 0 or 1, -1 when
 * it is none of them. */
static int mesh_frame_surface(struct MHD_Connection *conn)
{
    const char *v = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "surface");
    if (!v)
        return 0;
    if (!*v || !strcmp(v, "true") || !strcmp(v, "1") || !strcmp(v, "yes"))
        return 1;
    return !strcmp(v, "false") || !strcmp(v, "0") || !strcmp(v, "no") ? 0 : -1;
}

/* ?shape=KEY: the 16 hex digits of a shape key the client holds. 0 and
 * q->has_shape_key set when given, -1 when it is not 16 hex digits. */
static int mesh_frame_shape(struct MHD_Connection *conn, result_frame_request *q)
{
    const char *v = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "shape");
    if (!v)
        return 0;
    if (strlen(v) != 16 || strspn(v, "0123456789abcdefABCDEF") != 16)
        return -1;
    q->has_shape_key = 1;
    q->shape_key = strtoull(v, NULL, 16);
    return 0;
}

/* Called on the I/O thread with the frame's size, before it is allocated. */
static int mesh_frame_reserve(void *lease, size_t bytes)
{
    return lease ? membudget_grow(lease, bytes) : 0;
}

enum MHD_Result mesh_frame_reply(struct MHD_Connection *conn, server_case *c)
{
    result_frame_request q = {mesh_frame_snapshot(conn), 0, mesh_frame_reserve,
                              membudget_request_lease(), mesh_frame_surface(conn), 0, 0,
                              NULL, NULL};
    char detail[400] = "";
    if (q.snapshot == -2)
        return http_reply_problem(conn, 400, "Bad request",
                                  "?snapshot= takes a snapshot index, 0 or more", NULL);
    if (q.surface < 0)
        return http_reply_problem(conn, 400, "Bad request", "?surface= takes true or false",
                                  NULL);
    if (mesh_frame_shape(conn, &q) != 0)
        return http_reply_problem(conn, 400, "Bad request",
                                  "?shape= takes the 16 hex digits of a frame's shape key", NULL);
    if (mesh_frame_fields(conn, &q.fields, detail, sizeof detail) != 0)
        return http_reply_problem(conn, 400, "Bad request", detail, NULL);
    unsigned char *bytes = NULL;
    size_t size = 0;
    int rc = io_read_frame(c, &q, &bytes, &size, detail, sizeof detail);
    if (rc == 404)
        return http_reply_problem(conn, 404, "Not found", detail, NULL);
    if (rc == 503)
        return http_reply_unavailable(conn, detail, NULL);
    if (rc != 0)
        return http_reply_problem(conn, 500, "Internal error", detail, NULL);
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(size, bytes, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        free(bytes);
        return http_reply_problem(conn, 500, "Internal error", "out of memory", NULL);
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, "application/octet-stream");
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    return http_reply_response(conn, 200, resp);
}
