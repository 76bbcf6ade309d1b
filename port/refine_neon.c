/* NEON kernels of the refinement (aarch64, and armv7 built with -mfpu=neon): bit-identical to
 * port/refine_scalar.c; the float kernels are port/refine_f32x4.h's (armv7 NEON has no vector
 * division: the divides are per lane there). */
#include "refine_kernels.h"
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
#include <arm_neon.h>
#define FV_NAME(name) name##_neon
#define FV_LINKAGE static
#include "refine_f32x4.h"

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
            uint16x8_t s = vaddq_u16(vpaddlq_u8(vld1q_u8(a + 2 * x)),
                                     vpaddlq_u8(vld1q_u8(b + 2 * x)));
            vst1_u8(d + x, vmovn_u16(vshrq_n_u16(vaddq_u16(s, vdupq_n_u16(2)), 2)));
        }
        home__downsample_px(a, b, d, x, dst_w);
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
