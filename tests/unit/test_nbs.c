/*
 * test_nbs.c - Munjiza-NBS contact detection must return exactly the pair
 * set of the all-pairs reference (as sets: no duplicates, no self pairs) on
 * random, clustered, sparse, lattice, far-apart and degenerate inputs, and
 * its memory must not depend on how far apart the bodies are.
 *
 * Up to ~3e3 circles the reference is nbs_detect_brute; at 1e5 it is an
 * independent sort-by-x sweep written here, so the test stays fast under
 * ASan. Every comparison is exact (same circle test, same doubles).
 */
#include "check.h"
#include "nbs/nbs.h"
#include "pair_sets.h"

#include <stdint.h>
#include <stdlib.h>

/* ------------------------------------------------------------------ inputs */

typedef struct circles {
    size_t n;
    double *x, *y, *r;
    int32_t *body;
} circles;

static circles circles_new(size_t n)
{
    circles c = {n, calloc(n + 1, sizeof(double)), calloc(n + 1, sizeof(double)),
                 calloc(n + 1, sizeof(double)), calloc(n + 1, sizeof(int32_t))};
    return c;
}

static void circles_free(circles *c)
{
    free(c->x);
    free(c->y);
    free(c->r);
    free(c->body);
}


/* uniform centres in [x0, x0 + w] x [y0, y0 + h], radii in [rlo, rhi] */
static void fill_uniform(circles *c, size_t from, size_t to, double x0, double y0,
                         double w, double h, double rlo, double rhi)
{
    for (size_t i = from; i < to; i++) {
        c->x[i] = x0 + rng_range(0, w);
        c->y[i] = y0 + rng_range(0, h);
        c->r[i] = rng_range(rlo, rhi);
        c->body[i] = -1;
    }
}

/* offset-row (triangular) lattice with spacing 2 * r0: neighbours touch */
static void fill_lattice(circles *c, int cols, int rows, double x0, double y0,
                         double r0, double radius)
{
    size_t i = 0;
    for (int row = 0; row < rows; row++)
        for (int col = 0; col < cols; col++, i++) {
            c->x[i] = x0 + 2.0 * r0 * (col + 0.5 * (row & 1));
            c->y[i] = y0 + 2.0 * r0 * row * (sqrt(3.0) / 2.0);
            c->r[i] = radius;
            c->body[i] = -1;
        }
}

static void shuffle(circles *c)
{
    for (size_t i = c->n; i > 1; i--) {
        size_t j = (size_t)(rng_uniform() * (double)i);
        if (j >= i) j = i - 1;
        double t;
        t = c->x[i - 1]; c->x[i - 1] = c->x[j]; c->x[j] = t;
        t = c->y[i - 1]; c->y[i - 1] = c->y[j]; c->y[j] = t;
        t = c->r[i - 1]; c->r[i - 1] = c->r[j]; c->r[j] = t;
        int32_t b = c->body[i - 1]; c->body[i - 1] = c->body[j]; c->body[j] = b;
    }
}

/* The lists are cleared by looping over elements, so after a detection every
 * head must be empty again: rows over the whole table, and both cell tables
 * (this row and the row below, nx + 2 slots each with their guards). A stale
 * head would corrupt the next detection through the same grid. */
static void check_grid_clean(const char *what, const nbs_grid *grid)
{
    size_t stale = 0;
    for (size_t k = 0; k < grid->ny_capacity; k++) stale += grid->row_head[k] != -1;
    for (size_t k = 0; grid->nx > 0 && k < 2 * ((size_t)grid->nx + 2); k++)
        stale += grid->cell_head[k] != -1;
    CHECK(stale == 0, "%s: %zu list heads left non-empty", what, stale);
}

