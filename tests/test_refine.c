/* Photometric refinement (src/refine.c): accuracy on known homographies, robustness (occluder,
 * gain change, low light), the safeguards (textureless, iteration cap, trust region), the
 * failure rule, video == pair, the kernels against plain references, arena size and bad inputs.
 * Prints "N passed, N failed" last; `home-refine-tests NAME...` runs a subset. */
#include "test.h"
#include "synth.h"
#include "home_internal.h"
#include "refine_internal.h"
#include <math.h>
#include <stdint.h>
#include <string.h>


#define IMG_W 640
#define IMG_H 360
static uint8_t img_a[IMG_W * IMG_H], img_b[IMG_W * IMG_H];
static home_features fa, fb;
static union { unsigned char bytes[2u << 20]; double align; } arena;
static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

static home_context *context(const home_config *override_cfg)
{
    home_config cfg;
    home_context *ctx = NULL;
    if (override_cfg) cfg = *override_cfg;
    else home_default_config(&cfg, IMG_W, IMG_H);
    if (home_init(&ctx, &cfg, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes), NULL) != HOME_OK) return NULL;
    return ctx;
}

/* A band-limited texture: a sum of plane waves (wavelengths 7..60 px), analytic so any
 * homography renders it exactly. */
typedef struct texture { double kx[16], ky[16], phase[16], amp[16]; } texture;

static void make_texture(texture *t, uint64_t seed)
{
    synth_rng rng;
    int k;
    synth_seed(&rng, seed);
    for (k = 0; k < 16; k++) {
        double ang = synth_uniform(&rng) * 3.14159265358979, lambda = 7.0 + 53.0 * synth_uniform(&rng);
        t->kx[k] = 2 * 3.14159265358979 / lambda * cos(ang);
        t->ky[k] = 2 * 3.14159265358979 / lambda * sin(ang);
        t->phase[k] = 6.28318530717959 * synth_uniform(&rng);
        t->amp[k] = 6.0 + 8.0 * synth_uniform(&rng);
    }
}

/* Render texture seen through h (scene -> image), times gain, plus noise. */
static void render_texture(const texture *t, const double *h, double gain, double noise,
                           uint64_t seed, uint8_t *out)
{
    double inv[9];
    synth_rng rng;
    int x, y, k;
    synth_invert(h, inv);
    synth_seed(&rng, seed);
    for (y = 0; y < IMG_H; y++) {
        for (x = 0; x < IMG_W; x++) {
            double sx, sy, v = 128.0;
            synth_apply(inv, x, y, &sx, &sy);
            for (k = 0; k < 16; k++) v += t->amp[k] * sin(t->kx[k] * sx + t->ky[k] * sy + t->phase[k]);
            v = gain * v + noise * synth_gauss(&rng);
            out[y * IMG_W + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : floor(v + 0.5));
        }
    }
}

/* h_true composed with a random corner perturbation of up to p px: a start like HOME's. */
static void perturbed(const double *h_true, double p, uint64_t seed, double *h_out)
{
    double dh[9], t[9];
    synth_rng rng;
    int i, j, k;
    synth_seed(&rng, seed);
    synth_corner_homography(&rng, IMG_W, IMG_H, p, dh);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            t[i * 3 + j] = 0;
            for (k = 0; k < 3; k++) t[i * 3 + j] += dh[i * 3 + k] * h_true[k * 3 + j];
        }
    for (k = 0; k < 9; k++) h_out[k] = t[k] / t[8];
}

static void textured_pair(uint64_t seed, double p, double gain, double *h)
{
    texture t;
    synth_rng rng;
    make_texture(&t, seed);
    synth_seed(&rng, seed);
    synth_corner_homography(&rng, IMG_W, IMG_H, p, h);
    render_texture(&t, identity, 1.0, 2.5, 2 * seed + 1, img_a);
    render_texture(&t, h, gain, 2.5, 2 * seed + 2, img_b);
}

static void structured_pair(uint64_t seed, double p, double *h)
{
    synth_rng rng;
    synth_seed(&rng, seed);
    synth_corner_homography(&rng, IMG_W, IMG_H, p, h);
    synth_render(SYNTH_STRUCTURED, (uint32_t)seed, identity, 2.5, 2 * seed + 1, img_a, IMG_W, IMG_H, IMG_W);
    synth_render(SYNTH_STRUCTURED, (uint32_t)seed, h, 2.5, 2 * seed + 2, img_b, IMG_W, IMG_H, IMG_W);
}

/* Refine from a start `p_start` px off and return the corner error; checks acceptance. */
static double refine_from(home_context *ctx, const double *h, double p_start, uint64_t seed,
                          home_result *res)
{
    double h0[9];
    perturbed(h, p_start, seed, h0);
    CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W, img_b, IMG_W, h0, res), HOME_OK);
    return synth_corner_error(res->H, h, IMG_W, IMG_H);
}

/* Textured pairs 10, 25, 40 px apart (the first `pairs`), refined from 2 px off: each accepted
 * and within max_err px. */
static void textured_refines(home_context *ctx, int pairs, double max_err)
{
    int k;
    for (k = 0; k < pairs; k++) {
        double h[9], err;
        home_result res;
        textured_pair(100 + k, 10 + 15 * k, 1.0, h);
        err = refine_from(ctx, h, 2.0, 7 + k, &res);
        printf("     %d points, textured p=%d: start 2 px off -> %.3f px, status %d, %d iterations\n",
               ctx->cfg.refine_points, 10 + 15 * k, err, res.refine_status, res.refine_iterations);
        CHECK(res.refined);
        CHECK_LT(err, max_err);
    }
}

/* The identity test's grid without a division: the same regions as x * 8 / w and y * 6 / h
 * for every level size up to HOME_MAX_SIDE and every pixel. */
void test_region_grid_exact(void)
{
    int w, x, bad = 0;
    for (w = 1; w <= HOME_MAX_SIDE; w++) {
        const region_grid g = region_grid_for(w, w);
        for (x = 0; x < w; x++)
            bad += region_at(g, x, x) != (x * REGIONS_Y / w) * REGIONS_X + x * REGIONS_X / w;
    }
    CHECK_EQ_INT(bad, 0);
}

void test_textured_subpixel(void)
{
    home_context *ctx = context(NULL);
    if (!ctx) { CHECK(0); return; }
    textured_refines(ctx, 3, 0.1);
}

/* A smaller point budget: a quarter of the points still refine to sub-pixel, in a smaller
 * arena, and the template holds no more points than the budget. */
void test_point_budget(void)
{
    home_config cfg;
    home_context *ctx;
    size_t full;
    home_default_config(&cfg, IMG_W, IMG_H);
    full = home_arena_size(&cfg);
    cfg.refine_points = HOME_REFINE_MAX_POINTS / 4;
    CHECK(home_arena_size(&cfg) < full);
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    textured_refines(ctx, 2, 0.15);
    CHECK(ctx->refine.tpl[0][0].n + ctx->refine.tpl[1][0].n <= 2 * cfg.refine_points);
    CHECK(ctx->refine.tpl[0][0].n > cfg.refine_points / 2);
}

/* The refinement ending at half size (refine_finest_level = 1): no full-size template points
 * are selected, and it still lands within 0.1 px from 2 px off (the full-size one: ~0.03). */
void test_finest_level_half(void)
{
    home_config cfg;
    int k;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.refine_finest_level = 1;
    {
        home_config full_cfg;
        home_default_config(&full_cfg, IMG_W, IMG_H);
        CHECK(home_arena_size(&cfg) < home_arena_size(&full_cfg)); /* no full-size template */
    }
    for (k = 0; k < 2; k++) {
        double h[9], err_half, err_full;
        home_result res;
        home_context *ctx = context(NULL); /* one arena: full size first, then half */
        if (!ctx) { CHECK(0); return; }
        textured_pair(100 + k, 10 + 15 * k, 1.0, h);
        err_full = refine_from(ctx, h, 2.0, 7 + k, &res);
        ctx = context(&cfg);
        if (!ctx) { CHECK(0); return; }
        err_half = refine_from(ctx, h, 2.0, 7 + k, &res);
        printf("     textured p=%d: start 2 px off -> %.3f px ending at half size, %.3f px at full, "
               "%d iterations\n", 10 + 15 * k, err_half, err_full, res.refine_iterations);
        CHECK(res.refined);
        home__refine_settle(ctx, -1); /* frame b's points: selected when needed */
        CHECK_EQ_INT(ctx->refine.tpl[0][0].n + ctx->refine.tpl[1][0].n, 0);
        CHECK(ctx->refine.tpl[0][1].n > 0 && ctx->refine.tpl[1][1].n > 0);
        CHECK_LT(err_half, 0.1);
    }
}

void test_lines_subpixel(void)
{
    home_context *ctx = context(NULL);
    int k;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 3; k++) {
        double h[9], err;
        home_result res;
        structured_pair(200 + k, 10 + 15 * k, h);
        err = refine_from(ctx, h, 1.5, 17 + k, &res);
        printf("     line-only p=%d: start 1.5 px off -> %.3f px, status %d\n", 10 + 15 * k, err,
               res.refine_status);
        CHECK(res.refined);
        CHECK_LT(err, 0.5);
    }
}

void test_moving_occluder(void)
{
    /* a textured block of 20 % of the frame pasted into B only (it moved in from elsewhere) */
    home_context *ctx = context(NULL);
    double h[9], err;
    home_result res;
    synth_rng rng;
    int x, y, x0 = 150, y0 = 100, bw = 256, bh = 180; /* 256 * 180 = 20 % of 640 * 360 */
    if (!ctx) { CHECK(0); return; }
    textured_pair(300, 20, 1.0, h);
    synth_seed(&rng, 301);
    for (y = y0; y < y0 + bh; y++)
        for (x = x0; x < x0 + bw; x++)
            img_b[y * IMG_W + x] = (uint8_t)(((x / 12 + y / 9) & 1) ? 230 : 20) + (uint8_t)(synth_uniform(&rng) * 10);
    err = refine_from(ctx, h, 2.0, 31, &res);
    printf("     occluder 20 %%: %.3f px, status %d\n", err, res.refine_status);
    CHECK(res.refined);
    CHECK_LT(err, 0.1);
}

void test_gain_change(void)
{
    home_context *ctx = context(NULL);
    const double gains[2] = {1.3, 0.7};
    int k;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 2; k++) {
        double h[9], err;
        home_result res;
        textured_pair(400 + k, 20, gains[k], h);
        err = refine_from(ctx, h, 2.0, 41 + k, &res);
        printf("     gain x%.1f: %.3f px, status %d\n", gains[k], err, res.refine_status);
        CHECK(res.refined);
        CHECK_LT(err, 0.1);
    }
}

