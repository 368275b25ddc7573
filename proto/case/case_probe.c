/*
 * case_probe.c - the time-step check of a document that has other problems,
 * so a user learns that dt is too large in the same answer that names a bad
 * material, part or constraint (validation reports every problem at once).
 *
 * A dt above the stable step is found only by building a model (pass 3),
 * which an invalid document never gets. The probe builds a scratch model of
 * the parts that read without a problem, without constraints: its stable
 * step is at least the whole model's (a minimum over fewer elements and
 * contacts), so a dt above it is certainly too large and the problem is never
 * a false one. Everything else the probe finds goes to a scratch list: those
 * would be guesses about a model that is not the user's. The probe passes
 * the same memory limit and gate as a real build.
 */
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"

int case_problem_under(const problems *p, int from, const char *base)
{
    size_t n = strlen(base);
    for (int i = from; i < p->count; i++) {
        const char *at = p->items[i].pointer;
        if (strncmp(at, base, n) == 0 && (at[n] == '\0' || at[n] == '/')) return 1;
    }
    return 0;
}

static int material_sound(const case_doc *doc, int k, int from)
{
    char ptr[CASE_POINTER];
    pointer_join(ptr, sizeof ptr, "/materials", doc->materials[k].name);
    return !case_problem_under(doc->out, from, ptr);
}

int case_part_sound(const case_doc *doc, int i, int from)
{
    const case_part *part = &doc->parts[i];
    char ptr[CASE_POINTER];
    pointer_join_index(ptr, sizeof ptr, "/parts", i);
    return part->shape != CASE_SHAPE_NONE && part->material >= 0 &&
           part->material < doc->material_count && !case_problem_under(doc->out, from, ptr) &&
           material_sound(doc, part->material, from);
}

/* The probe document: every material (an unsound one replaced by a sound
 * one, so indices hold; no probe part uses it) and the sound parts, whose
 * meshes move over from `doc`. 0 when nothing is left to probe. */
static int probe_doc_make(case_doc *doc, int from, case_doc *probe, problems *scratch)
{
    memset(probe, 0, sizeof *probe);
    probe->out = scratch;
    probe->dimension = doc->dimension;
    probe->safety = doc->safety;
    memcpy(probe->gravity, doc->gravity, sizeof probe->gravity);
    int stand_in = -1;
    for (int k = 0; k < doc->material_count && stand_in < 0; k++)
        if (material_sound(doc, k, from)) stand_in = k;
    if (stand_in < 0 || doc->part_count <= 0) return 0;
    probe->materials = calloc((size_t)doc->material_count, sizeof *probe->materials);
    probe->parts = calloc((size_t)doc->part_count, sizeof *probe->parts);
    if (!probe->materials || !probe->parts) return 0;
    probe->material_count = doc->material_count;
    for (int k = 0; k < doc->material_count; k++)
        probe->materials[k] = doc->materials[material_sound(doc, k, from) ? k : stand_in];
    for (int i = 0; i < doc->part_count; i++) {
        if (!case_part_sound(doc, i, from)) continue;
        probe->parts[probe->part_count++] = doc->parts[i];
        /* what the part owns moves over: both documents are freed */
        memset(&doc->parts[i].mesh, 0, sizeof doc->parts[i].mesh);
        memset(&doc->parts[i].tet_mesh, 0, sizeof doc->parts[i].tet_mesh);
        memset(&doc->parts[i].groups, 0, sizeof doc->parts[i].groups);
        doc->parts[i].element_material = NULL;
        doc->parts[i].joint_sets = NULL;
        doc->parts[i].joint_set_count = 0;
    }
    return probe->part_count > 0;
}

/* The scratch model's stable step, and in *auto_dt its "auto" step. */
static double probe_stable_dt(case_doc *probe, size_t memory_limit, case_memory_gate gate,
                              void *gate_ctx, double *auto_dt)
{
    double bytes = case_check_memory(probe, memory_limit);
    if (probe->out->count || (gate && gate(gate_ctx, bytes) != 0)) return 0;
    fdem_model *model = fdem_model_create();
    if (!model) return 0;
    fdem_error err = {0};
    double stable = 0;
    if (fdem_set_dimension(model, probe->dimension, &err) == 0 &&
        case_add_materials(probe, model) == 0 && case_add_parts(probe, model) == 0) {
        fdem_set_gravity_v(model, probe->gravity);
        if (fdem_model_finalize(model, &err) == 0) {
            stable = fdem_stable_dt(model);
            *auto_dt = fdem_auto_dt(model, probe->safety);
        }
    }
    fdem_model_destroy(model);
    return stable;
}

void case_probe_dt(case_doc *doc, int from, size_t memory_limit, case_memory_gate gate,
                   void *gate_ctx)
{
    problems *out = doc->out;
    if (doc->dt_auto || !(doc->dt > 0) || out->dropped || case_problem_under(out, from, "/time/dt") ||
        case_problem_under(out, from, "/dimension"))
        return;
    problems scratch;
    problems_init(&scratch);
    case_doc probe;
    if (probe_doc_make(doc, from, &probe, &scratch)) {
        double auto_dt = 0, stable = probe_stable_dt(&probe, memory_limit, gate, gate_ctx, &auto_dt);
        if (stable > 0 && doc->dt > stable) case_dt_problem(doc, stable, auto_dt, "'s valid parts");
    }
    case_doc_free(&probe);
    problems_free(&scratch);
}
