/* A bare-metal image that uses the library (make baremetal): linked with -nostartfiles against
 * newlib's libc and libm but none of its system-call stubs (no nosys.specs, no rdimon), so any
 * OS service the library needs (files, clock, heap via sbrk, exit) is an undefined reference and
 * fails the link. Frames live in static buffers; the entry point is fw_main. Not run. */
#include "home.h"
#include "home_stab.h"

#define FW_W 320
#define FW_H 240

static unsigned char arena[1u << 20] __attribute__((aligned(HOME_ARENA_ALIGN)));
static unsigned char stab_arena[2u << 20] __attribute__((aligned(HOME_ARENA_ALIGN)));
static uint8_t frame_a[FW_W * FW_H], frame_b[FW_W * FW_H], out_y[FW_W * FW_H];
static home_features fa, fb;

int fw_main(void);
int fw_main(void)
{
    home_config cfg;
    home_context *ctx;
    home_result res;
    home_stab_config scfg;
    home_stab *st;
    home_stab_output out;
    home_stab_image in = {HOME_STAB_GREY, FW_W, FW_H, {frame_b, 0, 0}, {FW_W, 0, 0}};
    home_stab_image dst = {HOME_STAB_GREY, FW_W, FW_H, {out_y, 0, 0}, {FW_W, 0, 0}};
    int i;
    for (i = 0; i < FW_W * FW_H; i++) {
        frame_a[i] = (uint8_t)((i % FW_W) * 3 + (i / FW_W));
        frame_b[i] = (uint8_t)((i % FW_W) * 3 + (i / FW_W) + 2);
    }
    home_video_config(&cfg, FW_W, FW_H);
    if (home_init(&ctx, &cfg, arena, sizeof arena, 0) != HOME_OK) return 1;
    home_extract(ctx, frame_a, FW_W, &fa);
    home_extract(ctx, frame_b, FW_W, &fb);
    home_match(ctx, &fa, &fb, &res);
    home_stab_default_config(&scfg, FW_W, FW_H);
    if (home_stab_init(&st, &scfg, stab_arena, sizeof stab_arena, 0) != HOME_OK) return 2;
    if (home_stab_push(st, &in, &out) == HOME_OK && out.ready) home_stab_warp(out.warp, &in, &dst);
    return res.ok + (int)home_strerror(0)[0] + out_y[0];
}
