/* Sub-pixel photometric refinement of HOME's homography. This file: the rule that weighs the
 * refined estimate against HOME's (home__refine_apply) and home_refine(); the snapshot, the
 * solver and the static-camera test are in refine_snapshot.c, refine_solve.c, refine_static.c.
 *
 * Method: inverse-compositional Lucas-Kanade (Baker & Matthews) of the 8 homography parameters on
 * a uint8 pyramid (3x3 binomial blur at full resolution, then 2x2 means), coarse to fine,
 * started from HOME's estimate. The template is frame A: its
 * points and gradients are chosen once per frame when it is extracted, so in video a frame costs
 * one pyramid, one point selection and a few warps of the new frame. Photometric invariance: a
 * gain and bias (alpha * B + beta ~ A) re-fitted by weighted least squares every iteration.
 * Robustness: IRLS with Cauchy weights at 2.385 sigma, sigma = 1.4826 * median |residual|, so
 * occluders and moving objects lose their pull. Every level has a fixed iteration cap.
 *
 * Template points: per level, the pixel of largest |gx| + |gy| in each block (4x4, 2x2 at the
 * third level) whose score clears a camera-noise floor, strongest first (evenly spread) up to
 * refine_points >> level (at most HOME_REFINE_MAX_POINTS). Flat regions contribute nothing to
 * LK but time.
 *
 * The estimate ends at level refine_finest_level (0: full resolution), or at the finest coarser
 * level with at least 512 template points when that one has fewer (faint texture leaves few
 * points above the noise floor at full resolution).
 *
 * Safeguards (result.refine_status): the refined H replaces HOME's only if that finest level
 * converged within its cap, the estimate is well conditioned (the corners' standard deviation
 * predicted by the Fisher information, and the disagreement of two interleaved halves of the
 * points, which also sees noise in the template's own gradients, both under max(0.5 px,
 * max_sigma_px)), and the robust photometric error over the points both warps keep went down.
 * The refined estimate then goes through model selection (src/model.c), which gives its
 * sigma_px; home__refine_apply() weighs it against HOME's (the rule in home.h at home_match).
 * Noise-only templates never converge.
 *
 * Coordinates: normalised u = (x - cx) / f, v = (y - cy) / f with cx, cy the image centre and
 * f half the longer side, so the 8 parameters are O(1) at every level. Level l pixel x_l sits at
 * full-resolution x = 2^l x_l + (2^l - 1) / 2. */
#include "refine_internal.h"
#include <math.h>
#include <string.h>

#define STATIC_SHARE 0.5     /* the identity replaces a motion when it wins this share of the
                                regions (or of the clearly decided ones) */
#define TWO_MOTIONS_SHARE 0.1 /* ... and a motion is not ok when the identity clearly wins this
                                 share of the clearly decided regions */
#define APART_SIGMAS 2.0     /* an uncertain photometric optimum this many predicted errors away
                              * from HOME's estimate contradicts it (2, 3, 5 compared on the
                              * tuning set: docs/trust.md) */
#define IDENTITY_SIGMAS 2.0  /* a motion within this many predicted errors of the identity is it */
#define PLAIN_Z 6.0          /* ... and one the identity explains the plain background better
                                than, at this significance (z score; tuning set: wrong motions
                                on static fog 11-23, right ones at most 2: docs/trust.md) */
#define BACKGROUND_EVIDENCE 5.0 /* ... and one the background would show at this z score, but
                                   does not show at a third of it (refine_background.c; tuning
                                   set: docs/trust.md) */
#define STILL_SHARE 0.4      /* ... which stands still (the refusal's refine_status) when its
                                own translation is below this share of the motion's: tuning
                                set, a hand at the lens 0.13-0.27, blocks an encoder left 0.09-
                                0.18, the background behind a textured object 0.55-1.75 */
#define VOUCH_ZNCC 0.9       /* a refined estimate vouches for itself at this correlation */
#define VOUCH_SIGMA_SHARE 0.4 /* ... and a predicted error within this share of max_sigma_px:
                                 without HOME's confirmation, the tuning set's wrong refined
                                 answers (few edges) predicted 0.44-0.66 px, 95 % of the right
                                 ones less than 0.4 */
#define VOUCH_SHARE 0.9      /* ... and this share of its points within 3 robust sigmas (both
                                against HOME's estimate or with none; either beside it) */
