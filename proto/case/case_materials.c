/*
 * case_materials.c - the "materials" object of a case: read and range-check
 * every material (pass 1), then hand them to the engine in document order
 * (pass 3), so a material's engine index is its position in the object.
 *
 * The ranges are the ones the explicit solver can run: positive density and
 * stiffness, a Poisson ratio strictly inside (-1, 0.5) (0.5 would make the
 * bulk modulus, and so the stable step, degenerate), non-negative damping
 * and friction, and positive fracture strengths and energies.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"

static const char *const material_keys[] = {
    "density", "young", "poisson", "damping", "penalty", "friction", "fracture", NULL,
};
static const char *const fracture_keys[] = {
    "tensile_strength", "cohesion", "friction_angle", "energy_I", "energy_II", "variation",
    "aperture0", "pore_pressure", NULL,
};
static const char *const variation_keys[] = {"distribution", "modulus", "seed", NULL};

/* Adds a problem at base/key when `ok` is false. */
static void material_require(case_doc *doc, int ok, const char *base, const char *key,
                             const char *rule, double value)
{
    if (ok) return;
    char ptr[CASE_POINTER];
    pointer_join(ptr, sizeof ptr, base, key);
    case_problem(doc, ptr, "%s %s, got %g", key, rule, value);
}

static void material_read_poisson(case_doc *doc, const json_t *object, const char *base,
                                  double *poisson)
{
    if (!case_number_member(doc, object, base, "poisson", 1, poisson)) return;
    char ptr[CASE_POINTER];
    pointer_join(ptr, sizeof ptr, base, "poisson");
    if (*poisson == 0.5)
        case_problem(doc, ptr, "poisson must be below 0.5: an incompressible material "
                               "(0.5) is not supported by the explicit solver");
    else if (!(*poisson > -1 && *poisson < 0.5))
        case_problem(doc, ptr, "poisson must be in (-1, 0.5), got %g", *poisson);
}

/* "variation": {"distribution": "weibull", "modulus": m > 0, "seed": n}
 * (seed an integer in [0, 2^53], exact in JSON; 0 when absent). */
static void read_variation(case_doc *doc, const json_t *value, const char *ptr,
                           fdem_variation *v)
{
    if (!case_expect_object(doc, value, ptr)) return;
    case_check_keys(doc, value, ptr, variation_keys, "\"variation\"");
    char at[CASE_POINTER];
    json_t *distribution = case_member(value, ptr, "distribution", at);
    if (!distribution)
        case_problem(doc, ptr, "missing required \"distribution\": \"weibull\"");
    else if (!json_is_string(distribution) ||
             strcmp(json_string_value(distribution), "weibull") != 0)
        case_problem(doc, at, "the only distribution is \"weibull\", got %s%.32s%s",
                     json_is_string(distribution) ? "\"" : case_type_word(distribution),
                     json_is_string(distribution) ? json_string_value(distribution) : "",
                     json_is_string(distribution) ? "\"" : "");
    double modulus = 0;
    if (case_number_member(doc, value, ptr, "modulus", 1, &modulus)) {
        if (!(modulus >= 0.5 && modulus <= 1000))
            material_require(doc, 0, ptr, "modulus", "must be in [0.5, 1000] (the Weibull "
                             "modulus: larger is less scatter)", modulus);
        else
            v->weibull_modulus = modulus;
    }
    json_t *seed = case_member(value, ptr, "seed", at);
    long n = 0;
    if (seed && case_read_integer(doc, seed, at, 0, 9007199254740992L, &n))
        v->seed = (uint64_t)n;
}

void case_read_fracture(case_doc *doc, const json_t *value, const char *ptr, const char *what,
                        int required, fdem_fracture_params *f, fdem_variation *v)
{
    if (!case_expect_object(doc, value, ptr)) return;
    case_check_keys(doc, value, ptr, fracture_keys, what);
    char at[CASE_POINTER];
    json_t *variation = case_member(value, ptr, "variation", at);
    *v = (fdem_variation){0, 0};
    if (variation) read_variation(doc, variation, at, v);
    if (!required) { /* a joint set: what it leaves out is its material's */
        static const char *const keys[] = {"tensile_strength", "cohesion", "friction_angle",
                                           "energy_I", "energy_II", "aperture0",
                                           "pore_pressure"};
        int given = 0;
        for (int k = 0; k < 7; k++) given += json_object_get(value, keys[k]) != NULL;
        if (!given && !variation)
            case_problem(doc, ptr, "a joint set needs at least one fracture parameter "
                                   "(tensile_strength, cohesion, friction_angle, energy_I, "
                                   "energy_II, aperture0, pore_pressure or variation)");
    }
    if (case_number_member(doc, value, ptr, "tensile_strength", required, &f->tensile_strength))
        material_require(doc, f->tensile_strength > 0, ptr, "tensile_strength", "must be > 0",
                         f->tensile_strength);
    if (case_number_member(doc, value, ptr, "cohesion", required, &f->cohesion))
        material_require(doc, f->cohesion > 0, ptr, "cohesion", "must be > 0", f->cohesion);
    if (case_number_member(doc, value, ptr, "friction_angle", required, &f->friction_angle))
        material_require(doc, f->friction_angle >= 0 && f->friction_angle < 90, ptr,
                         "friction_angle", "must be in [0, 90) degrees", f->friction_angle);
    if (case_number_member(doc, value, ptr, "energy_I", required, &f->energy_I))
        material_require(doc, f->energy_I > 0, ptr, "energy_I", "must be > 0", f->energy_I);
    if (case_number_member(doc, value, ptr, "energy_II", required, &f->energy_II))
        material_require(doc, f->energy_II > 0, ptr, "energy_II", "must be > 0", f->energy_II);
    case_read_fracture_fluid(doc, value, ptr, f);
}

