/*
 * joint.c - the transition from continuum to discontinuum: four-noded joint
 * (cohesive) elements on every interior edge of a fracturing part, their
 * traction-separation law, breakage, and fragment counting.
 *
 * Kinematics. A joint joins face A (nodes a0 -> a1, in A's counter-clockwise
 * order) to face B (b0, b1: the copies of a0, a1 in the neighbour). At two
 * Gauss points along the edge, the relative displacement of B against A
 * gives the opening delta (along n, A's outward normal) and the sliding s
 * (along the edge), both in the current configuration.
 *
 * Law (Munjiza 2004 ch. 7, as in Y-Geo, with the slip given a history).
 * Penalty-elastic up to the strength: sigma = p delta / h, tau = p s_e / h
 * (h the smaller adjacent element size, p the material penalty, s_e the
 * elastic part of the sliding s), up to the tensile strength f_t and the
 * shear strength f_s = cohesion + sigma_c tan(phi) (sigma_c the compressive
 * normal stress). Sliding beyond f_s is plastic slip (Coulomb friction as
 * plasticity: an elastic trial and a return onto f_s, each point keeping
 * its plastic slide), so the shear traction always opposes the slip and
 * friction never gives energy back. Past the elastic limits the traction
 * softens by z(D), Munjiza's curve with a = 0.63, b = 1.8, c = 6, where
 * D = sqrt(Dn^2 + Ds^2) combines the opening beyond its limit and the slip
 * path over the softening spans delta_c - delta_p, chosen so that a joint
 * pulled apart in pure mode I absorbs exactly G_I per unit area (elastic
 * part plus softening: softening_span), and likewise G_II in pure mode II:
 * the mixed-mode criterion (dn)^2 + (ds)^2 >= 1 is D >= 1. D never
 * decreases (damage is irreversible); at D = 1 the joint is broken, exerts
 * nothing, and its two triangles meet through contact (with its own
 * Coulomb friction and stick springs) from then on: a broken joint keeps
 * no residual friction of its own. Compression is resisted by the joint's
 * penalty while it holds.
 *
 * The law at one integration point is joint_law.h's, shared with the 3D
 * joint (joint_tet.c); this file owns the 2D geometry around it: the edge,
 * its Gauss points, the exact elastic and compression integrals. What does
 * not depend on the dimension (stiffness, breakage, contact exclusion,
 * fragments) serves 6-node joints too; joint_tet_model.c builds those and
 * computes their forces.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kernel/joint_law.h"
#include "model/model.h"
#include "joint.h"

/* ------------------------------------------------------------ building */

typedef struct edge_ref {
    int32_t lo, hi;   /* original node ids, lo < hi */
    int32_t tri;      /* triangle within the part */
    int32_t corner;   /* the edge runs from corner to corner+1 (ccw) */
} edge_ref;

static int edge_compare(const void *pa, const void *pb)
{
    const edge_ref *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->tri < b->tri ? -1 : a->tri > b->tri;
}

/* Scratch for building part_index's joints, with the error filled when
 * there is no memory. */
void *joint_build_scratch(size_t bytes, int part_index, fdem_error *err)
{
    void *p = malloc(bytes ? bytes : 1);
    if (!p) model_error(err, FDEM_ITEM_PART, part_index, "out of memory building joints");
    return p;
}

/* Room for J joints in all (2 dim nodes and 2 elements each). */
int joint_reserve(fdem_model *m, int J, int part_index, fdem_error *err)
{
    size_t room = (size_t)(J ? J : 1);
    int32_t *jn = realloc(m->joint_node, sizeof(int32_t) * 2 * (size_t)m->dim * room);
    if (jn) m->joint_node = jn;
    int32_t *je = realloc(m->joint_elem, sizeof(int32_t) * 2 * room);
    if (je) m->joint_elem = je;
    if (jn && je) return 0;
    model_error(err, FDEM_ITEM_PART, part_index, "out of memory building joints");
    return -1;
}

/* Adds a joint on every edge shared by two triangles of the fracturing part
 * whose elements start at elem_begin (both in the region, when in_region is
 * given); tri holds the part's original (validated, counter-clockwise)
 * connectivity. */
