/*
 * bench_nbs.c - Munjiza-NBS contact detection speed and memory, printed by
 * `make bench`. Figures, not pass/fail: nothing here is a test.
 *
 * For N = 1e3 .. 1e6 circles on a jittered square lattice at packing
 * densities 1, 1/10, 1/100 and 1/1e4 circles per cell (cell = the largest
 * diameter), in lattice (spatial) and shuffled order, it times one detection
 * and sets it beside two baselines measured in the same run:
 *  - a counting-sort uniform grid (bin every circle into a dense nx*ny grid,
 *    gather the circles into cell order, test the same half mask) - the
 *    usual fast alternative, which pays O(nx*ny) and is skipped when the
 *    grid would exceed GRID_MAX_CELLS;
 *  - the all-pairs check (N <= 1e4 only).
 * Every method's pair count is compared; a mismatch is printed loudly.
 * The goals: <= 20 ns/element in spatial order at every N, flat
 * within 20 % across densities, and <= 1.5x the counting-sort grid.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "nbs/nbs.h"
#include "nbs/nbs_internal.h" /* the sphere test NBS uses, for the baseline */
#include "stream.h"
#include "math/clock.h"

#define GRID_MAX_CELLS ((int64_t)1 << 26) /* 256 MB of int32 counts */
#define BRUTE_MAX_N 10000
/* Many short batches, best taken: on a shared machine a batch that is
 * interrupted is simply not the best, so the figure tracks the code rather
 * than the neighbours. Every method gets the same treatment. The clock is
 * the thread's CPU time: the same as the wall on a quiet machine, but on a
 * busy one (two cores, three jobs) the wall figures of one binary differed
 * by up to 80 % between two runs of the 3D section, its CPU time figures by
 * a few % (lattice rows). */
#define TARGET_SECONDS 0.015 /* per timed batch */
#define BATCHES 15

/* ------------------------------------------------------------------ inputs */

typedef struct circles {
    size_t n;
    double *x, *y, *r;
    double *z; /* 3D only */
} circles;

static uint64_t rng_state = 12345;

static double rng_uniform(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
}

/* Row-major square lattice, spacing 1/sqrt(density) cells, jittered by
 * +-10 % of the spacing, radii 0.4 .. 0.5 (so the cell is 1): at density 1
 * neighbours overlap now and then, as loosely packed elements do. */
static circles circles_lattice(size_t n, double density)
{
    circles c = {n, malloc(n * sizeof(double)), malloc(n * sizeof(double)),
                 malloc(n * sizeof(double)), NULL};
    size_t cols = (size_t)ceil(sqrt((double)n));
    double s = 1.0 / sqrt(density);
    for (size_t i = 0; i < n; i++) {
        c.x[i] = s * ((double)(i % cols) + 0.2 * (rng_uniform() - 0.5));
        c.y[i] = s * ((double)(i / cols) + 0.2 * (rng_uniform() - 0.5));
        c.r[i] = 0.4 + 0.1 * rng_uniform();
    }
    c.r[0] = 0.5;
    return c;
}

static void circles_shuffle(circles *c)
{
    for (size_t i = c->n; i > 1; i--) {
        size_t j = (size_t)(rng_uniform() * (double)i) % i;
        double t;
        t = c->x[i - 1]; c->x[i - 1] = c->x[j]; c->x[j] = t;
        t = c->y[i - 1]; c->y[i - 1] = c->y[j]; c->y[j] = t;
        t = c->r[i - 1]; c->r[i - 1] = c->r[j]; c->r[j] = t;
        if (c->z) t = c->z[i - 1], c->z[i - 1] = c->z[j], c->z[j] = t;
    }
}

static void circles_free(circles *c)
{
    free(c->x);
    free(c->y);
    free(c->r);
    free(c->z);
}

/* The 3D input: a cubic lattice in x-fastest order, spacing
 * 1/cbrt(density) cells, jittered and with radii as in 2D. */
