/* Texture-preserving Hough transform J(theta, r) = [sum of grad I along the line] . n(theta),
 * with nearest-pixel line summation, then Gaussian smoothing.
 *
 * EXACT (the paper's definition, the reference): since n(theta) is constant along a line,
 * J = cos(theta) R[Ix] + sin(theta) R[Iy], where R sums the exact integer gradients of the pixels
 * whose centre falls in the r bin (Q16 fixed-point bin index, so the bins are exact integers).
 *
 * FAST: for lines within 45 degrees of the columns (the rows of the transposed image for the
 * others), parametrise a line by its intercept j on the centre row and a slope t; row p holds
 * the line at column j + round(t (p - centre)). Integer line sums S(j) of the image itself over
 * such digital lines are a shear-and-add (contiguous SIMD adds, port/). Along a digital line,
 *   sum of Ix = S(j+1) - S(j-1)                (exactly, by shifting)
 *   sum of Iy = [I](entry..exit) - t sum of Ix (telescoping: d/dp I(line) = t Ix + Iy)
 * so J = (1/|a|) ((S(j+1) - S(j-1)) / a + 2 b [I]) with (a, b) = (cos, sin) or (sin, cos), where
 * 1/|a| turns the per-row sum into a line integral. Pixels beyond the image are taken as the
 * replicated border (zero gradient across the border, computed in closed form from prefix sums
 * of the border columns, not read), and [I] is taken between the line's real entry and exit
 * pixels, so the image frame creates no features. J is then resampled from the intercept grid
 * (spacing |a| px in r) to the uniform r axis by linear interpolation. */
#include "home_internal.h"
#include <math.h>
#include <string.h>

void home__hough_accumulate_row(const int16_t *gx, const int16_t *gy, int width, int height,
                                int32_t cos_q, int32_t sin_q, int32_t base_q, int32_t *acc_x,
                                int32_t *acc_y, int r_bins)
{
    int x, y;
    memset(acc_x, 0, (size_t)r_bins * sizeof *acc_x);
    memset(acc_y, 0, (size_t)r_bins * sizeof *acc_y);
    /* border rows and columns have zero gradient: skip them */
    for (y = 1; y < height - 1; y++) {
        const int16_t *rx = gx + (size_t)y * width, *ry = gy + (size_t)y * width;
        int32_t pos = (2 - (width - 1)) * cos_q + (2 * y - (height - 1)) * sin_q + base_q;
        for (x = 1; x < width - 1; x++) {
            int bin = pos >> 16;           /* pos > 0 by construction of base_q */
            acc_x[bin] += rx[x];
            acc_y[bin] += ry[x];
            pos += 2 * cos_q;
        }
    }
}

static void prefix_edges(home_context *ctx);
static void refill_geometry(home_context *ctx);

void home__hough_load_rows(home_context *ctx, const uint8_t *image, ptrdiff_t stride, int y0,
                           int y1)
{
    const int width = ctx->hough_w, pad = HOME__RADON_BLOCK, ds = ctx->hough_scale;
    int y;
    if (!ctx->geom_borrowed) ctx->geom_stale = 1; /* the configured pass: its buffers change */
    for (y = y0; y < y1; y++) {
        uint8_t *row = ctx->img_n + (ptrdiff_t)y * ctx->img_n_stride;
        memset(row, 0, (size_t)pad);
        if (ds > 1)
            ctx->kernels->box_down(image + (ptrdiff_t)(ds * y) * stride, stride, ds, row + pad,
                                   width);
        else
            memcpy(row + pad, image + (ptrdiff_t)y * stride, (size_t)width);
        memset(row + pad + width, 0, (size_t)pad);
    }
}

/* The image (box-downscaled when hough_downscale is 2 or 4) in the zero-padded buffers
 * (HOME__RADON_BLOCK columns each side) used by the shear-and-add kernel: img_n as is (loaded
 * here unless image is NULL), img_t transposed from it; then the border prefix sums. */
