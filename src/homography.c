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

typedef struct line_problem {
    const home__match *matches;
    const int *index;        /* the inliers the fit runs over */
    int n;
    double scale, inv_scale; /* half diagonal, px: normalises r */
    double w_theta, w_r;     /* residual weights into Hough bins */
} line_problem;

/* Residual e (3 components) of match m at g. With k (may be NULL), the Jacobian in the six
 * numbers it is made of: with l the line in A, rows 0..2 of de/dg are
 * (k0 l, k1 l, 0, 0), (k1 l, k2 l, 0, 0) and (k3 l, k4 l, k5 l0, k5 l1). */
static void line_residual(const line_problem *lp, const home__match *m, const double *g,
                          double *e, double *k)
{
    double l0 = m->cos_a, l1 = m->sin_a;
    double l2 = -(double)m->r_a * lp->inv_scale;
    double a = g[0] * l0 + g[1] * l1 + g[2] * l2;
    double b = g[3] * l0 + g[4] * l1 + g[5] * l2;
    double c = g[6] * l0 + g[7] * l1 + l2;
    double n = sqrt(a * a + b * b), inv_n;
    if (!(n > 1e-12)) n = 1e-12;
    inv_n = 1.0 / n; /* one division: the residual and its Jacobian are latency bound */
    e[0] = lp->w_theta * (a * inv_n - m->cos_b);
    e[1] = lp->w_theta * (b * inv_n - m->sin_b);
    e[2] = lp->w_r * (c * inv_n + (double)m->r_b * lp->inv_scale);
    if (k) {
        const double inv_n3 = inv_n * inv_n * inv_n, wt = lp->w_theta * inv_n3, wr = lp->w_r * inv_n3;
        k[0] = wt * b * b;
        k[1] = -wt * a * b;
        k[2] = wt * a * a;
        k[3] = -wr * c * a;
        k[4] = -wr * c * b;
        k[5] = lp->w_r * inv_n;
    }
}

/* Cost, and J^T J, J^T e over the inliers. J^T J is made of blocks s * l l^T: six symmetric
 * 3x3 sums (36 products per line instead of the 192 of the dense 3x8 Jacobian). */
