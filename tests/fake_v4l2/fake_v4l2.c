/* A fake V4L2 capture device for tests: an LD_PRELOAD shim that intercepts open/openat/close/
 * ioctl/mmap/munmap/select/poll for one device path and serves the frames of a Y4M (I420) clip,
 * so that a real capture loop (examples/eis-v4l2.c) runs in CI without a camera or kernel module.
 *
 * Environment:
 *   FAKE_V4L2_CLIP     Y4M 4:2:0 clip to serve (required); it loops
 *   FAKE_V4L2_DEVICE   device path to fake (default /dev/video0)
 *   FAKE_V4L2_MPLANE   1: a multi-planar-only device (V4L2_CAP_VIDEO_CAPTURE_MPLANE)
 *   FAKE_V4L2_FORMAT   yuyv|nv12|yu12|nv12m: the format the driver picks whatever is asked
 *                      (default: the requested one when supported, else YUYV)
 *   FAKE_V4L2_PAD      bytes of padding after each line (bytesperline = row + pad)
 *   FAKE_V4L2_FAULTS   comma list of KIND@N, N counting dequeue attempts from 0:
 *                      eintr (select fails with EINTR), dqeintr (DQBUF fails with EINTR),
 *                      eagain (select wakes, DQBUF says EAGAIN), eio (DQBUF fails with EIO),
 *                      error (buffer flagged V4L2_BUF_FLAG_ERROR, contents garbage),
 *                      short (bytesused half a frame, contents garbage), drop (a clip frame
 *                      is skipped), stall (select times out), disconnect (ENODEV from then on)
 *   FAKE_V4L2_LOG      file to which a summary line is appended at close
 *   FAKE_V4L2_FPS      frames come no faster than this, as from a camera: frame k is ready
 *                      k / FPS s after STREAMON (select/poll sleep until then); default: at once
 * The clip size is the only size the driver offers: S_FMT adjusts the request to it. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/select.h>
#include <time.h>
#include <unistd.h>

#define FAKE_MAX_BUFFERS 8
#define FAKE_MAX_FAULTS 64
#define FAKE_OFFSET_STEP 0x1000000

enum fault_kind { F_EINTR, F_DQEINTR, F_EAGAIN, F_EIO, F_ERROR, F_SHORT, F_DROP, F_STALL, F_DISCONNECT, F_KINDS };
static const char *fault_names[F_KINDS] = {"eintr", "dqeintr", "eagain", "eio", "error", "short", "drop", "stall", "disconnect"};

typedef struct fake_state {
    int ready, fd, mplane, streaming, disconnected;
    uint32_t fourcc, forced;
    int width, height, pad, frames, n_planes;
    uint8_t *clip;                 /* frames * w*h*3/2 */
    uint32_t bpl[3], size[3];
    int n_buffers, queued[FAKE_MAX_BUFFERS], order[FAKE_MAX_BUFFERS], head, count;
    uint8_t *mem[FAKE_MAX_BUFFERS][3];
    long attempts, delivered, clip_pos, sequence;
    struct { int kind; long at; int done; } faults[FAKE_MAX_FAULTS];
    int n_faults;
    long fired[F_KINDS];
    double fps, t_stream_on;       /* FAKE_V4L2_FPS; CLOCK_MONOTONIC s at STREAMON */
} fake_state;

static fake_state S;   /* every use checks S.ready first */

/* the real functions, found with dlsym(RTLD_NEXT) */
typedef int (*open_fn)(const char *, int, ...);
typedef int (*openat_fn)(int, const char *, int, ...);
typedef int (*close_fn)(int);
typedef int (*ioctl_fn)(int, unsigned long, ...);
typedef void *(*mmap_fn)(void *, size_t, int, int, int, off_t);
typedef void *(*mmap64_fn)(void *, size_t, int, int, int, off64_t);
typedef int (*munmap_fn)(void *, size_t);
typedef int (*select_fn)(int, fd_set *, fd_set *, fd_set *, struct timeval *);
typedef int (*poll_fn)(struct pollfd *, nfds_t, int);

