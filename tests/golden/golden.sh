#!/usr/bin/env bash
# The byte-for-byte comparison test: the registrations of tests/golden/cases.txt (home-register
# --exact, with the defaults and with --video) and home-stab on the demo clip (`make demo`'s
# options; sha256 of its side-by-side Y4M, CSV and plot) under every SIMD backend this build
# and machine have (HOME_SIMD), against the outputs recorded in tests/golden/*.txt.
#   bash tests/golden/golden.sh BUILD          compare (exit 1 on any difference)
#   bash tests/golden/golden.sh BUILD --update record the scalar backend's outputs as golden
# The golden is tests/golden/register.txt and stab.txt (recorded on x86-64; aarch64 gives the
# same bits), or register.<target>.txt / stab.<target>.txt for a target (GOLDEN_TARGET, the
# compiler's -dumpmachine) whose floating point gives other last bits: armv7's libm. A target
# with its own registrations but no stab file skips the clip. GOLDEN_OWN=1 with --update
# records a target's own files.
# Environment: RUNNER (e.g. qemu-user for cross builds); under a RUNNER only every fourth pair
# and no clip, unless GOLDEN_FULL=1 (emulation is 10-20x slower); GOLDEN_CLIP=1 adds the clip to
# that quarter. Pairs and clip are cached in BUILD/golden; their hashes are part of the golden,
# so a changed generator shows too.
set -u
BUILD=${1:?usage: golden.sh BUILD [--update]}
mode=${2:-check}
RUNNER=${RUNNER:-}
here=$(dirname "$0")
work=$BUILD/golden
mkdir -p "$work/pairs"
status=0
target=${GOLDEN_TARGET:-}
reg_golden=$here/register.txt
stab_golden=$here/stab.txt
if [ -n "$target" ] && { [ -f "$here/register.$target.txt" ] || [ "${GOLDEN_OWN:-0}" = 1 ]; }; then
  reg_golden=$here/register.$target.txt
  stab_golden=$here/stab.$target.txt
fi

subset=0
[ -n "$RUNNER" ] && [ "${GOLDEN_FULL:-0}" != 1 ] && [ "$mode" != --update ] && subset=1
cases=()
n_case=0
while read -r name opts; do
  case $name in ''|'#'*) continue ;; esac
  n_case=$((n_case + 1))
  [ $subset = 1 ] && [ $(((n_case - 1) % 4)) != 0 ] && continue
  cases+=("$name")
  a=$work/pairs/${name}_a.pgm b=$work/pairs/${name}_b.pgm
  if [ ! -s "$b" ] || [ "$(cat "$work/pairs/$name.opts" 2> /dev/null)" != "$opts" ]; then
    # shellcheck disable=SC2086
    $RUNNER "$BUILD/bin/home-make-pair" $opts "$a" "$b" > /dev/null || { echo "golden: home-make-pair $opts failed"; exit 1; }
    echo "$opts" > "$work/pairs/$name.opts"
  fi
done < "$here/cases.txt"

# the clip: not under emulation's subset (unless GOLDEN_CLIP=1), nor for a target without a
# stab golden
want_clip=1
[ $subset = 1 ] && [ "${GOLDEN_CLIP:-0}" != 1 ] && want_clip=0
[ -f "$stab_golden" ] || [ "$mode" = --update ] || want_clip=0
clip=$work/shaky.y4m
clip_opts="--scene structured --frames 120 --shake 4 --rot 0.4 --pan 80 --seed 3"   # make demo's
if [ $want_clip = 1 ] && { [ ! -s "$clip" ] || [ "$(cat "$work/clip.opts" 2> /dev/null)" != "$clip_opts" ]; }; then
  # shellcheck disable=SC2086
  $RUNNER "$BUILD/bin/home-stab-clip" $clip_opts "$clip" "$work/truth.csv" > /dev/null || { echo "golden: home-stab-clip failed"; exit 1; }
  echo "$clip_opts" > "$work/clip.opts"
fi

