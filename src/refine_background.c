/* Does the background move as a motion says? A score test on the pixels of both frames' fine
 * backgrounds (quarter size, sixteenths of a grey level) away from texture.
 *
 * Where the background is faint (fog, a flat wall) and fresh noise differs in every frame, the
 * robust costs of the static test (refine_static.c) cannot tell a motion of a few pixels from
 * none: bilinear sampling averages the noise and favours any fractional motion. The residual of
 * the identity, r = B - A, can, without resampling it: if h were the background's motion, r
 * would follow p = -grad(I) . d (I smoothed, d the displacement h gives), and if the camera
 * stood still, r is noise, uncorrelated with p. Standardised by the noise,
 * observed = <r, p> / (sigma |p|) is about N(0, 1) under the identity, and under h about
 * expected = <r_h, p> / (sigma |p|), where r_h is what r would be under h, predicted from each
 * frame alone (A at h^-1(x) minus A(x), paired with B's p; B(x) minus B at h(x), paired with
 * A's): the frames' noises are independent, so the prediction carries no noise bias, and it
 * holds however fine the background's detail. evidence is expected over the spread of its
 * per-pixel terms: how much of the frame it rests on (a few edge pixels next to the mask
 * decide nothing). Gain and bias (exposure) are projected out; residuals far from the median
 * (occlusion) and clipped pixels are left out. Lens shading stays with the sensor, so r never
 * holds it while p and the predictions hold its change under h: where p shows a falloff towards
 * the corners, a second set of statistics has that change projected out too (else a camera
 * moving over a plain wall through a vignetting lens looks still). */
#include "refine_internal.h"
#include <math.h>
#include <string.h>

#define TEXTURE_SCORE 128   /* |gx| + |gy| (2x central differences, sixteenths): texture, */
#define TEXTURE_NEAR 4      /* ... and the pixels within this many of it are not background
                               (moving objects, their edges and what they uncover) */
#define BORDER 3            /* pixels at the border: no gradient of the smoothed image */
#define CLIP_MARGIN 8       /* sixteenths: a pixel this close to 0 or 255 is clipped */
#define REJECT_SIGMAS 4.0   /* residuals farther from the median: occluded or changed */
#define MAD_RADIUS 256      /* |r - median| in sixteenths told apart below this (the rest in
                               one) */
#define MAD_WINDOW (2 * MAD_RADIUS + 16)   /* at least the 512 grey levels of r's median */
#define MIN_SHARE 48        /* fewer than 1/MIN_SHARE of the pixels: no test */
#define SCREEN_STEP 4       /* the screening pass: every fourth row, */
#define SCREEN_EVIDENCE 5.0 /* ... the motion's expected score and evidence there this large, */
#define SCREEN_SHARE 0.667  /* ... and this share of it observed: the background moves */
#define SHADING_MIN_SHARE 1e-6 /* Z projected out where this share of it is not [1, A], */
#define SHADING_MIN_FALLOFF 0.02 /* ... and p holds a falloff of at least this at the corners (a
                                    brightening there is no lens's; tuning set: lens-shaded
                                    frames 0.13-0.44, the raw fog clip's objects -0.02-0) */

/* The background of A and B in sixteenths smoothed by the 5-tap binomial (sigma 1 px) in both
 * directions, edges replicated. Rows, then columns in place with the interior apart from the
 * two pixels at each end, so that the compiler vectorises both. The sums are taken modulo 2^16:
 * sixteenths of a grey level are at most 4080, so 16 times that plus the rounding fits. */
