/*
 * case_parts.c - the "parts" array of a case: each part's name, material,
 * fracture flag (or region: case_region.c), initial velocity and its one shape (pass 1), and turning
 * the shapes into engine parts (pass 3).
 *
 * Which shapes a part may have depends on the case's dimension: rectangle
 * and disc in 2D, box, sphere and cylinder in 3D, mesh and gmsh in both
 * (triangles in 2D, tetrahedra in 3D). A shape of the other dimension is a
 * problem at the shape, saying which dimension it belongs to. The shapes
 * themselves are read by case_shapes.c (generated) and case_mesh.c (given).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"

const char *const case_shape_keys[CASE_SHAPE_KINDS] = {
    "rectangle", "disc", "mesh", "gmsh", "box", "sphere", "cylinder",
};

static const char *const part_keys[] = {
    "name", "material", "fracture", "velocity", "initial_stress", "rectangle", "disc", "mesh",
    "gmsh", "box", "sphere", "cylinder", "materials", "discontinuities", NULL,
};

/* The dimension a shape belongs to, 0 for both. */
static int shape_dimension(case_shape shape)
{
    switch (shape) {
    case CASE_SHAPE_RECTANGLE:
    case CASE_SHAPE_DISC: return 2;
    case CASE_SHAPE_BOX:
    case CASE_SHAPE_SPHERE:
    case CASE_SHAPE_CYLINDER: return 3;
    default: return 0;
    }
}

static const char *shapes_of_dimension(int dimension)
{
    return dimension == 3 ? "box, sphere, cylinder, mesh or gmsh"
                          : "rectangle, disc, mesh or gmsh";
}

/* 1 when the shape belongs to the case's dimension, else a problem at it. */
static int shape_fits_dimension(case_doc *doc, case_shape shape, const char *ptr)
{
    int only = shape_dimension(shape);
    if (only == 0 || only == doc->dimension) return 1;
    const char *name = case_shape_keys[shape - 1];
    if (only == 3)
        case_problem(doc, ptr, "\"%s\" is a 3D shape and this case is 2D; set \"dimension\": "
                               "3 at the top of the case, or use a %s", name,
                     shapes_of_dimension(2));
    else
        case_problem(doc, ptr, "\"%s\" is a 2D shape and this case has \"dimension\": 3; use "
                               "a %s", name, shapes_of_dimension(3));
    return 0;
}

/* Exactly one of the shape keys; the pointer of the part names the problem. */
static void part_read_shape(case_doc *doc, case_part *part, const json_t *value,
                            const char *ptr)
{
    int found = 0;
    char list[128] = "";
    for (int s = 0; s < CASE_SHAPE_KINDS; s++) {
        if (!json_object_get(value, case_shape_keys[s])) continue;
        if (found++ == 0) part->shape = (case_shape)(CASE_SHAPE_RECTANGLE + s);
        size_t n = strlen(list);
        snprintf(list + n, sizeof list - n, "%s%s", n ? " and " : "", case_shape_keys[s]);
    }
    if (found == 0) {
        case_problem(doc, ptr, "a part needs a shape: one of %s",
                     shapes_of_dimension(doc->dimension));
        return;
    }
    if (found > 1) {
        part->shape = CASE_SHAPE_NONE;
        case_problem(doc, ptr, "a part has exactly one shape, this one has %s", list);
        return;
    }
    char at[CASE_POINTER];
    const json_t *shape = case_member(value, ptr, case_shape_keys[part->shape - 1], at);
    if (!shape_fits_dimension(doc, part->shape, at)) {
        part->shape = CASE_SHAPE_NONE;
        return;
    }
    switch (part->shape) {
    case CASE_SHAPE_RECTANGLE:
    case CASE_SHAPE_BOX: case_read_block(doc, part, shape, at); break;
    case CASE_SHAPE_DISC:
    case CASE_SHAPE_SPHERE: case_read_round(doc, part, shape, at); break;
    case CASE_SHAPE_CYLINDER: case_read_cylinder(doc, part, shape, at); break;
    case CASE_SHAPE_MESH: case_read_mesh(doc, part, shape, at); break;
    case CASE_SHAPE_GMSH: case_read_gmsh(doc, part, shape, at); break;
    case CASE_SHAPE_NONE: break;
    }
}

/* ------------------------------------------------------ the other fields */

static void part_read_name(case_doc *doc, case_part *part, int index, const json_t *value,
                           const char *ptr)
{
    char at[CASE_POINTER];
    json_t *name = case_member(value, ptr, "name", at);
    snprintf(part->name, sizeof part->name, "part%d", index);
    if (!name) return;
    if (!json_is_string(name)) {
        case_problem(doc, at, "expected a string, got %s", case_type_word(name));
    } else if (json_string_length(name) == 0 || json_string_length(name) >= CASE_NAME ||
               strlen(json_string_value(name)) != json_string_length(name)) {
        case_problem(doc, at, "a part name must be 1 to %d bytes long", CASE_NAME - 1);
    } else if (case_check_name_text(doc, json_string_value(name), at, "the part name")) {
        snprintf(part->name, sizeof part->name, "%s", json_string_value(name));
    }
}

