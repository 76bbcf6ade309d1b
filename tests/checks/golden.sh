# The byte-for-byte comparison test (sourced by tests/run.sh: ok/fail, $tmp, $BUILD, $RUNNER):
# every SIMD backend reproduces the registrations and the stabilised demo clip recorded in
# tests/golden/ (tests/golden/golden.sh; `make golden` records them anew).
if RUNNER="$RUNNER" GOLDEN_TARGET="$(${CC:-cc} -dumpmachine)" bash tests/golden/golden.sh "$BUILD" \
  > "$tmp/golden.out" 2>&1; then
  ok "golden_outputs ($(tail -n 1 "$tmp/golden.out" | sed 's/.*backends: //'))"
else
  fail golden_outputs "$(head -c 800 "$tmp/golden.out")"
fi
