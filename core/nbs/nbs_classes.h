/*
 * nbs_classes.h - contact detection that does not test what it can never
 * list: the elements of one body that holds most of them (a fracturing
 * body's intact piece) are never tested against each other, and on graded
 * meshes the elements go in size classes, each class on its own
 * Munjiza-NBS grid (nbs.c, nbs_3d.c) with its own cell size. Pairs between
 * two sets are found by looking one set's elements up in the other's cells.
 *
 * Contract:
 *  - The same pairs as nbs_detect / nbs_detect_3d (and so as the all-pairs
 *    reference) on the same circles or spheres and body ids: every pair
 *    (i, j), i != j, with |ci - cj| <= ri + rj and differing bodies, once.
 *  - A body id >= 0 held by more than half the valid elements is the bulk:
 *    the rest go on one grid, then each of them is looked up in the bulk's
 *    cells (used = 2).
 *  - Otherwise class k holds the radii in (rmax / 2^(k+1), rmax / 2^k] (the
 *    last class everything smaller). When one class would hold every
 *    element, or the classes would not pay by the cost estimate of
 *    nbs_classes.c, it is exactly one nbs_detect(_3d) call on the grid
 *    passed in: the same pairs in the same order, no memory of its own
 *    (used = 1).
 *  - With classes (used = their count) the pairs come class by class (each
 *    in its grid's order), then the pairs between classes, larger class by
 *    larger class, smaller element by element in class and index order.
 *    Every path is a pure function of the input, serial: the same list on
 *    any thread count and after a restore.
 *  - RAM O(n) (no array over nx * ny [* nz]); CPU O(n) for a given number
 *    of classes (at most NBS_CLASSES_MAX). Returns 0, or -1 when out of
 *    memory (pairs->count is then meaningless).
 */
#ifndef FDEM_NBS_CLASSES_H
#define FDEM_NBS_CLASSES_H

#include "nbs.h"

#define NBS_CLASSES_MAX 8

typedef struct nbs_classes {
    int32_t *member;          /* elements by class, class after class, index order */
    int32_t *cell_head;       /* hashed cells of one larger class (a power of two) */
    int32_t *cell_next;       /* per element of that class */
    double *sub;              /* one class's centres and radii gathered (4 per element) */
    int32_t *sub_body;        /* and its body ids */
    nbs_pairs sub_pairs;      /* one class's pairs in its own numbering */
    size_t n_capacity, head_capacity;
    int used;                 /* sets of the last detection: 1 one grid, 2 the bulk, or classes */
} nbs_classes;

void nbs_classes_init(nbs_classes *c);
void nbs_classes_free(nbs_classes *c);
size_t nbs_classes_memory_bytes(const nbs_classes *c);

int nbs_detect_classes(nbs_classes *c, nbs_grid *grid, size_t n, const double *cx,
                       const double *cy, const double *r, const int32_t *body,
                       nbs_pairs *pairs);
int nbs_detect_classes_3d(nbs_classes *c, nbs_grid_3d *grid, size_t n, const double *cx,
                          const double *cy, const double *cz, const double *r,
                          const int32_t *body, nbs_pairs *pairs);

#endif /* FDEM_NBS_CLASSES_H */
