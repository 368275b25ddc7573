/*
 * gmsh.h - reads the triangles (2D) or tetrahedra (3D) of an ASCII gmsh
 * mesh (format 2.2 or 4.1) into an engine mesh.
 *
 * Contract: only 3-node triangles (element type 2) are kept; nodes not used
 * by any triangle are dropped and the rest renumbered 0..n-1 in file order;
 * z is ignored. Any malformed input (binary files, bad counts, unknown node
 * tags, truncated sections, non-finite numbers, no triangles) returns -1
 * with a message that names the section and line. Never reads past `length`.
 */
#ifndef FDEM_GMSH_H
#define FDEM_GMSH_H

#include <stddef.h>
#include "fdem.h"
#include "mesh_3d.h"

int gmsh_read(const char *text, size_t length, fdem_mesh *out,
              char *message, size_t message_size);

/* The same for 3D: only 4-node tetrahedra (element type 4) are kept, z is
 * read, and the result is a tetrahedral mesh (not yet validated: pass it to
 * fdem_tet_mesh_validate, which orients it). */
int gmsh_read_tetrahedra(const char *text, size_t length, fdem_tet_mesh *out,
                         char *message, size_t message_size);

#endif
