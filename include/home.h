/* libhome: HOME (Hough-space One-dimensional Matching of Extrema) frame registration.
 *
 * Pipeline: grey uint8 image -> texture-preserving Hough transform J(theta, r) -> Hough-space
 * extrema as keypoints -> 1x16 uint8 radial descriptors -> L1 matching with a ratio test, same
 * sign only -> homography from line correspondences by deterministic threshold halving + LM.
 *
 * Memory: the library never allocates. home_arena_size() tells how many bytes a context needs;
 * home_init() lays the context out in a caller buffer aligned to HOME_ARENA_ALIGN. Features
 * (home_features) are plain fixed-size structs the caller owns, so a video frame's features are
 * extracted once and reused when the next frame is registered against it.
 *
 * Coordinates: pixel (x, y), x right, y down, centre of the top-left pixel = (0, 0). Hough lines
 * are in centred coordinates xc = x - (W-1)/2, yc = y - (H-1)/2: xc*cos(theta) + yc*sin(theta) = r,
 * theta in [0, pi). H maps image A's pixel coordinates to image B's, normalised to H[8] = 1.
 *
 * Threading: a context is used by one thread at a time; distinct contexts are independent.
 */
#ifndef HOME_H
#define HOME_H

#include <stddef.h>
#include <stdint.h>
#include "home_limits.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HOME_VERSION_MAJOR 0
#define HOME_VERSION_MINOR 1
#define HOME_VERSION_PATCH 0
#define HOME_VERSION_STRING "0.1.0"

/* Required alignment of the arena passed to home_init(). */
#define HOME_ARENA_ALIGN 16

/* Status codes: HOME_OK or a negative error. A registration that runs but does not find a
 * trustworthy homography is not an error: it returns HOME_OK with result.ok == 0. */
typedef enum home_status {
    HOME_OK = 0,
    HOME_E_NULL = -1,        /* a required pointer is NULL */
    HOME_E_SIZE = -2,        /* width/height outside [HOME_MIN_SIDE, HOME_MAX_SIDE] */
    HOME_E_STRIDE = -3,      /* stride smaller than the width */
    HOME_E_CONFIG = -4,      /* a config value is out of range, NaN or Inf */
    HOME_E_ARENA_SMALL = -5, /* arena smaller than home_arena_size() */
    HOME_E_ARENA_ALIGN = -6, /* arena not aligned to HOME_ARENA_ALIGN */
    HOME_E_MISMATCH = -7,    /* features from a different image size or config */
    HOME_E_STATE = -8,       /* context or features not initialised (or overwritten) */
    HOME_E_BUFFER = -9       /* reserved: no function returns it today */
} home_status;

/* Human-readable explanation of a status code (never NULL). */
const char *home_strerror(int status);

/* Optional timing hook: returns a monotonic time in milliseconds. The core has no OS clock. */
typedef double (*home_clock_fn)(void *user);

/* SIMD backend of a context. Every backend gives bit-identical results. AUTO (the default)
 * takes the environment variable HOME_SIMD=none|sse|avx2|neon when set (compile the library
 * with -DHOME_NO_GETENV for targets without an environment), else picks NEON on ARM, AVX2 on
 * x86-64 CPUs that have it (SSE2 for everything but the Hough kernel), else SSE2. */
enum home_simd {
    HOME_SIMD_AUTO = 0,
    HOME_SIMD_NONE,
    HOME_SIMD_SSE,
    HOME_SIMD_NEON,
    HOME_SIMD_AVX2
};

/* How J(theta, r) is computed. FAST: shear-and-add line sums of the image (one channel, exact
 * integer sums along nearest-pixel digital lines, SIMD), differentiated across lines with the
 * line ends handled exactly. EXACT: the paper's definition pixel by pixel (gradient summed into
 * nearest r bins), the slow reference. */
enum home_hough_method { HOME_HOUGH_FAST = 0, HOME_HOUGH_EXACT };

/* Motion models, simplest first (result.model; cfg.max_model caps the choice). */
enum home_model {
    HOME_MODEL_IDENTITY = 0,  /* no motion */
    HOME_MODEL_TRANSLATION,   /* 2 parameters */
    HOME_MODEL_SIMILARITY,    /* rotation, isotropic scale, translation: 4 */
    HOME_MODEL_AFFINE,        /* 6 */
    HOME_MODEL_HOMOGRAPHY     /* 8 */
};

