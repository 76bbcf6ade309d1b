/* The refinement's float kernels (port/refine_kernels.h) written once on port/simd_f32x4.h for
 * SSE2 and NEON: point i is lane i % 4 and every lane runs the scalar reference's operations in
 * its order, so both give its bits. The includer defines FV_NAME(name), the functions' names,
 * and FV_LINKAGE (empty, or static). */
#ifndef HOME_REFINE_F32X4_H
#define HOME_REFINE_F32X4_H
#include "refine_kernels.h"
#include "simd_f32x4.h" /* four lanes: point i is lane i % 4 */

FV_LINKAGE void FV_NAME(warp)(const float *m, const int16_t *xs, const int16_t *ys, int n,
                              const uint8_t *img, ptrdiff_t stride, int w, int h, float *out)
{
    const home__fv xmax = FV_SET1((float)(w - 1)), ymax = FV_SET1((float)(h - 1));
    const home__fv zero = FV_ZERO(), minus1 = FV_SET1(-1.0f);
    home__fv mm[9];
    int i, k;
    for (k = 0; k < 9; k++) mm[k] = FV_SET1(m[k]);
    for (i = 0; i < n; i += 4) {
        const home__fv x = home__fv_load_s16(xs + i), y = home__fv_load_s16(ys + i);
        const home__fv d = FV_ADD(FV_ADD(FV_MUL(mm[6], x), FV_MUL(mm[7], y)), mm[8]);
        const home__fv inv = FV_DIV(FV_SET1(1.0f), d);
        home__fv px = FV_MUL(FV_ADD(FV_ADD(FV_MUL(mm[0], x), FV_MUL(mm[1], y)), mm[2]), inv);
        home__fv py = FV_MUL(FV_ADD(FV_ADD(FV_MUL(mm[3], x), FV_MUL(mm[4], y)), mm[5]), inv);
        const home__mv ok =
            MV_AND(MV_AND(FV_GT(d, zero), FV_GE(px, zero)),
                   MV_AND(FV_GE(py, zero), MV_AND(FV_LT(px, xmax), FV_LT(py, ymax))));
        home__iv ix, iy;
        home__fv fx, fy, top, bot;
        int32_t cx[4], cy[4];
        float p00[4], p01[4], p10[4], p11[4];
        px = FV_KEEP(px, ok); /* invalid lanes sample (0, 0): in bounds, discarded */
        py = FV_KEEP(py, ok);
        ix = FV_TRUNC(px);
        iy = FV_TRUNC(py);
        fx = FV_SUB(px, IV_TO_F4(ix));
        fy = FV_SUB(py, IV_TO_F4(iy));
        IV_STORE(cx, ix);
        IV_STORE(cy, iy);
        for (k = 0; k < 4; k++) { /* the 2x2 supports, as floats (exact) */
            const uint8_t *p = img + (ptrdiff_t)cy[k] * stride + cx[k];
            p00[k] = (float)p[0];
            p01[k] = (float)p[1];
            p10[k] = (float)p[stride];
            p11[k] = (float)p[stride + 1];
        }
        top = FV_ADD(FV_LOAD(p00), FV_MUL(fx, FV_SUB(FV_LOAD(p01), FV_LOAD(p00))));
        bot = FV_ADD(FV_LOAD(p10), FV_MUL(fx, FV_SUB(FV_LOAD(p11), FV_LOAD(p10))));
        FV_STORE(out + i, FV_SELECT(ok, FV_ADD(top, FV_MUL(fy, FV_SUB(bot, top))), minus1));
    }
}

