/* The warp's scalar reference (port/stab_kernels.h): the definition every backend reproduces. */
#include "stab_kernels.h"

/* The reference's arithmetic on one 2x2 neighbourhood p (p[0], p[step], p[stride],
 * p[stride + step]) with 7-bit weights: every intermediate fits int16 and the vertical blend
 * int32, which SSE2's pmaddwd and NEON's widening multiplies compute exactly. */
static uint8_t blend(const uint8_t *p, ptrdiff_t stride, int step, uint32_t fx, uint32_t fy)
{
    const uint32_t top = p[0] * (128 - fx) + p[step] * fx;
    const uint32_t bot = p[stride] * (128 - fx) + p[stride + step] * fx;
    return (uint8_t)((top * (128 - fy) + bot * fy + 8192u) >> 14);
}

/* Inner loop for a row whose every sample lies inside [0, w-1) x [0, h-1): no clamping. Gives
 * the same bytes as the clamped loop there (xi = x >> 16 <= w - 2 already). */
static void warp_row_inside(const uint8_t *src, ptrdiff_t stride, int step, int32_t x, int32_t y,
                            int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n)
{
    int i;
    for (i = 0; i < n; i++, x += dx, y += dy)
        dst[(ptrdiff_t)i * dst_step] = blend(src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride +
                                                 (ptrdiff_t)(x >> HOME__WARP_FRAC_BITS) * step,
                                             stride, step, HOME__WARP_WEIGHT(x & 0xffff),
                                             HOME__WARP_WEIGHT(y & 0xffff));
}

int home__warp_row_inside(int w, int h, int32_t x0, int32_t y0, int32_t dx, int32_t dy, int n)
{
    const int32_t x_max = (int32_t)(w - 1) << HOME__WARP_FRAC_BITS;
    const int32_t y_max = (int32_t)(h - 1) << HOME__WARP_FRAC_BITS;
    const int64_t x1 = (int64_t)x0 + (int64_t)dx * (n - 1),
                  y1 = (int64_t)y0 + (int64_t)dy * (n - 1);
    /* affine: the row's extremes are its ends */
    return n > 0 && x0 >= 0 && x0 < x_max && x1 >= 0 && x1 < x_max && y0 >= 0 && y0 < y_max &&
           y1 >= 0 && y1 < y_max;
}

void home__warp_row_c(const uint8_t *src, ptrdiff_t stride, int step, int w, int h, int32_t x0,
                      int32_t y0, int32_t dx, int32_t dy, uint8_t *dst, int dst_step, int n)
{
    const int32_t x_max = (int32_t)(w - 1) << HOME__WARP_FRAC_BITS;
    const int32_t y_max = (int32_t)(h - 1) << HOME__WARP_FRAC_BITS;
    int32_t x = x0, y = y0;
    int i;
    if (home__warp_row_inside(w, h, x0, y0, dx, dy, n)) {
        if (step == 1 && dst_step == 1)   /* planar: constant steps let the compiler do better */
            warp_row_inside(src, stride, 1, x0, y0, dx, dy, dst, 1, n);
        else
            warp_row_inside(src, stride, step, x0, y0, dx, dy, dst, dst_step, n);
        return;
    }
    for (i = 0; i < n; i++, x += dx, y += dy) {
        /* clamp into the plane; at the last column/row use the pair (w-2, w-1) with weight 128 */
        int32_t xc = x < 0 ? 0 : x > x_max ? x_max : x;
        int32_t yc = y < 0 ? 0 : y > y_max ? y_max : y;
        int32_t xi = xc >> HOME__WARP_FRAC_BITS, yi = yc >> HOME__WARP_FRAC_BITS;
        if (xi > w - 2) xi = w - 2;
        if (yi > h - 2) yi = h - 2;
        dst[(ptrdiff_t)i * dst_step] =
            blend(src + (ptrdiff_t)yi * stride + (ptrdiff_t)xi * step, stride, step,
                  HOME__WARP_WEIGHT(xc - (xi << HOME__WARP_FRAC_BITS)),
                  HOME__WARP_WEIGHT(yc - (yi << HOME__WARP_FRAC_BITS)));
    }
}

/* the table's body kernel: planar rows inside the source */
static void warp_row_scalar(const uint8_t *src, ptrdiff_t stride, int w, int32_t x0, int32_t y0,
                            int32_t dx, int32_t dy, uint8_t *dst, int n)
{
    (void)w;
    warp_row_inside(src, stride, 1, x0, y0, dx, dy, dst, 1, n);
}

const home__stab_kernels home__stab_kernels_scalar = {.name = "none", .block = 1,
                                                      .warp_row = warp_row_scalar};
