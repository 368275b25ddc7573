/*
 * gmsh.h - reads the triangles (2D) or tetrahedra (3D) of an ASCII gmsh
 * mesh (format 2.2 or 4.1) into an engine mesh.
 *
 * Contract: only 3-node triangles (element type 2) are kept; nodes not used
 * by any triangle are dropped and the rest renumbered 0..n-1 in file order;
 * z is ignored. Any malformed input (binary files, bad counts, unknown node
 * tags, truncated sections, non-finite numbers, no triangles) returns -1
 * with a message that names the section and line. Never reads past `length`.
 *
 * Folder proto/gmsh/, the gmsh reader: owns this header and what gmsh.c
 * (sections, nodes, elements) and gmsh_groups.c (physical groups) share,
 * gmsh_internal.h. May call core/ (the engine's mesh types) and the C
 * library only: no JSON, no case. Called by proto/case/ (mesh and gmsh
 * parts, selectors by group), the unit tests and the case fuzzer.
 */
#ifndef FDEM_GMSH_H
#define FDEM_GMSH_H

#include <stddef.h>
#include <stdint.h>
#include "fdem.h"
#include "mesh/mesh_3d.h"

/* Physical groups (contract 5.3), read from $PhysicalNames and the
 * elements' tags (2.2) or their entities' (4.1, $Entities). Only named
 * groups are kept; several groups may share a name (in different
 * dimensions). Node and element indices are those of the mesh read with
 * them; an element in several groups (2.2 writes it once per group) is one
 * element of the mesh. */
#define GMSH_NAME 128

typedef struct gmsh_group {
    int dim;                 /* 0 points, 1 curves, 2 surfaces, 3 volumes */
    char name[GMSH_NAME];
    int32_t *nodes;          /* the mesh nodes of its elements, ascending */
    int node_count;
    int32_t *elements;       /* dim = the mesh's: its triangles (tetrahedra), ascending */
    int element_count;
    int32_t *faces;          /* dim = the mesh's - 1: its 2-node lines (3-node triangles) */
    int face_count;
} gmsh_group;

typedef struct gmsh_groups {
    gmsh_group *group;
    int count;
} gmsh_groups;

void gmsh_groups_free(gmsh_groups *groups);

/* gmsh_read and gmsh_read_tetrahedra, with the groups too (groups may be
 * NULL: not wanted, as the two below). */
int gmsh_read_grouped(const char *text, size_t length, fdem_mesh *out, gmsh_groups *groups,
                      char *message, size_t message_size);
int gmsh_read_tetrahedra_grouped(const char *text, size_t length, fdem_tet_mesh *out,
                                 gmsh_groups *groups, char *message, size_t message_size);

int gmsh_read(const char *text, size_t length, fdem_mesh *out,
              char *message, size_t message_size);

/* The same for 3D: only 4-node tetrahedra (element type 4) are kept, z is
 * read, and the result is a tetrahedral mesh (not yet validated: pass it to
 * fdem_tet_mesh_validate, which orients it). */
int gmsh_read_tetrahedra(const char *text, size_t length, fdem_tet_mesh *out,
                         char *message, size_t message_size);

#endif
