/* The refinement's float kernels (port/refine_kernels.h) written once on port/simd_f32x4.h for
 * SSE2 and NEON: point i is lane i % 4 and every lane runs the scalar reference's operations in
 * its order, so both give its bits. The includer defines F4_NAME(name), the functions' names,
 * and F4_LINKAGE (empty, or static). */
#ifndef HOME_REFINE_F32X4_H
#define HOME_REFINE_F32X4_H
#include "refine_kernels.h"
#include "simd_f32x4.h"

F4_LINKAGE void F4_NAME(warp)(const float *m, const int16_t *xs, const int16_t *ys, int n,
                              const uint8_t *img, ptrdiff_t stride, int w, int h, float *out)
{
    const home__f4 xmax = F4_SET1((float)(w - 1)), ymax = F4_SET1((float)(h - 1));
    const home__f4 zero = F4_ZERO(), minus1 = F4_SET1(-1.0f);
    home__f4 mm[9];
    int i, k;
    for (k = 0; k < 9; k++) mm[k] = F4_SET1(m[k]);
    for (i = 0; i < n; i += 4) {
        const home__f4 x = home__f4_load_s16(xs + i), y = home__f4_load_s16(ys + i);
        const home__f4 d = F4_ADD(F4_ADD(F4_MUL(mm[6], x), F4_MUL(mm[7], y)), mm[8]);
        const home__f4 inv = F4_DIV(F4_SET1(1.0f), d);
        home__f4 px = F4_MUL(F4_ADD(F4_ADD(F4_MUL(mm[0], x), F4_MUL(mm[1], y)), mm[2]), inv);
        home__f4 py = F4_MUL(F4_ADD(F4_ADD(F4_MUL(mm[3], x), F4_MUL(mm[4], y)), mm[5]), inv);
        const home__m4 ok =
            M4_AND(M4_AND(F4_GT(d, zero), F4_GE(px, zero)),
                   M4_AND(F4_GE(py, zero), M4_AND(F4_LT(px, xmax), F4_LT(py, ymax))));
        home__i4 ix, iy;
        home__f4 fx, fy, top, bot;
        int32_t cx[4], cy[4];
        float p00[4], p01[4], p10[4], p11[4];
        px = F4_KEEP(px, ok); /* invalid lanes sample (0, 0): in bounds, discarded */
        py = F4_KEEP(py, ok);
        ix = F4_TRUNC(px);
        iy = F4_TRUNC(py);
        fx = F4_SUB(px, I4_TO_F4(ix));
        fy = F4_SUB(py, I4_TO_F4(iy));
        I4_STORE(cx, ix);
        I4_STORE(cy, iy);
        for (k = 0; k < 4; k++) { /* the 2x2 supports, as floats (exact) */
            const uint8_t *p = img + (ptrdiff_t)cy[k] * stride + cx[k];
            p00[k] = (float)p[0];
            p01[k] = (float)p[1];
            p10[k] = (float)p[stride];
            p11[k] = (float)p[stride + 1];
        }
        top = F4_ADD(F4_LOAD(p00), F4_MUL(fx, F4_SUB(F4_LOAD(p01), F4_LOAD(p00))));
        bot = F4_ADD(F4_LOAD(p10), F4_MUL(fx, F4_SUB(F4_LOAD(p11), F4_LOAD(p10))));
        F4_STORE(out + i, F4_SELECT(ok, F4_ADD(top, F4_MUL(fy, F4_SUB(bot, top))), minus1));
    }
}