static circles spheres_lattice(size_t n, double density)
{
    circles c = {n, malloc(n * sizeof(double)), malloc(n * sizeof(double)),
                 malloc(n * sizeof(double)), malloc(n * sizeof(double))};
    size_t side = (size_t)ceil(cbrt((double)n) - 1e-9);
    double s = 1.0 / cbrt(density);
    for (size_t i = 0; i < n; i++) {
        size_t idx[3] = {i % side, (i / side) % side, i / (side * side)};
        double *axis[3] = {c.x, c.y, c.z};
        for (int a = 0; a < 3; a++)
            axis[a][i] = s * ((double)idx[a] + 0.2 * (rng_uniform() - 0.5));
        c.r[i] = 0.4 + 0.1 * rng_uniform();
    }
    c.r[0] = 0.5;
    return c;
}

/* ------------------------------------------ counting-sort uniform grid */

typedef struct grid_ws {
    int32_t *start;            /* cells + 1 prefix sums */
    int32_t *cell, *order;     /* per circle: cell index, circles in cell order */
    double *sx, *sy, *sr;      /* circles gathered into cell order */
    int64_t cells_capacity;
    size_t n_capacity;
} grid_ws;

static void grid_ws_free(grid_ws *w)
{
    free(w->start), free(w->cell), free(w->order);
    free(w->sx), free(w->sy), free(w->sr);
    memset(w, 0, sizeof *w);
}

static size_t grid_ws_bytes(const grid_ws *w)
{
    return (size_t)(w->cells_capacity + 1) * 4 + w->n_capacity * (4 + 4 + 24);
}

static int push(nbs_pairs *p, int32_t a, int32_t b)
{
    if (p->count == p->capacity) {
        size_t cap = p->capacity ? 2 * p->capacity : 1024;
        int32_t *na = realloc(p->a, cap * sizeof *na), *nb;
        if (!na) return -1;
        p->a = na;
        if (!(nb = realloc(p->b, cap * sizeof *nb))) return -1;
        p->b = nb;
        p->capacity = cap;
    }
    p->a[p->count] = a;
    p->b[p->count] = b;
    p->count++;
    return 0;
}

/* The same circle test as nbs.c (split statements: no FMA contraction). */
static inline int touch(double xi, double yi, double ri, double xj, double yj, double rj)
{
    double dx = xi - xj, dy = yi - yj, reach = ri + rj;
    double dx2 = dx * dx;
    double dy2 = dy * dy;
    double dist2 = dx2 + dy2;
    double reach2 = reach * reach;
    return dist2 <= reach2;
}

/* Returns 0, 1 when the dense grid would be too large, -1 on allocation
 * failure. Cell size is padded like nbs.c's so the two agree exactly. */