static void prepare_fast(home_context *ctx, const uint8_t *image, ptrdiff_t stride)
{
    const int width = ctx->hough_w, height = ctx->hough_h, pad = HOME__RADON_BLOCK;
    int x, y;
    if (image) home__hough_load_rows(ctx, image, stride, 0, height);
    for (x = 0; x < width; x++) {
        uint8_t *row = ctx->img_t + (ptrdiff_t)x * ctx->img_t_stride;
        memset(row, 0, (size_t)pad);
        memset(row + pad + height, 0, (size_t)pad);
    }
    for (y = 0; y < height; y++) {
        const uint8_t *src = ctx->img_n + (ptrdiff_t)y * ctx->img_n_stride + pad;
        uint8_t *dst = ctx->img_t + pad + y;
        for (x = 0; x < width; x++) dst[(ptrdiff_t)x * ctx->img_t_stride] = src[x];
    }
    prefix_edges(ctx);
}

/* The image a theta family reads, in processing order: its column 0 of row 0, the row step,
 * rows and columns. vertical: lines within 45 degrees of the columns (the image itself), else
 * the transposed image; flip: rows taken bottom to top. */
static const uint8_t *family_image(const home_context *ctx, int vertical, int flip,
                                   ptrdiff_t *stride, int *rows, int *cols)
{
    const ptrdiff_t img_stride = vertical ? ctx->img_n_stride : ctx->img_t_stride;
    const uint8_t *img = (vertical ? ctx->img_n : ctx->img_t) + HOME__RADON_BLOCK;
    *rows = vertical ? ctx->hough_h : ctx->hough_w;
    *cols = vertical ? ctx->hough_w : ctx->hough_h;
    *stride = flip ? -img_stride : img_stride;
    return flip ? img + (ptrdiff_t)(*rows - 1) * img_stride : img;
}

/* Prefix sums of the first and last column of a family's rows in processing order (the
 * replicated border's line sums), per frame for all four (vertical, flip): left, then right. */
static int32_t *edge_prefix(const home_context *ctx, int vertical, int flip)
{
    const int longest = ctx->hough_w > ctx->hough_h ? ctx->hough_w : ctx->hough_h;
    return ctx->edge_prefix + (ptrdiff_t)(2 * vertical + flip) * 2 * (longest + 1);
}

static void prefix_edges(home_context *ctx)
{
    const int longest = ctx->hough_w > ctx->hough_h ? ctx->hough_w : ctx->hough_h;
    int vertical, flip, p, rows, cols;
    ptrdiff_t stride;
    for (vertical = 0; vertical < 2; vertical++)
        for (flip = 0; flip < 2; flip++) {
            const uint8_t *base = family_image(ctx, vertical, flip, &stride, &rows, &cols);
            int32_t *left = edge_prefix(ctx, vertical, flip), *right = left + longest + 1;
            left[0] = right[0] = 0;
            for (p = 0; p < rows; p++) {
                const uint8_t *row = base + (ptrdiff_t)p * stride;
                left[p + 1] = left[p] + row[0];
                right[p + 1] = right[p] + row[cols - 1];
            }
        }
}

/* first row (in processing order) whose shift is >= v; shifts are nondecreasing */
static int first_row_at(const home__theta_geom *g, const int32_t *first_row, int v, int rows)
{
    if (v <= g->s_min) return 0;
    if (v > g->s_max) return rows;
    return first_row[v - g->s_min];
}

void home__hough_raw_rows(const home_config *cfg, int radius, int *first, int *count)
{
    /* the stream's smoothed rows run from -3 to theta_bins + 2 (wrap and descriptor margin) */
    *first = -3 - radius;
    *count = cfg->theta_bins + 6 + 2 * radius;
}

