/* End-to-end registration, video reuse, determinism, clean failures and bad inputs. */
#include "test.h"
#include "test_util.h"
#include "synth.h"
#include <math.h>
#include <string.h>

#define IMG_W 640
#define IMG_H 360
static uint8_t img_a[IMG_W * IMG_H], img_b[IMG_W * IMG_H];
static home_features fa, fb;
static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

/* A pair of `kind` scene `seed` with a random corner motion of up to p px: img_a, img_b and
 * the true homography h (A -> B); noise sigma 2.5, its own seed per image. */
static void render_pair(enum synth_kind kind, uint64_t seed, double p, double *h)
{
    synth_rng rng;
    synth_seed(&rng, seed);
    synth_corner_homography(&rng, IMG_W, IMG_H, p, h);
    synth_render(kind, (uint32_t)seed, identity, 2.5, 2 * seed + 1, img_a, IMG_W, IMG_H, IMG_W);
    synth_render(kind, (uint32_t)seed, h, 2.5, 2 * seed + 2, img_b, IMG_W, IMG_H, IMG_W);
}

/* Register n_pairs pairs of `kind` per p and check the mean corner error and no failures. */
static void end_to_end(enum synth_kind kind, uint64_t seed0)
{
    static const double ps[] = {10, 20, 30};
    home_context *ctx = test_context(IMG_W, IMG_H, NULL);
    size_t pi;
    if (!ctx) { CHECK(0); return; }
    for (pi = 0; pi < sizeof ps / sizeof ps[0]; pi++) {
        double sum = 0, worst = 0;
        int k, n = 4, failures = 0;
        for (k = 0; k < n; k++) {
            uint64_t seed = seed0 + 100 * pi + (uint64_t)k;
            double h[9], err;
            home_result res;
            render_pair(kind, seed, ps[pi], h);
            CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
            err = synth_corner_error(res.H, h, IMG_W, IMG_H);
            if (!res.ok) failures++;
            sum += err;
            if (err > worst) worst = err;
            if (err > 1.0 || !res.ok)
                fprintf(stderr, "    p=%g seed=%llu: ok=%d err=%.3f inliers=%d matches=%d\n", ps[pi],
                        (unsigned long long)seed, res.ok, err, res.inliers, res.matches);
        }
        printf("     %s p=%2.0f: mean corner error %.3f px, worst %.3f px, %d/%d failed\n",
               kind == SYNTH_STRUCTURED ? "structured" : "weak texture", ps[pi], sum / n, worst,
               failures, n);
        CHECK_EQ_INT(failures, 0);
        CHECK_LT(sum / n, 1.0);
    }
}

void test_end_to_end_structured(void) { end_to_end(SYNTH_STRUCTURED, 1000); }

/* hough_downscale = 2 or 4 (video presets for small cores) still registers: coarser without
 * the photometric refinement, full precision with it */
static void downscaled_hough(int downscale, int refine_levels, double bound)
{
    home_config cfg;
    home_context *ctx;
    double sum = 0;
    int k, failures = 0;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.hough_downscale = downscale;
    cfg.refine_levels = refine_levels;
    ctx = test_context(IMG_W, IMG_H, &cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 4; k++) {
        uint64_t seed = 3000 + (uint64_t)k;
        double h[9];
        home_result res;
        render_pair(SYNTH_STRUCTURED, seed, 20, h);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        failures += !res.ok;
        sum += synth_corner_error(res.H, h, IMG_W, IMG_H);
    }
    printf("     Hough on 1/%d size, %s, p=20: mean corner error %.3f px, %d/4 failed\n", downscale,
           refine_levels ? "refined" : "unrefined", sum / 4, failures);
    CHECK_EQ_INT(failures, 0);
    CHECK_LT(sum / 4, bound);
    cfg.hough_method = HOME_HOUGH_EXACT;            /* only the fast transform downscales */
    CHECK_EQ_INT(home_validate_config(&cfg), HOME_E_CONFIG);
}

void test_downscaled_hough(void)
{
    home_config cfg;
    downscaled_hough(2, 0, 1.5);
    downscaled_hough(4, 0, 3.0);
    downscaled_hough(4, home_default_config(&cfg, IMG_W, IMG_H) == HOME_OK ? cfg.refine_levels : 0, 0.2);
    cfg.hough_downscale = 3;
    CHECK_EQ_INT(home_validate_config(&cfg), HOME_E_CONFIG);
    cfg.hough_downscale = 4; cfg.width = 4 * HOME_MIN_SIDE - 1;
    CHECK_EQ_INT(home_validate_config(&cfg), HOME_E_CONFIG);
}
/* The video preset: Hough on a ~160 px frame, registering frame pairs of video-sized motion
 * (corners moved by up to 12 px) against cached features, sub-pixel after the refinement. */
