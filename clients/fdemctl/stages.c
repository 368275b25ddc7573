/*
 * stages.c - the fdemctl commands of a case in stages (contract 5.3
 * "Continue and clone"): extend runs a finished or paused case on to a
 * later end in the same files, clone makes a new case from a stored one and
 * a JSON Merge Patch.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include "fdemctl.h"

/* ----------------------------------------------------------------- extend */

static const char USAGE_EXTEND[] =
    "usage: fdemctl extend ID END [--start]\n"
    "  Runs a finished or paused case on to the later end time END (seconds):\n"
    "  the case becomes paused with the new end, and its results go on in the\n"
    "  same result.h5 when it is started (POST /cases/ID/extend).\n"
    "  --start   start it at once\n"
    "  Prints the case's state and end afterwards; a case that is running,\n"
    "  queued, created, stopped or failed, or an END not beyond the current\n"
    "  end, exits 1.\n";

static int extend_post(const ctl_options *o, const char *id, double end, json_t **status)
{
    char path[512], body[64];
    if (http_case_path(path, sizeof path, id, "/extend") != 0) {
        fprintf(stderr, "fdemctl: case id '%s' is too long\n", id);
        return CTL_USAGE;
    }
    snprintf(body, sizeof body, "{\"end\": %.17g}", end);
    http_response r;
    int code = ctl_call(o, "POST", path, body, strlen(body), 200, &r);
    if (code) return code;
    *status = json_loadb(r.body, r.length, 0, NULL);
    http_response_free(&r);
    return CTL_OK;
}

static int extend_start(const ctl_options *o, const char *id, json_t **status)
{
    char path[512];
    if (http_case_path(path, sizeof path, id, "/start") != 0)
        return CTL_USAGE;
    http_response r;
    int code = ctl_call(o, "POST", path, NULL, 0, 200, &r);
    if (code) return code;
    json_decref(*status);
    *status = json_loadb(r.body, r.length, 0, NULL);
    http_response_free(&r);
    return CTL_OK;
}

int cmd_extend(const ctl_options *o, int argc, char **argv)
{
    int start = 0;
    const char *args[2];
    ctl_option_spec specs[] = {{"--start", NULL, NULL, &start}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_EXTEND, args, 2, 2);
    if (n < 0) return ctl_args_exit(n);
    char *rest = NULL;
    double end = strtod(args[1], &rest);
    if (rest == args[1] || *rest != '\0' || !isfinite(end)) {
        fprintf(stderr, "fdemctl extend: END is a time in seconds, not '%s'\n%s", args[1],
                USAGE_EXTEND);
        return CTL_USAGE;
    }
    json_t *status = NULL;
    int code = extend_post(o, args[0], end, &status);
    if (code == CTL_OK && start)
        code = extend_start(o, args[0], &status);
    if (code == CTL_OK)
        printf("%s %s (end %.6g s)\n", args[0],
               json_string_value(json_object_get(status, "state")) ?
               json_string_value(json_object_get(status, "state")) : "?",
               json_number_value(json_object_get(status, "end_time")));
    json_decref(status);
    return code;
}

/* ------------------------------------------------------------------ clone */

static const char USAGE_CLONE[] =
    "usage: fdemctl clone ID PATCH|- [--start]\n"
    "  Creates a new case from the stored document of case ID with a JSON Merge\n"
    "  Patch (RFC 7396) applied: a file, or stdin for -. In the patch an object\n"
    "  merges into the document, null removes a member, anything else replaces\n"
    "  it; e.g. {\"name\": \"softer\", \"materials\": {\"rock\": {\"young\": 1e9}}}.\n"
    "  Prints the new case id. The patched case is checked as a submitted one:\n"
    "  its problems are printed as 'pointer: message' (pointers into the patched\n"
    "  document) and exit 1.\n"
    "  --start   start the new case at once\n";

int cmd_clone(const ctl_options *o, int argc, char **argv)
{
    int start = 0;
    const char *args[2];
    ctl_option_spec specs[] = {{"--start", NULL, NULL, &start}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_CLONE, args, 2, 2);
    if (n < 0) return ctl_args_exit(n);
    char path[512];
    if (http_case_path(path, sizeof path, args[0], start ? "/clone?start=true" : "/clone") != 0) {
        fprintf(stderr, "fdemctl: case id '%s' is too long\n", args[0]);
        return CTL_USAGE;
    }
    size_t length;
    char *patch = ctl_read_all(args[1], &length);
    if (!patch) return CTL_USAGE;
    http_response r;
    int code = ctl_call(o, "POST", path, patch, length, 201, &r);
    free(patch);
    if (code) return code;
    json_t *status = json_loadb(r.body, r.length, 0, NULL);
    http_response_free(&r);
    const char *id = json_string_value(json_object_get(status, "id"));
    const char *warning = json_string_value(json_object_get(status, "warning"));
    if (id) printf("%s\n", id);
    else fprintf(stderr, "fdemctl: the server created the clone but sent no id\n");
    if (warning) fprintf(stderr, "fdemctl: warning: %s\n", warning);
    json_decref(status);
    return id ? CTL_OK : CTL_FAIL;
}
