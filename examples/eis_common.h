/* Helpers shared by the live examples (eis-v4l2, eis-libcamera): tightly packed frame buffers
 * of the captured format, conversion to I420 for Y4M output and display, a millisecond clock. */
#ifndef HOME_EIS_COMMON_H
#define HOME_EIS_COMMON_H
#include "home_stab.h"
#include <stddef.h>
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif

/* The live examples' default lookahead: 6 frames (200 ms at 30 fps) of latency leave a fifth
 * of the causal filter's jitter (docs/stabiliser.md, "Defaults per tool"). */
#define EIS_LIVE_LOOKAHEAD 6

/* Monotonic milliseconds (a home_clock_fn). */
double eis_now_ms(void *user);
/* Bytes of a tightly packed w x h frame of a HOME_STAB_* format (YUYV, NV12 or I420). */
size_t eis_frame_bytes(int format, int w, int h);
/* View a tightly packed frame buffer as a home_stab_image. */
void eis_frame_view(int format, int w, int h, uint8_t *buf, home_stab_image *im);
/* Copy `rows` rows of `bytes` between buffers with different strides. */
void eis_copy_rows(uint8_t *dst, size_t dst_stride, const uint8_t *src, size_t src_stride, size_t bytes, int rows);
/* Convert a tightly packed frame to I420, into a w x h I420 frame (wide = 0) or into the left
 * (right = 0) or right half of a 2w x h one (wide = 1). */
void eis_to_i420(int format, int w, int h, const uint8_t *src, uint8_t *dst, int wide, int right);

#ifdef __cplusplus
}
#endif
#endif
