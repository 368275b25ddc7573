/*
 * json_patch_ops.c - JSON Patch (RFC 6902) and the JSON Pointers (RFC 6901)
 * its operations address values with (json_patch.h).
 *
 * Why: a parametric study changes one element of `parts` or `constraints`
 * of a stored case, and those arrays may embed whole meshes; a merge patch
 * (RFC 7396, json_patch.c) can only replace an array whole, so every clone
 * resent the mesh. jansson has no JSON Patch.
 *
 * Two passes. First every operation is checked for its shape (an object
 * with a known "op", a "path" and, as the op needs, "from" or "value", the
 * pointers well formed), so a patch with several malformed operations is
 * reported whole, each at its pointer into the patch. Then the operations
 * run in order on a deep copy of the target, and the first that fails (a
 * `test` that does not hold included) ends the patch: the copy is dropped,
 * so a failing patch changes nothing (RFC 6902 section 5), and the problem
 * names that operation ("/3") and why.
 */
#include "json_patch.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------- pointers */

/* A pointer split into its decoded reference tokens ("~1" is "/", "~0" is
 * "~"), each NUL-terminated in `text`. */
typedef struct json_pointer {
    char *text;
    const char **token;
    size_t count;
} json_pointer;

static void pointer_free(json_pointer *p)
{
    free(p->text);
    free(p->token);
    memset(p, 0, sizeof *p);
}

/* 0, -1 with a sentence in why (not RFC 6901), or -2 out of memory. */
static int pointer_parse(const json_t *string, json_pointer *out, char *why, size_t whylen)
{
    memset(out, 0, sizeof *out);
    const char *s = json_string_value(string);
    size_t length = json_string_length(string);
    if (strlen(s) != length) {
        snprintf(why, whylen, "a pointer cannot hold the character U+0000");
        return -1;
    }
    if (length > 0 && s[0] != '/') {
        snprintf(why, whylen, "\"%.80s\" is not a JSON Pointer: it must be \"\" (the whole "
                 "document) or start with \"/\"", s);
        return -1;
    }
    size_t slashes = 0;
    for (size_t i = 0; i < length; i++) {
        slashes += s[i] == '/';
        if (s[i] == '~' && s[i + 1] != '0' && s[i + 1] != '1') {
            snprintf(why, whylen, "\"%.80s\" is not a JSON Pointer: \"~\" must be followed by "
                     "0 or 1 (\"~0\" is \"~\", \"~1\" is \"/\")", s);
            return -1;
        }
    }
    out->text = malloc(length + 1);
    out->token = malloc(sizeof *out->token * (slashes ? slashes : 1));
    if (!out->text || !out->token) {
        pointer_free(out);
        return -2;
    }
    char *w = out->text;
    for (size_t i = 0; i < length; i++) {
        if (s[i] == '/') {
            if (out->count)
                *w++ = '\0';
            out->token[out->count++] = w;
        } else if (s[i] == '~') {
            *w++ = s[++i] == '1' ? '/' : '~';
        } else {
            *w++ = s[i];
        }
    }
    *w = '\0';
    return 0;
}

/* The first `depth` tokens of p as pointer text, for messages. */
static void pointer_prefix(const json_pointer *p, size_t depth, char *out, size_t size)
{
    out[0] = '\0';
    for (size_t i = 0; i < depth && i < p->count; i++)
        pointer_join(out, size, out, p->token[i]);
}

/* An array index token: "0" or digits without a leading zero (RFC 6901
 * section 4); 1 with *index, else 0 ("-", "01", "x", absurdly long). */
static int pointer_index(const char *token, size_t *index)
{
    size_t n = strlen(token);
    if (n == 0 || n > 15 || strspn(token, "0123456789") != n || (n > 1 && token[0] == '0'))
        return 0;
    *index = (size_t)strtoull(token, NULL, 10);
    return 1;
}

