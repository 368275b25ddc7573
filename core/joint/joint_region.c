/*
 * joint_region.c - fracture in a region (contract 6.1), both dimensions:
 * which corners of a part's elements share a node, and which elements move
 * as one piece through those shared nodes.
 *
 * A fracturing part puts a joint on every interior face (2D: edge) whose
 * two elements both lie in its fracture region (every element, for a
 * whole part). A joint needs a node of its own on each side; everywhere
 * else the part stays one continuous body, bonded to the region. So a mesh
 * vertex gets one node per class of its elements that are connected,
 * around it, through faces that carry no joint: a union-find over the
 * element corners (K per element), joining the two corners each jointless
 * interior face has at each of its vertices. The classes are numbered in
 * the order of their first corner (element by element, corner by corner),
 * which for a whole fracturing part, where no face joins anything, is
 * corner K t + c -> node K t + c: exactly the numbering a fracturing part
 * has always had. Faces are an element's corners but one, so the same
 * code serves triangles (edges, 2 vertices) and tetrahedra (faces, 3).
 *
 * The pieces: elements that share a node never come apart, so the
 * fragment labels (joint.c) start from the classes of elements joined
 * through shared nodes, computed once at finalize (model.elem_piece0).
 * And the bodies of contact detection: an element with no vertex on any
 * joint can never face a crack, so it joins its part's one body.
 */
#include <stdlib.h>
#include <string.h>

#include "math/node_ids.h"
#include "model/model.h"
#include "joint.h"

/* One face of one element: its vertices (mesh ids, ascending; a 2D edge
 * has its third key -1, so edges and triangles compare alike) and which of
 * the element's corners is not on it. */
typedef struct region_face {
    int32_t key[3];
    int32_t elem;
    int32_t off;
} region_face;

static int region_face_compare(const void *pa, const void *pb)
{
    const region_face *a = pa, *b = pb;
    int c = node_ids_compare(a->key, b->key, 3);
    return c ? c : a->elem < b->elem ? -1 : a->elem > b->elem;
}

