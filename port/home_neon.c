/* NEON kernels (aarch64, and armv7 built with -mfpu=neon). */
#include "kernels.h"
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
#include "simd_f32x4.h"
#include "home_fvec.h"
#include <arm_neon.h>

/* 64 lanes held as 8 x 8 uint16 in registers (vaddw_u8 widens while adding); widened into
 * int32 every 128 rows. Eight named accumulators: gcc keeps an array of vectors indexed in a
 * loop on the stack, a load and a store around every add. */
static void add_lanes(int32_t *dst, uint16x8_t a)
{
    vst1q_s32(dst, vaddq_s32(vld1q_s32(dst), vreinterpretq_s32_u32(vmovl_u16(vget_low_u16(a)))));
    vst1q_s32(dst + 4,
              vaddq_s32(vld1q_s32(dst + 4), vreinterpretq_s32_u32(vmovl_u16(vget_high_u16(a)))));
}

static void radon_blocks_neon(const uint8_t *base, ptrdiff_t stride, const int16_t *shift, int j0,
                              int n_blocks, const int16_t *row_lo, const int16_t *row_hi,
                              int32_t *out)
{
    int b, k;
    for (b = 0; b < n_blocks; b++) {
        int32_t *acc32 = out + (ptrdiff_t)b * HOME__RADON_BLOCK;
        int p = row_lo[b];
        for (k = 0; k < HOME__RADON_BLOCK; k += 4) vst1q_s32(acc32 + k, vdupq_n_s32(0));
        while (p <= row_hi[b]) {
            int end = p + HOME__RADON_ROWS_16BIT - 1 < row_hi[b] ? p + HOME__RADON_ROWS_16BIT - 1
                                                                 : row_hi[b];
            uint16x8_t a0 = vdupq_n_u16(0), a1 = a0, a2 = a0, a3 = a0, a4 = a0, a5 = a0, a6 = a0,
                       a7 = a0;
            for (; p <= end; p++) {
                const uint8_t *src = base + (ptrdiff_t)p * stride + j0 + b * HOME__RADON_BLOCK +
                                     shift[p];
                const uint8x16_t v0 = vld1q_u8(src), v1 = vld1q_u8(src + 16),
                                 v2 = vld1q_u8(src + 32), v3 = vld1q_u8(src + 48);
                a0 = vaddw_u8(a0, vget_low_u8(v0));
                a1 = vaddw_u8(a1, vget_high_u8(v0));
                a2 = vaddw_u8(a2, vget_low_u8(v1));
                a3 = vaddw_u8(a3, vget_high_u8(v1));
                a4 = vaddw_u8(a4, vget_low_u8(v2));
                a5 = vaddw_u8(a5, vget_high_u8(v2));
                a6 = vaddw_u8(a6, vget_low_u8(v3));
                a7 = vaddw_u8(a7, vget_high_u8(v3));
            }
            add_lanes(acc32, a0);
            add_lanes(acc32 + 8, a1);
            add_lanes(acc32 + 16, a2);
            add_lanes(acc32 + 24, a3);
            add_lanes(acc32 + 32, a4);
            add_lanes(acc32 + 40, a5);
            add_lanes(acc32 + 48, a6);
            add_lanes(acc32 + 56, a7);
        }
    }
}

static void nearest2_l1_neon(const uint8_t *query, const uint8_t *cands, ptrdiff_t stride, int n,
                             int *best, int *d1, int *d2)
{
    const uint8x16_t q = vld1q_u8(query);
    int j, b = -1, m1 = 1 << 30, m2 = 1 << 30;
    for (j = 0; j < n; j++) {
        uint8x16_t diff = vabdq_u8(q, vld1q_u8(cands + (ptrdiff_t)j * stride));
        uint64x2_t s = vpaddlq_u32(vpaddlq_u16(vpaddlq_u8(diff)));
        int d = (int)(vgetq_lane_u64(s, 0) + vgetq_lane_u64(s, 1));
        if (d < m1) { m2 = m1; m1 = d; b = j; }
        else if (d < m2) m2 = d;
    }
    *best = b; *d1 = m1; *d2 = m2;
}

static void box_down_neon(const uint8_t *src, ptrdiff_t stride, int ds, uint8_t *out, int out_w)
{
    int x = 0, v;
    if (ds == 4) {
        for (; x + 8 <= out_w; x += 8) {
            const uint8_t *s0 = src + 4 * x;
            uint16x8_t lo = vpaddlq_u8(vld1q_u8(s0)), hi = vpaddlq_u8(vld1q_u8(s0 + 16));
            for (v = 1; v < 4; v++) {
                lo = vpadalq_u8(lo, vld1q_u8(s0 + (ptrdiff_t)v * stride));
                hi = vpadalq_u8(hi, vld1q_u8(s0 + (ptrdiff_t)v * stride + 16));
            }
            vst1_u8(out + x, vmovn_u16(vcombine_u16(vrshrn_n_u32(vpaddlq_u16(lo), 4),
                                                    vrshrn_n_u32(vpaddlq_u16(hi), 4))));
        }
    } else {
        for (; x + 8 <= out_w; x += 8) {
            const uint8_t *s0 = src + 2 * x;
            uint16x8_t sum = vpadalq_u8(vpaddlq_u8(vld1q_u8(s0)), vld1q_u8(s0 + stride));
            vst1_u8(out + x, vrshrn_n_u16(sum, 2));
        }
    }
    if (x < out_w) home__kernels_scalar.box_down(src + ds * x, stride, ds, out + x, out_w - x);
}

const home__kernels home__kernels_neon = {
    .name = "neon",
    .radon_blocks = radon_blocks_neon,
    .nearest2_l1 = nearest2_l1_neon,
    .smooth_row = smooth_row_fv,
    .smooth_cols = smooth_cols_fv,
    .box_down = box_down_neon,
    .extremum_candidates = extremum_candidates_fv,
    .line_ends = home__line_ends_scalar,
    .resample = home__resample_scalar,
    .line_fit = &home__line_fit_scalar,
};
#else
typedef int home__neon_unavailable; /* ISO C forbids an empty translation unit */
#endif
