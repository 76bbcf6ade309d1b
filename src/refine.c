/* Sub-pixel photometric refinement of HOME's homography (issue 8).
 *
 * Method: inverse-compositional Lucas-Kanade (Baker & Matthews) of the 8 homography parameters on
 * a uint8 pyramid (3x3 binomial blur at full resolution, then 2x2 means), coarse to fine,
 * started from HOME's estimate. The template is frame A: its
 * points and gradients are chosen once per frame when it is extracted, so in video a frame costs
 * one pyramid, one point selection and a few warps of the new frame. Photometric invariance: a
 * gain and bias (alpha * B + beta ~ A) re-fitted by weighted least squares every iteration.
 * Robustness: IRLS with Cauchy weights at 2.385 sigma, sigma = 1.4826 * median |residual|, so
 * occluders and moving objects lose their pull. Every level has a fixed iteration cap.
 *
 * Template points: per level, the pixel of largest |gx| + |gy| in each block (4x4, 2x2 at the
 * third level) whose score clears a camera-noise floor, strongest first (evenly spread) up to
 * refine_points >> level (at most HOME_REFINE_MAX_POINTS). Flat regions contribute nothing to
 * LK but time.
 *
 * The estimate ends at level refine_finest_level (0: full resolution), or at the finest coarser
 * level with at least 512 template points when that one has fewer (faint texture leaves few
 * points above the noise floor at full resolution).
 *
 * Safeguards (result.refine_status): the refined H replaces HOME's only if that finest level
 * converged within its cap, the estimate is well conditioned (the corners' standard deviation
 * predicted by the Fisher information, and the disagreement of two interleaved halves of the
 * points, which also sees noise in the template's own gradients, both under max(0.5 px,
 * max_sigma_px)), and the robust photometric error over the points both warps keep went down.
 * The refined estimate then goes through model selection (src/model.c), which gives its
 * sigma_px; home__refine_apply() weighs it against HOME's (the rule in home.h at home_match).
 * Noise-only templates never converge.
 *
 * Coordinates: normalised u = (x - cx) / f, v = (y - cy) / f with cx, cy the image centre and
 * f half the longer side, so the 8 parameters are O(1) at every level. Level l pixel x_l sits at
 * full-resolution x = 2^l x_l + (2^l - 1) / 2. */
#include "home_internal.h"
#include <math.h>
#include <string.h>

#define LANES HOME__REFINE_LANES
#define N_ACC HOME__REFINE_ACC
#define HIST_BINS 512       /* |residual| histogram, 1/8 grey level per bin */
#define CAUCHY_K 2.385     /* 95 % efficiency at Gaussian noise */
#define SIGMA_FLOOR 0.5     /* grey levels: the residual scale never collapses below this */
#define MIN_POINTS 64       /* fewer usable template points at a level: textureless, decline */
#define FINEST_MIN_POINTS 512 /* the level the estimate ends at needs this many points, else the
                                 next coarser one is the finest (faint texture: less noise there) */
#define STEP_EPS_PX 0.02    /* convergence: largest corner update, full-resolution px */
#define STEP_NOISE_SHARE 0.25 /* ... or at the finest level, this share of the worst corner's
                                 predicted standard deviation */
#define NOISE_CHECK_PX 0.5  /* (that prediction is made only for steps below this) */
#define MAX_CORNER_STD_PX 0.5 /* worst corner's standard deviation (Fisher, or split-half) above
                                 this, or above max_sigma_px: ill conditioned */
#define REFINE_SIGMA_SCALE 1.5 /* predicted errors are the Fisher covariance's times this
                                  (calibrated on the evaluation's tuning set: neighbouring
                                  template points do not carry independent noise) */
#define REGIONS_X 8          /* the identity test's grid of regions (identity_region_share) */
#define REGIONS_Y 6
#define REGION_TOP 8         /* the identity test's points per region: the strongest blocks */
#define REGION_POINTS 3      /* a region with fewer points does not vote */
#define STATIC_SHARE 0.5     /* the identity replaces a motion that wins fewer regions */
#define TWO_MOTIONS_SHARE 0.1 /* ... and a motion the identity contests this much is not ok */
#define DECISIVE_RATIO 0.5   /* a region votes when its better cost is at most this share of the
                                other's */
#define DECISIVE_GREY 1.0    /* ... and they differ by more than this (grey levels) per point */
#define IDENTITY_SIGMAS 2.0  /* a motion within this many predicted errors of the identity is it */
#define MIN_VOTES 6          /* fewer voting regions: no decision (share 0) */
#define VOUCH_ZNCC 0.9       /* a refined estimate vouches for itself at this correlation */
#define VOUCH_SIGMA_SHARE 0.4 /* ... and a predicted error within this share of max_sigma_px:
                                 without HOME's confirmation, the tuning set's wrong refined
                                 answers (few edges) predicted 0.44-0.66 px, 95 % of the right
                                 ones less than 0.4 */
#define VOUCH_SHARE 0.9      /* ... and, against HOME's estimate or with none, with this share
                                of its points within 3 robust sigmas */

/* Block side of the point selection per level: 4x4, and 2x2 at quarter resolution so that level
 * still offers more candidates than its capacity. */
static int block_side(int level) { return level == 2 ? 2 : 4; }

/* Selection floor of the score |gx| + |gy| (2x central differences of the blurred level): above
 * the best of a block of pure camera noise up to sigma ~3 grey levels (the blur and each 2x2
 * average shrink the noise's score), so flat regions give no points and a textureless frame
 * gives too few to refine. */
static int score_floor(int level) { return level == 0 ? 8 : level == 1 ? 4 : 3; }

static int level_capacity(const home_config *cfg, int level)
{
    int c = cfg->refine_points >> level;
    c = c < 64 ? 64 : c;
    return (c + LANES - 1) & ~(LANES - 1);
}

/* ---------------------------------------------------------------------------------------------
 * Configuration and arena layout */

void home__refine_defaults(home_config *cfg)
{
    cfg->refine_levels = HOME_REFINE_MAX_LEVELS < 3 ? HOME_REFINE_MAX_LEVELS : 3;
    cfg->refine_iterations = 10;
    cfg->refine_trust_px = 6.0f;
    cfg->refine_points = HOME_REFINE_MAX_POINTS;
    cfg->refine_finest_level = 0;
}

int home__refine_validate(const home_config *cfg)
{
    if (cfg->refine_levels == 0) return HOME_OK; /* off: the other fields are ignored */
    if (cfg->refine_levels < 0 || cfg->refine_levels > HOME_REFINE_MAX_LEVELS) return HOME_E_CONFIG;
    if (cfg->refine_iterations < 1 || cfg->refine_iterations > HOME_REFINE_MAX_ITERS)
        return HOME_E_CONFIG;
    if (cfg->refine_points < 64 || cfg->refine_points > HOME_REFINE_MAX_POINTS) return HOME_E_CONFIG;
    if (cfg->refine_finest_level < 0 || cfg->refine_finest_level >= cfg->refine_levels)
        return HOME_E_CONFIG;
    if (!(isfinite(cfg->refine_trust_px) && cfg->refine_trust_px >= 0.05f &&
          cfg->refine_trust_px <= 256.0f))
        return HOME_E_CONFIG;
    return HOME_OK;
}

/* Levels actually used: the coarsest must keep at least 16 px a side. */
static int levels_for(const home_config *cfg)
{
    int l = cfg->refine_levels;
    while (l > 1 && ((cfg->width >> (l - 1)) < 16 || (cfg->height >> (l - 1)) < 16)) l--;
    return l;
}

static size_t align64(size_t n) { return (n + 63u) & ~(size_t)63u; }

static size_t blocks_at(const home_config *cfg, int level)
{
    size_t b = (size_t)block_side(level);
    size_t w = (size_t)(cfg->width >> level), h = (size_t)(cfg->height >> level);
    return ((w + b - 1) / b) * ((h + b - 1) / b);
}

