/* The line fit's arithmetic (port/line_fit_kernels.h), written once: included by
 * port/line_fit_scalar.c (the reference) and port/line_fit_avx2.c, the same source compiled with
 * AVX2 so each four-lane step is one 256-bit operation: element-wise IEEE arithmetic in C99
 * mode (no contraction, no reassociation), so both give the same bits. The includer defines
 * its table from line_normal and select_inliers. */
#ifndef HOME_LINE_FIT_H
#define HOME_LINE_FIT_H
#include "line_fit_kernels.h"
#include <math.h>
#include <string.h>

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
static void line_residuals(const home__line_problem *lp, const home__match *const *m,
                           const double *valid, const double *restrict g, int jacobian,
                           line_lanes *restrict out)
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
static void gather_lanes(const home__line_problem *lp, const int *index, int i, int n,
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
    const home__line_problem *lp = (const home__line_problem *)user;
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
            for (u = 0; u < 3; u++)
                evs[t][u] = (ev[t][u][0] + ev[t][u][1]) + (ev[t][u][2] + ev[t][u][3]);
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

static int select_inliers(const home__line_problem *lp, int n, const double *g, double threshold,
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

#endif
