/* Live electronic image stabilisation on HOME registration: camera path from per-frame
 * similarities, constant-velocity Kalman filter plus fixed-lag RTS smoothing over the lookahead,
 * crop-window constraint, hold-on-failure. See include/home_stab.h for the contract. This file:
 * configuration and arena, frames in (registration at the chosen size) and out (the crop
 * window); the similarities are in stab_motion.c, the path's filter in stab_path.c. */
#include "home_internal.h" /* home__refine_determined_motion() */
#include "home_stab.h"
#include "kernels.h"
#include "stab_internal.h"
#include <math.h>
#include <string.h>

#define STAB_MAGIC 0x48535442u            /* "HSTB" */
#define STAB_BISECT_STEPS 30
#define STAB_THETA_BINS 88                /* HOME's automatic theta bins for video registration */
#define STAB_REFINE_POINTS 1024           /* HOME's refinement template points at full size */
/* automatic hough_downscale: the 4x4-box copy down to this width (home_video_config's stops at
 * 160 px): the same jitter on the real-world set's 384x288 clips at 2/3 of the time (at 91 px,
 * 364 px wide, one clip's was worse: bench/stab/README.md) */
#define STAB_HOUGH_MIN_WIDTH 96
/* A registration's predicted error (sigma_px, full-size px) weighs its motion: the measurement
 * noise of its frame is r (1 + (sigma / STAB_SIGMA_REF_PX)^2), so a coarse or uncertain motion
 * pulls the path less; beyond STAB_MAX_SIGMA_PX the frame holds the path. */
#define STAB_SIGMA_REF_PX 0.5
#define STAB_MAX_SIGMA_PX 4.0
/* Key frames (key_check(), key_update()): */
#define STAB_KEY_THETA_BINS 240 /* theta bins of their registration */
#define STAB_KEY_MAX_AGE 30     /* frames after the key frame that are registered against it */
#define STAB_KEY_QUIET 8        /* a frame becomes the key frame only this many frames after
                                   the last one that left a part of the frame unexplained */
#define STAB_KEY_APART_PX 3.0   /* the key registration overrules the path when the two are
                                   this far apart (corner px) beyond 3 of its sigma_px, */
#define STAB_KEY_AGREE_PX 1.0   /* ... and vouches for it within this: the next */
#define STAB_KEY_TRUSTED 8      /* ... this many frames are not checked */
#define STAB_KEY_RETRY 4        /* a key registration that fails is tried again only this
                                   many frames later */
#define STAB_KEY_SHARE 0.15     /* a check starts where at least this share of the regions is
                                   unexplained (a smaller part continues one that found the
                                   path apart within STAB_KEY_TRUSTED frames) */
/* A scene cut: thumbnails correlating below STAB_CUT_SIMILARITY at every shift of up to
 * max_shift (at most STAB_CUT_MAX_SHIFT_CELLS cells, so that most cells are compared) */
#define STAB_CUT_SIMILARITY 0.5
#define STAB_CUT_MAX_SHIFT_CELLS 4

/* The smoothing time constant in frames. Automatic (0): with a lookahead of N frames the fixed-lag
 * smoother needs a lag of about twice the time constant to reach the full smoother's response,
 * so N / 2 (at least 3); causal, and below a lookahead of 5 (too short to centre even a
 * 3-frame smoother), 15. The measurements: docs/presets.md. */
#define STAB_CAUSAL_TIME_CONSTANT 15.0
#define STAB_MIN_CENTRED_LOOKAHEAD 5
static double stab_time_constant(const home_stab_config *cfg)
{
    if (cfg->smoothing > 0.0f) return cfg->smoothing;
    if (cfg->lookahead < STAB_MIN_CENTRED_LOOKAHEAD) return STAB_CAUSAL_TIME_CONSTANT;
    return cfg->lookahead / 2.0 < 3.0 ? 3.0 : cfg->lookahead / 2.0;
}

static size_t align_up(size_t n)
{
    return (n + HOME_ARENA_ALIGN - 1) / HOME_ARENA_ALIGN * HOME_ARENA_ALIGN;
}

static int is_finite_in(double v, double lo, double hi)
{
    return isfinite(v) && v >= lo && v <= hi;
}

int home_stab_default_config(home_stab_config *cfg, int width, int height)
{
    if (!cfg) return HOME_E_NULL;
    memset(cfg, 0, sizeof *cfg);
    cfg->width = width;
    cfg->height = height;
    cfg->margin_x = cfg->margin_y = 0.10f;
    cfg->smoothing = 0.0f;   /* automatic: see home_stab_config */
    cfg->lookahead = 0;
    /* the virtual camera starts from and comes to rest at the ends (docs/presets.md: the ITF /
     * jitter trade) */
    cfg->ease = 1.0f;
    /* registration at full size up to 960 px wide: half size costs textureless clips jitter */
    cfg->downscale = width > 960 ? 2 : 1;
    cfg->min_inliers = 20;
    cfg->refine = 1;
    /* the refinement ends at half size: as smooth as the full-size ending, and cheaper */
    cfg->refine_finest_level = 1;
    cfg->hough_downscale = 0;   /* automatic: the 4x4-box copy down to 96 px wide, else
                                   home_video_config's */
    {
        home_config h;
        home_video_config(&h, HOME_MIN_SIDE, HOME_MIN_SIDE);
        cfg->keypoints_per_sign = h.keypoints_per_sign;
        cfg->simd = h.simd;   /* HOME's default, including its HOME_SIMD override */
    }
    cfg->key_frames = 1;
    cfg->max_shift = 0.15f;
    cfg->max_rotation = 0.15f;
    cfg->max_zoom = 0.10f;
    cfg->max_residual = 0.025f * (float)width;
    return home_stab_validate_config(cfg) == HOME_E_SIZE ? HOME_E_SIZE : HOME_OK;
}

