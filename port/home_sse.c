/* SSE2 kernels (x86-64 baseline). */
#include "kernels.h"
#if defined(__SSE2__)
#include <emmintrin.h>

/* 64 lanes held as 8 x 8 uint16 in registers; widened into int32 every 128 rows. */
static void radon_blocks_sse(const uint8_t *base, ptrdiff_t stride, const int16_t *shift, int j0,
                             int n_blocks, const int16_t *row_lo, const int16_t *row_hi,
                             int32_t *out)
{
    const __m128i zero = _mm_setzero_si128();
    int b, k;
    for (b = 0; b < n_blocks; b++) {
        int32_t *acc32 = out + (ptrdiff_t)b * HOME__RADON_BLOCK;
        int p = row_lo[b];
        for (k = 0; k < HOME__RADON_BLOCK; k += 4) _mm_storeu_si128((__m128i *)(void *)(acc32 + k), zero);
        while (p <= row_hi[b]) {
            int end = p + HOME__RADON_ROWS_16BIT - 1 < row_hi[b] ? p + HOME__RADON_ROWS_16BIT - 1 : row_hi[b];
            __m128i a[8];
            for (k = 0; k < 8; k++) a[k] = zero;
            for (; p <= end; p++) {
                const uint8_t *src = base + (ptrdiff_t)p * stride + j0 + b * HOME__RADON_BLOCK + shift[p];
                for (k = 0; k < 4; k++) {
                    __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(src + 16 * k));
                    a[2 * k] = _mm_add_epi16(a[2 * k], _mm_unpacklo_epi8(v, zero));
                    a[2 * k + 1] = _mm_add_epi16(a[2 * k + 1], _mm_unpackhi_epi8(v, zero));
                }
            }
            for (k = 0; k < 8; k++) {
                __m128i lo = _mm_unpacklo_epi16(a[k], zero), hi = _mm_unpackhi_epi16(a[k], zero);
                __m128i *dst = (__m128i *)(void *)(acc32 + 8 * k);
                _mm_storeu_si128(dst, _mm_add_epi32(_mm_loadu_si128(dst), lo));
                _mm_storeu_si128(dst + 1, _mm_add_epi32(_mm_loadu_si128(dst + 1), hi));
            }
        }
    }
}

void home__nearest2_l1_sse(const uint8_t *query, const uint8_t *cands, ptrdiff_t stride, int n,
                            int *best, int *d1, int *d2)
{
    const __m128i q = _mm_loadu_si128((const __m128i *)(const void *)query);
    int j, b = -1, m1 = 1 << 30, m2 = 1 << 30;
    for (j = 0; j < n; j++) {
        __m128i c = _mm_loadu_si128((const __m128i *)(const void *)(cands + (ptrdiff_t)j * stride));
        __m128i sad = _mm_sad_epu8(q, c);  /* two 64-bit partial sums */
        int d = _mm_cvtsi128_si32(_mm_add_epi32(sad, _mm_srli_si128(sad, 8)));
        if (d < m1) { m2 = m1; m1 = d; b = j; }
        else if (d < m2) m2 = d;
    }
    *best = b; *d1 = m1; *d2 = m2;
}

/* Same multiply-then-add order as the scalar reference, 4 outputs at a time: bit-identical. */
/* The taps in the reference's order, one product and one sum each; the default radius 4 (sigma
 * 1.3) unrolled with its nine broadcast taps in registers, other radii by the generic loop. */
#define SMOOTH_TAP(k, src) acc = _mm_add_ps(acc, _mm_mul_ps(t##k, _mm_loadu_ps(src)))
#define SMOOTH_TAPS_4 \
    const __m128 t0 = _mm_set1_ps(taps[0]), t1 = _mm_set1_ps(taps[1]), t2 = _mm_set1_ps(taps[2]), \
                 t3 = _mm_set1_ps(taps[3]), t4 = _mm_set1_ps(taps[4]), t5 = _mm_set1_ps(taps[5]), \
                 t6 = _mm_set1_ps(taps[6]), t7 = _mm_set1_ps(taps[7]), t8 = _mm_set1_ps(taps[8])

