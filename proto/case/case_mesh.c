/*
 * case_mesh.c - meshes a user gives rather than the daemon generates: an
 * explicit "mesh" {nodes, triangles | tetrahedra} or the text of a gmsh
 * file, in the case's dimension, read and validated in pass 1.
 *
 * They are parsed in pass 1 because their size is bounded by the upload and
 * their errors (a bad tetrahedron, a gmsh line) belong in the full list of
 * problems. Both dimensions go through the same readers, parametrised by a
 * mesh_kind (how many numbers per node, how many nodes per element, what
 * the elements are called), so a 3D mesh is checked exactly like a 2D one
 * and its problems carry pointers of the same form
 * ("/parts/2/mesh/tetrahedra/7").
 */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"
#include "gmsh/gmsh.h"
#include "math/node_ids.h"

typedef struct mesh_kind {
    int dimension;           /* numbers per node */
    int corners;             /* nodes per element */
    const char *cells_key;   /* "triangles", "tetrahedra" */
    const char *cell_word;   /* "triangle", "tetrahedron" */
    const char *cell_layout; /* "three node indices [i, j, k]" */
    fdem_item_kind cell_item;
} mesh_kind;

static const mesh_kind mesh_kinds[2] = {
    {2, 3, "triangles", "triangle", "three node indices [i, j, k]", FDEM_ITEM_TRIANGLE},
    {3, 4, "tetrahedra", "tetrahedron", "four node indices [a, b, c, d]",
     FDEM_ITEM_TETRAHEDRON},
};

static const mesh_kind *mesh_kind_of(const case_doc *doc)
{
    return &mesh_kinds[doc->dimension == 3];
}

/* Where part's nodes and elements end up, whichever the dimension. */
typedef struct mesh_arrays {
    int *node_count, *cell_count;
    double **nodes;
    int32_t **cells;
} mesh_arrays;

static mesh_arrays mesh_arrays_of(case_part *part, const mesh_kind *kind)
{
    if (kind->dimension == 3)
        return (mesh_arrays){&part->tet_mesh.node_count, &part->tet_mesh.tet_count,
                             &part->tet_mesh.xyz, &part->tet_mesh.tet};
    return (mesh_arrays){&part->mesh.node_count, &part->mesh.triangle_count, &part->mesh.xy,
                         &part->mesh.tri};
}

/* ------------------------------------------------------- explicit mesh */

/* Room for the `width` numbers of each item of the list at `ptr`, which
 * must hold at least `min` items (`need` says so: "4 nodes"); NULL after a
 * problem. The engine counts in int, so width * count must fit one. */
static void *mesh_list_alloc(case_doc *doc, const json_t *list, const char *ptr, size_t min,
                             const char *need, int width, size_t item_size, int *count)
{
    if (!case_expect_array(doc, list, ptr)) return NULL;
    size_t n = json_array_size(list);
    if (n < min || n > (size_t)(INT_MAX / width)) {
        case_problem(doc, ptr, "a mesh needs at least %s, got %zu", need, n);
        return NULL;
    }
    void *items = malloc((size_t)width * n * item_size);
    if (!items) {
        case_problem(doc, ptr, "out of memory");
        return NULL;
    }
    *count = (int)n;
    return items;
}

/* Nodes [[x, y(, z)], ...]; each bad node is reported. */
static int mesh_read_nodes(case_doc *doc, const mesh_kind *kind, mesh_arrays a,
                           const json_t *nodes, const char *ptr)
{
    int dim = kind->dimension;
    char need[32];
    snprintf(need, sizeof need, "%d nodes", dim + 1);
    *a.nodes = mesh_list_alloc(doc, nodes, ptr, (size_t)dim + 1, need, dim, sizeof **a.nodes,
                               a.node_count);
    int ok = *a.nodes != NULL;
    for (int i = 0; *a.nodes && i < *a.node_count; i++) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, i);
        ok &= case_read_axes(doc, json_array_get(nodes, (size_t)i), at,
                             &(*a.nodes)[(size_t)dim * (size_t)i]);
    }
    return ok;
}