/* A short text of a JSON value for a message ("granite", 3, {...}). */
static void value_text(const json_t *v, char *out, size_t size)
{
    char *s = v ? json_dumps(v, JSON_ENCODE_ANY | JSON_COMPACT) : NULL;
    if (!s)
        snprintf(out, size, "(a value)");
    else if (strlen(s) > 60)
        snprintf(out, size, "%.56s...", s);
    else
        snprintf(out, size, "%s", s);
    free(s);
}

static const char *kind_name(const json_t *v)
{
    return json_is_object(v) ? "an object" : json_is_array(v) ? "an array"
         : json_is_string(v) ? "a string" : json_is_number(v) ? "a number"
         : json_is_boolean(v) ? "a boolean" : "null";
}

/* The child of `container` at `token`, or NULL. */
static json_t *pointer_child(json_t *container, const char *token)
{
    size_t index;
    if (json_is_object(container))
        return json_object_get(container, token);
    if (json_is_array(container) && pointer_index(token, &index))
        return json_array_get(container, index);
    return NULL;
}

/* Why the child at depth `depth` of p (its container `container`) does
 * not exist, as "path /parts/7 does not exist (/parts has 3 elements)". */
static void pointer_missing(const json_pointer *p, size_t depth, const json_t *container,
                            const char *member, char *why, size_t whylen)
{
    char at[256], parent[256];
    pointer_prefix(p, depth + 1, at, sizeof at);
    pointer_prefix(p, depth, parent, sizeof parent);
    const char *token = p->token[depth];
    size_t index;
    if (json_is_array(container) && !pointer_index(token, &index))
        snprintf(why, whylen, "%s %s does not exist: \"%.40s\" is not an index of the array "
                 "%s", member, at, token, parent[0] ? parent : "(the document)");
    else if (json_is_array(container))
        snprintf(why, whylen, "%s %s does not exist (%s has %zu element%s)", member, at,
                 parent[0] ? parent : "the document", json_array_size(container),
                 json_array_size(container) == 1 ? "" : "s");
    else if (json_is_object(container))
        snprintf(why, whylen, "%s %s does not exist (%s has no member \"%.60s\")", member, at,
                 parent[0] ? parent : "the document", token);
    else
        snprintf(why, whylen, "%s %s does not exist: %s is %s, not an object or array", member,
                 at, parent[0] ? parent : "the document", kind_name(container));
}

/* The value at the first `depth` tokens of p, or NULL with why. */
static json_t *pointer_resolve(json_t *doc, const json_pointer *p, size_t depth,
                               const char *member, char *why, size_t whylen)
{
    json_t *v = doc;
    for (size_t i = 0; i < depth; i++) {
        json_t *child = pointer_child(v, p->token[i]);
        if (!child) {
            pointer_missing(p, i, v, member, why, whylen);
            return NULL;
        }
        v = child;
    }
    return v;
}

/* ------------------------------------------------------------ equality */

/* RFC 6902 4.6: numbers are equal when their values are (1 and 1.0 are,
 * which json_equal denies); objects whatever their member order. */
static int json_same(const json_t *a, const json_t *b)
{
    if (json_is_number(a) && json_is_number(b)) {
        if (json_is_integer(a) && json_is_integer(b))
            return json_integer_value(a) == json_integer_value(b);
        return json_number_value(a) == json_number_value(b);
    }
    if (json_is_array(a) && json_is_array(b)) {
        if (json_array_size(a) != json_array_size(b))
            return 0;
        for (size_t i = 0; i < json_array_size(a); i++)
            if (!json_same(json_array_get(a, i), json_array_get(b, i)))
                return 0;
        return 1;
    }
    if (json_is_object(a) && json_is_object(b)) {
        if (json_object_size(a) != json_object_size(b))
            return 0;
        const char *key;
        json_t *value;
        json_object_foreach((json_t *)a, key, value) {
            if (!json_same(value, json_object_get(b, key)))
                return 0;
        }
        return 1;
    }
    return json_equal((json_t *)a, (json_t *)b);
}

/* ----------------------------------------------------------- operations */

typedef enum patch_op { OP_ADD, OP_REMOVE, OP_REPLACE, OP_MOVE, OP_COPY, OP_TEST, OP_UNKNOWN } patch_op;

