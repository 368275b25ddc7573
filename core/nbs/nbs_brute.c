/*
 * nbs_brute.c - all pairs, the reference both NBS detectors are held to
 * (tests/unit/test_nbs*.c and bench/bench_nbs.c): the same circle and
 * sphere tests, the same body rule, the same pair order as a sorted NBS
 * list, in O(N^2). Never called by a step.
 */
#include "nbs_internal.h"

int nbs_detect_brute(size_t n, const double *cx, const double *cy,
                     const double *r, const int32_t *body, nbs_pairs *pairs)
{
    pairs->count = 0;
    if (n > NBS_MAX_CIRCLES) return -1;
    for (size_t i = 0; i < n; i++) {
        if (!nbs_circle_valid(cx[i], cy[i], r[i])) continue;
        for (size_t j = i + 1; j < n; j++) {
            if (!nbs_circle_valid(cx[j], cy[j], r[j])) continue;
            if (!nbs_circles_touch(cx[i], cy[i], r[i], cx[j], cy[j], r[j])) continue;
            if (nbs_same_body(body, (int32_t)i, (int32_t)j)) continue;
            if (nbs_pairs_push(pairs, (int32_t)i, (int32_t)j) != 0) return -1;
        }
    }
    return 0;
}

int nbs_detect_brute_3d(size_t n, const double *cx, const double *cy, const double *cz,
                        const double *r, const int32_t *body, nbs_pairs *pairs)
{
    pairs->count = 0;
    if (n > NBS_MAX_CIRCLES) return -1;
    for (size_t i = 0; i < n; i++) {
        if (!nbs3_sphere_valid(cx[i], cy[i], cz[i], r[i])) continue;
        for (size_t j = i + 1; j < n; j++) {
            if (!nbs3_sphere_valid(cx[j], cy[j], cz[j], r[j])) continue;
            if (!nbs_spheres_touch(cx[i], cy[i], cz[i], r[i], cx[j], cy[j], cz[j], r[j]))
                continue;
            if (nbs_same_body(body, (int32_t)i, (int32_t)j)) continue;
            if (nbs_pairs_push(pairs, (int32_t)i, (int32_t)j) != 0) return -1;
        }
    }
    return 0;
}
