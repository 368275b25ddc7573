/*
 * fragments.c - `fdemctl fragments ID`: the pieces a case has broken into
 * and their sieve curve (GET /cases/ID/fragments, contract 5.4), as a
 * table a person reads; --json passes the server's answer through for
 * scripts.
 *
 * Why a file of its own: the table and the curve are the one place fdemctl
 * formats fragment records; commands.c stays with the status-like commands.
 */
#include "fdemctl.h"

#include <jansson.h>
#include <string.h>

static const char USAGE_FRAGMENTS[] =
    "usage: fdemctl fragments ID [--parts A,B] [--exclude-host] [--json]\n"
    "  The fragments of the case at one step boundary: id, elements, mass,\n"
    "  size (area in 2D, volume in 3D), equivalent diameter, centroid and\n"
    "  velocity of each, its part (index in the case's parts) and whether a\n"
    "  fix or velocity constraint holds it, then the sieve curve (mass\n"
    "  fraction of fragments no larger than each diameter) of those listed.\n"
    "  --parts A,B     only the fragments of the parts named A and B\n"
    "  --exclude-host  leave out the host body: every fragment a fix or\n"
    "                  velocity constraint holds, and one holding more than\n"
    "                  half the model's mass\n"
    "  --json          print the server's JSON instead.\n";

static double number_at(const json_t *o, const char *key)
{
    return json_number_value(json_object_get(o, key));
}

/* "(x, y)" or "(x, y, z)" of a JSON array of numbers, %.4g each. */
static void vector_text(const json_t *v, char *out, size_t size)
{
    size_t n = (size_t)snprintf(out, size, "(");
    for (size_t k = 0; k < json_array_size(v) && n < size; k++)
        n += (size_t)snprintf(out + n, size - n, "%s%.4g", k ? ", " : "",
                              json_number_value(json_array_get(v, k)));
    if (n < size) snprintf(out + n, size - n, ")");
}

static void print_fragments(const json_t *body)
{
    const json_t *list = json_object_get(body, "fragments");
    double total = 0;
    for (size_t i = 0; i < json_array_size(list); i++) total += number_at(json_array_get(list, i), "mass");
    /* a centroid has as many components as the case has dimensions */
    size_t dims = json_array_size(json_object_get(json_array_get(list, 0), "centroid"));
    const char *unit = dims == 3 ? "kg" : dims == 2 ? "kg per metre of thickness" : "kg (per metre in 2D)";
    printf("step %lld, t = %.6g s: %zu fragments, total mass %.6g %s\n",
           (long long)json_integer_value(json_object_get(body, "step")), number_at(body, "time"),
           json_array_size(list), total, unit);
    /* the centroid column as wide as its widest entry (a 3D one runs past
     * 30 characters and pushed the velocities out of line) */
    int width = (int)strlen("centroid");
    for (size_t i = 0; i < json_array_size(list); i++) {
        char centroid[96];
        vector_text(json_object_get(json_array_get(list, i), "centroid"), centroid, sizeof centroid);
        if ((int)strlen(centroid) > width) width = (int)strlen(centroid);
    }
    printf("%6s %9s %12s %12s %12s  %-*s %-*s %5s %s\n", "id", "elements", "mass", "size",
           "diameter", width, "centroid", width, "velocity", "part", "held");
    for (size_t i = 0; i < json_array_size(list); i++) {
        const json_t *f = json_array_get(list, i);
        char centroid[96], velocity[96];
        vector_text(json_object_get(f, "centroid"), centroid, sizeof centroid);
        vector_text(json_object_get(f, "velocity"), velocity, sizeof velocity);
        printf("%6lld %9lld %12.6g %12.6g %12.6g  %-*s %-*s %5lld %s\n",
               (long long)json_integer_value(json_object_get(f, "id")),
               (long long)json_integer_value(json_object_get(f, "elements")), number_at(f, "mass"),
               number_at(f, "size"), number_at(f, "diameter"), width, centroid, width, velocity,
               (long long)json_integer_value(json_object_get(f, "part")),
               json_is_true(json_object_get(f, "held")) ? "yes" : "no");
    }
    const json_t *host = json_object_get(body, "host");
    if (json_is_array(host)) {
        printf("left out as the host body: %zu fragment%s", json_array_size(host),
               json_array_size(host) == 1 ? "" : "s");
        for (size_t i = 0; i < json_array_size(host); i++)
            printf("%s%lld", i ? ", " : " (id ", (long long)json_integer_value(json_array_get(host, i)));
        printf("%s\n", json_array_size(host) ? ")" : "");
    }
    const json_t *curve = json_object_get(body, "distribution");
    printf("\nsieve curve: mass fraction passing\n%12s %9s\n", "diameter", "passing");
    for (size_t i = 0; i < json_array_size(curve); i++) {
        const json_t *p = json_array_get(curve, i);
        printf("%12.6g %8.2f %%\n", number_at(p, "diameter"), 100 * number_at(p, "passing"));
    }
}

