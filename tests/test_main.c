/* libhome unit and end-to-end test runner. Prints one line per test and a closing
 * "N passed, N failed" line; exits non-zero on any failure. `home-tests NAME...` runs a subset. */
#include "test.h"
#include "test_util.h"
#include "synth.h"
#include <math.h>
#include <stdint.h>
#include <string.h>


#define TEST_LIST(X) \
    X(config_defaults) X(arena_layout) X(hough_geometry_cache) X(heap_keeps_top_k) X(hough_edge_extremum) \
    X(hough_wrap_symmetry) X(descriptor_invariance) X(homography_plausible) X(lm_exact_lines) X(halving_with_outliers) X(theta_window_prior) \
    X(end_to_end_structured) X(end_to_end_weak_texture) X(downscaled_hough) X(video_config) X(fast_pass) X(video_reuse_matches_pair) \
    X(deterministic_output) X(fails_cleanly) X(bad_inputs) X(kernels_radon) X(kernels_line_ends) X(kernels_resample) X(kernels_nearest) \
    X(kernels_smooth) X(kernels_box_down) X(kernels_extremum_candidates) X(refine_kernels_backends) \
    X(warp_backends_identical) X(warp_plane_end) X(backends_identical_output) X(fast_hough_matches_exact) \
    X(static_scene_is_identity) X(shift_is_translation) X(model_cap) X(model_floor_weighs_perspective) \
    X(capped_perspective_is_one_motion) X(sigma_calibrated) X(few_edges_never_wrong) \
    X(few_edges_similarity_stands_in) X(few_edges_half_size_stand_ins) \
    X(few_edges_lens_shading_stand_ins) \
    X(textured_mover_never_steers) X(static_fog_is_identity) X(raw_fog_never_moves) X(fence_never_aliased) \
    X(pegboard_never_aliased)

#define DECLARE(name) void test_##name(void);
TEST_LIST(DECLARE)
#define ENTRY(name) {#name, test_##name},
static const test_case tests[] = {TEST_LIST(ENTRY)};

/* One static arena shared by the tests (the library itself never allocates). */
static union { unsigned char bytes[24u << 20]; double align; } arena;

home_context *test_context(int width, int height, const home_config *override_cfg)
{
    home_config cfg;
    home_context *ctx = NULL;
    if (override_cfg) cfg = *override_cfg;
    else if (home_default_config(&cfg, width, height) != HOME_OK) return NULL;
    if (home_init(&ctx, &cfg, ALIGNED_ARENA(arena.bytes), ALIGNED_BYTES(arena.bytes), NULL) != HOME_OK)
        return NULL;
    return ctx;
}

void test_map_line(const double *h, int width, int height, double theta, double r,
                   double *theta_out, double *r_out)
{
    double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1), inv[9], l[3], m[3], n;
    int k;
    /* centred (cos, sin, -r) -> pixel line; lines map by H^-T */
    l[0] = cos(theta); l[1] = sin(theta); l[2] = -r - cos(theta) * cx - sin(theta) * cy;
    synth_invert(h, inv);
    for (k = 0; k < 3; k++) m[k] = inv[0 * 3 + k] * l[0] + inv[1 * 3 + k] * l[1] + inv[2 * 3 + k] * l[2];
    n = sqrt(m[0] * m[0] + m[1] * m[1]);
    if (h[6] * cx + h[7] * cy + h[8] < 0) n = -n;
    for (k = 0; k < 3; k++) m[k] /= n;
    *theta_out = atan2(m[1], m[0]);
    *r_out = -m[2] - m[0] * cx - m[1] * cy;
}

int main(int argc, char **argv)
{
    return test_run(tests, sizeof tests / sizeof tests[0], "", argc, argv);
}
