#!/usr/bin/env bash
# libhome test driver: the C test binary, then the checks that need the built artefacts (library
# symbols, CLI contract and bad inputs, install). Prints "N passed, N failed" last; exits non-zero
# on any failure. Environment: BUILD (build dir), NM, RUNNER (e.g. qemu for cross builds).
set -u
BUILD=${BUILD:-build}
NM=${NM:-nm}
RUNNER=${RUNNER:-}
passed=0
failed=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

ok() { passed=$((passed + 1)); echo "ok   $1"; }
fail() { failed=$((failed + 1)); echo "FAIL $1${2:+: $2}"; }

# 1. test binaries (unit, end-to-end; areas add theirs to TEST_BINS in mk/*.mk). TEST_JOBS
#    processes (default: the online cores, at most 4) each run every binary's k-th share of the
#    cases (HOME_TEST_SHARD); the outputs are printed binary by binary once all are done.
jobs=${TEST_JOBS:-$(getconf _NPROCESSORS_ONLN 2> /dev/null || echo 1)}
[[ $jobs =~ ^[1-9][0-9]*$ ]] || jobs=1
[ "$jobs" -gt 4 ] && [ -z "${TEST_JOBS:-}" ] && jobs=4
bins=(${TEST_BINS:-$BUILD/bin/home-tests})
for ((k = 0; k < jobs; k++)); do
  (for i in "${!bins[@]}"; do
     HOME_TEST_SHARD="$k/$jobs" $RUNNER "${bins[$i]}" > "$tmp/unit.$i.$k.out" 2> "$tmp/unit.$i.$k.err"
     echo $? > "$tmp/unit.$i.$k.status"
   done) &
done
wait
for i in "${!bins[@]}"; do
  name=$(basename "${bins[$i]}")
  for ((k = 0; k < jobs; k++)); do
    out="$tmp/unit.$i.$k"
    head -n -1 "$out.out"
    cat "$out.err" >&2
    line=$(tail -n 1 "$out.out")
    unit_status=$(cat "$out.status")
    if [[ $line =~ ^([0-9]+)\ passed,\ ([0-9]+)\ failed$ ]]; then
      passed=$((passed + BASH_REMATCH[1])); failed=$((failed + BASH_REMATCH[2]))
      [ "$unit_status" -eq 0 ] || [ "${BASH_REMATCH[2]}" -gt 0 ] || fail "$name" "exit status $unit_status"
    else
      fail "$name" "crashed or printed no summary (exit status $unit_status, share $k/$jobs)"
      tail -n 1 "$out.out"
    fi
  done
done

# 2. the library is allocation-free and has no writable globals
lib="$BUILD/lib/libhome.a"
heap=$($NM -u "$lib" | awk '{print $NF}' | grep -wE 'malloc|calloc|realloc|free|aligned_alloc|posix_memalign|memalign|valloc|sbrk|mmap|alloca' | sort -u | tr '\n' ' ')
if [ -z "$heap" ] && $NM -u "$lib" > /dev/null 2>&1; then ok no_heap_symbols; else fail no_heap_symbols "$heap"; fi
# writable sections (.data*, .bss*, COMMON) must be empty; .data.rel.ro (relocated constants of
# PIE builds, read-only after start-up) is allowed
writable=$(${OBJDUMP:-objdump} -h "$lib" | awk '$2 ~ /^\.(data|bss)/ && $2 !~ /^\.data\.rel\.ro/ && $3 !~ /^0+$/ {print $2 "=0x" $3}' | sort | uniq -c | tr '\n' ' ')
commons=$($NM "$lib" | awk '$2 ~ /^[cC]$/ {print $3}' | tr '\n' ' ')
# (sanitizer builds add their own instrumentation data: the plain build's run checks this)
if [ -n "${SANFLAGS:-}" ]; then :
elif [ -z "$writable$commons" ]; then ok no_writable_globals; else fail no_writable_globals "$writable$commons"; fi

# 3. the CLI: JSON contract on a known pair, and exit 2 on bad input
reg="$RUNNER $BUILD/bin/home-register"
$RUNNER "$BUILD/bin/home-make-pair" --p 20 --seed 3 "$tmp/a.pgm" "$tmp/b.pgm" > "$tmp/truth.json"
if $reg "$tmp/a.pgm" "$tmp/b.pgm" > "$tmp/out.json" 2> "$tmp/err" &&
   python3 - "$tmp/truth.json" "$tmp/out.json" <<'PY'
import json, sys
truth = json.load(open(sys.argv[1]))
lines = [l for l in open(sys.argv[2]).read().splitlines() if l.strip()]
assert len(lines) == 1, "expected exactly one line"
j = json.loads(lines[0])
assert list(j)[:5] == ["ok", "H", "keypoints", "matches", "inliers"], list(j)
assert j["ok"] is True and len(j["H"]) == 9 and abs(j["H"][8] - 1) < 1e-12
assert len(j["keypoints"]) == 2 and j["inliers"] >= 20 and j["matches"] >= j["inliers"]
assert set(j["ms"]) >= {"hough", "detect", "describe", "match", "homography", "total"}
assert j["model"] in ("identity", "translation", "similarity", "affine", "homography"), j["model"]
assert j["failure"] == "none" and j["refine_status"] == "accepted", j
assert 0 < j["sigma_px"] <= 1.0, j["sigma_px"]
def ap(h, x, y):
    w = h[6] * x + h[7] * y + h[8]
    return (h[0] * x + h[1] * y + h[2]) / w, (h[3] * x + h[4] * y + h[5]) / w