void test_textureless_declines(void)
{
    /* smooth shading and noise only: nothing to align, the start must come back untouched */
    home_context *ctx = context(NULL);
    static const double noise[4] = {1.0, 2.5, 4.0, 6.0};
    double h[9], h0[9], inv[9];
    home_result res;
    synth_rng rng;
    int x, y, k;
    if (!ctx) { CHECK(0); return; }
    synth_seed(&rng, 5);
    synth_corner_homography(&rng, IMG_W, IMG_H, 15, h);
    synth_invert(h, inv);
    for (k = 0; k < 4; k++) {
        for (y = 0; y < IMG_H; y++)
            for (x = 0; x < IMG_W; x++) {
                double sx, sy;
                img_a[y * IMG_W + x] = (uint8_t)(100 + 0.05 * x + 0.04 * y + noise[k] * synth_gauss(&rng));
                synth_apply(inv, x, y, &sx, &sy);
                img_b[y * IMG_W + x] = (uint8_t)(100 + 0.05 * sx + 0.04 * sy + noise[k] * synth_gauss(&rng));
            }
        perturbed(h, 1.5, 9, h0);
        CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W, img_b, IMG_W, h0, &res), HOME_OK);
        printf("     shading + noise sigma %.1f: status %d\n", noise[k], res.refine_status);
        CHECK(!res.refined);
        CHECK(memcmp(res.H, h0, sizeof h0) == 0);
    }
    /* a flat grey pair */
    memset(img_a, 128, sizeof img_a);
    memset(img_b, 128, sizeof img_b);
    CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W, img_b, IMG_W, h0, &res), HOME_OK);
    CHECK_EQ_INT(res.refine_status, HOME_REFINE_FEW_POINTS);
    CHECK(memcmp(res.H, h0, sizeof h0) == 0);
}

void test_iteration_cap_keeps_start(void)
{
    home_config cfg;
    home_context *ctx;
    double h[9], h0[9];
    home_result res;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.refine_iterations = 1;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    textured_pair(500, 20, 1.0, h);
    perturbed(h, 3.0, 51, h0);
    CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W, img_b, IMG_W, h0, &res), HOME_OK);
    CHECK_EQ_INT(res.refine_status, HOME_REFINE_NOT_CONVERGED);
    CHECK(!res.refined);
    CHECK(memcmp(res.H, h0, sizeof h0) == 0);
}

/* Dim, noisy frames (low light): the template's gradients are mostly noise, J^T W J holds
 * several times the information the frames give, and every Gauss-Newton step falls short by
 * the same share. From a start HOME's lines would give, the refinement still reaches the
 * optimum (its finest level goes on while the steps keep shrinking slowly), and its predicted
 * error covers the true one. */
void test_low_light_converges(void)
{
    const double gain = 0.08, noise = 3.0; /* texture about 2.5 grey levels RMS */
    home_context *ctx = context(NULL);
    int k;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 6; k++) {
        texture t;
        double h[9], err;
        home_result res;
        synth_rng rng;
        make_texture(&t, 700 + k);
        synth_seed(&rng, 700 + k);
        synth_corner_homography(&rng, IMG_W, IMG_H, 4.0, h);
        render_texture(&t, identity, gain, noise, 1400 + 2 * k, img_a);
        render_texture(&t, h, gain, noise, 1401 + 2 * k, img_b);
        err = refine_from(ctx, h, 1.0, 30 + k, &res);
        printf("     pair %d: status %d, %d iterations, %s, error %.3f px, sigma %.3f px\n", k,
               res.refine_status, res.refine_iterations, home_model_name(res.model), err,
               res.sigma_px);
        /* without going on past the cap, pairs 1 and 3 end not converged; pair 1's perspective
         * does not stand out of the model choice's floor: its affine is 1.9 px off and says
         * 1.7 px */
        CHECK(res.refined);
        CHECK_LT(err, res.model == HOME_MODEL_HOMOGRAPHY ? 1.5 : 2.0);
        CHECK_LT(err, 3.0 * res.sigma_px);
    }
}

/* HOME short of inliers (held there by an unreachable min_inliers), its estimate refined: a
 * precise photometric optimum next to it, with nearly every point consistent, is the answer
 * even where camera noise holds the correlation well under 0.9 (dim textured frames). */
void test_noisy_refinement_confirms(void)
{
    const double gain = 0.08, noise = 3.0; /* texture about 2 grey levels RMS, fine grain */
    home_config cfg;
    home_context *ctx;
    int k, low_correlation = 0;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.min_inliers = 2000;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 4; k++) {
        texture t;
        double h[9], err;
        home_result res;
        synth_rng rng;
        int i;
        make_texture(&t, 900 + k);
        for (i = 0; i < 16; i++) { /* wavelengths 3.5-30 px: sharp gradients for the contrast */
            t.kx[i] *= 2.0;
            t.ky[i] *= 2.0;
        }
        synth_seed(&rng, 900 + k);
        synth_corner_homography(&rng, IMG_W, IMG_H, 10.0, h);
        render_texture(&t, identity, gain, noise, 1800 + 2 * k, img_a);
        render_texture(&t, h, gain, noise, 1801 + 2 * k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        printf("     pair %d: ok %d, %s, %s, %d inliers, zncc %.3f, share %.3f, error %.3f px, "
               "sigma %.3f px\n", k, res.ok, home_failure_name(res.failure),
               home_refine_status_name(res.refine_status), res.inliers, res.refine_zncc,
               res.refine_inlier_share, err, res.sigma_px);
        low_correlation += res.refine_zncc < 0.9;
        CHECK(res.ok);
        CHECK_EQ_INT(res.refine_status, HOME_REFINE_ACCEPTED);
        CHECK_LT(err, 0.5);
        CHECK_LT(err, 3.0 * res.sigma_px);
    }
    CHECK(low_correlation >= 2); /* the case this is about */
}

/* Dim structured frames (a tenth of the contrast over a dark floor, noise 3) under an affine
 * motion, max_model affine (so no dense alignment, which answers such frames first under a
 * homography cap): HOME's line fit is only too uncertain (sigma_px above max_sigma_px), and
 * the refinement next to it predicts more than the 0.4 max_sigma_px it would need to vouch
 * alone. Two measurements from different evidence agreeing within their combined error,
 * nearly every refined point consistent, are the answer, within 3 predicted errors; every ok
 * answer within 2 px. */
void test_uncertain_lines_confirmed(void)
{
    home_config cfg;
    home_context *ctx;
    int k, i, ok = 0, confirmed = 0;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.max_model = HOME_MODEL_AFFINE; /* below a homography: no dense alignment */
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 8; k++) {
        double h[9], err;
        home_result res;
        synth_rng rng;
        synth_seed(&rng, 3000 + k);
        { /* about the centre: 0.3-0.9 degrees, 1 % of scale, a little shear, 3-6 px */
            const double a = (0.005 + 0.01 * synth_uniform(&rng)) * (k % 2 ? -1.0 : 1.0);
            const double sc = 1.0 + 0.01 * (synth_uniform(&rng) - 0.5) * 2.0;
            const double tx = 3.0 + 3.0 * synth_uniform(&rng), ty = -2.0 + 4.0 * synth_uniform(&rng);
            const double cx = 0.5 * (IMG_W - 1), cy = 0.5 * (IMG_H - 1);
            h[0] = sc * cos(a); h[1] = -sc * sin(a) + 0.006; h[3] = sc * sin(a); h[4] = sc * cos(a) - 0.008;
            h[2] = cx + tx - h[0] * cx - h[1] * cy;
            h[5] = cy + ty - h[3] * cx - h[4] * cy;
            h[6] = h[7] = 0.0;
            h[8] = 1.0;
        }
        synth_render(SYNTH_STRUCTURED, (uint32_t)(3000 + k), identity, 0.0, 1, img_a, IMG_W, IMG_H, IMG_W);
        synth_render(SYNTH_STRUCTURED, (uint32_t)(3000 + k), h, 0.0, 2, img_b, IMG_W, IMG_H, IMG_W);
        for (i = 0; i < 2; i++) {
            uint8_t *im = i ? img_b : img_a;
            int j;
            synth_seed(&rng, 10 + 2 * k + i);
            for (j = 0; j < IMG_W * IMG_H; j++) {
                const double v = 40.0 + 0.10 * im[j] + 3.0 * synth_gauss(&rng);
                im[j] = (uint8_t)(v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : v + 0.5);
            }
        }
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        printf("     pair %d: ok %d, %s, %s, %d inliers, share %.3f, error %.3f px, sigma %.3f px\n",
               k, res.ok, home_failure_name(res.failure),
               home_refine_status_name(res.refine_status), res.inliers, res.refine_inlier_share,
               err, res.sigma_px);
        if (!res.ok) continue;
        ok++;
        CHECK_LT(err, 2.0);
        if (res.refine_status != HOME_REFINE_ACCEPTED || res.sigma_px <= 0.4) continue;
        confirmed++; /* more than a refinement may predict to vouch alone */
        CHECK_LT(err, 3.0 * res.sigma_px);
    }
    CHECK(confirmed >= 2); /* the case this is about */
    CHECK(ok >= 6);
}

/* Four plane waves of 300-900 px, 8-25 grey levels (faint: each times 0.3-1). */
static void shading_waves(texture *t, synth_rng *rng, int faint)
{
    int i;
    memset(t, 0, sizeof *t);
    for (i = 0; i < 4; i++) {
        const double th = 3.14159265358979 * synth_uniform(rng);
        const double lambda = 300.0 + 600.0 * synth_uniform(rng);
        t->kx[i] = 2 * 3.14159265358979 / lambda * cos(th);
        t->ky[i] = 2 * 3.14159265358979 / lambda * sin(th);
        t->phase[i] = 6.28318530717959 * synth_uniform(rng);
        t->amp[i] = 8.0 + 17.0 * synth_uniform(rng);
        if (faint) t->amp[i] *= 0.3 + 0.7 * synth_uniform(rng);
    }
}

/* Frames of slow shading only (four plane waves of 300-900 px, camera noise 2.5): no edge for
 * HOME, no gradient above the refinement's noise floor, yet all the pixels of the quarter-size
 * images fix a small camera motion (HOME_REFINE_DENSE). A linear ramp's shift is a bias change,
 * and noise alone holds no motion: both stay not ok. */
