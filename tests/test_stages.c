/* Per-stage tests against known truth. */
#include "test.h"
#include "test_util.h"
#include "home_internal.h"
#include "synth.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define IMG_W 320
#define IMG_H 180
static uint8_t img_a[IMG_W * IMG_H], img_b[IMG_W * IMG_H];
static home_features feat_a, feat_b;

void test_config_defaults(void)
{
    home_config cfg;
    CHECK_EQ_INT(home_default_config(&cfg, 640, 360), HOME_OK);
    CHECK_EQ_INT(cfg.theta_bins, 480);
    CHECK_EQ_INT(cfg.keypoints_per_sign, 1000);
    CHECK(fabsf(cfg.smooth_sigma - 1.3f) < 1e-6f);
    CHECK(fabsf(cfg.threshold_final - 1.0f) < 1e-6f);
    CHECK_EQ_INT(cfg.min_inliers, 20);
    CHECK_EQ_INT(home_validate_config(&cfg), HOME_OK);
    /* r axis covers the half diagonal (366.5 px at 640x360) at 1 px per bin, and is even */
    CHECK_EQ_INT(home__r_bins(&cfg), 2 * 368);
}

void test_arena_layout(void)
{
    home_config cfg;
    static union { unsigned char b[(4u << 20) + 64]; double d; } storage;
    unsigned char *mem = (unsigned char *)(((uintptr_t)storage.b + 63) & ~(uintptr_t)63);
    home_context *ctx;
    size_t need, got = 0;
    home_default_config(&cfg, 640, 360);
    need = home_arena_size(&cfg);
    CHECK(need > 0);
    CHECK(need <= (size_t)2 << 20);                          /* <= 2 MiB at 640x360 */
    CHECK_EQ_INT(home_init(&ctx, &cfg, mem, need - 1, &got), HOME_E_ARENA_SMALL);
    CHECK_EQ_INT(got, need);
    CHECK_EQ_INT(home_init(&ctx, &cfg, mem + 1, need, NULL), HOME_E_ARENA_ALIGN);
    /* the context stays inside exactly `need` bytes: a canary right after it survives use */
    mem[need] = 0xA5;
    CHECK_EQ_INT(home_init(&ctx, &cfg, mem, need, NULL), HOME_OK);
    {
        static uint8_t a[640 * 360];
        home_result res;
        synth_render(SYNTH_STRUCTURED, 3, (const double[9]){1, 0, 0, 0, 1, 0, 0, 0, 1}, 2.5, 9, a, 640, 360, 640);
        CHECK_EQ_INT(home_register(ctx, a, 640, a, 640, &res), HOME_OK);
    }
    CHECK_EQ_INT(mem[need], 0xA5);
}

/* The per-context theta geometry (home_video_config at 640x360 caches it) gives the features
 * computing it per frame gives, bit for bit, and extraction leaves the cache intact. */
