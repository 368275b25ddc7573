/*
 * case_fluid.c - fluid in the fractures in a case (contract 6.4): the
 * top-level "fluid" {"viscosity", "bulk_modulus", "density"}, the
 * hydraulic parameters of a joint's fracture parameters ("aperture0",
 * "pore_pressure" {"value", "gradient", "reference"}), and the checks that
 * span sections: a pore pressure or an injection without "fluid", a pore
 * pressure on the material of a part that does not fracture (it has no
 * joint to wet). The "inject" action is read with the other constraints
 * (case_constraints.c); an injection whose nodes touch no joint is found
 * by the engine at finalize and reported at the constraint.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "case_internal.h"

static const char *const fluid_keys[] = {"viscosity", "bulk_modulus", "density", NULL};
static const char *const pore_keys[] = {"value", "gradient", "reference", NULL};

/* A problem at base/key saying key's rule, when ok is false. */
static void fluid_require(case_doc *doc, int ok, const char *base, const char *key,
                          const char *rule, double value)
{
    if (ok) return;
    char ptr[CASE_POINTER];
    pointer_join(ptr, sizeof ptr, base, key);
    case_problem(doc, ptr, "%s %s, got %g", key, rule, value);
}

void case_read_fluid(case_doc *doc, const json_t *fluid)
{
    if (!fluid) return;
    const char *ptr = "/fluid";
    doc->has_fluid = 1;
    if (!case_expect_object(doc, fluid, ptr)) return;
    case_check_keys(doc, fluid, ptr, fluid_keys, "\"fluid\"");
    fdem_fluid_def *f = &doc->fluid;
    if (case_number_member(doc, fluid, ptr, "viscosity", 1, &f->viscosity))
        fluid_require(doc, f->viscosity > 0, ptr, "viscosity", "must be > 0 (Pa s; water: 1e-3)",
                      f->viscosity);
    if (case_number_member(doc, fluid, ptr, "bulk_modulus", 1, &f->bulk_modulus))
        fluid_require(doc, f->bulk_modulus > 0, ptr, "bulk_modulus",
                      "must be > 0 (Pa; water: 2.2e9)", f->bulk_modulus);
    if (case_number_member(doc, fluid, ptr, "density", 1, &f->density))
        fluid_require(doc, f->density >= 0, ptr, "density", "must be >= 0 (kg/m^3; water: 1000)",
                      f->density);
}

/* "aperture0" and "pore_pressure" of fracture parameters at ptr. */
void case_read_fracture_fluid(case_doc *doc, const json_t *value, const char *ptr,
                              fdem_fracture_params *f)
{
    char at[CASE_POINTER];
    if (json_object_get(value, "aperture0") &&
        case_number_member(doc, value, ptr, "aperture0", 0, &f->aperture0))
        fluid_require(doc, f->aperture0 > 0, ptr, "aperture0", "must be > 0 (m)", f->aperture0);
    json_t *pore = case_member(value, ptr, "pore_pressure", at);
    if (!pore) return;
    if (!doc->has_fluid)
        case_problem(doc, at, "a pore pressure needs the top-level \"fluid\": give "
                              "{\"viscosity\", \"bulk_modulus\", \"density\"}");
    if (!case_expect_object(doc, pore, at)) return;
    case_check_keys(doc, pore, at, pore_keys, "\"pore_pressure\"");
    double v[3] = {0, 0, 0};
    int ok = case_number_member(doc, pore, at, "value", 1, &v[0]);
    ok &= case_number_member(doc, pore, at, "gradient", 0, &v[1]);
    ok &= case_number_member(doc, pore, at, "reference", 0, &v[2]);
    if (!ok) return;
    f->has_pore_pressure = 1;
    memcpy(f->pore_pressure, v, sizeof v);
}

/* After the parts: a pore pressure on a material that a part without
 * fracture uses would wet nothing there. */
void case_check_fluid(case_doc *doc)
{
    for (int i = 0; i < doc->part_count; i++) {
        const case_part *p = &doc->parts[i];
        if (p->fracture || p->material < 0 || p->material >= doc->material_count) continue;
        const case_material *mat = &doc->materials[p->material];
        if (!mat->def.has_fracture || !mat->def.fracture.has_pore_pressure) continue;
        char at[CASE_POINTER], ptr[CASE_POINTER];
        pointer_join(at, sizeof at, "/materials", mat->name);
        pointer_join(ptr, sizeof ptr, at, "fracture");
        pointer_join(at, sizeof at, ptr, "pore_pressure");
        case_problem(doc, at, "material \"%.64s\" has a pore pressure, but part \"%.64s\" of it "
                              "does not fracture: a pore pressure wets joints, and only a part "
                              "with \"fracture\" has them", mat->name, p->name);
    }
}
