/*
 * http_frame.c - is the body of this request framed unambiguously?
 *
 * libmicrohttpd 0.9.75 decides the framing itself, before the daemon sees a
 * request, and gets three cases wrong: a malformed Content-Length ("-1",
 * "0x10", "+2", "8 ") is answered with a 400 whose status line is sent
 * twice; two disagreeing Content-Length fields are accepted (the first
 * wins, the classic request-smuggling ambiguity RFC 9112 section 6.3 forbids);
 * and any Transfer-Encoding but "chunked" makes it read the body until the
 * client closes, so "Transfer-Encoding: identity" hung for the whole
 * connection timeout. The gate runs these checks on the header block first
 * and answers such requests itself, once and cleanly.
 *
 * The rules are as strict as libmicrohttpd where it is strict (a value with
 * a trailing blank is refused, because it would refuse it too) and stricter
 * where it is lax: obsolete line folding and blanks before the colon are
 * refused (RFC 9112 section 5), since a folded Content-Length could be read
 * differently by the two parsers.
 */
#include "http_frame.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

#define FRAME_MAX_DIGITS 18 /* below 10^18: fits a long long, and far above --max-upload */
/* Each query parameter and header field costs libmicrohttpd a record in the
 * connection's 64 KiB memory pool; when the pool runs out it tries to send
 * an HTML error from that same pool, cannot, and holds the connection
 * silently until its 30 s timeout (issue 30: 1,000 query parameters). No
 * route takes more than two parameters, and real clients send a dozen
 * fields, so these bounds refuse only what is hostile, and they keep the
 * records of a whole 32 KiB header block well inside the pool. */
#define FRAME_MAX_QUERY_PARAMETERS HTTP_FRAME_MAX_QUERY
#define FRAME_MAX_FIELDS 100

/* Empty lines before the request line are skipped (RFC 9112 section 2.2,
 * and libmicrohttpd does too), so they neither end nor start the block. */
static size_t frame_skip_empty_lines(const char *data, size_t size)
{
    size_t i = 0;
    while (i < size && (data[i] == '\r' || data[i] == '\n')) i++;
    return i;
}

size_t http_frame_head_end(const char *data, size_t size)
{
    for (size_t i = frame_skip_empty_lines(data, size); i + 1 < size; i++) {
        if (data[i] != '\n') continue;
        if (data[i + 1] == '\n') return i + 2;
        if (data[i + 1] == '\r' && i + 2 < size && data[i + 2] == '\n') return i + 3;
    }
    return 0;
}

static int frame_refuse(http_frame_verdict *v, int status, const char *title,
                        const char *detail)
{
    v->status = status;
    snprintf(v->title, sizeof v->title, "%s", title);
    snprintf(v->detail, sizeof v->detail, "%s", detail);
    return status;
}

static int frame_is_blank(char c)
{
    return c == ' ' || c == '\t';
}

/* The field name is exactly `want` (any case), followed directly by ':'. */
static int frame_name_is(const char *line, size_t name_len, const char *want)
{
    return name_len == strlen(want) && strncasecmp(line, want, name_len) == 0;
}

typedef struct frame_lengths {
    int count;
    unsigned long long value;
    int te; /* a Transfer-Encoding field was seen */
    int fields;
} frame_lengths;

/* One Content-Length value: blanks, then 1 to 19 digits, then the line end. */
static int frame_read_length(const char *value, size_t len, frame_lengths *seen,
                             http_frame_verdict *v)
{
    size_t i = 0;
    while (i < len && frame_is_blank(value[i])) i++;
    size_t start = i;
    unsigned long long n = 0;
    while (i < len && value[i] >= '0' && value[i] <= '9') {
        if (i - start == FRAME_MAX_DIGITS)
            return frame_refuse(v, 413, "Payload too large",
                                "Content-Length is larger than any body this daemon accepts");
        n = 10 * n + (unsigned long long)(value[i] - '0');
        i++;
    }
    if (i == start || i != len)
        return frame_refuse(v, 400, "Bad request",
                            "Content-Length must be a decimal number of bytes (digits only, "
                            "no sign, no blanks after it)");
    if (seen->count++ > 0 && n != seen->value) {
        char detail[sizeof v->detail];
        snprintf(detail, sizeof detail,
                 "two Content-Length fields disagree (%llu and %llu); send one", seen->value, n);
        return frame_refuse(v, 400, "Bad request", detail);
    }
    seen->value = n;
    return 0;
}

/* The request line: METHOD SP target SP HTTP/1.x. libmicrohttpd answers a
 * malformed one with an HTML page (or not at all) and another version with
 * an HTML 505; here both get a problem+json answer like every other error.
 * Also counts the query parameters of the target (see
 * FRAME_MAX_QUERY_PARAMETERS). */