# one backend's outputs: register.<simd>.txt and stab.<simd>.txt
run_backend() {
  local simd=$1 name m
  local reg="$work/register.$simd.txt" st="$work/stab.$simd.txt"
  : > "$reg"
  for name in "${cases[@]}"; do
    for m in default video; do
      printf '%s %s ' "$name" "$m" >> "$reg"
      HOME_SIMD=$simd $RUNNER "$BUILD/bin/home-register" --exact $([ $m = video ] && echo --video) \
        "$work/pairs/${name}_a.pgm" "$work/pairs/${name}_b.pgm" >> "$reg" 2>&1 || echo "exit $?" >> "$reg"
    done
  done
  [ $want_clip = 0 ] && return
  {
    (cd "$work/pairs" && sha256sum -- *_a.pgm *_b.pgm)
    echo "$(sha256sum < "$clip" | cut -d' ' -f1)  shaky.y4m"
    HOME_SIMD=$simd $RUNNER "$BUILD/bin/home-stab" --quiet --lookahead 10 --side-by-side \
      --csv "$work/path.$simd.csv" --plot "$work/path.$simd.png" "$clip" - |
      sha256sum | sed 's/ .*/  side_by_side.y4m/'
    echo "$(sha256sum < "$work/path.$simd.csv" | cut -d' ' -f1)  path.csv"
    echo "$(sha256sum < "$work/path.$simd.png" | cut -d' ' -f1)  path.png"
  } > "$st"
}

# the backends compiled in and supported here (HOME_SIMD naming another one is refused)
backends=()
for simd in none sse avx2 neon; do
  if HOME_SIMD=$simd $RUNNER "$BUILD/bin/home-register" --exact "$work/pairs/${cases[0]}_a.pgm" \
       "$work/pairs/${cases[0]}_b.pgm" > /dev/null 2>&1; then backends+=("$simd"); fi
done

if [ "$mode" = --update ]; then
  run_backend none
  cp "$work/register.none.txt" "$reg_golden"
  cp "$work/stab.none.txt" "$stab_golden"
  echo "golden: recorded $reg_golden and $stab_golden from the scalar backend"
fi

pids=()
for simd in "${backends[@]}"; do run_backend "$simd" & pids+=($!); done
for p in "${pids[@]}"; do wait "$p"; done
# what this run compares: every recorded line of its pairs (all of them but under emulation)
files="register stab"
[ $want_clip = 1 ] || files=register
if [ $subset = 1 ]; then
  printf '%s\n' "${cases[@]}" | awk 'NR == FNR {want[$1] = 1; next} $1 in want' - "$reg_golden" \
    > "$work/register.expected"
else
  cp "$reg_golden" "$work/register.expected"
fi
[ -f "$stab_golden" ] && cp "$stab_golden" "$work/stab.expected"
# the stab file opens with the hashes of every pair: a quarter of them is compared with the clip
if [ $subset = 1 ] && [ $want_clip = 1 ]; then
  for f in "$work/stab.expected" "$work"/stab.*.txt; do
    grep -v -E '_[ab]\.pgm$' "$f" > "$f.clip" && mv "$f.clip" "$f"
  done
fi
for simd in "${backends[@]}"; do
  for f in $files; do
    if ! cmp -s "$work/$f.expected" "$work/$f.$simd.txt"; then
      echo "golden: $f differs under HOME_SIMD=$simd:"
      diff "$work/$f.expected" "$work/$f.$simd.txt" | head -6 | cut -c1-300
      status=1
    fi
  done
done
if [ $subset = 1 ]; then
  echo "golden: ${#cases[@]} of $n_case pairs x 2 configurations$([ "$files" = register ] || echo " + the demo clip") (emulated; GOLDEN_FULL=1: all and the clip) ($(basename "$reg_golden")), backends: ${backends[*]}"
else
  echo "golden: ${#cases[@]} pairs x 2 configurations$([ "$files" = register ] || echo " + the demo clip") ($(basename "$reg_golden")), backends: ${backends[*]}"
fi
exit $status
