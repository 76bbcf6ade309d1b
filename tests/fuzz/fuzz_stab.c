/* Fuzz the stabiliser API (home_stab_*): fuzzed configs and arena sizes, frame formats, sizes and
 * strides, short clips of shifted frames, flush, reset, and the warper on fuzzed matrices. Valid
 * calls must succeed, outputs must stay finite and in range, and every warp the stabiliser
 * reports must be one home_stab_warp() accepts. */
#include "fuzz_util.h"
#include "home_stab.h"
#include <math.h>

/* Every pushed frame costs a Hough transform, so executions are kept short (issue 7): unless all
 * three FLAG_LARGE bits are set (one random input in eight), frames are 32..36 px, 16..24 theta
 * bins, 8..24 keypoints per sign and 0..2 frames are pushed (none: the config, arena, frame and
 * warper checks alone); large inputs use 32..64 px, 16..120 theta bins or the automatic 120,
 * 8..150 keypoints, 1..5 frames. */
#define FZ_SIDE_MAX 64
#define FZ_TINY_SIDE 36
#define FZ_TINY_KEYPOINTS 24
#define FZ_TINY_FRAMES 2
#define FZ_TINY_THETA_BINS 24
#define FZ_FRAMES_MAX 5
#define FLAG_LARGE (7u << 13)
#define FZ_PLANE_BYTES (2 * (FZ_SIDE_MAX + 8) * FZ_SIDE_MAX)
#define FZ_ARENA_BYTES (8u << 20)

static union { unsigned char bytes[FZ_ARENA_BYTES]; double align; } arena;
static uint8_t planes[FZ_FRAMES_MAX + 1][3][FZ_PLANE_BYTES];

static int is_status(int s)
{
    return s <= HOME_OK && s >= HOME_E_BUFFER;
}

/* Rows of plane p of a w x h frame in format fmt, and bytes per row. */
static void plane_shape(int fmt, int p, int w, int h, int *rows, int *row_bytes)
{
    *rows = h;
    *row_bytes = w;
    if (fmt == HOME_STAB_YUYV) *row_bytes = 2 * w;
    if (p == 0) return;
    if (fmt == HOME_STAB_I420 || fmt == HOME_STAB_NV12) *rows = h / 2;
    if (fmt != HOME_STAB_NV12) *row_bytes = w / 2;
}

static int plane_count(int fmt)
{
    return fmt == HOME_STAB_I420 || fmt == HOME_STAB_I422 ? 3 : fmt == HOME_STAB_NV12 ? 2 : 1;
}

/* Frame k: the base scene shifted by (k*dx, k*dy); planes end where their buffers end. Returns
 * 1 when the frame is well formed. */
FZ_NO_COVERAGE static int make_frame(fz_reader *r, home_stab_image *im, int k, int fmt, int w, int h, int pad,
                      const uint8_t *scene, int dx, int dy)
{
    int p, x, y, valid = fmt >= HOME_STAB_I420 && fmt <= HOME_STAB_GREY;
    memset(im, 0, sizeof *im);
    im->format = fmt;
    im->width = w;
    im->height = h;
    for (p = 0; p < (valid ? plane_count(fmt) : 1); p++) {
        int rows, row_bytes;
        plane_shape(valid ? fmt : HOME_STAB_GREY, p, w, h, &rows, &row_bytes);
        im->stride[p] = row_bytes + pad;
        im->plane[p] = planes[k][p] + FZ_PLANE_BYTES - ((size_t)(rows - 1) * (size_t)im->stride[p] + (size_t)row_bytes);
        for (y = 0; y < rows; y++)
            for (x = 0; x < row_bytes; x++) {
                int sx = (x + k * dx) & 63, sy = (y + k * dy) & 63;
                im->plane[p][y * im->stride[p] + x] = p ? (uint8_t)(128 + x) : scene[sy * 64 + sx];
            }
    }
    if (fz_u8(r) == 0xff) { im->plane[0] = NULL; valid = 0; }
    return valid;
}

