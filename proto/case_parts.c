/*
 * case_parts.c - the "parts" array of a case: each part's name, material,
 * fracture flag, initial velocity and its one shape (pass 1), and turning
 * the shapes into engine parts (pass 3).
 *
 * Explicit meshes and gmsh text are parsed in pass 1 because their size is
 * bounded by the upload and their errors (a bad triangle, a gmsh line) are
 * part of the full list of problems. Generated shapes are only described in
 * pass 1; pass 2 (case_memory.c) estimates their size before any of them is
 * generated, so `"divisions": [1e9, 1e9]` is refused without allocating.
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"
#include "gmsh.h"

static const char *const part_keys[] = {
    "name", "material", "fracture", "velocity", "rectangle", "disc", "mesh", "gmsh", NULL,
};
static const char *const shape_keys[] = {"rectangle", "disc", "mesh", "gmsh"};
static const char *const rectangle_keys[] = {"origin", "size", "divisions", NULL};
static const char *const disc_keys[] = {"center", "radius", "divisions", NULL};
static const char *const mesh_keys[] = {"nodes", "triangles", NULL};

/* Divisions beyond this are refused outright; anything below it is left to
 * the memory estimate, which says how large the model would be. */
#define PART_DIVISIONS_MAX 1000000000000L

/* ---------------------------------------------------------------- shapes */

static void part_read_rectangle(case_doc *doc, case_part *part, const json_t *rect,
                                const char *ptr)
{
    if (!case_expect_object(doc, rect, ptr)) return;
    case_check_keys(doc, rect, ptr, rectangle_keys, "a rectangle");
    char at[CASE_POINTER];
    json_t *origin = case_member(rect, ptr, "origin", at);
    if (origin) case_read_vec2(doc, origin, at, part->at);
    json_t *size = case_member(rect, ptr, "size", at);
    if (!size)
        case_problem(doc, ptr, "missing required \"size\" [width, height]");
    else if (case_read_vec2(doc, size, at, part->size)) {
        if (!(part->size[0] > 0 && part->size[1] > 0))
            case_problem(doc, at, "width and height must be > 0, got [%g, %g]", part->size[0],
                         part->size[1]);
        else if (!isfinite(part->at[0] + part->size[0]) || !isfinite(part->at[1] + part->size[1]))
            case_problem(doc, at, "the rectangle reaches beyond the range of numbers");
    }
    json_t *divisions = case_member(rect, ptr, "divisions", at);
    if (!divisions) {
        case_problem(doc, ptr, "missing required \"divisions\" [nx, ny]");
    } else if (!json_is_array(divisions) || json_array_size(divisions) != 2) {
        case_problem(doc, at, "expected an array of two whole numbers [nx, ny], got %s",
                     case_type_word(divisions));
    } else {
        for (int k = 0; k < 2; k++) {
            char item[CASE_POINTER];
            pointer_join_index(item, sizeof item, at, k);
            case_read_integer(doc, json_array_get(divisions, (size_t)k), item, 1,
                              PART_DIVISIONS_MAX, &part->divisions[k]);
        }
    }
}

static void part_read_disc(case_doc *doc, case_part *part, const json_t *disc,
                           const char *ptr)
{
    if (!case_expect_object(doc, disc, ptr)) return;
    case_check_keys(doc, disc, ptr, disc_keys, "a disc");
    char at[CASE_POINTER];
    json_t *center = case_member(disc, ptr, "center", at);
    if (center) case_read_vec2(doc, center, at, part->at);
    if (case_number_member(doc, disc, ptr, "radius", 1, &part->radius)) {
        pointer_join(at, sizeof at, ptr, "radius");
        if (!(part->radius > 0))
            case_problem(doc, at, "radius must be > 0, got %g", part->radius);
        else if (!isfinite(fabs(part->at[0]) + fabs(part->at[1]) + 2 * part->radius))
            case_problem(doc, at, "the disc reaches beyond the range of numbers");
    }
    json_t *divisions = case_member(disc, ptr, "divisions", at);
    if (!divisions)
        case_problem(doc, ptr, "missing required \"divisions\" (nodes on the rim, at least 6)");
    else
        case_read_integer(doc, divisions, at, 6, PART_DIVISIONS_MAX, &part->divisions[0]);
}

/* Explicit nodes [[x, y], ...]; each bad node is reported. */
static int part_read_nodes(case_doc *doc, fdem_mesh *mesh, const json_t *nodes,
                           const char *ptr)
{
    if (!case_expect_array(doc, nodes, ptr)) return 0;
    size_t count = json_array_size(nodes);
    if (count < 3 || count > INT_MAX / 2) {
        case_problem(doc, ptr, "a mesh needs at least 3 nodes, got %zu", count);
        return 0;
    }
    mesh->xy = malloc(2 * count * sizeof *mesh->xy);
    if (!mesh->xy) {
        case_problem(doc, ptr, "out of memory");
        return 0;
    }
    mesh->node_count = (int)count;
    int ok = 1;
    for (size_t i = 0; i < count; i++) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, (long)i);
        ok &= case_read_vec2(doc, json_array_get(nodes, i), at, &mesh->xy[2 * i]);
    }
    return ok;
}