FV_LINKAGE void FV_NAME(accumulate)(const int16_t *xs, const int16_t *ys, const int16_t *gxs,
                                    const int16_t *gys, const float *r, const float *w, int n,
                                    const float *aff, int hessian, float *acc)
{
    const home__fv a = FV_SET1(aff[0]), bu = FV_SET1(aff[1]), bv = FV_SET1(aff[2]);
    home__fv sum[HOME__REFINE_ACC];
    int i, p, q, k;
    for (k = 0; k < HOME__REFINE_ACC; k++) sum[k] = FV_ZERO();
    for (i = 0; i < n; i += 4) {
        const home__fv u = FV_ADD(FV_MUL(a, home__fv_load_s16(xs + i)), bu);
        const home__fv v = FV_ADD(FV_MUL(a, home__fv_load_s16(ys + i)), bv);
        const home__fv gx = home__fv_load_s16(gxs + i), gy = home__fv_load_s16(gys + i);
        const home__fv g = FV_ADD(FV_MUL(gx, u), FV_MUL(gy, v));
        const home__fv wi = FV_LOAD(w + i), wr = FV_MUL(wi, FV_LOAD(r + i));
        home__fv sd[8];
        sd[0] = FV_MUL(gx, u); sd[1] = FV_MUL(gx, v); sd[2] = gx;
        sd[3] = FV_MUL(gy, u); sd[4] = FV_MUL(gy, v); sd[5] = gy;
        sd[6] = FV_NEG(FV_MUL(u, g)); sd[7] = FV_NEG(FV_MUL(v, g));
        for (p = 0; p < 8; p++) sum[36 + p] = FV_ADD(sum[36 + p], FV_MUL(sd[p], wr));
        if (!hessian) continue;
        for (p = 0, k = 0; p < 8; p++) {
            const home__fv ws = FV_MUL(wi, sd[p]);
            for (q = p; q < 8; q++, k++) sum[k] = FV_ADD(sum[k], FV_MUL(ws, sd[q]));
        }
    }
    for (k = hessian ? 0 : 36; k < HOME__REFINE_ACC; k++)
        FV_STORE(acc + k * HOME__REFINE_LANES, sum[k]);
}

FV_LINKAGE int FV_NAME(cauchy_sums)(const float *b, const float *keep, const int16_t *t, int n,
                                    int n_valid, float alpha, float beta, float inv_c, float *wt,
                                    float *part)
{
    const home__fv va = FV_SET1(alpha), vbeta = FV_SET1(beta), vc = FV_SET1(inv_c);
    const home__fv one = FV_SET1(1.0f), zero = FV_ZERO();
    const home__iv limit = IV_SET1(n_valid), step = IV_SET1(4);
    home__iv idx = IV_IOTA(), count = IV_ZERO();
    home__fv p0 = zero, p1 = zero, p2 = zero, p3 = zero, p4 = zero;
    int32_t c[4];
    int i;
    for (i = 0; i < n; i += 4) {
        const home__fv vb = FV_LOAD(b + i), ti = home__fv_load_s16(t + i);
        const home__mv ok = MV_AND(IV_LT(idx, limit),
                                   MV_AND(FV_GE(vb, zero), FV_GE(FV_LOAD(keep + i), zero)));
        const home__fv bi = FV_KEEP(vb, ok);
        const home__fv q = FV_MUL(FV_SUB(FV_ADD(FV_MUL(va, bi), vbeta), ti), vc);
        const home__fv wq = FV_KEEP(FV_DIV(one, FV_ADD(one, FV_MUL(q, q))), ok);
        const home__fv wb = FV_MUL(wq, bi);
        FV_STORE(wt + i, wq);
        p0 = FV_ADD(p0, wq);
        p1 = FV_ADD(p1, wb);
        p2 = FV_ADD(p2, FV_MUL(wq, ti));
        p3 = FV_ADD(p3, FV_MUL(wb, bi));
        p4 = FV_ADD(p4, FV_MUL(wb, ti));
        count = IV_SUB_M(count, ok);
        idx = IV_ADD(idx, step);
    }
    FV_STORE(part, p0);
    FV_STORE(part + 4, p1);
    FV_STORE(part + 8, p2);
    FV_STORE(part + 12, p3);
    FV_STORE(part + 16, p4);
    IV_STORE(c, count);
    return c[0] + c[1] + c[2] + c[3];
}

FV_LINKAGE void FV_NAME(residuals)(const float *b, const int16_t *t, const float *wt, int n,
                                   float alpha, float beta, float *res)
{
    const home__fv va = FV_SET1(alpha), vbeta = FV_SET1(beta), zero = FV_ZERO();
    int i;
    for (i = 0; i < n; i += 4) {
        const home__fv r = FV_SUB(FV_ADD(FV_MUL(va, FV_LOAD(b + i)), vbeta),
                                  home__fv_load_s16(t + i));
        FV_STORE(res + i, FV_KEEP(r, FV_GT(FV_LOAD(wt + i), zero)));
    }
}
#endif
