/* The photometric refinement's parts (src/refine*.c): the per-frame snapshot
 * (refine_snapshot.c), the Gauss-Newton solver (refine_solve.c), the static-camera test
 * (refine_static.c) and the rule that weighs it all against HOME's estimate (refine.c). */
#ifndef HOME_REFINE_INTERNAL_H
#define HOME_REFINE_INTERNAL_H

#include "home_internal.h"

#define LANES HOME__REFINE_LANES
#define N_ACC HOME__REFINE_ACC
#define CAUCHY_K 2.385     /* 95 % efficiency at Gaussian noise */
#define SIGMA_FLOOR 0.5     /* grey levels: the residual scale never collapses below this */
#define MIN_POINTS 64       /* fewer usable template points at a level: textureless, decline */
#define FINEST_MIN_POINTS 512 /* the level the estimate ends at needs this many points (or half
                                 its capacity, if less), else the next coarser one is the finest
                                 (faint texture: less noise there). With the stabiliser's small
                                 budget, a few edges never fill 512 at half size: ending a level
                                 coarser gave wrong optima 2-5 px off at sigma 0.6-0.9 */
#define REFINE_SIGMA_SCALE 1.5 /* predicted errors are the Fisher covariance's times this
                                  (calibrated on the evaluation's tuning set: neighbouring
                                  template points do not carry independent noise) */
#define REGIONS_X 8          /* the identity test's grid of regions (refine_static.c) */
#define REGIONS_Y 6
#define REGION_TOP 8         /* the identity test's points per region: the strongest blocks */
#define REGION_WEAK_SCORE 2  /* ... or, where none pass the level's floor, the blocks with a score
                                |gx| + |gy| (2x central differences) of at least this */
#define REGION_CAPACITY (REGIONS_X * REGIONS_Y * REGION_TOP)
typedef char home__regions_fit[REGIONS_X * REGIONS_Y <= HOME__MAX_REGIONS ? 1 : -1];

/* One refinement: the template, the estimate and the solver's state. */
typedef struct home__refine_solver {
    const home__refine_state *st;
    const home__refine_points *tpl;     /* template (frame A) points, one per level */
    double f, cx, cy;                   /* normalisation */
    double hn[9];                       /* A -> B in normalised coordinates */
    double alpha, beta;                 /* photometric model alpha * B + beta ~ A */
    double sigma;                       /* residual scale of the last iteration */
    double jtj[64];                     /* last weighted normal matrix (normalised units) */
    float acc[N_ACC * LANES];           /* per-lane sums of the normal equations */
    int hessian_level;                  /* level whose J^T W J acc holds (-1: none yet) */
    double resid_var;                   /* weighted residual variance of the last iteration
                                           (set once the finest level converged) */
    double split_px;                    /* split-half disagreement of the last finest step */
    double jtr[8];                      /* J^T W r of the last iteration (all 8 parameters) */
    double step[8];                     /* ... and the update it took (within the model) */
    int finest;                         /* level the estimate ends at */
    int k;                              /* parameters of the model fitted (8: a homography) */
    double basis[8][8];                 /* the update's subspace dp = B q when k < 8 */
    float *img_b, *img_b2, *res, *wt;   /* per-point scratch */
    const unsigned char *excluded;      /* per region of the identity test's grid: its points
                                           take no part where nonzero (NULL: every point
                                           does) */
    int mask_level;                     /* the level img_b2 holds the points' mask for */
    double signal_share;                /* the share of the finest J^T W J that is the
                                           frames' information, where its slow steps tell */
    int shading;                        /* fit a lens falloff fixed to the sensor too */
    double kappa;                       /* ... its depth s = 1 - kappa rho^2 (0 at the start) */
    double rho_scale;                   /* rho^2 = rho_scale |(u, v)|^2 in normalised units:
                                           1 at the frame's corners */
} home__refine_solver;

extern const double home__refine_identity[9];

/* The identity test's grid on a w x h level: x * REGIONS_X / w by a multiply with m = 2^32 / w
 * rounded up (armv7 has no divide instruction; a loop over pixels would call one per pixel).
 * Exact: m w - 2^32 < w, so the product errs by less than x REGIONS_X / 2^32 < 1 / w. */
typedef struct region_grid {
    uint32_t mx, my;
} region_grid;

static inline region_grid region_grid_for(int w, int h)
{
    region_grid g;
    g.mx = 0xffffffffu / (uint32_t)w + 1u;
    g.my = 0xffffffffu / (uint32_t)h + 1u;
    return g;
}

