/* SSE2 kernels of the refinement (x86-64 baseline): bit-identical to port/refine_scalar.c. */
#include "refine_kernels.h"
#if defined(__SSE2__)
#include <emmintrin.h>
#include <string.h>

static __m128i load8_u16(const uint8_t *p)
{
    return _mm_unpacklo_epi8(_mm_loadl_epi64((const __m128i *)(const void *)p), _mm_setzero_si128());
}

static void blur3_sse(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst, ptrdiff_t dst_stride,
                      int w, int h, int16_t *tmp)
{
    const __m128i eight = _mm_set1_epi16(8);
    int x, y;
    for (y = 0; y < h; y++) {
        const uint8_t *a, *b, *c;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        home__blur3_rows(src, src_stride, y, h, &a, &b, &c);
        for (x = 0; x + 8 <= w; x += 8) {
            __m128i vb = load8_u16(b + x);
            __m128i s = _mm_add_epi16(_mm_add_epi16(load8_u16(a + x), load8_u16(c + x)), _mm_add_epi16(vb, vb));
            _mm_storeu_si128((__m128i *)(void *)(tmp + x), s);
        }
        home__blur3_vertical(a, b, c, tmp, x, w);
        for (x = 1; x + 8 <= w - 1; x += 8) {
            __m128i l = _mm_loadu_si128((const __m128i *)(const void *)(tmp + x - 1));
            __m128i m = _mm_loadu_si128((const __m128i *)(const void *)(tmp + x));
            __m128i r = _mm_loadu_si128((const __m128i *)(const void *)(tmp + x + 1));
            __m128i s = _mm_add_epi16(_mm_add_epi16(l, r), _mm_add_epi16(m, m));
            s = _mm_srli_epi16(_mm_add_epi16(s, eight), 4);
            _mm_storel_epi64((__m128i *)(void *)(d + x), _mm_packus_epi16(s, s));
        }
        home__blur3_horizontal(tmp, d, x, w);
    }
}

void home__refine_downsample_sse(const uint8_t *src, ptrdiff_t src_stride, uint8_t *dst,
                                 ptrdiff_t dst_stride, int dst_w, int dst_h)
{
    const __m128i lo = _mm_set1_epi16(0xff), two = _mm_set1_epi16(2);
    int x, y;
    for (y = 0; y < dst_h; y++) {
        const uint8_t *a = src + 2 * (ptrdiff_t)y * src_stride, *b = a + src_stride;
        uint8_t *d = dst + (ptrdiff_t)y * dst_stride;
        for (x = 0; x + 8 <= dst_w; x += 8) {
            __m128i va = _mm_loadu_si128((const __m128i *)(const void *)(a + 2 * x));
            __m128i vb = _mm_loadu_si128((const __m128i *)(const void *)(b + 2 * x));
            __m128i s = _mm_add_epi16(_mm_add_epi16(_mm_and_si128(va, lo), _mm_srli_epi16(va, 8)),
                                      _mm_add_epi16(_mm_and_si128(vb, lo), _mm_srli_epi16(vb, 8)));
            s = _mm_srli_epi16(_mm_add_epi16(s, two), 2);
            _mm_storel_epi64((__m128i *)(void *)(d + x), _mm_packus_epi16(s, s));
        }
        for (; x < dst_w; x++)
            d[x] = (uint8_t)((a[2 * x] + a[2 * x + 1] + b[2 * x] + b[2 * x + 1] + 2) >> 2);
    }
}

static __m128i absdiff8(const uint8_t *p, const uint8_t *q)
{
    __m128i a = _mm_loadl_epi64((const __m128i *)(const void *)p);
    __m128i b = _mm_loadl_epi64((const __m128i *)(const void *)q);
    return _mm_unpacklo_epi8(_mm_or_si128(_mm_subs_epu8(a, b), _mm_subs_epu8(b, a)), _mm_setzero_si128());
}

