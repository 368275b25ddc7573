/*
 * case_read.c - typed reads of JSON values for the case builder, each of
 * which either accepts the value or records one problem at its pointer.
 *
 * Users write cases by hand and from scripts, so the messages say what was
 * expected and what was found ("expected a number, got a string"), and a
 * misspelt key is never ignored: it is reported with the closest valid name.
 */
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "case_internal.h"

const char *case_type_word(const json_t *value)
{
    switch (json_typeof(value)) {
    case JSON_OBJECT: return "an object";
    case JSON_ARRAY: return "an array";
    case JSON_STRING: return "a string";
    case JSON_INTEGER:
    case JSON_REAL: return "a number";
    case JSON_TRUE:
    case JSON_FALSE: return "a boolean";
    case JSON_NULL: return "null";
    }
    return "an unknown value";
}

void case_problem(case_doc *doc, const char *pointer, const char *fmt, ...)
{
    char message[sizeof ((problem *)0)->message];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof message, fmt, args);
    va_end(args);
    problems_add(doc->out, 422, pointer, "%s", message);
}

json_t *case_member(const json_t *object, const char *base, const char *key, char *ptr)
{
    pointer_join(ptr, CASE_POINTER, base, key);
    return json_object_get(object, key);
}

int case_expect_object(case_doc *doc, const json_t *value, const char *ptr)
{
    if (json_is_object(value)) return 1;
    case_problem(doc, ptr, "expected an object, got %s", case_type_word(value));
    return 0;
}

int case_expect_array(case_doc *doc, const json_t *value, const char *ptr)
{
    if (json_is_array(value)) return 1;
    case_problem(doc, ptr, "expected an array, got %s", case_type_word(value));
    return 0;
}

int case_read_number(case_doc *doc, const json_t *value, const char *ptr, double *out)
{
    if (!json_is_number(value)) {
        case_problem(doc, ptr, "expected a number, got %s", case_type_word(value));
        return 0;
    }
    double v = json_number_value(value);
    if (!isfinite(v)) {
        case_problem(doc, ptr, "expected a finite number");
        return 0;
    }
    *out = v;
    return 1;
}

const char *case_count_word(int count)
{
    static const char *const words[] = {"zero", "one", "two", "three", "four", "five", "six"};
    return count >= 0 && count <= 6 ? words[count] : "several";
}

const char *case_wrong_tuple(const case_doc *doc, const json_t *value, int per_axis, char *buf,
                             size_t size)
{
    if (!json_is_array(value)) {
        snprintf(buf, size, "%s", case_type_word(value));
        return buf;
    }
    /* The usual cause of a vector of the wrong length is a case written for
     * the other dimension ("dimension": 3 left out, or left in), and the
     * shape is then the only other problem that says so. */
    size_t n = json_array_size(value);
    const char *note = "";
    if (per_axis > 0 && doc->dimension == 2 && n == (size_t)(3 * per_axis))
        note = " (this case is 2D: set \"dimension\": 3 at the top of the case for a 3D one)";
    else if (per_axis > 0 && doc->dimension == 3 && n == (size_t)(2 * per_axis))
        note = " (this case has \"dimension\": 3, so vectors have three components)";
    snprintf(buf, size, "an array of %zu item%s%s", n, n == 1 ? "" : "s", note);
    return buf;
}

/* 1 when `value` is an array of exactly `count` items, else a problem
 * "expected an array of three numbers [layout], got ...". `per_axis` > 0:
 * `count` is that many per axis of the case (see case_wrong_tuple). */
static int case_expect_tuple(case_doc *doc, const json_t *value, const char *ptr, int count,
                             int per_axis, const char *items, const char *layout)
{
    if (json_is_array(value) && json_array_size(value) == (size_t)count) return 1;
    char got[160];
    case_problem(doc, ptr, "expected an array of %s %s%s%s, got %s", case_count_word(count),
                 items, layout[0] ? " " : "", layout,
                 case_wrong_tuple(doc, value, per_axis, got, sizeof got));
    return 0;
}

static int case_read_numbers(case_doc *doc, const json_t *value, const char *ptr, int count,
                             int per_axis, double *out)
{
    if (!case_expect_tuple(doc, value, ptr, count, per_axis, "numbers", "")) return 0;
    int ok = 1;
    for (int k = 0; k < count; k++) {
        char item[CASE_POINTER];
        pointer_join_index(item, sizeof item, ptr, k);
        ok &= case_read_number(doc, json_array_get(value, (size_t)k), item, &out[k]);
    }
    return ok;
}

int case_read_vector(case_doc *doc, const json_t *value, const char *ptr, int count,
                     double *out)
{
    return case_read_numbers(doc, value, ptr, count, 0, out);
}

int case_read_axes(case_doc *doc, const json_t *value, const char *ptr, double *out)
{
    return case_read_numbers(doc, value, ptr, doc->dimension, 1, out);
}