/* Name of a model ("identity", ..., "homography"; "unknown" when out of range). */
const char *home_model_name(int model);

typedef struct home_config {
    int width, height;        /* image size; both frames of a pair must have it */
    int theta_bins;           /* bins over [0, pi); paper: 480 */
    int wrap_band;            /* keypoints within this many theta bins of 0/pi are also matched
                                 in their alternate form (theta +- pi, -r, -sign); ~10 deg */
    float r_step;             /* px per r bin; 1.0 (the paper used 640 bins for the diagonal) */
    int r_bins;               /* 0 = derive from r_step so the image diagonal is covered */
    float smooth_sigma;       /* Gaussian smoothing of J, in bins; paper: 1.3 */
    int keypoints_per_sign;   /* top-K extrema kept per sign of J; paper: 1000 */
    float ratio;              /* Lowe ratio test; 0.9 (paper's baselines used 0.75) */
    float threshold_start;    /* first inlier threshold, Hough pixels; halved down to ... */
    float threshold_final;    /* ... this final threshold; paper: 1.0 */
    int min_inliers;          /* fewer final inliers -> failure; paper: 20 (twice this with
                                 hough_downscale > 1, see the failure rule at home_match) */
    /* photometric refinement of HOME's H (home_refine() below); refine_levels = 0 turns it off */
    int refine_levels;        /* pyramid levels, 1..HOME_REFINE_MAX_LEVELS; default 3 */
    int refine_iterations;    /* Gauss-Newton iteration cap per level; default 10 (from a
                                 start HOME's lines determine, the finest level may go on to
                                 4x while its steps keep shrinking slowly: noisy frames) */
    float refine_trust_px;    /* corner motion from HOME's H the refinement may always make,
                                 in px of the Hough image (x hough_downscale in the image);
                                 beyond it, and beyond 3x HOME's predicted error, the two
                                 disagree (see the failure rule at home_match); default 6 */
    int refine_points;        /* template points at full resolution (halved per coarser level,
                                 at least 64), 64..HOME_REFINE_MAX_POINTS; default the maximum
                                 (4096): fewer cost proportionally less per iteration */
    int refine_finest_level;  /* pyramid level the refinement ends at: 0 = full resolution
                                 (default); 1 = half: no full-size point selection or
                                 iterations (a faster refinement, a larger error; see
                                 docs/presets.md) */
    int simd;                 /* enum home_simd */
    int hough_method;         /* enum home_hough_method */
    int hough_downscale;      /* 1: Hough transform of the image itself; 2 or 4: of its 2x2- or
                                 4x4-box downscaled copy (FAST only): 4x or 16x less Hough work,
                                 for video on small cores (the photometric refinement restores
                                 full-resolution precision); r bins are then ds*r_step px */
    int max_model;            /* enum home_model: the most general model considered; default
                                 HOMOGRAPHY (the stabiliser asks for SIMILARITY) */
    float max_sigma_px;       /* ok needs a predicted RMS corner error (result.sigma_px) at
                                 most this, px; 0.02..100, default 1 */
    int match_theta_window;   /* video motion prior: 0 = off (default, still pairs); N > 0 =
                                 a keypoint is only compared with keypoints whose theta lies
                                 within N bins of its own (the frame rotates less than that) */
    int fast_pass_downscale;  /* home_register() only: 2 or 4 = first a fast pass (the Hough
                                 transform of a 2x2- or 4x4-box downscaled copy, half the theta
                                 bins and keypoints, the same refinement) and the configured
                                 pass only when the fast one's answer is not ok; 0 = one pass.
                                 The fast answer stands only when its sigma_px is at most
                                 0.2. Runs with the FAST transform and the refinement, when
                                 this exceeds hough_downscale (else one pass). Default 4 from
                                 640 x 4 * HOME_MIN_SIDE up (the same errors and silent errors
                                 in the evaluation, in a fraction of the time: docs/speed.md),
                                 else 0; the video preset 0 */
    home_clock_fn clock;      /* optional: per-stage timings in home_result.ms */
    void *clock_user;
} home_config;

/* Fill cfg with the paper's defaults for a width x height image. */
int home_default_config(home_config *cfg, int width, int height);