void test_dense_shading(void)
{
    home_context *ctx = context(NULL);
    int k, x, y, dense_ok = 0;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 3; k++) {
        texture t;
        synth_rng rng;
        home_result res;
        double h[9], err;
        const double angle = (k - 1) * 0.003;
        synth_seed(&rng, 2000 + k);
        shading_waves(&t, &rng, 0);
        h[0] = cos(angle); h[1] = -sin(angle); h[3] = sin(angle); h[4] = cos(angle);
        h[2] = 2.5 - k; h[5] = -1.5 + 1.5 * k; h[6] = h[7] = 0.0; h[8] = 1.0;
        render_texture(&t, identity, 1.0, 2.5, 2100 + 2 * k, img_a);
        render_texture(&t, h, 1.0, 2.5, 2101 + 2 * k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        printf("     shading %d: ok %d, %s, %s, %s, error %.3f px, sigma %.3f px\n", k, res.ok,
               home_failure_name(res.failure), home_refine_status_name(res.refine_status),
               home_model_name(res.model), err, res.sigma_px);
        if (!res.ok) continue;
        dense_ok++;
        CHECK_EQ_INT(res.refine_status, HOME_REFINE_DENSE);
        CHECK_LT(err, 0.5);
        CHECK_LT(err, 3.0 * res.sigma_px);
    }
    /* all three: the first one's similarity predicts 0.36 px, more than a dense homography
     * may (0.3 of max_sigma_px), within what any simpler model may */
    CHECK_EQ_INT(dense_ok, 3);
    for (k = 0; k < 2; k++) {
        home_result res;
        for (y = 0; y < IMG_H; y++)
            for (x = 0; x < IMG_W; x++) {
                const double ramp = k == 0 ? 60.0 + 0.2 * x + 0.1 * y : 128.0;
                img_a[y * IMG_W + x] = (uint8_t)floor(ramp + 0.5 + 2.5 * ((x * 7 + y * 13) % 5 - 2));
                img_b[y * IMG_W + x] =
                    (uint8_t)floor(ramp + 0.6 + 2.5 * ((x * 11 + y * 3) % 5 - 2));
            }
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        printf("     %s: ok %d, %s, %s\n", k == 0 ? "ramp" : "noise", res.ok,
               home_failure_name(res.failure), home_refine_status_name(res.refine_status));
        CHECK(!res.ok || res.model == HOME_MODEL_IDENTITY);
    }
}

/* Still pairs of slow shading under a perspective that moves the corners 17-40 px: beyond a
 * pixel of the dense alignment's coarsest image (16 px) from the identity, reached from the
 * best whole-pixel shift there; a homography resting on shading spread over the whole frame
 * may predict up to 0.45 max_sigma_px. Every ok answer lies within 2 px and 3 predicted
 * errors. */
void test_dense_still_pairs(void)
{
    home_context *ctx = context(NULL);
    int k, ok = 0, far = 0;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 24; k++) {
        texture t;
        synth_rng rng;
        home_result res;
        double h[9], err, motion;
        synth_seed(&rng, 2400 + k);
        shading_waves(&t, &rng, 0);
        synth_corner_homography(&rng, IMG_W, IMG_H, 30.0, h);
        motion = synth_corner_error(identity, h, IMG_W, IMG_H);
        render_texture(&t, identity, 1.0, 2.5, 2500 + 2 * k, img_a);
        render_texture(&t, h, 1.0, 2.5, 2501 + 2 * k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        printf("     pair %d (corners %.1f px): ok %d, %s, %s, %s, error %.3f px, sigma %.3f px\n",
               k, motion, res.ok, home_failure_name(res.failure),
               home_refine_status_name(res.refine_status), home_model_name(res.model), err,
               res.sigma_px);
        if (!res.ok) continue;
        ok++;
        far += motion > 16.0 && res.refine_status == HOME_REFINE_DENSE;
        CHECK_LT(err, 2.0);
        CHECK_LT(err, 3.0 * res.sigma_px);
    }
    printf("     %d ok, %d of them dense beyond 16 px\n", ok, far);
    CHECK(far >= 3); /* the case this is about */
}

/* Lens shading: frames of slow shading waves (test_dense_shading's, a small rotation and shift)
 * seen through a lens whose illumination falls off towards the corners by 25-40 %, fixed to
 * the sensor so that it does not move with the scene. A photometric model of one gain and bias
 * takes the still falloff for part of the scene and holds the motion back: the dense alignment
 * answered 7 of these 12 pairs 0.9-3.0 px off, two more than 2 px and five more than 3 predicted
 * errors. With the shading in its model (refine_dense.c) it answers 5, three within 1 px and 3
 * predicted errors; two homographies keep a bias (1.5 and 2.9 px off at a predicted 0.4 px: the
 * perspective and the falloff's curvature, docs/trust.md session 24). The template points'
 * refinement has no shading term yet. */
void test_dense_lens_shading(void)
{
    home_context *ctx = context(NULL);
    int k, x, y, dense = 0, silent = 0, beyond = 0;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 12; k++) {
        texture t;
        synth_rng rng, noise;
        home_result res;
        double h[9], err;
        const double angle = (k % 3 - 1) * 0.003, falloff = 0.25 + 0.0125 * k;
        int i;
        synth_seed(&rng, 2000 + k);
        shading_waves(&t, &rng, 0);
        h[0] = cos(angle); h[1] = -sin(angle); h[3] = sin(angle); h[4] = cos(angle);
        h[2] = 2.5 - k % 3; h[5] = -1.5 + 1.5 * (k % 3); h[6] = h[7] = 0.0; h[8] = 1.0;
        render_texture(&t, identity, 1.0, 0.0, 3200 + 2 * k, img_a);
        render_texture(&t, h, 1.0, 0.0, 3201 + 2 * k, img_b);
        for (i = 0; i < 2; i++) {
            uint8_t *im = i ? img_b : img_a;
            synth_seed(&noise, 3300 + 2 * k + i);
            for (y = 0; y < IMG_H; y++)
                for (x = 0; x < IMG_W; x++) {
                    const double dx = (x - 0.5 * (IMG_W - 1)) / (0.5 * (IMG_W - 1));
                    const double dy = (y - 0.5 * (IMG_H - 1)) / (0.5 * (IMG_W - 1));
                    const double corner = 1.0 + (double)IMG_H * IMG_H / ((double)IMG_W * IMG_W);
                    const double v = im[y * IMG_W + x] * (1.0 - falloff * (dx * dx + dy * dy) / corner) +
                                     2.5 * synth_gauss(&noise);
                    im[y * IMG_W + x] = (uint8_t)(v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : floor(v + 0.5));
                }
        }
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        printf("     shading %d (falloff %.2f): ok %d, %s, %s, error %.3f px, sigma %.3f px\n", k,
               falloff, res.ok, home_refine_status_name(res.refine_status),
               home_model_name(res.model), err, res.sigma_px);
        if (!res.ok || res.refine_status != HOME_REFINE_DENSE) continue;
        dense++;
        silent += err > 2.0;
        beyond += err > 3.0 * res.sigma_px;
    }
    printf("     %d dense answers, %d more than 2 px off, %d more than 3 predicted errors off\n",
           dense, silent, beyond);
    CHECK(silent <= 1);
    CHECK(beyond <= 2);
    CHECK(dense >= 4);
}

/* Dim frames of faint shading (gain 0.3-1, waves of 2-25 grey levels, noise 2-6, a small
 * rotation and shift): the dense alignment answers some with a translation or a similarity
 * predicting up to max_sigma_px (an affine motion it no longer vouches for: docs/trust.md,
 * session 23); every answer it vouches for lies within 2 px and 3 predicted errors of the truth
 * (iterating on past the cap while the steps shrink made one of these 1.6 px off at a
 * predicted 0.44 px: docs/trust.md). */
void test_dense_dim_calibrated(void)
{
    home_context *ctx = context(NULL);
    int k, ok = 0;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 40; k++) {
        texture t;
        synth_rng rng;
        home_result res;
        double h[9], err, angle, gain, noise;
        synth_seed(&rng, 2100 + k);
        shading_waves(&t, &rng, 1);
        angle = 0.004 * (synth_uniform(&rng) - 0.5);
        h[0] = cos(angle); h[1] = -sin(angle); h[3] = sin(angle); h[4] = cos(angle);
        h[2] = 4.0 * (synth_uniform(&rng) - 0.5);
        h[5] = 4.0 * (synth_uniform(&rng) - 0.5);
        h[6] = h[7] = 0.0; h[8] = 1.0;
        gain = 0.3 + 0.7 * synth_uniform(&rng);
        noise = 2.0 + 4.0 * synth_uniform(&rng);
        render_texture(&t, identity, gain, noise, 2200 + 2 * k, img_a);
        render_texture(&t, h, gain, noise, 2201 + 2 * k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        if (!res.ok) continue;
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        printf("     dim %2d: %s, %s, error %.3f px, sigma %.3f px\n", k,
               home_refine_status_name(res.refine_status), home_model_name(res.model), err,
               res.sigma_px);
        ok++;
        CHECK_LT(err, 2.0);
        CHECK_LT(err, 3.0 * res.sigma_px);
    }
    CHECK(ok >= 4); /* not vacuous */
}

/* A few long edges (3-6 anti-aliased steps of 15-45 grey levels across a flat floor, a gentle
 * illumination gradient), seen through h: by day (gain 1) with noise 2.5, else one low-light
 * capture: brightness times gain, shot noise (Gaussian, of the electrons' variance at 4 per
 * grey level) and read noise 1.5. */
