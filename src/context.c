/* The context: its arena layout (each stage's block sized and laid out by the stage itself where
 * it owns one: home__hough_bytes/_init, home__refine_bytes/_init) and its initialisation. */
#include "home_internal.h"
#include <string.h>

/* Offsets into the arena, each block on a HOME__BLOCK_ALIGN boundary. */
typedef struct layout {
    size_t ctx, hough, heap, heap_entries, extrema, candidates, matches, inliers, slots;
    size_t window_desc, window_theta, window_index, refine, total;
    int max_matches;
} layout;

static void plan(const home_config *cfg, layout *l)
{
    size_t cur = 0, r_bins = (size_t)home__r_bins(cfg);
    /* every query keypoint, in primary and (near the wrap) alternate form, yields <= 1 match */
    l->max_matches = 4 * cfg->keypoints_per_sign;
    l->ctx = home__take(&cur, sizeof(home_context));
    l->hough = home__take(&cur, home__hough_bytes(cfg));
    l->heap = home__take(&cur, 2 * (size_t)cfg->keypoints_per_sign * sizeof(home__candidate));
    l->heap_entries = home__take(&cur,
                                 2 * (size_t)cfg->keypoints_per_sign * sizeof(home__heap_entry));
    l->extrema = home__take(&cur, r_bins * sizeof(home__extremum));
    l->candidates = home__take(&cur, r_bins * sizeof(int));
    l->matches = home__take(&cur, (size_t)l->max_matches * sizeof(home__match));
    l->inliers = home__take(&cur, (size_t)l->max_matches * sizeof(int));
    l->slots = home__take(&cur, 2 * sizeof(home_features));
    {   /* b's keypoints sorted by theta, for the motion prior */
        size_t kp = 2 * (size_t)cfg->keypoints_per_sign;
        l->window_desc = home__take(&cur, kp * HOME_DESC_LEN);
        l->window_theta = home__take(&cur, kp * sizeof(float));
        l->window_index = home__take(&cur, kp * sizeof(int));
    }
    l->refine = home__take(&cur, home__refine_bytes(cfg));
    l->total = home__align_up(cur, HOME__BLOCK_ALIGN);
}

/* A pass's sizes from its configuration (its strides and geometry come with the Hough block) */
static void pass_from(const home_config *cfg, home__pass *p)
{
    memset(p, 0, sizeof *p);
    p->cfg = *cfg;
    p->r_bins = home__r_bins(cfg);
    home__hough_size(cfg, &p->hough_w, &p->hough_h);
    p->hough_scale = cfg->hough_downscale;
    /* the Hough image covers full-image columns [0, scale * hough_w): its centre sits at
     * (scale * hough_w - 1) / 2, i.e. this far from the full image's centre */
    p->hough_dx = 0.5 * (p->hough_scale * p->hough_w - cfg->width);
    p->hough_dy = 0.5 * (p->hough_scale * p->hough_h - cfg->height);
    p->cfg.r_bins = p->r_bins;
    p->config_id = home__config_id(&p->cfg);
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
    pass_from(cfg, &ctx->passes[0]);
    ctx->n_passes = 1;
    {
        home_config fast;
        if (home__fast_pass_config(cfg, &fast)) {
            pass_from(&fast, &ctx->passes[1]);
            ctx->n_passes = 2;
        }
    }
    home__select_pass(ctx, 0);
    ctx->kernels = home__kernels_for(cfg->simd);
    home__hough_init(ctx, base + l.hough);
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

const char *home_simd_backend(const home_context *ctx)
{
    const home__kernels *k;
    if (ctx && ctx->magic == HOME__MAGIC_CTX) return ctx->kernels->name;
    k = home__kernels_for(HOME_SIMD_AUTO);
    return k ? k->name : "unavailable"; /* HOME_SIMD names a backend not here */
}
