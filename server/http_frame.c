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

/* One header line (without its line end). */
static int frame_check_line(const char *line, size_t len, frame_lengths *seen,
                            http_frame_verdict *v)
{
    if (len > 0 && frame_is_blank(line[0]))
        return frame_refuse(v, 400, "Bad request",
                            "a header line starts with a blank (obsolete line folding is not "
                            "accepted)");
    const char *colon = memchr(line, ':', len);
    if (!colon) return 0; /* not a field; libmicrohttpd judges it */
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

int http_frame_check(const char *head, size_t size, http_frame_verdict *v)
{
    memset(v, 0, sizeof *v);
    v->content_length = -1;
    frame_lengths seen = {0, 0, 0};
    const char *p = head + frame_skip_empty_lines(head, size), *end = head + size;
    int first = 1;
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        size_t len = (size_t)((nl ? nl : end) - p);
        if (len > 0 && p[len - 1] == '\r') len--;
        if (len == 0 && !first) break; /* the blank line */
        if (!first && frame_check_line(p, len, &seen, v)) return v->status;
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