/* Defaults for consecutive video frames (small motion between them, registered against cached
 * features): the Hough transform of a box-downscaled frame about 160 px wide with 120 theta
 * bins, 500 keypoints per sign, an 8-bin (12 degree) theta window, a first threshold of 8;
 * the photometric refinement (2048 template points, ending at half resolution:
 * refine_finest_level 1; set it to 0 for full resolution at more cost) restores
 * sub-pixel precision. Motion between
 * the frames should stay under ~30 px at the corners (docs/speed.md). */
int home_video_config(home_config *cfg, int width, int height);

/* HOME_OK when every field is in range. */
int home_validate_config(const home_config *cfg);

typedef struct home_context home_context;

/* Name of the SIMD backend a context uses ("none", "sse", "avx2", "neon"); with ctx == NULL, the
 * backend HOME_SIMD_AUTO would pick here ("unavailable" when HOME_SIMD names one this build or
 * CPU lacks). */
const char *home_simd_backend(const home_context *ctx);

/* Exact bytes home_init() needs for cfg; 0 when cfg is invalid. */
size_t home_arena_size(const home_config *cfg);

/* Lay a context out in arena (aligned to HOME_ARENA_ALIGN). On HOME_E_ARENA_SMALL, *needed (if
 * not NULL) receives the size required. The config is copied. */
int home_init(home_context **ctx, const home_config *cfg, void *arena, size_t arena_bytes,
              size_t *needed);

/* One keypoint: a Hough-space extremum, i.e. a line with a sign (bright-to-dark or reverse). */
typedef struct home_keypoint {
    float theta;              /* radians, [0, pi) */
    float r;                  /* px, centred coordinates */
    float saliency;           /* |det H / tr H| of J at the extremum */
    int8_t sign;              /* +1 or -1: sign of J */
    uint8_t has_alt;          /* near the theta wrap: alt_desc is valid */
    uint8_t desc[HOME_DESC_LEN];
    uint8_t alt_desc[HOME_DESC_LEN]; /* descriptor of (theta +- pi, -r, -sign) */
    double cos_theta, sin_theta;     /* cos and sin of (double)theta, the line's normal: set by
                                        home_extract(), read by matching (edit theta, set them) */
} home_keypoint;

/* A frame's features. Caller-owned; fill with home_extract(). Positive keypoints come first
 * (kp[0 .. n_pos)), then negative ones, each sorted by decreasing saliency. */
typedef struct home_features {
    uint32_t magic;           /* set by home_extract() */
    uint32_t config_id;       /* fingerprint of the config that made them */
    int width, height;
    int n_pos, n_neg;
    float j_std;              /* standard deviation of J (quantisation scale) */
    double ms_hough, ms_detect, ms_describe; /* extraction timings when a clock is set */
    uint32_t frame_id;        /* refinement snapshot of this frame in the context (0: none) */
    double ms_refine;         /* time spent on that snapshot */
    home_keypoint kp[2 * HOME_MAX_KEYPOINTS_PER_SIGN];
} home_features;

/* Extract features of one grey image (width x height from the config, rows stride bytes apart). */
int home_extract(home_context *ctx, const uint8_t *image, ptrdiff_t stride, home_features *out);

enum home_stage {
    HOME_STAGE_HOUGH, HOME_STAGE_DETECT, HOME_STAGE_DESCRIBE, HOME_STAGE_MATCH,
    HOME_STAGE_HOMOGRAPHY, HOME_STAGE_REFINE, HOME_STAGE_TOTAL, HOME_STAGE_COUNT
};

/* Why a registration did not succeed (result.ok == 0). */
enum home_failure {
    HOME_FAIL_NONE = 0,
    HOME_FAIL_FEW_MATCHES,    /* too few matches to estimate a homography */
    HOME_FAIL_FEW_INLIERS,    /* fewer than min_inliers (2x with hough_downscale > 1) at the
                                 final threshold */
    HOME_FAIL_DEGENERATE,     /* det(H / H22) <= 0, an image corner mapped behind the camera
                                 (w <= 0), the frame mapped to a non-convex, flipped or
                                 collapsed quadrilateral, or a numerically unusable estimate */
    HOME_FAIL_UNCERTAIN,      /* no model up to max_model is determined by the inliers, or the
                                 predicted error (sigma_px) is above max_sigma_px */
    HOME_FAIL_INCONSISTENT    /* the refinement converged far from HOME's estimate (beyond
                                 its uncertainty) and cannot vouch for its own, or the frame
                                 holds two motions: regions the identity clearly explains
                                 better (a static background) beside the estimate's */
};

