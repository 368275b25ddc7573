/*
 * contact_shut.c - which candidate pairs of broken rock the contact stage
 * hands to the shut-joint kernel (kernel/contact_face.h), which it leaves
 * out, and which go to the general kernel (issue 34). Both dimensions.
 *
 * Shut. A mesh vertex is shut while every copy of it (the nodes with its
 * node_origin) is within SHUT_TOLERANCE x h_v of its first copy, h_v the
 * smallest height of the elements around it; an element is shut while all
 * its vertices are. Why 1e-4: the face kernel and the pairs it leaves out
 * differ from the general kernel by O(s / h) of the force (s the copies'
 * offset), and a broken block squeezed and sheared (test_contact_shut.c)
 * measured it: at 1e-4 h its nodes end within 1.4e-4 (2D) and 5e-5 (3D)
 * of their travel from the general kernel's run and its elastic energy
 * within 0.03 %; at 1e-3 h, 2 % and 7.5 % in 2D, where rows sliding along
 * a straight crack press the collinear edges of corner neighbours. And a
 * joint pressed shut sits at a penalty overlap of sigma h / (2 (D+1) p),
 * under 1e-4 h for any stress below 6e-3 p (a 30 GPa rock at p = 10 E:
 * 180 MPa), so a broken joint carrying load across stays shut. Once any
 * copy moves farther, its elements go back to the general kernel the same
 * step.
 *
 * Pairs (both elements shut): the two sides of a broken joint get the face
 * kernel; two elements that share a mesh vertex but no broken joint are
 * left out: around a vertex whose copies all sit together, they touch only
 * through the hair-apart copies (an area ~ s L at a potential ~ s / h:
 * second order in s / h), the faces between them being carried by the
 * face pairs, and everything around both elements is in place up to the
 * tolerance, so no other part of them can meet. Every other pair, and
 * every pair with an element not shut, takes the general kernel.
 *
 * Determinism: shut is a function of this step's positions alone, so it
 * needs no checkpoint (a restore recomputes it) and is the same on any
 * thread count; the face kernel keeps its stick springs in the general
 * kernel's slots with the same meaning (contact_face.h), so a pair passing
 * from one kernel to the other keeps its friction. A model with no broken
 * joint pays one test a step.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact_internal.h"
#include "kernel/contact_face.h"
#include "kernel/element_tet.h"
#include "model/model.h"

#define SHUT_TOLERANCE 1e-4

/* Per node: its vertex's first copy; per first copy: the squared
 * tolerance. Built once, from the mesh (node_origin, elem_h). */
int contact_shut_init(fdem_model *m)
{
    contact_state *cs = &m->contact;
    if (!m->joint_count) return 0;
    size_t N = (size_t)m->node_count;
    cs->shut_first = malloc(sizeof(int32_t) * N);
    cs->shut_tol2 = malloc(sizeof(double) * N);
    cs->shut_vertex = malloc(N);
    cs->elem_shut = calloc((size_t)m->elem_count, 1);
    cs->elem_due = malloc(sizeof(int32_t) * (size_t)m->elem_count);
    cs->elem_topo = calloc((size_t)m->elem_count, 1);
    cs->elem_first = malloc(sizeof(int32_t) * (size_t)m->elem_nodes * (size_t)m->elem_count);
    if (!cs->shut_first || !cs->shut_tol2 || !cs->shut_vertex || !cs->elem_shut || !cs->elem_due ||
        !cs->elem_topo || !cs->elem_first)
        return -1;
    /* the tolerances' room holds the table origin -> first copy meanwhile
     * (no scratch beyond what the memory estimate prices) */
    int32_t *first_of = cs->shut_first, *by_origin = (int32_t *)cs->shut_tol2;
    for (size_t n = 0; n < N; n++) by_origin[n] = -1;
    for (size_t n = 0; n < N; n++) {
        int32_t o = m->node_origin[n];
        if (o < 0 || (size_t)o >= N) o = (int32_t)n;
        if (by_origin[o] < 0) by_origin[o] = (int32_t)n;
        first_of[n] = by_origin[o];
    }
    for (size_t n = 0; n < N; n++) cs->shut_tol2[n] = INFINITY;
    const int K = m->elem_nodes;
    for (int e = 0; e < m->elem_count; e++) {
        const int32_t *nd = element_nodes(m, e);
        double t = SHUT_TOLERANCE * m->elem_h[e];
        for (int c = 0; c < K; c++) {
            int32_t f = first_of[nd[c]];
            cs->shut_tol2[f] = fmin(cs->shut_tol2[f], t * t);
            cs->elem_first[(size_t)K * e + c] = f;
        }
    }
    return 0;
}

