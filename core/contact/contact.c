/*
 * contact.c - the contact stage of either dimension: when to run detection,
 * which candidate pairs it finds, and the stage's entry point (detection,
 * then the near list, then the pair walk of contact_walk.c). The force
 * between two elements is a dimension's kernel (contact_pair.h): triangles
 * in contact_tri.c, tetrahedra in contact_tet.c; everything else is the
 * same algorithm for both and is written here once.
 *
 * Detection (nbs.c, nbs_3d.c) runs on bounding circles or spheres inflated
 * by a buffer, and only again once some node has moved more than half the
 * buffer since the last run: until then every pair that can overlap is
 * already a candidate. Each step the candidates whose element boxes overlap
 * go to the kernel; their forces are added to the contact force array in
 * pair order, on one thread or several (each thread lists its touching
 * pairs, the lists are added in thread order): the same bits on any thread
 * count.
 *
 * Most candidate pairs are far from touching, so the per-step walk takes
 * only the "near" pairs (contact_near.c), and gets the same bits as walking
 * every pair.
 *
 * Friction's stick springs (contact_pair.h) are kept per candidate pair, a
 * dimension's count of slots each (cs->slots), across steps, detections and
 * checkpoints (contact_history.c); a pair whose boxes part lets them go.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "kernel/contact_pair.h"
#include "model/model.h"
#include "parallel/team.h"
#include "contact.h"
#include "contact_internal.h"
#include "joint/joint.h"
#include "parallel/scatter_plan.h"

/* The near list (see the top of contact_near.c) is rebuilt every near_step x
 * buffer of travel (detection comes at buffer/2) and holds the pairs whose
 * boxes are within twice that: a shorter reach is more rebuilds and fewer
 * pairs and boxes each step. A disc pile's near pairs mostly touch, so
 * 1/16 and 1/64 walk about as much (callgrind: +0.3 % at 1/64); a
 * tetrahedron's loose sphere gives ~25 candidates an element in a sphere
 * pile and under 0.05 touching, and 1/64 walks far fewer of them (4k-element
 * pile: boxes 157M -> 25M instructions in 493 steps, whole step -10 %;
 * 1/128 gained no more). */
static const contact_kernel contact_kernels[2] = {
    {TRI_CONTACT_SLOTS, TRI_PAIR_OUT, tri_contact_pair_force, tri_contact_pair_clearance, 0.25,
     1.0 / 16},
    {TET_CONTACT_SLOTS, TET_PAIR_OUT, tet_contact_pair_force, tet_contact_pair_clearance, 0.153,
     1.0 / 64},
};

/* Force between two elements whose boxes overlap, both roles, into out
 * (pair_out numbers); springs are the pair's stick springs (updated), h the
 * last step's size, memo the walk's (contact_pair.h; NULL: none). Returns
 * 1 if they touched. Writes nothing in m. */
static int contact_pair_force(const fdem_model *m, int e1, int e2, double h, double *springs,
                              double *out, contact_pair_memo *memo)
{
    contact_pair_in in = contact_pair_input(m, e1, e2, h, memo);
    return m->contact.kernel->pair_force(&in, springs, out);
}

/* Force between two elements, both roles, added to the contact force
 * array, with no friction history (for tests). Returns 1 if they touched. */
int contact_potential_force(fdem_model *m, int e1, int e2, double h)
{
    double b1[6] = {0}, b2[6] = {0}, out[CONTACT_PAIR_OUT_MAX], springs[CONTACT_SLOTS_MAX] = {0};
    element_box(m, e1, b1);
    element_box(m, e2, b2);
    if (!boxes_overlap(b1, b2, m->dim) || !contact_pair_force(m, e1, e2, h, springs, out, NULL))
        return 0;
    contact_pair_scatter(m, e1, e2, out);
    return 1;
}

/* The bounding circle (2D) or sphere (3D) of element e at positions p:
 * centred on the centroid, through the farthest node. */