void test_hough_geometry_cache(void)
{
    static union { unsigned char b[(2u << 20) + 64]; double d; } storage;
    static uint8_t a[640 * 360];
    static home_features cached, per_frame;
    static int16_t shift[4096], row_lo[256], row_hi[256], res_k[4 * 4096], entry[2 * 4096 + 8], after[2 * 4096 + 8];
    static float res_f[4 * 4096];
    unsigned char *mem = (unsigned char *)(((uintptr_t)storage.b + 63) & ~(uintptr_t)63);
    home__theta_geom fresh, *geom;
    home_config cfg;
    home_context *ctx;
    int k, first, rows, bad = 0;
    home_video_config(&cfg, 640, 360);
    CHECK(home_arena_size(&cfg) <= sizeof storage.b - 64);
    CHECK_EQ_INT(home_init(&ctx, &cfg, mem, sizeof storage.b - 64, NULL), HOME_OK);
    CHECK(ctx->geom != NULL);
    if (!ctx->geom) return;
    synth_render(SYNTH_STRUCTURED, 4, (const double[9]){1, 0, 0, 0, 1, 0, 0, 0, 1}, 2.5, 9, a, 640, 360, 640);
    CHECK_EQ_INT(home_extract(ctx, a, 640, &cached), HOME_OK);
    /* the cache still holds what home__theta_geometry computes */
    fresh.shift = shift; fresh.row_lo = row_lo; fresh.row_hi = row_hi;
    fresh.res_k = res_k; fresh.res_f = res_f; fresh.entry = entry; fresh.after = after;
    home__hough_raw_rows(&ctx->cfg, ctx->smooth_radius, &first, &rows);
    for (k = 0; k < rows; k++) {
        const home__theta_geom *g = &ctx->geom[k];
        const int n_rows = g->vertical ? ctx->hough_h : ctx->hough_w, n_res = g->i_hi - g->i_lo;
        home__theta_geometry(ctx, (first + k) * HOME__PI / cfg.theta_bins, &fresh);
        bad += fresh.vertical != g->vertical || fresh.flip != g->flip || fresh.s_min != g->s_min ||
               fresh.s_max != g->s_max || fresh.j0 != g->j0 || fresh.n != g->n ||
               fresh.n_blocks != g->n_blocks || fresh.i_lo != g->i_lo || fresh.i_hi != g->i_hi ||
               fresh.d_scale != g->d_scale || fresh.end_scale != g->end_scale;
        bad += memcmp(fresh.shift, g->shift, (size_t)n_rows * sizeof *shift) != 0;
        bad += memcmp(fresh.row_lo, g->row_lo, (size_t)g->n_blocks * sizeof *row_lo) != 0;
        bad += memcmp(fresh.row_hi, g->row_hi, (size_t)g->n_blocks * sizeof *row_hi) != 0;
        bad += memcmp(fresh.res_k, g->res_k, (size_t)n_res * sizeof *res_k) != 0;
        bad += memcmp(fresh.entry, g->entry, (size_t)g->n * sizeof *entry) != 0;
        bad += memcmp(fresh.after, g->after, (size_t)g->n * sizeof *after) != 0;
        bad += memcmp(fresh.res_f, g->res_f, (size_t)n_res * sizeof *res_f) != 0;
    }
    CHECK_EQ_INT(bad, 0);
    /* the same context computing the geometry per frame into scratch arrays */
    geom = ctx->geom;
    ctx->geom = NULL;
    ctx->geom_rows = 0;
    ctx->geom_scratch = fresh;
    CHECK_EQ_INT(home_extract(ctx, a, 640, &per_frame), HOME_OK);
    ctx->geom = geom;
    ctx->geom_rows = rows;
    CHECK_EQ_INT(per_frame.n_pos + per_frame.n_neg, cached.n_pos + cached.n_neg);
    CHECK(per_frame.n_pos > 50);
    CHECK(memcmp(per_frame.kp, cached.kp, (size_t)(cached.n_pos + cached.n_neg) * sizeof *cached.kp) == 0);
    /* the defaults' full-size transform needs more than the budget: computed per frame; the
     * fast pass's rows (240 theta bins of a 160 x 90 image) are cached where they fit, in the
     * configured pass's image buffers, and computed anew after the configured pass ran */
    home_default_config(&cfg, 640, 360);
    CHECK_EQ_INT(home_init(&ctx, &cfg, mem, sizeof storage.b - 64, NULL), HOME_OK);
    CHECK(ctx->geom == NULL && ctx->geom_rows == 0);
    home__hough_raw_rows(&ctx->passes[1].cfg, ctx->smooth_radius, &first, &rows);
    CHECK(ctx->passes[1].geom_borrowed && ctx->passes[1].geom_rows > rows / 2);
    {
        static uint8_t b[640 * 360];
        home_result before, after;
        double h[9];
        synth_rng rng;
        synth_seed(&rng, 4);
        synth_corner_homography(&rng, 640, 360, 12, h);
        synth_render(SYNTH_STRUCTURED, 4, h, 2.5, 10, b, 640, 360, 640);
        CHECK_EQ_INT(home_register(ctx, a, 640, b, 640, &before), HOME_OK);
        CHECK_EQ_INT(home_extract(ctx, a, 640, &per_frame), HOME_OK); /* the configured pass */
        CHECK_EQ_INT(home_register(ctx, a, 640, b, 640, &after), HOME_OK);
        CHECK(before.ok && before.fast_pass && after.fast_pass);
        CHECK(memcmp(before.H, after.H, sizeof before.H) == 0);
    }
    home__select_pass(ctx, 1);
    for (k = 0, bad = 0; k < ctx->geom_rows; k++) {
        const home__theta_geom *g = &ctx->geom[k];
        home__theta_geometry(ctx, (first + k) * HOME__PI / ctx->cfg.theta_bins, &fresh);
        bad += fresh.n != g->n || fresh.i_hi != g->i_hi || fresh.d_scale != g->d_scale ||
               memcmp(fresh.entry, g->entry, (size_t)g->n * sizeof *entry) != 0 ||
               memcmp(fresh.res_f, g->res_f, (size_t)(g->i_hi - g->i_lo) * sizeof *res_f) != 0;
    }
    home__select_pass(ctx, 0);
    CHECK_EQ_INT(bad, 0);
}