static int frame_check_request_line(const char *line, size_t len, http_frame_verdict *v)
{
    const char *sp1 = memchr(line, ' ', len);
    const char *sp2 = sp1 ? memchr(sp1 + 1, ' ', len - (size_t)(sp1 + 1 - line)) : NULL;
    const char *version = sp2 ? sp2 + 1 : NULL;
    size_t version_len = version ? len - (size_t)(version - line) : 0;
    if (!sp1 || sp1 == line || !sp2 || sp2 == sp1 + 1 || memchr(version, ' ', version_len))
        return frame_refuse(v, 400, "Bad request",
                            "the request line must be METHOD /path HTTP/1.1 (three parts "
                            "separated by single spaces)");
    if (version_len != 8 || strncmp(version, "HTTP/", 5) != 0 || version[5] < '0' ||
        version[5] > '9' || version[6] != '.' || version[7] < '0' || version[7] > '9')
        return frame_refuse(v, 400, "Bad request",
                            "the request line must end with the protocol version, HTTP/1.1");
    if (version[5] != '1' || (version[7] != '0' && version[7] != '1')) {
        char detail[sizeof v->detail];
        snprintf(detail, sizeof detail, "this daemon speaks HTTP/1.1 (and 1.0), not %.8s",
                 version);
        return frame_refuse(v, 505, "HTTP version not supported", detail);
    }
    const char *target = sp1 + 1;
    size_t target_len = (size_t)(sp2 - target);
    const char *query = memchr(target, '?', target_len);
    if (!query) return 0;
    long parameters = 1;
    for (const char *p = query + 1; p < sp2; p++) parameters += *p == '&';
    if (parameters > FRAME_MAX_QUERY_PARAMETERS) {
        char detail[sizeof v->detail];
        snprintf(detail, sizeof detail,
                 "the request has %ld query parameters; this daemon takes at most %d (no route "
                 "takes more than two)", parameters, FRAME_MAX_QUERY_PARAMETERS);
        return frame_refuse(v, 414, "Too many query parameters", detail);
    }
    return 0;
}

/* One header line (without its line end). */
static int frame_check_line(const char *line, size_t len, frame_lengths *seen,
                            http_frame_verdict *v)
{
    if (len > 0 && frame_is_blank(line[0]))
        return frame_refuse(v, 400, "Bad request",
                            "a header line starts with a blank (obsolete line folding is not "
                            "accepted)");
    const char *colon = memchr(line, ':', len);
    if (!colon || colon == line)
        return frame_refuse(v, 400, "Bad request",
                            "a header line is not \"Name: value\" (it has no field name or "
                            "no colon)");
    if (++seen->fields > FRAME_MAX_FIELDS) {
        char detail[sizeof v->detail];
        snprintf(detail, sizeof detail, "the request has more than %d header fields",
                 FRAME_MAX_FIELDS);
        return frame_refuse(v, 431, "Request header fields too large", detail);
    }
    size_t name_len = (size_t)(colon - line);
    if (name_len > 0 && frame_is_blank(line[name_len - 1]))
        return frame_refuse(v, 400, "Bad request", "a header field name is followed by a blank");
    const char *value = colon + 1;
    size_t value_len = len - name_len - 1;
    if (frame_name_is(line, name_len, "Content-Length"))
        return frame_read_length(value, value_len, seen, v);
    if (frame_name_is(line, name_len, "Transfer-Encoding")) seen->te = 1;
    return 0;
}

/* libmicrohttpd reads every line as a C string, so a NUL cuts a line short
 * unseen: "Authorization: Bearer T\\0junk" was taken for the token "T".
 * RFC 9110 section 5.5 lets a recipient refuse such a field; here the
 * whole request is refused, and the gate makes it a 401 when the field is
 * the credentials and the daemon wants a token. */
static int frame_check_nul(const char *head, size_t size, http_frame_verdict *v)
{
    const char *nul = memchr(head, '\0', size);
    if (!nul) return 0;
    const char *line = nul;
    while (line > head && line[-1] != '\n') line--;
    v->nul_in_credentials = (size_t)(nul - line) >= 14 && strncasecmp(line, "Authorization:", 14) == 0;
    return frame_refuse(v, 400, "Bad request",
                        v->nul_in_credentials ? "the Authorization header holds a NUL byte"
                                              : "the request line or a header holds a NUL byte");
}

int http_frame_check(const char *head, size_t size, http_frame_verdict *v)
{
    memset(v, 0, sizeof *v);
    v->content_length = -1;
    frame_lengths seen = {0, 0, 0, 0};
    const char *p = head + frame_skip_empty_lines(head, size), *end = head + size;
    if (frame_check_nul(p, (size_t)(end - p), v)) return v->status;
    int first = 1;
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        size_t len = (size_t)((nl ? nl : end) - p);
        if (len > 0 && p[len - 1] == '\r') len--;
        if (len == 0 && !first) break; /* the blank line */
        if (first ? frame_check_request_line(p, len, v) : frame_check_line(p, len, &seen, v))
            return v->status;
        first = 0;
        if (!nl) break;
        p = nl + 1;
    }
    if (seen.te && seen.count)
        return frame_refuse(v, 400, "Bad request",
                            "Transfer-Encoding together with Content-Length; send the body "
                            "with Content-Length alone");
    if (seen.te)
        return frame_refuse(v, 411, "Length required",
                            "send the body with a Content-Length header and no "
                            "Transfer-Encoding (chunked uploads are not accepted)");
    if (seen.count) v->content_length = (long long)seen.value; /* < 10^18: fits */
    return 0;
}
