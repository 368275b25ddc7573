/*
 * element_tri.c - the 2D element kernel: constant-strain triangles at
 * finite strain and finite rotation (deformation gradient, Cauchy stress,
 * nodal forces, strain energy, the element's stable step). element.c runs
 * it through the scatter plan; element_tet_model.c is its 3D counterpart.
 *
 * F = [x][X]^-1 with [X]^-1 stored per element. The stress law is the
 * compressible neo-Hookean solid sigma = (mu/J)(B - I) + (lambda/J) ln J I,
 * B = F F^T: objective (a rigid rotation R gives B = I, so no stress) and
 * equal to plane-strain linear elasticity at small strain. Viscous damping
 * adds 2 eta D with D = sym([v][x_mid]^-1) on the mid-step configuration
 * x_mid = x - h_last v / 2 (v the half-step velocity, the chord of the last
 * step, h_last = dt_prev), so a rigid rotation gives D = 0 to round-off:
 * with the current x it gave D ~ h omega^2 / 2 and a free spin was damped,
 * booked in proportion to dt^2 (issue 29). The viscous stress's forces are
 * applied on the mid-step edges, in the same scatter as the elastic ones,
 * so the damping power booked, -det [x_mid] (eta D : D), is that of the
 * forces applied (the other way, forces on the current edges, would book
 * a power that is not theirs by a relative h omega; the power of the same
 * forces with the next velocities is booked at the next step on its
 * mid-step edges: tri_forces). An in-situ pre-stress S0 adds
 * F S0 F^T / J (initial_stress.c), in a second instance of the loop that
 * only the elements of stressed parts run.
 *
 * Nodal forces come from edge tractions: the force on node a is
 * 1/2 sigma m_a, m_a the outward normal (scaled by length) of the edge
 * opposite a. This needs no division; node 0 takes minus the sum of the
 * other two, so the forces sum to zero exactly.
 *
 * An element squashed to (or through) zero area would make ln J undefined;
 * below J_MIN the law continues along its tangent in J so the force stays
 * finite and keeps pushing the element open, instead of poisoning the run.
 */
#include <assert.h>
#include <math.h>
#include <string.h>

#include "math/log_near1.h"
#include "model/model.h"
#include "math/stable_step.h"
#include "element.h"

static_assert(sizeof(element_hot) == 64, "the hot element record is one cache line");

#define J_MIN 0.05

/* The loop's helpers are forced inline: the loop is instantiated once per
 * variant (tri_forces), and gcc left neo_hookean_half out of line once
 * there were three, a call per element. */
#define TRI_KERNEL static inline __attribute__((always_inline))

/* How far ahead element_forces asks for element records: 16 records = 1 KB,
 * measured best of 4/8/16/24 on a 1e6-element mesh. */
#define ELEM_PREFETCH 16
#if defined(__GNUC__)
#define ELEM_PREFETCH_READ(p) __builtin_prefetch(p)
#else
#define ELEM_PREFETCH_READ(p) ((void)(p))
#endif

void tri_element_prepare(fdem_model *m, int e)
{
    element_hot *el = &m->elem[e];
    const double *p = m->pos0;
    int a = el->node[0], b = el->node[1], c = el->node[2];
    double X1 = p[2 * b] - p[2 * a], Y1 = p[2 * b + 1] - p[2 * a + 1];
    double X2 = p[2 * c] - p[2 * a], Y2 = p[2 * c + 1] - p[2 * a + 1];
    double det = X1 * Y2 - X2 * Y1; /* > 0: validated and counter-clockwise */
    el->xinv[0] = Y2 / det;
    el->xinv[1] = -X2 / det;
    el->xinv[2] = -Y1 / det;
    el->xinv[3] = X1 / det;
    el->area0 = 0.5 * det;

    double l0 = hypot(X1, Y1), l1 = hypot(X2 - X1, Y2 - Y1), l2 = hypot(X2, Y2);
    double lmax = fmax(l0, fmax(l1, l2));
    m->elem_h[e] = det / lmax; /* smallest altitude */

    const material *mat = &m->materials[el->material];
    double modulus = mat->lambda + 2 * mat->mu;
    el->eta = mat->def.damping * m->elem_h[e] * sqrt(mat->def.density * modulus);
}

