/* The one test runner: runs every test in tests/test_list.h (or those whose name contains argv[1])
 * and ends with "N passed, N failed". Exit status is non-zero when anything failed.
 * PLUME_TEST_SKIP, a comma-separated list of substrings, leaves out the tests whose names contain
 * one (make asan: the tests that only run the apps/ binaries, which are not the sanitised build). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double wall(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#include "harness.h"
#include "../lib/core/openmp_env.h"

int plume_test_failures;

#define PLUME_TEST(name) void name(void);
#include "test_list.h"
#undef PLUME_TEST

typedef struct {
    const char *name;
    void (*fn)(void);
} test_case;

static const test_case all_tests[] = {
#define PLUME_TEST(name) {#name, name},
#include "test_list.h"
#undef PLUME_TEST
};

/* 1 when name contains one of the comma-separated substrings of list (NULL: none) */
static int listed(const char *name, const char *list)
{
    while (list && *list) {
        const char *end = strchr(list, ',');
        const size_t n = end ? (size_t)(end - list) : strlen(list);
        char part[128];
        if (n > 0 && n < sizeof part) {
            memcpy(part, list, n);
            part[n] = '\0';
            if (strstr(name, part))
                return 1;
        }
        list = end ? end + 1 : NULL;
    }
    return 0;
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    const char *filter = argc > 1 ? argv[1] : NULL, *skip = getenv("PLUME_TEST_SKIP");
    int passed = 0, failed = 0, skipped = 0;
    for (size_t i = 0; i < sizeof all_tests / sizeof all_tests[0]; i++) {
        if (filter && !strstr(all_tests[i].name, filter))
            continue;
        if (listed(all_tests[i].name, skip)) {
            skipped++;
            continue;
        }
        plume_test_failures = 0;
        double t0 = wall();
        fprintf(stderr, "[ RUN  ] %s\n", all_tests[i].name);
        all_tests[i].fn();
        double s = wall() - t0;
        if (plume_test_failures == 0) {
            passed++;
            fprintf(stderr, "[  OK  ] %s (%.2f s)\n", all_tests[i].name, s);
        } else {
            failed++;
            fprintf(stderr, "[ FAIL ] %s (%d checks)\n", all_tests[i].name, plume_test_failures);
        }
    }
    if (skipped)
        fprintf(stderr, "%d left out (PLUME_TEST_SKIP=%s)\n", skipped, skip);
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