static void select_keys_sse(const uint8_t *row, ptrdiff_t stride, int w, int b, int dy,
                            int16_t *keys, int accumulate)
{
    const __m128i iota = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7), mask = _mm_set1_epi16((short)(b - 1));
    const __m128i base = _mm_set1_epi16((short)(dy * b));
    int x;
    if (!accumulate) keys[0] = keys[w - 1] = 0;
    for (x = 1; x + 8 <= w - 1; x += 8) {
        __m128i s = _mm_add_epi16(absdiff8(row + x + 1, row + x - 1),
                                  absdiff8(row + x + stride, row + x - stride));
        __m128i off = _mm_add_epi16(base, _mm_and_si128(_mm_add_epi16(_mm_set1_epi16((short)x), iota), mask));
        __m128i key = _mm_or_si128(_mm_slli_epi16(s, 4), off);
        __m128i *dst = (__m128i *)(void *)(keys + x);
        if (accumulate) key = _mm_max_epi16(key, _mm_loadu_si128(dst));
        _mm_storeu_si128(dst, key);
    }
    home__select_keys_px(row, stride, x, w, b, dy, keys, accumulate);
}

static __m128 load4_s16(const int16_t *p)
{
    __m128i v = _mm_loadl_epi64((const __m128i *)(const void *)p);
    return _mm_cvtepi32_ps(_mm_srai_epi32(_mm_unpacklo_epi16(v, v), 16));
}

void home__refine_warp_sse(const float *m, const int16_t *xs, const int16_t *ys, int n,
                           const uint8_t *img, ptrdiff_t stride, int w, int h, float *out)
{
    const __m128 xmax = _mm_set1_ps((float)(w - 1)), ymax = _mm_set1_ps((float)(h - 1));
    const __m128 zero = _mm_setzero_ps(), minus1 = _mm_set1_ps(-1.0f);
    __m128 mm[9];
    int i, k;
    for (k = 0; k < 9; k++) mm[k] = _mm_set1_ps(m[k]);
    for (i = 0; i < n; i += 4) {
        __m128 x = load4_s16(xs + i), y = load4_s16(ys + i);
        __m128 d = _mm_add_ps(_mm_add_ps(_mm_mul_ps(mm[6], x), _mm_mul_ps(mm[7], y)), mm[8]);
        __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), d);
        __m128 px = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(mm[0], x), _mm_mul_ps(mm[1], y)), mm[2]), inv);
        __m128 py = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(mm[3], x), _mm_mul_ps(mm[4], y)), mm[5]), inv);
        __m128 ok = _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(d, zero), _mm_cmpge_ps(px, zero)),
                               _mm_and_ps(_mm_cmpge_ps(py, zero),
                                          _mm_and_ps(_mm_cmplt_ps(px, xmax), _mm_cmplt_ps(py, ymax))));
        __m128i ix, iy;
        __m128 fx, fy, p00, p01, p10, p11, top, bot, val;
        int32_t cx[4], cy[4], up[4], down[4];
        __m128i vu, vd;
        px = _mm_and_ps(px, ok);          /* invalid lanes sample (0, 0): in bounds, discarded */
        py = _mm_and_ps(py, ok);
        ix = _mm_cvttps_epi32(px);
        iy = _mm_cvttps_epi32(py);
        fx = _mm_sub_ps(px, _mm_cvtepi32_ps(ix));
        fy = _mm_sub_ps(py, _mm_cvtepi32_ps(iy));
        _mm_storeu_si128((__m128i *)(void *)cx, ix);
        _mm_storeu_si128((__m128i *)(void *)cy, iy);
        /* gather each 2x2 support as two pixel pairs, convert all four corners at once */
        for (k = 0; k < 4; k++) {
            const uint8_t *p = img + (ptrdiff_t)cy[k] * stride + cx[k];
            up[k] = p[0] | p[1] << 8;
            down[k] = p[stride] | p[stride + 1] << 8;
        }
        vu = _mm_loadu_si128((const __m128i *)(const void *)up);
        vd = _mm_loadu_si128((const __m128i *)(const void *)down);
        p00 = _mm_cvtepi32_ps(_mm_and_si128(vu, _mm_set1_epi32(0xff)));
        p01 = _mm_cvtepi32_ps(_mm_srli_epi32(vu, 8));
        p10 = _mm_cvtepi32_ps(_mm_and_si128(vd, _mm_set1_epi32(0xff)));
        p11 = _mm_cvtepi32_ps(_mm_srli_epi32(vd, 8));
        top = _mm_add_ps(p00, _mm_mul_ps(fx, _mm_sub_ps(p01, p00)));
        bot = _mm_add_ps(p10, _mm_mul_ps(fx, _mm_sub_ps(p11, p10)));
        val = _mm_add_ps(top, _mm_mul_ps(fy, _mm_sub_ps(bot, top)));
        _mm_storeu_ps(out + i, _mm_or_ps(_mm_and_ps(ok, val), _mm_andnot_ps(ok, minus1)));
    }
}