void home__smooth_row_sse(const float *in, float *out, int n, const float *taps, int radius)
{
    int i = radius, k;
    if (radius == 4) {
        SMOOTH_TAPS_4;
        for (; i + 4 <= n - radius; i += 4) {
            const float *p = in + i - 4;
            __m128 acc = _mm_setzero_ps();
            SMOOTH_TAP(0, p); SMOOTH_TAP(1, p + 1); SMOOTH_TAP(2, p + 2); SMOOTH_TAP(3, p + 3);
            SMOOTH_TAP(4, p + 4); SMOOTH_TAP(5, p + 5); SMOOTH_TAP(6, p + 6); SMOOTH_TAP(7, p + 7);
            SMOOTH_TAP(8, p + 8);
            _mm_storeu_ps(out + i, acc);
        }
    }
    for (; i + 4 <= n - radius; i += 4) {
        __m128 acc = _mm_setzero_ps();
        for (k = 0; k <= 2 * radius; k++)
            acc = _mm_add_ps(acc, _mm_mul_ps(_mm_set1_ps(taps[k]), _mm_loadu_ps(in + i - radius + k)));
        _mm_storeu_ps(out + i, acc);
    }
    /* the last < 4 outputs by the reference, on a window that starts at output i */
    home__kernels_scalar.smooth_row(in + i - radius, out + i - radius, n - i + radius, taps, radius);
}

void home__smooth_cols_sse(const float *const *rows, float *out, int n, const float *taps,
                           int radius)
{
    int i = 0, k;
    if (radius == 4) {
        SMOOTH_TAPS_4;
        const float *r0 = rows[0], *r1 = rows[1], *r2 = rows[2], *r3 = rows[3], *r4 = rows[4],
                    *r5 = rows[5], *r6 = rows[6], *r7 = rows[7], *r8 = rows[8];
        for (; i + 4 <= n; i += 4) {
            __m128 acc = _mm_setzero_ps();
            SMOOTH_TAP(0, r0 + i); SMOOTH_TAP(1, r1 + i); SMOOTH_TAP(2, r2 + i); SMOOTH_TAP(3, r3 + i);
            SMOOTH_TAP(4, r4 + i); SMOOTH_TAP(5, r5 + i); SMOOTH_TAP(6, r6 + i); SMOOTH_TAP(7, r7 + i);
            SMOOTH_TAP(8, r8 + i);
            _mm_storeu_ps(out + i, acc);
        }
    }
    for (; i + 4 <= n; i += 4) {
        __m128 acc = _mm_setzero_ps();
        for (k = 0; k <= 2 * radius; k++)
            acc = _mm_add_ps(acc, _mm_mul_ps(_mm_set1_ps(taps[k]), _mm_loadu_ps(rows[k] + i)));
        _mm_storeu_ps(out + i, acc);
    }
    if (i < n) {
        const float *tail[2 * HOME__MAX_TAPS_RADIUS + 1];
        for (k = 0; k <= 2 * radius; k++) tail[k] = rows[k] + i;
        home__kernels_scalar.smooth_cols(tail, out + i, n - i, taps, radius);
    }
}
#undef SMOOTH_TAP
#undef SMOOTH_TAPS_4

/* 16 outputs per step: rows summed in 16-bit lanes, neighbours paired by pmaddwd with ones (twice
 * for ds = 4), rounded and packed back to bytes; the tail by the reference. */
