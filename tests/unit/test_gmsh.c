/*
 * test_gmsh.c - the gmsh reader on files written by the installed gmsh
 * (the .msh files in tests/data, from the .geo files next to them) and on broken input:
 * every malformed file must fail with a message naming section and line,
 * never crash or read past the buffer (the ASan build checks the latter).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "gmsh/gmsh.h"
#include "read_file.h"

static double mesh_area(const fdem_mesh *m)
{
    double area = 0;
    for (int t = 0; t < m->triangle_count; t++) {
        const double *a = &m->xy[2 * m->tri[3 * t]], *b = &m->xy[2 * m->tri[3 * t + 1]],
                     *c = &m->xy[2 * m->tri[3 * t + 2]];
        area += fabs((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) / 2;
    }
    return area;
}

/* Every index in range and every node used by some triangle. */
static int mesh_is_compact(const fdem_mesh *m)
{
    char *used = calloc((size_t)m->node_count + 1, 1);
    int ok = 1;
    for (int i = 0; i < 3 * m->triangle_count; i++) {
        if (m->tri[i] < 0 || m->tri[i] >= m->node_count) ok = 0;
        else used[m->tri[i]] = 1;
    }
    for (int i = 0; i < m->node_count; i++)
        if (!used[i]) ok = 0;
    free(used);
    return ok;
}

/* Reads a file (copied into a buffer of exactly its size, so ASan catches
 * any read past the end) and checks its node/triangle counts and area. */
static void check_file(const char *path, int nodes, int triangles, double area)
{
    size_t length = 0;
    char *text = read_file(path, &length);
    if (!text) return;
    fdem_mesh m;
    char message[256];
    int rc = gmsh_read(text, length, &m, message, sizeof message);
    CHECK(rc == 0, "%s: %s", path, message);
    if (rc == 0) {
        CHECK(m.node_count == nodes, "%s: %d nodes, want %d", path, m.node_count, nodes);
        CHECK(m.triangle_count == triangles, "%s: %d triangles, want %d", path,
              m.triangle_count, triangles);
        CHECK_NEAR(mesh_area(&m), area, 1e-12);
        CHECK(mesh_is_compact(&m), "%s: index out of range or unused node", path);
        fdem_mesh_free(&m);
    }
    free(text);
}

/* Expected figures computed independently (Python) from the same files. */
static void square_v22(void) { check_file("tests/data/square_v22.msh", 12, 14, 1.0); }
static void square_v41(void) { check_file("tests/data/square_v41.msh", 12, 14, 1.0); }
/* The disc's centre point is a geometry node no triangle uses: dropped. */
static void disc_hole_v22(void)
{
    check_file("tests/data/disc_hole_v22.msh", 42, 58, 2.625632949971628);
}
static void disc_hole_v41(void)
{
    check_file("tests/data/disc_hole_v41.msh", 42, 58, 2.625632949971628);
}

/* Reads text with one of the two readers, freeing what it returns: 0 or -1. */
typedef int (*gmsh_reader_fn)(const char *text, size_t length, char *message, size_t size);

static int read_triangles(const char *text, size_t length, char *message, size_t size)
{
    fdem_mesh m;
    if (gmsh_read(text, length, &m, message, size) != 0) return -1;
    fdem_mesh_free(&m);
    return 0;
}

static int read_tetrahedra(const char *text, size_t length, char *message, size_t size)
{
    fdem_tet_mesh m;
    if (gmsh_read_tetrahedra(text, length, &m, message, size) != 0) return -1;
    fdem_tet_mesh_free(&m);
    return 0;
}

/* `read` refuses the length bytes of text (copied without a NUL: the
 * reader must not need one) with a message holding every needle (a NULL
 * ends the list) and, with_line, the line at fault. */
static void check_refused(gmsh_reader_fn read, const char *text, size_t length,
                          const char *const *needles, int with_line)
{
    char *copy = malloc(length ? length : 1);
    memcpy(copy, text, length);
    char message[256] = "";
    CHECK(read(copy, length, message, sizeof message) == -1, "accepted: %.60s", text);
    for (; *needles; needles++)
        CHECK(strstr(message, *needles) != NULL, "message \"%s\" lacks \"%s\"", message, *needles);
    if (with_line) CHECK(strstr(message, "line") != NULL, "no line in \"%s\"", message);
    free(copy);
}