static void smooth(const uint16_t *in, int w, int h, int16_t *out)
{
    int x, y;
    for (y = 0; y < h; y++) {
        const uint16_t *r0 = in + (ptrdiff_t)(y < 2 ? 0 : y - 2) * w;
        const uint16_t *r1 = in + (ptrdiff_t)(y < 1 ? 0 : y - 1) * w;
        const uint16_t *r2 = in + (ptrdiff_t)y * w;
        const uint16_t *r3 = in + (ptrdiff_t)(y + 1 >= h ? h - 1 : y + 1) * w;
        const uint16_t *r4 = in + (ptrdiff_t)(y + 2 >= h ? h - 1 : y + 2) * w;
        int16_t *o = out + (ptrdiff_t)y * w;
        for (x = 0; x < w; x++)
            o[x] = (int16_t)((uint16_t)(r0[x] + 4 * r1[x] + 6 * r2[x] + 4 * r3[x] + r4[x] + 8) >>
                             4);
    }
    for (y = 0; y < h; y++) {
        int16_t *o = out + (ptrdiff_t)y * w;
        /* the two pixels at each end from the replicated edges; the interior is written two
         * pixels early (o[x - 2] is read for the last time when it is written) and moved back */
        const int e0 = o[0], e1 = o[1], e2 = o[2], f0 = o[w - 1], f1 = o[w - 2], f2 = o[w - 3];
        const int first0 = (e0 + 4 * e0 + 6 * e0 + 4 * e1 + e2 + 8) >> 4;
        const int first1 = (e0 + 4 * e0 + 6 * e1 + 4 * e2 + o[3] + 8) >> 4;
        const int last1 = (o[w - 4] + 4 * f2 + 6 * f1 + 4 * f0 + f0 + 8) >> 4;
        const int last0 = (f2 + 4 * f1 + 6 * f0 + 4 * f0 + f0 + 8) >> 4;
        for (x = 2; x < w - 2; x++)
            o[x - 2] = (int16_t)((uint16_t)(o[x - 2] + 4 * o[x - 1] + 6 * o[x] + 4 * o[x + 1] +
                                            o[x + 2] + 8) >>
                                 4);
        for (x = w - 3; x >= 2; x--) o[x] = o[x - 2];
        o[0] = (int16_t)first0;
        o[1] = (int16_t)first1;
        o[w - 2] = (int16_t)last1;
        o[w - 1] = (int16_t)last0;
    }
}

/* The first x in [x, end) with row[x] set, else end: eight bytes at a time through the gaps
 * (the background is sparse in textured frames) */
static int next_set(const uint8_t *row, int x, int end)
{
    while (x + 8 <= end) {
        uint64_t v;
        memcpy(&v, row + x, sizeof v);
        if (v) break;
        x += 8;
    }
    while (x < end && !row[x]) x++;
    return x;
}

static uint16_t absdiff16(uint16_t p, uint16_t q)
{
    return (uint16_t)(p > q ? p - q : q - p);
}

/* Which pixels are background: no texture in A or B within TEXTURE_NEAR, neither clipped, not at
 * the border. tmp: w x h bytes. Each pass is a loop over a row without branches (the compiler
 * vectorises them): texture into mask, its dilation along the rows into tmp, along the columns
 * back into mask. */
