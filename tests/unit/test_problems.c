/*
 * test_problems.c - problem lists and RFC 6901 pointers: status and title
 * are set by the first problem, the list is capped with an honest count of
 * what was dropped, and pointer tokens are escaped and never overflow.
 */
#include <string.h>

#include "check.h"
#include "json/problems.h"

static void first_problem_sets_status_and_title(void)
{
    problems p;
    problems_init(&p);
    CHECK(p.status == 0 && p.count == 0, "fresh list status %d count %d", p.status, p.count);
    problems_add(&p, 422, "/time/end", "end must be > 0, got %g", -1.0);
    problems_add(&p, 400, "", "later status does not override");
    CHECK(p.status == 422, "status %d", p.status);
    CHECK(strcmp(p.title, "Invalid case") == 0, "title \"%s\"", p.title);
    CHECK(p.count == 2, "count %d", p.count);
    CHECK(strcmp(p.items[0].pointer, "/time/end") == 0, "pointer %s", p.items[0].pointer);
    CHECK(strcmp(p.items[0].message, "end must be > 0, got -1") == 0, "message %s",
          p.items[0].message);
    problems_free(&p);
    CHECK(p.items == NULL && p.count == 0, "free resets the list");
}

static void preset_title_is_kept(void)
{
    problems p;
    problems_init(&p);
    strcpy(p.title, "Malformed JSON");
    problems_add(&p, 400, "", "line 1, column 2: oops");
    CHECK(p.status == 400 && strcmp(p.title, "Malformed JSON") == 0, "status %d title %s",
          p.status, p.title);
    problems_free(&p);
}

static void list_is_capped(void)
{
    problems p;
    problems_init(&p);
    for (int i = 0; i < PROBLEMS_MAX + 37; i++) problems_add(&p, 422, "/parts", "problem %d", i);
    CHECK(p.count == PROBLEMS_MAX && p.dropped == 37, "count %d dropped %d", p.count, p.dropped);
    char want[32];
    snprintf(want, sizeof want, "problem %d", PROBLEMS_MAX - 1);
    CHECK(strcmp(p.items[PROBLEMS_MAX - 1].message, want) == 0, "last kept: %s",
          p.items[PROBLEMS_MAX - 1].message);
    problems_free(&p);
}

static void long_messages_are_truncated(void)
{
    problems p;
    problems_init(&p);
    char long_text[2000];
    memset(long_text, 'a', sizeof long_text - 1);
    long_text[sizeof long_text - 1] = '\0';
    problems_add(&p, 422, long_text, "%s", long_text);
    CHECK(strlen(p.items[0].message) == sizeof p.items[0].message - 1, "message length %zu",
          strlen(p.items[0].message));
    CHECK(strlen(p.items[0].pointer) == sizeof p.items[0].pointer - 1, "pointer length %zu",
          strlen(p.items[0].pointer));
    problems_free(&p);
}

static void pointers_escape_tokens(void)
{
    char out[64];
    pointer_join(out, sizeof out, "/materials", "a/b~c");
    CHECK(strcmp(out, "/materials/a~1b~0c") == 0, "got %s", out);
    pointer_join(out, sizeof out, "", "");
    CHECK(strcmp(out, "/") == 0, "empty token: got %s", out);
    pointer_join_index(out, sizeof out, "/parts", 12);
    CHECK(strcmp(out, "/parts/12") == 0, "got %s", out);
    /* joining in place */
    pointer_join(out, sizeof out, out, "mesh");
    CHECK(strcmp(out, "/parts/12/mesh") == 0, "in place: got %s", out);
}

static void pointers_never_overflow(void)
{
    char out[8];
    pointer_join(out, sizeof out, "/abc", "~~~~");
    /* "/abc/~0" fits (7 chars); the next escape would not and is not cut */
    CHECK(strcmp(out, "/abc/~0") == 0, "got %s", out);
    char tiny[1];
    pointer_join(tiny, sizeof tiny, "/abc", "x");
    CHECK(tiny[0] == '\0', "size 1 gives the empty string");
}

CHECK_MAIN(T(first_problem_sets_status_and_title), T(preset_title_is_kept), T(list_is_capped),
           T(long_messages_are_truncated), T(pointers_escape_tokens), T(pointers_never_overflow))