static void check_output(const home_stab_output *out)
{
    int k;
    FZ_CHECK(out->ready == 0 || out->ready == 1);
    if (!out->ready) return;
    for (k = 0; k < 9; k++) FZ_CHECK(isfinite(out->warp[k]));
    FZ_CHECK(out->correction_used >= 0.0 && out->correction_used <= 1.0);
    FZ_CHECK(out->motion_status >= HOME_STAB_MOTION_FIRST &&
             out->motion_status <= HOME_STAB_MOTION_BRIDGED);
    FZ_CHECK(isfinite(out->raw.tx) && isfinite(out->raw.ty) && isfinite(out->smooth.angle));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader rd = {data, size, 0}, *r = &rd;
    unsigned flags = fz_u16(r);
    home_stab_config cfg;
    home_stab *stab = NULL;
    home_stab_image frames[FZ_FRAMES_MAX], dst;
    home_stab_output out;
    uint8_t scene[64 * 64];
    size_t need, have;
    int large = (flags & FLAG_LARGE) == FLAG_LARGE, side_max = large ? FZ_SIDE_MAX : FZ_TINY_SIDE;
    int w = 2 * fz_range(r, HOME_MIN_SIDE / 2, side_max / 2), h = 2 * fz_range(r, HOME_MIN_SIDE / 2, side_max / 2);
    int s, k, n, fmt, pad, dx, dy, valid[FZ_FRAMES_MAX], pushed = 0;
    long last = -1;

    if (flags & 1) { w = (int16_t)fz_u16(r); h = (int16_t)fz_u16(r); }
    s = home_stab_default_config(&cfg, w, h);
    FZ_CHECK(is_status(s));
    cfg.keypoints_per_sign = fz_range(r, 8, large ? 150 : FZ_TINY_KEYPOINTS);
    cfg.theta_bins = !large ? fz_range(r, 16, FZ_TINY_THETA_BINS) : (fz_u8(r) & 1) ? 0 : fz_range(r, 16, 120);
    cfg.lookahead = fz_range(r, 0, 3);
    cfg.downscale = 1;
    if (flags & 2) {
        float f = fz_float_bits(r);
        int32_t raw = (int32_t)fz_u32(r);
        switch (fz_u8(r) % 11) {
        case 0: if (raw & 1) cfg.margin_x = f; else cfg.margin_y = f; break;
        case 1: cfg.smoothing = f; break;
        case 2: cfg.lookahead = raw % 256; break;
        case 3: cfg.downscale = raw % 8; break;
        case 4: cfg.keypoints_per_sign = raw % 2048; break;
        case 5: cfg.min_inliers = raw % 64; break;
        case 6: cfg.max_shift = f; break;
        case 7: cfg.max_rotation = f; break;
        case 8: cfg.max_zoom = f; break;
        case 9: cfg.theta_bins = raw % 4096; break;
        default: cfg.max_residual = f; break;
        }
    }
    s = home_stab_validate_config(&cfg);
    FZ_CHECK(is_status(s));
    need = home_stab_arena_size(&cfg);
    FZ_CHECK((s == HOME_OK) == (need > 0));
    have = need && need <= FZ_ARENA_BYTES - 2 * HOME_ARENA_ALIGN ? need : FZ_ARENA_BYTES - 2 * HOME_ARENA_ALIGN;
    if ((flags & 4) && need > 1) have = need - 1;
    {
        size_t needed = 0;
        int want = s != HOME_OK ? s : need > have ? HOME_E_ARENA_SMALL : HOME_OK;
        s = home_stab_init(&stab, &cfg, fz_align16(arena.bytes) + FZ_ARENA_BYTES - HOME_ARENA_ALIGN - (have & ~(size_t)15) - (have & 15 ? 16 : 0),
                           have, &needed);
        FZ_CHECK(s == want);
        if (s == HOME_E_ARENA_SMALL) FZ_CHECK(needed == need);
        if (s != HOME_OK) return 0;
    }
    if (cfg.width > FZ_SIDE_MAX || cfg.height > FZ_SIDE_MAX) return 0;

    /* a scene of rectangles; frames are it shifted by (dx, dy) per frame */
    memset(scene, (int)fz_u8(r), sizeof scene);
    for (k = fz_range(r, 0, 10); k > 0; k--) {
        int x0 = fz_range(r, 0, 63), y0 = fz_range(r, 0, 63), x1 = fz_range(r, x0, 63), y1 = fz_range(r, y0, 63);
        int v = (int)fz_u8(r), x, y;
        for (y = y0; y <= y1; y++)
            for (x = x0; x <= x1; x++) scene[y * 64 + x] = (uint8_t)v;
    }
    fmt = fz_range(r, 0, HOME_STAB_GREY + 1);
    pad = fz_range(r, 0, 8);
    dx = fz_range(r, -3, 3);
    dy = fz_range(r, -3, 3);
    n = large ? fz_range(r, 1, FZ_FRAMES_MAX) : fz_range(r, 0, FZ_TINY_FRAMES);
    /* frame 0 is made even when nothing is pushed: the warper's source */
    for (k = 0; k < (n ? n : 1); k++) valid[k] = make_frame(r, &frames[k], k, fmt, cfg.width, cfg.height, pad, scene, dx, dy);

    for (k = 0; k < n; k++) {
        if (fz_u8(r) % 8 == 0) FZ_CHECK(home_stab_cut(stab) == HOME_OK);
        s = home_stab_push(stab, &frames[k], &out);
        FZ_CHECK(is_status(s));
        if (valid[k]) FZ_CHECK(s == HOME_OK);
        else FZ_CHECK(s != HOME_OK);
        if (s != HOME_OK) continue;
        pushed++;
        check_output(&out);
        if (out.ready) {
            double again[9];
            FZ_CHECK(out.frame > last && out.frame < k + 1);
            /* the warp follows from the paths alone (home-stab's adaptive crop relies on it) */
            FZ_CHECK(home_stab_crop_warp(&cfg, &out.raw, &out.smooth, again, NULL) == HOME_OK &&
                     memcmp(again, out.warp, sizeof again) == 0);
            last = out.frame;
            /* the stabiliser's own warp is one the warper accepts */
            if (make_frame(r, &dst, FZ_FRAMES_MAX, fmt, cfg.width, cfg.height, 0, scene, 0, 0) &&
                valid[out.frame])
                FZ_CHECK(home_stab_warp(out.warp, &frames[out.frame], &dst) == HOME_OK);
        }
    }
    for (k = 0; k <= HOME_STAB_MAX_LOOKAHEAD + 1; k++) {
        FZ_CHECK(home_stab_flush(stab, &out) == HOME_OK);
        check_output(&out);
        if (!out.ready) break;
        FZ_CHECK(out.frame > last);
        last = out.frame;
    }
    FZ_CHECK(k <= cfg.lookahead);

    /* the warper on any matrix: refused or done, never out of bounds */
    if (valid[0]) {
        double m[9];
        home_stab_sim sim;
        for (k = 0; k < 9; k++) m[k] = (fz_u8(r) & 1) ? (double)fz_float_bits(r) : (k % 4 == 0);
        int dst_valid = make_frame(r, &dst, FZ_FRAMES_MAX, fmt, cfg.width, cfg.height,
                                   fz_range(r, 0, 4), scene, 0, 0);
        s = home_stab_warp(m, &frames[0], &dst);
        FZ_CHECK(is_status(s));
        /* an invalid destination (a fuzzed padding can make it one) must be refused */
        if (dst_valid) FZ_CHECK(s == HOME_OK || s == HOME_E_CONFIG);
        else FZ_CHECK(s != HOME_OK);
        {
            /* a band of it: done exactly when the whole warp is and the band is whole rows of
             * the frame (even ones with vertically subsampled chroma) */
            const int first = fz_range(r, -2, cfg.height + 2), rows = fz_range(r, -1, cfg.height + 2);
            const int even = fmt != HOME_STAB_I420 && fmt != HOME_STAB_NV12 ? 1 : first % 2 == 0 && rows % 2 == 0;
            const int band_ok = first >= 0 && rows >= 1 && first + rows <= cfg.height && even;
            const int sb = home_stab_warp_rows(m, &frames[0], &dst, first, rows);
            FZ_CHECK(is_status(sb));
            if (s != HOME_OK) FZ_CHECK(sb != HOME_OK);
            else FZ_CHECK(band_ok ? sb == HOME_OK : sb == HOME_E_CONFIG);
        }
        sim.tx = fz_float_bits(r);
        sim.ty = fz_float_bits(r);
        sim.angle = fz_float_bits(r);
        sim.log_scale = fz_float_bits(r);
        home_stab_sim_to_matrix(&sim, cfg.width, cfg.height, m);
    }
    FZ_CHECK(home_stab_reset(stab) == HOME_OK);
    if (pushed && valid[0]) {
        FZ_CHECK(home_stab_push(stab, &frames[0], &out) == HOME_OK);
        FZ_CHECK(out.newest_status == HOME_STAB_MOTION_FIRST);
    }
    return 0;
}
