/* Dense direct alignment for frames too faint for template points: a few slow shading waves, a
 * soft shadow, a gentle ridge. Their gradients stay under the noise floor of every pyramid
 * level's point selection, yet summed over all pixels of a coarse image they can determine a
 * small motion well (docs/trust.md, session 20).
 *
 * Method: inverse-compositional Gauss-Newton of the most general motion cfg.max_model allows
 * (refine.c calls it with a homography: a similarity fitted to a perspective motion is wrong
 * with a small predicted error) on the two slots' background16 images (quarter size, at most
 * HOME__BACKGROUND_PIXELS, in sixteenths of a grey level) and two 2x2 means of them, coarse to
 * fine from the coarsest image's best whole-pixel shift, every interior pixel a template
 * point; a gain and bias and Cauchy weights as in the refinement, and a lens's shading: a
 * falloff 1 + kappa |x|^2 fixed to the sensor, which a still pattern the scene does not share
 * would otherwise pull towards no motion. The predicted error comes from J^T W J without the
 * apparent information of the template's gradient noise and of what the gain, shading and bias
 * explain, through the same model selection as the refinement's: the larger
 * of its homoscedastic prediction and the sandwich with the scores summed over blocks of
 * pixels (residuals that are not independent: an edge the motion model does not quite fit,
 * blur that differs between frames). */
#include "refine_internal.h"
#include <math.h>
#include <string.h>

#define DENSE_LEVELS 3          /* the background image and two 2x2 means of it */
#define DENSE_MIN_SIDE 12       /* a coarser image than this a side is not made */
#define DENSE_SEARCH 4          /* the coarsest level's shifts tried first, level px either way */
#define DENSE_SEARCH_OVERLAP 2  /* ... where at least 1 / this of its pixels overlap */
#define DENSE_ITERATIONS 15     /* per level: one that does not converge ends the alignment */
#define DENSE_STEP_EPS 0.01     /* convergence: largest corner update, level px */
#define DENSE_HIST_BINS 256     /* |residual| histogram: 1/32 grey level per bin */
#define DENSE_SIGMA_FLOOR 0.1   /* grey levels: coarse images average the noise away */
#define DENSE_MAX_SHADING 1.0   /* |kappa| at most: lens shading of 1 + kappa |x|^2 (|x| = 1 half
                                   the longer side from the centre); a fit beyond it is not
                                   taken */
#define CLUSTER_SIDE 8          /* the covariance's blocks of pixels, finest dense level */
#define DENSE_MAX_CLUSTERS 32   /* block columns at most (wider images share the last) */
/* var(g) of a central difference over 2 is half a pixel's noise variance; the residual holds
 * frame A's noise and B's interpolated at a fractional position, its variance times the sum of
 * the bilinear weights squared (4/9 on average): 0.5 / (1 + 4/9) of the residual variance (an
 * integer shift's 0.25 let a single smooth blob's unseen turn about its centre look determined:
 * docs/trust.md, session 23) */
#define DENSE_GRADIENT_NOISE_SHARE 0.35

typedef struct dense_level {
    const uint16_t *a, *b;
    int w, h;
    double unit;                /* grey levels per stored unit */
    double scale, offset;       /* full-size x = scale * x_level + offset */
} dense_level;

typedef struct dense_solver {
    const home_context *ctx;
    double f, cx, cy;           /* normalisation, as the refinement's */
    double hn[9];               /* A -> B, normalised */
    double alpha, kappa, beta;  /* B's gain alpha (1 + kappa q) and bias; q = |x|^2 - |hn x|^2
                                   (normalised): lens shading fixed to the sensor, 1 + kappa
                                   |x|^2 at x, as it reaches the pixel A shows at x and B at
                                   hn x */
    int k;                      /* parameters of the model fitted */
    double gen[8][8];           /* their generators: update dq -> W = I + sum q_i gen_i (the
                                   homography's entries h0..h7) */
    int plain;                  /* gen is the identity (a homography or an affine motion) */
} dense_solver;

/* 2x2 sums of src (w x h) into dst (w/2 x h/2), rounded to `shift` bits fewer. */
static void halve(const uint16_t *src, int w, int h, uint16_t *dst, int shift)
{
    const int w2 = w / 2, h2 = h / 2, round = shift ? 1 << (shift - 1) : 0;
    int x, y;
    for (y = 0; y < h2; y++) {
        const uint16_t *r0 = src + (ptrdiff_t)(2 * y) * w, *r1 = r0 + w;
        for (x = 0; x < w2; x++)
            dst[(ptrdiff_t)y * w2 + x] = (uint16_t)(
                (r0[2 * x] + r0[2 * x + 1] + r1[2 * x] + r1[2 * x + 1] + round) >> shift);
    }
}

