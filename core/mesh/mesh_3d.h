/*
 * mesh_3d.h - tetrahedral meshes as plain arrays: the box, sphere and
 * cylinder generators of contract 5.2, the validation every input
 * tetrahedral mesh goes through (as fdem_mesh_validate for triangles), and
 * the quality measures the generators are held to.
 *
 * Contract:
 *  - Nodes are xyz triples, tetrahedra node index quadruples (0-based) with
 *    positive volume after validation. fdem_tet_mesh_free releases both.
 *  - Generators return 0 and a validated, conforming mesh (every interior
 *    face shared by exactly two tetrahedra), or -1 with err filled.
 *  - fdem_tet_mesh_validate: at least 4 nodes and 1 tetrahedron, finite
 *    coordinates, indices in range and distinct, no zero volume (relative
 *    to the element's size), every node used; negative volumes are
 *    reoriented (nodes 1 and 2 swapped) and counted in *reoriented.
 *    Errors name the node (FDEM_ITEM_NODE) or tetrahedron
 *    (FDEM_ITEM_TETRAHEDRON) at fault.
 */
#ifndef FDEM_MESH_3D_H
#define FDEM_MESH_3D_H

#include <stdint.h>

#include "fdem.h"

void fdem_tet_mesh_free(fdem_tet_mesh *mesh);

/* origin + [0, size] split into div[0] x div[1] x div[2] cells of six
 * tetrahedra each, mirrored cell by cell so no direction is preferred. */
int fdem_tet_mesh_box(const double origin[3], const double size[3], const int div[3],
                      fdem_tet_mesh *out, fdem_error *err);

/* divisions: element edges around a great circle, >= 8. */
int fdem_tet_mesh_sphere(const double center[3], double radius, int divisions,
                         fdem_tet_mesh *out, fdem_error *err);

/* center: centre of the end face at the low end of the axis; axis 0, 1, 2
 * for x, y, z; divisions[0] around the rim (>= 8), divisions[1] along the
 * axis (>= 1). */
int fdem_tet_mesh_cylinder(const double center[3], int axis, double radius, double length,
                           const int divisions[2], fdem_tet_mesh *out, fdem_error *err);

int fdem_tet_mesh_validate(fdem_tet_mesh *mesh, int *reoriented, fdem_error *err);

/* Worst quality over the mesh: the smallest dihedral angle (degrees) and
 * the smallest radius ratio 3 r_in / r_circ (1 for a regular tetrahedron). */
void fdem_tet_mesh_quality(const fdem_tet_mesh *mesh, double *min_dihedral_deg,
                           double *min_radius_ratio);

/* Total volume (sum of signed tetrahedron volumes). */
double fdem_tet_mesh_volume(const fdem_tet_mesh *mesh);

#endif /* FDEM_MESH_3D_H */
