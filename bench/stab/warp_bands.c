/* The warp split across threads with home_stab_warp_rows(): one 4:2:0 frame (default 1920x1080)
 * warped by a stabilisation-like similarity (0.8 crop zoom, a small shift and roll), whole on
 * one thread and in N equal bands on N threads (new threads each round, as a caller without a
 * pool would). Prints the median wall ms per frame of each and checks that the bands give the
 * whole warp's bytes.
 *   build/bin/home-warp-bands [WIDTH HEIGHT [THREADS [ROUNDS]]] */
#define _POSIX_C_SOURCE 200809L
#include "home_stab.h"
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_THREADS 16

typedef struct band {
    const double *m;
    const home_stab_image *src;
    home_stab_image *dst;
    int first_row, rows, status;
} band;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static void *warp_band(void *arg)
{
    band *b = arg;
    b->status = home_stab_warp_rows(b->m, b->src, b->dst, b->first_row, b->rows);
    return NULL;
}

static void i420(uint8_t *buf, int w, int h, home_stab_image *im)
{
    memset(im, 0, sizeof *im);
    im->format = HOME_STAB_I420;
    im->width = w;
    im->height = h;
    im->plane[0] = buf;
    im->plane[1] = buf + (size_t)w * h;
    im->plane[2] = buf + (size_t)w * h * 5 / 4;
    im->stride[0] = w;
    im->stride[1] = im->stride[2] = w / 2;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
    const int w = argc > 2 ? atoi(argv[1]) : 1920, h = argc > 2 ? atoi(argv[2]) : 1080;
    const int threads = argc > 3 ? atoi(argv[3]) : 2, rounds = argc > 4 ? atoi(argv[4]) : 50;
    const home_stab_sim sim = {3.7, -2.2, 0.004, -0.223};   /* a 0.8 crop zoom, as with a 10 % margin */
    double m[9], *t_whole, *t_bands;
    uint8_t *src, *whole, *split;
    home_stab_image a, b, c;
    size_t bytes, k;
    int r, t, bad = 0;
    if (w < 64 || h < 64 || w % 2 || h % 2 || threads < 1 || threads > MAX_THREADS || rounds < 1) {
        fprintf(stderr, "usage: home-warp-bands [WIDTH HEIGHT [THREADS 1..%d [ROUNDS]]] (even sizes >= 64)\n", MAX_THREADS);
        return 2;
    }
    bytes = (size_t)w * h * 3 / 2;
    src = malloc(bytes); whole = malloc(bytes); split = malloc(bytes);
    t_whole = malloc(sizeof *t_whole * (size_t)rounds); t_bands = malloc(sizeof *t_bands * (size_t)rounds);
    if (!src || !whole || !split || !t_whole || !t_bands) { fprintf(stderr, "home-warp-bands: out of memory\n"); return 2; }
    for (k = 0; k < bytes; k++) src[k] = (uint8_t)((k * 2654435761u) >> 24 ^ (k / (size_t)w) * 3);
    i420(src, w, h, &a); i420(whole, w, h, &b); i420(split, w, h, &c);
    home_stab_sim_to_matrix(&sim, w, h, m);
    for (r = 0; r < rounds; r++) {
        pthread_t tid[MAX_THREADS];
        band bands[MAX_THREADS];
        double t0 = now_ms();
        if (home_stab_warp(m, &a, &b) != HOME_OK) { fprintf(stderr, "home-warp-bands: warp refused\n"); return 1; }
        t_whole[r] = now_ms() - t0;
        t0 = now_ms();
        for (t = 0; t < threads; t++) {
            /* even band edges (4:2:0) */
            const int first = (int)((long)h * t / threads) & ~1, end = t + 1 == threads ? h : (int)((long)h * (t + 1) / threads) & ~1;
            bands[t] = (band){m, &a, &c, first, end - first, -1};
            if (t + 1 < threads) pthread_create(&tid[t], NULL, warp_band, &bands[t]);
        }
        warp_band(&bands[threads - 1]);   /* the calling thread takes the last band */
        for (t = 0; t + 1 < threads; t++) pthread_join(tid[t], NULL);
        t_bands[r] = now_ms() - t0;
        for (t = 0; t < threads; t++) bad += bands[t].status != HOME_OK;
    }
    bad += memcmp(whole, split, bytes) != 0;
    qsort(t_whole, (size_t)rounds, sizeof *t_whole, cmp_double);
    qsort(t_bands, (size_t)rounds, sizeof *t_bands, cmp_double);
    printf("%dx%d I420, %d rounds (median wall ms per frame): whole %.3f, %d bands on %d threads %.3f (%.2fx); bytes %s\n",
           w, h, rounds, t_whole[rounds / 2], threads, threads, t_bands[rounds / 2],
           t_whole[rounds / 2] / t_bands[rounds / 2], bad ? "DIFFER" : "identical");
    free(src); free(whole); free(split); free(t_whole); free(t_bands);
    return bad ? 1 : 0;
}
