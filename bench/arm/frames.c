/* The video registration's per-frame work, for counting ARM instructions under qemu
 * (bench/arm/count.sh): what `home-bench --frames video N` does, at any size and without
 * OpenCV, so that it cross-compiles.
 *   home-arm-frames [--width W] [--height H] [--frames N]
 * A structured scene and the same scene under a known homography (corners moved up to 12 px
 * at 640x360, scaled with the size); home_video_config; the first frame is extracted, then
 * each of N frames is extracted and matched against the previous one (alternating A and B),
 * as a video registers each new frame against cached features. home_arm_frame_mark() runs
 * after the set-up and after each frame: the plugin's working-set mode splits frames there. */
#include "home.h"
#include "synth.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* an out-of-line, visible call the plugin can find by its address (nm) */
void home_arm_frame_mark(int frame);
void __attribute__((noinline)) home_arm_frame_mark(int frame)
{
    __asm__ volatile("" : : "r"(frame) : "memory");
}

static home_features fa, fb;

int main(int argc, char **argv)
{
    int w = 640, h = 360, n = 3, i, r, c, k, bad = 0;
    double hw[9], hb[9], s, scale[9];
    synth_rng rng;
    uint8_t *a, *b;
    unsigned char *mem;
    home_config cfg;
    home_context *ctx;
    home_result res;
    size_t bytes;
    for (i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--width")) w = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--height")) h = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--frames")) n = atoi(argv[i + 1]);
        else { fprintf(stderr, "home-arm-frames: unknown option %s\n", argv[i]); return 2; }
    }
    /* the scene is laid out for 640x360: scale it to the frame, then (for B) the motion */
    s = w / 640.0;
    memset(scale, 0, sizeof scale);
    scale[0] = scale[4] = s;
    scale[8] = 1;
    synth_seed(&rng, 99);
    synth_corner_homography(&rng, w, h, 12 * s, hw);
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++)
            for (hb[r * 3 + c] = 0, k = 0; k < 3; k++) hb[r * 3 + c] += hw[r * 3 + k] * scale[k * 3 + c];
    a = malloc((size_t)w * h);
    b = malloc((size_t)w * h);
    home_video_config(&cfg, w, h);
    bytes = home_arena_size(&cfg);
    mem = malloc(bytes + HOME_ARENA_ALIGN);
    if (!a || !b || !mem || n < 0) return 2;
    synth_render(SYNTH_STRUCTURED, 7, scale, 2.5, 1, a, w, h, w);
    synth_render(SYNTH_STRUCTURED, 7, hb, 2.5, 2, b, w, h, w);
    if (home_init(&ctx, &cfg,
                  (void *)(((uintptr_t)mem + HOME_ARENA_ALIGN - 1) & ~(uintptr_t)(HOME_ARENA_ALIGN - 1)),
                  bytes, NULL) != HOME_OK) {
        fprintf(stderr, "home-arm-frames: home_init failed at %dx%d\n", w, h);
        return 2;
    }
    home_extract(ctx, a, w, &fa);
    home_arm_frame_mark(0);
    for (i = 0; i < n; i++) {
        home_features *prev = i % 2 ? &fb : &fa, *cur = i % 2 ? &fa : &fb;
        home_extract(ctx, i % 2 ? a : b, w, cur);
        home_match(ctx, prev, cur, &res);
        if (!res.ok || res.refine_status != HOME_REFINE_ACCEPTED) bad++;
        home_arm_frame_mark(i + 1);
    }
    printf("%dx%d frames %d arena %zu not-refined %d\n", w, h, n, bytes, bad);
    return 0;
}
