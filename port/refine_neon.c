/* NEON kernels of the refinement (aarch64, and armv7 built with -mfpu=neon): bit-identical to
 * port/refine_scalar.c. Multiply and add stay separate (no vfma/vmla) to round like scalar C99;
 * armv7 NEON has no vector division, so the perspective divide is done per lane there. */
#include "refine_kernels.h"
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
#include <arm_neon.h>

static void blur3_neon(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                       ptrdiff_t dst_stride, int w, int h, int16_t *tmp)
{
    int x, y;
    for (y = 0; y < h; y++) {
        const uint8_t *a, *b, *c;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        home__blur3_rows(src, src_stride, y, h, &a, &b, &c);
        for (x = 0; x + 8 <= w; x += 8) {
            uint16x8_t vb = vmovl_u8(vld1_u8(b + x));
            uint16x8_t s = vaddq_u16(vaddl_u8(vld1_u8(a + x), vld1_u8(c + x)), vaddq_u16(vb, vb));
            vst1q_s16(tmp + x, vreinterpretq_s16_u16(s));
        }
        home__blur3_vertical(a, b, c, tmp, x, w);
        for (x = 1; x + 8 <= w - 1; x += 8) {
            uint16x8_t l = vreinterpretq_u16_s16(vld1q_s16(tmp + x - 1));
            uint16x8_t m = vreinterpretq_u16_s16(vld1q_s16(tmp + x));
            uint16x8_t r = vreinterpretq_u16_s16(vld1q_s16(tmp + x + 1));
            uint16x8_t s = vaddq_u16(vaddq_u16(l, r), vaddq_u16(m, m));
            vst1_u8(d + x, vmovn_u16(vshrq_n_u16(vaddq_u16(s, vdupq_n_u16(8)), 4)));
        }
        home__blur3_horizontal(tmp, d, x, w);
    }
}

static void downsample_neon(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                            ptrdiff_t dst_stride, int dst_w, int dst_h)
{
    int x, y;
    for (y = 0; y < dst_h; y++) {
        const uint8_t *a = src + 2 * (ptrdiff_t)y * src_stride, *b = a + src_stride;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        for (x = 0; x + 8 <= dst_w; x += 8) {
            uint16x8_t s = vaddq_u16(vpaddlq_u8(vld1q_u8(a + 2 * x)), vpaddlq_u8(vld1q_u8(b + 2 * x)));
            vst1_u8(d + x, vmovn_u16(vshrq_n_u16(vaddq_u16(s, vdupq_n_u16(2)), 2)));
        }
        for (; x < dst_w; x++)
            d[x] = (uint8_t)((a[2 * x] + a[2 * x + 1] + b[2 * x] + b[2 * x + 1] + 2) >> 2);
    }
}

