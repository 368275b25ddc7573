/*
 * test_nbs_3d.c - 3D Munjiza-NBS must return exactly the pair set of the
 * all-pairs reference on random, clustered, sparse (1 sphere per 1e4
 * cells), lattice, folded and degenerate inputs of 10 .. 1e5 spheres, leave
 * every list head empty, and hold exactly 3N + nz + 2nx + 2ny integers.
 *
 * Up to 3e3 spheres the reference is nbs_detect_brute_3d; at 1e5 it is a
 * sweep along z written here (independent of the grid), so the test stays
 * fast under ASan. Comparisons are exact: same sphere test, same doubles.
 */
#include "check.h"
#include "heap_count.h"
#include "nbs/nbs.h"
#include "pair_sets.h"

#include <stdint.h>
#include <stdlib.h>

/* ------------------------------------------------------------------ inputs */

typedef struct spheres {
    size_t n;
    double *p[3]; /* centre coordinates x, y, z */
    double *r;
    int32_t *body;
} spheres;

static spheres spheres_new(size_t n)
{
    spheres s = {.n = n};
    for (int a = 0; a < 3; a++) s.p[a] = calloc(n + 1, sizeof(double));
    s.r = calloc(n + 1, sizeof(double));
    s.body = malloc((n + 1) * sizeof(int32_t));
    for (size_t i = 0; i <= n; i++) s.body[i] = -1;
    return s;
}

static void spheres_free(spheres *s)
{
    for (int a = 0; a < 3; a++) free(s->p[a]);
    free(s->r);
    free(s->body);
}

/* uniform centres in the cube [o, o + side]^3, radii in [rlo, rhi] */
static void put_in_cube(spheres *s, size_t from, size_t to, const double o[3], double side,
                        double rlo, double rhi)
{
    for (size_t i = from; i < to; i++) {
        for (int a = 0; a < 3; a++) s->p[a][i] = o[a] + side * rng_uniform();
        s->r[i] = rng_range(rlo, rhi);
    }
}

/* Every other sphere gets its predecessor's centre moved by less than the
 * sum of radii in a random direction: planted contacts. */
static void plant_partners(spheres *s)
{
    for (size_t i = 0; i + 1 < s->n; i += 2) {
        double u[3], len = 0;
        for (int a = 0; a < 3; a++) u[a] = rng_range(-1, 1), len += u[a] * u[a];
        len = sqrt(len) + 1e-300;
        double dist = (s->r[i] + s->r[i + 1]) * rng_range(0.3, 0.999);
        for (int a = 0; a < 3; a++) s->p[a][i + 1] = s->p[a][i] + dist * u[a] / len;
    }
}

/* side^3 simple cubic lattice of pitch 2 r0 at origin o */
static void put_cubic_lattice(spheres *s, int side, const double o[3], double r0, double radius)
{
    size_t i = 0;
    for (int k = 0; k < side; k++)
        for (int j = 0; j < side; j++)
            for (int m = 0; m < side; m++, i++) {
                int idx[3] = {m, j, k};
                for (int a = 0; a < 3; a++) s->p[a][i] = o[a] + 2.0 * r0 * idx[a];
                s->r[i] = radius;
            }
}

/* face neighbours of a side^3 cubic lattice */
static size_t cubic_lattice_pairs(size_t side) { return 3 * side * side * (side - 1); }

static void spheres_shuffle(spheres *s)
{
    for (size_t i = s->n; i > 1; i--) {
        size_t j = (size_t)(rng_uniform() * (double)i);
        if (j >= i) j = i - 1;
        for (int a = 0; a < 3; a++) {
            double t = s->p[a][i - 1];
            s->p[a][i - 1] = s->p[a][j];
            s->p[a][j] = t;
        }
        double t = s->r[i - 1]; s->r[i - 1] = s->r[j]; s->r[j] = t;
        int32_t b = s->body[i - 1]; s->body[i - 1] = s->body[j]; s->body[j] = b;
    }
}

/* ------------------------------------------------------------- detection */

/* After a detection every head of all three levels must be empty again. */
static void expect_heads_empty(const char *what, const nbs_grid_3d *g)
{
    size_t stale = 0;
    for (size_t k = 0; k < g->nz_capacity; k++) stale += g->layer_head[k] != -1;
    for (size_t k = 0; k < 2 * g->ny_capacity; k++) stale += g->row_head[k] != -1;
    for (size_t k = 0; k < 2 * g->nx_capacity; k++) stale += g->cell_head[k] != -1;
    CHECK(stale == 0, "%s: %zu list heads left non-empty", what, stale);
}

static int detect(nbs_grid_3d *g, const spheres *s, int use_body, nbs_pairs *out)
{
    return nbs_detect_3d(g, s->n, s->p[0], s->p[1], s->p[2], s->r,
                         use_body ? s->body : NULL, out);
}

/* Sweep along z: sort by z, then each sphere against those ahead while the
 * z gap can still be bridged (r_i + rmax, padded far above rounding). */