/* The largest eigenvalue of the 3x3 matrix M, whose eigenvalues are real
 * and non-negative (M = D G with D and G symmetric positive semi-definite):
 * the largest root of its characteristic cubic, in trigonometric form. */
static double largest_real_eigenvalue(const double M[3][3])
{
    double a = M[0][0] + M[1][1] + M[2][2];
    double b = M[0][0] * M[1][1] - M[0][1] * M[1][0] + M[0][0] * M[2][2] - M[0][2] * M[2][0] +
               M[1][1] * M[2][2] - M[1][2] * M[2][1];
    double c = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
               M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
               M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
    double p = b - a * a / 3, q = -2 * a * a * a / 27 + a * b / 3 - c;
    if (!(p < -1e-14 * a * a)) return a / 3; /* a triple root */
    double r = sqrt(-p / 3), arg = 3 * q / (2 * p) / r;
    arg = arg > 1 ? 1 : arg < -1 ? -1 : arg;
    return a / 3 + 2 * r * cos(acos(arg) / 3);
}

/* The stable step of one element by the element eigenvalue theorem: no
 * mode of the assembled mesh is faster than the fastest mode of any of its
 * elements with their share of the lumped masses (rho A / 3 a node). For a
 * constant-strain triangle the non-zero eigenvalues of K / m are those of
 * (A / m) D B B^T, a 3x3 matrix. The older estimate h_min / c was 6-43 %
 * above this bound (depending on the shape and Poisson's ratio), so a
 * safety of 1 could diverge. The viscous stress 2 eta D is diag(2, 2, 1)
 * eta on the engineering strain rate, so the largest damping rate is
 * c_max = (A / m) eta times the largest eigenvalue of diag(2, 2, 1) B B^T;
 * the limit falls with both (stable_step.h). Taking the damping ratio as
 * the material's xi instead was up to 2x too large for strongly damped
 * materials: eta is set from the smallest altitude h, and omega_max is
 * well above c / h. */
double tri_element_stable_dt(const fdem_model *m, int e)
{
    const element_hot *el = &m->elem[e];
    const material *mat = &m->materials[el->material];
    const double *p = m->pos0;
    const int32_t *n = el->node;
    double b[3], c[3]; /* 2A grad N_a = (b_a, c_a) */
    for (int a = 0; a < 3; a++) {
        int i = n[(a + 1) % 3], j = n[(a + 2) % 3];
        b[a] = p[2 * i + 1] - p[2 * j + 1];
        c[a] = p[2 * j] - p[2 * i];
    }
    double A = el->area0, s = 1.0 / (4 * A * A);
    double bb = 0, cc = 0, bc = 0;
    for (int a = 0; a < 3; a++) {
        bb += b[a] * b[a];
        cc += c[a] * c[a];
        bc += b[a] * c[a];
    }
    /* G = B B^T for strain (xx, yy, 2xy) */
    double G[3][3] = {{s * bb, 0, s * bc}, {0, s * cc, s * bc}, {s * bc, s * bc, s * (bb + cc)}};
    double l2 = mat->lambda + 2 * mat->mu, D[3][3] = {{l2, mat->lambda, 0}, {mat->lambda, l2, 0},
                                                      {0, 0, mat->mu}};
    double M[3][3];
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            M[r][k] = D[r][0] * G[0][k] + D[r][1] * G[1][k] + D[r][2] * G[2][k];
    double omega2 = 3 / mat->def.density * largest_real_eigenvalue(M); /* A / m = 3 / rho */
    double rate = 0;
    if (el->eta > 0) {
        const double viscous[3] = {2, 2, 1};
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++) M[r][k] = viscous[r] * G[r][k];
        rate = 3 / mat->def.density * el->eta * largest_real_eigenvalue(M);
    }
    return damped_mode_stable_dt(omega2, rate);
}