static void element_sphere(const fdem_model *m, const double *p, int e, double centre[3],
                           double *r)
{
    const int D = m->dim, K = m->elem_nodes;
    const int32_t *n = element_nodes(m, e);
    double x[3] = {0, 0, 0};
    for (int c = 0; c < K; c++)
        for (int d = 0; d < D; d++) x[d] += p[D * n[c] + d];
    for (int d = 0; d < D; d++) x[d] /= K;
    double r2 = 0;
    for (int c = 0; c < K; c++) {
        double s = 0;
        for (int d = 0; d < D; d++) {
            double dx = p[D * n[c] + d] - x[d];
            s += dx * dx;
        }
        r2 = fmax(r2, s);
    }
    for (int d = 0; d < 3; d++) centre[d] = x[d];
    *r = sqrt(r2);
}

/* Gives back what a pair list no longer needs once the glued pairs have
 * left it: in an intact fracturing block nearly every pair the spheres
 * found is glued (in 3D ~1.3-1.6 kB an element, more than half the
 * model), held until the next detection for nothing. A list at most a
 * quarter full is cut to twice its pairs; the next detection grows it
 * again as it grew it first (doubling). */
static void contact_pairs_fit(nbs_pairs *pairs)
{
    if (pairs->count > pairs->capacity / 4) return;
    size_t keep = 2 * pairs->count > 64 ? 2 * pairs->count : 64;
    if (keep >= pairs->capacity) return;
    int32_t *a = realloc(pairs->a, keep * sizeof *a);
    if (!a) return;
    pairs->a = a;
    pairs->capacity = keep; /* b may stay longer if its shrink fails */
    int32_t *b = realloc(pairs->b, keep * sizeof *b);
    if (b) pairs->b = b;
}

/* Pairs of elements glued by intact joints never contact: they leave the
 * candidate list (cs->piece and the broken vertices are this detection's:
 * contact_detect_bodies). */
static void contact_drop_joined(fdem_model *m)
{
    contact_state *cs = &m->contact;
    size_t kept = 0;
    for (size_t k = 0; k < cs->pairs.count; k++) {
        int a = cs->pairs.a[k], b = cs->pairs.b[k];
        if (contact_pair_joined(m, cs->piece, a, b)) continue;
        cs->pairs.a[kept] = cs->pairs.a[k];
        cs->pairs.b[kept] = cs->pairs.b[k];
        kept++;
    }
    cs->pairs.count = kept;
    contact_pairs_fit(&cs->pairs);
}

/* Candidate pair k's force now, both roles, into out (pair_out numbers),
 * on a copy of its stick springs: nothing in m changes. 1 if they touch. */
int contact_pair_force_now(const fdem_model *m, size_t k, double *out)
{
    const contact_state *cs = &m->contact;
    int a = cs->pairs.a[k], b = cs->pairs.b[k];
    double ba[6] = {0}, bb[6] = {0}, springs[CONTACT_SLOTS_MAX] = {0};
    element_box(m, a, ba);
    element_box(m, b, bb);
    if (!boxes_overlap(ba, bb, m->dim)) return 0;
    int32_t set = k < cs->pair_capacity ? cs->spring_of[k] : -1;
    if (set >= 0)
        memcpy(springs, cs->slip + (size_t)cs->slots * (size_t)set, sizeof(double) * (size_t)cs->slots);
    return contact_pair_force(m, a, b, m->dt_prev, springs, out, NULL);
}

/* The body ids this detection runs on: with joints, the pieces of this
 * moment (joint_contact_bodies), so that detection never lists the pairs
 * inside a piece away from its cracks, which contact_drop_joined would
 * drop: an intact fracturing block's detection was almost all listing and
 * dropping those (3D: ~100 pairs an element, each looked up in the joints). */
void contact_mark_cracks(fdem_model *m, int32_t *piece)
{
    contact_state *cs = &m->contact;
    /* the contact force array (D doubles a node) is free until this step's
     * pairs fill it: the crack marks take 4 int32 a node of it as scratch */
    joint_mark_cracks(m, piece, (int32_t *)cs->force);
    memset(cs->force, 0, sizeof(double) * (size_t)m->dim * (size_t)m->node_count);
    cs->force_is_zero = 1;
}