/* "?parts=A%2CB&exclude_host=true" for the options given, URL-escaped. */
static int fragments_query(const char *parts, int exclude_host, char *out, size_t size)
{
    size_t n = 0;
    out[0] = '\0';
    if (parts) {
        n += (size_t)snprintf(out, size, "?parts=");
        for (const unsigned char *c = (const unsigned char *)parts; *c && n + 4 < size; c++) {
            int plain = (*c >= 'A' && *c <= 'Z') || (*c >= 'a' && *c <= 'z') ||
                        (*c >= '0' && *c <= '9') || strchr("-_.~,", *c);
            n += (size_t)snprintf(out + n, size - n, plain ? "%c" : "%%%02X", *c);
        }
        if (n + 4 >= size) return -1;
    }
    if (exclude_host && n + 20 < size)
        snprintf(out + n, size - n, "%sexclude_host=true", parts ? "&" : "?");
    return 0;
}

int cmd_fragments(const ctl_options *o, int argc, char **argv)
{
    int raw = 0, exclude_host = 0;
    const char *id[1], *parts = NULL;
    ctl_option_spec specs[] = {{"--json", NULL, NULL, &raw}, {"--parts", NULL, &parts, NULL},
                               {"--exclude-host", NULL, NULL, &exclude_host}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_FRAGMENTS, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    char query[700], path[1800];
    if (fragments_query(parts, exclude_host, query, sizeof query) != 0) {
        fprintf(stderr, "fdemctl fragments: --parts is too long\n");
        return CTL_USAGE;
    }
    char suffix[800];
    snprintf(suffix, sizeof suffix, "/fragments%s", query);
    if (http_case_path(path, sizeof path, id[0], suffix) != 0) {
        fprintf(stderr, "fdemctl fragments: case id too long\n");
        return CTL_USAGE;
    }
    return ctl_show_list(o, path, raw, "fragments", "a fragment list", print_fragments);
}

int ctl_show_list(const ctl_options *o, const char *path, int raw, const char *key,
                  const char *what, void (*print)(const json_t *body))
{
    http_response r;
    int code = ctl_call(o, "GET", path, NULL, 0, 200, &r);
    if (code) return code;
    json_error_t error;
    json_t *body = raw ? NULL : json_loadb(r.body, r.length, 0, &error);
    if (raw) {
        fwrite(r.body, 1, r.length, stdout);
        if (r.length == 0 || r.body[r.length - 1] != '\n') fputc('\n', stdout);
    } else if (!body || !json_is_array(json_object_get(body, key))) {
        fprintf(stderr, "fdemctl: the server's answer to GET %s is not %s\n", path, what);
        code = CTL_FAIL;
    } else {
        print(body);
    }
    json_decref(body);
    http_response_free(&r);
    return code;
}
