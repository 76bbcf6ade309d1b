/* The refinement's Gauss-Newton solver: inverse-compositional Lucas-Kanade of the
 * homography's 8 parameters (or a smaller model's) coarse to fine on the snapshot's pyramid,
 * with a fitted gain and bias and Cauchy weights, and the predicted error of its estimate. */
#include "refine_internal.h"
#include <math.h>
#include <string.h>

#define HIST_BINS 512       /* |residual| histogram, 1/8 grey level per bin */
#define STEP_EPS_PX 0.02    /* convergence: largest corner update, full-resolution px */
#define STEP_NOISE_SHARE 0.25 /* ... or at the finest level, this share of the worst corner's
                                 predicted standard deviation */
#define NOISE_CHECK_PX 0.5  /* (that prediction is made only for steps below this) */
#define MAX_CORNER_STD_PX 0.5 /* worst corner's standard deviation (Fisher, or split-half) above
                                 this, or above max_sigma_px: ill conditioned */
/* The template's gradients carry its noise: E[g g^T] = g_true g_true^T + var(g) I, so J^T W J
 * holds information the noise only appears to give (a horizon in fog, the flat areas between
 * a few edges: every direction looks constrained). var(g) of a 2x central difference is about
 * the residual variance (two frames' noise) times this; taking each block's strongest
 * gradient raises it above 1 (3: the tuning set's calibration, docs/trust.md) */
#define NOISE_GRADIENT_SHARE 3.0
#define MODEL_FLOOR_PX 0.3   /* the model choice's floor (src/model.c): error of each corner
                                the Fisher information does not see (dim frames of a few edges:
                                homographies 1-2 px off at a predicted 0.2 px, docs/trust.md) */
#define DETERMINED_STD_PX 0.25 /* home__refine_determined(): a direction of the translation is
                                  solved when its standard deviation (without the noise's
                                  apparent information) is at most this, full-size px at the
                                  finest level (twice per coarser level) */
#define STAND_IN_MAX_MISFIT_PX 0.5 /* home__refine_run(): a similarity standing in for an
                                     undetermined homography leaves out at most this much
                                     perspective, */
#define STAND_IN_MAX_SIGMA_PX 0.15 /* ... its own predicted error is at most this, */
#define STAND_IN_MIN_SIGNAL 0.8 /* ... and at least this share of its translation's information is
                                   the frames' (not the template's gradient noise): only sharp
                                   edges pin a similarity; faint content, dim or shaded, leaves
                                   it at a biased optimum (docs/trust.md, session 33) */
#define STAND_IN_RIGID 2   /* refine_model()'s stand_in: a rigid motion (1: a similarity) */
#define RIGID_START 3      /* ... or a rigid motion only as a similarity's start, without a
                              stand-in's limits (home__refine_run_through_rigid()) */
#define RIGID_SCALE_PX 0.3 /* a rigid motion standing in for a similarity whose scale the frames do
                              not fix: the scale change it leaves out, px at the corners (the
                              evaluation's cameras: 0.18 px between frames in the median, 0.43 at
                              most; docs/trust.md, session 38) */
#define SPARSE_END_SIGMA 1.6 /* a stand-in ending at a level with fewer than FINEST_MIN_POINTS
                                points predicts its error times this (tuning frames: its errors
                                were 0.8 of the predicted in the median against 0.5 for the
                                rest, one scene biased 0.3 px along two parallel edges) */
#define RIGID_SPARSE_POINTS 128 /* a rigid stand-in may end at the finest level with this many
                                   points (a few edges fill 240-510 of its 4096 at full size,
                                   dim or by day; a similarity stand-in needs a quarter) */
#define CAPPED_MIN_SIGNAL 0.62 /* a model capped below the homography (the stabiliser's) needs
                                  this share of its translation's information to be the
                                  frames': fog, dim gradients and smooth blobs reach optima
                                  2-8 px off at a share of 0.50-0.61 (docs/trust.md, session
                                  39) */
#define SLOW_ITERATIONS 4    /* a finest level still shrinking its steps may take this many
                                times the iteration cap */
#define SIGNAL_SHARE_MIN 0.05 /* ... the information kept then, at least this share */

const double home__refine_identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

void home__refine_mat3_mul(const double *a, const double *b, double *out)
{
    int i, j;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            out[i * 3 + j] = a[i * 3 + 0] * b[0 * 3 + j] + a[i * 3 + 1] * b[1 * 3 + j] +
                             a[i * 3 + 2] * b[2 * 3 + j];
}

int home__refine_mat3_inv(const double *m, double *out)
{
    double d = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
               m[2] * (m[3] * m[7] - m[4] * m[6]);
    if (!(fabs(d) > 1e-300) || !isfinite(d)) return 0;
    out[0] = (m[4] * m[8] - m[5] * m[7]) / d;
    out[1] = (m[2] * m[7] - m[1] * m[8]) / d;
    out[2] = (m[1] * m[5] - m[2] * m[4]) / d;
    out[3] = (m[5] * m[6] - m[3] * m[8]) / d;
    out[4] = (m[0] * m[8] - m[2] * m[6]) / d;
    out[5] = (m[2] * m[3] - m[0] * m[5]) / d;
    out[6] = (m[3] * m[7] - m[4] * m[6]) / d;
    out[7] = (m[1] * m[6] - m[0] * m[7]) / d;
    out[8] = (m[0] * m[4] - m[1] * m[3]) / d;
    return 1;
}

static void normalise9(double *h)
{
    int k;
    double s = h[8];
    for (k = 0; k < 9; k++) h[k] /= s;
}

/* pixel H -> normalised N H N^-1, and back */
void home__refine_to_normalised(const home__refine_solver *s, const double *h, double *hn)
{
    const double n[9] = {1 / s->f, 0, -s->cx / s->f, 0, 1 / s->f, -s->cy / s->f, 0, 0, 1};
    const double ni[9] = {s->f, 0, s->cx, 0, s->f, s->cy, 0, 0, 1};
    double t[9] = {0}; /* all written by mat3_mul; zeroed for gcc's -fanalyzer (make lint) */
    home__refine_mat3_mul(n, h, t);
    home__refine_mat3_mul(t, ni, hn);
    normalise9(hn);
}

void home__refine_pixels_from_normalised(double f, double cx, double cy, const double *hn,
                                         double *h)
{
    const double n[9] = {1 / f, 0, -cx / f, 0, 1 / f, -cy / f, 0, 0, 1};
    const double ni[9] = {f, 0, cx, 0, f, cy, 0, 0, 1};
    double t[9] = {0}; /* all written by mat3_mul; zeroed for gcc's -fanalyzer (make lint) */
    home__refine_mat3_mul(ni, hn, t);
    home__refine_mat3_mul(t, n, h);
    normalise9(h);
}

static void to_pixels(const home__refine_solver *s, const double *hn, double *h)
{
    home__refine_pixels_from_normalised(s->f, s->cx, s->cy, hn, h);
}

void home__refine_scaled_matrix(double f, double cx, double cy, const double *hn, double scale,
                                double offset, double *m)
{
    const double q[9] = {scale / f, 0, (offset - cx) / f, 0, scale / f, (offset - cy) / f, 0,
                         0,         1};
    const double p[9] = {f / scale, 0, (cx - offset) / scale, 0, f / scale, (cy - offset) / scale,
                         0,         0, 1};
    double t[9] = {0}; /* t: gcc -fanalyzer loses it through mat3_mul's loops */
    home__refine_mat3_mul(hn, q, t);
    home__refine_mat3_mul(p, t, m);
}

/* Matrix taking template level-l pixels to B's level-l pixels under hn. */
void home__refine_level_matrix(const home__refine_solver *s, const double *hn, int level, float *m)
{
    const double sc = (double)(1 << level);
    double r[9];
    int k;
    home__refine_scaled_matrix(s->f, s->cx, s->cy, hn, sc, 0.5 * (sc - 1.0), r);
    for (k = 0; k < 9; k++) m[k] = (float)r[k];
}