/* NBS against brute force on c; returns the pair count for further checks. */
static size_t check_against_brute(const char *what, const circles *c, int use_body)
{
    nbs_grid grid;
    nbs_pairs got, want;
    nbs_grid_init(&grid);
    nbs_pairs_init(&got);
    nbs_pairs_init(&want);
    const int32_t *body = use_body ? c->body : NULL;
    CHECK(nbs_detect(&grid, c->n, c->x, c->y, c->r, body, &got) == 0, "%s: nbs_detect failed", what);
    check_grid_clean(what, &grid);
    CHECK(nbs_detect_brute(c->n, c->x, c->y, c->r, body, &want) == 0, "%s: brute failed", what);
    check_same_pairs(what, &got, &want);
    size_t count = got.count;
    nbs_grid_free(&grid);
    nbs_pairs_free(&got);
    nbs_pairs_free(&want);
    return count;
}

/* ------------------------------------------- independent sweep reference */

static const circles *sweep_input;

static int cmp_by_x(const void *a, const void *b)
{
    double x = sweep_input->x[*(const int32_t *)a], y = sweep_input->x[*(const int32_t *)b];
    return (x > y) - (x < y);
}

/* Same circle test as nbs.c, written out again on purpose (split statements:
 * no FMA contraction). */
static int touch(const circles *c, int32_t i, int32_t j)
{
    double dx = c->x[i] - c->x[j];
    double dy = c->y[i] - c->y[j];
    double reach = c->r[i] + c->r[j];
    double dx2 = dx * dx;
    double dy2 = dy * dy;
    double dist2 = dx2 + dy2;
    double reach2 = reach * reach;
    return dist2 <= reach2;
}

/* Sort by x, then sweep each circle forward while the x gap can still be
 * bridged by r_i + rmax (padded by 1e-9 relative, far above rounding). */
static void sweep_pairs(const circles *c, nbs_pairs *out)
{
    int32_t *order = malloc(c->n * sizeof *order);
    double rmax = 0;
    for (size_t i = 0; i < c->n; i++) {
        order[i] = (int32_t)i;
        if (c->r[i] > rmax) rmax = c->r[i];
    }
    sweep_input = c;
    qsort(order, c->n, sizeof *order, cmp_by_x);
    out->count = 0;
    for (size_t s = 0; s < c->n; s++) {
        int32_t i = order[s];
        double reach = (c->r[i] + rmax) * (1 + 1e-9);
        for (size_t t = s + 1; t < c->n && c->x[order[t]] - c->x[i] <= reach; t++) {
            int32_t j = order[t];
            if (!touch(c, i, j)) continue;
            if (out->count == out->capacity) {
                out->capacity = out->capacity ? 2 * out->capacity : 1024;
                out->a = realloc(out->a, out->capacity * sizeof *out->a);
                out->b = realloc(out->b, out->capacity * sizeof *out->b);
            }
            out->a[out->count] = i;
            out->b[out->count] = j;
            out->count++;
        }
    }
    free(order);
}

static size_t check_against_sweep(const char *what, const circles *c)
{
    nbs_grid grid;
    nbs_pairs got, want;
    nbs_grid_init(&grid);
    nbs_pairs_init(&got);
    nbs_pairs_init(&want);
    CHECK(nbs_detect(&grid, c->n, c->x, c->y, c->r, NULL, &got) == 0, "%s: nbs_detect failed", what);
    check_grid_clean(what, &grid);
    sweep_pairs(c, &want);
    check_same_pairs(what, &got, &want);
    size_t count = got.count;
    nbs_grid_free(&grid);
    nbs_pairs_free(&got);
    nbs_pairs_free(&want);
    return count;
}

/* ------------------------------------------------------------------ tests */

