/* The static-camera test: does the identity explain the frame's regions better than a
 * motion does? Moving objects are textured and draw HOME's lines and the template points to
 * themselves; every region here has its own points, so a plainer background still votes. */
#include "refine_internal.h"
#include <math.h>
#include <string.h>

#define REGION_POINTS 3      /* a region with fewer points does not vote */
#define DECISIVE_RATIO 0.5   /* a clear vote: the better cost at most this share of the other */
#define DECISIVE_GREY 1.0    /* ... and the two apart by more than this squared per point */
/* A faint region's costs are all small, and noise alone can halve one: its clear vote needs the
 * better cost at most this share of the other, and the two this far apart */
#define DECISIVE_RATIO_FAINT 0.25
#define DECISIVE_GREY_FAINT 0.25
#define MIN_VOTES 6          /* fewer clear votes: no decision (clear_share 0) */

/* Share of the frame's regions (a REGIONS_X x REGIONS_Y grid; those with at least REGION_POINTS
 * of the region points vote) whose points the identity explains better than h (pixels) does:
 * the robust photometric cost of each region under both, each with the better of the two
 * estimates' gain and bias. clear_share: the same over the regions one of them explains
 * clearly better, faint ones included (points below the textured floor: a horizon in fog,
 * which a close vote of noise must not decide but a clear one may). Moving objects are
 * textured and draw the template points (and HOME's lines) to themselves; the static
 * background wins by area. */
double home__refine_identity_share(home_context *ctx, int slot, const double *h,
                                    double *clear_share)
{
    const home__refine_state *st = &ctx->refine;
    double cost[2][2][REGIONS_X * REGIONS_Y], gain[2], bias[2], hn[9], sigma, c, cost_h, cost_i;
    int count[REGIONS_X * REGIONS_Y], e, i, k, r, votes = 0;
    int wins = 0, clear_votes = 0, clear_wins = 0, fl, n4;
    const unsigned char *faint = st->region_faint[slot]; /* frame A's, as its points */
    const home__refine_points *tp;
    float m[9];
    home__refine_solver s;
    *clear_share = 0.0;
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
    for (i = 0; i < tp->n; i++) {
        if (s.img_b[i] < 0.0f || s.img_b2[i] < 0.0f) continue;
        r = region_of(tp->x[i], tp->y[i], st->w[fl], st->h[fl]);
        count[r]++;
        for (e = 0; e < 2; e++) {
            const double v = e ? s.img_b2[i] : s.img_b[i];
            for (k = 0; k < 2; k++)
                cost[e][k][r] += robust_cost(gain[k] * v + bias[k] - tp->t[i], c);
        }
    }
    for (r = 0; r < REGIONS_X * REGIONS_Y; r++) {
        const double apart = faint[r] ? DECISIVE_GREY_FAINT : DECISIVE_GREY;
        const double ratio = faint[r] ? DECISIVE_RATIO_FAINT : DECISIVE_RATIO;
        if (count[r] < REGION_POINTS) continue;
        cost_h = cost[0][0][r] < cost[0][1][r] ? cost[0][0][r] : cost[0][1][r];
        cost_i = cost[1][0][r] < cost[1][1][r] ? cost[1][0][r] : cost[1][1][r];
        if (!faint[r]) {
            votes++;
            wins += cost_i < cost_h;
        }
        /* a clear vote: at most half the other's cost, and more than a grey level per point
         * apart (near the identity, or on flat regions, the costs tie) */
        if ((cost_i < cost_h ? cost_i : cost_h) >
                ratio * (cost_i < cost_h ? cost_h : cost_i) ||
            fabs(cost_i - cost_h) <= apart * apart * count[r])
            continue;
        clear_votes++;
        clear_wins += cost_i < cost_h;
    }
    *clear_share = clear_votes >= MIN_VOTES ? (double)clear_wins / clear_votes : 0.0;
    return votes >= REGIONS_X * REGIONS_Y / 4 ? (double)wins / votes : 0.0;
}
