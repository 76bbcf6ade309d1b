/* The static-camera test: does the identity explain the frame's regions better than a
 * motion does? Moving objects are textured and draw HOME's lines and the template points to
 * themselves; every region here has its own points, so a plainer background still votes. */
#include "refine_internal.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define REGION_POINTS 3      /* a region with fewer points does not vote */
#define DECISIVE_RATIO 0.5   /* a clear vote: the better cost at most this share of the other */
#define DECISIVE_GREY 1.0    /* ... and the two apart by more than this squared per point */
/* A faint region's costs are all small, and noise alone can halve one: its clear vote needs the
 * better cost at most this share of the other, and the two this far apart */
#define DECISIVE_RATIO_FAINT 0.25
#define DECISIVE_GREY_FAINT 0.25
#define MIN_VOTES 6          /* fewer clear votes: no decision (clear_share 0) */
#define PLAIN_MIN_PIXELS 4   /* fewer plain regions, or fewer usable pixels than this many
                                regions hold: too little to judge by */
#define PLAIN_FLAT 4         /* a plain region's pixel counts where no score |gx| + |gy| (2x
                                central differences) within 2 px reaches this: the tails of
                                the edges next to it differ in blur between frames */
#define UNEXPLAINED_COST 3.0     /* a region the motion leaves unexplained: its cost over this
                                    many times the median region's, */
#define UNEXPLAINED_IDENTITY 1.5 /* ... and the identity's at most this many times the motion's */
#define PLAIN_KAPPA_MAX 0.8 /* the falloff the plain test fits for a motion: at most a darkening
                               of four fifths at the corners */
#define PLAIN_HIST_BINS 256  /* the identity's residual histogram: 32 grey levels *
                                8 bins, the rest in one */

/* Sorts v[0..n) ascending (a few dozen values: insertion; no qsort on bare-metal targets). */
static void sort_ascending(double *v, int n)
{
    int i, j;
    for (i = 1; i < n; i++) {
        const double x = v[i];
        for (j = i; j > 0 && v[j - 1] > x; j--) v[j] = v[j - 1];
        v[j] = x;
    }
}

/* Share of the regions with points (at least REGION_POINTS) that the motion leaves unexplained:
 * its mean cost a point over UNEXPLAINED_COST times the median region's, and the identity's
 * at most UNEXPLAINED_IDENTITY times the motion's there (the part of the frame that does not
 * move so: a second motion, or a still background where h follows movers). best[e][r]: the
 * region's summed cost under e (0: h, 1: the identity), with the better gain and bias. */
static double unexplained_share(double best[2][REGIONS_X * REGIONS_Y], const int *count)
{
    double per_point[REGIONS_X * REGIONS_Y], median;
    int r, n = 0, left = 0;
    for (r = 0; r < REGIONS_X * REGIONS_Y; r++)
        if (count[r] >= REGION_POINTS) per_point[n++] = best[0][r] / count[r];
    if (n < REGIONS_X * REGIONS_Y / 4) return 0.0;
    sort_ascending(per_point, n);
    median = n % 2 ? per_point[n / 2] : 0.5 * (per_point[n / 2 - 1] + per_point[n / 2]);
    for (r = 0; r < REGIONS_X * REGIONS_Y; r++)
        left += count[r] >= REGION_POINTS && best[0][r] > UNEXPLAINED_COST * median * count[r] &&
                best[1][r] <= UNEXPLAINED_IDENTITY * best[0][r];
    return (double)left / n;
}

/* Share of the frame's regions (a REGIONS_X x REGIONS_Y grid; those with at least REGION_POINTS
 * of the region points vote) whose points the identity explains better than h (pixels) does:
 * the robust photometric cost of each region under both, each with the better of the two
 * estimates' gain and bias. clear_share: the same over the regions one of them explains
 * clearly better, faint ones included (points below the textured floor: a horizon in fog,
 * which a close vote of noise must not decide but a clear one may). Moving objects are
 * textured and draw the template points (and HOME's lines) to themselves; the static
 * background wins by area. */