static void render_few_edges_dim(synth_rng *scene, const double *h, double gain, uint64_t seed,
                                 uint8_t *out)
{
    double px[6], py[6], c[6], s[6], step[6], base, gx, gy, inv[9];
    int n, i, x, y;
    synth_rng rng = *scene;
    synth_rng noise;
    base = 90.0 + 80.0 * synth_uniform(&rng);
    n = 3 + (int)(4.0 * synth_uniform(&rng));
    for (i = 0; i < n; i++) {
        const double th = 3.14159265358979 * synth_uniform(&rng);
        px[i] = (0.2 + 0.6 * synth_uniform(&rng)) * IMG_W;
        py[i] = (0.2 + 0.6 * synth_uniform(&rng)) * IMG_H;
        c[i] = cos(th);
        s[i] = sin(th);
        step[i] = (synth_uniform(&rng) < 0.5 ? -1.0 : 1.0) * (15.0 + 30.0 * synth_uniform(&rng));
    }
    gx = 2.0 * synth_uniform(&rng) - 1.0;
    gy = 2.0 * synth_uniform(&rng) - 1.0;
    synth_invert(h, inv);
    synth_seed(&noise, seed);
    for (y = 0; y < IMG_H; y++)
        for (x = 0; x < IMG_W; x++) {
            double sx, sy, v = base, e;
            synth_apply(inv, x, y, &sx, &sy);
            for (i = 0; i < n; i++)
                v += step[i] * 0.5 * (1.0 + tanh(((sx - px[i]) * c[i] + (sy - py[i]) * s[i]) / 0.7));
            v += 12.0 * (gx * (sx / IMG_W - 0.5) + gy * (sy / IMG_H - 0.5));
            if (gain >= 1.0) {
                v += 2.5 * synth_gauss(&noise);
            } else {
                e = (v < 0.0 ? 0.0 : v) * gain * 4.0; /* electrons */
                e += sqrt(e) * synth_gauss(&noise);
                v = e / 4.0 + 1.5 * synth_gauss(&noise);
            }
            out[y * IMG_W + x] = (uint8_t)(v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : floor(v + 0.5));
        }
}

/* Consecutive frames of a few long edges, dim (low-light captures, gain 0.10-0.25) or by day
 * (noise 2.5), a hand-held camera between them (1-4 px, a tenth of a degree, a slight
 * keystone). Where HOME finds a few lines at most, a homography the refinement or the dense
 * alignment fits to the pixels alone may stop in one of several optima, each predicting a
 * small error. Thirteen frames of a sweep of 240: five that session 23's rules (docs/trust.md)
 * turned from answers 2.5-4.3 px off at a predicted 0.29-0.34 px, or a dense affine answer
 * 1.15 px off at 0.72, into failures; one whose homography is now as uncertain as the optima
 * other starts reach; seven answered right before and after. Every answer vouched for lies
 * within 2 px and 3 predicted errors. */
void test_few_edges_dim_calibrated(void)
{
    static const int frames[] = {44, 49, 51, 53, 72, 84, 86, 140, 172, 174, 176, 220, 226};
    home_context *ctx = context(NULL);
    int f, ok = 0;
    if (!ctx) { CHECK(0); return; }
    for (f = 0; f < (int)(sizeof frames / sizeof frames[0]); f++) {
        const int k = frames[f];
        const double cx = 0.5 * (IMG_W - 1), cy = 0.5 * (IMG_H - 1);
        synth_rng rng, scene;
        home_result res;
        double h[9], r[9], m[9], err, gain, angle, tx, ty, g0, g1;
        int i, j;
        synth_seed(&scene, 4000 + (uint64_t)(k / 8));
        synth_seed(&rng, 4100 + (uint64_t)k);
        tx = 1.0 + 3.0 * synth_uniform(&rng);
        ty = 3.0 * (synth_uniform(&rng) - 0.5);
        g0 = 4e-6 * (synth_uniform(&rng) - 0.5);
        g1 = 4e-6 * (synth_uniform(&rng) - 0.5);
        angle = 0.004 * (synth_uniform(&rng) - 0.5);
        /* h = T(c + t) r T(-c), r a roll with a keystone row */
        r[0] = cos(angle); r[1] = -sin(angle); r[2] = 0.0;
        r[3] = sin(angle); r[4] = cos(angle); r[5] = 0.0;
        r[6] = g0; r[7] = g1; r[8] = 1.0;
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++)
                m[i * 3 + j] = j < 2 ? r[i * 3 + j] : r[i * 3 + 2] - r[i * 3] * cx - r[i * 3 + 1] * cy;
        for (j = 0; j < 3; j++) {
            h[j] = m[j] + (cx + tx) * m[6 + j];
            h[3 + j] = m[3 + j] + (cy + ty) * m[6 + j];
            h[6 + j] = m[6 + j];
        }
        for (j = 0; j < 9; j++) h[j] /= h[8];
        gain = k % 2 ? 1.0 : 0.10 + 0.15 * synth_uniform(&rng);
        render_few_edges_dim(&scene, identity, gain, 4200 + 2 * (uint64_t)k, img_a);
        render_few_edges_dim(&scene, h, gain, 4201 + 2 * (uint64_t)k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        printf("     frame %3d: ok %d, %s, %s, %s, %d inliers, error %.3f px, sigma %.3f px\n", k,
               res.ok, home_failure_name(res.failure), home_refine_status_name(res.refine_status),
               home_model_name(res.model), res.inliers, err, res.sigma_px);
        if (!res.ok) continue;
        ok++;
        CHECK_LT(err, 2.0);
        CHECK_LT(err, 3.0 * res.sigma_px);
    }
    CHECK(ok >= 6); /* not vacuous */
}

/* h: a similarity about the image centre (a roll by angle, scale), then a shift by (tx, ty). */
static void similarity_about_centre(double angle, double scale, double tx, double ty, double *h)
{
    const double cx = 0.5 * (IMG_W - 1), cy = 0.5 * (IMG_H - 1);
    h[0] = scale * cos(angle); h[1] = -scale * sin(angle);
    h[2] = cx + tx - h[0] * cx - h[1] * cy;
    h[3] = scale * sin(angle); h[4] = scale * cos(angle);
    h[5] = cy + ty - h[3] * cx - h[4] * cy;
    h[6] = 0.0; h[7] = 0.0; h[8] = 1.0;
}

/* The few dim edges of few_edges_dim_calibrated, low light only, under the stabiliser's
 * similarity cap (max_model below the homography), a similarity between the frames: HOME's
 * lines are rarely ok there, and the similarity the refinement reaches from them rests on the
 * pixels alone. Its error is now at least the spread of the optima other starts reach, as a
 * homography's is: of 60 frames, 11 of 25 ok answers were beyond 3 predicted errors (0.57-4.8
 * px off at 0.12-0.25 px), 4 of 18 still were (docs/trust.md, session 37: a bias the probes do
 * not see), 4 of 19 with the rigid stand-in (session 38). */
void test_capped_few_edges_dim_calibrated(void)
{
    home_config cfg;
    home_context *ctx;
    int k, ok = 0, misses = 0;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.max_model = HOME_MODEL_SIMILARITY;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 240; k += 4) {
        synth_rng rng, scene;
        home_result res;
        double h[9], err, gain, angle, tx, ty;
        synth_seed(&scene, 4000 + (uint64_t)(k / 8));
        synth_seed(&rng, 4100 + (uint64_t)k);
        tx = 1.0 + 3.0 * synth_uniform(&rng);
        ty = 3.0 * (synth_uniform(&rng) - 0.5);
        angle = 0.004 * (synth_uniform(&rng) - 0.5);
        similarity_about_centre(angle, 1.0, tx, ty, h);
        gain = 0.10 + 0.15 * synth_uniform(&rng);
        render_few_edges_dim(&scene, identity, gain, 4200 + 2 * (uint64_t)k, img_a);
        render_few_edges_dim(&scene, h, gain, 4201 + 2 * (uint64_t)k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        if (!res.ok) continue;
        ok++;
        if (err > 3.0 * res.sigma_px) {
            misses++;
            printf("     frame %3d: %s, %d inliers, error %.3f px, sigma %.3f px\n", k,
                   home_model_name(res.model), res.inliers, err, res.sigma_px);
        }
    }
    printf("     %d of 60 ok, %d beyond 3 predicted errors\n", ok, misses);
    CHECK(ok >= 10); /* not vacuous */
    CHECK(misses <= 4);
}

/* One registration under known motion h: counts the ok answers and the rigid ones among them
 * (unit scale: a rigid motion's diagonal is exactly 1); every ok answer lies within 2 px and 3
 * predicted errors. */
static void check_rigid_test_answer(int frame, const home_result *res, const double *h, int *ok,
                                    int *rigid)
{
    const double err = synth_corner_error(res->H, h, IMG_W, IMG_H);
    if (!res->ok) return;
    ++*ok;
    *rigid += res->model == HOME_MODEL_SIMILARITY && fabs(res->H[0] - 1.0) < 1e-9 &&
              fabs(res->H[4] - 1.0) < 1e-9;
    if (err > 2.0 || err > 3.0 * res->sigma_px)
        printf("     frame %3d: %s, %s, %d inliers, error %.3f px, sigma %.3f px\n", frame,
               home_model_name(res->model), home_refine_status_name(res->refine_status),
               res->inliers, err, res->sigma_px);
    CHECK_LT(err, 2.0);
    CHECK_LT(err, 3.0 * res->sigma_px);
}

/* Frame of a fan: 3-5 long edges (steps of 15-45 grey levels, 0.7 px blur) through nearly one
 * point of the frame (within 6 px of it), on a faint gradient, seen through h, noise 2.5. */
static void render_fan(synth_rng *scene, const double *h, uint64_t seed, uint8_t *out)
{
    double px[5], py[5], c[5], s[5], step[5], base, gx, gy, inv[9], ox, oy;
    int n, i, x, y;
    synth_rng rng = *scene;
    synth_rng noise;
    base = 90.0 + 80.0 * synth_uniform(&rng);
    n = 3 + (int)(3.0 * synth_uniform(&rng));
    ox = (0.3 + 0.4 * synth_uniform(&rng)) * IMG_W;
    oy = (0.3 + 0.4 * synth_uniform(&rng)) * IMG_H;
    for (i = 0; i < n; i++) {
        const double th = 3.14159265358979 * (i + 0.6 * synth_uniform(&rng)) / n;
        px[i] = ox + 12.0 * (synth_uniform(&rng) - 0.5);
        py[i] = oy + 12.0 * (synth_uniform(&rng) - 0.5);
        c[i] = cos(th);
        s[i] = sin(th);
        step[i] = (synth_uniform(&rng) < 0.5 ? -1.0 : 1.0) * (15.0 + 30.0 * synth_uniform(&rng));
    }
    gx = 2.0 * synth_uniform(&rng) - 1.0;
    gy = 2.0 * synth_uniform(&rng) - 1.0;
    synth_invert(h, inv);
    synth_seed(&noise, seed);
    for (y = 0; y < IMG_H; y++)
        for (x = 0; x < IMG_W; x++) {
            double sx, sy, v = base;
            synth_apply(inv, x, y, &sx, &sy);
            for (i = 0; i < n; i++)
                v += step[i] * 0.5 * (1.0 + tanh(((sx - px[i]) * c[i] + (sy - py[i]) * s[i]) / 0.7));
            v += 12.0 * (gx * (sx / IMG_W - 0.5) + gy * (sy / IMG_H - 0.5)) +
                 2.5 * synth_gauss(&noise);
            out[y * IMG_W + x] = (uint8_t)(v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : floor(v + 0.5));
        }
}

