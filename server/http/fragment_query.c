/*
 * fragment_query.c - part names of ?parts= into part indices
 * (fragment_query.h).
 *
 * Why the document: the model knows its parts by index only; their names
 * are the user's, in case.json. It is read only when ?parts= asks for
 * names, and its tree is metered against --max-memory like every other
 * document a request parses.
 */
#include "fragment_query.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cases/case_model.h"
#include "common/memory_budget.h"
#include "files/persist.h"

/* The case's "parts" array (a new reference), or NULL with a status. */
static json_t *query_read_parts(const server_case *c, char *detail, size_t detail_size,
                                int *status)
{
    char path[1200], *text = NULL;
    size_t size = 0;
    snprintf(path, sizeof path, "%s/case.json", c->dir);
    if (persist_read_file(path, &text, &size, CASE_MODEL_MAX_DOCUMENT) != 0) {
        snprintf(detail, detail_size, "the stored case.json could not be read: %s",
                 strerror(errno));
        *status = 500;
        return NULL;
    }
    membudget_lease lease = {0};
    membudget_meter_begin(&lease, 0);
    json_t *doc = json_loadb(text, size, 0, NULL);
    json_t *parts = json_incref(json_object_get(doc, "parts"));
    json_decref(doc);
    membudget_meter_end();
    int refused = membudget_meter_refused();
    membudget_release(&lease);
    free(text);
    if (!json_is_array(parts)) {
        json_decref(parts);
        *status = refused ? 503 : 500;
        snprintf(detail, detail_size, refused ? "reading the part names of the case would take "
                 "the daemon past its memory budget (--max-memory) now" :
                 "the stored case.json has no parts");
        return NULL;
    }
    return parts;
}

/* Part i's name as result.h5 gives it; `scratch` holds a made-up one. */
static const char *query_part_name(const json_t *parts, size_t i, char *scratch, size_t size)
{
    const json_t *name = json_object_get(json_array_get(parts, i), "name");
    if (json_is_string(name) && json_string_length(name) > 0)
        return json_string_value(name);
    snprintf(scratch, size, "part%zu", i);
    return scratch;
}

/* "a", "b", "c" into out, for the sentence of an unknown name. */
static void query_list_names(const json_t *parts, char *out, size_t size)
{
    out[0] = '\0';
    for (size_t i = 0; i < json_array_size(parts); i++) {
        char scratch[32];
        size_t n = strlen(out);
        snprintf(out + n, size - n, "%s\"%.60s\"", i ? ", " : "",
                 query_part_name(parts, i, scratch, sizeof scratch));
    }
}

/* Flags the part named `token` (length n); 0, or -1 when none has it. */
static int query_flag_part(const json_t *parts, const char *token, size_t n, unsigned char *flags)
{
    int found = -1;
    for (size_t i = 0; i < json_array_size(parts); i++) {
        char scratch[32];
        const char *name = query_part_name(parts, i, scratch, sizeof scratch);
        if (strlen(name) == n && strncmp(name, token, n) == 0) {
            flags[i] = 1;
            found = 0;
        }
    }
    return found;
}

int fragment_query_parts(const server_case *c, const char *csv, fragment_selection *sel,
                         char *detail, size_t detail_size)
{
    int status = 0;
    json_t *parts = query_read_parts(c, detail, detail_size, &status);
    if (!parts)
        return status;
    size_t count = json_array_size(parts);
    unsigned char *flags = calloc(count ? count : 1, 1);
    if (!flags) {
        json_decref(parts);
        snprintf(detail, detail_size, "out of memory");
        return 503;
    }
    const char *p = csv;
    do {
        size_t n = strcspn(p, ",");
        if (n == 0 || query_flag_part(parts, p, n, flags) != 0) {
            char names[400];
            query_list_names(parts, names, sizeof names);
            if (n == 0)
                snprintf(detail, detail_size, "?parts= takes a comma-separated list of part names "
                         "(this case's are %s)", names);
            else
                snprintf(detail, detail_size, "?parts=: the case has no part named \"%.*s\"; its "
                         "parts are %s", (int)(n < 64 ? n : 64), p, names);
            status = 400;
            break;
        }
        p += n;
    } while (*p++ == ',');
    json_decref(parts);
    if (status) {
        free(flags);
        return status;
    }
    sel->parts = flags;
    sel->part_count = (int)count;
    return 0;
}

void fragment_query_free(fragment_selection *sel)
{
    free((unsigned char *)sel->parts);
    sel->parts = NULL;
}
