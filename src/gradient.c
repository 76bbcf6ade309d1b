/* Image gradient: central differences, kept as exact int16 (twice the true derivative).
 * Border pixels get a zero gradient so the image frame itself never becomes a line. */
#include "home_internal.h"
#include <string.h>

void home__gradient(const uint8_t *image, ptrdiff_t stride, int width, int height,
                    int16_t *gx, int16_t *gy)
{
    int x, y;
    memset(gx, 0, (size_t)width * sizeof *gx);
    memset(gy, 0, (size_t)width * sizeof *gy);
    memset(gx + (size_t)(height - 1) * width, 0, (size_t)width * sizeof *gx);
    memset(gy + (size_t)(height - 1) * width, 0, (size_t)width * sizeof *gy);
    for (y = 1; y < height - 1; y++) {
        const uint8_t *row = image + (ptrdiff_t)y * stride;
        int16_t *ox = gx + (size_t)y * width, *oy = gy + (size_t)y * width;
        ox[0] = oy[0] = ox[width - 1] = oy[width - 1] = 0;
        for (x = 1; x < width - 1; x++) {
            ox[x] = (int16_t)(row[x + 1] - row[x - 1]);
            oy[x] = (int16_t)(row[x + stride] - row[x - stride]);
        }
    }
}