static int finest_for(const home_config *cfg)
{
    const int levels = levels_for(cfg);
    return cfg->refine_finest_level < levels ? cfg->refine_finest_level : levels - 1;
}

/* The finest pyramid level computed: 0, or 1 when the refinement ends above full size (level 1
 * is then the blur of the 2x2-mean image, not the 2x2 mean of the blurred image: no full-size
 * pass but one 2x2 mean). */
static int base_for(const home_config *cfg) { return finest_for(cfg) > 0 ? 1 : 0; }

#define REGION_CAPACITY (REGIONS_X * REGIONS_Y * REGION_TOP)

/* Points a match-time scratch buffer holds: the finest template's, or the region points. */
static int match_capacity(const home_config *cfg)
{
    const int c = level_capacity(cfg, finest_for(cfg));
    return c > REGION_CAPACITY ? c : REGION_CAPACITY;
}

/* Scratch: per-point floats at match time (two warps, residuals, weights), or at extraction
 * time a row of int16 for the blur, then the half-size image (base level 1) or, later, the
 * block cells. */
static size_t scratch_bytes(const home_config *cfg)
{
    size_t match = 4 * (size_t)match_capacity(cfg) * sizeof(float), sel = 0;
    int l;
    for (l = finest_for(cfg); l < levels_for(cfg); l++) {
        size_t s = blocks_at(cfg, l) * sizeof(uint16_t);
        if (s > sel) sel = s;
    }
    if (base_for(cfg)) {
        size_t half = (size_t)(cfg->width >> 1) * (size_t)(cfg->height >> 1);
        if (half > sel) sel = half;
    }
    sel += align64((size_t)cfg->width * sizeof(int16_t));
    return match > sel ? match : sel;
}

size_t home__refine_bytes(const home_config *cfg)
{
    size_t total = 0;
    int l, n = cfg->refine_levels ? levels_for(cfg) : 0;
    for (l = n ? base_for(cfg) : 0; l < n; l++) {
        total += align64((size_t)(cfg->width >> l) * (size_t)(cfg->height >> l) + HOME__REFINE_IMAGE_SLACK);
        if (l >= finest_for(cfg)) /* no template below the finest level */
            total += 2 * 5 * align64((size_t)(level_capacity(cfg, l) + LANES) * sizeof(int16_t));
    }
    if (n) total += align64(scratch_bytes(cfg)) +
                    2 * 3 * align64((size_t)(REGION_CAPACITY + LANES) * sizeof(int16_t));
    return total;
}

void home__refine_init(home_context *ctx, unsigned char *block)
{
    home__refine_state *st = &ctx->refine;
    int l, s;
    memset(st, 0, sizeof *st);
    st->levels = ctx->cfg.refine_levels ? levels_for(&ctx->cfg) : 0;
    st->finest_level = st->levels ? finest_for(&ctx->cfg) : 0;
    st->base_level = st->levels ? base_for(&ctx->cfg) : 0;
    /* half size at most: a faint background's gradient is above the floor there, and the blur
     * and the 2x2 mean have halved the noise */
    st->region_level = st->finest_level < 1 && st->levels > 1 ? 1 : st->finest_level;
    st->rk = home__refine_kernels_for(ctx->cfg.simd);
    if (!st->rk) st->rk = &home__refine_kernels_scalar; /* every backend gives the same result */
    for (l = 0; l < st->levels; l++) {
        st->w[l] = ctx->cfg.width >> l;
        st->h[l] = ctx->cfg.height >> l;
        if (l < st->base_level) continue; /* never computed: no pixels */
        st->pyr[l] = block;
        block += align64((size_t)st->w[l] * (size_t)st->h[l] + HOME__REFINE_IMAGE_SLACK);
        for (s = 0; s < 2 && l >= st->finest_level; s++) {
            home__refine_points *p = &st->tpl[s][l];
            size_t bytes = align64((size_t)(level_capacity(&ctx->cfg, l) + LANES) * sizeof(int16_t));
            p->capacity = level_capacity(&ctx->cfg, l);
            p->x = (int16_t *)(void *)block; block += bytes;
            p->y = (int16_t *)(void *)block; block += bytes;
            p->t = (int16_t *)(void *)block; block += bytes;
            p->gx = (int16_t *)(void *)block; block += bytes;
            p->gy = (int16_t *)(void *)block; block += bytes;
        }
    }
    for (s = 0; s < 2 && st->levels; s++) {
        home__refine_points *p = &st->regions[s];
        const size_t bytes = align64((size_t)(REGION_CAPACITY + LANES) * sizeof(int16_t));
        p->capacity = REGION_CAPACITY;
        p->x = (int16_t *)(void *)block; block += bytes;
        p->y = (int16_t *)(void *)block; block += bytes;
        p->t = (int16_t *)(void *)block; block += bytes;
    }
    st->scratch = st->levels ? (void *)block : NULL;
}

/* ---------------------------------------------------------------------------------------------
 * Per-frame snapshot: pyramid and template points */

static uint32_t hash_bytes(const uint8_t *p, size_t n)
{
    uint32_t h = 2166136261u;
    size_t i;
    for (i = 0; i + 4 <= n; i += 4) {
        uint32_t v = (uint32_t)p[i] | (uint32_t)p[i + 1] << 8 | (uint32_t)p[i + 2] << 16 |
                     (uint32_t)p[i + 3] << 24;
        h = (h ^ v) * 16777619u;
        h ^= h >> 15;
    }
    for (; i < n; i++) h = (h ^ p[i]) * 16777619u;
    return h ? h : 1u;
}

/* Pick the strongest-gradient pixel of every block, keep those above the level's floor,
 * strongest first (score bins, then scan order) up to the capacity. keys: w int16; cells: one
 * uint16 per block (bit 15 set: a candidate, score bin << 4 | offset in the block). */
