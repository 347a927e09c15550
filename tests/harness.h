/* Minimal test harness: each test file defines `void test_<module>(void)` functions registered in
 * tests/run_tests.c; CHECK records a failure with file:line and keeps going. The runner ends with
 * the line "N passed, N failed" that CI tools understand. */
#ifndef PLUME_TEST_HARNESS_H
#define PLUME_TEST_HARNESS_H

#include <math.h>
#include <stdio.h>

extern int plume_test_failures; /* failures in the current test */

#define CHECK(cond)                                                                        \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            plume_test_failures++;                                                         \
            fprintf(stderr, "    CHECK failed %s:%d: %s\n", __FILE__, __LINE__, #cond);     \
        }                                                                                  \
    } while (0)

/* |a - b| <= tol * max(|b|, floor) : relative with an absolute floor */
#define CHECK_REL(a, b, tol, floor)                                                        \
    do {                                                                                   \
        double ca_ = (a), cb_ = (b);                                                       \
        double cs_ = fabs(cb_) > (floor) ? fabs(cb_) : (floor);                            \
        if (!(fabs(ca_ - cb_) <= (tol) * cs_)) {                                           \
            plume_test_failures++;                                                         \
            fprintf(stderr, "    CHECK_REL failed %s:%d: %s = %.12g vs %s = %.12g (rel %.3g > %.3g)\n", \
                    __FILE__, __LINE__, #a, ca_, #b, cb_, fabs(ca_ - cb_) / cs_, (double)(tol)); \
        }                                                                                  \
    } while (0)

#endif
