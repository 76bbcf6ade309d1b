/* SSE2 warp row kernel: four output pixels per step; the 2x2 source pixels are gathered with
 * scalar loads (SSE2 has no gather), the weights and blends are vector integer arithmetic giving
 * the scalar reference's bytes. Rows that need clamping, or are not planar, use the reference. */
#include "stab_kernels.h"
#if defined(__SSE2__)
#include <emmintrin.h>

/* lane-wise a * b for products below 2^32 */
static __m128i mul_u32(__m128i a, __m128i b)
{
    __m128i even = _mm_mul_epu32(a, b);
    __m128i odd = _mm_mul_epu32(_mm_srli_epi64(a, 32), _mm_srli_epi64(b, 32));
    return _mm_unpacklo_epi32(_mm_shuffle_epi32(even, _MM_SHUFFLE(0, 0, 2, 0)),
                              _mm_shuffle_epi32(odd, _MM_SHUFFLE(0, 0, 2, 0)));
}

static void warp_row_sse(const uint8_t *src, ptrdiff_t stride, int step, int w, int h, int32_t x0,
                         int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n)
{
    const __m128i frac = _mm_set1_epi32(0xffff), half = _mm_set1_epi32(128), one = _mm_set1_epi32(256);
    const __m128i round = _mm_set1_epi32(32768), step_x = _mm_set1_epi32(4 * dx), step_y = _mm_set1_epi32(4 * dy);
    __m128i vx, vy;
    int i = 0;
    if (step != 1 || dst_step != 1 || !home__warp_row_inside(w, h, x0, y0, dx, dy, n)) {
        home__warp_row_c(src, stride, step, w, h, x0, y0, dx, dy, dst, dst_step, n);
        return;
    }
    vx = _mm_setr_epi32(x0, x0 + dx, x0 + 2 * dx, x0 + 3 * dx);
    vy = _mm_setr_epi32(y0, y0 + dy, y0 + 2 * dy, y0 + 3 * dy);
    for (; i + 4 <= n; i += 4) {
        int32_t xi[4], yi[4], p01[4], p23[4];
        __m128i fx, fy, wx, top, bot, res;
        int k;
        _mm_storeu_si128((__m128i *)(void *)xi, _mm_srai_epi32(vx, HOME__WARP_FRAC_BITS));
        _mm_storeu_si128((__m128i *)(void *)yi, _mm_srai_epi32(vy, HOME__WARP_FRAC_BITS));
        for (k = 0; k < 4; k++) {
            const uint8_t *p = src + (ptrdiff_t)yi[k] * stride + xi[k];
            p01[k] = p[0] | p[1] << 16;             /* int16 pairs for madd */
            p23[k] = p[stride] | p[stride + 1] << 16;
        }
        fx = _mm_srli_epi32(_mm_add_epi32(_mm_and_si128(vx, frac), half), 8);
        fy = _mm_srli_epi32(_mm_add_epi32(_mm_and_si128(vy, frac), half), 8);
        wx = _mm_or_si128(_mm_sub_epi32(one, fx), _mm_slli_epi32(fx, 16));
        top = _mm_madd_epi16(_mm_loadu_si128((const __m128i *)(const void *)p01), wx);
        bot = _mm_madd_epi16(_mm_loadu_si128((const __m128i *)(const void *)p23), wx);
        res = _mm_add_epi32(_mm_add_epi32(mul_u32(top, _mm_sub_epi32(one, fy)), mul_u32(bot, fy)), round);
        res = _mm_srli_epi32(res, 16);
        res = _mm_packs_epi32(res, res);
        res = _mm_packus_epi16(res, res);
        {
            int32_t four = _mm_cvtsi128_si32(res);
            for (k = 0; k < 4; k++) dst[i + k] = (uint8_t)(four >> (8 * k));
        }
        vx = _mm_add_epi32(vx, step_x);
        vy = _mm_add_epi32(vy, step_y);
    }
    if (i < n)   /* the rest of an inside row: the reference's fast path, same bytes */
        home__warp_row_c(src, stride, 1, w, h, x0 + i * dx, y0 + i * dy, dx, dy, dst + i, 1, n - i);
}

const home__stab_kernels home__stab_kernels_sse = {"sse", warp_row_sse};
#else
typedef int home__stab_sse_unused; /* ISO C forbids an empty translation unit */
#endif
