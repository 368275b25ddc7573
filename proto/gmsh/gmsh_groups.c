/*
 * gmsh_groups.c - the physical groups of a gmsh file (contract 5.3: bonded
 * materials, joint sets and node selections by name): $PhysicalNames, the
 * physical tags of 4.1 entities ($Entities), and which elements of any
 * dimension (points, lines, surfaces, volumes) belong to which group.
 *
 * The two formats say it differently. 2.2 gives every element its physical
 * tag (the first of its tags) and writes an element once per group it is
 * in; 4.1 gives elements an entity, and the entity lists its physical tags.
 * While reading, gmsh.c hands every element that may matter to
 * gmsh_note_element with the key its format has (physical or entity tag);
 * once the mesh is renumbered, gmsh_resolve_groups turns the keys into
 * groups and the node tags into the mesh's node and element indices.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gmsh_internal.h"

/* ------------------------------------------------------------ reading */

/* pool[first ..]; NULL while the pool is empty (then nothing is read). */
static const long long *pool_at(const gmsh_reader *r, long first)
{
    return r->pool ? r->pool + first : NULL;
}

static int pool_push(gmsh_reader *r, long long value)
{
    if (gmsh_grow((void **)&r->pool, &r->pool_capacity, r->pool_count + 1, sizeof *r->pool))
        return gmsh_fail(r, "out of memory");
    r->pool[r->pool_count++] = value;
    return 0;
}

/* "dim tag \"name\"": the name runs from the first quote to the last one
 * of the line (it may hold spaces). */
static int read_physical_name(gmsh_reader *r, const gmsh_line *l)
{
    long long head[2];
    if (gmsh_line_longs(r, l, head, 2, "\"dimension tag \\\"name\\\"\"") < 0) return -1;
    if (head[0] < 0 || head[0] > 3)
        return gmsh_fail(r, "physical dimension %lld is not 0 to 3", head[0]);
    if (l->count < 3 || l->count >= GMSH_MAX_TOKENS || l->tokens[2][0] != '"')
        return gmsh_fail(r, "expected a quoted physical name after the tag");
    const char *begin = l->tokens[2] + 1;
    const char *end = l->tokens[l->count - 1] + l->lengths[l->count - 1] - 1;
    if (end < begin || *end != '"') return gmsh_fail(r, "the physical name has no closing quote");
    size_t length = (size_t)(end - begin);
    if (length == 0 || length >= GMSH_NAME)
        return gmsh_fail(r, "a physical name must be 1 to %d characters", GMSH_NAME - 1);
    if (gmsh_grow((void **)&r->physicals, &r->physical_capacity, r->physical_count + 1,
                  sizeof *r->physicals))
        return gmsh_fail(r, "out of memory");
    gmsh_physical *p = &r->physicals[r->physical_count++];
    p->dim = (int)head[0];
    p->tag = head[1];
    memcpy(p->name, begin, length);
    p->name[length] = '\0';
    return 0;
}

int gmsh_read_physical_names(gmsh_reader *r)
{
    gmsh_line l;
    long long count;
    if (gmsh_need_line(r, &l, "the number of physical names") < 0) return -1;
    if (gmsh_line_longs(r, &l, &count, 1, "the number of physical names") < 0) return -1;
    if (gmsh_check_count(r, count, 6, "physical names") < 0) return -1;
    for (long long i = 0; i < count; i++) {
        if (gmsh_need_line(r, &l, "a physical name") < 0) return -1;
        if (read_physical_name(r, &l) < 0) return -1;
    }
    return 0;
}

/* One entity line: "tag coordinates... numPhysicalTags tags... [bounding]";
 * a point has 3 coordinates, the others a box of 6. */
