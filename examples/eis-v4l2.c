/* eis-v4l2: live electronic image stabilisation from a V4L2 camera (/dev/videoN).
 * YUYV, NV12 and YU12 (I420), single- and multi-planar API, mmap streaming with the canonical
 * robust loop (EINTR retry, select timeout, bytesperline, V4L2_BUF_FLAG_ERROR, device loss ->
 * clean exit). Frames are stabilised with libhome and shown side by side (original | stabilised)
 * in an SDL2 window when built with SDL2, and/or written as Y4M (I420) to a file or stdout.
 * fps and per-stage milliseconds go to stderr once a second.
 * Threads (--threads N, default: the online CPUs up to 4): the capture thread dequeues, copies
 * and registers; the warp of each due frame runs on a fixed pool of N - 1 workers in row bands
 * (examples/eis_pool.h), overlapping the next registration, and the worker that ends it writes
 * the frame out. The output is byte-identical for any N. The window is drawn by the capture
 * thread (SDL's), a frame later with N > 1.
 * Exit: 0 done (frame count reached or interrupted), 1 device stalled (select timeout),
 * 2 usage / setup error, 3 device lost while streaming. */
#define _DEFAULT_SOURCE
#include "eis_common.h"
#include "eis_pool.h"
#include "home_stab.h"
#include <errno.h>
#include <pthread.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/select.h>
#include <time.h>
#include <unistd.h>
#ifdef HAVE_SDL2
#include <SDL.h>
#endif

#define MAX_BUFFERS 8
#define MAX_PLANES 3

static volatile sig_atomic_t stop_requested;
static void on_signal(int sig) { (void)sig; stop_requested = 1; }

/* ioctl, retried while a signal interrupts it */
static int xioctl(int fd, unsigned long request, void *arg)
{
    int r;
    do r = ioctl(fd, request, arg);
    while (r == -1 && errno == EINTR);
    return r;
}

typedef struct mapping { void *start; size_t length; } mapping;

typedef struct camera {
    int fd, mplane;
    enum v4l2_buf_type type;
    uint32_t fourcc;
    int width, height, n_planes;   /* n_planes: memory planes (2 for NV12M, 3 for YUV420M) */
    uint32_t bytesperline[MAX_PLANES], sizeimage[MAX_PLANES];
    mapping map[MAX_BUFFERS][MAX_PLANES];
    unsigned n_buffers;
    int streaming;
} camera;

typedef struct options {
    const char *device, *output;
    int width, height, frames, buffers, timeout_ms, window, quiet, threads;
    uint32_t fourcc;
    float margin, smoothing;
    int lookahead;
} options;

static void usage(FILE *f)
{
    fprintf(f, "usage: eis-v4l2 [--device /dev/videoN] [--size WxH] [--format yuyv|nv12|yu12]\n"
               "       [--frames N] [--buffers N] [--timeout-ms N] [--margin F] [--smoothing F]\n"
               "       [--lookahead N] [--threads N] [--output FILE.y4m|-] [--no-window] [--quiet]\n"
               "  --threads N   1: capture, register, warp and write in turn; N > 1: the warp in bands\n"
               "                on N - 1 more threads while the next frame registers (same bytes);\n"
               "                0 (default): the online CPUs, at most %d (here %d)\n"
               "Exit: 0 done, 1 device stalled (select timeout), 2 usage/setup error, 3 device lost.\n"
#ifdef HAVE_SDL2
               "Window: SDL2, original | stabilised (close it or press q to stop).\n"
#else
               "Window: not built (SDL2 was missing); use --output.\n"
#endif
    , EIS_POOL_AUTO_MAX, eis_pool_auto_threads());
}

