/*
 * test_fragments.c - fragments and the sieve curve (contract 5.4) against
 * what they must add up to: a fracturing bar pulled apart breaks into
 * pieces whose masses sum to the model's mass (1e-9), whose count is the
 * status count, whose momenta sum to the model's, and which no intact joint
 * crosses, and exactly the pieces at its pulled ends are held; two
 * separate 3D boxes are two fragments, one per part, with the box's mass,
 * volume, equivalent sphere, centre and velocity; a sieve curve of known
 * pieces has the mass fractions by hand.
 */
#include "build_model.h"
#include "check.h"
#include "mesh/mesh_3d.h"

#include <stdlib.h>

/* A fracturing bar, 0.1 x 0.01 m, whose ends are pulled apart at 5 m/s. */
static fdem_model *pulled_bar(void)
{
    fdem_model *m = fdem_model_create();
    int rock = build_fracturing_rock(m, 0.1);
    build_rectangle_part(m, rock, 0, 0, 0.1, 0.01, 20, 2, 1);
    for (int side = 0; side < 2; side++) {
        fdem_constraint_def c = {0};
        c.select = FDEM_SELECT_BOX;
        double x = side ? 0.1 : 0;
        const double box[4] = {x - 1e-9, -1, x + 1e-9, 1};
        for (int k = 0; k < 4; k++) c.box[k] = box[k];
        c.kind = FDEM_CONSTRAINT_VELOCITY;
        c.value[0] = side ? 5 : -5;
        c.free_y = 1;
        fdem_error err;
        if (fdem_add_constraint(m, &c, &err) < 0) build_die("constraint", &err);
    }
    build_finalize(m, 0.5);
    return m;
}

static void pieces_of_a_broken_bar_add_up(void)
{
    fdem_model *m = pulled_bar();
    fdem_error err;
    for (int s = 0; s < 20000 && fdem_get_counts(m).fragments < 2; s++)
        if (fdem_step(m, &err)) {
            CHECK(0, "%s", err.message);
            break;
        }
    for (int s = 0; s < 200; s++) fdem_step(m, &err); /* let the pieces separate */
    fdem_counts counts = fdem_get_counts(m);
    CHECK(counts.fragments >= 2, "the bar did not break: %d fragments", counts.fragments);
    fprintf(stderr, "  broke into %d fragments (%d of %d joints broken) at step %lld\n", counts.fragments,
            counts.broken_joints, counts.joints, (long long)fdem_get_step(m));
    fdem_fragment *f = NULL;
    int n = fdem_fragments(m, &f);
    CHECK(n == counts.fragments, "fragments %d, status %d", n, counts.fragments);
    double mass = 0, px = 0, py = 0, fmass = 0, fpx = 0, fpy = 0;
    int elements = 0;
    for (int i = 0; i < counts.nodes; i++) {
        mass += fdem_node_masses(m)[i];
        px += fdem_node_masses(m)[i] * fdem_velocities(m)[2 * i];
        py += fdem_node_masses(m)[i] * fdem_velocities(m)[2 * i + 1];
    }
    for (int k = 0; k < n; k++) {
        fmass += f[k].mass;
        fpx += f[k].mass * f[k].velocity[0];
        fpy += f[k].mass * f[k].velocity[1];
        elements += f[k].elements;
        CHECK_REL(f[k].diameter, sqrt(4 * f[k].size / M_PI), 1e-15);
        CHECK_REL(f[k].mass, 2700 * f[k].size, 1e-12);
    }
    CHECK_REL(fmass, mass, 1e-9);
    CHECK_REL(fmass, 2700 * 0.1 * 0.01, 1e-9);
    CHECK(elements == counts.elements, "elements %d of %d", elements, counts.elements);
    CHECK_NEAR(fpx, px, 1e-9 * mass * 5);
    CHECK_NEAR(fpy, py, 1e-9 * mass * 5);
    /* the left piece moves left, the right one right */
    double vmin = 1e9, vmax = -1e9;
    for (int k = 0; k < n; k++) {
        vmin = fmin(vmin, f[k].velocity[0]);
        vmax = fmax(vmax, f[k].velocity[0]);
    }
    CHECK(vmin < -1 && vmax > 1, "piece velocities %g .. %g m/s", vmin, vmax);
    /* labels: numbered by first element, and no intact joint crosses two */
    int32_t *label = malloc(sizeof(int32_t) * (size_t)counts.elements);
    CHECK(fdem_fragment_labels(m, label) == n, "label count");
    CHECK(label[0] == 0, "the first element's fragment is 0, got %d", label[0]);
    int next = 0;
    for (int e = 0; e < counts.elements; e++) {
        CHECK(label[e] >= 0 && label[e] <= next, "element %d label %d jumps past %d", e, label[e], next);
        if (label[e] == next) next++;
    }
    const int32_t *joints = fdem_joints(m);
    const double *damage = fdem_joint_damage(m);
    const int32_t *tri = fdem_triangles(m);
    int crossing = 0;
    for (int j = 0; j < counts.joints; j++) {
        if (damage[j] >= 1) continue;
        int ea = -1, eb = -1;
        for (int e = 0; e < counts.elements; e++)
            for (int c = 0; c < 3; c++) {
                if (tri[3 * e + c] == joints[4 * j]) ea = e;
                if (tri[3 * e + c] == joints[4 * j + 2]) eb = e;
            }
        crossing += label[ea] != label[eb];
    }
    CHECK(crossing == 0, "%d intact joints join two fragments", crossing);
    /* held: exactly the pieces with a node at a pulled end (x = 0 or 0.1
     * at t = 0, where the velocity constraints select) */
    int *end_piece = calloc((size_t)n, sizeof(int));
    const double *x0 = fdem_initial_positions(m);
    for (int e = 0; e < counts.elements; e++)
        for (int c = 0; c < 3; c++) {
            double x = x0[2 * tri[3 * e + c]];
            if (fabs(x) < 1e-9 || fabs(x - 0.1) < 1e-9) end_piece[label[e]] = 1;
        }
    int held = 0;
    for (int k = 0; k < n; k++) {
        CHECK(f[k].held == end_piece[k], "fragment %d: held %d, at a pulled end %d", k, f[k].held,
              end_piece[k]);
        CHECK(f[k].part == 0, "fragment %d: part %d of a one-part model", k, f[k].part);
        held += f[k].held;
    }
    CHECK(held == 2, "%d pieces held, want the two ends", held);
    free(end_piece);
    free(label);
    free(f);
    fdem_model_destroy(m);
}

