/*
 * element_tet.c - constant-strain tetrahedra at finite strain and finite
 * rotation: edge matrices, deformation gradient, neo-Hookean Cauchy stress,
 * viscous damping, nodal forces, strain energy and the stable step.
 *
 * The per-element expressions are element_tet_kernel.h's, inline, which the
 * engine's loop (element_tet_model.c) uses too: what the unit tests hold
 * here is what the engine runs. The triangle kernel (element_tri.c) shares
 * the law's ln J (log_near1.h); the rest is written out for its own size.
 *
 * Nodal forces come from face vectors, as the triangle's come from edge
 * normals: with current edges e_k = x_k - x_0 and det = e1 . (e2 x e3) = 6V,
 * grad N_1 = (e2 x e3)/det, grad N_2 = (e3 x e1)/det, grad N_3 =
 * (e1 x e2)/det, so f_a = -V sigma grad N_a = -sigma c_a / 6 with c_a those
 * cross products: no division for the elastic part. Node 0 takes minus the
 * sum of the other three.
 */
#include "element_tet.h"
#include "math/jacobi.h"
#include "element_tet_kernel.h"
#include "math/stable_step.h"
#include "math/vec3.h"

#include <math.h>
#include <string.h>

static inline double vnorm(const double a[3]) { return sqrt(vec3_dot(a, a)); }

/* Edges from node 0 and their face vectors (element_tet_kernel.h);
 * returns det = 6V. */
static double tet_edges(const double *p0, const double *p1, const double *p2,
                        const double *p3, double e[3][3], double c[3][3])
{
    tet_kernel_edges(p0, p1, p2, p3, e);
    return tet_kernel_faces(e, c);
}

const int tet_face_nodes[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

static const double *node_at(const double *xyz, int32_t n) { return xyz + 3 * (size_t)n; }

/* --------------------------------------------------------------- geometry */

double tet_volume(const double *p0, const double *p1, const double *p2, const double *p3)
{
    double e[3][3], c[3][3];
    return tet_edges(p0, p1, p2, p3, e, c) / 6.0;
}

double tet_smallest_height(const double *p0, const double *p1, const double *p2,
                           const double *p3)
{
    double e[3][3], c[3][3], a[3], b[3], opposite[3];
    double det = tet_edges(p0, p1, p2, p3, e, c);
    vec3_sub(p2, p1, a);
    vec3_sub(p3, p1, b);
    vec3_cross(a, b, opposite);
    /* twice the face areas; h = 3V / A = det / (2A) */
    double largest = fmax(fmax(vnorm(c[0]), vnorm(c[1])), fmax(vnorm(c[2]), vnorm(opposite)));
    return largest > 0 ? fabs(det) / largest : 0.0;
}

int tet_prepare(const double *pos0, const int32_t node[4], tet_geometry *out)
{
    const double *p[4];
    for (int a = 0; a < 4; a++) p[a] = node_at(pos0, node[a]);
    double e[3][3], c[3][3];
    double det = tet_edges(p[0], p[1], p[2], p[3], e, c);
    if (!(det > 0) || !isfinite(det)) return -1;
    /* [X]^-1 has the rows c_k / det (X has the edges as columns) */
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) out->xinv[3 * k + i] = c[k][i] / det;
    out->volume0 = det / 6.0;
    out->height = tet_smallest_height(p[0], p[1], p[2], p[3]);
    return 0;
}

void tet_deformation(const double *pos, const int32_t node[4], const tet_geometry *g,
                     double F[9])
{
    double e[3][3];
    tet_kernel_edges(node_at(pos, node[0]), node_at(pos, node[1]), node_at(pos, node[2]),
                     node_at(pos, node[3]), e);
    tet_kernel_gradient(e, g->xinv, F);
}

/* ------------------------------------------------------------------ stress */

double tet_stress(const double F[9], double lambda, double mu, double sigma[6], double *J_out)
{
    double J, invJ;
    double w = tet_kernel_stress(F, mu, lambda, 0.5 * mu, 0.5 * lambda, sigma, &J, &invJ);
    if (J_out) *J_out = J;
    return w;
}

