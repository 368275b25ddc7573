/*
 * args.c - option parsing shared by every fdemctl command.
 *
 * Hand-written rather than getopt_long because options may follow the
 * positionals ("fdemctl submit case.json --start") on every platform, and
 * because "-" must stay a positional meaning stdin.
 */
#include <string.h>
#include "fdemctl.h"

static const ctl_option_spec *args_find(const ctl_option_spec *specs, const char *arg,
                                        size_t name_length)
{
    for (const ctl_option_spec *s = specs; s->name; s++) {
        if (strlen(s->name) == name_length && strncmp(s->name, arg, name_length) == 0)
            return s;
        if (s->short_name && strlen(s->short_name) == name_length &&
            strncmp(s->short_name, arg, name_length) == 0)
            return s;
    }
    return NULL;
}

static int args_error(const char *usage, const char *command, const char *what,
                      int length, const char *arg)
{
    fprintf(stderr, "fdemctl %s: %s '%.*s'\n", command, what, length, arg);
    fputs(usage, stderr);
    return ARGS_ERROR;
}

static int args_is_help(const char *arg)
{
    return strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0;
}

int ctl_parse_args(int argc, char **argv, const ctl_option_spec *specs, const char *usage,
                   const char **positional, int min_positional, int max_positional)
{
    int count = 0, options_done = 0;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        int is_option = !options_done && arg[0] == '-' && arg[1] != '\0';
        if (is_option && strcmp(arg, "--") == 0) { options_done = 1; continue; }
        if (is_option && args_is_help(arg)) { fputs(usage, stdout); return ARGS_HELP; }
        if (!is_option) {
            if (count == max_positional)
                return args_error(usage, argv[0], "unexpected argument", (int)strlen(arg), arg);
            positional[count++] = arg;
            continue;
        }
        const char *eq = strchr(arg, '=');
        int name_length = eq ? (int)(eq - arg) : (int)strlen(arg);
        const ctl_option_spec *s = args_find(specs, arg, (size_t)name_length);
        if (!s)
            return args_error(usage, argv[0], "unknown option", name_length, arg);
        if (s->flag) {
            if (eq) return args_error(usage, argv[0], "option takes no value", name_length, arg);
            *s->flag = 1;
        } else if (eq) {
            *s->value = eq + 1;
        } else if (i + 1 < argc) {
            *s->value = argv[++i];
        } else {
            return args_error(usage, argv[0], "option needs a value", name_length, arg);
        }
    }
    if (count < min_positional) {
        fprintf(stderr, "fdemctl %s: missing argument\n", argv[0]);
        fputs(usage, stderr);
        return ARGS_ERROR;
    }
    return count;
}