void home__theta_geometry(const home_context *ctx, double theta, home__theta_geom *g)
{
    const double c = cos(theta), s = sin(theta);
    const int vertical = fabs(c) >= fabs(s);
    const int rows = vertical ? ctx->hough_h : ctx->hough_w;
    const int cols = vertical ? ctx->hough_w : ctx->hough_h;
    const double a = vertical ? c : s, b = vertical ? s : c, t = -b / a;
    const int flip = t < 0.0; /* process rows so that shifts are nondecreasing */
    const double centre = 0.5 * (rows - 1), inv_abs_a = 1.0 / fabs(a);
    const double t_processed = flip ? -t : t;
    int32_t *first_row = ctx->first_row;
    int p, v, blk, n, j0, s_min, s_max;

    g->vertical = vertical;
    g->flip = flip;
    for (p = 0; p < rows; p++) {
        /* row rows-1-p in original order: t (centre - p) == -t (p - centre) exactly */
        double x = t_processed * (p - centre) + 0.5;
        int k = (int)x;
        g->shift[p] = (int16_t)(k > x ? k - 1 : k); /* floor without a libm call */
    }
    s_min = g->s_min = g->shift[0];
    s_max = g->s_max = g->shift[rows - 1];
    /* first_row[v - s_min]: first row whose shift is >= v, for v in [s_min, s_max + 1]. Stored
     * from the last row back, each value's first row is the one left; the shift grows by at
     * most one a row (|t| <= 1) but for rounding, so a value no row has (rows before it: -1)
     * takes the next value's. No branch on the data in the common case. */
    for (v = 0; v <= s_max - s_min; v++) first_row[v] = -1;
    for (p = rows - 1; p >= 0; p--) first_row[g->shift[p] - s_min] = p;
    first_row[s_max - s_min + 1] = rows;
    for (v = s_max - s_min; v > 0; v--)
        if (first_row[v] < 0) first_row[v] = first_row[v + 1];
    /* intercepts of every line touching the image, plus one on each side for S(j +- 1) */
    j0 = g->j0 = -s_max - 1;
    n = g->n = cols - s_min - j0 + 1;
    g->n_blocks = (n + HOME__RADON_BLOCK - 1) / HOME__RADON_BLOCK;
    for (blk = 0; blk < g->n_blocks; blk++) {
        int jb = j0 + blk * HOME__RADON_BLOCK;
        g->row_lo[blk] =
            (int16_t)first_row_at(g, first_row, -jb - (HOME__RADON_BLOCK - 1), rows);
        g->row_hi[blk] = (int16_t)(first_row_at(g, first_row, cols - jb, rows) - 1);
    }
    {
        /* each intercept's entry row (rows before it lie left of the image) and the row after
         * its exit (from there on right of it); lines through every row: 0 and rows */
        const int span = s_max - s_min + 1, in_span = span + 1 < n ? span + 1 : n;
        const int before_exit = cols < n ? cols : n;
        const int16_t from_first = (int16_t)first_row[0], through_last =
                                                              (int16_t)first_row[span];
        int i;
        /* with j0 = -s_max - 1, intercept i enters at shift value span - i (clamped at 0: from
         * the first row) and leaves at cols + span - i (clamped at span: through the last
         * row), never below 0 (n = cols + span): runs of one value and reversed copies */
        for (i = 0; i < in_span; i++) g->entry[i] = (int16_t)first_row[span - i];
        for (; i < n; i++) g->entry[i] = from_first;
        for (i = 0; i < before_exit; i++) g->after[i] = through_last;
        for (; i < n; i++) g->after[i] = (int16_t)first_row[cols + span - i];
    }
    g->d_scale = (float)(inv_abs_a / a);
    g->end_scale = (float)((flip ? -2.0 * b : 2.0 * b) * inv_abs_a); /* [I] in original row order */
    {
        /* r bin i sits at intercept index jf = (i - r_centre) step / a + (cols-1)/2 - j0; the
         * bins with jf in [0, n - 1) are a contiguous range (jf is monotonic in i), zero elsewhere
         */
        const double dj = ctx->cfg.r_step / a;
        const double jf0 = -0.5 * (ctx->r_bins - 1) * dj + 0.5 * (cols - 1) - j0;
        const double last = (double)(n - 1);
        const int r_bins = ctx->r_bins;
        double lo = dj > 0 ? -jf0 / dj : (last - jf0) / dj;
        int i_lo = lo <= 0 ? 0 : lo >= r_bins ? r_bins : (int)lo, i_hi, i;
#define IN_LINE(bin) (jf0 + (bin) * dj >= 0.0 && jf0 + (bin) * dj < last)
        /* the estimate is within a bin or two: settle it with the exact test */
        while (i_lo > 0 && IN_LINE(i_lo - 1)) i_lo--;
        while (i_lo < r_bins && !IN_LINE(i_lo)) i_lo++;
        i_hi = i_lo;
        if (i_lo < r_bins) {
            double hi = dj > 0 ? (last - jf0) / dj : -jf0 / dj;
            i_hi = hi <= i_lo ? i_lo + 1 : hi >= r_bins ? r_bins : (int)hi;
            while (i_hi < r_bins && IN_LINE(i_hi)) i_hi++;
            while (i_hi > i_lo + 1 && !IN_LINE(i_hi - 1)) i_hi--;
        }
#undef IN_LINE
        g->i_lo = i_lo;
        g->i_hi = i_hi;
        for (i = i_lo; i < i_hi; i++) {
            double jf = jf0 + i * dj;
            int k = (int)jf; /* jf >= 0: truncation is floor */
            g->res_k[i - i_lo] = (int16_t)k;
            g->res_f[i - i_lo] = (float)(jf - k);
        }
    }
}

