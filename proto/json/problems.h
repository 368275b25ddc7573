/*
 * problems.h - a list of {JSON Pointer, message} problems found in a request,
 * reported all at once as RFC 9457 problem details by the server.
 *
 * Contract: problems_add() never fails visibly (on allocation failure the
 * problem is dropped and `dropped` counts it); pointers are RFC 6901 strings
 * ("" is the whole document); `status` is 400 for malformed JSON and 422 for
 * a well-formed but invalid case. At most PROBLEMS_MAX problems are kept;
 * later ones only increase `dropped` (a broken document must not produce a
 * response larger than itself).
 *
 * Folder proto/json/, plain JSON and problem reporting, which know nothing
 * of cases or the engine: owns this header (problem lists with JSON
 * Pointers, problems.c), the nesting check of a JSON text before it is
 * parsed (json_depth.h) and merge patch, JSON Patch and the exact-number dump
 * (json_patch.h). May call jansson and the C library only. Called by
 * proto/case/, server/ and the unit tests.
 */
#ifndef FDEM_PROBLEMS_H
#define FDEM_PROBLEMS_H

#include <stddef.h>

#define PROBLEMS_MAX 100

typedef struct problem {
    char pointer[256];
    char message[512];
} problem;

typedef struct problems {
    int status;        /* 400 or 422 once a problem is added; 0 when none */
    char title[64];    /* "Malformed JSON", "Invalid case", ... */
    problem *items;
    int count, capacity, dropped;
} problems;

void problems_init(problems *p);
void problems_free(problems *p);
/* Adds one problem; the first call also sets status and title when unset. */
void problems_add(problems *p, int status, const char *pointer, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Appends "/token" to a JSON Pointer with RFC 6901 escaping (~0, ~1). */
void pointer_join(char *out, size_t size, const char *base, const char *token);
void pointer_join_index(char *out, size_t size, const char *base, long index);

#endif
