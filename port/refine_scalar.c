/* Scalar reference kernels of the refinement: the definition every SIMD backend reproduces. */
#include "refine_kernels.h"
#include <string.h>

static void blur3_scalar(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                         ptrdiff_t dst_stride, int w, int h, int16_t *tmp)
{
    int y;
    for (y = 0; y < h; y++) {
        const uint8_t *a, *b, *c;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        home__blur3_rows(src, src_stride, y, h, &a, &b, &c);
        home__blur3_vertical(a, b, c, tmp, 0, w);
        home__blur3_horizontal(tmp, d, 1, w);
    }
}

static void downsample_scalar(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                              ptrdiff_t dst_stride, int dst_w, int dst_h)
{
    int y;
    for (y = 0; y < dst_h; y++) {
        const uint8_t *a = src + 2 * (ptrdiff_t)y * src_stride, *b = a + src_stride;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        home__downsample_px(a, b, d, 0, dst_w);
    }
}

static void select_keys_scalar(const uint8_t *row, ptrdiff_t stride, int w, int b, int dy,
                               int16_t *keys, int accumulate)
{
    if (!accumulate) keys[0] = keys[w - 1] = 0;
    home__select_keys_px(row, stride, 1, w, b, dy, keys, accumulate);
}

static void warp_scalar(const float *m, const int16_t *xs, const int16_t *ys, int n,
                        const uint8_t *img, ptrdiff_t stride, int w, int h, float *out)
{
    const float xmax = (float)(w - 1), ymax = (float)(h - 1);
    int i;
    for (i = 0; i < n; i++) {
        float x = (float)xs[i], y = (float)ys[i];
        float d = m[6] * x + m[7] * y + m[8], inv = 1.0f / d;
        float px = (m[0] * x + m[1] * y + m[2]) * inv;
        float py = (m[3] * x + m[4] * y + m[5]) * inv;
        if (d > 0.0f && px >= 0.0f && py >= 0.0f && px < xmax && py < ymax) {
            int ix = (int)px, iy = (int)py;
            float fx = px - (float)ix, fy = py - (float)iy;
            const uint8_t *p = img + (ptrdiff_t)iy * stride + ix;
            float p00 = (float)p[0], p01 = (float)p[1], p10 = (float)p[stride],
                  p11 = (float)p[stride + 1];
            float top = p00 + fx * (p01 - p00);
            float bot = p10 + fx * (p11 - p10);
            out[i] = top + fy * (bot - top);
        } else {
            out[i] = -1.0f;
        }
    }
}

static void accumulate_scalar(const int16_t *xs, const int16_t *ys, const int16_t *gxs,
                              const int16_t *gys, const float *r, const float *w, int n,
                              const float *aff, int hessian, float *acc)
{
    int i, p, q, k;
    if (hessian) memset(acc, 0, HOME__REFINE_ACC * HOME__REFINE_LANES * sizeof *acc);
    else memset(acc + 36 * HOME__REFINE_LANES, 0, 8 * HOME__REFINE_LANES * sizeof *acc);
    for (i = 0; i < n; i++) {
        const int lane = i & (HOME__REFINE_LANES - 1);
        float u = aff[0] * (float)xs[i] + aff[1], v = aff[0] * (float)ys[i] + aff[2];
        float gx = (float)gxs[i], gy = (float)gys[i];
        float g = gx * u + gy * v;
        float sd[8], wr = w[i] * r[i];
        sd[0] = gx * u; sd[1] = gx * v; sd[2] = gx;
        sd[3] = gy * u; sd[4] = gy * v; sd[5] = gy;
        sd[6] = -(u * g); sd[7] = -(v * g);
        for (p = 0, k = 0; p < 8; p++) {
            float ws = w[i] * sd[p];
            if (hessian)
                for (q = p; q < 8; q++, k++) acc[k * HOME__REFINE_LANES + lane] += ws * sd[q];
            acc[(36 + p) * HOME__REFINE_LANES + lane] += sd[p] * wr;
        }
    }
}

static void block_max_scalar(const int16_t *keys, int n, int b, uint16_t *cells)
{
    home__block_max_px(keys, 0, n, b, cells);
}

static int cauchy_sums_scalar(const float *b, const float *keep, const int16_t *t, int n,
                              int n_valid, float alpha, float beta, float inv_c, float *wt,
                              float *part)
{
    int i, count = 0;
    memset(part, 0, 5 * HOME__REFINE_LANES * sizeof *part);
    for (i = 0; i < n; i++) {
        const int lane = i & (HOME__REFINE_LANES - 1);
        const int ok = i < n_valid && b[i] >= 0.0f && keep[i] >= 0.0f;
        const float bi = ok ? b[i] : 0.0f, ti = (float)t[i];
        const float q = (alpha * bi + beta - ti) * inv_c;
        const float w = ok ? 1.0f / (1.0f + q * q) : 0.0f;
        const float wb = w * bi;
        wt[i] = w;
        part[0 * HOME__REFINE_LANES + lane] += w;
        part[1 * HOME__REFINE_LANES + lane] += wb;
        part[2 * HOME__REFINE_LANES + lane] += w * ti;
        part[3 * HOME__REFINE_LANES + lane] += wb * bi;
        part[4 * HOME__REFINE_LANES + lane] += wb * ti;
        count += ok;
    }
    return count;
}

static void residuals_scalar(const float *b, const int16_t *t, const float *wt, int n,
                             float alpha, float beta, float *res)
{
    int i;
    for (i = 0; i < n; i++) res[i] = wt[i] > 0.0f ? alpha * b[i] + beta - (float)t[i] : 0.0f;
}

const home__refine_kernels home__refine_kernels_scalar = {
    .name = "none",
    .blur3 = blur3_scalar,
    .downsample = downsample_scalar,
    .select_keys = select_keys_scalar,
    .block_max = block_max_scalar,
    .warp = warp_scalar,
    .accumulate = accumulate_scalar,
    .cauchy_sums = cauchy_sums_scalar,
    .residuals = residuals_scalar,
};
