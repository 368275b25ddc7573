/*
 * test_json_patch.c - JSON Merge Patch against every example of RFC 7396
 * appendix A (and the section 3 example), and the document dump: reals in
 * the fewest digits that read back to the same double, every value and the
 * member order kept. And the nesting scan that guards every JSON body.
 */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "json/json_depth.h"
#include "json/json_patch.h"

static json_t *parse(const char *text)
{
    json_error_t err;
    json_t *v = json_loads(text, JSON_DECODE_ANY, &err);
    CHECK(v != NULL, "test JSON does not parse: %s: %s", text, err.text);
    return v;
}

/* merge(original, patch) == result, and neither input is changed. */
static void check_merge(const char *original, const char *patch, const char *result)
{
    json_t *t = parse(original), *p = parse(patch), *want = parse(result);
    json_t *t_before = json_deep_copy(t), *p_before = json_deep_copy(p);
    json_t *got = json_merge_patch(t, p);
    char *got_text = got ? json_dumps(got, JSON_ENCODE_ANY | JSON_COMPACT) : NULL;
    CHECK(got && json_equal(got, want), "merge %s with %s gave %s, want %s", original, patch,
          got_text ? got_text : "NULL", result);
    CHECK(json_equal(t, t_before) && json_equal(p, p_before), "the inputs of %s + %s changed",
          original, patch);
    free(got_text);
    json_decref(got);
    json_decref(t);
    json_decref(p);
    json_decref(want);
    json_decref(t_before);
    json_decref(p_before);
}

static void rfc7396_appendix_a(void)
{
    static const char *const rows[][3] = {
        {"{\"a\":\"b\"}", "{\"a\":\"c\"}", "{\"a\":\"c\"}"},
        {"{\"a\":\"b\"}", "{\"b\":\"c\"}", "{\"a\":\"b\",\"b\":\"c\"}"},
        {"{\"a\":\"b\"}", "{\"a\":null}", "{}"},
        {"{\"a\":\"b\",\"b\":\"c\"}", "{\"a\":null}", "{\"b\":\"c\"}"},
        {"{\"a\":[\"b\"]}", "{\"a\":\"c\"}", "{\"a\":\"c\"}"},
        {"{\"a\":\"c\"}", "{\"a\":[\"b\"]}", "{\"a\":[\"b\"]}"},
        {"{\"a\":{\"b\":\"c\"}}", "{\"a\":{\"b\":\"d\",\"c\":null}}", "{\"a\":{\"b\":\"d\"}}"},
        {"{\"a\":[{\"b\":\"c\"}]}", "{\"a\":[1]}", "{\"a\":[1]}"},
        {"[\"a\",\"b\"]", "[\"c\",\"d\"]", "[\"c\",\"d\"]"},
        {"{\"a\":\"b\"}", "[\"c\"]", "[\"c\"]"},
        {"{\"a\":\"foo\"}", "null", "null"},
        {"{\"a\":\"foo\"}", "\"bar\"", "\"bar\""},
        {"{\"e\":null}", "{\"a\":1}", "{\"e\":null,\"a\":1}"},
        {"[1,2]", "{\"a\":\"b\",\"c\":null}", "{\"a\":\"b\"}"},
        {"{}", "{\"a\":{\"bb\":{\"ccc\":null}}}", "{\"a\":{\"bb\":{}}}"},
    };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++)
        check_merge(rows[i][0], rows[i][1], rows[i][2]);
}

static void rfc7396_section_3_example(void)
{
    check_merge("{\"title\":\"Goodbye!\",\"author\":{\"givenName\":\"John\",\"familyName\":\"Doe\"},"
                "\"tags\":[\"example\",\"sample\"],\"content\":\"This will be unchanged\"}",
                "{\"title\":\"Hello!\",\"phoneNumber\":\"+01-123-456-7890\","
                "\"author\":{\"familyName\":null},\"tags\":[\"example\"]}",
                "{\"title\":\"Hello!\",\"author\":{\"givenName\":\"John\"},\"tags\":[\"example\"],"
                "\"content\":\"This will be unchanged\",\"phoneNumber\":\"+01-123-456-7890\"}");
}

static void a_patch_on_a_case_changes_only_what_it_names(void)
{
    check_merge("{\"name\":\"a\",\"time\":{\"end\":0.5,\"safety\":0.5},\"gravity\":[0,-9.81]}",
                "{\"name\":\"b\",\"time\":{\"end\":1.0},\"gravity\":null}",
                "{\"name\":\"b\",\"time\":{\"end\":1.0,\"safety\":0.5}}");
}

static void dump_writes_the_shortest_exact_reals(void)
{
    json_t *doc = parse("{\"z\": 0.1, \"a\": [1e-7, 2.5, 1.0, 3, -0.30000000000000004, 1e300,"
                        " 6.02214076e23], \"s\": \"q\\\"\\n\\u00e9\", \"t\": true, \"n\": null,"
                        " \"e\": {}, \"l\": []}");
    size_t length = 0;
    char *text = json_dump_document(doc, &length);
    CHECK(text && strlen(text) == length, "dump failed or length wrong");
    if (!text) {
        json_decref(doc);
        return;
    }
    CHECK(strstr(text, "\"z\": 0.1,") != NULL, "0.1 written as in: %s", text);
    CHECK(strstr(text, "1e-07") || strstr(text, "1e-7"), "1e-7 kept short: %s", text);
    CHECK(strstr(text, "1.0,") != NULL, "a whole real stays a real: %s", text);
    CHECK(strstr(text, "-0.30000000000000004") != NULL, "17 digits where needed: %s", text);
    CHECK(strchr(text, 'z') < strchr(text, 'a'), "member order kept: %s", text);
    json_t *back = parse(text);
    CHECK(back && json_equal(back, doc), "the dump reads back to a different document: %s", text);
    json_t *one = json_array_get(json_object_get(back, "a"), 2);
    CHECK(json_is_real(one), "1.0 reads back as a real");
    json_decref(back);
    free(text);
    json_decref(doc);
}

/* Brackets in strings (escaped quotes included) do not count; the first
 * bracket past the limit is located by line and column. */
static void depth_scan_counts_only_real_nesting(void)
{
    int line = 0, column = 0;
    const char *flat = "{\"a\": \"[[[{{{\\\"[[[\", \"b\": [[1], [2]]}";
    CHECK(!json_depth_exceeds(flat, strlen(flat), 3, &line, &column), "strings counted: %s", flat);
    CHECK(json_depth_exceeds(flat, strlen(flat), 2, &line, &column) && line == 1 && column == 28,
          "limit 2 on %s: line %d column %d", flat, line, column);
    const char *deep = "{\n  \"x\": [\n    [[]]]}";
    CHECK(json_depth_exceeds(deep, strlen(deep), 3, &line, &column) && line == 3 && column == 6,
          "limit 3 on the deep text: line %d column %d", line, column);
    CHECK(!json_depth_exceeds(deep, strlen(deep), 4, NULL, NULL), "4 levels are within 4");
    char many[200];
    memset(many, '[', 100);
    memset(many + 100, ']', 100);
    CHECK(!json_depth_exceeds(many, 200, 100, NULL, NULL) && json_depth_exceeds(many, 200, 99, NULL, NULL),
          "100 levels: within 100, past 99");
}

CHECK_MAIN(T(rfc7396_appendix_a), T(rfc7396_section_3_example),
           T(a_patch_on_a_case_changes_only_what_it_names), T(dump_writes_the_shortest_exact_reals),
           T(depth_scan_counts_only_real_nesting))
