/* The bad-input table: every misuse and malformed input libhome and its tools must refuse, each
 * with the exact status it must give. One row per case: name, expected value, the call. Rows run
 * on a fresh fixture (a valid 64x64 config, context, images and extracted features), so each row
 * shows a single thing wrong. Also the test runner of home-hardening-tests: `NAME...` runs a
 * subset, `--list` prints the table. */
#define _POSIX_C_SOURCE 200809L
#include "test.h"
#include "test_bad_input.h"
#include "home.h"
#include "pgm.h"
#include "synth.h"
#include "y4m.h"
#include "home_stab.h"
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <string.h>


#define W 64
#define H 64

/* fixture */
static home_config cfg, bad;
static home_context *ctx, *ctx_other;
static home_result res;
static home_features fa, fb;
static uint8_t img_a[W * H], img_b[W * H], img_other[(W + 32) * H], hough[1 << 16];
static union { unsigned char bytes[4u << 20]; double align; } arena, arena_other;
static union { unsigned char bytes[256]; double align; } junk;
static size_t needed;
static home_stab_config scfg, sbad;
static home_stab_sim ssim;
static home_stab *stab;
static home_stab_image sframe, sdst;
static home_stab_output sout;
static union { unsigned char bytes[8u << 20]; double align; } stab_arena;
static double warp_m[9];
static float col, row;
static double h_init[9];
static int hw, hh;

static void fixture(void)
{
    static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    home_default_config(&cfg, W, H);
    cfg.keypoints_per_sign = 200; /* below the capacity, so a count can exceed one but not the other */
    bad = cfg;
    ctx = ctx_other = NULL;
    needed = 0;
    if (home_init(&ctx, &cfg, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes), NULL) != HOME_OK) ctx = NULL;
    synth_render(SYNTH_STRUCTURED, 3, identity, 0.0, 1, img_a, W, H, W);
    memcpy(img_b, img_a, sizeof img_a);
    memset(&fa, 0, sizeof fa);
    memset(&fb, 0, sizeof fb);
    if (ctx) {
        home_extract(ctx, img_a, W, &fa);
        home_extract(ctx, img_b, W, &fb);
    }
    memset(junk.bytes, 0x5a, sizeof junk.bytes);
    memset(h_init, 0, sizeof h_init);
    h_init[0] = h_init[4] = h_init[8] = 1.0;
    memcpy(warp_m, h_init, sizeof warp_m);
    home_stab_default_config(&scfg, W, H);
    sbad = scfg;
    memset(&ssim, 0, sizeof ssim);
    stab = NULL;
    if (home_stab_init(&stab, &scfg, ALIGNED_ARENA(stab_arena.bytes), ALIGNED_BYTES(stab_arena.bytes), NULL) != HOME_OK) ctx = NULL;
    memset(&sframe, 0, sizeof sframe);
    sframe.format = HOME_STAB_GREY;
    sframe.width = W;
    sframe.height = H;
    sframe.plane[0] = img_a;
    sframe.stride[0] = W;
    sdst = sframe;
    sdst.plane[0] = img_b;
}

/* a 4:2:0 frame whose chroma planes point into img_b */
static int push_i420(int drop_chroma)
{
    sframe.format = HOME_STAB_I420;
    sframe.plane[1] = drop_chroma ? NULL : img_b;
    sframe.plane[2] = img_b + W * H / 4;
    sframe.stride[1] = sframe.stride[2] = W / 2;
    return home_stab_push(stab, &sframe, &sout);
}

/* a band of an I420 warp (source chroma in img_b, destination chroma after it) */
static int warp_rows_i420(int first_row, int rows)
{
    sframe.format = sdst.format = HOME_STAB_I420;
    sframe.plane[1] = img_b;
    sframe.plane[2] = img_b + W * H / 4;
    sdst.plane[1] = img_b + W * H / 2;
    sdst.plane[2] = img_b + W * H * 3 / 4;
    sframe.stride[1] = sframe.stride[2] = sdst.stride[1] = sdst.stride[2] = W / 2;
    return home_stab_warp_rows(warp_m, &sframe, &sdst, first_row, rows);
}

