/*
 * joint_prestress.c - joints that carry the in-situ stress from t = 0
 * (contract 6.1, PHYSICS "Excavation under in-situ stress").
 *
 * A fracturing part under initial_stress has its elements pre-stressed
 * (initial_stress.c), but a joint's traction is its penalty times its gap,
 * and the gap is zero at t = 0: unloaded joints let every element pop
 * until the penalty catches it, and the block rings, loses its stored
 * energy to damping and can break joints nothing loads. So each joint is
 * given an in-situ gap at each corner: the opening and the slide whose
 * penalty traction k o is sigma.n of the in-situ field on its face (n
 * outward of face A, sigma evaluated at the corner's initial height).
 * Compression is carried by the joint's penalty like tension, and the
 * strength test sees the traction, because the kernels add the gap to the
 * measured one before anything else (joint.c, joint_tet_model.c).
 *
 * Why at the corners and not at the element centroids: the traction is
 * then the field's own, linear along the face and integrated exactly; an
 * element's constant stress sigma(centroid) gives its nodes the integral
 * of sigma grad N exactly, and the divergence theorem leaves each node of
 * the element the integral of div(sigma) N, which lumped gravity balances
 * when div(sigma) + rho g = 0. So a block held by the matching boundary
 * tractions is at rest node by node, gradient and gravity included.
 *
 * The gap is kept in the face's own frame (opening, then slide along the
 * tangent(s)) and turned with the face every step, so the in-situ stress
 * a joint carries turns with the rock as the elements' pre-stress does.
 * The joint's stored energy at t = 0, 1/2 k |o|^2 over the face, is joint
 * energy in the account (energy.c takes it, with these forces, as the
 * reference through joint_prestress_rest_forces).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kernel/joint_tet.h"
#include "math/voigt.h"
#include "model/model.h"
#include "joint.h"

/* The frame of joint j's face A at its initial position, as the kernels
 * build it at a zero gap: frame[0] the normal out of A, then the
 * tangent(s). Returns 0 for a degenerate face. */
static int initial_frame(const fdem_model *m, int j, double frame[3][3])
{
    const int32_t *n = m->joint_node + 2 * (size_t)m->dim * (size_t)j;
    const double *x = m->pos0;
    if (m->dim == 2) {
        double tx = x[2 * n[1]] - x[2 * n[0]], ty = x[2 * n[1] + 1] - x[2 * n[0] + 1];
        double L = hypot(tx, ty);
        if (!(L > 0)) return 0;
        frame[0][0] = ty / L;
        frame[0][1] = -tx / L;
        frame[1][0] = tx / L;
        frame[1][1] = ty / L;
        return 1;
    }
    double d[3][3] = {{0}}, N[3];
    double N_len = joint_tet_gaps(x, n, d, N);
    if (!(N_len > 0)) return 0;
    for (int c = 0; c < 3; c++) frame[0][c] = N[c] / N_len;
    return joint_tet_face_frame(x, n, d, frame[0], frame[1], frame[2]);
}

static const initial_stress_def *stress_def_of_part(const fdem_model *m, int p)
{
    for (int k = 0; k < m->stress0_def_count; k++)
        if (m->stress0_defs[k].part == p) return &m->stress0_defs[k];
    return NULL;
}

/* The pore pressure joint j holds at t = 0 (contract 6.4: its set's or its
 * material's fracture parameters, at the height of face A's centre, as
 * core/fluid evaluates it), 0 without fluid or without one. The fluid
 * pushes the faces apart with it, so the joint itself carries the
 * effective traction sigma . n + p n (Terzaghi): the two together are the
 * rock's sigma . n, and a stressed part with pore pressure is at rest at
 * t = 0 as one without. */
static double joint_pore_pressure0(const fdem_model *m, int j)
{
    if (!m->fluid) return 0;
    int set = m->joint_set_count ? joint_set_index(m, j) : -1;
    const fdem_fracture_params *p =
        set >= 0 ? &m->joint_sets[set].params
                 : &m->materials[element_material(m, m->joint_elem[2 * j])].def.fracture;
    if (!p->has_pore_pressure) return 0;
    const int D = m->dim;
    const int32_t *n = m->joint_node + 2 * (size_t)D * (size_t)j;
    double h = 0;
    for (int i = 0; i < D; i++) h += m->pos0[(size_t)D * (size_t)n[i] + (size_t)(D - 1)];
    h /= D;
    return p->pore_pressure[0] + p->pore_pressure[1] * (h - p->pore_pressure[2]);
}

/* Joint j's in-situ gaps, dim x dim values: corner by corner, the opening
 * and the slide(s) of k o = sigma . n (+ p n with a pore pressure). */
