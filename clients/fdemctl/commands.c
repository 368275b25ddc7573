/*
 * commands.c - the fdemctl commands that are one request and a printout:
 * health, submit, list, status, start/pause/stop, delete, case, state.
 * (wait.c polls; fetch.c downloads files.)
 *
 * stdout carries only what a script wants to capture (an id, a table, the
 * JSON); every complaint goes to stderr.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <jansson.h>
#include "fdemctl.h"

/* ---------------------------------------------------------------- helpers */

json_t *ctl_get_status(const ctl_options *o, const char *id, int *code)
{
    char path[512];
    http_response r;
    if (http_case_path(path, sizeof path, id, NULL) != 0) {
        fprintf(stderr, "fdemctl: case id '%s' is too long\n", id);
        *code = CTL_USAGE;
        return NULL;
    }
    if ((*code = ctl_call(o, "GET", path, NULL, 0, 200, &r)) != 0) return NULL;
    json_error_t err;
    json_t *status = json_loadb(r.body, r.length, 0, &err);
    http_response_free(&r);
    if (!json_is_object(status)) {
        fprintf(stderr, "fdemctl: the server's status of %s is not a JSON object (%s)\n",
                id, err.text);
        json_decref(status);
        *code = CTL_FAIL;
        return NULL;
    }
    return status;
}

static const char *status_text(json_t *obj, const char *key, const char *fallback)
{
    const char *s = json_string_value(json_object_get(obj, key));
    return s ? s : fallback;
}

/* The status' or dry run's "warnings" (contract 6.2), one a line: where
 * in the case (a JSON Pointer, "" for the whole case) and what. */
static void print_warnings(FILE *f, json_t *s, const char *lead)
{
    size_t i;
    json_t *w;
    json_array_foreach(json_object_get(s, "warnings"), i, w)
        fprintf(f, "%-14s%s: %s\n", lead, status_text(w, "pointer", ""),
                status_text(w, "message", ""));
}

static double status_number(json_t *obj, const char *key)
{
    return json_number_value(json_object_get(obj, key));
}

/* Reads a whole file (or stdin for "-") into a NUL-terminated buffer. */
char *ctl_read_all(const char *path, size_t *length)
{
    FILE *f = strcmp(path, "-") == 0 ? stdin : fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "fdemctl: cannot open %s: %s\n", path, strerror(errno));
        return NULL;
    }
    size_t capacity = 65536, n = 0;
    char *data = malloc(capacity);
    while (data) {
        if (n + 1 >= capacity) {
            char *grown = realloc(data, capacity * 2);
            if (!grown) { free(data); data = NULL; break; }
            data = grown;
            capacity *= 2;
        }
        size_t got = fread(data + n, 1, capacity - n - 1, f);
        n += got;
        if (got == 0) break;
    }
    int failed = ferror(f), read_errno = errno;
    if (f != stdin) fclose(f);
    if (!data || failed) {
        fprintf(stderr, "fdemctl: cannot read %s: %s\n", path,
                data ? strerror(read_errno) : "out of memory");
        free(data);
        return NULL;
    }
    data[n] = '\0';
    *length = n;
    return data;
}

/* GETs /cases/ID<suffix> (JSON) and copies it to stdout byte for byte. */
static int print_case_json(const ctl_options *o, const char *id, const char *suffix)
{
    char path[1024];
    if (http_case_path(path, sizeof path, id, suffix) != 0) {
        fprintf(stderr, "fdemctl: case id or field list too long\n");
        return CTL_USAGE;
    }
    http_response r;
    int code = ctl_call(o, "GET", path, NULL, 0, 200, &r);
    if (code) return code;
    fwrite(r.body, 1, r.length, stdout);
    if (r.length == 0 || r.body[r.length - 1] != '\n') fputc('\n', stdout);
    http_response_free(&r);
    return CTL_OK;
}

/* ----------------------------------------------------------------- health */

static const char USAGE_HEALTH[] =
    "usage: fdemctl health\n"
    "  Checks the server is alive: prints its version and how many cases it holds.\n";