/* features of another context: a frame of another size, or another config of the same size */
static int match_foreign(int width, int height, int theta_bins)
{
    home_config other;
    other = cfg;
    other.width = width;
    other.height = height;
    other.theta_bins = theta_bins;
    if (home_init(&ctx_other, &other, ALIGNED_ARENA(arena_other.bytes), ALIGNED_BYTES(arena_other.bytes), NULL) != HOME_OK)
        return 1;
    memset(img_other, 77, sizeof img_other);
    if (home_extract(ctx_other, img_other, width, &fb) != HOME_OK) return 1;
    return home_match(ctx, &fa, &fb, &res);
}

/* home_init with a too-small arena must also report the exact size it needs */
static int init_short(size_t bytes)
{
    int s = home_init(&ctx, &cfg, ALIGNED_ARENA(arena.bytes), bytes, &needed);
    return (needed == home_arena_size(&cfg) && ctx == NULL) ? s : 1;
}

static int pgm(const char *text, size_t size)
{
    int w, h;
    const uint8_t *pixels;
    char err[128] = "";
    int s = pgm_parse((const uint8_t *)text, size, HOME_MAX_SIDE, &w, &h, &pixels, err, sizeof err);
    return (s != 0 && err[0] == '\0') ? 1 : s; /* a refusal must say why */
}
#define PGM(literal) pgm(literal, sizeof literal - 1)

/* Y4M reader (examples/y4m.c): the header's status, or else the last frame read's (1 a frame,
 * 0 a clean end, -1 malformed or truncated); refusals must say why. The mapped reader (home-stab's
 * for a file) reads the same bytes from a file beside it and must agree on every frame's status
 * and pixels (97 where it does not). */
static int y4m(const char *text, size_t size, int frames)
{
    static char copy[256];
    static uint8_t frame[4096];
    char err[160] = "", map_err[160] = "";
    y4m_info info;
    y4m_map map;
    int s = -1, k, mapped = 0, agree = 1;
    FILE *f, *file;
    memcpy(copy, text, size);
    if (!(f = fmemopen(copy, size ? size : 1, "rb"))) return 99;
    if (!size) (void)getc(f); /* an empty stream: consume the placeholder byte */
    s = y4m_read_header(f, &info, err, sizeof err);
    if (s == 0 && (file = tmpfile()) != NULL) {
        y4m_info again;
        if (fwrite(text, 1, size, file) == size && fflush(file) == 0 && fseek(file, 0, SEEK_SET) == 0 &&
            y4m_read_header(file, &again, map_err, sizeof map_err) == 0)
            mapped = y4m_map_open(&map, file, ftell(file)) == 0;
        fclose(file); /* the map stays valid */
        if (!mapped) agree = 0;
    }
    for (k = 0; s == 0 && k < frames; k++) {
        int got;
        if (y4m_frame_bytes(&info) > sizeof frame) { s = 99; break; }
        got = y4m_read_frame(f, &info, frame, err, sizeof err);
        if (mapped) {
            const uint8_t *in_map = NULL;
            const int got_map = y4m_map_frame(&map, &info, &in_map, map_err, sizeof map_err);
            agree = agree && got_map == got &&
                    (got != 1 || !memcmp(in_map, frame, y4m_frame_bytes(&info))) &&
                    (got >= 0 || map_err[0] != '\0');
        }
        if (got <= 0 || k == frames - 1) { s = got; break; }
    }
    if (mapped) y4m_map_close(&map);
    fclose(f);
    if (!agree) return 97;
    return (s < 0 && err[0] == '\0') ? 98 : s;
}
#define Y4M(literal, frames) y4m(literal, sizeof literal - 1, frames)