static int parse(int argc, char **argv, options *o)
{
    int i;
    memset(o, 0, sizeof *o);
    o->device = "/dev/video0";
    o->width = 640; o->height = 480;
    o->fourcc = V4L2_PIX_FMT_YUYV;
    o->buffers = 4; o->timeout_ms = 2000; o->window = 1;
    o->margin = 0.10f; o->smoothing = 0.0f;   /* automatic */
    o->lookahead = EIS_LIVE_LOOKAHEAD;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        char *end = NULL;
        if (!strcmp(a, "--help")) { usage(stdout); exit(0); }
        if (!strcmp(a, "--no-window")) { o->window = 0; continue; }
        if (!strcmp(a, "--quiet")) { o->quiet = 1; continue; }
        if (!v) { fprintf(stderr, "eis-v4l2: %s needs a value (see --help)\n", a); return -1; }
        i++;
        if (!strcmp(a, "--device")) o->device = v;
        else if (!strcmp(a, "--output")) o->output = v;
        else if (!strcmp(a, "--size")) {
            if (sscanf(v, "%dx%d", &o->width, &o->height) != 2 || o->width < 32 || o->height < 32) goto bad;
        } else if (!strcmp(a, "--format")) {
            if (!strcmp(v, "yuyv")) o->fourcc = V4L2_PIX_FMT_YUYV;
            else if (!strcmp(v, "nv12")) o->fourcc = V4L2_PIX_FMT_NV12;
            else if (!strcmp(v, "yu12")) o->fourcc = V4L2_PIX_FMT_YUV420;
            else goto bad;
        } else if (!strcmp(a, "--frames")) { o->frames = (int)strtol(v, &end, 10); if (*end || o->frames < 0) goto bad; }
        else if (!strcmp(a, "--buffers")) { o->buffers = (int)strtol(v, &end, 10); if (*end || o->buffers < 2 || o->buffers > MAX_BUFFERS) goto bad; }
        else if (!strcmp(a, "--timeout-ms")) { o->timeout_ms = (int)strtol(v, &end, 10); if (*end || o->timeout_ms < 1) goto bad; }
        else if (!strcmp(a, "--threads")) { o->threads = (int)strtol(v, &end, 10); if (*end || o->threads < 0 || o->threads > EIS_POOL_MAX_THREADS) goto bad; }
        else if (!strcmp(a, "--lookahead")) { o->lookahead = (int)strtol(v, &end, 10); if (*end || o->lookahead < 0 || o->lookahead > HOME_STAB_MAX_LOOKAHEAD) goto bad; }
        else if (!strcmp(a, "--margin")) { o->margin = strtof(v, &end); if (*end) goto bad; }
        else if (!strcmp(a, "--smoothing")) { o->smoothing = strtof(v, &end); if (*end) goto bad; }
        else { fprintf(stderr, "eis-v4l2: unknown option %s (see --help)\n", a); return -1; }
        continue;
    bad:
        fprintf(stderr, "eis-v4l2: bad value for %s: %s\n", a, v);
        return -1;
    }
    return 0;
}

static const char *fourcc_name(uint32_t f, char *buf)
{
    int i;
    for (i = 0; i < 4; i++) buf[i] = (char)((f >> (8 * i)) & 0xff);
    buf[4] = 0;
    return buf;
}

static int stab_format(uint32_t fourcc)
{
    switch (fourcc) {
    case V4L2_PIX_FMT_YUYV: return HOME_STAB_YUYV;
    case V4L2_PIX_FMT_NV12: case V4L2_PIX_FMT_NV12M: return HOME_STAB_NV12;
    case V4L2_PIX_FMT_YUV420: case V4L2_PIX_FMT_YUV420M: return HOME_STAB_I420;
    default: return 0;
    }
}

static void camera_close(camera *c)
{
    unsigned b;
    int p;
    if (c->streaming) {
        enum v4l2_buf_type type = c->type;
        xioctl(c->fd, VIDIOC_STREAMOFF, &type);   /* may fail after device loss: nothing to do */
        c->streaming = 0;
    }
    for (b = 0; b < c->n_buffers; b++)
        for (p = 0; p < c->n_planes; p++)
            if (c->map[b][p].start && c->map[b][p].start != MAP_FAILED) munmap(c->map[b][p].start, c->map[b][p].length);
    c->n_buffers = 0;
    if (c->fd >= 0) close(c->fd);
    c->fd = -1;
}

