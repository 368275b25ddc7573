/*
 * result_frame_shape.c - the mesh's shape in a web frame: the whole mesh,
 * or only the facets that can be seen (result_frame_internal.h).
 *
 * The surface form exists for 3D: of a 1e5-tetrahedron fracturing block's
 * 4e5 faces about 2 % are on its surface or on a crack, and a frame of
 * those faces, of the nodes and elements they touch and of the joints
 * around those elements is ~1 MB where the whole mesh is 20 MB; the page
 * no longer has to find the surface itself either. Which facets show is
 * core knowledge (analysis/boundary_facets.h); this file lists what they
 * touch and writes it as sections. Both forms carry each joint's two
 * elements, which the page colours damage and fluid by.
 */
#include "result_frame_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>


size_t frame_shape_bytes(int dimension, uint32_t nodes, uint32_t elements, uint32_t joints)
{
    size_t facets = (size_t)(dimension + 1) * elements;
    return facet_map_bytes(dimension, (int)elements, (int)joints) + sizeof(int32_t) * facets +
           2 * sizeof(uint32_t) * ((size_t)nodes + elements + joints);
}

/* Each joint's two elements, in the carried elements' numbering. */
static int shape_joint_elements(frame_build *b, const facet_map *m, const uint32_t *element_slot)
{
    uint32_t J = b->carry.count[CARRY_JOINTS], per = (uint32_t)b->dimension + 1;
    uint32_t *out = frame_add(b, "joint_elements", FRAME_AT_JOINT, 2, FRAME_U32, J, 1);
    if (!out)
        return -1;
    for (uint32_t i = 0; i < J; i++) {
        uint32_t j = b->carry.id[CARRY_JOINTS] ? b->carry.id[CARRY_JOINTS][i] : i;
        for (int side = 0; side < 2; side++) {
            int32_t f = m->joint_facet[2 * j + side];
            uint32_t e = f < 0 ? FRAME_NONE : (uint32_t)f / per;
            out[2 * i + side] = e == FRAME_NONE ? FRAME_NONE
                                : element_slot ? element_slot[e] : e;
        }
    }
    return 0;
}

/* The whole mesh: cells and joints as in /mesh, every item carried. */
static int shape_whole(frame_build *b, const facet_map *m, uint32_t E, uint32_t J,
                       const int32_t *cells, const int32_t *joint_nodes)
{
    uint32_t d = (uint32_t)b->dimension;
    void *c = frame_add(b, "cells", FRAME_AT_ELEMENT, d + 1, FRAME_U32, E, 1);
    void *j = frame_add(b, "joints", FRAME_AT_JOINT, 2 * d, FRAME_U32, J, 1);
    if (!c || !j)
        return -1;
    memcpy(c, cells, sizeof(int32_t) * (size_t)E * (d + 1));
    if (J)
        memcpy(j, joint_nodes, sizeof(int32_t) * (size_t)J * 2 * d);
    return shape_joint_elements(b, m, NULL);
}

/* Numbers the marked items 0, 1, ... in increasing order: slot[i] gets
 * the new number (FRAME_NONE when unmarked) and the list of their original
 * indices is returned (its length in *count); NULL when out of memory. */
static uint32_t *shape_number(uint32_t *slot, uint32_t items, uint32_t *count)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < items; i++)
        if (slot[i] != FRAME_NONE)
            slot[i] = n++;
    uint32_t *id = malloc(sizeof(uint32_t) * (n ? n : 1));
    if (!id)
        return NULL;
    for (uint32_t i = 0; i < items; i++)
        if (slot[i] != FRAME_NONE)
            id[slot[i]] = i;
    *count = n;
    return id;
}

/* The id lists of the carried items, as sections (for a reader that
 * wants to find them in result.h5). */
static int shape_ids(frame_build *b)
{
    static const char *const names[CARRY_KINDS] = {"node_id", "element_id", "joint_id"};
    static const uint32_t at[CARRY_KINDS] = {FRAME_AT_NODE, FRAME_AT_ELEMENT, FRAME_AT_JOINT};
    for (int k = 0; k < CARRY_KINDS; k++) {
        void *out = frame_add(b, names[k], at[k], 1, FRAME_U32, b->carry.count[k], 1);
        if (!out)
            return -1;
        memcpy(out, b->carry.id[k], sizeof(uint32_t) * b->carry.count[k]);
    }
    return 0;
}

