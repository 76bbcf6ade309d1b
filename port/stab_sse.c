/* SSE2 warp row kernel: eight output pixels per step. A pixel's horizontal pairs (p00, p01) and
 * (p10, p11) are one 16-bit load each (pinsrw), so it costs two loads instead of four, and the
 * row address is shared while the eight pixels read the same source rows (a near-horizontal
 * warp: almost always). Weights come from the coordinates' 16-bit fractions, which wrap like
 * the low halves of the Q16 sums; the blends are pmullw and pmaddwd on the reference's 7-bit
 * weights, its bytes exactly. Rows that need clamping, or are not planar, use the reference. */
#include "stab_kernels.h"
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>

static int load_pair(const uint8_t *p)
{
    uint16_t v;
    memcpy(&v, p, sizeof v);   /* unaligned */
    return v;
}

/* low 16 bits of q as the bit pattern of a short (defined for every q, unlike a cast) */
static short low16(int32_t q) { return (short)((q & 0x7fff) - (q & 0x8000)); }

/* the fractions (q + k dq) & 0xffff, k = 0..7, in 16-bit lanes */
static __m128i fractions(int32_t q, int32_t dq)
{
    return _mm_setr_epi16(low16(q), low16(q + dq), low16(q + 2 * dq), low16(q + 3 * dq),
                          low16(q + 4 * dq), low16(q + 5 * dq), low16(q + 6 * dq), low16(q + 7 * dq));
}

/* HOME__WARP_WEIGHT of 16-bit fractions: (f + 256) >> 9 = ((f >> 8) + 1) >> 1, pavgw with 0 */
static __m128i weight(__m128i frac) { return _mm_avg_epu16(_mm_srli_epi16(frac, 8), _mm_setzero_si128()); }

static void warp_row_sse(const uint8_t *src, ptrdiff_t stride, int step, int w, int h, int32_t x0,
                         int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n)
{
    const __m128i zero = _mm_setzero_si128(), round = _mm_set1_epi32(8192);
    const __m128i c128 = _mm_set1_epi16(128), low = _mm_set1_epi16(0xff);
    const __m128i step_x = _mm_set1_epi16(low16(8 * dx)), step_y = _mm_set1_epi16(low16(8 * dy));
    __m128i frac_x, frac_y;
    int32_t x = x0, y = y0;
    int i = 0;
    if (step != 1 || dst_step != 1 || !home__warp_row_inside(w, h, x0, y0, dx, dy, n)) {
        home__warp_row_c(src, stride, step, w, h, x0, y0, dx, dy, dst, dst_step, n);
        return;
    }
    frac_x = fractions(x0, dx);
    frac_y = fractions(y0, dy);
    for (; i + 8 <= n; i += 8, x += 8 * dx, y += 8 * dy) {
        __m128i top = zero, bot = zero, fx, fy, gx, gy, t, b, r0, r1;
        const uint8_t *row = src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride;
        uint32_t xs = (uint32_t)x;   /* >= 0 in an inside row; unsigned: no sign extensions */
        /* affine: the eight pixels share their rows when the first and the last do; else (a
         * row of the warp crossing a source row: rare) the reference does them */
        if ((y >> HOME__WARP_FRAC_BITS) != ((y + 7 * dy) >> HOME__WARP_FRAC_BITS)) {
            home__warp_row_c(src, stride, 1, w, h, x, y, dx, dy, dst + i, 1, 8);
            goto next;
        }
#define SSE_LANE(k)                                                                        \
    {                                                                                      \
        const uint8_t *p = row + (xs >> HOME__WARP_FRAC_BITS);                             \
        top = _mm_insert_epi16(top, load_pair(p), k);                                      \
        bot = _mm_insert_epi16(bot, load_pair(p + stride), k);                             \
        xs += (uint32_t)dx;                                                                \
    }
        SSE_LANE(0) SSE_LANE(1) SSE_LANE(2) SSE_LANE(3) SSE_LANE(4) SSE_LANE(5) SSE_LANE(6) SSE_LANE(7)
#undef SSE_LANE
        fx = weight(frac_x);
        gx = _mm_sub_epi16(c128, fx);
        fy = weight(frac_y);
        gy = _mm_sub_epi16(c128, fy);
        /* horizontal: p0 (128 - fx) + p1 fx <= 32640, exact in 16 bits */
        t = _mm_add_epi16(_mm_mullo_epi16(_mm_and_si128(top, low), gx), _mm_mullo_epi16(_mm_srli_epi16(top, 8), fx));
        b = _mm_add_epi16(_mm_mullo_epi16(_mm_and_si128(bot, low), gx), _mm_mullo_epi16(_mm_srli_epi16(bot, 8), fx));
        /* vertical: top (128 - fy) + bot fy in 32 bits */
        r0 = _mm_madd_epi16(_mm_unpacklo_epi16(t, b), _mm_unpacklo_epi16(gy, fy));
        r1 = _mm_madd_epi16(_mm_unpackhi_epi16(t, b), _mm_unpackhi_epi16(gy, fy));
        r0 = _mm_srli_epi32(_mm_add_epi32(r0, round), 14);
        r1 = _mm_srli_epi32(_mm_add_epi32(r1, round), 14);
        r0 = _mm_packs_epi32(r0, r1);
        _mm_storel_epi64((__m128i *)(void *)(dst + i), _mm_packus_epi16(r0, r0));
    next:
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