#define DENSE_SIGMA_SHARE 0.3 /* a motion of the dense alignment within 2 sigma_px of the
                                 identity, where it started, vouches within this share of
                                 max_sigma_px; one farther, by its model: a translation or a
                                 similarity within max_sigma_px as any answer, a homography as
                                 below, an affine motion not at all (the tuning set's few-edges
                                 and smooth-blob frames: 22 of 39 more than 2 px off at a
                                 predicted 0.12-0.95 px, docs/trust.md session 23) */
#define DENSE_FEW_SIGMA_SHARE 0.15 /* ... a homography whose information a few edges hold
                                      (spread below DENSE_SPREAD), within this share (tuning
                                      set: the few-edges frames' 1-12 px off at 0.17-0.29 px,
                                      right line-rich pairs 0.08-0.11 px) */
#define DENSE_SPREAD 0.15     /* ... a homography whose information on a shift is spread over
                                 this share of the pixels (smooth shading, not a few edges:
                                 tuning set, 0.16-0.59 where right, the few-edges scene's wrong
                                 ones 0.03-0.11) */
#define DENSE_SPREAD_SIGMA_SHARE 0.45 /* ... vouches within this share of max_sigma_px (tuning
                                         set: its right answers predicted 0.34-0.48 px, wrong
                                         ones of smooth blobs 0.52 and more) */
#define CONFIRM_SIGMAS 2.0    /* HOME's uncertain estimate and the refined one agree within this
                                 many of their combined predicted errors */
#define CONFIRM_SHARE 0.97    /* ... with this share of the refined estimate's points within 3
                                 robust sigmas (noise alone leaves 99.7 %; tuning set: moving
                                 objects over static fog 0.90-0.94, right answers 0.98 and more) */
#define SAME_OPTIMUM_FLOOR_PX 0.5 /* overruling HOME: the same optimum from another start,
                                     within 3 sigma_px or this */
#define PROBE_PX 4.0          /* probe_spread(): its starts' offset, full-size px */

/* Largest distance of the image corners under two pixel homographies (NaN: infinitely far). */
static double corner_distance(const home_context *ctx, const double *h1, const double *h2)
{
    return home__refine_max_corner_distance(0.5 * (ctx->cfg.width - 1), 0.5 * (ctx->cfg.height - 1),
                                            h1, h2);
}

/* Does the refinement reach refined's H from halfway between start and it as well? Where the
 * frame leaves the motion undetermined (a few edges, most through one point), the optimum it
 * stops at depends on where it starts, and a large move away from HOME's estimate is then no
 * evidence. */
static int same_optimum(home_context *ctx, int slot, const double *start, int patient,
                        const home_result *refined)
{
    home_result check = *refined;
    double mid[9], tolerance = 3.0 * refined->sigma_px;
    int k;
    for (k = 0; k < 9; k++) mid[k] = 0.5 * (start[k] + refined->H[k]);
    check.refined = 0; /* set again only where this refinement converges */
    home__refine_run(ctx, slot, mid, patient, 1, &check);
    if (tolerance < SAME_OPTIMUM_FLOOR_PX) tolerance = SAME_OPTIMUM_FLOOR_PX;
    return check.refined && corner_distance(ctx, check.H, refined->H) <= tolerance;
}

/* A motion refused because a part of the frame stands still becomes the rest's: refined again
 * without the regions the identity explains better (still: a still occluder, a hand at the
 * lens, drags a fit of the whole frame). Not ok all the same: the motion a caller that knows
 * the camera moves (the stabiliser) may take. */
static void refit_rest(home_context *ctx, int slot, const unsigned char *still, home_result *trial)
{
    home_result rest = *trial;
    int r, any = 0;
    for (r = 0; r < REGIONS_X * REGIONS_Y; r++) any |= still[r];
    if (!any) return;
    rest.refined = 0;
    home__refine_run_without(ctx, slot, trial->H, still, &rest);
    if (rest.refined) {
        memcpy(trial->H, rest.H, sizeof trial->H);
        trial->model = rest.model;
        trial->sigma_px = rest.sigma_px;
    }
}

static int find_slot(const home__refine_state *st, uint32_t id)
{
    if (!id) return -1;
    if (st->slot_id[0] == id) return 0;
    if (st->slot_id[1] == id) return 1;
    return -1;
}

int home__refine_determined_motion(home_context *ctx, uint32_t id_a, uint32_t id_b, double *h,
                                   double *sigma_px)
{
    home__refine_state *st = &ctx->refine;
    const int slot = find_slot(st, id_a);
    if (!st->levels || slot < 0 || st->pyr_id != id_b || !id_b) return 0;
    home__refine_settle(ctx, slot);
    return home__refine_determined(ctx, slot, h, sigma_px);
}

