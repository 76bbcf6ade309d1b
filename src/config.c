/* Configuration: defaults, validation, the hash of what features depend on, and the names of
 * status codes. */
#include "home_internal.h"
#include <math.h>
#include <string.h>

const char *home_strerror(int status)
{
    switch (status) {
    case HOME_OK: return "success";
    case HOME_E_NULL: return "a required pointer argument is NULL";
    case HOME_E_SIZE:
        return "image size out of range (each side must be in [HOME_MIN_SIDE, HOME_MAX_SIDE])";
    case HOME_E_STRIDE: return "row stride is smaller than the image width";
    case HOME_E_CONFIG: return "a configuration value is out of range, NaN or infinite";
    case HOME_E_ARENA_SMALL: return "arena is smaller than home_arena_size() requires";
    case HOME_E_ARENA_ALIGN: return "arena is not aligned to HOME_ARENA_ALIGN bytes";
    case HOME_E_MISMATCH: return "features come from a different image size or configuration";
    case HOME_E_STATE: return "context or features are not initialised (or were overwritten)";
    case HOME_E_BUFFER: return "output buffer is too small";
    default: return "unknown status code";
    }
}

const char *home_failure_name(int failure)
{
    switch (failure) {
    case HOME_FAIL_NONE: return "none";
    case HOME_FAIL_FEW_MATCHES: return "few_matches";
    case HOME_FAIL_FEW_INLIERS: return "few_inliers";
    case HOME_FAIL_DEGENERATE: return "degenerate";
    case HOME_FAIL_UNCERTAIN: return "uncertain";
    case HOME_FAIL_INCONSISTENT: return "inconsistent";
    default: return "unknown";
    }
}

const char *home_refine_status_name(int status)
{
    switch (status) {
    case HOME_REFINE_OFF: return "off";
    case HOME_REFINE_ACCEPTED: return "accepted";
    case HOME_REFINE_NO_ESTIMATE: return "no_estimate";
    case HOME_REFINE_NO_SNAPSHOT: return "no_snapshot";
    case HOME_REFINE_FEW_POINTS: return "few_points";
    case HOME_REFINE_NOT_CONVERGED: return "not_converged";
    case HOME_REFINE_ILL_CONDITIONED: return "ill_conditioned";
    case HOME_REFINE_OUTSIDE_TRUST: return "outside_trust";
    case HOME_REFINE_NOT_LOWER: return "not_lower";
    case HOME_REFINE_LOW_CORRELATION: return "low_correlation";
    case HOME_REFINE_LESS_PRECISE: return "less_precise";
    case HOME_REFINE_STATIC: return "static";
    case HOME_REFINE_STILL_BACKGROUND: return "still_background";
    case HOME_REFINE_BACKGROUND_MOVES: return "background_moves";
    case HOME_REFINE_STILL_REGIONS: return "still_regions";
    case HOME_REFINE_PERIODIC: return "periodic";
    case HOME_REFINE_DENSE: return "dense";
    default: return "unknown";
    }
}

int home_default_config(home_config *cfg, int width, int height)
{
    if (!cfg) return HOME_E_NULL;
    memset(cfg, 0, sizeof *cfg);
    cfg->width = width;
    cfg->height = height;
    cfg->theta_bins = 480;
    cfg->wrap_band = 27;          /* 27 of 480 bins ~ 10 degrees */
    cfg->r_step = 1.0f;
    cfg->r_bins = 0;
    cfg->smooth_sigma = 1.3f;
    cfg->keypoints_per_sign = HOME_MAX_KEYPOINTS_PER_SIGN < 1000 ? HOME_MAX_KEYPOINTS_PER_SIGN
                                                                 : 1000;
    cfg->ratio = 0.9f;
    cfg->threshold_start = 64.0f;
    cfg->threshold_final = 1.0f;
    cfg->min_inliers = 20;
    home__refine_defaults(cfg);
    cfg->simd = HOME_SIMD_AUTO;
    cfg->hough_method = HOME_HOUGH_FAST;
    cfg->hough_downscale = 1;
    cfg->match_theta_window = 0;
    cfg->max_model = HOME_MODEL_HOMOGRAPHY;
    cfg->max_sigma_px = 1.0f;
    /* a fast pass on the 4x4-box copy where that leaves the Hough image 160 px wide or more:
     * a fraction of the time per pair, at the same errors and silent errors and with fewer
     * failures on every set of the evaluation (docs/speed.md) */
    cfg->fast_pass_downscale = width >= 640 && height >= 4 * HOME_MIN_SIDE ? 4 : 0;
    if (width < HOME_MIN_SIDE || height < HOME_MIN_SIDE || width > HOME_MAX_SIDE ||
        height > HOME_MAX_SIDE)
        return HOME_E_SIZE;
    return HOME_OK;
}