static void find_background(const uint16_t *a, const uint16_t *b, int w, int h, uint8_t *tmp,
                            uint8_t *mask)
{
    int x, y, k;
    memset(mask, 0, (size_t)w * (size_t)h);
    for (y = 1; y < h - 1; y++) {
        const uint16_t *ra = a + (ptrdiff_t)y * w, *rb = b + (ptrdiff_t)y * w;
        uint8_t *o = mask + (ptrdiff_t)y * w;
        for (x = 1; x < w - 1; x++) {
            /* in 16-bit lanes: sixteenths up to 4080, two differences' sum below 2^13 */
            const uint16_t sa = (uint16_t)(absdiff16(ra[x + 1], ra[x - 1]) +
                                           absdiff16(ra[x + w], ra[x - w]));
            const uint16_t sb = (uint16_t)(absdiff16(rb[x + 1], rb[x - 1]) +
                                           absdiff16(rb[x + w], rb[x - w]));
            o[x] = (uint8_t)((sa >= TEXTURE_SCORE) | (sb >= TEXTURE_SCORE));
        }
    }
    for (y = 0; y < h; y++) {
        const uint8_t *in = mask + (ptrdiff_t)y * w;
        uint8_t *out = tmp + (ptrdiff_t)y * w;
        memcpy(out, in, (size_t)w);
        for (k = 1; k <= TEXTURE_NEAR && k < w; k++) {
            for (x = 0; x < w - k; x++) out[x] |= in[x + k];
            for (x = k; x < w; x++) out[x] |= in[x - k];
        }
    }
    for (y = 0; y < h; y++) {
        uint8_t *out = mask + (ptrdiff_t)y * w;
        const uint16_t *ra = a + (ptrdiff_t)y * w, *rb = b + (ptrdiff_t)y * w;
        memset(out, 0, (size_t)w);
        if (y < BORDER || y >= h - BORDER) continue;
        for (k = y - TEXTURE_NEAR; k <= y + TEXTURE_NEAR; k++) {
            const uint8_t *in = tmp + (ptrdiff_t)k * w;
            if (k < 0 || k >= h) continue;
            for (x = 0; x < w; x++) out[x] |= in[x];
        }
        /* clipped pixels hold no noise and no motion */
        for (x = BORDER; x < w - BORDER; x++)
            out[x] = (uint8_t)(!out[x] & (ra[x] > CLIP_MARGIN) & (rb[x] > CLIP_MARGIN) &
                               (ra[x] < 4080 - CLIP_MARGIN) & (rb[x] < 4080 - CLIP_MARGIN));
        for (x = 0; x < BORDER && x < w; x++) out[x] = out[w - 1 - x] = 0;
    }
}

/* Bilinear sample (sixteenths) of a w x h image at (u, v), within half a pixel of [0, w-1] x
 * [0, h-1] (the clamps hold the reads inside the image). */
static double sample16(const uint16_t *img, int w, int h, double u, double v)
{
    int x0 = (int)u, y0 = (int)v;
    double fx, fy;
    const uint16_t *p;
    if (x0 > w - 2) x0 = w - 2;
    if (y0 > h - 2) y0 = h - 2;
    fx = u - x0;
    fy = v - y0;
    p = img + (ptrdiff_t)y0 * w + x0;
    {
        const double top = p[0] + fx * (p[1] - p[0]), bottom = p[w] + fx * (p[w + 1] - p[w]);
        return top + fy * (bottom - top);
    }
}

/* The inverse of the 3x3 matrix m into inv; 0 when singular. */
static int invert3(const double *m, double *inv)
{
    double c[9], det;
    int i, j;
    home__cofactors3(m, c);
    det = m[0] * c[0] + m[1] * c[1] + m[2] * c[2];
    if (!(fabs(det) > 1e-12)) return 0;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) inv[3 * i + j] = c[3 * j + i] / det;
    return 1;
}

/* The columns [*lo, *hi] of row y whose image under m lies in front of the camera and inside
 * [0, w-1] x [0, h-1]: u and v are monotonic along a row where the denominator keeps its sign,
 * so each bound is a linear inequality in x (a x + b >= 0). Empty when *lo > *hi. */
static void row_span(const double *m, int w, int h, int y, int *lo, int *hi)
{
    const double num_u = m[1] * y + m[2], num_v = m[4] * y + m[5], den = m[7] * y + m[8];
    /* a x + b >= 0 for: den > 0, u >= 0, u <= w - 1, v >= 0, v <= h - 1 */
    const double a[5] = {m[6], m[0], (w - 1) * m[6] - m[0], m[3], (h - 1) * m[6] - m[3]};
    const double b[5] = {den - 1e-9, num_u, (w - 1) * den - num_u, num_v, (h - 1) * den - num_v};
    double l = *lo, r = *hi;
    int i, empty = 0;
    for (i = 0; i < 5; i++) {
        if (a[i] > 0.0) {
            const double t = ceil(-b[i] / a[i]);
            if (t > l) l = t;
        } else if (a[i] < 0.0) {
            const double t = floor(-b[i] / a[i]);
            if (t < r) r = t;
        } else if (!(b[i] >= 0.0)) {
            empty = 1;
        }
    }
    /* l and r stay within the span given, or cross it (NaN: empty too) */
    if (empty || !(l <= r)) {
        *hi = *lo - 1;
        return;
    }
    *lo = (int)l;
    *hi = (int)r;
}

