/* SSE2 kernels (x86-64 baseline). */
#include "kernels.h"
#if defined(__SSE2__)
#include <emmintrin.h>

/* 64 lanes held as 8 x 8 uint16 in registers; widened into int32 every 128 rows. */
static void radon_blocks_sse(const uint8_t *base, ptrdiff_t stride, const int16_t *shift, int j0,
                             int n_blocks, const int16_t *row_lo, const int16_t *row_hi,
                             int32_t *out)
{
    const __m128i zero = _mm_setzero_si128();
    int b, k;
    for (b = 0; b < n_blocks; b++) {
        int32_t *acc32 = out + (ptrdiff_t)b * HOME__RADON_BLOCK;
        int p = row_lo[b];
        for (k = 0; k < HOME__RADON_BLOCK; k += 4) _mm_storeu_si128((__m128i *)(void *)(acc32 + k), zero);
        while (p <= row_hi[b]) {
            int end = p + HOME__RADON_ROWS_16BIT - 1 < row_hi[b] ? p + HOME__RADON_ROWS_16BIT - 1 : row_hi[b];
            __m128i a[8];
            for (k = 0; k < 8; k++) a[k] = zero;
            for (; p <= end; p++) {
                const uint8_t *src = base + (ptrdiff_t)p * stride + j0 + b * HOME__RADON_BLOCK + shift[p];
                for (k = 0; k < 4; k++) {
                    __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(src + 16 * k));
                    a[2 * k] = _mm_add_epi16(a[2 * k], _mm_unpacklo_epi8(v, zero));
                    a[2 * k + 1] = _mm_add_epi16(a[2 * k + 1], _mm_unpackhi_epi8(v, zero));
                }
            }
            for (k = 0; k < 8; k++) {
                __m128i lo = _mm_unpacklo_epi16(a[k], zero), hi = _mm_unpackhi_epi16(a[k], zero);
                __m128i *dst = (__m128i *)(void *)(acc32 + 8 * k);
                _mm_storeu_si128(dst, _mm_add_epi32(_mm_loadu_si128(dst), lo));
                _mm_storeu_si128(dst + 1, _mm_add_epi32(_mm_loadu_si128(dst + 1), hi));
            }
        }
    }
}

const home__kernels home__kernels_sse = {"sse", radon_blocks_sse};
#else
typedef int home__sse_unavailable; /* ISO C forbids an empty translation unit */
#endif
