/*
 * test_json_patch_ops.c - JSON Patch (RFC 6902) against every example of
 * the RFC's appendix A, the pointer examples of RFC 6901 section 5, and
 * what a clone needs of it: a failing operation (a failing test included)
 * changes nothing and is named by its index with the reason; malformed
 * operations are all reported at once, at their pointers into the patch.
 */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "json/json_patch.h"

static json_t *parse(const char *text)
{
    json_error_t err;
    json_t *v = json_loads(text, JSON_DECODE_ANY | JSON_REJECT_DUPLICATES, &err);
    CHECK(v != NULL, "test JSON does not parse: %s: %s", text, err.text);
    return v;
}

/* patch(doc) == result, and neither input is changed. */
static void check_patch(const char *doc, const char *patch, const char *result)
{
    json_t *t = parse(doc), *p = parse(patch), *want = parse(result);
    json_t *t_before = json_deep_copy(t), *p_before = json_deep_copy(p);
    problems probs;
    problems_init(&probs);
    json_t *got = json_patch_apply(t, p, &probs);
    char *got_text = got ? json_dumps(got, JSON_ENCODE_ANY | JSON_COMPACT) : NULL;
    CHECK(got && json_equal(got, want), "%s on %s gave %s (%s), want %s", patch, doc,
          got_text ? got_text : "NULL", probs.count ? probs.items[0].message : "", result);
    CHECK(probs.count == 0, "%s on %s: %d problems", patch, doc, probs.count);
    CHECK(json_equal(t, t_before) && json_equal(p, p_before), "the inputs of %s on %s changed",
          patch, doc);
    free(got_text);
    problems_free(&probs);
    json_decref(got);
    json_decref(t);
    json_decref(p);
    json_decref(want);
    json_decref(t_before);
    json_decref(p_before);
}

/* patch(doc) fails: NULL, one problem at `pointer` whose message holds
 * `says`, and the document is unchanged. */
static void check_fails(const char *doc, const char *patch, const char *pointer, const char *says)
{
    json_t *t = parse(doc), *p = parse(patch), *t_before = json_deep_copy(t);
    problems probs;
    problems_init(&probs);
    json_t *got = json_patch_apply(t, p, &probs);
    CHECK(got == NULL, "%s on %s should fail", patch, doc);
    CHECK(probs.count == 1 && probs.status == 422, "%s on %s: %d problems, status %d", patch, doc,
          probs.count, probs.status);
    if (probs.count >= 1) {
        CHECK(strcmp(probs.items[0].pointer, pointer) == 0, "%s on %s: pointer \"%s\", want \"%s\"",
              patch, doc, probs.items[0].pointer, pointer);
        CHECK(strstr(probs.items[0].message, says) != NULL, "%s on %s: message \"%s\" lacks \"%s\"",
              patch, doc, probs.items[0].message, says);
    }
    CHECK(json_equal(t, t_before), "a failed patch changed its target: %s", patch);
    json_decref(got);
    problems_free(&probs);
    json_decref(t);
    json_decref(p);
    json_decref(t_before);
}

