# eis-libcamera on libcamera's virtual camera (sourced by tests/run.sh: ok/fail, $tmp, $BUILD,
# $RUNNER). Runs when `make libcamera-virtual` has built libcamera with the virtual pipeline
# handler and eis-libcamera against it ($BUILD/libcamera-virtual), else says why it skipped.
# A shaky clip from home-stab-clip becomes a JPEG directory (ffmpeg) that the virtual camera
# plays (its virtual.yaml: frames: path:, each image shown 4 times); eis-libcamera captures
# it through the memfd buffer fallback (no /dev/dma_heap, no /dev/udmabuf here), writes the
# frames as captured and as stabilised, and tests/support/virtual_camera_check.py checks them:
# every frame out, the images played in order, the same bytes as home-stab --fixed-crop on
# the captured frames, and the residual jitter below half the input's; then causal runs on one
# thread and on three (the warp pool) give the same bytes.
# libcamera (built without udev) enumerates media devices through /sys/bus/media/devices, which
# a machine without any media driver lacks: the camera runs in a private mount namespace
# (unshare -m, root or sudo) with a tmpfs over /sys/bus holding that directory, and the
# test's virtual.yaml bind-mounted over the installed one.
lcv_dir="$BUILD/libcamera-virtual"
lcv_eis="$lcv_dir/bin/eis-libcamera"
lcv_yaml="$lcv_dir/prefix/share/libcamera/pipeline/virtual/virtual.yaml"
lcv_sudo=""
[ "$(id -u)" -ne 0 ] && lcv_sudo="sudo -n"
if [ -n "$RUNNER" ]; then
  echo "skip libcamera-virtual: a cross build"
elif [ ! -x "$lcv_eis" ] || [ ! -f "$lcv_yaml" ]; then
  echo "skip libcamera-virtual: not built (make libcamera-virtual: libcamera from source with the virtual camera)"
elif ! command -v ffmpeg > /dev/null 2>&1; then
  echo "skip libcamera-virtual: ffmpeg not installed (it writes the JPEGs the virtual camera plays)"
elif ! $lcv_sudo unshare -m true 2> /dev/null; then
  echo "skip libcamera-virtual: cannot make a mount namespace (unshare -m needs root, or sudo without a password)"
else
  lcv_t="$tmp/libcamera-virtual"
  mkdir -p "$lcv_t/jpeg"
  lcv_images=40
  lcv_repeat=4      # the virtual camera shows each image this often (libcamera's frameRepeat)
  lcv_lookahead=6
  $RUNNER "$BUILD/bin/home-stab-clip" --frames $lcv_images --width 640 --height 360 --pan 30 --shake 4 --seed 11 \
    "$lcv_t/clip.y4m" "$lcv_t/truth.csv" > /dev/null
  # 0.jpg, 1.jpg, ...: the names the virtual camera reads, in order
  ffmpeg -v error -y -i "$lcv_t/clip.y4m" -q:v 1 -pix_fmt yuvj420p -start_number 0 "$lcv_t/jpeg/%d.jpg"
  cat > "$lcv_t/virtual.yaml" <<EOF
%YAML 1.1
---
"Virtual0":
  supported_formats:
  - width: 640
    height: 360
    frame_rates:
    - 30
  frames:
    path: "$(cd "$lcv_t/jpeg" && pwd)/"
  location: "CameraLocationFront"
  model: "libhome shaky clip"
