/* Private declarations of the stabiliser: its state, shared by stabilise.c (configuration,
 * frames in and out, the crop), stab_motion.c (similarities about the frame centre) and
 * stab_path.c (the camera path's Kalman filter, fixed-lag smoother and mirrored stream ends),
 * and its warp (warp.c). */
#ifndef HOME_STAB_INTERNAL_H
#define HOME_STAB_INTERNAL_H
#include "home_stab.h"
#include "stab_kernels.h"

/* HOME_OK when im is a usable frame: known format, size within HOME's limits (even where
 * chroma is subsampled), planes present, strides at least a row. */
int home__stab_check_image(const home_stab_image *im);

/* One output row (home__warp_row_c's contract) by the table k's body kernel and the reference
 * for the rows it does not take and its tail. */
void home__warp_row(const home__stab_kernels *k, const uint8_t *src, ptrdiff_t stride, int step,
                    int w, int h, int32_t x0, int32_t y0, int32_t dx, int32_t dy, uint8_t *dst,
                    int dst_step, int n);

/* Scene cuts are told by a coarse thumbnail of each frame: HOME__STAB_THUMB_SIDE^2 cell means. */
#define HOME__STAB_THUMB_SIDE 16
#define HOME__STAB_THUMB_CELLS (HOME__STAB_THUMB_SIDE * HOME__STAB_THUMB_SIDE)

/* Slots of path history at least: stab_still.c looks at up to 8 frames before a motion decided
 * up to 2 frames late. */
#define HOME__STAB_MIN_RING 11

/* A hold is bridged by a frame at most this many frames after the last frame before it. */
#define HOME__STAB_BRIDGE 3

/* One frame of path history. Path components are normalised to pixels (angle and log scale
 * times the half diagonal) so that one filter covariance serves all four of them. */
typedef struct stab_slot {
    long frame;
    int status;
    double weight;                /* measurement noise factor (1: an exact motion) */
    home_stab_sim raw;            /* camera path: frame 0 -> this frame */
    double xf[4][2], xp[4][2];    /* filtered / predicted (position, velocity) per component */
    double pf[3], pp[3];          /* shared covariances {p00, p01, p11} */
    home_stab_sim motion;         /* the motion from the previous frame taken (0 when held) */
    int registered_still;         /* the registration was the identity */
    double ease;                  /* still, but next to the camera's move: how far the path may
                                     leave it (0: pinned, 1: an ordinary frame; stab_path.c) */
    int has_candidate;            /* held, refused only because the plain background stood still: */
    home_stab_sim candidate;      /* the refused motion, plausible, */
    double candidate_weight;      /* and the weight it would have */
    int has_score;                /* its motion, registered ok, had the still-background score
                                     test: */
    double score[3];              /* ... observed, expected, evidence (home__refine_last_score) */
    double unexplained;           /* ... and the share of regions it left unexplained
                                     (home__refine_last_unexplained) */
    int smoothed_ready;           /* its segment has ended: `smoothed` is its final path */
    home_stab_sim smoothed;
} stab_slot;

struct home_stab {
    uint32_t magic;
    home_stab_config cfg;
    home_context *home;
    home_features *feat[2];       /* [0] previous frame, [1] current: swapped by pointer */
    home_features *anchor;        /* the last frame before a hold (anchor_frame; -1: none) */
    long anchor_frame;
    uint8_t *small;               /* downscaled luma */
    int small_w, small_h;
    /* HOME's box downscale of planar rows (its backend's): the same rounding as the reference
     * loop in registration_luma() */
    void (*box_down)(const uint8_t *src, ptrdiff_t stride, int ds, uint8_t *out, int out_w);
    stab_slot *ring;              /* 2 lookahead + 1 slots (at least HOME__STAB_MIN_RING), frame n
                                     in ring[n % len] */
    int ring_len;
    long pushed, emitted;
    long first;                   /* first frame of the current segment (a cut starts one) */
    int tail;                     /* flush has ended the segment at the last frame pushed */
    int cut_requested;            /* home_stab_cut(): the next frame starts a segment */
    int thumb_index;              /* thumb[thumb_index]: the newest frame's */
    float thumb[2][HOME__STAB_THUMB_CELLS]; /* coarse luma of the last two frames (cuts) */
    double q, r, norm;            /* process / measurement noise, px per radian or log-scale */
    int sees_ahead;               /* the lookahead spans the path's time constant: a still
                                     frame's path is measured as the intended one, and a held
                                     frame's path glides on (stab_path.c) */
    home_context *key_home;       /* the key frame's registration (NULL: none) */
    uint8_t *key_luma;            /* the key frame: the last frame whose motion left nothing
                                     unexplained, away from frames that did (key_frame; -1:
                                     none), as registered */
    home_features *key_feat;      /* [0] the key frame's features (of key_feat_frame; -1: not
                                     extracted), [1] the frame registered against it */
    long key_frame, key_feat_frame, last_unexplained;
    long key_agreed;              /* the last frame whose key registration agreed with the path */
    long key_failed;              /* the last frame whose key registration failed */
    long key_apart;               /* the last frame whose key registration the path took */
};

static inline stab_slot *slot_of(const home_stab *st, long frame)
{
    return &st->ring[frame % st->ring_len];
}

/* stab_motion.c */
/* b after a */
home_stab_sim home__stab_sim_compose(const home_stab_sim *b, const home_stab_sim *a);
home_stab_sim home__stab_sim_inverse(const home_stab_sim *a);
home_stab_sim home__stab_sim_scaled(const home_stab_sim *a, double k);
void home__stab_apply(const double *h, double x, double y, double *u, double *v);
double home__stab_fit_similarity(const home_stab *st, const double *h, home_stab_sim *out);
double home__stab_corner_motion(const home_stab *st, const home_stab_sim *m);

/* stab_path.c */
void home__stab_path_components(const home_stab *st, const home_stab_sim *s, double *z);
void home__stab_kalman_step(const home_stab *st, const stab_slot *prev, stab_slot *cur,
                            const double *z);
void home__stab_refilter_mirrored_start(const home_stab *st, long first, long last);
void home__stab_refilter(const home_stab *st, long t, long newest);
void home__stab_ease_still(home_stab *st, long t, long newest);
double home__stab_ease_after_move(const home_stab *st, long n);
void home__stab_end_segment(home_stab *st, long last);
home_stab_sim home__stab_smoothed_path(const home_stab *st, long m, long last);

/* stab_still.c */
long home__stab_still_delay(const home_stab *st);
void home__stab_settle_still(home_stab *st, long t, long newest);
void home__stab_settle_restored(home_stab *st, long t, long newest);
int home__stab_camera_moves(const home_stab *st, long t);
/* Frame s's ok motion leaves a part of the frame unexplained (a second motion, or a still
 * background under moving objects). */
int home__stab_leaves_part(const stab_slot *s);
/* How many of the last decided frames before t moved (and how many were decided). */
int home__stab_moved_before(const home_stab *st, long t, int *decided);
/* Frame t's motion becomes m (status, weight): the path from t on is composed and filtered
 * again up to newest. */
void home__stab_retake_motion(home_stab *st, long t, long newest, const home_stab_sim *m,
                              int status, double weight);

/* stab_cut.c */
void home__stab_thumbnail(const uint8_t *luma, ptrdiff_t stride, int w, int h, float *thumb);
double home__stab_thumb_similarity(const float *a, const float *b, int max_shift_cells);

#endif
