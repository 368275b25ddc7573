/*
 * problems.c - the list of {JSON Pointer, message} problems a request
 * collects before the server answers with RFC 9457 problem details.
 *
 * Validation reports every problem at once, so a user fixes a case in one
 * round trip. The list is capped (PROBLEMS_MAX) because a hostile or broken
 * document (a million bad triangles) must not turn into a response, or an
 * allocation, many times larger than the upload; the overflow is counted in
 * `dropped` so the server can still say how many there were.
 */
#include "problems.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void problems_init(problems *p)
{
    memset(p, 0, sizeof *p);
}

void problems_free(problems *p)
{
    free(p->items);
    memset(p, 0, sizeof *p);
}

static const char *problems_default_title(int status)
{
    switch (status) {
    case 400: return "Bad request";
    case 422: return "Invalid case";
    default: return "Problem";
    }
}

/* Makes room for one more item; 0 when it cannot (cap or out of memory). */
static int problems_reserve(problems *p)
{
    if (p->count < p->capacity) return 1;
    if (p->count >= PROBLEMS_MAX) return 0;
    int capacity = p->capacity ? 2 * p->capacity : 8;
    if (capacity > PROBLEMS_MAX) capacity = PROBLEMS_MAX;
    problem *items = realloc(p->items, (size_t)capacity * sizeof *items);
    if (!items) return 0;
    p->items = items;
    p->capacity = capacity;
    return 1;
}

void problems_add(problems *p, int status, const char *pointer, const char *fmt, ...)
{
    if (!p->status) p->status = status;
    if (!p->title[0])
        snprintf(p->title, sizeof p->title, "%s", problems_default_title(p->status));
    if (!problems_reserve(p)) {
        p->dropped++;
        return;
    }
    problem *item = &p->items[p->count++];
    snprintf(item->pointer, sizeof item->pointer, "%s", pointer ? pointer : "");
    va_list args;
    va_start(args, fmt);
    vsnprintf(item->message, sizeof item->message, fmt, args);
    va_end(args);
}

/* RFC 6901: '~' is written "~0" and '/' is written "~1". A pointer that does
 * not fit is cut at a whole character, never in the middle of an escape. */
void pointer_join(char *out, size_t size, const char *base, const char *token)
{
    if (size == 0) return;
    size_t n = 0;
    if (out != base) {
        while (base[n] && n + 1 < size) {
            out[n] = base[n];
            n++;
        }
    } else {
        n = strlen(out);
    }
    if (n + 1 < size) out[n++] = '/';
    for (const char *c = token; *c; c++) {
        const char *piece = *c == '~' ? "~0" : *c == '/' ? "~1" : NULL;
        size_t len = piece ? 2 : 1;
        if (n + len >= size) break;
        if (piece) {
            out[n++] = piece[0];
            out[n++] = piece[1];
        } else {
            out[n++] = *c;
        }
    }
    out[n] = '\0';
}

void pointer_join_index(char *out, size_t size, const char *base, long index)
{
    char token[32];
    snprintf(token, sizeof token, "%ld", index);
    pointer_join(out, size, base, token);
}
