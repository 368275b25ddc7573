/*
 * contact.c - contact between finite elements of different bodies: when to
 * run detection, and the distributed potential contact force of Munjiza &
 * Andrews (2000) with Coulomb friction.
 *
 * Detection (nbs.c) runs on bounding circles inflated by a buffer, and only
 * again once some node has moved more than half the buffer since the last
 * run: until then every pair that can overlap is already a candidate.
 *
 * Force. Each triangle carries the potential phi = 3 min_k lambda_k (lambda
 * the area coordinates): 1 at the centroid, 0 on the boundary. The force on
 * a contactor c from a target t is -p * integral over the overlap of
 * grad phi_t, which the divergence theorem turns into an integral along the
 * contactor's edges inside t:  F = -p * integral (phi_t n_c) ds. phi_t is
 * piecewise linear along an edge (it changes branch where two area
 * coordinates cross), so the integral and its first moment are exact sums.
 * The resultant acts at the potential's centroid s* along the edge: it is
 * shared by the edge's two nodes by lever rule, and the equal and opposite
 * force goes to the target's nodes by the area coordinates of that same
 * point. Action equals reaction at one point, so both linear and angular
 * momentum are conserved to round-off. Then the roles swap.
 *
 * Friction is Coulomb with elastic stick (PHYSICS.md, "Friction"): each
 * contactor edge of a pair carries a tangential spring, loaded by the
 * relative tangential displacement at the point of action and capped at
 * mu Fn, beyond which the surfaces slide and the spring stays at the cap.
 * The spring's stiffness is 2/3 of the normal one, p L / (h/3) for the
 * length L of the edge inside the target of smallest altitude h, so it adds
 * nothing to the stable step; its force is kept per pair across steps
 * (contact_history.c). A block on a slope below its friction angle then
 * stays put for as long as one runs it, whatever the step; the energy that
 * sliding dissipates, cap x slip, is booked in the friction account.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "model.h"

/* Fewer candidate pairs than this are evaluated on one thread: below it the
 * threads' start-up costs more than they share. */
#define CONTACT_THREADED_PAIRS 2048

/* What a pair's evaluation hands back: two forces per corner of e1, then of
 * e2, then the energy friction dissipated. */
#define PAIR_OUT 13
#define PAIR_DISSIPATED 12

/* A thread's pairs that touched, in pair order, with their forces. */
typedef struct contact_touch {
    long pair;
    double force[PAIR_OUT];
} contact_touch;

typedef struct contact_touches {
    contact_touch *item;
    size_t count, capacity;
} contact_touches;

/* The current geometry of one triangle, gathered once per pair. */
typedef struct tri_now {
    int node[3];
    double x[3], y[3];
    double area2;       /* twice the signed area (> 0 unless inverted) */
    double penalty, friction;
} tri_now;

/* libm's fmin/fmax are calls unless NaN semantics are relaxed; these are not. */
static inline double min2(double a, double b) { return a < b ? a : b; }
static inline double max2(double a, double b) { return a > b ? a : b; }
static inline double min3(double a, double b, double c) { return min2(a, min2(b, c)); }
static inline double max3(double a, double b, double c) { return max2(a, max2(b, c)); }

static inline void tri_gather(const fdem_model *m, int e, tri_now *t)
{
    const element_hot *el = &m->elem[e];
    for (int c = 0; c < 3; c++) {
        t->node[c] = el->node[c];
        t->x[c] = m->pos[2 * el->node[c]];
        t->y[c] = m->pos[2 * el->node[c] + 1];
    }
}

/* The rest of the record, needed only for pairs whose boxes overlap. */
static inline void tri_complete(const fdem_model *m, int e, tri_now *t)
{
    const material *mat = &m->materials[m->elem[e].material];
    t->area2 = (t->x[1] - t->x[0]) * (t->y[2] - t->y[0]) - (t->y[1] - t->y[0]) * (t->x[2] - t->x[0]);
    t->penalty = mat->penalty;
    t->friction = mat->def.friction;
}