static void select_points(const home__refine_kernels *rk, const uint8_t *img, int w, int h,
                          int level, int16_t *keys, uint16_t *cells, home__refine_points *out)
{
    const int b = block_side(level);
    const int bw = (w + b - 1) / b, bh = (h + b - 1) / b;
    const int log2b = b == 4 ? 2 : b == 2 ? 1 : 0;
    int hist[256], hist4[4][256], bx, by, x, y, dy, bin, quota, n = 0, cut, above, i, spread;
    const int floor_bin = score_floor(level) / 2;
    memset(hist4, 0, sizeof hist4);
    /* pass 1: best key (score << 4 | offset) of every block, histogram of score bins */
    for (by = 0; by < bh; by++) {
        int rows = 0;
        for (dy = 0; dy < b; dy++) {
            y = by * b + dy;
            if (y < 1 || y > h - 2) continue;
            rk->select_keys(img + (ptrdiff_t)y * w, w, w, b, dy, keys, rows++ > 0);
        }
        if (!rows) memset(keys, 0, (size_t)w * sizeof *keys);
        rk->block_max(keys, w / b, b, cells + by * bw);    /* whole blocks */
        for (bx = w / b; bx < bw; bx++) {                   /* a partial block at the right edge */
            int best = 0;
            for (x = bx * b; x < w; x++) best = keys[x] > best ? keys[x] : best;
            cells[by * bw + bx] = (uint16_t)best;
        }
        /* bin = score / 2 (keys < 2^13: at most 255); four interleaved histograms: flat runs
         * hit one bin, and one counter would serialise on its own increments */
        for (bx = 0; bx < bw; bx++) hist4[bx & 3][cells[by * bw + bx] >> 5]++;
    }
    /* zeroed first: gcc's -fanalyzer (make lint) cannot tell that the loop writes every bin */
    memset(hist, 0, sizeof hist);
    for (i = 0; i < 256; i++) hist[i] += hist4[0][i] + hist4[1][i] + hist4[2][i] + hist4[3][i];
    /* the lowest bin that still fits the capacity, not below the floor */
    above = 0;
    for (cut = 255; cut > floor_bin; cut--) {
        if (above + hist[cut] >= out->capacity) break;
        above += hist[cut];
    }
    quota = out->capacity - above;
    /* pass 2: every block above the cut bin, and of the cut bin an evenly spread quota (the
     * j-th of its members when floor(j * quota / count) steps), so no image region is favoured.
     * quota <= count, so that floor steps by 0 or 1: spread carries (j * quota) mod count, and a
     * member is kept when adding quota wraps it (no division per member). */
    for (by = 0, i = 0, spread = 0; by < bh; by++) {
        for (bx = 0; bx < bw; bx++, i++) {
            /* branch-free compaction: always write, advance only when kept (the arrays have
             * a lane of slack); only the cut bin's members take a branch */
            int key, keep;
            if ((bx & 3) == 0 && bx + 4 <= bw) {
                /* four blocks all below the cut bin (most, with a small budget): skip them.
                 * Each 16-bit lane plus 2^15 - (cut << 5) stays below 2^16 (keys < 2^13), and
                 * its top bit is set exactly when that key is in the cut bin or above. */
                uint64_t four;
                memcpy(&four, cells + i, sizeof four);
                if (!((four + (0x8000u - ((unsigned)cut << 5)) * 0x0001000100010001ull) &
                      0x8000800080008000ull)) {
                    bx += 3;
                    i += 3;
                    continue;
                }
            }
            key = cells[i];
            bin = key >> 5;
            keep = bin > cut;
            if (bin == cut) {
                spread += quota;
                keep = spread >= hist[cut];
                spread -= keep ? hist[cut] : 0;
            }
            out->x[n] = (int16_t)(bx * b + (key & (b - 1)));
            out->y[n] = (int16_t)(by * b + ((key & 15) >> log2b));
            n += keep;
        }
    }
    out->n = n;
    for (i = 0; i < n; i++) {
        const uint8_t *p = img + (ptrdiff_t)out->y[i] * w + out->x[i];
        out->t[i] = (int16_t)p[0];
        out->gx[i] = (int16_t)(p[1] - p[-1]);
        out->gy[i] = (int16_t)(p[w] - p[-w]);
    }
    /* pad to whole lanes with inert points (zero gradient, zero weight at match time) */
    for (; n % LANES; n++) out->x[n] = out->y[n] = out->t[n] = out->gx[n] = out->gy[n] = 0;
}

/* Region of a level pixel in the identity test's grid. */
static int region_of(int x, int y, int w, int h)
{
    return (y * REGIONS_Y / h) * REGIONS_X + x * REGIONS_X / w;
}

/* The identity test's points from the block cells select_points left for this level: of every
 * region, its REGION_TOP strongest blocks above the level's floor (ties: scan order). A moving
 * object's texture fills the template's capacity, and the static background then has no say;
 * per region it keeps its own. */
static void select_region_points(const uint8_t *img, int w, int h, int level,
                                 const uint16_t *cells, home__refine_points *out)
{
    const int b = block_side(level);
    const int bw = (w + b - 1) / b, bh = (h + b - 1) / b;
    const int log2b = b == 4 ? 2 : b == 2 ? 1 : 0;
    const int floor_key = (score_floor(level) / 2 + 1) << 5;
    int16_t key[REGION_CAPACITY];
    int bx, by, i, j, r, n = 0;
    for (i = 0; i < REGION_CAPACITY; i++) key[i] = 0;
    for (by = 0; by < bh; by++) {
        for (bx = 0; bx < bw; bx++) {
            const int k = cells[by * bw + bx];
            int x, y;
            if (k < floor_key) continue;
            x = bx * b + (k & (b - 1));
            y = by * b + ((k & 15) >> log2b);
            r = region_of(x, y, w, h) * REGION_TOP;
            if (k <= key[r + REGION_TOP - 1]) continue;
            /* insert, strongest first; an equal key keeps the earlier block ahead */
            for (j = REGION_TOP - 1; j > 0 && key[r + j - 1] < k; j--) {
                key[r + j] = key[r + j - 1];
                out->x[r + j] = out->x[r + j - 1];
                out->y[r + j] = out->y[r + j - 1];
            }
            key[r + j] = (int16_t)k;
            out->x[r + j] = (int16_t)x;
            out->y[r + j] = (int16_t)y;
        }
    }
    for (i = 0; i < REGION_CAPACITY; i++) {
        if (!key[i]) continue;
        out->x[n] = out->x[i];
        out->y[n] = out->y[i];
        out->t[n] = (int16_t)img[(ptrdiff_t)out->y[n] * w + out->x[n]];
        n++;
    }
    out->n = n;
    for (; n % LANES; n++) out->x[n] = out->y[n] = out->t[n] = 0;
}

uint32_t home__refine_store(home_context *ctx, const uint8_t *image, ptrdiff_t stride)
{
    home__refine_state *st = &ctx->refine;
    int l, slot;
    int16_t *row_tmp;
    uint16_t *cells;
    if (!st->levels) return 0; /* refinement off: no scratch (arithmetic on NULL is undefined) */
    row_tmp = (int16_t *)st->scratch;
    cells = (uint16_t *)(void *)((unsigned char *)st->scratch +
                                 align64((size_t)st->w[0] * sizeof(int16_t)));
    if (st->base_level == 0) {
        st->rk->blur3(image, stride, st->pyr[0], st->w[0], st->w[0], st->h[0], row_tmp);
    } else {
        uint8_t *half = (uint8_t *)cells; /* free until the selection below */
        st->rk->downsample(image, stride, half, st->w[1], st->w[1], st->h[1]);
        st->rk->blur3(half, st->w[1], st->pyr[1], st->w[1], st->w[1], st->h[1], row_tmp);
    }
    for (l = st->base_level + 1; l < st->levels; l++)
        st->rk->downsample(st->pyr[l - 1], st->w[l - 1], st->pyr[l], st->w[l], st->w[l], st->h[l]);
    /* the id is a hash of the data: the same frame gets the same id, so outputs stay
     * deterministic, and features are tied to the snapshot they were extracted with */
    l = st->levels - 1;
    st->pyr_id = hash_bytes(st->pyr[l], (size_t)st->w[l] * (size_t)st->h[l]);
    slot = st->next_slot;
    st->next_slot ^= 1;
    /* the region points' level last: its block cells stay for them */
    for (l = st->levels - 1; l >= st->finest_level; l--)
        if (l != st->region_level)
            select_points(st->rk, st->pyr[l], st->w[l], st->h[l], l, row_tmp, cells, &st->tpl[slot][l]);
    l = st->region_level;
    select_points(st->rk, st->pyr[l], st->w[l], st->h[l], l, row_tmp, cells, &st->tpl[slot][l]);
    select_region_points(st->pyr[l], st->w[l], st->h[l], l, cells, &st->regions[slot]);
    st->slot_id[slot] = st->pyr_id;
    return st->pyr_id;
}

/* ---------------------------------------------------------------------------------------------
 * Gauss-Newton */

typedef struct solver {
    const home__refine_state *st;
    const home__refine_points *tpl;     /* template (frame A) points, one per level */
    double f, cx, cy;                   /* normalisation */
    double hn[9];                       /* A -> B in normalised coordinates */
    double alpha, beta;                 /* photometric model alpha * B + beta ~ A */
    double sigma;                       /* residual scale of the last iteration */
    double jtj[64];                     /* last weighted normal matrix (normalised units) */
    float acc[N_ACC * LANES];           /* per-lane sums of the normal equations */
    int hessian_level;                  /* level whose J^T W J acc holds (-1: none yet) */
    double resid_var;                   /* weighted residual variance of the last iteration
                                           (set once the finest level converged) */
    double split_px;                    /* split-half disagreement of the last finest step */
    int finest;                         /* level the estimate ends at */
    int k;                              /* parameters of the model fitted (8: a homography) */
    double basis[8][8];                 /* the update's subspace dp = B q when k < 8 */
    float *img_b, *img_b2, *res, *wt;   /* per-point scratch */
} solver;

