/*
 * test_mesh_3d.c - the tetrahedral generators and validator: positive
 * volumes, conforming meshes (every interior face shared by exactly two
 * tetrahedra, the boundary a closed surface of the shape's area), the
 * volume of the shape within the stated tolerance, bounded quality (worst
 * dihedral angle and radius ratio), the box mirror-symmetric (no preferred
 * direction), and every validation error naming its node or tetrahedron.
 */
#include "check.h"
#include "mesh/mesh_3d.h"

#include <stdint.h>
#include <stdlib.h>

/* ------------------------------------------------------------ topology */

typedef struct face_key {
    int32_t n[3];
} face_key;

static int cmp_face(const void *a, const void *b)
{
    const face_key *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->n[k] != y->n[k]) return x->n[k] < y->n[k] ? -1 : 1;
    return 0;
}

static void sort3(int32_t *v)
{
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (v[j] < v[i]) { int32_t t = v[i]; v[i] = v[j]; v[j] = t; }
}

static double face_area(const fdem_tet_mesh *m, const int32_t *n)
{
    const double *a = m->xyz + 3 * n[0], *b = m->xyz + 3 * n[1], *c = m->xyz + 3 * n[2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double x = u[1] * w[2] - u[2] * w[1], y = u[2] * w[0] - u[0] * w[2], z = u[0] * w[1] - u[1] * w[0];
    return 0.5 * sqrt(x * x + y * y + z * z);
}

/* Checks conformity; returns the boundary area. */
static double expect_conforming(const char *what, const fdem_tet_mesh *m)
{
    static const int opposite[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    size_t count = 4 * (size_t)m->tet_count;
    face_key *f = malloc(count * sizeof *f);
    for (int k = 0; k < m->tet_count; k++)
        for (int a = 0; a < 4; a++) {
            face_key *key = &f[4 * k + a];
            for (int c = 0; c < 3; c++) key->n[c] = m->tet[4 * k + opposite[a][c]];
            sort3(key->n);
        }
    qsort(f, count, sizeof *f, cmp_face);
    size_t over = 0, boundary = 0;
    double area = 0;
    face_key *edges = malloc(3 * count * sizeof *edges); /* boundary edges as (a, b, -1) */
    size_t edge_count = 0;
    for (size_t i = 0; i < count;) {
        size_t j = i;
        while (j < count && cmp_face(&f[i], &f[j]) == 0) j++;
        if (j - i > 2) over++;
        if (j - i == 1) {
            boundary++;
            area += face_area(m, f[i].n);
            for (int c = 0; c < 3; c++) {
                face_key e = {{f[i].n[c], f[i].n[(c + 1) % 3], -1}};
                sort3(e.n);
                edges[edge_count++] = e;
            }
        }
        i = j;
    }
    qsort(edges, edge_count, sizeof *edges, cmp_face);
    size_t open = 0;
    for (size_t i = 0; i < edge_count;) {
        size_t j = i;
        while (j < edge_count && cmp_face(&edges[i], &edges[j]) == 0) j++;
        if (j - i != 2) open++;
        i = j;
    }
    CHECK(over == 0, "%s: %zu faces shared by more than two tetrahedra", what, over);
    CHECK(boundary > 0 && open == 0, "%s: the boundary (%zu faces) has %zu edges not shared by two faces",
          what, boundary, open);
    free(f);
    free(edges);
    return area;
}

static void expect_positive(const char *what, const fdem_tet_mesh *m)
{
    int bad = 0;
    for (int k = 0; k < m->tet_count; k++) {
        fdem_tet_mesh one = {m->node_count, 1, m->xyz, m->tet + 4 * k};
        bad += fdem_tet_mesh_volume(&one) <= 0;
    }
    CHECK(bad == 0, "%s: %d tetrahedra with volume <= 0", what, bad);
}

/* ------------------------------------------------------------------ box */

static void test_tet_box(void)
{
    double o[3] = {1, -2, 0.5}, s[3] = {2.0, 1.0, 1.5};
    int d[3] = {4, 2, 3};
    fdem_tet_mesh m;
    fdem_error err;
    CHECK(fdem_tet_mesh_box(o, s, d, &m, &err) == 0, "box: %s", err.message);
    CHECK(m.node_count == 5 * 3 * 4 && m.tet_count == 6 * 24, "box: %d nodes %d tets", m.node_count,
          m.tet_count);
    expect_positive("box", &m);
    CHECK_REL(fdem_tet_mesh_volume(&m), 3.0, 1e-13);
    double area = expect_conforming("box", &m);
    CHECK_REL(area, 2 * (2.0 * 1.0 + 2.0 * 1.5 + 1.0 * 1.5), 1e-13);
    double angle, ratio;
    fdem_tet_mesh_quality(&m, &angle, &ratio);
    /* scaled Kuhn tetrahedra; on a cube the worst dihedral angle is 45 deg */
    CHECK(angle > 30 && ratio > 0.5, "box: worst dihedral %.2f deg, radius ratio %.3f", angle, ratio);
    fdem_tet_mesh_free(&m);

    /* unit cells: exactly the Kuhn figures */
    double unit[3] = {4, 4, 4};
    int cube[3] = {4, 4, 4};
    CHECK(fdem_tet_mesh_box(o, unit, cube, &m, &err) == 0, "cube: %s", err.message);
    fdem_tet_mesh_quality(&m, &angle, &ratio);
    CHECK_NEAR(angle, 45.0, 1e-9);
    CHECK_NEAR(ratio, 0.717438935214, 1e-9); /* 3 r_in / r_circ of the Kuhn tetrahedron */
    fdem_tet_mesh_free(&m);

    int zero[3] = {0, 1, 1};
    CHECK(fdem_tet_mesh_box(o, s, zero, &m, &err) != 0, "zero divisions accepted");
    double flat[3] = {1, 0, 1};
    CHECK(fdem_tet_mesh_box(o, flat, d, &m, &err) != 0, "zero size accepted");
}

/* No preferred direction: the box mesh of even divisions maps onto itself
 * under the mirror x -> -x (and y, z): the same set of tetrahedra. */
static int32_t mirror_node(int32_t n, int axis, const int cells[3])
{
    int idx[3] = {n % (cells[0] + 1), (n / (cells[0] + 1)) % (cells[1] + 1),
                  n / ((cells[0] + 1) * (cells[1] + 1))};
    idx[axis] = cells[axis] - idx[axis];
    return (int32_t)((idx[2] * (cells[1] + 1) + idx[1]) * (cells[0] + 1) + idx[0]);
}

typedef struct tet_key {
    int32_t n[4];
} tet_key;

static int cmp_tet(const void *a, const void *b) { return memcmp(a, b, sizeof(tet_key)); }

static void sort4(int32_t *v)
{
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++)
            if (v[j] < v[i]) { int32_t t = v[i]; v[i] = v[j]; v[j] = t; }
}

static void test_tet_box_mirror_symmetric(void)
{
    double o[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    int d[3] = {4, 2, 6};
    fdem_tet_mesh m;
    fdem_error err;
    CHECK(fdem_tet_mesh_box(o, s, d, &m, &err) == 0, "box: %s", err.message);
    tet_key *orig = malloc(m.tet_count * sizeof *orig), *mirrored = malloc(m.tet_count * sizeof *mirrored);
    for (int axis = 0; axis < 3; axis++) {
        for (int k = 0; k < m.tet_count; k++) {
            for (int c = 0; c < 4; c++) {
                orig[k].n[c] = m.tet[4 * k + c];
                mirrored[k].n[c] = mirror_node(m.tet[4 * k + c], axis, d);
            }
            sort4(orig[k].n);
            sort4(mirrored[k].n);
        }
        qsort(orig, m.tet_count, sizeof *orig, cmp_tet);
        qsort(mirrored, m.tet_count, sizeof *mirrored, cmp_tet);
        CHECK(memcmp(orig, mirrored, m.tet_count * sizeof *orig) == 0,
              "the box mesh is not symmetric under the mirror of axis %d", axis);
    }
    free(orig);
    free(mirrored);
    fdem_tet_mesh_free(&m);
}

/* ------------------------------------------------------ sphere, cylinder */

static void test_tet_sphere(void)
{
    /* divisions, worst volume deficit allowed (the inscribed polyhedron) */
    static const struct { int divisions; double volume_tol; } cases[] = {
        {8, 0.25}, {16, 0.08}, {32, 0.025}, {64, 0.006}};
    double c[3] = {3, -1, 2}, R = 0.5;
    for (int k = 0; k < 4; k++) {
        fdem_tet_mesh m;
        fdem_error err;
        char what[32];
        snprintf(what, sizeof what, "sphere %d", cases[k].divisions);
        CHECK(fdem_tet_mesh_sphere(c, R, cases[k].divisions, &m, &err) == 0, "%s: %s", what, err.message);
        expect_positive(what, &m);
        double area = expect_conforming(what, &m);
        double v = fdem_tet_mesh_volume(&m), exact = 4.0 / 3.0 * M_PI * R * R * R;
        CHECK(v < exact && v > (1 - cases[k].volume_tol) * exact, "%s: volume %.6g, exact %.6g",
              what, v, exact);
        CHECK(area < 4 * M_PI * R * R && area > (1 - cases[k].volume_tol) * 4 * M_PI * R * R,
              "%s: boundary area %.6g", what, area);
        double angle, ratio;
        fdem_tet_mesh_quality(&m, &angle, &ratio);
        /* measured: 45.0 / 24.8 / 19.5 / 17.9 deg, 0.85 / 0.46 / 0.34 / 0.34 */
        CHECK(angle >= 15.0 && ratio >= 0.3, "%s: worst dihedral %.2f deg, radius ratio %.3f",
              what, angle, ratio);
        /* every boundary node on the sphere */
        double worst = 0;
        for (int n = 0; n < m.node_count; n++) {
            double d2 = 0;
            for (int a = 0; a < 3; a++) d2 += (m.xyz[3 * n + a] - c[a]) * (m.xyz[3 * n + a] - c[a]);
            worst = fmax(worst, sqrt(d2));
        }
        CHECK_REL(worst, R, 1e-13);
        fdem_tet_mesh_free(&m);
    }
    fdem_tet_mesh m;
    fdem_error err;
    CHECK(fdem_tet_mesh_sphere(c, R, 7, &m, &err) != 0, "7 divisions accepted");
    CHECK(fdem_tet_mesh_sphere(c, -1, 8, &m, &err) != 0, "negative radius accepted");
}

static void test_tet_cylinder(void)
{
    double c[3] = {1, 2, 3}, R = 0.4, L = 1.6;
    for (int axis = 0; axis < 3; axis++)
        for (int k = 0; k < 3; k++) {
            int around = 8 << k; /* 8, 16, 32: the axial spacing matches the rim's */
            int d[2] = {around, (int)ceil(L / (2 * M_PI * R / around))};
            fdem_tet_mesh m;
            fdem_error err;
            char what[48];
            snprintf(what, sizeof what, "cylinder axis %d divisions %d", axis, around);
            CHECK(fdem_tet_mesh_cylinder(c, axis, R, L, d, &m, &err) == 0, "%s: %s", what, err.message);
            expect_positive(what, &m);
            expect_conforming(what, &m);
            double v = fdem_tet_mesh_volume(&m), exact = M_PI * R * R * L;
            double tol = k == 0 ? 0.11 : k == 1 ? 0.03 : 0.008;
            CHECK(v < exact && v > (1 - tol) * exact, "%s: volume %.6g, exact %.6g", what, v, exact);
            double lo = 1e300, hi = -1e300;
            for (int n = 0; n < m.node_count; n++) {
                lo = fmin(lo, m.xyz[3 * n + axis]);
                hi = fmax(hi, m.xyz[3 * n + axis]);
            }
            CHECK(lo == c[axis] && fabs(hi - (c[axis] + L)) < 1e-12, "%s: spans %g .. %g", what, lo, hi);
            double angle, ratio;
            fdem_tet_mesh_quality(&m, &angle, &ratio);
            /* measured: 35.3 / 28.7 / 19.4 deg, 0.71 / 0.53 / 0.41 */
            CHECK(angle >= 15.0 && ratio >= 0.35, "%s: worst dihedral %.2f deg, radius ratio %.3f",
                  what, angle, ratio);
            fdem_tet_mesh_free(&m);
        }
    fdem_tet_mesh m;
    fdem_error err;
    int bad[2] = {8, 0};
    CHECK(fdem_tet_mesh_cylinder(c, 2, R, L, bad, &m, &err) != 0, "0 axial divisions accepted");
    int ok[2] = {8, 2};
    CHECK(fdem_tet_mesh_cylinder(c, 3, R, L, ok, &m, &err) != 0, "axis 3 accepted");
}

/* ------------------------------------------------------------ validation */

static fdem_tet_mesh two_tets(double *xyz, int32_t *tet)
{
    static const double nodes[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    static const int32_t tets[8] = {0, 1, 2, 3, 1, 3, 2, 4};
    memcpy(xyz, nodes, sizeof nodes);
    memcpy(tet, tets, sizeof tets);
    fdem_tet_mesh m = {5, 2, xyz, tet};
    return m;
}

static void test_tet_validate(void)
{
    double xyz[15];
    int32_t tet[8];
    fdem_error err;
    int flipped = -1;
    fdem_tet_mesh m = two_tets(xyz, tet);
    CHECK(fdem_tet_mesh_validate(&m, &flipped, &err) == 0, "valid mesh refused: %s", err.message);
    /* the second one (1, 3, 2, 4) is negative as written: reoriented */
    CHECK(flipped == 1, "reoriented %d, want 1", flipped);
    CHECK(fdem_tet_mesh_volume(&m) > 0, "volume after reorientation %g", fdem_tet_mesh_volume(&m));
    CHECK(fdem_tet_mesh_validate(&m, &flipped, &err) == 0 && flipped == 0, "second pass flips %d", flipped);

    m = two_tets(xyz, tet);
    tet[5] = 7;
    CHECK(fdem_tet_mesh_validate(&m, NULL, &err) != 0 && err.kind == FDEM_ITEM_TETRAHEDRON &&
          err.item == 1 && strstr(err.message, "node 7"), "index range: %s", err.message);
    m = two_tets(xyz, tet);
    tet[2] = -1;
    CHECK(fdem_tet_mesh_validate(&m, NULL, &err) != 0 && err.item == 0, "negative index: %s", err.message);
    m = two_tets(xyz, tet);
    tet[7] = 1;
    CHECK(fdem_tet_mesh_validate(&m, NULL, &err) != 0 && err.kind == FDEM_ITEM_TETRAHEDRON &&
          err.item == 1 && strstr(err.message, "twice"), "repeated node: %s", err.message);
    m = two_tets(xyz, tet);
    xyz[3 * 2 + 1] = NAN;
    CHECK(fdem_tet_mesh_validate(&m, NULL, &err) != 0 && err.kind == FDEM_ITEM_NODE && err.item == 2,
          "non-finite: %s", err.message);
    m = two_tets(xyz, tet);
    xyz[3 * 4] = xyz[3 * 4 + 1] = xyz[3 * 4 + 2] = 1.0 / 3.0; /* node 4 in the plane of 1, 2, 3 */
    CHECK(fdem_tet_mesh_validate(&m, NULL, &err) != 0 && err.kind == FDEM_ITEM_TETRAHEDRON &&
          err.item == 1 && strstr(err.message, "zero volume"), "zero volume: %s", err.message);
    m = two_tets(xyz, tet);
    m.tet_count = 1; /* node 4 now unused */
    CHECK(fdem_tet_mesh_validate(&m, NULL, &err) != 0 && err.kind == FDEM_ITEM_NODE && err.item == 4,
          "unused node: %s", err.message);
    m = two_tets(xyz, tet);
    m.tet_count = 0;
    CHECK(fdem_tet_mesh_validate(&m, NULL, &err) != 0, "empty mesh accepted");
    /* sound tetrahedra at scales whose volumes overflow or underflow: named
     * as such, not as "zero volume" (nodes coplanar or coincident) */
    const double scales[] = {1e200, 1e-200};
    for (int s = 0; s < 2; s++) {
        m = two_tets(xyz, tet);
        for (int i = 0; i < 15; i++) xyz[i] *= scales[s];
        CHECK(fdem_tet_mesh_validate(&m, NULL, &err) != 0 && err.kind == FDEM_ITEM_TETRAHEDRON &&
                  err.item == 0 && strstr(err.message, "m across") &&
                  strstr(err.message, "double precision"),
              "scale %g: %s", scales[s], err.message);
    }
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        {"test_tet_box", test_tet_box},
        {"test_tet_box_mirror_symmetric", test_tet_box_mirror_symmetric},
        {"test_tet_sphere", test_tet_sphere},
        {"test_tet_cylinder", test_tet_cylinder},
        {"test_tet_validate", test_tet_validate},
    };
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
