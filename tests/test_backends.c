/* The backend-equivalence test: every compiled SIMD backend of every kernel table (HOME's,
 * the refinement's, the stabiliser's warp) against the scalar reference, bit for bit, through
 * the callers that finish what the kernel bodies leave: odd sizes, unaligned pointers, negative
 * strides, random and extreme inputs; then the whole pipeline per backend. */
#include "test.h"
#include "test_util.h"
#include "home_internal.h"
#include "stab_internal.h"
#include "synth.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const int backends[] = {HOME_SIMD_SSE, HOME_SIMD_AVX2, HOME_SIMD_NEON};

static uint8_t random_byte(synth_rng *rng, int extreme)
{
    double u = synth_uniform(rng);
    if (extreme) return u < 0.5 ? 0 : 255;
    return (uint8_t)(u * 256);
}

void test_kernels_radon(void)
{
    enum { ROWS = 150, COLS = 77, PAD = HOME__RADON_BLOCK, STRIDE = COLS + 2 * PAD + 5 };
    static uint8_t image[ROWS * STRIDE + 64];
    static int32_t want[8 * HOME__RADON_BLOCK], got[8 * HOME__RADON_BLOCK];
    int16_t shift[ROWS], lo[8], hi[8];
    synth_rng rng;
    size_t bi;
    int trial, compared = 0;
    synth_seed(&rng, 17);
    for (trial = 0; trial < 40; trial++) {
        int offset = trial % 4, n_blocks = 1 + trial % 3, b, p, flip = trial & 1;
        double slope = synth_uniform(&rng);
        uint8_t *base = image + offset + PAD;
        const uint8_t *start;
        ptrdiff_t stride = STRIDE;
        for (p = 0; p < ROWS * STRIDE; p++) image[offset + p] = random_byte(&rng, trial % 5 == 0);
        for (p = 0; p < ROWS; p++) shift[p] = (int16_t)((p - ROWS / 2) * slope * 0.5);
        /* row ranges: full, partial, empty and longer than the 16-bit flush interval */
        for (b = 0; b < n_blocks; b++) {
            lo[b] = (int16_t)(b == 1 ? 40 : 0);
            hi[b] = (int16_t)(b == 2 ? 10 : b == 1 ? 30 : ROWS - 1); /* block 1: empty */
        }
        start = flip ? base + (ptrdiff_t)(ROWS - 1) * STRIDE : base;
        if (flip) stride = -stride;
        home__kernels_scalar.radon_blocks(start, stride, shift, -20, n_blocks, lo, hi, want);
        for (bi = 0; bi < sizeof backends / sizeof backends[0]; bi++) {
            const home__kernels *k = home__kernels_for(backends[bi]);
            if (!k) continue;
            memset(got, 0x55, sizeof got);
            k->radon_blocks(start, stride, shift, -20, n_blocks, lo, hi, got);
            CHECK(memcmp(want, got, (size_t)n_blocks * HOME__RADON_BLOCK * sizeof *got) == 0);
            compared++;
        }
    }
    /* an all-255 column of 150 rows overflows 16 bits unless the kernel widens in time */
    CHECK(compared == 0 || compared >= 40);
}

/* The line-end terms: random entry/after rows (including lines that never enter: entry >=
 * after, and entry == rows), a sheared geometry, negative strides, odd ranges. */
