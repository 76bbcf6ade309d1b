/* Stabiliser tests (home-stab-tests): warp kernels against a floating-point reference and across
 * formats, the path filter on synthetic shaky clips with known camera motion (residual jitter,
 * crop window inside the frame, latency = lookahead, hold on failure), API contract.
 * Built only with -DHOME_STAB_TESTS (mk/stab.mk); in home-tests this file compiles to nothing. */
#ifdef HOME_STAB_TESTS
#include "home_stab.h"
#include "stab_clip.h"
#include "stab_internal.h"
#include "synth.h"
#include "test.h"
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


#define CW 256
#define CH 144
#define CLIP_FRAMES 72

static union { unsigned char bytes[8u << 20]; double align; } arena;
static uint8_t clip[CLIP_FRAMES][CW * CH * 3 / 2];
static double clip_g[CLIP_FRAMES][9];

/* refine_finest_level of the stabilisers make_stab() builds; -1: the default (one test sets 0) */
static int stab_refine_finest = -1;

static home_stab *make_stab(int lookahead, int downscale, int theta_bins)
{
    home_stab_config cfg;
    home_stab *st = NULL;
    home_stab_default_config(&cfg, CW, CH);
    if (stab_refine_finest >= 0) cfg.refine_finest_level = stab_refine_finest;
    cfg.lookahead = lookahead;
    cfg.downscale = downscale;
    cfg.theta_bins = theta_bins;
    if (home_stab_init(&st, &cfg, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes), NULL) != HOME_OK) return NULL;
    return st;
}

static void grey_image(uint8_t *buf, home_stab_image *im)
{
    memset(im, 0, sizeof *im);
    im->format = HOME_STAB_I420;
    im->width = CW;
    im->height = CH;
    im->plane[0] = buf;
    im->plane[1] = buf + CW * CH;
    im->plane[2] = buf + CW * CH + CW * CH / 4;
    im->stride[0] = CW;
    im->stride[1] = im->stride[2] = CW / 2;
}

/* Render the shaky clip once: structured scene, 3 px / 0.3 deg jitter, a 40 px pan. */
static void render_clip(void)
{
    static int done;
    stab_clip_motion m = {CLIP_FRAMES, 3.0, 0.3, 40.0, 5};
    int t;
    if (done) return;
    for (t = 0; t < CLIP_FRAMES; t++) {
        double intent[9];
        stab_clip_camera(&m, t, CW, CH, clip_g[t], intent);
        synth_render(SYNTH_STRUCTURED, 1, clip_g[t], 1.0, (uint64_t)t + 1, clip[t], CW, CH, CW);
        memset(clip[t] + CW * CH, 128, CW * CH / 2);
    }
    done = 1;
}

static int corners_inside(const double *w)
{
    int i;
    for (i = 0; i < 4; i++) {
        double x = (i & 1) ? CW - 1 : 0, y = (i & 2) ? CH - 1 : 0;
        double u = w[0] * x + w[1] * y + w[2], v = w[3] * x + w[4] * y + w[5];
        if (!(u >= -1e-9 && u <= CW - 1 + 1e-9 && v >= -1e-9 && v <= CH - 1 + 1e-9)) return 0;
    }
    return 1;
}

/* A horizon in fog seen by the clip's camera: sky 190, ground 172, a soft wavy ridge about
 * 4 px wide, sensor noise 1.5: too little structure for a whole motion. */
static void render_fog(uint8_t (*out)[CW * CH * 3 / 2])
{
    synth_rng rng;
    int t, x, y;
    render_clip();
    synth_seed(&rng, 77);
    for (t = 0; t < CLIP_FRAMES; t++) {
        double inv[9];
        synth_invert(clip_g[t], inv);
        for (y = 0; y < CH; y++)
            for (x = 0; x < CW; x++) {
                double rx, ry, ridge, v;
                synth_apply(inv, x, y, &rx, &ry);
                ridge = 0.45 * CH + 0.5 * sin(rx / 50.0) + 0.0 * sin(rx / 9.0);
                v = 181.0 - 5.0 * tanh((ry - ridge) / 4.0) + 2.5 * synth_gauss(&rng);
                out[t][y * CW + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
            }
        memset(out[t] + CW * CH, 128, CW * CH / 2);
    }
}

typedef struct run_result {
    double warp[CLIP_FRAMES][9];
    int status[CLIP_FRAMES];
    int emitted, order_ok, latency_ok, inside;
} run_result;

/* The frames run_clip() stabilises (NULL: the structured clip) */
static uint8_t (*clip_frames)[CW * CH * 3 / 2];

/* Stabilise the clip (frames flat_from..flat_to replaced by flat grey when flat_to >= 0). */
static void run_clip(int lookahead, int downscale, int theta_bins, int flat_from, int flat_to, run_result *r)
{
    static uint8_t flat[CW * CH * 3 / 2];
    home_stab *st = make_stab(lookahead, downscale, theta_bins);
    home_stab_output o;
    home_stab_image im;
    int t;
    memset(r, 0, sizeof *r);
    r->order_ok = r->latency_ok = r->inside = 1;
    memset(flat, 128, sizeof flat);
    CHECK(st != NULL);
    if (!st) return;
    render_clip();
    for (t = 0; t < CLIP_FRAMES; t++) {
        grey_image(t >= flat_from && t <= flat_to ? flat : clip_frames ? clip_frames[t] : clip[t], &im);
        CHECK_EQ_INT(home_stab_push(st, &im, &o), HOME_OK);
        r->status[t] = o.newest_status;
        if (o.ready != (t >= lookahead)) r->latency_ok = 0;
        if (!o.ready) continue;
        if (o.frame != t - lookahead || o.frame != r->emitted) r->order_ok = 0;
        memcpy(r->warp[o.frame], o.warp, sizeof o.warp);
        r->inside &= corners_inside(o.warp) && o.correction_used >= 0 && o.correction_used <= 1;
        r->emitted++;
    }
    while (home_stab_flush(st, &o) == HOME_OK && o.ready) {
        if (o.frame != r->emitted) r->order_ok = 0;
        memcpy(r->warp[o.frame], o.warp, sizeof o.warp);
        r->inside &= corners_inside(o.warp);
        r->emitted++;
    }
}

/* Jitter of the camera the output shows: ref -> output is warp^-1 after g; axis 0..2 (tx, ty,
 * angle) alone, or -1 all. */
static double output_jitter_of(const run_result *r, int axis)
{
    static double path[CLIP_FRAMES][3];
    int t, c;
    for (t = 0; t < CLIP_FRAMES; t++) {
        double inv[9], o[9];
        int i, j, k;
        synth_invert(r->warp[t], inv);
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++)
                for (o[3 * i + j] = 0, k = 0; k < 3; k++) o[3 * i + j] += inv[3 * i + k] * clip_g[t][3 * k + j];
        stab_clip_components(o, CW, CH, path[t]);
        for (c = 0; c < 3; c++)
            if (axis >= 0 && c != axis) path[t][c] = 0.0;
    }
    return stab_clip_jitter((const double (*)[3])path, CLIP_FRAMES, 4.0, 6);
}

static double output_jitter(const run_result *r) { return output_jitter_of(r, -1); }

static double input_jitter_of(int axis)
{
    static double path[CLIP_FRAMES][3];
    int t, c;
    render_clip();
    for (t = 0; t < CLIP_FRAMES; t++) {
        stab_clip_components(clip_g[t], CW, CH, path[t]);
        for (c = 0; c < 3; c++)
            if (axis >= 0 && c != axis) path[t][c] = 0.0;
    }
    return stab_clip_jitter((const double (*)[3])path, CLIP_FRAMES, 4.0, 6);
}

static double input_jitter(void) { return input_jitter_of(-1); }

/* Causal stabilisation of the clip with theta_bins (0: automatic): the jitter cut to a third,
 * nearly every frame registered, the window inside. */
static void check_causal_run(int theta_bins, run_result *r)
{
    double in = input_jitter(), out;
    int t, ok = 0;
    run_clip(0, 1, theta_bins, 0, -1, r);
    out = output_jitter(r);
    for (t = 1; t < CLIP_FRAMES; t++) ok += r->status[t] == HOME_STAB_MOTION_OK;
    printf("    jitter in %.3f px, out %.3f px (causal, theta bins %d), %d/%d registered\n", in, out,
           theta_bins, ok, CLIP_FRAMES - 1);
    CHECK(in > 2.0);
    CHECK_LT(out, 0.35 * in);
    CHECK(ok >= CLIP_FRAMES - 3);
    CHECK(r->inside);
}

static void test_jitter_reduced_causal(void)
{
    static run_result r;
    check_causal_run(0, &r);
    CHECK(r.order_ok && r.latency_ok);
    CHECK_EQ_INT(r.emitted, CLIP_FRAMES);
}

