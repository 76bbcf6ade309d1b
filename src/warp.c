/* Bilinear fixed-point warp of I420 / NV12 / YUYV / I422 / grey frames by an affine map. The map
 * is converted once to Q16 integers, so every row's start and step are exact integers and the
 * output is the same bit for bit on every platform and in every kernel version. */
#include "home_stab.h"
#include "stab_internal.h"
#include <math.h>

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

/* floor(a / b) for b > 0 */
static int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

/* The samples i of a row whose coordinate c0 + i d lies in [0, c_max): [*lo, *hi) (an affine
 * row enters and leaves the source once), intersected with what the two bounds hold. */
static void inside_span(int64_t c0, int64_t d, int64_t c_max, int64_t *lo, int64_t *hi)
{
    int64_t a, b;
    if (d == 0) {
        if (c0 < 0 || c0 >= c_max) *hi = *lo;
        return;
    }
    if (d > 0) {
        a = c0 >= 0 ? 0 : floor_div(-c0 + d - 1, d); /* first i with c >= 0 */
        b = floor_div(c_max - 1 - c0, d) + 1;        /* past the last i with c < c_max */
    } else {
        a = c0 < c_max ? 0 : floor_div(c0 - c_max, -d) + 1;
        b = floor_div(c0, -d) + 1;
    }
    if (a > *lo) *lo = a;
    if (b < *hi) *hi = b;
    if (*hi < *lo) *hi = *lo;
}

/* Sample i's coordinate on a row from c0 by steps d (Q16, wrapping as the reference's sum). */
static int32_t sample_at(int32_t c0, int32_t d, int i)
{
    return (int32_t)((uint32_t)c0 + (uint32_t)i * (uint32_t)d);
}

/* One output row (home__warp_row_c's contract) by the table k: its body kernel takes the part
 * of a planar row inside the source up to a multiple of its block, the reference the rest (a
 * crop that reaches the frame's last column or row, or the identity, still warps in SIMD). */
void home__warp_row(const home__stab_kernels *k, const uint8_t *src, ptrdiff_t stride, int step,
                    int w, int h, int32_t x0, int32_t y0, int32_t dx, int32_t dy, uint8_t *dst,
                    int dst_step, int n)
{
    int64_t lo = 0, hi = n;
    int first, end;
    if (step != 1 || dst_step != 1) {
        home__warp_row_c(src, stride, step, w, h, x0, y0, dx, dy, dst, dst_step, n);
        return;
    }
    inside_span(x0, dx, (int64_t)(w - 1) << HOME__WARP_FRAC_BITS, &lo, &hi);
    inside_span(y0, dy, (int64_t)(h - 1) << HOME__WARP_FRAC_BITS, &lo, &hi);
    first = lo < n ? (int)lo : n; /* past the row's end: no sample inside */
    /* a power of two: no division (armv7 has none) */
    end = first + ((int)(hi - lo) & ~(k->block - 1));
    if (first > 0) home__warp_row_c(src, stride, 1, w, h, x0, y0, dx, dy, dst, 1, first);
    if (end > first)
        k->warp_row(src, stride, w, sample_at(x0, dx, first), sample_at(y0, dy, first), dx, dy,
                    dst + first, end - first);
    if (end < n)
        home__warp_row_c(src, stride, 1, w, h, sample_at(x0, dx, end), sample_at(y0, dy, end),
                         dx, dy, dst + end, 1, n - end);
}

static int32_t to_q16(double v) { return (int32_t)floor(v * 65536.0 + 0.5); }

int home_stab_warp(const double *m, const home_stab_image *src, home_stab_image *dst)
{
    return home_stab_warp_rows(m, src, dst, 0, dst ? dst->height : 0);
}

int home_stab_warp_rows(const double *m, const home_stab_image *src, home_stab_image *dst,
                        int first_row, int rows)
{
    plane_view views[3];
    const home__stab_kernels *kern;
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
    if ((dst->format == HOME_STAB_I420 || dst->format == HOME_STAB_NV12) &&
        (first_row % 2 || rows % 2))
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
    /* the best backend here (port/dispatch.c; CPU detection, no getenv per band): all give the
     * same bytes, which tests/test_backends.c checks for every backend */
    kern = home__stab_kernels_for(HOME__SIMD_BEST);
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
            home__warp_row(kern, p->src, p->src_stride, p->step, p->w, p->h, bq * j + cq,
                           eq * j + fq, aq, dq, p->dst + (ptrdiff_t)j * p->dst_stride, p->step,
                           p->w);
    }
    return HOME_OK;
}
