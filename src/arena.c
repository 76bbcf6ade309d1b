/* Configuration, arena layout and context initialisation. */
#include "home_internal.h"
#include <math.h>
#include <string.h>

const char *home_strerror(int status)
{
    switch (status) {
    case HOME_OK: return "success";
    case HOME_E_NULL: return "a required pointer argument is NULL";
    case HOME_E_SIZE: return "image size out of range (each side must be in [HOME_MIN_SIDE, HOME_MAX_SIDE])";
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
    cfg->keypoints_per_sign = HOME_MAX_KEYPOINTS_PER_SIGN < 1000 ? HOME_MAX_KEYPOINTS_PER_SIGN : 1000;
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
    /* ~2.4 px of the Hough image at its rim: on the video set (bench/eval) 120, 160, 240 and
     * 480 bins give the same errors once refined (120: 0.15 / 0.14 / 0.17 / 0.33 px); still
     * pairs at p = 40 / 50 / 60 fail 0 / 6 / 17 % (160 bins: 1 / 4 / 17 %); 11 % fewer
     * instructions per frame than 160 */
    cfg->theta_bins = 120;
    cfg->wrap_band = 7;           /* ~10 degrees, like the defaults' 27 of 480 */
    cfg->keypoints_per_sign = HOME_MAX_KEYPOINTS_PER_SIGN < 500 ? HOME_MAX_KEYPOINTS_PER_SIGN : 500;
    cfg->match_theta_window = 8;  /* 12 degrees of roll between frames */
    cfg->threshold_start = 8.0f;
    /* half the refinement's points: on the video set the same errors to 0.01 px (0.15 / 0.14 /
     * 0.17 / 0.35 against 0.14 / 0.14 / 0.17 / 0.34), 15 % fewer instructions per frame */
    cfg->refine_points = HOME_REFINE_MAX_POINTS < 2048 ? HOME_REFINE_MAX_POINTS : 2048;
    /* the refinement ends at half size: on the video set 0.18 / 0.16 / 0.21 / 0.25 px against
     * 0.15 / 0.14 / 0.17 / 0.33 at full size, ~30 % fewer instructions per frame (no full-size
     * blur, point selection or iterations) and ~250 KB less arena at 640x360 */
    cfg->refine_finest_level = cfg->refine_levels > 1 ? 1 : 0;
    return HOME_OK;
}

static int finite_in(float v, float lo, float hi)
{
    return isfinite(v) && v >= lo && v <= hi;
}

/* Bins needed so that |r| <= half diagonal (+1 bin of margin) fits; always even so r -> -r is
 * the mirror i -> r_bins-1-i. */
static int r_bins_for(int width, int height, float r_step)
{
    double half_diag = 0.5 * sqrt((double)(width - 1) * (width - 1) + (double)(height - 1) * (height - 1));
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

int home_validate_config(const home_config *cfg)
{
    if (!cfg) return HOME_E_NULL;
    if (cfg->width < HOME_MIN_SIDE || cfg->height < HOME_MIN_SIDE ||
        cfg->width > HOME_MAX_SIDE || cfg->height > HOME_MAX_SIDE)
        return HOME_E_SIZE;
    if (cfg->theta_bins < 16 || cfg->theta_bins > HOME_MAX_THETA_BINS) return HOME_E_CONFIG;
    if (cfg->wrap_band < 0 || cfg->wrap_band > cfg->theta_bins / 4) return HOME_E_CONFIG;
    if (!finite_in(cfg->r_step, 0.25f, 8.0f)) return HOME_E_CONFIG;
    if (cfg->r_bins != 0) {
        /* an explicit r axis must be even and cover the image diagonal */
        if (cfg->r_bins < 0 || (cfg->r_bins & 1) ||
            cfg->r_bins < home__r_bins(&(home_config){.width = cfg->width, .height = cfg->height,
                                         .r_step = cfg->r_step,
                                         .hough_downscale = cfg->hough_downscale}) ||
            cfg->r_bins > 4 * HOME_MAX_SIDE)
            return HOME_E_CONFIG;
    }
    if (!finite_in(cfg->smooth_sigma, 0.3f, HOME__MAX_SMOOTH_RADIUS / 3.0f)) return HOME_E_CONFIG;
    if (cfg->keypoints_per_sign < 8 || cfg->keypoints_per_sign > HOME_MAX_KEYPOINTS_PER_SIGN)
        return HOME_E_CONFIG;
    if (!finite_in(cfg->ratio, 0.1f, 1.0f)) return HOME_E_CONFIG;
    if (!finite_in(cfg->threshold_final, 0.05f, 1000.0f)) return HOME_E_CONFIG;
    if (!finite_in(cfg->threshold_start, cfg->threshold_final, 4096.0f)) return HOME_E_CONFIG;
    /* the halving schedule must fit HOME_MAX_THRESHOLD_LEVELS */
    if (cfg->threshold_start > cfg->threshold_final * (float)(1 << (HOME_MAX_THRESHOLD_LEVELS - 1)))
        return HOME_E_CONFIG;
    if (cfg->min_inliers < 4 || cfg->min_inliers > 2 * HOME_MAX_KEYPOINTS_PER_SIGN)
        return HOME_E_CONFIG;
    if (home__refine_validate(cfg) != HOME_OK) return HOME_E_CONFIG;
    if (!home__kernels_for(cfg->simd)) return HOME_E_CONFIG; /* unknown or not compiled in */
    if (cfg->hough_method != HOME_HOUGH_FAST && cfg->hough_method != HOME_HOUGH_EXACT)
        return HOME_E_CONFIG;
    if (cfg->hough_downscale != 1 &&
        ((cfg->hough_downscale != 2 && cfg->hough_downscale != 4) ||
         cfg->hough_method != HOME_HOUGH_FAST || cfg->width / cfg->hough_downscale < HOME_MIN_SIDE ||
         cfg->height / cfg->hough_downscale < HOME_MIN_SIDE))
        return HOME_E_CONFIG;
    if (cfg->match_theta_window < 0 || cfg->match_theta_window > cfg->theta_bins)
        return HOME_E_CONFIG;
    if (cfg->max_model < HOME_MODEL_IDENTITY || cfg->max_model > HOME_MODEL_HOMOGRAPHY)
        return HOME_E_CONFIG;
    if (!finite_in(cfg->max_sigma_px, 0.02f, 100.0f)) return HOME_E_CONFIG;
    return HOME_OK;
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

/* Arena layout: every block starts on a 64-byte boundary (cache line, widest SIMD load). */
#define BLOCK_ALIGN 64u

typedef struct layout {
    size_t window_desc, window_theta, window_index;
    size_t img_n, img_t, geom, geom_scratch, line_sum, edge_prefix, line_j;
    size_t geom_bytes;                /* one record's arrays */
    int geom_rows, geom_first;        /* raw theta rows cached (0: none) and the first's k */
    int geom_longest, geom_blocks;
    size_t geom_intercepts;
    ptrdiff_t img_n_stride, img_t_stride;
    size_t ctx, grad_x, grad_y, acc_x, acc_y, raw_rows, smooth_rows, row_tmp, heap, heap_entries, extrema, candidates, matches,
        inliers, slots, refine, total;
    int max_matches;
} layout;

static size_t take(size_t *cursor, size_t bytes)
{
    size_t at = (*cursor + BLOCK_ALIGN - 1) & ~(size_t)(BLOCK_ALIGN - 1);
    *cursor = at + bytes;
    return at;
}

/* Bytes of one theta geometry record's arrays, each on a 16-byte boundary. */
static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

static size_t geom_record_bytes(int longest, int blocks, size_t intercepts, size_t r_bins)
{
    return align16(((size_t)longest + 1) * sizeof(int16_t)) + 2 * align16((size_t)blocks * sizeof(int16_t)) +
           align16(((size_t)longest + 4) * sizeof(int32_t)) + 2 * align16(intercepts * sizeof(int16_t)) +
           align16(r_bins * sizeof(int16_t)) + align16(r_bins * sizeof(float));
}

/* Point a record's arrays into mem (geom_record_bytes of it). */
static void carve_geom(home__theta_geom *g, unsigned char *mem, int longest, int blocks,
                       size_t intercepts, size_t r_bins)
{
    g->shift = (int16_t *)(void *)mem; /* + 1: line_ends may read a word at the last row */
    mem += align16(((size_t)longest + 1) * sizeof(int16_t));
    g->row_lo = (int16_t *)(void *)mem;
    mem += align16((size_t)blocks * sizeof(int16_t));
    g->row_hi = (int16_t *)(void *)mem;
    mem += align16((size_t)blocks * sizeof(int16_t));
    g->first_row = (int32_t *)(void *)mem;
    mem += align16(((size_t)longest + 4) * sizeof(int32_t));
    g->entry = (int16_t *)(void *)mem;
    mem += align16(intercepts * sizeof(int16_t));
    g->after = (int16_t *)(void *)mem;
    mem += align16(intercepts * sizeof(int16_t));
    g->res_k = (int16_t *)(void *)mem;
    mem += align16(r_bins * sizeof(int16_t));
    g->res_f = (float *)(void *)mem;
}

static void plan(const home_config *cfg, layout *l)
{
    size_t cur = 0, pixels = (size_t)cfg->width * (size_t)cfg->height;
    size_t r_bins = (size_t)home__r_bins(cfg);
    size_t radius = (size_t)ceil(3.0 * cfg->smooth_sigma); /* as home__gauss_taps() */
    /* every query keypoint, in primary and (near the wrap) alternate form, yields <= 1 match */
    l->max_matches = 4 * cfg->keypoints_per_sign;
    int hough_w, hough_h;
    size_t w, h, longest;
    if (radius > HOME__MAX_SMOOTH_RADIUS) radius = HOME__MAX_SMOOTH_RADIUS;
    home__hough_size(cfg, &hough_w, &hough_h);
    w = (size_t)hough_w;
    h = (size_t)hough_h;
    longest = w > h ? w : h;
    /* intercepts of one theta row: the other side + both shear extents + derivative + a block */
    size_t intercepts = w + h + 8 + 2 * HOME__RADON_BLOCK;
    l->ctx = take(&cur, sizeof(home_context));
    l->img_n = l->img_t = l->geom = l->geom_scratch = l->line_sum = l->edge_prefix = l->line_j = 0;
    l->geom_bytes = 0;
    l->geom_rows = 0;
    l->grad_x = l->grad_y = 0;
    if (cfg->hough_method == HOME_HOUGH_EXACT) {
        l->grad_x = take(&cur, pixels * sizeof(int16_t));
        l->grad_y = take(&cur, pixels * sizeof(int16_t));
    } else {
        l->img_n_stride = (ptrdiff_t)(w + 2 * HOME__RADON_BLOCK);
        l->img_t_stride = (ptrdiff_t)(h + 2 * HOME__RADON_BLOCK);
        l->img_n = take(&cur, h * (size_t)l->img_n_stride);
        l->img_t = take(&cur, w * (size_t)l->img_t_stride);
        l->geom_longest = (int)longest;
        l->geom_blocks = (int)(intercepts / HOME__RADON_BLOCK + 1);
        l->geom_intercepts = w + h + 8; /* a row's intercepts, without the kernel's block slack */
        l->geom_bytes = geom_record_bytes(l->geom_longest, l->geom_blocks, l->geom_intercepts, r_bins);
        {
            int rows;
            home__hough_raw_rows(cfg, (int)radius, &l->geom_first, &rows);
            size_t bytes = align16((size_t)rows * sizeof(home__theta_geom)) + (size_t)rows * l->geom_bytes;
            if (bytes <= HOME_HOUGH_GEOMETRY_BYTES) {
                l->geom_rows = rows;
                l->geom = take(&cur, bytes);
            } else {
                l->geom_scratch = take(&cur, l->geom_bytes);
            }
        }
        l->line_sum = take(&cur, (intercepts + HOME__RADON_BLOCK) * sizeof(int32_t));
        l->edge_prefix = take(&cur, 4 * 2 * (longest + 1) * sizeof(int32_t));
        l->line_j = take(&cur, (intercepts + HOME__RADON_BLOCK) * sizeof(float));
    }
    l->acc_x = take(&cur, r_bins * sizeof(int32_t));
    l->acc_y = take(&cur, r_bins * sizeof(int32_t));
    l->raw_rows = take(&cur, (2 * radius + 1) * r_bins * sizeof(float));
    l->smooth_rows = take(&cur, HOME__DESC_ROWS * r_bins * sizeof(float));
    l->row_tmp = take(&cur, r_bins * sizeof(float));
    l->heap = take(&cur, 2 * (size_t)cfg->keypoints_per_sign * sizeof(home__candidate));
    l->heap_entries = take(&cur, 2 * (size_t)cfg->keypoints_per_sign * sizeof(home__heap_entry));
    l->extrema = take(&cur, r_bins * sizeof(home__extremum));
    l->candidates = take(&cur, r_bins * sizeof(int));
    l->matches = take(&cur, (size_t)l->max_matches * sizeof(home__match));
    l->inliers = take(&cur, (size_t)l->max_matches * sizeof(int));
    l->slots = take(&cur, 2 * sizeof(home_features));
    {   /* b's keypoints sorted by theta, for the motion prior */
        size_t kp = 2 * (size_t)cfg->keypoints_per_sign;
        l->window_desc = take(&cur, kp * HOME_DESC_LEN);
        l->window_theta = take(&cur, kp * sizeof(float));
        l->window_index = take(&cur, kp * sizeof(int));
    }
    l->refine = take(&cur, home__refine_bytes(cfg));
    l->total = (cur + BLOCK_ALIGN - 1) & ~(size_t)(BLOCK_ALIGN - 1);
}

size_t home_arena_size(const home_config *cfg)
{
    layout l;
    if (home_validate_config(cfg) != HOME_OK) return 0;
    plan(cfg, &l);
    return l.total;
}

int home_init(home_context **out, const home_config *cfg, void *arena, size_t arena_bytes,
              size_t *needed)
{
    layout l;
    home_context *ctx;
    unsigned char *base = (unsigned char *)arena;
    int status;
    if (needed) *needed = 0;
    if (!out || !cfg || !arena) return HOME_E_NULL;
    *out = NULL;
    status = home_validate_config(cfg);
    if (status != HOME_OK) return status;
    if ((uintptr_t)arena % HOME_ARENA_ALIGN) return HOME_E_ARENA_ALIGN;
    plan(cfg, &l);
    if (needed) *needed = l.total;
    if (arena_bytes < l.total) return HOME_E_ARENA_SMALL;

    ctx = (home_context *)(void *)(base + l.ctx);
    memset(ctx, 0, sizeof *ctx);
    ctx->cfg = *cfg;
    ctx->r_bins = home__r_bins(cfg);
    home__hough_size(cfg, &ctx->hough_w, &ctx->hough_h);
    ctx->hough_scale = cfg->hough_downscale;
    /* the Hough image covers full-image columns [0, scale * hough_w): its centre sits at
     * (scale * hough_w - 1) / 2, i.e. this far from the full image's centre */
    ctx->hough_dx = 0.5 * (ctx->hough_scale * ctx->hough_w - cfg->width);
    ctx->hough_dy = 0.5 * (ctx->hough_scale * ctx->hough_h - cfg->height);
    ctx->cfg.r_bins = ctx->r_bins;
    ctx->config_id = home__config_id(&ctx->cfg);
    ctx->smooth_radius = home__gauss_taps(cfg->smooth_sigma, ctx->smooth_taps);
    ctx->kernels = home__kernels_for(cfg->simd);
    if (cfg->hough_method == HOME_HOUGH_EXACT) {
        ctx->grad_x = (int16_t *)(void *)(base + l.grad_x);
        ctx->grad_y = (int16_t *)(void *)(base + l.grad_y);
    } else {
        ctx->img_n = base + l.img_n;
        ctx->img_t = base + l.img_t;
        ctx->img_n_stride = l.img_n_stride;
        ctx->img_t_stride = l.img_t_stride;
        if (l.geom_rows) {
            /* records first, then their arrays; every row's geometry computed once, here */
            unsigned char *arrays = base + l.geom + align16((size_t)l.geom_rows * sizeof(home__theta_geom));
            int k;
            ctx->geom = (home__theta_geom *)(void *)(base + l.geom);
            for (k = 0; k < l.geom_rows; k++) {
                carve_geom(&ctx->geom[k], arrays + (size_t)k * l.geom_bytes, l.geom_longest,
                           l.geom_blocks, l.geom_intercepts, (size_t)ctx->r_bins);
                home__theta_geometry(ctx, (l.geom_first + k) * HOME__PI / cfg->theta_bins, &ctx->geom[k]);
            }
        } else {
            ctx->geom = NULL;
            carve_geom(&ctx->geom_scratch, base + l.geom_scratch, l.geom_longest, l.geom_blocks,
                       l.geom_intercepts, (size_t)ctx->r_bins);
        }
        ctx->line_sum = (int32_t *)(void *)(base + l.line_sum);
        ctx->edge_prefix = (int32_t *)(void *)(base + l.edge_prefix);
        ctx->line_j = (float *)(void *)(base + l.line_j);
    }
    ctx->acc_x = (int32_t *)(void *)(base + l.acc_x);
    ctx->acc_y = (int32_t *)(void *)(base + l.acc_y);
    ctx->raw_rows = (float *)(void *)(base + l.raw_rows);
    ctx->smooth_rows = (float *)(void *)(base + l.smooth_rows);
    ctx->row_tmp = (float *)(void *)(base + l.row_tmp);
    ctx->heap_items = (home__candidate *)(void *)(base + l.heap);
    ctx->heap_entries = (home__heap_entry *)(void *)(base + l.heap_entries);
    ctx->row_extrema = (home__extremum *)(void *)(base + l.extrema);
    ctx->row_candidates = (int *)(void *)(base + l.candidates);
    ctx->matches = (home__match *)(void *)(base + l.matches);
    ctx->max_matches = l.max_matches;
    ctx->inlier_index = (int *)(void *)(base + l.inliers);
    ctx->slots = (home_features *)(void *)(base + l.slots);
    ctx->window_desc = base + l.window_desc;
    ctx->window_theta = (float *)(void *)(base + l.window_theta);
    ctx->window_index = (int *)(void *)(base + l.window_index);
    ctx->slots[0].magic = ctx->slots[1].magic = 0;
    ctx->slots_valid = 0;
    home__refine_init(ctx, base + l.refine);
    ctx->magic = HOME__MAGIC_CTX;
    *out = ctx;
    return HOME_OK;
}

int home__check_image(const home_context *ctx, const uint8_t *image, ptrdiff_t stride)
{
    if (!image) return HOME_E_NULL;
    if (stride < (ptrdiff_t)ctx->cfg.width) return HOME_E_STRIDE;
    /* the last row's address, image + (height - 1) * stride, must not overflow */
    if (stride > (PTRDIFF_MAX - ctx->cfg.width) / (ctx->cfg.height - 1)) return HOME_E_STRIDE;
    return HOME_OK;
}

const char *home_simd_backend(const home_context *ctx)
{
    const home__kernels *k;
    if (ctx && ctx->magic == HOME__MAGIC_CTX) return ctx->kernels->name;
    k = home__kernels_for(HOME_SIMD_AUTO);
    return k->name;
}

double home__now(const home_context *ctx)
{
    return ctx->cfg.clock ? ctx->cfg.clock(ctx->cfg.clock_user) : 0.0;
}
