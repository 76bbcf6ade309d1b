// libhome speed benchmark, side by side with OpenCV's ORB pipeline in one run.
// For each size (640x360, 1280x720) it renders a structured scene and the same scene under a
// known homography, then times, as medians over many runs on one thread:
//   HOME video frame: extract the new frame + match against the previous frame's cached
//     features + homography (+ refinement when on), per backend (scalar, SSE2, AVX2/NEON);
//   HOME pair: both images (home_register), per stage;
//   ORB frame: ORB(2000).detectAndCompute on the new frame + BFMatcher knn ratio 0.75 against
//     the previous frame's cached descriptors + findHomography(RANSAC).
//   Head to head: the ORB frame and the HOME video frames (home_video_config, and the same
//     with the refinement ending at full size; the automatic backend) timed in rotation, 5x
//     runs of each, so load on a shared machine hits all alike; then the still-pair protocol:
//     ORB on both images + matching + homography against home_register() with the defaults
//     (a fast pass first, from 640 px wide) and in one pass.
// Prints a table and the ratios; usage: home-bench [runs]
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
extern "C" {
#include "home.h"
#include "synth.h"
}

static double now_ms(void *) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

static double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

struct HomeTimes { double frame, stage[HOME_STAGE_COUNT], pair_total; double err; size_t arena; };

// A HOME context on its own arena.
struct HomeContext {
    size_t bytes;
    std::vector<unsigned char> mem;
    home_context *ctx = nullptr;
    explicit HomeContext(const home_config &cfg) : bytes(home_arena_size(&cfg)), mem(bytes + HOME_ARENA_ALIGN) {
        void *arena = (void *)(((uintptr_t)mem.data() + HOME_ARENA_ALIGN - 1) & ~(uintptr_t)(HOME_ARENA_ALIGN - 1));
        if (home_init(&ctx, &cfg, arena, bytes, NULL) != HOME_OK) ctx = nullptr;
    }
};

// preset 0: defaults with refinement (and home_register()'s fast pass); 1: defaults without
// the refinement; 2: home_video_config (Hough of a ~160 px wide box-downscaled frame, 120
// theta bins, theta window, refinement ending at half size); 3: the video preset with the
// refinement ending at full size (refine_finest_level 0); 4: the defaults in one pass
// (fast_pass_downscale 0: the full-size Hough transform only)
static const char *preset_name[] = {"default", "no-refine", "video", "video-full", "one-pass"};
enum { N_PRESETS = 5 };

static void preset_config(int preset, int w, int h, home_config &cfg) {
    if (preset == 2 || preset == 3) home_video_config(&cfg, w, h);
    else home_default_config(&cfg, w, h);
    if (preset == 1) cfg.refine_levels = 0;
    if (preset == 3) cfg.refine_finest_level = 0;
    if (preset == 4) cfg.fast_pass_downscale = 0;
}

static bool time_home(int simd, int preset, int w, int h, const std::vector<uint8_t> &a,
                      const std::vector<uint8_t> &b, const double *truth, int runs, HomeTimes &out) {
    home_config cfg;
    preset_config(preset, w, h, cfg);
    cfg.simd = simd;
    cfg.clock = now_ms;
    if (home_validate_config(&cfg) != HOME_OK) return false;
    HomeContext home(cfg);
    home_context *ctx = home.ctx;
    if (!ctx) return false;
    out.arena = home.bytes;
    static home_features fa, fb;
    home_result res;
    std::vector<double> frame, total, stage[HOME_STAGE_COUNT];
    for (int i = 0; i < runs; i++) {
        home_register(ctx, a.data(), w, b.data(), w, &res);
        total.push_back(res.ms[HOME_STAGE_TOTAL]);
        for (int s = 0; s < HOME_STAGE_COUNT; s++) stage[s].push_back(res.ms[s]);
    }
    out.err = synth_corner_error(res.H, truth, w, h);
    for (int i = 0; i < runs; i++) {
        home_extract(ctx, a.data(), w, &fa);  // the previous frame, cached (not timed)
        double t0 = now_ms(nullptr);
        home_extract(ctx, b.data(), w, &fb);
        home_match(ctx, &fa, &fb, &res);
        frame.push_back(now_ms(nullptr) - t0);
    }
    out.frame = median(frame);
    out.pair_total = median(total);
    for (int s = 0; s < HOME_STAGE_COUNT; s++) out.stage[s] = median(stage[s]);
    return true;
}