/* The HOME configuration registration runs with. */
static int home_config_for(const home_stab_config *cfg, home_config *h)
{
    int f = cfg->downscale, status, bins;
    if (f != 1 && f != 2 && f != 4) return HOME_E_CONFIG;
    status = home_video_config(h, cfg->width / f, cfg->height / f);
    if (status != HOME_OK) return status;
    h->keypoints_per_sign = cfg->keypoints_per_sign;
    h->min_inliers = cfg->min_inliers;
    if (!cfg->refine) h->refine_levels = 0;
    /* a quarter of HOME's 4096: as smooth, and cheaper (docs/presets.md) */
    h->refine_points = STAB_REFINE_POINTS;
    /* the path is a similarity: ask for one, so scenes of a few edges, which leave a
     * homography undetermined, still register */
    h->max_model = HOME_MODEL_SIMILARITY;
    /* coarse estimates come back with their (larger) sigma, weighed by the smoother */
    h->max_sigma_px = (float)(STAB_MAX_SIGMA_PX / f);
    h->refine_finest_level = cfg->refine ? cfg->refine_finest_level : 0;
    if (cfg->hough_downscale)
        h->hough_downscale = cfg->hough_downscale;
    else if (cfg->width / f >= 4 * STAB_HOUGH_MIN_WIDTH && cfg->height / f >= 4 * HOME_MIN_SIDE)
        h->hough_downscale = 4;
    h->simd = cfg->simd;
    /* 88 instead of the video defaults' 120 theta bins: the refinement gives the precision, and
     * 88 is the fewest that keep enough inliers under strong shake (docs/presets.md) */
    bins = cfg->theta_bins ? cfg->theta_bins : STAB_THETA_BINS;
    if (bins < 16 || bins > HOME_MAX_THETA_BINS) return HOME_E_CONFIG;
    h->wrap_band = h->wrap_band * bins / h->theta_bins;
    h->theta_bins = bins;
    /* video motion prior: lines rotate by at most max_rotation between frames (+2 bins) */
    h->match_theta_window = (int)ceil(cfg->max_rotation * h->theta_bins / 3.14159265358979) + 2;
    if (h->match_theta_window > h->theta_bins) h->match_theta_window = h->theta_bins;
    /* cfg.clock times the whole registration (ms_register): HOME's own per-stage clock, read
     * on every Hough row, is left off */
    return home_validate_config(h);
}

int home_stab_validate_config(const home_stab_config *cfg)
{
    home_config h;
    if (!cfg) return HOME_E_NULL;
    if (cfg->width < HOME_MIN_SIDE || cfg->height < HOME_MIN_SIDE || cfg->width > HOME_MAX_SIDE ||
        cfg->height > HOME_MAX_SIDE || cfg->width % 2 || cfg->height % 2)
        return HOME_E_SIZE;
    if (!is_finite_in(cfg->margin_x, 0.0, 0.4) || !is_finite_in(cfg->margin_y, 0.0, 0.4) ||
        !(cfg->smoothing == 0.0f || is_finite_in(cfg->smoothing, 1.0, 1000.0)) ||
        cfg->lookahead < 0 || cfg->lookahead > HOME_STAB_MAX_LOOKAHEAD ||
        !is_finite_in(cfg->ease, 0.0, 1.0) || (cfg->refine != 0 && cfg->refine != 1) ||
        (cfg->key_frames != 0 && cfg->key_frames != 1) ||
        (cfg->refine_finest_level != 0 && cfg->refine_finest_level != 1) ||
        !is_finite_in(cfg->max_shift, 0.0, 1.0) || !is_finite_in(cfg->max_rotation, 0.0, 1.6) ||
        !is_finite_in(cfg->max_zoom, 0.0, 1.0) || !is_finite_in(cfg->max_residual, 0.0, 1e6))
        return HOME_E_CONFIG;
    return home_config_for(cfg, &h);
}

static int ring_length(const home_stab_config *cfg)
{
    const int n = 2 * cfg->lookahead + 1;
    return n < HOME__STAB_MIN_RING ? HOME__STAB_MIN_RING : n;
}

typedef struct stab_layout {
    size_t stab, home, feat, small, ring, key_home, key_luma, key_feat, total;
    size_t home_bytes, key_home_bytes;
} stab_layout;

/* The key frame's registration: HOME's still-pair defaults on the registration image (a
 * full-size Hough transform: the downscaled one the frames use finds too few lines past a
 * large occluder), capped at a similarity as the frames are. */
