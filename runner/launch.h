/*
 * launch.h - the command line that starts a case's ranks: the launcher
 * (`--launcher`, FDEM_LAUNCHER, default LAUNCH_DEFAULT: any line with
 * {ranks}, e.g. Slurm's `srun -n {ranks}`) followed by bin/fdem-rank and its
 * arguments. bin/fdem-run --ranks N and the daemon's ranked cases build it
 * here, so both start the same processes.
 *
 * Contract: launch_argv() replaces every {ranks} with N, splits the line as
 * a shell would split words (wordexp(3) without command substitution:
 * quotes and $VARIABLES work, `$(...)` is refused) and appends `extra`
 * (NULL-terminated). A NULL-terminated argv to free with
 * launch_argv_free(), or NULL with a sentence in err.
 */
#ifndef FDEM_LAUNCH_H
#define FDEM_LAUNCH_H

#include <stddef.h>

#define LAUNCH_DEFAULT "mpirun -np {ranks} --oversubscribe"

char **launch_argv(const char *line, int ranks, const char *const *extra, char *err,
                   size_t errlen);
void launch_argv_free(char **argv);
/* The path of bin/fdem-rank beside the running executable (/proc/self/exe),
 * into out; 0, or -1 when it cannot be found. */
int launch_rank_binary(char *out, size_t size);
/* out = NAME in the folder of the running binary ("../web" from bin/fdemd
 * finds the web page); -1 when /proc/self/exe cannot be read or out is
 * too small. */
int launch_beside_binary(const char *name, char *out, size_t size);
/* "ASAN_OPTIONS=<the caller's>:detect_leaks=0" for the ranks (malloc'd),
 * NULL when the caller has no ASAN_OPTIONS. A sanitizer build of
 * bin/fdem-rank turns leak checks off in __asan_default_options, since
 * OpenMPI keeps allocations past MPI_Finalize in modules it has unloaded,
 * but an ASAN_OPTIONS in the environment (CI sets detect_leaks=1) wins
 * over that and failed every ranked run at its exit (status 134). */
char *launch_rank_asan_options(void);

#endif