void contact_shut_free(contact_state *cs)
{
    free(cs->shut_first);
    free(cs->shut_tol2);
    free(cs->shut_vertex);
    free(cs->elem_shut);
    free(cs->elem_due);
    free(cs->elem_topo);
    free(cs->elem_first);
}

/* Whether copy n of a vertex is away from its first copy (past the shut
 * tolerance). */
static inline __attribute__((always_inline)) int vertex_away(const double *pos,
                                                             const int32_t *first,
                                                             const double *tol2, int n, int D)
{
    int32_t f = first[n];
    if (f == n) return 0;
    double s2 = 0;
    for (int d = 0; d < D; d++) {
        double x = pos[D * (size_t)n + d] - pos[D * (size_t)f + d];
        s2 += x * x;
    }
    return !(s2 <= tol2[f]);
}

/* Element e's mark this step (all its vertices shut); 1 if it is due: not
 * shut now or not last step (`had`: last step's marks hold). */
static inline __attribute__((always_inline)) int element_mark(uint8_t *elem_shut,
                                                              const uint8_t *vertex,
                                                              const int32_t *elem_first, int K,
                                                              uint8_t had, int e)
{
    uint8_t shut = 1;
    for (int c = 0; c < K; c++) shut &= vertex[elem_first[(size_t)K * e + c]];
    uint8_t was = elem_shut[e] & had;
    elem_shut[e] = shut;
    return !(shut & was);
}

/* This step's shut vertices and elements; D and K are constants where it
 * is called, so each dimension's loops are unrolled. On the model's
 * threads (serial, it was a twelfth of a broken 2D block's step on two):
 * a vertex is cleared by whichever of its copies is away (an atomic store
 * of the same 0, so the marks do not depend on which), each element's mark
 * is its own, and the list of elements due is compacted in element order
 * afterwards: the same marks and list on any thread count. */
static inline __attribute__((always_inline)) void shut_mark(fdem_model *m, int D, int K)
{
    contact_state *cs = &m->contact;
    const int N = m->node_count, E = m->elem_count;
    const double *pos = m->pos;
    const int32_t *first = cs->shut_first, *elem_first = cs->elem_first;
    const double *tol2 = cs->shut_tol2;
    uint8_t *vertex = cs->shut_vertex, *elem_shut = cs->elem_shut;
    int32_t *due = cs->elem_due;
    /* the elements not shut now or last step: only their vertex pairs can
     * hold a force or a spring (contact_near.c); without last step's marks
     * every element is */
    const uint8_t had = (uint8_t)cs->shut_was_any;
    memset(vertex, 1, (size_t)N);
    int count = 0;
    if (m->threads > 1 && N > CONTACT_THREADED_NODES) {
#pragma omp parallel num_threads(m->threads)
        {
#pragma omp for schedule(static)
            for (int n = 0; n < N; n++)
                if (vertex_away(pos, first, tol2, n, D)) {
#pragma omp atomic write
                    vertex[first[n]] = 0;
                }
#pragma omp for schedule(static)
            for (int e = 0; e < E; e++)
                due[e] = element_mark(elem_shut, vertex, elem_first, K, had, e) ? e : -1;
        }
        for (int e = 0; e < E; e++)
            if (due[e] >= 0) due[count++] = due[e];
    } else {
        for (int n = 0; n < N; n++)
            if (vertex_away(pos, first, tol2, n, D)) vertex[first[n]] = 0;
        for (int e = 0; e < E; e++)
            if (element_mark(elem_shut, vertex, elem_first, K, had, e))
                due[count++] = e;
    }
    cs->elem_due_count = count;
}