/* The level's pixel of A as B's level coordinates under s->hn: m (3x3). */
static void level_matrix(const dense_solver *s, const dense_level *lv, double *m)
{
    home__refine_scaled_matrix(s->f, s->cx, s->cy, s->hn, lv->scale, lv->offset, m);
}

/* Bilinear sample of B at (x, y), grey levels; 0 outside (the caller skips it). */
static int sample(const dense_level *lv, double x, double y, double *out)
{
    int ix, iy;
    double fx, fy;
    const uint16_t *p;
    if (!(x >= 0.0 && y >= 0.0 && x < lv->w - 1 && y < lv->h - 1)) return 0;
    ix = (int)x;
    iy = (int)y;
    fx = x - ix;
    fy = y - iy;
    p = lv->b + (ptrdiff_t)iy * lv->w + ix;
    *out = lv->unit * ((1.0 - fy) * ((1.0 - fx) * p[0] + fx * p[1]) +
                       fy * ((1.0 - fx) * p[lv->w] + fx * p[lv->w + 1]));
    return 1;
}

static double cauchy_weight(double r, double sigma)
{
    const double q = r / (CAUCHY_K * sigma);
    return 1.0 / (1.0 + q * q);
}

/* The pixel's row of J (k entries: the template's gradient times the warp's derivatives by
 * the model's parameters, normalised units) and those derivatives (x, y); returns the squared
 * magnitude of that gradient. */
static double pixel_jacobian(const dense_solver *s, const dense_level *lv, const uint16_t *ra,
                           int x, double v, double *jr, double *ddx, double *ddy)
{
    const double k = s->f / lv->scale; /* level px per normalised unit */
    const double u = (lv->scale * x + lv->offset - s->cx) / s->f;
    const double gx = 0.5 * lv->unit * (ra[x + 1] - ra[x - 1]) * k;
    const double gy = 0.5 * lv->unit * ((double)ra[x + lv->w] - ra[x - lv->w]) * k;
    /* the warp's derivatives by h0..h7 at the identity, x then y */
    const double dx[8] = {u, v, 1.0, 0.0, 0.0, 0.0, -u * u, -u * v};
    const double dy[8] = {0.0, 0.0, 0.0, u, v, 1.0, -u * v, -v * v};
    int i, e;
    for (i = 0; i < s->k; i++) {
        if (s->plain) { /* the generators are the entries themselves: the same sums */
            ddx[i] = dx[i];
            ddy[i] = dy[i];
            jr[i] = gx * ddx[i] + gy * ddy[i];
            continue;
        }
        ddx[i] = ddy[i] = 0.0;
        for (e = 0; e < 8; e++) {
            ddx[i] += s->gen[i][e] * dx[e];
            ddy[i] += s->gen[i][e] * dy[e];
        }
        jr[i] = gx * ddx[i] + gy * ddy[i];
    }
    return gx * gx + gy * gy;
}

/* The level's pixel (x, y) of A in B under m (level_matrix()): B's bilinear sample there (b)
 * and the lens shading term q = |x|^2 - |x_b|^2 in normalised units; 0 where it falls outside
 * B. */
static int warped(const dense_solver *s, const dense_level *lv, const double *m, int x, int y,
                  double *b, double *q)
{
    const double z = m[6] * x + m[7] * y + m[8];
    double bx, by, ua, va, ub, vb;
    if (!(z > 0.0)) return 0;
    bx = (m[0] * x + m[1] * y + m[2]) / z;
    by = (m[3] * x + m[4] * y + m[5]) / z;
    if (!sample(lv, bx, by, b)) return 0;
    ua = (lv->scale * x + lv->offset - s->cx) / s->f;
    va = (lv->scale * y + lv->offset - s->cy) / s->f;
    ub = (lv->scale * bx + lv->offset - s->cx) / s->f;
    vb = (lv->scale * by + lv->offset - s->cy) / s->f;
    *q = ua * ua + va * va - ub * ub - vb * vb;
    return 1;
}

/* B's sample b as the model predicts A there: gain, lens shading (q: warped()) and bias. */
static double predicted(const dense_solver *s, double b, double q)
{
    return s->alpha * (1.0 + s->kappa * q) * b + s->beta;
}

