/*
 * test_fracture_region.c - fracture in a region (contract 6.1,
 * fdem_add_part_region, joint_region.c), 2D and 3D:
 *
 *  - the joints are exactly the interior edges (faces) whose two elements
 *    both have their centroid in the region, counted here by brute force
 *    over all element pairs; the nodes are one per class of each vertex's
 *    elements joined around it through faces without a joint, counted
 *    here by a walk around each vertex; every node sits at its vertex;
 *  - a region of every element builds the whole fracturing part bit for
 *    bit (nodes, joints, their order); a region of none is refused;
 *  - a bar fracturing only in its middle, pulled apart, breaks there into
 *    two pieces, each end whole (2D and 3D); on 1 and 2 threads the same
 *    bits, and a checkpoint restored into a new model runs on to the same
 *    bits;
 *  - under a slowly ramped end force F the stress is the closed form
 *    sigma_xx = F / H in every element outside the region (and inside it):
 *    the far field is continuous and bonded to the region;
 *  - with every joint broken, the pieces are the elements joined through
 *    shared nodes (counted here from edge adjacency), and no two elements
 *    that share a node are ever handed to contact.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "build_model.h"
#include "check.h"
#include "joint/joint.h"
#include "model/model.h"

/* ---------------------------------------------------------- the meshes */

/* A mesh of either dimension as plain arrays. */
typedef struct test_mesh {
    int dim, K, node_count, elem_count;
    const double *xyz;
    const int32_t *elem;
} test_mesh;

static test_mesh view_2d(const fdem_mesh *m)
{
    return (test_mesh){2, 3, m->node_count, m->triangle_count, m->xy, m->tri};
}

static test_mesh view_3d(const fdem_tet_mesh *m)
{
    return (test_mesh){3, 4, m->node_count, m->tet_count, m->xyz, m->tet};
}

/* Flags of the elements whose centroid lies in box (lower, then upper). */
static uint8_t *centroid_mask(const test_mesh *t, const double *box)
{
    uint8_t *mask = calloc((size_t)t->elem_count, 1);
    for (int e = 0; e < t->elem_count; e++) {
        int inside = 1;
        for (int d = 0; d < t->dim; d++) {
            double c = 0;
            for (int k = 0; k < t->K; k++) c += t->xyz[t->dim * t->elem[t->K * e + k] + d];
            c /= t->K;
            inside &= c >= box[d] && c <= box[t->dim + d];
        }
        mask[e] = (uint8_t)inside;
    }
    return mask;
}

/* How many vertices elements a and b share. */
static int shared_vertices(const test_mesh *t, int a, int b)
{
    int n = 0;
    for (int i = 0; i < t->K; i++)
        for (int k = 0; k < t->K; k++) n += t->elem[t->K * a + i] == t->elem[t->K * b + k];
    return n;
}

static int holds_vertex(const test_mesh *t, int e, int v)
{
    for (int k = 0; k < t->K; k++)
        if (t->elem[t->K * e + k] == v) return 1;
    return 0;
}

/* Brute force: element pairs that share a face (dim vertices), both in. */
static int expected_joints(const test_mesh *t, const uint8_t *mask)
{
    int n = 0;
    for (int a = 0; a < t->elem_count; a++)
        for (int b = a + 1; b < t->elem_count; b++)
            n += mask[a] && mask[b] && shared_vertices(t, a, b) == t->dim;
    return n;
}

/* Around each vertex, the classes of its elements joined through faces
 * that carry no joint (a flood over the fan), summed. */
static int expected_nodes(const test_mesh *t, const uint8_t *mask)
{
    int *fan = malloc(sizeof(int) * (size_t)t->elem_count);
    int *label = malloc(sizeof(int) * (size_t)t->elem_count);
    int total = 0;
    for (int v = 0; v < t->node_count; v++) {
        int n = 0;
        for (int e = 0; e < t->elem_count; e++)
            if (holds_vertex(t, e, v)) fan[n++] = e;
        for (int i = 0; i < n; i++) label[i] = -1;
        for (int s = 0; s < n; s++) {
            if (label[s] >= 0) continue;
            label[s] = s;
            total++;
            for (int changed = 1; changed;) {
                changed = 0;
                for (int i = 0; i < n; i++) {
                    if (label[i] != s) continue;
                    for (int k = 0; k < n; k++) {
                        if (label[k] >= 0) continue;
                        int a = fan[i], b = fan[k];
                        if (shared_vertices(t, a, b) == t->dim && !(mask[a] && mask[b])) {
                            label[k] = s;
                            changed = 1;
                        }
                    }
                }
            }
        }
    }
    free(fan);
    free(label);
    return total;
}