/* Area coordinates of (px, py) in t: lambda_k belongs to node k. */
static inline void area_coordinates(const tri_now *t, double px, double py, double l[3])
{
    double inv = 1.0 / t->area2;
    for (int k = 0; k < 3; k++) {
        int i = (k + 1) % 3, j = (k + 2) % 3;
        l[k] = ((t->x[i] - px) * (t->y[j] - py) - (t->y[i] - py) * (t->x[j] - px)) * inv;
    }
}

/* Integral over s in [0,1] of phi(s) = 3 min_k lambda_k(s), clipped to where
 * all lambda_k >= 0, its first moment, and the fraction of the edge inside.
 * Returns 0 when the edge misses. */
static int edge_potential_integral(const double la[3], const double lb[3], double *i0, double *i1,
                                   double *inside)
{
    double smin = 0, smax = 1;
    for (int k = 0; k < 3; k++) {
        if (la[k] < 0 && lb[k] < 0) return 0;
        if (la[k] < 0) smin = max2(smin, la[k] / (la[k] - lb[k]));
        else if (lb[k] < 0) smax = min2(smax, la[k] / (la[k] - lb[k]));
    }
    if (!(smax > smin)) return 0;

    double s[5];
    int n = 0;
    s[n++] = smin;
    for (int k = 0; k < 3; k++) { /* where two coordinates cross, phi changes branch */
        int j = (k + 1) % 3;
        double denom = (lb[k] - la[k]) - (lb[j] - la[j]);
        if (fabs(denom) < 1e-300) continue;
        double sc = (la[j] - la[k]) / denom;
        if (sc > smin && sc < smax) s[n++] = sc;
    }
    s[n++] = smax;
    for (int a = 1; a < n; a++) /* insertion sort of at most 5 */
        for (int b = a; b > 0 && s[b] < s[b - 1]; b--) {
            double tmp = s[b]; s[b] = s[b - 1]; s[b - 1] = tmp;
        }
    double sum0 = 0, sum1 = 0, prev_s = s[0];
    double prev_phi = 3 * max2(0, min3(la[0] + prev_s * (lb[0] - la[0]), la[1] + prev_s * (lb[1] - la[1]),
                                       la[2] + prev_s * (lb[2] - la[2])));
    for (int a = 1; a < n; a++) {
        double sa = s[a];
        double phi = 3 * max2(0, min3(la[0] + sa * (lb[0] - la[0]), la[1] + sa * (lb[1] - la[1]),
                                      la[2] + sa * (lb[2] - la[2])));
        double ds = sa - prev_s;
        sum0 += 0.5 * ds * (prev_phi + phi);
        sum1 += ds / 6.0 * (prev_phi * (2 * prev_s + sa) + phi * (prev_s + 2 * sa));
        prev_s = sa;
        prev_phi = phi;
    }
    *i0 = sum0;
    *i1 = sum1;
    *inside = smax - smin;
    return sum0 > 0;
}

/* The friction force on edge (na, nb) of a contactor, acting at sbar along
 * it and lbar in the target t: the edge's stick spring `spring` is loaded
 * by the relative tangential displacement of the last step (velocity times
 * h, the last step's size), capped at mu Fn; *dissipated gets cap x slip. */
static double friction_force(const fdem_model *m, const tri_now *t, int na, int nb, double sbar,
                             const double lbar[3], double tx, double ty, double k_t, double cap,
                             double h, double *spring, double *dissipated)
{
    const double *v = m->vel;
    double vcx = (1 - sbar) * v[2 * na] + sbar * v[2 * nb];
    double vcy = (1 - sbar) * v[2 * na + 1] + sbar * v[2 * nb + 1];
    double vtx = 0, vty = 0;
    for (int k = 0; k < 3; k++) {
        vtx += lbar[k] * v[2 * t->node[k]];
        vty += lbar[k] * v[2 * t->node[k] + 1];
    }
    double slide = ((vcx - vtx) * tx + (vcy - vty) * ty) * h;
    double f = *spring - k_t * slide;
    if (fabs(f) > cap) {
        *dissipated += cap * (fabs(f) - cap) / k_t;
        f = f > 0 ? cap : -cap;
    }
    *spring = f;
    return f;
}