/* Name of a failure ("none", "few_matches", ...; "unknown" when out of range). */
const char *home_failure_name(int failure);

/* What the photometric refinement did (result.refine_status). */
enum home_refine_status {
    HOME_REFINE_OFF = 0,          /* refine_levels == 0 */
    HOME_REFINE_ACCEPTED,         /* H is the refined estimate (result.refined == 1) */
    HOME_REFINE_NO_ESTIMATE,      /* HOME found no homography to start from */
    HOME_REFINE_NO_SNAPSHOT,      /* a is not in the context's last two extracted frames, or b
                                     is not the last one (see home_match) */
    HOME_REFINE_FEW_POINTS,       /* too little texture: fewer than 64 usable template points */
    HOME_REFINE_NOT_CONVERGED,    /* the finest level used hit its iteration cap */
    HOME_REFINE_ILL_CONDITIONED,  /* corner standard deviation above max(0.5 px, max_sigma_px)
                                     (predicted, or from two interleaved halves of the points),
                                     no model determined, or the refined H fails
                                     HOME_FAIL_DEGENERATE's plausibility rule */
    HOME_REFINE_OUTSIDE_TRUST,    /* the refined H is farther from HOME's than refine_trust_px
                                     and 3x HOME's sigma_px, and cannot vouch for itself */
    HOME_REFINE_NOT_LOWER,        /* the photometric error did not go down */
    HOME_REFINE_LOW_CORRELATION,  /* HOME failed and the refinement cannot vouch (rule below) */
    HOME_REFINE_LESS_PRECISE,     /* the refined H agrees with HOME's but predicts a larger
                                     error (sigma_px): HOME's H stays */
    HOME_REFINE_STATIC,           /* a motion most of the frame's regions do not share
                                     (moving objects), or one within 2 sigma_px of the
                                     identity: H is the identity */
    HOME_REFINE_STILL_BACKGROUND, /* the frame's plain background (fog, a flat wall) stays
                                     where the motion would move it: the moving objects'
                                     motion (or the camera's, with a plain occluder such as a
                                     hand at the lens standing still), not ok
                                     (HOME_FAIL_INCONSISTENT) */
    HOME_REFINE_BACKGROUND_MOVES, /* the plain background does not move as the motion would
                                     move it, nor stands still: a third motion (a textured
                                     object's, with the camera moving), not ok
                                     (HOME_FAIL_INCONSISTENT) */
    HOME_REFINE_STILL_REGIONS,    /* a tenth of the regions that clearly decide prefer the
                                     identity: a part of the frame stands still while the
                                     motion moves the rest, not ok (HOME_FAIL_INCONSISTENT);
                                     under a max_model cap, also against the homography the
                                     frame's pixels give (a cap's misfit is not a still part) */
    HOME_REFINE_PERIODIC,         /* a repeated pattern: the motion one period along it fits
                                     about as well, so the pair cannot tell which is right;
                                     sigma_px at least the period, not ok (HOME_FAIL_UNCERTAIN) */
    HOME_REFINE_DENSE             /* frames too faint for HOME and for the refinement's points
                                     (slow shading, a soft shadow): aligned from the identity
                                     with every pixel of their quarter-size images (a
                                     homography, then the simplest model it supports) */
};

/* Name of a refinement status ("off", "accepted", ...; "unknown" when out of range). */
const char *home_refine_status_name(int status);

typedef struct home_result {
    int ok;                   /* 1: H is trustworthy by the failure rule */
    int failure;              /* enum home_failure */
    double H[9];              /* A -> B, row-major, H[8] = 1; when not ok, the rejected
                                 estimate (identity if there was none) */
    int model;                /* enum home_model of H (of the rejected estimate when not ok) */
    double sigma_px;          /* predicted RMS error of H at the image corners, px, from the
                                 final fit's covariance (the line fit's, or the refinement's
                                 when refined); infinite when the motion is not determined */
    int keypoints_a, keypoints_b, matches, inliers;
    int refined;              /* 1: H is HOME's estimate refined photometrically */
    int refine_status;        /* enum home_refine_status */
    int refine_iterations;    /* Gauss-Newton iterations over all levels */
    double refine_error[2];   /* robust photometric error (mean Geman-McClure cost, grey^2) of
                                 HOME's H and of the refined H over the points both keep */
    double refine_zncc;       /* weighted correlation of A and gain/bias-corrected B there */
    double refine_inlier_share; /* share of those points within 3 robust sigmas under the
                                 refined H (parts of the scene left misaligned lower it) */
    int fast_pass;            /* 1: home_register()'s fast pass gave this answer (ms then
                                 count it alone; otherwise they count both passes) */
    double ms[HOME_STAGE_COUNT]; /* per-stage milliseconds (0 without a clock) */
} home_result;

