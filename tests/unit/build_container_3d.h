/*
 * build_container_3d.h - the open box of fixed slabs that 3D contact models
 * pour things into (tests/unit/test_contact_3d.c, bench/bench_engine.c's
 * sphere pile), built in one place.
 *
 * Contract: build_container_mesh fills *all with one tetrahedral mesh of
 * five box meshes (fdem_tet_mesh_box) and returns 0, or returns -1 with
 * err filled and *all empty. The caller adds it as one part and frees it.
 */
#ifndef FDEM_BUILD_CONTAINER_3D_H
#define FDEM_BUILD_CONTAINER_3D_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fdem.h"
#include "mesh/mesh_3d.h"

/* An open box of five slabs T thick - a floor under [0, X] x [0, Y] and
 * four walls up to H - meshed with tetrahedra of about `size`, as ONE mesh,
 * so that as one part its slabs never contact each other. Returns 0, or -1
 * with err filled. Used by the 3D contact tests and the bench's sphere pile. */
static inline int build_container_mesh(double X, double Y, double H, double T, double size,
                                       fdem_tet_mesh *all, fdem_error *err)
{
    const double slabs[5][2][3] = {
        {{-T, -T, -T}, {X + 2 * T, Y + 2 * T, T}}, /* floor */
        {{-T, 0, 0}, {T, Y, H}},                   /* walls */
        {{X, 0, 0}, {T, Y, H}},
        {{-T, -T, 0}, {X + 2 * T, T, H}},
        {{-T, Y, 0}, {X + 2 * T, T, H}},
    };
    *all = (fdem_tet_mesh){0};
    for (int k = 0; k < 5; k++) {
        int div[3];
        for (int d = 0; d < 3; d++) div[d] = (int)fmax(1, lround(slabs[k][1][d] / size));
        fdem_tet_mesh one = {0};
        if (fdem_tet_mesh_box(slabs[k][0], slabs[k][1], div, &one, err)) {
            fdem_tet_mesh_free(all);
            return -1;
        }
        double *xyz = realloc(all->xyz, sizeof(double) * 3 * (size_t)(all->node_count + one.node_count));
        if (xyz) all->xyz = xyz;
        int32_t *tet = realloc(all->tet, sizeof(int32_t) * 4 * (size_t)(all->tet_count + one.tet_count));
        if (tet) all->tet = tet;
        if (!xyz || !tet) {
            snprintf(err->message, sizeof err->message, "out of memory building the container");
            fdem_tet_mesh_free(&one);
            fdem_tet_mesh_free(all);
            return -1;
        }
        memcpy(all->xyz + 3 * all->node_count, one.xyz, sizeof(double) * 3 * (size_t)one.node_count);
        for (int i = 0; i < 4 * one.tet_count; i++)
            all->tet[4 * all->tet_count + i] = one.tet[i] + all->node_count;
        all->node_count += one.node_count;
        all->tet_count += one.tet_count;
        fdem_tet_mesh_free(&one);
    }
    return 0;
}

#endif /* FDEM_BUILD_CONTAINER_3D_H */