static void test_nbs_tiny_inputs(void)
{
    nbs_grid grid;
    nbs_pairs p;
    nbs_grid_init(&grid);
    nbs_pairs_init(&p);
    double x[3] = {0.0, 1.0, 2.5}, y[3] = {0.0, 0.0, 0.0}, r[3] = {0.5, 0.5, 0.5};

    CHECK(nbs_detect(&grid, 0, x, y, r, NULL, &p) == 0 && p.count == 0, "n = 0: %zu pairs", p.count);
    CHECK(nbs_detect(&grid, 1, x, y, r, NULL, &p) == 0 && p.count == 0, "n = 1: %zu pairs", p.count);
    /* centres 1 apart, radii 0.5 + 0.5: exactly touching counts */
    CHECK(nbs_detect(&grid, 2, x, y, r, NULL, &p) == 0 && p.count == 1, "touching: %zu pairs", p.count);
    /* the third circle is 0.5 away from touching the second */
    CHECK(nbs_detect(&grid, 3, x, y, r, NULL, &p) == 0 && p.count == 1, "gap: %zu pairs", p.count);
    r[2] = 1.0;
    CHECK(nbs_detect(&grid, 3, x, y, r, NULL, &p) == 0 && p.count == 2, "reach: %zu pairs", p.count);
    if (p.count == 2)
        CHECK((p.a[1] == 1 && p.b[1] == 2) || (p.a[1] == 2 && p.b[1] == 1) ||
              (p.a[0] == 1 && p.b[0] == 2) || (p.a[0] == 2 && p.b[0] == 1),
              "pair (1,2) missing: (%d,%d) (%d,%d)", p.a[0], p.b[0], p.a[1], p.b[1]);
    nbs_grid_free(&grid);
    nbs_pairs_free(&p);
}

static void test_nbs_random_matches_brute(void)
{
    static const size_t sizes[] = {10, 100, 1000, 3000};
    rng_seed(1);
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        size_t n = sizes[s];
        circles c = circles_new(n);
        /* about one circle per cell of the largest diameter, radii vary x10 */
        double side = sqrt((double)n) * 1.0;
        fill_uniform(&c, 0, n, 0, 0, side, side, 0.05, 0.5);
        char what[64];
        snprintf(what, sizeof what, "random n=%zu", n);
        size_t found = check_against_brute(what, &c, 0);
        CHECK(n < 100 || found > n / 4, "%s: only %zu pairs, input too sparse to test", what, found);
        circles_free(&c);
    }
}

static void test_nbs_clustered_matches_brute(void)
{
    rng_seed(2);
    size_t n = 3000;
    circles c = circles_new(n);
    /* five dense blobs, each 0.5 wide, with radii up to 0.02: ~15 per cell */
    for (int blob = 0; blob < 5; blob++) {
        double bx = rng_range(-50, 50), by = rng_range(-50, 50);
        fill_uniform(&c, blob * n / 5, (blob + 1) * n / 5, bx, by, 0.5, 0.5, 0.001, 0.02);
    }
    size_t found = check_against_brute("clustered", &c, 0);
    CHECK(found > n, "clustered: only %zu pairs", found);
    circles_free(&c);
}

static void test_nbs_sparse_matches_brute(void)
{
    rng_seed(3);
    size_t n = 2000;
    circles c = circles_new(n);
    /* one circle per 1e4 cells (cell = 1): side = 100 * sqrt(n) */
    double side = 100.0 * sqrt((double)n);
    fill_uniform(&c, 0, n, -side / 2, -side / 2, side, side, 0.25, 0.5);
    /* every 4th circle gets a partner that overlaps it, so there is something to find */
    for (size_t i = 0; i + 1 < n; i += 4) {
        double angle = rng_range(0, 6.283185307179586);
        double dist = (c.r[i] + c.r[i + 1]) * rng_range(0.5, 0.999);
        c.x[i + 1] = c.x[i] + dist * cos(angle);
        c.y[i + 1] = c.y[i] + dist * sin(angle);
    }
    size_t found = check_against_brute("sparse", &c, 0);
    CHECK(found >= n / 4, "sparse: %zu pairs, want >= %zu planted", found, n / 4);
    circles_free(&c);
}