/* the next definition of a libc symbol (dlsym returns an object pointer; copy it over) */
static void *next_symbol(const char *name)
{
    return dlsym(RTLD_NEXT, name);
}
#define REAL(type, name, sym) type name; { void *p_ = next_symbol(sym); memcpy(&name, &p_, sizeof name); }

static double monotonic_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

static const char *device_path(void)
{
    const char *d = getenv("FAKE_V4L2_DEVICE");
    return d ? d : "/dev/video0";
}

static int load_clip(void)
{
    const char *path = getenv("FAKE_V4L2_CLIP");
    char line[512];
    FILE *f;
    size_t fb;
    const char *w, *h;
    if (!path || !(f = fopen(path, "rb"))) return -1;
    if (!fgets(line, sizeof line, f) || strncmp(line, "YUV4MPEG2", 9) || !(w = strstr(line, " W")) || !(h = strstr(line, " H"))) {
        fclose(f);
        return -1;
    }
    S.width = atoi(w + 2);
    S.height = atoi(h + 2);
    fb = (size_t)S.width * S.height * 3 / 2;
    for (;;) {
        uint8_t *grown;
        if (!fgets(line, sizeof line, f) || strncmp(line, "FRAME", 5)) break;
        grown = realloc(S.clip, fb * (size_t)(S.frames + 1));
        if (!grown) break;
        S.clip = grown;
        if (fread(S.clip + fb * (size_t)S.frames, 1, fb, f) != fb) break;
        S.frames++;
    }
    fclose(f);
    return S.frames > 0 ? 0 : -1;
}

static void parse_faults(void)
{
    const char *spec = getenv("FAKE_V4L2_FAULTS");
    char buf[1024], *tok;
    int k;
    if (!spec) return;
    snprintf(buf, sizeof buf, "%s", spec);
    for (tok = strtok(buf, ","); tok && S.n_faults < FAKE_MAX_FAULTS; tok = strtok(NULL, ",")) {
        char *at = strchr(tok, '@');
        if (!at) continue;
        *at = 0;
        for (k = 0; k < F_KINDS; k++)
            if (!strcmp(tok, fault_names[k])) {
                S.faults[S.n_faults].kind = k;
                S.faults[S.n_faults].at = atol(at + 1);
                S.n_faults++;
            }
    }
}

static uint32_t parse_format(const char *s)
{
    if (!s) return 0;
    if (!strcmp(s, "yuyv")) return V4L2_PIX_FMT_YUYV;
    if (!strcmp(s, "nv12")) return V4L2_PIX_FMT_NV12;
    if (!strcmp(s, "yu12")) return V4L2_PIX_FMT_YUV420;
    if (!strcmp(s, "nv12m")) return V4L2_PIX_FMT_NV12M;
    return 0;
}

/* Is fault `kind` scheduled for the current attempt (once)? */
static int fault_now(int kind)
{
    int i;
    for (i = 0; i < S.n_faults; i++)
        if (S.faults[i].kind == kind && S.faults[i].at == S.attempts && !S.faults[i].done) {
            S.faults[i].done = 1;
            S.fired[kind]++;
            return 1;
        }
    return 0;
}

static void write_log(void)
{
    const char *path = getenv("FAKE_V4L2_LOG");
    FILE *f;
    int k;
    if (!path || !(f = fopen(path, "a"))) return;
    fprintf(f, "attempts=%ld delivered=%ld", S.attempts, S.delivered);
    for (k = 0; k < F_KINDS; k++) fprintf(f, " %s=%ld", fault_names[k], S.fired[k]);
    fprintf(f, "\n");
    fclose(f);
}

static int fake_open(const char *path)
{
    REAL(open_fn, real_open, "open")
    if (!S.ready) {
        if (load_clip()) { errno = ENOENT; return -1; }
        parse_faults();
        S.mplane = getenv("FAKE_V4L2_MPLANE") && atoi(getenv("FAKE_V4L2_MPLANE"));
        S.forced = parse_format(getenv("FAKE_V4L2_FORMAT"));
        S.pad = getenv("FAKE_V4L2_PAD") ? atoi(getenv("FAKE_V4L2_PAD")) : 0;
        S.fps = getenv("FAKE_V4L2_FPS") ? atof(getenv("FAKE_V4L2_FPS")) : 0;
        S.ready = 1;
    }
    (void)path;
    S.fd = real_open("/dev/null", O_RDWR);
    return S.fd;
}