/* A fan of edges by day (render_fan) under the stabiliser's similarity cap, the camera rolling,
 * moving 1-4 px and changing scale by up to 0.2 px at the corners. Edges through nearly one
 * point leave the similarity's scale free and its refinement ill conditioned; a rigid motion
 * (unit scale) then stands in, its error holding the scale it leaves out (docs/trust.md,
 * session 38). Every answer lies within 2 px and 3 predicted errors. */
void test_capped_few_edges_day_rigid(void)
{
    home_config cfg;
    home_context *ctx;
    int k, ok = 0, rigid = 0;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.max_model = HOME_MODEL_SIMILARITY;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 240; k += 4) {
        synth_rng rng, scene;
        home_result res;
        double h[9], angle, scale, tx, ty;
        synth_seed(&scene, 4000 + (uint64_t)(k / 8));
        synth_seed(&rng, 4300 + (uint64_t)k);
        tx = 1.0 + 3.0 * synth_uniform(&rng);
        ty = 3.0 * (synth_uniform(&rng) - 0.5);
        angle = 0.004 * (synth_uniform(&rng) - 0.5);
        scale = 1.0 + 0.001 * (synth_uniform(&rng) - 0.5);
        similarity_about_centre(angle, scale, tx, ty, h);
        render_fan(&scene, identity, 4400 + 2 * (uint64_t)k, img_a);
        render_fan(&scene, h, 4401 + 2 * (uint64_t)k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        check_rigid_test_answer(k, &res, h, &ok, &rigid);
    }
    printf("     %d of 60 ok, %d of them rigid\n", ok, rigid);
    CHECK(ok >= 40);
}

/* The few dim edges of few_edges_dim_calibrated, low light, with the defaults (a homography
 * cap), the camera rolling and moving 1-4 px at unit scale (up to 0.2 px of scale change at the
 * corners). A few dim edges fill 200-500 template points at full size, fewer than a similarity
 * stand-in needs to end there; a rigid motion, three parameters, may end there with at least
 * RIGID_SPARSE_POINTS (src/refine_solve.c), its error holding the scale it leaves out beside its
 * own (docs/trust.md, session 39): 3 of 60 ok before (none rigid), 6 now (3 rigid). Every answer
 * lies within 2 px and 3 predicted errors. */
void test_few_edges_dim_rigid_sparse(void)
{
    home_context *ctx = context(NULL);
    int k, ok = 0, rigid = 0;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 240; k += 4) {
        synth_rng rng, scene;
        home_result res;
        double h[9], gain, angle, scale, tx, ty;
        synth_seed(&scene, 4000 + (uint64_t)(k / 8));
        synth_seed(&rng, 4500 + (uint64_t)k);
        tx = 1.0 + 3.0 * synth_uniform(&rng);
        ty = 3.0 * (synth_uniform(&rng) - 0.5);
        angle = 0.004 * (synth_uniform(&rng) - 0.5);
        scale = 1.0 + 0.001 * (synth_uniform(&rng) - 0.5);
        gain = 0.10 + 0.15 * synth_uniform(&rng);
        similarity_about_centre(angle, scale, tx, ty, h);
        render_few_edges_dim(&scene, identity, gain, 4600 + 2 * (uint64_t)k, img_a);
        render_few_edges_dim(&scene, h, gain, 4601 + 2 * (uint64_t)k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        check_rigid_test_answer(k, &res, h, &ok, &rigid);
    }
    printf("     %d of 60 ok, %d of them rigid\n", ok, rigid);
    CHECK(rigid >= 1); /* the case this is about */
}

/* A wavy line: three sines of amplitudes amp_min + amp_range u over 1, 2, 3 and wavelengths of
 * 0.7-1.3 times the frame's width over 1, 2, 3 (drawn from rng in that order). */
typedef struct wavy_line { double amp[3], freq[3], phase[3]; } wavy_line;

static void draw_wavy_line(synth_rng *rng, double amp_min, double amp_range, wavy_line *w)
{
    int i;
    for (i = 0; i < 3; i++) {
        w->amp[i] = (amp_min + amp_range * synth_uniform(rng)) / (i + 1);
        w->freq[i] = 6.28318530717959 * (i + 1) * (0.7 + 0.6 * synth_uniform(rng)) / IMG_W;
        w->phase[i] = 6.28318530717959 * synth_uniform(rng);
    }
}

static double wavy_line_at(const wavy_line *w, double x)
{
    return w->amp[0] * sin(w->freq[0] * x + w->phase[0]) +
           w->amp[1] * sin(w->freq[1] * x + w->phase[1]) +
           w->amp[2] * sin(w->freq[2] * x + w->phase[2]);
}

/* A horizon in fog: a wavy ridge (a step of 8-14 grey levels, blurred over 3 px) between a
 * brighter sky and a darker ground, each shaded, seen through h, noise 2.5. */
static void render_fog_horizon(synth_rng *scene, const double *h, uint64_t seed, uint8_t *out)
{
    double base, step, horizon, sky_shade, ground_shade, inv[9];
    int x, y;
    wavy_line ridge_line;
    synth_rng rng = *scene;
    synth_rng noise;
    base = 150.0 + 40.0 * synth_uniform(&rng);
    step = 8.0 + 6.0 * synth_uniform(&rng);
    horizon = (0.4 + 0.25 * synth_uniform(&rng)) * IMG_H;
    sky_shade = 6.0 + 8.0 * synth_uniform(&rng);
    ground_shade = 4.0 + 6.0 * synth_uniform(&rng);
    draw_wavy_line(&rng, 4.0, 10.0, &ridge_line);
    synth_invert(h, inv);
    synth_seed(&noise, seed);
    for (y = 0; y < IMG_H; y++)
        for (x = 0; x < IMG_W; x++) {
            double sx, sy, ridge, v;
            synth_apply(inv, x, y, &sx, &sy);
            ridge = horizon + wavy_line_at(&ridge_line, sx);
            v = base + sky_shade * (1.0 - sy / IMG_H) - ground_shade * (sy / IMG_H) -
                step * 0.5 * (1.0 + tanh((sy - ridge) / 3.0)) + 2.5 * synth_gauss(&noise);
            out[y * IMG_W + x] = (uint8_t)(v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : floor(v + 0.5));
        }
}

/* A horizon in fog under the stabiliser's similarity cap, the camera rolling and moving 1-4 px.
 * The pixels hold little more than the template's noise: a similarity fitted to them alone stops
 * at an optimum its Fisher prediction cannot see is biased (the evaluation's fog horizons, dim
 * gradients and smooth blobs: 2-8 px off at a predicted 0.2 px, with 0.50-0.61 of the
 * translation's information the frames'). Below CAPPED_MIN_SIGNAL such a fit is not an answer
 * (docs/trust.md, session 39): of 30 frames, 3 were ok before, 2.5-4.2 px off at a predicted
 * 0.19-0.21 px; none is now. Every ok answer lies within 2 px and 3 predicted errors. */
void test_capped_fog_horizon_calibrated(void)
{
    home_config cfg;
    home_context *ctx;
    int k, ok = 0, rigid = 0;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.max_model = HOME_MODEL_SIMILARITY;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 120; k += 4) {
        synth_rng rng, scene;
        home_result res;
        double h[9], angle, tx, ty;
        synth_seed(&scene, 4700 + (uint64_t)(k / 8));
        synth_seed(&rng, 4800 + (uint64_t)k);
        tx = 1.0 + 3.0 * synth_uniform(&rng);
        ty = 3.0 * (synth_uniform(&rng) - 0.5);
        angle = 0.004 * (synth_uniform(&rng) - 0.5);
        similarity_about_centre(angle, 1.0, tx, ty, h);
        render_fog_horizon(&scene, identity, 4900 + 2 * (uint64_t)k, img_a);
        render_fog_horizon(&scene, h, 4901 + 2 * (uint64_t)k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        check_rigid_test_answer(k, &res, h, &ok, &rigid);
    }
    printf("     %d of 30 ok, %d of them rigid\n", ok, rigid);
}

/* A sea horizon in haze: a sky brightening upwards over a sea of faint swell bands (1-2 grey
 * levels), low hills along the horizon and a soft sun glow, seen through h, noise 2. */
static void render_hazy_sea(synth_rng *scene, const double *h, uint64_t seed, uint8_t *out)
{
    double haze, horizon, tilt, sky, sea, swell, period, hill_depth, glow, gx, gy, inv[9];
    int x, y;
    wavy_line hill_line;
    synth_rng rng = *scene;
    synth_rng noise;
    haze = 140.0 + 50.0 * synth_uniform(&rng);
    horizon = (0.45 + 0.15 * synth_uniform(&rng)) * IMG_H;
    tilt = 0.06 * (synth_uniform(&rng) - 0.5);
    sky = 10.0 + 20.0 * synth_uniform(&rng);
    sea = 8.0 + 12.0 * synth_uniform(&rng);
    swell = 0.8 + 1.2 * synth_uniform(&rng);
    period = 25.0 + 20.0 * synth_uniform(&rng);
    hill_depth = 5.0 + 7.0 * synth_uniform(&rng);
    glow = 10.0 + 15.0 * synth_uniform(&rng);
    gx = (0.2 + 0.6 * synth_uniform(&rng)) * IMG_W;
    gy = horizon - (0.1 + 0.2 * synth_uniform(&rng)) * IMG_H;
    draw_wavy_line(&rng, 3.0, 6.0, &hill_line);
    synth_invert(h, inv);
    synth_seed(&noise, seed);
    for (y = 0; y < IMG_H; y++)
        for (x = 0; x < IMG_W; x++) {
            double sx, sy, yh, hills, below, v;
            synth_apply(inv, x, y, &sx, &sy);
            yh = sy - horizon - tilt * (sx - 0.5 * IMG_W);
            hills = 15.0 + wavy_line_at(&hill_line, sx);
            below = 0.5 * (1.0 + tanh(yh / 1.0));
            v = haze + sky * (yh < 0.0 ? (-yh / IMG_H > 1.0 ? 1.0 : -yh / IMG_H) : 0.0);
            v += below * (-sea - 0.05 * (yh > 0.0 ? yh : 0.0) - v + haze +
                          swell * sin(6.28318530717959 * pow(yh > 0.0 ? yh : 0.0, 1.3) / period));
            v -= hill_depth * 0.5 * (1.0 + tanh((yh + hills) / 2.0)) * (1.0 - below);
            v += glow * exp(-((sx - gx) * (sx - gx) + (sy - gy) * (sy - gy)) /
                            (2.0 * (0.15 * IMG_W) * (0.15 * IMG_W)));
            v += 2.0 * synth_gauss(&noise);
            out[y * IMG_W + x] = (uint8_t)(v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : floor(v + 0.5));
        }
}

