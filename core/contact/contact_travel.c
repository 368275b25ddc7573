/*
 * contact_travel.c - how far the nodes have gone since the last contact
 * detection, which decides when the next one is due. The integrator grows
 * a cheap bound each step (contact_travel_step); the contact stage asks
 * for the exact figure only once the bound passes its limit
 * (contact_travel_past), so most steps pay one square root for it. It
 * also owns each element's skin (contact_skin_init): how far its circle
 * reaches past the element, which sets how far its nodes may go before
 * detection is due.
 */
#include <math.h>
#include <stdlib.h>

#include "model/model.h"
#include "parallel/scatter_plan.h"
#include "contact.h"

/* How far the nodes have gone from pos_detect (the displacement-tracking
 * protocol of contact detection, contact.c). Detection runs again at the
 * first step after which some node is more than half the buffer from its
 * place there. Measuring that exactly each step means reading the whole
 * snapshot each step (24 bytes a node, a third of what the update itself
 * moves); instead contact.max_disp2 holds a bound of the squared distance,
 * grown each step by the largest step any node took (the triangle
 * inequality), which costs nothing the update does not already hold in
 * registers. Only when the bound passes the limit is the snapshot read
 * (contact_travel_past) and the bound restarted from the exact figure, so
 * detection runs exactly when the exact figure would have run it: the
 * same pairs in the same order, the same bits.
 *
 * Rounding: each node's step is new minus old position as computed, so
 * the true step is within a few units in the last place of it; the slack
 * below is a thousand times those, and keeps the bound a bound. Nodes
 * with a prescribed dof are measured exactly by constraint_enforce, which
 * moves them after this. */
#define TRAVEL_SLACK (1 + 1e-12)

void contact_travel_step(fdem_model *m, double step2)
{
    double reach = sqrt(m->contact.max_disp2) + sqrt(step2);
    m->contact.max_disp2 = reach * reach * TRAVEL_SLACK;
}

static void travel_exact_block(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    const size_t D = (size_t)m->dim;
    const double *x = m->pos, *xd = m->contact.pos_detect, *w = m->contact.travel_weight;
    double most = 0;
    for (size_t i = (size_t)begin; i < (size_t)end; i++) {
        double d2 = 0;
        for (size_t d = 0; d < D; d++) {
            double u = x[D * i + d] - xd[D * i + d];
            d2 += u * u;
        }
        if (w) d2 *= w[i];
        if (d2 > most) most = d2;
    }
    if (most > sums[SCATTER_MAX]) sums[SCATTER_MAX] = most;
}

int contact_travel_past(fdem_model *m, double limit2)
{
    if (!(m->contact.max_disp2 > limit2)) return 0;
    double sums[SCATTER_SUMS] = {0};
    scatter_plan_run(&m->node_plan, m, m->threads, travel_exact_block, sums);
    m->contact.max_disp2 = sums[SCATTER_MAX];
    return sums[SCATTER_MAX] > limit2;
}

/* Skins. A pair must be a candidate while its elements can touch before
 * the next detection: each element's circle at detection (over its nodes)
 * is widened by half its skin, and detection is due once a node has gone
 * half the skin of some element it is in (a point of an element moves no
 * farther than its farthest node). One skin for all, 0.4 of the largest
 * radius, made a graded mesh's small elements reach several times their
 * size (tunnel-region: 0.56 m on triangles of 0.16-0.23 m), and its
 * detection list ~5 times the pairs it needs: 30 % of the CPU of its run
 * once the rock broke, when every break runs one. So an element's skin
 * is 0.8 of its own radius up to that one (an element under half the
 * largest radius, the size classes of nbs_classes.c), and a node may go
 * half the smallest skin around it. The bound of contact_travel_step then
 * runs in units of the smallest allowance: each node's squared travel is
 * weighted by (smallest / its own allowance)^2 <= 1, so the bound's
 * growth, the largest step, still bounds every weighted travel. A mesh
 * whose radii are all within a factor 2 of the largest keeps one skin and
 * no weights: the same candidates as before, bit for bit. */
int contact_skin_init(fdem_model *m, double rmax)
{
    contact_state *cs = &m->contact;
    const int E = m->elem_count, N = m->node_count, K = m->elem_nodes;
    cs->buffer = 0.4 * rmax;
    double half = 0.5 * cs->buffer;
    cs->travel_limit2 = half * half;
    int graded = 0;
    for (int e = 0; e < E && !graded; e++) graded = 2.0 * cs->r[e] < rmax;
    if (!graded) return 0;
    cs->skin = malloc(sizeof(double) * (size_t)E);
    cs->travel_weight = malloc(sizeof(double) * (size_t)N);
    if (!cs->skin || !cs->travel_weight) return -1;
    double *allow = cs->travel_weight; /* each node's allowance first */
    for (int n = 0; n < N; n++) allow[n] = INFINITY;
    double least = INFINITY;
    for (int e = 0; e < E; e++) {
        cs->skin[e] = fmin(cs->buffer, 0.8 * cs->r[e]);
        const int32_t *node = m->elem_node + (size_t)K * (size_t)e;
        for (int c = 0; c < K; c++) allow[node[c]] = fmin(allow[node[c]], 0.5 * cs->skin[e]);
        least = fmin(least, 0.5 * cs->skin[e]);
    }
    for (int n = 0; n < N; n++) {
        double q = least / allow[n]; /* 0 for a node of no element */
        /* a hair over the ratio, so rounding never lets a node past its own */
        allow[n] = fmin(1.0, q * q * TRAVEL_SLACK);
    }
    cs->travel_limit2 = least * least;
    return 0;
}

double contact_skin(const contact_state *cs, int e)
{
    return cs->skin ? cs->skin[e] : cs->buffer;
}
