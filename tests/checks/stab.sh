# Stabilisation checks (sourced by tests/run.sh: ok/fail, $tmp, $BUILD, $RUNNER, $SANFLAGS):
# home-stab's Y4M contract and bad inputs, the ffmpeg cross-check of the Y4M reader/writer (when
# ffmpeg is installed), eis-v4l2's capture loop against the fake V4L2 device with injected faults,
# and eis-libcamera's clean exit without a camera.
stab_dir="$tmp/stab"
mkdir -p "$stab_dir"
stab="$RUNNER $BUILD/bin/home-stab"
# frame count, width, height and colour tag of a Y4M file
y4m_shape() {
  python3 - "$1" <<'PY'
import sys
d = open(sys.argv[1], 'rb').read()
head = d[:d.index(b'\n')].split()
tags = {t[:1]: t[1:] for t in head[1:]}
print(d.count(b'FRAME'), int(tags[b'W']), int(tags[b'H']), (tags.get(b'C') or b'420jpeg').decode())
PY
}
# compare the first N frames of two Y4M files (whole frames, or luma only)
y4m_same() { # a b frames luma|all
  python3 - "$@" <<'PY'
import sys
def frames(path):
    d = open(path, 'rb').read()
    head = d[:d.index(b'\n')].split()
    tags = {t[:1]: t[1:] for t in head[1:]}
    w, h = int(tags[b'W']), int(tags[b'H'])
    parts = d.split(b'FRAME\n')[1:]
    return [p[:w * h * 3 // 2] for p in parts], w * h
a, luma = frames(sys.argv[1]); b, _ = frames(sys.argv[2]); n = int(sys.argv[3])
cut = luma if sys.argv[4] == 'luma' else None
ok = len(a) >= n and len(b) >= n and all(a[i][:cut] == b[i][:cut] for i in range(n))
sys.exit(0 if ok else 1)
PY
}

$RUNNER "$BUILD/bin/home-stab-clip" --frames 24 --width 320 --height 180 --pan 24 --shake 3 "$stab_dir/clip.y4m" "$stab_dir/truth.csv" > /dev/null

# 1. the Y4M contract: same size out, side by side twice as wide, CSV and plot, pipes
if $stab --csv "$stab_dir/path.csv" --plot "$stab_dir/plot.png" "$stab_dir/clip.y4m" "$stab_dir/out.y4m" 2> "$stab_dir/err" &&
   [ "$(y4m_shape "$stab_dir/out.y4m")" = "24 320 180 420jpeg" ] &&
   [ "$(wc -l < "$stab_dir/path.csv")" -eq 25 ] && head -1 "$stab_dir/path.csv" | grep -q '^frame,status,inliers,raw_tx' &&
   head -c 4 "$stab_dir/plot.png" | od -c | grep -q 'P   N   G' && grep -q 'fps' "$stab_dir/err"; then
  ok stab_cli_y4m_csv_plot; else fail stab_cli_y4m_csv_plot "$(y4m_shape "$stab_dir/out.y4m") $(head -c 300 "$stab_dir/err")"; fi
if $stab --quiet --side-by-side "$stab_dir/clip.y4m" "$stab_dir/sbs.y4m" && [ "$(y4m_shape "$stab_dir/sbs.y4m")" = "24 640 180 420jpeg" ]; then
  ok stab_cli_side_by_side; else fail stab_cli_side_by_side "$(y4m_shape "$stab_dir/sbs.y4m")"; fi
# a pipe cannot be read twice: it gets the whole margins, as --fixed-crop does on a file; a file
# gets the adaptive crop (less zoom, the same path), so its frames differ
$stab --quiet --fixed-crop "$stab_dir/clip.y4m" "$stab_dir/fixed.y4m"
if cat "$stab_dir/clip.y4m" | $stab --quiet - - > "$stab_dir/piped.y4m" &&
   cmp -s "$stab_dir/piped.y4m" "$stab_dir/fixed.y4m" && ! cmp -s "$stab_dir/out.y4m" "$stab_dir/fixed.y4m" &&
   grep -q 'adaptive crop: margins' "$stab_dir/err"; then
  ok stab_cli_pipes; else fail stab_cli_pipes "stdin/stdout output differs from --fixed-crop file output"; fi
if $stab --quiet --lookahead 6 "$stab_dir/clip.y4m" "$stab_dir/la.y4m" && [ "$(y4m_shape "$stab_dir/la.y4m")" = "24 320 180 420jpeg" ]; then
  ok stab_cli_lookahead_drains; else fail stab_cli_lookahead_drains "$(y4m_shape "$stab_dir/la.y4m")"; fi
# the writer thread (--threads 2) changes nothing but the wall time: the same bytes as one thread,
# and a failing output ends the run with exit 2 instead of hanging either thread
if $stab --quiet --threads 1 --lookahead 6 --side-by-side --csv "$stab_dir/t1.csv" "$stab_dir/clip.y4m" "$stab_dir/t1.y4m" &&
   $stab --quiet --threads 2 --lookahead 6 --side-by-side --csv "$stab_dir/t2.csv" "$stab_dir/clip.y4m" "$stab_dir/t2.y4m" &&
   cmp -s "$stab_dir/t1.y4m" "$stab_dir/t2.y4m" && cmp -s "$stab_dir/t1.csv" "$stab_dir/t2.csv" &&
   [ "$(y4m_shape "$stab_dir/t2.y4m")" = "24 640 180 420jpeg" ]; then
  ok stab_cli_threads_same_bytes; else fail stab_cli_threads_same_bytes "--threads 1 and 2 differ"; fi
full_ok=1
if [ -w /dev/full ]; then
  for t in 1 2; do
    timeout 120 $stab --quiet --threads $t --lookahead 3 "$stab_dir/clip.y4m" /dev/full 2> "$stab_dir/e"; st=$?
    { [ $st -eq 2 ] && grep -q 'write error' "$stab_dir/e"; } || { full_ok=0; echo "    --threads $t to /dev/full: exit $st"; }
  done
fi
if [ $full_ok -eq 1 ]; then ok stab_cli_write_error_exits; else fail stab_cli_write_error_exits "no clean exit 2"; fi
python3 - "$stab_dir/clip.y4m" "$stab_dir/c422.y4m" <<'PY'
import sys
d = open(sys.argv[1], 'rb').read(); nl = d.index(b'\n')
w, h = 320, 180; parts = d[nl + 1:].split(b'FRAME\n')[1:]
out = [d[:nl].replace(b'C420jpeg', b'C422') + b'\n']
for p in parts:
    y, u, v = p[:w*h], p[w*h:w*h*5//4], p[w*h*5//4:w*h*3//2]
    up = lambda c: b''.join(c[r*(w//2):(r+1)*(w//2)] * 2 for r in range(h // 2))
    out.append(b'FRAME\n' + y + up(u) + up(v))
open(sys.argv[2], 'wb').write(b''.join(out))
PY
if $stab --quiet "$stab_dir/c422.y4m" "$stab_dir/o422.y4m" && [ "$(y4m_shape "$stab_dir/o422.y4m")" = "24 320 180 422" ] &&
   y4m_same "$stab_dir/o422.y4m" "$stab_dir/out.y4m" 24 luma; then
  ok stab_cli_422; else fail stab_cli_422 "$(y4m_shape "$stab_dir/o422.y4m")"; fi

# 2. malformed input: a clear error; every frame decoded before it is still written
frame_bytes=$((320 * 180 * 3 / 2 + 6))
header_bytes=$(head -1 "$stab_dir/clip.y4m" | wc -c)
head -c $((header_bytes + 10 * frame_bytes + 5000)) "$stab_dir/clip.y4m" > "$stab_dir/trunc.y4m"
$stab --quiet "$stab_dir/trunc.y4m" "$stab_dir/trunc_out.y4m" 2> "$stab_dir/err"; st=$?
if [ $st -eq 1 ] && grep -q 'truncated' "$stab_dir/err" && [ "$(y4m_shape "$stab_dir/trunc_out.y4m")" = "10 320 180 420jpeg" ]; then
  ok stab_cli_truncated_keeps_frames; else fail stab_cli_truncated_keeps_frames "exit $st, $(y4m_shape "$stab_dir/trunc_out.y4m"), $(cat "$stab_dir/err")"; fi
$stab --quiet --threads 2 --lookahead 4 "$stab_dir/trunc.y4m" "$stab_dir/trunc_t2.y4m" 2> /dev/null; st2=$?
$stab --quiet --threads 1 --lookahead 4 "$stab_dir/trunc.y4m" "$stab_dir/trunc_t1.y4m" 2> /dev/null; st1=$?
if [ $st1 -eq 1 ] && [ $st2 -eq 1 ] && cmp -s "$stab_dir/trunc_t1.y4m" "$stab_dir/trunc_t2.y4m" &&
   [ "$(y4m_shape "$stab_dir/trunc_t2.y4m")" = "10 320 180 420jpeg" ]; then
  ok stab_cli_truncated_threads; else fail stab_cli_truncated_threads "exit $st1 / $st2, $(y4m_shape "$stab_dir/trunc_t2.y4m")"; fi
{ head -c $((header_bytes + 7 * frame_bytes)) "$stab_dir/clip.y4m"; printf 'FRAMX\n'; head -c 100 /dev/zero; } > "$stab_dir/bad_marker.y4m"
$stab --quiet "$stab_dir/bad_marker.y4m" "$stab_dir/bm_out.y4m" 2> "$stab_dir/err"; st=$?
if [ $st -eq 1 ] && grep -q 'malformed' "$stab_dir/err" && [ "$(y4m_shape "$stab_dir/bm_out.y4m")" = "7 320 180 420jpeg" ]; then
  ok stab_cli_bad_frame_marker; else fail stab_cli_bad_frame_marker "exit $st, $(cat "$stab_dir/err")"; fi
stab_exit2() { # name, file content (printf format)
  printf "$2" > "$stab_dir/bad.y4m"
  $stab --quiet "$stab_dir/bad.y4m" "$stab_dir/bad_out.y4m" > "$stab_dir/o" 2> "$stab_dir/e"; local st=$?
  if [ $st -eq 2 ] && [ -s "$stab_dir/e" ]; then ok "stab_cli_bad_$1"; else fail "stab_cli_bad_$1" "exit $st, $(head -c 200 "$stab_dir/e")"; fi
}
stab_exit2 empty ''
stab_exit2 not_y4m 'P5\n64 64\n255\n'
stab_exit2 no_size 'YUV4MPEG2 F30:1\n'
stab_exit2 c444 'YUV4MPEG2 W64 H64 C444\n'
stab_exit2 huge 'YUV4MPEG2 W99999 H64\n'
stab_exit2 too_small 'YUV4MPEG2 W16 H16\nFRAME\n'
stab_exit2 odd_420 'YUV4MPEG2 W65 H64\n'
$stab --margin 0.9 "$stab_dir/clip.y4m" "$stab_dir/x.y4m" 2> "$stab_dir/e"; st=$?
if [ $st -eq 2 ] && grep -q 'margin' "$stab_dir/e"; then ok stab_cli_bad_option; else fail stab_cli_bad_option "exit $st"; fi

# 3. the Y4M reader and writer against ffmpeg (when it is installed)
if command -v ffmpeg > /dev/null 2>&1 && [ -z "$RUNNER" ]; then
  if ffmpeg -v error -y -i "$stab_dir/clip.y4m" -f yuv4mpegpipe -pix_fmt yuv420p "$stab_dir/ff.y4m" &&
     $stab --quiet "$stab_dir/ff.y4m" "$stab_dir/ff_out.y4m" && y4m_same "$stab_dir/ff_out.y4m" "$stab_dir/out.y4m" 24 all &&
     ffmpeg -v error -y -i "$stab_dir/out.y4m" -f rawvideo -pix_fmt yuv420p "$stab_dir/out.yuv" &&
     [ "$(stat -c %s "$stab_dir/out.yuv")" -eq $((24 * 320 * 180 * 3 / 2)) ] &&
     python3 - "$stab_dir/out.y4m" "$stab_dir/out.yuv" <<'PY'
import sys
d = open(sys.argv[1], 'rb').read(); raw = open(sys.argv[2], 'rb').read()
sys.exit(0 if b''.join(d[d.index(b'\n') + 1:].split(b'FRAME\n')) == raw else 1)
PY
  then ok stab_y4m_matches_ffmpeg; else fail stab_y4m_matches_ffmpeg; fi
fi

# 4. eis-v4l2's capture loop against the fake V4L2 device
if [ -x "$BUILD/bin/eis-v4l2" ] && [ -f "$BUILD/lib/fake_v4l2.so" ] && [ -z "$RUNNER" ]; then
  preload="$BUILD/lib/fake_v4l2.so"
  # sanitized programs: the sanitizer runtime need not come first in the preload list
  export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0"
  eis() { # env assignments..., then -- and eis-v4l2 arguments; sets st
    local envs=()
    while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
    rm -f "$stab_dir/eis.log"
    env "${envs[@]}" FAKE_V4L2_CLIP="$stab_dir/clip.y4m" FAKE_V4L2_LOG="$stab_dir/eis.log" LD_PRELOAD="$preload" \
      "$BUILD/bin/eis-v4l2" --no-window --timeout-ms 500 "$@" > "$stab_dir/eis.out" 2> "$stab_dir/eis.err"
    st=$?
  }
  # every format and API: the stabilised frames equal home-stab's (same library, same 16 frames,
  # the live examples' default lookahead of 6)
  python3 - "$stab_dir/clip.y4m" "$stab_dir/clip16.y4m" <<'PY'
import sys
d = open(sys.argv[1], 'rb').read()
parts = d.split(b'FRAME\n')
open(sys.argv[2], 'wb').write(b'FRAME\n'.join(parts[:17]))
PY
  $stab --quiet --fixed-crop --lookahead 6 "$stab_dir/clip16.y4m" "$stab_dir/la16.y4m"
  for case in "yu12 0 0 all" "nv12 0 32 all" "yuyv 0 64 luma" "nv12 1 0 all" "nv12m 1 16 all" "yuyv 1 8 luma"; do
    set -- $case
    eis FAKE_V4L2_FORMAT=$1 FAKE_V4L2_MPLANE=$2 FAKE_V4L2_PAD=$3 -- --frames 16 --output "$stab_dir/eis.y4m"
    if [ $st -eq 0 ] && [ "$(y4m_shape "$stab_dir/eis.y4m")" = "16 320 180 420jpeg" ] &&
       y4m_same "$stab_dir/eis.y4m" "$stab_dir/la16.y4m" 16 $4; then
      ok "stab_v4l2_${1}_mplane$2_pad$3"
    else fail "stab_v4l2_${1}_mplane$2_pad$3" "exit $st, $(y4m_shape "$stab_dir/eis.y4m"), $(tail -c 300 "$stab_dir/eis.err")"; fi
  done
  # the warp on the pool (--threads N: row bands on N - 1 workers, overlapping the next
  # registration) gives one thread's bytes: formats, APIs, lookaheads (0: each frame is due as
  # it is pushed), 30 frames of the 24-frame clip (it loops: a jump back to frame 0)
  for case in "nv12 0 32 4" "yuyv 1 8 0" "yu12 0 0 6"; do
    set -- $case
    eis FAKE_V4L2_FORMAT=$1 FAKE_V4L2_MPLANE=$2 FAKE_V4L2_PAD=$3 -- --frames 30 --lookahead $4 --threads 1 --output "$stab_dir/eis_t1.y4m"
    why=""; [ $st -eq 0 ] && [ "$(y4m_shape "$stab_dir/eis_t1.y4m")" = "30 320 180 420jpeg" ] || why="--threads 1: exit $st"
    for t in 2 3; do
      eis FAKE_V4L2_FORMAT=$1 FAKE_V4L2_MPLANE=$2 FAKE_V4L2_PAD=$3 -- --frames 30 --lookahead $4 --threads $t --output "$stab_dir/eis_t$t.y4m"
      { [ $st -eq 0 ] && grep -q "^eis-v4l2: $t thread(s)$" "$stab_dir/eis.err" && cmp -s "$stab_dir/eis_t1.y4m" "$stab_dir/eis_t$t.y4m"; } ||
        why="$why --threads $t: exit $st, $(cmp "$stab_dir/eis_t1.y4m" "$stab_dir/eis_t$t.y4m" 2>&1 | head -c 100)"
    done
    if [ -z "$why" ]; then ok "stab_v4l2_threads_same_bytes_$1_lookahead$4"; else fail "stab_v4l2_threads_same_bytes_$1_lookahead$4" "$why"; fi
  done
  # a failing output ends the run with exit 2 whichever thread writes
  full_ok=1
  if [ -w /dev/full ]; then
    for t in 1 2 3; do
      eis -- --frames 30 --lookahead 2 --threads $t --output /dev/full
      { [ $st -eq 2 ] && grep -q 'write error' "$stab_dir/eis.err"; } || { full_ok=0; echo "    --threads $t to /dev/full: exit $st"; }
    done
  fi
  if [ $full_ok -eq 1 ]; then ok stab_v4l2_threads_write_error_exits; else fail stab_v4l2_threads_write_error_exits "no clean exit 2"; fi
  eis FAKE_V4L2_FAULTS=eintr@2,dqeintr@4,eagain@6,eio@8,error@10,short@12,drop@14 -- --frames 16 --output "$stab_dir/eis.y4m"
  if [ $st -eq 0 ] && [ "$(y4m_shape "$stab_dir/eis.y4m")" = "16 320 180 420jpeg" ] &&
     grep -q 'eintr=1 dqeintr=1 eagain=1 eio=1 error=1 short=1 drop=1' "$stab_dir/eis.log" &&
     grep -q '16 frames stabilised, 16 written, 3 skipped' "$stab_dir/eis.err"; then
    ok stab_v4l2_injected_faults
  else fail stab_v4l2_injected_faults "exit $st, $(cat "$stab_dir/eis.log") $(tail -c 300 "$stab_dir/eis.err")"; fi
  eis FAKE_V4L2_FAULTS=disconnect@9 -- --lookahead 3 --output "$stab_dir/eis.y4m"
  if [ $st -eq 3 ] && grep -q 'device lost' "$stab_dir/eis.err" && [ "$(y4m_shape "$stab_dir/eis.y4m")" = "9 320 180 420jpeg" ]; then
    ok stab_v4l2_disconnect_clean_exit
  else fail stab_v4l2_disconnect_clean_exit "exit $st, $(y4m_shape "$stab_dir/eis.y4m"), $(tail -c 300 "$stab_dir/eis.err")"; fi
  eis FAKE_V4L2_FAULTS=stall@5 -- --output "$stab_dir/eis.y4m"
  if [ $st -eq 1 ] && grep -q 'select timeout' "$stab_dir/eis.err" && [ "$(y4m_shape "$stab_dir/eis.y4m")" = "5 320 180 420jpeg" ]; then
    ok stab_v4l2_stall; else fail stab_v4l2_stall "exit $st, $(tail -c 300 "$stab_dir/eis.err")"; fi
  eis FAKE_V4L2_DEVICE=/dev/video0 -- --device "$stab_dir/no-such-video" --frames 4
  if [ $st -eq 2 ] && grep -q 'cannot open' "$stab_dir/eis.err"; then ok stab_v4l2_no_device; else fail stab_v4l2_no_device "exit $st"; fi
  unset -f eis
fi

# 5. eis-libcamera with no camera: a clear message and exit 4, no crash
if [ -x "$BUILD/bin/eis-libcamera" ] && [ -z "$RUNNER" ]; then
  "$BUILD/bin/eis-libcamera" --frames 5 > "$stab_dir/lc.out" 2> "$stab_dir/lc.err"; st=$?
  if [ $st -eq 4 ] && grep -q 'no camera' "$stab_dir/lc.err"; then ok stab_libcamera_no_camera
  else fail stab_libcamera_no_camera "exit $st, $(tail -c 300 "$stab_dir/lc.err")"; fi
fi
unset -f y4m_shape y4m_same stab_exit2
