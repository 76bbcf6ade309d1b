/* Per-frame cost of the photometric refinement in the video case (extract the new frame, match
 * it against the previous one), side by side with HOME alone in the same run, per SIMD backend.
 *   home-bench-refine [--frames N] [--kind structured|weak] [--width W --height H] [--levels N]
 * Frames: a procedural scene under a slow random homography walk (corners move <= 4 px a frame),
 * noise sigma 2.5. Times are this thread's CPU time (robust to other load on the machine), so
 * they are comparable between runs on a shared box. Prints median ms per frame of HOME (refinement off), of the refinement
 * stage (snapshot of the new frame + Gauss-Newton), the accept count and the mean corner error
 * of both against the true frame-to-frame homography. */
#define _POSIX_C_SOURCE 200809L
#include "home.h"
#include "synth.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double clock_ms(void *user)
{
    struct timespec ts;
    (void)user;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void mul3(const double *a, const double *b, double *o)
{
    int i, j;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) o[i * 3 + j] = a[i * 3] * b[j] + a[i * 3 + 1] * b[3 + j] + a[i * 3 + 2] * b[6 + j];
}

int main(int argc, char **argv)
{
    static const int simds[4] = {HOME_SIMD_NONE, HOME_SIMD_SSE, HOME_SIMD_AVX2, HOME_SIMD_NEON};
    static const char *names[4] = {"none", "sse", "avx2", "neon"};
    int frames = 30, width = 640, height = 360, levels = -1, i, f, s, k;
    enum synth_kind kind = SYNTH_STRUCTURED;
    uint8_t *img[2];
    double *pose, *home_ms, *ref_ms, *snap_ms;
    for (i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--frames")) frames = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--width")) width = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--height")) height = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--levels")) levels = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--kind")) kind = !strcmp(argv[i + 1], "weak") ? SYNTH_WEAK_TEXTURE : SYNTH_STRUCTURED;
        else { fprintf(stderr, "home-bench-refine: unknown option %s\n", argv[i]); return 2; }
    }
    if (frames < 2 || frames > 10000) { fprintf(stderr, "home-bench-refine: --frames 2..10000\n"); return 2; }
    img[0] = malloc((size_t)width * height);
    img[1] = malloc((size_t)width * height);
    pose = malloc(sizeof(double) * 9 * (size_t)frames);
    home_ms = malloc(sizeof(double) * (size_t)frames);
    ref_ms = malloc(sizeof(double) * (size_t)frames);
    snap_ms = malloc(sizeof(double) * (size_t)frames);
    if (!img[0] || !img[1] || !pose || !home_ms || !ref_ms || !snap_ms) return 2;
    {   /* camera path: each frame's pose composes a small random homography */
        synth_rng rng;
        synth_seed(&rng, 2024);
        memcpy(pose, (double[9]){1, 0, 0, 0, 1, 0, 0, 0, 1}, sizeof(double) * 9);
        for (f = 1; f < frames; f++) {
            double step[9];
            synth_corner_homography(&rng, width, height, 4.0, step);
            mul3(step, pose + 9 * (f - 1), pose + 9 * f);
        }
    }
    printf("frames %d, %dx%d %s scene, corner motion <= 4 px a frame, noise 2.5\n", frames, width,
           height, kind == SYNTH_STRUCTURED ? "structured" : "weak-texture");
    for (s = 0; s < 4; s++) {
        home_config probe;
        home_default_config(&probe, width, height);
        probe.simd = simds[s];
        if (home_validate_config(&probe) != HOME_OK) continue; /* backend not compiled in */
        for (k = 0; k < 2; k++) {   /* k = 0: HOME alone; k = 1: with refinement */
            home_config cfg;
            home_context *ctx;
            static home_features feat[2];
            void *mem;
            size_t bytes;
            int accepted = 0, iterations = 0;
            double err = 0.0;
            home_default_config(&cfg, width, height);
            cfg.simd = simds[s];
            cfg.clock = clock_ms;
            if (levels >= 0) cfg.refine_levels = levels;
            if (!k) cfg.refine_levels = 0;
            bytes = home_arena_size(&cfg);
            mem = malloc(bytes + HOME_ARENA_ALIGN);
            if (!mem || home_init(&ctx, &cfg, (void *)(((uintptr_t)mem + 15) & ~(uintptr_t)15), bytes, NULL) != HOME_OK)
                return 2;
            for (f = 0; f < frames; f++) {
                home_result res;
                double t0, h_rel[9], inv[9];
                synth_render(kind, 7, pose + 9 * f, 2.5, 100 + (uint64_t)f, img[f & 1], width, height, width);
                t0 = clock_ms(NULL);
                home_extract(ctx, img[f & 1], width, &feat[f & 1]);
                if (!f) continue;
                home_match(ctx, &feat[(f - 1) & 1], &feat[f & 1], &res);
                home_ms[f - 1] = clock_ms(NULL) - t0 - res.ms[HOME_STAGE_REFINE];
                ref_ms[f - 1] = res.ms[HOME_STAGE_REFINE];
                snap_ms[f - 1] = feat[f & 1].ms_refine;
                accepted += res.refined;
                iterations += res.refine_iterations;
                synth_invert(pose + 9 * (f - 1), inv);
                mul3(pose + 9 * f, inv, h_rel);
                err += synth_corner_error(res.H, h_rel, width, height);
            }
            qsort(home_ms, (size_t)frames - 1, sizeof(double), cmp_double);
            qsort(ref_ms, (size_t)frames - 1, sizeof(double), cmp_double);
            qsort(snap_ms, (size_t)frames - 1, sizeof(double), cmp_double);
            if (!k)
                printf("%-5s HOME alone: %7.3f ms/frame, error %.4f px\n", names[s],
                       home_ms[(frames - 1) / 2], err / (frames - 1));
            else
                printf("%-5s HOME + refinement: HOME %7.3f + refine %.3f ms/frame (snapshot %.3f, "
                       "solve %.3f), %.1f iterations, accepted %d/%d, error %.4f px\n", names[s],
                       home_ms[(frames - 1) / 2], ref_ms[(frames - 1) / 2], snap_ms[(frames - 1) / 2],
                       ref_ms[(frames - 1) / 2] - snap_ms[(frames - 1) / 2],
                       (double)iterations / (frames - 1), accepted, frames - 1,
                       err / (frames - 1));
            free(mem);
        }
    }
    free(img[0]); free(img[1]); free(pose); free(home_ms); free(ref_ms); free(snap_ms);
    return 0;
}