// ORB(2000) + BFMatcher knn ratio 0.75 + findHomography(RANSAC) against cached features of A.
struct OrbPipeline {
    cv::Ptr<cv::ORB> orb = cv::ORB::create(2000);
    cv::BFMatcher bf{cv::NORM_HAMMING};
    std::vector<cv::KeyPoint> ka, kb;
    cv::Mat da, db;
    explicit OrbPipeline(const cv::Mat &ma) { orb->detectAndCompute(ma, cv::noArray(), ka, da); }
    // a still pair: both images' features, then as frame()
    cv::Mat pair(const cv::Mat &ma, const cv::Mat &mb) {
        orb->detectAndCompute(ma, cv::noArray(), ka, da);
        return frame(mb);
    }
    // one new frame: features, matches against A's, homography (A -> B), empty if too few
    cv::Mat frame(const cv::Mat &mb) {
        orb->detectAndCompute(mb, cv::noArray(), kb, db);
        std::vector<std::vector<cv::DMatch>> knn;
        bf.knnMatch(da, db, knn, 2);
        std::vector<cv::Point2f> src, dst;
        for (auto &m : knn)
            if (m.size() == 2 && m[0].distance < 0.75f * m[1].distance) {
                src.push_back(ka[m[0].queryIdx].pt);
                dst.push_back(kb[m[0].trainIdx].pt);
            }
        return src.size() >= 4 ? cv::findHomography(src, dst, cv::RANSAC) : cv::Mat();
    }
};

static double time_orb(int w, int h, const std::vector<uint8_t> &a, const std::vector<uint8_t> &b,
                       const double *truth, int runs, double &err) {
    cv::Mat ma(h, w, CV_8UC1, (void *)a.data()), mb(h, w, CV_8UC1, (void *)b.data()), H;
    OrbPipeline orb(ma);
    std::vector<double> t;
    for (int i = 0; i < runs; i++) {
        double t0 = now_ms(nullptr);
        H = orb.frame(mb);
        t.push_back(now_ms(nullptr) - t0);
    }
    err = -1;
    if (!H.empty()) {
        double he[9];
        for (int k = 0; k < 9; k++) he[k] = H.at<double>(k / 3, k % 3) / H.at<double>(2, 2);
        err = synth_corner_error(he, truth, w, h);
    }
    return median(t);
}

// ORB and two HOME presets in rotation, runs times each, medians (the automatic backend).
// pair: the still-pair protocol (ORB on both images + matching + homography, home_register());
// else one new frame against the previous one's cached features (home_extract + home_match).
static bool head_to_head(int w, int h, const std::vector<uint8_t> &a, const std::vector<uint8_t> &b,
                         int runs, const int *presets, bool pair, double &orb_ms, double *home_ms,
                         const char **backend) {
    cv::Mat ma(h, w, CV_8UC1, (void *)a.data()), mb(h, w, CV_8UC1, (void *)b.data());
    OrbPipeline orb(ma);
    home_config cfg[2];
    preset_config(presets[0], w, h, cfg[0]);
    preset_config(presets[1], w, h, cfg[1]);
    HomeContext home0(cfg[0]), home1(cfg[1]);
    HomeContext *home[2] = {&home0, &home1};
    if (!home0.ctx || !home1.ctx) return false;
    *backend = home_simd_backend(home0.ctx);
    static home_features fa, fb;
    home_result res;
    std::vector<double> t_orb, t_home[2];
    for (int i = 0; i < runs; i++) {
        double t0 = now_ms(nullptr);
        if (pair) orb.pair(ma, mb);
        else orb.frame(mb);
        t_orb.push_back(now_ms(nullptr) - t0);
        for (int k = 0; k < 2; k++) {
            home_context *ctx = home[k]->ctx;
            if (pair) {
                t0 = now_ms(nullptr);
                home_register(ctx, a.data(), w, b.data(), w, &res);
            } else {
                home_extract(ctx, a.data(), w, &fa);  // the previous frame, cached (not timed)
                t0 = now_ms(nullptr);
                home_extract(ctx, b.data(), w, &fb);
                home_match(ctx, &fa, &fb, &res);
            }
            t_home[k].push_back(now_ms(nullptr) - t0);
        }
    }
    orb_ms = median(t_orb);
    home_ms[0] = median(t_home[0]);
    home_ms[1] = median(t_home[1]);
    return true;
}