/* Two boxes apart, one moving: two fragments of exactly the box. */
static void separate_boxes_are_fragments(void)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    CHECK(fdem_set_dimension(m, 3, &err) == 0, "%s", err.message);
    int rock = build_material(m, 2000, 1e9, 0.25, 0, 0);
    const double size[3] = {0.2, 0.1, 0.1};
    const int div[3] = {2, 1, 1};
    const double origins[2][3] = {{0, 0, 0}, {1, 0, 0}};
    for (int b = 0; b < 2; b++) {
        fdem_tet_mesh mesh;
        if (fdem_tet_mesh_box(origins[b], size, div, &mesh, &err)) build_die("box", &err);
        if (fdem_add_part_3d(m, &mesh, rock, 0, &err) < 0) build_die("part", &err);
        fdem_tet_mesh_free(&mesh);
    }
    const double v[3] = {0.5, -0.25, 1};
    CHECK(fdem_set_part_velocity_v(m, 1, v, &err) == 0, "%s", err.message);
    fdem_fragment *f = NULL;
    if (fdem_model_finalize(m, &err)) build_die("finalize", &err);
    int n = fdem_fragments(m, &f);
    CHECK(n == 2, "fragments %d", n);
    double V = 0.2 * 0.1 * 0.1;
    for (int b = 0; b < 2 && n == 2; b++) {
        CHECK(f[b].elements == 12, "elements %d", f[b].elements);
        CHECK(f[b].part == b && f[b].held == 0, "box %d: part %d, held %d", b, f[b].part, f[b].held);
        CHECK_REL(f[b].size, V, 1e-12);
        CHECK_REL(f[b].mass, 2000 * V, 1e-12);
        CHECK_REL(f[b].diameter, cbrt(6 * V / M_PI), 1e-12);
        CHECK_NEAR(f[b].centroid[0], origins[b][0] + 0.1, 1e-12);
        CHECK_NEAR(f[b].centroid[1], 0.05, 1e-12);
        CHECK_NEAR(f[b].centroid[2], 0.05, 1e-12);
        for (int d = 0; d < 3; d++) CHECK_NEAR(f[b].velocity[d], b ? v[d] : 0, 1e-12);
    }
    free(f);
    fdem_model_destroy(m);
}

static void sieve_curve_by_hand(void)
{
    fdem_fragment f[5] = {{0}};
    const double diameters[5] = {0.3, 0.1, 0.2, 0.1, 0.4};
    const double masses[5] = {3, 1, 2, 1, 3};
    for (int k = 0; k < 5; k++) {
        f[k].diameter = diameters[k];
        f[k].mass = masses[k];
    }
    double d[5], p[5];
    int n = fdem_sieve_curve(f, 5, d, p);
    CHECK(n == 4, "points %d", n);
    const double want_d[4] = {0.1, 0.2, 0.3, 0.4}, want_p[4] = {0.2, 0.4, 0.7, 1.0};
    for (int k = 0; k < 4 && n == 4; k++) {
        CHECK_NEAR(d[k], want_d[k], 0);
        CHECK_NEAR(p[k], want_p[k], 1e-15);
    }
}

CHECK_MAIN(T(pieces_of_a_broken_bar_add_up), T(separate_boxes_are_fragments), T(sieve_curve_by_hand))