static int is_device(const char *path) { return path && !strcmp(path, device_path()); }

int open(const char *path, int flags, ...)
{
    REAL(open_fn, real_open, "open")
    mode_t mode = 0;
    if (flags & O_CREAT) { va_list ap; va_start(ap, flags); mode = (mode_t)va_arg(ap, int); va_end(ap); }
    if (is_device(path)) return fake_open(path);
    return real_open(path, flags, mode);
}

int open64(const char *path, int flags, ...)
{
    REAL(open_fn, real_open, "open64")
    mode_t mode = 0;
    if (flags & O_CREAT) { va_list ap; va_start(ap, flags); mode = (mode_t)va_arg(ap, int); va_end(ap); }
    if (is_device(path)) return fake_open(path);
    return real_open(path, flags, mode);
}

int openat(int dirfd, const char *path, int flags, ...)
{
    REAL(openat_fn, real_openat, "openat")
    mode_t mode = 0;
    if (flags & O_CREAT) { va_list ap; va_start(ap, flags); mode = (mode_t)va_arg(ap, int); va_end(ap); }
    if (is_device(path)) return fake_open(path);
    return real_openat(dirfd, path, flags, mode);
}

int close(int fd)
{
    REAL(close_fn, real_close, "close")
    if (S.ready && fd == S.fd && fd >= 0) {
        int b, p;
        write_log();
        for (b = 0; b < S.n_buffers; b++)
            for (p = 0; p < 3; p++) { free(S.mem[b][p]); S.mem[b][p] = NULL; }
        S.n_buffers = 0;
        S.streaming = 0;
        S.fd = -1;
    }
    return real_close(fd);
}

static void set_format(uint32_t fourcc)
{
    const uint32_t w = (uint32_t)S.width, h = (uint32_t)S.height, pad = (uint32_t)S.pad;
    S.fourcc = fourcc;
    S.n_planes = 1;
    memset(S.bpl, 0, sizeof S.bpl);
    memset(S.size, 0, sizeof S.size);
    switch (fourcc) {
    case V4L2_PIX_FMT_YUYV: S.bpl[0] = 2 * w + pad; S.size[0] = S.bpl[0] * h; break;
    case V4L2_PIX_FMT_NV12: S.bpl[0] = w + pad; S.size[0] = S.bpl[0] * h * 3 / 2; break;
    case V4L2_PIX_FMT_YUV420: S.bpl[0] = w + (pad & ~1u); S.size[0] = S.bpl[0] * h * 3 / 2; break;
    default: /* NV12M */
        S.n_planes = 2;
        S.bpl[0] = S.bpl[1] = w + pad;
        S.size[0] = S.bpl[0] * h;
        S.size[1] = S.bpl[1] * h / 2;
    }
}

static int do_fmt(struct v4l2_format *f, int apply)
{
    uint32_t want;
    int p;
    if ((int)f->type != (S.mplane ? V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE : V4L2_BUF_TYPE_VIDEO_CAPTURE)) { errno = EINVAL; return -1; }
    if (apply && S.n_buffers) { errno = EBUSY; return -1; }
    want = S.mplane ? f->fmt.pix_mp.pixelformat : f->fmt.pix.pixelformat;
    if (S.forced) want = S.forced;
    if (want != V4L2_PIX_FMT_YUYV && want != V4L2_PIX_FMT_NV12 && want != V4L2_PIX_FMT_YUV420 &&
        !(want == V4L2_PIX_FMT_NV12M && S.mplane))
        want = V4L2_PIX_FMT_YUYV;
    set_format(want);
    if (S.mplane) {
        memset(&f->fmt.pix_mp, 0, sizeof f->fmt.pix_mp);
        f->fmt.pix_mp.width = (uint32_t)S.width;
        f->fmt.pix_mp.height = (uint32_t)S.height;
        f->fmt.pix_mp.pixelformat = S.fourcc;
        f->fmt.pix_mp.field = V4L2_FIELD_NONE;
        f->fmt.pix_mp.num_planes = (uint8_t)S.n_planes;
        for (p = 0; p < S.n_planes; p++) {
            f->fmt.pix_mp.plane_fmt[p].bytesperline = S.bpl[p];
            f->fmt.pix_mp.plane_fmt[p].sizeimage = S.size[p];
        }
    } else {
        memset(&f->fmt.pix, 0, sizeof f->fmt.pix);
        f->fmt.pix.width = (uint32_t)S.width;
        f->fmt.pix.height = (uint32_t)S.height;
        f->fmt.pix.pixelformat = S.fourcc;
        f->fmt.pix.field = V4L2_FIELD_NONE;
        f->fmt.pix.bytesperline = S.bpl[0];
        f->fmt.pix.sizeimage = S.size[0];
    }
    return 0;
}

