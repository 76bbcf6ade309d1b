// home_eis: an rpicam-apps post-processing stage that stabilises the main (video) stream with
// libhome (C++17; an out-of-tree stage library, loaded by rpicam-vid --post-process-libs DIR and
// configured by the "home_eis" block of the --post-process-file JSON).
//
// Each request's Process() runs on a thread of its own, so the stage puts the requests back in
// order first: a request waits under the mutex until the one before it (by sequence number) is
// through, or - a frame that failed at the camera never reaches the stages, leaving a gap -
// until it is the oldest waiting for gap_ms. Then, still under the mutex: the main frame is
// copied into a ring of lookahead + 1 frames, the motion is registered on the low-resolution
// YUV420 stream when one is configured (rpicam-apps' "lores" block; its luma is read in place)
// or else on the main stream's luma, and the frame due - the one from `lookahead` requests back
// - is warped from the ring into this request's buffer. The first `lookahead` requests have no
// frame due and are dropped (the video starts that many frames late: the lookahead is latency);
// at Stop the last `lookahead` frames are lost with it, as no request is left to carry them.
// A request whose turn has passed (it arrived after its gap was closed) goes through untouched.
//
// JSON parameters, named as home-stab's options: lookahead (frames, default 6), margin (0.10),
// margin_x, margin_y (override margin per axis), smoothing (frames, 0 = automatic), ease,
// downscale (1, 2, 4; 0 = the library's choice), use_lores (1: motion from the lores stream
// when there is one), gap_ms (100), verbose (0, 1: statistics once a second).
#include <libcamera/formats.h>
#include <libcamera/stream.h>

#include "core/rpicam_app.hpp"
#include "post_processing_stages/post_processing_stage.hpp"

#include "home_stab.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <set>
#include <vector>

using libcamera::Stream;

namespace {

constexpr char const *kName = "home_eis";

class HomeEisStage : public PostProcessingStage
{
public:
    explicit HomeEisStage(RPiCamApp *app) : PostProcessingStage(app) {}
    ~HomeEisStage() override { Teardown(); }

    char const *Name() const override { return kName; }
    void Read(boost::property_tree::ptree const &params) override;
    void AdjustConfig(std::string const &use_case, StreamConfiguration *config) override;
    void Configure() override;
    bool Process(CompletedRequestPtr &completed_request) override;
    void Stop() override;
    void Teardown() override;

private:
    struct Params {
        int lookahead = 6;
        float margin = 0.10f, margin_x = -1.0f, margin_y = -1.0f, smoothing = 0.0f, ease = -1.0f;
        int downscale = 0;
        bool use_lores = true, verbose = false;
        int gap_ms = 100;
    } params_;

    // waits under lock until this sequence's turn; false: its turn has passed
    bool waitTurn(std::unique_lock<std::mutex> &lock, unsigned int sequence);
    bool stabilise(CompletedRequest &request);   // under mutex_; true: drop the request

    std::mutex mutex_;
    std::condition_variable turn_;
    std::set<unsigned int> waiting_;   // sequences of the requests waiting for their turn
    bool have_next_ = false;
    unsigned int next_ = 0;            // the sequence whose turn it is (once have_next_)

