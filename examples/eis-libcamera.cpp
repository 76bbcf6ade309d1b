// eis-libcamera: live electronic image stabilisation over libcamera (C++17).
// Acquire the camera, configure one stream (validate; an Adjusted configuration is reported and
// used), allocate buffers with FrameBufferAllocator - or, where it fails (no /dev/dma_heap and no
// /dev/udmabuf, as on some boards and in containers), in application memory: one memfd per
// buffer, which pipeline handlers that fill buffers from the CPU (the virtual camera) accept -
// and queue one request per buffer; completed requests are handed from the camera thread to the
// main thread through a queue, stabilised there with libhome, written as Y4M (I420) and reused.
// A frame byte-identical to the one before (a source repeating frames: libcamera's virtual
// camera shows each image 4 times) is not registered again: it is written as a copy of that
// frame's stabilised output. A clean stop cancels and frees all. With --threads N > 1 (default:
// the online CPUs up to 4) the warp of each due frame runs in row bands on a fixed pool of N - 1
// workers (eis_pool.h), whose last band's worker writes it out, while the main thread registers
// the next frame: the same bytes as one thread.
// Builds against Debian 12's libcamera 0.0.3 and libcamera 0.4 to 0.7 (Raspberry Pi OS).
// Exit: 0 done, 2 usage/setup error, 3 camera lost or failed while streaming, 4 no camera.
#include "eis_common.h"
#include "eis_pool.h"
#include "home_stab.h"

#include <libcamera/libcamera.h>

#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

using namespace libcamera;

namespace {

std::atomic<bool> stop_requested{false};
void on_signal(int) { stop_requested = true; }

struct Options {
    std::string camera_id, output, raw_output;
    unsigned width = 640, height = 480;
    std::string format = "yu12";
    long frames = 0;
    float margin_x = 0.10f, margin_y = 0.10f, smoothing = 0.0f;   // 0: automatic (home_stab_config)
    int lookahead = EIS_LIVE_LOOKAHEAD;
    int threads = 0;   // 0: eis_pool_auto_threads()
    bool quiet = false, keep_repeats = false;
};

void usage(FILE *f)
{
    std::fprintf(f, "usage: eis-libcamera [--camera ID|INDEX] [--size WxH] [--format yu12|nv12|yuyv]\n"
                    "       [--frames N] [--margin F] [--margin-x F] [--margin-y F] [--smoothing F]\n"
                    "       [--lookahead N] [--threads N] [--output FILE.y4m|-] [--raw-output FILE.y4m]\n"
                    "       [--keep-repeats] [--quiet] [--list]\n"
                    "  --frames N        stop after N captured frames (default: until interrupted)\n"
                    "  --output F        the stabilised frames as Y4M (I420); --raw-output F: as captured\n"
                    "  --keep-repeats    register a frame identical to the one before as any other (by\n"
                    "                    default it is written as a copy of that frame's stabilised output)\n"
                    "  --threads N       1: register, warp and write in turn; N > 1: the warp in bands on\n"
                    "                    N - 1 more threads while the next frame registers (same bytes);\n"
                    "                    0 (default): the online CPUs, at most %d (here %d)\n"
                    "Buffers come from the camera's FrameBufferAllocator or, where that fails, from\n"
                    "memfd application memory. Exit: 0 done, 2 usage/setup error, 3 camera lost or\n"
                    "failed, 4 no camera.\n", EIS_POOL_AUTO_MAX, eis_pool_auto_threads());
}

int stab_format(const PixelFormat &f)
{
    if (f == formats::YUV420) return HOME_STAB_I420;
    if (f == formats::NV12) return HOME_STAB_NV12;
    if (f == formats::YUYV) return HOME_STAB_YUYV;
    return 0;
}

// Completed requests, handed over from the camera thread: the slot does nothing else.
class CompletionQueue {
public:
    void push(Request *r)
    {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            queue_.push_back(r);
        }
        cv_.notify_one();
    }
    // nullptr on timeout
    Request *pop(int timeout_ms)
    {
        std::unique_lock<std::mutex> lock(mutex_);
        if (!cv_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [this] { return !queue_.empty(); }))
            return nullptr;
        Request *r = queue_.front();
        queue_.pop_front();
        return r;
    }

private:
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<Request *> queue_;
};

// A dmabuf (or memfd) mapped once, whole; each plane is base + offset.
struct Mapping {
    void *base = MAP_FAILED;
    size_t length = 0;
};