/* A cleared mmap buffer descriptor of c's type (planes attached for multi-planar). */
static void describe_buffer(const camera *c, unsigned index, struct v4l2_buffer *buf,
                            struct v4l2_plane *planes)
{
    memset(buf, 0, sizeof *buf);
    memset(planes, 0, MAX_PLANES * sizeof *planes);
    buf->type = c->type;
    buf->memory = V4L2_MEMORY_MMAP;
    buf->index = index;
    if (c->mplane) { buf->m.planes = planes; buf->length = (uint32_t)c->n_planes; }
}

static int queue_buffer(camera *c, unsigned index)
{
    struct v4l2_buffer buf;
    struct v4l2_plane planes[MAX_PLANES];
    describe_buffer(c, index, &buf, planes);
    return xioctl(c->fd, VIDIOC_QBUF, &buf);
}

static int camera_open(camera *c, const options *o)
{
    struct v4l2_capability cap;
    struct v4l2_format fmt;
    struct v4l2_requestbuffers req;
    uint32_t caps;
    unsigned b;
    int p;
    char name[5];
    memset(c, 0, sizeof *c);
    c->fd = open(o->device, O_RDWR | O_NONBLOCK);
    if (c->fd < 0) { fprintf(stderr, "eis-v4l2: cannot open %s: %s\n", o->device, strerror(errno)); return -1; }
    if (xioctl(c->fd, VIDIOC_QUERYCAP, &cap)) {
        fprintf(stderr, "eis-v4l2: %s is not a V4L2 device (%s)\n", o->device, strerror(errno));
        return -1;
    }
    caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_STREAMING)) { fprintf(stderr, "eis-v4l2: %s cannot stream (no mmap I/O)\n", o->device); return -1; }
    if (caps & V4L2_CAP_VIDEO_CAPTURE) c->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    else if (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) { c->type = V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE; c->mplane = 1; }
    else { fprintf(stderr, "eis-v4l2: %s is not a capture device\n", o->device); return -1; }

    memset(&fmt, 0, sizeof fmt);
    fmt.type = c->type;
    if (c->mplane) {
        fmt.fmt.pix_mp.width = (uint32_t)o->width;
        fmt.fmt.pix_mp.height = (uint32_t)o->height;
        fmt.fmt.pix_mp.pixelformat = o->fourcc;
        fmt.fmt.pix_mp.field = V4L2_FIELD_NONE;
    } else {
        fmt.fmt.pix.width = (uint32_t)o->width;
        fmt.fmt.pix.height = (uint32_t)o->height;
        fmt.fmt.pix.pixelformat = o->fourcc;
        fmt.fmt.pix.field = V4L2_FIELD_NONE;
    }
    if (xioctl(c->fd, VIDIOC_S_FMT, &fmt)) { fprintf(stderr, "eis-v4l2: VIDIOC_S_FMT: %s\n", strerror(errno)); return -1; }
    /* the driver may have changed size, format and line padding: use what it returns */
    if (c->mplane) {
        c->width = (int)fmt.fmt.pix_mp.width;
        c->height = (int)fmt.fmt.pix_mp.height;
        c->fourcc = fmt.fmt.pix_mp.pixelformat;
        c->n_planes = fmt.fmt.pix_mp.num_planes;
        if (c->n_planes < 1 || c->n_planes > MAX_PLANES) { fprintf(stderr, "eis-v4l2: driver reports %d planes\n", c->n_planes); return -1; }
        for (p = 0; p < c->n_planes; p++) {
            c->bytesperline[p] = fmt.fmt.pix_mp.plane_fmt[p].bytesperline;
            c->sizeimage[p] = fmt.fmt.pix_mp.plane_fmt[p].sizeimage;
        }
    } else {
        c->width = (int)fmt.fmt.pix.width;
        c->height = (int)fmt.fmt.pix.height;
        c->fourcc = fmt.fmt.pix.pixelformat;
        c->n_planes = 1;
        c->bytesperline[0] = fmt.fmt.pix.bytesperline;
        c->sizeimage[0] = fmt.fmt.pix.sizeimage;
    }
    if (!stab_format(c->fourcc) ||
        (c->n_planes > 1) != (c->fourcc == V4L2_PIX_FMT_NV12M || c->fourcc == V4L2_PIX_FMT_YUV420M)) {
        fprintf(stderr, "eis-v4l2: the driver chose %s (%d planes); supported: YUYV, NV12, YU12\n",
                fourcc_name(c->fourcc, name), c->n_planes);
        return -1;
    }
    {
        /* bytesperline 0 means tightly packed; below a row is a broken driver */
        uint32_t row = c->fourcc == V4L2_PIX_FMT_YUYV ? 2u * (uint32_t)c->width : (uint32_t)c->width;
        if (!c->bytesperline[0]) c->bytesperline[0] = row;
        if (c->bytesperline[0] < row || c->width % 2 || c->height % 2) {
            fprintf(stderr, "eis-v4l2: unusable format %dx%d, bytesperline %u\n", c->width, c->height, c->bytesperline[0]);
            return -1;
        }
    }

    memset(&req, 0, sizeof req);
    req.count = (uint32_t)o->buffers;
    req.type = c->type;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(c->fd, VIDIOC_REQBUFS, &req)) { fprintf(stderr, "eis-v4l2: VIDIOC_REQBUFS: %s\n", strerror(errno)); return -1; }
    if (req.count < 2 || req.count > MAX_BUFFERS) { fprintf(stderr, "eis-v4l2: driver gave %u buffers\n", req.count); return -1; }
    for (b = 0; b < req.count; b++) {
        struct v4l2_buffer buf;
        struct v4l2_plane planes[MAX_PLANES];
        describe_buffer(c, b, &buf, planes);
        if (xioctl(c->fd, VIDIOC_QUERYBUF, &buf)) { fprintf(stderr, "eis-v4l2: VIDIOC_QUERYBUF: %s\n", strerror(errno)); return -1; }
        c->n_buffers = b + 1;
        for (p = 0; p < c->n_planes; p++) {
            size_t len = c->mplane ? planes[p].length : buf.length;
            off_t off = c->mplane ? (off_t)planes[p].m.mem_offset : (off_t)buf.m.offset;
            c->map[b][p].length = len;
            c->map[b][p].start = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_SHARED, c->fd, off);
            if (c->map[b][p].start == MAP_FAILED) { fprintf(stderr, "eis-v4l2: mmap: %s\n", strerror(errno)); return -1; }
        }
    }
    for (b = 0; b < c->n_buffers; b++)
        if (queue_buffer(c, b)) { fprintf(stderr, "eis-v4l2: VIDIOC_QBUF: %s\n", strerror(errno)); return -1; }
    if (xioctl(c->fd, VIDIOC_STREAMON, &c->type)) { fprintf(stderr, "eis-v4l2: VIDIOC_STREAMON: %s\n", strerror(errno)); return -1; }
    c->streaming = 1;
    return 0;
}