/* Region of a level pixel (0 <= x < w, 0 <= y < h) in the identity test's grid. */
static inline int region_at(region_grid g, int x, int y)
{
    return (int)(((uint64_t)(uint32_t)(y * REGIONS_Y) * g.my) >> 32) * REGIONS_X +
           (int)(((uint64_t)(uint32_t)(x * REGIONS_X) * g.mx) >> 32);
}

static inline int region_of(int x, int y, int w, int h)
{
    return region_at(region_grid_for(w, h), x, y);
}

/* The acceptance test's error per point: Geman-McClure, bounded like the Cauchy weights'
 * influence and made of IEEE operations only (no libm), so every platform decides alike. */
static inline double robust_cost(double r, double c)
{
    double q = r / c;
    return 0.5 * r * r / (1.0 + q * q);
}

/* refine_snapshot.c: points a match-time scratch buffer holds */
int home__refine_match_capacity(const home_config *cfg);

/* refine_solve.c */
/* 3x3 row-major product out = a b; inverse (0 when singular) */
void home__refine_mat3_mul(const double *a, const double *b, double *out);
int home__refine_mat3_inv(const double *m, double *out);
void home__refine_solver_setup(home_context *ctx, int slot, home__refine_solver *s);
void home__refine_to_normalised(const home__refine_solver *s, const double *h, double *hn);
/* Normalised hn (u = (x - c) / f) as a homography of pixels, h8 = 1. */
void home__refine_pixels_from_normalised(double f, double cx, double cy, const double *hn,
                                         double *h);
/* The same map between images whose pixel x sits at full size scale x + offset: m (3x3). */
void home__refine_scaled_matrix(double f, double cx, double cy, const double *hn, double scale,
                                double offset, double *m);
void home__refine_level_matrix(const home__refine_solver *s, const double *hn, int level,
                               float *m);
double home__refine_robust_sigma(const float *img_b, const int16_t *t, int n, double alpha,
                                 double beta, int32_t *bins);
int home__refine_fit_photometric(home__refine_solver *s, const home__refine_points *tp,
                                 const float *img_b, const float *mask, double sigma, float *res,
                                 float *wt);
double home__refine_max_corner_distance(double cx, double cy, const double *h1,
                                        const double *h2);
/* Refine h0 (A -> B pixels) with the template of slot `slot` against the stored pyramid:
 * the refined H and the refine fields of result. patient (a start HOME vouches for): the
 * finest level may go on past the iteration cap while its steps keep shrinking (noisy
 * templates approach the optimum slowly). */
/* Returns, when it converged but the optimum is too uncertain to use (ILL_CONDITIONED), how far
 * the optimum lies from h0 in units of both estimates' predicted errors (result->sigma_px on
 * entry is h0's); else 0. may_stand_in: where the homography is not determined and HOME's
 * estimate (result->ok on entry) is not ok, a similarity may stand in for it (sets
 * ctx->refine.stood_in); probes of a homography's own optima pass 0. */
double home__refine_run(home_context *ctx, int slot, const double *h0, int patient,
                        int may_stand_in, home_result *result);
/* The same (not patient) as a homography, whatever cfg.max_model caps the answer to: the
 * motion the frame's pixels give where a capped model misfits them. */
void home__refine_run_homography(home_context *ctx, int slot, const double *h0,
                                 home_result *result);
/* The similarity reached from the rigid motion's optimum nearest h0 (both refined patiently;
 * the rigid optimum where the similarity does not lower its error; result->refined 0 when
 * either fails): another path to a capped similarity's optimum. */
void home__refine_run_through_rigid(home_context *ctx, int slot, const double *h0,
                                    home_result *result);
/* The same (patient) up to max_model, fitting beside the motion a lens falloff fixed to the
 * sensor, s = 1 - kappa rho^2 (rho^2 = 1 at the corners): frames whose background shows one,
 * or a similarity standing in (stand_in: home__refine_run()'s conditions on it). */
void home__refine_run_shaded(home_context *ctx, int slot, const double *h0, int max_model,
                             int stand_in, home_result *result);
/* The same without the points of the regions excluded flags (the identity test's grid): the
 * motion of the rest of the frame. */
double home__refine_run_without(home_context *ctx, int slot, const double *h0,
                                const unsigned char *excluded, home_result *result);
/* The same from h0 as a probe for another optimum: given up (not refined) as soon as the
 * estimate lies within radius (full-size px at the corners) of back or radius or more from h0,
 * or a level does not converge. */
