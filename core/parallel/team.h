/*
 * team.h - which thread of its team the caller is, inside an OpenMP
 * parallel region: the contact and joint loops cut their work into
 * shares by it. Without OpenMP every region is one thread, number 0.
 * And the one such share every step needs: an array of forces zeroed.
 */
#ifndef FDEM_PARALLEL_TEAM_H
#define FDEM_PARALLEL_TEAM_H

#include <stddef.h>
#include <string.h>

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

/* a[0, n) zeroed, a contiguous share per thread on `threads` threads (1:
 * here alone). A force array of 1e5 triangles is 4.8 MB a step: zeroed on
 * one thread while the others wait, it was a twentieth of a broken 2D
 * block's step on two. */
static inline void parallel_zero(double *a, size_t n, int threads)
{
#pragma omp parallel num_threads(threads) if (threads > 1)
    {
        int t, nt;
        parallel_team(&t, &nt);
        size_t lo = n * (size_t)t / (size_t)nt, hi = n * (size_t)(t + 1) / (size_t)nt;
        memset(a + lo, 0, sizeof(double) * (hi - lo));
    }
}

#endif /* FDEM_PARALLEL_TEAM_H */