/* Copy the dequeued buffer out (respecting bytesperline); -1 when it is too short to hold a
 * frame (a corrupted buffer). */
static int copy_frame(const camera *c, const struct v4l2_buffer *buf, const struct v4l2_plane *planes, uint8_t *dst)
{
    const int w = c->width, h = c->height, format = stab_format(c->fourcc);
    const size_t bpl = c->bytesperline[0];
    const uint8_t *src[MAX_PLANES];
    size_t used[MAX_PLANES], need[MAX_PLANES], cbpl = 0;
    home_stab_image im;
    int p, contiguous = c->n_planes == 1;
    for (p = 0; p < c->n_planes; p++) {
        src[p] = (const uint8_t *)c->map[buf->index][p].start;
        used[p] = c->mplane ? planes[p].bytesused : buf->bytesused;
        if (used[p] > c->map[buf->index][p].length) return -1;
    }
    if (format == HOME_STAB_YUYV) need[0] = bpl * (h - 1) + 2 * (size_t)w;
    else if (contiguous) {
        cbpl = format == HOME_STAB_NV12 ? bpl : bpl / 2;
        need[0] = bpl * h + cbpl * (h / 2) * (format == HOME_STAB_NV12 ? 1 : 2);
    } else {
        cbpl = c->bytesperline[1] ? c->bytesperline[1] : (format == HOME_STAB_NV12 ? (size_t)w : (size_t)w / 2);
        need[0] = bpl * h;
        for (p = 1; p < c->n_planes; p++) need[p] = cbpl * (h / 2);
    }
    for (p = 0; p < c->n_planes; p++)
        if (used[p] < need[p]) return -1;
    eis_frame_view(format, w, h, dst, &im);
    if (format == HOME_STAB_YUYV) { eis_copy_rows(dst, 2 * (size_t)w, src[0], bpl, 2 * (size_t)w, h); return 0; }
    eis_copy_rows(im.plane[0], (size_t)w, src[0], bpl, (size_t)w, h);
    if (format == HOME_STAB_NV12)
        eis_copy_rows(im.plane[1], (size_t)w, contiguous ? src[0] + bpl * h : src[1], cbpl, (size_t)w, h / 2);
    else
        for (p = 1; p < 3; p++)
            eis_copy_rows(im.plane[p], (size_t)w / 2,
                      contiguous ? src[0] + bpl * h + (p - 1) * cbpl * (h / 2) : src[p], cbpl, (size_t)w / 2, h / 2);
    return 0;
}


