#!/usr/bin/env bash
# Instruction counts per video frame (one new 640x360 frame registered against cached
# features), HOME per backend vs the ORB pipeline, by valgrind callgrind: repeatable whatever
# else the machine is doing. Each count is (N=3 frames) - (N=1 frame), halved, so set-up and
# the first frame's work cancel out. The Cortex-A72 column assumes the aarch64 NEON build runs
# about as many instructions as the x86 SSE2 build (both 128-bit) at an IPC of 1.5 at 1.5 GHz:
# an estimate, not a measurement; `make bench-arm` counts ARM's own instructions (docs/speed.md).
set -u
BUILD=${BUILD:-build}
bench=$BUILD/bin/home-bench
command -v valgrind > /dev/null || { echo "instructions: valgrind not installed, skipped"; exit 0; }
count() { # simd, method, n, downscale
  HOME_SIMD=$1 valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bench" --frames "$2" "$3" "$4" 2>&1 >/dev/null |
    awk '/Collected/ {print $NF}'
}
per_frame() { local one three; one=$(count "$@" 1 "${4:-1}"); three=$(count "$1" "$2" 3 "${4:-1}"); echo $(( (three - one) / 2 )); }
orb=$(per_frame none orb x 1)
echo "(A72 column: x86 SSE2 instructions at IPC 1.5; ARM's own counts: make bench-arm)"
printf '\n%-8s %-10s %14s %10s %14s\n' method preset frame_Ir "ORB/HOME" "A72 est. ms"
printf '%-8s %-10s %14d %10s %14s\n' orb - "$orb" 1.00 -
for simd in none sse avx2; do
  for preset in default video video-full; do
    method=$([ $preset = default ] && echo home || echo $preset)
    n=$(HOME_SIMD=$simd valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bench" --frames $method 1 2>&1 >/dev/null | awk '/Collected/ {print $NF}')
    m=$(HOME_SIMD=$simd valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bench" --frames $method 3 2>&1 >/dev/null | awk '/Collected/ {print $NF}')
    [ -n "$n" ] && [ -n "$m" ] || continue
    f=$(( (m - n) / 2 ))
    printf '%-8s %-10s %14d %10.2f %14.1f\n' "$simd" "$preset" "$f" \
      "$(echo "$orb / $f" | bc -l)" "$(echo "$f / 1.5 / 1500000" | bc -l)"
  done
done
