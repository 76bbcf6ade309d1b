/* Fuzz the PGM reader the CLI uses (examples/pgm.c): any byte string must either parse into a
 * raster that lies entirely inside the input, or be refused with a message. */
#include "fuzz_util.h"
#include "home.h"
#include "pgm.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* a small side limit too, so the size checks are reached by short inputs */
    static const int limits[2] = {HOME_MAX_SIDE, 64};
    int k;
    for (k = 0; k < 2; k++) {
        const uint8_t *pixels = NULL;
        char err[128];
        int width = -1, height = -1;
        err[0] = '\0';
        if (pgm_parse(data, size, limits[k], &width, &height, &pixels, err, sizeof err) != 0) {
            FZ_CHECK(err[0] != '\0');
            continue;
        }
        FZ_CHECK(width >= 1 && height >= 1 && width <= limits[k] && height <= limits[k]);
        FZ_CHECK(pixels > data && pixels <= data + size);
        FZ_CHECK((size_t)(data + size - pixels) >= (size_t)width * (size_t)height);
        {
            /* read every pixel: ASan flags a raster that leaves the input */
            unsigned sum = 0;
            size_t i, n = (size_t)width * (size_t)height;
            for (i = 0; i < n; i++) sum += pixels[i];
            FZ_CHECK(sum <= 255u * n);
        }
    }
    /* a NULL error buffer is allowed */
    {
        const uint8_t *pixels;
        int width, height;
        (void)pgm_parse(data, size, HOME_MAX_SIDE, &width, &height, &pixels, NULL, 0);
    }
    return 0;
}