// Only the per-frame work, n times, for instruction counting under callgrind:
//   home-bench --frames orb|video|video-full|home N [downscale [theta_window [threshold_start [theta_bins [keypoints]]]]]
// (video: home_video_config; video-full: the same, refinement ending at full size; home: the defaults with the given overrides)
static int count_frames(const char *method, int n, int downscale, int window, float t0, int theta_bins,
                        int keypoints) {
    const int w = 640, h = 360;
    double ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, hw[9];
    synth_rng rng;
    synth_seed(&rng, 99);
    synth_corner_homography(&rng, w, h, 12, hw);
    std::vector<uint8_t> a((size_t)w * h), b((size_t)w * h);
    synth_render(SYNTH_STRUCTURED, 7, ident, 2.5, 1, a.data(), w, h, w);
    synth_render(SYNTH_STRUCTURED, 7, hw, 2.5, 2, b.data(), w, h, w);
    if (std::string(method) == "orb") {
        double err;
        time_orb(w, h, a, b, hw, n, err);
        return 0;
    }
    home_config cfg;
    if (std::string(method) == "video" || std::string(method) == "video-full") {
        preset_config(std::string(method) == "video" ? 2 : 3, w, h, cfg);
        downscale = cfg.hough_downscale;
        window = cfg.match_theta_window;
    } else {
        home_default_config(&cfg, w, h);
    }
    cfg.hough_downscale = downscale;
    cfg.match_theta_window = window;
    if (t0 > 0) cfg.threshold_start = t0;
    if (theta_bins > 0) cfg.theta_bins = theta_bins;
    if (keypoints > 0) cfg.keypoints_per_sign = keypoints;
    HomeContext home(cfg);
    home_context *ctx = home.ctx;
    if (!ctx) return 1;
    static home_features fa, fb;
    home_result res;
    // a video alternating between the two frames: each step extracts one new frame and
    // registers it against the previous one, whose refinement snapshot the context still holds
    home_extract(ctx, a.data(), w, &fa);
    for (int i = 0; i < n; i++) {
        home_features *prev = i % 2 ? &fb : &fa, *cur = i % 2 ? &fa : &fb;
        home_extract(ctx, (i % 2 ? a : b).data(), w, cur);
        home_match(ctx, prev, cur, &res);
        if (res.refine_status != HOME_REFINE_ACCEPTED) fprintf(stderr, "frame %d not refined\n", i);
    }
    return 0;
}