int case_read_integer(case_doc *doc, const json_t *value, const char *ptr, long lo, long hi,
                      long *out)
{
    const long exact = 1L << 53; /* beyond this a double is not a whole count */
    double v;
    if (!case_read_number(doc, value, ptr, &v)) return 0;
    if (v != floor(v)) {
        case_problem(doc, ptr, "expected a whole number, got %g", v);
        return 0;
    }
    long top = hi < exact ? hi : exact;
    if (v < (double)lo) {
        case_problem(doc, ptr, "must be at least %ld, got %.17g", lo, v);
        return 0;
    }
    if (v > (double)top) {
        if (hi >= exact) case_problem(doc, ptr, "%.17g is too large", v);
        else case_problem(doc, ptr, "must be at most %ld, got %.17g", hi, v);
        return 0;
    }
    *out = (long)v; /* in range, so the conversion is defined */
    return 1;
}

int case_read_integers(case_doc *doc, const json_t *value, const char *ptr, int count,
                       const long *lo, long hi, const char *layout, long *out)
{
    if (!case_expect_tuple(doc, value, ptr, count, 0, "whole numbers", layout)) return 0;
    int ok = 1;
    for (int k = 0; k < count; k++) {
        char item[CASE_POINTER];
        pointer_join_index(item, sizeof item, ptr, k);
        ok &= case_read_integer(doc, json_array_get(value, (size_t)k), item, lo[k], hi, &out[k]);
    }
    return ok;
}

int case_read_bool(case_doc *doc, const json_t *value, const char *ptr, int *out)
{
    if (!json_is_boolean(value)) {
        case_problem(doc, ptr, "expected true or false, got %s", case_type_word(value));
        return 0;
    }
    *out = json_is_true(value);
    return 1;
}

int case_number_member(case_doc *doc, const json_t *object, const char *base,
                       const char *key, int required, double *out)
{
    char ptr[CASE_POINTER];
    json_t *value = case_member(object, base, key, ptr);
    if (!value) {
        if (!required) return 1;
        case_problem(doc, base, "missing required \"%s\"", key);
        return 0;
    }
    return case_read_number(doc, value, ptr, out);
}

/* --------------------------------------------------------------- names */

/* A jansson object is the hash table: reading a case must stay linear in
 * its size, and a linear scan per reference made a million materials (or
 * constraints) times 1024 parts cost seconds of CPU per request. */
int case_names_add(case_doc *doc, json_t **names, const char *name, int index)
{
    if (!*names) *names = json_object();
    json_t *known = *names ? json_object_get(*names, name) : NULL;
    if (known) return (int)json_integer_value(known);
    if (!*names || json_object_set_new(*names, name, json_integer(index)) != 0)
        case_problem(doc, "", "out of memory");
    return -1;
}

int case_names_find(const json_t *names, const char *name)
{
    json_t *known = names ? json_object_get(names, name) : NULL;
    return known ? (int)json_integer_value(known) : -1;
}

/* --------------------------------------------------------------- typos */

#define CASE_TYPO_MAX 64 /* longer words get no suggestion */

/* Suggestions are a courtesy, so the work spent on them is capped per
 * document: at most this many cells of edit-distance table in all (a few
 * milliseconds). Without the cap, 1024 unknown 64-byte names among 1500
 * materials cost 6e9 cells, over ten seconds of CPU for one request. Past the
 * cap a problem is still reported, only without a hint. */
#define CASE_TYPO_BUDGET (4L << 20)

static size_t case_min3(size_t a, size_t b, size_t c)
{
    size_t m = a < b ? a : b;
    return m < c ? m : c;
}

/* Edit distance counting an adjacent transposition as one edit ("tpo" is
 * one edit from "top"): optimal string alignment, three rows of state. */
static size_t case_edit_distance(const char *a, size_t la, const char *b, size_t lb)
{
    size_t rows[3][CASE_TYPO_MAX + 1];
    size_t *before = rows[0], *prev = rows[1], *row = rows[2];
    for (size_t j = 0; j <= lb; j++) prev[j] = j;
    for (size_t i = 1; i <= la; i++) {
        row[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t cost = a[i - 1] != b[j - 1];
            row[j] = case_min3(prev[j] + 1, row[j - 1] + 1, prev[j - 1] + cost);
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                before[j - 2] + 1 < row[j])
                row[j] = before[j - 2] + 1;
        }
        size_t *oldest = before;
        before = prev;
        prev = row;
        row = oldest;
    }
    return prev[lb];
}

/* strlen that gives up past CASE_TYPO_MAX: a candidate may be megabytes. */
static size_t case_typo_length(const char *s)
{
    size_t n = 0;
    while (n <= CASE_TYPO_MAX && s[n]) n++;
    return n;
}

const char *case_closest(const char *word, const char *const *candidates, int count,
                         long *cells_left)
{
    size_t lw = case_typo_length(word);
    if (lw == 0 || lw > CASE_TYPO_MAX) return NULL;
    const char *best = NULL;
    size_t best_distance = (size_t)-1;
    for (int i = 0; i < count; i++) {
        size_t lc = case_typo_length(candidates[i]);
        if (lc > CASE_TYPO_MAX) continue;
        size_t longer = lw > lc ? lw : lc;
        /* the distance is at least the difference in length */
        size_t gap = lw > lc ? lw - lc : lc - lw;
        if (3 * gap > longer || gap >= best_distance) continue;
        long cells = (long)(lw * lc);
        if (*cells_left < cells) break;
        *cells_left -= cells;
        size_t d = case_edit_distance(word, lw, candidates[i], lc);
        /* a plausible typo: at most a third of the longer word changed */
        if (d > 0 && 3 * d <= longer && d < best_distance) {
            best = candidates[i];
            best_distance = d;
        }
    }
    return best;
}

