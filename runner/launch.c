/*
 * launch.c - the launcher line of a case's ranks (launch.h).
 */
#include "launch.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <wordexp.h>

/* `line` with each {ranks} replaced by the number, or NULL without memory. */
static char *launch_substitute(const char *line, int ranks)
{
    char number[16];
    snprintf(number, sizeof number, "%d", ranks);
    size_t count = 0;
    for (const char *p = strstr(line, "{ranks}"); p; p = strstr(p + 7, "{ranks}"))
        count++;
    size_t size = strlen(line) + count * strlen(number) + 1;
    char *out = malloc(size), *w = out;
    if (!out)
        return NULL;
    for (const char *p = line; *p;) {
        if (strncmp(p, "{ranks}", 7) == 0) {
            w += sprintf(w, "%s", number);
            p += 7;
        } else {
            *w++ = *p++;
        }
    }
    *w = '\0';
    return out;
}

char **launch_argv(const char *line, int ranks, const char *const *extra, char *err,
                   size_t errlen)
{
    char *text = launch_substitute(line, ranks);
    if (!text) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    wordexp_t we;
    int rc = wordexp(text, &we, WRDE_NOCMD);
    free(text);
    if (rc != 0) {
        snprintf(err, errlen, "the launcher line \"%s\" cannot be split into words (%s)", line,
                 rc == WRDE_CMDSUB ? "command substitution is not allowed"
                 : rc == WRDE_BADCHAR ? "it holds one of | & ; < > ( ) { } or a newline"
                 : "unbalanced quotes or a syntax error");
        return NULL;
    }
    if (we.we_wordc == 0) {
        wordfree(&we);
        snprintf(err, errlen, "the launcher line is empty");
        return NULL;
    }
    size_t n_extra = 0;
    while (extra && extra[n_extra])
        n_extra++;
    char **argv = calloc(we.we_wordc + n_extra + 1, sizeof *argv);
    int ok = argv != NULL;
    for (size_t i = 0; ok && i < we.we_wordc; i++)
        ok = (argv[i] = strdup(we.we_wordv[i])) != NULL;
    for (size_t i = 0; ok && i < n_extra; i++)
        ok = (argv[we.we_wordc + i] = strdup(extra[i])) != NULL;
    wordfree(&we);
    if (!ok) {
        launch_argv_free(argv);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    return argv;
}

void launch_argv_free(char **argv)
{
    if (!argv)
        return;
    for (char **a = argv; *a; a++)
        free(*a);
    free(argv);
}

int launch_beside_binary(const char *name, char *out, size_t size)
{
    char self[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0)
        return -1;
    self[n] = '\0';
    char *slash = strrchr(self, '/');
    if (!slash)
        return -1;
    *slash = '\0';
    return (size_t)snprintf(out, size, "%s/%s", self, name) < size ? 0 : -1;
}

int launch_rank_binary(char *out, size_t size)
{
    if (launch_beside_binary("fdem-rank", out, size) != 0)
        return -1;
    return access(out, X_OK) == 0 ? 0 : -1;
}

char *launch_rank_asan_options(void)
{
    const char *given = getenv("ASAN_OPTIONS");
    if (!given)
        return NULL;
    static const char prefix[] = "ASAN_OPTIONS=", suffix[] = ":detect_leaks=0";
    size_t n = sizeof prefix - 1 + strlen(given) + sizeof suffix;
    char *out = malloc(n);
    if (out)
        snprintf(out, n, "%s%s%s", prefix, given, suffix);
    return out;
}
