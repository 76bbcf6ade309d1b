# The library's layers (sourced by tests/run.sh: ok/fail, $tmp, $BUILD, $NM): no arrow from
# port/ up into src/ (symbols and includes) and no circle between files (tests/checks/layers.py).
if python3 tests/checks/layers.py "$BUILD" "${NM:-nm}" > "$tmp/layers.out" 2>&1; then
  ok "layers ($(head -n 1 "$tmp/layers.out" | sed 's/^layers: //'))"
else
  fail layers "$(cat "$tmp/layers.out")"
fi
