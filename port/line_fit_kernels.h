/* The homography's line fit (src/homography.c) as a kernel: the transfer residuals of matched
 * lines, the normal equations of the LM solver and the inlier selection. One implementation,
 * port/line_fit.h, compiled once per instruction set (port/line_fit_scalar.c,
 * port/line_fit_avx2.c); element-wise IEEE arithmetic in C99 mode, so the same bits from each. */
#ifndef HOME_LINE_FIT_KERNELS_H
#define HOME_LINE_FIT_KERNELS_H

/* A candidate match: line (theta_a, r_a) in A against (theta_b, r_b) in B. */
typedef struct home__match {
    float theta_a, r_a, theta_b, r_b;
    double cos_a, sin_a, cos_b, sin_b; /* precomputed for the homography fit */
} home__match;

/* A least-squares problem over 8 parameters for src/lm.c: its cost and, when jtj is not NULL,
 * the Gauss-Newton normal equations J^T J (8x8, row-major) and J^T e at p. */
typedef double (*home__normal_fn)(const void *user, const double *p, double *jtj, double *jte);

typedef struct home__line_problem {
    const home__match *matches;
    const int *index;        /* the inliers the fit runs over */
    int n;
    double scale, inv_scale; /* half diagonal, px: normalises r */
    double w_theta, w_r;     /* residual weights into Hough bins */
} home__line_problem;

typedef struct home__line_fit {
    /* cost, and J^T J, J^T e when jtj is not NULL, over the inliers (home__lm_solve's fn) */
    home__normal_fn normal;
    /* the matches (of n) whose transfer error at g is under threshold, into index; how many */
    int (*select_inliers)(const home__line_problem *lp, int n, const double *g, double threshold,
                          int *index);
} home__line_fit;

extern const home__line_fit home__line_fit_scalar;
#if defined(__x86_64__) && !defined(HOME_NO_AVX2)
extern const home__line_fit home__line_fit_avx2; /* -mavx2 */
#endif
#endif
