/*
 * element_tet.c - constant-strain tetrahedra at finite strain and finite
 * rotation: edge matrices, deformation gradient, neo-Hookean Cauchy stress,
 * viscous damping, nodal forces, strain energy and the stable step.
 *
 * The triangle kernel (element.c) and this one are the same method in two
 * dimensions; they share no code because each is a handful of expressions
 * written out for its own matrix size, and the hot loops want them inline.
 *
 * Nodal forces come from face vectors, as the triangle's come from edge
 * normals: with current edges e_k = x_k - x_0 and det = e1 . (e2 x e3) = 6V,
 * grad N_1 = (e2 x e3)/det, grad N_2 = (e3 x e1)/det, grad N_3 =
 * (e1 x e2)/det, so f_a = -V sigma grad N_a = -sigma c_a / 6 with c_a those
 * cross products: no division for the elastic part. Node 0 takes minus the
 * sum of the other three.
 */
#include "element_tet.h"
#include "stable_step.h"
#include "vec3.h"

#include <math.h>
#include <string.h>

static inline double vnorm(const double a[3]) { return sqrt(vec3_dot(a, a)); }

/* Edges from node 0 and their cross products c1 = e2 x e3, c2 = e3 x e1,
 * c3 = e1 x e2 (each twice the area vector of the face through node 0 and
 * the other two edges' ends); returns det = e1 . c1 = 6V. */
static double tet_edges(const double *p0, const double *p1, const double *p2,
                        const double *p3, double e[3][3], double c[3][3])
{
    vec3_sub(p1, p0, e[0]);
    vec3_sub(p2, p0, e[1]);
    vec3_sub(p3, p0, e[2]);
    vec3_cross(e[1], e[2], c[0]);
    vec3_cross(e[2], e[0], c[1]);
    vec3_cross(e[0], e[1], c[2]);
    return vec3_dot(e[0], c[0]);
}

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
    const double *p0 = node_at(pos, node[0]);
    double e[3][3];
    for (int k = 0; k < 3; k++) vec3_sub(node_at(pos, node[k + 1]), p0, e[k]);
    /* F = [x][X]^-1: F_ij = sum_k (e_k)_i xinv_kj */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            F[3 * i + j] = e[0][i] * g->xinv[j] + e[1][i] * g->xinv[3 + j] +
                           e[2][i] * g->xinv[6 + j];
}

/* ------------------------------------------------------------------ stress */

/* Voigt slots of (i, j) in the order xx, yy, zz, yz, xz, xy */
static const int voigt[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};

double tet_stress(const double F[9], double lambda, double mu, double sigma[6], double *J_out)
{
    double J = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
               F[2] * (F[3] * F[7] - F[4] * F[6]);
    double lnJ, invJ;
    if (J >= TET_J_MIN) {
        lnJ = log(J);
        invJ = 1.0 / J;
    } else { /* the tangent of the law at J_MIN: finite, and pushing open */
        lnJ = log(TET_J_MIN) + (J - TET_J_MIN) / TET_J_MIN;
        invJ = 1.0 / TET_J_MIN;
    }
    /* B = F F^T */
    double B[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = i; j < 3; j++)
            B[i][j] = F[3 * i] * F[3 * j] + F[3 * i + 1] * F[3 * j + 1] + F[3 * i + 2] * F[3 * j + 2];
    double muJ = mu * invJ, vol = lambda * lnJ * invJ;
    for (int i = 0; i < 3; i++) {
        sigma[i] = muJ * (B[i][i] - 1.0) + vol;
        for (int j = i + 1; j < 3; j++) sigma[voigt[i][j]] = muJ * B[i][j];
    }
    if (J_out) *J_out = J;
    double trB = B[0][0] + B[1][1] + B[2][2];
    return 0.5 * mu * (trB - 3.0 - 2.0 * lnJ) + 0.5 * lambda * lnJ * lnJ;
}

/* Adds 2 eta D, D = sym(L), L = [v][x]^-1 = sum_a (v_a - v_0) (x) c_a / det. */
static void add_viscous(const double *vel, const int32_t node[4], const double c[3][3],
                        double det, double eta, double sigma[6])
{
    if (!vel || !(eta > 0) || !(fabs(det) > 0)) return;
    const double *v0 = node_at(vel, node[0]);
    double L[3][3] = {{0}};
    for (int k = 0; k < 3; k++) {
        double dv[3];
        vec3_sub(node_at(vel, node[k + 1]), v0, dv);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) L[i][j] += dv[i] * c[k][j];
    }
    double scale = eta / det; /* 2 eta * (L + L^T)/2 / det */
    for (int i = 0; i < 3; i++)
        for (int j = i; j < 3; j++) sigma[voigt[i][j]] += scale * (L[i][j] + L[j][i]);
}

double tet_forces(const double *pos, const double *vel, const int32_t node[4],
                  const tet_geometry *g, const tet_law *law, double f[12], double sigma_out[6])
{
    double F[9], sigma[6], J, e[3][3], c[3][3];
    tet_deformation(pos, node, g, F);
    double w = tet_stress(F, law->lambda, law->mu, sigma, &J);
    double det = tet_edges(node_at(pos, node[0]), node_at(pos, node[1]), node_at(pos, node[2]),
                           node_at(pos, node[3]), e, c);
    add_viscous(vel, node, c, det, law->eta, sigma);
    const double s[3][3] = {{sigma[0], sigma[5], sigma[4]},
                            {sigma[5], sigma[1], sigma[3]},
                            {sigma[4], sigma[3], sigma[2]}};
    double sum[3] = {0, 0, 0};
    for (int a = 1; a <= 3; a++)
        for (int i = 0; i < 3; i++) {
            double fi = -(s[i][0] * c[a - 1][0] + s[i][1] * c[a - 1][1] + s[i][2] * c[a - 1][2]) / 6.0;
            f[3 * a + i] = fi;
            sum[i] += fi;
        }
    for (int i = 0; i < 3; i++) f[i] = -sum[i];
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

/* Largest eigenvalue of the symmetric 6x6 matrix a (destroyed), by cyclic
 * Jacobi rotations: quadratically convergent, a few sweeps to round-off. */
static double symmetric6_largest_eigenvalue(double a[6][6])
{
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = 0, diag = 0;
        for (int i = 0; i < 6; i++) {
            diag += a[i][i] * a[i][i];
            for (int j = i + 1; j < 6; j++) off += a[i][j] * a[i][j];
        }
        if (!(off > 1e-30 * diag)) break;
        for (int p = 0; p < 5; p++)
            for (int q = p + 1; q < 6; q++) {
                if (a[p][q] == 0) continue;
                double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
                double t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 6; k++) { /* columns p, q */
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 6; k++) { /* rows p, q */
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
            }
    }
    double largest = a[0][0];
    for (int i = 1; i < 6; i++) largest = fmax(largest, a[i][i]);
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
