/* SSE2 warp row kernel: eight output pixels per step. A pixel's horizontal pairs are one 16-bit
 * load each (pinsrw) at a column taken from a vector of the eight Q16 x (pextrw), from the row
 * pair the kernel tracks while the row of the warp stays on it (a near-horizontal warp: almost
 * always); a group that crosses a source row finds each pixel's rows. The blend is
 * port/stab_x86.h's. Body only: src/warp.c passes planar rows inside the source, n a multiple
 * of eight, and finishes the tail. */
#include "stab_kernels.h"
#if defined(__SSE2__)
#include "stab_x86.h"

static void warp_row_sse(const uint8_t *src, ptrdiff_t stride, int w, int32_t x0, int32_t y0,
                         int32_t dx, int32_t dy, uint8_t *dst, int n)
{
    const __m128i step_x = _mm_set1_epi16(home__stab_low16(0, dx, 8)),
                  step_y = _mm_set1_epi16(home__stab_low16(0, dy, 8));
    const __m128i step8 = _mm_set1_epi32(home__stab_wrap32(0, dx, 8));
    const uint32_t dy7 = 7u * (uint32_t)dy, dy8 = 8u * (uint32_t)dy;
    __m128i frac_x, frac_y, xa, xb, top, bot;
    const uint8_t *row;
    uint8_t *d = dst, *const end = dst + n;
    /* lo: first Q16 y of the tracked source row; yrel: the group's last y - lo */
    uint32_t lo, yrel;
    (void)w; /* per-pixel loads: the row's width does not matter */
    {
        /* k dq & 0xffff = k (dq & 0xffff) & 0xffff: the fractions of pixels k = 0..7 are the
         * first's plus lanes k of these (wrapping like the Q16 sums) */
        const __m128i lane = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);
        frac_x = _mm_add_epi16(_mm_set1_epi16(home__stab_low16((uint32_t)x0, 0, 0)),
                               _mm_mullo_epi16(_mm_set1_epi16(home__stab_low16(0, dx, 1)), lane));
        frac_y = _mm_add_epi16(_mm_set1_epi16(home__stab_low16((uint32_t)y0, 0, 0)),
                               _mm_mullo_epi16(_mm_set1_epi16(home__stab_low16(0, dy, 1)), lane));
    }
    home__stab_xs((uint32_t)x0, dx, &xa, &xb);
    row = home__stab_track_row(src, stride, (uint32_t)y0, dy7, &lo, &yrel);
    while (d < end) {
        /* affine: a group's first pixel is on the tracked row when the previous group's last
         * was, so its last decides */
        if (yrel < 0x10000u) {
            home__stab_gather8(row, stride, xa, xb, &top, &bot);
        } else {   /* the group crosses a source row, here or before it: each pixel's own rows */
            const uint32_t y = lo + yrel - dy7, next = y + dy8;
            home__stab_gather8_rows(src, stride, (uint32_t)_mm_cvtsi128_si32(xa), (int32_t)y, dx,
                                    dy, &top, &bot);
            if (d + 8 < end) {   /* next is a pixel of the row: inside; track its row */
                /* yrel: next's (next + dy7 - lo) after the step below */
                row = home__stab_track_row(src, stride, next, dy7 - dy8, &lo, &yrel);
            }
        }
        home__stab_blend8(top, bot, frac_x, frac_y, d);
        frac_x = _mm_add_epi16(frac_x, step_x);
        frac_y = _mm_add_epi16(frac_y, step_y);
        xa = _mm_add_epi32(xa, step8);
        xb = _mm_add_epi32(xb, step8);
        yrel += dy8;
        d += 8;
    }
}

const home__stab_kernels home__stab_kernels_sse = { .name = "sse",
                                                    .block = 8,
                                                    .warp_row = warp_row_sse };
#else
typedef int home__stab_sse_unused; /* ISO C forbids an empty translation unit */
#endif
