# The CI steps' check harness (sourced by .ci/steps/*.sh): counters, ok/fail as tests/run.sh
# prints them (tests/checks/*.sh call these), each pass recorded by name so a step can insist
# that the checks its dependencies make possible did run.
passed=0
failed=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ok() { passed=$((passed + 1)); echo "ok   $1"; echo "${1%% (*}" >> "$tmp/passed"; }
fail() { failed=$((failed + 1)); echo "FAIL $1${2:+: $2}"; }
RUNNER=""

# unit_tests BIN NAME: a test binary whose last line must be "N passed, 0 failed"
unit_tests() {
  local line
  "$1" | tee "$tmp/unit.out" || true
  line=$(tail -n 1 "$tmp/unit.out")
  if [[ $line =~ ^([0-9]+)\ passed,\ 0\ failed$ ]]; then ok "$2"; else fail "$2" "$line"; fi
}

# require_checks NAME...: each must have passed (not skipped); then the summary and the status
require_checks() {
  local name
  for name in "$@"; do
    grep -qx "$name" "$tmp/passed" 2> /dev/null || fail "$name" "did not run"
  done
  echo "$passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}