static int read_entity(gmsh_reader *r, const gmsh_line *l, int dim)
{
    int at = 1 + (dim == 0 ? 3 : 6);
    long long tag, count;
    if (l->count >= GMSH_MAX_TOKENS)
        return gmsh_fail(r, "an entity line with more than %d values", GMSH_MAX_TOKENS - 1);
    if (gmsh_token_long(l, 0, &tag) < 0 || gmsh_token_long(l, at, &count) < 0 || count < 0 ||
        count > l->count - at - 1)
        return gmsh_fail(r, "expected \"tag %s numPhysicalTags physicalTags...\"",
                         dim == 0 ? "x y z" : "box");
    if (gmsh_grow((void **)&r->entities, &r->entity_capacity, r->entity_count + 1,
                  sizeof *r->entities))
        return gmsh_fail(r, "out of memory");
    gmsh_entity *e = &r->entities[r->entity_count++];
    *e = (gmsh_entity){dim, tag, r->pool_count, count};
    for (long long k = 0; k < count; k++) {
        long long physical;
        if (gmsh_token_long(l, at + 1 + (int)k, &physical) < 0)
            return gmsh_fail(r, "physical tag %lld of the entity is not an integer", k + 1);
        if (pool_push(r, physical < 0 ? -physical : physical) < 0) return -1;
    }
    return 0;
}

int gmsh_read_entities(gmsh_reader *r)
{
    gmsh_line l;
    long long count[4];
    if (gmsh_need_line(r, &l, "the $Entities header") < 0) return -1;
    if (gmsh_line_longs(r, &l, count, 4, "\"numPoints numCurves numSurfaces numVolumes\"") < 0)
        return -1;
    for (int dim = 0; dim < 4; dim++) {
        if (gmsh_check_count(r, count[dim], 8, "entities") < 0) return -1;
        for (long long i = 0; i < count[dim]; i++) {
            if (gmsh_need_line(r, &l, "an entity") < 0) return -1;
            if (read_entity(r, &l, dim) < 0) return -1;
        }
    }
    return 0;
}

int gmsh_type_dimension(long long type)
{
    switch (type) {
    case 15: return 0;                                     /* point */
    case 1: case 8: case 26: case 27: case 28: return 1;   /* lines */
    case 2: case 3: case 9: case 10: case 16: case 20: case 21: case 22: case 23: case 24:
    case 25: return 2;                                     /* triangles, quadrangles */
    case 4: case 5: case 6: case 7: case 11: case 12: case 13: case 14: case 17: case 18:
    case 19: case 29: case 30: case 31: case 92: case 93: return 3;
    default: return -1;
    }
}

int gmsh_note_element(gmsh_reader *r, int dim, long long key, const gmsh_line *l, int first,
                      long kept)
{
    if (dim < 0) return 0; /* a type we cannot place in a dimension is in no group */
    if (gmsh_grow((void **)&r->members, &r->member_capacity, r->member_count + 1,
                  sizeof *r->members))
        return gmsh_fail(r, "out of memory");
    gmsh_member *e = &r->members[r->member_count++];
    *e = (gmsh_member){dim, key, kept, r->pool_count, 0};
    if (kept >= 0) return 0; /* its nodes are the kept element's */
    if (first >= l->count) /* more tags declared than the line holds, or no nodes */
        return gmsh_fail(r, "the element's line ends before its node tags");
    for (int k = first; k < l->count; k++) {
        long long tag;
        if (gmsh_token_long(l, k, &tag) < 0)
            return gmsh_fail(r, "node tag %d of the element is not an integer", k - first + 1);
        if (pool_push(r, tag) < 0) return -1;
        e->count++;
    }
    return 0;
}

void gmsh_reader_free_groups(gmsh_reader *r)
{
    free(r->members);
    free(r->pool);
    free(r->physicals);
    free(r->entities);
}

void gmsh_groups_free(gmsh_groups *groups)
{
    if (!groups) return;
    for (int g = 0; g < groups->count; g++) {
        free(groups->group[g].nodes);
        free(groups->group[g].elements);
        free(groups->group[g].faces);
    }
    free(groups->group);
    groups->group = NULL;
    groups->count = 0;
}

/* ---------------------------------------------------------- resolving */

/* Growable int32 lists of a group while it is filled. */
typedef struct group_lists {
    long node_cap, element_cap, face_cap;
} group_lists;

static int push32(int32_t **items, int *count, long *capacity, int32_t value)
{
    if (gmsh_grow((void **)items, capacity, (long)*count + 1, sizeof **items)) return -1;
    (*items)[(*count)++] = value;
    return 0;
}

static int int32_compare(const void *pa, const void *pb)
{
    int32_t a = *(const int32_t *)pa, b = *(const int32_t *)pb;
    return (a > b) - (a < b);
}

