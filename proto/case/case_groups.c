/*
 * case_groups.c - what a case says by gmsh physical group (contract 5.3):
 * a part's "materials" (one bonded body, a material per group of
 * elements), its "discontinuities" (joint sets on groups of lines, 3D
 * surfaces), the {"part", "group"} node selector of constraints and the
 * group behind the element selector of a stage's "excavate" (6.1).
 *
 * The groups come from the gmsh reader (gmsh_groups.c) with the part's
 * mesh in pass 1, so every name is checked there and reported at its
 * pointer with the names the mesh does have; the engine sees only element
 * materials, face lists and vertex lists, never a name.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_internal.h"

static const char *const dimension_words[] = {"point", "curve", "surface", "volume"};

static int part_mesh_dimension(const case_doc *doc) { return doc->dimension; }

/* The index of the group `name` of dimension dim (-1 for any), or -1. */
static int group_find(const gmsh_groups *groups, const char *name, int dim)
{
    for (int g = 0; g < groups->count; g++)
        if ((dim < 0 || groups->group[g].dim == dim) && strcmp(groups->group[g].name, name) == 0)
            return g;
    return -1;
}

/* "; the mesh's surface groups are \"a\", \"b\"" (or that it has none). */
static void group_names(const gmsh_groups *groups, int dim, char *out, size_t size)
{
    size_t n = (size_t)snprintf(out, size, "; the %s groups of this part's mesh are",
                                dim >= 0 ? dimension_words[dim] : "physical");
    int listed = 0;
    for (int g = 0; g < groups->count && n < size; g++) {
        if (dim >= 0 && groups->group[g].dim != dim) continue;
        n += (size_t)snprintf(out + n, size - n, "%s \"%.32s\"", listed++ ? "," : "",
                              groups->group[g].name);
    }
    if (!listed) snprintf(out, size, "; this part's mesh has no named %s group",
                          dim >= 0 ? dimension_words[dim] : "physical");
}

/* The group named at `ptr` of dimension dim, or -1 after a problem. */
static int group_lookup(case_doc *doc, const case_part *part, const char *name, int dim,
                        const char *ptr)
{
    int g = group_find(&part->groups, name, dim);
    if (g >= 0) return g;
    char list[400];
    group_names(&part->groups, dim, list, sizeof list);
    int other = group_find(&part->groups, name, -1);
    if (other >= 0)
        case_problem(doc, ptr, "\"%.64s\" is a %s group; this needs a %s group%s", name,
                     dimension_words[part->groups.group[other].dim], dimension_words[dim], list);
    else
        case_problem(doc, ptr, "no physical group \"%.64s\" in this part's gmsh mesh%s", name,
                     list);
    return -1;
}

int case_element_group(case_doc *doc, const case_part *part, const json_t *name,
                       const char *ptr)
{
    if (!json_is_string(name)) {
        case_problem(doc, ptr, "expected the name of a physical group, got %s",
                     case_type_word(name));
        return -1;
    }
    if (part->shape != CASE_SHAPE_GMSH) {
        case_problem(doc, ptr, "part \"%.64s\" is not a \"gmsh\" mesh, so it has no physical "
                               "groups", part->name);
        return -1;
    }
    int g = group_lookup(doc, part, json_string_value(name), part_mesh_dimension(doc), ptr);
    if (g >= 0 && part->groups.group[g].element_count == 0) {
        case_problem(doc, ptr, "the group \"%.64s\" has no element of the mesh",
                     json_string_value(name));
        return -1;
    }
    return g;
}

/* ------------------------------------------------------------ materials */