static fdem_model *region_model(const test_mesh *t, const void *mesh, const uint8_t *mask,
                                double damping)
{
    fdem_model *m = fdem_model_create();
    fdem_error err = {0};
    if (t->dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
    int mat = build_fracturing_rock(m, damping);
    int p = t->dim == 3 ? fdem_add_part_region_3d(m, mesh, mat, mask, &err)
                        : fdem_add_part_region(m, mesh, mat, mask, &err);
    if (p < 0) build_die("region part", &err);
    return m;
}

/* Joints, nodes and node positions of a region against the brute force. */
static void check_counts(const test_mesh *t, const void *mesh, const double *box)
{
    uint8_t *mask = centroid_mask(t, box);
    int inside = 0;
    for (int e = 0; e < t->elem_count; e++) inside += mask[e];
    CHECK(inside > 0 && inside < t->elem_count, "the box should hold some elements: %d of %d",
          inside, t->elem_count);
    fdem_model *m = region_model(t, mesh, mask, 0);
    int joints = expected_joints(t, mask), nodes = expected_nodes(t, mask);
    CHECK(m->joint_count == joints, "%dD: %d joints, want %d", t->dim, m->joint_count, joints);
    CHECK(m->node_count == nodes, "%dD: %d nodes, want %d (mesh %d, whole fracture %d)", t->dim,
          m->node_count, nodes, t->node_count, t->K * t->elem_count);
    CHECK(nodes > t->node_count && nodes < t->K * t->elem_count,
          "a region lies between the mesh's %d and %d nodes: %d", t->node_count,
          t->K * t->elem_count, nodes);
    for (int j = 0; j < m->joint_count; j++)
        CHECK(mask[m->joint_elem[2 * j]] && mask[m->joint_elem[2 * j + 1]],
              "joint %d joins an element outside the region", j);
    int misplaced = 0;
    for (int e = 0; e < t->elem_count; e++)
        for (int k = 0; k < t->K; k++) {
            int node = m->elem_node[t->K * e + k], v = t->elem[t->K * e + k];
            misplaced += m->node_origin[node] != v;
            for (int d = 0; d < t->dim; d++)
                misplaced += m->pos0[t->dim * node + d] != t->xyz[t->dim * v + d];
        }
    CHECK(misplaced == 0, "%d corners are not at their vertex", misplaced);
    fdem_model_destroy(m);
    free(mask);
}

static void region_joints_and_nodes_2d(void)
{
    fdem_mesh mesh;
    fdem_error err;
    if (fdem_mesh_rectangle(0, 0, 8, 6, 8, 6, &mesh, &err)) build_die("rectangle", &err);
    test_mesh t = view_2d(&mesh);
    const double box[4] = {2, 1.5, 6, 4.5};
    check_counts(&t, &mesh, box);
    const double corner[4] = {-1, -1, 3, 2}; /* on the mesh's edge */
    check_counts(&t, &mesh, corner);
    fdem_mesh_free(&mesh);
}

static void region_joints_and_nodes_3d(void)
{
    fdem_tet_mesh mesh = {0};
    fdem_error err = {0};
    const double origin[3] = {0, 0, 0}, size[3] = {4, 3, 3};
    const int div[3] = {4, 3, 3};
    if (fdem_tet_mesh_box(origin, size, div, &mesh, &err)) build_die("box", &err);
    test_mesh t = view_3d(&mesh);
    const double box[6] = {1, 0.5, 0.5, 3, 2.5, 2.5};
    check_counts(&t, &mesh, box);
    fdem_tet_mesh_free(&mesh);
}

/* ------------------------------------------- all or nothing in the region */

static void same_as_whole(const test_mesh *t, const void *mesh)
{
    uint8_t *all = malloc((size_t)t->elem_count);
    memset(all, 1, (size_t)t->elem_count);
    fdem_model *r = region_model(t, mesh, all, 0);
    fdem_model *w = fdem_model_create();
    fdem_error err = {0};
    if (t->dim == 3 && fdem_set_dimension(w, 3, &err)) build_die("dimension", &err);
    int mat = build_fracturing_rock(w, 0);
    if ((t->dim == 3 ? fdem_add_part_3d(w, mesh, mat, 1, &err)
                     : fdem_add_part(w, mesh, mat, 1, &err)) < 0)
        build_die("whole part", &err);
    CHECK(r->node_count == w->node_count && r->joint_count == w->joint_count,
          "%dD: %d nodes %d joints, whole part %d, %d", t->dim, r->node_count, r->joint_count,
          w->node_count, w->joint_count);
    CHECK(r->parts[0].region == 0, "every element in the region is a whole fracturing part");
    size_t K = (size_t)t->K, E = (size_t)t->elem_count, D = (size_t)t->dim;
    if (r->node_count == w->node_count && r->joint_count == w->joint_count) {
        CHECK(memcmp(r->elem_node, w->elem_node, sizeof(int32_t) * K * E) == 0, "element nodes");
        CHECK(memcmp(r->node_origin, w->node_origin, sizeof(int32_t) * (size_t)r->node_count) == 0,
              "node origins");
        CHECK(memcmp(r->pos0, w->pos0, sizeof(double) * D * (size_t)r->node_count) == 0,
              "node positions");
        CHECK(memcmp(r->joint_node, w->joint_node, sizeof(int32_t) * 2 * D * (size_t)r->joint_count) == 0,
              "joint nodes (and order)");
        CHECK(memcmp(r->joint_elem, w->joint_elem, sizeof(int32_t) * 2 * (size_t)r->joint_count) == 0,
              "joint elements (and order)");
    }
    /* and none in it: refused, naming the part */
    memset(all, 0, (size_t)t->elem_count);
    fdem_model *n = fdem_model_create();
    if (t->dim == 3 && fdem_set_dimension(n, 3, &err)) build_die("dimension", &err);
    mat = build_fracturing_rock(n, 0);
    int p = t->dim == 3 ? fdem_add_part_region_3d(n, mesh, mat, all, &err)
                        : fdem_add_part_region(n, mesh, mat, all, &err);
    CHECK(p < 0 && err.kind == FDEM_ITEM_PART && strstr(err.message, "fracture region"),
          "an empty region: %d, %s", p, err.message);
    /* and a material without fracture parameters */
    int plain = build_material(n, 2700, 3e10, 0.25, 0, 0);
    memset(all, 1, (size_t)t->elem_count);
    p = t->dim == 3 ? fdem_add_part_region_3d(n, mesh, plain, all, &err)
                    : fdem_add_part_region(n, mesh, plain, all, &err);
    CHECK(p < 0 && strstr(err.message, "fracture parameters"), "no fracture block: %d, %s", p,
          err.message);
    fdem_model_destroy(n);
    fdem_model_destroy(r);
    fdem_model_destroy(w);
    free(all);
}

static void region_of_all_is_the_whole_part(void)
{
    fdem_mesh mesh;
    fdem_error err;
    if (fdem_mesh_rectangle(0, 0, 1, 1, 6, 5, &mesh, &err)) build_die("rectangle", &err);
    test_mesh t = view_2d(&mesh);
    same_as_whole(&t, &mesh);
    fdem_mesh_free(&mesh);
    fdem_tet_mesh tm = {0};
    const double origin[3] = {0, 0, 0}, size[3] = {1, 1, 1};
    const int div[3] = {3, 3, 2};
    if (fdem_tet_mesh_box(origin, size, div, &tm, &err)) build_die("box", &err);
    test_mesh t3 = view_3d(&tm);
    same_as_whole(&t3, &tm);
    fdem_tet_mesh_free(&tm);
}

/* ------------------------------------------------------ the pulled bar */

#define BAR_L 2.0
#define BAR_H 0.2

/* A 2 m x 0.2 m bar of 20 x 2 cells fracturing in 0.8 <= x <= 1.2 (by
 * centroid), its left end fixed, its right end pulled at `speed`. */
static fdem_model *pulled_bar(double speed, double damping)
{
    fdem_mesh mesh;
    fdem_error err;
    if (fdem_mesh_rectangle(0, 0, BAR_L, BAR_H, 20, 2, &mesh, &err)) build_die("bar", &err);
    test_mesh t = view_2d(&mesh);
    const double box[4] = {0.8, -1, 1.2, 1};
    uint8_t *mask = centroid_mask(&t, box);
    fdem_model *m = region_model(&t, &mesh, mask, damping);
    free(mask);
    fdem_mesh_free(&mesh);
    fdem_constraint_def c = {0};
    c.select = FDEM_SELECT_BOX;
    c.box[0] = -1; c.box[1] = -1; c.box[2] = 1e-9; c.box[3] = 1;
    c.kind = FDEM_CONSTRAINT_FIX;
    c.fix_x = c.fix_y = 1;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("fix", &err);
    c.box[0] = BAR_L - 1e-9; c.box[2] = BAR_L + 1;
    c.kind = FDEM_CONSTRAINT_VELOCITY;
    c.fix_x = c.fix_y = 0;
    c.value[0] = speed;
    c.free_y = 1;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("pull", &err);
    build_finalize(m, 0.5);
    return m;
}

static double element_cx(const fdem_model *m, int e)
{
    double c = 0;
    for (int k = 0; k < 3; k++) c += m->pos0[2 * m->elem_node[3 * e + k]];
    return c / 3;
}

static void region_bar_breaks_only_inside(void)
{
    fdem_model *m = pulled_bar(2.0, 0.1);
    int joints = m->joint_count;
    CHECK(joints > 0 && m->node_count < 3 * m->elem_count, "%d joints, %d nodes", joints,
          m->node_count);
    run_until(m, 2e-3);
    fdem_counts n = fdem_get_counts(m);
    CHECK(n.broken_joints > 0, "the bar should have broken: %d of %d joints", n.broken_joints,
          joints);
    int32_t *label = malloc(sizeof(int32_t) * (size_t)m->elem_count);
    joint_fragment_labels(m, label);
    int left = -1, right = -1, stray = 0;
    for (int e = 0; e < m->elem_count; e++) {
        double cx = element_cx(m, e);
        if (cx < 0.8) {
            if (left < 0) left = label[e];
            stray += label[e] != left;
        } else if (cx > 1.2) {
            if (right < 0) right = label[e];
            stray += label[e] != right;
        }
    }
    CHECK(stray == 0, "%d elements outside the region left their end's piece", stray);
    CHECK(left >= 0 && right >= 0 && left != right, "the two ends are pieces %d and %d", left,
          right);
    /* the ends separated: the gap between them is open */
    const double *x = fdem_positions(m);
    double reach_left = -INFINITY, reach_right = INFINITY;
    for (int e = 0; e < m->elem_count; e++)
        for (int k = 0; k < 3; k++) {
            double xi = x[2 * m->elem_node[3 * e + k]];
            if (label[e] == left) reach_left = fmax(reach_left, xi);
            if (label[e] == right) reach_right = fmin(reach_right, xi);
        }
    CHECK(reach_right - reach_left > -0.2 && n.fragments >= 2,
          "pieces %d; the right piece's left end %g, the left piece's right end %g", n.fragments,
          reach_right, reach_left);
    free(label);
    fdem_model_destroy(m);
}

static void step_n(fdem_model *m, int steps)
{
    fdem_error err;
    for (int s = 0; s < steps; s++)
        if (fdem_step(m, &err)) build_die("step", &err);
}

static void region_threads_and_checkpoint_keep_the_bits(void)
{
    fdem_model *a = pulled_bar(2.0, 0.1), *b = pulled_bar(2.0, 0.1), *c = pulled_bar(2.0, 0.1);
    fdem_set_threads(b, 2);
    const int half = 400;
    step_n(a, 2 * half);
    step_n(b, 2 * half);
    CHECK(fdem_get_counts(a).broken_joints > 0, "the bar should be breaking by step %d",
          2 * half);
    size_t N = (size_t)a->node_count * 2;
    CHECK(memcmp(a->pos, b->pos, sizeof(double) * N) == 0, "1 and 2 threads differ");
    CHECK(memcmp(a->joint_damage, b->joint_damage, sizeof(double) * (size_t)a->joint_count) == 0,
          "1 and 2 threads: damage differs");
    step_n(c, half);
    size_t size = fdem_checkpoint_size(c);
    void *buf = malloc(size);
    CHECK(fdem_checkpoint_write(c, buf, size) == 0, "checkpoint write");
    fdem_model *d = pulled_bar(2.0, 0.1);
    fdem_error err = {0};
    CHECK(fdem_checkpoint_read(d, buf, size, &err) == 0, "checkpoint read: %s", err.message);
    step_n(d, half);
    CHECK(memcmp(a->pos, d->pos, sizeof(double) * N) == 0, "restored run differs");
    CHECK(memcmp(a->joint_damage, d->joint_damage, sizeof(double) * (size_t)a->joint_count) == 0,
          "restored run: damage differs");
    free(buf);
    fdem_model_destroy(a);
    fdem_model_destroy(b);
    fdem_model_destroy(c);
    fdem_model_destroy(d);
}

/* The same in 3D: a 0.6 x 0.1 x 0.1 m bar of 6 x 1 x 1 cubes (six
 * tetrahedra each) fracturing in 0.2 <= x <= 0.4, its left face fixed, its
 * right face pulled at 2 m/s: two pieces, each end whole, the same bits on
 * 1 and 2 threads. */
static fdem_model *pulled_bar_3d(int threads)
{
    fdem_tet_mesh mesh = {0};
    fdem_error err = {0};
    const double origin[3] = {0, 0, 0}, size[3] = {0.6, 0.1, 0.1};
    const int div[3] = {6, 1, 1};
    if (fdem_tet_mesh_box(origin, size, div, &mesh, &err)) build_die("box", &err);
    test_mesh t = view_3d(&mesh);
    const double box[6] = {0.2, -1, -1, 0.4, 1, 1};
    uint8_t *mask = centroid_mask(&t, box);
    fdem_model *m = region_model(&t, &mesh, mask, 0.1);
    free(mask);
    fdem_tet_mesh_free(&mesh);
    fdem_constraint_def c = {0};
    c.select = FDEM_SELECT_BOX;
    const double left[6] = {-1, -1, -1, 1e-9, 1, 1}, right[6] = {0.6 - 1e-9, -1, -1, 2, 1, 1};
    memcpy(c.box, left, sizeof left);
    c.kind = FDEM_CONSTRAINT_FIX;
    c.fix_x = c.fix_y = c.fix_z = 1;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("fix", &err);
    memcpy(c.box, right, sizeof right);
    c.kind = FDEM_CONSTRAINT_VELOCITY;
    c.fix_x = c.fix_y = c.fix_z = 0;
    c.value[0] = 2.0;
    c.free_y = c.free_z = 1;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("pull", &err);
    build_finalize(m, 0.5);
    fdem_set_threads(m, threads);
    return m;
}

static void region_bar_3d_breaks_only_inside(void)
{
    fdem_model *a = pulled_bar_3d(1), *b = pulled_bar_3d(2);
    CHECK(a->joint_count > 0 && a->node_count < 4 * a->elem_count, "%d joints, %d nodes",
          a->joint_count, a->node_count);
    run_until(a, 6e-4);
    run_until(b, 6e-4);
    CHECK(memcmp(a->pos, b->pos, sizeof(double) * 3 * (size_t)a->node_count) == 0,
          "1 and 2 threads differ");
    CHECK(fdem_get_counts(a).broken_joints > 0, "the bar should have broken");
    int32_t *label = malloc(sizeof(int32_t) * (size_t)a->elem_count);
    joint_fragment_labels(a, label);
    int left = -1, right = -1, stray = 0;
    for (int e = 0; e < a->elem_count; e++) {
        double cx = 0;
        for (int k = 0; k < 4; k++) cx += 0.25 * a->pos0[3 * a->elem_node[4 * e + k]];
        int *end = cx < 0.2 ? &left : cx > 0.4 ? &right : NULL;
        if (!end) continue;
        if (*end < 0) *end = label[e];
        stray += label[e] != *end;
    }
    CHECK(stray == 0 && left >= 0 && right >= 0 && left != right,
          "ends are pieces %d and %d, %d elements outside the region strayed", left, right,
          stray);
    free(label);
    fdem_model_destroy(a);
    fdem_model_destroy(b);
}

/* ------------------------------------------------------- the far field */

/* F per unit thickness on the right end (a uniform traction), ramped as (1 - cos(pi t/T))/2
 * over T = 40 periods of the bar's first mode (4 L / c), then held: the
 * bar is left at rest to well under 0.1 % of F. sigma_xx = F / H in
 * every element, sigma_yy = sigma_xy = 0 (free sides). */
static void region_far_field_is_continuous(void)
{
    fdem_mesh mesh;
    fdem_error err;
    if (fdem_mesh_rectangle(0, 0, BAR_L, BAR_H, 20, 2, &mesh, &err)) build_die("bar", &err);
    test_mesh t = view_2d(&mesh);
    const double box[4] = {0.8, -1, 1.2, 1};
    uint8_t *mask = centroid_mask(&t, box);
    fdem_model *m = region_model(&t, &mesh, mask, 0.2);
    fdem_mesh_free(&mesh);
    const double F = 0.5e6 * BAR_H; /* half the tensile strength */
    double c_wave = sqrt(3e10 * 0.75 / (2700 * 1.25 * 0.5)); /* plane-strain P wave */
    double T = 40 * 4 * BAR_L / c_wave;
    double ramp[2 * 41];
    for (int i = 0; i <= 40; i++) {
        ramp[2 * i] = T * i / 40;
        ramp[2 * i + 1] = 0.5 * (1 - cos(M_PI * i / 40));
    }
    fdem_constraint_def c = {0};
    c.select = FDEM_SELECT_BOX;
    c.box[0] = -1; c.box[1] = -1; c.box[2] = 1e-9; c.box[3] = 1;
    c.kind = FDEM_CONSTRAINT_FIX;
    c.fix_x = 1;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("fix x", &err);
    c.box[3] = 1e-9; /* the corner: no rigid motion along y */
    c.fix_x = 0;
    c.fix_y = 1;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("fix y", &err);
    memset(&c, 0, sizeof c);
    c.select = FDEM_SELECT_BOX;
    c.box[0] = BAR_L - 1e-9; c.box[1] = -1; c.box[2] = BAR_L + 1; c.box[3] = 1;
    c.kind = FDEM_CONSTRAINT_PRESSURE; /* a traction F / H pulling the end */
    c.value[0] = -F / BAR_H;
    c.amplitude = ramp;
    c.amplitude_count = 41;
    if (fdem_add_constraint(m, &c, &err) < 0) build_die("force", &err);
    build_finalize(m, 0.5);
    run_until(m, 1.2 * T);
    CHECK(fdem_get_counts(m).broken_joints == 0, "nothing breaks at half the strength");
    double *s = malloc(sizeof(double) * 3 * (size_t)m->elem_count);
    fdem_element_stress(m, s);
    double want = F / BAR_H, worst_out = 0, worst_in = 0, worst_other = 0;
    for (int e = 0; e < m->elem_count; e++) {
        double err_xx = fabs(s[3 * e] - want) / want;
        if (mask[e]) worst_in = fmax(worst_in, err_xx);
        else worst_out = fmax(worst_out, err_xx);
        worst_other = fmax(worst_other, fmax(fabs(s[3 * e + 1]), fabs(s[3 * e + 2])) / want);
    }
    printf("  far field: sigma_xx off F/H by %.2e outside, %.2e inside the region; "
           "sigma_yy, sigma_xy up to %.2e of it\n", worst_out, worst_in, worst_other);
    CHECK(worst_out < 0.01, "sigma_xx outside the region off F/H by %g", worst_out);
    CHECK(worst_in < 0.01, "sigma_xx inside the region off F/H by %g", worst_in);
    CHECK(worst_other < 0.01, "sigma_yy, sigma_xy up to %g of F/H", worst_other);
    free(s);
    free(mask);
    fdem_model_destroy(m);
}

/* ------------------------------------- broken all through: pieces, contact */

/* With every joint broken: the pieces are 1 (the ring outside and the
 * region elements that share an edge with it) plus each region element
 * with no edge to the outside, which then has nodes of its own. */
static void region_pieces_and_contact(void)
{
    fdem_mesh mesh;
    fdem_error err;
    if (fdem_mesh_rectangle(0, 0, 6, 6, 6, 6, &mesh, &err)) build_die("rectangle", &err);
    test_mesh t = view_2d(&mesh);
    const double box[4] = {1, 1, 5, 5};
    uint8_t *mask = centroid_mask(&t, box);
    int isolated = 0;
    for (int a = 0; a < t.elem_count; a++) {
        if (!mask[a]) continue;
        int touches = 0;
        for (int b = 0; b < t.elem_count; b++)
            touches |= !mask[b] && shared_vertices(&t, a, b) == 2;
        isolated += !touches;
    }
    fdem_model *m = region_model(&t, &mesh, mask, 0);
    build_finalize(m, 0.5);
    CHECK(joint_fragment_count(m) == 1, "intact: one piece, got %d", joint_fragment_count(m));
    for (int j = 0; j < m->joint_count; j++) m->joint_damage[j] = 1;
    int pieces = joint_fragment_count(m);
    CHECK(pieces == 1 + isolated, "broken through: %d pieces, want 1 + %d", pieces, isolated);
    int32_t *piece = malloc(sizeof(int32_t) * (size_t)m->elem_count);
    int32_t *scratch = malloc(4 * sizeof(int32_t) * (size_t)m->node_count);
    joint_mark_cracks(m, piece, scratch);
    free(scratch);
    int share_kept = 0, crack_dropped = 0, sharing = 0, across = 0;
    for (int a = 0; a < m->elem_count; a++)
        for (int b = a + 1; b < m->elem_count; b++) {
            int share = 0;
            for (int i = 0; i < 3; i++)
                for (int k = 0; k < 3; k++)
                    share |= m->elem_node[3 * a + i] == m->elem_node[3 * b + k];
            int excluded = joint_contact_excluded(m, piece, a, b);
            if (share) {
                sharing++;
                share_kept += !excluded;
            } else if (joint_holds(m, a, b) == 0 && mask[a] && mask[b] &&
                       shared_vertices(&t, a, b) == 2) {
                across++; /* the two faces of a broken joint */
                crack_dropped += excluded;
            }
        }
    CHECK(sharing > 0 && share_kept == 0,
          "%d of %d pairs sharing a node would be handed to contact", share_kept, sharing);
    CHECK(across > 0 && crack_dropped == 0, "%d of %d broken joints' faces left out of contact",
          crack_dropped, across);
    free(piece);
    free(mask);
    fdem_mesh_free(&mesh);
    fdem_model_destroy(m);
}

/* Bonded materials in a region part: a joint takes its strengths from its
 * elements' materials, so the elements outside the region (a lining, a
 * far field) may have a material without fracture parameters; one inside
 * may not. */
static void region_materials_outside_need_no_fracture(void)
{
    fdem_mesh mesh;
    fdem_error err;
    if (fdem_mesh_rectangle(0, 0, 6, 6, 6, 6, &mesh, &err)) build_die("rectangle", &err);
    test_mesh t = view_2d(&mesh);
    const double box[4] = {1, 1, 5, 5};
    uint8_t *mask = centroid_mask(&t, box);
    fdem_model *m = region_model(&t, &mesh, mask, 0);
    int plain = build_material(m, 2400, 2e10, 0.2, 0, 0.5);
    int32_t *mat = malloc(sizeof(int32_t) * (size_t)t.elem_count);
    int inside = -1;
    for (int e = 0; e < t.elem_count; e++) {
        mat[e] = mask[e] ? 0 : plain;
        if (mask[e] && inside < 0) inside = e;
    }
    CHECK(fdem_set_element_materials(m, 0, mat, &err) == 0, "outside: %s", err.message);
    mat[inside] = plain;
    CHECK(fdem_set_element_materials(m, 0, mat, &err) < 0 &&
              strstr(err.message, "fracture region"),
          "an element inside without fracture parameters was accepted");
    fdem_model_destroy(m);
    free(mat);
    free(mask);
    fdem_mesh_free(&mesh);
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        {"region_joints_and_nodes_2d", region_joints_and_nodes_2d},
        {"region_joints_and_nodes_3d", region_joints_and_nodes_3d},
        {"region_of_all_is_the_whole_part", region_of_all_is_the_whole_part},
        {"region_bar_breaks_only_inside", region_bar_breaks_only_inside},
        {"region_bar_3d_breaks_only_inside", region_bar_3d_breaks_only_inside},
        {"region_threads_and_checkpoint_keep_the_bits", region_threads_and_checkpoint_keep_the_bits},
        {"region_far_field_is_continuous", region_far_field_is_continuous},
        {"region_pieces_and_contact", region_pieces_and_contact},
        {"region_materials_outside_need_no_fracture", region_materials_outside_need_no_fracture},
    };
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