/* One theta row of J, unsmoothed, on the uniform r axis. */
static void fast_theta_row(home_context *ctx, const home__theta_geom *g, float *out)
{
    const int longest = ctx->hough_w > ctx->hough_h ? ctx->hough_w : ctx->hough_h;
    const int16_t *shift = g->shift;
    const int s_min = g->s_min, s_max = g->s_max, j0 = g->j0, n = g->n;
    const int32_t *left = edge_prefix(ctx, g->vertical, g->flip), *right = left + longest + 1;
    int32_t *sum = ctx->line_sum;
    float *line = ctx->line_j;
    ptrdiff_t stride;
    int rows, cols, i;
    const uint8_t *base = family_image(ctx, g->vertical, g->flip, &stride, &rows, &cols);

    ctx->kernels->radon_blocks(base, stride, shift, j0, g->n_blocks, g->row_lo, g->row_hi, sum);
    {
        /* lines through every row (entry 0, exit rows - 1), [mid_lo, mid_hi): no border term,
         * and their end pixels lie on two contiguous rows; the others cross a side of the
         * image: the replicated border's share (the rows outside it) and their own ends */
        const int mid_lo = -s_min - j0, mid_hi = cols - s_max - j0;
        const uint8_t *first_row_px = base + shift[0];
        const uint8_t *last_row_px = base + (ptrdiff_t)(rows - 1) * stride + shift[rows - 1];
        const int32_t right_total = right[rows];
        if (mid_lo < mid_hi) {
            ctx->kernels->line_ends(base, stride, shift, j0, g->entry, g->after, left, right,
                                    right_total, 0, mid_lo, sum, line);
            for (i = mid_lo; i < mid_hi; i++)
                line[i] = (float)(last_row_px[j0 + i] - first_row_px[j0 + i]);
            ctx->kernels->line_ends(base, stride, shift, j0, g->entry, g->after, left, right,
                                    right_total, mid_hi, n, sum, line);
        } else {
            ctx->kernels->line_ends(base, stride, shift, j0, g->entry, g->after, left, right,
                                    right_total, 0, n, sum, line);
        }
    }
    /* J on the intercept grid (in place over the end terms), then resampled to the r axis */
    {
        const float d_scale = g->d_scale, end_scale = g->end_scale;
        for (i = 1; i < n - 1; i++)
            line[i] = d_scale * (float)(sum[i + 1] - sum[i - 1]) + end_scale * line[i];
        line[0] = line[n - 1] = 0.0f;
    }
    {
        const int r_bins = ctx->r_bins, i_lo = g->i_lo, i_hi = g->i_hi;
        for (i = 0; i < i_lo; i++) out[i] = 0.0f;
        ctx->kernels->resample(line, g->res_k, g->res_f, i_hi - i_lo, out + i_lo);
        for (i = i_hi; i < r_bins; i++) out[i] = 0.0f;
    }
}