/* This step's shut vertices and elements (none without a broken joint). */
void contact_shut_refresh(fdem_model *m)
{
    contact_state *cs = &m->contact;
    cs->shut_any = cs->elem_shut && m->broken_joints > 0 && !cs->shut_off;
    if (cs->shut_any) {
        if (m->dim == 3) shut_mark(m, 3, 4);
        else shut_mark(m, 2, 3);
    }
    cs->shut_was_any = cs->shut_any;
}

/* The broken joint between a and b, or -1. */
static int broken_joint_between(const fdem_model *m, int a, int b)
{
    const int faces = m->dim + 1;
    for (int c = 0; c < faces; c++) {
        int j = m->elem_joint[faces * a + c];
        if (j >= 0 && m->joint_damage[j] >= 1.0 &&
            m->joint_elem[2 * j] + m->joint_elem[2 * j + 1] - a == b)
            return j;
    }
    return -1;
}

/* The topology of two elements that share a face's worth of mesh
 * vertices (contact_shut_topology, contact_internal.h, tells the rest
 * apart inline, and hands over which corner of b holds each corner of a's
 * vertex, -1 for a's corner off the shared face): a broken joint between
 * them (its faces in *face, shut_face_pack), else a vertex pair. The
 * shared vertices are the joint's: two simplices sharing D vertices share
 * the face they span, and a joint lies on the face its two elements share
 * (its nodes are copies of that face's vertices, node_origin). So the
 * face and the copies come from the shared corners; looking the joint's
 * nodes up in both elements' node lists was 40 ns an element of a broken
 * 2D block's restore step. */
int contact_shut_face_topology(const fdem_model *m, int a, int b, const int8_t *copy_in_b,
                               uint16_t *face)
{
    if (broken_joint_between(m, a, b) < 0) return SHUT_TOPO_VERTEX;
    const int D = m->dim, K = D + 1;
    int off_a = 0, off_b = K * (K - 1) / 2; /* b's corners' sum, less the shared ones */
    for (int i = 0; i < K; i++) {
        if (copy_in_b[i] < 0) off_a = i;
        else off_b -= copy_in_b[i];
    }
    face_match fm = {0, 0, {0, 0, 0}};
    /* 3D: face f is opposite corner f; 2D: edge i runs from corner i to i + 1 */
    fm.face_a = D == 3 ? off_a : (off_a + 1) % 3;
    fm.face_b = D == 3 ? off_b : (off_b + 1) % 3;
    for (int k = 0; k < D; k++)
        fm.copy_in_b[k] = copy_in_b[D == 3 ? tet_face_nodes[fm.face_a][k] : (fm.face_a + k) % 3];
    *face = shut_face_pack(&fm);
    return SHUT_TOPO_FACE;
}

/* a and b are the two sides of a broken joint, both shut this step: then
 * each lies in place against the other up to the tolerance, as in an
 * intact mesh, so neither is deep in the other and the penetration check
 * (penetration.c) can pass them by: it was an eighth of a broken 2D
 * block's contact stage, for a depth of 1e-4 at most. (Shut elements that
 * share only a vertex never touch: the walk leaves them out.) */
int contact_shut_neighbours(const fdem_model *m, int a, int b)
{
    const contact_state *cs = &m->contact;
    if (!cs->shut_any || !cs->elem_shut[a] || !cs->elem_shut[b]) return 0;
    return broken_joint_between(m, a, b) >= 0;
}