static const int32_t *contact_detect_bodies(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (!m->joint_count) return cs->body;
    contact_mark_cracks(m, cs->piece);
    joint_contact_bodies(m, cs->piece, cs->body, cs->detect_body);
    return cs->detect_body;
}

/* Candidate pairs from the bounding circles or spheres of the elements at
 * `pos` (the current positions, or a checkpoint's positions at its last
 * detection), with the stick springs of the pairs that stay. */
static int contact_detect_at(fdem_model *m, const double *pos)
{
    contact_state *cs = &m->contact;
    if (contact_springs_sync(m) || contact_history_set_aside(cs)) return -1;
    for (int e = 0; e < m->elem_count; e++) {
        double c[3];
        element_sphere(m, pos, e, c, &cs->r[e]);
        cs->cx[e] = c[0];
        cs->cy[e] = c[1];
        if (cs->cz) cs->cz[e] = c[2];
        cs->r[e] += 0.5 * contact_skin(cs, e);
    }
    const int32_t *body = contact_detect_bodies(m);
    size_t n = (size_t)m->elem_count;
    int failed = m->dim == 3 ? nbs_detect_classes_3d(&cs->classes, &cs->grid3, n, cs->cx, cs->cy,
                                                     cs->cz, cs->r, body, &cs->pairs)
                             : nbs_detect_classes(&cs->classes, &cs->grid, n, cs->cx, cs->cy,
                                                  cs->r, body, &cs->pairs);
    if (failed) return -1;
    if (m->elem_active) contact_drop_excavated(m);
    if (m->joint_count) {
        contact_drop_joined(m);
        if (contact_pairs_order(m)) return -1; /* the order a break's mending keeps */
    }
    if (contact_history_take_back(cs)) return -1;
    cs->active_count =
        contact_collect_elements(cs, m->elem_count, NULL, cs->pairs.count, NULL, 0, cs->active);
    if (pos != cs->pos_detect)
        memcpy(cs->pos_detect, pos, sizeof(double) * (size_t)m->dim * (size_t)m->node_count);
    cs->need_detect = 0;
    cs->near_stale = 1;
    cs->detections++;
    contact_breaks_remember(m);
    return 0;
}

int contact_detect_again(fdem_model *m) { return contact_detect_at(m, m->contact.pos_detect); }

static int contact_detect(fdem_model *m)
{
    if (contact_detect_at(m, m->pos)) return -1;
    m->contact.max_disp2 = 0;
    return 0;
}

/* After a checkpoint restore: the candidate pairs of the last detection
 * before it (same circles, same joints, so the same list in the same
 * order: the run goes on bit for bit), with the stick springs the
 * checkpoint held, waiting in the records. */
int contact_restore_detection(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (!cs->enabled) return 0;
    cs->pairs.count = 0;
    cs->near_stale = 1;
    cs->springs_behind = 0; /* the checkpoint's records hold every spring */
    memset(cs->force, 0, sizeof(double) * (size_t)m->dim * (size_t)m->node_count);
    cs->force_is_zero = 1;
    int pending = cs->need_detect;
    if (pending == CONTACT_DETECT_ALL) return 0; /* the next step detects anyway */
    long detections = cs->detections;
    if (contact_detect_at(m, cs->pos_detect)) return -1;
    cs->detections = detections;
    /* a break waiting: its step still counts its (now empty) mending */
    cs->need_detect = pending;
    return 0;
}