double home__hough_stream(home_context *ctx, const uint8_t *image, ptrdiff_t stride,
                          home__row_fn on_row, void *user)
{
    const int n_theta = ctx->cfg.theta_bins, r_bins = ctx->r_bins, radius = ctx->smooth_radius;
    const int width = ctx->cfg.width, height = ctx->cfg.height;
    const int first_smooth = -3;
    const int raw_ring = 2 * radius + 1;
    const double scale = 32768.0 / ctx->cfg.r_step; /* Q16 over doubled coordinates */
    const int32_t base_q = (int32_t)(r_bins / 2) * 65536;
    const float *raw_window[2 * HOME__MAX_SMOOTH_RADIUS + 1];
    const float *window[HOME__DESC_ROWS];
    double t0 = home__now(ctx), spent = 0.0;
    int k, i, first_raw, n_raw, slot, oldest;

    const int exact = ctx->cfg.hough_method == HOME_HOUGH_EXACT;
    if (exact) {
        home__gradient(image, stride, width, height, ctx->grad_x, ctx->grad_y);
    } else {
        prepare_fast(ctx, image, stride);
        if (ctx->geom_borrowed && ctx->geom_stale) refill_geometry(ctx);
    }
    home__hough_raw_rows(&ctx->cfg, radius, &first_raw, &n_raw);
    for (k = first_raw, slot = 0; k < first_raw + n_raw; k++) {
        const double theta = k * HOME__PI / n_theta;
        float *raw = ctx->raw_rows + (size_t)slot * r_bins; /* slot = (k - first_raw) % ring */
        int j;
        slot = slot + 1 < raw_ring ? slot + 1 : 0; /* from here on, the oldest row's */
        if (exact) {
            const double c = cos(theta), s = sin(theta);
            home__hough_accumulate_row(ctx->grad_x, ctx->grad_y, width, height,
                                       (int32_t)lround(c * scale), (int32_t)lround(s * scale),
                                       base_q, ctx->acc_x, ctx->acc_y, r_bins);
            for (i = 0; i < r_bins; i++)
                ctx->row_tmp[i] = (float)(c * ctx->acc_x[i] + s * ctx->acc_y[i]);
        } else {
            home__theta_geom *g = &ctx->geom_scratch;
            if (k - first_raw < ctx->geom_rows)
                g = &ctx->geom[k - first_raw];
            else
                home__theta_geometry(ctx, theta, g);
            fast_theta_row(ctx, g, ctx->row_tmp);
        }
        home__smooth_r(ctx->kernels, ctx->row_tmp, raw, r_bins, ctx->smooth_taps, radius);
        if (k - first_raw < 2 * radius) continue;

        j = k - radius; /* the theta-smoothed row now complete */
        /* rows k - 2 radius .. k, the oldest (in the slot after k's) first */
        for (i = 0, oldest = slot; i < raw_ring; i++) {
            raw_window[i] = ctx->raw_rows + (size_t)oldest * r_bins;
            oldest = oldest + 1 < raw_ring ? oldest + 1 : 0;
        }
        home__smooth_theta(ctx->kernels, raw_window,
                           ctx->smooth_rows +
                               (size_t)((j - first_smooth) % HOME__DESC_ROWS) * r_bins,
                           r_bins, ctx->smooth_taps, radius);
        for (i = 0; i < HOME__DESC_ROWS; i++) {
            int row = j - (HOME__DESC_ROWS - 1) + i;
            window[i] = row < first_smooth ? NULL
                : ctx->smooth_rows + (size_t)((row - first_smooth) % HOME__DESC_ROWS) * r_bins;
        }
        {
            double t1 = home__now(ctx);
            on_row(user, j, window);
            t0 += home__now(ctx) - t1; /* exclude the consumer's time */
        }
    }
    spent = home__now(ctx) - t0;
    return spent;
}

/* The Hough stage's block of the arena: offsets from its start, each on a HOME__BLOCK_ALIGN
 * boundary. EXACT: the gradients; FAST: the image and its transpose, the theta rows' geometry
 * (every row's when it fits HOME_HOUGH_GEOMETRY_BYTES, else one scratch record) and the
 * first_row table its computation uses, line sums, border prefix sums and J over the
 * intercepts. Both: one theta row's sums, the smoothing rings. */
typedef struct hough_layout {
    size_t grad_x, grad_y, img_n, img_t, img_end, geom, geom_scratch, first_row, line_sum,
        edge_prefix, line_j;
    size_t acc_x, acc_y, raw_rows, smooth_rows, row_tmp, total;
    size_t geom_bytes;                /* one record's arrays */
    size_t geom_intercepts;           /* a row's intercepts, without the kernel's block slack */
    ptrdiff_t img_n_stride, img_t_stride;
    int geom_rows, geom_first;        /* raw theta rows cached (0: none) and the first's k */
    int geom_rows_all;                /* raw theta rows */
    int geom_longest, geom_blocks;
} hough_layout;