/* RFC 6902 appendix A, A.1 ... A.16, in order. */
static void rfc6902_appendix_a(void)
{
    /* A.1 Adding an Object Member */
    check_patch("{\"foo\":\"bar\"}", "[{\"op\":\"add\",\"path\":\"/baz\",\"value\":\"qux\"}]",
                "{\"baz\":\"qux\",\"foo\":\"bar\"}");
    /* A.2 Adding an Array Element */
    check_patch("{\"foo\":[\"bar\",\"baz\"]}", "[{\"op\":\"add\",\"path\":\"/foo/1\",\"value\":\"qux\"}]",
                "{\"foo\":[\"bar\",\"qux\",\"baz\"]}");
    /* A.3 Removing an Object Member */
    check_patch("{\"baz\":\"qux\",\"foo\":\"bar\"}", "[{\"op\":\"remove\",\"path\":\"/baz\"}]",
                "{\"foo\":\"bar\"}");
    /* A.4 Removing an Array Element */
    check_patch("{\"foo\":[\"bar\",\"qux\",\"baz\"]}", "[{\"op\":\"remove\",\"path\":\"/foo/1\"}]",
                "{\"foo\":[\"bar\",\"baz\"]}");
    /* A.5 Replacing a Value */
    check_patch("{\"baz\":\"qux\",\"foo\":\"bar\"}",
                "[{\"op\":\"replace\",\"path\":\"/baz\",\"value\":\"boo\"}]",
                "{\"baz\":\"boo\",\"foo\":\"bar\"}");
    /* A.6 Moving a Value */
    check_patch("{\"foo\":{\"bar\":\"baz\",\"waldo\":\"fred\"},\"qux\":{\"corge\":\"grault\"}}",
                "[{\"op\":\"move\",\"from\":\"/foo/waldo\",\"path\":\"/qux/thud\"}]",
                "{\"foo\":{\"bar\":\"baz\"},\"qux\":{\"corge\":\"grault\",\"thud\":\"fred\"}}");
    /* A.7 Moving an Array Element */
    check_patch("{\"foo\":[\"all\",\"grass\",\"cows\",\"eat\"]}",
                "[{\"op\":\"move\",\"from\":\"/foo/1\",\"path\":\"/foo/3\"}]",
                "{\"foo\":[\"all\",\"cows\",\"eat\",\"grass\"]}");
    /* A.8 Testing a Value: Success */
    check_patch("{\"baz\":\"qux\",\"foo\":[\"a\",2,\"c\"]}",
                "[{\"op\":\"test\",\"path\":\"/baz\",\"value\":\"qux\"},"
                "{\"op\":\"test\",\"path\":\"/foo/1\",\"value\":2}]",
                "{\"baz\":\"qux\",\"foo\":[\"a\",2,\"c\"]}");
    /* A.9 Testing a Value: Error */
    check_fails("{\"baz\":\"qux\"}", "[{\"op\":\"test\",\"path\":\"/baz\",\"value\":\"bar\"}]", "/0",
                "/baz is \"qux\", not \"bar\"");
    /* A.10 Adding a Nested Member Object */
    check_patch("{\"foo\":\"bar\"}", "[{\"op\":\"add\",\"path\":\"/child\",\"value\":{\"grandchild\":{}}}]",
                "{\"foo\":\"bar\",\"child\":{\"grandchild\":{}}}");
    /* A.11 Ignoring Unrecognized Elements */
    check_patch("{\"foo\":\"bar\"}", "[{\"op\":\"add\",\"path\":\"/baz\",\"value\":\"qux\",\"xyz\":123}]",
                "{\"foo\":\"bar\",\"baz\":\"qux\"}");
    /* A.12 Adding to a Nonexistent Target */
    check_fails("{\"foo\":\"bar\"}", "[{\"op\":\"add\",\"path\":\"/baz/bat\",\"value\":\"qux\"}]", "/0",
                "the parent of path /baz does not exist");
    /* A.13 Invalid JSON Patch Document: a repeated "op" is refused where the
     * patch is read (JSON_REJECT_DUPLICATES, as the daemon reads bodies) */
    json_error_t err;
    json_t *dup = json_loads("[{\"op\":\"add\",\"path\":\"/baz\",\"value\":\"qux\",\"op\":\"remove\"}]",
                             JSON_REJECT_DUPLICATES, &err);
    CHECK(dup == NULL, "A.13: a patch with \"op\" twice parses");
    json_decref(dup);
    /* A.14 ~ Escape Ordering */
    check_patch("{\"/\":9,\"~1\":10}", "[{\"op\":\"test\",\"path\":\"/~01\",\"value\":10}]",
                "{\"/\":9,\"~1\":10}");
    /* A.15 Comparing Strings and Numbers */
    check_fails("{\"/\":9,\"~1\":10}", "[{\"op\":\"test\",\"path\":\"/~01\",\"value\":\"10\"}]", "/0",
                "/~01 is 10, not \"10\"");
    /* A.16 Adding an Array Value */
    check_patch("{\"foo\":[\"bar\"]}", "[{\"op\":\"add\",\"path\":\"/foo/-\",\"value\":[\"abc\",\"def\"]}]",
                "{\"foo\":[\"bar\",[\"abc\",\"def\"]]}");
}

/* RFC 6901 section 5: every pointer of its example resolves to the value
 * it lists (checked with test operations, which must all hold). */
