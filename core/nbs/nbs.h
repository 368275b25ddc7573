/*
 * nbs.h - Munjiza-NBS contact detection in 2D (Munjiza 2004, ch. 3.7-3.11;
 * seed pages 124 and 145).
 *
 * Contract:
 *  - Input: n bounding circles (centres cx, cy and radii r) and an optional
 *    body id per circle. Output: every unordered pair (i, j), i != j, whose
 *    circles overlap or touch (|ci - cj| <= ri + rj) and whose body ids
 *    differ (pairs with equal body id >= 0 are skipped; pass NULL to keep all).
 *    The pairs are exactly those an all-pairs test of the same circles finds;
 *    their order is unspecified.
 *  - Cell size d = the largest diameter. Elements are mapped to rows
 *    (integerised y) in singly connected lists held in two integer arrays
 *    (heads B[ny], next Y[n]); only non-empty rows are visited, by looping
 *    over elements; each new row's elements go into cell lists (heads A[nx],
 *    next X[n]) and are tested against the neighbouring cells of the contact
 *    mask; the lists are then cleared by looping over the same elements
 *    (row heads as soon as no row can need them any more).
 *  - RAM is O(n + nx + ny) and never O(nx * ny); nx and ny are folded
 *    (integer coordinate modulo a table size of O(n)) so that two bodies a
 *    kilometre apart cost no more memory than two touching. Folding only
 *    adds candidates, which the circle test removes: the result is exact.
 *  - CPU is O(n) per detection. No allocation after the arrays reach their
 *    high-water mark.
 */
#ifndef FDEM_NBS_H
#define FDEM_NBS_H

#include <stddef.h>
#include <stdint.h>

/* A pair list's first capacity (it grows by doubling): the memory estimate
 * prices it for every model with contact. */
#define NBS_FIRST_PAIRS 1024

typedef struct nbs_pairs {
    int32_t *a, *b;   /* pair k is (a[k], b[k]) */
    size_t count, capacity;
} nbs_pairs;

typedef struct nbs_grid {
    /* integer arrays of the book: rows B (heads) / Y (next), cells A / X */
    int32_t *row_head, *row_next;
    int32_t *cell_head, *cell_next;
    int32_t *ix, *iy;          /* integerised (folded) coordinates per circle */
    int32_t *order;            /* the circles of the rows in the cell tables, gathered */
    size_t n_capacity;         /* capacity of per-circle arrays */
    size_t nx_capacity, ny_capacity;
    int32_t nx, ny;            /* folded table sizes of the last detection */
    double cell;               /* cell size d of the last detection */
} nbs_grid;

void nbs_grid_init(nbs_grid *grid);
void nbs_grid_free(nbs_grid *grid);
void nbs_pairs_init(nbs_pairs *pairs);
void nbs_pairs_free(nbs_pairs *pairs);
/* Room for `want` pairs (capacity doubles); 0, or -1 out of memory. */
int nbs_pairs_reserve(nbs_pairs *pairs, size_t want);

/* Finds all overlapping pairs; pairs->count is reset first. Returns 0, or -1
 * on allocation failure. body may be NULL. */
int nbs_detect(nbs_grid *grid, size_t n, const double *cx, const double *cy,
               const double *r, const int32_t *body, nbs_pairs *pairs);

/* The reference: all-pairs O(n^2) test with the same rules (for tests and
 * the bench baseline). */
int nbs_detect_brute(size_t n, const double *cx, const double *cy,
                     const double *r, const int32_t *body, nbs_pairs *pairs);

/* Bytes held by the grid and pair arrays. */
size_t nbs_memory_bytes(const nbs_grid *grid, const nbs_pairs *pairs);

/* ------------------------------------------------------------------- 3D */
/*
 * nbs_3d.c - the same detection for bounding spheres (seed page 145):
 *  - pairs (i, j) with |ci - cj| <= ri + rj and differing body ids (body may
 *    be NULL), exactly those of nbs_detect_brute_3d; order unspecified.
 *  - Elements are mapped to z-layers (heads nz, next N); each new layer and
 *    the layer below it (its contact-mask neighbour) to y-lists (two sets of
 *    ny heads, next N); each new row and the row below it to x-lists (two
 *    sets of nx heads, next N); the rows of the layer below are walked
 *    against the row's x-lists. Only non-empty layers and rows are visited,
 *    by looping over elements; lists are cleared the same way.
 *  - Integer RAM is exactly 3N + nz + 2nx + 2ny (nbs_integers_3d) plus the
 *    pair list: no integer coordinates are stored beside the lists (an
 *    element's x waits in its x-link while that link is unused), they are
 *    recomputed. Beside the integers the grid keeps a packed copy of the
 *    spheres, 32 B each (nbs_memory_bytes_3d counts it): a candidate is one
 *    cache line instead of four.
 *    Axes are folded like the 2D ones, so RAM is O(N) whatever the extent
 *    and never O(nx * ny * nz).
 */
/* An element's next in its y- and x-list, side by side. As two arrays of
 * N int32 (both page aligned once N is large) a store to one list and the
 * following load from the other share their offset in the page, and the
 * load waits as if the two aliased: 6 % of a detection at density 1, 10-18 %
 * of a sparse one (1e5 and 1e6 spheres, bench_nbs 3d). */
typedef struct nbs_next_3d {
    int32_t row, cell;
} nbs_next_3d;

typedef struct nbs_grid_3d {
    int32_t *layer_head, *layer_next; /* z: nz heads, N next */
    int32_t *row_head;                /* y: 2 sets of ny heads */
    int32_t *cell_head;               /* x: 2 sets of nx heads */
    nbs_next_3d *next;                /* y and x: N next each */
    double *sphere;                   /* N packed (x, y, z, r), 32-byte aligned */
    size_t n_capacity, nx_capacity, ny_capacity, nz_capacity;
    int32_t nx, ny, nz;               /* table sizes of the last detection */
    double cell;                      /* cell size d of the last detection */
} nbs_grid_3d;

void nbs_grid_3d_init(nbs_grid_3d *grid);
void nbs_grid_3d_free(nbs_grid_3d *grid);

/* Finds all overlapping sphere pairs; pairs->count is reset first. Returns
 * 0, or -1 on allocation failure. body may be NULL. */
int nbs_detect_3d(nbs_grid_3d *grid, size_t n, const double *cx, const double *cy,
                  const double *cz, const double *r, const int32_t *body, nbs_pairs *pairs);

/* All-pairs reference with the same rules. */
int nbs_detect_brute_3d(size_t n, const double *cx, const double *cy, const double *cz,
                        const double *r, const int32_t *body, nbs_pairs *pairs);

/* Integers the grid holds: 3 n_capacity + nz + 2 nx + 2 ny (capacities). */
size_t nbs_integers_3d(const nbs_grid_3d *grid);

/* Bytes held by the grid and pair arrays. */
size_t nbs_memory_bytes_3d(const nbs_grid_3d *grid, const nbs_pairs *pairs);

#endif /* FDEM_NBS_H */