static void mat3_mul(const double *a, const double *b, double *out)
{
    int i, j;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            out[i * 3 + j] = a[i * 3 + 0] * b[0 * 3 + j] + a[i * 3 + 1] * b[1 * 3 + j] +
                             a[i * 3 + 2] * b[2 * 3 + j];
}

static int mat3_inv(const double *m, double *out)
{
    double d = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
               m[2] * (m[3] * m[7] - m[4] * m[6]);
    if (!(fabs(d) > 1e-300) || !isfinite(d)) return 0;
    out[0] = (m[4] * m[8] - m[5] * m[7]) / d;
    out[1] = (m[2] * m[7] - m[1] * m[8]) / d;
    out[2] = (m[1] * m[5] - m[2] * m[4]) / d;
    out[3] = (m[5] * m[6] - m[3] * m[8]) / d;
    out[4] = (m[0] * m[8] - m[2] * m[6]) / d;
    out[5] = (m[2] * m[3] - m[0] * m[5]) / d;
    out[6] = (m[3] * m[7] - m[4] * m[6]) / d;
    out[7] = (m[1] * m[6] - m[0] * m[7]) / d;
    out[8] = (m[0] * m[4] - m[1] * m[3]) / d;
    return 1;
}

static void normalise9(double *h)
{
    int k;
    double s = h[8];
    for (k = 0; k < 9; k++) h[k] /= s;
}

/* pixel H -> normalised N H N^-1, and back */
static void to_normalised(const solver *s, const double *h, double *hn)
{
    const double n[9] = {1 / s->f, 0, -s->cx / s->f, 0, 1 / s->f, -s->cy / s->f, 0, 0, 1};
    const double ni[9] = {s->f, 0, s->cx, 0, s->f, s->cy, 0, 0, 1};
    double t[9] = {0}; /* all written by mat3_mul; zeroed for gcc's -fanalyzer (make lint) */
    mat3_mul(n, h, t);
    mat3_mul(t, ni, hn);
    normalise9(hn);
}

static void to_pixels(const solver *s, const double *hn, double *h)
{
    const double n[9] = {1 / s->f, 0, -s->cx / s->f, 0, 1 / s->f, -s->cy / s->f, 0, 0, 1};
    const double ni[9] = {s->f, 0, s->cx, 0, s->f, s->cy, 0, 0, 1};
    double t[9] = {0}; /* all written by mat3_mul; zeroed for gcc's -fanalyzer (make lint) */
    mat3_mul(ni, hn, t);
    mat3_mul(t, n, h);
    normalise9(h);
}

/* Matrix taking template level-l pixels to B's level-l pixels under hn. */
static void level_matrix(const solver *s, const double *hn, int level, float *m)
{
    const double sc = (double)(1 << level), o = 0.5 * (sc - 1.0);
    const double q[9] = {sc / s->f, 0, (o - s->cx) / s->f, 0, sc / s->f, (o - s->cy) / s->f, 0, 0, 1};
    const double p[9] = {s->f / sc, 0, (s->cx - o) / sc, 0, s->f / sc, (s->cy - o) / sc, 0, 0, 1};
    double t[9], r[9];
    int k;
    mat3_mul(hn, q, t);
    mat3_mul(p, t, r);
    for (k = 0; k < 9; k++) m[k] = (float)r[k];
}

/* Robust scale: 1.4826 * median |r| over the valid points, from a histogram. */
static double robust_sigma(const float *img_b, const int16_t *t, int n, double alpha, double beta,
                           int32_t *bins)
{
    const float a = (float)alpha, b = (float)beta;
    int hist[HIST_BINS + 2], i, count, half, acc = 0;
    memset(hist, 0, sizeof hist);
    /* bins first (element-wise: vectorised), then the histogram; invalid points in a spare bin */
    for (i = 0; i < n; i++) {
        const float r = fabsf(a * img_b[i] + b - (float)t[i]) * 8.0f;
        const int bin = r < (float)HIST_BINS ? (int)r : HIST_BINS;
        bins[i] = img_b[i] >= 0.0f ? bin : HIST_BINS + 1;
    }
    for (i = 0; i < n; i++) hist[bins[i]]++;
    count = n - hist[HIST_BINS + 1];
    if (!count) return SIGMA_FLOOR;
    half = (count + 1) / 2;
    for (i = 0; i <= HIST_BINS; i++) {
        acc += hist[i];
        if (acc >= half) break;
    }
    {
        double med = (i + 0.5) / 8.0, sigma = 1.4826 * med;
        return sigma > SIGMA_FLOOR ? sigma : SIGMA_FLOOR;
    }
}

/* The acceptance test's error per point: Geman-McClure, bounded like the Cauchy weights'
 * influence and made of IEEE operations only (no libm), so every platform decides alike. */
static double robust_cost(double r, double c)
{
    double q = r / c;
    return 0.5 * r * r / (1.0 + q * q);
}

/* Weighted least-squares gain and bias of alpha * B + beta ~ A with Cauchy weights
 * 1 / (1 + (r / c)^2), c = 2.385 sigma: the influence of a residual fades as 1 / |r| far out, so
 * occluders and moving objects barely pull, yet no point is ever cut off outright. Scale
 * sigma from the residuals of the current (alpha, beta); writes weights and new residuals.
 * mask (optional): only points valid there too. Returns the number of valid points. */
static int fit_photometric(solver *s, const home__refine_points *tp, const float *img_b,
                           const float *mask, double sigma, float *res, float *wt)
{
    const int n4 = (tp->n + LANES - 1) & ~(LANES - 1);
    float part[5 * LANES];
    double sum[5], den;
    int k, n;
    n = s->st->rk->cauchy_sums(img_b, mask ? mask : img_b, tp->t, n4, tp->n, (float)s->alpha,
                               (float)s->beta, (float)(1.0 / (CAUCHY_K * sigma)), wt, part);
    for (k = 0; k < 5; k++)
        sum[k] = ((double)part[k * LANES] + part[k * LANES + 1]) +
                 ((double)part[k * LANES + 2] + part[k * LANES + 3]);
    /* sum: w, w b, w a, w b b, w b a */
    if (n && sum[0] > 0) {
        den = sum[0] * sum[3] - sum[1] * sum[1];
        if (den > 1e-6 * sum[0] * sum[0]) {
            s->alpha = (sum[0] * sum[4] - sum[1] * sum[2]) / den;
            s->beta = (sum[2] - s->alpha * sum[1]) / sum[0];
        } else {
            s->alpha = 1.0;
            s->beta = (sum[2] - sum[1]) / sum[0];
        }
    }
    s->st->rk->residuals(img_b, tp->t, wt, n4, (float)s->alpha, (float)s->beta, res);
    return n;
}

/* Largest displacement of the image corners (full-resolution px) by the linearised update dp. */
static double corner_step_px(const solver *s, const double *dp)
{
    const double hu = s->cx / s->f, hv = s->cy / s->f;
    double worst = 0.0;
    int k;
    for (k = 0; k < 4; k++) {
        double u = (k & 1) ? hu : -hu, v = (k & 2) ? hv : -hv;
        double du = dp[0] * u + dp[1] * v + dp[2] - (dp[6] * u + dp[7] * v) * u;
        double dv = dp[3] * u + dp[4] * v + dp[5] - (dp[6] * u + dp[7] * v) * v;
        double d = sqrt(du * du + dv * dv) * s->f;
        if (d > worst) worst = d;
    }
    return worst;
}

/* Normal equations (J^T W J, J^T W r) in normalised units from the lanes in lane_mask. */
static void normal_equations(const float *acc, unsigned lane_mask, double k, double *a, double *g)
{
    int p, q, j, l;
    for (p = 0, j = 0; p < 8; p++) {
        double v;
        for (q = p; q < 8; q++, j++) {
            for (l = 0, v = 0.0; l < LANES; l++)
                if (lane_mask >> l & 1) v += (double)acc[j * LANES + l];
            a[p * 8 + q] = a[q * 8 + p] = v * k * k;
        }
        for (l = 0, v = 0.0; l < LANES; l++)
            if (lane_mask >> l & 1) v += (double)acc[(36 + p) * LANES + l];
        g[p] = v * k;
    }
}