double home__refine_identity_share(home_context *ctx, int slot, const double *h,
                                    double *clear_share, int *against, unsigned char *still)
{
    home__refine_state *st = &ctx->refine;
    double cost[2][2][REGIONS_X * REGIONS_Y], best[2][REGIONS_X * REGIONS_Y];
    double gain[2], bias[2], hn[9], sigma, c, cost_h, cost_i;
    int count[REGIONS_X * REGIONS_Y], e, i, k, r, votes = 0;
    int wins = 0, clear_votes = 0, clear_wins = 0, fl, n4;
    const unsigned char *faint = st->region_faint[slot]; /* frame A's, as its points */
    const home__refine_points *tp;
    float m[9];
    home__refine_solver s;
    region_grid grid;
    *clear_share = 0.0;
    *against = 0;
    st->unexplained = 0.0;
    if (still) memset(still, 0, REGIONS_X * REGIONS_Y);
    home__refine_solver_setup(ctx, slot, &s);
    fl = st->region_level;
    tp = &st->regions[slot];
    if (tp->n < MIN_POINTS) return 0.0;
    n4 = (tp->n + LANES - 1) & ~(LANES - 1);
    home__refine_to_normalised(&s, h, hn);
    home__refine_level_matrix(&s, hn, fl, m);
    st->rk->warp(m, tp->x, tp->y, n4, st->pyr[fl], st->w[fl], st->w[fl], st->h[fl], s.img_b);
    home__refine_level_matrix(&s, home__refine_identity, fl, m);
    st->rk->warp(m, tp->x, tp->y, n4, st->pyr[fl], st->w[fl], st->w[fl], st->h[fl], s.img_b2);
    /* one scale for both costs: the estimate's residuals (the identity's would let it excuse
     * itself) */
    home__refine_fit_photometric(&s, tp, s.img_b, s.img_b2, SIGMA_FLOOR * 1e3, s.res, s.wt);
    sigma =
        home__refine_robust_sigma(s.img_b, tp->t, tp->n, s.alpha, s.beta, (int32_t *)(void *)s.wt);
    c = CAUCHY_K * sigma;
    /* each estimate's own gain and bias: moving objects pull the identity's far off the
     * background's, so every region is scored under both and keeps its better one */
    for (e = 0; e < 2; e++) {
        s.alpha = 1.0;
        s.beta = 0.0;
        for (i = 0; i < 2; i++)
            home__refine_fit_photometric(&s, tp, e ? s.img_b2 : s.img_b, e ? s.img_b : s.img_b2,
                                         sigma, s.res, s.wt);
        gain[e] = s.alpha;
        bias[e] = s.beta;
    }
    memset(cost, 0, sizeof cost);
    memset(count, 0, sizeof count);
    grid = region_grid_for(st->w[fl], st->h[fl]);
    for (i = 0; i < tp->n; i++) {
        if (s.img_b[i] < 0.0f || s.img_b2[i] < 0.0f) continue;
        r = region_at(grid, tp->x[i], tp->y[i]);
        count[r]++;
        for (e = 0; e < 2; e++) {
            const double v = e ? s.img_b2[i] : s.img_b[i];
            for (k = 0; k < 2; k++)
                cost[e][k][r] += robust_cost(gain[k] * v + bias[k] - tp->t[i], c);
        }
    }
    for (e = 0; e < 2; e++)
        for (r = 0; r < REGIONS_X * REGIONS_Y; r++)
            best[e][r] = cost[e][0][r] < cost[e][1][r] ? cost[e][0][r] : cost[e][1][r];
    st->unexplained = unexplained_share(best, count);
    for (r = 0; r < REGIONS_X * REGIONS_Y; r++) {
        const double apart = faint[r] ? DECISIVE_GREY_FAINT : DECISIVE_GREY;
        const double ratio = faint[r] ? DECISIVE_RATIO_FAINT : DECISIVE_RATIO;
        if (count[r] < REGION_POINTS) continue;
        cost_h = best[0][r];
        cost_i = best[1][r];
        if (!faint[r]) {
            votes++;
            wins += cost_i < cost_h;
        }
        if (still) still[r] = cost_i < cost_h;
        /* a clear vote: at most half the other's cost, and more than a grey level per point
         * apart (near the identity, or on flat regions, the costs tie) */
        if ((cost_i < cost_h ? cost_i : cost_h) >
                ratio * (cost_i < cost_h ? cost_h : cost_i) ||
            fabs(cost_i - cost_h) <= apart * apart * count[r])
            continue;
        clear_votes++;
        clear_wins += cost_i < cost_h;
    }
    *against = votes - wins;
    *clear_share = clear_votes >= MIN_VOTES ? (double)clear_wins / clear_votes : 0.0;
    return votes >= REGIONS_X * REGIONS_Y / 4 ? (double)wins / votes : 0.0;
}

