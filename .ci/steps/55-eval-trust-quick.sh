#!/usr/bin/env bash
# Quick subset of the trust evaluation (bench/eval/trust.py: tuning and test sets, still pairs,
# consecutive frames, a static clip): fails when the harness crashes or home-register /
# home-stab error; the silent-error and calibration numbers are the report's business (the full
# run, make eval-trust, is the measurement). The pip install is 50-eval-quick.sh's.
set -euo pipefail
cd "$(dirname "$0")/../.."
make eval-trust-quick
test -s build/eval-cache/trust-quick/trust_results.md
grep -q "silent" build/eval-cache/trust-quick/trust_results.md
