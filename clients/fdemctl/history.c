/*
 * history.c - `fdemctl history ID [--since T] [--csv FILE]`: the history
 * rows of a case (GET /cases/ID/history, contract 6.2) as CSV, one line
 * per row, to stdout or FILE: what a spreadsheet or a plotting script
 * reads without knowing the JSON. --json passes the server's answer through.
 *
 * Columns: time, step; per point <name>_u<axis> then <name>_v<axis>; per
 * constraint c<k>_f<axis> then c<k>_u<axis> (its force and the mean
 * displacement of its nodes); with fluid, per "inject" constraint
 * c<k>_source_pressure then c<k>_injected_volume; then every energy
 * account by name.
 */
#include "fdemctl.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char USAGE_HISTORY[] =
    "usage: fdemctl history ID [--since T] [--csv FILE] [--json]\n"
    "  The history rows of the case as CSV: time, step, each monitoring point's\n"
    "  displacement and velocity, each constraint's force and mean displacement,\n"
    "  each injection's source pressure and injected volume, every energy\n"
    "  account. --csv FILE writes them to FILE instead of stdout; --since T\n"
    "  only the rows after time T (seconds); --json prints the server's JSON\n"
    "  instead.\n";

static const char AXES[] = "xyz";

/* The width of the vectors of `key` in the first row: the case's dimension. */
static size_t vector_width(const json_t *row, const char *group, const char *key)
{
    const json_t *list = group ? json_object_get(json_object_get(row, group), key)
                               : json_object_get(row, key);
    return json_array_size(json_array_get(list, 0));
}

static void header_vectors(FILE *out, const char *prefix, size_t count, const json_t *names,
                           const char *quantity, size_t dim)
{
    for (size_t i = 0; i < count; i++)
        for (size_t d = 0; d < dim && d < 3; d++) {
            if (names) fprintf(out, ",%s_%s%c", json_string_value(json_array_get(names, i)),
                               quantity, AXES[d]);
            else fprintf(out, ",%s%zu_%s%c", prefix, i, quantity, AXES[d]);
        }
}

static void row_vectors(FILE *out, const json_t *list)
{
    for (size_t i = 0; i < json_array_size(list); i++) {
        const json_t *v = json_array_get(list, i);
        for (size_t d = 0; d < json_array_size(v); d++)
            fprintf(out, ",%.17g", json_number_value(json_array_get(v, d)));
    }
}

/* The constraints that inject (their figures not null in the first row's
 * "fluid"): a mark per constraint in `injects` (at most `room`). */
static void injections(const json_t *first, char *injects, size_t room)
{
    const json_t *p = json_object_get(json_object_get(first, "fluid"), "source_pressure");
    for (size_t k = 0; k < room; k++) injects[k] = json_is_number(json_array_get(p, k));
}

static void header_fluid(FILE *out, const char *injects, size_t constraints)
{
    for (size_t k = 0; k < constraints; k++)
        if (injects[k]) fprintf(out, ",c%zu_source_pressure,c%zu_injected_volume", k, k);
}

static void row_fluid(FILE *out, const json_t *row, const char *injects, size_t constraints)
{
    const json_t *fluid = json_object_get(row, "fluid");
    const json_t *p = json_object_get(fluid, "source_pressure");
    const json_t *v = json_object_get(fluid, "injected_volume");
    for (size_t k = 0; k < constraints; k++)
        if (injects[k])
            fprintf(out, ",%.17g,%.17g", json_number_value(json_array_get(p, k)),
                    json_number_value(json_array_get(v, k)));
}

