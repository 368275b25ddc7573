/*
 * joint_crack.c - a crack cut through a model on purpose, for estimates.
 *
 * A short timing of a model before it runs sees its intact rock only: once
 * a crack opens, the elements along it meet through contact, and in 3D a
 * step after a split cost 27x one before it (issue 34). The daemon's
 * sizing prices that phase by timing a throwaway copy with a crack already
 * in it (server/cases/case_sizing.c): intact joints between two elements
 * whose centroids lie on either side of a plane break, all of them (a
 * crack running through the whole body along the plane) or the share of
 * them nearest a point (a crack inside the body, which the sizing uses:
 * a body cut in two meets only across the crack's faces, while a crack
 * inside it, as one growing in the run, also brings the elements around
 * its vertices into contact). No event is recorded and no energy booked:
 * the model is not meant to run on.
 */
#include <math.h>
#include <stdlib.h>

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

/* The joints a crack breaks: damage 1, counted, the fragments again, and
 * the contact list mended for them by the next step. */
static int joints_broken_by_a_cut(fdem_model *m, int broke)
{
    if (!broke) return 0;
    m->broken_joints += broke;
    int fragments = joint_fragment_count(m);
    if (fragments < 0) return -1;
    m->fragments = fragments;
    contact_detect_after_breaks(&m->contact); /* the crack's faces meet through contact */
    return broke;
}

static int distance_order(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

int fdem_break_joints_near(fdem_model *m, const double *normal, double offset,
                           const double *centre, double share)
{
    const int D = m->dim;
    double *far = malloc(sizeof(double) * (size_t)(m->joint_count ? m->joint_count : 1));
    double *sorted = malloc(sizeof(double) * (size_t)(m->joint_count ? m->joint_count : 1));
    if (!far || !sorted) {
        free(far);
        free(sorted);
        return -1;
    }
    int crossing = 0;
    for (int j = 0; j < m->joint_count; j++) {
        far[j] = INFINITY;
        if (!joint_crosses(m, j, normal, offset)) continue;
        double ca[3], cb[3], d2 = 0;
        element_centroid(m, m->joint_elem[2 * j], ca);
        element_centroid(m, m->joint_elem[2 * j + 1], cb);
        for (int d = 0; d < D; d++) {
            double u = 0.5 * (ca[d] + cb[d]) - centre[d];
            d2 += u * u;
        }
        far[j] = sorted[crossing++] = d2;
    }
    int broke = 0;
    int keep = (int)ceil(share * crossing);
    if (keep > 0) {
        qsort(sorted, (size_t)crossing, sizeof *sorted, distance_order);
        double reach = sorted[keep - 1];
        for (int j = 0; j < m->joint_count; j++)
            if (far[j] <= reach) {
                m->joint_damage[j] = 1.0;
                broke++;
            }
    }
    free(far);
    free(sorted);
    return joints_broken_by_a_cut(m, broke);
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
    return joints_broken_by_a_cut(m, broke);
}

int fdem_break_one_joint(fdem_model *m, int from, const double *avoid_normal,
                         double avoid_offset)
{
    const int J = m->joint_count;
    for (int k = 0; k < J; k++) {
        int j = ((from < 0 ? 0 : from) + k) % J;
        if (m->joint_damage[j] >= 1.0) continue;
        if (avoid_normal && joint_crosses(m, j, avoid_normal, avoid_offset)) continue;
        if (!element_is_active(m, m->joint_elem[2 * j]) ||
            !element_is_active(m, m->joint_elem[2 * j + 1]))
            continue;
        m->joint_damage[j] = 1.0;
        return joints_broken_by_a_cut(m, 1) < 0 ? -1 : j;
    }
    return -1;
}

void fdem_price_cracks_open(fdem_model *m, int open) { m->contact.shut_off = open != 0; }

void fdem_force_detection(fdem_model *m)
{
    m->contact.need_detect = m->contact.enabled;
}
