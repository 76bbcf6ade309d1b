/* Proofs of the embedded promises that need running code:
 * - the output depends on the pixels only: not on what the arena held before, the row padding,
 *   the image pointer's alignment, nor (per Hough method) the SIMD backend;
 * - the measured stack of every public function, libc included, stays under 16 KiB: each runs
 *   on a thread whose stack was painted with a pattern, and the untouched part is counted. */
#define _POSIX_C_SOURCE 200809L
#include "test.h"
#include "test_bad_input.h"
#include "home_stab.h"
#include "synth.h"
#include <pthread.h>
#include <string.h>

#if defined(__SANITIZE_ADDRESS__)
#define STACK_INSTRUMENTED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define STACK_INSTRUMENTED 1
#endif
#endif

#define STACK_LIMIT 16384

enum { DW = 160, DH = 120, PAD = 13 };
static union { unsigned char bytes[4u << 20]; double align; } proof_arena;
static uint8_t da[DW * DH], db[DW * DH], padded[(DW + PAD) * DH + 1];
static home_features ref_a, ref_b;

static void make_pair(void)
{
    static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double h[9];
    synth_rng rng;
    synth_seed(&rng, 77);
    synth_corner_homography(&rng, DW, DH, 6, h);
    synth_render(SYNTH_STRUCTURED, 77, identity, 2.5, 1, da, DW, DH, DW);
    synth_render(SYNTH_STRUCTURED, 77, h, 2.5, 2, db, DW, DH, DW);
}