/* A sea horizon in haze with the stabiliser's registration settings (src/stabilise.c,
 * home_config_for(): the video preset at 88 theta bins, a 4x4-box Hough image, 1024 refinement
 * points ending at half size, up to 4 px of predicted error), the camera shaking 4-10 px between
 * frames with a roll of up to 0.4 degrees. HOME finds a few lines (a translation, too few
 * inliers), and from there a similarity may slide along the valley where scale and translation
 * trade, to an optimum several px off at a predicted 0.5-1 px, where a path through the rigid
 * motion ends elsewhere: its error is at least that distance (docs/trust.md, session 40). Of 120
 * frames, 19 were ok, 7 of them 3.8-16.7 predicted errors off (up to 19 px); now 14, none beyond
 * 4 predicted errors. Still open: 4 are 3.1-3.6 predicted errors off (1.4-3.8 px), biased along
 * the horizon. */
void test_capped_fog_rigid_path(void)
{
    home_config cfg;
    home_context *ctx;
    int k, ok = 0, beyond = 0, beyond4 = 0;
    home_video_config(&cfg, IMG_W, IMG_H);
    cfg.theta_bins = 88;
    cfg.wrap_band = cfg.wrap_band * 88 / 120;
    cfg.match_theta_window = 7;
    cfg.hough_downscale = 4;
    cfg.refine_points = 1024;
    cfg.refine_finest_level = 1;
    cfg.max_model = HOME_MODEL_SIMILARITY;
    cfg.max_sigma_px = 4.0f;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 120; k++) {
        synth_rng rng, scene;
        home_result res;
        double h[9], angle, tx, ty, err;
        synth_seed(&scene, 5000 + (uint64_t)(k / 4));
        synth_seed(&rng, 5100 + (uint64_t)k);
        tx = (4.0 + 6.0 * synth_uniform(&rng)) * (synth_uniform(&rng) < 0.5 ? -1.0 : 1.0);
        ty = 6.0 * (synth_uniform(&rng) - 0.5);
        angle = 0.014 * (synth_uniform(&rng) - 0.5);
        similarity_about_centre(angle, 1.0, tx, ty, h);
        render_hazy_sea(&scene, identity, 5200 + 2 * (uint64_t)k, img_a);
        render_hazy_sea(&scene, h, 5201 + 2 * (uint64_t)k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        if (!res.ok) continue;
        ok++;
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        beyond4 += err > 4.0 * res.sigma_px;
        if (err > 3.0 * res.sigma_px) {
            beyond++;
            printf("     frame %2d: %s, %s, %d inliers, error %.3f px, sigma %.3f px\n", k,
                   home_model_name(res.model), home_refine_status_name(res.refine_status),
                   res.inliers, err, res.sigma_px);
        }
    }
    printf("     %d of 120 ok, %d beyond 3 sigma, %d beyond 4\n", ok, beyond, beyond4);
    CHECK_EQ_INT(beyond4, 0);
    CHECK(ok >= 10);
}

/* Lens shading: a falloff towards the corners of 15-40 %, fixed to the sensor, on frames A and
 * B (the rest of the pixels as rendered), then camera noise 2. */
static void shade_and_noise(uint8_t *im, double falloff, uint64_t seed)
{
    const double corner = 1.0 + (double)IMG_H * IMG_H / ((double)IMG_W * IMG_W);
    synth_rng noise;
    int x, y;
    synth_seed(&noise, seed);
    for (y = 0; y < IMG_H; y++)
        for (x = 0; x < IMG_W; x++) {
            const double dx = (x - 0.5 * (IMG_W - 1)) / (0.5 * (IMG_W - 1));
            const double dy = (y - 0.5 * (IMG_H - 1)) / (0.5 * (IMG_W - 1));
            const double v = im[y * IMG_W + x] * (1.0 - falloff * (dx * dx + dy * dy) / corner) +
                             2.0 * synth_gauss(&noise);
            im[y * IMG_W + x] = (uint8_t)(v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : floor(v + 0.5));
        }
}

/* Under the stabiliser's similarity, through a lens falloff of 15-40 %:
 * - a camera moving 1.5-3.5 px over a hazy scene (texture at a fifth of its contrast below the
 *   horizon, a plain sky with a fiftieth of it above): the falloff stands still, and the
 *   background's score test (refine_background.c) took it for a background that does not move
 *   and refused 9 of these 10 motions (the stabiliser held those frames). A refused motion of at
 *   most a similarity is now tested again with the falloff's change projected out, and the sky's
 *   faint texture shows it: 10 answered. Without a shading term in the template points'
 *   refinement they came out 0.03-0.38 px off, 2 of 10 beyond 3 predicted errors (4.8); the
 *   falloff is now fitted with the motion, and each is within 3;
 * - a still camera, a textured object (a third of the frame) moving 3 px over a plain, faintly
 *   graded background: with the falloff projected out, that background shows nothing either
 *   way. A rule that took "not refuted" for enough let the object's motion through (10 of 10
 *   answered 3 px off); it stays refused (the background has to show the motion). */
void test_lens_shading_pans_and_tripods(void)
{
    home_config cfg;
    home_context *ctx;
    int k, x, y, pans = 0, wrong = 0;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.max_model = HOME_MODEL_SIMILARITY;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 20; k++) {
        const int tripod = k >= 10;
        const double falloff = 0.15 + 0.25 * (k % 5) / 4.0;
        texture t;
        synth_rng rng;
        home_result res;
        double h[9], err;
        int i;
        synth_seed(&rng, 6100 + (uint64_t)k);
        make_texture(&t, 6000 + (uint64_t)k);
        if (!tripod) {
            const double angle = 0.002 * (synth_uniform(&rng) - 0.5);
            h[0] = cos(angle); h[1] = -sin(angle); h[3] = sin(angle); h[4] = cos(angle);
            h[2] = (k % 2 ? 1.0 : -1.0) * (1.5 + 2.0 * synth_uniform(&rng));
            h[5] = 2.0 * (synth_uniform(&rng) - 0.5);
            h[6] = h[7] = 0.0; h[8] = 1.0;
            for (i = 0; i < 2; i++) {
                uint8_t *im = i ? img_b : img_a;
                double inv[9];
                render_texture(&t, i ? h : identity, 1.0, 0.0, 0, im);
                synth_invert(i ? h : identity, inv);
                for (y = 0; y < IMG_H; y++)
                    for (x = 0; x < IMG_W; x++) {
                        double sx, sy, v, sky;
                        synth_apply(inv, x, y, &sx, &sy);
                        /* the horizon's row shares by cover (a hard step would put it on whole
                         * rows and move it by 0 or 1 px whatever the motion) */
                        sky = 0.6 * IMG_H - sy + 0.5;
                        sky = sky < 0.0 ? 0.0 : sky > 1.0 ? 1.0 : sky;
                        v = sky * (185.0 - 20.0 * sy / IMG_H + 0.02 * (im[y * IMG_W + x] - 128.0)) +
                            (1.0 - sky) * (160.0 + 0.2 * (im[y * IMG_W + x] - 128.0));
                        im[y * IMG_W + x] = (uint8_t)floor(v + 0.5);
                    }
            }
        } else {
            /* the object: a textured rectangle a third of the frame, 3 px to the right in B */
            const int ox = (int)(IMG_W * (0.1 + 0.3 * synth_uniform(&rng)));
            const int oy = (int)(IMG_H * (0.15 + 0.2 * synth_uniform(&rng)));
            memcpy(h, identity, sizeof h);
            render_texture(&t, identity, 1.0, 0.0, 0, img_b);
            for (y = 0; y < IMG_H; y++)
                for (x = 0; x < IMG_W; x++) {
                    const int in_a = x >= ox && x < ox + IMG_W / 2 && y >= oy && y < oy + IMG_H * 2 / 3;
                    const uint8_t plain = (uint8_t)floor(140.0 + 30.0 * y / IMG_H + 0.5);
                    img_a[y * IMG_W + x] = in_a ? img_b[y * IMG_W + x] : plain;
                }
            for (y = 0; y < IMG_H; y++)
                for (x = 0; x < IMG_W; x++) {
                    const int in_b = x >= ox + 3 && x < ox + 3 + IMG_W / 2 && y >= oy && y < oy + IMG_H * 2 / 3;
                    img_b[y * IMG_W + x] = in_b ? img_a[y * IMG_W + x - 3]
                                                : (uint8_t)floor(140.0 + 30.0 * y / IMG_H + 0.5);
                }
        }
        shade_and_noise(img_a, falloff, 6200 + 2 * (uint64_t)k);
        shade_and_noise(img_b, falloff, 6201 + 2 * (uint64_t)k);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        err = synth_corner_error(res.H, h, IMG_W, IMG_H);
        printf("     %s %2d (falloff %.2f): ok %d, %s, %s, %s, error %.3f px, sigma %.3f px\n",
               tripod ? "tripod" : "pan", k, falloff, res.ok, home_failure_name(res.failure),
               home_refine_status_name(res.refine_status), home_model_name(res.model), err,
               res.sigma_px);
        if (!res.ok) continue;
        if (tripod) {
            wrong += err > 0.5;
        } else {
            pans++;
            CHECK_LT(err, 3.0 * res.sigma_px);
        }
        CHECK_LT(err, 2.0);
    }
    printf("     pans: %d of 10 answered; tripod: %d answered wrong\n", pans, wrong);
    CHECK(pans >= 8);
    CHECK_EQ_INT(wrong, 0);
}

/* The texture t at scene point (sx, sy), times amp, about 0. */
static double texture_at(const texture *t, double sx, double sy, double amp)
{
    double v = 0.0;
    int k;
    for (k = 0; k < 16; k++) v += t->amp[k] * sin(t->kx[k] * sx + t->ky[k] * sy + t->phase[k]);
    return amp * v;
}

/* A plain view (faint texture of `faint` times its contrast) with a textured rectangle in its
 * left third; frame B's camera moved by h, or (tripod) only the rectangle moved by h; both
 * through a lens falloff of a quarter at the corners, noise 2. */
