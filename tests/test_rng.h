/* Deterministic random numbers for tests: xorshift64*, seeded per test (never rand()). */
#ifndef PLUME_TEST_RNG_H
#define PLUME_TEST_RNG_H

#include <stdint.h>

typedef struct {
    uint64_t s;
} rng64;

/* uniform in [0, 1) */
static inline double urand(rng64 *r)
{
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    return (double)((r->s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

/* uniform in [a, b) */
static inline double urange(rng64 *r, double a, double b)
{
    return a + (b - a) * urand(r);
}

#endif
