/*
 * report.c - turning a failed request into what the user reads on stderr.
 *
 * The server explains every refusal as RFC 9457 problem details; fdemctl
 * prints them verbatim (title, detail, one "pointer: message" line per
 * problem) because the pointers are what lets a user find the mistake in
 * their case document.
 */
#include <string.h>
#include <jansson.h>
#include "fdemctl.h"

static void report_problem_list(json_t *errors)
{
    size_t i;
    json_t *item;
    json_array_foreach(errors, i, item) {
        const char *pointer = json_string_value(json_object_get(item, "pointer"));
        const char *message = json_string_value(json_object_get(item, "message"));
        if (!message) continue;
        if (pointer && pointer[0])
            fprintf(stderr, "  %s: %s\n", pointer, message);
        else
            fprintf(stderr, "  (document): %s\n", message);
    }
}

/* Returns 1 when the body was problem details and got printed. */
static int report_problem(const http_response *r)
{
    json_t *doc = json_loadb(r->body, r->length, 0, NULL);
    if (!json_is_object(doc)) { json_decref(doc); return 0; }
    const char *title = json_string_value(json_object_get(doc, "title"));
    const char *detail = json_string_value(json_object_get(doc, "detail"));
    if (!title && !detail) { json_decref(doc); return 0; }
    fprintf(stderr, "fdemctl: %s (HTTP %ld)\n", title ? title : "request refused", r->status);
    if (detail && detail[0]) fprintf(stderr, "  %s\n", detail);
    report_problem_list(json_object_get(doc, "errors"));
    json_decref(doc);
    return 1;
}

int ctl_report_failure(const ctl_options *o, const char *path, const http_response *r)
{
    if (r->status == 0) {
        fprintf(stderr, "fdemctl: could not reach the fdemd server at %s%s (%s); "
                "is it running? (set --server or FDEMD_URL)\n",
                o->server, path, r->error);
        return CTL_USAGE;
    }
    if (!report_problem(r)) {
        /* Not problem details (a proxy, or an older server): show the start of it. */
        int shown = r->length > 300 ? 300 : (int)r->length;
        fprintf(stderr, "fdemctl: %s%s answered HTTP %ld%s%.*s\n", o->server, path,
                r->status, shown ? ": " : "", shown, r->body ? r->body : "");
    }
    return CTL_FAIL;
}

int ctl_call(const ctl_options *o, const char *method, const char *path,
             const char *body, size_t body_length, long expect_status, http_response *out)
{
    return ctl_call_as(o, method, path, body, body_length, "application/json", expect_status, out);
}

int ctl_call_as(const ctl_options *o, const char *method, const char *path, const char *body,
                size_t body_length, const char *content_type, long expect_status,
                http_response *out)
{
    if (http_request_as(o, method, path, body, body_length, content_type, out) != 0)
        return ctl_report_failure(o, path, out);
    if (out->status != expect_status) {
        int code = ctl_report_failure(o, path, out);
        http_response_free(out);
        return code;
    }
    return 0;
}