static const char *const op_names[] = {"add", "remove", "replace", "move", "copy", "test"};

static patch_op op_parse(const json_t *op)
{
    for (int k = 0; k < OP_UNKNOWN; k++)
        if (json_is_string(op) && strcmp(json_string_value(op), op_names[k]) == 0)
            return (patch_op)k;
    return OP_UNKNOWN;
}

static int op_takes_from(patch_op op) { return op == OP_MOVE || op == OP_COPY; }
static int op_takes_value(patch_op op) { return op == OP_ADD || op == OP_REPLACE || op == OP_TEST; }

/* Result codes of one operation on the document. */
enum { OP_DONE = 0, OP_FAILED = -1, OP_NO_MEMORY = -2 };

/* Puts `value` (a reference the call takes) at p: RFC 6902 4.1 "add". */
static int doc_add(json_t **doc, const json_pointer *p, json_t *value, char *why, size_t whylen)
{
    if (!value)
        return OP_NO_MEMORY;
    if (p->count == 0) {
        json_decref(*doc);
        *doc = value;
        return OP_DONE;
    }
    json_t *parent = pointer_resolve(*doc, p, p->count - 1, "the parent of path", why, whylen);
    const char *token = p->token[p->count - 1];
    char at[256];
    pointer_prefix(p, p->count - 1, at, sizeof at);
    size_t index, size = json_array_size(parent);
    int rc = OP_FAILED;
    if (json_is_object(parent))
        rc = json_object_set_new(parent, token, value) == 0 ? OP_DONE : OP_NO_MEMORY;
    else if (json_is_array(parent) && strcmp(token, "-") == 0)
        rc = json_array_append_new(parent, value) == 0 ? OP_DONE : OP_NO_MEMORY;
    else if (json_is_array(parent) && pointer_index(token, &index) && index <= size)
        rc = json_array_insert_new(parent, index, value) == 0 ? OP_DONE : OP_NO_MEMORY;
    else if (json_is_array(parent))
        snprintf(why, whylen, "\"%.40s\" is not a place in the array %s: it has %zu element%s, "
                 "so an index 0 ... %zu, or \"-\" for its end", token, at[0] ? at : "(the "
                 "document)", size, size == 1 ? "" : "s", size);
    else if (parent)
        snprintf(why, whylen, "the parent %s is %s, not an object or array", at[0] ? at :
                 "(the document)", kind_name(parent));
    if (rc == OP_FAILED)
        json_decref(value); /* set_new and insert_new take it even when they fail */
    return rc;
}

/* Takes the value at p out of the document: RFC 6902 4.2 "remove". With
 * `taken`, the removed value is handed to the caller (a reference). */
static int doc_remove(json_t *doc, const json_pointer *p, json_t **taken, char *why, size_t whylen)
{
    if (p->count == 0) {
        snprintf(why, whylen, "the whole document (path \"\") cannot be removed");
        return OP_FAILED;
    }
    json_t *value = pointer_resolve(doc, p, p->count, "path", why, whylen);
    if (!value)
        return OP_FAILED;
    json_t *parent = pointer_resolve(doc, p, p->count - 1, "path", why, whylen);
    if (taken)
        *taken = json_incref(value);
    size_t index;
    if (json_is_object(parent))
        json_object_del(parent, p->token[p->count - 1]);
    else if (pointer_index(p->token[p->count - 1], &index))
        json_array_remove(parent, index);
    return OP_DONE;
}

/* RFC 6902 4.3 "replace": the value at p, which must exist, becomes `value`. */
static int doc_replace(json_t **doc, const json_pointer *p, json_t *value, char *why,
                       size_t whylen)
{
    if (!value)
        return OP_NO_MEMORY;
    if (p->count > 0 && !pointer_resolve(*doc, p, p->count, "path", why, whylen)) {
        json_decref(value);
        return OP_FAILED;
    }
    if (p->count == 0) {
        json_decref(*doc);
        *doc = value;
        return OP_DONE;
    }
    json_t *parent = pointer_resolve(*doc, p, p->count - 1, "path", why, whylen);
    size_t index;
    if (json_is_object(parent))
        return json_object_set_new(parent, p->token[p->count - 1], value) == 0 ? OP_DONE
                                                                               : OP_NO_MEMORY;
    pointer_index(p->token[p->count - 1], &index);
    return json_array_set_new(parent, index, value) == 0 ? OP_DONE : OP_NO_MEMORY;
}