static int key_config_for(const home_config *h, home_config *key)
{
    int status = home_default_config(key, h->width, h->height);
    if (status != HOME_OK) return status;
    key->max_model = HOME_MODEL_SIMILARITY;
    /* half the bins and a quarter of the points: as accurate past an occluder, cheaper */
    key->wrap_band = key->wrap_band * STAB_KEY_THETA_BINS / key->theta_bins;
    key->theta_bins = STAB_KEY_THETA_BINS;
    key->refine_points = STAB_REFINE_POINTS;
    key->refine_finest_level = 1;
    /* the frames' roll prior, in the key's bins: a key registration rotated further is refused
     * as implausible anyway (plausible_motion()), so matches beyond it need not be tried */
    key->match_theta_window =
        (h->match_theta_window * STAB_KEY_THETA_BINS + h->theta_bins - 1) / h->theta_bins;
    if (key->match_theta_window > STAB_KEY_THETA_BINS) key->match_theta_window = STAB_KEY_THETA_BINS;
    key->fast_pass_downscale = 0; /* features of one image at a time (home_extract) */
    key->simd = h->simd;
    return home_validate_config(key);
}

static void plan(const home_stab_config *cfg, const home_config *h, stab_layout *l)
{
    home_config key;
    size_t at = 0;
    l->stab = at; at = align_up(at + sizeof(home_stab));
    l->home_bytes = home_arena_size(h);
    l->home = at; at = align_up(at + l->home_bytes);
    l->feat = at; at = align_up(at + 3 * sizeof(home_features)); /* previous, current, anchor */
    l->small = at; at = align_up(at + (size_t)h->width * (size_t)h->height);
    l->ring = at; at = align_up(at + (size_t)ring_length(cfg) * sizeof(stab_slot));
    l->key_home_bytes = 0;
    if (cfg->key_frames && key_config_for(h, &key) == HOME_OK) {
        l->key_home_bytes = home_arena_size(&key);
        l->key_home = at; at = align_up(at + l->key_home_bytes);
        l->key_luma = at; at = align_up(at + (size_t)h->width * (size_t)h->height);
        l->key_feat = at; at = align_up(at + 2 * sizeof(home_features));
    }
    l->total = at;
}

size_t home_stab_arena_size(const home_stab_config *cfg)
{
    home_config h;
    stab_layout l;
    if (home_stab_validate_config(cfg) != HOME_OK) return 0;
    home_config_for(cfg, &h);
    plan(cfg, &h, &l);
    return l.total;
}

int home_stab_init(home_stab **out, const home_stab_config *cfg, void *arena, size_t arena_bytes,
                   size_t *needed)
{
    home_config h;
    stab_layout l;
    home_stab *st;
    unsigned char *base = (unsigned char *)arena;
    int status;
    if (needed) *needed = 0;
    if (!out || !cfg || !arena) return HOME_E_NULL;
    *out = NULL;
    if ((status = home_stab_validate_config(cfg)) != HOME_OK) return status;
    if ((uintptr_t)arena % HOME_ARENA_ALIGN) return HOME_E_ARENA_ALIGN;
    home_config_for(cfg, &h);
    plan(cfg, &h, &l);
    if (needed) *needed = l.total;
    if (arena_bytes < l.total) return HOME_E_ARENA_SMALL;

    st = (home_stab *)(void *)(base + l.stab);
    memset(st, 0, sizeof *st);
    st->cfg = *cfg;
    status = home_init(&st->home, &h, base + l.home, l.home_bytes, NULL);
    if (status != HOME_OK) return status;
    st->feat[0] = (home_features *)(void *)(base + l.feat);
    st->feat[1] = st->feat[0] + 1;
    st->anchor = st->feat[0] + 2;
    st->anchor_frame = -1;
    memset(st->feat[0], 0, 3 * sizeof(home_features));
    {
        const home__kernels *k = home__kernels_for(h.simd);
        st->box_down = (k ? k : &home__kernels_scalar)->box_down;
    }
    st->small = base + l.small;
    st->small_w = h.width;
    st->small_h = h.height;
    st->ring = (stab_slot *)(void *)(base + l.ring);
    st->ring_len = ring_length(cfg);
    st->key_frame = st->key_feat_frame = st->last_unexplained = -1;
    st->key_agreed = st->key_failed = st->key_apart = -1;
    if (l.key_home_bytes) {
        home_config key;
        key_config_for(&h, &key);
        status = home_init(&st->key_home, &key, base + l.key_home, l.key_home_bytes, NULL);
        if (status != HOME_OK) return status;
        st->key_luma = base + l.key_luma;
        st->key_feat = (home_features *)(void *)(base + l.key_feat);
    }
    /* Kalman bandwidth ~ (q/r)^(1/4) per frame for the constant-velocity model */
    st->r = 1.0;
    st->q = 1.0 / pow(stab_time_constant(cfg), 4.0);
    st->sees_ahead = cfg->lookahead >= stab_time_constant(cfg);
    st->norm = 0.5 * sqrt((double)cfg->width * cfg->width + (double)cfg->height * cfg->height);
    st->magic = STAB_MAGIC;
    *out = st;
    return HOME_OK;
}