static int grid_detect(grid_ws *w, const circles *c, nbs_pairs *pairs)
{
    size_t n = c->n;
    pairs->count = 0;
    double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300, rmax = 0;
    for (size_t i = 0; i < n; i++) {
        xmin = fmin(xmin, c->x[i]), xmax = fmax(xmax, c->x[i]);
        ymin = fmin(ymin, c->y[i]), ymax = fmax(ymax, c->y[i]);
        rmax = fmax(rmax, c->r[i]);
    }
    double span = fmax(xmax - xmin, ymax - ymin);
    double cell = 2 * rmax * (1 + 1e-9) + 32 * 2.220446049250313e-16 * span;
    double inv = 1.0 / cell;
    int64_t nx = (int64_t)((xmax - xmin) * inv) + 1, ny = (int64_t)((ymax - ymin) * inv) + 1;
    int64_t cells = nx * ny;
    if (cells > GRID_MAX_CELLS) return 1;
    if (cells > w->cells_capacity) {
        free(w->start);
        if (!(w->start = malloc((size_t)(cells + 1) * sizeof *w->start))) return -1;
        w->cells_capacity = cells;
    }
    if (n > w->n_capacity) {
        w->cell = realloc(w->cell, n * sizeof *w->cell);
        w->order = realloc(w->order, n * sizeof *w->order);
        w->sx = realloc(w->sx, n * sizeof *w->sx);
        w->sy = realloc(w->sy, n * sizeof *w->sy);
        w->sr = realloc(w->sr, n * sizeof *w->sr);
        if (!w->cell || !w->order || !w->sx || !w->sy || !w->sr) return -1;
        w->n_capacity = n;
    }
    int32_t *start = w->start;
    memset(start, 0, (size_t)(cells + 1) * sizeof *start);
    for (size_t i = 0; i < n; i++) {
        int64_t ix = (int64_t)((c->x[i] - xmin) * inv), iy = (int64_t)((c->y[i] - ymin) * inv);
        w->cell[i] = (int32_t)(iy * nx + ix);
        start[w->cell[i] + 1]++;
    }
    for (int64_t k = 0; k < cells; k++) start[k + 1] += start[k];
    /* scatter; start[k] ends as the start of cell k + 1, shifted back below */
    for (size_t i = 0; i < n; i++) {
        int32_t k = start[w->cell[i]]++;
        w->order[k] = (int32_t)i;
        w->sx[k] = c->x[i], w->sy[k] = c->y[i], w->sr[k] = c->r[i];
    }
    for (int64_t k = cells; k > 0; k--) start[k] = start[k - 1];
    start[0] = 0;
    /* half mask: earlier circles of this cell and the left cell (one
     * contiguous range), then the three cells of the row below (another) */
    for (int32_t k = 0; k < (int32_t)n; k++) {
        int32_t cc = w->cell[w->order[k]];
        int64_t ix = cc % nx, iy = cc / nx;
        double xk = w->sx[k], yk = w->sy[k], rk = w->sr[k];
        int32_t lo = start[ix > 0 ? cc - 1 : cc];
        for (int32_t j = lo; j < k; j++)
            if (touch(xk, yk, rk, w->sx[j], w->sy[j], w->sr[j]) && push(pairs, w->order[k], w->order[j]))
                return -1;
        if (iy == 0) continue;
        int64_t below = cc - nx;
        int32_t b0 = start[ix > 0 ? below - 1 : below], b1 = start[ix + 1 < nx ? below + 2 : below + 1];
        for (int32_t j = b0; j < b1; j++)
            if (touch(xk, yk, rk, w->sx[j], w->sy[j], w->sr[j]) && push(pairs, w->order[k], w->order[j]))
                return -1;
    }
    return 0;
}

/* ------------------------------------------ hashed-cell grid in 3D */

/* The usual simple alternative in 3D, where a dense grid would be
 * O(nx ny nz): every sphere's cell (ix, iy, iz) is hashed into a table of
 * ~2N buckets, the spheres are counting-sorted by bucket (gathered with
 * their cell), and each sphere looks up the buckets of its own cell and the
 * 13 cells after it (half mask), keeping spheres of exactly that cell (so colliding cells neither
 * miss nor repeat a pair). O(N) memory and time whatever the density. */
typedef struct hash_ws {
    int32_t *start;                 /* buckets + 1 prefix sums */
    int32_t *bucket, *order;        /* per sphere: bucket; spheres in bucket order */
    int32_t *cx, *cy, *cz;          /* integer cell of the gathered spheres */
    double *sx, *sy, *sz, *sr;      /* spheres gathered into bucket order */
    size_t buckets, n_capacity;
} hash_ws;

static void hash_ws_free(hash_ws *w)
{
    free(w->start), free(w->bucket), free(w->order);
    free(w->cx), free(w->cy), free(w->cz);
    free(w->sx), free(w->sy), free(w->sz), free(w->sr);
    memset(w, 0, sizeof *w);
}

static size_t hash_ws_bytes(const hash_ws *w)
{
    return (w->buckets + 1) * 4 + w->n_capacity * (5 * 4 + 32);
}

/* Fibonacci hashing of the packed cell: the high bits of the product mix
 * every bit of the key (the low bits of x * a ^ y * b ^ z * c, the common
 * recipe, put a cubic lattice's cells into few buckets). */
