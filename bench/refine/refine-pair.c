/* home-refine-pair: refine a given homography between two PGM images with libhome's photometric
 * refinement (home_refine), for evaluating "method X + refinement" (e.g. ORB + refinement).
 *   home-refine-pair [--levels N] [--iterations N] [--trust PX] [--repeat N] A.pgm B.pgm h0 ... h8
 * prints {"refined":true|false,"status":N,"H":[...],"error":[e0,e1],"zncc":z,"iterations":n,"ms":t}
 * (ms: median of --repeat runs, snapshots of both frames included). Exit 2 on bad input. */
#define _POSIX_C_SOURCE 200809L
#include "home.h"
#include "pgm.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double clock_ms(void *user)
{
    struct timespec ts;
    (void)user;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static const uint8_t *load(const char *path, uint8_t **buf, int *w, int *h)
{
    char err[128];
    size_t size = 0;
    const uint8_t *px;
    *buf = pgm_read_file(path, &size, err, sizeof err);
    if (!*buf || pgm_parse(*buf, size, HOME_MAX_SIDE, w, h, &px, err, sizeof err) != 0) {
        fprintf(stderr, "home-refine-pair: %s: %s\n", path, err);
        return NULL;
    }
    return px;
}

int main(int argc, char **argv)
{
    home_config cfg;
    home_context *ctx;
    home_result res;
    const char *paths[2];
    double h0[9], *ms;
    int i = 1, k, repeat = 1, levels = -1, iters = -1, wa, ha, wb, hb, n_paths = 0;
    float trust = -1;
    uint8_t *ba = NULL, *bb = NULL;
    const uint8_t *pa, *pb;
    void *mem;
    size_t bytes;
    for (; i < argc && !strncmp(argv[i], "--", 2); i += 2) {
        if (i + 1 >= argc) { fprintf(stderr, "home-refine-pair: %s needs a value\n", argv[i]); return 2; }
        if (!strcmp(argv[i], "--levels")) levels = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--iterations")) iters = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--trust")) trust = (float)atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--repeat")) repeat = atoi(argv[i + 1]);
        else { fprintf(stderr, "home-refine-pair: unknown option %s\n", argv[i]); return 2; }
    }
    if (argc - i != 11 || repeat < 1) {
        fprintf(stderr, "usage: home-refine-pair [--levels N] [--iterations N] [--trust PX] "
                        "[--repeat N] A.pgm B.pgm h0 ... h8\n");
        return 2;
    }
    paths[n_paths++] = argv[i++];
    paths[n_paths++] = argv[i++];
    for (k = 0; k < 9; k++) h0[k] = atof(argv[i + k]);
    if (!(pa = load(paths[0], &ba, &wa, &ha)) || !(pb = load(paths[1], &bb, &wb, &hb))) return 2;
    if (wa != wb || ha != hb) { fprintf(stderr, "home-refine-pair: sizes differ\n"); return 2; }
    home_default_config(&cfg, wa, ha);
    if (levels >= 0) cfg.refine_levels = levels;
    if (iters >= 0) cfg.refine_iterations = iters;
    if (trust >= 0) cfg.refine_trust_px = trust;
    cfg.clock = clock_ms;
    bytes = home_arena_size(&cfg);
    if (!bytes) { fprintf(stderr, "home-refine-pair: bad options\n"); return 2; }
    mem = malloc(bytes + HOME_ARENA_ALIGN);
    ms = (double *)malloc(sizeof(double) * (size_t)repeat);
    if (!mem || !ms) return 2;
    if (home_init(&ctx, &cfg, (void *)(((uintptr_t)mem + HOME_ARENA_ALIGN - 1) & ~(uintptr_t)(HOME_ARENA_ALIGN - 1)),
                  bytes, NULL) != HOME_OK)
        return 2;
    for (k = 0; k < repeat; k++) {
        if (home_refine(ctx, pa, wa, pb, wb, h0, &res) != HOME_OK) {
            fprintf(stderr, "home-refine-pair: bad input\n");
            return 2;
        }
        ms[k] = res.ms[HOME_STAGE_REFINE];
    }
    qsort(ms, (size_t)repeat, sizeof *ms, cmp_double);
    printf("{\"refined\":%s,\"status\":%d,\"H\":[", res.refined ? "true" : "false", res.refine_status);
    for (k = 0; k < 9; k++) printf("%s%.10g", k ? "," : "", res.H[k]);
    printf("],\"error\":[%.4f,%.4f],\"zncc\":%.4f,\"iterations\":%d,\"ms\":%.3f}\n",
           res.refine_error[0], res.refine_error[1], res.refine_zncc, res.refine_iterations,
           ms[repeat / 2]);
    free(ms); free(mem); free(ba); free(bb);
    return 0;
}