/* Register features a (earlier frame) to b (current frame): H maps a's pixels to b's.
 *
 * Refinement in video: home_extract() also keeps a snapshot of its frame in the context: the
 * template points of its pyramid in one of two slots (the older is replaced) and the full pyramid
 * of the newest frame only. home_match(a, b) refines when a is one of the last two frames
 * extracted and b the last one (the usual previous/current order); otherwise it reports
 * HOME_REFINE_NO_SNAPSHOT and keeps HOME's H. Extract + match gives the same H as
 * home_register() on the same images.
 *
 * Model and accuracy: each fit (lines, then photometric) chooses the simplest model up to
 * cfg.max_model that its data support (BIC over the fit's Fisher information) and predicts the
 * RMS corner error sigma_px from its covariance. ok requires sigma_px <= cfg.max_sigma_px.
 * Where a few long edges leave the refinement's model undetermined, a simpler one stands in
 * from the same start if it is sharply fixed: a similarity for a homography (HOME's estimate
 * not ok), then a rigid motion (rotation and translation, unit scale) for a similarity whose
 * scale the edges leave free (they meet near one point; under a similarity cap also beside an
 * ok line fit). A rigid answer is reported as a similarity, its sigma_px holding 0.3 px for
 * the scale change between the frames it leaves out.
 *
 * Failure rule with refinement: HOME's estimate (ok, or short of inliers or certainty with at
 * least 8 inliers) is refined. An accepted refinement within max(refine_trust_px, 3 sigma_px)
 * of HOME's H agrees with it: the result is the refined H, ok when HOME's was, or when the
 * photometric fit vouches for it (sigma_px <= 0.4 max_sigma_px, and refine_zncc >= 0.9 or
 * refine_inlier_share >= 0.9: camera noise holds the correlation of dim frames down).
 * Farther away the two disagree: the refined H is the result only when it vouches for the
 * whole frame (also refine_inlier_share >= 0.9) and a second refinement, started halfway
 * between the two, reaches it too (within 3 sigma_px, at least 0.5 px), else the pair fails
 * (HOME_FAIL_INCONSISTENT). Where HOME's own estimate was not ok and the refined H is a
 * homography, or any model under a max_model below the homography, its sigma_px is at least the
 * largest distance to the optima that refinements started 4 px to either side of it along each
 * axis reach and vouch for (a few dim edges leave several). Under a similarity cap a refined
 * similarity HOME's estimate does not vouch for (or one aligned from the identity, below) also
 * has sigma_px at least its distance to the similarity reached through the rigid motion
 * nearest the same start, and infinite (not ok) where that path fails or does not vouch for
 * itself: faint frames let a similarity slide where scale and translation trade. These checks
 * stop once sigma_px exceeds max_sigma_px: a refused answer's sigma_px is then a lower bound.
 * A refinement that cannot converge although the frame has texture refutes HOME's estimate
 * (INCONSISTENT too); one declined for another reason, or one that agrees but predicts a larger
 * error, leaves HOME's H, sigma and ok. When HOME finds no estimate, direct alignment from the
 * identity is tried; it vouches like an overruling refinement, must stay within
 * refine_trust_px of the identity and may not be a homography. Where that fails too (and
 * nothing made the pair inconsistent), with max_model a homography, every pixel of the
 * quarter-size frames is aligned coarse to fine from the best whole-pixel shift of its
 * coarsest image within 4 of its pixels (HOME_REFINE_DENSE: slow shading, a soft shadow): it
 * vouches the same way with sigma_px <= 0.3 max_sigma_px within 2 sigma_px of the identity;
 * farther, a translation or a similarity with sigma_px <= max_sigma_px, a homography with
 * sigma_px <= 0.45 max_sigma_px when its information on a shift is spread over 15 % of the
 * pixels or more, else (a few edges) <= 0.15 max_sigma_px, never an affine motion; it lies
 * within 1 + the shift's length pixels of its coarsest image from the identity (16 px at
 * 640x360 without a shift, at most 107 px), and the refinement's points, where they determine
 * an optimum from it, must find it within 3 sigma_px. Regions that prefer the identity to such
 * a motion (below) make the pair inconsistent, not static. Where that gives no answer either,
 * HOME's estimate failed only as too uncertain and an agreeing refinement that could not vouch
 * confirm each other when the refined H predicts sigma_px <= max_sigma_px, refine_zncc >= 0.9
 * and refine_inlier_share >= 0.97, and the two lie within 2 of their combined predicted errors
 * (sqrt of the sum of both sigma_px squared): the refined H.
 *
 * Static camera: an ok motion within 2 sigma_px of the identity, or one that most regions of an
 * 8x6 grid explain worse than the identity does (each region votes with its own strongest
 * points, so textured moving objects cannot outvote a plainer background), becomes the
 * identity (HOME_REFINE_STATIC). One the identity clearly explains better in a tenth of the
 * clearly decided regions is two motions, not ok (HOME_REFINE_STILL_REGIONS,
 * HOME_FAIL_INCONSISTENT); so is HOME's kept estimate when the refinement converged
 * ill-conditioned more than 2 predicted errors (both estimates') away from it. The plain
 * background judges pixel by pixel: a motion becomes the
 * identity when the plain regions (no textured block) outnumber the textured regions that prefer
 * it and their flat pixels prefer the identity at z >= 6; and it is not ok
 * (HOME_REFINE_STILL_BACKGROUND, HOME_FAIL_INCONSISTENT) when the frame's background away from
 * texture would show it clearly (a z score of 5, spread over the background) and shows less
 * than a third of it: textured objects moving over fog or a flat wall. The refusal's
 * refine_status says whether that background stands still (STILL_BACKGROUND: its own
 * translation below 0.4 of the motion's) or moves otherwise (BACKGROUND_MOVES).
 *
 * Repeated patterns: where frame A repeats along its dominant gradient direction (or along its
 * rows, columns or diagonals: tiles, pegboards) and the refinement, started one period away
 * either way, reaches an optimum there that fits about as well as the answer (at most 1.75
 * times worse along the dominant direction, 1.07 along the others), the pair cannot tell the
 * two apart: not ok (HOME_REFINE_PERIODIC, HOME_FAIL_UNCERTAIN, sigma_px at least the period). */
