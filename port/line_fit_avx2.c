/* The line fit (port/line_fit.h) compiled with AVX2: each four-lane step is one 256-bit
 * operation instead of two 128-bit ones; the same IEEE operations in the same order, so the same
 * bits as the reference. */
#include "line_fit_kernels.h"
#if defined(__x86_64__) && !defined(HOME_NO_AVX2) && defined(__AVX2__)
#include "line_fit.h"

const home__line_fit home__line_fit_avx2 = {.normal = line_normal,
                                            .select_inliers = select_inliers};
#else
typedef int home__line_fit_avx2_unavailable; /* ISO C forbids an empty translation unit */
#endif