int joint_build_part(fdem_model *m, int part_index, const int32_t *tri, int triangle_count,
                     const uint8_t *in_region, fdem_error *err)
{
    size_t ne = 3 * (size_t)triangle_count;
    edge_ref *edges = joint_build_scratch(sizeof *edges * ne, part_index, err);
    if (!edges) return -1;
    for (int t = 0; t < triangle_count; t++)
        for (int c = 0; c < 3; c++) {
            int32_t p = tri[3 * t + c], q = tri[3 * t + (c + 1) % 3];
            edge_ref *e = &edges[3 * (size_t)t + c];
            e->lo = p < q ? p : q;
            e->hi = p < q ? q : p;
            e->tri = t;
            e->corner = c;
        }
    qsort(edges, ne, sizeof *edges, edge_compare);
    int shared = 0;
    for (size_t k = 0; k + 1 < ne; k++)
        if (edges[k].lo == edges[k + 1].lo && edges[k].hi == edges[k + 1].hi) shared++;
    /* room for a joint on every shared edge: a region's are fewer */
    int J0 = m->joint_count, J = J0 + shared;
    if (joint_reserve(m, J, part_index, err)) {
        free(edges);
        return -1;
    }
    const part *p = &m->parts[part_index];
    int j = J0;
    for (size_t k = 0; k + 1 < ne; k++) {
        const edge_ref *a = &edges[k], *b = &edges[k + 1];
        if (a->lo != b->lo || a->hi != b->hi) continue;
        if (k + 2 < ne && edges[k + 2].lo == a->lo && edges[k + 2].hi == a->hi) {
            int lo = a->lo, hi = a->hi;
            free(edges);
            model_error(err, FDEM_ITEM_PART, part_index,
                        "edge %d-%d of part %d is shared by more than two triangles", lo, hi,
                        part_index);
            return -1;
        }
        if (in_region && !(in_region[a->tri] && in_region[b->tri])) {
            k++; /* no joint: the two triangles share these nodes (joint_region.c) */
            continue;
        }
        int ea = p->elem_begin + a->tri, eb = p->elem_begin + b->tri;
        /* face A runs a0 -> a1 counter-clockwise in A; b0, b1 are the
         * neighbour's copies of the same two original nodes */
        int32_t a0 = m->elem[ea].node[a->corner], a1 = m->elem[ea].node[(a->corner + 1) % 3];
        int32_t orig_a0 = tri[3 * a->tri + a->corner];
        int32_t b_first = m->elem[eb].node[b->corner], b_second = m->elem[eb].node[(b->corner + 1) % 3];
        int32_t orig_b_first = tri[3 * b->tri + b->corner];
        int32_t b0 = orig_b_first == orig_a0 ? b_first : b_second;
        int32_t b1 = orig_b_first == orig_a0 ? b_second : b_first;
        m->joint_node[4 * j] = a0;
        m->joint_node[4 * j + 1] = a1;
        m->joint_node[4 * j + 2] = b0;
        m->joint_node[4 * j + 3] = b1;
        m->joint_elem[2 * j] = ea;
        m->joint_elem[2 * j + 1] = eb;
        j++;
        k++;
    }
    m->joint_count = j;
    free(edges);
    return 0;
}

/* Per-joint data derived at finalize: stiffness length, element map. */
int joint_prepare(fdem_model *m, fdem_error *err)
{
    if (joint_region_pieces(m, err)) return -1;
    if (!m->joint_count) return m->joint_set_count ? joint_strengths_assign(m, err) : 0;
    size_t J = (size_t)m->joint_count;
    m->joint_damage = calloc(J, sizeof(double));
    m->joint_slip = calloc(J * (size_t)m->dim, sizeof(joint_slip));
    m->joint_fracture = calloc(J, sizeof(double));
    m->joint_broke = calloc(J, 1);
    m->joint_h = malloc(sizeof(double) * J);
    m->joint_k = malloc(sizeof(double) * J);
    int faces = m->dim + 1; /* an element's faces, so at most its joints */
    m->elem_joint = malloc(sizeof(int32_t) * (size_t)faces * (size_t)m->elem_count);
    m->vertex_broken = calloc((size_t)m->node_count, 1);
    m->vertex_root = malloc(sizeof(int32_t) * (size_t)m->node_count);
    if (!m->joint_damage || !m->joint_slip || !m->joint_fracture || !m->joint_broke || !m->joint_h ||
        !m->elem_joint || !m->vertex_broken || !m->vertex_root || !m->joint_k) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for joints");
        return -1;
    }
    for (int k = 0; k < faces * m->elem_count; k++) m->elem_joint[k] = -1;
    for (int n = 0; n < m->node_count; n++) m->vertex_root[n] = n;
    for (int j = 0; j < m->joint_count; j++) {
        int ea = m->joint_elem[2 * j], eb = m->joint_elem[2 * j + 1];
        m->joint_h[j] = fmin(m->elem_h[ea], m->elem_h[eb]);
        int mat = element_material(m, ea);
        m->joint_k[j] = m->materials[mat].penalty / m->joint_h[j];
        for (int s = 0; s < 2; s++) {
            int e = m->joint_elem[2 * j + s];
            for (int c = 0; c < faces; c++)
                if (m->elem_joint[faces * e + c] < 0) {
                    m->elem_joint[faces * e + c] = j;
                    break;
                }
        }
    }
    return joint_strengths_assign(m, err);
}