/* Sums over the background pixels for inner products with [1, A, Z] projected out: Z is the
 * change lens shading makes under h (below). */
enum { V_R, V_P, V_PA, V_PB, V_QA, V_QB, V_GX, V_GY, N_V };
typedef struct score_sums {
    double n, a, aa, z, zz, az;
    double s[N_V], sa[N_V], sz[N_V]; /* sum of v, of v * A, of v * Z */
    double rr, rp, pp, qapb, qbpa;  /* the inner products used */
    double xx, xy, yy, rx, ry;      /* ... those of the background's own translation, */
    double dd;                      /* and h's squared displacements */
    double e, ee;                   /* the expected's terms: sum, sum of squares */
    int shading;                    /* Z projected out */
} score_sums;

/* <u, v> with the constant and A projected out, from the sums of u, u A, v, v A (n A A - (sum
 * A)^2 > 0) */
static double without_constant_and_a(const score_sums *k, double uv, double su, double sua,
                                     double sv, double sva)
{
    const double det = k->n * k->aa - k->a * k->a;
    return uv - (su * (k->aa * sv - k->a * sva) + sua * (k->n * sva - k->a * sv)) / det;
}

/* <u, v> with the constant, A and Z projected out (Z only where it is not (nearly) a
 * combination of the others: h close to the identity) */
static double projected(const score_sums *k, double uv, int u, int v)
{
    const double det = k->n * k->aa - k->a * k->a;
    const double g[9] = {k->n, k->a, k->z, k->a, k->aa, k->az, k->z, k->az, k->zz};
    const double su[3] = {k->s[u], k->sa[u], k->sz[u]}, sv[3] = {k->s[v], k->sa[v], k->sz[v]};
    double c[9], det3;
    int i, j;
    if (!(det > 0.0)) return uv - k->s[u] * k->s[v] / k->n;
    home__cofactors3(g, c);
    det3 = g[0] * c[0] + g[1] * c[1] + g[2] * c[2];
    /* Z's part beyond [1, A] (det3 / det) against its size */
    if (!k->shading || !(det3 > SHADING_MIN_SHARE * det * k->zz))
        return without_constant_and_a(k, uv, k->s[u], k->sa[u], k->s[v], k->sa[v]);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) uv -= su[i] * c[3 * j + i] * sv[j] / det3;
    return uv;
}

/* The background pixels (mask) both h (m, background pixels) and its inverse (m_inv) keep
 * inside the frame, their count, and the median and spread of r = B - A there (sixteenths).
 * 0 when there are too few. */