void test_kernels_line_ends(void)
{
    enum { ROWS = 90, COLS = 61, PAD = HOME__RADON_BLOCK, STRIDE = COLS + 2 * PAD + 3, N = 150 };
    static uint8_t image[ROWS * STRIDE + 64];
    int16_t shift[ROWS + 1], entry[N], after[N];
    int32_t left[ROWS + 1], right[ROWS + 1], want_sum[N], got_sum[N];
    float want_line[N], got_line[N];
    synth_rng rng;
    size_t bi;
    int trial, compared = 0;
    synth_seed(&rng, 23);
    for (trial = 0; trial < 30; trial++) {
        const int flip = trial & 1, i0 = trial % 7, i1 = N - trial % 5, j0 = -ROWS / 2 - 1;
        uint8_t *base = image + PAD + trial % 4;
        const uint8_t *start = flip ? base + (ptrdiff_t)(ROWS - 1) * STRIDE : base;
        const ptrdiff_t stride = flip ? -STRIDE : STRIDE;
        int p, i;
        for (p = 0; p < ROWS * STRIDE; p++) image[trial % 4 + p] = random_byte(&rng, trial % 5 == 0);
        for (p = 0; p < ROWS; p++) shift[p] = (int16_t)(p / 2); /* 0 .. ROWS/2 - 1 */
        shift[ROWS] = 0x7777; /* the word past the last row: must not matter */
        for (p = 0; p <= ROWS; p++) {
            left[p] = (int32_t)(synth_uniform(&rng) * 1e6);
            right[p] = (int32_t)(synth_uniform(&rng) * 1e6);
        }
        for (i = 0; i < N; i++) {
            /* a line j0 + i inside the columns on rows [entry, after) */
            const int j = j0 + i;
            int e = 0, a = ROWS;
            while (e < ROWS && j + shift[e] < 0) e++;
            a = e;
            while (a < ROWS && j + shift[a] >= 0 && j + shift[a] < COLS) a++;
            if (synth_uniform(&rng) < 0.1) { e = ROWS; a = ROWS; }      /* never enters */
            else if (synth_uniform(&rng) < 0.1) { a = e; }             /* empty */
            entry[i] = (int16_t)e;
            after[i] = (int16_t)a;
            want_sum[i] = (int32_t)(synth_uniform(&rng) * 1e6);
        }
        memcpy(got_sum, want_sum, sizeof got_sum);
        for (i = 0; i < N; i++) want_line[i] = got_line[i] = -1.0f;
        home__kernels_scalar.line_ends(start, stride, shift, j0, entry, after, left, right, 777,
                                       i0, i1, want_sum, want_line);
        for (bi = 0; bi < sizeof backends / sizeof backends[0]; bi++) {
            const home__kernels *k = home__kernels_for(backends[bi]);
            int32_t sum[N];
            float line[N];
            if (!k) continue;
            memcpy(sum, got_sum, sizeof sum);
            memcpy(line, got_line, sizeof line);
            k->line_ends(start, stride, shift, j0, entry, after, left, right, 777, i0, i1, sum, line);
            CHECK(memcmp(want_sum, sum, sizeof sum) == 0);
            CHECK(memcmp(want_line, line, sizeof line) == 0);
            compared++;
        }
    }
    CHECK(compared == 0 || compared >= 30);
}

/* Resampling by gathered neighbours: random positions and weights, odd counts. */
void test_kernels_resample(void)
{
    enum { N = 203 };
    float line[N + 1], f[N], want[N], got[N];
    int16_t k[N];
    synth_rng rng;
    size_t bi;
    int trial, i, compared = 0;
    synth_seed(&rng, 29);
    for (trial = 0; trial < 10; trial++) {
        const int n = N - trial * 3;
        for (i = 0; i <= N; i++) line[i] = (float)(synth_uniform(&rng) * 2000.0 - 1000.0);
        for (i = 0; i < N; i++) {
            k[i] = (int16_t)(synth_uniform(&rng) * N);
            f[i] = (float)synth_uniform(&rng);
        }
        home__kernels_scalar.resample(line, k, f, n, want);
        for (bi = 0; bi < sizeof backends / sizeof backends[0]; bi++) {
            const home__kernels *kt = home__kernels_for(backends[bi]);
            if (!kt) continue;
            memset(got, 0, sizeof got);
            kt->resample(line, k, f, n, got);
            CHECK(memcmp(want, got, (size_t)n * sizeof *got) == 0);
            compared++;
        }
    }
    CHECK(compared == 0 || compared >= 10);
}

void test_kernels_nearest(void)
{
    enum { N = 97, STRIDE = 48 };
    static uint8_t cands[N * STRIDE + 16], query[17];
    synth_rng rng;
    int trial;
    synth_seed(&rng, 18);
    for (trial = 0; trial < 60; trial++) {
        int n = 1 + trial % N, i, wb, wd1, wd2;
        size_t bi;
        for (i = 0; i < N * STRIDE; i++) cands[i] = random_byte(&rng, trial % 7 == 0);
        for (i = 0; i < 17; i++) query[i] = random_byte(&rng, trial % 7 == 0);
        if (trial % 3 == 0) memcpy(cands + 5 * STRIDE + 1, cands + 2 * STRIDE + 1, 16); /* a tie */
        if (trial % 3 == 1) memcpy(cands + 3 * STRIDE + 1, cands + 2 * STRIDE + 1, 16); /* in a group of four */
        home__kernels_scalar.nearest2_l1(query + trial % 2, cands + 1, STRIDE, n, &wb, &wd1, &wd2);
        for (bi = 0; bi < sizeof backends / sizeof backends[0]; bi++) {
            const home__kernels *k = home__kernels_for(backends[bi]);
            int b, d1, d2;
            if (!k) continue;
            k->nearest2_l1(query + trial % 2, cands + 1, STRIDE, n, &b, &d1, &d2);
            CHECK_EQ_INT(b, wb);
            CHECK_EQ_INT(d1, wd1);
            CHECK_EQ_INT(d2, wd2);
        }
    }
}