const char *case_did_you_mean(case_doc *doc, char *buf, size_t size, const char *word,
                              const char *const *candidates, int count)
{
    if (size) buf[0] = '\0';
    if (doc->out->count >= PROBLEMS_MAX) return buf; /* the problem will only be counted */
    long left = CASE_TYPO_BUDGET - doc->typo_cells;
    const char *close = case_closest(word, candidates, count, &left);
    doc->typo_cells = CASE_TYPO_BUDGET - left;
    if (close) snprintf(buf, size, "; did you mean \"%.64s\"?", close);
    return buf;
}

/* Names of the same quantity in other codes and textbooks, none a typo of
 * ours: a rock engineer's first case says "E" or "poisson_ratio". Offered
 * only where the name they mean is allowed. */
static const char *const case_other_names[][2] = {
    {"E", "young"},           {"youngs_modulus", "young"}, {"young_modulus", "young"},
    {"youngs", "young"},      {"elastic_modulus", "young"}, {"modulus", "young"},
    {"nu", "poisson"},        {"poisson_ratio", "poisson"}, {"poissons_ratio", "poisson"},
    {"rho", "density"},       {"mass_density", "density"},  {"mu", "friction"},
    {"friction_coefficient", "friction"}, {"phi", "friction_angle"}, {"c", "cohesion"},
    {"ft", "tensile_strength"}, {"f_t", "tensile_strength"}, {"tensile", "tensile_strength"},
    {"GI", "energy_I"},       {"G_I", "energy_I"},          {"Gf", "energy_I"},
    {"G_f", "energy_I"},      {"GII", "energy_II"},         {"G_II", "energy_II"}};

/* Keys of one section met in another ("interval" in "time"): where they go. */
static const char *const case_key_homes[][3] = {
    {"interval", "/output", "belongs in \"output\""},
    {"fields", "/output", "belongs in \"output\""},
    {"dt", "/time", "belongs in \"time\""},
    {"end", "/time", "belongs in \"time\""},
    {"safety", "/time", "belongs in \"time\""},
    {"gravity", "", "belongs at the top of the case"},
    {"dimension", "", "belongs at the top of the case"}};

/* The hint for an unknown key that is no typo: another name of an allowed
 * key, or a key of another section. */
static void case_key_hint(char *buf, size_t size, const char *key, const char *ptr,
                          const char *const *allowed, int count)
{
    for (size_t i = 0; i < sizeof case_other_names / sizeof case_other_names[0]; i++) {
        if (strcmp(key, case_other_names[i][0]) != 0) continue;
        for (int k = 0; k < count; k++)
            if (strcmp(allowed[k], case_other_names[i][1]) == 0) {
                snprintf(buf, size, "; did you mean \"%s\"?", allowed[k]);
                return;
            }
    }
    for (size_t i = 0; i < sizeof case_key_homes / sizeof case_key_homes[0]; i++)
        if (strcmp(key, case_key_homes[i][0]) == 0 && strcmp(ptr, case_key_homes[i][1]) != 0) {
            snprintf(buf, size, "; \"%s\" %s", key, case_key_homes[i][2]);
            return;
        }
}

int case_check_keys(case_doc *doc, const json_t *object, const char *ptr,
                    const char *const *allowed, const char *what)
{
    int count = 0, ok = 1;
    while (allowed[count]) count++;
    const char *key;
    json_t *value;
    json_object_foreach((json_t *)object, key, value) {
        int known = 0;
        for (int i = 0; i < count && !known; i++) known = strcmp(key, allowed[i]) == 0;
        if (known) continue;
        char at[CASE_POINTER], hint[96];
        pointer_join(at, sizeof at, ptr, key);
        case_did_you_mean(doc, hint, sizeof hint, key, allowed, count);
        if (!hint[0]) case_key_hint(hint, sizeof hint, key, ptr, allowed, count);
        case_problem(doc, at, "unknown key \"%.64s\" in %s%s", key, what, hint);
        ok = 0;
    }
    return ok;
}

int case_check_name_text(case_doc *doc, const char *name, const char *ptr, const char *what)
{
    const unsigned char *u = (const unsigned char *)name;
    for (size_t i = 0; u[i]; i++) {
        unsigned code = u[i];
        if (code == 0xC2 && u[i + 1] >= 0x80 && u[i + 1] <= 0x9F)
            code = u[i + 1]; /* U+0080..U+009F in UTF-8 */
        else if (code >= 0x20 && code != 0x7F)
            continue;
        case_problem(doc, ptr, "%s holds the control character U+%04X at byte %zu; names go "
                               "into result.xdmf and the daemon's log, so they must be printable "
                               "text", what, code, i);
        return 0;
    }
    return 1;
}