/* W x H offset-row lattice: H(W-1) pairs within rows + (H-1)(2W-1) between. */
static size_t lattice_pairs(int cols, int rows)
{
    return (size_t)rows * (cols - 1) + (size_t)(rows - 1) * (2 * cols - 1);
}

static void test_nbs_lattice_touching(void)
{
    rng_seed(4);
    int cols = 40, rows = 50;
    circles c = circles_new((size_t)cols * rows);
    /* exactly touching (the borderline for rounding): same set as brute */
    fill_lattice(&c, cols, rows, 0, 0, 0.5, 0.5);
    size_t exact = check_against_brute("lattice touching", &c, 0);
    CHECK(exact >= (size_t)rows * (cols - 1), "lattice touching: %zu pairs, want at least the %zu in-row contacts",
          exact, (size_t)rows * (cols - 1));
    /* radii 1e-9 larger: every lattice neighbour touches, a known count */
    fill_lattice(&c, cols, rows, 0, 0, 0.5, 0.5 * (1 + 1e-9));
    size_t inflated = check_against_brute("lattice inflated", &c, 0);
    CHECK(inflated == lattice_pairs(cols, rows), "lattice inflated: %zu pairs, want %zu",
          inflated, lattice_pairs(cols, rows));
    /* the same far from the origin with millimetre circles, in shuffled order */
    fill_lattice(&c, cols, rows, -1e6, 1e6, 0.0005, 0.0005 * (1 + 1e-6));
    shuffle(&c);
    size_t far = check_against_brute("lattice at 1e6 m", &c, 0);
    CHECK(far == lattice_pairs(cols, rows), "lattice at 1e6 m: %zu pairs, want %zu",
          far, lattice_pairs(cols, rows));
    circles_free(&c);
}

/* Touching pairs whose integerised x, unpadded, would land two cells apart:
 * (x - xmin) rounds down for one circle and up for the other. Found by a
 * search over d = 2r not commensurate with the ulp of x - xmin. */
static void test_nbs_rounding_at_cell_edges(void)
{
    static const double cases[][3] = {/* r, xi, xj */
        {0.43843939722600284, 3204.890540811867, 3205.767419606319},
        {0.5952419006512909, 10718.75516643622, 10719.945650237521},
        {0.72859407543205, 26042.48664636385, 26043.943834514714},
    };
    for (int k = 0; k < 3; k++) {
        circles c = circles_new(3);
        c.x[0] = cases[k][1]; c.x[1] = cases[k][2]; c.x[2] = -12345.678; /* sets xmin */
        c.r[0] = c.r[1] = cases[k][0];
        c.r[2] = 0.01;
        c.body[0] = c.body[1] = c.body[2] = -1;
        char what[64];
        snprintf(what, sizeof what, "cell edge case %d", k);
        size_t found = check_against_brute(what, &c, 0);
        CHECK(found == 1, "%s: %zu pairs, want the 1 touching pair", what, found);
        circles_free(&c);
    }
}

static void test_nbs_negative_coordinates(void)
{
    rng_seed(5);
    size_t n = 1500;
    circles c = circles_new(n);
    /* straddles zero and lies wholly below it: floor(-0.3) must be -1, not 0 */
    fill_uniform(&c, 0, n / 2, -20, -20, 40, 40, 0.1, 0.6);
    fill_uniform(&c, n / 2, n, -1030, -2050, 30, 30, 0.1, 0.6);
    size_t found = check_against_brute("negative coordinates", &c, 0);
    CHECK(found > n / 4, "negative coordinates: only %zu pairs", found);
    circles_free(&c);
}

