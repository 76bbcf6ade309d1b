/* NEON warp row kernel: four output pixels per step, scalar gathers of the 2x2 source pixels,
 * vector weights and blends in 32-bit lanes giving the scalar reference's bytes. Rows that need
 * clamping, or are not planar, use the reference. */
#include "stab_kernels.h"
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
#include <arm_neon.h>

static void warp_row_neon(const uint8_t *src, ptrdiff_t stride, int step, int w, int h, int32_t x0,
                          int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n)
{
    const uint32x4_t frac = vdupq_n_u32(0xffff), half = vdupq_n_u32(128), one = vdupq_n_u32(256);
    const uint32x4_t round = vdupq_n_u32(32768);
    const int32x4_t step_x = vdupq_n_s32(4 * dx), step_y = vdupq_n_s32(4 * dy);
    const int32_t lanes[4] = {0, 1, 2, 3};
    int32x4_t vx, vy;
    int i = 0;
    if (step != 1 || dst_step != 1 || !home__warp_row_inside(w, h, x0, y0, dx, dy, n)) {
        home__warp_row_c(src, stride, step, w, h, x0, y0, dx, dy, dst, dst_step, n);
        return;
    }
    vx = vmlaq_n_s32(vdupq_n_s32(x0), vld1q_s32(lanes), dx);
    vy = vmlaq_n_s32(vdupq_n_s32(y0), vld1q_s32(lanes), dy);
    for (; i + 4 <= n; i += 4) {
        int32_t xi[4], yi[4];
        uint32_t a[4], b[4], c[4], d[4];
        uint32x4_t fx, fy, wx, top, bot, res;
        uint16_t out[4];
        int k;
        vst1q_s32(xi, vshrq_n_s32(vx, HOME__WARP_FRAC_BITS));
        vst1q_s32(yi, vshrq_n_s32(vy, HOME__WARP_FRAC_BITS));
        for (k = 0; k < 4; k++) {
            const uint8_t *p = src + (ptrdiff_t)yi[k] * stride + xi[k];
            a[k] = p[0]; b[k] = p[1]; c[k] = p[stride]; d[k] = p[stride + 1];
        }
        fx = vshrq_n_u32(vaddq_u32(vandq_u32(vreinterpretq_u32_s32(vx), frac), half), 8);
        fy = vshrq_n_u32(vaddq_u32(vandq_u32(vreinterpretq_u32_s32(vy), frac), half), 8);
        wx = vsubq_u32(one, fx);
        top = vmlaq_u32(vmulq_u32(vld1q_u32(a), wx), vld1q_u32(b), fx);
        bot = vmlaq_u32(vmulq_u32(vld1q_u32(c), wx), vld1q_u32(d), fx);
        res = vaddq_u32(vmlaq_u32(vmulq_u32(top, vsubq_u32(one, fy)), bot, fy), round);
        vst1_u16(out, vmovn_u32(vshrq_n_u32(res, 16)));
        for (k = 0; k < 4; k++) dst[i + k] = (uint8_t)out[k];
        vx = vaddq_s32(vx, step_x);
        vy = vaddq_s32(vy, step_y);
    }
    if (i < n)   /* the rest of an inside row: the reference's fast path, same bytes */
        home__warp_row_c(src, stride, 1, w, h, x0 + i * dx, y0 + i * dy, dx, dy, dst + i, 1, n - i);
}

const home__stab_kernels home__stab_kernels_neon = {"neon", warp_row_neon};
#else
typedef int home__stab_neon_unused; /* ISO C forbids an empty translation unit */
#endif
