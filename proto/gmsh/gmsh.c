/*
 * gmsh.c - reads the 3-node triangles (2D) or the 4-node tetrahedra (3D) of
 * an ASCII gmsh mesh (formats 2.2 and 4.1) into an engine mesh.
 *
 * The text arrives inside a JSON string from an untrusted upload, so the
 * reader works on a (pointer, length) buffer that need not be NUL-terminated,
 * never trusts a declared count more than the bytes left can hold, and
 * reports the section and line of the first thing it does not understand.
 * It reads line by line: gmsh writes one node or element per line, and a
 * line number is what a user needs to find the fault in the file.
 *
 * Nodes are kept in file order with their tags; elements of the wanted type
 * are kept as tags and resolved once every section has been read (via a
 * tag-sorted index), because tags may be non-contiguous and sections may
 * come in any order. The two dimensions differ only in the element type
 * kept (gmsh_kind) and whether z is read.
 */
#include "gmsh_internal.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const gmsh_kind gmsh_triangles = {
    2, 3, 2, "triangle",
    "no 3-node triangles (element type 2) in $Elements; mesh the surfaces in 2D (gmsh -2)", 9,
    "only second-order 6-node triangles (element type 9) in $Elements; fdemd takes linear "
    "3-node ones: mesh with -order 1 (gmsh's default)", 4,
    "4-node tetrahedra (element type 4) in $Elements: this is a 3D mesh and the case is 2D; "
    "set \"dimension\": 3 at the top of the case (or mesh the surfaces only, gmsh -2)"};
static const gmsh_kind gmsh_tetrahedra = {
    4, 4, 3, "tetrahedron",
    "no 4-node tetrahedra (element type 4) in $Elements; mesh the volumes in 3D (gmsh -3)", 11,
    "only second-order 10-node tetrahedra (element type 11) in $Elements; fdemd takes linear "
    "4-node ones: mesh with -order 1 (gmsh's default)", 2,
    "no 4-node tetrahedra (element type 4) in $Elements, only 3-node triangles: this is a 2D "
    "mesh and the case has \"dimension\": 3; mesh the volumes in 3D (gmsh -3), or leave out "
    "\"dimension\": 3 for a 2D case"};

int gmsh_fail(gmsh_reader *r, const char *fmt, ...)
{
    if (r->failed) return -1;
    r->failed = 1;
    char what[400];
    va_list args;
    va_start(args, fmt);
    vsnprintf(what, sizeof what, fmt, args);
    va_end(args);
    char where[64] = "gmsh";
    if (r->section && r->line > 0)
        snprintf(where, sizeof where, "gmsh %s, line %d", r->section, r->line);
    else if (r->section)
        snprintf(where, sizeof where, "gmsh %s", r->section);
    else if (r->line > 0)
        snprintf(where, sizeof where, "gmsh line %d", r->line);
    snprintf(r->message, r->message_size, "%s: %s", where, what);
    return -1;
}

/* ------------------------------------------------------------------ lines */

/* Reads the next line into `out` (tokens point into the buffer). Returns 0,
 * or -1 at the end of the buffer. */
int gmsh_next_line(gmsh_reader *r, gmsh_line *out)
{
    if (r->p >= r->end) return -1;
    const char *start = r->p;
    const char *nl = memchr(start, '\n', (size_t)(r->end - start));
    const char *stop = nl ? nl : r->end;
    r->p = nl ? nl + 1 : r->end;
    r->line++;
    out->count = 0;
    const char *c = start;
    while (c < stop) {
        while (c < stop && (*c == ' ' || *c == '\t' || *c == '\r')) c++;
        if (c >= stop) break;
        const char *t = c;
        while (c < stop && *c != ' ' && *c != '\t' && *c != '\r') c++;
        if (out->count < GMSH_MAX_TOKENS) {
            out->tokens[out->count] = t;
            out->lengths[out->count] = (size_t)(c - t);
        }
        out->count++;
    }
    if (out->count > GMSH_MAX_TOKENS) out->count = GMSH_MAX_TOKENS;
    return 0;
}