static void rfc6901_section_5_pointers(void)
{
    static const char doc[] = "{\"foo\":[\"bar\",\"baz\"],\"\":0,\"a/b\":1,\"c%d\":2,\"e^f\":3,"
                              "\"g|h\":4,\"i\\\\j\":5,\"k\\\"l\":6,\" \":7,\"m~n\":8}";
    static const char *const rows[][2] = {
        {"", "{\"foo\":[\"bar\",\"baz\"],\"\":0,\"a/b\":1,\"c%d\":2,\"e^f\":3,\"g|h\":4,"
             "\"i\\\\j\":5,\"k\\\"l\":6,\" \":7,\"m~n\":8}"},
        {"/foo", "[\"bar\",\"baz\"]"}, {"/foo/0", "\"bar\""}, {"/", "0"}, {"/a~1b", "1"},
        {"/c%d", "2"}, {"/e^f", "3"}, {"/g|h", "4"}, {"/i\\\\j", "5"}, {"/k\\\"l", "6"},
        {"/ ", "7"}, {"/m~0n", "8"},
    };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++) {
        char patch[400];
        snprintf(patch, sizeof patch, "[{\"op\":\"test\",\"path\":\"%s\",\"value\":%s}]", rows[i][0],
                 rows[i][1]);
        check_patch(doc, patch, doc);
    }
}

/* Section 4.6: numbers equal by value, objects whatever their order. */
static void test_compares_values_not_spellings(void)
{
    check_patch("{\"a\":1,\"o\":{\"x\":1,\"y\":[2.5,null,true]}}",
                "[{\"op\":\"test\",\"path\":\"/a\",\"value\":1.0},"
                "{\"op\":\"test\",\"path\":\"/o\",\"value\":{\"y\":[2.5,null,true],\"x\":1e0}}]",
                "{\"a\":1,\"o\":{\"x\":1,\"y\":[2.5,null,true]}}");
    check_fails("{\"o\":{\"x\":1}}", "[{\"op\":\"test\",\"path\":\"/o\",\"value\":{\"x\":1,\"y\":2}}]",
                "/0", "/o is {\"x\":1}, not {\"x\":1,\"y\":2}");
    check_fails("{\"a\":[1,2]}", "[{\"op\":\"test\",\"path\":\"/a\",\"value\":[2,1]}]", "/0",
                "/a is [1,2], not [2,1]");
}

/* The whole document, "-", move inside one array, copy, and an operation
 * that reads what an earlier one of the same patch wrote. */
static void operations_apply_in_order(void)
{
    check_patch("{\"a\":1}", "[{\"op\":\"replace\",\"path\":\"\",\"value\":{\"b\":2}}]", "{\"b\":2}");
    check_patch("{\"a\":1}", "[{\"op\":\"add\",\"path\":\"\",\"value\":[1]}]", "[1]");
    check_patch("{\"a\":[1,2,3]}", "[{\"op\":\"move\",\"from\":\"/a/2\",\"path\":\"/a/0\"}]",
                "{\"a\":[3,1,2]}");
    check_patch("{\"a\":[1,2,3]}", "[{\"op\":\"move\",\"from\":\"/a\",\"path\":\"/a\"}]",
                "{\"a\":[1,2,3]}");
    check_patch("{\"a\":{\"x\":[1]}}", "[{\"op\":\"copy\",\"from\":\"/a\",\"path\":\"/b\"},"
                "{\"op\":\"add\",\"path\":\"/b/x/-\",\"value\":2}]",
                "{\"a\":{\"x\":[1]},\"b\":{\"x\":[1,2]}}");
    check_patch("{\"a\":[1,2]}", "[{\"op\":\"add\",\"path\":\"/a/2\",\"value\":3},"
                "{\"op\":\"test\",\"path\":\"/a/2\",\"value\":3},"
                "{\"op\":\"remove\",\"path\":\"/a/0\"}]", "{\"a\":[2,3]}");
    check_patch("{\"a\":{\"b\":1}}", "[{\"op\":\"add\",\"path\":\"/a/b\",\"value\":null}]",
                "{\"a\":{\"b\":null}}");
    check_patch("{}", "[]", "{}");
}

/* What cannot be done names the operation and why, and changes nothing
 * even when earlier operations had succeeded. */
