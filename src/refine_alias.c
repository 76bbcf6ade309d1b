/* Is a motion one period of a repeated pattern away from another just as good? A grating of
 * bars that fills the frame aligns as well one bar further on: neither HOME's lines nor the
 * photometric fit can tell which is right, and picking one is a guess. Frame A's periods come
 * from the autocorrelation of its profiles (the background image: quarter size) along a few
 * directions: the dominant gradient direction (a grating at any angle) and the two axes and
 * two diagonals (the lattice vectors of tiles, pegboards, window grids and wire mesh, along
 * which a profile across a two-dimensional pattern repeats; the period along the dominant
 * direction of such a pattern is in general no translation that maps it onto itself). For
 * each period the refinement is started from the motion shifted by it either way, and an
 * optimum it reaches elsewhere is scored against the motion itself on the identity test's
 * region points. */
#include "refine_internal.h"
#include <math.h>
#include <string.h>

#define PROFILE_BINS 256    /* profile across the pattern (wider: several unit bins in one) */
#define BIN_MIN_COUNT 4     /* pixels a profile bin needs */
#define PERIOD_MIN 3        /* lags below this many bins or background px are the blur, not a
                               period */
#define PERIOD_CORR 0.6     /* the profile's normalised autocorrelation at a period */
#define PERIODS_SEEN 3      /* the profile spans at least this many periods */
#define DIRECTIONS 5        /* the dominant direction, x, y and the two diagonals */
#define TESTED_MAX 3        /* the periods whose aliases are refined, at most */
#define PARALLEL_COS 0.94   /* a direction within 20 degrees of a tested one, */
#define SAME_PERIOD 0.15    /* ... with a period this close to its, adds nothing */
/* A motion is aliased when the optimum one period away has a mean robust cost of at most this
 * many times its own. Tuning set, group d (docs/trust.md): along the dominant direction the
 * wrong answers' alias optima 0.32-1.19, the right ones' 2.6 and more, except gratings whose
 * bars are all alike (0.93-1.14: refused, rightly); along the fixed directions the wrong
 * answers' 0.80-0.96 (pegboards), the right ones' 1.17 and more (tiles that differ in shade). */
#define ALIAS_RATIO 1.75
#define LATTICE_ALIAS_RATIO 1.07

typedef struct period_candidate {
    double n[2];     /* unit direction in the image */
    double period;   /* full-size px along n; 0: none */
    double corr;     /* the autocorrelation there */
} period_candidate;

/* The match-time scratch (at least 4 REGION_CAPACITY floats): a profile's sums and counts (or,
 * once it is normalised, the prefix sums of its squares), then unit bins as integers (or the
 * normalised profile). */
#define UNIT_BINS_MAX (4 * REGION_CAPACITY - 2 * PROFILE_BINS)
typedef char home__alias_scratch_fits[UNIT_BINS_MAX >= 2 * PROFILE_BINS ? 1 : -1];

/* The first lag from PERIOD_MIN (bins and background px; spacing: px per bin) that is a local
 * maximum of at least PERIOD_CORR of the normalised autocorrelation of the profile (sum /
 * count per bin; bins with fewer than BIN_MIN_COUNT pixels count as zero), in bins, and its
 * correlation; 0 when none. v: scratch for PROFILE_BINS doubles; the prefix sums overwrite
 * sum and count. */