int home_stab_reset(home_stab *st)
{
    if (!st) return HOME_E_NULL;
    if (st->magic != STAB_MAGIC) return HOME_E_STATE;
    st->pushed = st->emitted = st->first = 0;
    st->tail = st->cut_requested = 0;
    st->key_frame = st->key_feat_frame = st->last_unexplained = -1;
    st->key_agreed = st->key_failed = st->key_apart = -1;
    return HOME_OK;
}

int home_stab_cut(home_stab *st)
{
    if (!st) return HOME_E_NULL;
    if (st->magic != STAB_MAGIC) return HOME_E_STATE;
    st->cut_requested = 1;
    return HOME_OK;
}

/* The segment ends with frame last: its motions still undecided are settled with the frames
 * there are after them, and every frame still due is smoothed over the mirrored end. */
static void end_segment(home_stab *st, long last)
{
    long t;
    for (t = last - home__stab_still_delay(st) + 1; t <= last; t++) {
        home__stab_settle_still(st, t, last);
        home__stab_settle_restored(st, t, last);
        home__stab_ease_still(st, t, last);
    }
    home__stab_end_segment(st, last);
}

/* A frame HOME could not register to its predecessor starts a new scene when its coarse luma is
 * unlike the predecessor's at every plausible shift, gain and offset (docs/stabiliser.md: with
 * 0.5 the tests and both halves of bench/stab's real-world set find every cut and nothing
 * else). */
static int is_scene_cut(const home_stab *st)
{
    const int max_shift_cells = (int)ceil(st->cfg.max_shift * HOME__STAB_THUMB_SIDE);
    return home__stab_thumb_similarity(st->thumb[st->thumb_index ^ 1], st->thumb[st->thumb_index],
                                       max_shift_cells < STAB_CUT_MAX_SHIFT_CELLS
                                           ? max_shift_cells : STAB_CUT_MAX_SHIFT_CELLS)
           < STAB_CUT_SIMILARITY;
}

/* Box-average the frame's luma into st->small; returns the image registration reads. */
static const uint8_t *registration_luma(home_stab *st, const home_stab_image *im, ptrdiff_t *stride)
{
    const int f = st->cfg.downscale, step = im->format == HOME_STAB_YUYV ? 2 : 1;
    const uint8_t *y = im->plane[0];
    int i, j, a, b;
    if (f == 1 && step == 1) {
        *stride = im->stride[0];
        return y;
    }
    if (step == 1) {
        for (j = 0; j < st->small_h; j++)
            st->box_down(y + (ptrdiff_t)(j * f) * im->stride[0], im->stride[0], f,
                         st->small + (ptrdiff_t)j * st->small_w, st->small_w);
        *stride = st->small_w;
        return st->small;
    }
    for (j = 0; j < st->small_h; j++)
        for (i = 0; i < st->small_w; i++) {
            unsigned sum = 0;
            for (b = 0; b < f; b++) {
                const uint8_t *row = y + (ptrdiff_t)(j * f + b) * im->stride[0];
                for (a = 0; a < f; a++) sum += row[(ptrdiff_t)(i * f + a) * step];
            }
            st->small[(ptrdiff_t)j * st->small_w + i] =
                (uint8_t)((sum + (unsigned)(f * f / 2)) / (unsigned)(f * f));
        }
    *stride = st->small_w;
    return st->small;
}

/* output pixel -> input pixel for a correction (virtual camera -> real camera) share k, through
 * a window with margins mx, my */
static void crop_warp(const home_stab_config *cfg, double mx, double my, const home_stab_sim *corr,
                      double k, double *m)
{
    const double zx = 1.0 - 2.0 * mx, zy = 1.0 - 2.0 * my;
    const double cx = 0.5 * (cfg->width - 1), cy = 0.5 * (cfg->height - 1);
    home_stab_sim part = home__stab_sim_scaled(corr, k);
    double d[9];
    int i;
    home_stab_sim_to_matrix(&part, cfg->width, cfg->height, d);
    /* d after the zoom q -> c + diag(zx, zy) (q - c) */
    for (i = 0; i < 2; i++) {
        m[3 * i + 2] = d[3 * i + 0] * cx * (1 - zx) + d[3 * i + 1] * cy * (1 - zy) + d[3 * i + 2];
        m[3 * i + 0] = d[3 * i + 0] * zx;
        m[3 * i + 1] = d[3 * i + 1] * zy;
    }
    m[6] = 0; m[7] = 0; m[8] = 1;
}

static int window_inside(const home_stab_config *cfg, const double *m)
{
    const double xmax = cfg->width - 1, ymax = cfg->height - 1;
    int i;
    for (i = 0; i < 4; i++) {
        double x = (i & 1) ? xmax : 0.0, y = (i & 2) ? ymax : 0.0, u, v;
        home__stab_apply(m, x, y, &u, &v);
        if (!(u >= 0.0 && u <= xmax && v >= 0.0 && v <= ymax)) return 0;
    }
    return 1;
}

/* The warp for a frame of camera path raw and smoothed path smooth through margins mx, my: the
 * whole correction, or the largest share of it that keeps the window inside (0 always does). */