/* A horizon in fog gives HOME too few lines and the refinement too little to vouch for a whole
 * motion; the part the frames determine, the shift across the horizon, is still taken, and the
 * shake across it removed (without it every such frame was held: the input's jitter). Along the
 * horizon nothing is determined: that shake stays (and the few frames registered ok here are
 * off along it: issue 16's fog horizons). */
static void test_horizon_in_fog_partial(void)
{
    static uint8_t fog[CLIP_FRAMES][CW * CH * 3 / 2];
    static run_result r;
    const double in = input_jitter_of(1);
    double out;
    int t, partial = 0;
    render_fog(fog);
    clip_frames = fog;
    run_clip(12, 1, 0, 0, -1, &r);
    clip_frames = NULL;
    out = output_jitter_of(&r, 1);
    for (t = 1; t < CLIP_FRAMES; t++) partial += r.status[t] == HOME_STAB_MOTION_PARTIAL;
    printf("    fog: vertical jitter in %.3f px, out %.3f px; %d of %d frames partial\n", in, out,
           partial, CLIP_FRAMES - 1);
    CHECK(partial >= CLIP_FRAMES / 2);
    CHECK_LT(out, 0.75 * in);
    CHECK(r.inside);
}

static void test_lookahead_latency_and_gain(void)
{
    static run_result causal, ahead;
    double j0, j1;
    run_clip(0, 1, 0, 0, -1, &causal);
    run_clip(12, 1, 0, 0, -1, &ahead);
    j0 = output_jitter(&causal);
    j1 = output_jitter(&ahead);
    printf("    jitter causal %.3f px, lookahead 12: %.3f px\n", j0, j1);
    CHECK(ahead.latency_ok && ahead.order_ok);
    CHECK_EQ_INT(ahead.emitted, CLIP_FRAMES);
    CHECK(ahead.inside);
    CHECK_LT(j1, j0);
}

/* A user who grants a few frames of latency gets a steadier picture, never a shakier one: with
 * the automatic time constant the jitter does not grow from one lookahead to the next (5 %
 * tolerance for the clip's noise). A lookahead of 1-3 once came with a 3-frame time constant
 * and left up to 1.9x the causal jitter on the bench clips. */
static void test_more_latency_never_shakier(void)
{
    static const int lookaheads[] = {0, 1, 2, 3, 4, 5, 6, 8};
    static run_result r;
    double prev = 0.0;
    size_t k;
    for (k = 0; k < sizeof lookaheads / sizeof lookaheads[0]; k++) {
        double j;
        run_clip(lookaheads[k], 1, 0, 0, -1, &r);
        j = output_jitter(&r);
        printf("    lookahead %d: jitter %.3f px\n", lookaheads[k], j);
        CHECK(r.latency_ok && r.order_ok && r.inside);
        if (k > 0) CHECK_LT(j, 1.05 * prev);
        prev = j;
    }
}

/* The refinement ending at half size (the default: fewer instructions per frame) keeps most of
 * the full-size ending's precision, with the same latency and the window inside the frame. */
static void test_refine_ending_at_half_size(void)
{
    static run_result full, half;
    double j_full, j_half;
    stab_refine_finest = 0;
    run_clip(12, 1, 0, 0, -1, &full);
    stab_refine_finest = 1;
    run_clip(12, 1, 0, 0, -1, &half);
    stab_refine_finest = -1;
    j_full = output_jitter(&full);
    j_half = output_jitter(&half);
    printf("    jitter with lookahead 12, refinement ending at full size %.3f px, half size %.3f px\n",
           j_full, j_half);
    CHECK(half.latency_ok && half.order_ok && half.inside);
    CHECK_EQ_INT(half.emitted, CLIP_FRAMES);
    CHECK_LT(j_half, 1.5 * j_full);
}

static void test_downscaled_registration(void)
{
    static run_result r;
    double in = input_jitter(), out;
    run_clip(0, 2, 0, 0, -1, &r);
    out = output_jitter(&r);
    printf("    jitter with registration at 1/2 size: %.3f px\n", out);
    CHECK_LT(out, 0.5 * in);
    CHECK(r.inside);
}

/* Fewer theta bins than the automatic 88 (cheaper Hough transform) still stabilise. */
static void test_fewer_theta_bins(void)
{
    static run_result r;
    check_causal_run(48, &r);
}

/* Flat frames cannot be registered: the path holds, every warp stays valid, inside the frame,
 * and the correction changes smoothly (no garbage, no jump). */
static void test_hold_on_failure(void)
{
    static run_result r;
    double max_step = 0;
    int t, held = 0;
    run_clip(0, 1, 0, 30, 37, &r);
    for (t = 30; t <= 38; t++) held += r.status[t] == HOME_STAB_MOTION_FAILED || r.status[t] == HOME_STAB_MOTION_IMPLAUSIBLE;
    for (t = 1; t < CLIP_FRAMES; t++) {
        double step = hypot(r.warp[t][2] - r.warp[t - 1][2], r.warp[t][5] - r.warp[t - 1][5]);
        if (step > max_step) max_step = step;
    }
    printf("    %d frames held, largest frame-to-frame change of the warp %.2f px\n", held, max_step);
    CHECK(held >= 9);
    CHECK(r.inside);
    CHECK_EQ_INT(r.emitted, CLIP_FRAMES);
    CHECK_LT(max_step, 0.1 * CW);
}

/* A frame from a camera 60 px away (a glitch, or a cut and back) is not followed: the motion to
 * it and back is refused as implausible or failed, so the path holds and the output stays. */
static void test_implausible_jump_held(void)
{
    static uint8_t jumped[CW * CH * 3 / 2];
    home_stab *st = make_stab(0, 1, 0);
    home_stab_output o;
    home_stab_image im;
    double g[9], max_step = 0, prev_x = 0, prev_y = 0;
    int t, refused = 0, inside = 1;
    CHECK(st != NULL);
    if (!st) return;
    render_clip();
    memcpy(g, clip_g[20], sizeof g);
    g[2] += 60.0;
    synth_render(SYNTH_STRUCTURED, 1, g, 1.0, 99, jumped, CW, CH, CW);
    memset(jumped + CW * CH, 128, CW * CH / 2);
    for (t = 0; t < 40; t++) {
        grey_image(t == 20 ? jumped : clip[t], &im);
        CHECK_EQ_INT(home_stab_push(st, &im, &o), HOME_OK);
        if (t == 20 || t == 21)
            refused += o.newest_status == HOME_STAB_MOTION_IMPLAUSIBLE || o.newest_status == HOME_STAB_MOTION_FAILED;
        inside &= corners_inside(o.warp);
        if (t > 0 && t != 20 && t != 21) {
            double step = hypot(o.warp[2] - prev_x, o.warp[5] - prev_y);
            if (step > max_step) max_step = step;
        }
        prev_x = o.warp[2];
        prev_y = o.warp[5];
    }
    printf("    jump refused on %d of 2 frames, largest warp change elsewhere %.2f px\n", refused, max_step);
    CHECK_EQ_INT(refused, 2);
    CHECK(inside);
    CHECK_LT(max_step, 0.1 * CW);
}

/* Record an emitted frame; 0 when it is out of order or its window leaves the frame. */
static int take(const home_stab_output *o, int *next, double (*smooth)[2])
{
    int ok = o->frame == *next && corners_inside(o->warp);
    smooth[*next][0] = o->smooth.tx;
    smooth[*next][1] = o->smooth.ty;
    ++*next;
    return ok;
}

/* Stabilise clip frames [0, n) with lookahead 12 and the given ease, flushing after frame
 * flush_at too; the smoothed path per frame. 0 unless every frame came once, in order, at the
 * configured latency, with its window inside the frame. */
static int run_eased(float ease, int n, int flush_at, double (*smooth)[2])
{
    home_stab_config cfg;
    home_stab *st = NULL;
    home_stab_output o;
    home_stab_image im;
    int t, next = 0, ok = 1;
    home_stab_default_config(&cfg, CW, CH);
    cfg.lookahead = 12;
    cfg.ease = ease;
    if (home_stab_init(&st, &cfg, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes), NULL) != HOME_OK) return 0;
    render_clip();
    for (t = 0; t < n; t++) {
        grey_image(clip[t], &im);
        if (home_stab_push(st, &im, &o) != HOME_OK) return 0;
        if (o.ready != (t - next >= 12)) ok = 0;
        if (o.ready) ok &= take(&o, &next, smooth);
        if (t == flush_at)
            while (home_stab_flush(st, &o) == HOME_OK && o.ready) ok &= take(&o, &next, smooth);
    }
    while (home_stab_flush(st, &o) == HOME_OK && o.ready) ok &= take(&o, &next, smooth);
    return ok && next == n;
}

static double path_speed(double (*p)[2], int from, int to)
{
    double sum = 0;
    int t;
    for (t = from; t < to; t++) sum += hypot(p[t + 1][0] - p[t][0], p[t + 1][1] - p[t][1]);
    return sum / (to - from);
}