static const spheres *sweep_of;

static int by_z(const void *a, const void *b)
{
    double u = sweep_of->p[2][*(const int32_t *)a], v = sweep_of->p[2][*(const int32_t *)b];
    return (u > v) - (u < v);
}

/* The sphere test of nbs_3d.c written out again on purpose, in the same
 * split statements (no FMA contraction), so the sets compare exactly. */
static int touches(const spheres *s, int32_t i, int32_t j)
{
    double dist2 = 0;
    for (int a = 0; a < 3; a++) { /* ((dx2 + dy2) + dz2), as there */
        double d = s->p[a][i] - s->p[a][j];
        double d2 = d * d;
        dist2 = a == 0 ? d2 : dist2 + d2;
    }
    double reach = s->r[i] + s->r[j];
    double reach2 = reach * reach;
    return dist2 <= reach2;
}

static void reference_sweep(const spheres *s, nbs_pairs *out)
{
    int32_t *idx = malloc(s->n * sizeof *idx);
    double rmax = 0;
    for (size_t i = 0; i < s->n; i++) idx[i] = (int32_t)i, rmax = fmax(rmax, s->r[i]);
    sweep_of = s;
    qsort(idx, s->n, sizeof *idx, by_z);
    out->count = 0;
    for (size_t u = 0; u < s->n; u++) {
        int32_t i = idx[u];
        double window = (s->r[i] + rmax) * (1 + 1e-9);
        for (size_t v = u + 1; v < s->n && s->p[2][idx[v]] - s->p[2][i] <= window; v++) {
            int32_t j = idx[v];
            if (!touches(s, i, j)) continue;
            if (out->count == out->capacity) {
                out->capacity = out->capacity ? 2 * out->capacity : 4096;
                out->a = realloc(out->a, out->capacity * sizeof *out->a);
                out->b = realloc(out->b, out->capacity * sizeof *out->b);
            }
            out->a[out->count] = i;
            out->b[out->count++] = j;
        }
    }
    free(idx);
}

/* NBS against a reference (brute when sweep == 0); returns the pair count. */
static size_t expect_exact(const char *what, const spheres *s, int use_body, int sweep)
{
    nbs_grid_3d g;
    nbs_pairs got, want;
    nbs_grid_3d_init(&g);
    nbs_pairs_init(&got);
    nbs_pairs_init(&want);
    CHECK(detect(&g, s, use_body, &got) == 0, "%s: nbs_detect_3d failed", what);
    expect_heads_empty(what, &g);
    if (sweep)
        reference_sweep(s, &want);
    else
        CHECK(nbs_detect_brute_3d(s->n, s->p[0], s->p[1], s->p[2], s->r,
                                  use_body ? s->body : NULL, &want) == 0,
              "%s: brute failed", what);
    check_same_pairs(what, &got, &want);
    size_t count = got.count;
    nbs_grid_3d_free(&g);
    nbs_pairs_free(&got);
    nbs_pairs_free(&want);
    return count;
}

/* ------------------------------------------------------------------ tests */

static void test_nbs3_tiny(void)
{
    spheres s = spheres_new(3);
    double x[3] = {0, 0, 0}, z[3] = {0, 1, 2.5};
    for (int i = 0; i < 3; i++) s.p[0][i] = x[i], s.p[2][i] = z[i], s.r[i] = 0.5;
    s.n = 0;
    CHECK(expect_exact("n = 0", &s, 0, 0) == 0, "n = 0 has pairs");
    s.n = 1;
    CHECK(expect_exact("n = 1", &s, 0, 0) == 0, "n = 1 has pairs");
    s.n = 2; /* centres 1 apart along z, radii 0.5 + 0.5: touching counts */
    CHECK(expect_exact("touching", &s, 0, 0) == 1, "touching spheres not found");
    s.n = 3; /* the third is 0.5 short of the second */
    CHECK(expect_exact("gap", &s, 0, 0) == 1, "a gap counted as contact");
    s.r[2] = 1.0;
    CHECK(expect_exact("reach", &s, 0, 0) == 2, "a larger radius not found");
    spheres_free(&s);
}

static void test_nbs3_random(void)
{
    static const size_t sizes[] = {10, 100, 1000, 3000};
    rng_seed(21);
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        size_t n = sizes[k];
        spheres s = spheres_new(n);
        double o[3] = {-3, 2, 7};
        /* about one sphere per cell of the largest diameter, radii vary x10 */
        put_in_cube(&s, 0, n, o, cbrt((double)n), 0.05, 0.5);
        char what[48];
        snprintf(what, sizeof what, "random n=%zu", n);
        size_t found = expect_exact(what, &s, 0, 0);
        CHECK(n < 100 || found > n / 10, "%s: only %zu pairs, too sparse to test", what, found);
        spheres_shuffle(&s);
        snprintf(what, sizeof what, "random shuffled n=%zu", n);
        expect_exact(what, &s, 0, 0);
        spheres_free(&s);
    }
}

