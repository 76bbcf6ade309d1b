/* Homography from matched Hough keypoints (lines). Lines map by G = H^-T. G is estimated with
 * G22 = 1 in normalised centred coordinates (r divided by the half diagonal, so the 8
 * parameters are O(1)), by the paper's deterministic scheme: start at the identity, take the
 * matches under a threshold as inliers, re-fit by LM, halve the threshold, down to the final one.
 *
 * Transfer error: the paper's (a, b, c)/|(a, b)| - (cos, sin, -r) mixes radians and pixels; the
 * angle components are weighted by theta_bins/pi and the r component by 1/r_step so a residual
 * is measured in Hough bins on both axes and thresholds read as Hough pixels (home-notes.md,
 * finding 1). */
#include "home_internal.h"
#include <math.h>
#include <string.h>

static double det3(const double *m)
{
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
}

/* inverse transpose of a 3x3 matrix: (M^-1)^T = cofactor(M) / det */
static int inverse_transpose(const double *m, double *out)
{
    double d = det3(m);
    int k;
    if (!(fabs(d) > 1e-300) || !isfinite(d)) return 0;
    home__cofactors3(m, out);
    for (k = 0; k < 9; k++) out[k] /= d;
    return 1;
}

static void set_identity(double *h)
{
    int k;
    for (k = 0; k < 9; k++) h[k] = (k % 4 == 0) ? 1.0 : 0.0;
}

int home__homography_plausible(const double *h, int width, int height)
{
    /* the image corners in order (a positive turn at each for the identity) */
    const double xs[4] = {0.0, width - 1.0, width - 1.0, 0.0};
    const double ys[4] = {0.0, 0.0, height - 1.0, height - 1.0};
    const double min_cross = 1e-6 * (width - 1.0) * (height - 1.0);
    double u[4], v[4];
    int k;
    if (!(det3(h) > 0.0)) return 0;
    for (k = 0; k < 4; k++) {
        /* every image corner in front (w > 0): no real motion between frames folds part of the
         * image through infinity */
        const double w = h[6] * xs[k] + h[7] * ys[k] + h[8];
        if (!(w > 0.0)) return 0;
        u[k] = (h[0] * xs[k] + h[1] * ys[k] + h[2]) / w;
        v[k] = (h[3] * xs[k] + h[4] * ys[k] + h[5]) / w;
    }
    /* a convex quadrilateral turning the same way, and not collapsed: each corner's cross
     * product above a millionth of the image's (an orientation-preserving H can still map the
     * frame to a sliver along a line, which is no registration) */
    for (k = 0; k < 4; k++) {
        const int a = (k + 3) % 4, c = (k + 1) % 4;
        const double cross = (u[k] - u[a]) * (v[c] - v[k]) - (v[k] - v[a]) * (u[c] - u[k]);
        if (!(cross > min_cross)) return 0;
    }
    return 1;
}

/* The line fit's residual scale never counts as below this many Hough bins: the extrema's
 * subpixel positions carry their own error, which a handful of lines can understate. */
#define LINE_SIGMA_FLOOR_BINS 0.1
/* Predicted errors are the covariance's times this (calibrated on the evaluation's tuning set:
 * several extrema of one edge are not independent observations). */
#define LINE_SIGMA_SCALE 1.5

/* The line fit restricted to a model's parameters g = o + B q (src/model.c). */
typedef struct subspace_problem {
    const home__line_problem *lp;
    home__normal_fn fn;
    double o[8], basis[8][8];
    int k;
} subspace_problem;

static void subspace_point(const subspace_problem *sp, const double *q, double *g)
{
    int i, j;
    memcpy(g, sp->o, 8 * sizeof *g);
    for (i = 0; i < sp->k; i++)
        for (j = 0; j < 8; j++) g[j] += q[i] * sp->basis[i][j];
}

/* home__lm_solve's problem in q: the lines' normal equations projected (padded coordinates of
 * q beyond k get the identity and no gradient, so they never move) */
static double subspace_normal(const void *user, const double *q, double *jtj, double *jte)
{
    const subspace_problem *sp = (const subspace_problem *)user;
    double g[8], a[64], b[8], cost;
    subspace_point(sp, q, g);
    if (!jtj) return sp->fn(sp->lp, g, NULL, NULL);
    cost = sp->fn(sp->lp, g, a, b);
    home__project_normal(sp->basis, sp->k, a, b, jtj, jte);
    return cost;
}

/* Distinct lines among the inliers (their lines in A): several extrema of one edge are one
 * observation of it, not many. Lines are told apart on a grid of 3 degrees by 3 Hough bins (at
 * least 1/256 of the r range), counted in a bitmap. */
