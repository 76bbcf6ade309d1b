/* libhome's hot kernels: one table per SIMD backend, chosen per context at home_init().
 * Every backend must produce bit-identical results to the scalar reference (integer kernels),
 * which tests/test_backends.c checks on odd sizes, unaligned pointers and extreme inputs. */
#ifndef HOME_KERNELS_H
#define HOME_KERNELS_H
#include "dispatch.h"
#include "line_fit_kernels.h"
#include <stddef.h>
#include <stdint.h>

/* Lanes per block of the shear-and-add Radon kernel. */
#define HOME__RADON_BLOCK 64
/* Largest Gaussian radius the smoothing kernels accept. */
#define HOME__MAX_TAPS_RADIUS 8
/* Rows summed in 16-bit lanes before widening: 128 * 255 = 32640 fits int16. */
#define HOME__RADON_ROWS_16BIT 128

typedef struct home__kernels {
    const char *name;
    /* Shear-and-add line sums for n_blocks blocks of HOME__RADON_BLOCK intercepts:
     *   out[b*64 + l] = sum over rows p in [row_lo[b], row_hi[b]] of
     *                   base[p*stride + j0 + b*64 + l + shift[p]]
     * (an empty range when row_lo[b] > row_hi[b]). base may be read 64 bytes beyond each row's
     * in-image columns on both sides; stride may be negative. */
    void (*radon_blocks)(const uint8_t *base, ptrdiff_t stride, const int16_t *shift, int j0,
                         int n_blocks, const int16_t *row_lo, const int16_t *row_hi,
                         int32_t *out);
    /* L1 distances of a 16-byte query to n descriptors `stride` bytes apart: the index of the
     * nearest (lowest index on ties), its distance d1 and the second smallest distance d2
     * (1 << 30 when absent). */
    void (*nearest2_l1)(const uint8_t *query, const uint8_t *cands, ptrdiff_t stride, int n,
                        int *best, int *d1, int *d2);
    /* out[i] = sum_k taps[k] * in[i - radius + k] (k = 0 .. 2 radius, in this order) for i in
     * [radius, e), the interior of a row up to e <= n - radius, which it returns; the caller
     * (src/smooth.c) does the borders and the rest (home__smooth_row_px). */
    int (*smooth_row)(const float *in, float *out, int n, const float *taps, int radius);
    /* out[i] = sum_k taps[k] * rows[k][i] (k = 0 .. 2 radius, in this order) for i in [0, e),
     * e <= n returned; the caller does the rest (home__smooth_cols_px). */
    int (*smooth_cols)(const float *const *rows, float *out, int n, const float *taps,
                       int radius);
    /* One row of a ds x ds box downscale (ds = 2 or 4), rounded:
     *   out[x] = (sum over v, u < ds of src[v*stride + ds*x + u] + ds*ds/2) / (ds*ds),
     * x in [0, out_w). */
    void (*box_down)(const uint8_t *src, ptrdiff_t stride, int ds, uint8_t *out, int out_w);
    /* Hough extremum candidates: the indices i in [1, e), increasing, where mid[i] > 0 and
     * above all eight neighbours in up, mid, down at i - 1 .. i + 1, or mid[i] < 0 and below
     * them all (home__is_extremum), into idx; returns how many and sets *end = e <= n - 1 (at
     * least 1); the caller (src/extrema.c) tests the rest. Comparisons only: exact everywhere. */
    int (*extremum_candidates)(const float *up, const float *mid, const float *down, int n,
                               int *idx, int *end);
    /* The line-end terms of a theta row's lines that cross the image's side, i in [i0, i1)
     * (src/hough.c's shear geometry: line j0 + i meets row p at column j0 + i + shift[p]):
     *   sum[i] += left[entry[i]] + right_total - right[after[i]]
     *   line[i] = entry[i] < after[i] ? P(after[i] - 1) - P(entry[i]) : 0,
     *   P(p) = base[p * stride + j0 + i + shift[p]].
     * shift may be read one int16 past row entries' range, base 3 bytes past a pixel. */
    void (*line_ends)(const uint8_t *base, ptrdiff_t stride, const int16_t *shift, int j0,
                      const int16_t *entry, const int16_t *after, const int32_t *left,
                      const int32_t *right, int32_t right_total, int i0, int i1, int32_t *sum,
                      float *line);
    /* Linear resampling: out[i] = line[k[i]] + f[i] * (line[k[i] + 1] - line[k[i]]), i < n. */
    void (*resample)(const float *line, const int16_t *k, const float *f, int n, float *out);
    /* the homography's line fit (port/line_fit.h compiled for this instruction set) */
    const home__line_fit *line_fit;
} home__kernels;