/* The real camera seen from the virtual (smoothed) one: raw after smooth^-1 */
static home_stab_sim correction(const home_stab_sim *raw, const home_stab_sim *smooth)
{
    const home_stab_sim inv_smooth = home__stab_sim_inverse(smooth);
    return home__stab_sim_compose(raw, &inv_smooth);
}

static double crop(const home_stab_config *cfg, double mx, double my, const home_stab_sim *raw,
                   const home_stab_sim *smooth, double *warp)
{
    const home_stab_sim corr = correction(raw, smooth);
    double lo = 0.0, hi = 1.0;
    int i;
    crop_warp(cfg, mx, my, &corr, 1.0, warp);
    if (window_inside(cfg, warp)) return 1.0;
    for (i = 0; i < STAB_BISECT_STEPS; i++) {
        double mid = 0.5 * (lo + hi), w[9];
        crop_warp(cfg, mx, my, &corr, mid, w);
        if (window_inside(cfg, w)) lo = mid; else hi = mid;
    }
    crop_warp(cfg, mx, my, &corr, lo, warp);
    return lo;
}

static int valid_path(const home_stab_sim *s)
{
    return isfinite(s->tx) && isfinite(s->ty) && isfinite(s->angle) && isfinite(s->log_scale);
}

int home_stab_crop_warp(const home_stab_config *cfg, const home_stab_sim *raw,
                        const home_stab_sim *smooth, double *warp, double *correction_used)
{
    double used;
    int status;
    if (!cfg || !raw || !smooth || !warp) return HOME_E_NULL;
    if ((status = home_stab_validate_config(cfg)) != HOME_OK) return status;
    if (!valid_path(raw) || !valid_path(smooth)) return HOME_E_CONFIG;
    used = crop(cfg, cfg->margin_x, cfg->margin_y, raw, smooth, warp);
    if (correction_used) *correction_used = used;
    return HOME_OK;
}

int home_stab_margin_share(const home_stab_config *cfg, const home_stab_sim *raw,
                           const home_stab_sim *smooth, double *share)
{
    home_stab_sim corr;
    double lo = 0.0, hi = 1.0, w[9];
    int i, status;
    if (!cfg || !raw || !smooth || !share) return HOME_E_NULL;
    if ((status = home_stab_validate_config(cfg)) != HOME_OK) return status;
    if (!valid_path(raw) || !valid_path(smooth)) return HOME_E_CONFIG;
    *share = 1.0;
    /* crop() < 1 exactly where the whole correction's window leaves the frame */
    corr = correction(raw, smooth);
    crop_warp(cfg, cfg->margin_x, cfg->margin_y, &corr, 1.0, w);
    if (!window_inside(cfg, w)) return HOME_OK;
    /* the margins as the float fields a caller sets from the share */
    for (i = 0; i < STAB_BISECT_STEPS; i++) {
        const double mid = 0.5 * (lo + hi);
        crop_warp(cfg, (float)(mid * cfg->margin_x), (float)(mid * cfg->margin_y), &corr, 1.0, w);
        if (!window_inside(cfg, w))
            lo = mid;
        else
            hi = mid;
    }
    *share = hi;
    return HOME_OK;
}

static void emit(home_stab *st, long last, home_stab_output *out)
{
    const long m = st->emitted;
    const stab_slot *slot = slot_of(st, m);
    out->ready = 1;
    out->frame = m;
    out->raw = slot->raw;
    out->motion_status = slot->status;
    out->smooth = slot->smoothed_ready ? slot->smoothed : home__stab_smoothed_path(st, m, last);
    out->correction_used =
        crop(&st->cfg, st->cfg.margin_x, st->cfg.margin_y, &out->raw, &out->smooth, out->warp);
    st->emitted++;
}

/* The similarity of a registration's H when it is within the configured limits (1), with the
 * weight its predicted error gives it. */
static int plausible_motion(const home_stab *st, const home_result *reg, home_stab_sim *motion,
                            double *weight)
{
    /* home__stab_fit_similarity() fills s when it returns >= 0 */
    home_stab_sim s = {0, 0, 0, 0};
    const double res = home__stab_fit_similarity(st, reg->H, &s);
    double sigma;
    if (!(res >= 0.0 && res <= st->cfg.max_residual &&
          hypot(s.tx, s.ty) <= st->cfg.max_shift * st->cfg.width &&
          fabs(s.angle) <= st->cfg.max_rotation && fabs(s.log_scale) <= st->cfg.max_zoom))
        return 0;
    sigma = reg->sigma_px * st->cfg.downscale;
    if (!(sigma <= STAB_MAX_SIGMA_PX)) return 0;   /* a refused motion may be undetermined */
    *motion = s;
    *weight = 1.0 + (sigma / STAB_SIGMA_REF_PX) * (sigma / STAB_SIGMA_REF_PX);
    return 1;
}

/* A frame with too little structure for HOME (few lines, no refinement to vouch: a horizon in
 * fog) still determines part of its motion: that part, when plausible (1). Not for frames
 * refused for what they show (moving objects, a pattern), only for what they lack. */