/* x = B (B^T a B)^-1 B^T b: the solve in the model's parameters (a and b are overwritten; with
 * all 8, a plain solve). 0 when not positive definite. */
static int model_solve(const solver *s, double *a, double *b)
{
    double aq[64], bq[8];
    int i, j;
    if (s->k == 8) return home__solve_spd8(a, b);
    home__project_normal(s->basis, s->k, a, b, aq, bq);
    if (!home__solve_spd(aq, bq, s->k)) return 0;
    for (j = 0; j < 8; j++) {
        double v = 0.0;
        for (i = 0; i < s->k; i++) v += bq[i] * s->basis[i][j];
        b[j] = v;
    }
    return 1;
}

/* One IRLS Gauss-Newton step at a level. Returns 0 when too few points stay usable or the
 * system is singular; *step_px gets the corner motion of the update. */
static int iterate(solver *s, int level, double *step_px)
{
    const home__refine_state *st = s->st;
    const home__refine_points *tp = &s->tpl[level];
    const int n4 = (tp->n + LANES - 1) & ~(LANES - 1);
    const double sc = (double)(1 << level), o = 0.5 * (sc - 1.0);
    const double k = s->f / (2.0 * sc);  /* template gradient: 2x central difference per level px */
    float m[9], aff[3], *acc = s->acc;
    double a[64], g[8], dp[9], hd[9], hdi[9], t[9];
    int i, p, valid;

    level_matrix(s, s->hn, level, m);
    st->rk->warp(m, tp->x, tp->y, n4, st->pyr[level], st->w[level], st->w[level],
                      st->h[level], s->img_b);
    s->sigma = robust_sigma(s->img_b, tp->t, tp->n, s->alpha, s->beta, (int32_t *)(void *)s->wt);
    valid = fit_photometric(s, tp, s->img_b, NULL, s->sigma, s->res, s->wt);
    if (valid < MIN_POINTS) return 0;
    aff[0] = (float)(sc / s->f);
    aff[1] = (float)((o - s->cx) / s->f);
    aff[2] = (float)((o - s->cy) / s->f);
    /* J^T W J at a level's first iteration, then reused while the steps keep halving (a fresh
     * one otherwise, see refine()): in the inverse-compositional form it changes only through
     * the weights, and an approximate matrix changes the path to the solution, not the solution
     * (J^T W r = 0). J^T W J is 36 of the 44 sums per point. */
    st->rk->accumulate(tp->x, tp->y, tp->gx, tp->gy, s->res, s->wt, n4, aff,
                       s->hessian_level != level, acc);
    s->hessian_level = level;
    normal_equations(acc, 0xf, k, a, g);
    memcpy(s->jtj, a, sizeof a);
    if (level == s->finest) {
        /* split-half check: the steps of the even and the odd lanes (interleaved halves of the
         * points) from the same estimate agree when the points carry signal and scatter when
         * they carry template noise, which the Fisher covariance cannot see */
        double ae[64], ge[8], ao[64], go[8];
        normal_equations(acc, 0x5, k, ae, ge);
        normal_equations(acc, 0xa, k, ao, go);
        if (model_solve(s, ae, ge) && model_solve(s, ao, go)) {
            for (p = 0; p < 8; p++) ge[p] -= go[p];
            s->split_px = 0.5 * corner_step_px(s, ge);
        } else {
            s->split_px = INFINITY;
        }
    }
    if (!model_solve(s, a, g)) return 0;
    for (p = 0; p < 8; p++) dp[p] = g[p];
    *step_px = corner_step_px(s, dp);
    hd[0] = 1 + dp[0]; hd[1] = dp[1]; hd[2] = dp[2];
    hd[3] = dp[3]; hd[4] = 1 + dp[4]; hd[5] = dp[5];
    hd[6] = dp[6]; hd[7] = dp[7]; hd[8] = 1;
    if (!mat3_inv(hd, hdi)) return 0;
    mat3_mul(s->hn, hdi, t);
    normalise9(t);
    for (i = 0; i < 9; i++)
        if (!isfinite(t[i])) return 0;
    memcpy(s->hn, t, sizeof t);
    return 1;
}

/* Weighted residual variance of the last iteration (its weights and residuals are still in the
 * scratch), for the Fisher covariance below. */
static double residual_variance(const solver *s)
{
    const home__refine_points *tp = &s->tpl[s->finest];
    double sum_w = 0, sum_wr2 = 0;
    int i;
    for (i = 0; i < tp->n; i++) {
        sum_w += s->wt[i];
        sum_wr2 += (double)s->wt[i] * s->res[i] * s->res[i];
    }
    return sum_w > 8 ? sum_wr2 / (sum_w - 8) : sum_wr2;
}

/* Predicted standard deviation of the worst corner, px: sqrt(J_c (sigma^2 A^-1) J_c^T). */
static double corner_std_px(const solver *s)
{
    const double hu = s->cx / s->f, hv = s->cy / s->f;
    double worst = 0.0, l[64];
    int k, axis, i, j;
    /* one factor of the (model's) normal matrix for the eight corner coordinates */
    if (s->k == 8) {
        memcpy(l, s->jtj, sizeof l);
    } else {
        const double no_gradient[8] = {0};
        double unused[8];
        home__project_normal(s->basis, s->k, s->jtj, no_gradient, l, unused);
    }
    if (!home__cholesky8(l)) return INFINITY;
    for (k = 0; k < 4; k++) {
        double u = (k & 1) ? hu : -hu, v = (k & 2) ? hv : -hv, var = 0.0;
        for (axis = 0; axis < 2; axis++) {
            double jc[8], z[8], q = 0.0;
            memset(jc, 0, sizeof jc);
            if (axis == 0) { jc[0] = u; jc[1] = v; jc[2] = 1; jc[6] = -u * u; jc[7] = -u * v; }
            else { jc[3] = u; jc[4] = v; jc[5] = 1; jc[6] = -u * v; jc[7] = -v * v; }
            if (s->k == 8) {
                memcpy(z, jc, sizeof z);
            } else { /* B^T jc, zero beyond k */
                for (i = 0; i < 8; i++) {
                    z[i] = 0.0;
                    for (j = 0; j < 8 && i < s->k; j++) z[i] += s->basis[i][j] * jc[j];
                }
                memcpy(jc, z, sizeof jc);
            }
            home__cholesky_solve8(l, z);
            for (i = 0; i < 8; i++) q += jc[i] * z[i];
            var += q;
        }
        var *= s->resid_var * s->f * s->f;
        if (sqrt(var) > worst) worst = sqrt(var);
    }
    return worst;
}

/* Robust photometric error of the finest-level B samples img_b over the points other_b (the
 * samples under the other estimate) keeps too: mean robust cost at the fixed scale sigma,
 * after re-fitting gain and bias. Also the weighted correlation of A and B there. */
static double photometric_error(solver *s, const float *img_b, const float *other_b,
                                double sigma, double *zncc)
{
    const home__refine_points *tp = &s->tpl[s->finest];
    const double c = CAUCHY_K * sigma;
    double cost = 0, sw = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, va, vb;
    int i, it, n = 0;
    s->alpha = 1.0;
    s->beta = 0.0;
    for (it = 0; it < 2; it++) fit_photometric(s, tp, img_b, other_b, sigma, s->res, s->wt);
    for (i = 0; i < tp->n; i++) {
        double w = s->wt[i], a = tp->t[i], b = img_b[i];
        if (img_b[i] < 0.0f || other_b[i] < 0.0f) continue;
        cost += robust_cost(s->res[i], c);
        n++;
        sw += w; sa += w * a; sb += w * b; saa += w * a * a; sbb += w * b * b; sab += w * a * b;
    }
    *zncc = 0.0;
    if (sw > 0) {
        va = saa - sa * sa / sw;
        vb = sbb - sb * sb / sw;
        if (va > 0 && vb > 0) *zncc = (sab - sa * sb / sw) / sqrt(va * vb);
    }
    return n ? cost / n : INFINITY;
}