/* Joint springs in series with the element: each face node feels about
 * p L / (2h) from one joint and sits on two joints, against its own mass. */
double joint_stable_dt(const fdem_model *m)
{
    if (m->dim == 3) return joint_stable_dt_3d(m);
    double dt = INFINITY;
    for (int j = 0; j < m->joint_count; j++) {
        const int32_t *n = m->joint_node + 4 * j;
        double mass = fmin(fmin(m->mass[n[0]], m->mass[n[1]]), fmin(m->mass[n[2]], m->mass[n[3]]));
        const material *mat = &m->materials[m->elem[m->joint_elem[2 * j]].material];
        double L = hypot(m->pos0[2 * n[1]] - m->pos0[2 * n[0]], m->pos0[2 * n[1] + 1] - m->pos0[2 * n[0] + 1]);
        double k = 2 * mat->penalty * L / m->joint_h[j]; /* two joints, both faces */
        dt = fmin(dt, joint_spring_dt(mass, k));
    }
    return dt;
}

/* True while an intact joint holds elements a and b together. */
int joint_holds(const fdem_model *m, int a, int b)
{
    if (!m->joint_count) return 0;
    int faces = m->dim + 1;
    for (int c = 0; c < faces; c++) {
        int j = m->elem_joint[faces * a + c];
        if (j < 0) continue;
        int other = m->joint_elem[2 * j] == a ? m->joint_elem[2 * j + 1] : m->joint_elem[2 * j];
        if (other == b && m->joint_damage[j] < 1.0) return 1;
    }
    return 0;
}

static int32_t node_root(int32_t *root, int32_t n)
{
    while (root[n] != n) {
        root[n] = root[root[n]];
        n = root[n];
    }
    return n;
}

/* The copies of each mesh vertex held together around it by intact joints
 * (vertex_root: one root node per such group). Two elements whose copies
 * of a vertex share a root are joined around that vertex through elements
 * and joints that still hold: the fan between them moves as one piece
 * there, as around a vertex whose every joint is intact. */
static void joint_vertex_groups(fdem_model *m)
{
    int32_t *root = m->vertex_root;
    for (int n = 0; n < m->node_count; n++) root[n] = n;
    const int D = m->dim;
    for (int j = 0; j < m->joint_count; j++) {
        if (m->joint_damage[j] >= 1.0) continue;
        const int32_t *n = m->joint_node + 2 * D * (size_t)j;
        for (int i = 0; i < D; i++) {
            int32_t a = node_root(root, n[i]), b = node_root(root, n[D + i]);
            if (a != b) root[a < b ? b : a] = a < b ? a : b;
        }
    }
    for (int n = 0; n < m->node_count; n++) root[n] = node_root(root, n);
}

/* Marks every mesh vertex that lies on a broken joint, and groups each
 * vertex's copies by the intact joints around it (joint_vertex_groups). */
void joint_mark_broken_vertices(fdem_model *m)
{
    if (!m->joint_count) return;
    memset(m->vertex_broken, 0, (size_t)m->node_count);
    int broken = 0;
    for (int j = 0; j < m->joint_count; j++) {
        /* an excavated joint opens no crack: the elements around its
         * vertices that remain are still glued (element_on_crack) */
        if (m->joint_damage[j] < 1.0 || (m->elem_active && joint_is_excavated(m, j))) continue;
        const int32_t *n = m->joint_node + 2 * m->dim * (size_t)j;
        for (int i = 0; i < m->dim; i++) m->vertex_broken[m->node_origin[n[i]]] = 1;
        broken = 1;
    }
    if (broken) joint_vertex_groups(m);
}

/* Broken vertices whose copies lie in two groups (joint_vertex_groups) of
 * one piece, or in three or more groups, are marked 2: a crack there has
 * both its faces in one piece, which may close onto itself. A vertex whose
 * groups all lie in different pieces is on cracks that part pieces only
 * (the split of a Brazilian disc): every face there meets other pieces,
 * and the elements of one piece around it can meet only by folding the
 * piece, as elements away from cracks (element_on_crack). scratch holds 4
 * node_count numbers: per vertex its first two groups and their pieces. */