int contact_init(fdem_model *m, fdem_error *err)
{
    contact_state *cs = &m->contact;
    int fracture = 0;
    for (int k = 0; k < m->part_count; k++) fracture |= m->parts[k].fracture;
    cs->kernel = &contact_kernels[m->dim == 3];
    cs->slots = cs->kernel->slots;
    cs->pair_out = cs->kernel->pair_out;
    cs->enabled = m->part_count > 1 || fracture;
    if (!cs->enabled) return 0;
    size_t E = (size_t)m->elem_count, N = (size_t)m->node_count, D = (size_t)m->dim;
    cs->cx = malloc(sizeof(double) * E);
    cs->cy = malloc(sizeof(double) * E);
    cs->cz = D == 3 ? malloc(sizeof(double) * E) : NULL;
    cs->r = malloc(sizeof(double) * E);
    cs->body = malloc(sizeof(int32_t) * E);
    cs->piece = malloc(sizeof(int32_t) * E);
    cs->detect_body = malloc(sizeof(int32_t) * E);
    cs->pos_detect = malloc(sizeof(double) * D * N);
    cs->pos_near = malloc(sizeof(double) * D * N);
    cs->force = calloc(D * N, sizeof(double));
    cs->force_is_zero = 1;
    cs->box = malloc(sizeof(double) * 2 * D * E);
    cs->active = malloc(sizeof(int32_t) * E);
    cs->near_active = malloc(sizeof(int32_t) * E);
    cs->elem_gap = malloc(sizeof(double) * E);
    cs->in_pair = malloc(E);
    if (!cs->cx || !cs->cy || (D == 3 && !cs->cz) || !cs->r || !cs->body || !cs->piece ||
        !cs->detect_body ||
        !cs->pos_detect || !cs->pos_near || !cs->force || !cs->box || !cs->active || !cs->near_active || !cs->elem_gap ||
        !cs->in_pair) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for contact detection");
        return -1;
    }
    /* Elements of one unbroken part never touch each other; those of a
     * fracturing part each count as a body of their own. */
    for (int e = 0; e < m->elem_count; e++) {
        int p = m->elem_part[e];
        cs->body[e] = m->parts[p].fracture ? m->part_count + e : p;
    }
    if (joint_region_bodies(m, cs->body)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for contact detection");
        return -1;
    }
    double rmax = 0;
    for (int e = 0; e < m->elem_count; e++) {
        double c[3];
        element_sphere(m, m->pos, e, c, &cs->r[e]);
        rmax = fmax(rmax, cs->r[e]);
    }
    if (contact_shut_init(m) || contact_skin_init(m, rmax) || contact_breaks_init(m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for contact detection");
        return -1;
    }
    cs->need_detect = 1;
    /* the integrator measures from here until the first near list */
    memcpy(cs->pos_near, m->pos, sizeof(double) * D * N);
    cs->near_disp2 = 0;
    return 0;
}

void contact_free(contact_state *cs)
{
    free(cs->cx); free(cs->cy); free(cs->cz); free(cs->r); free(cs->body); free(cs->piece); free(cs->detect_body);
    free(cs->pos_detect); free(cs->pos_near); free(cs->force);
    free(cs->skin); free(cs->travel_weight);
    contact_breaks_free(cs);
    free(cs->box); free(cs->active); free(cs->near_active); free(cs->elem_gap); free(cs->in_pair);
    free(cs->near); /* near_vertex is its end */
    free(cs->vertex_start);
    free(cs->vertex_pairs);
    free(cs->vertex_walk);
    free(cs->vertex_due);
    contact_shut_free(cs);
    contact_walk_free(cs);
    free(cs->slip);
    free(cs->spring_of);
    free(cs->slip_free);
    free(cs->records);
    nbs_grid_free(&cs->grid);
    nbs_grid_3d_free(&cs->grid3);
    nbs_classes_free(&cs->classes);
    nbs_pairs_free(&cs->pairs);
    memset(cs, 0, sizeof *cs);
}

