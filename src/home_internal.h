/* Private declarations shared by libhome's stages. Names: home__ prefix or file-static. */
#ifndef HOME_INTERNAL_H
#define HOME_INTERNAL_H

#include "home.h"
#include "kernels.h"
#include <math.h>
#include "line_fit_kernels.h"
#include "refine_kernels.h"

#define HOME__MAGIC_CTX 0x484f4d43u   /* "HOMC" */
#define HOME__MAGIC_FEAT 0x484f4d46u  /* "HOMF" */
#define HOME__PI 3.14159265358979323846
#define HOME__MAX_SMOOTH_RADIUS HOME__MAX_TAPS_RADIUS /* sigma <= 2.6 bins */
#define HOME__DESC_ROWS 5             /* smoothed rows kept: detection (3) + descriptor (+-2) */

/* A keypoint candidate while the top-K heaps are filled. samples are the raw (float)
 * descriptor values; they are quantised once J's standard deviation is known. */
typedef struct home__candidate {
    float theta_bin, r_bin, saliency;
    uint32_t order;                   /* detection order: total-order tie break */
    float samples[HOME_DESC_LEN];
} home__candidate;

/* A fixed-capacity min-heap of candidates: the ordering moves small entries (rank and the pool
 * slot of the candidate), the candidates themselves stay where they were written */
typedef struct home__heap_entry {
    float saliency;
    uint32_t order;
    int slot;                         /* index into the pool */
} home__heap_entry;

typedef struct home__heap {
    home__heap_entry *entries;        /* capacity */
    home__candidate *pool;            /* capacity */
    int count, capacity;
} home__heap;

/* An extremum found on one theta row, before description. */
typedef struct home__extremum {
    float theta_bin, r_bin, saliency;
    int sign;
} home__extremum;

/* refine.c: template points of one pyramid level, structure of arrays padded to 4 lanes */
typedef struct home__refine_points {
    int16_t *x, *y;                   /* level pixel */
    int16_t *t;                       /* grey value */
    int16_t *gx, *gy;                 /* 2x central differences */
    int n, capacity;
} home__refine_points;

/* Pixels of the static test's background image at most (src/refine_static.c). */
#define HOME__BACKGROUND_PIXELS 16384

/* Regions of the refinement's identity test at most (its grid: src/refine_internal.h). */
#define HOME__MAX_REGIONS 64

/* refine.c: per-frame snapshots (arena-backed): template points of the last two frames, the
 * pyramid of the last one */
typedef struct home__refine_state {
    int levels;                       /* 0: refinement off */
    int finest_level;                 /* the finest level points are selected at */
    int base_level;                   /* the finest level with pixels (pyr[l] NULL below it) */
    int w[HOME_REFINE_MAX_LEVELS], h[HOME_REFINE_MAX_LEVELS];
    uint8_t *pyr[HOME_REFINE_MAX_LEVELS];
    uint32_t pyr_id, slot_id[2];
    uint32_t keep_id;                 /* a snapshot home__refine_store() does not replace (0:
                                         none): a frame registered to many, one at a time */
    int next_slot;
    int pending_slot;                 /* its template points not yet selected (deferred), or -1 */
    home__refine_points tpl[2][HOME_REFINE_MAX_LEVELS];
    home__refine_points regions[2];   /* the strongest points of every region of a grid at
                                         region_level, for the identity test (x, y, t only) */
    unsigned char region_faint[2][HOME__MAX_REGIONS]; /* per region: its points are faint */
    unsigned char region_plain[2][HOME__MAX_REGIONS]; /* per region: no block above the
                                                          textured floor (faint or flat) */
    int region_level;
    uint8_t *background[2];           /* each slot's frame at quarter size, box-reduced to at
                                         most HOME__BACKGROUND_PIXELS: the static test's plain
                                         regions, pixel by pixel */
    uint16_t *background16[2];        /* the same in sixteenths of a grey level, from the
                                         finer level: the background score test */
    int background_w, background_h;
    int background_level, background_factor; /* pyramid level, box side */
    uint8_t *flat;                    /* match time: which of frame A's background pixels are
                                         flat, */
    int16_t *sampled;                 /* ... and frame B there under the motion tested (the
                                         score test: frame A smoothed) */
    int16_t *smoothed_b;              /* the score test: frame B smoothed */
    int scored;                       /* the last home__refine_apply() ran the score test on
                                         its answer: */
    double score[3];                  /* ... observed, expected, evidence */
    double unexplained;               /* the share of regions its ok answer leaves unexplained
                                         (0: not measured: the identity, or within its sigma) */
    int stood_in;                     /* the last home__refine_run()'s answer is a similarity
                                         standing in for an undetermined homography */
    uint32_t dense_ids[2];            /* the frames of the last dense alignment (0: none), */
    int dense_model;                  /* ... its cfg.max_model, */
    int dense_found;                  /* ... whether it found a motion, */
    double dense_reach, dense_spread; /* ... its reach, where its information sits and its
                                         answer (H, model, sigma_px and the refine fields):
                                         home_register()'s second pass reuses it */
    home_result dense_answer;
    const home__refine_kernels *rk;   /* SIMD backend, as cfg.simd */
    void *scratch;
} home__refine_state;

