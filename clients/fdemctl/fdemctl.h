/*
 * fdemctl.h - the pieces of the fdemctl command-line client shared between
 * its files: options, the tiny HTTP helper, argument parsing and error
 * reporting.
 *
 * Contract:
 *  - fdemctl talks to fdemd over HTTP only (contract section 2); it knows
 *    nothing of the engine.
 *  - Exit codes: CTL_OK (0) success; CTL_FAIL (1) the server refused the
 *    request or the case ended failed/stopped; CTL_USAGE (2) bad usage or no
 *    connection to the server. Every command returns one of these.
 *  - The only state is the immutable ctl_options built by main() from
 *    --server / FDEMD_URL and FDEMD_TOKEN; every request builds and frees
 *    its own curl handle.
 */
#ifndef FDEMCTL_H
#define FDEMCTL_H

#include <stddef.h>
#include <stdio.h>
#include <jansson.h>

enum { CTL_OK = 0, CTL_FAIL = 1, CTL_USAGE = 2 };

typedef struct ctl_options {
    const char *server;   /* base URL without a trailing slash */
    const char *token;    /* bearer token or NULL */
} ctl_options;

typedef struct http_response {
    long status;          /* HTTP status, 0 when the request never completed */
    char *body;           /* NUL-terminated, may be empty, never NULL on success */
    size_t length;
    char error[256];      /* transport error when status == 0 */
} http_response;

/* --- http.c ------------------------------------------------------------ */

/* Sends METHOD base+path with an optional JSON body. Returns 0 when an HTTP
 * answer arrived (whatever its status), -1 on a transport failure (then
 * `error` says why). Free the response with http_response_free(). */
int http_request(const ctl_options *o, const char *method, const char *path,
                 const char *body, size_t body_length, http_response *out);
/* The same with the body's Content-Type (http_request sends application/json). */
int http_request_as(const ctl_options *o, const char *method, const char *path,
                    const char *body, size_t body_length, const char *content_type,
                    http_response *out);
/* GET base+path streaming the body into `sink`; status and transport error
 * are reported as for http_request (the body is not kept). */
int http_download(const ctl_options *o, const char *path, FILE *sink, http_response *out);
/* GET base+path, handing its body to `take` piece by piece as it arrives
 * (never from inside libcurl, so `take` may make requests itself) until
 * `take` returns non-zero: then 0. -1 when the answer is not 200 (status
 * and body in `out`), or the transfer failed, ended, or was silent for
 * `quiet_limit` seconds (`error` says which). Free `out` with
 * http_response_free(). */
typedef int (*http_piece_fn)(void *arg, const char *data, size_t length);
int http_follow(const ctl_options *o, const char *path, double quiet_limit, http_piece_fn take,
                void *arg, http_response *out);
void http_response_free(http_response *r);
/* "/cases/<escaped id><suffix>" into out; returns 0, or -1 if it doesn't fit. */
int http_case_path(char *out, size_t size, const char *id, const char *suffix);

/* --- report.c ---------------------------------------------------------- */

/* Prints why a request failed and returns the exit code to use:
 * transport failure -> one sentence naming the URL, CTL_USAGE;
 * an HTTP error -> the problem details (title, detail, each
 * "pointer: message"), CTL_FAIL. */
int ctl_report_failure(const ctl_options *o, const char *path, const http_response *r);
/* Performs a request expecting `expect_status`; on anything else reports
 * it and returns the exit code, else 0 with *out filled (caller frees). */
int ctl_call(const ctl_options *o, const char *method, const char *path,
             const char *body, size_t body_length, long expect_status, http_response *out);
int ctl_call_as(const ctl_options *o, const char *method, const char *path, const char *body,
                size_t body_length, const char *content_type, long expect_status,
                http_response *out);

/* --- args.c ------------------------------------------------------------ */

typedef struct ctl_option_spec {
    const char *name;         /* "--start" */
    const char *short_name;   /* "-o", or NULL */
    const char **value;       /* non-NULL: the option takes a value */
    int *flag;                /* non-NULL: set to 1 when present */
} ctl_option_spec;

