/*
 * case_region.c - fracture in a region (contract 6.1): a part's "fracture"
 * given as a selector, {"box": [...]} (elements whose centroid lies in the
 * box, bounds inclusive) or {"group": G} (the elements of a physical group
 * of the part's gmsh mesh), or a non-empty list of them (their union).
 *
 * Pass 1 reads the selectors (after the part's shape and groups, which a
 * group needs) and, for a mesh that is already read (mesh, gmsh), checks
 * that every selector selects some element; a generated shape's boxes are
 * checked right after pass 1, with its other problems (case_boxes.c), and
 * in pass 3 its part goes to the engine with a flag per element
 * (fdem_add_part_region). A problem is at the
 * selector's pointer: /parts/i/fracture, or /parts/i/fracture/k in a list.
 * That the part's material has a "fracture" block is checked with the
 * flag itself (case_parts.c), at /parts/i/fracture.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"

static const char *const selector_keys[] = {"box", "group", NULL};

static void selector_pointer(const char *part_ptr, int listed, int k, char *out)
{
    char fracture[CASE_POINTER];
    pointer_join(fracture, sizeof fracture, part_ptr, "fracture");
    if (listed) pointer_join_index(out, CASE_POINTER, fracture, k);
    else snprintf(out, CASE_POINTER, "%s", fracture);
}

/* One selector at ptr into *s: 1, or 0 after a problem. */
static int read_selector(case_doc *doc, const case_part *part, const json_t *value,
                         const char *ptr, case_region_selector *s)
{
    if (!json_is_object(value)) {
        case_problem(doc, ptr, "expected a selector {\"box\": [...]} or {\"group\": \"name\"}, "
                               "got %s", case_type_word(value));
        return 0;
    }
    if (!case_check_keys(doc, value, ptr, selector_keys, "a fracture region selector")) return 0;
    json_t *box = json_object_get(value, "box"), *group = json_object_get(value, "group");
    if (!box == !group) {
        case_problem(doc, ptr, "a fracture region selector has exactly one of \"box\" (element "
                               "centroids) or \"group\" (a physical group of the gmsh mesh)");
        return 0;
    }
    s->group = -1;
    if (box) {
        char at[CASE_POINTER];
        pointer_join(at, sizeof at, ptr, "box");
        return case_read_box(doc, box, at, s->box);
    }
    int readable = doc->dimension == 3 ? part->tet_mesh.tet != NULL : part->mesh.tri != NULL;
    if (part->shape == CASE_SHAPE_GMSH && !readable) return 0; /* the mesh's problem says why */
    if (part->shape == CASE_SHAPE_NONE) return 0; /* the part's problem says why */
    s->group = case_element_group(doc, part, group, ptr);
    return s->group >= 0;
}

void case_read_region(case_doc *doc, case_part *part, const json_t *value, const char *ptr,
                      int mesh_sound)
{
    char at[CASE_POINTER];
    json_t *fracture = case_member(value, ptr, "fracture", at);
    if (!json_is_object(fracture) && !json_is_array(fracture)) return; /* case_parts.c */
    case_region *r = &part->region;
    r->listed = json_is_array(fracture);
    size_t n = r->listed ? json_array_size(fracture) : 1;
    if (r->listed && (n == 0 || n > CASE_MAX_REGION_SELECTORS)) {
        case_problem(doc, at, "a fracture region is a list of 1 to %d selectors, got %zu",
                     CASE_MAX_REGION_SELECTORS, n);
        return;
    }
    int good = 1;
    for (size_t k = 0; k < n; k++) {
        char sel[CASE_POINTER];
        selector_pointer(ptr, r->listed, (int)k, sel);
        const json_t *v = r->listed ? json_array_get(fracture, k) : fracture;
        good &= read_selector(doc, part, v, sel, &r->selector[k]);
    }
    if (!good) return;
    r->count = (int)n;
    /* a mesh read in pass 1 is checked now, with the other problems */
    if (mesh_sound && (part->shape == CASE_SHAPE_MESH || part->shape == CASE_SHAPE_GMSH)) {
        int i = (int)(part - doc->parts);
        uint8_t *mask = NULL;
        case_region_mask(doc, i, &mask);
        free(mask);
    }
}