double tet_forces(const double *pos, const double *vel, const int32_t node[4],
                  const tet_geometry *g, const tet_law *law, double f[12], double sigma_out[6])
{
    double F[9], sigma[6], J, e[3][3], c[3][3];
    const double *p[4];
    for (int a = 0; a < 4; a++) p[a] = node_at(pos, node[a]);
    tet_kernel_edges(p[0], p[1], p[2], p[3], e);
    tet_kernel_gradient(e, g->xinv, F);
    double w = tet_stress(F, law->lambda, law->mu, sigma, &J);
    double det = tet_kernel_faces(e, c);
    /* 2 eta D, D = S / det */
    if (vel && law->eta > 0 && fabs(det) > 0) {
        double S[6];
        tet_kernel_rate(node_at(vel, node[0]), node_at(vel, node[1]), node_at(vel, node[2]),
                        node_at(vel, node[3]), c, S);
        for (int k = 0; k < 6; k++) sigma[k] += 2 * law->eta / det * S[k];
    }
    double sixth[6], load[4][3];
    for (int k = 0; k < 6; k++) sixth[k] = sigma[k] * (1.0 / 6);
    tet_kernel_face_loads(sixth, c, load);
    for (int i = 0; i < 3; i++) f[i] = load[0][i];
    for (int q = 3; q < 12; q++) f[q] = -load[q / 3][q % 3];
    if (sigma_out) memcpy(sigma_out, sigma, sizeof sigma);
    return g->volume0 * w;
}

/* ------------------------------------------------------------ stable step */

double tet_viscosity(double height, double lambda, double mu, double density, double xi)
{
    return xi * height * sqrt(density * (lambda + 2 * mu));
}

double tet_stable_dt(double height, double lambda, double mu, double density, double xi)
{
    double c = sqrt((lambda + 2 * mu) / density);
    return height / c * (sqrt(1 + xi * xi) - xi);
}

/* Largest eigenvalue of the symmetric 6x6 matrix a (destroyed). */
static double symmetric6_largest_eigenvalue(double a[6][6])
{
    double eigen[6];
    jacobi_eigenvalues(&a[0][0], 6, eigen);
    double largest = eigen[0];
    for (int i = 1; i < 6; i++) largest = fmax(largest, eigen[i]);
    return largest;
}

/* Largest eigenvalue of R G R for a symmetric root R. */
static double rooted_largest_eigenvalue(const double root[6][6], const double G[6][6])
{
    double t[6][6], S[6][6];
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) {
            t[i][j] = 0;
            for (int k = 0; k < 6; k++) t[i][j] += root[i][k] * G[k][j];
        }
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) {
            S[i][j] = 0;
            for (int k = 0; k < 6; k++) S[i][j] += t[i][k] * root[k][j];
        }
    return symmetric6_largest_eigenvalue(S);
}

double tet_stable_dt_eigen(const double *pos0, const int32_t node[4], double lambda, double mu,
                           double density, double eta)
{
    double e[3][3], c[3][3];
    double det = tet_edges(node_at(pos0, node[0]), node_at(pos0, node[1]), node_at(pos0, node[2]),
                           node_at(pos0, node[3]), e, c);
    /* grad N_a = c_{a-1} / det for a = 1..3, node 0 minus their sum */
    double g[4][3];
    for (int i = 0; i < 3; i++) {
        g[0][i] = 0;
        for (int a = 1; a <= 3; a++) {
            g[a][i] = c[a - 1][i] / det;
            g[0][i] -= g[a][i];
        }
    }
    /* G = sum_a B_a B_a^T for the engineering strain (xx, yy, zz, 2yz, 2xz, 2xy) */
    double G[6][6] = {{0}};
    for (int a = 0; a < 4; a++) {
        double gx = g[a][0], gy = g[a][1], gz = g[a][2];
        const double B[6][3] = {{gx, 0, 0}, {0, gy, 0}, {0, 0, gz},
                                {0, gz, gy}, {gz, 0, gx}, {gy, gx, 0}};
        for (int r = 0; r < 6; r++)
            for (int s = 0; s < 6; s++)
                G[r][s] += B[r][0] * B[s][0] + B[r][1] * B[s][1] + B[r][2] * B[s][2];
    }
    /* D^1/2: the normal block has 3 lambda + 2 mu on (1,1,1)/sqrt 3 and 2 mu
     * across it, the shear block mu */
    double root[6][6] = {{0}};
    double s2mu = sqrt(2 * mu), svol = sqrt(3 * lambda + 2 * mu), smu = sqrt(mu);
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) root[i][j] = (svol - s2mu) / 3;
        root[i][i] += s2mu;
        root[3 + i][3 + i] = smu;
    }
    double omega2 = 4 / density * rooted_largest_eigenvalue(root, G);
    double rate = 0;
    if (eta > 0) {
        double viscous_root[6][6] = {{0}};
        for (int i = 0; i < 6; i++) viscous_root[i][i] = i < 3 ? sqrt(2.0) : 1.0;
        rate = 4 / density * eta * rooted_largest_eigenvalue(viscous_root, G);
    }
    return damped_mode_stable_dt(omega2, rate);
}
