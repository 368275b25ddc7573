/*
 * case_doc.c - what the passes of the case builder share about the case_doc
 * (case_internal.h) beyond reading JSON values (case_read.c): the problems
 * that name a document item from an engine index (an engine error mapped to
 * the pointer of the material, part or constraint it names; a dt above the
 * stable step), and freeing the document.
 *
 * Why here rather than in case.c: the sections (case_materials.c,
 * case_constraints.c, case_groups.c) and the dt probe (case_probe.c) call
 * these, and case.c calls them all; with these in case.c the case files
 * called each other in a circle around it. Now case.c is the top of the
 * case builder, which no other file calls back.
 */
#include <stdio.h>
#include <stdlib.h>

#include "case_internal.h"

void case_engine_problem(case_doc *doc, const fdem_error *err, const char *fallback)
{
    char ptr[CASE_POINTER];
    snprintf(ptr, sizeof ptr, "%s", fallback);
    if (err->kind == FDEM_ITEM_MATERIAL && err->item >= 0 && err->item < doc->material_count)
        pointer_join(ptr, sizeof ptr, "/materials", doc->materials[err->item].name);
    else if (err->kind == FDEM_ITEM_PART && err->item >= 0 && err->item < doc->part_count)
        pointer_join_index(ptr, sizeof ptr, "/parts", err->item);
    else if (err->kind == FDEM_ITEM_CONSTRAINT && err->item >= 0 &&
             err->item < doc->constraint_count)
        snprintf(ptr, sizeof ptr, "%s", doc->constraints[err->item].ptr);
    case_problem(doc, ptr, "%s", err->message[0] ? err->message : "the engine refused the case");
}

void case_dt_problem(case_doc *doc, double stable, double auto_dt, const char *whose)
{
    case_problem(doc, "/time/dt", "dt = %g s is above the stable time step of this model%s, "
                                  "%.4g s; use at most that, or \"auto\" (%.4g s with safety "
                                  "%g)", doc->dt, whose, stable, auto_dt, doc->safety);
}

void case_doc_free(case_doc *doc)
{
    for (int i = 0; i < doc->part_count; i++) {
        fdem_mesh_free(&doc->parts[i].mesh);
        fdem_tet_mesh_free(&doc->parts[i].tet_mesh);
        case_part_groups_free(&doc->parts[i]);
    }
    for (int i = 0; i < doc->constraint_count; i++) free(doc->constraints[i].vertices);
    free(doc->parts);
    free(doc->materials);
    for (int i = 0; i < doc->constraint_count; i++) free(doc->constraints[i].amplitude);
    free(doc->constraints);
    case_stages_free(doc);
    free(doc->gravity_amplitude);
    json_decref(doc->material_names);
    json_decref(doc->part_names);
}