/* Robust scale: 1.4826 * median |r| over the valid points, from a histogram. */
double home__refine_robust_sigma(const float *img_b, const int16_t *t, int n, double alpha,
                                 double beta, int32_t *bins)
{
    const float a = (float)alpha, b = (float)beta;
    int hist[HIST_BINS + 2], i, count, half, acc = 0;
    memset(hist, 0, sizeof hist);
    /* bins first (element-wise: vectorised), then the histogram; invalid points in a spare bin */
    for (i = 0; i < n; i++) {
        const float r = fabsf(a * img_b[i] + b - (float)t[i]) * 8.0f;
        const int bin = r < (float)HIST_BINS ? (int)r : HIST_BINS;
        bins[i] = img_b[i] >= 0.0f ? bin : HIST_BINS + 1;
    }
    for (i = 0; i < n; i++) hist[bins[i]]++;
    count = n - hist[HIST_BINS + 1];
    if (!count) return SIGMA_FLOOR;
    half = (count + 1) / 2;
    for (i = 0; i <= HIST_BINS; i++) {
        acc += hist[i];
        if (acc >= half) break;
    }
    {
        double med = (i + 0.5) / 8.0, sigma = 1.4826 * med;
        return sigma > SIGMA_FLOOR ? sigma : SIGMA_FLOOR;
    }
}

/* Weighted least-squares gain and bias of alpha * B + beta ~ A with Cauchy weights
 * 1 / (1 + (r / c)^2), c = 2.385 sigma: the influence of a residual fades as 1 / |r| far out, so
 * occluders and moving objects barely pull, yet no point is ever cut off outright. Scale
 * sigma from the residuals of the current (alpha, beta); writes weights and new residuals.
 * mask (optional): only points valid there too. Returns the number of valid points. */
int home__refine_fit_photometric(home__refine_solver *s, const home__refine_points *tp,
                                 const float *img_b, const float *mask, double sigma, float *res,
                                 float *wt)
{
    const int n4 = (tp->n + LANES - 1) & ~(LANES - 1);
    float part[5 * LANES];
    double sum[5], den;
    int k, n;
    n = s->st->rk->cauchy_sums(img_b, mask ? mask : img_b, tp->t, n4, tp->n, (float)s->alpha,
                               (float)s->beta, (float)(1.0 / (CAUCHY_K * sigma)), wt, part);
    for (k = 0; k < 5; k++)
        sum[k] = ((double)part[k * LANES] + part[k * LANES + 1]) +
                 ((double)part[k * LANES + 2] + part[k * LANES + 3]);
    /* sum: w, w b, w a, w b b, w b a */
    if (n && sum[0] > 0) {
        den = sum[0] * sum[3] - sum[1] * sum[1];
        if (den > 1e-6 * sum[0] * sum[0]) {
            s->alpha = (sum[0] * sum[4] - sum[1] * sum[2]) / den;
            s->beta = (sum[2] - s->alpha * sum[1]) / sum[0];
        } else {
            s->alpha = 1.0;
            s->beta = (sum[2] - sum[1]) / sum[0];
        }
    }
    s->st->rk->residuals(img_b, tp->t, wt, n4, (float)s->alpha, (float)s->beta, res);
    return n;
}

/* Largest displacement of the image corners (full-resolution px) by the linearised update dp. */
static double corner_step_px(const home__refine_solver *s, const double *dp)
{
    const double hu = s->cx / s->f, hv = s->cy / s->f;
    double worst = 0.0;
    int k;
    for (k = 0; k < 4; k++) {
        double u = (k & 1) ? hu : -hu, v = (k & 2) ? hv : -hv;
        double du = dp[0] * u + dp[1] * v + dp[2] - (dp[6] * u + dp[7] * v) * u;
        double dv = dp[3] * u + dp[4] * v + dp[5] - (dp[6] * u + dp[7] * v) * v;
        double d = sqrt(du * du + dv * dv) * s->f;
        if (d > worst) worst = d;
    }
    return worst;
}

/* Normal equations (J^T W J, J^T W r) in normalised units from the lanes in lane_mask. */
static void normal_equations(const float *acc, unsigned lane_mask, double k, double *a, double *g)
{
    int p, q, j, l;
    for (p = 0, j = 0; p < 8; p++) {
        double v;
        for (q = p; q < 8; q++, j++) {
            for (l = 0, v = 0.0; l < LANES; l++)
                if (lane_mask >> l & 1) v += (double)acc[j * LANES + l];
            a[p * 8 + q] = a[q * 8 + p] = v * k * k;
        }
        for (l = 0, v = 0.0; l < LANES; l++)
            if (lane_mask >> l & 1) v += (double)acc[(36 + p) * LANES + l];
        g[p] = v * k;
    }
}

/* x = B (B^T a B)^-1 B^T b: the solve in the model's parameters (a and b are overwritten; with
 * all 8, a plain solve). 0 when not positive definite. */
static int model_solve(const home__refine_solver *s, double *a, double *b)
{
    double aq[64], bq[8];
    int i, j;
    if (s->k == 8) return home__solve_spd8(a, b);
    home__project_normal(s->basis, s->k, a, b, aq, bq);
    if (!home__solve_spd(aq, bq, s->k)) return 0;
    for (j = 0; j < 8; j++) {
        double v = 0.0;
        for (i = 0; i < s->k; i++) v += bq[i] * s->basis[i][j];
        b[j] = v;
    }
    return 1;
}

/* Point i of level `level`'s template lies in a region the solver leaves out. */
static int is_excluded(const home__refine_solver *s, const home__refine_points *tp, int i,
                       int level)
{
    return s->excluded[region_of(tp->x[i], tp->y[i], s->st->w[level], s->st->h[level])] != 0;
}

/* Template level-`level` pixels to normalised units, as the accumulate kernel takes them:
 * u = aff[0] x + aff[1], v = aff[0] y + aff[2]. */
static void level_affine(const home__refine_solver *s, int level, float *aff)
{
    const double sc = (double)(1 << level), o = 0.5 * (sc - 1.0);
    aff[0] = (float)(sc / s->f);
    aff[1] = (float)((o - s->cx) / s->f);
    aff[2] = (float)((o - s->cy) / s->f);
}

/* Lens shading fixed to the sensor, s(x) = 1 - kappa rho^2(x): frame B's sample at h(x) is
 * s(h(x)) times the scene, A's at x s(x) times it, so B's samples times s(x) / s(h(x)) compare
 * with A. rho^2 of a template point (u, v) and of its image under hn, normalised units. */
#define KAPPA_MIN (-0.5) /* the falloff fitted stays within these: a brightening towards the */
#define KAPPA_MAX 0.8    /* corners of half, a darkening of four fifths */

static void shading_radii(const home__refine_solver *s, const double *h, double u, double v,
                          double *ra, double *rb)
{
    const double w = h[6] * u + h[7] * v + h[8];
    const double x = (h[0] * u + h[1] * v + h[2]) / w, y = (h[3] * u + h[4] * v + h[5]) / w;
    *ra = s->rho_scale * (u * u + v * v);
    *rb = s->rho_scale * (x * x + y * y);
}

/* B's samples img_b at `level`'s points under hn times s(x) / s(h(x)) at the current kappa. */
static void shade_samples(const home__refine_solver *s, int level, const double *hn, float *img_b)
{
    const home__refine_points *tp = &s->tpl[level];
    float aff[3];
    int i;
    if (s->kappa == 0.0) return;
    level_affine(s, level, aff);
    for (i = 0; i < tp->n; i++) {
        double ra, rb;
        if (img_b[i] < 0.0f) continue;
        shading_radii(s, hn, (double)(aff[0] * (float)tp->x[i] + aff[1]),
                      (double)(aff[0] * (float)tp->y[i] + aff[2]), &ra, &rb);
        img_b[i] = (float)(img_b[i] * (1.0 - s->kappa * ra) / (1.0 - s->kappa * rb));
    }
}

/* The weighted sums that put kappa beside the motion in the normal equations, per parity of
 * the point's index (the split-half check's halves): c = d r / d kappa, the steepest-descent
 * images sd (the motion's Jacobian over the level's gradient scale), b (B's shaded sample), r. */
typedef struct shading_sums {
    double w, wb, wbb, wr, wbr, wc, wbc, wcc, wcr;
    double wsd[8], wbsd[8], wcsd[8];
} shading_sums;