int home_match(home_context *ctx, const home_features *a, const home_features *b,
               home_result *result);

/* Convenience: extract both images into the context's own feature slots and register a to b.
 * With cfg.fast_pass_downscale, a fast pass first; its answer stands when ok, else the
 * configured pass runs from the start (result.fast_pass says which). */
int home_register(home_context *ctx, const uint8_t *a, ptrdiff_t stride_a, const uint8_t *b,
                  ptrdiff_t stride_b, home_result *result);

/* Refine any estimate h_init (A -> B pixels, e.g. another method's) photometrically with the
 * context's refinement settings. result->H gets the refined H when accepted, else h_init
 * normalised; result->ok = result->refined; refine_* fields and ms[HOME_STAGE_REFINE] are set,
 * the feature fields are 0. Replaces the context's frame snapshots. */
int home_refine(home_context *ctx, const uint8_t *a, ptrdiff_t stride_a, const uint8_t *b,
                ptrdiff_t stride_b, const double *h_init, home_result *result);

/* The features home_register() last extracted (0: image a, 1: image b), or NULL; those of its
 * fast pass when that gave the answer (result.fast_pass): home_match() then refuses them with
 * features of home_extract() (HOME_E_MISMATCH), and home_keypoint_to_hough() does not apply. */
const home_features *home_last_features(const home_context *ctx, int which);

/* Size of the quantised Hough image home_render_hough() writes: r bins x theta bins. */
int home_hough_size(const home_context *ctx, int *width, int *height);

/* Render image's smoothed Hough image J quantised to uint8 (128 + J*127/(6*std)): row t is
 * theta = t*pi/theta_bins, column i is r = (i - (r_bins-1)/2) * r_step. */
int home_render_hough(home_context *ctx, const uint8_t *image, ptrdiff_t stride, uint8_t *out,
                      ptrdiff_t out_stride);

/* Map a keypoint to its (column, row) position in the rendered Hough image. */
int home_keypoint_to_hough(const home_context *ctx, const home_keypoint *kp, float *col,
                           float *row);

#ifdef __cplusplus
}
#endif
#endif
