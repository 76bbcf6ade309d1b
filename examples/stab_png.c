#include "stab_png.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PLOT_W 900
#define PANEL_H 220
#define PLOT_LEFT 70
#define PLOT_PAD 24

static uint32_t crc_update(uint32_t crc, const uint8_t *p, size_t n)
{
    size_t i;
    int k;
    crc = ~crc;
    for (i = 0; i < n; i++) {
        crc ^= p[i];
        for (k = 0; k < 8; k++) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

static void put32(uint8_t *p, uint32_t v) { p[0] = (uint8_t)(v >> 24); p[1] = (uint8_t)(v >> 16); p[2] = (uint8_t)(v >> 8); p[3] = (uint8_t)v; }

static int chunk(FILE *f, const char *type, const uint8_t *data, size_t n)
{
    uint8_t head[8], tail[4];
    uint32_t crc;
    put32(head, (uint32_t)n);
    memcpy(head + 4, type, 4);
    crc = crc_update(0, head + 4, 4);
    crc = crc_update(crc, data, n);
    put32(tail, crc);
    return fwrite(head, 1, 8, f) != 8 || (n && fwrite(data, 1, n, f) != n) || fwrite(tail, 1, 4, f) != 4;
}

int png_write_rgb(const char *path, const uint8_t *rgb, int width, int height)
{
    static const uint8_t signature[8] = {137, 80, 78, 71, 13, 10, 26, 10};
    const size_t row = (size_t)width * 3 + 1, raw = row * height;
    const size_t blocks = (raw + 65534) / 65535, zsize = 2 + raw + 5 * blocks + 4;
    uint8_t ihdr[13], *z = malloc(zsize), *filtered = malloc(raw), *q;
    uint32_t a = 1, b = 0;
    size_t i, left;
    FILE *f;
    int bad;
    if (!z || !filtered) { free(z); free(filtered); return -1; }
    for (i = 0; i < (size_t)height; i++) {
        filtered[i * row] = 0;   /* filter type None */
        memcpy(filtered + i * row + 1, rgb + i * (row - 1), row - 1);
    }
    for (i = 0; i < raw; i++) { a = (a + filtered[i]) % 65521; b = (b + a) % 65521; }
    q = z;
    *q++ = 0x78; *q++ = 0x01;    /* zlib header, no compression */
    for (i = 0, left = raw; left; ) {
        size_t n = left < 65535 ? left : 65535;
        *q++ = (uint8_t)(left == n);
        *q++ = (uint8_t)n; *q++ = (uint8_t)(n >> 8);
        *q++ = (uint8_t)~n; *q++ = (uint8_t)(~n >> 8);
        memcpy(q, filtered + i, n);
        q += n; i += n; left -= n;
    }
    put32(q, (b << 16) | a);
    put32(ihdr, (uint32_t)width);
    put32(ihdr + 4, (uint32_t)height);
    ihdr[8] = 8; ihdr[9] = 2; ihdr[10] = ihdr[11] = ihdr[12] = 0;
    f = fopen(path, "wb");
    bad = !f || fwrite(signature, 1, 8, f) != 8 || chunk(f, "IHDR", ihdr, 13) ||
          chunk(f, "IDAT", z, zsize) || chunk(f, "IEND", NULL, 0);
    if (f && fclose(f)) bad = 1;
    free(z);
    free(filtered);
    return bad ? -1 : 0;
}

void stab_plot_init(stab_path_plot *p) { memset(p, 0, sizeof *p); }

void stab_plot_free(stab_path_plot *p) { free(p->raw); free(p->smooth); stab_plot_init(p); }

int stab_plot_add(stab_path_plot *p, const home_stab_sim *raw, const home_stab_sim *smooth)
{
    if (p->n == p->capacity) {
        int cap = p->capacity ? 2 * p->capacity : 256;
        double (*r)[3] = realloc(p->raw, (size_t)cap * sizeof *r);
        double (*s)[3];
        if (!r) return -1;
        p->raw = r;
        if (!(s = realloc(p->smooth, (size_t)cap * sizeof *s))) return -1;
        p->smooth = s;
        p->capacity = cap;
    }
    p->raw[p->n][0] = raw->tx; p->raw[p->n][1] = raw->ty; p->raw[p->n][2] = raw->angle * 57.29577951308232;
    p->smooth[p->n][0] = smooth->tx; p->smooth[p->n][1] = smooth->ty; p->smooth[p->n][2] = smooth->angle * 57.29577951308232;
    p->n++;
    return 0;
}

/* 3x5 glyphs, rows top to bottom, 3 bits each (MSB = left) */
static unsigned glyph(char c)
{
    static const char chars[] = "0123456789-.ADEFGHMOPRSTWXY";
    static const unsigned bits[] = {
        075557, 026227, 071747, 071717, 055711, 074717, 074757, 071111, 075757, 075717, 000700,
        000002, 025755, 065556, 074647, 074644, 074557, 055755, 057755, 075557, 065644, 065655,
        074717, 072222, 055775, 055255, 055222};
    const char *at = strchr(chars, c);
    return c && at ? bits[at - chars] : 0;
}

static void text(uint8_t *img, int x, int y, const char *s, const uint8_t *rgb)
{
    int i, r, c, k, l;
    for (i = 0; s[i]; i++)
        for (r = 0; r < 5; r++)
            for (c = 0; c < 3; c++)
                if (glyph(s[i]) >> ((4 - r) * 3 + (2 - c)) & 1)
                    for (k = 0; k < 2; k++)
                        for (l = 0; l < 2; l++) {
                            int px = x + i * 8 + c * 2 + l, py = y + r * 2 + k;
                            if (px >= 0 && px < PLOT_W && py >= 0) memcpy(img + ((size_t)py * PLOT_W + px) * 3, rgb, 3);
                        }
}

static void line(uint8_t *img, int height, int x0, int y0, int x1, int y1, const uint8_t *rgb)
{
    int dx = abs(x1 - x0), dy = -abs(y1 - y0), sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    for (;;) {
        if (x0 >= 0 && x0 < PLOT_W && y0 >= 0 && y0 < height) memcpy(img + ((size_t)y0 * PLOT_W + x0) * 3, rgb, 3);
        if (x0 == x1 && y0 == y1) break;
        int e2 = 2 * err;
        if (e2 >= dy) { err += dy; x0 += sx; }
        if (e2 <= dx) { err += dx; y0 += sy; }
    }
}

int stab_plot_write(const stab_path_plot *p, const char *path, int frame_width, int frame_height)
{
    static const uint8_t red[3] = {220, 40, 40}, blue[3] = {30, 70, 220}, grey[3] = {190, 190, 190}, black[3] = {0, 0, 0};
    static const char *names[3] = {"TX PX", "TY PX", "ROT DEG"};
    const int height = 3 * PANEL_H + 30;
    uint8_t *img = malloc((size_t)PLOT_W * height * 3);
    int c, t, status;
    char label[32];
    (void)frame_width; (void)frame_height;
    if (!img) return -1;
    memset(img, 255, (size_t)PLOT_W * height * 3);
    for (c = 0; c < 3; c++) {
        const int top = c * PANEL_H + PLOT_PAD, bottom = (c + 1) * PANEL_H - 8;
        const int right = PLOT_W - 10;
        double lo = 1e300, hi = -1e300;
        for (t = 0; t < p->n; t++) {
            lo = fmin(lo, fmin(p->raw[t][c], p->smooth[t][c]));
            hi = fmax(hi, fmax(p->raw[t][c], p->smooth[t][c]));
        }
        if (p->n == 0) lo = hi = 0;
        if (hi - lo < 1e-6) { lo -= 1; hi += 1; }
        line(img, height, PLOT_LEFT, top, right, top, grey);
        line(img, height, PLOT_LEFT, bottom, right, bottom, grey);
        line(img, height, PLOT_LEFT, top, PLOT_LEFT, bottom, grey);
        text(img, 4, top - 16, names[c], black);
        snprintf(label, sizeof label, "%.1f", hi);
        text(img, 4, top, label, black);
        snprintf(label, sizeof label, "%.1f", lo);
        text(img, 4, bottom - 10, label, black);
        for (t = 1; t < p->n; t++) {
            double span = p->n > 1 ? p->n - 1 : 1;
            int x0 = PLOT_LEFT + (int)((right - PLOT_LEFT) * (t - 1) / span);
            int x1 = PLOT_LEFT + (int)((right - PLOT_LEFT) * t / span);
            int k;
            for (k = 0; k < 2; k++) {
                const double (*v)[3] = k ? (const double (*)[3])p->smooth : (const double (*)[3])p->raw;
                int y0 = bottom - (int)((bottom - top) * (v[t - 1][c] - lo) / (hi - lo));
                int y1 = bottom - (int)((bottom - top) * (v[t][c] - lo) / (hi - lo));
                line(img, height, x0, y0, x1, y1, k ? blue : red);
                line(img, height, x0, y0 + 1, x1, y1 + 1, k ? blue : red);
            }
        }
    }
    text(img, PLOT_LEFT, height - 20, "RAW", red);
    text(img, PLOT_LEFT + 40, height - 20, "SMOOTHED", blue);
    snprintf(label, sizeof label, "FRAMES 0-%d", p->n ? p->n - 1 : 0);
    text(img, PLOT_LEFT + 130, height - 20, label, black);
    status = png_write_rgb(path, img, PLOT_W, height);
    free(img);
    return status;
}
