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

/* The fit runs over FIT_LANES matches at a time: each lane is one line's arithmetic and has its
 * own partial sums, added in a fixed order at the end, so the result is the same on every
 * target; written as loops over lanes, which the compiler turns into vector arithmetic. */
#define FIT_LANES 4 /* the final sums combine exactly four lanes: (0 + 1) + (2 + 3) */

typedef struct line_lanes {
    double e[3][FIT_LANES];  /* residual, Hough bins */
    double k[6][FIT_LANES];  /* the Jacobian's numbers (see line_residuals) */
    double l[3][FIT_LANES];  /* the line in A, normalised */
} line_lanes;

/* Residuals e (3 components) of matches m[0..FIT_LANES) at g; lanes with valid 0 get e = k = 0.
 * With jacobian, also the numbers de/dg is made of: with l the line in A, rows 0..2 of de/dg
 * are (k0 l, k1 l, 0, 0), (k1 l, k2 l, 0, 0) and (k3 l, k4 l, k5 l0, k5 l1). */
static void line_residuals(const line_problem *lp, const home__match *const *m, const double *valid,
                           const double *restrict g, int jacobian, line_lanes *restrict out)
{
    double a[FIT_LANES], b[FIT_LANES], c[FIT_LANES], inv_n[FIT_LANES], cb[FIT_LANES],
        sb[FIT_LANES], rb[FIT_LANES];
    int j;
    for (j = 0; j < FIT_LANES; j++) {
        out->l[0][j] = m[j]->cos_a;
        out->l[1][j] = m[j]->sin_a;
        out->l[2][j] = -(double)m[j]->r_a * lp->inv_scale;
        cb[j] = m[j]->cos_b;
        sb[j] = m[j]->sin_b;
        rb[j] = (double)m[j]->r_b * lp->inv_scale;
    }
    for (j = 0; j < FIT_LANES; j++) {
        const double l0 = out->l[0][j], l1 = out->l[1][j], l2 = out->l[2][j];
        double n;
        a[j] = g[0] * l0 + g[1] * l1 + g[2] * l2;
        b[j] = g[3] * l0 + g[4] * l1 + g[5] * l2;
        c[j] = g[6] * l0 + g[7] * l1 + l2;
        n = sqrt(a[j] * a[j] + b[j] * b[j]);
        n = n > 1e-12 ? n : 1e-12; /* NaN too */
        inv_n[j] = valid[j] / n;
        out->e[0][j] = lp->w_theta * (a[j] * inv_n[j] - valid[j] * cb[j]);
        out->e[1][j] = lp->w_theta * (b[j] * inv_n[j] - valid[j] * sb[j]);
        out->e[2][j] = lp->w_r * (c[j] * inv_n[j] + valid[j] * rb[j]);
    }
    if (!jacobian) return;
    for (j = 0; j < FIT_LANES; j++) {
        /* valid^3 = valid: the masked lanes stay zero */
        const double inv_n3 = inv_n[j] * inv_n[j] * inv_n[j];
        const double wt = lp->w_theta * inv_n3, wr = lp->w_r * inv_n3;
        out->k[0][j] = wt * b[j] * b[j];
        out->k[1][j] = -wt * a[j] * b[j];
        out->k[2][j] = wt * a[j] * a[j];
        out->k[3][j] = -wr * c[j] * a[j];
        out->k[4][j] = -wr * c[j] * b[j];
        out->k[5][j] = lp->w_r * inv_n[j];
    }
}

/* The matches of lanes starting at position i of the fit's inlier list (index) or of all
 * matches (index NULL), n in total; lanes past the end repeat the last match with valid 0. */
static void gather_lanes(const line_problem *lp, const int *index, int i, int n,
                         const home__match **m, double *valid)
{
    int j;
    for (j = 0; j < FIT_LANES; j++) {
        const int q = i + j < n ? i + j : n - 1;
        m[j] = &lp->matches[index ? index[q] : q];
        valid[j] = i + j < n ? 1.0 : 0.0;
    }
}

/* Cost, and J^T J, J^T e over the inliers. J^T J is made of blocks s * l l^T: six symmetric
 * 3x3 sums (36 products per line instead of the 192 of the dense 3x8 Jacobian). */
