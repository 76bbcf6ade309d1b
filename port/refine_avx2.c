/* AVX2 kernels of the refinement (compiled with -mavx2, used when the CPU reports AVX2): the
 * 3x3 blur, the 2x2 means and the selection keys, which touch every pixel of every frame's
 * snapshot, sixteen pixels per step, and the warp (gathers); the rest of the table is the SSE2 one.
 * Bit-identical to port/refine_scalar.c (integer arithmetic only). */
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
    const __m256i mask = _mm256_set1_epi16((short)(b - 1)),
                  base = _mm256_set1_epi16((short)(dy * b));
    int x;
    if (!accumulate) keys[0] = keys[w - 1] = 0;
    for (x = 1; x + 16 <= w - 1; x += 16) {
        __m256i s = _mm256_add_epi16(absdiff16(row + x + 1, row + x - 1),
                                     absdiff16(row + x + stride, row + x - stride));
        __m256i off = _mm256_add_epi16(
            base, _mm256_and_si256(_mm256_add_epi16(_mm256_set1_epi16((short)x), iota), mask));
        __m256i key = _mm256_or_si256(_mm256_slli_epi16(s, 4), off);
        __m256i *dst = (__m256i *)(void *)(keys + x);
        if (accumulate) key = _mm256_max_epi16(key, _mm256_loadu_si256(dst));
        _mm256_storeu_si256(dst, key);
    }
    home__select_keys_px(row, stride, x, w, b, dy, keys, accumulate);
}

/* Eight points per step: the reference's float arithmetic lane by lane (no FMA: -mavx2 alone),
 * each 2x2 support fetched as two 32-bit gathers (pixels p[0], p[1] in the low bytes; the image
 * has slack for the 2 bytes read past its last pixel). */
static void warp_avx2(const float *m, const int16_t *xs, const int16_t *ys, int n,
                      const uint8_t *img, ptrdiff_t stride, int w, int h, float *out)
{
    const __m256 xmax = _mm256_set1_ps((float)(w - 1)), ymax = _mm256_set1_ps((float)(h - 1));
    const __m256 zero = _mm256_setzero_ps(), minus1 = _mm256_set1_ps(-1.0f),
                 one = _mm256_set1_ps(1.0f);
    const __m256i vstride = _mm256_set1_epi32((int)stride), low8 = _mm256_set1_epi32(0xff);
    const int *row0 = (const int *)(const void *)img,
              *row1 = (const int *)(const void *)(img + stride);
    __m256 mm[9];
    int i, k;
    for (k = 0; k < 9; k++) mm[k] = _mm256_set1_ps(m[k]);
    for (i = 0; i + 8 <= n; i += 8) {
        __m256 x = _mm256_cvtepi32_ps(
            _mm256_cvtepi16_epi32(_mm_loadu_si128((const __m128i *)(const void *)(xs + i))));
        __m256 y = _mm256_cvtepi32_ps(
            _mm256_cvtepi16_epi32(_mm_loadu_si128((const __m128i *)(const void *)(ys + i))));
        __m256 d = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(mm[6], x), _mm256_mul_ps(mm[7], y)),
                                 mm[8]);
        __m256 inv = _mm256_div_ps(one, d);
        __m256 px = _mm256_mul_ps(
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(mm[0], x), _mm256_mul_ps(mm[1], y)), mm[2]),
            inv);
        __m256 py = _mm256_mul_ps(
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(mm[3], x), _mm256_mul_ps(mm[4], y)), mm[5]),
            inv);
        __m256 ok = _mm256_and_ps(
            _mm256_and_ps(_mm256_cmp_ps(d, zero, _CMP_GT_OQ), _mm256_cmp_ps(px, zero, _CMP_GE_OQ)),
            _mm256_and_ps(_mm256_cmp_ps(py, zero, _CMP_GE_OQ),
                          _mm256_and_ps(_mm256_cmp_ps(px, xmax, _CMP_LT_OQ),
                                        _mm256_cmp_ps(py, ymax, _CMP_LT_OQ))));
        __m256i ix, iy, at, up, down;
        __m256 fx, fy, p00, p01, p10, p11, top, bot;
        px = _mm256_and_ps(px, ok); /* invalid lanes sample (0, 0): in bounds, discarded */
        py = _mm256_and_ps(py, ok);
        ix = _mm256_cvttps_epi32(px);
        iy = _mm256_cvttps_epi32(py);
        fx = _mm256_sub_ps(px, _mm256_cvtepi32_ps(ix));
        fy = _mm256_sub_ps(py, _mm256_cvtepi32_ps(iy));
        at = _mm256_add_epi32(_mm256_mullo_epi32(iy, vstride), ix);
        up = _mm256_i32gather_epi32(row0, at, 1);
        down = _mm256_i32gather_epi32(row1, at, 1);
        p00 = _mm256_cvtepi32_ps(_mm256_and_si256(up, low8));
        p01 = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(up, 8), low8));
        p10 = _mm256_cvtepi32_ps(_mm256_and_si256(down, low8));
        p11 = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(down, 8), low8));
        top = _mm256_add_ps(p00, _mm256_mul_ps(fx, _mm256_sub_ps(p01, p00)));
        bot = _mm256_add_ps(p10, _mm256_mul_ps(fx, _mm256_sub_ps(p11, p10)));
        _mm256_storeu_ps(
            out + i,
            _mm256_blendv_ps(minus1, _mm256_add_ps(top, _mm256_mul_ps(fy, _mm256_sub_ps(bot, top))),
                             ok));
    }
    if (i < n) home__refine_warp_sse(m, xs + i, ys + i, n - i, img, stride, w, h, out + i);
}

/* 2x2 means, sixteen outputs per step (as the SSE2 kernel, twice as wide); the SSE2 kernel takes
 * the columns left over */
static void downsample_avx2(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                            ptrdiff_t dst_stride, int dst_w, int dst_h)
{
    const __m256i lo = _mm256_set1_epi16(0xff), two = _mm256_set1_epi16(2);
    const int wide = dst_w & ~15;
    int x, y;
    for (y = 0; y < dst_h; y++) {
        const uint8_t *a = src + 2 * (ptrdiff_t)y * src_stride, *b = a + src_stride;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        for (x = 0; x < wide; x += 16) {
            __m256i va = _mm256_loadu_si256((const __m256i *)(const void *)(a + 2 * x));
            __m256i vb = _mm256_loadu_si256((const __m256i *)(const void *)(b + 2 * x));
            __m256i sum = _mm256_add_epi16(
                _mm256_add_epi16(_mm256_and_si256(va, lo), _mm256_srli_epi16(va, 8)),
                _mm256_add_epi16(_mm256_and_si256(vb, lo), _mm256_srli_epi16(vb, 8)));
            store16_u8(d + x, _mm256_srli_epi16(_mm256_add_epi16(sum, two), 2));
        }
    }
    if (wide < dst_w)
        home__refine_downsample_sse(src + 2 * wide, src_stride, dst + wide, dst_stride,
                                    dst_w - wide, dst_h);
}

const home__refine_kernels home__refine_kernels_avx2 = {
    .name = "avx2",
    .blur3 = blur3_avx2,
    .downsample = downsample_avx2,
    .select_keys = select_keys_avx2,
    .block_max = home__refine_block_max_sse,
    .warp = warp_avx2,
    .accumulate = home__refine_accumulate_sse,
    .cauchy_sums = home__refine_cauchy_sums_sse,
    .residuals = home__refine_residuals_sse,
};
#else
typedef int home__refine_avx2_unused; /* ISO C forbids an empty translation unit */
#endif
