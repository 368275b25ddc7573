/*
 * test_contact_skin.c - a graded mesh's elements each get a skin of their
 * own size (contact_travel.c, contact_skin_init): a small element's circle
 * reaches 0.8 of its radius past it, not 0.4 of the largest radius, and
 * detection is due once a node has gone half the smallest skin around it.
 * Two checks on a fine block thrown at a coarse one, in 2D and 3D, with
 * many detections on the way:
 *  - the protocol itself, at every step: no node of an element is farther
 *    from where the last detection saw it than half that element's skin
 *    (with the limit of one skin for all this fails at the first travel);
 *  - what it is for: every pair of elements of which one has a vertex
 *    inside the other is a candidate pair (brute force over both blocks).
 * The test also checks that the mesh is graded (some skin under the
 * largest), that the blocks met and that detection ran on travel, or it
 * could not fail.
 */
#include "build_model.h"
#include "check.h"
#include "contact/contact.h"
#include "fdem.h"
#include "model/model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A coarse block (a few large elements) and a fine one (elements a tenth
 * its size) flying into it at 12 m/s apart. */
static fdem_model *fine_into_coarse(int dim, int *coarse, int *fine)
{
    fdem_model *m = fdem_model_create();
    fdem_error err = {0};
    if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_material(m, 2700, 1e9, 0.25, 0, 0.3);
    const double oa[3] = {0, 0, 0}, sa[3] = {0.1, 0.05, 0.05}, ob[3] = {0.1005, 0.008, 0.01},
                 sb[3] = {0.03, 0.03, 0.03};
    const int da[3] = {2, 1, 1}, db[3] = {dim == 3 ? 5 : 10, dim == 3 ? 5 : 10, 5};
    *coarse = build_box_at(m, mat, dim, oa, sa, da, 0);
    *fine = build_box_at(m, mat, dim, ob, sb, db, 0);
    const double va[3] = {2.0, 0.5, 0.0}, vb[3] = {-10.0, 0, 0.3};
    if (fdem_set_part_velocity_v(m, *coarse, va, &err) ||
        fdem_set_part_velocity_v(m, *fine, vb, &err))
        build_die("velocity", &err);
    build_finalize(m, 0.5);
    return m;
}

/* The farthest any node of an element has gone from pos_detect, over half
 * the element's skin: at most 1 while the candidate list holds. */
static double worst_travel_over_skin(const fdem_model *m, const double *x)
{
    const contact_state *cs = &m->contact;
    const int D = m->dim, K = m->elem_nodes;
    double worst = 0;
    for (int e = 0; e < m->elem_count; e++) {
        double allow = 0.5 * contact_skin(cs, e);
        const int32_t *node = m->elem_node + (size_t)K * (size_t)e;
        for (int c = 0; c < K; c++) {
            double d2 = 0;
            for (int d = 0; d < D; d++) {
                double u = x[D * node[c] + d] - cs->pos_detect[D * node[c] + d];
                d2 += u * u;
            }
            worst = fmax(worst, sqrt(d2) / allow);
        }
    }
    return worst;
}

