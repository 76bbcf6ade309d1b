# GStreamer checks (sourced by tests/run.sh: ok/fail, $tmp, $BUILD, $RUNNER): the built plugin
# as gst-launch-1.0 sees it. gst-inspect-1.0 homestab; a videotestsrc pipeline per format
# (every frame out); a live pipeline whose sink drops late frames (the lookahead's latency is
# reported, so none are late); `filesrc ! y4mdec ! homestab ! y4menc` byte-identical to
# home-stab --fixed-crop with the same options, also with the warp on 3 threads (frame
# payloads: the Y4M headers' tags differ); `make install` put the plugin in GStreamer's plugin
# directory. Skipped, saying why, without the plugin or GStreamer's tools (gstreamer1.0-tools,
# y4menc from plugins-good, y4mdec from plugins-bad).
gst_plugin_dir="$BUILD/lib/gstreamer-1.0"
gst_missing=""
for gst_tool in gst-launch-1.0 gst-inspect-1.0; do
  command -v $gst_tool > /dev/null 2>&1 || gst_missing="$gst_missing $gst_tool"
done
if [ -n "$RUNNER" ]; then
  echo "skip gst: a cross build (the plugin is built for the host only)"
elif [ ! -f "$gst_plugin_dir/libgsthome.so" ]; then
  echo "skip gst: the plugin was not built (apt-get install libgstreamer1.0-dev libgstreamer-plugins-base1.0-dev)"
elif [ -n "$gst_missing" ]; then
  echo "skip gst:$gst_missing not installed (apt-get install gstreamer1.0-tools gstreamer1.0-plugins-good gstreamer1.0-plugins-bad)"
