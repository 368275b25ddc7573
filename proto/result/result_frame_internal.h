/*
 * result_frame_internal.h - what the two forms of the web page's binary
 * frame share (docs/api.md, "Binary mesh frames"): result_frame.c reads
 * result.h5 and writes the header and sections; result_frame_shape.c
 * gives the mesh's shape, whole or only the facets that can be seen. A frame
 * is built as a list of sections (named typed arrays, each owning its
 * buffer), then written in one piece. I/O thread only.
 */
#ifndef FDEM_RESULT_FRAME_INTERNAL_H
#define FDEM_RESULT_FRAME_INTERNAL_H

#include <stdint.h>

#include "analysis/boundary_facets.h"
#include "result_internal.h"

/* Where a section's items live, and its value type (the header codes). */
enum { FRAME_AT_NODE = 0, FRAME_AT_ELEMENT = 1, FRAME_AT_JOINT = 2, FRAME_AT_FACE = 3 };
enum { FRAME_F32 = 0, FRAME_U32 = 1 };
#define FRAME_NONE 0xffffffffu /* a u32 index that points nowhere */
#define FRAME_MAX_SECTIONS 32

typedef struct frame_section {
    char name[16];  /* NUL-padded, not terminated when 16 long */
    uint32_t at, width, type, items;
    int shape;     /* 1: part of the mesh's shape, left out when the client holds it */
    void *data;    /* items * width 4-byte values, malloc'd */
} frame_section;

/* The items a frame carries: every one (id NULL) or those listed. */
enum { CARRY_NODES, CARRY_ELEMENTS, CARRY_JOINTS, CARRY_KINDS };
typedef struct frame_carry {
    uint32_t count[CARRY_KINDS];
    uint32_t *id[CARRY_KINDS]; /* the original index of each carried item, or NULL */
} frame_carry;

typedef struct frame_build {
    int dimension, surface;
    uint32_t faces;         /* facets carried (surface form) */
    frame_carry carry;
    int count;
    frame_section section[FRAME_MAX_SECTIONS];
} frame_build;

/* A new section of items x width values, zeroed; NULL when out of memory
 * or past FRAME_MAX_SECTIONS. */
void *frame_add(frame_build *b, const char *name, uint32_t at, uint32_t width, uint32_t type,
                uint32_t items, int shape);

/* A mesh as /mesh gives it, with its facet map: what the cache keeps. */
typedef struct frame_mesh {
    char owner[64];       /* whose mesh (the cache's key), "" when empty */
    int dimension;
    uint32_t nodes, elements, joints;
    int32_t *cells;       /* E rows of D+1 */
    int32_t *joint_nodes; /* J rows of 2D */
    float *position0;     /* N rows of D */
    facet_map map;
    /* work space of one frame, kept with the mesh so that the next frame
     * does not fault in fresh pages (tens of ms per 10 MB on this VM) */
    double *row;          /* one /snapshots row as read */
    size_t row_values;
    int32_t *facet;       /* (D+1)E: the facets shown */
    uint32_t *slot;       /* E + N + J: carried numbering */
    unsigned char *broken, *active; /* J, E */
} frame_mesh;

/* The mesh's work space, with room for a row of `values` doubles; 0 or -1
 * when out of memory. */
int frame_mesh_work(frame_mesh *m, size_t values);

struct result_frame_cache {
    frame_mesh mesh;
};

void frame_mesh_clear(frame_mesh *m);
/* Its bytes held (the cache's size). */
size_t frame_mesh_bytes(const frame_mesh *m);

/* The mesh's shape as sections, and what the frame carries (b->carry):
 * the whole mesh (cells, joints, joint_elements), or with b->surface the
 * visible facets (faces, face_element, face_joint, node_id, element_id,
 * joint_id, joint_elements) and only the nodes, elements and joints they
 * touch. broken[J] and active[E] of the snapshot (NULL: none broken, all
 * there). 0, or -1 with err (out of memory). */
int frame_shape(frame_build *b, const frame_mesh *mesh, const unsigned char *broken,
                const unsigned char *active, char *err, size_t errlen);

/* Checks the mesh's node ids and builds its facet map. 0, or -1 with err. */
int frame_mesh_map(frame_mesh *m, char *err, size_t errlen);

/* The peak bytes frame_shape and frame_mesh_map allocate besides the
 * sections and the mesh arrays. */
size_t frame_shape_bytes(int dimension, uint32_t nodes, uint32_t elements, uint32_t joints);

#endif