/* FAST: what one theta row of the transform needs that depends only on theta and the Hough
 * image's size (src/hough.c): the shear of every row, the row range of every intercept block,
 * the intercept -> r resampling. Computed once per context for every theta row when all of them
 * fit HOME_HOUGH_GEOMETRY_BYTES, else per row and frame into one scratch record (the fast pass:
 * as many rows as fit the configured pass's image buffers, which it does not use, cached there
 * until the configured pass runs). */
typedef struct home__theta_geom {
    int vertical, flip;               /* lines within 45 degrees of the columns; rows reversed */
    int s_min, s_max, j0, n, n_blocks; /* shift range, first intercept, intercepts, blocks */
    int i_lo, i_hi;                   /* r bins [i_lo, i_hi) fall inside the intercept range */
    float d_scale, end_scale;         /* J = d_scale (S(j+1) - S(j-1)) + end_scale [I] */
    int16_t *shift, *row_lo, *row_hi; /* per-row shear, per-block row ranges */
    int16_t *entry, *after;           /* per intercept: first row inside the image, and the row
                                         after its last */
    int16_t *res_k;                   /* r bin i (from i_lo): intercept index k and weight */
    float *res_f;                     /*   f of line[k] + f (line[k+1] - line[k]) */
} home__theta_geom;

/* One Hough set-up of the context: the configured one, and home_register()'s fast pass
 * (cfg.fast_pass_downscale). The stages read the context's live copies of these fields;
 * home__select_pass() switches them. */
typedef struct home__pass {
    home_config cfg;                  /* the context's configuration with this pass's Hough
                                         settings */
    uint32_t config_id;
    int r_bins, hough_w, hough_h, hough_scale;
    double hough_dx, hough_dy;
    uint8_t *img_n, *img_t;
    ptrdiff_t img_n_stride, img_t_stride;
    home__theta_geom *geom;           /* FAST: its first geom_rows raw theta rows' geometry */
    int geom_rows;
    int geom_borrowed;                /* geom lies in the configured pass's image buffers */
} home__pass;

struct home_context {
    uint32_t magic;
    home_config cfg;
    uint32_t config_id;
    int r_bins;
    int hough_w, hough_h;             /* image size the Hough transform sees */
    int hough_scale;                  /* hough_downscale: full-image px per Hough-image px */
    double hough_dx, hough_dy;        /* full-image centred coordinates of the Hough image's
                                         centre (non-zero for odd sizes when downscaled) */
    int smooth_radius;
    float smooth_taps[2 * HOME__MAX_SMOOTH_RADIUS + 1];
    const home__kernels *kernels;     /* SIMD backend */
    /* arena-backed buffers */
    /* EXACT: width x height central differences, 0 on the border */
    int16_t *grad_x, *grad_y;
    uint8_t *img_n, *img_t;           /* FAST: the image and its transpose, zero-padded by
                                         HOME__RADON_BLOCK columns on each side */
    ptrdiff_t img_n_stride, img_t_stride;
    home__theta_geom *geom;           /* FAST: the first geom_rows raw theta rows' geometry */
    int geom_rows;
    home__theta_geom geom_scratch;    /* FAST: one row's, when not cached */
    int32_t *first_row;               /* FAST: while computing a row's geometry, the first row
                                         whose shift reaches a value */
    int geom_borrowed;                /* the live pass's geom lies in the configured pass's
                                         image buffers (the fast pass's, when its table does
                                         not fit HOME_HOUGH_GEOMETRY_BYTES) ... */
    int geom_stale;                   /* ... which the configured pass has overwritten since */
    int32_t *line_sum;                /* FAST: line sums over the intercept range */
    int32_t *edge_prefix;             /* FAST: prefix sums of the first and last column, per
                                         theta family and direction (src/hough.c) */
    float *line_j;                    /* FAST: J over the intercept range */
    int32_t *acc_x, *acc_y;           /* r_bins: line sums of one theta row */
    float *raw_rows;                  /* ring of (2*radius+1) r-smoothed rows */
    float *smooth_rows;               /* ring of HOME__DESC_ROWS fully smoothed rows */
    float *row_tmp;                   /* r_bins scratch */
    home__candidate *heap_items;      /* 2 * keypoints_per_sign */
    home__heap_entry *heap_entries;   /* 2 * keypoints_per_sign */
    home__extremum *row_extrema;      /* r_bins: extrema of one theta row */
    int *row_candidates;              /* r_bins: their candidate bins (extremum_candidates) */
    home__match *matches;             /* capacity max_matches */
    int max_matches;
    int *inlier_index;                /* max_matches: indices of current inliers */
    home_features *slots;             /* 2: home_register()'s own features */
    uint8_t *window_desc;             /* motion prior: b's descriptors in theta order per sign */
    float *window_theta;              /*   their theta */
    int *window_index;                /*   their index in b */
    int slots_valid;
    home__pass passes[2];             /* 0: the configured pass; 1: the fast pass, if any */
    int n_passes;
    home__refine_state refine;
};

