/* Kernels of the stabiliser's warp (src/warp.c): one table per SIMD backend, chosen like
 * home__kernels. Every backend gives the scalar reference's bytes exactly (integer arithmetic),
 * which tests/test_backends.c checks on odd widths, unaligned pointers and clamped rows. */
#ifndef HOME_STAB_KERNELS_H
#define HOME_STAB_KERNELS_H
#include "dispatch.h"
#include <stddef.h>
#include <stdint.h>

/* Fixed point of warp coordinates: Q16 pixels. The bilinear weight of a coordinate is its
 * offset f (Q16, 0..65536) from the pair's first pixel rounded to 1/128: 0..128, 7 bits that
 * keep every intermediate of the blend in int16. */
#define HOME__WARP_FRAC_BITS 16
#define HOME__WARP_WEIGHT(f) ((uint32_t)(((f) + 256) >> 9))

/* One output row of a bilinear warp. Output pixel i samples the source at
 * (x0 + i*dx, y0 + i*dy) (Q16 source pixels), clamped to [0, w-1] x [0, h-1] (edge replicate).
 * Source pixel (x, y) is the byte src[y*stride + x*step]; output pixel i goes to dst[i*dst_step].
 * Requires w, h >= 2 and every coordinate of the row within int32. With the weights
 * fx, fy = HOME__WARP_WEIGHT of the (clamped) coordinates' fractions, the result is
 * ((p00 (128-fx) + p01 fx) (128-fy) + (p10 (128-fx) + p11 fx) fy + 2^13) >> 14, and every
 * implementation must give it bit for bit. This is the reference (port/stab_scalar.c). */
void home__warp_row_c(const uint8_t *src, ptrdiff_t stride, int step, int w, int h, int32_t x0,
                      int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n);

/* The body of a warp row: home__warp_row_c's bytes for a planar row (step = dst_step = 1) whose
 * every sample lies inside (home__warp_row_inside), n a positive multiple of the table's block.
 * The caller (src/warp.c) sends other rows, and the tail, to the reference. */
typedef void (*home__warp_row_fn)(const uint8_t *src, ptrdiff_t stride, int w, int32_t x0,
                                  int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int n);

/* The SIMD warp bodies follow the source row pair their groups of pixels sit on: for a group
 * whose first pixel is at Q16 y and whose last `span` further, *lo becomes the first Q16 y of y's
 * source row and *yrel the last pixel's y less *lo (wrapping); returns the row's first byte. */
static inline const uint8_t *home__stab_track_row(const uint8_t *src, ptrdiff_t stride,
                                                  uint32_t y, uint32_t span, uint32_t *lo,
                                                  uint32_t *yrel)
{
    *lo = y & ~0xffffu;
    *yrel = y + span - *lo;
    return src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride;
}

typedef struct home__stab_kernels {
    const char *name;
    int block;                 /* output pixels per step of warp_row, a power of two */
    home__warp_row_fn warp_row;
} home__stab_kernels;

/* 1 when every sample of the row lies inside [0, w-1) x [0, h-1) (no clamping needed). */
int home__warp_row_inside(int w, int h, int32_t x0, int32_t y0, int32_t dx, int32_t dy, int n);

extern const home__stab_kernels home__stab_kernels_scalar;
#if defined(__SSE2__)
extern const home__stab_kernels home__stab_kernels_sse;
#endif
#if defined(__x86_64__) && !defined(HOME_NO_AVX2)
extern const home__stab_kernels home__stab_kernels_avx2;   /* port/stab_avx2.c, -mavx2 */
#endif
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
extern const home__stab_kernels home__stab_kernels_neon;
#endif

/* The table for a home_simd value (home__simd_resolve()), NULL when refused. */
const home__stab_kernels *home__stab_kernels_for(int simd);
#endif