/* The ends are smoothed over the mirrored path: with ease 1 the virtual camera starts from and
 * comes to rest, with ease 0 it keeps the pan (about 0.55 px per frame); either way in order, at
 * the configured latency, inside the frame. Streams shorter than the lookahead, and pushes after
 * a flush, work too. */
static void test_ends_mirrored(void)
{
    static double rest[CLIP_FRAMES][2], pan[CLIP_FRAMES][2], part[CLIP_FRAMES][2];
    double mid, r0, r1, p0, p1;
    CHECK(run_eased(1.0f, CLIP_FRAMES, -1, rest));
    CHECK(run_eased(0.0f, CLIP_FRAMES, -1, pan));
    mid = path_speed(pan, 20, CLIP_FRAMES - 21);
    r0 = path_speed(rest, 0, 3);
    r1 = path_speed(rest, CLIP_FRAMES - 4, CLIP_FRAMES - 1);
    p0 = path_speed(pan, 0, 3);
    p1 = path_speed(pan, CLIP_FRAMES - 4, CLIP_FRAMES - 1);
    printf("    smoothed px per frame, first / last 3 frames: ease 1 %.2f / %.2f, ease 0 %.2f / %.2f;"
           " between %.2f\n", r0, r1, p0, p1, mid);
    CHECK(mid > 0.4);
    CHECK_LT(r0, 0.4 * mid);
    CHECK_LT(r1, 0.4 * mid);
    CHECK(p0 > 0.7 * mid && p1 > 0.7 * mid);
    CHECK(run_eased(0.5f, 5, -1, part));
    CHECK(run_eased(0.5f, 40, 19, part));
}

static void test_deterministic(void)
{
    static run_result a, b;
    run_clip(4, 1, 0, 0, -1, &a);
    run_clip(4, 1, 0, 0, -1, &b);
    CHECK(memcmp(a.warp, b.warp, sizeof a.warp) == 0);
}

/* ---- warp kernels ---- */

static double ref_sample(const uint8_t *p, ptrdiff_t stride, int step, int w, int h, double x, double y)
{
    int xi, yi;
    double fx, fy;
    x = x < 0 ? 0 : x > w - 1 ? w - 1 : x;
    y = y < 0 ? 0 : y > h - 1 ? h - 1 : y;
    xi = (int)x < w - 1 ? (int)x : w - 2;
    yi = (int)y < h - 1 ? (int)y : h - 2;
    fx = x - xi;
    fy = y - yi;
    p += yi * stride + xi * step;
    return (p[0] * (1 - fx) + p[step] * fx) * (1 - fy) + (p[stride] * (1 - fx) + p[stride + step] * fx) * fy;
}

static void test_warp_matches_reference(void)
{
    static uint8_t src[CW * CH * 3 / 2], dst[CW * CH * 3 / 2];
    home_stab_image a, b;
    double worst = 0, sum = 0;
    long count = 0;
    int trial, x, y;
    synth_rng rng;
    synth_seed(&rng, 11);
    render_clip();
    memcpy(src, clip[3], sizeof src);
    for (x = 0; x < CW * CH / 2; x++) src[CW * CH + x] = (uint8_t)(x * 7);   /* chroma pattern */
    grey_image(src, &a);
    grey_image(dst, &b);
    for (trial = 0; trial < 20; trial++) {
        home_stab_sim s;
        double m[9];
        s.tx = 20 * (synth_uniform(&rng) - 0.5);
        s.ty = 20 * (synth_uniform(&rng) - 0.5);
        s.angle = 0.2 * (synth_uniform(&rng) - 0.5);
        s.log_scale = 0.3 * (synth_uniform(&rng) - 0.5);
        home_stab_sim_to_matrix(&s, CW, CH, m);
        CHECK_EQ_INT(home_stab_warp(m, &a, &b), HOME_OK);
        for (y = 0; y < CH; y++)
            for (x = 0; x < CW; x++) {
                double u = m[0] * x + m[1] * y + m[2], v = m[3] * x + m[4] * y + m[5];
                double d = fabs(dst[y * CW + x] - ref_sample(src, CW, 1, CW, CH, u, v));
                if (d > worst) worst = d;
                sum += d;
                count++;
            }
        for (y = 0; y < CH / 2; y++)   /* chroma: centre-sited, half resolution */
            for (x = 0; x < CW / 2; x++) {
                double u = m[0] * (2 * x + 0.5) + m[1] * (2 * y + 0.5) + m[2];
                double v = m[3] * (2 * x + 0.5) + m[4] * (2 * y + 0.5) + m[5];
                double d = fabs(dst[CW * CH + y * CW / 2 + x] -
                                ref_sample(src + CW * CH, CW / 2, 1, CW / 2, CH / 2, (u - 0.5) / 2, (v - 0.5) / 2));
                if (d > worst) worst = d;
            }
    }
    printf("    difference from floating-point bilinear: largest %.3f, mean %.3f grey levels\n", worst, sum / count);
    /* weights rounded to 1/128 are each within 1/256 of exact: at most 2 x 255 / 256 across a
     * full-range edge in both directions, plus the final rounding's 0.5 */
    CHECK_LT(worst, 2.5);
    CHECK_LT(sum / count, 0.35);
}

static void test_warp_identity_and_shift(void)
{
    static uint8_t src[CW * CH * 3 / 2], dst[CW * CH * 3 / 2];
    home_stab_image a, b;
    double id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, shift[9] = {1, 0, 4, 0, 1, -2, 0, 0, 1};
    int x, y, bad = 0;
    render_clip();
    memcpy(src, clip[0], sizeof src);
    for (x = 0; x < CW * CH / 2; x++) src[CW * CH + x] = (uint8_t)(x * 13);
    grey_image(src, &a);
    grey_image(dst, &b);
    CHECK_EQ_INT(home_stab_warp(id, &a, &b), HOME_OK);
    CHECK(memcmp(src, dst, sizeof src) == 0);
    CHECK_EQ_INT(home_stab_warp(shift, &a, &b), HOME_OK);
    for (y = 0; y < CH - 2; y++)
        for (x = 0; x < CW - 4; x++) bad += dst[(y + 2) * CW + x] != src[y * CW + x + 4];
    for (y = 0; y < CH / 2 - 1; y++)   /* 4, -2 luma px = 2, -1 chroma px: exact */
        for (x = 0; x < CW / 2 - 2; x++) bad += dst[CW * CH + (y + 1) * CW / 2 + x] != src[CW * CH + y * CW / 2 + x + 2];
    CHECK_EQ_INT(bad, 0);
}

/* The same picture as I420, NV12 and YUYV warps to the same samples. */
static void test_warp_formats_agree(void)
{
    static uint8_t i420[CW * CH * 3 / 2], nv12[CW * CH * 3 / 2], yuyv[CW * CH * 2];
    static uint8_t o420[CW * CH * 3 / 2], onv[CW * CH * 3 / 2], oyuyv[CW * CH * 2];
    home_stab_image a, b, c, d, e, f;
    home_stab_sim s = {3.3, -2.7, 0.03, 0.05};
    double m[9];
    int x, y, bad = 0;
    render_clip();
    memcpy(i420, clip[5], CW * CH);
    for (x = 0; x < CW * CH / 4; x++) { i420[CW * CH + x] = (uint8_t)(x * 3); i420[CW * CH * 5 / 4 + x] = (uint8_t)(x * 5 + 1); }
    memcpy(nv12, i420, CW * CH);
    for (x = 0; x < CW * CH / 4; x++) { nv12[CW * CH + 2 * x] = i420[CW * CH + x]; nv12[CW * CH + 2 * x + 1] = i420[CW * CH * 5 / 4 + x]; }
    for (y = 0; y < CH; y++)
        for (x = 0; x < CW; x++) yuyv[y * 2 * CW + 2 * x] = i420[y * CW + x];
    for (y = 0; y < CH; y++)
        for (x = 0; x < CW / 2; x++) { yuyv[y * 2 * CW + 4 * x + 1] = 0; yuyv[y * 2 * CW + 4 * x + 3] = 0; }
    grey_image(i420, &a); grey_image(o420, &b);
    c = a; c.format = HOME_STAB_NV12; c.plane[0] = nv12; c.plane[1] = nv12 + CW * CH; c.stride[1] = CW;
    d = c; d.plane[0] = onv; d.plane[1] = onv + CW * CH;
    memset(&e, 0, sizeof e);
    e.format = HOME_STAB_YUYV; e.width = CW; e.height = CH; e.plane[0] = yuyv; e.stride[0] = 2 * CW;
    f = e; f.plane[0] = oyuyv;
    home_stab_sim_to_matrix(&s, CW, CH, m);
    CHECK_EQ_INT(home_stab_warp(m, &a, &b), HOME_OK);
    CHECK_EQ_INT(home_stab_warp(m, &c, &d), HOME_OK);
    CHECK_EQ_INT(home_stab_warp(m, &e, &f), HOME_OK);
    CHECK(memcmp(o420, onv, CW * CH) == 0);
    for (x = 0; x < CW * CH / 4; x++)
        bad += onv[CW * CH + 2 * x] != o420[CW * CH + x] || onv[CW * CH + 2 * x + 1] != o420[CW * CH * 5 / 4 + x];
    for (y = 0; y < CH; y++)
        for (x = 0; x < CW; x++) bad += oyuyv[y * 2 * CW + 2 * x] != o420[y * CW + x];
    CHECK_EQ_INT(bad, 0);
}