static int partial_motion(const home_stab *st, const home_result *reg, home_stab_sim *motion,
                          double *weight)
{
    home_result part;
    if (reg->failure != HOME_FAIL_FEW_INLIERS) return 0;
    memset(&part, 0, sizeof part);
    if (!home__refine_determined_motion(st->home, st->feat[0]->frame_id, st->feat[1]->frame_id,
                                        part.H, &part.sigma_px))
        return 0;
    return plausible_motion(st, &part, motion, weight);
}

static int check_stab(const home_stab *st, const home_stab_output *out)
{
    if (!st || !out) return HOME_E_NULL;
    return st->magic == STAB_MAGIC ? HOME_OK : HOME_E_STATE;
}

/* A frame held with no refused motion the restore could take. */
static int held_for_good(const stab_slot *s)
{
    return (s->status == HOME_STAB_MOTION_FAILED && !s->has_candidate) ||
           s->status == HOME_STAB_MOTION_IMPLAUSIBLE;
}

/* The path from frame a to frame n becomes m_an (weight): where every frame of (a, n] was held
 * each takes an equal share, else frame k (the last held one, or n itself) takes what closes
 * the gap and the motions after it stay. */
static void close_gap(home_stab *st, long a, long k, long n, int all_held,
                      const home_stab_sim *m_an, double weight)
{
    home_stab_sim target, post, m_k;
    long i;
    if (all_held) {
        const home_stab_sim share = home__stab_sim_scaled(m_an, 1.0 / (double)(n - a));
        for (i = a + 1; i < n; i++)
            home__stab_retake_motion(st, i, n, &share, HOME_STAB_MOTION_BRIDGED, weight);
    }
    /* raw_n' = m_an raw_a, and raw_n' = post m_k raw_(k-1), post the motions after k */
    target = home__stab_sim_compose(m_an, &slot_of(st, a)->raw);
    {
        const home_stab_sim inv_k = home__stab_sim_inverse(&slot_of(st, k)->raw);
        post = home__stab_sim_compose(&slot_of(st, n)->raw, &inv_k);
    }
    {
        const home_stab_sim inv_post = home__stab_sim_inverse(&post);
        const home_stab_sim inv_before = home__stab_sim_inverse(&slot_of(st, k - 1)->raw);
        const home_stab_sim rest = home__stab_sim_compose(&target, &inv_before);
        m_k = home__stab_sim_compose(&inv_post, &rest);
    }
    home__stab_retake_motion(st, k, n, &m_k, HOME_STAB_MOTION_BRIDGED, weight);
}

/* Frame n (features in feat[0]) against the anchor, the last frame a before a hold among
 * frames that register a moving camera (home__stab_camera_moves()): when HOME
 * registers it there, the held frames in (a, n] take the motion that makes the path from a to
 * n that registration, and the hold is over. Where all of (a, n] was held, each frame takes an
 * equal share (the last one what closes the gap exactly); else the last held frame takes all.
 * The anchor's refinement snapshot is gone, so this is HOME's own estimate, weighted by its
 * sigma. */
static int bridge(home_stab *st, long n)
{
    home_result reg;
    home_stab_sim m_an;
    double weight;
    long a = st->anchor_frame, k, i;
    int all_held = 1;
    /* not across a cut, nor over a frame the restore may still take (its motion would count
     * twice) */
    for (i = a + 1; i <= n; i++) {
        const stab_slot *s = slot_of(st, i);
        if (s->status == HOME_STAB_MOTION_CUT ||
            (s->status == HOME_STAB_MOTION_FAILED && s->has_candidate))
            return 0;
        all_held &= held_for_good(s);
    }
    /* frames settled since the anchor was set may have shown a still camera after all */
    if (!home__stab_camera_moves(st, a)) return 0;
    for (k = n; k > a && !held_for_good(slot_of(st, k)); k--)
        ;
    if (k <= a || (all_held ? a + 1 : k) < st->emitted) return 0;
    if (home_match(st->home, st->anchor, st->feat[0], &reg) != HOME_OK || !reg.ok ||
        !plausible_motion(st, &reg, &m_an, &weight))
        return 0;
    close_gap(st, a, k, n, all_held, &m_an, weight);
    return 1;
}

/* Frame n's ok motion leaves a part of the frame unexplained while the camera moves: a second
 * motion (an object crossing, a hand at the lens) that HOME may have followed instead of the
 * camera. The key frame, from before that part appeared, is registered against frame n (HOME's
 * still-pair defaults); where that places frame n farther from the path than 3 of its
 * predicted errors and STAB_KEY_APART_PX allow, the path takes it, as a bridge: the object's
 * motion is not the camera's, and frames held on the way get their missed motion. An answer HOME refuses
 * only because its refinement did not converge (the moving part pulls it) is used too; one
 * refused because the background stood still is not (a still camera over movers). */
