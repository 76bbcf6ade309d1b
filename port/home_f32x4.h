/* The HOME kernels whose SSE2 and NEON versions are the same four-lane float algorithm, written
 * once on port/simd_f32x4.h and included by port/home_sse.c and port/home_neon.c. Body only: each
 * returns how far it got, and the callers (src/smooth.c, src/extrema.c) finish with the
 * reference's arithmetic. */
#ifndef HOME_HOME_F32X4_H
#define HOME_HOME_F32X4_H
#include "kernels.h"
#include "simd_f32x4.h"

/* The taps in the reference's order, one product and one sum each; the default radius 4 (sigma
 * 1.3) unrolled with its nine broadcast taps in registers, other radii by the generic loop. */
#define SMOOTH_TAP(k, src) acc = F4_ADD(acc, F4_MUL(t[k], F4_LOAD(src)))
#define SMOOTH_TAPS_4                                                                            \
    home__f4 t[9];                                                                               \
    for (k = 0; k < 9; k++) t[k] = F4_SET1(taps[k])

static int smooth_row_f4(const float *in, float *out, int n, const float *taps, int radius)
{
    int i = radius, k;
    if (radius == 4) {
        SMOOTH_TAPS_4;
        for (; i + 4 <= n - radius; i += 4) {
            const float *p = in + i - 4;
            home__f4 acc = F4_ZERO();
            SMOOTH_TAP(0, p); SMOOTH_TAP(1, p + 1); SMOOTH_TAP(2, p + 2); SMOOTH_TAP(3, p + 3);
            SMOOTH_TAP(4, p + 4); SMOOTH_TAP(5, p + 5); SMOOTH_TAP(6, p + 6); SMOOTH_TAP(7, p + 7);
            SMOOTH_TAP(8, p + 8);
            F4_STORE(out + i, acc);
        }
    }
    for (; i + 4 <= n - radius; i += 4) {
        home__f4 acc = F4_ZERO();
        for (k = 0; k <= 2 * radius; k++)
            acc = F4_ADD(acc, F4_MUL(F4_SET1(taps[k]), F4_LOAD(in + i - radius + k)));
        F4_STORE(out + i, acc);
    }
    return i;
}

static int smooth_cols_f4(const float *const *rows, float *out, int n, const float *taps,
                          int radius)
{
    int i = 0, k;
    if (radius == 4) {
        SMOOTH_TAPS_4;
        const float *r0 = rows[0], *r1 = rows[1], *r2 = rows[2], *r3 = rows[3], *r4 = rows[4],
                    *r5 = rows[5], *r6 = rows[6], *r7 = rows[7], *r8 = rows[8];
        for (; i + 4 <= n; i += 4) {
            home__f4 acc = F4_ZERO();
            SMOOTH_TAP(0, r0 + i); SMOOTH_TAP(1, r1 + i); SMOOTH_TAP(2, r2 + i);
            SMOOTH_TAP(3, r3 + i); SMOOTH_TAP(4, r4 + i); SMOOTH_TAP(5, r5 + i);
            SMOOTH_TAP(6, r6 + i); SMOOTH_TAP(7, r7 + i); SMOOTH_TAP(8, r8 + i);
            F4_STORE(out + i, acc);
        }
    }
    for (; i + 4 <= n; i += 4) {
        home__f4 acc = F4_ZERO();
        for (k = 0; k <= 2 * radius; k++)
            acc = F4_ADD(acc, F4_MUL(F4_SET1(taps[k]), F4_LOAD(rows[k] + i)));
        F4_STORE(out + i, acc);
    }
    return i;
}
#undef SMOOTH_TAP
#undef SMOOTH_TAPS_4

/* Four bins per step: the largest and smallest of the eight neighbours, then the sign test;
 * most steps have no candidate. */
static int extremum_candidates_f4(const float *up, const float *mid, const float *down, int n,
                                  int *idx, int *end)
{
    const home__f4 zero = F4_ZERO();
    int i, count = 0, lane;
    for (i = 1; i + 4 <= n - 1; i += 4) {
        const home__f4 v = F4_LOAD(mid + i);
        const home__f4 a = F4_LOAD(up + i - 1), b = F4_LOAD(up + i), c = F4_LOAD(up + i + 1);
        const home__f4 d = F4_LOAD(mid + i - 1), e = F4_LOAD(mid + i + 1);
        const home__f4 f = F4_LOAD(down + i - 1), g = F4_LOAD(down + i);
        const home__f4 h = F4_LOAD(down + i + 1);
        const home__f4 hi = F4_MAX(F4_MAX(F4_MAX(a, b), F4_MAX(c, d)),
                                   F4_MAX(F4_MAX(e, f), F4_MAX(g, h)));
        const home__f4 lo = F4_MIN(F4_MIN(F4_MIN(a, b), F4_MIN(c, d)),
                                   F4_MIN(F4_MIN(e, f), F4_MIN(g, h)));
        const int mask = M4_BITS(M4_OR(M4_AND(F4_GT(v, zero), F4_GT(v, hi)),
                                       M4_AND(F4_LT(v, zero), F4_LT(v, lo))));
        for (lane = 0; mask >> lane; lane++)
            if (mask >> lane & 1) idx[count++] = i + lane;
    }
    *end = i;
    return count;
}
#endif