/* 1 when `a` is a proper prefix of `b` (b lies inside the value at a). */
static int pointer_is_inside(const json_pointer *a, const json_pointer *b)
{
    if (a->count >= b->count)
        return 0;
    for (size_t i = 0; i < a->count; i++)
        if (strcmp(a->token[i], b->token[i]) != 0)
            return 0;
    return 1;
}

static int pointer_same(const json_pointer *a, const json_pointer *b)
{
    if (a->count != b->count)
        return 0;
    for (size_t i = 0; i < a->count; i++)
        if (strcmp(a->token[i], b->token[i]) != 0)
            return 0;
    return 1;
}

/* RFC 6902 4.4 "move": remove at `from`, add at `path`. */
static int doc_move(json_t **doc, const json_pointer *from, const json_pointer *path, char *why,
                    size_t whylen)
{
    if (!pointer_resolve(*doc, from, from->count, "from", why, whylen))
        return OP_FAILED;
    if (pointer_is_inside(from, path)) {
        char a[256], b[256];
        pointer_prefix(from, from->count, a, sizeof a);
        pointer_prefix(path, path->count, b, sizeof b);
        snprintf(why, whylen, "%.120s cannot be moved into itself (%.120s lies inside it)",
                 a[0] ? a : "the document", b);
        return OP_FAILED;
    }
    if (pointer_same(from, path))
        return OP_DONE;
    json_t *value = NULL;
    int rc = doc_remove(*doc, from, &value, why, whylen);
    return rc == OP_DONE ? doc_add(doc, path, value, why, whylen) : rc;
}

/* RFC 6902 4.5 "copy": a copy of the value at `from` added at `path`. */
static int doc_copy(json_t **doc, const json_pointer *from, const json_pointer *path, char *why,
                    size_t whylen)
{
    json_t *value = pointer_resolve(*doc, from, from->count, "from", why, whylen);
    return value ? doc_add(doc, path, json_deep_copy(value), why, whylen) : OP_FAILED;
}

/* RFC 6902 4.6 "test": the value at `path` equals `value`. */
static int doc_test(json_t *doc, const json_pointer *path, const json_t *value, char *why,
                    size_t whylen)
{
    json_t *found = pointer_resolve(doc, path, path->count, "path", why, whylen);
    if (!found)
        return OP_FAILED;
    if (json_same(found, value))
        return OP_DONE;
    char at[256], is[80], wanted[80];
    pointer_prefix(path, path->count, at, sizeof at);
    value_text(found, is, sizeof is);
    value_text(value, wanted, sizeof wanted);
    snprintf(why, whylen, "%s is %s, not %s", at[0] ? at : "the document", is, wanted);
    return OP_FAILED;
}

/* One operation whose shape op_check() accepted. */
static int op_run(json_t **doc, const json_t *operation, patch_op op, char *why, size_t whylen)
{
    json_pointer path, from = {0};
    char unused[8];
    if (pointer_parse(json_object_get(operation, "path"), &path, unused, sizeof unused) != 0)
        return OP_NO_MEMORY; /* its form was checked: only memory can fail */
    if (op_takes_from(op) &&
        pointer_parse(json_object_get(operation, "from"), &from, unused, sizeof unused) != 0) {
        pointer_free(&path);
        return OP_NO_MEMORY;
    }
    const json_t *value = json_object_get(operation, "value");
    int rc = OP_FAILED;
    switch (op) {
    case OP_ADD: rc = doc_add(doc, &path, json_deep_copy(value), why, whylen); break;
    case OP_REMOVE: rc = doc_remove(*doc, &path, NULL, why, whylen); break;
    case OP_REPLACE: rc = doc_replace(doc, &path, json_deep_copy(value), why, whylen); break;
    case OP_MOVE: rc = doc_move(doc, &from, &path, why, whylen); break;
    case OP_COPY: rc = doc_copy(doc, &from, &path, why, whylen); break;
    case OP_TEST: rc = doc_test(*doc, &path, value, why, whylen); break;
    case OP_UNKNOWN: break;
    }
    pointer_free(&path);
    pointer_free(&from);
    return rc;
}

