/* AVX2-machine warp row kernel (compiled with -mavx2, used when the CPU has AVX2): the SSE2
 * kernel with its sixteen pinsrw gathers replaced, where the eight pixels' source pairs lie in
 * one 16-byte window (dx in [0, 2): every stabilisation warp), by one load per row and a byte
 * shuffle (pshufb) of each pixel's pair into its lane. Same blend, same bytes. */
#include "kernels.h"
#include "stab_kernels.h"
#if defined(HOME__HAVE_AVX2) && defined(__AVX2__)
#include "stab_x86.h"
#include <immintrin.h>

static void warp_row_avx2(const uint8_t *src, ptrdiff_t stride, int step, int w, int h, int32_t x0,
                          int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n)
{
    const __m128i step_x = _mm_set1_epi16(home__stab_low16(8 * dx)), step_y = _mm_set1_epi16(home__stab_low16(8 * dy));
    const __m128i pair = _mm_set1_epi16(0x0100);
    __m128i frac_x, frac_y, vx0, vx1, top, bot;
    int32_t x = x0, y = y0;
    int i = 0;
    if (step != 1 || dst_step != 1 || !home__warp_row_inside(w, h, x0, y0, dx, dy, n)) {
        home__warp_row_c(src, stride, step, w, h, x0, y0, dx, dy, dst, dst_step, n);
        return;
    }
    frac_x = home__stab_fractions(x0, dx);
    frac_y = home__stab_fractions(y0, dy);
    vx0 = _mm_setr_epi32(0, dx, 2 * dx, 3 * dx);   /* offsets from the group's first pixel */
    vx1 = _mm_add_epi32(vx0, _mm_set1_epi32(4 * dx));
    for (; i + 8 <= n; i += 8, x += 8 * dx, y += 8 * dy) {
        const int32_t base = x >> HOME__WARP_FRAC_BITS;
        if ((y >> HOME__WARP_FRAC_BITS) != ((y + 7 * dy) >> HOME__WARP_FRAC_BITS)) {
            home__warp_row_c(src, stride, 1, w, h, x, y, dx, dy, dst + i, 1, 8);   /* rows differ */
        } else {
            const uint8_t *row = src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride;
            /* the window: pixel 7's pair ends within 16 bytes, which stay inside the row */
            if (dx >= 0 && ((x + 7 * dx) >> HOME__WARP_FRAC_BITS) - base <= 14 && base + 16 <= w) {
                /* lane k's index (x + k dx) >> 16 - base from its offset and x's fraction */
                const __m128i f = _mm_set1_epi32(x & 0xffff);
                const __m128i k = _mm_packs_epi32(_mm_srli_epi32(_mm_add_epi32(vx0, f), HOME__WARP_FRAC_BITS),
                                                  _mm_srli_epi32(_mm_add_epi32(vx1, f), HOME__WARP_FRAC_BITS));
                /* bytes (k, k + 1) of each 16-bit lane pick p0 and p1 */
                const __m128i ctrl = _mm_add_epi16(_mm_or_si128(k, _mm_slli_epi16(k, 8)), pair);
                top = _mm_shuffle_epi8(_mm_loadu_si128((const __m128i *)(const void *)(row + base)), ctrl);
                bot = _mm_shuffle_epi8(_mm_loadu_si128((const __m128i *)(const void *)(row + stride + base)), ctrl);
            } else {
                home__stab_gather8(row, stride, (uint32_t)x, dx, &top, &bot);
            }
            home__stab_blend8(top, bot, frac_x, frac_y, dst + i);
        }
        frac_x = _mm_add_epi16(frac_x, step_x);
        frac_y = _mm_add_epi16(frac_y, step_y);
    }
    if (i < n)   /* the rest of an inside row: the reference's fast path, same bytes */
        home__warp_row_c(src, stride, 1, w, h, x, y, dx, dy, dst + i, 1, n - i);
}

const home__stab_kernels home__stab_kernels_avx2 = {"avx2", warp_row_avx2};
#else
typedef int home__stab_avx2_unused; /* ISO C forbids an empty translation unit */
#endif
