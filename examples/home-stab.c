/* home-stab: offline stabilisation of a Y4M stream (4:2:0, 4:2:2 or mono) with libhome.
 *   ffmpeg -i in.mp4 -f yuv4mpegpipe - | home-stab - - | ffmpeg -i - out.mp4
 * The output has the input's size: the crop window is scaled to fill the frame.
 * With --threads 2 a second thread warps and writes frame t while the first reads and registers
 * the next ones: the same bytes out, sooner, for some more CPU time (bench/stab/README.md). */
#define _POSIX_C_SOURCE 200809L
#include "home_stab.h"
#include "stab_png.h"
#include "y4m.h"
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* A file has no latency constraint: 30 frames of lookahead (a 15-frame time constant) leave
 * about 30 % less jitter than 15 and keep the eased stream ends (docs/stabiliser.md, "Defaults
 * per tool"); latency 0 is --lookahead 0. */
#define HOME_STAB_FILE_LOOKAHEAD 30

static double now_ms(void *user)
{
    struct timespec ts;
    (void)user;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: home-stab [options] IN.y4m OUT.y4m      (- for stdin / stdout)\n"
            "  --margin F        crop margin per side, fraction of the frame (default 0.10)\n"
            "  --margin-x F, --margin-y F  the left/right margin (fraction of the width) and the\n"
            "                    top/bottom one (of the height) apart; unequal margins change the\n"
            "                    picture's aspect\n"
            "  --smoothing F     path smoothing time constant, frames (default: lookahead / 2, at\n"
            "                    least 3; 15 with a lookahead below 5 or none)\n"
            "  --lookahead N     frames of latency for fixed-lag smoothing (default 30: a file\n"
            "                    has no latency constraint; 0 = causal, as a live camera)\n"
            "  --ease F          with a lookahead: share of the pan given up at the clip's ends,\n"
            "                    0 (keep panning) .. 1 (start from and come to rest); default 1\n"
            "  --downscale N     register on luma downscaled by 1, 2 or 4 (default: 2 above 960 px)\n"
            "  --keypoints N     HOME keypoints per sign (default 500)\n"
            "  --no-refine       skip HOME's photometric refinement of each registration\n"
            "  --refine-finest L end the refinement at full (0) or half (1) size (default 1)\n"
            "  --no-key-frames   do not register frames that leave a part unexplained (an object\n"
            "                    crossing, a hand) against the frame before it came (less memory)\n"
            "  --hough-downscale N  HOME's Hough transform on the registration image (1) or on\n"
            "                    its 1/2 or 1/4 size copy (2, 4; default: 4 down to 96 px wide,\n"
            "                    else 2 from 320 px)\n"
            "  --theta-bins N    HOME's theta bins (16..%d; default 88)\n"
            "  --fixed-crop      crop by the whole margins; the default for a file IN is two\n"
            "                    passes over it with the smallest share of the margins that every\n"
            "                    frame's whole correction needs (less zoom where the shake is\n"
            "                    small, never a border; a pipe always gets the whole margins)\n"
            "  --side-by-side    write original | stabilised, twice as wide\n"
            "  --csv FILE        per frame: raw and smoothed camera path (tx, ty px, angle rad,\n"
            "                    log scale), share of the correction applied, and the warp\n"
            "                    (output pixel -> input pixel, affine, w00..w12), and the frame's\n"
            "                    registration: its motion model and predicted error sigma_px\n"
            "                    (px of the registration image; an uncertain motion pulls less)\n"
            "  --plot FILE.png   plot of the raw and smoothed path\n"
            "  --threads N       1 (default): register, warp and write in turn; 2: warp and write\n"
            "                    on a second thread, overlapping the next registrations (same output)\n"
            "  --quiet           no progress on stderr\n"
            "Exit: 0 ok; 1 input ended with a malformed or truncated frame (the frames before it\n"
            "are written); 2 bad usage or unreadable input.\n", HOME_MAX_THETA_BINS);
}

static int number(const char *s, double lo, double hi, double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (*end || end == s || !(v >= lo && v <= hi)) return -1;
    *out = v;
    return 0;
}

/* Outputs waiting for the writer thread; a few suffice: registration is the slower half. */
#define WRITE_QUEUE 4

/* What the CSV reports of a frame's registration (the frame is written lookahead frames later). */
typedef struct reg_info {
    int inliers, model;           /* model: enum home_model */
    double sigma_px;              /* predicted RMS corner error, registration px (inf: none) */
} reg_info;

