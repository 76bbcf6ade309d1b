/* libhome live electronic image stabilisation (home_stab_*).
 *
 * Per frame the stabiliser registers the frame's (optionally downscaled) luma to the previous
 * frame with HOME, reusing the previous frame's features and asking it for a similarity
 * (home_config.max_model), which it fits as a similarity (translation, rotation, zoom about the
 * image centre); accumulates the camera path; smooths it with a constant-velocity Kalman filter
 * (each frame's measurement noise grows with the registration's predicted error sigma_px, so an
 * uncertain motion pulls the path less; a static scene registers as exactly no motion) and, with a
 * lookahead of N frames, a fixed-lag Rauch-Tung-Striebel smoother over those N frames; and returns
 * the warp that shows the smoothed camera through a crop window (margins on each side, scaled to
 * fill the frame). The correction is shrunk towards identity whenever the window would leave the
 * frame, so the output never shows pixels from outside the input. A failed or implausible
 * registration is taken as "no motion": the path holds and the correction decays smoothly towards
 * identity. A still camera stays still: a motion among frames that register as the identity (at
 * least 2 of the 4 nearest, up to 2 of them ahead within the lookahead, and no other motion
 * among them) is taken as none, unless it moves the corners by more than 2 % of the half
 * diagonal (a knocked tripod). A moving camera keeps moving: a motion HOME refused because the
 * plain background stood still (HOME_REFINE_STILL_BACKGROUND: a hand at the lens) is taken when
 * at least 2 of the 8 frames before it and up to 2 after it register a motion and none the
 * identity (a tripod shot's objects over fog are refused alike, among still frames). Frames
 * held after frames that register a moving camera are bridged when a later frame (up to 3
 * later) registers to the last frame before the hold: they take the motion that closes the
 * gap, so the path does not keep the missed motion as an offset.
 *
 * Scene cuts: a frame that cannot be registered to its predecessor and whose coarse luma (16x16
 * cell means) correlates below 0.5 with the predecessor's at every shift up to max_shift, once
 * gain and offset are allowed for, starts a new scene (or home_stab_cut() says so). The frames
 * still due before it are smoothed as if the stream ended there, and the path restarts at it:
 * no smoothing window spans the cut and no frame is warped by motion from the other side.
 * Exposure steps and fades are not cuts (the correlation ignores gain and offset; a flat frame
 * tells nothing).
 *
 * Frames, latency and memory: the caller owns every frame buffer. home_stab_push() takes the
 * newest frame (only its luma is read) and, once N = lookahead frames are queued behind it,
 * reports the warp for the frame pushed N calls earlier; the caller keeps its last N + 1 frames
 * (a ring) and warps the reported one with home_stab_warp() into its output buffer. At the end
 * of a stream home_stab_flush() reports the N frames still queued, smoothed over the mirrored
 * path (see home_stab_config.ease); a push after a flush continues the stream. Everything else -
 * the HOME context, the two feature slots (previous/current, swapped by pointer), the downscaled
 * luma, the path history - lives in one caller arena of home_stab_arena_size() bytes.
 *
 * Coordinates as in home.h: pixel centres, (0, 0) top-left. A warp maps output pixel
 * coordinates to input (source) pixel coordinates of the luma plane; chroma follows with
 * centre-sited subsampling. Threading: one thread per stabiliser at a time.
 */
#ifndef HOME_STAB_H
#define HOME_STAB_H

#include "home.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest lookahead (frames of latency) a stabiliser accepts. */
#ifndef HOME_STAB_MAX_LOOKAHEAD
#define HOME_STAB_MAX_LOOKAHEAD 120
#endif

/* Pixel formats of home_stab_image. */
enum home_stab_format {
    HOME_STAB_I420 = 1, /* planes Y, U, V; chroma w/2 x h/2 */
    HOME_STAB_NV12,     /* planes Y, UV interleaved; chroma w/2 x h/2 */
    HOME_STAB_YUYV,     /* one packed plane Y0 U Y1 V, 4:2:2 */
    HOME_STAB_I422,     /* planes Y, U, V; chroma w/2 x h */
    HOME_STAB_GREY      /* luma only */
};

typedef struct home_stab_image {
    int format;               /* enum home_stab_format */
    int width, height;        /* luma size; even for the subsampled formats */
    uint8_t *plane[3];
    ptrdiff_t stride[3];      /* bytes between rows of each plane */
} home_stab_image;