static void shading_accumulate(const home__refine_solver *s, int level, const float *aff,
                               shading_sums *half)
{
    const home__refine_points *tp = &s->tpl[level];
    int i, p;
    memset(half, 0, 2 * sizeof *half);
    for (i = 0; i < tp->n; i++) {
        const double w = s->wt[i];
        shading_sums *q = &half[i & 1];
        double u, v, gx, gy, g, ra, rb, b, c, r, sd[8];
        if (!(w > 0.0)) continue;
        /* as the accumulate kernel forms them */
        u = (double)(aff[0] * (float)tp->x[i] + aff[1]);
        v = (double)(aff[0] * (float)tp->y[i] + aff[2]);
        gx = tp->gx[i];
        gy = tp->gy[i];
        g = gx * u + gy * v;
        sd[0] = gx * u; sd[1] = gx * v; sd[2] = gx;
        sd[3] = gy * u; sd[4] = gy * v; sd[5] = gy;
        sd[6] = -(u * g); sd[7] = -(v * g);
        shading_radii(s, s->hn, u, v, &ra, &rb);
        b = s->img_b[i];
        r = s->res[i];
        c = s->alpha * b * (rb - ra) / ((1.0 - s->kappa * ra) * (1.0 - s->kappa * rb));
        q->w += w; q->wb += w * b; q->wbb += w * b * b; q->wr += w * r; q->wbr += w * b * r;
        q->wc += w * c; q->wbc += w * b * c; q->wcc += w * c * c; q->wcr += w * c * r;
        for (p = 0; p < 8; p++) {
            q->wsd[p] += w * sd[p];
            q->wbsd[p] += w * b * sd[p];
            q->wcsd[p] += w * c * sd[p];
        }
    }
}

/* kappa's row of the normal equations beside the motion's (gradient scale k), the gain and
 * bias (fitted beside) taken out of its column first: col (the cross terms with the motion),
 * kk and gk. 0 when the data hold no falloff's change (no motion, or nothing to shade). */
static int shading_row(const shading_sums *half, unsigned parities, double k, double *col,
                       double *kk, double *gk)
{
    shading_sums t;
    double det, g0, g1, cc, cr;
    int p, q;
    memset(&t, 0, sizeof t);
    for (q = 0; q < 2; q++) {
        const shading_sums *h = &half[q];
        if (!(parities >> q & 1)) continue;
        t.w += h->w; t.wb += h->wb; t.wbb += h->wbb; t.wr += h->wr; t.wbr += h->wbr;
        t.wc += h->wc; t.wbc += h->wbc; t.wcc += h->wcc; t.wcr += h->wcr;
        for (p = 0; p < 8; p++) {
            t.wsd[p] += h->wsd[p];
            t.wbsd[p] += h->wbsd[p];
            t.wcsd[p] += h->wcsd[p];
        }
    }
    /* c's part beyond the gain and bias: c - g0 - g1 b, weighted least squares */
    det = t.w * t.wbb - t.wb * t.wb;
    if (!(det > 1e-9 * t.w * t.w)) return 0;
    g1 = (t.w * t.wbc - t.wb * t.wc) / det;
    g0 = (t.wc - g1 * t.wb) / t.w;
    cc = t.wcc - g0 * t.wc - g1 * t.wbc;
    cr = t.wcr - g0 * t.wr - g1 * t.wbr;
    if (!(cc > 1e-12 * t.wcc) || !(cc > 0.0)) return 0;
    /* the column of -c (the residual r + c dkappa against J dp) */
    for (p = 0; p < 8; p++) col[p] = -k * (t.wcsd[p] - g0 * t.wsd[p] - g1 * t.wbsd[p]);
    *kk = cc;
    *gk = -cr;
    return 1;
}

/* kappa taken out of the motion's normal equations (a, g) by the Schur complement. */
static void eliminate_shading(const double *col, double kk, double gk, double *a, double *g)
{
    int p, q;
    for (p = 0; p < 8; p++) {
        for (q = 0; q < 8; q++) a[p * 8 + q] -= col[p] * col[q] / kk;
        g[p] -= col[p] * gk / kk;
    }
}

/* One IRLS Gauss-Newton step at a level. Returns 0 when too few points stay usable or the
 * system is singular; *step_px gets the corner motion of the update. */
static int iterate(home__refine_solver *s, int level, double *step_px)
{
    const home__refine_state *st = s->st;
    const home__refine_points *tp = &s->tpl[level];
    const int n4 = (tp->n + LANES - 1) & ~(LANES - 1);
    const double sc = (double)(1 << level);
    const double k = s->f / (2.0 * sc);  /* template gradient: 2x central difference per level px */
    float m[9], aff[3], *acc = s->acc;
    double a[64], g[8], dp[9], hd[9], hdi[9], t[9], col[8], kk = 0.0, gk = 0.0;
    shading_sums half[2];
    int i, p, valid, shaded = 0;

    level_affine(s, level, aff);
    home__refine_level_matrix(s, s->hn, level, m);
    st->rk->warp(m, tp->x, tp->y, n4, st->pyr[level], st->w[level], st->w[level],
                      st->h[level], s->img_b);
    if (s->shading) shade_samples(s, level, s->hn, s->img_b);
    s->sigma = home__refine_robust_sigma(s->img_b, tp->t, tp->n, s->alpha, s->beta,
                                         (int32_t *)(void *)s->wt);
    if (s->excluded && s->mask_level != level) {
        /* the points of excluded regions as outside the frame (img_b2 is free while solving) */
        for (i = 0; i < n4; i++)
            s->img_b2[i] = i < tp->n && is_excluded(s, tp, i, level) ? -1.0f : 0.0f;
        s->mask_level = level;
    }
    valid = home__refine_fit_photometric(s, tp, s->img_b, s->excluded ? s->img_b2 : NULL,
                                         s->sigma, s->res, s->wt);
    if (valid < MIN_POINTS) return 0;
    /* J^T W J at a level's first iteration, then reused while the steps keep halving (a fresh
     * one otherwise, see refine()): in the inverse-compositional form it changes only through
     * the weights, and an approximate matrix changes the path to the solution, not the solution
     * (J^T W r = 0). J^T W J is 36 of the 44 sums per point. */
    st->rk->accumulate(tp->x, tp->y, tp->gx, tp->gy, s->res, s->wt, n4, aff,
                       s->hessian_level != level, acc);
    s->hessian_level = level;
    normal_equations(acc, 0xf, k, a, g);
    if (s->shading) {
        shading_accumulate(s, level, aff, half);
        shaded = shading_row(half, 3, k, col, &kk, &gk);
        if (shaded) eliminate_shading(col, kk, gk, a, g);
    }
    memcpy(s->jtj, a, sizeof a);
    memcpy(s->jtr, g, sizeof s->jtr);
    if (level == s->finest) {
        /* split-half check: the steps of the even and the odd lanes (interleaved halves of the
         * points) from the same estimate agree when the points carry signal and scatter when
         * they carry template noise, which the Fisher covariance cannot see */
        double ae[64], ge[8], ao[64], go[8];
        normal_equations(acc, 0x5, k, ae, ge);
        normal_equations(acc, 0xa, k, ao, go);
        double half_col[8], half_k, half_g;
        if (shaded) {
            if (shading_row(half, 1, k, half_col, &half_k, &half_g))
                eliminate_shading(half_col, half_k, half_g, ae, ge);
            if (shading_row(half, 2, k, half_col, &half_k, &half_g))
                eliminate_shading(half_col, half_k, half_g, ao, go);
        }
        if (model_solve(s, ae, ge) && model_solve(s, ao, go)) {
            for (p = 0; p < 8; p++) ge[p] -= go[p];
            s->split_px = 0.5 * corner_step_px(s, ge);
        } else {
            s->split_px = INFINITY;
        }
    }
    if (!model_solve(s, a, g)) return 0;
    for (p = 0; p < 8; p++) dp[p] = g[p];
    memcpy(s->step, dp, sizeof s->step);
    *step_px = corner_step_px(s, dp);
    if (shaded) {
        double dk = gk;
        for (p = 0; p < 8; p++) dk -= col[p] * dp[p];
        s->kappa += dk / kk;
        s->kappa = s->kappa < KAPPA_MIN ? KAPPA_MIN : s->kappa > KAPPA_MAX ? KAPPA_MAX : s->kappa;
    }
    hd[0] = 1 + dp[0]; hd[1] = dp[1]; hd[2] = dp[2];
    hd[3] = dp[3]; hd[4] = 1 + dp[4]; hd[5] = dp[5];
    hd[6] = dp[6]; hd[7] = dp[7]; hd[8] = 1;
    if (!home__refine_mat3_inv(hd, hdi)) return 0;
    home__refine_mat3_mul(s->hn, hdi, t);
    normalise9(t);
    for (i = 0; i < 9; i++)
        if (!isfinite(t[i])) return 0;
    memcpy(s->hn, t, sizeof t);
    return 1;
}

