/*
 * test_nbs_classes.c - detection in size classes (nbs_classes.h) must
 * return exactly the all-pairs reference's set on graded inputs in 2D and
 * 3D (sizes doubling from slab to slab, a few large circles among many
 * small ones, body ids, invalid circles), must really use its classes
 * there (or the test would pass on the one grid), must give the same list
 * in the same order when run again, and on a uniform input must be the
 * one grid's call: the same pairs in the same order, no memory of its own.
 * ~5e3 circles at most, so the reference stays fast under ASan.
 */
#include "check.h"
#include "nbs/nbs_classes.h"
#include "pair_sets.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct circles {
    int dim;
    size_t n, cap;
    double *p[3], *r;
    int32_t *body;
} circles;

static circles circles_new(int dim, size_t cap)
{
    circles s = {.dim = dim, .cap = cap};
    for (int a = 0; a < 3; a++) s.p[a] = calloc(cap, sizeof(double));
    s.r = calloc(cap, sizeof(double));
    s.body = calloc(cap, sizeof(int32_t));
    return s;
}

static void circles_free(circles *s)
{
    for (int a = 0; a < 3; a++) free(s->p[a]);
    free(s->r);
    free(s->body);
}

static void circles_add(circles *s, const double *x, double r, int32_t body)
{
    if (s->n == s->cap) return;
    for (int a = 0; a < 3; a++) s->p[a][s->n] = a < s->dim ? x[a] : 0.0;
    s->r[s->n] = r;
    s->body[s->n] = body;
    s->n++;
}

/* A graded mesh's bounding circles: slab k (x in [k, k+1)) holds jittered
 * points h0 2^k apart with radii 0.55 .. 0.85 of that spacing, so
 * neighbours overlap as a mesh's do and each slab is about one class. */
static circles graded(int dim, double h0, int slabs)
{
    circles s = circles_new(dim, 20000);
    for (int k = 0; k < slabs; k++) {
        double h = h0 * pow(2.0, k);
        int across = (int)floor(1.0 / h + 0.5);
        int ny = across, nz = dim == 3 ? across : 1;
        for (int i = 0; i < across; i++)
            for (int j = 0; j < ny; j++)
                for (int l = 0; l < nz; l++) {
                    double x[3] = {k + (i + rng_range(0.2, 0.8)) * h, (j + rng_range(0.2, 0.8)) * h,
                                   (l + rng_range(0.2, 0.8)) * h};
                    circles_add(&s, x, h * rng_range(0.55, 0.85), -1);
                }
    }
    return s;
}

static void detect(nbs_classes *c, nbs_grid *g2, nbs_grid_3d *g3, const circles *s,
                   const int32_t *body, nbs_pairs *out)
{
    int rc = s->dim == 3 ? nbs_detect_classes_3d(c, g3, s->n, s->p[0], s->p[1], s->p[2], s->r,
                                                 body, out)
                         : nbs_detect_classes(c, g2, s->n, s->p[0], s->p[1], s->r, body, out);
    CHECK(rc == 0, "dim %d: detection failed", s->dim);
}

static void brute(const circles *s, const int32_t *body, nbs_pairs *out)
{
    int rc = s->dim == 3 ? nbs_detect_brute_3d(s->n, s->p[0], s->p[1], s->p[2], s->r, body, out)
                         : nbs_detect_brute(s->n, s->p[0], s->p[1], s->r, body, out);
    CHECK(rc == 0, "dim %d: reference failed", s->dim);
}

static int same_list(const nbs_pairs *x, const nbs_pairs *y)
{
    return x->count == y->count && !memcmp(x->a, y->a, x->count * sizeof *x->a) &&
           !memcmp(x->b, y->b, x->count * sizeof *x->b);
}

/* The classes' set against the reference's, with and without bodies; the
 * classes used; a second run on fresh grids gives the same list. */
static void check_graded(const char *what, const circles *s, int min_classes)
{
    nbs_classes c, c2;
    nbs_grid g2, h2;
    nbs_grid_3d g3, h3;
    nbs_pairs got, again, want;
    nbs_classes_init(&c), nbs_classes_init(&c2);
    nbs_grid_init(&g2), nbs_grid_init(&h2), nbs_grid_3d_init(&g3), nbs_grid_3d_init(&h3);
    nbs_pairs_init(&got), nbs_pairs_init(&again), nbs_pairs_init(&want);
    for (int with_body = 0; with_body < 2; with_body++) {
        const int32_t *body = with_body ? s->body : NULL;
        detect(&c, &g2, &g3, s, body, &got);
        brute(s, body, &want);
        check_same_pairs(what, &got, &want);
        CHECK(c.used >= min_classes, "%s: %d classes used, want >= %d", what, c.used,
              min_classes);
        CHECK(2 * want.count > s->n, "%s: only %zu pairs for %zu circles", what, want.count, s->n);
        detect(&c2, &h2, &h3, s, body, &again);
        CHECK(same_list(&got, &again), "%s: a second detection gave another list", what);
    }
    nbs_classes_free(&c), nbs_classes_free(&c2);
    nbs_grid_free(&g2), nbs_grid_free(&h2), nbs_grid_3d_free(&g3), nbs_grid_3d_free(&h3);
    nbs_pairs_free(&got), nbs_pairs_free(&again), nbs_pairs_free(&want);
}

