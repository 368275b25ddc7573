/*
 * case_history.c - the top-level "history" block (contract 6.2): its
 * interval and monitoring points, read in pass 1 and located in the built
 * model in pass 3.
 *
 * A point is followed through the node nearest it at t = 0 (the engine has
 * no interpolation at arbitrary points, and a node is what a strain gauge
 * or a displacement transducer is glued to). A point that lies in no
 * element at t = 0 is almost surely a typo (a coordinate in mm, a swapped
 * axis): its nearest node could be metres away, so it is refused at its
 * pointer rather than silently snapped. The lookups are linear in the
 * model's size, done once at build time, never while stepping.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "case_internal.h"

static const char *const history_keys[] = {"interval", "points", NULL};
static const char *const point_keys[] = {"name", "at", NULL};

static void history_read_point(case_doc *doc, const json_t *point, const char *ptr)
{
    if (!case_expect_object(doc, point, ptr)) return;
    case_check_keys(doc, point, ptr, point_keys, "a history point");
    char at_ptr[CASE_POINTER], name_ptr[CASE_POINTER];
    json_t *name = case_member(point, ptr, "name", name_ptr);
    json_t *at = case_member(point, ptr, "at", at_ptr);
    int k = doc->history_point_count;
    case_history_point *p = &doc->history_points[k];
    memset(p, 0, sizeof *p);
    snprintf(p->ptr, sizeof p->ptr, "%s", ptr);
    int ok = 1;
    if (!name) {
        case_problem(doc, ptr, "missing required \"name\"");
        ok = 0;
    } else if (!json_is_string(name)) {
        case_problem(doc, name_ptr, "expected a string, got %s", case_type_word(name));
        ok = 0;
    } else if (json_string_length(name) == 0 || json_string_length(name) >= CASE_HISTORY_NAME ||
               strlen(json_string_value(name)) != json_string_length(name)) {
        case_problem(doc, name_ptr, "a point's name is 1 to %d bytes, without NUL characters",
                     CASE_HISTORY_NAME - 1);
        ok = 0;
    } else if (!case_check_name_text(doc, json_string_value(name), name_ptr, "the name")) {
        ok = 0;
    } else {
        for (int j = 0; j < k; j++)
            if (strcmp(doc->history_points[j].name, json_string_value(name)) == 0) {
                case_problem(doc, name_ptr, "the name \"%s\" is already the name of %s",
                             json_string_value(name), doc->history_points[j].ptr);
                ok = 0;
            }
        if (ok) snprintf(p->name, sizeof p->name, "%s", json_string_value(name));
    }
    if (!at) {
        case_problem(doc, ptr, "missing required \"at\" [x, y%s]",
                     doc->dimension == 3 ? ", z" : "");
        ok = 0;
    } else if (!case_read_axes(doc, at, at_ptr, p->at)) {
        ok = 0;
    }
    p->node = -1;
    p->sound = ok;
    doc->history_point_count++;
}

void case_read_history(case_doc *doc, const json_t *history)
{
    doc->history_given = 1;
    if (!case_expect_object(doc, history, "/history")) return;
    case_check_keys(doc, history, "/history", history_keys, "\"history\"");
    if (!json_object_get(history, "interval"))
        case_problem(doc, "/history", "missing required \"interval\" (seconds)");
    else if (case_number_member(doc, history, "/history", "interval", 1,
                                &doc->history_interval) &&
             !(doc->history_interval > 0))
        case_problem(doc, "/history/interval", "interval must be > 0, got %g",
                     doc->history_interval);
    json_t *points = json_object_get(history, "points");
    if (!points || !case_expect_array(doc, points, "/history/points")) return;
    if (json_array_size(points) > CASE_MAX_HISTORY_POINTS) {
        case_problem(doc, "/history/points", "a case may have at most %d history points, got %zu",
                     CASE_MAX_HISTORY_POINTS, json_array_size(points));
        return;
    }
    size_t i;
    json_t *point;
    json_array_foreach(points, i, point) {
        char ptr[CASE_POINTER];
        pointer_join_index(ptr, sizeof ptr, "/history/points", (long)i);
        history_read_point(doc, point, ptr);
    }
}

/* Checked after time.end is known: more rows than snapshots may have is a typo. */
void case_check_history_rows(case_doc *doc)
{
    if (!doc->history_given || !(doc->history_interval > 0) || !(doc->end_time > 0)) return;
    if (doc->end_time / doc->history_interval > CASE_MAX_HISTORY_ROWS)
        case_problem(doc, "/history/interval",
                     "an interval of %g s over %g s would record %.3g rows; the limit is %.0f",
                     doc->history_interval, doc->end_time,
                     doc->end_time / doc->history_interval, CASE_MAX_HISTORY_ROWS);
}