void test_video_config(void)
{
    home_config cfg;
    home_context *ctx;
    double worst = 0.0;
    int k;
    CHECK_EQ_INT(home_video_config(&cfg, IMG_W, IMG_H), HOME_OK);
    CHECK_EQ_INT(home_validate_config(&cfg), HOME_OK);
    CHECK_EQ_INT(cfg.hough_downscale, 4);
    /* 1.25 MB with the cached theta geometry; issue 4's bound is 2 MiB */
    CHECK(home_arena_size(&cfg) < (size_t)3 << 19);
    CHECK_EQ_INT(home_video_config(&cfg, 320, 180), HOME_OK);
    CHECK_EQ_INT(cfg.hough_downscale, 2);
    CHECK_EQ_INT(home_validate_config(&cfg), HOME_OK);
    CHECK_EQ_INT(home_video_config(&cfg, 160, 120), HOME_OK);
    CHECK_EQ_INT(cfg.hough_downscale, 1);
    CHECK_EQ_INT(home_validate_config(&cfg), HOME_OK);
    CHECK_EQ_INT(home_video_config(NULL, IMG_W, IMG_H), HOME_E_NULL);
    CHECK_EQ_INT(home_video_config(&cfg, 8, IMG_H), HOME_E_SIZE);
    home_video_config(&cfg, IMG_W, IMG_H);
    ctx = test_context(IMG_W, IMG_H, &cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 4; k++) {
        const int kind = k & 1 ? SYNTH_WEAK_TEXTURE : SYNTH_STRUCTURED;
        uint64_t seed = 4100 + (uint64_t)k;
        double h[9], e;
        home_result res;
        render_pair(kind, seed, 12, h);
        CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &fa), HOME_OK);
        CHECK_EQ_INT(home_extract(ctx, img_b, IMG_W, &fb), HOME_OK);
        CHECK_EQ_INT(home_match(ctx, &fa, &fb, &res), HOME_OK);
        CHECK(res.ok);
        e = synth_corner_error(res.H, h, IMG_W, IMG_H);
        worst = e > worst ? e : worst;
    }
    printf("     video preset, p=12: worst corner error %.3f px of 4 pairs\n", worst);
    CHECK_LT(worst, 0.3);
}

void test_end_to_end_weak_texture(void) { end_to_end(SYNTH_WEAK_TEXTURE, 2000); }

void test_fast_pass(void)
{
    /* home_register()'s fast pass answers a structured pair as precisely as the full pass; its
     * features cannot be mixed with home_extract()'s; and when it is not ok (here: noise
     * against other noise), the answer is the one-pass answer bit for bit */
    home_config cfg, one;
    home_context *ctx;
    home_result fast, full, res;
    double h[9];
    synth_rng rng;
    size_t i;
    home_default_config(&cfg, IMG_W, IMG_H);
    CHECK_EQ_INT(cfg.fast_pass_downscale, 4);
    home_default_config(&one, IMG_W / 2, IMG_H / 2);
    CHECK_EQ_INT(one.fast_pass_downscale, 0);   /* a Hough image under 160 px: one pass */
    home_video_config(&one, IMG_W, IMG_H);
    CHECK_EQ_INT(one.fast_pass_downscale, 0);
    render_pair(SYNTH_STRUCTURED, 61, 20, h);
    ctx = test_context(IMG_W, IMG_H, &cfg);
    if (!ctx) { CHECK(0); return; }
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &fast), HOME_OK);
    CHECK(fast.ok && fast.fast_pass && fast.refined);
    CHECK(synth_corner_error(fast.H, h, IMG_W, IMG_H) < 0.15);
    CHECK(home_last_features(ctx, 0) != NULL);
    CHECK_EQ_INT(home_extract(ctx, img_b, IMG_W, &fb), HOME_OK);
    CHECK_EQ_INT(home_match(ctx, home_last_features(ctx, 0), &fb, &res), HOME_E_MISMATCH);

    one = cfg;
    one.fast_pass_downscale = 0;
    ctx = test_context(IMG_W, IMG_H, &one);
    if (!ctx) { CHECK(0); return; }
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &full), HOME_OK);
    CHECK(full.ok && !full.fast_pass);
    CHECK(fabs(synth_corner_error(fast.H, h, IMG_W, IMG_H) -
               synth_corner_error(full.H, h, IMG_W, IMG_H)) < 0.05);

    synth_seed(&rng, 5);
    for (i = 0; i < sizeof img_a; i++) {
        img_a[i] = (uint8_t)(synth_uniform(&rng) * 256);
        img_b[i] = (uint8_t)(synth_uniform(&rng) * 256);
    }
    ctx = test_context(IMG_W, IMG_H, &one);
    if (!ctx) { CHECK(0); return; }
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &full), HOME_OK);
    ctx = test_context(IMG_W, IMG_H, &cfg);
    if (!ctx) { CHECK(0); return; }
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
    CHECK(!res.fast_pass);
    CHECK_EQ_INT(res.ok, full.ok);
    CHECK_EQ_INT(res.failure, full.failure);
    CHECK_EQ_INT(res.refine_status, full.refine_status);
    CHECK(memcmp(res.H, full.H, sizeof res.H) == 0);
    CHECK_EQ_INT(res.inliers, full.inliers);
    CHECK_EQ_INT(res.matches, full.matches);
}