/* Share of the points (valid under both estimates) whose residual under the estimate of img_b
 * (s->res, left by photometric_error) is within 3 robust sigmas of its own: a refinement that
 * aligned part of the scene (two edges of three, say) leaves the rest far off, and the robust
 * weights that let it ignore them also hide them from the weighted correlation. */
static double inlier_share(solver *s, const float *img_b, const float *other_b)
{
    const home__refine_points *tp = &s->tpl[s->finest];
    double sigma, limit;
    int i, n = 0, in = 0;
    /* the scale from the residuals (robust_sigma's histogram bins go to the weights' scratch) */
    sigma = robust_sigma(img_b, tp->t, tp->n, s->alpha, s->beta, (int32_t *)(void *)s->wt);
    limit = 3.0 * sigma;
    for (i = 0; i < tp->n; i++) {
        if (img_b[i] < 0.0f || other_b[i] < 0.0f) continue;
        n++;
        in += fabs(s->res[i]) <= limit;
    }
    return n ? (double)in / n : 0.0;
}

static double max_corner_distance(double cx, double cy, const double *h1, const double *h2)
{
    const double xs[2] = {0.0, 2.0 * cx}, ys[2] = {0.0, 2.0 * cy};
    double worst = 0.0;
    int k;
    for (k = 0; k < 4; k++) {
        double x = xs[k & 1], y = ys[k >> 1];
        double w1 = h1[6] * x + h1[7] * y + h1[8], w2 = h2[6] * x + h2[7] * y + h2[8];
        double dx = (h1[0] * x + h1[1] * y + h1[2]) / w1 - (h2[0] * x + h2[1] * y + h2[2]) / w2;
        double dy = (h1[3] * x + h1[4] * y + h1[5]) / w1 - (h2[3] * x + h2[4] * y + h2[5]) / w2;
        double d = sqrt(dx * dx + dy * dy);
        if (!(d <= worst)) worst = d; /* NaN counts as infinitely far */
    }
    return worst;
}

/* dp of the inverse-compositional update that takes hn to hn2 (both normalised, h8 = 1):
 * hn2 = hn (I + D(dp))^-1, so I + D = hn2^-1 hn scaled to a unit corner. */
static int update_between(const double *hn, const double *hn2, double *dp)
{
    double inv[9], m[9];
    int k;
    if (!mat3_inv(hn2, inv)) return 0;
    mat3_mul(inv, hn, m);
    if (!(fabs(m[8]) > 1e-12)) return 0;
    normalise9(m);
    for (k = 0; k < 8; k++) dp[k] = m[k] - (k == 0 || k == 4 ? 1.0 : 0.0);
    return 1;
}

/* Model selection over the refinement's Fisher information (src/model.c): J^T W J over the
 * weighted residual variance is the information of the update dp at the estimate; the chain
 * rule through dp(h) (central differences) gives that of h's entries. h1 (pixels) becomes the
 * chosen model's estimate; sets result->model and sigma_px. */
static int choose_model(solver *s, int max_model, double *h1, home_result *result)
{
    home__model_problem mp;
    home__model_choice choice;
    double jac[8][8], t[8][8], hn[9];
    int i, j, a, b;
    mp.space = HOME__SPACE_H;
    for (j = 0; j < 8; j++) {
        const double eps = 1e-7;
        double hp[9], hm[9], dpp[8], dpm[8];
        memcpy(hp, s->hn, sizeof hp);
        memcpy(hm, s->hn, sizeof hm);
        hp[j] += eps;
        hm[j] -= eps;
        if (!update_between(s->hn, hp, dpp) || !update_between(s->hn, hm, dpm)) return 0;
        for (i = 0; i < 8; i++) jac[i][j] = (dpp[i] - dpm[i]) / (2 * eps);
    }
    for (a = 0; a < 8; a++) /* t = J^T W J  d dp / d h, then d dp / d h^T t */
        for (j = 0; j < 8; j++) {
            double v = 0.0;
            for (b = 0; b < 8; b++) v += s->jtj[a * 8 + b] * jac[b][j];
            t[a][j] = v;
        }
    for (i = 0; i < 8; i++)
        for (j = 0; j < 8; j++) {
            double v = 0.0;
            for (a = 0; a < 8; a++) v += jac[a][i] * t[a][j];
            mp.info[i * 8 + j] = v / (s->resid_var * REFINE_SIGMA_SCALE * REFINE_SIGMA_SCALE);
        }
    memcpy(mp.p, s->hn, sizeof mp.p);
    mp.penalty = log((double)s->tpl[s->finest].n);
    mp.max_model = max_model;
    mp.max_params = 8;
    mp.scale = s->f;
    mp.cx = s->cx;
    mp.cy = s->cy;
    if (!home__select_model(&mp, &choice)) return 0;
    memcpy(hn, choice.p, 8 * sizeof *hn);
    hn[8] = 1.0;
    to_pixels(s, hn, h1);
    result->model = choice.model;
    result->sigma_px = choice.sigma_px;
    return 1;
}

static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

/* A solver on the template of slot `slot`, its scratch, the normalisation and the level the
 * estimate ends at. */
static void solver_setup(home_context *ctx, int slot, solver *s)
{
    const home__refine_state *st = &ctx->refine;
    float *scratch = (float *)st->scratch;
    const int cap = match_capacity(&ctx->cfg);
    memset(s, 0, sizeof *s);
    s->st = st;
    s->tpl = st->tpl[slot];
    s->cx = 0.5 * (ctx->cfg.width - 1);
    s->cy = 0.5 * (ctx->cfg.height - 1);
    s->f = 0.5 * (ctx->cfg.width > ctx->cfg.height ? ctx->cfg.width : ctx->cfg.height);
    s->img_b = scratch;
    s->img_b2 = scratch + cap;
    s->res = scratch + 2 * cap;
    s->wt = scratch + 3 * cap;
    s->alpha = 1.0;
    s->hessian_level = -1;
    s->k = 8;
    for (s->finest = st->finest_level; s->finest < st->levels - 1; s->finest++)
        if (s->tpl[s->finest].n >= FINEST_MIN_POINTS) break;
}

/* Share of the frame's regions (a REGIONS_X x REGIONS_Y grid; those with at least REGION_POINTS
 * of the region points vote) whose points the identity explains better than h (pixels) does:
 * the robust photometric cost of each region under both, each with the better of the two
 * estimates' gain and bias. clear_share: the same over the regions one of them explains
 * clearly better. Moving objects are textured and draw the template points (and HOME's lines)
 * to themselves; the static background wins by area. */