void test_kernels_smooth(void)
{
    enum { N = 203 };
    static float in[17][N + 1], want[N + 1], got[N + 1];
    float taps[17];
    const float *rows[17];
    synth_rng rng;
    int trial, i, k;
    synth_seed(&rng, 19);
    for (trial = 0; trial < 30; trial++) {
        int radius = 1 + trial % 8, n = 2 * radius + 1 + (trial * 7) % (N - 2 * radius);
        int offset = trial % 2;
        size_t bi;
        home__gauss_taps(0.4f + 0.33f * (float)radius, taps);
        for (k = 0; k < 17; k++) {
            for (i = 0; i <= N; i++)
                in[k][i] = (float)((synth_uniform(&rng) - 0.5) * (trial % 4 == 0 ? 3e6 : 300.0));
            rows[k] = in[k] + offset;
        }
        memset(want, 0, sizeof want);
        home__smooth_r(&home__kernels_scalar, in[0] + offset, want, n, taps, radius);
        for (bi = 0; bi < sizeof backends / sizeof backends[0]; bi++) {
            const home__kernels *kr = home__kernels_for(backends[bi]);
            if (!kr) continue;
            memset(got, 0, sizeof got);
            home__smooth_r(kr, in[0] + offset, got, n, taps, radius);
            CHECK(memcmp(want, got, sizeof want) == 0);
        }
        home__smooth_theta(&home__kernels_scalar, rows, want, n, taps, radius);
        for (bi = 0; bi < sizeof backends / sizeof backends[0]; bi++) {
            const home__kernels *kr = home__kernels_for(backends[bi]);
            if (!kr) continue;
            home__smooth_theta(kr, rows, got, n, taps, radius);
            CHECK(memcmp(want, got, (size_t)n * sizeof *got) == 0);
        }
    }
}

/* The box downscale: the reference against direct sums, then every backend against it, at
 * odd output widths (SIMD bodies and tails), unaligned rows, extreme and random bytes. */
void test_kernels_box_down(void)
{
    enum { W = 4 * 77 + 3, ROWS = 4, STRIDE = W + 9 };
    static uint8_t image[ROWS * STRIDE + 16], want[W], got[W];
    synth_rng rng;
    int trial;
    synth_seed(&rng, 23);
    for (trial = 0; trial < 60; trial++) {
        const int ds = trial & 1 ? 4 : 2, out_w = 1 + (trial * 13) % (W / ds), offset = trial % 7;
        const uint8_t *src = image + offset;
        size_t bi;
        int p, x, u, v, exact = 1;
        for (p = 0; p < ROWS * STRIDE + 16; p++) image[p] = random_byte(&rng, trial % 5 == 0);
        if (trial % 10 == 9) memset(image, 255, sizeof image); /* the largest sums */
        home__kernels_scalar.box_down(src, STRIDE, ds, want, out_w);
        for (x = 0; x < out_w; x++) {
            int sum = 0;
            for (v = 0; v < ds; v++)
                for (u = 0; u < ds; u++) sum += src[v * STRIDE + ds * x + u];
            exact &= want[x] == (uint8_t)((sum + ds * ds / 2) / (ds * ds));
        }
        CHECK(exact);
        for (bi = 0; bi < sizeof backends / sizeof backends[0]; bi++) {
            const home__kernels *kr = home__kernels_for(backends[bi]);
            if (!kr) continue;
            memset(got, 0xAA, sizeof got);
            kr->box_down(src, STRIDE, ds, got, out_w);
            CHECK(memcmp(want, got, (size_t)out_w) == 0);
            CHECK(got[out_w] == 0xAA); /* nothing written past the row */
        }
    }
}

/* Extremum candidates: every backend finds exactly the strict, signed 3x3 extrema of the
 * definition, on rows with plateaus, zeros and both signs, odd lengths and unaligned starts. */