static void part_read_material(case_doc *doc, case_part *part, const json_t *value,
                               const char *ptr)
{
    char at[CASE_POINTER];
    json_t *material = case_member(value, ptr, "material", at);
    part->material = -1;
    if (!material) {
        case_problem(doc, ptr, "missing required \"material\"");
        return;
    }
    if (!json_is_string(material)) {
        case_problem(doc, at, "expected the name of a material, got %s",
                     case_type_word(material));
        return;
    }
    const char *name = json_string_value(material);
    part->material = case_material_index(doc, name);
    if (part->material >= 0) return;
    const char **names = malloc((size_t)(doc->material_count + 1) * sizeof *names);
    char hint[160] = "";
    if (names) {
        for (int i = 0; i < doc->material_count; i++) names[i] = doc->materials[i].name;
        case_did_you_mean(doc, hint, sizeof hint, name, names, doc->material_count);
        free(names);
    }
    /* no close name: list the ones there are (a material named in the part
     * but never defined, or defined under another name); at most three, of
     * at most 24 characters, so the hint always fits */
    if (!hint[0] && doc->material_count > 0) {
        size_t used = (size_t)snprintf(hint, sizeof hint, "; the case's materials are ");
        for (int i = 0; i < doc->material_count && i < 3; i++)
            used += (size_t)snprintf(hint + used, sizeof hint - used, "%s\"%.24s\"",
                                     i ? ", " : "", doc->materials[i].name);
        if (doc->material_count > 3) snprintf(hint + used, sizeof hint - used, ", ...");
    }
    case_problem(doc, at, "unknown material \"%.64s\"%s", name, hint);
}

static void part_read_flags(case_doc *doc, case_part *part, const json_t *value,
                            const char *ptr)
{
    char at[CASE_POINTER];
    json_t *fracture = case_member(value, ptr, "fracture", at);
    /* a selector or a list of them: a fracture region (case_region.c) */
    int region = json_is_object(fracture) || json_is_array(fracture);
    if (region) part->fracture = part->fracture_region = 1;
    else if (fracture && !json_is_boolean(fracture))
        case_problem(doc, at, "expected true or false, or a fracture region: a selector "
                              "({\"box\": [...]} or {\"group\": \"name\"}) or a list of them, "
                              "got %s",
                     case_type_word(fracture));
    else if (fracture) part->fracture = json_is_true(fracture);
    if (part->fracture && part->material >= 0 && !doc->materials[part->material].def.has_fracture)
        case_problem(doc, at, "%s needs a \"fracture\" block in material \"%.64s\"",
                     region ? "a fracture region" : "\"fracture\": true",
                     doc->materials[part->material].name);
    json_t *velocity = case_member(value, ptr, "velocity", at);
    if (velocity)
        part->has_velocity = case_read_axes(doc, velocity, at, part->velocity);
    json_t *stress = case_member(value, ptr, "initial_stress", at);
    if (stress) case_read_initial_stress(doc, part, stress, at);
}

static void part_read(case_doc *doc, case_part *part, int index, const json_t *value)
{
    char ptr[CASE_POINTER];
    pointer_join_index(ptr, sizeof ptr, "/parts", index);
    if (!case_expect_object(doc, value, ptr)) return;
    char what[32];
    snprintf(what, sizeof what, "part %d", index);
    case_check_keys(doc, value, ptr, part_keys, what);
    part_read_name(doc, part, index, value, ptr);
    part_read_material(doc, part, value, ptr);
    part_read_flags(doc, part, value, ptr);
    int before = doc->out->count + doc->out->dropped;
    part_read_shape(doc, part, value, ptr);
    int mesh_sound = doc->out->count + doc->out->dropped == before;
    case_read_part_groups(doc, part, value, ptr);
    case_read_region(doc, part, value, ptr, mesh_sound);
}

/* Names must be unique because constraints select parts by name. */
static void part_check_names(case_doc *doc)
{
    for (int i = 0; i < doc->part_count; i++) {
        int first = case_names_add(doc, &doc->part_names, doc->parts[i].name, i);
        if (first < 0) continue;
        char ptr[CASE_POINTER];
        pointer_join_index(ptr, sizeof ptr, "/parts", i);
        case_problem(doc, ptr, "the part name \"%s\" is already used by /parts/%d",
                     doc->parts[i].name, first);
    }
}