/* One element: `corners` 0-based indices below node_count. */
static int mesh_read_cell(case_doc *doc, const mesh_kind *kind, const json_t *cell,
                          const char *ptr, int node_count, int32_t *out)
{
    if (!json_is_array(cell) || json_array_size(cell) != (size_t)kind->corners) {
        case_problem(doc, ptr, "expected %s, got %s%s", kind->cell_layout, case_type_word(cell),
                     json_is_array(cell) ? " of another length" : "");
        return 0;
    }
    int ok = 1;
    for (int k = 0; k < kind->corners; k++) {
        char item[CASE_POINTER];
        long index = 0;
        pointer_join_index(item, sizeof item, ptr, k);
        if (!case_read_integer(doc, json_array_get(cell, (size_t)k), item, 0, LONG_MAX, &index)) {
            ok = 0;
        } else if (node_count > 0 && index >= node_count) {
            case_problem(doc, ptr, "node index %ld is out of range: the mesh has %d nodes "
                                   "(indices 0 to %d)", index, node_count, node_count - 1);
            ok = 0;
        } else {
            out[k] = (int32_t)index;
        }
    }
    return ok;
}

static int mesh_read_cells(case_doc *doc, const mesh_kind *kind, mesh_arrays a,
                           const json_t *cells, const char *ptr)
{
    char need[32];
    snprintf(need, sizeof need, "one %s", kind->cell_word);
    *a.cells = mesh_list_alloc(doc, cells, ptr, 1, need, kind->corners, sizeof **a.cells,
                               a.cell_count);
    int ok = *a.cells != NULL;
    for (int t = 0; *a.cells && t < *a.cell_count; t++) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, t);
        ok &= mesh_read_cell(doc, kind, json_array_get(cells, (size_t)t), at, *a.node_count,
                             &(*a.cells)[(size_t)kind->corners * (size_t)t]);
    }
    return ok;
}

/* Runs the engine's mesh check for the dimension (finite nodes, zero
 * sizes, unused nodes; reorients the other orientation). */
static int mesh_validate(case_part *part, const mesh_kind *kind, fdem_error *err)
{
    int reoriented = 0;
    if (kind->dimension == 3) return fdem_tet_mesh_validate(&part->tet_mesh, &reoriented, err);
    return fdem_mesh_validate(&part->mesh, &reoriented, err);
}

/* A cell's nodes in increasing order (unused corners -1) and its index:
 * equal keys are the same element listed twice, in any node order. */
typedef struct cell_key {
    int32_t nodes[4];
    int index;
} cell_key;

static int cell_key_compare(const void *pa, const void *pb)
{
    const cell_key *a = pa, *b = pb;
    int c = node_ids_compare(a->nodes, b->nodes, 4);
    return c ? c : (a->index > b->index) - (a->index < b->index);
}

static cell_key cell_key_of(const mesh_kind *kind, const int32_t *cells, int t)
{
    cell_key c = {{-1, -1, -1, -1}, t};
    memcpy(c.nodes, cells + (size_t)kind->corners * (size_t)t, (size_t)kind->corners * sizeof *cells);
    node_ids_sort(c.nodes, kind->corners);
    return c;
}

/* A repeated element would carry its mass and stiffness twice and pass
 * every other check (a fracturing part would find its faces "shared by
 * more than two"), so it is named here: the later of the first pair
 * found, with the earlier in the message (the list has one problem, as
 * the engine's checks give). gmsh files need no such check:
 * the reader merges their repeats (2.2 writes one per physical group). */
static void mesh_check_repeats(case_doc *doc, const mesh_kind *kind, mesh_arrays a,
                               const char *cells_ptr)
{
    int n = *a.cell_count;
    cell_key *keys = malloc((size_t)n * sizeof *keys);
    if (!keys) {
        case_problem(doc, cells_ptr, "out of memory");
        return;
    }
    for (int t = 0; t < n; t++) keys[t] = cell_key_of(kind, *a.cells, t);
    qsort(keys, (size_t)n, sizeof *keys, cell_key_compare);
    for (int t = 1; t < n; t++)
        if (node_ids_compare(keys[t].nodes, keys[t - 1].nodes, 4) == 0) {
            char at[CASE_POINTER];
            pointer_join_index(at, sizeof at, cells_ptr, keys[t].index);
            case_problem(doc, at, "%s %d has the same nodes as %s %d", kind->cell_word,
                         keys[t].index, kind->cell_word, keys[t - 1].index);
            break;
        }
    free(keys);
}

/* A problem about item err->item of the mesh at `mesh_ptr`: under its
 * "nodes" or element list when it names one, else at the mesh itself. */