void test_kernels_extremum_candidates(void)
{
    enum { N = 203 };
    static float rows[3][N + 8];
    static int want[N], got[N];
    synth_rng rng;
    int trial, total = 0;
    synth_seed(&rng, 41);
    for (trial = 0; trial < 40; trial++) {
        const int n = 3 + (trial * 37) % (N - 3), off = trial % 5;
        const float *up = rows[0] + off, *mid = rows[1] + off, *down = rows[2] + off;
        int r, i, count, want_n = 0;
        size_t bi;
        for (r = 0; r < 3; r++)
            for (i = 0; i < N + 8; i++) {
                /* coarse levels make ties and plateaus common; every fifth value is 0 */
                float v = (float)((int)(synth_uniform(&rng) * 9) - 4);
                rows[r][i] = i % 5 == 0 ? 0.0f : trial % 3 ? v : v * 0.37f + (float)synth_uniform(&rng);
            }
        for (i = 1; i < n - 1; i++) {
            float v = mid[i];
            int k, above = 1, below = 1;
            const float nb[8] = {up[i - 1], up[i], up[i + 1], mid[i - 1], mid[i + 1], down[i - 1], down[i], down[i + 1]};
            for (k = 0; k < 8; k++) { above &= v > nb[k]; below &= v < nb[k]; }
            if ((v > 0.0f && above) || (v < 0.0f && below)) want[want_n++] = i;
        }
        total += want_n;
        count = home__extremum_candidates(&home__kernels_scalar, up, mid, down, n, got);
        CHECK_EQ_INT(count, want_n);
        CHECK(memcmp(want, got, (size_t)want_n * sizeof *want) == 0);
        for (bi = 0; bi < sizeof backends / sizeof backends[0]; bi++) {
            const home__kernels *kr = home__kernels_for(backends[bi]);
            if (!kr) continue;
            count = home__extremum_candidates(kr, up, mid, down, n, got);
            CHECK_EQ_INT(count, want_n);
            CHECK(memcmp(want, got, (size_t)want_n * sizeof *want) == 0);
        }
    }
    CHECK(total > 100);
}

void test_backends_identical_output(void)
{
    /* the whole registration is bit-identical on every compiled backend */
    enum { W = 320, H = 180 };
    static uint8_t a[W * H], b[W * H];
    static home_features ref_a;
    home_config cfg;
    home_result ref, res;
    double h[9], ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    synth_rng rng;
    size_t bi;
    home_context *ctx;
    synth_seed(&rng, 23);
    synth_corner_homography(&rng, W, H, 12, h);
    synth_render(SYNTH_STRUCTURED, 23, ident, 2.5, 1, a, W, H, W);
    synth_render(SYNTH_STRUCTURED, 23, h, 2.5, 2, b, W, H, W);
    home_default_config(&cfg, W, H);
    cfg.simd = HOME_SIMD_NONE;
    ctx = test_context(W, H, &cfg);
    if (!ctx) { CHECK(0); return; }
    CHECK_EQ_INT(home_register(ctx, a, W, b, W, &ref), HOME_OK);
    CHECK(ref.ok);
    memcpy(&ref_a, home_last_features(ctx, 0), sizeof ref_a);
    for (bi = 0; bi < sizeof backends / sizeof backends[0]; bi++) {
        cfg.simd = backends[bi];
        if (!home__kernels_for(cfg.simd)) continue;
        ctx = test_context(W, H, &cfg);
        if (!ctx) { CHECK(0); continue; }
        CHECK(strcmp(home_simd_backend(ctx), "none") != 0);
        CHECK_EQ_INT(home_register(ctx, a, W, b, W, &res), HOME_OK);
        CHECK(memcmp(ref.H, res.H, sizeof ref.H) == 0);
        CHECK_EQ_INT(res.matches, ref.matches);
        CHECK(memcmp(ref_a.kp, home_last_features(ctx, 0)->kp, sizeof ref_a.kp) == 0);
    }
}