/* The maximum of each 2- or 4-lane group lands in the group's first lane (shifts within 32- or
 * 64-bit lanes), then packs gather those lanes (values < 2^15: signed packing is exact). */
void home__refine_block_max_sse(const int16_t *keys, int n, int b, uint16_t *cells)
{
    const __m128i low16 = _mm_set1_epi32(0xffff);
    int i = 0;
    if (b == 2) {
        for (; i + 8 <= n; i += 8) {
            __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(keys + 2 * i));
            __m128i w = _mm_loadu_si128((const __m128i *)(const void *)(keys + 2 * i + 8));
            v = _mm_and_si128(_mm_max_epi16(v, _mm_srli_epi32(v, 16)), low16);
            w = _mm_and_si128(_mm_max_epi16(w, _mm_srli_epi32(w, 16)), low16);
            _mm_storeu_si128((__m128i *)(void *)(cells + i), _mm_packs_epi32(v, w));
        }
    } else if (b == 4) {
        const __m128i low64 = _mm_set_epi32(0, 0xffff, 0, 0xffff);
        for (; i + 8 <= n; i += 8) {
            __m128i q[4];
            int j;
            for (j = 0; j < 4; j++) {
                __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(keys + 4 * i + 8 * j));
                v = _mm_max_epi16(v, _mm_srli_epi64(v, 16));
                q[j] = _mm_and_si128(_mm_max_epi16(v, _mm_srli_epi64(v, 32)), low64);
            }
            /* 32-bit lanes 0 and 2 of each hold two blocks' maxima: pack twice */
            _mm_storeu_si128((__m128i *)(void *)(cells + i),
                             _mm_packs_epi32(_mm_packs_epi32(q[0], q[1]), _mm_packs_epi32(q[2], q[3])));
        }
    }
    home__block_max_px(keys, i, n, b, cells);
}

void home__refine_accumulate_sse(const int16_t *xs, const int16_t *ys, const int16_t *gxs,
                                 const int16_t *gys, const float *r, const float *w, int n,
                                 const float *aff, int hessian, float *acc)
{
    const __m128 a = _mm_set1_ps(aff[0]), bu = _mm_set1_ps(aff[1]), bv = _mm_set1_ps(aff[2]);
    const __m128 sign = _mm_set1_ps(-0.0f);
    __m128 sum[HOME__REFINE_ACC];
    int i, p, q, k;
    for (k = 0; k < HOME__REFINE_ACC; k++) sum[k] = _mm_setzero_ps();
    for (i = 0; i < n; i += 4) {
        __m128 u = _mm_add_ps(_mm_mul_ps(a, load4_s16(xs + i)), bu);
        __m128 v = _mm_add_ps(_mm_mul_ps(a, load4_s16(ys + i)), bv);
        __m128 gx = load4_s16(gxs + i), gy = load4_s16(gys + i);
        __m128 g = _mm_add_ps(_mm_mul_ps(gx, u), _mm_mul_ps(gy, v));
        __m128 wi = _mm_loadu_ps(w + i), wr = _mm_mul_ps(wi, _mm_loadu_ps(r + i));
        __m128 sd[8];
        sd[0] = _mm_mul_ps(gx, u); sd[1] = _mm_mul_ps(gx, v); sd[2] = gx;
        sd[3] = _mm_mul_ps(gy, u); sd[4] = _mm_mul_ps(gy, v); sd[5] = gy;
        sd[6] = _mm_xor_ps(_mm_mul_ps(u, g), sign); sd[7] = _mm_xor_ps(_mm_mul_ps(v, g), sign);
        for (p = 0; p < 8; p++) sum[36 + p] = _mm_add_ps(sum[36 + p], _mm_mul_ps(sd[p], wr));
        if (!hessian) continue;
        for (p = 0, k = 0; p < 8; p++) {
            __m128 ws = _mm_mul_ps(wi, sd[p]);
            for (q = p; q < 8; q++, k++) sum[k] = _mm_add_ps(sum[k], _mm_mul_ps(ws, sd[q]));
        }
    }
    for (k = hessian ? 0 : 36; k < HOME__REFINE_ACC; k++) _mm_storeu_ps(acc + k * HOME__REFINE_LANES, sum[k]);
}

