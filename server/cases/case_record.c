/*
 * case_record.c - one case's record (registry.h: server_case): its
 * lifetime and reference count, the names of its states, its id's form and
 * the timestamps it carries. It calls nothing else of the case lifecycle,
 * so every file of cases/ may lean on it without a circle through it (the
 * registry table and state machine: registry.c).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "registry.h"
#include "registry_internal.h"

static const char *const state_names[] = {
    "created", "queued", "running", "paused", "finished", "stopped", "failed",
};

const char *case_state_name(case_state s)
{
    return (unsigned)s < sizeof state_names / sizeof *state_names ? state_names[s] : "failed";
}

int case_state_parse(const char *name, case_state *out)
{
    for (unsigned i = 0; i < sizeof state_names / sizeof *state_names; i++)
        if (name && strcmp(name, state_names[i]) == 0) {
            *out = (case_state)i;
            return 0;
        }
    return -1;
}

int case_state_is_terminal(case_state s)
{
    return s == CASE_FINISHED || s == CASE_STOPPED || s == CASE_FAILED;
}

int id_is_valid(const char *s)
{
    if (!s)
        return 0;
    for (int i = 0; i < CASE_ID_LEN; i++)
        if (!((s[i] >= '0' && s[i] <= '9') || (s[i] >= 'a' && s[i] <= 'f')))
            return 0;
    return s[CASE_ID_LEN] == '\0';
}

/* ------------------------------------------------------------ lifetime */

server_case *case_new(void)
{
    server_case *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    atomic_init(&c->refs, 1);
    atomic_init(&c->command, WORKER_GO);
    atomic_init(&c->state_waiters, 0);
    atomic_init(&c->deleted, 0);
    pthread_mutex_init(&c->lock, NULL);
    pthread_cond_init(&c->cv, NULL);
    pthread_mutex_init(&c->ctl_lock, NULL);
    pthread_mutex_init(&c->model_lock, NULL);
    pthread_mutex_init(&c->yield_lock, NULL);
    pthread_cond_init(&c->yield_cv, NULL);
    pthread_mutex_init(&c->persist_lock, NULL);
    c->last_snapshot_step = -1;
    c->last_checkpoint_step = -1;
    c->resume_rows_until = -1;
    c->fig.stage = -1; /* no stages until a model or status.json says */
    c->fig.eta = NAN;
    c->fig.cpu_share = NAN;
    c->estimated_seconds = NAN;
    return c;
}

static void case_free(server_case *c)
{
    if (c->model)
        fdem_model_destroy(c->model);
    membudget_release(&c->reserve);
    json_decref(c->warnings);
    pthread_mutex_destroy(&c->lock);
    pthread_cond_destroy(&c->cv);
    pthread_mutex_destroy(&c->ctl_lock);
    pthread_mutex_destroy(&c->model_lock);
    pthread_mutex_destroy(&c->yield_lock);
    pthread_cond_destroy(&c->yield_cv);
    pthread_mutex_destroy(&c->persist_lock);
    free(c);
}

void case_retain(server_case *c)
{
    atomic_fetch_add(&c->refs, 1);
}

void case_release(server_case *c)
{
    if (c && atomic_fetch_sub(&c->refs, 1) == 1)
        case_free(c);
}