static void test_nbs3_clustered(void)
{
    rng_seed(22);
    size_t n = 3000;
    spheres s = spheres_new(n);
    /* six dense blobs 0.4 wide, radii up to 0.06: ~80 per cell, ~8 contacts each */
    for (int blob = 0; blob < 6; blob++) {
        double o[3] = {rng_range(-40, 40), rng_range(-40, 40), rng_range(-40, 40)};
        put_in_cube(&s, blob * n / 6, (blob + 1) * n / 6, o, 0.4, 0.002, 0.06);
    }
    size_t found = expect_exact("clustered", &s, 0, 0);
    CHECK(found > n, "clustered: only %zu pairs", found);
    spheres_free(&s);
}

static void test_nbs3_sparse(void)
{
    rng_seed(23);
    size_t n = 2000;
    spheres s = spheres_new(n);
    /* one sphere per 1e4 cells of 1: a cube of 1e4 n cells */
    double side = cbrt(1e4 * (double)n), o[3] = {-side / 2, -side / 2, 0};
    put_in_cube(&s, 0, n, o, side, 0.25, 0.5);
    plant_partners(&s);
    size_t found = expect_exact("sparse", &s, 0, 0);
    CHECK(found >= n / 2, "sparse: %zu pairs, want >= the %zu planted", found, n / 2);
    spheres_free(&s);
}

static void test_nbs3_lattice(void)
{
    rng_seed(24);
    int side = 14; /* 2744 spheres */
    size_t n = (size_t)side * side * side;
    spheres s = spheres_new(n);
    double o[3] = {0, 0, 0};
    /* exactly touching: the borderline for rounding, same set as brute */
    put_cubic_lattice(&s, side, o, 0.5, 0.5);
    expect_exact("lattice touching", &s, 0, 0);
    /* radii 1e-9 larger: every face neighbour touches, no diagonal does */
    put_cubic_lattice(&s, side, o, 0.5, 0.5 * (1 + 1e-9));
    size_t found = expect_exact("lattice inflated", &s, 0, 0);
    CHECK(found == cubic_lattice_pairs((size_t)side), "lattice inflated: %zu pairs, want %zu",
          found, cubic_lattice_pairs((size_t)side));
    /* millimetre spheres 1e6 m from the origin, shuffled */
    double far[3] = {1e6, -1e6, 5e5};
    put_cubic_lattice(&s, side, far, 0.0005, 0.0005 * (1 + 1e-6));
    spheres_shuffle(&s);
    found = expect_exact("lattice at 1e6 m", &s, 0, 0);
    CHECK(found == cubic_lattice_pairs((size_t)side), "lattice at 1e6 m: %zu pairs, want %zu",
          found, cubic_lattice_pairs((size_t)side));
    spheres_free(&s);
}

static void test_nbs3_large_against_sweep(void)
{
    rng_seed(25);
    size_t n = 100000;
    spheres s = spheres_new(n);
    double o[3] = {10, -20, 30};
    put_in_cube(&s, 0, n, o, cbrt((double)n), 0.1, 0.5);
    size_t found = expect_exact("random 1e5", &s, 0, 1);
    CHECK(found > n / 10, "random 1e5: only %zu pairs", found);

    double sparse_side = cbrt(1e4 * (double)n);
    put_in_cube(&s, 0, n, o, sparse_side, 0.25, 0.5);
    plant_partners(&s);
    found = expect_exact("sparse 1e5", &s, 0, 1);
    CHECK(found >= n / 2, "sparse 1e5: %zu pairs, want >= %zu planted", found, n / 2);
    spheres_free(&s);

    int side = 46; /* 97336 */
    size_t m = (size_t)side * side * side;
    spheres l = spheres_new(m);
    put_cubic_lattice(&l, side, o, 0.5, 0.5 * (1 + 1e-9));
    spheres_shuffle(&l);
    found = expect_exact("lattice 1e5", &l, 0, 1);
    CHECK(found == cubic_lattice_pairs((size_t)side), "lattice 1e5: %zu pairs, want %zu",
          found, cubic_lattice_pairs((size_t)side));
    spheres_free(&l);
}

/* Few spheres over a huge extent fold onto tables of 4 .. 32 slots, and
 * layers or rows at a fold-sized pitch fill every slot, so the runs must
 * stop after one lap: pairs must still be met exactly once. */