/* log_near1 (log_near1.h) as a function, for the test that holds it to log(). */
double element_log_near1(double J);
double element_log_near1(double J) { return log_near1(J); }

/* Half the stress of a deformation gradient (a b; c d) for Lame constants
 * 2 hlambda, 2 hmu; returns J (and in *invJ_out the 1/J the law used).
 * *w gets the strain energy density per unit initial area. Half, because nodal forces are 1/2 sigma m_a: scaling by a
 * power of two is exact, so this is bit for bit half of sigma and the 0.5
 * costs no multiplications per component. lambda ln J is shared by the
 * stress and the energy. */
TRI_KERNEL double neo_hookean_half(double a, double b, double c, double d, double hlambda,
                                   double hmu, double hs[3], double *w, double *invJ_out)
{
    double J = a * d - b * c;
    double lnJ, invJ;
    neo_hookean_log_inverse(J, J_MIN, &lnJ, &invJ);
    *invJ_out = invJ;
    double B11 = a * a + b * b, B22 = c * c + d * d, B12 = a * c + b * d;
    double hmuJ = hmu * invJ, hl_lnJ = hlambda * lnJ, hvol = hl_lnJ * invJ;
    hs[0] = hmuJ * (B11 - 1) + hvol;
    hs[1] = hmuJ * (B22 - 1) + hvol;
    hs[2] = hmuJ * B12;
    *w = hmu * (B11 + B22 - 2 - 2 * lnJ) + hl_lnJ * lnJ;
    return J;
}

/* The in-situ pre-stress S0 (s0: xx, yy, xy) pushed forward by F = (a b;
 * c d), F S0 F^T / J, times `scale` (1/2 for the half stress, with 1/J as
 * the law takes it below J_MIN), added to hs; returns its strain energy
 * density S0 : E = (tr(F S0 F^T) - tr S0) / 2 (initial_stress.c). */
TRI_KERNEL double prestress_add(double a, double b, double c, double d, double scale,
                                const double s0[3], double hs[3])
{
    double r0 = a * s0[0] + b * s0[2], r1 = a * s0[2] + b * s0[1]; /* first row of F S0 */
    double q0 = c * s0[0] + d * s0[2], q1 = c * s0[2] + d * s0[1]; /* second row */
    double txx = r0 * a + r1 * b, tyy = q0 * c + q1 * d, txy = r0 * c + r1 * d;
    hs[0] += scale * txx;
    hs[1] += scale * tyy;
    hs[2] += scale * txy;
    return 0.5 * (txx + tyy - s0[0] - s0[1]);
}

/* The rate of deformation D = sym([v][x]^-1) of an element on its mid-step
 * configuration x_mid = x - hh v (hh = h_last / 2: the positions halfway
 * along the last step, whose chord velocity v is), as det [x_mid] D in a
 * (D11, D22, D12 times det) and 1 / det in *inv_out, with the mid-step edge
 * vectors in mid (x1, y1, x2, y2); returns 0 (a, inv unset) for a mid-step
 * element of no area. For a rigid motion the chord velocity is W x_mid
 * with W skew (the Cayley transform of the step's rotation), so D = 0 to
 * round-off; on the current geometry it was of order h omega^2 (the spin
 * was damped). The division is paid only by damped elements. */
static inline int rate_of_deformation(const double *v, int n0, int n1, int n2, double hh,
                                   double x1, double y1, double x2, double y2, double mid[4],
                                   double *inv_out, double a[3])
{
    double u1 = v[2 * n1] - v[2 * n0], w1 = v[2 * n1 + 1] - v[2 * n0 + 1];
    double u2 = v[2 * n2] - v[2 * n0], w2 = v[2 * n2 + 1] - v[2 * n0 + 1];
    x1 -= hh * u1;
    y1 -= hh * w1;
    x2 -= hh * u2;
    y2 -= hh * w2;
    mid[0] = x1;
    mid[1] = y1;
    mid[2] = x2;
    mid[3] = y2;
    double det = x1 * y2 - x2 * y1;
    if (!(fabs(det) > 0)) return 0;
    /* det [x]^-1 = (y2 -x2; -y1 x1); det L = [v] det [x]^-1 */
    a[0] = u1 * y2 - u2 * y1;
    a[1] = w2 * x1 - w1 * x2;
    a[2] = 0.5 * ((u2 * x1 - u1 * x2) + (w1 * y2 - w2 * y1));
    *inv_out = 1.0 / det;
    return 1;
}