/* Bytes of one theta geometry record's arrays, each on a 16-byte boundary. */
static size_t geom_record_bytes(int longest, int blocks, size_t intercepts, size_t r_bins)
{
    return home__align_up(((size_t)longest + 1) * sizeof(int16_t), 16) +
           2 * home__align_up((size_t)blocks * sizeof(int16_t), 16) +
           2 * home__align_up(intercepts * sizeof(int16_t), 16) +
           home__align_up(r_bins * sizeof(int16_t), 16) +
           home__align_up(r_bins * sizeof(float), 16);
}

/* Point a record's arrays into mem (geom_record_bytes of it). */
static void carve_geom(home__theta_geom *g, unsigned char *mem, int longest, int blocks,
                       size_t intercepts, size_t r_bins)
{
    g->shift = (int16_t *)(void *)mem; /* + 1: line_ends may read a word at the last row */
    mem += home__align_up(((size_t)longest + 1) * sizeof(int16_t), 16);
    g->row_lo = (int16_t *)(void *)mem;
    mem += home__align_up((size_t)blocks * sizeof(int16_t), 16);
    g->row_hi = (int16_t *)(void *)mem;
    mem += home__align_up((size_t)blocks * sizeof(int16_t), 16);
    g->entry = (int16_t *)(void *)mem;
    mem += home__align_up(intercepts * sizeof(int16_t), 16);
    g->after = (int16_t *)(void *)mem;
    mem += home__align_up(intercepts * sizeof(int16_t), 16);
    g->res_k = (int16_t *)(void *)mem;
    mem += home__align_up(r_bins * sizeof(int16_t), 16);
    g->res_f = (float *)(void *)mem;
}

static void hough_plan(const home_config *cfg, hough_layout *l)
{
    size_t cur = 0, pixels = (size_t)cfg->width * (size_t)cfg->height;
    size_t r_bins = (size_t)home__r_bins(cfg);
    size_t radius = (size_t)ceil(3.0 * cfg->smooth_sigma); /* as home__gauss_taps() */
    int hough_w, hough_h;
    size_t w, h, longest, intercepts;
    if (radius > HOME__MAX_SMOOTH_RADIUS) radius = HOME__MAX_SMOOTH_RADIUS;
    home__hough_size(cfg, &hough_w, &hough_h);
    w = (size_t)hough_w;
    h = (size_t)hough_h;
    longest = w > h ? w : h;
    /* intercepts of one theta row: the other side + both shear extents + derivative + a block */
    intercepts = w + h + 8 + 2 * HOME__RADON_BLOCK;
    memset(l, 0, sizeof *l);
    if (cfg->hough_method == HOME_HOUGH_EXACT) {
        l->grad_x = home__take(&cur, pixels * sizeof(int16_t));
        l->grad_y = home__take(&cur, pixels * sizeof(int16_t));
    } else {
        int rows;
        size_t bytes;
        l->img_n_stride = (ptrdiff_t)(w + 2 * HOME__RADON_BLOCK);
        l->img_t_stride = (ptrdiff_t)(h + 2 * HOME__RADON_BLOCK);
        l->img_n = home__take(&cur, h * (size_t)l->img_n_stride);
        l->img_t = home__take(&cur, w * (size_t)l->img_t_stride);
        l->img_end = l->img_t + w * (size_t)l->img_t_stride;
        l->geom_longest = (int)longest;
        l->geom_blocks = (int)(intercepts / HOME__RADON_BLOCK + 1);
        l->geom_intercepts = w + h + 8;
        l->geom_bytes = geom_record_bytes(l->geom_longest, l->geom_blocks, l->geom_intercepts,
                                          r_bins);
        home__hough_raw_rows(cfg, (int)radius, &l->geom_first, &rows);
        l->geom_rows_all = rows;
        bytes = home__align_up((size_t)rows * sizeof(home__theta_geom), 16) +
                (size_t)rows * l->geom_bytes;
        if (bytes <= HOME_HOUGH_GEOMETRY_BYTES) {
            l->geom_rows = rows;
            l->geom = home__take(&cur, bytes);
        } else {
            l->geom_scratch = home__take(&cur, l->geom_bytes);
        }
        l->first_row = home__take(&cur, (longest + 4) * sizeof(int32_t));
        l->line_sum = home__take(&cur, (intercepts + HOME__RADON_BLOCK) * sizeof(int32_t));
        l->edge_prefix = home__take(&cur, 4 * 2 * (longest + 1) * sizeof(int32_t));
        l->line_j = home__take(&cur, (intercepts + HOME__RADON_BLOCK) * sizeof(float));
    }
    l->acc_x = home__take(&cur, r_bins * sizeof(int32_t));
    l->acc_y = home__take(&cur, r_bins * sizeof(int32_t));
    l->raw_rows = home__take(&cur, (2 * radius + 1) * r_bins * sizeof(float));
    l->smooth_rows = home__take(&cur, HOME__DESC_ROWS * r_bins * sizeof(float));
    l->row_tmp = home__take(&cur, r_bins * sizeof(float));
    l->total = home__align_up(cur, HOME__BLOCK_ALIGN);
}