int home__refine_last_score(const home_context *ctx, double *observed, double *expected,
                            double *evidence)
{
    const home__refine_state *st = &ctx->refine;
    if (!st->scored) return 0;
    *observed = st->score[0];
    *expected = st->score[1];
    *evidence = st->score[2];
    return 1;
}

double home__refine_last_unexplained(const home_context *ctx)
{
    return ctx->refine.unexplained;
}

int home__refine_score_refutes(double observed, double expected, double evidence)
{
    return expected >= BACKGROUND_EVIDENCE && evidence >= BACKGROUND_EVIDENCE &&
           observed < expected / 3.0;
}

/* Under a model cap (the stabiliser asks for a similarity), the regions a change of perspective
 * moves least can prefer the identity to the capped motion while the frame's homography moves
 * them all (a camera travelling over a table). 1 when the homography refined from the capped
 * answer leaves less than TWO_MOTIONS_SHARE of the clearly decided regions to the identity: one
 * motion the cap cannot follow, not a part of the frame standing still. The unexplained share
 * is then the homography's. */
static int cap_misfit_only(home_context *ctx, int slot, const home_result *trial)
{
    home_result full = *trial;
    double clear_share, unexplained = ctx->refine.unexplained;
    int against;
    if (ctx->cfg.max_model >= HOME_MODEL_HOMOGRAPHY) return 0;
    home__refine_run_homography(ctx, slot, trial->H, &full);
    if (full.refine_status != HOME_REFINE_ACCEPTED) return 0;
    home__refine_identity_share(ctx, slot, full.H, &clear_share, &against, NULL);
    if (clear_share < TWO_MOTIONS_SHARE) return 1;
    ctx->refine.unexplained = unexplained;
    return 0;
}

/* Does the background refute h (the score test; kept for home__refine_last_score())? A lens
 * falloff fixed to the sensor stands still whatever the camera does, so on a plain background
 * it refutes every motion: a motion the test refutes is tested again with the falloff's change
 * projected out, and stands when the background then shows it (expected and evidence at least
 * BACKGROUND_EVIDENCE, at least a third of it observed). Not refuted is not enough there: with
 * the falloff taken out, the faint background of a still camera may show nothing either way,
 * and textured objects moving over it would pass (a static fog clip seen through a 15 % falloff:
 * 31 of 100 similarity answers more than 2 px off). The motion that stands is refined again
 * with the falloff fitted beside it (trial is updated); a homography or an affine motion only
 * when that refinement is accepted: refined without the falloff, those bend to it (tuning set,
 * where a falloff merely did not refute them: answers 0.8-1.5 px off at a predicted
 * 0.25-0.35 px; a few-edges pair 5.4 px off at 0.56 px). */
static int background_refutes(home_context *ctx, int slot, home_result *trial, int stands_in,
                              double *own_motion)
{
    home__refine_state *st = &ctx->refine;
    double stats[4], shaded[4];
    const int similarity = trial->model <= HOME_MODEL_SIMILARITY;
    home_result fit;
    st->scored = home__refine_background_score(ctx, st->background16[slot],
                                               st->background16[st->next_slot ^ 1], trial->H,
                                               stats, shaded);
    memcpy(st->score, stats, sizeof st->score);
    *own_motion = stats[3];
    if (!st->scored || !home__refine_score_refutes(stats[0], stats[1], stats[2])) return 0;
    fit = *trial;
    if (!(shaded[1] >= BACKGROUND_EVIDENCE && shaded[2] >= BACKGROUND_EVIDENCE &&
          shaded[0] >= shaded[1] / 3.0)) {
        /* a similarity standing in for a few long edges over a plain background that could not
         * show the motion once the falloff is out: nothing there refutes it; it stands if it
         * stands in again with the falloff fitted */
        if (!(stands_in && shaded[1] < BACKGROUND_EVIDENCE)) return 1;
        home__refine_run_shaded(ctx, slot, trial->H, HOME_MODEL_SIMILARITY, 1, &fit);
        if (fit.refine_status != HOME_REFINE_ACCEPTED) return 1;
        /* its error stays at least what the stand-in's was (the spread of the probes' optima) */
        if (fit.sigma_px < trial->sigma_px) fit.sigma_px = trial->sigma_px;
    } else {
        /* the falloff is in the frames: the motion refined again with it */
        home__refine_run_shaded(ctx, slot, trial->H, ctx->cfg.max_model, 0, &fit);
        if (!similarity && fit.refine_status != HOME_REFINE_ACCEPTED) return 1;
    }
    memcpy(st->score, shaded, sizeof st->score);
    *own_motion = shaded[3];
    if (fit.refine_status == HOME_REFINE_ACCEPTED) {
        memcpy(trial->H, fit.H, sizeof trial->H);
        trial->model = fit.model;
        trial->sigma_px = fit.sigma_px;
        trial->ok = trial->sigma_px <= ctx->cfg.max_sigma_px;
        trial->failure = trial->ok ? HOME_FAIL_NONE : HOME_FAIL_UNCERTAIN;
    }
    return 0;
}