static void write_csv(FILE *out, const json_t *body)
{
    const json_t *rows = json_object_get(body, "rows"), *names = json_object_get(body, "names");
    const json_t *first = json_array_get(rows, 0), *energy = json_object_get(first, "energy");
    size_t points = json_array_size(names);
    size_t constraints = json_array_size(json_object_get(first, "constraint_force"));
    size_t dim = vector_width(first, NULL, "constraint_force");
    if (!dim) dim = vector_width(first, "points", "displacement");
    fprintf(out, "time,step");
    header_vectors(out, "p", points, names, "u", dim);
    header_vectors(out, "p", points, names, "v", dim);
    header_vectors(out, "c", constraints, NULL, "f", dim);
    header_vectors(out, "c", constraints, NULL, "u", dim);
    char *injects = calloc(constraints ? constraints : 1, 1);
    if (injects) injections(first, injects, constraints);
    if (injects) header_fluid(out, injects, constraints);
    const char *term;
    const json_t *value;
    json_object_foreach((json_t *)energy, term, value) fprintf(out, ",%s", term);
    fputc('\n', out);
    for (size_t r = 0; r < json_array_size(rows); r++) {
        const json_t *row = json_array_get(rows, r);
        const json_t *p = json_object_get(row, "points"), *e = json_object_get(row, "energy");
        fprintf(out, "%.17g,%lld", json_number_value(json_object_get(row, "time")),
                (long long)json_integer_value(json_object_get(row, "step")));
        row_vectors(out, json_object_get(p, "displacement"));
        row_vectors(out, json_object_get(p, "velocity"));
        row_vectors(out, json_object_get(row, "constraint_force"));
        row_vectors(out, json_object_get(row, "constraint_displacement"));
        if (injects) row_fluid(out, row, injects, constraints);
        json_object_foreach((json_t *)energy, term, value)
            fprintf(out, ",%.17g", json_number_value(json_object_get(e, term)));
        fputc('\n', out);
    }
    free(injects);
}

int cmd_history(const ctl_options *o, int argc, char **argv)
{
    int raw = 0;
    const char *id[1], *since = NULL, *csv = NULL;
    ctl_option_spec specs[] = {{"--since", NULL, &since, NULL}, {"--csv", NULL, &csv, NULL},
                               {"--json", NULL, NULL, &raw}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_HISTORY, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    char path[1024];
    if (http_case_path(path, sizeof path, id[0], "/history") != 0) {
        fprintf(stderr, "fdemctl history: case id too long\n");
        return CTL_USAGE;
    }
    if (since) {
        char *end = NULL;
        double t = strtod(since, &end);
        if (!*since || *end || !isfinite(t)) {
            fprintf(stderr, "fdemctl history: --since takes a time in seconds, not \"%s\"\n%s",
                    since, USAGE_HISTORY);
            return CTL_USAGE;
        }
        size_t used = strlen(path);
        snprintf(path + used, sizeof path - used, "?since=%.17g", t);
    }
    http_response r;
    int code = ctl_call(o, "GET", path, NULL, 0, 200, &r);
    if (code) return code;
    if (raw) {
        fwrite(r.body, 1, r.length, stdout);
        if (r.length == 0 || r.body[r.length - 1] != '\n') fputc('\n', stdout);
        http_response_free(&r);
        return 0;
    }
    json_error_t error;
    json_t *body = json_loadb(r.body, r.length, 0, &error);
    http_response_free(&r);
    if (!body || !json_is_array(json_object_get(body, "rows"))) {
        fprintf(stderr, "fdemctl: the server's answer to GET %s is not a history\n", path);
        json_decref(body);
        return CTL_FAIL;
    }
    FILE *out = csv ? fopen(csv, "w") : stdout;
    if (!out) {
        fprintf(stderr, "fdemctl history: cannot write %s: %s\n", csv, strerror(errno));
        json_decref(body);
        return CTL_FAIL;
    }
    write_csv(out, body);
    int failed = ferror(out);
    if (csv && fclose(out) != 0) failed = 1;
    if (csv && !failed)
        fprintf(stderr, "%zu history rows written to %s\n",
                json_array_size(json_object_get(body, "rows")), csv);
    json_decref(body);
    if (failed) fprintf(stderr, "fdemctl history: writing %s failed\n", csv ? csv : "stdout");
    return failed ? CTL_FAIL : 0;
}
