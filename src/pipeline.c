/* The public pipeline: feature extraction (Hough -> extrema -> descriptors), matching and
 * homography estimation, and the rendered Hough image for inspection. */
#include "home_internal.h"
#include <math.h>
#include <string.h>

#define FAST_PASS_SIGMA_PX 0.2 /* home_register()'s fast pass answers alone this precisely, else
                                  the configured pass decides: tuning set, its wrong answers
                                  where that pass refused (few edges, fog) predicted 0.24-0.59
                                  px, 95 % of its right ones less (docs/speed.md) */

typedef struct extract_state {
    home_context *ctx;
    home__heap pos, neg;
    uint32_t order;
    double sum, sum_sq;        /* statistics of J over [0, pi) for the quantisation scale */
    double ms_detect, ms_describe;
    int detect;                /* find and describe keypoints */
    uint8_t *out;              /* render mode: quantised rows go here */
    ptrdiff_t out_stride;
    float out_scale;
} extract_state;

static int check_ctx(const home_context *ctx)
{
    if (!ctx) return HOME_E_NULL;
    return ctx->magic == HOME__MAGIC_CTX ? HOME_OK : HOME_E_STATE;
}

/* Four partial sums (element i in lane i % 4), added (0 + 1) + (2 + 3) at the end: a fixed order
 * on every target, and four independent chains instead of one (a single running sum waits on
 * each addition; docs/simd.md). */
static void accumulate_stats(extract_state *st, const float *row, int n)
{
    double s[4] = {0.0, 0.0, 0.0, 0.0}, s2[4] = {0.0, 0.0, 0.0, 0.0};
    int i, l;
    for (i = 0; i + 4 <= n; i += 4)
        for (l = 0; l < 4; l++) {
            s[l] += row[i + l];
            s2[l] += (double)row[i + l] * row[i + l];
        }
    for (l = 0; i < n; i++, l++) {
        s[l] += row[i];
        s2[l] += (double)row[i] * row[i];
    }
    st->sum += (s[0] + s[1]) + (s[2] + s[3]);
    st->sum_sq += (s2[0] + s2[1]) + (s2[2] + s2[3]);
}

static void quantise_row(const float *row, int n, float scale, uint8_t *out)
{
    int i;
    for (i = 0; i < n; i++) {
        float q = floorf(128.0f + row[i] * scale + 0.5f);
        out[i] = (uint8_t)(q < 0.0f ? 0.0f : q > 255.0f ? 255.0f : q);
    }
}

static void on_row(void *user, int j, const float *const *window)
{
    extract_state *st = (extract_state *)user;
    home_context *ctx = st->ctx;
    const int n_theta = ctx->cfg.theta_bins, r_bins = ctx->r_bins;
    int centre = j - 2, n, k;
    double t0, t1;

    if (j >= 0 && j < n_theta) {
        if (st->out)
            quantise_row(window[4], r_bins, st->out_scale, st->out + (ptrdiff_t)j * st->out_stride);
        else
            accumulate_stats(st, window[4], r_bins);
    }
    if (!st->detect || !window[0] || centre < -1 || centre > n_theta) return;

    t0 = home__now(ctx);
    n = home__detect_row(ctx->kernels, window + 1, centre, r_bins, n_theta, ctx->row_candidates,
                         ctx->row_extrema);
    t1 = home__now(ctx);
    for (k = 0; k < n; k++) {
        const home__extremum *x = &ctx->row_extrema[k];
        home__heap *heap = x->sign > 0 ? &st->pos : &st->neg;
        home__candidate cand;
        uint32_t order = st->order++;
        if (!home__heap_would_accept(heap, x->saliency, order)) continue;
        cand.theta_bin = x->theta_bin;
        cand.r_bin = x->r_bin;
        cand.saliency = x->saliency;
        cand.order = order;
        home__describe_samples(window, centre, r_bins, x->theta_bin, x->r_bin, cand.samples);
        home__heap_push(heap, &cand);
    }
    st->ms_detect += t1 - t0;
    st->ms_describe += home__now(ctx) - t1;
}