static void joint_mark_inner_cracks(fdem_model *m, const int32_t *piece, int32_t *scratch)
{
    const int N = m->node_count, K = m->elem_nodes;
    int32_t *group1 = scratch, *piece1 = scratch + N, *group2 = scratch + 2 * (size_t)N,
            *piece2 = scratch + 3 * (size_t)N;
    for (int v = 0; v < N; v++) group1[v] = group2[v] = -1;
    for (int e = 0; e < m->elem_count; e++) {
        const int32_t *n = m->elem_node + (size_t)K * (size_t)e;
        for (int c = 0; c < K; c++) {
            int32_t v = m->node_origin[n[c]], g = m->vertex_root[n[c]];
            if (!m->vertex_broken[v] || g == group1[v] || g == group2[v]) continue;
            if (group1[v] < 0) {
                group1[v] = g, piece1[v] = piece[e];
            } else if (group2[v] < 0) {
                group2[v] = g, piece2[v] = piece[e];
                if (piece2[v] == piece1[v]) m->vertex_broken[v] = 2;
            } else {
                m->vertex_broken[v] = 2; /* a third group */
            }
        }
    }
}

void joint_mark_cracks(fdem_model *m, int32_t *piece, int32_t *scratch)
{
    joint_mark_broken_vertices(m);
    joint_fragment_labels(m, piece);
    if (m->joint_count) joint_mark_inner_cracks(m, piece, scratch);
}

/* True when a and b (of one fracturing part) are glued together: an intact
 * joint joins them, they share a mesh vertex around which every joint is
 * intact, or they share a node (a fracture region's elements outside its
 * joints do, as in a part that does not fracture). Such a fan of triangles
 * moves as one piece; its members overlap only by the joints' own elastic
 * compliance, which the joints resist.
 * Leaving these pairs out of contact keeps an intact fracturing block as
 * cheap as its joints instead of paying for about a dozen touching-at-a-
 * point pairs per triangle. Valid after joint_mark_broken_vertices. */
static int element_on_crack(const fdem_model *m, int e)
{
    int K = m->elem_nodes;
    const int32_t *n = m->elem_node + (size_t)K * (size_t)e;
    int on = 0;
    for (int i = 0; i < K; i++) on |= m->vertex_broken[m->node_origin[n[i]]] == 2;
    if (on || !m->elem_active) return on;
    /* a face on an excavated opening is exposed as a crack's is: the
     * elements across the opening may meet if it closes */
    const int faces = m->dim + 1;
    for (int c = 0; c < faces; c++) {
        int j = m->elem_joint[faces * e + c];
        if (j >= 0 && joint_is_excavated(m, j)) return 1;
    }
    return 0;
}

/* True when contact between a and b (of one fracturing part) can be left
 * out: they are glued (joint_fan_holds), or they belong
 * to one piece (piece[], from joint_fragment_labels) and neither has a
 * vertex on a crack inside a piece (joint_mark_inner_cracks). The faces a
 * crack exposes all have a vertex on it, so every pair that can meet
 * across a crack stays: across a crack that parts two pieces the pair is of
 * two pieces; two elements inside one piece could only meet if the piece
 * folded onto itself, which no joint in a brittle solid survives, or across
 * a crack both of whose faces it holds. This makes an intact fracturing
 * block cost its joints and no contact at all, and a split one little
 * more (issue 34). Valid after joint_mark_cracks. */
/* a and b hold one node (a fracture region's elements do where no joint
 * splits the vertex): glued there whatever the joints. */
static int elements_share_a_node(const fdem_model *m, int a, int b)
{
    int K = m->elem_nodes;
    const int32_t *na = m->elem_node + (size_t)K * (size_t)a;
    const int32_t *nb = m->elem_node + (size_t)K * (size_t)b;
    for (int i = 0; i < K; i++)
        for (int k = 0; k < K; k++)
            if (na[i] == nb[k]) return 1;
    return 0;
}

/* a and b are the two faces of a broken joint. */
static int joint_broken_between(const fdem_model *m, int a, int b)
{
    const int faces = m->dim + 1;
    for (int c = 0; c < faces; c++) {
        int j = m->elem_joint[faces * a + c];
        if (j >= 0 && m->joint_damage[j] >= 1.0 &&
            m->joint_elem[2 * j] + m->joint_elem[2 * j + 1] - a == b)
            return 1;
    }
    return 0;
}

/* e holds a face of a broken joint whose other face is of e's own piece:
 * a crack closed off around (its vertices' copies one group each), whose
 * two faces still meet each other (joint_contact_excluded keeps that
 * pair, so detection must list it). */
static int element_faces_own_piece(const fdem_model *m, const int32_t *piece, int e)
{
    const int faces = m->dim + 1;
    for (int c = 0; c < faces; c++) {
        int j = m->elem_joint[faces * e + c];
        if (j < 0 || m->joint_damage[j] < 1.0 || (m->elem_active && joint_is_excavated(m, j)))
            continue;
        if (piece[m->joint_elem[2 * j] + m->joint_elem[2 * j + 1] - e] == piece[e]) return 1;
    }
    return 0;
}