int same_features(const home_features *a, const home_features *b)
{
    int i;
    if (a->n_pos != b->n_pos || a->n_neg != b->n_neg || memcmp(&a->j_std, &b->j_std, sizeof a->j_std))
        return 0;
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

/* Register the pair in a fresh context on an arena pre-filled with `fill`; image a is copied
 * into rows `stride` apart starting `offset` bytes into a buffer whose padding holds noise. */
static int register_layout(home_config *cfg, int fill, ptrdiff_t stride, size_t offset,
                           home_result *res, home_features *fa, home_features *fb)
{
    home_context *ctx = NULL;
    uint8_t *img = padded + offset;
    int y;
    synth_rng rng;
    synth_seed(&rng, (uint64_t)fill + 1);
    for (y = 0; y < (int)sizeof padded; y++) padded[y] = (uint8_t)(synth_uniform(&rng) * 256);
    for (y = 0; y < DH; y++) memcpy(img + y * stride, da + y * DW, DW);
    memset(proof_arena.bytes, fill, sizeof proof_arena.bytes);
    if (home_init(&ctx, cfg, ALIGNED_ARENA(proof_arena.bytes), ALIGNED_BYTES(proof_arena.bytes), NULL) != HOME_OK) return -1;
    if (home_register(ctx, img, stride, db, DW, res) != HOME_OK) return -1;
    memcpy(fa, home_last_features(ctx, 0), sizeof *fa);
    memcpy(fb, home_last_features(ctx, 1), sizeof *fb);
    return 0;
}

void test_output_independent_of_arena_and_layout(void)
{
    static const int backends[] = {HOME_SIMD_NONE, HOME_SIMD_SSE, HOME_SIMD_AVX2, HOME_SIMD_NEON};
    static const int methods[] = {HOME_HOUGH_FAST, HOME_HOUGH_EXACT};
    static home_features fa, fb;
    size_t m, b;
    make_pair();
    for (m = 0; m < sizeof methods / sizeof methods[0]; m++) {
        home_config cfg;
        home_result ref, res;
        int runs = 0;
        home_default_config(&cfg, DW, DH);
        cfg.hough_method = methods[m];
        cfg.simd = HOME_SIMD_NONE;
        if (register_layout(&cfg, 0x00, DW, 0, &ref, &ref_a, &ref_b) != 0) { CHECK(0); continue; }
        CHECK(ref.ok);
        for (b = 0; b < sizeof backends / sizeof backends[0]; b++) {
            cfg.simd = backends[b];
            if (home_validate_config(&cfg) != HOME_OK) continue; /* backend not compiled in */
            /* dirty arena, padded rows, odd address */
            CHECK_EQ_INT(register_layout(&cfg, 0xff, DW + PAD, 1, &res, &fa, &fb), 0);
            CHECK(memcmp(ref.H, res.H, sizeof ref.H) == 0);
            CHECK(ref.ok == res.ok && ref.matches == res.matches && ref.inliers == res.inliers);
            CHECK(same_features(&ref_a, &fa) && same_features(&ref_b, &fb));
            runs++;
        }
        printf("     %s Hough: identical on %d backend(s) with a dirty arena, padded rows, odd address\n",
               methods[m] == HOME_HOUGH_FAST ? "fast" : "exact", runs);
    }
}

/* ---- painted stack ---------------------------------------------------------------------- */

#define PAINT 0xa5
static union { unsigned char bytes[256u << 10]; long double align; } thread_stack;
static void (*stack_job)(void);

static void *run_job(void *unused)
{
    (void)unused;
    stack_job();
    return NULL;
}

/* Bytes of thread_stack the job touched (stacks grow down on every supported target). */
static long painted_depth(void (*job)(void))
{
    pthread_attr_t attr;
    pthread_t thread;
    size_t i;
    memset(thread_stack.bytes, PAINT, sizeof thread_stack.bytes);
    stack_job = job;
    if (pthread_attr_init(&attr) ||
        pthread_attr_setstack(&attr, thread_stack.bytes, sizeof thread_stack.bytes) ||
        pthread_create(&thread, &attr, run_job, NULL) || pthread_join(thread, NULL))
        return -1;
    pthread_attr_destroy(&attr);
    for (i = 0; i < sizeof thread_stack.bytes && thread_stack.bytes[i] == PAINT; i++) continue;
    return (long)(sizeof thread_stack.bytes - i);
}

static home_config s_cfg;
static home_context *s_ctx;
static home_result s_res;
static home_features s_fa, s_fb;
static uint8_t s_hough[1u << 18];
static int s_hw, s_hh;
static float s_col, s_row;

static void job_nothing(void) {}
static void job_default_config(void) { home_default_config(&s_cfg, DW, DH); }
static void job_validate_config(void) { home_validate_config(&s_cfg); }
static void job_arena_size(void) { home_arena_size(&s_cfg); }
static void job_init(void) { home_init(&s_ctx, &s_cfg, ALIGNED_ARENA(proof_arena.bytes), ALIGNED_BYTES(proof_arena.bytes), NULL); }
static void job_extract(void) { home_extract(s_ctx, da, DW, &s_fa); }
static void job_match(void) { home_match(s_ctx, &s_fa, &s_fb, &s_res); }
static void job_register(void) { home_register(s_ctx, da, DW, db, DW, &s_res); }
static void job_last_features(void) { home_last_features(s_ctx, 1); }
static void job_hough_size(void) { home_hough_size(s_ctx, &s_hw, &s_hh); }
static void job_render_hough(void) { home_render_hough(s_ctx, da, DW, s_hough, s_hw); }
static void job_keypoint_to_hough(void) { home_keypoint_to_hough(s_ctx, &s_fa.kp[0], &s_col, &s_row); }
static void job_strerror(void) { home_strerror(HOME_E_CONFIG); }
static void job_names(void)
{
    home_model_name(HOME_MODEL_SIMILARITY);
    home_failure_name(HOME_FAIL_UNCERTAIN);
    home_refine_status_name(HOME_REFINE_ACCEPTED);
}
static void job_simd_backend(void) { home_simd_backend(s_ctx); }
static void job_refine(void) { home_refine(s_ctx, da, DW, db, DW, s_res.H, &s_res); }

/* the stabiliser, on the same pair as two grey frames */
static union { unsigned char bytes[8u << 20]; double align; } stab_arena;
static home_stab *s_stab;
static home_stab_output s_out;
static uint8_t s_warped[DW * DH];
static home_stab_image frame_image(uint8_t *pixels)
{
    home_stab_image im;
    memset(&im, 0, sizeof im);
    im.format = HOME_STAB_GREY;
    im.width = DW;
    im.height = DH;
    im.plane[0] = pixels;
    im.stride[0] = DW;
    return im;
}
static void job_stab_init(void)
{
    home_stab_config c;
    home_stab_default_config(&c, DW, DH);
    c.lookahead = 2;
    if (home_stab_init(&s_stab, &c, ALIGNED_ARENA(stab_arena.bytes), ALIGNED_BYTES(stab_arena.bytes), NULL) != HOME_OK) s_stab = NULL;
}
static home_stab_image s_frame_a, s_frame_b; /* static: the job's own frame stays small */
static void job_stab_push(void)
{
    home_stab_push(s_stab, &s_frame_a, &s_out);
    home_stab_push(s_stab, &s_frame_b, &s_out);
}
static void job_stab_push_cut(void)
{
    home_stab_push(s_stab, &s_frame_a, &s_out);
    home_stab_cut(s_stab);
    home_stab_push(s_stab, &s_frame_b, &s_out);
}
static void job_stab_flush(void) { home_stab_flush(s_stab, &s_out); }
static void job_stab_warp(void)
{
    static const double shift[9] = {1, 0, 1.5, 0, 1, -0.5, 0, 0, 1};
    home_stab_image a = frame_image(da), out = frame_image(s_warped);
    home_stab_warp(shift, &a, &out);
}

static void job_stab_warp_rows(void)
{
    static const double shift[9] = {1, 0, 1.5, 0, 1, -0.5, 0, 0, 1};
    home_stab_image a = frame_image(da), out = frame_image(s_warped);
    home_stab_warp_rows(shift, &a, &out, 2, 6);
}

void test_stack_painted(void)
{
    static const struct { const char *name; void (*job)(void); } jobs[] = {
        {"home_default_config", job_default_config}, {"home_validate_config", job_validate_config},
        {"home_arena_size", job_arena_size}, {"home_init", job_init},
        {"home_extract", job_extract}, {"home_match", job_match},
        {"home_register", job_register}, {"home_last_features", job_last_features},
        {"home_hough_size", job_hough_size}, {"home_render_hough", job_render_hough},
        {"home_keypoint_to_hough", job_keypoint_to_hough}, {"home_strerror", job_strerror},
        {"home_model_name, home_failure_name, home_refine_status_name", job_names},
        {"home_simd_backend", job_simd_backend}, {"home_refine", job_refine},
        {"home_stab_init", job_stab_init}, {"home_stab_push (2 frames)", job_stab_push},
        {"home_stab_push (a frame, a cut, a frame)", job_stab_push_cut},
        {"home_stab_flush", job_stab_flush}, {"home_stab_warp", job_stab_warp},
        {"home_stab_warp_rows", job_stab_warp_rows},
    };
    static const int backends[] = {HOME_SIMD_NONE, HOME_SIMD_SSE, HOME_SIMD_AVX2, HOME_SIMD_NEON};
    static const int methods[] = {HOME_HOUGH_FAST, HOME_HOUGH_EXACT};
    long worst[sizeof jobs / sizeof jobs[0]] = {0}, base = painted_depth(job_nothing), all = 0;
    size_t j, b, m;
    make_pair();
    s_frame_a = frame_image(da);
    s_frame_b = frame_image(db);
    CHECK(base > 0);
    for (m = 0; m < sizeof methods / sizeof methods[0]; m++)
        for (b = 0; b < sizeof backends / sizeof backends[0]; b++) {
            home_config probe;
            home_default_config(&probe, DW, DH);
            probe.simd = backends[b];
            probe.hough_method = methods[m];
            if (home_validate_config(&probe) != HOME_OK) continue;
            for (j = 0; j < sizeof jobs / sizeof jobs[0]; j++) {
                long used;
                if (jobs[j].job == job_init) s_cfg = probe; /* the config under test */
                used = painted_depth(jobs[j].job) - base;
                if (jobs[j].job == job_default_config) s_cfg = probe;
                if (jobs[j].job == job_extract) s_fb = s_fa; /* a match of a frame with itself */
                if (used > worst[j]) worst[j] = used;
            }
            CHECK(s_ctx != NULL && s_fa.n_pos + s_fa.n_neg > 0 && s_stab != NULL);
        }
    printf("     painted stack per public function, worst over backends and Hough methods (bytes):\n");
    for (j = 0; j < sizeof jobs / sizeof jobs[0]; j++) {
        printf("       %-26s %6ld\n", jobs[j].name, worst[j]);
        if (worst[j] > all) all = worst[j];
    }
#ifdef STACK_INSTRUMENTED
    printf("     (AddressSanitizer build: frames are inflated, the %d-byte bound is not checked)\n", STACK_LIMIT);
#else
    CHECK_LT(all, STACK_LIMIT + 1);
#endif
}