void home__refine_probe(home_context *ctx, int slot, const double *h0, const double *back,
                        double radius, home_result *result);

/* The stabiliser's fallback where a frame holds too little structure for a motion (a horizon
 * in fog): from the identity, only the directions of a translation that the data determine
 * (src/refine_solve.c), none in the others. 1 with h (A -> B pixels) and its predicted error
 * when it converged, determines something and fits B better than the identity. */
int home__refine_determined(home_context *ctx, int slot, double *h, double *sigma_px);

/* refine_static.c */
/* h (full-size pixels) as a map of background pixels, into m. */
void home__refine_background_matrix(const home__refine_state *st, const double *h, double *m);
/* still (optional, REGIONS_X * REGIONS_Y): 1 for the regions the identity explains better. */
double home__refine_identity_share(home_context *ctx, int slot, const double *h,
                                   double *clear_share, int *against, unsigned char *still);
/* Mean robust cost of the region points under each of the k motions hs (pixels), each with
 * its own gain and bias, at the scale of the first one's residuals; INFINITY where a motion is
 * missing (NULL). */
void home__refine_region_costs(home_context *ctx, int slot, const double *const *hs, int k,
                               double *cost);
/* Regions of frame A with no block above the textured floor (faint or flat). */
int home__refine_plain_regions(const home_context *ctx, int slot);
/* How much better the identity than h (pixels) explains frame A's plain regions (no block
 * above the textured floor: fog, sky, a flat wall), every pixel of them in the background image:
 * the sum of the differences of the two robust costs over its own spread (a z score; positive:
 * the identity is better; 0 with too few plain regions or pixels). Their few faint
 * points cannot decide a region's vote, but all their pixels together can: a horizon in fog,
 * the blocks an encoder left unchanged. fit_falloff: h's side also fits a lens falloff fixed
 * to the sensor (s = 1 - kappa rho^2, rho^2 = 1 at the corners), which always prefers the
 * identity on plain pixels whatever the camera did. */
double home__refine_plain_background(home_context *ctx, int slot, const double *h,
                                     int fit_falloff);

/* refine_background.c: the score test of h (pixels, A -> B) on the fine backgrounds a and b
 * (background16 images: refine.background_w x background_h) at the pixels away from texture,
 * into stats[4]: observed, the identity's residual projected on the one h predicts, over its
 * noise (about N(0, 1) if the background stands still); expected, the same if h were the
 * background's motion; evidence, expected over the spread of its per-pixel terms; own motion,
 * the translation the background shows by itself (least squares on its gradient) over h's RMS
 * displacement there (about 0 if it stands still, below 1 if a part of it moves with h, large
 * if it moves otherwise). Every fourth row is tested first: where the background there
 * already shows the motion (observed at least two thirds of expected, both expected and
 * evidence at least 5), those rows' statistics are returned. shaded[4]: the same from the
 * same sums with a lens falloff's change under h projected out (see the file), screened
 * alike. Returns 0 (stats all 0) when there is too little background or no
 * refinement. Uses the match-time scratch. */
int home__refine_background_score(home_context *ctx, const uint16_t *a, const uint16_t *b,
                                  const double *h, double *stats, double *shaded);

/* refine_dense.c: frames A (slot) and B aligned from the identity with every pixel of their
 * background16 images and two 2x2 means of them, in the most general model cfg.max_model
 * allows, coarse to fine. 1 with result's H, model, sigma_px, refine_zncc and
 * refine_inlier_share (refine_status HOME_REFINE_DENSE) when it converged to a determined,
 * plausible motion; else 0 (result's refine_status may say why). *reach_px: 1 + the length
 * of its start's shift, in pixels of its coarsest image, as full-size px (how far from the
 * identity it reaches). *spread: the share of
 * its finest image's pixels that carry the information on a shift, (sum g)^2 / (n sum g^2) with
 * g a pixel's weighted squared gradient (near 1: smooth shading everywhere; small: a few
 * edges). Uses st->sampled and st->smoothed_b. */
int home__refine_dense(home_context *ctx, int slot, home_result *result, double *reach_px,
                       double *spread);

/* refine_alias.c: 1 when the refinement, started from h shifted by one period of frame A's
 * repeated pattern either way (periods along a few directions, up to three of them tried),
 * reaches an optimum away from h that explains the identity test's region points about as
 * well as h (mean robust cost within a bound), with that period (full-size px) in *period;
 * else 0. Uses the match-time scratch. */
int home__refine_aliased(home_context *ctx, int slot, const double *h, double *period);

#endif
