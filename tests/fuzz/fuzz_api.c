/* Fuzz the public API: fuzzed configs, image sizes, strides, arena sizes and alignments, image
 * content, corrupted features and call orders drive every home_* entry point. Each call must
 * return its documented status, and results must keep their invariants (keypoints in range and
 * sorted, ok => finite H with H[8] = 1, det > 0 and enough inliers, bit-identical re-runs).
 *
 * Input layout (bytes consumed from the front, the rest is image content):
 *   flags, sizes, config overrides, arena/stride tweaks, image recipe, then pixels/shapes. */
#include "fuzz_util.h"
#include "home.h"
#include <math.h>

/* Executions must be fast (millions per campaign, issue 7), so configs are tiny unless all three
 * FLAG_LARGE bits are set (one random input in eight): tiny = sides 32..36, 16..24 theta bins,
 * 8..40 keypoints per sign and Hough images up to FZ_TINY_HOUGH_CELLS; large = sides 32..56,
 * 16..48 bins, 8..200 keypoints, Hough images up to FZ_MAX_HOUGH_CELLS. Tiny configs still walk
 * every entry point, the validation, the arena layout and both outcomes of a registration; the
 * large ones keep the loop counts of bigger images in play. Buffers allow up to 96 px (raw
 * sizes). */
#define FZ_TINY_SIDE 36
#define FZ_TINY_THETA 24
#define FZ_TINY_KEYPOINTS 40
#define FZ_TINY_HOUGH_CELLS (128 * 64)
#define FZ_SMALL_SIDE 56
#define FZ_SMALL_THETA 48
#define FZ_SMALL_KEYPOINTS 200
#define FZ_MAX_SIDE 96
#define FZ_MAX_HOUGH_CELLS (256 * 200)
#define FZ_MAX_STRIDE (FZ_MAX_SIDE + 16)
#define FZ_ARENA_BYTES (6u << 20)

enum {
    FLAG_FUZZ_CONFIG = 1 << 0,   /* overwrite config fields with fuzzed raw values */
    FLAG_MISALIGN = 1 << 1,      /* arena not aligned to HOME_ARENA_ALIGN */
    FLAG_ARENA_SHORT = 1 << 2,   /* arena smaller than needed */
    FLAG_STRIDE = 1 << 3,        /* fuzzed strides (padding, too small, negative) */
    FLAG_INDEPENDENT_B = 1 << 4, /* image b unrelated to a (else a shifted copy) */
    FLAG_RENDER = 1 << 5,        /* render the Hough image */
    FLAG_CORRUPT = 1 << 6,       /* corrupt features before matching */
    FLAG_RAW_SIZE = 1 << 7,      /* any width/height, in range or not */
    FLAG_VIDEO = 1 << 8,         /* extract both frames again and match: same result as the pair */
    FLAG_CLOCK = 1 << 9,         /* a timing hook is set */
    FLAG_REFINE = 1 << 10,       /* home_refine() from a fuzzed initial H */
    FLAG_EXACT = 1 << 11,        /* the exact (pixel by pixel) Hough method */
    FLAG_HOUGH_HALF = 1 << 12,   /* the Hough transform of a 2x2-downscaled copy */
    FLAG_LARGE = 7 << 13         /* all three set: large sizes and counts (else tiny ones) */
};

static union { unsigned char bytes[FZ_ARENA_BYTES]; double align; } arena;
static uint8_t img_a_buf[FZ_MAX_STRIDE * FZ_MAX_SIDE], img_b_buf[FZ_MAX_STRIDE * FZ_MAX_SIDE];
static uint8_t hough[1u << 20];
static home_features fa, fb;

/* Images and the arena end exactly where their buffers end, so ASan sees any read past them. */
static uint8_t *at_buffer_end(uint8_t *buf, size_t size, int width, int height, ptrdiff_t stride)
{
    return stride < width ? buf : buf + size - ((size_t)(height - 1) * (size_t)stride + (size_t)width);
}

static int is_status(int s)
{
    return s <= HOME_OK && s >= HOME_E_BUFFER;
}

static double fake_clock(void *user)
{
    return (double)++*(unsigned *)user;
}

