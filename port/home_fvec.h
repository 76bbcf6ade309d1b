/* The HOME kernels whose SSE2, NEON and AVX2 versions are the same float algorithm, written once
 * on a vector layer of FV_LANES floats that the includer provides (port/simd_f32x4.h for
 * port/home_sse.c and port/home_neon.c, port/simd_f32x8.h for port/home_avx2.c). Body only: each
 * returns how far it got, and the callers (src/smooth.c, src/extrema.c) finish with the
 * reference's arithmetic. */
#ifndef HOME_HOME_FVEC_H
#define HOME_HOME_FVEC_H
#include "kernels.h"
#ifndef FV_LANES
#error "include a vector layer (port/simd_f32x4.h, port/simd_f32x8.h) first"
#endif

/* The taps in the reference's order, one product and one sum each; the default radius 4 (sigma
 * 1.3) unrolled with its nine broadcast taps in registers, other radii by the generic loop. */
#define SMOOTH_TAP(k, src) acc = FV_ADD(acc, FV_MUL(t[k], FV_LOAD(src)))
#define SMOOTH_TAPS_4                                                                            \
    home__fv t[9];                                                                               \
    for (k = 0; k < 9; k++) t[k] = FV_SET1(taps[k])

static int smooth_row_fv(const float *in, float *out, int n, const float *taps, int radius)
{
    int i = radius, k;
    if (radius == 4) {
        SMOOTH_TAPS_4;
        for (; i + FV_LANES <= n - radius; i += FV_LANES) {
            const float *p = in + i - 4;
            home__fv acc = FV_ZERO();
            SMOOTH_TAP(0, p); SMOOTH_TAP(1, p + 1); SMOOTH_TAP(2, p + 2); SMOOTH_TAP(3, p + 3);
            SMOOTH_TAP(4, p + 4); SMOOTH_TAP(5, p + 5); SMOOTH_TAP(6, p + 6); SMOOTH_TAP(7, p + 7);
            SMOOTH_TAP(8, p + 8);
            FV_STORE(out + i, acc);
        }
    }
    for (; i + FV_LANES <= n - radius; i += FV_LANES) {
        home__fv acc = FV_ZERO();
        for (k = 0; k <= 2 * radius; k++)
            acc = FV_ADD(acc, FV_MUL(FV_SET1(taps[k]), FV_LOAD(in + i - radius + k)));
        FV_STORE(out + i, acc);
    }
    return i;
}

static int smooth_cols_fv(const float *const *rows, float *out, int n, const float *taps,
                          int radius)
{
    int i = 0, k;
    if (radius == 4) {
        SMOOTH_TAPS_4;
        const float *r0 = rows[0], *r1 = rows[1], *r2 = rows[2], *r3 = rows[3], *r4 = rows[4],
                    *r5 = rows[5], *r6 = rows[6], *r7 = rows[7], *r8 = rows[8];
        for (; i + FV_LANES <= n; i += FV_LANES) {
            home__fv acc = FV_ZERO();
            SMOOTH_TAP(0, r0 + i); SMOOTH_TAP(1, r1 + i); SMOOTH_TAP(2, r2 + i);
            SMOOTH_TAP(3, r3 + i); SMOOTH_TAP(4, r4 + i); SMOOTH_TAP(5, r5 + i);
            SMOOTH_TAP(6, r6 + i); SMOOTH_TAP(7, r7 + i); SMOOTH_TAP(8, r8 + i);
            FV_STORE(out + i, acc);
        }
    }
    for (; i + FV_LANES <= n; i += FV_LANES) {
        home__fv acc = FV_ZERO();
        for (k = 0; k <= 2 * radius; k++)
            acc = FV_ADD(acc, FV_MUL(FV_SET1(taps[k]), FV_LOAD(rows[k] + i)));
        FV_STORE(out + i, acc);
    }
    return i;
}
#undef SMOOTH_TAP
#undef SMOOTH_TAPS_4

/* FV_LANES bins per step: the largest and smallest of the eight neighbours, then the sign test;
 * most steps have no candidate. */
static int extremum_candidates_fv(const float *up, const float *mid, const float *down, int n,
                                  int *idx, int *end)
{
    const home__fv zero = FV_ZERO();
    int i, count = 0, lane;
    for (i = 1; i + FV_LANES <= n - 1; i += FV_LANES) {
        const home__fv v = FV_LOAD(mid + i);
        const home__fv a = FV_LOAD(up + i - 1), b = FV_LOAD(up + i), c = FV_LOAD(up + i + 1);
        const home__fv d = FV_LOAD(mid + i - 1), e = FV_LOAD(mid + i + 1);
        const home__fv f = FV_LOAD(down + i - 1), g = FV_LOAD(down + i);
        const home__fv h = FV_LOAD(down + i + 1);
        const home__fv hi = FV_MAX(FV_MAX(FV_MAX(a, b), FV_MAX(c, d)),
                                   FV_MAX(FV_MAX(e, f), FV_MAX(g, h)));
        const home__fv lo = FV_MIN(FV_MIN(FV_MIN(a, b), FV_MIN(c, d)),
                                   FV_MIN(FV_MIN(e, f), FV_MIN(g, h)));
        const int mask = MV_BITS(MV_OR(MV_AND(FV_GT(v, zero), FV_GT(v, hi)),
                                       MV_AND(FV_LT(v, zero), FV_LT(v, lo))));
        for (lane = 0; mask >> lane; lane++)
            if (mask >> lane & 1) idx[count++] = i + lane;
    }
    *end = i;
    return count;
}
#endif
