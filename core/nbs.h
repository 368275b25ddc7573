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

#endif /* FDEM_NBS_H */