static void read_group_material(case_doc *doc, case_part *part, int count, const char *name,
                                const json_t *value, const char *ptr)
{
    int g = group_lookup(doc, part, name, part_mesh_dimension(doc), ptr);
    if (!json_is_string(value)) {
        case_problem(doc, ptr, "expected the name of a material, got %s", case_type_word(value));
        return;
    }
    int mat = case_material_index(doc, json_string_value(value));
    if (mat < 0) {
        case_problem(doc, ptr, "unknown material \"%.64s\"", json_string_value(value));
        return;
    }
    /* in a fracture region only its elements need one: the engine knows them */
    if (part->fracture && !part->fracture_region && !doc->materials[mat].def.has_fracture)
        case_problem(doc, ptr, "the part fractures, so material \"%.64s\" needs a "
                               "\"fracture\" block", json_string_value(value));
    if (g < 0 || !part->element_material) return;
    const gmsh_group *group = &part->groups.group[g];
    if (group->element_count == 0) { /* the material would silently apply to nothing */
        case_problem(doc, ptr, "the group \"%.64s\" has no element of the mesh", name);
        return;
    }
    for (int k = 0; k < group->element_count; k++)
        if (group->elements[k] < count) part->element_material[group->elements[k]] = mat;
}

static void read_materials(case_doc *doc, case_part *part, const json_t *materials,
                           const char *ptr)
{
    if (!case_expect_object(doc, materials, ptr)) return;
    int count = doc->dimension == 3 ? part->tet_mesh.tet_count : part->mesh.triangle_count;
    part->element_material = malloc(sizeof(int32_t) * (size_t)(count ? count : 1));
    if (!part->element_material) {
        case_problem(doc, ptr, "out of memory");
        return;
    }
    for (int t = 0; t < count; t++) part->element_material[t] = part->material;
    const char *name;
    json_t *value;
    json_object_foreach((json_t *)materials, name, value) {
        char at[CASE_POINTER];
        pointer_join(at, sizeof at, ptr, name);
        read_group_material(doc, part, count, name, value, at);
    }
}

/* ------------------------------------------------------ discontinuities */

static void read_discontinuities(case_doc *doc, case_part *part, const json_t *sets,
                                 const char *ptr)
{
    if (!case_expect_object(doc, sets, ptr)) return;
    if (!part->fracture) {
        case_problem(doc, ptr, "\"discontinuities\" are joint sets of a fracturing part; set "
                               "\"fracture\": true");
        return;
    }
    size_t n = json_object_size(sets);
    part->joint_sets = calloc(n ? n : 1, sizeof *part->joint_sets);
    if (!part->joint_sets) {
        case_problem(doc, ptr, "out of memory");
        return;
    }
    const fdem_material_def *mat = part->material >= 0 ? &doc->materials[part->material].def : NULL;
    const char *name;
    json_t *value;
    json_object_foreach((json_t *)sets, name, value) {
        char at[CASE_POINTER], what[160];
        pointer_join(at, sizeof at, ptr, name);
        snprintf(what, sizeof what, "the joint set \"%.64s\"", name);
        case_joint_set *set = &part->joint_sets[part->joint_set_count];
        set->group = group_lookup(doc, part, name, part_mesh_dimension(doc) - 1, at);
        if (mat) set->params = mat->fracture;
        case_read_fracture(doc, value, at, what, 0, &set->params, &set->variation);
        if (set->group >= 0 && part->groups.group[set->group].face_count == 0) {
            case_problem(doc, at, "the group \"%.64s\" has no %s of the mesh", name,
                         doc->dimension == 3 ? "3-node triangles" : "2-node lines");
            continue;
        }
        if (set->group >= 0) part->joint_set_count++;
    }
}

void case_read_part_groups(case_doc *doc, case_part *part, const json_t *value,
                           const char *ptr)
{
    static const char *const keys[] = {"materials", "discontinuities"};
    json_t *given[2];
    char at[2][CASE_POINTER];
    for (int k = 0; k < 2; k++) {
        given[k] = case_member(value, ptr, keys[k], at[k]);
        if (given[k] && part->shape != CASE_SHAPE_GMSH) {
            case_problem(doc, at[k], "\"%s\" names physical groups of a \"gmsh\" mesh; this "
                                     "part has none", keys[k]);
            given[k] = NULL;
        }
    }
    /* a gmsh text that did not read has no groups to check against */
    int readable = doc->dimension == 3 ? part->tet_mesh.tet != NULL : part->mesh.tri != NULL;
    if (!readable) return;
    if (given[0]) read_materials(doc, part, given[0], at[0]);
    if (given[1]) read_discontinuities(doc, part, given[1], at[1]);
}

