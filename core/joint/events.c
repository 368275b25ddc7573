/*
 * events.c - fracture events (contract 5.4): every joint that breaks is one
 * record of when, where, how and at what energy cost, kept until the
 * caller drains it (fdem_drain_events), so the daemon can stream the crack
 * history to result.h5 as it grows.
 *
 * Determinism. The joint loop may run its blocks on several threads; each
 * joint only marks itself (joint_broke[j] = its mode) and books its own
 * fracture energy (joint_fracture[j]). This file, serially after the loop,
 * turns the marks into events in joint order, so the events come out in
 * (step, joint) order on one thread or eight. Only steps in which a joint
 * broke pay for that pass; it skips the unmarked joints with memchr.
 *
 * The record: time is the end of the step the joint broke in (the time of
 * the first snapshot that shows it broken), position the mean of its 2 dim
 * nodes at the start of that step (the state that broke it), energy all its
 * damage growth dissipated from the first damage to the break, so the
 * events' energies add up to the fracture account of the broken joints.
 *
 * A checkpoint carries the events not drained yet and every joint's
 * fracture account, so a restored model reports a joint that was damaged
 * before the checkpoint and breaks after it with its whole energy.
 */
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "joint.h"

static int events_reserve(fdem_model *m, int more)
{
    if (m->event_count + more <= m->event_capacity) return 0;
    int capacity = m->event_capacity ? m->event_capacity : 64;
    while (capacity < m->event_count + more) capacity *= 2;
    fdem_event *grown = realloc(m->events, sizeof *grown * (size_t)capacity);
    if (!grown) return -1;
    m->events = grown;
    m->event_capacity = capacity;
    return 0;
}

static void event_of_joint(const fdem_model *m, int j, double time, fdem_event *ev)
{
    int D = m->dim, K = 2 * D;
    const int32_t *n = m->joint_node + (size_t)K * (size_t)j;
    memset(ev, 0, sizeof *ev);
    ev->time = time;
    ev->joint = j;
    ev->mode = (int8_t)m->joint_broke[j];
    ev->energy = m->joint_fracture[j];
    for (int i = 0; i < K; i++)
        for (int d = 0; d < D; d++) ev->position[d] += m->pos[(size_t)D * (size_t)n[i] + d];
    for (int d = 0; d < D; d++) ev->position[d] /= K;
}

/* The first marked joint at or after j, or count: eight marks per test
 * over the long unmarked runs. */
static int next_mark(const uint8_t *mark, int j, int count)
{
    while (j < count && (j & 7)) {
        if (mark[j]) return j;
        j++;
    }
    for (; j + 8 <= count; j += 8) {
        uint64_t word;
        memcpy(&word, mark + j, sizeof word);
        if (word) break;
    }
    while (j < count && !mark[j]) j++;
    return j;
}

int events_collect(fdem_model *m, int broke)
{
    if (events_reserve(m, broke)) return -1;
    /* the end of this step, as fdem_step forms it */
    double carry, time = model_time_after(m, m->dt, &carry);
    int found = 0;
    for (int j = next_mark(m->joint_broke, 0, m->joint_count); j < m->joint_count && found < broke;
         j = next_mark(m->joint_broke, j + 1, m->joint_count)) {
        event_of_joint(m, j, time, &m->events[m->event_count++]);
        m->joint_broke[j] = 0;
        found++;
    }
    return 0;
}

int fdem_event_count(const fdem_model *m) { return m->event_count; }

int fdem_drain_events(fdem_model *m, fdem_event *out, int max)
{
    int n = max < m->event_count ? max : m->event_count;
    if (n <= 0) return 0;
    memcpy(out, m->events, sizeof *out * (size_t)n);
    memmove(m->events, m->events + n, sizeof *out * (size_t)(m->event_count - n));
    m->event_count -= n;
    return n;
}

const double *fdem_joint_fracture_energy(const fdem_model *m)
{
    return m->joint_count ? m->joint_fracture : NULL;
}

/* ---------------------------------------------------------- checkpoints */

/* Every joint's fracture account, then the events not drained. */
size_t events_checkpoint_size(const fdem_model *m)
{
    return sizeof(double) * (size_t)m->joint_count + sizeof(fdem_event) * (size_t)m->event_count;
}

void events_checkpoint_write(const fdem_model *m, unsigned char *p)
{
    size_t jb = sizeof(double) * (size_t)m->joint_count;
    if (jb) memcpy(p, m->joint_fracture, jb);
    if (m->event_count) memcpy(p + jb, m->events, sizeof(fdem_event) * (size_t)m->event_count);
}

/* count events follow the accounts; -1 without memory for them. */
int events_checkpoint_read(fdem_model *m, const unsigned char *p, int64_t count)
{
    size_t jb = sizeof(double) * (size_t)m->joint_count;
    if (jb) memcpy(m->joint_fracture, p, jb);
    m->event_count = 0;
    if (count > 0 && events_reserve(m, (int)count)) return -1;
    if (count > 0) memcpy(m->events, p + jb, sizeof(fdem_event) * (size_t)count);
    m->event_count = (int)count;
    return 0;
}