/* The viscous half stress eta D (D on the mid-step configuration) into hv,
 * the mid-step edges into mid, and the power of the nodal forces of it and
 * of prev (the last step's viscous half stress), both applied on the
 * mid-step edges, with these velocities, added to power[0] and power[1]:
 * sum_a f_a . v_a = -A sigma : L = -det [x_mid] (h : D) = -(h : a) for a
 * half stress h (a = det D: rate_of_deformation). The two powers are the
 * same expression on two stresses, written as a loop over the pair so that
 * the compiler evaluates them side by side in one vector register (each
 * lane rounds exactly as the scalar would, so the damping account keeps its
 * bits; 18.9 -> 17.2 ns per damped element, CPU time). */
static inline void viscous_half(const double *v, int n0, int n1, int n2, double hh, double x1,
                             double y1, double x2, double y2, double eta, const double prev[3],
                             double hv[3], double mid[4], double power[2])
{
    double inv, a[3];
    if (!rate_of_deformation(v, n0, n1, n2, hh, x1, y1, x2, y2, mid, &inv, a)) {
        hv[0] = hv[1] = hv[2] = 0;
        power[0] += 0.0;
        power[1] += 0.0;
        return;
    }
    double scale = eta * inv;
    for (int k = 0; k < 3; k++) hv[k] = scale * a[k];
    const double s0[2] = {hv[0], prev[0]}, s1[2] = {hv[1], prev[1]}, s2[2] = {hv[2], prev[2]};
    for (int k = 0; k < 2; k++) power[k] -= s0[k] * a[0] + s1[k] * a[1] + 2 * s2[k] * a[2];
}

/* Nodal forces 1/2 sigma m_a of a half stress hs on the element with edge
 * vectors (x1, y1), (x2, y2), added to f (node 0 takes minus the sum). */
TRI_KERNEL void edge_traction_forces(double *f, int n0, int n1, int n2, double x1, double y1,
                                     double x2, double y2, const double hs[3])
{
    double f1x = hs[2] * x2 - hs[0] * y2, f1y = hs[1] * x2 - hs[2] * y2;
    double f2x = hs[0] * y1 - hs[2] * x1, f2y = hs[2] * y1 - hs[1] * x1;
    double *g0 = f + 2 * (size_t)n0, *g1 = f + 2 * (size_t)n1, *g2 = f + 2 * (size_t)n2;
    g1[0] += f1x;
    g1[1] += f1y;
    g2[0] += f2x;
    g2[1] += f2y;
    g0[0] -= f1x + f2x;
    g0[1] -= f1y + f2y;
}

/* The same for a damped element: the elastic half stress hs on the current
 * edges and the viscous one hv on the mid-step edges mid, in one scatter
 * (the power booked for hv is that of these forces: viscous_half). The x
 * and y components side by side in one vector register: per component
 * the operations of the scalar expression (hs2 x2 - hs0 y2) + (hv2 mx2 -
 * hv0 my2) and so on, in half the instructions. */
