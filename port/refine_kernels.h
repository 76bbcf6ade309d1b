/* Kernels of the photometric refinement (src/refine.c): one table per SIMD backend, chosen per
 * context like home__kernels. Integer kernels are bit-identical to the scalar reference; the
 * float kernels are too, because every backend runs the same IEEE operations in the same order
 * on the same lane (point i is lane i % 4; no fused multiply-add, C99 contracts none), which
 * tests/test_backends.c checks on odd sizes and unaligned pointers. */
#ifndef HOME_REFINE_KERNELS_H
#define HOME_REFINE_KERNELS_H
#include "dispatch.h"
#include <stddef.h>
#include <stdint.h>

#define HOME__REFINE_LANES 4
#define HOME__REFINE_ACC 44   /* 36 upper-triangle entries of J^T W J, then 8 of J^T W r */

/* Bytes readable past the last pixel of an image the warp samples (the pyramid levels have them).
 */
#define HOME__REFINE_IMAGE_SLACK 4

typedef struct home__refine_kernels {
    const char *name;
    /* 3x3 binomial blur ([1 2 1] / 4 both ways, one rounding: (sum + 8) >> 4), edges
     * replicated; w >= 2; tmp holds w int16. */
    void (*blur3)(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst, ptrdiff_t dst_stride,
                  int w, int h, int16_t *tmp);
    /* 2x2 mean with rounding ((a + b + c + d + 2) >> 2) into dst_w x dst_h. */
    void (*downsample)(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                       ptrdiff_t dst_stride, int dst_w, int dst_h);
    /* Selection keys of one row (rows above and below must exist): for 1 <= x <= w - 2,
     * key = (|P[x+1] - P[x-1]| + |P[x+stride] - P[x-stride]|) << 4 | (dy * b + (x & (b - 1)))
     * stored into keys[x] (accumulate == 0) or maxed into it; keys[0] and keys[w-1] are set
     * to 0 when storing. b is 1, 2 or 4. */
    void (*select_keys)(const uint8_t *row, ptrdiff_t stride, int w, int b, int dy,
                        int16_t *keys, int accumulate);
    /* Largest key of each group of b (2 or 4): cells[i] = max(keys[b i .. b i + b - 1]) for
     * i < n; keys are non-negative. */
    void (*block_max)(const int16_t *keys, int n, int b, uint16_t *cells);
    /* Bilinear samples at m * (x, y, 1) after the perspective divide (one reciprocal 1 / d, then
     * two products), -1 where the point maps behind the camera or its 2x2 support leaves the
     * w x h image. n is a multiple of 4. img may be read up to HOME__REFINE_IMAGE_SLACK bytes
     * past its last pixel (whole-word gathers). */
    void (*warp)(const float *m, const int16_t *xs, const int16_t *ys, int n, const uint8_t *img,
                 ptrdiff_t stride, int w, int h, float *out);
    /* Weighted normal equations of one inverse-compositional step, per lane:
     * acc[k * 4 + lane], k < 36 the upper triangle of sum w sd sd^T, k = 36 + j sum w r sd_j,
     * sd = (gx u, gx v, gx, gy u, gy v, gy, -(u g), -(v g)), g = gx u + gy v,
     * u = aff[0] x + aff[1], v = aff[0] y + aff[2]; ws = w sd_p then += ws sd_q; wr = w r then
     * += sd_j wr. n is a multiple of 4. hessian == 0: only the J^T W r entries (k >= 36) are
     * written, the rest of acc is left as it is (the solver reuses a level's first Hessian). */
    void (*accumulate)(const int16_t *xs, const int16_t *ys, const int16_t *gxs,
                       const int16_t *gys, const float *r, const float *w, int n,
                       const float *aff, int hessian, float *acc);
    /* Cauchy weights of the gain/bias fit, per lane (point i is lane i % 4): point i counts when
     * i < n_valid, b[i] >= 0 and keep[i] >= 0; then with bi = b[i] (else bi = 0),
     * q = (alpha bi + beta - t[i]) inv_c, w = 1 / (1 + q q) (else w = 0), wt[i] = w and
     * part[k * 4 + lane] (zeroed first) sums w, w bi, w t, (w bi) bi, (w bi) t for k = 0..4.
     * Returns how many points count. n is a multiple of 4. */
    int (*cauchy_sums)(const float *b, const float *keep, const int16_t *t, int n, int n_valid,
                       float alpha, float beta, float inv_c, float *wt, float *part);
    /* res[i] = wt[i] > 0 ? alpha b[i] + beta - t[i] : 0. n is a multiple of 4. */
    void (*residuals)(const float *b, const int16_t *t, const float *wt, int n, float alpha,
                      float beta, float *res);
} home__refine_kernels;

