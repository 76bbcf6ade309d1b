/* home-register: register two grey PGM images with HOME and print one line of JSON.
 *   {"ok":true,"H":[9 numbers],"keypoints":[nA,nB],"matches":m,"inliers":k,"ms":{...}}
 * H maps A's pixel coordinates to B's (h22 = 1). Exit 0 after a registration (ok or not),
 * 2 on unreadable or malformed input or bad options. */
#define _POSIX_C_SOURCE 200809L
#include "home.h"
#include "pgm.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double clock_ms(void *user)
{
    struct timespec ts;
    (void)user;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static void usage(FILE *f)
{
    fprintf(f,
        "usage: home-register [options] A.pgm B.pgm\n"
        "Registers binary PGM image A (P5, 8-bit) to B of the same size (%d..%d px a side) and\n"
        "prints one JSON line: ok, H (A -> B pixels, row-major, h22 = 1), keypoints, matches,\n"
        "inliers, ms. Exit 0 after a registration (\"ok\":false when it failed), 2 on bad input.\n"
        "options (applied in this order after the defaults):\n"
        "  --video              start from the video-frame defaults (home_video_config): Hough\n"
        "                       on a frame ~160 px wide, 120 theta bins, 500 keypoints, theta\n"
        "                       window 8, first threshold 8; the refinement with 2048 points,\n"
        "                       ending at half size\n"
        "  --keypoints N        keypoints kept per sign of J (default 1000, max %d)\n"
        "  --theta-bins N       Hough theta bins over [0, pi) (default 480)\n"
        "  --r-step PX          px per Hough r bin (default 1.0)\n"
        "  --sigma BINS         Gaussian smoothing of the Hough image (default 1.3)\n"
        "  --hough-downscale N  1: Hough transform of the full image (default); 2 or 4: of a\n"
        "                       2x2- or 4x4-box downscaled copy (4x or 16x less Hough work)\n"
        "  --fast-pass N        0: one pass; 2 or 4: first a fast pass (Hough of a 2x2- or\n"
        "                       4x4-box downscaled copy, half the theta bins and keypoints),\n"
        "                       the full one when it is not ok or not within 0.2 px (default\n"
        "                       4 from 640x128 up, else 0; --video 0; ignored with\n"
        "                       --save-hough); \"fast_pass\" says which answered\n"
        "  --theta-window N     motion prior: match only keypoints within N theta bins of each\n"
        "                       other (0 = off, the default; --video: 8 of 120 bins = 12 degrees)\n"
        "  --ratio R            Lowe ratio test (default 0.9)\n"
        "  --threshold T        final inlier threshold in Hough pixels (default 1.0)\n"
        "  --threshold-start T  first inlier threshold, halved down to the final (default 64)\n"
        "  --min-inliers N      fewer final inliers means failure (default 20)\n"
        "  --no-refine          keep HOME's homography (no photometric refinement)\n"
        "  --refine-levels N    refinement pyramid levels (default 3)\n"
        "  --refine-iterations N  Gauss-Newton iteration cap per level (default 10; the\n"
        "                       finest level up to 4x while its steps shrink slowly)\n"
        "  --refine-points N    refinement template points at full size, halved per level\n"
        "                       (default 4096, 64..4096)\n"
        "  --refine-finest L    pyramid level the refinement ends at: 0 full size (default),\n"
        "                       1 half size (--video's; about half the refinement's cost)\n"
        "  --max-model M        most general motion model: identity, translation, similarity,\n"
        "                       affine or homography (default); the simplest the data support\n"
        "                       is reported as \"model\"\n"
        "  --max-sigma PX       ok needs a predicted RMS corner error (\"sigma_px\") at most\n"
        "                       this (default 1)\n"
        "  --refine-trust PX    largest corner motion the refinement may make, in Hough-image\n"
        "                       px (default 6)\n"
        "  --repeat N           register N times; ms are medians, plus \"frame\": one new frame\n"
        "                       registered against the previous one's cached features (the\n"
        "                       video case: B, A, B, ... alternately)\n"
        "  --exact              every digit of H, sigma_px and the refinement's scores, no\n"
        "                       timings (byte-comparable output)\n"
        "  --save-hough F.pgm   write A's quantised Hough image (rows theta, columns r) with\n"
        "                       its keypoints marked (white: J > 0, black: J < 0)\n"
        "  --help               this text\n",
        HOME_MIN_SIDE, HOME_MAX_SIDE, HOME_MAX_KEYPOINTS_PER_SIGN);
}

static int parse_int(const char *s, int *out)
{
    char *end;
    long v;
    errno = 0;
    v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < -1000000 || v > 1000000) return -1;
    *out = (int)v;
    return 0;
}

