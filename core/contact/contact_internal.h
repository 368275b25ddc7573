/*
 * contact_internal.h - what contact.c, contact_walk.c and contact_near.c
 * share and no other folder needs: a dimension's pair-kernel record, the near-pair record the
 * per-step walk streams, the element boxes (inline: the walk's box test is
 * on its hot path), and the near list's two entry points.
 */
#ifndef FDEM_CONTACT_INTERNAL_H
#define FDEM_CONTACT_INTERNAL_H

#include "kernel/contact_face.h"
#include "kernel/contact_pair.h"
#include "joint/joint.h"
#include "model/model.h"

/* A dimension's pair kernel and the numbers the shared stage sizes by. */
typedef struct contact_kernel {
    int slots;          /* stick springs per pair */
    int pair_out;       /* forces on both elements' nodes, then the dissipation */
    int (*pair_force)(const contact_pair_in *in, double *springs, double *out);
    double (*pair_clearance)(const contact_pair_in *in); /* by a face plane alone */
    double dt_factor;   /* contact_stable_dt: dt_factor h sqrt(rho / p) */
    double near_step;   /* the near list's reach (cs->near_reach) per unit buffer */
} contact_kernel;

/* A near pair: what the per-step walk reads of a candidate pair, in one
 * record. sprung mirrors contact_pair_sprung for the pair, kept by the walk
 * as it lets springs go or adopts them, so a pair apart without springs
 * (nearly all) reads nothing else. */
typedef struct near_pair {
    double gap;      /* apart while the travel since the list was built (near_apart)
                        stays under it: its boxes' gap then, raised by a clearance
                        its kernel found (pair_evaluate) */
    uint32_t pair;   /* its index among the candidate pairs */
    int32_t a, b;    /* its elements */
    uint8_t sprung;  /* some stick spring of it holds a force */
    uint8_t topology; /* what its elements share, at the list's build (contact_shut.c:
                         SHUT_TOPO_*): a break reruns detection, which rebuilds it */
    uint16_t face;    /* SHUT_TOPO_FACE: where the broken joint lies in a and b
                         (shut_face_pack, bits 0-9), found once at the list's
                         build; any pair: NEAR_EDGES_TRIED */
} near_pair;

/* Elements a and b of one part glued by intact joints (joint_contact_excluded
 * on the pieces `piece`): never a candidate pair. */
static inline int contact_pair_joined(const fdem_model *m, const int32_t *piece, int a, int b)
{
    return m->elem_part[a] == m->elem_part[b] && joint_contact_excluded(m, piece, a, b);
}

/* The crack marks of this moment (joint_mark_cracks: broken vertices, their
 * groups, the pieces into `piece`), with the contact force array as their
 * scratch, zeroed after (contact.c). */
void contact_mark_cracks(fdem_model *m, int32_t *piece);

/* This process's share [*lo, *hi) of n items when the contact walk is
 * split between processes (step_share.contact_ranks; all n otherwise):
 * process r of R takes [n r / R, n (r + 1) / R). The walk evaluates the
 * pairs of its share (contact_walk.c), the near list keeps their boxes
 * (contact_near.c) and contact_springs_sync hands over their springs, so
 * all three cut here. */
static inline void contact_share(const step_share *share, size_t n, size_t *lo, size_t *hi)
{
    if (!share || share->contact_ranks < 2) {
        *lo = 0, *hi = n;
        return;
    }
    const size_t r = (size_t)share->contact_rank, R = (size_t)share->contact_ranks;
    *lo = n * r / R, *hi = n * (r + 1) / R;
}

/* Axis-aligned boxes (lo, hi per axis) that overlap or touch. */
static inline int boxes_overlap(const double *a, const double *b, int dim)
{
    int apart = a[1] < b[0] || b[1] < a[0] || a[3] < b[2] || b[3] < a[2];
    if (dim == 3) apart |= a[5] < b[4] || b[5] < a[4];
    return !apart;
}

