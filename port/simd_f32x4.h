/* Four-lane float vectors named once for SSE2 and NEON, so a float kernel is written once
 * (port/home_fvec.h, port/refine_f32x4.h) and compiled by the _sse.c and _neon.c files: each
 * name maps to the one instruction that ISA's kernel used before, so each gives the scalar
 * reference's bits. Multiply and add stay separate (no fused multiply-add): C99's rounding. */
#ifndef HOME_SIMD_F32X4_H
#define HOME_SIMD_F32X4_H
#include <stdint.h>

#define FV_LANES 4
#if defined(__SSE2__)
#include <emmintrin.h>
typedef __m128 home__fv;  /* four floats */
typedef __m128 home__mv;  /* four lane masks (all ones or zero) */
typedef __m128i home__iv; /* four int32 */
#define FV_ZERO() _mm_setzero_ps()
#define FV_SET1(x) _mm_set1_ps(x)
#define FV_LOAD(p) _mm_loadu_ps(p)
#define FV_STORE(p, v) _mm_storeu_ps(p, v)
#define FV_ADD(a, b) _mm_add_ps(a, b)
#define FV_SUB(a, b) _mm_sub_ps(a, b)
#define FV_MUL(a, b) _mm_mul_ps(a, b)
#define FV_DIV(a, b) _mm_div_ps(a, b)
#define FV_NEG(a) _mm_xor_ps(a, _mm_set1_ps(-0.0f))
#define FV_MAX(a, b) _mm_max_ps(a, b)
#define FV_MIN(a, b) _mm_min_ps(a, b)
#define FV_GT(a, b) _mm_cmpgt_ps(a, b)
#define FV_GE(a, b) _mm_cmpge_ps(a, b)
#define FV_LT(a, b) _mm_cmplt_ps(a, b)
#define MV_AND(a, b) _mm_and_ps(a, b)
#define MV_OR(a, b) _mm_or_ps(a, b)
#define MV_BITS(m) _mm_movemask_ps(m) /* lane k's mask as bit k */
#define FV_KEEP(v, m) _mm_and_ps(v, m) /* v where m, else 0 */
#define FV_SELECT(m, a, b) _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b))
#define FV_TRUNC(v) _mm_cvttps_epi32(v)
#define IV_TO_F4(v) _mm_cvtepi32_ps(v)
#define IV_SET1(x) _mm_set1_epi32(x)
#define IV_IOTA() _mm_setr_epi32(0, 1, 2, 3)
#define IV_ZERO() _mm_setzero_si128()
#define IV_ADD(a, b) _mm_add_epi32(a, b)
#define IV_LT(a, b) _mm_castsi128_ps(_mm_cmplt_epi32(a, b))
#define IV_SUB_M(a, m) _mm_sub_epi32(a, _mm_castps_si128(m)) /* + 1 where m */
#define IV_STORE(p, v) _mm_storeu_si128((__m128i *)(void *)(p), v)

/* four int16 as floats (exact) */
static inline home__fv home__fv_load_s16(const int16_t *p)
{
    __m128i v = _mm_loadl_epi64((const __m128i *)(const void *)p);
    return _mm_cvtepi32_ps(_mm_srai_epi32(_mm_unpacklo_epi16(v, v), 16));
}

#elif defined(__ARM_NEON) || defined(__ARM_NEON__)
#include <arm_neon.h>
typedef float32x4_t home__fv;
typedef uint32x4_t home__mv;
typedef int32x4_t home__iv;
#define FV_ZERO() vdupq_n_f32(0.0f)
#define FV_SET1(x) vdupq_n_f32(x)
#define FV_LOAD(p) vld1q_f32(p)
#define FV_STORE(p, v) vst1q_f32(p, v)
#define FV_ADD(a, b) vaddq_f32(a, b)
#define FV_SUB(a, b) vsubq_f32(a, b)
#define FV_MUL(a, b) vmulq_f32(a, b)
#define FV_DIV(a, b) home__fv_div(a, b)
#define FV_NEG(a) vnegq_f32(a)
#define FV_MAX(a, b) vmaxq_f32(a, b)
#define FV_MIN(a, b) vminq_f32(a, b)
#define FV_GT(a, b) vcgtq_f32(a, b)
#define FV_GE(a, b) vcgeq_f32(a, b)
#define FV_LT(a, b) vcltq_f32(a, b)
#define MV_AND(a, b) vandq_u32(a, b)
#define MV_OR(a, b) vorrq_u32(a, b)
#define MV_BITS(m) home__mv_bits(m)
#define FV_KEEP(v, m) vreinterpretq_f32_u32(vandq_u32(vreinterpretq_u32_f32(v), m))
#define FV_SELECT(m, a, b) vbslq_f32(m, a, b)
#define FV_TRUNC(v) vcvtq_s32_f32(v)
#define IV_TO_F4(v) vcvtq_f32_s32(v)
#define IV_SET1(x) vdupq_n_s32(x)
#define IV_IOTA() home__iv_iota()
#define IV_ZERO() vdupq_n_s32(0)
#define IV_ADD(a, b) vaddq_s32(a, b)
#define IV_LT(a, b) vcltq_s32(a, b)
#define IV_SUB_M(a, m) vsubq_s32(a, vreinterpretq_s32_u32(m))
#define IV_STORE(p, v) vst1q_s32(p, v)

static inline home__fv home__fv_load_s16(const int16_t *p)
{
    return vcvtq_f32_s32(vmovl_s16(vld1_s16(p)));
}

/* a / b: armv7 NEON has no vector division, so per lane there (the same IEEE quotients) */
static inline home__fv home__fv_div(home__fv a, home__fv b)
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

/* lane k's mask as bit k, in registers (a store and four loads cost the extremum scan more than
 * its compares on armv7) */
static inline int home__mv_bits(home__mv m)
{
    static const uint32_t bit[4] = {1, 2, 4, 8};
    const uint32x4_t b = vandq_u32(m, vld1q_u32(bit));
#if defined(__aarch64__)
    return (int)vaddvq_u32(b);
#else
    const uint32x2_t s = vpadd_u32(vget_low_u32(b), vget_high_u32(b));
    return (int)vget_lane_u32(vpadd_u32(s, s), 0);
#endif
}

static inline home__iv home__iv_iota(void)
{
    static const int32_t iota[4] = {0, 1, 2, 3};
    return vld1q_s32(iota);
}
#endif
#endif
