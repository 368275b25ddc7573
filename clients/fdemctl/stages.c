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
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &args[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
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
    "usage: fdemctl clone ID PATCH|- [--start | --dry-run]\n"
    "  Creates a new case from the stored document of case ID with a patch\n"
    "  applied: a file, or stdin for -. An object is a JSON Merge Patch (RFC\n"
    "  7396): an object merges into the document, null removes a member,\n"
    "  anything else replaces it; e.g. {\"name\": \"softer\", \"materials\":\n"
    "  {\"rock\": {\"young\": 1e9}}}. An array is a JSON Patch (RFC 6902), sent as\n"
    "  application/json-patch+json: operations that change one element of an\n"
    "  array without resending it; e.g. [{\"op\": \"replace\", \"path\":\n"
    "  \"/parts/0/material\", \"value\": \"granite\"}]. It is all or nothing: an\n"
    "  operation that fails (a failed \"test\" too) creates nothing.\n"
    "  Prints the new case id. The patched case is checked as a submitted one:\n"
    "  its problems are printed as 'pointer: message' (pointers into the patched\n"
    "  document; for a failed JSON Patch operation /i, its index) and exit 1.\n"
    "  --start    start the new case at once\n"
    "  --dry-run  create nothing: check and size the clone as submit --dry-run\n"
    "             does (nodes, steps, memory, result size, estimated time)\n";

/* An array (first character past white space "[") is a JSON Patch. */
static const char *clone_content_type(const char *patch)
{
    while (*patch == ' ' || *patch == '\t' || *patch == '\n' || *patch == '\r') patch++;
    return *patch == '[' ? "application/json-patch+json" : "application/json";
}

int cmd_clone(const ctl_options *o, int argc, char **argv)
{
    int start = 0, dry_run = 0;
    const char *args[2];
    ctl_option_spec specs[] = {{"--start", NULL, NULL, &start},
                               {"--dry-run", NULL, NULL, &dry_run}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_CLONE, args, 2, 2);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &args[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    if (start && dry_run) {
        fprintf(stderr, "fdemctl clone: --dry-run creates nothing, so it cannot --start\n%s",
                USAGE_CLONE);
        return CTL_USAGE;
    }
    char path[512];
    const char *suffix = dry_run ? "/clone?dry_run=true" : start ? "/clone?start=true" : "/clone";
    if (http_case_path(path, sizeof path, args[0], suffix) != 0) {
        fprintf(stderr, "fdemctl: case id '%s' is too long\n", args[0]);
        return CTL_USAGE;
    }
    size_t length;
    char *patch = ctl_read_all(args[1], &length);
    if (!patch) return CTL_USAGE;
    http_response r;
    int code = ctl_call_as(o, "POST", path, patch, length, clone_content_type(patch),
                           dry_run ? 200 : 201, &r);
    free(patch);
    if (code) return code;
    if (dry_run) {
        code = ctl_print_sizing(&r);
        http_response_free(&r);
        return code;
    }
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