static void test_nbs3_folding_and_runs(void)
{
    rng_seed(26);
    for (int trial = 0; trial < 400; trial++) {
        size_t n = 2 + (size_t)(rng_uniform() * 30);
        spheres s = spheres_new(n);
        double pitch = trial % 4 == 0 ? 1.0 : trial % 4 == 1 ? 17.0 : trial % 4 == 2 ? 33.0 : 1e4;
        for (size_t i = 0; i < n; i++)
            for (int a = 0; a < 3; a++) {
                double cellv = floor(rng_range(0, 6));
                s.p[a][i] = cellv * (a == trial % 3 ? pitch : 1.0) + rng_range(0, 1);
            }
        for (size_t i = 0; i < n; i++) s.r[i] = rng_range(0.3, 0.5);
        for (size_t i = 0; i + 1 < n; i += 2)
            for (int a = 0; a < 3; a++) s.p[a][i + 1] = s.p[a][i] + rng_range(-0.9, 0.9);
        if (trial % 5 == 4) spheres_shuffle(&s);
        char what[64];
        snprintf(what, sizeof what, "folding trial %d n=%zu", trial, n);
        expect_exact(what, &s, 0, 0);
        spheres_free(&s);
    }
}

static void test_nbs3_bodies(void)
{
    /* 40 spheres on one spot, ids 0..3 and -1: known count */
    size_t n = 40, per[4] = {0};
    spheres s = spheres_new(n);
    for (size_t i = 0; i < n; i++) {
        s.p[0][i] = 1e-3 * (double)(i % 7);
        s.p[1][i] = 1e-3 * (double)(i % 5);
        s.p[2][i] = 1e-3 * (double)(i % 3);
        s.r[i] = 0.1;
        s.body[i] = i % 5 == 4 ? -1 : (int32_t)(i % 5);
        if (s.body[i] >= 0) per[s.body[i]]++;
    }
    size_t want = n * (n - 1) / 2;
    for (int b = 0; b < 4; b++) want -= per[b] * (per[b] - 1) / 2;
    CHECK(expect_exact("bodies", &s, 1, 0) == want, "bodies: want %zu pairs", want);
    CHECK(expect_exact("bodies ignored", &s, 0, 0) == n * (n - 1) / 2, "body NULL keeps all");
    spheres_free(&s);

    rng_seed(27);
    spheres m = spheres_new(2000);
    double o[3] = {0, 0, 0};
    put_in_cube(&m, 0, 2000, o, 10, 0.1, 0.5);
    for (size_t i = 0; i < 2000; i++) m.body[i] = (int32_t)(i / 10) - 3;
    expect_exact("body mix", &m, 1, 0);
    spheres_free(&m);
}

static void test_nbs3_invalid_spheres(void)
{
    rng_seed(28);
    spheres s = spheres_new(300);
    double o[3] = {0, 0, 0};
    put_in_cube(&s, 0, 300, o, 6, 0.2, 0.5);
    s.p[0][3] = NAN;
    s.p[1][7] = INFINITY;
    s.p[2][9] = -1e300;
    s.r[11] = -1.0;
    s.r[13] = NAN;
    size_t found = expect_exact("invalid spheres", &s, 0, 0);
    CHECK(found > 50, "invalid spheres: only %zu pairs", found);
    /* zero radius: only coincident centres touch (10 groups of 5) */
    spheres z = spheres_new(50);
    for (size_t i = 0; i < 50; i++)
        z.p[0][i] = 0.37 * (double)(i % 10), z.p[2][i] = -1.1 * (double)(i % 10);
    CHECK(expect_exact("zero radius", &z, 0, 0) == 100, "zero radius: want 100 pairs");
    spheres_free(&z);
    spheres_free(&s);
}

/* The book's RAM: exactly 3N + nz + 2nx + 2ny integers, where nz, nx, ny
 * are the table sizes (cells spanned + 1, or the fold); never the product.
 * A model 1e7 cells wide holds no more than a compact one of the same N
 * may (tables fold at the power of two >= N). */
static void test_nbs3_integer_ram(void)
{
    rng_seed(29);
    size_t n = 5000;
    spheres s = spheres_new(n);
    double o[3] = {0, 0, 0};
    put_in_cube(&s, 0, n, o, 60, 0.3, 0.5); /* ~60^3 cells, 1 sphere per 43 */
    nbs_grid_3d g;
    nbs_pairs p;
    nbs_grid_3d_init(&g);
    nbs_pairs_init(&p);
    CHECK(detect(&g, &s, 0, &p) == 0, "detect failed");
    size_t want = 3 * n + (size_t)g.nz + 2 * (size_t)g.nx + 2 * (size_t)g.ny;
    CHECK(nbs_integers_3d(&g) == want, "%zu integers, want 3N + nz + 2nx + 2ny = %zu",
          nbs_integers_3d(&g), want);
    /* the integers and the packed copy of the spheres, (x, y, z, r) each */
    size_t want_bytes = 4 * want + 4 * sizeof(double) * n;
    CHECK(nbs_memory_bytes_3d(&g, NULL) == want_bytes, "memory %zu B, want %zu",
          nbs_memory_bytes_3d(&g, NULL), want_bytes);
    CHECK(g.nx >= 60 && g.nx <= 64 && g.ny <= 64 && g.nz <= 64, "tables %d %d %d for 60 cells",
          g.nx, g.ny, g.nz);
    nbs_grid_3d_free(&g);

    /* the same N, in four clusters 1 km .. 1000 km apart: folded tables */
    put_in_cube(&s, 0, n / 4, o, 5, 0.05, 0.1);
    double o2[3] = {1000, 0, 0}, o3[3] = {0, -1000, 1000}, o4[3] = {1e6, 1e6, -1e6};
    put_in_cube(&s, n / 4, n / 2, o2, 5, 0.05, 0.1);
    put_in_cube(&s, n / 2, 3 * n / 4, o3, 5, 0.05, 0.1);
    put_in_cube(&s, 3 * n / 4, n, o4, 5, 0.05, 0.1);
    nbs_grid_3d_init(&g);
    expect_exact("km apart", &s, 0, 0);
    CHECK(detect(&g, &s, 0, &p) == 0, "km apart: detect failed");
    CHECK(g.nx == 8192 && g.ny == 8192 && g.nz == 8192, "km apart: tables %d %d %d, want the fold 8192",
          g.nx, g.ny, g.nz);
    want = 3 * n + 5 * 8192;
    CHECK(nbs_integers_3d(&g) == want, "km apart: %zu integers, want %zu", nbs_integers_3d(&g), want);
    nbs_grid_3d_free(&g);
    nbs_pairs_free(&p);
    spheres_free(&s);
}