/* name, expected value, expression; the comment column of docs/errors.md's table */
#define BAD_INPUTS(X) \
    /* configuration */ \
    X(config_null, HOME_E_NULL, home_default_config(NULL, W, H)) \
    X(config_zero_width, HOME_E_SIZE, home_default_config(&bad, 0, H)) \
    X(config_negative_height, HOME_E_SIZE, home_default_config(&bad, W, -64)) \
    X(config_below_min_side, HOME_E_SIZE, home_default_config(&bad, HOME_MIN_SIDE - 1, H)) \
    X(config_above_max_side, HOME_E_SIZE, home_default_config(&bad, W, HOME_MAX_SIDE + 1)) \
    X(config_int_max_sides, HOME_E_SIZE, home_default_config(&bad, INT_MAX, INT_MAX)) \
    X(validate_null, HOME_E_NULL, home_validate_config(NULL)) \
    X(validate_area_overflows_int, HOME_E_SIZE, (bad.width = bad.height = 65536, home_validate_config(&bad))) \
    X(validate_odd_sizes_accepted, HOME_OK, (bad.width = 33, bad.height = 97, home_validate_config(&bad))) \
    X(theta_bins_zero, HOME_E_CONFIG, (bad.theta_bins = 0, home_validate_config(&bad))) \
    X(theta_bins_negative, HOME_E_CONFIG, (bad.theta_bins = -480, home_validate_config(&bad))) \
    X(theta_bins_above_max, HOME_E_CONFIG, (bad.theta_bins = HOME_MAX_THETA_BINS + 1, home_validate_config(&bad))) \
    X(wrap_band_negative, HOME_E_CONFIG, (bad.wrap_band = -1, home_validate_config(&bad))) \
    X(wrap_band_above_quarter, HOME_E_CONFIG, (bad.wrap_band = bad.theta_bins / 4 + 1, home_validate_config(&bad))) \
    X(r_step_zero, HOME_E_CONFIG, (bad.r_step = 0.0f, home_validate_config(&bad))) \
    X(r_step_nan, HOME_E_CONFIG, (bad.r_step = (float)NAN, home_validate_config(&bad))) \
    X(r_step_inf, HOME_E_CONFIG, (bad.r_step = (float)INFINITY, home_validate_config(&bad))) \
    X(r_bins_odd, HOME_E_CONFIG, (bad.r_bins = 201, home_validate_config(&bad))) \
    X(r_bins_short_of_diagonal, HOME_E_CONFIG, (bad.r_bins = 2, home_validate_config(&bad))) \
    X(r_bins_negative, HOME_E_CONFIG, (bad.r_bins = -200, home_validate_config(&bad))) \
    X(smooth_sigma_negative, HOME_E_CONFIG, (bad.smooth_sigma = -1.3f, home_validate_config(&bad))) \
    X(smooth_sigma_inf, HOME_E_CONFIG, (bad.smooth_sigma = (float)INFINITY, home_validate_config(&bad))) \
    X(keypoints_zero, HOME_E_CONFIG, (bad.keypoints_per_sign = 0, home_validate_config(&bad))) \
    X(keypoints_above_max, HOME_E_CONFIG, (bad.keypoints_per_sign = HOME_MAX_KEYPOINTS_PER_SIGN + 1, home_validate_config(&bad))) \
    X(ratio_nan, HOME_E_CONFIG, (bad.ratio = (float)NAN, home_validate_config(&bad))) \
    X(ratio_above_one, HOME_E_CONFIG, (bad.ratio = 1.5f, home_validate_config(&bad))) \
    X(ratio_minus_inf, HOME_E_CONFIG, (bad.ratio = -(float)INFINITY, home_validate_config(&bad))) \
    X(threshold_final_zero, HOME_E_CONFIG, (bad.threshold_final = 0.0f, home_validate_config(&bad))) \
    X(threshold_final_nan, HOME_E_CONFIG, (bad.threshold_final = (float)NAN, home_validate_config(&bad))) \
    X(threshold_start_below_final, HOME_E_CONFIG, (bad.threshold_start = 0.5f, home_validate_config(&bad))) \
    X(threshold_too_many_halvings, HOME_E_CONFIG, (bad.threshold_start = bad.threshold_final * (float)(1 << HOME_MAX_THRESHOLD_LEVELS), home_validate_config(&bad))) \
    X(min_inliers_three, HOME_E_CONFIG, (bad.min_inliers = 3, home_validate_config(&bad))) \
    X(min_inliers_above_max, HOME_E_CONFIG, (bad.min_inliers = 2 * HOME_MAX_KEYPOINTS_PER_SIGN + 1, home_validate_config(&bad))) \
    X(refine_levels_negative, HOME_E_CONFIG, (bad.refine_levels = -1, home_validate_config(&bad))) \
    X(refine_levels_above_max, HOME_E_CONFIG, (bad.refine_levels = HOME_REFINE_MAX_LEVELS + 1, home_validate_config(&bad))) \
    X(refine_iterations_zero, HOME_E_CONFIG, (bad.refine_iterations = 0, home_validate_config(&bad))) \
    X(refine_trust_nan, HOME_E_CONFIG, (bad.refine_trust_px = (float)NAN, home_validate_config(&bad))) \
    X(refine_points_above_max, HOME_E_CONFIG, (bad.refine_points = HOME_REFINE_MAX_POINTS + 1, home_validate_config(&bad))) \
    X(refine_finest_negative, HOME_E_CONFIG, (bad.refine_finest_level = -1, home_validate_config(&bad))) \
    X(refine_finest_not_below_levels, HOME_E_CONFIG, (bad.refine_finest_level = bad.refine_levels, home_validate_config(&bad))) \
    X(max_model_negative, HOME_E_CONFIG, (bad.max_model = -1, home_validate_config(&bad))) \
    X(max_model_above_homography, HOME_E_CONFIG, (bad.max_model = HOME_MODEL_HOMOGRAPHY + 1, home_validate_config(&bad))) \
    X(max_sigma_nan, HOME_E_CONFIG, (bad.max_sigma_px = (float)NAN, home_validate_config(&bad))) \
    X(max_sigma_zero, HOME_E_CONFIG, (bad.max_sigma_px = 0.0f, home_validate_config(&bad))) \
    X(max_sigma_inf, HOME_E_CONFIG, (bad.max_sigma_px = (float)INFINITY, home_validate_config(&bad))) \
    X(simd_unknown, HOME_E_CONFIG, (bad.simd = 99, home_validate_config(&bad))) \
    X(hough_method_unknown, HOME_E_CONFIG, (bad.hough_method = 7, home_validate_config(&bad))) \
    X(arena_size_null, 0, (int)home_arena_size(NULL)) \
    X(arena_size_bad_config, 0, (bad.theta_bins = 0, (int)home_arena_size(&bad))) \
    /* context initialisation */ \
    X(init_null_out, HOME_E_NULL, home_init(NULL, &cfg, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes), NULL)) \
    X(init_null_config, HOME_E_NULL, home_init(&ctx, NULL, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes), NULL)) \
    X(init_null_arena, HOME_E_NULL, home_init(&ctx, &cfg, NULL, ALIGNED_BYTES(arena.bytes), NULL)) \
    X(init_bad_config, HOME_E_CONFIG, (bad.ratio = (float)NAN, home_init(&ctx, &bad, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes), NULL))) \
    X(init_arena_empty, HOME_E_ARENA_SMALL, init_short(0)) \
    X(init_arena_one_byte_short, HOME_E_ARENA_SMALL, init_short(home_arena_size(&cfg) - 1)) \
    X(init_arena_misaligned_1, HOME_E_ARENA_ALIGN, home_init(&ctx, &cfg, ALIGNED_ARENA(arena.bytes) + 1, ALIGNED_BYTES(arena.bytes) - 1, NULL)) \
    X(init_arena_misaligned_8, HOME_E_ARENA_ALIGN, home_init(&ctx, &cfg, ALIGNED_ARENA(arena.bytes) + 8, ALIGNED_BYTES(arena.bytes) - 8, NULL)) \
    /* feature extraction */ \
    X(extract_null_context, HOME_E_NULL, home_extract(NULL, img_a, W, &fa)) \
    X(extract_null_image, HOME_E_NULL, home_extract(ctx, NULL, W, &fa)) \
    X(extract_null_features, HOME_E_NULL, home_extract(ctx, img_a, W, NULL)) \
    X(extract_stride_below_width, HOME_E_STRIDE, home_extract(ctx, img_a, W - 1, &fa)) \
    X(extract_stride_zero, HOME_E_STRIDE, home_extract(ctx, img_a, 0, &fa)) \
    X(extract_stride_negative, HOME_E_STRIDE, home_extract(ctx, img_a + (H - 1) * W, -W, &fa)) \
    X(extract_stride_overflows, HOME_E_STRIDE, home_extract(ctx, img_a, PTRDIFF_MAX / 2, &fa)) \
    X(extract_uninitialised_context, HOME_E_STATE, home_extract((home_context *)(void *)junk.bytes, img_a, W, &fa)) \
    X(extract_context_overwritten, HOME_E_STATE, (memset(ALIGNED_ARENA(arena.bytes), 0, 64), home_extract(ctx, img_a, W, &fa))) \
    /* matching: stages out of order, corrupted or foreign features */ \
    X(match_before_extract, HOME_E_STATE, (memset(&fb, 0, sizeof fb), home_match(ctx, &fa, &fb, &res))) \
    X(match_null_features, HOME_E_NULL, home_match(ctx, NULL, &fb, &res)) \
    X(match_null_result, HOME_E_NULL, home_match(ctx, &fa, &fb, NULL)) \
    X(match_null_context, HOME_E_NULL, home_match(NULL, &fa, &fb, &res)) \
    X(match_negative_count, HOME_E_STATE, (fb.n_pos = -3, home_match(ctx, &fa, &fb, &res))) \
    X(match_count_above_capacity, HOME_E_STATE, (fb.n_neg = HOME_MAX_KEYPOINTS_PER_SIGN + 1, home_match(ctx, &fa, &fb, &res))) \
    X(match_count_above_config, HOME_E_MISMATCH, (fb.n_pos = cfg.keypoints_per_sign + 1, home_match(ctx, &fa, &fb, &res))) \
    X(match_corrupt_magic, HOME_E_STATE, (fb.magic ^= 1u, home_match(ctx, &fa, &fb, &res))) \
    X(match_frames_of_different_sizes, HOME_E_MISMATCH, match_foreign(W + 32, H, cfg.theta_bins)) \
    X(match_features_of_other_config, HOME_E_MISMATCH, match_foreign(W, H, cfg.theta_bins / 2)) \
    /* two-image registration */ \
    X(register_null_context, HOME_E_NULL, home_register(NULL, img_a, W, img_b, W, &res)) \
    X(register_null_image_b, HOME_E_NULL, home_register(ctx, img_a, W, NULL, W, &res)) \
    X(register_stride_b_below_width, HOME_E_STRIDE, home_register(ctx, img_a, W, img_b, W / 2, &res)) \
    X(register_null_result, HOME_E_NULL, home_register(ctx, img_a, W, img_b, W, NULL)) \
    X(last_features_before_register, 0, home_last_features(ctx, 0) != NULL) \
    X(last_features_index_out_of_range, 0, (home_register(ctx, img_a, W, img_b, W, &res), home_last_features(ctx, 2) != NULL)) \
    /* photometric refinement from a caller's H */ \
    X(refine_null_initial_h, HOME_E_NULL, home_refine(ctx, img_a, W, img_b, W, NULL, &res)) \
    X(refine_nan_initial_h, HOME_E_CONFIG, (h_init[4] = NAN, home_refine(ctx, img_a, W, img_b, W, h_init, &res))) \
    X(refine_zero_h22, HOME_E_CONFIG, (h_init[8] = 0.0, home_refine(ctx, img_a, W, img_b, W, h_init, &res))) \
    X(refine_stride_a_below_width, HOME_E_STRIDE, home_refine(ctx, img_a, 1, img_b, W, h_init, &res)) \
    X(refine_uninitialised_context, HOME_E_STATE, home_refine((home_context *)(void *)junk.bytes, img_a, W, img_b, W, h_init, &res)) \
    /* stabiliser (home_stab_*) */ \
    X(stab_config_null, HOME_E_NULL, home_stab_default_config(NULL, W, H)) \
    X(stab_odd_width, HOME_E_SIZE, (sbad.width = W + 1, home_stab_validate_config(&sbad))) \
    X(stab_margin_x_nan, HOME_E_CONFIG, (sbad.margin_x = (float)NAN, home_stab_validate_config(&sbad))) \
    X(stab_margin_y_above_0_4, HOME_E_CONFIG, (sbad.margin_y = 0.41f, home_stab_validate_config(&sbad))) \
    X(stab_theta_bins_below_16, HOME_E_CONFIG, (sbad.theta_bins = 15, home_stab_validate_config(&sbad))) \
    X(stab_refine_finest_level_2, HOME_E_CONFIG, (sbad.refine_finest_level = 2, home_stab_validate_config(&sbad))) \
    X(stab_lookahead_above_max, HOME_E_CONFIG, (sbad.lookahead = HOME_STAB_MAX_LOOKAHEAD + 1, home_stab_validate_config(&sbad))) \
    X(stab_arena_one_byte_short, HOME_E_ARENA_SMALL, home_stab_init(&stab, &scfg, ALIGNED_ARENA(stab_arena.bytes), home_stab_arena_size(&scfg) - 1, NULL)) \
    X(stab_push_null_frame, HOME_E_NULL, home_stab_push(stab, NULL, &sout)) \
    X(stab_push_frame_of_other_size, HOME_E_MISMATCH, (sframe.height = H - 2, home_stab_push(stab, &sframe, &sout))) \
    X(stab_push_stride_below_width, HOME_E_STRIDE, (sframe.stride[0] = W - 1, home_stab_push(stab, &sframe, &sout))) \
    X(stab_push_unknown_format, HOME_E_CONFIG, (sframe.format = 0, home_stab_push(stab, &sframe, &sout))) \
    X(stab_push_odd_width_i420, HOME_E_SIZE, (sframe.width = W - 1, push_i420(0))) \
    X(stab_push_missing_chroma_plane, HOME_E_NULL, push_i420(1)) \
    X(stab_push_uninitialised, HOME_E_STATE, home_stab_push((home_stab *)(void *)junk.bytes, &sframe, &sout)) \
    X(stab_flush_null_output, HOME_E_NULL, home_stab_flush(stab, NULL)) \
    X(stab_cut_null, HOME_E_NULL, home_stab_cut(NULL)) \
    X(stab_crop_warp_null_path, HOME_E_NULL, home_stab_crop_warp(&scfg, NULL, &ssim, warp_m, NULL)) \
    X(stab_crop_warp_nan_path, HOME_E_CONFIG, (ssim.tx = NAN, home_stab_crop_warp(&scfg, &ssim, &ssim, warp_m, NULL))) \
    X(stab_crop_warp_bad_config, HOME_E_CONFIG, (sbad.margin_x = 0.5f, home_stab_crop_warp(&sbad, &ssim, &ssim, warp_m, NULL))) \
    X(stab_margin_share_null_out, HOME_E_NULL, home_stab_margin_share(&scfg, &ssim, &ssim, NULL)) \
    X(stab_cut_uninitialised, HOME_E_STATE, home_stab_cut((home_stab *)(void *)junk.bytes)) \
    X(stab_warp_projective, HOME_E_CONFIG, (warp_m[6] = 1e-3, home_stab_warp(warp_m, &sframe, &sdst))) \
    X(stab_warp_nan, HOME_E_CONFIG, (warp_m[2] = NAN, home_stab_warp(warp_m, &sframe, &sdst))) \
    X(stab_warp_far_outside, HOME_E_CONFIG, (warp_m[2] = 10.0 * W, home_stab_warp(warp_m, &sframe, &sdst))) \
    X(stab_warp_format_mismatch, HOME_E_MISMATCH, (sdst.format = HOME_STAB_YUYV, sdst.stride[0] = 2 * W, home_stab_warp(warp_m, &sframe, &sdst))) \
    X(stab_warp_stride_overflows, HOME_E_STRIDE, (sframe.stride[0] = PTRDIFF_MAX / 2, home_stab_warp(warp_m, &sframe, &sdst))) \
    X(stab_warp_rows_null_map, HOME_E_NULL, home_stab_warp_rows(NULL, &sframe, &sdst, 0, 2)) \
    X(stab_warp_rows_none, HOME_E_CONFIG, home_stab_warp_rows(warp_m, &sframe, &sdst, 0, 0)) \
    X(stab_warp_rows_negative_start, HOME_E_CONFIG, home_stab_warp_rows(warp_m, &sframe, &sdst, -1, 4)) \
    X(stab_warp_rows_past_the_end, HOME_E_CONFIG, home_stab_warp_rows(warp_m, &sframe, &sdst, H - 2, 3)) \
    X(stab_warp_rows_int_max, HOME_E_CONFIG, home_stab_warp_rows(warp_m, &sframe, &sdst, 2, INT_MAX)) \
    X(stab_warp_rows_odd_start_i420, HOME_E_CONFIG, warp_rows_i420(1, 2)) \
    X(stab_warp_rows_odd_count_i420, HOME_E_CONFIG, warp_rows_i420(2, 3)) \
    /* inspection */ \
    X(hough_size_null_output, HOME_E_NULL, home_hough_size(ctx, &hw, NULL)) \
    X(render_hough_null_output, HOME_E_NULL, home_render_hough(ctx, img_a, W, NULL, 1024)) \
    X(render_hough_stride_too_small, HOME_E_STRIDE, (home_hough_size(ctx, &hw, &hh), home_render_hough(ctx, img_a, W, hough, hw - 1))) \
    X(keypoint_to_hough_null_keypoint, HOME_E_NULL, home_keypoint_to_hough(ctx, NULL, &col, &row)) \
    X(strerror_unknown_code, 0, strcmp(home_strerror(-12345), "unknown status code")) \
    X(model_name_unknown, 0, strcmp(home_model_name(-1), "unknown") | strcmp(home_model_name(5), "unknown")) \
    X(failure_name_unknown, 0, strcmp(home_failure_name(99), "unknown")) \
    X(refine_status_name_unknown, 0, strcmp(home_refine_status_name(-3), "unknown")) \
    /* PGM reader (examples/pgm.c): refusals return -1 with a reason */ \
    X(pgm_empty, -1, PGM("")) \
    X(pgm_garbage, -1, PGM("\x89PNG\r\n\x1a\n")) \
    X(pgm_ascii_p2, -1, PGM("P2\n2 2\n255\n1 2 3 4\n")) \
    X(pgm_16_bit, -1, PGM("P5\n2 2\n65535\n\1\2\3\4\5\6\7\10")) \
    X(pgm_maxval_zero, -1, PGM("P5\n2 2\n0\n\1\2\3\4")) \
    X(pgm_width_zero, -1, PGM("P5\n0 2\n255\n")) \
    X(pgm_negative_height, -1, PGM("P5\n2 -2\n255\n\1\2\3\4")) \
    X(pgm_side_above_limit, -1, PGM("P5\n4097 1\n255\n")) \
    X(pgm_number_overflow, -1, PGM("P5\n99999999999999999999 2\n255\n")) \
    X(pgm_no_separator_after_maxval, -1, PGM("P5\n2 2\n255")) \
    X(pgm_truncated_raster, -1, PGM("P5\n2 2\n255\n\1\2\3")) \
    X(pgm_with_comments_accepted, 0, PGM("P5 # c\n#only comment\n2 2 255\n\1\2\3\4")) \
    X(pgm_trailing_bytes_accepted, 0, PGM("P5\n2 1\n255\n\1\2\3")) \
    /* Y4M reader (examples/y4m.c): refusals return -1 with a reason; home-stab exits 2 (header) \
     * or 1 (a bad frame after good ones) */ \
    X(y4m_empty, -1, Y4M("", 0)) \
    X(y4m_not_y4m, -1, Y4M("RIFF\x24\0\0\0WAVEfmt \n", 0)) \
    X(y4m_no_size, -1, Y4M("YUV4MPEG2 F30:1 C420\n", 0)) \
    X(y4m_width_zero, -1, Y4M("YUV4MPEG2 W0 H2\n", 0)) \
    X(y4m_width_negative, -1, Y4M("YUV4MPEG2 W-2 H2\n", 0)) \
    X(y4m_absurd_size, -1, Y4M("YUV4MPEG2 W99999 H99999\n", 0)) \
    X(y4m_size_not_a_number, -1, Y4M("YUV4MPEG2 W2x H2\n", 0)) \
    X(y4m_444_unsupported, -1, Y4M("YUV4MPEG2 W2 H2 C444\n", 0)) \
    X(y4m_10_bit_unsupported, -1, Y4M("YUV4MPEG2 W2 H2 C420p10\n", 0)) \
    X(y4m_16_bit_mono_unsupported, -1, Y4M("YUV4MPEG2 W2 H2 Cmono16\n", 0)) \
    X(y4m_odd_size_420, -1, Y4M("YUV4MPEG2 W3 H3 C420\n", 0)) \
    X(y4m_no_newline, -1, Y4M("YUV4MPEG2 W2 H2", 0)) \
    X(y4m_bad_frame_marker, -1, Y4M("YUV4MPEG2 W2 H2 Cmono\nFRAMX\n\1\2\3\4", 1)) \
    X(y4m_truncated_frame, -1, Y4M("YUV4MPEG2 W2 H2 C420jpeg\nFRAME\n\1\2\3", 1)) \
    X(y4m_truncated_second_frame, -1, Y4M("YUV4MPEG2 W2 H2 C420\nFRAME\n\1\2\3\4\5\6FRAME\n\1", 2)) \
    X(y4m_420_frame_accepted, 1, Y4M("YUV4MPEG2 W2 H2 F30:1 Ip A1:1 C420mpeg2 XYSCSS=420MPEG2\nFRAME\n\1\2\3\4\5\6", 1)) \
    X(y4m_clean_end_accepted, 0, Y4M("YUV4MPEG2 W2 H2 C422\nFRAME\n\1\2\3\4\5\6\7\10", 2)) \
    X(y4m_frame_params_accepted, 1, Y4M("YUV4MPEG2 W2 H2 Cmono\nFRAME Ixyz\n\1\2\3\4FRAME\n\5\6\7\10", 2)) \
    X(y4m_frame_header_unterminated, -1, Y4M("YUV4MPEG2 W2 H2 Cmono\nFRAME", 1)) \
    X(y4m_frame_marker_too_long, -1, Y4M("YUV4MPEG2 W2 H2 Cmono\nFRAMES\n\1\2\3\4", 1))