static void material_read(case_doc *doc, const char *name, const json_t *value,
                          const char *ptr, fdem_material_def *def)
{
    char what[96];
    snprintf(what, sizeof what, "material \"%.64s\"", name);
    if (!case_expect_object(doc, value, ptr)) return;
    case_check_keys(doc, value, ptr, material_keys, what);
    if (case_number_member(doc, value, ptr, "density", 1, &def->density))
        material_require(doc, def->density > 0, ptr, "density", "must be > 0", def->density);
    if (case_number_member(doc, value, ptr, "young", 1, &def->young)) {
        material_require(doc, def->young > 0, ptr, "young", "must be > 0", def->young);
        /* the default penalty is 10 x young and must stay finite */
        material_require(doc, isfinite(10 * def->young), ptr, "young", "is too large",
                         def->young);
    }
    /* each > 0, yet e.g. a subnormal density leaves no finite wave speed
     * and so no stable step: the material is at fault, not the case */
    double speed = def->young > 0 && def->density > 0 ? sqrt(def->young / def->density) : 1;
    if (!(speed > 0 && isfinite(speed)))
        case_problem(doc, ptr, "young / density (%g / %g) gives no finite wave speed, so no "
                               "stable time step", def->young, def->density);
    material_read_poisson(doc, value, ptr, &def->poisson);
    if (case_number_member(doc, value, ptr, "damping", 0, &def->damping))
        material_require(doc, def->damping >= 0, ptr, "damping", "must be >= 0", def->damping);
    def->penalty = 0; /* the engine's default, 10 x young */
    if (json_object_get(value, "penalty") &&
        case_number_member(doc, value, ptr, "penalty", 0, &def->penalty))
        material_require(doc, def->penalty > 0, ptr, "penalty", "must be > 0", def->penalty);
    if (case_number_member(doc, value, ptr, "friction", 0, &def->friction))
        material_require(doc, def->friction >= 0, ptr, "friction", "must be >= 0",
                         def->friction);
    char fracture_ptr[CASE_POINTER];
    json_t *fracture = case_member(value, ptr, "fracture", fracture_ptr);
    if (fracture) {
        char fracture_what[128];
        snprintf(fracture_what, sizeof fracture_what, "the fracture block of %s", what);
        def->has_fracture = 1;
        case_read_fracture(doc, fracture, fracture_ptr, fracture_what, 1, &def->fracture,
                           &def->variation);
    }
}

void case_read_materials(case_doc *doc, const json_t *materials)
{
    if (!case_expect_object(doc, materials, "/materials")) return;
    size_t count = json_object_size(materials);
    if (count == 0) {
        case_problem(doc, "/materials", "a case needs at least one material");
        return;
    }
    doc->materials = calloc(count, sizeof *doc->materials);
    if (!doc->materials) {
        case_problem(doc, "/materials", "out of memory");
        return;
    }
    const char *name;
    json_t *value;
    json_object_foreach((json_t *)materials, name, value) {
        case_material *m = &doc->materials[doc->material_count++];
        char ptr[CASE_POINTER];
        pointer_join(ptr, sizeof ptr, "/materials", name);
        m->name = name;
        case_check_name_text(doc, name, ptr, "the material name");
        case_names_add(doc, &doc->material_names, name, doc->material_count - 1);
        material_read(doc, name, value, ptr, &m->def);
    }
}

int case_material_index(const case_doc *doc, const char *name)
{
    return case_names_find(doc->material_names, name);
}

int case_add_materials(case_doc *doc, fdem_model *model)
{
    for (int i = 0; i < doc->material_count; i++) {
        fdem_error err = {0};
        if (fdem_add_material(model, &doc->materials[i].def, &err) != i) {
            char ptr[CASE_POINTER];
            pointer_join(ptr, sizeof ptr, "/materials", doc->materials[i].name);
            case_engine_problem(doc, &err, ptr);
            return -1;
        }
    }
    return 0;
}
