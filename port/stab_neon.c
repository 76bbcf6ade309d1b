/* NEON warp row kernel: the SSE2 kernel's scheme (port/stab_sse.c) - eight output pixels per
 * step, each pixel's horizontal pairs one 16-bit load from rows shared by the eight (or its own
 * where the eight cross a source row), weights from 16-bit fractions - with widening multiplies
 * and rounding narrowing shifts that give the reference's bytes exactly. Rows that need
 * clamping, or are not planar, use the reference. */
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

/* the fractions (q + k dq) & 0xffff, k = 0..7 */
static uint16x8_t fractions(int32_t q, int32_t dq)
{
    uint16_t f[8];
    int k;
    for (k = 0; k < 8; k++) f[k] = (uint16_t)((uint32_t)q + (uint32_t)k * (uint32_t)dq);   /* wraps */
    return vld1q_u16(f);
}

static void warp_row_neon(const uint8_t *src, ptrdiff_t stride, int step, int w, int h, int32_t x0,
                          int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n)
{
    const uint8x8_t c128 = vdup_n_u8(128);
    const uint16x8_t c128w = vdupq_n_u16(128);
    const uint16x8_t step_x = vdupq_n_u16((uint16_t)(8u * (uint32_t)dx)), step_y = vdupq_n_u16((uint16_t)(8u * (uint32_t)dy));
    uint16x8_t frac_x, frac_y;
    int32_t x = x0, y = y0;
    int i = 0;
    if (step != 1 || dst_step != 1 || !home__warp_row_inside(w, h, x0, y0, dx, dy, n)) {
        home__warp_row_c(src, stride, step, w, h, x0, y0, dx, dy, dst, dst_step, n);
        return;
    }
    frac_x = fractions(x0, dx);
    frac_y = fractions(y0, dy);
    for (; i + 8 <= n; i += 8, x += 8 * dx, y += 8 * dy) {
        uint16x8_t top = vdupq_n_u16(0), bot = vdupq_n_u16(0), t, b, fy, gy;
        uint8x8_t fx, gx;
        uint32x4_t r0, r1;
        uint32_t xs = (uint32_t)x;   /* >= 0 in an inside row */
        int32_t ys = y;
        /* affine: the eight pixels share their rows when the first and the last do; else (a
         * row of the warp crossing a source row) each finds its own */
#define NEON_LANE(k, row)                                                                  \
    {                                                                                      \
        const uint8_t *p = (row) + (xs >> HOME__WARP_FRAC_BITS);                           \
        top = vsetq_lane_u16(load_pair(p), top, k);                                        \
        bot = vsetq_lane_u16(load_pair(p + stride), bot, k);                               \
        xs += (uint32_t)dx;                                                                \
        ys += dy;                                                                          \
    }
        if ((y >> HOME__WARP_FRAC_BITS) == ((y + 7 * dy) >> HOME__WARP_FRAC_BITS)) {
            const uint8_t *row = src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride;
            NEON_LANE(0, row) NEON_LANE(1, row) NEON_LANE(2, row) NEON_LANE(3, row)
            NEON_LANE(4, row) NEON_LANE(5, row) NEON_LANE(6, row) NEON_LANE(7, row)
        } else {
#define NEON_ROW (src + (ptrdiff_t)(ys >> HOME__WARP_FRAC_BITS) * stride)
            NEON_LANE(0, NEON_ROW) NEON_LANE(1, NEON_ROW) NEON_LANE(2, NEON_ROW) NEON_LANE(3, NEON_ROW)
            NEON_LANE(4, NEON_ROW) NEON_LANE(5, NEON_ROW) NEON_LANE(6, NEON_ROW) NEON_LANE(7, NEON_ROW)
#undef NEON_ROW
        }
#undef NEON_LANE
        /* HOME__WARP_WEIGHT: vrshr computes (f + 256) >> 9 without overflowing 16 bits */
        fx = vmovn_u16(vrshrq_n_u16(frac_x, 9));
        gx = vsub_u8(c128, fx);
        fy = vrshrq_n_u16(frac_y, 9);
        gy = vsubq_u16(c128w, fy);
        t = vmlal_u8(vmull_u8(vmovn_u16(top), gx), vshrn_n_u16(top, 8), fx);
        b = vmlal_u8(vmull_u8(vmovn_u16(bot), gx), vshrn_n_u16(bot, 8), fx);
        r0 = vmlal_u16(vmull_u16(vget_low_u16(t), vget_low_u16(gy)), vget_low_u16(b), vget_low_u16(fy));
        r1 = vmlal_u16(vmull_u16(vget_high_u16(t), vget_high_u16(gy)), vget_high_u16(b), vget_high_u16(fy));
        /* vrshrn: (r + 2^13) >> 14 */
        vst1_u8(dst + i, vmovn_u16(vcombine_u16(vrshrn_n_u32(r0, 14), vrshrn_n_u32(r1, 14))));
        frac_x = vaddq_u16(frac_x, step_x);
        frac_y = vaddq_u16(frac_y, step_y);
    }
    if (i < n)   /* the rest of an inside row: the reference's fast path, same bytes */
        home__warp_row_c(src, stride, 1, w, h, x, y, dx, dy, dst + i, 1, n - i);
}

const home__stab_kernels home__stab_kernels_neon = {"neon", warp_row_neon};
#else
typedef int home__stab_neon_unused; /* ISO C forbids an empty translation unit */
#endif