static int parse_float(const char *s, float *out)
{
    char *end;
    double v;
    errno = 0;
    v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return -1;
    *out = (float)v;
    return 0;
}

static int load(const char *path, uint8_t **buf, const uint8_t **pixels, int *w, int *h)
{
    char err[128];
    size_t size = 0;
    *buf = pgm_read_file(path, &size, err, sizeof err);
    if (!*buf) {
        fprintf(stderr, "home-register: %s: %s\n", path, err);
        return -1;
    }
    if (pgm_parse(*buf, size, HOME_MAX_SIDE, w, h, pixels, err, sizeof err) != 0) {
        fprintf(stderr, "home-register: %s: %s\n", path, err);
        return -1;
    }
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static int save_hough(home_context *ctx, const uint8_t *img, int w, const char *path)
{
    const home_features *fa = home_last_features(ctx, 0);
    int hw, hh, i, d;
    uint8_t *out;
    home_hough_size(ctx, &hw, &hh);
    out = (uint8_t *)malloc((size_t)hw * hh);
    if (!out) return -1;
    home_render_hough(ctx, img, w, out, hw);
    for (i = 0; fa && i < fa->n_pos + fa->n_neg; i++) {
        float col, row;
        uint8_t v = fa->kp[i].sign > 0 ? 255 : 0;
        home_keypoint_to_hough(ctx, &fa->kp[i], &col, &row);
        for (d = -2; d <= 2; d++) {       /* a small plus sign */
            int c = (int)lroundf(col), r = (int)lroundf(row);
            if (r >= 0 && r < hh && c + d >= 0 && c + d < hw) out[(size_t)r * hw + c + d] = v;
            if (c >= 0 && c < hw && r + d >= 0 && r + d < hh) out[(size_t)(r + d) * hw + c] = v;
        }
    }
    i = pgm_write(path, out, hw, hh, hw);
    free(out);
    return i;
}

int main(int argc, char **argv)
{
    const char *paths[2] = {NULL, NULL}, *hough_path = NULL;
    home_config cfg;
    int n_paths = 0, i, repeat = 1, status, s, video = 0, exact = 0;
    int opt_kp = -1, opt_theta = -1, opt_min_in = -1, opt_rlevels = -1, opt_riters = -1, opt_rpoints = -1, opt_downscale = -1, opt_fast = -1,
        opt_window = -1, opt_rfinest = -1, opt_max_model = -1;
    float opt_rtrust = -1, opt_max_sigma = -1;
    float opt_ratio = -1, opt_thr = -1, opt_thr0 = -1, opt_rstep = -1, opt_sigma = -1;
    uint8_t *buf_a = NULL, *buf_b = NULL;
    const uint8_t *pa, *pb;
    int wa, ha, wb, hb;
    void *arena_mem, *arena;
    size_t arena_bytes;
    home_context *ctx;
    home_result res;
    double *samples, ms[HOME_STAGE_COUNT], frame_ms = 0.0;
    static const char *stage_names[HOME_STAGE_COUNT] = {"hough", "detect", "describe", "match",
                                                        "homography", "refine", "total"};

    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        int bad = 0;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(stdout); return 0; }
        if (!strcmp(a, "--no-refine")) { opt_rlevels = 0; continue; }
        if (!strcmp(a, "--video")) { video = 1; continue; }
        if (!strcmp(a, "--exact")) { exact = 1; continue; }
        if (!strncmp(a, "--", 2) && !v) { fprintf(stderr, "home-register: %s needs a value\n", a); return 2; }
        if (!strcmp(a, "--keypoints")) bad = parse_int(v, &opt_kp), i++;
        else if (!strcmp(a, "--theta-bins")) bad = parse_int(v, &opt_theta), i++;
        else if (!strcmp(a, "--min-inliers")) bad = parse_int(v, &opt_min_in), i++;
        else if (!strcmp(a, "--refine-levels")) bad = parse_int(v, &opt_rlevels), i++;
        else if (!strcmp(a, "--refine-iterations")) bad = parse_int(v, &opt_riters), i++;
        else if (!strcmp(a, "--refine-points")) bad = parse_int(v, &opt_rpoints), i++;
        else if (!strcmp(a, "--refine-finest")) bad = parse_int(v, &opt_rfinest), i++;
        else if (!strcmp(a, "--refine-trust")) bad = parse_float(v, &opt_rtrust), i++;
        else if (!strcmp(a, "--max-sigma")) bad = parse_float(v, &opt_max_sigma), i++;
        else if (!strcmp(a, "--max-model")) {
            for (opt_max_model = HOME_MODEL_HOMOGRAPHY; opt_max_model >= 0; opt_max_model--)
                if (!strcmp(v, home_model_name(opt_max_model))) break;
            bad = opt_max_model < 0;
            i++;
        }
        else if (!strcmp(a, "--repeat")) bad = parse_int(v, &repeat) || repeat < 1 || repeat > 10000, i++;
        else if (!strcmp(a, "--ratio")) bad = parse_float(v, &opt_ratio), i++;
        else if (!strcmp(a, "--threshold")) bad = parse_float(v, &opt_thr), i++;
        else if (!strcmp(a, "--threshold-start")) bad = parse_float(v, &opt_thr0), i++;
        else if (!strcmp(a, "--r-step")) bad = parse_float(v, &opt_rstep), i++;
        else if (!strcmp(a, "--sigma")) bad = parse_float(v, &opt_sigma), i++;
        else if (!strcmp(a, "--hough-downscale")) bad = parse_int(v, &opt_downscale), i++;
        else if (!strcmp(a, "--fast-pass")) bad = parse_int(v, &opt_fast), i++;
        else if (!strcmp(a, "--theta-window")) bad = parse_int(v, &opt_window), i++;
        else if (!strcmp(a, "--save-hough")) hough_path = v, i++;
        else if (!strncmp(a, "--", 2)) { fprintf(stderr, "home-register: unknown option %s\n", a); usage(stderr); return 2; }
        else if (n_paths < 2) paths[n_paths++] = a;
        else { fprintf(stderr, "home-register: too many arguments\n"); return 2; }
        if (bad) { fprintf(stderr, "home-register: bad value for %s\n", a); return 2; }
    }
    if (n_paths != 2) { usage(stderr); return 2; }
    if (load(paths[0], &buf_a, &pa, &wa, &ha) || load(paths[1], &buf_b, &pb, &wb, &hb)) {
        free(buf_a); free(buf_b);
        return 2;
    }
    if (wa != wb || ha != hb) {
        fprintf(stderr, "home-register: images differ in size (%dx%d vs %dx%d)\n", wa, ha, wb, hb);
        free(buf_a); free(buf_b);
        return 2;
    }
    if ((status = (video ? home_video_config : home_default_config)(&cfg, wa, ha)) != HOME_OK) {
        fprintf(stderr, "home-register: %dx%d: %s\n", wa, ha, home_strerror(status));
        free(buf_a); free(buf_b);
        return 2;
    }
    if (opt_kp >= 0) cfg.keypoints_per_sign = opt_kp;
    if (opt_theta >= 0) cfg.theta_bins = opt_theta;
    if (opt_min_in >= 0) cfg.min_inliers = opt_min_in;
    if (opt_ratio >= 0) cfg.ratio = opt_ratio;
    if (opt_thr >= 0) cfg.threshold_final = opt_thr;
    if (opt_thr0 >= 0) cfg.threshold_start = opt_thr0;
    if (opt_rstep >= 0) cfg.r_step = opt_rstep;
    if (opt_sigma >= 0) cfg.smooth_sigma = opt_sigma;
    if (opt_downscale >= 0) cfg.hough_downscale = opt_downscale;
    if (opt_window >= 0) cfg.match_theta_window = opt_window;
    if (opt_fast >= 0) cfg.fast_pass_downscale = opt_fast;
    if (hough_path) cfg.fast_pass_downscale = 0; /* the saved keypoints are the full pass's */
    if (opt_rlevels >= 0) cfg.refine_levels = opt_rlevels;
    if (opt_riters >= 0) cfg.refine_iterations = opt_riters;
    if (opt_rpoints >= 0) cfg.refine_points = opt_rpoints;
    if (opt_rfinest >= 0) cfg.refine_finest_level = opt_rfinest;
    if (opt_rtrust >= 0) cfg.refine_trust_px = opt_rtrust;
    if (opt_max_sigma >= 0) cfg.max_sigma_px = opt_max_sigma;
    if (opt_max_model >= 0) cfg.max_model = opt_max_model;
    if (cfg.wrap_band > cfg.theta_bins / 4) cfg.wrap_band = cfg.theta_bins / 18;
    cfg.clock = clock_ms;
    if ((status = home_validate_config(&cfg)) != HOME_OK) {
        fprintf(stderr, "home-register: options: %s\n", home_strerror(status));
        free(buf_a); free(buf_b);
        return 2;
    }
    arena_bytes = home_arena_size(&cfg);
    arena_mem = malloc(arena_bytes + HOME_ARENA_ALIGN); /* C99 has no aligned_alloc */
    arena = arena_mem ? (void *)(((uintptr_t)arena_mem + HOME_ARENA_ALIGN - 1) &
                                 ~(uintptr_t)(HOME_ARENA_ALIGN - 1)) : NULL;
    samples = (double *)malloc(sizeof(double) * (size_t)repeat * (HOME_STAGE_COUNT + 1));
    if (!arena || !samples) { fprintf(stderr, "home-register: out of memory\n"); return 2; }
    if ((status = home_init(&ctx, &cfg, arena, arena_bytes, NULL)) != HOME_OK) {
        fprintf(stderr, "home-register: %s\n", home_strerror(status));
        return 2;
    }

    for (i = 0; i < repeat; i++) {
        if ((status = home_register(ctx, pa, wa, pb, wb, &res)) != HOME_OK) {
            fprintf(stderr, "home-register: %s\n", home_strerror(status));
            return 2;
        }
        for (s = 0; s < HOME_STAGE_COUNT; s++) samples[(size_t)s * repeat + i] = res.ms[s];
    }
    for (s = 0; s < HOME_STAGE_COUNT; s++) ms[s] = median(samples + (size_t)s * repeat, repeat);
    if (repeat > 1) {
        /* the video case: a clip alternating B, A, B, ...: each step extracts the new frame
         * and registers it against the previous one, whose features and refinement snapshot
         * are cached (registering against a frame two steps back would find no snapshot) */
        static home_features fa, fb;
        home_result fr;
        home_extract(ctx, pa, wa, &fa);
        for (i = 0; i < repeat; i++) {
            const int odd = i % 2;
            double t0 = clock_ms(NULL);
            home_extract(ctx, odd ? pa : pb, odd ? wa : wb, odd ? &fa : &fb);
            home_match(ctx, odd ? &fb : &fa, odd ? &fa : &fb, &fr);
            samples[i] = clock_ms(NULL) - t0;
        }
        frame_ms = median(samples, repeat);
        home_register(ctx, pa, wa, pb, wb, &res); /* restore the slots for --save-hough */
    }
    if (hough_path && save_hough(ctx, pa, wa, hough_path) != 0) {
        fprintf(stderr, "home-register: cannot write %s\n", hough_path);
        return 2;
    }

    printf("{\"ok\":%s", res.ok ? "true" : "false");
    if (res.ok || res.failure != 0) {
        printf(",\"H\":[");
        for (i = 0; i < 9; i++) printf("%s%.*g", i ? "," : "", exact ? 17 : 10, res.H[i]);
        printf("]");
    }
    printf(",\"keypoints\":[%d,%d],\"matches\":%d,\"inliers\":%d,\"refined\":%s",
           res.keypoints_a, res.keypoints_b, res.matches, res.inliers,
           res.refined ? "true" : "false");
    printf(",\"model\":\"%s\",\"sigma_px\":", home_model_name(res.model));
    if (isfinite(res.sigma_px)) printf("%.*g", exact ? 17 : 6, res.sigma_px);
    else printf("null"); /* not determined: JSON has no infinity */
    printf(",\"failure\":\"%s\",\"refine_status\":\"%s\",\"fast_pass\":%s",
           home_failure_name(res.failure), home_refine_status_name(res.refine_status),
           res.fast_pass ? "true" : "false");
    if (exact) { /* every digit, no timings: byte-comparable output (tests/checks/golden.sh) */
        printf(",\"refine_zncc\":%.17g,\"refine_inlier_share\":%.17g}\n", res.refine_zncc,
               res.refine_inlier_share);
    } else {
        printf(",\"refine_zncc\":%.4f,\"refine_inlier_share\":%.4f,\"ms\":{", res.refine_zncc,
               res.refine_inlier_share);
        for (s = 0; s < HOME_STAGE_COUNT; s++)
            printf("%s\"%s\":%.3f", s ? "," : "", stage_names[s], ms[s]);
        if (repeat > 1) printf(",\"frame\":%.3f", frame_ms);
        printf("}}\n");
    }
    free(samples);
    free(arena_mem);
    free(buf_a);
    free(buf_b);
    return 0;
}