/* Removes from s->jtj (the finest level's J^T W J) the part the template's gradient noise
 * contributes on average: var(g) sum w D^T D, D the warp's 2x8 Jacobian at each point,
 * D = [u v 1 0 0 0 -u^2 -uv; 0 0 0 u v 1 -uv -v^2]: its entries are the weighted moments
 * m[a][b] = sum w u^a v^b up to degree 4. */
/* var(g) sum w D^T D at `level` (its template points, the weights of its last iteration) for
 * the residual variance resid_var, into b (normalised units, as jtj). */
static void noise_information(const home__refine_solver *s, int level, double resid_var,
                              double *b)
{
    const home__refine_points *tp = &s->tpl[level];
    const double sc = (double)(1 << level), o = 0.5 * (sc - 1.0);
    const double k = s->f / (2.0 * sc);
    const double var_g = NOISE_GRADIENT_SHARE * resid_var * k * k;
    double m[5][5];
    int i, p, q;
    memset(m, 0, sizeof m);
    for (i = 0; i < tp->n; i++) {
        const double w = s->wt[i], u = (tp->x[i] * sc + o - s->cx) / s->f,
                     v = (tp->y[i] * sc + o - s->cy) / s->f;
        double wu = w;
        int a, c;
        if (!(w > 0.0)) continue;
        for (a = 0; a <= 4; a++, wu *= u) {
            double wuv = wu;
            for (c = 0; a + c <= 4; c++, wuv *= v) m[a][c] += wuv;
        }
    }
    memset(b, 0, 64 * sizeof *b);
    b[0 * 8 + 0] = b[3 * 8 + 3] = m[2][0];
    b[0 * 8 + 1] = b[3 * 8 + 4] = m[1][1];
    b[0 * 8 + 2] = b[3 * 8 + 5] = m[1][0];
    b[1 * 8 + 1] = b[4 * 8 + 4] = m[0][2];
    b[1 * 8 + 2] = b[4 * 8 + 5] = m[0][1];
    b[2 * 8 + 2] = b[5 * 8 + 5] = m[0][0];
    b[0 * 8 + 6] = -m[3][0];
    b[0 * 8 + 7] = b[1 * 8 + 6] = b[3 * 8 + 6] = -m[2][1];
    b[1 * 8 + 7] = b[3 * 8 + 7] = b[4 * 8 + 6] = -m[1][2];
    b[4 * 8 + 7] = -m[0][3];
    b[2 * 8 + 6] = -m[2][0];
    b[2 * 8 + 7] = b[5 * 8 + 6] = -m[1][1];
    b[5 * 8 + 7] = -m[0][2];
    b[6 * 8 + 6] = m[4][0] + m[2][2];
    b[6 * 8 + 7] = m[3][1] + m[1][3];
    b[7 * 8 + 7] = m[2][2] + m[0][4];
    for (p = 0; p < 8; p++)
        for (q = p; q < 8; q++) b[p * 8 + q] = b[q * 8 + p] = var_g * b[p * 8 + q];
}

static void remove_noise_information(home__refine_solver *s)
{
    double b[64];
    int p, q;
    noise_information(s, s->finest, s->resid_var, b);
    for (p = 0; p < 8; p++)
        for (q = p; q < 8; q++) {
            s->jtj[p * 8 + q] -= b[p * 8 + q];
            s->jtj[q * 8 + p] = s->jtj[p * 8 + q];
        }
}

/* Weighted residual variance of the last iteration at `level` (its weights and residuals are
 * still in the scratch), for the Fisher covariance below; residual_variance(): the finest's. */
static double residual_variance_at(const home__refine_solver *s, int level)
{
    const home__refine_points *tp = &s->tpl[level];
    double sum_w = 0, sum_wr2 = 0;
    int i;
    for (i = 0; i < tp->n; i++) {
        sum_w += s->wt[i];
        sum_wr2 += (double)s->wt[i] * s->res[i] * s->res[i];
    }
    return sum_w > 8 ? sum_wr2 / (sum_w - 8) : sum_wr2;
}

static double residual_variance(const home__refine_solver *s)
{
    return residual_variance_at(s, s->finest);
}

/* Predicted standard deviation of the worst corner, px: sqrt(J_c (sigma^2 A^-1) J_c^T). */
static double corner_std_px(const home__refine_solver *s)
{
    const double hu = s->cx / s->f, hv = s->cy / s->f;
    double worst = 0.0, l[64];
    int k, axis, i, j;
    /* one factor of the (model's) normal matrix for the eight corner coordinates */
    if (s->k == 8) {
        memcpy(l, s->jtj, sizeof l);
    } else {
        const double no_gradient[8] = {0};
        double unused[8];
        home__project_normal(s->basis, s->k, s->jtj, no_gradient, l, unused);
    }
    if (!home__cholesky8(l)) return INFINITY;
    for (k = 0; k < 4; k++) {
        double u = (k & 1) ? hu : -hu, v = (k & 2) ? hv : -hv, var = 0.0;
        for (axis = 0; axis < 2; axis++) {
            double jc[8], z[8], q = 0.0;
            memset(jc, 0, sizeof jc);
            if (axis == 0) { jc[0] = u; jc[1] = v; jc[2] = 1; jc[6] = -u * u; jc[7] = -u * v; }
            else { jc[3] = u; jc[4] = v; jc[5] = 1; jc[6] = -u * v; jc[7] = -v * v; }
            if (s->k == 8) {
                memcpy(z, jc, sizeof z);
            } else { /* B^T jc, zero beyond k */
                for (i = 0; i < 8; i++) {
                    z[i] = 0.0;
                    for (j = 0; j < 8 && i < s->k; j++) z[i] += s->basis[i][j] * jc[j];
                }
                memcpy(jc, z, sizeof jc);
            }
            home__cholesky_solve8(l, z);
            for (i = 0; i < 8; i++) q += jc[i] * z[i];
            var += q;
        }
        var *= s->resid_var * s->f * s->f;
        if (sqrt(var) > worst) worst = sqrt(var);
    }
    return worst;
}

/* How far a homography's optimum lies from the similarity standing in for it, px at the worst
 * corner: the last linearisation's full Gauss-Newton step (all 8 parameters) less the step the
 * similarity took. A prior of MODEL_FLOOR_PX per corner holds the directions the frames do not
 * determine at the similarity; those they do determine show the perspective the similarity
 * leaves out (a still pair's, far larger than a consecutive frame's). */
static double stand_in_misfit_px(const home__refine_solver *s)
{
    const double hu = s->cx / s->f, hv = s->cy / s->f;
    const double prior = s->resid_var * REFINE_SIGMA_SCALE * REFINE_SIGMA_SCALE * s->f * s->f /
                         (MODEL_FLOOR_PX * MODEL_FLOOR_PX);
    double a[64], d[8], jc[4][2][8];
    int k, axis, i, j;
    for (k = 0; k < 4; k++) {
        const double u = (k & 1) ? hu : -hu, v = (k & 2) ? hv : -hv;
        const double row[2][8] = {{u, v, 1, 0, 0, 0, -u * u, -u * v},
                                  {0, 0, 0, u, v, 1, -u * v, -v * v}};
        memcpy(jc[k], row, sizeof row);
    }
    memcpy(a, s->jtj, sizeof a);
    memcpy(d, s->jtr, sizeof d);
    for (k = 0; k < 4; k++)
        for (axis = 0; axis < 2; axis++)
            for (i = 0; i < 8; i++)
                for (j = 0; j < 8; j++) a[i * 8 + j] += prior * jc[k][axis][i] * jc[k][axis][j];
    if (!home__solve_spd8(a, d)) return INFINITY;
    for (i = 0; i < 8; i++) d[i] -= s->step[i];
    return corner_step_px(s, d);
}