static double line_normal(const void *user, const double *g, double *jtj, double *jte)
{
    const line_problem *lp = (const line_problem *)user;
    /* blocks: AA, AB, BB (3x3), AC, BC (3x2), CC (2x2) over l l^T's entries 00 01 02 11 12 22 */
    double blk[6][6], ev[3][3], cost = 0.0;
    int i, t, u;
    if (jtj) { memset(blk, 0, sizeof blk); memset(ev, 0, sizeof ev); }
    for (i = 0; i < lp->n; i++) {
        const home__match *m = &lp->matches[lp->index[i]];
        double e[3], k[6];
        line_residual(lp, m, g, e, jtj ? k : NULL);
        cost += e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        if (jtj) {
            const double l[3] = {m->cos_a, m->sin_a, -(double)m->r_a * lp->inv_scale};
            const double ll[6] = {l[0] * l[0], l[0] * l[1], l[0] * l[2],
                                  l[1] * l[1], l[1] * l[2], l[2] * l[2]};
            const double s[6] = {k[0] * k[0] + k[1] * k[1] + k[3] * k[3],
                                 k[0] * k[1] + k[1] * k[2] + k[3] * k[4],
                                 k[1] * k[1] + k[2] * k[2] + k[4] * k[4],
                                 k[3] * k[5], k[4] * k[5], k[5] * k[5]};
            const double ea = k[0] * e[0] + k[1] * e[1] + k[3] * e[2];
            const double eb = k[1] * e[0] + k[2] * e[1] + k[4] * e[2];
            const double ec = k[5] * e[2];
            for (t = 0; t < 6; t++)
                for (u = 0; u < 6; u++) blk[t][u] += s[t] * ll[u];
            for (t = 0; t < 3; t++) { ev[0][t] += ea * l[t]; ev[1][t] += eb * l[t]; ev[2][t] += ec * l[t]; }
        }
    }
    if (jtj) {
        static const int ll_index[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
        for (t = 0; t < 3; t++) {
            for (u = 0; u < 3; u++) {
                const int q = ll_index[t][u];
                jtj[t * 8 + u] = blk[0][q];
                jtj[t * 8 + 3 + u] = jtj[(3 + u) * 8 + t] = blk[1][q];
                jtj[(3 + t) * 8 + 3 + u] = blk[2][q];
            }
            for (u = 0; u < 2; u++) {
                const int q = ll_index[t][u];
                jtj[t * 8 + 6 + u] = jtj[(6 + u) * 8 + t] = blk[3][q];
                jtj[(3 + t) * 8 + 6 + u] = jtj[(6 + u) * 8 + 3 + t] = blk[4][q];
            }
            jte[t] = ev[0][t];
            jte[3 + t] = ev[1][t];
        }
        for (t = 0; t < 2; t++)
            for (u = 0; u < 2; u++) jtj[(6 + t) * 8 + 6 + u] = blk[5][ll_index[t][u]];
        jte[6] = ev[2][0];
        jte[7] = ev[2][1];
    }
    return cost;
}

static int select_inliers(const line_problem *lp, int n, const double *g, double threshold,
                          int *index)
{
    int i, count = 0;
    double t2 = threshold * threshold, e[3];
    for (i = 0; i < n; i++) {
        line_residual(lp, &lp->matches[i], g, e, NULL);
        if (e[0] * e[0] + e[1] * e[1] + e[2] * e[2] < t2) index[count++] = i;
    }
    return count;
}

static double det3(const double *m)
{
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
}

/* inverse transpose of a 3x3 matrix: (M^-1)^T = cofactor(M) / det */
static int inverse_transpose(const double *m, double *out)
{
    double d = det3(m);
    if (!(fabs(d) > 1e-300) || !isfinite(d)) return 0;
    out[0] = (m[4] * m[8] - m[5] * m[7]) / d;
    out[1] = -(m[3] * m[8] - m[5] * m[6]) / d;
    out[2] = (m[3] * m[7] - m[4] * m[6]) / d;
    out[3] = -(m[1] * m[8] - m[2] * m[7]) / d;
    out[4] = (m[0] * m[8] - m[2] * m[6]) / d;
    out[5] = -(m[0] * m[7] - m[1] * m[6]) / d;
    out[6] = (m[1] * m[5] - m[2] * m[4]) / d;
    out[7] = -(m[0] * m[5] - m[2] * m[3]) / d;
    out[8] = (m[0] * m[4] - m[1] * m[3]) / d;
    return 1;
}

static void set_identity(double *h)
{
    int k;
    for (k = 0; k < 9; k++) h[k] = (k % 4 == 0) ? 1.0 : 0.0;
}

int home__estimate_homography(home_context *ctx, int n_matches, home_result *result)
{
    const home_config *cfg = &ctx->cfg;
    const double cx = 0.5 * (cfg->width - 1), cy = 0.5 * (cfg->height - 1);
    line_problem lp;
    double g[8] = {1, 0, 0, 0, 1, 0, 0, 0};
    double gm[9], hn[9], h[9], t;
    int n_in = 0, k, level;

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

    t = cfg->threshold_start;
    for (level = 0; level < HOME_MAX_THRESHOLD_LEVELS; level++) {
        n_in = select_inliers(&lp, n_matches, g, t, ctx->inlier_index);
        if (n_in < 6) break;               /* too few lines left to constrain 8 parameters */
        /* coarse levels only move the estimate into the next, narrower gate: a few iterations
         * do; the final level converges fully */
        lp.n = n_in;
        if (!home__lm_solve(g, line_normal, &lp,
                            t <= cfg->threshold_final ? HOME_LM_MAX_ITERS : HOME_LM_COARSE_ITERS))
            break;
        if (t <= cfg->threshold_final) break;
        t = t * 0.5 > cfg->threshold_final ? t * 0.5 : cfg->threshold_final;
    }
    n_in = select_inliers(&lp, n_matches, g, cfg->threshold_final, ctx->inlier_index);
    result->inliers = n_in;

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
    if (!(fabs(h[8]) > 1e-12) || !isfinite(h[8])) { result->failure = HOME_FAIL_DEGENERATE; return HOME_OK; }
    {
        const double h22 = h[8];
        for (k = 0; k < 9; k++) h[k] /= h22;
    }
    for (k = 0; k < 9; k++)
        if (!isfinite(h[k])) { result->failure = HOME_FAIL_DEGENERATE; return HOME_OK; }
    for (k = 0; k < 9; k++) result->H[k] = h[k];
    if (!(det3(h) > 0.0)) { result->failure = HOME_FAIL_DEGENERATE; return HOME_OK; }
    {
        /* plausibility: every image corner must stay in front (w > 0); a homography that folds
         * part of the frame through infinity is never a real camera motion between frames */
        const double xs[2] = {0.0, cfg->width - 1.0}, ys[2] = {0.0, cfg->height - 1.0};
        int cx_i, cy_i;
        for (cx_i = 0; cx_i < 2; cx_i++)
            for (cy_i = 0; cy_i < 2; cy_i++)
                if (!(h[6] * xs[cx_i] + h[7] * ys[cy_i] + h[8] > 0.0)) {
                    result->failure = HOME_FAIL_DEGENERATE;
                    return HOME_OK;
                }
    }
    /* a downscaled Hough image's 1-bin gate spans several image px and spurious consistent
     * lines pass it more easily (one moved edge, which fixes 2 of 8 degrees of freedom, gave
     * 11-30 inliers with the video preset against 5-14 at full size): twice min_inliers there */
    if (n_in < cfg->min_inliers * (ctx->hough_scale > 1 ? 2 : 1)) {
        result->failure = HOME_FAIL_FEW_INLIERS;
        return HOME_OK;
    }
    result->failure = HOME_FAIL_NONE;
    result->ok = 1;
    return HOME_OK;
}
