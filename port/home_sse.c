/* SSE2 kernels (x86-64 baseline). */
#include "kernels.h"
#if defined(__SSE2__)
#include "simd_f32x4.h"
#include "home_fvec.h"
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
        for (k = 0; k < HOME__RADON_BLOCK; k += 4)
            _mm_storeu_si128((__m128i *)(void *)(acc32 + k), zero);
        while (p <= row_hi[b]) {
            int end = p + HOME__RADON_ROWS_16BIT - 1 < row_hi[b] ? p + HOME__RADON_ROWS_16BIT - 1
                                                                 : row_hi[b];
            __m128i a[8];
            for (k = 0; k < 8; k++) a[k] = zero;
            for (; p <= end; p++) {
                const uint8_t *src = base + (ptrdiff_t)p * stride + j0 + b * HOME__RADON_BLOCK +
                                     shift[p];
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
    int j = 0, k, b = -1, m1 = 1 << 30, m2 = 1 << 30;
    /* four candidates per step, looked at one by one (in order, as below) only when one of
     * them is closer than the second best: once those two are small, hardly ever */
    for (; j + 4 <= n; j += 4) {
        const uint8_t *c = cands + (ptrdiff_t)j * stride;
        const __m128i s0 = _mm_sad_epu8(q, _mm_loadu_si128((const __m128i *)(const void *)c)),
                      s1 = _mm_sad_epu8(
                          q, _mm_loadu_si128((const __m128i *)(const void *)(c + stride))),
                      s2 = _mm_sad_epu8(
                          q, _mm_loadu_si128((const __m128i *)(const void *)(c + 2 * stride))),
                      s3 = _mm_sad_epu8(
                          q, _mm_loadu_si128((const __m128i *)(const void *)(c + 3 * stride)));
        /* each candidate's two partial sums added: d0, d1 in the low halves of s01, ... */
        const __m128i s01 = _mm_add_epi32(_mm_unpacklo_epi64(s0, s1), _mm_unpackhi_epi64(s0, s1)),
                      s23 = _mm_add_epi32(_mm_unpacklo_epi64(s2, s3), _mm_unpackhi_epi64(s2, s3));
        const __m128i d = _mm_castps_si128(_mm_shuffle_ps(
            _mm_castsi128_ps(s01), _mm_castsi128_ps(s23), _MM_SHUFFLE(2, 0, 2, 0)));
        int dist[4];
        if (!_mm_movemask_epi8(_mm_cmplt_epi32(d, _mm_set1_epi32(m2)))) continue;
        _mm_storeu_si128((__m128i *)(void *)dist, d);
        for (k = 0; k < 4; k++) {
            if (dist[k] < m1) { m2 = m1; m1 = dist[k]; b = j + k; }
            else if (dist[k] < m2) m2 = dist[k];
        }
    }
    for (; j < n; j++) {
        __m128i c = _mm_loadu_si128((const __m128i *)(const void *)(cands + (ptrdiff_t)j * stride));
        __m128i sad = _mm_sad_epu8(q, c);  /* two 64-bit partial sums */
        int d = _mm_cvtsi128_si32(_mm_add_epi32(sad, _mm_srli_si128(sad, 8)));
        if (d < m1) { m2 = m1; m1 = d; b = j; }
        else if (d < m2) m2 = d;
    }
    *best = b; *d1 = m1; *d2 = m2;
}

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
                    __m128i b = _mm_loadu_si128(
                        (const __m128i *)(const void *)(s0 + (ptrdiff_t)v * stride));
                    lo = _mm_add_epi16(lo, _mm_unpacklo_epi8(b, zero));
                    hi = _mm_add_epi16(hi, _mm_unpackhi_epi8(b, zero));
                }
                pairs = _mm_packs_epi32(_mm_madd_epi16(lo, ones), _mm_madd_epi16(hi, ones));
                q[c] = _mm_madd_epi16(pairs, ones);
            } else {
                __m128i b0 = _mm_loadl_epi64((const __m128i *)(const void *)s0);
                __m128i b1 = _mm_loadl_epi64((const __m128i *)(const void *)(s0 + stride));
                q[c] = _mm_madd_epi16(
                    _mm_add_epi16(_mm_unpacklo_epi8(b0, zero), _mm_unpacklo_epi8(b1, zero)), ones);
            }
            q[c] = _mm_srai_epi32(_mm_add_epi32(q[c], half), shift);
        }
        _mm_storeu_si128(
            (__m128i *)(void *)(out + x),
            _mm_packus_epi16(_mm_packs_epi32(q[0], q[1]), _mm_packs_epi32(q[2], q[3])));
    }
    if (x < out_w) home__kernels_scalar.box_down(src + ds * x, stride, ds, out + x, out_w - x);
}

const home__kernels home__kernels_sse = {
    .name = "sse",
    .radon_blocks = radon_blocks_sse,
    .nearest2_l1 = home__nearest2_l1_sse,
    .smooth_row = smooth_row_fv,
    .smooth_cols = smooth_cols_fv,
    .box_down = home__box_down_sse,
    .extremum_candidates = extremum_candidates_fv,
    .line_ends = home__line_ends_scalar,
    .resample = home__resample_scalar,
    .line_fit = &home__line_fit_scalar,
};
#else
typedef int home__sse_unavailable; /* ISO C forbids an empty translation unit */
#endif
