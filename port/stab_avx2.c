/* AVX2-machine warp row kernel (compiled with -mavx2, used when the CPU has AVX2): sixteen output
 * pixels per step, two groups of eight in the two 128-bit lanes. While the row of the warp stays
 * on one source row pair and dx is in [0, 2) (every stabilisation warp), each group's pairs lie
 * in a 16-byte window per row: one load per row and lane and a byte shuffle (pshufb) whose
 * control comes from the x fractions alone (pixel k's pair is at window offset
 * (k dx) >> 16 plus the carry of its fraction). The blend is pmaddubsw (horizontal, on pixels
 * offset by -128 so that the weight 128 fits a byte) and pmaddwd (vertical). Other groups gather
 * per pixel (port/stab_x86.h). Same bytes as the reference. Body only (home__stab_kernels). */
#include "kernels.h"
#include "stab_kernels.h"
#if defined(HOME__HAVE_AVX2) && defined(__AVX2__)
#include "stab_x86.h"
#include <immintrin.h>

/* Sixteen pixels (lanes: pixels 0-7 | 8-15) whose pairs sit as p0 | p1 << 8 in the 16-bit lanes
 * of top and bottom, blended with the reference's 7-bit weights (16-bit results), its bytes
 * exactly: with fx = HOME__WARP_WEIGHT of the x fraction, the bytes (128 - fx, fx) times the
 * pairs less 128 give top - 16384 (|products| <= 2^14: no saturation), and
 * (top - 2^14) (128 - fy) + (bot - 2^14) fy = R - 2^21, so the result is (that + 2^21 + 2^13)
 * >> 14. */
static inline __m256i blend16_words(__m256i top, __m256i bot, __m256i frac_x, __m256i frac_y)
{
    const __m256i zero = _mm256_setzero_si256(), c128 = _mm256_set1_epi16(128),
                  flip = _mm256_set1_epi8(-128);
    /* HOME__WARP_WEIGHT of 16-bit fractions: (f + 256) >> 9 = ((f >> 8) + 1) >> 1, pavgw with 0 */
    const __m256i fx = _mm256_avg_epu16(_mm256_srli_epi16(frac_x, 8), zero);
    /* 128 - fx | fx << 8 */
    const __m256i wx = _mm256_add_epi16(_mm256_mullo_epi16(fx, _mm256_set1_epi16(255)), c128);
    const __m256i fy = _mm256_avg_epu16(_mm256_srli_epi16(frac_y, 8), zero),
                  gy = _mm256_sub_epi16(c128, fy);
    const __m256i t = _mm256_maddubs_epi16(wx, _mm256_xor_si256(top, flip));
    const __m256i b = _mm256_maddubs_epi16(wx, _mm256_xor_si256(bot, flip));
    const __m256i round = _mm256_set1_epi32((1 << 21) + (1 << 13));
    __m256i r0 = _mm256_madd_epi16(_mm256_unpacklo_epi16(t, b), _mm256_unpacklo_epi16(gy, fy));
    __m256i r1 = _mm256_madd_epi16(_mm256_unpackhi_epi16(t, b), _mm256_unpackhi_epi16(gy, fy));
    r0 = _mm256_srli_epi32(_mm256_add_epi32(r0, round), 14);
    r1 = _mm256_srli_epi32(_mm256_add_epi32(r1, round), 14);
    return _mm256_packs_epi32(r0, r1);   /* 16-bit lanes: pixels 0-7 | 8-15 */
}

/* blend16_words's pixels into dst[0..15] */
static inline void blend16(__m256i top, __m256i bot, __m256i frac_x, __m256i frac_y, uint8_t *dst)
{
    const __m256i r = _mm256_packus_epi16(blend16_words(top, bot, frac_x, frac_y),
                                          _mm256_setzero_si256());
    /* lanes: bytes 0-7 | 8-15 */
    _mm_storeu_si128((__m128i *)(void *)dst,
                     _mm256_castsi256_si128(_mm256_permute4x64_epi64(r, 0x08)));
}

/* one 16-byte window per row and lane: lane j's window starts at column base_j */
static inline __m256i window(const uint8_t *row, uint32_t base0, uint32_t base1)
{
    return _mm256_inserti128_si256(
        _mm256_castsi128_si256(_mm_loadu_si128((const __m128i *)(const void *)(row + base0))),
        _mm_loadu_si128((const __m128i *)(const void *)(row + base1)), 1);
}

/* sixteen pixels from (x, y) that the shuffle path does not take (a group crossing a source row,
 * a window past the row's end, dx outside [0, 2)): each group of eight from its row pair or, when
 * it crosses a source row, per pixel. Kept out of line: the fast loop keeps its registers. */
