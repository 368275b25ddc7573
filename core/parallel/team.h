/*
 * team.h - which thread of its team the caller is, inside an OpenMP
 * parallel region: the contact and joint loops cut their work into
 * shares by it. Without OpenMP every region is one thread, number 0.
 */
#ifndef FDEM_PARALLEL_TEAM_H
#define FDEM_PARALLEL_TEAM_H

#ifdef _OPENMP
#include <omp.h>
#endif

/* *t: this thread's number, *nt: the team's size (0 and 1 outside a
 * region or without OpenMP). */
static inline void parallel_team(int *t, int *nt)
{
#ifdef _OPENMP
    *t = omp_get_thread_num();
    *nt = omp_get_num_threads();
#else
    *t = 0;
    *nt = 1;
#endif
}

#endif /* FDEM_PARALLEL_TEAM_H */
