/* 1x16 radial descriptors. The paper crops a 2x32 patch of the quantised Hough image at the
 * keypoint and shrinks it by 2. Cutting that patch at integer bins misaligns it by up to one
 * bin (home-notes.md, finding 2), so the patch is sampled bilinearly centred on the subpixel
 * keypoint instead: each value is the mean of the 2x2 block it shrinks from. */
#include "home_internal.h"
#include <math.h>

/* J along the r axis at r0, r0 + 1, ..., r0 + 31 on the theta position t (relative to rows[0]),
 * bilinear; zero beyond the r axis. Each of the 33 columns is interpolated in theta once, then
 * neighbours in r (branch-free loops, which the compiler vectorises). */
static void radial_profile(const float *const *rows, float t, float r0, int r_bins, float *out)
{
    int t0 = (int)floorf(t), i0 = (int)floorf(r0), m, lo, hi;
    float ft = t - (float)t0, fr = r0 - (float)i0, col[2 * HOME_DESC_LEN + 1];
    const float *a, *b;
    if (t0 < 0) { t0 = 0; ft = 0.0f; }
    if (t0 > HOME__DESC_ROWS - 2) { t0 = HOME__DESC_ROWS - 2; ft = 1.0f; }
    a = rows[t0];
    b = rows[t0 + 1];
    /* columns i0 + m inside [0, r_bins): m in [lo, hi) */
    lo = i0 < 0 ? -i0 : 0;
    hi = r_bins - i0 < 2 * HOME_DESC_LEN + 1 ? r_bins - i0 : 2 * HOME_DESC_LEN + 1;
    if (lo > 2 * HOME_DESC_LEN + 1) lo = 2 * HOME_DESC_LEN + 1;
    if (hi < lo) hi = lo;
    for (m = 0; m < lo; m++) col[m] = 0.0f;
    for (; m < hi; m++) col[m] = a[i0 + m] + ft * (b[i0 + m] - a[i0 + m]);
    for (; m < 2 * HOME_DESC_LEN + 1; m++) col[m] = 0.0f;
    for (m = 0; m < 2 * HOME_DESC_LEN; m++) out[m] = col[m] + fr * (col[m + 1] - col[m]);
}

/* rows[0..4] are smoothed rows centre-2 .. centre+2. The 2x32 patch centred on the keypoint
 * has its rows at theta +- 0.5 and its columns at r - 15.5 .. r + 15.5. */
void home__describe_samples(const float *const *rows, int centre, int r_bins, float theta_bin,
                            float r_bin, float *samples)
{
    float t = theta_bin - (float)(centre - 2), lo[2 * HOME_DESC_LEN], hi[2 * HOME_DESC_LEN];
    int k;
    radial_profile(rows, t - 0.5f, r_bin - 15.5f, r_bins, lo);
    radial_profile(rows, t + 0.5f, r_bin - 15.5f, r_bins, hi);
    for (k = 0; k < HOME_DESC_LEN; k++)
        samples[k] = 0.25f * (lo[2 * k] + lo[2 * k + 1] + hi[2 * k] + hi[2 * k + 1]);
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