double contact_stable_dt(const fdem_model *m)
{
    if (!m->contact.enabled) return INFINITY;
    /* A face pressed a depth d into a triangle of altitude h is pushed back
     * with p 3 d / h from each side, so a corner node of an element of
     * size h, on two such faces, feels a spring of up to about 16 p / (rho
     * h^2) per unit mass: omega dt = 2, the stability limit, at
     * 0.5 h sqrt(rho / p). The contact step is half that, 0.25 h
     * sqrt(rho / p) (omega dt = 1): a penalty switching on within a step
     * adds energy well before the step goes unstable, and flat impacts of
     * shared-node and fracturing blocks (test_contact.c) keep their energy
     * within 1 % at this step, while 1.8 x it (0.45, the factor of
     * 7f53400) gained 8-21 %. fdem_auto_dt never exceeds this step and
     * scales the limit (CONTACT_STABLE_OVER_STEP x it) by the safety. A
     * tetrahedron's potential is steeper (p 4 d / h), and its corner node
     * (mass rho h^3 / 24 against rho h^2 / 6) sits on three faces of area
     * h^2 / 2 (a third each): 8/3 times the stiffness per unit mass, so the
     * factor is 0.25 sqrt(3/8) = 0.153 (test_contact_3d.c's flat impacts). */
    double dt = INFINITY, factor = m->contact.kernel->dt_factor;
    for (int e = 0; e < m->elem_count; e++) {
        const material *mat = &m->materials[element_material(m, e)];
        dt = fmin(dt, factor * m->elem_h[e] * sqrt(mat->def.density / mat->penalty));
    }
    return dt;
}

/* The walk's lists (contact_walk.c), the stick springs (a set index per candidate
 * pair, slots doubles per set in the pool: only pairs that touch hold a
 * set), the records set aside across a detection and the near list. */
size_t contact_memory_bytes(const contact_state *cs)
{
    size_t b = contact_walk_bytes(cs);
    b += cs->pair_capacity * sizeof(int32_t);
    b += cs->slip_capacity * (sizeof(double) * (size_t)cs->slots + sizeof(int32_t));
    b += cs->record_capacity * sizeof(contact_record);
    b += cs->near_capacity * sizeof(near_pair); /* near_vertex is its end */
    b += cs->vertex_pairs_capacity * sizeof(int32_t) + cs->vertex_walk_capacity * sizeof(int32_t);
    b += cs->vertex_due_capacity; /* vertex_start: an int32 an element, with the element arrays */
    /* contact_breaks.c: the spare and mended lists, and its arrays */
    b += 2 * (cs->spare.capacity + cs->fresh.capacity) * sizeof(int32_t) + cs->breaks_bytes;
    return b;
}

/* The contact force array zeroed, in a share per thread: on one thread
 * alone it was a thirtieth of a broken 2D block's step on two. */
static void contact_force_clear(fdem_model *m)
{
    const int threads = m->threads > 1 && m->node_count > CONTACT_THREADED_NODES ? m->threads : 1;
    parallel_zero(m->contact.force, (size_t)m->dim * (size_t)m->node_count, threads);
}

/* Detection when due, then every candidate pair's force. The stick springs
 * are loaded by the motion of the last step (m->dt_prev). Returns 0, or -1
 * when out of memory. */
int contact_forces(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (!cs->enabled) return 0;
    int all = cs->need_detect == CONTACT_DETECT_ALL || contact_travel_past(m, cs->travel_limit2);
    if (all || cs->need_detect) {
        double t0 = stage_clock();
        if (all ? contact_detect(m) : contact_detect_breaks(m)) return -1;
        double spent = stage_clock() - t0;
        m->times.detection += spent;
        m->times.contact -= spent; /* the caller books the whole call as contact */
    }
    /* With no candidate pair (bodies apart, an intact fracturing block) the
     * force array stays zero, and the integrator skips reading it. */
    if (!cs->force_is_zero) contact_force_clear(m);
    cs->force_is_zero = cs->pairs.count == 0;
    /* the shut marks first: they say which boxes the near list needs */
    contact_shut_refresh(m);
    if (contact_near_refresh(m)) return -1;
    contact_vertex_due(m);
    int touching = contact_pairs_forces(m, m->dt_prev);
    if (touching < 0) return -1;
    cs->touching = touching;
    return 0;
}
