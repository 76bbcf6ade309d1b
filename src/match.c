/* Brute-force L1 matching of 1x16 descriptors with Lowe's ratio test. A keypoint is only
 * compared with keypoints of the same sign of J; near the theta wrap it is also queried in its
 * alternate form (theta +- pi, -r, opposite sign), since a near-vertical line can cross the
 * wrap between two frames (home-notes.md, finding 4). */
#include "home_internal.h"
#include <math.h>

void home__match_set(home__match *m, float theta_a, float r_a, float theta_b, float r_b)
{
    m->theta_a = theta_a; m->r_a = r_a; m->theta_b = theta_b; m->r_b = r_b;
    m->cos_a = cos((double)theta_a); m->sin_a = sin((double)theta_a);
    m->cos_b = cos((double)theta_b); m->sin_b = sin((double)theta_b);
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

int home__match_features(home_context *ctx, const home_features *a, const home_features *b)
{
    const float ratio = ctx->cfg.ratio;
    int i, n = 0;
    for (i = 0; i < a->n_pos + a->n_neg; i++) {
        const home_keypoint *q = &a->kp[i];
        int same_lo = q->sign > 0 ? 0 : b->n_pos, same_hi = q->sign > 0 ? b->n_pos : b->n_pos + b->n_neg;
        int opp_lo = q->sign > 0 ? b->n_pos : 0, opp_hi = q->sign > 0 ? b->n_pos + b->n_neg : b->n_pos;
        int j = best_match(ctx->kernels, q->desc, b, same_lo, same_hi, ratio);
        if (j >= 0 && n < ctx->max_matches)
            home__match_set(&ctx->matches[n++], q->theta, q->r, b->kp[j].theta, b->kp[j].r);
        if (!q->has_alt) continue;
        j = best_match(ctx->kernels, q->alt_desc, b, opp_lo, opp_hi, ratio);
        if (j >= 0 && n < ctx->max_matches)
            home__match_set(&ctx->matches[n++],
                            q->theta < (float)(HOME__PI / 2) ? q->theta + (float)HOME__PI
                                                             : q->theta - (float)HOME__PI,
                            -q->r, b->kp[j].theta, b->kp[j].r);
    }
    return n;
}
