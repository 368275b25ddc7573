/*
 * fault_point.c - the crash a test asks for at a named point
 * (fault_point.h). It reads the environment at each call: the points sit
 * on rare paths (an extend), never in the step loop.
 */
#include "fault_point.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void fault_point(const char *name)
{
    const char *wanted = getenv("FDEMD_FAULT_POINT");
    if (!wanted || strcmp(wanted, name) != 0)
        return;
    fprintf(stderr, "fdemd: FDEMD_FAULT_POINT=%s: killing the daemon here\n", name);
    raise(SIGKILL);
}