void case_element_centroid(const case_doc *doc, const case_part *part, int t, double *c)
{
    const int dim = doc->dimension, K = dim + 1;
    const double *xyz = dim == 3 ? part->tet_mesh.xyz : part->mesh.xy;
    const int32_t *elem = dim == 3 ? part->tet_mesh.tet : part->mesh.tri;
    for (int d = 0; d < dim; d++) c[d] = 0;
    for (int k = 0; k < K; k++)
        for (int d = 0; d < dim; d++)
            c[d] += xyz[(size_t)dim * (size_t)elem[(size_t)K * (size_t)t + (size_t)k] + (size_t)d];
    for (int d = 0; d < dim; d++) c[d] /= K;
}

/* Sets the flags of the elements whose centroid lies in box; how many. The
 * span of all centroids goes to lo, hi for the message of an empty box. */
static int mark_box(const case_doc *doc, const case_part *part, const double *box, uint8_t *mask,
                    int count, double *lo, double *hi)
{
    const int dim = doc->dimension;
    int marked = 0;
    for (int t = 0; t < count; t++) {
        double c[3];
        case_element_centroid(doc, part, t, c);
        int inside = 1;
        for (int d = 0; d < dim; d++) {
            inside &= c[d] >= box[d] && c[d] <= box[dim + d];
            if (t == 0 || c[d] < lo[d]) lo[d] = c[d];
            if (t == 0 || c[d] > hi[d]) hi[d] = c[d];
        }
        if (inside) {
            mask[t] = 1;
            marked++;
        }
    }
    return marked;
}

static void empty_box_problem(case_doc *doc, const char *ptr, const double *lo, const double *hi)
{
    if (doc->dimension == 3)
        case_problem(doc, ptr, "the fracture region lies outside the part: its box holds no "
                               "element centroid (the part's centroids span [%g, %g, %g, %g, "
                               "%g, %g])", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    else
        case_problem(doc, ptr, "the fracture region lies outside the part: its box holds no "
                               "element centroid (the part's centroids span [%g, %g, %g, %g])",
                     lo[0], lo[1], hi[0], hi[1]);
}

int case_region_mask(case_doc *doc, int i, uint8_t **mask)
{
    const case_part *part = &doc->parts[i];
    *mask = NULL;
    if (part->region.count == 0) return 0;
    int count = doc->dimension == 3 ? part->tet_mesh.tet_count : part->mesh.triangle_count;
    char part_ptr[CASE_POINTER], ptr[CASE_POINTER];
    pointer_join_index(part_ptr, sizeof part_ptr, "/parts", i);
    *mask = calloc((size_t)(count > 0 ? count : 1), 1);
    if (!*mask) {
        selector_pointer(part_ptr, 0, 0, ptr);
        case_problem(doc, ptr, "out of memory");
        return -1;
    }
    int rc = 0;
    for (int k = 0; k < part->region.count; k++) {
        const case_region_selector *s = &part->region.selector[k];
        if (s->group >= 0) {
            const gmsh_group *g = &part->groups.group[s->group];
            for (int e = 0; e < g->element_count; e++)
                if (g->elements[e] >= 0 && g->elements[e] < count) (*mask)[g->elements[e]] = 1;
            continue;
        }
        double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
        if (mark_box(doc, part, s->box, *mask, count, lo, hi) > 0) continue;
        selector_pointer(part_ptr, part->region.listed, k, ptr);
        empty_box_problem(doc, ptr, lo, hi);
        rc = -1;
    }
    if (rc) {
        free(*mask);
        *mask = NULL;
    }
    return rc;
}