#define DEFINE_ROW(name, expect, expr) static int row_##name(void) { return (expr); }
BAD_INPUTS(DEFINE_ROW)
#define ROW_ENTRY(name, expect, expr) {#name, expect, row_##name},
static const struct { const char *name; int expect; int (*run)(void); } table[] = {BAD_INPUTS(ROW_ENTRY)};

#define ROW_COUNT (int)(sizeof table / sizeof table[0])

static void test_bad_input_table(void)
{
    int i, failed = 0;
    for (i = 0; i < ROW_COUNT; i++) {
        int got;
        fixture();
        if (!ctx) { CHECK(ctx != NULL); return; }
        got = table[i].run();
        if (got != table[i].expect) {
            failed++;
            test_failures++;
            fprintf(stderr, "    bad input %s: got %d (%s), expected %d (%s)\n", table[i].name, got,
                    home_strerror(got), table[i].expect, home_strerror(table[i].expect));
        }
    }
    printf("     %d bad-input rows, %d wrong\n", ROW_COUNT, failed);
    CHECK(ROW_COUNT >= 30);
}

/* After every refusal the context still works: a refused call changes no state. */
static void test_refusals_leave_context_usable(void)
{
    static home_features again;
    fixture();
    if (!ctx) { CHECK(0); return; }
    CHECK_EQ_INT(home_extract(ctx, img_a, W - 1, &fb), HOME_E_STRIDE);
    CHECK_EQ_INT(home_match(ctx, &fa, NULL, &res), HOME_E_NULL);
    CHECK_EQ_INT(home_register(ctx, img_a, W, NULL, W, &res), HOME_E_NULL);
    CHECK_EQ_INT(home_extract(ctx, img_a, W, &again), HOME_OK);
    CHECK(same_features(&again, &fa));
}

#define HARD_TEST_LIST(X) \
    X(bad_input_table) X(refusals_leave_context_usable) HARD_TESTS_MORE(X)

#define HARD_DECLARE(name) void test_##name(void);
HARD_TESTS_MORE(HARD_DECLARE)
#define HARD_ENTRY(name) {#name, test_##name},
static const test_case tests[] = {HARD_TEST_LIST(HARD_ENTRY)};

int main(int argc, char **argv)
{
    int k;
    if (argc == 2 && !strcmp(argv[1], "--list")) {
        for (k = 0; k < ROW_COUNT; k++) printf("%-36s %d\n", table[k].name, table[k].expect);
        return 0;
    }
    return test_run(tests, sizeof tests / sizeof tests[0], "", argc, argv);
}