/* The adaptive crop (a file's default): what the first pass keeps of every frame's output. */
typedef struct planned {
    home_stab_sim raw, smooth;
    int status;
    reg_info reg;
} planned;

typedef struct plan {
    planned *frames;
    long n, capacity;
} plan;

static int plan_add(plan *p, const home_stab_output *o, const reg_info *reg)
{
    if (p->n == p->capacity) {
        long cap = p->capacity ? 2 * p->capacity : 256;
        planned *grown = realloc(p->frames, (size_t)cap * sizeof *grown);
        if (!grown) { fprintf(stderr, "home-stab: out of memory\n"); return -1; }
        p->frames = grown;
        p->capacity = cap;
    }
    p->frames[p->n].raw = o->raw;
    p->frames[p->n].smooth = o->smooth;
    p->frames[p->n].status = o->motion_status;
    p->frames[p->n].reg = *reg;
    p->n++;
    return 0;
}

typedef struct app {
    y4m_info info;
    FILE *out, *csv;
    int side_by_side, quiet;
    size_t frame_bytes;
    uint8_t **ring;               /* lookahead + 1 input frames, + WRITE_QUEUE with a writer thread */
    const uint8_t **frame;        /* per ring slot: its frame, in `ring` or in `map` */
    y4m_map map;                  /* a file input, mapped (map.base NULL: read into `ring`) */
    int ring_len;
    uint8_t *result, *wide;
    reg_info *reg;                /* per ring slot: the frame's registration */
    stab_path_plot plot;
    long written;                 /* frames written (by the writer thread when there is one) */
    double ms_warp;               /* time in write_output(): warp, side by side, write */
    /* the writer thread: the reader queues outputs (the queue's bound keeps ring slots from
     * being reused before their frame is written); everything write_output() touches belongs
     * to the writer meanwhile */
    int threaded, closed, failed;
    pthread_t writer;
    pthread_mutex_t lock;
    pthread_cond_t changed;
    home_stab_output queue[WRITE_QUEUE];
    long queued;                  /* outputs handed to the writer; it has written `written` */
} app;

static const char *status_name(int s)
{
    static const char *names[] = {"first", "ok", "failed", "implausible", "cut",
                                  "still", "restored", "partial", "bridged"};
    return s >= 0 && s < (int)(sizeof names / sizeof names[0]) ? names[s] : "?";
}

/* Copy the planes of a (w x h) frame into the left or right half of a 2w-wide frame. */
static void place(const y4m_info *info, const uint8_t *src, uint8_t *wide, int right)
{
    home_stab_image a, b;
    int k, row, rows, bytes;
    y4m_image(info, info->width, (uint8_t *)src, &a);
    y4m_image(info, 2 * info->width, wide, &b);
    for (k = 0; k < 3 && a.plane[k]; k++) {
        rows = k && info->chroma == 420 ? info->height / 2 : info->height;
        bytes = (int)a.stride[k];
        for (row = 0; row < rows; row++)
            memcpy(b.plane[k] + row * b.stride[k] + (right ? bytes : 0), a.plane[k] + row * a.stride[k], (size_t)bytes);
    }
}

static int write_output(app *ap, const home_stab_output *o)
{
    const uint8_t *src = ap->frame[o->frame % ap->ring_len];
    home_stab_image in, out;
    int status;
    double t0 = now_ms(NULL);
    y4m_image(&ap->info, ap->info.width, (uint8_t *)src, &in);
    y4m_image(&ap->info, ap->info.width, ap->result, &out);
    status = home_stab_warp(o->warp, &in, &out);
    if (status != HOME_OK) {
        fprintf(stderr, "home-stab: warp: %s\n", home_strerror(status));
        return -1;
    }
    if (ap->side_by_side) {
        place(&ap->info, src, ap->wide, 0);
        place(&ap->info, ap->result, ap->wide, 1);
    }
    if (y4m_write_frame(ap->out, ap->side_by_side ? ap->wide : ap->result,
                        ap->side_by_side ? 2 * ap->frame_bytes : ap->frame_bytes)) {
        fprintf(stderr, "home-stab: write error\n");
        return -1;
    }
    if (ap->csv) {
        const reg_info *reg = &ap->reg[o->frame % ap->ring_len];
        fprintf(ap->csv, "%ld,%s,%d,%.4f,%.4f,%.6f,%.6f,%.4f,%.4f,%.6f,%.6f,%.4f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%s,%.4g\n",
                o->frame, status_name(o->motion_status), reg->inliers, o->raw.tx,
                o->raw.ty, o->raw.angle, o->raw.log_scale, o->smooth.tx, o->smooth.ty,
                o->smooth.angle, o->smooth.log_scale, o->correction_used, o->warp[0], o->warp[1],
                o->warp[2], o->warp[3], o->warp[4], o->warp[5],
                o->frame ? home_model_name(reg->model) : "none", o->frame ? reg->sigma_px : 0.0);
    }
    stab_plot_add(&ap->plot, &o->raw, &o->smooth);
    ap->ms_warp += now_ms(NULL) - t0;
    return 0;
}