/* Fill a width x height image: tiled raw bytes, or shapes (rectangles and bars) on a ramp. */
FZ_NO_COVERAGE static void fill_image(fz_reader *r, uint8_t *img, int width, int height, ptrdiff_t stride)
{
    int recipe = (int)(fz_u8(r) % 3), x, y;
    if (recipe == 0) {
        size_t n = fz_remaining(r), k = 0;
        const uint8_t *src = r->data + r->pos;
        for (y = 0; y < height; y++)
            for (x = 0; x < width; x++) img[y * stride + x] = n ? src[k++ % n] : 0;
        r->pos += n < 256 ? n : 256;
    } else {
        int base = (int)fz_u8(r), slope_x = fz_range(r, -3, 3), slope_y = fz_range(r, -3, 3);
        int shapes = recipe == 1 ? fz_range(r, 0, 12) : 1, s;
        for (y = 0; y < height; y++)
            for (x = 0; x < width; x++)
                img[y * stride + x] = (uint8_t)((base + slope_x * x + slope_y * y) & 255);
        for (s = 0; s < shapes; s++) {
            int x0 = fz_range(r, 0, width - 1), y0 = fz_range(r, 0, height - 1);
            int x1 = fz_range(r, x0, width - 1), y1 = fz_range(r, y0, height - 1);
            int v = (int)fz_u8(r);
            for (y = y0; y <= y1; y++)
                for (x = x0; x <= x1; x++) img[y * stride + x] = (uint8_t)v;
        }
    }
}

/* b = a shifted by (dx, dy) with edge replication, plus sparse fuzzed perturbations. */
FZ_NO_COVERAGE static void shifted_copy(fz_reader *r, const uint8_t *a, uint8_t *b, int width, int height,
                         ptrdiff_t sa, ptrdiff_t sb)
{
    int dx = fz_range(r, -6, 6), dy = fz_range(r, -6, 6), x, y, k, n = fz_range(r, 0, 8);
    for (y = 0; y < height; y++)
        for (x = 0; x < width; x++) {
            int ux = x - dx, uy = y - dy;
            ux = ux < 0 ? 0 : ux >= width ? width - 1 : ux;
            uy = uy < 0 ? 0 : uy >= height ? height - 1 : uy;
            b[y * sb + x] = a[uy * sa + ux];
        }
    for (k = 0; k < n; k++) b[fz_range(r, 0, height - 1) * sb + fz_range(r, 0, width - 1)] ^= (uint8_t)fz_u8(r);
}

static void check_features(const home_config *cfg, const home_features *f)
{
    int i;
    FZ_CHECK(f->width == cfg->width && f->height == cfg->height);
    FZ_CHECK(f->n_pos >= 0 && f->n_pos <= cfg->keypoints_per_sign);
    FZ_CHECK(f->n_neg >= 0 && f->n_neg <= cfg->keypoints_per_sign);
    FZ_CHECK(isfinite(f->j_std) && f->j_std >= 0.0f);
    for (i = 0; i < f->n_pos + f->n_neg; i++) {
        const home_keypoint *kp = &f->kp[i];
        FZ_CHECK(kp->sign == (i < f->n_pos ? 1 : -1));
        /* [0, pi) before rounding: a theta just below pi rounds to (float)pi (regress-theta-pi) */
        FZ_CHECK(kp->theta >= 0.0f && kp->theta <= (float)3.14159265358979323846);
        FZ_CHECK(isfinite(kp->r) && isfinite(kp->saliency) && kp->saliency >= 0.0f);
        FZ_CHECK(kp->has_alt == 0 || kp->has_alt == 1);
        if (i != 0 && i != f->n_pos) FZ_CHECK(kp[-1].saliency >= kp->saliency);
    }
}