/* The facets that show, and the nodes, elements and joints they touch. */
static int shape_surface(frame_build *b, const facet_map *m, uint32_t N, const int32_t *cells,
                         const unsigned char *broken, const unsigned char *active,
                         int32_t *facet, uint32_t *slot)
{
    uint32_t d = (uint32_t)b->dimension, per = d + 1, E = (uint32_t)m->elements;
    uint32_t J = (uint32_t)m->joints;
    int S = facet_map_boundary(m, broken, active, facet);
    /* the elements that own a facet shown, and the joints around them */
    uint32_t *elem = slot, *node = slot + E, *joint = slot + E + N;
    memset(slot, 0xff, sizeof(uint32_t) * ((size_t)E + N + J));
    for (int i = 0; i < S; i++)
        elem[(uint32_t)facet[i] / per] = 0;
    for (uint32_t j = 0; j < J; j++)
        for (int side = 0; side < 2; side++) {
            int32_t f = m->joint_facet[2 * j + side];
            if (f >= 0 && elem[(uint32_t)f / per] != FRAME_NONE)
                joint[j] = 0;
        }
    for (int i = 0; i < S; i++) {
        int32_t v[3];
        facet_nodes((int)d, cells, facet[i], v);
        for (uint32_t k = 0; k < d; k++)
            node[v[k]] = 0;
    }
    b->carry.id[CARRY_ELEMENTS] = shape_number(elem, E, &b->carry.count[CARRY_ELEMENTS]);
    b->carry.id[CARRY_NODES] = shape_number(node, N, &b->carry.count[CARRY_NODES]);
    b->carry.id[CARRY_JOINTS] = shape_number(joint, J, &b->carry.count[CARRY_JOINTS]);
    b->faces = (uint32_t)S;
    uint32_t *faces = frame_add(b, "faces", FRAME_AT_FACE, d, FRAME_U32, b->faces, 1);
    uint32_t *owner = frame_add(b, "face_element", FRAME_AT_FACE, 1, FRAME_U32, b->faces, 1);
    uint32_t *on = frame_add(b, "face_joint", FRAME_AT_FACE, 1, FRAME_U32, b->faces, 1);
    if (!b->carry.id[CARRY_ELEMENTS] || !b->carry.id[CARRY_NODES] ||
        !b->carry.id[CARRY_JOINTS] || !faces || !owner || !on)
        return -1;
    for (int i = 0; i < S; i++) {
        int32_t v[3], j = m->joint[facet[i]];
        facet_nodes((int)d, cells, facet[i], v);
        for (uint32_t k = 0; k < d; k++)
            faces[(size_t)i * d + k] = node[v[k]];
        owner[i] = elem[(uint32_t)facet[i] / per];
        on[i] = j < 0 ? FRAME_NONE : joint[j];
    }
    if (shape_ids(b) != 0)
        return -1;
    return shape_joint_elements(b, m, elem);
}

int frame_mesh_map(frame_mesh *m, char *err, size_t errlen)
{
    size_t ids = (size_t)(m->dimension + 1) * m->elements;
    for (size_t i = 0; i < ids; i++)
        if (m->cells[i] < 0 || (uint32_t)m->cells[i] >= m->nodes) {
            snprintf(err, errlen, "the result file's /mesh names node %d of %u", m->cells[i],
                     m->nodes);
            return -1;
        }
    if (facet_map_build(&m->map, m->dimension, (int)m->elements, m->cells, (int)m->joints,
                        m->joint_nodes) != 0) {
        snprintf(err, errlen, "the result file's /mesh cannot be read as a mesh (out of memory, "
                 "or a negative node id in /mesh/joints)");
        return -1;
    }
    return 0;
}

void frame_mesh_clear(frame_mesh *m)
{
    free(m->cells);
    free(m->joint_nodes);
    free(m->position0);
    free(m->row);
    free(m->facet);
    free(m->slot);
    free(m->broken);
    free(m->active);
    facet_map_free(&m->map);
    memset(m, 0, sizeof *m);
}

size_t frame_mesh_bytes(const frame_mesh *m)
{
    if (!m->cells)
        return 0;
    size_t facets = (size_t)(m->dimension + 1) * m->elements;
    size_t items = (size_t)m->elements + m->nodes + m->joints;
    return sizeof(int32_t) * (facets + (size_t)m->joints * 2 * m->dimension) +
           sizeof(float) * (size_t)m->nodes * m->dimension +
           sizeof(int32_t) * (2 * facets + 2 * (size_t)m->joints) +
           (m->row ? sizeof(double) * m->row_values : 0) +
           (m->facet ? sizeof(int32_t) * facets + sizeof(uint32_t) * items +
                           (size_t)m->elements + m->joints : 0);
}

int frame_mesh_work(frame_mesh *m, size_t values)
{
    size_t facets = (size_t)(m->dimension + 1) * m->elements;
    if (!m->facet) {
        m->facet = malloc(sizeof(int32_t) * (facets + 1));
        m->slot = malloc(sizeof(uint32_t) * ((size_t)m->elements + m->nodes + m->joints + 1));
        m->broken = malloc((size_t)m->joints + 1);
        m->active = malloc((size_t)m->elements + 1);
    }
    if (values > m->row_values) {
        free(m->row);
        m->row = malloc(sizeof(double) * values);
        m->row_values = m->row ? values : 0;
    }
    return m->facet && m->slot && m->broken && m->active && m->row ? 0 : -1;
}

result_frame_cache *result_frame_cache_new(void)
{
    return calloc(1, sizeof(result_frame_cache));
}

void result_frame_cache_clear(result_frame_cache *cache)
{
    if (cache)
        frame_mesh_clear(&cache->mesh);
}

void result_frame_cache_free(result_frame_cache *cache)
{
    result_frame_cache_clear(cache);
    free(cache);
}

size_t result_frame_cache_bytes(const result_frame_cache *cache)
{
    return cache ? frame_mesh_bytes(&cache->mesh) : 0;
}

int frame_shape(frame_build *b, const frame_mesh *mesh, const unsigned char *broken,
                const unsigned char *active, char *err, size_t errlen)
{
    const facet_map *m = &mesh->map;
    uint32_t nodes = mesh->nodes, elements = mesh->elements, joints = mesh->joints;
    b->carry.count[CARRY_NODES] = nodes;
    b->carry.count[CARRY_ELEMENTS] = elements;
    b->carry.count[CARRY_JOINTS] = joints;
    int rc;
    if (!b->surface)
        rc = shape_whole(b, m, elements, joints, mesh->cells, mesh->joint_nodes);
    else
        rc = shape_surface(b, m, nodes, mesh->cells, broken, active, mesh->facet, mesh->slot);
    if (rc != 0)
        snprintf(err, errlen, "out of memory for the frame's mesh");
    return rc;
}