#define NEEDLES(...) ((const char *const[]){__VA_ARGS__, NULL})

/* The triangle reader refuses text with needle in its message. */
static void check_fails(const char *text, const char *needle, int with_line)
{
    check_refused(read_triangles, text, strlen(text), NEEDLES(needle), with_line);
}

/* A file of tests/data refused by `read` as check_refused says (no check
 * where the file is missing, as the other file tests). */
static void check_file_refused(const char *path, gmsh_reader_fn read, const char *const *needles)
{
    size_t length = 0;
    char *text = read_file(path, &length);
    if (!text) return;
    check_refused(read, text, length, needles, 0);
    free(text);
}

#define V22 "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
#define V41 "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"

/* Non-contiguous tags, an unused node, CRLF line ends, a point element and a
 * skipped section: nodes renumbered in file order. */
static void tags_and_renumbering_v22(void)
{
    const char *text = V22 "$PhysicalNames\r\n1\r\n2 1 \"x\"\r\n$EndPhysicalNames\r\n"
                           "$Nodes\r\n4\r\n10 0 0 0\r\n7 5 5 0\r\n30 1 0 0\r\n20 0 1 0\r\n"
                           "$EndNodes\r\n$Elements\r\n2\r\n1 15 2 0 1 7\r\n"
                           "2 2 2 0 1 10 30 20\r\n$EndElements\r\n";
    fdem_mesh m;
    char message[256];
    int rc = gmsh_read(text, strlen(text), &m, message, sizeof message);
    CHECK(rc == 0, "%s", message);
    if (rc) return;
    CHECK(m.node_count == 3 && m.triangle_count == 1, "%d nodes, %d triangles", m.node_count,
          m.triangle_count);
    CHECK(m.tri[0] == 0 && m.tri[1] == 1 && m.tri[2] == 2, "tri %d %d %d", m.tri[0], m.tri[1],
          m.tri[2]);
    CHECK_NEAR(m.xy[2], 1.0, 0); /* tag 30 -> index 1 */
    CHECK_NEAR(m.xy[5], 1.0, 0); /* tag 20 -> index 2 */
    fdem_mesh_free(&m);
}

/* 4.1 with a parametric block (extra coordinates ignored) and a block of
 * lines that is skipped. */
static void blocks_v41(void)
{
    const char *text = V41 "$Nodes\n2 4 1 9\n1 1 1 1\n9\n0.5 0 0 0.5\n2 1 0 3\n1\n2\n3\n"
                           "0 0 0\n1 0 0\n0 1 0\n$EndNodes\n$Elements\n2 3 1 3\n"
                           "1 1 1 1\n1 1 9\n2 1 2 2\n2 1 2 3\n3 9 3 2\n$EndElements\n";
    fdem_mesh m;
    char message[256];
    int rc = gmsh_read(text, strlen(text), &m, message, sizeof message);
    CHECK(rc == 0, "%s", message);
    if (rc) return;
    CHECK(m.node_count == 4 && m.triangle_count == 2, "%d nodes, %d triangles", m.node_count,
          m.triangle_count);
    CHECK(m.tri[3] == 0 && m.tri[4] == 3 && m.tri[5] == 2, "second tri %d %d %d", m.tri[3],
          m.tri[4], m.tri[5]);
    CHECK_NEAR(mesh_area(&m), 0.5 + 0.25, 1e-15);
    fdem_mesh_free(&m);
}

static void rejects_binary(void)
{
    check_fails("$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n", "binary", 1);
}

static void rejects_other_versions(void)
{
    check_fails("$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", "version 3.0", 1);
    check_fails("$MeshFormat\n4 0 8\n$EndMeshFormat\n", "2.2 or 4.1", 1);
}