/* Robust photometric error of the finest-level B samples img_b over the points other_b (the
 * samples under the other estimate) keeps too: mean robust cost at the fixed scale sigma,
 * after re-fitting gain and bias. Also the weighted correlation of A and B there. */
static double photometric_error(home__refine_solver *s, const float *img_b, const float *other_b,
                                double sigma, double *zncc)
{
    const home__refine_points *tp = &s->tpl[s->finest];
    const double c = CAUCHY_K * sigma;
    double cost = 0, sw = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, va, vb;
    int i, it, n = 0;
    s->alpha = 1.0;
    s->beta = 0.0;
    for (it = 0; it < 2; it++)
        home__refine_fit_photometric(s, tp, img_b, other_b, sigma, s->res, s->wt);
    for (i = 0; i < tp->n; i++) {
        double w = s->wt[i], a = tp->t[i], b = img_b[i];
        if (img_b[i] < 0.0f || other_b[i] < 0.0f) continue;
        cost += robust_cost(s->res[i], c);
        n++;
        sw += w; sa += w * a; sb += w * b; saa += w * a * a; sbb += w * b * b; sab += w * a * b;
    }
    *zncc = 0.0;
    if (sw > 0) {
        va = saa - sa * sa / sw;
        vb = sbb - sb * sb / sw;
        if (va > 0 && vb > 0) *zncc = (sab - sa * sb / sw) / sqrt(va * vb);
    }
    return n ? cost / n : INFINITY;
}

/* Share of the points (valid under both estimates) whose residual under the estimate of img_b
 * (s->res, left by photometric_error) is within 3 robust sigmas of its own: a refinement that
 * aligned part of the scene (two edges of three, say) leaves the rest far off, and the robust
 * weights that let it ignore them also hide them from the weighted correlation. */
static double inlier_share(home__refine_solver *s, const float *img_b, const float *other_b)
{
    const home__refine_points *tp = &s->tpl[s->finest];
    double sigma, limit;
    int i, n = 0, in = 0;
    /* the scale from the residuals (home__refine_robust_sigma's histogram bins go to the weights'
     * scratch) */
    sigma =
        home__refine_robust_sigma(img_b, tp->t, tp->n, s->alpha, s->beta, (int32_t *)(void *)s->wt);
    limit = 3.0 * sigma;
    for (i = 0; i < tp->n; i++) {
        if (img_b[i] < 0.0f || other_b[i] < 0.0f) continue;
        n++;
        in += fabs(s->res[i]) <= limit;
    }
    return n ? (double)in / n : 0.0;
}

double home__refine_max_corner_distance(double cx, double cy, const double *h1, const double *h2)
{
    const double xs[2] = {0.0, 2.0 * cx}, ys[2] = {0.0, 2.0 * cy};
    double worst = 0.0;
    int k;
    for (k = 0; k < 4; k++) {
        double x = xs[k & 1], y = ys[k >> 1];
        double w1 = h1[6] * x + h1[7] * y + h1[8], w2 = h2[6] * x + h2[7] * y + h2[8];
        double dx = (h1[0] * x + h1[1] * y + h1[2]) / w1 - (h2[0] * x + h2[1] * y + h2[2]) / w2;
        double dy = (h1[3] * x + h1[4] * y + h1[5]) / w1 - (h2[3] * x + h2[4] * y + h2[5]) / w2;
        double d = sqrt(dx * dx + dy * dy);
        if (!(d <= worst)) worst = d; /* NaN counts as infinitely far */
    }
    return worst;
}

/* dp of the inverse-compositional update that takes hn to hn2 (both normalised, h8 = 1):
 * hn2 = hn (I + D(dp))^-1, so I + D = hn2^-1 hn scaled to a unit corner. */
static int update_between(const double *hn, const double *hn2, double *dp)
{
    double inv[9], m[9];
    int k;
    if (!home__refine_mat3_inv(hn2, inv)) return 0;
    home__refine_mat3_mul(inv, hn, m);
    if (!(fabs(m[8]) > 1e-12)) return 0;
    normalise9(m);
    for (k = 0; k < 8; k++) dp[k] = m[k] - (k == 0 || k == 4 ? 1.0 : 0.0);
    return 1;
}

/* Model selection over the refinement's Fisher information (src/model.c): J^T W J over the
 * weighted residual variance is the information of the update dp at the estimate; the chain
 * rule through dp(h) (central differences) gives that of h's entries. A homography must also
 * stand out of MODEL_FLOOR_PX. h1 (pixels) becomes the chosen model's estimate; sets
 * result->model and sigma_px. */
static int choose_model(home__refine_solver *s, int max_model, int rigid, double *h1,
                        home_result *result)
{
    home__model_problem mp;
    home__model_choice choice;
    double jac[8][8], t[8][8], hn[9];
    int i, j, a, b;
    mp.space = HOME__SPACE_H;
    for (j = 0; j < 8; j++) {
        const double eps = 1e-7;
        double hp[9], hm[9], dpp[8], dpm[8];
        memcpy(hp, s->hn, sizeof hp);
        memcpy(hm, s->hn, sizeof hm);
        hp[j] += eps;
        hm[j] -= eps;
        if (!update_between(s->hn, hp, dpp) || !update_between(s->hn, hm, dpm)) return 0;
        for (i = 0; i < 8; i++) jac[i][j] = (dpp[i] - dpm[i]) / (2 * eps);
    }
    for (a = 0; a < 8; a++) /* t = J^T W J  d dp / d h, then d dp / d h^T t */
        for (j = 0; j < 8; j++) {
            double v = 0.0;
            for (b = 0; b < 8; b++) v += s->jtj[a * 8 + b] * jac[b][j];
            t[a][j] = v;
        }
    for (i = 0; i < 8; i++)
        for (j = 0; j < 8; j++) {
            double v = 0.0;
            for (a = 0; a < 8; a++) v += jac[a][i] * t[a][j];
            mp.info[i * 8 + j] = v / (s->resid_var * REFINE_SIGMA_SCALE * REFINE_SIGMA_SCALE);
        }
    memcpy(mp.p, s->hn, sizeof mp.p);
    mp.penalty = log((double)s->tpl[s->finest].n);
    mp.max_model = max_model;
    mp.rigid = rigid;
    mp.max_params = 8;
    mp.scale = s->f;
    mp.cx = s->cx;
    mp.cy = s->cy;
    mp.floor_px = MODEL_FLOOR_PX;
    if (!home__select_model(&mp, &choice)) return 0;
    memcpy(hn, choice.p, 8 * sizeof *hn);
    hn[8] = 1.0;
    to_pixels(s, hn, h1);
    result->model = choice.model;
    result->sigma_px = choice.sigma_px;
    return 1;
}

/* A solver on the template of slot `slot`, its scratch, the normalisation and the level the
 * estimate ends at. */
void home__refine_solver_setup(home_context *ctx, int slot, home__refine_solver *s)
{
    const home__refine_state *st = &ctx->refine;
    float *scratch = (float *)st->scratch;
    const int cap = home__refine_match_capacity(&ctx->cfg);
    memset(s, 0, sizeof *s);
    s->st = st;
    s->tpl = st->tpl[slot];
    s->cx = 0.5 * (ctx->cfg.width - 1);
    s->cy = 0.5 * (ctx->cfg.height - 1);
    s->f = 0.5 * (ctx->cfg.width > ctx->cfg.height ? ctx->cfg.width : ctx->cfg.height);
    s->img_b = scratch;
    s->img_b2 = scratch + cap;
    s->res = scratch + 2 * cap;
    s->wt = scratch + 3 * cap;
    s->alpha = 1.0;
    s->hessian_level = -1;
    s->mask_level = -1;
    s->signal_share = 1.0;
    s->rho_scale = s->f * s->f / (s->cx * s->cx + s->cy * s->cy);
    s->k = 8;
    for (s->finest = st->finest_level; s->finest < st->levels - 1; s->finest++) {
        const int cap_half = s->tpl[s->finest].capacity / 2;
        if (s->tpl[s->finest].n >= (cap_half < FINEST_MIN_POINTS ? cap_half : FINEST_MIN_POINTS))
            break;
    }
}

