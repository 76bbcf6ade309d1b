/* Registration trust: the predicted accuracy against the truth, motion-model selection (a static
 * scene is the identity, a shift a translation, the cap honoured) and the refusal of estimates
 * nothing vouches for. */
#include "test.h"
#include "test_util.h"
#include "synth.h"
#include <math.h>
#include <string.h>

#define IMG_W 640
#define IMG_H 360
static uint8_t img_a[IMG_W * IMG_H], img_b[IMG_W * IMG_H];
static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

static void render(enum synth_kind kind, uint32_t variant, const double *h, uint64_t noise_seed,
                   uint8_t *out)
{
    synth_render(kind, variant, h, 2.5, noise_seed, out, IMG_W, IMG_H, IMG_W);
}

/* Paste a textured block (a moving object) at (x0, y0) of out. */
static void paste_object(uint8_t *out, int x0, int y0, int w, int h, uint32_t seed)
{
    synth_rng rng;
    int x, y;
    synth_seed(&rng, seed);
    for (y = y0; y < y0 + h && y < IMG_H; y++)
        for (x = x0; x < x0 + w && x < IMG_W; x++) {
            const int v = ((x / 9 + y / 7) % 2) * 120 + 60 + (int)(20.0 * synth_uniform(&rng));
            if (x >= 0 && y >= 0) out[y * IMG_W + x] = (uint8_t)v;
        }
}

static home_context *context_for(int video, int max_model)
{
    home_config cfg;
    if (video) home_video_config(&cfg, IMG_W, IMG_H);
    else home_default_config(&cfg, IMG_W, IMG_H);
    cfg.max_model = max_model;
    return test_context(IMG_W, IMG_H, &cfg);
}

/* The same static scene in both frames, new noise, and an object moved across a fifth of the
 * frame: the identity, exactly, with the defaults and the video preset. */
void test_static_scene_is_identity(void)
{
    int video, k;
    for (video = 0; video < 2; video++) {
        home_context *ctx = context_for(video, HOME_MODEL_HOMOGRAPHY);
        int identities = 0;
        if (!ctx) { CHECK(0); return; }
        for (k = 0; k < 4; k++) {
            home_result res;
            double err;
            render(SYNTH_STRUCTURED, 40u + (uint32_t)k, identity, 100u + 2u * (uint64_t)k, img_a);
            render(SYNTH_STRUCTURED, 40u + (uint32_t)k, identity, 101u + 2u * (uint64_t)k, img_b);
            paste_object(img_a, 60 + 40 * k, 90, 200, 130, 7u + (uint32_t)k);
            paste_object(img_b, 72 + 40 * k, 94, 200, 130, 7u + (uint32_t)k);
            CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
            err = synth_corner_error(res.H, identity, IMG_W, IMG_H);
            printf("     %s scene %d: ok %d, model %s, sigma %.3f px, error %.4f px\n",
                   video ? "video" : "defaults", k, res.ok, home_model_name(res.model), res.sigma_px, err);
            CHECK(res.ok);
            identities += res.model == HOME_MODEL_IDENTITY;
            CHECK_LT(err, 0.05);
        }
        /* most frames come back as exactly no motion, not a small drifting one */
        CHECK(identities >= 3);
    }
}

/* A pure shift is a translation (2 parameters), and H has exactly that form. */
void test_shift_is_translation(void)
{
    home_context *ctx = context_for(1, HOME_MODEL_HOMOGRAPHY);
    double h[9] = {1, 0, 3.25, 0, 1, -2.5, 0, 0, 1};
    home_result res;
    if (!ctx) { CHECK(0); return; }
    render(SYNTH_STRUCTURED, 51, identity, 301, img_a);
    render(SYNTH_STRUCTURED, 51, h, 302, img_b);
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
    printf("     model %s, sigma %.3f px, error %.3f px\n", home_model_name(res.model), res.sigma_px,
           synth_corner_error(res.H, h, IMG_W, IMG_H));
    CHECK(res.ok);
    CHECK_EQ_INT(res.model, HOME_MODEL_TRANSLATION);
    CHECK(res.H[0] == 1.0 && res.H[4] == 1.0 && res.H[1] == 0.0 && res.H[3] == 0.0);
    CHECK(res.H[6] == 0.0 && res.H[7] == 0.0);
    CHECK_LT(synth_corner_error(res.H, h, IMG_W, IMG_H), 0.1);
}

