/* The one dispatch point: maps a home_simd request to a kernel table. Compiled with baseline
 * flags; the tables live in per-ISA files. No state: each context stores its own table. */
#include "kernels.h"
#include "home.h"

const home__kernels *home__kernels_for(int simd)
{
    switch (simd) {
    case HOME_SIMD_NONE: return &home__kernels_scalar;
    case HOME_SIMD_SSE:
#ifdef HOME__HAVE_SSE
        return &home__kernels_sse;
#else
        return NULL;
#endif
    case HOME_SIMD_AVX2:
#ifdef HOME__HAVE_AVX2
        return __builtin_cpu_supports("avx2") ? &home__kernels_avx2 : NULL;
#else
        return NULL;
#endif
    case HOME_SIMD_NEON:
#ifdef HOME__HAVE_NEON
        return &home__kernels_neon;
#else
        return NULL;
#endif
    case HOME_SIMD_AUTO:
#if defined(HOME__HAVE_NEON)
        return &home__kernels_neon;
#elif defined(HOME__HAVE_AVX2)
        return __builtin_cpu_supports("avx2") ? &home__kernels_avx2 : &home__kernels_sse;
#elif defined(HOME__HAVE_SSE)
        return &home__kernels_sse;
#else
        return &home__kernels_scalar;
#endif
    default: return NULL;
    }
}
