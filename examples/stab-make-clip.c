/* home-stab-clip: render a shaky Y4M clip with known camera motion, from a procedural scene or
 * a photograph (binary PGM larger than the frame; the frame is its central crop), and write the
 * ground truth per frame as CSV. */
#include "pgm.h"
#include "stab_clip.h"
#include "synth.h"
#include "y4m.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void usage(FILE *f)
{
    fprintf(f, "usage: home-stab-clip [--scene structured|weak|FILE.pgm] [--frames N] [--width W]\n"
               "       [--height H] [--shake PX] [--rot DEG] [--pan PX] [--decay A] [--noise SIGMA]\n"
               "       [--seed N] OUT.y4m [TRUTH.csv]\n"
               "  truth CSV: frame, g00..g12 (reference -> frame t, affine), the same without jitter\n");
}

static int number(const char *s, double lo, double hi, double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (*end || end == s || !(v >= lo && v <= hi)) return -1;
    *out = v;
    return 0;
}

static uint8_t sample(const uint8_t *img, int w, int h, double x, double y)
{
    int xi, yi;
    double fx, fy, v;
    x = x < 0 ? 0 : x > w - 1 ? w - 1 : x;
    y = y < 0 ? 0 : y > h - 1 ? h - 1 : y;
    xi = (int)x < w - 1 ? (int)x : w - 2;
    yi = (int)y < h - 1 ? (int)y : h - 2;
    fx = x - xi; fy = y - yi;
    img += (size_t)yi * w + xi;
    v = (img[0] * (1 - fx) + img[1] * fx) * (1 - fy) + (img[w] * (1 - fx) + img[w + 1] * fx) * fy;
    return (uint8_t)(v + 0.5);
}

int main(int argc, char **argv)
{
    stab_clip_motion m = {90, 4.0, 0.4, 60.0, 1};
    const char *scene = "structured", *out_path = NULL, *truth_path = NULL;
    double width = 640, height = 360, decay = 0.0, noise = 2.0, seed = 1;
    uint8_t *photo_file = NULL, *frame;
    const uint8_t *photo = NULL;
    int pw = 0, ph = 0, i, t, w, h;
    FILE *out, *truth = NULL;
    y4m_info info;
    synth_rng rng;

    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        double v;
        if (!strcmp(a, "--help")) { usage(stdout); return 0; }
        if (a[0] == '-' && a[1] == '-') {
            if (i + 1 >= argc) { fprintf(stderr, "home-stab-clip: %s needs a value\n", a); return 2; }
            if (!strcmp(a, "--scene")) { scene = argv[++i]; continue; }
            if (!strcmp(a, "--frames") && !number(argv[i + 1], 2, 100000, &v)) m.frames = (int)v;
            else if (!strcmp(a, "--width") && !number(argv[i + 1], 32, 4096, &v)) width = v;
            else if (!strcmp(a, "--height") && !number(argv[i + 1], 32, 4096, &v)) height = v;
            else if (!strcmp(a, "--shake") && !number(argv[i + 1], 0, 100, &v)) m.shake_px = v;
            else if (!strcmp(a, "--rot") && !number(argv[i + 1], 0, 10, &v)) m.shake_deg = v;
            else if (!strcmp(a, "--pan") && !number(argv[i + 1], -4096, 4096, &v)) m.pan_px = v;
            else if (!strcmp(a, "--decay") && !number(argv[i + 1], 0, 1, &v)) decay = v;
            else if (!strcmp(a, "--noise") && !number(argv[i + 1], 0, 50, &v)) noise = v;
            else if (!strcmp(a, "--seed") && !number(argv[i + 1], 0, 1e9, &v)) seed = v;
            else { fprintf(stderr, "home-stab-clip: bad option or value: %s %s\n", a, argv[i + 1]); return 2; }
            i++;
        } else if (!out_path) out_path = a;
        else if (!truth_path) truth_path = a;
        else { usage(stderr); return 2; }
    }
    if (!out_path) { usage(stderr); return 2; }
    w = (int)width & ~1;
    h = (int)height & ~1;
    m.seed = (uint64_t)seed;
    if (strcmp(scene, "structured") && strcmp(scene, "weak")) {
        char err[256];
        size_t size;
        photo_file = pgm_read_file(scene, &size, err, sizeof err);
        if (!photo_file || pgm_parse(photo_file, size, 16384, &pw, &ph, &photo, err, sizeof err)) {
            fprintf(stderr, "home-stab-clip: %s: %s\n", scene, err);
            return 2;
        }
        if (pw < w || ph < h) {
            fprintf(stderr, "home-stab-clip: %s (%dx%d) is smaller than the frame\n", scene, pw, ph);
            return 2;
        }
    }
    out = strcmp(out_path, "-") ? fopen(out_path, "wb") : stdout;
    if (!out || (truth_path && !(truth = fopen(truth_path, "w")))) {
        fprintf(stderr, "home-stab-clip: cannot write %s\n", out ? truth_path : out_path);
        return 2;
    }
    memset(&info, 0, sizeof info);
    info.width = w; info.height = h; info.chroma = 420;
    snprintf(info.params, sizeof info.params, " F30:1 Ip A1:1");
    snprintf(info.colour_tag, sizeof info.colour_tag, "C420jpeg");
    frame = malloc(y4m_frame_bytes(&info));
    if (!frame) return 2;
    y4m_write_header(out, &info, w);
    if (truth) fprintf(truth, "frame,g00,g01,g02,g10,g11,g12,i00,i01,i02,i10,i11,i12\n");
    synth_seed(&rng, m.seed + 99);
    for (t = 0; t < m.frames; t++) {
        double g[9], intent[9], inv[9];
        int x, y;
        stab_clip_camera(&m, t, w, h, g, intent);
        if (photo) {
            double ox = 0.5 * (pw - w), oy = 0.5 * (ph - h);
            synth_invert(g, inv);
            for (y = 0; y < h; y++)
                for (x = 0; x < w; x++) {
                    double u, v;
                    synth_apply(inv, x, y, &u, &v);
                    frame[(size_t)y * w + x] = sample(photo, pw, ph, u + ox, v + oy);
                }
        } else {
            synth_render(strcmp(scene, "weak") ? SYNTH_STRUCTURED : SYNTH_WEAK_TEXTURE, 1, g, 0.0,
                         0, frame, w, h, w);
        }
        for (x = 0; x < w * h; x++) {
            double v = frame[x] + decay * (128.0 - frame[x]) + noise * synth_gauss(&rng);
            frame[x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : floor(v + 0.5));
        }
        memset(frame + (size_t)w * h, 128, (size_t)w * h / 2);
        if (y4m_write_frame(out, frame, y4m_frame_bytes(&info))) {
            fprintf(stderr, "home-stab-clip: write error\n");
            return 2;
        }
        if (truth)
            fprintf(truth, "%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", t,
                    g[0], g[1], g[2], g[3], g[4], g[5], intent[0], intent[1], intent[2],
                    intent[3], intent[4], intent[5]);
    }
    if (truth) fclose(truth);
    if (out != stdout) fclose(out); else fflush(out);
    free(frame);
    free(photo_file);
    return 0;
}