static double identity_region_share(home_context *ctx, int slot, const double *h,
                                    double *clear_share)
{
    const home__refine_state *st = &ctx->refine;
    double cost[2][2][REGIONS_X * REGIONS_Y], gain[2], bias[2], hn[9], sigma, c, cost_h, cost_i;
    int count[REGIONS_X * REGIONS_Y], e, i, k, r, votes = 0, wins = 0, clear_votes = 0, fl, n4;
    int clear_wins = 0;
    const home__refine_points *tp;
    float m[9];
    solver s;
    *clear_share = 0.0;
    solver_setup(ctx, slot, &s);
    fl = st->region_level;
    tp = &st->regions[slot];
    if (tp->n < MIN_POINTS) return 0.0;
    n4 = (tp->n + LANES - 1) & ~(LANES - 1);
    to_normalised(&s, h, hn);
    level_matrix(&s, hn, fl, m);
    st->rk->warp(m, tp->x, tp->y, n4, st->pyr[fl], st->w[fl], st->w[fl], st->h[fl], s.img_b);
    level_matrix(&s, identity, fl, m);
    st->rk->warp(m, tp->x, tp->y, n4, st->pyr[fl], st->w[fl], st->w[fl], st->h[fl], s.img_b2);
    /* one scale for both costs: the estimate's residuals (the identity's would let it excuse
     * itself) */
    fit_photometric(&s, tp, s.img_b, s.img_b2, SIGMA_FLOOR * 1e3, s.res, s.wt);
    sigma = robust_sigma(s.img_b, tp->t, tp->n, s.alpha, s.beta, (int32_t *)(void *)s.wt);
    c = CAUCHY_K * sigma;
    /* each estimate's own gain and bias: moving objects pull the identity's far off the
     * background's, so every region is scored under both and keeps its better one */
    for (e = 0; e < 2; e++) {
        s.alpha = 1.0;
        s.beta = 0.0;
        for (i = 0; i < 2; i++)
            fit_photometric(&s, tp, e ? s.img_b2 : s.img_b, e ? s.img_b : s.img_b2, sigma, s.res, s.wt);
        gain[e] = s.alpha;
        bias[e] = s.beta;
    }
    memset(cost, 0, sizeof cost);
    memset(count, 0, sizeof count);
    for (i = 0; i < tp->n; i++) {
        if (s.img_b[i] < 0.0f || s.img_b2[i] < 0.0f) continue;
        r = region_of(tp->x[i], tp->y[i], st->w[fl], st->h[fl]);
        count[r]++;
        for (e = 0; e < 2; e++) {
            const double v = e ? s.img_b2[i] : s.img_b[i];
            for (k = 0; k < 2; k++) cost[e][k][r] += robust_cost(gain[k] * v + bias[k] - tp->t[i], c);
        }
    }
    for (r = 0; r < REGIONS_X * REGIONS_Y; r++) {
        if (count[r] < REGION_POINTS) continue;
        cost_h = cost[0][0][r] < cost[0][1][r] ? cost[0][0][r] : cost[0][1][r];
        cost_i = cost[1][0][r] < cost[1][1][r] ? cost[1][0][r] : cost[1][1][r];
        votes++;
        wins += cost_i < cost_h;
        /* a clear vote: at most half the other's cost, and more than a grey level per point
         * apart (near the identity, or on flat regions, the costs tie) */
        if ((cost_i < cost_h ? cost_i : cost_h) > DECISIVE_RATIO * (cost_i < cost_h ? cost_h : cost_i) ||
            fabs(cost_i - cost_h) <= DECISIVE_GREY * DECISIVE_GREY * count[r])
            continue;
        clear_votes++;
        clear_wins += cost_i < cost_h;
    }
    *clear_share = clear_votes >= MIN_VOTES ? (double)clear_wins / clear_votes : 0.0;
    return votes >= REGIONS_X * REGIONS_Y / 4 ? (double)wins / votes : 0.0;
}

/* Refine h (A -> B pixels) with the template of slot `slot` against the stored pyramid.
 * Writes the refined H and fills the refine fields of result. */
static void refine(home_context *ctx, int slot, const double *h0, home_result *result)
{
    const home__refine_state *st = &ctx->refine;
    solver s;
    double hn0[9], h1[9], e0, e1, zncc0, zncc1, step = INFINITY, sigma0, refined_std;
    double noise_std = -1.0;
    int level, it, converged = 0, iterations = 0;
    const double max_std = MAX_CORNER_STD_PX > ctx->cfg.max_sigma_px ? MAX_CORNER_STD_PX : ctx->cfg.max_sigma_px;

    solver_setup(ctx, slot, &s);
    /* below a homography the update stays in the model (it is a group: I + D(dp) in it keeps
     * the estimate in it), so a few edges that leave a homography undetermined still fix it */
    s.k = 8;
    if (ctx->cfg.max_model < HOME_MODEL_HOMOGRAPHY) {
        double o[8];
        s.k = home__model_basis(HOME__SPACE_H, ctx->cfg.max_model, o, s.basis);
    }
    to_normalised(&s, h0, hn0);
    memcpy(s.hn, hn0, sizeof hn0);
    for (level = s.finest; level < st->levels; level++) {
        if (s.tpl[level].n < MIN_POINTS) { result->refine_status = HOME_REFINE_FEW_POINTS; return; }
    }
    for (level = st->levels - 1; level >= s.finest; level--) {
        double last_step = INFINITY;
        converged = 0;
        for (it = 0; it < ctx->cfg.refine_iterations; it++) {
            iterations++;
            if (!iterate(&s, level, &step)) {
                result->refine_iterations = iterations;
                result->refine_status = HOME_REFINE_FEW_POINTS;
                return;
            }
            if (step < STEP_EPS_PX * (double)(1 << level)) { converged = 1; break; }
            /* at the finest level, also a step far below the estimate's own predicted
             * uncertainty: noisy frames (low light) keep the steps jittering at that scale */
            if (level == s.finest && step < NOISE_CHECK_PX * (double)(1 << level)) {
                if (!(noise_std >= 0.0)) { /* predicted once, near the optimum */
                    s.resid_var = residual_variance(&s);
                    noise_std = corner_std_px(&s);
                }
                if (step < STEP_NOISE_SHARE * noise_std) { converged = 1; break; }
            }
            /* the reused J^T W J no longer fits the weights (steps not even halving): fresh */
            if (step > 0.5 * last_step) s.hessian_level = -1;
            last_step = step;
        }
    }
    result->refine_iterations = iterations;
    if (!converged) { result->refine_status = HOME_REFINE_NOT_CONVERGED; return; }
    to_pixels(&s, s.hn, h1);
    s.resid_var = residual_variance(&s);
    refined_std = corner_std_px(&s);
    if (refined_std > max_std || !(s.split_px <= max_std)) {
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return;
    }
    /* the same plausibility HOME's estimate passed: a refinement that slid towards a singular
     * H (a frame squeezed to a line keeps the photometric error low on flat content) is no
     * estimate (fuzz_api found one: tests/fuzz/corpus/api/regress-refined-singular-h) */
    if (!home__homography_plausible(h1, ctx->cfg.width, ctx->cfg.height)) {
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return;
    }
    /* like for like: both estimates over the points both keep, at the scale of HOME's */
    {
        const int fl = s.finest;
        const home__refine_points *tp = &s.tpl[fl];
        const int n4 = (tp->n + LANES - 1) & ~(LANES - 1);
        float m[9];
        level_matrix(&s, s.hn, fl, m);
        st->rk->warp(m, tp->x, tp->y, n4, st->pyr[fl], st->w[fl], st->w[fl], st->h[fl], s.img_b2);
        level_matrix(&s, hn0, fl, m);
        st->rk->warp(m, tp->x, tp->y, n4, st->pyr[fl], st->w[fl], st->w[fl], st->h[fl], s.img_b);
        s.alpha = 1.0;
        s.beta = 0.0;
        fit_photometric(&s, tp, s.img_b, s.img_b2, SIGMA_FLOOR * 1e3, s.res, s.wt);
        sigma0 = robust_sigma(s.img_b, tp->t, tp->n, s.alpha, s.beta, (int32_t *)(void *)s.wt);
        e0 = photometric_error(&s, s.img_b, s.img_b2, sigma0, &zncc0);
        e1 = photometric_error(&s, s.img_b2, s.img_b, sigma0, &zncc1);
        result->refine_inlier_share = inlier_share(&s, s.img_b2, s.img_b);
    }
    result->refine_error[0] = e0;
    result->refine_error[1] = e1;
    result->refine_zncc = zncc1;
    /* not lower: a divergence, or (noisy frames) the start was already the optimum within the
     * refined estimate's own uncertainty, which then stands */
    if (!(e1 < e0) && !(max_corner_distance(s.cx, s.cy, h1, h0) <= 3.0 * refined_std)) {
        result->refine_status = HOME_REFINE_NOT_LOWER;
        return;
    }
    if (!choose_model(&s, ctx->cfg.max_model, h1, result)) {
        result->refine_status = HOME_REFINE_ILL_CONDITIONED;
        return;
    }
    memcpy(result->H, h1, sizeof h1);
    result->refined = 1;
    result->refine_status = HOME_REFINE_ACCEPTED;
}

