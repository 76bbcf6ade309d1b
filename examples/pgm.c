#include "pgm.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void set_err(char *err, size_t n, const char *msg)
{
    if (err && n) snprintf(err, n, "%s", msg);
}

/* Skip whitespace and '#' comments; returns the new offset. */
static size_t skip_space(const uint8_t *d, size_t n, size_t i)
{
    while (i < n) {
        if (d[i] == '#') {
            while (i < n && d[i] != '\n' && d[i] != '\r') i++;
        } else if (d[i] == ' ' || d[i] == '\t' || d[i] == '\n' || d[i] == '\r' ||
                   d[i] == '\v' || d[i] == '\f') {
            i++;
        } else {
            break;
        }
    }
    return i;
}

/* Parse a decimal header number no larger than limit; returns -1 on failure. */
static long parse_number(const uint8_t *d, size_t n, size_t *i, long limit)
{
    long v = 0;
    size_t start;
    *i = skip_space(d, n, *i);
    start = *i;
    while (*i < n && d[*i] >= '0' && d[*i] <= '9') {
        v = v * 10 + (d[*i] - '0');
        if (v > limit) return -1;
        (*i)++;
    }
    return *i == start ? -1 : v;
}

int pgm_parse(const uint8_t *data, size_t size, int max_side, int *width, int *height,
              const uint8_t **pixels, char *err, size_t err_size)
{
    size_t i = 2;
    long w, h, maxval;
    if (!data || size < 2 || data[0] != 'P' || data[1] != '5') {
        set_err(err, err_size, "not a binary PGM (P5) file");
        return -1;
    }
    w = parse_number(data, size, &i, max_side);
    h = parse_number(data, size, &i, max_side);
    if (w <= 0 || h <= 0) {
        set_err(err, err_size, "PGM width/height missing, zero or too large");
        return -1;
    }
    maxval = parse_number(data, size, &i, 65535);
    if (maxval != 255) {
        set_err(err, err_size, "PGM maxval must be 255 (8-bit grey)");
        return -1;
    }
    /* exactly one whitespace byte separates the header from the raster */
    if (i >= size || !(data[i] == ' ' || data[i] == '\t' || data[i] == '\n' || data[i] == '\r')) {
        set_err(err, err_size, "PGM header is not followed by whitespace");
        return -1;
    }
    i++;
    if (size - i < (size_t)w * (size_t)h) {
        set_err(err, err_size, "PGM raster is truncated");
        return -1;
    }
    *width = (int)w;
    *height = (int)h;
    *pixels = data + i;
    return 0;
}

uint8_t *pgm_read_file(const char *path, size_t *size, char *err, size_t err_size)
{
    FILE *f = fopen(path, "rb");
    uint8_t *buf = NULL;
    size_t cap = 0, len = 0;
    if (!f) {
        set_err(err, err_size, "cannot open file");
        return NULL;
    }
    for (;;) {
        size_t got;
        if (len == cap) {
            uint8_t *nb;
            cap = cap ? cap * 2 : 1 << 16;
            if (cap > ((size_t)1 << 31)) { set_err(err, err_size, "file too large"); break; }
            nb = (uint8_t *)realloc(buf, cap);
            if (!nb) { set_err(err, err_size, "out of memory"); break; }
            buf = nb;
        }
        got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0) {
            if (ferror(f)) { set_err(err, err_size, "read error"); break; }
            fclose(f);
            *size = len;
            return buf;
        }
    }
    fclose(f);
    free(buf);
    return NULL;
}

int pgm_write(const char *path, const uint8_t *pixels, int width, int height, ptrdiff_t stride)
{
    FILE *f = fopen(path, "wb");
    int y, ok;
    if (!f) return -1;
    ok = fprintf(f, "P5\n%d %d\n255\n", width, height) > 0;
    for (y = 0; ok && y < height; y++)
        ok = fwrite(pixels + (ptrdiff_t)y * stride, 1, (size_t)width, f) == (size_t)width;
    return (fclose(f) == 0 && ok) ? 0 : -1;
}