void test_fast_hough_matches_exact(void)
{
    /* the fast transform finds the same lines as the paper's pixel-by-pixel definition */
    enum { W = 320, H = 180 };
    static uint8_t img[W * H];
    static home_features fast, exact;
    home_config cfg;
    double ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    int i, j, found = 0;
    home_context *ctx;
    synth_render(SYNTH_STRUCTURED, 5, ident, 2.5, 1, img, W, H, W);
    home_default_config(&cfg, W, H);
    cfg.hough_method = HOME_HOUGH_EXACT;
    ctx = test_context(W, H, &cfg);
    CHECK_EQ_INT(home_extract(ctx, img, W, &exact), HOME_OK);
    cfg.hough_method = HOME_HOUGH_FAST;
    ctx = test_context(W, H, &cfg);
    CHECK_EQ_INT(home_extract(ctx, img, W, &fast), HOME_OK);
    /* the 40 most salient lines of each sign of the exact transform reappear within 0.3 bin */
    for (i = 0; i < 80; i++) {
        const home_keypoint *e = &exact.kp[i < 40 ? i : exact.n_pos + i - 40];
        for (j = 0; j < fast.n_pos + fast.n_neg; j++) {
            const home_keypoint *f = &fast.kp[j];
            if (f->sign == e->sign && fabsf(f->r - e->r) < 0.3f &&
                fabsf(f->theta - e->theta) < 0.3f * 3.14159265f / 480) { found++; break; }
        }
    }
    printf("     %d of 80 strongest exact-transform keypoints found by the fast transform\n", found);
    CHECK(found >= 64);
}

/* The refinement's kernels (port/refine_kernels.h): every compiled-in backend reproduces the
 * scalar kernels bit for bit: odd sizes, unaligned pointers, points leaving the image, extreme
 * grey levels. */
