#include "synth.h"
#include <math.h>

void synth_seed(synth_rng *rng, uint64_t seed) { rng->state = seed * 2862933555777941757ull + 3037000493ull; }

double synth_uniform(synth_rng *rng)
{
    /* splitmix64: simple, well mixed, identical on every platform */
    uint64_t z = (rng->state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

double synth_gauss(synth_rng *rng)
{
    double u = synth_uniform(rng), v = synth_uniform(rng);
    if (u < 1e-300) u = 1e-300;
    return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}

void synth_apply(const double *h, double x, double y, double *ox, double *oy)
{
    double w = h[6] * x + h[7] * y + h[8];
    *ox = (h[0] * x + h[1] * y + h[2]) / w;
    *oy = (h[3] * x + h[4] * y + h[5]) / w;
}

int synth_invert(const double *m, double *inv)
{
    double a = m[4] * m[8] - m[5] * m[7], b = -(m[3] * m[8] - m[5] * m[6]), c = m[3] * m[7] - m[4] * m[6];
    double det = m[0] * a + m[1] * b + m[2] * c;
    if (fabs(det) < 1e-300) return -1;
    inv[0] = a / det; inv[1] = -(m[1] * m[8] - m[2] * m[7]) / det; inv[2] = (m[1] * m[5] - m[2] * m[4]) / det;
    inv[3] = b / det; inv[4] = (m[0] * m[8] - m[2] * m[6]) / det; inv[5] = -(m[0] * m[5] - m[2] * m[3]) / det;
    inv[6] = c / det; inv[7] = -(m[0] * m[7] - m[1] * m[6]) / det; inv[8] = (m[0] * m[4] - m[1] * m[3]) / det;
    return 0;
}

int synth_homography_from_points(const double *src, const double *dst, double *h)
{
    double a[8][9];
    int i, j, k;
    for (i = 0; i < 4; i++) {
        double x = src[2 * i], y = src[2 * i + 1], u = dst[2 * i], v = dst[2 * i + 1];
        double r0[9] = {x, y, 1, 0, 0, 0, -u * x, -u * y, u};
        double r1[9] = {0, 0, 0, x, y, 1, -v * x, -v * y, v};
        for (j = 0; j < 9; j++) { a[2 * i][j] = r0[j]; a[2 * i + 1][j] = r1[j]; }
    }
    for (k = 0; k < 8; k++) {           /* Gauss-Jordan with partial pivoting */
        int piv = k;
        for (i = k + 1; i < 8; i++) if (fabs(a[i][k]) > fabs(a[piv][k])) piv = i;
        if (fabs(a[piv][k]) < 1e-12) return -1;
        for (j = 0; j < 9; j++) { double t = a[k][j]; a[k][j] = a[piv][j]; a[piv][j] = t; }
        for (i = 0; i < 8; i++) {
            double f;
            if (i == k) continue;
            f = a[i][k] / a[k][k];
            for (j = k; j < 9; j++) a[i][j] -= f * a[k][j];
        }
    }
    for (i = 0; i < 8; i++) h[i] = a[i][8] / a[i][i];
    h[8] = 1.0;
    return 0;
}

void synth_corner_homography(synth_rng *rng, int width, int height, double p, double *h)
{
    double src[8] = {0, 0, width - 1, 0, width - 1, height - 1, 0, height - 1}, dst[8];
    int i;
    for (i = 0; i < 8; i++) dst[i] = src[i] + p * (2.0 * synth_uniform(rng) - 1.0);
    synth_homography_from_points(src, dst, h);
}

double synth_corner_error(const double *he, const double *ht, int width, int height)
{
    double cx[4] = {0, width - 1, 0, width - 1}, cy[4] = {0, 0, height - 1, height - 1}, sum = 0;
    int i;
    for (i = 0; i < 4; i++) {
        double ax, ay, bx, by;
        synth_apply(he, cx[i], cy[i], &ax, &ay);
        synth_apply(ht, cx[i], cy[i], &bx, &by);
        sum += sqrt((ax - bx) * (ax - bx) + (ay - by) * (ay - by));
    }
    return sum / 4;
}

/* ~1 px wide soft step */
static double step(double d)
{
    if (d > 8) return 1.0;
    if (d < -8) return 0.0;
    return 1.0 / (1.0 + exp(-d / 0.6));
}

/* Lattice value noise: a hashed random grey level per integer cell corner, smoothly
 * interpolated; two octaves give a faint, photograph-like texture. */
static double lattice(int64_t x, int64_t y, uint32_t variant)
{
    uint64_t z = (uint64_t)(x * 73856093) ^ (uint64_t)(y * 19349663) ^ ((uint64_t)variant << 32);
    z = (z ^ (z >> 33)) * 0xff51afd7ed558ccdull;
    z = (z ^ (z >> 33)) * 0xc4ceb9fe1a85ec53ull;
    z ^= z >> 33;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0;
}

static double value_noise(double x, double y, double cell, uint32_t variant)
{
    double fx = x / cell, fy = y / cell, x0 = floor(fx), y0 = floor(fy);
    double tx = fx - x0, ty = fy - y0;
    int64_t ix = (int64_t)x0, iy = (int64_t)y0;
    tx = tx * tx * (3 - 2 * tx);
    ty = ty * ty * (3 - 2 * ty);
    return (1 - ty) * ((1 - tx) * lattice(ix, iy, variant) + tx * lattice(ix + 1, iy, variant)) +
           ty * ((1 - tx) * lattice(ix, iy + 1, variant) + tx * lattice(ix + 1, iy + 1, variant));
}

/* Scene in scene coordinates (nominally 640x360 but defined everywhere): smooth shading,
 * long straight edges, a facade-like grid of rectangles, and faint texture. The weak-texture
 * kind has the same kinds of structure at a quarter of the contrast and fewer of them. */
static double scene(enum synth_kind kind, uint32_t variant, double x, double y)
{
    synth_rng rng;
    double v, gain = kind == SYNTH_STRUCTURED ? 1.0 : 0.3;
    int k, n_lines = kind == SYNTH_STRUCTURED ? 6 : 3, rows, cols, i, j;
    double gx0, gy0, gdx, gdy, ww, wh;
    if (kind == SYNTH_CONSTANT) return 128.0;
    synth_seed(&rng, 1000 + variant);
    v = 110 + 30 * sin(x / (80.0 + 30 * synth_uniform(&rng))) * cos(y / (60.0 + 30 * synth_uniform(&rng)));
    for (k = 0; k < n_lines; k++) {
        double a = 3.14159265358979 * synth_uniform(&rng);
        double r = 260 * (synth_uniform(&rng) - 0.5);
        double c = gain * (20 + 25 * synth_uniform(&rng)) * (synth_uniform(&rng) < 0.5 ? -1 : 1);
        v += c * step((x - 320) * cos(a) + (y - 180) * sin(a) - r);
    }
    /* a grid of "windows" on a slightly rotated facade */
    rows = 2 + (int)(3 * synth_uniform(&rng));
    cols = 3 + (int)(4 * synth_uniform(&rng));
    gx0 = 40 + 120 * synth_uniform(&rng);
    gy0 = 30 + 80 * synth_uniform(&rng);
    gdx = (560 - gx0) / cols;
    gdy = (330 - gy0) / rows;
    ww = gdx * (0.4 + 0.3 * synth_uniform(&rng));
    wh = gdy * (0.4 + 0.3 * synth_uniform(&rng));
    {
        double c = gain * (30 + 20 * synth_uniform(&rng)) * (synth_uniform(&rng) < 0.5 ? -1 : 1);
        double rot = 0.2 * (synth_uniform(&rng) - 0.5), cr = cos(rot), sr = sin(rot);
        double u = (x - 320) * cr + (y - 180) * sr + 320, w = -(x - 320) * sr + (y - 180) * cr + 180;
        i = (int)floor((u - gx0) / gdx);
        j = (int)floor((w - gy0) / gdy);
        if (i >= 0 && i < cols && j >= 0 && j < rows) {
            double x0 = gx0 + i * gdx, y0 = gy0 + j * gdy;
            v += c * step(u - x0) * step(x0 + ww - u) * step(w - y0) * step(y0 + wh - w);
        }
    }
    v += (kind == SYNTH_STRUCTURED ? 8 : 5) * value_noise(x, y, 5.0, variant) +
         (kind == SYNTH_STRUCTURED ? 10 : 6) * value_noise(x, y, 23.0, variant + 7);
    return v;
}

void synth_render(enum synth_kind kind, uint32_t variant, const double *h, double noise_sigma,
                  uint64_t noise_seed, uint8_t *out, int width, int height, ptrdiff_t stride)
{
    double inv[9];
    synth_rng rng;
    int x, y;
    synth_invert(h, inv);
    synth_seed(&rng, noise_seed);
    for (y = 0; y < height; y++)
        for (x = 0; x < width; x++) {
            double sx, sy, v;
            synth_apply(inv, x, y, &sx, &sy);
            v = scene(kind, variant, sx, sy) + (noise_sigma > 0 ? noise_sigma * synth_gauss(&rng) : 0.0);
            v = floor(v + 0.5);
            out[(ptrdiff_t)y * stride + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
        }
}