/* Forces of target t's potential on contactor c's edges, added to fc (two
 * per corner of c), and their reactions on t, added to ft; springs holds the
 * stick springs of c's three edges against t (updated; an edge that does not
 * touch lets its spring go) and *dissipated gets what friction dissipated.
 * Returns 1 if any force acted. Reads the model, writes nothing in it:
 * pairs can be evaluated side by side. */
static int contactor_against_target(const fdem_model *m, const tri_now *c, const tri_now *t,
                                    double penalty, double friction, double h, double springs[3],
                                    double fc[6], double ft[6], double *dissipated)
{
    double lam[3][3];
    for (int i = 0; i < 3; i++) area_coordinates(t, c->x[i], c->y[i], lam[i]);
    double stiffness = 0; /* p / (h_t / 3), h_t the target's smallest altitude */
    int acted = 0;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        double i0, i1, inside;
        if (!edge_potential_integral(lam[i], lam[j], &i0, &i1, &inside)) {
            springs[i] = 0;
            continue;
        }
        acted = 1;
        double ex = c->x[j] - c->x[i], ey = c->y[j] - c->y[i];
        double len = hypot(ex, ey);
        double sbar = i1 / i0;
        /* normal: -p * i0 * (length-scaled outward normal) */
        double fx = -penalty * i0 * ey, fy = penalty * i0 * ex;
        double lbar[3];
        for (int k = 0; k < 3; k++) lbar[k] = lam[i][k] + sbar * (lam[j][k] - lam[i][k]);
        int na = c->node[i], nb = c->node[j];
        if (friction > 0 && len > 0) {
            if (stiffness == 0) {
                double dx0 = t->x[1] - t->x[0], dy0 = t->y[1] - t->y[0];
                double dx1 = t->x[2] - t->x[1], dy1 = t->y[2] - t->y[1];
                double dx2 = t->x[0] - t->x[2], dy2 = t->y[0] - t->y[2];
                double longest2 = max3(dx0 * dx0 + dy0 * dy0, dx1 * dx1 + dy1 * dy1,
                                       dx2 * dx2 + dy2 * dy2);
                stiffness = 3 * penalty * sqrt(longest2) / t->area2;
            }
            double tx = ex / len, ty = ey / len;
            double k_t = (2.0 / 3.0) * stiffness * inside * len;
            double f_t = friction_force(m, t, na, nb, sbar, lbar, tx, ty, k_t,
                                        friction * penalty * i0 * len, h, &springs[i], dissipated);
            fx += f_t * tx;
            fy += f_t * ty;
        } else {
            springs[i] = 0;
        }
        fc[2 * i] += (1 - sbar) * fx;
        fc[2 * i + 1] += (1 - sbar) * fy;
        fc[2 * j] += sbar * fx;
        fc[2 * j + 1] += sbar * fy;
        for (int k = 0; k < 3; k++) {
            ft[2 * k] -= lbar[k] * fx;
            ft[2 * k + 1] -= lbar[k] * fy;
        }
    }
    return acted;
}

/* Axis-aligned boxes (xmin, xmax, ymin, ymax) that overlap or touch. */
static inline int boxes_overlap(const double *a, const double *b)
{
    return !(a[1] < b[0] || b[1] < a[0] || a[3] < b[2] || b[3] < a[2]);
}

static inline void element_box(const fdem_model *m, int e, double b[4])
{
    const double *p = m->pos;
    const int32_t *n = m->elem[e].node;
    double x0 = p[2 * n[0]], y0 = p[2 * n[0] + 1], x1 = p[2 * n[1]], y1 = p[2 * n[1] + 1];
    double x2 = p[2 * n[2]], y2 = p[2 * n[2] + 1];
    b[0] = min3(x0, x1, x2);
    b[1] = max3(x0, x1, x2);
    b[2] = min3(y0, y1, y2);
    b[3] = max3(y0, y1, y2);
}

/* The current box of every element in some candidate pair. Most candidate
 * pairs do not touch (their bounding circles, inflated by the buffer,
 * overlap; their triangles do not): the box test then reads two 32-byte
 * boxes instead of two element records and six scattered nodes. */
static void contact_boxes(fdem_model *m)
{
    contact_state *cs = &m->contact;
    const int32_t *active = cs->active;
    double *box = cs->box;
    int count = cs->active_count;
#pragma omp parallel for num_threads(m->threads) if (m->threads > 1 && count > 4096) \
    schedule(static)
    for (int k = 0; k < count; k++) element_box(m, active[k], box + 4 * (size_t)active[k]);
}

