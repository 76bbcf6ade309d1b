/* The homography's line fit (src/line_fit.h) compiled with AVX2: each four-lane step of the
 * fit is one 256-bit operation instead of two 128-bit ones (-0.3 M instructions per video
 * frame); the same IEEE operations in the same order, so the same bits as the reference. */
#include "kernels.h"
#if defined(HOME__HAVE_AVX2) && defined(__AVX2__)
#define HOME__LINE_FIT_NAME(name) home__##name##_avx2
#include "../src/line_fit.h"

const home__line_fit home__line_fit_avx2 = {home__line_normal_avx2, home__select_inliers_avx2};
#else
typedef int home__line_fit_avx2_unavailable; /* ISO C forbids an empty translation unit */
#endif
