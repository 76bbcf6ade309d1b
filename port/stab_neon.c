/* NEON warp row kernel: eight output pixels per step. While the row of the warp stays on one
 * source row pair and dx is in [0, 2) (every stabilisation warp), a group's pairs lie in a
 * 16-byte window per row: one load per row and four table lookups (p00, p01, p10, p11) whose
 * indices come from the x fractions alone (pixel k's pair is at window offset (k dx) >> 16 plus
 * the carry of its fraction), as in port/stab_avx2.c; a group crossing a source row looks up
 * three row windows and selects per pixel. Other groups gather per pixel. The blend: widening
 * multiplies and rounding narrowing shifts that give the reference's bytes exactly. Body only
 * (home__stab_kernels). */
#include "stab_kernels.h"
#include <string.h>
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
#include <arm_neon.h>

static uint16_t load_pair(const uint8_t *p)
{
    uint16_t v;
    memcpy(&v, p, sizeof v);   /* unaligned */
    return v;
}

/* bytes w[idx[k]], idx[k] < 16 */
static inline uint8x8_t lookup(uint8x16_t w, uint8x8_t idx)
{
#if defined(__aarch64__)
    return vqtbl1_u8(w, idx);
#else
    uint8x8x2_t t;
    t.val[0] = vget_low_u8(w);
    t.val[1] = vget_high_u8(w);
    return vtbl2_u8(t, idx);
#endif
}

/* eight pixels' p00, p01 (top row) and p10, p11 (bottom row) blended with the reference's 7-bit
 * weights of fractions frac_x, frac_y into dst[0..7], its bytes exactly */
static inline void blend8(uint8x8_t p00, uint8x8_t p01, uint8x8_t p10, uint8x8_t p11,
                          uint16x8_t frac_x, uint16x8_t frac_y, uint8_t *dst)
{
    /* HOME__WARP_WEIGHT: vrshr computes (f + 256) >> 9 without overflowing 16 bits */
    const uint8x8_t fx = vmovn_u16(vrshrq_n_u16(frac_x, 9)), gx = vsub_u8(vdup_n_u8(128), fx);
    const uint16x8_t fy = vrshrq_n_u16(frac_y, 9), gy = vsubq_u16(vdupq_n_u16(128), fy);
    const uint16x8_t t = vmlal_u8(vmull_u8(p00, gx), p01, fx),
                     b = vmlal_u8(vmull_u8(p10, gx), p11, fx);
    const uint32x4_t r0 = vmlal_u16(vmull_u16(vget_low_u16(t), vget_low_u16(gy)), vget_low_u16(b),
                                    vget_low_u16(fy));
    const uint32x4_t r1 = vmlal_u16(vmull_u16(vget_high_u16(t), vget_high_u16(gy)),
                                    vget_high_u16(b), vget_high_u16(fy));
    /* vrshrn: (r + 2^13) >> 14 */
    vst1_u8(dst, vmovn_u16(vcombine_u16(vrshrn_n_u32(r0, 14), vrshrn_n_u32(r1, 14))));
}

/* eight pixels from (x, y) (Q16, inside the plane) gathered per pixel, each from its own rows:
 * the groups the window path does not take */
static void gather8(const uint8_t *src, ptrdiff_t stride, uint32_t x, uint32_t y, int32_t dx,
                    int32_t dy, uint16x8_t frac_x, uint16x8_t frac_y, uint8_t *dst)
{
    uint16x8_t top = vdupq_n_u16(0), bot = vdupq_n_u16(0);
#define NEON_LANE(k)                                                                               \
    {                                                                                              \
        const uint8_t *p = src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride +                 \
                           (x >> HOME__WARP_FRAC_BITS);                                            \
        top = vsetq_lane_u16(load_pair(p), top, k);                                                \
        bot = vsetq_lane_u16(load_pair(p + stride), bot, k);                                       \
        x += (uint32_t)dx;                                                                         \
        y += (uint32_t)dy;                                                                         \
    }
    NEON_LANE(0)
    NEON_LANE(1) NEON_LANE(2) NEON_LANE(3) NEON_LANE(4) NEON_LANE(5) NEON_LANE(6) NEON_LANE(7)
#undef NEON_LANE
        blend8(vmovn_u16(top), vshrn_n_u16(top, 8), vmovn_u16(bot), vshrn_n_u16(bot, 8), frac_x,
               frac_y, dst);
}