enum { ARGS_ERROR = -1, ARGS_HELP = -2 };

/* Parses argv[1..argc) of one command (argv[0] is its name) against specs
 * (terminated by a zeroed entry), accepting "--opt value" and "--opt=value"
 * anywhere; "-" is a positional (stdin), "--" ends options. Returns the
 * number of positionals (stored in `positional`, at most max_positional,
 * and at least min_positional), ARGS_HELP after printing `usage` to stdout
 * for --help/-h, or ARGS_ERROR after printing what was wrong and `usage`
 * to stderr. ctl_args_exit() maps the negative values to an exit code. */
int ctl_parse_args(int argc, char **argv, const ctl_option_spec *specs, const char *usage,
                   const char **positional, int min_positional, int max_positional);
static inline int ctl_args_exit(int parsed) { return parsed == ARGS_HELP ? CTL_OK : CTL_USAGE; }

/* --- ids.c ------------------------------------------------------------- */

/* Room for a resolved case id (ids are 16 characters). */
#define CTL_ID_SIZE 64
/* A case id typed by the user, possibly shortened to a unique prefix of
 * one: a prefix that exactly one case's id starts with is replaced by that
 * id (*id then points into buf); a whole id, or one that no case starts
 * with, is left as typed (the server answers 404 for an unknown one).
 * Returns CTL_OK, or CTL_USAGE after saying why when the prefix is empty
 * or shared by several cases (they are listed on stderr). */
int ctl_resolve_id(const ctl_options *o, const char **id, char *buf, size_t size);

/* --- commands.c (shared with wait.c and fetch.c) ----------------------- */

/* GET /cases/ID as a JSON object, or NULL after reporting why (then *code
 * holds the exit code). The caller json_decref()s it. */
struct json_t;
struct json_t *ctl_get_status(const ctl_options *o, const char *id, int *code);
/* Prints the sizing object of a dry run (POST /cases?dry_run=true, or a
 * clone's); CTL_OK, or CTL_FAIL when the answer is not one. */
int ctl_print_sizing(const http_response *r);
/* The status' "stage" as `1 "excavate"` (index, then the name), or ""
 * for a case without stages (contract 6.1). */
void ctl_stage_text(json_t *status, char *out, size_t size);
/* A whole file (or stdin for "-"), NUL-terminated; NULL after saying why
 * (the caller exits CTL_USAGE: the file is the user's mistake, not the server's). */
char *ctl_read_all(const char *path, size_t *length);

/* --- commands --------------------------------------------------------- */

int cmd_health(const ctl_options *o, int argc, char **argv);
int cmd_submit(const ctl_options *o, int argc, char **argv);
int cmd_list(const ctl_options *o, int argc, char **argv);
int cmd_status(const ctl_options *o, int argc, char **argv);
int cmd_control(const ctl_options *o, int argc, char **argv);   /* start|pause|stop */
int cmd_delete(const ctl_options *o, int argc, char **argv);
int cmd_case(const ctl_options *o, int argc, char **argv);
int cmd_state(const ctl_options *o, int argc, char **argv);
int cmd_wait(const ctl_options *o, int argc, char **argv);
int cmd_fetch(const ctl_options *o, int argc, char **argv);
int cmd_fragments(const ctl_options *o, int argc, char **argv);
int cmd_extend(const ctl_options *o, int argc, char **argv);    /* stages.c */
int cmd_clone(const ctl_options *o, int argc, char **argv);
/* fragments.c, shared with events.c: GET path and print the JSON object
 * whose `key` is a list with print(), or pass it through as is (raw);
 * `what` names the list in the message when the answer is not one. */
int ctl_show_list(const ctl_options *o, const char *path, int raw, const char *key,
                  const char *what, void (*print)(const json_t *body));
int cmd_events(const ctl_options *o, int argc, char **argv);
int cmd_history(const ctl_options *o, int argc, char **argv);

#endif
