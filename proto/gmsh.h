/*
 * gmsh.h - reads the triangles of an ASCII gmsh mesh (format 2.2 or 4.1)
 * into an engine mesh.
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

int gmsh_read(const char *text, size_t length, fdem_mesh *out,
              char *message, size_t message_size);

#endif
