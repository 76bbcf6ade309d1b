/* The one SIMD resolver and the kernel tables it hands out. Compiled with baseline flags; the
 * tables live in the per-ISA files. No state: a context stores the tables it was given. */
#include "kernels.h"
#include "refine_kernels.h"
#include "stab_kernels.h"
#include "home.h"
#ifndef HOME_NO_GETENV
#include <stdlib.h>
#include <string.h>
#endif

#ifdef HOME__HAVE_AVX2
/* 1 when the CPU runs this build's AVX2 kernels */
static int have_avx2(void) { return __builtin_cpu_supports("avx2") != 0; }
#endif

/* the best backend this build and CPU have */
static int best_simd(void)
{
#if defined(HOME__HAVE_NEON)
    return HOME_SIMD_NEON;
#elif defined(HOME__HAVE_AVX2)
    return have_avx2() ? HOME_SIMD_AVX2 : HOME_SIMD_SSE;
#elif defined(HOME__HAVE_SSE)
    return HOME_SIMD_SSE;
#else
    return HOME_SIMD_NONE;
#endif
}

int home__simd_resolve(int simd)
{
    if (simd == HOME__SIMD_BEST) return best_simd();
#ifndef HOME_NO_GETENV
    if (simd == HOME_SIMD_AUTO) {
        const char *env = getenv("HOME_SIMD");
        if (env && !strcmp(env, "none")) simd = HOME_SIMD_NONE;
        else if (env && !strcmp(env, "sse")) simd = HOME_SIMD_SSE;
        else if (env && !strcmp(env, "neon")) simd = HOME_SIMD_NEON;
        else if (env && !strcmp(env, "avx2")) simd = HOME_SIMD_AVX2;
    }
#endif
    switch (simd) {
    case HOME_SIMD_AUTO: return best_simd();
    case HOME_SIMD_NONE: return HOME_SIMD_NONE;
#ifdef HOME__HAVE_SSE
    case HOME_SIMD_SSE: return HOME_SIMD_SSE;
#endif
#ifdef HOME__HAVE_AVX2
    case HOME_SIMD_AVX2: return have_avx2() ? HOME_SIMD_AVX2 : -1;
#endif
#ifdef HOME__HAVE_NEON
    case HOME_SIMD_NEON: return HOME_SIMD_NEON;
#endif
    default: return -1;
    }
}

/* Each table lookup: the resolved backend's table of that kind (tables named
 * <prefix>_scalar, _sse, _avx2, _neon), NULL when the resolver refuses. */
#ifdef HOME__HAVE_SSE
#define CASE_SSE(prefix) case HOME_SIMD_SSE: return &prefix##_sse;
#else
#define CASE_SSE(prefix)
#endif
#ifdef HOME__HAVE_AVX2
#define CASE_AVX2(prefix) case HOME_SIMD_AVX2: return &prefix##_avx2;
#else
#define CASE_AVX2(prefix)
#endif
#ifdef HOME__HAVE_NEON
#define CASE_NEON(prefix) case HOME_SIMD_NEON: return &prefix##_neon;
#else
#define CASE_NEON(prefix)
#endif
#define TABLE_FOR(type, prefix)                                                                  \
    {                                                                                            \
        switch (home__simd_resolve(simd)) {                                                      \
        case HOME_SIMD_NONE: return &prefix##_scalar;                                            \
        CASE_SSE(prefix) CASE_AVX2(prefix) CASE_NEON(prefix)                                     \
        default: return (const type *)0;                                                         \
        }                                                                                        \
    }

const home__kernels *home__kernels_for(int simd) TABLE_FOR(home__kernels, home__kernels)

const home__refine_kernels *home__refine_kernels_for(int simd)
    TABLE_FOR(home__refine_kernels, home__refine_kernels)

const home__stab_kernels *home__stab_kernels_for(int simd)
    TABLE_FOR(home__stab_kernels, home__stab_kernels)
