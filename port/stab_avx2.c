/* AVX2-machine warp row kernel (compiled with -mavx2, used when the CPU has AVX2): sixteen output
 * pixels per step, two groups of eight in the two 128-bit lanes. Where a group's source pairs lie
 * in one 16-byte window (dx in [0, 2): every stabilisation warp) they are gathered by one load
 * per row and a byte shuffle (pshufb) instead of sixteen pinsrw; the blend is port/stab_x86.h's
 * at twice the width. Other groups take the SSE2 kernel's steps. Same bytes as the reference. */
#include "kernels.h"
#include "stab_kernels.h"
#if defined(HOME__HAVE_AVX2) && defined(__AVX2__)
#include "stab_x86.h"
#include <immintrin.h>

/* port/stab_x86.h's blend for sixteen pixels (lanes: pixels 0-7 | 8-15) into dst[0..15] */
static void blend16(__m256i top, __m256i bot, __m256i frac_x, __m256i frac_y, uint8_t *dst)
{
    const __m256i zero = _mm256_setzero_si256(), c128 = _mm256_set1_epi16(128), low = _mm256_set1_epi16(0xff);
    const __m256i fx = _mm256_avg_epu16(_mm256_srli_epi16(frac_x, 8), zero), gx = _mm256_sub_epi16(c128, fx);
    const __m256i fy = _mm256_avg_epu16(_mm256_srli_epi16(frac_y, 8), zero), gy = _mm256_sub_epi16(c128, fy);
    const __m256i t = _mm256_add_epi16(_mm256_mullo_epi16(_mm256_and_si256(top, low), gx),
                                       _mm256_mullo_epi16(_mm256_srli_epi16(top, 8), fx));
    const __m256i b = _mm256_add_epi16(_mm256_mullo_epi16(_mm256_and_si256(bot, low), gx),
                                       _mm256_mullo_epi16(_mm256_srli_epi16(bot, 8), fx));
    __m256i r0 = _mm256_madd_epi16(_mm256_unpacklo_epi16(t, b), _mm256_unpacklo_epi16(gy, fy));
    __m256i r1 = _mm256_madd_epi16(_mm256_unpackhi_epi16(t, b), _mm256_unpackhi_epi16(gy, fy));
    r0 = _mm256_srli_epi32(_mm256_add_epi32(r0, _mm256_set1_epi32(8192)), 14);
    r1 = _mm256_srli_epi32(_mm256_add_epi32(r1, _mm256_set1_epi32(8192)), 14);
    r0 = _mm256_packus_epi16(_mm256_packs_epi32(r0, r1), zero);   /* lanes: bytes 0-7 | 8-15 */
    _mm_storeu_si128((__m128i *)(void *)dst, _mm256_castsi256_si128(_mm256_permute4x64_epi64(r0, 0x08)));
}

/* one 16-byte window per row and lane: lane j's source pairs start at base[j] */
static __m256i window(const uint8_t *row, int32_t base0, int32_t base1)
{
    return _mm256_inserti128_si256(_mm256_castsi128_si256(_mm_loadu_si128((const __m128i *)(const void *)(row + base0))),
                                   _mm_loadu_si128((const __m128i *)(const void *)(row + base1)), 1);
}

/* the SSE2 kernel's step for pixels x, x + dx, ... x + 7 dx */
static void group8(const uint8_t *src, ptrdiff_t stride, int32_t x, int32_t y, int32_t dx,
                   int32_t dy, __m128i frac_x, __m128i frac_y, uint8_t *dst)
{
    __m128i top, bot;
    if ((y >> HOME__WARP_FRAC_BITS) == ((y + 7 * dy) >> HOME__WARP_FRAC_BITS))
        home__stab_gather8(src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride, stride, (uint32_t)x, dx, &top, &bot);
    else
        home__stab_gather8_rows(src, stride, (uint32_t)x, y, dx, dy, &top, &bot);
    home__stab_blend8(top, bot, frac_x, frac_y, dst);
}