static void *writer_main(void *arg)
{
    app *ap = arg;
    pthread_mutex_lock(&ap->lock);
    for (;;) {
        home_stab_output o;
        int bad;
        while (ap->written == ap->queued && !ap->closed) pthread_cond_wait(&ap->changed, &ap->lock);
        if (ap->written == ap->queued) break;   /* closed and drained */
        o = ap->queue[ap->written % WRITE_QUEUE];
        pthread_mutex_unlock(&ap->lock);
        bad = write_output(ap, &o);
        pthread_mutex_lock(&ap->lock);
        if (bad) { ap->failed = 1; pthread_cond_broadcast(&ap->changed); break; }
        ap->written++;                           /* frees its queue entry and ring slot */
        pthread_cond_broadcast(&ap->changed);
    }
    pthread_mutex_unlock(&ap->lock);
    return NULL;
}

/* Write o's frame, or hand it to the writer thread (waiting while its queue is full). */
static int emit_output(app *ap, const home_stab_output *o)
{
    int bad;
    if (!ap->threaded) {
        if (write_output(ap, o)) return -1;
        ap->written++;
        return 0;
    }
    pthread_mutex_lock(&ap->lock);
    while (!ap->failed && ap->queued - ap->written >= WRITE_QUEUE) pthread_cond_wait(&ap->changed, &ap->lock);
    if (!(bad = ap->failed)) {
        ap->queue[ap->queued % WRITE_QUEUE] = *o;
        ap->queued++;
        pthread_cond_broadcast(&ap->changed);
    }
    pthread_mutex_unlock(&ap->lock);
    return bad ? -1 : 0;
}

/* Let the writer drain its queue and end; 0 when everything queued was written. */
static int finish_writer(app *ap)
{
    if (!ap->threaded) return 0;
    pthread_mutex_lock(&ap->lock);
    ap->closed = 1;
    pthread_cond_broadcast(&ap->changed);
    pthread_mutex_unlock(&ap->lock);
    pthread_join(ap->writer, NULL);
    pthread_cond_destroy(&ap->changed);
    pthread_mutex_destroy(&ap->lock);
    ap->threaded = 0;
    return ap->failed ? -1 : 0;
}

/* Frame n into its ring slot: read into the slot's buffer, or found in the map. As
 * y4m_read_frame. */
static int next_frame(app *ap, FILE *in, long n, char *err, size_t err_size)
{
    const int slot = (int)(n % ap->ring_len);
    if (ap->map.base) {
        /* the ring's oldest frame, n - ring_len + 1, is the first still needed */
        if (ap->frame[(n + 1) % ap->ring_len])
            y4m_map_release(&ap->map, ap->frame[(n + 1) % ap->ring_len]);
        return y4m_map_frame(&ap->map, &ap->info, &ap->frame[slot], err, err_size);
    }
    ap->frame[slot] = ap->ring[slot];
    return y4m_read_frame(in, &ap->info, ap->ring[slot], err, err_size);
}

/* The adaptive crop's second pass: the margins scaled to the largest share any frame's whole
 * correction needs, then every planned frame read again from `in` (at data_start) and written
 * through them. The registrations are not repeated: the warp follows from the planned path. */