EOF
  # in a private mount namespace: /sys/bus/media/devices on a tmpfs, the test's camera config
  lcv_run() { # eis-libcamera arguments
    $lcv_sudo unshare -m sh -ec '
      mount -t tmpfs libhome-sysbus /sys/bus
      mkdir -p /sys/bus/media/devices
      mount --bind "$1" "$2"
      shift 2
      exec "$@"' sh "$lcv_t/virtual.yaml" "$lcv_yaml" "$lcv_eis" "$@"
  }
  lcv_run --list > "$lcv_t/list.txt" 2> "$lcv_t/list.err"
  st=$?
  if [ $st -eq 0 ] && grep -q '^0: ' "$lcv_t/list.txt"; then ok libcamera_virtual_lists_camera
  else fail libcamera_virtual_lists_camera "exit $st, $(head -c 300 "$lcv_t/list.txt" "$lcv_t/list.err")"; fi
  lcv_frames=$((lcv_images * lcv_repeat))
  lcv_run --size 640x360 --format nv12 --frames $lcv_frames --lookahead $lcv_lookahead \
    --output "$lcv_t/out.y4m" --raw-output "$lcv_t/raw.y4m" > "$lcv_t/eis.out" 2> "$lcv_t/eis.err"
  st=$?
  if [ $st -eq 0 ] && grep -q 'memfd' "$lcv_t/eis.err" &&
     grep -q "$lcv_frames frames captured ($lcv_images registered, $((lcv_frames - lcv_images)) repeats), $lcv_frames written" "$lcv_t/eis.err"; then
    ok libcamera_virtual_capture
  else fail libcamera_virtual_capture "exit $st, $(tail -c 400 "$lcv_t/eis.err")"; fi
  # home-stab on the distinct captured frames, with eis-libcamera's options (single pass)
  python3 - "$lcv_t/raw.y4m" "$lcv_t/distinct.y4m" <<'PY'
import sys
d = open(sys.argv[1], 'rb').read()
nl = d.index(b'\n')
parts = d[nl + 1:].split(b'FRAME\n')[1:]
keep = [p for i, p in enumerate(parts) if i == 0 or p != parts[i - 1]]
open(sys.argv[2], 'wb').write(d[:nl + 1] + b''.join(b'FRAME\n' + p for p in keep))
PY
  $RUNNER "$BUILD/bin/home-stab" --quiet --fixed-crop --lookahead $lcv_lookahead "$lcv_t/distinct.y4m" "$lcv_t/hs.y4m"
  if python3 tests/support/virtual_camera_check.py "$lcv_t/clip.y4m" "$lcv_t/raw.y4m" "$lcv_t/out.y4m" \
       "$lcv_t/hs.y4m" $lcv_images $lcv_repeat > "$lcv_t/check.txt" 2>&1; then
    ok "libcamera_virtual_stabilises ($(tail -n 1 "$lcv_t/check.txt"))"
  else fail libcamera_virtual_stabilises "$(cat "$lcv_t/check.txt")"; fi
  sed 's/^/    /' "$lcv_t/check.txt" | head -n 4
  # the warp pool, causal (each repeat is written once its frame's output job is done): one
  # thread and three give the same bytes for the same captured frames, and every image is
  # registered once (a causal ring of one frame once took every frame for a repeat)
  for t in 1 3; do
    lcv_run --size 640x360 --format nv12 --frames $lcv_frames --lookahead 0 --threads $t \
      --output "$lcv_t/out_t$t.y4m" --raw-output "$lcv_t/raw_t$t.y4m" > /dev/null 2> "$lcv_t/eis_t$t.err"
    echo $? > "$lcv_t/st_t$t"
  done
  if [ "$(cat "$lcv_t/st_t1") $(cat "$lcv_t/st_t3")" = "0 0" ] && grep -q '^eis-libcamera: 3 thread(s)$' "$lcv_t/eis_t3.err" &&
     grep -q "($lcv_images registered" "$lcv_t/eis_t1.err" &&
     cmp -s "$lcv_t/raw_t1.y4m" "$lcv_t/raw_t3.y4m" && cmp -s "$lcv_t/out_t1.y4m" "$lcv_t/out_t3.y4m" &&
     [ "$(grep -a -c FRAME "$lcv_t/out_t3.y4m")" -eq $lcv_frames ]; then
    ok libcamera_virtual_threads_same_bytes
  else fail libcamera_virtual_threads_same_bytes "exit $(cat "$lcv_t/st_t1") / $(cat "$lcv_t/st_t3"), $(tail -c 300 "$lcv_t/eis_t3.err")"; fi
fi
