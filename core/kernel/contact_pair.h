/*
 * contact_pair.h - what the contact stage (contact.c) hands a dimension's
 * pair kernel, and what it gets back: the triangle kernel (contact_tri.c)
 * and the tetrahedron kernel (contact_tet.c) answer the same call.
 *
 * Contract:
 *  - The kernel gets the two elements' node lists (3 or 4 nodes, positive
 *    area or volume at rest), node positions and velocities (dim numbers a
 *    node), the pair's penalty and Coulomb coefficient, and h, the last
 *    step's size, which turns relative velocities into slip.
 *  - springs are the pair's stick springs, read and updated: first the
 *    contactor boundaries (edges, faces) of a against b, then those of b
 *    against a, the same count for each (so swapping the halves turns the
 *    pair (a, b) into (b, a)). A boundary that does not touch, or a pair
 *    without friction, leaves its springs at zero: a pair that did not
 *    touch has them all at zero.
 *  - It returns 1 if the pair touched; out then holds the forces on a's
 *    nodes (dim per node, node by node), then on b's, then the energy
 *    friction dissipated. It returns 0 if not, every spring let go, and
 *    out[0] then holds the pair's clearance: a distance the two elements
 *    are apart by, less the kernel's rounding, such that while their nodes
 *    together travel less than it (and no element gets flatter than its
 *    kernel allows for) the kernel would keep returning 0 - or 0 when it
 *    cannot tell (the rest of out is undefined). The contact stage skips
 *    the pair until then (contact.c, pair_evaluate): the same bits. An
 *    inverted element has no potential: no force, springs let go.
 *  - Action equals reaction at one point per boundary: linear and angular
 *    momentum are conserved to round-off. Kernels write nothing else (but
 *    memo), so pairs can be evaluated side by side.
 *  - memo (may be NULL) is what a kernel keeps from one call to the next
 *    within one walk over the pairs: one thread, one step, positions that
 *    do not move. The stage clears it (contact_pair_memo_clear) before the
 *    walk. What a kernel takes from it is what it would have worked out
 *    again, bit for bit.
 */
#ifndef FDEM_CONTACT_PAIR_H
#define FDEM_CONTACT_PAIR_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* An element meets the same few neighbours in pair after pair (the pairs
 * come grouped by their first element, and neighbours by their second), so
 * the tetrahedron kernel keeps elements' barycentric maps (a division per
 * number) here, in slots chosen by the element. */
#define CONTACT_MEMO_SLOTS 64
typedef struct contact_pair_memo {
    const int32_t *node[CONTACT_MEMO_SLOTS]; /* whose numbers a slot holds (its node list) */
    double numbers[CONTACT_MEMO_SLOTS][14];
    /* the shut-face kernel's own (contact_face_tet.c): its numbers differ
     * from the general kernel's, and an element meets both in one walk */
    const int32_t *face_node[CONTACT_MEMO_SLOTS];
    double face_numbers[CONTACT_MEMO_SLOTS][14];
} contact_pair_memo;

/* The memo slot of the element whose node list is n: the top 6 bits of its
 * address times 2^64 / phi (Fibonacci hashing), the address standing for
 * the element. One rule for both kernels' memos. */
static inline unsigned contact_memo_slot(const int32_t *n)
{
    _Static_assert(CONTACT_MEMO_SLOTS == 64, "slot is 6 bits");
    return (unsigned)(((uint64_t)(uintptr_t)n * 0x9E3779B97F4A7C15u) >> 58);
}

static inline void contact_pair_memo_clear(contact_pair_memo *memo)
{
    for (int s = 0; s < CONTACT_MEMO_SLOTS; s++) memo->node[s] = memo->face_node[s] = 0;
}

typedef struct contact_pair_in {
    const double *pos, *vel;
    const int32_t *node_a, *node_b;
    double penalty, friction, h;
    contact_pair_memo *memo;
    /* 3D: when the pair is found untouched, look for a clearance across an
     * edge of each too (contact_tet.c, edge_pair_clearance): ~1,500
     * instructions, so the walk asks once a pair and near list */
    int edge_clearance;
    /* 3D: look across the edges before clipping (contact_tet.c), instead
     * of after: for a pair more likely apart than not, once a near list */
    int edges_first;
} contact_pair_in;

/* Triangles: one tangential spring per edge, 3 edges x 2 roles; forces
 * 2 x 3 nodes x 2 components, then the dissipated energy. */
#define TRI_CONTACT_SLOTS 6
#define TRI_PAIR_OUT 13
/* Tetrahedra: a tangential spring vector per face, 4 faces x 2 roles x 3
 * components; forces 2 x 4 nodes x 3 components, then the dissipation. */
#define TET_CONTACT_SLOTS 24
#define TET_PAIR_OUT 25

#define CONTACT_SLOTS_MAX TET_CONTACT_SLOTS
#define CONTACT_PAIR_OUT_MAX TET_PAIR_OUT

/* A pair's first n springs or forces (n a constant where it is called)
 * set to zero, copied from a row of zeros (contact_face.c): as a loop or a
 * memset, GCC zeroes 24 slots or 25 forces with `rep stos`, whose start-up
 * every pair paid (a fifth of the 3D face kernel's time); a copy is plain
 * stores. */
extern const double contact_zeros[CONTACT_PAIR_OUT_MAX];
static inline void contact_zero(double *x, size_t n)
{
    memcpy(x, contact_zeros, sizeof(double) * n);
}

/* libm's fmin/fmax are calls unless NaN semantics are relaxed; these are not. */
static inline double min2(double a, double b) { return a < b ? a : b; }
static inline double max2(double a, double b) { return a > b ? a : b; }

/* A clearance (above) as both kernels finish it: the distance the pair is
 * apart by less the rounding margin 1e-8 S + 1e-7 L (S the coordinates'
 * size, L the longer of the two elements' longest edges), or 0; trusted
 * only of elements no flatter than CONTACT_CLEARANCE_QUALITY (2A >= q L^2,
 * 6V >= q L^3). Why the margin covers the rounding: contact_tet.c,
 * pair_clearance. */
#define CONTACT_CLEARANCE_QUALITY 1e-6
static inline double contact_clearance_less_margin(double apart, double size, double longest)
{
    double clear = apart - (1e-8 * size + 1e-7 * longest);
    return clear > 0 ? clear : 0;
}

int tri_contact_pair_force(const contact_pair_in *in, double *springs, double *out);
int tet_contact_pair_force(const contact_pair_in *in, double *springs, double *out);

/* The clearance the kernel above would return for a pair a plane of an
 * element's face (2D: edge) separates, without the pair's forces (in's
 * velocities and springs unread), or 0 when none does: a few dozen
 * operations where the kernel may clip both elements in full. */
double tri_contact_pair_clearance(const contact_pair_in *in);
double tet_contact_pair_clearance(const contact_pair_in *in);

#endif /* FDEM_CONTACT_PAIR_H */