static void test_nbs_bodies_km_apart(void)
{
    rng_seed(6);
    size_t n = 1200;
    circles c = circles_new(n);
    /* three blobs of 0.1 m circles on a line 1 km apart and one 1000 km
     * away: the real extent is ~1e7 cells, folded onto a 2048-slot table */
    fill_uniform(&c, 0, 300, 0, 0, 3, 3, 0.05, 0.1);
    fill_uniform(&c, 300, 600, 1000, 0, 3, 3, 0.05, 0.1);
    fill_uniform(&c, 600, 900, -1000, 1000, 3, 3, 0.05, 0.1);
    fill_uniform(&c, 900, 1200, 1e6, -1e6, 3, 3, 0.05, 0.1);
    size_t found = check_against_brute("km apart", &c, 0);
    CHECK(found > n, "km apart: only %zu pairs", found);

    nbs_grid grid;
    nbs_pairs p;
    nbs_grid_init(&grid);
    nbs_pairs_init(&p);
    CHECK(nbs_detect(&grid, n, c.x, c.y, c.r, NULL, &p) == 0, "km apart: detect failed");
    CHECK(grid.nx <= 2048 && grid.ny <= 2048, "km apart: tables %d x %d not folded", grid.nx, grid.ny);
    nbs_grid_free(&grid);
    nbs_pairs_free(&p);
    circles_free(&c);
}

/* Few circles over a huge extent fold onto tiny tables (4 or 8 slots): many
 * distant circles share a slot, and pairs must still be met exactly once. */
static void test_nbs_folding_stress(void)
{
    rng_seed(7);
    for (int trial = 0; trial < 300; trial++) {
        size_t n = 2 + (size_t)(rng_uniform() * 30);
        circles c = circles_new(n);
        double extent = trial % 2 ? 60.0 : 1e5;
        /* integer-ish cells with unit circles: neighbours on every side */
        for (size_t i = 0; i < n; i++) {
            c.x[i] = floor(rng_range(0, extent)) + rng_range(0, 1);
            c.y[i] = floor(rng_range(0, extent)) + rng_range(0, 1);
            c.r[i] = rng_range(0.3, 0.5);
            c.body[i] = -1;
        }
        /* half the circles get a neighbour in one of the 8 surrounding cells */
        for (size_t i = 0; i + 1 < n; i += 2) {
            c.x[i + 1] = c.x[i] + rng_range(-0.9, 0.9);
            c.y[i + 1] = c.y[i] + rng_range(-0.9, 0.9);
        }
        char what[64];
        snprintf(what, sizeof what, "folding trial %d n=%zu", trial, n);
        check_against_brute(what, &c, 0);
        circles_free(&c);
    }
}

static void test_nbs_body_filter(void)
{
    /* 40 circles on one spot: every pair overlaps; ids 0..3 and -1 */
    size_t n = 40;
    circles c = circles_new(n);
    size_t per_body[4] = {0};
    size_t unowned = 0;
    for (size_t i = 0; i < n; i++) {
        c.x[i] = 3.0 + 1e-3 * (double)(i % 7);
        c.y[i] = -2.0 + 1e-3 * (double)(i % 5);
        c.r[i] = 0.1;
        c.body[i] = i % 5 == 4 ? -1 : (int32_t)(i % 5);
        if (c.body[i] >= 0) per_body[c.body[i]]++; else unowned++;
    }
    size_t want = n * (n - 1) / 2;
    for (int b = 0; b < 4; b++) want -= per_body[b] * (per_body[b] - 1) / 2;
    size_t found = check_against_brute("body filter", &c, 1);
    CHECK(found == want, "body filter: %zu pairs, want %zu (unowned %zu)", found, want, unowned);
    size_t all = check_against_brute("body NULL", &c, 0);
    CHECK(all == n * (n - 1) / 2, "body NULL: %zu pairs, want %zu", all, n * (n - 1) / 2);

    /* a random mix with many bodies */
    rng_seed(8);
    circles m = circles_new(2000);
    fill_uniform(&m, 0, 2000, 0, 0, 30, 30, 0.1, 0.5);
    for (size_t i = 0; i < 2000; i++) m.body[i] = (int32_t)(i / 10) - 3;
    check_against_brute("body mix", &m, 1);
    circles_free(&m);
    circles_free(&c);
}