static void mesh_item_problem(case_doc *doc, const mesh_kind *kind, const fdem_error *err,
                              const char *mesh_ptr)
{
    const char *list = err->kind == FDEM_ITEM_NODE ? "nodes"
                       : err->kind == kind->cell_item ? kind->cells_key
                                                      : NULL;
    if (!list || err->item < 0) {
        case_problem(doc, mesh_ptr, "%s", err->message);
        return;
    }
    char list_ptr[CASE_POINTER], at[CASE_POINTER];
    pointer_join(list_ptr, sizeof list_ptr, mesh_ptr, list);
    pointer_join_index(at, sizeof at, list_ptr, err->item);
    case_problem(doc, at, "%s", err->message);
}

void case_read_mesh(case_doc *doc, case_part *part, const json_t *mesh, const char *ptr)
{
    const mesh_kind *kind = mesh_kind_of(doc);
    const char *const keys[] = {"nodes", kind->cells_key, NULL};
    if (!case_expect_object(doc, mesh, ptr)) return;
    case_check_keys(doc, mesh, ptr, keys, kind->dimension == 3 ? "a 3D mesh" : "a mesh");
    char nodes_ptr[CASE_POINTER], cells_ptr[CASE_POINTER];
    json_t *nodes = case_member(mesh, ptr, "nodes", nodes_ptr);
    json_t *cells = case_member(mesh, ptr, kind->cells_key, cells_ptr);
    if (!nodes)
        case_problem(doc, ptr, "missing required \"nodes\" %s",
                     kind->dimension == 3 ? "[[x, y, z], ...]" : "[[x, y], ...]");
    if (!cells)
        case_problem(doc, ptr, "missing required \"%s\" [%s, ...]", kind->cells_key,
                     strchr(kind->cell_layout, '['));
    if (!nodes || !cells) return;
    mesh_arrays a = mesh_arrays_of(part, kind);
    int ok = mesh_read_nodes(doc, kind, a, nodes, nodes_ptr);
    ok &= mesh_read_cells(doc, kind, a, cells, cells_ptr);
    fdem_error err = {0};
    if (ok && mesh_validate(part, kind, &err) != 0)
        mesh_item_problem(doc, kind, &err, ptr);
    else if (ok)
        mesh_check_repeats(doc, kind, a, cells_ptr);
}

/* ---------------------------------------------------------------- gmsh */

/* memmem without _GNU_SOURCE: does s[0 .. n) contain word? */
static int text_contains(const char *s, size_t n, const char *word)
{
    size_t w = strlen(word);
    for (const char *p = s; n >= w && (p = memchr(p, word[0], n - w + 1 - (size_t)(p - s)));
         p++)
        if (memcmp(p, word, w) == 0) return 1;
    return 0;
}

void case_read_gmsh(case_doc *doc, case_part *part, const json_t *text, const char *ptr)
{
    if (!json_is_string(text)) {
        case_problem(doc, ptr, "expected the text of a .msh file, got %s", case_type_word(text));
        return;
    }
    const mesh_kind *kind = mesh_kind_of(doc);
    char message[400];
    const char *s = json_string_value(text);
    size_t n = json_string_length(text);
    /* only named groups can be used, so a file without names skips them */
    gmsh_groups *groups = text_contains(s, n, "$PhysicalNames") ? &part->groups : NULL;
    int rc = kind->dimension == 3
                 ? gmsh_read_tetrahedra_grouped(s, n, &part->tet_mesh, groups, message,
                                                sizeof message)
                 : gmsh_read_grouped(s, n, &part->mesh, groups, message, sizeof message);
    if (rc < 0) {
        case_problem(doc, ptr, "%s", message);
        return;
    }
    fdem_error err = {0};
    /* the file's numbering is not the user's: the gmsh text is the place */
    if (mesh_validate(part, kind, &err) != 0)
        case_problem(doc, ptr, "in the gmsh mesh: %s", err.message);
}

/* -------------------------------------------------------------- pass 3 */

void case_mesh_problem(case_doc *doc, int part, const fdem_error *err, const char *fallback)
{
    const mesh_kind *kind = mesh_kind_of(doc);
    int names_item = err->item >= 0 &&
                     (err->kind == FDEM_ITEM_NODE || err->kind == kind->cell_item);
    if (doc->parts[part].shape != CASE_SHAPE_MESH || !names_item) {
        case_problem(doc, fallback, "%s", err->message);
        return;
    }
    char mesh_ptr[CASE_POINTER];
    case_part_mesh_pointer(doc, part, mesh_ptr);
    mesh_item_problem(doc, kind, err, mesh_ptr);
}