/* Does a refined estimate vouch for itself? A predicted error within VOUCH_SIGMA_SHARE of
 * max_sigma_px, and a correlation of VOUCH_ZNCC and VOUCH_SHARE of its points within 3 robust
 * sigmas: both for the whole frame (against HOME's estimate, or without one); beside HOME's
 * estimate either, since camera noise (dim frames) holds the correlation down, not that share. */
static int vouches(const home_context *ctx, const home_result *r, int whole_frame)
{
    const int correlated = r->refine_zncc >= VOUCH_ZNCC;
    const int consistent = r->refine_inlier_share >= VOUCH_SHARE;
    return r->sigma_px <= VOUCH_SIGMA_SHARE * ctx->cfg.max_sigma_px &&
           (whole_frame ? correlated && consistent : correlated || consistent);
}

/* Do HOME's line fit, only too uncertain, and the refinement beside it confirm each other? Two
 * measurements of one motion from different evidence (lines at the Hough image's resolution,
 * the pixels' intensities) that agree within their combined predicted error, the refined one
 * vouching for the whole frame: dim frames whose line fit HOME alone cannot trust and whose
 * refinement predicts more than VOUCH_SIGMA_SHARE of max_sigma_px. */
static int confirms_uncertain(const home_context *ctx, const home_result *home,
                              const home_result *refined, double apart)
{
    return home->failure == HOME_FAIL_UNCERTAIN && isfinite(home->sigma_px) &&
           refined->sigma_px <= ctx->cfg.max_sigma_px &&
           refined->refine_zncc >= VOUCH_ZNCC && refined->refine_inlier_share >= CONFIRM_SHARE &&
           apart <= CONFIRM_SIGMAS * sqrt(home->sigma_px * home->sigma_px +
                                          refined->sigma_px * refined->sigma_px);
}

/* Does the dense alignment vouch for itself? As a refined estimate for the whole frame, but
 * by its model: a homography's perspective rests on the frame's faint periphery, and where the
 * alignment keeps it against simpler models its predicted error runs low, the more so where a
 * few edges carry the information (spread: the share of pixels that do); and a motion its
 * predicted error cannot tell from the identity may be where the alignment started and stayed */
static int dense_vouches(const home_context *ctx, const home_result *r, double spread)
{
    const int left_start = corner_distance(ctx, r->H, home__refine_identity) >
                           IDENTITY_SIGMAS * r->sigma_px;
    const double bound = !left_start                          ? DENSE_SIGMA_SHARE
                         : r->model != HOME_MODEL_HOMOGRAPHY ? 1.0
                         : spread >= DENSE_SPREAD            ? DENSE_SPREAD_SIGMA_SHARE
                                                             : DENSE_FEW_SIGMA_SHARE;
    /* an affine motion that left the start is not vouched for at any predicted error */
    if (left_start && r->model == HOME_MODEL_AFFINE) return 0;
    return r->refine_zncc >= VOUCH_ZNCC && r->refine_inlier_share >= VOUCH_SHARE &&
           r->sigma_px <= bound * ctx->cfg.max_sigma_px;
}

/* home__refine_dense() on frames id_a (slot) and id_b, or its stored answer when it ran on
 * them last with the same max_model (home_register()'s passes share the frames). */
static int dense_alignment(home_context *ctx, int slot, uint32_t id_a, uint32_t id_b,
                           home_result *dense, double *reach, double *spread)
{
    home__refine_state *st = &ctx->refine;
    if (!(st->dense_ids[0] == id_a && st->dense_ids[1] == id_b &&
          st->dense_model == ctx->cfg.max_model)) {
        st->dense_answer = *dense;
        st->dense_found = home__refine_dense(ctx, slot, &st->dense_answer, &st->dense_reach,
                                             &st->dense_spread);
        st->dense_ids[0] = id_a;
        st->dense_ids[1] = id_b;
        st->dense_model = ctx->cfg.max_model;
    }
    memcpy(dense->H, st->dense_answer.H, sizeof dense->H);
    dense->model = st->dense_answer.model;
    dense->sigma_px = st->dense_answer.sigma_px;
    dense->refine_zncc = st->dense_answer.refine_zncc;
    dense->refine_inlier_share = st->dense_answer.refine_inlier_share;
    dense->refined = st->dense_answer.refined;
    dense->refine_status = st->dense_answer.refine_status;
    *reach = st->dense_reach;
    *spread = st->dense_spread;
    return st->dense_found;
}