static void test_nbs_degenerate(void)
{
    rng_seed(9);
    /* all in one cell: one big circle sets d, 500 tiny ones inside it */
    circles c = circles_new(501);
    fill_uniform(&c, 0, 500, 10, 10, 1, 1, 0.001, 0.02);
    c.x[500] = 10.5; c.y[500] = 10.5; c.r[500] = 5.0;
    size_t found = check_against_brute("one cell", &c, 0);
    CHECK(found >= 500, "one cell: %zu pairs, the big circle alone touches 500", found);
    circles_free(&c);

    /* zero radius: only coincident centres touch (10 groups of 5) */
    circles z = circles_new(50);
    for (size_t i = 0; i < 50; i++) {
        z.x[i] = (double)(i % 10) * 0.37;
        z.y[i] = -(double)(i % 10) * 1.1;
        z.r[i] = 0.0;
        z.body[i] = -1;
    }
    found = check_against_brute("zero radius", &z, 0);
    CHECK(found == 10 * 10, "zero radius: %zu pairs, want 100", found);
    /* all on one point */
    for (size_t i = 0; i < 50; i++) { z.x[i] = 1e6; z.y[i] = -1e6; }
    found = check_against_brute("one point", &z, 0);
    CHECK(found == 50 * 49 / 2, "one point: %zu pairs, want 1225", found);
    circles_free(&z);

    /* invalid circles take no part and do not disturb the others */
    circles v = circles_new(200);
    fill_uniform(&v, 0, 200, 0, 0, 10, 10, 0.2, 0.5);
    v.x[3] = NAN;
    v.y[7] = INFINITY;
    v.r[11] = -1.0;
    v.r[13] = NAN;
    v.x[17] = 1e300;
    size_t with_bad = check_against_brute("invalid circles", &v, 0);
    CHECK(with_bad > 50, "invalid circles: only %zu pairs", with_bad);
    circles_free(&v);
}

static void test_nbs_large_against_sweep(void)
{
    rng_seed(10);
    size_t n = 100000;
    circles c = circles_new(n);
    double side = sqrt((double)n);
    fill_uniform(&c, 0, n, -side / 2, 100, side, side, 0.1, 0.5);
    size_t found = check_against_sweep("random 1e5", &c);
    CHECK(found > n / 2, "random 1e5: only %zu pairs", found);

    /* a 1e5 lattice (316 x 316), inflated radii, shuffled */
    int cols = 316, rows = 316;
    circles l = circles_new((size_t)cols * rows);
    fill_lattice(&l, cols, rows, 5.0, -7.0, 0.5, 0.5 * (1 + 1e-9));
    shuffle(&l);
    found = check_against_sweep("lattice 1e5", &l);
    CHECK(found == lattice_pairs(cols, rows), "lattice 1e5: %zu pairs, want %zu",
          found, lattice_pairs(cols, rows));
    circles_free(&l);
    circles_free(&c);
}

/* Rows are done in runs of consecutive new rows, found by walking down from
 * the first circle's row and then up. Folded, every row of the table can be
 * occupied, so the walk must stop after one lap; rows met top-down, bottom-up,
 * interleaved or shuffled must all give the all-pairs set. */
