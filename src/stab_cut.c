/* Scene cuts: a coarse thumbnail of every frame (cell means of the registration luma), and how
 * alike two thumbnails are once gain, offset and a plausible shift are allowed for. A frame
 * that HOME cannot register and whose thumbnail is unlike its predecessor's at every such shift
 * starts a new scene (stabilise.c). */
#include "stab_internal.h"
#include <math.h>

#define SIDE HOME__STAB_THUMB_SIDE
/* Below this standard deviation (grey levels) over the compared cells a thumbnail is flat (a
 * black or faded frame): it tells nothing about a cut. */
#define FLAT_THUMB_STD 2.0

/* Columns summed at once (a stack buffer: the frame's width in chunks of this many) */
#define THUMB_CHUNK 256
/* A band's column sums: at most (HOME_MAX_SIDE / SIDE + 1) / 2 + 1 rows of 255, 16 bits
 * (twice the lanes of 32) up to the default HOME_MAX_SIDE */
#if ((HOME_MAX_SIDE / HOME__STAB_THUMB_SIDE + 1) / 2 + 1) * 255 <= 65535
typedef uint16_t column_sum;
#else
typedef uint32_t column_sum;
#endif

/* Cell means over every second row and column (the cells are 8 px or more on any frame HOME
 * accepts; a quarter of the pixels tell the mean as well). Each band of cells first sums its
 * sampled rows column by column (a contiguous loop the compiler vectorises), then every
 * cell adds its sampled columns from those sums: the same integers as pixel by pixel. */
void home__stab_thumbnail(const uint8_t *luma, ptrdiff_t stride, int w, int h, float *thumb)
{
    column_sum column[THUMB_CHUNK];
    uint32_t cell[SIDE];
    int cx, cy, x, y, i;
    for (cy = 0; cy < SIDE; cy++) {
        const int y0 = cy * h / SIDE, y1 = (cy + 1) * h / SIDE, rows = (y1 - y0 + 1) / 2;
        int start;
        for (cx = 0; cx < SIDE; cx++) cell[cx] = 0;
        for (start = 0; start < w; start += THUMB_CHUNK) {
            const int end = start + THUMB_CHUNK < w ? start + THUMB_CHUNK : w;
            for (i = 0; i < end - start; i++) column[i] = 0;
            for (y = y0; y < y1; y += 2) {
                const uint8_t *row = luma + (ptrdiff_t)y * stride + start;
                for (i = 0; i < end - start; i++) column[i] = (column_sum)(column[i] + row[i]);
            }
            for (cx = 0; cx < SIDE; cx++) {
                const int x0 = cx * w / SIDE, x1 = (cx + 1) * w / SIDE;
                /* the cell's sampled columns x0, x0 + 2, ... within this chunk */
                x = x0 >= start ? x0 : start + ((start - x0) & 1);
                for (; x < x1 && x < end; x += 2) cell[cx] += column[x - start];
            }
        }
        for (cx = 0; cx < SIDE; cx++) {
            const int x0 = cx * w / SIDE, x1 = (cx + 1) * w / SIDE;
            const uint32_t count = (uint32_t)rows * (uint32_t)((x1 - x0 + 1) / 2);
            thumb[cy * SIDE + cx] = count ? (float)cell[cx] / (float)count : 0.0f;
        }
    }
}

/* Correlation of a and b over the cells they share when b is shifted by (dx, dy) cells; 1 when
 * either is flat there. */
static double shifted_correlation(const float *a, const float *b, int dx, int dy)
{
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, n, va, vb;
    int x, y, count = 0;
    for (y = 0; y < SIDE; y++) {
        if (y + dy < 0 || y + dy >= SIDE) continue;
        for (x = 0; x < SIDE; x++) {
            double p, q;
            if (x + dx < 0 || x + dx >= SIDE) continue;
            p = a[y * SIDE + x];
            q = b[(y + dy) * SIDE + x + dx];
            sa += p; sb += q; saa += p * p; sbb += q * q; sab += p * q;
            count++;
        }
    }
    n = count;
    va = saa - sa * sa / n;
    vb = sbb - sb * sb / n;
    if (va < FLAT_THUMB_STD * FLAT_THUMB_STD * n || vb < FLAT_THUMB_STD * FLAT_THUMB_STD * n)
        return 1.0;
    return (sab - sa * sb / n) / sqrt(va * vb);
}

/* The best correlation of the two thumbnails over shifts of up to max_shift_cells cells. */
double home__stab_thumb_similarity(const float *a, const float *b, int max_shift_cells)
{
    double best = -1.0;
    int dx, dy;
    for (dy = -max_shift_cells; dy <= max_shift_cells; dy++)
        for (dx = -max_shift_cells; dx <= max_shift_cells; dx++) {
            const double c = shifted_correlation(a, b, dx, dy);
            if (c > best) best = c;
        }
    return best;
}