/* The references of line_ends and resample at one index (scalar kernels and SIMD tails). */
static inline void home__line_ends_px(const uint8_t *base, ptrdiff_t stride, const int16_t *shift,
                                      int j0, const int16_t *entry, const int16_t *after,
                                      const int32_t *left, const int32_t *right,
                                      int32_t right_total, int i, int32_t *sum, float *line)
{
    const int e = entry[i], a = after[i], j = j0 + i;
    sum[i] += left[e] + right_total - right[a];
    line[i] = e < a ? (float)(base[(ptrdiff_t)(a - 1) * stride + j + shift[a - 1]] -
                              base[(ptrdiff_t)e * stride + j + shift[e]]) /* exact: |.| <= 255 */
                    : 0.0f;
}

static inline float home__resample_px(const float *line, int k, float f)
{
    return line[k] + f * (line[k + 1] - line[k]);
}

extern const home__kernels home__kernels_scalar;
/* shared by the tables without gathers (SSE2, NEON) */
void home__line_ends_scalar(const uint8_t *base, ptrdiff_t stride, const int16_t *shift, int j0,
                            const int16_t *entry, const int16_t *after, const int32_t *left,
                            const int32_t *right, int32_t right_total, int i0, int i1,
                            int32_t *sum, float *line);
void home__resample_scalar(const float *line, const int16_t *k, const float *f, int n, float *out);
#if defined(__SSE2__)
#define HOME__HAVE_SSE 1
extern const home__kernels home__kernels_sse;
/* shared by the AVX2 table */
void home__nearest2_l1_sse(const uint8_t *query, const uint8_t *cands, ptrdiff_t stride, int n,
                           int *best, int *d1, int *d2);
void home__box_down_sse(const uint8_t *src, ptrdiff_t stride, int ds, uint8_t *out, int out_w);
#endif

/* The references of smooth_row and smooth_cols for outputs [i0, i1) (the scalar kernels, and
 * the callers for what the SIMD bodies leave). */
static inline void home__smooth_row_px(const float *in, float *out, int i0, int i1,
                                       const float *taps, int radius)
{
    int i, k;
    for (i = i0; i < i1; i++) {
        float acc = 0.0f;
        for (k = 0; k <= 2 * radius; k++) acc += taps[k] * in[i - radius + k];
        out[i] = acc;
    }
}

static inline void home__smooth_cols_px(const float *const *rows, float *out, int i0, int i1,
                                        const float *taps, int radius)
{
    int i, k;
    for (i = i0; i < i1; i++) {
        float acc = 0.0f;
        for (k = 0; k <= 2 * radius; k++) acc += taps[k] * rows[k][i];
        out[i] = acc;
    }
}

/* The reference test of extremum_candidates at one index (scalar kernel and the callers). */
static inline int home__is_extremum(const float *up, const float *mid, const float *down, int i)
{
    const float v = mid[i];
    if (v > 0.0f)
        return v > mid[i - 1] && v > mid[i + 1] && v > up[i - 1] && v > up[i] && v > up[i + 1] &&
               v > down[i - 1] && v > down[i] && v > down[i + 1];
    if (v < 0.0f)
        return v < mid[i - 1] && v < mid[i + 1] && v < up[i - 1] && v < up[i] && v < up[i + 1] &&
               v < down[i - 1] && v < down[i] && v < down[i + 1];
    return 0;
}
#if defined(__x86_64__) && !defined(HOME_NO_AVX2)
/* the port/..._avx2.c files are compiled with -mavx2 and used only when the CPU reports AVX2 */
#define HOME__HAVE_AVX2 1
extern const home__kernels home__kernels_avx2;
#endif
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
#define HOME__HAVE_NEON 1
extern const home__kernels home__kernels_neon;
#endif


/* The table for a home_simd value, or NULL when home__simd_resolve() refuses it. */
const home__kernels *home__kernels_for(int simd);
#endif
