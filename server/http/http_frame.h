/*
 * http_frame.h - checks on the raw header block of a request that decide
 * how its body is framed (Content-Length, Transfer-Encoding), done before
 * libmicrohttpd sees the request.
 *
 * Contract: pure functions on plain bytes (no sockets, no globals), so the
 * gate and the fuzzer call the same code.
 *  - http_frame_head_end() finds the blank line that ends the header block
 *    (CRLF or bare LF line ends, as libmicrohttpd accepts both).
 *  - http_frame_check() accepts a block whose body length is unambiguous:
 *    no Transfer-Encoding, and every Content-Length field is 1*DIGIT (after
 *    leading blanks) with the same value. Anything else gets a status (400,
 *    411 or 413) and a one-line reason for the client.
 *  - It also refuses, so that libmicrohttpd never answers them itself (in
 *    HTML, or not at all): a request line that is not METHOD SP target SP
 *    HTTP/d.d (400) or of another version than 1.0 and 1.1 (505), more
 *    than 64 query parameters (414) or 100 header fields (431), a header
 *    line without "name:" (400), and a NUL byte anywhere (400, with
 *    nul_in_credentials set when it is in the Authorization field).
 */
#ifndef FDEMD_HTTP_FRAME_H
#define FDEMD_HTTP_FRAME_H

#include <stddef.h>

/* The most query parameters a request may carry (no route takes more
 * than two; see http_frame.c for why there is a bound at all). */
#define HTTP_FRAME_MAX_QUERY 64

typedef struct http_frame_verdict {
    int status;        /* 0 when the framing is acceptable */
    char title[48];    /* "Bad request", ... */
    char detail[200];
    long long content_length; /* the agreed value when acceptable, else -1 */
    int nul_in_credentials;   /* the NUL refused is in the Authorization field */
} http_frame_verdict;

/* Offset just past the blank line ending the header block, or 0 if `data`
 * does not hold a whole block yet. */
size_t http_frame_head_end(const char *data, size_t size);

/* Checks the header block head[0..size). Returns v->status. */
int http_frame_check(const char *head, size_t size, http_frame_verdict *v);

#endif
