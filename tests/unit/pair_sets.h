/*
 * pair_sets.h - what the 2D and 3D NBS tests share: a deterministic random
 * source (splitmix64, so a failure reproduces) and the comparison of two
 * pair lists as sets (no self pairs, no duplicates, same members).
 */
#ifndef FDEM_TEST_PAIR_SETS_H
#define FDEM_TEST_PAIR_SETS_H

#include <stdint.h>
#include <stdlib.h>

#include "check.h"
#include "nbs/nbs.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;

static void rng_seed(uint64_t seed) { rng_state = seed * 0x9e3779b97f4a7c15ull + 1; }

/* splitmix64: deterministic, so a failure reproduces */
static double rng_uniform(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
}

static double rng_range(double lo, double hi) { return lo + (hi - lo) * rng_uniform(); }

/* ------------------------------------------------------------ pair sets */

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Pairs as sorted (min << 32 | max) keys; counts self pairs and duplicates. */
static uint64_t *pair_keys(const nbs_pairs *p, int *self, int *dups)
{
    uint64_t *k = malloc((p->count + 1) * sizeof *k);
    *self = 0;
    for (size_t i = 0; i < p->count; i++) {
        uint32_t a = (uint32_t)p->a[i], b = (uint32_t)p->b[i];
        if (a == b) (*self)++;
        k[i] = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
    }
    qsort(k, p->count, sizeof *k, cmp_u64);
    *dups = 0;
    for (size_t i = 1; i < p->count; i++)
        if (k[i] == k[i - 1]) (*dups)++;
    return k;
}

/* Checks got == want as sets, and that got has no self or duplicate pairs. */
static void check_same_pairs(const char *what, const nbs_pairs *got, const nbs_pairs *want)
{
    int self_g, dup_g, self_w, dup_w;
    uint64_t *g = pair_keys(got, &self_g, &dup_g);
    uint64_t *w = pair_keys(want, &self_w, &dup_w);
    CHECK(self_g == 0, "%s: %d self pairs", what, self_g);
    CHECK(dup_g == 0, "%s: %d duplicate pairs", what, dup_g);
    CHECK(self_w == 0 && dup_w == 0, "%s: reference has %d self, %d duplicate pairs",
          what, self_w, dup_w);
    CHECK(got->count == want->count, "%s: %zu pairs, reference %zu", what,
          got->count, want->count);
    size_t common = got->count < want->count ? got->count : want->count;
    size_t first_diff = common;
    for (size_t i = 0; i < common; i++)
        if (g[i] != w[i]) { first_diff = i; break; }
    CHECK(first_diff == common, "%s: first differing pair at rank %zu: (%u,%u) vs (%u,%u)",
          what, first_diff, (unsigned)(g[first_diff] >> 32), (unsigned)g[first_diff],
          (unsigned)(w[first_diff] >> 32), (unsigned)w[first_diff]);
    free(g);
    free(w);
}

#endif /* FDEM_TEST_PAIR_SETS_H */