/* ------------------------------------------------------------- selector */

int case_group_vertices(case_doc *doc, int part_index, const json_t *group, const char *ptr,
                        int32_t **vertices, int *count)
{
    *vertices = NULL;
    *count = 0;
    if (!json_is_string(group)) {
        case_problem(doc, ptr, "expected the name of a physical group, got %s",
                     case_type_word(group));
        return -1;
    }
    if (part_index < 0 || part_index >= doc->part_count) return -1; /* reported at "part" */
    const case_part *part = &doc->parts[part_index];
    const char *name = json_string_value(group);
    if (part->shape != CASE_SHAPE_GMSH) {
        case_problem(doc, ptr, "part \"%.64s\" is not a \"gmsh\" mesh, so it has no physical "
                               "groups", part->name);
        return -1;
    }
    int total = 0;
    for (int g = 0; g < part->groups.count; g++)
        if (strcmp(part->groups.group[g].name, name) == 0) total += part->groups.group[g].node_count;
    if (total == 0) {
        if (group_find(&part->groups, name, -1) >= 0)
            case_problem(doc, ptr, "the group \"%.64s\" has no node of the mesh", name);
        else
            group_lookup(doc, part, name, -1, ptr);
        return -1;
    }
    *vertices = malloc(sizeof(int32_t) * (size_t)total);
    if (!*vertices) {
        case_problem(doc, ptr, "out of memory");
        return -1;
    }
    for (int g = 0; g < part->groups.count; g++) /* a name in several dimensions: all */
        if (strcmp(part->groups.group[g].name, name) == 0) {
            memcpy(*vertices + *count, part->groups.group[g].nodes,
                   sizeof(int32_t) * (size_t)part->groups.group[g].node_count);
            *count += part->groups.group[g].node_count;
        }
    return 0;
}

int case_group_with_elements(case_doc *doc, int part_index, const json_t *group,
                             const char *ptr)
{
    if (part_index < 0 || part_index >= doc->part_count) return -1; /* reported at "part" */
    return case_element_group(doc, &doc->parts[part_index], group, ptr);
}

/* --------------------------------------------------------------- pass 3 */

int case_add_part_groups(case_doc *doc, fdem_model *model, int i, int index)
{
    case_part *part = &doc->parts[i];
    char base[CASE_POINTER], ptr[CASE_POINTER];
    pointer_join_index(base, sizeof base, "/parts", i);
    fdem_error err = {0};
    if (part->element_material && fdem_set_element_materials(model, index, part->element_material, &err)) {
        pointer_join(ptr, sizeof ptr, base, "materials");
        case_engine_problem(doc, &err, ptr);
        return -1;
    }
    for (int k = 0; k < part->joint_set_count; k++) {
        const case_joint_set *set = &part->joint_sets[k];
        const gmsh_group *group = &part->groups.group[set->group];
        if (fdem_add_joint_set(model, index, &set->params, &set->variation, group->faces,
                               group->face_count, &err) < 0) {
            char sets[CASE_POINTER];
            pointer_join(sets, sizeof sets, base, "discontinuities");
            pointer_join(ptr, sizeof ptr, sets, group->name);
            case_problem(doc, ptr, "%s", err.message);
            return -1;
        }
    }
    return 0;
}

void case_part_groups_free(case_part *part)
{
    gmsh_groups_free(&part->groups);
    free(part->element_material);
    free(part->joint_sets);
    part->element_material = NULL;
    part->joint_sets = NULL;
}