#define DISTINCT_THETA_CELLS 60
#define DISTINCT_R_CELLS 256
static int distinct_lines(const home_context *ctx, const home__line_problem *lp, int n)
{
    uint32_t bits[DISTINCT_THETA_CELLS * DISTINCT_R_CELLS / 32];
    const double r_range = ctx->r_bins * ctx->cfg.r_step * ctx->hough_scale;
    double cell_r = 3.0 * ctx->cfg.r_step * ctx->hough_scale;
    int i, count = 0;
    if (cell_r * DISTINCT_R_CELLS < r_range) cell_r = r_range / DISTINCT_R_CELLS;
    memset(bits, 0, sizeof bits);
    for (i = 0; i < n; i++) {
        const home__match *m = &lp->matches[lp->index[i]];
        int t = (int)(m->theta_a * (DISTINCT_THETA_CELLS / HOME__PI));
        int r = (int)floor((m->r_a + 0.5 * r_range) / cell_r);
        unsigned cell;
        t = t < 0 ? 0 : t >= DISTINCT_THETA_CELLS ? DISTINCT_THETA_CELLS - 1 : t;
        r = r < 0 ? 0 : r >= DISTINCT_R_CELLS ? DISTINCT_R_CELLS - 1 : r;
        cell = (unsigned)(t * DISTINCT_R_CELLS + r);
        if (!(bits[cell / 32] >> (cell % 32) & 1u)) count++;
        bits[cell / 32] |= 1u << (cell % 32);
    }
    return count;
}

/* Model selection over the final inliers (src/model.c): the LM's J^T J over the residual
 * variance (two degrees of freedom per line: its angle and its offset) is the information of g.
 * Writes the chosen model's g, result->model and result->sigma_px (infinite if none is
 * determined). */
static void choose_model(home_context *ctx, home__line_problem *lp, int n_in, double *g,
                         home_result *result)
{
    home__model_problem mp;
    home__model_choice choice;
    double jtj[64], jte[8], cost, var;
    int k, distinct;
    lp->index = ctx->inlier_index;
    lp->n = n_in;
    cost = ctx->kernels->line_fit->normal(lp, g, jtj, jte);
    var = 2 * n_in > 8 ? cost / (2 * n_in - 8) : cost;
    if (!(var >= LINE_SIGMA_FLOOR_BINS * LINE_SIGMA_FLOOR_BINS))
        var = LINE_SIGMA_FLOOR_BINS * LINE_SIGMA_FLOOR_BINS;
    distinct = distinct_lines(ctx, lp, n_in);
    /* n_in observations carry the information of `distinct` independent ones */
    var *= LINE_SIGMA_SCALE * LINE_SIGMA_SCALE * n_in / (distinct > 0 ? distinct : 1);
    mp.space = HOME__SPACE_G;
    mp.floor_px = 0.0;
    memcpy(mp.p, g, sizeof mp.p);
    for (k = 0; k < 64; k++) mp.info[k] = jtj[k] / var;
    mp.penalty = log(2.0 * (distinct > 0 ? distinct : 1));
    mp.max_model = ctx->cfg.max_model;
    mp.rigid = 0;
    mp.max_params = distinct; /* each line fixes two parameters: twice what a model needs */
    mp.scale = lp->scale;
    mp.cx = 0.5 * (ctx->cfg.width - 1);
    mp.cy = 0.5 * (ctx->cfg.height - 1);
    if (!home__select_model(&mp, &choice)) return;
    memcpy(g, choice.p, sizeof choice.p);
    result->model = choice.model;
    result->sigma_px = choice.sigma_px;
}