typedef double tri_xy __attribute__((vector_size(16)));
static inline void edge_traction_forces_damped(double *f, int n0, int n1, int n2, double x1,
                                            double y1, double x2, double y2, const double hs[3],
                                            const double mid[4], const double hv[3])
{
    const tri_xy A = {hs[2], hs[1]}, B = {hs[0], hs[2]}, Av = {hv[2], hv[1]}, Bv = {hv[0], hv[2]};
    tri_xy f1 = (x2 * A - y2 * B) + (mid[2] * Av - mid[3] * Bv);
    tri_xy f2 = (y1 * B - x1 * A) + (mid[1] * Bv - mid[0] * Av);
    double *g0 = f + 2 * (size_t)n0, *g1 = f + 2 * (size_t)n1, *g2 = f + 2 * (size_t)n2;
    tri_xy h0, h1, h2;
    memcpy(&h0, g0, sizeof h0);
    memcpy(&h1, g1, sizeof h1);
    memcpy(&h2, g2, sizeof h2);
    h1 += f1;
    h2 += f2;
    h0 -= f1 + f2;
    memcpy(g1, &h1, sizeof h1);
    memcpy(g2, &h2, sizeof h2);
    memcpy(g0, &h0, sizeof h0);
}

/* The hot loop: one pass over the element records, gathering three nodes
 * and scattering three forces each. Per element it is ~80 floating-point
 * operations and one division, so it is bound by the FP ports rather than
 * memory; the shape below is chosen to keep that count low:
 *  - half stress (above), so the 1/2 of 1/2 sigma m_a is free;
 *  - the edge normals opposite nodes 1 and 2 are (-y2, x2) and (y1, -x1),
 *    read straight off the edge vectors; node 0 takes minus the sum of the
 *    other two, which is 1/2 sigma m_0 since m_0 + m_1 + m_2 = 0, and makes
 *    each element's forces sum to exactly zero in floating point;
 *  - the material's constants are reloaded only when the material changes
 *    (elements of a part are contiguous);
 *  - element records are prefetched ahead: on meshes larger than the cache
 *    the loop is too long per element for the hardware prefetcher's window
 *    to keep the record stream ahead of it (1e6 elements: ~17.5 -> ~15 ns
 *    per element-step). */
TRI_KERNEL void
tri_forces(fdem_model *m, int begin, int end_index, const int stressed, const int damped,
           double sums[SCATTER_SUMS])
{
    const double *pos = m->pos, *vel = m->vel;
    /* stressed: this block's pre-stresses, walked alongside the records */
    const double *stress0 = stressed ? m->elem_stress0 + 3 * (size_t)begin : NULL;
    double *f = m->force;
    /* this block's stored viscous stresses, walked alongside the records
     * (restrict: no other array of the loop lives there) */
    double *restrict prev = damped ? m->elem_viscous + 3 * (size_t)begin : NULL;
    const material *mats = m->materials;
    double energy = 0, power[2] = {0, 0}; /* of this step's and the last step's viscous stress */
    int32_t cur_mat = -1;
    double hlambda = 0, hmu = 0;
    const double hh = 0.5 * m->dt_prev; /* x_mid = x - hh v */
    const element_hot *el = m->elem + begin, *end = m->elem + end_index;
    for (; el < end; el++) {
        ELEM_PREFETCH_READ(end - el > ELEM_PREFETCH ? el + ELEM_PREFETCH : el);
        int n0 = el->node[0], n1 = el->node[1], n2 = el->node[2];
        const double *p0 = pos + 2 * (size_t)n0, *p1 = pos + 2 * (size_t)n1,
                     *p2 = pos + 2 * (size_t)n2;
        double x1 = p1[0] - p0[0], y1 = p1[1] - p0[1];
        double x2 = p2[0] - p0[0], y2 = p2[1] - p0[1];
        const double *Xi = el->xinv;
        double a = x1 * Xi[0] + x2 * Xi[2], b = x1 * Xi[1] + x2 * Xi[3];
        double c = y1 * Xi[0] + y2 * Xi[2], d = y1 * Xi[1] + y2 * Xi[3];
        if (el->material != cur_mat) {
            cur_mat = el->material;
            hlambda = 0.5 * mats[cur_mat].lambda;
            hmu = 0.5 * mats[cur_mat].mu;
        }
        double hs[3], w, invJ;
        neo_hookean_half(a, b, c, d, hlambda, hmu, hs, &w, &invJ);
        if (stressed) {
            w += prestress_add(a, b, c, d, 0.5 * invJ, stress0, hs);
            stress0 += 3;
        }
        energy += w * el->area0;
        if (damped && el->eta > 0) {
            /* Damping is booked with the step-averaged velocity, like every
             * work: its forces' power with the velocities before this step
             * now, and with those after it at the next step, from the stored
             * stress on the mid-step geometry then (a step's motion later
             * than the edges it acted on: an error of order h |L|^2 |sigma|
             * A, L the velocity gradient, spin included; element_tet_model.c
             * says when that matters). */
            double hv[3], mid[4];
            viscous_half(vel, n0, n1, n2, hh, x1, y1, x2, y2, el->eta, prev, hv, mid, power);
            prev[0] = hv[0];
            prev[1] = hv[1];
            prev[2] = hv[2];
            edge_traction_forces_damped(f, n0, n1, n2, x1, y1, x2, y2, hs, mid, hv);
        } else {
            edge_traction_forces(f, n0, n1, n2, x1, y1, x2, y2, hs);
        }
        if (damped) prev += 3; /* NULL + 0 would be undefined: undamped models have no array */
    }
    sums[0] += energy;
    sums[1] += power[0];
    sums[2] += power[1];
}

