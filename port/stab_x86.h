/* The x86 warp kernels' shared steps (port/stab_sse.c, port/stab_avx2.c). A pixel's horizontal
 * pairs (p00, p01), (p10, p11) sit as p0 | p1 << 8 in the 16-bit lanes of top and bottom; the
 * weights come from the coordinates' 16-bit fractions, which wrap like the low halves of the Q16
 * sums. Included by one file per instruction set: static inline, so each compiles it with its
 * flags. The SSE2 blend is here; the AVX2 kernel blends with pmaddubsw (port/stab_avx2.c). */
#ifndef HOME_STAB_X86_H
#define HOME_STAB_X86_H
#include "stab_kernels.h"
#include <emmintrin.h>
#include <string.h>

static inline int home__stab_load_pair(const uint8_t *p)
{
    uint16_t v;
    memcpy(&v, p, sizeof v);   /* unaligned */
    return v;
}

/* low 16 bits of q + k dq (wrapping: defined past the row's end too) as the bit pattern of a
 * short (defined for every value, unlike a cast) */
static inline short home__stab_low16(uint32_t q, int32_t dq, int k)
{
    const uint32_t v = q + (uint32_t)k * (uint32_t)dq;
    return (short)((int)(v & 0x7fff) - (int)(v & 0x8000));
}

/* the fractions (q + k dq) & 0xffff, k = 0..7, in 16-bit lanes */
static inline __m128i home__stab_fractions(uint32_t q, int32_t dq)
{
    return _mm_setr_epi16(home__stab_low16(q, dq, 0), home__stab_low16(q, dq, 1),
                          home__stab_low16(q, dq, 2), home__stab_low16(q, dq, 3),
                          home__stab_low16(q, dq, 4), home__stab_low16(q, dq, 5),
                          home__stab_low16(q, dq, 6), home__stab_low16(q, dq, 7));
}

/* q + k dq in 32 bits, wrapping, as an int32_t (defined for every value, unlike a cast) */
static inline int32_t home__stab_wrap32(uint32_t q, int32_t dq, int k)
{
    const uint32_t v = q + (uint32_t)k * (uint32_t)dq;
    return v <= 0x7fffffffu ? (int32_t)v : -(int32_t)(~v) - 1;
}

/* Q16 x of pixels 0-3 (*xa) and 4-7 (*xb) of a group whose first pixel is at x */
static inline void home__stab_xs(uint32_t x, int32_t dx, __m128i *xa, __m128i *xb)
{
    *xa = _mm_setr_epi32(home__stab_wrap32(x, dx, 0), home__stab_wrap32(x, dx, 1),
                         home__stab_wrap32(x, dx, 2), home__stab_wrap32(x, dx, 3));
    *xb = _mm_add_epi32(*xa, _mm_set1_epi32(home__stab_wrap32(0, dx, 4)));
}

/* pairs of eight pixels on one source row pair: pixel k's source column is lane k of
 * packs(xa >> 16, xb >> 16) (Q16 x >= 0, so at most HOME_MAX_SIDE: 16 bits), one pextrw and two
 * 16-bit loads (pinsrw) per pixel */
static inline void home__stab_gather8(const uint8_t *row, ptrdiff_t stride, __m128i xa, __m128i xb,
                                      __m128i *top, __m128i *bot)
{
    const __m128i col = _mm_packs_epi32(_mm_srli_epi32(xa, HOME__WARP_FRAC_BITS),
                                        _mm_srli_epi32(xb, HOME__WARP_FRAC_BITS));
    const uint8_t *row1 = row + stride;
    __m128i t = _mm_setzero_si128(), b = _mm_setzero_si128();
#define HOME__STAB_LANE(k)                                                                  \
    {                                                                                       \
        const int c = _mm_extract_epi16(col, k);                                            \
        t = _mm_insert_epi16(t, home__stab_load_pair(row + c), k);                          \
        b = _mm_insert_epi16(b, home__stab_load_pair(row1 + c), k);                         \
    }
    HOME__STAB_LANE(0) HOME__STAB_LANE(1) HOME__STAB_LANE(2) HOME__STAB_LANE(3)
    HOME__STAB_LANE(4) HOME__STAB_LANE(5) HOME__STAB_LANE(6) HOME__STAB_LANE(7)
#undef HOME__STAB_LANE
    *top = t;
    *bot = b;
}