static void plain_view(const texture *t, const double *h, int tripod, double faint, uint64_t seed)
{
    double inv[9];
    int i, x, y;
    synth_invert(h, inv);
    for (i = 0; i < 2; i++) {
        uint8_t *im = i ? img_b : img_a;
        for (y = 0; y < IMG_H; y++)
            for (x = 0; x < IMG_W; x++) {
                double sx = x, sy = y, ox = x, oy = y, v;
                if (i) synth_apply(inv, x, y, &ox, &oy);
                if (i && !tripod) { sx = ox; sy = oy; }
                v = 150.0 + texture_at(t, sx, sy, faint);
                if (ox >= 40.0 && ox < 200.0 && oy >= 80.0 && oy < 280.0)
                    v = 128.0 + texture_at(t, ox, oy, 1.0);
                im[y * IMG_W + x] = (uint8_t)floor(v + 0.5);
            }
        shade_and_noise(im, 0.25, seed + (uint64_t)i);
    }
}

/* The plain-background test (refine_static.c) against a motion h of 7 px: a lens falloff stays
 * with the sensor, so on plain pixels it prefers the identity whatever the camera did. With
 * the falloff fitted on h's side (for a similarity standing in, refine.c), a camera's true
 * motion over a truly plain view is no longer refuted (z below PLAIN_Z = 6 of refine.c; 14
 * without the fit); a faint texture the still camera holds (a sixtieth of the texture's
 * contrast, about 0.5 grey levels) still refutes a moving object's motion, and shows the
 * camera's where it moves. */
void test_plain_test_fits_lens_falloff(void)
{
    static const struct { int tripod; double faint; } cases[3] = {{0, 0.0}, {1, 0.015}, {0, 0.015}};
    home_config cfg;
    home_context *ctx;
    const double h[9] = {1, 0, 6.0, 0, 1, -4.0, 0, 0, 1};
    texture t;
    int c;
    home_video_config(&cfg, IMG_W, IMG_H);
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    make_texture(&t, 6500);
    for (c = 0; c < 3; c++) {
        home_result res;
        double z[2];
        int slot, fit;
        plain_view(&t, h, cases[c].tripod, cases[c].faint, 6600 + 2 * (uint64_t)c);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        /* frame A's slot: the one frame B (the pyramid's) is not in */
        slot = ctx->refine.slot_id[0] == ctx->refine.pyr_id ? 1 : 0;
        CHECK(home__refine_plain_regions(ctx, slot) >= 24);
        for (fit = 0; fit < 2; fit++) z[fit] = home__refine_plain_background(ctx, slot, h, fit);
        printf("     %s, faint texture %.3f: plain regions %d, z %.2f, falloff fitted %.2f\n",
               cases[c].tripod ? "tripod" : "camera moved", cases[c].faint,
               home__refine_plain_regions(ctx, slot), z[0], z[1]);
        if (cases[c].tripod) {
            CHECK(z[1] >= 6.0);
        } else {
            CHECK_LT(z[1], 6.0);
            if (cases[c].faint == 0.0) CHECK(z[0] >= 6.0);
        }
    }
}

void test_trust_region(void)
{
    /* the same start, corners ~3 px from the truth, a 1 px trust region: beyond it the refined
     * H is taken only when it vouches for the whole frame (correlation >= 0.9, 90 % of its
     * points within 3 robust sigmas). As a growing block of B is replaced by an occluder, the
     * correction is first accepted, then refused (HOME's H stays, the pair fails as
     * inconsistent), never accepted without the evidence. */
    home_config cfg;
    home_context *ctx;
    double h[9], h0[9];
    home_result res;
    int k, accepted = 0, refused = 0;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.refine_trust_px = 1.0f;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 8; k++) {
        texture t;
        synth_rng rng;
        const int bw = 64 * k, bh = 180; /* 0 to 35 % of the frame */
        int x, y;
        make_texture(&t, 600);
        synth_seed(&rng, 600);
        synth_corner_homography(&rng, IMG_W, IMG_H, 20, h);
        render_texture(&t, identity, 1.0, 2.5, 1201, img_a);
        render_texture(&t, h, 1.0, 2.5, 1202 + k, img_b);
        for (y = 90; y < 90 + bh; y++)
            for (x = 100; x < 100 + bw; x++)
                img_b[y * IMG_W + x] = (uint8_t)(((x / 12 + y / 9) & 1) ? 230 : 20);
        perturbed(h, 3.0, 61, h0);
        CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W, img_b, IMG_W, h0, &res), HOME_OK);
        printf("    occluder %2d %%: status %s, zncc %.3f, inliers %.2f, error %.3f px\n",
               bw * bh * 100 / (IMG_W * IMG_H), home_refine_status_name(res.refine_status),
               res.refine_zncc, res.refine_inlier_share,
               synth_corner_error(res.H, h, IMG_W, IMG_H));
        if (res.refine_status == HOME_REFINE_ACCEPTED) {
            accepted++;
            CHECK(res.refine_zncc >= 0.9 && res.refine_inlier_share >= 0.9);
            CHECK_LT(synth_corner_error(res.H, h, IMG_W, IMG_H), 0.5);
        } else if (res.refine_status == HOME_REFINE_OUTSIDE_TRUST) {
            refused++;
            CHECK(!res.ok && !res.refined && res.failure == HOME_FAIL_INCONSISTENT);
            CHECK(memcmp(res.H, h0, sizeof h0) == 0);
        }
    }
    CHECK(accepted > 0);
    CHECK(refused > 0);
}

void test_video_equals_pair(void)
{
    /* one pass: a fast pass's features are its own */
    home_config cfg;
    home_context *ctx;
    home_result pair, video;
    double h[9];
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.fast_pass_downscale = 0;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    structured_pair(700, 20, h);
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &pair), HOME_OK);
    CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &fa), HOME_OK);
    CHECK_EQ_INT(home_extract(ctx, img_b, IMG_W, &fb), HOME_OK);
    CHECK_EQ_INT(home_match(ctx, &fa, &fb, &video), HOME_OK);
    CHECK(pair.ok && video.ok && pair.refined && video.refined);
    CHECK(memcmp(pair.H, video.H, sizeof pair.H) == 0);
    /* b is not the newest frame: no snapshot, HOME's IMG_H, not an error */
    CHECK_EQ_INT(home_match(ctx, &fb, &fa, &video), HOME_OK);
    CHECK_EQ_INT(video.refine_status, HOME_REFINE_NO_SNAPSHOT);
    CHECK(!video.refined);
}

/* A kept snapshot (the stabiliser's key frame): frame a registered to b, then to a later c, each
 * extracted once, refines as home_register(a, c) does; without the keep, c's snapshot replaces
 * a's and the refinement has nothing to start from. */
void test_kept_snapshot(void)
{
    static home_features fc;
    static uint8_t img_c[IMG_W * IMG_H];
    home_config cfg;
    home_context *ctx;
    home_result pair, kept;
    double h[9], h_c[9];
    int keep;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.fast_pass_downscale = 0;
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    structured_pair(710, 20, h_c);
    memcpy(img_c, img_b, sizeof img_c);
    {   /* b: the same scene under another motion */
        synth_rng rng;
        synth_seed(&rng, 711);
        synth_corner_homography(&rng, IMG_W, IMG_H, 15, h);
        synth_render(SYNTH_STRUCTURED, 710, h, 2.5, 1423, img_b, IMG_W, IMG_H, IMG_W);
    }
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_c, IMG_W, &pair), HOME_OK);
    CHECK(pair.ok && pair.refined);
    for (keep = 1; keep >= 0; keep--) {
        CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &fa), HOME_OK);
        home__refine_keep(ctx, keep ? fa.frame_id : 0);
        CHECK_EQ_INT(home_extract(ctx, img_b, IMG_W, &fb), HOME_OK);
        CHECK_EQ_INT(home_match(ctx, &fa, &fb, &kept), HOME_OK);
        CHECK(kept.refined);
        CHECK_EQ_INT(home_extract(ctx, img_c, IMG_W, &fc), HOME_OK);
        CHECK_EQ_INT(home_match(ctx, &fa, &fc, &kept), HOME_OK);
        if (keep) {
            CHECK(kept.ok && kept.refined);
            CHECK(memcmp(pair.H, kept.H, sizeof pair.H) == 0);
            CHECK(pair.sigma_px == kept.sigma_px);
        } else {
            CHECK_EQ_INT(kept.refine_status, HOME_REFINE_NO_SNAPSHOT);
        }
    }
    home__refine_keep(ctx, 0);
    CHECK_LT(synth_corner_error(pair.H, h_c, IMG_W, IMG_H), 0.5);
}

void test_refinement_improves_home(void)
{
    /* end to end: HOME then refinement on line-only scenes never loses more than 0.5 px and
     * lands within 0.5 px */
    home_config cfg;
    home_context *ctx;
    int k;
    home_default_config(&cfg, IMG_W, IMG_H);
    for (k = 0; k < 3; k++) {
        double h[9], e_home, e_ref;
        home_result r0, r1;
        structured_pair(800 + k, 10 + 20 * k, h);
        cfg.refine_levels = 0;
        ctx = context(&cfg);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &r0), HOME_OK);
        cfg.refine_levels = 3;
        ctx = context(&cfg);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &r1), HOME_OK);
        e_home = synth_corner_error(r0.H, h, IMG_W, IMG_H);
        e_ref = synth_corner_error(r1.H, h, IMG_W, IMG_H);
        printf("     structured p=%d: HOME %.3f px -> refined %.3f px (%s)\n", 10 + 20 * k, e_home,
               e_ref, r1.refined ? "accepted" : "declined");
        CHECK(r0.ok && r1.ok);
        CHECK_EQ_INT(r0.refine_status, HOME_REFINE_OFF);
        CHECK_LT(e_ref, e_home + 0.5);
        CHECK_LT(e_ref, 0.5);
    }
}

