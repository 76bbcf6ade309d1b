/* The SIMD resolver (port/dispatch.c), which every kernel table lookup goes through. */
#ifndef HOME_DISPATCH_H
#define HOME_DISPATCH_H

/* The one SIMD resolver (port/dispatch.c): the backend a home_simd request runs on. AUTO becomes
 * the HOME_SIMD environment variable's choice when set (none, sse, avx2 or neon; not read when
 * built with -DHOME_NO_GETENV), else the best this build and CPU have; HOME__SIMD_BEST is that
 * best without the environment (CPU detection only: no getenv, for calls without a context that
 * may run per band). Returns -1 when the request names a backend this build or CPU lacks. Every
 * table lookup goes through it. */
#define HOME__SIMD_BEST (-2)
int home__simd_resolve(int simd);
#endif
