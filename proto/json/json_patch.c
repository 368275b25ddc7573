/*
 * json_patch.c - JSON Merge Patch (RFC 7396) and the exact-number dump of
 * a rewritten case document (json_patch.h).
 *
 * jansson has neither: it has no merge patch, and json_dumps() writes reals
 * with 17 significant digits, which turns every 0.1 of a user's document
 * into 0.10000000000000001. The dump here writes the shortest form that
 * reads back to the same double, so the stored document still reads as the
 * user wrote it and builds bit-identically the same model.
 */
#include "json_patch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

json_t *json_merge_patch(const json_t *target, const json_t *patch)
{
    if (!json_is_object(patch))
        return json_deep_copy(patch);
    json_t *out = json_is_object(target) ? json_deep_copy(target) : json_object();
    if (!out)
        return NULL;
    const char *name;
    json_t *value;
    json_object_foreach((json_t *)patch, name, value) {
        if (json_is_null(value)) {
            json_object_del(out, name);
            continue;
        }
        json_t *merged = json_merge_patch(json_object_get(out, name), value);
        if (!merged || json_object_set_new(out, name, merged) != 0) {
            json_decref(out);
            return NULL;
        }
    }
    return out;
}

/* ------------------------------------------------------------------ dump */

typedef struct dump_buffer {
    char *text;
    size_t length, capacity;
    int failed;
} dump_buffer;

static void dump_put(dump_buffer *b, const char *s, size_t n)
{
    if (b->failed)
        return;
    if (b->length + n + 1 > b->capacity) {
        size_t cap = b->capacity ? b->capacity : 256;
        while (cap < b->length + n + 1)
            cap *= 2;
        /* jansson's allocator, so that a daemon metering jansson (its
         * memory budget) also meters the text: a rewritten document can be
         * many times its source. The text is still free()d as usual. */
        json_malloc_t jmalloc;
        json_free_t jfree;
        json_get_alloc_funcs(&jmalloc, &jfree);
        char *grown = jmalloc(cap);
        if (!grown) {
            b->failed = 1;
            return;
        }
        if (b->text)
            memcpy(grown, b->text, b->length + 1);
        jfree(b->text);
        b->text = grown;
        b->capacity = cap;
    }
    memcpy(b->text + b->length, s, n);
    b->length += n;
    b->text[b->length] = '\0';
}

static void dump_str(dump_buffer *b, const char *s)
{
    dump_put(b, s, strlen(s));
}

/* A scalar as jansson writes it (strings escaped the same way). */
static void dump_jansson(dump_buffer *b, const json_t *v)
{
    char *s = json_dumps(v, JSON_ENCODE_ANY);
    if (!s) {
        b->failed = 1;
        return;
    }
    dump_str(b, s);
    free(s);
}

void format_shortest_real(char *out, size_t size, double x)
{
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(out, size, "%.*g", digits, x);
        if (strtod(out, NULL) == x)
            break;
    }
}

/* The fewest significant digits that read back to x; ".0" keeps a whole
 * real a real, as jansson does. */
static void dump_real(dump_buffer *b, double x)
{
    char s[40];
    format_shortest_real(s, sizeof s, x);
    if (!strpbrk(s, ".eE"))
        strcat(s, ".0");
    dump_str(b, s);
}

static void dump_indent(dump_buffer *b, int depth)
{
    dump_put(b, "\n", 1);
    for (int i = 0; i < depth; i++)
        dump_put(b, "  ", 2);
}

static void dump_value(dump_buffer *b, const json_t *v, int depth)
{
    if (json_is_object(v)) {
        if (json_object_size(v) == 0) {
            dump_str(b, "{}");
            return;
        }
        dump_str(b, "{");
        const char *name;
        json_t *member;
        int first = 1;
        json_object_foreach((json_t *)v, name, member) {
            dump_str(b, first ? "" : ",");
            first = 0;
            dump_indent(b, depth + 1);
            json_t *key = json_string(name);
            if (!key)
                b->failed = 1;
            else
                dump_jansson(b, key);
            json_decref(key);
            dump_str(b, ": ");
            dump_value(b, member, depth + 1);
        }
        dump_indent(b, depth);
        dump_str(b, "}");
    } else if (json_is_array(v)) {
        if (json_array_size(v) == 0) {
            dump_str(b, "[]");
            return;
        }
        dump_str(b, "[");
        for (size_t i = 0; i < json_array_size(v); i++) {
            dump_str(b, i ? ", " : "");
            dump_value(b, json_array_get(v, i), depth + 1);
        }
        dump_str(b, "]");
    } else if (json_is_real(v) && isfinite(json_real_value(v))) {
        dump_real(b, json_real_value(v));
    } else {
        dump_jansson(b, v);
    }
}

char *json_dump_document(const json_t *doc, size_t *length)
{
    dump_buffer b = {0};
    dump_value(&b, doc, 0);
    dump_put(&b, "\n", 1);
    if (b.failed) {
        free(b.text);
        return NULL;
    }
    if (length)
        *length = b.length;
    return b.text;
}