typedef struct home_stab_config {
    int width, height;        /* frame size (luma) */
    float margin_x, margin_y; /* crop margin on the left and right, fraction of the width, and
                                 on the top and bottom, fraction of the height; 0.10 each. The
                                 window is scaled to fill the frame: unequal margins change the
                                 picture's aspect (e.g. to spend the spare height of 4:3 content
                                 framed in 16:9) */
    float smoothing;          /* path smoothing time constant in frames (Kalman bandwidth
                                 1/smoothing per frame); larger = steadier, more crop used;
                                 0 = automatic: lookahead / 2 (at least 3); with a
                                 lookahead below 5 (or causal) 15 */
    int lookahead;            /* frames of latency used for fixed-lag smoothing; 0 = causal */
    float ease;               /* with a lookahead: share of the pan the virtual camera gives up
                                 at the stream's ends, 0..1 (0: the pan goes on through the
                                 first and last frames, 1: it starts from and comes to rest);
                                 1. The path beyond each end is the mirrored path plus the
                                 share 1 - ease of its trend, so the end frames are smoothed
                                 over a full window; no effect when causal */
    int downscale;            /* register on luma box-averaged by 1, 2 or 4 */
    int keypoints_per_sign;   /* HOME's budget per frame (see home_config) */
    int min_inliers;          /* HOME's failure rule (see home_config) */
    int refine;               /* 1: HOME's photometric refinement of each H (home_config's
                                 refine_levels default), 0: off */
    int refine_finest_level;  /* HOME's refine_finest_level (see home_config): 0 = the
                                 refinement ends at the registration image's full size, 1 = at
                                 half size (the default: as steady as full size for less work;
                                 docs/presets.md) */
    int hough_downscale;      /* HOME's Hough transform on the registration image (1) or on its
                                 2x2- or 4x4-box downscaled copy (2, 4), see home_config; 0 =
                                 automatic (4 where that copy is at least 96 px wide, else
                                 home_video_config's: 2 from 320 px wide) */
    int theta_bins;           /* HOME's theta bins; 0 = automatic (88, fewer than
                                 home_video_config's 120: the refinement gives the precision);
                                 fewer suit tiny frames */
    int simd;                 /* enum home_simd for HOME (default AUTO: the HOME_SIMD env or the
                                 best compiled in); the warp takes the best this CPU has (all
                                 backends give the same bytes) */
    int key_frames;           /* 1 (the default): a frame whose motion leaves a part of the
                                 frame unexplained while the camera moves (an object crossing,
                                 a hand at the lens) is also registered against the last frame
                                 before that part appeared, with HOME's still-pair defaults, and
                                 the path follows that registration where the two disagree
                                 (docs/stabiliser.md). Costs a second HOME context, a frame
                                 and two feature sets in the arena (640x360: 1.8 -> 4.0 MB)
                                 and a full-size Hough transform (5-8 ms at 640x360, x86)
                                 on such frames; 0: off */
    float max_shift;          /* plausible per-frame translation, fraction of the width */
    float max_rotation;       /* plausible per-frame rotation, radians */
    float max_zoom;           /* plausible per-frame |log scale| */
    float max_residual;       /* plausible RMS px gap between HOME's H and its similarity fit */
    home_clock_fn clock;      /* optional: ms_register in home_stab_output (reg.ms stays 0) */
    void *clock_user;
} home_stab_config;

/* What became of a frame's registration to its predecessor. */
enum home_stab_motion_status {
    HOME_STAB_MOTION_FIRST = 0, /* first frame: nothing to register to */
    HOME_STAB_MOTION_OK,        /* HOME's H, fitted by a similarity, is the motion */
    HOME_STAB_MOTION_FAILED,    /* HOME found no trustworthy H: held (no motion) */
    HOME_STAB_MOTION_IMPLAUSIBLE, /* H outside the configured limits: held (no motion) */
    HOME_STAB_MOTION_CUT,       /* a scene cut (or home_stab_cut()): the path restarts here */
    HOME_STAB_MOTION_STILL,     /* a small motion among frames registered as the identity (a
                                   still camera), or one the plain background of the frames
                                   around refutes (objects over fog): taken as none */
    HOME_STAB_MOTION_RESTORED,  /* a motion HOME refused because the frame's plain background
                                   stood still, taken because the frames around it register a
                                   moving camera (a plain part moving with the camera: a hand at
                                   the lens, blocks an encoder left unchanged) */
    HOME_STAB_MOTION_PARTIAL,   /* too little structure for a whole motion (a horizon in fog):
                                   the shift the frames determine (across the horizon), none
                                   along it and no rotation */
    HOME_STAB_MOTION_BRIDGED    /* held among frames of a moving camera, then given its share
                                   of the motion a later frame (up to 3 later) registers against
                                   the last frame before the hold: the path after the hold goes
                                   on where the camera is, not offset by the missed motion */
};

/* A similarity about the image centre c: p -> exp(log_scale) R(angle) (p - c) + c + (tx, ty). */
typedef struct home_stab_sim {
    double tx, ty, angle, log_scale;
} home_stab_sim;

