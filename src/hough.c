/* Texture-preserving Hough transform J(theta, r) = [sum of grad I along the line] . n(theta),
 * with nearest-bin line summation, then Gaussian smoothing.
 *
 * Since n(theta) is constant along a line, J = cos(theta) R[Ix] + sin(theta) R[Iy], where R sums
 * the exact integer gradients of the pixels whose centre falls in the r bin. The bin index is
 * computed in Q16 fixed point over doubled centred coordinates (integers), so every backend
 * produces the same bins. */
#include "home_internal.h"
#include <math.h>
#include <string.h>

void home__hough_accumulate_row(const int16_t *gx, const int16_t *gy, int width, int height,
                                int32_t cos_q, int32_t sin_q, int32_t base_q, int32_t *acc_x,
                                int32_t *acc_y, int r_bins)
{
    int x, y;
    memset(acc_x, 0, (size_t)r_bins * sizeof *acc_x);
    memset(acc_y, 0, (size_t)r_bins * sizeof *acc_y);
    /* border rows and columns have zero gradient: skip them */
    for (y = 1; y < height - 1; y++) {
        const int16_t *rx = gx + (size_t)y * width, *ry = gy + (size_t)y * width;
        int32_t pos = (2 - (width - 1)) * cos_q + (2 * y - (height - 1)) * sin_q + base_q;
        for (x = 1; x < width - 1; x++) {
            int bin = pos >> 16;           /* pos > 0 by construction of base_q */
            acc_x[bin] += rx[x];
            acc_y[bin] += ry[x];
            pos += 2 * cos_q;
        }
    }
}

double home__hough_stream(home_context *ctx, const uint8_t *image, ptrdiff_t stride,
                          home__row_fn on_row, void *user)
{
    const int n_theta = ctx->cfg.theta_bins, r_bins = ctx->r_bins, radius = ctx->smooth_radius;
    const int width = ctx->cfg.width, height = ctx->cfg.height;
    const int first_smooth = -3, last_smooth = n_theta + 2;
    const int first_raw = first_smooth - radius, last_raw = last_smooth + radius;
    const int raw_ring = 2 * radius + 1;
    const double scale = 32768.0 / ctx->cfg.r_step; /* Q16 over doubled coordinates */
    const int32_t base_q = (int32_t)(r_bins / 2) * 65536;
    const float *raw_window[2 * HOME__MAX_SMOOTH_RADIUS + 1];
    const float *window[HOME__DESC_ROWS];
    double t0 = home__now(ctx), spent = 0.0;
    int k, i;

    home__gradient(image, stride, width, height, ctx->grad_x, ctx->grad_y);
    for (k = first_raw; k <= last_raw; k++) {
        double theta = k * HOME__PI / n_theta, c = cos(theta), s = sin(theta);
        float *raw = ctx->raw_rows + (size_t)((k - first_raw) % raw_ring) * r_bins;
        int j;
        home__hough_accumulate_row(ctx->grad_x, ctx->grad_y, width, height,
                                   (int32_t)lround(c * scale), (int32_t)lround(s * scale), base_q,
                                   ctx->acc_x, ctx->acc_y, r_bins);
        for (i = 0; i < r_bins; i++)
            ctx->row_tmp[i] = (float)(c * ctx->acc_x[i] + s * ctx->acc_y[i]);
        home__smooth_r(ctx->row_tmp, raw, r_bins, ctx->smooth_taps, radius);
        if (k - first_raw < 2 * radius) continue;

        j = k - radius; /* the theta-smoothed row now complete */
        for (i = 0; i < raw_ring; i++)
            raw_window[i] = ctx->raw_rows + (size_t)((j - radius + i - first_raw) % raw_ring) * r_bins;
        home__smooth_theta(raw_window, ctx->smooth_rows +
                               (size_t)((j - first_smooth) % HOME__DESC_ROWS) * r_bins,
                           r_bins, ctx->smooth_taps, radius);
        for (i = 0; i < HOME__DESC_ROWS; i++) {
            int row = j - (HOME__DESC_ROWS - 1) + i;
            window[i] = row < first_smooth ? NULL
                : ctx->smooth_rows + (size_t)((row - first_smooth) % HOME__DESC_ROWS) * r_bins;
        }
        {
            double t1 = home__now(ctx);
            on_row(user, j, window);
            t0 += home__now(ctx) - t1; /* exclude the consumer's time */
        }
    }
    spent = home__now(ctx) - t0;
    return spent;
}