static void fill_keypoints(const home_context *ctx, home__heap *heap, int sign, float scale,
                           home_keypoint *out)
{
    const int n_theta = ctx->cfg.theta_bins, band = ctx->cfg.wrap_band;
    const float centre_bin = 0.5f * (float)(ctx->r_bins - 1);
    int i, n = home__heap_sort_desc(heap);
    for (i = 0; i < n; i++) {
        const home__candidate *c = &heap->pool[heap->entries[i].slot];
        home_keypoint *kp = &out[i];
        kp->theta = (float)(c->theta_bin * (HOME__PI / n_theta));
        /* [0, pi) */
        if (kp->theta >= (float)HOME__PI) kp->theta = nextafterf((float)HOME__PI, 0.0f);
        /* r in full-image px: scale up from the (possibly downscaled) Hough image and move to
         * the full image's centre */
        kp->cos_theta = cos((double)kp->theta);
        kp->sin_theta = sin((double)kp->theta);
        kp->r = (float)(ctx->hough_scale * (c->r_bin - centre_bin) * ctx->cfg.r_step +
                        kp->cos_theta * ctx->hough_dx + kp->sin_theta * ctx->hough_dy);
        kp->saliency = c->saliency;
        kp->sign = (int8_t)sign;
        kp->has_alt = (uint8_t)(c->theta_bin < (float)band ||
                                c->theta_bin > (float)(n_theta - band));
        home__quantise_descriptor(c->samples, scale, 0, kp->desc);
        if (kp->has_alt)
            home__quantise_descriptor(c->samples, scale, 1, kp->alt_desc);
        else
            memset(kp->alt_desc, 0, sizeof kp->alt_desc);
    }
}

/* When the Hough image is a box-downscaled copy and the refinement's snapshot starts from the
 * 2x2-mean frame, both are made in one pass over the frame: each band of hough_downscale rows
 * comes from memory once, for the box and (still in cache) the 2x2 means; the same bytes as two
 * passes. Returns 1 when done (both consumers then skip their own pass). */
static int read_frame_once(home_context *ctx, const uint8_t *image, ptrdiff_t stride)
{
    const int ds = ctx->hough_scale;
    int y, half_rows;
    if (ds < 2 || ctx->cfg.hough_method != HOME_HOUGH_FAST ||
        !home__refine_half_frame(ctx, &half_rows))
        return 0;
    for (y = 0; y < ctx->hough_h; y++) {
        home__hough_load_rows(ctx, image, stride, y, y + 1);
        home__refine_half_rows(ctx, image, stride, y * ds / 2, (y + 1) * ds / 2);
    }
    home__refine_half_rows(ctx, image, stride, ctx->hough_h * ds / 2, half_rows);
    return 1;
}

/* The features of a checked image; with snapshot (1, or 2: its template points deferred), also
 * the refinement's snapshot of it (else frame_id and ms_refine are the caller's) */
static void extract(home_context *ctx, const uint8_t *image, ptrdiff_t stride, home_features *out,
                    int snapshot)
{
    extract_state st;
    double n_values, mean, var, t_end, t_read;
    float scale;
    int read_once;

    memset(&st, 0, sizeof st);
    st.ctx = ctx;
    st.detect = 1;
    home__heap_init(&st.pos, ctx->heap_entries, ctx->heap_items, ctx->cfg.keypoints_per_sign);
    home__heap_init(&st.neg, ctx->heap_entries + ctx->cfg.keypoints_per_sign,
                    ctx->heap_items + ctx->cfg.keypoints_per_sign, ctx->cfg.keypoints_per_sign);
    t_read = home__now(ctx);
    if (snapshot) home__refine_settle(ctx, -1); /* the last snapshot's pyramid is still there */
    read_once = read_frame_once(ctx, image, stride);
    t_read = home__now(ctx) - t_read; /* counted as the Hough stage's */
    out->ms_hough = t_read + home__hough_stream(ctx, read_once ? NULL : image, stride, on_row, &st);

    n_values = (double)ctx->cfg.theta_bins * ctx->r_bins;
    mean = st.sum / n_values;
    var = st.sum_sq / n_values - mean * mean;
    out->j_std = var > 0.0 ? (float)sqrt(var) : 0.0f;
    scale = out->j_std > 0.0f ? 127.0f / (6.0f * out->j_std) : 0.0f;

    t_end = home__now(ctx);
    out->n_pos = st.pos.count;
    out->n_neg = st.neg.count;
    fill_keypoints(ctx, &st.pos, 1, scale, out->kp);
    fill_keypoints(ctx, &st.neg, -1, scale, out->kp + out->n_pos);
    out->ms_detect = st.ms_detect;
    out->ms_describe = st.ms_describe + (home__now(ctx) - t_end);
    if (snapshot) {
        t_end = home__now(ctx);
        out->frame_id = home__refine_store(ctx, read_once ? NULL : image, stride, snapshot == 2);
        out->ms_refine = home__now(ctx) - t_end;
    }
    out->width = ctx->cfg.width;
    out->height = ctx->cfg.height;
    out->config_id = ctx->config_id;
    out->magic = HOME__MAGIC_FEAT;
}