int cmd_health(const ctl_options *o, int argc, char **argv)
{
    ctl_option_spec specs[] = {{0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_HEALTH, NULL, 0, 0);
    if (n < 0) return ctl_args_exit(n);
    http_response r;
    int code = ctl_call(o, "GET", "/health", NULL, 0, 200, &r);
    if (code) return code;
    json_t *h = json_loadb(r.body, r.length, 0, NULL);
    printf("%s: fdemd %s, %lld cases, %lld running\n", status_text(h, "status", "?"),
           status_text(h, "version", "?"), json_integer_value(json_object_get(h, "cases")),
           json_integer_value(json_object_get(h, "running")));
    json_decref(h);
    http_response_free(&r);
    return CTL_OK;
}

/* ----------------------------------------------------------------- submit */

static const char USAGE_SUBMIT[] =
    "usage: fdemctl submit FILE|- [--start | --dry-run]\n"
    "  Uploads a case document (a file, or stdin for -), prints the new case id.\n"
    "  --start    start it at once (POST /cases?start=true)\n"
    "  --dry-run  only check and size it (POST /cases?dry_run=true): prints the\n"
    "             nodes, steps, snapshots, memory, result size and estimated time;\n"
    "             nothing is stored\n"
    "  An invalid case prints every problem as 'pointer: message' and exits 1.\n"
    "  A case that will run for hours is stored with a warning on stderr.\n";

/* "1.5 GiB" */
static void submit_format_bytes(double bytes, char *out, size_t size)
{
    static const char *const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
    int unit = 0;
    while (bytes >= 1024 && unit < 5) { bytes /= 1024; unit++; }
    if (unit == 0) snprintf(out, size, "%.0f bytes", bytes);
    else snprintf(out, size, "%.3g %s", bytes, units[unit]);
}

int ctl_print_sizing(const http_response *r)
{
    json_t *z = json_loadb(r->body, r->length, 0, NULL);
    if (!json_is_object(z)) {
        fprintf(stderr, "fdemctl: the server's dry run answer is not a JSON object\n");
        json_decref(z);
        return CTL_FAIL;
    }
    char memory[32], result[32];
    submit_format_bytes(status_number(z, "memory_bytes"), memory, sizeof memory);
    submit_format_bytes(status_number(z, "result_bytes"), result, sizeof result);
    printf("%-18s%.0f nodes, %.0f elements, %.0f joints\n", "mesh", status_number(z, "nodes"),
           status_number(z, "elements"), status_number(z, "joints"));
    printf("%-18s%.0f of %.4g s\n", "steps", status_number(z, "steps"), status_number(z, "dt"));
    printf("%-18s%.0f\n", "snapshots", status_number(z, "snapshots"));
    printf("%-18s%s\n", "memory", memory);
    printf("%-18s%s\n", "result.h5", result);
    printf("%-18s%.3g s\n", "estimated time", status_number(z, "estimated_seconds"));
    const char *warning = status_text(z, "warning", NULL);
    if (warning) fprintf(stderr, "fdemctl: warning: %s\n", warning);
    print_warnings(stderr, z, "fdemctl: warning");
    json_decref(z);
    return CTL_OK;
}

int cmd_submit(const ctl_options *o, int argc, char **argv)
{
    int start = 0, dry_run = 0;
    const char *file[1];
    ctl_option_spec specs[] = {{"--start", NULL, NULL, &start},
                               {"--dry-run", NULL, NULL, &dry_run}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_SUBMIT, file, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    if (start && dry_run) {
        fprintf(stderr, "fdemctl submit: --dry-run stores nothing, so it cannot --start\n%s",
                USAGE_SUBMIT);
        return CTL_USAGE;
    }

    size_t length;
    char *text = ctl_read_all(file[0], &length);
    if (!text) return CTL_USAGE;
    http_response r;
    const char *path = dry_run ? "/cases?dry_run=true" : start ? "/cases?start=true" : "/cases";
    int code = ctl_call(o, "POST", path, text, length, dry_run ? 200 : 201, &r);
    free(text);
    if (code) return code;
    if (dry_run) {
        code = ctl_print_sizing(&r);
        http_response_free(&r);
        return code;
    }
    json_t *status = json_loadb(r.body, r.length, 0, NULL);
    const char *id = status_text(status, "id", NULL);
    const char *warning = status_text(status, "warning", NULL);
    if (id) printf("%s\n", id);
    else fprintf(stderr, "fdemctl: the server created the case but sent no id\n");
    if (warning) fprintf(stderr, "fdemctl: warning: %s\n", warning);
    print_warnings(stderr, status, "fdemctl: warning");
    json_decref(status);
    http_response_free(&r);
    return id ? CTL_OK : CTL_FAIL;
}

/* ------------------------------------------------------------------- list */

static const char USAGE_LIST[] =
    "usage: fdemctl list [--state STATE]\n"
    "  One line per case, oldest first: id, name, state, progress, step, time,\n"
    "  CPU (the share of a core the case's stepping got of late; '-' unless\n"
    "  running), speed (steps per second: now while running, else the mean of\n"
    "  the run) and ETA (wall time left from the recent speed; '-' unless running).\n"
    "  --state S   only the cases in state S (created, queued, running, paused,\n"
    "              finished, stopped or failed)\n";

/* A duration as a person reads it: "42s", "3m05s", "2h07m", "3.1d";
 * "-" when unknown (a status whose eta is null). */
static void list_duration_text(json_t *value, char *out, size_t size)
{
    if (!json_is_number(value)) {
        snprintf(out, size, "-");
        return;
    }
    double s = json_number_value(value);
    if (!(s >= 0)) snprintf(out, size, "-");
    else if (s < 59.5) snprintf(out, size, "%.0fs", s);
    else if (s < 3600 - 0.5) snprintf(out, size, "%dm%02ds", (int)(s + 0.5) / 60, (int)(s + 0.5) % 60);
    else if (s < 86400 * 2) snprintf(out, size, "%dh%02dm", (int)(s / 3600), (int)(s / 60) % 60);
    else snprintf(out, size, "%.1fd", s / 86400);
}

static void list_print_row(json_t *c, int id_width, int name_width)
{
    char eta[32], cpu[16] = "-";
    list_duration_text(json_object_get(c, "eta"), eta, sizeof eta);
    json_t *share = json_object_get(c, "cpu_share");
    if (json_is_number(share))
        snprintf(cpu, sizeof cpu, "%.0f%%", 100.0 * json_number_value(share));
    printf("%-*s  %-*s  %-9s %6.1f%%  %10lld  %-10.4g  %4s  %10.4g  %s\n", id_width,
           status_text(c, "id", "?"), name_width, status_text(c, "name", ""),
           status_text(c, "state", "?"), 100.0 * status_number(c, "progress"),
           json_integer_value(json_object_get(c, "step")), status_number(c, "time"), cpu,
           status_number(c, "steps_per_second"), eta);
}

int cmd_list(const ctl_options *o, int argc, char **argv)
{
    const char *state = NULL;
    ctl_option_spec specs[] = {{"--state", NULL, &state, NULL}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_LIST, NULL, 0, 0);
    if (n < 0) return ctl_args_exit(n);
    char path[64] = "/cases";
    if (state) {
        /* State names are lower-case words: nothing to escape, and the
         * server names the valid ones if this is not one. */
        size_t len = strspn(state, "abcdefghijklmnopqrstuvwxyz");
        if (len == 0 || state[len] != '\0' || len > 32) {
            fprintf(stderr, "fdemctl list: --state takes a state name such as running, not '%s'\n",
                    state);
            return CTL_USAGE;
        }
        snprintf(path, sizeof path, "/cases?state=%s", state);
    }
    http_response r;
    int code = ctl_call(o, "GET", path, NULL, 0, 200, &r);
    if (code) return code;
    json_t *doc = json_loadb(r.body, r.length, 0, NULL);
    http_response_free(&r);
    json_t *cases = json_object_get(doc, "cases");
    if (!json_is_array(cases)) {
        fprintf(stderr, "fdemctl: the server's case list has no \"cases\" array\n");
        json_decref(doc);
        return CTL_FAIL;
    }
    int id_width = 2, name_width = 4;
    size_t i;
    json_t *c;
    json_array_foreach(cases, i, c) {
        int w = (int)strlen(status_text(c, "id", "?"));
        if (w > id_width) id_width = w;
        w = (int)strlen(status_text(c, "name", ""));
        if (w > name_width) name_width = w;
    }
    if (name_width > 40) name_width = 40;
    printf("%-*s  %-*s  %-9s %7s  %10s  %-10s  %4s  %10s  %s\n", id_width, "ID", name_width,
           "NAME", "STATE", "PROGRESS", "STEP", "TIME [s]", "CPU", "STEPS/S", "ETA");
    json_array_foreach(cases, i, c) list_print_row(c, id_width, name_width);
    json_decref(doc);
    return CTL_OK;
}

/* ----------------------------------------------------------------- status */

static const char USAGE_STATUS[] =
    "usage: fdemctl status ID [--json]\n"
    "  Shows the progress and figures of one case.\n"
    "  --json    print the server's status object exactly as it was sent\n";

/* 2D energies are per metre of thickness, 3D ones plain joules (contract
 * 5.2); a status that does not say its dimension gets both units named. */
static const char *energy_label(json_t *status)
{
    json_t *dimension = json_object_get(status, "dimension");
    if (!json_is_integer(dimension)) return "energy [J/m; J in 3D]";
    return json_integer_value(dimension) == 3 ? "energy [J]" : "energy [J/m]";
}

static void status_print_energy(json_t *status)
{
    json_t *energy = json_object_get(status, "energy");
    if (!json_is_object(energy)) return;
    const char *label = energy_label(status);
    printf("%-14s%s", label, strlen(label) < 14 ? "" : " ");
    const char *key;
    json_t *value;
    int first = 1;
    json_object_foreach(energy, key, value) {
        printf("%s%s %.4g", first ? "" : ", ", key, json_number_value(value));
        first = 0;
    }
    printf("\n");
}

/* Every scalar the table above does not show, so new server fields appear. */
static void status_print_others(json_t *s)
{
    static const char *shown[] = {"id", "name", "state", "step", "time", "end_time",
                                  "progress", "dt", "nodes", "elements", "joints",
                                  "broken_joints", "contacts", "snapshots", "energy",
                                  "steps_per_second", "error", NULL};
    const char *key;
    json_t *value;
    json_object_foreach(s, key, value) {
        int known = 0;
        for (int i = 0; shown[i]; i++) known |= strcmp(shown[i], key) == 0;
        if (known || json_is_null(value) || json_is_object(value) || json_is_array(value))
            continue;
        if (json_is_string(value)) printf("%-14s%s\n", key, json_string_value(value));
        else if (json_is_integer(value)) printf("%-14s%lld\n", key, json_integer_value(value));
        else if (json_is_real(value)) printf("%-14s%.6g\n", key, json_real_value(value));
        else if (json_is_boolean(value)) printf("%-14s%s\n", key, json_is_true(value) ? "true" : "false");
    }
}

void ctl_stage_text(json_t *status, char *out, size_t size)
{
    json_t *stage = json_object_get(status, "stage");
    json_t *index = json_object_get(stage, "index");
    const char *name = json_string_value(json_object_get(stage, "name"));
    if (json_is_integer(index))
        snprintf(out, size, "%lld \"%.64s\"", json_integer_value(index), name ? name : "");
    else
        snprintf(out, size, "%s", "");
}

static void status_print_table(json_t *s)
{
    printf("%-14s%s\n", "id", status_text(s, "id", "?"));
    printf("%-14s%s\n", "name", status_text(s, "name", ""));
    printf("%-14s%s\n", "state", status_text(s, "state", "?"));
    printf("%-14s%.1f %%  (t = %.6g of %.6g s)\n", "progress", 100.0 * status_number(s, "progress"),
           status_number(s, "time"), status_number(s, "end_time"));
    printf("%-14s%lld\n", "step", json_integer_value(json_object_get(s, "step")));
    char stage[96];
    ctl_stage_text(s, stage, sizeof stage);
    if (stage[0]) printf("%-14s%s\n", "stage", stage);
    printf("%-14s%.4g s\n", "dt", status_number(s, "dt"));
    printf("%-14s%lld nodes, %lld elements, %lld joints (%lld broken)\n", "mesh",
           json_integer_value(json_object_get(s, "nodes")),
           json_integer_value(json_object_get(s, "elements")),
           json_integer_value(json_object_get(s, "joints")),
           json_integer_value(json_object_get(s, "broken_joints")));
    printf("%-14s%lld\n", "contacts", json_integer_value(json_object_get(s, "contacts")));
    json_t *fluid = json_object_get(s, "fluid"); /* contract 6.4, null without fluid */
    if (json_is_object(fluid))
        printf("%-14sinjected %.4g, stored %.4g, source pressure %.4g Pa, flow step %.3g s x %lld\n",
               "fluid", status_number(fluid, "injected_volume"),
               status_number(fluid, "stored_volume"), status_number(fluid, "source_pressure"),
               status_number(fluid, "fluid_step"),
               json_integer_value(json_object_get(fluid, "fluid_subcycles")));
    printf("%-14s%lld\n", "snapshots", json_integer_value(json_object_get(s, "snapshots")));
    status_print_energy(s);
    printf("%-14s%.4g steps/s\n", "speed", status_number(s, "steps_per_second"));
    status_print_others(s);
    const char *error = status_text(s, "error", NULL);
    if (error) printf("%-14s%s\n", "error", error);
    print_warnings(stdout, s, "warning");
}

int cmd_status(const ctl_options *o, int argc, char **argv)
{
    int raw = 0;
    const char *id[1];
    ctl_option_spec specs[] = {{"--json", NULL, NULL, &raw}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_STATUS, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    if (raw) return print_case_json(o, id[0], NULL);
    int code;
    json_t *s = ctl_get_status(o, id[0], &code);
    if (!s) return code;
    status_print_table(s);
    json_decref(s);
    return CTL_OK;
}

/* ------------------------------------------------------ start/pause/stop */

static const char USAGE_CONTROL[] =
    "usage: fdemctl start|pause|stop ID\n"
    "  start  runs a created or paused case\n"
    "  pause  pauses a running case at the next step boundary\n"
    "  stop   ends a case for good (its results are kept)\n"
    "  Prints the case's state afterwards; a command the state does not allow exits 1.\n";

int cmd_control(const ctl_options *o, int argc, char **argv)
{
    const char *id[1];
    ctl_option_spec specs[] = {{0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_CONTROL, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    char suffix[16], path[512];
    snprintf(suffix, sizeof suffix, "/%s", argv[0]);
    if (http_case_path(path, sizeof path, id[0], suffix) != 0) {
        fprintf(stderr, "fdemctl: case id '%s' is too long\n", id[0]);
        return CTL_USAGE;
    }
    http_response r;
    int code = ctl_call(o, "POST", path, NULL, 0, 200, &r);
    if (code) return code;
    json_t *s = json_loadb(r.body, r.length, 0, NULL);
    printf("%s %s\n", id[0], status_text(s, "state", "?"));
    json_decref(s);
    http_response_free(&r);
    return CTL_OK;
}

/* ----------------------------------------------------------------- delete */

static const char USAGE_DELETE[] =
    "usage: fdemctl delete ID\n"
    "  Stops the case if needed and removes it with all its files.\n";

int cmd_delete(const ctl_options *o, int argc, char **argv)
{
    const char *id[1];
    ctl_option_spec specs[] = {{0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_DELETE, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    char path[512];
    if (http_case_path(path, sizeof path, id[0], NULL) != 0) {
        fprintf(stderr, "fdemctl: case id '%s' is too long\n", id[0]);
        return CTL_USAGE;
    }
    http_response r;
    int code = ctl_call(o, "DELETE", path, NULL, 0, 204, &r);
    if (code) return code;
    printf("%s deleted\n", id[0]);
    http_response_free(&r);
    return CTL_OK;
}

/* -------------------------------------------------------- case and state */

static const char USAGE_CASE[] =
    "usage: fdemctl case ID\n"
    "  Prints the case document exactly as it was uploaded.\n";

int cmd_case(const ctl_options *o, int argc, char **argv)
{
    const char *id[1];
    ctl_option_spec specs[] = {{0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_CASE, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    return print_case_json(o, id[0], "/case");
}

static const char USAGE_STATE[] =
    "usage: fdemctl state ID [--fields FIELD,...]\n"
    "  FIELD: position, velocity, stress, damage, strain, principal_stress,\n"
    "  displacement (default: position,velocity).\n"
    "  Prints the current state (taken at one step boundary) as JSON:\n"
    "  position/velocity/displacement [[x, y], ...] per node ([[x, y, z], ...]\n"
    "  in 3D; displacement = position - initial position), stress and strain\n"
    "  [[xx, yy, xy], ...] per element (3D: xx, yy, zz, yz, xz, xy),\n"
    "  principal_stress [[s1, s2], ...] (3D: three) descending with tension\n"
    "  positive: the last column is the most compressive, sigma1 of rock\n"
    "  mechanics (principal_stress_names), damage per joint.\n";

int cmd_state(const ctl_options *o, int argc, char **argv)
{
    const char *id[1], *fields = NULL;
    ctl_option_spec specs[] = {{"--fields", "-f", &fields, NULL}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_STATE, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;
    char suffix[512] = "/state";
    if (fields) {
        for (const char *c = fields; *c; c++) {
            if (!(*c == ',' || *c == '_' || (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z'))) {
                fprintf(stderr, "fdemctl state: --fields takes names separated by commas, "
                        "not '%s'\n", fields);
                return CTL_USAGE;
            }
        }
        snprintf(suffix, sizeof suffix, "/state?fields=%.400s", fields);
    }
    return print_case_json(o, id[0], suffix);
}