/* One grid reused over inputs of growing and shrinking size and extent:
 * stale heads or a stale layout would lose or invent pairs. */
static void test_nbs3_reuse(void)
{
    rng_seed(30);
    nbs_grid_3d g;
    nbs_pairs got, want;
    nbs_grid_3d_init(&g);
    nbs_pairs_init(&got);
    nbs_pairs_init(&want);
    static const size_t sizes[] = {500, 50, 2000, 7, 900};
    for (int k = 0; k < 5; k++) {
        spheres s = spheres_new(sizes[k]);
        double o[3] = {k * 100.0, -k * 3.0, 0};
        put_in_cube(&s, 0, s.n, o, cbrt((double)s.n) * (k % 2 ? 10 : 1), 0.1, 0.5);
        char what[32];
        snprintf(what, sizeof what, "reuse %d", k);
        CHECK(detect(&g, &s, 0, &got) == 0, "%s: detect failed", what);
        expect_heads_empty(what, &g);
        nbs_detect_brute_3d(s.n, s.p[0], s.p[1], s.p[2], s.r, NULL, &want);
        check_same_pairs(what, &got, &want);
        spheres_free(&s);
    }
    nbs_grid_3d_free(&g);
    nbs_pairs_free(&got);
    nbs_pairs_free(&want);
}

/* A run that wraps round a folded z-axis starts above a layer not done
 * yet, and the walks of its first layer read each element's x from the
 * x-links of that layer, which must hold them although none of its rows
 * has been through an x-set yet. Four spheres fold z onto 4 slots, every
 * one a layer; sphere 0's is the layer below the run's first, and it
 * touches sphere 1 above it. The grid is reused, so that a stale x from the first
 * detection (sphere 0 two cells away in x) would lose the pair. */
static void test_nbs3_wrapped_run(void)
{
    spheres s = spheres_new(4);
    double x[4] = {1.2, 3.3, 0.0, 3.3}, z[4] = {1.5, 2.2, 0.0, 7.5}; /* z cells 1, 2, 0, 7 */
    for (int i = 0; i < 4; i++) s.p[0][i] = x[i], s.p[1][i] = 0.0, s.p[2][i] = z[i], s.r[i] = 0.5;
    nbs_grid_3d g;
    nbs_pairs got, want;
    nbs_grid_3d_init(&g);
    nbs_pairs_init(&got);
    nbs_pairs_init(&want);
    for (int round = 0; round < 2; round++) {
        if (round) s.p[0][0] = 3.3; /* now on top of sphere 1, 0.7 below it */
        CHECK(detect(&g, &s, 0, &got) == 0, "wrapped run: detect failed");
        CHECK(g.nz == 4, "wrapped run: %d z slots, want the fold 4", g.nz);
        nbs_detect_brute_3d(s.n, s.p[0], s.p[1], s.p[2], s.r, NULL, &want);
        CHECK(want.count == (size_t)round, "wrapped run: brute finds %zu pairs", want.count);
        check_same_pairs(round ? "wrapped run, reused" : "wrapped run", &got, &want);
    }
    nbs_grid_3d_free(&g);
    nbs_pairs_free(&got);
    nbs_pairs_free(&want);
    spheres_free(&s);
}

/* Centres on the unit lattice (m, j, k), 0 <= m, j, k < side, leaving out
 * every third row (j % 3 == 2) and every third layer (k % 3 == 2): blocks
 * of two rows and two layers, so every layer and every row is the first
 * or the last of its run. Radii 0.5 (1 + 1e-9): face neighbours touch.
 * Returns the count placed. */
