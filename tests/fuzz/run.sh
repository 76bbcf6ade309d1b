#!/usr/bin/env bash
# Run each libFuzzer target for FUZZ_SECONDS, one after the other, starting from the checked-in
# seed corpus. New inputs go to $FUZZ_BUILD/corpus/<target> (the checked-in corpus is never
# written), crashes to $FUZZ_BUILD/crashes/. Prints one summary line per target; exits non-zero
# if any target crashed. Environment: FUZZ_BUILD (build-fuzz), FUZZ_SECONDS (60),
# FUZZ_FLAGS (extra libFuzzer flags, e.g. "-jobs=2 -workers=2" or "-max_total_time=..." ).
set -u
cd "$(dirname "$0")/../.."
FUZZ_BUILD=${FUZZ_BUILD:-build-fuzz}
FUZZ_SECONDS=${FUZZ_SECONDS:-60}
status=0
for target in "$@"; do
  bin=$FUZZ_BUILD/fuzz/fuzz_$target
  corpus=$FUZZ_BUILD/corpus/$target
  log=$FUZZ_BUILD/logs/$target.log
  mkdir -p "$corpus" "$FUZZ_BUILD/crashes" "$FUZZ_BUILD/logs"
  dict=()
  [ -f "tests/fuzz/$target.dict" ] && dict=(-dict="tests/fuzz/$target.dict")
  # -timeout: one input taking over 10 s is a hang; -rss_limit_mb: a leak or runaway allocation
  # shellcheck disable=SC2086
  "$bin" -max_total_time="$FUZZ_SECONDS" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$FUZZ_BUILD/crashes/$target-" "${dict[@]}" ${FUZZ_FLAGS:-} \
    "$corpus" "tests/fuzz/corpus/$target" > "$log" 2>&1
  st=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
  units=$(find "$corpus" -type f | wc -l)
  if [ $st -eq 0 ]; then
    echo "fuzz_$target: ${execs:-?} executions in ${FUZZ_SECONDS} s (${speed:-?}/s), corpus +$units, 0 crashes"
  else
    status=1
    echo "fuzz_$target: CRASH (exit $st) after ${execs:-?} executions; log $log:"
    grep -E 'ERROR|SUMMARY|invariant failed|Test unit written|#0 |#1 |#2 |#3 ' "$log" | head -n 20
  fi
done
exit $status