static long prepare(const home__refine_state *st, const uint16_t *a, const uint16_t *b,
                    const double *h, double *m, double *m_inv, double *median, double *mad)
{
    const int w = st->background_w, hh = st->background_h;
    uint8_t *mask = st->flat;
    int hist[MAD_WINDOW], x, y, i, j, f, c, t, half, cum, lo;
    long n = 0;
    if (!st->levels || w < 2 * BORDER + 2 || hh < 2 * BORDER + 2) return 0;
    home__refine_background_matrix(st, h, m);
    if (!invert3(m, m_inv)) return 0;
    find_background(a, b, w, hh, (uint8_t *)(void *)st->sampled, mask);
    /* the pixels h and its inverse keep inside the frame (the predictions need both), and the
     * histogram of r = B - A there (sixteenths, within +-4095) by grey levels: for its median,
     * the grey level, then the sixteenth */
    memset(hist, 0, sizeof hist);
    for (y = BORDER; y < hh - BORDER; y++) {
        uint8_t *row = mask + (ptrdiff_t)y * w;
        int lo = BORDER, hi = w - BORDER - 1;
        row_span(m, w, hh, y, &lo, &hi);
        row_span(m_inv, w, hh, y, &lo, &hi);
        if (lo > hi) {
            memset(row, 0, (size_t)w);
            continue;
        }
        memset(row, 0, (size_t)lo);
        memset(row + hi + 1, 0, (size_t)(w - hi - 1));
        for (x = next_set(row, lo, hi + 1); x <= hi; x = next_set(row, x + 1, hi + 1)) {
            const ptrdiff_t p = (ptrdiff_t)y * w + x;
            n++;
            hist[((int)b[p] - (int)a[p] + 4096) >> 4]++;
        }
    }
    if (n * MIN_SHARE < (long)w * hh) return 0;
    half = (int)(n / 2);
    for (j = 0, cum = 0; j < 511 && cum + hist[j] <= half; j++) cum += hist[j];
    /* then r by sixteenths from MAD_RADIUS below that grey level to MAD_RADIUS above it: the
     * median's sixteenth, and about the median |r - median| out to MAD_RADIUS for the spread */
    lo = 16 * j - 4096 - MAD_RADIUS;
    memset(hist, 0, sizeof hist);
    for (i = 0; i < w * hh; i++) {
        const unsigned v = (unsigned)((int)b[i] - (int)a[i] - lo);
        if (mask[i] && v < MAD_WINDOW) hist[v]++;
    }
    for (f = 0; f < 15 && cum + hist[MAD_RADIUS + f] <= half; f++) cum += hist[MAD_RADIUS + f];
    *median = 16 * j + f - 4096;
    c = MAD_RADIUS + f;
    for (t = 0, cum = 0; t < MAD_RADIUS; t++) {
        const int count = hist[c + t] + (t ? hist[c - t] : 0);
        if (cum + count > half) break;
        cum += count;
    }
    *mad = 1.4826 * (t + 0.25);
    if (*mad < 1.0) *mad = 1.0;
    return n;
}

/* The sums over the background rows first, first + step, ... (mask from prepare(); sa, sb:
 * both frames smoothed; r outside [lo, hi] left out) added into k. */