/* cfg.max_model caps the model: a homography pair registered with SIMILARITY gives a similarity
 * (h0 = h4, h1 = -h3, no perspective) and never a more general model. */
void test_model_cap(void)
{
    home_context *ctx = context_for(0, HOME_MODEL_SIMILARITY);
    synth_rng rng;
    double h[9];
    home_result res;
    int k;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 3; k++) {
        synth_seed(&rng, 60u + (uint64_t)k);
        synth_corner_homography(&rng, IMG_W, IMG_H, 4.0, h);
        render(SYNTH_STRUCTURED, 60u + (uint32_t)k, identity, 401u + 2u * (uint64_t)k, img_a);
        render(SYNTH_STRUCTURED, 60u + (uint32_t)k, h, 402u + 2u * (uint64_t)k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        printf("     pair %d: ok %d, model %s\n", k, res.ok, home_model_name(res.model));
        CHECK(res.model <= HOME_MODEL_SIMILARITY);
        CHECK(fabs(res.H[0] - res.H[4]) < 1e-9 && fabs(res.H[1] + res.H[3]) < 1e-9);
        CHECK(res.H[6] == 0.0 && res.H[7] == 0.0);
    }
}

/* A camera travelling over a scene changes its perspective between frames. Capped to a
 * similarity (the stabiliser's model), the motion misfits the regions a perspective change moves
 * least, which then prefer the identity: judged against the homography the pixels give, they do
 * not stand still, so the pair is one motion, not two (visp's cube had 17 of 79 pairs refused).
 * The video preset, a 2 px shift with visp cube's change of perspective, scaled to 640 px. */