int joint_contact_excluded(const fdem_model *m, const int32_t *piece, int a, int b)
{
    /* the two faces of a broken joint always meet: pressed together,
     * nothing else stops them (the joints around may be damaged and
     * slide; the 2D Brazilian disc made 6.7 times its work without it) */
    if (m->elem_piece0 && elements_share_a_node(m, a, b)) return 1; /* a region's */
    if (joint_broken_between(m, a, b)) return 0;
    if (joint_fan_holds(m, a, b)) return 1;
    return piece[a] == piece[b] && !element_on_crack(m, a) && !element_on_crack(m, b);
}

/* The element's own body (part_count + e) marks it as one of a fracturing
 * part (contact_init, joint_region_bodies). A piece's id, part_count +
 * elements + its label, can be no element's own nor a part's: the pairs
 * left out are exactly those of one piece with neither on a crack, which
 * joint_contact_excluded drops, so the list kept is the same, in the same
 * order (detection only skips pairs), for a fraction of the work: an
 * intact fracturing block lists no pair at all. */
void joint_contact_bodies(const fdem_model *m, const int32_t *piece, const int32_t *body,
                          int32_t *out)
{
    const int32_t own = m->part_count, pieces = m->part_count + m->elem_count;
    for (int e = 0; e < m->elem_count; e++)
        out[e] = body[e] >= own && !element_on_crack(m, e) && !element_faces_own_piece(m, piece, e)
                     ? pieces + piece[e]
                     : body[e];
}

int joint_fan_holds(const fdem_model *m, int a, int b)
{
    if (joint_holds(m, a, b)) return 1;
    int K = m->elem_nodes;
    const int32_t *na = m->elem_node + (size_t)K * (size_t)a;
    const int32_t *nb = m->elem_node + (size_t)K * (size_t)b;
    for (int i = 0; i < K; i++) {
        int32_t v = m->node_origin[na[i]];
        if (m->vertex_broken[v]) { /* only a node both hold glues them now */
            if (m->elem_piece0) /* a fracture region's, where elements share nodes */
                for (int k = 0; k < K; k++)
                    if (nb[k] == na[i]) return 1;
            continue;
        }
        for (int k = 0; k < K; k++)
            if (m->node_origin[nb[k]] == v) return 1;
    }
    return 0;
}

/* --------------------------------------------------------------- forces */

/* Two-point Gauss rule along the edge, as fractions from a0 (b0) to a1 (b1). */
static const double gauss[2] = {0.21132486540518713, 0.78867513459481287};

/* The integrals over xi in [a, b] of c, xi c and c^2, c linear from ca to cb. */
static inline void linear_moments(double a, double b, double ca, double cb, double out[3])
{
    double w = b - a;
    out[0] = 0.5 * w * (ca + cb);
    out[1] = w / 6 * (ca * (2 * a + b) + cb * (a + 2 * b));
    out[2] = w / 3 * (ca * ca + ca * cb + cb * cb);
}

/* The joint's resistance to being pressed shut, k min(delta, 0) along n,
 * integrated exactly along the face (delta linear from delta0 at a0 to
 * delta1 at a1) and added to fa0, fa1; returns its stored energy,
 * 1/2 k integral min(delta, 0)^2. Two Gauss points would not do: a damaged
 * joint that opens at one end and closes at the other hinges about the
 * Gauss point nearer the closed end, where delta is about 0, and its corner
 * then sinks into the neighbour unresisted (tens of micrometres in the
 * Brazilian disc). That overlap is energy nobody paid for: the contact that
 * takes over when the joint breaks throws the faces apart with it. */
static double joint_compression(double k, double L, double delta0, double delta1, double nx,
                                double ny, double fa0[2], double fa1[2])
{
    double mom[3] = {0, 0, 0};
    if (delta0 < 0 && delta1 < 0) {
        linear_moments(0, 1, delta0, delta1, mom);
    } else if (delta0 < 0 || delta1 < 0) { /* shut between a0 (or a1) and the zero */
        double zero = delta0 / (delta0 - delta1);
        if (delta0 < 0) linear_moments(0, zero, delta0, 0, mom);
        else linear_moments(zero, 1, 0, delta1, mom);
    } else {
        return 0;
    }
    double s0 = k * L * (mom[0] - mom[1]), s1 = k * L * mom[1];
    fa0[0] += s0 * nx; fa0[1] += s0 * ny;
    fa1[0] += s1 * nx; fa1[1] += s1 * ny;
    return 0.5 * k * L * mom[2];
}