/* Arena blocks start on this boundary (cache line, widest SIMD load). */
#define HOME__BLOCK_ALIGN 64u

/* n rounded up to a multiple of a (a power of two) */
static inline size_t home__align_up(size_t n, size_t a) { return (n + a - 1) & ~(a - 1); }

/* The offset of the next block of bytes at *cursor (HOME__BLOCK_ALIGN), and the cursor past it. */
static inline size_t home__take(size_t *cursor, size_t bytes)
{
    const size_t at = home__align_up(*cursor, HOME__BLOCK_ALIGN);
    *cursor = at + bytes;
    return at;
}

/* 1 when v is finite and in [lo, hi] */
static inline int home__finite_in(double v, double lo, double hi)
{
    return isfinite(v) && v >= lo && v <= hi;
}

/* config.c */
uint32_t home__config_id(const home_config *cfg);
/* home_register()'s fast pass for cfg (a valid configuration): 1 and its configuration in
 * *fast, or 0 when it has none. */
int home__fast_pass_config(const home_config *cfg, home_config *fast);
int home__r_bins(const home_config *cfg);
void home__hough_size(const home_config *cfg, int *width, int *height);

/* common.c: the image check and the clock every stage uses */
int home__check_image(const home_context *ctx, const uint8_t *image, ptrdiff_t stride);
double home__now(const home_context *ctx);

/* gradient.c */
void home__gradient(const uint8_t *image, ptrdiff_t stride, int width, int height,
                    int16_t *gx, int16_t *gy);

/* hough.c: the texture-preserving Hough transform, streamed one theta row at a time so only a
 * few rows are ever stored. For every fully smoothed row j in [-3, theta_bins + 2] it calls
 * on_row with window[0..4] = smoothed rows j-4 .. j (older ones undefined while j < -3 + 4).
 * Rows outside [0, theta_bins) are computed directly at theta < 0 or >= pi: they are the paper's
 * padding J(theta +- pi, r) = -J(theta, -r). Returns the ms spent outside on_row. */
typedef void (*home__row_fn)(void *user, int row, const float *const *window);
void home__hough_accumulate_row(const int16_t *gx, const int16_t *gy, int width, int height,
                                int32_t cos_q, int32_t sin_q, int32_t base_q, int32_t *acc_x,
                                int32_t *acc_y, int r_bins);
/* Raw theta rows the stream computes (the theta-smoothing margin and the wrap rows included):
 * k = first .. first + count - 1, theta = k pi / theta_bins. */
void home__hough_raw_rows(const home_config *cfg, int radius, int *first, int *count);
/* Fill a geometry record (its arrays already carved) for theta. */
void home__theta_geometry(const home_context *ctx, double theta, home__theta_geom *g);
/* The Hough stage's arena block: its bytes, and its buffers and geometry laid out in it (the
 * context's sizes, cfg and r_bins, already set). */
size_t home__hough_bytes(const home_config *cfg);
void home__hough_init(home_context *ctx, unsigned char *block);
/* Make pass k (0 configured, 1 fast) the one the stages see. */
void home__select_pass(home_context *ctx, int k);
/* Rows [y0, y1) of the image the Hough transform sees (box-downscaled when hough_downscale > 1)
 * from image; FAST only. */