    Stream *main_ = nullptr, *lores_ = nullptr;
    StreamInfo main_info_, lores_info_;
    home_stab_config cfg_{};
    void *arena_ = nullptr;
    home_stab *stab_ = nullptr;
    std::vector<std::vector<uint8_t>> ring_;   // main frames, packed I420
    double to_main_[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, to_motion_[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    long pushed_ = 0, shown_ = 0, passed_ = 0;
    std::chrono::steady_clock::time_point since_;
};

void HomeEisStage::Read(boost::property_tree::ptree const &p)
{
    params_.lookahead = p.get<int>("lookahead", params_.lookahead);
    params_.margin = p.get<float>("margin", params_.margin);
    params_.margin_x = p.get<float>("margin_x", params_.margin_x);
    params_.margin_y = p.get<float>("margin_y", params_.margin_y);
    params_.smoothing = p.get<float>("smoothing", params_.smoothing);
    params_.ease = p.get<float>("ease", params_.ease);
    params_.downscale = p.get<int>("downscale", params_.downscale);
    params_.use_lores = p.get<int>("use_lores", 1) != 0;
    params_.gap_ms = p.get<int>("gap_ms", params_.gap_ms);
    params_.verbose = p.get<int>("verbose", 0) != 0;
    if (params_.lookahead < 0 || params_.lookahead > HOME_STAB_MAX_LOOKAHEAD)
        throw std::runtime_error("home_eis: lookahead must be 0.." + std::to_string(HOME_STAB_MAX_LOOKAHEAD));
}

// The stage warps YUV420: ask for it on the stream it stabilises (the main one; a preview's
// default may be RGB)
void HomeEisStage::AdjustConfig(std::string const &use_case, StreamConfiguration *config)
{
    if (use_case == "video" && config->pixelFormat != libcamera::formats::YUV420) {
        LOG(1, kName << ": asking for YUV420 instead of " << config->pixelFormat.toString());
        config->pixelFormat = libcamera::formats::YUV420;
    }
}

void HomeEisStage::Configure()
{
    Teardown();
    main_ = app_->GetMainStream();
    if (!main_) return;
    main_info_ = app_->GetStreamInfo(main_);
    if (main_info_.pixel_format != libcamera::formats::YUV420 || main_info_.width % 2 || main_info_.height % 2) {
        LOG_ERROR(kName << ": the main stream is " << main_info_.pixel_format.toString() << " "
                        << main_info_.width << "x" << main_info_.height << "; stabilising only even-sized YUV420: off");
        main_ = nullptr;
        return;
    }
    lores_ = params_.use_lores ? app_->LoresStream(&lores_info_) : nullptr;
    if (lores_ && (lores_info_.pixel_format != libcamera::formats::YUV420 || lores_info_.width % 2 ||
                   lores_info_.height % 2 || lores_info_.width > main_info_.width)) {
        LOG(1, kName << ": the lores stream is not even-sized YUV420 no larger than the main one: motion from the main stream");
        lores_ = nullptr;
    }
    const unsigned mw = lores_ ? lores_info_.width : main_info_.width;
    const unsigned mh = lores_ ? lores_info_.height : main_info_.height;

    int st = home_stab_default_config(&cfg_, (int)mw, (int)mh);
    cfg_.margin_x = params_.margin_x >= 0 ? params_.margin_x : params_.margin;
    cfg_.margin_y = params_.margin_y >= 0 ? params_.margin_y : params_.margin;
    cfg_.smoothing = params_.smoothing;
    cfg_.lookahead = params_.lookahead;
    if (params_.ease >= 0) cfg_.ease = params_.ease;
    if (params_.downscale) cfg_.downscale = params_.downscale;
    if (st == HOME_OK) st = home_stab_validate_config(&cfg_);
    const size_t need = st == HOME_OK ? home_stab_arena_size(&cfg_) : 0;
    if (st != HOME_OK || posix_memalign(&arena_, HOME_ARENA_ALIGN, need) ||
        (st = home_stab_init(&stab_, &cfg_, arena_, need, nullptr)) != HOME_OK)
        throw std::runtime_error(std::string("home_eis: stabiliser: ") + home_strerror(st != HOME_OK ? st : HOME_E_NULL));

    // motion is measured in the lores frame: a warp there becomes T W T^-1 on the main frame,
    // T mapping lores pixel centres onto main ones (x_main = (x + 0.5) sx - 0.5)
    const double sx = (double)main_info_.width / mw, sy = (double)main_info_.height / mh;
    const double t[9] = {sx, 0, 0.5 * sx - 0.5, 0, sy, 0.5 * sy - 0.5, 0, 0, 1};
    const double ti[9] = {1 / sx, 0, -(0.5 * sx - 0.5) / sx, 0, 1 / sy, -(0.5 * sy - 0.5) / sy, 0, 0, 1};
    std::copy(t, t + 9, to_main_);
    std::copy(ti, ti + 9, to_motion_);
    ring_.assign((size_t)cfg_.lookahead + 1, std::vector<uint8_t>((size_t)main_info_.width * main_info_.height * 3 / 2));
    LOG(1, kName << ": " << main_info_.width << "x" << main_info_.height << ", motion from the "
                 << (lores_ ? "lores" : "main") << " stream (" << mw << "x" << mh << "), lookahead " << cfg_.lookahead
                 << ", margins " << cfg_.margin_x << " x " << cfg_.margin_y);
}

bool HomeEisStage::waitTurn(std::unique_lock<std::mutex> &lock, unsigned int sequence)
{
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(params_.gap_ms);
    waiting_.insert(sequence);
    for (;;) {
        if (have_next_ && sequence == next_) break;
        if (have_next_ && sequence < next_) { waiting_.erase(sequence); return false; }
        // the oldest waiting, its predecessor missing: a gap once gap_ms have passed
        const bool oldest = *waiting_.begin() == sequence;
        if (oldest && std::chrono::steady_clock::now() >= deadline) break;
        if (oldest) turn_.wait_until(lock, deadline);
        else turn_.wait(lock);
    }
    waiting_.erase(sequence);
    return true;
}

bool HomeEisStage::Process(CompletedRequestPtr &completed_request)
{
    if (!main_ || !stab_) return false;
    std::unique_lock<std::mutex> lock(mutex_);
    bool drop = false;
    if (waitTurn(lock, completed_request->sequence)) {
        drop = stabilise(*completed_request);
        have_next_ = true;
        next_ = completed_request->sequence + 1;
    } else {
        passed_++;
    }
    turn_.notify_all();
    return drop;
}

bool HomeEisStage::stabilise(CompletedRequest &request)
{
    const unsigned w = main_info_.width, h = main_info_.height, stride = main_info_.stride;
    BufferWriteSync main_sync(app_, request.buffers[main_]);
    const std::vector<libcamera::Span<uint8_t>> &planes = main_sync.Get();
    // YUV420 planes: three spans, or one holding all three one after the other
    uint8_t *p[3];
    const size_t luma = (size_t)stride * h, chroma = (size_t)(stride / 2) * (h / 2);
    if (planes.size() >= 3) {
        for (int i = 0; i < 3; i++) p[i] = planes[i].data();
    } else if (!planes.empty() && planes[0].size() >= luma + 2 * chroma) {
        p[0] = planes[0].data();
        p[1] = p[0] + luma;
        p[2] = p[1] + chroma;
    } else {
        LOG_ERROR(kName << ": unexpected main buffer layout");
        return false;
    }
    home_stab_image frame;   // the request's buffer as it is
    frame.format = HOME_STAB_I420;
    frame.width = (int)w;
    frame.height = (int)h;
    frame.stride[0] = stride;
    frame.stride[1] = frame.stride[2] = stride / 2;
    for (int i = 0; i < 3; i++) frame.plane[i] = p[i];

    // 1. copy the frame into the ring (packed I420)
    home_stab_image slot;
    uint8_t *dst = ring_[(size_t)pushed_ % ring_.size()].data();
    slot.format = HOME_STAB_I420;
    slot.width = (int)w;
    slot.height = (int)h;
    slot.plane[0] = dst;
    slot.plane[1] = dst + (size_t)w * h;
    slot.plane[2] = slot.plane[1] + (size_t)(w / 2) * (h / 2);
    slot.stride[0] = w;
    slot.stride[1] = slot.stride[2] = w / 2;
    for (int i = 0; i < 3; i++) {
        const unsigned rows = i ? h / 2 : h, bytes = i ? w / 2 : w;
        for (unsigned r = 0; r < rows; r++)
            std::memcpy(slot.plane[i] + (size_t)r * slot.stride[i], frame.plane[i] + (size_t)r * frame.stride[i], bytes);
    }

    // 2. register it: the lores luma in place, or the main luma from the copy
    home_stab_output out;
    int st;
    if (lores_) {
        BufferReadSync lores_sync(app_, request.buffers[lores_]);
        home_stab_image motion{};
        motion.format = HOME_STAB_GREY;
        motion.width = (int)lores_info_.width;
        motion.height = (int)lores_info_.height;
        motion.plane[0] = lores_sync.Get()[0].data();
        motion.stride[0] = lores_info_.stride;
        st = home_stab_push(stab_, &motion, &out);
    } else {
        st = home_stab_push(stab_, &slot, &out);
    }
    pushed_++;
    if (st != HOME_OK) {
        LOG_ERROR(kName << ": stabiliser: " << home_strerror(st));
        return false;
    }
    if (!out.ready) return true;   // nothing due yet: the lookahead is filling

    // 3. the frame due, warped into this request's buffer
    double m[9], warp[9];
    for (int r = 0; r < 3; r++)   // m = to_main * warp_motion, warp = m * to_motion
        for (int c = 0; c < 3; c++) {
            m[3 * r + c] = 0;
            for (int k = 0; k < 3; k++) m[3 * r + c] += to_main_[3 * r + k] * out.warp[3 * k + c];
        }
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            warp[3 * r + c] = 0;
            for (int k = 0; k < 3; k++) warp[3 * r + c] += m[3 * r + k] * to_motion_[3 * k + c];
        }
    home_stab_image src = slot;
    const uint8_t *due = ring_[(size_t)out.frame % ring_.size()].data();
    src.plane[0] = const_cast<uint8_t *>(due);
    src.plane[1] = src.plane[0] + (size_t)w * h;
    src.plane[2] = src.plane[1] + (size_t)(w / 2) * (h / 2);
    st = home_stab_warp(warp, &src, &frame);
    if (st != HOME_OK) LOG_ERROR(kName << ": warp: " << home_strerror(st));
    shown_++;
    if (params_.verbose) {
        auto now = std::chrono::steady_clock::now();
        if (now - since_ >= std::chrono::seconds(1)) {
            LOG(1, kName << ": frame " << out.frame << " shown in request " << request.sequence << ", correction used "
                         << out.correction_used << ", newest registration " << out.newest_status << " ("
                         << out.ms_register << " ms)");
            since_ = now;
        }
    }
    return false;
}

// The camera stops: frames still held cannot be shown (no request is left to carry them); a
// restart begins a new path
void HomeEisStage::Stop()
{
    std::lock_guard<std::mutex> lock(mutex_);
    if (stab_) home_stab_reset(stab_);
    if (params_.verbose && (shown_ || passed_))
        LOG(1, kName << ": " << pushed_ << " frames registered, " << shown_ << " shown, " << passed_
                     << " passed through out of turn");
    have_next_ = false;
    pushed_ = shown_ = passed_ = 0;
}

void HomeEisStage::Teardown()
{
    std::lock_guard<std::mutex> lock(mutex_);
    stab_ = nullptr;
    std::free(arena_);
    arena_ = nullptr;
    ring_.clear();
    have_next_ = false;
}

PostProcessingStage *Create(RPiCamApp *app) { return new HomeEisStage(app); }

RegisterStage reg(kName, &Create);

} // namespace