void case_read_parts(case_doc *doc, const json_t *parts)
{
    if (!case_expect_array(doc, parts, "/parts")) return;
    size_t count = json_array_size(parts);
    if (count == 0 || count > CASE_MAX_PARTS) {
        case_problem(doc, "/parts", "a case needs 1 to %d parts, got %zu", CASE_MAX_PARTS,
                     count);
        return;
    }
    doc->parts = calloc(count, sizeof *doc->parts);
    if (!doc->parts) {
        case_problem(doc, "/parts", "out of memory");
        return;
    }
    doc->part_count = (int)count;
    for (int i = 0; i < doc->part_count; i++) {
        doc->parts[i].material = -1;
        part_read(doc, &doc->parts[i], i, json_array_get(parts, (size_t)i));
    }
    part_check_names(doc);
}

/* --------------------------------------------------------------- pass 3 */

void case_part_mesh_pointer(const case_doc *doc, int part, char *ptr)
{
    char base[CASE_POINTER];
    pointer_join_index(base, sizeof base, "/parts", part);
    case_shape shape = doc->parts[part].shape;
    if (shape == CASE_SHAPE_NONE)
        snprintf(ptr, CASE_POINTER, "%s", base);
    else
        pointer_join(ptr, CASE_POINTER, base, case_shape_keys[shape - 1]);
}

/* The part as an engine part; a fracture region goes as a flag per element
 * (in_region, NULL for none). */
static int part_add_mesh(const case_doc *doc, fdem_model *model, case_part *part,
                         const uint8_t *in_region, fdem_error *err)
{
    if (doc->dimension == 3)
        return in_region ? fdem_add_part_region_3d(model, &part->tet_mesh, part->material,
                                                   in_region, err)
                         : fdem_add_part_3d(model, &part->tet_mesh, part->material,
                                            part->fracture, err);
    return in_region ? fdem_add_part_region(model, &part->mesh, part->material, in_region, err)
                     : fdem_add_part(model, &part->mesh, part->material, part->fracture, err);
}

/* Lowest and highest node of the part (y in 2D, z in 3D): where its
 * initial stress field takes its extreme values. */
static void part_height_range(const case_doc *doc, const case_part *part, double height[2])
{
    const int dim = doc->dimension == 3 ? 3 : 2;
    const double *xyz = dim == 3 ? part->tet_mesh.xyz : part->mesh.xy;
    int count = dim == 3 ? part->tet_mesh.node_count : part->mesh.node_count;
    height[0] = height[1] = 0;
    for (int n = 0; xyz && n < count; n++) {
        double h = xyz[(size_t)dim * (size_t)n + (size_t)(dim - 1)];
        if (n == 0 || h < height[0]) height[0] = h;
        if (n == 0 || h > height[1]) height[1] = h;
    }
}

/* Generated shapes are meshed here, after the memory check. */
static int part_add(case_doc *doc, fdem_model *model, int i)
{
    case_part *part = &doc->parts[i];
    char part_ptr[CASE_POINTER], ptr[CASE_POINTER];
    fdem_error err = {0};
    pointer_join_index(part_ptr, sizeof part_ptr, "/parts", i);
    case_part_mesh_pointer(doc, i, ptr);
    if (case_generate_shape(part, &err) < 0) {
        case_problem(doc, ptr, "%s", err.message);
        return -1;
    }
    uint8_t *in_region = NULL;
    if (case_region_mask(doc, i, &in_region) < 0) {
        fdem_mesh_free(&part->mesh);
        fdem_tet_mesh_free(&part->tet_mesh);
        return -1;
    }
    int index = part_add_mesh(doc, model, part, in_region, &err);
    free(in_region);
    double height[2];
    part_height_range(doc, part, height);
    fdem_mesh_free(&part->mesh); /* the engine keeps its own copy */
    fdem_tet_mesh_free(&part->tet_mesh);
    if (index < 0) {
        case_mesh_problem(doc, i, &err, part_ptr);
        return -1;
    }
    /* `index` is i unless an earlier part was refused (case_add_parts) */
    if (case_add_part_groups(doc, model, i, index) < 0) return -1;
    if (part->has_velocity && fdem_set_part_velocity_v(model, index, part->velocity, &err) < 0) {
        pointer_join(ptr, sizeof ptr, part_ptr, "velocity");
        case_problem(doc, ptr, "%s", err.message);
        return -1;
    }
    return case_add_initial_stress(doc, model, i, index, height);
}

/* Every part is meshed and checked even after one is refused, so that one
 * answer names each bad mesh; such a model is never finalized. */
int case_add_parts(case_doc *doc, fdem_model *model)
{
    int rc = 0;
    for (int i = 0; i < doc->part_count; i++)
        if (part_add(doc, model, i) < 0) rc = -1;
    return rc;
}