void test_capped_perspective_is_one_motion(void)
{
    home_context *ctx = context_for(1, HOME_MODEL_SIMILARITY);
    int k, ok = 0;
    if (!ctx) { CHECK(0); return; }
    for (k = 0; k < 4; k++) {
        const double cx = 0.5 * (IMG_W - 1), cy = 0.5 * (IMG_H - 1), f = 384.0 / IMG_W;
        const double p = 1.26e-5 * f, q = -2.2e-5 * f, a = 1.0045, d = 0.9947, b = 0.002;
        double h[9], centre_x, centre_y, got_x, got_y, w;
        home_result res;
        /* about the centre: x' = (A (x - c)) / (1 + p (x - cx) + q (y - cy)) + c + shift */
        h[0] = a + (cx - 1.9) * p; h[1] = b + (cx - 1.9) * q; h[6] = p; h[7] = q;
        h[3] = b + (cy - 0.4) * p; h[4] = d + (cy - 0.4) * q;
        h[2] = (cx - 1.9) * (1.0 - p * cx - q * cy) - a * cx - b * cy;
        h[5] = (cy - 0.4) * (1.0 - p * cx - q * cy) - b * cx - d * cy;
        h[8] = 1.0 - p * cx - q * cy;
        render(SYNTH_STRUCTURED, 70u + (uint32_t)k, identity, 501u + 2u * (uint64_t)k, img_a);
        render(SYNTH_STRUCTURED, 70u + (uint32_t)k, h, 502u + 2u * (uint64_t)k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        w = h[6] * cx + h[7] * cy + h[8];
        centre_x = (h[0] * cx + h[1] * cy + h[2]) / w - cx;
        centre_y = (h[3] * cx + h[4] * cy + h[5]) / w - cy;
        got_x = res.H[0] * cx + res.H[1] * cy + res.H[2] - cx;
        got_y = res.H[3] * cx + res.H[4] * cy + res.H[5] - cy;
        printf("     pair %d: ok %d, model %s, %s; centre moved (%.2f, %.2f) px, answer (%.2f, %.2f)\n",
               k, res.ok, home_model_name(res.model), home_refine_status_name(res.refine_status),
               centre_x, centre_y, got_x, got_y);
        if (!res.ok) continue;
        ok++;
        CHECK(res.model <= HOME_MODEL_SIMILARITY);
        /* a similarity cannot follow the perspective: 0.1-0.3 px off at the centre */
        CHECK_LT(hypot(got_x - centre_x, got_y - centre_y), 0.5);
    }
    CHECK(ok >= 3);
}

/* The predicted error is calibrated on structured and weakly textured pairs of 10..40 px: every
 * ok answer within 3 sigma of the truth (+0.02 px of the truth's own rendering), sigma within
 * max_sigma_px; and so is HOME's line fit alone (no refinement). */
void test_sigma_calibrated(void)
{
    int refine;
    for (refine = 0; refine < 2; refine++) {
        home_config cfg;
        home_context *ctx;
        int k, ok = 0, within = 0;
        double worst_ratio = 0;
        home_default_config(&cfg, IMG_W, IMG_H);
        if (!refine) cfg.refine_levels = 0;
        ctx = test_context(IMG_W, IMG_H, &cfg);
        if (!ctx) { CHECK(0); return; }
        for (k = 0; k < 12; k++) {
            const enum synth_kind kind = k % 2 ? SYNTH_WEAK_TEXTURE : SYNTH_STRUCTURED;
            synth_rng rng;
            double h[9], err;
            home_result res;
            synth_seed(&rng, 700u + (uint64_t)k);
            synth_corner_homography(&rng, IMG_W, IMG_H, 10.0 + 10.0 * (k % 4), h);
            render(kind, 700u + (uint32_t)k, identity, 1401u + 2u * (uint64_t)k, img_a);
            render(kind, 700u + (uint32_t)k, h, 1402u + 2u * (uint64_t)k, img_b);
            CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
            if (!res.ok) continue;
            ok++;
            err = synth_corner_error(res.H, h, IMG_W, IMG_H);
            CHECK(res.sigma_px > 0 && res.sigma_px <= cfg.max_sigma_px);
            within += err <= 3.0 * res.sigma_px + 0.02;
            if (err / res.sigma_px > worst_ratio) worst_ratio = err / res.sigma_px;
        }
        printf("     %s: %d of 12 ok, %d within 3 sigma, worst error / sigma %.2f\n",
               refine ? "refined" : "line fit", ok, within, worst_ratio);
        CHECK(ok >= 10);
        CHECK_EQ_INT(within, ok);
    }
}

/* A frame of three long edges on flat areas leaves a homography undetermined (two lines' worth
 * of constraints short): whatever the model cap, an answer is either refused or right. */
void test_few_edges_never_wrong(void)
{
    static const double lines[3][3] = {{0.93, 0.36, -260}, {-0.2, 0.98, -150}, {0.6, -0.8, 40}};
    double h[9] = {1, 0, 2.0, 0, 1, -1.5, 0, 0, 1};
    int cap;
    for (cap = HOME_MODEL_SIMILARITY; cap <= HOME_MODEL_HOMOGRAPHY; cap += 2) {
        home_context *ctx = context_for(0, cap);
        home_result res;
        int pass;
        if (!ctx) { CHECK(0); return; }
        for (pass = 0; pass < 2; pass++) {
            uint8_t *out = pass ? img_b : img_a;
            synth_rng rng;
            int x, y, k;
            synth_seed(&rng, 900u + (uint64_t)pass);
            for (y = 0; y < IMG_H; y++)
                for (x = 0; x < IMG_W; x++) {
                    /* scene point of output pixel (x, y): h^-1 for B (a pure shift here) */
                    const double sx = pass ? x - h[2] : x, sy = pass ? y - h[5] : y;
                    double v = 100.0;
                    for (k = 0; k < 3; k++)
                        v += 30.0 * (lines[k][0] * sx + lines[k][1] * sy + lines[k][2] > 0);
                    v += 2.5 * synth_gauss(&rng);
                    out[y * IMG_W + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
                }
        }
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        printf("     cap %s: ok %d, model %s, sigma %.3f px, failure %s, error %.3f px\n",
               home_model_name(cap), res.ok, home_model_name(res.model), res.sigma_px,
               home_failure_name(res.failure), synth_corner_error(res.H, h, IMG_W, IMG_H));
        if (res.ok) CHECK_LT(synth_corner_error(res.H, h, IMG_W, IMG_H), 1.0);
        if (cap == HOME_MODEL_HOMOGRAPHY) CHECK(!res.ok || res.model < HOME_MODEL_HOMOGRAPHY);
    }
}

/* Four long edges across flat areas (a door's two sides, a floor line and a diagonal, as in
 * bench/eval's few-edges scenes), antialiased 4x4, noise sigma 2.5, the scene seen under h. */
static void render_four_edges_shaded(const double *h, uint64_t seed, double falloff,
                                     uint8_t *out)
{
    static const double lines[4][3] = {{1.0, 0.0, -200.0}, {0.999, 0.045, -430.0},
                                       {-0.03, 0.9995, -250.0}, {0.6, -0.8, 40.0}};
    static const double step[4] = {-40.0, 35.0, -30.0, 20.0};
    double inv[9];
    synth_rng rng;
    int x, y, i, j, k;
    synth_invert(h, inv);
    synth_seed(&rng, seed);
    for (y = 0; y < IMG_H; y++)
        for (x = 0; x < IMG_W; x++) {
            double v = 0.0;
            for (j = 0; j < 4; j++)
                for (i = 0; i < 4; i++) {
                    const double px = x - 0.375 + 0.25 * i, py = y - 0.375 + 0.25 * j;
                    const double w = inv[6] * px + inv[7] * py + inv[8];
                    const double sx = (inv[0] * px + inv[1] * py + inv[2]) / w;
                    const double sy = (inv[3] * px + inv[4] * py + inv[5]) / w;
                    double g = 90.0;
                    for (k = 0; k < 4; k++)
                        g += step[k] * (lines[k][0] * sx + lines[k][1] * sy + lines[k][2] > 0);
                    v += g / 16.0;
                }
            if (falloff > 0.0) {
                /* a lens falloff fixed to the sensor: 1 - falloff at the corners */
                const double dx = x - 0.5 * (IMG_W - 1), dy = y - 0.5 * (IMG_H - 1);
                v *= 1.0 - falloff * (dx * dx + dy * dy) /
                               (0.25 * ((IMG_W - 1) * (IMG_W - 1) + (IMG_H - 1) * (IMG_H - 1)));
            }
            v += 2.5 * synth_gauss(&rng);
            out[y * IMG_W + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
        }
}

static void render_four_edges(const double *h, uint64_t seed, uint8_t *out)
{
    render_four_edges_shaded(h, seed, 0.0, out);
}

/* Registers img_a to img_b (true motion h): 1 when ok, which a similarity (or a simpler model)
 * must be, right within 3 sigma; *err its corner error. */
static int stand_in_frame(home_context *ctx, int k, const double *h, double *err)
{
    home_result res;
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
    *err = synth_corner_error(res.H, h, IMG_W, IMG_H);
    printf("     frame %d: ok %d, model %s, status %s, sigma %.3f px, error %.3f px\n", k, res.ok,
           home_model_name(res.model), home_refine_status_name(res.refine_status), res.sigma_px,
           *err);
    if (!res.ok) return 0;
    CHECK(res.model <= HOME_MODEL_AFFINE);
    CHECK_LT(*err, 3.0 * res.sigma_px);
    return 1;
}

/* Consecutive frames of four long edges: a similarity stands in for the homography they do not
 * determine (the defaults refused all five before), right within 3 sigma; still pairs of the
 * same scene, whose 30 px perspective no similarity holds, are refused or right. */
void test_few_edges_similarity_stands_in(void)
{
    home_context *ctx = context_for(0, HOME_MODEL_HOMOGRAPHY);
    int k, ok = 0;
    if (!ctx) { CHECK(0); return; }
    render_four_edges(identity, 950u, img_a);
    for (k = 0; k < 5; k++) {
        const double angle = (0.1 + 0.05 * k) * 3.14159265358979 / 180.0, scale = 1.0 + 0.001 * k;
        const double c = scale * cos(angle), s = scale * sin(angle);
        const double h[9] = {c, -s, 3.0 - 0.5 * k, s, c, -2.0 + 0.4 * k, 0, 0, 1};
        double err;
        render_four_edges(h, 951u + (uint64_t)k, img_b);
        if (!stand_in_frame(ctx, k, h, &err)) continue;
        ok++;
        CHECK_LT(err, 0.3);
    }
    CHECK(ok >= 4);
    for (k = 0; k < 3; k++) {
        double h[9];
        home_result res;
        synth_rng rng;
        synth_seed(&rng, 960u + (uint64_t)k);
        synth_corner_homography(&rng, IMG_W, IMG_H, 30.0, h);
        render_four_edges(h, 961u + (uint64_t)k, img_b);
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        printf("     still pair %d: ok %d, model %s, status %s, error %.3f px\n", k, res.ok,
               home_model_name(res.model), home_refine_status_name(res.refine_status),
               synth_corner_error(res.H, h, IMG_W, IMG_H));
        if (res.ok) CHECK_LT(synth_corner_error(res.H, h, IMG_W, IMG_H), 2.0);
    }
}

/* Eight consecutive frames of the four edges (2-3 px of similarity motion) through a lens
 * falloff (0: none), with the video preset: how many are ok (each checked by stand_in_frame). */
static int four_edges_video_frames(double falloff)
{
    home_context *ctx = context_for(1, HOME_MODEL_HOMOGRAPHY);
    int k, ok = 0;
    if (!ctx) { CHECK(0); return 0; }
    for (k = 0; k < 8; k++) {
        const double angle = (0.1 + 0.05 * (k % 4)) * 3.14159265358979 / 180.0;
        const double scale = 1.0 + 0.001 * (k % 3), c = scale * cos(angle), s = scale * sin(angle);
        const double h[9] = {c, -s, 3.0 - 0.7 * k, s, c, -2.5 + 0.6 * k, 0, 0, 1};
        double err;
        render_four_edges_shaded(identity, 970u + 2u * (uint64_t)k, falloff, img_a);
        render_four_edges_shaded(h, 971u + 2u * (uint64_t)k, falloff, img_b);
        ok += stand_in_frame(ctx, k, h, &err);
    }
    return ok;
}

/* With the video preset the template ends at half size: there the four edges fill fewer points
 * than faint texture would need (FINEST_MIN_POINTS), yet the stand-in may end there (0 of 8 ok
 * before, docs/trust.md session 34); every ok answer right within 3 sigma. */
void test_few_edges_half_size_stand_ins(void)
{
    CHECK(four_edges_video_frames(0.0) >= 5);
}

/* The same frames through a lens whose light falls off by 15 % at the corners (fixed to the
 * sensor): the falloff stands still on the plain areas, which then show no motion, and the
 * background's test refused most stand-ins (3 of 8 ok, docs/trust.md session 34); with the
 * falloff fitted they stand, every ok answer right within 3 sigma. */
void test_few_edges_lens_shading_stand_ins(void)
{
    CHECK(four_edges_video_frames(0.15) >= 6);
}

/* A picket fence filling the frame (bench/eval/scenes.py's: pickets every 34 px, two rails
 * across), seen under a homography: an alignment one picket further on fits nearly as well, so
 * an answer is either right or refused (HOME_REFINE_PERIODIC where the alias was found), with
 * both presets. */
static double fence(double x, double y)
{
    const double period = 34.0;
    const int picket = x - period * floor(x / period) < 0.55 * period;
    const int rail = fabs(y - 0.35 * IMG_H) < 8.0 || fabs(y - 0.62 * IMG_H) < 8.0;
    return picket || rail ? 190.0 : 85.0;
}

/* Pairs of pattern under homographies with corners moved by 30-60 px, both presets: how many
 * answers are ok but more than 2 px off, and how many were refused as periodic. */
static void count_aliased(double (*pattern)(double, double), uint64_t seed, int *wrong,
                          int *periodic)
{
    int k, video;
    *wrong = *periodic = 0;
    for (video = 0; video < 2; video++) {
        home_context *ctx = context_for(video, HOME_MODEL_HOMOGRAPHY);
        if (!ctx) { CHECK(0); return; }
        for (k = 0; k < 8; k++) {
            double h[9], inv[9], err;
            home_result res;
            synth_rng rng;
            int pass, x, y, i;
            synth_seed(&rng, seed + (uint64_t)k);
            synth_corner_homography(&rng, IMG_W, IMG_H, 30.0 + 10.0 * (k % 4), h);
            synth_invert(h, inv);
            for (pass = 0; pass < 2; pass++) {
                uint8_t *out = pass ? img_b : img_a;
                for (y = 0; y < IMG_H; y++)
                    for (x = 0; x < IMG_W; x++) {
                        /* the pattern at the scene points of output pixel (x, y), 2x2 samples */
                        double val = 0.0;
                        for (i = 0; i < 4; i++) {
                            double u = x - 0.25 + 0.5 * (i & 1), v = y - 0.25 + 0.5 * (i >> 1);
                            if (pass) synth_apply(inv, u, v, &u, &v);
                            val += 0.25 * pattern(u, v);
                        }
                        val += 2.5 * synth_gauss(&rng);
                        out[y * IMG_W + x] = (uint8_t)(val < 0 ? 0 : val > 255 ? 255 : val + 0.5);
                    }
            }
            CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
            err = synth_corner_error(res.H, h, IMG_W, IMG_H);
            printf("     %s, pair %d: ok %d, refine %s, sigma %.2f px, error %.2f px\n",
                   video ? "video" : "defaults", k, res.ok,
                   home_refine_status_name(res.refine_status), res.sigma_px, err);
            *wrong += res.ok && err > 2.0;
            *periodic += res.refine_status == HOME_REFINE_PERIODIC;
        }
    }
}

void test_fence_never_aliased(void)
{
    int wrong, periodic;
    count_aliased(fence, 1200u, &wrong, &periodic);
    CHECK_EQ_INT(wrong, 0);
    CHECK(periodic >= 1);
}

/* A pegboard: dark holes 46 px apart across and 31 px down (bench/eval/scenes.py's lattice, a
 * tuning scene), all alike. Along its dominant gradient direction its profile repeats with no
 * translation of the board behind it; along the rows and columns it does: an answer one hole
 * off is refused. */
static double pegboard(double x, double y)
{
    const double px = 46.0, py = 31.0, r = 5.5;
    const double dx = x - px * floor(x / px) - 0.5 * px, dy = y - py * floor(y / py) - 0.5 * py;
    return dx * dx + dy * dy < r * r ? 40.0 : 185.0;
}

void test_pegboard_never_aliased(void)
{
    int wrong, periodic;
    count_aliased(pegboard, 1300u, &wrong, &periodic);
    CHECK_EQ_INT(wrong, 0);
    CHECK(periodic >= 1);
}

/* The mover tests' four configurations: bit 0 the video preset, 2 and 3 capped at a
 * similarity. */
static home_context *mover_context(int config)
{
    return context_for(config & 1, config < 2 ? HOME_MODEL_HOMOGRAPHY : HOME_MODEL_SIMILARITY);
}

/* A turn by angle about (ox, oy) and a (dx, dy) px shift. */
static void turn_and_shift(double angle, double ox, double oy, double dx, double dy, double *h)
{
    const double c = cos(angle), s = sin(angle);
    const double m[9] = {c, -s, ox - c * ox + s * oy + dx, s, c, oy - s * ox - c * oy + dy,
                         0, 0, 1};
    memcpy(h, m, sizeof m);
}

static void print_mover_result(int config, const home_result *res, double err)
{
    printf("     %s, cap %s: ok %d, model %s, failure %s, refine %s, error %.3f px\n",
           config & 1 ? "video" : "defaults", config < 2 ? "homography" : "similarity", res->ok,
           home_model_name(res->model), home_failure_name(res->failure),
           home_refine_status_name(res->refine_status), err);
}

/* A static camera over a plain background with a few faint long edges, and a structured object
 * (a quarter of the frame, strong edges) moving and turning across it: the object draws HOME's
 * lines and the refinement's template to itself, yet the answer is never its motion. Either the
 * identity, or not ok. */
void test_textured_mover_never_steers(void)
{
    static const double lines[4][3] = {
        {0.93, 0.36, -260}, {-0.2, 0.98, -150}, {0.6, -0.8, 40}, {0.1, 0.99, -300}};
    static uint8_t object[IMG_W * IMG_H];
    const double ox = 420.0, oy = 190.0, dx = 5.0, dy = 2.0;
    double h_obj[9];
    int config, identities = 0;
    /* the object's motion: a 0.02 rad turn about its centre and a (5, 2) px shift */
    turn_and_shift(0.02, ox, oy, dx, dy, h_obj);
    for (config = 0; config < 4; config++) {
        home_context *ctx = mover_context(config);
        home_result res;
        int pass;
        double err;
        if (!ctx) { CHECK(0); return; }
        for (pass = 0; pass < 2; pass++) {
            uint8_t *out = pass ? img_b : img_a;
            synth_rng rng;
            int x, y, k;
            render(SYNTH_STRUCTURED, 70u + (uint32_t)config, pass ? h_obj : identity,
                   960u + (uint64_t)(2 * config + pass), object);
            synth_seed(&rng, 950u + (uint64_t)(2 * config + pass));
            for (y = 0; y < IMG_H; y++)
                for (x = 0; x < IMG_W; x++) {
                    /* inside the moved window: the object (window moved with its centre) */
                    const double wx = x - (pass ? dx : 0.0) - ox, wy = y - (pass ? dy : 0.0) - oy;
                    double v = 90.0;
                    if (fabs(wx) < 150.0 && fabs(wy) < 100.0) {
                        out[y * IMG_W + x] = object[y * IMG_W + x];
                        continue;
                    }
                    for (k = 0; k < 4; k++)
                        v += 12.0 * (lines[k][0] * x + lines[k][1] * y + lines[k][2] > 0);
                    v += 2.5 * synth_gauss(&rng);
                    out[y * IMG_W + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
                }
        }
        CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, &res), HOME_OK);
        err = synth_corner_error(res.H, identity, IMG_W, IMG_H);
        print_mover_result(config, &res, err);
        if (res.ok) CHECK_LT(err, 0.05);
        identities += res.ok && res.model == HOME_MODEL_IDENTITY;
    }
    /* and where it answers, the static background decides */
    CHECK(identities >= 1);
}

/* A static camera on a horizon in fog with a structured object over a fifth of the frame,
 * moving (6, 3) px and turning 0.03 rad in B; noise of shared_sigma the same in both frames (as
 * in the blocks an encoder leaves unchanged), of own_sigma new in each. Registered with the
 * mover configuration config into res: never the object's motion as ok. 0 if no context. */
static int register_fog_mover(int config, double shared_sigma, double own_sigma,
                              home_result *res)
{
    static uint8_t object[IMG_W * IMG_H];
    const double ox = 470.0, oy = 110.0, dx = 6.0, dy = 3.0;
    home_context *ctx = mover_context(config);
    double h_obj[9];
    int pass;
    if (!ctx) return 0;
    turn_and_shift(0.03, ox, oy, dx, dy, h_obj);
    for (pass = 0; pass < 2; pass++) {
        uint8_t *out = pass ? img_b : img_a;
        synth_rng shared, own;
        int x, y;
        render(SYNTH_STRUCTURED, 80u + (uint32_t)config, pass ? h_obj : identity,
               980u + (uint64_t)(2 * config + pass), object);
        synth_seed(&shared, 990u + (uint64_t)config);
        synth_seed(&own, 1990u + (uint64_t)(2 * config + pass));
        for (y = 0; y < IMG_H; y++)
            for (x = 0; x < IMG_W; x++) {
                const double wx = x - (pass ? dx : 0.0) - ox, wy = y - (pass ? dy : 0.0) - oy;
                const double ridge = 200.0 + 0.05 * x + 14.0 * sin(x / 57.0) +
                                     6.0 * sin(x / 23.0 + 1.0);
                /* sky brightening upwards, land 8 grey levels darker, a soft ridge */
                double v = 170.0 + 0.03 * (ridge - y) - 8.0 / (1.0 + exp(-(y - ridge) / 2.0)) +
                           shared_sigma * synth_gauss(&shared) + own_sigma * synth_gauss(&own);
                if (fabs(wx) < 130.0 && fabs(wy) < 90.0) v = object[y * IMG_W + x];
                out[y * IMG_W + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
            }
    }
    CHECK_EQ_INT(home_register(ctx, img_a, IMG_W, img_b, IMG_W, res), HOME_OK);
    print_mover_result(config, res, synth_corner_error(res->H, identity, IMG_W, IMG_H));
    if (res->ok) CHECK_EQ_INT(res->model, HOME_MODEL_IDENTITY);
    return 1;
}

/* Every textured region is the object's, and the fog's are too faint for a clear vote of their
 * own. Part of the background's noise is the same in both frames, part is new, so the fog leans
 * to the identity everywhere and decides nowhere alone; all its pixels together do: the
 * identity with both presets when the model is capped at a similarity. */
void test_static_fog_is_identity(void)
{
    int config, identities = 0;
    for (config = 0; config < 4; config++) {
        home_result res;
        if (!register_fog_mover(config, 2.5, 2.0, &res)) { CHECK(0); return; }
        identities += res.ok && res.model == HOME_MODEL_IDENTITY;
    }
    CHECK(identities >= 2);
}

/* The same with a live camera's raw frames: all the noise new in each. Two frames hold too
 * little evidence to call the scene static, but the fog would show the object's motion and
 * does not: never that motion as ok, with any preset (the video preset capped at a similarity
 * returned it, 6.5 px off, before the still-background test). */
void test_raw_fog_never_moves(void)
{
    int config, refused = 0;
    for (config = 0; config < 4; config++) {
        home_result res;
        if (!register_fog_mover(config, 0.0, 2.0, &res)) { CHECK(0); return; }
        refused += res.refine_status == HOME_REFINE_STILL_BACKGROUND;
    }
    /* the rules before it refuse the others; this one is the still-background test's */
    CHECK(refused >= 1);
}