/* One pass over the level's interior pixels under s->hn. mode 0: the |residual| histogram;
 * 1: the weighted sums of the photometric fit (sums[9]: P^T W P, upper triangle by rows, and
 * P^T W a, P = [B, q B, 1]); 2: the lower triangle of J^T W J
 * (jtj, k x k, row stride 8; what the solve reads), J^T W r and the sums of w and w r^2;
 * 3: the whole J^T W J, J^T W r, those sums, the gradient noise's sum w D^T D (noise), the
 * correlation's sums (corr[6] of w, w a, w b', w a^2, w b'^2, w a b'), J's weighted sums
 * against the photometric parameters' derivatives (cross[24]: w J a, w J q a, w J; B taken as
 * A, which it matches at the optimum) and theirs (pp, 3 x 3, row stride 8), and where the
 * information on a shift sits (spread[2]: the sums of w |grad A|^2 and of its square).
 * Returns the pixels used. */
static int pass(const dense_solver *s, const dense_level *lv, int mode, double sigma,
                int32_t *hist, double *sums, double *jtj, double *jtr, double *noise,
                double *corr, double *cross, double *pp, double *spread)
{
    double m[9];
    const double k = s->f / lv->scale; /* level px per normalised unit */
    int x, y, i, j, p, n = 0;
    level_matrix(s, lv, m);
    for (y = 1; y < lv->h - 1; y++) {
        const uint16_t *ra = lv->a + (ptrdiff_t)y * lv->w;
        const double v = (lv->scale * y + lv->offset - s->cy) / s->f;
        for (x = 1; x < lv->w - 1; x++) {
            const double a = lv->unit * ra[x];
            double q, b, r, w;
            if (!warped(s, lv, m, x, y, &b, &q)) continue;
            n++;
            r = predicted(s, b, q) - a;
            if (mode == 0) { /* (NaN or beyond the last bin: the last bin) */
                const double bin = fabs(r) * 32.0;
                hist[bin < DENSE_HIST_BINS - 1 ? (int)bin : DENSE_HIST_BINS - 1]++;
                continue;
            }
            w = cauchy_weight(r, sigma);
            if (mode == 1) {
                const double pr[3] = {b, q * b, 1.0};
                for (i = 0, p = 0; i < 3; i++) {
                    for (j = i; j < 3; j++) sums[p++] += w * pr[i] * pr[j];
                    sums[6 + i] += w * pr[i] * a;
                }
            } else {
                double jr[8], ddx[8], ddy[8];
                const double g2 = w * pixel_jacobian(s, lv, ra, x, v, jr, ddx, ddy);
                if (mode == 3) { /* where the information on a shift sits */
                    spread[0] += g2;
                    spread[1] += g2 * g2;
                }
                for (i = 0; i < s->k; i++) { /* mode 2: the lower triangle the solve reads */
                    const int columns = mode == 2 ? i + 1 : s->k;
                    jtr[i] += w * jr[i] * r;
                    for (j = 0; j < columns; j++) jtj[i * 8 + j] += w * jr[i] * jr[j];
                }
                sums[0] += w;
                sums[1] += w * r * r;
                if (mode == 2) continue;
                {
                    const double pa[3] = {a, q * a, 1.0};
                    for (i = 0; i < s->k; i++) {
                        for (j = 0; j < 3; j++) /* J against the photometric parameters' */
                            cross[8 * j + i] += w * jr[i] * pa[j];
                        for (j = 0; j < s->k; j++)
                            noise[i * 8 + j] += w * k * k * (ddx[i] * ddx[j] + ddy[i] * ddy[j]);
                    }
                    for (i = 0; i < 3; i++)
                        for (j = 0; j < 3; j++) pp[i * 8 + j] += w * pa[i] * pa[j];
                }
                b = predicted(s, b, q);
                corr[0] += w;
                corr[1] += w * a;
                corr[2] += w * b;
                corr[3] += w * a * a;
                corr[4] += w * b * b;
                corr[5] += w * a * b;
            }
        }
    }
    return n;
}

/* The scores' spread, clustered: sum over blocks of CLUSTER_SIDE^2 pixels of (sum w r J)
 * (sum w r J)^T (k x k, row stride 8). Residuals that are not independent from pixel to pixel
 * (an edge the model does not quite fit, blur that differs between the frames) add up within
 * a block, so the covariance (J^T W J)^-1 meat (J^T W J)^-1 sees them. */