/* Per-stage milliseconds of the capture thread since the last report. */
typedef struct stage_clock { double wait, copy, reg, blocked; long frames; double since; } stage_clock;

/* What the output job adds up (a pool worker's with --threads > 1): under the sink's lock. */
typedef struct out_clock { double warp, out, latency, latency_max; long frames; } out_clock;

/* Where stabilised frames go: the Y4M file and/or the window. */
typedef struct sink {
    int format, width, height, ring_len;
    uint8_t **ring, *warped[2], *i420, *shown;   /* warped: by frame parity (the window's frame
                                                    stays while the next is warped) */
    double *captured_at;          /* per ring slot: when its frame was dequeued (ms) */
    FILE *out;
    eis_pool *pool;
    long pending;                 /* the window: the frame submitted and not yet shown, or -1 */
    pthread_mutex_t lock;         /* guards the rest */
    long written;
    out_clock now, total;         /* since the last report; since the start */
#ifdef HAVE_SDL2
    SDL_Renderer *ren;
    SDL_Texture *tex;
#endif
} sink;

/* The output job, once frame `frame` is warped (on a pool worker, or here with one thread): the
 * Y4M frame, and the frame's time from capture to output. */
static int write_out(void *user, long frame, double warp_ms)
{
    sink *k = user;
    const size_t i420 = (size_t)k->width * k->height * 3 / 2;
    const double t0 = eis_now_ms(NULL);
    double t1, latency;
    int bad = 0;
    if (k->out) {
        eis_to_i420(k->format, k->width, k->height, k->warped[frame % 2], k->i420, 0, 0);
        bad = fputs("FRAME\n", k->out) < 0 || fwrite(k->i420, 1, i420, k->out) != i420;
        if (bad) fprintf(stderr, "eis-v4l2: write error\n");
    }
    t1 = eis_now_ms(NULL);
    latency = t1 - k->captured_at[frame % k->ring_len];
    pthread_mutex_lock(&k->lock);
    k->written += k->out && !bad;
    k->now.warp += warp_ms; k->now.out += t1 - t0; k->now.latency += latency; k->now.frames++;
    if (latency > k->now.latency_max) k->now.latency_max = latency;
    k->total.warp += warp_ms; k->total.out += t1 - t0; k->total.latency += latency; k->total.frames++;
    if (latency > k->total.latency_max) k->total.latency_max = latency;
    pthread_mutex_unlock(&k->lock);
    return bad;
}

/* Draw the pending frame in the window, original | stabilised (this thread created it). */
static void present(sink *k)
{
#ifdef HAVE_SDL2
    if (k->tex && k->pending >= 0) {
        SDL_Event ev;
        eis_to_i420(k->format, k->width, k->height, k->ring[k->pending % k->ring_len], k->shown, 1, 0);
        eis_to_i420(k->format, k->width, k->height, k->warped[k->pending % 2], k->shown, 1, 1);
        SDL_UpdateTexture(k->tex, NULL, k->shown, 2 * k->width);
        SDL_RenderClear(k->ren);
        SDL_RenderCopy(k->ren, k->tex, NULL, NULL);
        SDL_RenderPresent(k->ren);
        while (SDL_PollEvent(&ev))
            if (ev.type == SDL_QUIT || (ev.type == SDL_KEYDOWN && ev.key.keysym.sym == SDLK_q)) stop_requested = 1;
    }
#endif
    k->pending = -1;
}