void test_heap_keeps_top_k(void)
{
    static home__candidate store[37];
    static home__heap_entry entries[37];
    home__heap heap;
    float saliency[500];
    int i, k;
    synth_rng rng;
    synth_seed(&rng, 5);
    home__heap_init(&heap, entries, store, 37);
    for (i = 0; i < 500; i++) {
        home__candidate c;
        memset(&c, 0, sizeof c);
        saliency[i] = (float)floor(synth_uniform(&rng) * 300); /* many ties */
        c.saliency = saliency[i];
        c.order = (uint32_t)i;
        c.theta_bin = (float)i;
        if (home__heap_would_accept(&heap, c.saliency, c.order)) home__heap_push(&heap, &c);
    }
    CHECK_EQ_INT(home__heap_sort_desc(&heap), 37);
    /* exactly the 37 best by (saliency desc, order asc), in that order */
    for (k = 0; k < 37; k++) {
        int best = -1;
        for (i = 0; i < 500; i++)
            if (saliency[i] >= 0 && (best < 0 || saliency[i] > saliency[best])) best = i;
        CHECK_EQ_INT((int)store[entries[k].slot].theta_bin, best);
        saliency[best] = -1;
    }
}

/* A single straight step edge: bright side where xc cos(t) + yc sin(t) > r. */
static void render_edge(uint8_t *img, double theta, double r, double contrast)
{
    int x, y;
    for (y = 0; y < IMG_H; y++)
        for (x = 0; x < IMG_W; x++) {
            double d = (x - 0.5 * (IMG_W - 1)) * cos(theta) + (y - 0.5 * (IMG_H - 1)) * sin(theta) - r;
            double v = 100 + contrast / (1 + exp(-d / 0.7));
            img[y * IMG_W + x] = (uint8_t)floor(v + 0.5);
        }
}

void test_hough_edge_extremum(void)
{
    static const double cases[][3] = {{0.7, 12.0, 60}, {2.2, -30.5, -60}, {1.5708, 20.25, 50}};
    size_t c;
    home_context *ctx = test_context(IMG_W, IMG_H, NULL);
    CHECK(ctx != NULL);
    if (!ctx) return;
    for (c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        double theta = cases[c][0], r = cases[c][1], contrast = cases[c][2];
        const home_keypoint *kp;
        render_edge(img_a, theta, r, contrast);
        CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &feat_a), HOME_OK);
        /* the strongest extremum is the edge, with the sign of the contrast along n(theta) */
        kp = contrast > 0 ? &feat_a.kp[0] : &feat_a.kp[feat_a.n_pos];
        CHECK(contrast > 0 ? feat_a.n_pos > 0 : feat_a.n_neg > 0);
        CHECK_EQ_INT(kp->sign, contrast > 0 ? 1 : -1);
        CHECK_LT(fabs(kp->theta - theta), 0.2 * HOME__PI / 480);
        CHECK_LT(fabs(kp->r - r), 0.15);
        /* and it dominates: no other keypoint of that sign is half as salient */
        CHECK_LT(kp[1].saliency, 0.5 * kp->saliency);
    }
}