/* Sorts a list and drops repeats. */
static int sort_unique(int32_t *items, int count)
{
    if (count == 0) return 0;
    qsort(items, (size_t)count, sizeof *items, int32_compare);
    int kept = 1;
    for (int i = 1; i < count; i++)
        if (items[i] != items[kept - 1]) items[kept++] = items[i];
    return kept;
}

/* The named group of (dim, physical tag), or -1. */
static int group_of(const gmsh_reader *r, int dim, long long physical)
{
    for (long p = 0; p < r->physical_count; p++)
        if (r->physicals[p].dim == dim && r->physicals[p].tag == physical) return (int)p;
    return -1;
}

/* Adds member e's nodes (and its element or face) to group g. */
static int group_add_member(gmsh_reader *r, const gmsh_member *e, gmsh_group *g,
                            group_lists *lists, const long *sorted, const int32_t *renumber,
                            const long *element_of)
{
    const long long *tags = e->kept >= 0 ? r->elements[e->kept].tags : pool_at(r, e->first);
    int count = e->kept >= 0 ? r->kind->nodes : (int)e->count;
    int32_t face[4];
    int on_mesh = 1;
    for (int k = 0; k < count; k++) {
        long found = gmsh_find_tag(sorted, r->node_count, r->nodes, tags[k]);
        int32_t node = found >= 0 ? renumber[found] : -1;
        if (k < 4) face[k] = node;
        if (node < 0) { /* a node no kept element uses: not a node of this mesh */
            on_mesh = 0;
            continue;
        }
        if (push32(&g->nodes, &g->node_count, &lists->node_cap, node)) return -1;
    }
    int top = r->kind->dims;
    if (e->kept >= 0 && e->dim == top &&
        push32(&g->elements, &g->element_count, &lists->element_cap, (int32_t)element_of[e->kept]))
        return -1;
    if (e->dim == top - 1 && count == top && on_mesh)
        for (int k = 0; k < top; k++)
            if (push32(&g->faces, &g->face_count, &lists->face_cap, face[k])) return -1;
    return 0;
}

/* The physical tags of member e: its own (2.2) or its entity's (4.1). */
static const long long *member_physicals(const gmsh_reader *r, const gmsh_member *e,
                                         long *count)
{
    if (r->version != 41) {
        *count = 1;
        return &e->key;
    }
    for (long k = 0; k < r->entity_count; k++)
        if (r->entities[k].dim == e->dim && r->entities[k].tag == e->key) {
            *count = r->entities[k].count;
            return pool_at(r, r->entities[k].first);
        }
    *count = 0;
    return NULL;
}

int gmsh_resolve_groups(gmsh_reader *r, const long *sorted, const int32_t *renumber,
                        const long *element_of, gmsh_groups *out)
{
    long n = r->physical_count;
    out->group = calloc((size_t)(n ? n : 1), sizeof *out->group);
    group_lists *lists = calloc((size_t)(n ? n : 1), sizeof *lists);
    if (!out->group || !lists) {
        free(lists);
        return gmsh_fail(r, "out of memory");
    }
    out->count = (int)n;
    for (long p = 0; p < n; p++) {
        out->group[p].dim = r->physicals[p].dim;
        memcpy(out->group[p].name, r->physicals[p].name, GMSH_NAME);
    }
    int rc = 0;
    /* members come in runs of one entity (one physical tag in 2.2): look
     * their groups up once a run */
    const gmsh_member *last = NULL;
    long count = 0;
    const long long *physicals = NULL;
    for (long i = 0; rc == 0 && n > 0 && i < r->member_count; i++) {
        const gmsh_member *e = &r->members[i];
        if (!last || last->dim != e->dim || last->key != e->key)
            physicals = member_physicals(r, e, &count);
        last = e;
        for (long k = 0; rc == 0 && k < count; k++) {
            int g = group_of(r, e->dim, physicals[k]);
            if (g >= 0)
                rc = group_add_member(r, e, &out->group[g], &lists[g], sorted, renumber,
                                      element_of);
        }
    }
    free(lists);
    if (rc < 0) {
        gmsh_groups_free(out);
        return gmsh_fail(r, "out of memory");
    }
    for (int g = 0; g < out->count; g++) {
        out->group[g].node_count = sort_unique(out->group[g].nodes, out->group[g].node_count);
        out->group[g].element_count =
            sort_unique(out->group[g].elements, out->group[g].element_count);
        out->group[g].face_count /= r->kind->dims;
    }
    return 0;
}
