/* Shaky camera paths with ground truth, for the stabiliser's tests, demo and benchmark. */
#ifndef HOME_STAB_CLIP_H
#define HOME_STAB_CLIP_H
#include <stdint.h>

typedef struct stab_clip_motion {
    int frames;
    double shake_px;          /* RMS of the translation jitter per axis, px */
    double shake_deg;         /* RMS of the rotation jitter, degrees */
    double pan_px;            /* intended horizontal pan over the whole clip, px */
    uint64_t seed;
} stab_clip_motion;

/* Camera of frame t for a width x height frame: g maps reference coordinates (the unshaken
 * first frame) to frame t's pixels (affine, 3x3 row-major); intent is the same without jitter.
 * Jitter: three random sinusoids of 0.08..0.3 cycles/frame plus white noise, deterministic in
 * the seed. */
void stab_clip_camera(const stab_clip_motion *m, int t, int width, int height, double *g,
                      double *intent);

/* Jitter of a path of similarities (per frame: tx, ty, angle in px at the half diagonal): RMS
 * of what a centred Gaussian (sigma frames) leaves, over frames [skip, n - skip). */
double stab_clip_jitter(const double (*path)[3], int n, double sigma, int skip);

/* Path components (tx, ty, angle * half diagonal) of an affine camera matrix. */
void stab_clip_components(const double *g, int width, int height, double *out3);
#endif