int home_extract(home_context *ctx, const uint8_t *image, ptrdiff_t stride, home_features *out)
{
    int status = check_ctx(ctx);
    if (status != HOME_OK) return status;
    if (!out) return HOME_E_NULL;
    status = home__check_image(ctx, image, stride);
    if (status != HOME_OK) return status;
    extract(ctx, image, stride, out, 1);
    return HOME_OK;
}

static int check_features(const home_context *ctx, const home_features *f)
{
    if (!f) return HOME_E_NULL;
    if (f->magic != HOME__MAGIC_FEAT || f->n_pos < 0 || f->n_neg < 0 ||
        f->n_pos > HOME_MAX_KEYPOINTS_PER_SIGN || f->n_neg > HOME_MAX_KEYPOINTS_PER_SIGN)
        return HOME_E_STATE;
    if (f->config_id != ctx->config_id || f->width != ctx->cfg.width ||
        f->height != ctx->cfg.height || f->n_pos > ctx->cfg.keypoints_per_sign ||
        f->n_neg > ctx->cfg.keypoints_per_sign)
        return HOME_E_MISMATCH;
    return HOME_OK;
}

static void reset_result(home_result *r)
{
    memset(r, 0, sizeof *r);
    r->H[0] = r->H[4] = r->H[8] = 1.0;
    r->model = HOME_MODEL_HOMOGRAPHY;
    r->sigma_px = INFINITY;
}

/* matching + homography; the extraction timings are added by the callers */
static int match_and_estimate(home_context *ctx, const home_features *a, const home_features *b,
                              home_result *result)
{
    double t0, t1, t2;
    int n;
    result->keypoints_a = a->n_pos + a->n_neg;
    result->keypoints_b = b->n_pos + b->n_neg;
    t0 = home__now(ctx);
    n = home__match_features(ctx, a, b);
    t1 = home__now(ctx);
    result->matches = n;
    home__estimate_homography(ctx, n, result);
    t2 = home__now(ctx);
    result->ms[HOME_STAGE_MATCH] = t1 - t0;
    result->ms[HOME_STAGE_HOMOGRAPHY] = t2 - t1;
    return HOME_OK;
}

static void add_extract_ms(home_result *r, const home_features *f)
{
    r->ms[HOME_STAGE_HOUGH] += f->ms_hough;
    r->ms[HOME_STAGE_DETECT] += f->ms_detect;
    r->ms[HOME_STAGE_DESCRIBE] += f->ms_describe;
    r->ms[HOME_STAGE_REFINE] += f->ms_refine;
}

static void sum_total(home_result *r)
{
    int s;
    r->ms[HOME_STAGE_TOTAL] = 0.0;
    for (s = 0; s < HOME_STAGE_TOTAL; s++) r->ms[HOME_STAGE_TOTAL] += r->ms[s];
}

int home_match(home_context *ctx, const home_features *a, const home_features *b,
               home_result *result)
{
    int status = check_ctx(ctx);
    if (status != HOME_OK) return status;
    if (!result) return HOME_E_NULL;
    reset_result(result);
    if ((status = check_features(ctx, a)) != HOME_OK) return status;
    if ((status = check_features(ctx, b)) != HOME_OK) return status;
    match_and_estimate(ctx, a, b, result);
    home__refine_apply(ctx, a->frame_id, b->frame_id, result);
    add_extract_ms(result, b); /* the video case: only the new frame was extracted */
    sum_total(result);
    return HOME_OK;
}

/* One pass of home_register() with the live Hough set-up (the images are checked). snapshot 0:
 * the previous pass stored both frames' refinement snapshots, which stay (same frames, same
 * ids). */
