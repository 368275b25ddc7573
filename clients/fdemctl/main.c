/*
 * main.c - fdemctl, the command-line client of the fdemd daemon.
 *
 *   fdemctl [--server URL] COMMAND [ARGS...]   (--server may also follow COMMAND)
 *
 * Reads the global options (server URL from --server or FDEMD_URL, token
 * from FDEMD_TOKEN) once into an immutable ctl_options and dispatches to one
 * function per command. The token is deliberately not a command-line
 * option: arguments are visible to every user through ps.
 */
#include <stdlib.h>
#include <string.h>
#include <curl/curl.h>
#include "fdemctl.h"

#define CTL_DEFAULT_SERVER "http://127.0.0.1:8080"

typedef struct ctl_command {
    const char *name;
    int (*run)(const ctl_options *o, int argc, char **argv);
    const char *summary;
} ctl_command;

static const ctl_command ctl_commands[] = {
    {"submit", cmd_submit, "submit FILE|- [--start]   upload a case, print its id (--dry-run: only size it)"},
    {"list",   cmd_list,   "list [--state S]          cases (in state S): id, name, state, progress"},
    {"status", cmd_status, "status ID [--json]        progress and figures of one case"},
    {"start",  cmd_control, "start ID                  run a created or paused case"},
    {"pause",  cmd_control, "pause ID                  pause a running case"},
    {"stop",   cmd_control, "stop ID                   end a case (results kept)"},
    {"delete", cmd_delete, "delete ID                 remove a case and its files"},
    {"wait",   cmd_wait,   "wait ID [--interval S]    follow progress; exit 0 iff finished"},
    {"state",  cmd_state,  "state ID [--fields LIST]  current state as JSON"},
    {"fragments", cmd_fragments, "fragments ID [--parts A,B] [--exclude-host] [--json] fragments and sieve curve"},
    {"events", cmd_events, "events ID [--since T]     fracture events: time, joint, position, mode, energy"},
    {"history", cmd_history, "history ID [--since T] [--csv FILE] history rows as CSV (points, constraints, energy)"},
    {"fetch",  cmd_fetch,  "fetch ID [-o F] [--force] download result.h5 + .xdmf (as <name>.h5)"},
    {"extend", cmd_extend, "extend ID END [--start]   run a finished or paused case on to a later end"},
    {"clone",  cmd_clone,  "clone ID PATCH|- [--start|--dry-run] new case from a stored one + a merge or JSON Patch"},
    {"case",   cmd_case,   "case ID                   the case document as uploaded"},
    {"health", cmd_health, "health                    is the server alive"},
    {NULL, NULL, NULL},
};

static void ctl_print_help(FILE *out)
{
    fprintf(out,
            "usage: fdemctl [--server URL] COMMAND [ARGS...]\n"
            "\n"
            "Drives an fdemd simulation server over HTTP.\n"
            "\n"
            "commands:\n");
    for (const ctl_command *c = ctl_commands; c->name; c++) fprintf(out, "  %s\n", c->summary);
    fprintf(out,
            "\n"
            "options:\n"
            "  --server URL   server base URL (default $FDEMD_URL, else " CTL_DEFAULT_SERVER ")\n"
            "  --help         this text; 'fdemctl COMMAND --help' explains one command\n"
            "\n"
            "environment:\n"
            "  FDEMD_URL      server base URL\n"
            "  FDEMD_TOKEN    bearer token, when the server was started with --token\n"
            "\n"
            "case ids: every ID may be shortened to a prefix that only one case's id\n"
            "starts with (fdemctl status 3f2a); a prefix several ids share is refused,\n"
            "listing them.\n"
            "\n"
            "exit status: 0 success, 1 refused by the server (or the case failed/was\n"
            "stopped, for wait; or no case has that id: 404), 2 usage or connection\n"
            "error (an id prefix shared by several cases is a usage error).\n");
}

static const ctl_command *ctl_find_command(const char *name)
{
    for (const ctl_command *c = ctl_commands; c->name; c++)
        if (strcmp(c->name, name) == 0) return c;
    return NULL;
}

/* Copies the URL without trailing slashes; NULL when it is not http(s). */
static char *ctl_server_url(const char *url)
{
    if (strncmp(url, "http://", 7) != 0 && strncmp(url, "https://", 8) != 0) {
        fprintf(stderr, "fdemctl: the server URL must start with http:// or https://, "
                "not '%s'\n", url);
        return NULL;
    }
    char *copy = strdup(url);
    if (!copy) return NULL;
    size_t n = strlen(copy);
    while (n > 0 && copy[n - 1] == '/') copy[--n] = '\0';
    return copy;
}

/* Consumes the options that come before the command; returns the index of
 * the command word, or -1 for an error, or 0 when --help was printed. */
static int ctl_global_options(int argc, char **argv, const char **server)
{
    int i = 1;
    while (i < argc && argv[i][0] == '-') {
        const char *arg = argv[i];
        if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
            ctl_print_help(stdout);
            return 0;
        } else if (strcmp(arg, "--server") == 0 && i + 1 < argc) {
            *server = argv[i + 1];
            i += 2;
        } else if (strncmp(arg, "--server=", 9) == 0) {
            *server = arg + 9;
            i += 1;
        } else {
            fprintf(stderr, "fdemctl: unknown option '%s'\n\n", arg);
            ctl_print_help(stderr);
            return -1;
        }
    }
    if (i == argc) {
        ctl_print_help(stderr);
        return -1;
    }
    return i;
}

/* --server may also follow the command ("fdemctl list --server URL"), as
 * every command's own options may: takes it out of the command's arguments
 * (up to a "--") so the command never sees it. Returns the new count, or -1
 * when --server has no value. */
static int ctl_server_after_command(int argc, char **argv, const char **server)
{
    int kept = 1, options_done = 0;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (!options_done && strcmp(arg, "--") == 0) options_done = 1;
        if (!options_done && strcmp(arg, "--server") == 0) {
            if (i + 1 == argc) {
                fprintf(stderr, "fdemctl %s: option needs a value '--server'\n", argv[0]);
                return -1;
            }
            *server = argv[++i];
            continue;
        }
        if (!options_done && strncmp(arg, "--server=", 9) == 0) {
            *server = arg + 9;
            continue;
        }
        argv[kept++] = argv[i];
    }
    argv[kept] = NULL;
    return kept;
}

int main(int argc, char **argv)
{
    const char *server = getenv("FDEMD_URL");
    if (!server || !server[0]) server = CTL_DEFAULT_SERVER;
    int first = ctl_global_options(argc, argv, &server);
    if (first <= 0) return first == 0 ? CTL_OK : CTL_USAGE;

    const ctl_command *command = ctl_find_command(argv[first]);
    if (!command) {
        fprintf(stderr, "fdemctl: unknown command '%s' (try fdemctl --help)\n", argv[first]);
        return CTL_USAGE;
    }
    int command_argc = ctl_server_after_command(argc - first, argv + first, &server);
    if (command_argc < 0) return CTL_USAGE;
    char *url = ctl_server_url(server);
    if (!url) return CTL_USAGE;
    const char *token = getenv("FDEMD_TOKEN");
    ctl_options options = {url, token && token[0] ? token : NULL};

    if (curl_global_init(CURL_GLOBAL_DEFAULT) != 0) {
        fprintf(stderr, "fdemctl: cannot initialise libcurl\n");
        free(url);
        return CTL_USAGE;
    }
    int code = command->run(&options, command_argc, argv + first);
    curl_global_cleanup();
    free(url);
    return code;
}