/* Robust photometric errors e0 of the estimate hn0 and e1 of hn (both normalised) at the finest
 * level over the points both keep (and not in an excluded region), at hn0's residual scale, and
 * their correlations; img_b holds B under hn0, img_b2 under hn afterwards. */
static void compare_estimates(home__refine_solver *s, const double *hn, const double *hn0,
                              const unsigned char *excluded, double *e0, double *e1,
                              double *zncc0, double *zncc1)
{
    const home__refine_state *st = s->st;
    const int fl = s->finest;
    const home__refine_points *tp = &s->tpl[fl];
    const int n4 = (tp->n + LANES - 1) & ~(LANES - 1);
    double sigma0;
    float m[9];
    home__refine_level_matrix(s, hn, fl, m);
    st->rk->warp(m, tp->x, tp->y, n4, st->pyr[fl], st->w[fl], st->w[fl], st->h[fl], s->img_b2);
    home__refine_level_matrix(s, hn0, fl, m);
    st->rk->warp(m, tp->x, tp->y, n4, st->pyr[fl], st->w[fl], st->w[fl], st->h[fl], s->img_b);
    if (s->shading) { /* both under the falloff fitted */
        shade_samples(s, fl, hn, s->img_b2);
        shade_samples(s, fl, hn0, s->img_b);
    }
    if (excluded) {
        int i;
        for (i = 0; i < tp->n; i++)
            if (is_excluded(s, tp, i, fl)) s->img_b[i] = s->img_b2[i] = -1.0f;
    }
    s->alpha = 1.0;
    s->beta = 0.0;
    home__refine_fit_photometric(s, tp, s->img_b, s->img_b2, SIGMA_FLOOR * 1e3, s->res, s->wt);
    sigma0 = home__refine_robust_sigma(s->img_b, tp->t, tp->n, s->alpha, s->beta,
                                       (int32_t *)(void *)s->wt);
    *e0 = photometric_error(s, s->img_b, s->img_b2, sigma0, zncc0);
    *e1 = photometric_error(s, s->img_b2, s->img_b, sigma0, zncc1);
}

/* A probe's leash: the refinement gives up as soon as its estimate lies within radius of back
 * (it came back: no optimum of its own) or radius or more from h0 (it went elsewhere), or a
 * level ends without converging. */
typedef struct probe_leash {
    const double *back;
    double radius;
} probe_leash;

/* A probe's estimate came back or went elsewhere. */
static int off_leash(const home__refine_solver *s, const double *h0, const probe_leash *leash)
{
    double h[9];
    to_pixels(s, s->hn, h);
    return home__refine_max_corner_distance(s->cx, s->cy, h, leash->back) < leash->radius ||
           !(home__refine_max_corner_distance(s->cx, s->cy, h, h0) < leash->radius);
}

/* Gauss-Newton steps at `level`, at most max_iterations (at the finest level up to
 * slow_iterations while the steps keep shrinking), counted in *iterations: 1 when
 * converged (a step below STEP_EPS_PX, or at the finest level far below the estimate's own
 * predicted error: noisy frames, low light, keep the steps jittering at that scale), -1 when a
 * step fails (too few usable points, singular), else 0 (out of steps, or off a probe's leash). */
static int run_level(home__refine_solver *s, int level, int max_iterations, int slow_iterations,
                     const double *h0, const probe_leash *leash, int *iterations)
{
    double step, last_step = INFINITY, noise_std = -1.0, cap_step = 0.0;
    int it, shrinking = 0, converged = 0;
    for (it = 0; it < slow_iterations || it < max_iterations; it++) {
        /* past the cap, the finest level goes on (up to slow_iterations) only while every step
         * is shorter than the last, though not by half: template gradients that are mostly
         * noise (low light) shorten each Gauss-Newton step by about the same share, and the
         * optimum is still approached, slowly */
        if (it >= max_iterations && !(level == s->finest && shrinking)) break;
        ++*iterations;
        if (!iterate(s, level, &step)) return -1;
        if (step < STEP_EPS_PX * (double)(1 << level)) converged = 1;
        if (!converged && level == s->finest && step < NOISE_CHECK_PX * (double)(1 << level)) {
            if (!(noise_std >= 0.0)) { /* predicted once, near the optimum */
                s->resid_var = residual_variance(s);
                noise_std = corner_std_px(s);
            }
            converged = step < STEP_NOISE_SHARE * noise_std;
        }
        if (converged) {
            /* past the cap, each step was rho times the last: J^T W J held 1 / (1 - rho) times
             * the information the frames give (the rest is the template's noise) */
            if (it >= max_iterations && cap_step > 0.0) {
                const double rho = pow(step / cap_step, 1.0 / (it - max_iterations + 1));
                s->signal_share = rho < 1.0 - SIGNAL_SHARE_MIN ? 1.0 - rho : SIGNAL_SHARE_MIN;
            }
            return 1;
        }
        if (it == max_iterations - 1) cap_step = step;
        /* the reused J^T W J no longer fits the weights (steps not even halving): fresh */
        if (step > 0.5 * last_step) s->hessian_level = -1;
        /* slowly: shorter than the last step, but not by half */
        shrinking = step < last_step && step >= 0.5 * last_step;
        last_step = step;
        if (leash && off_leash(s, h0, leash)) break;
    }
    return 0;
}

/* Refine h (A -> B pixels) with the template of slot `slot` against the stored pyramid,
 * without the points of the excluded regions (NULL: none), on a probe's leash (NULL: none),
 * with a lens falloff fitted beside the motion when shading is set; stand_in: 1, a similarity
 * standing in for an undetermined homography, or STAND_IN_RIGID, a rigid motion for a similarity
 * (from the start's rotation and centre at unit scale), refused outside the STAND_IN_ limits, its
 * sigma holding the motion it leaves out (a rigid one's also RIGID_SCALE_PX), or RIGID_START,
 * that rigid motion without the limits; a model capped
 * below the homography, refused below CAPPED_MIN_SIGNAL. Writes the refined H and fills the
 * refine fields of result. */