/* The next line, which must exist: a missing one means a truncated file. */
int gmsh_need_line(gmsh_reader *r, gmsh_line *out, const char *what)
{
    if (gmsh_next_line(r, out) == 0) return 0;
    return gmsh_fail(r, "the file ends where %s was expected (truncated?)", what);
}

static int gmsh_token_is(const gmsh_line *l, int i, const char *word)
{
    return i < l->count && l->lengths[i] == strlen(word) &&
           memcmp(l->tokens[i], word, l->lengths[i]) == 0;
}

/* Copies token i into a NUL-terminated buffer for strtod/strtoll. */
static int gmsh_token_copy(const gmsh_line *l, int i, char *buf)
{
    if (i >= l->count || l->lengths[i] >= GMSH_TOKEN_CHARS) return -1;
    memcpy(buf, l->tokens[i], l->lengths[i]);
    buf[l->lengths[i]] = '\0';
    return 0;
}

int gmsh_token_long(const gmsh_line *l, int i, long long *out)
{
    char buf[GMSH_TOKEN_CHARS];
    if (gmsh_token_copy(l, i, buf) < 0) return -1;
    char *stop;
    errno = 0;
    long long v = strtoll(buf, &stop, 10);
    if (errno || stop == buf || *stop) return -1;
    *out = v;
    return 0;
}