int home_video_config(home_config *cfg, int width, int height)
{
    int status = home_default_config(cfg, width, height);
    if (status != HOME_OK) return status;
    /* the largest box that leaves the Hough image at least 160 px wide */
    cfg->hough_downscale = width >= 640 && height >= 4 * HOME_MIN_SIDE ? 4
                         : width >= 320 && height >= 2 * HOME_MIN_SIDE ? 2 : 1;
    /* ~2.4 px of the Hough image at its rim: once refined as precise as more bins, and cheaper
     * (docs/presets.md) */
    cfg->theta_bins = 120;
    cfg->wrap_band = 7;           /* ~10 degrees, like the defaults' 27 of 480 */
    cfg->fast_pass_downscale = 0; /* one pass: it is as fast as a fast pass */
    cfg->keypoints_per_sign = HOME_MAX_KEYPOINTS_PER_SIGN < 500 ? HOME_MAX_KEYPOINTS_PER_SIGN : 500;
    cfg->match_theta_window = 8;  /* 12 degrees of roll between frames */
    cfg->threshold_start = 8.0f;
    /* half the refinement's points: the same errors, less work (docs/presets.md) */
    cfg->refine_points = HOME_REFINE_MAX_POINTS < 2048 ? HOME_REFINE_MAX_POINTS : 2048;
    /* the refinement ends at half size: no full-size blur, point selection or iterations, and
     * a smaller arena, for slightly larger errors (docs/presets.md) */
    cfg->refine_finest_level = cfg->refine_levels > 1 ? 1 : 0;
    return HOME_OK;
}

/* Bins needed so that |r| <= half diagonal (+1 bin of margin) fits; always even so r -> -r is
 * the mirror i -> r_bins-1-i. */
static int r_bins_for(int width, int height, float r_step)
{
    double half_diag =
        0.5 * sqrt((double)(width - 1) * (width - 1) + (double)(height - 1) * (height - 1));
    return 2 * ((int)ceil(half_diag / r_step) + 1);
}

/* Size of the image the Hough transform sees (after hough_downscale). */
void home__hough_size(const home_config *cfg, int *width, int *height)
{
    int ds = cfg->hough_downscale == 2 || cfg->hough_downscale == 4 ? cfg->hough_downscale : 1;
    *width = cfg->width / ds;
    *height = cfg->height / ds;
}

int home__r_bins(const home_config *cfg)
{
    int w, h;
    home__hough_size(cfg, &w, &h);
    return cfg->r_bins ? cfg->r_bins : r_bins_for(w, h, cfg->r_step);
}