/* Forces on face A's nodes (fa0, fa1) from the Gauss-point law, for a joint
 * that is damaged or leaving its elastic range; updates *damage (the
 * largest either Gauss point asks for, never less than before) and the
 * slip each point keeps (slip[2]), and adds to *e the joint's stored
 * energy and what its damage growth and slip dissipated; a joint that
 * breaks while pressed shut adds the energy of its compression, which the
 * contact of its faces takes over, to e->handed. d0 and d1 are the
 * displacements of b0 against a0 and b1 against a1; (tx, ty) the unit face
 * tangent and L the face length. The slide is along that tangent, so a
 * rigid rotation of the pair leaves it, and the plastic slide kept against
 * it, as they were. */
static void joint_forces_general(const joint_law *law, const double d0[2], const double d1[2],
                                 double tx, double ty, double L, double *damage,
                                 joint_slip slip[2], double fa0[2], double fa1[2],
                                 joint_energy *e)
{
    double nx = ty, ny = -tx; /* A's outward normal */
    joint_point g[2];
    for (int i = 0; i < 2; i++) {
        double xi = gauss[i];
        double dx = (1 - xi) * d0[0] + xi * d1[0], dy = (1 - xi) * d0[1] + xi * d1[1];
        const double slide[2] = {dx * tx + dy * ty, 0};
        joint_point_measure(law, dx * nx + dy * ny, slide, &slip[i], &g[i]);
    }
    double D = joint_points_damage(g, 2, *damage);
    double z_old, z;
    joint_softening_step(*damage, D, &z_old, &z);
    *damage = D;
    if (D >= 1) e->broke = joint_points_mode(law, g, 2);
    double w = 0.5 * L; /* Gauss weight */
    fa0[0] = fa0[1] = fa1[0] = fa1[1] = 0;
    for (int i = 0; i < 2; i++) {
        double xi = gauss[i], sigma, tau[2];
        joint_point_respond(law, &g[i], w, z_old, z, e, &sigma, tau);
        slip[i] = g[i].slip;
        double Tx = w * (sigma * nx + tau[0] * tx), Ty = w * (sigma * ny + tau[0] * ty);
        fa0[0] += (1 - xi) * Tx; fa0[1] += (1 - xi) * Ty;
        fa1[0] += xi * Tx;       fa1[1] += xi * Ty;
    }
    double squeezed = joint_compression(law->k, L, d0[0] * nx + d0[1] * ny,
                                        d1[0] * nx + d1[1] * ny, nx, ny, fa0, fa1);
    e->stored += squeezed;
    if (D >= 1) e->handed += squeezed; /* broken shut: its overlap goes on as contact */
}

typedef struct joint_view_2d {
    const double *x;
    const joint_strength *strengths;
} joint_view_2d;

/* What the loop reads of the model, once per call: the loop stores into
 * model arrays, and without these locals the compiler reloads them per
 * joint (11 % more instructions measured). */
static inline joint_view_2d joint_view_of(const fdem_model *m)
{
    return (joint_view_2d){m->pos, m->joint_strengths};
}

/* A joint past the elastic test: its law point by point
 * (joint_forces_general) with the slip its points keep; returns the new
 * damage, face A's forces in fa. Kept out of line and handed the gaps by
 * value, so that nothing the elastic path holds has its address taken: it
 * stays in registers (joint_forces_range_2d took 5-11 % more instructions
 * with this path inline in a function of two callers, which gcc then kept
 * apart). */
static __attribute__((noinline)) double joint_softening_2d(const fdem_model *m,
                                                            const joint_view_2d *w, int j,
                                                            double damage, double d0x,
                                                            double d0y, double d1x, double d1y,
                                                            double tx, double ty, double L,
                                                            double fa[4], joint_energy *e)
{
    const double d0[2] = {d0x, d0y}, d1[2] = {d1x, d1y};
    const joint_law law = joint_law_of(&w->strengths[m->joint_strength_of[j]], m->joint_k[j]);
    double inv_L = 1.0 / L;
    joint_forces_general(&law, d0, d1, tx * inv_L, ty * inv_L, L, &damage,
                         m->joint_slip + 2 * (size_t)j, fa, fa + 2, e);
    return damage;
}

/* Joint j's forces on face A (fa: a0 then a1; face B takes their
 * negatives), its damage and its share of the running sums t (joints that
 * broke, stored energy, what damage growth dissipated, the compression
 * energy of those that broke shut, the frictional work of their sliding in
 * the last step). Returns 0 when it adds nothing: broken before or now, or
 * its face is degenerate.
 *
 * Nearly every joint in nearly every step is undamaged and elastic at both
 * Gauss points. There the traction is k (delta n + s t) = k d: the penalty
 * acts on the whole relative displacement, whatever the face's direction,
 * and the two-point rule integrates the linear d exactly:
 *   f_a0 = L k (2 d0 + d1) / 6,   f_a1 = L k (d0 + 2 d1) / 6,
 * the same forces as the Gauss-point sum, without unit vectors, tractions or
 * the damage bookkeeping. Only the elastic test needs the projections. */
