/*
 * test_mesh.c - generators and input validation: node and triangle counts,
 * total area against the exact shape, triangle quality of the disc (no
 * slivers), and one error per kind of broken input naming the triangle.
 */
#include "check.h"
#include "fdem.h"

static double mesh_area(const fdem_mesh *m, double *min_angle_deg)
{
    double area = 0, min_angle = 180;
    for (int k = 0; k < m->triangle_count; k++) {
        const int32_t *t = m->tri + 3 * k;
        double x[3], y[3];
        for (int c = 0; c < 3; c++) { x[c] = m->xy[2 * t[c]]; y[c] = m->xy[2 * t[c] + 1]; }
        double a2 = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
        area += 0.5 * a2;
        for (int c = 0; c < 3; c++) {
            int i = (c + 1) % 3, j = (c + 2) % 3;
            double ux = x[i] - x[c], uy = y[i] - y[c], vx = x[j] - x[c], vy = y[j] - y[c];
            double ang = acos((ux * vx + uy * vy) / (hypot(ux, uy) * hypot(vx, vy))) * 180 / M_PI;
            if (ang < min_angle) min_angle = ang;
        }
    }
    if (min_angle_deg) *min_angle_deg = min_angle;
    return area;
}

static void rectangle_counts_and_area(void)
{
    fdem_mesh m;
    fdem_error err;
    CHECK(fdem_mesh_rectangle(-1, 2, 3, 0.5, 6, 2, &m, &err) == 0, "%s", err.message);
    CHECK(m.node_count == 7 * 3, "nodes %d", m.node_count);
    CHECK(m.triangle_count == 2 * 6 * 2, "triangles %d", m.triangle_count);
    double min_angle;
    CHECK_REL(mesh_area(&m, &min_angle), 1.5, 1e-12);
    fdem_mesh_free(&m);
}

static void disc_area_and_quality(void)
{
    int divisions[] = {6, 12, 48, 200};
    for (int i = 0; i < 4; i++) {
        fdem_mesh m;
        fdem_error err;
        CHECK(fdem_mesh_disc(1, -2, 0.5, divisions[i], &m, &err) == 0, "%s", err.message);
        double min_angle;
        double area = mesh_area(&m, &min_angle);
        /* the polygon inscribed in the circle with `divisions` sides */
        double n = divisions[i], polygon = 0.5 * n * 0.25 * sin(2 * M_PI / n);
        CHECK_REL(area, polygon, 1e-9);
        CHECK(min_angle > 25, "divisions %d: smallest angle %.1f degrees (sliver)", divisions[i], min_angle);
        fdem_mesh_free(&m);
    }
}

static void validation_names_the_triangle(void)
{
    double xy[] = {0, 0, 1, 0, 0, 1, 2, 0};
    int32_t bad_index[] = {0, 1, 2, 0, 1, 7};
    int32_t collinear[] = {0, 1, 2, 0, 1, 3};
    int32_t clockwise[] = {0, 2, 1, 1, 3, 2};
    fdem_error err;
    fdem_mesh m = {4, 2, xy, bad_index};
    CHECK(fdem_mesh_validate(&m, NULL, &err) < 0 && err.kind == FDEM_ITEM_TRIANGLE && err.item == 1,
          "%s", err.message);
    CHECK(strstr(err.message, "triangle 1") != NULL, "%s", err.message);
    m.tri = collinear;
    CHECK(fdem_mesh_validate(&m, NULL, &err) < 0 && err.item == 1 && strstr(err.message, "zero area"),
          "%s", err.message);
    m.tri = clockwise;
    int reoriented = 0;
    CHECK(fdem_mesh_validate(&m, &reoriented, &err) == 0, "%s", err.message);
    CHECK(reoriented == 1, "reoriented %d", reoriented);
    CHECK(clockwise[1] == 1 && clockwise[2] == 2, "first triangle now %d %d %d", clockwise[0],
          clockwise[1], clockwise[2]);
    double nan_xy[] = {0, 0, 1, 0, 0, NAN};
    int32_t one[] = {0, 1, 2};
    fdem_mesh n = {3, 1, nan_xy, one};
    CHECK(fdem_mesh_validate(&n, NULL, &err) < 0 && err.kind == FDEM_ITEM_NODE && err.item == 2,
          "%s", err.message);
    /* a sound triangle at scales whose area overflows or underflows: named
     * as such, not as "zero area" (nodes collinear or coincident) */
    const double scales[] = {1e200, 1e-200};
    for (int s = 0; s < 2; s++) {
        double scaled[] = {0, 0, scales[s], 0, 0, scales[s]};
        fdem_mesh k = {3, 1, scaled, one};
        CHECK(fdem_mesh_validate(&k, NULL, &err) < 0 && err.kind == FDEM_ITEM_TRIANGLE &&
                  err.item == 0 && strstr(err.message, "m across"),
              "scale %g: %s", scales[s], err.message);
    }
}

static void unused_node_is_rejected(void)
{
    double xy[] = {0, 0, 1, 0, 0, 1, 5, 5};
    int32_t tri[] = {0, 1, 2};
    fdem_mesh m = {4, 1, xy, tri};
    fdem_error err;
    CHECK(fdem_mesh_validate(&m, NULL, &err) < 0 && err.kind == FDEM_ITEM_NODE && err.item == 3,
          "%s", err.message);
}

static void lumped_mass_is_total_mass(void)
{
    fdem_model *model = fdem_model_create();
    fdem_material_def d = {.density = 2700, .young = 3e10, .poisson = 0.25};
    fdem_error err;
    int mat = fdem_add_material(model, &d, &err);
    fdem_mesh m;
    fdem_mesh_rectangle(0, 0, 2, 1, 8, 4, &m, &err);
    fdem_add_part(model, &m, mat, 0, &err);
    fdem_mesh_free(&m);
    CHECK(fdem_model_finalize(model, &err) == 0, "%s", err.message);
    double total = 0;
    const double *ms = fdem_node_masses(model);
    for (int i = 0; i < fdem_get_counts(model).nodes; i++) total += ms[i];
    CHECK_REL(total, 2700 * 2.0, 1e-12);
    /* corner node of a structured mesh touches one or two triangles */
    CHECK(ms[0] > 0, "corner mass %g", ms[0]);
    fdem_model_destroy(model);
}

CHECK_MAIN(T(rectangle_counts_and_area), T(disc_area_and_quality), T(validation_names_the_triangle),
           T(unused_node_is_rejected), T(lumped_mass_is_total_mass))