static void key_check(home_stab *st, long n, const uint8_t *luma, ptrdiff_t stride)
{
    const long a = st->key_frame;
    home_result reg;
    home_stab_sim m_an, chain, off;
    double weight, d;
    long k, i;
    int decided;
    /* the key frame's path must still be in the ring (causal: 11 frames) */
    if (!st->key_home || a < st->first || a >= n || n - a > STAB_KEY_MAX_AGE ||
        (st->key_agreed > a && n - st->key_agreed <= STAB_KEY_TRUSTED) ||
        (st->key_failed > a && n - st->key_failed < STAB_KEY_RETRY) ||
        n - a >= st->ring_len || slot_of(st, a)->frame != a)
        return;
    /* a camera that moved in most of the decided frames before (else the frame may be a
     * still camera's over moving objects: stab_still.c decides those) */
    if (2 * home__stab_moved_before(st, n, &decided) <= decided) return;
    /* not across a cut, nor over a frame the restore may still take */
    for (i = a + 1; i <= n; i++) {
        const stab_slot *s = slot_of(st, i);
        if (s->status == HOME_STAB_MOTION_CUT ||
            (s->status == HOME_STAB_MOTION_FAILED && s->has_candidate &&
             i > n - home__stab_still_delay(st)))
            return;
    }
    /* the key frame is frame n's predecessor: the part frame n leaves unexplained is new in
     * it, so the frame's own motion cannot be that part's yet; it vouches as an agreeing key
     * registration would */
    if (a == n - 1) {
        st->key_agreed = n;
        return;
    }
    /* an object draws HOME's lines to itself only where it covers much of the frame: a
     * smaller unexplained part (a hand's edge, parallax) starts no check */
    if (slot_of(st, n)->unexplained < STAB_KEY_SHARE &&
        !(st->key_apart > a && n - st->key_apart <= STAB_KEY_TRUSTED))
        return;
    for (k = n; k > a && !held_for_good(slot_of(st, k)); k--)
        ;
    if (k <= a || k < st->emitted) k = n;
    /* the key frame's features and refinement snapshot are extracted once and kept: only
     * frame n's are new for each frame registered against it */
    if (st->key_feat_frame != a) {
        if (home_extract(st->key_home, st->key_luma, st->small_w, &st->key_feat[0]) != HOME_OK)
            return;
        home__refine_keep(st->key_home, st->key_feat[0].frame_id);
        st->key_feat_frame = a;
    }
    if (home_extract(st->key_home, luma, stride, &st->key_feat[1]) != HOME_OK ||
        home_match(st->key_home, &st->key_feat[0], &st->key_feat[1], &reg) != HOME_OK)
        return;
    if (!(reg.ok || reg.refine_status == HOME_REFINE_NOT_CONVERGED) ||
        !plausible_motion(st, &reg, &m_an, &weight)) {
        st->key_failed = n;
        return;
    }
    {
        const home_stab_sim inv_a = home__stab_sim_inverse(&slot_of(st, a)->raw);
        chain = home__stab_sim_compose(&slot_of(st, n)->raw, &inv_a);
    }
    {
        const home_stab_sim inv_chain = home__stab_sim_inverse(&chain);
        off = home__stab_sim_compose(&m_an, &inv_chain);
    }
    d = home__stab_corner_motion(st, &off) - 3.0 * reg.sigma_px * st->cfg.downscale;
    if (d <= STAB_KEY_AGREE_PX) st->key_agreed = n;
    if (d > STAB_KEY_APART_PX) {
        st->key_apart = n;
        close_gap(st, a, k, n, 0, &m_an, weight);
    }
}

/* Frame n becomes the key frame when its motion left nothing unexplained and none of the
 * STAB_KEY_QUIET frames before it did (a frame between two that did may be the object's
 * motion with little left over). */
static void key_update(home_stab *st, long n, const uint8_t *luma, ptrdiff_t stride)
{
    const stab_slot *s = slot_of(st, n);
    int y;
    if (!st->key_home) return;
    if (!(n == st->first || s->status == HOME_STAB_MOTION_OK) ||
        (n - st->last_unexplained <= STAB_KEY_QUIET && st->last_unexplained >= st->first))
        return;
    for (y = 0; y < st->small_h; y++)
        memcpy(st->key_luma + (ptrdiff_t)y * st->small_w, luma + y * stride, (size_t)st->small_w);
    st->key_frame = n;
}