static inline __attribute__((always_inline)) int joint_evaluate_2d(fdem_model *m,
                                                                    const joint_view_2d *w, int j,
                                                                    const double *offset,
                                                                    joint_totals *t,
                                                                    double fa[4])
{
    const double *x = w->x;
    double damage = m->joint_damage[j];
    if (damage >= 1.0) return 0;
    const int32_t *n = m->joint_node + 4 * j;
    const joint_law law = joint_law_of(&w->strengths[m->joint_strength_of[j]], m->joint_k[j]);
    const double k = law.k;
    const double *a0 = x + 2 * (size_t)n[0], *a1 = x + 2 * (size_t)n[1];
    const double *b0 = x + 2 * (size_t)n[2], *b1 = x + 2 * (size_t)n[3];
    double d0[2] = {b0[0] - a0[0], b0[1] - a0[1]}, d1[2] = {b1[0] - a1[0], b1[1] - a1[1]};
    /* mean face tangent, length L: A's edge plus half the gap change */
    double tx = (a1[0] - a0[0]) + 0.5 * (d1[0] - d0[0]);
    double ty = (a1[1] - a0[1]) + 0.5 * (d1[1] - d0[1]);
    double L2 = tx * tx + ty * ty;
    if (!(L2 > 0)) return 0;
    double L = sqrt(L2);
    if (offset) joint_add_offsets_2d(offset + 4 * (size_t)j, tx, ty, L, d0, d1);
    double *fa0 = fa, *fa1 = fa + 2;
    int elastic = 0;
    if (damage == 0) {
        double g0x = (1 - gauss[0]) * d0[0] + gauss[0] * d1[0];
        double g0y = (1 - gauss[0]) * d0[1] + gauss[0] * d1[1];
        double g1x = (1 - gauss[1]) * d0[0] + gauss[1] * d1[0];
        double g1y = (1 - gauss[1]) * d0[1] + gauss[1] * d1[1];
        /* (tx, ty) has length L, normal (ty, -tx): projections are L x */
        elastic = joint_point_elastic(&law, L, g0x * ty - g0y * tx, g0x * tx + g0y * ty) &&
                  joint_point_elastic(&law, L, g1x * ty - g1y * tx, g1x * tx + g1y * ty);
    }
    if (elastic) {
        double s = L * k * (1.0 / 6);
        fa0[0] = s * (2 * d0[0] + d1[0]);
        fa0[1] = s * (2 * d0[1] + d1[1]);
        fa1[0] = s * (d0[0] + 2 * d1[0]);
        fa1[1] = s * (d0[1] + 2 * d1[1]);
        /* 1/2 integral of k |d|^2 along the face, exact for linear d */
        t->stored += 0.5 * ((fa0[0] * d0[0] + fa0[1] * d0[1]) + (fa1[0] * d1[0] + fa1[1] * d1[1]));
        return 1;
    }
    joint_energy e = {0};
    double g[4]; /* its own array: fa stays in registers on the elastic path */
    damage = joint_softening_2d(m, w, j, damage, d0[0], d0[1], d1[0], d1[1], tx, ty, L, g, &e);
    t->dissipated += e.dissipated;
    t->handed += e.handed;
    t->friction += e.friction;
    m->joint_fracture[j] += e.dissipated;
    if (damage >= 1.0) { /* broken within this step: it carries nothing from now on */
        m->joint_damage[j] = 1.0;
        m->joint_broke[j] = (uint8_t)e.broke;
        t->broke++;
        return 0;
    }
    t->stored += e.stored;
    m->joint_damage[j] = damage;
    for (int i = 0; i < 4; i++) fa[i] = g[i];
    return 1;
}

/* Adds the forces of intact joints [begin, end) to m->force, continuing
 * the running sums (joint_totals) in sums; offset is m->joint_offset,
 * passed as a constant NULL by the loop of models without in-situ gaps so
 * that theirs compiles without a trace of them. */
static inline __attribute__((always_inline)) void joint_loop_2d(fdem_model *m, int begin, int end,
                                                                const double *offset,
                                                                double sums[SCATTER_SUMS])
{
    double *f = m->force;
    const joint_view_2d w = joint_view_of(m);
    /* a local, so that the loop's sums stay in registers */
    joint_totals t = joint_totals_load(sums);
    for (int j = begin; j < end; j++) {
        double fa[4];
        if (!joint_evaluate_2d(m, &w, j, offset, &t, fa)) continue;
        const int32_t *n = m->joint_node + 4 * j;
        double *ga0 = f + 2 * (size_t)n[0], *ga1 = f + 2 * (size_t)n[1];
        double *gb0 = f + 2 * (size_t)n[2], *gb1 = f + 2 * (size_t)n[3];
        ga0[0] += fa[0]; ga0[1] += fa[1];
        ga1[0] += fa[2]; ga1[1] += fa[3];
        gb0[0] -= fa[0]; gb0[1] -= fa[1];
        gb1[0] -= fa[2]; gb1[1] -= fa[3];
    }
    joint_totals_store(&t, sums);
}