else
  gst_dir="$tmp/gst"
  mkdir -p "$gst_dir"
  # this plugin and the system's, in a registry of our own
  gst() { # tool, then its arguments
    local tool=$1; shift
    GST_PLUGIN_PATH="$(cd "$gst_plugin_dir" && pwd)" GST_REGISTRY="$gst_dir/registry.bin" "$tool" "$@"
  }

  # 1. the element as the registry sees it
  if gst gst-inspect-1.0 homestab > "$gst_dir/inspect.txt" 2>&1 &&
     grep -q 'HOME video stabiliser' "$gst_dir/inspect.txt" &&
     grep -q 'GRAY8' "$gst_dir/inspect.txt" &&
     ( for p in lookahead margin margin-x margin-y smoothing ease downscale keypoints refine refine-finest \
                hough-downscale theta-bins post-messages threads; do grep -q "^  $p  *:" "$gst_dir/inspect.txt" || exit 1; done ); then
    ok gst_inspect
  else fail gst_inspect "$(head -c 300 "$gst_dir/inspect.txt")"; fi

  # 2. every format through a moving test picture: 30 frames in, 30 out (8 of them drained at EOS)
  for fmt in "I420 115200" "NV12 115200" "YUY2 153600" "GRAY8 76800"; do
    set -- $fmt
    rm -f "$gst_dir/out.raw"
    gst gst-launch-1.0 -q videotestsrc num-buffers=30 pattern=ball motion=sweep \
      ! video/x-raw,format=$1,width=320,height=240,framerate=30/1 \
      ! homestab lookahead=8 ! filesink location="$gst_dir/out.raw" > "$gst_dir/launch.txt" 2>&1
    st=$?
    size=$(stat -c %s "$gst_dir/out.raw" 2> /dev/null || echo 0)
    if [ $st -eq 0 ] && [ "$size" -eq $((30 * $2)) ]; then ok "gst_pipeline_$1"
    else fail "gst_pipeline_$1" "exit $st, $size bytes for 30 frames of $2, $(head -c 300 "$gst_dir/launch.txt")"; fi
  done

  # 3. live: the sink drops frames later than 20 ms; the reported latency covers the 8 held
  gst gst-launch-1.0 -v videotestsrc is-live=true num-buffers=20 pattern=ball \
    ! video/x-raw,format=NV12,width=320,height=240,framerate=30/1 ! homestab lookahead=8 \
    ! fakesink sync=true qos=true max-lateness=20000000 silent=false > "$gst_dir/live.txt" 2>&1
  st=$?
  rendered=$(grep -c 'fakesink0: last-message = chain' "$gst_dir/live.txt")
  if [ $st -eq 0 ] && [ "$rendered" -eq 20 ]; then ok gst_live_latency
  else fail gst_live_latency "exit $st, $rendered of 20 frames rendered in time"; fi

  # 4. byte identity with home-stab (single pass: its --fixed-crop), three sets of options
  $RUNNER "$BUILD/bin/home-stab-clip" --frames 40 --width 320 --height 180 --pan 30 --shake 3 --seed 5 \
    "$gst_dir/clip.y4m" "$gst_dir/truth.csv" > /dev/null
  gst_same_frames() { # a.y4m b.y4m in.y4m frames: the payloads equal, and not the input's
    python3 - "$@" <<'PY'
import sys
def frames(path):
    d = open(path, 'rb').read()
    head = d[:d.index(b'\n')].split()
    tags = {t[:1]: t[1:] for t in head[1:]}
    size = int(tags[b'W']) * int(tags[b'H']) * 3 // 2
    out, at = [], d.index(b'\n') + 1
    while at < len(d):
        assert d[at:at + 5] == b'FRAME', 'bad frame marker'
        at = d.index(b'\n', at) + 1
        out.append(d[at:at + size]); at += size
    return out
a, b, src = frames(sys.argv[1]), frames(sys.argv[2]), frames(sys.argv[3])
n = int(sys.argv[4])
assert len(a) == n and len(b) == n, 'frames %d and %d of %d' % (len(a), len(b), n)
diff = [i for i in range(n) if a[i] != b[i]]
assert not diff, 'frames differ: %s' % diff[:10]
assert sum(a[i] != src[i] for i in range(n)) >= n - 1, 'output equals the input'
PY
  }
  for case in "0|--lookahead 0|lookahead=0" \
              "8|--lookahead 8 --ease 0.3 --margin-x 0.06 --margin-y 0.12|lookahead=8 ease=0.3 margin-x=0.06 margin-y=0.12" \
              "8_threads3|--lookahead 8 --ease 0.3 --margin-x 0.06 --margin-y 0.12|lookahead=8 ease=0.3 margin-x=0.06 margin-y=0.12 threads=3" \
              "12|--lookahead 12 --smoothing 5 --margin 0.08 --keypoints 300 --theta-bins 64|lookahead=12 smoothing=5 margin=0.08 keypoints=300 theta-bins=64"; do
    IFS='|' read -r n stab_opts gst_opts <<< "$case"
    rm -f "$gst_dir/ref.y4m" "$gst_dir/gst.y4m"
    # shellcheck disable=SC2086
    $RUNNER "$BUILD/bin/home-stab" --quiet --fixed-crop $stab_opts "$gst_dir/clip.y4m" "$gst_dir/ref.y4m"
    # shellcheck disable=SC2086
    gst gst-launch-1.0 -q filesrc location="$gst_dir/clip.y4m" ! y4mdec ! homestab $gst_opts \
      ! y4menc ! filesink location="$gst_dir/gst.y4m" > "$gst_dir/launch.txt" 2>&1
    st=$?
    if [ $st -eq 0 ] && gst_same_frames "$gst_dir/gst.y4m" "$gst_dir/ref.y4m" "$gst_dir/clip.y4m" 40 2> "$gst_dir/cmp.txt"; then
      ok "gst_same_bytes_as_home_stab_lookahead$n"
    else fail "gst_same_bytes_as_home_stab_lookahead$n" "exit $st, $(tail -c 300 "$gst_dir/cmp.txt") $(head -c 200 "$gst_dir/launch.txt")"; fi
  done

  # 5. make install (tests/run.sh ran it into $tmp/dest) put the plugin where GStreamer looks
  gst_plugins=$(pkg-config --variable=pluginsdir gstreamer-1.0 2> /dev/null)
  if [ -n "$gst_plugins" ] && [ -f "$tmp/dest$gst_plugins/libgsthome.so" ]; then ok gst_make_install
  else fail gst_make_install "no $tmp/dest$gst_plugins/libgsthome.so"; fi
  unset -f gst gst_same_frames
fi
