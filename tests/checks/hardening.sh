# Hardening checks sourced by tests/run.sh (uses ok/fail, $tmp, $BUILD, $RUNNER): home-stab's
# exit status on malformed Y4M input: 2 for a stream it cannot start (bad header, unsupported
# layout or size), 1 for a bad frame after good ones (those are written), 0 for a clean stream.
stab_bin="$BUILD/bin/home-stab"
if [ -x "$stab_bin" ]; then
  y4m_frames() { # header, frame bytes, frame count
    printf '%s\n' "$1"
    for _ in $(seq "$3"); do printf 'FRAME\n'; head -c "$2" /dev/zero; done
  }
  expect_stab_exit() { # name, expected status, input file
    $RUNNER "$stab_bin" --quiet "$3" "$tmp/stab-out.y4m" > /dev/null 2> "$tmp/stab-err"
    local st=$?
    if [ "$st" -eq "$2" ] && { [ "$2" -eq 0 ] || [ -s "$tmp/stab-err" ]; }; then ok "stab_y4m_$1"
    else fail "stab_y4m_$1" "exit $st (want $2): $(head -c 200 "$tmp/stab-err")"; fi
  }
  : > "$tmp/s-empty.y4m"
  printf 'P5\n64 64\n255\n' > "$tmp/s-pgm.y4m"
  y4m_frames "YUV4MPEG2 W64 H64 C444" 12288 1 > "$tmp/s-444.y4m"
  y4m_frames "YUV4MPEG2 W64 H64 C420p10" 12288 1 > "$tmp/s-10bit.y4m"
  y4m_frames "YUV4MPEG2 W99999 H99999 C420" 0 0 > "$tmp/s-huge.y4m"
  y4m_frames "YUV4MPEG2 W65 H63 C420" 0 0 > "$tmp/s-odd.y4m"
  y4m_frames "YUV4MPEG2 W16 H16 Cmono" 256 2 > "$tmp/s-tiny.y4m"
  y4m_frames "YUV4MPEG2 F30:1 Cmono" 4096 1 > "$tmp/s-nosize.y4m"
  y4m_frames "YUV4MPEG2 W64 H64 Cmono" 4096 3 > "$tmp/s-good.y4m"
  { y4m_frames "YUV4MPEG2 W64 H64 Cmono" 4096 2; printf 'FRAME\n'; head -c 1000 /dev/zero; } > "$tmp/s-trunc.y4m"
  { y4m_frames "YUV4MPEG2 W64 H64 Cmono" 4096 1; printf 'FRAMX\n'; head -c 4096 /dev/zero; } > "$tmp/s-marker.y4m"
  expect_stab_exit empty 2 "$tmp/s-empty.y4m"
  expect_stab_exit not_y4m 2 "$tmp/s-pgm.y4m"
  expect_stab_exit 444 2 "$tmp/s-444.y4m"
  expect_stab_exit 10bit 2 "$tmp/s-10bit.y4m"
  expect_stab_exit absurd_size 2 "$tmp/s-huge.y4m"
  expect_stab_exit odd_size_420 2 "$tmp/s-odd.y4m"
  expect_stab_exit below_min_side 2 "$tmp/s-tiny.y4m"
  expect_stab_exit no_size 2 "$tmp/s-nosize.y4m"
  expect_stab_exit missing_file 2 "$tmp/does-not-exist.y4m"
  expect_stab_exit truncated_frame 1 "$tmp/s-trunc.y4m"
  expect_stab_exit bad_frame_marker 1 "$tmp/s-marker.y4m"
  expect_stab_exit clean_stream 0 "$tmp/s-good.y4m"
  # frames written: (file size - header line) / ("FRAME\n" + 64x64 mono)
  $RUNNER "$stab_bin" --quiet "$tmp/s-trunc.y4m" "$tmp/stab-out.y4m" 2> /dev/null
  frames_trunc=$(( ($(wc -c < "$tmp/stab-out.y4m") - $(head -n 1 "$tmp/stab-out.y4m" | wc -c)) / 4102 ))
  if [ "$frames_trunc" = 2 ]; then ok stab_y4m_truncated_keeps_good_frames
  else fail stab_y4m_truncated_keeps_good_frames "$frames_trunc frames written (want 2)"; fi
fi