void home__hough_load_rows(home_context *ctx, const uint8_t *image, ptrdiff_t stride, int y0,
                           int y1);
/* J row by row to on_row; image NULL: its rows were all loaded with home__hough_load_rows(). */
double home__hough_stream(home_context *ctx, const uint8_t *image, ptrdiff_t stride,
                          home__row_fn on_row, void *user);

/* smooth.c */
int home__gauss_taps(float sigma, float *taps);
void home__smooth_r(const home__kernels *kernels, const float *in, float *out, int n,
                    const float *taps, int radius);
/* Along theta: out[i] = sum_k taps[k] rows[k][i], i in [0, n) (the smooth_cols kernel and the
 * reference for what it leaves). */
void home__smooth_theta(const home__kernels *kernels, const float *const *rows, float *out, int n,
                        const float *taps, int radius);

/* extrema.c */
void home__heap_init(home__heap *heap, home__heap_entry *entries, home__candidate *pool,
                     int capacity);
int home__heap_would_accept(const home__heap *heap, float saliency, uint32_t order);
void home__heap_push(home__heap *heap, const home__candidate *cand);
/* Sorts the entries, most salient first; the i-th is then &pool[entries[i].slot]. Returns the
 * count. */
int home__heap_sort_desc(home__heap *heap);
/* Scan smoothed row rows[1] (rows[0..2] = centre-1 .. centre+1) for strict extrema with a valid
 * Newton step whose refined theta lies in [0, theta_bins); returns how many were written.
 * candidates: r_bins ints of scratch. */
/* The strict signed 3x3 extrema of row mid, i in [1, n - 1), into idx; how many (the kernel's
 * body, then the reference for the rest). */
int home__extremum_candidates(const home__kernels *kernels, const float *up, const float *mid,
                              const float *down, int n, int *idx);
int home__detect_row(const home__kernels *kernels, const float *const *rows, int centre, int r_bins,
                     int theta_bins, int *candidates, home__extremum *out);

/* describe.c */
void home__describe_samples(const float *const *rows, int centre, int r_bins, float theta_bin,
                            float r_bin, float *samples);
void home__quantise_descriptor(const float *samples, float scale, int reverse_negate,
                               uint8_t *desc);

/* match.c */
void home__match_set(home__match *m, float theta_a, float r_a, float theta_b, float r_b);
int home__match_features(home_context *ctx, const home_features *a, const home_features *b);

/* homography.c */
int home__estimate_homography(home_context *ctx, int n_matches, home_result *result);
/* 1 when H (pixels, h22 = 1) maps the width x height frame plausibly: det > 0, every corner in
 * front (w > 0), and onto a convex quadrilateral of the same turn that is not collapsed. */
int home__homography_plausible(const double *h, int width, int height);

/* lm.c: minimise a sum of squares over 8 parameters. The problem supplies its cost and, when
 * jtj is not NULL, the Gauss-Newton normal equations (home__normal_fn, port/line_fit_kernels.h),
 * so it can exploit the structure of its Jacobian. */
int home__lm_solve(double *p, home__normal_fn fn, const void *user, int max_iters);
int home__solve_spd8(double *a, double *b);
/* The same in two steps, to solve for several right-hand sides with one factor. */
int home__cholesky8(double *a);
void home__cholesky_solve8(const double *l, double *b);


/* model.c: motion-model selection over a fit's Fisher information (see there) */
#define HOME__SPACE_H 0          /* parameters: the homography's entries h0..h7 */
#define HOME__SPACE_G 1          /* parameters: those of G = H^-T (the line fit's) */
#define HOME__MODEL_RIGID (HOME_MODEL_HOMOGRAPHY + 1) /* internal: a similarity whose scale is
                                                     held (rotation and translation) */
typedef struct home__model_problem {
    int space;                   /* HOME__SPACE_H or _G */
    double p[8];                 /* the estimate, normalised coordinates */
    double info[64];             /* its Fisher information (inverse covariance) */
    double penalty;              /* per parameter, in units of the information's chi-square */
    int max_model;               /* enum home_model: the caller's cap */
    int rigid;                   /* 1: the similarity's scale is held (HOME__MODEL_RIGID) */
    int max_params;              /* models with more parameters are not determined by the data */
    double scale, cx, cy;        /* pixel = scale * normalised + (cx, cy) */
    double floor_px;             /* > 0: the choice weighs each model's misfit as if every
                                    corner coordinate also carried this much error of its own
                                    (space H only) */
} home__model_problem;
typedef struct home__model_choice {
    int model;                   /* enum home_model */
    double p[8];                 /* the model's estimate, same space */
    double delta;                /* its misfit against the full estimate (chi-square units) */
    double sigma_px;             /* predicted RMS corner error, px */
} home__model_choice;
/* 1 and the choice, or 0 when no model up to max_model is determined by the information. */
int home__select_model(const home__model_problem *mp, home__model_choice *out);
/* The model's parameters as an affine subspace p = o + B q of the 8 (basis: k columns of 8,
 * the same form in both spaces but for the translation and perspective entries); returns k. */