int main(int argc, char **argv) {
    if (argc > 3 && std::string(argv[1]) == "--frames")
        return count_frames(argv[2], atoi(argv[3]), argc > 4 ? atoi(argv[4]) : 1,
                            argc > 5 ? atoi(argv[5]) : 0, argc > 6 ? (float)atof(argv[6]) : 0.0f,
                            argc > 7 ? atoi(argv[7]) : 0, argc > 8 ? atoi(argv[8]) : 0);
    int runs = argc > 1 ? atoi(argv[1]) : 41;
    cv::setNumThreads(1);  // single thread, like libhome
    static const int sizes[][2] = {{640, 360}, {1280, 720}};
    static const struct { int simd; const char *name; } backends[] = {
        {HOME_SIMD_NONE, "scalar"}, {HOME_SIMD_SSE, "sse2"}, {HOME_SIMD_AVX2, "avx2"}, {HOME_SIMD_NEON, "neon"}};
    printf("libhome %s vs OpenCV %s ORB(2000)+BFMatcher ratio 0.75+findHomography(RANSAC), one thread,\n"
           "medians of %d runs; frame = one new frame registered against cached features\n\n",
           HOME_VERSION_STRING, CV_VERSION, runs);
    for (auto &sz : sizes) {
        int w = sz[0], h = sz[1];
        double s = w / 640.0, scale[9] = {s, 0, 0, 0, s, 0, 0, 0, 1}, hwarp[9], hb[9];
        synth_rng rng;
        synth_seed(&rng, 99);
        synth_corner_homography(&rng, w, h, 12 * s, hwarp);
        // scene -> image: scale the 640x360 scene, then (for B) the known motion
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                hb[r * 3 + c] = 0;
                for (int k = 0; k < 3; k++) hb[r * 3 + c] += hwarp[r * 3 + k] * scale[k * 3 + c];
            }
        std::vector<uint8_t> a((size_t)w * h), b((size_t)w * h);
        synth_render(SYNTH_STRUCTURED, 7, scale, 2.5, 1, a.data(), w, h, w);
        synth_render(SYNTH_STRUCTURED, 7, hb, 2.5, 2, b.data(), w, h, w);
        double orb_err, orb_ms = time_orb(w, h, a, b, hwarp, runs, orb_err);
        printf("== %dx%d   ORB frame: %.2f ms (corner error %.3f px)\n", w, h, orb_ms, orb_err);
        printf("%-8s %-9s %8s %8s %6s | pair stages: %7s %7s %8s %6s %6s %6s %7s | %8s %6s\n", "backend",
               "preset", "frame", "ORB/HOME", "err", "hough", "detect", "describe", "match", "homog",
               "refine", "total", "arena", "");
        for (auto &bk : backends)
            for (int preset = 0; preset < N_PRESETS; preset++) {
                HomeTimes t;
                if (!time_home(bk.simd, preset, w, h, a, b, hwarp, runs, t)) continue;
                printf("%-8s %-9s %8.2f %8.2f %6.3f | %19.2f %7.2f %8.2f %6.2f %6.2f %6.2f %7.2f | %8zu\n",
                       bk.name, preset_name[preset], t.frame, orb_ms / t.frame, t.err,
                       t.stage[HOME_STAGE_HOUGH], t.stage[HOME_STAGE_DETECT], t.stage[HOME_STAGE_DESCRIBE],
                       t.stage[HOME_STAGE_MATCH], t.stage[HOME_STAGE_HOMOGRAPHY], t.stage[HOME_STAGE_REFINE],
                       t.stage[HOME_STAGE_TOTAL], t.arena);
            }
        double h2h_orb, h2h_home[2];
        const char *backend = "";
        static const int video_presets[2] = {2, 3}, pair_presets[2] = {0, 4};
        if (head_to_head(w, h, a, b, 5 * runs, video_presets, false, h2h_orb, h2h_home, &backend))
            printf("head to head (in rotation, %d runs each, %s): ORB frame %.2f ms; HOME video frame "
                   "%.2f ms, ORB/HOME %.2f; video-full frame %.2f ms, ORB/HOME %.2f\n",
                   5 * runs, backend, h2h_orb, h2h_home[0], h2h_orb / h2h_home[0], h2h_home[1],
                   h2h_orb / h2h_home[1]);
        double pair_orb, pair_home[2];
        if (head_to_head(w, h, a, b, 5 * runs, pair_presets, true, pair_orb, pair_home, &backend))
            printf("still pairs head to head (in rotation, %d runs each): ORB pair %.2f ms; HOME "
                   "defaults pair %.2f ms, HOME/ORB %.2f; in one pass %.2f ms, HOME/ORB "
                   "%.2f\n",
                   5 * runs, pair_orb, pair_home[0], pair_home[0] / pair_orb, pair_home[1],
                   pair_home[1] / pair_orb);
        printf("\n");
    }
    return 0;
}