// Bytes of each plane of a frame as libcamera lays it out for a stream of luma stride `stride`:
// YUV420 Y, U, V; NV12 Y, UV; YUYV one plane.
std::vector<size_t> plane_bytes(int format, unsigned stride, unsigned height)
{
    const size_t luma = (size_t)stride * height;
    if (format == HOME_STAB_YUYV) return {luma};
    if (format == HOME_STAB_NV12) return {luma, (size_t)stride * (height / 2)};
    return {luma, (size_t)(stride / 2) * (height / 2), (size_t)(stride / 2) * (height / 2)};
}

// The fallback when FrameBufferAllocator fails: `count` buffers in application memory, each a
// memfd with the planes one after the other (as the allocators lay them out in one dmabuf).
// A pipeline handler that fills buffers from the CPU (the virtual camera, a software ISP) maps
// them like dmabufs; one that hands them to a V4L2 device needs real dmabufs and fails to queue
// them. Empty on failure, with errno set.
std::vector<std::unique_ptr<FrameBuffer>> memfd_buffers(int format, unsigned stride, unsigned height,
                                                         size_t frame_size, unsigned count)
{
    std::vector<std::unique_ptr<FrameBuffer>> buffers;
    const std::vector<size_t> sizes = plane_bytes(format, stride, height);
    size_t total = 0;
    for (size_t s : sizes) total += s;
    total = std::max(total, frame_size);
    for (unsigned i = 0; i < count; i++) {
        int fd = memfd_create("eis-libcamera", MFD_CLOEXEC);
        if (fd < 0 || ftruncate(fd, (off_t)total) < 0) {
            int err = errno;
            if (fd >= 0) close(fd);
            errno = err;
            return {};
        }
        SharedFD shared(std::move(fd));   // owns the descriptor; the planes share it
        std::vector<FrameBuffer::Plane> planes;
        size_t offset = 0;
        for (size_t s : sizes) {
            FrameBuffer::Plane plane;
            plane.fd = shared;
            plane.offset = (unsigned)offset;
            plane.length = (unsigned)s;
            planes.push_back(plane);
            offset += s;
        }
        buffers.push_back(std::make_unique<FrameBuffer>(planes));
    }
    return buffers;
}

} // namespace