/* Hand the due frame to the output job, once the previous one is written (and drawn): -1 when
 * the warp or the output failed, or the window was closed. */
static int show(sink *k, const home_stab_output *so, stage_clock *st)
{
    home_stab_image src, dst;
    const double t0 = eis_now_ms(NULL);
    int status = eis_pool_wait(k->pool);
    st->blocked += eis_now_ms(NULL) - t0;
    if (status != HOME_OK) return -1;
    present(k);
    eis_frame_view(k->format, k->width, k->height, k->ring[so->frame % k->ring_len], &src);
    eis_frame_view(k->format, k->width, k->height, k->warped[so->frame % 2], &dst);
    if (eis_pool_submit(k->pool, so->warp, &src, &dst, write_out, k, so->frame) != HOME_OK) return -1;
    k->pending = so->frame;
    if (eis_pool_threads(k->pool) == 1) {   /* done already: draw it now */
        if (eis_pool_wait(k->pool) != HOME_OK) return -1;
        present(k);
    }
    return 0;
}

int main(int argc, char **argv)
{
    options o;
    camera cam;
    home_stab_config cfg;
    home_stab *stab = NULL;
    home_stab_output so;
    void *arena = NULL;
    sink k;
    stage_clock st;
    long pushed = 0, eintr_seen = 0, skipped = 0;
    double t_first = 0;
    int rc = 0, i, status, threads;
    size_t fbytes, need;
    struct sigaction sa;
    char name[5];
#ifdef HAVE_SDL2
    SDL_Window *win = NULL;
#endif

    if (parse(argc, argv, &o)) return 2;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;            /* no SA_RESTART: the loop sees EINTR and retries */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
    if (camera_open(&cam, &o)) { camera_close(&cam); return 2; }
    if (!o.quiet)
        fprintf(stderr, "eis-v4l2: %s %dx%d %s, %s API, %d plane(s), bytesperline %u, %u buffers\n",
                o.device, cam.width, cam.height, fourcc_name(cam.fourcc, name),
                cam.mplane ? "multi-planar" : "single-planar", cam.n_planes, cam.bytesperline[0], cam.n_buffers);
    status = home_stab_default_config(&cfg, cam.width, cam.height);
    cfg.margin_x = cfg.margin_y = o.margin;
    cfg.smoothing = o.smoothing;
    cfg.lookahead = o.lookahead;
    cfg.clock = eis_now_ms;
    if (status == HOME_OK) status = home_stab_validate_config(&cfg);
    need = home_stab_arena_size(&cfg);
    if (status != HOME_OK || posix_memalign(&arena, HOME_ARENA_ALIGN, need) ||
        (status = home_stab_init(&stab, &cfg, arena, need, NULL)) != HOME_OK) {
        fprintf(stderr, "eis-v4l2: stabiliser: %s\n", home_strerror(status != HOME_OK ? status : HOME_E_NULL));
        camera_close(&cam);
        return 2;
    }
    memset(&k, 0, sizeof k);
    k.format = stab_format(cam.fourcc);
    k.width = cam.width;
    k.height = cam.height;
    k.pending = -1;
    if (eis_pool_start(&k.pool, o.threads) || pthread_mutex_init(&k.lock, NULL)) {
        fprintf(stderr, "eis-v4l2: cannot start %d threads\n", o.threads);
        camera_close(&cam);
        return 2;
    }
    fbytes = eis_frame_bytes(k.format, cam.width, cam.height);
    /* the stabiliser reports frame n - lookahead: keep them; with workers, frame n + 1 is
     * captured while frame n - lookahead is warped */
    k.ring_len = cfg.lookahead + 1 + (eis_pool_threads(k.pool) > 1);
    k.ring = calloc((size_t)k.ring_len, sizeof *k.ring);
    k.captured_at = calloc((size_t)k.ring_len, sizeof *k.captured_at);
    k.warped[0] = malloc(fbytes);
    k.warped[1] = malloc(fbytes);
    k.i420 = malloc((size_t)cam.width * cam.height * 3 / 2);
    k.shown = malloc((size_t)cam.width * cam.height * 3);   /* I420, 2w x h */
    for (i = 0; k.ring && i < k.ring_len; i++) k.ring[i] = malloc(fbytes);
    if (!k.ring || !k.captured_at || !k.warped[0] || !k.warped[1] || !k.i420 || !k.shown || !k.ring[k.ring_len - 1]) {
        fprintf(stderr, "eis-v4l2: out of memory\n");
        camera_close(&cam);
        return 2;
    }
    if (!o.quiet) fprintf(stderr, "eis-v4l2: %d thread(s)\n", eis_pool_threads(k.pool));
    if (o.output) {
        k.out = strcmp(o.output, "-") ? fopen(o.output, "wb") : stdout;
        if (!k.out) { fprintf(stderr, "eis-v4l2: cannot write %s\n", o.output); camera_close(&cam); return 2; }
        fprintf(k.out, "YUV4MPEG2 W%d H%d F30:1 Ip A1:1 C420jpeg\n", cam.width, cam.height);
    }
#ifdef HAVE_SDL2
    if (o.window) {
        if (SDL_Init(SDL_INIT_VIDEO) != 0 ||
            !(win = SDL_CreateWindow("eis-v4l2: original | stabilised", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED,
                                     2 * cam.width, cam.height, SDL_WINDOW_RESIZABLE)) ||
            !(k.ren = SDL_CreateRenderer(win, -1, 0)) ||
            !(k.tex = SDL_CreateTexture(k.ren, SDL_PIXELFORMAT_IYUV, SDL_TEXTUREACCESS_STREAMING, 2 * cam.width, cam.height))) {
            fprintf(stderr, "eis-v4l2: no window (%s)%s\n", SDL_GetError(), o.output ? "" : "; use --output");
            k.tex = NULL;
        }
    }
#else
    if (o.window && !o.output && !o.quiet)
        fprintf(stderr, "eis-v4l2: built without SDL2: no window; stabilising without output (use --output)\n");
#endif

    memset(&st, 0, sizeof st);
    st.since = eis_now_ms(NULL);
    while (!stop_requested && (o.frames == 0 || pushed < o.frames)) {
        struct v4l2_buffer buf;
        struct v4l2_plane planes[MAX_PLANES];
        struct timeval tv;
        fd_set fds;
        home_stab_image im;
        double t0 = eis_now_ms(NULL), t1;
        int r, bad;
        uint8_t *slot;

        FD_ZERO(&fds);
        FD_SET(cam.fd, &fds);
        tv.tv_sec = o.timeout_ms / 1000;
        tv.tv_usec = (o.timeout_ms % 1000) * 1000;
        r = select(cam.fd + 1, &fds, NULL, NULL, &tv);
        if (r == -1) {
            if (errno == EINTR) { eintr_seen++; continue; }   /* a signal: retry (or stop) */
            fprintf(stderr, "eis-v4l2: device lost (select: %s) after %ld frames\n", strerror(errno), pushed);
            rc = 3;
            break;
        }
        if (r == 0) {
            fprintf(stderr, "eis-v4l2: no frame within %d ms (select timeout): device stalled\n", o.timeout_ms);
            rc = 1;
            break;
        }
        describe_buffer(&cam, 0, &buf, planes);
        if (xioctl(cam.fd, VIDIOC_DQBUF, &buf)) {
            if (errno == EAGAIN) continue;                     /* spurious wake-up */
            if (errno == EIO) { skipped++; continue; }         /* transient; the driver requeues */
            fprintf(stderr, "eis-v4l2: device lost (VIDIOC_DQBUF: %s) after %ld frames\n", strerror(errno), pushed);
            rc = 3;
            break;
        }
        if (buf.index >= cam.n_buffers) {
            fprintf(stderr, "eis-v4l2: driver returned unknown buffer %u\n", buf.index);
            rc = 3;
            break;
        }
        t1 = eis_now_ms(NULL);
        st.wait += t1 - t0;
        if (!t_first) t_first = t1;
        k.captured_at[pushed % k.ring_len] = t1;
        slot = k.ring[pushed % k.ring_len];
        bad = (buf.flags & V4L2_BUF_FLAG_ERROR) || copy_frame(&cam, &buf, planes, slot);
        if (queue_buffer(&cam, buf.index)) {
            fprintf(stderr, "eis-v4l2: device lost (VIDIOC_QBUF: %s) after %ld frames\n", strerror(errno), pushed);
            rc = 3;
            break;
        }
        st.copy += eis_now_ms(NULL) - t1;
        if (bad) { skipped++; continue; }                      /* never stabilise a broken frame */

        eis_frame_view(k.format, cam.width, cam.height, slot, &im);
        status = home_stab_push(stab, &im, &so);
        if (status != HOME_OK) { fprintf(stderr, "eis-v4l2: stabiliser: %s\n", home_strerror(status)); rc = 2; break; }
        pushed++;
        st.frames++;
        st.reg += so.ms_register;
        if (so.ready && show(&k, &so, &st)) { rc = 2; break; }
        if (!o.quiet && eis_now_ms(NULL) - st.since >= 1000.0) {
            double dt = eis_now_ms(NULL) - st.since, n = st.frames ? (double)st.frames : 1.0, m;
            out_clock oc;
            pthread_mutex_lock(&k.lock);
            oc = k.now;
            memset(&k.now, 0, sizeof k.now);
            pthread_mutex_unlock(&k.lock);
            m = oc.frames ? (double)oc.frames : 1.0;
            fprintf(stderr, "eis-v4l2: %.1f fps | ms/frame: wait %.1f copy %.1f register %.1f blocked %.1f warp %.1f "
                            "output %.1f | capture to output %.1f ms (max %.1f) | %ld skipped\n",
                    st.frames * 1e3 / dt, st.wait / n, st.copy / n, st.reg / n, st.blocked / n, oc.warp / m,
                    oc.out / m, oc.latency / m, oc.latency_max, skipped);
            memset(&st, 0, sizeof st);
            st.since = eis_now_ms(NULL);
        }
    }
    /* the frames still queued for lookahead are shown too, whatever ended the stream */
    while (rc != 2 && home_stab_flush(stab, &so) == HOME_OK && so.ready)
        if (show(&k, &so, &st)) { rc = 2; break; }
    if (eis_pool_wait(k.pool) != HOME_OK) rc = 2;   /* the last frame out */
    present(&k);
    threads = eis_pool_threads(k.pool);
    eis_pool_stop(k.pool);                           /* the workers end: k is this thread's */
    if (!o.quiet) {
        const double n = k.total.frames ? (double)k.total.frames : 1.0, dt = eis_now_ms(NULL) - t_first;
        fprintf(stderr, "eis-v4l2: %ld frames stabilised, %ld written, %ld skipped (error flag, short buffer or EIO), "
                        "%ld interrupted waits retried%s\n",
                pushed, k.written, skipped, eintr_seen, stop_requested ? ", stopped by signal or window" : "");
        if (k.total.frames)
            fprintf(stderr, "eis-v4l2: %d thread(s): %.1f frames/s from the first capture to the last output; "
                            "per frame: warp %.2f ms, output %.2f ms, capture to output %.2f ms (max %.2f)\n",
                    threads, k.total.frames * 1e3 / dt, k.total.warp / n, k.total.out / n,
                    k.total.latency / n, k.total.latency_max);
    }
    camera_close(&cam);
    if (k.out && fflush(k.out) != 0) rc = 2;
    if (k.out && k.out != stdout) fclose(k.out);
#ifdef HAVE_SDL2
    if (k.tex) SDL_DestroyTexture(k.tex);
    if (k.ren) SDL_DestroyRenderer(k.ren);
    if (win) SDL_DestroyWindow(win);
    SDL_Quit();
#endif
    for (i = 0; i < k.ring_len; i++) free(k.ring[i]);
    free(k.ring); free(k.captured_at); free(k.warped[0]); free(k.warped[1]); free(k.i420); free(k.shown); free(arena);
    pthread_mutex_destroy(&k.lock);
    return rc;
}