void test_video_reuse_matches_pair(void)
{
    /* registering cached features gives exactly what the two-image call gives in one pass (a
     * fast pass extracts features of its own) */
    home_config cfg;
    home_context *ctx;
    home_result pair, video;
    double h[9];
    synth_rng rng;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.fast_pass_downscale = 0;
    ctx = test_context(IMG_W, IMG_H, &cfg);
    if (!ctx) { CHECK(0); return; }
    synth_seed(&rng, 31);
    synth_corner_homography(&rng, IMG_W, IMG_H, 15, h);
    synth_render(SYNTH_STRUCTURED, 31, identity, 2.5, 1, img_a, IMG_W, IMG_H, IMG_W);
    synth_render(SYNTH_STRUCTURED, 31, h, 2.5, 2, img_b, IMG_W, IMG_H, IMG_W);
    static home_features fb_pair;
    home_result onward, onward_again;
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &pair), HOME_OK);
    /* b's refinement points are selected only once another frame comes: b registered onward
     * to it is refined as when b was extracted on its own */
    memcpy(&fb_pair, home_last_features(ctx, 1), sizeof fb_pair);
    CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &fa), HOME_OK);
    CHECK_EQ_INT(home_match(ctx, &fb_pair, &fa, &onward), HOME_OK);
    CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &fa), HOME_OK);
    CHECK_EQ_INT(home_extract(ctx, img_b, IMG_W, &fb), HOME_OK);
    CHECK_EQ_INT(home_match(ctx, &fa, &fb, &video), HOME_OK);
    CHECK(pair.ok && video.ok);
    CHECK(memcmp(pair.H, video.H, sizeof pair.H) == 0);
    CHECK_EQ_INT(pair.inliers, video.inliers);
    CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &fa), HOME_OK);
    CHECK_EQ_INT(home_match(ctx, &fb, &fa, &onward_again), HOME_OK);
    CHECK(onward.refined && onward_again.refined);
    CHECK(memcmp(onward.H, onward_again.H, sizeof onward.H) == 0);
    {
        /* the same keypoints (entries past the counts are unspecified) */
        const home_features *cached = home_last_features(ctx, 1);
        int k, same = cached && cached->n_pos == fb.n_pos && cached->n_neg == fb.n_neg;
        for (k = 0; same && k < fb.n_pos + fb.n_neg; k++) {
            const home_keypoint *p = &cached->kp[k], *q = &fb.kp[k];
            same = p->theta == q->theta && p->r == q->r && p->saliency == q->saliency &&
                   p->sign == q->sign && p->has_alt == q->has_alt &&
                   !memcmp(p->desc, q->desc, sizeof p->desc) &&
                   (!p->has_alt || !memcmp(p->alt_desc, q->alt_desc, sizeof p->alt_desc));
        }
        CHECK(same);
    }
}

void test_deterministic_output(void)
{
    home_context *ctx = test_context(IMG_W, IMG_H, NULL);
    home_result r1, r2;
    double h[9];
    synth_rng rng;
    if (!ctx) { CHECK(0); return; }
    synth_seed(&rng, 41);
    synth_corner_homography(&rng, IMG_W, IMG_H, 25, h);
    synth_render(SYNTH_WEAK_TEXTURE, 41, identity, 2.5, 1, img_a, IMG_W, IMG_H, IMG_W);
    synth_render(SYNTH_WEAK_TEXTURE, 41, h, 2.5, 2, img_b, IMG_W, IMG_H, IMG_W);
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &r1), HOME_OK);
    memcpy(&fa, home_last_features(ctx, 0), sizeof fa);
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &r2), HOME_OK);
    CHECK(memcmp(r1.H, r2.H, sizeof r1.H) == 0);
    CHECK(memcmp(&fa, home_last_features(ctx, 0), sizeof fa) == 0);
}

