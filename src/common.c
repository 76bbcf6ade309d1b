/* What every stage of a context uses: the clock and the image check. A leaf: it calls no other
 * file of the library. */
#include "home_internal.h"

int home__check_image(const home_context *ctx, const uint8_t *image, ptrdiff_t stride)
{
    if (!image) return HOME_E_NULL;
    if (stride < (ptrdiff_t)ctx->cfg.width) return HOME_E_STRIDE;
    /* the last row's address, image + (height - 1) * stride, must not overflow */
    if (stride > (PTRDIFF_MAX - ctx->cfg.width) / (ctx->cfg.height - 1)) return HOME_E_STRIDE;
    return HOME_OK;
}

double home__now(const home_context *ctx)
{
    return ctx->cfg.clock ? ctx->cfg.clock(ctx->cfg.clock_user) : 0.0;
}
