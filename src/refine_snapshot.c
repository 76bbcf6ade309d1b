/* The refinement's per-frame snapshot: its configuration and arena layout, the pyramid of
 * every extracted frame, its template points (the strongest gradient block maxima above a
 * camera-noise floor, evenly spread) and the static-camera test's region points. */
#include "refine_internal.h"
#include <math.h>
#include <string.h>

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
    if (cfg->refine_points < 64 || cfg->refine_points > HOME_REFINE_MAX_POINTS)
        return HOME_E_CONFIG;
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

static size_t align64(size_t n) { return home__align_up(n, HOME__BLOCK_ALIGN); }

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

/* The static test's background image: the quarter-size level (noise averaged down) or the
 * coarsest there is, box-reduced by the smallest factor that leaves at most
 * HOME__BACKGROUND_PIXELS: the same evidence and cost at every frame size. */
static void background_size(const home_config *cfg, int *w, int *h, int *level, int *factor)
{
    const int levels = levels_for(cfg);
    const int l = levels > 2 ? 2 : levels - 1;
    int f = 1;
    while ((cfg->width >> l) / f * ((cfg->height >> l) / f) > HOME__BACKGROUND_PIXELS) f++;
    *level = l;
    *factor = f;
    *w = (cfg->width >> l) / f;
    *h = (cfg->height >> l) / f;
}

static size_t background_bytes(const home_config *cfg)
{
    int w, h, l, f;
    background_size(cfg, &w, &h, &l, &f);
    return align64((size_t)w * (size_t)h);
}

/* Points a match-time scratch buffer holds: the finest template's, or the region points. */
int home__refine_match_capacity(const home_config *cfg)
{
    const int c = level_capacity(cfg, finest_for(cfg));
    return c > REGION_CAPACITY ? c : REGION_CAPACITY;
}

/* Scratch: per-point floats at match time (two warps, residuals, weights), or at extraction
 * time a row of int16 for the blur, then the half-size image (base level 1) or, later, the
 * block cells. */
static size_t scratch_bytes(const home_config *cfg)
{
    size_t match = 4 * (size_t)home__refine_match_capacity(cfg) * sizeof(float), sel = 0;
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
        total += align64((size_t)(cfg->width >> l) * (size_t)(cfg->height >> l) +
                         HOME__REFINE_IMAGE_SLACK);
        if (l >= finest_for(cfg)) /* no template below the finest level */
            total += 2 * 5 * align64((size_t)(level_capacity(cfg, l) + LANES) * sizeof(int16_t));
    }
    if (n) total += align64(scratch_bytes(cfg)) +
                    2 * 3 * align64((size_t)(REGION_CAPACITY + LANES) * sizeof(int16_t)) +
                    11 * background_bytes(cfg);
    return total;
}