static double det3(const double *a, const double *b, const double *c)
{
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/* Point p strictly inside element e (a triangle or a tetrahedron): every
 * barycentric volume has the sign of the whole. */
static int point_inside(const fdem_model *m, const double *x, int e, const double *p)
{
    const int D = m->dim, K = m->elem_nodes;
    const int32_t *n = m->elem_node + (size_t)K * (size_t)e;
    double v[4][3] = {{0}};
    for (int c = 0; c < K; c++)
        for (int d = 0; d < D; d++) v[c][d] = x[D * n[c] + d];
    double q[3] = {p[0], p[1], D == 3 ? p[2] : 0};
    if (D == 2) {
        double whole = (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) -
                       (v[1][1] - v[0][1]) * (v[2][0] - v[0][0]);
        for (int c = 0; c < 3; c++) {
            const double *s = v[(c + 1) % 3], *t = v[(c + 2) % 3];
            double sub = (s[0] - q[0]) * (t[1] - q[1]) - (s[1] - q[1]) * (t[0] - q[0]);
            if (!(sub * whole > 0)) return 0;
        }
        return 1;
    }
    double e1[3], e2[3], e3[3];
    for (int d = 0; d < 3; d++) e1[d] = v[1][d] - v[0][d], e2[d] = v[2][d] - v[0][d], e3[d] = v[3][d] - v[0][d];
    double whole = det3(e1, e2, e3);
    for (int c = 0; c < 4; c++) {
        double w[3][3];
        for (int k = 0, r = 0; k < 4; k++) {
            if (k == c) continue;
            for (int d = 0; d < 3; d++) w[r][d] = v[k][d] - q[d];
            r++;
        }
        /* the sub-volume with p in place of corner c, oriented as the whole */
        double sub = det3(w[0], w[1], w[2]) * ((c & 1) ? -1.0 : 1.0);
        if (!(sub * whole > 0)) return 0;
    }
    return 1;
}

/* Each element's box at x: lo then hi per axis, 6 doubles. */
static void element_boxes(const fdem_model *m, const double *x, double *box)
{
    const int D = m->dim, K = m->elem_nodes;
    for (int e = 0; e < m->elem_count; e++) {
        const int32_t *n = m->elem_node + (size_t)K * (size_t)e;
        double *b = box + 6 * (size_t)e;
        for (int d = 0; d < D; d++) {
            b[d] = b[3 + d] = x[D * n[0] + d];
            for (int c = 1; c < K; c++) {
                double v = x[D * n[c] + d];
                b[d] = v < b[d] ? v : b[d];
                b[3 + d] = v > b[3 + d] ? v : b[3 + d];
            }
        }
    }
}

/* Elements a and b overlap by a vertex of one inside the other. */
static int vertex_inside(const fdem_model *m, const double *x, const double *box, int a, int b)
{
    const int D = m->dim, K = m->elem_nodes;
    const double *ba = box + 6 * (size_t)a, *bb = box + 6 * (size_t)b;
    for (int d = 0; d < D; d++)
        if (ba[d] > bb[3 + d] || bb[d] > ba[3 + d]) return 0;
    for (int k = 0; k < 2; k++) {
        int from = k ? b : a, into = k ? a : b;
        const int32_t *n = m->elem_node + (size_t)K * (size_t)from;
        for (int c = 0; c < K; c++)
            if (point_inside(m, x, into, x + D * n[c])) return 1;
    }
    return 0;
}

static void run_skins(int dim)
{
    int coarse, fine;
    fdem_model *m = fine_into_coarse(dim, &coarse, &fine);
    const contact_state *cs = &m->contact;
    const int E = m->elem_count, D = dim;
    CHECK(cs->skin != NULL, "%dD: the fine block beside the coarse one gives a graded mesh", dim);
    double least = INFINITY;
    for (int e = 0; e < E; e++) least = fmin(least, contact_skin(cs, e));
    CHECK(least < 0.25 * cs->buffer, "%dD: the fine elements' skin %.3g is well under the "
          "largest %.3g", dim, least, cs->buffer);

    int *order = malloc(sizeof(int) * (size_t)E), in_coarse = 0; /* the coarse block's first */
    for (int e = 0; e < E; e++)
        if (m->elem_part[e] == coarse) order[in_coarse++] = e;
    for (int e = 0, k = in_coarse; e < E; e++)
        if (m->elem_part[e] == fine) order[k++] = e;
    uint8_t *listed = calloc((size_t)E * (size_t)E, 1);
    double *box = malloc(sizeof(double) * 6 * (size_t)E);
    double *x = malloc(sizeof(double) * (size_t)D * (size_t)m->node_count);
    double worst = 0;
    long overlaps = 0, missed = 0;
    const double end = 2.5e-3;
    fdem_error err = {0};
    while (fdem_get_time(m) < end) {
        /* the step's contact stage sees the positions it starts from */
        memcpy(x, m->pos, sizeof(double) * (size_t)D * (size_t)m->node_count);
        if (fdem_step(m, &err)) build_die("step", &err);
        worst = fmax(worst, worst_travel_over_skin(m, x));
        element_boxes(m, x, box);
        for (size_t k = 0; k < cs->pairs.count; k++) {
            int a = cs->pairs.a[k], b = cs->pairs.b[k];
            listed[(size_t)a * (size_t)E + (size_t)b] = listed[(size_t)b * (size_t)E + (size_t)a] = 1;
        }
        for (int i = 0; i < in_coarse; i++)
            for (int k = 0; k < E - in_coarse; k++) {
                int a = order[i], b = order[in_coarse + k];
                if (!vertex_inside(m, x, box, a, b)) continue;
                overlaps++;
                missed += !listed[(size_t)a * (size_t)E + (size_t)b];
            }
        for (size_t k = 0; k < cs->pairs.count; k++) {
            int a = cs->pairs.a[k], b = cs->pairs.b[k];
            listed[(size_t)a * (size_t)E + (size_t)b] = listed[(size_t)b * (size_t)E + (size_t)a] = 0;
        }
    }
    CHECK(worst <= 1.0, "%dD: a node went %.3f times half its element's skin from where the "
          "last detection saw it", dim, worst);
    CHECK(cs->detections >= 5, "%dD: %ld detections: the run must re-detect on travel", dim,
          cs->detections);
    CHECK(overlaps > 0, "%dD: the blocks met (%ld element-steps with a vertex inside another)",
          dim, overlaps);
    CHECK(missed == 0, "%dD: %ld of %ld overlapping pairs were not candidates", dim, missed,
          overlaps);
    printf("   %dD: %d elements, skins %.3g-%.3g, %ld detections, worst travel %.3f of the "
           "allowance, %ld overlapping element-steps\n",
           dim, E, least, cs->buffer, cs->detections, worst, overlaps);
    free(listed);
    free(order);
    free(box);
    free(x);
    fdem_model_destroy(m);
}

static void graded_skins_hold_every_overlap_2d(void) { run_skins(2); }
static void graded_skins_hold_every_overlap_3d(void) { run_skins(3); }

CHECK_MAIN(T(graded_skins_hold_every_overlap_2d), T(graded_skins_hold_every_overlap_3d))
