/*
 * case_feed.h - the daemon-wide feed of case events that GET /stream
 * serves (contract 6.3): a case's status when its state changes and, while
 * it runs, at most CASE_FEED_STATUS_RATE times a second; each snapshot
 * written; each case deleted.
 *
 * Contract:
 *  - Every event gets an id one above the last. The first id of a run is
 *    the wall clock at start-up in microseconds, so ids also grow across
 *    restarts and an id from an earlier run is never mistaken for one of
 *    this run's.
 *  - The last CASE_FEED_KEEP events are kept, each as its whole
 *    text/event-stream block ("id: N\nevent: KIND\ndata: JSON\n\n"), so a
 *    reader that comes back with the last id it saw misses nothing if it
 *    is within them; one further behind is told so (case_feed_read).
 *  - Publishing takes no lock a caller may hold except its own, and must
 *    be called without the case's lock: the status is built under the
 *    feed's publish lock, so a case's events follow its state changes in
 *    order and its last status event shows its latest state.
 *  - cases/ publishes; http/ reads and waits. The feed knows nothing of HTTP.
 */
#ifndef FDEMD_CASE_FEED_H
#define FDEMD_CASE_FEED_H

#include <stddef.h>
#include <stdint.h>

#include "registry.h"

#define CASE_FEED_KEEP 1000
#define CASE_FEED_STATUS_RATE 4 /* status events a second per running case, at most */

/* Sets the first id from the clock (registry_init calls it). */
void case_feed_init(void);

/* The case's status object as an event, now (a state changed). */
void case_feed_status(server_case *c);
/* The same, unless the case had one less than 1/CASE_FEED_STATUS_RATE s
 * ago (the worker calls it as it publishes its figures). */
void case_feed_progress(server_case *c);
/* Snapshot `index` (0-based, as in result.h5) at simulated `time` is written. */
void case_feed_snapshot(server_case *c, int index, double time);
/* The case and its files are gone. */
void case_feed_deleted(const char *id);

/* The id of the last event (the first id less one before any). */
uint64_t case_feed_last_id(void);
/* Copies, into a malloc'd *text, the blocks of the events after id `after`
 * that concern case `only` (NULL: every case), about `max_bytes` at most
 * but at least one event; *after moves past every event looked at, those
 * of other cases included. When events after `after` are no longer kept
 * (or `after` is no id of this run), the text starts with a comment line
 * saying so and goes on from the oldest kept. Returns the length, 0 (and
 * *text NULL) when there is nothing. */
size_t case_feed_read(uint64_t *after, const char *only, size_t max_bytes, char **text);
/* Whether an event after `after` concerns case `only` (NULL: any). */
int case_feed_has(uint64_t after, const char *only);
/* Waits until an event after `seen` exists, case_feed_wake() is called or
 * `seconds` pass; returns the last id. */
uint64_t case_feed_wait(uint64_t seen, double seconds);
void case_feed_wake(void);

#endif