static __attribute__((noinline)) void joint_offset_loop_2d(fdem_model *m, int begin, int end,
                                                           double sums[SCATTER_SUMS])
{
    joint_loop_2d(m, begin, end, m->joint_offset, sums);
}

void joint_forces_range_2d(fdem_model *m, int begin, int end, double sums[SCATTER_SUMS])
{
    if (m->joint_offset) joint_offset_loop_2d(m, begin, end, sums);
    else joint_loop_2d(m, begin, end, NULL, sums);
}

/* Joint j alone, its face A forces handed back (joint_one_fn). */
int joint_forces_one_2d(fdem_model *m, int j, joint_totals *t, double fa[JOINT_FACE_VALUES])
{
    const joint_view_2d w = joint_view_of(m);
    return joint_evaluate_2d(m, &w, j, m->joint_offset, t, fa);
}

/* Adds the forces of every intact joint to m->force, sets the joints'
 * stored energy and adds what they dissipated to the fracture account (by
 * damage) and the friction account (by sliding against sigma_c tan(phi)).
 * Each joint that broke is one fracture event (events.c). Returns the
 * number of joints that broke in this call, or -1 when there was no memory
 * to record their events. */
int joint_forces(fdem_model *m)
{
    double sums[SCATTER_SUMS] = {0};
    if (m->dim == 3) joint_sweep_run(m, joint_forces_range_3d, joint_forces_one_3d, sums);
    else joint_sweep_run(m, joint_forces_range_2d, joint_forces_one_2d, sums);
    m->joint_energy = sums[1];
    m->fracture_energy += sums[2];
    m->joint_friction_energy += sums[4];
    m->contact_work -= sums[3]; /* what the contact of broken-shut faces now holds */
    int broke = (int)sums[0];
    if (broke && events_collect(m, broke)) return -1;
    return broke;
}

/* ------------------------------------------------------------ fragments */

static int uf_find(int32_t *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* The first active element of part p (its piece's root once elements were
 * excavated), or the part's first element when none is left. */
static int part_root(const fdem_model *m, int p)
{
    const part *pt = &m->parts[p];
    for (int e = pt->elem_begin; e < pt->elem_begin + pt->elem_count; e++)
        if (element_is_active(m, e)) return e;
    return pt->elem_begin;
}

/* Labels every element with its piece (elements joined by intact joints
 * or shared nodes; a part that does not fracture is one piece): label[e] is
 * the smallest active element of e's piece. Returns the number of pieces.
 * An excavated element is a piece of its own that is not counted (its
 * joints read broken: excavation.c). A part that does not fracture stays
 * one piece however excavation cuts it. */
int joint_fragment_labels(const fdem_model *m, int32_t *label)
{
    int root = -1, root_part = -1;
    for (int e = 0; e < m->elem_count; e++) {
        int p = m->elem_part[e];
        if (m->elem_piece0 && element_is_active(m, e)) {
            /* elem_piece0[e] <= e is the first element of e's piece; once
             * it was excavated, its slot holds the piece's first active
             * element, which every later one then joins */
            int r = m->elem_piece0[e];
            if (r != e && !element_is_active(m, r) && label[r] == r) label[r] = e;
            label[e] = r == e ? e : label[r];
            continue;
        }
        if (m->parts[p].fracture || m->elem_piece0 || !element_is_active(m, e)) {
            label[e] = e;
            continue;
        }
        if (p != root_part) root = m->elem_active ? part_root(m, p) : m->parts[p].elem_begin;
        root_part = p;
        label[e] = root;
    }
    for (int j = 0; j < m->joint_count; j++) {
        if (m->joint_damage[j] >= 1.0) continue;
        int a = uf_find(label, m->joint_elem[2 * j]), b = uf_find(label, m->joint_elem[2 * j + 1]);
        if (a != b) label[a < b ? b : a] = a < b ? a : b;
    }
    int count = 0;
    for (int e = 0; e < m->elem_count; e++) {
        label[e] = uf_find(label, e);
        count += label[e] == e && element_is_active(m, e);
    }
    return count;
}

/* The number of pieces, or -1 on allocation failure. */
int joint_fragment_count(const fdem_model *m)
{
    int32_t *label = malloc(sizeof(int32_t) * (size_t)(m->elem_count ? m->elem_count : 1));
    if (!label) return -1;
    int count = joint_fragment_labels(m, label);
    free(label);
    return count;
}