/* Warping in bands of rows gives the whole warp's bytes (I420: even bands; YUYV: any), a band
 * writes nothing outside its rows, and bands that are empty, outside the frame or odd in I420
 * are refused with the destination untouched. */
static void test_warp_bands_match_whole(void)
{
    static uint8_t i420[CW * CH * 3 / 2], whole[CW * CH * 3 / 2], bands[CW * CH * 3 / 2];
    static uint8_t yuyv[CW * CH * 2], ywhole[CW * CH * 2], ybands[CW * CH * 2];
    static const int cuts420[] = {0, 10, 36, 92, CH}, cutsyuyv[] = {0, 7, 8, 101, CH};
    home_stab_image a, b, c, ya, yb, yc;
    home_stab_sim s = {-4.1, 2.6, -0.04, 0.06};
    double m[9];
    int k, y, outside = 0, inside = 0;
    render_clip();
    memcpy(i420, clip[9], sizeof i420);
    for (k = 0; k < CW * CH / 2; k++) i420[CW * CH + k] = (uint8_t)(k * 7 + (k >> 5));
    for (k = 0; k < CW * CH; k++) { yuyv[2 * k] = i420[k]; yuyv[2 * k + 1] = (uint8_t)(k * 13); }
    grey_image(i420, &a); grey_image(whole, &b); grey_image(bands, &c);
    memset(&ya, 0, sizeof ya);
    ya.format = HOME_STAB_YUYV; ya.width = CW; ya.height = CH; ya.plane[0] = yuyv; ya.stride[0] = 2 * CW;
    yb = ya; yb.plane[0] = ywhole;
    yc = ya; yc.plane[0] = ybands;
    home_stab_sim_to_matrix(&s, CW, CH, m);
    CHECK_EQ_INT(home_stab_warp(m, &a, &b), HOME_OK);
    CHECK_EQ_INT(home_stab_warp(m, &ya, &yb), HOME_OK);
    memset(bands, 0xA5, sizeof bands);
    memset(ybands, 0xA5, sizeof ybands);
    for (k = 0; k + 1 < (int)(sizeof cuts420 / sizeof cuts420[0]); k++) {
        CHECK_EQ_INT(home_stab_warp_rows(m, &a, &c, cuts420[k], cuts420[k + 1] - cuts420[k]), HOME_OK);
        CHECK_EQ_INT(home_stab_warp_rows(m, &ya, &yc, cutsyuyv[k], cutsyuyv[k + 1] - cutsyuyv[k]), HOME_OK);
    }
    CHECK(memcmp(whole, bands, sizeof whole) == 0);
    CHECK(memcmp(ywhole, ybands, sizeof ywhole) == 0);

    /* one band (luma rows 36..91, chroma rows 18..45) into a sentinel frame */
    memset(bands, 0xA5, sizeof bands);
    CHECK_EQ_INT(home_stab_warp_rows(m, &a, &c, 36, 56), HOME_OK);
    for (y = 0; y < CH; y++) {
        const int in = y >= 36 && y < 92;
        for (k = 0; k < CW; k++) {
            const uint8_t got = bands[y * CW + k], want = in ? whole[y * CW + k] : 0xA5;
            outside += !in && got != want;
            inside += in && got != want;
        }
    }
    for (y = 0; y < CH / 2; y++) {
        const int in = y >= 18 && y < 46;
        for (k = 0; k < CW / 2; k++) {
            const size_t u = (size_t)CW * CH + (size_t)y * (CW / 2) + (size_t)k, v = u + (size_t)CW * CH / 4;
            outside += !in && (bands[u] != 0xA5 || bands[v] != 0xA5);
            inside += in && (bands[u] != whole[u] || bands[v] != whole[v]);
        }
    }
    CHECK_EQ_INT(inside, 0);
    CHECK_EQ_INT(outside, 0);

    memset(bands, 0xA5, sizeof bands);
    CHECK_EQ_INT(home_stab_warp_rows(m, &a, &c, 0, 0), HOME_E_CONFIG);
    CHECK_EQ_INT(home_stab_warp_rows(m, &a, &c, -2, 4), HOME_E_CONFIG);
    CHECK_EQ_INT(home_stab_warp_rows(m, &a, &c, CH - 2, 4), HOME_E_CONFIG);
    CHECK_EQ_INT(home_stab_warp_rows(m, &a, &c, 3, 4), HOME_E_CONFIG);
    CHECK_EQ_INT(home_stab_warp_rows(m, &a, &c, 4, 3), HOME_E_CONFIG);
    CHECK_EQ_INT(home_stab_warp_rows(m, &a, &c, 2, 2147483647), HOME_E_CONFIG);
    CHECK_EQ_INT(home_stab_warp_rows(m, &ya, &yc, 3, 1), HOME_OK);
    for (k = 0, outside = 0; k < (int)sizeof bands; k++) outside += bands[k] != 0xA5;
    CHECK_EQ_INT(outside, 0);
}

static void test_row_kernel_edges(void)
{
    /* 2x2 source: every clamped coordinate lands on an edge pixel pair with weights 0 or 256 */
    static const uint8_t src[4] = {10, 20, 30, 40};
    uint8_t out[4];
    home__warp_row_c(src, 2, 1, 2, 2, -5 * 65536, -5 * 65536, 10 * 65536, 0, out, 1, 2);
    CHECK_EQ_INT(out[0], 10);
    CHECK_EQ_INT(out[1], 20);
    home__warp_row_c(src, 2, 1, 2, 2, 1 << 15, 1 << 15, 0, 0, out, 1, 1);
    CHECK_EQ_INT(out[0], 25);
    home__warp_row_c(src, 2, 1, 2, 2, 1 << 16, 1 << 16, 0, 0, out, 1, 1);
    CHECK_EQ_INT(out[0], 40);
}


