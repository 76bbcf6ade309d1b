/* AVX2 kernels (x86-64 CPUs that report AVX2; compiled with -mavx2): those that are worth 256-bit
 * vectors (docs/simd.md); the other entries of this table are the SSE2 kernels. */
#include "kernels.h"
#if defined(HOME__HAVE_AVX2) && defined(__AVX2__)
#include "simd_f32x8.h"
#include "home_fvec.h"
#include <immintrin.h>

/* 64 lanes as 4 x 16 uint16 (vpmovzxbw widens 16 pixels per load); into int32 every 128 rows */
static void radon_blocks_avx2(const uint8_t *base, ptrdiff_t stride, const int16_t *shift,
                              int j0, int n_blocks, const int16_t *row_lo,
                              const int16_t *row_hi, int32_t *out)
{
    int b, k;
    for (b = 0; b < n_blocks; b++) {
        int32_t *acc32 = out + (ptrdiff_t)b * HOME__RADON_BLOCK;
        int p = row_lo[b];
        for (k = 0; k < HOME__RADON_BLOCK; k += 8)
            _mm256_storeu_si256((__m256i *)(void *)(acc32 + k), _mm256_setzero_si256());
        while (p <= row_hi[b]) {
            int end = p + HOME__RADON_ROWS_16BIT - 1 < row_hi[b] ? p + HOME__RADON_ROWS_16BIT - 1
                                                                 : row_hi[b];
            __m256i a0 = _mm256_setzero_si256(), a1 = a0, a2 = a0, a3 = a0;
            for (; p <= end; p++) {
                const uint8_t *src = base + (ptrdiff_t)p * stride + j0 + b * HOME__RADON_BLOCK +
                                     shift[p];
                a0 = _mm256_add_epi16(
                    a0, _mm256_cvtepu8_epi16(_mm_loadu_si128((const __m128i *)(const void *)src)));
                a1 = _mm256_add_epi16(a1, _mm256_cvtepu8_epi16(_mm_loadu_si128(
                                              (const __m128i *)(const void *)(src + 16))));
                a2 = _mm256_add_epi16(a2, _mm256_cvtepu8_epi16(_mm_loadu_si128(
                                              (const __m128i *)(const void *)(src + 32))));
                a3 = _mm256_add_epi16(a3, _mm256_cvtepu8_epi16(_mm_loadu_si128(
                                              (const __m128i *)(const void *)(src + 48))));
            }
            {
                __m256i acc[4];
                acc[0] = a0; acc[1] = a1; acc[2] = a2; acc[3] = a3;
                for (k = 0; k < 4; k++) {
                    __m256i *dst = (__m256i *)(void *)(acc32 + 16 * k);
                    __m256i lo = _mm256_cvtepu16_epi32(_mm256_castsi256_si128(acc[k]));
                    __m256i hi = _mm256_cvtepu16_epi32(_mm256_extracti128_si256(acc[k], 1));
                    _mm256_storeu_si256(dst, _mm256_add_epi32(_mm256_loadu_si256(dst), lo));
                    _mm256_storeu_si256(dst + 1, _mm256_add_epi32(_mm256_loadu_si256(dst + 1), hi));
                }
            }
        }
    }
}

/* Eight lines per step; every table lookup is a gather. Lines that never enter the image
 * (entry >= after) are masked out of the shift and pixel gathers, so nothing past the rows is
 * read. Pixels are gathered as 32-bit words and masked to their low byte. */