void home__refine_region_costs(home_context *ctx, int slot, const double *const *hs, int k,
                               double *cost)
{
    const home__refine_state *st = &ctx->refine;
    const home__refine_points *tp = &st->regions[slot];
    const int fl = st->region_level, n4 = (tp->n + LANES - 1) & ~(LANES - 1);
    home__refine_solver s;
    double sigma = 0.0;
    int j, i, valid;
    home__refine_solver_setup(ctx, slot, &s);
    for (j = 0; j < k; j++) {
        double hn[9];
        float m[9];
        cost[j] = INFINITY;
        if (!hs[j]) continue;
        home__refine_to_normalised(&s, hs[j], hn);
        home__refine_level_matrix(&s, hn, fl, m);
        st->rk->warp(m, tp->x, tp->y, n4, st->pyr[fl], st->w[fl], st->w[fl], st->h[fl], s.img_b);
        s.alpha = 1.0;
        s.beta = 0.0;
        if (j == 0) {
            home__refine_fit_photometric(&s, tp, s.img_b, NULL, SIGMA_FLOOR * 1e3, s.res, s.wt);
            sigma = home__refine_robust_sigma(s.img_b, tp->t, tp->n, s.alpha, s.beta,
                                              (int32_t *)(void *)s.wt);
            s.alpha = 1.0;
            s.beta = 0.0;
        }
        for (i = 0; i < 2; i++)
            home__refine_fit_photometric(&s, tp, s.img_b, NULL, sigma, s.res, s.wt);
        cost[j] = 0.0;
        valid = 0;
        for (i = 0; i < tp->n; i++)
            if (s.img_b[i] >= 0.0f) {
                cost[j] += robust_cost(s.res[i], CAUCHY_K * sigma);
                valid++;
            }
        /* mean over the points each keeps in the frame */
        cost[j] = valid ? cost[j] / valid : INFINITY;
    }
}

/* Bilinear sample of a level image at (u, v) inside [0, w-1] x [0, h-1]. */
static double sample(const uint8_t *img, int w, int h, double u, double v)
{
    int x0 = (int)u, y0 = (int)v;
    double fx, fy;
    const uint8_t *p;
    if (x0 > w - 2) x0 = w - 2;
    if (y0 > h - 2) y0 = h - 2;
    fx = u - x0;
    fy = v - y0;
    p = img + (ptrdiff_t)y0 * w + x0;
    return (1.0 - fy) * ((1.0 - fx) * p[0] + fx * p[1]) + fy * ((1.0 - fx) * p[w] + fx * p[w + 1]);
}

static inline uint8_t max_u8(uint8_t a, uint8_t b) { return a > b ? a : b; }

/* Which pixels of a (w x h) are flat: no score of PLAIN_FLAT or more within 2 px (the border's
 * two pixels never). tmp: w x h bytes. Plain loops over rows (the compiler vectorises them). */