static int same_keypoints(const home_features *a, const home_features *b)
{
    int i;
    if (a->n_pos != b->n_pos || a->n_neg != b->n_neg) return 0;
    for (i = 0; i < a->n_pos + a->n_neg; i++) {
        const home_keypoint *p = &a->kp[i], *q = &b->kp[i];
        if (memcmp(&p->theta, &q->theta, sizeof p->theta) || memcmp(&p->r, &q->r, sizeof p->r) ||
            memcmp(&p->saliency, &q->saliency, sizeof p->saliency) || p->sign != q->sign ||
            p->has_alt != q->has_alt || memcmp(p->desc, q->desc, sizeof p->desc) ||
            memcmp(p->alt_desc, q->alt_desc, sizeof p->alt_desc))
            return 0;
    }
    return 1;
}

static void check_result(const home_config *cfg, const home_result *res)
{
    int k;
    FZ_CHECK(res->ok == 0 || res->ok == 1);
    FZ_CHECK(res->matches >= 0 && res->inliers >= 0 && res->inliers <= res->matches);
    for (k = 0; k < 9; k++) FZ_CHECK(isfinite(res->H[k]));
    if (res->ok) {
        const double *h = res->H;
        double det = h[0] * (h[4] * h[8] - h[5] * h[7]) - h[1] * (h[3] * h[8] - h[5] * h[6]) +
                     h[2] * (h[3] * h[7] - h[4] * h[6]);
        FZ_CHECK(h[8] == 1.0 && det > 0.0);
        FZ_CHECK(res->failure == HOME_FAIL_NONE);
        /* ok means a determined model within the cap and a predicted error within the bound */
        FZ_CHECK(res->sigma_px >= 0.0 && res->sigma_px <= cfg->max_sigma_px);
        FZ_CHECK(res->model >= HOME_MODEL_IDENTITY && res->model <= cfg->max_model);
        if (res->inliers < cfg->min_inliers) /* the refinement's rescue (home.h's failure rule) */
            FZ_CHECK(res->refined &&
                     (res->refine_zncc >= 0.9 || res->refine_inlier_share >= 0.9));
    } else {
        FZ_CHECK(res->failure >= HOME_FAIL_FEW_MATCHES && res->failure <= HOME_FAIL_INCONSISTENT);
    }
    FZ_CHECK(res->model >= HOME_MODEL_IDENTITY && res->model <= HOME_MODEL_HOMOGRAPHY);
    FZ_CHECK(!(res->sigma_px < 0.0)); /* NaN never: infinite when undetermined */
}

static void fuzz_config(fz_reader *r, home_config *cfg)
{
    int n = fz_range(r, 1, 4), k;
    for (k = 0; k < n; k++) {
        int32_t raw = (int32_t)fz_u32(r);
        float f = fz_float_bits(r);
        switch (fz_u8(r) % 20) {
        case 0: cfg->theta_bins = raw % 4096; break;
        case 1: cfg->wrap_band = raw % 1024; break;
        case 2: cfg->r_step = f; break;
        case 3: cfg->r_bins = raw % 40000; break;
        case 4: cfg->smooth_sigma = f; break;
        case 5: cfg->keypoints_per_sign = raw % 2048; break;
        case 6: cfg->ratio = f; break;
        case 7: cfg->threshold_start = f; break;
        case 8: cfg->threshold_final = f; break;
        case 9: cfg->min_inliers = raw % 4096; break;
        case 10: cfg->refine_levels = raw % 16; break;
        case 11: cfg->refine_iterations = raw % 256; break;
        case 12: cfg->refine_trust_px = f; break;
        case 13: cfg->simd = raw % 8; break;
        case 14: cfg->hough_method = raw % 4; break;
        case 15: /* 1, 2, 4 valid; the fast pass's 0, 2, 4 from the same bytes (the corpus's
                  * entries keep their meaning) */
            cfg->hough_downscale = raw % 6;
            cfg->fast_pass_downscale = (int)((uint32_t)raw / 6 % 6);
            break;
        case 16: cfg->match_theta_window = raw % 4096; break;
        case 17: cfg->refine_points = raw % 8192; break;
        case 18: cfg->refine_finest_level = raw % 4; break;
        default:
            /* a third each: the model cap (-1..5: 0..4 valid), the sigma bound, the width */
            if (raw % 3 == 0) cfg->max_model = (int)((uint32_t)raw / 3 % 7) - 1;
            else if (raw % 3 == 1 || raw % 3 == -1) cfg->max_sigma_px = f;
            else cfg->width = raw;
            break;
        }
    }
}