void home__select_pass(home_context *ctx, int k)
{
    const home__pass *p = &ctx->passes[k];
    ctx->cfg = p->cfg;
    ctx->config_id = p->config_id;
    ctx->r_bins = p->r_bins;
    ctx->hough_w = p->hough_w;
    ctx->hough_h = p->hough_h;
    ctx->hough_scale = p->hough_scale;
    ctx->hough_dx = p->hough_dx;
    ctx->hough_dy = p->hough_dy;
    ctx->img_n = p->img_n;
    ctx->img_t = p->img_t;
    ctx->img_n_stride = p->img_n_stride;
    ctx->img_t_stride = p->img_t_stride;
    ctx->geom = p->geom;
    ctx->geom_rows = p->geom_rows;
    ctx->geom_borrowed = p->geom_borrowed;
}

/* Bytes of a pass's cached theta geometry (0: none, rows computed one at a time) */
static size_t geom_table_bytes(const hough_layout *l)
{
    return l->geom_rows ? home__align_up((size_t)l->geom_rows * sizeof(home__theta_geom), 16) +
                              (size_t)l->geom_rows * l->geom_bytes
                        : 0;
}

/* The buffers are the configured pass's; a fast pass (smaller in every dimension) shares them
 * and adds only its own cached geometry, after them. */
size_t home__hough_bytes(const home_config *cfg)
{
    hough_layout l, f;
    home_config fast;
    hough_plan(cfg, &l);
    if (!home__fast_pass_config(cfg, &fast)) return l.total;
    hough_plan(&fast, &f);
    return home__align_up(l.total + geom_table_bytes(&f), HOME__BLOCK_ALIGN);
}

/* The live pass's theta geometry for its first `rows` raw theta rows: the records at table,
 * then their arrays (l's sizes) */
static void fill_geometry(home_context *ctx, unsigned char *table, const hough_layout *l, int rows)
{
    unsigned char *arrays = table + home__align_up((size_t)rows * sizeof(home__theta_geom), 16);
    int k;
    ctx->geom = (home__theta_geom *)(void *)table;
    ctx->geom_rows = rows;
    for (k = 0; k < rows; k++) {
        carve_geom(&ctx->geom[k], arrays + (size_t)k * l->geom_bytes, l->geom_longest,
                   l->geom_blocks, l->geom_intercepts, (size_t)ctx->r_bins);
        home__theta_geometry(ctx, (l->geom_first + k) * HOME__PI / ctx->cfg.theta_bins,
                             &ctx->geom[k]);
    }
}

/* The fast pass's borrowed geometry anew, after the configured pass overwrote it */
static void refill_geometry(home_context *ctx)
{
    hough_layout l;
    hough_plan(&ctx->cfg, &l);
    fill_geometry(ctx, (unsigned char *)ctx->geom, &l, ctx->geom_rows);
    ctx->geom_stale = 0;
}

/* The fast pass's buffers where the configured pass has its image buffers (which the fast pass
 * does not otherwise use): its image and transpose first, then as many geometry records as fit
 * the rest. block: the Hough block; l, f: the configured and the fast pass's layouts. */