static void find_flat(const uint8_t *a, int w, int h, uint8_t *tmp, uint8_t *flat)
{
    int x, y;
    memset(tmp, 255, (size_t)w * (size_t)h);
    for (y = 1; y < h - 1; y++) {
        const uint8_t *p = a + (ptrdiff_t)y * w;
        uint8_t *g = tmp + (ptrdiff_t)y * w;
        for (x = 1; x < w - 1; x++) {
            const int s = abs(p[x + 1] - p[x - 1]) + abs(p[x + w] - p[x - w]);
            g[x] = (uint8_t)(s < 255 ? s : 255);
        }
    }
    /* the largest score of the 5x5 neighbourhood: rows into flat, then columns into tmp */
    memset(flat, 255, (size_t)w * (size_t)h);
    for (y = 0; y < h; y++) {
        const uint8_t *g = tmp + (ptrdiff_t)y * w;
        uint8_t *o = flat + (ptrdiff_t)y * w;
        for (x = 2; x < w - 2; x++)
            o[x] = max_u8(max_u8(max_u8(g[x - 2], g[x - 1]), max_u8(g[x], g[x + 1])), g[x + 2]);
    }
    memset(tmp, 255, (size_t)w * (size_t)h);
    for (y = 2; y < h - 2; y++) {
        const uint8_t *r0 = flat + (ptrdiff_t)(y - 2) * w, *r1 = r0 + w, *r2 = r1 + w;
        const uint8_t *r3 = r2 + w, *r4 = r3 + w;
        uint8_t *o = tmp + (ptrdiff_t)y * w;
        for (x = 0; x < w; x++)
            o[x] = max_u8(max_u8(max_u8(r0[x], r1[x]), max_u8(r2[x], r3[x])), r4[x]);
    }
    for (x = 0; x < w * h; x++) flat[x] = tmp[x] < PLAIN_FLAT;
}

/* Sums over the pixels of frame A's plain regions that h maps into frame B, per estimate (0: h,
 * 1: the identity): for their photometric fits, then the cost differences. */
typedef struct plain_sums {
    double n, t, v[2], vv[2], vt[2];
    double gain[2], bias[2];
    int hist[PLAIN_HIST_BINS + 1];       /* the identity's |residual|, eighths of a grey level */
    double d, d2;
} plain_sums;

/* B at h(x) (m: background pixels) for every flat pixel of a plain region that h maps inside B, in
 * sixteenths of a grey level (-1: not used), and the sums of the two photometric fits. */
static void sample_plain(const home__refine_state *st, int slot, const double *m,
                         int16_t *sampled, plain_sums *acc)
{
    const int w = st->background_w, h = st->background_h;
    const uint8_t *a = st->background[slot], *b = st->background[st->next_slot ^ 1];
    const unsigned char *plain = st->region_plain[slot];
    int x, y, r;
    for (x = 0; x < w * h; x++) sampled[x] = -1;
    for (r = 0; r < REGIONS_X * REGIONS_Y; r++) {
        /* the region's pixels: region_of(x, y) == r exactly where x * REGIONS_X / w == r % X */
        const int rx = r % REGIONS_X, ry = r / REGIONS_X;
        const int x0 = (rx * w + REGIONS_X - 1) / REGIONS_X;
        const int x1 = ((rx + 1) * w + REGIONS_X - 1) / REGIONS_X;
        const int y0 = (ry * h + REGIONS_Y - 1) / REGIONS_Y;
        const int y1 = ((ry + 1) * h + REGIONS_Y - 1) / REGIONS_Y;
        if (!plain[r]) continue;
        for (y = y0; y < y1; y++) {
            for (x = x0; x < x1; x++) {
                const ptrdiff_t i = (ptrdiff_t)y * w + x;
                const double den = m[6] * x + m[7] * y + m[8];
                double u, v, val[2], t;
                int e;
                if (!st->flat[i] || !(den > 1e-9)) continue;
                u = (m[0] * x + m[1] * y + m[2]) / den;
                v = (m[3] * x + m[4] * y + m[5]) / den;
                if (!(u >= 0.0 && v >= 0.0 && u <= w - 1 && v <= h - 1)) continue;
                sampled[i] = (int16_t)floor(16.0 * sample(b, w, h, u, v) + 0.5);
                val[0] = sampled[i] / 16.0;
                val[1] = b[i];
                t = a[i];
                acc->n += 1.0;
                acc->t += t;
                for (e = 0; e < 2; e++) {
                    acc->v[e] += val[e];
                    acc->vv[e] += val[e] * val[e];
                    acc->vt[e] += val[e] * t;
                }
            }
        }
    }
}