int main(int argc, char **argv)
{
    Options o;
    bool list_only = false;
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : nullptr;
        if (a == "--help") { usage(stdout); return 0; }
        if (a == "--quiet") { o.quiet = true; continue; }
        if (a == "--list") { list_only = true; continue; }
        if (a == "--keep-repeats") { o.keep_repeats = true; continue; }
        if (!v) { std::fprintf(stderr, "eis-libcamera: %s needs a value (see --help)\n", a.c_str()); return 2; }
        i++;
        char *end = nullptr;
        bool bad = false;
        if (a == "--camera") o.camera_id = v;
        else if (a == "--output") o.output = v;
        else if (a == "--raw-output") o.raw_output = v;
        else if (a == "--format") { o.format = v; bad = o.format != "yu12" && o.format != "nv12" && o.format != "yuyv"; }
        else if (a == "--size") bad = std::sscanf(v, "%ux%u", &o.width, &o.height) != 2 || o.width < 32 || o.height < 32;
        else if (a == "--frames") { o.frames = std::strtol(v, &end, 10); bad = *end || o.frames < 0; }
        else if (a == "--margin") { o.margin_x = o.margin_y = std::strtof(v, &end); bad = *end; }
        else if (a == "--margin-x") { o.margin_x = std::strtof(v, &end); bad = *end; }
        else if (a == "--margin-y") { o.margin_y = std::strtof(v, &end); bad = *end; }
        else if (a == "--smoothing") { o.smoothing = std::strtof(v, &end); bad = *end; }
        else if (a == "--threads") { o.threads = (int)std::strtol(v, &end, 10); bad = *end || o.threads < 0 || o.threads > EIS_POOL_MAX_THREADS; }
        else if (a == "--lookahead") { o.lookahead = (int)std::strtol(v, &end, 10); bad = *end || o.lookahead < 0 || o.lookahead > HOME_STAB_MAX_LOOKAHEAD; }
        else { std::fprintf(stderr, "eis-libcamera: unknown option %s (see --help)\n", a.c_str()); return 2; }
        if (bad) { std::fprintf(stderr, "eis-libcamera: bad value for %s: %s\n", a.c_str(), v); return 2; }
    }
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", 0);   // libcamera's INFO lines would drown ours

    auto cm = std::make_unique<CameraManager>();
    if (int ret = cm->start()) {
        // without udev, libcamera enumerates media devices through sysfs, and fails where the
        // kernel has no media bus (no camera driver loaded: containers, CI machines)
        const bool no_media_bus = access("/sys/bus/media/devices", F_OK) != 0;
        std::fprintf(stderr, "eis-libcamera: cannot start the camera manager: %s%s\n", std::strerror(-ret),
                     no_media_bus ? " (/sys/bus/media/devices is missing: no media device driver is loaded; "
                                    "see docs/libcamera.md)" : "");
        return 2;
    }
    std::vector<std::shared_ptr<Camera>> cameras = cm->cameras();
    if (list_only) {
        for (size_t i = 0; i < cameras.size(); i++) std::printf("%zu: %s\n", i, cameras[i]->id().c_str());
    }
    if (cameras.empty()) {
        std::fprintf(stderr, "eis-libcamera: no camera found (libcamera lists none)%s\n",
                     list_only ? "" : "; connect one, or use eis-v4l2 for a UVC webcam");
        cm->stop();
        return list_only ? 0 : 4;
    }
    if (list_only) { cm->stop(); return 0; }

    std::shared_ptr<Camera> camera;
    if (o.camera_id.empty()) camera = cameras[0];
    for (size_t i = 0; !camera && i < cameras.size(); i++)
        if (cameras[i]->id() == o.camera_id || std::to_string(i) == o.camera_id) camera = cameras[i];
    if (!camera) {
        std::fprintf(stderr, "eis-libcamera: no camera '%s' (see --list)\n", o.camera_id.c_str());
        cm->stop();
        return 4;
    }
    if (camera->acquire()) {
        std::fprintf(stderr, "eis-libcamera: camera %s is in use by another process\n", camera->id().c_str());
        camera.reset();
        cm->stop();
        return 2;
    }

    int rc = 0;
    std::unique_ptr<CameraConfiguration> config = camera->generateConfiguration({StreamRole::Viewfinder});
    std::unique_ptr<FrameBufferAllocator> allocator;
    std::vector<std::unique_ptr<FrameBuffer>> own_buffers;   // the memfd fallback's
    std::vector<std::unique_ptr<Request>> requests;
    std::map<int, Mapping> maps;   // by dmabuf fd
    CompletionQueue completed;
    bool started = false;
    home_stab *stab = nullptr;
    void *arena = nullptr;
    std::vector<std::vector<uint8_t>> ring;
    std::vector<int> repeats;   // per ring slot: captured repeats of that frame not yet written
    std::vector<int> copies;    // per ring slot: outputs the output job writes of its frame
    std::vector<uint8_t> warped, i420, job_i420;   // i420: this thread's; job_i420: the output job's
    eis_pool *pool = nullptr;
    FILE *out = nullptr, *raw_out = nullptr;
    Stream *stream = nullptr;
    int format = 0;
    unsigned width = 0, height = 0, stride = 0;
    long captured = 0, pushed = 0, repeated = 0, written = 0, failed_frames = 0;
    long shown = -1;   // the newest frame (push index) whose stabilised output was written

    auto write_i420 = [&](FILE *f, const uint8_t *frame, std::vector<uint8_t> &buf) -> bool {
        eis_to_i420(format, (int)width, (int)height, frame, buf.data(), 0, 0);
        if (std::fputs("FRAME\n", f) < 0 || std::fwrite(buf.data(), 1, buf.size(), f) != buf.size()) {
            std::fprintf(stderr, "eis-libcamera: write error\n");
            return false;
        }
        return true;
    };
    // the output job, once frame `frame` is warped (on a pool worker, or here with one thread)
    std::function<int(long)> output_job = [&](long frame) -> int {
        for (int c = copies[(size_t)frame % ring.size()]; out && c > 0; c--, written++)
            if (!write_i420(out, warped.data(), job_i420)) return 1;
        return 0;
    };
    const eis_pool_done_fn run_output_job = [](void *user, long frame, double) -> int {
        return (*static_cast<std::function<int(long)> *>(user))(frame);
    };
    // warp the frame due and write it, once and once more per repeat of it captured so far,
    // after the previous one (it shares `warped` and the counters)
    auto show = [&](const home_stab_output &so) -> bool {
        home_stab_image src, dst;
        const size_t slot = (size_t)so.frame % ring.size();
        if (eis_pool_wait(pool) != HOME_OK) return false;
        eis_frame_view(format, (int)width, (int)height, ring[slot].data(), &src);
        eis_frame_view(format, (int)width, (int)height, warped.data(), &dst);
        copies[slot] = 1 + repeats[slot];
        repeats[slot] = 0;
        shown = so.frame;
        return eis_pool_submit(pool, so.warp, &src, &dst, run_output_job, &output_job, so.frame) == HOME_OK;
    };

    do {
        if (!config || config->size() != 1) { std::fprintf(stderr, "eis-libcamera: no viewfinder configuration\n"); rc = 2; break; }
        StreamConfiguration &sc = config->at(0);
        sc.size.width = o.width;
        sc.size.height = o.height;
        sc.pixelFormat = o.format == "nv12" ? formats::NV12 : o.format == "yuyv" ? formats::YUYV : formats::YUV420;
        CameraConfiguration::Status status = config->validate();
        if (status == CameraConfiguration::Invalid) { std::fprintf(stderr, "eis-libcamera: configuration invalid\n"); rc = 2; break; }
        if (status == CameraConfiguration::Adjusted && !o.quiet)
            std::fprintf(stderr, "eis-libcamera: configuration adjusted to %s\n", sc.toString().c_str());
        format = stab_format(sc.pixelFormat);
        if (!format) {
            std::fprintf(stderr, "eis-libcamera: the camera offers %s; supported: YUV420, NV12, YUYV\n", sc.pixelFormat.toString().c_str());
            rc = 2;
            break;
        }
        if (camera->configure(config.get())) { std::fprintf(stderr, "eis-libcamera: configure failed\n"); rc = 2; break; }
        stream = sc.stream();
        width = sc.size.width;
        height = sc.size.height;
        stride = sc.stride;
        if (width % 2 || height % 2 || stride < (format == HOME_STAB_YUYV ? 2 * width : width)) {
            std::fprintf(stderr, "eis-libcamera: unusable stream %ux%u stride %u\n", width, height, stride);
            rc = 2;
            break;
        }

        home_stab_config cfg;
        int st = home_stab_default_config(&cfg, (int)width, (int)height);
        cfg.margin_x = o.margin_x;
        cfg.margin_y = o.margin_y;
        cfg.smoothing = o.smoothing;
        cfg.lookahead = o.lookahead;
        cfg.clock = eis_now_ms;
        if (st == HOME_OK) st = home_stab_validate_config(&cfg);
        size_t need = st == HOME_OK ? home_stab_arena_size(&cfg) : 0;
        if (st != HOME_OK || posix_memalign(&arena, HOME_ARENA_ALIGN, need) ||
            (st = home_stab_init(&stab, &cfg, arena, need, nullptr)) != HOME_OK) {
            std::fprintf(stderr, "eis-libcamera: stabiliser: %s\n", home_strerror(st != HOME_OK ? st : HOME_E_NULL));
            rc = 2;
            break;
        }
        if (eis_pool_start(&pool, o.threads)) { std::fprintf(stderr, "eis-libcamera: cannot start %d threads\n", o.threads); rc = 2; break; }
        if (!o.quiet) std::fprintf(stderr, "eis-libcamera: %d thread(s)\n", eis_pool_threads(pool));
        const size_t fbytes = eis_frame_bytes(format, (int)width, (int)height);
        // the stabiliser reports frame n - lookahead: keep them; with workers, frame n + 1 is
        // captured while frame n - lookahead is warped; and a new frame is compared with the
        // newest pushed before it replaces it (causal on one thread: a ring of 1 compared the
        // frame with itself, and every frame after the first was taken as a repeat)
        ring.assign((size_t)cfg.lookahead + 1 + (eis_pool_threads(pool) > 1 || cfg.lookahead == 0),
                    std::vector<uint8_t>(fbytes));
        repeats.assign(ring.size(), 0);
        copies.assign(ring.size(), 0);
        warped.resize(fbytes);
        i420.resize((size_t)width * height * 3 / 2);
        job_i420.resize(i420.size());
        if (!o.output.empty()) {
            out = o.output == "-" ? stdout : std::fopen(o.output.c_str(), "wb");
            if (!out) { std::fprintf(stderr, "eis-libcamera: cannot write %s\n", o.output.c_str()); rc = 2; break; }
            std::fprintf(out, "YUV4MPEG2 W%u H%u F30:1 Ip A1:1 C420jpeg\n", width, height);
        }
        if (!o.raw_output.empty()) {
            raw_out = std::fopen(o.raw_output.c_str(), "wb");
            if (!raw_out) { std::fprintf(stderr, "eis-libcamera: cannot write %s\n", o.raw_output.c_str()); rc = 2; break; }
            std::fprintf(raw_out, "YUV4MPEG2 W%u H%u F30:1 Ip A1:1 C420jpeg\n", width, height);
        }

        allocator = std::make_unique<FrameBufferAllocator>(camera);
        std::vector<FrameBuffer *> buffers;
        if (allocator->allocate(stream) > 0) {
            for (const std::unique_ptr<FrameBuffer> &buffer : allocator->buffers(stream)) buffers.push_back(buffer.get());
        } else {
            allocator.reset();
            own_buffers = memfd_buffers(format, stride, height, sc.frameSize, std::max(sc.bufferCount, 4u));
            if (own_buffers.empty()) {
                std::fprintf(stderr, "eis-libcamera: cannot allocate buffers, from the camera nor in memory (memfd: %s)\n",
                             std::strerror(errno));
                rc = 2;
                break;
            }
            if (!o.quiet)
                std::fprintf(stderr, "eis-libcamera: the camera's buffer allocator failed (no /dev/dma_heap or "
                                     "/dev/udmabuf?): %zu buffers in application memory (memfd)\n", own_buffers.size());
            for (const std::unique_ptr<FrameBuffer> &buffer : own_buffers) buffers.push_back(buffer.get());
        }
        for (FrameBuffer *buffer : buffers) {
            for (const FrameBuffer::Plane &plane : buffer->planes()) {
                Mapping &m = maps[plane.fd.get()];
                m.length = std::max(m.length, (size_t)plane.offset + plane.length);
            }
            std::unique_ptr<Request> request = camera->createRequest();
            if (!request || request->addBuffer(stream, buffer)) { std::fprintf(stderr, "eis-libcamera: cannot create a request\n"); rc = 2; break; }
            requests.push_back(std::move(request));
        }
        if (rc) break;
        for (auto &[fd, m] : maps) {
            m.base = mmap(nullptr, m.length, PROT_READ, MAP_SHARED, fd, 0);
            if (m.base == MAP_FAILED) { std::fprintf(stderr, "eis-libcamera: mmap: %s\n", std::strerror(errno)); rc = 2; break; }
        }
        if (rc) break;

        camera->requestCompleted.connect(&completed, &CompletionQueue::push);
        if (camera->start()) { std::fprintf(stderr, "eis-libcamera: cannot start the camera\n"); rc = 2; break; }
        started = true;
        for (std::unique_ptr<Request> &r : requests)
            if (camera->queueRequest(r.get()) < 0) {
                std::fprintf(stderr, "eis-libcamera: cannot queue a request%s\n",
                             own_buffers.empty() ? "" : " (this camera needs dmabufs: memfd buffers serve only "
                                                        "pipeline handlers that fill buffers from the CPU)");
                rc = 3;
                break;
            }
        if (rc) break;

        double since = eis_now_ms(nullptr), ms_reg = 0;
        long frames_since = 0;
        while (!stop_requested && (o.frames == 0 || captured < o.frames)) {
            Request *request = completed.pop(2000);
            if (!request) { std::fprintf(stderr, "eis-libcamera: no frame within 2 s: camera stalled\n"); rc = 3; break; }
            if (request->status() == Request::RequestCancelled) break;   // the camera is stopping
            FrameBuffer *buffer = request->buffers().begin()->second;
            const FrameMetadata &meta = buffer->metadata();
            bool ok = meta.status == FrameMetadata::FrameSuccess;
            if (ok) {
                // copy the planes out (respecting the stride), then give the buffer back at once
                uint8_t *slot = ring[(size_t)pushed % ring.size()].data();
                home_stab_image im;
                eis_frame_view(format, (int)width, (int)height, slot, &im);
                const auto &planes = buffer->planes();
                for (size_t p = 0; ok && p < planes.size() && p < 3 && im.plane[p]; p++) {
                    const Mapping &m = maps[planes[p].fd.get()];
                    const uint8_t *src = (const uint8_t *)m.base + planes[p].offset;
                    const size_t src_stride = p == 0 ? stride : (format == HOME_STAB_NV12 ? stride : stride / 2);
                    const int rows = p == 0 ? (int)height : (int)height / 2;
                    const size_t row_bytes = (size_t)im.stride[p];
                    if (src_stride * (size_t)(rows - 1) + row_bytes > planes[p].length) { ok = false; break; }
                    eis_copy_rows(im.plane[p], row_bytes, src, src_stride, row_bytes, rows);
                }
                if (ok && planes.size() == 1 && format != HOME_STAB_YUYV) {
                    // all planes in one: chroma follows the luma at stride * height
                    const Mapping &m = maps[planes[0].fd.get()];
                    const uint8_t *base = (const uint8_t *)m.base + planes[0].offset + (size_t)stride * height;
                    const size_t cstride = format == HOME_STAB_NV12 ? stride : stride / 2;
                    if ((size_t)stride * height + cstride * (height / 2) * (format == HOME_STAB_NV12 ? 1 : 2) > m.length) ok = false;
                    else {
                        eis_copy_rows(im.plane[1], (size_t)im.stride[1], base, cstride, (size_t)im.stride[1], (int)height / 2);
                        if (format == HOME_STAB_I420)
                            eis_copy_rows(im.plane[2], (size_t)im.stride[2], base + cstride * (height / 2), cstride, (size_t)im.stride[2], (int)height / 2);
                    }
                }
                if (ok) captured++;
                if (ok && raw_out && !write_i420(raw_out, slot, i420)) rc = 2;
                if (ok && !rc && !o.keep_repeats && pushed > 0 &&
                    std::memcmp(slot, ring[(size_t)(pushed - 1) % ring.size()].data(), fbytes) == 0) {
                    // a repeat of the newest frame: written again if its output already was,
                    // else with it
                    repeated++;
                    if (shown == pushed - 1) {   // once its output job is done
                        if (eis_pool_wait(pool) != HOME_OK || (out && !write_i420(out, warped.data(), i420))) rc = 2;
                        written += out ? 1 : 0;
                    } else {
                        repeats[(size_t)(pushed - 1) % ring.size()]++;
                    }
                } else if (ok && !rc) {
                    home_stab_output so;
                    int st2 = home_stab_push(stab, &im, &so);
                    if (st2 != HOME_OK) { std::fprintf(stderr, "eis-libcamera: stabiliser: %s\n", home_strerror(st2)); rc = 2; }
                    repeats[(size_t)pushed % ring.size()] = 0;
                    pushed++;
                    frames_since++;
                    ms_reg += so.ms_register;
                    if (!rc && so.ready && !show(so)) rc = 2;
                }
            }
            if (!ok) failed_frames++;
            request->reuse(Request::ReuseBuffers);
            if (!rc && camera->queueRequest(request) < 0) { std::fprintf(stderr, "eis-libcamera: camera lost (cannot requeue)\n"); rc = 3; }
            if (rc) break;
            if (!o.quiet && eis_now_ms(nullptr) - since >= 1000.0) {
                double dt = eis_now_ms(nullptr) - since;
                std::fprintf(stderr, "eis-libcamera: %.1f fps | register %.1f ms/frame | %ld failed frames\n",
                             frames_since * 1e3 / dt, frames_since ? ms_reg / frames_since : 0.0, failed_frames);
                since = eis_now_ms(nullptr);
                frames_since = 0;
                ms_reg = 0;
            }
        }
        home_stab_output so;
        while (rc != 2 && home_stab_flush(stab, &so) == HOME_OK && so.ready)
            if (!show(so)) { rc = 2; break; }
    } while (false);
    if (pool && eis_pool_wait(pool) != HOME_OK) rc = 2;   // the last frame out
    eis_pool_stop(pool);

    if (started) camera->stop();           // completes every pending request as cancelled
    if (started) camera->requestCompleted.disconnect(&completed, &CompletionQueue::push);
    requests.clear();
    for (auto &[fd, m] : maps)
        if (m.base != MAP_FAILED) munmap(m.base, m.length);
    if (allocator && stream) allocator->free(stream);
    allocator.reset();
    own_buffers.clear();
    config.reset();
    camera->release();
    camera.reset();
    cm->stop();
    if (!o.quiet)
        std::fprintf(stderr, "eis-libcamera: %ld frames captured (%ld registered, %ld repeats), %ld written, %ld failed%s\n",
                     captured, pushed, repeated, written, failed_frames, stop_requested ? ", stopped by signal" : "");
    if (out && std::fflush(out) != 0) rc = 2;
    if (out && out != stdout && std::fclose(out) != 0) rc = 2;
    if (raw_out && std::fclose(raw_out) != 0) rc = 2;
    std::free(arena);
    return rc;
}
