/* numpy's default_rng in portable C: SeedSequence (numpy/random/bit_generator.pyx) feeding PCG64
 * (XSL-RR 128/64, numpy/random/src/pcg64) and Generator.uniform (low + (high - low) * next_double).
 * The native FMU draws its random line, ripple and floor phases with it, so a given `seed` gives the
 * phases numpy.random.default_rng(seed) / default_rng((seed, k)) gives the Python FMU and rwadist
 * (tests/test_fmu_native.py compares them bit for bit).  128-bit arithmetic on two uint64 halves:
 * no compiler extension needed. */
#ifndef RWADIST_RNG_H
#define RWADIST_RNG_H
#include <stdint.h>
#include <stddef.h>

typedef struct { uint64_t hi, lo; } rw_u128;

static rw_u128 rw_u128_add(rw_u128 a, rw_u128 b)
{
    rw_u128 r;
    r.lo = a.lo + b.lo;
    r.hi = a.hi + b.hi + (r.lo < a.lo);
    return r;
}

static uint64_t rw_mulhi64(uint64_t a, uint64_t b)
{
    const uint64_t a0 = a & 0xffffffffu, a1 = a >> 32, b0 = b & 0xffffffffu, b1 = b >> 32;
    const uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    const uint64_t mid = (p00 >> 32) + (p01 & 0xffffffffu) + (p10 & 0xffffffffu);
    return p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
}

static rw_u128 rw_u128_mul(rw_u128 a, rw_u128 b)
{
    rw_u128 r;
    r.lo = a.lo * b.lo;
    r.hi = rw_mulhi64(a.lo, b.lo) + a.hi * b.lo + a.lo * b.hi;
    return r;
}

typedef struct { rw_u128 state, inc; } rw_pcg64;

static void rw_pcg64_step(rw_pcg64 *g)
{
    static const rw_u128 mult = {0x2360ED051FC65DA4ULL, 0x4385DF649FCCF645ULL};
    g->state = rw_u128_add(rw_u128_mul(g->state, mult), g->inc);
}

static uint64_t rw_pcg64_next(rw_pcg64 *g)
{
    rw_pcg64_step(g);
    const uint64_t x = g->state.hi ^ g->state.lo;
    const unsigned rot = (unsigned)(g->state.hi >> 58);
    return (x >> rot) | (x << ((64u - rot) & 63u));
}

/* SeedSequence(entropy words).generate_state(4, uint64) -> PCG64 seeding (pcg64_set_seed) */
static void rw_default_rng(rw_pcg64 *g, const uint32_t *entropy, size_t n_entropy)
{
    enum { POOL = 4 };
    const uint32_t INIT_A = 0x43b0d7e5u, MULT_A = 0x931e8875u, INIT_B = 0x8b51f9ddu, MULT_B = 0x58f38dedu;
    const uint32_t MIX_L = 0xca01f9ddu, MIX_R = 0x4973f715u;
    uint32_t pool[POOL], hash = INIT_A;
#define RW_HASHMIX(v, out)            \
    do {                              \
        uint32_t val_ = (v) ^ hash;   \
        hash *= MULT_A;               \
        val_ *= hash;                 \
        val_ ^= val_ >> 16;           \
        (out) = val_;                 \
    } while (0)
#define RW_MIX(x, y, out)                              \
    do {                                               \
        uint32_t r_ = (MIX_L * (x)) - (MIX_R * (y));   \
        r_ ^= r_ >> 16;                                \
        (out) = r_;                                    \
    } while (0)
    for (size_t i = 0; i < POOL; i++)
        RW_HASHMIX(i < n_entropy ? entropy[i] : 0u, pool[i]);
    for (size_t s = 0; s < POOL; s++)
        for (size_t d = 0; d < POOL; d++)
            if (s != d) {
                uint32_t hm;
                RW_HASHMIX(pool[s], hm);
                RW_MIX(pool[d], hm, pool[d]);
            }
    for (size_t s = POOL; s < n_entropy; s++)
        for (size_t d = 0; d < POOL; d++) {
            uint32_t hm;
            RW_HASHMIX(entropy[s], hm);
            RW_MIX(pool[d], hm, pool[d]);
        }
#undef RW_HASHMIX
#undef RW_MIX
    uint32_t words[8];
    uint32_t hb = INIT_B;
    for (size_t i = 0; i < 8; i++) {
        uint32_t v = pool[i % POOL];
        v ^= hb;
        hb *= MULT_B;
        v *= hb;
        v ^= v >> 16;
        words[i] = v;
    }
    uint64_t s64[4];
    for (size_t i = 0; i < 4; i++)
        s64[i] = (uint64_t)words[2 * i] | ((uint64_t)words[2 * i + 1] << 32);
    /* pcg64_set_seed(seed = s64[0:2], inc = s64[2:4]): 128-bit values with the first word high */
    const rw_u128 initstate = {s64[0], s64[1]}, initseq = {s64[2], s64[3]};
    g->state.hi = g->state.lo = 0;
    g->inc.hi = (initseq.hi << 1) | (initseq.lo >> 63);
    g->inc.lo = (initseq.lo << 1) | 1u;
    rw_pcg64_step(g);
    g->state = rw_u128_add(g->state, initstate);
    rw_pcg64_step(g);
}

/* default_rng(seed) for seed >= 0 (seed < 2^32: one entropy word), then, when key >= 0,
 * default_rng((seed, key)) (entropy words [seed, key]) */
static void rw_rng_seed(rw_pcg64 *g, uint32_t seed, int key)
{
    uint32_t e[2] = {seed, (uint32_t)key};
    rw_default_rng(g, e, key >= 0 ? 2 : 1);
}

/* Generator.uniform(low, high): low + (high - low) * ((next64 >> 11) * 2^-53) */
static double rw_uniform(rw_pcg64 *g, double low, double high)
{
    return low + (high - low) * ((double)(rw_pcg64_next(g) >> 11) * (1.0 / 9007199254740992.0));
}
#endif
