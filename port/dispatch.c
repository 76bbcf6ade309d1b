/* The one dispatch point: maps a home_simd request to a kernel table. Compiled with baseline
 * flags; the tables live in per-ISA files. No state: each context stores its own table. */
#include "kernels.h"
#include "refine_kernels.h"
#include "stab_kernels.h"
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

/* The refinement's and the stabiliser's tables follow the same choice. */
const home__refine_kernels *home__refine_kernels_for(int simd)
{
    const home__kernels *k = home__kernels_for(simd);
    return k ? k->refine : NULL;
}

const home__stab_kernels *home__stab_kernels_for(int simd)
{
    const home__kernels *k = home__kernels_for(simd);
    return k ? k->stab : NULL;
}
