#!/usr/bin/env bash
# Cross builds for Raspberry Pi-class targets; the whole suite runs under qemu-user, so NEON is
# checked bit for bit against the scalar reference on aarch64 and armv7.
set -euo pipefail
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
$SUDO apt-get install -y -qq --no-install-recommends gcc-aarch64-linux-gnu gcc-arm-linux-gnueabihf \
  libc6-dev-arm64-cross libc6-dev-armhf-cross qemu-user-static binutils-aarch64-linux-gnu \
  binutils-arm-linux-gnueabihf > /dev/null
for target in aarch64-linux-gnu arm-linux-gnueabihf; do
  echo "--- make test CROSS_COMPILE=$target-"
  make -j2 test CROSS_COMPILE=$target- BUILD=build-$target
done
