/*
 * element_tet.h - the 4-node tetrahedron at finite strain and rotation, as
 * functions over plain arrays (positions and velocities as xyz triples,
 * elements as node index quadruples), so a dimension-aware model can call
 * them per element.
 *
 * Contract:
 *  - tet_prepare: from the initial positions, [X]^-1 of the edge matrix
 *    [X1-X0, X2-X0, X3-X0], the volume V0 and the smallest height
 *    (3V / largest face area). Fails (returns -1) unless V0 > 0: meshes are
 *    validated (and reoriented) first.
 *  - tet_stress: F = [x][X]^-1, the compressible neo-Hookean Cauchy stress
 *    sigma = (mu/J)(B - I) + (lambda/J) ln J I with the full 3D lambda and
 *    mu; any rigid rotation gives zero stress; below J = TET_J_MIN the law
 *    continues along its tangent so squashed elements stay finite.
 *  - tet_forces: adds the viscous stress 2 eta D (D = sym([v][x]^-1) at
 *    the positions given; the engine's loop takes D, and applies the
 *    viscous forces, on the mid-step configuration: element_tet_model.c) and
 *    writes the nodal forces f_a = -V sigma grad N_a (f[3a .. 3a+2]); the
 *    four sum to zero to round-off (node 0 takes minus the sum of the other
 *    three) and their moment vanishes (sigma is symmetric). Returns the
 *    elastic strain energy V0 W.
 *  - Stress is stored in the order xx, yy, zz, yz, xz, xy (contract 5.2).
 *  - tet_stable_dt: h / c (sqrt(1 + xi^2) - xi), c = sqrt((lambda+2mu)/rho),
 *    the central-difference limit of the stiffest mode with damping ratio xi.
 */
#ifndef FDEM_ELEMENT_TET_H
#define FDEM_ELEMENT_TET_H

#include <stdint.h>

#define TET_J_MIN 0.05

/* The four faces of a positively oriented tetrahedron, face f opposite
 * node f, each ordered so that (x1-x0) x (x2-x0) points out of it. */
extern const int tet_face_nodes[4][3];

typedef struct tet_geometry {
    double xinv[9];  /* [X]^-1, row-major */
    double volume0;  /* initial volume */
    double height;   /* smallest initial height */
} tet_geometry;

typedef struct tet_law {
    double lambda, mu; /* Lame constants (3D) */
    double eta;        /* viscosity of the damping stress 2 eta D */
} tet_law;

/* Signed volume of the tetrahedron of four points (xyz triples). */
double tet_volume(const double *p0, const double *p1, const double *p2, const double *p3);

/* Smallest height 3V / (largest face area); 0 for a flat tetrahedron. */
double tet_smallest_height(const double *p0, const double *p1, const double *p2,
                           const double *p3);

int tet_prepare(const double *pos0, const int32_t node[4], tet_geometry *out);

/* Deformation gradient (row-major) of the element at positions pos. */
void tet_deformation(const double *pos, const int32_t node[4], const tet_geometry *g,
                     double F[9]);

/* Cauchy stress (xx, yy, zz, yz, xz, xy) of F; returns the strain energy
 * density per unit initial volume, *J gets det F. */
double tet_stress(const double F[9], double lambda, double mu, double sigma[6], double *J);

/* Nodal forces (12 numbers) and the total stress (elastic + viscous, may
 * be NULL); vel may be NULL (no damping). Returns the strain energy. */
double tet_forces(const double *pos, const double *vel, const int32_t node[4],
                  const tet_geometry *g, const tet_law *law, double f[12], double sigma[6]);

/* Viscosity of a damping ratio xi for the element's highest mode:
 * eta = xi h sqrt(rho (lambda + 2 mu)), as for triangles. */
double tet_viscosity(double height, double lambda, double mu, double density, double xi);

double tet_stable_dt(double height, double lambda, double mu, double density, double xi);

/* The central-difference limit of the tetrahedron with lumped masses
 * rho V / 4 by the element eigenvalue theorem: omega_max^2 is 4/rho times
 * the largest eigenvalue of D B B^T (6x6, strain space), found by Jacobi
 * rotations of its symmetric form D^1/2 B B^T D^1/2; the viscous stress
 * 2 eta D gives the largest damping rate c_max = 4/rho eta times that of
 * diag(2,2,2,1,1,1) B B^T, and a mode of frequency omega and rate c is
 * stable for h <= 2 / (sqrt(omega^2 + c^2/4) + c/2), which falls with
 * both. h/c (tet_stable_dt) is up to 1.6 times this on common shapes. */
double tet_stable_dt_eigen(const double *pos0, const int32_t node[4], double lambda, double mu,
                           double density, double eta);

#endif /* FDEM_ELEMENT_TET_H */