/* the same for eight pixels whose source rows differ (a warp row crossing a source row) */
static inline void home__stab_gather8_rows(const uint8_t *src, ptrdiff_t stride, uint32_t x,
                                           int32_t y, int32_t dx, int32_t dy, __m128i *top,
                                           __m128i *bot)
{
    __m128i t = _mm_setzero_si128(), b = _mm_setzero_si128();
#define HOME__STAB_LANE(k)                                                                         \
    {                                                                                              \
        const uint8_t *p = src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride +                 \
                           (x >> HOME__WARP_FRAC_BITS);                                            \
        t = _mm_insert_epi16(t, home__stab_load_pair(p), k);                                       \
        b = _mm_insert_epi16(b, home__stab_load_pair(p + stride), k);                              \
        x += (uint32_t)dx;                                                                         \
        y += dy;                                                                                   \
    }
    HOME__STAB_LANE(0) HOME__STAB_LANE(1) HOME__STAB_LANE(2) HOME__STAB_LANE(3)
    HOME__STAB_LANE(4) HOME__STAB_LANE(5) HOME__STAB_LANE(6) HOME__STAB_LANE(7)
#undef HOME__STAB_LANE
    *top = t;
    *bot = b;
}

/* pairs of the eight pixels from (x, y) (Q16, all inside the plane), from one row pair when
 * they share it (affine: when the first and the last do), else from each pixel's own rows */
static inline void home__stab_gather8_any(const uint8_t *src, ptrdiff_t stride, uint32_t x,
                                          uint32_t y, int32_t dx, int32_t dy, __m128i *top,
                                          __m128i *bot)
{
    if ((y >> HOME__WARP_FRAC_BITS) == ((y + 7u * (uint32_t)dy) >> HOME__WARP_FRAC_BITS)) {
        __m128i xa, xb;
        home__stab_xs(x, dx, &xa, &xb);
        home__stab_gather8(src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride, stride, xa, xb,
                           top, bot);
    } else {
        home__stab_gather8_rows(src, stride, x, (int32_t)y, dx, dy, top, bot);
    }
}

/* blend eight pixels' pairs with the weights of fractions frac_x, frac_y into dst[0..7] (SSE2) */
static inline void home__stab_blend8(__m128i top, __m128i bot, __m128i frac_x, __m128i frac_y,
                                     uint8_t *dst)
{
    const __m128i zero = _mm_setzero_si128(), c128 = _mm_set1_epi16(128),
                  low = _mm_set1_epi16(0xff);
    /* HOME__WARP_WEIGHT of 16-bit fractions: (f + 256) >> 9 = ((f >> 8) + 1) >> 1, pavgw with 0 */
    const __m128i fx = _mm_avg_epu16(_mm_srli_epi16(frac_x, 8), zero), gx = _mm_sub_epi16(c128, fx);
    const __m128i fy = _mm_avg_epu16(_mm_srli_epi16(frac_y, 8), zero), gy = _mm_sub_epi16(c128, fy);
    /* horizontal: p0 (128 - fx) + p1 fx <= 32640, exact in 16 bits */
    const __m128i t = _mm_add_epi16(_mm_mullo_epi16(_mm_and_si128(top, low), gx),
                                    _mm_mullo_epi16(_mm_srli_epi16(top, 8), fx));
    const __m128i b = _mm_add_epi16(_mm_mullo_epi16(_mm_and_si128(bot, low), gx),
                                    _mm_mullo_epi16(_mm_srli_epi16(bot, 8), fx));
    /* vertical: top (128 - fy) + bot fy in 32 bits, (+ 2^13) >> 14 */
    __m128i r0 = _mm_madd_epi16(_mm_unpacklo_epi16(t, b), _mm_unpacklo_epi16(gy, fy));
    __m128i r1 = _mm_madd_epi16(_mm_unpackhi_epi16(t, b), _mm_unpackhi_epi16(gy, fy));
    r0 = _mm_srli_epi32(_mm_add_epi32(r0, _mm_set1_epi32(8192)), 14);
    r1 = _mm_srli_epi32(_mm_add_epi32(r1, _mm_set1_epi32(8192)), 14);
    r0 = _mm_packs_epi32(r0, r1);
    _mm_storel_epi64((__m128i *)(void *)dst, _mm_packus_epi16(r0, r0));
}
#endif