void test_refine_kernels_backends(void)
{
    static const int simds[3] = {HOME_SIMD_SSE, HOME_SIMD_AVX2, HOME_SIMD_NEON};
    const home__refine_kernels *ref = home__refine_kernels_for(HOME_SIMD_NONE);
    static uint8_t src[101 * 67 + 64], d_ref[101 * 67], d_simd[101 * 67];
    static int16_t t_ref[128], t_simd[128], k_ref[128], k_simd[128];
    static int16_t xs[260], ys[260], gx[260], gy[260];
    static float r[260], w[260], o_ref[260], o_simd[260], a_ref[44 * 4], a_simd[44 * 4];
    static float w_ref[260], w_simd[260], r_simd[260];
    const float aff[3] = {0.0123f, -0.71f, -0.4f};
    float m[9];
    synth_rng rng;
    int s, i, off, tested = 0;
    synth_seed(&rng, 99);
    for (i = 0; i < (int)sizeof src; i++)
        src[i] = (uint8_t)(i % 7 == 0 ? 255 * (i % 2) : synth_uniform(&rng) * 256);
    for (i = 0; i < 260; i++) {
        xs[i] = (int16_t)(synth_uniform(&rng) * 110 - 5);
        ys[i] = (int16_t)(synth_uniform(&rng) * 75 - 4);
        gx[i] = (int16_t)(synth_uniform(&rng) * 1020 - 510);
        gy[i] = (int16_t)(synth_uniform(&rng) * 1020 - 510);
        r[i] = (float)(synth_gauss(&rng) * 30);
        w[i] = (float)synth_uniform(&rng);
    }
    m[0] = 1.01f; m[1] = 0.02f; m[2] = 0.7f; m[3] = -0.015f; m[4] = 0.99f; m[5] = -1.3f;
    m[6] = 1e-4f; m[7] = -2e-4f; m[8] = 1.0f;
    for (s = 0; s < 3; s++) {
        const home__refine_kernels *k = home__refine_kernels_for(simds[s]);
        if (!k) continue;
        tested++;
        for (off = 0; off < 3; off++) {
            const uint8_t *in = src + off;
            int width = 101 - 2 * off, height = 67 - off, b, dy;
            ref->blur3(in, 101, d_ref, 101, width, height, t_ref);
            k->blur3(in, 101, d_simd, 101, width, height, t_simd);
            CHECK(memcmp(d_ref, d_simd, sizeof d_ref) == 0);
            ref->downsample(in, 101, d_ref, 50, width / 2, height / 2);
            k->downsample(in, 101, d_simd, 50, width / 2, height / 2);
            CHECK(memcmp(d_ref, d_simd, sizeof d_ref) == 0);
            for (b = 1; b <= 4; b *= 2)
                for (dy = 0; dy < b; dy++) {
                    ref->select_keys(in + 101 * (dy + 1), 101, width, b, dy, k_ref, dy > 0);
                    k->select_keys(in + 101 * (dy + 1), 101, width, b, dy, k_simd, dy > 0);
                    CHECK(memcmp(k_ref, k_simd, (size_t)width * sizeof *k_ref) == 0);
                }
            for (b = 2; b <= 4; b += 2) {
                /* keys from the rows above (non-negative, < 2^13), an odd count of blocks */
                static uint16_t c_ref[64], c_simd[64];
                const int blocks = (width - 1) / b;
                ref->block_max(k_ref, blocks, b, c_ref);
                k->block_max(k_ref, blocks, b, c_simd);
                CHECK(memcmp(c_ref, c_simd, (size_t)blocks * sizeof *c_ref) == 0);
            }
            /* 252: a count of whole 4-point lanes that is not one of 8 (AVX2's tail) */
            ref->warp(m, xs + off, ys + off, 252, in, 101, width, height, o_ref);
            k->warp(m, xs + off, ys + off, 252, in, 101, width, height, o_simd);
            CHECK(memcmp(o_ref, o_simd, 252 * sizeof *o_ref) == 0);
            ref->warp(m, xs + off, ys + off, 256, in, 101, width, height, o_ref);
            k->warp(m, xs + off, ys + off, 256, in, 101, width, height, o_simd);
            CHECK(memcmp(o_ref, o_simd, 256 * sizeof *o_ref) == 0);
            ref->accumulate(xs + off, ys + off, gx + off, gy + off, r + off, w + off, 256, aff, 1, a_ref);
            k->accumulate(xs + off, ys + off, gx + off, gy + off, r + off, w + off, 256, aff, 1, a_simd);
            CHECK(memcmp(a_ref, a_simd, sizeof a_ref) == 0);
            /* J^T W r alone: the same sums, J^T W J left as it was */
            memset(a_simd, 0x7f, sizeof a_simd);
            k->accumulate(xs + off, ys + off, gx + off, gy + off, r + off, w + off, 256, aff, 0, a_simd);
            CHECK(memcmp(a_ref + 36 * 4, a_simd + 36 * 4, 8 * 4 * sizeof *a_ref) == 0);
            CHECK(a_simd[0] == a_simd[35 * 4 + 3] && a_simd[0] != a_ref[0]);
            /* gain/bias fit: o_ref holds warped samples (some -1), r doubles as the keep mask */
            CHECK_EQ_INT(ref->cauchy_sums(o_ref, r + off, gx + off, 256, 250 - off, 1.07f, -3.5f, 0.11f, w_ref, a_ref),
                         k->cauchy_sums(o_ref, r + off, gx + off, 256, 250 - off, 1.07f, -3.5f, 0.11f, w_simd, a_simd));
            CHECK(memcmp(w_ref, w_simd, 256 * sizeof *w_ref) == 0);
            CHECK(memcmp(a_ref, a_simd, 20 * sizeof *a_ref) == 0);
            ref->residuals(o_ref, gy + off, w_ref, 256, 0.93f, 2.25f, o_simd);
            k->residuals(o_ref, gy + off, w_ref, 256, 0.93f, 2.25f, r_simd);
            CHECK(memcmp(o_simd, r_simd, 256 * sizeof *r_simd) == 0);
        }
        printf("     %s: identical to scalar\n", k->name);
    }
    if (!tested) printf("     no SIMD backend compiled in\n");
}

/* Every compiled-in SIMD backend gives the scalar reference's bytes: odd widths, unaligned source
 * and destination, inside (steep and near-horizontal) and clamped rows, packed steps; nothing
 * written past the row. A third of the rows are stabilisation-like (dx in [0, 2.2) px, slopes
 * up to 0.07 rows per pixel either way, some at the kernels' limits: dx 0, 1, 2 - 2^-16, 2 px,
 * |dy| 4095..4097 / 2^16), long enough to cross source rows within and between the kernels'
 * groups of pixels and to reach the plane's right end; some planes end where the array ends. */