/* The reference's per-pixel arithmetic of blur3 and select_keys, written once: the scalar
 * kernels are these over whole rows, the SIMD kernels over the pixels their vectors leave. */

/* the rows above and below row y, replicated at the image's top and bottom */
static inline void home__blur3_rows(const uint8_t *src, ptrdiff_t stride, int y, int h,
                                    const uint8_t **a, const uint8_t **b, const uint8_t **c)
{
    *a = src + (ptrdiff_t)(y > 0 ? y - 1 : 0) * stride;
    *b = src + (ptrdiff_t)y * stride;
    *c = src + (ptrdiff_t)(y < h - 1 ? y + 1 : h - 1) * stride;
}

/* vertical [1 2 1]: tmp[x] for x in [x0, w) */
static inline void home__blur3_vertical(const uint8_t *a, const uint8_t *b, const uint8_t *c,
                                        int16_t *tmp, int x0, int w)
{
    int x;
    for (x = x0; x < w; x++) tmp[x] = (int16_t)(a[x] + 2 * b[x] + c[x]);
}

/* horizontal [1 2 1] and the one rounding: d[x] for x in [x0, w - 1), and both edge pixels
 * (replicated neighbour) */
static inline void home__blur3_horizontal(const int16_t *tmp, uint8_t *d, int x0, int w)
{
    int x;
    for (x = x0; x < w - 1; x++) d[x] = (uint8_t)((tmp[x - 1] + 2 * tmp[x] + tmp[x + 1] + 8) >> 4);
    d[0] = (uint8_t)((3 * tmp[0] + tmp[1] + 8) >> 4);
    d[w - 1] = (uint8_t)((tmp[w - 2] + 3 * tmp[w - 1] + 8) >> 4);
}

/* 2x2 means of row pair a, b for outputs [x0, w) (see downsample) */
static inline void home__downsample_px(const uint8_t *a, const uint8_t *b, uint8_t *d, int x0,
                                       int w)
{
    int x;
    for (x = x0; x < w; x++)
        d[x] = (uint8_t)((a[2 * x] + a[2 * x + 1] + b[2 * x] + b[2 * x + 1] + 2) >> 2);
}

/* block maxima for blocks [i0, n) (see block_max) */
static inline void home__block_max_px(const int16_t *keys, int i0, int n, int b, uint16_t *cells)
{
    int i, k;
    for (i = i0; i < n; i++) {
        int best = keys[b * i];
        for (k = 1; k < b; k++) best = keys[b * i + k] > best ? keys[b * i + k] : best;
        cells[i] = (uint16_t)best;
    }
}

/* selection keys for x in [x0, w - 1) (see select_keys) */
static inline void home__select_keys_px(const uint8_t *row, ptrdiff_t stride, int x0, int w, int b,
                                        int dy, int16_t *keys, int accumulate)
{
    int x;
    for (x = x0; x < w - 1; x++) {
        int gx = row[x + 1] - row[x - 1], gy = row[x + stride] - row[x - stride];
        int key = ((gx < 0 ? -gx : gx) + (gy < 0 ? -gy : gy)) << 4 | (dy * b + (x & (b - 1)));
        if (!accumulate || key > keys[x]) keys[x] = (int16_t)key;
    }
}

extern const home__refine_kernels home__refine_kernels_scalar;
#if defined(__SSE2__)
extern const home__refine_kernels home__refine_kernels_sse;
/* shared by the AVX2 table (port/refine_avx2.c), which replaces the blur and the keys */
void home__refine_downsample_sse(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                                 ptrdiff_t dst_stride, int dst_w, int dst_h);
void home__refine_block_max_sse(const int16_t *keys, int n, int b, uint16_t *cells);
void home__refine_warp_sse(const float *m, const int16_t *xs, const int16_t *ys, int n,
                           const uint8_t *img, ptrdiff_t stride, int w, int h, float *out);
void home__refine_accumulate_sse(const int16_t *xs, const int16_t *ys, const int16_t *gxs,
                                 const int16_t *gys, const float *r, const float *w, int n,
                                 const float *aff, int hessian, float *acc);
int home__refine_cauchy_sums_sse(const float *b, const float *keep, const int16_t *t, int n,
                                 int n_valid, float alpha, float beta, float inv_c, float *wt,
                                 float *part);
void home__refine_residuals_sse(const float *b, const int16_t *t, const float *wt, int n,
                                float alpha, float beta, float *res);
#endif
#if defined(__x86_64__) && !defined(HOME_NO_AVX2)
extern const home__refine_kernels home__refine_kernels_avx2; /* port/refine_avx2.c, -mavx2 */
#endif
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
extern const home__refine_kernels home__refine_kernels_neon;
#endif

/* The table for a home_simd value (home__simd_resolve()), NULL when refused. */
const home__refine_kernels *home__refine_kernels_for(int simd);
#endif