static size_t put_blocky_lattice(spheres *s, int side)
{
    size_t i = 0;
    for (int k = 0; k < side; k++)
        for (int j = 0; j < side; j++)
            for (int m = 0; m < side; m++) {
                if (j % 3 == 2 || k % 3 == 2) continue;
                s->p[0][i] = m, s->p[1][i] = j, s->p[2][i] = k;
                s->r[i] = 0.5 * (1 + 1e-9);
                i++;
            }
    return i;
}

/* The walk exists twice (with and without body ids), and the walks of a
 * lower row against one x-set (the first row of a run against the row
 * below it, the last row against its two) are out of line once a case.
 * In blocks of two rows and layers every row is the first or last of its
 * run, and with four body ids (and -1) by column most touching pairs
 * across layers share a body, in both kinds of walk. */
static void test_nbs3_bodies_across_runs(void)
{
    rng_seed(31);
    int side = 9;
    spheres s = spheres_new((size_t)side * side * side);
    s.n = put_blocky_lattice(&s, side);
    for (size_t i = 0; i < s.n; i++) /* layers meet their own body, x sometimes too */
        s.body[i] = (int32_t)(((int)s.p[0][i] / 2 + (int)s.p[1][i]) % 5) - 1;
    size_t all = expect_exact("blocky lattice, bodies ignored", &s, 0, 0);
    size_t kept = expect_exact("blocky lattice, bodies", &s, 1, 0);
    CHECK(kept < all && kept > all / 2, "blocky lattice: %zu pairs with bodies, %zu without",
          kept, all);
    spheres_shuffle(&s);
    expect_exact("blocky lattice shuffled, bodies", &s, 1, 0);
    spheres_free(&s);
}

/* The layer and row searches stop once the runs have taken every valid
 * sphere, counted apart from the walk. Invalid spheres interleaved with a
 * lattice of many runs, and a few lone spheres each in a layer of its own
 * at the end of the index order (the last runs the search finds): a count
 * one short would leave such a layer undone, its head not empty. */
static void test_nbs3_invalid_many_runs(void)
{
    rng_seed(32);
    int side = 8;
    size_t lone = 4;
    spheres s = spheres_new((size_t)side * side * side + lone);
    static const double bad[] = {NAN, INFINITY, -INFINITY, 2e150, -2e150};
    for (int every = 2; every <= 3; every++)
        for (int shuffled = 0; shuffled <= 1; shuffled++) {
            size_t n = put_blocky_lattice(&s, side);
            for (size_t t = 0; t < lone; t++, n++) {
                s.p[0][n] = 1.0 + (double)t, s.p[1][n] = 2.0, s.p[2][n] = 20.0 + 3.0 * (double)t;
                s.r[n] = 0.5;
            }
            s.n = n;
            for (size_t i = (size_t)every - 1, k = 0; i + lone < n; i += (size_t)every, k++) {
                if (k % 6 == 5)
                    s.r[i] = k % 12 == 5 ? -1.0 : NAN;
                else
                    s.p[k % 3][i] = bad[k % 5];
            }
            if (shuffled) { /* the lone spheres stay last */
                s.n = n - lone;
                spheres_shuffle(&s);
                s.n = n;
            }
            for (size_t i = 0; i < n; i++) s.body[i] = (int32_t)(i % 3) - 1;
            char what[64];
            snprintf(what, sizeof what, "invalid 1 in %d, %s", every,
                     shuffled ? "shuffled" : "in order");
            size_t found = expect_exact(what, &s, 0, 0);
            CHECK(found > n / 10, "%s: only %zu pairs", what, found);
            expect_exact(what, &s, 1, 0);
        }
    spheres_free(&s);
}

/* The extremes are taken two spheres a step, with a scalar tail: whatever
 * index holds the lowest or highest centre on an axis, or the largest
 * radius (a lane, the other lane, the tail of an odd count), the layout
 * must be the one of any other order. 32 spheres in a small cube and one
 * far out (or with a larger radius), moved through every index. */