static void line_ends_avx2(const uint8_t *base, ptrdiff_t stride, const int16_t *shift, int j0,
                           const int16_t *entry, const int16_t *after, const int32_t *left,
                           const int32_t *right, int32_t right_total, int i0, int i1,
                           int32_t *sum, float *line)
{
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), one = _mm256_set1_epi32(1);
    const __m256i vstride = _mm256_set1_epi32((int32_t)stride),
                  total = _mm256_set1_epi32(right_total);
    const __m256i low_byte = _mm256_set1_epi32(0xff);
    const int *shift_words = (const int *)(const void *)shift;
    int i = i0;
    for (; i + 8 <= i1; i += 8) {
        const __m256i e =
            _mm256_cvtepi16_epi32(_mm_loadu_si128((const __m128i *)(const void *)(entry + i)));
        const __m256i a =
            _mm256_cvtepi16_epi32(_mm_loadu_si128((const __m128i *)(const void *)(after + i)));
        const __m256i inside = _mm256_cmpgt_epi32(a, e), zero = _mm256_setzero_si256();
        const __m256i j = _mm256_add_epi32(_mm256_set1_epi32(j0 + i), lane),
                      last = _mm256_sub_epi32(a, one);
        __m256i border =
            _mm256_sub_epi32(_mm256_add_epi32(_mm256_i32gather_epi32(left, e, 4), total),
                             _mm256_i32gather_epi32(right, a, 4));
        __m256i s_first = _mm256_mask_i32gather_epi32(zero, shift_words, e, inside, 2);
        __m256i s_last = _mm256_mask_i32gather_epi32(zero, shift_words, last, inside, 2);
        __m256i at_first, at_last, p_first, p_last;
        __m256i *sum_at = (__m256i *)(void *)(sum + i);
        s_first = _mm256_srai_epi32(_mm256_slli_epi32(s_first, 16), 16);
        s_last = _mm256_srai_epi32(_mm256_slli_epi32(s_last, 16), 16);
        at_first = _mm256_add_epi32(_mm256_add_epi32(_mm256_mullo_epi32(e, vstride), j), s_first);
        at_last = _mm256_add_epi32(_mm256_add_epi32(_mm256_mullo_epi32(last, vstride), j), s_last);
        p_first = _mm256_and_si256(
            _mm256_mask_i32gather_epi32(zero, (const int *)(const void *)base, at_first, inside, 1),
            low_byte);
        p_last = _mm256_and_si256(_mm256_mask_i32gather_epi32(zero, (const int *)(const void *)base,
                                                              at_last, inside, 1), low_byte);
        _mm256_storeu_si256(sum_at, _mm256_add_epi32(_mm256_loadu_si256(sum_at), border));
        _mm256_storeu_ps(line + i, _mm256_cvtepi32_ps(_mm256_sub_epi32(p_last, p_first)));
    }
    for (; i < i1; i++)
        home__line_ends_px(base, stride, shift, j0, entry, after, left, right, right_total, i, sum,
                           line);
}

static void resample_avx2(const float *line, const int16_t *k, const float *f, int n, float *out)
{
    int i = 0;
    for (; i + 8 <= n; i += 8) {
        const __m256i kk =
            _mm256_cvtepi16_epi32(_mm_loadu_si128((const __m128i *)(const void *)(k + i)));
        const __m256 lo = _mm256_i32gather_ps(line, kk, 4),
                     hi = _mm256_i32gather_ps(line + 1, kk, 4);
        _mm256_storeu_ps(out + i, _mm256_add_ps(lo, _mm256_mul_ps(_mm256_loadu_ps(f + i),
                                                                  _mm256_sub_ps(hi, lo))));
    }
    for (; i < n; i++) out[i] = home__resample_px(line, k[i], f[i]);
}

/* Box downscale, 16 outputs per step: pmaddubsw adds horizontal pixel pairs of each source row,
 * the rows are added, and for ds = 4 pmaddwd adds pairs of pairs; the SSE2 kernel takes the
 * outputs left over. */
static void box_down_avx2(const uint8_t *src, ptrdiff_t stride, int ds, uint8_t *out, int out_w)
{
    const __m256i ones8 = _mm256_set1_epi8(1), ones16 = _mm256_set1_epi16(1);
    int x = 0, v;
    if (ds == 4) {
        const __m256i half = _mm256_set1_epi32(8);
        for (; x + 16 <= out_w; x += 16) {
            const uint8_t *s0 = src + 4 * x;
            __m256i lo = _mm256_setzero_si256(), hi = lo;
            for (v = 0; v < 4; v++) {
                const uint8_t *row = s0 + (ptrdiff_t)v * stride;
                lo = _mm256_add_epi16(
                    lo, _mm256_maddubs_epi16(_mm256_loadu_si256((const __m256i *)(const void *)row),
                                             ones8));
                hi = _mm256_add_epi16(
                    hi, _mm256_maddubs_epi16(
                            _mm256_loadu_si256((const __m256i *)(const void *)(row + 32)), ones8));
            }
            lo = _mm256_srai_epi32(_mm256_add_epi32(_mm256_madd_epi16(lo, ones16), half), 4);
            hi = _mm256_srai_epi32(_mm256_add_epi32(_mm256_madd_epi16(hi, ones16), half), 4);
            /* packs per 128-bit lane: lo0 hi0 lo1 hi1 in order 0 2 1 3 after the pack */
            lo = _mm256_permute4x64_epi64(_mm256_packs_epi32(lo, hi), 0xD8);
            _mm_storeu_si128((__m128i *)(void *)(out + x),
                             _mm256_castsi256_si128(
                                 _mm256_permute4x64_epi64(_mm256_packus_epi16(lo, lo), 0xD8)));
        }
    } else {
        const __m256i half = _mm256_set1_epi16(2);
        for (; x + 16 <= out_w; x += 16) {
            const uint8_t *s0 = src + 2 * x;
            __m256i sum = _mm256_add_epi16(
                _mm256_maddubs_epi16(_mm256_loadu_si256((const __m256i *)(const void *)s0), ones8),
                _mm256_maddubs_epi16(
                    _mm256_loadu_si256((const __m256i *)(const void *)(s0 + stride)), ones8));
            sum = _mm256_srai_epi16(_mm256_add_epi16(sum, half), 2);
            _mm_storeu_si128((__m128i *)(void *)(out + x),
                             _mm256_castsi256_si128(
                                 _mm256_permute4x64_epi64(_mm256_packus_epi16(sum, sum), 0xD8)));
        }
    }
    if (x < out_w) home__box_down_sse(src + ds * x, stride, ds, out + x, out_w - x);
}

