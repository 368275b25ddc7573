/*
 * test_http_frame.c - the framing checks the gate runs on a request's
 * header block (server/http/http_frame.c) before libmicrohttpd sees it.
 *
 * Unit tests link only below the server, so the one pure server file under
 * test is compiled into this binary directly.
 */
#include "../../server/http/http_frame.c"

#include "check.h"

static int verdict(const char *head, http_frame_verdict *v)
{
    return http_frame_check(head, strlen(head), v);
}

#define POST "POST /cases HTTP/1.1\r\nHost: x\r\n"

static void head_end_finds_the_blank_line(void)
{
    const char *crlf = "GET / HTTP/1.1\r\nHost: x\r\n\r\nbody";
    CHECK(http_frame_head_end(crlf, strlen(crlf)) == strlen(crlf) - 4, "CRLF");
    const char *lf = "GET / HTTP/1.1\nHost: x\n\nbody";
    CHECK(http_frame_head_end(lf, strlen(lf)) == strlen(lf) - 4, "bare LF");
    const char *partial = "GET / HTTP/1.1\r\nHost: x\r\n";
    CHECK(http_frame_head_end(partial, strlen(partial)) == 0, "not whole yet");
    /* empty lines before the request line neither end nor start the block */
    const char *lead = "\r\n\r\nPOST /cases HTTP/1.1\r\nContent-Length: -1\r\n\r\n";
    size_t end = http_frame_head_end(lead, strlen(lead));
    CHECK(end == strlen(lead), "got %zu of %zu", end, strlen(lead));
    http_frame_verdict v;
    CHECK(http_frame_check(lead, end, &v) == 400, "the length after leading lines is checked");
}

static void plain_lengths_are_accepted(void)
{
    http_frame_verdict v;
    CHECK(verdict(POST "Content-Length: 42\r\n\r\n", &v) == 0, "%s", v.detail);
    CHECK(v.content_length == 42, "got %lld", v.content_length);
    CHECK(verdict(POST "content-length:\t7\r\n\r\n", &v) == 0, "any case, leading tab");
    CHECK(v.content_length == 7, "got %lld", v.content_length);
    CHECK(verdict(POST "Content-Length: 5\r\nContent-Length: 5\r\n\r\n", &v) == 0,
          "the same value twice is unambiguous");
    CHECK(verdict("GET /health HTTP/1.1\r\n\r\n", &v) == 0 && v.content_length == -1,
          "no length at all");
}

static void malformed_lengths_are_400(void)
{
    const char *bad[] = {"-1", "0x10", "+2", "8 ", "", "8, 8", "1e3", "１"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        char head[128];
        snprintf(head, sizeof head, POST "Content-Length: %s\r\n\r\n", bad[i]);
        http_frame_verdict v;
        CHECK(verdict(head, &v) == 400, "\"%s\" gave %d", bad[i], v.status);
        CHECK(strstr(v.detail, "Content-Length") != NULL, "%s", v.detail);
    }
}

static void disagreeing_lengths_are_400(void)
{
    http_frame_verdict v;
    CHECK(verdict(POST "Content-Length: 8\r\nContent-Length: 2\r\n\r\n", &v) == 400, "%d",
          v.status);
    CHECK(strstr(v.detail, "8 and 2") != NULL, "%s", v.detail);
}

static void huge_lengths_are_413(void)
{
    http_frame_verdict v;
    CHECK(verdict(POST "Content-Length: 999999999999999999\r\n\r\n", &v) == 0,
          "18 digits still parse");
    CHECK(verdict(POST "Content-Length: 1000000000000000000\r\n\r\n", &v) == 413, "19 digits");
    CHECK(verdict(POST "Content-Length: 99999999999999999999999\r\n\r\n", &v) == 413, "overflow");
}

static void transfer_encoding_is_refused(void)
{
    http_frame_verdict v;
    CHECK(verdict(POST "Transfer-Encoding: identity\r\nContent-Length: 2\r\n\r\n", &v) == 400,
          "with a length: ambiguous");
    CHECK(verdict(POST "Transfer-Encoding: chunked\r\n\r\n", &v) == 411, "alone: no length");
    CHECK(verdict(POST "Transfer-Encoding: identity\r\n\r\n", &v) == 411, "identity alone");
}

static void folding_and_blanks_before_colon_are_400(void)
{
    http_frame_verdict v;
    CHECK(verdict(POST "X-A: 1\r\n Content-Length: 2\r\n\r\n", &v) == 400, "folded line");
    CHECK(verdict(POST "Content-Length : 2\r\n\r\n", &v) == 400, "blank before the colon");
    CHECK(verdict(POST "X-Other : fine?\r\n\r\n", &v) == 400, "any field name");
}

/* What libmicrohttpd would answer in HTML, or hold silently (issue 30). */
static void malformed_heads_are_refused_here(void)
{
    http_frame_verdict v;
    CHECK(verdict("GET /health HTTP/2.0\r\n\r\n", &v) == 505, "%d", v.status);
    CHECK(verdict("GET /health HTTP/1.0\r\n\r\n", &v) == 0, "%s", v.detail);
    CHECK(verdict("GARBAGE\r\n\r\n", &v) == 400, "no parts");
    CHECK(verdict("GET  /health HTTP/1.1\r\n\r\n", &v) == 400, "double space");
    CHECK(verdict("GET /health HTTP/1.1\r\nNoColon\r\n\r\n", &v) == 400, "field without colon");
    CHECK(verdict("GET /health HTTP/1.1\r\n: v\r\n\r\n", &v) == 400, "empty field name");
    char head[8192] = "GET /cases?a=1";
    for (int i = 0; i < 64; i++) strcat(head, "&b=2");
    strcat(head, " HTTP/1.1\r\n\r\n");
    CHECK(verdict(head, &v) == 414 && strstr(v.detail, "65 query parameters"), "%s", v.detail);
    snprintf(head, sizeof head, "GET /cases?a=1&b=2 HTTP/1.1\r\n");
    for (int i = 0; i < 100; i++) strcat(head, "X-A: 1\r\n");
    strcat(head, "\r\n");
    CHECK(verdict(head, &v) == 0, "100 fields: %s", v.detail);
    strcpy(head + strlen(head) - 2, "X-A: 1\r\n\r\n");
    CHECK(verdict(head, &v) == 431, "101 fields: %d", v.status);
}

static void nul_bytes_are_refused(void)
{
    static const char with_token[] = "GET /cases HTTP/1.1\r\nAuthorization: Bearer T\0junk\r\n\r\n";
    http_frame_verdict v;
    CHECK(http_frame_check(with_token, sizeof with_token - 1, &v) == 400 && v.nul_in_credentials,
          "in the token: %d %d", v.status, v.nul_in_credentials);
    static const char elsewhere[] = "GET /cases HTTP/1.1\r\nX-A: \0\r\n\r\n";
    CHECK(http_frame_check(elsewhere, sizeof elsewhere - 1, &v) == 400 && !v.nul_in_credentials,
          "elsewhere: %d %d", v.status, v.nul_in_credentials);
}

CHECK_MAIN(T(head_end_finds_the_blank_line), T(plain_lengths_are_accepted),
           T(malformed_lengths_are_400), T(disagreeing_lengths_are_400), T(huge_lengths_are_413),
           T(transfer_encoding_is_refused), T(folding_and_blanks_before_colon_are_400),
           T(malformed_heads_are_refused_here), T(nul_bytes_are_refused))