/* Corrupt b's features the ways a caller could: counts, content, magic, size. Returns the
 * status home_match() must give. */
static int corrupt_features(fz_reader *r, const home_config *cfg, home_features *f)
{
    int i, n;
    switch (fz_u8(r) % 5) {
    case 0:
        f->n_pos = (int32_t)fz_u32(r);
        if (f->n_pos < 0 || f->n_pos > HOME_MAX_KEYPOINTS_PER_SIGN) return HOME_E_STATE;
        return f->n_pos > cfg->keypoints_per_sign ? HOME_E_MISMATCH : HOME_OK;
    case 1:
        f->magic ^= 1u << (fz_u8(r) % 32);
        return HOME_E_STATE;
    case 2:
        f->height = f->height + 1;
        return HOME_E_MISMATCH;
    case 3:
        f->config_id ^= 1u << (fz_u8(r) % 32);
        return HOME_E_MISMATCH;
    default: /* garbage keypoint content (NaN/Inf angles, any sign byte) */
        n = f->n_pos + f->n_neg;
        for (i = 0; i < n && fz_remaining(r) >= 8; i++) {
            f->kp[i].theta = fz_float_bits(r);
            f->kp[i].r = fz_float_bits(r);
            f->kp[i].sign = (int8_t)fz_u8(r);
            f->kp[i].has_alt = (uint8_t)fz_u8(r);
            if (fz_remaining(r) >= 8) {
                f->kp[i].cos_theta = fz_float_bits(r);
                f->kp[i].sin_theta = fz_float_bits(r);
            }
        }
        return HOME_OK;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader rd = {data, size, 0}, *r = &rd;
    unsigned flags = fz_u16(r), ticks = 0;
    home_config cfg;
    home_context *ctx = NULL;
    home_result res, res2;
    size_t need, have, needed = 0;
    int large = (flags & FLAG_LARGE) == FLAG_LARGE, width, height, status, expect, s;
    ptrdiff_t stride_a, stride_b;
    unsigned char *base;
    uint8_t *img_a, *img_b;
    size_t off;

    if (flags & FLAG_RAW_SIZE) {
        width = (int16_t)fz_u16(r);
        height = (int16_t)fz_u16(r);
    } else {
        width = fz_range(r, HOME_MIN_SIDE, large ? FZ_SMALL_SIDE : FZ_TINY_SIDE);
        height = fz_range(r, HOME_MIN_SIDE, large ? FZ_SMALL_SIDE : FZ_TINY_SIDE);
    }
    status = home_default_config(&cfg, width, height);
    expect = (width < HOME_MIN_SIDE || height < HOME_MIN_SIDE || width > HOME_MAX_SIDE ||
              height > HOME_MAX_SIDE) ? HOME_E_SIZE : HOME_OK;
    FZ_CHECK(status == expect);
    /* raw values come with FLAG_FUZZ_CONFIG */
    cfg.theta_bins = fz_range(r, 16, large ? FZ_SMALL_THETA : FZ_TINY_THETA);
    cfg.wrap_band = cfg.theta_bins / 18;
    cfg.keypoints_per_sign = fz_range(r, 8, large ? FZ_SMALL_KEYPOINTS : FZ_TINY_KEYPOINTS);
    cfg.min_inliers = fz_range(r, 4, 30);
    cfg.simd = fz_range(r, HOME_SIMD_AUTO, HOME_SIMD_AVX2 + 1); /* uncompiled ones are refused */
    if (flags & FLAG_EXACT) cfg.hough_method = HOME_HOUGH_EXACT;
    if (flags & FLAG_HOUGH_HALF) cfg.hough_downscale = 2;
    if (flags & FLAG_CLOCK) {
        cfg.clock = fake_clock;
        cfg.clock_user = &ticks;
    }
    if (flags & FLAG_FUZZ_CONFIG) fuzz_config(r, &cfg);

    status = home_validate_config(&cfg);
    FZ_CHECK(is_status(status));
    need = home_arena_size(&cfg);
    FZ_CHECK((status == HOME_OK) == (need > 0));
    FZ_CHECK(need % HOME_ARENA_ALIGN == 0);

    off = (flags & FLAG_MISALIGN) ? (size_t)fz_range(r, 1, HOME_ARENA_ALIGN - 1) : 0;
    have = FZ_ARENA_BYTES - 2 * HOME_ARENA_ALIGN;
    if (status == HOME_OK && need <= have)
        have = (flags & FLAG_ARENA_SHORT) ? need - 1 - (size_t)fz_range(r, 0, (int)(need - 1 < 65535 ? need - 1 : 65535)) : need;
    base = fz_align16(arena.bytes) + ((FZ_ARENA_BYTES - HOME_ARENA_ALIGN - have - off) & ~(size_t)(HOME_ARENA_ALIGN - 1)) + off;
    {
        int init = home_init(&ctx, &cfg, base, have, &needed);
        int want = status != HOME_OK ? status
                   : (flags & FLAG_MISALIGN) ? HOME_E_ARENA_ALIGN
                   : need > have ? HOME_E_ARENA_SMALL : HOME_OK;
        FZ_CHECK(init == want);
        FZ_CHECK((init == HOME_OK) == (ctx != NULL));
        if (init == HOME_OK || init == HOME_E_ARENA_SMALL) FZ_CHECK(needed == need);
        if (init != HOME_OK) return 0;
    }
    /* a valid config may still describe images larger than this harness's buffers, or a Hough
     * image so large that executions would crawl (fuzzed theta_bins, r_step, r_bins) */
    if (cfg.width > FZ_MAX_SIDE || cfg.height > FZ_MAX_SIDE) return 0;
    {
        int hw = 0, hh = 0;
        FZ_CHECK(home_hough_size(ctx, &hw, &hh) == HOME_OK);
        if ((long)hw * hh > (large ? FZ_MAX_HOUGH_CELLS : FZ_TINY_HOUGH_CELLS)) return 0;
    }

    stride_a = stride_b = cfg.width;
    if (flags & FLAG_STRIDE) {
        stride_a = cfg.width + fz_range(r, -2, FZ_MAX_STRIDE - cfg.width);
        stride_b = (fz_u8(r) & 1) ? -(ptrdiff_t)cfg.width : cfg.width + fz_range(r, 0, FZ_MAX_STRIDE - cfg.width);
    }
    img_a = at_buffer_end(img_a_buf, sizeof img_a_buf, cfg.width, cfg.height, stride_a);
    img_b = at_buffer_end(img_b_buf, sizeof img_b_buf, cfg.width, cfg.height, stride_b);
    if (stride_a >= cfg.width) fill_image(r, img_a, cfg.width, cfg.height, stride_a);
    if (stride_b >= cfg.width) {
        if ((flags & FLAG_INDEPENDENT_B) || stride_a < cfg.width)
            fill_image(r, img_b, cfg.width, cfg.height, stride_b);
        else
            shifted_copy(r, img_a, img_b, cfg.width, cfg.height, stride_a, stride_b);
    }

    /* stages out of order: matching before any extraction */
    memset(&fa, 0, sizeof fa);
    FZ_CHECK(home_match(ctx, &fa, &fa, &res) == HOME_E_STATE);
    FZ_CHECK(home_last_features(ctx, 0) == NULL);

    s = home_register(ctx, img_a, stride_a, img_b, stride_b, &res);
    if (stride_a < cfg.width || stride_b < cfg.width) {
        FZ_CHECK(s == HOME_E_STRIDE);
        FZ_CHECK(home_extract(ctx, img_a, stride_a, &fa) == (stride_a < cfg.width ? HOME_E_STRIDE : HOME_OK));
        return 0;
    }
    FZ_CHECK(s == HOME_OK);
    check_result(&cfg, &res);
    FZ_CHECK(home_last_features(ctx, 0) != NULL && home_last_features(ctx, 2) == NULL);
    check_features(&cfg, home_last_features(ctx, 0));
    check_features(&cfg, home_last_features(ctx, 1));

    FZ_CHECK(res.fast_pass == 0 || res.fast_pass == 1);
    FZ_CHECK(!res.fast_pass || res.ok);
    if (res.fast_pass) {
        /* the fast pass's features are its own: refused beside the configured pass's */
        FZ_CHECK(home_extract(ctx, img_a, stride_a, &fa) == HOME_OK);
        FZ_CHECK(home_extract(ctx, img_b, stride_b, &fb) == HOME_OK);
        FZ_CHECK(home_match(ctx, home_last_features(ctx, 0), &fb, &res2) == HOME_E_MISMATCH);
    } else if (flags & FLAG_VIDEO) {
        /* the video path (and so a re-extraction) reproduces the pair path bit for bit */
        FZ_CHECK(home_extract(ctx, img_a, stride_a, &fa) == HOME_OK);
        FZ_CHECK(home_extract(ctx, img_b, stride_b, &fb) == HOME_OK);
        FZ_CHECK(same_keypoints(&fa, home_last_features(ctx, 0)));
        FZ_CHECK(same_keypoints(&fb, home_last_features(ctx, 1)));
        FZ_CHECK(home_match(ctx, &fa, &fb, &res2) == HOME_OK);
        FZ_CHECK(res2.ok == res.ok && res2.inliers == res.inliers && memcmp(res2.H, res.H, sizeof res.H) == 0);
    } else {
        memcpy(&fa, home_last_features(ctx, 0), sizeof fa);
        memcpy(&fb, home_last_features(ctx, 1), sizeof fb);
    }

    {
        int i, hw = 0, hh = 0;
        float col, row;
        FZ_CHECK(home_hough_size(ctx, &hw, &hh) == HOME_OK);
        FZ_CHECK(hh == cfg.theta_bins && hw >= 2);
        for (i = 0; i < fa.n_pos + fa.n_neg; i++) {
            FZ_CHECK(home_keypoint_to_hough(ctx, &fa.kp[i], &col, &row) == HOME_OK);
            FZ_CHECK(col >= 0.0f && col <= (float)hw && row >= 0.0f && row <= (float)hh * 1.0001f);
        }
        if ((flags & FLAG_RENDER) && (size_t)hw * (size_t)hh <= sizeof hough) {
            int out_stride = hw + fz_range(r, -1, 3);
            if ((size_t)out_stride * (size_t)hh > sizeof hough) out_stride = hw;
            uint8_t *out = at_buffer_end(hough, sizeof hough, hw, hh, out_stride);
            FZ_CHECK(home_render_hough(ctx, img_a, stride_a, out, out_stride) ==
                     (out_stride < hw ? HOME_E_STRIDE : HOME_OK));
        }
    }

    if (flags & FLAG_CORRUPT) {
        expect = corrupt_features(r, &cfg, &fb);
        s = home_match(ctx, &fa, &fb, &res2);
        FZ_CHECK(s == expect);
        if (s == HOME_OK) {
            int k;
            FZ_CHECK(res2.ok == 0 || res2.ok == 1);
            for (k = 0; k < 9; k++) FZ_CHECK(isfinite(res2.H[k]));
        }
    }

    if (flags & FLAG_REFINE) {
        /* any finite H with H[8] != 0 is accepted; NaN/Inf or H[8] == 0 are refused */
        double h0[9];
        int k, finite = 1;
        for (k = 0; k < 9; k++) {
            h0[k] = (fz_u8(r) & 1) ? res.H[k] + (double)fz_float_bits(r) * 1e-3 : res.H[k];
            finite &= isfinite(h0[k]);
        }
        expect = finite && fabs(h0[8]) > 1e-12 ? HOME_OK : HOME_E_CONFIG;
        s = home_refine(ctx, img_a, stride_a, img_b, stride_b, h0, &res2);
        FZ_CHECK(s == expect);
        if (s == HOME_OK) FZ_CHECK(res2.ok == 0 || res2.ok == 1);
        if (s == HOME_OK && res2.ok) for (k = 0; k < 9; k++) FZ_CHECK(isfinite(res2.H[k]));
    }

    /* features of another config are refused */
    fa.config_id ^= 0x80u;
    FZ_CHECK(home_match(ctx, &fa, &fb, &res2) == HOME_E_MISMATCH);
    return 0;
}
