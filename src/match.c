/* Brute-force L1 matching of 1x16 descriptors with Lowe's ratio test. A keypoint is only
 * compared with keypoints of the same sign of J; near the theta wrap it is also queried in its
 * alternate form (theta +- pi, -r, opposite sign), since a near-vertical line can cross the
 * wrap between two frames (home-notes.md, finding 4). */
#include "home_internal.h"
#include <math.h>
#include <string.h>

void home__match_set(home__match *m, float theta_a, float r_a, float theta_b, float r_b)
{
    m->theta_a = theta_a; m->r_a = r_a; m->theta_b = theta_b; m->r_b = r_b;
    m->cos_a = cos((double)theta_a); m->sin_a = sin((double)theta_a);
    m->cos_b = cos((double)theta_b); m->sin_b = sin((double)theta_b);
}

/* A match of two keypoints as they are: their normals come with them (no cos/sin per match;
 * in video, a frame's keypoints are matched twice) */
static void match_keypoints(home__match *m, const home_keypoint *a, const home_keypoint *b)
{
    m->theta_a = a->theta; m->r_a = a->r; m->theta_b = b->theta; m->r_b = b->r;
    m->cos_a = a->cos_theta; m->sin_a = a->sin_theta;
    m->cos_b = b->cos_theta; m->sin_b = b->sin_theta;
}

/* Best candidate in b's keypoints [lo, hi) passing the ratio test, or -1. */
static int best_match(const home__kernels *kernels, const uint8_t *desc, const home_features *b,
                      int lo, int hi, float ratio)
{
    int best, d1, d2;
    if (hi - lo < 2) return -1;
    kernels->nearest2_l1(desc, b->kp[lo].desc, (ptrdiff_t)sizeof(home_keypoint), hi - lo, &best,
                         &d1, &d2);
    return (float)d1 < ratio * (float)d2 ? lo + best : -1;
}

/* theta order with the keypoint index as tie break: a strict total order */
static int theta_before(const float *theta, const int *idx, int i, int j)
{
    if (theta[i] != theta[j]) return theta[i] < theta[j];
    return idx[i] < idx[j];
}

/* the key at i down to its place in a max-heap of n, bottom-up: the hole follows the later child
 * to a leaf, then the key rises back up that path (one comparison a level on the way down; the
 * same heap as swapping it down, the order being strict) */
static void sift_down(float *theta, int *idx, int n, int i)
{
    const float key_theta = theta[i];
    const int key_idx = idx[i];
    int hole = i, child;
    while ((child = 2 * hole + 1) < n) {
        if (child + 1 < n && theta_before(theta, idx, child, child + 1)) child++;
        theta[hole] = theta[child];
        idx[hole] = idx[child];
        hole = child;
    }
    while (hole > i) {
        const int parent = (hole - 1) / 2;
        if (theta[parent] != key_theta ? !(theta[parent] < key_theta) : !(idx[parent] < key_idx))
            break;
        theta[hole] = theta[parent];
        idx[hole] = idx[parent];
        hole = parent;
    }
    theta[hole] = key_theta;
    idx[hole] = key_idx;
}

/* b's keypoints [lo, hi) in theta order (heap sort, no recursion, on the keys themselves: no
 * keypoint is read while sorting): their descriptors packed contiguously, so a theta window is
 * one run for the nearest-neighbour kernel. */
static void sort_by_theta(home_context *ctx, const home_features *b, int lo, int hi)
{
    int *idx = ctx->window_index + lo, n = hi - lo, i, t;
    float *theta = ctx->window_theta + lo, f;
    for (i = 0; i < n; i++) {
        idx[i] = lo + i;
        theta[i] = b->kp[lo + i].theta;
    }
    for (i = n / 2 - 1; i >= 0; i--) sift_down(theta, idx, n, i);
    for (i = n - 1; i > 0; i--) {
        t = idx[0]; idx[0] = idx[i]; idx[i] = t;
        f = theta[0]; theta[0] = theta[i]; theta[i] = f;
        sift_down(theta, idx, i, 0);
    }
    for (i = 0; i < n; i++)
        memcpy(ctx->window_desc + (size_t)(lo + i) * HOME_DESC_LEN, b->kp[idx[i]].desc,
               HOME_DESC_LEN);
}

/* first position in [lo, hi) whose theta is >= value */
static int lower_bound(const float *theta, int lo, int hi, float value)
{
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (theta[mid] < value) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* Best candidate among b's keypoints [lo, hi) within +- window of theta, or -1. */
static int best_match_window(const home_context *ctx, const uint8_t *desc, float theta, int lo,
                             int hi, float window, float ratio)
{
    int p0 = lower_bound(ctx->window_theta, lo, hi, theta - window);
    int p1 = lower_bound(ctx->window_theta, p0, hi, theta + window + 1e-6f);
    int best, d1, d2;
    if (p1 - p0 < 2) return -1;
    ctx->kernels->nearest2_l1(desc, ctx->window_desc + (size_t)p0 * HOME_DESC_LEN, HOME_DESC_LEN,
                              p1 - p0, &best, &d1, &d2);
    return (float)d1 < ratio * (float)d2 ? ctx->window_index[p0 + best] : -1;
}

int home__match_features(home_context *ctx, const home_features *a, const home_features *b)
{
    const float ratio = ctx->cfg.ratio;
    const float window = (float)(ctx->cfg.match_theta_window * HOME__PI / ctx->cfg.theta_bins);
    int i, n = 0;
    if (window > 0.0f) {
        sort_by_theta(ctx, b, 0, b->n_pos);
        sort_by_theta(ctx, b, b->n_pos, b->n_pos + b->n_neg);
    }
    for (i = 0; i < a->n_pos + a->n_neg; i++) {
        const home_keypoint *q = &a->kp[i];
        int same_lo = q->sign > 0 ? 0 : b->n_pos,
            same_hi = q->sign > 0 ? b->n_pos : b->n_pos + b->n_neg;
        int opp_lo = q->sign > 0 ? b->n_pos : 0,
            opp_hi = q->sign > 0 ? b->n_pos + b->n_neg : b->n_pos;
        float alt_theta = q->theta < (float)(HOME__PI / 2) ? q->theta + (float)HOME__PI
                                                            : q->theta - (float)HOME__PI;
        int j = window > 0.0f
                    ? best_match_window(ctx, q->desc, q->theta, same_lo, same_hi, window, ratio)
                    : best_match(ctx->kernels, q->desc, b, same_lo, same_hi, ratio);
        if (j >= 0 && n < ctx->max_matches)
            match_keypoints(&ctx->matches[n++], q, &b->kp[j]);
        if (!q->has_alt) continue;
        j = window > 0.0f
                ? best_match_window(ctx, q->alt_desc, alt_theta, opp_lo, opp_hi, window, ratio)
                : best_match(ctx->kernels, q->alt_desc, b, opp_lo, opp_hi, ratio);
        if (j >= 0 && n < ctx->max_matches)
            home__match_set(&ctx->matches[n++], alt_theta, -q->r, b->kp[j].theta, b->kp[j].r);
    }
    return n;
}
