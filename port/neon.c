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

const home__kernels home__kernels_neon = {"neon", radon_blocks_neon};
#else
typedef int home__neon_unavailable; /* ISO C forbids an empty translation unit */
#endif
