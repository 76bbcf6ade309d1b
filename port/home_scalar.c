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
            const uint8_t *src = base + (ptrdiff_t)p * stride + j0 + b * HOME__RADON_BLOCK +
                                 shift[p];
            for (l = 0; l < HOME__RADON_BLOCK; l++) acc[l] += src[l];
        }
    }
}

static void nearest2_l1_scalar(const uint8_t *query, const uint8_t *cands, ptrdiff_t stride,
                               int n, int *best, int *d1, int *d2)
{
    int j, k, b = -1, m1 = 1 << 30, m2 = 1 << 30;
    for (j = 0; j < n; j++) {
        const uint8_t *c = cands + (ptrdiff_t)j * stride;
        int d = 0;
        for (k = 0; k < 16; k++) d += query[k] > c[k] ? query[k] - c[k] : c[k] - query[k];
        if (d < m1) { m2 = m1; m1 = d; b = j; }
        else if (d < m2) m2 = d;
    }
    *best = b; *d1 = m1; *d2 = m2;
}

static int smooth_row_scalar(const float *in, float *out, int n, const float *taps, int radius)
{
    home__smooth_row_px(in, out, radius, n - radius, taps, radius);
    return n - radius;
}

static int smooth_cols_scalar(const float *const *rows, float *out, int n, const float *taps,
                              int radius)
{
    home__smooth_cols_px(rows, out, 0, n, taps, radius);
    return n;
}

static void box_down_scalar(const uint8_t *src, ptrdiff_t stride, int ds, uint8_t *out, int out_w)
{
    const int shift = ds == 2 ? 2 : 4;
    int x, u, v;
    for (x = 0; x < out_w; x++) {
        int sum = 1 << (shift - 1);
        for (v = 0; v < ds; v++)
            for (u = 0; u < ds; u++) sum += src[(ptrdiff_t)v * stride + ds * x + u];
        out[x] = (uint8_t)(sum >> shift);
    }
}

static int extremum_candidates_scalar(const float *up, const float *mid, const float *down, int n,
                                      int *idx, int *end)
{
    int i, count = 0;
    for (i = 1; i < n - 1; i++)
        if (home__is_extremum(up, mid, down, i)) idx[count++] = i;
    *end = i;
    return count;
}

void home__line_ends_scalar(const uint8_t *base, ptrdiff_t stride, const int16_t *shift, int j0,
                            const int16_t *entry, const int16_t *after, const int32_t *left,
                            const int32_t *right, int32_t right_total, int i0, int i1,
                            int32_t *sum, float *line)
{
    int i;
    for (i = i0; i < i1; i++)
        home__line_ends_px(base, stride, shift, j0, entry, after, left, right, right_total, i, sum,
                           line);
}

void home__resample_scalar(const float *line, const int16_t *k, const float *f, int n, float *out)
{
    int i;
    for (i = 0; i < n; i++) out[i] = home__resample_px(line, k[i], f[i]);
}

const home__kernels home__kernels_scalar = {
    .name = "none",
    .radon_blocks = radon_blocks_scalar,
    .nearest2_l1 = nearest2_l1_scalar,
    .smooth_row = smooth_row_scalar,
    .smooth_cols = smooth_cols_scalar,
    .box_down = box_down_scalar,
    .extremum_candidates = extremum_candidates_scalar,
    .line_ends = home__line_ends_scalar,
    .resample = home__resample_scalar,
    .line_fit = &home__line_fit_scalar,
};