static void a_failing_operation_changes_nothing(void)
{
    static const char parts[] = "{\"parts\":[{\"material\":\"rock\"},{\"material\":\"steel\"},{}]}";
    check_fails(parts, "[{\"op\":\"replace\",\"path\":\"/parts/0/material\",\"value\":\"granite\"},"
                "{\"op\":\"remove\",\"path\":\"/parts/1\"},"
                "{\"op\":\"test\",\"path\":\"/parts/0/material\",\"value\":\"granite\"},"
                "{\"op\":\"remove\",\"path\":\"/parts/7\"}]",
                "/3", "remove failed, so the patch changed nothing: path /parts/7 does not exist "
                      "(/parts has 2 elements)");
    check_fails(parts, "[{\"op\":\"replace\",\"path\":\"/parts/0/material\",\"value\":\"granite\"},"
                "{\"op\":\"test\",\"path\":\"/parts/0/material\",\"value\":\"rock\"}]",
                "/1", "/parts/0/material is \"granite\", not \"rock\"");
    check_fails(parts, "[{\"op\":\"replace\",\"path\":\"/parts/3\",\"value\":{}}]", "/0",
                "path /parts/3 does not exist (/parts has 3 elements)");
    check_fails(parts, "[{\"op\":\"add\",\"path\":\"/parts/4\",\"value\":{}}]", "/0",
                "\"4\" is not a place in the array /parts: it has 3 elements");
    check_fails(parts, "[{\"op\":\"replace\",\"path\":\"/parts/01\",\"value\":{}}]", "/0",
                "\"01\" is not an index of the array /parts");
    check_fails(parts, "[{\"op\":\"remove\",\"path\":\"/parts/-\"}]", "/0",
                "\"-\" is not an index of the array /parts");
    check_fails(parts, "[{\"op\":\"add\",\"path\":\"/parts/0/material/x\",\"value\":1}]", "/0",
                "the parent /parts/0/material is a string, not an object or array");
    check_fails(parts, "[{\"op\":\"remove\",\"path\":\"/parts/2/name\"}]", "/0",
                "path /parts/2/name does not exist (/parts/2 has no member \"name\")");
    check_fails(parts, "[{\"op\":\"move\",\"from\":\"/parts\",\"path\":\"/parts/0/old\"}]", "/0",
                "/parts cannot be moved into itself");
    check_fails(parts, "[{\"op\":\"copy\",\"from\":\"/name\",\"path\":\"/parts/0/name\"}]", "/0",
                "from /name does not exist");
    check_fails(parts, "[{\"op\":\"remove\",\"path\":\"\"}]", "/0",
                "the whole document (path \"\") cannot be removed");
}

/* Every malformed operation is reported, each at its own pointer, and no
 * operation runs. */
static void malformed_operations_are_all_reported(void)
{
    json_t *doc = parse("{\"a\":1}");
    json_t *patch = parse("[{\"op\":\"replace\",\"path\":\"/a\",\"value\":2},"
                          "{\"op\":\"delete\",\"path\":\"/a\"},"
                          "{\"path\":\"/a\"},"
                          "{\"op\":\"add\",\"path\":\"a\",\"value\":1},"
                          "{\"op\":\"move\",\"path\":\"/b\"},"
                          "{\"op\":\"test\",\"path\":\"/a~2\"},"
                          "5]");
    problems p;
    problems_init(&p);
    json_t *got = json_patch_apply(doc, patch, &p);
    static const char *const want[][2] = {
        {"/1/op", "unknown op \"delete\""}, {"/2/op", "missing \"op\""},
        {"/3/path", "must be \"\" (the whole document) or start with \"/\""},
        {"/4/from", "missing \"from\""}, {"/5/path", "\"~\" must be followed by 0 or 1"},
        {"/5/value", "missing \"value\": test needs the value to compare with"},
        {"/6", "an operation is an object"},
    };
    size_t n = sizeof want / sizeof *want;
    CHECK(got == NULL && p.count == (int)n, "got %p with %d problems, want NULL and %zu",
          (void *)got, p.count, n);
    for (size_t i = 0; i < n && i < (size_t)p.count; i++)
        CHECK(strcmp(p.items[i].pointer, want[i][0]) == 0 && strstr(p.items[i].message, want[i][1]),
              "problem %zu: %s: %s; want %s: ...%s...", i, p.items[i].pointer, p.items[i].message,
              want[i][0], want[i][1]);
    json_decref(got);
    problems_free(&p);
    problems_init(&p);
    json_t *object = parse("{\"op\":\"add\"}");
    CHECK(json_patch_apply(doc, object, &p) == NULL && p.count == 1 &&
          strcmp(p.items[0].pointer, "") == 0 && strstr(p.items[0].message, "is an array of operations"),
          "an object as a JSON Patch: %d problems", p.count);
    problems_free(&p);
    json_decref(object);
    json_decref(patch);
    json_decref(doc);
}

CHECK_MAIN(T(rfc6902_appendix_a), T(rfc6901_section_5_pointers), T(test_compares_values_not_spellings),
           T(operations_apply_in_order), T(a_failing_operation_changes_nothing),
           T(malformed_operations_are_all_reported))
