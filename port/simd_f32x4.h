/* Four-lane float vectors named once for SSE2 and NEON, so a float kernel is written once
 * (port/home_f32x4.h, port/refine_f32x4.h) and compiled by the _sse.c and _neon.c files: each
 * name maps to the one instruction that ISA's kernel used before, so each gives the scalar
 * reference's bits. Multiply and add stay separate (no fused multiply-add): C99's rounding. */
#ifndef HOME_SIMD_F32X4_H
#define HOME_SIMD_F32X4_H
#include <stdint.h>

#if defined(__SSE2__)
#include <emmintrin.h>
typedef __m128 home__f4;  /* four floats */
typedef __m128 home__m4;  /* four lane masks (all ones or zero) */
typedef __m128i home__i4; /* four int32 */
#define F4_ZERO() _mm_setzero_ps()
#define F4_SET1(x) _mm_set1_ps(x)
#define F4_LOAD(p) _mm_loadu_ps(p)
#define F4_STORE(p, v) _mm_storeu_ps(p, v)
#define F4_ADD(a, b) _mm_add_ps(a, b)
#define F4_SUB(a, b) _mm_sub_ps(a, b)
#define F4_MUL(a, b) _mm_mul_ps(a, b)
#define F4_DIV(a, b) _mm_div_ps(a, b)
#define F4_NEG(a) _mm_xor_ps(a, _mm_set1_ps(-0.0f))
#define F4_MAX(a, b) _mm_max_ps(a, b)
#define F4_MIN(a, b) _mm_min_ps(a, b)
#define F4_GT(a, b) _mm_cmpgt_ps(a, b)
#define F4_GE(a, b) _mm_cmpge_ps(a, b)
#define F4_LT(a, b) _mm_cmplt_ps(a, b)
#define M4_AND(a, b) _mm_and_ps(a, b)
#define M4_OR(a, b) _mm_or_ps(a, b)
#define M4_BITS(m) _mm_movemask_ps(m) /* lane k's mask as bit k */
#define F4_KEEP(v, m) _mm_and_ps(v, m) /* v where m, else 0 */
#define F4_SELECT(m, a, b) _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b))
#define F4_TRUNC(v) _mm_cvttps_epi32(v)
#define I4_TO_F4(v) _mm_cvtepi32_ps(v)
#define I4_SET1(x) _mm_set1_epi32(x)
#define I4_IOTA() _mm_setr_epi32(0, 1, 2, 3)
#define I4_ZERO() _mm_setzero_si128()
#define I4_ADD(a, b) _mm_add_epi32(a, b)
#define I4_LT(a, b) _mm_castsi128_ps(_mm_cmplt_epi32(a, b))
#define I4_SUB_M(a, m) _mm_sub_epi32(a, _mm_castps_si128(m)) /* + 1 where m */
#define I4_STORE(p, v) _mm_storeu_si128((__m128i *)(void *)(p), v)

/* four int16 as floats (exact) */
static inline home__f4 home__f4_load_s16(const int16_t *p)
{
    __m128i v = _mm_loadl_epi64((const __m128i *)(const void *)p);
    return _mm_cvtepi32_ps(_mm_srai_epi32(_mm_unpacklo_epi16(v, v), 16));
}

#elif defined(__ARM_NEON) || defined(__ARM_NEON__)
#include <arm_neon.h>
typedef float32x4_t home__f4;
typedef uint32x4_t home__m4;
typedef int32x4_t home__i4;
#define F4_ZERO() vdupq_n_f32(0.0f)
#define F4_SET1(x) vdupq_n_f32(x)
#define F4_LOAD(p) vld1q_f32(p)
#define F4_STORE(p, v) vst1q_f32(p, v)
#define F4_ADD(a, b) vaddq_f32(a, b)
#define F4_SUB(a, b) vsubq_f32(a, b)
#define F4_MUL(a, b) vmulq_f32(a, b)
#define F4_DIV(a, b) home__f4_div(a, b)
#define F4_NEG(a) vnegq_f32(a)
#define F4_MAX(a, b) vmaxq_f32(a, b)
#define F4_MIN(a, b) vminq_f32(a, b)
#define F4_GT(a, b) vcgtq_f32(a, b)
#define F4_GE(a, b) vcgeq_f32(a, b)
#define F4_LT(a, b) vcltq_f32(a, b)
#define M4_AND(a, b) vandq_u32(a, b)
#define M4_OR(a, b) vorrq_u32(a, b)
#define M4_BITS(m) home__m4_bits(m)
#define F4_KEEP(v, m) vreinterpretq_f32_u32(vandq_u32(vreinterpretq_u32_f32(v), m))
#define F4_SELECT(m, a, b) vbslq_f32(m, a, b)
#define F4_TRUNC(v) vcvtq_s32_f32(v)
#define I4_TO_F4(v) vcvtq_f32_s32(v)
#define I4_SET1(x) vdupq_n_s32(x)
#define I4_IOTA() home__i4_iota()
#define I4_ZERO() vdupq_n_s32(0)
#define I4_ADD(a, b) vaddq_s32(a, b)
#define I4_LT(a, b) vcltq_s32(a, b)
#define I4_SUB_M(a, m) vsubq_s32(a, vreinterpretq_s32_u32(m))
#define I4_STORE(p, v) vst1q_s32(p, v)

static inline home__f4 home__f4_load_s16(const int16_t *p)
{
    return vcvtq_f32_s32(vmovl_s16(vld1_s16(p)));
}

/* a / b: armv7 NEON has no vector division, so per lane there (the same IEEE quotients) */
static inline home__f4 home__f4_div(home__f4 a, home__f4 b)
{
#if defined(__aarch64__)
    return vdivq_f32(a, b);
#else
    float x[4], y[4];
    int k;
    vst1q_f32(x, a);
    vst1q_f32(y, b);
    for (k = 0; k < 4; k++) x[k] /= y[k];
    return vld1q_f32(x);
#endif
}

static inline int home__m4_bits(home__m4 m)
{
    uint32_t b[4];
    vst1q_u32(b, m);
    return (b[0] & 1) | (b[1] & 2) | (b[2] & 4) | (b[3] & 8);
}

static inline home__i4 home__i4_iota(void)
{
    static const int32_t iota[4] = {0, 1, 2, 3};
    return vld1q_s32(iota);
}
#endif
#endif