static void test_api_contract(void)
{
    static uint8_t buf[CW * CH * 3 / 2];
    home_stab_config cfg, bad;
    home_stab *st = NULL;
    home_stab_output o;
    home_stab_image im, small;
    unsigned char *base = ALIGNED_ARENA(arena.bytes);
    size_t need = 0, size;
    double affine[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, proj[9] = {1, 0, 0, 0, 1, 0, 1e-4, 0, 1};
    double far[9] = {1, 0, 900, 0, 1, 0, 0, 0, 1}, nan_map[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    CHECK_EQ_INT(home_stab_default_config(&cfg, CW, CH), HOME_OK);
    CHECK_EQ_INT(home_stab_validate_config(&cfg), HOME_OK);
    size = home_stab_arena_size(&cfg);
    CHECK(size > 0 && size < ALIGNED_BYTES(arena.bytes));
    CHECK_EQ_INT(home_stab_init(&st, &cfg, base, size - 1, &need), HOME_E_ARENA_SMALL);
    CHECK_EQ_INT(need, size);
    CHECK_EQ_INT(home_stab_init(&st, &cfg, base + 1, size + 16, NULL), HOME_E_ARENA_ALIGN);
    CHECK_EQ_INT(home_stab_init(&st, NULL, base, size, NULL), HOME_E_NULL);
    bad = cfg; bad.width = CW + 1; CHECK_EQ_INT(home_stab_validate_config(&bad), HOME_E_SIZE);
    bad = cfg; bad.margin_x = 0.5f; CHECK_EQ_INT(home_stab_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.margin_y = -0.1f; CHECK_EQ_INT(home_stab_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.smoothing = NAN; CHECK_EQ_INT(home_stab_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.lookahead = HOME_STAB_MAX_LOOKAHEAD + 1; CHECK_EQ_INT(home_stab_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.ease = 1.5f; CHECK_EQ_INT(home_stab_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.ease = NAN; CHECK_EQ_INT(home_stab_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.downscale = 3; CHECK_EQ_INT(home_stab_validate_config(&bad), HOME_E_CONFIG);
    bad = cfg; bad.downscale = 8; CHECK(home_stab_validate_config(&bad) != HOME_OK);
    CHECK_EQ_INT(home_stab_arena_size(&bad), 0);
    CHECK_EQ_INT(home_stab_init(&st, &cfg, base, size, NULL), HOME_OK);
    grey_image(buf, &im);
    CHECK_EQ_INT(home_stab_push(st, NULL, &o), HOME_E_NULL);
    CHECK_EQ_INT(home_stab_push(NULL, &im, &o), HOME_E_NULL);
    small = im; small.width = CW / 2; CHECK_EQ_INT(home_stab_push(st, &small, &o), HOME_E_MISMATCH);
    small = im; small.stride[1] = CW / 4; CHECK_EQ_INT(home_stab_push(st, &small, &o), HOME_E_STRIDE);
    small = im; small.format = 77; CHECK_EQ_INT(home_stab_push(st, &small, &o), HOME_E_CONFIG);
    small = im; small.plane[2] = NULL; CHECK_EQ_INT(home_stab_push(st, &small, &o), HOME_E_NULL);
    CHECK_EQ_INT(home_stab_warp(proj, &im, &im), HOME_E_CONFIG);
    CHECK_EQ_INT(home_stab_warp(far, &im, &im), HOME_E_CONFIG);
    nan_map[2] = NAN;
    CHECK_EQ_INT(home_stab_warp(nan_map, &im, &im), HOME_E_CONFIG);
    small = im; small.height = CH - 2; CHECK_EQ_INT(home_stab_warp(affine, &im, &small), HOME_E_MISMATCH);
    /* a garbage-filled handle is refused, not followed */
    memset(base, 0x5a, 4096);
    CHECK_EQ_INT(home_stab_push(st, &im, &o), HOME_E_STATE);
    CHECK_EQ_INT(home_stab_flush(st, &o), HOME_E_STATE);
}

/* A static camera with a textured object crossing a fifth of the frame: the object must not
 * steer the path: every registration is the identity or refused, and the raw path stays 0. */
static void test_static_camera_moving_object(void)
{
    static uint8_t frame[CW * CH * 3 / 2];
    static const double still[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    home_stab *st = make_stab(4, 1, 0);
    home_stab_output o;
    home_stab_image im;
    double worst = 0.0;
    int t, x, y, identities = 0, moved = 0, n = 0;
    CHECK(st != NULL);
    if (!st) return;
    for (t = 0; t < 40; t++) {
        synth_render(SYNTH_STRUCTURED, 9, still, 2.5, (uint64_t)t + 100, frame, CW, CH, CW);
        memset(frame + CW * CH, 128, CW * CH / 2);
        for (y = 40; y < 40 + 56; y++) /* a 90x56 checkered object moving 3 px a frame */
            for (x = 10 + 3 * t; x < 10 + 3 * t + 90 && x < CW; x++)
                frame[y * CW + x] = (uint8_t)(((x - 3 * t) / 6 + y / 5) % 2 ? 200 : 40);
        grey_image(frame, &im);
        CHECK_EQ_INT(home_stab_push(st, &im, &o), HOME_OK);
        if (t > 0) {
            n++;
            identities += o.reg.ok && o.reg.model == HOME_MODEL_IDENTITY;
            moved += o.reg.ok && o.reg.model != HOME_MODEL_IDENTITY;
        }
        if (o.ready) {
            const double d = fabs(o.raw.tx) + fabs(o.raw.ty) + fabs(o.raw.angle) * CW;
            if (d > worst) worst = d;
        }
    }
    printf("    %d of %d registrations the identity, %d a motion (the rest refused), largest raw "
           "path excursion %.4f px\n", identities, n, moved, worst);
    CHECK_EQ_INT(moved, 0);
    CHECK(4 * identities >= 3 * n);
    CHECK_LT(worst, 0.05);
}

/* A tripod shot that pans `speed` px a frame over frames 21-34 and stands still before and
 * after it: the smoothed path of each frame, and its status, with the given lookahead. */
enum { TRIPOD_FRAMES = 60, TRIPOD_PAN_FROM = 20, TRIPOD_PAN_TO = 34 };

static void run_tripod_pan(int lookahead, double speed, home_stab_sim *smooth, int *status)
{
    static uint8_t frame[CW * CH * 3 / 2];
    home_stab *st = make_stab(lookahead, 1, 0);
    home_stab_output o;
    home_stab_image im;
    double pan_x = 0.0;
    int t, n = 0;
    CHECK(st != NULL);
    if (!st) return;
    for (t = 0; t < TRIPOD_FRAMES + lookahead; t++) {
        int rc;
        if (t < TRIPOD_FRAMES) {
            double h[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
            if (t > TRIPOD_PAN_FROM)
                pan_x = speed * ((t < TRIPOD_PAN_TO ? t : TRIPOD_PAN_TO) - TRIPOD_PAN_FROM);
            h[2] = -pan_x;
            synth_render(SYNTH_STRUCTURED, 9, h, 2.5, (uint64_t)t + 100, frame, CW, CH, CW);
            memset(frame + CW * CH, 128, CW * CH / 2);
            grey_image(frame, &im);
            rc = home_stab_push(st, &im, &o);
        } else {
            rc = home_stab_flush(st, &o);
        }
        CHECK_EQ_INT(rc, HOME_OK);
        if (rc == HOME_OK && o.ready && o.frame < TRIPOD_FRAMES) {
            smooth[o.frame] = o.smooth;
            status[o.frame] = o.motion_status;
            n++;
        }
    }
    CHECK_EQ_INT(n, TRIPOD_FRAMES);
}

/* Output motion from frame t - 1 to t where the raw path stands still: the smoothed path's. */
static double smoothed_step(const home_stab_sim *smooth, int t)
{
    return hypot(smooth[t].tx - smooth[t - 1].tx, smooth[t].ty - smooth[t - 1].ty) +
           fabs(smooth[t].angle - smooth[t - 1].angle) * CW;
}

/* Change of the output's motion at frame t (px a frame, a frame): its acceleration. */
static double smoothed_jerk(const home_stab_sim *smooth, int t)
{
    return hypot(smooth[t + 1].tx - 2.0 * smooth[t].tx + smooth[t - 1].tx,
                 smooth[t + 1].ty - 2.0 * smooth[t].ty + smooth[t - 1].ty);
}

/* With lookahead 15 the still stretches stay still in the output: the smoother used to take up
 * part of the pan there, easing in over the 15 frames before it started and out after it
 * stopped (2.7 px before the first frame of a move on a real clip). Only the still frames next
 * to the pan (13 before it and after it, pinned the more the farther) are eased over, so that a
 * pan that starts at full speed is not eased into within its first frames (with every still
 * frame pinned, the output's motion changed by 0.87 px a frame in a frame; now 0.63). Causal,
 * the path cannot see the end of the pan coming and must not jump onto the still frames after
 * it: it glides on. */
static void test_tripod_pan_keeps_still_frames(void)
{
    static home_stab_sim smooth[TRIPOD_FRAMES];
    static int status[TRIPOD_FRAMES];
    double before = 0.0, after = 0.0, causal = 0.0, jerk = 0.0;
    int t, ok = 0;
    run_tripod_pan(15, 3.0, smooth, status);
    for (t = 1; t < TRIPOD_FRAMES; t++) {
        ok += status[t] == HOME_STAB_MOTION_OK;
        if (t <= TRIPOD_PAN_FROM - 13 && smoothed_step(smooth, t) > before)
            before = smoothed_step(smooth, t);
        if (t > TRIPOD_PAN_TO + 1 + 13 && smoothed_step(smooth, t) > after)
            after = smoothed_step(smooth, t);
        if (t + 1 < TRIPOD_FRAMES && smoothed_jerk(smooth, t) > jerk)
            jerk = smoothed_jerk(smooth, t);
    }
    run_tripod_pan(0, 3.0, smooth, status);
    for (t = TRIPOD_PAN_TO + 1; t < TRIPOD_FRAMES; t++)
        if (smoothed_step(smooth, t) > causal) causal = smoothed_step(smooth, t);
    printf("    lookahead 15: %d of %d frames ok, largest output motion a frame %.4f px before "
           "the pan's ease, %.4f px after it, largest change of it %.2f px a frame; causal, "
           "after the pan: %.2f px\n", ok, TRIPOD_FRAMES - 1, before, after, jerk, causal);
    CHECK(ok >= TRIPOD_FRAMES - 3);
    CHECK_LT(before, 0.05);
    CHECK_LT(after, 0.05);
    CHECK_LT(jerk, 0.75);
    CHECK_LT(causal, 3.0);
}

/* A drift of 0.5 px a frame is no move to ease into: the still frames before and after it stay
 * pinned, and the output stands still there (easing them, it moved 0.24 px in a frame). */
static void test_slow_drift_keeps_still_frames(void)
{
    static home_stab_sim smooth[TRIPOD_FRAMES];
    static int status[TRIPOD_FRAMES];
    double still = 0.0;
    int t;
    run_tripod_pan(15, 0.5, smooth, status);
    for (t = 1; t < TRIPOD_FRAMES; t++)
        if ((t <= TRIPOD_PAN_FROM || t > TRIPOD_PAN_TO + 1) && smoothed_step(smooth, t) > still)
            still = smoothed_step(smooth, t);
    printf("    lookahead 15, a 0.5 px a frame drift: largest output motion a frame outside it "
           "%.4f px\n", still);
    CHECK_LT(still, 0.01);
}

/* A tripod shot of fog with textured objects crossing it, a live camera's frames (new noise in
 * every frame): one pair's background is too plain to refute the objects' motion, which HOME
 * then reports ok; the score tests of the frames around, summed, refute most of them, and a
 * motion that leaves a still part of the frame unexplained on a camera that was not moving is
 * taken as none too. Not all: two motions leave too little unexplained (a share of 0.07), and
 * the path still wanders that far. */
static void test_static_fog_with_objects(void)
{
    static uint8_t frame[CW * CH * 3 / 2];
    home_stab *st = make_stab(15, 1, 0);
    home_stab_output o;
    home_stab_image im;
    synth_rng rng;
    double worst = 0.0;
    int t, x, y, ok = 0, still = 0, n = 0;
    CHECK(st != NULL);
    if (!st) return;
    synth_seed(&rng, 91);
    for (t = 0; t < 60; t++) {
        for (y = 0; y < CH; y++)
            for (x = 0; x < CW; x++) {
                const double ridge = 0.45 * CH + 0.5 * sin(x / 50.0);
                /* a horizon and detail a tenth of the noise */
                const double v = 181.0 - 5.0 * tanh((y - ridge) / 4.0) +
                                 0.3 * (sin(x / 3.1 + y / 4.3) + sin(x / 5.3 - y / 2.9)) +
                                 2.5 * synth_gauss(&rng);
                frame[y * CW + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
            }
        memset(frame + CW * CH, 128, CW * CH / 2);
        for (y = 2 + t; y < 2 + t + 50 && y < CH; y++) /* two objects, (3, 1) px a frame */
            for (x = 5 + 3 * t; x < 5 + 3 * t + 70 && x < CW; x++)
                frame[y * CW + x] = (uint8_t)(((x - 3 * t) / 6 + (y - t) / 5) % 2 ? 200 : 60);
        for (y = 80 + t; y < 80 + t + 40 && y < CH; y++)
            for (x = 3 * t; x < 3 * t + 60 && x < CW; x++)
                frame[y * CW + x] = (uint8_t)(((x - 3 * t) / 5 + (y - t) / 7) % 2 ? 190 : 70);
        grey_image(frame, &im);
        CHECK_EQ_INT(home_stab_push(st, &im, &o), HOME_OK);
        if (o.ready) {
            const double d = fabs(o.raw.tx) + fabs(o.raw.ty) + fabs(o.raw.angle) * CW;
            if (d > worst) worst = d;
            n++;
            ok += o.motion_status == HOME_STAB_MOTION_OK;
            still += o.motion_status == HOME_STAB_MOTION_STILL;
        }
    }
    printf("    %d frames out: %d with a motion, %d held as still; largest raw path excursion "
           "%.2f px\n", n, ok, still, worst);
    /* without the summed tests: 37 motions, none held, 137 px; without the unexplained part
     * (dd50476): 27 held, 24.3 px */
    CHECK(2 * still >= n);
    CHECK_LT(worst, 12.0);
}

/* ---- the crop after the fact (home-stab's adaptive crop) ---- */

/* home_stab_crop_warp() gives push's own warp from its paths, byte for byte; through the share
 * of the margins home_stab_margin_share() reports the whole correction fits, and through a
 * smaller one it does not. */
static void test_crop_after_the_fact(void)
{
    home_stab_config cfg;
    home_stab *st = make_stab(6, 1, 0);
    home_stab_output o;
    home_stab_image im;
    int t, same = 1, fits = 1, tight = 1, n = 0;
    double smallest = 1.0;
    CHECK(st != NULL);
    if (!st) return;
    home_stab_default_config(&cfg, CW, CH);
    render_clip();
    for (t = 0; t < CLIP_FRAMES + 6; t++) {
        double w[9], used, share;
        if (t < CLIP_FRAMES) {
            grey_image(clip[t], &im);
            CHECK_EQ_INT(home_stab_push(st, &im, &o), HOME_OK);
        } else {
            CHECK_EQ_INT(home_stab_flush(st, &o), HOME_OK);
        }
        if (!o.ready) continue;
        n++;
        CHECK_EQ_INT(home_stab_crop_warp(&cfg, &o.raw, &o.smooth, w, &used), HOME_OK);
        same &= memcmp(w, o.warp, sizeof w) == 0 && used == o.correction_used;
        CHECK_EQ_INT(home_stab_margin_share(&cfg, &o.raw, &o.smooth, &share), HOME_OK);
        if (share < smallest) smallest = share;
        if (share < 1.0) {
            home_stab_config c = cfg;
            c.margin_x = (float)(share * cfg.margin_x);
            c.margin_y = (float)(share * cfg.margin_y);
            home_stab_crop_warp(&c, &o.raw, &o.smooth, w, &used);
            fits &= used == 1.0;
            c.margin_x = (float)((share - 0.02) * cfg.margin_x);
            c.margin_y = (float)((share - 0.02) * cfg.margin_y);
            if (share > 0.02) {
                home_stab_crop_warp(&c, &o.raw, &o.smooth, w, &used);
                tight &= used < 1.0;
            }
        }
    }
    printf("    %d frames: warps %s push's, smallest share of the margins needed %.3f\n", n,
           same ? "equal to" : "differ from", smallest);
    CHECK_EQ_INT(n, CLIP_FRAMES);
    CHECK(same);
    CHECK(fits);
    CHECK(tight);
    CHECK_LT(smallest, 1.0);
}

/* ---- scene cuts ---- */

/* Stabilise frames[0..n) (I420 buffers) with the given lookahead, calling home_stab_cut() before
 * frame cut_call (-1: never); the warp and the newest status per frame. 0 unless every frame
 * came out once, in order. */
static int run_frames(int lookahead, uint8_t *const *frames, int n, int cut_call,
                      double (*warp)[9], int *status)
{
    home_stab *st = make_stab(lookahead, 1, 0);
    home_stab_output o;
    home_stab_image im;
    int t, next = 0, ok = st != NULL;
    for (t = 0; ok && t < n; t++) {
        if (t == cut_call && home_stab_cut(st) != HOME_OK) ok = 0;
        grey_image(frames[t], &im);
        if (home_stab_push(st, &im, &o) != HOME_OK) { ok = 0; break; }
        status[t] = o.newest_status;
        if (!o.ready) continue;
        ok &= o.frame == next;
        memcpy(warp[next++], o.warp, sizeof o.warp);
    }
    while (ok && home_stab_flush(st, &o) == HOME_OK && o.ready) {
        ok &= o.frame == next;
        memcpy(warp[next++], o.warp, sizeof o.warp);
    }
    return ok && next == n;
}

#define CUT_AT 30

/* The stream cut at CUT_AT must give, byte for byte, the warps of its two parts stabilised as
 * separate streams: no smoothing window spans the cut and no frame after it is warped by the
 * motion before it (nor one before it by the motion after). */
static int cut_matches_parts(int lookahead, uint8_t *const *frames, int cut_call, int *status)
{
    static double whole[CLIP_FRAMES][9], part[CLIP_FRAMES][9];
    static int part_status[CLIP_FRAMES];
    int ok = run_frames(lookahead, frames, CLIP_FRAMES, cut_call, whole, status);
    ok &= run_frames(lookahead, frames, CUT_AT, -1, part, part_status);
    ok &= run_frames(lookahead, frames + CUT_AT, CLIP_FRAMES - CUT_AT, -1, part + CUT_AT,
                     part_status);
    return ok && memcmp(whole, part, sizeof whole) == 0;
}

static int count_cuts(const int *status, int n)
{
    int t, cuts = 0;
    for (t = 0; t < n; t++) cuts += status[t] == HOME_STAB_MOTION_CUT;
    return cuts;
}

/* A hard cut to another scene under the same shake is found at its frame, and only there, and
 * the path restarts there (causal and with a lookahead). */
static void test_cut_restarts_path(void)
{
    static uint8_t other[CLIP_FRAMES][CW * CH * 3 / 2];
    static int status[CLIP_FRAMES];
    uint8_t *frames[CLIP_FRAMES];
    static const int lookaheads[] = {0, 8};
    int t, k;
    render_clip();
    for (t = 0; t < CLIP_FRAMES; t++) {
        if (t >= CUT_AT) {
            synth_render(SYNTH_STRUCTURED, 4, clip_g[t], 1.0, (uint64_t)t + 500, other[t], CW,
                         CH, CW);
            memset(other[t] + CW * CH, 128, CW * CH / 2);
        }
        frames[t] = t < CUT_AT ? clip[t] : other[t];
    }
    for (k = 0; k < 2; k++) {
        const int same = cut_matches_parts(lookaheads[k], frames, -1, status);
        printf("    lookahead %d: %d cut(s) found, at frame %d: %s; warps %s the parts'\n",
               lookaheads[k], count_cuts(status, CLIP_FRAMES), CUT_AT,
               status[CUT_AT] == HOME_STAB_MOTION_CUT ? "yes" : "no",
               same ? "equal to" : "differ from");
        CHECK_EQ_INT(status[CUT_AT], HOME_STAB_MOTION_CUT);
        CHECK_EQ_INT(count_cuts(status, CLIP_FRAMES), 1);
        CHECK(same);
    }
}

/* home_stab_cut() restarts the path at the next frame, on a stream with no visible cut. */
static void test_caller_cut(void)
{
    static int status[CLIP_FRAMES];
    uint8_t *frames[CLIP_FRAMES];
    int t;
    render_clip();
    for (t = 0; t < CLIP_FRAMES; t++) frames[t] = clip[t];
    CHECK(cut_matches_parts(6, frames, CUT_AT, status));
    CHECK_EQ_INT(status[CUT_AT], HOME_STAB_MOTION_CUT);
    CHECK_EQ_INT(count_cuts(status, CLIP_FRAMES), 1);
}

/* Exposure steps of +-1 EV and a fade through black are not cuts: the path goes on. */
static void test_no_cut_on_exposure_or_fade(void)
{
    static uint8_t lit[CLIP_FRAMES][CW * CH * 3 / 2];
    static double warp[CLIP_FRAMES][9];
    static int status[CLIP_FRAMES];
    uint8_t *frames[CLIP_FRAMES];
    int t, i, held = 0;
    render_clip();
    for (t = 0; t < CLIP_FRAMES; t++) {
        /* x2 for frames 15..29, x0.5 for 30..44, a fade to black and back over 50..63 */
        double gain = t >= 15 && t < 30 ? 2.0 : t >= 30 && t < 45 ? 0.5 : 1.0;
        if (t >= 50 && t < 64) gain = fabs(t - 56.5) / 7.5;
        for (i = 0; i < CW * CH; i++) {
            const double v = gain * clip[t][i];
            lit[t][i] = (uint8_t)(v > 255.0 ? 255 : v + 0.5);
        }
        memset(lit[t] + CW * CH, 128, CW * CH / 2);
        frames[t] = lit[t];
    }
    CHECK(run_frames(8, frames, CLIP_FRAMES, -1, warp, status));
    for (t = 1; t < CLIP_FRAMES; t++) held += status[t] != HOME_STAB_MOTION_OK;
    printf("    %d cuts, %d frames held of %d\n", count_cuts(status, CLIP_FRAMES), held,
           CLIP_FRAMES - 1);
    CHECK_EQ_INT(count_cuts(status, CLIP_FRAMES), 0);
}

/* Push a grey frame (w x h luma, its I420 chroma planes after it set to 128; NULL: flush) and
 * keep the path and status of the frame reported. */
static int feed(home_stab *st, uint8_t *frame, int w, int h, home_stab_sim *raw, int *status)
{
    home_stab_image im;
    home_stab_output o;
    int rc;
    if (!frame) {
        rc = home_stab_flush(st, &o);
    } else {
        memset(frame + w * h, 128, (size_t)(w * h / 2));
        memset(&im, 0, sizeof im);
        im.format = HOME_STAB_I420;
        im.width = w;
        im.height = h;
        im.plane[0] = frame;
        im.plane[1] = frame + w * h;
        im.plane[2] = frame + w * h + w * h / 4;
        im.stride[0] = w;
        im.stride[1] = im.stride[2] = w / 2;
        rc = home_stab_push(st, &im, &o);
    }
    if (rc == HOME_OK && o.ready) {
        raw[o.frame] = o.raw;
        status[o.frame] = o.motion_status;
    }
    return rc;
}

/* Corner error of the path from frame i to frame j (raw(j) raw(i)^-1) against the camera's. */
static double path_error(const home_stab_sim *raw, double (*g)[9], int i, int j, int w, int h)
{
    double a[9], b[9], inv[9], got[9], want[9];
    int c, r, k;
    home_stab_sim_to_matrix(&raw[j], w, h, a);
    home_stab_sim_to_matrix(&raw[i], w, h, b);
    synth_invert(b, inv);
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++)
            for (got[3 * r + c] = 0, k = 0; k < 3; k++) got[3 * r + c] += a[3 * r + k] * inv[3 * k + c];
    synth_invert(g[i], inv);
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++)
            for (want[3 * r + c] = 0, k = 0; k < 3; k++) want[3 * r + c] += g[j][3 * r + k] * inv[3 * k + c];
    return synth_corner_error(got, want, w, h);
}

/* A dark blurred hand at the lens (bench/stab/realworld.py's, smaller: frames 20..51 over the
 * lower left), 640x360, camera shaking by shake_px (0: on a tripod). Counts the frames restored
 * and held, and the worst corner error of a restored motion against the camera's. */
static int hand_at_lens(double shake_px, int *held, double *worst)
{
    enum { HW = 640, HH = 360, FRAMES = 60, LOOKAHEAD = 8 };
    static uint8_t frame[HW * HH * 3 / 2];
    static double g[FRAMES][9];
    static home_stab_sim raw[FRAMES];
    static int status[FRAMES];
    const stab_clip_motion motion = {FRAMES, shake_px, shake_px / 10.0, shake_px * 13.0, 5};
    home_stab_config cfg;
    home_stab *st = NULL;
    int t, i, restored = 0;
    home_stab_default_config(&cfg, HW, HH);
    cfg.lookahead = LOOKAHEAD;
    *held = 0;
    *worst = 0.0;
    CHECK_EQ_INT(home_stab_init(&st, &cfg, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes),
                                NULL), HOME_OK);
    if (!st) return 0;
    for (t = 0; t < FRAMES + LOOKAHEAD; t++) {
        if (t < FRAMES) {
            const int k = t - 20;
            const double cover = k < 0 || k > 31 ? 0.0 : fmin(fmin(k / 4.0, (31 - k) / 4.0), 1.0);
            const double cx = -0.25 * HW + 0.45 * HW * cover + 3.0 * sin(0.7 * k);
            const double cy = 1.2 * HH - 0.3 * HH * cover + 2.0 * cos(0.5 * k);
            double intent[9];
            stab_clip_camera(&motion, t, HW, HH, g[t], intent);
            synth_render(SYNTH_STRUCTURED, 1, g[t], 2.0, (uint64_t)t + 1, frame, HW, HH, HW);
            for (i = 0; cover > 0.0 && i < HW * HH; i++) {
                const double dx = (i % HW - cx) / (0.2 * HW), dy = (i / HW - cy) / (0.35 * HH);
                const double m = 0.5 - 0.5 * tanh((sqrt(dx * dx + dy * dy) - 1.0) * 0.35 * HH / 25.0);
                frame[i] = (uint8_t)(m * (22.0 + 10.0 * (i / HW) / HH) + (1.0 - m) * frame[i] + 0.5);
            }
        }
        CHECK_EQ_INT(feed(st, t < FRAMES ? frame : NULL, HW, HH, raw, status), HOME_OK);
    }
    for (t = 1; t < FRAMES; t++) {
        /* the motion taken against the camera's */
        double err;
        if (status[t] == HOME_STAB_MOTION_FAILED) ++*held;
        if (status[t] != HOME_STAB_MOTION_RESTORED) continue;
        restored++;
        err = path_error(raw, g, t - 1, t, HW, HH);
        if (err > *worst) *worst = err;
    }
    return restored;
}

/* Two flat frames (20, 21) in a shaking clip: no registration to or from them, so frames 20-22
 * are held. Frame 22 registers to frame 19, the last before the hold, and the three share the
 * motion that closes the gap (bridged): the path from 19 to 22 is the camera's, not short of
 * the three frames' shake (without the bridge it is the identity). A longer hold is not
 * bridged. */
static void test_hold_bridged(void)
{
    enum { HW = 640, HH = 360, FRAMES = 40, LOOKAHEAD = 8 };
    static uint8_t frame[HW * HH * 3 / 2];
    static double g[FRAMES][9];
    static home_stab_sim raw[FRAMES];
    static int status[FRAMES];
    const stab_clip_motion motion = {FRAMES, 4.0, 0.4, 52.0, 5};
    int flat_last;
    for (flat_last = 21; flat_last <= 25; flat_last += 4) {
        home_stab_config cfg;
        home_stab *st = NULL;
        double err, shake;
        int t;
        home_stab_default_config(&cfg, HW, HH);
        cfg.lookahead = LOOKAHEAD;
        CHECK_EQ_INT(home_stab_init(&st, &cfg, ALIGNED_ARENA(arena.bytes),
                                    ALIGNED_BYTES(arena.bytes), NULL), HOME_OK);
        if (!st) return;
        for (t = 0; t < FRAMES + LOOKAHEAD; t++) {
            if (t < FRAMES) {
                double intent[9];
                stab_clip_camera(&motion, t, HW, HH, g[t], intent);
                synth_render(SYNTH_STRUCTURED, 1, g[t], 2.0, (uint64_t)t + 1, frame, HW, HH, HW);
                if (t >= 20 && t <= flat_last) memset(frame, 100, HW * HH);
            }
            CHECK_EQ_INT(feed(st, t < FRAMES ? frame : NULL, HW, HH, raw, status), HOME_OK);
        }
        err = path_error(raw, g, 19, flat_last + 1, HW, HH);
        {
            const home_stab_sim none = {0, 0, 0, 0};
            home_stab_sim still[FRAMES];
            for (t = 0; t < FRAMES; t++) still[t] = none;
            shake = path_error(still, g, 19, flat_last + 1, HW, HH);
        }
        printf("    frames 20-%d flat: frame %d %s, path 19 -> %d %.2f px off (the camera "
               "moved %.2f px)\n", flat_last, flat_last + 1,
               status[flat_last + 1] == HOME_STAB_MOTION_BRIDGED ? "bridged" : "held",
               flat_last + 1, err, shake);
        if (flat_last == 21) {
            for (t = 20; t <= 22; t++) CHECK_EQ_INT(status[t], HOME_STAB_MOTION_BRIDGED);
            CHECK_LT(err, 1.5); /* HOME's lines alone: the anchor's refinement snapshot is gone */
            CHECK(shake > 10.0); /* the hold would have left that much */
        } else {
            CHECK(status[flat_last + 1] != HOME_STAB_MOTION_BRIDGED);
        }
    }
}

/* Causal, the path cannot see past a hold: a held frame's motion is taken as none and the path
 * stands still with it, so the frame keeps the correction of the frame before and its output
 * moves as its input did. A path that glided on through the hold would add its own motion to
 * the camera's (a camera sweeping 10-20 px a frame over two long edges came out shakier than
 * it went in). A pan of 5 px a frame, frames 30-33 flat. */
static void test_held_frame_keeps_correction(void)
{
    enum { FRAMES = 48, FLAT_FROM = 30, FLAT_TO = 33 };
    static uint8_t frame[CW * CH * 3 / 2];
    home_stab *st = make_stab(0, 1, 0);
    home_stab_output o;
    home_stab_image im;
    home_stab_sim prev_smooth = {0, 0, 0, 0};
    double prev_warp[6] = {0, 0, 0, 0, 0, 0}, worst_held = 0.0, path_speed = 1e9;
    int t, held = 0;
    CHECK(st != NULL);
    if (!st) return;
    for (t = 0; t < FRAMES; t++) {
        double h[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, step;
        h[2] = -5.0 * t;
        synth_render(SYNTH_STRUCTURED, 3, h, 1.0, (uint64_t)t + 7, frame, CW, CH, CW);
        if (t >= FLAT_FROM && t <= FLAT_TO) memset(frame, 100, CW * CH);
        memset(frame + CW * CH, 128, CW * CH / 2);
        grey_image(frame, &im);
        CHECK_EQ_INT(home_stab_push(st, &im, &o), HOME_OK);
        CHECK(o.ready && o.frame == t);
        step = hypot(o.warp[2] - prev_warp[2], o.warp[5] - prev_warp[5]);
        if (o.motion_status == HOME_STAB_MOTION_FAILED ||
            o.motion_status == HOME_STAB_MOTION_IMPLAUSIBLE) {
            held++;
            if (step > worst_held) worst_held = step;
        } else if (t > 10 && t < FLAT_FROM) { /* the path's own motion: it pans with the camera */
            const double v = hypot(o.smooth.tx - prev_smooth.tx, o.smooth.ty - prev_smooth.ty);
            if (v < path_speed) path_speed = v;
        }
        memcpy(prev_warp, o.warp, sizeof prev_warp);
        prev_smooth = o.smooth;
    }
    printf("    %d frames held, their correction moved at most %.2g px (the path moves at least "
           "%.2f px a frame before the hold)\n", held, worst_held, path_speed);
    CHECK(held >= 4);
    CHECK_LT(worst_held, 1e-6);
    CHECK(path_speed > 4.0);
}

/* With the camera shaking, HOME refuses motions the hand's plain area does not show; where the
 * frames around them register a moving camera, the stabiliser takes them (restored), and each
 * is the camera's motion, not the hand's. On a tripod the same hand restores nothing. */
static void test_hand_at_lens_followed(void)
{
    int held, restored;
    double worst;
    restored = hand_at_lens(3.0, &held, &worst);
    printf("    shaking: %d frames restored (worst %.2f px from the camera's motion), %d held\n",
           restored, worst, held);
    CHECK(restored >= 4);
    CHECK_LT(worst, 0.5);
    restored = hand_at_lens(0.0, &held, &worst);
    printf("    on a tripod: %d frames restored, %d held\n", restored, held);
    CHECK_EQ_INT(restored, 0);
}

/* A textured board sliding 2 px a frame over half of a shaking camera's view (in at frames
 * 20-27, out at 48-55): HOME registers consecutive frames by the board, and before key frames
 * the path followed it (36 px off the camera's by frame 47). Registered against the frame
 * before the board came wherever a frame's motion leaves a part unexplained, the path stays
 * on the camera: within 0.5 px on most of the frames the board slides over, and within 10 px
 * (a held frame beside a corrected one) on every frame. */
static void test_object_does_not_steer(void)
{
    enum { HW = 640, HH = 360, FRAMES = 60, LOOKAHEAD = 15 };
    static uint8_t frame[HW * HH * 3 / 2];
    static double g[FRAMES][9];
    static home_stab_sim raw[FRAMES];
    static int status[FRAMES];
    const stab_clip_motion motion = {FRAMES, 4.0, 0.2, 30.0, 9};
    home_stab_config cfg;
    home_stab *st = NULL;
    double worst = 0.0;
    int t, x, y, k, close = 0;
    home_stab_default_config(&cfg, HW, HH);
    cfg.lookahead = LOOKAHEAD;
    CHECK_EQ_INT(home_stab_init(&st, &cfg, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes),
                                NULL), HOME_OK);
    if (!st) return;
    for (t = 0; t < FRAMES + LOOKAHEAD; t++) {
        if (t < FRAMES) {
            double intent[9];
            stab_clip_camera(&motion, t, HW, HH, g[t], intent);
            synth_render(SYNTH_STRUCTURED, 3, g[t], 2.0, (uint64_t)t + 1, frame, HW, HH, HW);
            if (t >= 20 && t <= 55) {
                const int x0 = t < 28   ? HW - 40 * (t - 19)
                               : t <= 47 ? HW - 320 - 2 * (t - 28)
                                         : HW - 358 - 40 * (t - 47);
                /* a band-limited texture, moving with the board: only where it is */
                for (y = 20; y < HH - 20; y++)
                    for (x = x0 < 0 ? 0 : x0; x < x0 + 320 && x < HW; x++) {
                        double v = 128.0;
                        for (k = 0; k < 12; k++)
                            v += (6.0 + 2.0 * (k % 4)) *
                                 sin((x - x0) * (0.11 + 0.07 * (k % 5)) * cos(0.5 * k) +
                                     y * (0.11 + 0.07 * (k % 5)) * sin(0.5 * k) + k);
                        frame[y * HW + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
                    }
            }
        }
        CHECK_EQ_INT(feed(st, t < FRAMES ? frame : NULL, HW, HH, raw, status), HOME_OK);
    }
    for (t = 20; t < 50; t++) {
        const double err = path_error(raw, g, 19, t, HW, HH);
        if (err > worst) worst = err;
        if (t >= 29 && t <= 47) close += err < 0.5;
    }
    printf("    board over half the frame: path within %.2f px of the camera's over frames "
           "20-49, within 0.5 px on %d of the 19 frames it slides over\n", worst, close);
    CHECK_LT(worst, 10.0);
    CHECK(close >= 10);
}

#define STAB_TESTS(X) \
    X(api_contract) X(row_kernel_edges) X(warp_identity_and_shift) X(warp_matches_reference) \
    X(warp_formats_agree) X(warp_bands_match_whole) X(jitter_reduced_causal) X(horizon_in_fog_partial) X(lookahead_latency_and_gain) X(more_latency_never_shakier) X(refine_ending_at_half_size) \
    X(downscaled_registration) X(fewer_theta_bins) X(hold_on_failure) X(implausible_jump_held) X(ends_mirrored) \
    X(deterministic) X(static_camera_moving_object) X(tripod_pan_keeps_still_frames) X(slow_drift_keeps_still_frames) X(static_fog_with_objects) X(cut_restarts_path) X(caller_cut) \
    X(no_cut_on_exposure_or_fade) X(crop_after_the_fact) X(hand_at_lens_followed) X(object_does_not_steer) X(hold_bridged) \
    X(held_frame_keeps_correction)
#define ENTRY(name) {#name, test_##name},
static const test_case tests[] = {STAB_TESTS(ENTRY)};

int main(int argc, char **argv)
{
    return test_run(tests, sizeof tests / sizeof tests[0], "stab_", argc, argv);
}
#else
typedef int home_stab_tests_not_built; /* ISO C forbids an empty translation unit */
#endif