static void test_nbs_row_runs(void)
{
    rng_seed(13);
    for (int trial = 0; trial < 200; trial++) {
        int rows = 3 + trial % 40, cols = 1 + trial % 7;
        size_t n = (size_t)rows * (size_t)cols;
        circles c = circles_new(n);
        /* unit cells; a row pitch of 1 or of 1 + a fold-sized gap (16 cells
         * for tables of <= 16 slots) puts every folded row in use */
        double pitch = trial % 3 == 0 ? 1.0 : trial % 3 == 1 ? 17.0 : 1e4 + 1.0;
        for (int row = 0; row < rows; row++)
            for (int col = 0; col < cols; col++) {
                size_t i = (size_t)row * (size_t)cols + (size_t)col;
                int ry = trial % 4 == 0 ? rows - 1 - row : trial % 4 == 1 ? row : (row * 7) % rows;
                c.x[i] = col + rng_range(-0.2, 0.2);
                c.y[i] = ry * pitch + rng_range(0.05, 0.95);
                c.r[i] = rng_range(0.3, 0.5);
                c.body[i] = -1;
            }
        if (trial % 5 == 4) shuffle(&c);
        char what[64];
        snprintf(what, sizeof what, "row runs trial %d n=%zu", trial, n);
        check_against_brute(what, &c, 0);
        circles_free(&c);
    }
}

/* One invalid circle sends the bounds to the careful loop; the valid ones
 * must still all be found, and the invalid one never. */
static void test_nbs_one_invalid_circle(void)
{
    rng_seed(14);
    size_t n = 500;
    double bad[] = {NAN, INFINITY, -INFINITY, 1e200, -1.0};
    for (int k = 0; k < 5; k++) {
        circles c = circles_new(n);
        fill_uniform(&c, 0, n, 0, 0, 20, 20, 0.2, 0.6);
        size_t victim = (size_t)(rng_uniform() * (double)n) % n;
        if (k == 4) c.r[victim] = bad[k];
        else if (k % 2) c.x[victim] = bad[k];
        else c.y[victim] = bad[k];
        char what[64];
        snprintf(what, sizeof what, "one invalid circle (%g)", bad[k]);
        check_against_brute(what, &c, 0);
        circles_free(&c);
    }
}

/* Two small clusters touching and 1 km apart must cost the same memory. */
static void test_nbs_memory_independent_of_distance(void)
{
    rng_seed(11);
    size_t n = 400;
    circles near = circles_new(n), far = circles_new(n);
    fill_uniform(&near, 0, n / 2, 0, 0, 2, 2, 0.05, 0.1);
    fill_uniform(&near, n / 2, n, 2.1, 0, 2, 2, 0.05, 0.1);
    for (size_t i = 0; i < n; i++) {
        far.x[i] = near.x[i] + (i >= n / 2 ? 1000.0 : 0.0);
        far.y[i] = near.y[i] + (i >= n / 2 ? 1000.0 : 0.0);
        far.r[i] = near.r[i];
    }
    nbs_grid g_near, g_far;
    nbs_pairs p_near, p_far;
    nbs_grid_init(&g_near);
    nbs_grid_init(&g_far);
    nbs_pairs_init(&p_near);
    nbs_pairs_init(&p_far);
    CHECK(nbs_detect(&g_near, n, near.x, near.y, near.r, NULL, &p_near) == 0, "near failed");
    CHECK(nbs_detect(&g_far, n, far.x, far.y, far.r, NULL, &p_far) == 0, "far failed");
    size_t m_near = nbs_memory_bytes(&g_near, &p_near), m_far = nbs_memory_bytes(&g_far, &p_far);
    CHECK_REL((double)m_far, (double)m_near, 0.02);
    /* and it is O(n): under 100 bytes per circle for this input */
    CHECK(m_far < 100 * n, "memory %zu bytes for %zu circles", m_far, n);
    nbs_grid_free(&g_near);
    nbs_grid_free(&g_far);
    nbs_pairs_free(&p_near);
    nbs_pairs_free(&p_far);
    circles_free(&near);
    circles_free(&far);
}

/* Reusing one grid: no reallocation at the high-water mark, and lists left
 * clean between calls (a smaller, different input right after a big one). */
