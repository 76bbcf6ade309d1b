/* home-make-pair: write a procedurally generated image pair A.pgm, B.pgm related by a known
 * homography (each corner moved by up to p px) and print {"H":[...]} (A -> B) on stdout. */
#include "pgm.h"
#include "synth.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    int width = 640, height = 360, i, n_paths = 0;
    double p = 20, noise = 2.5, h[9], ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    unsigned long seed = 1;
    enum synth_kind kind = SYNTH_STRUCTURED;
    const char *paths[2] = {NULL, NULL};
    uint8_t *a, *b;
    synth_rng rng;
    for (i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : "";
        if (!strcmp(argv[i], "--p")) p = atof(v), i++;
        else if (!strcmp(argv[i], "--seed")) seed = strtoul(v, NULL, 10), i++;
        else if (!strcmp(argv[i], "--noise")) noise = atof(v), i++;
        else if (!strcmp(argv[i], "--width")) width = atoi(v), i++;
        else if (!strcmp(argv[i], "--height")) height = atoi(v), i++;
        else if (!strcmp(argv[i], "--kind")) {
            kind = !strcmp(v, "weak") ? SYNTH_WEAK_TEXTURE : !strcmp(v, "constant") ? SYNTH_CONSTANT : SYNTH_STRUCTURED;
            i++;
        } else if (n_paths < 2) paths[n_paths++] = argv[i];
    }
    if (n_paths != 2 || width < 8 || height < 8 || width > 8192 || height > 8192) {
        fprintf(stderr, "usage: home-make-pair [--kind structured|weak|constant] [--p PX] [--seed N]\n"
                        "       [--noise SIGMA] [--width W] [--height H] A.pgm B.pgm\n");
        return 2;
    }
    a = (uint8_t *)malloc((size_t)width * height);
    b = (uint8_t *)malloc((size_t)width * height);
    if (!a || !b) return 2;
    synth_seed(&rng, seed);
    synth_corner_homography(&rng, width, height, p, h);
    synth_render(kind, (uint32_t)seed, ident, noise, seed * 2 + 1, a, width, height, width);
    synth_render(kind, (uint32_t)seed, h, noise, seed * 2 + 2, b, width, height, width);
    if (pgm_write(paths[0], a, width, height, width) || pgm_write(paths[1], b, width, height, width)) {
        fprintf(stderr, "home-make-pair: cannot write output\n");
        return 2;
    }
    printf("{\"H\":[");
    for (i = 0; i < 9; i++) printf("%s%.12g", i ? "," : "", h[i]);
    printf("],\"width\":%d,\"height\":%d}\n", width, height);
    free(a);
    free(b);
    return 0;
}
