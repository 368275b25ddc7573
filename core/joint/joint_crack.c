/*
 * joint_crack.c - a crack cut through a model on purpose, for estimates.
 *
 * A short timing of a model before it runs sees its intact rock only: once
 * a crack opens, the elements along it meet through contact, and in 3D a
 * step after a split cost 27x one before it (issue 34). The daemon's
 * sizing prices that phase by timing a throwaway copy with a crack already
 * in it (server/cases/case_sizing.c): every intact joint between two
 * elements whose centroids lie on either side of a plane breaks, as a crack
 * running through the whole body along that plane would. No event is
 * recorded and no energy booked: the model is not meant to run on.
 */
#include <math.h>

#include "fdem.h"
#include "joint.h"
#include "model/model.h"

static void element_centroid(const fdem_model *m, int e, double c[3])
{
    const int32_t *n = element_nodes(m, e);
    c[0] = c[1] = c[2] = 0;
    for (int k = 0; k < m->elem_nodes; k++)
        for (int d = 0; d < m->dim; d++) c[d] += m->pos[m->dim * (size_t)n[k] + d];
    for (int d = 0; d < m->dim; d++) c[d] /= m->elem_nodes;
}

static double plane_side(const fdem_model *m, const double *normal, double offset, int e)
{
    double c[3];
    element_centroid(m, e, c);
    double s = -offset;
    for (int d = 0; d < m->dim; d++) s += normal[d] * c[d];
    return s;
}

/* Intact joint j of two active elements whose centroids lie on either
 * side of the plane. */
static int joint_crosses(const fdem_model *m, int j, const double *normal, double offset)
{
    if (m->joint_damage[j] >= 1.0) return 0;
    int a = m->joint_elem[2 * j], b = m->joint_elem[2 * j + 1];
    if (!element_is_active(m, a) || !element_is_active(m, b)) return 0;
    double sa = plane_side(m, normal, offset, a), sb = plane_side(m, normal, offset, b);
    return (sa < 0 && sb >= 0) || (sa >= 0 && sb < 0);
}

int fdem_joints_across(const fdem_model *m, const double *normal, double offset)
{
    int n = 0;
    for (int j = 0; j < m->joint_count; j++) n += joint_crosses(m, j, normal, offset);
    return n;
}

int fdem_break_joints_across(fdem_model *m, const double *normal, double offset)
{
    int broke = 0;
    for (int j = 0; j < m->joint_count; j++) {
        if (!joint_crosses(m, j, normal, offset)) continue;
        m->joint_damage[j] = 1.0;
        broke++;
    }
    if (!broke) return 0;
    m->broken_joints += broke;
    int fragments = joint_fragment_count(m);
    if (fragments < 0) return -1;
    m->fragments = fragments;
    contact_detect_after_breaks(&m->contact); /* the crack's faces meet through contact */
    return broke;
}

int fdem_break_one_joint(fdem_model *m, int from)
{
    const int J = m->joint_count;
    for (int k = 0; k < J; k++) {
        int j = ((from < 0 ? 0 : from) + k) % J;
        if (m->joint_damage[j] >= 1.0) continue;
        if (!element_is_active(m, m->joint_elem[2 * j]) ||
            !element_is_active(m, m->joint_elem[2 * j + 1]))
            continue;
        m->joint_damage[j] = 1.0;
        m->broken_joints++;
        int fragments = joint_fragment_count(m);
        if (fragments < 0) return -1;
        m->fragments = fragments;
        contact_detect_after_breaks(&m->contact);
        return j;
    }
    return -1;
}

void fdem_force_detection(fdem_model *m)
{
    m->contact.need_detect = m->contact.enabled;
}