/* Largest distance of the image corners under two pixel homographies (NaN: infinitely far). */
static double corner_distance(const home_context *ctx, const double *h1, const double *h2)
{
    return max_corner_distance(0.5 * (ctx->cfg.width - 1), 0.5 * (ctx->cfg.height - 1), h1, h2);
}

static int find_slot(const home__refine_state *st, uint32_t id)
{
    if (!id) return -1;
    if (st->slot_id[0] == id) return 0;
    if (st->slot_id[1] == id) return 1;
    return -1;
}

/* Failure rule with the refinement (documented in home.h at home_match). */
void home__refine_apply(home_context *ctx, uint32_t id_a, uint32_t id_b, home_result *result)
{
    home__refine_state *st = &ctx->refine;
    home_result trial;
    int slot, vouches, agrees, has_estimate;
    double t0 = home__now(ctx), radius, d, share, clear_share;
    result->refined = 0;
    result->refine_status = HOME_REFINE_OFF;
    if (!st->levels) return;
    slot = find_slot(st, id_a);
    if (slot < 0 || st->pyr_id != id_b || !id_b) {
        result->refine_status = HOME_REFINE_NO_SNAPSHOT;
        return;
    }
    has_estimate = result->ok || ((result->failure == HOME_FAIL_FEW_INLIERS ||
                                   result->failure == HOME_FAIL_UNCERTAIN) && result->inliers >= 8);
    trial = *result;
    /* without an estimate of HOME's, direct alignment from the identity (small motion: dim,
     * faint or textureless frames give too few lines but may hold enough gradient) */
    refine(ctx, slot, has_estimate ? result->H : identity, &trial);
    if (!has_estimate) {
        /* a local method vouches only within its reach: the identity is a start whose
         * uncertainty is the trust floor */
        if (trial.refined && trial.refine_zncc >= VOUCH_ZNCC &&
            trial.sigma_px <= VOUCH_SIGMA_SHARE * ctx->cfg.max_sigma_px &&
            trial.refine_inlier_share >= VOUCH_SHARE &&
            trial.sigma_px <= ctx->cfg.max_sigma_px &&
            corner_distance(ctx, trial.H, identity) <= ctx->cfg.refine_trust_px * ctx->hough_scale) {
            trial.ok = 1;
            trial.failure = HOME_FAIL_NONE;
        } else {
            /* HOME's rejected estimate and its failure stay */
            memcpy(trial.H, result->H, sizeof trial.H);
            trial.model = result->model;
            trial.sigma_px = result->sigma_px;
            trial.refined = 0;
            trial.refine_status = HOME_REFINE_NO_ESTIMATE;
        }
    } else if (trial.refined) {
        /* HOME's own precision scales with the Hough image's pixel: so does the floor */
        radius = ctx->cfg.refine_trust_px * ctx->hough_scale;
        if (isfinite(result->sigma_px) && 3.0 * result->sigma_px > radius)
            radius = 3.0 * result->sigma_px;
        d = corner_distance(ctx, trial.H, result->H);
        agrees = d <= radius;
        vouches = trial.refine_zncc >= VOUCH_ZNCC &&
                  trial.sigma_px <= VOUCH_SIGMA_SHARE * ctx->cfg.max_sigma_px;
        /* overruling HOME takes the whole frame: nearly every point consistent */
        if (agrees && result->sigma_px <= trial.sigma_px) {
            /* consistent, and HOME's line fit predicts the smaller error: it stays */
            trial = *result;
            trial.refine_status = HOME_REFINE_LESS_PRECISE;
            trial.refine_zncc = 0.0;
        } else if (agrees ? result->ok || vouches : vouches && trial.refine_inlier_share >= VOUCH_SHARE) {
            trial.ok = trial.sigma_px <= ctx->cfg.max_sigma_px;
            trial.failure = trial.ok ? HOME_FAIL_NONE : HOME_FAIL_UNCERTAIN;
        } else {
            /* nothing vouches for the refined H: HOME's estimate stays, as rejected */
            memcpy(trial.H, result->H, sizeof trial.H);
            trial.model = result->model;
            trial.sigma_px = result->sigma_px;
            trial.refined = 0;
            trial.ok = 0;
            trial.failure = agrees ? result->failure : HOME_FAIL_INCONSISTENT;
            trial.refine_status = agrees ? HOME_REFINE_LOW_CORRELATION : HOME_REFINE_OUTSIDE_TRUST;
        }
    } else if (trial.refine_status == HOME_REFINE_NOT_CONVERGED && trial.ok) {
        /* enough texture to align, yet no optimum near HOME's estimate: on the evaluation's
         * tuning set nearly every such estimate was more than 2 px off */
        trial.ok = 0;
        trial.failure = HOME_FAIL_INCONSISTENT;
    }
    /* a motion its own predicted error cannot tell from the identity is no evidence of one */
    if (trial.ok && trial.model != HOME_MODEL_IDENTITY &&
        isfinite(trial.sigma_px) &&
        corner_distance(ctx, trial.H, identity) <= IDENTITY_SIGMAS * trial.sigma_px) {
        memcpy(trial.H, identity, sizeof trial.H);
        trial.model = HOME_MODEL_IDENTITY;
        trial.refine_status = HOME_REFINE_STATIC;
    }
    /* a motion the static background does not share is the moving objects' */
    if (trial.ok && trial.model != HOME_MODEL_IDENTITY &&
        ((share = identity_region_share(ctx, slot, trial.H, &clear_share)) >= STATIC_SHARE ||
         clear_share >= TWO_MOTIONS_SHARE)) {
        if (share >= STATIC_SHARE || clear_share >= STATIC_SHARE) {
            memcpy(trial.H, identity, sizeof trial.H);
            trial.model = HOME_MODEL_IDENTITY;
            trial.refine_status = HOME_REFINE_STATIC;
        } else {
            trial.ok = 0;
            trial.failure = HOME_FAIL_INCONSISTENT;
        }
    }
    *result = trial;
    result->ms[HOME_STAGE_REFINE] += home__now(ctx) - t0;
}

int home_refine(home_context *ctx, const uint8_t *a, ptrdiff_t stride_a, const uint8_t *b,
                ptrdiff_t stride_b, const double *h_init, home_result *result)
{
    double t0;
    uint32_t id_a, id_b;
    int k, status;
    if (!ctx || !result || !h_init) return HOME_E_NULL;
    if (ctx->magic != HOME__MAGIC_CTX) return HOME_E_STATE;
    if ((status = home__check_image(ctx, a, stride_a)) != HOME_OK) return status;
    if ((status = home__check_image(ctx, b, stride_b)) != HOME_OK) return status;
    for (k = 0; k < 9; k++)
        if (!isfinite(h_init[k])) return HOME_E_CONFIG;
    if (!(fabs(h_init[8]) > 1e-12)) return HOME_E_CONFIG;
    memset(result, 0, sizeof *result);
    for (k = 0; k < 9; k++) result->H[k] = h_init[k] / h_init[8];
    /* the refinement may move the caller's estimate by refine_trust_px, farther only when the
     * photometric fit vouches for the whole frame */
    result->ok = 1;
    result->model = HOME_MODEL_HOMOGRAPHY;
    result->sigma_px = INFINITY; /* unknown: any refined estimate is more precise */
    t0 = home__now(ctx);
    id_a = home__refine_store(ctx, a, stride_a);
    id_b = home__refine_store(ctx, b, stride_b);
    result->ms[HOME_STAGE_REFINE] = home__now(ctx) - t0;
    home__refine_apply(ctx, id_a, id_b, result);
    result->ok = result->refined && result->ok;
    result->ms[HOME_STAGE_TOTAL] = result->ms[HOME_STAGE_REFINE];
    return HOME_OK;
}
