/*
 * case_shapes.c - the generated shapes of a part in both dimensions: read
 * in pass 1 (only described, nothing allocated), meshed in pass 3 once the
 * memory estimate has let the case through.
 *
 * A rectangle is the 2D box and a disc the 2D sphere: each pair is read by
 * one function over the case's dimension, so both dimensions check the
 * same things with the same messages. The cylinder has no 2D twin.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "case_internal.h"

/* Divisions beyond this are refused outright; anything below it is left to
 * the memory estimate, which says how large the model would be. */
#define SHAPE_DIVISIONS_MAX 1000000000000L

static const char *const block_keys[] = {"origin", "size", "divisions", NULL};
static const char *const round_keys[] = {"center", "radius", "divisions", NULL};
static const char *const cylinder_keys[] = {
    "center", "axis", "radius", "length", "divisions", NULL,
};

/* "[1, 2, 3]" */
static void shape_format_vector(char *out, size_t size, const double *v, int count)
{
    size_t n = (size_t)snprintf(out, size, "[");
    for (int k = 0; k < count && n < size; k++)
        n += (size_t)snprintf(out + n, size - n, "%s%g", k ? ", " : "", v[k]);
    if (n < size) snprintf(out + n, size - n, "]");
}

/* 1 when every |at[k]| + reach[k] is a finite number. */
static int shape_within_range(const double *at, const double *reach, int count)
{
    double sum = 0;
    for (int k = 0; k < count; k++) sum += fabs(at[k]) + fabs(reach[k]);
    return isfinite(sum);
}

/* The optional origin or centre: `dimension` numbers, default 0. */
static void shape_read_point(case_doc *doc, case_part *part, const json_t *shape,
                             const char *ptr, const char *key)
{
    char at[CASE_POINTER];
    json_t *point = case_member(shape, ptr, key, at);
    if (point) case_read_axes(doc, point, at, part->at);
}

/* --------------------------------------------------- rectangle and box */

void case_read_block(case_doc *doc, case_part *part, const json_t *block, const char *ptr)
{
    int dim = doc->dimension;
    const char *size_layout = dim == 2 ? "[width, height]" : "[sx, sy, sz]";
    const char *divisions_layout = dim == 2 ? "[nx, ny]" : "[nx, ny, nz]";
    if (!case_expect_object(doc, block, ptr)) return;
    case_check_keys(doc, block, ptr, block_keys, dim == 2 ? "a rectangle" : "a box");
    shape_read_point(doc, part, block, ptr, "origin");
    char at[CASE_POINTER], text[128];
    json_t *size = case_member(block, ptr, "size", at);
    if (!size) {
        case_problem(doc, ptr, "missing required \"size\" %s", size_layout);
    } else if (case_read_axes(doc, size, at, part->size)) {
        int positive = 1;
        for (int k = 0; k < dim; k++) positive &= part->size[k] > 0;
        shape_format_vector(text, sizeof text, part->size, dim);
        if (!positive)
            case_problem(doc, at, "every size %s must be > 0, got %s", size_layout, text);
        else if (!shape_within_range(part->at, part->size, dim))
            case_problem(doc, at, "the %s reaches beyond the range of numbers",
                         dim == 2 ? "rectangle" : "box");
    }
    json_t *divisions = case_member(block, ptr, "divisions", at);
    static const long at_least_one[3] = {1, 1, 1};
    if (!divisions)
        case_problem(doc, ptr, "missing required \"divisions\" %s", divisions_layout);
    else
        case_read_integers(doc, divisions, at, dim, at_least_one, SHAPE_DIVISIONS_MAX,
                           divisions_layout, part->divisions);
}

/* ----------------------------------------------------- disc and sphere */

void case_read_round(case_doc *doc, case_part *part, const json_t *round, const char *ptr)
{
    int dim = doc->dimension;
    const char *name = dim == 2 ? "disc" : "sphere";
    long min_divisions = dim == 2 ? 6 : 8;
    if (!case_expect_object(doc, round, ptr)) return;
    case_check_keys(doc, round, ptr, round_keys, dim == 2 ? "a disc" : "a sphere");
    shape_read_point(doc, part, round, ptr, "center");
    char at[CASE_POINTER];
    if (case_number_member(doc, round, ptr, "radius", 1, &part->radius)) {
        pointer_join(at, sizeof at, ptr, "radius");
        double reach[3] = {2 * part->radius, 0, 0};
        if (!(part->radius > 0))
            case_problem(doc, at, "radius must be > 0, got %g", part->radius);
        else if (!shape_within_range(part->at, reach, dim))
            case_problem(doc, at, "the %s reaches beyond the range of numbers", name);
    }
    json_t *divisions = case_member(round, ptr, "divisions", at);
    if (!divisions)
        case_problem(doc, ptr, "missing required \"divisions\" (%s, at least %ld)",
                     dim == 2 ? "nodes on the rim" : "element edges around a great circle",
                     min_divisions);
    else
        case_read_integer(doc, divisions, at, min_divisions, SHAPE_DIVISIONS_MAX,
                          &part->divisions[0]);
}