static void joint_offsets(const fdem_model *m, int j, const initial_stress_def *def, double *o)
{
    const int D = m->dim, S = model_stress_comps(m);
    double frame[3][3];
    if (!initial_frame(m, j, frame)) return; /* a face of no area carries nothing */
    const int32_t *n = m->joint_node + 2 * (size_t)D * (size_t)j;
    double k = m->joint_k[j], pore = joint_pore_pressure0(m, j);
    for (int i = 0; i < D; i++) {
        double s[6], t[3];
        initial_stress_at(def, S, m->pos0[(size_t)D * (size_t)n[i] + (size_t)(D - 1)], s);
        voigt_dot(D, s, frame[0], t);
        for (int a = 0; a < D; a++) {
            double along = 0;
            for (int c = 0; c < D; c++) along += t[c] * frame[a][c];
            if (a == 0 && pore != 0) along += pore; /* without: the same bits as before */
            o[D * i + a] = along / k;
        }
    }
}

int joint_prestress_prepare(fdem_model *m, fdem_error *err)
{
    free(m->joint_offset);
    m->joint_offset = NULL;
    int any = 0;
    for (int j = 0; j < m->joint_count && !any; j++)
        any = m->parts[m->elem_part[m->joint_elem[2 * j]]].stressed;
    if (!any) return 0;
    const size_t per = (size_t)m->dim * (size_t)m->dim;
    m->joint_offset = calloc(per * (size_t)m->joint_count, sizeof(double));
    if (!m->joint_offset) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the joints' in-situ gaps");
        return -1;
    }
    for (int j = 0; j < m->joint_count; j++) {
        const initial_stress_def *def = stress_def_of_part(m, m->elem_part[m->joint_elem[2 * j]]);
        if (def) joint_offsets(m, j, def, m->joint_offset + per * (size_t)j);
    }
    return 0;
}

/* 2D joint j's elastic forces at the current positions with its gap,
 * added to the force array; returns its stored energy. */
static double rest_forces_2d(fdem_model *m, int j)
{
    const int32_t *n = m->joint_node + 4 * (size_t)j;
    const double *x = m->pos;
    const double *a0 = x + 2 * (size_t)n[0], *a1 = x + 2 * (size_t)n[1];
    const double *b0 = x + 2 * (size_t)n[2], *b1 = x + 2 * (size_t)n[3];
    double d0[2] = {b0[0] - a0[0], b0[1] - a0[1]}, d1[2] = {b1[0] - a1[0], b1[1] - a1[1]};
    double tx = (a1[0] - a0[0]) + 0.5 * (d1[0] - d0[0]);
    double ty = (a1[1] - a0[1]) + 0.5 * (d1[1] - d0[1]);
    double L = hypot(tx, ty);
    if (!(L > 0)) return 0;
    joint_add_offsets_2d(m->joint_offset + 4 * (size_t)j, tx, ty, L, d0, d1);
    double s = L * m->joint_k[j] / 6, fa[4];
    for (int c = 0; c < 2; c++) {
        fa[c] = s * (2 * d0[c] + d1[c]);
        fa[2 + c] = s * (d0[c] + 2 * d1[c]);
    }
    double *f = m->force;
    for (int i = 0; i < 2; i++)
        for (int c = 0; c < 2; c++) {
            f[2 * (size_t)n[i] + (size_t)c] += fa[2 * i + c];
            f[2 * (size_t)n[2 + i] + (size_t)c] -= fa[2 * i + c];
        }
    return 0.5 * (fa[0] * d0[0] + fa[1] * d0[1] + fa[2] * d1[0] + fa[3] * d1[1]);
}

static double rest_forces_3d(fdem_model *m, int j)
{
    const int32_t *n = m->joint_node + 6 * (size_t)j;
    double d[3][3], N[3], fa[9];
    double N_len = joint_tet_gaps(m->pos, n, d, N);
    if (!joint_tet_add_offsets(m->pos, n, N, N_len, m->joint_offset + 9 * (size_t)j, d)) return 0;
    double stored = joint_tet_elastic_forces(m->joint_k[j], 0.5 * N_len, d, fa);
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++) {
            m->force[3 * (size_t)n[i] + (size_t)c] += fa[3 * i + c];
            m->force[3 * (size_t)n[3 + i] + (size_t)c] -= fa[3 * i + c];
        }
    return stored;
}

/* The joints' forces and stored energy at the current positions as if
 * every intact one were elastic, added to m->force: what the gaps hold at
 * t = 0, for the energy reference (energy_initial). A joint the in-situ
 * stress already loads past its strength breaks in the first step, and
 * its fracture account then books what it held. Returns 0 without gaps. */
double joint_prestress_rest_forces(fdem_model *m)
{
    if (!m->joint_offset) return 0;
    double stored = 0;
    for (int j = 0; j < m->joint_count; j++) {
        if (m->joint_damage[j] >= 1.0) continue;
        stored += m->dim == 3 ? rest_forces_3d(m, j) : rest_forces_2d(m, j);
    }
    return stored;
}
