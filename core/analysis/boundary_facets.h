/*
 * boundary_facets.h - the facets of a simplex mesh that can be seen: the
 * outer surface of each body plus both faces of every broken joint (a
 * crack), for the web page's 3D view, which draws ~2 % of a fracturing
 * mesh's faces instead of all of them (issue 35).
 *
 * A facet is an edge of a triangle (2D) or a face of a tetrahedron (3D),
 * numbered f = (D+1)e + k. Two things hide one: another element with the
 * same nodes (a part that does not fracture shares its nodes), or a joint
 * still holding (damage below 1) whose other side is a facet of an element
 * still there (a fracturing part gives each element its own nodes, so only
 * the joint tells its inner faces from its surface). Excavated elements
 * (active 0) show nothing, and the walls they leave show.
 *
 * Contract: facet_map_build matches facets to their twins and to the
 * joints lying on them from the mesh arrays alone (linear time, one hash
 * table); facet_map_boundary then picks one snapshot's visible facets, in
 * increasing facet order, in one pass. facet_nodes gives a facet's nodes,
 * ordered so that its normal points out of its element (for a triangle of
 * positive area or a tetrahedron of positive volume). No model is read:
 * the arrays are those of result.h5's /mesh, so the same code serves a
 * file on disk and a running case.
 */
#ifndef FDEM_BOUNDARY_FACETS_H
#define FDEM_BOUNDARY_FACETS_H

#include <stddef.h>
#include <stdint.h>

typedef struct facet_map {
    int dimension;        /* 2 or 3: facets have `dimension` nodes */
    int elements, joints;
    int32_t *twin;        /* (D+1)E: the facet of another element with the same nodes, or -1 */
    int32_t *joint;       /* (D+1)E: the joint one of whose sides is this facet, or -1 */
    int32_t *joint_facet; /* 2J: the facets of side a and of side b, -1 when none matches */
} facet_map;

/* The peak bytes facet_map_build allocates for such a mesh (the map and
 * its hash table), for a caller that charges a memory budget first. */
size_t facet_map_bytes(int dimension, int elements, int joints);

/* cells: E rows of D+1 node ids; joint_nodes: J rows of 2D (side a's D
 * nodes, then side b's), as /mesh/joints. 0, or -1 when out of memory or
 * a node id is negative (the map is then empty). */
int facet_map_build(facet_map *m, int dimension, int elements, const int32_t *cells, int joints,
                    const int32_t *joint_nodes);
void facet_map_free(facet_map *m);

/* The visible facets of one snapshot into out (room for (D+1)E), their
 * count returned. broken[j] non-zero: joint j is broken (NULL: none is);
 * active[e] zero: element e is excavated (NULL: all are there). */
int facet_map_boundary(const facet_map *m, const unsigned char *broken,
                       const unsigned char *active, int32_t *out);

/* Facet f's D node ids into nodes, outward-ordered (see above). */
void facet_nodes(int dimension, const int32_t *cells, int32_t f, int32_t *nodes);

#endif /* FDEM_BOUNDARY_FACETS_H */