static inline uint32_t cell_hash(int64_t x, int64_t y, int64_t z, uint32_t mask)
{
    uint64_t key = ((uint64_t)x & 0x1fffff) | ((uint64_t)y & 0x1fffff) << 21 |
                   ((uint64_t)z & 0x1fffff) << 42;
    return (uint32_t)((key * 0x9e3779b97f4a7c15ull) >> 40) & mask;
}

static int hash_detect_3d(hash_ws *w, const circles *c, nbs_pairs *pairs)
{
    size_t n = c->n;
    pairs->count = 0;
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, rmax = 0;
    const double *axis[3] = {c->x, c->y, c->z};
    for (size_t i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++) lo[a] = fmin(lo[a], axis[a][i]), hi[a] = fmax(hi[a], axis[a][i]);
        rmax = fmax(rmax, c->r[i]);
    }
    double span = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    double inv = 1.0 / (2 * rmax * (1 + 1e-9) + 32 * 2.220446049250313e-16 * span);
    size_t buckets = 4;
    while (buckets < 2 * n) buckets *= 2;
    if (buckets > w->buckets) {
        free(w->start);
        if (!(w->start = malloc((buckets + 1) * sizeof *w->start))) return -1;
        w->buckets = buckets;
    }
    if (n > w->n_capacity) {
        int32_t **ints[] = {&w->bucket, &w->order, &w->cx, &w->cy, &w->cz};
        double **reals[] = {&w->sx, &w->sy, &w->sz, &w->sr};
        for (int k = 0; k < 5; k++)
            if (!(*ints[k] = realloc(*ints[k], n * sizeof(int32_t)))) return -1;
        for (int k = 0; k < 4; k++)
            if (!(*reals[k] = realloc(*reals[k], n * sizeof(double)))) return -1;
        w->n_capacity = n;
    }
    uint32_t mask = (uint32_t)(buckets - 1);
    int32_t *start = w->start;
    memset(start, 0, (buckets + 1) * sizeof *start);
    for (size_t i = 0; i < n; i++) {
        int64_t x = (int64_t)((c->x[i] - lo[0]) * inv), y = (int64_t)((c->y[i] - lo[1]) * inv),
                z = (int64_t)((c->z[i] - lo[2]) * inv);
        w->bucket[i] = (int32_t)cell_hash(x, y, z, mask);
        start[w->bucket[i] + 1]++;
    }
    for (size_t k = 0; k < buckets; k++) start[k + 1] += start[k];
    for (size_t i = 0; i < n; i++) { /* start[b] ends as the start of b + 1 */
        int32_t k = start[w->bucket[i]]++;
        w->order[k] = (int32_t)i;
        w->sx[k] = c->x[i], w->sy[k] = c->y[i], w->sz[k] = c->z[i], w->sr[k] = c->r[i];
        w->cx[k] = (int32_t)((c->x[i] - lo[0]) * inv);
        w->cy[k] = (int32_t)((c->y[i] - lo[1]) * inv);
        w->cz[k] = (int32_t)((c->z[i] - lo[2]) * inv);
    }
    for (size_t k = buckets; k > 0; k--) start[k] = start[k - 1];
    start[0] = 0;
    for (int32_t k = 0; k < (int32_t)n; k++) {
        double xk = w->sx[k], yk = w->sy[k], zk = w->sz[k], rk = w->sr[k];
        /* half mask: its own cell (later spheres) and the 13 cells after it */
        for (int d = 13; d < 27; d++) {
            int32_t x = w->cx[k] + d % 3 - 1, y = w->cy[k] + d / 3 % 3 - 1, z = w->cz[k] + d / 9 - 1;
            uint32_t b = cell_hash(x, y, z, mask);
            for (int32_t j = start[b]; j < start[b + 1]; j++)
                if ((d > 13 || j > k) && w->cx[j] == x && w->cy[j] == y && w->cz[j] == z &&
                    nbs_spheres_touch(xk, yk, zk, rk, w->sx[j], w->sy[j], w->sz[j], w->sr[j]) &&
                    push(pairs, w->order[k], w->order[j]))
                    return -1;
        }
    }
    return 0;
}

/* ---------------------------------------------------------------- timing */