void test_hough_wrap_symmetry(void)
{
    /* a vertical edge sits at the theta wrap: theta ~ 0 with r, or theta ~ pi with -r and the
     * opposite sign. It must be found once, flagged for the alternate form. */
    home_context *ctx = test_context(IMG_W, IMG_H, NULL);
    const home_keypoint *kp;
    if (!ctx) { CHECK(0); return; }
    render_edge(img_a, 0.004, 25.0, 60);
    CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &feat_a), HOME_OK);
    kp = &feat_a.kp[0];
    CHECK(feat_a.n_pos > 0 && kp->has_alt);
    CHECK_LT(fabs(kp->theta - 0.004), 0.002);
    CHECK_LT(fabs(kp->r - 25.0), 0.2);
    /* alternate descriptor is the primary reversed and mirrored around 128 */
    CHECK_LT(abs((int)kp->alt_desc[0] - (256 - kp->desc[15])), 2);
    CHECK_LT(abs((int)kp->alt_desc[7] - (256 - kp->desc[8])), 2);
}

static double rotate_translate(double *h, double angle, double tx, double ty)
{
    double cx = 0.5 * (IMG_W - 1), cy = 0.5 * (IMG_H - 1), c = cos(angle), s = sin(angle);
    h[0] = c; h[1] = -s; h[2] = cx - c * cx + s * cy + tx;
    h[3] = s; h[4] = c; h[5] = cy - s * cx - c * cy + ty;
    h[6] = h[7] = 0; h[8] = 1;
    return 0;
}

/* Parallel bars of different widths and contrasts inside a soft disc, seen through h: the
 * whole pattern stays inside the frame under small motions, so its radial Hough profile must
 * be unchanged by rotation and translation. */
static void render_bars(uint8_t *img, const double *h)
{
    static const double edges[][2] = {{-40, 35}, {-28, -20}, {-12, 45}, {-4, -45}, {10, 30}, {26, -30}};
    double inv[9];
    int x, y;
    size_t k;
    synth_invert(h, inv);
    for (y = 0; y < IMG_H; y++)
        for (x = 0; x < IMG_W; x++) {
            double sx, sy, u, v = 0.0, rho;
            synth_apply(inv, x, y, &sx, &sy);
            sx -= 0.5 * (IMG_W - 1);
            sy -= 0.5 * (IMG_H - 1);
            u = sx * cos(0.6) + sy * sin(0.6);     /* bars run across direction 0.6 rad */
            for (k = 0; k < sizeof edges / sizeof edges[0]; k++)
                v += edges[k][1] / (1 + exp(-(u - edges[k][0]) / 0.7));
            rho = sqrt(sx * sx + sy * sy);
            v = 100 + v / (1 + exp((rho - 70) / 2.0));
            img[y * IMG_W + x] = (uint8_t)floor(v + 0.5);
        }
}

