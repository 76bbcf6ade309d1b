/* Eight-lane float vectors for the AVX2 kernels (compiled with -mavx2): the names of
 * port/simd_f32x4.h that port/home_fvec.h uses, each one AVX instruction; ordered comparisons
 * like SSE2's, so every lane's result is the four-lane kernels' and the reference's. */
#ifndef HOME_SIMD_F32X8_H
#define HOME_SIMD_F32X8_H
#include <immintrin.h>
#define FV_LANES 8
typedef __m256 home__fv;
typedef __m256 home__mv;
#define FV_ZERO() _mm256_setzero_ps()
#define FV_SET1(x) _mm256_set1_ps(x)
#define FV_LOAD(p) _mm256_loadu_ps(p)
#define FV_STORE(p, v) _mm256_storeu_ps(p, v)
#define FV_ADD(a, b) _mm256_add_ps(a, b)
#define FV_MUL(a, b) _mm256_mul_ps(a, b)
#define FV_MAX(a, b) _mm256_max_ps(a, b)
#define FV_MIN(a, b) _mm256_min_ps(a, b)
#define FV_GT(a, b) _mm256_cmp_ps(a, b, _CMP_GT_OQ)
#define FV_LT(a, b) _mm256_cmp_ps(a, b, _CMP_LT_OQ)
#define MV_AND(a, b) _mm256_and_ps(a, b)
#define MV_OR(a, b) _mm256_or_ps(a, b)
#define MV_BITS(m) _mm256_movemask_ps(m)
#endif
