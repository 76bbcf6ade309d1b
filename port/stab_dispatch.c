/* Dispatch of the warp kernels: the same choice as home__kernels_for(). */
#include "stab_kernels.h"
#include "home.h"

const home__stab_kernels *home__stab_kernels_for(int simd)
{
    switch (simd) {
    case HOME_SIMD_NONE: return &home__stab_kernels_scalar;
    case HOME_SIMD_SSE:
    case HOME_SIMD_AVX2:
#if defined(__SSE2__)
        return &home__stab_kernels_sse;
#else
        return NULL;
#endif
    case HOME_SIMD_NEON:
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
        return &home__stab_kernels_neon;
#else
        return NULL;
#endif
    case HOME_SIMD_AUTO:
#if defined(__ARM_NEON) || defined(__ARM_NEON__)
        return &home__stab_kernels_neon;
#elif defined(__SSE2__)
        return &home__stab_kernels_sse;
#else
        return &home__stab_kernels_scalar;
#endif
    default: return NULL;
    }
}
