/*
 * ids.c - case ids shortened to a unique prefix, as git does with commits:
 * `fdemctl status 3f2a` names the one case whose id starts with "3f2a".
 *
 * The prefix is resolved against GET /cases before the command's own
 * request. An id that is a whole id, or that no case starts with, goes to
 * the server as typed, so an unknown case is still the server's 404 (exit
 * 1) with its own words; only a prefix that two or more cases share is
 * refused here (exit 2, a usage error: the argument names no one case),
 * with every match listed so the user can pick.
 */
#include <string.h>
#include <jansson.h>
#include "fdemctl.h"

/* Ids the daemon makes are this long (server/cases/registry.h): such an
 * argument is already a whole id and needs no listing. */
#define CTL_FULL_ID_LENGTH 16
/* Matches listed in the message of an ambiguous prefix; more are counted. */
#define CTL_AMBIGUOUS_SHOWN 10

/* The server's case list as a JSON array (owned by *doc), or NULL when it
 * cannot be had: then the id goes through as typed and the command's own
 * request reports what is wrong (no server, a token, ...). */
static json_t *ids_list_cases(const ctl_options *o, json_t **doc)
{
    http_response r;
    *doc = NULL;
    if (http_request(o, "GET", "/cases", NULL, 0, &r) != 0 || r.status != 200) {
        http_response_free(&r);
        return NULL;
    }
    *doc = json_loadb(r.body, r.length, 0, NULL);
    http_response_free(&r);
    json_t *cases = json_object_get(*doc, "cases");
    return json_is_array(cases) ? cases : NULL;
}

static void ids_report_ambiguous(json_t *cases, const char *prefix, int matches)
{
    fprintf(stderr, "fdemctl: case id prefix '%s' is ambiguous: %d cases start with it; "
            "type more of the id:\n", prefix, matches);
    size_t i;
    json_t *c;
    int shown = 0;
    json_array_foreach(cases, i, c) {
        const char *id = json_string_value(json_object_get(c, "id"));
        if (!id || strncmp(id, prefix, strlen(prefix)) != 0) continue;
        if (shown++ == CTL_AMBIGUOUS_SHOWN) {
            fprintf(stderr, "  ... and %d more\n", matches - CTL_AMBIGUOUS_SHOWN);
            break;
        }
        const char *name = json_string_value(json_object_get(c, "name"));
        const char *state = json_string_value(json_object_get(c, "state"));
        fprintf(stderr, "  %s  %s  %s\n", id, state ? state : "?", name ? name : "");
    }
}

int ctl_resolve_id(const ctl_options *o, const char **id, char *buf, size_t size)
{
    size_t length = strlen(*id);
    if (length == 0) {
        fprintf(stderr, "fdemctl: an empty case id names no case\n");
        return CTL_USAGE;
    }
    if (length >= CTL_FULL_ID_LENGTH) return CTL_OK;
    json_t *doc;
    json_t *cases = ids_list_cases(o, &doc);
    const char *found = NULL;
    int matches = 0, exact = 0;
    size_t i;
    json_t *c;
    json_array_foreach(cases, i, c) {
        const char *candidate = json_string_value(json_object_get(c, "id"));
        if (!candidate || strncmp(candidate, *id, length) != 0) continue;
        exact |= candidate[length] == '\0';
        found = candidate;
        matches++;
    }
    int code = CTL_OK;
    if (matches > 1 && !exact) {
        ids_report_ambiguous(cases, *id, matches);
        code = CTL_USAGE;
    } else if (matches == 1 && !exact) {
        if (strlen(found) + 1 > size) {
            fprintf(stderr, "fdemctl: case id '%s' is too long\n", found);
            code = CTL_USAGE;
        } else {
            memcpy(buf, found, strlen(found) + 1);
            *id = buf;
        }
    }
    json_decref(doc);
    return code;
}