__attribute__((noinline)) static void gather16(const uint8_t *src, ptrdiff_t stride, uint32_t x,
                                               uint32_t y, int32_t dx, int32_t dy, __m256i frac_x,
                                               __m256i frac_y, uint8_t *dst)
{
    __m128i t0, b0, t1, b1;
    home__stab_gather8_any(src, stride, x, y, dx, dy, &t0, &b0);
    home__stab_gather8_any(src, stride, x + 8u * (uint32_t)dx, y + 8u * (uint32_t)dy, dx, dy, &t1,
                           &b1);
    blend16(_mm256_inserti128_si256(_mm256_castsi128_si256(t0), t1, 1),
            _mm256_inserti128_si256(_mm256_castsi128_si256(b0), b1, 1), frac_x, frac_y, dst);
}

static void warp_row_avx2(const uint8_t *src, ptrdiff_t stride, int w, int32_t x0, int32_t y0,
                          int32_t dx, int32_t dy, uint8_t *dst, int n)
{
    const uint32_t dx8 = 8u * (uint32_t)dx, dx16 = 16u * (uint32_t)dx, dy15 = 15u * (uint32_t)dy,
                   dy16 = 16u * (uint32_t)dy;
    /* the shuffle path: the pairs of a group of eight within 16 bytes (dx in [0, 2): pixel 7's
     * pair at offset <= 13 + 1) and the windows inside the row (x8 >> 16 <= w - 16, x8 = x + 8 dx
     * the second group's first pixel: x8 < xlim); x grows, so a prefix of the groups */
    const uint32_t xlim = dx >= 0 && dx < (2 << HOME__WARP_FRAC_BITS) && w >= 16
                              ? (uint32_t)(w - 15) << HOME__WARP_FRAC_BITS
                              : 0;
    /* 15 |dy| < 2^16: a group spans at most two source rows */
    const int cross = dy > -4096 && dy < 4096;
    const __m256i lane = _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    __m256i frac_x, frac_y, edge, pairs, step_x, step_y;
    const uint8_t *row;
    uint8_t *d = dst, *const end = dst + n, *fast_end;
    /* lo: first Q16 y of the tracked source row; yrel: the group's last y - lo */
    uint32_t x = (uint32_t)x0, lo, yrel;
    {
        /* k dq & 0xffff = k (dq & 0xffff) & 0xffff: the fractions of pixels k = 0..15 are the
         * first's plus lanes k of these (wrapping like the Q16 sums) */
        const __m256i ex = _mm256_mullo_epi16(_mm256_set1_epi16(home__stab_low16(0, dx, 1)), lane);
        const __m256i ey = _mm256_mullo_epi16(_mm256_set1_epi16(home__stab_low16(0, dy, 1)), lane);
        /* pixel k of a group (first pixel's fraction f) has its pair at window offset D_k + carry,
         * D_k = (k dx) >> 16, carry = f + (k dx & 0xffff) >= 2^16: its own fraction below
         * e_k = k dx & 0xffff. The control bytes (D_k + carry, D_k + 1 + carry) are
         * pairs = (D_k + 1) 0x0101 + 0x0100 less the bytes of the mask "fraction >= e_k" (all
         * ones). Only used with dx in [0, 2): k dx < 2^20, D_k < 16. */
        const __m256i kdx = _mm256_mullo_epi32(_mm256_set1_epi32(dx & 0x1ffff),
                                               _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        const __m256i dk = _mm256_packus_epi32(_mm256_srli_epi32(kdx, HOME__WARP_FRAC_BITS),
                                               _mm256_setzero_si256());
        const uint32_t groups = (uint32_t)n / 16;
        uint32_t fast = 0;
        pairs = _mm256_add_epi16(
            _mm256_mullo_epi16(_mm256_permute4x64_epi64(dk, 0x88), _mm256_set1_epi16(257)),
            _mm256_set1_epi16(513)); /* lanes 0-7 | 0-7 */
        edge = _mm256_permute2x128_si256(ex, ex, 0x00);
        step_x = _mm256_set1_epi16(home__stab_low16(0, dx, 16));
        step_y = _mm256_set1_epi16(home__stab_low16(0, dy, 16));
        frac_x = _mm256_add_epi16(_mm256_set1_epi16(home__stab_low16((uint32_t)x0, 0, 0)), ex);
        frac_y = _mm256_add_epi16(_mm256_set1_epi16(home__stab_low16((uint32_t)y0, 0, 0)), ey);
        if (x + dx8 < xlim) fast = dx16 ? (xlim - 1 - x - dx8) / dx16 + 1 : groups;
        fast_end = dst + 16 * (ptrdiff_t)(fast < groups ? fast : groups);
    }
    row = home__stab_track_row(src, stride, (uint32_t)y0, dy15, &lo, &yrel);
    while (d < end) {
        if (d < fast_end && yrel < 0x10000u) {
            /* affine: a group's first pixel is on the tracked row when the previous group's last
             * was, so its last decides: the groups up to stop stay on it (yrel + (g - 1) dy16 in
             * [0, 2^16) for g of them) */
            const uint8_t *const row1 = row + stride;
            const uint32_t g = dy > 0   ? (0xffffu - yrel) / dy16 + 1
                               : dy < 0 ? yrel / (0u - dy16) + 1
                                        : 0xffffffu;
            uint8_t *const stop = (uint32_t)(fast_end - d) / 16 > g ? d + 16 * (ptrdiff_t)g
                                                                    : fast_end;
            yrel += (uint32_t)(stop - d) / 16 * dy16;
#define HOME__STAB_GROUP(words, x)                                                                 \
    {                                                                                              \
        const __m256i ctrl =                                                                       \
            _mm256_add_epi8(pairs, _mm256_cmpeq_epi16(_mm256_max_epu16(frac_x, edge), frac_x));    \
        const uint32_t base0 = (x) >> HOME__WARP_FRAC_BITS,                                        \
                       base1 = ((x) + dx8) >> HOME__WARP_FRAC_BITS;                                \
        words = blend16_words(_mm256_shuffle_epi8(window(row, base0, base1), ctrl),                \
                              _mm256_shuffle_epi8(window(row1, base0, base1), ctrl), frac_x,       \
                              frac_y);                                                             \
        frac_x = _mm256_add_epi16(frac_x, step_x);                                                 \
        frac_y = _mm256_add_epi16(frac_y, step_y);                                                 \
    }
            for (; d + 32 <= stop; d += 32, x += 2 * dx16) {   /* two groups: one pack and store */
                __m256i r0, r1;
                HOME__STAB_GROUP(r0, x)
                HOME__STAB_GROUP(r1, x + dx16)
                _mm256_storeu_si256((__m256i *)(void *)d,
                                    _mm256_permute4x64_epi64(_mm256_packus_epi16(r0, r1), 0xd8));
            }
            if (d < stop) {
                __m256i r0;
                HOME__STAB_GROUP(r0, x)
                r0 = _mm256_packus_epi16(r0, _mm256_setzero_si256());
                _mm_storeu_si128((__m128i *)(void *)d,
                                 _mm256_castsi256_si128(_mm256_permute4x64_epi64(r0, 0x08)));
                x += dx16;
                d += 16;
            }
#undef HOME__STAB_GROUP
            continue;
        }
        {
            const uint32_t y = lo + yrel - dy15, next = y + dy16;
            /* the row was crossed before this group: track the new one */
            if ((y & ~0xffffu) != lo) {
                row = home__stab_track_row(src, stride, y, dy15, &lo, &yrel);
                continue;
            }
            if (d < fast_end && cross) {
                /* the sixteen pixels cross one source row (|15 dy| < 2^16): the first is on the
                 * tracked row, the rest there or on the next one in dy's direction, which its
                 * fraction tells: dy > 0, at least the first's; dy < 0, at most */
                const __m256i ctrl = _mm256_add_epi8(
                    pairs, _mm256_cmpeq_epi16(_mm256_max_epu16(frac_x, edge), frac_x));
                const __m256i f0 = _mm256_broadcastw_epi16(_mm256_castsi256_si128(frac_y));
                const __m256i same = _mm256_cmpeq_epi16(
                    dy > 0 ? _mm256_max_epu16(frac_y, f0) : _mm256_min_epu16(frac_y, f0), frac_y);
                const uint32_t base0 = x >> HOME__WARP_FRAC_BITS,
                               base1 = (x + dx8) >> HOME__WARP_FRAC_BITS;
                const uint8_t *other = dy > 0 ? row + stride : row - stride;
                const __m256i t0 = _mm256_shuffle_epi8(window(row, base0, base1), ctrl);
                const __m256i b0 = _mm256_shuffle_epi8(window(row + stride, base0, base1), ctrl);
                const __m256i t1 = dy > 0 ? b0
                                          : _mm256_shuffle_epi8(window(other, base0, base1), ctrl);
                const __m256i b1 =
                    dy > 0 ? _mm256_shuffle_epi8(window(other + stride, base0, base1), ctrl) : t0;
                blend16(_mm256_blendv_epi8(t1, t0, same), _mm256_blendv_epi8(b1, b0, same), frac_x,
                        frac_y, d);
            } else {
                gather16(src, stride, x, y, dx, dy, frac_x, frac_y, d);
            }
            frac_x = _mm256_add_epi16(frac_x, step_x);
            frac_y = _mm256_add_epi16(frac_y, step_y);
            x += dx16;
            d += 16;
            if (d < end) {   /* next is a pixel of the row: inside; track its row */
                row = home__stab_track_row(src, stride, next, dy15, &lo, &yrel);
            }
        }
    }
}

const home__stab_kernels home__stab_kernels_avx2 = { .name = "avx2",
                                                     .block = 16,
                                                     .warp_row = warp_row_avx2 };
#else
typedef int home__stab_avx2_unused; /* ISO C forbids an empty translation unit */
#endif