static void register_pass(home_context *ctx, const uint8_t *a, ptrdiff_t stride_a,
                          const uint8_t *b, ptrdiff_t stride_b, home_result *result, int snapshot)
{
    const uint32_t id_a = ctx->slots[0].frame_id, id_b = ctx->slots[1].frame_id;
    reset_result(result);
    ctx->slots_valid = 0;
    extract(ctx, a, stride_a, &ctx->slots[0], snapshot);
    extract(ctx, b, stride_b, &ctx->slots[1], snapshot ? 2 : 0); /* b's points: when needed */
    if (!snapshot) {
        ctx->slots[0].frame_id = id_a;
        ctx->slots[1].frame_id = id_b;
        ctx->slots[0].ms_refine = ctx->slots[1].ms_refine = 0.0;
    }
    ctx->slots_valid = 1;
    match_and_estimate(ctx, &ctx->slots[0], &ctx->slots[1], result);
    home__refine_apply(ctx, ctx->slots[0].frame_id, ctx->slots[1].frame_id, result);
    add_extract_ms(result, &ctx->slots[0]);
    add_extract_ms(result, &ctx->slots[1]);
    sum_total(result);
}

int home_register(home_context *ctx, const uint8_t *a, ptrdiff_t stride_a, const uint8_t *b,
                  ptrdiff_t stride_b, home_result *result)
{
    double fast_ms[HOME_STAGE_COUNT];
    int s, status = check_ctx(ctx);
    if (status != HOME_OK) return status;
    if (!result) return HOME_E_NULL;
    reset_result(result);
    if ((status = home__check_image(ctx, a, stride_a)) != HOME_OK) return status;
    if ((status = home__check_image(ctx, b, stride_b)) != HOME_OK) return status;
    memset(fast_ms, 0, sizeof fast_ms);
    /* both snapshot slots are replaced: a deferred one is not worth selecting first */
    home__refine_drop_pending(ctx);
    if (ctx->n_passes > 1) {
        /* the fast pass: its answer stands when ok and precise; else it only costs its time */
        home__select_pass(ctx, 1);
        register_pass(ctx, a, stride_a, b, stride_b, result, 1);
        home__select_pass(ctx, 0);
        if (result->ok && result->sigma_px <= FAST_PASS_SIGMA_PX) {
            result->fast_pass = 1;
            return HOME_OK;
        }
        memcpy(fast_ms, result->ms, sizeof fast_ms);
    }
    register_pass(ctx, a, stride_a, b, stride_b, result, ctx->n_passes == 1);
    for (s = 0; s < HOME_STAGE_COUNT; s++) result->ms[s] += fast_ms[s];
    return HOME_OK;
}

const home_features *home_last_features(const home_context *ctx, int which)
{
    if (check_ctx(ctx) != HOME_OK || !ctx->slots_valid || which < 0 || which > 1) return NULL;
    return &ctx->slots[which];
}

int home_hough_size(const home_context *ctx, int *width, int *height)
{
    int status = check_ctx(ctx);
    if (status != HOME_OK) return status;
    if (!width || !height) return HOME_E_NULL;
    *width = ctx->r_bins;
    *height = ctx->cfg.theta_bins;
    return HOME_OK;
}

int home_render_hough(home_context *ctx, const uint8_t *image, ptrdiff_t stride, uint8_t *out,
                      ptrdiff_t out_stride)
{
    extract_state st;
    double n_values, mean, var;
    int status = check_ctx(ctx);
    if (status != HOME_OK) return status;
    if (!out) return HOME_E_NULL;
    if ((status = home__check_image(ctx, image, stride)) != HOME_OK) return status;
    if (out_stride < (ptrdiff_t)ctx->r_bins) return HOME_E_STRIDE;
    /* pass 1: statistics of J; pass 2: quantised rows (the context keeps only a few rows) */
    memset(&st, 0, sizeof st);
    st.ctx = ctx;
    home__hough_stream(ctx, image, stride, on_row, &st);
    n_values = (double)ctx->cfg.theta_bins * ctx->r_bins;
    mean = st.sum / n_values;
    var = st.sum_sq / n_values - mean * mean;
    st.out = out;
    st.out_stride = out_stride;
    st.out_scale = var > 0.0 ? (float)(127.0 / (6.0 * sqrt(var))) : 0.0f;
    home__hough_stream(ctx, image, stride, on_row, &st);
    return HOME_OK;
}

int home_keypoint_to_hough(const home_context *ctx, const home_keypoint *kp, float *col,
                           float *row)
{
    int status = check_ctx(ctx);
    if (status != HOME_OK) return status;
    if (!kp || !col || !row) return HOME_E_NULL;
    *row = (float)(kp->theta * ctx->cfg.theta_bins / HOME__PI);
    *col = (float)((kp->r - cos((double)kp->theta) * ctx->hough_dx -
                    sin((double)kp->theta) * ctx->hough_dy) / (ctx->hough_scale * ctx->cfg.r_step) +
                   0.5 * (ctx->r_bins - 1));
    return HOME_OK;
}