static void cluster_meat(const dense_solver *s, const dense_level *lv, double sigma,
                         double *meat)
{
    double m[9], score[DENSE_MAX_CLUSTERS][8];
    const int columns = (lv->w + CLUSTER_SIDE - 1) / CLUSTER_SIDE;
    int x, y, i, j, c;
    level_matrix(s, lv, m);
    memset(meat, 0, 64 * sizeof *meat);
    memset(score, 0, sizeof score);
    for (y = 1; y < lv->h - 1; y++) {
        const uint16_t *ra = lv->a + (ptrdiff_t)y * lv->w;
        const double v = (lv->scale * y + lv->offset - s->cy) / s->f;
        for (x = 1; x < lv->w - 1; x++) {
            const double a = lv->unit * ra[x];
            double b, q, r, w, jr[8], ddx[8], ddy[8];
            double *sc = score[x / CLUSTER_SIDE < DENSE_MAX_CLUSTERS ? x / CLUSTER_SIDE
                                                                      : DENSE_MAX_CLUSTERS - 1];
            if (!warped(s, lv, m, x, y, &b, &q)) continue;
            r = predicted(s, b, q) - a;
            w = cauchy_weight(r, sigma);
            pixel_jacobian(s, lv, ra, x, v, jr, ddx, ddy);
            for (i = 0; i < s->k; i++) sc[i] += w * r * jr[i];
        }
        if (y % CLUSTER_SIDE == CLUSTER_SIDE - 1 || y == lv->h - 2) {
            for (c = 0; c < columns && c < DENSE_MAX_CLUSTERS; c++) {
                for (i = 0; i < s->k; i++)
                    for (j = 0; j < s->k; j++) meat[i * 8 + j] += score[c][i] * score[c][j];
            }
            memset(score, 0, sizeof score);
        }
    }
}

/* Robust scale of the residuals: 1.4826 x their median magnitude. */
static double robust_sigma(const dense_solver *s, const dense_level *lv, int32_t *hist)
{
    int n, i, seen = 0;
    memset(hist, 0, DENSE_HIST_BINS * sizeof *hist);
    n = pass(s, lv, 0, 0.0, hist, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL);
    for (i = 0; i < DENSE_HIST_BINS; i++) {
        seen += hist[i];
        if (2 * seen >= n) break;
    }
    return 1.4826 * (i + 0.5) / 32.0 > DENSE_SIGMA_FLOOR ? 1.4826 * (i + 0.5) / 32.0
                                                           : DENSE_SIGMA_FLOOR;
}

/* W = I + sum dq_i gen_i (3x3). */
static void update_matrix(const dense_solver *s, const double *dq, double *w)
{
    int i, e;
    for (e = 0; e < 9; e++) w[e] = e % 4 == 0 ? 1.0 : 0.0;
    for (i = 0; i < s->k; i++)
        for (e = 0; e < 8; e++) w[e] += dq[i] * s->gen[i][e];
}

/* hn <- hn W(dq)^-1; 0 when W is singular. */
static int compose_inverse(dense_solver *s, const double *dq)
{
    double w[9], inv[9] = {0}, out[9] = {0};
    int e;
    update_matrix(s, dq, w);
    if (!home__refine_mat3_inv(w, inv)) return 0;
    home__refine_mat3_mul(s->hn, inv, out);
    if (!(fabs(out[8]) > 1e-12)) return 0;
    for (e = 0; e < 9; e++) s->hn[e] = out[e] / out[8];
    return 1;
}

/* Largest corner displacement of the update dq, level px. */
static double step_px(const dense_solver *s, const dense_level *lv, const double *dq)
{
    const double hu = s->cx / s->f, hv = s->cy / s->f;
    double w[9], worst = 0.0;
    int c;
    update_matrix(s, dq, w);
    for (c = 0; c < 4; c++) {
        const double u = (c & 1) ? hu : -hu, v = (c & 2) ? hv : -hv;
        const double z = w[6] * u + w[7] * v + w[8];
        const double dx = (w[0] * u + w[1] * v + w[2]) / z - u;
        const double dy = (w[3] * u + w[4] * v + w[5]) / z - v;
        const double d = sqrt(dx * dx + dy * dy);
        if (!(d <= worst)) worst = d;
    }
    return worst * s->f / lv->scale;
}