typedef enum method { M_NBS, M_GRID, M_BRUTE, M_NBS3, M_HASH3, M_BRUTE3 } method;

typedef struct runner {
    const circles *c;
    nbs_grid nbs;
    nbs_grid_3d nbs3;
    grid_ws grid;
    hash_ws hash;
    nbs_pairs pairs;
} runner;

static int run_once(runner *u, method m)
{
    const circles *c = u->c;
    switch (m) {
    case M_NBS: return nbs_detect(&u->nbs, c->n, c->x, c->y, c->r, NULL, &u->pairs);
    case M_GRID: return grid_detect(&u->grid, c, &u->pairs);
    case M_BRUTE: return nbs_detect_brute(c->n, c->x, c->y, c->r, NULL, &u->pairs);
    case M_NBS3: return nbs_detect_3d(&u->nbs3, c->n, c->x, c->y, c->z, c->r, NULL, &u->pairs);
    case M_HASH3: return hash_detect_3d(&u->hash, c, &u->pairs);
    case M_BRUTE3: return nbs_detect_brute_3d(c->n, c->x, c->y, c->z, c->r, NULL, &u->pairs);
    }
    return -1;
}

/* Best ns per element over BATCHES batches of detections sized to
 * TARGET_SECONDS; -1 if the method cannot run. *pairs gets the count. */
static double time_method(runner *u, method m, size_t *pairs)
{
    if (run_once(u, m) != 0) return -1; /* warm-up: reach the high-water mark */
    *pairs = u->pairs.count;
    double t0 = clock_cpu_seconds();
    run_once(u, m);
    double once = clock_cpu_seconds() - t0;
    int reps = once > 0 ? (int)(TARGET_SECONDS / once) : 1000;
    if (reps < 1) reps = 1;
    int batches = m == M_BRUTE || m == M_BRUTE3 ? 1 : BATCHES;
    double best = 1e30;
    for (int b = 0; b < batches; b++) {
        t0 = clock_cpu_seconds();
        for (int k = 0; k < reps; k++) run_once(u, m);
        double t = (clock_cpu_seconds() - t0) / reps;
        if (t < best) best = t;
    }
    return best * 1e9 / (double)u->c->n;
}

/* ------------------------------------------------------------------ main */

typedef struct summary {
    double worst_ns, worst_ratio, worst_spread;
    int mismatches;
} summary;

static void print_cell(double v, const char *fmt)
{
    if (v < 0) printf(" %8s", "-");
    else printf(fmt, v);
}

/* The 3D section: 1e4 .. 1e6 spheres at densities 1 .. 1/1e4 spheres per
 * cell, in lattice and shuffled order, beside the hashed-cell grid (same
 * process, same spheres) and the all-pairs check at 1e4. B/el counts the
 * book's 3N + nz + 2nx + 2ny integers, the packed copy of the spheres the
 * detector keeps (32 B each) and the pair list.
 * Goals of issue 12: <= 30 ns/el in spatial order, flat within 30 %. */
