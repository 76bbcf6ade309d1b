#!/usr/bin/env bash
# Hardening (issue 7): cppcheck + gcc -fanalyzer, the worst-case stack of every public function
# (<= 16 KiB), memcheck over the bad-input table, the fuzz corpus and the CLI, then each of the
# four fuzz targets for FUZZ_SECONDS (45; two at a time on two cores: 1.5 minutes) under
# ASan/UBSan, starting from the checked-in corpus. Any finding fails CI.
set -euo pipefail
cd "$(dirname "$0")/../.."
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
$SUDO apt-get install -y -qq --no-install-recommends clang libclang-rt-14-dev cppcheck valgrind > /dev/null

echo "--- make lint"
make -j2 lint
echo "--- make stack"
make stack
echo "--- make valgrind"
make -j2 valgrind
echo "--- make fuzz"
make fuzz FUZZ_SECONDS="${FUZZ_SECONDS:-45}"