/* Do the template points, where they determine an optimum from the dense estimate, find it
 * there too (within 3 sigma_px of either)? A few edges over wide shaded areas: the shading
 * pulls the dense fit off what the edges say. */
static int points_agree(home_context *ctx, int slot, const home_result *dense)
{
    home_result check = *dense;
    double tolerance;
    check.refined = 0;
    home__refine_run(ctx, slot, dense->H, 0, 0, &check);
    if (!check.refined) return 1;
    tolerance = 3.0 * (check.sigma_px > dense->sigma_px ? check.sigma_px : dense->sigma_px);
    return corner_distance(ctx, check.H, dense->H) <= tolerance;
}

/* How far apart the optima lie that the refinement reaches from PROBE_PX to either side of
 * refined's H along each axis and vouches for (full-size px at the corners; 0 when every start
 * comes back). The same data from another start: a well-determined optimum is reached again
 * within the convergence tolerance. Beside an estimate HOME cannot vouch for, a homography
 * fitted to a few dim edges may stop in one of several optima, or anywhere along a flat
 * valley, each predicting a small error (docs/trust.md, session 23). The probes stop once the
 * spread exceeds `enough` (an answer that wide is refused whatever the rest would add). */
static double probe_spread(home_context *ctx, int slot, const home_result *refined,
                           int stand_in, double enough)
{
    static const double shifts[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    double spread = 0.0;
    int k;
    for (k = 0; k < 4 && spread <= enough; k++) {
        home_result probe = *refined;
        double start[9], d;
        memcpy(start, refined->H, sizeof start);
        start[2] += PROBE_PX * shifts[k][0];
        start[5] += PROBE_PX * shifts[k][1];
        probe.refined = 0;
        home__refine_run(ctx, slot, start, 0, stand_in, &probe);
        if (!probe.refined || !vouches(ctx, &probe, 0)) continue;
        d = corner_distance(ctx, probe.H, refined->H);
        if (d > spread) spread = d;
    }
    return spread;
}

/* A similarity under the similarity cap, refined from h0 where HOME cannot vouch for it (not
 * stood in): its error is at least the distance to the optimum reached through the rigid motion
 * nearest h0, and unknown where that path fails or does not vouch for itself. A similarity whose
 * scale the frames do not determine slides along a valley where scale and translation trade:
 * from HOME's uncertain estimate in fog to optima 5-12 px off at a predicted 0.6-1 px, where
 * the rigid path comes out elsewhere (docs/trust.md, session 40). */
static void widen_by_rigid_path(home_context *ctx, int slot, const double *h0, int stood_in,
                                home_result *trial)
{
    home_result other = *trial;
    double apart;
    if (stood_in || trial->model != HOME_MODEL_SIMILARITY ||
        ctx->cfg.max_model != HOME_MODEL_SIMILARITY)
        return;
    other.refined = 0;
    home__refine_run_through_rigid(ctx, slot, h0, &other);
    apart = other.refined && vouches(ctx, &other, 0) ? corner_distance(ctx, other.H, trial->H)
                                                     : INFINITY;
    if (apart > trial->sigma_px) trial->sigma_px = apart;
}

/* Widen an uncertain answer's sigma_px: the spread of the optima other starts reach, then the
 * rigid path. Both only widen it, so they stop once it exceeds `bound` (the answer is then
 * refused whatever they would add, and its sigma_px is a lower bound). */
static void widen_to_bound(home_context *ctx, int slot, const double *h0, int probe_stand_in,
                           int stood_in, double bound, home_result *trial)
{
    double spread;
    if (!(trial->sigma_px <= bound)) return;
    spread = probe_spread(ctx, slot, trial, probe_stand_in, bound);
    if (spread > trial->sigma_px) trial->sigma_px = spread;
    if (trial->sigma_px <= bound) widen_by_rigid_path(ctx, slot, h0, stood_in, trial);
}

/* Failure rule with the refinement (documented in home.h at home_match). */
void home__refine_apply(home_context *ctx, uint32_t id_a, uint32_t id_b, home_result *result)
{
    home__refine_state *st = &ctx->refine;
    home_result trial, confirmed;
    int slot, agrees, has_estimate, patient, stood_in;
    double t0 = home__now(ctx), radius, d, share, clear_share, apart;
    result->refined = 0;
    result->refine_status = HOME_REFINE_OFF;
    st->scored = 0;
    st->unexplained = 0.0;
    if (!st->levels) return;
    slot = find_slot(st, id_a);
    if (slot < 0 || st->pyr_id != id_b || !id_b) {
        result->refine_status = HOME_REFINE_NO_SNAPSHOT;
        return;
    }
    home__refine_settle(ctx, slot); /* a frame registered to itself */
    has_estimate = result->ok || ((result->failure == HOME_FAIL_FEW_INLIERS ||
                                   result->failure == HOME_FAIL_UNCERTAIN) && result->inliers >= 8);
    trial = *result;
    confirmed.ok = 0;
    /* a start HOME's lines determine (ok, or only too uncertain) is worth more iterations */
    patient = result->ok || result->failure == HOME_FAIL_UNCERTAIN;
    /* without an estimate of HOME's, direct alignment from the identity (small motion: dim,
     * faint or textureless frames give too few lines but may hold enough gradient) */
    apart = home__refine_run(ctx, slot, has_estimate ? result->H : home__refine_identity, patient,
                             1, &trial);
    stood_in = ctx->refine.stood_in;
    if (!has_estimate) {
        /* a local method vouches only within its reach: the identity is a start whose
         * uncertainty is the trust floor; and not for a homography, whose perspective nothing
         * but the photometric fit then fixes (a few dim edges: 11 of the tuning set's 12 such
         * answers were 1.9-9.4 px off at a predicted 0.2-0.4 px, docs/trust.md session 23) */
        const int may_vouch =
            trial.refined && vouches(ctx, &trial, 1) && trial.model != HOME_MODEL_HOMOGRAPHY &&
            corner_distance(ctx, trial.H, home__refine_identity) <=
                ctx->cfg.refine_trust_px * ctx->hough_scale;
        if (may_vouch && (stood_in || ctx->cfg.max_model < HOME_MODEL_HOMOGRAPHY)) {
            /* a similarity standing in, or a capped model: its error is at least the spread
             * of the optima other starts reach (vouches() then holds it to the bound) */
            widen_to_bound(ctx, slot, home__refine_identity, 1, stood_in,
                           VOUCH_SIGMA_SHARE * ctx->cfg.max_sigma_px, &trial);
        }
        if (may_vouch && vouches(ctx, &trial, 1)) {
            trial.ok = 1;
            trial.failure = HOME_FAIL_NONE;
        } else {
            /* HOME's rejected estimate and its failure stay */
            memcpy(trial.H, result->H, sizeof trial.H);
            trial.model = result->model;
            trial.sigma_px = result->sigma_px;
            trial.refined = 0;
            trial.refine_status = HOME_REFINE_NO_ESTIMATE;
        }
    } else if (trial.refined) {
        /* HOME's own precision scales with the Hough image's pixel: so does the floor */
        radius = ctx->cfg.refine_trust_px * ctx->hough_scale;
        if (isfinite(result->sigma_px) && 3.0 * result->sigma_px > radius)
            radius = 3.0 * result->sigma_px;
        d = corner_distance(ctx, trial.H, result->H);
        agrees = d <= radius;
        /* overruling HOME takes the whole frame */
        /* the wide radius only admits the refinement's move; a like-for-like choice by sigma
         * needs the two within 3 sigma of each other (else the refinement went elsewhere: to
         * moving objects the static test below can then refute, say) */
        if (agrees && result->sigma_px <= trial.sigma_px &&
            d <= 3.0 * (trial.sigma_px > result->sigma_px ? trial.sigma_px : result->sigma_px)) {
            /* consistent, and HOME's line fit predicts the smaller error: it stays */
            trial = *result;
            trial.refine_status = HOME_REFINE_LESS_PRECISE;
            trial.refine_zncc = 0.0;
        } else if (agrees ? result->ok || vouches(ctx, &trial, 0)
                          : vouches(ctx, &trial, 1) &&
                                same_optimum(ctx, slot, result->H, patient, &trial)) {
            /* a homography on the photometric evidence alone, a similarity standing in for
             * one, or a model capped below it (the stabiliser's: a few dim edges fix a
             * similarity's optimum no better than a homography's, docs/trust.md session 37):
             * its error is at least the spread of the optima other starts reach */
            if (!result->ok && (trial.model == HOME_MODEL_HOMOGRAPHY || stood_in ||
                                ctx->cfg.max_model < HOME_MODEL_HOMOGRAPHY))
                widen_to_bound(ctx, slot, result->H, stood_in, stood_in, ctx->cfg.max_sigma_px,
                               &trial);
            trial.ok = trial.sigma_px <= ctx->cfg.max_sigma_px;
            trial.failure = trial.ok ? HOME_FAIL_NONE : HOME_FAIL_UNCERTAIN;
        } else {
            /* nothing vouches for the refined H: HOME's estimate stays, as rejected (HOME's
             * uncertain estimate and the refined one may still confirm each other, below) */
            if (agrees && confirms_uncertain(ctx, result, &trial, d)) {
                confirmed = trial;
                confirmed.ok = 1;
                confirmed.failure = HOME_FAIL_NONE;
            }
            memcpy(trial.H, result->H, sizeof trial.H);
            trial.model = result->model;
            trial.sigma_px = result->sigma_px;
            trial.refined = 0;
            trial.ok = 0;
            trial.failure = agrees ? result->failure : HOME_FAIL_INCONSISTENT;
            trial.refine_status = agrees ? HOME_REFINE_LOW_CORRELATION : HOME_REFINE_OUTSIDE_TRUST;
        }
    } else if (trial.refine_status == HOME_REFINE_NOT_CONVERGED && trial.ok) {
        /* enough texture to align, yet no optimum near HOME's estimate: on the evaluation's
         * tuning set nearly every such estimate was more than 2 px off */
        trial.ok = 0;
        trial.failure = HOME_FAIL_INCONSISTENT;
    }
    /* frames too faint for HOME's lines and for the refinement's points (no failure of
     * consistency: nothing refutes another answer) may still hold a motion in the slow
     * shading of all their pixels; it vouches like direct alignment without an estimate.
     * Only with a homography to compare simpler models against: a similarity fitted alone to
     * a horizon in fog (the stabiliser's cap) predicted too little error (docs/trust.md) */
    if (!trial.ok && !result->ok && trial.failure != HOME_FAIL_INCONSISTENT &&
        ctx->cfg.max_model == HOME_MODEL_HOMOGRAPHY) {
        home_result dense = *result;
        const double reach = ctx->cfg.refine_trust_px * ctx->hough_scale;
        double dense_reach, dense_spread;
        if (dense_alignment(ctx, slot, id_a, id_b, &dense, &dense_reach, &dense_spread) &&
            dense_vouches(ctx, &dense, dense_spread) &&
            corner_distance(ctx, dense.H, home__refine_identity) <=
                (dense_reach > reach ? dense_reach : reach) &&
            points_agree(ctx, slot, &dense)) {
            trial = dense;
            trial.ok = 1;
            trial.failure = HOME_FAIL_NONE;
        }
    }
    /* where the dense alignment gives no answer either, an uncertain line fit and the refined
     * estimate that confirm each other are one (the dense answer, where it vouches, is the
     * more precise: dim shading) */
    if (!trial.ok && confirmed.ok) trial = confirmed;
    /* a motion its own predicted error cannot tell from the identity is no evidence of one; a
     * motion the static background does not share is the moving objects' */
    if (trial.ok && trial.model != HOME_MODEL_IDENTITY) {
        const double d_identity = corner_distance(ctx, trial.H, home__refine_identity);
        const int within_sigma =
            isfinite(trial.sigma_px) && d_identity <= IDENTITY_SIGMAS * trial.sigma_px;
        const int stands_in = stood_in && trial.refined && trial.model != HOME_MODEL_HOMOGRAPHY &&
                              trial.refine_status != HOME_REFINE_DENSE;
        int against = 0, identity_wins;
        unsigned char still_regions[REGIONS_X * REGIONS_Y] = {0};
        double own_motion;
        share = clear_share = 0.0;
        if (!within_sigma)
            share = home__refine_identity_share(ctx, slot, trial.H, &clear_share, &against,
                                                still_regions);
        /* the plain regions, when their pixels show the identity, outweigh the textured regions
         * that prefer the motion (the background wins by area: a flat occluder in front of
         * the lens moves with the camera and covers less). Against a similarity standing in,
         * where a few long edges are all the frame's texture, the lens falloff is fitted
         * first: it stays with the sensor, so on plain pixels it prefers the identity whatever
         * the camera did (docs/trust.md, session 34) */
        identity_wins =
            within_sigma || share >= STATIC_SHARE || clear_share >= STATIC_SHARE ||
            (home__refine_plain_regions(ctx, slot) > against &&
             home__refine_plain_background(ctx, slot, trial.H, stands_in) >= PLAIN_Z);
        if (identity_wins && !within_sigma && trial.refine_status == HOME_REFINE_DENSE) {
            /* the dense alignment's motion is what all pixels, the plain ones included, say;
             * regions that prefer the identity contradict it rather than refute it */
            trial.ok = 0;
            trial.failure = HOME_FAIL_INCONSISTENT;
        } else if (identity_wins) {
            memcpy(trial.H, home__refine_identity, sizeof trial.H);
            trial.model = HOME_MODEL_IDENTITY;
            trial.refine_status = HOME_REFINE_STATIC;
        } else if (clear_share >= TWO_MOTIONS_SHARE && !cap_misfit_only(ctx, slot, &trial)) {
            /* ... or a part of the frame clearly stands still: two motions */
            trial.ok = 0;
            trial.failure = HOME_FAIL_INCONSISTENT;
            trial.refine_status = HOME_REFINE_STILL_REGIONS;
        } else if (trial.refine_status == HOME_REFINE_ILL_CONDITIONED && apart > APART_SIGMAS) {
            /* ... or, HOME's estimate kept, the frame's own optimum (uncertain as it is) lies
             * farther from it than both predicted errors allow (static fog with moving objects:
             * HOME's lines 1-1.5 px off, the optimum 4-8 px away): neither can be vouched for */
            trial.ok = 0;
            trial.failure = HOME_FAIL_INCONSISTENT;
        } else if (background_refutes(ctx, slot, &trial, stands_in, &own_motion)) {
            /* ... or the background would show the motion clearly, and shows far less of it
             * than predicted: the moving objects' motion over a still background */
            trial.ok = 0;
            trial.failure = HOME_FAIL_INCONSISTENT;
            if (own_motion >= STILL_SHARE) {
                trial.refine_status = HOME_REFINE_BACKGROUND_MOVES;
            } else {
                trial.refine_status = HOME_REFINE_STILL_BACKGROUND;
                refit_rest(ctx, slot, still_regions, &trial);
            }
        }
    }
    /* a repeated pattern whose alias one period away explains the frame about as well: which
     * of the two is right, nothing in the pair tells */
    if (trial.ok) {
        double period;
        if (home__refine_aliased(ctx, slot, trial.H, &period)) {
            trial.ok = 0;
            trial.failure = HOME_FAIL_UNCERTAIN;
            trial.refine_status = HOME_REFINE_PERIODIC;
            if (!(trial.sigma_px >= period)) trial.sigma_px = period;
        }
    }
    *result = trial;
    result->ms[HOME_STAGE_REFINE] += home__now(ctx) - t0;
}

int home_refine(home_context *ctx, const uint8_t *a, ptrdiff_t stride_a, const uint8_t *b,
                ptrdiff_t stride_b, const double *h_init, home_result *result)
{
    double t0;
    uint32_t id_a, id_b;
    int k, status;
    if (!ctx || !result || !h_init) return HOME_E_NULL;
    if (ctx->magic != HOME__MAGIC_CTX) return HOME_E_STATE;
    if ((status = home__check_image(ctx, a, stride_a)) != HOME_OK) return status;
    if ((status = home__check_image(ctx, b, stride_b)) != HOME_OK) return status;
    for (k = 0; k < 9; k++)
        if (!isfinite(h_init[k])) return HOME_E_CONFIG;
    if (!(fabs(h_init[8]) > 1e-12)) return HOME_E_CONFIG;
    memset(result, 0, sizeof *result);
    for (k = 0; k < 9; k++) result->H[k] = h_init[k] / h_init[8];
    /* the refinement may move the caller's estimate by refine_trust_px, farther only when the
     * photometric fit vouches for the whole frame */
    result->ok = 1;
    result->model = HOME_MODEL_HOMOGRAPHY;
    result->sigma_px = INFINITY; /* unknown: any refined estimate is more precise */
    t0 = home__now(ctx);
    id_a = home__refine_store(ctx, a, stride_a, 0);
    id_b = home__refine_store(ctx, b, stride_b, 1);
    result->ms[HOME_STAGE_REFINE] = home__now(ctx) - t0;
    home__refine_apply(ctx, id_a, id_b, result);
    result->ok = result->refined && result->ok;
    result->ms[HOME_STAGE_TOTAL] = result->ms[HOME_STAGE_REFINE];
    return HOME_OK;
}