/* k x k solve (row stride 8); 0 when not positive definite. */
static int solve_k(const double *a8, const double *b, int k, double *x)
{
    double a[64], l[8];
    int i, j;
    for (i = 0; i < 8; i++) {
        for (j = 0; j < 8; j++) a[i * 8 + j] = i < k && j < k ? a8[i * 8 + j] : (i == j);
        l[i] = i < k ? b[i] : 0.0;
    }
    if (!home__cholesky8(a)) return 0;
    home__cholesky_solve8(a, l);
    for (i = 0; i < k; i++) x[i] = l[i];
    return 1;
}

typedef struct dense_fit {
    double jtj[64], jtr[8], noise[64], corr[6], cross[24], pp[64], spread[2], sum_w, sum_wr2;
    double sigma;
    int n;
} dense_fit;

/* One Gauss-Newton iteration at the level: the residuals' scale (rescale: anew, else
 * fit->sigma's), gain, shading and bias, then the normal equations (into fit; full: with the
 * statistics of the estimate's prediction, pass() mode 3). 0 when too few pixels overlap. */
static int iterate(dense_solver *s, const dense_level *lv, int32_t *hist, int rescale, int full,
                   dense_fit *fit)
{
    double sums[9] = {0}, a8[64], q[3];
    int i, j, p;
    if (rescale) fit->sigma = robust_sigma(s, lv, hist);
    if (pass(s, lv, 1, fit->sigma, NULL, sums, NULL, NULL, NULL, NULL, NULL, NULL, NULL) <
        MIN_POINTS)
        return 0;
    /* gain, shading and bias: least squares (kept as they were where singular: flat B) */
    for (i = 0, p = 0; i < 3; i++)
        for (j = i; j < 3; j++, p++) a8[i * 8 + j] = a8[j * 8 + i] = sums[p];
    if (solve_k(a8, sums + 6, 3, q) && q[0] > 0.0 && fabs(q[1]) <= DENSE_MAX_SHADING * q[0]) {
        s->alpha = q[0];
        s->kappa = q[1] / q[0];
        s->beta = q[2];
    }
    {
        const double sigma = fit->sigma;
        memset(fit, 0, sizeof *fit);
        fit->sigma = sigma;
    }
    {
        double pair[2] = {0.0, 0.0};
        fit->n = pass(s, lv, full ? 3 : 2, fit->sigma, NULL, pair, fit->jtj, fit->jtr, fit->noise,
                      fit->corr, fit->cross, fit->pp, fit->spread);
        fit->sum_w = pair[0];
        fit->sum_wr2 = pair[1];
    }
    return fit->n >= MIN_POINTS;
}

/* The start: the whole-pixel shift of the coarsest level within DENSE_SEARCH either way whose
 * overlap correlates best (gain and bias free), as a translation in s->hn; its length in
 * level px returned. Gauss-Newton from the identity reaches about a pixel of that level; a
 * still pair of smooth shading moves farther. */
static double coarse_shift(dense_solver *s, const dense_level *lv)
{
    double best = -2.0;
    int dx, dy, bx = 0, by = 0, x, y;
    for (dy = -DENSE_SEARCH; dy <= DENSE_SEARCH; dy++)
        for (dx = -DENSE_SEARCH; dx <= DENSE_SEARCH; dx++) {
            const int x0 = dx < 0 ? -dx : 0, x1 = dx > 0 ? lv->w - dx : lv->w;
            const int y0 = dy < 0 ? -dy : 0, y1 = dy > 0 ? lv->h - dy : lv->h;
            double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, n, va, vb, r;
            if (DENSE_SEARCH_OVERLAP * (x1 - x0) * (y1 - y0) < lv->w * lv->h) continue;
            for (y = y0; y < y1; y++) {
                const uint16_t *ra = lv->a + (ptrdiff_t)y * lv->w;
                const uint16_t *rb = lv->b + (ptrdiff_t)(y + dy) * lv->w + dx;
                for (x = x0; x < x1; x++) {
                    const double a = ra[x], b = rb[x];
                    sa += a;
                    sb += b;
                    saa += a * a;
                    sbb += b * b;
                    sab += a * b;
                }
            }
            n = (double)(x1 - x0) * (y1 - y0);
            va = saa - sa * sa / n;
            vb = sbb - sb * sb / n;
            if (!(va > 0.0 && vb > 0.0)) continue;
            r = (sab - sa * sb / n) / sqrt(va * vb);
            /* a tie keeps the shorter shift */
            if (r > best + 1e-12 ||
                (fabs(r - best) <= 1e-12 && dx * dx + dy * dy < bx * bx + by * by)) {
                best = r;
                bx = dx;
                by = dy;
            }
        }
    s->hn[2] = bx * lv->scale / s->f;
    s->hn[5] = by * lv->scale / s->f;
    return sqrt((double)(bx * bx + by * by));
}