int home__estimate_homography(home_context *ctx, int n_matches, home_result *result)
{
    const home_config *cfg = &ctx->cfg;
    const double cx = 0.5 * (cfg->width - 1), cy = 0.5 * (cfg->height - 1);
    home__line_problem lp;
    double g[8] = {1, 0, 0, 0, 1, 0, 0, 0};
    double gm[9], hn[9], h[9], t, q[8];
    int n_in = 0, k, level;
    subspace_problem sub;

    lp.matches = ctx->matches;
    lp.index = ctx->inlier_index;
    lp.n = 0;
    lp.scale = sqrt(cx * cx + cy * cy);
    lp.inv_scale = 1.0 / lp.scale;
    lp.w_theta = cfg->theta_bins / HOME__PI;
    lp.w_r = lp.scale / (cfg->r_step * ctx->hough_scale); /* Hough bins of the transform */
    set_identity(result->H);
    result->inliers = 0;
    if (n_matches < 8) { result->failure = HOME_FAIL_FEW_MATCHES; return HOME_OK; }

    /* below a homography, the whole fit runs in the model's parameters: a few lines that leave
     * a homography undetermined still fix a similarity, and no undetermined direction drifts */
    sub.lp = &lp;
    sub.fn = ctx->kernels->line_fit->normal;
    sub.k = home__model_basis(HOME__SPACE_G, cfg->max_model, sub.o, sub.basis);
    for (k = 0; k < 8; k++) {
        double num = 0.0, den = 0.0;
        int j;
        for (j = 0; j < 8 && k < sub.k; j++) {
            num += sub.basis[k][j] * (g[j] - sub.o[j]);
            den += sub.basis[k][j] * sub.basis[k][j];
        }
        q[k] = den > 0.0 ? num / den : 0.0;
    }
    t = cfg->threshold_start;
    for (level = 0; level < HOME_MAX_THRESHOLD_LEVELS; level++) {
        const int iters = t <= cfg->threshold_final ? HOME_LM_MAX_ITERS : HOME_LM_COARSE_ITERS;
        int solved;
        n_in = ctx->kernels->line_fit->select_inliers(&lp, n_matches, g, t, ctx->inlier_index);
        if (n_in < 6) break;               /* too few lines left to constrain 8 parameters */
        /* coarse levels only move the estimate into the next, narrower gate: a few iterations
         * do; the final level converges fully */
        lp.n = n_in;
        if (cfg->max_model == HOME_MODEL_HOMOGRAPHY) {
            solved = home__lm_solve(g, ctx->kernels->line_fit->normal, &lp, iters);
        } else {
            solved = sub.k > 0 && home__lm_solve(q, subspace_normal, &sub, iters);
            subspace_point(&sub, q, g);
        }
        if (!solved) break;
        if (t <= cfg->threshold_final) break;
        t = t * 0.5 > cfg->threshold_final ? t * 0.5 : cfg->threshold_final;
    }
    n_in = ctx->kernels->line_fit->select_inliers(&lp, n_matches, g, cfg->threshold_final,
                                                  ctx->inlier_index);
    result->inliers = n_in;
    result->model = HOME_MODEL_HOMOGRAPHY;
    result->sigma_px = INFINITY;
    if (n_in >= 6) choose_model(ctx, &lp, n_in, g, result);

    /* G (lines, normalised coords) -> H_n = G^-T -> pixel coordinates: H = S^-1 H_n S with
     * S = [1/s 0 -cx/s; 0 1/s -cy/s; 0 0 1]. */
    for (k = 0; k < 8; k++) gm[k] = g[k];
    gm[8] = 1.0;
    if (!inverse_transpose(gm, hn)) { result->failure = HOME_FAIL_DEGENERATE; return HOME_OK; }
    {
        const double s = lp.scale;
        double hs[9];
        /* hs = H_n S */
        for (k = 0; k < 3; k++) {
            hs[k * 3 + 0] = hn[k * 3 + 0] / s;
            hs[k * 3 + 1] = hn[k * 3 + 1] / s;
            hs[k * 3 + 2] = -hn[k * 3 + 0] * cx / s - hn[k * 3 + 1] * cy / s + hn[k * 3 + 2];
        }
        /* h = S^-1 hs, S^-1 = [s 0 cx; 0 s cy; 0 0 1] */
        for (k = 0; k < 3; k++) {
            h[0 * 3 + k] = s * hs[0 * 3 + k] + cx * hs[2 * 3 + k];
            h[1 * 3 + k] = s * hs[1 * 3 + k] + cy * hs[2 * 3 + k];
            h[2 * 3 + k] = hs[2 * 3 + k];
        }
    }
    if (!(fabs(h[8]) > 1e-12) || !isfinite(h[8])) {
        result->failure = HOME_FAIL_DEGENERATE;
        return HOME_OK;
    }
    {
        const double h22 = h[8];
        for (k = 0; k < 9; k++) h[k] /= h22;
    }
    for (k = 0; k < 9; k++)
        if (!isfinite(h[k])) { result->failure = HOME_FAIL_DEGENERATE; return HOME_OK; }
    for (k = 0; k < 9; k++) result->H[k] = h[k];
    if (!home__homography_plausible(h, cfg->width, cfg->height)) {
        result->failure = HOME_FAIL_DEGENERATE;
        return HOME_OK;
    }
    /* a downscaled Hough image's 1-bin gate spans several image px and spurious consistent
     * lines pass it more easily (one moved edge, which fixes 2 of 8 degrees of freedom, gave
     * 11-30 inliers with the video preset against 5-14 at full size): twice min_inliers there */
    if (n_in < cfg->min_inliers * (ctx->hough_scale > 1 ? 2 : 1)) {
        result->failure = HOME_FAIL_FEW_INLIERS;
        return HOME_OK;
    }
    if (!(result->sigma_px <= cfg->max_sigma_px)) {
        result->failure = HOME_FAIL_UNCERTAIN;
        return HOME_OK;
    }
    result->failure = HOME_FAIL_NONE;
    result->ok = 1;
    return HOME_OK;
}