static int gmsh_token_double(const gmsh_line *l, int i, double *out)
{
    char buf[GMSH_TOKEN_CHARS];
    if (gmsh_token_copy(l, i, buf) < 0) return -1;
    char *stop;
    double v = strtod(buf, &stop);
    if (stop == buf || *stop || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

/* Reads `n` integers from the start of a line; names them in the message. */
int gmsh_line_longs(gmsh_reader *r, const gmsh_line *l, long long *out, int n,
                           const char *what)
{
    if (l->count < n) return gmsh_fail(r, "expected %s, found %d value(s)", what, l->count);
    for (int i = 0; i < n; i++)
        if (gmsh_token_long(l, i, &out[i]) < 0)
            return gmsh_fail(r, "expected %s, value %d is not an integer", what, i + 1);
    return 0;
}

/* A declared count must be non-negative and fit in the rest of the buffer
 * (every item takes at least `min_bytes`), so a hostile header cannot make
 * us allocate more than the upload's size. */
int gmsh_check_count(gmsh_reader *r, long long count, long min_bytes, const char *what)
{
    if (count < 0) return gmsh_fail(r, "negative number of %s (%lld)", what, count);
    long long room = (long long)(r->end - r->p) / min_bytes + 1;
    if (count > room)
        return gmsh_fail(r, "declares %lld %s but the rest of the file is too short for that "
                            "(truncated?)", count, what);
    return 0;
}

/* --------------------------------------------------------------- storage */

int gmsh_grow(void **items, long *capacity, long need, size_t item_size)
{
    if (need <= *capacity) return 0;
    long capacity_new = *capacity ? *capacity : 64;
    while (capacity_new < need) capacity_new *= 2;
    void *grown = realloc(*items, (size_t)capacity_new * item_size);
    if (!grown) return -1;
    *items = grown;
    *capacity = capacity_new;
    return 0;
}

static int gmsh_push_node(gmsh_reader *r, long long tag)
{
    if (tag <= 0) return gmsh_fail(r, "node tag %lld is not positive", tag);
    if (gmsh_grow((void **)&r->nodes, &r->node_capacity, r->node_count + 1, sizeof *r->nodes))
        return gmsh_fail(r, "out of memory");
    r->nodes[r->node_count++] = (gmsh_node){tag, 0, 0, 0};
    return 0;
}

static int gmsh_push_element(gmsh_reader *r, const long long tags[4])
{
    if (gmsh_grow((void **)&r->elements, &r->element_capacity, r->element_count + 1,
                  sizeof *r->elements))
        return gmsh_fail(r, "out of memory");
    gmsh_element *e = &r->elements[r->element_count++];
    memcpy(e->tags, tags, sizeof e->tags);
    e->line = r->line;
    return 0;
}

/* Reads "x y [z ...]" from token `first` on; z only in 3D (2D ignores it). */
static int gmsh_line_xyz(gmsh_reader *r, const gmsh_line *l, int first, gmsh_node *node)
{
    int dims = r->kind->dims;
    if (l->count < first + dims) return gmsh_fail(r, "expected node coordinates x y z");
    if (gmsh_token_double(l, first, &node->x) < 0 || gmsh_token_double(l, first + 1, &node->y) < 0 ||
        (dims == 3 && gmsh_token_double(l, first + 2, &node->z) < 0))
        return gmsh_fail(r, "node coordinates must be finite numbers");
    return 0;
}

/* The node tags of a kept element from token `first` on. */
static int gmsh_line_element(gmsh_reader *r, const gmsh_line *l, int first)
{
    long long tags[4] = {0, 0, 0, 0};
    const gmsh_kind *kind = r->kind;
    if (l->count < first + kind->nodes)
        return gmsh_fail(r, "a %s needs %d node tags", kind->name, kind->nodes);
    for (int k = 0; k < kind->nodes; k++)
        if (gmsh_token_long(l, first + k, &tags[k]) < 0)
            return gmsh_fail(r, "%s node tag %d is not an integer", kind->name, k + 1);
    return gmsh_push_element(r, tags);
}

/* --------------------------------------------------------------- sections */

static int gmsh_read_format(gmsh_reader *r)
{
    gmsh_line l;
    if (gmsh_need_line(r, &l, "the version line") < 0) return -1;
    long long file_type = 0;
    if (l.count < 3 || gmsh_token_long(&l, 1, &file_type) < 0)
        return gmsh_fail(r, "expected \"version file-type data-size\"");
    if (file_type != 0)
        return gmsh_fail(r, "binary .msh files are not supported; save the mesh as ASCII "
                            "(gmsh -format msh22 or msh41, without -bin)");
    if (gmsh_token_is(&l, 0, "2.2"))
        r->version = 22;
    else if (gmsh_token_is(&l, 0, "4.1"))
        r->version = 41;
    else
        return gmsh_fail(r, "format version %.*s is not supported; use 2.2 or 4.1 "
                            "(gmsh -format msh22 or msh41)",
                         (int)(l.lengths[0] < 16 ? l.lengths[0] : 16), l.tokens[0]);
    return 0;
}

static int gmsh_read_nodes22(gmsh_reader *r)
{
    gmsh_line l;
    long long count;
    if (gmsh_need_line(r, &l, "the number of nodes") < 0) return -1;
    if (gmsh_line_longs(r, &l, &count, 1, "the number of nodes") < 0) return -1;
    if (gmsh_check_count(r, count, 8, "nodes") < 0) return -1;
    for (long long i = 0; i < count; i++) {
        long long tag;
        if (gmsh_need_line(r, &l, "a node") < 0) return -1;
        if (gmsh_line_longs(r, &l, &tag, 1, "a node number") < 0) return -1;
        if (gmsh_push_node(r, tag) < 0) return -1;
        if (gmsh_line_xyz(r, &l, 1, &r->nodes[r->node_count - 1]) < 0) return -1;
    }
    return 0;
}

/* 4.1: one block per entity, the block's tags first, then its coordinates
 * (followed by parametric coordinates, which we ignore). */
static int gmsh_read_node_block41(gmsh_reader *r, long long *total)
{
    gmsh_line l;
    long long head[4];
    if (gmsh_need_line(r, &l, "a node block header") < 0) return -1;
    if (gmsh_line_longs(r, &l, head, 4, "\"entityDim entityTag parametric numNodes\"") < 0)
        return -1;
    long long n = head[3];
    if (gmsh_check_count(r, n, 8, "nodes in the block") < 0) return -1;
    long first = r->node_count;
    for (long long i = 0; i < n; i++) {
        long long tag;
        if (gmsh_need_line(r, &l, "a node tag") < 0) return -1;
        if (gmsh_line_longs(r, &l, &tag, 1, "a node tag") < 0) return -1;
        if (gmsh_push_node(r, tag) < 0) return -1;
    }
    for (long long i = 0; i < n; i++) {
        if (gmsh_need_line(r, &l, "node coordinates") < 0) return -1;
        gmsh_node *node = &r->nodes[first + i];
        if (gmsh_line_xyz(r, &l, 0, node) < 0) return -1;
    }
    *total += n;
    return 0;
}

static int gmsh_read_nodes41(gmsh_reader *r)
{
    gmsh_line l;
    long long head[4];
    if (gmsh_need_line(r, &l, "the $Nodes header") < 0) return -1;
    if (gmsh_line_longs(r, &l, head, 4,
                        "\"numEntityBlocks numNodes minNodeTag maxNodeTag\"") < 0)
        return -1;
    if (gmsh_check_count(r, head[0], 8, "node blocks") < 0) return -1;
    if (gmsh_check_count(r, head[1], 8, "nodes") < 0) return -1;
    long long total = 0;
    for (long long b = 0; b < head[0]; b++)
        if (gmsh_read_node_block41(r, &total) < 0) return -1;
    if (total != head[1])
        return gmsh_fail(r, "the header declares %lld nodes but the blocks hold %lld",
                         head[1], total);
    return 0;
}

static int gmsh_read_elements22(gmsh_reader *r)
{
    gmsh_line l;
    long long count;
    if (gmsh_need_line(r, &l, "the number of elements") < 0) return -1;
    if (gmsh_line_longs(r, &l, &count, 1, "the number of elements") < 0) return -1;
    if (gmsh_check_count(r, count, 8, "elements") < 0) return -1;
    for (long long i = 0; i < count; i++) {
        long long head[3]; /* number, type, number of tags */
        if (gmsh_need_line(r, &l, "an element") < 0) return -1;
        if (gmsh_line_longs(r, &l, head, 3, "\"number type number-of-tags ...\"") < 0)
            return -1;
        int kept = head[1] == r->kind->type;
        r->quadratic_count += head[1] == r->kind->quadratic_type;
        r->other_count += head[1] == r->kind->other_type;
        if (!kept && !r->want_groups) continue;
        if (head[2] < 0 || head[2] > GMSH_MAX_TOKENS)
            return gmsh_fail(r, "bad number of element tags (%lld)", head[2]);
        if (kept && gmsh_line_element(r, &l, 3 + (int)head[2]) < 0) return -1;
        long long physical = 0; /* the first tag; 0: in no physical group */
        if (r->want_groups && head[2] > 0 && gmsh_token_long(&l, 3, &physical) < 0)
            return gmsh_fail(r, "element tag 1 is not an integer");
        if (physical != 0 &&
            gmsh_note_element(r, gmsh_type_dimension(head[1]), physical, &l, 3 + (int)head[2],
                              kept ? r->element_count - 1 : -1) < 0)
            return -1;
    }
    return 0;
}

static int gmsh_read_element_block41(gmsh_reader *r, long long *total)
{
    gmsh_line l;
    long long head[4];
    if (gmsh_need_line(r, &l, "an element block header") < 0) return -1;
    if (gmsh_line_longs(r, &l, head, 4, "\"entityDim entityTag elementType numElements\"") < 0)
        return -1;
    long long n = head[3];
    if (gmsh_check_count(r, n, 4, "elements in the block") < 0) return -1;
    int kept = head[2] == r->kind->type;
    if (head[2] == r->kind->quadratic_type) r->quadratic_count += n;
    if (head[2] == r->kind->other_type) r->other_count += n;
    if (r->want_groups && (head[0] < 0 || head[0] > 3))
        return gmsh_fail(r, "entity dimension %lld is not 0 to 3", head[0]);
    for (long long i = 0; i < n; i++) {
        if (gmsh_need_line(r, &l, "an element") < 0) return -1;
        if (kept && gmsh_line_element(r, &l, 1) < 0) return -1;
        if (r->want_groups && gmsh_note_element(r, (int)head[0], head[1], &l, 1,
                                                kept ? r->element_count - 1 : -1) < 0)
            return -1;
    }
    *total += n;
    return 0;
}

static int gmsh_read_elements41(gmsh_reader *r)
{
    gmsh_line l;
    long long head[4];
    if (gmsh_need_line(r, &l, "the $Elements header") < 0) return -1;
    if (gmsh_line_longs(r, &l, head, 4,
                        "\"numEntityBlocks numElements minElementTag maxElementTag\"") < 0)
        return -1;
    if (gmsh_check_count(r, head[0], 8, "element blocks") < 0) return -1;
    if (gmsh_check_count(r, head[1], 4, "elements") < 0) return -1;
    long long total = 0;
    for (long long b = 0; b < head[0]; b++)
        if (gmsh_read_element_block41(r, &total) < 0) return -1;
    if (total != head[1])
        return gmsh_fail(r, "the header declares %lld elements but the blocks hold %lld",
                         head[1], total);
    return 0;
}

/* After a section's content: the matching "$EndName" line. */
static int gmsh_expect_end(gmsh_reader *r, const char *end_word)
{
    gmsh_line l;
    if (gmsh_need_line(r, &l, end_word) < 0) return -1;
    if (l.count != 1 || !gmsh_token_is(&l, 0, end_word))
        return gmsh_fail(r, "expected %s (more entries than the declared count?)", end_word);
    return 0;
}

/* Sections we do not need ($Entities, $PhysicalNames, ...) are skipped. */
static int gmsh_skip_section(gmsh_reader *r, const gmsh_line *start)
{
    char end_word[GMSH_TOKEN_CHARS + 4];
    snprintf(end_word, sizeof end_word, "$End%.*s", (int)(start->lengths[0] - 1),
             start->tokens[0] + 1);
    gmsh_line l;
    while (gmsh_next_line(r, &l) == 0)
        if (l.count == 1 && gmsh_token_is(&l, 0, end_word)) return 0;
    return gmsh_fail(r, "the file ends before %s (truncated?)", end_word);
}

static int gmsh_read_section(gmsh_reader *r, const gmsh_line *l)
{
    if (gmsh_token_is(l, 0, "$MeshFormat")) {
        if (r->version) return gmsh_fail(r, "a second $MeshFormat section");
        r->section = "$MeshFormat";
        if (gmsh_read_format(r) < 0) return -1;
        return gmsh_expect_end(r, "$EndMeshFormat");
    }
    if (!r->version)
        return gmsh_fail(r, "not a gmsh mesh: the file must start with $MeshFormat");
    if (gmsh_token_is(l, 0, "$Nodes")) {
        if (r->seen_nodes++) return gmsh_fail(r, "a second $Nodes section");
        r->section = "$Nodes";
        if ((r->version == 22 ? gmsh_read_nodes22(r) : gmsh_read_nodes41(r)) < 0) return -1;
        return gmsh_expect_end(r, "$EndNodes");
    }
    if (gmsh_token_is(l, 0, "$Elements")) {
        if (r->seen_elements++) return gmsh_fail(r, "a second $Elements section");
        r->section = "$Elements";
        if ((r->version == 22 ? gmsh_read_elements22(r) : gmsh_read_elements41(r)) < 0)
            return -1;
        return gmsh_expect_end(r, "$EndElements");
    }
    if (r->want_groups && gmsh_token_is(l, 0, "$PhysicalNames")) {
        r->section = "$PhysicalNames";
        if (gmsh_read_physical_names(r) < 0) return -1;
        return gmsh_expect_end(r, "$EndPhysicalNames");
    }
    if (r->want_groups && r->version == 41 && gmsh_token_is(l, 0, "$Entities")) {
        r->section = "$Entities";
        if (gmsh_read_entities(r) < 0) return -1;
        return gmsh_expect_end(r, "$EndEntities");
    }
    r->section = NULL;
    return gmsh_skip_section(r, l);
}

static int gmsh_read_sections(gmsh_reader *r)
{
    gmsh_line l;
    while (gmsh_next_line(r, &l) == 0) {
        r->section = NULL;
        if (l.count == 0) continue;
        if (l.lengths[0] < 2 || l.tokens[0][0] != '$' || l.count != 1) {
            if (!r->version)
                return gmsh_fail(r, "not a gmsh mesh: the file must start with $MeshFormat");
            return gmsh_fail(r, "expected a section such as $Nodes, found \"%.*s\"",
                             (int)(l.lengths[0] < 32 ? l.lengths[0] : 32), l.tokens[0]);
        }
        if (gmsh_read_section(r, &l) < 0) return -1;
    }
    r->section = NULL;
    if (!r->version) return gmsh_fail(r, "not a gmsh mesh: no $MeshFormat section");
    if (!r->seen_nodes) return gmsh_fail(r, "no $Nodes section");
    if (!r->seen_elements) return gmsh_fail(r, "no $Elements section");
    /* A 2D case given a 3D file would keep its surface triangles, flattened
     * onto z = 0 and overlapping: refuse it whole rather than let the mesh
     * check report a "zero area" triangle of a wall. A 3D case given a 2D
     * file has no tetrahedra at all: say it is the dimension, not the mesher. */
    if (r->kind->dims == 2 && r->other_count > 0) return gmsh_fail(r, "%s", r->kind->other);
    if (r->element_count == 0)
        return gmsh_fail(r, "%s", r->quadratic_count ? r->kind->only_quadratic
                                  : r->other_count   ? r->kind->other
                                                     : r->kind->missing);
    return 0;
}

/* --------------------------------------------------------------- resolve */

/* Sorts indices, stably, by `before`. qsort_r is a GNU extension and qsort
 * would need the reader in a global, so a small merge sort it is. */
typedef int (*gmsh_before_fn)(const gmsh_reader *r, long a, long b);

static void gmsh_merge_sort(long *idx, long *tmp, long n, const gmsh_reader *r,
                            gmsh_before_fn before)
{
    if (n < 2) return;
    long half = n / 2;
    gmsh_merge_sort(idx, tmp, half, r, before);
    gmsh_merge_sort(idx + half, tmp, n - half, r, before);
    long i = 0, j = half, k = 0;
    while (i < half && j < n)
        tmp[k++] = before(r, idx[j], idx[i]) ? idx[j++] : idx[i++];
    while (i < half) tmp[k++] = idx[i++];
    while (j < n) tmp[k++] = idx[j++];
    memcpy(idx, tmp, (size_t)n * sizeof *idx);
}

static int gmsh_node_before(const gmsh_reader *r, long a, long b)
{
    return r->nodes[a].tag < r->nodes[b].tag;
}

long gmsh_find_tag(const long *sorted, long n, const gmsh_node *nodes, long long tag)
{
    long lo = 0, hi = n - 1;
    while (lo <= hi) {
        long mid = lo + (hi - lo) / 2;
        long long t = nodes[sorted[mid]].tag;
        if (t == tag) return sorted[mid];
        if (t < tag) lo = mid + 1; else hi = mid - 1;
    }
    return -1;
}

/* Element t's node tags, ascending (a fourth of 0 for a triangle). */
static void gmsh_element_key(const gmsh_reader *r, long t, long long key[4])
{
    int per = r->kind->nodes;
    for (int k = 0; k < 4; k++) key[k] = k < per ? r->elements[t].tags[k] : 0;
    for (int i = 1; i < per; i++)
        for (int k = i; k > 0 && key[k - 1] > key[k]; k--) {
            long long s = key[k];
            key[k] = key[k - 1];
            key[k - 1] = s;
        }
}

static int gmsh_element_before(const gmsh_reader *r, long a, long b)
{
    long long ka[4], kb[4];
    gmsh_element_key(r, a, ka);
    gmsh_element_key(r, b, kb);
    for (int k = 0; k < 4; k++)
        if (ka[k] != kb[k]) return ka[k] < kb[k];
    return a < b;
}

/* 2.2 writes an element once for each physical group it is in: every
 * repeat of a node set becomes the element of its first occurrence.
 * element_of[t] is the mesh index of kept element t; returns how many
 * distinct elements there are, or -1 when out of memory. */
static long gmsh_merge_repeats(const gmsh_reader *r, long *element_of)
{
    long m = r->element_count;
    long *order = malloc((size_t)(m ? m : 1) * sizeof *order);
    long *tmp = malloc((size_t)(m ? m : 1) * sizeof *tmp);
    if (!order || !tmp) {
        free(order);
        free(tmp);
        return -1;
    }
    for (long t = 0; t < m; t++) order[t] = t, element_of[t] = t;
    gmsh_merge_sort(order, tmp, m, r, gmsh_element_before);
    long long prev[4], key[4];
    for (long i = 0; i < m; i++) {
        gmsh_element_key(r, order[i], key);
        if (i > 0 && memcmp(key, prev, sizeof key) == 0) element_of[order[i]] = element_of[order[i - 1]];
        memcpy(prev, key, sizeof key);
    }
    long distinct = 0; /* first occurrences keep file order */
    for (long t = 0; t < m; t++) element_of[t] = element_of[t] == t ? distinct++ : -1 - element_of[t];
    for (long t = 0; t < m; t++)
        if (element_of[t] < 0) element_of[t] = element_of[-1 - element_of[t]];
    free(order);
    free(tmp);
    return distinct;
}

/* The resolved mesh in plain arrays: dims coordinates per node, the
 * kind's node count per element. */
typedef struct gmsh_arrays {
    double *coords;
    int32_t *elements;
    int node_count, element_count;
} gmsh_arrays;

/* Keeps only the nodes some element uses, renumbered in file order. */
static int gmsh_resolve(gmsh_reader *r, gmsh_arrays *out, gmsh_groups *groups)
{
    long n = r->node_count, m = r->element_count;
    const int per = r->kind->nodes, dims = r->kind->dims;
    if (n > INT32_MAX || m > INT32_MAX / per) return gmsh_fail(r, "the mesh is too large");
    long *sorted = malloc((size_t)(n ? n : 1) * sizeof *sorted);
    long *tmp = malloc((size_t)(n ? n : 1) * sizeof *tmp);
    long *file_index = malloc((size_t)m * per * sizeof *file_index);
    int32_t *renumber = malloc((size_t)(n ? n : 1) * sizeof *renumber);
    long *element_of = malloc((size_t)(m ? m : 1) * sizeof *element_of);
    int rc = -1;
    long distinct = element_of ? gmsh_merge_repeats(r, element_of) : -1;
    if (!sorted || !tmp || !file_index || !renumber || distinct < 0) {
        gmsh_fail(r, "out of memory");
        goto done;
    }
    for (long i = 0; i < n; i++) sorted[i] = i;
    gmsh_merge_sort(sorted, tmp, n, r, gmsh_node_before);
    for (long i = 1; i < n; i++)
        if (r->nodes[sorted[i]].tag == r->nodes[sorted[i - 1]].tag) {
            r->section = "$Nodes";
            r->line = 0;
            gmsh_fail(r, "node tag %lld is defined twice", r->nodes[sorted[i]].tag);
            goto done;
        }
    for (long i = 0; i < n; i++) renumber[i] = -1;
    for (long t = 0; t < m; t++)
        for (int k = 0; k < per; k++) {
            long found = gmsh_find_tag(sorted, n, r->nodes, r->elements[t].tags[k]);
            if (found < 0) {
                r->section = "$Elements";
                r->line = r->elements[t].line;
                gmsh_fail(r, "the %s refers to node %lld, which is not in $Nodes",
                          r->kind->name, r->elements[t].tags[k]);
                goto done;
            }
            file_index[(long)per * t + k] = found;
            renumber[found] = 0;
        }
    int used = 0;
    for (long i = 0; i < n; i++)
        if (renumber[i] == 0) renumber[i] = used++;
    out->coords = malloc((size_t)(used ? used : 1) * dims * sizeof *out->coords);
    out->elements = malloc((size_t)distinct * per * sizeof *out->elements);
    if (!out->coords || !out->elements) {
        free(out->coords);
        free(out->elements);
        memset(out, 0, sizeof *out);
        gmsh_fail(r, "out of memory");
        goto done;
    }
    for (long i = 0; i < n; i++)
        if (renumber[i] >= 0) {
            double xyz[3] = {r->nodes[i].x, r->nodes[i].y, r->nodes[i].z};
            memcpy(out->coords + (size_t)dims * renumber[i], xyz, (size_t)dims * sizeof *xyz);
        }
    for (long t = 0; t < m; t++)
        for (int k = 0; k < per; k++)
            out->elements[per * element_of[t] + k] = renumber[file_index[per * t + k]];
    out->node_count = used;
    out->element_count = (int)distinct;
    rc = 0;
    if (groups && gmsh_resolve_groups(r, sorted, renumber, element_of, groups) < 0) {
        free(out->coords);
        free(out->elements);
        memset(out, 0, sizeof *out);
        rc = -1;
    }
done:
    free(sorted);
    free(tmp);
    free(file_index);
    free(renumber);
    free(element_of);
    return rc;
}

static int gmsh_read_kind(const char *text, size_t length, const gmsh_kind *kind,
                          gmsh_arrays *out, gmsh_groups *groups, char *message,
                          size_t message_size)
{
    char scratch[8];
    memset(out, 0, sizeof *out);
    if (groups) memset(groups, 0, sizeof *groups);
    gmsh_reader r = {0};
    if (!text) text = "", length = 0;
    r.p = text;
    r.end = text + length;
    r.kind = kind;
    r.want_groups = groups != NULL;
    r.message = message && message_size ? message : scratch;
    r.message_size = message && message_size ? message_size : sizeof scratch;
    r.message[0] = '\0';
    int rc = gmsh_read_sections(&r);
    if (rc == 0) rc = gmsh_resolve(&r, out, groups);
    free(r.nodes);
    free(r.elements);
    gmsh_reader_free_groups(&r);
    return rc;
}

int gmsh_read_grouped(const char *text, size_t length, fdem_mesh *out, gmsh_groups *groups,
                      char *message, size_t message_size)
{
    gmsh_arrays a;
    memset(out, 0, sizeof *out);
    if (gmsh_read_kind(text, length, &gmsh_triangles, &a, groups, message, message_size) != 0)
        return -1;
    out->xy = a.coords;
    out->tri = a.elements;
    out->node_count = a.node_count;
    out->triangle_count = a.element_count;
    return 0;
}

int gmsh_read_tetrahedra_grouped(const char *text, size_t length, fdem_tet_mesh *out,
                                 gmsh_groups *groups, char *message, size_t message_size)
{
    gmsh_arrays a;
    memset(out, 0, sizeof *out);
    if (gmsh_read_kind(text, length, &gmsh_tetrahedra, &a, groups, message, message_size) != 0)
        return -1;
    out->xyz = a.coords;
    out->tet = a.elements;
    out->node_count = a.node_count;
    out->tet_count = a.element_count;
    return 0;
}

int gmsh_read(const char *text, size_t length, fdem_mesh *out, char *message,
              size_t message_size)
{
    return gmsh_read_grouped(text, length, out, NULL, message, message_size);
}

int gmsh_read_tetrahedra(const char *text, size_t length, fdem_tet_mesh *out, char *message,
                         size_t message_size)
{
    return gmsh_read_tetrahedra_grouped(text, length, out, NULL, message, message_size);
}
