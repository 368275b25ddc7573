/*
 * fuzz_http.c - libFuzzer harness for the request path up to the case
 * parser: the raw bytes a client sends are treated as one HTTP request,
 * the way the gate and the routes see it.
 *
 *  1. http_frame_head_end() finds the header block; http_frame_check()
 *     decides its framing (the code that runs on every connection before
 *     libmicrohttpd, see server/http/http_frame.c);
 *  2. a "fields=" query in the request target goes to case_parse_fields();
 *  3. when the framing is acceptable, the Content-Length bytes after the
 *     block are the body, and go to case_build() as POST /cases would.
 *
 * Invariants (a trap when broken): the block end lies inside the input just
 * after a line feed and is stable when the input is cut there; a refusal
 * has one of the documented statuses and a reason; an acceptance gives a
 * length that is absent or non-negative; the body gives a model or a
 * problem list with 400/422, as in fuzz_case.c.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "case/case.h"
#include "http/http_frame.h"

#define FUZZ_MEMORY_LIMIT ((size_t)64 << 20)

static void fuzz_fields(const char *data, size_t head)
{
    const char *line_end = memchr(data, '\n', head);
    size_t line = line_end ? (size_t)(line_end - data) : head;
    const char *at = NULL;
    for (size_t i = 0; i + 7 <= line; i++)
        if (memcmp(data + i, "fields=", 7) == 0) {
            at = data + i + 7;
            break;
        }
    if (!at) return;
    size_t n = 0;
    while (at + n < data + line && at[n] != ' ' && at[n] != '&') n++;
    char *csv = malloc(n + 1);
    if (!csv) return;
    memcpy(csv, at, n);
    csv[n] = '\0';
    problems out;
    problems_init(&out);
    unsigned fields = case_parse_fields(csv, &out);
    if (out.count + out.dropped > 0 && out.status != 400) __builtin_trap();
    (void)fields;
    problems_free(&out);
    free(csv);
}

static void fuzz_body(const char *body, size_t size)
{
    problems out;
    problems_init(&out);
    case_info info;
    fdem_model *model = case_build(body, size, FUZZ_MEMORY_LIMIT, &info, &out);
    if (model) {
        if (!(info.dt > 0) || out.count != 0) __builtin_trap();
        fdem_model_destroy(model);
    } else if (out.count + out.dropped == 0 || (out.status != 400 && out.status != 422)) {
        __builtin_trap();
    }
    problems_free(&out);
}

int LLVMFuzzerTestOneInput(const uint8_t *bytes, size_t size)
{
    const char *data = (const char *)bytes;
    size_t head = http_frame_head_end(data, size);
    if (!head) return 0;
    if (head > size || data[head - 1] != '\n' || http_frame_head_end(data, head) != head)
        __builtin_trap();

    http_frame_verdict v;
    int status = http_frame_check(data, head, &v);
    if (status != v.status) __builtin_trap();
    if (status) {
        if (status != 400 && status != 411 && status != 413 && status != 414 && status != 431 &&
            status != 505)
            __builtin_trap();
        if (!v.title[0] || !v.detail[0] || v.content_length != -1) __builtin_trap();
        if (v.nul_in_credentials && (status != 400 || !memchr(data, '\0', head))) __builtin_trap();
        return 0;
    }
    if (v.content_length < -1) __builtin_trap();

    fuzz_fields(data, head);
    if (v.content_length > 0) {
        size_t rest = size - head;
        size_t len = (unsigned long long)v.content_length < rest ? (size_t)v.content_length : rest;
        fuzz_body(data + head, len);
    }
    return 0;
}