/* D and K are constants where it is called (element_box), so each
 * dimension gets its own unrolled copy of this one loop. */
static inline __attribute__((always_inline)) void box_of_nodes(const double *p, const int32_t *n,
                                                               int D, int K, double *b)
{
    for (int d = 0; d < D; d++) {
        double lo = p[D * n[0] + d], hi = lo;
        for (int c = 1; c < K; c++) {
            double x = p[D * n[c] + d];
            lo = min2(lo, x);
            hi = max2(hi, x);
        }
        b[2 * d] = lo;
        b[2 * d + 1] = hi;
    }
}

static inline void element_box(const fdem_model *m, int e, double *b)
{
    if (m->dim == 3) box_of_nodes(m->pos, m->tet[e].node, 3, 4, b);
    else box_of_nodes(m->pos, m->elem[e].node, 2, 3, b);
}

/* The kernel's input for elements e1 and e2 (contact_pair.h): h the last
 * step's size, memo the walk's (NULL: none). The softer surface sets the
 * penalty; friction is the larger of the two, so giving it on one material
 * is enough. */
static inline contact_pair_in contact_pair_input(const fdem_model *m, int e1, int e2, double h,
                                                 contact_pair_memo *memo)
{
    const material *ma = &m->materials[element_material(m, e1)];
    const material *mb = &m->materials[element_material(m, e2)];
    return (contact_pair_in){m->pos, m->vel, element_nodes(m, e1), element_nodes(m, e2),
                             min2(ma->penalty, mb->penalty),
                             max2(ma->def.friction, mb->def.friction), h, memo, 0, 0};
}


/* Fewer nodes than this are marked shut (contact_shut.c) and have their
 * contact force cleared (contact.c) on one thread: below it the threads'
 * start-up costs more than they share. */
#define CONTACT_THREADED_NODES 8192

/* contact_rows.c: a pair's forces (pair_out numbers, both roles) added to
 * the contact force array and the friction account (add), and with the
 * penetration look where it is due (scatter: every 8th step, not between
 * neighbours across a broken joint: looks). contact_walk.c: every near
 * pair's force this step (the pairs that touched, or -1 when out of
 * memory); what its lists hold, and freeing them. */
void contact_pair_add(fdem_model *m, int e1, int e2, const double *out);
int contact_penetration_looks(const fdem_model *m, int e1, int e2);
void contact_pair_scatter(fdem_model *m, int e1, int e2, const double *out);
int contact_pairs_forces(fdem_model *m, double h);
size_t contact_walk_bytes(const contact_state *cs);
void contact_walk_free(contact_state *cs);

/* contact_near.c: the elements of the near pairs and the `more` pairs (of
 * every candidate pair when near is NULL), once each and in element order,
 * into list (returns how many; contact_listed_elements: those in_pair
 * marks already); this step's vertex pairs to walk (after
 * contact_shut_refresh); and this step's boxes of the elements the near
 * lists need, the lists rebuilt first when due (0, or -1 when out of
 * memory). */
int contact_collect_elements(contact_state *cs, int elem_count, const near_pair *near,
                             size_t count, const near_pair *more, size_t more_count,
                             int32_t *list);
int contact_listed_elements(const contact_state *cs, int elem_count, int32_t *list);
void contact_vertex_due(fdem_model *m);
int contact_near_refresh(fdem_model *m);

/* A near pair whose gap is over this stays apart until the list is rebuilt
 * (contact_near_due: near_apart is at most twice the reach before then;
 * a margin over the rebuild's own limit, for the rounding of that root),
 * so the walk would only step over it: contact_near_compact takes such
 * pairs out of the list, in order (the walk counts them in near_dead). */
static inline double contact_near_dead(const contact_state *cs)
{
    return 2.0 * cs->near_reach * (1 + 4e-9);
}
void contact_near_compact(fdem_model *m);

/* contact_shut.c: the shut broken joints (see its top). init builds the
 * vertex tables once (0, or -1 without memory); refresh marks this step's
 * shut elements; kind says what the walk does with a pair of them: the
 * general kernel, the face kernel (fm filled) or nothing. */