void home__refine_background_matrix(const home__refine_state *st, const double *h, double *m)
{
    /* full-size px per background px, and the offset of its centre */
    const double sc = (double)((1 << st->background_level) * st->background_factor);
    const double o = 0.5 * (sc - 1.0);
    const double to_full[9] = {sc, 0, o, 0, sc, o, 0, 0, 1};
    const double to_level[9] = {1.0 / sc, 0, -o / sc, 0, 1.0 / sc, -o / sc, 0, 0, 1};
    double t[9];
    int i, j, k;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            for (t[3 * i + j] = 0.0, k = 0; k < 3; k++)
                t[3 * i + j] += h[3 * i + k] * to_full[3 * k + j];
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            for (m[3 * i + j] = 0.0, k = 0; k < 3; k++)
                m[3 * i + j] += to_level[3 * i + k] * t[3 * k + j];
}

/* The least-squares gain and bias (gain * v + bias ~ t) from the sums over n pixels of v, v^2,
 * v t and t; a gain of 1 where v does not vary. */
static void fit_gain_bias(double n, double sv, double svv, double svt, double st, double *gain,
                          double *bias)
{
    const double var_v = svv - sv * sv / n, cov = svt - sv * st / n;
    *gain = var_v > 1e-9 * n ? cov / var_v : 1.0;
    *bias = (st - *gain * sv) / n;
}

/* rho^2 of background pixel (x, y): 0 at the centre, 1 at the corners */
static double rho2(double x, double y, int w, int h)
{
    const double cx = 0.5 * (w - 1), cy = 0.5 * (h - 1);
    return ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / (cx * cx + cy * cy);
}

/* rho^2 at pixel (x, y) and at its image under m */
static void rho2_pair(const double *m, int x, int y, int w, int h, double *at_x, double *at_hx)
{
    const double den = m[6] * x + m[7] * y + m[8];
    *at_x = rho2(x, y, w, h);
    *at_hx = rho2((m[0] * x + m[1] * y + m[2]) / den, (m[3] * x + m[4] * y + m[5]) / den, w, h);
}

/* s(x) / s(h(x)) for a lens falloff s = 1 - kappa rho^2 fixed to the sensor: what frame B's
 * sample at h(x) is multiplied by to compare with A at x (1 where kappa is 0). */
static double falloff_ratio(const double *m, int x, int y, int w, int h, double kappa)
{
    double ra, rb;
    if (kappa == 0.0) return 1.0;
    rho2_pair(m, x, y, w, h, &ra, &rb);
    return (1.0 - kappa * ra) / (1.0 - kappa * rb);
}

/* The falloff that explains A against B under m over the sampled plain pixels: least squares
 * of A on B's sample, 1, and B's sample times the change of rho^2 under m (kappa over the gain),
 * kappa within [0, PLAIN_KAPPA_MAX]; h's gain and bias are refitted with it. */