static double refine_model(home_context *ctx, int slot, const double *h0,
                           const unsigned char *excluded, const probe_leash *leash, int patient,
                           int shading, int max_model, int stand_in, home_result *result)
{
    const home__refine_state *st = &ctx->refine;
    home__refine_solver s;
    double hn0[9], h1[9], e0, e1, zncc0, zncc1, refined_std, misfit = 0.0, signal;
    int level, k, converged = 0, iterations = 0, sparse_end = 0;
    const int rigid = stand_in == STAND_IN_RIGID || stand_in == RIGID_START;
    const double max_std =
        MAX_CORNER_STD_PX > ctx->cfg.max_sigma_px ? MAX_CORNER_STD_PX : ctx->cfg.max_sigma_px;

    home__refine_solver_setup(ctx, slot, &s);
    s.excluded = excluded;
    s.shading = shading;
    /* below a homography the update stays in the model (it is a group: I + D(dp) in it keeps
     * the estimate in it), so a few edges that leave a homography undetermined still fix it */
    s.k = 8;
    if (max_model < HOME_MODEL_HOMOGRAPHY) {
        double o[8];
        s.k = home__model_basis(HOME__SPACE_H,
                                rigid ? HOME__MODEL_RIGID : max_model, o,
                                s.basis);
    }
    /* a few sharp edges at half size (the video preset's finest level) fill fewer points than
     * FINEST_MIN_POINTS asks of faint texture; a quarter of the level's capacity lets a
     * stand-in end there (fog and dim gradients fill less, the signal share refuses the rest),
     * with a larger predicted error; a rigid motion's three parameters, fewer points (a few
     * dim edges at full size) */
    if (stand_in && s.finest != st->finest_level &&
        s.tpl[st->finest_level].n >= (rigid ? RIGID_SPARSE_POINTS
                                          : s.tpl[st->finest_level].capacity / 4)) {
        s.finest = st->finest_level;
        sparse_end = 1;
    }
    if (stand_in && s.finest != st->finest_level) {
        /* faint texture (too few points at the level the estimate should end at): nothing
         * there vouches for the similarity (fog, dim gradients, dim few edges: 86 of the tuning
         * set's 263 such stand-ins were more than 2 px off, 71 more beyond 3 sigma) */
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return 0.0;
    }
    home__refine_to_normalised(&s, h0, hn0);
    if (rigid) {
        /* the rigid motion nearest the start: its rotation and its centre's motion, unit scale */
        const double det = hn0[0] * hn0[4] - hn0[1] * hn0[3];
        if (!(det > 0.0)) {
            result->refine_status = HOME_REFINE_ILL_CONDITIONED;
            return 0.0;
        }
        for (k = 0; k < 9; k++) hn0[k] /= hn0[8];
        hn0[0] = hn0[4] = 0.5 * (hn0[0] + hn0[4]) / sqrt(det);
        hn0[3] = 0.5 * (hn0[3] - hn0[1]) / sqrt(det);
        hn0[1] = -hn0[3];
        hn0[6] = hn0[7] = 0.0;
    }
    memcpy(s.hn, hn0, sizeof hn0);
    for (level = s.finest; level < st->levels; level++) {
        if (s.tpl[level].n < MIN_POINTS) {
            result->refine_status = HOME_REFINE_FEW_POINTS;
            return 0.0;
        }
    }
    for (level = st->levels - 1; level >= s.finest; level--) {
        converged = run_level(&s, level, ctx->cfg.refine_iterations,
                              patient ? SLOW_ITERATIONS * ctx->cfg.refine_iterations : 0, h0,
                              leash, &iterations);
        if (converged < 0) {
            result->refine_iterations = iterations;
            result->refine_status = HOME_REFINE_FEW_POINTS;
            return 0.0;
        }
        if (leash && !converged) break;
    }
    result->refine_iterations = iterations;
    if (!converged) { result->refine_status = HOME_REFINE_NOT_CONVERGED; return 0.0; }
    to_pixels(&s, s.hn, h1);
    s.resid_var = residual_variance(&s);
    if (stand_in) misfit = stand_in_misfit_px(&s);
    signal = s.jtj[2 * 8 + 2] + s.jtj[5 * 8 + 5];
    remove_noise_information(&s);
    /* the share of the translation's information that is the frames', not the template's
     * gradient noise */
    signal = signal > 0.0 ? (s.jtj[2 * 8 + 2] + s.jtj[5 * 8 + 5]) / signal : 0.0;
    if (s.signal_share < 1.0)
        for (k = 0; k < 64; k++) s.jtj[k] *= s.signal_share;
    refined_std = corner_std_px(&s);
    if (refined_std > max_std || !(s.split_px <= max_std)) {
        /* how far the optimum lies from the start, in both estimates' predicted errors (the
         * split-half spread where the Fisher one is undefined) */
        const double own = isfinite(refined_std) ? refined_std : s.split_px;
        const double spread = sqrt(own * own + result->sigma_px * result->sigma_px);
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return spread > 0.0 && isfinite(spread)
                   ? home__refine_max_corner_distance(s.cx, s.cy, h1, h0) / spread : 0.0;
    }
    /* the same plausibility HOME's estimate passed: a refinement that slid towards a singular
     * H (a frame squeezed to a line keeps the photometric error low on flat content) is no
     * estimate (fuzz_api found one: tests/fuzz/corpus/api/regress-refined-singular-h) */
    if (!home__homography_plausible(h1, ctx->cfg.width, ctx->cfg.height)) {
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return 0.0;
    }
    /* like for like: both estimates over the points both keep, at the scale of HOME's */
    compare_estimates(&s, s.hn, hn0, excluded, &e0, &e1, &zncc0, &zncc1);
    result->refine_inlier_share = inlier_share(&s, s.img_b2, s.img_b);
    result->refine_error[0] = e0;
    result->refine_error[1] = e1;
    result->refine_zncc = zncc1;
    /* not lower: a divergence, or (noisy frames) the start was already the optimum within the
     * refined estimate's own uncertainty, which then stands */
    if (!(e1 < e0) &&
        !(home__refine_max_corner_distance(s.cx, s.cy, h1, h0) <= 3.0 * refined_std)) {
        result->refine_status = HOME_REFINE_NOT_LOWER;
        return 0.0;
    }
    if (!stand_in && max_model < HOME_MODEL_HOMOGRAPHY && signal < CAPPED_MIN_SIGNAL) {
        /* (before choose_model(), which writes the result's model and sigma) */
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return 0.0;
    }
    if (!choose_model(&s, max_model, rigid, h1, result) ||
        (stand_in && stand_in != RIGID_START && !(misfit <= STAND_IN_MAX_MISFIT_PX &&
                       result->sigma_px <= STAND_IN_MAX_SIGMA_PX && signal >= STAND_IN_MIN_SIGNAL))) {
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return 0.0;
    }
    /* a stand-in's error holds the perspective it leaves out (at a sparse level, both as
     * measured there), a rigid one's also the scale it holds (a prior, not a measurement) */
    result->sigma_px = sqrt(result->sigma_px * result->sigma_px + misfit * misfit);
    if (sparse_end) result->sigma_px *= SPARSE_END_SIGMA;
    if (rigid)
        result->sigma_px = hypot(result->sigma_px, RIGID_SCALE_PX);
    memcpy(result->H, h1, sizeof h1);
    result->refined = 1;
    result->refine_status = HOME_REFINE_ACCEPTED;
    return 0.0;
}

/* The refinement of the most general model cfg.max_model allows. Where that is a homography the
 * frames do not determine (a few long edges: ill conditioned, or sliding without converging)
 * and HOME's estimate is not ok (an ok line fit's homography stands), a similarity stands in
 * for it from the same start, if the perspective it leaves out is small
 * (stand_in_misfit_px()); where that is refused, or under a similarity cap the similarity is
 * not determined (edges through nearly one point leave its scale free), a rigid motion. */
double home__refine_run(home_context *ctx, int slot, const double *h0, int patient,
                        int may_stand_in, home_result *result)
{
    const home_result start = *result;
    const double apart = refine_model(ctx, slot, h0, NULL, NULL, patient, 0,
                                      ctx->cfg.max_model, 0, result);
    int stand_in;
    ctx->refine.stood_in = 0;
    /* (an ok line fit's homography stands; a similarity it fixes may still need the stand-in
     * where its scale rests on the noise) */
    if (!may_stand_in || (start.ok && ctx->cfg.max_model == HOME_MODEL_HOMOGRAPHY) ||
        (ctx->cfg.max_model != HOME_MODEL_HOMOGRAPHY &&
         ctx->cfg.max_model != HOME_MODEL_SIMILARITY))
        return apart;
    /* a similarity for a homography, then a rigid motion for a similarity whose scale the
     * edges leave free (they meet near one point: docs/trust.md, session 38) */
    for (stand_in = ctx->cfg.max_model == HOME_MODEL_HOMOGRAPHY ? 1 : STAND_IN_RIGID;
         stand_in <= STAND_IN_RIGID && (result->refine_status == HOME_REFINE_ILL_CONDITIONED ||
                                        result->refine_status == HOME_REFINE_NOT_CONVERGED);
         stand_in++) {
        home_result capped = start;
        capped.refined = 0;
        refine_model(ctx, slot, h0, NULL, NULL, patient, 0, HOME_MODEL_SIMILARITY, stand_in,
                     &capped);
        if (capped.refined) {
            *result = capped;
            ctx->refine.stood_in = 1;
            return 0.0;
        }
    }
    return apart;
}

/* Eigen-decomposition of the symmetric n x n matrix a (row stride 8, destroyed: its diagonal
 * becomes the eigenvalues) by cyclic Jacobi rotations; v's rows the eigenvectors. */
