/*
 * memory_budget.h - the daemon's --max-memory account (contract 5.5).
 *
 * Contract:
 *  - Whatever large the daemon holds for a case (a model, a request body and
 *    the JSON tree parsed from it) is reserved here before it is allocated.
 *    A reservation that would take the total past the limit is refused; the
 *    caller then answers 503 with Retry-After: MEMBUDGET_RETRY_AFTER and
 *    changes nothing.
 *  - A lease is one holder's share of the total (an upload, a running case,
 *    a temporary rebuild). One owner at a time; the total is thread-safe.
 *  - While a meter is on (membudget_meter_begin), jansson allocations made
 *    by this thread are charged to the meter's lease, which grows as needed;
 *    when the budget refuses, the allocation fails (so the parse fails) and
 *    membudget_meter_refused() says so.
 *  - Releasing a large share hands freed heap pages back to the OS, so the
 *    daemon's RSS follows what it holds.
 */
#ifndef FDEMD_MEMORY_BUDGET_H
#define FDEMD_MEMORY_BUDGET_H

#include <stddef.h>

#define MEMBUDGET_RETRY_AFTER 5 /* seconds, for the Retry-After header */

typedef struct membudget_lease {
    size_t bytes;
} membudget_lease;

/* Half the physical memory (the default --max-memory). */
size_t membudget_default_limit(void);
/* Sets the limit and routes jansson's allocations through the meter. */
void membudget_init(size_t limit);
size_t membudget_limit(void);
size_t membudget_used(void);

/* 0 when `bytes` more fit (the lease grows), -1 when they do not. */
int membudget_grow(membudget_lease *lease, size_t bytes);
/* Gives back part (shrink) or all (release) of a lease. */
void membudget_shrink(membudget_lease *lease, size_t bytes);
void membudget_release(membudget_lease *lease);
/* Hands the heap's free pages back to the OS (malloc_trim), e.g. after a
 * parse tree was freed. */
void membudget_give_back(void);
/* Moves up to `bytes` from one lease to another (the total is unchanged). */
void membudget_move(membudget_lease *from, membudget_lease *to, size_t bytes);

/* What an upload of `body_bytes` is admitted at: the body, the meshes read
 * from it and a typical JSON tree (a larger tree grows it through the meter). */
size_t membudget_upload_cost(size_t body_bytes);

/* "12 KiB", "25.6 MiB", "1.5 GiB" into buf; returns buf. */
const char *membudget_describe(size_t bytes, char *buf, size_t size);

/* `allowance`: bytes of the lease already meant for the tree. */
void membudget_meter_begin(membudget_lease *lease, size_t allowance);
void membudget_meter_end(void);
int membudget_meter_refused(void);

/* The lease of the request this thread is serving (NULL if none), so that
 * code deep in a route charges the upload's admission instead of a second
 * reservation. */
void membudget_request_enter(membudget_lease *lease);
void membudget_request_leave(void);
membudget_lease *membudget_request_lease(void);

#endif
