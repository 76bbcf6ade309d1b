/* SSE2 warp row kernel: eight output pixels per step. A pixel's horizontal pairs are one 16-bit
 * load each (pinsrw), two loads instead of four, from row addresses shared while the eight
 * pixels read the same source rows (a near-horizontal warp: almost always); the blend is
 * port/stab_x86.h's. Rows that need clamping, or are not planar, use the reference. */
#include "stab_kernels.h"
#if defined(__SSE2__)
#include "stab_x86.h"

static void warp_row_sse(const uint8_t *src, ptrdiff_t stride, int step, int w, int h, int32_t x0,
                         int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n)
{
    const __m128i step_x = _mm_set1_epi16(home__stab_low16(0, dx, 8)), step_y = _mm_set1_epi16(home__stab_low16(0, dy, 8));
    __m128i frac_x, frac_y, top, bot;
    int32_t x = x0, y = y0;
    int i = 0;
    if (step != 1 || dst_step != 1 || !home__warp_row_inside(w, h, x0, y0, dx, dy, n)) {
        home__warp_row_c(src, stride, step, w, h, x0, y0, dx, dy, dst, dst_step, n);
        return;
    }
    frac_x = home__stab_fractions((uint32_t)x0, dx);
    frac_y = home__stab_fractions((uint32_t)y0, dy);
    for (; i + 8 <= n; i += 8, x += 8 * dx, y += 8 * dy) {
        /* affine: the eight pixels share their rows when the first and the last do; else (a
         * row of the warp crossing a source row) each finds its own */
        if ((y >> HOME__WARP_FRAC_BITS) == ((y + 7 * dy) >> HOME__WARP_FRAC_BITS))
            home__stab_gather8(src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride, stride, (uint32_t)x, dx, &top, &bot);
        else
            home__stab_gather8_rows(src, stride, (uint32_t)x, y, dx, dy, &top, &bot);
        home__stab_blend8(top, bot, frac_x, frac_y, dst + i);
        frac_x = _mm_add_epi16(frac_x, step_x);
        frac_y = _mm_add_epi16(frac_y, step_y);
    }
    if (i < n)   /* the rest of an inside row: the reference's fast path, same bytes */
        home__warp_row_c(src, stride, 1, w, h, x, y, dx, dy, dst + i, 1, n - i);
}

const home__stab_kernels home__stab_kernels_sse = {"sse", warp_row_sse};
#else
typedef int home__stab_sse_unused; /* ISO C forbids an empty translation unit */
#endif
