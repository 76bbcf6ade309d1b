#!/usr/bin/env bash
# Run each libFuzzer target for FUZZ_SECONDS, FUZZ_JOBS of them side by side, starting from the
# checked-in seed corpus. New inputs go to $FUZZ_BUILD/corpus/<target> (the checked-in corpus is
# never written), crashes to $FUZZ_BUILD/crashes/. Prints one summary line per target; exits
# non-zero if any target crashed. Environment: FUZZ_BUILD (build-fuzz), FUZZ_SECONDS (60),
# FUZZ_JOBS (the online cores), FUZZ_FLAGS (extra libFuzzer flags, e.g. "-jobs=2 -workers=2" or
# "-max_total_time=...").
set -u
cd "$(dirname "$0")/../.."
FUZZ_BUILD=${FUZZ_BUILD:-build-fuzz}
FUZZ_SECONDS=${FUZZ_SECONDS:-60}
FUZZ_JOBS=${FUZZ_JOBS:-$(getconf _NPROCESSORS_ONLN 2> /dev/null || echo 1)}
[[ $FUZZ_JOBS =~ ^[1-9][0-9]*$ ]] || FUZZ_JOBS=1

# one target: its summary line (and the crash's trace) on stdout, non-zero if it crashed
fuzz_target() {
  local target=$1
  local bin=$FUZZ_BUILD/fuzz/fuzz_$target
  local corpus=$FUZZ_BUILD/corpus/$target
  local log=$FUZZ_BUILD/logs/$target.log
  local dict st execs speed units
  mkdir -p "$corpus" "$FUZZ_BUILD/crashes"
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
    echo "fuzz_$target: CRASH (exit $st) after ${execs:-?} executions; log $log:"
    grep -E 'ERROR|SUMMARY|invariant failed|Test unit written|#0 |#1 |#2 |#3 ' "$log" | head -n 20
    return 1
  fi
}

# FUZZ_JOBS targets at a time; the summaries in the order the targets were given
status=0
targets=("$@")
mkdir -p "$FUZZ_BUILD/logs"
for ((first = 0; first < ${#targets[@]}; first += FUZZ_JOBS)); do
  pids=()
  for ((i = first; i < first + FUZZ_JOBS && i < ${#targets[@]}; i++)); do
    fuzz_target "${targets[$i]}" > "$FUZZ_BUILD/logs/${targets[$i]}.summary" &
    pids+=($!)
  done
  for ((i = first; i < first + FUZZ_JOBS && i < ${#targets[@]}; i++)); do
    wait "${pids[$((i - first))]}" || status=1
    cat "$FUZZ_BUILD/logs/${targets[$i]}.summary"
  done
done
exit $status