typedef struct home_stab_output {
    int ready;                /* 1: warp frame `frame` now (0: nothing due yet / drained) */
    long frame;               /* index (from 0, in push order) of the frame to warp */
    double warp[9];           /* output pixel -> input pixel of that frame (affine, row-major) */
    home_stab_sim raw;        /* camera path of that frame: frame 0 -> frame */
    home_stab_sim smooth;     /* smoothed path of that frame */
    double correction_used;   /* share of the smoothing correction applied: 1, or less where the
                                 crop window had to stay inside the frame */
    int motion_status;        /* enum home_stab_motion_status of that frame */
    /* about the newest pushed frame: */
    home_result reg;          /* its registration to the previous frame */
    int newest_status;        /* enum home_stab_motion_status */
    double ms_register;       /* downscale + extract + match (0 without a clock) */
} home_stab_output;

typedef struct home_stab home_stab;

/* Defaults for a width x height stream: margins 0.10, automatic smoothing, lookahead 0, ease 1,
 * downscale 2 for frames wider than 960 px (else 1), then home_video_config()'s choices for the
 * registration image (500 keypoints per sign; automatic hough_downscale: the 4x4-box copy where
 * that is at least 96 px wide, else home_video_config's) with 88 theta bins, a theta window from
 * max_rotation, refinement on with 1024 points, ending at half size; key frames on. */
int home_stab_default_config(home_stab_config *cfg, int width, int height);

/* HOME_OK when every field is in range (sizes even, registration size within HOME's limits). */
int home_stab_validate_config(const home_stab_config *cfg);

/* Exact bytes home_stab_init() needs; 0 when cfg is invalid. */
size_t home_stab_arena_size(const home_stab_config *cfg);

/* Lay a stabiliser out in arena (aligned to HOME_ARENA_ALIGN). On HOME_E_ARENA_SMALL, *needed
 * (if not NULL) receives the size required. */
int home_stab_init(home_stab **stab, const home_stab_config *cfg, void *arena,
                   size_t arena_bytes, size_t *needed);

/* Push the newest frame (its luma only is read, during the call). out->ready says whether a
 * frame is due: with lookahead N, the frame pushed N calls earlier. */
int home_stab_push(home_stab *stab, const home_stab_image *frame, home_stab_output *out);

/* End of stream: report the next queued frame (out->ready = 0 once none is left). */
int home_stab_flush(home_stab *stab, home_stab_output *out);

/* Forget the path and queued frames (e.g. after a capture restart): frames still queued are
 * dropped. */
int home_stab_reset(home_stab *stab);

/* The next frame pushed starts a new scene, as a detected cut does (see the top of this file):
 * for a caller that knows of a cut or a discontinuity (an edit, a stream switch). Nothing
 * queued is lost. */
int home_stab_cut(home_stab *stab);

/* Warp src into dst (same format and size) by the affine map warp (output luma pixel -> source
 * luma pixel), bilinear in fixed point, edges replicated. HOME_E_CONFIG when the map is not
 * affine or sends the frame further than one frame size outside the source. */
int home_stab_warp(const double *warp, const home_stab_image *src, home_stab_image *dst);

/* home_stab_warp() for the output luma rows first_row .. first_row + rows - 1 only (and their
 * chroma rows): the same bytes there, nothing else written. Bands on several threads split the
 * warp across cores (the library keeps no state: any thread may call it). I420 and NV12 bands
 * start and end on an even row; HOME_E_CONFIG otherwise or outside the frame. */
int home_stab_warp_rows(const double *warp, const home_stab_image *src, home_stab_image *dst,
                        int first_row, int rows);

/* The warp home_stab_push() reports for a frame of camera path raw and smoothed path smooth,
 * through cfg's crop margins (the correction shrunk where the window would leave the frame;
 * *correction_used, if not NULL, gets the share kept): for a caller that picks the margins
 * after seeing the whole path (home-stab's adaptive crop). HOME_E_CONFIG for a path that is not
 * finite. */
int home_stab_crop_warp(const home_stab_config *cfg, const home_stab_sim *raw,
                        const home_stab_sim *smooth, double *warp, double *correction_used);

/* The smallest share (0..1) of cfg's margins, both scaled by it (margin_x = (float)(share *
 * margin_x), the same for y), through which the frame's whole correction keeps the window inside
 * the frame; 1 when it needs them all or more. */
int home_stab_margin_share(const home_stab_config *cfg, const home_stab_sim *raw,
                           const home_stab_sim *smooth, double *share);

/* Similarity parameters <-> 3x3 matrices (about the centre of a width x height frame). */
void home_stab_sim_to_matrix(const home_stab_sim *s, int width, int height, double *m);

#ifdef __cplusplus
}
#endif
#endif
