/*
 * case_feed.c - the ring of the last CASE_FEED_KEEP case events, each kept
 * as the text/event-stream block GET /stream sends (case_feed.h).
 *
 * Why blocks of text: a stream reader copies what it has not sent yet and
 * nothing more, whoever publishes; a status object is built and encoded
 * once, however many streams are open. Why a ring with ids: a client that
 * lost its connection comes back with the last id it saw (Last-Event-ID)
 * and gets what it missed, as long as it is within the ring.
 *
 * Two locks, both below every lock of the registry and the case: the
 * publish lock orders status events (the status is built under it, so of
 * two state changes in a row the later one's event comes last); the ring
 * lock guards the ring and is a leaf (nothing else is taken under it).
 */
#include "case_feed.h"

#include <inttypes.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "math/clock.h"

typedef struct feed_event {
    uint64_t id;
    char case_id[CASE_ID_LEN + 1];
    char *text;   /* "id: N\nevent: KIND\ndata: JSON\n\n" */
    size_t length;
} feed_event;

static struct {
    pthread_mutex_t publish_lock;
    pthread_mutex_t lock;   /* the ring and the ids */
    pthread_cond_t grew;
    feed_event ring[CASE_FEED_KEEP];
    int first, count;       /* ring[first] is the oldest kept */
    uint64_t first_id;      /* the first id of this run */
    uint64_t last_id;       /* first_id - 1 before any event */
    unsigned wakes;         /* case_feed_wake() calls */
} feed = {.publish_lock = PTHREAD_MUTEX_INITIALIZER, .lock = PTHREAD_MUTEX_INITIALIZER,
          .grew = PTHREAD_COND_INITIALIZER, .first_id = 1};