static void borrow_image_buffers(home_context *ctx, unsigned char *block, const hough_layout *l,
                                 const hough_layout *f)
{
    home__pass *fast = &ctx->passes[1];
    size_t at = l->img_n, record = sizeof(home__theta_geom) + f->geom_bytes, room;
    int rows;
    fast->img_n = block + at;
    at = home__align_up(at + (size_t)fast->hough_h * (size_t)f->img_n_stride, HOME__BLOCK_ALIGN);
    fast->img_t = block + at;
    at = home__align_up(at + (size_t)fast->hough_w * (size_t)f->img_t_stride, HOME__BLOCK_ALIGN);
    room = at + 16 < l->img_end ? l->img_end - at - 16 : 0; /* 16: the records' alignment */
    rows = (int)(room / record < (size_t)f->geom_rows_all ? room / record
                                                          : (size_t)f->geom_rows_all);
    if (rows <= 0) return;
    home__select_pass(ctx, 1);
    fill_geometry(ctx, block + at, f, rows);
    home__select_pass(ctx, 0);
    fast->geom = (home__theta_geom *)(void *)(block + at);
    fast->geom_rows = rows;
    fast->geom_borrowed = 1;
}

void home__hough_init(home_context *ctx, unsigned char *block)
{
    const home_config *cfg = &ctx->cfg;
    hough_layout l;
    hough_plan(cfg, &l);
    ctx->smooth_radius = home__gauss_taps(cfg->smooth_sigma, ctx->smooth_taps);
    if (cfg->hough_method == HOME_HOUGH_EXACT) {
        ctx->grad_x = (int16_t *)(void *)(block + l.grad_x);
        ctx->grad_y = (int16_t *)(void *)(block + l.grad_y);
    } else {
        ctx->img_n = block + l.img_n;
        ctx->img_t = block + l.img_t;
        ctx->first_row = (int32_t *)(void *)(block + l.first_row);
        ctx->img_n_stride = l.img_n_stride;
        ctx->img_t_stride = l.img_t_stride;
        if (l.geom_rows) {
            /* records first, then their arrays; every row's geometry computed once, here */
            fill_geometry(ctx, block + l.geom, &l, l.geom_rows);
        } else {
            ctx->geom = NULL;
            ctx->geom_rows = 0;
            carve_geom(&ctx->geom_scratch, block + l.geom_scratch, l.geom_longest, l.geom_blocks,
                       l.geom_intercepts, (size_t)ctx->r_bins);
        }
        ctx->line_sum = (int32_t *)(void *)(block + l.line_sum);
        ctx->edge_prefix = (int32_t *)(void *)(block + l.edge_prefix);
        ctx->line_j = (float *)(void *)(block + l.line_j);
    }
    ctx->acc_x = (int32_t *)(void *)(block + l.acc_x);
    ctx->acc_y = (int32_t *)(void *)(block + l.acc_y);
    ctx->raw_rows = (float *)(void *)(block + l.raw_rows);
    ctx->smooth_rows = (float *)(void *)(block + l.smooth_rows);
    ctx->row_tmp = (float *)(void *)(block + l.row_tmp);
    ctx->passes[0].img_n = ctx->img_n;
    ctx->passes[0].img_t = ctx->img_t;
    ctx->passes[0].img_n_stride = ctx->img_n_stride;
    ctx->passes[0].img_t_stride = ctx->img_t_stride;
    ctx->passes[0].geom = ctx->geom;
    ctx->passes[0].geom_rows = ctx->geom_rows;
    if (ctx->n_passes > 1) {
        /* the fast pass: its strides in the shared buffers, its own geometry after them, or
         * what fits in the configured pass's image buffers (the rest per row in the shared
         * scratch record, which the configured pass's larger sizes carved) */
        home__pass *fast = &ctx->passes[1];
        hough_layout f;
        hough_plan(&fast->cfg, &f);
        fast->img_n = ctx->img_n;
        fast->img_t = ctx->img_t;
        fast->img_n_stride = f.img_n_stride;
        fast->img_t_stride = f.img_t_stride;
        if (f.geom_rows) {
            home__select_pass(ctx, 1);
            fill_geometry(ctx, block + l.total, &f, f.geom_rows);
            home__select_pass(ctx, 0);
            fast->geom = (home__theta_geom *)(void *)(block + l.total);
            fast->geom_rows = f.geom_rows;
        } else {
            borrow_image_buffers(ctx, block, &l, &f);
        }
    }
}