static void rejects_garbage(void)
{
    check_fails("", "no $MeshFormat", 0);
    check_fails("hello world\n", "not a gmsh mesh", 1);
    check_fails("{\"nodes\": []}", "not a gmsh mesh", 1);
    check_fails("$Nodes\n1\n1 0 0 0\n$EndNodes\n", "must start with $MeshFormat", 1);
    check_fails(V22 "$Nodes\n1\n1 zero 0 0\n$EndNodes\n", "finite", 1);
    check_fails(V22 "$Nodes\n1\n1 nan 0 0\n$EndNodes\n", "finite", 1);
    check_fails(V22 "$Nodes\n1\n1 1e999 0 0\n$EndNodes\n", "finite", 1);
    check_fails(V22 "$Nodes\n-1\n$EndNodes\n", "negative", 1);
    check_fails(V22 "$Nodes\n1\n0 0 0 0\n$EndNodes\n", "not positive", 1);
    check_fails(V22 "stray\n", "expected a section", 1);
}

static void rejects_truncated(void)
{
    check_fails(V22 "$Nodes\n3\n1 0 0 0\n", "truncated", 1);
    check_fails(V22 "$Nodes\n999999999999\n1 0 0 0\n$EndNodes\n", "too short", 1);
    check_fails(V22 "$Nodes\n1\n1 0 0 0\n", "$EndNodes", 1);
    check_fails(V22 "$Entities\n1 2 3\n", "$EndEntities", 0);
    check_fails("$MeshFormat\n2.2 0 8", "$EndMeshFormat", 1);
    check_fails(V41 "$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n", "truncated", 1);
    check_fails(V41 "$Nodes\n1 2 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n",
                "declares 2 nodes", 1);
    check_fails(V22 "$Nodes\n2\n1 0 0 0\n2 1 0 0\n3 1 1 0\n$EndNodes\n", "$EndNodes", 1);
}

static void rejects_bad_references(void)
{
    check_fails(V22 "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
                    "$Elements\n1\n1 2 2 0 1 1 2 4\n$EndElements\n",
                "node 4", 1);
    check_fails(V22 "$Nodes\n3\n1 0 0 0\n1 1 0 0\n3 0 1 0\n$EndNodes\n"
                    "$Elements\n1\n1 2 2 0 1 1 3 3\n$EndElements\n",
                "defined twice", 0);
    check_fails(V22 "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
                    "$Elements\n1\n1 2 2 0 1 1 2\n$EndElements\n",
                "3 node tags", 1);
}

static void rejects_missing_sections(void)
{
    check_fails(V22 "$Nodes\n1\n1 0 0 0\n$EndNodes\n", "no $Elements", 0);
    check_fails(V22 "$Elements\n0\n$EndElements\n", "no $Nodes", 0);
    check_fails(V22 "$Nodes\n2\n1 0 0 0\n2 1 0 0\n$EndNodes\n"
                    "$Elements\n1\n1 1 2 0 1 1 2\n$EndElements\n",
                "no 3-node triangles", 0);
    check_fails(V22 V22, "second $MeshFormat", 1);
}

/* Every prefix of a real file must fail cleanly (or, for the full length,
 * succeed): exercises every truncation point under ASan. Only the whole
 * file and the file without its final newline parse. */
static void check_every_prefix(const char *path, gmsh_reader_fn reader)
{
    size_t length = 0;
    char *text = read_file(path, &length);
    if (!text) return;
    int accepted = 0, unexplained = 0;
    for (size_t n = 0; n <= length; n++) {
        char *copy = malloc(n ? n : 1);
        memcpy(copy, text, n);
        char message[256] = "";
        if (reader(copy, n, message, sizeof message) == 0)
            accepted++;
        else if (strncmp(message, "gmsh", 4) != 0)
            unexplained++;
        free(copy);
    }
    CHECK(accepted == 2, "%s: %d prefixes accepted", path, accepted);
    CHECK(unexplained == 0, "%s: %d failures without a message", path, unexplained);
    free(text);
}

static void every_prefix_of_a_real_file(void)
{
    check_every_prefix("tests/data/square_v41.msh", read_triangles);
}

/* ------------------------------------------------------------ tetrahedra */

/* The cube of cube.geo as the installed gmsh meshes it: 45 nodes and 100
 * tetrahedra (counted independently with Python from the v2.2 file), volume
 * 1 once validated (which orients every tetrahedron). */
