/*
 * bench_partition.c - what a decomposition into 2-64 ranks costs on 1e6 and
 * 1e7 element meshes, for the parallel-efficiency model of docs/parallel.md
 * (issue 37 item 5). METIS k-way on the element dual graph (elements
 * sharing an edge in 2D, a face in 3D); then, with each node owned by the
 * part of its first element and the border of two parts split between
 * them, as the rank engine owns them (runner/mpi/rank_borders.h):
 *   halo    elements a part computes beside its own (they touch a node it
 *           owns), as a fraction of its own: the redundant work;
 *   bytes   what a part receives each step in a halo-only exchange of
 *           positions and velocities of the nodes its computed elements
 *           touch and others own (2 dim doubles a node); it sends about as
 *           much;
 *   time    METIS's CPU seconds (the dual graph's too, once per mesh).
 * Figures only. `bench_partition [elements]` (default 1e6; 1e7 when asked
 * and memory allows: run.sh asks).
 */
#include <metis.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fdem.h"
#include "math/clock.h"
#include "mesh/mesh_3d.h"
#include "../../runner/mpi/rank_borders.h"

/* Process CPU seconds: on a shared machine the wall time of METIS says
 * more about the neighbours than about METIS. */
static double now(void) { return clock_seconds_of(CLOCK_PROCESS_CPUTIME_ID); }

/* Halo and bytes of one partition (part per element). */
static void halo_figures(const int32_t *en, int ne, int K, int nn, int D, const idx_t *part,
                         int parts, double *halo_frac, double *halo_max, double *bytes_max,
                         double *bytes_mean)
{
    int32_t *owner = malloc(sizeof(int32_t) * (size_t)nn);
    int32_t *seen = malloc(sizeof(int32_t) * (size_t)nn); /* last part that counted the node */
    long *own = calloc((size_t)parts, sizeof(long)), *halo = calloc((size_t)parts, sizeof(long));
    long *need = calloc((size_t)parts, sizeof(long));
    for (int i = 0; i < nn; i++) owner[i] = -1, seen[i] = -1;
    for (int e = 0; e < ne; e++)
        for (int c = 0; c < K; c++)
            if (owner[en[(size_t)K * e + c]] < 0) owner[en[(size_t)K * e + c]] = (int32_t)part[e];
    int32_t *part32 = malloc(sizeof(int32_t) * (size_t)ne);
    for (int e = 0; e < ne; e++) part32[e] = (int32_t)part[e];
    rank_split_borders(en, ne, K, nn, part32, 1, parts, owner);
    free(part32);
    for (int e = 0; e < ne; e++) own[part[e]]++;
    /* per part p: the elements touching a node of p that are not p's */
    for (int p = 0; p < parts; p++) {
        for (int e = 0; e < ne; e++) {
            int touch = part[e] == p;
            for (int c = 0; c < K && !touch; c++) touch = owner[en[(size_t)K * e + c]] == p;
            if (!touch) continue;
            if (part[e] != p) halo[p]++;
            for (int c = 0; c < K; c++) {
                int32_t n = en[(size_t)K * e + c];
                if (owner[n] != p && seen[n] != p) seen[n] = p, need[p]++;
            }
        }
    }
    long halo_all = 0;
    double hmax = 0, bmax = 0, bsum = 0;
    for (int p = 0; p < parts; p++) {
        halo_all += halo[p];
        double h = own[p] ? (double)halo[p] / (double)own[p] : 0, b = 16.0 * D * (double)need[p];
        if (h > hmax) hmax = h;
        if (b > bmax) bmax = b;
        bsum += b;
    }
    *halo_frac = (double)halo_all / ne;
    *halo_max = hmax;
    *bytes_max = bmax;
    *bytes_mean = bsum / parts;
    free(owner), free(seen), free(own), free(halo), free(need);
}

static void bench_mesh(const char *name, const int32_t *en, int ne, int K, int nn, int D)
{
    idx_t e = ne, n = nn, common = D, numflag = 0, *xadj = NULL, *adj = NULL;
    idx_t *eptr = malloc(sizeof(idx_t) * ((size_t)ne + 1)), *eind = malloc(sizeof(idx_t) * (size_t)K * ne);
    for (int i = 0; i <= ne; i++) eptr[i] = (idx_t)K * i;
    for (size_t i = 0; i < (size_t)K * ne; i++) eind[i] = en[i];
    double t0 = now();
    if (METIS_MeshToDual(&e, &n, eptr, eind, &common, &numflag, &xadj, &adj) != METIS_OK) {
        printf("%s: METIS_MeshToDual failed\n", name);
        return;
    }
    printf("%s: %d elements, %d nodes, dual graph %.2f s cpu\n", name, ne, nn, now() - t0);
    printf("  %5s %11s %10s %10s %14s %14s\n", "parts", "metis_cpu_s", "halo_frac", "halo_max",
           "bytes_max/step", "bytes_mean/step");
    idx_t *part = malloc(sizeof(idx_t) * (size_t)ne), options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    for (idx_t parts = 2; parts <= 64; parts *= 2) {
        idx_t ncon = 1, cut = 0, np = parts;
        t0 = now();
        int rc = METIS_PartGraphKway(&e, &ncon, xadj, adj, NULL, NULL, NULL, &np, NULL, NULL,
                                     options, &cut, part);
        double secs = now() - t0;
        if (rc != METIS_OK) {
            printf("  %5d METIS failed\n", (int)parts);
            continue;
        }
        double hf, hm, bm, bmean;
        halo_figures(en, ne, K, nn, D, part, (int)parts, &hf, &hm, &bm, &bmean);
        printf("  %5d %11.2f %10.4f %10.4f %14.0f %14.0f\n", (int)parts, secs, hf, hm, bm, bmean);
        fflush(stdout);
    }
    METIS_Free(xadj);
    METIS_Free(adj);
    free(part), free(eptr), free(eind);
}

int main(int argc, char **argv)
{
    double want = argc > 1 ? atof(argv[1]) : 1e6;
    fdem_error err;
    int side = 1;
    while (2.0 * side * side < want) side++;
    fdem_mesh tri;
    if (fdem_mesh_rectangle(0, 0, 1, 1, side, side, &tri, &err) == 0) {
        char name[64];
        snprintf(name, sizeof name, "2D rectangle %dx%d", side, side);
        bench_mesh(name, tri.tri, tri.triangle_count, 3, tri.node_count, 2);
        fdem_mesh_free(&tri);
    }
    int cube = 1;
    while (6.0 * cube * cube * cube < want) cube++;
    fdem_tet_mesh tet;
    const double o[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    const int div[3] = {cube, cube, cube};
    if (want <= 2e6 && fdem_tet_mesh_box(o, s, div, &tet, &err) == 0) {
        char name[64];
        snprintf(name, sizeof name, "3D box %d^3 x 6", cube);
        bench_mesh(name, tet.tet, tet.tet_count, 4, tet.node_count, 3);
        fdem_tet_mesh_free(&tet);
    }
    return 0;
}