static void test_nbs3_bounds_any_index(void)
{
    rng_seed(33);
    for (size_t n = 33; n <= 34; n++) {
        spheres s = spheres_new(n);
        for (int what_moves = 0; what_moves < 7; what_moves++) {
            int32_t size0[3] = {0, 0, 0};
            double cell0 = 0;
            for (size_t at = 0; at < n; at++) {
                double o[3] = {20, -20, 40};
                rng_seed(34 + (uint64_t)what_moves);
                put_in_cube(&s, 0, n, o, 2.0, 0.4, 0.5);
                /* the odd one out goes to index `at` */
                size_t odd = n - 1;
                if (what_moves < 6) {
                    int axis = what_moves / 2;
                    s.p[axis][odd] = o[axis] + (what_moves % 2 ? 25.0 : -23.0);
                } else {
                    s.r[odd] = 3.0;
                }
                for (int a = 0; a < 3; a++) {
                    double t = s.p[a][at]; s.p[a][at] = s.p[a][odd]; s.p[a][odd] = t;
                }
                double t = s.r[at]; s.r[at] = s.r[odd]; s.r[odd] = t;
                char what[64];
                snprintf(what, sizeof what, "bounds n=%zu case %d at %zu", n, what_moves, at);
                expect_exact(what, &s, 0, 0);
                nbs_grid_3d g;
                nbs_pairs p;
                nbs_grid_3d_init(&g);
                nbs_pairs_init(&p);
                CHECK(detect(&g, &s, 0, &p) == 0, "%s: detect failed", what);
                int32_t size[3] = {g.nx, g.ny, g.nz};
                if (at == 0) {
                    for (int a = 0; a < 3; a++) size0[a] = size[a];
                    cell0 = g.cell;
                    CHECK(what_moves < 6 ? size[what_moves / 2] >= 16 : g.cell > 6.0,
                          "%s: tables %d %d %d, cell %g: the odd one out not taken", what,
                          size[0], size[1], size[2], g.cell);
                }
                CHECK(size[0] == size0[0] && size[1] == size0[1] && size[2] == size0[2] &&
                          g.cell == cell0,
                      "%s: tables %d %d %d, cell %g; at index 0 %d %d %d, %g", what, size[0],
                      size[1], size[2], g.cell, size0[0], size0[1], size0[2], cell0);
                nbs_grid_3d_free(&g);
                nbs_pairs_free(&p);
            }
        }
        spheres_free(&s);
    }
}

/* The candidate test adds the squares in the order of nbs_spheres_touch,
 * (dx2 + dy2) + dz2. Two pairs (found by search) whose reach squared lies
 * between that sum and the sums of the orders dx2 + (dy2 + dz2) and
 * (dx2 + dz2) + dy2: one touches, one does not, and only that order decides
 * both as the all-pairs check does. Reach is 2r, exact. */
static void test_nbs3_sum_order(void)
{
    static const double cases[2][4] = { /* dx, dy, dz, r */
        {0x1.50ec52f1e7886p-2, 0x1.675f6ce9a4c7ep-1, 0x1.3254aa29f5d02p-1, 0x1.f55d5eb92ca6cp-2},
        {0x1.b836ef5c17e69p-1, 0x1.93c3bae409b98p-2, 0x1.ec1f3a4796418p-2, 0x1.0f9c8f10933aep-1},
    };
    static const int touching[2] = {1, 0};
    spheres s = spheres_new(2);
    for (int k = 0; k < 2; k++) {
        const double *c = cases[k];
        for (int a = 0; a < 3; a++) s.p[a][0] = 0.0, s.p[a][1] = c[a];
        s.r[0] = s.r[1] = c[3];
        double dx2 = c[0] * c[0], dy2 = c[1] * c[1], dz2 = c[2] * c[2];
        double reach2 = (c[3] + c[3]) * (c[3] + c[3]);
        double yz = dy2 + dz2, xz = dx2 + dz2;
        int other1 = dx2 + yz <= reach2, other2 = xz + dy2 <= reach2;
        CHECK(other1 != touching[k] && other2 != touching[k],
              "case %d: not a borderline of the order of the sum", k);
        char what[32];
        snprintf(what, sizeof what, "sum order case %d", k);
        size_t found = expect_exact(what, &s, 0, 0);
        CHECK(found == (size_t)touching[k], "%s: %zu pairs, want %d", what, found, touching[k]);
    }
    spheres_free(&s);
}

/* Rows are taken from y (of the packed copy): a line of spheres along y,
 * touching in twos, has one or two a row, and each walk makes room in the
 * pair list for a row's pairs, so the list stays at its first N pairs. A
 * row taken from x or z would hold the whole line, every sphere the
 * candidate of every other, and the room made for it would outgrow N. */
static void test_nbs3_line_along_y(void)
{
    size_t n = 4096; /* a power of two >= NBS_FIRST_PAIRS: the list starts at N */
    spheres s = spheres_new(n);
    for (size_t i = 0; i < n; i++) {
        s.p[0][i] = 1.0, s.p[2][i] = -2.0, s.r[i] = 0.5;
        s.p[1][i] = 4.0 * (double)(i / 2) + 0.9 * (double)(i % 2);
    }
    nbs_grid_3d g;
    nbs_pairs p;
    nbs_grid_3d_init(&g);
    nbs_pairs_init(&p);
    CHECK(detect(&g, &s, 0, &p) == 0, "line along y: detect failed");
    CHECK(p.count == n / 2, "line along y: %zu pairs, want %zu", p.count, n / 2);
    CHECK(p.capacity <= n, "line along y: the pair list grew to %zu for %zu spheres", p.capacity,
          n);
    nbs_grid_3d_free(&g);
    nbs_pairs_free(&p);
    expect_exact("line along y", &s, 0, 0);
    spheres_free(&s);
}

/* Cells are taken from x (of the packed copy): once a detection is done,
 * each sphere's x-link holds its x cell again (nbs3_row_unmap), the
 * truncation of (x - lowest x) / d on the x-table. */
