/* Procedural test scenes with known homographies (deterministic, no files needed). Used by the
 * tests, the demo and the benchmarks. */
#ifndef HOME_SYNTH_H
#define HOME_SYNTH_H
#include <stddef.h>
#include <stdint.h>

enum synth_kind {
    SYNTH_STRUCTURED,   /* straight edges and rectangles on smooth shading */
    SYNTH_WEAK_TEXTURE, /* few faint edges, faint blotchy texture, shading */
    SYNTH_CONSTANT      /* flat grey */
};

typedef struct synth_rng { uint64_t state; } synth_rng;
void synth_seed(synth_rng *rng, uint64_t seed);
double synth_uniform(synth_rng *rng);            /* [0, 1) */
double synth_gauss(synth_rng *rng);              /* N(0, 1) */

/* Render scene `kind` (variant picks the layout) seen through homography h (scene -> image:
 * pixel x of the output shows scene point h^-1 x), plus Gaussian noise of sigma grey levels. */
void synth_render(enum synth_kind kind, uint32_t variant, const double *h, double noise_sigma,
                  uint64_t noise_seed, uint8_t *out, int width, int height, ptrdiff_t stride);

/* Homography moving each corner of a width x height image by a random offset in [-p, p]^2. */
void synth_corner_homography(synth_rng *rng, int width, int height, double p, double *h);

/* Solve the homography mapping src[i] -> dst[i] (4 points, xy pairs); returns 0 on success. */
int synth_homography_from_points(const double *src, const double *dst, double *h);

void synth_apply(const double *h, double x, double y, double *ox, double *oy);
int synth_invert(const double *h, double *inv);

/* Mean distance of the four image corners under h_est vs h_true. */
double synth_corner_error(const double *h_est, const double *h_true, int width, int height);
#endif