static void accumulate(const home__refine_state *st, const uint16_t *a, const uint16_t *b,
                       const int16_t *sa, const int16_t *sb, const double *m,
                       const double *m_inv, double lo, double hi, int first, int step,
                       score_sums *k)
{
    const int w = st->background_w, hh = st->background_h;
    const uint8_t *mask = st->flat;
    const double cx = 0.5 * (w - 1), cy = 0.5 * (hh - 1), inv_r2 = 1.0 / (cx * cx + cy * cy);
    int x, y, j;
    for (y = first; y < hh - BORDER; y += step) {
        /* both maps along the row: numerators and denominators linear in x */
        const double nub = m[1] * y + m[2], nvb = m[4] * y + m[5], db = m[7] * y + m[8];
        const double nua = m_inv[1] * y + m_inv[2], nva = m_inv[4] * y + m_inv[5];
        const double da = m_inv[7] * y + m_inv[8];
        for (x = next_set(mask + (ptrdiff_t)y * w, BORDER, w - BORDER); x < w - BORDER;
             x = next_set(mask + (ptrdiff_t)y * w, x + 1, w - BORDER)) {
            const ptrdiff_t p = (ptrdiff_t)y * w + x;
            double dx, dy, v[N_V], av, zv, ua, va, ub, vb, inv;
            v[V_R] = (int)b[p] - (int)a[p];
            if (v[V_R] < lo || v[V_R] > hi) continue;
            inv = 1.0 / (m[6] * x + db);
            ub = (m[0] * x + nub) * inv;
            vb = (m[3] * x + nvb) * inv;
            inv = 1.0 / (m_inv[6] * x + da);
            ua = (m_inv[0] * x + nua) * inv;
            va = (m_inv[3] * x + nva) * inv;
            /* the span's inequalities in floating point: far off only for extreme matrices
             * (fuzz_api), whose rounding the division does not share */
            if (!(ua > -0.5 && ua < w - 0.5 && va > -0.5 && va < hh - 0.5 && ub > -0.5 &&
                  ub < w - 0.5 && vb > -0.5 && vb < hh - 0.5))
                continue;
            dx = ub - x;
            dy = vb - y;
            /* the prediction p = -grad . d from A and from B smoothed (central differences) */
            v[V_PA] = -0.5 * ((sa[p + 1] - sa[p - 1]) * dx + (sa[p + w] - sa[p - w]) * dy);
            v[V_PB] = -0.5 * ((sb[p + 1] - sb[p - 1]) * dx + (sb[p + w] - sb[p - w]) * dy);
            /* what r would be under h, from A alone (A at h^-1(x) - A(x)) and from B alone
             * (B(x) - B at h(x)): exact where the background's detail is finer than d */
            v[V_QA] = sample16(a, w, hh, ua, va) - a[p];
            v[V_QB] = b[p] - sample16(b, w, hh, ub, vb);
            v[V_P] = 0.5 * (v[V_PA] + v[V_PB]);
            v[V_GX] = 0.25 * ((sa[p + 1] - sa[p - 1]) + (sb[p + 1] - sb[p - 1]));
            v[V_GY] = 0.25 * ((sa[p + w] - sa[p - w]) + (sb[p + w] - sb[p - w]));
            av = a[p];
            /* lens shading stays with the sensor: a falloff s = 1 - kappa rho^2 (rho from the
             * centre) changes r under h by about kappa A (rho^2(x + d) - rho^2(x)), which p and
             * the predictions hold and r does not */
            zv = av * ((x - cx) * dx + (y - cy) * dy) * inv_r2;
            k->n += 1.0;
            k->a += av;
            k->aa += av * av;
            k->z += zv;
            k->zz += zv * zv;
            k->az += av * zv;
            for (j = 0; j < N_V; j++) {
                k->s[j] += v[j];
                k->sa[j] += v[j] * av;
                k->sz[j] += v[j] * zv;
            }
            k->rr += v[V_R] * v[V_R];
            k->rp += v[V_R] * v[V_P];
            k->pp += v[V_P] * v[V_P];
            k->qapb += v[V_QA] * v[V_PB];
            k->qbpa += v[V_QB] * v[V_PA];
            k->xx += v[V_GX] * v[V_GX];
            k->xy += v[V_GX] * v[V_GY];
            k->yy += v[V_GY] * v[V_GY];
            k->rx += v[V_R] * v[V_GX];
            k->ry += v[V_R] * v[V_GY];
            k->dd += dx * dx + dy * dy;
            {
                const double t = 0.5 * (v[V_QA] * v[V_PB] + v[V_QB] * v[V_PA]);
                k->e += t;
                k->ee += t * t;
            }
        }
    }
}

/* The falloff kappa (s = 1 - kappa rho^2) that p's Z part beyond [1, A] implies: p = -grad A . d
 * holds 2 kappa Z of it */
static double shading_falloff(const score_sums *k)
{
    double pz = k->sz[V_P], zz = k->zz;
    if (k->n * k->aa - k->a * k->a > 0.0) {
        pz = without_constant_and_a(k, pz, k->s[V_P], k->sa[V_P], k->z, k->az);
        zz = without_constant_and_a(k, zz, k->z, k->az, k->z, k->az);
    }
    return zz > 0.0 ? 0.5 * pz / zz : 0.0;
}

