/*
 * mesh.h - meshes as plain arrays, before they are parts of a model: the
 * validation of input triangle meshes (mesh.c, fdem_mesh_validate in
 * fdem.h) and tetrahedral meshes with their generators (mesh_3d.c,
 * mesh_3d.h). Calls only the model's error helper and the tetrahedron
 * kernel's volume; building (build/) and proto/ call it.
 */
#ifndef FDEM_MESH_H
#define FDEM_MESH_H

#include "fdem.h"
#include "mesh_3d.h"

/* The mesh checks (mesh.c, mesh_3d.c) take an element only when its size
 * squared (2D) or cubed (3D) is above this and finite: the 1e-12 tolerance
 * on its area or volume is then still a normal double. Edges from about
 * 1e-93 m (3D; 1e-140 m in 2D) up to 5e102 m (1e154 m) pass. */
#define MESH_SMALLEST_CUBE 1e-280

#endif