err = 0
for x, y in ((0, 0), (639, 0), (0, 359), (639, 359)):
    a, b = ap(j["H"], x, y), ap(truth["H"], x, y)
    err += ((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2) ** 0.5 / 4
assert err < 1.0, "corner error %.3f" % err
assert err < 3 * j["sigma_px"] + 0.05, "corner error %.3f against sigma %.3f" % (err, j["sigma_px"])
PY
then ok cli_json_contract; else fail cli_json_contract "$(head -c 300 "$tmp/out.json" "$tmp/err")"; fi

$RUNNER "$BUILD/bin/home-make-pair" --kind constant --p 5 --seed 3 "$tmp/c1.pgm" "$tmp/c2.pgm" > /dev/null
if $reg "$tmp/c1.pgm" "$tmp/c2.pgm" > "$tmp/out.json" && grep -q '^{"ok":false' "$tmp/out.json"; then
  ok cli_failure_is_ok_false; else fail cli_failure_is_ok_false "$(cat "$tmp/out.json")"; fi

if $reg --help | grep -q -- '--save-hough'; then ok cli_help; else fail cli_help; fi
if $reg --save-hough "$tmp/h.pgm" "$tmp/a.pgm" "$tmp/b.pgm" > /dev/null && head -c 2 "$tmp/h.pgm" | grep -q P5; then
  ok cli_save_hough; else fail cli_save_hough; fi

expect_exit2() { # name, then the arguments
  local name=$1; shift
  $reg "$@" > "$tmp/o" 2> "$tmp/e"
  local st=$?
  if [ $st -eq 2 ] && [ -s "$tmp/e" ] && [ ! -s "$tmp/o" ]; then ok "cli_bad_input_$name"
  else fail "cli_bad_input_$name" "exit $st, stderr: $(head -c 200 "$tmp/e")"; fi
}
head -c 40000 "$tmp/a.pgm" > "$tmp/trunc.pgm"
printf 'P5\n640 360\n' > "$tmp/nomax.pgm"
printf 'P2\n4 4\n255\n1 2 3 4\n' > "$tmp/ascii.pgm"
printf 'P5\n64 64\n65535\n' > "$tmp/deep.pgm"; head -c 8192 /dev/zero >> "$tmp/deep.pgm"
printf 'P5\n99999999 99999999\n255\n' > "$tmp/huge.pgm"
printf 'P5\n0 10\n255\n' > "$tmp/zero.pgm"
printf 'P5\n16 16\n255\n' > "$tmp/tiny.pgm"; head -c 256 /dev/zero >> "$tmp/tiny.pgm"
printf 'P5\n-640 360\n255\n' > "$tmp/neg.pgm"
: > "$tmp/empty.pgm"
$RUNNER "$BUILD/bin/home-make-pair" --width 320 --height 180 "$tmp/s1.pgm" "$tmp/s2.pgm" > /dev/null
expect_exit2 truncated "$tmp/trunc.pgm" "$tmp/b.pgm"
expect_exit2 no_maxval "$tmp/a.pgm" "$tmp/nomax.pgm"
expect_exit2 ascii_pgm "$tmp/ascii.pgm" "$tmp/b.pgm"
expect_exit2 16bit "$tmp/deep.pgm" "$tmp/deep.pgm"
expect_exit2 huge "$tmp/huge.pgm" "$tmp/huge.pgm"
expect_exit2 zero_width "$tmp/zero.pgm" "$tmp/zero.pgm"
expect_exit2 too_small "$tmp/tiny.pgm" "$tmp/tiny.pgm"
expect_exit2 negative_size "$tmp/neg.pgm" "$tmp/neg.pgm"
expect_exit2 empty "$tmp/empty.pgm" "$tmp/b.pgm"
expect_exit2 missing_file "$tmp/does-not-exist.pgm" "$tmp/b.pgm"
expect_exit2 size_mismatch "$tmp/a.pgm" "$tmp/s1.pgm"
expect_exit2 one_argument "$tmp/a.pgm"
expect_exit2 unknown_option --frobnicate "$tmp/a.pgm" "$tmp/b.pgm"
expect_exit2 bad_option_value --keypoints many "$tmp/a.pgm" "$tmp/b.pgm"
expect_exit2 out_of_range_option --ratio 7 "$tmp/a.pgm" "$tmp/b.pgm"

# 4. make install lays out header, library and a usable home.pc
if [ -z "$RUNNER" ]; then
  if make -s install BUILD="$BUILD" DESTDIR="$tmp/dest" PREFIX=/opt/home > /dev/null &&
     [ -f "$tmp/dest/opt/home/include/home.h" ] && [ -f "$tmp/dest/opt/home/lib/libhome.a" ] &&
     grep -q '^Libs: .*-lhome' "$tmp/dest/opt/home/lib/pkgconfig/home.pc" &&
     printf '#include <home.h>\nint main(void){home_config c; return home_default_config(&c, 64, 64);}\n' > "$tmp/use.c" &&
     ${CC:-cc} ${SANFLAGS:-} -std=c99 -I"$tmp/dest/opt/home/include" "$tmp/use.c" "$tmp/dest/opt/home/lib/libhome.a" -lm -o "$tmp/use" &&
     "$tmp/use"; then ok make_install; else fail make_install; fi
fi

# 5. checks of other areas: tests/checks/*.sh are sourced here and use ok/fail, $tmp, $BUILD,
#    $RUNNER
for check in tests/checks/*.sh; do
  [ -f "$check" ] || continue
  # shellcheck source=/dev/null
  . "$check"
done

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
