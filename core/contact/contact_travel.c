/*
 * contact_travel.c - how far the nodes have gone since the last contact
 * detection, which decides when the next one is due. The integrator grows
 * a cheap bound each step (contact_travel_step); the contact stage asks
 * for the exact figure only once the bound passes its limit
 * (contact_travel_past), so most steps pay one square root for it.
 */
#include <math.h>

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
    const double *x = m->pos, *xd = m->contact.pos_detect;
    double most = 0;
    for (size_t k = D * (size_t)begin; k < D * (size_t)end; k += D) {
        double d2 = 0;
        for (size_t d = 0; d < D; d++) {
            double u = x[k + d] - xd[k + d];
            d2 += u * u;
        }
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
