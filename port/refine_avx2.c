/* AVX2 kernels of the refinement (compiled with -mavx2, used when the CPU reports AVX2): the
 * 3x3 blur and the selection keys, which touch every pixel of every frame's snapshot, sixteen
 * pixels per step; the rest of the table is the SSE2 one. Bit-identical to
 * port/refine_scalar.c (integer arithmetic only). */
#include "kernels.h"
#include "refine_kernels.h"
#if defined(HOME__HAVE_AVX2) && defined(__AVX2__)
#include <immintrin.h>

static __m256i load16_u16(const uint8_t *p)
{
    return _mm256_cvtepu8_epi16(_mm_loadu_si128((const __m128i *)(const void *)p));
}

/* sixteen int16 lanes back to bytes in order (packus works per 128-bit lane) */
static void store16_u8(uint8_t *d, __m256i v)
{
    __m256i packed = _mm256_permute4x64_epi64(_mm256_packus_epi16(v, v), 0xD8);
    _mm_storeu_si128((__m128i *)(void *)d, _mm256_castsi256_si128(packed));
}

static void blur3_avx2(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                       ptrdiff_t dst_stride, int w, int h, int16_t *tmp)
{
    const __m256i eight = _mm256_set1_epi16(8);
    int x, y;
    for (y = 0; y < h; y++) {
        const uint8_t *a, *b, *c;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        home__blur3_rows(src, src_stride, y, h, &a, &b, &c);
        for (x = 0; x + 16 <= w; x += 16) {
            __m256i vb = load16_u16(b + x);
            __m256i s = _mm256_add_epi16(_mm256_add_epi16(load16_u16(a + x), load16_u16(c + x)),
                                         _mm256_add_epi16(vb, vb));
            _mm256_storeu_si256((__m256i *)(void *)(tmp + x), s);
        }
        home__blur3_vertical(a, b, c, tmp, x, w);
        for (x = 1; x + 16 <= w - 1; x += 16) {
            __m256i l = _mm256_loadu_si256((const __m256i *)(const void *)(tmp + x - 1));
            __m256i m = _mm256_loadu_si256((const __m256i *)(const void *)(tmp + x));
            __m256i r = _mm256_loadu_si256((const __m256i *)(const void *)(tmp + x + 1));
            __m256i s = _mm256_add_epi16(_mm256_add_epi16(l, r), _mm256_add_epi16(m, m));
            store16_u8(d + x, _mm256_srli_epi16(_mm256_add_epi16(s, eight), 4));
        }
        home__blur3_horizontal(tmp, d, x, w);
    }
}

static __m256i absdiff16(const uint8_t *p, const uint8_t *q)
{
    __m128i a = _mm_loadu_si128((const __m128i *)(const void *)p);
    __m128i b = _mm_loadu_si128((const __m128i *)(const void *)q);
    return _mm256_cvtepu8_epi16(_mm_or_si128(_mm_subs_epu8(a, b), _mm_subs_epu8(b, a)));
}

static void select_keys_avx2(const uint8_t *row, ptrdiff_t stride, int w, int b, int dy,
                             int16_t *keys, int accumulate)
{
    const __m256i iota = _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m256i mask = _mm256_set1_epi16((short)(b - 1)), base = _mm256_set1_epi16((short)(dy * b));
    int x;
    if (!accumulate) keys[0] = keys[w - 1] = 0;
    for (x = 1; x + 16 <= w - 1; x += 16) {
        __m256i s = _mm256_add_epi16(absdiff16(row + x + 1, row + x - 1),
                                     absdiff16(row + x + stride, row + x - stride));
        __m256i off = _mm256_add_epi16(base, _mm256_and_si256(_mm256_add_epi16(_mm256_set1_epi16((short)x), iota), mask));
        __m256i key = _mm256_or_si256(_mm256_slli_epi16(s, 4), off);
        __m256i *dst = (__m256i *)(void *)(keys + x);
        if (accumulate) key = _mm256_max_epi16(key, _mm256_loadu_si256(dst));
        _mm256_storeu_si256(dst, key);
    }
    home__select_keys_px(row, stride, x, w, b, dy, keys, accumulate);
}

const home__refine_kernels home__refine_kernels_avx2 = {
    "avx2", blur3_avx2, home__refine_downsample_sse, select_keys_avx2, home__refine_block_max_sse,
    home__refine_warp_sse,
    home__refine_accumulate_sse, home__refine_cauchy_sums_sse, home__refine_residuals_sse};
#else
typedef int home__refine_avx2_unused; /* ISO C forbids an empty translation unit */
#endif
