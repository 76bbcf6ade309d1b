/* Separable Gaussian smoothing of the Hough image: along r within a row (zero outside the
 * r axis, where no line crosses the image), and along theta across a ring of rows. */
#include "home_internal.h"
#include <math.h>

/* Normalised taps for radius ceil(3 sigma); returns the radius. */
int home__gauss_taps(float sigma, float *taps)
{
    int radius = (int)ceil(3.0 * sigma), k;
    double sum = 0.0;
    if (radius > HOME__MAX_SMOOTH_RADIUS) radius = HOME__MAX_SMOOTH_RADIUS;
    for (k = -radius; k <= radius; k++) sum += exp(-0.5 * k * k / ((double)sigma * sigma));
    for (k = -radius; k <= radius; k++)
        taps[k + radius] = (float)(exp(-0.5 * k * k / ((double)sigma * sigma)) / sum);
    return radius;
}

/* Borders (where taps fall off the r axis) here; the interior through the SIMD kernel, and the
 * interior's end it leaves by the reference. */
void home__smooth_r(const home__kernels *kernels, const float *in, float *out, int n,
                    const float *taps, int radius)
{
    int i, k;
    for (i = 0; i < n; i++) {
        float acc = 0.0f;
        int lo, hi;
        if (i == radius && n > 2 * radius) i = n - radius; /* skip the interior */
        lo = i - radius < 0 ? radius - i : 0;
        hi = i + radius >= n ? radius + (n - 1 - i) : 2 * radius;
        for (k = lo; k <= hi; k++) acc += taps[k] * in[i - radius + k];
        out[i] = acc;
    }
    if (n > 2 * radius)
        home__smooth_row_px(in, out, kernels->smooth_row(in, out, n, taps, radius), n - radius,
                            taps, radius);
}

void home__smooth_theta(const home__kernels *kernels, const float *const *rows, float *out, int n,
                        const float *taps, int radius)
{
    home__smooth_cols_px(rows, out, kernels->smooth_cols(rows, out, n, taps, radius), n, taps,
                         radius);
}
