/* Private declarations of the stabiliser (src/stabilise.c) and its warp (src/warp.c). */
#ifndef HOME_STAB_INTERNAL_H
#define HOME_STAB_INTERNAL_H
#include "home_stab.h"
#include "stab_kernels.h"

/* HOME_OK when im is a usable frame: known format, size within HOME's limits (even where
 * chroma is subsampled), planes present, strides at least a row. */
int home__stab_check_image(const home_stab_image *im);

/* One output row (home__warp_row_c's contract) by the table k's body kernel and the reference
 * for the rows it does not take and its tail. */
void home__warp_row(const home__stab_kernels *k, const uint8_t *src, ptrdiff_t stride, int step,
                    int w, int h, int32_t x0, int32_t y0, int32_t dx, int32_t dy, uint8_t *dst,
                    int dst_step, int n);
#endif