/* ------------------------------------------------------------ cylinder */

static void cylinder_read_axis(case_doc *doc, case_part *part, const json_t *cylinder,
                               const char *ptr)
{
    static const char *const axes[] = {"x", "y", "z"};
    char at[CASE_POINTER];
    json_t *axis = case_member(cylinder, ptr, "axis", at);
    if (!axis) {
        case_problem(doc, ptr, "missing required \"axis\" (\"x\", \"y\" or \"z\")");
        return;
    }
    const char *s = json_is_string(axis) ? json_string_value(axis) : "";
    for (int a = 0; a < 3; a++)
        if (strcmp(s, axes[a]) == 0) {
            part->axis = a;
            return;
        }
    if (json_is_string(axis))
        case_problem(doc, at, "expected \"x\", \"y\" or \"z\", got \"%.32s\"", s);
    else
        case_problem(doc, at, "expected \"x\", \"y\" or \"z\", got %s", case_type_word(axis));
}

/* A required number member that must be > 0; its pointer names a problem. */
static void shape_read_positive(case_doc *doc, const json_t *shape, const char *ptr,
                                const char *key, double *out)
{
    if (!case_number_member(doc, shape, ptr, key, 1, out)) return;
    char at[CASE_POINTER];
    pointer_join(at, sizeof at, ptr, key);
    if (!(*out > 0)) case_problem(doc, at, "%s must be > 0, got %g", key, *out);
}

void case_read_cylinder(case_doc *doc, case_part *part, const json_t *cylinder,
                        const char *ptr)
{
    if (!case_expect_object(doc, cylinder, ptr)) return;
    case_check_keys(doc, cylinder, ptr, cylinder_keys, "a cylinder");
    shape_read_point(doc, part, cylinder, ptr, "center");
    cylinder_read_axis(doc, part, cylinder, ptr);
    shape_read_positive(doc, cylinder, ptr, "radius", &part->radius);
    shape_read_positive(doc, cylinder, ptr, "length", &part->length);
    double reach[3] = {2 * part->radius, part->length, 0};
    if (part->radius > 0 && part->length > 0 && !shape_within_range(part->at, reach, 3))
        case_problem(doc, ptr, "the cylinder reaches beyond the range of numbers");
    char at[CASE_POINTER];
    json_t *divisions = case_member(cylinder, ptr, "divisions", at);
    static const long lowest[2] = {8, 1};
    if (!divisions)
        case_problem(doc, ptr, "missing required \"divisions\" [around the rim (at least 8), "
                               "along the axis]");
    else
        case_read_integers(doc, divisions, at, 2, lowest, SHAPE_DIVISIONS_MAX,
                           "[around the rim, along the axis]", part->divisions);
}

/* -------------------------------------------------------------- pass 3 */

/* The memory check has bounded every count by INT_MAX, so the divisions
 * fit an int here. A shape meshed already (for its boxes: case_boxes.c)
 * is left as it is. */
int case_generate_shape(case_part *part, fdem_error *err)
{
    if (part->mesh.tri || part->tet_mesh.tet) return 0;
    int d[3] = {(int)part->divisions[0], (int)part->divisions[1], (int)part->divisions[2]};
    switch (part->shape) {
    case CASE_SHAPE_RECTANGLE:
        return fdem_mesh_rectangle(part->at[0], part->at[1], part->size[0], part->size[1], d[0],
                                   d[1], &part->mesh, err);
    case CASE_SHAPE_DISC:
        return fdem_mesh_disc(part->at[0], part->at[1], part->radius, d[0], &part->mesh, err);
    case CASE_SHAPE_BOX:
        return fdem_tet_mesh_box(part->at, part->size, d, &part->tet_mesh, err);
    case CASE_SHAPE_SPHERE:
        return fdem_tet_mesh_sphere(part->at, part->radius, d[0], &part->tet_mesh, err);
    case CASE_SHAPE_CYLINDER:
        return fdem_tet_mesh_cylinder(part->at, part->axis, part->radius, part->length, d,
                                      &part->tet_mesh, err);
    case CASE_SHAPE_MESH:
    case CASE_SHAPE_GMSH:
    case CASE_SHAPE_NONE:
        break;
    }
    return 0;
}