static double plain_falloff(const home__refine_state *st, const double *m, const uint8_t *a,
                            double n, double *gain, double *bias)
{
    const int w = st->background_w, h = st->background_h;
    double nrm[64] = {0}, rhs[8] = {0}, kappa, sv = 0.0, svv = 0.0, svt = 0.0, sa = 0.0;
    int i, j, l;
    for (i = 0; i < w * h; i++) {
        double f[3], ra, rb;
        if (st->sampled[i] < 0) continue;
        rho2_pair(m, i % w, i / w, w, h, &ra, &rb);
        f[0] = st->sampled[i] / 16.0;
        f[1] = 1.0;
        f[2] = f[0] * (rb - ra); /* d(s(x) / s(h(x))) / d kappa at kappa = 0 */
        for (j = 0; j < 3; j++) {
            rhs[j] += f[j] * a[i];
            for (l = 0; l < 3; l++) nrm[j * 8 + l] += f[j] * f[l];
        }
    }
    if (!home__solve_spd(nrm, rhs, 3) || !(rhs[0] != 0.0)) return 0.0;
    kappa = rhs[2] / rhs[0];
    if (!(kappa > 0.0)) return 0.0;
    if (kappa > PLAIN_KAPPA_MAX) kappa = PLAIN_KAPPA_MAX;
    for (i = 0; i < w * h; i++) {
        double v;
        if (st->sampled[i] < 0) continue;
        v = st->sampled[i] / 16.0 * falloff_ratio(m, i % w, i / w, w, h, kappa);
        sv += v;
        svv += v * v;
        svt += v * a[i];
        sa += a[i];
    }
    fit_gain_bias(n, sv, svv, svt, sa, gain, bias);
    return kappa;
}

int home__refine_plain_regions(const home_context *ctx, int slot)
{
    int r, n = 0;
    for (r = 0; r < REGIONS_X * REGIONS_Y; r++) n += ctx->refine.region_plain[slot][r] != 0;
    return n;
}

double home__refine_plain_background(home_context *ctx, int slot, const double *h,
                                    int fit_falloff)
{
    const home__refine_state *st = &ctx->refine;
    const int w = st->background_w, hh = st->background_h;
    /* frame B is the one stored last */
    const uint8_t *a = st->background[slot], *b = st->background[st->next_slot ^ 1];
    plain_sums acc;
    double m[9], spread, sigma, c, kappa;
    int e, i, half, cum;
    if (home__refine_plain_regions(ctx, slot) < PLAIN_MIN_PIXELS || w < 2 || hh < 2) return 0.0;
    home__refine_background_matrix(st, h, m);
    find_flat(st->background[slot], w, hh, (uint8_t *)(void *)st->sampled, st->flat);
    memset(&acc, 0, sizeof acc);
    sample_plain(st, slot, m, st->sampled, &acc);
    if (acc.n < PLAIN_MIN_PIXELS * (double)w * hh / (REGIONS_X * REGIONS_Y)) return 0.0;
    /* each estimate's gain and bias (alpha * B + beta ~ A), least squares over the same pixels */
    for (e = 0; e < 2; e++)
        fit_gain_bias(acc.n, acc.v[e], acc.vv[e], acc.vt[e], acc.t, &acc.gain[e], &acc.bias[e]);
    kappa = fit_falloff ? plain_falloff(st, m, a, acc.n, &acc.gain[0], &acc.bias[0]) : 0.0;
    /* one scale for both: the identity's robust residual scale, not below the camera floor */
    for (i = 0; i < w * hh; i++) {
        double r;
        if (st->sampled[i] < 0) continue;
        r = fabs(acc.gain[1] * b[i] + acc.bias[1] - a[i]) * 8.0;
        acc.hist[r < PLAIN_HIST_BINS ? (int)r : PLAIN_HIST_BINS]++;
    }
    half = (int)(acc.n / 2.0);
    for (i = 0, cum = 0; i < PLAIN_HIST_BINS && cum + acc.hist[i] <= half; i++) cum += acc.hist[i];
    sigma = 1.4826 * (i + 0.5) / 8.0;
    if (sigma < SIGMA_FLOOR) sigma = SIGMA_FLOOR;
    c = CAUCHY_K * sigma;
    for (i = 0; i < w * hh; i++) {
        double d;
        if (st->sampled[i] < 0) continue;
        d = robust_cost(acc.gain[0] * (st->sampled[i] / 16.0) *
                                falloff_ratio(m, i % w, i / w, w, hh, kappa) +
                            acc.bias[0] - a[i],
                        c) -
            robust_cost(acc.gain[1] * b[i] + acc.bias[1] - a[i], c);
        acc.d += d;
        acc.d2 += d * d;
    }
    spread = acc.d2 - acc.d * acc.d / acc.n;
    return spread > 0.0 ? acc.d / sqrt(spread) : 0.0;
}