/* k into the test's statistics (home__refine_background_score's); 0 when they are undefined */
static int finish(score_sums *k, double *observed, double *expected, double *evidence,
                  double *own_motion)
{
    double e_raw, spread, sigma2, norm, rp, pp, rr;
    k->shading = k->shading && shading_falloff(k) >= SHADING_MIN_FALLOFF;
    rp = projected(k, k->rp, V_R, V_P);
    pp = projected(k, k->pp, V_P, V_P);
    rr = projected(k, k->rr, V_R, V_R);
    if (!(pp > 0.0) || !(k->n > 3.0)) return 0;
    /* the noise: what r keeps after the constant, A and p */
    sigma2 = (rr - rp * rp / pp) / (k->n - 3.0);
    if (!(sigma2 > 0.0)) return 0;
    norm = sqrt(sigma2 * pp);
    *observed = rp / norm;
    e_raw = 0.5 * (projected(k, k->qapb, V_QA, V_PB) + projected(k, k->qbpa, V_QB, V_PA));
    *expected = e_raw / norm;
    spread = k->ee - k->e * k->e / k->n;
    *evidence = spread > 0.0 ? e_raw / sqrt(spread) : 0.0;
    /* the background's own translation g: least squares of r = -grad . g, against h's RMS
     * displacement there */
    *own_motion = 0.0;
    {
        const double xx = projected(k, k->xx, V_GX, V_GX), xy = projected(k, k->xy, V_GX, V_GY);
        const double yy = projected(k, k->yy, V_GY, V_GY), rx = projected(k, k->rx, V_R, V_GX);
        const double ry = projected(k, k->ry, V_R, V_GY), det = xx * yy - xy * xy;
        if (det > 0.0 && k->dd > 0.0)
            *own_motion = hypot(yy * rx - xy * ry, xx * ry - xy * rx) / det / sqrt(k->dd / k->n);
    }
    return 1;
}

/* finish() of a copy of k, with or without the falloff's change projected out, into
 * stats[4] (observed, expected, evidence, own motion; all 0 where undefined). */
static int finish_as(const score_sums *k, int shading, double *stats)
{
    score_sums t = *k;
    t.shading = shading;
    if (finish(&t, &stats[0], &stats[1], &stats[2], &stats[3])) return 1;
    memset(stats, 0, 4 * sizeof *stats);
    return 0;
}

/* The screening pass's verdict: the background already shows most of the motion there. */
static int screen_moves(const double *stats)
{
    return stats[1] >= SCREEN_EVIDENCE && stats[2] >= SCREEN_EVIDENCE &&
           stats[0] >= SCREEN_SHARE * stats[1];
}

int home__refine_background_score(home_context *ctx, const uint16_t *a, const uint16_t *b,
                                  const double *h, double *stats, double *shaded)
{
    const home__refine_state *st = &ctx->refine;
    const int w = st->background_w, hh = st->background_h;
    int16_t *sa = st->sampled, *sb = st->smoothed_b;
    int first, shaded_screened = 0;
    double m[9], m_inv[9], median, mad, lo, hi;
    score_sums k;
    memset(stats, 0, 4 * sizeof *stats);
    memset(shaded, 0, 4 * sizeof *shaded);
    if (!prepare(st, a, b, h, m, m_inv, &median, &mad)) return 0;
    lo = median - REJECT_SIGMAS * mad;
    hi = median + REJECT_SIGMAS * mad;
    smooth(a, w, hh, sa);
    smooth(b, w, hh, sb);
    memset(&k, 0, sizeof k);
    /* every SCREEN_STEP-th row first: a background that already shows most of the motion
     * there, on evidence of its own, moves (the full test could only agree but by chance);
     * the same sums serve both tests */
    accumulate(st, a, b, sa, sb, m, m_inv, lo, hi, BORDER, SCREEN_STEP, &k);
    if (k.n * MIN_SHARE * SCREEN_STEP >= (double)w * hh) {
        shaded_screened = finish_as(&k, 1, shaded) && screen_moves(shaded);
        if (finish_as(&k, 0, stats) && screen_moves(stats)) return 1;
    }
    for (first = BORDER + 1; first < BORDER + SCREEN_STEP; first++)
        accumulate(st, a, b, sa, sb, m, m_inv, lo, hi, first, SCREEN_STEP, &k);
    memset(stats, 0, 4 * sizeof *stats);
    if (!shaded_screened) memset(shaded, 0, 4 * sizeof *shaded);
    if (k.n * MIN_SHARE < (double)w * hh) return 0;
    if (!shaded_screened) finish_as(&k, 1, shaded);
    return finish_as(&k, 0, stats);
}
