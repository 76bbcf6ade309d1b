/* NEON kernels (aarch64, and armv7 built with -mfpu=neon). */
#include "kernels.h"
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
#include <arm_neon.h>

/* 64 lanes held as 8 x 8 uint16 in registers (vaddw_u8 widens while adding); widened into
 * int32 every 128 rows. */
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
            int end = p + HOME__RADON_ROWS_16BIT - 1 < row_hi[b] ? p + HOME__RADON_ROWS_16BIT - 1 : row_hi[b];
            uint16x8_t a[8];
            for (k = 0; k < 8; k++) a[k] = vdupq_n_u16(0);
            for (; p <= end; p++) {
                const uint8_t *src = base + (ptrdiff_t)p * stride + j0 + b * HOME__RADON_BLOCK + shift[p];
                for (k = 0; k < 4; k++) {
                    uint8x16_t v = vld1q_u8(src + 16 * k);
                    a[2 * k] = vaddw_u8(a[2 * k], vget_low_u8(v));
                    a[2 * k + 1] = vaddw_u8(a[2 * k + 1], vget_high_u8(v));
                }
            }
            for (k = 0; k < 8; k++) {
                int32_t *dst = acc32 + 8 * k;
                vst1q_s32(dst, vaddq_s32(vld1q_s32(dst), vreinterpretq_s32_u32(vmovl_u16(vget_low_u16(a[k])))));
                vst1q_s32(dst + 4, vaddq_s32(vld1q_s32(dst + 4), vreinterpretq_s32_u32(vmovl_u16(vget_high_u16(a[k])))));
            }
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

/* vmulq then vaddq (never a fused multiply-add): the same rounding as the scalar reference. */
/* The taps in the reference's order, one product and one sum each (no fused multiply-add); the
 * default radius 4 (sigma 1.3) unrolled with its nine taps in registers, other radii by the
 * generic loop. */
#define SMOOTH_TAP(k, src) acc = vaddq_f32(acc, vmulq_f32(t##k, vld1q_f32(src)))
#define SMOOTH_TAPS_4 \
    const float32x4_t t0 = vdupq_n_f32(taps[0]), t1 = vdupq_n_f32(taps[1]), t2 = vdupq_n_f32(taps[2]), \
                      t3 = vdupq_n_f32(taps[3]), t4 = vdupq_n_f32(taps[4]), t5 = vdupq_n_f32(taps[5]), \
                      t6 = vdupq_n_f32(taps[6]), t7 = vdupq_n_f32(taps[7]), t8 = vdupq_n_f32(taps[8])

static void smooth_row_neon(const float *in, float *out, int n, const float *taps, int radius)
{
    int i = radius, k;
    if (radius == 4) {
        SMOOTH_TAPS_4;
        for (; i + 4 <= n - radius; i += 4) {
            const float *p = in + i - 4;
            float32x4_t acc = vdupq_n_f32(0.0f);
            SMOOTH_TAP(0, p); SMOOTH_TAP(1, p + 1); SMOOTH_TAP(2, p + 2); SMOOTH_TAP(3, p + 3);
            SMOOTH_TAP(4, p + 4); SMOOTH_TAP(5, p + 5); SMOOTH_TAP(6, p + 6); SMOOTH_TAP(7, p + 7);
            SMOOTH_TAP(8, p + 8);
            vst1q_f32(out + i, acc);
        }
    }
    for (; i + 4 <= n - radius; i += 4) {
        float32x4_t acc = vdupq_n_f32(0.0f);
        for (k = 0; k <= 2 * radius; k++)
            acc = vaddq_f32(acc, vmulq_f32(vdupq_n_f32(taps[k]), vld1q_f32(in + i - radius + k)));
        vst1q_f32(out + i, acc);
    }
    /* the last < 4 outputs by the reference, on a window that starts at output i */
    home__kernels_scalar.smooth_row(in + i - radius, out + i - radius, n - i + radius, taps, radius);
}