/* The elements of the candidate pairs, once each and in element order (so
 * that contact_boxes walks the mesh forwards), for contact_boxes. */
static void contact_collect_active(contact_state *cs, int elem_count)
{
    memset(cs->in_pair, 0, (size_t)elem_count);
    for (size_t k = 0; k < cs->pairs.count; k++) {
        cs->in_pair[cs->pairs.a[k]] = 1;
        cs->in_pair[cs->pairs.b[k]] = 1;
    }
    int count = 0;
    for (int e = 0; e < elem_count; e++)
        if (cs->in_pair[e]) cs->active[count++] = e;
    cs->active_count = count;
}

/* Force between two elements whose boxes overlap, both roles, into out;
 * springs are the pair's CONTACT_SLOTS stick springs (updated), h the last
 * step's size. Returns 1 if they touched (out is then filled; otherwise it
 * may be left as it was). Writes nothing in m. */
static int contact_pair_force(const fdem_model *m, int e1, int e2, double h,
                              double springs[CONTACT_SLOTS], double out[PAIR_OUT])
{
    tri_now a, b;
    tri_gather(m, e1, &a);
    tri_gather(m, e2, &b);
    tri_complete(m, e1, &a);
    tri_complete(m, e2, &b);
    if (!(a.area2 > 0) || !(b.area2 > 0)) { /* inverted: no potential defined */
        memset(springs, 0, sizeof(double) * CONTACT_SLOTS);
        return 0;
    }
    /* The softer surface sets the penalty; friction is the larger of the two,
     * so giving it on one material is enough. */
    double penalty = min2(a.penalty, b.penalty);
    double friction = max2(a.friction, b.friction);
    for (int k = 0; k < PAIR_OUT; k++) out[k] = 0;
    double *dissipated = &out[PAIR_DISSIPATED];
    int touched = contactor_against_target(m, &a, &b, penalty, friction, h, springs, out, out + 6,
                                           dissipated);
    touched |= contactor_against_target(m, &b, &a, penalty, friction, h, springs + 3, out + 6,
                                        out, dissipated);
    return touched;
}

/* Adds a pair's forces (contact_pair_force) to the contact force array and
 * what its friction dissipated to the friction account; called in pair
 * order, so every sum is formed in the same order on any thread count. */
static void contact_pair_scatter(fdem_model *m, int e1, int e2, const double out[PAIR_OUT])
{
    double *f = m->contact.force;
    const int32_t *n1 = m->elem[e1].node, *n2 = m->elem[e2].node;
    for (int c = 0; c < 3; c++) {
        f[2 * n1[c]] += out[2 * c];
        f[2 * n1[c] + 1] += out[2 * c + 1];
    }
    for (int c = 0; c < 3; c++) {
        f[2 * n2[c]] += out[6 + 2 * c];
        f[2 * n2[c] + 1] += out[6 + 2 * c + 1];
    }
    m->friction_energy += out[PAIR_DISSIPATED];
}

/* A pair whose boxes no longer overlap lets its stick springs go. */
static inline void pair_springs_release(contact_state *cs, size_t k)
{
    if (!cs->sprung[k]) return;
    double *springs = cs->slip + CONTACT_SLOTS * k;
    for (int s = 0; s < CONTACT_SLOTS; s++) springs[s] = 0;
    cs->sprung[k] = 0;
}

/* Notes whether pair k's springs hold anything after its evaluation. */
static inline void pair_springs_mark(contact_state *cs, size_t k)
{
    const double *springs = cs->slip + CONTACT_SLOTS * k;
    int any = 0;
    for (int s = 0; s < CONTACT_SLOTS; s++) any |= springs[s] != 0;
    cs->sprung[k] = (uint8_t)any;
}

/* Force between two elements, both roles, added to the contact force
 * array, with no friction history (for tests). Returns 1 if they touched. */