void home__refine_init(home_context *ctx, unsigned char *block)
{
    home__refine_state *st = &ctx->refine;
    int l, s;
    memset(st, 0, sizeof *st);
    st->pending_slot = -1;
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
            size_t bytes =
                align64((size_t)(level_capacity(&ctx->cfg, l) + LANES) * sizeof(int16_t));
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
    if (st->levels) {
        background_size(&ctx->cfg, &st->background_w, &st->background_h, &st->background_level,
                        &st->background_factor);
        for (s = 0; s < 2; s++) {
            st->background[s] = block;
            block += background_bytes(&ctx->cfg);
        }
        for (s = 0; s < 2; s++) {
            st->background16[s] = (uint16_t *)(void *)block;
            block += 2 * background_bytes(&ctx->cfg);
        }
        st->flat = block;
        block += background_bytes(&ctx->cfg);
        st->sampled = (int16_t *)(void *)block; /* w x h int16 */
        block += 2 * background_bytes(&ctx->cfg);
        st->smoothed_b = (int16_t *)(void *)block;
        block += 2 * background_bytes(&ctx->cfg);
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

/* The identity test's points from the block cells select_points left for this level: of every
 * region, its REGION_TOP strongest blocks above the level's floor (ties: scan order), or, in a
 * region with none, above REGION_WEAK_SCORE (a horizon in fog). A moving object's texture fills
 * the template's capacity, and the static background then has no say; per region it keeps its
 * own. */
/* The score |gx| + |gy| a region point of `level` needs to count as textured. */
static int region_floor(int level)
{
    return (score_floor(level) / 2 + 1) * 2;
}

static void select_region_points(const uint8_t *img, int w, int h, int level,
                                 const uint16_t *cells, home__refine_points *out,
                                 unsigned char *faint, unsigned char *plain)
{
    const int b = block_side(level);
    const int bw = (w + b - 1) / b, bh = (h + b - 1) / b;
    const int log2b = b == 4 ? 2 : b == 2 ? 1 : 0;
    const int floor_key = region_floor(level) << 4, weak_key = REGION_WEAK_SCORE << 4;
    const region_grid grid = region_grid_for(w, h);
    int16_t key[REGION_CAPACITY];
    int bx, by, i, j, r, n = 0;
    for (i = 0; i < REGION_CAPACITY; i++) key[i] = 0;
    for (by = 0; by < bh; by++) {
        for (bx = 0; bx < bw; bx++) {
            const int k = cells[by * bw + bx];
            int x, y;
            if (k < weak_key) continue;
            x = bx * b + (k & (b - 1));
            y = by * b + ((k & 15) >> log2b);
            r = region_at(grid, x, y) * REGION_TOP;
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
    for (r = 0; r < REGIONS_X * REGIONS_Y; r++) {
        faint[r] = key[r * REGION_TOP] > 0 && key[r * REGION_TOP] < floor_key;
        plain[r] = key[r * REGION_TOP] < floor_key;
    }
    for (i = 0; i < REGION_CAPACITY; i++) {
        /* a region with blocks above the floor keeps only those */
        if (!key[i] || (key[i] < floor_key && key[i - i % REGION_TOP] >= floor_key)) continue;
        out->x[n] = out->x[i];
        out->y[n] = out->y[i];
        out->t[n] = (int16_t)img[(ptrdiff_t)out->y[n] * w + out->x[n]];
        n++;
    }
    out->n = n;
    for (; n % LANES; n++) out->x[n] = out->y[n] = out->t[n] = 0;
}

/* Sum of the side x side box of a level image at p. */
static long box_sum(const uint8_t *p, int stride, int side)
{
    long sum = 0;
    int i, j;
    for (j = 0; j < side; j++)
        for (i = 0; i < side; i++) sum += p[(ptrdiff_t)j * stride + i];
    return sum;
}

/* k with 2^k = v, or -1 when v is no power of two */
static int exact_log2(int v)
{
    int k = 0;
    while (k < 30 && (1 << k) < v) k++;
    return (1 << k) == v ? k : -1;
}

/* (sum + d / 2) / d for sum >= 0: a shift when d = 2^k (k >= 0) */
static long rounded_quotient(long sum, long d, int k)
{
    return k >= 0 ? (sum + d / 2) >> k : (sum + d / 2) / d;
}

/* The slot's background images from the pyramid: box means of f x f at the background level,
 * rounded, and the same boxes from the finer level in sixteenths (the score test's evidence is
 * below a grey level at quarter size). */
static void store_background(home__refine_state *st, int slot)
{
    const int f = st->background_factor, l = st->background_level;
    const int w = st->background_w, h = st->background_h, stride = st->w[l];
    const int src = l > st->base_level ? l - 1 : l, g = f << (l - src), src_stride = st->w[src];
    const int kf = exact_log2(f * f), kg = exact_log2(g * g);
    int x, y;
    for (y = 0; y < h; y++) {
        const uint8_t *r0 = st->pyr[l] + (ptrdiff_t)(y * f) * stride, *r1 = r0 + stride;
        uint8_t *o = st->background[slot] + (ptrdiff_t)y * w;
        if (f == 1) {   /* up to HOME__BACKGROUND_PIXELS at the level: the level itself */
            memcpy(o, r0, (size_t)w);
        } else if (f == 2) {
            for (x = 0; x < w; x++)
                o[x] = (uint8_t)((r0[2 * x] + r0[2 * x + 1] + r1[2 * x] + r1[2 * x + 1] + 2) >> 2);
        } else {
            for (x = 0; x < w; x++)
                o[x] = (uint8_t)rounded_quotient(box_sum(r0 + x * f, stride, f), (long)f * f, kf);
        }
    }
    for (y = 0; y < h; y++) {
        const uint8_t *r0 = st->pyr[src] + (ptrdiff_t)(y * g) * src_stride, *r1 = r0 + src_stride;
        uint16_t *o = st->background16[slot] + (ptrdiff_t)y * w;
        if (g == 2) {   /* the usual case: 16 x the mean of 2 x 2 is 4 x their sum, exactly */
            for (x = 0; x < w; x++)
                o[x] = (uint16_t)(4 * (r0[2 * x] + r0[2 * x + 1] + r1[2 * x] + r1[2 * x + 1]));
        } else if (g == 4) {   /* ... and of 4 x 4 their sum */
            const uint8_t *r2 = r1 + src_stride, *r3 = r2 + src_stride;
            for (x = 0; x < w; x++) {
                const uint8_t *a = r0 + 4 * x, *b = r1 + 4 * x, *c = r2 + 4 * x, *d = r3 + 4 * x;
                o[x] = (uint16_t)(a[0] + a[1] + a[2] + a[3] + b[0] + b[1] + b[2] + b[3] + c[0] +
                                  c[1] + c[2] + c[3] + d[0] + d[1] + d[2] + d[3]);
            }
        } else {
            for (x = 0; x < w; x++)
                o[x] = (uint16_t)rounded_quotient(16 * box_sum(r0 + x * g, src_stride, g),
                                                  (long)g * g, kg);
        }
    }
}

/* The selection's block cells, in the scratch after a row of int16 */
static uint16_t *scratch_cells(const home__refine_state *st)
{
    return (uint16_t *)(void *)((unsigned char *)st->scratch +
                                align64((size_t)st->w[0] * sizeof(int16_t)));
}

uint8_t *home__refine_half_frame(home_context *ctx, int *rows)
{
    home__refine_state *st = &ctx->refine;
    if (!st->levels || st->base_level == 0) return NULL;
    *rows = st->h[1];
    return (uint8_t *)scratch_cells(st); /* free until the point selection */
}

void home__refine_half_rows(home_context *ctx, const uint8_t *image, ptrdiff_t stride, int y0,
                            int y1)
{
    home__refine_state *st = &ctx->refine;
    uint8_t *half = (uint8_t *)scratch_cells(st);
    if (y1 > y0)
        st->rk->downsample(image + 2 * (ptrdiff_t)y0 * stride, stride,
                           half + (ptrdiff_t)y0 * st->w[1], st->w[1], st->w[1], y1 - y0);
}

/* The template points of slot `slot` (and its identity-test region points) from the current
 * pyramid, which must be that slot's frame. Uses the scratch cells and rows. */
static void select_templates(home__refine_state *st, int slot)
{
    int16_t *row_tmp = (int16_t *)st->scratch;
    uint16_t *cells = scratch_cells(st);
    int l;
    /* the region points' level last: its block cells stay for them */
    for (l = st->levels - 1; l >= st->finest_level; l--)
        if (l != st->region_level)
            select_points(st->rk, st->pyr[l], st->w[l], st->h[l], l, row_tmp, cells,
                          &st->tpl[slot][l]);
    l = st->region_level;
    select_points(st->rk, st->pyr[l], st->w[l], st->h[l], l, row_tmp, cells, &st->tpl[slot][l]);
    select_region_points(st->pyr[l], st->w[l], st->h[l], l, cells, &st->regions[slot],
                         st->region_faint[slot], st->region_plain[slot]);
}

void home__refine_settle(home_context *ctx, int slot)
{
    home__refine_state *st = &ctx->refine;
    if (!st->levels || st->pending_slot < 0 || (slot >= 0 && slot != st->pending_slot)) return;
    select_templates(st, st->pending_slot);
    st->pending_slot = -1;
}

void home__refine_drop_pending(home_context *ctx)
{
    home__refine_state *st = &ctx->refine;
    if (!st->levels || st->pending_slot < 0) return;
    st->slot_id[st->pending_slot] = 0;
    st->pending_slot = -1;
}

void home__refine_keep(home_context *ctx, uint32_t frame_id)
{
    ctx->refine.keep_id = frame_id;
}

uint32_t home__refine_store(home_context *ctx, const uint8_t *image, ptrdiff_t stride, int defer)
{
    home__refine_state *st = &ctx->refine;
    int l, slot;
    int16_t *row_tmp;
    uint16_t *cells;
    if (!st->levels) return 0; /* refinement off: no scratch (arithmetic on NULL is undefined) */
    /* a deferred selection needs the pyramid about to be replaced (with image NULL the caller
     * settled it before filling the 2x2-mean frame, which shares its scratch) */
    if (image) home__refine_settle(ctx, -1);
    row_tmp = (int16_t *)st->scratch;
    cells = scratch_cells(st);
    if (st->base_level == 0) {
        st->rk->blur3(image, stride, st->pyr[0], st->w[0], st->w[0], st->h[0], row_tmp);
    } else {
        const uint8_t *half = (const uint8_t *)cells; /* free until the selection below */
        if (image) home__refine_half_rows(ctx, image, stride, 0, st->h[1]);
        st->rk->blur3(half, st->w[1], st->pyr[1], st->w[1], st->w[1], st->h[1], row_tmp);
    }
    for (l = st->base_level + 1; l < st->levels; l++)
        st->rk->downsample(st->pyr[l - 1], st->w[l - 1], st->pyr[l], st->w[l], st->w[l], st->h[l]);
    /* the id is a hash of the data: the same frame gets the same id, so outputs stay
     * deterministic, and features are tied to the snapshot they were extracted with */
    l = st->levels - 1;
    st->pyr_id = hash_bytes(st->pyr[l], (size_t)st->w[l] * (size_t)st->h[l]);
    slot = st->next_slot;
    if (st->keep_id && st->slot_id[slot] == st->keep_id) slot ^= 1;
    st->next_slot = slot ^ 1; /* slot then holds the latest frame, as the refinement expects */
    if (defer)
        st->pending_slot = slot;
    else
        select_templates(st, slot);
    store_background(st, slot);
    st->slot_id[slot] = st->pyr_id;
    return st->pyr_id;
}