/* Build the levels: the slots' background16 images, then 2x2 sums of them in the match-time
 * buffers st->sampled (A's) and st->smoothed_b (B's). Returns the number of levels. */
static int make_levels(const home_context *ctx, int slot, dense_level *lv)
{
    const home__refine_state *st = &ctx->refine;
    uint16_t *wa = (uint16_t *)(void *)st->sampled, *wb = (uint16_t *)(void *)st->smoothed_b;
    int n = 1;
    lv[0].a = st->background16[slot];
    lv[0].b = st->background16[st->next_slot ^ 1];
    lv[0].w = st->background_w;
    lv[0].h = st->background_h;
    lv[0].unit = 1.0 / 16.0;
    lv[0].scale = (double)((1 << st->background_level) * st->background_factor);
    lv[0].offset = 0.5 * (lv[0].scale - 1.0);
    while (n < DENSE_LEVELS && lv[n - 1].w / 2 >= DENSE_MIN_SIDE &&
           lv[n - 1].h / 2 >= DENSE_MIN_SIDE) {
        dense_level *c = &lv[n];
        const dense_level *p = &lv[n - 1];
        c->w = p->w / 2;
        c->h = p->h / 2;
        /* sixteenths summed to 64ths (at most 4 x 4080), then 64ths stay 64ths */
        halve(p->a, p->w, p->h, wa, n == 1 ? 0 : 2);
        halve(p->b, p->w, p->h, wb, n == 1 ? 0 : 2);
        c->a = wa;
        c->b = wb;
        wa += (size_t)c->w * (size_t)c->h;
        wb += (size_t)c->w * (size_t)c->h;
        c->unit = 1.0 / 64.0;
        c->scale = 2.0 * p->scale;
        c->offset = 0.5 * (c->scale - 1.0);
        n++;
    }
    return n;
}

/* Model selection over the information infoq of the k parameters (row stride 8), carried to
 * the homography's entries: M = B (B^T B)^-1 infoq (B^T B)^-1 B^T (ginv: (B^T B)^-1). */
static int choose(const dense_solver *s, const double *infoq, double basis[8][8],
                  const double *ginv, int n, home__model_choice *choice)
{
    home__model_problem mp;
    double core[64] = {0}; /* zeroed for cppcheck (make lint) */
    int i, j, p, q;
    for (i = 0; i < s->k; i++)
        for (j = 0; j < s->k; j++) {
            double v = 0.0;
            for (p = 0; p < s->k; p++)
                for (q = 0; q < s->k; q++)
                    v += ginv[i * 8 + p] * infoq[p * 8 + q] * ginv[q * 8 + j];
            core[i * 8 + j] = v;
        }
    memset(&mp, 0, sizeof mp);
    mp.space = HOME__SPACE_H;
    for (i = 0; i < 8; i++) {
        mp.p[i] = s->hn[i];
        for (j = 0; j < 8; j++) {
            double v = 0.0;
            for (p = 0; p < s->k; p++)
                for (q = 0; q < s->k; q++) v += basis[i][p] * core[p * 8 + q] * basis[j][q];
            mp.info[i * 8 + j] = v;
        }
    }
    mp.penalty = log((double)n);
    mp.max_model = s->ctx->cfg.max_model;
    mp.rigid = 0;
    mp.max_params = s->k;
    mp.scale = s->f;
    mp.cx = s->cx;
    mp.cy = s->cy;
    return home__select_model(&mp, choice);
}

/* The generators of the model's updates over h0..h7 (k of them): the most general model
 * cfg.max_model allows. */
static void set_model(dense_solver *s, int max_model)
{
    memset(s->gen, 0, sizeof s->gen);
    s->plain = 0;
    if (max_model >= HOME_MODEL_AFFINE) {
        int e;
        s->k = max_model >= HOME_MODEL_HOMOGRAPHY ? 8 : 6;
        for (e = 0; e < s->k; e++) s->gen[e][e] = 1.0;
        s->plain = 1;
        return;
    }
    s->gen[0][2] = 1.0; /* translation */
    s->gen[1][5] = 1.0;
    s->k = 2;
    if (max_model >= HOME_MODEL_SIMILARITY) {
        s->gen[2][0] = s->gen[2][4] = 1.0; /* scale */
        s->gen[3][1] = -1.0;               /* rotation */
        s->gen[3][3] = 1.0;
        s->k = 4;
    }
}

