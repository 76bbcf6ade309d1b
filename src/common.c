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

void home__cofactors3(const double *m, double *c)
{
    c[0] = m[4] * m[8] - m[5] * m[7];
    c[1] = -(m[3] * m[8] - m[5] * m[6]);
    c[2] = m[3] * m[7] - m[4] * m[6];
    c[3] = -(m[1] * m[8] - m[2] * m[7]);
    c[4] = m[0] * m[8] - m[2] * m[6];
    c[5] = -(m[0] * m[7] - m[1] * m[6]);
    c[6] = m[1] * m[5] - m[2] * m[4];
    c[7] = -(m[0] * m[5] - m[2] * m[3]);
    c[8] = m[0] * m[4] - m[1] * m[3];
}
