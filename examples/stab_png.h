/* A PNG plot of a stabiliser's raw and smoothed camera path, written without any library
 * (stored deflate blocks), so `make demo` needs nothing beyond a C compiler. */
#ifndef HOME_STAB_PNG_H
#define HOME_STAB_PNG_H
#include "home_stab.h"

typedef struct stab_path_plot {
    double (*raw)[3], (*smooth)[3];   /* per frame: tx px, ty px, angle deg */
    int n, capacity;
} stab_path_plot;

void stab_plot_init(stab_path_plot *p);
int stab_plot_add(stab_path_plot *p, const home_stab_sim *raw, const home_stab_sim *smooth);
/* Three panels (tx, ty, rotation) over the frames: raw in red, smoothed in blue. 0 on success. */
int stab_plot_write(const stab_path_plot *p, const char *path, int frame_width, int frame_height);
void stab_plot_free(stab_path_plot *p);

/* Write an 8-bit RGB image as PNG; 0 on success. */
int png_write_rgb(const char *path, const uint8_t *rgb, int width, int height);
#endif