static void jacobi_eigen(double *a, int n, double v[8][8])
{
    int sweep, p, q, r;
    for (p = 0; p < n; p++)
        for (q = 0; q < n; q++) v[p][q] = p == q ? 1.0 : 0.0;
    for (sweep = 0; sweep < 32; sweep++) {
        double off = 0.0, diag = 0.0;
        for (p = 0; p < n; p++) {
            diag += a[p * 8 + p] * a[p * 8 + p];
            for (q = p + 1; q < n; q++) off += a[p * 8 + q] * a[p * 8 + q];
        }
        if (!(off > 1e-30 * diag)) return;
        for (p = 0; p < n; p++)
            for (q = p + 1; q < n; q++) {
                const double apq = a[p * 8 + q];
                double theta, t, c, sn;
                if (apq == 0.0) continue;
                theta = (a[q * 8 + q] - a[p * 8 + p]) / (2.0 * apq);
                t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                c = 1.0 / sqrt(t * t + 1.0);
                sn = t * c;
                for (r = 0; r < n; r++) { /* columns p, q, then rows p, q */
                    const double arp = a[r * 8 + p], arq = a[r * 8 + q];
                    a[r * 8 + p] = c * arp - sn * arq;
                    a[r * 8 + q] = sn * arp + c * arq;
                }
                for (r = 0; r < n; r++) {
                    const double apr = a[p * 8 + r], aqr = a[q * 8 + r];
                    a[p * 8 + r] = c * apr - sn * aqr;
                    a[q * 8 + r] = sn * apr + c * aqr;
                }
                for (r = 0; r < n; r++) {
                    const double vp = v[p][r], vq = v[q][r];
                    v[p][r] = c * vp - sn * vq;
                    v[q][r] = sn * vp + c * vq;
                }
            }
    }
}

/* The directions of the translation the data at `level` determine, about s->hn: s->basis and
 * s->k become them (a smaller model whose updates never leave it). The level's normal matrix,
 * without the noise's apparent information, is decomposed; a direction is kept when its
 * standard deviation is at most DETERMINED_STD_PX (times 2^level). A translation moves every
 * pixel alike, so that is px anywhere in the frame (a similarity's tilt, tried on a horizon,
 * came out no better than none at a predicted fraction of a px: docs/stabiliser.md). 0: none,
 * or too few points. */
static int determined_subspace(home__refine_solver *s, int level)
{
    const home__refine_state *st = s->st;
    const home__refine_points *tp = &s->tpl[level];
    const int n4 = (tp->n + LANES - 1) & ~(LANES - 1);
    const double sc = (double)(1 << level);
    const double k = s->f / (2.0 * sc);
    const double limit = DETERMINED_STD_PX * sc / s->f; /* normalised units */
    double shift[8][8], o8[8], a[64], g[8], noise[64], aq[64], unused[8], v[8][8], var;
    float m[9], aff[3];
    int i, j, kept = 0;
    const int n = home__model_basis(HOME__SPACE_H, HOME_MODEL_TRANSLATION, o8, shift);
    home__refine_level_matrix(s, s->hn, level, m);
    st->rk->warp(m, tp->x, tp->y, n4, st->pyr[level], st->w[level], st->w[level], st->h[level],
                 s->img_b);
    s->sigma = home__refine_robust_sigma(s->img_b, tp->t, tp->n, s->alpha, s->beta,
                                         (int32_t *)(void *)s->wt);
    if (home__refine_fit_photometric(s, tp, s->img_b, NULL, s->sigma, s->res, s->wt) < MIN_POINTS)
        return 0;
    level_affine(s, level, aff);
    st->rk->accumulate(tp->x, tp->y, tp->gx, tp->gy, s->res, s->wt, n4, aff, 1, s->acc);
    s->hessian_level = level;
    normal_equations(s->acc, 0xf, k, a, g);
    var = residual_variance_at(s, level);
    noise_information(s, level, var, noise);
    for (i = 0; i < 64; i++) a[i] -= noise[i];
    home__project_normal((const double(*)[8])shift, n, a, g, aq, unused);
    jacobi_eigen(aq, n, v);
    memset(s->basis, 0, sizeof s->basis);
    for (i = 0; i < n; i++) {
        /* standard deviation along eigenvector i: sqrt(var / lambda) */
        if (!(aq[i * 8 + i] > 0.0) || var / aq[i * 8 + i] > limit * limit) continue;
        for (j = 0; j < n; j++) {
            int e;
            for (e = 0; e < 8; e++) s->basis[kept][e] += v[i][j] * shift[j][e];
        }
        kept++;
    }
    s->k = kept;
    return kept > 0;
}

int home__refine_determined(home_context *ctx, int slot, double *h, double *sigma_px)
{
    const home__refine_state *st = &ctx->refine;
    home__refine_solver s;
    double hn0[9], h1[9], e0, e1, zncc0, zncc1;
    int level, converged = 0, iterations = 0;
    home__refine_solver_setup(ctx, slot, &s);
    home__refine_to_normalised(&s, home__refine_identity, s.hn);
    for (level = s.finest; level < st->levels; level++)
        if (s.tpl[level].n < MIN_POINTS) return 0;
    for (level = st->levels - 1; level >= s.finest; level--) {
        if (!determined_subspace(&s, level)) return 0;
        s.hessian_level = -1;
        /* a horizon in fog is blurred: its steps shrink slowly (up to four times the
         * refinement's iterations per level) */
        converged = run_level(&s, level, 4 * ctx->cfg.refine_iterations, 0, NULL, NULL,
                              &iterations);
        if (converged < 0) return 0;
    }
    if (!converged) return 0;
    to_pixels(&s, s.hn, h1);
    if (!home__homography_plausible(h1, ctx->cfg.width, ctx->cfg.height)) return 0;
    s.resid_var = residual_variance(&s);
    remove_noise_information(&s);
    *sigma_px = REFINE_SIGMA_SCALE * corner_std_px(&s);
    if (!(*sigma_px <= DETERMINED_STD_PX * 2.0)) return 0;
    /* the estimate explains frame B better than the identity does */
    home__refine_to_normalised(&s, home__refine_identity, hn0);
    compare_estimates(&s, s.hn, hn0, NULL, &e0, &e1, &zncc0, &zncc1);
    if (!(e1 < e0)) return 0;
    memcpy(h, h1, sizeof h1);
    return 1;
}

void home__refine_run_homography(home_context *ctx, int slot, const double *h0,
                                 home_result *result)
{
    refine_model(ctx, slot, h0, NULL, NULL, 0, 0, HOME_MODEL_HOMOGRAPHY, 0, result);
}

/* The similarity reached from the rigid motion's optimum nearest h0, both refined patiently
 * (result->refined 0 when either fails; the rigid optimum where the similarity does not lower
 * its error). Where a similarity's scale is not determined (a horizon in fog: scale and
 * translation trade along a valley), the optimum depends on the path to it, and one reached
 * from HOME's estimate directly may lie 5-10 px from this one. */
void home__refine_run_through_rigid(home_context *ctx, int slot, const double *h0,
                                    home_result *result)
{
    const home_result start = *result;
    home_result rigid;
    refine_model(ctx, slot, h0, NULL, NULL, 1, 0, HOME_MODEL_SIMILARITY, RIGID_START, result);
    if (!result->refined) return;
    rigid = *result;
    *result = start;
    result->refined = 0;
    refine_model(ctx, slot, rigid.H, NULL, NULL, 1, 0, HOME_MODEL_SIMILARITY, 0, result);
    if (result->refine_status == HOME_REFINE_NOT_LOWER) *result = rigid;
}

void home__refine_run_shaded(home_context *ctx, int slot, const double *h0, int max_model,
                             int stand_in, home_result *result)
{
    refine_model(ctx, slot, h0, NULL, NULL, 1, 1, max_model, stand_in, result);
}

double home__refine_run_without(home_context *ctx, int slot, const double *h0,
                                const unsigned char *excluded, home_result *result)
{
    return refine_model(ctx, slot, h0, excluded, NULL, 0, 0, ctx->cfg.max_model, 0, result);
}

void home__refine_probe(home_context *ctx, int slot, const double *h0, const double *back,
                        double radius, home_result *result)
{
    probe_leash leash;
    leash.back = back;
    leash.radius = radius;
    refine_model(ctx, slot, h0, NULL, &leash, 0, 0, ctx->cfg.max_model, 0, result);
}