#define DENSITIES_3D 5
static int bench_3d(void)
{
    static const size_t sizes[] = {10000, 100000, 1000000};
    static const double densities[DENSITIES_3D] = {1.0, 0.1, 0.01, 1e-3, 1e-4};
    static const char *density_names[DENSITIES_3D] = {"1", "1/10", "1/100", "1/1e3", "1/1e4"};
    printf("\n# Munjiza-NBS in 3D (bounding spheres, cubic lattice, single core)\n");
    printf("ns/el: one detection divided by N (thread CPU time, best of %d batches); NBS B: lists, "
           "packed spheres and pairs per sphere, int B: the 3N + nz + 2nx + 2ny integers alone;\n"
           "hash: hashed-cell grid "
           "baseline (14 buckets a sphere, counting sort, gathered copy); brute: all pairs (N <= %d)\n\n",
           BATCHES, BRUTE_MAX_N);
    printf("%8s %-8s %-6s %8s %8s %8s %8s %8s %8s %8s %8s %9s\n", "N", "order", "dens",
           "pairs/el", "NBS ns", "NBS B", "int B", "hash ns", "hash B", "NBS/hash", "brute ns",
           "brute/NBS");
    double worst = 0, worst_spread = 0, worst_ratio = 0;
    int mismatches = 0;
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++) {
        double spatial[DENSITIES_3D];
        for (int order = 0; order < 2; order++)
            for (size_t di = 0; di < DENSITIES_3D; di++) {
                size_t n = sizes[si];
                circles c = spheres_lattice(n, densities[di]);
                if (order) circles_shuffle(&c);
                runner u = {.c = &c};
                nbs_grid_3d_init(&u.nbs3);
                nbs_pairs_init(&u.pairs);
                size_t p_nbs = 0, p_hash = 0, p_brute = 0;
                double ns = time_method(&u, M_NBS3, &p_nbs);
                double bytes = (double)nbs_memory_bytes_3d(&u.nbs3, &u.pairs) / (double)n;
                double ints = 4.0 * (double)nbs_integers_3d(&u.nbs3) / (double)n;
                double hash = time_method(&u, M_HASH3, &p_hash);
                double brute = n <= BRUTE_MAX_N ? time_method(&u, M_BRUTE3, &p_brute) : -1;
                int bad = p_hash != p_nbs || (brute >= 0 && p_brute != p_nbs);
                mismatches += bad;
                printf("%8zu %-8s %-6s %8.2f", n, order ? "shuffled" : "lattice",
                       density_names[di], (double)p_nbs / (double)n);
                print_cell(ns, " %8.1f");
                print_cell(bytes, " %8.1f");
                print_cell(ints, " %8.1f");
                print_cell(hash, " %8.1f");
                print_cell(hash >= 0 ? (double)hash_ws_bytes(&u.hash) / (double)n : -1, " %8.0f");
                print_cell(hash > 0 ? ns / hash : -1, " %8.2f");
                print_cell(brute, " %8.1f");
                print_cell(brute > 0 ? brute / ns : -1, " %9.1f");
                printf("%s\n", bad ? "  PAIR COUNT MISMATCH" : "");
                fflush(stdout);
                if (!order) {
                    spatial[di] = ns;
                    worst = fmax(worst, ns);
                    if (hash > 0) worst_ratio = fmax(worst_ratio, ns / hash);
                }
                nbs_grid_3d_free(&u.nbs3);
                nbs_pairs_free(&u.pairs);
                hash_ws_free(&u.hash);
                circles_free(&c);
            }
        double lo = spatial[0], hi = spatial[0];
        for (int k = 1; k < DENSITIES_3D; k++) lo = fmin(lo, spatial[k]), hi = fmax(hi, spatial[k]);
        worst_spread = fmax(worst_spread, hi / lo - 1);
    }
    printf("\n3D goals (lattice order): worst %.1f ns/el (goal <= 30): %s; spread across "
           "densities %.0f %% (goal <= 30 %%): %s; worst NBS/hash %.2f; pair count mismatches: %d\n",
           worst, worst <= 30 ? "met" : "MISSED", 100 * worst_spread,
           worst_spread <= 0.3 ? "met" : "MISSED", worst_ratio, mismatches);
    return mismatches;
}