void test_descriptor_invariance(void)
{
    static const double motions[][3] = {{0.0, 7.3, -4.1}, {0.15, 3.0, 5.0}, {-0.3, -6.0, 2.5}, {1.0, 0, 0}};
    home_context *ctx = test_context(IMG_W, IMG_H, NULL);
    size_t m;
    double ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (!ctx) { CHECK(0); return; }
    render_bars(img_a, ident);
    CHECK_EQ_INT(home_extract(ctx, img_a, IMG_W, &feat_a), HOME_OK);
    for (m = 0; m < sizeof motions / sizeof motions[0]; m++) {
        double h[9];
        int i, j, compared = 0, worst = 0;
        rotate_translate(h, motions[m][0], motions[m][1], motions[m][2]);
        render_bars(img_b, h);
        CHECK_EQ_INT(home_extract(ctx, img_b, IMG_W, &feat_b), HOME_OK);
        /* the six most salient keypoints of each sign are the bar edges; each must reappear
         * at the mapped (theta, r) with a descriptor within 2 grey levels per value */
        for (i = 0; i < feat_a.n_pos + feat_a.n_neg; i++) {
            const home_keypoint *ka = &feat_a.kp[i];
            double tb, rb, best = 1e9;
            int jb = -1, k, sad = 0;
            if ((ka->sign > 0 ? i : i - feat_a.n_pos) >= 3) continue;
            test_map_line(h, IMG_W, IMG_H, ka->theta, ka->r, &tb, &rb);
            for (j = 0; j < feat_b.n_pos + feat_b.n_neg; j++) {
                double d = fabs(feat_b.kp[j].theta - tb) * 480 / HOME__PI + fabs(feat_b.kp[j].r - rb);
                if (feat_b.kp[j].sign == ka->sign && d < best) best = d, jb = j;
            }
            CHECK_LT(best, 0.75); /* theta bins + r px */
            if (jb < 0) continue;
            for (k = 0; k < HOME_DESC_LEN; k++) sad += abs(ka->desc[k] - feat_b.kp[jb].desc[k]);
            if (sad > worst) worst = sad;
            compared++;
        }
        CHECK_EQ_INT(compared, 6);
        CHECK(worst <= 2 * HOME_DESC_LEN);
        printf("     motion %d: worst descriptor SAD %d over %d bar edges\n", (int)m, worst, compared);
    }
}

/* Matches from exact line correspondences of pixel homography h. */
static int exact_matches(home_context *ctx, const double *h, int n, double outlier_share,
                         double noise, synth_rng *rng)
{
    int i;
    for (i = 0; i < n; i++) {
        double theta = HOME__PI * synth_uniform(rng), r = 150 * (synth_uniform(rng) - 0.5);
        double tb, rb;
        test_map_line(h, IMG_W, IMG_H, theta, r, &tb, &rb);
        if (synth_uniform(rng) < outlier_share) {
            tb = HOME__PI * synth_uniform(rng);
            rb = 150 * (synth_uniform(rng) - 0.5);
        } else {
            tb += noise * synth_gauss(rng) * HOME__PI / 480;
            rb += noise * synth_gauss(rng);
        }
        home__match_set(&ctx->matches[i], (float)theta, (float)r, (float)tb, (float)rb);
    }
    return n;
}

/* The plausibility rule for an estimate (both HOME's and the refined one): real motions pass;
 * a flip, a corner behind the camera and a frame squeezed to a line do not. The last
 * is the H the refinement once returned for a fuzzed pair (det -3.5e-18). */
void test_homography_plausible(void)
{
    const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const double zoom_out[9] = {0.05, 0, 300, 0, 0.05, 170, 0, 0, 1};
    const double keystone[9] = {1.02, 0.03, -9, -0.02, 0.98, 6, 2e-4, -1e-4, 1};
    const double mirror[9] = {-1, 0, 639, 0, 1, 0, 0, 0, 1};
    const double behind[9] = {1, 0, 0, 0, 1, 0, -0.002, 0, 1};          /* w < 0 at x = 639 */
    const double steep[9] = {1, 0, 0, 0, 1, 0, -0.0015, 0, 1};          /* w = 0.04 at x = 639 */
    const double sliver[9] = {0.15883520771283627, 0.21936185211168963, 50.458401863441843,
                              0.16610942426617356, 0.21939325425703907, 53.361697432041595,
                              0.0031478445976687911, 0.0043473800994601412, 1};
    const double thin[9] = {1, 0, 0, 0, 1e-7, 180, 0, 0, 1};            /* 360 px -> 4e-5 px */
    CHECK(home__homography_plausible(identity, 640, 360));
    CHECK(home__homography_plausible(zoom_out, 640, 360));
    CHECK(home__homography_plausible(keystone, 640, 360));
    CHECK(!home__homography_plausible(mirror, 640, 360));
    CHECK(!home__homography_plausible(behind, 640, 360));
    CHECK(home__homography_plausible(steep, 640, 360)); /* extreme, but in front and convex */
    CHECK(!home__homography_plausible(sliver, 94, 87));
    CHECK(!home__homography_plausible(thin, 640, 360));
}