F4_LINKAGE void F4_NAME(accumulate)(const int16_t *xs, const int16_t *ys, const int16_t *gxs,
                                    const int16_t *gys, const float *r, const float *w, int n,
                                    const float *aff, int hessian, float *acc)
{
    const home__f4 a = F4_SET1(aff[0]), bu = F4_SET1(aff[1]), bv = F4_SET1(aff[2]);
    home__f4 sum[HOME__REFINE_ACC];
    int i, p, q, k;
    for (k = 0; k < HOME__REFINE_ACC; k++) sum[k] = F4_ZERO();
    for (i = 0; i < n; i += 4) {
        const home__f4 u = F4_ADD(F4_MUL(a, home__f4_load_s16(xs + i)), bu);
        const home__f4 v = F4_ADD(F4_MUL(a, home__f4_load_s16(ys + i)), bv);
        const home__f4 gx = home__f4_load_s16(gxs + i), gy = home__f4_load_s16(gys + i);
        const home__f4 g = F4_ADD(F4_MUL(gx, u), F4_MUL(gy, v));
        const home__f4 wi = F4_LOAD(w + i), wr = F4_MUL(wi, F4_LOAD(r + i));
        home__f4 sd[8];
        sd[0] = F4_MUL(gx, u); sd[1] = F4_MUL(gx, v); sd[2] = gx;
        sd[3] = F4_MUL(gy, u); sd[4] = F4_MUL(gy, v); sd[5] = gy;
        sd[6] = F4_NEG(F4_MUL(u, g)); sd[7] = F4_NEG(F4_MUL(v, g));
        for (p = 0; p < 8; p++) sum[36 + p] = F4_ADD(sum[36 + p], F4_MUL(sd[p], wr));
        if (!hessian) continue;
        for (p = 0, k = 0; p < 8; p++) {
            const home__f4 ws = F4_MUL(wi, sd[p]);
            for (q = p; q < 8; q++, k++) sum[k] = F4_ADD(sum[k], F4_MUL(ws, sd[q]));
        }
    }
    for (k = hessian ? 0 : 36; k < HOME__REFINE_ACC; k++)
        F4_STORE(acc + k * HOME__REFINE_LANES, sum[k]);
}

F4_LINKAGE int F4_NAME(cauchy_sums)(const float *b, const float *keep, const int16_t *t, int n,
                                    int n_valid, float alpha, float beta, float inv_c, float *wt,
                                    float *part)
{
    const home__f4 va = F4_SET1(alpha), vbeta = F4_SET1(beta), vc = F4_SET1(inv_c);
    const home__f4 one = F4_SET1(1.0f), zero = F4_ZERO();
    const home__i4 limit = I4_SET1(n_valid), step = I4_SET1(4);
    home__i4 idx = I4_IOTA(), count = I4_ZERO();
    home__f4 p0 = zero, p1 = zero, p2 = zero, p3 = zero, p4 = zero;
    int32_t c[4];
    int i;
    for (i = 0; i < n; i += 4) {
        const home__f4 vb = F4_LOAD(b + i), ti = home__f4_load_s16(t + i);
        const home__m4 ok = M4_AND(I4_LT(idx, limit),
                                   M4_AND(F4_GE(vb, zero), F4_GE(F4_LOAD(keep + i), zero)));
        const home__f4 bi = F4_KEEP(vb, ok);
        const home__f4 q = F4_MUL(F4_SUB(F4_ADD(F4_MUL(va, bi), vbeta), ti), vc);
        const home__f4 wq = F4_KEEP(F4_DIV(one, F4_ADD(one, F4_MUL(q, q))), ok);
        const home__f4 wb = F4_MUL(wq, bi);
        F4_STORE(wt + i, wq);
        p0 = F4_ADD(p0, wq);
        p1 = F4_ADD(p1, wb);
        p2 = F4_ADD(p2, F4_MUL(wq, ti));
        p3 = F4_ADD(p3, F4_MUL(wb, bi));
        p4 = F4_ADD(p4, F4_MUL(wb, ti));
        count = I4_SUB_M(count, ok);
        idx = I4_ADD(idx, step);
    }
    F4_STORE(part, p0);
    F4_STORE(part + 4, p1);
    F4_STORE(part + 8, p2);
    F4_STORE(part + 12, p3);
    F4_STORE(part + 16, p4);
    I4_STORE(c, count);
    return c[0] + c[1] + c[2] + c[3];
}

F4_LINKAGE void F4_NAME(residuals)(const float *b, const int16_t *t, const float *wt, int n,
                                   float alpha, float beta, float *res)
{
    const home__f4 va = F4_SET1(alpha), vbeta = F4_SET1(beta), zero = F4_ZERO();
    int i;
    for (i = 0; i < n; i += 4) {
        const home__f4 r = F4_SUB(F4_ADD(F4_MUL(va, F4_LOAD(b + i)), vbeta),
                                  home__f4_load_s16(t + i));
        F4_STORE(res + i, F4_KEEP(r, F4_GT(F4_LOAD(wt + i), zero)));
    }
}
#endif
