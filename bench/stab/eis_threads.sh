#!/usr/bin/env bash
# eis-v4l2 with 1, 2, ... threads on the fake V4L2 device (tests/fake_v4l2): a shaky clip at
# WxH (default 1920x1080, YU12: the fake device's copy is a memcpy) captured in a loop.
#   throughput: frames served as fast as the program takes them, the live default lookahead
#               (6): frames/s from the first capture to the last output
#   latency:    frames paced at FPS (default 30) as a camera gives them, lookahead 0: ms from a
#               frame's dequeue to its output written (mean, max), at a camera's pace
# Each row is the median of ROUNDS runs (default 3); stdout is a Markdown table. Then the
# bytes: 30 frames written with each thread count, compared with one thread's.
#   bash bench/stab/eis_threads.sh [BUILD [W H [THREAD_COUNTS [FRAMES [ROUNDS [FPS]]]]]]
#   e.g. bash bench/stab/eis_threads.sh build 1920 1080 "1 2 3" 300 3 30
set -euo pipefail
build=${1:-build}
w=${2:-1920}
h=${3:-1080}
counts=${4:-"1 2"}
frames=${5:-300}
rounds=${6:-3}
fps=${7:-30}
eis="$build/bin/eis-v4l2"
fake="$build/lib/fake_v4l2.so"
[ -x "$eis" ] && [ -f "$fake" ] || { echo "eis_threads: build eis-v4l2 and the fake device first (make)" >&2; exit 2; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$build/bin/home-stab-clip" --frames 30 --width "$w" --height "$h" --shake 4 --pan 40 --seed 7 \
  "$dir/clip.y4m" "$dir/truth.csv" > /dev/null

run() { # threads lookahead frames output [env...]: the summary line's numbers "fps latency max"
  local t=$1 la=$2 n=$3 out=$4; shift 4
  env "$@" FAKE_V4L2_FORMAT=yu12 FAKE_V4L2_CLIP="$dir/clip.y4m" LD_PRELOAD="$fake" \
    "$eis" --no-window --frames "$n" --lookahead "$la" --threads "$t" --output "$out" 2>&1 |
    sed -n 's/.*thread(s): \([0-9.]*\) frames\/s.*capture to output \([0-9.]*\) ms (max \([0-9.]*\)).*/\1 \2 \3/p'
}
median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

echo "eis-v4l2 on the fake V4L2 device, ${w}x${h} YU12, $(nproc) CPUs, load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| threads | frames/s, unpaced, lookahead 6 | capture to output ms at $fps fps, lookahead 0: mean / max |"
echo "|---|---|---|"
for t in $counts; do
  fpss=""; lat=""; latmax=""
  for r in $(seq "$rounds"); do
    set -- $(run "$t" 6 "$frames" /dev/null)
    fpss="$fpss $1"
    set -- $(run "$t" 0 $((fps * 4)) /dev/null FAKE_V4L2_FPS="$fps")
    lat="$lat $2"; latmax="$latmax $3"
  done
  echo "| $t | $(tr ' ' '\n' <<< "$fpss" | grep . | median) | $(tr ' ' '\n' <<< "$lat" | grep . | median) / $(tr ' ' '\n' <<< "$latmax" | grep . | median) |"
done
echo
same="identical"
for t in $counts; do
  run "$t" 6 30 "$dir/out$t.y4m" > /dev/null
  cmp -s "$dir/out$t.y4m" "$dir/out$(set -- $counts; echo "$1").y4m" || same="DIFFER ($t threads)"
done
echo "bytes of 30 frames with threads $counts: $same; load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
[ "$same" = identical ]