/* Eight candidates per step (j..j+3 in the low 128-bit lanes, j+4..j+7 in the high ones), looked
 * at one by one in order only when one is closer than the second best; as the SSE2 kernel. */
static void nearest2_l1_avx2(const uint8_t *query, const uint8_t *cands, ptrdiff_t stride, int n,
                             int *best, int *d1, int *d2)
{
    const __m128i q1 = _mm_loadu_si128((const __m128i *)(const void *)query);
    const __m256i q = _mm256_broadcastsi128_si256(q1);
    int j = 0, k, b = -1, m1 = 1 << 30, m2 = 1 << 30;
#define CAND(i) _mm_loadu_si128((const __m128i *)(const void *)(c + (i) * stride))
#define SAD_PAIR(i) \
    _mm256_sad_epu8(q, _mm256_inserti128_si256(_mm256_castsi128_si256(CAND(i)), CAND((i) + 4), 1))
    for (; j + 8 <= n; j += 8) {
        const uint8_t *c = cands + (ptrdiff_t)j * stride;
        const __m256i s0 = SAD_PAIR(0), s1 = SAD_PAIR(1), s2 = SAD_PAIR(2), s3 = SAD_PAIR(3);
        /* per 128-bit lane: d0, d1 in the low halves of s01's 64-bit words, d2, d3 in s23's */
        const __m256i s01 = _mm256_add_epi32(_mm256_unpacklo_epi64(s0, s1),
                                             _mm256_unpackhi_epi64(s0, s1)),
                      s23 = _mm256_add_epi32(_mm256_unpacklo_epi64(s2, s3),
                                             _mm256_unpackhi_epi64(s2, s3));
        const __m256i d = _mm256_castps_si256(_mm256_shuffle_ps(
            _mm256_castsi256_ps(s01), _mm256_castsi256_ps(s23), _MM_SHUFFLE(2, 0, 2, 0)));
        int dist[8];
        if (!_mm256_movemask_epi8(_mm256_cmpgt_epi32(_mm256_set1_epi32(m2), d))) continue;
        _mm256_storeu_si256((__m256i *)(void *)dist, d);
        for (k = 0; k < 8; k++) {
            if (dist[k] < m1) { m2 = m1; m1 = dist[k]; b = j + k; }
            else if (dist[k] < m2) m2 = dist[k];
        }
    }
#undef SAD_PAIR
#undef CAND
    for (; j < n; j++) {
        const __m128i sad = _mm_sad_epu8(
            q1, _mm_loadu_si128((const __m128i *)(const void *)(cands + (ptrdiff_t)j * stride)));
        const int dist = _mm_cvtsi128_si32(_mm_add_epi32(sad, _mm_srli_si128(sad, 8)));
        if (dist < m1) { m2 = m1; m1 = dist; b = j; }
        else if (dist < m2) m2 = dist;
    }
    *best = b; *d1 = m1; *d2 = m2;
}

const home__kernels home__kernels_avx2 = {
    .name = "avx2",
    .radon_blocks = radon_blocks_avx2,
    .nearest2_l1 = nearest2_l1_avx2,
    .smooth_row = smooth_row_fv,
    .smooth_cols = smooth_cols_fv,
    .box_down = box_down_avx2,
    .extremum_candidates = extremum_candidates_fv,
    .line_ends = line_ends_avx2,
    .resample = resample_avx2,
    .line_fit = &home__line_fit_avx2,
};
#else
typedef int home__avx2_unavailable; /* ISO C forbids an empty translation unit */
#endif