/* Convert clip frame `index` into buffer b in the current format. */
static void fill(int b, long index)
{
    const int w = S.width, h = S.height;
    const uint8_t *y = S.clip + (size_t)(index % S.frames) * w * h * 3 / 2, *u = y + w * h, *v = u + (w / 2) * (h / 2);
    uint8_t *d = S.mem[b][0];
    int r, i;
    switch (S.fourcc) {
    case V4L2_PIX_FMT_YUYV:
        for (r = 0; r < h; r++)
            for (i = 0; i < w / 2; i++) {
                uint8_t *o = d + (size_t)r * S.bpl[0] + 4 * i;
                o[0] = y[r * w + 2 * i]; o[1] = u[(r / 2) * (w / 2) + i];
                o[2] = y[r * w + 2 * i + 1]; o[3] = v[(r / 2) * (w / 2) + i];
            }
        break;
    case V4L2_PIX_FMT_YUV420:
        for (r = 0; r < h; r++) memcpy(d + (size_t)r * S.bpl[0], y + r * w, (size_t)w);
        for (r = 0; r < h / 2; r++) {
            memcpy(d + (size_t)S.bpl[0] * h + (size_t)r * (S.bpl[0] / 2), u + r * (w / 2), (size_t)w / 2);
            memcpy(d + (size_t)S.bpl[0] * h + (size_t)(S.bpl[0] / 2) * (h / 2) + (size_t)r * (S.bpl[0] / 2), v + r * (w / 2), (size_t)w / 2);
        }
        break;
    default: { /* NV12, NV12M */
        uint8_t *uv = S.n_planes == 2 ? S.mem[b][1] : d + (size_t)S.bpl[0] * h;
        const uint32_t uv_bpl = S.n_planes == 2 ? S.bpl[1] : S.bpl[0];
        for (r = 0; r < h; r++) memcpy(d + (size_t)r * S.bpl[0], y + r * w, (size_t)w);
        for (r = 0; r < h / 2; r++)
            for (i = 0; i < w / 2; i++) {
                uv[(size_t)r * uv_bpl + 2 * i] = u[r * (w / 2) + i];
                uv[(size_t)r * uv_bpl + 2 * i + 1] = v[r * (w / 2) + i];
            }
    }
    }
}

static int dqbuf(struct v4l2_buffer *buf)
{
    int b, p, bad_error, bad_short;
    if (S.disconnected) { errno = ENODEV; return -1; }
    if (!S.streaming) { errno = EINVAL; return -1; }
    if (fault_now(F_DQEINTR)) { errno = EINTR; return -1; }
    if (fault_now(F_EAGAIN)) { S.attempts++; errno = EAGAIN; return -1; }
    if (fault_now(F_EIO)) { S.attempts++; errno = EIO; return -1; }
    if (!S.count) { errno = EAGAIN; return -1; }
    if (fault_now(F_DROP)) { S.clip_pos++; S.sequence++; }
    bad_error = fault_now(F_ERROR);
    bad_short = fault_now(F_SHORT);
    b = S.order[S.head];
    S.head = (S.head + 1) % FAKE_MAX_BUFFERS;
    S.count--;
    S.queued[b] = 0;
    if (bad_error || bad_short) {
        for (p = 0; p < S.n_planes; p++) memset(S.mem[b][p], 0xA5, S.size[p]);   /* garbage */
    } else {
        fill(b, S.clip_pos);
    }
    S.clip_pos++;
    buf->index = (uint32_t)b;
    buf->flags = V4L2_BUF_FLAG_MAPPED | (bad_error ? V4L2_BUF_FLAG_ERROR : 0);
    buf->field = V4L2_FIELD_NONE;
    buf->sequence = (uint32_t)S.sequence++;
    if (S.mplane) {
        for (p = 0; p < S.n_planes && p < (int)buf->length; p++)
            buf->m.planes[p].bytesused = bad_short ? S.size[p] / 2 : S.size[p];
    } else {
        buf->bytesused = bad_short ? S.size[0] / 2 : S.size[0];
    }
    S.attempts++;
    S.delivered++;
    return 0;
}

