#!/usr/bin/env bash
# Cross builds for Raspberry Pi-class targets; the suite runs under qemu-user, so NEON is
# checked bit for bit against the scalar reference on aarch64 and armv7. The two targets run
# side by side, each test binary in two shares (tests/run.sh, TEST_JOBS; qemu is
# single-threaded and CI has 2 cores). Under emulation the long accuracy tests of
# tests/cross-skip.txt are left to the native runs, and the golden check adds the demo clip.
set -euo pipefail
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
$SUDO apt-get install -y -qq --no-install-recommends gcc-aarch64-linux-gnu gcc-arm-linux-gnueabihf \
  libc6-dev-arm64-cross libc6-dev-armhf-cross qemu-user-static binutils-aarch64-linux-gnu \
  binutils-arm-linux-gnueabihf > /dev/null
HOME_TEST_SKIP=$(sed 's/#.*//' tests/cross-skip.txt)
export HOME_TEST_SKIP GOLDEN_CLIP=1 TEST_JOBS=2
pids=()
for target in aarch64-linux-gnu arm-linux-gnueabihf; do
  mkdir -p build-$target
  make -s test CROSS_COMPILE=$target- BUILD=build-$target > "build-$target/test.log" 2>&1 &
  pids+=($!)
done
status=0
for i in 0 1; do
  target=$([ $i = 0 ] && echo aarch64-linux-gnu || echo arm-linux-gnueabihf)
  if wait "${pids[$i]}"; then
    echo "--- $target: $(tail -n 1 build-$target/test.log) ($(awk '/skipped \(HOME_TEST_SKIP\)/ {n += $1} END {print n + 0}' build-$target/test.log) left to the native runs)"
  else echo "--- $target FAILED:"; grep -E 'FAIL|error|Error' "build-$target/test.log" | head -40; tail -n 3 "build-$target/test.log"; status=1; fi
done
exit $status