void test_fails_cleanly(void)
{
    /* no structure at all: a flat image, and pure noise against other pure noise */
    home_context *ctx = test_context(IMG_W, IMG_H, NULL);
    home_result res;
    synth_rng rng;
    int i;
    if (!ctx) { CHECK(0); return; }
    memset(img_a, 128, sizeof img_a);
    memset(img_b, 128, sizeof img_b);
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
    CHECK(!res.ok);
    CHECK_EQ_INT(res.keypoints_a, 0);
    synth_seed(&rng, 5);
    for (i = 0; i < IMG_W * IMG_H; i++) {
        img_a[i] = (uint8_t)(synth_uniform(&rng) * 256);
        img_b[i] = (uint8_t)(synth_uniform(&rng) * 256);
    }
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
    CHECK(!res.ok);
}

void test_bad_inputs(void)
{
    home_config cfg, bad;
    home_context *ctx;
    home_result res;
    static union { unsigned char b[(1 << 16) + 16]; double d; } small_storage;
    unsigned char *small = (unsigned char *)(((uintptr_t)small_storage.b + 15) & ~(uintptr_t)15);
    size_t need = 0;
    CHECK_EQ_INT(home_default_config(NULL, IMG_W, IMG_H), HOME_E_NULL);
    CHECK_EQ_INT(home_default_config(&cfg, 0, IMG_H), HOME_E_SIZE);
    CHECK_EQ_INT(home_default_config(&cfg, IMG_W, -5), HOME_E_SIZE);
    CHECK_EQ_INT(home_default_config(&cfg, HOME_MAX_SIDE + 1, IMG_H), HOME_E_SIZE);
    CHECK_EQ_INT(home_default_config(&cfg, IMG_W, IMG_H), HOME_OK);
    CHECK_EQ_INT(home_validate_config(NULL), HOME_E_NULL);
    CHECK_EQ_INT(home_arena_size(NULL), 0);
    bad = cfg; bad.theta_bins = 0; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.ratio = (float)NAN; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.smooth_sigma = (float)INFINITY; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.keypoints_per_sign = HOME_MAX_KEYPOINTS_PER_SIGN + 1; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.r_bins = 101; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.threshold_start = 0.5f; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    CHECK_EQ_INT(home_arena_size(&bad), 0);
    CHECK_EQ_INT(home_init(NULL, &cfg, small, (size_t)1 << 16, NULL), HOME_E_NULL);
    CHECK_EQ_INT(home_init(&ctx, &cfg, NULL, 1 << 30, NULL), HOME_E_NULL);
    CHECK_EQ_INT(home_init(&ctx, &cfg, small, (size_t)1 << 16, &need), HOME_E_ARENA_SMALL);
    CHECK_EQ_INT(need, home_arena_size(&cfg));
    CHECK(ctx == NULL);
    CHECK(strlen(home_strerror(HOME_E_ARENA_SMALL)) > 10);
    CHECK(strcmp(home_strerror(12345), "unknown status code") == 0);

    ctx = test_context(IMG_W, IMG_H, NULL);
    if (!ctx) { CHECK(0); return; }
    memset(img_a, 90, sizeof img_a);
    CHECK_EQ_INT(home_extract(NULL, img_a, IMG_W, &fa), HOME_E_NULL);
    CHECK_EQ_INT(home_extract(ctx, NULL, IMG_W, &fa), HOME_E_NULL);
    CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, NULL), HOME_E_NULL);
    CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W - 1, &fa), HOME_E_STRIDE);
    CHECK_EQ_INT(home_extract(ctx, img_a, -IMG_W, &fa), HOME_E_STRIDE);
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, 0, &res), HOME_E_STRIDE);
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, NULL), HOME_E_NULL);
    /* features never extracted, or corrupted */
    memset(&fb, 0, sizeof fb);
    CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &fa), HOME_OK);
    CHECK_EQ_INT(home_match(ctx, &fa, &fb, &res), HOME_E_STATE);
    CHECK_EQ_INT(home_match(ctx, &fa, NULL, &res), HOME_E_NULL);
    fb = fa; fb.n_pos = -3;
    CHECK_EQ_INT(home_match(ctx, &fa, &fb, &res), HOME_E_STATE);
    /* features of a different frame size are refused */
    {
        home_context *small_ctx = test_context(320, 180, NULL);
        CHECK_EQ_INT(home_extract(small_ctx, img_a, 320, &fb), HOME_OK);
        ctx = test_context(IMG_W, IMG_H, NULL);
        CHECK_EQ_INT(home_match(ctx, &fa, &fb, &res), HOME_E_MISMATCH);
    }
    /* a context that was never initialised */
    {
        static union { unsigned char b[sizeof(void *) * 64]; double d; } junk;
        memset(junk.b, 0x5a, sizeof junk.b);
        CHECK_EQ_INT(home_extract((home_context *)(void *)junk.b, img_a, IMG_W, &fa), HOME_E_STATE);
    }
}