static void select_keys_neon(const uint8_t *row, ptrdiff_t stride, int w, int b, int dy,
                             int16_t *keys, int accumulate)
{
    static const int16_t iota_v[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    const int16x8_t iota = vld1q_s16(iota_v), mask = vdupq_n_s16((int16_t)(b - 1));
    const int16x8_t base = vdupq_n_s16((int16_t)(dy * b));
    int x;
    if (!accumulate) keys[0] = keys[w - 1] = 0;
    for (x = 1; x + 8 <= w - 1; x += 8) {
        uint16x8_t s = vaddl_u8(vabd_u8(vld1_u8(row + x + 1), vld1_u8(row + x - 1)),
                                vabd_u8(vld1_u8(row + x + stride), vld1_u8(row + x - stride)));
        int16x8_t off = vaddq_s16(base, vandq_s16(vaddq_s16(vdupq_n_s16((int16_t)x), iota), mask));
        int16x8_t key = vorrq_s16(vshlq_n_s16(vreinterpretq_s16_u16(s), 4), off);
        if (accumulate) key = vmaxq_s16(key, vld1q_s16(keys + x));
        vst1q_s16(keys + x, key);
    }
    home__select_keys_px(row, stride, x, w, b, dy, keys, accumulate);
}

/* pairwise maxima (vpmax on 64-bit halves, in armv7 and aarch64 alike): one round for pairs,
 * two for groups of four */
static void block_max_neon(const int16_t *keys, int n, int b, uint16_t *cells)
{
    int i = 0;
    if (b == 2) {
        for (; i + 4 <= n; i += 4) {
            int16x8_t v = vld1q_s16(keys + 2 * i);
            vst1_u16(cells + i, vreinterpret_u16_s16(vpmax_s16(vget_low_s16(v), vget_high_s16(v))));
        }
    } else if (b == 4) {
        for (; i + 4 <= n; i += 4) {
            int16x8_t v = vld1q_s16(keys + 4 * i), w = vld1q_s16(keys + 4 * i + 8);
            int16x4_t pv = vpmax_s16(vget_low_s16(v), vget_high_s16(v));
            int16x4_t pw = vpmax_s16(vget_low_s16(w), vget_high_s16(w));
            vst1_u16(cells + i, vreinterpret_u16_s16(vpmax_s16(pv, pw)));
        }
    }
    home__block_max_px(keys, i, n, b, cells);
}

static float32x4_t load4_s16(const int16_t *p)
{
    return vcvtq_f32_s32(vmovl_s16(vld1_s16(p)));
}

static float32x4_t divide(float32x4_t a, float32x4_t b)
{
#if defined(__aarch64__)
    return vdivq_f32(a, b);
#else
    float x[4], y[4];
    int k;
    vst1q_f32(x, a);
    vst1q_f32(y, b);
    for (k = 0; k < 4; k++) x[k] /= y[k];
    return vld1q_f32(x);
#endif
}

static void warp_neon(const float *m, const int16_t *xs, const int16_t *ys, int n,
                      const uint8_t *img, ptrdiff_t stride, int w, int h, float *out)
{
    const float32x4_t xmax = vdupq_n_f32((float)(w - 1)), ymax = vdupq_n_f32((float)(h - 1));
    const float32x4_t zero = vdupq_n_f32(0.0f), minus1 = vdupq_n_f32(-1.0f);
    float32x4_t mm[9];
    int i, k;
    for (k = 0; k < 9; k++) mm[k] = vdupq_n_f32(m[k]);
    for (i = 0; i < n; i += 4) {
        float32x4_t x = load4_s16(xs + i), y = load4_s16(ys + i);
        float32x4_t d = vaddq_f32(vaddq_f32(vmulq_f32(mm[6], x), vmulq_f32(mm[7], y)), mm[8]);
        float32x4_t inv = divide(vdupq_n_f32(1.0f), d);
        float32x4_t px = vmulq_f32(vaddq_f32(vaddq_f32(vmulq_f32(mm[0], x), vmulq_f32(mm[1], y)), mm[2]), inv);
        float32x4_t py = vmulq_f32(vaddq_f32(vaddq_f32(vmulq_f32(mm[3], x), vmulq_f32(mm[4], y)), mm[5]), inv);
        uint32x4_t ok = vandq_u32(vandq_u32(vcgtq_f32(d, zero), vcgeq_f32(px, zero)),
                                  vandq_u32(vcgeq_f32(py, zero),
                                            vandq_u32(vcltq_f32(px, xmax), vcltq_f32(py, ymax))));
        int32x4_t ix, iy;
        float32x4_t fx, fy, p00, p01, p10, p11, top, bot, val;
        int32_t cx[4], cy[4];
        float f00[4], f01[4], f10[4], f11[4];
        px = vreinterpretq_f32_u32(vandq_u32(vreinterpretq_u32_f32(px), ok));
        py = vreinterpretq_f32_u32(vandq_u32(vreinterpretq_u32_f32(py), ok));
        ix = vcvtq_s32_f32(px);
        iy = vcvtq_s32_f32(py);
        fx = vsubq_f32(px, vcvtq_f32_s32(ix));
        fy = vsubq_f32(py, vcvtq_f32_s32(iy));
        vst1q_s32(cx, ix);
        vst1q_s32(cy, iy);
        for (k = 0; k < 4; k++) {
            const uint8_t *p = img + (ptrdiff_t)cy[k] * stride + cx[k];
            f00[k] = (float)p[0]; f01[k] = (float)p[1]; f10[k] = (float)p[stride]; f11[k] = (float)p[stride + 1];
        }
        p00 = vld1q_f32(f00); p01 = vld1q_f32(f01); p10 = vld1q_f32(f10); p11 = vld1q_f32(f11);
        top = vaddq_f32(p00, vmulq_f32(fx, vsubq_f32(p01, p00)));
        bot = vaddq_f32(p10, vmulq_f32(fx, vsubq_f32(p11, p10)));
        val = vaddq_f32(top, vmulq_f32(fy, vsubq_f32(bot, top)));
        vst1q_f32(out + i, vbslq_f32(ok, val, minus1));
    }
}

static void accumulate_neon(const int16_t *xs, const int16_t *ys, const int16_t *gxs,
                            const int16_t *gys, const float *r, const float *w, int n,
                            const float *aff, int hessian, float *acc)
{
    const float32x4_t a = vdupq_n_f32(aff[0]), bu = vdupq_n_f32(aff[1]), bv = vdupq_n_f32(aff[2]);
    float32x4_t sum[HOME__REFINE_ACC];
    int i, p, q, k;
    for (k = 0; k < HOME__REFINE_ACC; k++) sum[k] = vdupq_n_f32(0.0f);
    for (i = 0; i < n; i += 4) {
        float32x4_t u = vaddq_f32(vmulq_f32(a, load4_s16(xs + i)), bu);
        float32x4_t v = vaddq_f32(vmulq_f32(a, load4_s16(ys + i)), bv);
        float32x4_t gx = load4_s16(gxs + i), gy = load4_s16(gys + i);
        float32x4_t g = vaddq_f32(vmulq_f32(gx, u), vmulq_f32(gy, v));
        float32x4_t wi = vld1q_f32(w + i), wr = vmulq_f32(wi, vld1q_f32(r + i));
        float32x4_t sd[8];
        sd[0] = vmulq_f32(gx, u); sd[1] = vmulq_f32(gx, v); sd[2] = gx;
        sd[3] = vmulq_f32(gy, u); sd[4] = vmulq_f32(gy, v); sd[5] = gy;
        sd[6] = vnegq_f32(vmulq_f32(u, g)); sd[7] = vnegq_f32(vmulq_f32(v, g));
        for (p = 0; p < 8; p++) sum[36 + p] = vaddq_f32(sum[36 + p], vmulq_f32(sd[p], wr));
        if (!hessian) continue;
        for (p = 0, k = 0; p < 8; p++) {
            float32x4_t ws = vmulq_f32(wi, sd[p]);
            for (q = p; q < 8; q++, k++) sum[k] = vaddq_f32(sum[k], vmulq_f32(ws, sd[q]));
        }
    }
    for (k = hessian ? 0 : 36; k < HOME__REFINE_ACC; k++) vst1q_f32(acc + k * HOME__REFINE_LANES, sum[k]);
}

static int cauchy_sums_neon(const float *b, const float *keep, const int16_t *t, int n,
                            int n_valid, float alpha, float beta, float inv_c, float *wt,
                            float *part)
{
    static const int32_t iota_v[4] = {0, 1, 2, 3};
    const float32x4_t va = vdupq_n_f32(alpha), vbeta = vdupq_n_f32(beta), vc = vdupq_n_f32(inv_c);
    const float32x4_t one = vdupq_n_f32(1.0f), zero = vdupq_n_f32(0.0f);
    const int32x4_t limit = vdupq_n_s32(n_valid);
    int32x4_t idx = vld1q_s32(iota_v);
    uint32x4_t count = vdupq_n_u32(0);
    float32x4_t p0 = zero, p1 = zero, p2 = zero, p3 = zero, p4 = zero;
    uint32_t c[4];
    int i;
    for (i = 0; i < n; i += 4) {
        float32x4_t vb = vld1q_f32(b + i), ti = load4_s16(t + i);
        uint32x4_t ok = vandq_u32(vcltq_s32(idx, limit),
                                  vandq_u32(vcgeq_f32(vb, zero), vcgeq_f32(vld1q_f32(keep + i), zero)));
        float32x4_t bi = vreinterpretq_f32_u32(vandq_u32(vreinterpretq_u32_f32(vb), ok));
        float32x4_t q = vmulq_f32(vsubq_f32(vaddq_f32(vmulq_f32(va, bi), vbeta), ti), vc);
        float32x4_t w = divide(one, vaddq_f32(one, vmulq_f32(q, q)));
        float32x4_t wb;
        w = vreinterpretq_f32_u32(vandq_u32(vreinterpretq_u32_f32(w), ok));
        wb = vmulq_f32(w, bi);
        vst1q_f32(wt + i, w);
        p0 = vaddq_f32(p0, w);
        p1 = vaddq_f32(p1, wb);
        p2 = vaddq_f32(p2, vmulq_f32(w, ti));
        p3 = vaddq_f32(p3, vmulq_f32(wb, bi));
        p4 = vaddq_f32(p4, vmulq_f32(wb, ti));
        count = vsubq_u32(count, ok);
        idx = vaddq_s32(idx, vdupq_n_s32(4));
    }
    vst1q_f32(part, p0);
    vst1q_f32(part + 4, p1);
    vst1q_f32(part + 8, p2);
    vst1q_f32(part + 12, p3);
    vst1q_f32(part + 16, p4);
    vst1q_u32(c, count);
    return (int)(c[0] + c[1] + c[2] + c[3]);
}

static void residuals_neon(const float *b, const int16_t *t, const float *wt, int n, float alpha,
                           float beta, float *res)
{
    const float32x4_t va = vdupq_n_f32(alpha), vbeta = vdupq_n_f32(beta), zero = vdupq_n_f32(0.0f);
    int i;
    for (i = 0; i < n; i += 4) {
        float32x4_t r = vsubq_f32(vaddq_f32(vmulq_f32(va, vld1q_f32(b + i)), vbeta), load4_s16(t + i));
        uint32x4_t pos = vcgtq_f32(vld1q_f32(wt + i), zero);
        vst1q_f32(res + i, vreinterpretq_f32_u32(vandq_u32(vreinterpretq_u32_f32(r), pos)));
    }
}

const home__refine_kernels home__refine_kernels_neon = {
    .name = "neon",
    .blur3 = blur3_neon,
    .downsample = downsample_neon,
    .select_keys = select_keys_neon,
    .block_max = block_max_neon,
    .warp = warp_neon,
    .accumulate = accumulate_neon,
    .cauchy_sums = cauchy_sums_neon,
    .residuals = residuals_neon,
};
#else
typedef int home__refine_neon_unused; /* ISO C forbids an empty translation unit */
#endif