static int write_planned(app *ap, const plan *p, home_stab_config cfg, FILE *in, long data_start,
                         const char *in_path)
{
    double share = 0.0;
    char err[256];
    long i;
    for (i = 0; i < p->n; i++) {
        double s;
        if (home_stab_margin_share(&cfg, &p->frames[i].raw, &p->frames[i].smooth, &s) != HOME_OK)
            s = 1.0;
        if (s > share) share = s;
    }
    cfg.margin_x = (float)(share * cfg.margin_x);
    cfg.margin_y = (float)(share * cfg.margin_y);
    if (!ap->quiet)
        fprintf(stderr, "home-stab: adaptive crop: margins %.4f x %.4f (%.0f %% of the maximum)\n",
                cfg.margin_x, cfg.margin_y, 100.0 * share);
    if (ap->map.base) {
        y4m_map_rewind(&ap->map);
        memset(ap->frame, 0, (size_t)ap->ring_len * sizeof *ap->frame);
    }
    else if (fseek(in, data_start, SEEK_SET)) {
        fprintf(stderr, "home-stab: %s: cannot read it again for the adaptive crop\n", in_path);
        return -1;
    }
    for (i = 0; i < p->n; i++) {
        home_stab_output o;
        if (next_frame(ap, in, i, err, sizeof err) <= 0) {
            fprintf(stderr, "home-stab: %s: frame %ld changed between the passes\n", in_path, i);
            return -1;
        }
        memset(&o, 0, sizeof o);
        o.ready = 1;
        o.frame = i;
        o.raw = p->frames[i].raw;
        o.smooth = p->frames[i].smooth;
        o.motion_status = p->frames[i].status;
        home_stab_crop_warp(&cfg, &o.raw, &o.smooth, o.warp, &o.correction_used);
        ap->reg[i % ap->ring_len] = p->frames[i].reg;
        if (emit_output(ap, &o)) return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *in_path = NULL, *out_path = NULL, *csv_path = NULL, *plot_path = NULL;
    home_stab_config cfg;
    double margin = 0.10, margin_x = -1, margin_y = -1, smoothing = 0,
           lookahead = HOME_STAB_FILE_LOOKAHEAD, downscale = 0, keypoints = 500, hough_ds = 0,
           theta_bins = 0, ease = -1, refine_finest = -1, threads = 1;
    double t_start, ms_reg = 0, last_report;
    app ap;
    home_stab *stab = NULL;
    home_stab_output o;
    void *arena = NULL;
    FILE *in;
    char err[256];
    int i, status, rc = 0, got, refine = 1, adaptive = 1, key_frames = 1;
    plan planned_path = {NULL, 0, 0};
    long data_start = 0;
    long frames = 0, failed = 0, cuts = 0;
    size_t need;

    memset(&ap, 0, sizeof ap);
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        double *target = NULL, lo = 0, hi = 0;
        if (!strcmp(a, "--help")) { usage(stdout); return 0; }
        if (!strcmp(a, "--side-by-side")) { ap.side_by_side = 1; continue; }
        if (!strcmp(a, "--quiet")) { ap.quiet = 1; continue; }
        if (!strcmp(a, "--no-refine")) { refine = 0; continue; }
        if (!strcmp(a, "--no-key-frames")) { key_frames = 0; continue; }
        if (!strcmp(a, "--fixed-crop")) { adaptive = 0; continue; }
        if (!strcmp(a, "-") || a[0] != '-') {
            if (!in_path) in_path = a;
            else if (!out_path) out_path = a;
            else { fprintf(stderr, "home-stab: too many arguments\n"); return 2; }
            continue;
        }
        if (i + 1 >= argc) { fprintf(stderr, "home-stab: %s needs a value\n", a); return 2; }
        if (!strcmp(a, "--csv")) { csv_path = argv[++i]; continue; }
        if (!strcmp(a, "--plot")) { plot_path = argv[++i]; continue; }
        if (!strcmp(a, "--margin")) { target = &margin; lo = 0; hi = 0.4; }
        else if (!strcmp(a, "--margin-x")) { target = &margin_x; lo = 0; hi = 0.4; }
        else if (!strcmp(a, "--margin-y")) { target = &margin_y; lo = 0; hi = 0.4; }
        else if (!strcmp(a, "--smoothing")) { target = &smoothing; lo = 1; hi = 1000; }
        else if (!strcmp(a, "--lookahead")) { target = &lookahead; lo = 0; hi = HOME_STAB_MAX_LOOKAHEAD; }
        else if (!strcmp(a, "--ease")) { target = &ease; lo = 0; hi = 1; }
        else if (!strcmp(a, "--refine-finest")) { target = &refine_finest; lo = 0; hi = 1; }
        else if (!strcmp(a, "--downscale")) { target = &downscale; lo = 1; hi = 4; }
        else if (!strcmp(a, "--hough-downscale")) { target = &hough_ds; lo = 1; hi = 4; }
        else if (!strcmp(a, "--theta-bins")) { target = &theta_bins; lo = 16; hi = HOME_MAX_THETA_BINS; }
        else if (!strcmp(a, "--keypoints")) { target = &keypoints; lo = 16; hi = HOME_MAX_KEYPOINTS_PER_SIGN; }
        else if (!strcmp(a, "--threads")) { target = &threads; lo = 1; hi = 2; }
        else { fprintf(stderr, "home-stab: unknown option %s (see --help)\n", a); return 2; }
        if (number(argv[++i], lo, hi, target)) {
            fprintf(stderr, "home-stab: bad value for %s: %s (%g..%g)\n", a, argv[i], lo, hi);
            return 2;
        }
    }
    if (!in_path || !out_path) { usage(stderr); return 2; }
    in = strcmp(in_path, "-") ? fopen(in_path, "rb") : stdin;
    if (!in) { fprintf(stderr, "home-stab: cannot open %s\n", in_path); return 2; }
    if (y4m_read_header(in, &ap.info, err, sizeof err)) {
        fprintf(stderr, "home-stab: %s: %s\n", in_path, err);
        return 2;
    }
    /* the adaptive crop reads the input twice: a pipe gets the whole margins */
    if (adaptive && (in == stdin || (data_start = ftell(in)) < 0 || fseek(in, data_start, SEEK_SET)))
        adaptive = 0;
    status = home_stab_default_config(&cfg, ap.info.width, ap.info.height);
    cfg.margin_x = (float)(margin_x >= 0 ? margin_x : margin);
    cfg.margin_y = (float)(margin_y >= 0 ? margin_y : margin);
    cfg.smoothing = (float)smoothing;
    cfg.lookahead = (int)lookahead;
    if (ease >= 0) cfg.ease = (float)ease;
    if (downscale > 0) cfg.downscale = (int)downscale;
    cfg.keypoints_per_sign = (int)keypoints;
    cfg.refine = refine;
    if (refine_finest >= 0) cfg.refine_finest_level = (int)refine_finest;
    cfg.key_frames = key_frames;
    if (hough_ds > 0) cfg.hough_downscale = (int)hough_ds;
    cfg.theta_bins = (int)theta_bins;
    cfg.clock = now_ms;
    if (status == HOME_OK) status = home_stab_validate_config(&cfg);
    if (status != HOME_OK) {
        fprintf(stderr, "home-stab: %dx%d: %s\n", ap.info.width, ap.info.height, home_strerror(status));
        return 2;
    }
    need = home_stab_arena_size(&cfg);
    if (posix_memalign(&arena, HOME_ARENA_ALIGN, need)) arena = NULL;
    ap.frame_bytes = y4m_frame_bytes(&ap.info);
    /* frame n is read once outputs 0 .. n - lookahead - 1 were queued, and the queue holds at
     * most WRITE_QUEUE unwritten ones: its slot's previous frame, n - ring_len, is written */
    ap.ring_len = cfg.lookahead + 1 + (threads > 1 ? WRITE_QUEUE : 0);
    ap.ring = calloc((size_t)ap.ring_len, sizeof *ap.ring);
    ap.frame = calloc((size_t)ap.ring_len, sizeof *ap.frame);
    ap.reg = calloc((size_t)ap.ring_len, sizeof *ap.reg);
    ap.result = malloc(ap.frame_bytes);
    ap.wide = malloc(2 * ap.frame_bytes);
    if (!arena || !ap.ring || !ap.frame || !ap.reg || !ap.result || !ap.wide) { fprintf(stderr, "home-stab: out of memory\n"); return 2; }
    /* a file read twice is mapped: neither pass copies its frames */
    if (!adaptive || y4m_map_open(&ap.map, in, data_start))
        for (i = 0; i < ap.ring_len; i++)
            if (!(ap.ring[i] = malloc(ap.frame_bytes))) { fprintf(stderr, "home-stab: out of memory\n"); return 2; }
    status = home_stab_init(&stab, &cfg, arena, need, NULL);
    if (status != HOME_OK) { fprintf(stderr, "home-stab: %s\n", home_strerror(status)); return 2; }
    stab_plot_init(&ap.plot);

    ap.out = strcmp(out_path, "-") ? fopen(out_path, "wb") : stdout;
    if (!ap.out) { fprintf(stderr, "home-stab: cannot write %s\n", out_path); return 2; }
    if (csv_path) {
        if (!(ap.csv = fopen(csv_path, "w"))) { fprintf(stderr, "home-stab: cannot write %s\n", csv_path); return 2; }
        fprintf(ap.csv, "frame,status,inliers,raw_tx,raw_ty,raw_angle,raw_log_scale,smooth_tx,"
                        "smooth_ty,smooth_angle,smooth_log_scale,correction_used,w00,w01,w02,w10,w11,w12,"
                        "model,sigma_px\n");
    }
    y4m_write_header(ap.out, &ap.info, ap.side_by_side ? 2 * ap.info.width : ap.info.width);
    if (threads > 1) {
        if (pthread_mutex_init(&ap.lock, NULL) || pthread_cond_init(&ap.changed, NULL) ||
            pthread_create(&ap.writer, NULL, writer_main, &ap)) {
            fprintf(stderr, "home-stab: cannot start the writer thread\n");
            return 2;
        }
        ap.threaded = 1;
    }

    t_start = last_report = now_ms(NULL);
    for (;;) {
        home_stab_image im;
        got = next_frame(&ap, in, frames, err, sizeof err);
        if (got == 0) break;
        if (got < 0) {
            fprintf(stderr, "home-stab: %s: frame %ld: %s; writing the %ld frames decoded so far\n",
                    in_path, frames, err, frames);
            rc = 1;
            break;
        }
        y4m_image(&ap.info, ap.info.width, (uint8_t *)ap.frame[frames % ap.ring_len], &im);
        status = home_stab_push(stab, &im, &o);
        if (status != HOME_OK) { fprintf(stderr, "home-stab: %s\n", home_strerror(status)); rc = 2; break; }
        ap.reg[frames % ap.ring_len].inliers = o.reg.inliers;
        ap.reg[frames % ap.ring_len].model = o.reg.model;
        ap.reg[frames % ap.ring_len].sigma_px = o.reg.sigma_px;
        failed += o.newest_status == HOME_STAB_MOTION_FAILED || o.newest_status == HOME_STAB_MOTION_IMPLAUSIBLE;
        cuts += o.newest_status == HOME_STAB_MOTION_CUT;
        ms_reg += o.ms_register;
        frames++;
        if (o.ready && (adaptive ? plan_add(&planned_path, &o, &ap.reg[o.frame % ap.ring_len])
                                 : emit_output(&ap, &o))) { rc = 2; break; }
        if (!ap.quiet && now_ms(NULL) - last_report >= 1000.0) {
            double ms_warp, written;
            if (ap.threaded) pthread_mutex_lock(&ap.lock);
            ms_warp = ap.ms_warp;
            written = (double)ap.written;
            if (ap.threaded) pthread_mutex_unlock(&ap.lock);
            last_report = now_ms(NULL);
            fprintf(stderr, "home-stab: frame %ld, %.1f fps, register %.1f ms, warp %.1f ms, %ld held\n",
                    frames, frames * 1e3 / (last_report - t_start), ms_reg / frames,
                    written > 0 ? ms_warp / written : 0.0, failed);
        }
    }
    while (rc != 2 && home_stab_flush(stab, &o) == HOME_OK && o.ready)
        if (adaptive ? plan_add(&planned_path, &o, &ap.reg[o.frame % ap.ring_len])
                     : emit_output(&ap, &o)) { rc = 2; break; }
    if (adaptive && rc != 2 && write_planned(&ap, &planned_path, cfg, in, data_start, in_path))
        rc = 2;
    free(planned_path.frames);
    if (finish_writer(&ap)) rc = 2;
    if (fflush(ap.out) != 0) { fprintf(stderr, "home-stab: write error\n"); rc = 2; }
    if (!ap.quiet)
        fprintf(stderr, "home-stab: %ld frames in, %ld out, %.1f fps, register %.1f ms/frame, "
                        "warp %.1f ms/frame, %ld held (registration failed or implausible), "
                        "%ld scene cuts\n",
                frames, ap.written, frames * 1e3 / (now_ms(NULL) - t_start + 1e-9),
                frames ? ms_reg / frames : 0.0, ap.written ? ap.ms_warp / ap.written : 0.0, failed,
                cuts);
    if (plot_path && stab_plot_write(&ap.plot, plot_path, ap.info.width, ap.info.height)) {
        fprintf(stderr, "home-stab: cannot write %s\n", plot_path);
        rc = 2;
    }
    if (ap.csv) fclose(ap.csv);
    if (ap.out != stdout) fclose(ap.out);
    if (in != stdin) fclose(in);
    for (i = 0; i < ap.ring_len; i++) free(ap.ring[i]);
    y4m_map_close(&ap.map);
    free(ap.ring); free(ap.frame); free(ap.reg); free(ap.result); free(ap.wide); free(arena);
    stab_plot_free(&ap.plot);
    return rc;
}