static void smooth_cols_neon(const float *const *rows, float *out, int n, const float *taps,
                             int radius)
{
    int i = 0, k;
    if (radius == 4) {
        SMOOTH_TAPS_4;
        const float *r0 = rows[0], *r1 = rows[1], *r2 = rows[2], *r3 = rows[3], *r4 = rows[4],
                    *r5 = rows[5], *r6 = rows[6], *r7 = rows[7], *r8 = rows[8];
        for (; i + 4 <= n; i += 4) {
            float32x4_t acc = vdupq_n_f32(0.0f);
            SMOOTH_TAP(0, r0 + i); SMOOTH_TAP(1, r1 + i); SMOOTH_TAP(2, r2 + i); SMOOTH_TAP(3, r3 + i);
            SMOOTH_TAP(4, r4 + i); SMOOTH_TAP(5, r5 + i); SMOOTH_TAP(6, r6 + i); SMOOTH_TAP(7, r7 + i);
            SMOOTH_TAP(8, r8 + i);
            vst1q_f32(out + i, acc);
        }
    }
    for (; i + 4 <= n; i += 4) {
        float32x4_t acc = vdupq_n_f32(0.0f);
        for (k = 0; k <= 2 * radius; k++)
            acc = vaddq_f32(acc, vmulq_f32(vdupq_n_f32(taps[k]), vld1q_f32(rows[k] + i)));
        vst1q_f32(out + i, acc);
    }
    if (i < n) {
        const float *tail[2 * HOME__MAX_TAPS_RADIUS + 1];
        for (k = 0; k <= 2 * radius; k++) tail[k] = rows[k] + i;
        home__kernels_scalar.smooth_cols(tail, out + i, n - i, taps, radius);
    }
}
#undef SMOOTH_TAP
#undef SMOOTH_TAPS_4

/* 8 outputs per step: pairwise widening adds along the row, accumulated over the rows, then a
 * rounding narrowing shift ((sum + half) >> shift); the tail by the reference. */
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

/* Four bins per step as in the SSE2 kernel; "any lane set" by a pairwise max (armv7 has no
 * across-vector reduction). */
static int extremum_candidates_neon(const float *up, const float *mid, const float *down, int n,
                                    int *idx)
{
    const float32x4_t zero = vdupq_n_f32(0.0f);
    int i, count = 0, lane;
    for (i = 1; i + 4 <= n - 1; i += 4) {
        float32x4_t v = vld1q_f32(mid + i);
        float32x4_t a = vld1q_f32(up + i - 1), b = vld1q_f32(up + i), c = vld1q_f32(up + i + 1);
        float32x4_t d = vld1q_f32(mid + i - 1), e = vld1q_f32(mid + i + 1);
        float32x4_t f = vld1q_f32(down + i - 1), g = vld1q_f32(down + i), h = vld1q_f32(down + i + 1);
        float32x4_t hi = vmaxq_f32(vmaxq_f32(vmaxq_f32(a, b), vmaxq_f32(c, d)),
                                   vmaxq_f32(vmaxq_f32(e, f), vmaxq_f32(g, h)));
        float32x4_t lo = vminq_f32(vminq_f32(vminq_f32(a, b), vminq_f32(c, d)),
                                   vminq_f32(vminq_f32(e, f), vminq_f32(g, h)));
        uint32x4_t m = vorrq_u32(vandq_u32(vcgtq_f32(v, zero), vcgtq_f32(v, hi)),
                                 vandq_u32(vcltq_f32(v, zero), vcltq_f32(v, lo)));
        uint32x2_t any = vorr_u32(vget_low_u32(m), vget_high_u32(m));
        uint32_t bits[4];
        if (!vget_lane_u32(vpmax_u32(any, any), 0)) continue;
        vst1q_u32(bits, m);
        for (lane = 0; lane < 4; lane++)
            if (bits[lane]) idx[count++] = i + lane;
    }
    for (; i < n - 1; i++)
        if (home__is_extremum(up, mid, down, i)) idx[count++] = i;
    return count;
}

const home__kernels home__kernels_neon = {
    .name = "neon",
    .radon_blocks = radon_blocks_neon,
    .nearest2_l1 = nearest2_l1_neon,
    .smooth_row = smooth_row_neon,
    .smooth_cols = smooth_cols_neon,
    .box_down = box_down_neon,
    .extremum_candidates = extremum_candidates_neon,
    .line_ends = home__line_ends_scalar,
    .resample = home__resample_scalar,
    .line_fit = &home__line_fit_scalar,
};
#else
typedef int home__neon_unavailable; /* ISO C forbids an empty translation unit */
#endif