static int profile_period(float *sum, const float *count, int bins, double spacing, double *v,
                          double *corr)
{
    const int px_lag = (int)ceil(PERIOD_MIN / spacing),
              min_lag = PERIOD_MIN > px_lag ? PERIOD_MIN : px_lag;
    double *squares = (double *)(void *)sum; /* squares[i]: v[0]^2 + ... + v[i]^2 */
    double r[3] = {0.0, 0.0, 0.0}, mean = 0.0, total_sq = 0.0;
    int x, lag, max_lag;
    long total = 0;
    for (x = 0; x < bins; x++)
        if (count[x] >= BIN_MIN_COUNT) {
            sum[x] /= count[x];
            mean += sum[x];
            total++;
        }
    if (total < 2) return 0;
    mean /= (double)total;
    for (x = 0; x < bins; x++) v[x] = count[x] >= BIN_MIN_COUNT ? (float)(sum[x] - mean) : 0.0f;
    for (x = 0; x < bins; x++) {
        total_sq += v[x] * v[x];
        squares[x] = total_sq;
    }
    max_lag = (bins - 1) / PERIODS_SEEN;
    for (lag = min_lag - 1; lag <= max_lag + 1; lag++) {
        /* <v[x], v[x + lag]> over x + lag < bins, normalised by both parts' norms */
        const double saa = squares[bins - 1 - lag], sbb = total_sq - squares[lag - 1];
        /* four interleaved partial sums: independent chains the compiler can keep in vector
         * lanes (the same order on every target, so the same result) */
        double part[4] = {0.0, 0.0, 0.0, 0.0}, sab;
        const int n = bins - lag, n4 = n & ~3;
        for (x = 0; x < n4; x += 4) {
            part[0] += v[x] * v[x + lag];
            part[1] += v[x + 1] * v[x + 1 + lag];
            part[2] += v[x + 2] * v[x + 2 + lag];
            part[3] += v[x + 3] * v[x + 3 + lag];
        }
        for (; x < n; x++) part[x & 3] += v[x] * v[x + lag];
        sab = (part[0] + part[1]) + (part[2] + part[3]);
        r[0] = r[1];
        r[1] = r[2];
        r[2] = saa > 0.0 && sbb > 0.0 ? (float)(sab / sqrt(saa * sbb)) : 0.0f;
        /* the first local maximum is known once the lag after it is */
        if (lag - 1 >= min_lag && lag - 1 <= max_lag && r[1] >= PERIOD_CORR && r[1] >= r[0] &&
            r[1] >= r[2]) {
            *corr = r[1];
            return lag - 1;
        }
    }
    return 0;
}

/* The profile of the background a (w x h) along the dominant gradient direction of its
 * structure tensor, into sum and count (unit: scratch for 2 PROFILE_BINS integers): its bins
 * (0 for a flat image), the direction in n and the background px per bin in *spacing. */
static int dominant_profile(const uint8_t *a, int w, int h, int32_t *unit, float *sum,
                            float *count, double *n, double *spacing)
{
    int32_t *isum = unit, *icount = unit + PROFILE_BINS;
    int x, y, bins;
    int64_t sxx = 0, syy = 0, sxy = 0;
    double phi, c, s, span, step;
    /* a row's sums fit 32 bits (at most HOME__BACKGROUND_PIXELS / 8 terms of at most 255^2), so
     * the compiler keeps them in vector lanes */
    for (y = 1; y < h - 1; y++) {
        const uint8_t *p = a + (ptrdiff_t)y * w;
        int32_t rxx = 0, ryy = 0, rxy = 0;
        for (x = 1; x < w - 1; x++) {
            const int gx = p[x + 1] - p[x - 1], gy = p[x + w] - p[x - w];
            rxx += gx * gx;
            ryy += gy * gy;
            rxy += gx * gy;
        }
        sxx += rxx;
        syy += ryy;
        sxy += rxy;
    }
    if (!(sxx + syy > 0)) return 0;
    phi = 0.5 * atan2(2.0 * (double)sxy, (double)(sxx - syy));
    c = cos(phi);
    s = sin(phi);
    span = fabs(c) * (w - 1) + fabs(s) * (h - 1);
    step = span < PROFILE_BINS - 1 ? 1.0 : ceil(span / (PROFILE_BINS - 1));
    bins = (int)(span / step) + 1;
    memset(unit, 0, 2 * PROFILE_BINS * sizeof *unit);
    /* bin of pixel (x, y): its position along n from the corner n points away from, in bins
     * (integer sums: below 2^24, so the same as in floats) */
    for (y = 0; y < h; y++) {
        const uint8_t *p = a + (ptrdiff_t)y * w;
        double u = (c * (0 - 0.5 * (w - 1)) + s * (y - 0.5 * (h - 1)) + 0.5 * span) / step + 0.5;
        const double du = c / step;
        for (x = 0; x < w; x++, u += du) {
            int b = (int)u;
            b = b < 0 ? 0 : b >= bins ? bins - 1 : b;
            isum[b] += p[x];
            icount[b]++;
        }
    }
    for (x = 0; x < PROFILE_BINS; x++) {
        sum[x] = (float)isum[x];
        count[x] = (float)icount[x];
    }
    n[0] = c;
    n[1] = s;
    *spacing = step;
    return bins;
}