enum { SHUT_TOPO_NONE, SHUT_TOPO_FACE, SHUT_TOPO_VERTEX };

/* elem_topo's bits: the element is in a near pair of shut topology (face
 * or vertex), and this step such a pair of it may take the general kernel
 * (contact_near.c). */
#define TOPO_LISTED 1u
#define TOPO_OPEN 2u
int contact_shut_init(fdem_model *m);
void contact_shut_free(contact_state *cs);
void contact_shut_refresh(fdem_model *m);
int contact_shut_face_topology(const fdem_model *m, int a, int b, const int8_t *copy_in_b,
                               uint16_t *face);

/* What a and b share, which only a break changes: a broken joint (its
 * faces in *face), a mesh vertex, or nothing; the near list keeps both
 * (contact_near.c). By the mesh vertices they share, from elem_first
 * (each element's K first copies in a row): a joint's two faces are
 * copies of the same D vertices (node_origin), so only elements sharing
 * that many can have one between them, and the joints are looked at for
 * those few. Inline, with D and K constants where the near list's rebuild
 * calls it for every pair within reach (66 an element in a broken 3D
 * block): as a call it was 15 % of the rebuild step. */
static inline __attribute__((always_inline)) int
contact_shut_topology(const fdem_model *m, const int32_t *elem_first, int a, int b,
                      uint16_t *face, const int D, const int K)
{
    const int32_t *fa = elem_first + (size_t)K * (size_t)a;
    const int32_t *fb = elem_first + (size_t)K * (size_t)b;
    int shared = 0;
    for (int i = 0; i < K; i++)
        for (int k = 0; k < K; k++) shared += fa[i] == fb[k];
    *face = 0;
    if (shared < D) return shared ? SHUT_TOPO_VERTEX : SHUT_TOPO_NONE;
    int8_t copy_in_b[4] = {-1, -1, -1, -1}; /* per corner of a, b's corner on its vertex */
    for (int i = 0; i < K; i++)
        for (int k = 0; k < K; k++)
            if (fa[i] == fb[k]) copy_in_b[i] = (int8_t)k;
    return contact_shut_face_topology(m, a, b, copy_in_b, face);
}
int contact_shut_neighbours(const fdem_model *m, int a, int b);

/* near_pair.face: the kernel has looked for a clearance across two edges
 * (contact_pair_in.edge_clearance) since the list was built. A pair that
 * one look found none for (two spheres of a pile resting a hair apart)
 * would pay for it every step; the rebuild, after the nodes have moved,
 * looks again. Skips never change bits, so neither does when one looks. */
#define NEAR_EDGES_TRIED 0x8000u

/* near_pair.face, bits 10-13: how often the box test has turned the pair
 * away since the list was built, up to the dimension's count, when broken
 * rock's pair asks its kernel for a face plane's clearance (contact_walk.c,
 * pair_turned_away), then NEAR_TURNED_LOOKED. */
#define NEAR_TURNED_SHIFT 10
#define NEAR_TURNED_MASK (15u << NEAR_TURNED_SHIFT)
#define NEAR_TURNED_LOOKED 15u
#define NEAR_LOOK_AFTER_2D 4
#define NEAR_LOOK_AFTER_3D 14

/* A face_match in near_pair.face: two bits each for face_a, face_b and
 * copy_in_b[0..2] (corners and faces number at most 4). */
static inline uint16_t shut_face_pack(const face_match *fm)
{
    return (uint16_t)(fm->face_a | fm->face_b << 2 | fm->copy_in_b[0] << 4 |
                      fm->copy_in_b[1] << 6 | fm->copy_in_b[2] << 8);
}

static inline face_match shut_face_unpack(uint16_t face)
{
    return (face_match){face & 3, face >> 2 & 3, {face >> 4 & 3, face >> 6 & 3, face >> 8 & 3}};
}

#endif
