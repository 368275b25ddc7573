/*
 * case_doc.h - building case documents in unit tests: JSON written with
 * single quotes (readable in C), edited at a JSON Pointer, built with
 * case_build(), and the problems it reports searched by pointer and text.
 * Shared by the 2D and 3D case tests so both check problems the same way.
 */
#ifndef FDEM_CASE_DOC_H
#define FDEM_CASE_DOC_H

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case/case.h"
#include "check.h"
#include "read_file.h"

#define GiB ((size_t)1 << 30)

static inline char *quotes(const char *text)
{
    char *s = strdup(text);
    for (char *c = s; *c; c++)
        if (*c == '\'') *c = '"';
    return s;
}

static inline json_t *load(const char *single_quoted)
{
    char *text = quotes(single_quoted);
    json_error_t error;
    json_t *v = json_loads(text, JSON_DECODE_ANY, &error);
    if (!v) fprintf(stderr, "test document does not parse: %s\n", error.text);
    free(text);
    return v;
}

/* Walks a pointer of object keys and array indices (no escapes needed in
 * these tests) and replaces the target with `value` (NULL removes it). */
static inline void edit(json_t *root, const char *pointer, json_t *value)
{
    char path[256];
    snprintf(path, sizeof path, "%s", pointer);
    json_t *parent = root;
    char *token = path + 1, *slash;
    while ((slash = strchr(token, '/'))) {
        *slash = '\0';
        parent = json_is_array(parent) ? json_array_get(parent, (size_t)atoi(token))
                                       : json_object_get(parent, token);
        token = slash + 1;
    }
    if (json_is_array(parent)) {
        size_t index = (size_t)atoi(token);
        if (value && index == json_array_size(parent)) json_array_append_new(parent, value);
        else if (value) json_array_set_new(parent, index, value);
        else json_array_remove(parent, (size_t)atoi(token));
    } else {
        if (value) json_object_set_new(parent, token, value);
        else json_object_del(parent, token);
    }
}

static inline fdem_model *build_json(const json_t *doc, size_t limit, case_info *info, problems *p)
{
    char *text = json_dumps(doc, JSON_COMPACT);
    problems_init(p);
    fdem_model *m = case_build(text, strlen(text), limit, info, p);
    free(text);
    return m;
}

static inline int has_problem(const problems *p, const char *pointer, const char *needle)
{
    for (int i = 0; i < p->count; i++)
        if (strcmp(p->items[i].pointer, pointer) == 0 && strstr(p->items[i].message, needle))
            return 1;
    return 0;
}

static inline void dump_problems(const problems *p)
{
    for (int i = 0; i < p->count; i++)
        fprintf(stderr, "    problem %s: %s\n", p->items[i].pointer, p->items[i].message);
}

/* The outcome of a refused build: no model, `status`, and a problem at
 * `pointer` whose message contains `needle`. Frees the model and problems. */
static inline void expect_refused(fdem_model *m, problems *p, int status, const char *pointer,
                                  const char *needle)
{
    CHECK(m == NULL, "a model was built; expected a problem at %s", pointer);
    CHECK(p->status == status, "status %d, want %d", p->status, status);
    int found = has_problem(p, pointer, needle);
    CHECK(found, "no problem at \"%s\" containing \"%s\"", pointer, needle);
    if (!found) dump_problems(p);
    if (m) fdem_model_destroy(m);
    problems_free(p);
}

/* Builds `doc` (and frees it), expecting it refused as expect_refused says. */
static inline void expect_doc(json_t *doc, size_t limit, int status, const char *pointer,
                              const char *needle)
{
    problems p;
    case_info info;
    fdem_model *m = build_json(doc, limit, &info, &p);
    json_decref(doc);
    expect_refused(m, &p, status, pointer, needle);
}

/* Builds `doc` (and frees it), expecting no model: its problems in *p,
 * for checks at several pointers (free them after). */
static inline void build_refused(json_t *doc, size_t limit, problems *p)
{
    case_info info;
    fdem_model *m = build_json(doc, limit, &info, p);
    json_decref(doc);
    CHECK(m == NULL, "a model was built");
    if (m) fdem_model_destroy(m);
}

/* Builds `doc` (and frees it), expecting a model: NULL after reporting
 * the problems. `info` may be NULL. */
static inline fdem_model *expect_built(json_t *doc, case_info *info)
{
    problems p;
    case_info own;
    fdem_model *m = build_json(doc, GiB, info ? info : &own, &p);
    json_decref(doc);
    CHECK(m != NULL, "refused with %d problems", p.count);
    if (!m) dump_problems(&p);
    problems_free(&p);
    return m;
}

/* `base` (single-quoted JSON) with `value` (single-quoted, or NULL to
 * delete) at `at`, expected to fail with a 422 at `pointer` mentioning
 * `needle`. */
static inline void expect_variant_of(const char *base, const char *at, const char *value,
                              const char *pointer, const char *needle)
{
    json_t *doc = load(base);
    edit(doc, at, value ? load(value) : NULL);
    expect_doc(doc, GiB, 422, pointer, needle);
}

/* Bisects the smallest memory limit at which `doc` builds. */
static inline size_t smallest_accepted_limit(const json_t *doc)
{
    size_t lo = 0, hi = GiB; /* refused at lo, accepted at hi */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        problems p;
        case_info info;
        fdem_model *m = build_json(doc, mid, &info, &p);
        if (m) hi = mid; else lo = mid;
        if (m) fdem_model_destroy(m);
        problems_free(&p);
    }
    return hi;
}

#endif