/* Signed measure (twice the area, six times the volume) of the simplex
 * x[0..dim] of `dim` + 1 points. */
static double simplex_measure(int dim, const double *x[4])
{
    double a[3][3];
    for (int r = 0; r < dim; r++)
        for (int c = 0; c < dim; c++) a[r][c] = x[r + 1][c] - x[0][c];
    if (dim == 2) return a[0][0] * a[1][1] - a[0][1] * a[1][0];
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

/* Whether p lies in element e at t = 0 (its faces included, with a margin of
 * a millionth of the element's measure so a point on a shared face or on
 * the boundary counts). */
static int element_contains(const fdem_model *model, int e, const double *p)
{
    int dim = fdem_get_dimension(model), k = dim + 1;
    const int32_t *nodes = fdem_element_nodes(model) + (size_t)k * e;
    const double *x0 = fdem_initial_positions(model);
    const double *x[4];
    for (int i = 0; i < k; i++) x[i] = x0 + (size_t)dim * nodes[i];
    double whole = simplex_measure(dim, x);
    if (whole == 0) return 0;
    for (int i = 0; i < k; i++) {
        const double *keep = x[i];
        x[i] = p;
        double part = simplex_measure(dim, x) / whole;
        x[i] = keep;
        if (part < -1e-6) return 0;
    }
    return 1;
}

static int nearest_node(const fdem_model *model, const double *p)
{
    int dim = fdem_get_dimension(model), best = -1;
    int n = fdem_get_counts(model).nodes;
    const double *x0 = fdem_initial_positions(model);
    double best_d2 = INFINITY;
    for (int i = 0; i < n; i++) {
        double d2 = 0;
        for (int d = 0; d < dim; d++) {
            double r = x0[(size_t)dim * i + d] - p[d];
            d2 += r * r;
        }
        if (d2 < best_d2) {
            best_d2 = d2;
            best = i;
        }
    }
    return best;
}

int case_locate_history(case_doc *doc, const fdem_model *model)
{
    int ok = 1, elements = fdem_get_counts(model).elements;
    for (int k = 0; k < doc->history_point_count; k++) {
        case_history_point *p = &doc->history_points[k];
        if (!p->sound) continue;
        int inside = 0;
        for (int e = 0; e < elements && !inside; e++) inside = element_contains(model, e, p->at);
        if (!inside) {
            char at[CASE_POINTER], where[96];
            pointer_join(at, sizeof at, p->ptr, "at");
            if (doc->dimension == 3)
                snprintf(where, sizeof where, "(%.6g, %.6g, %.6g)", p->at[0], p->at[1], p->at[2]);
            else
                snprintf(where, sizeof where, "(%.6g, %.6g)", p->at[0], p->at[1]);
            case_problem(doc, at, "the history point \"%s\" at %s lies outside every body at "
                                  "t = 0", p->name, where);
            ok = 0;
            continue;
        }
        p->node = nearest_node(model, p->at);
    }
    return ok;
}

void case_fill_history_info(const case_doc *doc, case_info *info)
{
    info->history_interval = doc->history_given ? doc->history_interval : 0;
    info->history_point_count = doc->history_point_count;
    for (int k = 0; k < doc->history_point_count; k++) {
        snprintf(info->history_names[k], sizeof info->history_names[k], "%s",
                 doc->history_points[k].name);
        info->history_nodes[k] = doc->history_points[k].node;
    }
}