static void check_tet_file(const char *path)
{
    size_t length = 0;
    char *text = read_file(path, &length);
    if (!text) return;
    fdem_tet_mesh m;
    fdem_error err;
    char message[256];
    int rc = gmsh_read_tetrahedra(text, length, &m, message, sizeof message);
    CHECK(rc == 0, "%s: %s", path, message);
    if (rc == 0) {
        CHECK(m.node_count == 45 && m.tet_count == 100, "%s: %d nodes, %d tetrahedra, want 45, 100",
              path, m.node_count, m.tet_count);
        CHECK(fdem_tet_mesh_validate(&m, NULL, &err) == 0, "%s: %s", path, err.message);
        CHECK_NEAR(fdem_tet_mesh_volume(&m), 1.0, 1e-12);
        double zmax = 0;
        for (int n = 0; n < m.node_count; n++) zmax = fmax(zmax, m.xyz[3 * n + 2]);
        CHECK(zmax == 1.0, "%s: z not read (max %g)", path, zmax);
        fdem_tet_mesh_free(&m);
    }
    free(text);
}

static void cube_tetrahedra_v22(void) { check_tet_file("tests/data/cube_v22.msh"); }
static void cube_tetrahedra_v41(void) { check_tet_file("tests/data/cube_v41.msh"); }

static void tetrahedra_rejects(void)
{
    fdem_tet_mesh m;
    char message[256] = "";
    size_t length = 0;
    char *square = read_file("tests/data/square_v22.msh", &length);
    if (square) {
        CHECK(gmsh_read_tetrahedra(square, length, &m, message, sizeof message) != 0 &&
              strstr(message, "no 4-node tetrahedra"), "a 2D file: %s", message);
        free(square);
    }
    static const char *no_z = V22 "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1\n4 0 0 1\n$EndNodes\n"
                                  "$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n";
    CHECK(gmsh_read_tetrahedra(no_z, strlen(no_z), &m, message, sizeof message) != 0 &&
          strstr(message, "line 8"), "a node without z: %s", message);
    static const char *short_tet = V22 "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
                                       "$Elements\n1\n1 4 0 1 2 3\n$EndElements\n";
    CHECK(gmsh_read_tetrahedra(short_tet, strlen(short_tet), &m, message, sizeof message) != 0 &&
          strstr(message, "4 node tags"), "three tags: %s", message);
    static const char *unknown = V22 "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
                                     "$Elements\n1\n1 4 0 1 2 3 9\n$EndElements\n";
    CHECK(gmsh_read_tetrahedra(unknown, strlen(unknown), &m, message, sizeof message) != 0 &&
          strstr(message, "tetrahedron refers to node 9"), "unknown node: %s", message);
    /* every prefix of the v4.1 cube fails cleanly or (whole file) parses */
    check_every_prefix("tests/data/cube_v41.msh", read_tetrahedra);
}

/* A mesh of second-order elements only (gmsh -order 2) is named as such:
 * it used to be told to "mesh the volumes in 3D (gmsh -3)", which it was. */
static void second_order_meshes_are_named(void)
{
    static const char *tet10_v22 =
        V22 "$Nodes\n10\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 .5 0 0\n6 .5 .5 0\n"
            "7 0 .5 0\n8 0 0 .5\n9 0 .5 .5\n10 .5 0 .5\n$EndNodes\n"
            "$Elements\n1\n1 11 2 1 1 1 2 3 4 5 6 7 8 10 9\n$EndElements\n";
    check_refused(read_tetrahedra, tet10_v22, strlen(tet10_v22),
                  NEEDLES("second-order 10-node tetrahedra", "-order 1"), 0);
    static const char *tet10_v41 =
        V41 "$Nodes\n1 10 1 10\n3 1 0 10\n1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n"
            "0 0 0\n1 0 0\n0 1 0\n0 0 1\n.5 0 0\n.5 .5 0\n0 .5 0\n0 0 .5\n0 .5 .5\n.5 0 .5\n"
            "$EndNodes\n$Elements\n1 1 1 1\n3 1 11 1\n1 1 2 3 4 5 6 7 8 10 9\n$EndElements\n";
    check_refused(read_tetrahedra, tet10_v41, strlen(tet10_v41),
                  NEEDLES("second-order 10-node tetrahedra"), 0);
    static const char *tri6_v22 =
        V22 "$Nodes\n6\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 .5 0 0\n5 .5 .5 0\n6 0 .5 0\n"
            "$EndNodes\n$Elements\n1\n1 9 2 1 1 1 2 3 4 5 6\n$EndElements\n";
    check_fails(tri6_v22, "second-order 6-node triangles", 0);
}