int main(int argc, char **argv)
{
    /* `bench_nbs 3d` runs the 3D section alone */
    if (argc > 1 && strcmp(argv[1], "3d") == 0) return bench_3d() ? 1 : 0;
    static const size_t sizes[] = {1000, 10000, 100000, 1000000};
    static const double densities[] = {1.0, 0.1, 0.01, 1e-4};
    static const char *density_names[] = {"1", "1/10", "1/100", "1/1e4"};

    double copy = stream_copy_gbs(), triad = stream_bandwidth_gbs();
    printf("# Munjiza-NBS contact detection (single core)\n");
    printf("single-core bandwidth: copy %.1f GB/s, triad %.1f GB/s\n", copy, triad);
    double load[1];
    if (getloadavg(load, 1) == 1)
        printf("load average at start: %.2f (timings are noisier when it nears the core count)\n",
               load[0]);
    printf("ns/el: one detection divided by N (thread CPU time, best of %d batches); "
           "B/el: detector memory / N\n"
           "(NBS: lists + pairs; grid: counts + sort + gathered copy; inputs not counted); grid: counting-sort dense grid baseline\n"
           "(n/a above %lld cells); brute: all pairs (N <= %d)\n\n",
           BATCHES, (long long)GRID_MAX_CELLS, BRUTE_MAX_N);
    printf("%8s %-8s %-6s %8s %8s %8s %8s %8s %8s %8s %9s\n", "N", "order", "dens", "pairs/el",
           "NBS ns", "NBS B", "grid ns", "grid B", "NBS/grid", "brute ns", "brute/NBS");

    summary s = {0, 0, 0, 0};
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++) {
        double spatial_ns[4];
        for (int order = 0; order < 2; order++) {
            for (size_t di = 0; di < 4; di++) {
                size_t n = sizes[si];
                circles c = circles_lattice(n, densities[di]);
                if (order) circles_shuffle(&c);
                runner u = {.c = &c};
                nbs_grid_init(&u.nbs);
                nbs_pairs_init(&u.pairs);
                size_t p_nbs = 0, p_grid = 0, p_brute = 0;
                double nbs_ns = time_method(&u, M_NBS, &p_nbs);
                double bytes = (double)nbs_memory_bytes(&u.nbs, &u.pairs) / (double)n;
                double grid_ns = time_method(&u, M_GRID, &p_grid);
                double brute_ns = n <= BRUTE_MAX_N ? time_method(&u, M_BRUTE, &p_brute) : -1;
                int bad = (grid_ns >= 0 && p_grid != p_nbs) || (brute_ns >= 0 && p_brute != p_nbs);
                s.mismatches += bad;

                printf("%8zu %-8s %-6s %8.2f", n, order ? "shuffled" : "lattice",
                       density_names[di], (double)p_nbs / (double)n);
                print_cell(nbs_ns, " %8.1f");
                print_cell(bytes, " %8.1f");
                print_cell(grid_ns, " %8.1f");
                print_cell(grid_ns >= 0 ? (double)grid_ws_bytes(&u.grid) / (double)n : -1, " %8.0f");
                print_cell(grid_ns > 0 ? nbs_ns / grid_ns : -1, " %8.2f");
                print_cell(brute_ns, " %8.1f");
                print_cell(brute_ns > 0 ? brute_ns / nbs_ns : -1, " %9.1f");
                printf("%s\n", bad ? "  PAIR COUNT MISMATCH" : "");
                fflush(stdout);

                if (!order) {
                    spatial_ns[di] = nbs_ns;
                    if (nbs_ns > s.worst_ns) s.worst_ns = nbs_ns;
                    if (grid_ns > 0 && nbs_ns / grid_ns > s.worst_ratio) s.worst_ratio = nbs_ns / grid_ns;
                }
                nbs_grid_free(&u.nbs);
                nbs_pairs_free(&u.pairs);
                grid_ws_free(&u.grid);
                circles_free(&c);
            }
            if (!order) {
                double lo = spatial_ns[0], hi = spatial_ns[0];
                for (int k = 1; k < 4; k++) lo = fmin(lo, spatial_ns[k]), hi = fmax(hi, spatial_ns[k]);
                if (hi / lo - 1 > s.worst_spread) s.worst_spread = hi / lo - 1;
            }
        }
    }
    printf("\ngoals (lattice order): worst %.1f ns/el (goal <= 20): %s; "
           "spread across densities %.0f %% (goal <= 20 %%): %s; "
           "worst NBS/grid %.2f (goal <= 1.5): %s; pair count mismatches: %d\n",
           s.worst_ns, s.worst_ns <= 20 ? "met" : "MISSED", 100 * s.worst_spread,
           s.worst_spread <= 0.2 ? "met" : "MISSED", s.worst_ratio,
           s.worst_ratio <= 1.5 ? "met" : "MISSED", s.mismatches);
    s.mismatches += bench_3d();
    return s.mismatches ? 1 : 0;
}
