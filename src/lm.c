/* A small fixed-size Levenberg-Marquardt solver for 8 parameters: the problem builds its normal
 * equations (in double), solved in place by Cholesky. Work is bounded by max_iters outer
 * iterations of at most LM_MAX_TRIES damping attempts each. */
#include "home_internal.h"
#include <math.h>
#include <string.h>

#define NP 8
#define LM_MAX_TRIES 8

/* Cholesky factor of a symmetric positive definite 8x8 a (row-major), in place: the lower
 * triangle becomes L with a = L L^T. Returns 0 when a is not positive definite. */
int home__cholesky8(double *a)
{
    int i, j, k;
    for (j = 0; j < NP; j++) {
        double d = a[j * NP + j];
        for (k = 0; k < j; k++) d -= a[j * NP + k] * a[j * NP + k];
        if (!(d > 0.0) || !isfinite(d)) return 0;
        d = sqrt(d);
        a[j * NP + j] = d;
        for (i = j + 1; i < NP; i++) {
            double s = a[i * NP + j];
            for (k = 0; k < j; k++) s -= a[i * NP + k] * a[j * NP + k];
            a[i * NP + j] = s / d;
        }
    }
    return 1;
}

/* b <- (L L^T)^-1 b for the factor home__cholesky8 left in l. */
void home__cholesky_solve8(const double *l, double *b)
{
    int i, k;
    for (i = 0; i < NP; i++) {            /* L y = b */
        double s = b[i];
        for (k = 0; k < i; k++) s -= l[i * NP + k] * b[k];
        b[i] = s / l[i * NP + i];
    }
    for (i = NP - 1; i >= 0; i--) {       /* L^T x = y */
        double s = b[i];
        for (k = i + 1; k < NP; k++) s -= l[k * NP + i] * b[k];
        b[i] = s / l[i * NP + i];
    }
}

/* Solve a x = b for symmetric positive definite a (8x8, row-major); a is overwritten by its
 * Cholesky factor and b by x. Returns 0 when a is not positive definite. */
int home__solve_spd8(double *a, double *b)
{
    if (!home__cholesky8(a)) return 0;
    home__cholesky_solve8(a, b);
    return 1;
}

int home__lm_solve(double *p, home__normal_fn fn, const void *user, int max_iters)
{
    double lambda = 1e-3, cost = fn(user, p, NULL, NULL);
    int it;
    if (!isfinite(cost)) return 0;
    for (it = 0; it < max_iters; it++) {
        double jtj[NP * NP], jte[NP];
        int a, tries, improved = 0;
        fn(user, p, jtj, jte);
        for (tries = 0; tries < LM_MAX_TRIES; tries++) {
            double m[NP * NP], step[NP], trial[NP], new_cost;
            memcpy(m, jtj, sizeof m);
            for (a = 0; a < NP; a++) {
                m[a * NP + a] += lambda * (jtj[a * NP + a] + 1e-9);
                step[a] = -jte[a];
            }
            if (home__solve_spd8(m, step)) {
                for (a = 0; a < NP; a++) trial[a] = p[a] + step[a];
                new_cost = fn(user, trial, NULL, NULL);
                if (isfinite(new_cost) && new_cost < cost) {
                    double gain = cost - new_cost;
                    memcpy(p, trial, sizeof trial);
                    lambda = lambda * 0.1 < 1e-12 ? 1e-12 : lambda * 0.1;
                    improved = 1;
                    if (gain <= 1e-8 * cost) return 1; /* converged: far below bin precision */
                    cost = new_cost;
                    break;
                }
            }
            lambda *= 10.0;
        }
        if (!improved) break; /* no damping reduces the cost: at a minimum */
    }
    return 1;
}