/* The profile along a fixed direction: kind 0 x, 1 y, 2 the diagonal (1, 1), 3 (1, -1). Each
 * row adds into a run of unit bins (x, y, x + y or x - y + h - 1: contiguous, so the compiler
 * vectorises it); runs of k of them then make the profile's bins. 0 when the unit bins do
 * not fit the scratch. */
static int fixed_profile(const uint8_t *a, int w, int h, int kind, int32_t *unit, float *sum,
                         float *count, double *n, double *spacing)
{
    const int units = kind == 0 ? w : kind == 1 ? h : w + h - 1;
    const int k = (units + PROFILE_BINS - 1) / PROFILE_BINS, bins = (units + k - 1) / k;
    int x, y, i, bin, in_bin;
    if (units > UNIT_BINS_MAX) return 0;
    memset(unit, 0, (size_t)units * sizeof *unit);
    for (y = 0; y < h; y++) {
        const uint8_t *p = a + (ptrdiff_t)y * w;
        if (kind == 1) {
            int32_t t = 0;
            for (x = 0; x < w; x++) t += p[x];
            unit[y] = t;
        } else {
            int32_t *u = unit + (kind == 0 ? 0 : kind == 2 ? y : h - 1 - y);
            for (x = 0; x < w; x++) u[x] += p[x];
        }
    }
    memset(sum, 0, PROFILE_BINS * sizeof *sum);
    memset(count, 0, PROFILE_BINS * sizeof *count);
    for (i = 0, bin = 0, in_bin = 0; i < units; i++) {
        /* pixels on unit line i: a column, a row, or a diagonal's run; bin = i / k */
        const int len = kind == 0   ? h
                        : kind == 1 ? w
                        : i + 1 < w + h - 1 - i ? i + 1
                                                : w + h - 1 - i;
        const int cap = w < h ? w : h;
        sum[bin] += (float)unit[i];
        count[bin] += (float)(kind < 2 ? len : len < cap ? len : cap);
        if (++in_bin == k) {
            in_bin = 0;
            bin++;
        }
    }
    n[0] = kind == 1 ? 0.0 : kind == 0 ? 1.0 : 0.7071067811865476;
    n[1] = kind == 0 ? 0.0 : kind == 1 ? 1.0 : kind == 2 ? 0.7071067811865476 : -0.7071067811865476;
    *spacing = k * (kind < 2 ? 1.0 : 0.7071067811865476);
    return bins;
}

/* Frame A's candidate periods (full-size px), the dominant direction's first. */
static void find_periods(const home__refine_state *st, int slot, period_candidate *cand)
{
    const uint8_t *a = st->background[slot];
    const int w = st->background_w, h = st->background_h;
    const double sc = (double)((1 << st->background_level) * st->background_factor);
    float *sum = (float *)st->scratch, *count = sum + PROFILE_BINS;
    int32_t *unit = (int32_t *)(void *)(count + PROFILE_BINS);
    int d;
    memset(cand, 0, DIRECTIONS * sizeof *cand);
    if (!a || w < 8 || h < 8) return;
    for (d = 0; d < DIRECTIONS; d++) {
        double spacing = 0.0, corr = 0.0;
        const int bins = d == 0 ? dominant_profile(a, w, h, unit, sum, count, cand[d].n,
                                                   &spacing)
                                : fixed_profile(a, w, h, d - 1, unit, sum, count, cand[d].n,
                                                &spacing);
        const int lag =
            bins ? profile_period(sum, count, bins, spacing, (double *)(void *)unit, &corr) : 0;
        cand[d].period = lag * spacing * sc;
        cand[d].corr = corr;
    }
}