int contact_potential_force(fdem_model *m, int e1, int e2, double h)
{
    double b1[4], b2[4], out[PAIR_OUT], springs[CONTACT_SLOTS] = {0};
    element_box(m, e1, b1);
    element_box(m, e2, b2);
    if (!boxes_overlap(b1, b2) || !contact_pair_force(m, e1, e2, h, springs, out)) return 0;
    contact_pair_scatter(m, e1, e2, out);
    return 1;
}

static void element_circle(const double *p, const element_hot *el, double *cx, double *cy,
                           double *r)
{
    double x = 0, y = 0;
    for (int c = 0; c < 3; c++) {
        x += p[2 * el->node[c]];
        y += p[2 * el->node[c] + 1];
    }
    x /= 3;
    y /= 3;
    double r2 = 0;
    for (int c = 0; c < 3; c++) {
        double dx = p[2 * el->node[c]] - x, dy = p[2 * el->node[c] + 1] - y;
        r2 = fmax(r2, dx * dx + dy * dy);
    }
    *cx = x;
    *cy = y;
    *r = sqrt(r2);
}

/* Candidate pairs from the bounding circles of the elements at `pos` (the
 * current positions, or a checkpoint's positions at its last detection),
 * with the stick springs of the pairs that stay. */
static int contact_detect_at(fdem_model *m, const double *pos)
{
    contact_state *cs = &m->contact;
    if (contact_history_set_aside(cs)) return -1;
    for (int e = 0; e < m->elem_count; e++) {
        element_circle(pos, &m->elem[e], &cs->cx[e], &cs->cy[e], &cs->r[e]);
        cs->r[e] += 0.5 * cs->buffer;
    }
    if (nbs_detect(&cs->grid, (size_t)m->elem_count, cs->cx, cs->cy, cs->r, cs->body, &cs->pairs))
        return -1;
    if (m->joint_count) { /* triangles glued by intact joints never contact */
        joint_mark_broken_vertices(m);
        joint_fragment_labels(m, cs->piece);
        size_t kept = 0;
        for (size_t k = 0; k < cs->pairs.count; k++) {
            int a = cs->pairs.a[k], b = cs->pairs.b[k];
            if (m->elem_part[a] == m->elem_part[b] && joint_contact_excluded(m, cs->piece, a, b))
                continue;
            cs->pairs.a[kept] = cs->pairs.a[k];
            cs->pairs.b[kept] = cs->pairs.b[k];
            kept++;
        }
        cs->pairs.count = kept;
    }
    if (contact_history_take_back(cs)) return -1;
    contact_collect_active(cs, m->elem_count);
    if (pos != cs->pos_detect)
        memcpy(cs->pos_detect, pos, sizeof(double) * 2 * (size_t)m->node_count);
    cs->need_detect = 0;
    cs->detections++;
    return 0;
}

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
    memset(cs->force, 0, sizeof(double) * 2 * (size_t)m->node_count);
    cs->force_is_zero = 1;
    if (cs->need_detect) return 0; /* the next step detects anyway */
    long detections = cs->detections;
    if (contact_detect_at(m, cs->pos_detect)) return -1;
    cs->detections = detections;
    return 0;
}

int contact_init(fdem_model *m, fdem_error *err)
{
    contact_state *cs = &m->contact;
    int fracture = 0;
    for (int k = 0; k < m->part_count; k++) fracture |= m->parts[k].fracture;
    cs->enabled = m->part_count > 1 || fracture;
    if (!cs->enabled) return 0;
    if (m->dim == 3) {
        model_error(err, FDEM_ITEM_NONE, -1, "contact between tetrahedral parts is not built yet");
        return -1;
    }
    size_t E = (size_t)m->elem_count, N = (size_t)m->node_count;
    cs->cx = malloc(sizeof(double) * E);
    cs->cy = malloc(sizeof(double) * E);
    cs->r = malloc(sizeof(double) * E);
    cs->body = malloc(sizeof(int32_t) * E);
    cs->piece = malloc(sizeof(int32_t) * E);
    cs->pos_detect = malloc(sizeof(double) * 2 * N);
    cs->force = calloc(2 * N, sizeof(double));
    cs->force_is_zero = 1;
    cs->box = malloc(sizeof(double) * 4 * E);
    cs->active = malloc(sizeof(int32_t) * E);
    cs->in_pair = malloc(E);
    if (!cs->cx || !cs->cy || !cs->r || !cs->body || !cs->piece || !cs->pos_detect || !cs->force ||
        !cs->box || !cs->active || !cs->in_pair) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for contact detection");
        return -1;
    }
    /* Triangles of one unbroken part never touch each other; those of a
     * fracturing part each count as a body of their own. */
    for (int e = 0; e < m->elem_count; e++) {
        int p = m->elem_part[e];
        cs->body[e] = m->parts[p].fracture ? m->part_count + e : p;
    }
    double rmax = 0;
    for (int e = 0; e < m->elem_count; e++) {
        double x, y, r;
        element_circle(m->pos, &m->elem[e], &x, &y, &r);
        rmax = fmax(rmax, r);
    }
    cs->buffer = 0.4 * rmax;
    cs->need_detect = 1;
    return 0;
}

