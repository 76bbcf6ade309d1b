#include "stab_clip.h"
#include "synth.h"
#include <math.h>

#define CLIP_PI 3.14159265358979323846

/* One jitter channel: three sinusoids and white noise, RMS ~1. */
static double jitter(uint64_t seed, int channel, int t)
{
    synth_rng rng;
    double v = 0.0, noise;
    int k;
    synth_seed(&rng, seed * 16 + (uint64_t)channel);
    for (k = 0; k < 3; k++) {
        double freq = 0.08 + 0.22 * synth_uniform(&rng), phase = 2 * CLIP_PI * synth_uniform(&rng);
        v += sin(2 * CLIP_PI * freq * t + phase);
    }
    synth_seed(&rng, seed * 7919 + (uint64_t)channel * 104729 + (uint64_t)t);
    noise = synth_gauss(&rng);
    return (v + 0.5 * noise) / sqrt(1.5 + 0.25);
}

static void similarity(double tx, double ty, double angle, int width, int height, double *g)
{
    double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1), c = cos(angle), s = sin(angle);
    g[0] = c; g[1] = -s; g[2] = cx + tx - c * cx + s * cy;
    g[3] = s; g[4] = c;  g[5] = cy + ty - s * cx - c * cy;
    g[6] = 0; g[7] = 0;  g[8] = 1;
}

void stab_clip_camera(const stab_clip_motion *m, int t, int width, int height, double *g,
                      double *intent)
{
    double u = m->frames > 1 ? (double)t / (m->frames - 1) : 0.0;
    /* intended: a pan plus a slow vertical drift and tilt */
    double ix = -m->pan_px * u, iy = 0.02 * height * sin(CLIP_PI * u), ia = 0.01 * sin(2 * CLIP_PI * u);
    double rad = m->shake_deg * CLIP_PI / 180.0;
    similarity(ix, iy, ia, width, height, intent);
    similarity(ix + m->shake_px * jitter(m->seed, 0, t), iy + m->shake_px * jitter(m->seed, 1, t),
               ia + rad * jitter(m->seed, 2, t), width, height, g);
}

void stab_clip_components(const double *g, int width, int height, double *out3)
{
    double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
    double half_diag = 0.5 * sqrt((double)width * width + (double)height * height);
    out3[0] = g[0] * cx + g[1] * cy + g[2] - cx;
    out3[1] = g[3] * cx + g[4] * cy + g[5] - cy;
    out3[2] = atan2(g[3], g[0]) * half_diag;
}

double stab_clip_jitter(const double (*path)[3], int n, double sigma, int skip)
{
    double sum = 0.0;
    int t, k, c, count = 0, radius = (int)ceil(3 * sigma);
    for (t = skip; t < n - skip; t++)
        for (c = 0; c < 3; c++) {
            double acc = 0.0, wsum = 0.0;
            for (k = -radius; k <= radius; k++) {
                int i = t + k < 0 ? 0 : t + k >= n ? n - 1 : t + k;
                double w = exp(-0.5 * k * k / (sigma * sigma));
                acc += w * path[i][c];
                wsum += w;
            }
            sum += (path[t][c] - acc / wsum) * (path[t][c] - acc / wsum);
            count++;
        }
    return count ? sqrt(sum / count) : 0.0;
}