void home__box_down_sse(const uint8_t *src, ptrdiff_t stride, int ds, uint8_t *out, int out_w)
{
    const __m128i zero = _mm_setzero_si128(), ones = _mm_set1_epi16(1);
    const int shift = ds == 2 ? 2 : 4;
    const __m128i half = _mm_set1_epi32(1 << (shift - 1));
    int x = 0, v, c;
    for (; x + 16 <= out_w; x += 16) {
        __m128i q[4]; /* four outputs per 32-bit lane group */
        for (c = 0; c < 4; c++) {
            /* the source bytes of outputs x + 4c .. x + 4c + 3 */
            const uint8_t *s0 = src + ds * (x + 4 * c);
            __m128i pairs;
            if (ds == 4) {
                __m128i lo = zero, hi = zero;
                for (v = 0; v < 4; v++) {
                    __m128i b = _mm_loadu_si128((const __m128i *)(const void *)(s0 + (ptrdiff_t)v * stride));
                    lo = _mm_add_epi16(lo, _mm_unpacklo_epi8(b, zero));
                    hi = _mm_add_epi16(hi, _mm_unpackhi_epi8(b, zero));
                }
                pairs = _mm_packs_epi32(_mm_madd_epi16(lo, ones), _mm_madd_epi16(hi, ones));
                q[c] = _mm_madd_epi16(pairs, ones);
            } else {
                __m128i b0 = _mm_loadl_epi64((const __m128i *)(const void *)s0);
                __m128i b1 = _mm_loadl_epi64((const __m128i *)(const void *)(s0 + stride));
                q[c] = _mm_madd_epi16(_mm_add_epi16(_mm_unpacklo_epi8(b0, zero), _mm_unpacklo_epi8(b1, zero)), ones);
            }
            q[c] = _mm_srai_epi32(_mm_add_epi32(q[c], half), shift);
        }
        _mm_storeu_si128((__m128i *)(void *)(out + x),
                         _mm_packus_epi16(_mm_packs_epi32(q[0], q[1]), _mm_packs_epi32(q[2], q[3])));
    }
    if (x < out_w) home__kernels_scalar.box_down(src + ds * x, stride, ds, out + x, out_w - x);
}

/* Four bins per step: the largest and smallest of the eight neighbours, then the sign test;
 * most steps have no candidate and cost one movemask. */
int home__extremum_candidates_sse(const float *up, const float *mid, const float *down, int n,
                                  int *idx)
{
    const __m128 zero = _mm_setzero_ps();
    int i, count = 0;
    for (i = 1; i + 4 <= n - 1; i += 4) {
        __m128 v = _mm_loadu_ps(mid + i);
        __m128 a = _mm_loadu_ps(up + i - 1), b = _mm_loadu_ps(up + i), c = _mm_loadu_ps(up + i + 1);
        __m128 d = _mm_loadu_ps(mid + i - 1), e = _mm_loadu_ps(mid + i + 1);
        __m128 f = _mm_loadu_ps(down + i - 1), g = _mm_loadu_ps(down + i), h = _mm_loadu_ps(down + i + 1);
        __m128 hi = _mm_max_ps(_mm_max_ps(_mm_max_ps(a, b), _mm_max_ps(c, d)),
                               _mm_max_ps(_mm_max_ps(e, f), _mm_max_ps(g, h)));
        __m128 lo = _mm_min_ps(_mm_min_ps(_mm_min_ps(a, b), _mm_min_ps(c, d)),
                               _mm_min_ps(_mm_min_ps(e, f), _mm_min_ps(g, h)));
        int mask = _mm_movemask_ps(_mm_or_ps(_mm_and_ps(_mm_cmpgt_ps(v, zero), _mm_cmpgt_ps(v, hi)),
                                             _mm_and_ps(_mm_cmplt_ps(v, zero), _mm_cmplt_ps(v, lo))));
        while (mask) {
            int lane = mask & 1 ? 0 : mask & 2 ? 1 : mask & 4 ? 2 : 3;
            idx[count++] = i + lane;
            mask &= mask - 1;
        }
    }
    for (; i < n - 1; i++)
        if (home__is_extremum(up, mid, down, i)) idx[count++] = i;
    return count;
}

const home__kernels home__kernels_sse = {
    .name = "sse",
    .radon_blocks = radon_blocks_sse,
    .nearest2_l1 = home__nearest2_l1_sse,
    .smooth_row = home__smooth_row_sse,
    .smooth_cols = home__smooth_cols_sse,
    .box_down = home__box_down_sse,
    .extremum_candidates = home__extremum_candidates_sse,
    .line_ends = home__line_ends_scalar,
    .resample = home__resample_scalar,
    .line_fit = &home__line_fit_scalar,
};
#else
typedef int home__sse_unavailable; /* ISO C forbids an empty translation unit */
#endif