void contact_free(contact_state *cs)
{
    free(cs->cx); free(cs->cy); free(cs->r); free(cs->body); free(cs->piece);
    free(cs->pos_detect); free(cs->force);
    free(cs->box); free(cs->active); free(cs->in_pair);
    for (int t = 0; t < cs->touch_lists; t++) free(cs->touches[t].item);
    free(cs->touches);
    free(cs->slip);
    free(cs->sprung);
    free(cs->records);
    nbs_grid_free(&cs->grid);
    nbs_pairs_free(&cs->pairs);
    memset(cs, 0, sizeof *cs);
}

double contact_stable_dt(const fdem_model *m)
{
    if (!m->contact.enabled) return INFINITY;
    /* A face pressed a depth d into a triangle of altitude h is pushed back
     * with p 3 d / h from each side, so a corner node of an element of
     * size h, on two such faces, feels a spring of up to about 16 p / (rho
     * h^2) per unit mass. 0.25 h sqrt(rho / p) keeps omega dt at 1 at
     * safety 1: measured on flat impacts of shared-node and fracturing
     * blocks (test_contact.c), the energy after the impact is within 1 % of
     * the energy before at every safety up to 1 (0.45, the earlier factor,
     * gained 20 % at safety 1). */
    double dt = INFINITY;
    for (int e = 0; e < m->elem_count; e++) {
        const material *mat = &m->materials[m->elem[e].material];
        dt = fmin(dt, 0.25 * m->elem_h[e] * sqrt(mat->def.density / mat->penalty));
    }
    return dt;
}

size_t contact_memory_bytes(const contact_state *cs)
{
    size_t b = (size_t)cs->touch_lists * sizeof(contact_touches);
    for (int t = 0; t < cs->touch_lists; t++) b += cs->touches[t].capacity * sizeof(contact_touch);
    return b;
}

static int contact_touch_push(contact_touches *list, long pair, const double force[PAIR_OUT])
{
    if (list->count == list->capacity) {
        size_t cap = list->capacity ? 2 * list->capacity : 1024;
        contact_touch *p = realloc(list->item, cap * sizeof *p);
        if (!p) return -1;
        list->item = p;
        list->capacity = cap;
    }
    contact_touch *t = &list->item[list->count++];
    t->pair = pair;
    memcpy(t->force, force, sizeof t->force);
    return 0;
}

/* One list per thread; 0, or -1 if they cannot be had. */
static int contact_touch_lists(contact_state *cs, int threads)
{
    if (threads <= cs->touch_lists) return 0;
    contact_touches *t = realloc(cs->touches, sizeof *t * (size_t)threads);
    if (!t) return -1;
    memset(t + cs->touch_lists, 0, sizeof *t * (size_t)(threads - cs->touch_lists));
    cs->touches = t;
    cs->touch_lists = threads;
    return 0;
}

/* Every candidate pair's force, added to the contact force array in pair
 * order, one pair at a time. Returns the number of pairs that touched. */