static void warp_row_neon(const uint8_t *src, ptrdiff_t stride, int w, int32_t x0, int32_t y0,
                          int32_t dx, int32_t dy, uint8_t *dst, int n)
{
    const uint16x8_t step_x = vdupq_n_u16((uint16_t)(8u * (uint32_t)dx)),
                     step_y = vdupq_n_u16((uint16_t)(8u * (uint32_t)dy));
    const uint32_t dx8 = 8u * (uint32_t)dx, dy7 = 7u * (uint32_t)dy, dy8 = 8u * (uint32_t)dy;
    /* a / |dy8| for a < 2^16 as a multiply by ceil(2^32 / |dy8|), exact (the error a e / 2^32,
     * e < |dy8| <= 2^16, stays below 1 / |dy8|): armv7 has no divide instruction, and the runs
     * below need one each. 0: |dy8| > a, the quotient is 0. */
    const uint32_t ady8 = dy > 0 ? dy8 : 0u - dy8;
    const uint32_t dy8_inv = ady8 >= 8 && ady8 <= 0xffffu ? 0xffffffffu / ady8 + 1 : 0;
    /* the window path: a group's pairs within 16 bytes (dx in [0, 2): pixel 7's pair at offset
     * <= 13 + 1) and the window inside the row (x >> 16 <= w - 16: x < xlim); x grows, so a
     * prefix of the groups */
    const uint32_t xlim = dx >= 0 && dx < (2 << HOME__WARP_FRAC_BITS) && w >= 16
                              ? (uint32_t)(w - 15) << HOME__WARP_FRAC_BITS
                              : 0;
    /* 7 |dy| < 2^16: a group spans at most two source rows */
    const int cross = dy > -8192 && dy < 8192;
    static const uint16_t lanes[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    const uint16x8_t lane = vld1q_u16(lanes);
    uint16x8_t frac_x, frac_y, edge;
    uint8x8_t k0, k1;
    const uint8_t *row;
    uint8_t *d = dst, *const end = dst + n, *fast_end;
    /* lo: first Q16 y of the tracked source row; yrel: the group's last y - lo */
    uint32_t x = (uint32_t)x0, lo, yrel;
    {
        /* pixel k of a group (first pixel's fraction f) has its pair at window offset D_k + carry,
         * D_k = (k dx) >> 16, carry = f + (k dx & 0xffff) >= 2^16: its own fraction below
         * e_k = k dx & 0xffff. The indices D_k + 1 + carry, D_k + 2 + carry less one where
         * "fraction >= e_k" (mask bytes 0xff) give p0 and p1. */
        uint8_t dk[8];
        const uint32_t groups = (uint32_t)n / 8;
        uint32_t fast = 0;
        int k;
        for (k = 0; k < 8; k++)
            dk[k] = (uint8_t)(((uint32_t)k * (uint32_t)dx >> HOME__WARP_FRAC_BITS & 0x3f) + 1);
        k0 = vld1_u8(dk);
        k1 = vadd_u8(k0, vdup_n_u8(1));
        edge = vmulq_n_u16(lane, (uint16_t)dx);
        if (x < xlim) fast = dx8 ? (xlim - 1 - x) / dx8 + 1 : groups;
        fast_end = dst + 8 * (ptrdiff_t)(fast < groups ? fast : groups);
    }
    /* k dq & 0xffff = k (dq & 0xffff) & 0xffff: the fractions of pixels k = 0..7 are the first's
     * plus lanes k of these (wrapping like the Q16 sums) */
    frac_x = vaddq_u16(vdupq_n_u16((uint16_t)x0), edge);
    frac_y = vaddq_u16(vdupq_n_u16((uint16_t)y0), vmulq_n_u16(lane, (uint16_t)dy));
    row = home__stab_track_row(src, stride, (uint32_t)y0, dy7, &lo, &yrel);
    while (d < end) {
        if (d < fast_end && yrel < 0x10000u) {
            /* affine: a group's first pixel is on the tracked row when the previous group's last
             * was, so its last decides: the groups up to stop stay on it (yrel + (g - 1) dy8 in
             * [0, 2^16) for g of them) */
            const uint8_t *const row1 = row + stride;
            const uint32_t g =
                dy ? (uint32_t)((uint64_t)(dy > 0 ? 0xffffu - yrel : yrel) * dy8_inv >> 32) + 1
                   : 0xffffffu;
            uint8_t *const stop = (uint32_t)(fast_end - d) / 8 > g ? d + 8 * (ptrdiff_t)g
                                                                   : fast_end;
            yrel += (uint32_t)(stop - d) / 8 * dy8;
            do {
                const uint8x8_t m = vmovn_u16(vcgeq_u16(frac_x, edge)), i0 = vadd_u8(k0, m),
                                i1 = vadd_u8(k1, m);
                const uint32_t base = x >> HOME__WARP_FRAC_BITS;
                const uint8x16_t wt = vld1q_u8(row + base), wb = vld1q_u8(row1 + base);
                blend8(lookup(wt, i0), lookup(wt, i1), lookup(wb, i0), lookup(wb, i1), frac_x,
                       frac_y, d);
                frac_x = vaddq_u16(frac_x, step_x);
                frac_y = vaddq_u16(frac_y, step_y);
                x += dx8;
                d += 8;
            } while (d < stop);
            continue;
        }
        {
            const uint32_t y = lo + yrel - dy7, next = y + dy8;
            /* the row was crossed before this group: track the new one */
            if ((y & ~0xffffu) != lo) {
                row = home__stab_track_row(src, stride, y, dy7, &lo, &yrel);
                continue;
            }
            if (d < fast_end && cross) {
                /* the eight pixels cross one source row: the first is on the tracked row, the
                 * rest there or on the next one in dy's direction, which its fraction tells:
                 * dy > 0, at least the first's; dy < 0, at most */
                const uint8x8_t m = vmovn_u16(vcgeq_u16(frac_x, edge)), i0 = vadd_u8(k0, m),
                                i1 = vadd_u8(k1, m);
                const uint16x8_t f0 = vdupq_n_u16(vgetq_lane_u16(frac_y, 0));
                const uint8x8_t same = vmovn_u16(dy > 0 ? vcgeq_u16(frac_y, f0)
                                                        : vcleq_u16(frac_y, f0));
                const uint8_t *other = dy > 0 ? row + stride : row - stride;
                const uint8x16_t wt = vld1q_u8(row + (x >> HOME__WARP_FRAC_BITS)),
                                 wb = vld1q_u8(row + stride + (x >> HOME__WARP_FRAC_BITS));
                const uint8x16_t wo =
                    vld1q_u8((dy > 0 ? other + stride : other) + (x >> HOME__WARP_FRAC_BITS));
                const uint8x16_t ot = dy > 0 ? wb : wo, ob = dy > 0 ? wo : wt;
                blend8(vbsl_u8(same, lookup(wt, i0), lookup(ot, i0)),
                       vbsl_u8(same, lookup(wt, i1), lookup(ot, i1)),
                       vbsl_u8(same, lookup(wb, i0), lookup(ob, i0)),
                       vbsl_u8(same, lookup(wb, i1), lookup(ob, i1)), frac_x, frac_y, d);
            } else {
                gather8(src, stride, x, y, dx, dy, frac_x, frac_y, d);
            }
            frac_x = vaddq_u16(frac_x, step_x);
            frac_y = vaddq_u16(frac_y, step_y);
            x += dx8;
            d += 8;
            if (d < end) {   /* next is a pixel of the row: inside; track its row */
                row = home__stab_track_row(src, stride, next, dy7, &lo, &yrel);
            }
        }
    }
}

const home__stab_kernels home__stab_kernels_neon = { .name = "neon",
                                                     .block = 8,
                                                     .warp_row = warp_row_neon };
#else
typedef int home__stab_neon_unused; /* ISO C forbids an empty translation unit */
#endif
