/*
 * heavy_work.h - threads of their own for the requests whose work is a
 * model build (creating, dry-running and cloning a case; the state and
 * fragments of a case that holds no model), so that the threads that
 * answer HTTP never wait on them (issue 30, item 9: four rebuilds of a
 * 750k-tetrahedron case held every HTTP thread for 46 s).
 *
 * Contract:
 *  - heavy_work_reserve() takes a place in the bounded queue, or returns -1
 *    when every place is taken (the caller answers 503 at once, so no
 *    request is ever dropped unanswered); heavy_work_submit() then hands
 *    the job over and cannot fail. Reserving before submitting lets the
 *    caller suspend its connection in between, so a job never finishes
 *    before its connection was suspended.
 *  - Jobs run in the order submitted, HEAVY_WORK_THREADS at a time.
 *  - heavy_work_stop() runs every job already submitted, then ends the
 *    threads; a reserve or submit after it fails.
 */
#ifndef FDEMD_HEAVY_WORK_H
#define FDEMD_HEAVY_WORK_H

#define HEAVY_WORK_THREADS 2
#define HEAVY_WORK_QUEUE 32 /* jobs waiting or running at once */

typedef void (*heavy_work_fn)(void *arg);

int heavy_work_start(void);
int heavy_work_reserve(void);
void heavy_work_submit(heavy_work_fn fn, void *arg);
void heavy_work_stop(void);

#endif /* FDEMD_HEAVY_WORK_H */