static int contact_pairs_forces_serial(fdem_model *m, double h)
{
    contact_state *cs = &m->contact;
    int touching = 0;
    const double *box = cs->box;
    for (size_t k = 0; k < cs->pairs.count; k++) {
        int32_t a = cs->pairs.a[k], b = cs->pairs.b[k];
        double out[PAIR_OUT], *springs = cs->slip + CONTACT_SLOTS * k;
        if (!boxes_overlap(box + 4 * (size_t)a, box + 4 * (size_t)b)) {
            pair_springs_release(cs, k);
            continue;
        }
        int touched = contact_pair_force(m, a, b, h, springs, out);
        pair_springs_mark(cs, k);
        if (!touched) continue;
        contact_pair_scatter(m, a, b, out);
        touching++;
    }
    return touching;
}

/* The same on several threads: each takes a contiguous share of the pairs
 * and lists the ones that touched with their forces; the lists are then
 * added in thread order, which is pair order. Every node's sum is formed in
 * the order the serial loop forms it: the same bits on any thread count.
 * Returns the number of pairs that touched, or -1 if a list could not grow
 * (nothing has been added then). */
static int contact_pairs_forces_threaded(fdem_model *m, double h)
{
    contact_state *cs = &m->contact;
    long n = (long)cs->pairs.count;
    const int32_t *pa = cs->pairs.a, *pb = cs->pairs.b;
    int touching = 0, failed = 0, used = 1;
    contact_touches *lists = cs->touches;
#pragma omp parallel num_threads(m->threads) reduction(+ : touching)
    {
        int t = 0, nt = 1;
#ifdef _OPENMP
        t = omp_get_thread_num();
        nt = omp_get_num_threads();
#endif
        if (t == 0) used = nt;
        contact_touches *list = &lists[t];
        list->count = 0;
        long begin = n * t / nt, end = n * (t + 1) / nt;
        const double *box = cs->box;
        for (long k = begin; k < end; k++) {
            double force[PAIR_OUT], *springs = cs->slip + CONTACT_SLOTS * k;
            if (!boxes_overlap(box + 4 * (size_t)pa[k], box + 4 * (size_t)pb[k])) {
                pair_springs_release(cs, (size_t)k);
                continue;
            }
            int touched = contact_pair_force(m, pa[k], pb[k], h, springs, force);
            pair_springs_mark(cs, (size_t)k);
            if (!touched) continue;
            touching++;
            if (contact_touch_push(list, k, force)) {
#pragma omp atomic write
                failed = 1;
                break;
            }
        }
    }
    if (failed) return -1;
    for (int t = 0; t < used; t++)
        for (size_t i = 0; i < lists[t].count; i++) {
            const contact_touch *c = &lists[t].item[i];
            contact_pair_scatter(m, pa[c->pair], pb[c->pair], c->force);
        }
    return touching;
}

/* Threads only pay off with enough pairs; without room for their lists the
 * step stays on one thread. Returns the number of pairs that touched, or -1
 * when out of memory. */
static int contact_pairs_forces(fdem_model *m, double h)
{
    contact_state *cs = &m->contact;
    if (m->threads > 1 && cs->pairs.count >= CONTACT_THREADED_PAIRS &&
        contact_touch_lists(cs, m->threads) == 0) {
        /* a list that cannot grow has already moved some stick springs:
         * the step fails rather than run the pairs twice */
        return contact_pairs_forces_threaded(m, h);
    }
    return contact_pairs_forces_serial(m, h);
}

/* Detection when due, then every candidate pair's force. The stick springs
 * are loaded by the motion of the last step (m->dt_prev). Returns 0, or -1
 * when out of memory. */
int contact_forces(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (!cs->enabled) return 0;
    double half = 0.5 * cs->buffer;
    if (cs->need_detect || cs->max_disp2 > half * half) {
        double t0 = stage_clock();
        if (contact_detect(m)) return -1;
        double spent = stage_clock() - t0;
        m->times.detection += spent;
        m->times.contact -= spent; /* the caller books the whole call as contact */
    }
    /* With no candidate pair (bodies apart, an intact fracturing block) the
     * force array stays zero, and the integrator skips reading it. */
    if (!cs->force_is_zero) memset(cs->force, 0, sizeof(double) * 2 * (size_t)m->node_count);
    cs->force_is_zero = cs->pairs.count == 0;
    if (cs->pairs.count) contact_boxes(m);
    int touching = contact_pairs_forces(m, m->dt_prev);
    if (touching < 0) return -1;
    cs->touching = touching;
    return 0;
}