static void warp_row_avx2(const uint8_t *src, ptrdiff_t stride, int step, int w, int h, int32_t x0,
                          int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n)
{
    const __m256i step_x = _mm256_set1_epi16(home__stab_low16(0, dx, 16)), step_y = _mm256_set1_epi16(home__stab_low16(0, dy, 16));
    const __m256i pair = _mm256_set1_epi16(0x0100);
    __m256i frac_x, frac_y, off0, off1;
    int32_t x = x0, y = y0;
    int i = 0;
    if (step != 1 || dst_step != 1 || !home__warp_row_inside(w, h, x0, y0, dx, dy, n)) {
        home__warp_row_c(src, stride, step, w, h, x0, y0, dx, dy, dst, dst_step, n);
        return;
    }
    /* pixels 0-7 | 8-15 (the start wraps like the fractions: rows shorter than 16 never use it) */
    frac_x = _mm256_inserti128_si256(_mm256_castsi128_si256(home__stab_fractions((uint32_t)x0, dx)),
                                     home__stab_fractions((uint32_t)x0 + 8u * (uint32_t)dx, dx), 1);
    frac_y = _mm256_inserti128_si256(_mm256_castsi128_si256(home__stab_fractions((uint32_t)y0, dy)),
                                     home__stab_fractions((uint32_t)y0 + 8u * (uint32_t)dy, dy), 1);
    /* pixel k's offset k dx from its group's first pixel: k = 0-3 in off0, 4-7 in off1, per lane */
    off0 = _mm256_setr_epi32(0, dx, 2 * dx, 3 * dx, 0, dx, 2 * dx, 3 * dx);
    off1 = _mm256_add_epi32(off0, _mm256_set1_epi32(4 * dx));
    for (; i + 16 <= n; i += 16, x += 16 * dx, y += 16 * dy) {
        const int32_t x8 = x + 8 * dx, base0 = x >> HOME__WARP_FRAC_BITS, base1 = x8 >> HOME__WARP_FRAC_BITS;
        /* sixteen pixels on one row pair (affine: the ends decide), each group's pairs in a
         * window that stays inside the row */
        if ((y >> HOME__WARP_FRAC_BITS) == ((y + 15 * dy) >> HOME__WARP_FRAC_BITS) && dx >= 0 &&
            ((x8 - dx) >> HOME__WARP_FRAC_BITS) - base0 <= 14 && ((x8 + 7 * dx) >> HOME__WARP_FRAC_BITS) - base1 <= 14 &&
            base1 + 16 <= w) {
            const uint8_t *row = src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride;
            /* index of pixel k's pair in its window: (frac + k dx) >> 16 */
            const __m256i f = _mm256_setr_epi32(x & 0xffff, x & 0xffff, x & 0xffff, x & 0xffff,
                                                x8 & 0xffff, x8 & 0xffff, x8 & 0xffff, x8 & 0xffff);
            const __m256i k = _mm256_packs_epi32(_mm256_srli_epi32(_mm256_add_epi32(off0, f), HOME__WARP_FRAC_BITS),
                                                 _mm256_srli_epi32(_mm256_add_epi32(off1, f), HOME__WARP_FRAC_BITS));
            /* bytes (k, k + 1) of each 16-bit lane pick p0 and p1 */
            const __m256i ctrl = _mm256_add_epi16(_mm256_or_si256(k, _mm256_slli_epi16(k, 8)), pair);
            blend16(_mm256_shuffle_epi8(window(row, base0, base1), ctrl),
                    _mm256_shuffle_epi8(window(row + stride, base0, base1), ctrl), frac_x, frac_y, dst + i);
        } else {
            group8(src, stride, x, y, dx, dy, _mm256_castsi256_si128(frac_x), _mm256_castsi256_si128(frac_y), dst + i);
            group8(src, stride, x8, y + 8 * dy, dx, dy, _mm256_extracti128_si256(frac_x, 1),
                   _mm256_extracti128_si256(frac_y, 1), dst + i + 8);
        }
        frac_x = _mm256_add_epi16(frac_x, step_x);
        frac_y = _mm256_add_epi16(frac_y, step_y);
    }
    if (i + 8 <= n) {
        group8(src, stride, x, y, dx, dy, _mm256_castsi256_si128(frac_x), _mm256_castsi256_si128(frac_y), dst + i);
        i += 8, x += 8 * dx, y += 8 * dy;
    }
    if (i < n)   /* the rest of an inside row: the reference's fast path, same bytes */
        home__warp_row_c(src, stride, 1, w, h, x, y, dx, dy, dst + i, 1, n - i);
}

const home__stab_kernels home__stab_kernels_avx2 = {"avx2", warp_row_avx2};
#else
typedef int home__stab_avx2_unused; /* ISO C forbids an empty translation unit */
#endif
