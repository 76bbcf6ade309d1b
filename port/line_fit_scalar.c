/* The line fit (port/line_fit.h) at the baseline instruction set: the reference. */
#include "line_fit.h"

const home__line_fit home__line_fit_scalar = {.normal = line_normal,
                                              .select_inliers = select_inliers};