void test_warp_backends_identical(void)
{
    static uint8_t src[4 + 97 * 71 * 4], ref[4 + 300 * 4], out[4 + 300 * 4];
    static const int simds[] = {HOME_SIMD_SSE, HOME_SIMD_AVX2, HOME_SIMD_NEON};
    static const int32_t edge_dx[] = {0, 65536, 131071, 131072}, edge_dy[] = {4095, 4096, 4097};
    synth_rng rng;
    const uint8_t *plane;
    int b, trial, k, tested = 0, mismatches = 0, crossing = 0, partly = 0;
    synth_seed(&rng, 23);
    for (k = 0; k < (int)sizeof src; k++) src[k] = (uint8_t)(synth_uniform(&rng) * 256);
    for (b = 0; b < 3; b++) {
        const home__stab_kernels *kern = home__stab_kernels_for(simds[b]);
        if (!kern || (b > 0 && kern == home__stab_kernels_for(simds[b - 1]))) continue;
        tested++;
        crossing = 0;
        for (trial = 0; trial < 4500; trial++) {
            const int w = 2 + (int)(synth_uniform(&rng) * 95), h = 2 + (int)(synth_uniform(&rng) * 69);
            const int step = trial % 5 == 4 ? 2 : 1, dst_step = step;
            const ptrdiff_t stride = (ptrdiff_t)w * step + (ptrdiff_t)(synth_uniform(&rng) * 8);
            int n = 1 + (int)(synth_uniform(&rng) * 299);
            const int so = trial & 3, dofs = (trial >> 2) & 3;
            const int inside = trial % 3 != 0, stab = trial % 3 == 2;
            /* inside rows: start and end well within the plane; others roam outside it */
            double x0 = inside ? synth_uniform(&rng) * (w - 1.01) : (synth_uniform(&rng) - 0.5) * 3 * w;
            double y0 = inside ? synth_uniform(&rng) * (h - 1.01) : (synth_uniform(&rng) - 0.5) * 3 * h;
            double x1 = inside ? synth_uniform(&rng) * (w - 1.01) : (synth_uniform(&rng) - 0.5) * 3 * w;
            double y1 = inside ? synth_uniform(&rng) * (h - 1.01) : (synth_uniform(&rng) - 0.5) * 3 * h;
            int32_t dx, dy;
            /* stabilisation rows are near-horizontal: the kernels' shared-row path */
            if (inside && trial % 6 == 1) y1 = y0 * (1.0 - 0.02 * synth_uniform(&rng));
            dx = (int32_t)((x1 - x0) * 65536.0 / (n > 1 ? n - 1 : 1));
            dy = (int32_t)((y1 - y0) * 65536.0 / (n > 1 ? n - 1 : 1));
            if (stab) {   /* from near the left end, as long as the row stays inside */
                const double u = synth_uniform(&rng);
                x0 = synth_uniform(&rng) * 0.3 * (w - 1.01);
                dx = u < 0.1 ? edge_dx[trial % 4] : (int32_t)(synth_uniform(&rng) * 2.2 * 65536);
                dy = u > 0.9 ? edge_dy[trial % 3] : (int32_t)(synth_uniform(&rng) * 0.07 * 65536);
                if (synth_uniform(&rng) < 0.5) dy = -dy;
                if (dx > 0 && (w - 1.01 - x0) * 65536.0 / dx + 1 < n) n = (int)((w - 1.01 - x0) * 65536.0 / dx) + 1;
                if (dy != 0) {
                    const double room = dy > 0 ? h - 1.01 - y0 : y0;
                    if (room * 65536.0 / abs(dy) + 1 < n) n = (int)(room * 65536.0 / abs(dy)) + 1;
                }
                if (n < 1) n = 1;
                crossing += n >= 32 && ((int32_t)(y0 * 65536) >> 16) != (((int32_t)(y0 * 65536) + (n - 1) * dy) >> 16);
            }
            if ((size_t)(so + stride * h) > sizeof src) continue;
            /* every seventh plane ends where src ends: a read past its last row (the kernels'
             * 16-byte windows) leaves the array, which SANITIZE=address builds report */
            plane = trial % 7 == 5 ? src + sizeof src - ((size_t)stride * (size_t)(h - 1) + (size_t)w * (size_t)step) : src + so;
            memset(ref, 0x77, sizeof ref);
            memset(out, 0x77, sizeof out);
            home__warp_row_c(plane, stride, step, w, h, (int32_t)(x0 * 65536), (int32_t)(y0 * 65536),
                             dx, dy, ref + dofs, dst_step, n);
            home__warp_row(kern, plane, stride, step, w, h, (int32_t)(x0 * 65536),
                           (int32_t)(y0 * 65536), dx, dy, out + dofs, dst_step, n);
            mismatches += memcmp(ref, out, sizeof ref) != 0;
            if (step == 1 && !home__warp_row_inside(w, h, (int32_t)(x0 * 65536), (int32_t)(y0 * 65536), dx, dy, n)) {
                /* a row that leaves the plane with 32+ samples inside it: a SIMD body between
                 * the reference's ends */
                int i, run = 0, longest = 0;
                for (i = 0; i < n; i++) {
                    const int in = home__warp_row_inside(w, h, (int32_t)(x0 * 65536) + i * dx,
                                                         (int32_t)(y0 * 65536) + i * dy, dx, dy, 1);
                    run = in ? run + 1 : 0;
                    if (run > longest) longest = run;
                }
                partly += longest >= 32;
            }
        }
        printf("    warp backend %s: %d mismatching rows of 4500 (%d stabilisation-like rows of 32+ pixels "
               "crossing a source row, %d rows partly outside with 32+ pixels inside)\n",
               kern->name, mismatches, crossing, partly);
        CHECK(crossing >= 100);
        CHECK(partly >= 100);
        partly = 0;
    }
    CHECK_EQ_INT(mismatches, 0);
    CHECK(tested >= 1 || home__stab_kernels_for(HOME_SIMD_AUTO) == &home__stab_kernels_scalar);
}