/* The ratio for one period along n: the better of the two optima the refinement reaches from
 * h shifted by it either way, if they are aliases (away from h, near where they started),
 * over h's cost; INFINITY without one. */
static double alias_ratio_along(home_context *ctx, int slot, const double *h, const double *n,
                                double period)
{
    const double cx = 0.5 * (ctx->cfg.width - 1), cy = 0.5 * (ctx->cfg.height - 1);
    double cost[3], alias[2][9];
    const double *hs[3];
    int k, i;
    hs[0] = h;
    for (k = 0; k < 2; k++) {
        /* the optimum the refinement reaches from h after a shift of one period along n in A
         * (where the pattern repeats), either way: the period is known to a background pixel
         * only, and the pattern's alias is a homography of its own */
        const double d = k ? -period : period;
        home_result r;
        memset(&r, 0, sizeof r);
        for (i = 0; i < 9; i++) alias[k][i] = h[i];
        for (i = 0; i < 3; i++) alias[k][3 * i + 2] += d * (n[0] * h[3 * i] + n[1] * h[3 * i + 1]);
        r.sigma_px = INFINITY;
        home__refine_probe(ctx, slot, alias[k], h, 0.5 * period, &r);
        hs[1 + k] = NULL;
        if (r.refined && home__refine_max_corner_distance(cx, cy, r.H, h) > 0.5 * period &&
            home__refine_max_corner_distance(cx, cy, r.H, alias[k]) < 0.5 * period) {
            memcpy(alias[k], r.H, sizeof alias[k]);
            hs[1 + k] = alias[k];
        }
    }
    if (!hs[1] && !hs[2]) return INFINITY;
    home__refine_region_costs(ctx, slot, hs, 3, cost);
    return cost[0] > 0.0 ? (cost[1] < cost[2] ? cost[1] : cost[2]) / cost[0] : INFINITY;
}

int home__refine_aliased(home_context *ctx, int slot, const double *h, double *period)
{
    const home__refine_state *st = &ctx->refine;
    period_candidate cand[DIRECTIONS];
    int tested[TESTED_MAX], n_tested = 0, d, j;
    double ratio[TESTED_MAX];
    *period = 0.0;
    if (st->regions[slot].n < MIN_POINTS) return 0;
    find_periods(st, slot, cand);
    /* the dominant direction first, then the fixed ones by their correlation, leaving out
     * those that repeat a tested one which found an alias (one whose shifts all came back to
     * h was no translation of the pattern: a two-dimensional pattern's along its dominant
     * direction) */
    while (n_tested < TESTED_MAX) {
        int next = -1;
        for (d = 0; d < DIRECTIONS; d++) {
            int near = 0;
            if (!(cand[d].period > 0.0)) continue;
            for (j = 0; j < n_tested; j++)
                near |= tested[j] == d || (isfinite(ratio[j]) &&
                        fabs(cand[d].n[0] * cand[tested[j]].n[0] +
                             cand[d].n[1] * cand[tested[j]].n[1]) > PARALLEL_COS &&
                        fabs(cand[d].period - cand[tested[j]].period) <
                            SAME_PERIOD * cand[tested[j]].period);
            if (near) continue;
            if (next < 0 || (d > 0 && next > 0 && cand[d].corr > cand[next].corr)) next = d;
            if (next == 0) break;
        }
        if (next < 0) return 0;
        tested[n_tested] = next;
        ratio[n_tested] = alias_ratio_along(ctx, slot, h, cand[next].n, cand[next].period);
        if (ratio[n_tested++] <= (next == 0 ? ALIAS_RATIO : LATTICE_ALIAS_RATIO)) {
            *period = cand[next].period;
            return 1;
        }
    }
    return 0;
}