/* Bodies: stripes across the slabs, so pairs of one body are met within a
 * class and between classes alike. */
static void stripe_bodies(circles *s)
{
    for (size_t i = 0; i < s->n; i++) {
        double y = s->p[1][i];
        s->body[i] = isfinite(y) && fabs(y) < 1e3 ? (int32_t)floor(y * 5.0) - 1 : -1;
    }
}

static void test_classes_graded_2d(void)
{
    rng_seed(21);
    circles s = graded(2, 1.0 / 48, 5);
    stripe_bodies(&s);
    check_graded("graded 2d", &s, 4);
    circles_free(&s);
}

static void test_classes_graded_3d(void)
{
    rng_seed(31);
    circles s = graded(3, 1.0 / 12, 4);
    stripe_bodies(&s);
    check_graded("graded 3d", &s, 3);
    circles_free(&s);
}

/* A few large circles (platens, a coarse far field) among many small
 * ones, and circles that take no part: NaN, infinite, negative. */
static void test_classes_few_large_and_invalid(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        rng_seed(40 + (uint64_t)dim);
        circles s = graded(dim, dim == 3 ? 1.0 / 12 : 1.0 / 48, 1);
        for (int k = 0; k < 6; k++) {
            double x[3] = {rng_range(-0.3, 1.3), rng_range(-0.3, 1.3), rng_range(-0.3, 1.3)};
            circles_add(&s, x, rng_range(0.2, 0.6), -1);
        }
        double bad[3] = {0.5, 0.5, 0.5};
        circles_add(&s, bad, NAN, -1);
        circles_add(&s, bad, -0.1, -1);
        circles_add(&s, bad, INFINITY, -1);
        bad[1] = NAN;
        circles_add(&s, bad, 0.1, -1);
        stripe_bodies(&s);
        check_graded(dim == 3 ? "few large 3d" : "few large 2d", &s, 2);
        circles_free(&s);
    }
}

/* One body holding most elements (a fracturing body's intact piece), the
 * rest each their own (the elements along its cracks) or another piece:
 * the bulk's pairs are never listed, and never tested. */
static void test_classes_bulk_body(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        rng_seed(60 + (uint64_t)dim);
        circles s = graded(dim, dim == 3 ? 1.0 / 12 : 1.0 / 40, 2);
        for (size_t i = 0; i < s.n; i++) {
            double y = s.p[1][i];
            s.body[i] = fabs(y - 0.5) < 0.1 ? (int32_t)(100 + i) : (y > 0.9 ? 5 : 7);
        }
        double bad[3] = {0.5, 0.5, 0.5};
        circles_add(&s, bad, NAN, 7);
        circles_add(&s, bad, 0.2, 9);
        check_graded(dim == 3 ? "bulk 3d" : "bulk 2d", &s, 2);
        circles_free(&s);
    }
}

/* Radii within a factor of 2: one grid, exactly its call. */
static void test_classes_uniform_is_one_grid(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        rng_seed(50 + (uint64_t)dim);
        circles s = graded(dim, dim == 3 ? 1.0 / 10 : 1.0 / 40, 1);
        nbs_classes c;
        nbs_grid g2, h2;
        nbs_grid_3d g3, h3;
        nbs_pairs got, want;
        nbs_classes_init(&c);
        nbs_grid_init(&g2), nbs_grid_init(&h2), nbs_grid_3d_init(&g3), nbs_grid_3d_init(&h3);
        nbs_pairs_init(&got), nbs_pairs_init(&want);
        detect(&c, &g2, &g3, &s, s.body, &got);
        int rc = dim == 3 ? nbs_detect_3d(&h3, s.n, s.p[0], s.p[1], s.p[2], s.r, s.body, &want)
                          : nbs_detect(&h2, s.n, s.p[0], s.p[1], s.r, s.body, &want);
        CHECK(rc == 0 && want.count > s.n, "dim %d: one grid: %zu pairs", dim, want.count);
        CHECK(c.used == 1, "dim %d: %d classes on a uniform input", dim, c.used);
        CHECK(same_list(&got, &want), "dim %d: not the one grid's list", dim);
        CHECK(nbs_classes_memory_bytes(&c) == 0, "dim %d: %zu bytes of classes", dim,
              nbs_classes_memory_bytes(&c));
        nbs_classes_free(&c);
        nbs_grid_free(&g2), nbs_grid_free(&h2), nbs_grid_3d_free(&g3), nbs_grid_3d_free(&h3);
        nbs_pairs_free(&got), nbs_pairs_free(&want);
        circles_free(&s);
    }
}

CHECK_MAIN(T(test_classes_graded_2d), T(test_classes_graded_3d),
           T(test_classes_few_large_and_invalid), T(test_classes_bulk_body),
           T(test_classes_uniform_is_one_grid))
