/* libhome compile-time limits. Every value can be overridden with -D at build time;
 * the library's fixed-size arrays and the arena layout derive from these alone. */
#ifndef HOME_LIMITS_H
#define HOME_LIMITS_H

/* Largest image side accepted. The Hough bin index is computed in 32-bit fixed point
 * (Q16 over doubled centred coordinates), which stays exact up to this size. */
#ifndef HOME_MAX_SIDE
#define HOME_MAX_SIDE 4096
#endif

/* Smallest image side accepted: below this no meaningful lines fit. */
#ifndef HOME_MIN_SIDE
#define HOME_MIN_SIDE 32
#endif

/* Capacity of a home_features object: keypoints kept per sign (positive / negative J). */
#ifndef HOME_MAX_KEYPOINTS_PER_SIGN
#define HOME_MAX_KEYPOINTS_PER_SIGN 1000
#endif

/* Largest theta resolution (bins over [0, pi)). */
#ifndef HOME_MAX_THETA_BINS
#define HOME_MAX_THETA_BINS 2048
#endif

/* Descriptor length (1x16 radial pattern, uint8). Fixed by the method. */
#define HOME_DESC_LEN 16

/* Levenberg-Marquardt iterations per threshold level, and the number of threshold levels
 * (64 -> 32 -> ... -> final threshold is at most this many halvings). */
#ifndef HOME_LM_MAX_ITERS
#define HOME_LM_MAX_ITERS 20
#endif
#ifndef HOME_LM_COARSE_ITERS
#define HOME_LM_COARSE_ITERS 5
#endif
#ifndef HOME_MAX_THRESHOLD_LEVELS
#define HOME_MAX_THRESHOLD_LEVELS 12
#endif

/* Arena bytes the fast Hough transform may spend on its theta geometry (row shears, block row
 * ranges, resampling weights) computed once per context instead of every frame: about 2 KB per
 * theta row for a 160 px wide Hough image (docs/simd.md). Contexts that need more compute it
 * per frame. */
#ifndef HOME_HOUGH_GEOMETRY_BYTES
#define HOME_HOUGH_GEOMETRY_BYTES (512u * 1024u)
#endif

/* Photometric refinement (src/refine.c): pyramid levels, template points kept at the finest level
 * (halved per coarser level), and the largest Gauss-Newton iteration cap per level. */
#ifndef HOME_REFINE_MAX_LEVELS
#define HOME_REFINE_MAX_LEVELS 3
#endif
#ifndef HOME_REFINE_MAX_POINTS
#define HOME_REFINE_MAX_POINTS 4096
#endif
#ifndef HOME_REFINE_MAX_ITERS
#define HOME_REFINE_MAX_ITERS 50
#endif

#endif