/* ---------------------------------------------------------------- shape */

/* operation[name] is a well-formed JSON Pointer; else a problem at it. */
static void member_check_pointer(const json_t *operation, const char *name, const char *at,
                                 problems *p)
{
    char where[80], why[300];
    pointer_join(where, sizeof where, at, name);
    const json_t *v = json_object_get(operation, name);
    json_pointer parsed;
    if (!v)
        problems_add(p, 422, where, "missing \"%s\": a JSON Pointer into the case document, "
                     "e.g. \"/parts/0/material\"", name);
    else if (!json_is_string(v))
        problems_add(p, 422, where, "\"%s\" must be a string (a JSON Pointer), not %s", name,
                     kind_name(v));
    else if (pointer_parse(v, &parsed, why, sizeof why) == -1)
        problems_add(p, 422, where, "%s", why);
    else
        pointer_free(&parsed);
}

/* The shape of operation i (RFC 6902 section 4); members no op defines
 * are ignored, as the RFC asks. */
static void op_check(const json_t *operation, size_t i, problems *p)
{
    char at[40], where[80];
    pointer_join_index(at, sizeof at, "", (long)i);
    if (!json_is_object(operation)) {
        problems_add(p, 422, at, "an operation is an object {\"op\", \"path\", ...}, not %s",
                     kind_name(operation));
        return;
    }
    const json_t *name = json_object_get(operation, "op");
    patch_op op = op_parse(name);
    pointer_join(where, sizeof where, at, "op");
    if (!name)
        problems_add(p, 422, where, "missing \"op\": one of add, remove, replace, move, copy, "
                     "test");
    else if (op == OP_UNKNOWN) {
        char text[80];
        value_text(name, text, sizeof text);
        problems_add(p, 422, where, "unknown op %s: an op is one of add, remove, replace, "
                     "move, copy, test", text);
    }
    member_check_pointer(operation, "path", at, p);
    if (op_takes_from(op))
        member_check_pointer(operation, "from", at, p);
    pointer_join(where, sizeof where, at, "value");
    if (op_takes_value(op) && !json_object_get(operation, "value"))
        problems_add(p, 422, where, "missing \"value\": %s needs the value to %s",
                     op_names[op], op == OP_TEST ? "compare with" : "put at \"path\"");
}

/* ----------------------------------------------------------------- apply */

json_t *json_patch_apply(const json_t *target, const json_t *patch, problems *p)
{
    if (!json_is_array(patch)) {
        problems_add(p, 422, "", "a JSON Patch (RFC 6902) is an array of operations, e.g. "
                     "[{\"op\": \"replace\", \"path\": \"/name\", \"value\": \"copy\"}], not %s",
                     kind_name(patch));
        return NULL;
    }
    int before = p->count + p->dropped;
    for (size_t i = 0; i < json_array_size(patch); i++)
        op_check(json_array_get(patch, i), i, p);
    if (p->count + p->dropped > before)
        return NULL;
    json_t *doc = target ? json_deep_copy(target) : json_null();
    for (size_t i = 0; doc && i < json_array_size(patch); i++) {
        const json_t *operation = json_array_get(patch, i);
        patch_op op = op_parse(json_object_get(operation, "op"));
        char why[480] = "";
        int rc = op_run(&doc, operation, op, why, sizeof why);
        if (rc == OP_DONE)
            continue;
        if (rc == OP_FAILED) {
            char at[40];
            pointer_join_index(at, sizeof at, "", (long)i);
            problems_add(p, 422, at, "%s failed, so the patch changed nothing: %s", op_names[op],
                         why);
        }
        json_decref(doc);
        doc = NULL;
    }
    return doc;
}
