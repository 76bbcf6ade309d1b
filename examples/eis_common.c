/* Helpers of the live examples: see eis_common.h. */
#define _POSIX_C_SOURCE 200809L
#include "eis_common.h"
#include <string.h>
#include <time.h>

double eis_now_ms(void *user)
{
    struct timespec ts;
    (void)user;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

size_t eis_frame_bytes(int format, int w, int h) { return format == HOME_STAB_YUYV ? (size_t)w * h * 2 : (size_t)w * h * 3 / 2; }

void eis_frame_view(int format, int w, int h, uint8_t *buf, home_stab_image *im)
{
    memset(im, 0, sizeof *im);
    im->format = format; im->width = w; im->height = h;
    im->plane[0] = buf;
    if (format == HOME_STAB_YUYV) { im->stride[0] = 2 * w; return; }
    im->stride[0] = w;
    im->plane[1] = buf + (size_t)w * h;
    if (format == HOME_STAB_NV12) { im->stride[1] = w; return; }
    im->plane[2] = im->plane[1] + (size_t)(w / 2) * (h / 2);
    im->stride[1] = im->stride[2] = w / 2;
}

void eis_copy_rows(uint8_t *dst, size_t dst_stride, const uint8_t *src, size_t src_stride, size_t bytes, int rows)
{
    int r;
    for (r = 0; r < rows; r++) memcpy(dst + r * dst_stride, src + r * src_stride, bytes);
}

void eis_to_i420(int format, int w, int h, const uint8_t *src, uint8_t *dst, int wide, int right)
{
    const int dw = wide ? 2 * w : w, x0 = right ? w : 0;
    uint8_t *y = dst, *u = dst + (size_t)dw * h, *v = u + (size_t)(dw / 2) * (h / 2);
    int r, i;
    for (r = 0; r < h; r++) {
        uint8_t *yr = y + (size_t)r * dw + x0;
        if (format == HOME_STAB_YUYV) for (i = 0; i < w; i++) yr[i] = src[(size_t)r * 2 * w + 2 * i];
        else memcpy(yr, src + (size_t)r * w, (size_t)w);
    }
    for (r = 0; r < h / 2; r++) {
        uint8_t *ur = u + (size_t)r * (dw / 2) + x0 / 2, *vr = v + (size_t)r * (dw / 2) + x0 / 2;
        for (i = 0; i < w / 2; i++) {
            if (format == HOME_STAB_YUYV) {
                const uint8_t *a = src + (size_t)(2 * r) * 2 * w + 4 * i, *b = a + 2 * w;
                ur[i] = (uint8_t)((a[1] + b[1] + 1) / 2);
                vr[i] = (uint8_t)((a[3] + b[3] + 1) / 2);
            } else if (format == HOME_STAB_NV12) {
                const uint8_t *c = src + (size_t)w * h + (size_t)r * w + 2 * i;
                ur[i] = c[0]; vr[i] = c[1];
            } else {
                ur[i] = src[(size_t)w * h + (size_t)r * (w / 2) + i];
                vr[i] = src[(size_t)w * h + (size_t)(w / 2) * (h / 2) + (size_t)r * (w / 2) + i];
            }
        }
    }
}
