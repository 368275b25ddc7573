/*
 * fuzz_case.c - libFuzzer harness for case_build(): any byte string must
 * give either a model or a list of problems, never a crash, a leak or an
 * allocation beyond the memory limit (ASan enforces -rss_limit_mb and
 * -malloc_limit_mb; the limit below keeps accepted models small so the
 * fuzzer spends its time on the parser, not on meshing).
 *
 * The same bytes also go to the gmsh reader (with its physical groups) directly: inside a case, gmsh text
 * sits in an escaped JSON string that mutations rarely keep valid, so the
 * reader gets its own raw-text coverage from the same run (the corpus holds
 * the .msh files of tests/data as they are), for triangles and tetrahedra
 * both: the 3D reader keeps other elements and sections.
 */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "case/case.h"
#include "gmsh/gmsh.h"
#include "mesh/mesh_3d.h"

#define FUZZ_MEMORY_LIMIT ((size_t)64 << 20)

/* Every index a group holds is one of the mesh's (a face has face_nodes). */
static void check_groups(const gmsh_groups *groups, int nodes, int elements, int face_nodes)
{
    for (int g = 0; g < groups->count; g++) {
        const gmsh_group *k = &groups->group[g];
        for (int i = 0; i < k->node_count; i++)
            if (k->nodes[i] < 0 || k->nodes[i] >= nodes) __builtin_trap();
        for (int i = 0; i < k->element_count; i++)
            if (k->elements[i] < 0 || k->elements[i] >= elements) __builtin_trap();
        for (int i = 0; i < face_nodes * k->face_count; i++)
            if (k->faces[i] < 0 || k->faces[i] >= nodes) __builtin_trap();
    }
}

/* The 3D reader on the same bytes: a mesh it returns is whole (every index
 * in range, every group index one of the mesh's), a failure says where. */
static void check_tetrahedra(const uint8_t *data, size_t size)
{
    fdem_tet_mesh mesh;
    gmsh_groups groups;
    char message[256];
    if (gmsh_read_tetrahedra_grouped((const char *)data, size, &mesh, &groups, message,
                                     sizeof message) != 0) {
        if (strncmp(message, "gmsh", 4) != 0) __builtin_trap();
        return;
    }
    if (mesh.node_count < 4 || mesh.tet_count < 1) __builtin_trap();
    for (size_t i = 0; i < 4 * (size_t)mesh.tet_count; i++)
        if (mesh.tet[i] < 0 || mesh.tet[i] >= mesh.node_count) __builtin_trap();
    check_groups(&groups, mesh.node_count, mesh.tet_count, 3);
    gmsh_groups_free(&groups);
    fdem_tet_mesh_free(&mesh);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    problems out;
    problems_init(&out);
    case_info info;
    fdem_model *model = case_build((const char *)data, size, FUZZ_MEMORY_LIMIT, &info, &out);
    if (model) {
        /* a built model must be consistent with what case_build reported */
        if (!(info.dt > 0) || info.dt > info.stable_dt || out.count != 0) __builtin_trap();
        fdem_model_destroy(model);
    } else if (out.count + out.dropped == 0 || (out.status != 400 && out.status != 422)) {
        __builtin_trap(); /* a refusal must say why */
    }
    problems_free(&out);

    fdem_mesh mesh;
    gmsh_groups groups;
    char message[256];
    if (gmsh_read_grouped((const char *)data, size, &mesh, &groups, message, sizeof message) == 0) {
        if (mesh.node_count < 3 || mesh.triangle_count < 1) __builtin_trap();
        for (int i = 0; i < 3 * mesh.triangle_count; i++)
            if (mesh.tri[i] < 0 || mesh.tri[i] >= mesh.node_count) __builtin_trap();
        check_groups(&groups, mesh.node_count, mesh.triangle_count, 2);
        gmsh_groups_free(&groups);
        fdem_mesh_free(&mesh);
    } else if (strncmp(message, "gmsh", 4) != 0) {
        __builtin_trap(); /* every failure names where it happened */
    }
    check_tetrahedra(data, size);
    return 0;
}