/* A mesh of the other dimension names the missing "dimension": 3 (or the one
 * too many). A 3D file read for a 2D case used to be read as its surface
 * triangles projected on z = 0 and refused as "triangle 14 has zero area". */
static void other_dimension_is_named(void)
{
    const char *const *read_for_2d = NEEDLES("3D mesh", "\"dimension\": 3");
    const char *const *read_for_3d = NEEDLES("no 4-node tetrahedra", "2D mesh", "\"dimension\": 3");
    check_file_refused("tests/data/cube_v22.msh", read_triangles, read_for_2d);
    check_file_refused("tests/data/cube_v41.msh", read_triangles, read_for_2d);
    check_file_refused("tests/data/square_v22.msh", read_tetrahedra, read_for_3d);
    check_file_refused("tests/data/square_v41.msh", read_tetrahedra, read_for_3d);
}

static int read_triangles_grouped(const char *text, size_t length, char *message, size_t size)
{
    fdem_mesh m;
    gmsh_groups g;
    if (gmsh_read_grouped(text, length, &m, &g, message, size) != 0) return -1;
    fdem_mesh_free(&m);
    gmsh_groups_free(&g);
    return 0;
}

/* A group member that is not a kept triangle has its nodes read from its
 * own line. A line ending before them (more tags declared than the line
 * holds, or no node at all) made the first such member point into an empty
 * tag pool: a null pointer plus an offset, which the fuzzer's UBSan build
 * stopped on (a mutated "61 22 21 1 535 450 536" in examples/gmsh-plate),
 * and the member was taken with no nodes. Now the line is named. */
static void member_without_nodes_is_refused(void)
{
    const char *groups = "$PhysicalNames\n2\n2 1 \"plate\"\n1 2 \"edge\"\n$EndPhysicalNames\n";
    const char *nodes = "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n";
    static const char *const members[] = {"2 1 21 2 1 1 2", "2 1 2 2 1", "2 22 21 1 535 450 536"};
    for (size_t k = 0; k < sizeof members / sizeof members[0]; k++) {
        char text[512];
        snprintf(text, sizeof text, V22 "%s%s$Elements\n2\n1 2 2 1 1 1 2 3\n%s\n$EndElements\n",
                 groups, nodes, members[k]);
        check_refused(read_triangles_grouped, text, strlen(text),
                      NEEDLES("ends before its node tags", "$Elements"), 1);
    }
    static const char *v41 =
        V41 "$PhysicalNames\n1\n2 1 \"plate\"\n$EndPhysicalNames\n"
            "$Entities\n0 0 1 0\n1 0 0 0 1 1 0 1 1 0\n$EndEntities\n"
            "$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n"
            "$Elements\n2 2 1 2\n2 1 2 1\n1 1 2 3\n2 1 1 1\n2\n$EndElements\n";
    check_refused(read_triangles_grouped, v41, strlen(v41),
                  NEEDLES("ends before its node tags"), 1);
}

CHECK_MAIN(T(square_v22), T(square_v41), T(disc_hole_v22), T(disc_hole_v41),
           T(tags_and_renumbering_v22), T(blocks_v41), T(rejects_binary),
           T(rejects_other_versions), T(rejects_garbage), T(rejects_truncated),
           T(rejects_bad_references), T(rejects_missing_sections),
           T(every_prefix_of_a_real_file), T(cube_tetrahedra_v22), T(cube_tetrahedra_v41),
           T(second_order_meshes_are_named), T(other_dimension_is_named),
           T(tetrahedra_rejects), T(member_without_nodes_is_refused))
