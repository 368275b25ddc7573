/*
 * http_keepalive.c - what a kept-alive connection's later requests need
 * (http.h): whether the client asks to close after this request, and the
 * framing checks the gate makes on a first request's raw bytes, made on a
 * later one from the fields libmicrohttpd parsed, since the gate never sees
 * those bytes. Apart from http.c because it is one job with its own data
 * (the rebuilt header block) and http.c had passed 800 lines.
 */
#include <microhttpd.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "http.h"
#include "http_frame.h"

/* Does the client want its connection closed after this request? It says
 * "Connection: close", or speaks HTTP/1.0 without asking to keep alive. */
static int http_has_token(const char *list, const char *token)
{
    size_t n = strlen(token);
    for (const char *p = list; p && *p; p++)
        if (strncasecmp(p, token, n) == 0)
            return 1;
    return 0;
}

int http_client_closes(struct MHD_Connection *conn, const char *version)
{
    const char *c = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONNECTION);
    if (http_has_token(c, "close"))
        return 1;
    return strcmp(version, MHD_HTTP_VERSION_1_0) == 0 && !http_has_token(c, "keep-alive");
}

/* The header block of a later request on a kept-alive connection, as
 * libmicrohttpd parsed it, rebuilt for http_frame_check: the gate read the
 * first request's raw bytes, but libmicrohttpd reads the later ones itself. */
typedef struct http_rebuilt {
    char text[32 * 1024];
    size_t size;
    int overflow;
} http_rebuilt;

static enum MHD_Result http_rebuild_field(void *cls, enum MHD_ValueKind kind, const char *key,
                                          const char *value)
{
    (void)kind;
    http_rebuilt *b = cls;
    size_t room = sizeof b->text - b->size;
    int n = snprintf(b->text + b->size, room, "%s: %s\r\n", key, value ? value : "");
    if (n < 0 || (size_t)n + 2 >= room) { /* + the blank line */
        b->overflow = 1;
        return MHD_NO;
    }
    b->size += (size_t)n;
    return MHD_YES;
}

/* The framing checks the gate makes on a first request, made on a later
 * one from its parsed fields (disagreeing lengths, Transfer-Encoding, too
 * many fields or query parameters). libmicrohttpd has read no body yet.
 * Returns 1 when an answer was queued in *rc. What the parsed fields can no
 * longer show (a malformed Content-Length, which libmicrohttpd answers
 * itself before this) is in docs/api.md. */
int http_refuse_bad_framing(struct MHD_Connection *conn, const char *method,
                                   const char *version, enum MHD_Result *rc)
{
    static _Thread_local http_rebuilt b;
    b.size = 0;
    b.overflow = 0;
    int n = snprintf(b.text, sizeof b.text, "%s / %s\r\n", method, version);
    b.size = n > 0 ? (size_t)n : 0;
    MHD_get_connection_values(conn, MHD_HEADER_KIND, http_rebuild_field, &b);
    http_frame_verdict v;
    if (b.overflow) {
        *rc = http_reply_problem(conn, 431, "Request header fields too large",
                                 "the request line and headers exceed 32 KiB", NULL);
        return 1;
    }
    memcpy(b.text + b.size, "\r\n", 2);
    if (http_frame_check(b.text, b.size + 2, &v)) {
        *rc = http_reply_problem(conn, (unsigned)v.status, v.title, v.detail, NULL);
        return 1;
    }
    if (MHD_get_connection_values(conn, MHD_GET_ARGUMENT_KIND, NULL, NULL) > HTTP_FRAME_MAX_QUERY) {
        *rc = http_reply_problem(conn, 414, "Too many query parameters",
                                 "the request has more query parameters than any route takes",
                                 NULL);
        return 1;
    }
    return 0;
}