/* The root of i, halving the path on the way. */
static int32_t corner_root(int32_t *parent, int32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* Joins the classes of i and j; the smaller index stays the root, so a
 * class's root is its first corner. */
static void corner_join(int32_t *parent, int32_t i, int32_t j)
{
    i = corner_root(parent, i);
    j = corner_root(parent, j);
    if (i != j) parent[i < j ? j : i] = i < j ? i : j;
}

/* Joins, at every vertex of the face they share, the corners of elements
 * a and b (K corners each; the face is a's corners but a_off). */
static void join_across(int32_t *parent, const int32_t *elems, int K, int a, int a_off, int b)
{
    for (int ca = 0; ca < K; ca++) {
        if (ca == a_off) continue;
        int32_t v = elems[(size_t)K * (size_t)a + (size_t)ca];
        for (int cb = 0; cb < K; cb++)
            if (elems[(size_t)K * (size_t)b + (size_t)cb] == v)
                corner_join(parent, K * a + ca, K * b + cb);
    }
}

/* Joins the corners across every interior face that carries no joint (one
 * of its two elements lies outside the region). 0, or -1 without memory. */
static int join_jointless_faces(int32_t *parent, const int32_t *elems, int elem_count, int K,
                                const uint8_t *in_region, int part_index, fdem_error *err)
{
    const int D = K - 1;
    size_t nf = (size_t)K * (size_t)elem_count;
    region_face *faces = joint_build_scratch(sizeof *faces * nf, part_index, err);
    if (!faces) return -1;
    for (int t = 0; t < elem_count; t++)
        for (int off = 0; off < K; off++) {
            region_face *f = &faces[(size_t)K * (size_t)t + (size_t)off];
            int n = 0;
            f->key[2] = -1;
            for (int c = 0; c < K; c++)
                if (c != off) f->key[n++] = elems[(size_t)K * (size_t)t + (size_t)c];
            node_ids_sort(f->key, D);
            f->elem = t;
            f->off = off;
        }
    qsort(faces, nf, sizeof *faces, region_face_compare);
    for (size_t k = 0; k + 1 < nf; k++) {
        const region_face *a = &faces[k], *b = &faces[k + 1];
        if (node_ids_compare(a->key, b->key, 3) != 0) continue;
        if (!(in_region[a->elem] && in_region[b->elem]))
            join_across(parent, elems, K, a->elem, a->off, b->elem);
        k++; /* a face shared by more than two elements is the joint builder's error */
    }
    free(faces);
    return 0;
}

int joint_region_nodes(const int32_t *elems, int elem_count, int K, const uint8_t *in_region,
                       int32_t *corner_node, int *node_count, int part_index, fdem_error *err)
{
    size_t corners = (size_t)K * (size_t)elem_count;
    for (size_t i = 0; i < corners; i++) corner_node[i] = (int32_t)i;
    if (in_region &&
        join_jointless_faces(corner_node, elems, elem_count, K, in_region, part_index, err))
        return -1;
    /* every corner to its root first: the numbering below overwrites the
     * links as it goes, so no walk may pass through a numbered corner */
    for (size_t i = 0; i < corners; i++) corner_node[i] = corner_root(corner_node, (int32_t)i);
    /* roots are first corners, so a root is numbered before its class's others */
    int next = 0;
    for (size_t i = 0; i < corners; i++) {
        int32_t r = corner_node[i];
        corner_node[i] = r == (int32_t)i ? next++ : corner_node[r];
    }
    *node_count = next;
    return 0;
}

/* ---------------------------------------------------- pieces by node */

static int32_t piece_root(int32_t *piece, int32_t e)
{
    while (piece[e] != e) {
        piece[e] = piece[piece[e]];
        e = piece[e];
    }
    return e;
}

/* Elements of region part p joined through the nodes they share. first is
 * scratch of the part's node count. */
static void region_part_pieces(const fdem_model *m, const part *p, int32_t *piece, int32_t *first)
{
    const int K = m->elem_nodes;
    for (int i = 0; i < p->node_count; i++) first[i] = -1;
    for (int e = p->elem_begin; e < p->elem_begin + p->elem_count; e++) {
        for (int c = 0; c < K; c++) {
            int32_t n = m->elem_node[(size_t)K * (size_t)e + (size_t)c] - p->node_begin;
            if (first[n] < 0) {
                first[n] = e;
                continue;
            }
            int32_t a = piece_root(piece, e), b = piece_root(piece, first[n]);
            if (a != b) piece[a < b ? b : a] = a < b ? a : b;
        }
    }
    for (int e = p->elem_begin; e < p->elem_begin + p->elem_count; e++)
        piece[e] = piece_root(piece, e);
}

int joint_region_pieces(fdem_model *m, fdem_error *err)
{
    int regions = 0, most_nodes = 0;
    for (int k = 0; k < m->part_count; k++)
        if (m->parts[k].region) {
            regions++;
            if (m->parts[k].node_count > most_nodes) most_nodes = m->parts[k].node_count;
        }
    if (!regions) return 0;
    m->elem_piece0 = malloc(sizeof(int32_t) * (size_t)m->elem_count);
    int32_t *first = malloc(sizeof(int32_t) * (size_t)most_nodes);
    if (!m->elem_piece0 || !first) {
        free(first);
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the fracture regions");
        return -1;
    }
    for (int e = 0; e < m->elem_count; e++) {
        const part *p = &m->parts[m->elem_part[e]];
        m->elem_piece0[e] = p->fracture ? e : p->elem_begin;
    }
    for (int k = 0; k < m->part_count; k++)
        if (m->parts[k].region) region_part_pieces(m, &m->parts[k], m->elem_piece0, first);
    free(first);
    return 0;
}

/* ------------------------------------------------ bodies for contact */

/* In a fracture region's part, an element with no vertex on a joint can
 * never have a crack face (every face a crack exposes has a vertex on a
 * broken joint): such elements are one body with the part's number, as a
 * part that does not fracture, so detection never pairs them with each
 * other; they still meet every other element. 0, or -1 without memory. */
int joint_region_bodies(const fdem_model *m, int32_t *body)
{
    int regions = 0;
    for (int k = 0; k < m->part_count; k++) regions |= m->parts[k].region;
    if (!regions) return 0;
    uint8_t *jointed = calloc((size_t)m->node_count + 1, 1); /* per mesh vertex */
    if (!jointed) return -1;
    const int K = m->elem_nodes, face_nodes = 2 * m->dim;
    for (int j = 0; j < m->joint_count; j++)
        for (int i = 0; i < face_nodes; i++)
            jointed[m->node_origin[m->joint_node[(size_t)face_nodes * (size_t)j + (size_t)i]]] = 1;
    for (int e = 0; e < m->elem_count; e++) {
        int p = m->elem_part[e];
        if (!m->parts[p].region) continue;
        int on = 0;
        for (int c = 0; c < K; c++)
            on |= jointed[m->node_origin[m->elem_node[(size_t)K * (size_t)e + (size_t)c]]];
        if (!on) body[e] = p;
    }
    free(jointed);
    return 0;
}