/* A model without a damped element (no elem_viscous: finalize.c) runs a
 * loop with no damping code in it at all: the damped branch, inlined into
 * the one loop, had cost the undamped elements their registers and the
 * stored-stress pointer's walk (issue 38: 1.36x the samples of 7f53400's
 * loop on the same undamped block). Same arithmetic, same bits. */
/* Its own function, so that gcc inlines the damping helpers into it as
 * into the one loop before (beside a second loop in one body it left
 * viscous_half out of line: +10 % instructions a damped element). */
static __attribute__((noinline)) void tri_forces_damped(fdem_model *m, int begin, int end,
                                                        double sums[SCATTER_SUMS])
{
    tri_forces(m, begin, end, 0, 1, sums);
}

void tri_element_forces_range(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    if (m->elem_viscous) tri_forces_damped(m, begin, end, sums);
    else tri_forces(m, begin, end, 0, 0, sums);
}

/* The same loop for the elements of a part with an in-situ stress (rare:
 * one loop for damped and undamped models). */
void tri_element_forces_range_stressed(fdem_model *m, int begin, int end,
                                       double sums[SCATTER_SUMS])
{
    tri_forces(m, begin, end, 1, m->elem_viscous != NULL, sums);
}

void tri_element_stress(const fdem_model *m, int e, double out[3])
{
    const element_hot *el = &m->elem[e];
    const double *pos = m->pos;
    int n0 = el->node[0], n1 = el->node[1], n2 = el->node[2];
    double x0 = pos[2 * n0], y0 = pos[2 * n0 + 1];
    double x1 = pos[2 * n1] - x0, y1 = pos[2 * n1 + 1] - y0;
    double x2 = pos[2 * n2] - x0, y2 = pos[2 * n2 + 1] - y0;
    const double *Xi = el->xinv;
    double a = x1 * Xi[0] + x2 * Xi[2], b = x1 * Xi[1] + x2 * Xi[3];
    double c = y1 * Xi[0] + y2 * Xi[2], d = y1 * Xi[1] + y2 * Xi[3];
    const material *mat = &m->materials[el->material];
    double w, invJ;
    neo_hookean_half(a, b, c, d, 0.5 * mat->lambda, 0.5 * mat->mu, out, &w, &invJ);
    if (m->elem_stress0 && m->parts[m->elem_part[e]].stressed)
        prestress_add(a, b, c, d, 0.5 * invJ, m->elem_stress0 + 3 * (size_t)e, out);
    double inv, D[3], mid[4]; /* the D of the forces: mid-step configuration */
    if (el->eta > 0 &&
        rate_of_deformation(m->vel, n0, n1, n2, 0.5 * m->dt_prev, x1, y1, x2, y2, mid, &inv, D)) {
        double scale = el->eta * inv; /* as viscous_half */
        for (int k = 0; k < 3; k++) out[k] += scale * D[k];
    }
    for (int k = 0; k < 3; k++) out[k] *= 2; /* exact */
}
