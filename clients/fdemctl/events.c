/*
 * events.c - `fdemctl events ID [--since T]`: the fracture events of a case
 * (GET /cases/ID/events, contract 5.4) as a table, in the order the joints
 * broke, with the running count and energy an acoustic-emission catalogue
 * is read by; --json passes the server's answer through for scripts.
 *
 * A file of its own for the same reason as fragments.c: it is the one
 * place fdemctl formats event records.
 */
#include "fdemctl.h"

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char USAGE_EVENTS[] =
    "usage: fdemctl events ID [--since T] [--json]\n"
    "  The fracture events of the case: one per joint that broke, in the order\n"
    "  they broke: time, joint, position (its midpoint), mode (tensile, shear\n"
    "  or mixed), the energy it dissipated, and the running count and energy.\n"
    "  --since T lists only the events after time T (seconds). --json prints\n"
    "  the server's JSON instead.\n";

static const char *mode_name(long long mode)
{
    return mode == 1 ? "tensile" : mode == 2 ? "shear" : mode == 3 ? "mixed" : "?";
}

static void print_events(const json_t *body)
{
    const json_t *list = json_object_get(body, "events");
    size_t n = json_array_size(list);
    double total = 0;
    printf("%zu fracture events\n", n);
    if (!n) return;
    printf("%14s %8s  %-36s %-8s %12s %7s %12s\n", "time", "joint", "position", "mode", "energy",
           "count", "cumulative");
    for (size_t i = 0; i < n; i++) {
        const json_t *e = json_array_get(list, i);
        const json_t *p = json_object_get(e, "position");
        char position[96];
        size_t at = (size_t)snprintf(position, sizeof position, "(");
        for (size_t k = 0; k < json_array_size(p) && at < sizeof position; k++)
            at += (size_t)snprintf(position + at, sizeof position - at, "%s%.5g", k ? ", " : "",
                                   json_number_value(json_array_get(p, k)));
        if (at < sizeof position) snprintf(position + at, sizeof position - at, ")");
        double energy = json_number_value(json_object_get(e, "energy"));
        total += energy;
        printf("%14.8g %8lld  %-36s %-8s %12.6g %7zu %12.6g\n",
               json_number_value(json_object_get(e, "time")),
               (long long)json_integer_value(json_object_get(e, "joint")), position,
               mode_name(json_integer_value(json_object_get(e, "mode"))), energy, i + 1, total);
    }
    /* n > 0 here; a position has as many components as the case has dimensions */
    size_t dims = json_array_size(json_object_get(json_array_get(list, 0), "position"));
    printf("energy in all: %.6g %s\n", total, dims == 3 ? "J" : "J per metre of thickness");
}

int cmd_events(const ctl_options *o, int argc, char **argv)
{
    int raw = 0;
    const char *id[1], *since = NULL;
    ctl_option_spec specs[] = {{"--since", NULL, &since, NULL}, {"--json", NULL, NULL, &raw}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_EVENTS, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    char path[1024];
    if (http_case_path(path, sizeof path, id[0], "/events") != 0) {
        fprintf(stderr, "fdemctl events: case id too long\n");
        return CTL_USAGE;
    }
    if (since) {
        char *end = NULL;
        double t = strtod(since, &end);
        if (!*since || *end || !isfinite(t)) {
            fprintf(stderr, "fdemctl events: --since takes a time in seconds, not \"%s\"\n%s",
                    since, USAGE_EVENTS);
            return CTL_USAGE;
        }
        size_t used = strlen(path);
        snprintf(path + used, sizeof path - used, "?since=%.17g", t);
    }
    return ctl_show_list(o, path, raw, "events", "an event list", print_events);
}