/* The estimate's matrices and the residual histogram, in the match-time scratch (the call
 * stack of home_stab_push() stays under its bound). */
typedef struct dense_work {
    double info[64], basis[8][8], g[64], ginv[64], info_h[64], info_s[64], meat[64], t8[64];
    int32_t hist[DENSE_HIST_BINS];
} dense_work;
typedef char home__dense_work_fits[sizeof(dense_work) <= 4 * REGION_CAPACITY * sizeof(float) ? 1
                                                                                              : -1];

int home__refine_dense(home_context *ctx, int slot, home_result *result, double *reach_px,
                       double *spread)
{
    const home__refine_state *st = &ctx->refine;
    dense_work *wk = (dense_work *)st->scratch;
    double *info = wk->info, (*basis)[8] = wk->basis, *g = wk->g, *ginv = wk->ginv;
    double *info_h = wk->info_h, *info_s = wk->info_s, *meat = wk->meat, *t8 = wk->t8;
    int32_t *hist = wk->hist;
    dense_level lv[DENSE_LEVELS];
    dense_solver s;
    dense_fit fit;
    int levels, level, it, i, j, p, converged = 0;
    home__model_choice choice, sandwich;
    double resid_var, var_g;

    *reach_px = *spread = 0.0;
    if (!st->levels || ctx->cfg.max_model < HOME_MODEL_TRANSLATION) return 0;
    memset(&s, 0, sizeof s);
    s.ctx = ctx;
    s.cx = 0.5 * (ctx->cfg.width - 1);
    s.cy = 0.5 * (ctx->cfg.height - 1);
    s.f = 0.5 * (ctx->cfg.width > ctx->cfg.height ? ctx->cfg.width : ctx->cfg.height);
    memcpy(s.hn, home__refine_identity, sizeof s.hn);
    s.alpha = 1.0;
    s.beta = 0.0;
    set_model(&s, ctx->cfg.max_model);
    levels = make_levels(ctx, slot, lv);
    *reach_px = lv[levels - 1].scale * (1.0 + coarse_shift(&s, &lv[levels - 1]));
    for (level = levels - 1; level >= 0; level--) {
        converged = 0;
        /* the residuals' scale once per level: it changes little within one */
        for (it = 0; it < DENSE_ITERATIONS && !converged; it++) {
            double dq[8];
            if (!iterate(&s, &lv[level], hist, it == 0, 0, &fit) ||
                !solve_k(fit.jtj, fit.jtr, s.k, dq) || !compose_inverse(&s, dq))
                return 0;
            converged = step_px(&s, &lv[level], dq) < DENSE_STEP_EPS;
        }
        if (!converged) { /* a motion the frames do not determine slides (a horizon in fog) */
            result->refine_status = HOME_REFINE_NOT_CONVERGED;
            return 0;
        }
    }
    /* the statistics at the estimate */
    if (!iterate(&s, &lv[0], hist, 1, 1, &fit)) return 0;
    resid_var = fit.sum_w > s.k ? fit.sum_wr2 / (fit.sum_w - s.k) : fit.sum_wr2;
    var_g = DENSE_GRADIENT_NOISE_SHARE * resid_var;
    for (i = 0; i < 64; i++) info[i] = fit.jtj[i] - var_g * fit.noise[i];
    /* less what the gain, the lens shading and the bias explain as well (a shading ramp's
     * shift is a bias change): the Schur complement of their block, P = [A, q A, 1]:
     * info -= C (P^T W P)^-1 C^T, C = J^T W P */
    {
        double ppinv[24];
        for (j = 0; j < 3; j++) {
            double col[3] = {0.0, 0.0, 0.0}, x[3];
            col[j] = 1.0;
            if (!solve_k(fit.pp, col, 3, x)) return 0;
            for (i = 0; i < 3; i++) ppinv[i * 8 + j] = x[i];
        }
        for (i = 0; i < s.k; i++)
            for (j = 0; j < s.k; j++) {
                double v = 0.0;
                int c, d;
                for (c = 0; c < 3; c++)
                    for (d = 0; d < 3; d++)
                        v += fit.cross[8 * c + i] * ppinv[c * 8 + d] * fit.cross[8 * d + j];
                info[i * 8 + j] -= v;
            }
    }
    /* in the homography's entries (h8 = 1): dh = B dq, B's columns the derivatives of
     * hn (I + gen_i) normalised, and M = B (B^T B)^-1 I (B^T B)^-1 B^T */
    for (j = 0; j < s.k; j++) {
        double w[9], t[9] = {0};
        int e;
        for (e = 0; e < 9; e++) w[e] = e < 8 ? s.gen[j][e] : 0.0;
        home__refine_mat3_mul(s.hn, w, t);
        for (e = 0; e < 8; e++) basis[e][j] = t[e] - s.hn[e] * t[8];
    }
    for (i = 0; i < s.k; i++)
        for (j = 0; j < s.k; j++) {
            g[i * 8 + j] = 0.0;
            for (p = 0; p < 8; p++) g[i * 8 + j] += basis[p][i] * basis[p][j];
        }
    for (j = 0; j < s.k; j++) { /* (B^T B)^-1, column by column */
        double col[8] = {0, 0, 0, 0, 0, 0, 0, 0}, x[8];
        col[j] = 1.0;
        if (!solve_k(g, col, s.k, x)) return 0;
        for (i = 0; i < s.k; i++) ginv[i * 8 + j] = x[i];
    }
    /* two predictions: J^T W J over the residual variance (times the refinement's scale), and
     * the clustered sandwich (J^T W J) meat^-1 (J^T W J); the larger predicted error stands */
    for (i = 0; i < 64; i++)
        info_h[i] = info[i] / (resid_var * REFINE_SIGMA_SCALE * REFINE_SIGMA_SCALE);
    cluster_meat(&s, &lv[0], fit.sigma, meat);
    for (j = 0; j < s.k; j++) { /* meat^-1 info, column by column */
        double col[8], x[8];
        for (i = 0; i < 8; i++) col[i] = i < s.k ? info[i * 8 + j] : 0.0;
        if (!solve_k(meat, col, s.k, x)) return 0;
        for (i = 0; i < s.k; i++) t8[i * 8 + j] = x[i];
    }
    for (i = 0; i < s.k; i++)
        for (j = 0; j < s.k; j++) {
            double v = 0.0;
            for (p = 0; p < s.k; p++) v += info[i * 8 + p] * t8[p * 8 + j];
            info_s[i * 8 + j] = v;
        }
    if (!choose(&s, info_h, basis, ginv, fit.n, &choice) ||
        !choose(&s, info_s, basis, ginv, fit.n, &sandwich)) {
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return 0;
    }
    if (sandwich.sigma_px > choice.sigma_px) choice = sandwich;
    /* the correlation and the consistent share at the estimate */
    {
        const double *c = fit.corr;
        const double va = c[3] / c[0] - (c[1] / c[0]) * (c[1] / c[0]);
        const double vb = c[4] / c[0] - (c[2] / c[0]) * (c[2] / c[0]);
        const double cab = c[5] / c[0] - (c[1] / c[0]) * (c[2] / c[0]);
        const int within = (int)(3.0 * fit.sigma * 32.0);
        int in = 0, n;
        result->refine_zncc = va > 0.0 && vb > 0.0 ? cab / sqrt(va * vb) : 0.0;
        memset(hist, 0, DENSE_HIST_BINS * sizeof *hist);
        n = pass(&s, &lv[0], 0, 0.0, hist, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL);
        for (i = 0; i < DENSE_HIST_BINS && i < within; i++) in += hist[i];
        result->refine_inlier_share = n ? (double)in / n : 0.0;
    }
    {
        double hc[9];
        memcpy(hc, choice.p, 8 * sizeof *hc);
        hc[8] = 1.0;
        home__refine_pixels_from_normalised(s.f, s.cx, s.cy, hc, result->H);
    }
    if (!home__homography_plausible(result->H, ctx->cfg.width, ctx->cfg.height)) {
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return 0;
    }
    result->model = choice.model;
    result->sigma_px = choice.sigma_px;
    result->refined = 1;
    result->refine_status = HOME_REFINE_DENSE;
    /* the pixels that carry the information, as a share of those used: (sum g)^2 / sum g^2 */
    if (fit.spread[1] > 0.0 && fit.n > 0)
        *spread = fit.spread[0] * fit.spread[0] / fit.spread[1] / fit.n;
    return 1;
}
