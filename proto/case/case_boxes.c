/*
 * case_boxes.c - the box selectors that select nothing, found before the
 * model is built, so that they are named in the same answer as the other
 * problems of the document (contract: one 422 with every problem).
 *
 * Which elements a box holds (by centroid: a fracture region's box,
 * case_region.c, or an excavation's, case_stages.c) is known only once the
 * parts are meshed. Explicit and gmsh meshes are read in pass 1, and their
 * region boxes are checked there; a generated shape is meshed only after
 * the memory estimate. This check runs after pass 1 whatever it found:
 * it meshes the generated shapes that some box needs, when their part
 * read without a problem and the meshes fit the memory limit (a valid
 * document's meshes then go on to pass 3, which does not mesh them again),
 * and checks each region box against its part and each excavation box
 * against every part. An excavation box is checked only when every part
 * read without a problem: an element of a part that did not read might
 * lie in it, and a problem here is never a guess.
 */
#include <stdlib.h>

#include "case_internal.h"

static int part_meshed(const case_doc *doc, const case_part *part)
{
    return doc->dimension == 3 ? part->tet_mesh.tet != NULL : part->mesh.tri != NULL;
}

static int part_element_count(const case_doc *doc, const case_part *part)
{
    return doc->dimension == 3 ? part->tet_mesh.tet_count : part->mesh.triangle_count;
}

static int stages_have_boxes(const case_doc *doc)
{
    for (int k = 0; k < doc->stage_count; k++)
        for (int j = 0; j < doc->stages[k].excavate_count; j++)
            if (doc->stages[k].excavate[j].kind == CASE_PICK_BOX) return 1;
    return 0;
}

static int region_has_box(const case_part *part)
{
    for (int k = 0; k < part->region.count; k++)
        if (part->region.selector[k].group < 0) return 1;
    return 0;
}

/* Part i's mesh, if the part read without a problem: its generated shape
 * is meshed if it is not yet, spending from *budget (bytes); 1 when the
 * part has a sound mesh now. */
static int part_mesh_for_boxes(case_doc *doc, int i, int from, double *budget)
{
    case_part *part = &doc->parts[i];
    if (!case_part_sound(doc, i, from)) return 0;
    if (part_meshed(doc, part)) return 1;
    double bytes = case_part_bytes(doc, part);
    if (bytes > *budget) return 0;
    fdem_error err = {0};
    if (case_generate_shape(part, &err) < 0) return 0; /* pass 3 says why */
    *budget -= bytes;
    return part_meshed(doc, part);
}

/* Some element centroid of the parts' meshes lies in `box` (bounds included). */
static int box_holds_an_element(const case_doc *doc, const double *box)
{
    const int dim = doc->dimension;
    for (int i = 0; i < doc->part_count; i++) {
        const case_part *part = &doc->parts[i];
        for (int t = 0; t < part_element_count(doc, part); t++) {
            double c[3];
            case_element_centroid(doc, part, t, c);
            int inside = 1;
            for (int d = 0; d < dim; d++) inside &= c[d] >= box[d] && c[d] <= box[dim + d];
            if (inside) return 1;
        }
    }
    return 0;
}

static void check_excavation_boxes(case_doc *doc)
{
    for (int k = 0; k < doc->stage_count; k++)
        for (int j = 0; j < doc->stages[k].excavate_count; j++) {
            const case_element_selector *sel = &doc->stages[k].excavate[j];
            if (sel->kind != CASE_PICK_BOX || box_holds_an_element(doc, sel->box)) continue;
            char at[CASE_POINTER];
            pointer_join_index(at, sizeof at, "/stages", k);
            pointer_join(at, sizeof at, at, "excavate");
            pointer_join_index(at, sizeof at, at, j);
            case_problem(doc, at, "the selector selects no element: no element's centroid lies "
                                  "in the box");
        }
}

void case_check_boxes(case_doc *doc, int from, size_t memory_limit)
{
    if (case_problem_under(doc->out, from, "/dimension")) return; /* shapes read in 2D */
    double budget = (double)memory_limit;
    int excavation_boxes = stages_have_boxes(doc), all_meshed = doc->part_count > 0;
    for (int i = 0; i < doc->part_count; i++) {
        case_part *part = &doc->parts[i];
        int generated = part->shape != CASE_SHAPE_MESH && part->shape != CASE_SHAPE_GMSH;
        int region = generated && region_has_box(part); /* a read mesh was checked in pass 1 */
        if (!region && !excavation_boxes) continue;
        int meshed = part_mesh_for_boxes(doc, i, from, &budget);
        all_meshed &= meshed;
        if (region && meshed) {
            uint8_t *mask = NULL;
            case_region_mask(doc, i, &mask);
            free(mask);
        }
    }
    if (excavation_boxes && all_meshed) check_excavation_boxes(doc);
}