void test_lm_exact_lines(void)
{
    home_context *ctx = test_context(IMG_W, IMG_H, NULL);
    synth_rng rng;
    int trial;
    if (!ctx) { CHECK(0); return; }
    synth_seed(&rng, 77);
    for (trial = 0; trial < 5; trial++) {
        double h[9];
        home_result res;
        memset(&res, 0, sizeof res);
        synth_corner_homography(&rng, IMG_W, IMG_H, 8 + 4 * trial, h);
        exact_matches(ctx, h, 60, 0.0, 0.0, &rng);
        home__estimate_homography(ctx, 60, &res);
        CHECK(res.ok);
        CHECK_EQ_INT(res.inliers, 60);
        CHECK_LT(synth_corner_error(res.H, h, IMG_W, IMG_H), 1e-3);
    }
}

void test_halving_with_outliers(void)
{
    home_context *ctx = test_context(IMG_W, IMG_H, NULL);
    synth_rng rng;
    int trial;
    if (!ctx) { CHECK(0); return; }
    synth_seed(&rng, 78);
    for (trial = 0; trial < 5; trial++) {
        double h[9];
        home_result res;
        memset(&res, 0, sizeof res);
        synth_corner_homography(&rng, IMG_W, IMG_H, 10 + 4 * trial, h);
        exact_matches(ctx, h, 300, 0.3, 0.3, &rng);
        home__estimate_homography(ctx, 300, &res);
        CHECK(res.ok);
        CHECK(res.inliers >= 150);
        CHECK_LT(synth_corner_error(res.H, h, IMG_W, IMG_H), 0.3);
    }
}

void test_theta_window_prior(void)
{
    /* with the motion prior every match pairs lines within the window, and registration holds */
    enum { PW = 640, PH = 360 };
    static uint8_t a[PW * PH], b[PW * PH];
    double h[9], ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    home_config cfg;
    home_context *ctx;
    home_result res;
    synth_rng rng;
    int i, outside = 0;
    synth_seed(&rng, 61);
    synth_corner_homography(&rng, PW, PH, 20, h);
    synth_render(SYNTH_STRUCTURED, 61, ident, 2.5, 1, a, PW, PH, PW);
    synth_render(SYNTH_STRUCTURED, 61, h, 2.5, 2, b, PW, PH, PW);
    home_default_config(&cfg, PW, PH);
    cfg.match_theta_window = 12;
    cfg.refine_levels = 0;
    ctx = test_context(PW, PH, &cfg);
    if (!ctx) { CHECK(0); return; }
    CHECK_EQ_INT(home_register(ctx, a, PW, b, PW, &res), HOME_OK);
    CHECK(res.ok);
    CHECK_LT(synth_corner_error(res.H, h, PW, PH), 1.0);
    for (i = 0; i < res.matches; i++) {
        double d = fabs((double)ctx->matches[i].theta_a - ctx->matches[i].theta_b) * 480 / HOME__PI;
        if (d > 12.0 + 1e-3) outside++;
    }
    CHECK_EQ_INT(outside, 0);
    CHECK(res.matches > 100);
}