static void test_nbs3_x_links_hold_x(void)
{
    rng_seed(35);
    size_t n = 501;
    spheres s = spheres_new(n);
    double o[3] = {-7, 3, 11};
    put_in_cube(&s, 0, n, o, 8, 0.2, 0.5);
    nbs_grid_3d g;
    nbs_pairs p;
    nbs_grid_3d_init(&g);
    nbs_pairs_init(&p);
    CHECK(detect(&g, &s, 0, &p) == 0, "x-links: detect failed");
    double lo = s.p[0][0], inv = 1.0 / g.cell;
    for (size_t i = 1; i < n; i++) lo = fmin(lo, s.p[0][i]);
    size_t wrong = 0;
    for (size_t i = 0; i < n; i++) {
        int32_t x = (int32_t)((int64_t)((s.p[0][i] - lo) * inv) & (int64_t)(g.nx - 1));
        wrong += g.next[i].cell != x;
    }
    CHECK(wrong == 0, "x-links: %zu of %zu spheres do not hold their x cell", wrong, n);
    nbs_grid_3d_free(&g);
    nbs_pairs_free(&p);
    spheres_free(&s);
}

/* A grid grown by less than double (1001 spheres, then 1002, then 1500
 * within the room taken) holds room for all of them, its heap is what
 * nbs_memory_bytes_3d counts (the packed copy of a smaller N not left
 * behind), and nbs_grid_3d_free gives it all back (the heap is read where
 * HEAP_COUNTED). One sphere too many for its room is overrun by a few
 * bytes only, so the check fails before a larger overrun can hang. */
static void test_nbs3_grow_and_free(void)
{
    rng_seed(36);
    static const size_t sizes[3] = {1001, 1002, 1500};
    spheres s = spheres_new(1500);
    double o[3] = {5, 5, -5};
    put_in_cube(&s, 0, 1500, o, 11, 0.2, 0.5);
    double before = heap_in_use();
    nbs_grid_3d g;
    nbs_pairs p;
    nbs_grid_3d_init(&g);
    nbs_pairs_init(&p);
    for (int k = 0; k < 3; k++) {
        s.n = sizes[k];
        CHECK(detect(&g, &s, 0, &p) == 0, "grow: detect of %zu failed", s.n);
        CHECK(g.n_capacity >= s.n, "grow: room for %zu spheres, detected %zu", g.n_capacity,
              s.n);
        if (g.n_capacity < s.n) break;
    }
    double grown = heap_in_use() - before, counted = (double)nbs_memory_bytes_3d(&g, &p);
    CHECK(!HEAP_COUNTED || fabs(grown - counted) <= 4096,
          "grow: the heap grew by %.0f, counted %.0f", grown, counted);
    nbs_pairs want;
    nbs_pairs_init(&want);
    nbs_detect_brute_3d(s.n, s.p[0], s.p[1], s.p[2], s.r, NULL, &want);
    check_same_pairs("grown grid", &p, &want);
    nbs_pairs_free(&want);
    nbs_grid_3d_free(&g);
    nbs_pairs_free(&p);
    double left = heap_in_use() - before;
    CHECK(!HEAP_COUNTED || fabs(left) <= 4096, "grow: %.0f bytes left after nbs_grid_3d_free",
          left);
    spheres_free(&s);
}

int main(int argc, char **argv)
{
    static const check_test tests[] = {
        {"test_nbs3_tiny", test_nbs3_tiny},
        {"test_nbs3_random", test_nbs3_random},
        {"test_nbs3_clustered", test_nbs3_clustered},
        {"test_nbs3_sparse", test_nbs3_sparse},
        {"test_nbs3_lattice", test_nbs3_lattice},
        {"test_nbs3_large_against_sweep", test_nbs3_large_against_sweep},
        {"test_nbs3_folding_and_runs", test_nbs3_folding_and_runs},
        {"test_nbs3_bodies", test_nbs3_bodies},
        {"test_nbs3_invalid_spheres", test_nbs3_invalid_spheres},
        {"test_nbs3_integer_ram", test_nbs3_integer_ram},
        {"test_nbs3_reuse", test_nbs3_reuse},
        {"test_nbs3_wrapped_run", test_nbs3_wrapped_run},
        {"test_nbs3_bodies_across_runs", test_nbs3_bodies_across_runs},
        {"test_nbs3_invalid_many_runs", test_nbs3_invalid_many_runs},
        {"test_nbs3_bounds_any_index", test_nbs3_bounds_any_index},
        {"test_nbs3_sum_order", test_nbs3_sum_order},
        {"test_nbs3_line_along_y", test_nbs3_line_along_y},
        {"test_nbs3_x_links_hold_x", test_nbs3_x_links_hold_x},
        {"test_nbs3_grow_and_free", test_nbs3_grow_and_free},
    };
    return check_run(tests, (int)(sizeof tests / sizeof tests[0]), argc, argv);
}