static double line_normal(const void *user, const double *g, double *jtj, double *jte)
{
    const line_problem *lp = (const line_problem *)user;
    /* blocks: AA, AB, BB (3x3), AC, BC (3x2), CC (2x2) over l l^T's entries 00 01 02 11 12 22 */
    double blk[6][6][FIT_LANES], ev[3][3][FIT_LANES], cost[FIT_LANES];
    int i, j, t, u;
    memset(cost, 0, sizeof cost);
    if (jtj) { memset(blk, 0, sizeof blk); memset(ev, 0, sizeof ev); }
    for (i = 0; i < lp->n; i += FIT_LANES) {
        const home__match *m[FIT_LANES];
        double valid[FIT_LANES];
        line_lanes r;
        gather_lanes(lp, lp->index, i, lp->n, m, valid);
        line_residuals(lp, m, valid, g, jtj != NULL, &r);
        for (j = 0; j < FIT_LANES; j++)
            cost[j] += r.e[0][j] * r.e[0][j] + r.e[1][j] * r.e[1][j] + r.e[2][j] * r.e[2][j];
        if (jtj) {
            double ll[6][FIT_LANES], s[6][FIT_LANES], ea[FIT_LANES], eb[FIT_LANES], ec[FIT_LANES];
            for (j = 0; j < FIT_LANES; j++) {
                const double *k0 = r.k[0], *k1 = r.k[1], *k2 = r.k[2], *k3 = r.k[3], *k4 = r.k[4],
                             *k5 = r.k[5];
                ll[0][j] = r.l[0][j] * r.l[0][j];
                ll[1][j] = r.l[0][j] * r.l[1][j];
                ll[2][j] = r.l[0][j] * r.l[2][j];
                ll[3][j] = r.l[1][j] * r.l[1][j];
                ll[4][j] = r.l[1][j] * r.l[2][j];
                ll[5][j] = r.l[2][j] * r.l[2][j];
                s[0][j] = k0[j] * k0[j] + k1[j] * k1[j] + k3[j] * k3[j];
                s[1][j] = k0[j] * k1[j] + k1[j] * k2[j] + k3[j] * k4[j];
                s[2][j] = k1[j] * k1[j] + k2[j] * k2[j] + k4[j] * k4[j];
                s[3][j] = k3[j] * k5[j];
                s[4][j] = k4[j] * k5[j];
                s[5][j] = k5[j] * k5[j];
                ea[j] = k0[j] * r.e[0][j] + k1[j] * r.e[1][j] + k3[j] * r.e[2][j];
                eb[j] = k1[j] * r.e[0][j] + k2[j] * r.e[1][j] + k4[j] * r.e[2][j];
                ec[j] = k5[j] * r.e[2][j];
            }
            for (t = 0; t < 6; t++)
                for (u = 0; u < 6; u++)
                    for (j = 0; j < FIT_LANES; j++) blk[t][u][j] += s[t][j] * ll[u][j];
            for (t = 0; t < 3; t++)
                for (j = 0; j < FIT_LANES; j++) {
                    ev[0][t][j] += ea[j] * r.l[t][j];
                    ev[1][t][j] += eb[j] * r.l[t][j];
                    ev[2][t][j] += ec[j] * r.l[t][j];
                }
        }
    }
    if (jtj) {
        static const int ll_index[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
        double sum[6][6], evs[3][3];
        for (t = 0; t < 6; t++)
            for (u = 0; u < 6; u++)
                sum[t][u] = (blk[t][u][0] + blk[t][u][1]) + (blk[t][u][2] + blk[t][u][3]);
        for (t = 0; t < 3; t++)
            for (u = 0; u < 3; u++) evs[t][u] = (ev[t][u][0] + ev[t][u][1]) + (ev[t][u][2] + ev[t][u][3]);
        for (t = 0; t < 3; t++) {
            for (u = 0; u < 3; u++) {
                const int q = ll_index[t][u];
                jtj[t * 8 + u] = sum[0][q];
                jtj[t * 8 + 3 + u] = jtj[(3 + u) * 8 + t] = sum[1][q];
                jtj[(3 + t) * 8 + 3 + u] = sum[2][q];
            }
            for (u = 0; u < 2; u++) {
                const int q = ll_index[t][u];
                jtj[t * 8 + 6 + u] = jtj[(6 + u) * 8 + t] = sum[3][q];
                jtj[(3 + t) * 8 + 6 + u] = jtj[(6 + u) * 8 + 3 + t] = sum[4][q];
            }
            jte[t] = evs[0][t];
            jte[3 + t] = evs[1][t];
        }
        for (t = 0; t < 2; t++)
            for (u = 0; u < 2; u++) jtj[(6 + t) * 8 + 6 + u] = sum[5][ll_index[t][u]];
        jte[6] = evs[2][0];
        jte[7] = evs[2][1];
    }
    return (cost[0] + cost[1]) + (cost[2] + cost[3]);
}

static int select_inliers(const line_problem *lp, int n, const double *g, double threshold,
                          int *index)
{
    int i, j, count = 0;
    const double t2 = threshold * threshold;
    for (i = 0; i < n; i += FIT_LANES) {
        const home__match *m[FIT_LANES];
        double valid[FIT_LANES];
        line_lanes r;
        gather_lanes(lp, NULL, i, n, m, valid);
        line_residuals(lp, m, valid, g, 0, &r);
        for (j = 0; j < FIT_LANES && i + j < n; j++)
            if (r.e[0][j] * r.e[0][j] + r.e[1][j] * r.e[1][j] + r.e[2][j] * r.e[2][j] < t2)
                index[count++] = i + j;
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