/* Corners (px) of a normalised homography p (h8 = 1): pixel = scale u + (cx, cy). */
static void model_corners(const double *p, double scale, double cx, double cy, double *xy)
{
    int c;
    for (c = 0; c < 4; c++) {
        const double u = (c & 1 ? cx : -cx) / scale, v = (c & 2 ? cy : -cy) / scale;
        const double w = p[6] * u + p[7] * v + 1.0;
        xy[2 * c] = scale * (p[0] * u + p[1] * v + p[2]) / w + cx;
        xy[2 * c + 1] = scale * (p[3] * u + p[4] * v + p[5]) / w + cy;
    }
}

/* A fit whose every corner coordinate is known to sd px: information J^T J / sd^2, J the
 * corners' Jacobian by central differences. */
static void corner_information(home__model_problem *mp, double sd)
{
    double jac[8][8];
    int i, j, k;
    for (j = 0; j < 8; j++) {
        double plus[8], minus[8], xp[8], xm[8];
        memcpy(plus, mp->p, sizeof plus);
        memcpy(minus, mp->p, sizeof minus);
        plus[j] += 1e-6;
        minus[j] -= 1e-6;
        model_corners(plus, mp->scale, mp->cx, mp->cy, xp);
        model_corners(minus, mp->scale, mp->cx, mp->cy, xm);
        for (i = 0; i < 8; i++) jac[i][j] = (xp[i] - xm[i]) / 2e-6;
    }
    for (i = 0; i < 8; i++)
        for (j = 0; j < 8; j++) {
            double v = 0.0;
            for (k = 0; k < 8; k++) v += jac[k][i] * jac[k][j];
            mp->info[i * 8 + j] = v / (sd * sd);
        }
}

/* The corner floor of the model choice: a sheared motion whose perspective moves the corners
 * by about 0.3 px (RMS), measured to 0.05 px, is a homography on the plain information and an
 * affine with a 0.3 px floor, whose predicted error then holds the perspective it leaves out;
 * a perspective ten times as large stays a homography with the floor. */
void test_model_floor_weighs_perspective(void)
{
    home__model_problem mp;
    home__model_choice plain, floored, large;
    double corners_h[8], corners_affine[8], rms = 0.0;
    int i;
    memset(&mp, 0, sizeof mp);
    mp.space = HOME__SPACE_H;
    mp.scale = 320.0;
    mp.cx = 319.5;
    mp.cy = 179.5;
    mp.penalty = log(1000.0);
    mp.max_model = HOME_MODEL_HOMOGRAPHY;
    mp.max_params = 8;
    {
        const double p[8] = {1.0, 0.01, 0.002, 0.0, 1.0, 0.001, 0.0016, 0.0};
        memcpy(mp.p, p, sizeof p);
    }
    corner_information(&mp, 0.05);
    CHECK(home__select_model(&mp, &plain));
    CHECK_EQ_INT(plain.model, HOME_MODEL_HOMOGRAPHY);
    mp.floor_px = 0.3;
    CHECK(home__select_model(&mp, &floored));
    CHECK_EQ_INT(floored.model, HOME_MODEL_AFFINE);
    CHECK(fabs(floored.p[6]) < 1e-12 && fabs(floored.p[7]) < 1e-12);
    model_corners(mp.p, mp.scale, mp.cx, mp.cy, corners_h);
    model_corners(floored.p, mp.scale, mp.cx, mp.cy, corners_affine);
    for (i = 0; i < 8; i++) {
        const double d = corners_h[i] - corners_affine[i];
        rms += d * d;
    }
    rms = sqrt(rms / 4.0);
    printf("    perspective left out: %.3f px RMS, sigma %.3f px\n", rms, floored.sigma_px);
    CHECK(rms > 0.2 && rms < 0.8);
    CHECK(floored.sigma_px >= rms);
    mp.p[6] = 0.016;
    corner_information(&mp, 0.05);
    CHECK(home__select_model(&mp, &large));
    CHECK_EQ_INT(large.model, HOME_MODEL_HOMOGRAPHY);
}