static int fake_ioctl(unsigned long request, void *arg)
{
    int b, p;
    if (S.disconnected && request != VIDIOC_STREAMOFF && request != VIDIOC_REQBUFS) { errno = ENODEV; return -1; }
    switch (request) {
    case VIDIOC_QUERYCAP: {
        struct v4l2_capability *c = arg;
        memset(c, 0, sizeof *c);
        snprintf((char *)c->driver, sizeof c->driver, "fake_v4l2");
        snprintf((char *)c->card, sizeof c->card, "libhome test clip");
        c->device_caps = V4L2_CAP_STREAMING | (S.mplane ? V4L2_CAP_VIDEO_CAPTURE_MPLANE : V4L2_CAP_VIDEO_CAPTURE);
        c->capabilities = c->device_caps | V4L2_CAP_DEVICE_CAPS;
        return 0;
    }
    case VIDIOC_S_FMT: return do_fmt(arg, 1);
    case VIDIOC_TRY_FMT: return do_fmt(arg, 0);
    case VIDIOC_G_FMT: {
        struct v4l2_format *f = arg;
        if (!S.fourcc) set_format(V4L2_PIX_FMT_YUYV);
        f->fmt.pix.pixelformat = S.fourcc;
        f->fmt.pix_mp.pixelformat = S.fourcc;
        return do_fmt(f, 0);
    }
    case VIDIOC_REQBUFS: {
        struct v4l2_requestbuffers *r = arg;
        if (r->memory != V4L2_MEMORY_MMAP) { errno = EINVAL; return -1; }
        for (b = 0; b < S.n_buffers; b++)
            for (p = 0; p < 3; p++) { free(S.mem[b][p]); S.mem[b][p] = NULL; }
        S.n_buffers = (int)(r->count > FAKE_MAX_BUFFERS ? FAKE_MAX_BUFFERS : r->count);
        if (!S.fourcc) set_format(V4L2_PIX_FMT_YUYV);
        for (b = 0; b < S.n_buffers; b++)
            for (p = 0; p < S.n_planes; p++)
                if (posix_memalign((void **)&S.mem[b][p], 4096, S.size[p])) { errno = ENOMEM; return -1; }
        r->count = (uint32_t)S.n_buffers;
        S.count = S.head = 0;
        memset(S.queued, 0, sizeof S.queued);
        return 0;
    }
    case VIDIOC_QUERYBUF: {
        struct v4l2_buffer *q = arg;
        if ((int)q->index >= S.n_buffers) { errno = EINVAL; return -1; }
        q->flags = V4L2_BUF_FLAG_MAPPED;
        if (S.mplane) {
            if ((int)q->length < S.n_planes || !q->m.planes) { errno = EINVAL; return -1; }
            q->length = (uint32_t)S.n_planes;
            for (p = 0; p < S.n_planes; p++) {
                q->m.planes[p].length = S.size[p];
                q->m.planes[p].m.mem_offset = (uint32_t)((q->index * 3 + (uint32_t)p + 1) * FAKE_OFFSET_STEP);
            }
        } else {
            q->length = S.size[0];
            q->m.offset = (q->index * 3 + 1) * FAKE_OFFSET_STEP;
        }
        return 0;
    }
    case VIDIOC_QBUF: {
        struct v4l2_buffer *q = arg;
        if ((int)q->index >= S.n_buffers || S.queued[q->index]) { errno = EINVAL; return -1; }
        S.queued[q->index] = 1;
        S.order[(S.head + S.count) % FAKE_MAX_BUFFERS] = (int)q->index;
        S.count++;
        return 0;
    }
    case VIDIOC_DQBUF: return dqbuf(arg);
    case VIDIOC_STREAMON: S.streaming = 1; S.t_stream_on = monotonic_s(); return 0;
    case VIDIOC_STREAMOFF: S.streaming = 0; S.count = S.head = 0; memset(S.queued, 0, sizeof S.queued); return 0;
    default: errno = ENOTTY; return -1;
    }
}

