/* Is a motion one period of a repeated pattern away from another just as good? A grating of
 * bars that fills the frame aligns as well one bar further on: neither HOME's lines nor the
 * photometric fit can tell which is right, and picking one is a guess. Frame A's period along
 * its dominant gradient direction comes from the autocorrelation of its profile across the bars
 * (the background image: quarter size); the refinement is started from the motion shifted by
 * one period either way, and an optimum it reaches elsewhere is scored against the motion
 * itself on the identity test's region points. */
#include "refine_internal.h"
#include <math.h>
#include <string.h>

#define PROFILE_BINS 256    /* profile across the pattern, background px (wider: 2 px bins) */
#define BIN_MIN_COUNT 4     /* pixels a profile bin needs */
#define PERIOD_MIN 3        /* lags below this many bins are the blur, not a period */
#define PERIOD_CORR 0.6     /* the profile's normalised autocorrelation at a period */
#define PERIODS_SEEN 3      /* the profile spans at least this many periods */

/* The period of frame A's background (full-size px along the unit vector n), or 0. The
 * profile and its autocorrelation go to the match-time scratch (at least 4 REGION_CAPACITY
 * floats). */
static double find_period(const home__refine_state *st, int slot, double *n)
{
    const uint8_t *a = st->background[slot];
    const int w = st->background_w, h = st->background_h;
    const double sc = (double)((1 << st->background_level) * st->background_factor);
    float *sum = (float *)st->scratch, *count = sum + PROFILE_BINS, *r = count + PROFILE_BINS;
    int x, y, lag, bins, max_lag;
    int64_t sxx = 0, syy = 0, sxy = 0;
    long total = 0;
    double phi, c, s, span, step, mean = 0.0;
    if (!a || w < 8 || h < 8) return 0.0;
    /* a row's sums fit 32 bits (at most HOME__BACKGROUND_PIXELS / 8 terms of at most 255^2), so
     * the compiler keeps them in vector lanes */
    for (y = 1; y < h - 1; y++) {
        const uint8_t *p = a + (ptrdiff_t)y * w;
        int32_t rxx = 0, ryy = 0, rxy = 0;
        for (x = 1; x < w - 1; x++) {
            const int gx = p[x + 1] - p[x - 1], gy = p[x + w] - p[x - w];
            rxx += gx * gx;
            ryy += gy * gy;
            rxy += gx * gy;
        }
        sxx += rxx;
        syy += ryy;
        sxy += rxy;
    }
    if (!(sxx + syy > 0)) return 0.0;
    phi = 0.5 * atan2(2.0 * (double)sxy, (double)(sxx - syy));
    c = cos(phi);
    s = sin(phi);
    span = fabs(c) * (w - 1) + fabs(s) * (h - 1);
    step = span < PROFILE_BINS - 1 ? 1.0 : ceil(span / (PROFILE_BINS - 1));
    bins = (int)(span / step) + 1;
    memset(sum, 0, 2 * PROFILE_BINS * sizeof *sum);
    /* bin of pixel (x, y): its position along n from the corner n points away from, in bins */
    for (y = 0; y < h; y++) {
        const uint8_t *p = a + (ptrdiff_t)y * w;
        double u = (c * (0 - 0.5 * (w - 1)) + s * (y - 0.5 * (h - 1)) + 0.5 * span) / step + 0.5;
        const double du = c / step;
        for (x = 0; x < w; x++, u += du) {
            int b = (int)u;
            b = b < 0 ? 0 : b >= bins ? bins - 1 : b;
            sum[b] += p[x];
            count[b] += 1.0f;
        }
    }
    for (x = 0; x < bins; x++)
        if (count[x] >= BIN_MIN_COUNT) {
            sum[x] /= count[x];
            mean += sum[x];
            total++;
        }
    if (total < 2) return 0.0;
    mean /= (double)total;
    for (x = 0; x < bins; x++) sum[x] = count[x] >= BIN_MIN_COUNT ? (float)(sum[x] - mean) : 0.0f;
    /* normalised autocorrelation (bins too thin count as zero), then the first lag from
     * PERIOD_MIN that is a local maximum of at least PERIOD_CORR */
    max_lag = (bins - 1) / PERIODS_SEEN;
    for (lag = PERIOD_MIN - 1; lag <= max_lag + 1; lag++) {
        double sab = 0.0, saa = 0.0, sbb = 0.0;
        for (x = 0; x + lag < bins; x++) {
            sab += (double)sum[x] * sum[x + lag];
            saa += (double)sum[x] * sum[x];
            sbb += (double)sum[x + lag] * sum[x + lag];
        }
        r[lag] = saa > 0.0 && sbb > 0.0 ? (float)(sab / sqrt(saa * sbb)) : 0.0f;
    }
    for (lag = PERIOD_MIN; lag <= max_lag; lag++)
        if (r[lag] >= PERIOD_CORR && r[lag] >= r[lag - 1] && r[lag] >= r[lag + 1]) {
            n[0] = c;
            n[1] = s;
            return lag * step * sc;
        }
    return 0.0;
}

double home__refine_alias_ratio(home_context *ctx, int slot, const double *h, double *period)
{
    const home__refine_state *st = &ctx->refine;
    double n[2], cost[3], alias[2][9];
    const double *hs[3];
    int k, i;
    *period = find_period(st, slot, n);
    if (!(*period > 0.0) || st->regions[slot].n < MIN_POINTS) return INFINITY;
    hs[0] = h;
    for (k = 0; k < 2; k++) {
        /* the optimum the refinement reaches from h after a shift of one period along n in A
         * (where the pattern repeats), either way: the period is known to a background pixel
         * only, and the pattern's alias is a homography of its own */
        const double d = k ? -*period : *period;
        home_result r;
        memset(&r, 0, sizeof r);
        for (i = 0; i < 9; i++) alias[k][i] = h[i];
        for (i = 0; i < 3; i++)
            alias[k][3 * i + 2] += d * (n[0] * h[3 * i] + n[1] * h[3 * i + 1]);
        r.sigma_px = INFINITY;
        home__refine_run(ctx, slot, alias[k], &r);
        hs[1 + k] = NULL;
        if (r.refined && home__refine_max_corner_distance(0.5 * (ctx->cfg.width - 1),
                                                          0.5 * (ctx->cfg.height - 1), r.H, h) >
                             0.5 * *period) {
            memcpy(alias[k], r.H, sizeof alias[k]);
            hs[1 + k] = alias[k];
        }
    }
    if (!hs[1] && !hs[2]) return INFINITY;
    home__refine_region_costs(ctx, slot, hs, 3, cost);
    return cost[0] > 0.0 ? (cost[1] < cost[2] ? cost[1] : cost[2]) / cost[0] : INFINITY;
}