int home_stab_push(home_stab *st, const home_stab_image *frame, home_stab_output *out)
{
    const uint8_t *luma;
    ptrdiff_t stride;
    home_features *swap;
    home_stab_sim motion = {0, 0, 0, 0}, candidate = {0, 0, 0, 0};
    double weight = 1.0, candidate_weight = 1.0, score[3] = {0.0, 0.0, 0.0};
    double unexplained = 0.0;
    int has_candidate = 0, has_score = 0;
    stab_slot *slot;
    double t0 = 0, z[4];
    long n;
    int status = check_stab(st, out);
    if (status != HOME_OK) return status;
    if ((status = home__stab_check_image(frame)) != HOME_OK) return status;
    if (frame->width != st->cfg.width || frame->height != st->cfg.height) return HOME_E_MISMATCH;

    memset(out, 0, sizeof *out);
    if (st->cfg.clock) t0 = st->cfg.clock(st->cfg.clock_user);
    luma = registration_luma(st, frame, &stride);
    status = home_extract(st->home, luma, stride, st->feat[1]);
    if (status != HOME_OK) return status;
    n = st->pushed;
    out->newest_status = HOME_STAB_MOTION_FIRST;
    if (n > 0) {
        status = home_match(st->home, st->feat[0], st->feat[1], &out->reg);
        if (status != HOME_OK) return status;
        out->newest_status = HOME_STAB_MOTION_FAILED;
        if (out->reg.ok) {
            out->newest_status = HOME_STAB_MOTION_IMPLAUSIBLE;
            if (plausible_motion(st, &out->reg, &motion, &weight))
                out->newest_status = HOME_STAB_MOTION_OK;
            has_score = home__refine_last_score(st->home, &score[0], &score[1], &score[2]);
            unexplained = home__refine_last_unexplained(st->home);
        } else if (out->reg.refine_status == HOME_REFINE_STILL_BACKGROUND) {
            has_candidate = plausible_motion(st, &out->reg, &candidate, &candidate_weight);
        } else if (partial_motion(st, &out->reg, &motion, &weight)) {
            out->newest_status = HOME_STAB_MOTION_PARTIAL;
        }
    }
    swap = st->feat[0];
    st->feat[0] = st->feat[1];
    st->feat[1] = swap;
    st->thumb_index ^= 1;
    home__stab_thumbnail(luma, stride, st->small_w, st->small_h, st->thumb[st->thumb_index]);
    if (n > 0 && (st->cut_requested ||
                  (out->newest_status != HOME_STAB_MOTION_OK && is_scene_cut(st)))) {
        /* a new scene: the frames still due are smoothed as if the stream ended before it, and
         * its path starts afresh, so no smoothing window and no motion spans the cut */
        if (st->emitted < n) end_segment(st, n - 1);
        st->first = n;
        out->newest_status = HOME_STAB_MOTION_CUT;
        weight = 1.0;   /* as a stream's first frame */
        memset(&motion, 0, sizeof motion);
        has_candidate = 0;
        has_score = 0;
        unexplained = 0.0;
    }
    st->cut_requested = 0;
    if (st->cfg.clock) out->ms_register = st->cfg.clock(st->cfg.clock_user) - t0;

    slot = slot_of(st, n);
    slot->frame = n;
    slot->status = out->newest_status;
    slot->weight = weight;
    slot->motion = motion;
    slot->registered_still = out->newest_status == HOME_STAB_MOTION_OK &&
                             out->reg.model == HOME_MODEL_IDENTITY;
    slot->has_candidate = has_candidate;
    slot->candidate = candidate;
    slot->candidate_weight = candidate_weight;
    slot->has_score = has_score;
    memcpy(slot->score, score, sizeof score);
    slot->unexplained = unexplained;
    slot->smoothed_ready = 0;
    slot->ease = n > st->first ? home__stab_ease_after_move(st, n) : 0.0;
    if (n == st->first) {
        memset(&slot->raw, 0, sizeof slot->raw);
        home__stab_path_components(st, &slot->raw, z);
        home__stab_kalman_step(st, NULL, slot, z);
    } else {
        const stab_slot *prev = slot_of(st, n - 1);
        slot->raw = home__stab_sim_compose(&motion, &prev->raw);
        home__stab_path_components(st, &slot->raw, z);
        home__stab_kalman_step(st, prev, slot, z);
    }
    st->pushed = n + 1;
    st->tail = 0;
    /* a hold: the last frame before it stays as the anchor; a later frame may bridge it */
    if (st->anchor_frame >= 0 &&
        (slot->status == HOME_STAB_MOTION_CUT || n - st->anchor_frame > HOME__STAB_BRIDGE ||
         bridge(st, n)))
        st->anchor_frame = -1;
    if (st->anchor_frame < 0 && n > st->first && held_for_good(slot) &&
        home__stab_camera_moves(st, n - 1)) { /* a tripod's holds stay holds */
        swap = st->anchor; /* feat[1] holds frame n - 1's features until the next extract */
        st->anchor = st->feat[1];
        st->feat[1] = swap;
        st->anchor_frame = n - 1;
    }
    if (home__stab_leaves_part(slot)) {
        st->last_unexplained = n;
        key_check(st, n, luma, stride);
    } else {
        key_update(st, n, luma, stride);
    }
    home__stab_settle_still(st, n - home__stab_still_delay(st), n);
    home__stab_settle_restored(st, n - home__stab_still_delay(st), n);
    home__stab_ease_still(st, n - home__stab_still_delay(st), n);
    if (n - st->first == st->cfg.lookahead) home__stab_refilter_mirrored_start(st, st->first, n);
    if (n - st->emitted >= st->cfg.lookahead) emit(st, n, out);
    return HOME_OK;
}

int home_stab_flush(home_stab *st, home_stab_output *out)
{
    int status = check_stab(st, out);
    if (status != HOME_OK) return status;
    memset(out, 0, sizeof *out);
    if (st->emitted >= st->pushed) return HOME_OK;
    if (!st->tail) {
        end_segment(st, st->pushed - 1);
        st->tail = 1;
    }
    emit(st, st->emitted + st->cfg.lookahead, out);
    return HOME_OK;
}