int home__refine_cauchy_sums_sse(const float *b, const float *keep, const int16_t *t, int n,
                                 int n_valid, float alpha, float beta, float inv_c, float *wt,
                                 float *part)
{
    const __m128 va = _mm_set1_ps(alpha), vbeta = _mm_set1_ps(beta), vc = _mm_set1_ps(inv_c);
    const __m128 one = _mm_set1_ps(1.0f), zero = _mm_setzero_ps();
    const __m128i limit = _mm_set1_epi32(n_valid), step = _mm_set1_epi32(4);
    __m128i idx = _mm_setr_epi32(0, 1, 2, 3), count = _mm_setzero_si128();
    __m128 p0 = zero, p1 = zero, p2 = zero, p3 = zero, p4 = zero;
    int i, c[4];
    for (i = 0; i < n; i += 4) {
        __m128 vb = _mm_loadu_ps(b + i), ti = load4_s16(t + i);
        __m128 ok = _mm_and_ps(_mm_castsi128_ps(_mm_cmplt_epi32(idx, limit)),
                               _mm_and_ps(_mm_cmpge_ps(vb, zero), _mm_cmpge_ps(_mm_loadu_ps(keep + i), zero)));
        __m128 bi = _mm_and_ps(vb, ok);
        __m128 q = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(_mm_mul_ps(va, bi), vbeta), ti), vc);
        __m128 w = _mm_and_ps(_mm_div_ps(one, _mm_add_ps(one, _mm_mul_ps(q, q))), ok);
        __m128 wb = _mm_mul_ps(w, bi);
        _mm_storeu_ps(wt + i, w);
        p0 = _mm_add_ps(p0, w);
        p1 = _mm_add_ps(p1, wb);
        p2 = _mm_add_ps(p2, _mm_mul_ps(w, ti));
        p3 = _mm_add_ps(p3, _mm_mul_ps(wb, bi));
        p4 = _mm_add_ps(p4, _mm_mul_ps(wb, ti));
        count = _mm_sub_epi32(count, _mm_castps_si128(ok));
        idx = _mm_add_epi32(idx, step);
    }
    _mm_storeu_ps(part, p0);
    _mm_storeu_ps(part + 4, p1);
    _mm_storeu_ps(part + 8, p2);
    _mm_storeu_ps(part + 12, p3);
    _mm_storeu_ps(part + 16, p4);
    _mm_storeu_si128((__m128i *)(void *)c, count);
    return c[0] + c[1] + c[2] + c[3];
}

void home__refine_residuals_sse(const float *b, const int16_t *t, const float *wt, int n,
                                float alpha, float beta, float *res)
{
    const __m128 va = _mm_set1_ps(alpha), vbeta = _mm_set1_ps(beta), zero = _mm_setzero_ps();
    int i;
    for (i = 0; i < n; i += 4) {
        __m128 r = _mm_sub_ps(_mm_add_ps(_mm_mul_ps(va, _mm_loadu_ps(b + i)), vbeta), load4_s16(t + i));
        _mm_storeu_ps(res + i, _mm_and_ps(r, _mm_cmpgt_ps(_mm_loadu_ps(wt + i), zero)));
    }
}

const home__refine_kernels home__refine_kernels_sse = {
    .name = "sse",
    .blur3 = blur3_sse,
    .downsample = home__refine_downsample_sse,
    .select_keys = select_keys_sse,
    .block_max = home__refine_block_max_sse,
    .warp = home__refine_warp_sse,
    .accumulate = home__refine_accumulate_sse,
    .cauchy_sums = home__refine_cauchy_sums_sse,
    .residuals = home__refine_residuals_sse,
};
#else
typedef int home__refine_sse_unused; /* ISO C forbids an empty translation unit */
#endif
