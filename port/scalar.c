/* Scalar reference kernels: the definition every SIMD backend must reproduce bit for bit. */
#include "kernels.h"
#include <string.h>

static void radon_blocks_scalar(const uint8_t *base, ptrdiff_t stride, const int16_t *shift,
                                int j0, int n_blocks, const int16_t *row_lo,
                                const int16_t *row_hi, int32_t *out)
{
    int b, p, l;
    for (b = 0; b < n_blocks; b++) {
        int32_t *acc = out + (ptrdiff_t)b * HOME__RADON_BLOCK;
        memset(acc, 0, HOME__RADON_BLOCK * sizeof *acc);
        for (p = row_lo[b]; p <= row_hi[b]; p++) {
            const uint8_t *src = base + (ptrdiff_t)p * stride + j0 + b * HOME__RADON_BLOCK + shift[p];
            for (l = 0; l < HOME__RADON_BLOCK; l++) acc[l] += src[l];
        }
    }
}

const home__kernels home__kernels_scalar = {"none", radon_blocks_scalar};
