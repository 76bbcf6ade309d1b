/* SSE2 kernels of the refinement (x86-64 baseline): bit-identical to port/refine_scalar.c. */
#include "refine_kernels.h"
#if defined(__SSE2__)
#include <emmintrin.h>
#include <string.h>
#define FV_NAME(name) home__refine_##name##_sse /* the AVX2 table shares them */
#define FV_LINKAGE
#include "refine_f32x4.h"

static __m128i load8_u16(const uint8_t *p)
{
    return _mm_unpacklo_epi8(_mm_loadl_epi64((const __m128i *)(const void *)p),
                             _mm_setzero_si128());
}

static void blur3_sse(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst, ptrdiff_t dst_stride,
                      int w, int h, int16_t *tmp)
{
    const __m128i eight = _mm_set1_epi16(8);
    int x, y;
    for (y = 0; y < h; y++) {
        const uint8_t *a, *b, *c;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        home__blur3_rows(src, src_stride, y, h, &a, &b, &c);
        for (x = 0; x + 8 <= w; x += 8) {
            __m128i vb = load8_u16(b + x);
            __m128i s = _mm_add_epi16(_mm_add_epi16(load8_u16(a + x), load8_u16(c + x)),
                                      _mm_add_epi16(vb, vb));
            _mm_storeu_si128((__m128i *)(void *)(tmp + x), s);
        }
        home__blur3_vertical(a, b, c, tmp, x, w);
        for (x = 1; x + 8 <= w - 1; x += 8) {
            __m128i l = _mm_loadu_si128((const __m128i *)(const void *)(tmp + x - 1));
            __m128i m = _mm_loadu_si128((const __m128i *)(const void *)(tmp + x));
            __m128i r = _mm_loadu_si128((const __m128i *)(const void *)(tmp + x + 1));
            __m128i s = _mm_add_epi16(_mm_add_epi16(l, r), _mm_add_epi16(m, m));
            s = _mm_srli_epi16(_mm_add_epi16(s, eight), 4);
            _mm_storel_epi64((__m128i *)(void *)(d + x), _mm_packus_epi16(s, s));
        }
        home__blur3_horizontal(tmp, d, x, w);
    }
}

void home__refine_downsample_sse(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                                 ptrdiff_t dst_stride, int dst_w, int dst_h)
{
    const __m128i lo = _mm_set1_epi16(0xff), two = _mm_set1_epi16(2);
    int x, y;
    for (y = 0; y < dst_h; y++) {
        const uint8_t *a = src + 2 * (ptrdiff_t)y * src_stride, *b = a + src_stride;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        for (x = 0; x + 8 <= dst_w; x += 8) {
            __m128i va = _mm_loadu_si128((const __m128i *)(const void *)(a + 2 * x));
            __m128i vb = _mm_loadu_si128((const __m128i *)(const void *)(b + 2 * x));
            __m128i s = _mm_add_epi16(_mm_add_epi16(_mm_and_si128(va, lo), _mm_srli_epi16(va, 8)),
                                      _mm_add_epi16(_mm_and_si128(vb, lo), _mm_srli_epi16(vb, 8)));
            s = _mm_srli_epi16(_mm_add_epi16(s, two), 2);
            _mm_storel_epi64((__m128i *)(void *)(d + x), _mm_packus_epi16(s, s));
        }
        home__downsample_px(a, b, d, x, dst_w);
    }
}

static __m128i absdiff8(const uint8_t *p, const uint8_t *q)
{
    __m128i a = _mm_loadl_epi64((const __m128i *)(const void *)p);
    __m128i b = _mm_loadl_epi64((const __m128i *)(const void *)q);
    return _mm_unpacklo_epi8(_mm_or_si128(_mm_subs_epu8(a, b), _mm_subs_epu8(b, a)),
                             _mm_setzero_si128());
}

static void select_keys_sse(const uint8_t *row, ptrdiff_t stride, int w, int b, int dy,
                            int16_t *keys, int accumulate)
{
    const __m128i iota = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7),
                  mask = _mm_set1_epi16((short)(b - 1));
    const __m128i base = _mm_set1_epi16((short)(dy * b));
    int x;
    if (!accumulate) keys[0] = keys[w - 1] = 0;
    for (x = 1; x + 8 <= w - 1; x += 8) {
        __m128i s = _mm_add_epi16(absdiff8(row + x + 1, row + x - 1),
                                  absdiff8(row + x + stride, row + x - stride));
        __m128i off =
            _mm_add_epi16(base, _mm_and_si128(_mm_add_epi16(_mm_set1_epi16((short)x), iota), mask));
        __m128i key = _mm_or_si128(_mm_slli_epi16(s, 4), off);
        __m128i *dst = (__m128i *)(void *)(keys + x);
        if (accumulate) key = _mm_max_epi16(key, _mm_loadu_si128(dst));
        _mm_storeu_si128(dst, key);
    }
    home__select_keys_px(row, stride, x, w, b, dy, keys, accumulate);
}

/* The maximum of each 2- or 4-lane group lands in the group's first lane (shifts within 32- or
 * 64-bit lanes), then packs gather those lanes (values < 2^15: signed packing is exact). */
void home__refine_block_max_sse(const int16_t *keys, int n, int b, uint16_t *cells)
{
    const __m128i low16 = _mm_set1_epi32(0xffff);
    int i = 0;
    if (b == 2) {
        for (; i + 8 <= n; i += 8) {
            __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(keys + 2 * i));
            __m128i w = _mm_loadu_si128((const __m128i *)(const void *)(keys + 2 * i + 8));
            v = _mm_and_si128(_mm_max_epi16(v, _mm_srli_epi32(v, 16)), low16);
            w = _mm_and_si128(_mm_max_epi16(w, _mm_srli_epi32(w, 16)), low16);
            _mm_storeu_si128((__m128i *)(void *)(cells + i), _mm_packs_epi32(v, w));
        }
    } else if (b == 4) {
        const __m128i low64 = _mm_set_epi32(0, 0xffff, 0, 0xffff);
        for (; i + 8 <= n; i += 8) {
            __m128i q[4];
            int j;
            for (j = 0; j < 4; j++) {
                __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(keys + 4 * i + 8 * j));
                v = _mm_max_epi16(v, _mm_srli_epi64(v, 16));
                q[j] = _mm_and_si128(_mm_max_epi16(v, _mm_srli_epi64(v, 32)), low64);
            }
            /* 32-bit lanes 0 and 2 of each hold two blocks' maxima: pack twice */
            _mm_storeu_si128(
                (__m128i *)(void *)(cells + i),
                _mm_packs_epi32(_mm_packs_epi32(q[0], q[1]), _mm_packs_epi32(q[2], q[3])));
        }
    }
    home__block_max_px(keys, i, n, b, cells);
}

const home__refine_kernels home__refine_kernels_sse = {
    .name = "sse",
    .blur3 = blur3_sse,
    .downsample = home__refine_downsample_sse,
    .select_keys = select_keys_sse,
    .block_max = home__refine_block_max_sse,
    .warp = home__refine_warp_sse,
    .accumulate = home__refine_accumulate_sse,
    .cauchy_sums = home__refine_cauchy_sums_sse,
    .residuals = home__refine_residuals_sse,
};
#else
typedef int home__refine_sse_unused; /* ISO C forbids an empty translation unit */
#endif