/* Triangles [[i, j, k], ...] with 0-based indices into the nodes. */
static int part_read_triangles(case_doc *doc, fdem_mesh *mesh, const json_t *triangles,
                               const char *ptr, int node_count)
{
    if (!case_expect_array(doc, triangles, ptr)) return 0;
    size_t count = json_array_size(triangles);
    if (count < 1 || count > INT_MAX / 3) {
        case_problem(doc, ptr, "a mesh needs at least one triangle");
        return 0;
    }
    mesh->tri = malloc(3 * count * sizeof *mesh->tri);
    if (!mesh->tri) {
        case_problem(doc, ptr, "out of memory");
        return 0;
    }
    mesh->triangle_count = (int)count;
    int ok = 1;
    for (size_t t = 0; t < count; t++) {
        char at[CASE_POINTER];
        pointer_join_index(at, sizeof at, ptr, (long)t);
        json_t *tri = json_array_get(triangles, t);
        if (!json_is_array(tri) || json_array_size(tri) != 3) {
            case_problem(doc, at, "expected three node indices [i, j, k], got %s%s",
                         case_type_word(tri), json_is_array(tri) ? " of another length" : "");
            ok = 0;
            continue;
        }
        for (int k = 0; k < 3; k++) {
            char item[CASE_POINTER];
            long index = 0;
            pointer_join_index(item, sizeof item, at, k);
            json_t *v = json_array_get(tri, (size_t)k);
            if (!case_read_integer(doc, v, item, 0, LONG_MAX, &index)) {
                ok = 0;
            } else if (node_count > 0 && index >= node_count) {
                case_problem(doc, at, "node index %ld is out of range: the mesh has %d nodes "
                                      "(indices 0 to %d)", index, node_count, node_count - 1);
                ok = 0;
            } else {
                mesh->tri[3 * t + (size_t)k] = (int32_t)index;
            }
        }
    }
    return ok;
}

/* Runs the engine's mesh check (finite nodes, zero areas, unused nodes;
 * reorients clockwise triangles) and maps the item it names to a pointer. */
static void part_validate_mesh(case_doc *doc, case_part *part, const char *ptr)
{
    int reoriented = 0;
    fdem_error err = {0};
    if (fdem_mesh_validate(&part->mesh, &reoriented, &err) == 0) return;
    char at[CASE_POINTER];
    const char *list = err.kind == FDEM_ITEM_NODE ? "nodes" : "triangles";
    if (part->shape == CASE_SHAPE_GMSH) {
        case_problem(doc, ptr, "in the gmsh mesh: %s", err.message);
    } else if ((err.kind == FDEM_ITEM_TRIANGLE || err.kind == FDEM_ITEM_NODE) && err.item >= 0) {
        char list_ptr[CASE_POINTER];
        pointer_join(list_ptr, sizeof list_ptr, ptr, list);
        pointer_join_index(at, sizeof at, list_ptr, err.item);
        case_problem(doc, at, "%s", err.message);
    } else {
        case_problem(doc, ptr, "%s", err.message);
    }
}

static void part_read_mesh(case_doc *doc, case_part *part, const json_t *mesh,
                           const char *ptr)
{
    if (!case_expect_object(doc, mesh, ptr)) return;
    case_check_keys(doc, mesh, ptr, mesh_keys, "a mesh");
    char nodes_ptr[CASE_POINTER], tri_ptr[CASE_POINTER];
    json_t *nodes = case_member(mesh, ptr, "nodes", nodes_ptr);
    json_t *triangles = case_member(mesh, ptr, "triangles", tri_ptr);
    if (!nodes) case_problem(doc, ptr, "missing required \"nodes\" [[x, y], ...]");
    if (!triangles) case_problem(doc, ptr, "missing required \"triangles\" [[i, j, k], ...]");
    if (!nodes || !triangles) return;
    int ok = part_read_nodes(doc, &part->mesh, nodes, nodes_ptr);
    ok &= part_read_triangles(doc, &part->mesh, triangles, tri_ptr, part->mesh.node_count);
    if (ok) part_validate_mesh(doc, part, ptr);
}

static void part_read_gmsh(case_doc *doc, case_part *part, const json_t *text,
                           const char *ptr)
{
    if (!json_is_string(text)) {
        case_problem(doc, ptr, "expected the text of a .msh file, got %s", case_type_word(text));
        return;
    }
    char message[400];
    if (gmsh_read(json_string_value(text), json_string_length(text), &part->mesh, message,
                  sizeof message) < 0) {
        case_problem(doc, ptr, "%s", message);
        return;
    }
    part_validate_mesh(doc, part, ptr);
}

