/*
 * test_launch.c - the launcher line of a case's ranks (runner/launch.h):
 * {ranks} replaced everywhere, words split as a shell splits them, the
 * extra arguments appended, and a line that cannot be split (command
 * substitution, a pipe, an open quote, nothing) refused with a sentence.
 */
#include <string.h>

#include "check.h"
#include "launch.h"

static int argv_equals(char **argv, const char *const *want)
{
    int i = 0;
    for (; argv[i] && want[i]; i++)
        if (strcmp(argv[i], want[i]) != 0)
            return 0;
    return !argv[i] && !want[i];
}

static void default_line_with_the_rank_binary(void)
{
    char err[300] = "";
    const char *extra[] = {"bin/fdem-rank", "case.json", "--out", "dir", NULL};
    char **argv = launch_argv(LAUNCH_DEFAULT, 4, extra, err, sizeof err);
    const char *want[] = {"mpirun", "-np", "4", "--oversubscribe", "bin/fdem-rank", "case.json",
                          "--out", "dir", NULL};
    CHECK(argv && argv_equals(argv, want), "default line split wrong (%s)", err);
    launch_argv_free(argv);
}

static void every_ranks_is_replaced_and_quotes_hold(void)
{
    char err[300] = "";
    char **argv = launch_argv("srun -n {ranks} --label 'a b' --x={ranks}{ranks}", 12, NULL, err,
                              sizeof err);
    const char *want[] = {"srun", "-n", "12", "--label", "a b", "--x=1212", NULL};
    CHECK(argv && argv_equals(argv, want), "srun line split wrong (%s)", err);
    launch_argv_free(argv);
}

static void lines_that_cannot_be_split_are_refused(void)
{
    const char *bad[] = {"mpirun -np $(nproc)", "mpirun -np {ranks} | tee log",
                         "mpirun 'open", "", "   "};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        char err[300] = "";
        char **argv = launch_argv(bad[i], 2, NULL, err, sizeof err);
        CHECK(!argv, "\"%s\" was accepted", bad[i]);
        CHECK(strstr(err, "launcher") != NULL, "\"%s\": no sentence naming the launcher: %s",
              bad[i], err);
        launch_argv_free(argv);
    }
}

CHECK_MAIN(T(default_line_with_the_rank_binary), T(every_ranks_is_replaced_and_quotes_hold),
           T(lines_that_cannot_be_split_are_refused))
