/* 1x16 radial descriptors. The paper crops a 2x32 patch of the quantised Hough image at the
 * keypoint and shrinks it by 2. Cutting that patch at integer bins misaligns it by up to one
 * bin (home-notes.md, finding 2), so the patch is sampled bilinearly centred on the subpixel
 * keypoint instead: each value is the mean of the 2x2 block it shrinks from. */
#include "home_internal.h"
#include <math.h>

/* Bilinear J at (row t relative to rows[0], column r); zero beyond the r axis. */
static float sample(const float *const *rows, float t, float r, int r_bins)
{
    int t0 = (int)floorf(t), r0 = (int)floorf(r);
    float ft = t - (float)t0, fr = r - (float)r0;
    float a0 = 0.0f, a1 = 0.0f, b0 = 0.0f, b1 = 0.0f;
    if (t0 < 0) { t0 = 0; ft = 0.0f; }
    if (t0 > HOME__DESC_ROWS - 2) { t0 = HOME__DESC_ROWS - 2; ft = 1.0f; }
    if (r0 >= 0 && r0 < r_bins) { a0 = rows[t0][r0]; b0 = rows[t0 + 1][r0]; }
    if (r0 + 1 >= 0 && r0 + 1 < r_bins) { a1 = rows[t0][r0 + 1]; b1 = rows[t0 + 1][r0 + 1]; }
    return (1.0f - ft) * ((1.0f - fr) * a0 + fr * a1) + ft * ((1.0f - fr) * b0 + fr * b1);
}

/* rows[0..4] are smoothed rows centre-2 .. centre+2. */
void home__describe_samples(const float *const *rows, int centre, int r_bins, float theta_bin,
                            float r_bin, float *samples)
{
    float t = theta_bin - (float)(centre - 2);
    int k;
    for (k = 0; k < HOME_DESC_LEN; k++) {
        float r = r_bin - 16.0f + 2.0f * (float)k;
        samples[k] = 0.25f * (sample(rows, t - 0.5f, r + 0.5f, r_bins) +
                              sample(rows, t - 0.5f, r + 1.5f, r_bins) +
                              sample(rows, t + 0.5f, r + 0.5f, r_bins) +
                              sample(rows, t + 0.5f, r + 1.5f, r_bins));
    }
}

/* uint8 quantisation 128 + v*scale. The alternate form of a keypoint near the theta wrap is
 * (theta +- pi, -r, -sign), whose radial pattern is this one reversed and negated. */
void home__quantise_descriptor(const float *samples, float scale, int reverse_negate,
                               uint8_t *desc)
{
    int k;
    for (k = 0; k < HOME_DESC_LEN; k++) {
        float v = reverse_negate ? -samples[HOME_DESC_LEN - 1 - k] : samples[k];
        float q = floorf(128.0f + v * scale + 0.5f);
        desc[k] = (uint8_t)(q < 0.0f ? 0.0f : q > 255.0f ? 255.0f : q);
    }
}