void test_failure_rule_rescue(void)
{
    /* HOME short of inliers (min_inliers above what any pair has) on a good pair: the accepted
     * refinement with a high correlation makes it ok; without refinement it stays a failure */
    home_config cfg;
    home_context *ctx;
    home_result res;
    double h[9];
    synth_rng rng;
    int i;
    home_default_config(&cfg, IMG_W, IMG_H);
    cfg.min_inliers = 2 * HOME_MAX_KEYPOINTS_PER_SIGN;
    structured_pair(900, 20, h);
    ctx = context(&cfg);
    if (!ctx) { CHECK(0); return; }
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
    CHECK(res.ok && res.refined && res.failure == HOME_FAIL_NONE);
    CHECK(res.inliers >= 8 && res.inliers < cfg.min_inliers);
    CHECK(res.refine_zncc >= 0.9);
    CHECK_LT(synth_corner_error(res.H, h, IMG_W, IMG_H), 0.5);
    cfg.refine_levels = 0;
    ctx = context(&cfg);
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
    CHECK(!res.ok && res.failure == HOME_FAIL_FEW_INLIERS);
    /* noise against other noise is never rescued */
    cfg.refine_levels = 3;
    cfg.min_inliers = 20;
    ctx = context(&cfg);
    synth_seed(&rng, 5);
    for (i = 0; i < IMG_W * IMG_H; i++) {
        img_a[i] = (uint8_t)(synth_uniform(&rng) * 256);
        img_b[i] = (uint8_t)(synth_uniform(&rng) * 256);
    }
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
    CHECK(!res.ok && !res.refined);
}

void test_kernels_match_references(void)
{
    /* the scalar reference against plain definitions: downsample = rounded 2x2 mean; warp =
     * the pixel itself at integer shifts; accumulate = the double-precision normal equations */
    const home__refine_kernels *k = home__refine_kernels_for(HOME_SIMD_NONE);
    static uint8_t src[37 * 23], dst[18 * 11];
    static int16_t xs[64], ys[64], gx[64], gy[64];
    static float r[64], w[64], out[64], acc[44 * 4];
    const float m[9] = {1, 0, 2, 0, 1, 3, 0, 0, 1}, aff[3] = {0.01f, -0.3f, -0.2f};
    synth_rng rng;
    int i, j, x, y, bad = 0;
    double ref[44];
    synth_seed(&rng, 77);
    for (i = 0; i < (int)sizeof src; i++) src[i] = (uint8_t)(synth_uniform(&rng) * 256);
    k->downsample(src, 37, dst, 18, 18, 11);
    for (y = 0; y < 11; y++)
        for (x = 0; x < 18; x++) {
            int s = src[2 * y * 37 + 2 * x] + src[2 * y * 37 + 2 * x + 1] +
                    src[(2 * y + 1) * 37 + 2 * x] + src[(2 * y + 1) * 37 + 2 * x + 1];
            bad += dst[y * 18 + x] != (uint8_t)((s + 2) / 4);
        }
    CHECK_EQ_INT(bad, 0);
    for (i = 0; i < 64; i++) {
        xs[i] = (int16_t)(i % 40 - 3);
        ys[i] = (int16_t)(i / 3);
        gx[i] = (int16_t)(synth_uniform(&rng) * 400 - 200);
        gy[i] = (int16_t)(synth_uniform(&rng) * 400 - 200);
        r[i] = (float)(synth_uniform(&rng) * 20 - 10);
        w[i] = (float)synth_uniform(&rng);
    }
    k->warp(m, xs, ys, 64, src, 37, 37, 23, out);
    for (i = 0, bad = 0; i < 64; i++) {
        int px = xs[i] + 2, py = ys[i] + 3;
        float expect = (px >= 0 && py >= 0 && px < 36 && py < 22) ? (float)src[py * 37 + px] : -1.0f;
        bad += out[i] != expect;
    }
    CHECK_EQ_INT(bad, 0);
    k->accumulate(xs, ys, gx, gy, r, w, 64, aff, 1, acc);
    memset(ref, 0, sizeof ref);
    for (i = 0; i < 64; i++) {
        double u = aff[0] * (double)xs[i] + aff[1], v = aff[0] * (double)ys[i] + aff[2], g = gx[i] * u + gy[i] * v;
        double sd[8];
        int q, c = 0;
        sd[0] = gx[i] * u; sd[1] = gx[i] * v; sd[2] = gx[i]; sd[3] = gy[i] * u; sd[4] = gy[i] * v;
        sd[5] = gy[i]; sd[6] = -u * g; sd[7] = -v * g;
        for (j = 0; j < 8; j++) {
            for (q = j; q < 8; q++) ref[c++] += w[i] * sd[j] * sd[q];
            ref[36 + j] += w[i] * sd[j] * r[i];
        }
    }
    for (j = 0, bad = 0; j < 44; j++) {
        double s = (double)acc[j * 4] + acc[j * 4 + 1] + acc[j * 4 + 2] + acc[j * 4 + 3];
        bad += fabs(s - ref[j]) > 1e-4 * (fabs(ref[j]) + 1.0);
    }
    CHECK_EQ_INT(bad, 0);
    /* block maxima: the largest of each group of 2 or 4 */
    {
        static int16_t keys[4 * 37];
        static uint16_t cells[37];
        int b;
        for (i = 0; i < 4 * 37; i++) keys[i] = (int16_t)(synth_uniform(&rng) * 8192);
        for (b = 2; b <= 4; b += 2) {
            k->block_max(keys, 37, b, cells);
            for (i = 0, bad = 0; i < 37; i++) {
                int best = 0, q;
                for (q = 0; q < b; q++) best = keys[b * i + q] > best ? keys[b * i + q] : best;
                bad += cells[i] != best;
            }
            CHECK_EQ_INT(bad, 0);
        }
    }
    /* J^T W r alone (hessian = 0): the same sums, J^T W J left untouched */
    {
        static float grad_only[44 * 4];
        memset(grad_only, 0x7f, sizeof grad_only);
        k->accumulate(xs, ys, gx, gy, r, w, 64, aff, 0, grad_only);
        CHECK(memcmp(grad_only + 36 * 4, acc + 36 * 4, 8 * 4 * sizeof *acc) == 0);
        CHECK(grad_only[0] == grad_only[35 * 4 + 3] && grad_only[0] != acc[0]);
    }
    /* Cauchy fit sums: points past n_valid or with a negative sample or mask do not count */
    {
        static float wt[64], part[20];
        double sums[5] = {0, 0, 0, 0, 0};
        int count = 0, got;
        for (i = 0; i < 64; i++) out[i] = i % 5 == 0 ? -1.0f : (float)(i * 3 % 200);
        got = k->cauchy_sums(out, r, gx, 64, 60, 1.1f, -2.0f, 0.2f, wt, part);
        for (i = 0, bad = 0; i < 64; i++) {
            int ok = i < 60 && out[i] >= 0 && r[i] >= 0;
            double q = (1.1 * out[i] - 2.0 - gx[i]) * 0.2, wi = ok ? 1.0 / (1.0 + q * q) : 0.0;
            bad += fabs(wt[i] - wi) > 1e-6;
            count += ok;
            if (ok) {
                sums[0] += wi; sums[1] += wi * out[i]; sums[2] += wi * gx[i];
                sums[3] += wi * out[i] * out[i]; sums[4] += wi * out[i] * gx[i];
            }
        }
        CHECK_EQ_INT(got, count);
        for (j = 0; j < 5; j++) {
            double s = (double)part[j * 4] + part[j * 4 + 1] + part[j * 4 + 2] + part[j * 4 + 3];
            bad += fabs(s - sums[j]) > 1e-4 * (fabs(sums[j]) + 1.0);
        }
        CHECK_EQ_INT(bad, 0);
    }
}

void test_arena_and_config(void)
{
    home_config cfg, bad;
    size_t with, without;
    home_default_config(&cfg, IMG_W, IMG_H);
    CHECK_EQ_INT(cfg.refine_levels, 3);
    with = home_arena_size(&cfg);
    bad = cfg;
    bad.refine_levels = 0;
    without = home_arena_size(&bad);
    printf("     arena at 640x360: %zu bytes with refinement, %zu without\n", with, without);
    CHECK(with <= (size_t)2 << 20);
    CHECK(with > without);
    bad = cfg; bad.refine_levels = HOME_REFINE_MAX_LEVELS + 1; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.refine_levels = -1; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.refine_iterations = 0; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.refine_trust_px = (float)NAN; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.refine_points = 63; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.refine_points = HOME_REFINE_MAX_POINTS + 1; CHECK_EQ_INT(home_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.refine_levels = 0; bad.refine_iterations = 0; CHECK_EQ_INT(home_validate_config(&bad), HOME_OK);
    /* smallest images still get a usable pyramid */
    CHECK_EQ_INT(home_default_config(&cfg, HOME_MIN_SIDE, HOME_MIN_SIDE), HOME_OK);
    CHECK(home_arena_size(&cfg) > 0);
}

void test_refine_bad_inputs(void)
{
    home_context *ctx = context(NULL);
    home_result res;
    double h[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (!ctx) { CHECK(0); return; }
    memset(img_a, 90, sizeof img_a);
    CHECK_EQ_INT(home_refine(NULL, img_a, IMG_W, img_b, IMG_W, h, &res), HOME_E_NULL);
    CHECK_EQ_INT(home_refine(ctx, NULL, IMG_W, img_b, IMG_W, h, &res), HOME_E_NULL);
    CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W, img_b, IMG_W, NULL, &res), HOME_E_NULL);
    CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W, img_b, IMG_W, h, NULL), HOME_E_NULL);
    CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W - 1, img_b, IMG_W, h, &res), HOME_E_STRIDE);
    h[4] = NAN;
    CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W, img_b, IMG_W, h, &res), HOME_E_CONFIG);
    h[4] = 1; h[8] = 0;
    CHECK_EQ_INT(home_refine(ctx, img_a, IMG_W, img_b, IMG_W, h, &res), HOME_E_CONFIG);
}

#define TEST_LIST(X) \
    X(kernels_match_references) X(arena_and_config) X(region_grid_exact) X(textured_subpixel) X(point_budget) X(finest_level_half) X(lines_subpixel) \
    X(moving_occluder) X(gain_change) X(textureless_declines) X(iteration_cap_keeps_start) X(low_light_converges) X(noisy_refinement_confirms) X(uncertain_lines_confirmed) X(dense_shading) X(dense_still_pairs) X(dense_dim_calibrated) X(dense_lens_shading) X(lens_shading_pans_and_tripods) X(plain_test_fits_lens_falloff) X(few_edges_dim_calibrated) X(capped_few_edges_dim_calibrated) X(capped_few_edges_day_rigid) X(few_edges_dim_rigid_sparse) X(capped_fog_horizon_calibrated) X(capped_fog_rigid_path) \
    X(trust_region) X(video_equals_pair) X(kept_snapshot) X(refinement_improves_home) X(failure_rule_rescue) \
    X(refine_bad_inputs)

#define ENTRY(name) {#name, test_##name},
static const test_case tests[] = {TEST_LIST(ENTRY)};

int main(int argc, char **argv)
{
    return test_run(tests, sizeof tests / sizeof tests[0], "", argc, argv);
}