void case_feed_init(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    pthread_mutex_lock(&feed.lock);
    if (feed.count == 0) {
        feed.first_id = (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
        feed.last_id = feed.first_id - 1;
    }
    pthread_mutex_unlock(&feed.lock);
}

/* ---------------------------------------------------------- publishing */

/* Appends one event whose data is `json` (compact, one line). */
static void feed_append(const char *case_id, const char *kind, const char *json)
{
    size_t size = strlen(json) + strlen(kind) + 64;
    char *text = malloc(size);
    if (!text)
        return; /* the event is lost; a reader sees the next one */
    pthread_mutex_lock(&feed.lock);
    uint64_t id = ++feed.last_id;
    int n = snprintf(text, size, "id: %" PRIu64 "\nevent: %s\ndata: %s\n\n", id, kind, json);
    feed_event *slot;
    if (feed.count == CASE_FEED_KEEP) {
        slot = &feed.ring[feed.first];
        free(slot->text);
        feed.first = (feed.first + 1) % CASE_FEED_KEEP;
    } else {
        slot = &feed.ring[(feed.first + feed.count) % CASE_FEED_KEEP];
        feed.count++;
    }
    slot->id = id;
    snprintf(slot->case_id, sizeof slot->case_id, "%s", case_id);
    slot->text = text;
    slot->length = (size_t)n;
    pthread_cond_broadcast(&feed.grew);
    pthread_mutex_unlock(&feed.lock);
}

/* Appends `o` (consumed) as an event of `kind`. */
static void feed_append_json(const char *case_id, const char *kind, json_t *o)
{
    char *json = o ? json_dumps(o, JSON_COMPACT) : NULL;
    json_decref(o);
    if (json)
        feed_append(case_id, kind, json);
    free(json);
}

/* With the publish lock held. */
static void feed_status_locked(server_case *c, double now)
{
    c->feed_status_at = now;
    feed_append_json(c->id, "status", case_status_json(c));
}

void case_feed_status(server_case *c)
{
    if (atomic_load(&c->deleted))
        return;
    pthread_mutex_lock(&feed.publish_lock);
    feed_status_locked(c, clock_wall_seconds());
    pthread_mutex_unlock(&feed.publish_lock);
}

void case_feed_progress(server_case *c)
{
    double now = clock_wall_seconds();
    pthread_mutex_lock(&feed.publish_lock);
    if (now - c->feed_status_at >= 1.0 / CASE_FEED_STATUS_RATE && !atomic_load(&c->deleted))
        feed_status_locked(c, now);
    pthread_mutex_unlock(&feed.publish_lock);
}

void case_feed_snapshot(server_case *c, int index, double time)
{
    json_t *o = json_pack("{s:s, s:i, s:f}", "id", c->id, "index", index, "time", time);
    pthread_mutex_lock(&feed.publish_lock);
    feed_append_json(c->id, "snapshot", o);
    pthread_mutex_unlock(&feed.publish_lock);
}

void case_feed_deleted(const char *id)
{
    json_t *o = json_pack("{s:s}", "id", id);
    pthread_mutex_lock(&feed.publish_lock);
    feed_append_json(id, "deleted", o);
    pthread_mutex_unlock(&feed.publish_lock);
}

/* ------------------------------------------------------------- reading */

uint64_t case_feed_last_id(void)
{
    pthread_mutex_lock(&feed.lock);
    uint64_t id = feed.last_id;
    pthread_mutex_unlock(&feed.lock);
    return id;
}

/* The oldest id kept (last_id + 1 when none is). With the lock held. */
static uint64_t feed_oldest_locked(void)
{
    return feed.count ? feed.ring[feed.first].id : feed.last_id + 1;
}

static const feed_event *feed_at_locked(int k) /* k-th oldest kept */
{
    return &feed.ring[(feed.first + k) % CASE_FEED_KEEP];
}

static int feed_concerns(const feed_event *e, const char *only)
{
    return !only || strcmp(e->case_id, only) == 0;
}

int case_feed_has(uint64_t after, const char *only)
{
    pthread_mutex_lock(&feed.lock);
    int found = 0;
    for (int k = feed.count - 1; k >= 0 && !found; k--) {
        const feed_event *e = feed_at_locked(k);
        if (e->id <= after)
            break;
        found = feed_concerns(e, only);
    }
    pthread_mutex_unlock(&feed.lock);
    return found;
}

/* The comment line that opens a read from an id whose next events are
 * gone (dropped from the ring, or of an earlier run), or that this daemon
 * never gave; *after is moved to where the read goes on. With the lock
 * held. Returns the note's length (0: none). */
static size_t feed_gap_note_locked(uint64_t *after, char *out, size_t size)
{
    uint64_t oldest = feed_oldest_locked();
    int n = 0;
    if (*after + 1 < oldest) {
        n = snprintf(out, size, ": events after id %" PRIu64 " are no longer kept (the daemon "
                     "keeps its last %d events, and ids start afresh above the last run's at "
                     "each start); going on from id %" PRIu64 "\n\n", *after, CASE_FEED_KEEP,
                     oldest);
        *after = oldest - 1;
    } else if (*after > feed.last_id) {
        n = snprintf(out, size, ": id %" PRIu64 " is no event id of this daemon (its last is "
                     "%" PRIu64 "); going on from there\n\n", *after, feed.last_id);
        *after = feed.last_id;
    }
    return n > 0 ? (size_t)n : 0;
}

size_t case_feed_read(uint64_t *after, const char *only, size_t max_bytes, char **text)
{
    *text = NULL;
    char note[320];
    pthread_mutex_lock(&feed.lock);
    uint64_t from = *after;
    size_t length = feed_gap_note_locked(&from, note, sizeof note), total = length;
    /* ids in the ring follow one another: the k-th oldest is oldest + k */
    int begin = (int)(from + 1 - feed_oldest_locked()), end = begin, taken = 0;
    for (; end < feed.count; end++) {
        const feed_event *e = feed_at_locked(end);
        if (!feed_concerns(e, only))
            continue;
        if (taken && total + e->length > max_bytes)
            break;
        total += e->length;
        taken++;
    }
    char *out = total ? malloc(total + 1) : NULL;
    if (out) {
        memcpy(out, note, length);
        for (int k = begin; k < end; k++) {
            const feed_event *e = feed_at_locked(k);
            if (feed_concerns(e, only)) {
                memcpy(out + length, e->text, e->length);
                length += e->length;
            }
        }
        out[length] = '\0';
    }
    if (out || !total) /* without memory, the same read is tried again */
        *after = end > begin ? feed_at_locked(end - 1)->id : from;
    pthread_mutex_unlock(&feed.lock);
    *text = out;
    return out ? length : 0;
}

uint64_t case_feed_wait(uint64_t seen, double seconds)
{
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    double whole = (double)until.tv_sec + 1e-9 * (double)until.tv_nsec + seconds;
    until.tv_sec = (time_t)whole;
    until.tv_nsec = (long)((whole - (double)until.tv_sec) * 1e9);
    pthread_mutex_lock(&feed.lock);
    unsigned wakes = feed.wakes;
    while (feed.last_id <= seen && feed.wakes == wakes &&
           pthread_cond_timedwait(&feed.grew, &feed.lock, &until) == 0)
        ;
    uint64_t last = feed.last_id;
    pthread_mutex_unlock(&feed.lock);
    return last;
}

void case_feed_wake(void)
{
    pthread_mutex_lock(&feed.lock);
    feed.wakes++;
    pthread_cond_broadcast(&feed.grew);
    pthread_mutex_unlock(&feed.lock);
}