/* Everything but the fast pass (validated as a configuration of its own, with this) */
static int validate_pass(const home_config *cfg)
{
    if (cfg->width < HOME_MIN_SIDE || cfg->height < HOME_MIN_SIDE ||
        cfg->width > HOME_MAX_SIDE || cfg->height > HOME_MAX_SIDE)
        return HOME_E_SIZE;
    if (cfg->theta_bins < 16 || cfg->theta_bins > HOME_MAX_THETA_BINS) return HOME_E_CONFIG;
    if (cfg->wrap_band < 0 || cfg->wrap_band > cfg->theta_bins / 4) return HOME_E_CONFIG;
    if (!home__finite_in(cfg->r_step, 0.25f, 8.0f)) return HOME_E_CONFIG;
    if (cfg->r_bins != 0) {
        /* an explicit r axis must be even and cover the image diagonal */
        if (cfg->r_bins < 0 || (cfg->r_bins & 1) ||
            cfg->r_bins < home__r_bins(&(home_config){.width = cfg->width, .height = cfg->height,
                                         .r_step = cfg->r_step,
                                         .hough_downscale = cfg->hough_downscale}) ||
            cfg->r_bins > 4 * HOME_MAX_SIDE)
            return HOME_E_CONFIG;
    }
    if (!home__finite_in(cfg->smooth_sigma, 0.3f, HOME__MAX_SMOOTH_RADIUS / 3.0f))
        return HOME_E_CONFIG;
    if (cfg->keypoints_per_sign < 8 || cfg->keypoints_per_sign > HOME_MAX_KEYPOINTS_PER_SIGN)
        return HOME_E_CONFIG;
    if (!home__finite_in(cfg->ratio, 0.1f, 1.0f)) return HOME_E_CONFIG;
    if (!home__finite_in(cfg->threshold_final, 0.05f, 1000.0f)) return HOME_E_CONFIG;
    if (!home__finite_in(cfg->threshold_start, cfg->threshold_final, 4096.0f)) return HOME_E_CONFIG;
    /* the halving schedule must fit HOME_MAX_THRESHOLD_LEVELS */
    if (cfg->threshold_start > cfg->threshold_final * (float)(1 << (HOME_MAX_THRESHOLD_LEVELS - 1)))
        return HOME_E_CONFIG;
    if (cfg->min_inliers < 4 || cfg->min_inliers > 2 * HOME_MAX_KEYPOINTS_PER_SIGN)
        return HOME_E_CONFIG;
    if (home__refine_validate(cfg) != HOME_OK) return HOME_E_CONFIG;
    if (!home__kernels_for(cfg->simd)) return HOME_E_CONFIG; /* unknown or not compiled in */
    if (cfg->hough_method != HOME_HOUGH_FAST && cfg->hough_method != HOME_HOUGH_EXACT)
        return HOME_E_CONFIG;
    if (cfg->hough_downscale != 1 && ((cfg->hough_downscale != 2 && cfg->hough_downscale != 4) ||
                                      cfg->hough_method != HOME_HOUGH_FAST ||
                                      cfg->width / cfg->hough_downscale < HOME_MIN_SIDE ||
                                      cfg->height / cfg->hough_downscale < HOME_MIN_SIDE))
        return HOME_E_CONFIG;
    if (cfg->match_theta_window < 0 || cfg->match_theta_window > cfg->theta_bins)
        return HOME_E_CONFIG;
    if (cfg->max_model < HOME_MODEL_IDENTITY || cfg->max_model > HOME_MODEL_HOMOGRAPHY)
        return HOME_E_CONFIG;
    if (!home__finite_in(cfg->max_sigma_px, 0.02f, 100.0f)) return HOME_E_CONFIG;
    return HOME_OK;
}

int home_validate_config(const home_config *cfg)
{
    home_config fast;
    int status;
    if (!cfg) return HOME_E_NULL;
    if ((status = validate_pass(cfg)) != HOME_OK) return status;
    if (cfg->fast_pass_downscale != 0 && cfg->fast_pass_downscale != 2 &&
        cfg->fast_pass_downscale != 4)
        return HOME_E_CONFIG;
    if (home__fast_pass_config(cfg, &fast) && validate_pass(&fast) != HOME_OK)
        return HOME_E_CONFIG;
    return HOME_OK;
}

int home__fast_pass_config(const home_config *cfg, home_config *fast)
{
    if (cfg->fast_pass_downscale <= cfg->hough_downscale || cfg->hough_method != HOME_HOUGH_FAST ||
        !cfg->refine_levels)
        return 0;
    *fast = *cfg;
    fast->fast_pass_downscale = 0;
    fast->hough_downscale = cfg->fast_pass_downscale;
    fast->r_bins = 0;
    /* half the theta bins and keypoints: on the evaluation's tuning set the same failures and
     * errors as all of them once refined, for half the work (docs/speed.md) */
    fast->theta_bins = cfg->theta_bins / 2 < 16 ? 16 : cfg->theta_bins / 2;
    fast->keypoints_per_sign = cfg->keypoints_per_sign / 2 < 8 ? 8 : cfg->keypoints_per_sign / 2;
    if (fast->wrap_band > fast->theta_bins / 4) fast->wrap_band = fast->theta_bins / 4;
    fast->match_theta_window = cfg->match_theta_window / 2;
    if (cfg->match_theta_window > 0 && fast->match_theta_window == 0) fast->match_theta_window = 1;
    return 1;
}

/* FNV-1a over the fields that change what features mean. */
uint32_t home__config_id(const home_config *cfg)
{
    uint32_t h = 2166136261u;
    int32_t fields[6];
    float ffields[2];
    const unsigned char *p;
    size_t i;
    fields[0] = cfg->width + (cfg->hough_downscale / 2 << 20); /* 1, 2, 4 -> 0, 1, 2 */
    fields[1] = cfg->height; fields[2] = cfg->theta_bins;
    fields[3] = home__r_bins(cfg); fields[4] = cfg->keypoints_per_sign; fields[5] = cfg->wrap_band;
    ffields[0] = cfg->r_step; ffields[1] = cfg->smooth_sigma;
    p = (const unsigned char *)fields;
    for (i = 0; i < sizeof fields; i++) h = (h ^ p[i]) * 16777619u;
    p = (const unsigned char *)ffields;
    for (i = 0; i < sizeof ffields; i++) h = (h ^ p[i]) * 16777619u;
    return h;
}