int home__model_basis(int space, int model, double *o, double basis[8][8]);
/* Normal equations of p projected onto q (B^T A B, B^T g), padded to 8x8 with the identity. */
void home__project_normal(const double basis[8][8], int k, const double *jtj, const double *jte,
                          double *jtj_q, double *jte_q);
/* a x = b for a k x k SPD a (row stride 8; overwritten), k <= 8; 0 when not positive definite */
int home__solve_spd(double *a, double *b, int k);
/* p (h0..h7 of a matrix with h8 = 1) -> the same of its inverse transpose; 0 when singular */
int home__inverse_transpose8(const double *p, double *out);

/* common.c: the cofactor matrix c of the 3x3 matrix m (row major; m^-1 = c^T / det m) */
void home__cofactors3(const double *m, double *c);

/* refine.c */
void home__refine_defaults(home_config *cfg);
int home__refine_validate(const home_config *cfg);
size_t home__refine_bytes(const home_config *cfg);
void home__refine_init(home_context *ctx, unsigned char *block);
/* Where the snapshot's 2x2-mean frame is built when it starts at half size (its rows in *rows),
 * else NULL; home__refine_half_rows() fills its rows [y0, y1) from the full-size image. */
uint8_t *home__refine_half_frame(home_context *ctx, int *rows);
void home__refine_half_rows(home_context *ctx, const uint8_t *image, ptrdiff_t stride, int y0,
                            int y1);
/* Snapshot of a frame; image NULL: the 2x2-mean frame was filled by home__refine_half_rows().
 * defer: its template points are selected only when needed (home__refine_settle), since a
 * frame B is only ever registered to, never from, until another frame is stored. */
uint32_t home__refine_store(home_context *ctx, const uint8_t *image, ptrdiff_t stride, int defer);
/* Keep the snapshot frame_id (0: none) while later frames are stored: each replaces the other
 * slot, so frame_id can be registered to one frame after another (the stabiliser's key frame). */
void home__refine_keep(home_context *ctx, uint32_t frame_id);
/* Select a deferred slot's template points from the pyramid, which is still its frame's (slot:
 * only that slot's; -1: any). Before anything replaces the pyramid or its scratch. */
void home__refine_settle(home_context *ctx, int slot);
/* Forget a deferred slot without selecting (the caller replaces both slots): its snapshot
 * becomes unusable. */
void home__refine_drop_pending(home_context *ctx);
void home__refine_apply(home_context *ctx, uint32_t id_a, uint32_t id_b, home_result *result);
/* Frame a -> b (snapshot ids, b the latest) as far as the frames determine a translation, from
 * the identity, none in the other directions (a horizon in fog: the shift across it; src/
 * refine_solve.c, home__refine_determined): 1 with h and its predicted error (full-size px). */
int home__refine_determined_motion(home_context *ctx, uint32_t id_a, uint32_t id_b, double *h,
                                   double *sigma_px);
/* The still-background score test of the last home__refine_apply()'s motion (src/
 * refine_background.c: observed, expected, evidence), where it ran: 1, else 0. A frame's test
 * can be too weak to refute the motion (a plain background in fog); several frames' together
 * can be strong enough (the stabiliser sums them). */
int home__refine_last_score(const home_context *ctx, double *observed, double *expected,
                            double *evidence);
/* The share of frame A's regions that the last home__refine_apply()'s ok motion leaves
 * unexplained where the identity explains them about as well (src/refine_static.c), 0 where it
 * was not measured. One pair cannot tell a still background (the motion follows movers over
 * it) from a second motion in front of a moving camera (a hand, parallax); the stabiliser's
 * path history can. */
double home__refine_last_unexplained(const home_context *ctx);
/* The score test's verdict (src/refine.c): the background would show the motion clearly
 * (expected and evidence, both z scores, large enough) and shows far less of it (observed). */
int home__refine_score_refutes(double observed, double expected, double evidence);

#endif
