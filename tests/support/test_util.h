/* Shared helpers for the test files. */
#ifndef HOME_TEST_UTIL_H
#define HOME_TEST_UTIL_H
#include "home.h"
#include <stddef.h>

/* A context for a width x height image in a static arena; NULL if it does not fit. */
home_context *test_context(int width, int height, const home_config *override_cfg);
/* Line (theta, r) in centred coords of an image mapped by pixel homography h; returns the line
 * in the other image with the orientation h keeps. */
void test_map_line(const double *h, int width, int height, double theta, double r,
                   double *theta_out, double *r_out);
#endif
