/* A small fixed-size Levenberg-Marquardt solver for 8 parameters with 3-component residuals:
 * normal equations accumulated in double and solved in place by Cholesky. Work is bounded by
 * max_iters outer iterations of at most LM_MAX_TRIES damping attempts each. */
#include "home_internal.h"
#include <math.h>
#include <string.h>

#define NP 8
#define LM_MAX_TRIES 8

/* Solve a x = b for symmetric positive definite a (8x8, row-major); a is overwritten by its
 * Cholesky factor and b by x. Returns 0 when a is not positive definite. */
int home__solve_spd8(double *a, double *b)
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
    for (i = 0; i < NP; i++) {            /* L y = b */
        double s = b[i];
        for (k = 0; k < i; k++) s -= a[i * NP + k] * b[k];
        b[i] = s / a[i * NP + i];
    }
    for (i = NP - 1; i >= 0; i--) {       /* L^T x = y */
        double s = b[i];
        for (k = i + 1; k < NP; k++) s -= a[k * NP + i] * b[k];
        b[i] = s / a[i * NP + i];
    }
    return 1;
}

static double total_cost(const double *p, int n, const int *index, home__residual_fn fn,
                         const void *user)
{
    double cost = 0.0, e[3];
    int i;
    for (i = 0; i < n; i++) {
        fn(user, index[i], p, e, NULL);
        cost += e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    }
    return cost;
}

int home__lm_solve(double *p, int n, const int *index, home__residual_fn fn, const void *user,
                   int max_iters)
{
    double lambda = 1e-3, cost = total_cost(p, n, index, fn, user);
    int it;
    if (!isfinite(cost)) return 0;
    for (it = 0; it < max_iters; it++) {
        double jtj[NP * NP], jte[NP], e[3], jac[3 * NP];
        int i, r, a, tries, improved = 0;
        memset(jtj, 0, sizeof jtj);
        memset(jte, 0, sizeof jte);
        for (i = 0; i < n; i++) {
            fn(user, index[i], p, e, jac);
            /* the full square, unrolled; Jacobian rows are often partly zero */
            for (r = 0; r < 3; r++) {
                const double *row = jac + r * NP;
                for (a = 0; a < NP; a++) {
                    const double ra = row[a];
                    double *dst = jtj + a * NP;
                    if (ra == 0.0) continue;
                    jte[a] += ra * e[r];
                    dst[0] += ra * row[0]; dst[1] += ra * row[1];
                    dst[2] += ra * row[2]; dst[3] += ra * row[3];
                    dst[4] += ra * row[4]; dst[5] += ra * row[5];
                    dst[6] += ra * row[6]; dst[7] += ra * row[7];
                }
            }
        }
        for (tries = 0; tries < LM_MAX_TRIES; tries++) {
            double m[NP * NP], step[NP], trial[NP], new_cost;
            memcpy(m, jtj, sizeof m);
            for (a = 0; a < NP; a++) {
                m[a * NP + a] += lambda * (jtj[a * NP + a] + 1e-9);
                step[a] = -jte[a];
            }
            if (home__solve_spd8(m, step)) {
                for (a = 0; a < NP; a++) trial[a] = p[a] + step[a];
                new_cost = total_cost(trial, n, index, fn, user);
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