/* Exactly one of the shape keys; the pointer of the part names the problem. */
static void part_read_shape(case_doc *doc, case_part *part, const json_t *value,
                            const char *ptr)
{
    int found = 0;
    char list[64] = "";
    for (int s = 0; s < 4; s++) {
        if (!json_object_get(value, shape_keys[s])) continue;
        if (found++ == 0) part->shape = (case_shape)(CASE_SHAPE_RECTANGLE + s);
        size_t n = strlen(list);
        snprintf(list + n, sizeof list - n, "%s%s", n ? " and " : "", shape_keys[s]);
    }
    if (found == 0) {
        case_problem(doc, ptr, "a part needs a shape: one of rectangle, disc, mesh or gmsh");
        return;
    }
    if (found > 1) {
        part->shape = CASE_SHAPE_NONE;
        case_problem(doc, ptr, "a part has exactly one shape, this one has %s", list);
        return;
    }
    char at[CASE_POINTER];
    const json_t *shape = case_member(value, ptr, shape_keys[part->shape - 1], at);
    switch (part->shape) {
    case CASE_SHAPE_RECTANGLE: part_read_rectangle(doc, part, shape, at); break;
    case CASE_SHAPE_DISC: part_read_disc(doc, part, shape, at); break;
    case CASE_SHAPE_MESH: part_read_mesh(doc, part, shape, at); break;
    case CASE_SHAPE_GMSH: part_read_gmsh(doc, part, shape, at); break;
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
    } else {
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
    char hint[96] = "";
    if (names) {
        for (int i = 0; i < doc->material_count; i++) names[i] = doc->materials[i].name;
        case_did_you_mean(doc, hint, sizeof hint, name, names, doc->material_count);
        free(names);
    }
    case_problem(doc, at, "unknown material \"%.64s\"%s", name, hint);
}

static void part_read_flags(case_doc *doc, case_part *part, const json_t *value,
                            const char *ptr)
{
    char at[CASE_POINTER];
    json_t *fracture = case_member(value, ptr, "fracture", at);
    if (fracture && case_read_bool(doc, fracture, at, &part->fracture) && part->fracture &&
        part->material >= 0 && !doc->materials[part->material].def.has_fracture)
        case_problem(doc, at, "\"fracture\": true needs a \"fracture\" block in material "
                              "\"%.64s\"", doc->materials[part->material].name);
    json_t *velocity = case_member(value, ptr, "velocity", at);
    if (velocity) part->has_velocity = case_read_vec2(doc, velocity, at, part->velocity);
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
    part_read_shape(doc, part, value, ptr);
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
        pointer_join(ptr, CASE_POINTER, base, shape_keys[shape - 1]);
}

/* Generated shapes are meshed here, after the memory check. */
static int part_generate(case_part *part, fdem_error *err)
{
    if (part->shape == CASE_SHAPE_RECTANGLE)
        return fdem_mesh_rectangle(part->at[0], part->at[1], part->size[0], part->size[1],
                                   (int)part->divisions[0], (int)part->divisions[1],
                                   &part->mesh, err);
    if (part->shape == CASE_SHAPE_DISC)
        return fdem_mesh_disc(part->at[0], part->at[1], part->radius,
                              (int)part->divisions[0], &part->mesh, err);
    return 0;
}

static int part_add(case_doc *doc, fdem_model *model, int i)
{
    case_part *part = &doc->parts[i];
    char ptr[CASE_POINTER];
    fdem_error err = {0};
    case_part_mesh_pointer(doc, i, ptr);
    if (part_generate(part, &err) < 0) {
        case_problem(doc, ptr, "%s", err.message);
        return -1;
    }
    int index = fdem_add_part(model, &part->mesh, part->material, part->fracture, &err);
    if (part->shape == CASE_SHAPE_RECTANGLE || part->shape == CASE_SHAPE_DISC)
        fdem_mesh_free(&part->mesh); /* the engine keeps its own copy */
    if (index != i) {
        if (part->shape == CASE_SHAPE_MESH &&
            (err.kind == FDEM_ITEM_TRIANGLE || err.kind == FDEM_ITEM_NODE) && err.item >= 0) {
            char list[CASE_POINTER], at[CASE_POINTER];
            pointer_join(list, sizeof list, ptr,
                         err.kind == FDEM_ITEM_NODE ? "nodes" : "triangles");
            pointer_join_index(at, sizeof at, list, err.item);
            case_problem(doc, at, "%s", err.message);
        } else {
            pointer_join_index(ptr, sizeof ptr, "/parts", i);
            case_problem(doc, ptr, "%s", err.message);
        }
        return -1;
    }
    if (part->has_velocity &&
        fdem_set_part_velocity(model, i, part->velocity[0], part->velocity[1], &err) < 0) {
        pointer_join_index(ptr, sizeof ptr, "/parts", i);
        pointer_join(ptr, sizeof ptr, ptr, "velocity");
        case_problem(doc, ptr, "%s", err.message);
        return -1;
    }
    return 0;
}

int case_add_parts(case_doc *doc, fdem_model *model)
{
    for (int i = 0; i < doc->part_count; i++)
        if (part_add(doc, model, i) < 0) return -1;
    return 0;
}