int ioctl(int fd, unsigned long request, ...)
{
    REAL(ioctl_fn, real_ioctl, "ioctl")
    va_list ap;
    void *arg;
    va_start(ap, request);
    arg = va_arg(ap, void *);
    va_end(ap);
    if (S.ready && fd == S.fd && fd >= 0) return fake_ioctl(request, arg);
    return real_ioctl(fd, request, arg);
}

static void *fake_mmap(size_t len, off_t off)
{
    long slot = (long)(off / FAKE_OFFSET_STEP) - 1;
    int b = (int)(slot / 3), p = (int)(slot % 3);
    if (off % FAKE_OFFSET_STEP || slot < 0 || b >= S.n_buffers || p >= S.n_planes || len > S.size[p]) {
        errno = EINVAL;
        return MAP_FAILED;
    }
    return S.mem[b][p];
}

void *mmap(void *addr, size_t len, int prot, int flags, int fd, off_t off)
{
    REAL(mmap_fn, real_mmap, "mmap")
    if (S.ready && fd == S.fd && fd >= 0) return fake_mmap(len, off);
    return real_mmap(addr, len, prot, flags, fd, off);
}

void *mmap64(void *addr, size_t len, int prot, int flags, int fd, off64_t off)
{
    REAL(mmap64_fn, real_mmap, "mmap64")
    if (S.ready && fd == S.fd && fd >= 0) return fake_mmap(len, (off_t)off);
    return real_mmap(addr, len, prot, flags, fd, off);
}

int munmap(void *addr, size_t len)
{
    REAL(munmap_fn, real_munmap, "munmap")
    int b, p;
    for (b = 0; b < FAKE_MAX_BUFFERS; b++)
        for (p = 0; p < 3; p++)
            if (addr && S.mem[b][p] == addr) return 0;
    return real_munmap(addr, len);
}

/* With FAKE_V4L2_FPS: sleep until the next frame is due (a late reader finds it ready). */
static void pace(void)
{
    double wait;
    struct timespec ts;
    if (S.fps <= 0) return;
    wait = S.t_stream_on + (double)S.clip_pos / S.fps - monotonic_s();
    if (wait <= 0) return;
    ts.tv_sec = (time_t)wait;
    ts.tv_nsec = (long)((wait - (double)ts.tv_sec) * 1e9);
    nanosleep(&ts, NULL);
}

/* 1: a frame can be dequeued (or an error is pending); 0: timeout; -1 EINTR */
static int fake_wait(void)
{
    if (fault_now(F_EINTR)) { errno = EINTR; return -1; }
    if (fault_now(F_DISCONNECT)) S.disconnected = 1;
    if (S.disconnected) return 1;
    if (fault_now(F_STALL)) return 0;
    if (S.streaming && S.count) pace();
    return S.streaming && S.count ? 1 : 0;
}

int select(int nfds, fd_set *r, fd_set *w, fd_set *e, struct timeval *tv)
{
    REAL(select_fn, real_select, "select")
    if (S.ready && S.fd >= 0 && S.fd < nfds && r && FD_ISSET(S.fd, r)) {
        int st = fake_wait();
        if (st < 0) return -1;
        FD_ZERO(r);
        if (w) FD_ZERO(w);
        if (e) FD_ZERO(e);
        if (st) FD_SET(S.fd, r);
        return st;
    }
    return real_select(nfds, r, w, e, tv);
}

int poll(struct pollfd *fds, nfds_t n, int timeout)
{
    REAL(poll_fn, real_poll, "poll")
    nfds_t i;
    for (i = 0; S.ready && i < n; i++)
        if (fds[i].fd == S.fd && S.fd >= 0) {
            int st = fake_wait();
            if (st < 0) return -1;
            fds[i].revents = (short)(st ? (S.disconnected ? POLLERR : POLLIN) : 0);
            return st;
        }
    return real_poll(fds, n, timeout);
}
