/* Bilinear fixed-point warp of I420 / NV12 / YUYV / I422 / grey frames by an affine map. The map
 * is converted once to Q16 integers, so every row's start and step are exact integers and the
 * output is the same bit for bit on every platform and in every kernel version. */
#include "home_stab.h"
#include "stab_kernels.h"
#include <math.h>

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
        dst[(ptrdiff_t)i * dst_step] =
            blend(src + (ptrdiff_t)(y >> HOME__WARP_FRAC_BITS) * stride + (ptrdiff_t)(x >> HOME__WARP_FRAC_BITS) * step,
                  stride, step, HOME__WARP_WEIGHT(x & 0xffff), HOME__WARP_WEIGHT(y & 0xffff));
}

int home__warp_row_inside(int w, int h, int32_t x0, int32_t y0, int32_t dx, int32_t dy, int n)
{
    const int32_t x_max = (int32_t)(w - 1) << HOME__WARP_FRAC_BITS;
    const int32_t y_max = (int32_t)(h - 1) << HOME__WARP_FRAC_BITS;
    const int64_t x1 = (int64_t)x0 + (int64_t)dx * (n - 1), y1 = (int64_t)y0 + (int64_t)dy * (n - 1);
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

const home__stab_kernels home__stab_kernels_scalar = {"none", home__warp_row_c};

/* One component plane of a frame: where its samples are and how it is subsampled. */
typedef struct plane_view {
    const uint8_t *src;
    uint8_t *dst;
    ptrdiff_t src_stride, dst_stride;
    int step, w, h, sub_x, sub_y;
} plane_view;

static int plane_views(const home_stab_image *s, home_stab_image *d, plane_view *v)
{
    const int w = s->width, h = s->height;
    int n = 0, k;
    switch (s->format) {
    case HOME_STAB_GREY:
        v[n++] = (plane_view){s->plane[0], d->plane[0], s->stride[0], d->stride[0], 1, w, h, 1, 1};
        break;
    case HOME_STAB_I420:
    case HOME_STAB_I422: {
        int sy = s->format == HOME_STAB_I420 ? 2 : 1;
        v[n++] = (plane_view){s->plane[0], d->plane[0], s->stride[0], d->stride[0], 1, w, h, 1, 1};
        for (k = 1; k < 3; k++)
            v[n++] = (plane_view){s->plane[k], d->plane[k], s->stride[k], d->stride[k], 1, w / 2,
                                  h / sy, 2, sy};
        break;
    }
    case HOME_STAB_NV12:
        v[n++] = (plane_view){s->plane[0], d->plane[0], s->stride[0], d->stride[0], 1, w, h, 1, 1};
        for (k = 0; k < 2; k++)
            v[n++] = (plane_view){s->plane[1] + k, d->plane[1] + k, s->stride[1], d->stride[1], 2,
                                  w / 2, h / 2, 2, 2};
        break;
    case HOME_STAB_YUYV:
        v[n++] = (plane_view){s->plane[0], d->plane[0], s->stride[0], d->stride[0], 2, w, h, 1, 1};
        for (k = 0; k < 2; k++)
            v[n++] = (plane_view){s->plane[0] + 1 + 2 * k, d->plane[0] + 1 + 2 * k, s->stride[0],
                                  d->stride[0], 4, w / 2, h, 2, 1};
        break;
    default:
        return 0;
    }
    return n;
}

static int check_image(const home_stab_image *im)
{
    int planes, k;
    ptrdiff_t row_bytes[3];
    if (!im) return HOME_E_NULL;
    if (im->width < HOME_MIN_SIDE || im->height < HOME_MIN_SIDE || im->width > HOME_MAX_SIDE ||
        im->height > HOME_MAX_SIDE)
        return HOME_E_SIZE;
    switch (im->format) {
    case HOME_STAB_GREY: planes = 1; row_bytes[0] = im->width; break;
    case HOME_STAB_I420:
    case HOME_STAB_I422:
        planes = 3; row_bytes[0] = im->width; row_bytes[1] = row_bytes[2] = im->width / 2; break;
    case HOME_STAB_NV12: planes = 2; row_bytes[0] = row_bytes[1] = im->width; break;
    case HOME_STAB_YUYV: planes = 1; row_bytes[0] = 2 * (ptrdiff_t)im->width; break;
    default: return HOME_E_CONFIG;
    }
    if (im->format != HOME_STAB_GREY && (im->width % 2 || (im->format != HOME_STAB_YUYV &&
                                                           im->format != HOME_STAB_I422 &&
                                                           im->height % 2)))
        return HOME_E_SIZE;
    for (k = 0; k < planes; k++) {
        if (!im->plane[k]) return HOME_E_NULL;
        if (im->stride[k] < row_bytes[k]) return HOME_E_STRIDE;
        /* the last row's address must not overflow (checked for the luma's row count) */
        if (im->stride[k] > (PTRDIFF_MAX - row_bytes[k]) / (im->height - 1)) return HOME_E_STRIDE;
    }
    return HOME_OK;
}

int home__stab_check_image(const home_stab_image *im) { return check_image(im); }

static int32_t to_q16(double v) { return (int32_t)floor(v * 65536.0 + 0.5); }

int home_stab_warp(const double *m, const home_stab_image *src, home_stab_image *dst)
{
    return home_stab_warp_rows(m, src, dst, 0, dst ? dst->height : 0);
}

int home_stab_warp_rows(const double *m, const home_stab_image *src, home_stab_image *dst, int first_row, int rows)
{
    plane_view views[3];
    const home__stab_kernels *kern;
    home_config simd_choice;
    int status, n, k, j;
    double limit_x, limit_y;
    static const double corners[4][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    if (!m) return HOME_E_NULL;
    if ((status = check_image(src)) != HOME_OK || (status = check_image(dst)) != HOME_OK)
        return status;
    if (src->format != dst->format || src->width != dst->width || src->height != dst->height)
        return HOME_E_MISMATCH;
    /* a band of whole chroma rows: with vertically subsampled chroma it starts and ends even */
    if (first_row < 0 || rows < 1 || rows > dst->height - first_row) return HOME_E_CONFIG;
    if ((dst->format == HOME_STAB_I420 || dst->format == HOME_STAB_NV12) && (first_row % 2 || rows % 2))
        return HOME_E_CONFIG;
    for (k = 0; k < 9; k++)
        if (!isfinite(m[k])) return HOME_E_CONFIG;
    if (m[6] != 0.0 || m[7] != 0.0 || m[8] != 1.0) return HOME_E_CONFIG;
    /* the frame's corners must land within one frame size of the source, which keeps every Q16
     * coordinate (affine: extremes at the corners) well inside int32 */
    limit_x = 2.0 * src->width;
    limit_y = 2.0 * src->height;
    for (k = 0; k < 4; k++) {
        double x = corners[k][0] * (src->width - 1), y = corners[k][1] * (src->height - 1);
        double u = m[0] * x + m[1] * y + m[2], v = m[3] * x + m[4] * y + m[5];
        if (u < -limit_x + src->width || u > limit_x || v < -limit_y + src->height || v > limit_y)
            return HOME_E_CONFIG;
    }
    /* the backend HOME would use (HOME_SIMD honoured); all give the same bytes */
    home_default_config(&simd_choice, HOME_MIN_SIDE, HOME_MIN_SIDE);
    kern = home__stab_kernels_for(simd_choice.simd);
    if (!kern) kern = &home__stab_kernels_scalar;
    n = plane_views(src, dst, views);
    for (k = 0; k < n; k++) {
        const plane_view *p = &views[k];
        /* plane coords c relate to luma coords l by l = sub*c + (sub-1)/2 (centre siting) */
        const double sx = p->sub_x, sy = p->sub_y, ox = 0.5 * (sx - 1), oy = 0.5 * (sy - 1);
        const double a = m[0], b = m[1] * sy / sx, c = (m[0] * ox + m[1] * oy + m[2] - ox) / sx;
        const double d = m[3] * sx / sy, e = m[4], f = (m[3] * ox + m[4] * oy + m[5] - oy) / sy;
        const int32_t aq = to_q16(a), bq = to_q16(b), cq = to_q16(c);
        const int32_t dq = to_q16(d), eq = to_q16(e), fq = to_q16(f);
        /* each row starts from its own index (no running sum): a band's bytes are the whole
         * warp's */
        for (j = first_row / p->sub_y; j < (first_row + rows) / p->sub_y; j++)
            kern->warp_row(p->src, p->src_stride, p->step, p->w, p->h, bq * j + cq, eq * j + fq, aq,
                           dq, p->dst + (ptrdiff_t)j * p->dst_stride, p->step, p->w);
    }
    return HOME_OK;
}