/* Rows on a plane's last row pair that run to its right end, the plane ending where its array
 * ends: the backends' bytes are the reference's, and a read past the plane (a 16-byte window
 * one column too far) leaves the array, which SANITIZE=address builds report. */
void test_warp_plane_end(void)
{
    static uint8_t src[64 * 4], ref[4 + 128], out[4 + 128];
    static const int simds[] = {HOME_SIMD_SSE, HOME_SIMD_AVX2, HOME_SIMD_NEON};
    synth_rng rng;
    int b, w, k, rows = 0, mismatches = 0;
    synth_seed(&rng, 29);
    for (k = 0; k < (int)sizeof src; k++) src[k] = (uint8_t)(synth_uniform(&rng) * 256);
    for (b = 0; b < 3; b++) {
        const home__stab_kernels *kern = home__stab_kernels_for(simds[b]);
        if (!kern || (b > 0 && kern == home__stab_kernels_for(simds[b - 1]))) continue;
        for (w = 16; w <= 64; w++)
            for (k = 0; k < 24; k++) {
                const int h = 2 + k % 3, n = 16 + (int)(synth_uniform(&rng) * 100);
                const uint8_t *plane = src + sizeof src - (size_t)w * (size_t)h;   /* stride w */
                const double x1 = w - 1.01 - 0.3 * synth_uniform(&rng), x0 = synth_uniform(&rng) * 0.5 * x1;
                const double y0 = h - 2 + 0.98 * synth_uniform(&rng);
                const int32_t dx = (int32_t)((x1 - x0) * 65536.0 / (n - 1));
                memset(ref, 0x77, sizeof ref);
                memset(out, 0x77, sizeof out);
                home__warp_row_c(plane, w, 1, w, h, (int32_t)(x0 * 65536), (int32_t)(y0 * 65536), dx, 0, ref + 1, 1, n);
                home__warp_row(kern, plane, w, 1, w, h, (int32_t)(x0 * 65536), (int32_t)(y0 * 65536), dx,
                               0, out + 1, 1, n);
                mismatches += memcmp(ref, out, sizeof ref) != 0;
                rows++;
            }
        /* the identity's rows (a tripod shot's output): the last sample of each lies on the
         * plane's last column and the last row on its last row, outside the inside rule */
        for (w = 16; w <= 64; w++)
            for (k = 0; k < 3; k++) {
                const int h = 4, y = h - 1 - k % 2;
                const uint8_t *plane = src + sizeof src - (size_t)w * (size_t)h;
                memset(ref, 0x77, sizeof ref);
                memset(out, 0x77, sizeof out);
                home__warp_row_c(plane, w, 1, w, h, 0, y * 65536, 65536, 0, ref + 1, 1, w);
                home__warp_row(kern, plane, w, 1, w, h, 0, y * 65536, 65536, 0, out + 1, 1, w);
                mismatches += memcmp(ref, out, sizeof ref) != 0 ||
                              memcmp(ref + 1, plane + (ptrdiff_t)y * w, (size_t)w) != 0;
                rows++;
            }
    }
    printf("    %d rows at planes' bottom right ends, %d mismatching\n", rows, mismatches);
    CHECK_EQ_INT(mismatches, 0);
}
