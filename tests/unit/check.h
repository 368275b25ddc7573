/*
 * check.h - the unit-test harness: a test is a function registered in a
 * table; CHECK_* record failures with file:line and the values involved.
 * Each binary prints one "PASS name" or "FAIL name" line per test, which
 * tests/run_tests.sh counts into the closing "N passed, N failed" line.
 */
#ifndef FDEM_CHECK_H
#define FDEM_CHECK_H

#include <math.h>
#include <stdio.h>
#include <string.h>

static int check_failures_in_test;

#define CHECK(cond, ...)                                                     \
    do {                                                                     \
        if (!(cond)) {                                                       \
            check_failures_in_test++;                                        \
            fprintf(stderr, "  %s:%d: check failed: %s: ", __FILE__,        \
                    __LINE__, #cond);                                        \
            fprintf(stderr, __VA_ARGS__);                                    \
            fputc('\n', stderr);                                             \
        }                                                                    \
    } while (0)

/* |got - want| <= tol */
#define CHECK_NEAR(got, want, tol)                                           \
    do {                                                                     \
        double g_ = (got), w_ = (want), t_ = (tol);                          \
        CHECK(fabs(g_ - w_) <= t_, "got %.12g, want %.12g, tolerance %.3g",  \
              g_, w_, t_);                                                   \
    } while (0)

/* relative: |got - want| <= rel * |want| */
#define CHECK_REL(got, want, rel)                                            \
    do {                                                                     \
        double g_ = (got), w_ = (want), r_ = (rel);                          \
        CHECK(fabs(g_ - w_) <= r_ * fabs(w_),                                \
              "got %.12g, want %.12g, relative error %.3g > %.3g", g_, w_,   \
              w_ != 0 ? fabs(g_ - w_) / fabs(w_) : INFINITY, r_);            \
    } while (0)

typedef struct check_test {
    const char *name;
    void (*fn)(void);
} check_test;

/* Runs the tests named on the command line (all when none) and returns the
 * process exit code. */
static inline int check_run(const check_test *tests, int count, int argc, char **argv)
{
    int failed = 0;
    for (int i = 0; i < count; i++) {
        int wanted = argc <= 1;
        for (int a = 1; a < argc; a++)
            if (strcmp(argv[a], tests[i].name) == 0) wanted = 1;
        if (!wanted) continue;
        check_failures_in_test = 0;
        tests[i].fn();
        printf("%s %s\n", check_failures_in_test ? "FAIL" : "PASS", tests[i].name);
        fflush(stdout);
        if (check_failures_in_test) failed++;
    }
    return failed ? 1 : 0;
}

#define CHECK_MAIN(...)                                                      \
    int main(int argc, char **argv)                                          \
    {                                                                        \
        static const check_test tests_[] = {__VA_ARGS__};                    \
        return check_run(tests_, (int)(sizeof tests_ / sizeof tests_[0]),    \
                         argc, argv);                                        \
    }
#define T(fn) {#fn, fn}

#endif
