/*
 * boundary_facets.c - the facets of a mesh that are seen: outer surfaces
 * and crack faces (boundary_facets.h).
 *
 * One open-addressing table keyed by each facet's sorted node ids finds
 * the twins (the same nodes in two elements) and the facet under each
 * joint side in time linear in the mesh: a sort of the 4e5 faces of 1e5
 * tetrahedra took several times longer, and the page asks for a frame at
 * every snapshot. Both dimensions are one code; only the local facet
 * tables differ.
 */
#include "boundary_facets.h"

#include <stdlib.h>
#include <string.h>

#include "math/node_ids.h"

/* Each facet's local nodes, listed so that its normal (right-hand rule in
 * 3D, the edge's right side in 2D) points out of a positive element. */
static const int facet_local_2d[3][2] = {{0, 1}, {1, 2}, {2, 0}};
static const int facet_local_3d[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

void facet_nodes(int dimension, const int32_t *cells, int32_t f, int32_t *nodes)
{
    int per = dimension + 1;
    const int32_t *cell = cells + (size_t)(f / per) * (size_t)per;
    for (int i = 0; i < dimension; i++)
        nodes[i] = cell[dimension == 3 ? facet_local_3d[f % per][i] : facet_local_2d[f % per][i]];
}

/* ------------------------------------------------------------ the table */

typedef struct facet_table {
    int dimension;
    uint32_t mask;      /* size - 1, size a power of two at least twice the facets */
    int32_t *slot;      /* facet index, or -1 */
    const int32_t *key; /* each facet's sorted node ids, 3 per facet */
} facet_table;

static uint32_t facet_hash(const int32_t *key, int n)
{
    uint32_t h = 2166136261u;
    for (int i = 0; i < n; i++)
        h = (h ^ (uint32_t)key[i]) * 16777619u;
    return h ^ (h >> 15);
}

static void facet_key(int dimension, const int32_t *cells, int32_t f, int32_t *key)
{
    key[2] = -1; /* an edge's third id, so that every key compares as three */
    facet_nodes(dimension, cells, f, key);
    node_ids_sort(key, dimension);
}

/* The slot holding the facet with these sorted nodes, or the empty slot
 * where it would go. */
static uint32_t facet_find(const facet_table *t, const int32_t *key)
{
    uint32_t h = facet_hash(key, t->dimension) & t->mask;
    for (;;) {
        int32_t f = t->slot[h];
        if (f < 0 || node_ids_compare(key, t->key + 3 * (size_t)f, 3) == 0)
            return h;
        h = (h + 1) & t->mask;
    }
}

static uint32_t facet_table_size(int facets)
{
    uint32_t size = 16;
    while (size < 2u * (uint32_t)facets)
        size <<= 1;
    return size;
}

/* ------------------------------------------------------------- building */

size_t facet_map_bytes(int dimension, int elements, int joints)
{
    size_t facets = (size_t)(dimension + 1) * (size_t)elements;
    return sizeof(int32_t) * (5 * facets + 2 * (size_t)joints + facet_table_size((int)facets));
}

void facet_map_free(facet_map *m)
{
    free(m->twin);
    free(m->joint);
    free(m->joint_facet);
    memset(m, 0, sizeof *m);
}

/* Twins: the first facet with a key keeps the slot, a second one with the
 * same key is paired with it (a valid mesh has no third). */
static void facet_map_twins(facet_map *m, facet_table *t, int facets)
{
    for (int32_t f = 0; f < facets; f++) {
        uint32_t h = facet_find(t, t->key + 3 * (size_t)f);
        int32_t first = t->slot[h];
        if (first < 0) {
            t->slot[h] = f;
        } else if (m->twin[first] < 0) {
            m->twin[first] = f;
            m->twin[f] = first;
        }
    }
}

static void facet_map_joints(facet_map *m, const facet_table *t, const int32_t *joint_nodes)
{
    int d = m->dimension;
    for (int j = 0; j < m->joints; j++)
        for (int side = 0; side < 2; side++) {
            int32_t key[3] = {-1, -1, -1};
            memcpy(key, joint_nodes + (size_t)j * 2 * d + side * d, sizeof(int32_t) * d);
            node_ids_sort(key, d);
            int32_t f = t->slot[facet_find(t, key)];
            m->joint_facet[2 * j + side] = f;
            if (f >= 0)
                m->joint[f] = j;
        }
}

static int ids_valid(const int32_t *ids, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (ids[i] < 0)
            return 0;
    return 1;
}

int facet_map_build(facet_map *m, int dimension, int elements, const int32_t *cells, int joints,
                    const int32_t *joint_nodes)
{
    memset(m, 0, sizeof *m);
    int facets = (dimension + 1) * elements;
    if ((dimension != 2 && dimension != 3) || elements < 0 || joints < 0 ||
        !ids_valid(cells, (size_t)elements * (size_t)(dimension + 1)) ||
        !ids_valid(joint_nodes, (size_t)joints * 2 * (size_t)dimension))
        return -1;
    m->dimension = dimension;
    m->elements = elements;
    m->joints = joints;
    facet_table t = {dimension, facet_table_size(facets) - 1, NULL, NULL};
    int32_t *key = malloc(sizeof(int32_t) * 3 * (size_t)(facets ? facets : 1));
    m->twin = malloc(sizeof(int32_t) * (size_t)(facets ? facets : 1));
    m->joint = malloc(sizeof(int32_t) * (size_t)(facets ? facets : 1));
    m->joint_facet = malloc(sizeof(int32_t) * (size_t)(joints ? 2 * joints : 1));
    t.slot = malloc(sizeof(int32_t) * ((size_t)t.mask + 1));
    if (!key || !m->twin || !m->joint || !m->joint_facet || !t.slot) {
        free(key);
        free(t.slot);
        facet_map_free(m);
        return -1;
    }
    for (int32_t f = 0; f < facets; f++)
        facet_key(dimension, cells, f, key + 3 * (size_t)f);
    t.key = key;
    memset(t.slot, 0xff, sizeof(int32_t) * ((size_t)t.mask + 1)); /* -1 everywhere */
    memset(m->twin, 0xff, sizeof(int32_t) * (size_t)facets);
    memset(m->joint, 0xff, sizeof(int32_t) * (size_t)facets);
    facet_map_twins(m, &t, facets);
    facet_map_joints(m, &t, joint_nodes);
    free(t.slot);
    free(key);
    return 0;
}

/* ------------------------------------------------------------- choosing */

static int element_there(const facet_map *m, const unsigned char *active, int32_t f)
{
    return f >= 0 && (!active || active[f / (m->dimension + 1)]);
}

int facet_map_boundary(const facet_map *m, const unsigned char *broken,
                       const unsigned char *active, int32_t *out)
{
    int per = m->dimension + 1, facets = per * m->elements, count = 0;
    for (int32_t f = 0; f < facets; f++) {
        if (!element_there(m, active, f) || element_there(m, active, m->twin[f]))
            continue;
        int32_t j = m->joint[f];
        if (j >= 0 && !(broken && broken[j])) {
            int32_t other = m->joint_facet[2 * j] == f ? m->joint_facet[2 * j + 1]
                                                       : m->joint_facet[2 * j];
            if (element_there(m, active, other))
                continue; /* held by an intact joint to an element still there */
        }
        out[count++] = f;
    }
    return count;
}
