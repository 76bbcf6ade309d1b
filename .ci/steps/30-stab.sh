#!/usr/bin/env bash
# Stabilisation (issue 6): with SDL2, libcamera, a C++17 compiler and ffmpeg installed, build every
# example (eis-v4l2 with its window, eis-libcamera) and run the stabiliser tests and checks: the
# V4L2 capture loop against the fake device with injected faults, eis-libcamera's clean exit with
# no camera, the Y4M reader against ffmpeg. Then a smoke run of the ffmpeg comparison (bench/stab).
set -euo pipefail
cd "$(dirname "$0")/../.."
export DEBIAN_FRONTEND=noninteractive
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
$SUDO apt-get install -y -qq --no-install-recommends g++ pkg-config libsdl2-dev libcamera-dev ffmpeg \
  linux-libc-dev > /dev/null

# `make test` built everything before SDL2 and libcamera were here: rebuild only what they change
BUILD=${STAB_CI_BUILD:-build}
rm -f "$BUILD/obj/examples/eis-v4l2.o" "$BUILD/bin/eis-v4l2" "$BUILD/bin/eis-libcamera"
make -j2 BUILD=$BUILD all
for bin in eis-v4l2 eis-libcamera home-stab home-stab-clip; do
  [ -x "$BUILD/bin/$bin" ] || { echo "30-stab: $bin was not built"; exit 1; }
done
nm -u "$BUILD/bin/eis-v4l2" | grep -q SDL_CreateWindow || { echo "30-stab: eis-v4l2 built without SDL2"; exit 1; }

# shellcheck source=../checks.sh
. .ci/checks.sh
unit_tests "$BUILD/bin/home-stab-tests" home-stab-tests
# the checks run commands that are meant to fail (as under tests/run.sh, which has no set -e)
set +eu
# shellcheck source=/dev/null
. tests/checks/stab.sh
set -eu
# home-stab's writer thread under ThreadSanitizer (clang: installed by 20-hardening for the fuzzers):
# no race reported, the same bytes as the plain build, and a clean exit 2 on a failing output
if command -v clang > /dev/null; then
  make -j2 BUILD=build-tsan CC=clang SANITIZE=thread build-tsan/bin/home-stab > /dev/null
  export TSAN_OPTIONS="halt_on_error=1 exitcode=66"
  # without address randomisation: clang 14's TSan rejects the mappings of kernels with 32
  # random mmap bits
  tsan_stab="setarch $(uname -m) -R build-tsan/bin/home-stab"
  st=0; st_full=0
  $tsan_stab --quiet --threads 2 --lookahead 6 --side-by-side --csv "$tmp/tsan.csv" "$stab_dir/clip.y4m" "$tmp/tsan.y4m" || st=$?
  "$BUILD/bin/home-stab" --quiet --lookahead 6 --side-by-side --csv "$tmp/plain.csv" "$stab_dir/clip.y4m" "$tmp/plain.y4m"
  $tsan_stab --quiet --threads 2 --lookahead 3 "$stab_dir/clip.y4m" /dev/full 2> /dev/null || st_full=$?
  if [ $st -eq 0 ] && [ $st_full -eq 2 ] && cmp -s "$tmp/tsan.y4m" "$tmp/plain.y4m" && cmp -s "$tmp/tsan.csv" "$tmp/plain.csv"; then
    ok stab_cli_threads_tsan; else fail stab_cli_threads_tsan "exit $st, to /dev/full $st_full"; fi
  # eis-v4l2's warp pool on the fake device: no race, one thread's bytes
  make -j2 BUILD=build-tsan CC=clang SANITIZE=thread build-tsan/bin/eis-v4l2 build-tsan/lib/fake_v4l2.so > /dev/null
  st=0
  for t in 1 3; do
    FAKE_V4L2_CLIP="$stab_dir/clip.y4m" FAKE_V4L2_FORMAT=nv12 LD_PRELOAD=build-tsan/lib/fake_v4l2.so \
      setarch "$(uname -m)" -R build-tsan/bin/eis-v4l2 --no-window --quiet --frames 30 --lookahead 3 --threads $t \
      --output "$tmp/eis_tsan$t.y4m" || st=$?
  done
  if [ $st -eq 0 ] && cmp -s "$tmp/eis_tsan1.y4m" "$tmp/eis_tsan3.y4m"; then
    ok stab_v4l2_threads_tsan; else fail stab_v4l2_threads_tsan "exit $st"; fi
  unset TSAN_OPTIONS
else
  fail stab_cli_threads_tsan "clang not installed"
  fail stab_v4l2_threads_tsan "clang not installed"
fi
# with the dependencies installed, none of the optional checks may have been skipped
require_checks stab_y4m_matches_ffmpeg stab_v4l2_injected_faults stab_v4l2_disconnect_clean_exit \
  stab_libcamera_no_camera

echo "--- bench/stab smoke run (the full comparison: python3 bench/stab/compare.py)"
python3 -c 'import numpy' 2> /dev/null || pip install -q numpy
python3 bench/stab/compare.py --smoke --build "$BUILD"