static void test_nbs_reuse(void)
{
    rng_seed(12);
    size_t n = 3000;
    circles c = circles_new(n);
    fill_uniform(&c, 0, n, 0, 0, 50, 50, 0.1, 0.5);
    nbs_grid grid;
    nbs_pairs p, want;
    nbs_grid_init(&grid);
    nbs_pairs_init(&p);
    nbs_pairs_init(&want);
    CHECK(nbs_detect(&grid, n, c.x, c.y, c.r, NULL, &p) == 0, "first detect failed");
    size_t first = p.count, bytes = nbs_memory_bytes(&grid, &p);
    const int32_t *heads = grid.row_head, *cells = grid.cell_head, *pa = p.a;
    for (int k = 0; k < 3; k++) {
        CHECK(nbs_detect(&grid, n, c.x, c.y, c.r, NULL, &p) == 0, "repeat %d failed", k);
        CHECK(p.count == first, "repeat %d: %zu pairs, first %zu", k, p.count, first);
    }
    CHECK(nbs_memory_bytes(&grid, &p) == bytes && heads == grid.row_head &&
          cells == grid.cell_head && pa == p.a, "arrays reallocated at the high-water mark");
    /* smaller input, far away, through the same grid */
    for (size_t i = 0; i < 500; i++) { c.x[i] -= 5e5; c.y[i] *= 0.3; }
    CHECK(nbs_detect(&grid, 500, c.x, c.y, c.r, NULL, &p) == 0, "small detect failed");
    CHECK(nbs_detect_brute(500, c.x, c.y, c.r, NULL, &want) == 0, "brute failed");
    check_same_pairs("reuse small", &p, &want);
    /* folded (two groups 1e5 m apart, mirrored guards) then unfolded again */
    for (size_t i = 0; i < 250; i++) c.x[i] += 1e5;
    CHECK(nbs_detect(&grid, 500, c.x, c.y, c.r, NULL, &p) == 0, "folded detect failed");
    CHECK(grid.nx <= 512, "reuse: table %d not folded", grid.nx);
    CHECK(nbs_detect_brute(500, c.x, c.y, c.r, NULL, &want) == 0, "brute failed");
    check_same_pairs("reuse folded", &p, &want);
    for (size_t i = 0; i < 250; i++) c.x[i] -= 1e5;
    CHECK(nbs_detect(&grid, 400, c.x, c.y, c.r, NULL, &p) == 0, "unfolded detect failed");
    CHECK(nbs_detect_brute(400, c.x, c.y, c.r, NULL, &want) == 0, "brute failed");
    check_same_pairs("reuse unfolded after folded", &p, &want);
    check_grid_clean("reuse", &grid);
    /* two bands with an empty row between them: that row's head is read as
     * "the row below" and must not hold a list from an earlier call */
    fill_uniform(&c, 0, 300, 0, 0, 20, 0.9, 0.1, 0.5);
    fill_uniform(&c, 150, 300, 0, 2.1, 20, 0.9, 0.1, 0.5);
    CHECK(nbs_detect(&grid, 300, c.x, c.y, c.r, NULL, &p) == 0, "banded detect failed");
    CHECK(nbs_detect_brute(300, c.x, c.y, c.r, NULL, &want) == 0, "brute failed");
    check_same_pairs("reuse banded", &p, &want);
    nbs_grid_free(&grid);
    nbs_pairs_free(&p);
    nbs_pairs_free(&want);
    circles_free(&c);
}

CHECK_MAIN(T(test_nbs_tiny_inputs), T(test_nbs_random_matches_brute),
           T(test_nbs_clustered_matches_brute), T(test_nbs_sparse_matches_brute),
           T(test_nbs_lattice_touching), T(test_nbs_rounding_at_cell_edges),
           T(test_nbs_negative_coordinates),
           T(test_nbs_bodies_km_apart), T(test_nbs_folding_stress),
           T(test_nbs_body_filter), T(test_nbs_degenerate),
           T(test_nbs_large_against_sweep), T(test_nbs_memory_independent_of_distance),
           T(test_nbs_reuse), T(test_nbs_row_runs), T(test_nbs_one_invalid_circle))
